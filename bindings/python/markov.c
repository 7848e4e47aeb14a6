/* _beamsim.markov_build, markov_predict and markov_validate: the Markov
 * chain's maps built, a lattice predicted from them and the prediction
 * validated against direct simulation, as `beamsim markov build`, `predict`
 * and `validate` make them (beamsim/markov.h), with the GIL released, a
 * progress callable and Ctrl-C for the long ones. The package
 * (beamsim/__init__.py) checks and converts the arguments and reads the
 * files back (validate.json: every check of a validation). */
#define _GNU_SOURCE /* open_memstream */

#include "pyb.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A map of a build as a dict: group, k (left, right), key ("map_HASH", its
 * files' name; a training field's "visits_HASH") and how it was had. */
static PyObject *built_dict(const bsim_markov_built *m, bsim_markov_method method)
{
	char key[32];
	snprintf(key, sizeof key, "%s_%016llx",
	         method == BSIM_MARKOV_METHOD_NEAREST ? "visits" : "map",
	         (unsigned long long)m->key);
	const char *how = m->elsewhere ? "elsewhere"
	                  : m->copied  ? "copied"
	                  : m->cached  ? "reused"
	                               : "built";
	return Py_BuildValue("{sis(dd)sssssi}", "group", m->group, "k", m->k[0], m->k[1], "key",
	                     key, "how", how, "pass", m->pass);
}

/* entries: a sequence of str, each "self", "self:N", "flow", "flow:N" or a
 * path (bsim_markov_entries_kind); the paths into *paths (the strings the
 * sequence's own), malloc'd. -1 with an exception set. */
static int entries_from(PyObject *seq, bsim_markov_def *def, const char ***paths, int *n)
{
	*paths = NULL;
	*n = 0;
	if (seq == Py_None)
		return 0;
	if (!PyList_Check(seq)) {
		PyErr_SetString(PyExc_TypeError, "entries: expected a list of str");
		return -1;
	}
	Py_ssize_t len = PyList_Size(seq);
	*paths = calloc((size_t)(len ? len : 1), sizeof **paths);
	if (!*paths) {
		PyErr_NoMemory();
		return -1;
	}
	for (Py_ssize_t i = 0; i < len; i++) {
		const char *v = pyb_text(PyList_GetItem(seq, i), "entries");
		int is_kind = 0;
		bsim_error err;
		if (v && bsim_markov_entries_kind(v, def, &is_kind, &err) != BSIM_OK) {
			pyb_raise(err.code, &err);
			v = NULL;
		}
		if (!v) {
			free(*paths);
			*paths = NULL;
			return -1;
		}
		if (!is_kind)
			(*paths)[(*n)++] = v;
	}
	return 0;
}

PyObject *pyb_markov_build(PyObject *self, PyObject *args, PyObject *kw)
{
	(void)self;
	static char *kwlist[] = {
	        "experiment",   "out",          "trials",      "bins",  "vmax",      "entries",
	        "seed",         "threads",      "backend",     "sets",  "grid",      "backend_opts",
	        "progress",     "start_trials", "after_start", "train", "crossings", "per_crossing",
	        "after_trials", "method",       "k",           NULL};
	const char *experiment, *out, *backend_spec = NULL, *method = NULL;
	int trials = 0, threads = 0, start_trials = 0, after_start = -1, train = -1, crossings = -1,
	    per_crossing = -1, after_trials = -1, k = 0;
	double vmax = 0.0;
	PyObject *bins_o = Py_None, *entries_o = Py_None, *seed_o = Py_None, *sets_o = Py_None,
	         *grid_o = Py_None, *opts_o = Py_None, *progress_o = Py_None;
	if (!PyArg_ParseTupleAndKeywords(args, kw, "ss|iOdOOizOOOOiiiiiizi", kwlist, &experiment,
	                                 &out, &trials, &bins_o, &vmax, &entries_o, &seed_o,
	                                 &threads, &backend_spec, &sets_o, &grid_o, &opts_o,
	                                 &progress_o, &start_trials, &after_start, &train,
	                                 &crossings, &per_crossing, &after_trials, &method, &k))
		return NULL;
	bsim_markov_build_def def = bsim_markov_build_def_default();
	/* the method: as given, else maps if an argument of theirs alone is */
	const char *maps_only = trials > 0             ? "trials"
	                        : bins_o != Py_None    ? "bins"
	                        : vmax != 0.0          ? "vmax"
	                        : entries_o != Py_None ? "entries"
	                        : start_trials != 0    ? "start_trials"
	                        : after_start >= 0     ? "after_start"
	                        : crossings >= 0       ? "crossings"
	                        : per_crossing >= 0    ? "per_crossing"
	                        : after_trials >= 0    ? "after_trials"
	                                               : NULL;
	bsim_error err;
	if (bsim_markov_build_method(method, maps_only, k > 0 ? "k" : NULL, &def.method, &err) !=
	    BSIM_OK) {
		PyErr_SetString(PyExc_ValueError, err.msg);
		return NULL;
	}
	if (bins_o != Py_None && !PyArg_ParseTuple(bins_o, "iii", &def.map.bins.n_pos,
	                                           &def.map.bins.n_speed, &def.map.bins.n_dir))
		return NULL;
	if (vmax != 0.0) /* 0: the default, from the propulsion; the library refuses one < 0 */
		def.map.bins.v_max = vmax;
	if (trials > 0)
		def.map.trials = trials;
	bsim_options opts;
	if (!(def.map.backend = pyb_backend(backend_spec, opts_o, &opts)))
		return NULL;
	def.map.opts = &opts;
	def.map.threads = threads;
	const char **paths;
	if (entries_from(entries_o, &def.map, &paths, &def.n_entries))
		return NULL;
	if (start_trials != 0) /* 0: the default (self and flow entries: trials) */
		def.map.start_trials = start_trials;
	if (after_start >= 0) /* -1: the default (self and flow entries: 0) */
		def.map.after_start = after_start;
	if (train >= 0) /* -1: the default training field */
		def.map.train_trials = train;
	if (crossings >= 0) /* -1: the default, counted where a training field */
		def.map.train_crossings = crossings;
	if (per_crossing >= 0) /* -1: the default */
		def.map.trials_per_crossing = per_crossing;
	if (after_trials >= 0) /* -1: the default; 0: every start trial */
		def.map.after_trials = after_trials;
	def.entries = paths;
	pyb_run_inputs in;
	if (pyb_run_inputs_from(seed_o, sets_o, grid_o, progress_o, &in)) {
		free(paths);
		return NULL;
	}
	PYB_RUN_INPUTS_SET_SCENES(def, in);
	def.experiment = experiment;
	def.out = out;
	def.map.progress = pyb_progress_update;
	def.map.progress_user = &in.progress;
	def.map.stop = &in.progress.stop;
	/* the walks' training fields: their trials (train), k, the same
	 * backend, threads, progress and stop */
	def.nearest.backend = def.map.backend;
	def.nearest.opts = &opts;
	def.nearest.threads = threads;
	if (train >= 0)
		def.nearest.trials = train;
	if (k > 0)
		def.nearest.k = k;
	def.nearest.progress = pyb_progress_update;
	def.nearest.progress_user = &in.progress;
	def.nearest.stop = &in.progress.stop;
	bsim_markov_build_result res;
	int rc;
	Py_BEGIN_ALLOW_THREADS;
	rc = bsim_markov_build_run(&def, &res, &err);
	Py_END_ALLOW_THREADS;
	pyb_run_inputs_free(&in);
	free(paths);
	if (!pyb_progress_end(&in.progress, rc, &err)) {
		if (rc == BSIM_OK)
			bsim_markov_build_result_free(&res);
		return NULL;
	}
	PyObject *maps = PyList_New(res.n_maps), *d = NULL;
	for (int i = 0; maps && i < res.n_maps; i++) {
		PyObject *m = built_dict(&res.maps[i], res.method);
		if (!m)
			Py_CLEAR(maps);
		else
			PyList_SET_ITEM(maps, i, m);
	}
	const int nearest = res.method == BSIM_MARKOV_METHOD_NEAREST;
	if (maps)
		d = Py_BuildValue("{sNsisisisdsisisssisssssl}", "maps", maps, "built", res.built,
		                  "reused", res.reused, "groups", res.n_groups, "cpu_seconds",
		                  res.seconds, "bins", res.n_bins, "trials",
		                  nearest ? def.nearest.trials : def.map.trials, "run", res.run,
		                  "pass", res.pass, "scope", res.scope, "method",
		                  nearest ? "nearest" : "maps", "visits", res.visits);
	bsim_markov_build_result_free(&res);
	return d;
}

/* The prediction as markov predict --json prints it (the text, which the
 * package parses), with its arrays: p_time ((bins, 3): end, side, stuck),
 * p_loc_time (a location's p at the trial's duration) and time_bin. */
static PyObject *prediction_dict(const char *scene, const bsim_markov_predict_result *r)
{
	char *text = NULL;
	size_t len = 0;
	FILE *f = open_memstream(&text, &len);
	if (!f)
		return PyErr_NoMemory();
	bsim_markov_predict_json(f, scene, r);
	if (fclose(f) != 0) {
		free(text);
		return PyErr_NoMemory();
	}
	const bsim_markov_prediction *p = &r->p;
	PyObject *d = PyDict_New();
	long dims[2] = {p->walks > 0 ? p->n_time_bins : 0, 3};
	long n_loc = p->walks > 0 ? p->n_locations : 0;
	if (!d || pyb_set(d, "json", PyUnicode_FromStringAndSize(text, (Py_ssize_t)len)) ||
	    pyb_set(d, "time_bin", PyFloat_FromDouble(p->walks > 0 ? p->time_bin : 0.0)) ||
	    pyb_set(d, "p_time", pyb_array(2, dims, p->p_time)) ||
	    pyb_set(d, "p_loc_time", pyb_array(1, &n_loc, p->p_loc_time)))
		Py_CLEAR(d);
	free(text);
	return d;
}

PyObject *pyb_markov_method(PyObject *self, PyObject *args)
{
	(void)self;
	const char *dir;
	if (!PyArg_ParseTuple(args, "s", &dir))
		return NULL;
	bsim_markov_method method;
	bsim_error err;
	const int rc = bsim_markov_dir_method(dir, &method, &err);
	if (rc != BSIM_OK)
		return pyb_raise(rc, &err);
	return PyUnicode_FromString(method == BSIM_MARKOV_METHOD_NEAREST ? "nearest" : "maps");
}

PyObject *pyb_markov_predict(PyObject *self, PyObject *args, PyObject *kw)
{
	(void)self;
	static char *kwlist[] = {"scene",     "map",    "sets", "tol",   "gates", "walks",   "out",
	                         "overwrite", "visits", "k",    "train", "seed",  "threads", NULL};
	const char *scene, *map, *out = NULL, *visits = NULL;
	PyObject *sets_o = Py_None, *seed_o = Py_None;
	double tol = 0.0;
	int gates = -1, overwrite = 0, k = 0, train = 0, threads = 0;
	long walks = BSIM_MARKOV_WALKS;
	if (!PyArg_ParseTupleAndKeywords(args, kw, "sz|OdilzpziiOi", kwlist, &scene, &map, &sets_o,
	                                 &tol, &gates, &walks, &out, &overwrite, &visits, &k,
	                                 &train, &seed_o, &threads))
		return NULL;
	pyb_sets sets;
	if (pyb_sets_from(sets_o, &sets))
		return NULL;
	bsim_markov_predict_def def = bsim_markov_predict_def_default();
	def.scene = scene;
	def.map_dir = map;
	/* the walks over a build in map (the package said which): these */
	def.nearest.walks = walks > 0 ? walks : def.nearest.walks;
	def.nearest.threads = threads;
	if (visits) { /* nearest-neighbour walks; the package checked the numbers */
		def.visits_dir = visits;
		if (k > 0)
			def.nearest.k = k;
		if (train > 0)
			def.nearest.trials = train;
		if (seed_o != Py_None) {
			def.nearest.seed = PyLong_AsUnsignedLongLongMask(seed_o);
			if (PyErr_Occurred()) {
				pyb_sets_free(&sets);
				return NULL;
			}
		}
	}
	def.sets = sets.ov;
	def.n_sets = sets.n;
	def.tol = tol;
	def.gates = gates;
	def.walks = walks;
	def.out = out;
	def.overwrite = overwrite;
	def.overwrite_option = "overwrite=True";
	bsim_markov_predict_result r;
	bsim_error err;
	int rc;
	Py_BEGIN_ALLOW_THREADS;
	rc = bsim_markov_predict_run(&def, &r, &err);
	Py_END_ALLOW_THREADS;
	pyb_sets_free(&sets);
	if (rc != BSIM_OK)
		return pyb_raise(rc, &err);
	PyObject *d = prediction_dict(scene, &r);
	bsim_markov_predict_result_free(&r);
	return d;
}

PyObject *pyb_markov_validate(PyObject *self, PyObject *args, PyObject *kw)
{
	(void)self;
	static char *kwlist[] = {"experiment", "map",       "out",    "trials",    "seed",
	                         "threads",    "sets",      "grid",   "bootstrap", "progress",
	                         "resume",     "overwrite", "visits", "k",         "train",
	                         "walks",      NULL};
	const char *experiment, *map, *out, *visits = NULL;
	long trials = 0, walks = 0;
	int threads = 0, bootstrap = -1, resume = 0, overwrite = 0, k = 0, train = 0;
	PyObject *seed_o = Py_None, *sets_o = Py_None, *grid_o = Py_None, *progress_o = Py_None;
	if (!PyArg_ParseTupleAndKeywords(args, kw, "szs|lOiOOiOppziil", kwlist, &experiment, &map,
	                                 &out, &trials, &seed_o, &threads, &sets_o, &grid_o,
	                                 &bootstrap, &progress_o, &resume, &overwrite, &visits, &k,
	                                 &train, &walks))
		return NULL;
	bsim_markov_validate_def def = bsim_markov_validate_def_default();
	pyb_run_inputs in;
	if (pyb_run_inputs_from(seed_o, sets_o, grid_o, progress_o, &in))
		return NULL;
	PYB_RUN_INPUTS_SET(def, in);
	def.experiment = experiment;
	def.map_dir = map;
	/* the walks, over visits or a build in map: these */
	def.nearest.threads = threads;
	if (walks > 0)
		def.nearest.walks = walks;
	if (visits) { /* nearest-neighbour walks; the package checked the numbers */
		def.visits_dir = visits;
		if (k > 0)
			def.nearest.k = k;
		if (train > 0)
			def.nearest.trials = train;
	}
	def.out = out;
	def.trials = trials;
	def.threads = threads;
	if (bootstrap >= 0)
		def.bootstrap = bootstrap;
	def.resume = resume;
	def.overwrite = overwrite;
	bsim_markov_validation v;
	bsim_error err;
	int rc;
	Py_BEGIN_ALLOW_THREADS;
	rc = bsim_markov_validate(&def, &v, &err);
	Py_END_ALLOW_THREADS;
	pyb_run_inputs_free(&in);
	if (!pyb_progress_end(&in.progress, rc, &err)) {
		if (rc == BSIM_OK)
			bsim_markov_validation_free(&v);
		return NULL;
	}
	/* the package reads validate.json, every check, back from out */
	bsim_markov_validation_free(&v);
	Py_RETURN_NONE;
}
