/* The body effects: the essay's constant propulsion along +y (or along the
 * body's heading) and piecewise constant lateral random force (held), with
 * its ou and white variants; a periodic lateral force; viscous drag and
 * ground friction, which read the body's motion and give a force and, on a
 * body that turns, a torque. Each is a pipeline entry only if the scene
 * lists it (beam spring, damping and restitution are the backend's). */
#include "beamsim/effects.h"
#include "model/body_outline.h"
#include "model/footprint_friction.h"
#include "model/schedule_spare.h"

#include <math.h>
#include <string.h>

/* F_prop = (0, F): essay Eq. 2.1. */
static void propulsion_apply(bsim_effect *e, long n, double h, const bsim_state *s, double f[3])
{
	(void)n;
	(void)h;
	(void)s;
	f[1] += e->param;
	e->last = e->param;
}

/* F_rand = (Rm z_j, 0), z_j held for 1/f seconds: essay Eq. 2.3. The
 * steps it holds over are kept, so that bsim_effects_force_at reads it
 * there without a call. */
static void random_force_apply(bsim_effect *e, long n, double h, const bsim_state *s, double f[3])
{
	(void)s;
	double value = bsim_schedule_at_step_held(e->schedule, n, h, e->held);
	e->held_h = h;
	f[0] += value;
	e->last = value;
}

/* White: F_n = Rm / sqrt(f_R h) z_n, a new value each step; its spectrum
 * below 1/(2h) is flat at the held force's low-frequency level 2 Rm^2 / f_R
 * whatever h (docs/files.md "Forcing spectra"). */
static void random_white_apply(bsim_effect *e, long n, double h, const bsim_state *s, double f[3])
{
	(void)s;
	if (h != e->h) {
		e->h = h;
		e->coef[0] = e->param / sqrt(e->coef[1] * h);
	}
	double value = e->coef[0] * bsim_schedule_value(e->schedule, n);
	f[0] += value;
	e->last = value;
}

/* Ornstein-Uhlenbeck, the exact update over a step h (no time-step error):
 *   F_0 = sigma z_0,  F_n = a F_(n-1) + sigma sqrt(1 - a^2) z_n,  a = exp(-h/tau),
 * so F_n ~ N(0, sigma^2) at every step and cov(F_n, F_(n+k)) = sigma^2 a^k =
 * sigma^2 exp(-k h / tau). A step asked for out of order is reached from the
 * nearest earlier one (from step 0 if it lies behind): F_n is a function of
 * the seed and n alone. */
static void random_ou_apply(bsim_effect *e, long n, double h, const bsim_state *s, double f[3])
{
	(void)s;
	if (h != e->h) {
		e->h = h;
		e->coef[0] = exp(-h / e->coef[1]);
		e->at = -1; /* the values are for another h */
	}
	if (n < e->at || e->at < 0) {
		e->value = e->param * bsim_schedule_value(e->schedule, 0);
		e->at = 0;
	}
	const double a = e->coef[0], b = e->param * sqrt(1.0 - a * a);
	while (e->at < n) {
		e->at++;
		e->value = a * e->value + b * bsim_schedule_value(e->schedule, e->at);
	}
	f[0] += e->value;
	e->last = e->value;
}

/* The lateral oscillation A sin(w t + phi), w = 2 pi f, as its mean over
 * the step [t_n, t_n + h]:
 *   F_n = A (cos(w t_n + phi) - cos(w t_n + w h + phi)) / (w h),
 * so the impulse of each step, and a free body's velocity at every step,
 * is the sine's exactly; F_n -> A sin(w t_n + phi) as h -> 0. */
static void oscillation_apply(bsim_effect *e, long n, double h, const bsim_state *s, double f[3])
{
	(void)s;
	const double w = e->coef[0], phi = e->coef[1], t = (double)n * h;
	double value = e->param * (cos(w * t + phi) - cos(w * (t + h) + phi)) / (w * h);
	e->applied[0] = value;
	e->last = value;
	f[0] += value;
}

/* Viscous drag F = -c v, the exact update over a step: on a free body
 * (m dv/dt = -c v) v(t + h) = v(t) exp(-c h / m), so the force that takes v
 * there in one step of the backends' v += h F / m is
 *   F = m v (exp(-c h / m) - 1) / h,
 * -c v to first order in h, never overshooting (v keeps its sign at any
 * c h / m). The forces of the other effects and contacts add to it. */
static void drag_apply(bsim_effect *e, long n, double h, const bsim_state *s, double f[3])
{
	(void)n;
	if (h != e->h) {
		e->h = h;
		e->coef[0] = e->mass * expm1(-e->param * h / e->mass) / h;
	}
	e->applied[0] = e->coef[0] * s->v[0];
	e->applied[1] = e->coef[0] * s->v[1];
	f[0] += e->applied[0];
	f[1] += e->applied[1];
}

/* Drag on a body that turns: the linear part as drag_apply, and the torque
 * -c_w omega by the same exact update (J domega/dt = -c_w omega gives
 * omega(t + h) = omega(t) exp(-c_w h / J); the backends turn the body by
 * omega += h tau / J):
 *   tau = J omega (exp(-c_w h / J) - 1) / h. */
static void drag_turn_apply(bsim_effect *e, long n, double h, const bsim_state *s, double f[3])
{
	if (h != e->h) {
		e->coef_turn = e->inertia * expm1(-e->param_turn * h / e->inertia) / h;
		e->h = NAN; /* drag_apply's coefficient too */
	}
	drag_apply(e, n, h, s, f);
	e->applied_torque = e->coef_turn * s->angular_velocity;
	f[2] += e->applied_torque;
}

/* Coulomb friction with the plane, exact stick/slip. Over a step h the
 * friction impulse is at most mu m g h. Without friction the body would end
 * the step at v* = v + h f / m (f: every other effect's force, which f
 * holds since friction is the pipeline's last). If the impulse that stops it,
 * m v*, is within the cone, |m v / h + f| <= mu m g, the body sticks:
 *   F = -(m v / h + f)           (it ends the step at rest, exactly);
 * else it slides:
 *   F = -mu m g (m v / h + f) / |m v / h + f|.
 * A body at rest under |f| <= mu m g gets F = -f and stays at rest to the
 * bit: no chatter. Contact impulses in the step are not in f. */
static void ground_friction_apply(bsim_effect *e, long n, double h, const bsim_state *s,
                                  double f[3])
{
	(void)n;
	const double m = e->mass, limit = e->coef[0];
	double p[2] = {m * s->v[0] / h + f[0], m * s->v[1] / h + f[1]};
	double size = sqrt(p[0] * p[0] + p[1] * p[1]);
	if (size <= limit) {
		e->applied[0] = -p[0];
		e->applied[1] = -p[1];
	} else {
		e->applied[0] = -limit * p[0] / size;
		e->applied[1] = -limit * p[1] / size;
	}
	f[0] += e->applied[0];
	f[1] += e->applied[1];
}

/* Ground friction on a body that turns, the decoupled model
 * (effects.ground_friction.model: decoupled; Box2D's friction joint's):
 * the sliding friction as ground_friction_apply, and spinning friction
 * with the same exact stick/slip. Under uniform pressure M g / A over the
 * footprint, a body spinning in place meets the friction torque
 *   T = mu (M g / A) integral |r| dA = mu M g r_s
 * (r_s = bsim_effects_spin_arm: 2R/3 for a disk). Over a step the torque
 * that stops the spin is J omega / h + tau (tau: the other effects'); if
 * it is within T the body stops turning exactly, else it gets -T in its
 * direction. Sliding and spinning are taken apart: each has its own full
 * limit (mu M g and T). Exact for a body that only slides (the footprints
 * are centrally symmetric: no torque) or only spins (no net force); when
 * it does both, the true friction of each point opposes that point's
 * velocity v + omega x r and both the force and the torque are smaller
 * than their limits, so here both motions stop sooner than they would
 * (ground_friction_coupled_apply is that friction). */
static void ground_friction_turn_apply(bsim_effect *e, long n, double h, const bsim_state *s,
                                       double f[3])
{
	ground_friction_apply(e, n, h, s, f);
	const double limit = e->param_turn;
	double p = e->inertia * s->angular_velocity / h + f[2];
	e->applied_torque = fabs(p) <= limit ? -p : (p > 0 ? -limit : limit);
	f[2] += e->applied_torque;
}

/* Ground friction on a body that turns, the sliding and the spinning
 * coupled (footprint_friction.c): each patch of the footprint rubs against
 * its own velocity v + omega x r. The same exact stick/slip: the body ends
 * the step at rest when friction can hold the wrench that stops it,
 * (m v / h + f, J omega / h + tau), else it gets the friction of the twist
 * it ends the step with. */
static void ground_friction_coupled_apply(bsim_effect *e, long n, double h, const bsim_state *s,
                                          double f[3])
{
	(void)n;
	const double p[2] = {e->mass * s->v[0] / h + f[0], e->mass * s->v[1] / h + f[1]};
	const double q = e->inertia * s->angular_velocity / h + f[2];
	double w[3];
	bsim_footprint_friction_wrench(e->footprint, s->heading, p, q, w);
	e->applied[0] = w[0];
	e->applied[1] = w[1];
	e->applied_torque = w[2];
	f[0] += w[0];
	f[1] += w[1];
	f[2] += w[2];
}

/* An effect the backend simulates itself (bsim_effects_init_taking): no
 * force from the pipeline; its applied force and torque stay 0, and its
 * loss is the backend's (bsim_step_energy). */
static void taken_apply(bsim_effect *e, long n, double h, const bsim_state *s, double f[3])
{
	(void)e;
	(void)n;
	(void)h;
	(void)s;
	(void)f;
}

/* Propulsion along the heading psi at the step's start, F (cos psi,
 * sin psi): the hovercraft's thrust, which turns with the body. */
static void propulsion_heading_apply(bsim_effect *e, long n, double h, const bsim_state *s,
                                     double f[3])
{
	(void)n;
	(void)h;
	e->applied[0] = e->param * cos(s->heading);
	e->applied[1] = e->param * sin(s->heading);
	e->last = e->param;
	f[0] += e->applied[0];
	f[1] += e->applied[1];
}

/* integral over [p0, p1] of rho(phi)^3 / 3 dphi by Simpson's rule on n
 * (even) intervals: rho is smooth on each piece it is asked for. */
static double rho3_integral(const bsim_body_def *b, double p0, double p1, int n)
{
	const double step = (p1 - p0) / n;
	double sum = 0.0;
	for (int i = 0; i <= n; i++) {
		double phi = p0 + i * step;
		double rho = bsim_body_rho(b, phi);
		double w = (i == 0 || i == n) ? 1.0 : (i % 2 ? 4.0 : 2.0);
		sum += w * rho * rho * rho / 3.0;
	}
	return sum * step / 3.0;
}

/* In polar coordinates about the centre, integral |r| dA = integral over
 * phi of rho(phi)^3 / 3; the shapes are symmetric about both axes, so 4
 * times the quarter [0, pi/2], split where the capsule's side meets its
 * cap (atan(r / l)), where rho's curvature jumps. */
double bsim_effects_spin_arm(const bsim_body_def *b)
{
	const double quarter = 1.57079632679489661923;
	double moment;
	switch (b->shape) {
	case BSIM_SHAPE_CAPSULE: {
		double kink = atan2(b->radius, b->length / 2);
		moment = 4.0 * (rho3_integral(b, 0.0, kink, 2048) +
		                rho3_integral(b, kink, quarter, 2048));
		break;
	}
	case BSIM_SHAPE_ELLIPSE:
		moment = 4.0 * rho3_integral(b, 0.0, quarter, 4096);
		break;
	default:
		return 2.0 * b->radius / 3.0;
	}
	return moment / bsim_body_area(b);
}

static bsim_effect *effects_add(bsim_effects *fx, const char *name,
                                void (*apply)(bsim_effect *, long, double, const bsim_state *,
                                              double[3]),
                                int axis, double param)
{
	bsim_effect *e = &fx->e[fx->n++];
	memset(e, 0, sizeof *e);
	e->name = name;
	e->apply = apply;
	e->axis = axis;
	e->param = param;
	return e;
}

int bsim_effects_friction_takeable(const bsim_scene *scene)
{
	return !scene->body.rotates || scene->effects.ground_model == BSIM_FRICTION_DECOUPLED;
}

int bsim_effects_random(const bsim_scene *scene)
{
	return scene->effects.has_random_force;
}

int bsim_effects_init(bsim_effects *fx, const bsim_scene *scene, uint64_t seed)
{
	return bsim_effects_init_taking(fx, scene, seed, 0u);
}

/* A schedule of magnitude and frequency for seed: spare's, restarted, if
 * it holds one (spare NULL: none), else a new one. */
static bsim_schedule *schedule_for(double magnitude, double frequency, uint64_t seed,
                                   bsim_effects_spare *spare)
{
	if (!spare || !spare->schedule)
		return bsim_schedule_alloc(magnitude, frequency, seed);
	bsim_schedule *s = spare->schedule;
	spare->schedule = NULL;
	bsim_schedule_restart(s, magnitude, frequency, seed);
	return s;
}

int bsim_effects_init_taking(bsim_effects *fx, const bsim_scene *scene, uint64_t seed,
                             unsigned taken)
{
	return bsim_effects_init_spare(fx, scene, seed, taken, NULL);
}

int bsim_effects_init_spare(bsim_effects *fx, const bsim_scene *scene, uint64_t seed,
                            unsigned taken, bsim_effects_spare *spare)
{
	memset(fx, 0, sizeof *fx);
	const bsim_effects_def *d = &scene->effects;
	const int turns = scene->body.rotates;
	if (d->has_propulsion && d->propulsion_along == BSIM_ALONG_Y)
		effects_add(fx, "propulsion", propulsion_apply, 1, d->propulsion_force)->kind =
		        BSIM_EFFECT_CONSTANT;
	if (d->has_random_force) {
		bsim_effect *e;
		if (d->random_model == BSIM_RANDOM_OU) {
			e = effects_add(fx, "random_force", random_ou_apply, 0,
			                d->random_magnitude);
			e->coef[1] = d->random_correlation_time;
			e->at = -1;
		} else if (d->random_model == BSIM_RANDOM_WHITE) {
			e = effects_add(fx, "random_force", random_white_apply, 0,
			                d->random_magnitude);
			e->coef[1] = d->random_frequency;
		} else {
			e = effects_add(fx, "random_force", random_force_apply, 0,
			                d->random_magnitude);
			e->kind = BSIM_EFFECT_HELD;
		}
		/* ou and white scale z_n themselves: the schedule gives z_n, one per step */
		e->schedule = d->random_model == BSIM_RANDOM_HELD
		                      ? schedule_for(d->random_magnitude, d->random_frequency, seed,
		                                     spare)
		                      : schedule_for(1.0, d->random_frequency, seed, spare);
		if (!e->schedule) {
			fx->n--;
			return BSIM_EFAIL;
		}
		fx->random = e;
	}
	fx->n_work = fx->n;
	if (d->has_propulsion && d->propulsion_along == BSIM_ALONG_HEADING) {
		/* its work is booked from its force: after the random force, whose
		 * force is along x only, so that the sum is the same */
		fx->heading = effects_add(fx, "propulsion", propulsion_heading_apply, 1,
		                          d->propulsion_force);
	}
	if (d->has_oscillation) {
		bsim_effect *e =
		        effects_add(fx, "oscillation", oscillation_apply, 0, d->osc_amplitude);
		e->coef[0] = 2.0 * 3.14159265358979323846 * d->osc_frequency;
		e->coef[1] = d->osc_phase;
		fx->oscillation = e;
	}
	if (d->has_drag) { /* after the forces that do work: they book losses */
		int angular = turns && d->drag_angular != 0;
		bsim_effect *e = effects_add(fx, "drag", angular ? drag_turn_apply : drag_apply, 0,
		                             d->drag_linear);
		e->mass = scene->body.mass;
		e->inertia = bsim_body_inertia(&scene->body);
		e->param_turn = d->drag_angular;
		if (taken & BSIM_TAKES_DRAG) {
			e->apply = taken_apply;
			e->taken = 1;
		}
		fx->drag = e;
	}
	if (d->has_ground_friction) { /* the last: it reads the others' forces */
		const int coupled = turns && d->ground_model == BSIM_FRICTION_COUPLED;
		bsim_effect *e = effects_add(fx, "ground_friction",
		                             coupled ? ground_friction_coupled_apply
		                             : turns ? ground_friction_turn_apply
		                                     : ground_friction_apply,
		                             0, d->ground_mu);
		e->mass = scene->body.mass;
		e->coef[0] = d->ground_mu * scene->body.mass * d->ground_g;
		if (turns) {
			e->inertia = bsim_body_inertia(&scene->body);
			e->param_turn = e->coef[0] * bsim_effects_spin_arm(&scene->body);
		}
		if (coupled) {
			bsim_footprint_friction *kept = spare ? spare->footprint : NULL;
			if (spare)
				spare->footprint = NULL;
			e->footprint = bsim_footprint_friction_alloc(&scene->body, d->ground_mu,
			                                             d->ground_g, kept);
			if (!e->footprint) {
				bsim_effects_free_spare(fx, spare);
				return BSIM_EFAIL;
			}
		}
		if ((taken & BSIM_TAKES_GROUND_FRICTION) && bsim_effects_friction_takeable(scene)) {
			e->apply = taken_apply;
			e->taken = 1;
		}
		fx->friction = e;
	}
	return BSIM_OK;
}

int bsim_effects_status(const bsim_effects *fx, bsim_error *err)
{
	return fx->random ? bsim_schedule_status(fx->random->schedule, err) : BSIM_OK;
}

void bsim_effects_free(bsim_effects *fx)
{
	bsim_effects_free_spare(fx, NULL);
}

void bsim_effects_free_spare(bsim_effects *fx, bsim_effects_spare *spare)
{
	for (int i = 0; i < fx->n; i++) {
		if (spare && fx->e[i].footprint) {
			bsim_footprint_friction_free(spare->footprint);
			spare->footprint = fx->e[i].footprint;
		} else {
			bsim_footprint_friction_free(fx->e[i].footprint);
		}
		if (spare && fx->e[i].schedule) {
			bsim_schedule_free(spare->schedule);
			spare->schedule = fx->e[i].schedule;
			bsim_schedule_keep(spare->schedule);
		} else {
			bsim_schedule_free(fx->e[i].schedule);
		}
	}
	memset(fx, 0, sizeof *fx);
}

void bsim_effects_spare_free(bsim_effects_spare *spare)
{
	bsim_schedule_free(spare->schedule);
	bsim_footprint_friction_free(spare->footprint);
	spare->schedule = NULL;
	spare->footprint = NULL;
}
