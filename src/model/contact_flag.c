/* The geometry of the contact flag (beamsim/contact_flag.h): a beam's gap to
 * the body, computed the same way for every backend and for the runner's
 * overlap measure (docs/model.md section 3):
 *   s = clamp((C - P) . u, 0, L),  Q = P + s u,  gap = |C - Q| - R,
 *   tangent if 0 < (C - P) . u < L, tip otherwise. */
#include "beamsim/contact_flag.h"

#include <math.h>

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
