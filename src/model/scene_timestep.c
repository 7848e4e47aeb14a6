/* The time step a scene can be resolved at (docs/model.md "The time
 * step"): bounds on integration.dt from the scene's own time scales, the
 * same for every backend. A longer step does not fail loudly: the essay's
 * solver books its energy exactly whatever dt, so a step of 12 s runs and
 * reports a side exit 1.5 km away. Each bound is where the model stops
 * being represented at all, generous for accuracy (docs/accuracy.md
 * measures that):
 *
 *   held random force   dt <= 1/f          a value must hold for a step,
 *                                          else draws are skipped and the
 *                                          force's low-frequency power
 *                                          grows as f dt
 *   ou random force     dt <= tau          successive values still
 *                                          correlated (exp(-1)); beyond,
 *                                          the steps' values are a held
 *                                          force of hold dt
 *   white random force  none of its own    defined per step, flat to
 *                                          1/(2 dt) whatever dt
 *   oscillation         dt < 1/(2 f)       Nyquist: at half the period a
 *                                          step's mean can vanish
 *   a beam's spring     dt <= pi sqrt(I/k) half the natural period
 *                                          (Nyquist)
 *   a beam's damper     dt <= 2 I / d      the midpoint rule's damping
 *                                          factor (1 - h d/2I)/(1 + h d/2I)
 *                                          turns negative beyond, and an
 *                                          explicit damper's 1 - h d/I
 *                                          passes -1
 *   the body's crossing dt <= r / v        a step moves the body at most
 *                                          its half-width (or a beam's
 *                                          length, if shorter) at the
 *                                          scene's speed scale v */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "beamsim/body_shape.h"
#include "model/scene_internal.h"

#define BSIM_PI 3.14159265358979323846

/* A step within this relative distance of a bound is on it: 1 / 50 Hz is
 * the double nearest 0.02, but a bound computed through sqrt need not be
 * the double a user writes for it. */
#define DT_ROUNDING 1e-12

static void bound_paths(scene_dt_bound *b, const char *const *paths, int n, int beam)
{
	b->n_paths = 0;
	for (int i = 0; i < n && b->n_paths < SCENE_DT_PATHS; i++)
		snprintf(b->paths[b->n_paths++], sizeof b->paths[0], paths[i], beam);
}

/* The random force and the oscillation: the forcing must be representable
 * at steps of dt. */
static int forcing_bounds(const bsim_scene *s, scene_dt_bound *out, int describe)
{
	const bsim_effects_def *e = &s->effects;
	int n = 0;
	if (e->has_random_force && e->random_model == BSIM_RANDOM_HELD) {
		scene_dt_bound *b = &out[n++];
		*b = (scene_dt_bound){.max = 1.0 / e->random_frequency};
		if (describe) {
			snprintf(b->what, sizeof b->what, "the random force's hold 1/f, f = %g Hz",
			         e->random_frequency);
			static const char *const p[] = {"effects.random_force.frequency",
			                                "effects.random_force.model"};
			bound_paths(b, p, 2, 0);
		}
	}
	if (e->has_random_force && e->random_model == BSIM_RANDOM_OU) {
		scene_dt_bound *b = &out[n++];
		*b = (scene_dt_bound){.max = e->random_correlation_time};
		if (describe) {
			snprintf(b->what, sizeof b->what,
			         "the ou random force's correlation time tau = %g s",
			         e->random_correlation_time);
			static const char *const p[] = {"effects.random_force.correlation_time",
			                                "effects.random_force.model"};
			bound_paths(b, p, 2, 0);
		}
	}
	if (e->has_oscillation) {
		scene_dt_bound *b = &out[n++];
		*b = (scene_dt_bound){.max = 0.5 / e->osc_frequency, .strict = 1};
		if (describe) {
			snprintf(b->what, sizeof b->what,
			         "half the oscillation's period 1/(2f), f = %g Hz (Nyquist)",
			         e->osc_frequency);
			static const char *const p[] = {"effects.oscillation.frequency"};
			bound_paths(b, p, 1, 0);
		}
	}
	return n;
}

/* The beams' spring and damper: the tightest beam of each. */
static int beam_bounds(const bsim_scene *s, scene_dt_bound *out, int describe)
{
	int spring = -1, damper = -1;
	double t_spring = INFINITY, t_damper = INFINITY;
	for (int i = 0; i < s->n_beams; i++) {
		const bsim_beam_def *d = &s->beams[i];
		double t = d->stiffness > 0 ? BSIM_PI * sqrt(d->inertia / d->stiffness) : INFINITY;
		if (t < t_spring) {
			t_spring = t;
			spring = i;
		}
		t = d->damping > 0 ? 2.0 * d->inertia / d->damping : INFINITY;
		if (t < t_damper) {
			t_damper = t;
			damper = i;
		}
	}
	/* A lattice's beams come from its beam: block and stiffness maps. */
	static const char *const beam_p[] = {"beams.%d.stiffness", "beams.%d.inertia",
	                                     "beams.%d.mass", "beams.%d.length"};
	static const char *const lattice_p[] = {"lattice.beam.stiffness", "lattice.beam.inertia",
	                                        "lattice.beam.mass", "lattice.beam.length",
	                                        "lattice.stiffness"};
	int n = 0;
	if (spring >= 0) {
		const bsim_beam_def *d = &s->beams[spring];
		scene_dt_bound *b = &out[n++];
		*b = (scene_dt_bound){.max = t_spring};
		if (describe) {
			snprintf(b->what, sizeof b->what,
			         "half the natural period pi sqrt(I/k) of beam %d (beams.%d), I = "
			         "%g kg "
			         "m^2, k = %g N m/rad",
			         spring + 1, spring, d->inertia, d->stiffness);
			if (s->has_lattice)
				bound_paths(b, lattice_p, 5, 0);
			else
				bound_paths(b, beam_p, 4, spring);
		}
	}
	if (damper >= 0) {
		const bsim_beam_def *d = &s->beams[damper];
		scene_dt_bound *b = &out[n++];
		*b = (scene_dt_bound){.max = t_damper};
		if (describe) {
			snprintf(b->what, sizeof b->what,
			         "twice the damping time 2 I/d of beam %d (beams.%d), I = %g kg "
			         "m^2, d = %g "
			         "N m s/rad",
			         damper + 1, damper, d->inertia, d->damping);
			static const char *const beam_d[] = {"beams.%d.damping", "beams.%d.inertia",
			                                     "beams.%d.mass", "beams.%d.length"};
			static const char *const lattice_d[] = {
			        "lattice.beam.damping", "lattice.beam.inertia", "lattice.beam.mass",
			        "lattice.beam.length"};
			bound_paths(b, s->has_lattice ? lattice_d : beam_d, 4, damper);
		}
	}
	return n;
}

/* The body's narrowest half-width: a disk's radius, a capsule's, an
 * ellipse's smaller semi-axis. */
static double body_half_width(const bsim_body_def *b)
{
	if (b->shape == BSIM_SHAPE_ELLIPSE)
		return fmin(b->semi_axes[0], b->semi_axes[1]);
	return b->radius;
}

void bsim_scene_speed_scale(const bsim_scene *s, scene_speed *v)
{
	const bsim_effects_def *e = &s->effects;
	const bsim_body_def *body = &s->body;
	memset(v, 0, sizeof *v);
	v->start = hypot(body->velocity[0], body->velocity[1]);
	double f = (e->has_propulsion ? fabs(e->propulsion_force) : 0) +
	           (e->has_random_force ? e->random_magnitude : 0) +
	           (e->has_oscillation ? fabs(e->osc_amplitude) : 0);
	v->accel = f / body->mass;
	/* The run the body has before it meets its last beam: beyond the
	 * farthest point a beam reaches, its speed meets nothing. A lattice
	 * repeats its gates, so the next row or column of beams is a gate's
	 * depth or width away whatever the field's size. */
	if (s->has_lattice) {
		v->distance = fmax(s->lattice.depth, s->lattice.width);
	} else {
		for (int i = 0; i < s->n_beams; i++) {
			const bsim_beam_def *d = &s->beams[i];
			double far =
			        hypot(d->pivot[0] - body->start[0], d->pivot[1] - body->start[1]) +
			        d->length;
			v->distance = fmax(v->distance, far);
		}
	}
	v->forces = v->accel > 0 ? sqrt(2.0 * v->accel * v->distance) : 0.0;
	if (e->has_drag && e->drag_linear > 0 && f / e->drag_linear < v->forces) {
		v->forces = f / e->drag_linear;
		v->drag_capped = 1;
	}
	v->spin = body->rotates ? fabs(body->angular_velocity) * bsim_body_shape_reach(body) : 0;
	for (int i = 0; i < s->n_beams; i++) {
		const bsim_beam_def *d = &s->beams[i];
		double w2 = d->initial_omega * d->initial_omega +
		            d->stiffness * d->initial_theta * d->initial_theta / d->inertia;
		v->tips = fmax(v->tips, d->length * sqrt(w2));
	}
	v->total = v->start + v->forces + v->spin + v->tips;
}

static int crossing_bound(const bsim_scene *s, scene_dt_bound *b, int describe)
{
	scene_speed v;
	bsim_scene_speed_scale(s, &v);
	if (!(v.total > 0))
		return 0;
	double size = body_half_width(&s->body);
	int shortest = -1;
	for (int i = 0; i < s->n_beams; i++)
		if (s->beams[i].length < size) {
			size = s->beams[i].length;
			shortest = i;
		}
	*b = (scene_dt_bound){.max = size / v.total};
	if (!describe)
		return 1;
	char whose[64], extra[96] = "";
	if (shortest >= 0)
		snprintf(whose, sizeof whose, "beam %d's length", shortest + 1);
	else
		snprintf(whose, sizeof whose, "its half-width");
	if (v.spin > 0 || v.tips > 0)
		snprintf(extra, sizeof extra, " + spin %.3g m/s + beam tips %.3g m/s", v.spin,
		         v.tips);
	snprintf(b->what, sizeof b->what,
	         "the body's crossing: %s %g m at the scene's speed %.3g m/s = start %g m/s + "
	         "forces %.3g m/s (%.3g m/s^2 over %.3g m%s)%s",
	         whose, size, v.total, v.start, v.forces, v.accel, v.distance,
	         v.drag_capped ? ", capped at the drag's F/c" : "", extra);
	static const char *const p[] = {"body.velocity",
	                                "body.velocity.0",
	                                "body.velocity.1",
	                                "body.mass",
	                                "body.radius",
	                                "body.semi_axes",
	                                "body.angular_velocity",
	                                "body.start",
	                                "effects.propulsion.force",
	                                "effects.random_force.magnitude",
	                                "effects.oscillation.amplitude",
	                                "effects.drag.linear"};
	bound_paths(b, p, 12, 0);
	return 1;
}

/* The bounds, each with its description and fields where describe (only
 * a bound a step breaks needs them: a scene checked costs no text). */
static int dt_bounds(const bsim_scene *s, scene_dt_bound out[SCENE_DT_BOUNDS], int describe)
{
	int n = forcing_bounds(s, out, describe);
	n += beam_bounds(s, out + n, describe);
	n += crossing_bound(s, out + n, describe);
	return n;
}

int bsim_scene_dt_bounds(const bsim_scene *s, scene_dt_bound out[SCENE_DT_BOUNDS])
{
	return dt_bounds(s, out, 1);
}

static int dt_breaks(double dt, const scene_dt_bound *b)
{
	double max = b->max * (1 + DT_ROUNDING);
	return b->strict ? !(dt < b->max * (1 - DT_ROUNDING)) : !(dt <= max);
}

int bsim_scene_dt_find(const bsim_scene *s, scene_dt_bound *broken)
{
	scene_dt_bound all[SCENE_DT_BOUNDS];
	int n = dt_bounds(s, all, 0), found = -1;
	for (int i = 0; i < n; i++)
		if (dt_breaks(s->dt, &all[i]) && (found < 0 || all[i].max < all[found].max))
			found = i;
	if (found < 0)
		return 0;
	dt_bounds(s, all, 1); /* the same bounds, described */
	*broken = all[found];
	return 1;
}

/* x rounded down to 4 significant digits, so that the bound a message
 * states is a step the scene accepts. */
static double floor_4(double x)
{
	if (!(x > 0) || !isfinite(x))
		return x;
	double p = pow(10.0, floor(log10(x)) - 3);
	double r = floor(x / p) * p;
	/* x / p may round up past a whole number: 0.02 stays 0.02 */
	return fabs(r + p - x) <= DT_ROUNDING * x ? r + p : r;
}

void bsim_scene_dt_message(const bsim_scene *s, const scene_dt_bound *b, char *buf, size_t size)
{
	snprintf(buf, size, "expected %s %.4g s (%s), got %g", b->strict ? "less than" : "at most",
	         floor_4(b->max), b->what, s->dt);
}
