/* Scenes built in code for the physics tests (no files involved). */
#ifndef BSIM_TEST_SCENES_H
#define BSIM_TEST_SCENES_H

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

#endif
