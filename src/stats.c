/* Statistics of traversal counts.
 *
 * Wilson score interval: with p = k/n and c = z^2/n,
 *   centre = (p + c/2) / (1 + c)
 *   half   = z / (1 + c) * sqrt(p (1 - p) / n + c / (4 n))
 * It stays inside [0, 1] and is sensible at p = 0 and p = 1, where the
 * normal-approximation interval collapses to a point. */
#include "beamsim/stats.h"

#include <math.h>
#include <stdlib.h>

void bsim_wilson(int k, int n, double z, double *lo, double *hi)
{
	if (n <= 0) {
		*lo = 0.0;
		*hi = 1.0;
		return;
	}
	double p = (double)k / n;
	double c = z * z / n;
	double centre = (p + 0.5 * c) / (1.0 + c);
	double half = z / (1.0 + c) * sqrt(p * (1.0 - p) / n + 0.25 * c / n);
	/* At k = 0 and k = n the bound is exactly 0 or 1; computing it would
	 * leave a round-off residue like 1e-18 in the output. */
	*lo = k <= 0 ? 0.0 : fmax(0.0, centre - half);
	*hi = k >= n ? 1.0 : fmin(1.0, centre + half);
}

/* McNemar, exact: P(X <= k) for X ~ Binomial(m, 1/2) summed in log space,
 * so m in the thousands neither overflows nor underflows early. */
double bsim_mcnemar_exact(int b, int c)
{
	int m = b + c, k = b < c ? b : c;
	if (m <= 0)
		return 1.0;
	const double ln2 = 0.693147180559945309417;
	double tail = 0.0;
	for (int i = 0; i <= k; i++)
		tail += exp(lgamma(m + 1.0) - lgamma(i + 1.0) - lgamma(m - i + 1.0) - m * ln2);
	return fmin(1.0, 2.0 * tail);
}

typedef struct holm_item {
	double p;
	int i;
} holm_item;

static int holm_cmp(const void *x, const void *y)
{
	const holm_item *a = x, *b = y;
	/* Ties by index keep the order, and so the result, reproducible. */
	return a->p < b->p ? -1 : a->p > b->p ? 1 : a->i - b->i;
}

/* Holm: sort p ascending; the k-th smallest (k = 0..n-1) is scaled by
 * (n - k) and the running maximum keeps the adjusted values monotone. */
void bsim_holm(const double *p, int n, double *adj)
{
	holm_item *it = malloc((size_t)(n > 0 ? n : 1) * sizeof *it);
	if (!it) { /* Bonferroni is never smaller than Holm: still valid */
		for (int i = 0; i < n; i++)
			adj[i] = fmin(1.0, p[i] * n);
		return;
	}
	for (int i = 0; i < n; i++)
		it[i] = (holm_item){p[i], i};
	qsort(it, (size_t)n, sizeof *it, holm_cmp);
	double run = 0.0;
	for (int k = 0; k < n; k++) {
		run = fmax(run, fmin(1.0, (n - k) * it[k].p));
		adj[it[k].i] = run;
	}
	free(it);
}

/* Newcombe (1998) method 10. With p1 = (a+b)/n in [l1, u1] and
 * p2 = (a+c)/n in [l2, u2] (Wilson), d = p1 - p2 and the phi coefficient
 *   phi = (ad - bc) / sqrt((a+b)(c+d)(a+c)(b+d))   (0 if a margin is 0)
 *   L = d - sqrt((p1 - l1)^2 - 2 phi (p1 - l1)(u2 - p2) + (u2 - p2)^2)
 *   U = d + sqrt((u1 - p1)^2 - 2 phi (u1 - p1)(p2 - l2) + (p2 - l2)^2)
 * clipped to [-1, 1]. Identical outcomes (b = c = 0) give an interval
 * around 0 as wide as the sample allows, not a point. */
void bsim_paired_diff_ci(const bsim_pairs *t, double z, double *lo, double *hi)
{
	int n = t->a + t->b + t->c + t->d;
	if (n <= 0) {
		*lo = -1.0;
		*hi = 1.0;
		return;
	}
	double l1, u1, l2, u2;
	bsim_wilson(t->a + t->b, n, z, &l1, &u1);
	bsim_wilson(t->a + t->c, n, z, &l2, &u2);
	double p1 = (double)(t->a + t->b) / n, p2 = (double)(t->a + t->c) / n;
	double d = p1 - p2;
	double den = (double)(t->a + t->b) * (t->c + t->d) * (t->a + t->c) * (t->b + t->d);
	double phi = den > 0.0 ? ((double)t->a * t->d - (double)t->b * t->c) / sqrt(den) : 0.0;
	double dl =
	        (p1 - l1) * (p1 - l1) - 2.0 * phi * (p1 - l1) * (u2 - p2) + (u2 - p2) * (u2 - p2);
	double du =
	        (u1 - p1) * (u1 - p1) - 2.0 * phi * (u1 - p1) * (p2 - l2) + (p2 - l2) * (p2 - l2);
	*lo = fmax(-1.0, d - sqrt(fmax(dl, 0.0)));
	*hi = fmin(1.0, d + sqrt(fmax(du, 0.0)));
}
