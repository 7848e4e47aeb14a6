/* The accuracy study's comparison at equal error (bsim_accuracy_equal_error,
 * equal_error.csv) on a synthetic table whose answer is worked out by hand
 * below: per target, each backend's cheapest row by CPU time per simulated
 * second among its rows with err_mean <= target, never the reference row
 * nor a row with an unstable trial, and the cost over the first backend's. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "beamsim/accuracy.h"
#include "support.h"

/* backend, reference, h (s), err_mean (m), CPU s per simulated s, failed */
static const struct {
	const char *backend;
	int reference;
	double h, err, cpu;
	int failed;
} table[] = {
        {"thesis", 0, 0.016, 0.05, 1e-5, 0},    /* 0: reaches none */
        {"thesis", 0, 0.008, 0.02, 2e-5, 0},    /* 1: exactly 0.02 counts */
        {"thesis", 0, 0.004, 0.003, 4e-5, 0},   /* 2 */
        {"thesis", 0, 0.004, 0.004, 3.5e-5, 0}, /* 3: cheaper than 2 */
        {"thesis", 1, 0.001, 0.0, 1e-6, 0},     /* 4: reference, cheapest, never picked */
        {"box2d", 0, 0.008, 0.015, 3e-4, 0},    /* 5 */
        {"box2d", 0, 0.008, 0.012, 2e-4, 1},    /* 6: an unstable trial: never picked */
        {"box2d", 0, 0.004, 0.004, 8e-4, 0},    /* 7 */
        {"box2d", 0, 0.004, 0.0049, 6e-4, 0},   /* 8 */
        {"box2d", 0, 0.002, NAN, 1e-4, 0},      /* 9: no error measured */
        {"box2d", 1, 0.001, 0.0, 1e-3, 0},      /* 10: reference */
};
enum { N_ROWS = sizeof table / sizeof table[0] };

static void synthetic(bsim_accuracy_result *r, bsim_accuracy_row *rows)
{
	memset(rows, 0, N_ROWS * sizeof *rows);
	for (int i = 0; i < N_ROWS; i++) {
		rows[i].backend = table[i].backend;
		snprintf(rows[i].setting, sizeof rows[i].setting, "row%d", i);
		rows[i].reference = table[i].reference;
		rows[i].h = table[i].h;
		rows[i].err_mean = table[i].err;
		rows[i].cpu_cost = table[i].cpu;
		rows[i].failed = table[i].failed;
	}
	r->n = N_ROWS;
	r->rows = rows;
}

static void test_selection(void **state)
{
	(void)state;
	bsim_accuracy_row rows[N_ROWS];
	bsim_accuracy_result r;
	synthetic(&r, rows);
	const double targets[] = {0.02, 0.005, 0.0035, 0.001};
	bsim_accuracy_equal *eq;
	int n;
	bsim_error err;
	assert_int_equal(bsim_accuracy_equal_error(&r, targets, 4, &eq, &n, &err), BSIM_OK);
	assert_int_equal(n, 8); /* 4 targets x 2 backends, target by target */
	/* By hand: (target, backend) -> row, ratio. */
	static const struct {
		const char *backend;
		int row;
		double ratio;
	} want[] = {
	        {"thesis", 1, 1.0},  {"box2d", 5, 3e-4 / 2e-5},   /* 0.02: 15 */
	        {"thesis", 3, 1.0},  {"box2d", 8, 6e-4 / 3.5e-5}, /* 0.005: 17.14 */
	        {"thesis", 2, 1.0},  {"box2d", -1, NAN},          /* 0.0035 */
	        {"thesis", -1, NAN}, {"box2d", -1, NAN},          /* 0.001 */
	};
	for (int i = 0; i < n; i++) {
		assert_true(eq[i].target == targets[i / 2]);
		assert_string_equal(eq[i].backend, want[i].backend);
		assert_int_equal(eq[i].row, want[i].row);
		if (isnan(want[i].ratio)) {
			assert_true(isnan(eq[i].ratio));
		} else {
			assert_true(eq[i].cpu_cost == table[want[i].row].cpu);
			assert_true(fabs(eq[i].ratio - want[i].ratio) <= 1e-12 * want[i].ratio);
		}
	}

	/* The CSV: the picks' rows, empty cells where a backend reaches none. */
	const char *dir = bsim_test_dir("accuracy_equal");
	char path[1100];
	snprintf(path, sizeof path, "%s/equal_error.csv", dir);
	assert_int_equal(bsim_accuracy_write_equal_csv(path, &r, eq, n, &err), BSIM_OK);
	char *csv = bsim_test_read(path);
	assert_non_null(csv);
	assert_string_equal(
	        csv, "target_m,backend,setting,h_s,err_mean_m,cpu_per_sim_s,ratio_equal_error\n"
	             "0.02,thesis,row1,0.008,2.000000e-02,2.000000e-05,1\n"
	             "0.02,box2d,row5,0.008,1.500000e-02,3.000000e-04,15\n"
	             "0.005,thesis,row3,0.004,4.000000e-03,3.500000e-05,1\n"
	             "0.005,box2d,row8,0.004,4.900000e-03,6.000000e-04,17.1429\n"
	             "0.0035,thesis,row2,0.004,3.000000e-03,4.000000e-05,1\n"
	             "0.0035,box2d,,,,,\n"
	             "0.001,thesis,,,,,\n"
	             "0.001,box2d,,,,,\n");
	free(csv);
	free(eq);
}

/* The Pareto front of accuracy.md, worked out by hand on a table of its
 * own: the rows at the reference step (a backend against itself: error 0,
 * or another setting's round-off) neither join the front nor push a row
 * off it, as in the figure; of the others a row joins when no other is at
 * least as fast and as accurate and better in one. */
static void test_front(void **state)
{
	(void)state;
	/* backend, reference, h (s), err_mean (m), speed (x real time) */
	static const struct {
		const char *backend;
		int reference;
		double h, err, speed;
		int front;
	} t[] = {
	        {"thesis", 0, 0.004, 2e-3, 4e4, 1},     /* fastest */
	        {"thesis", 0, 0.001, 7e-4, 7e3, 1},     /* */
	        {"thesis", 1, 0.000125, 0.0, 300, 0},   /* the reference */
	        {"thesis", 0, 0.000125, 1e-15, 330, 0}, /* another setting at h_ref */
	        {"box2d", 0, 0.004, 5e-3, 1e3, 0},      /* slower and worse than row 0 */
	        {"box2d", 0, 0.00025, 1.2e-4, 50, 1},   /* off the front only by rows 2, 3 */
	        {"box2d", 0, 0.0005, 2.2e-4, 40, 0},    /* slower and worse than row 5 */
	};
	enum { N = sizeof t / sizeof t[0] };
	bsim_accuracy_row rows[N];
	memset(rows, 0, sizeof rows);
	for (int i = 0; i < N; i++) {
		rows[i].backend = t[i].backend;
		snprintf(rows[i].setting, sizeof rows[i].setting, "row%d", i);
		rows[i].reference = t[i].reference;
		rows[i].h = t[i].h;
		rows[i].err_mean = t[i].err;
		rows[i].speed = t[i].speed;
		rows[i].cpu_cost = 1.0 / t[i].speed;
	}
	bsim_accuracy_result r = {.n = N, .rows = rows};
	bsim_accuracy_config cfg = bsim_accuracy_config_default();
	cfg.n_targets = 0;
	assert_true(cfg.h_ref == 0.000125);
	const char *dir = bsim_test_dir("accuracy_front");
	char path[1100];
	snprintf(path, sizeof path, "%s/accuracy.md", dir);
	bsim_error err;
	assert_int_equal(bsim_accuracy_write_md(path, &r, &cfg, "hand-made", &err), BSIM_OK);
	char *md = bsim_test_read(path);
	assert_non_null(md);
	const char *front = strstr(md, "## Pareto front");
	assert_non_null(front);
	for (int i = 0; i < N; i++) {
		/* the row in the table, ending in its mark; and in the front's list */
		char line[128];
		snprintf(line, sizeof line, "| %s | row%d%s |", t[i].backend, i,
		         t[i].reference ? " (ref)" : "");
		const char *row = strstr(md, line);
		assert_non_null(row);
		const char *eol = strchr(row, '\n');
		assert_non_null(eol);
		int marked = eol[-3] == '*';
		snprintf(line, sizeof line, "| %s | row%d |", t[i].backend, i);
		int listed = strstr(front, line) != NULL;
		if (marked != t[i].front || listed != t[i].front)
			fail_msg("row %d: marked %d, listed %d, by hand %d", i, marked, listed,
			         t[i].front);
	}
	free(md);
}

static void test_bad_targets(void **state)
{
	(void)state;
	bsim_accuracy_row rows[N_ROWS];
	bsim_accuracy_result r;
	synthetic(&r, rows);
	bsim_accuracy_equal *eq;
	int n;
	bsim_error err;
	const double zero[] = {0.0}, nan[] = {NAN};
	assert_int_equal(bsim_accuracy_equal_error(&r, zero, 1, &eq, &n, &err), BSIM_EINPUT);
	assert_int_equal(bsim_accuracy_equal_error(&r, nan, 1, &eq, &n, &err), BSIM_EINPUT);
	assert_int_equal(
	        bsim_accuracy_equal_error(&r, zero, BSIM_ACCURACY_TARGETS_MAX + 1, &eq, &n, &err),
	        BSIM_EINPUT);
	/* An empty study has no picks. */
	bsim_accuracy_result empty = {0};
	const double t[] = {0.01};
	assert_int_equal(bsim_accuracy_equal_error(&empty, t, 1, &eq, &n, &err), BSIM_OK);
	assert_int_equal(n, 0);
	assert_null(eq);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_selection),
	        cmocka_unit_test(test_bad_targets),
	        cmocka_unit_test(test_front),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
