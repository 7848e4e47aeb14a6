/* beamsim accuracy: (a) the consistency error of the thesis backend falls at
 * order 2 for implicit midpoint and order 1 for semi-implicit Euler in
 * smooth motion (two beams in free damped vibration, no impacts):
 * e(h) / e(h/2) ~ 2^q; (b) the command runs (--quick) and writes a CSV row
 * per (backend, setting, h) of finite numbers and its figure (drawn by
 * gnuplot when it is installed, the script in any case) and equal_error.csv
 * (a line per error target and backend); (c) the errors do
 * not depend on the number of threads. */
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
#include "util/figure.h"
#include "support.h"

/* Two beams of the essay's gate released from 0.3 and -0.2 rad, the body
 * at rest out of reach: smooth motion, no impacts. */
static double vibration_consistency(const char *integrator, double h,
                                    const bsim_accuracy_reference *ref)
{
	bsim_scene s;
	bsim_scene_init_gate(&s, 0.0, 0.0);
	s.beams[0].initial_theta = 0.3;
	s.beams[1].initial_theta = -0.2;
	s.dt = h;
	s.max_steps = (int)lround(2.0 / h);
	bsim_options o = {0};
	char kv[64];
	snprintf(kv, sizeof kv, "integrator=%s", integrator);
	assert_int_equal(bsim_options_add(&o, kv, NULL), BSIM_OK);
	double mean, max;
	bsim_error err;
	int rc = bsim_accuracy_consistency(ref, &s, bsim_test_backend("thesis"), &o, 1, 0.064, 8,
	                                   &mean, &max, &err);
	if (rc)
		print_error("%s\n", err.msg);
	assert_int_equal(rc, BSIM_OK);
	bsim_scene_free(&s);
	return mean;
}

static void test_consistency_order(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 0.0, 0.0);
	s.beams[0].initial_theta = 0.3;
	s.beams[1].initial_theta = -0.2;
	s.dt = 0.000125;
	s.max_steps = 16000; /* 2 s */
	bsim_accuracy_reference ref;
	bsim_error err;
	assert_int_equal(bsim_accuracy_reference_run(&ref, &s, bsim_test_backend("thesis"), NULL, 1,
	                                             0.016, &err),
	                 BSIM_OK);
	assert_true(ref.n > 100);
	double m2 = vibration_consistency("midpoint", 0.002, &ref);
	double m1 = vibration_consistency("midpoint", 0.001, &ref);
	double e2 = vibration_consistency("euler", 0.002, &ref);
	double e1 = vibration_consistency("euler", 0.001, &ref);
	print_message("midpoint %.3g -> %.3g (ratio %.2f), euler %.3g -> %.3g (ratio %.2f)\n", m2,
	              m1, m2 / m1, e2, e1, e2 / e1);
	assert_true(m1 > 0 && e1 > 0);
	assert_true(m2 / m1 > 2.5);                  /* order 2: 4 */
	assert_true(e2 / e1 > 1.6 && e2 / e1 < 2.5); /* order 1: 2 */
	assert_true(m1 < e1);
	bsim_accuracy_reference_free(&ref);
	bsim_scene_free(&s);
}

/* Counts CSV fields that are not finite numbers in columns 3.. of a row. */
static int csv_check_row(char *line, int *fields)
{
	int bad = 0, i = 0;
	char *save = NULL;
	for (char *t = strtok_r(line, ",", &save); t; t = strtok_r(NULL, ",", &save), i++) {
		if (i < 2)
			continue;
		char *end;
		double v = strtod(t, &end);
		bad += end == t || (*end && *end != '\n') || !isfinite(v);
	}
	*fields = i;
	return bad;
}

static char *run_quick(const char *name, const char *backends, const char *threads)
{
	char dir[1024];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir(name));
	char scene[1024];
	snprintf(scene, sizeof scene, "%s", bsim_test_src("configs/thesis/gate.yaml"));
	const char *argv[] = {"accuracy",   "--quick",
	                      "--out",      dir,
	                      "--scene",    scene,
	                      "--set",      "effects.propulsion.force=9",
	                      "--set",      "effects.random_force.magnitude=20",
	                      "--backends", backends,
	                      "--threads",  threads,
	                      NULL};
	char *err = NULL;
	int status = bsim_test_cli(argv, NULL, &err);
	if (status != 0)
		print_error("%s\n", err ? err : "");
	free(err);
	assert_int_equal(status, 0);
	char path[1100];
	snprintf(path, sizeof path, "%s/accuracy.gp", dir);
	char *gp = bsim_test_read(path);
	assert_non_null(gp);
	free(gp);
	if (bsim_figure_available()) {
		snprintf(path, sizeof path, "%s/accuracy.png", dir);
		char *png = bsim_test_read(path);
		assert_non_null(png);
		assert_memory_equal(png, "\x89PNG\r\n\x1a\n", 8);
		free(png);
	}
	snprintf(path, sizeof path, "%s/accuracy.mat", dir); /* its twin, as test_matlab checks */
	char *mat = bsim_test_read(path);
	assert_non_null(mat);
	free(mat);
	snprintf(path, sizeof path, "%s/accuracy.md", dir);
	char *md = bsim_test_read(path);
	assert_non_null(md);
	assert_non_null(strstr(md, "| backend |"));
	assert_non_null(strstr(md, "## At equal error"));
	free(md);
	/* equal_error.csv: a line per default target and backend (its selection
	 * is test_accuracy_equal's). */
	snprintf(path, sizeof path, "%s/equal_error.csv", dir);
	char *eq = bsim_test_read(path);
	assert_non_null(eq);
	assert_non_null(strstr(eq, "ratio_equal_error"));
	int n_backends = 1 + (strchr(backends, ',') != NULL);
	assert_int_equal(bsim_test_count_lines(eq), 1 + 5 * n_backends);
	free(eq);
	snprintf(path, sizeof path, "%s/accuracy.csv", dir);
	char *csv = bsim_test_read(path);
	assert_non_null(csv);
	return csv;
}

static void test_cli_quick(void **state)
{
	(void)state;
	char *csv = run_quick("quick", "thesis,box2d", "2");
	int rows = 0, thesis = 0, box2d = 0;
	char *save = NULL;
	char *line = strtok_r(csv, "\n", &save);
	assert_non_null(strstr(line, "err_mean_m"));
	while ((line = strtok_r(NULL, "\n", &save))) {
		thesis += strncmp(line, "thesis,", 7) == 0;
		box2d += strncmp(line, "box2d,", 6) == 0;
		int fields;
		char copy[512];
		snprintf(copy, sizeof copy, "%s", line);
		assert_int_equal(csv_check_row(copy, &fields), 0);
		assert_int_equal(fields, 17);
		rows++;
	}
	/* 6 steps (0.016 .. 0.0005 s) x 4 thesis and 12 box2d settings. */
	assert_int_equal(thesis, 4 * 6);
	assert_int_equal(box2d, 12 * 6);
	assert_int_equal(rows, 96);
	free(csv);
}

/* Each row up to p_err (its first 10 columns): timings differ run to run. */
static char *without_timings(const char *csv)
{
	char *out = malloc(strlen(csv) + 1);
	size_t k = 0;
	int commas = 0;
	for (const char *c = csv; *c; c++) {
		if (*c == '\n') {
			commas = 0;
			out[k++] = '\n';
			continue;
		}
		commas += *c == ',';
		if (commas < 10)
			out[k++] = *c;
	}
	out[k] = '\0';
	return out;
}

static void test_threads_independent(void **state)
{
	(void)state;
	char *one = run_quick("threads1", "thesis", "1");
	char *two = run_quick("threads2", "thesis", "2");
	char *a = without_timings(one), *b = without_timings(two);
	assert_string_equal(a, b);
	free(a);
	free(b);
	free(one);
	free(two);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_consistency_order),
	        cmocka_unit_test(test_cli_quick),
	        cmocka_unit_test(test_threads_independent),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
