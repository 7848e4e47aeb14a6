/* beamsim_landscape: the potential energy landscape of a scene on a grid
 * and its barriers, as `beamsim landscape` computes them.
 *
 *   l = beamsim_landscape(SCENE, NAME, VALUE, ...)
 *
 * Names: 'set' {KEY, VALUE, ...}, 'region' [X0 X1 Y0 Y1] (m), 'resolution'
 * (the grid spacing, m), 'out' (a directory: also write the program's files
 * and figures there), 'overwrite' (true: replace the result 'out' holds;
 * without it such a directory is refused, as by `beamsim landscape`).
 * l.x (1 x nx) and l.y (ny x 1) are the grid's coordinates, l.e_total,
 * l.e_beam and l.e_prop ny x nx matrices (rows y, columns x, as meshgrid
 * and surf take them), l.theta ny x nx x n_beams; l.barriers the start,
 * the far side and the passes (landscape.json's). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bsim_mex.h"

enum { A_SET, A_REGION, A_RESOLUTION, A_OUT, A_OVERWRITE, N_ARGS };
static const char *const arg_names[N_ARGS] = {"set", "region", "resolution", "out", "overwrite"};

/* Grid values v (entry j nx + i at x_i, y_j) as an ny x nx matrix. */
static mxArray *grid_matrix(const bsim_landscape_grid *g, const double *v)
{
	mxArray *m = mxCreateDoubleMatrix((mwSize)g->ny, (mwSize)g->nx, mxREAL);
	double *d = mxGetPr(m);
	size_t nx = (size_t)g->nx, ny = (size_t)g->ny;
	for (size_t j = 0; j < ny; j++)
		for (size_t i = 0; i < nx; i++)
			d[i * ny + j] = v[j * nx + i];
	return m;
}

static mxArray *pass_struct(const bsim_landscape_pass *p)
{
	mxArray *s = mxCreateStructMatrix(1, 1, 0, NULL);
	bmx_set(s, 0, "kind", bmx_string(bsim_landscape_pass_kind_name(p->kind)));
	bmx_set(s, 0, "beam", bmx_scalar(p->beam + 1));
	const char *names[] = {"x",
	                       "y",
	                       "e_total",
	                       "e_beam",
	                       "e_prop",
	                       "floor_e",
	                       "height",
	                       "above_start",
	                       "grid_x",
	                       "grid_y",
	                       "grid_e",
	                       "refine_spacing",
	                       "refine_change"};
	const double values[] = {p->x,
	                         p->y,
	                         p->e_total,
	                         p->e_beam,
	                         p->e_prop,
	                         p->floor_e,
	                         p->height,
	                         p->above_start,
	                         p->grid_x,
	                         p->grid_y,
	                         p->grid_e,
	                         p->refine_spacing,
	                         p->refine_change};
	for (size_t i = 0; i < sizeof values / sizeof values[0]; i++)
		bmx_set(s, 0, names[i], bmx_scalar(values[i]));
	bmx_set(s, 0, "floor", bmx_row(p->floor, 2));
	/* The path of least resistance, one (x, y) row a point. */
	size_t n = p->n_path > 0 ? (size_t)p->n_path : 0;
	mxArray *path = mxCreateDoubleMatrix((mwSize)n, 2, mxREAL);
	double *d = mxGetPr(path);
	for (size_t k = 0; k < n; k++) {
		d[k] = p->path[2 * k];
		d[n + k] = p->path[2 * k + 1];
	}
	bmx_set(s, 0, "path", path);
	return s;
}

static mxArray *barriers_struct(const bsim_landscape_barriers *b)
{
	mxArray *s = mxCreateStructMatrix(1, 1, 0, NULL);
	bmx_set(s, 0, "start", bmx_row(b->start, 2));
	bmx_set(s, 0, "start_e", bmx_scalar(b->start_e));
	bmx_set(s, 0, "far_y", bmx_scalar(b->far_y));
	bmx_set(s, 0, "lowest", pass_struct(&b->lowest));
	/* One pass per beam: a struct array of the same fields. */
	mxArray *beams = NULL;
	for (int i = 0; i < b->n_beams; i++) {
		mxArray *one = pass_struct(&b->beam[i]);
		if (!beams) {
			int nf = mxGetNumberOfFields(one);
			const char **names = mxMalloc((size_t)nf * sizeof *names);
			for (int f = 0; f < nf; f++)
				names[f] = mxGetFieldNameByNumber(one, f);
			beams = mxCreateStructMatrix((mwSize)b->n_beams, 1, nf, names);
			mxFree(names);
		}
		int nf = mxGetNumberOfFields(one);
		for (int f = 0; f < nf; f++) {
			mxSetFieldByNumber(beams, (mwIndex)i, f,
			                   mxDuplicateArray(mxGetFieldByNumber(one, 0, f)));
		}
		mxDestroyArray(one);
	}
	bmx_set(s, 0, "beams", beams ? beams : mxCreateStructMatrix(0, 1, 0, NULL));
	return s;
}

static mxArray *landscape_struct(const bsim_scene *sc, const bsim_landscape_grid *g,
                                 const bsim_landscape_barriers *b)
{
	mxArray *s = mxCreateStructMatrix(1, 1, 0, NULL);
	bmx_set(s, 0, "scene", bmx_string(sc->path));
	bmx_set(s, 0, "name", bmx_string(sc->name));
	mxArray *x = mxCreateDoubleMatrix(1, (mwSize)g->nx, mxREAL);
	mxArray *y = mxCreateDoubleMatrix((mwSize)g->ny, 1, mxREAL);
	for (int i = 0; i < g->nx; i++)
		mxGetPr(x)[i] = g->x0 + i * g->spacing;
	for (int j = 0; j < g->ny; j++)
		mxGetPr(y)[j] = g->y0 + j * g->spacing;
	bmx_set(s, 0, "x", x);
	bmx_set(s, 0, "y", y);
	bmx_set(s, 0, "spacing", bmx_scalar(g->spacing));
	bmx_set(s, 0, "region", bmx_row(g->region, 4));
	bmx_set(s, 0, "e_total", grid_matrix(g, g->e_total));
	bmx_set(s, 0, "e_beam", grid_matrix(g, g->e_beam));
	bmx_set(s, 0, "e_prop", grid_matrix(g, g->e_prop));
	const mwSize dims[3] = {(mwSize)g->ny, (mwSize)g->nx, (mwSize)g->n_beams};
	mxArray *theta = mxCreateNumericArray(3, dims, mxDOUBLE_CLASS, mxREAL);
	double *d = mxGetPr(theta);
	size_t nx = (size_t)g->nx, ny = (size_t)g->ny;
	for (size_t k = 0; k < (size_t)g->n_beams; k++)
		for (size_t j = 0; j < ny; j++)
			for (size_t i = 0; i < nx; i++)
				d[k * nx * ny + i * ny + j] = g->theta[k * nx * ny + j * nx + i];
	bmx_set(s, 0, "theta", theta);
	bmx_set(s, 0, "barriers", barriers_struct(b));
	return s;
}

typedef struct landscape_call {
	bmx_pool pool;
	bsim_scene scene;
	bsim_landscape_grid *g;
	bsim_landscape_barriers *b;
} landscape_call;

static int landscape(landscape_call *c, int nrhs, const mxArray *prhs[], mxArray **out,
                     bsim_error *err)
{
	const mxArray *v[N_ARGS];
	if (nrhs < 1)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "expected a scene file, then name-value pairs");
	if (bmx_pairs(nrhs, prhs, 1, arg_names, N_ARGS, v, err) != BSIM_OK)
		return BSIM_EINPUT;
	const char *path = NULL, *dir = NULL;
	int overwrite = 0;
	bsim_override *sets = NULL;
	int n_sets = 0;
	bsim_landscape_grid_def def = bsim_landscape_grid_def_default();
	if (bmx_text("scene", prhs[0], &c->pool, &path, err) ||
	    bmx_overrides("set", v[A_SET], &c->pool, &sets, &n_sets, err) ||
	    (v[A_RESOLUTION] && bmx_double("resolution", v[A_RESOLUTION], &def.spacing, err)) ||
	    (v[A_OUT] && bmx_text("out", v[A_OUT], &c->pool, &dir, err)) ||
	    (v[A_OVERWRITE] && bmx_flag("overwrite", v[A_OVERWRITE], &overwrite, err)))
		return err->code;
	if (v[A_RESOLUTION] && !(def.spacing > 0))
		return bsim_error_set(err, BSIM_EINPUT,
		                      "'resolution': expected a grid spacing > 0 in m");
	if (v[A_REGION]) {
		const mxArray *r = v[A_REGION];
		if (!mxIsDouble(r) || mxIsComplex(r) || mxGetNumberOfElements(r) != 4)
			return bsim_error_set(err, BSIM_EINPUT,
			                      "'region': expected [X0 X1 Y0 Y1] in m");
		for (int i = 0; i < 4; i++)
			def.region[i] = mxGetPr(r)[i];
		if (!(def.region[0] < def.region[1]) || !(def.region[2] < def.region[3]) ||
		    !isfinite(def.region[1] - def.region[0]) ||
		    !isfinite(def.region[3] - def.region[2]))
			return bsim_error_set(err, BSIM_EINPUT,
			                      "'region': expected [X0 X1 Y0 Y1] in m with X0 < X1 "
			                      "and Y0 < Y1, e.g. [-25 25 0 65]");
		def.has_region = 1;
	}
	if (bsim_scene_load(path, sets, n_sets, &c->scene, err) != BSIM_OK)
		return err->code ? err->code : BSIM_EINPUT;
	int rc;
	/* 'out' refused in the function's own words ('overwrite'), before the
	 * grid is computed */
	if (dir && bsim_output_dir_check(dir, overwrite, "'overwrite', true", err) != BSIM_OK)
		return err->code;
	if (dir) {
		int drawn = 0;
		rc = bsim_landscape_store(dir, overwrite, &c->scene, &def, &c->g, &c->b, &drawn,
		                          err);
	} else {
		rc = bsim_landscape_grid_alloc(&c->scene, &def, &c->g, err);
		if (rc == BSIM_OK)
			rc = bsim_landscape_barriers_alloc(&c->scene, c->g, &c->b, err);
	}
	if (rc != BSIM_OK)
		return rc;
	*out = landscape_struct(&c->scene, c->g, c->b);
	return BSIM_OK;
}

void mexFunction(int nlhs, mxArray *plhs[], int nrhs, const mxArray *prhs[])
{
	(void)nlhs;
	landscape_call c;
	memset(&c, 0, sizeof c);
	bsim_error err;
	bsim_error_clear(&err);
	mxArray *out = NULL;
	int rc = landscape(&c, nrhs, prhs, &out, &err);
	bsim_landscape_barriers_free(c.b);
	bsim_landscape_grid_free(c.g);
	bsim_scene_free(&c.scene);
	bmx_pool_free(&c.pool);
	if (rc != BSIM_OK)
		bmx_fail(&err);
	plhs[0] = out;
}
