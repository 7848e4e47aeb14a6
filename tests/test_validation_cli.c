/* Bad scenes and experiments through the real program: each error kind exits
 * with status 2 and one line on stderr naming the file (or the --set), the
 * line, the field and what was expected; a failed sweep writes nothing. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"

/* A valid gate body and beam list that the bad files below build on. */
#define BODY "body: { mass: 1, radius: 10 }\n"
#define BEAMS                                                                                      \
	"beams:\n"                                                                                 \
	"  - { pivot: [-25, 30], length: 25, mass: 0.1, stiffness: 400 }\n"                        \
	"  - { pivot: [25, 30], rest_angle_deg: 180, length: 25, mass: 0.1,\n"                     \
	"      stiffness: 400 }\n"

/* beamsim run on a scene file with the given text. */
static void run_bad_scene(const char *name, const char *text, const char *const needles[])
{
	const char *dir = bsim_test_dir(name);
	char file[64];
	snprintf(file, sizeof file, "%s.yaml", name);
	char path[1200];
	snprintf(path, sizeof path, "%s", bsim_test_write(dir, file, text));
	const char *argv[] = {"run", path, NULL};
	bsim_test_expect_input_error(argv, needles);
}

static void unknown_key(void **state)
{
	(void)state;
	const char *text = BODY "beams:\n"
	                        "  - pivot: [-25, 30]\n"
	                        "    length: 25\n"
	                        "    mass: 0.1\n"
	                        "    stifness: 400\n";
	const char *needles[] = {"unknown_key.yaml:6:5: ", "beams.0.stifness",
	                         "unknown key (expected one of pivot,", NULL};
	run_bad_scene("unknown_key", text, needles);
}

static void unknown_top_level_key(void **state)
{
	(void)state;
	const char *needles[] = {"top_key.yaml:7:1: ", "bodyy",
	                         "unknown key (expected one of name, body", NULL};
	run_bad_scene("top_key", BODY BEAMS "\nbodyy: 3\n", needles);
}

static void string_for_number(void **state)
{
	(void)state;
	const char *needles[] = {"wrong_type.yaml:1:15: ", "body.mass",
	                         "expected a positive number, got heavy", NULL};
	run_bad_scene("wrong_type", "body: { mass: heavy, radius: 10 }\n" BEAMS, needles);
}

static void mapping_for_list(void **state)
{
	(void)state;
	const char *needles[] = {"map_list.yaml:2:", "beams", "expected a non-empty list of beams",
	                         "got a mapping", NULL};
	run_bad_scene("map_list", BODY "beams: { pivot: [0, 30] }\n", needles);
}

static void three_element_pivot(void **state)
{
	(void)state;
	const char *text =
	        BODY "beams:\n"
	             "  - { pivot: [-25, 30, 0], length: 25, mass: 0.1, stiffness: 1 }\n";
	const char *needles[] = {"pivot3.yaml:3:", "beams.0.pivot", "expected a list of 2 numbers",
	                         "got a list of 3 items", NULL};
	run_bad_scene("pivot3", text, needles);
}

static void non_integer_max_steps(void **state)
{
	(void)state;
	const char *needles[] = {"steps.yaml:6:", "integration.max_steps",
	                         "expected a positive integer, got 2.5", NULL};
	run_bad_scene("steps", BODY BEAMS "integration: { max_steps: 2.5 }\n", needles);
}

/* A trial's length given twice in one file, as steps and in seconds, that
 * disagree: exit 2 naming the file, line, field and both values; likewise
 * the per-gate limit. */
static void inconsistent_duration(void **state)
{
	(void)state;
	const char *needles[] = {"duration.yaml:6:38: ", "integration.max_steps",
	                         "expected 3000 (integration.duration 12 s at integration.dt "
	                         "0.004 s; give one of the two), got 2999",
	                         NULL};
	run_bad_scene("duration",
	              BODY BEAMS "integration: { dt: 0.004, max_steps: 2999, duration: 12 }\n",
	              needles);
	const char *gate[] = {"gate_time.yaml:7:28: ", "termination.gate_steps",
	                      "expected 2500 (termination.gate_time 10 s at integration.dt "
	                      "0.004 s; give one of the two), got 3000",
	                      NULL};
	run_bad_scene("gate_time",
	              BODY BEAMS "integration: { duration: 12 }\n"
	                         "termination: { gate_steps: 3000, gate_time: 10 }\n",
	              gate);
}

static void nan_value(void **state)
{
	(void)state;
	const char *needles[] = {"nan.yaml:6:", "contact.restitution",
	                         "expected a finite number, got .nan", NULL};
	run_bad_scene("nan", BODY BEAMS "contact: { restitution: .nan }\n", needles);
}

static void inf_value(void **state)
{
	(void)state;
	const char *text = BODY "beams:\n"
	                        "  - { pivot: [-25, 30], length: 25, mass: 0.1, stiffness: 1,\n"
	                        "      damping: -.inf }\n";
	const char *needles[] = {"inf.yaml:4:16: ", "beams.0.damping",
	                         "expected a finite number, got -.inf", NULL};
	run_bad_scene("inf", text, needles);
	const char *needles2[] = {"inftext.yaml:1:", "body.radius", "expected a finite number",
	                          "got inf", NULL};
	run_bad_scene("inftext", "body: { mass: 1, radius: inf }\n" BEAMS, needles2);
}

static void non_positive_mass(void **state)
{
	(void)state;
	const char *needles[] = {"mass.yaml:1:15: ", "body.mass",
	                         "expected a positive number, got 0", NULL};
	run_bad_scene("mass", "body: { mass: 0, radius: 10 }\n" BEAMS, needles);
}

static void non_positive_length(void **state)
{
	(void)state;
	const char *text = BODY "beams:\n"
	                        "  - { pivot: [-25, 30], length: -25, mass: 0.1, stiffness: 1 }\n";
	const char *needles[] = {"length.yaml:3:", "beams.0.length",
	                         "expected a positive number, got -25", NULL};
	run_bad_scene("length", text, needles);
}

static void non_positive_dt(void **state)
{
	(void)state;
	const char *needles[] = {"dt.yaml:7:", "integration.dt",
	                         "expected a positive number, got 0", NULL};
	run_bad_scene("dt", BODY BEAMS "integration:\n  dt: 0\n", needles);
}

/* A step the model cannot resolve: exit 2 naming integration.dt, where it
 * was set, the bound and its numbers. On the essay's gate the random force
 * holds each value 1/f = 1/50 Hz = 0.02 s: 0.5 s and 12 s are refused at
 * their --set, 0.02 s runs. */
static void unresolvable_dt(void **state)
{
	(void)state;
	const char *gate = bsim_test_src("configs/thesis/gate.yaml");
	static const char *const steps[] = {"0.5", "12"};
	for (int i = 0; i < 2; i++) {
		char set[64], says[200];
		snprintf(set, sizeof set, "integration.dt=%s", steps[i]);
		snprintf(says, sizeof says,
		         "--set %s: integration.dt: expected at most 0.02 s (the random force's "
		         "hold "
		         "1/f, f = 50 Hz), got %s",
		         set, steps[i]);
		const char *argv[] = {"run", gate, "--set", set, NULL};
		const char *needles[] = {says, NULL};
		bsim_test_expect_input_error(argv, needles);
	}
	const char *ok[] = {"run", gate, "--set", "integration.dt=0.02", NULL};
	assert_int_equal(bsim_test_cli(ok, NULL, NULL), 0);
	/* In a file: at the file's dt. */
	const char *needles[] = {"dt_hold.yaml:9:7: integration.dt: expected at most 0.02 s",
	                         "got 0.5", NULL};
	run_bad_scene("dt_hold",
	              BODY BEAMS "effects:\n  random_force: { magnitude: 20 }\n"
	                         "integration:\n  dt: 0.5\n",
	              needles);
	/* A bound's field an override changed last is where the step broke it:
	 * k = 2e7 N m/rad on I = 0.1 x 25^2 / 3 kg m^2 has half a period of
	 * pi sqrt(I/k) = 3.2 ms, under the gate's 4 ms. */
	const char *stiff[] = {"run", gate, "--set", "beams.0.stiffness=2e7", NULL};
	const char *stiff_says[] = {"--set beams.0.stiffness=2e7: integration.dt: expected at most "
	                            "0.003206 s (half the natural period pi sqrt(I/k) of beam 1 "
	                            "(beams.0)",
	                            "got 0.004", NULL};
	bsim_test_expect_input_error(stiff, stiff_says);
	/* The body's crossing: 10 km/s covers 40 m a step of 4 ms, four times
	 * its radius. */
	const char *fast[] = {"run", gate, "--backend", "box2d", "--set", "body.velocity.1=1e4",
	                      NULL};
	const char *fast_says[] = {"--set body.velocity.1=1e4: integration.dt: expected at most",
	                           "the body's crossing: its half-width 10 m", "got 0.004", NULL};
	bsim_test_expect_input_error(fast, fast_says);
}

static void missing_required_key(void **state)
{
	(void)state;
	const char *text = BODY "beams:\n"
	                        "  - { pivot: [-25, 30], mass: 0.1, stiffness: 1 }\n";
	const char *needles[] = {"missing.yaml:3:", "beams.0.length",
	                         "missing (expected a positive number)", NULL};
	run_bad_scene("missing", text, needles);
}

static void overlapping_start(void **state)
{
	(void)state;
	/* 5 m below the left beam with a 10 m radius. */
	const char *needles[] = {
	        "overlap.yaml:1:", "body.start",
	        "the body (radius 10) overlaps beam 1 (beams.0) at the start (distance 5 m)", NULL};
	run_bad_scene("overlap", "body: { mass: 1, radius: 10, start: [-10, 25] }\n" BEAMS,
	              needles);
}

static void yaml_syntax_error(void **state)
{
	(void)state;
	const char *needles[] = {"syntax.yaml:2:26: ", "syntax: expected valid YAML",
	                         "mismatched flow sequence end", NULL};
	run_bad_scene("syntax",
	              "body: { mass: 1, radius: 10 }\n"
	              "beams: [ {pivot: [0, 30] ]\n"
	              "integration: { dt: 1 }\n",
	              needles);
	const char *needles2[] = {"dup.yaml:2:1: ", "duplicate key", NULL};
	run_bad_scene("dup", BODY "body: { mass: 2 }\n", needles2);
}

static void bad_set_value(void **state)
{
	(void)state;
	const char *gate = bsim_test_src("configs/thesis/gate.yaml");
	char path[1100];
	snprintf(path, sizeof path, "%s", gate);
	const char *argv[] = {"run", path, "--set", "body.mass=-1", NULL};
	const char *needles[] = {"--set body.mass=-1", "body.mass",
	                         "expected a positive number, got -1", NULL};
	bsim_test_expect_input_error(argv, needles);
	const char *argv2[] = {"run", path, "--set", "body.start=[1, 2", NULL};
	const char *needles2[] = {"body.start=[1, 2", "body.start", "expected a YAML value", NULL};
	bsim_test_expect_input_error(argv2, needles2);
	const char *argv3[] = {"run", path, "--set", "beams.7.mass=1", NULL};
	const char *needles3[] = {"beams.7.mass=1", "beams.7", "expected an index from 0 to 1",
	                          NULL};
	bsim_test_expect_input_error(argv3, needles3);
}

static void set_into_unknown_key(void **state)
{
	(void)state;
	char path[1100];
	snprintf(path, sizeof path, "%s", bsim_test_src("configs/thesis/gate.yaml"));
	const char *argv[] = {"run", path, "--set", "effects.random_force.magnitud=3", NULL};
	const char *needles[] = {
	        "--set effects.random_force.magnitud=3", "effects.random_force.magnitud",
	        "unknown key (expected one of magnitude, frequency, model, correlation_time)",
	        NULL};
	bsim_test_expect_input_error(argv, needles);
}

/* beamsim sweep on an experiment with the given text (next to a good
 * gate.yaml), with --limit limit if it is not NULL; the output directory
 * must stay without results. */
static void sweep_bad_experiment_limit(const char *name, const char *text, const char *limit,
                                       const char *const needles[])
{
	char dir[1024], exp[1200], out[1200];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir(name));
	bsim_test_write(dir, "gate.yaml", BODY BEAMS);
	char file[64];
	snprintf(file, sizeof file, "%s.yaml", name);
	snprintf(exp, sizeof exp, "%s", bsim_test_write(dir, file, text));
	snprintf(out, sizeof out, "%s/out", dir);
	const char *argv[] = {"sweep", exp, "--trials", "1", "--out", out, "--limit", limit, NULL};
	if (!limit)
		argv[6] = NULL;
	bsim_test_expect_input_error(argv, needles);
	char path[1300];
	snprintf(path, sizeof path, "%s/summary.json", out);
	char *summary = bsim_test_read(path);
	snprintf(path, sizeof path, "%s/trials.csv", out);
	char *trials = bsim_test_read(path);
	assert_null(summary);
	assert_null(trials);
}

static void sweep_bad_experiment(const char *name, const char *text, const char *const needles[])
{
	sweep_bad_experiment_limit(name, text, NULL, needles);
}

static void empty_grid(void **state)
{
	(void)state;
	const char *needles[] = {"empty_grid.yaml:4:", "grid", "expected at least one axis",
	                         "got an empty mapping", NULL};
	sweep_bad_experiment("empty_grid", "scene: gate.yaml\ntrials: 2\nseed: 1\ngrid: {}\n",
	                     needles);
	const char *needles2[] = {"empty_axis.yaml:5:", "grid.effects.propulsion.force",
	                          "expected a non-empty list of values, got an empty list", NULL};
	sweep_bad_experiment("empty_axis",
	                     "scene: gate.yaml\ntrials: 2\nseed: 1\ngrid:\n"
	                     "  effects.propulsion.force: []\n",
	                     needles2);
}

static void bad_grid_value(void **state)
{
	(void)state;
	const char *needles[] = {"grid_value.yaml:6: ", "body.mass",
	                         "expected a positive number, got -1", NULL};
	sweep_bad_experiment("grid_value",
	                     "scene: gate.yaml\ntrials: 2\nseed: 1\ngrid:\n"
	                     "  effects.propulsion.force: [4, 5]\n"
	                     "  body.mass: [1, -1]\n",
	                     needles);
}

/* Each grid value is tried in one group before the product is counted or
 * built: the 8th of 8 values of the slowest axis of 96,000 groups (the
 * product, in order, builds 84,000 groups before it) is named although the
 * limit of 100 groups would refuse the grid, and so with no more than 100
 * groups' work; the message is the one the product gives. */
static void grid_value_first(void **state)
{
	(void)state;
	char *text = bsim_test_read(bsim_test_src(
	        "tests/fuzz/regressions/experiment/bad_8th_value_of_96000_groups.yaml"));
	assert_non_null(text);
	const char *needles[] = {"grid_8th.yaml:5: ", "body.mass",
	                         "expected a positive number, got -1", NULL};
	sweep_bad_experiment_limit("grid_8th", text, "groups=100", needles);
	free(text);
}

static void bad_experiment_keys(void **state)
{
	(void)state;
	const char *needles[] = {"trials.yaml:2:", "trials", "expected a positive integer, got 0",
	                         NULL};
	sweep_bad_experiment("trials",
	                     "scene: gate.yaml\ntrials: 0\nseed: 1\ngrid: {body.mass: [1]}\n",
	                     needles);
	const char *needles2[] = {
	        "exp_key.yaml:4:", "seeds",
	        "unknown key (expected one of name, scene, trials, seed, set, grid)", NULL};
	sweep_bad_experiment("exp_key",
	                     "scene: gate.yaml\ntrials: 2\nseed: 1\nseeds: 2\n"
	                     "grid: {body.mass: [1]}\n",
	                     needles2);
	const char *needles3[] = {"no_scene.yaml:1:", "scene", "expected a readable scene file",
	                          NULL};
	sweep_bad_experiment("no_scene",
	                     "scene: nowhere.yaml\ntrials: 2\nseed: 1\ngrid: {body.mass: [1]}\n",
	                     needles3);
}

/* A fixed value for a field the grid varies would be lost in every group:
 * refused, from the experiment's set: block and from the command line. */
static void grid_conflict(void **state)
{
	(void)state;
	const char *needles[] = {"set_grid.yaml:5",
	                         "set.beams.0.stiffness",
	                         "the grid varies beams.0.stiffness (",
	                         "set_grid.yaml:7)",
	                         "expected a key the grid does not vary",
	                         NULL};
	sweep_bad_experiment("set_grid",
	                     "scene: gate.yaml\ntrials: 2\nseed: 1\nset:\n"
	                     "  beams.0.stiffness: 300\ngrid:\n"
	                     "  beams.0.stiffness: [100, 200]\n",
	                     needles);

	char dir[1024], exp[1200], out[1200], path[1300];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("cli_grid"));
	bsim_test_write(dir, "gate.yaml", BODY BEAMS);
	snprintf(exp, sizeof exp, "%s",
	         bsim_test_write(dir, "cli_grid.yaml",
	                         "scene: gate.yaml\ntrials: 2\nseed: 1\ngrid:\n"
	                         "  effects.propulsion.force: [4, 5]\n"));
	snprintf(out, sizeof out, "%s/out", dir);
	const char *argv[] = {"sweep", exp, "--set", "effects.propulsion.force=7",
	                      "--out", out, NULL};
	const char *needles2[] = {"--set effects.propulsion.force=7",
	                          "grid varies effects.propulsion.force (", "cli_grid.yaml:5)",
	                          NULL};
	bsim_test_expect_input_error(argv, needles2);
	snprintf(path, sizeof path, "%s/trials.csv", out);
	char *trials = bsim_test_read(path);
	assert_null(trials);
}

/* A file of the other kind: an experiment given to a command that takes a
 * scene (landscape; run and video take both, test_replay), a scene given to
 * sweep or compare, is named as what it is, with the command that takes
 * it. */
static void wrong_kind_of_file(void **state)
{
	(void)state;
	char exp[1024], scene[1024];
	snprintf(exp, sizeof exp, "%s", bsim_test_src("configs/thesis/h1_symmetric.yaml"));
	snprintf(scene, sizeof scene, "%s", bsim_test_src("configs/thesis/gate.yaml"));
	const char *out = bsim_test_dir("wrong_kind");
	const char *run[] = {"landscape", exp, "--out", out, NULL};
	const char *run_needles[] = {"h1_symmetric.yaml:2:1: scene: this is an experiment file",
	                             "beamsim sweep or compare", NULL};
	bsim_test_expect_input_error(run, run_needles);
	const char *sweep[] = {"sweep", scene, "--out", out, NULL};
	const char *compare[] = {"compare", scene, "--out", out, NULL};
	const char *scene_needles[] = {"gate.yaml:3:1: body: this is a scene file", "beamsim run",
	                               NULL};
	bsim_test_expect_input_error(sweep, scene_needles);
	bsim_test_expect_input_error(compare, scene_needles);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(unknown_key),
	        cmocka_unit_test(unknown_top_level_key),
	        cmocka_unit_test(string_for_number),
	        cmocka_unit_test(mapping_for_list),
	        cmocka_unit_test(three_element_pivot),
	        cmocka_unit_test(non_integer_max_steps),
	        cmocka_unit_test(nan_value),
	        cmocka_unit_test(inf_value),
	        cmocka_unit_test(non_positive_mass),
	        cmocka_unit_test(non_positive_length),
	        cmocka_unit_test(non_positive_dt),
	        cmocka_unit_test(unresolvable_dt),
	        cmocka_unit_test(missing_required_key),
	        cmocka_unit_test(overlapping_start),
	        cmocka_unit_test(yaml_syntax_error),
	        cmocka_unit_test(bad_set_value),
	        cmocka_unit_test(set_into_unknown_key),
	        cmocka_unit_test(empty_grid),
	        cmocka_unit_test(bad_grid_value),
	        cmocka_unit_test(bad_experiment_keys),
	        cmocka_unit_test(grid_conflict),
	        cmocka_unit_test(wrong_kind_of_file),
	        cmocka_unit_test(grid_value_first),
	        cmocka_unit_test(inconsistent_duration),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
