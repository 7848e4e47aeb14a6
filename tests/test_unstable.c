/* The runner's verdict on a failing backend, with backends built to fail
 * in a known way: one whose state turns NaN at a given step, one that
 * creates energy (a body speeding up with no force), one that loses most
 * of it (a body slowing down fast with no force) and one that loses a
 * third. The first three are unstable, with the reason and the last finite
 * state; the fourth is an ordinary outcome (energy lost within
 * BSIM_LEDGER_LOST_BOUND is inaccuracy, not instability). A backend whose step
 * fails (out of memory) makes the trial an error, never a result; one
 * whose solvers count what they gave up on has its counts in the result. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "beamsim/schedule.h"
#include "beamsim/sweep.h"
#include "beamsim/trial.h"

/* A body alone: the beams never move. kind 0: NaN at step 10; 1: speed
 * grows by 1% a step; 2: speed falls by 1% a step; 3: the step fails at
 * step 7; 4: every third step a solve reaches its limit, every step two
 * substeps are clamped; 5: speed falls by 0.1% a step. */
struct bsim_world {
	int kind, n_beams;
	long step;
	double x[2], v[2];
	bsim_solver_counts solver;
};

static int kind_of(const bsim_options *o)
{
	const char *v = bsim_options_get(o, "kind");
	return v ? atoi(v) : 0;
}

static int fake_create(const bsim_scene *s, const bsim_options *o, bsim_world **out,
                       bsim_error *err)
{
	(void)err;
	bsim_world *w = calloc(1, sizeof *w);
	w->kind = kind_of(o);
	w->n_beams = s->n_beams;
	memcpy(w->x, s->body.start, sizeof w->x);
	w->v[1] = 1.0; /* 1 m/s forward: 0.5 J */
	*out = w;
	return BSIM_OK;
}

static void fake_destroy(bsim_world *w)
{
	free(w);
}

static int fake_step(bsim_world *w, const double force[2], double torque, double h, bsim_error *err)
{
	(void)force; /* the scene below has no forces */
	(void)torque;
	w->step++;
	if (w->kind == 3 && w->step == 7)
		return bsim_error_set(err, BSIM_EFAIL, "fake: out of memory at step 7");
	if (w->kind == 4) {
		w->solver.iteration_limit += w->step % 3 == 0;
		w->solver.clamped += 2;
	}
	double f = w->kind == 1 ? 1.01 : w->kind == 2 ? 0.99 : w->kind == 5 ? 0.999 : 1.0;
	w->v[1] *= f;
	w->x[1] += h * w->v[1];
	if (w->kind == 0 && w->step == 10)
		w->x[0] = NAN;
	return BSIM_OK;
}

static void fake_get_state(const bsim_world *w, bsim_state *s)
{
	memcpy(s->x, w->x, sizeof s->x);
	memcpy(s->v, w->v, sizeof s->v);
	for (int i = 0; i < s->n_beams; i++) {
		s->theta[i] = s->omega[i] = 0.0;
		s->contact[i] = 0;
	}
	memset(&s->energy, 0, sizeof s->energy);
	s->solver = w->solver;
}

/* advance: the steps one by one, each state read after its step */
static int fake_advance(bsim_world *w, const bsim_wrench *schedule, double h, int n,
                        bsim_state *out, int *made, bsim_error *err)
{
	return bsim_backend_advance_each(w, fake_step, fake_get_state, schedule, h, n, out, made,
	                                 err);
}

static const bsim_knob fake_knobs[] = {{"kind", BSIM_KNOB_INT, "0", NULL, "how it fails"}};

static const bsim_backend fake = {
        .name = "fake",
        .knobs = fake_knobs,
        .n_knobs = 1,
        .create = fake_create,
        .destroy = fake_destroy,
        .advance = fake_advance,
        .get_state = fake_get_state,
};

static bsim_trial_result run(int kind)
{
	bsim_scene s;
	bsim_scene_init_gate(&s, 0.0, 0.0);
	s.effects.has_propulsion = 0;
	s.max_steps = 200;
	bsim_options o = {0};
	bsim_error err;
	char kv[16];
	snprintf(kv, sizeof kv, "kind=%d", kind);
	assert_int_equal(bsim_options_add(&o, kv, &err), BSIM_OK);
	bsim_trial_runner *r = bsim_trial_runner_alloc();
	bsim_trial_result out;
	assert_int_equal(bsim_trial_run(r, &s, &fake, &o, 1, NULL, &out, &err), BSIM_OK);
	bsim_trial_runner_free(r);
	bsim_scene_free(&s);
	return out;
}

static void test_nonfinite(void **state)
{
	(void)state;
	bsim_trial_result r = run(0);
	assert_int_equal(r.outcome, BSIM_UNSTABLE);
	assert_int_equal(r.instability, BSIM_UNSTABLE_NONFINITE);
	assert_int_equal(r.unstable_step, 10);
	assert_int_equal(r.steps_run, 9); /* the last finite state is reported */
	assert_true(isfinite(r.x_end) && isfinite(r.y_end) && isfinite(r.ledger.e_end));
	char why[256];
	bsim_trial_instability_text(&r, 0.004, why, sizeof why);
	assert_string_equal(why, "non-finite state at step 10 (t = 0.04 s)");
}

/* 1% a step for 200 steps: E grows by 1.01^400 = 53 times from 0.5 J with
 * nothing flowing in but the 0.5 J it started with. */
static void test_energy_created(void **state)
{
	(void)state;
	bsim_trial_result r = run(1);
	assert_int_equal(r.outcome, BSIM_UNSTABLE);
	assert_int_equal(r.instability, BSIM_UNSTABLE_ENERGY);
	assert_float_equal(r.ledger.e_start, 0.5, 1e-15);
	assert_float_equal(r.ledger.inflow, 0.5, 1e-15);
	assert_float_equal(r.ledger.e_end, 0.5 * pow(1.01, 400), 1e-9);
	assert_float_equal(r.ledger.residual, r.ledger.e_end - r.ledger.e_start, 1e-9);
	char why[256];
	bsim_trial_instability_text(&r, 0.004, why, sizeof why);
	assert_non_null(strstr(why, "energy created: ledger residual"));
}

/* 1% a step for 200 steps: E falls to 0.99^400 = 1.8% of the 0.5 J that
 * flowed in, 98% of it vanished with no loss booked: beyond the bound of
 * 75%, unstable, and the reason says which side. */
static void test_energy_vanished(void **state)
{
	(void)state;
	bsim_trial_result r = run(2);
	assert_int_equal(r.outcome, BSIM_UNSTABLE);
	assert_int_equal(r.instability, BSIM_UNSTABLE_ENERGY_LOST);
	assert_float_equal(r.ledger.inflow, 0.5, 1e-15);
	assert_float_equal(r.ledger.e_end, 0.5 * pow(0.99, 400), 1e-9);
	assert_float_equal(r.ledger.residual, r.ledger.e_end - 0.5, 1e-9);
	char why[256];
	bsim_trial_instability_text(&r, 0.004, why, sizeof why);
	assert_non_null(strstr(why, "energy vanished: ledger residual -0.491 J < -0.75 x 0.5 J"));
}

/* 0.1% a step: E falls to 0.999^400 = 67% of 0.5 J, a third vanished:
 * inaccuracy within the bound, an ordinary outcome. */
static void test_energy_lost(void **state)
{
	(void)state;
	bsim_trial_result r = run(5);
	assert_int_equal(r.outcome, BSIM_STUCK);
	assert_int_equal(r.instability, BSIM_STABLE);
	assert_float_equal(r.ledger.e_end, 0.5 * pow(0.999, 400), 1e-9);
	assert_true(r.ledger.residual < -0.3 * r.ledger.inflow);
}

static void test_step_fails(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 0.0, 0.0);
	s.effects.has_propulsion = 0;
	s.max_steps = 200;
	bsim_options o = {0};
	bsim_error err;
	assert_int_equal(bsim_options_add(&o, "kind=3", &err), BSIM_OK);
	bsim_trial_runner *r = bsim_trial_runner_alloc();
	bsim_trial_result out;
	assert_int_equal(bsim_trial_run(r, &s, &fake, &o, 1, NULL, &out, &err), BSIM_EFAIL);
	assert_string_equal(err.msg, "fake: out of memory at step 7");
	bsim_trial_runner_free(r);
	bsim_scene_free(&s);
}

/* 200 steps: 66 of them a multiple of 3, two clamped substeps each. */
static void test_solver_counts(void **state)
{
	(void)state;
	bsim_trial_result r = run(4);
	assert_int_equal(r.steps_run, 200);
	assert_int_equal(r.solver.iteration_limit, 66);
	assert_int_equal(r.solver.clamped, 400);
	bsim_group_result g;
	bsim_trial_result two[2] = {r, r};
	bsim_sweep_group_aggregate(two, 2, &g);
	assert_int_equal(g.solver.iteration_limit, 132);
	assert_int_equal(g.solver.clamped, 800);
}

/* A value no schedule reaches is 0 and the schedule's status fails, naming
 * it: never a NaN. */
static void test_schedule_status(void **state)
{
	(void)state;
	bsim_schedule *s = bsim_schedule_alloc(20.0, 50.0, 7);
	bsim_error err;
	assert_non_null(s);
	assert_true(isfinite(bsim_schedule_value(s, 3)));
	assert_int_equal(bsim_schedule_status(s, &err), BSIM_OK);
	assert_true(bsim_schedule_value(s, -1) == 0.0);
	assert_int_equal(bsim_schedule_status(s, &err), BSIM_EFAIL);
	assert_non_null(strstr(err.msg, "value -1"));
	bsim_schedule_reset(s, 20.0, 7);
	assert_int_equal(bsim_schedule_status(s, &err), BSIM_OK);
	bsim_schedule_free(s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_nonfinite),       cmocka_unit_test(test_energy_created),
	        cmocka_unit_test(test_energy_vanished), cmocka_unit_test(test_energy_lost),
	        cmocka_unit_test(test_step_fails),      cmocka_unit_test(test_solver_counts),
	        cmocka_unit_test(test_schedule_status),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
