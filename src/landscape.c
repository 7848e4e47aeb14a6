/* The potential energy landscape (beamsim/landscape.h, MODEL.md section 7).
 *
 * phi is computed from the centre's components along the rest direction u0
 * and along the forward normal sgn * perp(u0), so that a mirrored beam (u0
 * and sgn both negated in x) gives the same two components bit for bit and
 * the landscape of a symmetric gate is exactly mirror symmetric. */
#include "beamsim/landscape.h"

#include <math.h>

double bsim_landscape_theta(const bsim_beam_def *b, double radius, const double c[2])
{
	double u0[2];
	bsim_beam_rest_direction(b, u0);
	const double sgn = bsim_beam_forward_sign(b);
	const double dx = c[0] - b->pivot[0], dy = c[1] - b->pivot[1];
	const double along = u0[0] * dx + u0[1] * dy;       /* rho cos(phi) */
	const double fwd = sgn * (u0[0] * dy - u0[1] * dx); /* rho sin(phi) */
	const double rho = sqrt(along * along + fwd * fwd);
	const double L = b->length, R = radius;
	if (rho >= L + R)
		return 0.0;
	const double phi = atan2(fwd, along);
	double th;
	if (rho * rho <= L * L + R * R)
		th = phi + (R >= rho ? 1.5707963267948966 : asin(R / rho));
	else
		th = phi + acos(fmin(1.0, (rho * rho + L * L - R * R) / (2.0 * rho * L)));
	return th > 0.0 ? th : 0.0;
}

double bsim_landscape_e_prop(const bsim_scene *s, double y)
{
	if (!s->effects.has_propulsion)
		return 0.0;
	return s->effects.propulsion_force * (s->landscape_y0 - y);
}

double bsim_landscape_energy(const bsim_scene *s, const double c[2], double *theta, double *e_beam,
                             double *e_prop)
{
	double eb = 0.0;
	for (int i = 0; i < s->n_beams; i++) {
		double th = bsim_landscape_theta(&s->beams[i], s->body.radius, c);
		if (theta)
			theta[i] = th;
		eb += 0.5 * s->beams[i].stiffness * th * th;
	}
	double ep = bsim_landscape_e_prop(s, c[1]);
	if (e_beam)
		*e_beam = eb;
	if (e_prop)
		*e_prop = ep;
	return ep + eb;
}
