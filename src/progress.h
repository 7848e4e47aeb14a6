/* A progress line for long runs on a terminal (DESIGN.md "Command line":
 * progress and an ETA on a terminal, quiet when not on one).
 *
 *   "\r  1234/3000 trials  41%  ETA 0:03" on stderr, redrawn in place. */
#ifndef BEAMSIM_PROGRESS_H
#define BEAMSIM_PROGRESS_H

#ifdef __cplusplus
extern "C" {
#endif

typedef struct bsim_progress {
	int active;     /* enabled and stderr is a terminal */
	int shown;      /* a line is on the screen and needs a newline */
	double t_start; /* s, monotonic */
	double t_last;  /* s, when the line was last drawn */
	long base;      /* done at the first update (a resumed run's journaled trials), or -1 */
} bsim_progress;

/* Starts the clock. Prints nothing ever if !enabled or stderr is not a
 * terminal. */
void bsim_progress_init(bsim_progress *p, int enabled);

/* A bsim_progress_fn: user is the bsim_progress. Redraws at most ten times
 * a second, and always for the last trial. */
void bsim_progress_update(void *user, long done, long total);

/* Ends the line with a newline if one was drawn. */
void bsim_progress_finish(bsim_progress *p);

#ifdef __cplusplus
}
#endif
#endif
