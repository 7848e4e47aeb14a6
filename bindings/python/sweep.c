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
	bsim_sweep_dir_def def = bsim_sweep_dir_def_default();
	if (!(def.backend = pyb_backend(backend_spec, opts_o, &def.opts)))
		return NULL;
	pyb_run_inputs in;
	if (pyb_run_inputs_from(seed_o, sets_o, grid_o, progress_o, &in))
		return NULL;
	PYB_RUN_INPUTS_SET(def, in);
	def.experiment = experiment;
	def.out = out;
	def.trials = trials;
	def.threads = threads;
	def.keep = (int)keep;
	def.resume = resume;
	def.overwrite = overwrite;
	def.hold_cell_bytes = hold;
	bsim_sweep_dir_result res;
	bsim_error err;
	int rc;
	Py_BEGIN_ALLOW_THREADS;
	rc = bsim_sweep_dir_run(&def, &res, &err);
	Py_END_ALLOW_THREADS;
	pyb_run_inputs_free(&in);
	PyObject *d = NULL;
	if (!pyb_progress_end(&in.progress, rc, &err)) {
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
