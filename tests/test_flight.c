/* Free-flight runs (the thesis backend's advance in flight,
 * backends/thesis/thesis_flight.c, booked by the runner's runs of steps)
 * against the step loop they stand in for, which is the truth here: a
 * trial the runner books in runs gives the same result to the bit as the
 * same trial stepped one step at a time (a trace, which sees every step,
 * keeps the runner on the step loop; each of its steps is the step itself,
 * no state written, then get_state), and the thesis backend's runs leave
 * the body where its steps leave it. Each case counts the steps made in
 * runs with no beam listed (free flight's states), so that a case which
 * never took one fails rather than passes unseen: whole
 * trials in flight (ending at max_steps between two draws), flight then
 * the beams (H1), flight up to a beam's segment, a traversal and the run on to classify_y in
 * flight, a side exit, a state that stops being finite, and the pipelines with one force only. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "beamsim/backend.h"
#include "beamsim/scene.h"
#include "beamsim/trial.h"
#include "scenes.h"
#include "support.h"

static void no_trace(void *user, long step, const bsim_state *s)
{
	(void)user;
	(void)step;
	(void)s;
}

/* The trial of seed through runs (r) and stepped (r_step); returns the
 * steps the first made in runs. */
static long run_both(const bsim_scene *s, uint64_t seed, bsim_trial_result *r,
                     bsim_trial_result *r_step)
{
	bsim_backend counted = *bsim_test_backend("thesis");
	counted.advance = bsim_test_counted_advance;
	bsim_options o = {0};
	bsim_error err;
	bsim_trial_runner *runner = bsim_trial_runner_alloc();
	assert_non_null(runner);
	bsim_test_run_free = 0;
	assert_int_equal(bsim_trial_run(runner, s, &counted, &o, seed, NULL, r, &err), BSIM_OK);
	long made = bsim_test_run_free;
	bsim_recorder rec = {.stride = 1, .trace = no_trace};
	assert_int_equal(bsim_trial_run(runner, s, &counted, &o, seed, &rec, r_step, &err),
	                 BSIM_OK);
	assert_int_equal(bsim_test_run_free, made); /* the trace kept it on the step loop */
	bsim_trial_runner_free(runner);
	return made;
}

static void assert_same(const bsim_trial_result *a, const bsim_trial_result *b)
{
	assert_int_equal(a->outcome, b->outcome);
	assert_int_equal(a->steps_run, b->steps_run);
	assert_int_equal(a->instability, b->instability);
	assert_memory_equal(a, b, sizeof *a);
}

static void test_whole_trial_in_flight(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 7.0, 20.0);
	s.body.start[1] = -10000.0;
	s.side_x = 1e9;
	s.max_steps = 1003; /* ends two steps into a hold */
	for (uint64_t seed = 1; seed <= 3; seed++) {
		bsim_trial_result r, r_step;
		long made = run_both(&s, seed, &r, &r_step);
		assert_same(&r, &r_step);
		assert_int_equal(r.steps_run, 1003);
		/* every step: the first run prepares the beams, as the
		 * first step would */
		assert_int_equal(made, 1003);
		assert_true(r.draws > 200);
	}
	bsim_scene_free(&s);
}

/* Leaving the beams at 100 m/s from 100 m below them: the room the first
 * test finds is used up within a run, and the beams are tested again
 * (and found out of reach) there, as the step does. */
static void test_room_refilled_in_flight(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 7.0, 20.0);
	s.body.start[1] = -100.0;
	s.body.velocity[1] = -100.0;
	s.side_x = 1e9;
	s.max_steps = 2000;
	bsim_trial_result r, r_step;
	long made = run_both(&s, 3, &r, &r_step);
	assert_same(&r, &r_step);
	assert_int_equal(made, 2000);
	assert_true(r.y_end < -600.0); /* -100 - 100 t + 7 t^2 / 2 at t = 8 s: -676 m */
	bsim_scene_free(&s);
}

static void test_flight_then_beams(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 7.0, 20.0);
	long made = 0;
	for (uint64_t seed = 1; seed <= 8; seed++) {
		bsim_trial_result r, r_step;
		made += run_both(&s, seed, &r, &r_step);
		assert_same(&r, &r_step);
	}
	assert_true(made > 100);
	bsim_scene_free(&s);
}

/* Straight up the gate's midline at 10 m/s, no force: free flight lasts
 * until the body is within R + the step's margin (2 h |v| + slop + 6 mm,
 * 0.086 m) of a beam's segment, at y = 20 - 0.086 m, well inside the
 * pivots' discs (L + R + margin from a pivot, which it enters at y = 5.4):
 * every step from y = -50 to y = 19.9 is made in runs. */
static void test_flight_to_the_beams(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 0.0, 0.0);
	s.effects.has_propulsion = 0;
	s.body.start[1] = -50.0;
	s.body.velocity[1] = 10.0;
	s.max_steps = 1600; /* y = 14 at the end */
	bsim_trial_result r, r_step;
	long made = run_both(&s, 1, &r, &r_step);
	assert_same(&r, &r_step);
	assert_true(r.y_end > 13.9);
	assert_int_equal(made, 1600);
	s.max_steps = 2000; /* to y = 30: the beams met */
	made = run_both(&s, 1, &r, &r_step);
	assert_same(&r, &r_step);
	/* (19.9 + 50) / (10 m/s x 4 ms) = 1747 steps in flight at least */
	assert_true(made >= 1747);
	assert_true(made < 2000);
	bsim_scene_free(&s);
}

/* Above the beams, rising: success_y is crossed in a run, which goes on
 * to classify_y. */
static void test_traversal_in_flight(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 7.0, 20.0);
	s.body.start[1] = 70.0; /* its pivots farther than L + R */
	s.body.velocity[1] = 3.0;
	s.success_y = 75.0;
	s.classify_y = 90.0;
	bsim_trial_result r, r_step;
	long made = run_both(&s, 5, &r, &r_step);
	assert_same(&r, &r_step);
	assert_int_equal(r.outcome, BSIM_TRAVERSED);
	assert_true(r.steps < r.steps_run);
	/* every step in flight; the last run goes on past the trial's end by
	 * less than a run (64 steps) */
	assert_true(made >= r.steps_run && made < r.steps_run + 64);
	bsim_scene_free(&s);
}

static void test_side_exit_in_flight(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 7.0, 20.0);
	s.body.start[1] = -300.0;
	s.body.velocity[0] = 20.0;
	bsim_trial_result r, r_step;
	long made = run_both(&s, 2, &r, &r_step);
	assert_same(&r, &r_step);
	assert_int_equal(r.outcome, BSIM_SIDE_EXIT);
	assert_true(made >= r.steps_run && made < r.steps_run + 64);
	bsim_scene_free(&s);
}

/* The overflowing body of scene_gate_overflow: the fifth step, inside the
 * trial's first run, is not finite. */
static void test_nonfinite_in_flight(void **state)
{
	(void)state;
	bsim_scene s;
	scene_gate_overflow(&s);
	bsim_trial_result r, r_step;
	long made = run_both(&s, 1, &r, &r_step);
	assert_same(&r, &r_step);
	assert_int_equal(r.instability, BSIM_UNSTABLE_NONFINITE);
	assert_int_equal(r.unstable_step, 5);
	assert_true(made >= 5); /* made, not all kept: the world runs ahead */
	bsim_scene_free(&s);
}

/* Propulsion alone (no draws) and the random force alone. */
static void test_one_force(void **state)
{
	(void)state;
	const double forces[2][2] = {{7.0, 0.0}, {0.0, 20.0}};
	for (int k = 0; k < 2; k++) {
		bsim_scene s;
		bsim_scene_init_gate(&s, forces[k][0], forces[k][1]);
		s.body.start[1] = -10000.0;
		s.side_x = 1e9;
		s.max_steps = 500;
		bsim_trial_result r, r_step;
		long made = run_both(&s, 4, &r, &r_step);
		assert_same(&r, &r_step);
		assert_int_equal(made, 500);
		bsim_scene_free(&s);
	}
}

/* The backend alone: runs of 1 to 7 steps, their force changing within
 * them, leave the body where as many steps leave it, and a state as after
 * them. */
static void test_thesis_runs(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 7.0, 0.0);
	s.body.start[1] = -1000.0;
	bsim_options o = {0};
	bsim_error err;
	bsim_world *a, *b;
	const bsim_backend *t = bsim_test_backend("thesis");
	assert_int_equal(t->create(&s, &o, &a, &err), BSIM_OK);
	assert_int_equal(t->create(&s, &o, &b, &err), BSIM_OK);
	bsim_state sa, sb;
	assert_int_equal(bsim_state_init(&sa, s.n_beams), BSIM_OK);
	assert_int_equal(bsim_state_init(&sb, s.n_beams), BSIM_OK);
	const double h = 0.004;
	/* the lateral force turned over every second step, within a run */
	bsim_wrench f[7];
	for (int k = 0; k < 7; k++)
		f[k] = (bsim_wrench){{(k / 2) % 2 ? -1.5 : 1.5, 7.0}, 0.0};
	bsim_state run[7];
	for (int k = 0; k < 7; k++)
		assert_int_equal(bsim_state_init(&run[k], s.n_beams), BSIM_OK);
	/* unprepared for h: the run prepares the beams, as the step would */
	long steps = 0;
	for (int n = 1; n <= 7; n++) {
		int m;
		assert_int_equal(t->advance(b, f, h, n, run, &m, &err), BSIM_OK);
		assert_int_equal(m, n);
		for (int k = 0; k < n; k++) {
			assert_int_equal(bsim_backend_step(t, a, f[k].force, 0.0, h, &err),
			                 BSIM_OK);
			t->get_state(a, &sa);
			assert_memory_equal(sa.x, run[k].x, sizeof sa.x);
			assert_memory_equal(sa.v, run[k].v, sizeof sa.v);
			assert_memory_equal(&sa.heading, &run[k].heading, sizeof sa.heading);
			assert_memory_equal(&sa.energy, &run[k].energy, sizeof sa.energy);
			assert_memory_equal(&sa.solver, &run[k].solver, sizeof sa.solver);
			assert_int_equal(run[k].n_active, 0);
			assert_int_equal(run[k].impacts, 0);
		}
		steps += n;
		t->get_state(b, &sb);
		assert_memory_equal(sa.x, sb.x, sizeof sa.x);
		assert_memory_equal(sa.v, sb.v, sizeof sa.v);
		assert_memory_equal(&sa.energy, &sb.energy, sizeof sa.energy);
		assert_int_equal(sb.n_active, 0);
		assert_int_equal(sb.impacts, 0);
	}
	assert_int_equal(steps, 28);
	for (int k = 0; k < 7; k++)
		bsim_state_free(&run[k]);
	bsim_state_free(&sa);
	bsim_state_free(&sb);
	t->destroy(a);
	t->destroy(b);
	bsim_scene_free(&s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_whole_trial_in_flight),
	        cmocka_unit_test(test_room_refilled_in_flight),
	        cmocka_unit_test(test_flight_then_beams),
	        cmocka_unit_test(test_flight_to_the_beams),
	        cmocka_unit_test(test_traversal_in_flight),
	        cmocka_unit_test(test_side_exit_in_flight),
	        cmocka_unit_test(test_nonfinite_in_flight),
	        cmocka_unit_test(test_one_force),
	        cmocka_unit_test(test_thesis_runs),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
