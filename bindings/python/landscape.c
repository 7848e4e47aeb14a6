/* _beamsim.landscape: the potential energy landscape of a scene on a grid
 * and its passes (beamsim/landscape.h, landscape_barriers.h), in memory:
 * what `beamsim landscape SCENE --out DIR` writes to landscape.csv and
 * landscape.json. */
#define _POSIX_C_SOURCE 200809L

#include "pyb.h"

#include <string.h>

static PyObject *pair(const double v[2])
{
	return Py_BuildValue("(dd)", v[0], v[1]);
}

/* A pass as landscape.json names its fields; beam 0-based, None for -1. */
static PyObject *pass_dict(const bsim_landscape_pass *p)
{
	PyObject *d = PyDict_New();
	long dims[2] = {p->n_path, 2};
	if (!d ||
	    pyb_set(d, "kind", PyUnicode_FromString(bsim_landscape_pass_kind_name(p->kind))) ||
	    pyb_set(d, "beam", p->beam >= 0 ? PyLong_FromLong(p->beam) : Py_NewRef(Py_None)) ||
	    pyb_set(d, "x", PyFloat_FromDouble(p->x)) ||
	    pyb_set(d, "y", PyFloat_FromDouble(p->y)) ||
	    pyb_set(d, "e_total", PyFloat_FromDouble(p->e_total)) ||
	    pyb_set(d, "e_beam", PyFloat_FromDouble(p->e_beam)) ||
	    pyb_set(d, "e_prop", PyFloat_FromDouble(p->e_prop)) ||
	    pyb_set(d, "floor", pair(p->floor)) ||
	    pyb_set(d, "floor_e", PyFloat_FromDouble(p->floor_e)) ||
	    pyb_set(d, "height", PyFloat_FromDouble(p->height)) ||
	    pyb_set(d, "above_start", PyFloat_FromDouble(p->above_start)) ||
	    pyb_set(d, "grid", Py_BuildValue("(ddd)", p->grid_x, p->grid_y, p->grid_e)) ||
	    pyb_set(d, "refine_spacing", PyFloat_FromDouble(p->refine_spacing)) ||
	    pyb_set(d, "refine_change", PyFloat_FromDouble(p->refine_change)) ||
	    pyb_set(d, "path", pyb_array(2, dims, p->path)))
		Py_CLEAR(d);
	return d;
}

static PyObject *barriers_dict(const bsim_landscape_barriers *b)
{
	PyObject *d = PyDict_New();
	PyObject *beams = PyList_New(b->n_beams);
	if (!d || !beams)
		goto fail;
	for (int i = 0; i < b->n_beams; i++) {
		PyObject *p = pass_dict(&b->beam[i]);
		if (!p)
			goto fail;
		PyList_SET_ITEM(beams, i, p);
	}
	if (pyb_set(d, "start", pair(b->start)) ||
	    pyb_set(d, "start_e", PyFloat_FromDouble(b->start_e)) ||
	    pyb_set(d, "far_y", PyFloat_FromDouble(b->far_y)) ||
	    pyb_set(d, "lowest", pass_dict(&b->lowest)))
		goto fail;
	int rc = pyb_set(d, "beams", beams);
	beams = NULL;
	if (rc)
		goto fail;
	return d;
fail:
	Py_XDECREF(beams);
	Py_XDECREF(d);
	return NULL;
}

/* Grids as (ny, nx) arrays, row j at y = y0 + j spacing. */
static PyObject *grid_dict(const bsim_landscape_grid *g)
{
	PyObject *d = PyDict_New();
	long n = (long)g->nx * g->ny;
	long dims2[2] = {g->ny, g->nx}, dims3[3] = {g->n_beams, g->ny, g->nx};
	double *xs = malloc((size_t)g->nx * sizeof *xs), *ys = malloc((size_t)g->ny * sizeof *ys);
	if (!d || !xs || !ys) {
		free(xs);
		free(ys);
		Py_XDECREF(d);
		return PyErr_NoMemory();
	}
	for (int i = 0; i < g->nx; i++)
		xs[i] = g->x0 + i * g->spacing;
	for (int j = 0; j < g->ny; j++)
		ys[j] = g->y0 + j * g->spacing;
	long nx = g->nx, ny = g->ny;
	if (pyb_set(d, "x", pyb_array(1, &nx, xs)) || pyb_set(d, "y", pyb_array(1, &ny, ys)) ||
	    pyb_set(d, "spacing", PyFloat_FromDouble(g->spacing)) ||
	    pyb_set(d, "region",
	            Py_BuildValue("(dddd)", g->region[0], g->region[1], g->region[2],
	                          g->region[3])) ||
	    pyb_set(d, "e_total", pyb_array(2, dims2, g->e_total)) ||
	    pyb_set(d, "e_beam", pyb_array(2, dims2, g->e_beam)) ||
	    pyb_set(d, "e_prop", pyb_array(2, dims2, g->e_prop)) ||
	    pyb_set(d, "theta", pyb_array(3, dims3, g->theta)))
		Py_CLEAR(d);
	(void)n;
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
	else if ((d = grid_dict(g)) && pyb_set(d, "barriers", barriers_dict(b)))
		Py_CLEAR(d);
	bsim_landscape_barriers_free(b);
	bsim_landscape_grid_free(g);
	if (loaded)
		bsim_scene_free(&scene);
	return d;
}
