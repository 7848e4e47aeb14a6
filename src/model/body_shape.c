/* The body's outline against a segment (model/body_shape.h). */
#include "model/body_shape.h"

#include <math.h>

/* The point of segment p0-p1 nearest q, and whether it is an end. */
static void segment_nearest(const double p0[2], const double p1[2], const double q[2],
                            double out[2], int *at_end)
{
	double d[2] = {p1[0] - p0[0], p1[1] - p0[1]};
	double t = ((q[0] - p0[0]) * d[0] + (q[1] - p0[1]) * d[1]) / (d[0] * d[0] + d[1] * d[1]);
	*at_end = !(t > 0.0 && t < 1.0);
	t = fmin(fmax(t, 0.0), 1.0);
	out[0] = p0[0] + t * d[0];
	out[1] = p0[1] + t * d[1];
}

/* A disk of radius r about x. */
static int disk_segment(double r, const double x[2], const double p0[2], const double p1[2],
                        body_segment_contact *out)
{
	segment_nearest(p0, p1, x, out->on_segment, &out->at_end);
	double dx = x[0] - out->on_segment[0], dy = x[1] - out->on_segment[1];
	double d = hypot(dx, dy);
	if (!(d > 0.0))
		return BSIM_EFAIL;
	out->n[0] = dx / d;
	out->n[1] = dy / d;
	out->dist = d - r;
	out->on_body[0] = x[0] - r * out->n[0];
	out->on_body[1] = x[1] - r * out->n[1];
	return BSIM_OK;
}

int body_shape_segment(const bsim_body_def *b, const double x[2], double psi, const double p0[2],
                       const double p1[2], body_segment_contact *out)
{
	switch (b->shape) {
	case BSIM_SHAPE_ELLIPSE:
		return body_shape_ellipse_segment(b->semi_axes[0], b->semi_axes[1], x, psi, p0, p1,
		                                  out);
	case BSIM_SHAPE_CAPSULE:
		(void)psi;
		return BSIM_EFAIL; /* the capsule's case is not written yet */
	default:
		return disk_segment(b->radius, x, p0, p1, out);
	}
}

double body_shape_reach(const bsim_body_def *b)
{
	switch (b->shape) {
	case BSIM_SHAPE_CAPSULE:
		return b->length / 2 + b->radius;
	case BSIM_SHAPE_ELLIPSE:
		return fmax(b->semi_axes[0], b->semi_axes[1]);
	default:
		return b->radius;
	}
}
