/* How far a turning body turned, in every output of a sweep, through the
 * real program: a sweep of the shape study's capsule in the essay's gate
 * (configs/shape/gate_capsule.yaml), one group whose body rotates and one
 * whose does not (body.rotates: [true, false]).
 *   - trials.csv carries heading_end, angular_velocity_end, turn_end and
 *     turn_max after t_exit: the body that does not rotate keeps its
 *     heading (90 deg) with 0 in the other three; the one that rotates
 *     turned, never further at the end than at its largest;
 *   - summary.json's group whose body rotates gives the mean of turn_end,
 *     of |turn_end|, the largest |turn_end| and the largest turn_max, as
 *     the rows give them; the other group gives none;
 *   - run --json of a trial gives its row's four numbers;
 *   - the trials of the sweep in two parts merged, and of the sweep killed
 *     while its trials ran and resumed, are the uninterrupted run's, byte
 *     for byte (the journal's records hold the turn);
 *   - beamsim regress repeats the run with no trial changed, the turn
 *     compared. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "support.h"
#include "util/csv_table.h"

#define PI     3.14159265358979323846
#define TRIALS "24"

static char dir[1024], experiment[1200], one[1200];

static int setup(void **state)
{
	(void)state;
	char text[2048];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("turn_outputs"));
	snprintf(text, sizeof text,
	         "scene: %s\n"
	         "trials: " TRIALS "\n"
	         "seed: 3\n"
	         "grid:\n"
	         "  body.rotates: [true, false]\n",
	         bsim_test_src("configs/shape/gate_capsule.yaml"));
	snprintf(experiment, sizeof experiment, "%s", bsim_test_write(dir, "exp.yaml", text));
	snprintf(one, sizeof one, "%s", bsim_test_join(dir, "one"));
	const char *argv[] = {"sweep", experiment, "--out", one, "--quiet", NULL};
	char *err = NULL;
	int rc = bsim_test_cli(argv, NULL, &err);
	if (rc != 0)
		print_error("%s", err ? err : "");
	free(err);
	return rc;
}

static char *read_in(const char *out, const char *file)
{
	char *text = bsim_test_read(bsim_test_join(out, file));
	if (!text)
		fail_msg("cannot read %s/%s", out, file);
	return text;
}

/* A number of row r of trials.csv by column name. */
static double cell(const csv_table *t, long r, const char *name)
{
	double x;
	int c = bsim_csv_table_col(t, name);
	assert_true(c >= 0);
	assert_int_equal(bsim_csv_table_number(t, r, c, &x), 0);
	return x;
}

/* The line of summary.json of group g (one group a line), malloc'd. */
static char *group_line(const char *summary, int g)
{
	const char *p = summary;
	for (int k = 0; k <= g; k++) {
		p = strstr(p, "{\"params\": ");
		assert_non_null(p);
		if (k < g)
			p++;
	}
	size_t n = strcspn(p, "\n");
	char *line = malloc(n + 1);
	assert_non_null(line);
	memcpy(line, p, n);
	line[n] = '\0';
	return line;
}

/* a and b equal but for trials.csv's 10 significant digits */
static void assert_close(double a, double b)
{
	if (!(fabs(a - b) <= 1e-9 * (1.0 + fabs(b))))
		fail_msg("%.17g, expected %.17g", a, b);
}

static void test_columns_and_summary(void **state)
{
	(void)state;
	char *csv = read_in(one, "trials.csv");
	assert_non_null(strstr(csv, ",t_exit,heading_end,angular_velocity_end,turn_end,turn_max,"
	                            "body.rotates\n"));
	free(csv);
	csv_table t;
	bsim_error err;
	if (bsim_csv_table_read(bsim_test_join(one, "trials.csv"), &t, &err) != 0)
		fail_msg("%s", err.msg);
	double mean = 0.0, mean_abs = 0.0, max_abs = 0.0, turn_max = 0.0;
	int n = 0, turned = 0;
	for (long r = 0; r < t.n_rows; r++) {
		double heading = cell(&t, r, "heading_end"),
		       w = cell(&t, r, "angular_velocity_end"), turn = cell(&t, r, "turn_end"),
		       far = cell(&t, r, "turn_max");
		if (cell(&t, r, "group") == 1) { /* the body keeps its heading, 90 deg */
			assert_close(heading, PI / 2);
			assert_true(w == 0.0 && turn == 0.0 && far == 0.0);
			continue;
		}
		/* the row's own relations, at its precision */
		assert_close(turn, heading - PI / 2);
		assert_true(far >= fabs(turn) * (1.0 - 1e-9));
		turned += fabs(turn) > 0.05;
		mean += turn;
		mean_abs += fabs(turn);
		max_abs = fmax(max_abs, fabs(turn));
		turn_max = fmax(turn_max, far);
		n++;
	}
	bsim_csv_table_free(&t);
	assert_int_equal(n, atoi(TRIALS));
	assert_true(turned >= n / 2); /* the check covers bodies that turned */
	char *summary = read_in(one, "summary.json");
	char *g0 = group_line(summary, 0), *g1 = group_line(summary, 1);
	print_message("group 0: mean turn %.4g rad, mean |turn| %.4g rad, largest %.4g rad, "
	              "largest during a trial %.4g rad\n",
	              mean / n, mean_abs / n, max_abs, turn_max);
	assert_close(bsim_test_json_number(g0, "turn_end_mean"), mean / n);
	assert_close(bsim_test_json_number(g0, "turn_end_mean_abs"), mean_abs / n);
	assert_close(bsim_test_json_number(g0, "turn_end_max_abs"), max_abs);
	assert_close(bsim_test_json_number(g0, "turn_max"), turn_max);
	assert_null(strstr(g1, "turn")); /* its body does not rotate */
	free(g0);
	free(g1);
	free(summary);
}

/* run --json of trials of the group whose body rotates: its row's four
 * numbers, as trials.csv writes them. */
static void test_run_json(void **state)
{
	(void)state;
	csv_table t;
	bsim_error err;
	if (bsim_csv_table_read(bsim_test_join(one, "trials.csv"), &t, &err) != 0)
		fail_msg("%s", err.msg);
	static const char *const names[] = {"heading_end", "angular_velocity_end", "turn_end",
	                                    "turn_max"};
	for (long r = 0; r < 3; r++) {
		char trial[16];
		snprintf(trial, sizeof trial, "%ld", r);
		const char *argv[] = {"run",     experiment, "--group", "0",
		                      "--trial", trial,      "--json",  NULL};
		char *out = NULL;
		assert_int_equal(bsim_test_cli(argv, &out, NULL), 0);
		for (int k = 0; k < 4; k++) {
			char a[64];
			snprintf(a, sizeof a, "%.10g", bsim_test_json_number(out, names[k]));
			assert_string_equal(
			        a, bsim_csv_table_cell(&t, r, bsim_csv_table_col(&t, names[k])));
		}
		free(out);
	}
	bsim_csv_table_free(&t);
}

static void same_trials(const char *ref, const char *out)
{
	char *a = read_in(ref, "trials.csv"), *b = read_in(out, "trials.csv");
	if (strcmp(a, b) != 0)
		fail_msg("%s/trials.csv differs from the uninterrupted run's", out);
	free(a);
	free(b);
}

/* The sweep in two parts, merged: the parts' journals carry each trial's
 * result, turn and all. */
static void test_merge(void **state)
{
	(void)state;
	char part[2][1200], out[1200];
	for (int i = 0; i < 2; i++) {
		char shard[16];
		snprintf(part[i], sizeof part[i], "%s/part%d", dir, i + 1);
		snprintf(shard, sizeof shard, "%d/2", i + 1);
		const char *argv[] = {"sweep", experiment, "--shard", shard,
		                      "--out", part[i],    "--quiet", NULL};
		assert_int_equal(bsim_test_cli(argv, NULL, NULL), 0);
	}
	snprintf(out, sizeof out, "%s/merged", dir);
	const char *argv[] = {"merge", part[0], part[1], "--out", out, "--quiet", NULL};
	assert_int_equal(bsim_test_cli(argv, NULL, NULL), 0);
	same_trials(one, out);
}

/* The sweep, of RESUME_TRIALS trials a group (about a second of work, so
 * that the kill comes while trials run), killed once its journal holds two
 * trials, then resumed: the resumed run takes those trials' results from
 * the journal. */
#define RESUME_TRIALS "400"
static void test_resume(void **state)
{
	(void)state;
	char ref[1200], out[1200];
	snprintf(ref, sizeof ref, "%s/uninterrupted", dir);
	snprintf(out, sizeof out, "%s/resumed", dir);
	const char *whole[] = {"sweep", experiment, "--trials", RESUME_TRIALS,
	                       "--out", ref,        "--quiet",  NULL};
	assert_int_equal(bsim_test_cli(whole, NULL, NULL), 0);
	const char *argv[] = {"sweep", experiment, "--trials", RESUME_TRIALS, "--threads",
	                      "1",     "--out",    out,        "--quiet",     NULL};
	int pid = bsim_test_spawn(argv), rc = 0;
	if (!bsim_test_await_records(pid, bsim_test_join(out, ".beamsim/journal"), 2, &rc))
		fail_msg("the sweep ended (status %d) before its journal held two trials", rc);
	kill(pid, SIGKILL);
	assert_int_equal(bsim_test_wait(pid), 128 + SIGKILL);
	long kept = bsim_test_journal_records(bsim_test_join(out, ".beamsim/journal"));
	int total = 2 * atoi(RESUME_TRIALS);
	print_message("killed with %ld trials journaled of %d\n", kept, total);
	assert_true(kept >= 2 && kept < total);
	const char *again[] = {"sweep", experiment, "--trials", RESUME_TRIALS, "--out",
	                       out,     "--quiet",  "--resume", NULL};
	assert_int_equal(bsim_test_cli(again, NULL, NULL), 0);
	same_trials(ref, out);
}

/* regress reruns the stored sweep: no trial changed, the turn compared
 * (both files have its columns). */
static void test_regress(void **state)
{
	(void)state;
	char out[1200];
	snprintf(out, sizeof out, "%s/regress", dir);
	const char *argv[] = {"regress", one, "--out", out, NULL};
	char *text = NULL, *err = NULL;
	int rc = bsim_test_cli(argv, &text, &err);
	if (rc != 0)
		fail_msg("beamsim regress exited %d: %s", rc, err ? err : "");
	char want[64];
	snprintf(want, sizeof want, ": 0 of %d trials changed", 2 * atoi(TRIALS));
	if (!strstr(text, want))
		fail_msg("regress said: %s", text);
	free(text);
	free(err);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_columns_and_summary),
	        cmocka_unit_test(test_run_json),
	        cmocka_unit_test(test_merge),
	        cmocka_unit_test(test_resume),
	        cmocka_unit_test(test_regress),
	};
	return cmocka_run_group_tests(tests, setup, NULL);
}
