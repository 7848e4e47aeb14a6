/* The effect pipeline and the random-force schedule: only listed effects
 * run, a scene without random force makes no draws at all, values refresh
 * at the scene's frequency, seeds depend on (seed, group, trial) only, and
 * a schedule kept for another trial draws as a new one. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "beamsim/effects.h"
#include "beamsim/schedule.h"
#include "beamsim/trial.h"
#include "model/schedule_spare.h"
#include "scenes.h"
#include "support.h"

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
	assert_int_equal(
	        bsim_trial_run(r, &s, bsim_test_backend("thesis"), NULL, 1, NULL, &out, &err),
	        BSIM_OK);
	assert_true(out.steps_run > 100);
	assert_int_equal(out.draws, 0);
	assert_int_equal(bsim_schedule_total_draws(), before);

	/* the same scene with noise draws once per 1/f = 5 steps actually run */
	bsim_scene_free(&s);
	bsim_scene_init_gate(&s, 9.0, 20.0);
	before = bsim_schedule_total_draws();
	assert_int_equal(
	        bsim_trial_run(r, &s, bsim_test_backend("thesis"), NULL, 1, NULL, &out, &err),
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
	double f[BSIM_WRENCH] = {1, 1, 1};
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

/* Mean over k sequences of the estimator est(seq) and its standard error
 * from the spread between the sequences (they are independent). */
typedef struct est_sum {
	double sum, sum2;
	int k;
} est_sum;

static void est_add(est_sum *e, double v)
{
	e->sum += v;
	e->sum2 += v * v;
	e->k++;
}

static double est_mean(const est_sum *e)
{
	return e->sum / e->k;
}

static double est_se(const est_sum *e)
{
	double m = est_mean(e);
	return sqrt((e->sum2 / e->k - m * m) / (e->k - 1));
}

/* The random force of scene s, steps 0 .. n-1 at step h, trial seed. */
static void forcing_series(const bsim_scene *s, uint64_t seed, double h, double *out, int n)
{
	bsim_effects fx;
	assert_int_equal(bsim_effects_init(&fx, s, seed), BSIM_OK);
	assert_non_null(fx.random);
	for (int i = 0; i < n; i++) {
		double f[BSIM_WRENCH];
		bsim_effects_force(&fx, i, h, f);
		assert_true(f[0] == fx.random->last);
		out[i] = f[0];
	}
	assert_int_equal(bsim_effects_status(&fx, NULL), BSIM_OK);
	bsim_effects_free(&fx);
}

/* OU: stationary from step 0 with variance sigma^2, autocorrelation
 * exp(-lag h / tau), each within 5 standard errors (the spread over 200
 * independent seeds); the standard errors small enough that a wrong
 * variance (by 10%) or a wrong correlation time (by 20%) would fail. */
static void test_ou_variance_and_autocorrelation(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 0.0, 3.0);
	s.effects.random_model = BSIM_RANDOM_OU;
	s.effects.random_correlation_time = 0.02;
	const double h = 0.004, sigma = 3.0, tau = 0.02;
	enum { N = 400, K = 200 };
	static double x[N];
	const int lags[] = {1, 5, 10};
	est_sum var0 = {0}, var_late = {0}, acf[3] = {{0}};
	for (int k = 0; k < K; k++) {
		forcing_series(&s, bsim_schedule_seed_mix(7, 0, (uint64_t)k), h, x, N);
		est_add(&var0, x[0] * x[0] / (sigma * sigma)); /* stationary at once */
		double v = 0.0;
		for (int i = 0; i < N; i++)
			v += x[i] * x[i];
		est_add(&var_late, v / N / (sigma * sigma));
		for (int l = 0; l < 3; l++) {
			double c = 0.0;
			for (int i = 0; i + lags[l] < N; i++)
				c += x[i] * x[i + lags[l]];
			est_add(&acf[l], c / (N - lags[l]) / (sigma * sigma));
		}
	}
	assert_true(fabs(est_mean(&var0) - 1.0) < 5 * est_se(&var0));
	assert_true(fabs(est_mean(&var_late) - 1.0) < 5 * est_se(&var_late));
	assert_true(5 * est_se(&var_late) < 0.1);
	for (int l = 0; l < 3; l++) {
		double truth = exp(-lags[l] * h / tau);
		assert_true(fabs(est_mean(&acf[l]) - truth) < 5 * est_se(&acf[l]));
		/* tau 20% off moves the lag-5 value by 0.07: outside 5 SE */
		assert_true(5 * est_se(&acf[l]) < 0.06);
	}
	/* a step asked for again, or out of order, is the same value */
	bsim_effects fx;
	assert_int_equal(bsim_effects_init(&fx, &s, bsim_schedule_seed_mix(7, 0, 3)), BSIM_OK);
	double f[BSIM_WRENCH], at37;
	bsim_effects_force(&fx, 37, h, f);
	at37 = f[0];
	bsim_effects_force(&fx, 5, h, f);
	bsim_effects_force(&fx, 37, h, f);
	assert_true(f[0] == at37);
	bsim_effects_free(&fx);
	forcing_series(&s, bsim_schedule_seed_mix(7, 0, 3), h, x, 38);
	assert_true(x[37] == at37);
	bsim_scene_free(&s);
}

/* White: independent steps with variance Rm^2 / (f_R h), so the variance
 * times h (the spectrum's level, 2 Rm^2 / f_R one-sided) is the same at
 * h = 4 ms and 1 ms; lag-1 correlation 0; each within 5 standard errors. */
static void test_white_scales_with_dt(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 0.0, 20.0);
	s.effects.random_model = BSIM_RANDOM_WHITE;
	const double rm = 20.0, f_r = 50.0, hs[2] = {0.004, 0.001};
	enum { N = 20000 };
	static double x[N];
	for (int j = 0; j < 2; j++) {
		forcing_series(&s, bsim_schedule_seed_mix(11, 1, (uint64_t)j), hs[j], x, N);
		double want = rm * rm / (f_r * hs[j]);
		double v = 0.0, c = 0.0;
		for (int i = 0; i < N; i++)
			v += x[i] * x[i];
		for (int i = 0; i + 1 < N; i++)
			c += x[i] * x[i + 1];
		v /= N;
		c /= (N - 1) * want;
		assert_true(fabs(v / want - 1.0) < 5 * sqrt(2.0 / N));
		assert_true(fabs(c) < 5 / sqrt((double)N));
	}
	bsim_scene_free(&s);
}

/* The model key: held is today's force to the bit; a misspelt model is
 * refused naming the file, the field and what is expected. */
static void test_model_key(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("effects_model");
	const char *base =
	        "body: { mass: 1, radius: 10 }\n"
	        "beams: [ { pivot: [-25, 30], length: 25, mass: 0.1, stiffness: 400 } ]\n"
	        "effects:\n  random_force: { magnitude: 20, %s }\n";
	char text[512];
	const char *models[] = {"model: held", "frequency: 50", "model: ou, correlation_time: 0.05",
	                        "model: white"};
	const bsim_random_model want[] = {BSIM_RANDOM_HELD, BSIM_RANDOM_HELD, BSIM_RANDOM_OU,
	                                  BSIM_RANDOM_WHITE};
	double held[2][50];
	for (int i = 0; i < 4; i++) {
		snprintf(text, sizeof text, base, models[i]);
		const char *path = bsim_test_write(dir, "scene.yaml", text);
		bsim_scene s;
		bsim_error err;
		assert_int_equal(bsim_scene_load(path, NULL, 0, &s, &err), BSIM_OK);
		assert_int_equal(s.effects.random_model, want[i]);
		if (i == 2)
			assert_true(s.effects.random_correlation_time == 0.05);
		if (i < 2)
			forcing_series(&s, 99, s.dt, held[i], 50);
		bsim_scene_free(&s);
	}
	for (int n = 0; n < 50; n++)
		assert_true(held[0][n] == held[1][n]);
	snprintf(text, sizeof text, base, "model: pink");
	const char *path = bsim_test_write(dir, "scene.yaml", text);
	bsim_scene s;
	bsim_error err;
	assert_int_equal(bsim_scene_load(path, NULL, 0, &s, &err), BSIM_EINPUT);
	const char *needles[] = {
	        "scene.yaml:4", "effects.random_force.model", "held", "ou", "white", "pink", NULL};
	for (int i = 0; needles[i]; i++)
		assert_non_null(strstr(err.msg, needles[i]));
	bsim_test_remove(dir);
}

/* A schedule restarted for another trial (a runner keeps one: bsim_effects_
 * init_spare) gives what a new one of the same magnitude, frequency and
 * seed gives, whatever it drew and held before at another frequency; and a
 * runner's trials give the same results as trials on runners of their own. */
static void test_schedule_restart_is_new(void **state)
{
	(void)state;
	const uint64_t seed = bsim_schedule_seed_mix(3, 1, 4);
	bsim_schedule *fresh = bsim_schedule_alloc(20.0, 50.0, seed);
	bsim_schedule *kept = bsim_schedule_alloc(7.0, 25.0, bsim_schedule_seed_mix(3, 2, 9));
	long held[2];
	for (long n = 0; n < 400; n++)
		bsim_schedule_at_step_held(kept, n, 0.004, held);
	bsim_schedule_restart(kept, 20.0, 50.0, seed);
	assert_int_equal(bsim_schedule_draws(kept), 0);
	for (long n = 0; n < 400; n++) {
		long hf[2], hk[2];
		double f = bsim_schedule_at_step_held(fresh, n, 0.004, hf);
		double k = bsim_schedule_at_step_held(kept, n, 0.004, hk);
		assert_memory_equal(&f, &k, sizeof f);
		assert_int_equal(hf[0], hk[0]);
		assert_int_equal(hf[1], hk[1]);
	}
	bsim_schedule_free(fresh);
	bsim_schedule_free(kept);

	bsim_scene a, b;
	bsim_scene_init_gate(&a, 9.0, 20.0);
	bsim_scene_init_gate(&b, 6.0, 40.0);
	b.effects.random_frequency = 25.0;
	const bsim_backend *thesis = bsim_test_backend("thesis");
	bsim_trial_runner *shared = bsim_trial_runner_alloc();
	bsim_trial_result first, second, alone;
	bsim_error err;
	assert_int_equal(bsim_trial_run(shared, &b, thesis, NULL, 11, NULL, &first, &err), BSIM_OK);
	assert_int_equal(bsim_trial_run(shared, &a, thesis, NULL, 12, NULL, &second, &err),
	                 BSIM_OK);
	assert_true(first.draws > 0 && second.draws > 0);
	bsim_trial_runner *own = bsim_trial_runner_alloc();
	assert_int_equal(bsim_trial_run(own, &a, thesis, NULL, 12, NULL, &alone, &err), BSIM_OK);
	assert_int_equal(second.draws, alone.draws);
	assert_int_equal(second.steps_run, alone.steps_run);
	assert_memory_equal(&second.x_end, &alone.x_end, sizeof alone.x_end);
	assert_memory_equal(&second.y_end, &alone.y_end, sizeof alone.y_end);
	assert_memory_equal(&second.vx_end, &alone.vx_end, sizeof alone.vx_end);
	bsim_trial_runner_free(own);
	bsim_trial_runner_free(shared);
	bsim_scene_free(&a);
	bsim_scene_free(&b);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_no_random_force_no_draws),
	        cmocka_unit_test(test_empty_pipeline),
	        cmocka_unit_test(test_schedule_hold_and_scale),
	        cmocka_unit_test(test_seed_mixing),
	        cmocka_unit_test(test_schedule_restart_is_new),
	        cmocka_unit_test(test_ou_variance_and_autocorrelation),
	        cmocka_unit_test(test_white_scales_with_dt),
	        cmocka_unit_test(test_model_key),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
