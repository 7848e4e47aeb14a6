/* The body's outline against a segment (beamsim/body_shape.h). */
#include "beamsim/body_shape.h"

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
                        bsim_body_segment_contact *out)
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

/* 1 if the segments a0-a1 and b0-b1 share a point (orientation test; a
 * touching end counts). */
static int segments_cross(const double a0[2], const double a1[2], const double b0[2],
                          const double b1[2])
{
	double d1 = (b1[0] - b0[0]) * (a0[1] - b0[1]) - (b1[1] - b0[1]) * (a0[0] - b0[0]);
	double d2 = (b1[0] - b0[0]) * (a1[1] - b0[1]) - (b1[1] - b0[1]) * (a1[0] - b0[0]);
	double d3 = (a1[0] - a0[0]) * (b0[1] - a0[1]) - (a1[1] - a0[1]) * (b0[0] - a0[0]);
	double d4 = (a1[0] - a0[0]) * (b1[1] - a0[1]) - (a1[1] - a0[1]) * (b1[0] - a0[0]);
	return d1 * d2 <= 0.0 && d3 * d4 <= 0.0;
}

/* A capsule: the points within r of its core segment A-B, of length l along
 * the heading psi through x. Two segments that do not cross are nearest at
 * an end of one of them, so the nearest pair is the best of four
 * end-to-segment distances:
 *   A and B against p0-p1 (on_segment inside or at an end of the beam),
 *   p0 and p1 against A-B (on_segment an end of the beam).
 * With core point K and beam point S at distance d: n = (K - S) / d,
 * dist = d - r, on_body = K - r n. Where the core lies parallel to the beam
 * and overlaps it, every pair along the overlap is as near; the pair at the
 * overlap's middle is taken, so that a capsule lying on a beam is pressed
 * at the middle of its flat, not at one end. */
static int capsule_segment(double r, double l, const double x[2], double psi, const double p0[2],
                           const double p1[2], bsim_body_segment_contact *out)
{
	double h[2] = {0.5 * l * cos(psi), 0.5 * l * sin(psi)};
	double ca[2] = {x[0] - h[0], x[1] - h[1]}, cb[2] = {x[0] + h[0], x[1] + h[1]};
	if (segments_cross(ca, cb, p0, p1))
		return BSIM_EFAIL;
	const double *core_end[2] = {ca, cb}, *beam_end[2] = {p0, p1};
	double best = INFINITY, k[2] = {0, 0}, sp[2] = {0, 0};
	int at_end = 1;
	for (int e = 0; e < 2; e++) {
		double q[2];
		int end;
		segment_nearest(p0, p1, core_end[e], q, &end);
		double d = hypot(core_end[e][0] - q[0], core_end[e][1] - q[1]);
		if (d < best) {
			best = d;
			k[0] = core_end[e][0], k[1] = core_end[e][1];
			sp[0] = q[0], sp[1] = q[1];
			at_end = end;
		}
	}
	for (int e = 0; e < 2; e++) {
		double q[2];
		int end;
		segment_nearest(ca, cb, beam_end[e], q, &end);
		double d = hypot(q[0] - beam_end[e][0], q[1] - beam_end[e][1]);
		if (d < best) {
			best = d;
			k[0] = q[0], k[1] = q[1];
			sp[0] = beam_end[e][0], sp[1] = beam_end[e][1];
			at_end = 1;
		}
	}
	if (!(best > 0.0))
		return BSIM_EFAIL;
	double n[2] = {(k[0] - sp[0]) / best, (k[1] - sp[1]) / best};
	/* Parallel and overlapping: the middle of the overlap, measured along
	 * the beam's direction u. */
	double ub[2] = {p1[0] - p0[0], p1[1] - p0[1]}, lb = hypot(ub[0], ub[1]);
	ub[0] /= lb, ub[1] /= lb;
	double cross = ub[0] * (cb[1] - ca[1]) - ub[1] * (cb[0] - ca[0]);
	if (fabs(cross) <= 1e-9 * l) {
		double sa = (ca[0] - p0[0]) * ub[0] + (ca[1] - p0[1]) * ub[1];
		double sb = (cb[0] - p0[0]) * ub[0] + (cb[1] - p0[1]) * ub[1];
		double lo = fmax(fmin(sa, sb), 0.0), hi = fmin(fmax(sa, sb), lb);
		if (hi > lo) {
			double s = 0.5 * (lo + hi);
			sp[0] = p0[0] + s * ub[0], sp[1] = p0[1] + s * ub[1];
			k[0] = sp[0] + best * n[0], k[1] = sp[1] + best * n[1];
			at_end = !(s > 0.0 && s < lb);
		}
	}
	out->dist = best - r;
	out->n[0] = n[0];
	out->n[1] = n[1];
	out->on_body[0] = k[0] - r * n[0];
	out->on_body[1] = k[1] - r * n[1];
	out->on_segment[0] = sp[0];
	out->on_segment[1] = sp[1];
	out->at_end = at_end;
	return BSIM_OK;
}

int bsim_body_shape_segment(const bsim_body_def *b, const double x[2], double psi,
                            const double p0[2], const double p1[2], bsim_body_segment_contact *out)
{
	switch (b->shape) {
	case BSIM_SHAPE_ELLIPSE:
		return bsim_body_shape_ellipse_segment(b->semi_axes[0], b->semi_axes[1], x, psi, p0,
		                                       p1, out);
	case BSIM_SHAPE_CAPSULE:
		return capsule_segment(b->radius, b->length, x, psi, p0, p1, out);
	default:
		return disk_segment(b->radius, x, p0, p1, out);
	}
}

double bsim_body_shape_reach(const bsim_body_def *b)
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
