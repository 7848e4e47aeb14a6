/* The contact flag (bsim_state.contact, beamsim/state.h; the trajectory's
 * contact columns) and the geometry of a beam's gap behind it. The runner
 * defines the flag and computes it, from the raw facts a backend reports
 * (bsim_contact_flags): no backend computes it, and every backend gets the
 * same rule. A backend may use the same functions for what it decides
 * itself (which beams to list as active, or to keep awake).
 *
 * Beam i is in contact during a step when, at the step's end,
 *   gap_i = |C - Q_i| - R < BSIM_CONTACT_TOL        (beamsim/state.h, 6 mm)
 * (C the body's centre, Q_i the nearest point of the beam's segment, R the
 * body's radius: docs/model.md section 3), or the beam exchanged a nonzero
 * normal impulse with the body during the step (touched_i). The flag's
 * value is the contact's type at the step's end: TANGENT when the nearest
 * point lies inside the segment, TIP at either end. For a body that is not
 * a disk the gap is the outline's (bsim_body_shape_segment,
 * beamsim/body_shape.h), the type where the outline's nearest point of the
 * segment lies, and a segment through the body's centre line (no
 * separating normal) is in contact with the type the centre's nearest
 * point gives.
 *
 * For beam i with pivot p and length L at the step's end, direction u
 * (bsim_beam_direction of its rest direction u0, forward sign sgn and
 * angle theta; the state's direction):
 *   d2 = bsim_beam_distance2(p, u, L, x, &type);
 *   contact[i] = bsim_contact_flag(d2, R, type, touched_i);      (a disk) */
#ifndef BSIM_CONTACT_FLAG_H
#define BSIM_CONTACT_FLAG_H

#include "beamsim/base.h"
#include "beamsim/scene.h"
#include "beamsim/state.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The direction of a beam at angle theta, rest direction u0 and forward
 * sign sgn (bsim_scene_beam_rest_direction, bsim_scene_beam_forward_sign):
 * u = R(sgn theta) u0. */
BSIM_API void bsim_beam_direction(const double u0[2], double sgn, double theta, double u[2]);

/* C - Q for a body's centre x against the segment from the pivot p along
 * u of the given length, in d; *type the contact's type there
 * (BSIM_CONTACT_TANGENT or _TIP). Inline: the backends ask it every step. */
static inline void bsim_beam_offset(const double p[2], const double u[2], double length,
                                    const double x[2], int *type, double d[2])
{
	double dx = x[0] - p[0], dy = x[1] - p[1];
	double s = dx * u[0] + dy * u[1];
	*type = s > 0.0 && s < length ? BSIM_CONTACT_TANGENT : BSIM_CONTACT_TIP;
	double along = s > 0.0 ? (s < length ? s : length) : 0.0;
	d[0] = dx - along * u[0];
	d[1] = dy - along * u[1];
}

/* |C - Q|^2, m^2: the squared distance of the centre from the segment. */
static inline double bsim_beam_distance2(const double p[2], const double u[2], double length,
                                         const double x[2], int *type)
{
	double d[2];
	bsim_beam_offset(p, u, length, x, type, d);
	return d[0] * d[0] + d[1] * d[1];
}

/* |C - Q|, m, the same distance (hypot: no overflow, for the runner's
 * overlap measure). */
BSIM_API double bsim_beam_distance(const double p[2], const double u[2], double length,
                                   const double x[2], int *type);

/* The flag of a beam at squared distance dist2 (bsim_beam_distance2) from
 * the centre of a body of radius R at the step's end: type if the gap
 * |C - Q| - R is below BSIM_CONTACT_TOL (|C - Q|^2 < (R + tol)^2, no square
 * root in every step) or pushed (a nonzero impulse in the step), else
 * BSIM_CONTACT_NONE. */
static inline int bsim_contact_flag(double dist2, double radius, int type, int pushed)
{
	const double reach = radius + BSIM_CONTACT_TOL;
	return pushed || dist2 < reach * reach ? type : BSIM_CONTACT_NONE;
}

/* The flag of a beam (pivot p, direction u, length) against a body of
 * any shape at centre x with heading psi (rad), touched in the step or
 * not: the rule above, the outline's gap for a shape that is not a disk. */
BSIM_API int bsim_contact_flag_of(const bsim_body_def *body, const double x[2], double psi,
                                  const double p[2], const double u[2], double length, int touched);

/* The contact flag of beam i, one that state s lists as active, from s's
 * raw facts (x, heading, touched, direction) and the beams of scene, the
 * scene of the world that reported s: a beam whose direction is NaN (apart,
 * the backend says) is in contact only if touched. Inline: the runner asks
 * it of the beams of the states it books. */
static inline int bsim_contact_flag_in(const bsim_scene *scene, const bsim_state *s, int i)
{
	const double *u = &s->direction[2 * i];
	if (u[0] != u[0] && !s->touched[i])
		return BSIM_CONTACT_NONE;
	const bsim_beam_def *b = &scene->beams[i];
	if (scene->body.shape != BSIM_SHAPE_DISK)
		return bsim_contact_flag_of(&scene->body, s->x, s->heading, b->pivot, u, b->length,
		                            s->touched[i]);
	int type;
	const double d2 = bsim_beam_distance2(b->pivot, u, b->length, s->x, &type);
	return bsim_contact_flag(d2, scene->body.radius, type, s->touched[i]);
}

/* bsim_contact_flag_in of every beam s lists as active, into s->contact.
 * The runner calls it on the states whose flags it reports; a caller
 * stepping a world itself calls it for the flags. Inline, as the rule. */
static inline void bsim_contact_flags(const bsim_scene *scene, bsim_state *s)
{
	for (int k = 0; k < s->n_active; k++)
		s->contact[s->active[k]] = bsim_contact_flag_in(scene, s, s->active[k]);
}

#ifdef __cplusplus
}
#endif
#endif
