/* The effect pipeline and the random-force schedule: only listed effects
 * run, a scene without random force makes no draws at all, values refresh
 * at the scene's frequency, and seeds depend on (seed, group, trial) only. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>

#include <cmocka.h>

#include "beamsim/effects.h"
#include "beamsim/schedule.h"
#include "beamsim/trial.h"
#include "scenes.h"

static void test_no_random_force_no_draws(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 9.0, 0.0); /* Rm = 0: the effect is absent */
	assert_int_equal(s.effects.has_random_force, 0);
	bsim_effects fx;
	assert_int_equal(bsim_effects_init(&fx, &s, 1), BSIM_OK);
	assert_int_equal(fx.n, 1);
	assert_null(fx.random);
	bsim_effects_free(&fx);

	bsim_trial_runner *r = bsim_trial_runner_alloc();
	bsim_trial_result out;
	bsim_error err;
	unsigned long before = bsim_schedule_total_draws();
	assert_int_equal(bsim_trial_run(r, &s, &bsim_backend_thesis, NULL, 1, NULL, &out, &err),
	                 BSIM_OK);
	assert_true(out.steps_run > 100);
	assert_int_equal(out.draws, 0);
	assert_int_equal(bsim_schedule_total_draws(), before);

	/* the same scene with noise draws once per 1/f = 5 steps actually run */
	bsim_scene_free(&s);
	bsim_scene_init_gate(&s, 9.0, 20.0);
	before = bsim_schedule_total_draws();
	assert_int_equal(bsim_trial_run(r, &s, &bsim_backend_thesis, NULL, 1, NULL, &out, &err),
	                 BSIM_OK);
	assert_int_equal(out.draws, (unsigned long)((out.steps_run - 1) / 5 + 1));
	assert_int_equal(bsim_schedule_total_draws() - before, out.draws);
	bsim_trial_runner_free(r);
	bsim_scene_free(&s);
}

static void test_empty_pipeline(void **state)
{
	(void)state;
	bsim_scene s;
	scene_gate_quiet(&s);
	bsim_effects fx;
	assert_int_equal(bsim_effects_init(&fx, &s, 1), BSIM_OK);
	assert_int_equal(fx.n, 0);
	double f[2] = {1, 1};
	bsim_effects_force(&fx, 0, s.dt, f);
	assert_true(f[0] == 0.0 && f[1] == 0.0);
	bsim_effects_free(&fx);
	bsim_scene_free(&s);
}

/* Piecewise constant at 50 Hz with h = 4 ms: five steps per value, value j
 * on [j/f, (j+1)/f); standard normal with scale Rm. */
static void test_schedule_hold_and_scale(void **state)
{
	(void)state;
	bsim_schedule *s = bsim_schedule_alloc(20.0, 50.0, bsim_schedule_seed_mix(1, 2, 3));
	for (long n = 0; n < 1000; n++)
		assert_int_equal(bsim_schedule_index(s, n, 0.004), n / 5);
	assert_int_equal(bsim_schedule_index(s, 7, 0.003), (long)floor(7 * 0.003 * 50.0));
	double sum = 0.0, sum2 = 0.0;
	const int n = 20000;
	for (int j = 0; j < n; j++) {
		double v = bsim_schedule_value(s, j);
		sum += v;
		sum2 += v * v;
	}
	double mean = sum / n, sd = sqrt(sum2 / n - mean * mean);
	assert_true(fabs(mean) < 4.0 * 20.0 / sqrt(n)); /* 4 standard errors */
	assert_true(fabs(sd - 20.0) < 0.4);
	assert_int_equal(bsim_schedule_draws(s), (unsigned long)n);
	/* values are kept: reading back draws nothing */
	double v5 = bsim_schedule_value(s, 5);
	assert_true(v5 == bsim_schedule_value(s, 5));
	assert_int_equal(bsim_schedule_draws(s), (unsigned long)n);
	bsim_schedule_free(s);
}

static void test_seed_mixing(void **state)
{
	(void)state;
	uint64_t base = bsim_schedule_seed_mix(1, 0, 0);
	assert_true(base == bsim_schedule_seed_mix(1, 0, 0));
	assert_true(base != bsim_schedule_seed_mix(1, 0, 1));
	assert_true(base != bsim_schedule_seed_mix(1, 1, 0));
	assert_true(base != bsim_schedule_seed_mix(2, 0, 0));
	assert_true(bsim_schedule_seed_mix(1, 1, 0) !=
	            bsim_schedule_seed_mix(1, 0, 1)); /* not symmetric */
	bsim_schedule *a = bsim_schedule_alloc(1.0, 50.0, bsim_schedule_seed_mix(1, 4, 7));
	bsim_schedule *b = bsim_schedule_alloc(1.0, 50.0, bsim_schedule_seed_mix(1, 4, 7));
	bsim_schedule *c = bsim_schedule_alloc(1.0, 50.0, bsim_schedule_seed_mix(1, 4, 8));
	int same_c = 0;
	for (int j = 0; j < 100; j++) {
		assert_true(bsim_schedule_value(a, j) == bsim_schedule_value(b, j));
		same_c += bsim_schedule_value(a, j) == bsim_schedule_value(c, j);
	}
	assert_int_equal(same_c, 0);
	bsim_schedule_free(a);
	bsim_schedule_free(b);
	bsim_schedule_free(c);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_no_random_force_no_draws),
	        cmocka_unit_test(test_empty_pipeline),
	        cmocka_unit_test(test_schedule_hold_and_scale),
	        cmocka_unit_test(test_seed_mixing),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
