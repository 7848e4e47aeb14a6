/* Scenes built in code: the essay's gate, defaults, validation, copies
 * (docs/model.md sections 1-6). A scene owns its beams array; every
 * function that fills a scene from scratch overwrites it without freeing,
 * so free the old contents first with bsim_scene_free. */
#include "beamsim/scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/limits.h"
#include "beamsim/body_shape.h"
#include "model/scene_internal.h"

#define BSIM_PI 3.14159265358979323846

bsim_scene bsim_scene_default(void)
{
	bsim_scene d;
	bsim_scene_defaults(&d);
	return d;
}

bsim_beam_def bsim_beam_def_default(void)
{
	bsim_beam_def b;
	memset(&b, 0, sizeof b);
	b.length = 25;                                /* m, essay Table 2.1 */
	b.mass = 0.1;                                 /* kg */
	b.inertia = b.mass * b.length * b.length / 3; /* rod about its end */
	b.stiffness = 400;                            /* N m/rad */
	b.damping = 50;                               /* N m s/rad */
	return b;
}

bsim_body_def bsim_body_def_default(void)
{
	bsim_body_def b;
	memset(&b, 0, sizeof b);
	b.mass = 1;         /* kg, essay Table 2.1 */
	b.radius = 10;      /* m */
	b.heading_deg = 90; /* +y, the direction of travel */
	return b;
}

bsim_contact_def bsim_contact_def_default(void)
{
	bsim_contact_def c;
	memset(&c, 0, sizeof c);
	c.restitution = 0.8;     /* essay Table 2.1 */
	c.tip_restitution = 1.0; /* the essay's tip impacts are elastic */
	c.rest_threshold = 0.05; /* m/s */
	return c;
}

bsim_effects_def bsim_effects_def_default(void)
{
	bsim_effects_def e;
	memset(&e, 0, sizeof e);
	e.random_frequency = 50; /* Hz, the essay's refresh rate */
	/* s: 1 / (2 x 50 Hz), the OU force whose low-frequency power is the
	 * held force's at the default frequency (docs/files.md "Forcing spectra") */
	e.random_correlation_time = 0.01;
	e.ground_g = 9.81; /* m/s^2 */
	return e;
}

bsim_lattice_def bsim_lattice_def_default(void)
{
	bsim_lattice_def l;
	memset(&l, 0, sizeof l);
	l.columns = l.rows = 9; /* essay Sec. 2.6 */
	l.ix_min = -4;
	l.ix_max = 4;
	l.width = 50;   /* m, docs/model.md section 8 */
	l.depth = 60;   /* m */
	l.pivot_y = 30; /* m */
	l.beam = bsim_beam_def_default();
	l.protocol = BSIM_PROTOCOL_WORLD;
	return l;
}

void bsim_scene_defaults(bsim_scene *s)
{
	memset(s, 0, sizeof *s);
	s->body.heading_deg = 90; /* the only body key with a default other than 0 */
	s->contact = bsim_contact_def_default();
	s->effects = bsim_effects_def_default();
	s->dt = 0.004;       /* s */
	s->max_steps = 3000; /* 12 s */
	s->success_y = 65;   /* m: pivot row 30 + L 25 + R 10 */
	s->side_x = 25;      /* m: the gate's half width */
	s->classify_y = 80;  /* m */
	/* m/s: five times the lateral speed that solve order and float32
	 * rounding give Box2D in the exactly symmetric noise-free gate
	 * (2.1 mm/s), where the type is round-off, not a side. */
	s->classify_deadband = 0.01;
	s->landscape_y0 = 60; /* m: essay Eq. 2.16 */
}

static void gate_beam(bsim_beam_def *b, double px, double rest_deg)
{
	*b = bsim_beam_def_default();
	b->pivot[0] = px;
	b->pivot[1] = 30; /* m */
	b->rest_angle_deg = rest_deg;
}

void bsim_scene_init_gate(bsim_scene *s, double f_prop, double rm)
{
	bsim_scene_defaults(s);
	snprintf(s->name, sizeof s->name, "thesis-gate");
	s->body = bsim_body_def_default();
	/* On allocation failure the scene has no beams and fails validation. */
	if (bsim_scene_set_beams(s, 2) == BSIM_OK) {
		gate_beam(&s->beams[0], -25, 0);  /* left, pointing at the midline */
		gate_beam(&s->beams[1], 25, 180); /* right, mirrored */
	}
	s->effects.has_propulsion = 1;
	s->effects.propulsion_force = f_prop;
	s->effects.has_random_force = rm > 0; /* Rm = 0: no draws at all */
	s->effects.random_magnitude = rm;
}

void bsim_scene_beam_rest_direction(const bsim_beam_def *b, double u0[2])
{
	double q = b->rest_angle_deg / 90.0;
	if (q == floor(q) && fabs(q) < 1e15) {
		static const double c[4] = {1, 0, -1, 0}, s[4] = {0, 1, 0, -1};
		long k = ((long)fmod(q, 4.0) + 4) % 4;
		u0[0] = c[k];
		u0[1] = s[k];
		return;
	}
	const double rad = b->rest_angle_deg * (BSIM_PI / 180);
	u0[0] = cos(rad);
	u0[1] = sin(rad);
}

double bsim_scene_beam_forward_sign(const bsim_beam_def *b)
{
	double u0[2];
	bsim_scene_beam_rest_direction(b, u0);
	return u0[0] >= 0.0 ? 1.0 : -1.0;
}

double bsim_body_inertia(const bsim_body_def *b)
{
	if (b->inertia > 0)
		return b->inertia;
	const double r = b->radius, l = b->length, a = b->semi_axes[0], c = b->semi_axes[1];
	switch (b->shape) {
	case BSIM_SHAPE_CAPSULE: {
		double rect = 2 * r * l, disk = BSIM_PI * r * r,
		       m_r = b->mass * rect / (rect + disk), m_d = b->mass - m_r;
		return m_r * (l * l + 4 * r * r) / 12 +
		       m_d * (r * r / 2 + l * l / 4 + 4 * r * l / (3 * BSIM_PI));
	}
	case BSIM_SHAPE_ELLIPSE:
		return b->mass * (a * a + c * c) / 4;
	default:
		return b->mass * r * r / 2;
	}
}

double bsim_body_heading(const bsim_body_def *b)
{
	return b->heading_deg * (BSIM_PI / 180);
}

double bsim_body_area(const bsim_body_def *b)
{
	switch (b->shape) {
	case BSIM_SHAPE_CAPSULE:
		return 2 * b->radius * b->length + BSIM_PI * b->radius * b->radius;
	case BSIM_SHAPE_ELLIPSE:
		return BSIM_PI * b->semi_axes[0] * b->semi_axes[1];
	default:
		return BSIM_PI * b->radius * b->radius;
	}
}

/* The body's keys that depend on its shape, and the turning keys that need
 * a body that turns. */
static int body_validate(const bsim_scene *s, const char *who, bsim_error *err)
{
	const bsim_body_def *b = &s->body;
	static const char *const shapes[] = {"disk", "capsule", "ellipse"};
	if (b->shape < BSIM_SHAPE_DISK || b->shape > BSIM_SHAPE_ELLIPSE)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: body.shape: expected disk, capsule or ellipse, got %d",
		                      who, (int)b->shape);
	const char *shape = shapes[b->shape];
	int ellipse = b->shape == BSIM_SHAPE_ELLIPSE;
	if (!ellipse && !(b->radius > 0))
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: body.radius: expected a positive number (the %s's %s), "
		                      "got %g",
		                      who, shape,
		                      b->shape == BSIM_SHAPE_DISK ? "radius" : "half-width",
		                      b->radius);
	if (ellipse && b->radius != 0)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: body.radius: expected none for an ellipse (its size is "
		                      "body.semi_axes), got %g",
		                      who, b->radius);
	if (b->shape == BSIM_SHAPE_CAPSULE && !(b->length > 0))
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: body.length: expected a positive number (the capsule's "
		                      "segment), got %g",
		                      who, b->length);
	if (b->shape != BSIM_SHAPE_CAPSULE && b->length != 0)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: body.length: expected none for a %s (only a capsule has "
		                      "a length), got %g",
		                      who, shape, b->length);
	if (ellipse && !(b->semi_axes[0] > 0 && b->semi_axes[1] > 0))
		return bsim_error_set(
		        err, BSIM_EINPUT,
		        "%s: body.semi_axes: expected two positive numbers [a, b], got "
		        "[%g, %g]",
		        who, b->semi_axes[0], b->semi_axes[1]);
	if (!ellipse && (b->semi_axes[0] != 0 || b->semi_axes[1] != 0))
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: body.semi_axes: expected none for a %s (only an ellipse "
		                      "has semi-axes)",
		                      who, shape);
	if (!b->rotates && b->angular_velocity != 0)
		return bsim_error_set(
		        err, BSIM_EINPUT,
		        "%s: body.angular_velocity: expected 0 for a body that does not "
		        "turn (body.rotates: false), got %g",
		        who, b->angular_velocity);
	if (s->effects.has_drag && s->effects.drag_angular != 0 && !b->rotates)
		return bsim_error_set(
		        err, BSIM_EINPUT,
		        "%s: effects.drag.angular: expected 0 for a body that does not "
		        "turn (body.rotates: false), got %g",
		        who, s->effects.drag_angular);
	return BSIM_OK;
}

int bsim_scene_overlap(const bsim_scene *s, double *dist)
{
	const double *c = s->body.start;
	for (int i = 0; i < s->n_beams; i++) {
		const bsim_beam_def *b = &s->beams[i];
		/* Forward-positive theta moves the tip toward +y: a beam pointing
		 * left (cos(rest) < 0) turns clockwise for positive theta. */
		double u0[2];
		bsim_scene_beam_rest_direction(b, u0);
		double sn = bsim_scene_beam_forward_sign(b) * sin(b->initial_theta);
		double cs = cos(b->initial_theta);
		double ux = u0[0] * cs - u0[1] * sn, uy = u0[1] * cs + u0[0] * sn;
		double dx = c[0] - b->pivot[0], dy = c[1] - b->pivot[1];
		double along = fmin(fmax(dx * ux + dy * uy, 0), b->length);
		double d = hypot(dx - along * ux, dy - along * uy);
		if (s->body.shape != BSIM_SHAPE_DISK) {
			/* The outline (beamsim/body_shape.h), for a beam within the
			 * body's reach; no normal: the beam crosses the body's
			 * centre line. */
			if (!(d < bsim_body_shape_reach(&s->body)))
				continue;
			double tip[2] = {b->pivot[0] + b->length * ux,
			                 b->pivot[1] + b->length * uy};
			bsim_body_segment_contact bc;
			if (bsim_body_shape_segment(&s->body, c, bsim_body_heading(&s->body),
			                            b->pivot, tip, &bc) != BSIM_OK) {
				*dist = 0.0;
				return i;
			}
			if (bc.dist < 0) {
				*dist = bc.dist;
				return i;
			}
			continue;
		}
		if (d < s->body.radius) {
			*dist = d;
			return i;
		}
	}
	return -1;
}

static const char *scene_who(const bsim_scene *s)
{
	if (s->path[0])
		return s->path;
	return s->name[0] ? s->name : "scene";
}

static int check_value(const bsim_scene *s, const scene_field *f, const char *base,
                       const scene_path *at, bsim_error *err)
{
	const char *who = scene_who(s);
	const char *p = base + f->offset;
	double v[2] = {0, 0};
	int n = 1;
	char field[256];
	if (f->kind == SK_INT) {
		int k = *(const int *)p;
		if (k >= (f->range == SR_NONNEG ? 0 : 1))
			return BSIM_OK;
		bsim_scene_path_format(at, field, sizeof field);
		return bsim_error_set(err, BSIM_EINPUT, "%s: %s: expected %s, got %d", who, field,
		                      bsim_scene_phrase(f), k);
	}
	if (f->kind == SK_NAME) {
		if (memchr(p, '\0', sizeof s->name))
			return BSIM_OK;
		bsim_scene_path_format(at, field, sizeof field);
		return bsim_error_set(err, BSIM_EINPUT, "%s: %s: expected %s", who, field,
		                      "a string of at most 127 characters");
	}
	memcpy(v, p, (f->kind == SK_VEC2 ? 2 : 1) * sizeof(double));
	n = f->kind == SK_VEC2 ? 2 : 1;
	for (int i = 0; i < n; i++) {
		if (isfinite(v[i]) && bsim_scene_in_range(f->range, v[i]))
			continue;
		bsim_scene_path_format(at, field, sizeof field);
		if (!isfinite(v[i]))
			return bsim_error_set(err, BSIM_EINPUT,
			                      "%s: %s: expected a finite number, got %g", who,
			                      field, v[i]);
		return bsim_error_set(err, BSIM_EINPUT, "%s: %s: expected %s, got %g", who, field,
		                      bsim_scene_phrase(f), v[i]);
	}
	return BSIM_OK;
}

/* Checks every field of table t over the struct at base, at path at (NULL:
 * the top). Blocks with a presence flag that is 0 are not simulated, so not
 * checked. A path is spelled out only for a message. */
static int check_table(const bsim_scene *s, const scene_table *t, const char *base,
                       const scene_path *at, bsim_error *err)
{
	for (int i = 0; i < t->n_fields; i++) {
		const scene_field *f = &t->fields[i];
		const scene_path field = {at, f->key, 0};
		int rc = BSIM_OK;
		if (f->kind == SK_BLOCK) {
			if (f->offset != SCENE_NO_FLAG && !*(const int *)(base + f->offset))
				continue;
			rc = check_table(s, f->sub, base, &field, err);
		} else if (f->kind == SK_NUMBER || f->kind == SK_INT || f->kind == SK_VEC2 ||
		           f->kind == SK_NAME) {
			rc = check_value(s, f, base, &field, err);
		}
		if (rc)
			return rc;
	}
	return BSIM_OK;
}

/* A lattice's shape must match its beams, and the body must start inside
 * the field (between the sides; below the end). */
static int lattice_validate(const bsim_scene *s, const char *who, bsim_error *err)
{
	const bsim_lattice_def *l = &s->lattice;
	if (l->rows < 1 || l->columns < 1 || l->ix_max - l->ix_min + 1 != l->columns)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: lattice: expected at least one gate (columns = ix_max - "
		                      "ix_min + 1 >= 1, rows >= 1), got %d x %d",
		                      who, l->columns, l->rows);
	if (!(l->width > 0) || !(l->depth > 0) || !isfinite(l->width) || !isfinite(l->depth) ||
	    !isfinite(l->pivot_y))
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: lattice.gate: expected positive width and depth, got %g "
		                      "and %g",
		                      who, l->width, l->depth);
	if ((long)s->n_beams != 2L * l->columns * l->rows)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: lattice: expected %ld beams (2 per gate), got %d", who,
		                      2L * l->columns * l->rows, s->n_beams);
	double centre = 0.5 * l->width * (l->ix_min + l->ix_max);
	if (!(fabs(s->body.start[0] - centre) < s->side_x))
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: body.start: expected a point between the lattice's "
		                      "sides (|x - %g| < side_x = %g), got x = %g",
		                      who, centre, s->side_x, s->body.start[0]);
	return BSIM_OK;
}

int bsim_scene_excess_find(const bsim_scene *s, scene_excess *x)
{
	const bsim_limits *l = bsim_limits_get();
	/* In doubles: the products of valid fields can exceed any integer. */
	/* held: one value per 1/frequency s; ou and white: one per step */
	double values = s->effects.random_model == BSIM_RANDOM_HELD
	                        ? (double)s->max_steps * s->dt * s->effects.random_frequency
	                        : (double)s->max_steps;
	/* Every beam of a lattice counts: the thesis backend's step costs the
	 * beams near the body, but Box2D's visits every body and joint of its
	 * world each step (0.21 s a step on a 333 x 300 field, 199,800 beams),
	 * and the limit holds for any backend. */
	double beam_steps = (double)s->max_steps * (s->n_beams > 0 ? s->n_beams : 1);
	if (s->effects.has_random_force && values > l->schedule) {
		*x = (scene_excess){"effects.random_force.frequency",
		                    "schedule",
		                    values,
		                    l->schedule,
		                    "random-force values per trial (frequency x dt x max_steps)",
		                    0};
		return 1;
	}
	if (beam_steps > l->beam_steps) {
		*x = (scene_excess){"integration.max_steps",
		                    "beam_steps",
		                    beam_steps,
		                    l->beam_steps,
		                    "beam-steps per trial (max_steps x beams)",
		                    s->n_beams};
		return 1;
	}
	return 0;
}

void bsim_scene_excess_detail(const bsim_scene *s, const scene_excess *x, char *buf, size_t size)
{
	if (strcmp(x->limit, "beam_steps") != 0) {
		snprintf(buf, size, "%s", "");
		return;
	}
	if (s->has_lattice)
		snprintf(buf, size, " = %ld steps x %d beams (a %d x %d lattice, 2 beams a gate)",
		         (long)s->max_steps, x->beams, s->lattice.columns, s->lattice.rows);
	else
		snprintf(buf, size, " = %ld steps x %d beams", (long)s->max_steps, x->beams);
}

int bsim_scene_validate(const bsim_scene *s, bsim_error *err)
{
	const char *who = scene_who(s);
	int rc = check_table(s, &bsim_scene_top_table, (const char *)s, NULL, err);
	if (rc)
		return rc;
	if (s->n_beams < 1 || !s->beams)
		return bsim_error_set(err, BSIM_EINPUT, "%s: beams: expected %s, got %d beams", who,
		                      "a non-empty list of beams", s->n_beams);
	const scene_path beams = {NULL, "beams", 0};
	for (int i = 0; i < s->n_beams; i++) {
		const scene_path beam = {&beams, NULL, i};
		rc = check_table(s, &bsim_scene_beam_table, (const char *)&s->beams[i], &beam, err);
		if (rc)
			return rc;
	}
	if (s->has_lattice) {
		rc = lattice_validate(s, who, err);
		if (rc)
			return rc;
	}
	if (s->effects.has_random_force && (s->effects.random_model < BSIM_RANDOM_HELD ||
	                                    s->effects.random_model > BSIM_RANDOM_WHITE))
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: effects.random_force.model: expected held, ou or white, "
		                      "got %d",
		                      who, (int)s->effects.random_model);
	if (s->effects.has_ground_friction && s->effects.ground_model != BSIM_FRICTION_COUPLED &&
	    s->effects.ground_model != BSIM_FRICTION_DECOUPLED)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: effects.ground_friction.model: expected coupled or "
		                      "decoupled, got %d",
		                      who, (int)s->effects.ground_model);
	rc = body_validate(s, who, err);
	if (rc)
		return rc;
	if (s->effects.propulsion_along != BSIM_ALONG_Y &&
	    s->effects.propulsion_along != BSIM_ALONG_HEADING)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: effects.propulsion.along: expected y or heading, got %d",
		                      who, (int)s->effects.propulsion_along);
	if (s->classify_y < s->success_y)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: termination.classify_y: expected a number >= success_y "
		                      "(%g), got %g",
		                      who, s->success_y, s->classify_y);
	double d = 0;
	int beam = bsim_scene_overlap(s, &d);
	if (beam >= 0 && s->body.shape != BSIM_SHAPE_DISK)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: body.start: the body (%s, heading %g deg) overlaps beam "
		                      "%d (beams.%d) at the start (outline's gap %.3g m)",
		                      who,
		                      s->body.shape == BSIM_SHAPE_CAPSULE ? "capsule" : "ellipse",
		                      s->body.heading_deg, beam + 1, beam, d);
	if (beam >= 0)
		return bsim_error_set(
		        err, BSIM_EINPUT,
		        "%s: body.start: the body (radius %g) overlaps beam %d (beams.%d) at "
		        "the start (distance %.3g m)",
		        who, s->body.radius, beam + 1, beam, d);
	scene_dt_bound bound;
	if (bsim_scene_dt_find(s, &bound)) {
		char msg[640];
		bsim_scene_dt_message(s, &bound, msg, sizeof msg);
		return bsim_error_set(err, BSIM_EINPUT, "%s: integration.dt: %s", who, msg);
	}
	scene_excess x;
	if (bsim_scene_excess_find(s, &x)) {
		char hint[160], detail[128];
		bsim_limits_hint(hint, sizeof hint, x.limit, x.max);
		bsim_scene_excess_detail(s, &x, detail, sizeof detail);
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: %s: expected at most %.15g %s, got %.3g%s (%s)", who,
		                      x.field, x.max, x.what, x.got, detail, hint);
	}
	return BSIM_OK;
}

int bsim_scene_copy(bsim_scene *dst, const bsim_scene *src)
{
	*dst = *src;
	dst->beams = NULL;
	dst->n_beams = 0;
	if (src->n_beams <= 0)
		return BSIM_OK;
	dst->beams = malloc((size_t)src->n_beams * sizeof *dst->beams);
	if (!dst->beams)
		return BSIM_EFAIL;
	memcpy(dst->beams, src->beams, (size_t)src->n_beams * sizeof *dst->beams);
	dst->n_beams = src->n_beams;
	return BSIM_OK;
}

void bsim_scene_free(bsim_scene *s)
{
	if (!s)
		return;
	free(s->beams);
	s->beams = NULL;
	s->n_beams = 0;
}

int bsim_scene_set_beams(bsim_scene *s, int n_beams)
{
	if (n_beams < 0)
		return BSIM_EINPUT;
	if (n_beams == 0) {
		bsim_scene_free(s);
		return BSIM_OK;
	}
	bsim_beam_def *b = realloc(s->beams, (size_t)n_beams * sizeof *b);
	if (!b)
		return BSIM_EFAIL;
	if (n_beams > s->n_beams)
		memset(b + s->n_beams, 0, (size_t)(n_beams - s->n_beams) * sizeof *b);
	s->beams = b;
	s->n_beams = n_beams;
	return BSIM_OK;
}
