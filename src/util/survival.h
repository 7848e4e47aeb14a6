/* Internal: time-to-event statistics of a set of trials, each of which
 * either has an event (it left the gate) at a time or is censored (still in
 * the gate when it ended): the Kaplan-Meier estimate of the survival
 * function with Greenwood's variance, and the constant-hazard (exponential)
 * rate with its exact Poisson interval. Used by the sweep's survival.csv
 * (store/survival_files.c) and the escape-rate analysis
 * (analysis/escape.c). */
#ifndef BSIM_UTIL_SURVIVAL_H
#define BSIM_UTIL_SURVIVAL_H

/* The Kaplan-Meier product limit, fed the distinct times in increasing
 * order:
 *   S(t) = prod over event times t_i <= t of (1 - d_i / n_i)
 * with d_i the events at t_i and n_i the trials still at risk just before
 * t_i (censored trials leave the risk set after the events of their time,
 * the usual convention). Greenwood's variance:
 *   Var S(t) = S(t)^2 sum_i d_i / (n_i (n_i - d_i)). */
typedef struct survival_km {
	long at_risk;     /* n: trials at risk after the last step */
	double s;         /* S after the last step */
	double greenwood; /* sum d_i / (n_i (n_i - d_i)) */
} survival_km;

/* A curve of n trials, S = 1. */
void bsim_survival_km_start(survival_km *k, long n);

/* At one time: d events, then c censored. */
void bsim_survival_km_step(survival_km *k, long d, long c);

/* The pointwise interval of S at confidence z (1.96: 95%) from Greenwood's
 * variance on the log(-log S) scale (Kalbfleisch and Prentice), which
 * stays inside [0, 1]: S^exp(+-z sigma), sigma = sqrt(greenwood) / |ln S|.
 * S = 1 (no event yet) gives [1, 1], S = 0 gives [0, 0]. */
void bsim_survival_km_interval(const survival_km *k, double z, double *lo, double *hi);

/* The maximum-likelihood rate of an exponential time to event with
 * censoring, events / exposure (1/s; exposure the summed time at risk, s),
 * and its exact (Garwood) 95% interval from the chi-square quantiles of the
 * Poisson count: [chi2(0.025; 2d) / 2T, chi2(0.975; 2d + 2) / 2T]. No
 * exposure gives rate NaN, [0, inf]. */
void bsim_survival_rate(long events, double exposure, double *rate, double *lo, double *hi);

#endif
