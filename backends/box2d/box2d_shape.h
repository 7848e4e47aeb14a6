/* Internal: what the Box2D backend's shapes cost in accuracy
 * (backends/box2d/box2d_world.cpp, docs/backends.md "Shapes"). */
#ifndef BSIM_BOX2D_BOX2D_SHAPE_H
#define BSIM_BOX2D_BOX2D_SHAPE_H

#ifdef __cplusplus
extern "C" {
#endif

/* The shape error of the ellipse with semi-axes a, b (m) as the box2d
 * backend builds it at unit_scale s: the relative area error of its
 * outline (*area_rel, Box2D's less the ellipse's over the ellipse's) and
 * the largest distance between the two outlines (*max_dist, m).
 * BSIM_EINPUT if the ellipse is too small for Box2D's skin at s. */
int bsim_box2d_ellipse_error(double a, double b, double s, double *area_rel, double *max_dist);

#ifdef __cplusplus
}
#endif
#endif
