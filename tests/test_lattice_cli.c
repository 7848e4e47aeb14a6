/* Lattice scenes and experiments through the real program:
 *   - every bad lattice (a map of the wrong shape, a negative stiffness in
 *     the file, the map or its CSV, an empty lattice, ...) exits 2 with one
 *     line naming the file, line, field and what was expected, and a sweep
 *     on it writes nothing;
 *   - a lattice sweep writes its files with the documented columns, the
 *     same whatever the number of threads, and its counts agree with each
 *     other (final locations sum to the trials; each trial's path in
 *     trials.csv is the sequence of its rows in gate_entries.csv);
 *   - regress --exact reruns a stored lattice sweep (its stiffness CSV kept
 *     in inputs/) to the same trials;
 *   - compare --protocols world,essay runs both protocols on the same
 *     schedules and reports the final-location test, and regress reruns it;
 *     compare of the two backends on a lattice reports both distributions. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "support.h"

#define BODY "body: { mass: 1, radius: 10 }\n"

/* beamsim run on a scene (and a CSV beside it, if csv is not NULL). */
static void bad_lattice(const char *name, const char *scene, const char *csv,
                        const char *const needles[])
{
	const char *dir = bsim_test_dir(name);
	char path[1200];
	if (csv)
		bsim_test_write(dir, "map.csv", csv);
	snprintf(path, sizeof path, "%s", bsim_test_write(dir, "scene.yaml", scene));
	const char *argv[] = {"run", path, NULL};
	bsim_test_expect_input_error(argv, needles);
}

#define LATTICE_3X3                                                                                \
	"lattice:\n"                                                                               \
	"  columns: 3\n"                                                                           \
	"  rows: 3\n"                                                                              \
	"  beam: { length: 25, mass: 0.1, stiffness: 400, damping: 50 }\n"

static void map_wrong_rows(void **state)
{
	(void)state;
	const char *needles[] = {"scene.yaml:6:16: ", "lattice.stiffness",
	                         "expected a list of 3 rows (row iy = 0 first) of 3 numbers",
	                         "got a list of 2 items", NULL};
	bad_lattice("lat_rows", BODY LATTICE_3X3 "  stiffness: [[1, 2, 3], [4, 5, 6]]\n", NULL,
	            needles);
}

/* A per-gate map with a per-beam one: refused, naming both keys. */
static void map_and_beam_maps(void **state)
{
	(void)state;
	const char *gate[] = {"scene.yaml:7:", "lattice.stiffness_left",
	                      "expected either stiffness or stiffness_left, not both", NULL};
	bad_lattice("lat_both",
	            BODY LATTICE_3X3 "  stiffness: [[1, 2, 3], [4, 5, 6], [7, 8, 9]]\n"
	                             "  stiffness_left: [[1, 2, 3], [4, 5, 6], [7, 8, 9]]\n",
	            NULL, gate);
	const char *file[] = {"scene.yaml:7:", "lattice.stiffness_right",
	                      "expected either stiffness_file or stiffness_right, not both", NULL};
	bad_lattice("lat_both_file",
	            BODY LATTICE_3X3 "  stiffness_file: map.csv\n"
	                             "  stiffness_right: [[1, 2, 3], [4, 5, 6], [7, 8, 9]]\n",
	            "1,2,3\n4,5,6\n7,8,9\n", file);
}

static void map_wrong_columns(void **state)
{
	(void)state;
	const char *needles[] = {"scene.yaml:", "lattice.stiffness.1",
	                         "expected a list of 3 numbers (ix = -1 .. 1)", NULL};
	bad_lattice("lat_cols", BODY LATTICE_3X3 "  stiffness: [[1, 2, 3], [4, 5], [7, 8, 9]]\n",
	            NULL, needles);
}

static void map_negative(void **state)
{
	(void)state;
	const char *needles[] = {"scene.yaml:6:", "lattice.stiffness_left.2.0",
	                         "expected a number >= 0", "got -5", NULL};
	bad_lattice("lat_neg",
	            BODY LATTICE_3X3 "  stiffness_left: [[1, 2, 3], [4, 5, 6], [-5, 8, 9]]\n", NULL,
	            needles);
}

static void beam_negative(void **state)
{
	(void)state;
	const char *needles[] = {"scene.yaml:5:", "lattice.beam.stiffness",
	                         "expected a number >= 0", NULL};
	bad_lattice("lat_beam",
	            BODY "lattice:\n  columns: 3\n  rows: 3\n"
	                 "  beam: { length: 25, mass: 0.1, stiffness: -400 }\n",
	            NULL, needles);
}

static void csv_negative(void **state)
{
	(void)state;
	const char *needles[] = {"map.csv:3:3: ", "lattice.stiffness_file",
	                         "expected a number >= 0", "got -2", NULL};
	bad_lattice("lat_csv_neg", BODY LATTICE_3X3 "  stiffness_file: map.csv\n",
	            "# a map\n1, 2, 3\n4,-2, 6\n7, 8, 9\n", needles);
}

static void csv_wrong_shape(void **state)
{
	(void)state;
	const char *rows[] = {"map.csv:", "lattice.stiffness_file", "expected 3 rows", "got 2",
	                      NULL};
	bad_lattice("lat_csv_rows", BODY LATTICE_3X3 "  stiffness_file: map.csv\n",
	            "1, 2, 3\n4, 5, 6\n", rows);
	const char *cols[] = {"map.csv:2: ", "lattice.stiffness_file", "expected 3 values", "got 4",
	                      NULL};
	bad_lattice("lat_csv_cols", BODY LATTICE_3X3 "  stiffness_file: map.csv\n",
	            "1, 2, 3\n4, 5, 6, 7\n7, 8, 9\n", cols);
	const char *missing[] = {"scene.yaml:6:19: ", "lattice.stiffness_file",
	                         "expected a readable CSV file", NULL};
	bad_lattice("lat_csv_missing", BODY LATTICE_3X3 "  stiffness_file: nowhere.csv\n", NULL,
	            missing);
	const char *outside[] = {"lattice.stiffness_file", "relative to the scene's directory",
	                         NULL};
	bad_lattice("lat_csv_up", BODY LATTICE_3X3 "  stiffness_file: ../map.csv\n", NULL, outside);
}

static void empty_lattice(void **state)
{
	(void)state;
	const char *rows[] = {"scene.yaml:4:9: ", "lattice.rows", "expected a positive integer",
	                      "got 0", NULL};
	bad_lattice("lat_empty",
	            BODY "lattice:\n  columns: 3\n  rows: 0\n"
	                 "  beam: { length: 25, mass: 0.1, stiffness: 400 }\n",
	            NULL, rows);
	const char *range[] = {"lattice.ix_max", "expected an integer >= lattice.ix_min (2)", NULL};
	bad_lattice("lat_range",
	            BODY "lattice:\n  ix_min: 2\n  ix_max: 1\n  rows: 2\n"
	                 "  beam: { length: 25, mass: 0.1, stiffness: 400 }\n",
	            NULL, range);
	const char *even[] = {"lattice.columns", "expected an odd number", "got 4", NULL};
	bad_lattice("lat_even",
	            BODY "lattice:\n  columns: 4\n  rows: 2\n"
	                 "  beam: { length: 25, mass: 0.1, stiffness: 400 }\n",
	            NULL, even);
}

static void lattice_and_beams(void **state)
{
	(void)state;
	const char *both[] = {"lattice", "expected either beams: or lattice:, not both", NULL};
	bad_lattice("lat_both",
	            BODY "beams:\n  - { pivot: [-25, 30], length: 25, mass: 0.1, stiffness: 1 "
	                 "}\n" LATTICE_3X3,
	            NULL, both);
	const char *neither[] = {"beams",
	                         "missing (expected a non-empty list of beams, or a "
	                         "lattice: block)",
	                         NULL};
	bad_lattice("lat_neither", BODY "effects: {}\n", NULL, neither);
	const char *outside[] = {"body.start", "between the lattice's sides", NULL};
	bad_lattice("lat_outside", "body: { mass: 1, radius: 10, start: [100, 0] }\n" LATTICE_3X3,
	            NULL, outside);
}

static void bad_protocol(void **state)
{
	(void)state;
	const char *argv[] = {"run", bsim_test_src("configs/lattice/uniform_9x9.yaml"), "--set",
	                      "lattice.protocol=gate", NULL};
	const char *needles[] = {"--set lattice.protocol=gate: lattice.protocol: expected world",
	                         NULL};
	bsim_test_expect_input_error(argv, needles);
}

/* A bad scene leaves no output directory behind. */
static void sweep_writes_nothing(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("lat_sweep_bad");
	char scene[1200], exp[1200], out[1300];
	snprintf(scene, sizeof scene, "%s",
	         bsim_test_write(dir, "scene.yaml",
	                         BODY LATTICE_3X3 "  stiffness: [[1, 2, 3], [4, 5, 6]]\n"));
	snprintf(exp, sizeof exp, "%s",
	         bsim_test_write(dir, "exp.yaml",
	                         "scene: scene.yaml\ntrials: 2\nseed: 1\n"
	                         "grid:\n  effects.propulsion.force: [6]\n"));
	snprintf(out, sizeof out, "%s/out", dir);
	const char *argv[] = {"sweep", exp, "--out", out, "--quiet", NULL};
	const char *needles[] = {"scene.yaml:6:16: ", "lattice.stiffness", NULL};
	bsim_test_expect_input_error(argv, needles);
	struct stat st;
	assert_true(stat(out, &st) != 0);
}

/* ---- sweeps, regress and compare ------------------------------------------ */

static char *read_in(const char *dir, const char *name)
{
	char path[2000];
	if (snprintf(path, sizeof path, "%s/%s", dir, name) >= (int)sizeof path)
		fail_msg("path too long");
	char *t = bsim_test_read(path);
	if (!t)
		fail_msg("%s missing", path);
	return t;
}

static int run_ok(const char *const argv[])
{
	char *out = NULL, *err = NULL;
	int rc = bsim_test_cli(argv, &out, &err);
	if (rc != 0 && rc != 3)
		fail_msg("exit status %d: %s", rc, err ? err : "");
	free(out);
	free(err);
	return rc;
}

/* The C-track (its CSV beside it), 6 trials of 30 s. */
static const char *c_track_experiment(const char *dir)
{
	static char path[1200];
	char text[1600];
	snprintf(text, sizeof text,
	         "scene: %s\ntrials: 6\nseed: 3\nset:\n  integration.max_steps: 7500\n"
	         "grid:\n  effects.propulsion.force: [6]\n  effects.random_force.magnitude: [30]\n",
	         bsim_test_src("configs/lattice/c_track.yaml"));
	snprintf(path, sizeof path, "%s", bsim_test_write(dir, "c_track_exp.yaml", text));
	return path;
}

/* The n-th field (0-based) of a CSV line. */
static void csv_field(const char *line, int n, char *buf, size_t size)
{
	for (int k = 0; k < n && line; k++) {
		line = strchr(line, ',');
		line = line ? line + 1 : NULL;
	}
	size_t len = line ? strcspn(line, ",\n") : 0;
	snprintf(buf, size, "%.*s", (int)(len < size ? len : size - 1), line ? line : "");
}

static void sweep_files(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("lat_sweep");
	char exp[1200], out1[1300], out2[1300];
	snprintf(exp, sizeof exp, "%s", c_track_experiment(dir));
	snprintf(out1, sizeof out1, "%s/t1", dir);
	snprintf(out2, sizeof out2, "%s/t2", dir);
	const char *a1[] = {"sweep", exp, "--out", out1, "--threads", "1", "--quiet", NULL};
	const char *a2[] = {"sweep", exp, "--out", out2, "--threads", "2", "--quiet", NULL};
	assert_int_equal(run_ok(a1), 0);
	assert_int_equal(run_ok(a2), 0);
	static const struct {
		const char *name, *header;
	} files[] = {
	        {"trials.csv", "group,trial,outcome,type,steps,t_end,x_end,y_end,vx_end,max_theta1,"
	                       "max_theta2,e_start,e_end,work_in,losses,residual,overlap_max,"
	                       "final_ix,final_iy,location,path,"},
	        {"lattice_map.csv", "group,ix,iy,x_min,x_max,y_min,y_max,pivot_y,k_left,k_right\n"},
	        {"final_locations.csv", "group,location,kind,ix,iy,count,p,ci95_lo,ci95_hi\n"},
	        {"transitions.csv", "group,from_ix,from_iy,to_ix,to_iy,count\n"},
	        {"gate_entries.csv", "group,trial,seq,ix,iy,edge,step,t,pos,x,y,vx,vy,theta_left,"
	                             "omega_left,theta_right,omega_right\n"},
	        {"beam_peaks.csv", "group,trial,beam,ix,iy,side,max_theta\n"},
	};
	for (size_t k = 0; k < sizeof files / sizeof files[0]; k++) {
		char *x = read_in(out1, files[k].name), *y = read_in(out2, files[k].name);
		if (strncmp(x, files[k].header, strlen(files[k].header)))
			fail_msg("%s: header %.120s", files[k].name, x);
		assert_string_equal(x, y); /* threads change nothing */
		free(x);
		free(y);
	}
	/* 81 gates in the map, the C-track's soft gate (-3, 4) */
	char *map = read_in(out1, "lattice_map.csv");
	assert_int_equal(bsim_test_count_lines(map), 1 + 81);
	assert_non_null(strstr(map, "\n0,-3,4,-175,-125,240,300,270,100,100\n"));
	free(map);
	/* final locations add up to the trials */
	char *loc = read_in(out1, "final_locations.csv");
	int total = 0;
	for (const char *line = strchr(loc, '\n'); line && line[1]; line = strchr(line + 1, '\n')) {
		char count[32];
		csv_field(line + 1, 5, count, sizeof count);
		total += atoi(count);
	}
	assert_int_equal(total, 6);
	free(loc);
	/* each path in trials.csv is its trial's sequence of gate entries */
	char *trials = read_in(out1, "trials.csv"), *entries = read_in(out1, "gate_entries.csv");
	for (const char *line = strchr(trials, '\n'); line && line[1];
	     line = strchr(line + 1, '\n')) {
		char trial[16], path[2048], want[2048] = "";
		csv_field(line + 1, 1, trial, sizeof trial);
		csv_field(line + 1, 20, path, sizeof path);
		for (const char *e = strchr(entries, '\n'); e && e[1]; e = strchr(e + 1, '\n')) {
			char t[16], ix[16], iy[16];
			csv_field(e + 1, 1, t, sizeof t);
			if (strcmp(t, trial))
				continue;
			csv_field(e + 1, 3, ix, sizeof ix);
			csv_field(e + 1, 4, iy, sizeof iy);
			snprintf(want + strlen(want), sizeof want - strlen(want), "%s%s:%s",
			         want[0] ? " " : "", ix, iy);
		}
		assert_string_equal(path, want);
	}
	free(trials);
	free(entries);
	/* the summary carries the lattice's distribution */
	char *summary = read_in(out1, "summary.json");
	assert_non_null(strstr(summary, "\"final_locations\": [{\"location\": "));
	assert_non_null(strstr(summary, "\"rows\": [{\"iy\": 0, \"trials\": 6, "));
	free(summary);
}

/* The sweep prints the end / side / stuck split of the trials: the counts
 * of trials.csv's outcomes (end: traversed, side: side_exit), each with
 * its fraction and Wilson's 95% interval. */
static void sweep_prints_split(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("lat_split");
	char exp[1200], out[1300];
	snprintf(exp, sizeof exp, "%s", c_track_experiment(dir));
	snprintf(out, sizeof out, "%s/o", dir);
	const char *argv[] = {"sweep",    exp,  "--out", out, "--set", "integration.max_steps=2500",
	                      "--trials", "10", NULL};
	char *stdout_text = NULL;
	assert_int_equal(bsim_test_cli(argv, &stdout_text, NULL), 0);
	assert_non_null(stdout_text);
	int counts[3] = {0, 0, 0}, n = 0;
	static const char *const outcomes[] = {"traversed", "side_exit", "stuck"};
	char *trials = read_in(out, "trials.csv");
	for (const char *line = strchr(trials, '\n'); line && line[1];
	     line = strchr(line + 1, '\n')) {
		char outcome[32];
		csv_field(line + 1, 2, outcome, sizeof outcome);
		for (int k = 0; k < 3; k++)
			counts[k] += strcmp(outcome, outcomes[k]) == 0;
		n++;
	}
	free(trials);
	assert_int_equal(n, 10);
	static const char *const kinds[] = {"\n  end ", "\n  side ", "\n  stuck "};
	for (int k = 0; k < 3; k++) {
		const char *p = strstr(stdout_text, kinds[k]);
		if (!p)
			fail_msg("no '%s' line in:\n%s", kinds[k] + 1, stdout_text);
		int count, of;
		double f, lo, hi, wlo, whi;
		assert_int_equal(sscanf(p + strlen(kinds[k]), "%d of %d %lf [%lf, %lf]", &count,
		                        &of, &f, &lo, &hi),
		                 5);
		assert_int_equal(count, counts[k]);
		assert_int_equal(of, n);
		bsim_test_wilson(counts[k], n, &wlo, &whi);
		assert_true(f > (double)counts[k] / n - 6e-4 && f < (double)counts[k] / n + 6e-4);
		assert_true(lo > wlo - 6e-4 && lo < wlo + 6e-4);
		assert_true(hi > whi - 6e-4 && hi < whi + 6e-4);
	}
	free(stdout_text);
}

/* regress --exact reruns a stored lattice sweep (the map's CSV copied into
 * inputs/) to the same trials. */
static void regress_lattice(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("lat_regress");
	char exp[1200], base[1300], rerun[1300], csv[1400];
	snprintf(exp, sizeof exp, "%s", c_track_experiment(dir));
	snprintf(base, sizeof base, "%s/base", dir);
	snprintf(rerun, sizeof rerun, "%s/rerun", dir);
	const char *a[] = {"sweep", exp, "--out", base, "--quiet", NULL};
	assert_int_equal(run_ok(a), 0);
	snprintf(csv, sizeof csv, "%s/inputs/c_track.csv", base);
	char *copy = bsim_test_read(csv);
	assert_non_null(copy);
	free(copy);
	const char *r[] = {"regress", base, "--exact", "--out", rerun, "--quiet", NULL};
	assert_int_equal(run_ok(r), 0);
	char *md = read_in(rerun, "regress.md");
	assert_non_null(strstr(md, "0 of 6 trials changed"));
	free(md);
}

static void compare_protocols(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("lat_protocols");
	char exp[1200], out[1300], rerun[1300];
	snprintf(exp, sizeof exp, "%s", c_track_experiment(dir));
	snprintf(out, sizeof out, "%s/cmp", dir);
	snprintf(rerun, sizeof rerun, "%s/rerun", dir);
	const char *a[] = {"compare", exp, "--protocols", "world,essay",
	                   "--out",   out, "--quiet",     NULL};
	run_ok(a);
	char *md = read_in(out, "report.md");
	assert_non_null(strstr(md, "# beamsim compare: world vs essay"));
	assert_non_null(strstr(md, "## Final locations"));
	assert_non_null(strstr(md, "permutation p = "));
	free(md);
	char path[1400];
	snprintf(path, sizeof path, "%s/essay", out);
	char *t = read_in(path, "trials.csv");
	free(t);
	char *pairs = read_in(out, "pairs.csv");
	assert_non_null(strstr(pairs, ",t_separate,location_a,location_b\n"));
	free(pairs);
	/* both sides again, from the record */
	const char *r[] = {"regress", out, "--exact", "--out", rerun, "--quiet", NULL};
	assert_int_equal(run_ok(r), 0);
	char *rmd = read_in(rerun, "regress.md");
	assert_non_null(strstr(rmd, "## essay\n\n0 of 6 trials changed"));
	free(rmd);
	const char *bad[] = {"compare", exp, "--protocols", "world,world", "--out", out, NULL};
	char *err = NULL;
	assert_int_equal(bsim_test_cli(bad, NULL, &err), 2);
	assert_non_null(strstr(err, "--protocols world,world: expected two different"));
	free(err);
}

static void compare_backends_on_lattice(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("lat_backends");
	char exp[1200], out[1300];
	snprintf(exp, sizeof exp, "%s", c_track_experiment(dir));
	snprintf(out, sizeof out, "%s/cmp", dir);
	const char *a[] = {"compare", exp, "--trials", "3", "--out", out, "--quiet", NULL};
	run_ok(a);
	char *json = read_in(out, "report.json");
	assert_non_null(strstr(json, "\"final_location_test\": \"paired_permutation\""));
	assert_non_null(
	        strstr(json, "\"final_locations\": {\"test\": \"paired permutation, exact\""));
	free(json);
	char path[1400];
	snprintf(path, sizeof path, "%s/box2d", out);
	char *peaks = read_in(path, "beam_peaks.csv");
	assert_true(bsim_test_count_lines(peaks) > 1);
	free(peaks);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(map_wrong_rows),
	        cmocka_unit_test(map_wrong_columns),
	        cmocka_unit_test(map_and_beam_maps),
	        cmocka_unit_test(map_negative),
	        cmocka_unit_test(beam_negative),
	        cmocka_unit_test(csv_negative),
	        cmocka_unit_test(csv_wrong_shape),
	        cmocka_unit_test(empty_lattice),
	        cmocka_unit_test(lattice_and_beams),
	        cmocka_unit_test(bad_protocol),
	        cmocka_unit_test(sweep_writes_nothing),
	        cmocka_unit_test(sweep_files),
	        cmocka_unit_test(sweep_prints_split),
	        cmocka_unit_test(regress_lattice),
	        cmocka_unit_test(compare_protocols),
	        cmocka_unit_test(compare_backends_on_lattice),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
