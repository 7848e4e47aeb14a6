/* A progress line for long runs (docs/files.md "Command line"): on a
 * terminal
 *   "\r  1234/3000 trials  41%  ETA 0:03" on stderr, redrawn in place;
 * off one (a log, nohup, a batch job), a line of its own every 10 s
 * (BEAMSIM_PROGRESS_SECONDS), none for a run shorter than that:
 *   "beamsim: progress: 1234/3000 trials  41%  ETA 0:03". */
#ifndef BSIM_CLI_CLI_PROGRESS_H
#define BSIM_CLI_CLI_PROGRESS_H

typedef struct cli_progress {
	int active;          /* enabled (not --quiet) */
	int tty;             /* stderr is a terminal */
	double log_interval; /* s between the lines off a terminal */
	int shown;           /* a line is on the screen and needs a newline */
	const char *unit;    /* what is counted: "trials" */
	double t_start;      /* s, monotonic */
	double t_last;       /* s, when the line was last drawn */
	/* done and the time, s, at the first update, or done0 = -1 before it:
	 * the rate counts from there, so neither the start-up nor a resumed
	 * run's journaled trials (which took no time) enter it. */
	long done0;
	double t0;
} cli_progress;

/* Starts the clock. Prints nothing ever if !enabled. unit names what is
 * counted. */
void cli_progress_init(cli_progress *p, int enabled, const char *unit);

/* A bsim_progress_fn (beamsim/progress.h): user is the cli_progress.
 * Redraws at most ten times a second, and always for the last item. */
void cli_progress_update(void *user, long done, long total);

/* The ETA rule: the seconds left of a run with done of total items finished
 * at time now (s), from its rate since done0 were finished at time t0, or
 * -1 while that rate rests on too little: fewer than 3% of the items this
 * run does (total - done0) and less than 2 s measured. 0 once done. */
double cli_progress_eta(long done, long total, long done0, double t0, double now);

/* Ends the line with a newline if one was drawn. */
void cli_progress_finish(cli_progress *p);

#endif
