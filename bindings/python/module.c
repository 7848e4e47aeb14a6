/* The module beamsim._beamsim: its table of functions, errors, argument
 * conversion and NumPy arrays (the only file that uses NumPy's C API). */
#define _POSIX_C_SOURCE 200809L

#include "pyb.h"

#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>

#include <stdio.h>
#include <string.h>
#include <time.h>

PyObject *pyb_raise(int rc, const bsim_error *err)
{
	PyErr_SetString(rc == BSIM_EINPUT ? PyExc_ValueError : PyExc_RuntimeError, err->msg);
	return NULL;
}

const char *pyb_text(PyObject *o, const char *what)
{
	if (!o || !PyUnicode_Check(o)) {
		PyErr_Format(PyExc_TypeError, "%s: expected a str", what);
		return NULL;
	}
	Py_ssize_t len;
	const char *text = PyUnicode_AsUTF8AndSize(o, &len);
	bsim_error err;
	if (text && bsim_error_nul_check(what, text, (size_t)len, &err) != BSIM_OK)
		return pyb_raise(err.code, &err), NULL;
	return text;
}

/* The text of item i of a tuple (pyb_text). */
static const char *tuple_text(PyObject *t, Py_ssize_t i, const char *what)
{
	return pyb_text(PyTuple_GetItem(t, i), what);
}

int pyb_sets_from(PyObject *seq, pyb_sets *s)
{
	memset(s, 0, sizeof *s);
	if (!seq || seq == Py_None)
		return 0;
	if (!PyList_Check(seq)) {
		PyErr_SetString(PyExc_TypeError, "set: expected a list of (key, value, origin)");
		return -1;
	}
	Py_ssize_t n = PyList_Size(seq);
	s->ov = calloc((size_t)(n ? n : 1), sizeof *s->ov);
	if (!s->ov) {
		PyErr_NoMemory();
		return -1;
	}
	for (Py_ssize_t i = 0; i < n; i++) {
		PyObject *t = PyList_GetItem(seq, i);
		if (!PyTuple_Check(t) || PyTuple_Size(t) != 3) {
			PyErr_SetString(PyExc_TypeError,
			                "set: expected (key, value, origin) tuples");
			pyb_sets_free(s);
			return -1;
		}
		bsim_override *o = &s->ov[s->n];
		char what[160];
		if ((o->key = tuple_text(t, 0, "set: the key")))
			snprintf(what, sizeof what, "set %s: the value", o->key);
		if (!o->key || !(o->value = tuple_text(t, 1, what)) ||
		    !(o->origin = tuple_text(t, 2, "set: the origin"))) {
			pyb_sets_free(s);
			return -1;
		}
		s->n++;
	}
	return 0;
}

void pyb_sets_free(pyb_sets *s)
{
	free(s->ov);
	memset(s, 0, sizeof *s);
}

int pyb_grid_from(PyObject *seq, pyb_grid *g)
{
	memset(g, 0, sizeof *g);
	if (!seq || seq == Py_None)
		return 0;
	if (!PyList_Check(seq)) {
		PyErr_SetString(PyExc_TypeError, "grid: expected a list of (key, values, origin)");
		return -1;
	}
	Py_ssize_t n = PyList_Size(seq);
	g->axes = calloc((size_t)(n ? n : 1), sizeof *g->axes);
	if (!g->axes) {
		PyErr_NoMemory();
		return -1;
	}
	for (Py_ssize_t i = 0; i < n; i++) {
		PyObject *t = PyList_GetItem(seq, i);
		PyObject *values =
		        PyTuple_Check(t) && PyTuple_Size(t) == 3 ? PyTuple_GetItem(t, 1) : NULL;
		if (!values || !PyList_Check(values)) {
			PyErr_SetString(PyExc_TypeError,
			                "grid: expected (key, [values], origin) tuples");
			pyb_grid_free(g);
			return -1;
		}
		bsim_grid_axis *ax = &g->axes[g->n++];
		Py_ssize_t m = PyList_Size(values);
		ax->n_values = (int)m;
		ax->values = calloc((size_t)(m ? m : 1), sizeof *ax->values);
		const char *key = tuple_text(t, 0, "grid: the key");
		const char *origin = key ? tuple_text(t, 2, "grid: the origin") : NULL;
		if (!ax->values || !origin) {
			if (!PyErr_Occurred())
				PyErr_NoMemory();
			pyb_grid_free(g);
			return -1;
		}
		/* The library only reads an axis given to it (const); the
		 * origin ("--grid KEY") is the axis's, one for all its values. */
		ax->key = (char *)key;
		ax->origin = (char *)origin;
		char what[160];
		snprintf(what, sizeof what, "grid %s: the value", key);
		for (Py_ssize_t k = 0; k < m; k++) {
			const char *text = pyb_text(PyList_GetItem(values, k), what);
			if (!text) {
				pyb_grid_free(g);
				return -1;
			}
			ax->values[k] = (char *)text;
		}
	}
	return 0;
}

void pyb_grid_free(pyb_grid *g)
{
	for (int i = 0; i < g->n; i++)
		free(g->axes[i].values);
	free(g->axes);
	memset(g, 0, sizeof *g);
}

int pyb_sets_grid_from(PyObject *sets, PyObject *grid, pyb_sets *s, pyb_grid *g)
{
	if (pyb_sets_from(sets, s))
		return -1;
	if (pyb_grid_from(grid, g)) {
		pyb_sets_free(s);
		return -1;
	}
	return 0;
}

int pyb_seed_from(PyObject *o, int *has_seed, uint64_t *seed)
{
	if (o == Py_None)
		return 0;
	*has_seed = 1;
	*seed = PyLong_AsUnsignedLongLong(o);
	return PyErr_Occurred() ? -1 : 0;
}

const bsim_backend *pyb_backend(const char *spec, PyObject *seq, bsim_options *opts)
{
	bsim_error err;
	memset(opts, 0, sizeof *opts);
	if (seq && seq != Py_None) {
		if (!PyList_Check(seq)) {
			PyErr_SetString(PyExc_TypeError,
			                "backend_opt: expected a list of KEY=VALUE");
			return NULL;
		}
		for (Py_ssize_t i = 0; i < PyList_Size(seq); i++) {
			const char *kv =
			        pyb_text(PyList_GetItem(seq, i), "backend_opt: the option");
			if (!kv)
				return NULL;
			if (bsim_options_add(opts, kv, &err) != BSIM_OK)
				return pyb_raise(err.code, &err), NULL;
		}
	}
	/* As beamsim run reads --backend: the name, the --backend-opt
	 * options, then the spec's own (they win). */
	if (!spec)
		spec = bsim_backend_default()->name;
	size_t n = bsim_backend_spec_name(spec);
	char name[1024];
	snprintf(name, sizeof name, "%.*s", (int)(n < sizeof name ? n : sizeof name - 1), spec);
	const bsim_backend *b = bsim_backend_find(name, &err);
	if (!b)
		return pyb_raise(err.code ? err.code : BSIM_EINPUT, &err), NULL;
	if (bsim_backend_spec_options(spec, opts, &err) != BSIM_OK)
		return pyb_raise(err.code, &err), NULL;
	if (bsim_options_check(opts, b->knobs, b->n_knobs, b->name, &err) != BSIM_OK) {
		if (spec[n]) {
			bsim_error e2;
			bsim_error_set(&e2, BSIM_EINPUT, "--backend %s: %s", spec, err.msg);
			return pyb_raise(BSIM_EINPUT, &e2), NULL;
		}
		return pyb_raise(BSIM_EINPUT, &err), NULL;
	}
	return b;
}

PyObject *pyb_column(const double *data, long n, long stride, int ints)
{
	npy_intp dims[1] = {n};
	PyObject *a = PyArray_SimpleNew(1, dims, ints ? NPY_INT32 : NPY_DOUBLE);
	if (!a)
		return NULL;
	if (ints) {
		int32_t *p = PyArray_DATA((PyArrayObject *)a);
		for (long i = 0; i < n; i++)
			p[i] = (int32_t)data[i * stride];
	} else {
		double *p = PyArray_DATA((PyArrayObject *)a);
		for (long i = 0; i < n; i++)
			p[i] = data[i * stride];
	}
	return a;
}

PyObject *pyb_array(int nd, const long *dims, const double *data)
{
	npy_intp d[3];
	size_t n = 1;
	for (int i = 0; i < nd; i++) {
		d[i] = dims[i];
		n *= (size_t)dims[i];
	}
	PyObject *a = PyArray_SimpleNew(nd, d, NPY_DOUBLE);
	if (a && n)
		memcpy(PyArray_DATA((PyArrayObject *)a), data, n * sizeof *data);
	return a;
}

PyObject *pyb_int_array(const int *v, long n)
{
	npy_intp d[1] = {n};
	PyObject *a = PyArray_SimpleNew(1, d, NPY_INT32);
	if (a && n)
		memcpy(PyArray_DATA((PyArrayObject *)a), v, (size_t)n * sizeof *v);
	return a;
}

static void free_capsule(PyObject *capsule)
{
	free(PyCapsule_GetPointer(capsule, "beamsim.column"));
}

PyObject *pyb_adopt(void *data, long n, int ints)
{
	npy_intp dims[1] = {n};
	PyObject *a = PyArray_SimpleNewFromData(1, dims, ints ? NPY_INT64 : NPY_DOUBLE, data);
	/* The capsule frees data once it is the array's base, not before:
	 * on failure data stays the caller's. */
	PyObject *owner = a ? PyCapsule_New(data, "beamsim.column", NULL) : NULL;
	if (!owner) {
		Py_XDECREF(a);
		return NULL;
	}
	if (PyArray_SetBaseObject((PyArrayObject *)a, owner) != 0) { /* takes owner */
		Py_DECREF(a);
		return NULL;
	}
	PyCapsule_SetDestructor(owner, free_capsule);
	return a;
}

PyObject *pyb_text_column(const uint32_t *codes, long n, PyObject *labels)
{
	Py_ssize_t n_labels = labels ? PyList_GET_SIZE(labels) : 0, width = 1;
	for (Py_ssize_t i = 0; i < n_labels; i++) {
		Py_ssize_t len = PyUnicode_GET_LENGTH(PyList_GET_ITEM(labels, i));
		width = len > width ? len : width;
	}
	/* each label's code points once, copied into its rows */
	Py_UCS4 **ucs = PyMem_Calloc((size_t)(n_labels ? n_labels : 1), sizeof *ucs);
	PyObject *type = PyUnicode_FromFormat("<U%zd", width);
	PyArray_Descr *descr = NULL;
	PyObject *a = NULL;
	int ok = ucs && type && PyArray_DescrConverter(type, &descr) == NPY_SUCCEED;
	for (Py_ssize_t i = 0; ok && i < n_labels; i++)
		ok = (ucs[i] = PyUnicode_AsUCS4Copy(PyList_GET_ITEM(labels, i))) != NULL;
	if (ok) {
		npy_intp dims[1] = {n};
		a = PyArray_Zeros(1, dims, descr, 0); /* takes descr */
		descr = NULL;
	}
	if (a) {
		char *row = PyArray_DATA((PyArrayObject *)a);
		size_t item = (size_t)width * sizeof(Py_UCS4);
		for (long k = 0; k < n; k++, row += item) {
			PyObject *s = PyList_GET_ITEM(labels, codes[k]);
			memcpy(row, ucs[codes[k]],
			       (size_t)PyUnicode_GET_LENGTH(s) * sizeof(Py_UCS4));
		}
	}
	for (Py_ssize_t i = 0; ucs && i < n_labels; i++)
		PyMem_Free(ucs[i]);
	PyMem_Free(ucs);
	Py_XDECREF(type);
	Py_XDECREF(descr);
	if (!a && !PyErr_Occurred())
		PyErr_NoMemory();
	return a;
}

int pyb_set(PyObject *d, const char *key, PyObject *value)
{
	if (!value)
		return -1;
	int rc = PyDict_SetItemString(d, key, value);
	Py_DECREF(value);
	return rc;
}

/* ---- progress and Ctrl-C ------------------------------------------------ */

static double now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void pyb_progress_init(pyb_progress *p, PyObject *fn)
{
	memset(p, 0, sizeof *p);
	p->fn = fn == Py_None ? NULL : fn;
	p->last = now();
}

int pyb_run_inputs_from(PyObject *seed_o, PyObject *sets_o, PyObject *grid_o, PyObject *progress_o,
                        pyb_run_inputs *in)
{
	if (progress_o != Py_None && !PyCallable_Check(progress_o)) {
		PyErr_SetString(PyExc_TypeError, "progress: expected a callable(done, total)");
		return -1;
	}
	in->has_seed = 0;
	if (pyb_seed_from(seed_o, &in->has_seed, &in->seed) ||
	    pyb_sets_grid_from(sets_o, grid_o, &in->sets, &in->grid))
		return -1;
	pyb_progress_init(&in->progress, progress_o);
	return 0;
}

void pyb_run_inputs_free(pyb_run_inputs *in)
{
	pyb_sets_free(&in->sets);
	pyb_grid_free(&in->grid);
}

void pyb_progress_update(void *user, long done, long total)
{
	pyb_progress *p = user;
	if (p->stop)
		return;
	/* Without a callable the GIL is taken about 10 times a second, to see
	 * a Ctrl-C, not after every trial. */
	double t = now();
	if (!p->fn && t - p->last < 0.1 && done < total)
		return;
	p->last = t;
	PyGILState_STATE g = PyGILState_Ensure();
	int failed = PyErr_CheckSignals() != 0;
	if (!failed && p->fn) {
		PyObject *r = PyObject_CallFunction(p->fn, "ll", done, total);
		failed = r == NULL;
		Py_XDECREF(r);
	}
	if (failed) {
		PyErr_Fetch(&p->type, &p->value, &p->trace);
		p->stop = 1;
	}
	PyGILState_Release(g);
}

PyObject *pyb_progress_end(pyb_progress *p, int rc, const bsim_error *err)
{
	/* A signal that came after the last check. */
	if (!p->type && PyErr_CheckSignals() != 0)
		return NULL;
	if (p->type) {
		PyErr_Restore(p->type, p->value, p->trace);
		p->type = p->value = p->trace = NULL;
		return NULL;
	}
	if (rc != BSIM_OK)
		return pyb_raise(rc, err);
	return Py_None;
}

/* ---- the module ------------------------------------------------------------ */

static PyObject *py_version(PyObject *self, PyObject *args)
{
	(void)self;
	(void)args;
	return PyUnicode_FromString(bsim_version());
}

/* backends(): the names of the backends compiled in, the registry's order
 * (the first is the default), as `beamsim backends` lists them. */
static PyObject *py_backends(PyObject *self, PyObject *args)
{
	(void)self;
	(void)args;
	PyObject *list = PyList_New(0);
	for (const bsim_backend *const *b = bsim_backend_list(); list && *b; b++) {
		PyObject *name = PyUnicode_FromString((*b)->name);
		if (!name || PyList_Append(list, name) != 0)
			Py_CLEAR(list);
		Py_XDECREF(name);
	}
	return list;
}

/* bsim_text_check(what, text): None, or ValueError naming what if the str text
 * holds a NUL (pyb_text): the package's check of the arguments the
 * functions above take as C strings (paths, backends), whose own
 * conversion would refuse one without naming the argument. */
static PyObject *py_text_check(PyObject *self, PyObject *args)
{
	(void)self;
	const char *what;
	PyObject *text;
	if (!PyArg_ParseTuple(args, "sO", &what, &text) || !pyb_text(text, what))
		return NULL;
	Py_RETURN_NONE;
}

static PyMethodDef methods[] = {
        {"run", (PyCFunction)(void (*)(void))pyb_run, METH_VARARGS | METH_KEYWORDS,
         "run(path, seed, group, trial, backend, sets, backend_opts, trajectory, stride)"},
        {"sweep", (PyCFunction)(void (*)(void))pyb_sweep, METH_VARARGS | METH_KEYWORDS,
         "sweep(experiment, out, trials, threads, seed, backend, sets, grid, backend_opts, "
         "progress, trajectories, resume, hold)"},
        {"compare", (PyCFunction)(void (*)(void))pyb_compare, METH_VARARGS | METH_KEYWORDS,
         "compare(experiment, out, a, b, trials, threads, seed, sets, grid, progress, "
         "resume)"},
        {"landscape", (PyCFunction)(void (*)(void))pyb_landscape, METH_VARARGS | METH_KEYWORDS,
         "landscape(scene, sets, spacing, region)"},
        {"markov_build", (PyCFunction)(void (*)(void))pyb_markov_build,
         METH_VARARGS | METH_KEYWORDS,
         "markov_build(experiment, out, trials, bins, vmax, entries, seed, threads, backend, "
         "sets, grid, backend_opts, progress, ..., method, k)"},
        {"markov_predict", (PyCFunction)(void (*)(void))pyb_markov_predict,
         METH_VARARGS | METH_KEYWORDS,
         "markov_predict(scene, map, sets, tol, gates, walks, out, overwrite)"},
        {"markov_method", pyb_markov_method, METH_VARARGS,
         "markov_method(dir): 'nearest' or 'maps', what the build in dir holds"},
        {"markov_validate", (PyCFunction)(void (*)(void))pyb_markov_validate,
         METH_VARARGS | METH_KEYWORDS,
         "markov_validate(experiment, map, out, trials, seed, threads, sets, grid, bootstrap, "
         "progress, resume, overwrite)"},
        {"read_table", pyb_read_table, METH_VARARGS,
         "read_table(path): a CSV table as a dict of NumPy arrays by column"},
        {"version", py_version, METH_NOARGS, "the library's version"},
        {"backends", py_backends, METH_NOARGS,
         "the backends compiled in, by name; the first is the default"},
        {"register_backend", pyb_register_backend, METH_VARARGS,
         "register_backend(cls, name, description): a backend written in Python, its name"},
        {"bsim_text_check", py_text_check, METH_VARARGS,
         "bsim_text_check(what, text): ValueError naming what if text holds a NUL"},
        {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
        PyModuleDef_HEAD_INIT,
        "_beamsim",
        "libbeamsim's calls (use the package beamsim).",
        -1,
        methods,
        NULL,
        NULL,
        NULL,
        NULL,
};

PyMODINIT_FUNC PyInit__beamsim(void);
PyMODINIT_FUNC PyInit__beamsim(void)
{
	import_array();
	PyObject *m = PyModule_Create(&module);
	if (m && pyb_world_add(m) < 0)
		Py_CLEAR(m);
	return m;
}
