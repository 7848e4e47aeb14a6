/* A progress line for long runs on a terminal (DESIGN.md "Command line":
 * progress and an ETA on a terminal, quiet when not on one).
 *
 *   "\r  1234/3000 trials  41%  ETA 0:03" on stderr, redrawn in place. */
#ifndef BSIM_CLI_CLI_PROGRESS_H
#define BSIM_CLI_CLI_PROGRESS_H

typedef struct cli_progress {
	int active;       /* enabled and stderr is a terminal */
	int shown;        /* a line is on the screen and needs a newline */
	const char *unit; /* what is counted: "trials" */
	double t_start;   /* s, monotonic */
	double t_last;    /* s, when the line was last drawn */
	long base;        /* done at the first update (a resumed run's journaled trials), or -1 */
} cli_progress;

/* Starts the clock. Prints nothing ever if !enabled or stderr is not a
 * terminal. unit names what is counted. */
void cli_progress_init(cli_progress *p, int enabled, const char *unit);

/* A bsim_progress_fn (beamsim/progress.h): user is the cli_progress.
 * Redraws at most ten times a second, and always for the last item. */
void cli_progress_update(void *user, long done, long total);

/* Ends the line with a newline if one was drawn. */
void cli_progress_finish(cli_progress *p);

#endif
