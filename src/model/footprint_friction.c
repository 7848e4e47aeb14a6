/* Coulomb friction with the plane over the footprint of a body that turns,
 * the sliding and the spinning coupled.
 *
 * Uniform pressure p0 = M g / A over the footprint S (area A, centrally
 * symmetric). The patch at r from the centre moves at u = v + omega z x r
 * and feels -mu p0 u / |u| dA, so the friction force and torque are
 *   W = -grad D(xi),   D(xi) = mu p0 integral_S |v + omega z x r| dA,
 * xi = (v, omega) the twist and D the rate at which friction dissipates:
 * convex and homogeneous of degree 1, so that W depends on the twist's
 * direction alone. Only sliding: W = (-mu M g v / |v|, 0); only spinning:
 * W = (0, -mu M g r_s sgn omega), r_s = (1/A) integral_S |r| dA.
 *
 * A step of h takes friction implicitly (backward Euler; the principle of
 * maximal dissipation). P = (M v / h + f, J omega / h + tau) is the wrench
 * that stops the body within the step (f, tau the other effects'); with
 * M = diag(M, M, J) the step ends at the twist h xi',
 *   xi' = argmin_xi 1/2 (xi - M^-1 P)^T M (xi - M^-1 P) + D(xi),
 * and friction gives W = -grad D(xi') = M xi' - P. The minimum is xi' = 0,
 * the body ending the step at rest with W = -P, exactly when P lies in the
 * limit set L = {W : W . xi <= D(xi) for every xi}, the wrenches friction
 * can hold. Sliding alone L is the disk |F| <= mu M g, and this is the
 * exact stick/slip of effects.c's ground_friction_apply. The step is the
 * proximal map of a convex function: it never carries the body past rest,
 * whatever h, so neither the velocity nor the spin reverses and nothing
 * chatters; a body whose sliding and spinning would both reverse within
 * the step is held at rest.
 *
 * The disk in closed form (disk_*). Place the twist's centre of rotation
 * c = z x v / omega at d = eps R from the centre, eps = |v| / (R |omega|):
 * then u = omega z x (r - c), and with Phi(d) = integral_S |r - c| dA,
 *   |F| = mu p0 Phi'(d) against v,   |T| = mu p0 (Phi - d Phi'(d)) against omega.
 * Integrating |r - c| over the angle gives complete elliptic integrals K,
 * E and D = (K - E) / k^2 of modulus k; for the unit disk
 *   eps <= 1, k = eps:      Phi = 4/9 [(7 + eps^2) E - 4 (1 - eps^2) K],
 *   eps >= 1, k = 1/eps:    Phi = 4/9 [eps (7 + eps^2) E - (eps^2 - 1)(eps^2 + 3) K / eps]
 * (the real part of the first past k = 1), so that F = mu M g f(eps) and
 * T = mu M g R t(eps) with
 *   eps <= 1:   f = 4 eps (E + K - D) / (3 pi),   t = 4 [(4 - 2 k^2) E - (1 - k^2) K] / (9 pi),
 *   eps >= 1:   f = 4 (E + K - D) / (3 pi),       t = 4 [2 D + 4 E - 5 K + 3 k^2 K] / (9 pi k).
 * f rises from 0 (f ~ eps) to 1 and t falls from 2/3 to 0 (t ~ 1 / (4 eps)),
 * both continuous at eps = 1 (8 / (3 pi), 8 / (9 pi)), and t' = -eps f'.
 * (Phi checked against a numerical double integral at eps = 0.1 to 10;
 * f and t by test_footprint_friction against a sum over a million patches,
 * within 2.1e-6.) For k < 0.05 t's bracket loses
 * digits to cancellation and its series k/4 + k^3/48 + 3 k^5/512 +
 * 5 k^7/2048 stands in. The disk's limit set in (|F|, |T|) lies under
 * the curve mu M g (f, R t), whose normal at eps is the twist (eps R, 1):
 * the step comes down to one equation in th = atan(eps).
 *
 * A capsule and an ellipse by quadrature (footprint_*): Gauss-Legendre
 * nodes in polar coordinates about the centre, 12 along each ray (r up to
 * the outline's rho(phi)) and 24 rays a quarter (the capsule's split where
 * its side meets its cap), 1152 in all. Their sums give D, its gradient
 * and its Hessian, and Newton's method the step's minimum. Where the
 * centre of rotation falls on a node the sums are coarsest (that patch's
 * friction turns about it); test_footprint_friction finds the force
 * within 3.8e-4 mu M g of a fine sum over patches at its twists. */
#include "model/footprint_friction.h"

#include <math.h>
#include <stdlib.h>

#include <gsl/gsl_integration.h>
#include <gsl/gsl_sf_ellint.h>

#include "model/body_outline.h"

#define PI 3.14159265358979323846

enum { RAY_NODES = 12, QUARTER_RAYS = 24 };

/* ---- the disk ---- */

/* f and t at th = atan(eps) in [0, pi/2], given as its sine and cosine. */
static void disk_limit(double sn, double cs, double *f, double *t)
{
	const int outside = sn > cs; /* eps > 1: the centre of rotation beyond the rim */
	const double k = outside ? cs / sn : sn / cs, k2 = k * k;
	if (k2 >= 1.0) {
		*f = 8.0 / (3.0 * PI);
		*t = 8.0 / (9.0 * PI);
		return;
	}
	const double K = gsl_sf_ellint_Kcomp(k, GSL_PREC_DOUBLE);
	const double D = gsl_sf_ellint_Dcomp(k, GSL_PREC_DOUBLE);
	const double E = K - k2 * D;
	if (!outside) {
		*f = 4.0 * k / (3.0 * PI) * (E + K - D);
		*t = 4.0 / (9.0 * PI) * ((4.0 - 2.0 * k2) * E - (1.0 - k2) * K);
	} else {
		*f = 4.0 / (3.0 * PI) * (E + K - D);
		*t = k < 0.05 ? k * (0.25 + k2 * (1.0 / 48 + k2 * (3.0 / 512 + k2 * 5.0 / 2048)))
		              : 4.0 / (9.0 * PI * k) * (2.0 * D + 4.0 * E - 5.0 * K + 3.0 * k2 * K);
	}
}

/* A disk's step: |p| = ps, |q| = qs (both > 0), M, J, R, limit F_l. */
typedef struct disk_step {
	double ps, qs, mass, inertia, radius, force_limit, torque_limit; /* torque: F_l R */
} disk_step;

/* The step's end twist against the wrench it gets at th: with that
 * wrench, F_l (f, R t)(th), the body ends the step at s = h (ps - F_l f) / M
 * and omega = h (qs - F_l R t) / J, which must lie along the twist of th,
 * (R omega, s) along (cos th, sin th):
 *   J (ps - F_l f) cos th - M R (qs - F_l R t) sin th = 0. */
static double disk_direction(double th, const void *ctx)
{
	const disk_step *d = ctx;
	double sn = th >= PI / 2 ? 1.0 : sin(th), cs = th >= PI / 2 ? 0.0 : cos(th), f, t;
	disk_limit(sn, cs, &f, &t);
	return d->inertia * (d->ps - d->force_limit * f) * cs -
	       d->mass * d->radius * (d->qs - d->torque_limit * t) * sn;
}

/* The torque limit at th against qs: F_l R t(th) - qs, falling in th. */
static double disk_spin(double th, const void *ctx)
{
	const disk_step *d = ctx;
	double f, t;
	disk_limit(th >= PI / 2 ? 1.0 : sin(th), th >= PI / 2 ? 0.0 : cos(th), &f, &t);
	return d->torque_limit * t - d->qs;
}

/* The root of fn between a and b, fn(a) = fa >= 0 >= fb = fn(b), by
 * regula falsi with Anderson and Bjorck's scaling, trying x first if it
 * lies between them: superlinear, and always within the bracket. */
static double root_between(double (*fn)(double, const void *), const void *ctx, double a, double fa,
                           double b, double fb, double x)
{
	if (fa == 0.0)
		return a;
	if (fb == 0.0)
		return b;
	if (!(x > a && x < b))
		x = (a * fb - b * fa) / (fb - fa);
	for (int i = 0; i < 200 && fabs(b - a) > 4e-16; i++) {
		double fx = fn(x, ctx);
		if (fx == 0.0)
			return x;
		if ((fx > 0) != (fb > 0)) {
			a = b;
			fa = fb;
		} else {
			double m = 1.0 - fx / fb;
			fa *= m > 0.0 ? m : 0.5;
		}
		b = x;
		fb = fx;
		x = (a * fb - b * fa) / (fb - fa);
		if (!(x > fmin(a, b) && x < fmax(a, b)))
			x = 0.5 * (a + b);
	}
	return b;
}

/* The disk's wrench for |p| = ps and |q| = qs: out[0] the force along p,
 * out[2] the torque along q (both negative); 1 if the body sticks. */
static int disk_wrench(const bsim_footprint_friction *fr, double ps, double qs, double out[3])
{
	disk_step d = {.ps = ps,
	               .qs = qs,
	               .mass = fr->mass,
	               .inertia = fr->inertia,
	               .radius = fr->radius,
	               .force_limit = fr->force_limit,
	               .torque_limit = fr->force_limit * fr->radius};
	double lo = 0.0, f, t;
	if (ps <= d.force_limit && qs <= fr->spin_limit) {
		/* within the limit set if ps is below the force the curve has
		 * where its torque is qs */
		lo = root_between(disk_spin, &d, 0.0, disk_spin(0.0, &d), PI / 2, -qs, NAN);
		disk_limit(sin(lo), cos(lo), &f, &t);
		if (ps <= d.force_limit * f)
			return 1;
	}
	/* Past lo (where the spin would just stop) the equation has one root;
	 * the free twist's direction is the first guess. */
	double guess = atan2(fr->inertia * ps, fr->mass * fr->radius * qs);
	double th = root_between(disk_direction, &d, lo, disk_direction(lo, &d), PI / 2,
	                         disk_direction(PI / 2, &d), guess);
	disk_limit(th >= PI / 2 ? 1.0 : sin(th), th >= PI / 2 ? 0.0 : cos(th), &f, &t);
	out[0] = -d.force_limit * f;
	out[1] = 0.0;
	out[2] = -d.torque_limit * t;
	return 0;
}

/* ---- a capsule or an ellipse: sums over the nodes ---- */

/* D at the twist xi (body frame), and if grad its gradient, and if hess
 * the upper triangle of its Hessian (00 01 02 11 12 22). Each node and its
 * mirror (x, -y) are added together. */
static double footprint_sums(const bsim_footprint_friction *fr, const double xi[3], double grad[3],
                             double hess[6])
{
	const double vx = xi[0], vy = xi[1], w = xi[2];
	double D = 0.0;
	if (!grad) {
		for (int i = 0; i < fr->n; i++) {
			const double uy = vy + w * fr->x[i], wy = w * fr->y[i];
			const double u1 = vx - wy, u2 = vx + wy;
			D += fr->c[i] * (sqrt(u1 * u1 + uy * uy) + sqrt(u2 * u2 + uy * uy));
		}
		return D;
	}
	double g[3] = {0, 0, 0}, H[6] = {0, 0, 0, 0, 0, 0};
	if (!hess) {
		for (int i = 0; i < fr->n; i++) {
			const double x = fr->x[i], y = fr->y[i], c = fr->c[i];
			const double uy = vy + w * x, wy = w * y;
			const double u1 = vx - wy, u2 = vx + wy;
			const double m1 = sqrt(u1 * u1 + uy * uy), m2 = sqrt(u2 * u2 + uy * uy);
			const double i1 = m1 > 0 ? 1.0 / m1 : 0.0, i2 = m2 > 0 ? 1.0 / m2 : 0.0;
			const double e1x = u1 * i1, e1y = uy * i1, e2x = u2 * i2, e2y = uy * i2;
			D += c * (m1 + m2);
			g[0] += c * (e1x + e2x);
			g[1] += c * (e1y + e2y);
			g[2] += c * ((x * e1y - y * e1x) + (x * e2y + y * e2x));
		}
		for (int k = 0; k < 3; k++)
			grad[k] = g[k];
		return D;
	}
	for (int i = 0; i < fr->n; i++) {
		const double x = fr->x[i], y = fr->y[i], c = fr->c[i];
		const double uy = vy + w * x, wy = w * y;
		const double u1 = vx - wy, u2 = vx + wy; /* at (x, y) and (x, -y) */
		const double m1 = sqrt(u1 * u1 + uy * uy), m2 = sqrt(u2 * u2 + uy * uy);
		D += c * (m1 + m2);
		/* the unit directions e, and a = (-e_y, e_x, y_k e_y + x e_x), the
		 * Hessian's c / m a a^T (an exact 0 where the centre of rotation
		 * sits on the node) */
		const double i1 = m1 > 0 ? 1.0 / m1 : 0.0, i2 = m2 > 0 ? 1.0 / m2 : 0.0;
		const double e1x = u1 * i1, e1y = uy * i1, k1 = c * i1;
		const double e2x = u2 * i2, e2y = uy * i2, k2 = c * i2;
		g[0] += c * (e1x + e2x);
		g[1] += c * (e1y + e2y);
		g[2] += c * ((x * e1y - y * e1x) + (x * e2y + y * e2x));
		const double a10 = -e1y, a11 = e1x, a12 = y * e1y + x * e1x;
		const double a20 = -e2y, a21 = e2x, a22 = x * e2x - y * e2y;
		H[0] += k1 * a10 * a10 + k2 * a20 * a20;
		H[1] += k1 * a10 * a11 + k2 * a20 * a21;
		H[2] += k1 * a10 * a12 + k2 * a20 * a22;
		H[3] += k1 * a11 * a11 + k2 * a21 * a21;
		H[4] += k1 * a11 * a12 + k2 * a21 * a22;
		H[5] += k1 * a12 * a12 + k2 * a22 * a22;
	}
	for (int k = 0; k < 3; k++)
		grad[k] = g[k];
	for (int k = 0; k < 6; k++)
		hess[k] = H[k];
	return D;
}

/* x = A^-1 b for the symmetric positive definite A (upper triangle as
 * footprint_sums), by Cholesky; returns 0 if A is not. */
static int solve3(const double A[6], const double b[3], double x[3])
{
	const double l00 = sqrt(A[0]);
	if (!(l00 > 0))
		return 0;
	const double l10 = A[1] / l00, l20 = A[2] / l00;
	const double d11 = A[3] - l10 * l10;
	if (!(d11 > 0))
		return 0;
	const double l11 = sqrt(d11), l21 = (A[4] - l20 * l10) / l11;
	const double d22 = A[5] - l20 * l20 - l21 * l21;
	if (!(d22 > 0))
		return 0;
	const double l22 = sqrt(d22);
	const double y0 = b[0] / l00, y1 = (b[1] - l10 * y0) / l11;
	const double y2 = (b[2] - l20 * y0 - l21 * y1) / l22;
	x[2] = y2 / l22;
	x[1] = (y1 - l21 * x[2]) / l11;
	x[0] = (y0 - l10 * x[1] - l20 * x[2]) / l00;
	return 1;
}

static double dot3(const double a[3], const double b[3])
{
	return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* Whether P lies outside the limit set: some n with P . n = 1 has
 * D(n) < 1 (its gauge max P . n / D(n) exceeds 1). Newton's method for
 * the least D on the plane P . n = 1 (convex), from n on it, stopping
 * as soon as D(n) < 1; n holds that point. */
static int footprint_outside(const bsim_footprint_friction *fr, const double P[3], double n[3])
{
	const double pp = dot3(P, P);
	for (int it = 0; it < 60; it++) {
		double g[3], H[6], x1[3], x2[3], d[3];
		const double Dn = footprint_sums(fr, n, g, H);
		if (Dn < 1.0)
			return 1;
		/* the step on the plane: (H + s P P^T) d = -g + lambda P, P . d = 0
		 * (H is singular along n, which the plane does not hold) */
		const double s = (H[0] + H[3] + H[5]) / pp;
		const double A[6] = {H[0] + s * P[0] * P[0], H[1] + s * P[0] * P[1],
		                     H[2] + s * P[0] * P[2], H[3] + s * P[1] * P[1],
		                     H[4] + s * P[1] * P[2], H[5] + s * P[2] * P[2]};
		if (!solve3(A, g, x1) || !solve3(A, P, x2))
			return 0;
		const double lambda = dot3(P, x1) / dot3(P, x2);
		for (int k = 0; k < 3; k++)
			d[k] = lambda * x2[k] - x1[k];
		const double decrement = -dot3(g, d);
		if (!(decrement > 1e-14 * Dn))
			return 0; /* the least D on the plane is 1 or more */
		double step = 1.0;
		for (;;) {
			double m[3];
			for (int k = 0; k < 3; k++)
				m[k] = n[k] + step * d[k];
			const double on = dot3(P, m);
			for (int k = 0; k < 3; k++)
				m[k] /= on;
			if (footprint_sums(fr, m, NULL, NULL) <= Dn - 1e-4 * step * decrement) {
				for (int k = 0; k < 3; k++)
					n[k] = m[k];
				break;
			}
			step *= 0.5;
			if (step < 1e-12)
				return 0;
		}
	}
	return 0;
}

/* The step's wrench W (body frame) for the stopping wrench P (body
 * frame, both p and q nonzero); 1 if the body sticks (W = -P). */
static int footprint_wrench(const bsim_footprint_friction *fr, const double P[3], double W[3])
{
	const double m[3] = {fr->mass, fr->mass, fr->inertia};
	const double free_twist[3] = {P[0] / m[0], P[1] / m[1], P[2] / m[2]}; /* M^-1 P */
	const double scale = dot3(P, free_twist);                             /* P^T M^-1 P */
	/* The start: a point where Psi is below its value at rest, so that
	 * the minimum is not there: the best point on the free twist's ray
	 * (the twist without friction, M^-1 P), along which Psi(t n) falls from
	 * rest while D(n) < P . n, or failing that the point on another ray
	 * that footprint_outside finds, or none: at rest. */
	double xi[3] = {free_twist[0], free_twist[1], free_twist[2]}, gD[3], H[6], t;
	const double Df = footprint_sums(fr, xi, NULL, NULL);
	if (Df < scale) {
		t = 1.0 - Df / scale;
	} else {
		for (int k = 0; k < 3; k++)
			xi[k] = free_twist[k] / scale;
		if (!footprint_outside(fr, P, xi))
			return 1;
		t = (1.0 - footprint_sums(fr, xi, NULL, NULL)) /
		    (m[0] * xi[0] * xi[0] + m[1] * xi[1] * xi[1] + m[2] * xi[2] * xi[2]);
	}
	for (int k = 0; k < 3; k++)
		xi[k] *= t;
	double D = footprint_sums(fr, xi, gD, H);
	/* Newton's method on Psi(xi) = 1/2 (xi - M^-1 P)^T M (xi - M^-1 P) + D(xi),
	 * halving the step while Psi does not fall enough, except close to the
	 * minimum, where the full step is taken (Psi's round-off there is
	 * larger than its fall). Close to it, a step's end is first summed
	 * without the Hessian: if the decrement there, by the last Hessian, is
	 * already below the tolerance, that is the minimum. */
	double A[6];
	int have_hessian = 1, converged = 0;
	for (int it = 0; it < 60; it++) {
		double g[3], d[3];
		for (int k = 0; k < 3; k++)
			g[k] = m[k] * (xi[k] - free_twist[k]) + gD[k];
		if (have_hessian) {
			for (int k = 0; k < 6; k++)
				A[k] = H[k];
			A[0] += m[0];
			A[3] += m[1];
			A[5] += m[2];
		}
		if (!solve3(A, g, d))
			break;
		/* g^T A^-1 g against the twist's size xi^T M xi: the twist and
		 * the friction to 1e-10 relative */
		const double decrement = dot3(g, d);
		const double size =
		        m[0] * xi[0] * xi[0] + m[1] * xi[1] * xi[1] + m[2] * xi[2] * xi[2];
		if (!(decrement > 1e-20 * size)) {
			converged = 1;
			break;
		}
		if (!have_hessian) { /* not yet the minimum: the Hessian here */
			D = footprint_sums(fr, xi, gD, H);
			have_hessian = 1;
			continue;
		}
		double psi = D;
		for (int k = 0; k < 3; k++)
			psi += 0.5 * m[k] * (xi[k] - free_twist[k]) * (xi[k] - free_twist[k]);
		const int close = decrement < 1e-8 * size;
		double step = 1.0;
		for (;;) {
			double at[3], gt[3], Ht[6];
			for (int k = 0; k < 3; k++)
				at[k] = xi[k] - step * d[k];
			const double Dt = footprint_sums(fr, at, gt, close ? NULL : Ht);
			double psi_t = Dt;
			for (int k = 0; k < 3; k++)
				psi_t += 0.5 * m[k] * (at[k] - free_twist[k]) *
				         (at[k] - free_twist[k]);
			if (close || psi_t <= psi - 1e-4 * step * decrement) {
				for (int k = 0; k < 3; k++) {
					xi[k] = at[k];
					gD[k] = gt[k];
				}
				if (!close)
					for (int k = 0; k < 6; k++)
						H[k] = Ht[k];
				have_hessian = !close;
				D = Dt;
				break;
			}
			step *= 0.5;
			if (step < 1e-10)
				break;
		}
		if (step * step * decrement <= 1e-24 * size)
			break; /* no progress: at a kink of the sums */
	}
	/* At the minimum, the friction of the twist found. Stopped short, at a
	 * kink of the sums (the centre of rotation on a node, whose patch's
	 * friction may then point anywhere within its share): the wrench that
	 * takes the body to the twist found, M xi - P, which the optimality
	 * condition makes the right one there. */
	for (int k = 0; k < 3; k++)
		W[k] = converged ? -gD[k] : m[k] * xi[k] - P[k];
	return 0;
}

bsim_footprint_friction *bsim_footprint_friction_alloc(const bsim_body_def *body, double mu,
                                                       double g)
{
	bsim_footprint_friction *fr = calloc(1, sizeof *fr);
	if (!fr)
		return NULL;
	fr->shape = body->shape;
	fr->mass = body->mass;
	fr->inertia = bsim_body_inertia(body);
	fr->force_limit = mu * body->mass * g;
	if (body->shape == BSIM_SHAPE_DISK) {
		fr->radius = body->radius;
		fr->spin_limit = fr->force_limit * (2.0 * body->radius / 3.0);
		return fr;
	}
	/* the quarter's rays: a capsule's in two pieces, split at its kink */
	double ray[QUARTER_RAYS], ray_w[QUARTER_RAYS];
	const int pieces = body->shape == BSIM_SHAPE_CAPSULE ? 2 : 1;
	const int per = QUARTER_RAYS / pieces;
	const double kink = pieces == 2 ? atan2(body->radius, body->length / 2) : PI / 2;
	gsl_integration_glfixed_table *tp = gsl_integration_glfixed_table_alloc((size_t)per);
	gsl_integration_glfixed_table *tr = gsl_integration_glfixed_table_alloc(RAY_NODES);
	fr->n = 2 * QUARTER_RAYS * RAY_NODES;
	fr->x = malloc(3 * (size_t)fr->n * sizeof *fr->x);
	if (!tp || !tr || !fr->x) {
		gsl_integration_glfixed_table_free(tp);
		gsl_integration_glfixed_table_free(tr);
		bsim_footprint_friction_free(fr);
		return NULL;
	}
	fr->y = fr->x + fr->n;
	fr->c = fr->y + fr->n;
	for (int piece = 0; piece < pieces; piece++) {
		const double a = piece ? kink : 0.0, b = piece ? PI / 2 : kink;
		for (int j = 0; j < per; j++)
			gsl_integration_glfixed_point(a, b, (size_t)j, &ray[piece * per + j],
			                              &ray_w[piece * per + j], tp);
	}
	/* the upper half: each ray phi and its mirror pi - phi, RAY_NODES
	 * along each: the area rho^2 w_phi w_s s at r = rho s */
	double area = 0.0;
	int i = 0;
	for (int j = 0; j < QUARTER_RAYS; j++) {
		const double rho = bsim_body_rho(body, ray[j]);
		const double cs = cos(ray[j]), sn = sin(ray[j]);
		for (int k = 0; k < RAY_NODES; k++) {
			double s, ws;
			gsl_integration_glfixed_point(0.0, 1.0, (size_t)k, &s, &ws, tr);
			const double a = rho * rho * ray_w[j] * ws * s;
			for (int side = 0; side < 2; side++) {
				fr->x[i] = (side ? -1.0 : 1.0) * rho * s * cs;
				fr->y[i] = rho * s * sn;
				fr->c[i] = a;
				area += 2.0 * a; /* with its mirror below */
				i++;
			}
		}
	}
	gsl_integration_glfixed_table_free(tp);
	gsl_integration_glfixed_table_free(tr);
	/* mu p0 a with p0 = M g over the nodes' area: a body that only slides
	 * meets mu M g to rounding */
	const double scale = fr->force_limit / area;
	for (int k = 0; k < fr->n; k++)
		fr->c[k] *= scale;
	const double spin[3] = {0.0, 0.0, 1.0};
	fr->spin_limit = footprint_sums(fr, spin, NULL, NULL);
	return fr;
}

void bsim_footprint_friction_free(bsim_footprint_friction *fr)
{
	if (!fr)
		return;
	free(fr->x);
	free(fr);
}

void bsim_footprint_friction_wrench(const bsim_footprint_friction *fr, double heading,
                                    const double p[2], double q, double out[3])
{
	const double ps = sqrt(p[0] * p[0] + p[1] * p[1]);
	const double limit = fr->force_limit;
	if (q == 0.0 || ps == 0.0) {
		/* only sliding or only spinning: the other stays stopped, and each
		 * is held within its limit or slides at it */
		if (ps <= limit) {
			out[0] = -p[0];
			out[1] = -p[1];
		} else {
			out[0] = -limit * p[0] / ps;
			out[1] = -limit * p[1] / ps;
		}
		out[2] =
		        fabs(q) <= fr->spin_limit ? -q : (q > 0 ? -fr->spin_limit : fr->spin_limit);
		return;
	}
	if (fr->shape == BSIM_SHAPE_DISK) {
		double w[3];
		if (disk_wrench(fr, ps, fabs(q), w)) {
			out[0] = -p[0];
			out[1] = -p[1];
			out[2] = -q;
			return;
		}
		out[0] = w[0] * p[0] / ps;
		out[1] = w[0] * p[1] / ps;
		out[2] = q > 0 ? w[2] : -w[2];
		return;
	}
	/* The body's frame from psi and from pi - psi, so that the frame of
	 * a body's mirror image (heading pi - psi) is the mirror image of its
	 * frame to the bit. */
	const double cs = 0.5 * (cos(heading) - cos(PI - heading));
	const double sn = 0.5 * (sin(heading) + sin(PI - heading));
	const double P[3] = {cs * p[0] + sn * p[1], cs * p[1] - sn * p[0], q};
	double W[3];
	if (footprint_wrench(fr, P, W)) {
		out[0] = -p[0];
		out[1] = -p[1];
		out[2] = -q;
		return;
	}
	out[0] = cs * W[0] - sn * W[1];
	out[1] = sn * W[0] + cs * W[1];
	out[2] = W[2];
}
