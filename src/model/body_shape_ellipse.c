/* An ellipse against a segment (beamsim/body_shape.h). */
#include "beamsim/body_shape.h"

#include <float.h>
#include <math.h>

#include "util/fminmax.h"

/*
 * The body is the ellipse E of semi-axes a along u = (cos psi, sin psi) and
 * c along v = (-sin psi, cos psi) about x; the segment S runs p0-p1, d = p1 -
 * p0. Everything below is in the body's frame (u, v), where the support
 * function of E - x is h(n) = sqrt(a^2 n_u^2 + c^2 n_v^2), attained at
 * e(n) = (a^2 n_u, c^2 n_v) / h(n).
 *
 * For a unit n (from the segment toward the body) the body's lowest point
 * along n, x - e(n), lies
 *     g(n) = n.(x - p0) - h(n) - max(0, n.d)
 * beyond the segment's highest point. For two convex sets the signed
 * distance is max over n of g: the distance when apart, and when they
 * overlap minus the smallest translation that separates them (the body
 * moved by -dist n). So dist = max g, n its argmax, on_body = x - e(n),
 * on_segment the segment's point highest along n.
 *
 * On the half circle n.d < 0 the highest point is p0 and g = g_0, on n.d > 0
 * it is p1 and g = g_1, where g_k(n) = n.(x - p_k) - h(n); the halves meet
 * at n = +-m, m perpendicular to d (a face contact). The maximum of g is at
 * +-m or at a local maximum of some g_k. dg_k/dphi = n'.(x - e(n) - p_k) = 0
 * says that p_k lies on the outline's normal at x - e(n): the critical
 * points of g_k are the normals from p_k to the outline (Eberly, "Distance
 * from a point to an ellipse, an ellipsoid, or a hyperellipsoid", 2013).
 * With e0 >= e1 the semi-axes (major first) and y = (y0, y1) >= 0 the point
 * reflected into the first quadrant, the outline point q_i = e_i^2 y_i /
 * (t + e_i^2) has its normal through y when t is a root of
 *     F(t) = (e0 y0 / (t + e0^2))^2 + (e1 y1 / (t + e1^2))^2 - 1,
 * and its outward normal is (y0 / (t + e0^2), y1 / (t + e1^2)). F is convex
 * between its poles t = -e0^2, -e1^2. For t > -e1^2 it falls from +inf to
 * -1: one root, the nearest point, g_k's global maximum. For -e0^2 < t <
 * -e1^2 its minimum is at t + e1^2 = -(e0^2 - e1^2) / (1 + K), K = (e0 y0 /
 * (e1 y1))^(2/3); below zero there (y inside the evolute) it has two roots,
 * g_k's other local maximum and a local minimum. The root t < -e0^2 is the
 * farthest point, g_k's minimum. Each root is found in z > 0, the distance
 * of t from the pole next to it (so that a root near a pole keeps its
 * relative precision), where the function reads (P/z)^2 + (Q/(z+s))^2 - 1,
 * convex and falling up to the root: Newton's method from a point with F >=
 * 0 then rises monotonically to it, a Newton step from a point with F <= 0
 * lands below it, and the iteration stops when its step is under 2 ulp of z:
 * the root to about 1 ulp (at most 14 steps for a million random points
 * about a 9 x 3 ellipse, 34 beside a cusp of its evolute; should
 * NEWTON_MAX pass, the bracket is bisected, which ends within ~70). A quartic
 * solver (gsl_poly_complex_solve_quartic) gives the four at once but loses
 * precision at double roots and would need the same polishing.
 *
 * Apart (the segment's point nearest the centre, in the frame scaled by 1/a
 * and 1/c, is outside the unit circle), the distance along the segment is
 * convex in its parameter: the answer is the face normal if the line misses
 * E and the foot of x + e(m) lies within the segment, else the nearest
 * point of the end on the side of the line's minimum (one root). Overlapping,
 * dist is the largest g among +-m and both ends' local maxima (at most
 * three roots an end; an end outside E gives only its other local maximum,
 * since at its nearest point g_k > 0 > max g). Either way the answer is g's exact maximum, to the
 * rounding of its terms (about 1e-16 of the scene's size).
 */

enum { NEWTON_MAX = 40, BISECT_MAX = 200 };

/* The root of (P/z)^2 + (Q/(z+s))^2 - 1 in (z, zhi), the function falling
 * and convex there, >= 0 at z and <= 0 at zhi. */
static double falling_root(double P, double Q, double s, double z, double zhi)
{
	for (int i = 0; i < NEWTON_MAX; i++) {
		double A = P / z, B = Q / (z + s);
		double f = A * A + B * B - 1.0;
		if (!(f > 0.0))
			return z; /* at the root within rounding */
		double step = f / (2.0 * (A * A / z + B * B / (z + s)));
		z += step;
		if (!(z < zhi))
			return zhi; /* only by rounding: the step lands below the root */
		if (step <= 2.0 * DBL_EPSILON * z)
			return z;
	}
	for (int i = 0; i < BISECT_MAX && zhi - z > 2.0 * DBL_EPSILON * z; i++) {
		double mid = zhi > 4.0 * z ? sqrt(z) * sqrt(zhi) : 0.5 * (z + zhi);
		double A = P / mid, B = Q / (mid + s);
		if (A * A + B * B - 1.0 > 0.0)
			z = mid;
		else
			zhi = mid;
	}
	return z;
}

typedef struct ellipse {
	double a, c;   /* m, semi-axes along u and v */
	double e0, e1; /* m, the major and the minor */
	double dd;     /* m^2, e0^2 - e1^2 */
	int swap;      /* 1: the major axis is v */
} ellipse;

enum { NEAREST = 1, OTHER = 2 };

/* The outward normals (body frame, not unit) at the outline points whose
 * normal passes through y (body frame): the nearest if want has NEAREST,
 * g_k's other local maximum if it has OTHER. Returns how many (<= 3; none
 * for the centre of a circle, where every direction is one). */
static int normals_through(const ellipse *E, const double y[2], int want, double N[3][2])
{
	double y0 = fabs(E->swap ? y[1] : y[0]), y1 = fabs(E->swap ? y[0] : y[1]);
	double e0 = E->e0, e1 = E->e1, dd = E->dd;
	/* Within rounding of an axis is on it (and no subnormal P or Q). */
	if (y0 < DBL_EPSILON * e0)
		y0 = 0.0;
	if (y1 < DBL_EPSILON * e1)
		y1 = 0.0;
	int k = 0;
	double P = e1 * y1, Q = e0 * y0;
	if (P > 0.0) {
		double z;
		if (want & NEAREST) {
			/* One Newton step from hi (where F <= 0) lands below the root. */
			double hi = sqrt(P * P + Q * Q);
			double A = P / hi, B = Q / (hi + dd), f = A * A + B * B - 1.0;
			z = bsim_fmax(P, hi + f / (2.0 * (A * A / hi + B * B / (hi + dd))));
			z = falling_root(P, Q, dd, z, hi);
			N[k][0] = y0 / (z + dd);
			N[k++][1] = y1 / z;
		}
		/* the evolute lies within |y0| < dd / e0, |y1| < dd / e1 */
		if ((want & OTHER) && y0 > 0.0 && Q < dd && P < dd) {
			double r = cbrt(Q / P), K = r * r;
			double zl = dd * (K / (1.0 + K)), zr = dd / (1.0 + K);
			double A = Q / zl, B = P / zr;
			if (A * A + B * B - 1.0 < 0.0) {
				/* z = t + e0^2 from the pole -e0^2, and z = -(t + e1^2) from -e1^2
				 */
				z = falling_root(Q, P, -dd, Q, zl);
				N[k][0] = y0 / z;
				N[k++][1] = y1 / (z - dd);
				z = falling_root(P, Q, -dd, P, zr);
				N[k][0] = y0 / (dd - z);
				N[k++][1] = -y1 / z;
			}
		} else if ((want & OTHER) && y0 == 0.0) {
			N[k][0] = 0.0; /* the opposite end of the minor axis */
			N[k++][1] = -1.0;
		}
	} else if (!(want & NEAREST)) {
		/* on the major axis g_k has no other local maximum */
	} else if (dd > 0.0 && e0 * y0 < dd) {
		/* On the major axis inside the evolute: two nearest points */
		double q0 = e0 * e0 * y0 / dd,
		       q1 = e1 * sqrt(bsim_fmax(0.0, 1.0 - (q0 / e0) * (q0 / e0)));
		N[k][0] = q0 / (e0 * e0);
		N[k++][1] = q1 / (e1 * e1);
		N[k][0] = q0 / (e0 * e0);
		N[k++][1] = -q1 / (e1 * e1);
	} else if (y0 > 0.0) {
		N[k][0] = 1.0; /* the end of the major axis */
		N[k++][1] = 0.0;
	}
	for (int i = 0; i < k; i++) {
		if (E->swap ? y[1] < 0.0 : y[0] < 0.0)
			N[i][0] = -N[i][0];
		if (E->swap ? y[0] < 0.0 : y[1] < 0.0)
			N[i][1] = -N[i][1];
		if (E->swap) {
			double t = N[i][0];
			N[i][0] = N[i][1];
			N[i][1] = t;
		}
	}
	return k;
}

/* The best normal so far (body frame, unit, segment toward body). */
typedef struct best {
	double g, n[2];
	int face; /* 1: n is +-m */
	int end;  /* the end whose normal it is (a tip) */
} best;

/* Scores the direction -N (N an outward normal of the outline, not unit):
 * y0 = p0 - x and dv = d in the body frame. */
static void consider(const ellipse *E, const double y0[2], const double dv[2], const double N[2],
                     int face, int end, best *b)
{
	double len = sqrt(N[0] * N[0] + N[1] * N[1]);
	double n0 = -N[0] / len, n1 = -N[1] / len;
	double h = sqrt(E->a * E->a * n0 * n0 + E->c * E->c * n1 * n1);
	double g = -(n0 * y0[0] + n1 * y0[1]) - h - bsim_fmax(0.0, n0 * dv[0] + n1 * dv[1]);
	if (g > b->g) {
		b->g = g;
		b->n[0] = n0;
		b->n[1] = n1;
		b->face = face;
		b->end = end;
	}
}

int bsim_body_shape_ellipse_segment(double a, double c, const double x[2], double psi,
                                    const double p0[2], const double p1[2],
                                    bsim_body_segment_contact *out)
{
	if (!(a > 0.0 && c > 0.0 && isfinite(a) && isfinite(c) && isfinite(psi)))
		return BSIM_EFAIL;
	double d[2] = {p1[0] - p0[0], p1[1] - p0[1]};
	double cs = cos(psi), sn = sin(psi);
	/* p0 - x, p1 - x and d in the body frame (u, v) */
	double r0[2] = {p0[0] - x[0], p0[1] - x[1]}, r1[2] = {p1[0] - x[0], p1[1] - x[1]};
	double y[2][2] = {{cs * r0[0] + sn * r0[1], -sn * r0[0] + cs * r0[1]},
	                  {cs * r1[0] + sn * r1[1], -sn * r1[0] + cs * r1[1]}};
	double dv[2] = {cs * d[0] + sn * d[1], -sn * d[0] + cs * d[1]};
	double dd2 = dv[0] * dv[0] + dv[1] * dv[1];
	if (!(dd2 > 0.0) || !isfinite(dd2) || !isfinite(y[0][0] + y[0][1] + y[1][0] + y[1][1]))
		return BSIM_EFAIL;
	ellipse E = {a, c, bsim_fmax(a, c), bsim_fmin(a, c), (a - c) * (a + c), c > a};
	if (E.swap)
		E.dd = -E.dd;

	/* The segment in the frame scaled by 1/a, 1/c: its line's point nearest
	 * the centre at parameter ts, the segment's at the clamped one. */
	double s0[2] = {y[0][0] / a, y[0][1] / c}, sd[2] = {dv[0] / a, dv[1] / c};
	double ts = -(s0[0] * sd[0] + s0[1] * sd[1]) / (sd[0] * sd[0] + sd[1] * sd[1]);
	double tc = bsim_fmin(bsim_fmax(ts, 0.0), 1.0);
	double cl[2] = {s0[0] + tc * sd[0], s0[1] + tc * sd[1]};
	double ln[2] = {s0[0] + ts * sd[0], s0[1] + ts * sd[1]};
	/* m: the unit normal of the segment, from the centre toward its line */
	double len = sqrt(dd2), m[2] = {-dv[1] / len, dv[0] / len};
	if (m[0] * y[0][0] + m[1] * y[0][1] < 0.0)
		m[0] = -m[0], m[1] = -m[1];

	best b = {-INFINITY, {0.0, 0.0}, 0, 0};
	double N[3][2];
	if (cl[0] * cl[0] + cl[1] * cl[1] > 1.0) {
		int end = ts < 0.0 ? 0 : 1;
		if (ln[0] * ln[0] + ln[1] * ln[1] > 1.0) {
			/* The line misses E: is the foot of x + e(m) within the segment? */
			double h = sqrt(a * a * m[0] * m[0] + c * c * m[1] * m[1]);
			double em[2] = {a * a * m[0] / h - y[0][0], c * c * m[1] / h - y[0][1]};
			double t = (em[0] * dv[0] + em[1] * dv[1]) / dd2;
			end = t < 0.0 ? 0 : 1;
			if (t >= 0.0 && t <= 1.0)
				consider(&E, y[0], dv, m, 1, 0, &b);
		}
		if (!b.face && normals_through(&E, y[end], NEAREST, N) == 1)
			consider(&E, y[0], dv, N[0], 0, end, &b);
	} else {
		double mm[2] = {-m[0], -m[1]};
		consider(&E, y[0], dv, m, 1, 0, &b);
		consider(&E, y[0], dv, mm, 1, 0, &b);
		/* An end outside E is no maximum's tip: there g_k > 0 > max g. */
		for (int k = 0; k < 2; k++) {
			double o = s0[0] + k * sd[0], v = s0[1] + k * sd[1];
			int want = o * o + v * v > 1.0 ? OTHER : NEAREST | OTHER;
			int nk = normals_through(&E, y[k], want, N);
			for (int i = 0; i < nk; i++)
				consider(&E, y[0], dv, N[i], 0, k, &b);
		}
	}
	if (!isfinite(b.g))
		return BSIM_EFAIL;

	/* The body's point x - e(n), and the segment's highest along n */
	double h = sqrt(a * a * b.n[0] * b.n[0] + c * c * b.n[1] * b.n[1]);
	double eb[2] = {-a * a * b.n[0] / h, -c * c * b.n[1] / h};
	out->dist = b.g;
	out->n[0] = cs * b.n[0] - sn * b.n[1];
	out->n[1] = sn * b.n[0] + cs * b.n[1];
	out->on_body[0] = x[0] + cs * eb[0] - sn * eb[1];
	out->on_body[1] = x[1] + sn * eb[0] + cs * eb[1];
	if (b.face) {
		double t = ((eb[0] - y[0][0]) * dv[0] + (eb[1] - y[0][1]) * dv[1]) / dd2;
		out->at_end = !(t > 0.0 && t < 1.0);
		const double *p = t <= 0.0 ? p0 : p1;
		out->on_segment[0] = out->at_end ? p[0] : p0[0] + t * d[0];
		out->on_segment[1] = out->at_end ? p[1] : p0[1] + t * d[1];
	} else {
		double nd = b.n[0] * dv[0] + b.n[1] * dv[1];
		int end = nd < 0.0 ? 0 : nd > 0.0 ? 1 : b.end;
		const double *p = end ? p1 : p0;
		out->at_end = 1;
		out->on_segment[0] = p[0];
		out->on_segment[1] = p[1];
	}
	return BSIM_OK;
}
