/* The Wilson score interval against published values (Newcombe 1998,
 * "Two-sided confidence intervals for the single proportion", Table I) and
 * values worked by hand, plus its shape: inside [0, 1], monotonic in k. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "beamsim/stats.h"
#include "beamsim/sweep.h"

static void check(int k, int n, double lo, double hi)
{
	double l, h;
	bsim_stats_wilson(k, n, BSIM_STATS_Z95, &l, &h);
	/* Published to 4 decimals. */
	assert_float_equal(l, lo, 5e-5);
	assert_float_equal(h, hi, 5e-5);
}

static void test_wilson_published(void **state)
{
	(void)state;
	check(81, 263, 0.2553, 0.3662);
	check(15, 148, 0.0624, 0.1605);
	check(0, 20, 0.0, 0.1611);
	check(1, 29, 0.0061, 0.1718);
}

static void test_wilson_hundred(void **state)
{
	(void)state;
	check(0, 100, 0.0, 0.0370);
	check(50, 100, 0.4038, 0.5962);
	check(100, 100, 0.9630, 1.0);
	check(1, 10, 0.0179, 0.4042);
}

static void test_wilson_exact_ends(void **state)
{
	(void)state;
	double lo, hi;
	bsim_stats_wilson(0, 100, BSIM_STATS_Z95, &lo, &hi);
	assert_true(lo == 0.0);
	bsim_stats_wilson(100, 100, BSIM_STATS_Z95, &lo, &hi);
	assert_true(hi == 1.0);
}

static void test_wilson_empty(void **state)
{
	(void)state;
	double lo = -1, hi = -1;
	bsim_stats_wilson(0, 0, BSIM_STATS_Z95, &lo, &hi);
	assert_true(lo == 0.0);
	assert_true(hi == 1.0);
}

/* Both bounds rise with k, contain k/n, and mirror: [lo, hi] for k is
 * [1 - hi, 1 - lo] for n - k. */
static void test_wilson_shape(void **state)
{
	(void)state;
	const int n = 100;
	double plo = -1.0, phi = -1.0;
	for (int k = 0; k <= n; k++) {
		double lo, hi, mlo, mhi;
		bsim_stats_wilson(k, n, BSIM_STATS_Z95, &lo, &hi);
		assert_true(lo >= 0.0 && hi <= 1.0 && lo <= hi);
		assert_true(lo <= (double)k / n && (double)k / n <= hi);
		assert_true(lo > plo || (k == 0 && lo == 0.0));
		assert_true(hi > phi);
		bsim_stats_wilson(n - k, n, BSIM_STATS_Z95, &mlo, &mhi);
		assert_float_equal(lo, 1.0 - mhi, 1e-12);
		assert_float_equal(hi, 1.0 - mlo, 1e-12);
		plo = lo;
		phi = hi;
	}
}

/* Narrower with more trials at the same proportion. */
static void test_wilson_narrows(void **state)
{
	(void)state;
	double lo1, hi1, lo2, hi2;
	bsim_stats_wilson(30, 100, BSIM_STATS_Z95, &lo1, &hi1);
	bsim_stats_wilson(300, 1000, BSIM_STATS_Z95, &lo2, &hi2);
	assert_true(hi2 - lo2 < hi1 - lo1);
}

static void test_group_aggregate(void **state)
{
	(void)state;
	bsim_trial_result t[6] = {0};
	t[0].outcome = BSIM_TRAVERSED, t[0].type = BSIM_TYPE_LEFT, t[0].landscape_beam = 0;
	t[0].max_theta[0] = 0.5, t[0].max_theta[1] = 0.2;
	t[1].outcome = BSIM_TRAVERSED, t[1].type = BSIM_TYPE_RIGHT, t[1].landscape_beam = 1;
	t[1].max_theta[0] = 0.1, t[1].max_theta[1] = 0.4;
	t[2].outcome = BSIM_SIDE_EXIT;
	t[3].outcome = BSIM_STUCK, t[3].in_contact_end = 1;
	t[4].outcome = BSIM_STUCK;
	t[5].outcome = BSIM_TRAVERSED, t[5].type = BSIM_TYPE_LEFT, t[5].landscape_beam = -1;
	for (int i = 0; i < 6; i++)
		t[i].steps_run = 100 + i;
	bsim_group_result g;
	bsim_sweep_group_aggregate(t, 6, &g);
	assert_int_equal(g.trials, 6);
	assert_int_equal(g.traversed, 3);
	assert_int_equal(g.side_exit, 1);
	assert_int_equal(g.stuck, 2);
	assert_int_equal(g.left, 2);
	assert_int_equal(g.right, 1);
	assert_int_equal(g.stuck_in_contact, 1);
	assert_int_equal(g.landscape_left, 1);
	assert_int_equal(g.landscape_right, 1);
	assert_int_equal(g.steps, 615);
	assert_float_equal(g.p_traverse, 0.5, 1e-15);
	double lo, hi;
	bsim_stats_wilson(3, 6, BSIM_STATS_Z95, &lo, &hi);
	assert_true(g.ci95[0] == lo && g.ci95[1] == hi);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_wilson_published),  cmocka_unit_test(test_wilson_hundred),
	        cmocka_unit_test(test_wilson_exact_ends), cmocka_unit_test(test_wilson_empty),
	        cmocka_unit_test(test_wilson_shape),      cmocka_unit_test(test_wilson_narrows),
	        cmocka_unit_test(test_group_aggregate),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
