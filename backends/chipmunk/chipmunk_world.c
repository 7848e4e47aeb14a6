/* The Chipmunk2D 7 backend ("chipmunk"): the model of docs/model.md
 * sections 2-5 built from Chipmunk's rigid bodies, pivot joints, damped
 * rotary springs and contacts (Debian's libchipmunk-dev, 7.0.3, double
 * precision, SI units as they are: metres, kilograms, seconds).
 *
 * Bodies.
 *   body:   dynamic, mass M at its centre, moment bsim_body_inertia if it
 *           turns (body.rotates), else infinite (Chipmunk then never turns
 *           it: its inverse moment is 0 in every row); angle the heading.
 *           One shape, in the body's frame with the heading along +x:
 *             disk:    a circle of radius R;
 *             capsule: a segment from (-L/2, 0) to (L/2, 0) of radius R,
 *                      Chipmunk's rounded segment, exactly the capsule;
 *             ellipse: one convex polygon of ELLIPSE_VERTICES vertices at
 *                      eccentric anomalies 2 pi k / K on the ellipse of
 *                      semi-axes a, b, scaled by 2 / (1 + cos(pi / K)) so
 *                      that its chords' midpoints lie as far inside the
 *                      ellipse as its vertices lie outside
 *                      (bsim_chipmunk_ellipse_polygon); with knob
 *                      ellipse=polygon only: off its axes the polygon's
 *                      restitution is not the scene's, and check
 *                      refuses it unless told.
 *   beam i: dynamic, its origin and centre of gravity at the pivot P, angle
 *           a_i = sgn theta_i (sgn = +1 if the rest direction u0 has x >= 0:
 *           theta > 0 swings the tip forward, +y), one segment of radius 0
 *           from (0, 0) to L u0 in its frame; moment I (the scene's, about
 *           the pivot, which is its centre), mass PIN_MASS_RATIO M (the pin
 *           holds the centre still: the model never sees this mass, and the
 *           iterative solve converges faster the larger it is).
 *           A cpPivotJoint pins its centre to P on the space's static body,
 *           and a cpDampedRotarySpring (rest angle 0, stiffness k, damping
 *           d) joins it to the static body: I beta = -k theta - d omega + tau_c
 *           (essay Eq. 2.2).
 *   Collision filter: the body's category meets beams only, the beams' the
 *   body only (docs/model.md section 1: beams pass through each other).
 *
 * A Chipmunk step of h (cpSpaceStep; knob substeps: n of h/n per runner
 * step, the force and torque set for each) moves every body with its
 * velocity first, x += h (v + v_bias) (v_bias the contacts' position
 * correction), then finds contacts at the new positions, applies the
 * spring's impulse -k a h to the beam (explicit, with the moved angle),
 * integrates the force, v += h F / M, and solves contacts, pins and the
 * damper by sequential impulses (knob iterations). The damper drives the
 * beam's omega toward omega exp(-d h / I) (exact for the damper alone).
 * So the spring is symplectic Euler (position first), stable only for
 * omega_n h < sqrt(2 + 2 exp(d h / I)), which check requires of every beam
 * (omega_n h = pi is the scene's own bound, docs/model.md section 11).
 * A state after a step holds the moved positions and the solved
 * velocities: a force acts on the velocity at once and on the position
 * in the next step.
 *
 * Contacts (chipmunk_contact.c): Chipmunk makes a contact once two shapes
 * overlap (no speculative margin), resolves its approach with the
 * restitution e the collision handler chooses (contact.restitution,
 * tip_restitution at a beam's end, 0 below contact.rest_threshold), and
 * pushes the overlap out by bias velocities that move positions only:
 * collision_slop (m) of overlap is left alone, the rest decays by the
 * factor collision_bias each second. Friction mu = contact.friction.
 *
 * Ground friction and drag are the runner's forces (bsim_backend.takes 0):
 * Chipmunk has no per-body damping (its space damping would slow the beams
 * too), and the pipeline's forces act through cpBodySetForce like the
 * others.
 *
 * What the runner defines (energy flows, the contact flag, pivot drift) is
 * measured in chipmunk_measure.c. Chipmunk's solvers report nothing they
 * gave up on (a fixed number of iterations, no clamping): the solver
 * counts stay 0.
 *
 * Debian builds Chipmunk without NDEBUG: its first cpSpaceNew prints a
 * banner on stdout, and its assertions abort the process on a body whose
 * position or velocity is not finite. The banner is sent to /dev/null
 * once (banner_swallow); a world whose motion leaves MOTION_MAX stops
 * before Chipmunk would step it there (step). */
#define _POSIX_C_SOURCE 200809L /* O_CLOEXEC, dup */

#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <threads.h>
#include <unistd.h>

#include "chipmunk/chipmunk_world.h"
#include "beamsim/contact_flag.h"

/* This backend's table, defined at the end of the file; the registry
 * (src/registry) lists it. */
extern const bsim_backend bsim_backend_chipmunk;

/* The knobs. Defaults: Chipmunk's iterations and collision bias; a slop of
 * 1 mm, 0.01% of the essay's body radius (Chipmunk's default 0.1 assumes
 * pixels). */
static const bsim_knob chipmunk_knobs[] = {
        {"iterations", BSIM_KNOB_INT, "10", NULL,
         "Chipmunk solver iterations per step (contacts, pins, dampers), 1..1000"},
        {"substeps", BSIM_KNOB_INT, "1", NULL,
         "Chipmunk steps of h/n per step, force and torque set for each, 1..1000"},
        {"collision_slop", BSIM_KNOB_DOUBLE, "0.001", NULL,
         "overlap (m) Chipmunk leaves between body and beam, >= 0"},
        {"collision_bias", BSIM_KNOB_DOUBLE, "0.0017970102999144358", NULL,
         "fraction of an overlap left after one second of correction, 0..1 (Chipmunk's "
         "default (1 - 0.1)^60)"},
        {"sleep", BSIM_KNOB_CHOICE, "auto", "auto|on|off",
         "beams at rest start asleep in Chipmunk (not stepped) until the body touches them; "
         "a beam once woken stays awake; auto: on for lattice scenes"},
        {"ellipse", BSIM_KNOB_CHOICE, "refuse", "refuse|polygon",
         "an ellipse body: refused (off its axes the polygon's restitution is not the "
         "scene's), or taken as Chipmunk's convex polygon of 128 vertices"},
};
enum { KNOB_ITERATIONS, KNOB_SUBSTEPS, KNOB_SLOP, KNOB_BIAS, KNOB_SLEEP, KNOB_ELLIPSE };
enum { SLEEP_AUTO = 0, SLEEP_ON = 1, SLEEP_OFF = 2 };
enum { ELLIPSE_REFUSE = 0, ELLIPSE_POLYGON = 1 };
#define N_KNOBS ((int)(sizeof chipmunk_knobs / sizeof chipmunk_knobs[0]))

/* The accuracy study's settings (beamsim accuracy), the most accurate
 * first: substeps, then iterations. */
static const bsim_knob_setting chipmunk_accuracy[] = {
        {"it=30 sub=4", "iterations=30:substeps=4"}, {"it=10 sub=4", "iterations=10:substeps=4"},
        {"it=5 sub=4", "iterations=5:substeps=4"},   {"it=30 sub=1", "iterations=30:substeps=1"},
        {"it=10 sub=1", "iterations=10:substeps=1"}, {"it=5 sub=1", "iterations=5:substeps=1"},
};

/* Chipmunk's sleep time with knob sleep: so long that no body falls asleep
 * by itself (a finite one turns Chipmunk's sleeping on). */
#define SLEEP_NEVER 1e300 /* s */

/* The beam's mass as a multiple of the body's (the header's "beam i"). */
#define PIN_MASS_RATIO 1e6

/* The ellipse's polygon: vertices (the header's "body"). */
#define ELLIPSE_VERTICES 128

/* Collision categories: the body meets beams, nothing else meets anything. */
enum { CATEGORY_BODY = 1u, CATEGORY_BEAM = 2u };

/* The largest position (m), velocity (m/s), angle (rad) or angular velocity
 * (rad/s) a world steps on: Chipmunk aborts the process on a non-finite one,
 * and below this neither a step's products nor the runner's energies
 * overflow. */
#define MOTION_MAX 1e100

/* ---- the banner ------------------------------------------------------------ */

static once_flag banner_once = ONCE_FLAG_INIT;

/* Chipmunk built without NDEBUG prints "Initializing cpSpace - Chipmunk
 * v7.0.3 (Debug Enabled)" and a second line with printf at its first
 * cpSpaceNew, once per process (a static flag in cpSpaceInit). The program's
 * stdout carries results (beamsim run --json), so that first space is made
 * here, once, with descriptor 1 on /dev/null: stdout's buffer is flushed
 * before, the banner flushed into /dev/null, and the descriptor restored. */
static void banner_swallow(void)
{
	fflush(stdout);
	const int saved = dup(STDOUT_FILENO);
	const int null = open("/dev/null", O_WRONLY | O_CLOEXEC);
	if (saved >= 0 && null >= 0)
		dup2(null, STDOUT_FILENO);
	cpSpaceFree(cpSpaceNew());
	fflush(stdout);
	if (saved >= 0 && null >= 0)
		dup2(saved, STDOUT_FILENO);
	if (saved >= 0)
		close(saved);
	if (null >= 0)
		close(null);
}

/* ---- building ------------------------------------------------------------- */

void bsim_chipmunk_ellipse_polygon(double a, double b, int n, cpVect *out)
{
	const double pi = 3.14159265358979323846;
	const double s = 2.0 / (1.0 + cos(pi / n));
	for (int k = 0; k < n; k++) {
		const double t = 2.0 * pi * k / n;
		out[k] = cpv(s * a * cos(t), s * b * sin(t));
	}
}

/* The body's shape in its frame (the header's "body"). */
static cpShape *body_shape_new(const bsim_body_def *body, cpBody *b)
{
	if (body->shape == BSIM_SHAPE_DISK)
		return cpCircleShapeNew(b, body->radius, cpvzero);
	if (body->shape == BSIM_SHAPE_CAPSULE)
		return cpSegmentShapeNew(b, cpv(-0.5 * body->length, 0.0),
		                         cpv(0.5 * body->length, 0.0), body->radius);
	cpVect ring[ELLIPSE_VERTICES];
	bsim_chipmunk_ellipse_polygon(body->semi_axes[0], body->semi_axes[1], ELLIPSE_VERTICES,
	                              ring);
	return cpPolyShapeNew(b, ELLIPSE_VERTICES, ring, cpTransformIdentity, 0.0);
}

/* Builds the space with the body at x, v, heading psi, angular velocity
 * omega_body and the beams at theta, omega; the live list from them. */
static void world_build(struct bsim_world *w, const double x[2], const double v[2], double psi,
                        double omega_body, const double *theta, const double *omega)
{
	call_once(&banner_once, banner_swallow);
	const bsim_body_def *bd = &w->scene.body;
	cpSpace *space = w->space = cpSpaceNew(); /* no gravity: a horizontal plane */
	cpSpaceSetIterations(space, w->iterations);
	cpSpaceSetCollisionSlop(space, w->slop);
	cpSpaceSetCollisionBias(space, w->bias);
	if (w->sleep)
		cpSpaceSetSleepTimeThreshold(space, SLEEP_NEVER);
	cpBody *ground = cpSpaceGetStaticBody(space);

	w->body = cpSpaceAddBody(space, cpBodyNew(bd->mass, w->rotates ? w->inertia : INFINITY));
	cpBodySetPosition(w->body, cpv(x[0], x[1]));
	cpBodySetVelocity(w->body, cpv(v[0], v[1]));
	cpBodySetAngle(w->body, psi);
	if (w->rotates)
		cpBodySetAngularVelocity(w->body, omega_body);
	w->body_shape = cpSpaceAddShape(space, body_shape_new(bd, w->body));
	cpShapeSetFilter(w->body_shape,
	                 cpShapeFilterNew(CP_NO_GROUP, CATEGORY_BODY, CATEGORY_BEAM));
	cpShapeSetCollisionType(w->body_shape, CHIP_TYPE_BODY);

	for (int i = 0; i < w->n_beams; i++) {
		chip_beam *b = &w->beams[i];
		b->body = cpSpaceAddBody(space, cpBodyNew(PIN_MASS_RATIO * bd->mass, b->inertia));
		cpBodySetPosition(b->body, cpv(b->pivot[0], b->pivot[1]));
		cpBodySetAngle(b->body, b->sgn * theta[i]);
		cpBodySetAngularVelocity(b->body, b->sgn * omega[i]);
		b->shape = cpSpaceAddShape(
		        space,
		        cpSegmentShapeNew(b->body, cpvzero,
		                          cpv(b->length * b->u0[0], b->length * b->u0[1]), 0.0));
		cpShapeSetFilter(b->shape,
		                 cpShapeFilterNew(CP_NO_GROUP, CATEGORY_BEAM, CATEGORY_BODY));
		cpShapeSetCollisionType(b->shape, CHIP_TYPE_BEAM);
		cpShapeSetUserData(b->shape, (cpDataPointer)(intptr_t)(i + 1));
		b->pin = cpSpaceAddConstraint(
		        space,
		        cpPivotJointNew2(ground, b->body, cpv(b->pivot[0], b->pivot[1]), cpvzero));
		b->spring = cpSpaceAddConstraint(
		        space,
		        cpDampedRotarySpringNew(ground, b->body, 0.0, b->stiffness, b->damping));
		/* Asleep, a beam at rest is left out of every step until the body's
		 * contact wakes it (Chipmunk, in the step that finds the contact,
		 * before its solve): exactly at rest meanwhile, as it would be
		 * awake. Put to sleep as it is made, when the space's arrays it
		 * leaves hold only the bodies made awake, Chipmunk finds it at once. */
		if (w->sleep && theta[i] == 0.0 && omega[i] == 0.0)
			cpBodySleep(b->body);
		b->touched = 0;
		b->pushed = 0;
		b->reported = 0;
		b->impulse_step = b->impulse_reported = 0.0;
	}
	bsim_chipmunk_contact_install(w);

	w->n_live = 0;
	w->n_pushed = 0;
	w->n_reported = 0;
	memset(w->is_live, 0, (size_t)w->n_beams);
	for (int i = 0; i < w->n_beams; i++)
		if (!w->track_live || theta[i] != 0.0 || omega[i] != 0.0)
			chipmunk_mark_live(w, i);
	w->diverged = 0;
	w->h_last = 0.0; /* a new space's */
	memset(&w->energy, 0, sizeof w->energy);
	w->impacts = 0;
}

/* Frees the space, then every body, shape and constraint that was in it
 * (cpSpaceFree frees none of them, and wakes the bodies it still holds). */
static void world_free_space(struct bsim_world *w)
{
	if (!w->space)
		return;
	cpSpaceFree(w->space);
	w->space = NULL;
	for (int i = 0; i < w->n_beams; i++) {
		chip_beam *b = &w->beams[i];
		cpConstraintFree(b->spring);
		cpConstraintFree(b->pin);
		cpShapeFree(b->shape);
		cpBodyFree(b->body);
		b->spring = b->pin = NULL;
		b->shape = NULL;
		b->body = NULL;
	}
	cpShapeFree(w->body_shape);
	cpBodyFree(w->body);
	w->body_shape = NULL;
	w->body = NULL;
}

/* ---- what create refuses ---------------------------------------------------- */

/* A check's refusal: the scene key to blame into field (check in
 * bsim_backend), the message into err. */
static int refuse(char *field, size_t size, const char *key, bsim_error *err, const char *msg)
{
	snprintf(field, size, "%s", key);
	return bsim_error_set(err, BSIM_EINPUT, "chipmunk: %s", msg);
}

/* A scene value and the least magnitude Chipmunk takes of it (0: any). */
typedef struct range_value {
	const char *key;
	double v, lo;
} range_value;

/* v refused, naming key, unless its magnitude is below MOTION_MAX and at
 * least lo. */
static int in_range(char *field, size_t size, const char *key, double v, double lo, bsim_error *err)
{
	if (fabs(v) < MOTION_MAX && fabs(v) >= lo)
		return BSIM_OK;
	char msg[BSIM_ERROR_MSG_MAX];
	snprintf(msg, sizeof msg,
	         "%g is beyond what the chipmunk backend takes (magnitudes %s%g: Chipmunk aborts "
	         "the process on a mass, moment, position or velocity that is not finite)",
	         v, lo > 0.0 ? "from 1e-100 to " : "below ", MOTION_MAX);
	return refuse(field, size, key, err, msg);
}

/* The largest omega_n h of a stable explicit spring with damping factor
 * exp(-d h / I) a step (the header's "A Chipmunk step"): the update
 * a' = a + h w, w' = c (w - h omega_n^2 a') has determinant c and trace
 * 1 + c (1 - (omega_n h)^2), inside the unit circle for
 * (omega_n h)^2 < 2 (1 + c) / c. */
static double spring_limit(const bsim_beam_def *b, double h)
{
	return sqrt(2.0 + 2.0 * exp(b->damping * h / b->inertia));
}

/* What create refuses (bsim_backend's check): the options, then the beams
 * whose explicit spring Chipmunk's step of dt / substeps cannot hold. */
static int chipmunk_check(const bsim_scene *scene, const bsim_options *opts, char *field,
                          size_t size, bsim_error *err)
{
	snprintf(field, size, "%s", "");
	int rc = bsim_options_check(opts, chipmunk_knobs, N_KNOBS, "chipmunk", err);
	if (rc)
		return rc;
	const long iterations = bsim_options_int(opts, &chipmunk_knobs[KNOB_ITERATIONS]);
	const long substeps = bsim_options_int(opts, &chipmunk_knobs[KNOB_SUBSTEPS]);
	const double slop = bsim_options_double(opts, &chipmunk_knobs[KNOB_SLOP]);
	const double bias = bsim_options_double(opts, &chipmunk_knobs[KNOB_BIAS]);
	if (iterations < 1 || iterations > 1000)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "chipmunk: iterations=%ld: expected 1..1000", iterations);
	if (substeps < 1 || substeps > 1000)
		return bsim_error_set(err, BSIM_EINPUT, "chipmunk: substeps=%ld: expected 1..1000",
		                      substeps);
	if (!(slop >= 0.0) || !isfinite(slop))
		return bsim_error_set(err, BSIM_EINPUT,
		                      "chipmunk: collision_slop=%g: expected a number >= 0 (m)",
		                      slop);
	if (!(bias >= 0.0 && bias <= 1.0))
		return bsim_error_set(err, BSIM_EINPUT,
		                      "chipmunk: collision_bias=%g: expected a number from 0 to 1",
		                      bias);
	/* A polygon meets a beam at its vertex nearest the beam, not at the
	 * ellipse's contact point, and the impulse's moment about the centre
	 * is the vertex's: off its axes Newton's law does not hold at the
	 * ellipse's point (test_impact, "impact.shape.restitution"), and a
	 * finer outline buys it dearly (docs/backends.md, "Shapes"). */
	if (scene->body.shape == BSIM_SHAPE_ELLIPSE &&
	    bsim_options_choice(opts, &chipmunk_knobs[KNOB_ELLIPSE]) == ELLIPSE_REFUSE) {
		char msg[BSIM_ERROR_MSG_MAX];
		snprintf(msg, sizeof msg,
		         "an ellipse is Chipmunk's polygon of %d vertices, which meets a beam at a "
		         "vertex: off its axes its restitution at the ellipse's contact point is "
		         "0.768 to 0.893 for e = 0.8 (12%% off; 2.0%% at 1024 vertices, "
		         "6.5 times the cost a step); --backend-opt ellipse=polygon takes it as "
		         "that polygon",
		         ELLIPSE_VERTICES);
		return refuse(field, size, "body.shape", err, msg);
	}
	/* What Chipmunk would abort on: a mass, moment, size, position or
	 * velocity whose products or inverses are not finite. */
	const bsim_body_def *bd = &scene->body;
	const range_value body[] = {
	        {"body.start.0", bd->start[0], 0.0},
	        {"body.start.1", bd->start[1], 0.0},
	        {"body.velocity.0", bd->velocity[0], 0.0},
	        {"body.velocity.1", bd->velocity[1], 0.0},
	        {"body.angular_velocity", bd->angular_velocity, 0.0},
	        {"body.mass", bd->mass, 1.0 / MOTION_MAX},
	        {"body.inertia", bd->rotates ? bsim_body_inertia(bd) : 1.0, 1.0 / MOTION_MAX},
	        {"body.radius", bd->radius, 0.0},
	        {"body.length", bd->length, 0.0},
	        {"body.semi_axes.0", bd->semi_axes[0], 0.0},
	        {"body.semi_axes.1", bd->semi_axes[1], 0.0},
	};
	for (size_t k = 0; k < sizeof body / sizeof body[0]; k++)
		if ((rc = in_range(field, size, body[k].key, body[k].v, body[k].lo, err)) !=
		    BSIM_OK)
			return rc;
	for (int i = 0; i < scene->n_beams; i++) {
		const bsim_beam_def *b = &scene->beams[i];
		const range_value beam[] = {
		        {"pivot.0", b->pivot[0], 0.0},
		        {"pivot.1", b->pivot[1], 0.0},
		        {"initial_theta", b->initial_theta, 0.0},
		        {"initial_omega", b->initial_omega, 0.0},
		        {"length", b->length, 0.0},
		        {"inertia", b->inertia, 1.0 / MOTION_MAX},
		};
		for (size_t k = 0; k < sizeof beam / sizeof beam[0]; k++) {
			char name[64];
			snprintf(name, sizeof name, "beams.%d.%s", i, beam[k].key);
			if ((rc = in_range(field, size, name, beam[k].v, beam[k].lo, err)) !=
			    BSIM_OK)
				return rc;
		}
	}
	const double h = scene->dt / (double)substeps;
	for (int i = 0; i < scene->n_beams; i++) {
		const bsim_beam_def *b = &scene->beams[i];
		if (!(b->stiffness > 0.0))
			continue;
		const double wnh = sqrt(b->stiffness / b->inertia) * h, limit = spring_limit(b, h);
		if (wnh < limit)
			continue;
		long need = substeps + 1;
		while (need < 1000 && sqrt(b->stiffness / b->inertia) * scene->dt / (double)need >=
		                              spring_limit(b, scene->dt / (double)need))
			need++;
		char key[64], msg[BSIM_ERROR_MSG_MAX];
		snprintf(key, sizeof key, "beams.%d.stiffness", i);
		snprintf(msg, sizeof msg,
		         "%g N m/rad gives omega_n dt / substeps = %.4g (I = %g kg m^2, dt / "
		         "substeps "
		         "= %g s); Chipmunk's damped rotary spring is explicit (symplectic Euler) "
		         "and "
		         "grows without bound from %.4g at this damping; use --backend-opt "
		         "substeps=%ld or more",
		         b->stiffness, wnh, b->inertia, h, limit, need);
		return refuse(field, size, key, err, msg);
	}
	return BSIM_OK;
}

/* ---- the interface ------------------------------------------------------------ */

static void chipmunk_destroy(bsim_world *w)
{
	if (!w)
		return;
	world_free_space(w);
	free(w->beams);
	free(w->live);
	free(w->is_live);
	free(w->contact_type);
	free(w->typed);
	free(w->pushed);
	free(w->reported);
	bsim_scene_free(&w->scene);
	free(w);
}

/* Beam angles for world_build: the state's, or the scene's initial ones. */
static void start_angles(const struct bsim_world *w, double *theta, double *omega)
{
	for (int i = 0; i < w->n_beams; i++) {
		theta[i] = w->scene.beams[i].initial_theta;
		omega[i] = w->scene.beams[i].initial_omega;
	}
}

/* Builds the space from the scene's start (create, reset); the flags at
 * the start measured. BSIM_EFAIL out of memory. */
static int world_start(struct bsim_world *w, bsim_error *err)
{
	const size_t n = (size_t)w->n_beams + 1;
	double *theta = malloc(n * sizeof *theta), *omega = malloc(n * sizeof *omega);
	if (!theta || !omega) {
		free(theta);
		free(omega);
		return bsim_error_set(err, BSIM_EFAIL, "chipmunk: out of memory");
	}
	start_angles(w, theta, omega);
	const bsim_body_def *bd = &w->scene.body;
	world_build(w, bd->start, bd->velocity, bsim_body_heading(bd), bd->angular_velocity, theta,
	            omega);
	free(theta);
	free(omega);
	w->n_typed = 0;
	for (int i = 0; i < w->n_beams; i++)
		w->contact_type[i] = BSIM_CONTACT_NONE;
	bsim_chipmunk_measure(w, 0.0, 1);
	return BSIM_OK;
}

static int chipmunk_create(const bsim_scene *scene, const bsim_options *opts, bsim_world **out,
                           bsim_error *err)
{
	*out = NULL;
	/* Without where the scene came from: the field names itself. */
	int rc = bsim_backend_check(&bsim_backend_chipmunk, opts, scene, NULL, NULL, 0, err);
	if (rc)
		return rc;
	struct bsim_world *w = calloc(1, sizeof *w);
	if (!w)
		return bsim_error_set(err, BSIM_EFAIL, "chipmunk: out of memory");
	const size_t n = (size_t)scene->n_beams + 1; /* + 1: never a size of 0 */
	w->n_beams = scene->n_beams;
	w->beams = calloc(n, sizeof *w->beams);
	w->live = calloc(n, sizeof *w->live);
	w->is_live = calloc(n, 1);
	w->contact_type = calloc(n, sizeof *w->contact_type);
	w->typed = calloc(n, sizeof *w->typed);
	w->pushed = calloc(n, sizeof *w->pushed);
	w->reported = calloc(n, sizeof *w->reported);
	if (!w->beams || !w->live || !w->is_live || !w->contact_type || !w->typed || !w->pushed ||
	    !w->reported || bsim_scene_copy(&w->scene, scene) != BSIM_OK) {
		chipmunk_destroy(w);
		return bsim_error_set(err, BSIM_EFAIL, "chipmunk: out of memory");
	}
	w->iterations = (int)bsim_options_int(opts, &chipmunk_knobs[KNOB_ITERATIONS]);
	w->substeps = (int)bsim_options_int(opts, &chipmunk_knobs[KNOB_SUBSTEPS]);
	w->slop = bsim_options_double(opts, &chipmunk_knobs[KNOB_SLOP]);
	w->bias = bsim_options_double(opts, &chipmunk_knobs[KNOB_BIAS]);
	w->track_live = scene->has_lattice != 0;
	const int sleep = bsim_options_choice(opts, &chipmunk_knobs[KNOB_SLEEP]);
	w->sleep = sleep == SLEEP_ON || (sleep == SLEEP_AUTO && scene->has_lattice);
	w->rotates = scene->body.rotates != 0;
	w->inertia = bsim_body_inertia(&scene->body);
	const bsim_body_def *bd = &scene->body;
	w->reach = bd->shape == BSIM_SHAPE_CAPSULE   ? 0.5 * bd->length + bd->radius
	           : bd->shape == BSIM_SHAPE_ELLIPSE ? fmax(bd->semi_axes[0], bd->semi_axes[1])
	                                             : bd->radius;
	for (int i = 0; i < w->n_beams; i++) {
		const bsim_beam_def *d = &scene->beams[i];
		chip_beam *b = &w->beams[i];
		b->pivot[0] = d->pivot[0];
		b->pivot[1] = d->pivot[1];
		bsim_scene_beam_rest_direction(d, b->u0);
		b->sgn = bsim_scene_beam_forward_sign(d); /* forward = toward +y */
		b->inertia = d->inertia;
		b->stiffness = d->stiffness;
		b->damping = d->damping;
		b->length = d->length;
	}
	if ((rc = world_start(w, err)) != BSIM_OK) {
		chipmunk_destroy(w);
		return rc;
	}
	*out = w;
	return BSIM_OK;
}

/* Whether every body's position, velocity, angle and angular velocity is
 * within MOTION_MAX (not NaN). */
static int motion_in_range(const struct bsim_world *w)
{
	for (int k = -1; k < w->n_live; k++) {
		const cpBody *b = k < 0 ? w->body : w->beams[w->live[k]].body;
		const cpVect p = cpBodyGetPosition(b), v = cpBodyGetVelocity(b);
		const double q[6] = {
		        p.x, p.y, v.x, v.y, cpBodyGetAngle(b), cpBodyGetAngularVelocity(b)};
		for (int j = 0; j < 6; j++)
			if (!(fabs(q[j]) < MOTION_MAX))
				return 0;
	}
	return 1;
}

/* The body and the live beams before a substep (bsim_chipmunk_measure's "-"). */
static void substep_start(struct bsim_world *w)
{
	w->x0 = cpBodyGetPosition(w->body);
	w->v0 = cpBodyGetVelocity(w->body);
	w->psi0 = cpBodyGetAngle(w->body);
	w->w0 = cpBodyGetAngularVelocity(w->body);
	for (int k = 0; k < w->n_live; k++) {
		chip_beam *b = &w->beams[w->live[k]];
		b->a0 = cpBodyGetAngle(b->body);
		b->w0 = cpBodyGetAngularVelocity(b->body);
		b->p0 = cpBodyGetPosition(b->body);
		b->u0_v = cpBodyGetVelocity(b->body);
	}
}

/* One step of h: substeps Chipmunk steps of h / substeps, the force and
 * torque set for each. A world whose motion left MOTION_MAX stops: Chipmunk
 * would abort the process at its next step; its state stays, and the
 * runner's ledger books the energy it gained (unstable). */
static int chipmunk_step(bsim_world *w, const double force[2], double torque, double h,
                         bsim_error *err)
{
	(void)err;
	memset(&w->energy, 0, sizeof w->energy);
	w->impacts = 0;
	if (w->diverged)
		return BSIM_OK;
	w->force[0] = force[0];
	w->force[1] = force[1];
	w->torque = w->rotates ? torque : 0.0;
	const double hs = h / w->substeps;
	/* the velocity a substep's force and torque add, which Chipmunk's
	 * velocity update asserts finite */
	const double kick = hs * fmax(hypot(force[0], force[1]) / w->scene.body.mass,
	                              w->rotates ? fabs(w->torque) / w->inertia : 0.0);
	if (!(kick < MOTION_MAX)) {
		w->diverged = 1;
		return BSIM_OK;
	}
	for (int k = 0; k < w->substeps; k++) {
		substep_start(w);
		cpBodySetForce(w->body, cpv(force[0], force[1]));
		if (w->rotates)
			cpBodySetTorque(w->body, w->torque);
		w->warm_coef = w->h_last == 0.0 ? 0.0 : hs / w->h_last; /* as cpSpaceStep's */
		cpSpaceStep(w->space, hs);
		w->h_last = hs;
		if (!motion_in_range(w)) {
			w->diverged = 1;
			return BSIM_OK;
		}
		bsim_chipmunk_measure(w, hs, k == w->substeps - 1);
	}
	return BSIM_OK;
}

static void chipmunk_get_state(const bsim_world *w, bsim_state *st)
{
	const cpVect p = cpBodyGetPosition(w->body), v = cpBodyGetVelocity(w->body);
	st->x[0] = p.x;
	st->x[1] = p.y;
	st->v[0] = v.x;
	st->v[1] = v.y;
	st->heading = w->rotates ? cpBodyGetAngle(w->body) : bsim_body_heading(&w->scene.body);
	st->angular_velocity = w->rotates ? cpBodyGetAngularVelocity(w->body) : 0.0;
	if (w->track_live) {
		bsim_state_set_active(st, w->live, w->n_live);
	} else {
		const int n = st->n_beams < w->n_beams ? st->n_beams : w->n_beams;
		st->n_active = 0;
		for (int i = 0; i < n; i++)
			st->active[st->n_active++] = i;
	}
	for (int k = 0; k < st->n_active; k++) {
		const int i = st->active[k];
		const chip_beam *b = &w->beams[i];
		const double angle = cpBodyGetAngle(b->body);
		const cpVect pin = cpBodyGetPosition(b->body);
		st->theta[i] = b->sgn * angle;
		st->omega[i] = b->sgn * cpBodyGetAngularVelocity(b->body);
		st->touched[i] = b->reported;
		st->impulse[i] = b->impulse_reported;
		bsim_beam_direction(b->u0, b->sgn, b->sgn * angle, &st->direction[2 * i]);
		st->pin[2 * i] = pin.x;
		st->pin[2 * i + 1] = pin.y;
	}
	st->energy = w->energy;
	st->impacts = w->impacts;
	st->solver = w->solver;
}

/* bsim_backend.advance: the steps one by one, each state read after its
 * step. */
static int chipmunk_advance(bsim_world *w, const bsim_wrench *schedule, double h, int n,
                            bsim_state *out, int *made, bsim_error *err)
{
	return bsim_backend_advance_each(w, chipmunk_step, chipmunk_get_state, schedule, h, n, out,
	                                 made, err);
}

#define STATE_EXPECTED                                                                             \
	"expected a finite value below 1e100 in magnitude (Chipmunk aborts the process on one "    \
	"that is not finite)"

/* Rebuilds the world at the state: no contact or joint impulses carried
 * over, so a run restarted here is the same as a fresh world started here;
 * the contact flags are the state's, as they were reported. */
static int chipmunk_set_state(bsim_world *w, const bsim_state *st, bsim_error *err)
{
	if (st->n_beams != w->n_beams)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "chipmunk: state has %d beams, world has %d", st->n_beams,
		                      w->n_beams);
	/* Chipmunk aborts on a value that is not finite: each is tested. */
	const double body[6] = {st->x[0], st->x[1],    st->v[0],
	                        st->v[1], st->heading, st->angular_velocity};
	static const char *const body_name[6] = {"x",  "y",       "vx",
	                                         "vy", "heading", "angular_velocity"};
	for (int k = 0; k < 6; k++)
		if (!(fabs(body[k]) < MOTION_MAX))
			return bsim_error_set(err, BSIM_EINPUT, "chipmunk: state %s = %g: %s",
			                      body_name[k], body[k], STATE_EXPECTED);
	for (int i = 0; i < st->n_beams; i++) {
		if (!(fabs(st->theta[i]) < MOTION_MAX))
			return bsim_error_set(err, BSIM_EINPUT, "chipmunk: state theta%d = %g: %s",
			                      i + 1, st->theta[i], STATE_EXPECTED);
		if (!(fabs(st->omega[i]) < MOTION_MAX))
			return bsim_error_set(err, BSIM_EINPUT, "chipmunk: state omega%d = %g: %s",
			                      i + 1, st->omega[i], STATE_EXPECTED);
	}
	world_free_space(w);
	world_build(w, st->x, st->v, st->heading, st->angular_velocity, st->theta, st->omega);
	w->n_typed = 0;
	for (int i = 0; i < st->n_beams; i++) {
		w->contact_type[i] = st->contact[i];
		if (st->contact[i] != BSIM_CONTACT_NONE) {
			chipmunk_mark_live(w, i);
			w->typed[w->n_typed++] = i;
		}
	}
	return BSIM_OK;
}

/* The world create made from scene, rebuilt: a fresh space, so the same
 * steps give the same bits (Chipmunk keeps contacts, their impulses and
 * its bounding-box tree across steps). What the world derived from the
 * beams' definitions is kept; the body's start and velocity are read
 * again. */
static int chipmunk_reset(bsim_world *w, const bsim_scene *scene, bsim_error *err)
{
	if (scene->n_beams != w->n_beams)
		return bsim_error_set(err, BSIM_EINPUT, "chipmunk: reset to %d beams, world has %d",
		                      scene->n_beams, w->n_beams);
	memcpy(w->scene.body.start, scene->body.start, sizeof w->scene.body.start);
	memcpy(w->scene.body.velocity, scene->body.velocity, sizeof w->scene.body.velocity);
	world_free_space(w);
	return world_start(w, err);
}

/* The bounds it holds itself to in the checks every backend runs
 * (docs/tests.md, "Every backend"), a little above what they measure on it
 * (each test prints its figures: `ctest --test-dir build -R NAME -V`). */
static const bsim_backend_bound chipmunk_bounds[] = {
        {"impact", 1e-6,
         "closed-form impulses to round-off (3e-16); a tip impact's angular momentum about the "
         "pivot 1.4e-7: the overlap is pushed out by moving positions"},
        {"impact.shape", 1e-9,
         "closed-form impulses: the ellipse's tips are vertices of its polygon, so the normal "
         "passes through the centre (3.5e-16; the major axis's tip 3.8e-10)"},
        {"impact.shape.flat", 1.5e-3,
         "the flat capsule's two points solved by 10 iterations stop short of the simultaneous "
         "solution: 9.1e-4 (5.7e-16 at 200)"},
        /* No "impact.shape.restitution": off its axes the ellipse's
         * polygon meets the beam at a vertex up to half a vertex's spacing
         * from the true contact point, and the impulse's moment with it:
         * the restitution there 0.768 to 0.893 for e = 0.8; check refuses
         * the ellipse unless ellipse=polygon (test_chipmunk_oracles). */
        {"vibration", 1e-3, "the explicit spring, first order in h: 8.9e-4 rad"},
        {"vibration.order", 1, "symplectic Euler is first order"},
        {"vibration.mirror", 1e-12, "round-off (measured 0)"},
        /* No "stiff": the explicit spring grows without bound from
         * omega_n h = 2 (undamped), and check refuses such a beam
         * (test_chipmunk_oracles); below it the energy oscillates about
         * its value (x 1.33 at omega_n h = 0.5). */
        {"ledger.drift", 2e-3,
         "the explicit spring's splitting at each impact: +1.8e-3 over 12 s, O(h)"},
        {"ledger.elastic", 1e-9, "elastic impulses in double (1.7e-11)"},
        {"ledger.residual", 0.11,
         "a force credited over a displacement made with the velocity before it, and the "
         "explicit spring: 0.096 of what flowed, O(h)"},
        {"ledger.numerical", 3e-3, "contact and position correction: 1.9e-3"},
        {"mirror.free.disk", 0, "every operation mirrors to the bit"},
        {"mirror.contact.disk", 0, "every operation mirrors to the bit"},
        {"mirror.trial.disk", 1e-12, "round-off: 6 of 40 trials' ends depart, by 1.2e-13 at most"},
        {"mirror.free.capsule", 0, "free flight and every effect mirror to the bit"},
        {"mirror.free.ellipse", 0, "free flight and every effect mirror to the bit"},
        {"mirror.contact.capsule", 1e-12,
         "the body's frame from cos and sin of psi and pi - psi, which differ in the last bit "
         "(7e-15)"},
        {"mirror.contact.ellipse", 0.06,
         "its polygon of 128 vertices: the images part from the first contact, 0.045 in the "
         "first second"},
        /* No "mirror.trial.SHAPE": a turning body's images part in contact
         * (0.11 to 0.16 m by the end) and the test checks the outcome. */
        {"hard.apex", 1e-9, "round-off of positions in double (measured 0)"},
        {"hard.centred", 1e-12, "round-off (6e-18)"},
        {"hard.penetration", 1.5,
         "contacts start at overlap: a body sinks in as far as the two close in a step, 1.40 m "
         "where a light beam swings back at its tip"},
        {"hard.pivot", 1e-8, "pivot joint rows converge iteratively, in double: 1.5e-9 m"},
        /* No "hard.energy": the overlap pushed out by moving positions
         * turns a light beam against its spring, +4.6 J of 29.8 J at
         * omega_n h 0.5, booked as the correction's (a negative loss). */
        {"hard.graze.energy", 1e-9, "an elastic tip impulse in double (measured 0)"},
        {"hard.graze.momentum", 1e-6,
         "the overlap pushed out by moving positions: 4.0e-7 about the pivot"},
        {"hard.graze.penetration", 5e-3, "contacts start at overlap: 3.3 mm"},
        {"hard.noise.penetration", 0.6,
         "no continuous collision: a 1000 N impact sinks in as far as the body moves in a step, "
         "0.49 m"},
        /* No "hard.conservative.*": the explicit spring's energy oscillates
         * about its value and ends +0.54% after 400 s, where the check
         * allows only a loss. */
        {"effects.drag.terminal", 1e-6,
         "3.1e-7 of F/c after 15 time constants: the approach's own exp(-15)"},
        {"effects.drag.velocity", 1e-12, "the runner's exact decay, in double"},
        {"effects.drag.step", 1e-12, "the runner's exact decay, in double"},
        {"effects.drag.energy", 1e-9, "in double"},
        {"effects.drag.residual", 1e-3,
         "its position moved with the velocity before the step's drag: 7.9e-4, first order in "
         "c h / m"},
        {"effects.oscillation.velocity", 1e-12, "in double"},
        {"effects.oscillation.residual", 0.2,
         "x += h v_n books h^2 F^2 / 2m less work a step (0.167 of the energy gained in 3.5 s)"},
        {"effects.friction.stop", 1, "a step"},
        {"effects.friction.direction", 1e-12, "in double"},
        {"effects.friction.velocity", 1e-9, "in double"},
        {"effects.friction.energy", 5e-3,
         "booked over the distance moved with the velocity before each step's friction: "
         "3.9e-3"},
        {"effects.friction.residual", 5e-3, "the same: 3.9e-3"},
        {"effects.friction.push", 1e-9, "in double"},
        {"effects.ledger", 0.02, "the runner's forces credited over its position update, O(h)"},
        {"landscape.theta", 5e-4, "contacts rest at an overlap of a few mm: 2.9e-4 rad"},
        {"landscape.release", 1e-3, "that overlap near the release: 6.3e-4 rad"},
        /* No "contact.stick": a disk pushed into a stiff beam at 70 deg,
         * inside the friction cone, creeps along it (0.052 m in 1.6 s
         * after the contact settled, test_body_turn) where it should
         * stick. */
};

/* The version as Chipmunk writes its cpVersionString (chipmunk.c), from the
 * header's numbers: a table's fields are constants, and cpVersionString is
 * a variable of the library (test_chipmunk_oracles holds the two equal). */
#define CHIPMUNK_TEXT_OF(x) #x
#define CHIPMUNK_TEXT(x)    CHIPMUNK_TEXT_OF(x)
#define CHIPMUNK_VERSION                                                                           \
	CHIPMUNK_TEXT(CP_VERSION_MAJOR)                                                            \
	"." CHIPMUNK_TEXT(CP_VERSION_MINOR) "." CHIPMUNK_TEXT(CP_VERSION_RELEASE)

/* This backend's table; the registry (src/registry) lists it. */
const bsim_backend bsim_backend_chipmunk = {
        .name = "chipmunk",
        .description = "Chipmunk2D 7: sequential impulses with restitution and split-impulse "
                       "overlap correction, pivot joints and damped rotary springs (explicit), "
                       "double precision",
        .knobs = chipmunk_knobs,
        .n_knobs = N_KNOBS,
        .create = chipmunk_create,
        .destroy = chipmunk_destroy,
        .advance = chipmunk_advance,
        .get_state = chipmunk_get_state,
        .set_state = chipmunk_set_state,
        .accuracy = chipmunk_accuracy,
        .n_accuracy = (int)(sizeof chipmunk_accuracy / sizeof chipmunk_accuracy[0]),
        .reset = chipmunk_reset,
        .takes = 0,
        .check = chipmunk_check,
        .engine = "Chipmunk2D",
        .version = CHIPMUNK_VERSION,
        /* Every beam awake is stepped (sleep off): on a lattice with
         * sleeping this bounds the cost from above. */
        .cost_ns_per_beam_step = 510.0,
        .cost_basis = "Chipmunk2D measured at 7.0-7.4 s of one core for H1's 6.98e6 steps of 2 "
                      "beams",
        .bounds = chipmunk_bounds,
        .n_bounds = (int)(sizeof chipmunk_bounds / sizeof chipmunk_bounds[0]),
        .exact_pins = 0, /* a pivot joint, solved iteratively */
};
