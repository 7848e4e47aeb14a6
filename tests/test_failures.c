/* Failures said, per trial, and limits that hold (the program run on the
 * shipped scenes):
 *  - a scene file asking for a force of 1e25 N is refused at its time step
 *    (the body would cross light-years in one); the same scene built in
 *    code, and a mass of 1e-29 kg or a velocity of 1e25 m/s, is refused by
 *    the box2d backend naming the field, before float32 loses the body;
 *    the thesis backend, in double, runs it to its ordinary end (the body
 *    leaves the gate in one step, as x' = x + h^2 F / m says); a body
 *    within Box2D's skin is refused naming where the scene gave it;
 *  - a trial whose energy vanishes (Box2D clamping a 2 km/s body to
 *    b2_maxTranslation = 2 units a step: 500 m/s at h = 4 ms) is unstable,
 *    "energy vanished", exit 1 - never an ordinary outcome;
 *  - trials.csv says per trial how often the solver hit an iteration limit
 *    or a clamp, summary.json how many trials of each group did, and an
 *    older trials.csv without those columns still reads;
 *  - beam_steps counts every beam of a lattice (2 a gate), and a run that
 *    may take more than an hour says so, with its basis, before it starts. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "beamsim/backend.h"
#include "beamsim/output.h"
#include "beamsim/schedule.h"
#include "beamsim/sweep.h"
#include "beamsim/trial.h"
#include "beamsim/trial_fields.h"
#include "support.h"

static const char *gate(void)
{
	return bsim_test_src("configs/thesis/gate.yaml");
}

/* The essay's gate, loaded, with one field then set in code: a scene no
 * file can give (bsim_scene_load refuses it), which a program can still
 * hand to a backend. */
static void gate_with(bsim_scene *s, double force, double mass, double vy)
{
	bsim_error err;
	assert_int_equal(bsim_scene_load(gate(), NULL, 0, s, &err), BSIM_OK);
	s->effects.propulsion_force = force;
	s->body.mass = mass;
	s->body.velocity[1] = vy;
}

static void expect_box2d_refusal(const bsim_scene *s, const char *const needles[])
{
	bsim_world *w = NULL;
	bsim_error err;
	assert_int_equal(bsim_test_backend("box2d")->create(s, NULL, &w, &err), BSIM_EINPUT);
	assert_null(w);
	for (int i = 0; needles[i]; i++)
		if (!strstr(err.msg, needles[i]))
			fail_msg("\"%s\" lacks \"%s\"", err.msg, needles[i]);
}

/* A force of 1e25 N, a mass of 1e-29 kg, a velocity of 1e25 m/s: a step
 * of 4 ms moves the body light-years, so a scene file asking for them is
 * refused at its time step (the body's crossing), on either backend. A
 * program that builds such a scene and gives it to Box2D is refused by the
 * backend, naming the field, before float32 loses the body. */
static void test_box2d_force_refused(void **state)
{
	(void)state;
	const char *argv[] = {"run",   gate(),  "--backend",
	                      "box2d", "--set", "effects.propulsion.force=1e25",
	                      NULL};
	const char *needles[] = {"--set effects.propulsion.force=1e25: integration.dt: expected "
	                         "at most",
	                         "the body's crossing", NULL};
	bsim_test_expect_input_error(argv, needles);
	bsim_scene s;
	gate_with(&s, 1e25, 1.0, 0.0);
	const char *force[] = {"effects.propulsion.force: box2d: 1e+25 N",
	                       "beyond what Box2D's float32 can integrate", "usable up to", NULL};
	expect_box2d_refusal(&s, force);
	bsim_scene_free(&s);
	gate_with(&s, 7.0, 1e-29, 0.0);
	const char *mass[] = {"body.mass: box2d: 1e-29 kg", "usable down to", NULL};
	expect_box2d_refusal(&s, mass);
	bsim_scene_free(&s);
	gate_with(&s, 7.0, 1.0, 1e25);
	const char *vel[] = {"body.velocity.1: box2d: 1e+25 m/s", NULL};
	expect_box2d_refusal(&s, vel);
	bsim_scene_free(&s);
}

/* "FILE:LINE:" of the first line of text holding key, into buf. */
static void line_of(const char *file, const char *text, const char *key, char *buf, size_t size)
{
	const char *at = strstr(text, key);
	assert_non_null(at);
	int line = 1;
	for (const char *c = text; c < at; c++)
		line += *c == '\n';
	snprintf(buf, size, "%s:%d:", file, line);
}

/* Regression: a body within Box2D's skin (radius at most twice
 * b2_polygonRadius, 0.02 units at unit_scale 1, in float32) was refused as "group 0,
 * trial 0: box2d: ..." without saying where the radius came from. It is
 * said as a scene error is: the --set, the grid value, the set: line or the
 * scene file's line that gave the field, exit 2, before any trial (no
 * output directory), and a radius just past the skin runs. */
static void test_box2d_small_body_located(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("small_body");
	/* A step short enough for such a body (its crossing), so that the
	 * scene loads and Box2D is the one to refuse it. */
	const char *fine = "integration.dt=1e-5";
	const char *set[] = {"run",   gate(), "--backend", "box2d", "--set", "body.radius=0.019",
	                     "--set", fine,   NULL};
	const char *set_needles[] = {"--set body.radius=0.019: body.radius: box2d: 0.019 m",
	                             "expected more than 0.02 units", NULL};
	bsim_test_expect_input_error(set, set_needles);
	const char *past[] = {"run",       gate(),
	                      "--backend", "box2d",
	                      "--set",     "body.radius=0.0201",
	                      "--set",     fine,
	                      "--set",     "integration.max_steps=10",
	                      NULL};
	assert_int_equal(bsim_test_cli(past, NULL, NULL), 0);
	/* the scene file's line */
	char *text = bsim_test_read(gate());
	assert_non_null(text);
	char *small = malloc(strlen(text) + 16);
	assert_non_null(small);
	const char *r = strstr(text, "radius: 10.0");
	assert_non_null(r);
	snprintf(small, strlen(text) + 16, "%.*sradius: 0.001%s", (int)(r - text), text,
	         r + strlen("radius: 10.0"));
	char scene[1100], where[1200];
	snprintf(scene, sizeof scene, "%s", bsim_test_write(dir, "small.yaml", small));
	line_of(scene, small, "radius: 0.001", where, sizeof where);
	const char *file[] = {"run", scene, "--backend", "box2d", "--set", fine, NULL};
	const char *file_needles[] = {where, "body.radius: box2d: 0.001 m", NULL};
	bsim_test_expect_input_error(file, file_needles);
	/* an experiment's set: line, and a grid value of the command line */
	char exp_text[1400], exp[1100];
	snprintf(exp_text, sizeof exp_text,
	         "scene: %s\ntrials: 2\nseed: 1\nset:\n  body.radius: 0.001\n"
	         "  integration.dt: 1e-5\n  integration.duration: 0.01\n"
	         "grid:\n  effects.propulsion.force: [7, 8]\n",
	         gate());
	snprintf(exp, sizeof exp, "%s", bsim_test_write(dir, "exp.yaml", exp_text));
	line_of(exp, exp_text, "body.radius: 0.001", where, sizeof where);
	const char *out = bsim_test_join(dir, "out");
	const char *sweep[] = {"sweep", exp, "--backend", "box2d", "--out", out, NULL};
	const char *sweep_needles[] = {where, "body.radius: box2d: 0.001 m", NULL};
	bsim_test_expect_input_error(sweep, sweep_needles);
	const char *grid[] = {"sweep",     bsim_test_src("configs/thesis/h1_symmetric.yaml"),
	                      "--backend", "box2d",
	                      "--grid",    "body.radius=10,0.001",
	                      "--set",     fine,
	                      "--set",     "integration.duration=0.01",
	                      "--out",     out,
	                      NULL};
	const char *grid_needles[] = {"--grid body.radius=0.001: body.radius: box2d: 0.001 m",
	                              NULL};
	char *err = NULL;
	int rc = bsim_test_cli(grid, NULL, &err);
	bsim_test_check_input_error(rc, err, grid_needles, 1);
	assert_null(strstr(err, "group 0, trial 0"));
	free(err);
	assert_false(bsim_test_exists(out));
	free(small);
	free(text);
	bsim_test_remove(dir);
}

/* The thesis backend integrates in double: F = 1e25 N on 1 kg for one step
 * of 4 ms moves the body h^2 F / m = 1.6e20 m, far past success_y, and the
 * trial ends there, an ordinary outcome of a scene built in code. */
static void test_thesis_force_runs(void **state)
{
	(void)state;
	bsim_scene s;
	gate_with(&s, 1e25, 1.0, 0.0);
	bsim_trial_runner *r = bsim_trial_runner_alloc();
	assert_non_null(r);
	bsim_trial_result res;
	bsim_error err;
	assert_int_equal(bsim_trial_run(r, &s, bsim_test_backend("thesis"), NULL,
	                                bsim_schedule_seed_mix(1, 0, 0), NULL, &res, &err),
	                 BSIM_OK);
	assert_int_equal(res.outcome, BSIM_TRAVERSED);
	assert_int_equal(res.steps, 1);
	bsim_trial_runner_free(r);
	bsim_scene_free(&s);
}

/* Box2D clamps the translation to 2 units a step: a body started at
 * 2 km/s (2e6 J; 8 m a step of 4 ms, within its radius, so the scene is
 * valid) keeps at most 500 m/s (1.25e5 J), so nearly all the energy that
 * came in vanishes without a loss booked for it. */
static void test_box2d_clamp_unstable(void **state)
{
	(void)state;
	const char *argv[] = {"run",    gate(),  "--backend",
	                      "box2d",  "--set", "body.velocity.1=2000",
	                      "--json", NULL};
	char *out = NULL, *err = NULL;
	int rc = bsim_test_cli(argv, &out, &err);
	assert_int_equal(rc, 1);
	assert_non_null(strstr(out, "\"outcome\": \"unstable\""));
	assert_non_null(strstr(out, "energy vanished"));
	assert_true(bsim_test_json_number(out, "clamped") > 0);
	free(out);
	free(err);
}

/* The last eight fields of a trials.csv row of a one-axis grid:
 * iteration_limits, clamps, t_exit, the turn's four, the axis's value. */
static void row_tail(const char *row, long *limits, long *clamps)
{
	const char *end = strchr(row, '\n'), *p = end;
	assert_non_null(end);
	for (int commas = 0; commas < 8; commas++) {
		p--;
		while (p > row && *p != ',')
			p--;
	}
	assert_int_equal(sscanf(p, ",%ld,%ld,", limits, clamps), 2);
}

/* A slop of 0 asks the thesis backend's projection to leave no
 * penetration at all, which round-off does not allow: each persistent
 * contact's projection stops at its pass limit. The sweep's trials.csv has
 * each trial's count in its row, as run --json gives it for that trial,
 * and summary.json their sum and how many trials had one. */
static void test_solver_columns(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("solver_columns");
	char exp[512];
	snprintf(exp, sizeof exp,
	         "scene: %s\ntrials: 2\nseed: 1\ngrid:\n  effects.propulsion.force: [9]\n", gate());
	const char *path = bsim_test_write(dir, "exp.yaml", exp);
	const char *out_dir = bsim_test_join(dir, "out");
	const char *argv[] = {"sweep", path,    "--backend-opt", "thesis:slop=0",
	                      "--out", out_dir, "--quiet",       NULL};
	char *err = NULL;
	assert_int_equal(bsim_test_cli(argv, NULL, &err), 0);
	assert_non_null(strstr(err, "per trial, trials.csv: iteration_limits, clamps"));
	free(err);
	char *csv = bsim_test_read(bsim_test_join(out_dir, "trials.csv"));
	assert_non_null(csv);
	const char *header =
	        ",path,iteration_limits,clamps,t_exit,heading_end,angular_velocity_end,"
	        "turn_end,turn_max,effects.propulsion.force\n";
	const char *row = strstr(csv, header);
	assert_non_null(row);
	row += strlen(header);
	long sum = 0, hit = 0;
	for (int t = 0; t < 2; t++) {
		long limits = 0, clamps = -1;
		row_tail(row, &limits, &clamps);
		char trial[8];
		snprintf(trial, sizeof trial, "%d", t);
		const char *one[] = {"run",     path,  "--backend-opt", "thesis:slop=0",
		                     "--trial", trial, "--json",        NULL};
		char *out = NULL;
		assert_int_equal(bsim_test_cli(one, &out, NULL), 0);
		assert_int_equal(limits, (long)bsim_test_json_number(out, "iteration_limit"));
		free(out);
		assert_true(limits > 0);
		assert_int_equal(clamps, 0);
		sum += limits;
		hit += limits > 0;
		row = strchr(row, '\n') + 1;
	}
	free(csv);
	char *sum_json = bsim_test_read(bsim_test_join(out_dir, "summary.json"));
	assert_non_null(sum_json);
	assert_int_equal((long)bsim_test_json_number(sum_json, "iteration_limit"), sum);
	assert_int_equal((long)bsim_test_json_number(sum_json, "trials_iteration_limit"), hit);
	assert_int_equal((int)bsim_test_json_number(sum_json, "trials_clamped"), 0);
	free(sum_json);
	bsim_test_remove(dir);
}

/* Column c of a CSV line (no quoted fields before it), into out. */
static void csv_cell(const char *line, int c, char *out, size_t size)
{
	for (int k = 0; k < c && line; k++)
		line = strchr(line, ',') ? strchr(line, ',') + 1 : NULL;
	snprintf(out, size, "%.*s", line ? (int)strcspn(line, ",\n") : 0, line ? line : "");
}

/* trials.csv read back puts each column into the member it came from: a
 * sweep's file (the shape study's capsule, which turns, and the
 * C-track's, whose final gates are not 0),
 * read and written again from what was read, is the file, column by
 * column, but for the two the reader does not read (overlap_max; path,
 * which the result does not hold: without the trials' logs it is the
 * final gate) and the grid's, which the writer adds from the experiment. */
static void test_trials_csv_read_back(void **state)
{
	(void)state;
	static const char *const exps[] = {"configs/shape/study_capsule.yaml",
	                                   "configs/markov/c_track.yaml"};
	int n_fields;
	const bsim_trial_field *f = bsim_trial_fields(&n_fields);
	for (int i = 0; i < 2; i++) {
		char dir[1200], again[1400];
		snprintf(dir, sizeof dir, "%s",
		         bsim_test_dir(i ? "read_back_c" : "read_back_turn"));
		const char *argv[] = {
		        "sweep", bsim_test_src(exps[i]), "--trials", "3", "--quiet", "--out", dir,
		        NULL};
		int rc = bsim_test_cli(argv, NULL, NULL);
		assert_true(rc == 0);
		const char *path = bsim_test_join(dir, "trials.csv");
		char *text = bsim_test_read(path);
		assert_non_null(text);
		long rows = -1;
		for (const char *c = text; *c; c++)
			rows += *c == '\n';
		/* the file's shape: its last row's group + 1 groups of 3 trials */
		bsim_sweep_result r;
		bsim_error err;
		assert_int_equal(bsim_output_trials_read(path, (int)(rows / 3), 3, &r, &err),
		                 BSIM_OK);
		snprintf(again, sizeof again, "%s/again.csv", dir);
		assert_int_equal(bsim_output_trials_csv(again, NULL, &r, &err), BSIM_OK);
		bsim_sweep_result_free(&r);
		char *back = bsim_test_read(again);
		assert_non_null(back);
		const char *a = text, *b = back;
		for (long line = 1; *a && *b; line++) {
			for (int c = 0; c < n_fields; c++) {
				char x[256], y[256];
				if (strcmp(f[c].name, "overlap_max") == 0 ||
				    strcmp(f[c].name, "path") == 0)
					continue;
				csv_cell(a, c, x, sizeof x);
				csv_cell(b, c, y, sizeof y);
				if (strcmp(x, y) != 0)
					fail_msg("%s:%ld: %s: '%s' written, '%s' read back", path,
					         line, f[c].name, x, y);
			}
			a = strchr(a, '\n') + 1;
			b = strchr(b, '\n') + 1;
		}
		assert_true(!*a && !*b);
		free(text);
		free(back);
	}
}

/* A trials.csv written before the solver's columns reads, its counts 0;
 * one written before the turn's reads, its turn 0 and unknown (has_turn
 * 0, so that a comparison leaves it out); the turn's columns are read
 * back, and a file with some of them but not all is refused, naming the
 * file and the columns expected. */
static void test_old_trials_csv(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("old_csv");
	const char *path = bsim_test_write(
	        dir, "trials.csv",
	        "group,trial,outcome,type,steps,t_end,x_end,y_end,vx_end,max_theta1,max_theta2,"
	        "e_start,e_end,work_in,losses,residual,overlap_max,final_ix,final_iy,location,"
	        "path\n"
	        "0,0,stuck,none,3000,12,0,28.3,0,0.5,0.5,0,53.7,113.3,59.6,1e-12,,0,0,stuck:0:0,"
	        "0:0\n");
	bsim_sweep_result r;
	bsim_error err;
	assert_int_equal(bsim_output_trials_read(path, 1, 1, &r, &err), BSIM_OK);
	assert_int_equal(r.trials_out[0].outcome, BSIM_STUCK);
	assert_int_equal(r.trials_out[0].solver.iteration_limit, 0);
	assert_int_equal(r.trials_out[0].solver.clamped, 0);
	bsim_sweep_result_free(&r);
	path = bsim_test_write(
	        dir, "new.csv",
	        "group,trial,outcome,type,steps,t_end,x_end,y_end,vx_end,max_theta1,max_theta2,"
	        "e_start,e_end,work_in,losses,residual,overlap_max,final_ix,final_iy,location,"
	        "path,iteration_limits,clamps\n"
	        "0,0,side_exit,none,9,270,100,20,3,0.5,0.5,0,53.7,113.3,59.6,1e-12,,1,0,side:1,"
	        "0:0 1:0,7,2\n");
	assert_int_equal(bsim_output_trials_read(path, 1, 1, &r, &err), BSIM_OK);
	assert_int_equal(r.trials_out[0].solver.iteration_limit, 7);
	assert_int_equal(r.trials_out[0].solver.clamped, 2);
	assert_int_equal(r.has_turn, 0);
	assert_true(r.trials_out[0].heading_end == 0.0 && r.trials_out[0].turn_max == 0.0);
	bsim_sweep_result_free(&r);
	const char *turn_header =
	        "group,trial,outcome,type,steps,t_end,x_end,y_end,vx_end,max_theta1,max_theta2,"
	        "e_start,e_end,work_in,losses,residual,overlap_max,final_ix,final_iy,location,"
	        "path,iteration_limits,clamps,t_exit,heading_end,angular_velocity_end,turn_end,"
	        "turn_max\n";
	char text[1024];
	snprintf(text, sizeof text, "%s%s", turn_header,
	         "0,0,stuck,none,3000,12,0,28.3,0,0.5,0.5,0,53.7,113.3,59.6,1e-12,,0,0,stuck:0:0,"
	         "0:0,0,0,,2.25,-0.125,0.6792036732,1.5\n");
	path = bsim_test_write(dir, "turn.csv", text);
	assert_int_equal(bsim_output_trials_read(path, 1, 1, &r, &err), BSIM_OK);
	assert_int_equal(r.has_turn, 1);
	assert_true(r.trials_out[0].heading_end == 2.25);
	assert_true(r.trials_out[0].angular_velocity_end == -0.125);
	assert_true(r.trials_out[0].turn_end == 0.6792036732);
	assert_true(r.trials_out[0].turn_max == 1.5);
	bsim_sweep_result_free(&r);
	/* turn_max dropped from the header and the row */
	snprintf(text, sizeof text, "%.*s\n%s", (int)(strlen(turn_header) - strlen(",turn_max\n")),
	         turn_header,
	         "0,0,stuck,none,3000,12,0,28.3,0,0.5,0.5,0,53.7,113.3,59.6,1e-12,,0,0,stuck:0:0,"
	         "0:0,0,0,,2.25,-0.125,0.6792036732\n");
	path = bsim_test_write(dir, "part.csv", text);
	assert_int_equal(bsim_output_trials_read(path, 1, 1, &r, &err), BSIM_EINPUT);
	assert_non_null(strstr(err.msg, path));
	assert_non_null(strstr(err.msg, "heading_end, angular_velocity_end, turn_end, turn_max all "
	                                "or none"));
	bsim_test_remove(dir);
}

/* beam_steps counts the lattice's every beam: 9 x 9 gates of 2 beams,
 * 162, times 54,000 steps = 8.75e6; and 333 x 300 gates on Box2D, 199,800
 * beams, refused at the default limit (it ran 0.21 s a step). */
static void test_lattice_beam_steps(void **state)
{
	(void)state;
	const char *lattice = bsim_test_src("configs/lattice/uniform_9x9.yaml");
	const char *argv[] = {"run", lattice, "--limit", "beam_steps=1000000", NULL};
	/* The limit names the key the scene gives the length by. */
	const char *needles[] = {"uniform_9x9.yaml:17:37: integration.duration: expected at most "
	                         "1000000 beam-steps",
	                         "got 8.75e+06 = 54000 steps x 162 beams (a 9 x 9 lattice", NULL};
	bsim_test_expect_input_error(argv, needles);
	const char *big[] = {"run",       lattice,
	                     "--backend", "box2d",
	                     "--set",     "integration.max_steps=3000",
	                     "--set",     "lattice.columns=333",
	                     "--set",     "lattice.rows=300",
	                     "--set",     "termination.side_x=10000",
	                     NULL};
	const char *big_needles[] = {"lattice.rows: expected at most 100000000 beam-steps",
	                             "= 3000 steps x 199800 beams (a 333 x 300 lattice", NULL};
	bsim_test_expect_input_error(big, big_needles);
}

/* H1 on Box2D with max_steps 10^6: 6 groups without random force run one
 * trial, 24 with it 100 each: 2406 x 10^6 x 2 beams = 4.81e9 beam-steps,
 * 1.4 hours at the stated 1050 ns. The line comes before the output
 * directory is opened (which /proc refuses, so nothing runs), from the
 * run's own plan (bsim_sweep_plan_for). */
static void test_estimate_line(void **state)
{
	(void)state;
	const char *argv[] = {"sweep",     bsim_test_src("configs/thesis/h1_symmetric.yaml"),
	                      "--backend", "box2d",
	                      "--set",     "integration.max_steps=1000000",
	                      "--limit",   "beam_steps=1e12",
	                      "--out",     "/proc/beamsim-none",
	                      NULL};
	char *err = NULL;
	int rc = bsim_test_cli(argv, NULL, &err);
	assert_int_equal(rc, 2);
	assert_non_null(strstr(err, "note: this run may take up to about 1.4 hours of one core: "
	                            "at most 4.81e+09 beam-steps"));
	assert_non_null(strstr(err, "1050 ns a beam-step on box2d"));
	free(err);
	/* A comparison of thesis and box2d: both sides run every trial, at the
	 * costlier box2d's constant, 2 x 4.81e9 beam-steps, said before the
	 * output directory is opened. */
	const char *cmp[] = {"compare", bsim_test_src("configs/thesis/h1_symmetric.yaml"),
	                     "--set",   "integration.max_steps=1000000",
	                     "--limit", "beam_steps=1e13",
	                     "--out",   "/proc/beamsim-none",
	                     NULL};
	rc = bsim_test_cli(cmp, NULL, &err);
	assert_int_equal(rc, 2);
	assert_non_null(strstr(err, "note: this run may take up to about 2.81 hours of one core: "
	                            "at most 9.62e+09 beam-steps"));
	assert_non_null(strstr(err, "1050 ns a beam-step on box2d"));
	free(err);
	/* The same on the thesis backend at its default steps: no line. */
	const char *quiet[] = {"sweep", bsim_test_src("configs/thesis/h1_symmetric.yaml"), "--out",
	                       "/proc/beamsim-none", NULL};
	rc = bsim_test_cli(quiet, NULL, &err);
	assert_int_equal(rc, 2);
	assert_null(strstr(err, "note:"));
	free(err);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_box2d_force_refused),
	        cmocka_unit_test(test_box2d_small_body_located),
	        cmocka_unit_test(test_thesis_force_runs),
	        cmocka_unit_test(test_box2d_clamp_unstable),
	        cmocka_unit_test(test_solver_columns),
	        cmocka_unit_test(test_old_trials_csv),
	        cmocka_unit_test(test_trials_csv_read_back),
	        cmocka_unit_test(test_lattice_beam_steps),
	        cmocka_unit_test(test_estimate_line),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
