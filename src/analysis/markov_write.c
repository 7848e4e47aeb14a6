/* A prediction's files (beamsim markov predict --out DIR; beamsim/markov.h). */
#define _POSIX_C_SOURCE 200809L

#include <stdio.h>
#include <string.h>

#include "util/atomic_file.h"
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

int bsim_markov_prediction_store(const char *dir, const bsim_markov_prediction *p, bsim_error *err)
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
	return bsim_session_close(&ss, rc, "markov predict", NULL, err);
}
