/* _beamsim.run: one trial as `beamsim run PATH --json` runs it (the
 * library's replay, beamsim/replay.h), its JSON object and, if asked, the
 * trajectory as NumPy columns named as trajectory.csv's. */
#define _POSIX_C_SOURCE 200809L

#include "pyb.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The trajectory's rows as they are recorded, trajectory.csv's columns:
 * t, x, y, vx, vy, theta_i, omega_i (each beam), f_rand, contact_i, e_kin,
 * e_beam, e_prop, and heading, angular_velocity for a body that turns or is
 * not a disk (body); and at the same times ledger.csv's (LEDGER). Filled
 * with the GIL released: no Python here. */
typedef struct rows {
	int n_beams, width, body;
	long n, cap;
	double *v, *ledger;
	int oom;
} rows;

static const char *const LEDGER[] = {"t",        "e_kin",  "e_beam", "e_mech",  "w_prop",
                                     "w_rand",   "damper", "impact", "contact", "correction",
                                     "residual", "sleep",  "reset"};
enum { LEDGER_WIDTH = sizeof LEDGER / sizeof LEDGER[0] };

static void rows_record(void *user, const bsim_record_row *row)
{
	rows *r = user;
	const bsim_state *s = row->state;
	if (r->oom)
		return;
	if (r->n == 0) {
		r->n_beams = s->n_beams;
		r->body = row->body_columns;
		r->width = 9 + 3 * s->n_beams + 2 * r->body;
	}
	if (r->n == r->cap) {
		long cap = r->cap ? 2 * r->cap : 1024;
		double *v = realloc(r->v, (size_t)cap * (size_t)r->width * sizeof *v);
		if (v)
			r->v = v;
		double *l = v ? realloc(r->ledger, (size_t)cap * LEDGER_WIDTH * sizeof *l) : NULL;
		if (!l) {
			r->oom = 1;
			return;
		}
		r->ledger = l;
		r->cap = cap;
	}
	/* ledger.csv's row: the flows summed over [0, t] (beamsim/trial.h) */
	const bsim_ledger *g = row->ledger;
	double *q = r->ledger + r->n * LEDGER_WIDTH;
	const double lrow[LEDGER_WIDTH] = {
	        row->t,     row->e_kin,    row->e_beam, row->e_kin + row->e_beam,
	        g->w_prop,  g->w_rand,     g->damper,   g->impact,
	        g->contact, g->correction, g->residual, g->sleep,
	        g->reset};
	memcpy(q, lrow, sizeof lrow);
	double *p = r->v + r->n++ * r->width;
	*p++ = row->t;
	*p++ = s->x[0];
	*p++ = s->x[1];
	*p++ = s->v[0];
	*p++ = s->v[1];
	for (int i = 0; i < s->n_beams; i++) {
		*p++ = s->theta[i];
		*p++ = s->omega[i];
	}
	*p++ = row->f_rand;
	for (int i = 0; i < s->n_beams; i++)
		*p++ = s->contact[i];
	*p++ = row->e_kin;
	*p++ = row->e_beam;
	*p++ = row->e_prop;
	if (r->body) {
		*p++ = s->heading;
		*p++ = s->angular_velocity;
	}
}

/* The columns by name, each a NumPy array (contact_i int32). */
static PyObject *rows_dict(const rows *r)
{
	PyObject *d = PyDict_New();
	if (!d)
		return NULL;
	int c = 0, nb = r->n_beams;
	char name[32];
	static const char *const head[] = {"t", "x", "y", "vx", "vy"};
	for (int k = 0; k < 5; k++, c++)
		if (pyb_set(d, head[k], pyb_column(r->v + c, r->n, r->width, 0)))
			goto fail;
	for (int i = 1; i <= nb; i++) {
		snprintf(name, sizeof name, "theta%d", i);
		if (pyb_set(d, name, pyb_column(r->v + c++, r->n, r->width, 0)))
			goto fail;
		snprintf(name, sizeof name, "omega%d", i);
		if (pyb_set(d, name, pyb_column(r->v + c++, r->n, r->width, 0)))
			goto fail;
	}
	if (pyb_set(d, "f_rand", pyb_column(r->v + c++, r->n, r->width, 0)))
		goto fail;
	for (int i = 1; i <= nb; i++) {
		snprintf(name, sizeof name, "contact%d", i);
		if (pyb_set(d, name, pyb_column(r->v + c++, r->n, r->width, 1)))
			goto fail;
	}
	static const char *const tail[] = {"e_kin", "e_beam", "e_prop", "heading",
	                                   "angular_velocity"};
	for (int k = 0; k < 3 + 2 * r->body; k++, c++)
		if (pyb_set(d, tail[k], pyb_column(r->v + c, r->n, r->width, 0)))
			goto fail;
	return d;
fail:
	Py_DECREF(d);
	return NULL;
}

/* ledger.csv's columns by name. */
static PyObject *ledger_dict(const rows *r)
{
	PyObject *d = PyDict_New();
	for (int c = 0; d && c < LEDGER_WIDTH; c++)
		if (pyb_set(d, LEDGER[c], pyb_column(r->ledger + c, r->n, LEDGER_WIDTH, 0)))
			Py_CLEAR(d);
	return d;
}

/* The JSON object of `beamsim run --json` (bsim_run_output_json). */
static PyObject *json_text(const bsim_run_info *info, const bsim_trial_result *res)
{
	char *buf = NULL;
	size_t len = 0;
	FILE *f = open_memstream(&buf, &len);
	if (!f)
		return PyErr_NoMemory();
	bsim_run_output_json(f, info, res, 0);
	fclose(f);
	PyObject *s = PyUnicode_FromStringAndSize(buf, (Py_ssize_t)len);
	free(buf);
	return s;
}

int pyb_trial_from(const char *path, PyObject *seed_o, long group, long trial,
                   const char *backend_spec, PyObject *sets_o, PyObject *opts_o, PyObject *grid_o,
                   pyb_trial *t)
{
	memset(t, 0, sizeof *t);
	t->def = bsim_replay_def_default();
	t->def.path = path;
	t->def.group = group;
	t->def.trial = trial;
	if (pyb_seed_from(seed_o, &t->def.has_seed, &t->def.seed))
		return -1;
	/* A stored run's directory names its own backend: backend is a
	 * side's label there. */
	t->stored = bsim_replay_is_dir(path);
	if (t->stored) {
		t->def.side = backend_spec;
		t->def.has_backend_opts =
		        opts_o != Py_None && PyList_Check(opts_o) && PyList_Size(opts_o) > 0;
	} else if (!(t->backend = pyb_backend(backend_spec, opts_o, &t->opts))) {
		return -1;
	}
	if (pyb_sets_grid_from(sets_o, grid_o, &t->sets, &t->grid))
		return -1;
	t->def.sets = t->sets.ov;
	t->def.n_sets = t->sets.n;
	t->def.grid = t->grid.axes;
	t->def.n_grid = t->grid.n;
	return 0;
}

void pyb_trial_free(pyb_trial *t)
{
	pyb_sets_free(&t->sets);
	pyb_grid_free(&t->grid);
}

PyObject *pyb_run(PyObject *self, PyObject *args, PyObject *kw)
{
	(void)self;
	static char *kwlist[] = {"path",         "seed",       "group",  "trial", "backend", "sets",
	                         "backend_opts", "trajectory", "stride", "grid",  NULL};
	const char *path, *backend_spec = NULL;
	PyObject *seed_o = Py_None, *sets_o = Py_None, *opts_o = Py_None, *grid_o = Py_None;
	long group = 0, trial = 0, stride = 1;
	int trajectory = 0;
	if (!PyArg_ParseTupleAndKeywords(args, kw, "s|OllzOOplO", kwlist, &path, &seed_o, &group,
	                                 &trial, &backend_spec, &sets_o, &opts_o, &trajectory,
	                                 &stride, &grid_o))
		return NULL;
	if (stride < 1) {
		PyErr_Format(PyExc_ValueError, "--stride %ld: expected an integer >= 1", stride);
		return NULL;
	}
	pyb_trial t;
	if (pyb_trial_from(path, seed_o, group, trial, backend_spec, sets_o, opts_o, grid_o, &t))
		return NULL;
	int stored = t.stored;
	const bsim_backend *backend = t.backend;
	bsim_options opts = t.opts;

	bsim_replay *rp = NULL;
	bsim_trial_log *log = bsim_trial_log_alloc();
	rows traj = {0};
	bsim_recorder rec = {.stride = (int)stride, .log = log, .overlap = 1};
	if (trajectory) {
		rec.record = rows_record;
		rec.record_user = &traj;
	}
	bsim_trial_result res;
	bsim_error err;
	int rc;
	Py_BEGIN_ALLOW_THREADS;
	rc = log ? bsim_replay_open(&t.def, &rp, &err)
	         : bsim_error_set(&err, BSIM_EFAIL, "out of memory");
	if (rc == BSIM_OK) {
		if (stored) {
			backend = rp->backend;
			opts = rp->opts;
		}
		rc = bsim_replay_run(rp, backend, &opts, &rec, &res, &err);
	}
	if (rc == BSIM_OK && traj.oom)
		rc = bsim_error_set(&err, BSIM_EFAIL, "out of memory for the trajectory");
	Py_END_ALLOW_THREADS;

	PyObject *out = NULL;
	if (rc != BSIM_OK) {
		pyb_raise(rc, &err);
		goto done;
	}
	bsim_run_info info = bsim_run_info_default();
	info.scene_path = rp->scene_path;
	info.scene = &rp->scene;
	info.sets = rp->ov;
	info.n_sets = rp->n_ov;
	info.backend = backend;
	info.opts = &opts;
	info.seed = rp->seed;
	info.group = rp->group;
	info.trial = rp->trial;
	info.mixed_seed = rp->mixed_seed;
	info.stride = (int)stride;
	info.log = log;
	out = PyDict_New();
	if (!out || pyb_set(out, "json", json_text(&info, &res)))
		goto fail;
	char row[256], why[256];
	bsim_replay_row(row, sizeof row, rp->group, rp->trial, &res);
	bsim_trial_instability_text(&res, rp->scene.dt, why, sizeof why);
	if (pyb_set(out, "row", PyUnicode_FromString(row)) ||
	    pyb_set(out, "grid", PyUnicode_FromString(rp->grid)) ||
	    pyb_set(out, "kind",
	            PyUnicode_FromString(rp->kind == BSIM_REPLAY_SCENE        ? "scene"
	                                 : rp->kind == BSIM_REPLAY_EXPERIMENT ? "experiment"
	                                                                      : "stored")) ||
	    pyb_set(out, "label", PyUnicode_FromString(stored ? rp->label : backend->name)) ||
	    pyb_set(out, "instability_text", PyUnicode_FromString(why)))
		goto fail;
	const bsim_trial_result *y = bsim_replay_stored_row(rp);
	if (y) {
		bsim_replay_row(row, sizeof row, rp->group, rp->trial, y);
		if (pyb_set(out, "stored_row", PyUnicode_FromString(row)))
			goto fail;
	}
	if (trajectory && (pyb_set(out, "trajectory", rows_dict(&traj)) ||
	                   pyb_set(out, "ledger_rows", ledger_dict(&traj))))
		goto fail;
	goto done;
fail:
	Py_CLEAR(out);
done:
	free(traj.v);
	free(traj.ledger);
	bsim_trial_log_free(log);
	bsim_replay_free(rp);
	pyb_trial_free(&t);
	return out;
}
