/* Ground friction over the footprint of a body that turns, the sliding and
 * the spinning coupled (footprint_friction.c; docs/files.md "Ground
 * friction"): the pipeline's effect for effects.ground_friction, model
 * coupled, on a body that rotates. Internal to the library. */
#ifndef BSIM_MODEL_FOOTPRINT_FRICTION_H
#define BSIM_MODEL_FOOTPRINT_FRICTION_H

#include "beamsim/scene.h"
#include "model/footprint_table.h"

/* The footprint under uniform pressure M g / A and its friction limits. A
 * disk's friction is in closed form; a capsule's and an ellipse's come
 * from the table of the rate at which friction dissipates over the
 * twist's direction (footprint_table.h), which depends on the outline
 * alone: kept from one trial to the next of the same outline. */
typedef struct bsim_footprint_friction {
	int shape;                   /* BSIM_SHAPE_* */
	double mass;                 /* kg */
	double inertia;              /* kg m^2 */
	double force_limit;          /* N: mu M g, the friction of a body that only slides */
	double spin_limit;           /* N m: the friction torque of a body that only spins */
	double radius;               /* m: the disk's R */
	bsim_footprint_table *table; /* a capsule's and an ellipse's, NULL for a disk */
} bsim_footprint_friction;

/* The footprint of body (shape, sizes, mass, inertia) on ground friction
 * mu, g (m/s^2); NULL if out of memory. If spare is not NULL it is
 * reused, its table kept if it is the same outline's, or freed. */
bsim_footprint_friction *bsim_footprint_friction_alloc(const bsim_body_def *body, double mu,
                                                       double g, bsim_footprint_friction *spare);
void bsim_footprint_friction_free(bsim_footprint_friction *fr);

/* The friction force (out[0], out[1], N, world frame) and torque (out[2],
 * N m) over a step, given the wrench that would stop the body within it,
 * p = M v / h + f (N, world frame) and q = J omega / h + tau (N m), f and
 * tau the other effects', and the body's heading (rad) at the step's
 * start. The body ends the step at rest if friction can hold p and q
 * (then out = -(p, q)); else out is the friction of the twist it ends the
 * step with (backward Euler). */
void bsim_footprint_friction_wrench(bsim_footprint_friction *fr, double heading, const double p[2],
                                    double q, double out[3]);

/* The friction force (body frame, N) and torque (N m) of a body moving at
 * the twist (v_x, v_y, omega) of its own frame (m/s, rad/s; not 0). */
void bsim_footprint_friction_of_twist(bsim_footprint_friction *fr, const double twist[3],
                                      double out[3]);

#endif
