/* The progress line of long runs; see cli_progress.h. */
#define _POSIX_C_SOURCE 200809L

#include "cli/cli_progress.h"

#include "util/clock.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

/* Redraw interval, s: fast enough to look live, slow enough to cost nothing. */
#define PROGRESS_INTERVAL 0.1

/* When an ETA may be shown. Its rate counts from the first update, which a
 * sweep makes when its first thread ends its first trial: the start-up
 * (loading, building the worlds) is left out, and a rate measured from one
 * update of that thread to the next spans about one trial of every thread.
 * A rate over 3% of the items, or over 2 s, has averaged out the trials'
 * spread of durations well enough that the first ETA shown is within a
 * small factor of the time left; one over the first few trials alone is
 * not (it said 56:34 for a sweep of 30 s: the start-up and the trials the
 * other threads finished with the first were counted against one trial). */
#define ETA_MIN_FRACTION 0.03
#define ETA_MIN_SECONDS  2.0

/* Off a terminal (a log, nohup, a batch job): a line every so many
 * seconds, BEAMSIM_PROGRESS_SECONDS or LOG_INTERVAL; a run shorter than
 * that prints none. */
#define LOG_INTERVAL 10.0

void cli_progress_init(cli_progress *p, int enabled, const char *unit)
{
	p->tty = isatty(STDERR_FILENO);
	p->active = enabled;
	p->log_interval = LOG_INTERVAL;
	const char *env = getenv("BEAMSIM_PROGRESS_SECONDS");
	char *end;
	double v = env ? strtod(env, &end) : NAN;
	if (env && end != env && *end == '\0' && v >= 0.0)
		p->log_interval = v;
	p->unit = unit;
	p->shown = 0;
	p->t_start = bsim_clock_seconds();
	p->t_last = -1.0;
	p->done0 = -1;
	p->t0 = 0.0;
}

double cli_progress_eta(long done, long total, long done0, double t0, double now)
{
	if (done >= total)
		return 0.0;
	long n = done - done0;
	double measured = now - t0;
	if (n < 1 || !(measured > 0.0))
		return -1.0;
	if ((double)n < ETA_MIN_FRACTION * (double)(total - done0) && measured < ETA_MIN_SECONDS)
		return -1.0;
	return measured * (double)(total - done) / (double)n;
}

/* "0:03", "12:40", "1:02:03". */
static void format_duration(char *buf, size_t n, double s)
{
	long t = (long)(s + 0.5);
	if (t >= 3600)
		snprintf(buf, n, "%ld:%02ld:%02ld", t / 3600, t / 60 % 60, t % 60);
	else
		snprintf(buf, n, "%ld:%02ld", t / 60, t % 60);
}

void cli_progress_update(void *user, long done, long total)
{
	cli_progress *p = user;
	if (!p || !p->active || total <= 0)
		return;
	double now = bsim_clock_seconds();
	if (p->done0 < 0) {
		p->done0 = done;
		p->t0 = now;
	}
	if (!p->tty) {
		/* a line of its own every log_interval s from the start, the last
		 * item's left to the command's own closing line */
		if (done >= total ||
		    now - (p->t_last >= 0.0 ? p->t_last : p->t_start) < p->log_interval)
			return;
	} else if (done < total && p->t_last >= 0.0 && now - p->t_last < PROGRESS_INTERVAL) {
		return;
	}
	p->t_last = now;

	char eta[32] = "-:--";
	double left = cli_progress_eta(done, total, p->done0, p->t0, now);
	if (done >= total)
		format_duration(eta, sizeof eta, now - p->t_start);
	else if (left >= 0.0)
		format_duration(eta, sizeof eta, left);
	const int pct = (int)(100.0 * (double)done / (double)total);
	if (!p->tty) {
		fprintf(stderr, "beamsim: progress: %ld/%ld %s  %d%%  ETA %s\n", done, total,
		        p->unit, pct, eta);
		fflush(stderr);
		return;
	}
	/* Trailing spaces wipe what a longer previous line left behind. */
	fprintf(stderr, "\r  %ld/%ld %s  %d%%  %s %s   ", done, total, p->unit, pct,
	        done >= total ? "took" : "ETA", eta);
	fflush(stderr);
	p->shown = 1;
}

void cli_progress_finish(cli_progress *p)
{
	if (p->active && p->shown)
		fputc('\n', stderr);
	p->shown = 0;
}
