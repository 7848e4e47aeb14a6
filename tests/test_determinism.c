/* docs/model.md check 6 / docs/files.md "Experiment file (YAML)": the same
 * experiment and seed give byte-identical trials.csv and the same
 * summary.json (but for the wall time) whatever the number of threads;
 * another seed gives other trials. Runs the real program, on every backend
 * of the registry (--backend). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "support.h"

static char dir[1024];
static char experiment[1100];

/* Writes the experiment once. */
static void prepare(void)
{
	if (experiment[0])
		return;
	char text[2048];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("determinism"));
	/* 2 x 2 groups of 20 trials; shortened trials keep it quick while
	 * still letting traversals, side exits and stuck runs all happen. */
	snprintf(text, sizeof text,
	         "scene: %s\n"
	         "trials: 20\n"
	         "seed: 11\n"
	         "set:\n"
	         "  integration.max_steps: 1500\n"
	         "grid:\n"
	         "  effects.propulsion.force: [6, 9]\n"
	         "  effects.random_force.magnitude: [10, 40]\n",
	         bsim_test_src("configs/thesis/gate.yaml"));
	snprintf(experiment, sizeof experiment, "%s", bsim_test_write(dir, "exp.yaml", text));
}

/* Runs the sweep on backend b into dir/B-name; returns nothing, asserts
 * success. */
static void sweep(const bsim_backend *b, const char *name, const char *threads, const char *seed)
{
	char out[1200];
	prepare();
	snprintf(out, sizeof out, "%s/%s-%s", dir, b->name, name);
	const char *with_seed[] = {"sweep",   experiment,  "--out", out,      "--threads", threads,
	                           "--quiet", "--backend", b->name, "--seed", seed,        NULL};
	const char *without[] = {"sweep", experiment, "--out",     out,     "--threads",
	                         threads, "--quiet",  "--backend", b->name, NULL};
	char *err = NULL;
	int status = bsim_test_cli(seed ? with_seed : without, NULL, &err);
	if (status != 0)
		fail_msg("beamsim sweep --backend %s --threads %s exited %d: %s", b->name, threads,
		         status, err ? err : "");
	free(err);
}

static char *read_out(const bsim_backend *b, const char *name, const char *file)
{
	char path[1300];
	snprintf(path, sizeof path, "%s/%s-%s/%s", dir, b->name, name, file);
	char *text = bsim_test_read(path);
	if (!text)
		fail_msg("cannot read %s", path);
	return text;
}

/* Removes the line holding "wall_seconds", the one field that measures
 * the machine rather than the model. */
static void drop_wall_line(char *json)
{
	char *p = strstr(json, "\"wall_seconds\"");
	assert_non_null(p);
	char *start = p, *end = strchr(p, '\n');
	assert_non_null(end);
	while (start > json && start[-1] != '\n')
		start--;
	memmove(start, end + 1, strlen(end + 1) + 1);
}

static void test_threads_do_not_matter(void **state)
{
	const bsim_backend *b = *state;
	sweep(b, "t1", "1", NULL);
	sweep(b, "t2", "2", NULL);
	sweep(b, "t3", "3", NULL);
	char *csv1 = read_out(b, "t1", "trials.csv"), *csv2 = read_out(b, "t2", "trials.csv");
	char *csv3 = read_out(b, "t3", "trials.csv");
	assert_int_equal(strlen(csv1), strlen(csv2));
	assert_string_equal(csv1, csv2);
	assert_string_equal(csv1, csv3);
	/* Every trial is there: header + 4 groups x 20 trials. */
	int lines = 0;
	for (const char *p = csv1; *p; p++)
		lines += *p == '\n';
	assert_int_equal(lines, 1 + 4 * 20);

	char *sum1 = read_out(b, "t1", "summary.json"), *sum2 = read_out(b, "t2", "summary.json");
	drop_wall_line(sum1);
	drop_wall_line(sum2);
	assert_string_equal(sum1, sum2);
	free(csv1);
	free(csv2);
	free(csv3);
	free(sum1);
	free(sum2);
}

static void test_same_seed_same_result(void **state)
{
	const bsim_backend *be = *state;
	sweep(be, "again", "2", "11");
	char *a = read_out(be, "t1", "trials.csv"), *b = read_out(be, "again", "trials.csv");
	assert_string_equal(a, b);
	free(a);
	free(b);
}

static void test_seed_matters(void **state)
{
	const bsim_backend *be = *state;
	sweep(be, "s12", "2", "12");
	char *a = read_out(be, "t1", "trials.csv"), *b = read_out(be, "s12", "trials.csv");
	assert_string_not_equal(a, b);
	free(a);
	free(b);
	char *sum = read_out(be, "s12", "summary.json");
	assert_non_null(strstr(sum, "\"seed\": 12,"));
	free(sum);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_threads_do_not_matter),
	        cmocka_unit_test(test_same_seed_same_result),
	        cmocka_unit_test(test_seed_matters),
	};
	return bsim_test_run_per_backend("determinism", tests, sizeof tests / sizeof tests[0]);
}
