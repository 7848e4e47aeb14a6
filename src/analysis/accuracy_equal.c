/* The accuracy study's comparison at equal error (equal_error.csv and the
 * "At equal error" section of accuracy.md): a speed ratio between backends
 * measured at one step and one setting each says nothing about what each
 * buys for its time; this one asks, for a trajectory error a user wants,
 * what each backend's cheapest way to reach it costs.
 *
 * For a target e* (m, mean consistency error) and a backend b:
 *   pick(e*, b) = argmin over rows r of b with err_mean(r) <= e*,
 *                 r not the reference and no trial of r unstable,
 *                 of cpu_cost(r) (CPU s per simulated s)
 *   ratio(e*, b) = cpu_cost(pick(e*, b)) / cpu_cost(pick(e*, b0)),
 * b0 the first backend of the study. The reference row is left out because
 * its error is 0 by definition (it is its own reference), not measured; a
 * tie in cost keeps the earlier row. */
#include "beamsim/accuracy.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "util/atomic_file.h"

/* The backends of r in order of first appearance; returns their number. */
static int backends_of(const bsim_accuracy_result *r, const char **names)
{
	int n = 0;
	for (int i = 0; i < r->n; i++) {
		int k = 0;
		while (k < n && strcmp(names[k], r->rows[i].backend) != 0)
			k++;
		if (k == n)
			names[n++] = r->rows[i].backend;
	}
	return n;
}

static int pick(const bsim_accuracy_result *r, const char *backend, double target)
{
	int best = -1;
	for (int i = 0; i < r->n; i++) {
		const bsim_accuracy_row *w = &r->rows[i];
		if (strcmp(w->backend, backend) != 0 || w->reference || w->failed > 0 ||
		    !isfinite(w->err_mean) || !isfinite(w->cpu_cost) || !(w->err_mean <= target))
			continue;
		if (best < 0 || w->cpu_cost < r->rows[best].cpu_cost)
			best = i;
	}
	return best;
}

int bsim_accuracy_equal_error(const bsim_accuracy_result *r, const double *targets, int n_targets,
                              bsim_accuracy_equal **out, int *n, bsim_error *err)
{
	*out = NULL;
	*n = 0;
	if (n_targets < 0 || n_targets > BSIM_ACCURACY_TARGETS_MAX)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "accuracy: %d error targets: expected 0..%d", n_targets,
		                      BSIM_ACCURACY_TARGETS_MAX);
	for (int t = 0; t < n_targets; t++)
		if (!isfinite(targets[t]) || targets[t] <= 0.0)
			return bsim_error_set(err, BSIM_EINPUT,
			                      "accuracy: error target %g m: expected a number > 0",
			                      targets[t]);
	const char **names = r->n ? malloc((size_t)r->n * sizeof *names) : NULL;
	if (r->n && !names)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	int n_b = backends_of(r, names);
	if (n_b == 0 || n_targets == 0) {
		free(names);
		return BSIM_OK;
	}
	bsim_accuracy_equal *eq = calloc((size_t)(n_b * n_targets), sizeof *eq);
	if (!eq) {
		free(names);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	for (int t = 0; t < n_targets; t++) {
		bsim_accuracy_equal *row = &eq[t * n_b];
		for (int b = 0; b < n_b; b++) {
			bsim_accuracy_equal *e = &row[b];
			e->target = targets[t];
			e->backend = names[b];
			e->row = pick(r, names[b], targets[t]);
			e->cpu_cost = e->row >= 0 ? r->rows[e->row].cpu_cost : NAN;
		}
		for (int b = 0; b < n_b; b++)
			row[b].ratio = row[b].row >= 0 && row[0].row >= 0
			                       ? row[b].cpu_cost / row[0].cpu_cost
			                       : NAN;
	}
	free(names);
	*out = eq;
	*n = n_b * n_targets;
	return BSIM_OK;
}

int bsim_accuracy_write_equal_csv(const char *path, const bsim_accuracy_result *r,
                                  const bsim_accuracy_equal *eq, int n_eq, bsim_error *err)
{
	bsim_atomic_file o;
	int rc = bsim_atomic_file_open(&o, path, err);
	if (rc)
		return rc;
	fputs("target_m,backend,setting,h_s,err_mean_m,cpu_per_sim_s,ratio_equal_error\n", o.f);
	for (int i = 0; i < n_eq; i++) {
		const bsim_accuracy_equal *e = &eq[i];
		if (e->row < 0) {
			fprintf(o.f, "%.6g,%s,,,,,\n", e->target, e->backend);
			continue;
		}
		const bsim_accuracy_row *w = &r->rows[e->row];
		fprintf(o.f, "%.6g,%s,%s,%.9g,%.6e,%.6e,", e->target, e->backend, w->setting, w->h,
		        w->err_mean, e->cpu_cost);
		if (isfinite(e->ratio))
			fprintf(o.f, "%.6g", e->ratio);
		fputc('\n', o.f);
	}
	return bsim_atomic_file_commit(&o, err);
}
