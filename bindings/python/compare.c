/* _beamsim.compare: two or more sides of an experiment with the same
 * schedules as `beamsim compare EXPERIMENT --backends A,B,... --out DIR` runs them
 * (bsim_compare_dir_run), with the GIL released, a progress callable and
 * Ctrl-C; the package reads DIR's files back. */
#define _POSIX_C_SOURCE 200809L

#include "pyb.h"

#include <string.h>

/* A tuple of each side's directory (what 0) or unstable trials (1); NULL
 * with an exception on failure. */
static PyObject *per_side(const bsim_compare_dir_result *res, int what)
{
	PyObject *t = PyTuple_New(res->n_sides);
	for (int i = 0; t && i < res->n_sides; i++) {
		PyObject *v = what ? PyLong_FromLong(res->unstable[i])
		                   : PyUnicode_FromString(res->dir[i]);
		if (!v)
			Py_CLEAR(t);
		else
			PyTuple_SET_ITEM(t, i, v);
	}
	return t;
}

PyObject *pyb_compare(PyObject *self, PyObject *args, PyObject *kw)
{
	(void)self;
	static char *kwlist[] = {"experiment", "out",  "sides",    "trials", "threads",   "seed",
	                         "sets",       "grid", "progress", "resume", "overwrite", NULL};
	const char *experiment, *out;
	long trials = 0;
	int threads = 0, resume = 0, overwrite = 0;
	PyObject *sides_o = Py_None, *seed_o = Py_None, *sets_o = Py_None, *grid_o = Py_None,
	         *progress_o = Py_None;
	if (!PyArg_ParseTupleAndKeywords(args, kw, "ss|OliOOOOpp", kwlist, &experiment, &out,
	                                 &sides_o, &trials, &threads, &seed_o, &sets_o, &grid_o,
	                                 &progress_o, &resume, &overwrite))
		return NULL;
	bsim_compare_dir_def def = bsim_compare_dir_def_default();
	bsim_error err;
	/* sides None: the registry's default ones (bsim_compare_dir_def_default) */
	PyObject *sides =
	        sides_o == Py_None
	                ? NULL
	                : PySequence_Fast(sides_o, "backends: expected a sequence of sides");
	if (!sides && sides_o != Py_None)
		return NULL;
	Py_ssize_t n = sides ? PySequence_Fast_GET_SIZE(sides) : def.n_sides;
	if (n < 2 || n > BSIM_COMPARE_SIDES_MAX) {
		Py_XDECREF(sides);
		PyErr_Format(PyExc_ValueError, "backends: %zd sides; expected 2 to %d", n,
		             BSIM_COMPARE_SIDES_MAX);
		return NULL;
	}
	def.n_sides = (int)n;
	for (Py_ssize_t i = 0; sides && i < n; i++) {
		const char *spec = PyUnicode_Check(PySequence_Fast_GET_ITEM(sides, i))
		                           ? PyUnicode_AsUTF8(PySequence_Fast_GET_ITEM(sides, i))
		                           : NULL;
		if (!spec) {
			Py_DECREF(sides);
			if (!PyErr_Occurred())
				PyErr_SetString(PyExc_TypeError,
				                "backends: expected strings NAME[:KEY=VALUE]...");
			return NULL;
		}
		memset(&def.side[i], 0, sizeof def.side[i]);
		if (bsim_compare_side_parse(spec, &def.side[i], &err) != BSIM_OK) {
			Py_DECREF(sides);
			return pyb_raise(err.code, &err);
		}
	}
	Py_XDECREF(sides);
	pyb_run_inputs in;
	if (pyb_run_inputs_from(seed_o, sets_o, grid_o, progress_o, &in))
		return NULL;
	PYB_RUN_INPUTS_SET(def, in);
	def.experiment = experiment;
	def.out = out;
	def.trials = trials;
	def.threads = threads;
	def.resume = resume;
	def.overwrite = overwrite;
	bsim_compare_dir_result res;
	int rc;
	Py_BEGIN_ALLOW_THREADS;
	rc = bsim_compare_dir_run(&def, &res, &err);
	Py_END_ALLOW_THREADS;
	pyb_run_inputs_free(&in);
	if (!pyb_progress_end(&in.progress, rc, &err)) {
		if (rc == BSIM_OK)
			bsim_compare_dir_result_free(&res);
		return NULL;
	}
	PyObject *d = PyDict_New();
	if (!d || pyb_set(d, "threads", PyLong_FromLong(res.threads)) ||
	    pyb_set(d, "n_disagree", PyLong_FromLong(res.cmp.n_disagree)) ||
	    pyb_set(d, "dirs", per_side(&res, 0)) || pyb_set(d, "unstable", per_side(&res, 1)))
		Py_CLEAR(d);
	bsim_compare_dir_result_free(&res);
	return d;
}
