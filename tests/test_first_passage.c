/* First passage through beamsim: trials.csv's t_exit is t_end for a trial
 * that left the gate (traversed, side exit) and empty for one still in it;
 * the horizon curve of a sweep run twice as long, read at the first
 * sweep's horizon, is that sweep's outcome counts (a trial does not know
 * how long it may run: cutting a 24 s sweep at 12 s is the 12 s sweep),
 * and at its own horizon it is its own summary; beamsim plot draws the
 * survival figure; beamsim escape writes the Kramers table and refuses
 * what is no sweep. */
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

#include "util/csv_table.h"
#include "support.h"

static const char *exp_path, *d12, *d24;

static int setup(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("first_passage");
	char text[1024];
	snprintf(text, sizeof text,
	         "scene: %s\ntrials: 60\nseed: 3\ngrid:\n  effects.propulsion.force: [7, 9]\n"
	         "  effects.random_force.magnitude: [20]\n",
	         bsim_test_src("configs/thesis/gate.yaml"));
	exp_path = strdup(bsim_test_write(dir, "exp.yaml", text));
	d12 = strdup(bsim_test_join(dir, "d12"));
	d24 = strdup(bsim_test_join(dir, "d24"));
	const char *a12[] = {"sweep", exp_path, "--out", d12, "--quiet", NULL};
	const char *a24[] = {
	        "sweep", exp_path, "--out", d24, "--quiet", "--set", "integration.duration=24",
	        NULL};
	assert_int_equal(bsim_test_cli(a12, NULL, NULL), 0);
	assert_int_equal(bsim_test_cli(a24, NULL, NULL), 0);
	return 0;
}

static void read_table(const char *dir, const char *name, csv_table *t)
{
	bsim_error err;
	if (bsim_csv_table_read(bsim_test_join(dir, name), t, &err) != 0)
		fail_msg("%s", err.msg);
}

/* counts[g][0..2]: traversed, side_exit, stuck of trials.csv in dir. */
static void outcome_counts(const char *dir, long counts[2][3])
{
	csv_table t;
	read_table(dir, "trials.csv", &t);
	memset(counts, 0, 2 * sizeof counts[0]);
	int cg = bsim_csv_table_col(&t, "group"), co = bsim_csv_table_col(&t, "outcome"),
	    ct = bsim_csv_table_col(&t, "t_end"), cx = bsim_csv_table_col(&t, "t_exit");
	assert_true(cg >= 0 && co >= 0 && ct >= 0 && cx >= 0);
	for (long r = 0; r < t.n_rows; r++) {
		double g;
		bsim_csv_table_number(&t, r, cg, &g);
		const char *o = bsim_csv_table_cell(&t, r, co);
		int k = strcmp(o, "traversed") == 0 ? 0 : strcmp(o, "side_exit") == 0 ? 1 : 2;
		counts[(int)g][k]++;
		/* t_exit: t_end, as written, for an exit; empty otherwise */
		if (k < 2)
			assert_string_equal(bsim_csv_table_cell(&t, r, cx),
			                    bsim_csv_table_cell(&t, r, ct));
		else
			assert_string_equal(bsim_csv_table_cell(&t, r, cx), "");
	}
	bsim_csv_table_free(&t);
}

/* horizon.csv of dir at h, group g: traversed, side_exit, stuck. */
static void horizon_at(const char *dir, int g, double h, long out[3])
{
	csv_table t;
	read_table(dir, "horizon.csv", &t);
	const char *cols[] = {"traversed", "side_exit", "stuck"};
	int found = 0;
	for (long r = 0; r < t.n_rows; r++) {
		double gg, hh;
		bsim_csv_table_number(&t, r, bsim_csv_table_col(&t, "group"), &gg);
		bsim_csv_table_number(&t, r, bsim_csv_table_col(&t, "h"), &hh);
		if ((int)gg != g || fabs(hh - h) > 1e-9)
			continue;
		for (int k = 0; k < 3; k++) {
			double v;
			bsim_csv_table_number(&t, r, bsim_csv_table_col(&t, cols[k]), &v);
			out[k] = (long)v;
		}
		found = 1;
	}
	bsim_csv_table_free(&t);
	assert_true(found);
}

static void test_horizon_identity(void **state)
{
	(void)state;
	long c12[2][3], c24[2][3];
	outcome_counts(d12, c12);
	outcome_counts(d24, c24);
	for (int g = 0; g < 2; g++) {
		long h[3];
		horizon_at(d24, g, 12.0, h);
		for (int k = 0; k < 3; k++)
			assert_int_equal(h[k], c12[g][k]);
		horizon_at(d12, g, 12.0, h);
		for (int k = 0; k < 3; k++)
			assert_int_equal(h[k], c12[g][k]);
		horizon_at(d24, g, 24.0, h);
		for (int k = 0; k < 3; k++)
			assert_int_equal(h[k], c24[g][k]);
	}
	/* the survival curve ends at the share still in the gate */
	csv_table t;
	read_table(d12, "survival.csv", &t);
	double last_s = -1, last_t = -1;
	for (long r = 0; r < t.n_rows; r++) {
		double g;
		bsim_csv_table_number(&t, r, bsim_csv_table_col(&t, "group"), &g);
		if ((int)g == 1) {
			bsim_csv_table_number(&t, r, bsim_csv_table_col(&t, "survival"), &last_s);
			bsim_csv_table_number(&t, r, bsim_csv_table_col(&t, "t"), &last_t);
		}
	}
	bsim_csv_table_free(&t);
	if (c12[1][2] > 0)
		assert_true(fabs(last_t - 12.0) < 1e-9);
	assert_true(fabs(last_s - c12[1][2] / 60.0) < 1e-9);
}

static void test_plot_and_escape(void **state)
{
	(void)state;
	const char *plot[] = {"plot", d12, NULL};
	assert_int_equal(bsim_test_cli(plot, NULL, NULL), 0);
	assert_true(bsim_test_exists(bsim_test_join(d12, "survival.gp")));
	assert_true(bsim_test_check_figures(d12) >= 1);
	char *out = strdup(bsim_test_join(bsim_test_dir("first_passage_escape"), "esc"));
	char *o = NULL;
	const char *esc[] = {"escape", d24, "--out", out, NULL};
	assert_int_equal(bsim_test_cli(esc, &o, NULL), 0);
	assert_non_null(strstr(o, "2 groups"));
	/* two groups: too few for a fit, so no verdict, and null in the file */
	assert_null(strstr(o, "verdict"));
	free(o);
	char *csv = bsim_test_read(bsim_test_join(out, "kramers.csv"));
	assert_int_equal(bsim_test_count_lines(csv), 3);
	assert_non_null(strstr(csv, "group,barrier,above_start,kind,noise"));
	free(csv);
	assert_true(bsim_test_exists(bsim_test_join(out, "kramers.json")));
	assert_true(bsim_test_check_figures(out) >= 0); /* kramers, when drawn */
	char *js = bsim_test_read(bsim_test_join(out, "kramers.json"));
	assert_non_null(strstr(js, "\"verdict\": null"));
	free(js);
	const char *bad[] = {"escape", exp_path, "--out", out, NULL};
	const char *needles[] = {"exp.yaml", NULL};
	bsim_test_expect_input_error(bad, needles);
	free(out);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_horizon_identity),
	        cmocka_unit_test(test_plot_and_escape),
	};
	return cmocka_run_group_tests(tests, setup, NULL);
}
