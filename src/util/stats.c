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

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_roots.h>

void bsim_stats_wilson(int k, int n, double z, double *lo, double *hi)
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
double bsim_stats_mcnemar_exact(int b, int c)
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
void bsim_stats_holm(const double *p, int n, double *adj)
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
void bsim_stats_newcombe_ci(const bsim_pairs *t, double z, double *lo, double *hi)
{
	int n = t->a + t->b + t->c + t->d;
	if (n <= 0) {
		*lo = -1.0;
		*hi = 1.0;
		return;
	}
	double l1, u1, l2, u2;
	bsim_stats_wilson(t->a + t->b, n, z, &l1, &u1);
	bsim_stats_wilson(t->a + t->c, n, z, &l2, &u2);
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

/* Tango (1998). Under H0: p_A - p_B = delta the probabilities of the
 * discordant cells are q12 = q21 + delta and q21 = q; maximising the
 * likelihood in q gives the root of
 *   2n q^2 + B q + C = 0,  B = -b - c + (2n - b + c) delta,
 *                          C = -c delta (1 - delta),
 *   q = (sqrt(B^2 - 4 (2n) C) - B) / (4n),
 * and the score statistic
 *   T = (b - c - n delta) / sqrt(n (2 q + delta (1 - delta))).
 * The interval's ends solve T = z (lower) and T = -z (upper); T is
 * monotone, so each end is one bracketed root (Brent, GSL). */
double bsim_stats_tango_score(const bsim_pairs *t, double delta)
{
	double n = (double)t->a + t->b + t->c + t->d;
	double b = t->b, c = t->c;
	double A = 2.0 * n;
	double B = -b - c + (2.0 * n - b + c) * delta;
	double C = -c * delta * (1.0 - delta);
	double q = (sqrt(fmax(B * B - 4.0 * A * C, 0.0)) - B) / (2.0 * A);
	double var = n * (2.0 * q + delta * (1.0 - delta));
	double num = b - c - n * delta;
	if (var <= 0.0) /* only at delta = +-1 with the data at that end */
		return num > 0.0 ? HUGE_VAL : num < 0.0 ? -HUGE_VAL : 0.0;
	return num / sqrt(var);
}

typedef struct tango_root {
	const bsim_pairs *t;
	double target;
} tango_root;

static double tango_f(double delta, void *p)
{
	const tango_root *r = p;
	return bsim_stats_tango_score(r->t, delta) - r->target;
}

/* The delta in [lo, hi] where T(delta) = target, given T(lo) - target and
 * T(hi) - target of opposite signs; the end itself if they are not (the
 * interval reaches -1 or 1). */
static double tango_solve(const bsim_pairs *t, double target, double lo, double hi)
{
	tango_root r = {t, target};
	gsl_function f = {tango_f, &r};
	double f_lo = tango_f(lo, &r), f_hi = tango_f(hi, &r);
	if (f_lo == 0.0)
		return lo;
	if (f_hi == 0.0)
		return hi;
	if ((f_lo > 0.0) == (f_hi > 0.0))
		return fabs(f_lo) < fabs(f_hi) ? lo : hi;
	gsl_root_fsolver *s = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
	if (!s)
		return 0.5 * (lo + hi);
	gsl_error_handler_t *old = gsl_set_error_handler_off();
	double x = 0.5 * (lo + hi);
	if (gsl_root_fsolver_set(s, &f, lo, hi) == GSL_SUCCESS)
		for (int i = 0; i < 200; i++) {
			if (gsl_root_fsolver_iterate(s) != GSL_SUCCESS)
				break;
			x = gsl_root_fsolver_root(s);
			double a = gsl_root_fsolver_x_lower(s), b = gsl_root_fsolver_x_upper(s);
			if (gsl_root_test_interval(a, b, 1e-15, 1e-13) == GSL_SUCCESS)
				break;
		}
	gsl_set_error_handler(old);
	gsl_root_fsolver_free(s);
	return x;
}

void bsim_stats_tango_ci(const bsim_pairs *t, double z, double *lo, double *hi)
{
	int n = t->a + t->b + t->c + t->d;
	if (n <= 0) {
		*lo = -1.0;
		*hi = 1.0;
		return;
	}
	double d = (double)(t->b - t->c) / n;
	/* T(d) = 0; T grows without bound toward delta = -1 (unless d is -1
	 * itself) and falls without bound toward +1, so each end lies between
	 * d and -1 or +1. The ends of the search stop short of +-1, where the
	 * variance vanishes. */
	const double edge = 1.0 - 1e-12;
	*lo = d <= -edge ? -1.0 : tango_solve(t, z, -edge, d);
	*hi = d >= edge ? 1.0 : tango_solve(t, -z, d, edge);
}

double bsim_stats_tango_tost(const bsim_pairs *t, double margin)
{
	if (margin <= 0.0 || t->a + t->b + t->c + t->d <= 0)
		return 1.0;
	if (margin >= 1.0)
		return 0.0;
	/* H0: delta <= -margin is rejected for large T(-margin), H0: delta >=
	 * margin for small T(margin). */
	double p_low = gsl_cdf_ugaussian_Q(bsim_stats_tango_score(t, -margin));
	double p_high = gsl_cdf_ugaussian_P(bsim_stats_tango_score(t, margin));
	return fmax(p_low, p_high);
}

int bsim_stats_mcnemar_split(int m, double level)
{
	int k = -1;
	/* The p-value rises with k up to m / 2. */
	for (int j = 0; 2 * j < m && bsim_stats_mcnemar_exact(j, m - j) < level; j++)
		k = j;
	return k;
}

void bsim_stats_mcnemar_splits(int n, double level, int *k)
{
	const double ln2 = 0.693147180559945309417;
	for (int m = 0; m <= n; m++) {
		/* The tail summed in bsim_stats_mcnemar_exact's order, so the
		 * thresholds are bsim_stats_mcnemar_split's to the bit. */
		double tail = 0.0;
		k[m] = -1;
		for (int j = 0; 2 * j < m; j++) {
			tail += exp(lgamma(m + 1.0) - lgamma(j + 1.0) - lgamma(m - j + 1.0) -
			            m * ln2);
			if (fmin(1.0, 2.0 * tail) >= level)
				break;
			k[m] = j;
		}
	}
}

/* The exact power of the exact McNemar test (Duffy, Biometrics 40, 1984,
 * 1005-1015). Of n pairs m are discordant, m ~ Binomial(n, psi); given m,
 * the b going A's way are Binomial(m, q), q = (psi + delta) / (2 psi). The
 * test rejects when min(b, m - b) <= k_m (never when k_m < 0), so
 *   power = sum_m Bin(m; n, psi) [F(k_m; m, q) + F(k_m; m, 1 - q)]
 * with F the binomial distribution function (the two tails are disjoint:
 * 2 k_m < m). Terms beyond 12 standard deviations of m are below 1e-30.
 *
 * The minimum detectable difference solves power(delta; max(psi, delta)) =
 * target by bisection: the power rises with delta at fixed psi, and along
 * psi = delta (q = 1: power = P(m >= the fewest pairs that reach the
 * level)), and the two meet at delta = psi. Connor's normal approximation
 * (Biometrics 43, 1987, 207-211)
 *   sqrt(n) delta = z_{level/2} sqrt(psi) + z_{power} sqrt(psi - delta^2)
 * agrees when the discordant pairs are many; with few, as in most groups
 * of 100 pairs at a Holm level, it overstates the difference (0.165
 * against 0.134 at 100 pairs and level 0.05 / 51, where its power is about
 * 0.95), so the power is computed exactly. */
double bsim_stats_mcnemar_power(int n, const int *k, double psi, double delta)
{
	if (n <= 0 || !(psi > 0.0))
		return 0.0;
	psi = fmin(psi, 1.0);
	double q = fmin(1.0, fmax(0.0, 0.5 * (1.0 + delta / psi)));
	double mean = n * psi, sd = sqrt(n * psi * (1.0 - psi));
	int lo = (int)fmax(0.0, floor(mean - 12.0 * sd - 2.0));
	int hi = (int)fmin((double)n, ceil(mean + 12.0 * sd + 2.0));
	double power = 0.0;
	for (int m = lo; m <= hi; m++) {
		if (k[m] < 0)
			continue;
		double tails = gsl_cdf_binomial_P((unsigned)k[m], q, (unsigned)m) +
		               gsl_cdf_binomial_P((unsigned)k[m], 1.0 - q, (unsigned)m);
		power += gsl_ran_binomial_pdf((unsigned)m, psi, (unsigned)n) * tails;
	}
	return fmin(1.0, power);
}

double bsim_stats_mcnemar_mde(int n, const int *k, double psi, double power)
{
	psi = fmin(1.0, fmax(0.0, psi));
	if (n <= 0 || bsim_stats_mcnemar_power(n, k, 1.0, 1.0) < power)
		return NAN;
	double lo = 0.0, hi = 1.0;
	for (int i = 0; i < 50; i++) {
		double mid = 0.5 * (lo + hi);
		if (bsim_stats_mcnemar_power(n, k, fmax(psi, mid), mid) >= power)
			hi = mid;
		else
			lo = mid;
	}
	return hi;
}

double bsim_stats_normal_upper(double q)
{
	return gsl_cdf_ugaussian_Qinv(q);
}

/* Fisher's exact test of x1/n1 against x2/n2: conditional on the margins,
 * the count x1 is hypergeometric,
 *   P(X = x) = C(n1, x) C(n2, t - x) / C(n1 + n2, t),  t = x1 + x2,
 * and the two-sided p-value sums P(X = x) over every x no more likely than
 * the observed one (R's fisher.test: "no more likely" with a relative
 * tolerance of 1e-7 against round-off). Log space: n in the thousands. */
static double hyper_log(int x, int n1, int n2, int t)
{
	return lgamma(n1 + 1.0) - lgamma(x + 1.0) - lgamma(n1 - x + 1.0) + lgamma(n2 + 1.0) -
	       lgamma(t - x + 1.0) - lgamma(n2 - t + x + 1.0) - lgamma(n1 + n2 + 1.0) +
	       lgamma(t + 1.0) + lgamma(n1 + n2 - t + 1.0);
}

double bsim_stats_fisher_exact(int x1, int n1, int x2, int n2)
{
	if (n1 <= 0 || n2 <= 0)
		return 1.0;
	int t = x1 + x2;
	int lo = t - n2 > 0 ? t - n2 : 0, hi = t < n1 ? t : n1;
	double l0 = hyper_log(x1, n1, n2, t), p = 0.0;
	for (int x = lo; x <= hi; x++) {
		double l = hyper_log(x, n1, n2, t);
		if (l <= l0 + 1e-7)
			p += exp(l);
	}
	return p < 1.0 ? p : 1.0;
}

/* Newcombe's hybrid score interval for p1 - p2 of independent samples
 * (Statist. Med. 17, 1998, 873-890, method 10): with [l_i, u_i] the Wilson
 * intervals and d = p1 - p2,
 *   [d - sqrt((p1 - l1)^2 + (u2 - p2)^2), d + sqrt((u1 - p1)^2 + (p2 - l2)^2)]. */
void bsim_stats_newcombe_diff_ci(int x1, int n1, int x2, int n2, double z, double *lo, double *hi)
{
	double l1, u1, l2, u2;
	bsim_stats_wilson(x1, n1, z, &l1, &u1);
	bsim_stats_wilson(x2, n2, z, &l2, &u2);
	double p1 = n1 > 0 ? (double)x1 / n1 : 0.0, p2 = n2 > 0 ? (double)x2 / n2 : 0.0;
	double d = p1 - p2;
	*lo = d - sqrt((p1 - l1) * (p1 - l1) + (u2 - p2) * (u2 - p2));
	*hi = d + sqrt((u1 - p1) * (u1 - p1) + (p2 - l2) * (p2 - l2));
}

/* Cochran-Armitage test for a linear trend of k proportions x_i/n_i in
 * scores s_i (Agresti, Categorical Data Analysis, 2002, Sec. 5.3.5): with
 * the pooled p = sum x / sum n and sbar = sum n_i s_i / sum n,
 *   z = sum x_i (s_i - sbar) / sqrt(p (1 - p) sum n_i (s_i - sbar)^2),
 * N(0, 1) under "no trend". The slope is the weighted least-squares line
 * of p_i on s_i, b = sum n_i (s_i - sbar) p_i / Sxx, Sxx = sum n_i
 * (s_i - sbar)^2, and its Wald interval uses each group's own binomial
 * variance: Var b = sum n_i (s_i - sbar)^2 p_i (1 - p_i) / Sxx^2. */
void bsim_stats_cochran_armitage(const int *x, const int *n, const double *s, int k, double z,
                                 bsim_stats_trend *out)
{
	double N = 0.0, X = 0.0, S = 0.0;
	for (int i = 0; i < k; i++) {
		N += n[i];
		X += x[i];
		S += n[i] * s[i];
	}
	*out = (bsim_stats_trend){.p = 1.0};
	if (N <= 0.0)
		return;
	double sbar = S / N, p = X / N, t = 0.0, sxx = 0.0, b = 0.0, var = 0.0;
	for (int i = 0; i < k; i++) {
		double ds = s[i] - sbar, pi = n[i] > 0 ? (double)x[i] / n[i] : 0.0;
		t += x[i] * ds;
		sxx += n[i] * ds * ds;
		b += n[i] * ds * pi;
		var += n[i] * ds * ds * pi * (1.0 - pi);
	}
	if (sxx <= 0.0)
		return;
	out->slope = b / sxx;
	double se = sqrt(var) / sxx;
	out->lo = out->slope - z * se;
	out->hi = out->slope + z * se;
	double v0 = p * (1.0 - p) * sxx;
	if (v0 > 0.0) {
		out->z = t / sqrt(v0);
		out->p = fmin(1.0, 2.0 * gsl_cdf_ugaussian_Q(fabs(out->z)));
	}
}
