/* Kaplan-Meier survival with Greenwood's variance, and the exponential rate
 * with its exact interval; see survival.h. */
#include "util/survival.h"

#include <math.h>

#include <gsl/gsl_cdf.h>

void bsim_survival_km_start(survival_km *k, long n)
{
	k->at_risk = n;
	k->s = 1.0;
	k->greenwood = 0.0;
}

void bsim_survival_km_step(survival_km *k, long d, long c)
{
	long n = k->at_risk;
	if (d > 0 && n > 0) {
		k->s *= 1.0 - (double)d / (double)n;
		/* d = n takes S to 0, where the variance is 0 and the sum is
		 * no longer used (bsim_survival_km_interval) */
		if (n > d)
			k->greenwood += (double)d / ((double)n * (double)(n - d));
	}
	k->at_risk = n - d - c;
}

void bsim_survival_km_interval(const survival_km *k, double z, double *lo, double *hi)
{
	if (k->s >= 1.0 || k->s <= 0.0) {
		*lo = *hi = k->s;
		return;
	}
	double ls = log(k->s);
	double sigma = sqrt(k->greenwood) / fabs(ls);
	/* S^exp(z sigma) is the lower bound: a larger power of S < 1 */
	*lo = pow(k->s, exp(z * sigma));
	*hi = pow(k->s, exp(-z * sigma));
}

/* The p-quantile of chi-square with nu degrees of freedom: GSL's inverse,
 * which fails to converge for large nu, up to 400; beyond, Wilson and
 * Hilferty's cube-root normal approximation (relative error below 1e-4
 * there). */
static double chisq_quantile(double p, double nu)
{
	if (nu <= 400.0)
		return gsl_cdf_chisq_Pinv(p, nu);
	double z = gsl_cdf_ugaussian_Pinv(p), a = 2.0 / (9.0 * nu);
	double c = 1.0 - a + z * sqrt(a);
	return nu * c * c * c;
}

void bsim_survival_rate(long events, double exposure, double *rate, double *lo, double *hi)
{
	if (!(exposure > 0.0)) {
		*rate = NAN;
		*lo = 0.0;
		*hi = INFINITY;
		return;
	}
	*rate = (double)events / exposure;
	*lo = events > 0 ? chisq_quantile(0.025, 2.0 * (double)events) / (2.0 * exposure) : 0.0;
	*hi = chisq_quantile(0.975, 2.0 * (double)events + 2.0) / (2.0 * exposure);
}
