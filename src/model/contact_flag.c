/* The geometry of the contact flag (beamsim/contact_flag.h): a beam's gap to
 * the body, computed the same way for every backend and for the runner's
 * overlap measure (docs/model.md section 3):
 *   s = clamp((C - P) . u, 0, L),  Q = P + s u,  gap = |C - Q| - R,
 *   tangent if 0 < (C - P) . u < L, tip otherwise. */
#include "beamsim/contact_flag.h"

#include <math.h>

#include "beamsim/body_shape.h"

void bsim_beam_direction(const double u0[2], double sgn, double theta, double u[2])
{
	double cs = cos(theta), sn = sgn * sin(theta);
	u[0] = u0[0] * cs - u0[1] * sn;
	u[1] = u0[1] * cs + u0[0] * sn;
}

double bsim_beam_distance(const double p[2], const double u[2], double length, const double x[2],
                          int *type)
{
	double d[2];
	bsim_beam_offset(p, u, length, x, type, d);
	return hypot(d[0], d[1]);
}

int bsim_contact_flag_of(const bsim_body_def *body, const double x[2], double psi,
                         const double p[2], const double u[2], double length, int touched)
{
	int type;
	const double d2 = bsim_beam_distance2(p, u, length, x, &type);
	if (body->shape == BSIM_SHAPE_DISK)
		return bsim_contact_flag(d2, body->radius, type, touched);
	/* the outline: the circle about it decides most steps */
	const double far = bsim_body_shape_reach(body) + BSIM_CONTACT_TOL;
	if (d2 >= far * far && !touched)
		return BSIM_CONTACT_NONE;
	const double tip[2] = {p[0] + length * u[0], p[1] + length * u[1]};
	bsim_body_segment_contact c;
	if (bsim_body_shape_segment(body, x, psi, p, tip, &c) != BSIM_OK)
		return type; /* through its centre line: overlapping */
	type = c.at_end ? BSIM_CONTACT_TIP : BSIM_CONTACT_TANGENT;
	return touched || c.dist < BSIM_CONTACT_TOL ? type : BSIM_CONTACT_NONE;
}
