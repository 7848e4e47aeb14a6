/* The progress line's ETA rule (cli_progress_eta): no ETA until the rate
 * rests on enough finished work, and then the time left at that rate. The
 * times are arguments, so nothing here waits or reads a clock. And the
 * lines off a terminal, at an interval of 0 s or one never reached. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* The program's progress line, compiled in: it is not part of the
 * library the tests link. */
#include "cli/cli_progress.c"

/* Nothing finished since the first update, or no time measured: no ETA. */
static void test_no_rate_no_eta(void **state)
{
	(void)state;
	assert_true(cli_progress_eta(5, 3240, 5, 20.0, 20.0) < 0);
	assert_true(cli_progress_eta(5, 3240, 5, 20.0, 25.0) < 0);
	assert_true(cli_progress_eta(6, 3240, 5, 20.0, 20.0) < 0);
}

/* Below 3% of the run's items and 2 s: none; at either, the time left at
 * the rate since the first update, exactly. */
static void test_thresholds(void **state)
{
	(void)state;
	long total = 1005, done0 = 5; /* 1000 items this run: 3% is 30 */
	assert_true(cli_progress_eta(done0 + 29, total, done0, 10.0, 11.9) < 0);
	double at_fraction = cli_progress_eta(done0 + 30, total, done0, 10.0, 11.5);
	assert_float_equal(at_fraction, 1.5 * (double)(total - done0 - 30) / 30.0, 1e-12);
	double at_seconds = cli_progress_eta(done0 + 1, total, done0, 10.0, 12.0);
	assert_float_equal(at_seconds, 2.0 * (double)(total - done0 - 1), 1e-12);
	/* done: nothing left */
	assert_float_equal(cli_progress_eta(total, total, done0, 10.0, 30.0), 0.0, 0.0);
}

/* The case that said 56:34 for a sweep of 30 s: 3240 trials on 8 threads
 * at 0.074 s a trial after 10 s of start-up, the first thread's updates
 * each reporting the trials every thread finished. The first ETA shown is
 * within 25% of the time actually left, and every later one too. */
static void test_first_eta_near(void **state)
{
	(void)state;
	const long total = 3240;
	const int threads = 8;
	const double trial = 0.074, startup = 10.0;
	long done0 = -1, shown = 0;
	double t0 = 0.0;
	for (int k = 1; k * threads <= total; k++) {
		/* leader's k-th trial ends: every thread has finished k (the
		 * others a little later, so k - 1 of theirs are counted) */
		double now = startup + k * trial;
		long done = k + (long)(threads - 1) * (k - 1);
		if (done0 < 0) {
			done0 = done;
			t0 = now;
		}
		double eta = cli_progress_eta(done, total, done0, t0, now);
		double left = (double)(total - done) / threads * trial;
		if (eta < 0) {
			assert_int_equal(shown, 0); /* once shown, always shown */
			continue;
		}
		shown++;
		if (fabs(eta - left) > 0.25 * left)
			fail_msg("update %d: ETA %.1f s, left %.1f s", k, eta, left);
	}
	assert_true(shown > 0);
}

/* The lines a run of n items prints off a terminal (stderr a file) with
 * BEAMSIM_PROGRESS_SECONDS at seconds ("" unset), enabled or not. */
static int lines_off_terminal(const char *seconds, int enabled, long n, char *buf, size_t size)
{
	FILE *log = tmpfile();
	assert_non_null(log);
	fflush(stderr);
	int saved = dup(STDERR_FILENO);
	assert_true(saved >= 0 && dup2(fileno(log), STDERR_FILENO) >= 0);
	if (seconds[0])
		setenv("BEAMSIM_PROGRESS_SECONDS", seconds, 1);
	else
		unsetenv("BEAMSIM_PROGRESS_SECONDS");
	cli_progress p;
	cli_progress_init(&p, enabled, "trials");
	for (long k = 1; k <= n; k++)
		cli_progress_update(&p, k, n);
	cli_progress_finish(&p);
	fflush(stderr);
	dup2(saved, STDERR_FILENO);
	close(saved);
	unsetenv("BEAMSIM_PROGRESS_SECONDS");
	rewind(log);
	size_t got = fread(buf, 1, size - 1, log);
	buf[got] = '\0';
	fclose(log);
	int lines = 0;
	for (const char *c = buf; *c; c++)
		lines += *c == '\n';
	return lines;
}

/* Off a terminal: a line of its own for each update once the interval has
 * passed (0 s: every update but the last, which the command's own closing
 * line reports), counting up, with no carriage return; none when disabled
 * (--quiet), none within the interval. */
static void test_off_terminal(void **state)
{
	(void)state;
	char buf[4096];
	assert_int_equal(lines_off_terminal("0", 1, 10, buf, sizeof buf), 9);
	assert_null(strchr(buf, '\r'));
	const char *at = buf;
	for (long k = 1; k <= 9; k++) {
		char want[64];
		snprintf(want, sizeof want, "beamsim: progress: %ld/10 trials  %ld%%  ETA ", k,
		         10 * k);
		assert_true(strncmp(at, want, strlen(want)) == 0);
		at = strchr(at, '\n') + 1;
	}
	assert_int_equal(lines_off_terminal("0", 0, 10, buf, sizeof buf), 0);
	assert_int_equal(lines_off_terminal("1e9", 1, 10, buf, sizeof buf), 0);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_no_rate_no_eta),
	        cmocka_unit_test(test_thresholds),
	        cmocka_unit_test(test_first_eta_near),
	        cmocka_unit_test(test_off_terminal),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
