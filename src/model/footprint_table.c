/* The rate at which ground friction dissipates over a capsule's or an
 * ellipse's footprint, as a table over the twist's direction.
 *
 * Under uniform pressure, in units of mu M g = 1, the rate is
 *   D(v, omega) = (1/A) integral_S |v + omega z x r| dA
 * (footprint_friction.c), convex and homogeneous of degree 1: its gradient,
 * the friction's force and torque, depends on the twist's direction alone.
 * The footprints are symmetric in both axes of the body, so D is even in
 * v_x, v_y and omega each: the positive octant holds it all. There the
 * table takes the twist as q = (v_x / L_y, v_y / L_x, omega), L_x and L_y
 * the outline's reach along the body's x and y, so that the centre of
 * rotation c = z x v / omega of a twist is (-q_1 L_x, q_0 L_y) / q_2: the
 * outline spans q's unit square whatever its aspect. The octant's
 * directions are the three faces of the unit cube where one component is
 * the largest, m: face 0 (m = q_0) at (u, v) = (q_1, q_2) / m, face 1 at
 * (q_0, q_2) / q_1, face 2 at (q_0, q_1) / q_2, each in [0, 1]^2. On a
 * face D = m d(u, v), so that
 *   dD/dq_u = d_u,  dD/dq_v = d_v,  dD/dm = d - u d_u - v d_v,
 * and the Hessian is d's second derivatives over m (H q = 0 gives its
 * row and column along m). A face holds d, d_u, d_v and d_uv at the nodes
 * of an N x N grid, and each cell the bicubic Hermite interpolant of its
 * corners' (as its 16 coefficients): D, its gradient and its Hessian are
 * one function's, continuous with its gradient inside a face (the faces
 * meet to the table's error). Nodes on the planes q_k = 0 have d's
 * derivative across that plane 0 exactly, as D has (D is even there).
 * A node and a cell are computed when a twist first needs them: a table
 * holds only the directions a body has moved in, and a runner keeps it
 * for the next trial of the same outline (its values do not depend on
 * the order they were computed in).
 *
 * A node's values are integrals over the footprint about the twist's
 * centre of rotation (a node with omega = 0 only slides: D = |v|, its
 * gradient v / |v| and d_uv = 0). There u = omega z x (r - c), and along
 * the ray r = c + s e(theta) that meets S over s1 <= s <= s2 the integrands
 * are powers of s (omega > 0):
 *   A D          = omega integral (s2^3 - s1^3) / 3 dtheta
 *   A dD/dv      = integral z x e (s2^2 - s1^2) / 2 dtheta
 *   A dD/domega  = integral [(s2^3 - s1^3) / 3 + (e . c)(s2^2 - s1^2) / 2] dtheta
 *   A d2D        = integral b b^T (s2 - s1) dtheta / omega,  b = (e_x, e_y, c_x e_y - c_y e_x).
 * With c inside S the rays go all round (s1 = 0); outside, over the window
 * of rays that meet S, at whose ends (tangent rays) s2 - s1 grows as the
 * square root of the angle (ray_piece says how that is made smooth). The
 * rays through a capsule's four kinks, where its sides meet its caps, cut
 * the angle into pieces, each integrated by adaptive Gauss-Kronrod (7 and
 * 15 points) until the two rules agree within 1e-4 of each integral's
 * scale (the Kronrod sum is kept, far closer than that: the nodes' gradient
 * lies within 3e-5 of mu M g of a sum over patches in
 * test_footprint_friction, the patches' own error); a node whose c lies
 * near the outline takes more points.
 *
 * D is smooth but where c crosses the outline, where its Hessian has a
 * kink (the third derivative grows as a log): the table's error is
 * largest there and falls as 1 / N^2. N = 16 keeps it within 4e-4 of
 * mu M g and of mu M g r_s up to an aspect ratio of 4; thinner outlines
 * take N = 16 (aspect / 4)^(3/4) (test_footprint_friction: the table
 * against these integrals, and these against a sum over patches;
 * docs/files.md "A body that turns"). */
#include "model/footprint_table.h"
#include "util/fminmax.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846

enum { INTEGRALS = 5 };

/* the face's axes: its largest component, then u's and v's */
static const int face_axes[3][3] = {{0, 1, 2}, {1, 0, 2}, {2, 0, 1}};

/* ---- the outline along a ray ---- */

/* What the rays from one centre c share. */
typedef struct ray_origin {
	bsim_body_shape shape;
	double c[2];
	/* an ellipse: 1/a^2, 1/b^2, (c_x / a^2, c_y / b^2) and |c|^2 in those
	 * units less 1; a capsule: its rectangle's sides less c (x from, x to,
	 * y from, y to) and, for its end disks at (-l, 0) and (l, 0), c less
	 * the centre and that distance squared less r^2 */
	double k[8];
} ray_origin;

static ray_origin ray_origin_at(const bsim_footprint_table *t, const double c[2])
{
	const double p = t->half[0], r = t->half[1];
	ray_origin o = {.shape = t->shape, .c = {c[0], c[1]}};
	if (t->shape == BSIM_SHAPE_ELLIPSE) {
		o.k[0] = 1.0 / (p * p);
		o.k[1] = 1.0 / (r * r);
		o.k[2] = c[0] * o.k[0];
		o.k[3] = c[1] * o.k[1];
		o.k[4] = c[0] * o.k[2] + c[1] * o.k[3] - 1.0;
	} else {
		o.k[0] = -p - c[0];
		o.k[1] = p - c[0];
		o.k[2] = -r - c[1];
		o.k[3] = r - c[1];
		o.k[4] = c[0] + p; /* from (-l, 0) */
		o.k[5] = c[0] - p; /* from (l, 0) */
		o.k[6] = o.k[4] * o.k[4] + c[1] * c[1] - r * r;
		o.k[7] = o.k[5] * o.k[5] + c[1] * c[1] - r * r;
	}
	return o;
}

/* The ray c + s e (s >= 0) within the footprint: s1 <= s <= s2; 0 if it
 * misses. A capsule: within r of the segment (-l, 0)-(l, 0), the union
 * of its rectangle and its end disks (convex: one interval). */
static int ray_chord(const ray_origin *o, double ex, double ey, double *s1, double *s2)
{
	const double *k = o->k;
	double lo, hi;
	if (o->shape == BSIM_SHAPE_ELLIPSE) {
		const double qa = ex * ex * k[0] + ey * ey * k[1], qb = ex * k[2] + ey * k[3];
		const double disc = qb * qb - qa * k[4];
		if (!(disc > 0.0))
			return 0;
		const double root = sqrt(disc), inv = 1.0 / qa;
		lo = (-qb - root) * inv;
		hi = (-qb + root) * inv;
	} else {
		/* the rectangle: the slabs in x and in y */
		double a = -INFINITY, b = INFINITY;
		if (ex != 0.0) {
			const double inv = 1.0 / ex, x0 = k[0] * inv, x1 = k[1] * inv;
			a = ex > 0.0 ? x0 : x1;
			b = ex > 0.0 ? x1 : x0;
		} else if (k[0] > 0.0 || k[1] < 0.0) {
			b = a;
		}
		if (ey != 0.0) {
			const double inv = 1.0 / ey, y0 = k[2] * inv, y1 = k[3] * inv;
			a = bsim_fmax(a, ey > 0.0 ? y0 : y1);
			b = bsim_fmin(b, ey > 0.0 ? y1 : y0);
		} else if (k[2] > 0.0 || k[3] < 0.0) {
			b = a;
		}
		lo = a < b ? a : INFINITY;
		hi = a < b ? b : -INFINITY;
		/* the end disks */
		for (int end = 0; end < 2; end++) {
			const double qb = k[4 + end] * ex + o->c[1] * ey,
			             disc = qb * qb - k[6 + end];
			if (disc > 0.0) {
				const double root = sqrt(disc);
				lo = bsim_fmin(lo, -qb - root);
				hi = bsim_fmax(hi, -qb + root);
			}
		}
		if (!(lo < hi))
			return 0;
	}
	if (!(hi > 0.0))
		return 0;
	*s1 = lo > 0.0 ? lo : 0.0;
	*s2 = hi;
	return 1;
}

static int outline_holds(const bsim_footprint_table *t, const double c[2])
{
	if (t->shape == BSIM_SHAPE_ELLIPSE) {
		const double x = c[0] / t->half[0], y = c[1] / t->half[1];
		return x * x + y * y < 1.0;
	}
	const double dx = bsim_fmax(fabs(c[0]) - t->half[0], 0.0);
	return dx * dx + c[1] * c[1] < t->half[1] * t->half[1];
}

/* an angle taken to within pi of ref */
static double angle_near(double x, double ref)
{
	while (x > ref + PI)
		x -= 2.0 * PI;
	while (x < ref - PI)
		x += 2.0 * PI;
	return x;
}

/* The window [*a, *b] of rays from c (outside S) that meet S: the
 * tangents to a capsule's end disks, or to the ellipse (the disk's in
 * coordinates scaled by its axes, which keep tangency). */
static void ray_window(const bsim_footprint_table *t, const double c[2], double *a, double *b)
{
	const double ref = atan2(-c[1], -c[0]); /* towards the centre */
	double lo = INFINITY, hi = -INFINITY;
	if (t->shape == BSIM_SHAPE_ELLIPSE) {
		const double pa = t->half[0], pb = t->half[1];
		const double x = c[0] / pa, y = c[1] / pb, mid = atan2(-y, -x);
		const double spread = asin(bsim_fmin(1.0, 1.0 / hypot(x, y)));
		for (int k = -1; k <= 1; k += 2) {
			const double d = mid + k * spread;
			const double th = angle_near(atan2(pb * sin(d), pa * cos(d)), ref);
			lo = bsim_fmin(lo, th);
			hi = bsim_fmax(hi, th);
		}
	} else {
		for (int k = -1; k <= 1; k += 2) {
			const double dx = k * t->half[0] - c[0], dy = -c[1];
			const double mid = angle_near(atan2(dy, dx), ref);
			const double spread = asin(bsim_fmin(1.0, t->half[1] / hypot(dx, dy)));
			lo = bsim_fmin(lo, mid - spread);
			hi = bsim_fmax(hi, mid + spread);
		}
	}
	*a = lo;
	*b = hi;
}

/* ---- the integrals about the centre of rotation ---- */

/* The rays from c with directions theta = mid + phi, |phi| <= half <= pi/2,
 * taken by tau = tan(phi / 2), so that a direction costs no sine:
 * e = ((1 - tau^2), 2 tau) / (1 + tau^2) turned by mid, and
 * dphi = 2 dtau / (1 + tau^2). At an end where the rays leave the
 * footprint tangentially (s2 - s1 grows as the square root of the angle)
 * tau goes as the square of the parameter x in [0, 1], and the integrand
 * is smooth in x. */
typedef struct ray_piece {
	double cm, sm;     /* cos and sin of mid */
	double tau0, span; /* tau at x = 0, and its range */
	int tangent;       /* 1: the start is a tangent ray; 2: the end; 3: both */
	double share;      /* of the whole angle, for the tolerance */
} ray_piece;

typedef struct about {
	ray_origin o;
	int hess[2];           /* the Hessian's entry: two components of b (0, 1, 2) */
	double tol[INTEGRALS]; /* absolute, over all the rays */
} about;

/* The integrands at x on piece p, times the weights wk and wg, added to
 * kr and (if wg) ga. */
static void about_add(const about *ab, const ray_piece *p, double x, double wk, double wg,
                      double kr[INTEGRALS], double ga[INTEGRALS])
{
	double y = x, dy = 1.0;
	if (p->tangent == 1) {
		y = x * x;
		dy = 2.0 * x;
	} else if (p->tangent == 2) {
		y = x * (2.0 - x);
		dy = 2.0 * (1.0 - x);
	} else if (p->tangent == 3) {
		y = x * x * (3.0 - 2.0 * x);
		dy = 6.0 * x * (1.0 - x);
	}
	const double tau = p->tau0 + p->span * y, den = 1.0 / (1.0 + tau * tau);
	const double lx = (1.0 - tau * tau) * den, ly = 2.0 * tau * den;
	const double ex = p->cm * lx - p->sm * ly, ey = p->sm * lx + p->cm * ly;
	double s1, s2;
	if (!ray_chord(&ab->o, ex, ey, &s1, &s2))
		return;
	const double wt = 2.0 * den * p->span * dy;
	const double len = s2 - s1, sq = 0.5 * len * (s2 + s1);
	const double cube = len * (s2 * s2 + s2 * s1 + s1 * s1) * (1.0 / 3.0);
	const double ec = ex * ab->o.c[0] + ey * ab->o.c[1];
	const double b[3] = {ex, ey, ab->o.c[0] * ey - ab->o.c[1] * ex};
	const double f[INTEGRALS] = {wt * cube, -wt * ey * sq, wt * ex * sq, wt * (cube + ec * sq),
	                             wt * len * b[ab->hess[0]] * b[ab->hess[1]]};
	for (int i = 0; i < INTEGRALS; i++)
		kr[i] += wk * f[i];
	if (wg != 0.0)
		for (int i = 0; i < INTEGRALS; i++)
			ga[i] += wg * f[i];
}

/* Gauss-Kronrod 7-15 (QUADPACK's qk15): nodes on [-1, 1] from the end to
 * the middle, the Kronrod weights and the Gauss weights of the odd nodes. */
static const double gk_node[8] = {
        0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
        0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
        0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
        0.207784955007898467600689403773245, 0.0};
static const double gk_kronrod[8] = {
        0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
        0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
        0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
        0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
static const double gk_gauss[4] = {
        0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
        0.381830050505118944950369775488975, 0.417959183673469387755102040816327};

/* The integrals over x in [lo, hi] of piece p added to out, halving the
 * interval until the two rules agree within its share of the tolerance. */
static void about_integrate(const about *ab, const ray_piece *p, double lo, double hi, double share,
                            int depth, double out[INTEGRALS])
{
	double kr[INTEGRALS] = {0}, ga[INTEGRALS] = {0};
	const double mid = 0.5 * (lo + hi), half = 0.5 * (hi - lo);
	for (int k = 0; k < 8; k++) {
		const double wg = k % 2 ? gk_gauss[k / 2] : 0.0;
		about_add(ab, p, mid + half * gk_node[k], gk_kronrod[k], wg, kr, ga);
		if (k < 7)
			about_add(ab, p, mid - half * gk_node[k], gk_kronrod[k], wg, kr, ga);
	}
	int fine = 1;
	for (int i = 0; i < INTEGRALS && fine; i++)
		fine = fabs(kr[i] - ga[i]) * half <= share * ab->tol[i];
	if (fine || depth == 16) {
		for (int i = 0; i < INTEGRALS; i++)
			out[i] += kr[i] * half;
		return;
	}
	about_integrate(ab, p, lo, mid, 0.5 * share, depth + 1, out);
	about_integrate(ab, p, mid, hi, 0.5 * share, depth + 1, out);
}

static int compare_doubles(const void *a, const void *b)
{
	const double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

/* The rays between the angles from and to (to - from <= pi), tangent at
 * the ends the flags say, on a whole of the given width. */
static ray_piece ray_piece_make(double from, double to, int tangent, double whole)
{
	const double mid = 0.5 * (from + to), half = 0.5 * (to - from);
	ray_piece p = {.cm = cos(mid), .sm = sin(mid), .tangent = tangent};
	p.tau0 = -tan(0.5 * half);
	p.span = -2.0 * p.tau0;
	p.share = (to - from) / whole;
	return p;
}

/* The five integrals about c (above, A times the table's units, per
 * |omega| and sgn omega): out[0] of D, out[1..3] of its gradient, out[4]
 * of its Hessian's entry b_i b_j (i, j = hess). */
static void about_centre(const bsim_footprint_table *t, const double c[2], const int hess[2],
                         double out[INTEGRALS])
{
	about ab = {.o = ray_origin_at(t, c), .hess = {hess[0], hess[1]}};
	const double reach = t->half[0] + (t->shape == BSIM_SHAPE_CAPSULE ? t->half[1] : 0.0);
	const double far = hypot(c[0], c[1]) + reach;
	/* each integral's scale: D's A far, the force's A, the torque's A a,
	 * the Hessian's A / far times b's components (b_2 ~ far) */
	const double scale[INTEGRALS] = {t->area * far, t->area, t->area, t->area * t->arm,
	                                 t->area / far * (hess[0] == 2 ? far : 1.0) *
	                                         (hess[1] == 2 ? far : 1.0)};
	for (int i = 0; i < INTEGRALS; i++)
		ab.tol[i] = t->tolerance * scale[i];
	/* the rays through a capsule's kinks cut the angle into pieces */
	double cut[12];
	int n = 0;
	for (int i = 0; t->shape == BSIM_SHAPE_CAPSULE && i < 4; i++)
		cut[n++] = atan2((i & 1 ? 1 : -1) * t->half[1] - c[1],
		                 (i & 2 ? 1 : -1) * t->half[0] - c[0]);
	double lo, hi;
	const int outside = !outline_holds(t, c);
	if (!outside) {
		lo = n ? cut[0] : 0.0;
		hi = lo + 2.0 * PI;
	} else {
		ray_window(t, c, &lo, &hi);
	}
	int kept = 0;
	for (int i = 0; i < n; i++) {
		const double x = angle_near(cut[i], 0.5 * (lo + hi));
		if (x > lo && x < hi)
			cut[kept++] = x;
	}
	n = kept;
	cut[n++] = lo;
	cut[n++] = hi;
	qsort(cut, (size_t)n, sizeof *cut, compare_doubles);
	memset(out, 0, INTEGRALS * sizeof *out);
	for (int i = 0; i + 1 < n; i++) {
		const double from = cut[i], to = cut[i + 1];
		if (!(to > from))
			continue;
		/* halves of a piece wider than pi */
		const int halves = to - from > PI ? 2 : 1;
		for (int k = 0; k < halves; k++) {
			const double a = k ? 0.5 * (from + to) : from;
			const double b = k + 1 < halves ? 0.5 * (from + to) : to;
			const int tangent = outside ? (a == lo ? 1 : 0) | (b == hi ? 2 : 0) : 0;
			const ray_piece p = ray_piece_make(a, b, tangent, hi - lo);
			about_integrate(&ab, &p, 0.0, 1.0, p.share, 0, out);
		}
	}
}

/* The centre of rotation of the scaled twist q (q[2] > 0). */
static void centre_of(const bsim_footprint_table *t, const double q[3], double c[2])
{
	c[0] = -q[1] * t->scale[1] / q[2];
	c[1] = q[0] * t->scale[0] / q[2];
}

double bsim_footprint_table_exact(const bsim_footprint_table *t, const double q[3], double g[3])
{
	double in[INTEGRALS], c[2];
	centre_of(t, q, c);
	about_centre(t, c, (const int[2]){0, 0}, in);
	const double ia = 1.0 / t->area;
	/* D is even in q_0 and q_1: its derivative across is 0 */
	g[0] = q[0] == 0.0 ? 0.0 : in[1] * ia * t->scale[0];
	g[1] = q[1] == 0.0 ? 0.0 : in[2] * ia * t->scale[1];
	g[2] = in[3] * ia;
	return q[2] * in[0] * ia;
}

/* ---- the table ---- */

/* Computes node at (its index in the table). */
static void table_node(bsim_footprint_table *t, size_t at)
{
	double *e = t->node + 4 * at;
	const size_t side = (size_t)t->cells + 1;
	const int face = (int)(at / (side * side)), i = (int)(at / side % side),
	          j = (int)(at % side);
	const int *ax = face_axes[face];
	const double h = 1.0 / t->cells;
	double q[3], g[3];
	q[ax[0]] = 1.0;
	q[ax[1]] = i * h;
	q[ax[2]] = j * h;
	const double *k = t->scale;
	if (q[2] == 0.0) { /* only sliding */
		const double v[2] = {k[0] * q[0], k[1] * q[1]};
		e[0] = hypot(v[0], v[1]);
		g[0] = k[0] * v[0] / e[0];
		g[1] = k[1] * v[1] / e[0];
		g[2] = 0.0;
		e[3] = 0.0;
	} else {
		/* d_uv: D's Hessian entry (q_u, q_v), b's components u and v */
		double in[INTEGRALS], c[2];
		centre_of(t, q, c);
		about_centre(t, c, (const int[2]){ax[1], ax[2]}, in);
		const double ia = 1.0 / t->area;
		e[0] = q[2] * in[0] * ia;
		g[0] = in[1] * ia * k[0];
		g[1] = in[2] * ia * k[1];
		g[2] = in[3] * ia;
		e[3] = in[4] * ia / q[2] * k[ax[1]] * k[ax[2]];
		/* D is even in each component: its derivative across a plane
		 * q_k = 0 is 0 there, and so is the Hessian's entry across it */
		for (int l = 0; l < 2; l++) {
			if (q[l] == 0.0) {
				g[l] = 0.0;
				e[3] = 0.0;
			}
		}
	}
	/* stored times the cell's width h, h^2: as the interpolant takes them */
	e[1] = h * g[ax[1]];
	e[2] = h * g[ax[2]];
	e[3] *= h * h;
	t->built[at] = 1;
	t->nodes_built++;
}

/* The cell (face, i, j)'s bicubic d = sum a_kl s^k r^l (k, l = 0..3; s and
 * r from 0 to 1 across the cell, u = (i + s) / N, v = (j + r) / N): the
 * Hermite interpolant of its corners' d, d_s, d_r, d_sr, A = B C B^T with C
 * those (rows: s = 0, s = 1, d_s at 0, at 1; columns the same in r) and B
 * the monomial coefficients of the Hermite basis. */
static const double *table_cell(bsim_footprint_table *t, int face, int i, int j)
{
	const int n = t->cells;
	const size_t at = ((size_t)face * (size_t)n + (size_t)i) * (size_t)n + (size_t)j;
	double *a = t->cell + 16 * at;
	if (t->cell_built[at])
		return a;
	const size_t side = (size_t)n + 1;
	const size_t corner = ((size_t)face * side + (size_t)i) * side + (size_t)j;
	const size_t nodes[4] = {corner, corner + 1, corner + side, corner + side + 1};
	for (int k = 0; k < 4; k++)
		if (!t->built[nodes[k]])
			table_node(t, nodes[k]);
	const double *e[2][2] = {{t->node + 4 * nodes[0], t->node + 4 * nodes[1]},
	                         {t->node + 4 * nodes[2], t->node + 4 * nodes[3]}};
	double C[4][4];
	for (int x = 0; x < 2; x++) {
		for (int y = 0; y < 2; y++) {
			C[x][y] = e[x][y][0];
			C[x][2 + y] = e[x][y][2];
			C[2 + x][y] = e[x][y][1];
			C[2 + x][2 + y] = e[x][y][3];
		}
	}
	static const double B[4][4] = {{1, 0, 0, 0}, {0, 0, 1, 0}, {-3, 3, -2, -1}, {2, -2, 1, 1}};
	double BC[4][4];
	for (int k = 0; k < 4; k++)
		for (int l = 0; l < 4; l++)
			BC[k][l] = B[k][0] * C[0][l] + B[k][1] * C[1][l] + B[k][2] * C[2][l] +
			           B[k][3] * C[3][l];
	for (int k = 0; k < 4; k++)
		for (int l = 0; l < 4; l++)
			a[4 * k + l] = BC[k][0] * B[l][0] + BC[k][1] * B[l][1] +
			               BC[k][2] * B[l][2] + BC[k][3] * B[l][3];
	t->cell_built[at] = 1;
	return a;
}

double bsim_footprint_table_eval(bsim_footprint_table *t, const double q[3], double g[3],
                                 double H[6])
{
	const double p[3] = {fabs(q[0]), fabs(q[1]), fabs(q[2])};
	const int face = p[0] >= p[1] && p[0] >= p[2] ? 0 : p[1] >= p[2] ? 1 : 2;
	const int *ax = face_axes[face];
	const int n = t->cells;
	const double m = p[ax[0]];
	if (!(m > 0.0)) { /* at rest: D's least value, and no direction */
		g[0] = g[1] = g[2] = 0.0;
		for (int k = 0; H && k < 6; k++)
			H[k] = 0.0;
		return 0.0;
	}
	const double im = 1.0 / m, u = p[ax[1]] * im, v = p[ax[2]] * im;
	double s = u * n, r = v * n;
	int i = (int)s, j = (int)r;
	i = i < n ? i : n - 1;
	j = j < n ? j : n - 1;
	s -= i;
	r -= j;
	const double *a = table_cell(t, face, i, j);
	/* along r for each power of s: the value, and its first and second
	 * derivatives in r; then along s */
	double P[4], Pr[4], Prr[4];
	for (int k = 0; k < 4; k++) {
		const double *c = a + 4 * k;
		P[k] = c[0] + r * (c[1] + r * (c[2] + r * c[3]));
		Pr[k] = c[1] + r * (2.0 * c[2] + 3.0 * r * c[3]);
		Prr[k] = 2.0 * c[2] + 6.0 * r * c[3];
	}
	const double d = P[0] + s * (P[1] + s * (P[2] + s * P[3]));
	const double ds = P[1] + s * (2.0 * P[2] + 3.0 * s * P[3]);
	const double dr = Pr[0] + s * (Pr[1] + s * (Pr[2] + s * Pr[3]));
	const double du = ds * n, dv = dr * n;
	/* the signs of q's components along the face's axes */
	const double s0 = q[ax[0]] < 0 ? -1.0 : 1.0, s1 = q[ax[1]] < 0 ? -1.0 : 1.0;
	const double s2 = q[ax[2]] < 0 ? -1.0 : 1.0;
	g[ax[0]] = s0 * (d - u * du - v * dv);
	g[ax[1]] = s1 * du;
	g[ax[2]] = s2 * dv;
	if (H) {
		const double dss = 2.0 * P[2] + 6.0 * s * P[3];
		const double dsr = Pr[1] + s * (2.0 * Pr[2] + 3.0 * s * Pr[3]);
		const double drr = Prr[0] + s * (Prr[1] + s * (Prr[2] + s * Prr[3]));
		const double k = n * n * im, huu = dss * k, huv = dsr * k, hvv = drr * k;
		const double hmu = -(u * huu + v * huv), hmv = -(u * huv + v * hvv);
		const double hmm = -(u * hmu + v * hmv);
		/* back to q's components (00 01 02 11 12 22): face 0 is q's
		 * order, face 1 exchanges q_0 and q_1, face 2 takes (q_2, q_0, q_1) */
		if (face == 0) {
			H[0] = hmm;
			H[1] = s0 * s1 * hmu;
			H[2] = s0 * s2 * hmv;
			H[3] = huu;
			H[4] = s1 * s2 * huv;
			H[5] = hvv;
		} else if (face == 1) {
			H[0] = huu;
			H[1] = s0 * s1 * hmu;
			H[2] = s1 * s2 * huv;
			H[3] = hmm;
			H[4] = s0 * s2 * hmv;
			H[5] = hvv;
		} else {
			H[0] = huu;
			H[1] = s1 * s2 * huv;
			H[2] = s0 * s1 * hmu;
			H[3] = hvv;
			H[4] = s0 * s2 * hmv;
			H[5] = hmm;
		}
	}
	return m * d;
}

bsim_footprint_table *bsim_footprint_table_alloc(const bsim_body_def *body)
{
	bsim_footprint_table *t = calloc(1, sizeof *t);
	if (!t)
		return NULL;
	t->shape = body->shape;
	if (body->shape == BSIM_SHAPE_CAPSULE) {
		t->half[0] = body->length / 2;
		t->half[1] = body->radius;
	} else {
		t->half[0] = body->semi_axes[0];
		t->half[1] = body->semi_axes[1];
	}
	t->area = bsim_body_area(body);
	/* q = (v_x / L_y, v_y / L_x, omega): the centre of rotation of a
	 * twist on face 2 is at (-v L_x, u L_y), the outline's reach L_x
	 * along x and L_y across */
	const double reach = t->half[0] + (t->shape == BSIM_SHAPE_CAPSULE ? t->half[1] : 0.0);
	t->scale[0] = t->half[1];
	t->scale[1] = reach;
	t->scale[2] = 1.0;
	/* N = 16 up to an aspect ratio of 4 (length over width), finer for
	 * thinner outlines, whose error grows with it (docs/files.md) */
	const double aspect =
	        bsim_fmax(t->scale[0], t->scale[1]) / bsim_fmin(t->scale[0], t->scale[1]);
	t->cells = aspect <= 4.0 ? 16 : (int)bsim_fmin(64.0, ceil(16.0 * pow(aspect / 4.0, 0.75)));
	t->tolerance = 1e-4;
	const size_t nodes = 3 * (size_t)(t->cells + 1) * (size_t)(t->cells + 1);
	const size_t cells = 3 * (size_t)t->cells * (size_t)t->cells;
	t->node = malloc(4 * nodes * sizeof *t->node);
	t->built = calloc(nodes, 1);
	t->cell = malloc(16 * cells * sizeof *t->cell);
	t->cell_built = calloc(cells, 1);
	if (!t->node || !t->built || !t->cell || !t->cell_built) {
		bsim_footprint_table_free(t);
		return NULL;
	}
	/* a = (1/A) integral |r| dA: D of spinning alone at omega = 1 */
	double in[INTEGRALS];
	t->arm = 1.0; /* the tolerance's torque scale, for this integral */
	about_centre(t, (const double[2]){0.0, 0.0}, (const int[2]){0, 0}, in);
	t->arm = in[0] / t->area;
	return t;
}

void bsim_footprint_table_free(bsim_footprint_table *t)
{
	if (!t)
		return;
	free(t->node);
	free(t->built);
	free(t->cell);
	free(t->cell_built);
	free(t);
}

int bsim_footprint_table_fits(const bsim_footprint_table *t, const bsim_body_def *body)
{
	if (body->shape != t->shape)
		return 0;
	if (body->shape == BSIM_SHAPE_CAPSULE)
		return t->half[0] == body->length / 2 && t->half[1] == body->radius;
	return t->half[0] == body->semi_axes[0] && t->half[1] == body->semi_axes[1];
}
