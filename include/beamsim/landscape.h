/* The potential energy landscape of a scene (docs/model.md section 7, essay
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
#ifndef BSIM_LANDSCAPE_H
#define BSIM_LANDSCAPE_H

#include "beamsim/base.h"
#include "beamsim/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* th of beam b, rad, against a body of the given radius (m) centred at c
 * (m). A centre closer to the pivot than the radius (the body would cover
 * the pivot) takes the tangent branch with asin clamped at pi/2. */
BSIM_API double bsim_landscape_theta(const bsim_beam_def *b, double radius, const double c[2]);

/* E_prop = F_prop (y0 - y), J: the propulsive potential with its zero at
 * the scene's landscape_y0; 0 if the scene has no propulsion. */
BSIM_API double bsim_landscape_e_prop(const bsim_scene *s, double y);

/* E_total at the body centre c, J. theta (n_beams entries), e_beam and
 * e_prop receive the parts if not NULL. */
BSIM_API double bsim_landscape_energy(const bsim_scene *s, const double c[2], double *theta,
                                      double *e_beam, double *e_prop);

/* 1 if a body of the given radius centred at c lies within beam b's reach,
 * rho < L + R (the disc where th can be non-zero), else 0. */
BSIM_API int bsim_landscape_beam_reach(const bsim_beam_def *b, double radius, const double c[2]);

/* 1 if the body centred at c lies within any beam's reach. */
BSIM_API int bsim_landscape_in_reach(const bsim_scene *s, const double c[2]);

/* The beam whose barrier a body centred at c is on: among the beams with
 * touching[i] != 0 (all beams if touching is NULL), the one holding the
 * most spring energy 1/2 k th(c)^2 (0-based); -1 if none of them is
 * deflected or two hold the same largest energy (the exact midline of a
 * symmetric gate).
 *
 * The landscape label of a traversing trial is this beam at the last step
 * before success_y at which the body touched any beam, counting only the
 * beams it touched then: the barrier it came off last. Beams not touching
 * the body are left out because the landscape assumes every beam within
 * reach is pushed, and a body that has crossed one beam often runs on
 * through the reach of the other, still at rest (the essay's trajectory
 * "below the surface", Fig. 2.7). The barrier search labels exits with
 * touching NULL: on the landscape every beam within reach is attached. */
BSIM_API int bsim_landscape_label(const bsim_scene *s, const double c[2], const int *touching);

/* ---- The landscape on a grid ------------------------------------------ */

/* Where to sample. The default region is the arena a trial runs in:
 * x in [-side_x, side_x], y from the body's start to success_y (for the
 * essay's gate [-25, 25] x [0, 65] m, the gate region with the beams'
 * whole reach in front of the success line). */
typedef struct bsim_landscape_grid_def {
	int has_region;   /* 0: the default region */
	double region[4]; /* x0, x1, y0, y1, m, x0 < x1, y0 < y1 */
	double spacing;   /* m, > 0; 0: the region's longer side / 260 (0.25 m on the gate) */
} bsim_landscape_grid_def;

/* The default region at the default spacing. */
BSIM_API bsim_landscape_grid_def bsim_landscape_grid_def_default(void);

/* The landscape sampled at (x0 + i spacing, y0 + j spacing), i < nx,
 * j < ny; point (i, j) is entry k = j nx + i (x varies fastest). */
typedef struct bsim_landscape_grid {
	double x0, y0, spacing; /* m */
	double region[4];       /* the region asked for, m */
	int nx, ny, n_beams;
	double *e_total, *e_beam, *e_prop; /* J, nx ny entries each */
	double *theta;                     /* rad, beam b at point k: theta[b nx ny + k] */
} bsim_landscape_grid;

/* Most points a grid may have (memory: about 8 (n_beams + 5) bytes each). */
#define BSIM_LANDSCAPE_MAX_POINTS 4000000

/* Samples the landscape of s. BSIM_EINPUT for a bad region or spacing
 * (empty, non-finite, under 3 points a side, over BSIM_LANDSCAPE_MAX_POINTS),
 * naming the field; BSIM_EFAIL out of memory. */
BSIM_API int bsim_landscape_grid_alloc(const bsim_scene *s, const bsim_landscape_grid_def *def,
                                       bsim_landscape_grid **out, bsim_error *err);
BSIM_API void bsim_landscape_grid_free(bsim_landscape_grid *g);

#ifdef __cplusplus
}
#endif
#endif
