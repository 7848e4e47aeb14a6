/* The thesis backend's contact_mode knob. physical (the default) keeps
 * every beam out of the body: the body's overlap with any beam stays within
 * the projection's slop (docs/model.md section 5, penetration below a stated
 * tolerance). essay reads the essay's flowchart literally: while one beam
 * is held in persistent contact, the others are not tested, so a beam can
 * pass into the body, but only while another beam is held; with a single
 * beam there is nothing to skip and the two modes are the same to the bit.
 * The ledger closes in both (the pass-through does no work). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "beamsim/schedule.h"
#include "beamsim/trial.h"
#include "support.h"

/* What a trace watches: the deepest overlap, and whether any step had a
 * beam deeper than tol in the body while no other beam touched it. */
typedef struct watch {
	const bsim_scene *s;
	double deepest;
	int unheld_overlaps; /* steps with an overlap but no other beam in contact */
	int overlap_steps;
} watch;

static double beam_overlap(const bsim_scene *s, int i, const bsim_state *st)
{
	const bsim_beam_def *b = &s->beams[i];
	double u0[2];
	bsim_scene_beam_rest_direction(b, u0);
	double cs = cos(st->theta[i]), sn = bsim_scene_beam_forward_sign(b) * sin(st->theta[i]);
	double u[2] = {u0[0] * cs - u0[1] * sn, u0[1] * cs + u0[0] * sn};
	double dx = st->x[0] - b->pivot[0], dy = st->x[1] - b->pivot[1];
	double along = fmin(fmax(dx * u[0] + dy * u[1], 0.0), b->length);
	return s->body.radius - hypot(dx - along * u[0], dy - along * u[1]);
}

static void watch_fn(void *user, long step, const bsim_state *st)
{
	watch *w = user;
	(void)step;
	for (int i = 0; i < st->n_beams; i++) {
		double o = beam_overlap(w->s, i, st);
		w->deepest = fmax(w->deepest, o);
		if (o <= 1e-3)
			continue;
		int other = 0;
		for (int j = 0; j < st->n_beams; j++)
			other |= j != i && st->contact[j] != BSIM_CONTACT_NONE;
		w->overlap_steps++;
		w->unheld_overlaps += !other;
	}
}

static bsim_trial_result run(const bsim_scene *s, const char *mode, uint64_t seed, watch *w)
{
	bsim_options o = {0};
	bsim_error err;
	char kv[64];
	snprintf(kv, sizeof kv, "contact_mode=%s", mode);
	assert_int_equal(bsim_options_add(&o, kv, &err), BSIM_OK);
	memset(w, 0, sizeof *w);
	w->s = s;
	bsim_recorder rec = {.stride = 1, .trace = watch_fn, .trace_user = w, .overlap = 1};
	bsim_trial_runner *r = bsim_trial_runner_alloc();
	bsim_trial_result out;
	assert_int_equal(
	        bsim_trial_run(r, s, bsim_test_backend("thesis"), &o, seed, &rec, &out, &err),
	        BSIM_OK);
	bsim_trial_runner_free(r);
	return out;
}

/* The essay's gate at F = 7 N, Rm = 10 N, 20 trials. */
static void test_pass_through(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 7.0, 10.0);
	double physical = 0.0, essay = 0.0;
	int essay_steps = 0;
	for (int t = 0; t < 20; t++) {
		uint64_t seed = bsim_schedule_seed_mix(1, 17, (uint64_t)t);
		watch w;
		bsim_trial_result r = run(&s, "physical", seed, &w);
		physical = fmax(physical, w.deepest);
		assert_float_equal(r.overlap_max, w.deepest, 1e-12); /* the runner's measure */
		assert_int_equal(r.outcome == BSIM_UNSTABLE, 0);
		assert_true(fabs(r.ledger.residual) < 1e-9);
		r = run(&s, "essay", seed, &w);
		essay = fmax(essay, w.deepest);
		essay_steps += w.overlap_steps;
		assert_int_equal(w.unheld_overlaps, 0);
		assert_int_equal(r.outcome == BSIM_UNSTABLE, 0);
		assert_true(fabs(r.ledger.residual) < 1e-9);
	}
	print_message("deepest overlap: physical %.3g m, essay %.3g m (%d steps in the body)\n",
	              physical, essay, essay_steps);
	assert_true(physical <= 2e-6); /* the slop, 1e-6 m, and round-off */
	assert_true(essay > 1.0);      /* beams through the body, metres deep */
	bsim_scene_free(&s);
}

/* One beam: no other beam to skip, the same trial to the bit. */
static void test_one_beam_same(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 7.0, 20.0);
	assert_int_equal(bsim_scene_set_beams(&s, 1), BSIM_OK);
	int touched = 0;
	for (int t = 0; t < 5; t++) {
		uint64_t seed = bsim_schedule_seed_mix(2, 0, (uint64_t)t);
		watch w;
		bsim_trial_result a = run(&s, "physical", seed, &w);
		bsim_trial_result b = run(&s, "essay", seed, &w);
		assert_true(a.steps_run > 0 && a.steps_run == b.steps_run);
		assert_true(a.x_end == b.x_end && a.y_end == b.y_end && a.vx_end == b.vx_end);
		assert_true(a.max_theta[0] == b.max_theta[0]);
		touched += a.max_theta[0] > 0.0;
	}
	assert_true(touched > 0); /* the beam was pushed, so contacts were solved */
	bsim_scene_free(&s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_pass_through),
	        cmocka_unit_test(test_one_beam_same),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
