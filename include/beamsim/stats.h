/* Statistics of traversal counts. */
#ifndef BSIM_STATS_H
#define BSIM_STATS_H

#include "beamsim/base.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Wilson score interval for k successes in n trials at confidence z
 * (1.959964 for 95%). n = 0 gives [0, 1]. */
BSIM_API void bsim_stats_wilson(int k, int n, double z, double *lo, double *hi);

#define BSIM_STATS_Z95 1.959963984540054

/* Exact two-sided McNemar test: of the b + c discordant pairs, b went one
 * way and c the other; under "no difference" b ~ Binomial(b + c, 1/2).
 * Returns min(1, 2 P(X <= min(b, c))); 1 when there is no discordant pair. */
BSIM_API double bsim_stats_mcnemar_exact(int b, int c);

/* Holm's step-down adjustment of n p-values (family-wise error control under
 * any dependence): adj[i] = max over the j sorted before i of
 * min(1, (n - rank_j) p_j). p and adj may be the same array. */
BSIM_API void bsim_stats_holm(const double *p, int n, double *adj);

/* A 2x2 table of paired binary outcomes (the same trial on backends A and
 * B): a both yes, b A yes and B no, c A no and B yes, d both no. */
typedef struct bsim_pairs {
	int a, b, c, d;
} bsim_pairs;

/* The 95% interval of p_A - p_B = (b - c) / n for paired data: Newcombe's
 * hybrid score interval (Statist. Med. 17, 1998, method 10), built from the
 * two Wilson intervals and the correlation of the pairs. It shrinks to a
 * point when the pairs are perfectly correlated (b = c = 0 with a, d > 0);
 * beamsim compare uses Tango's interval below. */
BSIM_API void bsim_stats_newcombe_ci(const bsim_pairs *t, double z, double *lo, double *hi);

/* Tango's score statistic (Statist. Med. 17, 1998, 891-908) for
 * H0: p_A - p_B = delta, delta in (-1, 1):
 *   T(delta) = (b - c - n delta) / sqrt(n (2 q + delta (1 - delta)))
 * with q the maximum-likelihood estimate of the probability of a (no, yes)
 * pair under H0. T falls as delta rises; T ~ N(0, 1) under H0. */
BSIM_API double bsim_stats_tango_score(const bsim_pairs *t, double delta);

/* Tango's score interval for p_A - p_B: every delta with |T(delta)| <= z.
 * Unlike Wald or Newcombe it keeps a width with no discordant pair at all
 * (b = c = 0 gives +-z^2 / (n + z^2)) and stays inside [-1, 1]. */
BSIM_API void bsim_stats_tango_ci(const bsim_pairs *t, double z, double *lo, double *hi);

/* Tango's equivalence test of the paired difference against +-margin:
 * two one-sided score tests, H0: p_A - p_B <= -margin and
 * H0: p_A - p_B >= margin. Returns the larger of their p-values; below
 * alpha, the difference is shown to lie within +-margin (equivalently, the
 * 1 - 2 alpha Tango interval lies inside it). 1 for margin <= 0. */
BSIM_API double bsim_stats_tango_tost(const bsim_pairs *t, double margin);

/* Of m discordant pairs, the largest count k going one way for which the
 * exact McNemar test (k against m - k) has a p-value below level; -1 if
 * none (too few pairs to reach it). |b - c| >= m - 2k is then significant. */
BSIM_API int bsim_stats_mcnemar_split(int m, double level);

/* The exact McNemar test's thresholds for every count of discordant pairs:
 * k[m] = bsim_stats_mcnemar_split(m, level) for m = 0..n (k has n + 1
 * entries), in O(n^2) operations instead of O(n^3). */
BSIM_API void bsim_stats_mcnemar_splits(int n, double level, int *k);

/* The exact power of the two-sided exact McNemar test with thresholds k
 * (bsim_stats_mcnemar_splits) on n pairs when a pair is discordant with
 * probability psi and the difference is delta = p_A - p_B,
 * 0 <= |delta| <= psi <= 1: the probability that its p-value is below the
 * level of k. */
BSIM_API double bsim_stats_mcnemar_power(int n, const int *k, double psi, double delta);

/* The minimum detectable difference: the smallest delta > 0 that the exact
 * McNemar test with thresholds k detects with the given power on n pairs of
 * discordance psi. A difference needs at least that much discordance, so
 * where delta would exceed psi the discordance is taken as delta (every
 * discordant pair one way); psi = 0 (no discordant pair) gives the
 * difference detected that way. NaN when even every pair discordant one
 * way (delta = 1) falls short of the power. */
BSIM_API double bsim_stats_mcnemar_mde(int n, const int *k, double psi, double power);

/* The standard normal quantile z with P(Z > z) = q. */
BSIM_API double bsim_stats_normal_upper(double q);

/* Fisher's exact test of x1/n1 against x2/n2 (independent samples): the
 * two-sided p-value of the hypergeometric count, summed over the tables no
 * more likely than the observed one (R's fisher.test). 1 if n1 or n2 is 0. */
BSIM_API double bsim_stats_fisher_exact(int x1, int n1, int x2, int n2);

/* The 95% interval of p1 - p2 for independent samples: Newcombe's hybrid
 * score interval from the two Wilson intervals (Statist. Med. 17, 1998,
 * method 10). */
BSIM_API void bsim_stats_newcombe_diff_ci(int x1, int n1, int x2, int n2, double z, double *lo,
                                          double *hi);

/* A linear trend of proportions in a score: the least-squares slope
 * (proportion per unit of score) with its Wald interval, and the
 * Cochran-Armitage statistic z with its two-sided p-value. */
typedef struct bsim_stats_trend {
	double slope, lo, hi;
	double z, p;
} bsim_stats_trend;

/* The Cochran-Armitage trend test of x[i]/n[i] in scores s[i], i < k, at
 * confidence z for the slope's interval. p = 1 and z = 0 when every
 * group has the same outcome (no variance). */
BSIM_API void bsim_stats_cochran_armitage(const int *x, const int *n, const double *s, int k,
                                          double z, bsim_stats_trend *out);

#ifdef __cplusplus
}
#endif
#endif
