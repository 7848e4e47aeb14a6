/* Internal: the escape rate out of the gate against the landscape's
 * barrier over the noise power, fitted Arrhenius/Kramers-style (beamsim
 * escape, docs/first_passage.md):
 *
 *   ln k = ln k0 - dE / (c D)
 *
 * k the constant-hazard rate of traversal (traversals / time at risk after
 * the body first reaches the beams), dE the lowest pass's height above the
 * start basin's floor (analysis/landscape_barrier.c), D = Rm^2 / f the
 * low-frequency power spectral density of the held random force (N^2 s). */
#ifndef BSIM_ANALYSIS_ESCAPE_H
#define BSIM_ANALYSIS_ESCAPE_H

#include "beamsim/landscape.h"
#include "beamsim/scene.h"
#include "beamsim/trial.h"

/* A straight line y = a + b x by least squares (gsl_fit_linear), its
 * standard errors from the scatter about it, and the Arrhenius reading:
 * k0 = exp(a), c = -1 / b with se(c) = se(b) / b^2. chisq_poisson =
 * sum events_i r_i^2: the residuals against their Poisson sampling error
 * (var ln k = 1 / events), chi-square with n - 2 degrees of freedom if the
 * line holds; p its upper tail. */
typedef struct escape_fit {
	int n;
	double a, b, se_a, se_b, cov_ab;
	double k0, c, se_c;
	double rms; /* root mean square of the residuals of ln k */
	double r2;  /* coefficient of determination */
	double chisq_poisson, p_poisson;
} escape_fit;

/* Fits y = a + b x over n points (events[i] the Poisson weight of point i
 * for chisq_poisson; may be NULL). BSIM_EINPUT under 3 points or without
 * spread in x. */
int bsim_escape_fit_line(const double *x, const double *y, const double *events, int n,
                         escape_fit *out, bsim_error *err);

/* What the fit f says of the data, in a sentence (a constant string): the
 * Arrhenius line is rejected when the residuals exceed their Poisson
 * sampling error (p_poisson < ESCAPE_P_REJECT), and explains little when
 * R^2 < ESCAPE_R2_LITTLE; k0 and c then do not describe the groups. */
#define ESCAPE_P_REJECT  0.01
#define ESCAPE_R2_LITTLE 0.5
const char *bsim_escape_fit_verdict(const escape_fit *f);

/* s, the time the body of scene s, pushed by its propulsion from its start
 * velocity, first touches a beam at rest (the lateral random force does not
 * move it forward): 0 if it starts touching or is never pushed forward. */
double bsim_escape_contact_time(const bsim_scene *s);

/* The options of bsim escape: the landscape grid the barriers are searched
 * on. */
typedef struct escape_def {
	const char *dir; /* a sweep's output directory */
	const char *out; /* where kramers.csv, kramers.json and the figure go */
	int overwrite;   /* 1: replace the result out holds; 0: refuse it */
	bsim_landscape_grid_def grid;
} escape_def;

typedef struct escape_summary {
	int groups, used, scenes; /* groups, groups in the fit, landscapes searched */
	escape_fit fit;
	int fitted; /* 0: too few groups with a barrier, noise and a traversal */
	int drawn;  /* 1: gnuplot drew the figure, -1: it failed on it (util/figure.h) */
} escape_summary;

/* Reads the sweep in def->dir, searches each distinct scene's landscape,
 * fits and writes def->out as a set. BSIM_EINPUT for a directory that is
 * no sweep or a lattice sweep. */
int bsim_escape_run(const escape_def *def, escape_summary *sum, bsim_error *err);

#endif
