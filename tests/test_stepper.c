/* A world stepped by hand (beamsim/stepper.h), on every backend: under the
 * scene's effects and a trial's seed it makes that trial's steps as the
 * runner makes them, to the bit (the runner's result and every state its
 * trace sees); a held force on a free body gives the body the impulse's
 * velocity (momentum: v_n = v_0 + n h F / M); a reset starts the same steps
 * again; a refused scene or option is said. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "support.h"

#include "beamsim/beamsim.h"

/* The states a traced trial saw, one per step. */
typedef struct seen {
	long n, cap;
	bsim_state *s;
} seen;

static void trace_keep(void *user, long step, const bsim_state *s)
{
	seen *t = user;
	if (step == 0)
		return;
	if (t->n == t->cap) {
		t->cap = t->cap ? 2 * t->cap : 1024;
		t->s = realloc(t->s, (size_t)t->cap * sizeof *t->s);
		assert_non_null(t->s);
	}
	bsim_state *k = &t->s[t->n++];
	assert_int_equal(bsim_state_init(k, s->n_beams), BSIM_OK);
	bsim_state_copy(k, s);
}

/* The same state to the bit: body, every beam's angle, velocity, flag,
 * touch and impulse, and the step's energy flows. */
static void assert_same_state(const bsim_state *a, const bsim_state *b, long step)
{
	int same = memcmp(a->x, b->x, sizeof a->x) == 0 && memcmp(a->v, b->v, sizeof a->v) == 0 &&
	           a->heading == b->heading && a->angular_velocity == b->angular_velocity &&
	           memcmp(&a->energy, &b->energy, sizeof a->energy) == 0;
	for (int i = 0; same && i < a->n_beams; i++)
		same = a->theta[i] == b->theta[i] && a->omega[i] == b->omega[i] &&
		       a->contact[i] == b->contact[i];
	if (!same)
		fail_msg("step %ld: the stepped world's state differs from the trial's: x (%.17g, "
		         "%.17g) against (%.17g, %.17g)",
		         step, a->x[0], a->x[1], b->x[0], b->x[1]);
}

/* Trial t of group g of the experiment (by the library's replay), on b:
 * the runner's result without a trace (its runs of steps) and with one
 * (every state), against a stepper of the trial's scene and mixed seed. */
static long reproduce(const bsim_backend *b, const char *experiment, long g, long t,
                      void (*edit)(bsim_scene *))
{
	bsim_replay_def def = bsim_replay_def_default();
	def.path = experiment;
	def.group = g;
	def.trial = t;
	bsim_replay *rp;
	bsim_error err;
	assert_int_equal(bsim_replay_open(&def, &rp, &err), BSIM_OK);
	if (edit)
		edit(&rp->scene);
	char field[64];
	if (b->check && b->check(&rp->scene, NULL, field, sizeof field, &err) != BSIM_OK) {
		bsim_replay_free(rp);
		bsim_test_skip(b, "it refuses the scene: %s", err.msg);
	}
	bsim_trial_runner *r = bsim_trial_runner_alloc();
	bsim_trial_result plain, traced;
	assert_int_equal(bsim_trial_run(r, &rp->scene, b, NULL, rp->mixed_seed, NULL, &plain, &err),
	                 BSIM_OK);
	seen kept = {0};
	bsim_recorder rec = {.trace = trace_keep, .trace_user = &kept};
	assert_int_equal(
	        bsim_trial_run(r, &rp->scene, b, NULL, rp->mixed_seed, &rec, &traced, &err),
	        BSIM_OK);
	bsim_trial_runner_free(r);
	/* every step the trial made: to its outcome (steps), and on to the
	 * line that classifies a traversal */
	assert_int_equal(plain.steps, traced.steps);
	assert_true(kept.n >= plain.steps);

	bsim_stepper_def sd = bsim_stepper_def_default();
	sd.scene = &rp->scene;
	sd.backend = b;
	sd.seed = rp->mixed_seed;
	bsim_stepper *s;
	assert_int_equal(bsim_stepper_alloc(&sd, &s, &err), BSIM_OK);
	for (long k = 0; k < kept.n; k++) {
		assert_int_equal(bsim_stepper_step(s, 1, &err), BSIM_OK);
		assert_same_state(bsim_stepper_state(s), &kept.s[k], k + 1);
	}
	const bsim_state *end = bsim_stepper_state(s);
	if (!(end->x[0] == plain.x_end && end->x[1] == plain.y_end && end->v[0] == plain.vx_end))
		fail_msg("the trial ends at (%.17g, %.17g), the stepped world at (%.17g, %.17g)",
		         plain.x_end, plain.y_end, end->x[0], end->x[1]);
	/* back to the start: the same steps again, n at a time */
	assert_int_equal(bsim_stepper_reset(s, &err), BSIM_OK);
	assert_int_equal(bsim_stepper_steps(s), 0);
	assert_int_equal(bsim_stepper_step(s, kept.n, &err), BSIM_OK);
	assert_same_state(bsim_stepper_state(s), &kept.s[kept.n - 1], kept.n);
	bsim_stepper_free(s);
	for (long k = 0; k < kept.n; k++)
		bsim_state_free(&kept.s[k]);
	free(kept.s);
	bsim_replay_free(rp);
	return kept.n;
}

/* H1's trials: propulsion and the held random force, contact, traversal or
 * not. */
static void test_trial(void **state)
{
	const bsim_backend *b = *state;
	const char *h1 = bsim_test_src("configs/thesis/h1_symmetric.yaml");
	long steps = 0;
	for (long g = 6; g < 30; g += 11)
		for (long t = 0; t < 2; t++)
			steps += reproduce(b, h1, g, t, NULL);
	print_message("%s: %ld steps of 6 H1 trials stepped by hand, each state the trial's\n",
	              b->name, steps);
}

/* Effects that read the state: drag, ground friction and an oscillating
 * force, besides H1's. */
static void add_state_effects(bsim_scene *s)
{
	s->effects.has_drag = 1;
	s->effects.drag_linear = 0.3;
	s->effects.has_ground_friction = 1;
	s->effects.ground_mu = 0.05;
	s->effects.has_oscillation = 1;
	s->effects.osc_amplitude = 2.0;
	s->effects.osc_frequency = 0.7;
}

static void test_state_effects(void **state)
{
	const bsim_backend *b = *state;
	long steps = reproduce(b, bsim_test_src("configs/thesis/h1_symmetric.yaml"), 17, 1,
	                       add_state_effects);
	print_message("%s: %ld steps under drag, ground friction and oscillation\n", b->name,
	              steps);
}

/* A held force on a body far from the beams: v_n = v_0 + n h F / M. */
static void test_push(void **state)
{
	const bsim_backend *b = *state;
	bsim_scene scene;
	bsim_scene_init_gate(&scene, 0.0, 0.0);
	scene.body.start[0] = 500.0;
	scene.body.velocity[0] = 1.5;
	bsim_stepper_def sd = bsim_stepper_def_default();
	sd.scene = &scene;
	sd.backend = b;
	bsim_stepper *s;
	bsim_error err;
	assert_int_equal(bsim_stepper_alloc(&sd, &s, &err), BSIM_OK);
	const double f[2] = {-3.0, 7.0};
	const long n = 250;
	assert_int_equal(bsim_stepper_push(s, f, 0.0, n, &err), BSIM_OK);
	const bsim_state *st = bsim_stepper_state(s);
	double h = scene.dt, m = scene.body.mass;
	double vx = 1.5 + n * h * f[0] / m, vy = n * h * f[1] / m;
	double worst = fmax(fabs(st->v[0] - vx) / fabs(vx), fabs(st->v[1] - vy) / fabs(vy));
	print_message("%s: a held force for %ld steps, velocity off the impulse's by %.2g "
	              "relative\n",
	              b->name, n, worst);
	assert_true(worst < 1e-5); /* float32 on Box2D */
	double w[3];
	bsim_stepper_wrench(s, w);
	assert_true(w[0] == f[0] && w[1] == f[1] && w[2] == 0.0);
	assert_int_equal(bsim_stepper_steps(s), n);
	double kin, elastic;
	bsim_stepper_energy(s, &kin, &elastic);
	assert_true(fabs(kin - 0.5 * m * (st->v[0] * st->v[0] + st->v[1] * st->v[1])) <=
	            1e-12 * kin);
	assert_true(elastic == 0.0);
	bsim_stepper_free(s);
	bsim_scene_free(&scene);
}

/* An option the backend does not have is refused with its message;
 * nothing is left to free. */
static void test_refused(void **state)
{
	const bsim_backend *b = *state;
	bsim_scene scene;
	bsim_scene_init_gate(&scene, 5.0, 0.0);
	bsim_options opts;
	memset(&opts, 0, sizeof opts);
	bsim_error err;
	assert_int_equal(bsim_options_add(&opts, "no_such_knob=1", &err), BSIM_OK);
	bsim_stepper_def sd = bsim_stepper_def_default();
	sd.scene = &scene;
	sd.backend = b;
	sd.opts = &opts;
	bsim_stepper *s = (bsim_stepper *)&sd; /* set to NULL on failure */
	assert_int_equal(bsim_stepper_alloc(&sd, &s, &err), BSIM_EINPUT);
	assert_null(s);
	assert_non_null(strstr(err.msg, "no_such_knob"));
	bsim_scene_free(&scene);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_trial),
	        cmocka_unit_test(test_state_effects),
	        cmocka_unit_test(test_push),
	        cmocka_unit_test(test_refused),
	};
	return bsim_test_run_per_backend("stepper", tests, sizeof tests / sizeof tests[0]);
}
