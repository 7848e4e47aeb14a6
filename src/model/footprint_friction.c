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
 *   eps >= 1:   f = 4 (E + K - D) / (3 pi),       t = 4 [2 D + 4 E - 5 K + 3 k^2 K] / (9 pi k),
 *   df/deps = 4 (2 E - K + D) / (3 pi) and 4 k (2 K - 2 D - E) / (3 pi).
 * f rises from 0 (f ~ eps) to 1 and t falls from 2/3 to 0 (t ~ 1 / (4 eps)),
 * both continuous at eps = 1 (8 / (3 pi), 8 / (9 pi)), and t' = -eps f'.
 * (Phi checked against a numerical double integral at eps = 0.1 to 10;
 * f and t by test_footprint_friction against a sum over a million patches.)
 * K, E and D come from the arithmetic-geometric mean of 1 and
 * k' = sqrt(1 - k^2): K = pi / (2 a_inf), D = K S, E = K (1 - k^2 S),
 * S = 1/2 + k^2 T, T = sum_(n >= 1) 2^(n-1) (c_n / k)^2, c_n = c_(n-1)^2 / (4 a_n),
 * c_0 = k, written so that nothing cancels as k -> 0 (where t's bracket
 * outside the rim is k^2 (1 + 2 T (1 - 2 k^2))). The disk's limit set in
 * (|F|, |T|) lies under the curve mu M g (f, R t), whose normal at eps is
 * the twist (eps R, 1): the step comes down to one equation in
 * th = atan(eps), solved by Newton's method within a bracket.
 *
 * A capsule and an ellipse by the table of D over the twist's direction
 * (footprint_table.c), in its scaled twist q (xi_k = k_k q_k, k the
 * table's scale; the wrench k_k P_k and the masses k_k^2 M_k with it). D is
 * even in each of q's components (the footprints' two mirror axes), so
 * the step's end twist has the signs of P's components, each or 0 (grad D
 * has the signs of q's, and M q' = P - grad D(q')). The step is solved for
 * |P| in the positive octant and the signs put back: with the body's frame
 * mirrored to the bit (body_frame), a body and its mirror image get
 * mirrored friction to the bit. There Newton's method on the table's D
 * (its Hessian that of the interpolant), from the best point on the ray of
 * the twist without friction M^-1 P, halving the step while Psi does not
 * fall. Once the Newton decrement is below 1e-9 of the twist's size
 * q^T M q (the step below about 3e-5 of the twist; what it leaves is of
 * the step's square) the last step is taken without a new look-up, and
 * friction is the wrench that takes the body to that twist, M xi' - P:
 * test_footprint_friction finds it within 1e-8 of the limits of the end
 * twist's own friction. While the body slides fast that is two look-ups
 * a step: at the twist without friction, and after one Newton step. */
#include "model/footprint_friction.h"

#include <math.h>
#include <stdlib.h>

#define PI 3.14159265358979323846

/* ---- the disk ---- */

/* K(k) for 0 <= k < 1, and T (above), by the arithmetic-geometric mean. */
static double disk_agm(double k, double *T)
{
	double a = 1.0, b = sqrt((1.0 - k) * (1.0 + k)), r = 0.25, w = 1.0, sum = 0.0;
	for (int n = 1; n < 40; n++) {
		const double next = 0.5 * (a + b);
		r = (n == 1 ? 1.0 : k * k * r * r) / (4.0 * next); /* c_n / k */
		b = sqrt(a * b);
		a = next;
		sum += w * r * r;
		w *= 2.0;
		if (k * k * r <= 1e-17 * a) /* c_n: a and b agree to it */
			break;
	}
	*T = sum;
	return PI / (2.0 * a);
}

/* f and t at th = atan(eps) in [0, pi/2], given as its sine and cosine,
 * and their derivatives in th. */
static void disk_limit(double sn, double cs, double *f, double *t, double *df, double *dt)
{
	const int outside = sn > cs; /* eps > 1: the centre of rotation beyond the rim */
	const double k = outside ? cs / sn : sn / cs, k2 = k * k;
	if (k2 >= 1.0) {
		*f = 8.0 / (3.0 * PI);
		*t = 8.0 / (9.0 * PI);
		*df = 2.0 * 4.0 / (3.0 * PI); /* df/deps (1 + eps^2), E(1) = 1 */
		*dt = -*df;
		return;
	}
	double T;
	const double K = disk_agm(k, &T), S = 0.5 + k2 * T;
	if (!outside) {
		const double slope =
		        4.0 * K * (1.0 + S * (1.0 - 2.0 * k2)) / (3.0 * PI); /* df/deps */
		*f = 4.0 * k * K * (2.0 - S * (1.0 + k2)) / (3.0 * PI);
		*t = 4.0 * K * ((4.0 - 2.0 * k2) * (1.0 - k2 * S) - (1.0 - k2)) / (9.0 * PI);
		*df = slope / (cs * cs);
		*dt = -k * *df;
	} else {
		/* df/deps = k^3 slope, deps/dth = 1 / cs^2 */
		const double slope = 4.0 * K * (0.5 - T * (2.0 - k2)) / (3.0 * PI);
		*f = 4.0 * K * (2.0 - S * (1.0 + k2)) / (3.0 * PI);
		*t = 4.0 * K * k * (1.0 + 2.0 * T * (1.0 - 2.0 * k2)) / (9.0 * PI);
		*df = slope * cs / (sn * sn * sn);
		*dt = -slope / (sn * sn);
	}
}

/* A disk's step: |p| = ps, |q| = qs (both > 0), M, J, R, limit F_l. */
typedef struct disk_step {
	double ps, qs, mass, inertia, radius, force_limit, torque_limit; /* torque: F_l R */
} disk_step;

static void disk_limit_at(double th, double *sn, double *cs, double *f, double *t, double *df,
                          double *dt)
{
	*sn = th >= PI / 2 ? 1.0 : sin(th);
	*cs = th >= PI / 2 ? 0.0 : cos(th);
	disk_limit(*sn, *cs, f, t, df, dt);
}

/* The step's end twist against the wrench it gets at th: with that
 * wrench, F_l (f, R t)(th), the body ends the step at s = h (ps - F_l f) / M
 * and omega = h (qs - F_l R t) / J, which must lie along the twist of th,
 * (R omega, s) along (cos th, sin th):
 *   J (ps - F_l f) cos th - M R (qs - F_l R t) sin th = 0;
 * *slope its derivative in th. */
static double disk_direction(double th, const void *ctx, double *slope)
{
	const disk_step *d = ctx;
	double sn, cs, f, t, df, dt;
	disk_limit_at(th, &sn, &cs, &f, &t, &df, &dt);
	const double a = d->inertia * (d->ps - d->force_limit * f);
	const double b = d->mass * d->radius * (d->qs - d->torque_limit * t);
	*slope = -d->inertia * d->force_limit * df * cs - a * sn +
	         d->mass * d->radius * d->torque_limit * dt * sn - b * cs;
	return a * cs - b * sn;
}

/* The torque limit at th against qs: F_l R t(th) - qs, falling in th. */
static double disk_spin(double th, const void *ctx, double *slope)
{
	const disk_step *d = ctx;
	double sn, cs, f, t, df, dt;
	disk_limit_at(th, &sn, &cs, &f, &t, &df, &dt);
	*slope = d->torque_limit * dt;
	return d->torque_limit * t - d->qs;
}

/* The root of fn between a and b, fn(a) = fa >= 0 >= fb = fn(b), by
 * Newton's method from x, kept within the bracket (bisecting where a step
 * leaves it). Once a step is below 1e-7 rad its end is the root (its
 * error the step's square). */
static double root_between(double (*fn)(double, const void *, double *), const void *ctx, double a,
                           double fa, double b, double fb, double x)
{
	if (fa == 0.0)
		return a;
	if (fb == 0.0)
		return b;
	if (!(x > a && x < b))
		x = 0.5 * (a + b);
	for (int i = 0; i < 100; i++) {
		double slope, fx = fn(x, ctx, &slope);
		if (fx == 0.0)
			return x;
		if (fx > 0.0)
			a = x;
		else
			b = x;
		double next = x - fx / slope;
		if (!(next > a && next < b))
			next = 0.5 * (a + b);
		if (fabs(next - x) <= 1e-7 || b - a <= 4e-16)
			return next;
		x = next;
	}
	return x;
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
	double lo = 0.0, sn, cs, f, t, df, dt, slope;
	if (ps <= d.force_limit && qs <= fr->spin_limit) {
		/* within the limit set if ps is below the force the curve has
		 * where its torque is qs */
		lo = root_between(disk_spin, &d, 0.0, disk_spin(0.0, &d, &slope), PI / 2, -qs, NAN);
		disk_limit_at(lo, &sn, &cs, &f, &t, &df, &dt);
		if (ps <= d.force_limit * f)
			return 1;
	}
	/* Past lo (where the spin would just stop) the equation has one root;
	 * the free twist's direction is the first guess. At th = 0 (f = 0,
	 * t = 2/3) the equation's left side is J ps, at pi/2 (f = 1, t = 0)
	 * -M R qs. */
	double guess = atan2(fr->inertia * ps, fr->mass * fr->radius * qs);
	double th = root_between(disk_direction, &d, lo,
	                         lo > 0.0 ? disk_direction(lo, &d, &slope) : fr->inertia * ps,
	                         PI / 2, -fr->mass * fr->radius * qs, guess);
	disk_limit_at(th, &sn, &cs, &f, &t, &df, &dt);
	out[0] = -d.force_limit * f;
	out[1] = 0.0;
	out[2] = -d.torque_limit * t;
	return 0;
}

/* ---- a capsule or an ellipse: Newton's method on the table ---- */

/* x = A^-1 b for the symmetric positive definite A (upper triangle 00 01
 * 02 11 12 22), by Cholesky; returns 0 if A is not. */
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
 * as soon as D(n) < 1; n holds that point, and *D, g and H its D, gradient
 * and Hessian. */
static int footprint_outside(bsim_footprint_friction *fr, const double P[3], double n[3], double *D,
                             double g[3], double H[6])
{
	const double pp = dot3(P, P);
	for (int it = 0; it < 60; it++) {
		double x1[3], x2[3], d[3];
		const double Dn = bsim_footprint_table_eval(fr->table, n, g, H);
		*D = Dn;
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
			double m[3], gm[3];
			for (int k = 0; k < 3; k++)
				m[k] = n[k] + step * d[k];
			const double on = dot3(P, m);
			for (int k = 0; k < 3; k++)
				m[k] /= on;
			if (bsim_footprint_table_eval(fr->table, m, gm, NULL) <=
			    Dn - 1e-4 * step * decrement) {
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

/* The step's wrench W (scaled frame, all of P's components >= 0, not
 * all 0) for the stopping wrench P; m the scaled masses; all in units of
 * mu M g (D's); 1 if the body sticks (W = -P). */
static int footprint_wrench(bsim_footprint_friction *fr, const double m[3], const double P[3],
                            double W[3])
{
	const double free_twist[3] = {P[0] / m[0], P[1] / m[1], P[2] / m[2]}; /* M^-1 P */
	const double scale = dot3(P, free_twist);                             /* P^T M^-1 P */
	/* The start: a point where Psi is below its value at rest, so that
	 * the minimum is not there: the best point on the free twist's ray
	 * (the twist without friction, M^-1 P), along which Psi(t n) falls from
	 * rest while D(n) < P . n, or failing that the point on another ray
	 * that footprint_outside finds, or none: at rest. D's gradient is the
	 * same along a ray and its Hessian falls as 1/t. */
	double q[3] = {free_twist[0], free_twist[1], free_twist[2]}, g[3], H[6], D, t;
	D = bsim_footprint_table_eval(fr->table, q, g, H);
	if (D < scale) {
		t = 1.0 - D / scale;
	} else {
		for (int k = 0; k < 3; k++)
			q[k] = free_twist[k] / scale;
		if (!footprint_outside(fr, P, q, &D, g, H))
			return 1;
		t = (1.0 - D) / (m[0] * q[0] * q[0] + m[1] * q[1] * q[1] + m[2] * q[2] * q[2]);
	}
	const double inv = 1.0 / t;
	for (int k = 0; k < 3; k++)
		q[k] *= t;
	for (int k = 0; k < 6; k++)
		H[k] *= inv;
	D *= t;
	/* Newton's method on Psi(q) = 1/2 (q - M^-1 P)^T M (q - M^-1 P) + D(q),
	 * halving the step while Psi does not fall enough. */
	for (int it = 0; it < 60; it++) {
		double grad[3], d[3], A[6];
		for (int k = 0; k < 3; k++)
			grad[k] = m[k] * (q[k] - free_twist[k]) + g[k];
		for (int k = 0; k < 6; k++)
			A[k] = H[k];
		A[0] += m[0];
		A[3] += m[1];
		A[5] += m[2];
		if (!solve3(A, grad, d))
			break;
		/* g^T A^-1 g against the twist's size q^T M q: a step below
		 * 3e-5 of the twist is the last, taken without a new look-up */
		const double decrement = dot3(grad, d);
		const double size = m[0] * q[0] * q[0] + m[1] * q[1] * q[1] + m[2] * q[2] * q[2];
		if (!(decrement > 1e-9 * size)) {
			for (int k = 0; k < 3; k++)
				q[k] -= d[k];
			break;
		}
		double psi = D;
		for (int k = 0; k < 3; k++)
			psi += 0.5 * m[k] * (q[k] - free_twist[k]) * (q[k] - free_twist[k]);
		double step = 1.0;
		for (;;) {
			double at[3], gt[3], Ht[6];
			for (int k = 0; k < 3; k++)
				at[k] = q[k] - step * d[k];
			const double Dt = bsim_footprint_table_eval(fr->table, at, gt, Ht);
			double psi_t = Dt;
			for (int k = 0; k < 3; k++)
				psi_t += 0.5 * m[k] * (at[k] - free_twist[k]) *
				         (at[k] - free_twist[k]);
			if (psi_t <= psi - 1e-4 * step * decrement) {
				for (int k = 0; k < 3; k++) {
					q[k] = at[k];
					g[k] = gt[k];
				}
				for (int k = 0; k < 6; k++)
					H[k] = Ht[k];
				D = Dt;
				break;
			}
			step *= 0.5;
			if (step < 1e-10)
				break;
		}
		if (step < 1e-10)
			break; /* no progress: Psi's round-off */
	}
	/* The wrench that takes the body to the twist found, which lies in
	 * P's octant (the minimum does). */
	for (int k = 0; k < 3; k++)
		W[k] = m[k] * (q[k] > 0.0 ? q[k] : 0.0) - P[k];
	return 0;
}

/* ---- the effect ---- */

bsim_footprint_friction *bsim_footprint_friction_alloc(const bsim_body_def *body, double mu,
                                                       double g, bsim_footprint_friction *spare)
{
	bsim_footprint_friction *fr = spare ? spare : calloc(1, sizeof *fr);
	if (!fr)
		return NULL;
	bsim_footprint_table *table = fr->table;
	if (table && (body->shape == BSIM_SHAPE_DISK || !bsim_footprint_table_fits(table, body))) {
		bsim_footprint_table_free(table);
		table = NULL;
	}
	fr->table = NULL;
	fr->shape = body->shape;
	fr->mass = body->mass;
	fr->inertia = bsim_body_inertia(body);
	fr->force_limit = mu * body->mass * g;
	fr->radius = 0.0;
	if (body->shape == BSIM_SHAPE_DISK) {
		fr->radius = body->radius;
		fr->spin_limit = fr->force_limit * (2.0 * body->radius / 3.0);
		return fr;
	}
	fr->table = table ? table : bsim_footprint_table_alloc(body);
	if (!fr->table) {
		bsim_footprint_friction_free(fr);
		return NULL;
	}
	fr->spin_limit = fr->force_limit * fr->table->arm;
	return fr;
}

void bsim_footprint_friction_free(bsim_footprint_friction *fr)
{
	if (!fr)
		return;
	bsim_footprint_table_free(fr->table);
	free(fr);
}

/* The body's frame (cos psi, sin psi) as (-sin x, cos x), x = (psi - (pi -
 * psi)) / 2 = psi - pi/2: a body's mirror image, heading pi - psi, has -x
 * to the bit (subtraction is antisymmetric), and so the mirror image of
 * its frame (sine odd, cosine even), with one sine and cosine. */
static void body_frame(double heading, double *cs, double *sn)
{
	const double x = 0.5 * (heading - (PI - heading));
	*cs = -sin(x);
	*sn = cos(x);
}

void bsim_footprint_friction_wrench(bsim_footprint_friction *fr, double heading, const double p[2],
                                    double q, double out[3])
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
	/* In the body's frame and the table's scaled twist q (xi_k = k_k q_k),
	 * in units of mu M g: the wrench k_k P_k, the masses k_k^2 M_k; the
	 * octant of P's signs. */
	double cs, sn;
	body_frame(heading, &cs, &sn);
	const double *k = fr->table->scale, unit = 1.0 / limit;
	const double P[3] = {cs * p[0] + sn * p[1], cs * p[1] - sn * p[0], q};
	const double m[3] = {fr->mass * k[0] * k[0] * unit, fr->mass * k[1] * k[1] * unit,
	                     fr->inertia * k[2] * k[2] * unit};
	const double Pa[3] = {fabs(P[0]) * k[0] * unit, fabs(P[1]) * k[1] * unit,
	                      fabs(P[2]) * k[2] * unit};
	double W[3];
	if (footprint_wrench(fr, m, Pa, W)) {
		out[0] = -p[0];
		out[1] = -p[1];
		out[2] = -q;
		return;
	}
	for (int l = 0; l < 3; l++)
		W[l] = (P[l] < 0.0 ? -W[l] : W[l]) * limit / k[l];
	out[0] = cs * W[0] - sn * W[1];
	out[1] = sn * W[0] + cs * W[1];
	out[2] = W[2];
}

void bsim_footprint_friction_of_twist(bsim_footprint_friction *fr, const double twist[3],
                                      double out[3])
{
	const double v = hypot(twist[0], twist[1]), w = twist[2];
	if (fr->shape == BSIM_SHAPE_DISK) {
		double sn, cs, f, t, df, dt;
		disk_limit_at(atan2(v, fr->radius * fabs(w)), &sn, &cs, &f, &t, &df, &dt);
		out[0] = v > 0.0 ? -fr->force_limit * f * twist[0] / v : 0.0;
		out[1] = v > 0.0 ? -fr->force_limit * f * twist[1] / v : 0.0;
		out[2] = -fr->force_limit * fr->radius * t * (w > 0.0 ? 1.0 : w < 0.0 ? -1.0 : 0.0);
		return;
	}
	const double *k = fr->table->scale;
	const double q[3] = {twist[0] / k[0], twist[1] / k[1], twist[2] / k[2]};
	double g[3];
	bsim_footprint_table_eval(fr->table, q, g, NULL);
	for (int l = 0; l < 3; l++)
		out[l] = -g[l] / k[l] * fr->force_limit;
}
