/* Grid axes from the command line (sweep --grid KEY=V1,V2 or KEY=A:B:STEP,
 * numbers or a key's words) against the same axes written into the
 * experiment file: the file edited by hand is the independent truth, byte
 * for byte; the stored run repeats
 * under beamsim regress; bad --grid values are input errors naming the
 * option; and plot --select lists every axis of a 3-axis sweep. Runs the
 * real program. */
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

/* The experiment the --grid options act on: 2 x 2 groups, shortened
 * trials (the physics is not under test here, only which groups run). */
static const char *experiment_text(char *text, size_t size, const char *set_lines,
                                   const char *grid_lines)
{
	snprintf(text, size,
	         "scene: %s\n"
	         "trials: 4\n"
	         "seed: 5\n"
	         "set:\n"
	         "  integration.max_steps: 600\n"
	         "%s"
	         "grid:\n"
	         "%s",
	         bsim_test_src("configs/thesis/gate.yaml"), set_lines, grid_lines);
	return text;
}

static const char *const base_grid = "  effects.propulsion.force: [7, 9]\n"
                                     "  effects.random_force.magnitude: [10, 40]\n";

static int setup(void **state)
{
	(void)state;
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("grid"));
	return 0;
}

static char *read_in(const char *out, const char *file)
{
	char *text = bsim_test_read(bsim_test_join(out, file));
	if (!text)
		fail_msg("cannot read %s/%s", out, file);
	return text;
}

/* summary.json without its "wall_seconds" line, the one field that
 * measures the machine rather than the run. */
static char *summary_without_wall(const char *out)
{
	char *json = read_in(out, "summary.json");
	char *p = strstr(json, "\"wall_seconds\"");
	assert_non_null(p);
	char *start = p, *end = strchr(p, '\n');
	assert_non_null(end);
	while (start > json && start[-1] != '\n')
		start--;
	memmove(start, end + 1, strlen(end + 1) + 1);
	return json;
}

static void run_ok(const char *const argv[])
{
	char *err = NULL;
	int rc = bsim_test_cli(argv, NULL, &err);
	if (rc != 0)
		fail_msg("beamsim %s exited %d: %s", argv[0], rc, err ? err : "");
	free(err);
}

/* --grid replacing an axis (the random force's), adding two (a decimal
 * range and a list), one of them on a field the file's set: fixes, gives
 * the trials of the file edited to that grid (the set: line removed), at
 * the same path, byte for byte; the stored experiment holds that grid and
 * beamsim regress repeats the run with no trial changed. */
static void test_grid_equals_edited_file(void **state)
{
	(void)state;
	char text[4096];
	const char *exp = bsim_test_join(dir, "exp.yaml");
	char exp_path[1200], out_cli[1200], out_file[1200], out_regress[1200];
	snprintf(exp_path, sizeof exp_path, "%s", exp);
	snprintf(out_cli, sizeof out_cli, "%s", bsim_test_join(dir, "by_cli"));
	snprintf(out_file, sizeof out_file, "%s", bsim_test_join(dir, "by_file"));
	snprintf(out_regress, sizeof out_regress, "%s", bsim_test_join(dir, "regress"));
	bsim_test_write(
	        dir, "exp.yaml",
	        experiment_text(text, sizeof text, "  beams.1.stiffness: 500\n", base_grid));
	const char *by_cli[] = {"sweep",
	                        exp_path,
	                        "--out",
	                        out_cli,
	                        "--quiet",
	                        "--grid",
	                        "effects.random_force.magnitude=0.1:0.5:0.1",
	                        "--grid",
	                        "beams.0.stiffness=100,250",
	                        "--grid",
	                        "beams.1.stiffness=300:500:200",
	                        NULL};
	run_ok(by_cli);

	/* The same grid written by hand: the replaced axis where it stood,
	 * the new ones after it in command-line order, 0.1 + 2 x 0.1 as 0.3. */
	bsim_test_write(dir, "exp.yaml",
	                experiment_text(text, sizeof text, "",
	                                "  effects.propulsion.force: [7, 9]\n"
	                                "  effects.random_force.magnitude: [0.1, 0.2, 0.3, "
	                                "0.4, 0.5]\n"
	                                "  beams.0.stiffness: [100, 250]\n"
	                                "  beams.1.stiffness: [300, 500]\n"));
	const char *by_file[] = {"sweep", exp_path, "--out", out_file, "--quiet", NULL};
	run_ok(by_file);

	char *a = read_in(out_cli, "trials.csv"), *b = read_in(out_file, "trials.csv");
	assert_string_equal(a, b);
	/* every group of the product ran: 2 x 5 x 2 x 2 groups of 4 trials */
	assert_int_equal(bsim_test_count_lines(a), 1 + 2 * 5 * 2 * 2 * 4);
	assert_non_null(strstr(a, ",effects.propulsion.force,effects.random_force.magnitude,"
	                          "beams.0.stiffness,beams.1.stiffness\n"));
	free(a);
	free(b);
	a = summary_without_wall(out_cli);
	b = summary_without_wall(out_file);
	assert_string_equal(a, b);
	free(a);
	free(b);

	/* The record holds the grid that ran, not the file's. */
	char *stored = read_in(out_cli, "inputs/experiment.yaml");
	assert_non_null(
	        strstr(stored, "effects.random_force.magnitude: [0.1, 0.2, 0.3, 0.4, 0.5]"));
	assert_non_null(strstr(stored, "beams.0.stiffness: [100, 250]"));
	assert_non_null(strstr(stored, "beams.1.stiffness: [300, 500]"));
	assert_null(strstr(stored, "beams.1.stiffness: 500"));
	free(stored);

	const char *regress[] = {"regress", out_cli, "--out", out_regress, NULL};
	char *out = NULL, *err = NULL;
	int rc = bsim_test_cli(regress, &out, &err);
	if (rc != 0)
		fail_msg("beamsim regress exited %d: %s", rc, err ? err : "");
	if (!strstr(out, ": 0 of 160 trials changed"))
		fail_msg("regress said: %s", out);
	free(out);
	free(err);
}

/* A key whose values are words takes them from --grid as from the file:
 * --grid effects.random_force.model=held,ou gives the trials and summary
 * of the file whose grid: lists [held, ou], byte for byte, and the record
 * holds those words. */
static void test_grid_words(void **state)
{
	(void)state;
	char text[4096], exp_path[1200], out_cli[1200], out_file[1200];
	snprintf(exp_path, sizeof exp_path, "%s",
	         bsim_test_write(dir, "words.yaml",
	                         experiment_text(text, sizeof text, "", base_grid)));
	snprintf(out_cli, sizeof out_cli, "%s", bsim_test_join(dir, "words_cli"));
	snprintf(out_file, sizeof out_file, "%s", bsim_test_join(dir, "words_file"));
	const char *by_cli[] = {"sweep",
	                        exp_path,
	                        "--out",
	                        out_cli,
	                        "--quiet",
	                        "--grid",
	                        "effects.random_force.model=held, ou",
	                        NULL};
	run_ok(by_cli);
	bsim_test_write(dir, "words.yaml",
	                experiment_text(text, sizeof text, "",
	                                "  effects.propulsion.force: [7, 9]\n"
	                                "  effects.random_force.magnitude: [10, 40]\n"
	                                "  effects.random_force.model: [held, ou]\n"));
	const char *by_file[] = {"sweep", exp_path, "--out", out_file, "--quiet", NULL};
	run_ok(by_file);
	char *a = read_in(out_cli, "trials.csv"), *b = read_in(out_file, "trials.csv");
	assert_string_equal(a, b);
	assert_int_equal(bsim_test_count_lines(a), 1 + 2 * 2 * 2 * 4);
	/* both values' groups ran, each named by its word */
	assert_non_null(strstr(a, ",held\n"));
	assert_non_null(strstr(a, ",ou\n"));
	free(a);
	free(b);
	a = summary_without_wall(out_cli);
	b = summary_without_wall(out_file);
	assert_string_equal(a, b);
	assert_non_null(strstr(a, "\"effects.random_force.model\": \"ou\""));
	free(a);
	free(b);
	char *stored = read_in(out_cli, "inputs/experiment.yaml");
	assert_non_null(strstr(stored, "effects.random_force.model: [held, ou]"));
	free(stored);
}

/* compare takes --grid too: its pairs and each side's trials equal those
 * of the file edited to the same grid; a --grid given twice for one KEY
 * runs the later values. */
static void test_compare_grid(void **state)
{
	(void)state;
	char text[4096], exp_path[1200], out_cli[1200], out_file[1200];
	snprintf(exp_path, sizeof exp_path, "%s",
	         bsim_test_write(dir, "cmp.yaml",
	                         experiment_text(text, sizeof text, "", base_grid)));
	snprintf(out_cli, sizeof out_cli, "%s", bsim_test_join(dir, "cmp_cli"));
	snprintf(out_file, sizeof out_file, "%s", bsim_test_join(dir, "cmp_file"));
	const char *by_cli[] = {"compare",
	                        exp_path,
	                        "--backends",
	                        "thesis,thesis:integrator=euler",
	                        "--out",
	                        out_cli,
	                        "--quiet",
	                        "--grid",
	                        "effects.propulsion.force=1,2",
	                        "--grid",
	                        "beams.0.stiffness=200:300:50",
	                        "--grid",
	                        "effects.propulsion.force=8",
	                        NULL};
	char *err = NULL;
	int rc = bsim_test_cli(by_cli, NULL, &err);
	if (rc != 0 && rc != 3)
		fail_msg("beamsim compare exited %d: %s", rc, err ? err : "");
	free(err);
	bsim_test_write(dir, "cmp.yaml",
	                experiment_text(text, sizeof text, "",
	                                "  effects.propulsion.force: [8]\n"
	                                "  effects.random_force.magnitude: [10, 40]\n"
	                                "  beams.0.stiffness: [200, 250, 300]\n"));
	const char *by_file[] = {
	        "compare", exp_path, "--backends", "thesis,thesis:integrator=euler",
	        "--out",   out_file, "--quiet",    NULL};
	err = NULL;
	int rc_file = bsim_test_cli(by_file, NULL, &err);
	assert_int_equal(rc_file, rc);
	free(err);
	const char *files[] = {"pairs.csv", "thesis/trials.csv",
	                       "thesis-integrator=euler/trials.csv", NULL};
	for (int i = 0; files[i]; i++) {
		char *a = read_in(out_cli, files[i]), *b = read_in(out_file, files[i]);
		if (strcmp(a, b) != 0)
			fail_msg("compare --grid: %s differs from the edited file's", files[i]);
		free(a);
		free(b);
	}
	char *a = read_in(out_cli, "thesis/trials.csv");
	assert_int_equal(bsim_test_count_lines(a), 1 + 1 * 2 * 3 * 4);
	free(a);
}

/* The values A:B:STEP gives, read back from the stored experiment, against
 * A + i STEP for i = 0, 1, ... while within 1e-9 of a STEP of B, each
 * written in %.10g (the shortest decimal of these sums). */
static void check_range(const char *key, double a, double b, double step, const char *spec)
{
	char text[4096], option[256], out[1200], want[1024];
	snprintf(option, sizeof option, "%s=%s", key, spec);
	snprintf(out, sizeof out, "%s", bsim_test_join(dir, "range"));
	bsim_test_remove(out);
	const char *exp = bsim_test_write(dir, "range.yaml",
	                                  experiment_text(text, sizeof text, "", base_grid));
	char exp_path[1200];
	snprintf(exp_path, sizeof exp_path, "%s", exp);
	const char *argv[] = {"sweep",  exp_path,  "--out",
	                      out,      "--quiet", "--trials",
	                      "1",      "--set",   "integration.max_steps=5",
	                      "--grid", option,    NULL};
	run_ok(argv);
	int k = snprintf(want, sizeof want, "%s: [", key);
	double tol = 1e-9 * (step > 0 ? step : -step);
	for (int i = 0; step > 0 ? a + i * step <= b + tol : a + i * step >= b - tol; i++)
		k += snprintf(want + k, sizeof want - (size_t)k, "%s%.10g", i ? ", " : "",
		              a + i * step);
	snprintf(want + k, sizeof want - (size_t)k, "]");
	char *stored = read_in(out, "inputs/experiment.yaml");
	if (!strstr(stored, want))
		fail_msg("--grid %s: expected \"%s\" in the stored experiment:\n%s", option, want,
		         stored);
	free(stored);
}

static void test_range_expansion(void **state)
{
	(void)state;
	check_range("beams.0.stiffness", 0.1, 0.5, 0.1, "0.1:0.5:0.1");
	check_range("beams.0.stiffness", 0.1, 0.35, 0.05, "0.1:0.35:0.05"); /* B reached */
	check_range("beams.0.stiffness", 0, 1, 0.3, "0:1:0.3");             /* B not reached */
	check_range("beams.0.stiffness", 100, 250, 50, "1e2:2.5e2:50");
	check_range("effects.random_force.magnitude", 0.001, 0.004, 0.001, "1e-3:4e-3:1e-3");
	check_range("effects.propulsion.force", 9, 7, -0.5, "9:7:-0.5"); /* downwards */
	check_range("beams.0.initial_theta", -0.3, 0.3, 0.15, "-0.3:0.3:0.15");
	check_range("beams.0.stiffness", 300, 300, 7, "300:300:7"); /* one value */
}

/* Each bad --grid: exit status 2, a message naming --grid, what it names
 * (named, or the whole text given when NULL) and what was expected; no
 * trial runs. */
static void expect_grid_error_naming(const char *option, const char *named, const char *expected,
                                     const char *limit)
{
	char text[4096], exp_path[1200], out[1200];
	snprintf(exp_path, sizeof exp_path, "%s",
	         bsim_test_write(dir, "err.yaml",
	                         experiment_text(text, sizeof text, "", base_grid)));
	snprintf(out, sizeof out, "%s", bsim_test_join(dir, "err_out"));
	const char *argv[] = {"sweep",   exp_path, "--out", out,
	                      "--quiet", "--grid", option,  limit ? "--limit" : NULL,
	                      limit,     NULL};
	char *o = NULL, *err = NULL;
	int rc = bsim_test_cli(argv, &o, &err);
	/* the message is the first line (a usage error adds "Try ... --help") */
	char first[2048];
	snprintf(first, sizeof first, "%.*s", (int)strcspn(err ? err : "", "\n"), err ? err : "");
	const char *needles[] = {"--grid", named ? named : option, expected, NULL};
	bsim_test_check_input_error(rc, first, needles, 0);
	const char *nl = strchr(err, '\n');
	if (nl && nl[1] != '\0' && !strstr(err, "Try 'beamsim sweep --help'"))
		fail_msg("more than the message: %s", err);
	assert_false(bsim_test_exists(bsim_test_join(out, "trials.csv")));
	free(o);
	free(err);
}

static void expect_grid_error(const char *option, const char *expected, const char *limit)
{
	expect_grid_error_naming(option, NULL, expected, limit);
}

static void test_errors(void **state)
{
	(void)state;
	expect_grid_error_naming("beams.0.stifness=100,200",
	                         "--grid beams.0.stifness=100: ", "unknown key", NULL);
	expect_grid_error("nosuchblock.k=1", "unknown key", NULL);
	expect_grid_error("beams.0.stiffness=", "non-empty list of values", NULL);
	expect_grid_error("beams.0.stiffness=100,,200", "non-empty list", NULL);
	/* a value is judged by the key's scene field, as the file's grid
	 * values are: a word where a number goes, a word the key does not
	 * take (named with the words it takes) */
	expect_grid_error_naming("beams.0.stiffness=100,abc",
	                         "--grid beams.0.stiffness=abc: beams.0.stiffness: ",
	                         "expected a number >= 0, got abc", NULL);
	expect_grid_error_naming("beams.0.stiffness=0x64",
	                         "--grid beams.0.stiffness=0x64: beams.0.stiffness: ",
	                         "expected a number >= 0, got 0x64", NULL);
	expect_grid_error_naming("effects.random_force.model=held,ou,hold",
	                         "--grid effects.random_force.model=hold: "
	                         "effects.random_force.model: expected held",
	                         "ou (Ornstein-Uhlenbeck", NULL);
	expect_grid_error_naming("effects.random_force.model=held,ou,hold",
	                         "--grid effects.random_force.model=hold: ",
	                         "or white (a new value each step), got hold", NULL);
	expect_grid_error("beams.0.stiffness=1:x:1", "three decimal numbers", NULL);
	expect_grid_error("beams.0.stiffness=1:5", "A:B:STEP", NULL);
	expect_grid_error("beams.0.stiffness=100:200:0", "STEP other than 0", NULL);
	expect_grid_error("beams.0.stiffness=200:100:10", "STEP of the sign of B - A", NULL);
	/* a bad value is named with its key, as a --set names itself */
	expect_grid_error_naming("beams.0.stiffness=10,-5,20",
	                         "--grid beams.0.stiffness=-5: ", "expected a number >= 0", NULL);
	/* too many values for the limit groups, given after --grid or before */
	expect_grid_error("beams.0.stiffness=1:100:1", "expected at most 50 values", "groups=50");
	expect_grid_error_naming("beams.0.stiffness=1:20:1", "--grid beams.0.stiffness (20 values)",
	                         "expected at most 50 groups", "groups=50");
}

/* Without KEY= there is no axis to name. */
static void test_error_no_key(void **state)
{
	(void)state;
	expect_grid_error("=100,200", "expected KEY=V1,V2", NULL);
	expect_grid_error("beams.0.stiffness", "expected KEY=V1,V2", NULL);
}

/* --grid of a field --set also fixes: refused, pointing at --grid. */
static void test_set_conflict(void **state)
{
	(void)state;
	char text[4096], exp_path[1200], out[1200];
	snprintf(exp_path, sizeof exp_path, "%s",
	         bsim_test_write(dir, "conf.yaml",
	                         experiment_text(text, sizeof text, "", base_grid)));
	snprintf(out, sizeof out, "%s", bsim_test_join(dir, "conf_out"));
	const char *argv[] = {"sweep",
	                      exp_path,
	                      "--out",
	                      out,
	                      "--quiet",
	                      "--set",
	                      "beams.0.stiffness=300",
	                      "--grid",
	                      "beams.0.stiffness=100,200",
	                      NULL};
	const char *needles[] = {"--set beams.0.stiffness=300", "(--grid beams.0.stiffness)", NULL};
	bsim_test_expect_input_error(argv, needles);
}

/* plot --select on a 3-axis sweep lists all three axes: the selected one
 * with its value, the others with theirs; a key that is no axis is
 * refused with all three named. */
static void test_select_lists_every_axis(void **state)
{
	(void)state;
	char text[4096], exp_path[1200], out[1200], figs[1200];
	snprintf(exp_path, sizeof exp_path, "%s",
	         bsim_test_write(dir, "three.yaml",
	                         experiment_text(text, sizeof text, "", base_grid)));
	snprintf(out, sizeof out, "%s", bsim_test_join(dir, "three"));
	snprintf(figs, sizeof figs, "%s", bsim_test_join(dir, "three_figs"));
	const char *sweep[] = {
	        "sweep", exp_path, "--out", out, "--quiet", "--grid", "beams.0.stiffness=100,300",
	        NULL};
	run_ok(sweep);
	const char *plot[] = {"plot",  out,  "--select", "beams.0.stiffness=300",
	                      "--out", figs, NULL};
	char *o = NULL, *err = NULL;
	int rc = bsim_test_cli(plot, &o, &err);
	if (rc != 0)
		fail_msg("beamsim plot exited %d: %s", rc, err ? err : "");
	const char *lines[] = {"4 of 8 groups selected",
	                       "effects.propulsion.force: 7, 9 (all 2 values)",
	                       "effects.random_force.magnitude: 10, 40 (all 2 values)",
	                       "beams.0.stiffness = 300 (selected of 2 values)", NULL};
	for (int i = 0; lines[i]; i++)
		if (!strstr(o, lines[i]))
			fail_msg("plot --select printed no \"%s\":\n%s", lines[i], o);
	free(o);
	free(err);

	const char *bad[] = {"plot", out, "--select", "k1=300", "--out", figs, "--overwrite", NULL};
	const char *needles[] = {"--select k1=300",
	                         "effects.propulsion.force, effects.random_force.magnitude, "
	                         "beams.0.stiffness",
	                         NULL};
	bsim_test_expect_input_error(bad, needles);
	const char *none[] = {"plot",  out,  "--select",    "beams.0.stiffness=200",
	                      "--out", figs, "--overwrite", NULL};
	const char *values[] = {"beams.0.stiffness has no value 200", "its values: 100, 300", NULL};
	bsim_test_expect_input_error(none, values);
}

/* A --grid axis costs its values' text, not its values times the option's
 * text: 2,000 values of 55 characters (a 112 KB option) sweep, and the
 * stored run and the experiment with the option replay a trial, each in a
 * child whose address space is bounded to 256 MB (RLIMIT_AS), about three
 * times what the sweep needs. With the option's text copied for each of
 * its values (once on the command line, once in the experiment: 450 MB)
 * the sweep ran out of memory (exit 1). Not under AddressSanitizer, whose
 * shadow memory takes terabytes of address space. */
static void test_long_axis_memory(void **state)
{
	(void)state;
#if defined(__SANITIZE_ADDRESS__)
	skip();
#endif
	enum { VALUES = 2000 };
	const size_t size = (size_t)VALUES * 64 + 64;
	char *option = malloc(size);
	assert_non_null(option);
	size_t at = (size_t)snprintf(option, size, "body.mass=");
	for (int i = 1; i <= VALUES; i++)
		at += (size_t)snprintf(option + at, size - at, "%s%d.%050d1", i > 1 ? "," : "", i,
		                       0);
	char text[4096], exp_path[1200], out[1200];
	snprintf(text, sizeof text,
	         "scene: %s\ntrials: 1\nseed: 5\nset:\n  integration.max_steps: 2\n"
	         "grid:\n  effects.propulsion.force: [8]\n",
	         bsim_test_src("configs/thesis/gate.yaml"));
	snprintf(exp_path, sizeof exp_path, "%s", bsim_test_write(dir, "long.yaml", text));
	snprintf(out, sizeof out, "%s", bsim_test_join(dir, "long"));
	bsim_test_remove(out);
	const bsim_test_opts bounded = {.as = 256L << 20};
	const char *sweep[] = {"sweep",     exp_path, "--out",  out,    "--quiet",
	                       "--threads", "1",      "--grid", option, NULL};
	const char *stored[] = {"run", out, "--group", "1999", "--trial", "0", NULL};
	const char *again[] = {"run", exp_path, "--grid", option, "--group", "1999", NULL};
	const char *const *runs[] = {sweep, stored, again};
	for (int k = 0; k < 3; k++) {
		char *err = NULL;
		int rc = bsim_test_cli_with(runs[k], &bounded, NULL, &err);
		if (rc != 0)
			fail_msg("beamsim %s %s in 256 MB of address space: exit %d: %.300s",
			         runs[k][0], runs[k][1], rc, err ? err : "");
		free(err);
	}
	/* the last group holds the last value, as written */
	char last[128];
	snprintf(last, sizeof last, ",%d.%050d1\n", VALUES, 0);
	char *csv = read_in(out, "trials.csv");
	const char *row = strstr(csv, "\n1999,0,");
	assert_non_null(row);
	assert_non_null(strstr(row, last));
	free(csv);
	free(option);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_grid_equals_edited_file),
	        cmocka_unit_test(test_grid_words),
	        cmocka_unit_test(test_compare_grid),
	        cmocka_unit_test(test_range_expansion),
	        cmocka_unit_test(test_errors),
	        cmocka_unit_test(test_error_no_key),
	        cmocka_unit_test(test_set_conflict),
	        cmocka_unit_test(test_select_lists_every_axis),
	        cmocka_unit_test(test_long_axis_memory),
	};
	return cmocka_run_group_tests(tests, setup, NULL);
}
