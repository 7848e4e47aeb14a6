/* The paired statistics of beamsim compare against values worked by hand
 * (the binomial tails of McNemar's exact test, Holm's adjustment of a small
 * family) and against the large-sample normal limit (Newcombe's paired
 * interval must approach the Wald interval of the paired difference). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "beamsim/stats.h"

static void test_mcnemar_by_hand(void **state)
{
	(void)state;
	/* 0 of 5 discordant pairs one way: 2 * (1/2)^5. */
	assert_float_equal(bsim_mcnemar_exact(0, 5), 0.0625, 1e-14);
	/* 1 of 10: 2 * (1 + 10) / 1024. */
	assert_float_equal(bsim_mcnemar_exact(1, 9), 22.0 / 1024.0, 1e-14);
	assert_float_equal(bsim_mcnemar_exact(9, 1), 22.0 / 1024.0, 1e-14);
	/* Balanced and empty: no evidence at all. */
	assert_true(bsim_mcnemar_exact(5, 5) == 1.0);
	assert_true(bsim_mcnemar_exact(0, 0) == 1.0);
	/* 2 of 20: 2 * (1 + 20 + 190) / 2^20. */
	assert_float_equal(bsim_mcnemar_exact(2, 18), 422.0 / 1048576.0, 1e-15);
}

/* For many pairs the exact test meets the continuity-corrected normal
 * approximation, z = (|b - c| - 1) / sqrt(b + c). */
static void test_mcnemar_normal_limit(void **state)
{
	(void)state;
	int b = 1000, c = 1100;
	double z = (fabs((double)(b - c)) - 1.0) / sqrt((double)(b + c));
	double normal = erfc(z / sqrt(2.0));
	double exact = bsim_mcnemar_exact(b, c);
	assert_true(exact > 0.0 && exact < 1.0);
	assert_float_equal(exact / normal, 1.0, 0.03);
}

static void test_holm_by_hand(void **state)
{
	(void)state;
	/* Sorted: 0.005 x4 = 0.02, 0.01 x3 = 0.03, 0.03 x2 = 0.06,
	 * 0.04 x1 = 0.04 raised to the running maximum 0.06. */
	double p[4] = {0.01, 0.04, 0.03, 0.005};
	double adj[4];
	bsim_holm(p, 4, adj);
	assert_float_equal(adj[0], 0.03, 1e-15);
	assert_float_equal(adj[1], 0.06, 1e-15);
	assert_float_equal(adj[2], 0.06, 1e-15);
	assert_float_equal(adj[3], 0.02, 1e-15);
	/* Capped at 1, and in place. */
	double q[3] = {0.5, 0.9, 0.4};
	bsim_holm(q, 3, q);
	assert_true(q[0] == 1.0 && q[1] == 1.0 && q[2] == 1.0);
}

/* Large n: Newcombe's interval tends to d +- z sqrt(((b+c)/n - d^2) / n). */
static void test_paired_ci_normal_limit(void **state)
{
	(void)state;
	bsim_pairs t = {.a = 3000, .b = 600, .c = 400, .d = 6000};
	double n = 10000, d = (t.b - t.c) / n;
	double se = sqrt(((t.b + t.c) / n - d * d) / n);
	double lo, hi;
	bsim_paired_diff_ci(&t, BSIM_Z95, &lo, &hi);
	assert_float_equal(lo, d - BSIM_Z95 * se, 3e-4);
	assert_float_equal(hi, d + BSIM_Z95 * se, 3e-4);
}

/* Shape: contains the estimate, mirrors when A and B swap, stays within
 * [-1, 1], and identical outcomes give an interval around 0 that is not a
 * point. */
static void test_paired_ci_shape(void **state)
{
	(void)state;
	for (int b = 0; b <= 20; b += 4)
		for (int c = 0; c <= 20; c += 5) {
			bsim_pairs t = {.a = 30, .b = b, .c = c, .d = 50 - b - c + 20};
			bsim_pairs s = {.a = t.a, .b = c, .c = b, .d = t.d};
			int n = t.a + t.b + t.c + t.d;
			double lo, hi, slo, shi, d = (double)(b - c) / n;
			bsim_paired_diff_ci(&t, BSIM_Z95, &lo, &hi);
			bsim_paired_diff_ci(&s, BSIM_Z95, &slo, &shi);
			assert_true(-1.0 <= lo && lo <= d && d <= hi && hi <= 1.0);
			assert_float_equal(lo, -shi, 1e-12);
			assert_float_equal(hi, -slo, 1e-12);
		}
	bsim_pairs same = {.a = 40, .b = 0, .c = 0, .d = 60};
	double lo, hi;
	bsim_paired_diff_ci(&same, BSIM_Z95, &lo, &hi);
	assert_true(lo < 0.0 && hi > 0.0);
	assert_float_equal(lo, -hi, 1e-12);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_mcnemar_by_hand),
	        cmocka_unit_test(test_mcnemar_normal_limit),
	        cmocka_unit_test(test_holm_by_hand),
	        cmocka_unit_test(test_paired_ci_normal_limit),
	        cmocka_unit_test(test_paired_ci_shape),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
