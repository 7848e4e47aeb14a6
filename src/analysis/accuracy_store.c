/* The accuracy study stored in an output directory (beamsim accuracy --out
 * DIR); see beamsim/accuracy.h. */
#include "beamsim/accuracy.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "store/matlab.h"
#include "store/session.h"
#include "beamsim/limits.h"

bsim_accuracy_config bsim_accuracy_config_default(void)
{
	return (bsim_accuracy_config){
	        .h_ref = 0.000125,
	        .h_max = 0.016,
	        .piece = 0.064,
	        .n_pieces = 16,
	        .n_trials = 40,
	        .seed = 1,
	        /* Errors both backends' rows span (docs/accuracy.md "At equal
	         * error"), a 1-2-5 series from 2 cm to 1 mm. */
	        .n_targets = 5,
	        .targets = {0.02, 0.01, 0.005, 0.002, 0.001},
	};
}

bsim_accuracy_config bsim_accuracy_quick(void)
{
	bsim_accuracy_config c = bsim_accuracy_config_default();
	c.h_ref = 0.0005;
	c.n_pieces = 4;
	c.n_trials = 8;
	return c;
}

int bsim_accuracy_store(const char *out, int overwrite, const bsim_scene *scene,
                        const char *scene_label, const bsim_backend *const *backends,
                        int n_backends, const bsim_accuracy_config *cfg, bsim_accuracy_result *res,
                        bsim_figures_result *fig, bsim_error *err)
{
	memset(res, 0, sizeof *res);
	memset(fig, 0, sizeof *fig);
	bsim_session ss;
	int rc = bsim_session_open(&ss, out, bsim_session_mode(0, overwrite), "accuracy", NULL,
	                           NULL, 0, err);
	if (rc != BSIM_OK)
		return rc;
	char path[BSIM_PATH_MAX], mat[BSIM_PATH_MAX];
	rc = bsim_accuracy_run(scene, backends, n_backends, cfg, res, err);
	if (rc == BSIM_OK) {
		snprintf(path, sizeof path, "%s/accuracy.csv", ss.stage);
		snprintf(mat, sizeof mat, "%s/accuracy.mat", ss.stage);
		rc = bsim_accuracy_write_csv(path, res, err);
		if (rc == BSIM_OK)
			rc = bsim_matlab_from_csv(path, mat, "accuracy", err);
	}
	if (rc == BSIM_OK) {
		bsim_accuracy_equal *eq = NULL;
		int n_eq = 0;
		rc = bsim_accuracy_equal_error(res, cfg->targets, cfg->n_targets, &eq, &n_eq, err);
		snprintf(path, sizeof path, "%s/equal_error.csv", ss.stage);
		if (rc == BSIM_OK)
			rc = bsim_accuracy_write_equal_csv(path, res, eq, n_eq, err);
		free(eq);
	}
	if (rc == BSIM_OK) {
		snprintf(path, sizeof path, "%s/accuracy.md", ss.stage);
		rc = bsim_accuracy_write_md(path, res, cfg, scene_label, err);
	}
	if (rc == BSIM_OK) {
		bsim_figures_def def = bsim_figures_def_default();
		def.kind = BSIM_FIGURES_ACCURACY;
		rc = bsim_figures_draw(ss.stage, &def, fig, err);
		/* the tables are kept beside a figure gnuplot failed on */
		rc = bsim_session_defer(&ss, rc, fig->failed > 0, err);
	}
	rc = bsim_session_close(&ss, rc, "accuracy", NULL, err);
	if (rc != BSIM_OK) {
		bsim_figures_result_free(fig);
		bsim_accuracy_result_free(res);
	}
	return rc;
}
