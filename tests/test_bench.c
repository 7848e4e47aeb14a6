/* beamsim bench's figures read against what they must be:
 *   - Box2D 2.4.1 reads its clock, for its b2Profile, twice for the step and
 *     twice each for collide, solve, the broad phase and continuous
 *     collision (b2_world.cpp) and seven times per island (b2_island.cpp):
 *     10 + 7 k reads a step with k = 1 .. 3 islands for the gate's body and
 *     two beams, so between 17 and 31; the thesis backend never reads it;
 *   - taking that time out of Box2D's lowers the ratio, by its share;
 *   - free flight runs every trial to its last step (trials x max_steps);
 *   - --repeat N gives N one-thread runs and the median of them;
 *   - the paired ratios, by wall and by CPU time, are the medians of theirs;
 *   - --callgrind's measures (bench --measure) run the steps they count:
 *     lattice trials of 1000 steps each, free flight and the minimal loop
 *     trials x max_steps. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "support.h"

static char *bench_json(const char *name, const char *backend, const char *vs, const char *repeat)
{
	const char *dir = bsim_test_dir(name);
	char json[1200];
	snprintf(json, sizeof json, "%s/bench.json", dir);
	char h1[1200];
	snprintf(h1, sizeof h1, "%s", bsim_test_src("configs/thesis/h1_symmetric.yaml"));
	const char *argv[] = {"bench",     "--experiment", h1,     "--trials", "2",
	                      "--backend", backend,        "--vs", vs,         "--repeat",
	                      repeat,      "--json",       json,   NULL};
	char *out = NULL, *err = NULL;
	int rc = bsim_test_cli(argv, &out, &err);
	if (rc != 0)
		fail_msg("bench exited %d: %s", rc, err);
	free(out);
	free(err);
	char *text = bsim_test_read(json);
	assert_non_null(text);
	return text;
}

/* The array name of five positive ratios in vs, and median the middle one. */
static void pairs_median(const char *vs, const char *name, const char *median)
{
	char key[64];
	snprintf(key, sizeof key, "\"%s\": [", name);
	const char *r = strstr(vs, key);
	assert_non_null(r);
	r += strlen(key);
	double ratio[5];
	for (int i = 0; i < 5; i++) {
		char *end;
		ratio[i] = strtod(r, &end);
		assert_true(end != r && ratio[i] > 0.0);
		r = end + strspn(end, ", ");
	}
	assert_int_equal(*r, ']');
	double paired = bsim_test_json_number(vs, median);
	int under = 0, over = 0;
	for (int i = 0; i < 5; i++) {
		under += ratio[i] < paired;
		over += ratio[i] > paired;
	}
	assert_true(under <= 2 && over <= 2);
}

static void box2d_reads_its_clock(void **state)
{
	(void)state;
	char *j = bench_json("bench_thesis", "thesis", "box2d", "3");
	const char *vs = strstr(j, "\"vs\": {");
	assert_non_null(vs);
	double per_step = bsim_test_json_number(vs, "clock_reads_per_step");
	assert_true(per_step >= 17.0 && per_step <= 31.0);
	double share = bsim_test_json_number(vs, "clock_share");
	assert_true(share > 0.0 && share < 1.0);
	double with = bsim_test_json_number(vs, "speedup_per_trial");
	double without = bsim_test_json_number(vs, "speedup_per_trial_without_clock");
	assert_true(fabs(without - with * (1.0 - share)) <= 1e-9 * with);

	/* five interleaved pairs (the default): ratio_paired is the median of
	 * their wall-time ratios, ratio_paired_cpu of their CPU-time ones */
	assert_int_equal((int)bsim_test_json_number(vs, "pairs"), 5);
	pairs_median(vs, "pair_ratios", "ratio_paired");
	pairs_median(vs, "pair_ratios_cpu", "ratio_paired_cpu");

	/* free flight: every trial to its last step, 3000 of them */
	const char *ff = strstr(j, "\"free_flight\": {");
	assert_non_null(ff);
	double trials = bsim_test_json_number(ff, "trials"),
	       steps = bsim_test_json_number(ff, "steps");
	assert_true(trials > 0 && steps == 3000.0 * trials);
	assert_true(bsim_test_json_number(ff, "ns_per_step") > 0.0 &&
	            bsim_test_json_number(ff, "minimal_ns_per_step") > 0.0);

	/* three one-thread runs, the median theirs */
	assert_int_equal((int)bsim_test_json_number(j, "repeat"), 3);
	double wall[3];
	const char *p = strstr(j, "\"runs\": [");
	assert_non_null(p);
	for (int i = 0; i < 3; i++) {
		p = strstr(p, "\"threads\": 1,");
		assert_non_null(p);
		wall[i] = bsim_test_json_number(p, "wall_seconds");
		p++;
	}
	double median = bsim_test_json_number(strstr(j, "\"one_thread_median\""), "wall_seconds");
	int below = 0, above = 0;
	for (int i = 0; i < 3; i++) {
		below += wall[i] < median;
		above += wall[i] > median;
	}
	assert_true(below <= 1 && above <= 1);
	free(j);
}

/* The other way round: the thesis backend as the second one reads no clock. */
static void thesis_reads_none(void **state)
{
	(void)state;
	char *j = bench_json("bench_box2d", "box2d", "thesis", "1");
	const char *vs = strstr(j, "\"vs\": {");
	assert_non_null(vs);
	assert_true(bsim_test_json_number(vs, "clock_reads") == 0.0);
	assert_true(bsim_test_json_number(vs, "clock_share") == 0.0);
	free(j);
}

/* The steps bench --measure WHAT --trials T prints. */
static long measure_steps(const char *what, const char *trials)
{
	char h1[1200];
	snprintf(h1, sizeof h1, "%s", bsim_test_src("configs/thesis/h1_symmetric.yaml"));
	const char *argv[] = {"bench", "--measure",    what, "--trials",
	                      trials,  "--experiment", h1,   NULL};
	char *out = NULL, *err = NULL;
	int rc = bsim_test_cli(argv, &out, &err);
	if (rc != 0)
		fail_msg("bench --measure %s exited %d: %s", what, rc, err);
	long steps = -1;
	assert_int_equal(sscanf(out, "steps %ld", &steps), 1);
	free(out);
	free(err);
	return steps;
}

static void measures_count_their_steps(void **state)
{
	(void)state;
	assert_int_equal(measure_steps("lattice:5", "3"), 3000);
	assert_int_equal(measure_steps("lattice:33", "2"), 2000);
	long free_steps = measure_steps("free", "1");
	assert_true(free_steps > 0 && free_steps % 3000 == 0);
	assert_int_equal(measure_steps("minimal", "1"), free_steps);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(box2d_reads_its_clock),
	        cmocka_unit_test(thesis_reads_none),
	        cmocka_unit_test(measures_count_their_steps),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
