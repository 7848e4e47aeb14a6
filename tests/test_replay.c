/* Replaying one trial of a sweep: `beamsim run EXPERIMENT --group G --trial
 * T` and `beamsim run DIR --group G --trial T` run exactly the trial the
 * sweep ran. The truth is the sweep's own trials.csv: for rows picked at
 * random (a fixed seed) of a 3-axis experiment, with deterministic groups
 * (no random force) among them, the replay's outcome, type, steps, t_end,
 * x_end and y_end (from run --json, written as trials.csv writes them)
 * equal the row's text; the grid values the report names are those the
 * group index gives (first axis slowest). The same on a lattice
 * experiment, on a comparison's second side (by backend options, and by
 * lattice protocol), and for video. A stored row that the replay does not
 * give (steps altered in a directory without its manifest) exits 3. A
 * scene given --group says that it applies no grid values; a group or
 * trial out of range exits 2 naming the range; a comparison's directory
 * without a side names its sides. */
#define _POSIX_C_SOURCE 200809L

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"

/* The experiment's grid (first axis slowest) and its size. */
static const char *const force[] = {"7", "9"};
static const char *const magnitude[] = {"0", "30"};
static const char *const stiffness[] = {"150", "400"};
enum { GROUPS = 8, TRIALS = 3 };

static char experiment[1200], sweep_dir[1200], work[1200];

/* The fields group..y_end of trial (g, t) in the trials.csv at path, as
 * written: "g,t,outcome,type,steps,t_end,x_end,y_end". */
static void csv_row(const char *path, int g, int t, char *buf, size_t size)
{
	char *text = bsim_test_read(path);
	assert_non_null(text);
	char prefix[32];
	snprintf(prefix, sizeof prefix, "\n%d,%d,", g, t);
	const char *p = strstr(text, prefix);
	if (!p)
		fail_msg("%s: no row %d,%d", path, g, t);
	p++;
	/* eight fields: up to the eighth comma */
	const char *q = p;
	for (int commas = 0; *q && *q != '\n'; q++)
		if (*q == ',' && ++commas == 8)
			break;
	snprintf(buf, size, "%.*s", (int)(q - p), p);
	free(text);
}

/* The JSON string value of key in text ("traversed"). */
static void json_text(const char *text, const char *key, char *buf, size_t size)
{
	char pat[64];
	snprintf(pat, sizeof pat, "\"%s\": \"", key);
	const char *p = strstr(text, pat);
	if (!p)
		fail_msg("no \"%s\" in %s", key, text);
	p += strlen(pat);
	snprintf(buf, size, "%.*s", (int)strcspn(p, "\""), p);
}

/* The replayed trial of argv (run ... --json) in the fields of a row. */
static void replay_row(const char *const argv[], int g, int t, char *buf, size_t size)
{
	char *out = NULL, *err = NULL;
	int rc = bsim_test_cli(argv, &out, &err);
	if (rc != 0)
		fail_msg("exit %d: %s", rc, err);
	char outcome[32], type[32];
	json_text(out, "outcome", outcome, sizeof outcome);
	json_text(out, "type", type, sizeof type);
	snprintf(buf, size, "%d,%d,%s,%s,%.0f,%.10g,%.10g,%.10g", g, t, outcome, type,
	         bsim_test_json_number(out, "steps"), bsim_test_json_number(out, "t_end"),
	         bsim_test_json_number(out, "x_end"), bsim_test_json_number(out, "y_end"));
	free(out);
	free(err);
}

static int setup(void **state)
{
	(void)state;
	snprintf(work, sizeof work, "%s", bsim_test_dir("replay"));
	char text[2048];
	snprintf(text, sizeof text,
	         "scene: %s\ntrials: %d\nseed: 5\n"
	         "grid:\n"
	         "  effects.propulsion.force: [%s, %s]\n"
	         "  effects.random_force.magnitude: [%s, %s]\n"
	         "  beams.0.stiffness: [%s, %s]\n",
	         bsim_test_src("configs/thesis/gate.yaml"), TRIALS, force[0], force[1],
	         magnitude[0], magnitude[1], stiffness[0], stiffness[1]);
	snprintf(experiment, sizeof experiment, "%s", bsim_test_write(work, "exp.yaml", text));
	snprintf(sweep_dir, sizeof sweep_dir, "%s", bsim_test_join(work, "sweep"));
	const char *argv[] = {"sweep",     experiment, "--out",   sweep_dir,
	                      "--threads", "2",        "--quiet", NULL};
	char *err = NULL;
	int rc = bsim_test_cli(argv, NULL, &err);
	if (rc != 0)
		fail_msg("sweep: exit %d: %s", rc, err);
	free(err);
	return 0;
}

/* Rows picked at random, and a deterministic group's copy (trial 2 of
 * group 1: F = 7 N, no random force), replayed from the experiment and
 * from the directory; the report's grid line names the group's values. */
static void rows_replay_exactly(void **state)
{
	(void)state;
	char csv[1300];
	snprintf(csv, sizeof csv, "%s/trials.csv", sweep_dir);
	srand(20261126u);
	int picks[12][2] = {{1, 2}};
	for (int k = 1; k < 12; k++) {
		picks[k][0] = rand() / (RAND_MAX / GROUPS + 1);
		picks[k][1] = rand() / (RAND_MAX / TRIALS + 1);
	}
	for (int k = 0; k < 12; k++) {
		int g = picks[k][0], t = picks[k][1];
		char gs[8], ts[8], want[256], got[256];
		snprintf(gs, sizeof gs, "%d", g);
		snprintf(ts, sizeof ts, "%d", t);
		csv_row(csv, g, t, want, sizeof want);
		const char *from_exp[] = {"run",     experiment, "--group", gs,
		                          "--trial", ts,         "--json",  NULL};
		replay_row(from_exp, g, t, got, sizeof got);
		assert_string_equal(got, want);
		const char *from_dir[] = {"run",     sweep_dir, "--group", gs,
		                          "--trial", ts,        "--json",  NULL};
		replay_row(from_dir, g, t, got, sizeof got);
		assert_string_equal(got, want);
		printf("# group %d, trial %d: %s\n", g, t, want);

		/* The text report names the grid values of the group. */
		char grid[256];
		snprintf(grid, sizeof grid,
		         "grid        group %d: effects.propulsion.force=%s, "
		         "effects.random_force.magnitude=%s, beams.0.stiffness=%s\n",
		         g, force[g / 4], magnitude[g / 2 % 2], stiffness[g % 2]);
		const char *text[] = {"run", sweep_dir, "--group", gs, "--trial", ts, NULL};
		char *out = NULL, *err = NULL;
		assert_int_equal(bsim_test_cli(text, &out, &err), 0);
		assert_non_null(strstr(out, grid));
		assert_non_null(strstr(out, "(the same)"));
		free(out);
		free(err);
	}
}

/* A stored row altered (steps + 1; the manifest removed, which would
 * refuse the file): the replay says it differs and exits 3. */
static void altered_row_exits_3(void **state)
{
	(void)state;
	char dir[1300], csv[1400], row[256], altered[320];
	snprintf(dir, sizeof dir, "%s", bsim_test_join(work, "altered"));
	const char *sweep[] = {"sweep",     experiment, "--out",   dir,
	                       "--threads", "2",        "--quiet", NULL};
	assert_int_equal(bsim_test_cli(sweep, NULL, NULL), 0);
	assert_int_equal(bsim_test_remove(bsim_test_join(dir, "manifest.json")), 0);
	snprintf(csv, sizeof csv, "%s/trials.csv", dir);
	csv_row(csv, 6, 1, row, sizeof row);
	char outcome[32], type[32], rest[200];
	int steps;
	assert_int_equal(sscanf(row, "6,1,%31[^,],%31[^,],%d,%199s", outcome, type, &steps, rest),
	                 4);
	snprintf(altered, sizeof altered, "6,1,%s,%s,%d,%s", outcome, type, steps + 1, rest);
	char *text = bsim_test_read(csv);
	assert_non_null(text);
	char *at = strstr(text, row);
	assert_non_null(at);
	size_t head = (size_t)(at - text), n = strlen(row);
	char *changed = malloc(strlen(text) + 16);
	assert_non_null(changed);
	sprintf(changed, "%.*s%s%s", (int)head, text, altered, at + n);
	bsim_test_write(dir, "trials.csv", changed);
	free(changed);
	free(text);
	const char *argv[] = {"run", dir, "--group", "6", "--trial", "1", NULL};
	char *out = NULL, *err = NULL;
	assert_int_equal(bsim_test_cli(argv, &out, &err), 3);
	assert_non_null(strstr(out, "(differs from the replay)"));
	assert_non_null(strstr(err, "differs from its row"));
	assert_non_null(strstr(err, altered));
	free(out);
	free(err);
}

/* A lattice experiment (the C track, two trials), one row. */
static void lattice_row_replays(void **state)
{
	(void)state;
	char exp[1200], dir[1300], csv[1400], want[256], got[256];
	snprintf(exp, sizeof exp, "%s", bsim_test_src("configs/lattice/c_track_essay.yaml"));
	snprintf(dir, sizeof dir, "%s", bsim_test_join(work, "lattice"));
	const char *sweep[] = {"sweep", exp, "--trials", "2", "--out", dir, "--quiet", NULL};
	assert_int_equal(bsim_test_cli(sweep, NULL, NULL), 0);
	snprintf(csv, sizeof csv, "%s/trials.csv", dir);
	csv_row(csv, 0, 1, want, sizeof want);
	const char *from_exp[] = {"run", exp, "--trial", "1", "--json", NULL};
	replay_row(from_exp, 0, 1, got, sizeof got);
	assert_string_equal(got, want);
	const char *from_dir[] = {"run", dir, "--group", "0", "--trial", "1", "--json", NULL};
	replay_row(from_dir, 0, 1, got, sizeof got);
	assert_string_equal(got, want);
}

/* A comparison's second side: by options (from the experiment with the
 * side's label, and from the directory), and by lattice protocol (from the
 * directory; from the experiment with the protocol's --set). */
static void compare_sides_replay(void **state)
{
	(void)state;
	char dir[1300], csv[1400], want[256], got[256], other[256];
	snprintf(dir, sizeof dir, "%s", bsim_test_join(work, "compare"));
	const char *side = "thesis:integrator=euler";
	const char *compare[] = {
	        "compare",  experiment, "--backends", "thesis,thesis:integrator=euler",
	        "--trials", "2",        "--out",      dir,
	        "--quiet",  NULL};
	int rc = bsim_test_cli(compare, NULL, NULL);
	assert_true(rc == 0 || rc == 3);
	snprintf(csv, sizeof csv, "%s/thesis-integrator=euler/trials.csv", dir);
	csv_row(csv, 7, 1, want, sizeof want);
	/* the sides part in this trial, so a replay of the wrong one shows */
	snprintf(csv, sizeof csv, "%s/thesis/trials.csv", dir);
	csv_row(csv, 7, 1, other, sizeof other);
	assert_string_not_equal(want, other);
	const char *from_exp[] = {"run", experiment, "--backend", side,     "--group",
	                          "7",   "--trial",  "1",         "--json", NULL};
	replay_row(from_exp, 7, 1, got, sizeof got);
	assert_string_equal(got, want);
	const char *from_dir[] = {"run", dir,       "--backend", side,     "--group",
	                          "7",   "--trial", "1",         "--json", NULL};
	replay_row(from_dir, 7, 1, got, sizeof got);
	assert_string_equal(got, want);

	/* Without a side: both named, exit 2. */
	const char *no_side[] = {"run", dir, "--group", "7", NULL};
	const char *const needles[] = {"two sides", "--backend thesis ",
	                               "--backend thesis:integrator=euler", NULL};
	bsim_test_expect_input_error(no_side, needles);

	/* --protocols world,essay on the C track: the essay side. */
	char lat[1200], pdir[1300];
	snprintf(lat, sizeof lat, "%s", bsim_test_src("configs/lattice/c_track_essay.yaml"));
	snprintf(pdir, sizeof pdir, "%s", bsim_test_join(work, "protocols"));
	const char *protocols[] = {"compare", lat,     "--protocols", "world,essay", "--trials",
	                           "3",       "--out", pdir,          "--quiet",     NULL};
	rc = bsim_test_cli(protocols, NULL, NULL);
	assert_true(rc == 0 || rc == 3);
	snprintf(csv, sizeof csv, "%s/essay/trials.csv", pdir);
	csv_row(csv, 0, 2, want, sizeof want);
	/* the sides part in this trial, so a replay of the wrong one shows */
	snprintf(csv, sizeof csv, "%s/world/trials.csv", pdir);
	csv_row(csv, 0, 2, other, sizeof other);
	assert_string_not_equal(want, other);
	const char *essay_dir[] = {"run",     pdir, "--backend", "essay",
	                           "--trial", "2",  "--json",    NULL};
	replay_row(essay_dir, 0, 2, got, sizeof got);
	assert_string_equal(got, want);
	const char *essay_exp[] = {"run",     lat, "--set",  "lattice.protocol=essay",
	                           "--trial", "2", "--json", NULL};
	replay_row(essay_exp, 0, 2, got, sizeof got);
	assert_string_equal(got, want);
	/* the side's label given to an experiment: what it amounts to */
	const char *label[] = {"run", lat, "--backend", "essay", NULL};
	const char *const l_needles[] = {"--backend essay", "--set lattice.protocol=essay", NULL};
	bsim_test_expect_input_error(label, l_needles);
}

/* A scene has no grid: --group says so and names the ways to replay. */
static void scene_group_note(void **state)
{
	(void)state;
	const char *argv[] = {"run",     bsim_test_src("configs/thesis/gate.yaml"),
	                      "--group", "3",
	                      "--set",   "integration.max_steps=200",
	                      NULL};
	char *out = NULL, *err = NULL;
	assert_int_equal(bsim_test_cli(argv, &out, &err), 0);
	assert_non_null(strstr(err, "is a scene, which has no grid"));
	assert_non_null(strstr(err, "applies no grid values"));
	assert_non_null(strstr(err, "EXPERIMENT|DIR --group G --trial T"));
	assert_null(strstr(out, "grid "));
	free(out);
	free(err);
	/* without --group, nothing on stderr */
	const char *plain[] = {"run", bsim_test_src("configs/thesis/gate.yaml"), "--set",
	                       "integration.max_steps=200", NULL};
	assert_int_equal(bsim_test_cli(plain, &out, &err), 0);
	assert_string_equal(err, "");
	free(out);
	free(err);
}

/* Out of range: exit 2, one line naming the range. */
static void out_of_range_exits_2(void **state)
{
	(void)state;
	const char *group[] = {"run", experiment, "--group", "8", NULL};
	const char *const g_needles[] = {"--group 8", "expected 0 to 7", "8 groups", NULL};
	bsim_test_expect_input_error(group, g_needles);
	const char *trial[] = {"run", sweep_dir, "--group", "1", "--trial", "3", NULL};
	const char *const t_needles[] = {"--trial 3", "expected 0 to 2", "3 trials per group",
	                                 NULL};
	bsim_test_expect_input_error(trial, t_needles);
	const char *video[] = {"video", experiment, "--group",
	                       "9",     "--out",    bsim_test_join(work, "never.mp4"),
	                       NULL};
	bsim_test_expect_input_error(video, g_needles + 1);
	assert_false(bsim_test_exists(bsim_test_join(work, "never.mp4")));
	/* A stored run's seed is its own. */
	const char *seed[] = {"run", sweep_dir, "--seed", "3", NULL};
	const char *const s_needles[] = {"--seed", "inputs/experiment.yaml", NULL};
	bsim_test_expect_input_error(seed, s_needles);
}

/* A sweep run with --grid (an axis replaced, one added) replays from its
 * experiment with the same --grid, and from its directory, which records
 * the grid; --grid on a scene or a stored run is refused. */
static void grid_rows_replay(void **state)
{
	(void)state;
	char dir[1300], csv[1400];
	snprintf(dir, sizeof dir, "%s", bsim_test_join(work, "grid-sweep"));
	snprintf(csv, sizeof csv, "%s/trials.csv", dir);
	const char *sweep[] = {"sweep",   experiment,
	                       "--grid",  "beams.0.stiffness=200:300:100",
	                       "--grid",  "body.mass=1.5",
	                       "--out",   dir,
	                       "--quiet", NULL};
	char *err = NULL;
	int rc = bsim_test_cli(sweep, NULL, &err);
	if (rc != 0)
		fail_msg("sweep --grid: exit %d: %s", rc, err);
	free(err);
	const int picks[][2] = {{3, 1}, {6, 2}, {5, 0}};
	for (int k = 0; k < 3; k++) {
		int g = picks[k][0], t = picks[k][1];
		char gs[8], ts[8], want[256], got[256];
		snprintf(gs, sizeof gs, "%d", g);
		snprintf(ts, sizeof ts, "%d", t);
		csv_row(csv, g, t, want, sizeof want);
		const char *from_exp[] = {"run",     experiment,
		                          "--grid",  "beams.0.stiffness=200:300:100",
		                          "--grid",  "body.mass=1.5",
		                          "--group", gs,
		                          "--trial", ts,
		                          "--json",  NULL};
		replay_row(from_exp, g, t, got, sizeof got);
		assert_string_equal(got, want);
		const char *from_dir[] = {"run", dir, "--group", gs, "--trial", ts, "--json", NULL};
		replay_row(from_dir, g, t, got, sizeof got);
		assert_string_equal(got, want);
	}
	const char *on_scene[] = {"run", bsim_test_src("configs/thesis/gate.yaml"), "--grid",
	                          "body.mass=1,2", NULL};
	const char *const scene_needles[] = {"--grid body.mass", "has no grid", NULL};
	bsim_test_expect_input_error(on_scene, scene_needles);
	const char *on_dir[] = {"run", dir, "--grid", "body.mass=1,2", NULL};
	const char *const dir_needles[] = {"--grid", "inputs/experiment.yaml", NULL};
	bsim_test_expect_input_error(on_dir, dir_needles);
}

/* video EXPERIMENT --group --trial: the trial, its grid values, a file. */
static void video_replays(void **state)
{
	(void)state;
	char mp4[1300], csv[1400], want[256];
	snprintf(mp4, sizeof mp4, "%s", bsim_test_join(work, "trial.mp4"));
	const char *argv[] = {"video",  experiment, "--group", "5",     "--trial",
	                      "2",      "--size",   "64x64",   "--fps", "1",
	                      "--hold", "0",        "--out",   mp4,     NULL};
	char *out = NULL, *err = NULL;
	int rc = bsim_test_cli(argv, &out, &err);
	if (rc != 0)
		fail_msg("exit %d: %s", rc, err);
	assert_true(bsim_test_size(mp4) > 0);
	assert_non_null(strstr(out, "grid        group 5: effects.propulsion.force=9, "
	                            "effects.random_force.magnitude=0, beams.0.stiffness=400"));
	/* its outcome is the row's */
	snprintf(csv, sizeof csv, "%s/trials.csv", sweep_dir);
	csv_row(csv, 5, 2, want, sizeof want);
	char outcome[64];
	assert_int_equal(sscanf(want, "%*d,%*d,%63[^,]", outcome), 1);
	char *line = strstr(out, "\nthesis ");
	assert_non_null(line);
	assert_non_null(strstr(line, outcome));
	free(out);
	free(err);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(rows_replay_exactly), cmocka_unit_test(altered_row_exits_3),
	        cmocka_unit_test(lattice_row_replays), cmocka_unit_test(compare_sides_replay),
	        cmocka_unit_test(scene_group_note),    cmocka_unit_test(out_of_range_exits_2),
	        cmocka_unit_test(video_replays),       cmocka_unit_test(grid_rows_replay),
	};
	return cmocka_run_group_tests(tests, setup, NULL);
}
