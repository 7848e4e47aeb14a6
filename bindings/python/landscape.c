/* _beamsim.landscape: the potential energy landscape of a scene on a grid
 * and its passes (beamsim/landscape.h, landscape_barriers.h), in memory:
 * what `beamsim landscape SCENE --out DIR` writes to landscape.csv and
 * landscape.json. */
#define _POSIX_C_SOURCE 200809L

#include "pyb.h"

#include <string.h>

/* {"x", "y", "e_total"} as landscape.json writes a point. */
static PyObject *point(double x, double y, double e)
{
	return Py_BuildValue("{sdsdsd}", "x", x, "y", y, "e_total", e);
}

/* A pass as landscape.json writes it: crossed is the beam, from 1 as in
 * every output, or None; a pass of kind none has no more. */
static PyObject *pass_dict(const bsim_landscape_pass *p)
{
	PyObject *d = PyDict_New();
	long dims[2] = {p->n_path, 2};
	if (!d ||
	    pyb_set(d, "kind", PyUnicode_FromString(bsim_landscape_pass_kind_name(p->kind))) ||
	    pyb_set(d, "crossed", p->beam >= 0 ? PyLong_FromLong(p->beam + 1) : Py_NewRef(Py_None)))
		goto fail;
	if (p->kind == BSIM_PASS_NONE)
		return d;
	if (pyb_set(d, "x", PyFloat_FromDouble(p->x)) ||
	    pyb_set(d, "y", PyFloat_FromDouble(p->y)) ||
	    pyb_set(d, "e_total", PyFloat_FromDouble(p->e_total)) ||
	    pyb_set(d, "e_beam", PyFloat_FromDouble(p->e_beam)) ||
	    pyb_set(d, "e_prop", PyFloat_FromDouble(p->e_prop)) ||
	    pyb_set(d, "height", PyFloat_FromDouble(p->height)) ||
	    pyb_set(d, "above_start", PyFloat_FromDouble(p->above_start)) ||
	    pyb_set(d, "floor", point(p->floor[0], p->floor[1], p->floor_e)) ||
	    pyb_set(d, "grid", point(p->grid_x, p->grid_y, p->grid_e)) ||
	    pyb_set(d, "refine_spacing", PyFloat_FromDouble(p->refine_spacing)) ||
	    pyb_set(d, "refine_change", PyFloat_FromDouble(p->refine_change)) ||
	    pyb_set(d, "path", pyb_array(2, dims, p->path)))
		goto fail;
	return d;
fail:
	Py_XDECREF(d);
	return NULL;
}

/* start, far_y, lowest_pass and barriers ([{"beam": b, "pass": ...}], b
 * from 1) into d, as in landscape.json. */
static int barriers_set(PyObject *d, const bsim_landscape_barriers *b)
{
	PyObject *beams = PyList_New(b->n_beams);
	if (!beams)
		return -1;
	for (int i = 0; i < b->n_beams; i++) {
		PyObject *p = pass_dict(&b->beam[i]);
		PyObject *e = p ? Py_BuildValue("{sisN}", "beam", i + 1, "pass", p) : NULL;
		if (!e) {
			Py_DECREF(beams);
			return -1;
		}
		PyList_SET_ITEM(beams, i, e);
	}
	if (pyb_set(d, "start", point(b->start[0], b->start[1], b->start_e)) ||
	    pyb_set(d, "far_y", PyFloat_FromDouble(b->far_y)) ||
	    pyb_set(d, "lowest_pass", pass_dict(&b->lowest))) {
		Py_DECREF(beams);
		return -1;
	}
	return pyb_set(d, "barriers", beams);
}

/* The grid as landscape.json's "grid" and the sampled values as (ny, nx)
 * arrays, row j at y = y0 + j spacing (landscape.csv's rows, reshaped). */
static PyObject *grid_dict(const bsim_landscape_grid *g)
{
	PyObject *d = PyDict_New();
	long dims2[2] = {g->ny, g->nx}, dims3[3] = {g->n_beams, g->ny, g->nx};
	long nx = g->nx, ny = g->ny;
	double *xs = malloc((size_t)nx * sizeof *xs), *ys = malloc((size_t)ny * sizeof *ys);
	if (!d || !xs || !ys) {
		free(xs);
		free(ys);
		Py_XDECREF(d);
		return PyErr_NoMemory();
	}
	for (long i = 0; i < nx; i++)
		xs[i] = g->x0 + (double)i * g->spacing;
	for (long j = 0; j < ny; j++)
		ys[j] = g->y0 + (double)j * g->spacing;
	PyObject *grid =
	        Py_BuildValue("{sdsdsdsdsdsisi}", "x0", g->x0, "x1", xs[nx - 1], "y0", g->y0, "y1",
	                      ys[ny - 1], "spacing", g->spacing, "nx", g->nx, "ny", g->ny);
	if (pyb_set(d, "grid", grid) || pyb_set(d, "x", pyb_array(1, &nx, xs)) ||
	    pyb_set(d, "y", pyb_array(1, &ny, ys)) ||
	    pyb_set(d, "e_total", pyb_array(2, dims2, g->e_total)) ||
	    pyb_set(d, "e_beam", pyb_array(2, dims2, g->e_beam)) ||
	    pyb_set(d, "e_prop", pyb_array(2, dims2, g->e_prop)) ||
	    pyb_set(d, "theta", pyb_array(3, dims3, g->theta)))
		Py_CLEAR(d);
	free(xs);
	free(ys);
	return d;
}

PyObject *pyb_landscape(PyObject *self, PyObject *args, PyObject *kw)
{
	(void)self;
	static char *kwlist[] = {"scene", "sets", "spacing", "region", NULL};
	const char *path;
	PyObject *sets_o = Py_None, *region_o = Py_None;
	double spacing = 0.0;
	if (!PyArg_ParseTupleAndKeywords(args, kw, "s|OdO", kwlist, &path, &sets_o, &spacing,
	                                 &region_o))
		return NULL;
	bsim_landscape_grid_def def = bsim_landscape_grid_def_default();
	def.spacing = spacing;
	if (region_o != Py_None) {
		def.has_region = 1;
		if (!PyArg_ParseTuple(region_o, "dddd", &def.region[0], &def.region[1],
		                      &def.region[2], &def.region[3]))
			return NULL;
	}
	pyb_sets sets;
	if (pyb_sets_from(sets_o, &sets))
		return NULL;
	bsim_scene scene;
	bsim_landscape_grid *g = NULL;
	bsim_landscape_barriers *b = NULL;
	bsim_error err;
	int rc, loaded;
	Py_BEGIN_ALLOW_THREADS;
	rc = bsim_scene_load(path, sets.ov, sets.n, &scene, &err);
	loaded = rc == BSIM_OK;
	if (rc == BSIM_OK)
		rc = bsim_landscape_grid_alloc(&scene, &def, &g, &err);
	if (rc == BSIM_OK)
		rc = bsim_landscape_barriers_alloc(&scene, g, &b, &err);
	Py_END_ALLOW_THREADS;
	pyb_sets_free(&sets);
	PyObject *d = NULL;
	if (rc != BSIM_OK)
		pyb_raise(rc, &err);
	else if ((d = grid_dict(g)) && barriers_set(d, b))
		Py_CLEAR(d);
	bsim_landscape_barriers_free(b);
	bsim_landscape_grid_free(g);
	if (loaded)
		bsim_scene_free(&scene);
	return d;
}
