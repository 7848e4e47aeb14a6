/* _beamsim.World: a world stepped by hand (beamsim/stepper.h), made from a
 * scene, an experiment's trial or a stored run's trial as beamsim.run names
 * them (beamsim/replay.h). */
#include "pyb.h"

#include <string.h>

typedef struct {
	PyObject_HEAD bsim_stepper *s;
	char label[128]; /* the backend, or a stored run's side */
} pyb_world;

static void world_dealloc(pyb_world *self)
{
	bsim_stepper_free(self->s);
	Py_TYPE(self)->tp_free((PyObject *)self);
}

static int world_init(pyb_world *self, PyObject *args, PyObject *kw)
{
	static char *kwlist[] = {"path", "seed",         "group", "trial", "backend",
	                         "sets", "backend_opts", "grid",  NULL};
	const char *path, *backend_spec = NULL;
	PyObject *seed_o = Py_None, *sets_o = Py_None, *opts_o = Py_None, *grid_o = Py_None;
	long group = 0, trial = 0;
	if (!PyArg_ParseTupleAndKeywords(args, kw, "s|OllzOOO", kwlist, &path, &seed_o, &group,
	                                 &trial, &backend_spec, &sets_o, &opts_o, &grid_o))
		return -1;
	bsim_stepper_free(self->s);
	self->s = NULL;
	pyb_trial t;
	if (pyb_trial_from(path, seed_o, group, trial, backend_spec, sets_o, opts_o, grid_o, &t))
		return -1;
	bsim_replay *rp = NULL;
	bsim_error err;
	int rc = bsim_replay_open(&t.def, &rp, &err);
	if (rc == BSIM_OK) {
		bsim_stepper_def sd = bsim_stepper_def_default();
		sd.scene = &rp->scene;
		sd.backend = t.stored ? rp->backend : t.backend;
		sd.opts = t.stored ? &rp->opts : &t.opts;
		sd.seed = rp->mixed_seed;
		rc = bsim_stepper_alloc(&sd, &self->s, &err);
		snprintf(self->label, sizeof self->label, "%s",
		         t.stored ? rp->label : t.backend->name);
	}
	bsim_replay_free(rp);
	pyb_trial_free(&t);
	if (rc != BSIM_OK) {
		pyb_raise(rc, &err);
		return -1;
	}
	return 0;
}

static int world_ready(const pyb_world *self)
{
	if (self->s)
		return 1;
	PyErr_SetString(PyExc_RuntimeError, "World: not made (its __init__ failed)");
	return 0;
}

/* step(force, n, torque): n steps under force (a pair, N) and torque held,
 * or, force None, under the scene's effects (the trial's forces). */
static PyObject *world_step(pyb_world *self, PyObject *args, PyObject *kw)
{
	static char *kwlist[] = {"force", "n", "torque", NULL};
	PyObject *force_o = Py_None;
	long n = 1;
	double torque = 0.0;
	if (!world_ready(self) ||
	    !PyArg_ParseTupleAndKeywords(args, kw, "|Old", kwlist, &force_o, &n, &torque))
		return NULL;
	if (n < 1) {
		PyErr_Format(PyExc_ValueError, "n %ld: expected an integer >= 1", n);
		return NULL;
	}
	double f[2];
	if (force_o != Py_None && !PyArg_ParseTuple(force_o, "dd", &f[0], &f[1])) {
		PyErr_SetString(PyExc_TypeError, "force: expected a pair (F_x, F_y) of numbers, N");
		return NULL;
	}
	bsim_error err;
	int rc;
	Py_BEGIN_ALLOW_THREADS;
	rc = force_o == Py_None ? bsim_stepper_step(self->s, n, &err)
	                        : bsim_stepper_push(self->s, f, torque, n, &err);
	Py_END_ALLOW_THREADS;
	if (rc != BSIM_OK)
		return pyb_raise(rc, &err);
	Py_RETURN_NONE;
}

static PyObject *world_reset(pyb_world *self, PyObject *noargs)
{
	(void)noargs;
	bsim_error err;
	if (!world_ready(self))
		return NULL;
	if (bsim_stepper_reset(self->s, &err) != BSIM_OK)
		return pyb_raise(err.code, &err);
	Py_RETURN_NONE;
}

static PyObject *world_state(pyb_world *self, void *closure)
{
	(void)closure;
	if (!world_ready(self))
		return NULL;
	const bsim_state *s = bsim_stepper_state(self->s);
	const bsim_scene *sc = bsim_stepper_scene(self->s);
	long two = 2, three = 3, nb = s->n_beams;
	double wrench[3], kin, elastic;
	bsim_stepper_wrench(self->s, wrench);
	bsim_stepper_energy(self->s, &kin, &elastic);
	long step = bsim_stepper_steps(self->s);
	PyObject *d = PyDict_New(), *e = PyDict_New(), *solver = PyDict_New();
	if (!d || !e || !solver)
		goto fail;
	if (pyb_set(e, "damper", PyFloat_FromDouble(s->energy.damper)) ||
	    pyb_set(e, "impact", PyFloat_FromDouble(s->energy.impact)) ||
	    pyb_set(e, "contact", PyFloat_FromDouble(s->energy.contact)) ||
	    pyb_set(e, "correction", PyFloat_FromDouble(s->energy.correction)) ||
	    pyb_set(e, "sleep", PyFloat_FromDouble(s->energy.sleep)) ||
	    pyb_set(solver, "iteration_limit", PyLong_FromLong(s->solver.iteration_limit)) ||
	    pyb_set(solver, "clamped", PyLong_FromLong(s->solver.clamped)))
		goto fail;
	if (pyb_set(d, "step", PyLong_FromLong(step)) ||
	    pyb_set(d, "t", PyFloat_FromDouble((double)step * sc->dt)) ||
	    pyb_set(d, "x", pyb_array(1, &two, s->x)) ||
	    pyb_set(d, "v", pyb_array(1, &two, s->v)) ||
	    pyb_set(d, "heading", PyFloat_FromDouble(s->heading)) ||
	    pyb_set(d, "angular_velocity", PyFloat_FromDouble(s->angular_velocity)) ||
	    pyb_set(d, "theta", pyb_array(1, &nb, s->theta)) ||
	    pyb_set(d, "omega", pyb_array(1, &nb, s->omega)) ||
	    pyb_set(d, "contact", pyb_int_array(s->contact, nb)) ||
	    pyb_set(d, "touched", pyb_int_array(s->touched, nb)) ||
	    pyb_set(d, "impulse", pyb_array(1, &nb, s->impulse)) ||
	    pyb_set(d, "force", pyb_array(1, &three, wrench)) ||
	    pyb_set(d, "e_kin", PyFloat_FromDouble(kin)) ||
	    pyb_set(d, "e_elastic", PyFloat_FromDouble(elastic)) ||
	    pyb_set(d, "impacts", PyLong_FromLong(s->impacts)))
		goto fail;
	if (PyDict_SetItemString(d, "energy", e) || PyDict_SetItemString(d, "solver", solver))
		goto fail;
	Py_DECREF(e);
	Py_DECREF(solver);
	return d;
fail:
	Py_XDECREF(d);
	Py_XDECREF(e);
	Py_XDECREF(solver);
	return NULL;
}

static PyObject *world_dt(pyb_world *self, void *closure)
{
	(void)closure;
	return world_ready(self) ? PyFloat_FromDouble(bsim_stepper_scene(self->s)->dt) : NULL;
}

static PyObject *world_label(pyb_world *self, void *closure)
{
	(void)closure;
	return world_ready(self) ? PyUnicode_FromString(self->label) : NULL;
}

static PyMethodDef world_methods[] = {
        {"step", (PyCFunction)(void (*)(void))world_step, METH_VARARGS | METH_KEYWORDS,
         "step(force=None, n=1, torque=0.0)"},
        {"reset", (PyCFunction)world_reset, METH_NOARGS, "reset(): back to step 0"},
        {NULL, NULL, 0, NULL},
};

static PyGetSetDef world_getset[] = {
        {"state", (getter)world_state, NULL, "the state after the last step", NULL},
        {"dt", (getter)world_dt, NULL, "the scene's time step, s", NULL},
        {"backend", (getter)world_label, NULL, "the backend (a stored run's side)", NULL},
        {NULL, NULL, NULL, NULL, NULL},
};

static PyTypeObject world_type = {
        PyVarObject_HEAD_INIT(NULL, 0).tp_name = "_beamsim.World",
        .tp_basicsize = sizeof(pyb_world),
        .tp_dealloc = (destructor)world_dealloc,
        .tp_flags = Py_TPFLAGS_DEFAULT,
        .tp_doc = "World(path, seed, group, trial, backend, sets, backend_opts, grid)",
        .tp_methods = world_methods,
        .tp_getset = world_getset,
        .tp_init = (initproc)world_init,
        .tp_new = PyType_GenericNew,
};

int pyb_world_add(PyObject *module)
{
	if (PyType_Ready(&world_type) < 0)
		return -1;
	Py_INCREF(&world_type);
	if (PyModule_AddObject(module, "World", (PyObject *)&world_type) < 0) {
		Py_DECREF(&world_type);
		return -1;
	}
	return 0;
}
