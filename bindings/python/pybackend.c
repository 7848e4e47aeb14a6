/* _beamsim.register_backend(cls): a backend written in Python, driven by the
 * runner like any other (docs/bindings.md, "A backend in Python").
 *
 * The class is registered as a backend table (bsim_backend_register) whose
 * functions call it: create makes cls(scene) from the scene as a dict,
 * advance calls obj.advance(force, torque, h) once a step and obj.state()
 * after it, set_state calls obj.set_state(state) where the class has one.
 * The runner's threads call them without the GIL, so each takes it
 * (PyGILState_Ensure): the worlds of a sweep run one Python call at a time.
 * A Python exception becomes the step's error, its type and text, which
 * the runner reports with the trial it happened in.
 *
 * create does not know which table it was called through, so each class
 * has its own slot: PYB_SLOTS tables, each with its own create. */
#include "pyb.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PYB_SLOTS 8

typedef struct pyb_slot {
	bsim_backend table;
	PyObject *cls; /* the class (a reference held for the process) */
	char name[32];
	char description[160];
} pyb_slot;

static pyb_slot slots[PYB_SLOTS];

struct bsim_world {
	PyObject *obj;
	int n_beams;
	double (*u0)[2]; /* each beam's rest direction, for the state's direction */
	double *sgn;
	bsim_state last; /* obj.state() after create and after each step */
};

/* The current Python exception as err's message, prefixed by what, and
 * cleared: "MySolver.advance raised ValueError: ...". */
static int py_failure(const char *what, bsim_error *err)
{
	PyObject *type, *value, *trace;
	PyErr_Fetch(&type, &value, &trace);
	PyErr_NormalizeException(&type, &value, &trace);
	PyObject *text = value ? PyObject_Str(value) : NULL;
	const char *t = text ? PyUnicode_AsUTF8(text) : NULL;
	const char *tn = type ? ((PyTypeObject *)type)->tp_name : "an exception";
	bsim_error_set(err, BSIM_EFAIL, "%s raised %s: %s", what, tn, t ? t : "");
	PyErr_Clear();
	Py_XDECREF(text);
	Py_XDECREF(type);
	Py_XDECREF(value);
	Py_XDECREF(trace);
	return BSIM_EFAIL;
}

/* d[key] = a tuple of n doubles. */
static int set_tuple(PyObject *d, const char *key, const double *v, int n)
{
	PyObject *t = PyTuple_New(n);
	for (int i = 0; t && i < n; i++)
		PyTuple_SET_ITEM(t, i, PyFloat_FromDouble(v[i]));
	return pyb_set(d, key, t);
}

static int set_double(PyObject *d, const char *key, double v)
{
	return pyb_set(d, key, PyFloat_FromDouble(v));
}

/* The scene as the class's constructor gets it: body, beams (with each
 * beam's rest direction and forward sign, as the library derives them),
 * contact, dt. */
static PyObject *scene_dict(const bsim_scene *sc)
{
	static const char *const shapes[] = {"disk", "capsule", "ellipse"};
	PyObject *d = PyDict_New(), *body = PyDict_New(), *contact = PyDict_New();
	PyObject *beams = PyList_New(sc->n_beams);
	if (!d || !body || !contact || !beams)
		goto fail;
	const bsim_body_def *b = &sc->body;
	if (set_double(body, "mass", b->mass) || set_double(body, "radius", b->radius) ||
	    set_tuple(body, "start", b->start, 2) || set_tuple(body, "velocity", b->velocity, 2) ||
	    pyb_set(body, "shape", PyUnicode_FromString(shapes[b->shape])) ||
	    set_double(body, "length", b->length) ||
	    set_tuple(body, "semi_axes", b->semi_axes, 2) ||
	    set_double(body, "heading", bsim_body_heading(b)) ||
	    set_double(body, "angular_velocity", b->angular_velocity) ||
	    set_double(body, "inertia", bsim_body_inertia(b)) ||
	    pyb_set(body, "rotates", PyBool_FromLong(b->rotates)))
		goto fail;
	for (int i = 0; i < sc->n_beams; i++) {
		const bsim_beam_def *bd = &sc->beams[i];
		double u0[2];
		bsim_scene_beam_rest_direction(bd, u0);
		PyObject *e = PyDict_New();
		PyList_SET_ITEM(beams, i, e);
		if (!e || set_tuple(e, "pivot", bd->pivot, 2) ||
		    set_double(e, "length", bd->length) || set_double(e, "mass", bd->mass) ||
		    set_double(e, "inertia", bd->inertia) ||
		    set_double(e, "stiffness", bd->stiffness) ||
		    set_double(e, "damping", bd->damping) ||
		    set_double(e, "initial_theta", bd->initial_theta) ||
		    set_double(e, "initial_omega", bd->initial_omega) ||
		    set_tuple(e, "rest_direction", u0, 2) ||
		    set_double(e, "forward_sign", bsim_scene_beam_forward_sign(bd)))
			goto fail;
	}
	const bsim_contact_def *c = &sc->contact;
	if (set_double(contact, "restitution", c->restitution) ||
	    set_double(contact, "tip_restitution", c->tip_restitution) ||
	    set_double(contact, "rest_threshold", c->rest_threshold) ||
	    set_double(contact, "friction", c->friction))
		goto fail;
	if (pyb_set(d, "name", PyUnicode_FromString(sc->name)) || set_double(d, "dt", sc->dt) ||
	    PyDict_SetItemString(d, "body", body) || PyDict_SetItemString(d, "contact", contact) ||
	    PyDict_SetItemString(d, "beams", beams))
		goto fail;
	Py_DECREF(body);
	Py_DECREF(contact);
	Py_DECREF(beams);
	return d;
fail:
	Py_XDECREF(d);
	Py_XDECREF(body);
	Py_XDECREF(contact);
	Py_XDECREF(beams);
	return NULL;
}

/* n numbers of the sequence d[key] into v; 0 if d has no key and
 * optional (v left), -1 with an exception otherwise. */
static int get_numbers(PyObject *d, const char *key, double *v, int n, int optional)
{
	PyObject *o = PyDict_GetItemString(d, key); /* borrowed */
	if (!o) {
		if (optional)
			return 0;
		PyErr_Format(PyExc_KeyError, "state(): no '%s'", key);
		return -1;
	}
	if (n == 1 && PyNumber_Check(o) && !PySequence_Check(o)) {
		v[0] = PyFloat_AsDouble(o);
		return PyErr_Occurred() ? -1 : 0;
	}
	PyObject *seq = PySequence_Fast(o, "");
	if (!seq || PySequence_Fast_GET_SIZE(seq) != n) {
		Py_XDECREF(seq);
		PyErr_Clear();
		PyErr_Format(PyExc_ValueError, "state()['%s']: expected %d number%s", key, n,
		             n == 1 ? "" : "s");
		return -1;
	}
	for (int i = 0; i < n; i++)
		v[i] = PyFloat_AsDouble(PySequence_Fast_GET_ITEM(seq, i));
	Py_DECREF(seq);
	return PyErr_Occurred() ? -1 : 0;
}

/* obj.state() into w->last, every beam listed, the raw facts the runner
 * derives from (direction, touched) computed here; -1 with an exception. */
static int state_read(struct bsim_world *w)
{
	PyObject *d = PyObject_CallMethod(w->obj, "state", NULL);
	if (!d)
		return -1;
	if (!PyDict_Check(d)) {
		Py_DECREF(d);
		PyErr_SetString(PyExc_TypeError, "state(): expected a dict");
		return -1;
	}
	bsim_state *s = &w->last;
	int nb = w->n_beams;
	double e[4] = {0.0, 0.0, 0.0, 0.0};
	int rc = get_numbers(d, "x", s->x, 2, 0) || get_numbers(d, "v", s->v, 2, 0) ||
	         get_numbers(d, "theta", s->theta, nb, 0) ||
	         get_numbers(d, "omega", s->omega, nb, 0) ||
	         get_numbers(d, "heading", &s->heading, 1, 1) ||
	         get_numbers(d, "angular_velocity", &s->angular_velocity, 1, 1);
	for (int i = 0; i < nb; i++)
		s->impulse[i] = 0.0;
	if (!rc)
		rc = get_numbers(d, "impulse", s->impulse, nb, 1);
	PyObject *flows = PyDict_GetItemString(d, "energy");
	if (!rc && flows) {
		static const char *const keys[4] = {"damper", "impact", "contact", "correction"};
		if (!PyDict_Check(flows)) {
			PyErr_SetString(PyExc_TypeError, "state()['energy']: expected a dict");
			rc = -1;
		}
		for (int k = 0; !rc && k < 4; k++)
			rc = get_numbers(flows, keys[k], &e[k], 1, 1);
	}
	Py_DECREF(d);
	if (rc)
		return -1;
	s->energy = (bsim_step_energy){e[0], e[1], e[2], e[3], 0.0};
	for (int i = 0; i < nb; i++) {
		s->touched[i] = s->impulse[i] > 0.0;
		bsim_beam_direction(w->u0[i], w->sgn[i], s->theta[i], &s->direction[2 * i]);
	}
	return 0;
}

static void py_destroy(bsim_world *w)
{
	if (!w)
		return;
	PyGILState_STATE g = PyGILState_Ensure();
	Py_XDECREF(w->obj);
	PyGILState_Release(g);
	bsim_state_free(&w->last);
	free(w->u0);
	free(w->sgn);
	free(w);
}

static int py_create(int slot, const bsim_scene *scene, bsim_world **out, bsim_error *err)
{
	*out = NULL;
	bsim_world *w = calloc(1, sizeof *w);
	int nb = scene->n_beams;
	if (!w || bsim_state_init(&w->last, nb) != BSIM_OK ||
	    !(w->u0 = calloc((size_t)(nb ? nb : 1), sizeof *w->u0)) ||
	    !(w->sgn = calloc((size_t)(nb ? nb : 1), sizeof *w->sgn))) {
		py_destroy(w);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	w->n_beams = nb;
	for (int i = 0; i < nb; i++) {
		bsim_scene_beam_rest_direction(&scene->beams[i], w->u0[i]);
		w->sgn[i] = bsim_scene_beam_forward_sign(&scene->beams[i]);
		w->last.active[i] = i;
	}
	w->last.n_active = nb;
	w->last.heading = bsim_body_heading(&scene->body);
	char what[64];
	snprintf(what, sizeof what, "%s(scene)", slots[slot].name);
	PyGILState_STATE g = PyGILState_Ensure();
	int rc = BSIM_OK;
	PyObject *sd = scene_dict(scene);
	w->obj = sd ? PyObject_CallOneArg(slots[slot].cls, sd) : NULL;
	Py_XDECREF(sd);
	if (!w->obj)
		rc = py_failure(what, err);
	else if (state_read(w))
		rc = py_failure(what, err);
	PyGILState_Release(g);
	if (rc != BSIM_OK) {
		py_destroy(w);
		return rc;
	}
	*out = w;
	return BSIM_OK;
}

/* One create per slot (the head says why). */
#define PYB_CREATE(k)                                                                              \
	static int py_create_##k(const bsim_scene *scene, const bsim_options *opts,                \
	                         bsim_world **out, bsim_error *err)                                \
	{                                                                                          \
		(void)opts;                                                                        \
		return py_create(k, scene, out, err);                                              \
	}
PYB_CREATE(0)
PYB_CREATE(1)
PYB_CREATE(2)
PYB_CREATE(3)
PYB_CREATE(4)
PYB_CREATE(5)
PYB_CREATE(6)
PYB_CREATE(7)
static int (*const creates[PYB_SLOTS])(const bsim_scene *, const bsim_options *, bsim_world **,
                                       bsim_error *) = {py_create_0, py_create_1, py_create_2,
                                                        py_create_3, py_create_4, py_create_5,
                                                        py_create_6, py_create_7};

static void py_get_state(const bsim_world *w, bsim_state *out)
{
	bsim_state_copy(out, &w->last);
}

static int py_advance(bsim_world *w, const bsim_wrench *schedule, double h, int n, bsim_state *out,
                      int *made, bsim_error *err)
{
	int rc = BSIM_OK;
	*made = 0;
	PyGILState_STATE g = PyGILState_Ensure();
	for (int k = 0; k < n; k++) {
		const bsim_wrench *f = &schedule[k];
		PyObject *r = PyObject_CallMethod(w->obj, "advance", "(dd)dd", f->force[0],
		                                  f->force[1], f->torque, h);
		if (!r) {
			rc = py_failure("advance", err);
			break;
		}
		Py_DECREF(r);
		if (state_read(w)) {
			rc = py_failure("state", err);
			break;
		}
		if (out)
			bsim_state_copy(&out[k], &w->last);
		(*made)++;
	}
	PyGILState_Release(g);
	return rc;
}

static int py_set_state(bsim_world *w, const bsim_state *s, bsim_error *err)
{
	int rc = BSIM_OK;
	PyGILState_STATE g = PyGILState_Ensure();
	PyObject *d = PyDict_New();
	if (!d || set_tuple(d, "x", s->x, 2) || set_tuple(d, "v", s->v, 2) ||
	    set_tuple(d, "theta", s->theta, s->n_beams) ||
	    set_tuple(d, "omega", s->omega, s->n_beams) || set_double(d, "heading", s->heading) ||
	    set_double(d, "angular_velocity", s->angular_velocity)) {
		rc = py_failure("set_state", err);
	} else {
		PyObject *r = PyObject_CallMethod(w->obj, "set_state", "(O)", d);
		if (!r || state_read(w))
			rc = py_failure("set_state", err);
		Py_XDECREF(r);
	}
	Py_XDECREF(d);
	PyGILState_Release(g);
	return rc;
}

/* register_backend(cls, name, description): the class's table, registered
 * once; returns the name. */
PyObject *pyb_register_backend(PyObject *self, PyObject *args)
{
	(void)self;
	PyObject *cls;
	const char *name, *description;
	if (!PyArg_ParseTuple(args, "Oss", &cls, &name, &description))
		return NULL;
	int free_slot = -1;
	for (int k = 0; k < PYB_SLOTS; k++) {
		if (slots[k].cls == cls)
			return PyUnicode_FromString(slots[k].name);
		if (!slots[k].cls && free_slot < 0)
			free_slot = k;
	}
	if (free_slot < 0) {
		PyErr_Format(PyExc_ValueError,
		             "backend %s: more than %d backends in Python in one process", name,
		             PYB_SLOTS);
		return NULL;
	}
	pyb_slot *s = &slots[free_slot];
	snprintf(s->name, sizeof s->name, "%s", name);
	snprintf(s->description, sizeof s->description, "%s", description);
	s->table = (bsim_backend){
	        .name = s->name,
	        .description = s->description,
	        .create = creates[free_slot],
	        .destroy = py_destroy,
	        .advance = py_advance,
	        .get_state = py_get_state,
	        .set_state = py_set_state,
	        .engine = "Python",
	        .version = PY_VERSION,
	};
	bsim_error err;
	if (strlen(name) >= sizeof s->name) {
		bsim_error_set(&err, BSIM_EINPUT, "backend %s: a name longer than %zu characters",
		               name, sizeof s->name - 1);
		return pyb_raise(BSIM_EINPUT, &err);
	}
	if (!bsim_backend_register(&s->table, &err)) {
		memset(s, 0, sizeof *s);
		return pyb_raise(err.code, &err);
	}
	Py_INCREF(cls);
	s->cls = cls;
	return PyUnicode_FromString(s->name);
}
