/* The outline's distance from a body's centre along a direction of its
 * frame (the heading along +x), for the sums over its footprint in polar
 * coordinates (effects.c). Internal to the library. */
#ifndef BSIM_MODEL_BODY_OUTLINE_H
#define BSIM_MODEL_BODY_OUTLINE_H

#include <math.h>

#include "beamsim/scene.h"

/* A capsule of half-segment l and radius r meets the ray at angle phi on
 * its side y = r (at r / sin phi) if that point lies within the segment's
 * span, else on its end cap. Its curvature jumps at phi = atan(r / l). */
static inline double bsim_capsule_rho(double l, double r, double phi)
{
	double c = fabs(cos(phi)), sn = fabs(sin(phi));
	if (r * c <= l * sn)
		return r / sn;
	return l * c + sqrt(r * r - l * l * sn * sn);
}

static inline double bsim_ellipse_rho(double a, double b, double phi)
{
	return a * b / hypot(b * cos(phi), a * sin(phi));
}

/* The capsule's or the ellipse's rho(phi). */
static inline double bsim_body_rho(const bsim_body_def *b, double phi)
{
	return b->shape == BSIM_SHAPE_CAPSULE
	               ? bsim_capsule_rho(b->length / 2, b->radius, phi)
	               : bsim_ellipse_rho(b->semi_axes[0], b->semi_axes[1], phi);
}

#endif
