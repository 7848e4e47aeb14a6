/* set_state on every backend of the registry: a state taken from one world
 * in contact with both beams of the gate, put into a fresh world of the
 * same scene, reads back as it was set (to float32: 1e-5 m, 1e-6 rad and
 * rad/s), and the fresh world, stepped on under the same force, follows the
 * original within 1 mm after 0.4 s (what it cannot take over: a solver's
 * warm start, its contacts' history); a state of another number of beams is
 * refused. A backend's own refusals and exactness are checked in its own
 * tests (test_chipmunk_oracles). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>

#include <cmocka.h>

#include "support.h"

static void test_restart_from_state(void **state)
{
	const bsim_backend *b = *state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 7.0, 0.0);
	bsim_world *w = bsim_test_world(b, &s, NULL), *w2 = bsim_test_world(b, &s, NULL);
	bsim_state st, st2;
	bsim_state_init(&st, 2);
	bsim_state_init(&st2, 2);
	const double f[2] = {0.0, 7.0};
	for (int n = 0; n < 700; n++) /* into contact with both beams */
		assert_int_equal(bsim_backend_step(b, w, f, 0.0, s.dt, NULL), BSIM_OK);
	b->get_state(w, &st);
	assert_true(st.theta[0] > 0.05 && st.theta[1] > 0.05);
	bsim_error err;
	assert_int_equal(b->set_state(w2, &st, &err), BSIM_OK);
	b->get_state(w2, &st2);
	for (int k = 0; k < 2; k++) {
		assert_true(fabs(st2.x[k] - st.x[k]) <= 1e-5 && fabs(st2.v[k] - st.v[k]) <= 1e-5);
		assert_true(fabs(st2.theta[k] - st.theta[k]) <= 1e-6);
		assert_true(fabs(st2.omega[k] - st.omega[k]) <= 1e-6);
	}
	for (int n = 0; n < 100; n++) {
		assert_int_equal(bsim_backend_step(b, w, f, 0.0, s.dt, NULL), BSIM_OK);
		assert_int_equal(bsim_backend_step(b, w2, f, 0.0, s.dt, NULL), BSIM_OK);
	}
	b->get_state(w, &st);
	b->get_state(w2, &st2);
	print_message("%s set_state: the restarted run differs by %.2e m after 0.4 s\n", b->name,
	              fabs(st2.x[1] - st.x[1]));
	assert_true(fabs(st2.x[1] - st.x[1]) <= 1e-3);
	bsim_state bad;
	bsim_state_init(&bad, 3);
	assert_int_equal(b->set_state(w2, &bad, &err), BSIM_EINPUT);
	bsim_state_free(&bad);
	bsim_state_free(&st);
	bsim_state_free(&st2);
	b->destroy(w);
	b->destroy(w2);
	bsim_scene_free(&s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_restart_from_state),
	};
	return bsim_test_run_per_backend("set_state", tests, sizeof tests / sizeof tests[0]);
}
