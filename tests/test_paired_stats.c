/* The paired statistics of beamsim compare against values worked by hand
 * (the binomial tails of McNemar's exact test, Holm's adjustment of a small
 * family), against published intervals (Tango's score interval in Tango
 * 1998, Agresti & Min 2005 and Fagerland, Lydersen & Laake 2014), and
 * against the large-sample normal limit (the paired intervals must approach
 * the Wald interval of the paired difference); the minimum detectable
 * difference against a simulation of the test's power and, with many
 * discordant pairs, Connor's normal approximation. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
#include <gsl/gsl_rng.h>

#include "beamsim/stats.h"

static void test_mcnemar_by_hand(void **state)
{
	(void)state;
	/* 0 of 5 discordant pairs one way: 2 * (1/2)^5. */
	assert_float_equal(bsim_stats_mcnemar_exact(0, 5), 0.0625, 1e-14);
	/* 1 of 10: 2 * (1 + 10) / 1024. */
	assert_float_equal(bsim_stats_mcnemar_exact(1, 9), 22.0 / 1024.0, 1e-14);
	assert_float_equal(bsim_stats_mcnemar_exact(9, 1), 22.0 / 1024.0, 1e-14);
	/* Balanced and empty: no evidence at all. */
	assert_true(bsim_stats_mcnemar_exact(5, 5) == 1.0);
	assert_true(bsim_stats_mcnemar_exact(0, 0) == 1.0);
	/* 2 of 20: 2 * (1 + 20 + 190) / 2^20. */
	assert_float_equal(bsim_stats_mcnemar_exact(2, 18), 422.0 / 1048576.0, 1e-15);
}

/* For many pairs the exact test meets the continuity-corrected normal
 * approximation, z = (|b - c| - 1) / sqrt(b + c). */
static void test_mcnemar_normal_limit(void **state)
{
	(void)state;
	int b = 1000, c = 1100;
	double z = (fabs((double)(b - c)) - 1.0) / sqrt((double)(b + c));
	double normal = erfc(z / sqrt(2.0));
	double exact = bsim_stats_mcnemar_exact(b, c);
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
	bsim_stats_holm(p, 4, adj);
	assert_float_equal(adj[0], 0.03, 1e-15);
	assert_float_equal(adj[1], 0.06, 1e-15);
	assert_float_equal(adj[2], 0.06, 1e-15);
	assert_float_equal(adj[3], 0.02, 1e-15);
	/* Capped at 1, and in place. */
	double q[3] = {0.5, 0.9, 0.4};
	bsim_stats_holm(q, 3, q);
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
	bsim_stats_newcombe_ci(&t, BSIM_STATS_Z95, &lo, &hi);
	assert_float_equal(lo, d - BSIM_STATS_Z95 * se, 3e-4);
	assert_float_equal(hi, d + BSIM_STATS_Z95 * se, 3e-4);
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
			bsim_stats_newcombe_ci(&t, BSIM_STATS_Z95, &lo, &hi);
			bsim_stats_newcombe_ci(&s, BSIM_STATS_Z95, &slo, &shi);
			assert_true(-1.0 <= lo && lo <= d && d <= hi && hi <= 1.0);
			assert_float_equal(lo, -shi, 1e-12);
			assert_float_equal(hi, -slo, 1e-12);
		}
	bsim_pairs same = {.a = 40, .b = 0, .c = 0, .d = 60};
	double lo, hi;
	bsim_stats_newcombe_ci(&same, BSIM_STATS_Z95, &lo, &hi);
	assert_true(lo < 0.0 && hi > 0.0);
	assert_float_equal(lo, -hi, 1e-12);
}

/* Tango's score interval against the published values, to the three
 * decimals they are printed with. Tables are (a, b, c, d): both, A only,
 * B only, neither. */
static void test_tango_published(void **state)
{
	(void)state;
	static const struct {
		bsim_pairs t;
		double level, lo, hi;
		const char *source;
	} cases[] = {
	        /* Tango (1998), the 44-pair example with one discordant pair:
	         * 90% interval, as for his equivalence test. */
	        {{43, 0, 1, 0}, 0.90, -0.096, 0.037, "Tango 1998"},
	        {{4, 9, 3, 16}, 0.95, -0.027, 0.390, "Tango 1998"},
	        /* Agresti & Min (2005), Statist. Med. 24, 729-740. */
	        {{53, 16, 8, 9}, 0.95, -0.020, 0.207, "Agresti & Min 2005"},
	        /* Fagerland, Lydersen & Laake (2014), Statist. Med. 33,
	         * 2850-2875: airway hyper-responsiveness (Bentur et al.). */
	        {{1, 1, 7, 12}, 0.95, -0.517, -0.026, "Fagerland et al. 2014"},
	};
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		double lo, hi, z = bsim_stats_normal_upper((1.0 - cases[i].level) / 2.0);
		bsim_stats_tango_ci(&cases[i].t, z, &lo, &hi);
		print_message("%s: [%.4f, %.4f], published [%.3f, %.3f]\n", cases[i].source, lo, hi,
		              cases[i].lo, cases[i].hi);
		assert_float_equal(lo, cases[i].lo, 5e-4);
		assert_float_equal(hi, cases[i].hi, 5e-4);
	}
}

/* With no discordant pair the interval is the closed form +-z^2/(n + z^2)
 * (T(delta) = -sqrt(n delta / (1 - delta)) for delta > 0), whatever the
 * concordant pairs are: not a point, as Newcombe's becomes when a and d
 * are both positive. */
static void test_tango_no_discordant(void **state)
{
	(void)state;
	const bsim_pairs tables[] = {{40, 0, 0, 60}, {100, 0, 0, 0}, {0, 0, 0, 100}};
	double z = BSIM_STATS_Z95, w = z * z / (100.0 + z * z);
	for (int i = 0; i < 3; i++) {
		double lo, hi;
		bsim_stats_tango_ci(&tables[i], z, &lo, &hi);
		assert_float_equal(lo, -w, 1e-9);
		assert_float_equal(hi, w, 1e-9);
	}
	double nlo, nhi;
	bsim_stats_newcombe_ci(&tables[0], z, &nlo, &nhi);
	assert_true(nhi - nlo < 0.5 * (2.0 * w)); /* the collapse Tango avoids */
}

/* Large n: Tango's interval tends to the Wald interval too; it contains
 * the estimate and mirrors when A and B swap. */
static void test_tango_limit_and_shape(void **state)
{
	(void)state;
	bsim_pairs t = {.a = 3000, .b = 600, .c = 400, .d = 6000};
	double n = 10000, d = (t.b - t.c) / n;
	double se = sqrt(((t.b + t.c) / n - d * d) / n);
	double lo, hi;
	bsim_stats_tango_ci(&t, BSIM_STATS_Z95, &lo, &hi);
	assert_float_equal(lo, d - BSIM_STATS_Z95 * se, 3e-4);
	assert_float_equal(hi, d + BSIM_STATS_Z95 * se, 3e-4);
	for (int b = 0; b <= 20; b += 4)
		for (int c = 0; c <= 20; c += 5) {
			bsim_pairs u = {.a = 30, .b = b, .c = c, .d = 70 - b - c};
			bsim_pairs s = {.a = u.a, .b = c, .c = b, .d = u.d};
			double l1, h1, l2, h2, e = (double)(b - c) / 100.0;
			bsim_stats_tango_ci(&u, BSIM_STATS_Z95, &l1, &h1);
			bsim_stats_tango_ci(&s, BSIM_STATS_Z95, &l2, &h2);
			assert_true(-1.0 <= l1 && l1 < e && e < h1 && h1 <= 1.0);
			assert_float_equal(l1, -h2, 1e-9);
			assert_float_equal(h1, -l2, 1e-9);
		}
	/* All n pairs discordant one way: q = (1 - delta) / 2 and
	 * T = sqrt(n (1 - delta) / (1 + delta)), so the interval is
	 * [(n - z^2) / (n + z^2), 1]. */
	bsim_pairs all = {0, 10, 0, 0};
	double z2 = BSIM_STATS_Z95 * BSIM_STATS_Z95;
	bsim_stats_tango_ci(&all, BSIM_STATS_Z95, &lo, &hi);
	assert_true(hi == 1.0);
	assert_float_equal(lo, (10.0 - z2) / (10.0 + z2), 1e-9);
}

/* Tango's equivalence test is the interval read at level 1 - 2 alpha: the
 * difference is shown within +-margin exactly when the 90% interval lies
 * inside it (alpha 0.05). */
static void test_tango_tost_matches_interval(void **state)
{
	(void)state;
	double z90 = bsim_stats_normal_upper(0.05);
	for (int b = 0; b <= 12; b++)
		for (int c = 0; c <= 12; c += 3)
			for (double m = 0.02; m < 0.3; m += 0.04) {
				bsim_pairs t = {.a = 40, .b = b, .c = c, .d = 60 - b - c};
				double lo, hi;
				bsim_stats_tango_ci(&t, z90, &lo, &hi);
				int inside = lo > -m && hi < m;
				int tost = bsim_stats_tango_tost(&t, m) < 0.05;
				assert_int_equal(inside, tost);
			}
	bsim_pairs none = {40, 0, 0, 60};
	assert_true(bsim_stats_tango_tost(&none, 0.0) == 1.0);
	/* 100 identical pairs: 90% interval +-0.026, inside +-0.05. */
	assert_true(bsim_stats_tango_tost(&none, 0.05) < 0.05);
}

/* The smallest significant split by hand: 2 (1/2)^m < level decides a
 * one-way split; with Holm over 150 tests at 0.05 that takes 13 pairs. */
static void test_mcnemar_split(void **state)
{
	(void)state;
	assert_int_equal(bsim_stats_mcnemar_split(12, 0.05 / 150), -1);
	assert_int_equal(bsim_stats_mcnemar_split(13, 0.05 / 150), 0);
	assert_int_equal(bsim_stats_mcnemar_split(5, 0.0625), -1);
	assert_int_equal(bsim_stats_mcnemar_split(5, 0.0626), 0);
	/* 10 pairs at 0.05: 1 vs 9 gives 22/1024 = 0.021, 2 vs 8 gives 0.109. */
	assert_int_equal(bsim_stats_mcnemar_split(10, 0.05), 1);
	assert_int_equal(bsim_stats_mcnemar_split(0, 0.05), -1);
}

/* The thresholds for every count agree with the one-count search. */
static void test_mcnemar_splits(void **state)
{
	(void)state;
	static const double levels[] = {0.05, 0.05 / 51, 1e-6};
	int k[301];
	for (int l = 0; l < 3; l++) {
		bsim_stats_mcnemar_splits(300, levels[l], k);
		for (int m = 0; m <= 300; m++)
			assert_int_equal(k[m], bsim_stats_mcnemar_split(m, levels[l]));
	}
}

/* The power of the exact McNemar test at the minimum detectable difference
 * is 0.80, counted by simulating the trials: n pairs each discordant A's way
 * with probability (psi + delta) / 2, B's way with (psi - delta) / 2, the
 * exact test at the level, 20,000 replicates (fixed seed; standard error of
 * a power of 0.8: 0.0028; tolerance 0.015, over 5 of them). Cases: many
 * discordant pairs at 0.05; few at a Holm level of a family of 51 (H1's),
 * where the difference exceeds psi and is taken as the discordance; none
 * (psi = 0: every discordant pair one way). */
static void test_mde_monte_carlo(void **state)
{
	(void)state;
	static const struct {
		int n;
		double psi, level;
	} cases[] = {
	        {100, 0.2, 0.05}, {100, 0.03, 0.05 / 51}, {100, 0.0, 0.05 / 51}, {300, 0.1, 0.01}};
	enum { R = 20000 };
	static int k[301];
	gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
	gsl_rng_set(rng, 20260601);
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		int n = cases[i].n;
		bsim_stats_mcnemar_splits(n, cases[i].level, k);
		double d = bsim_stats_mcnemar_mde(n, k, cases[i].psi, 0.8);
		double psi = fmax(cases[i].psi, d);
		double p10 = 0.5 * (psi + d), p01 = 0.5 * (psi - d);
		int reject = 0;
		for (int r = 0; r < R; r++) {
			int b = 0, c = 0;
			for (int t = 0; t < n; t++) {
				double u = gsl_rng_uniform(rng);
				b += u < p10;
				c += u >= p10 && u < p10 + p01;
			}
			reject += bsim_stats_mcnemar_exact(b, c) < cases[i].level;
		}
		double power = (double)reject / R;
		print_message("n %d, psi %.2f, level %.3g: mde80 %.4f, simulated power %.4f\n", n,
		              cases[i].psi, cases[i].level, d, power);
		assert_true(fabs(power - 0.8) < 0.015);
		assert_float_equal(bsim_stats_mcnemar_power(n, k, psi, d), 0.8, 1e-9);
	}
	gsl_rng_free(rng);
}

/* With many discordant pairs the exact minimum detectable difference
 * approaches Connor's (Biometrics 43, 1987) normal approximation,
 *   sqrt(n) delta = z_{level/2} sqrt(psi) + z_{0.2} sqrt(psi - delta^2),
 * solved for delta; and a difference no trial count can reach is NaN. */
static void test_mde_connor(void **state)
{
	(void)state;
	enum { N = 2000 };
	static int k[N + 1];
	double level = 0.05 / 100, psi = 0.1;
	bsim_stats_mcnemar_splits(N, level, k);
	double za = bsim_stats_normal_upper(level / 2), zb = bsim_stats_normal_upper(0.2);
	double c = (sqrt((double)N) * za + zb * sqrt(N - za * za + zb * zb)) / (N + zb * zb);
	double connor = c * sqrt(psi);
	double d = bsim_stats_mcnemar_mde(N, k, psi, 0.8);
	assert_true(fabs(d - connor) < 0.02 * connor);
	int k3[4];
	bsim_stats_mcnemar_splits(3, 0.05, k3); /* 3 pairs one way: p = 0.25 */
	assert_true(isnan(bsim_stats_mcnemar_mde(3, k3, 0.5, 0.8)));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_mcnemar_by_hand),
	        cmocka_unit_test(test_mcnemar_normal_limit),
	        cmocka_unit_test(test_holm_by_hand),
	        cmocka_unit_test(test_paired_ci_normal_limit),
	        cmocka_unit_test(test_paired_ci_shape),
	        cmocka_unit_test(test_tango_published),
	        cmocka_unit_test(test_tango_no_discordant),
	        cmocka_unit_test(test_tango_limit_and_shape),
	        cmocka_unit_test(test_tango_tost_matches_interval),
	        cmocka_unit_test(test_mcnemar_split),
	        cmocka_unit_test(test_mcnemar_splits),
	        cmocka_unit_test(test_mde_monte_carlo),
	        cmocka_unit_test(test_mde_connor),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
