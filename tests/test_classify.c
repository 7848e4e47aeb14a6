/* The left/right type of a traversal (docs/model.md section 6): the sign of v_x
 * at classify_y, with |v_x| below termination.classify_deadband typed
 * none. A body that never meets a beam keeps its starting lateral speed
 * exactly (no lateral force), so the type is known in advance. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>

#include <cmocka.h>

#include "beamsim/trial.h"
#include "support.h"

static bsim_trial_result coast(double vx, double deadband)
{
	bsim_scene s;
	bsim_scene_init_gate(&s, 5.0, 0.0); /* propulsion only */
	s.beams[0].pivot[0] = -500.0;       /* beams far out of the way */
	s.beams[1].pivot[0] = 500.0;
	s.side_x = 1000.0;
	s.body.velocity[0] = vx;
	s.classify_deadband = deadband;
	bsim_error err;
	assert_int_equal(bsim_scene_validate(&s, &err), BSIM_OK);
	bsim_trial_runner *r = bsim_trial_runner_alloc();
	bsim_trial_result out;
	assert_int_equal(
	        bsim_trial_run(r, &s, bsim_test_backend("thesis"), NULL, 1, NULL, &out, &err),
	        BSIM_OK);
	bsim_trial_runner_free(r);
	bsim_scene_free(&s);
	assert_int_equal(out.outcome, BSIM_TRAVERSED);
	assert_true(out.vx_end == vx);
	return out;
}

static void test_deadband(void **state)
{
	(void)state;
	assert_int_equal(coast(0.005, 0.01).type, BSIM_TYPE_NONE);
	assert_int_equal(coast(-0.005, 0.01).type, BSIM_TYPE_NONE);
	assert_int_equal(coast(0.005, 0.001).type, BSIM_TYPE_LEFT);
	assert_int_equal(coast(-0.02, 0.01).type, BSIM_TYPE_RIGHT);
	assert_int_equal(coast(0.02, 0.01).type, BSIM_TYPE_LEFT);
	assert_int_equal(coast(0.0, 0.0).type, BSIM_TYPE_NONE); /* the sign alone */
	assert_int_equal(coast(1e-9, 0.0).type, BSIM_TYPE_LEFT);
}

/* The default is 1 cm/s (scene.c says why). */
static void test_default(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 5.0, 0.0);
	assert_float_equal(s.classify_deadband, 0.01, 0.0);
	bsim_scene_free(&s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_deadband),
	        cmocka_unit_test(test_default),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
