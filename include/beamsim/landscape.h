/* The potential energy landscape of a scene (MODEL.md section 7, essay
 * Sec. 2.5, Eq. 2.16):
 *
 *   E_total(x, y) = E_prop(y) + E_beam(x, y)
 *   E_prop(y)     = F_prop (y0 - y)
 *   E_beam(x, y)  = sum_i 1/2 k_i th_i(x, y)^2
 *
 * th_i(x, y) is the forward angle of beam i when it rests against a body of
 * radius R centred at (x, y), the beam always attached and deflected
 * forward. With rho, phi the polar coordinates of the centre about the
 * pivot, phi measured from the rest direction, forward positive:
 *
 *   rho <= sqrt(L^2 + R^2)      th = phi + asin(R / rho)                       (tangent)
 *   sqrt(L^2+R^2) < rho < L+R   th = phi + acos((rho^2 + L^2 - R^2) / (2 rho L)) (tip)
 *   rho >= L + R                th = 0
 *   th = max(th, 0)
 *
 * The two branches meet at rho^2 = L^2 + R^2, where the tangent point is
 * the tip. This is the one home of the landscape's math: the runner's
 * e_prop, the landscape label of a trial and `beamsim landscape` use it. */
#ifndef BEAMSIM_LANDSCAPE_H
#define BEAMSIM_LANDSCAPE_H

#include "beamsim/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* th of beam b, rad, against a body of the given radius (m) centred at c
 * (m). A centre closer to the pivot than the radius (the body would cover
 * the pivot) takes the tangent branch with asin clamped at pi/2. */
double bsim_landscape_theta(const bsim_beam_def *b, double radius, const double c[2]);

/* E_prop = F_prop (y0 - y), J: the propulsive potential with its zero at
 * the scene's landscape_y0; 0 if the scene has no propulsion. */
double bsim_landscape_e_prop(const bsim_scene *s, double y);

/* E_total at the body centre c, J. theta (n_beams entries), e_beam and
 * e_prop receive the parts if not NULL. */
double bsim_landscape_energy(const bsim_scene *s, const double c[2], double *theta, double *e_beam,
                             double *e_prop);

#ifdef __cplusplus
}
#endif
#endif
