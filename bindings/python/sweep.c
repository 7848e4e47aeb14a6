/* _beamsim.sweep: an experiment's sweep as `beamsim sweep EXPERIMENT --out
 * DIR` runs it (bsim_sweep_dir_run), with the GIL released, a progress
 * callable and Ctrl-C; the package reads DIR's files back. hold: the bytes
 * a cell of trials.csv will take in the package's arrays, for the run to
 * be refused at once if they would not fit in memory. */
#define _POSIX_C_SOURCE 200809L

#include "pyb.h"

#include <string.h>

PyObject *pyb_sweep(PyObject *self, PyObject *args, PyObject *kw)
{
	(void)self;
	static char *kwlist[] = {"experiment",   "out",    "trials",    "threads",      "seed",
	                         "backend",      "sets",   "grid",      "backend_opts", "progress",
	                         "trajectories", "resume", "overwrite", "hold",         NULL};
	const char *experiment, *out, *backend_spec = NULL;
	long trials = 0, keep = 0;
	int threads = 0, resume = 0, overwrite = 0;
	double hold = 0;
	PyObject *seed_o = Py_None, *sets_o = Py_None, *grid_o = Py_None, *opts_o = Py_None,
	         *progress_o = Py_None;
	if (!PyArg_ParseTupleAndKeywords(args, kw, "ss|liOzOOOOlppd", kwlist, &experiment, &out,
	                                 &trials, &threads, &seed_o, &backend_spec, &sets_o,
	                                 &grid_o, &opts_o, &progress_o, &keep, &resume, &overwrite,
	                                 &hold))
		return NULL;
	if (progress_o != Py_None && !PyCallable_Check(progress_o)) {
		PyErr_SetString(PyExc_TypeError, "progress: expected a callable(done, total)");
		return NULL;
	}
	bsim_sweep_dir_def def = bsim_sweep_dir_def_default();
	if (!(def.backend = pyb_backend(backend_spec, opts_o, &def.opts)))
		return NULL;
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
	def.keep = (int)keep;
	def.resume = resume;
	def.overwrite = overwrite;
	def.resume_option = "resume=True";
	def.overwrite_option = "overwrite=True";
	def.hold_cell_bytes = hold;
	def.progress = pyb_progress_update;
	def.progress_user = &progress;
	def.stop = &progress.stop;
	bsim_sweep_dir_result res;
	bsim_error err;
	int rc;
	Py_BEGIN_ALLOW_THREADS;
	rc = bsim_sweep_dir_run(&def, &res, &err);
	Py_END_ALLOW_THREADS;
	pyb_sets_free(&sets);
	pyb_grid_free(&grid);
	PyObject *d = NULL;
	if (!pyb_progress_end(&progress, rc, &err)) {
		if (rc == BSIM_OK)
			bsim_sweep_dir_result_free(&res);
		return NULL;
	}
	char why[512] = "";
	if (res.unstable > 0)
		snprintf(why, sizeof why,
		         "%ld of %ld trials unstable on the %s backend (outcome unstable in "
		         "%s/trials.csv); the first, group %ld trial %ld: %s",
		         res.unstable, (long)res.r.n_groups * res.r.trials, def.backend->name, out,
		         res.first_unstable / res.r.trials, res.first_unstable % res.r.trials,
		         res.unstable_why);
	d = PyDict_New();
	if (!d || pyb_set(d, "threads", PyLong_FromLong(res.threads)) ||
	    pyb_set(d, "unstable", PyLong_FromLong(res.unstable)) ||
	    pyb_set(d, "unstable_text", PyUnicode_FromString(why)) ||
	    pyb_set(d, "wall_seconds", PyFloat_FromDouble(res.r.wall_seconds)))
		Py_CLEAR(d);
	bsim_sweep_dir_result_free(&res);
	return d;
}
