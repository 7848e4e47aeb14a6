/* The one call that moves a world (bsim_backend.advance), on every backend
 * of the registry: its contract is that each step of a call for many steps
 * is the step a call for one step makes, to the bit, whatever path the
 * backend takes for it. The truth here is the backend's own single step:
 * two worlds of one scene take the same forces, one a step at a time
 * (advance of one step, no state written, then get_state), the other in
 * calls for 1 to 64 steps under a schedule whose lateral force changes
 * every 1 to 8 steps (as the runner's schedules change at the random
 * force's draws), the rest asked again where a call makes fewer; every
 * state of the calls must be the stepped one to the bit (body, listed
 * beams, angles, velocities, touched beams, the direction of each beam the
 * runner's flag reads, energy flows, impacts, solver counts). The scene:
 * the essay's gate at three of H1's propulsions, the body from its start
 * below the beams through them (free flight, impacts, resting contact).
 * The test counts the states it compared and those with a contact flag,
 * so that a run that never reached the beams fails rather than passes. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "beamsim/contact_flag.h"
#include "support.h"

#define CALL_MAX 64

/* the test's own forces, reproducible */
static uint64_t rng_state;

static double rng_uniform(void)
{
	return bsim_test_uniform(&rng_state);
}

static void assert_same(const bsim_backend *be, const bsim_state *a, const bsim_state *b, long step)
{
	if (memcmp(a->x, b->x, sizeof a->x) || memcmp(a->v, b->v, sizeof a->v))
		fail_msg("%s step %ld: body (%.17g, %.17g) against (%.17g, %.17g) stepped",
		         be->name, step, b->x[0], b->x[1], a->x[0], a->x[1]);
	assert_memory_equal(&a->heading, &b->heading, sizeof a->heading);
	assert_memory_equal(&a->angular_velocity, &b->angular_velocity, sizeof a->heading);
	if (a->n_active != b->n_active)
		fail_msg("%s step %ld: %d beams listed against %d stepped", be->name, step,
		         b->n_active, a->n_active);
	assert_memory_equal(a->active, b->active, (size_t)a->n_active * sizeof *a->active);
	for (int k = 0; k < a->n_active; k++) {
		const int i = a->active[k];
		if (memcmp(&a->theta[i], &b->theta[i], sizeof a->theta[i]) ||
		    memcmp(&a->omega[i], &b->omega[i], sizeof a->omega[i]))
			fail_msg("%s step %ld beam %d: theta %.17g omega %.17g against %.17g %.17g",
			         be->name, step, i, b->theta[i], b->omega[i], a->theta[i],
			         a->omega[i]);
		assert_int_equal(a->touched[i], b->touched[i]);
		assert_memory_equal(&a->impulse[i], &b->impulse[i], sizeof a->impulse[i]);
		assert_int_equal(a->contact[i], b->contact[i]);
		if (a->contact[i] != BSIM_CONTACT_NONE)
			assert_memory_equal(&a->direction[2 * i], &b->direction[2 * i],
			                    2 * sizeof *a->direction);
		if (!be->exact_pins)
			assert_memory_equal(&a->pin[2 * i], &b->pin[2 * i], 2 * sizeof *a->pin);
	}
	if (memcmp(&a->energy, &b->energy, sizeof a->energy))
		fail_msg("%s step %ld: energy flows differ (damper %.17g against %.17g)", be->name,
		         step, b->energy.damper, a->energy.damper);
	assert_int_equal(a->impacts, b->impacts);
	assert_memory_equal(&a->solver, &b->solver, sizeof a->solver);
	assert_memory_equal(&a->drag_loss, &b->drag_loss, sizeof a->drag_loss);
	assert_memory_equal(&a->friction_loss, &b->friction_loss, sizeof a->friction_loss);
}

/* 1 if a beam s lists is flagged in contact. */
static int any_flag(const bsim_state *s)
{
	for (int k = 0; k < s->n_active; k++)
		if (s->contact[s->active[k]] != BSIM_CONTACT_NONE)
			return 1;
	return 0;
}

/* `steps` steps of scene s on backend be, forces of propulsion f_prop and
 * a lateral force up to rm held over calls of random lengths (pulled back
 * toward the centre line, so that the body meets the beams); into *touching
 * the compared states with a contact flag. */
static long compare(const bsim_backend *be, const bsim_scene *s, double f_prop, double rm,
                    long steps, uint64_t seed, long *touching)
{
	bsim_world *wa = bsim_test_world(be, s, NULL), *wb = bsim_test_world(be, s, NULL);
	bsim_state sa, run[CALL_MAX];
	assert_int_equal(bsim_state_init(&sa, s->n_beams), BSIM_OK);
	for (int k = 0; k < CALL_MAX; k++)
		assert_int_equal(bsim_state_init(&run[k], s->n_beams), BSIM_OK);
	bsim_error err;
	rng_state = seed * 0x9E3779B97F4A7C15ull + 1;
	long n = 0, compared = 0;
	be->get_state(wa, &sa);
	while (n < steps) {
		int len = 1 + (int)(rng_uniform() * CALL_MAX);
		if (len > steps - n)
			len = (int)(steps - n);
		/* the call's schedule: the lateral force held over 1 to 8 steps
		 * at a time, so that it changes within a call */
		bsim_wrench schedule[CALL_MAX];
		for (int k = 0, hold = 0; k < len; k++, hold--) {
			if (hold == 0) {
				hold = 1 + (int)(rng_uniform() * 8);
				schedule[k] = (bsim_wrench){
				        {rm * (2.0 * rng_uniform() - 1.0) - 0.5 * f_prop * sa.x[0],
				         f_prop},
				        0.0};
			} else
				schedule[k] = schedule[k - 1];
		}
		for (int made = 0, m; made < len; made += m) {
			assert_int_equal(be->advance(wb, &schedule[made], s->dt, len - made,
			                             &run[made], &m, &err),
			                 BSIM_OK);
			assert_true(m >= 1 && m <= len - made);
		}
		for (int k = 0; k < len; k++, n++) {
			assert_int_equal(
			        bsim_backend_step(be, wa, schedule[k].force, 0.0, s->dt, &err),
			        BSIM_OK);
			be->get_state(wa, &sa);
			bsim_contact_flags(s, &sa);
			bsim_contact_flags(s, &run[k]);
			assert_same(be, &sa, &run[k], n + 1);
			compared++;
			*touching += any_flag(&sa);
		}
	}
	for (int k = 0; k < CALL_MAX; k++)
		bsim_state_free(&run[k]);
	bsim_state_free(&sa);
	be->destroy(wa);
	be->destroy(wb);
	return compared;
}

/* The essay's gate at H1's forces, the body from below the beams to well
 * past them or stuck: flight, impacts and resting contact. */
static void test_gate(void **state)
{
	const bsim_backend *be = *state;
	static const double props[] = {4.0, 7.0, 10.0};
	long compared = 0, touching = 0;
	for (int p = 0; p < 3; p++) {
		bsim_scene s;
		bsim_scene_init_gate(&s, props[p], 20.0);
		compared += compare(be, &s, props[p], 20.0, 2500, 1 + (uint64_t)p, &touching);
		bsim_scene_free(&s);
	}
	print_message("%s: %ld states compared, %ld with a contact flag\n", be->name, compared,
	              touching);
	assert_int_equal(compared, 7500);
	assert_true(touching > 250); /* contact is exercised */
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_gate),
	};
	return bsim_test_run_per_backend("advance", tests, sizeof tests / sizeof tests[0]);
}
