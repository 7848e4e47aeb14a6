/* Statistics of traversal counts. */
#ifndef BEAMSIM_STATS_H
#define BEAMSIM_STATS_H

#ifdef __cplusplus
extern "C" {
#endif

/* Wilson score interval for k successes in n trials at confidence z
 * (1.959964 for 95%). n = 0 gives [0, 1]. */
void bsim_wilson(int k, int n, double z, double *lo, double *hi);

#define BSIM_Z95 1.959963984540054

/* Exact two-sided McNemar test: of the b + c discordant pairs, b went one
 * way and c the other; under "no difference" b ~ Binomial(b + c, 1/2).
 * Returns min(1, 2 P(X <= min(b, c))); 1 when there is no discordant pair. */
double bsim_mcnemar_exact(int b, int c);

/* Holm's step-down adjustment of n p-values (family-wise error control under
 * any dependence): adj[i] = max over the j sorted before i of
 * min(1, (n - rank_j) p_j). p and adj may be the same array. */
void bsim_holm(const double *p, int n, double *adj);

/* A 2x2 table of paired binary outcomes (the same trial on backends A and
 * B): a both yes, b A yes and B no, c A no and B yes, d both no. */
typedef struct bsim_pairs {
	int a, b, c, d;
} bsim_pairs;

/* The 95% interval of p_A - p_B = (b - c) / n for paired data: Newcombe's
 * hybrid score interval (Statist. Med. 17, 1998, method 10), built from the
 * two Wilson intervals and the correlation of the pairs. */
void bsim_paired_diff_ci(const bsim_pairs *t, double z, double *lo, double *hi);

#ifdef __cplusplus
}
#endif
#endif
