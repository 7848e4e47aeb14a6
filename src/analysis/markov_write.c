/* A prediction's files (beamsim markov predict --out DIR; beamsim/markov.h). */
#define _POSIX_C_SOURCE 200809L

#include <stdio.h>
#include <string.h>

#include "analysis/markov_internal.h"
#include "util/atomic_file.h"
#include "beamsim/backend.h"
#include "beamsim/markov.h"
#include "beamsim/lattice_outcome.h"
#include "store/matlab.h"
#include "store/session.h"
#include "beamsim/limits.h"

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
                        const bsim_markov_prediction *p, bsim_error *err)
{
	char fp[32], rm[32], params[300], title[600];
	snprintf(fp, sizeof fp, "%g",
	         lattice->effects.has_propulsion ? lattice->effects.propulsion_force : 0.0);
	snprintf(rm, sizeof rm, "%g",
	         lattice->effects.has_random_force ? lattice->effects.random_magnitude : 0.0);
	const bsim_override ov[2] = {{"effects.propulsion.force", fp, NULL},
	                             {"effects.random_force.magnitude", rm, NULL}};
	const bsim_backend *b = set && set->def.backend ? set->def.backend : bsim_backend_default();
	markov_title_params(params, sizeof params, b ? b->name : NULL, ov, 2);
	snprintf(title, sizeof title,
	         "%s: final locations predicted by the Markov chain (%d states, %s)\n%s, "
	         "%d trials per entry bin",
	         lattice->name, p->n_states, p->exact ? "LU" : "series", params,
	         set ? set->def.trials : 0);
	const markov_field_panel panel = {"probability of each final location", p->p, NULL};
	return markov_field_figure(stage, "prediction", title, p->loc, p->n_locations, &panel, 1, 1,
	                           NULL, err);
}

int bsim_markov_prediction_store(const char *dir, const bsim_scene *lattice,
                                 const bsim_markov_set *set, const bsim_markov_prediction *p,
                                 bsim_error *err)
{
	bsim_session ss;
	int rc = bsim_session_open(&ss, dir, 0, NULL, 0, err);
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
	if (rc == BSIM_OK)
		rc = write_figure(ss.stage, lattice, set, p, err);
	return bsim_session_close(&ss, rc, "markov predict", NULL, err);
}
