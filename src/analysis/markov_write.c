/* A prediction's files (beamsim markov predict --out DIR; beamsim/markov.h). */
#define _POSIX_C_SOURCE 200809L

#include <stdio.h>
#include <string.h>

#include "analysis/markov_internal.h"
#include "beamsim/backend_registry.h"
#include "util/atomic_file.h"
#include "beamsim/backend.h"
#include "beamsim/markov.h"
#include "beamsim/lattice_outcome.h"
#include "store/matlab.h"
#include "store/session.h"
#include "beamsim/limits.h"
#include "util/figure.h"

static int write_tables(const char *stage, const bsim_markov_prediction *p, bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	bsim_atomic_file o;
	snprintf(path, sizeof path, "%s/prediction.csv", stage);
	if (bsim_atomic_file_open(&o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	fputs("location,kind,ix,iy,p\n", o.f);
	static const char *const kinds[] = {"end", "side", "stuck"};
	for (int i = 0; i < p->n_locations; i++) {
		char label[48];
		bsim_lattice_location_label(p->loc[i], label, sizeof label);
		fprintf(o.f, "%s,%s,%d,%d,%.12g\n", label, kinds[p->loc[i].kind], p->loc[i].ix,
		        p->loc[i].iy, p->p[i]);
	}
	if (bsim_atomic_file_commit(&o, err) != BSIM_OK)
		return BSIM_EFAIL;
	snprintf(path, sizeof path, "%s/prediction_gates.csv", stage);
	if (bsim_atomic_file_open(&o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	fputs("gates,p\n", o.f);
	for (int k = 1; k <= p->n_gates; k++)
		if (p->p_gates[k] > 1e-15)
			fprintf(o.f, "%d,%.12g\n", k, p->p_gates[k]);
	return bsim_atomic_file_commit(&o, err);
}

/* prediction.png: the predicted final locations as the field, titled
 * with the lattice, the chain and what the maps were simulated with. */
static int write_figure(const char *stage, const bsim_scene *lattice, const bsim_markov_set *set,
                        const bsim_markov_prediction *p, int *drawn, bsim_error *err)
{
	char fp[32], rm[32], params[300], title[600];
	snprintf(fp, sizeof fp, "%g",
	         lattice->effects.has_propulsion ? lattice->effects.propulsion_force : 0.0);
	snprintf(rm, sizeof rm, "%g",
	         lattice->effects.has_random_force ? lattice->effects.random_magnitude : 0.0);
	const bsim_override ov[2] = {{"effects.propulsion.force", fp, NULL},
	                             {"effects.random_force.magnitude", rm, NULL}};
	const bsim_backend *b = set && set->def.backend ? set->def.backend : bsim_backend_default();
	bsim_markov_title_params(params, sizeof params, b ? b->name : NULL, ov, 2);
	if (p->nearest_walks > 0)
		snprintf(title, sizeof title,
		         "%s: final locations predicted by %ld nearest-neighbour walks\n%s, "
		         "each step from the %d nearest of %d visits",
		         lattice->name, p->nearest_walks, params, p->nearest_k, p->n_states);
	else
		snprintf(title, sizeof title,
		         "%s: final locations predicted by the Markov chain (%d states, %s)\n%s, "
		         "%d trials per entry bin",
		         lattice->name, p->n_states, p->exact ? "LU" : "series", params,
		         set ? set->def.trials : 0);
	const markov_field_panel panel = {"probability of each final location", p->p, NULL};
	return bsim_markov_field_figure(stage, "prediction", title, p->loc, p->n_locations, &panel,
	                                1, 1, drawn, err);
}

/* time.csv: the walks' distribution of the time to the outcome, a row a
 * bin, with each kind's cumulative probability; and the figure time. */
static int write_time(const char *stage, const bsim_scene *lattice, const bsim_markov_prediction *p,
                      int *drawn, bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	bsim_atomic_file o;
	snprintf(path, sizeof path, "%s/time.csv", stage);
	if (bsim_atomic_file_open(&o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	fputs("t_lo,t_hi,p_end,p_side,p_stuck,cdf_end,cdf_side,cdf_stuck\n", o.f);
	double cdf[3] = {0, 0, 0};
	for (int b = 0; b < p->n_time_bins; b++) {
		const double *q = p->p_time + (size_t)b * 3;
		for (int k = 0; k < 3; k++)
			cdf[k] += q[k];
		fprintf(o.f, "%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", b * p->time_bin,
		        (b + 1) * p->time_bin, q[0], q[1], q[2], cdf[0], cdf[1], cdf[2]);
	}
	if (bsim_atomic_file_commit(&o, err) != BSIM_OK)
		return BSIM_EFAIL;
	char body[1600];
	snprintf(body, sizeof body,
	         "set datafile separator ','\n"
	         "set title \"%s: time to the outcome by %ld walks of the semi-Markov chain\\n"
	         "out by the duration %g s: end %.4f, side %.4f; stuck %.4f\" noenhanced\n"
	         "set xlabel 'time t (s)'\nset ylabel 'probability of the outcome by t'\n"
	         "set key left top\nset grid\n"
	         "plot 'time.csv' every ::1 using 2:6 with steps lw 2 lc rgb '#0072B2' "
	         "title 'end', \\\n"
	         "     '' every ::1 using 2:7 with steps lw 2 lc rgb '#D55E00' title 'side', "
	         "\\\n"
	         "     '' every ::1 using 2:8 with steps lw 2 lc rgb '#777777' title \"stuck "
	         "(a gate's limit or the duration)\"\n",
	         lattice->name, p->walks, p->duration, p->p_by[0], p->p_by[1], p->p_by[2]);
	bsim_figure_def fd = bsim_figure_def_default();
	fd.dir = stage;
	fd.name = "time";
	return bsim_figure_render(&fd, body, drawn, err);
}

int bsim_markov_prediction_store(const char *dir, int overwrite, const bsim_scene *lattice,
                                 const bsim_markov_set *set, const bsim_markov_prediction *p,
                                 bsim_error *err)
{
	bsim_session ss;
	int rc = bsim_session_open(&ss, dir, bsim_session_mode(0, overwrite), "markov predict",
	                           NULL, NULL, 0, err);
	if (rc != BSIM_OK)
		return rc;
	rc = write_tables(ss.stage, p, err);
	static const char *const names[] = {"prediction", "prediction_gates"};
	for (int i = 0; i < 2 && rc == BSIM_OK; i++) {
		char csv[BSIM_PATH_MAX], mat[BSIM_PATH_MAX];
		snprintf(csv, sizeof csv, "%s/%s.csv", ss.stage, names[i]);
		snprintf(mat, sizeof mat, "%s/%s.mat", ss.stage, names[i]);
		rc = bsim_matlab_from_csv(csv, mat, names[i], err);
	}
	/* A figure gnuplot fails on is reported at the end, the tables (those
	 * after it too) kept beside its script and data. */
	int drawn = BSIM_FIGURE_UNDRAWN;
	if (rc == BSIM_OK) {
		rc = write_figure(ss.stage, lattice, set, p, &drawn, err);
		rc = bsim_session_defer(&ss, rc, drawn == BSIM_FIGURE_FAILED, err);
	}
	if (rc == BSIM_OK && p->walks > 0) {
		drawn = BSIM_FIGURE_UNDRAWN;
		rc = write_time(ss.stage, lattice, p, &drawn, err);
		rc = bsim_session_defer(&ss, rc, drawn == BSIM_FIGURE_FAILED, err);
	}
	if (rc == BSIM_OK && p->walks > 0) {
		char csv[BSIM_PATH_MAX], mat[BSIM_PATH_MAX];
		snprintf(csv, sizeof csv, "%s/time.csv", ss.stage);
		snprintf(mat, sizeof mat, "%s/time.mat", ss.stage);
		rc = bsim_matlab_from_csv(csv, mat, "time", err);
	}
	return bsim_session_close(&ss, rc, "markov predict", NULL, err);
}
