/* docs/model.md check 4: a scene mirrored in x, run with the random force
 * negated, gives the mirrored trajectory bit for bit. The gate is made
 * asymmetric (k1 = 300, k2 = 500) so that the mirror is a different scene. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "beamsim/schedule.h"
#include "beamsim/trial.h"
#include "scenes.h"

static void asymmetric_gate(bsim_scene *s, double f_prop, double rm)
{
	bsim_scene_init_gate(s, f_prop, rm);
	s->beams[0].stiffness = 300.0;
	s->beams[1].stiffness = 500.0;
	s->body.start[0] = 1.5;
}

/* Steps both worlds with mirrored forces and compares every step. */
static void test_mirror_bitwise_steps(void **state)
{
	(void)state;
	bsim_scene a, b;
	asymmetric_gate(&a, 8.0, 30.0);
	scene_mirror(&a, &b);
	bsim_world *wa = NULL, *wb = NULL;
	bsim_error err;
	assert_int_equal(bsim_backend_thesis.create(&a, NULL, &wa, &err), BSIM_OK);
	assert_int_equal(bsim_backend_thesis.create(&b, NULL, &wb, &err), BSIM_OK);
	bsim_schedule *sched = bsim_schedule_alloc(30.0, 50.0, bsim_schedule_seed_mix(5, 0, 0));
	bsim_state sa, sb;
	bsim_state_init(&sa, 2);
	bsim_state_init(&sb, 2);
	int contact_steps = 0;
	for (long n = 0; n < 3000; n++) {
		double fr = bsim_schedule_value(sched, bsim_schedule_index(sched, n, a.dt));
		const double fa[2] = {fr, 8.0}, fb[2] = {-fr, 8.0};
		assert_int_equal(bsim_backend_thesis.step(wa, fa, 0.0, a.dt, NULL), BSIM_OK);
		assert_int_equal(bsim_backend_thesis.step(wb, fb, 0.0, b.dt, NULL), BSIM_OK);
		bsim_backend_thesis.get_state(wa, &sa);
		bsim_backend_thesis.get_state(wb, &sb);
		assert_true(sa.x[0] == -sb.x[0] && sa.x[1] == sb.x[1]);
		assert_true(sa.v[0] == -sb.v[0] && sa.v[1] == sb.v[1]);
		assert_true(sa.theta[0] == sb.theta[1] && sa.theta[1] == sb.theta[0]);
		assert_true(sa.omega[0] == sb.omega[1] && sa.omega[1] == sb.omega[0]);
		assert_int_equal(sa.contact[0], sb.contact[1]);
		contact_steps += sa.contact[0] || sa.contact[1];
	}
	assert_true(contact_steps > 100); /* the comparison covered contact */
	bsim_schedule_free(sched);
	bsim_state_free(&sa);
	bsim_state_free(&sb);
	bsim_backend_thesis.destroy(wa);
	bsim_backend_thesis.destroy(wb);
	bsim_scene_free(&a);
	bsim_scene_free(&b);
}

/* Through the runner: a negative magnitude negates the schedule; outcomes
 * match, left and right types swap, the end state mirrors exactly. */
static void test_mirror_trials(void **state)
{
	(void)state;
	bsim_trial_runner *r = bsim_trial_runner_alloc();
	int traversed = 0;
	for (int t = 0; t < 40; t++) {
		bsim_scene a, b;
		asymmetric_gate(&a, 8.0, 30.0);
		scene_mirror(&a, &b);
		b.effects.random_magnitude = -a.effects.random_magnitude;
		bsim_trial_result ra, rb;
		bsim_error err;
		uint64_t seed = bsim_schedule_seed_mix(9, 1, (uint64_t)t);
		assert_int_equal(
		        bsim_trial_run(r, &a, &bsim_backend_thesis, NULL, seed, NULL, &ra, &err),
		        BSIM_OK);
		assert_int_equal(
		        bsim_trial_run(r, &b, &bsim_backend_thesis, NULL, seed, NULL, &rb, &err),
		        BSIM_OK);
		assert_int_equal(ra.outcome, rb.outcome);
		assert_int_equal(ra.steps, rb.steps);
		assert_true(ra.x_end == -rb.x_end && ra.vx_end == -rb.vx_end);
		assert_true(ra.max_theta[0] == rb.max_theta[1]);
		if (ra.outcome == BSIM_TRAVERSED) {
			traversed++;
			assert_int_equal(ra.type == BSIM_TYPE_LEFT, rb.type == BSIM_TYPE_RIGHT);
		}
		bsim_scene_free(&a);
		bsim_scene_free(&b);
	}
	print_message("mirror: %d of 40 trials traversed\n", traversed);
	bsim_trial_runner_free(r);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_mirror_bitwise_steps),
	        cmocka_unit_test(test_mirror_trials),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
