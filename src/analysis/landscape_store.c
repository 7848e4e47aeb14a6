/* The landscape of a scene computed and stored in an output directory
 * (beamsim landscape SCENE --out DIR); see beamsim/landscape.h. */
#include "beamsim/landscape.h"
#include "beamsim/landscape_barriers.h"

#include "store/session.h"
#include "util/figure.h"

int bsim_landscape_store(const char *out, int overwrite, const bsim_scene *s,
                         const bsim_landscape_grid_def *def, bsim_landscape_grid **g,
                         bsim_landscape_barriers **b, int *drawn, bsim_error *err)
{
	*g = NULL;
	*b = NULL;
	if (drawn)
		*drawn = 0;
	/* DIR is checked before the grid is computed, and its files appear
	 * together. */
	bsim_session ss;
	int rc = bsim_session_open(&ss, out, bsim_session_mode(0, overwrite), "landscape", NULL,
	                           NULL, 0, err);
	if (rc != BSIM_OK)
		return rc;
	rc = bsim_landscape_grid_alloc(s, def, g, err);
	if (rc == BSIM_OK)
		rc = bsim_landscape_barriers_alloc(s, *g, b, err);
	int shown = BSIM_FIGURE_UNDRAWN;
	if (rc == BSIM_OK)
		rc = bsim_landscape_write(ss.stage, s, *g, *b, &shown, err);
	/* A figure gnuplot failed on is written last: the tables are kept
	 * with its script and data, and the run fails. */
	rc = bsim_session_defer(&ss, rc, shown == BSIM_FIGURE_FAILED, err);
	if (drawn)
		*drawn = shown;
	rc = bsim_session_close(&ss, rc, "landscape", NULL, err);
	if (rc != BSIM_OK) {
		bsim_landscape_barriers_free(*b);
		bsim_landscape_grid_free(*g);
		*g = NULL;
		*b = NULL;
	}
	return rc;
}
