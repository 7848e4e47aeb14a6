/* Scenes built in code for the physics tests (no files involved). */
#ifndef BSIM_TESTS_SCENES_H
#define BSIM_TESTS_SCENES_H

#include <math.h>

#include "beamsim/scene.h"

/* The essay's gate with no effects at all, body at rest at (0, 0). */
static inline void scene_gate_quiet(bsim_scene *s)
{
	bsim_scene_init_gate(s, 0.0, 0.0);
	s->effects.has_propulsion = 0;
	s->effects.has_random_force = 0;
}

/* One beam along +x from the origin (length 25 m, I = 20.83 kg m^2), no
 * spring or damper, and the body of radius 10 m at rest far away. */
static inline void scene_one_beam(bsim_scene *s)
{
	scene_gate_quiet(s);
	bsim_scene_set_beams(s, 1);
	bsim_beam_def *b = &s->beams[0];
	b->pivot[0] = 0.0;
	b->pivot[1] = 0.0;
	b->rest_angle_deg = 0.0;
	b->length = 25.0;
	b->mass = 0.1;
	b->inertia = 0.1 * 25.0 * 25.0 / 3.0;
	b->stiffness = 0.0;
	b->damping = 0.0;
	s->body.start[0] = 0.0;
	s->body.start[1] = -100.0;
}

/* The damped oscillator I th'' + d th' + k th = 0 (underdamped) from
 * theta(0) = th0 at rest: theta(t). */
static inline double damped_oscillator(double k, double d, double inertia, double th0, double t)
{
	double wn = sqrt(k / inertia), zeta = d / (2.0 * sqrt(k * inertia));
	double wd = wn * sqrt(1.0 - zeta * zeta);
	return th0 * exp(-zeta * wn * t) * (cos(wd * t) + zeta * wn / wd * sin(wd * t));
}

/* The gate with elastic impacts (tangent and tip), springs but no dampers,
 * no effects, and the body launched at (3, 0) with (0.4, 12) m/s: energy
 * is conserved exactly by the model (docs/model.md check 3). */
static inline void scene_gate_conservative(bsim_scene *s)
{
	scene_gate_quiet(s);
	s->contact.restitution = 1.0;
	s->contact.tip_restitution = 1.0;
	s->beams[0].damping = s->beams[1].damping = 0.0;
	s->body.start[0] = 3.0;
	s->body.velocity[0] = 0.4;
	s->body.velocity[1] = 12.0;
}

/* A body of 1e300 kg at 1e4 m/s, 1e6 m below the gate, gaining 2e3 m/s a
 * step (5e305 N along y): its kinetic energy 0.5 M v^2 overflows at 2e4
 * m/s, in the fifth step. */
static inline void scene_gate_overflow(bsim_scene *s)
{
	bsim_scene_init_gate(s, 5e305, 0.0);
	s->body.mass = 1e300;
	s->body.start[1] = -1e6;
	s->body.velocity[1] = 1e4;
	s->side_x = 1e9;
}

/* Six beams at forces f_prop, rm: the gate, a second gate 50 m above it
 * and a pair of 12 m stubs between them (the left one soft), so that a
 * body meets up to three at once. */
static inline int scene_six_beams(bsim_scene *s, double f_prop, double rm)
{
	bsim_scene_init_gate(s, f_prop, rm);
	int rc = bsim_scene_set_beams(s, 6);
	if (rc)
		return rc;
	for (int i = 2; i < 6; i++)
		s->beams[i] = s->beams[i % 2];
	s->beams[2].pivot[1] = s->beams[3].pivot[1] = 80.0;
	s->beams[4].pivot[1] = s->beams[5].pivot[1] = 55.0;
	s->beams[4].length = s->beams[5].length = 12.0;
	s->beams[4].stiffness = 50.0;
	return 0;
}

/* The mirror image of a two-beam scene: x -> -x, so the beams change
 * places and sides (docs/model.md check 4). m is a new scene. */
static inline void scene_mirror(const bsim_scene *s, bsim_scene *m)
{
	bsim_scene_copy(m, s);
	m->body.start[0] = -s->body.start[0];
	m->body.velocity[0] = -s->body.velocity[0];
	for (int i = 0; i < 2; i++) {
		m->beams[i] = s->beams[1 - i];
		m->beams[i].pivot[0] = -s->beams[1 - i].pivot[0];
		m->beams[i].rest_angle_deg = 180.0 - s->beams[1 - i].rest_angle_deg;
	}
}

#endif
