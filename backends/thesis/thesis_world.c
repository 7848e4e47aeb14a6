/* The thesis backend: world creation, state access, knobs, and the step's
 * calls; the order of one step (docs/model.md sections 3-5; thesis_step.h
 * makes it):
 *   1. detect the contacts the step can reach (speculative margin);
 *   2. impacts of approaching contacts (restitution, or plastic below
 *      rest_threshold);
 *   3. smooth motion under the external force, springs, dampers and
 *      persistent contact forces;
 *   4. projection of any penetration left by the contacts' curvature;
 *   5. sleeping: beams the body has left and whose energy has decayed are
 *      put exactly to rest (beam_sleep.c);
 *   6. the beams listed for the contact flag the runner computes from the
 *      state (contact_list.h), which moves nothing.
 * Only the beams near the body (broad_phase.c) and the awake ones are
 * touched, so a step costs the same in a field of one gate or a thousand.
 *
 * contact_mode=essay reads the essay's flowchart (Sec. 2.4, Fig. 2.5)
 * literally: once a contact turns persistent the program leaves the
 * collision loop for the constraint loop and stays there "until both beams
 * are detached", so while any beam is held, a beam that is not held is not
 * tested for contact at all and can swing through the body (or the body
 * through it). A beam is held after a step in which it touched the body
 * (gap <= contact_tol) and the smooth solve pressed on it (P > 0); it is
 * released by the first step whose solve leaves it unpressed. The default,
 * physical, tests every beam the step can reach. */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/version.h"
#include "beamsim/body_shape.h"
#include "thesis/thesis.h"
#include "thesis/thesis_step.h"

static const bsim_knob thesis_knobs[] = {
        {"integrator", BSIM_KNOB_CHOICE, "midpoint", "midpoint|euler",
         "beam and body update: implicit midpoint (A-stable, exact energy ledger) or "
         "semi-implicit Euler"},
        {"impact_order", BSIM_KNOB_CHOICE, "simultaneous", "simultaneous|nearest_first",
         "impacts with both beams: one complementarity solve, or the essay's nearest-first order"},
        {"projection", BSIM_KNOB_INT, "1", NULL,
         "1: project out penetration deeper than slop after each step; 0: leave it"},
        {"slop", BSIM_KNOB_DOUBLE, "1e-6", NULL, "penetration tolerated before projection, m"},
        {"contact_tol", BSIM_KNOB_DOUBLE, "1e-3", NULL,
         "gap below which the solver counts a beam as touching the body (held under "
         "contact_mode=essay, kept awake), m; the reported contact flag is the same on "
         "every backend (gap under 6 mm, or an impulse in the step)"},
        {"contact_mode", BSIM_KNOB_CHOICE, "physical", "physical|essay",
         "physical: every beam the step can reach is tested for contact; essay: the essay's "
         "flowchart read literally, while one beam is held in persistent contact the others "
         "are not tested and can pass through the body"},
        {"broad_phase", BSIM_KNOB_INT, "1", NULL,
         "1: test only the beams near the body (a grid over the pivots) and the awake "
         "ones; 0: test every beam every step (same results, for checking)"},
        {"sleep", BSIM_KNOB_CHOICE, "auto", "auto|on|off",
         "put beams the body has left back exactly to rest once their energy is below "
         "sleep_energy; auto: on for lattice scenes"},
        {"sleep_energy", BSIM_KNOB_DOUBLE, "1e-6", NULL,
         "energy below which a beam the body has left sleeps, J"},
        /* No default value: unset, the impact solve uses the body's own mass
         * (the same 1/M, so every result is unchanged). */
        {"impact_mass", BSIM_KNOB_DOUBLE, NULL, NULL,
         "the body's mass in the impact solve only, kg (> 0; unset: the body's mass): 0.1 "
         "reads essay Eq. 2.4 literally, with the beam's mass m where the body's M belongs; "
         "impacts then conserve neither the body's momentum nor, in general, energy (the "
         "ledger's impact loss is negative where they create it)"},
};
/* The accuracy study's settings (beamsim accuracy): the integrators and
 * impact orders; the first, the reference, is the most accurate. */
static const bsim_knob_setting thesis_accuracy[] = {
        {"midpoint simultaneous", "integrator=midpoint:impact_order=simultaneous"},
        {"midpoint nearest_first", "integrator=midpoint:impact_order=nearest_first"},
        {"euler simultaneous", "integrator=euler:impact_order=simultaneous"},
        {"euler nearest_first", "integrator=euler:impact_order=nearest_first"},
};

/* The bounds of the checks every backend runs (docs/tests.md, "Every
 * backend"), with the default options; each a little above what the tests
 * measured (they print it), most of them round-off of doubles. */
static const bsim_backend_bound thesis_bounds[] = {
        {"impact", 1e-12, "one closed-form impulse in double"},
        {"impact.shape", 1e-12,
         "a capsule's end or an ellipse's tip: the outline's normal through the centre, one "
         "closed-form impulse in double (3.5e-16)"},
        {"impact.shape.flat", 1e-12,
         "a capsule's flat side: its two points in one simultaneous solve, in double (8.3e-16)"},
        {"impact.shape.restitution", 1e-12,
         "the true ellipse's contact point: Newton's law there, in double (8.9e-16)"},
        {"vibration", 2e-5, "the midpoint rule, 0.02% of theta0 over 3 s"},
        {"vibration.order", 2, "the midpoint rule is second order"},
        {"vibration.mirror", 1e-12, "round-off"},
        {"stiff", 1e-12, "the midpoint rule is A-stable and keeps the spring's energy"},
        {"ledger.drift", 1e-9, "round-off of the midpoint rule's exact ledger"},
        {"ledger.elastic", 1e-9, "elastic impulses in double"},
        {"ledger.residual", 1e-9, "round-off"},
        {"ledger.numerical", 0.02, "persistent contact and projection"},
        {"mirror.free.disk", 0, "every operation mirrors to the bit"},
        {"mirror.contact.disk", 0, "the simultaneous impact solve mirrors to the bit"},
        {"mirror.trial.disk", 0, "every operation mirrors to the bit"},
        {"mirror.free.capsule", 0, "free flight and every effect mirror to the bit"},
        {"mirror.free.ellipse", 0, "free flight and every effect mirror to the bit"},
        {"mirror.contact.capsule", 1e-9,
         "the body's frame from cos and sin of psi and pi - psi, which differ in the last bit"},
        {"mirror.contact.ellipse", 1e-9,
         "the body's frame from cos and sin of psi and pi - psi, which differ in the last bit"},
        {"mirror.trial.capsule", 1e-6, "that round-off, grown by a chaotic path over 12 s"},
        {"mirror.trial.ellipse", 1e-6, "that round-off, grown by a chaotic path over 12 s"},
        {"hard.apex", 1e-9, "round-off of positions in double"},
        {"hard.centred", 1e-12, "the simultaneous impact solve is symmetric to round-off"},
        {"hard.penetration", 1e-5, "projection to slop, 1e-6 m"},
        {"hard.pivot", 0, "the pin is exact: beams only turn"},
        {"hard.energy", 1e-6,
         "round-off: the solver only loses energy here (3.3 to 51 J in the mass-ratio cases)"},
        {"hard.graze.energy", 1e-9, "an elastic tip impulse in double"},
        {"hard.graze.momentum", 1e-9, "an elastic tip impulse in double"},
        {"hard.graze.penetration", 1e-5, "speculative contacts, projection to slop"},
        {"hard.noise.penetration", 1e-5, "speculative contacts, projection to slop"},
        {"hard.conservative.drift", 0.011,
         "1.06% lost over 400 s as persistent-contact work: a contact a beam's spring closes "
         "within a step, which the impact stage does not predict from the step's start, is "
         "stopped plastically by the smooth solve"},
        {"hard.conservative.tunnels", 0, "speculative contacts: no step passes a beam"},
        {"effects.drag.terminal", 1e-6,
         "3.1e-7 of F/c after 15 time constants: the approach's own exp(-15)"},
        {"effects.drag.velocity", 1e-12, "the runner's exact decay, in double"},
        {"effects.drag.step", 1e-12, "the runner's exact decay, in double"},
        {"effects.drag.energy", 1e-9, "in double"},
        {"effects.drag.residual", 1e-9, "the trapezoid's position update: the ledger closes"},
        {"effects.oscillation.velocity", 1e-12, "in double"},
        {"effects.oscillation.residual", 1e-9, "the trapezoid's position update"},
        {"effects.friction.stop", 1, "a step"},
        {"effects.friction.direction", 1e-12, "in double"},
        {"effects.friction.velocity", 1e-9, "in double"},
        {"effects.friction.energy", 1e-9, "in double"},
        {"effects.friction.residual", 1e-9, "in double"},
        {"effects.friction.push", 1e-9, "in double"},
        {"effects.ledger", 1e-9, "round-off"},
        {"landscape.theta", 1e-4, "a held contact's gap over its lever"},
        {"landscape.release", 2e-3, "the sprung beam lags th by a step near the release"},
        /* No "contact.stick": a disk pushed into a stiff beam at 70 deg,
         * inside the friction cone, creeps along it (0.049 m in 1.6 s
         * after the contact settled, test_body_turn) where it should
         * stick. */
};

enum {
	KNOB_INTEGRATOR,
	KNOB_IMPACT_ORDER,
	KNOB_PROJECTION,
	KNOB_SLOP,
	KNOB_CONTACT_TOL,
	KNOB_CONTACT_MODE,
	KNOB_BROAD_PHASE,
	KNOB_SLEEP,
	KNOB_SLEEP_ENERGY,
	KNOB_IMPACT_MASS
};
enum { SLEEP_AUTO = 0, SLEEP_ON = 1, SLEEP_OFF = 2 };
#define N_KNOBS ((int)(sizeof thesis_knobs / sizeof thesis_knobs[0]))

static void thesis_destroy(bsim_world *w)
{
	if (!w)
		return;
	free((void *)w->model);
	free(w);
}

/* Bytes, rounded up to an alignment for any type: each part of an
 * allocation starts at such an offset. */
static size_t part_round(size_t bytes)
{
	const size_t align = _Alignof(max_align_t);
	return (bytes + align - 1) / align * align;
}

/* THESIS_BEAM_ARRAYS' bytes and places, for nb beams, in the allocation of
 * the struct o (the model or the world), after it. */
#define ARRAY_SIZE(name, type, per, more) size += part_round((nb * (per) + (more)) * sizeof(type));
#define ARRAY_SET(name, type, per, more)                                                           \
	o->name = (type *)(void *)(block + at);                                                    \
	at += part_round((nb * (per) + (more)) * sizeof(type));
#define ARRAY_NONE(name, type, per, more)

/* The model for nb beams, its arrays carved from its one zeroed
 * allocation; NULL out of memory. *size: the allocation's bytes. */
static thesis_model *model_alloc(size_t nb, size_t *size_out)
{
	size_t size = part_round(sizeof(thesis_model) + nb * sizeof(thesis_beam_model));
	THESIS_BEAM_ARRAYS(ARRAY_SIZE, ARRAY_NONE)
	unsigned char *block = calloc(1, size);
	if (!block)
		return NULL;
	thesis_model *o = (thesis_model *)(void *)block;
	size_t at = part_round(sizeof *o + nb * sizeof *o->beams);
	THESIS_BEAM_ARRAYS(ARRAY_SET, ARRAY_NONE)
	*size_out = size;
	return o;
}

/* The world (its data) for nb beams, in one zeroed allocation; NULL out of
 * memory. */
static bsim_world *data_alloc(size_t nb)
{
	size_t size = part_round(sizeof(bsim_world) + nb * sizeof(thesis_beam));
	THESIS_BEAM_ARRAYS(ARRAY_NONE, ARRAY_SIZE)
	unsigned char *block = calloc(1, size);
	if (!block)
		return NULL;
	bsim_world *o = (bsim_world *)(void *)block;
	size_t at = part_round(sizeof *o + nb * sizeof *o->beams);
	THESIS_BEAM_ARRAYS(ARRAY_NONE, ARRAY_SET)
	return o;
}
#undef ARRAY_SIZE
#undef ARRAY_SET
#undef ARRAY_NONE

/* A shape whose outline bsim_body_shape_segment cannot give (a far segment has
 * a normal for every shape it supports) is refused. */
static int shape_check(const bsim_scene *scene, bsim_error *err)
{
	const bsim_body_def *b = &scene->body;
	if (b->shape == BSIM_SHAPE_DISK)
		return BSIM_OK;
	double r = bsim_body_shape_reach(b), x[2] = {0.0, 0.0};
	double p0[2] = {2.0 * r + 1.0, -1.0}, p1[2] = {2.0 * r + 1.0, 1.0};
	bsim_body_segment_contact c;
	if (!(r > 0.0) || bsim_body_shape_segment(b, x, 0.0, p0, p1, &c) != BSIM_OK)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "thesis: %s: body.shape: no contact detection for this "
		                      "shape (beamsim/body_shape.h gives none)",
		                      scene->path[0] ? scene->path : scene->name);
	return BSIM_OK;
}

/* The body's extended-path fields (thesis.h) from its definition. */
static void body_setup(thesis_model *m, const bsim_scene *scene)
{
	const bsim_body_def *b = &scene->body;
	m->body = *b;
	m->shaped = b->shape != BSIM_SHAPE_DISK;
	m->rotates = b->rotates != 0;
	m->friction = scene->contact.friction;
	m->extended = m->shaped || m->rotates || m->friction > 0.0;
	m->radius = m->shaped ? bsim_body_shape_reach(b) : b->radius;
	m->body_inertia = bsim_body_inertia(b);
	m->inv_body_inertia = m->rotates ? 1.0 / m->body_inertia : 0.0;
}

/* The model of scene under opts into m (allocated for its beams). */
static int model_setup(thesis_model *m, const bsim_scene *scene, const bsim_options *opts,
                       bsim_error *err)
{
	m->mass = scene->body.mass;
	m->inv_mass = 1.0 / scene->body.mass;
	m->impact_inv_mass = m->inv_mass;
	body_setup(m, scene);
	m->n_beams = scene->n_beams;
	for (int i = 0; i < scene->n_beams; i++) {
		const bsim_beam_def *d = &scene->beams[i];
		thesis_beam_model *b = &m->beams[i];
		memcpy(b->p, d->pivot, sizeof b->p);
		bsim_scene_beam_rest_direction(d, b->u0);
		b->sgn = bsim_scene_beam_forward_sign(d); /* forward = toward +y */
		b->length = d->length;
		b->reach = b->length + m->radius; /* m->radius: body_setup's, above */
		b->inertia = d->inertia;
		b->inv_inertia = 1.0 / d->inertia;
		b->stiffness = d->stiffness;
		b->damping = d->damping;
		if (d->initial_theta != 0.0 || d->initial_omega != 0.0)
			m->start_awake[m->n_start_awake++] = i;
	}
	m->e_tangent = scene->contact.restitution;
	m->e_tip = scene->contact.tip_restitution;
	m->rest_threshold = scene->contact.rest_threshold;
	m->integrator = bsim_options_choice(opts, &thesis_knobs[KNOB_INTEGRATOR]);
	m->impact_order = bsim_options_choice(opts, &thesis_knobs[KNOB_IMPACT_ORDER]);
	m->projection = bsim_options_int(opts, &thesis_knobs[KNOB_PROJECTION]) != 0;
	m->slop = bsim_options_double(opts, &thesis_knobs[KNOB_SLOP]);
	m->contact_tol = fmax(bsim_options_double(opts, &thesis_knobs[KNOB_CONTACT_TOL]), m->slop);
	m->contact_mode = bsim_options_choice(opts, &thesis_knobs[KNOB_CONTACT_MODE]);
	m->flight_disk = !m->extended && m->contact_mode != THESIS_CONTACT_ESSAY;
	m->broad_phase = bsim_options_int(opts, &thesis_knobs[KNOB_BROAD_PHASE]) != 0;
	int sleep = bsim_options_choice(opts, &thesis_knobs[KNOB_SLEEP]);
	m->sleep = sleep == SLEEP_ON || (sleep == SLEEP_AUTO && scene->has_lattice);
	m->sleep_energy = bsim_options_double(opts, &thesis_knobs[KNOB_SLEEP_ENERGY]);
	m->steps_disk = bsim_thesis_steps_takes(m);
	if (!(m->sleep_energy >= 0.0) || !isfinite(m->sleep_energy))
		return bsim_error_set(err, BSIM_EINPUT,
		                      "thesis: sleep_energy: expected a number >= 0 (J)");
	if (bsim_options_get(opts, thesis_knobs[KNOB_IMPACT_MASS].name)) {
		double mass = bsim_options_double(opts, &thesis_knobs[KNOB_IMPACT_MASS]);
		if (!(mass > 0.0))
			return bsim_error_set(err, BSIM_EINPUT,
			                      "thesis: impact_mass: expected a number > 0 (kg)");
		m->impact_inv_mass = 1.0 / mass;
	}
	if (m->broad_phase)
		bsim_thesis_grid_build(m);
	return BSIM_OK;
}

static int thesis_create(const bsim_scene *scene, const bsim_options *opts, bsim_world **out,
                         bsim_error *err)
{
	*out = NULL;
	int rc = bsim_options_check(opts, thesis_knobs, N_KNOBS, "thesis", err);
	if (rc)
		return rc;
	if ((rc = shape_check(scene, err)) != BSIM_OK)
		return rc;
	size_t nb = scene->n_beams > 0 ? (size_t)scene->n_beams : 1, model_size = 0;
	thesis_model *m = model_alloc(nb, &model_size);
	if (!m)
		return bsim_error_set(err, BSIM_EFAIL, "thesis: out of memory");
	if ((rc = model_setup(m, scene, opts, err)) != BSIM_OK) {
		free(m);
		return rc;
	}
	bsim_world *w = data_alloc(nb);
	if (!w) {
		free(m);
		return bsim_error_set(err, BSIM_EFAIL, "thesis: out of memory");
	}
	w->model = m; /* const from here on */
	w->model_size = model_size;
	memcpy(w->x, scene->body.start, sizeof w->x);
	memcpy(w->v, scene->body.velocity, sizeof w->v);
	w->heading = bsim_body_heading(&scene->body);
	w->angular_velocity = m->rotates ? scene->body.angular_velocity : 0.0;
	w->h_prepared = NAN; /* thesis_beams_prepare at the first step */
	for (int i = 0; i < scene->n_beams; i++) {
		const bsim_beam_def *d = &scene->beams[i];
		thesis_beam *b = &w->beams[i];
		b->geo.theta = NAN;
		b->theta = d->initial_theta;
		b->omega = d->initial_omega;
		b->u_theta = 0.0; /* the rest direction, u0: never read from here */
		b->u[0] = m->beams[i].u0[0];
		b->u[1] = m->beams[i].u0[1];
		w->contact_of[i] = -1;
	}
	for (int k = 0; k < m->n_start_awake; k++)
		bsim_thesis_beam_wake(w, m->start_awake[k]);
	contact_list_beams(w, NULL, 1); /* a body that starts touching a beam */
	bsim_thesis_model_seal(w);
	bsim_thesis_validate(w);
	*out = w;
	return BSIM_OK;
}

/* A beam back to how thesis_create made it from its definition d. */
static void beam_restore(bsim_world *w, int i, const bsim_beam_def *d)
{
	thesis_beam *b = &w->beams[i];
	b->theta = d->initial_theta;
	b->omega = d->initial_omega;
	b->u_theta = 0.0;
	b->u[0] = w->model->beams[i].u0[0];
	b->u[1] = w->model->beams[i].u0[1];
	memset(&b->geo, 0, sizeof b->geo);
	b->geo.theta = NAN;
	w->is_awake[i] = 0;
	w->impulse[i] = 0.0;
	w->held[i] = 0;
	w->contact_of[i] = -1;
	w->touched[i] = 0;
}

/* The world as thesis_create(scene) made it, at the cost of the beams the
 * trials since touched: the model (the grid, the rest directions and
 * forward signs ...) and the beams' constants for the last step size are
 * kept (they depend on the scene's beams and the options only, which the
 * runner guarantees unchanged: the same scene). The body and the beams'
 * initial angles are read again. */
static int thesis_reset(bsim_world *w, const bsim_scene *scene, bsim_error *err)
{
	if (scene->n_beams != w->model->n_beams)
		return bsim_error_set(err, BSIM_EINPUT, "thesis: reset to %d beams, world has %d",
		                      scene->n_beams, w->model->n_beams);
	if (w->touched_all)
		for (int i = 0; i < w->model->n_beams; i++)
			beam_restore(w, i, &scene->beams[i]);
	else
		for (int k = 0; k < w->n_touched; k++)
			beam_restore(w, w->touched_list[k], &scene->beams[w->touched_list[k]]);
	w->touched_all = 0;
	w->n_touched = 0;
	memcpy(w->x, scene->body.start, sizeof w->x);
	memcpy(w->v, scene->body.velocity, sizeof w->v);
	w->heading = bsim_body_heading(&scene->body);
	w->angular_velocity = w->model->rotates ? scene->body.angular_velocity : 0.0;
	w->impacts_scaled = 0;
	w->n_awake = w->n_pushed = w->n_contacts = 0;
	w->any_held = 0;
	w->flight_skip = w->flight_wait = 0;
	memset(&w->energy, 0, sizeof w->energy);
	w->impacts = 0;
	memset(&w->solver, 0, sizeof w->solver);
	bsim_thesis_near_forget(w);
	for (int k = 0; k < w->model->n_start_awake; k++)
		bsim_thesis_beam_wake(w, w->model->start_awake[k]);
	contact_list_beams(w, NULL, 1); /* a body that starts touching a beam */
	bsim_thesis_validate(w);
	return BSIM_OK;
}

/* The two copies, apart from thesis_step, whose free flight then needs
 * no more registers than it uses. */
THESIS_APART int step_extended(bsim_world *w, const double force[2], double torque, double h,
                               int in_flight)
{
	return step_run(w, NULL, force, torque, h, in_flight, &w->energy, &w->impacts, 1,
	                w->model->integrator);
}

THESIS_APART int step_disk(bsim_world *w, const double force[2], double h, int in_flight)
{
	return step_run(w, NULL, force, 0.0, h, in_flight, &w->energy, &w->impacts, 0,
	                w->model->integrator);
}

/* Nothing in a step allocates: the world's memory is sized at creation. */
static inline int thesis_step(bsim_world *w, const double force[2], double torque, double h,
                              bsim_error *err)
{
	(void)err;
	/* Free flight among beams at rest (none awake, none in reach): no
	 * contact, no beam to move, no square root for the margin; the essay's
	 * disk's at once, as it was before the extended path. */
	thesis_contact_spent(w);
	int in_flight = w->n_awake == 0 && thesis_flight_clear(w, force, h);
	memset(&w->energy, 0, sizeof w->energy);
	w->impacts = 0;
	if (in_flight && h == w->h_prepared && w->model->flight_disk) {
		flight_step(w, force, torque, h, 0);
		return BSIM_OK;
	}
	if (w->model->extended)
		return step_extended(w, force, torque, h, in_flight);
	return step_disk(w, force, h, in_flight);
}

THESIS_APART void thesis_get_state(const bsim_world *w, bsim_state *s)
{
	step_state(w, NULL, s);
}

/* advance's steps one after another, thesis_step and get_state each;
 * into *made those made. Apart: the runs' dispatch stays short. */
THESIS_APART int advance_each(bsim_world *w, const bsim_wrench *schedule, double h, int n,
                              bsim_state *out, int *made, bsim_error *err)
{
	for (int m = 0; m < n; m++) {
		int rc = thesis_step(w, schedule[m].force, schedule[m].torque, h, err);
		if (rc) {
			*made = m;
			return rc;
		}
		if (out)
			thesis_get_state(w, &out[m]);
	}
	*made = n;
	return BSIM_OK;
}

/* bsim_backend.advance: one step by thesis_step and get_state; more, a
 * run of free flight (thesis_flight.c) where the body flies among beams at
 * rest, else the essay's disk's runs of steps (thesis_steps.c) where the
 * world is one they take, else advance_each. Each path's steps are
 * thesis_step's, to the bit (test_steps, test_flight). A try at flight
 * that makes no step costs its room test; after one, the next waits
 * (flight_skip), doubling the wait after each such try. */
static inline int advance_calls(bsim_world *w, const bsim_wrench *schedule, double h, int n,
                                bsim_state *out, int *made, bsim_error *err)
{
	if (n == 1 && (w->flight_skip || w->n_awake || !out)) {
		/* one step, not of free flight: the step loop's usual call */
		if (w->flight_skip)
			w->flight_skip--;
		*made = 1;
		int rc = thesis_step(w, schedule[0].force, schedule[0].torque, h, err);
		if (out)
			thesis_get_state(w, out);
		return rc;
	}
	if (out && w->flight_skip == 0 && w->n_awake == 0) {
		int m = bsim_thesis_flight(w, schedule, h, n, out);
		if (m > 0) {
			w->flight_wait = 0;
			*made = m;
			return BSIM_OK;
		}
		w->flight_wait = w->flight_wait ? 2 * w->flight_wait : 1;
		if (w->flight_wait > THESIS_FLIGHT_WAIT_MAX)
			w->flight_wait = THESIS_FLIGHT_WAIT_MAX;
		w->flight_skip = w->flight_wait;
	}
	int rc = BSIM_OK;
	if (out && n > 1 && w->model->steps_disk && out[0].n_beams == w->model->n_beams)
		*made = bsim_thesis_steps(w, schedule, h, n, out);
	else
		rc = advance_each(w, schedule, h, n, out, made, err);
	w->flight_skip = w->flight_skip > *made ? w->flight_skip - *made : 0;
	return rc;
}

static int thesis_advance(bsim_world *w, const bsim_wrench *schedule, double h, int n,
                          bsim_state *out, int *made, bsim_error *err)
{
	int rc = advance_calls(w, schedule, h, n, out, made, err);
	bsim_thesis_validate(w);
	return rc;
}

static int thesis_set_state(bsim_world *w, const bsim_state *s, bsim_error *err)
{
	if (s->n_beams != w->model->n_beams)
		return bsim_error_set(err, BSIM_EINPUT, "thesis: state has %d beams, world has %d",
		                      s->n_beams, w->model->n_beams);
	memcpy(w->x, s->x, sizeof w->x);
	memcpy(w->v, s->v, sizeof w->v);
	w->heading = s->heading;
	w->angular_velocity = w->model->rotates ? s->angular_velocity : 0.0;
	w->n_awake = 0;
	step_contacts_clear(w); /* a state has no contacts: its flags wake beams */
	w->n_contacts = 0;
	thesis_contact_spent(w);
	memset(w->is_awake, 0, (size_t)w->model->n_beams * sizeof *w->is_awake);
	for (int i = 0; i < w->model->n_beams; i++) {
		w->beams[i].theta = s->theta[i];
		w->beams[i].omega = s->omega[i];
		if (s->theta[i] != 0.0 || s->omega[i] != 0.0 || s->contact[i] != BSIM_CONTACT_NONE)
			bsim_thesis_beam_wake(w, i);
		w->held[i] = 0; /* a state has no loop: contact_mode=essay starts afresh */
	}
	w->any_held = 0;
	w->flight_skip = w->flight_wait = 0;
	w->touched_all = 1; /* every beam's angle set */
	bsim_thesis_near_forget(w);
	bsim_thesis_validate(w);
	return BSIM_OK;
}

/* This backend's table; the registry (src/registry) lists it. */
const bsim_backend bsim_backend_thesis = {
        .name = "thesis",
        .description = "the essay's collision + constraint solver: impulses with restitution, "
                       "persistent contact by complementarity, implicit beam springs; a body "
                       "that turns, capsule and ellipse outlines, Coulomb contact friction",
        .knobs = thesis_knobs,
        .n_knobs = N_KNOBS,
        .create = thesis_create,
        .destroy = thesis_destroy,
        .advance = thesis_advance,
        .get_state = thesis_get_state,
        .set_state = thesis_set_state,
        .reset = thesis_reset,
        .accuracy = thesis_accuracy,
        .n_accuracy = (int)(sizeof thesis_accuracy / sizeof thesis_accuracy[0]),
        .engine = "beamsim",
        .version = BSIM_VERSION,
        /* A step costs the beams near the body, so on a lattice this
         * bounds the cost from above. */
        .cost_ns_per_beam_step = 150.0,
        .cost_basis = "the thesis backend's 1e8 beam-steps in about 15 s of one core "
                      "(docs/robustness.md, beam_steps)",
        .bounds = thesis_bounds,
        .n_bounds = (int)(sizeof thesis_bounds / sizeof thesis_bounds[0]),
        .exact_pins = 1,
};
