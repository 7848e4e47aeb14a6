/* _beamsim.compare: two sides of an experiment with the same schedules as
 * `beamsim compare EXPERIMENT --backends A,B --out DIR` runs them
 * (bsim_compare_dir_run), with the GIL released, a progress callable and
 * Ctrl-C; the package reads DIR's files back. */
#define _POSIX_C_SOURCE 200809L

#include "pyb.h"

#include <string.h>

PyObject *pyb_compare(PyObject *self, PyObject *args, PyObject *kw)
{
	(void)self;
	static char *kwlist[] = {"experiment", "out",    "a",        "b",
	                         "trials",     "threads", "seed",     "sets",
	                         "grid",       "progress", "resume",  "overwrite",
	                         NULL};
	/* a, b None: the registry's default sides (bsim_compare_dir_def_default) */
	const char *experiment, *out, *a = NULL, *b = NULL;
	long trials = 0;
	int threads = 0, resume = 0, overwrite = 0;
	PyObject *seed_o = Py_None, *sets_o = Py_None, *grid_o = Py_None, *progress_o = Py_None;
	if (!PyArg_ParseTupleAndKeywords(args, kw, "ss|zzliOOOOpp", kwlist, &experiment, &out, &a,
	                                 &b, &trials, &threads, &seed_o, &sets_o, &grid_o,
	                                 &progress_o, &resume, &overwrite))
		return NULL;
	if (progress_o != Py_None && !PyCallable_Check(progress_o)) {
		PyErr_SetString(PyExc_TypeError, "progress: expected a callable(done, total)");
		return NULL;
	}
	bsim_compare_dir_def def = bsim_compare_dir_def_default();
	bsim_error err;
	const char *spec[2] = {a, b};
	for (int i = 0; i < 2; i++) {
		if (!spec[i])
			continue;
		memset(&def.side[i], 0, sizeof def.side[i]);
		if (bsim_compare_side_parse(spec[i], &def.side[i], &err) != BSIM_OK)
			return pyb_raise(err.code, &err);
	}
	if (pyb_seed_from(seed_o, &def.has_seed, &def.seed))
		return NULL;
	pyb_sets sets;
	pyb_grid grid;
	if (pyb_sets_grid_from(sets_o, grid_o, &sets, &grid))
		return NULL;
	pyb_progress progress;
	pyb_progress_init(&progress, progress_o);
	def.experiment = experiment;
	def.out = out;
	def.sets = sets.ov;
	def.n_sets = sets.n;
	def.grid = grid.axes;
	def.n_grid = grid.n;
	def.trials = trials;
	def.threads = threads;
	def.resume = resume;
	def.overwrite = overwrite;
	def.resume_option = "resume=True";
	def.overwrite_option = "overwrite=True";
	def.progress = pyb_progress_update;
	def.progress_user = &progress;
	def.stop = &progress.stop;
	bsim_compare_dir_result res;
	int rc;
	Py_BEGIN_ALLOW_THREADS;
	rc = bsim_compare_dir_run(&def, &res, &err);
	Py_END_ALLOW_THREADS;
	pyb_sets_free(&sets);
	pyb_grid_free(&grid);
	if (!pyb_progress_end(&progress, rc, &err)) {
		if (rc == BSIM_OK)
			bsim_compare_dir_result_free(&res);
		return NULL;
	}
	PyObject *d = PyDict_New();
	if (!d || pyb_set(d, "threads", PyLong_FromLong(res.threads)) ||
	    pyb_set(d, "n_disagree", PyLong_FromLong(res.cmp.n_disagree)) ||
	    pyb_set(d, "dirs", Py_BuildValue("(ss)", res.dir[0], res.dir[1])) ||
	    pyb_set(d, "labels", Py_BuildValue("(ss)", def.side[0].label, def.side[1].label)) ||
	    pyb_set(d, "unstable", Py_BuildValue("(ll)", res.unstable[0], res.unstable[1])))
		Py_CLEAR(d);
	bsim_compare_dir_result_free(&res);
	return d;
}
