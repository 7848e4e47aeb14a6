/* docs/model.md check 6 / docs/files.md "Experiment file (YAML)": the same
 * experiment and seed give byte-identical trials.csv and the same
 * summary.json (but for the wall time) whatever the number of threads, on
 * every backend of the registry; another seed gives other trials. Runs the
 * real program. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "beamsim/backend.h"
#include "support.h"

static char dir[1024];
static char experiment[1100];

static int setup(void **state)
{
	(void)state;
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
	return 0;
}

/* Runs the sweep into dir/name on backend (NULL: the default); returns
 * nothing, asserts success. */
static void sweep_on(const char *name, const char *threads, const char *seed, const char *backend)
{
	char out[1200];
	snprintf(out, sizeof out, "%s/%s", dir, name);
	const char *with_seed[] = {"sweep", experiment, "--out",  out,  "--threads",
	                           threads, "--quiet",  "--seed", seed, NULL};
	const char *without[] = {"sweep", experiment, "--out",     out,     "--threads",
	                         threads, "--quiet",  "--backend", backend, NULL};
	if (!backend)
		without[7] = NULL;
	char *err = NULL;
	int status = bsim_test_cli(seed ? with_seed : without, NULL, &err);
	if (status != 0)
		fail_msg("beamsim sweep --threads %s exited %d: %s", threads, status,
		         err ? err : "");
	free(err);
}

static void sweep(const char *name, const char *threads, const char *seed)
{
	sweep_on(name, threads, seed, NULL);
}

static char *read_out(const char *name, const char *file)
{
	char path[1300];
	snprintf(path, sizeof path, "%s/%s/%s", dir, name, file);
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
	(void)state;
	sweep("t1", "1", NULL);
	sweep("t2", "2", NULL);
	sweep("t3", "3", NULL);
	char *csv1 = read_out("t1", "trials.csv"), *csv2 = read_out("t2", "trials.csv");
	char *csv3 = read_out("t3", "trials.csv");
	assert_int_equal(strlen(csv1), strlen(csv2));
	assert_string_equal(csv1, csv2);
	assert_string_equal(csv1, csv3);
	/* Every trial is there: header + 4 groups x 20 trials. */
	int lines = 0;
	for (const char *p = csv1; *p; p++)
		lines += *p == '\n';
	assert_int_equal(lines, 1 + 4 * 20);

	char *sum1 = read_out("t1", "summary.json"), *sum2 = read_out("t2", "summary.json");
	drop_wall_line(sum1);
	drop_wall_line(sum2);
	assert_string_equal(sum1, sum2);
	free(csv1);
	free(csv2);
	free(csv3);
	free(sum1);
	free(sum2);
}

/* Every backend of the registry: one thread or two, the same trials.csv. */
static void test_threads_do_not_matter_any_backend(void **state)
{
	(void)state;
	const bsim_backend *const *list = bsim_backend_list();
	for (int k = 0; list[k]; k++) {
		char one[64], two[64];
		snprintf(one, sizeof one, "%s_t1", list[k]->name);
		snprintf(two, sizeof two, "%s_t2", list[k]->name);
		sweep_on(one, "1", NULL, list[k]->name);
		sweep_on(two, "2", NULL, list[k]->name);
		char *a = read_out(one, "trials.csv"), *b = read_out(two, "trials.csv");
		if (strcmp(a, b) != 0)
			fail_msg("%s: trials.csv differs between 1 and 2 threads", list[k]->name);
		free(a);
		free(b);
	}
}

static void test_same_seed_same_result(void **state)
{
	(void)state;
	sweep("again", "2", "11");
	char *a = read_out("t1", "trials.csv"), *b = read_out("again", "trials.csv");
	assert_string_equal(a, b);
	free(a);
	free(b);
}

static void test_seed_matters(void **state)
{
	(void)state;
	sweep("s12", "2", "12");
	char *a = read_out("t1", "trials.csv"), *b = read_out("s12", "trials.csv");
	assert_string_not_equal(a, b);
	free(a);
	free(b);
	char *sum = read_out("s12", "summary.json");
	assert_non_null(strstr(sum, "\"seed\": 12,"));
	free(sum);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_threads_do_not_matter),
	        cmocka_unit_test(test_threads_do_not_matter_any_backend),
	        cmocka_unit_test(test_same_seed_same_result),
	        cmocka_unit_test(test_seed_matters),
	};
	return cmocka_run_group_tests(tests, setup, NULL);
}
