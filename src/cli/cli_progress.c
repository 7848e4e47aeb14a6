/* The progress line of long runs; see cli_progress.h. */
#define _POSIX_C_SOURCE 200809L

#include "cli/cli_progress.h"

#include "util/clock.h"

#include <stdio.h>
#include <unistd.h>

/* Redraw interval, s: fast enough to look live, slow enough to cost nothing. */
#define PROGRESS_INTERVAL 0.1

void cli_progress_init(cli_progress *p, int enabled, const char *unit)
{
	p->active = enabled && isatty(STDERR_FILENO);
	p->unit = unit;
	p->shown = 0;
	p->t_start = bsim_clock_seconds();
	p->t_last = -1.0;
	p->base = -1;
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
	/* Trials taken from a journal took no time: the ETA counts from the
	 * first trial this run finished. */
	if (p->base < 0)
		p->base = done > 0 ? done - 1 : 0;
	double now = bsim_clock_seconds();
	if (done < total && p->t_last >= 0.0 && now - p->t_last < PROGRESS_INTERVAL)
		return;
	p->t_last = now;

	char eta[32] = "-:--";
	double elapsed = now - p->t_start;
	if (done >= total)
		format_duration(eta, sizeof eta, elapsed);
	else if (done > p->base)
		format_duration(eta, sizeof eta,
		                elapsed * (double)(total - done) / (double)(done - p->base));
	/* Trailing spaces wipe what a longer previous line left behind. */
	fprintf(stderr, "\r  %ld/%ld %s  %d%%  %s %s   ", done, total, p->unit,
	        (int)(100.0 * (double)done / (double)total), done >= total ? "took" : "ETA", eta);
	fflush(stderr);
	p->shown = 1;
}

void cli_progress_finish(cli_progress *p)
{
	if (p->active && p->shown)
		fputc('\n', stderr);
	p->shown = 0;
}
