/* The ellipse against a beam's segment (bsim_body_shape_ellipse_segment,
 * beamsim/body_shape.h) against independent truths:
 *
 * - a circle (a = c) against the disk's closed form: dist = |x - S| - r
 *   (apart and overlapping), n from the segment's nearest point to x;
 * - a segment parallel to an axis at known offset (closed form: dist the
 *   offset, on_body the end of the axis), and a segment along the major
 *   axis pointing at its end (a tip at known distance);
 * - brute force for several hundred random configurations (segments beside
 *   the outline, tips pointing at it, segments anywhere, overlaps from
 *   slight to deep): apart, the least distance between the outline sampled
 *   in its angle parameter (and refined by golden section) and the segment;
 *   overlapping, the largest separation max_n [min over the outline of n.B
 *   - max(n.p0, n.p1)] over directions sampled and refined, and the body
 *   moved by (-dist + delta) n found exactly delta from the segment by the
 *   sampled outline and moved by (-dist - delta) n still overlapping;
 * - invariance under rotating and mirroring the scene, exchanging the
 *   segment's ends, and naming the same ellipse by (c, a, psi + pi/2);
 * - continuity: as the segment slides round the outline, dist changes by no
 *   more than the segment's ends move (signed distance is 1-Lipschitz);
 * - degenerate input is BSIM_EFAIL.
 * It also measures the cost per call (printed, not checked). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <time.h>

#include <cmocka.h>

#include "beamsim/body_shape.h"

#define PI 3.14159265358979323846

typedef struct config {
	double a, c, x[2], psi, p0[2], p1[2];
} config;

/* A fixed-seed generator (splitmix64): the same configurations every run. */
static uint64_t rng_state = 0x9e3779b97f4a7c15u;
static double uniform(double lo, double hi)
{
	uint64_t z = (rng_state += 0x9e3779b97f4a7c15u);
	z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
	z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
	z ^= z >> 31;
	return lo + (hi - lo) * ((double)(z >> 11) / 9007199254740992.0);
}

static int contact(const config *k, bsim_body_segment_contact *o)
{
	return bsim_body_shape_ellipse_segment(k->a, k->c, k->x, k->psi, k->p0, k->p1, o);
}

/* The outline's point at angle parameter th. */
static void outline(const config *k, double th, double b[2])
{
	double cu = k->a * cos(th), cv = k->c * sin(th);
	b[0] = k->x[0] + cu * cos(k->psi) - cv * sin(k->psi);
	b[1] = k->x[1] + cu * sin(k->psi) + cv * cos(k->psi);
}

/* The distance from q to the segment, and the nearest point's parameter. */
static double segment_distance(const config *k, const double q[2], double *t_out)
{
	double d[2] = {k->p1[0] - k->p0[0], k->p1[1] - k->p0[1]};
	double t =
	        ((q[0] - k->p0[0]) * d[0] + (q[1] - k->p0[1]) * d[1]) / (d[0] * d[0] + d[1] * d[1]);
	t = fmin(fmax(t, 0.0), 1.0);
	if (t_out)
		*t_out = t;
	return hypot(q[0] - k->p0[0] - t * d[0], q[1] - k->p0[1] - t * d[1]);
}

/* (X/a)^2 + (Y/c)^2 in the body's frame: < 1 inside. */
static double implicit(const config *k, const double q[2])
{
	double r[2] = {q[0] - k->x[0], q[1] - k->x[1]};
	double X = r[0] * cos(k->psi) + r[1] * sin(k->psi);
	double Y = -r[0] * sin(k->psi) + r[1] * cos(k->psi);
	return (X / k->a) * (X / k->a) + (Y / k->c) * (Y / k->c);
}

/* Does the segment reach inside the ellipse? The implicit function along
 * the segment, a quadratic in its parameter, at its least. */
static int overlapping(const config *k)
{
	double v0 = implicit(k, k->p0), v1 = implicit(k, k->p1);
	double pm[2] = {0.5 * (k->p0[0] + k->p1[0]), 0.5 * (k->p0[1] + k->p1[1])};
	double vm = implicit(k, pm);
	/* f(t) = A t^2 + B t + C through f(0), f(1/2), f(1) */
	double A = 2 * v0 - 4 * vm + 2 * v1, B = -3 * v0 + 4 * vm - v1;
	double t = A > 0 ? fmin(fmax(-B / (2 * A), 0.0), 1.0) : 0.0;
	double f = fmin(fmin(v0, v1), v0 + t * (B + A * t));
	return f < 1.0;
}

/* Golden-section search for the least of f on [lo, hi]. */
typedef double (*fun)(const config *k, double s);
static double golden_min(const config *k, fun f, double lo, double hi, double *arg)
{
	const double r = 0.6180339887498949;
	double x1 = hi - r * (hi - lo), x2 = lo + r * (hi - lo);
	double f1 = f(k, x1), f2 = f(k, x2);
	for (int i = 0; i < 80; i++) {
		if (f1 < f2) {
			hi = x2, x2 = x1, f2 = f1;
			x1 = hi - r * (hi - lo), f1 = f(k, x1);
		} else {
			lo = x1, x1 = x2, f1 = f2;
			x2 = lo + r * (hi - lo), f2 = f(k, x2);
		}
	}
	*arg = f1 < f2 ? x1 : x2;
	return fmin(f1, f2);
}

/* Sampled at n points, then refined about the least sample. */
static double sampled_min(const config *k, fun f, int n, double *arg)
{
	int best = 0;
	double fb = INFINITY;
	for (int j = 0; j < n; j++) {
		double v = f(k, 2 * PI * j / n);
		if (v < fb)
			fb = v, best = j;
	}
	double step = 2 * PI / n;
	double v = golden_min(k, f, step * (best - 1), step * (best + 1), arg);
	if (!(v <= fb))
		*arg = step * best, v = fb;
	return v;
}

static double outline_to_segment(const config *k, double th)
{
	double b[2];
	outline(k, th, b);
	return segment_distance(k, b, NULL);
}

/* Minus the separation along n(phi) = (cos phi, sin phi): the outline's
 * lowest point along n (the angle parameter that minimises a cos(th) n_u
 * + c sin(th) n_v) less the segment's highest. */
static double minus_separation(const config *k, double phi)
{
	double n[2] = {cos(phi), sin(phi)};
	double nu = n[0] * cos(k->psi) + n[1] * sin(k->psi);
	double nv = -n[0] * sin(k->psi) + n[1] * cos(k->psi);
	double b[2];
	outline(k, atan2(-k->c * nv, -k->a * nu), b);
	double low = n[0] * b[0] + n[1] * b[1];
	double high = fmax(n[0] * k->p0[0] + n[1] * k->p0[1], n[0] * k->p1[0] + n[1] * k->p1[1]);
	return -(low - high);
}

static double scale(const config *k)
{
	return fmax(fmax(k->a, k->c), fmax(hypot(k->p0[0] - k->x[0], k->p0[1] - k->x[1]),
	                                   hypot(k->p1[0] - k->x[0], k->p1[1] - k->x[1])));
}

/* What every answer satisfies: n a unit vector, on_body on the outline,
 * on_segment on the segment (an end when at_end), on_body = on_segment +
 * dist n. */
static void check_consistent(const config *k, const bsim_body_segment_contact *o)
{
	double S = scale(k);
	assert_true(fabs(hypot(o->n[0], o->n[1]) - 1.0) < 1e-14);
	assert_true(fabs(implicit(k, o->on_body) - 1.0) < 1e-13);
	assert_true(segment_distance(k, o->on_segment, NULL) < 1e-13 * S);
	if (o->at_end) {
		double e0 = hypot(o->on_segment[0] - k->p0[0], o->on_segment[1] - k->p0[1]);
		double e1 = hypot(o->on_segment[0] - k->p1[0], o->on_segment[1] - k->p1[1]);
		assert_true(fmin(e0, e1) == 0.0);
	}
	for (int i = 0; i < 2; i++)
		assert_true(fabs(o->on_body[i] - o->on_segment[i] - o->dist * o->n[i]) < 1e-12 * S);
}

static double max_err_apart, max_err_overlap, max_err_moved;

/* The answer against brute force; returns dist. */
static double check_brute(const config *k)
{
	bsim_body_segment_contact o;
	assert_int_equal(contact(k, &o), BSIM_OK);
	check_consistent(k, &o);
	double S = scale(k);
	if (!overlapping(k)) {
		double th, tseg;
		double bd = sampled_min(k, outline_to_segment, 4096, &th);
		double b[2];
		outline(k, th, b);
		segment_distance(k, b, &tseg);
		double err = fabs(o.dist - bd) / S;
		max_err_apart = fmax(max_err_apart, err);
		assert_true(o.dist > -1e-13 * S);
		assert_true(err < 1e-12);
		/* where the nearest points are (golden section finds th to ~1e-8) */
		assert_true(hypot(o.on_body[0] - b[0], o.on_body[1] - b[1]) < 1e-6 * S);
		/* at an end unless the brute force's foot is near one */
		double d[2] = {k->p1[0] - k->p0[0], k->p1[1] - k->p0[1]};
		double tu = ((b[0] - k->p0[0]) * d[0] + (b[1] - k->p0[1]) * d[1]) /
		            (d[0] * d[0] + d[1] * d[1]);
		(void)tseg;
		if (tu > 1e-6 && tu < 1 - 1e-6)
			assert_int_equal(o.at_end, 0);
		else if (tu < -1e-6 || tu > 1 + 1e-6)
			assert_int_equal(o.at_end, 1);
	} else {
		double phi;
		double bd = -sampled_min(k, minus_separation, 3600, &phi);
		double err = fabs(o.dist - bd) / S;
		max_err_overlap = fmax(max_err_overlap, err);
		assert_true(o.dist < 1e-13 * S);
		assert_true(err < 1e-12);
		/* moved by (-dist + delta) n it is delta away; by (-dist - delta) n
		 * it still overlaps */
		double delta = 1e-4 * fmin(k->a, k->c);
		config m = *k;
		for (int i = 0; i < 2; i++)
			m.x[i] = k->x[i] + (-o.dist + delta) * o.n[i];
		double th, md = sampled_min(&m, outline_to_segment, 4096, &th);
		max_err_moved = fmax(max_err_moved, fabs(md - delta) / S);
		assert_true(fabs(md - delta) < 1e-11 * S);
		for (int i = 0; i < 2; i++)
			m.x[i] = k->x[i] + (-o.dist - delta) * o.n[i];
		assert_true(overlapping(&m));
	}
	return o.dist;
}

/* A configuration about the outline point at angle parameter th: the
 * point q at offset s min(a, c) along the outward normal, and a segment of kind
 * 0 (beside the outline, through q, nearly tangent), 1 (a tip at q pointing
 * at the body) or 2 (anywhere near the body). */
static void random_config(config *k, int kind, double s)
{
	k->a = uniform(2.0, 15.0);
	k->c = uniform(2.0, 15.0);
	k->psi = uniform(-PI, PI);
	k->x[0] = uniform(-30.0, 30.0);
	k->x[1] = uniform(-30.0, 30.0);
	double th = uniform(-PI, PI), q[2];
	outline(k, th, q);
	/* the outward normal: the gradient of the implicit function */
	double X = k->a * cos(th), Y = k->c * sin(th);
	double gu = X / (k->a * k->a), gv = Y / (k->c * k->c);
	double N[2] = {gu * cos(k->psi) - gv * sin(k->psi), gu * sin(k->psi) + gv * cos(k->psi)};
	double len = hypot(N[0], N[1]);
	N[0] /= len, N[1] /= len;
	s *= fmin(k->a, k->c);
	q[0] += s * N[0], q[1] += s * N[1];
	if (kind == 0) {
		double tilt = uniform(-0.3, 0.3);
		double t[2] = {-N[1] * cos(tilt) + N[0] * sin(tilt),
		               N[0] * cos(tilt) + N[1] * sin(tilt)};
		double l0 = uniform(0.1, 20.0), l1 = uniform(0.1, 20.0);
		for (int i = 0; i < 2; i++) {
			k->p0[i] = q[i] - l0 * t[i];
			k->p1[i] = q[i] + l1 * t[i];
		}
	} else if (kind == 1) {
		double tilt = uniform(-1.2, 1.2), l = uniform(1.0, 25.0);
		double t[2] = {N[0] * cos(tilt) - N[1] * sin(tilt),
		               N[0] * sin(tilt) + N[1] * cos(tilt)};
		for (int i = 0; i < 2; i++) {
			k->p1[i] = q[i];
			k->p0[i] = q[i] + l * t[i];
		}
	} else {
		double R = 1.3 * fmax(k->a, k->c);
		for (int i = 0; i < 2; i++) {
			k->p0[i] = k->x[i] + uniform(-R, R);
			k->p1[i] = k->x[i] + uniform(-R, R);
		}
	}
}

static void test_circle_closed_form(void **state)
{
	(void)state;
	double worst = 0.0;
	for (int trial = 0; trial < 300; trial++) {
		config k;
		random_config(&k, trial % 3, uniform(-0.3, 3.0));
		k.c = k.a;
		bsim_body_segment_contact o;
		assert_int_equal(contact(&k, &o), BSIM_OK);
		check_consistent(&k, &o);
		double t, dx = segment_distance(&k, k.x, &t);
		double near[2] = {k.p0[0] + t * (k.p1[0] - k.p0[0]),
		                  k.p0[1] + t * (k.p1[1] - k.p0[1])};
		double err = fabs(o.dist - (dx - k.a)) / scale(&k);
		worst = fmax(worst, err);
		assert_true(err < 1e-13);
		assert_true(fabs(o.n[0] - (k.x[0] - near[0]) / dx) < 1e-9);
		assert_true(fabs(o.n[1] - (k.x[1] - near[1]) / dx) < 1e-9);
		assert_true(hypot(o.on_segment[0] - near[0], o.on_segment[1] - near[1]) <
		            1e-9 * scale(&k));
		assert_int_equal(o.at_end, t == 0.0 || t == 1.0);
	}
	printf("circle: largest |dist - (|x - S| - r)| / size %.2g over 300\n", worst);
}

static void test_axis_parallel_closed_form(void **state)
{
	(void)state;
	const double offsets[] = {3.0, 0.5, 1e-3, 1e-9, 0.0, -1e-9, -1e-3, -0.02};
	for (int j = 0; j < 40; j++) {
		double a = uniform(2.0, 15.0), c = uniform(2.0, 15.0), psi = uniform(-PI, PI);
		double x[2] = {uniform(-30, 30), uniform(-30, 30)};
		double u[2] = {cos(psi), sin(psi)}, v[2] = {-sin(psi), cos(psi)};
		for (size_t i = 0; i < sizeof offsets / sizeof *offsets; i++) {
			double g = offsets[i] * fmin(a, c);
			/* parallel to u at c + g (beside the minor axis's end), then
			 * parallel to v at a + g, each long enough to span the chord */
			for (int side = 0; side < 2; side++) {
				const double *along = side ? v : u, *across = side ? u : v;
				double off = (side ? a : c) + g,
				       l0 = uniform(3.0, 5.0) * fmax(a, c);
				double l1 = uniform(3.0, 5.0) * fmax(a, c);
				config k = {a, c, {x[0], x[1]}, psi, {0, 0}, {0, 0}};
				for (int m = 0; m < 2; m++) {
					k.p0[m] = x[m] + off * across[m] - l0 * along[m];
					k.p1[m] = x[m] + off * across[m] + l1 * along[m];
				}
				bsim_body_segment_contact o;
				assert_int_equal(contact(&k, &o), BSIM_OK);
				check_consistent(&k, &o);
				assert_true(fabs(o.dist - g) < 1e-13 * scale(&k));
				assert_true(fabs(o.n[0] + across[0]) < 1e-12);
				assert_true(fabs(o.n[1] + across[1]) < 1e-12);
				double rad = side ? a : c;
				assert_true(fabs(o.on_body[0] - x[0] - rad * across[0]) <
				            1e-12 * scale(&k));
				assert_true(fabs(o.on_body[1] - x[1] - rad * across[1]) <
				            1e-12 * scale(&k));
				assert_int_equal(o.at_end, 0);
				/* along the major axis, pointing at its end: a tip. A point
				 * beyond the end is nearest it; one within it by less than
				 * the curvature radius c^2 / a too. */
				const double *major = a >= c ? u : v;
				double e = fmax(a, c), l = uniform(1.0, 20.0);
				for (int m = 0; m < 2; m++) {
					k.p1[m] = x[m] + (e + g) * major[m];
					k.p0[m] = x[m] + (e + g + l) * major[m];
				}
				assert_int_equal(contact(&k, &o), BSIM_OK);
				check_consistent(&k, &o);
				assert_true(fabs(o.dist - g) < 1e-13 * scale(&k));
				assert_int_equal(o.at_end, 1);
				assert_true(o.on_segment[0] == k.p1[0] &&
				            o.on_segment[1] == k.p1[1]);
			}
		}
	}
}

static void test_brute_force(void **state)
{
	(void)state;
	int n_apart = 0, n_overlap = 0, n_end = 0;
	for (int trial = 0; trial < 450; trial++) {
		config k;
		int kind = trial % 3;
		/* offsets from 1% of the minor semi-axis inside to well outside */
		double s = trial % 6 < 3 ? uniform(-0.01, 0.0) : uniform(0.0, 4.0);
		random_config(&k, kind, s);
		double d = check_brute(&k);
		bsim_body_segment_contact o;
		contact(&k, &o);
		n_apart += d > 0;
		n_overlap += d <= 0;
		n_end += o.at_end;
	}
	printf("brute force: %d apart (largest error %.2g of the size), %d overlapping (%.2g; "
	       "moved out: %.2g), %d at an end\n",
	       n_apart, max_err_apart, n_overlap, max_err_overlap, max_err_moved, n_end);
	assert_true(n_apart > 100 && n_overlap > 100 && n_end > 100);
}

/* The answer of k transformed by the rotation R (angle beta) about the
 * origin and then, if mirror, x -> -x. */
static void transform(double beta, int mirror, const double in[2], double out[2])
{
	out[0] = cos(beta) * in[0] - sin(beta) * in[1];
	out[1] = sin(beta) * in[0] + cos(beta) * in[1];
	if (mirror)
		out[0] = -out[0];
}

static void test_invariance(void **state)
{
	(void)state;
	for (int trial = 0; trial < 300; trial++) {
		config k;
		random_config(&k, trial % 3, uniform(-0.01, 2.0));
		bsim_body_segment_contact o;
		assert_int_equal(contact(&k, &o), BSIM_OK);
		double S = scale(&k);
		for (int form = 0; form < 4; form++) {
			config t = k;
			double beta = form == 1 ? 0.0 : uniform(-PI, PI);
			int mirror = form >= 1 && form <= 2;
			transform(beta, mirror, k.x, t.x);
			transform(beta, mirror, k.p0, t.p0);
			transform(beta, mirror, k.p1, t.p1);
			t.psi = mirror ? PI - (k.psi + beta) : k.psi + beta;
			if (form == 3) {
				/* the same ellipse named the other way, ends exchanged */
				t.a = k.c, t.c = k.a, t.psi += PI / 2;
				double p[2] = {t.p0[0], t.p0[1]};
				t.p0[0] = t.p1[0], t.p0[1] = t.p1[1], t.p1[0] = p[0],
				t.p1[1] = p[1];
			}
			bsim_body_segment_contact r;
			assert_int_equal(contact(&t, &r), BSIM_OK);
			assert_true(fabs(r.dist - o.dist) < 1e-12 * S);
			double n[2], b[2], q[2];
			transform(beta, mirror, o.n, n);
			transform(beta, mirror, o.on_body, b);
			transform(beta, mirror, o.on_segment, q);
			assert_int_equal(r.at_end, o.at_end);
			for (int i = 0; i < 2; i++) {
				assert_true(fabs(r.n[i] - n[i]) < 1e-8);
				assert_true(fabs(r.on_body[i] - b[i]) < 1e-8 * S);
				assert_true(fabs(r.on_segment[i] - q[i]) < 1e-8 * S);
			}
		}
	}
}

static void test_continuity(void **state)
{
	(void)state;
	/* A segment of length L at offset s outside (or inside) the outline,
	 * its midpoint carried round once and turned with the normal, then
	 * turned about its tip while the tip crosses the outline. */
	const double offsets[] = {0.5, 1e-3, 0.0, -0.01};
	for (size_t j = 0; j < sizeof offsets / sizeof *offsets; j++) {
		config k = {9.0, 3.0, {1.0, -2.0}, 0.4, {0, 0}, {0, 0}};
		const int steps = 20000;
		double prev = NAN, p0[2] = {0, 0}, p1[2] = {0, 0};
		for (int i = 0; i <= steps; i++) {
			double th = 2 * PI * i / steps, q[2];
			outline(&k, th, q);
			double X = k.a * cos(th), Y = k.c * sin(th);
			double gu = X / (k.a * k.a), gv = Y / (k.c * k.c);
			double N[2] = {gu * cos(k.psi) - gv * sin(k.psi),
			               gu * sin(k.psi) + gv * cos(k.psi)};
			double len = hypot(N[0], N[1]);
			N[0] /= len, N[1] /= len;
			double off = offsets[j] * k.c, L = 4.0, shift = 3.0 * sin(7 * th);
			for (int m = 0; m < 2; m++) {
				double mid = q[m] + off * N[m] + shift * (m ? N[0] : -N[1]);
				k.p0[m] = mid - 0.5 * L * (m ? N[0] : -N[1]);
				k.p1[m] = mid + 0.5 * L * (m ? N[0] : -N[1]);
			}
			bsim_body_segment_contact o;
			assert_int_equal(contact(&k, &o), BSIM_OK);
			if (i > 0) {
				double moved = fmax(hypot(k.p0[0] - p0[0], k.p0[1] - p0[1]),
				                    hypot(k.p1[0] - p1[0], k.p1[1] - p1[1]));
				assert_true(fabs(o.dist - prev) <= moved * (1 + 1e-9) + 1e-12);
			}
			prev = o.dist;
			p0[0] = k.p0[0], p0[1] = k.p0[1], p1[0] = k.p1[0], p1[1] = k.p1[1];
		}
	}
	/* A tip swept through the outline: pivot outside, the segment turning. */
	config k = {9.0, 3.0, {0.0, 0.0}, 0.0, {2.0, 10.0}, {0, 0}};
	double prev = NAN, p1[2] = {0, 0};
	for (int i = 0; i <= 20000; i++) {
		double ang = -PI / 2 + 1.2 * (i / 20000.0 - 0.5);
		k.p1[0] = k.p0[0] + 7.3 * cos(ang);
		k.p1[1] = k.p0[1] + 7.3 * sin(ang);
		bsim_body_segment_contact o;
		assert_int_equal(contact(&k, &o), BSIM_OK);
		if (i > 0) {
			double moved = hypot(k.p1[0] - p1[0], k.p1[1] - p1[1]);
			assert_true(fabs(o.dist - prev) <= moved * (1 + 1e-9) + 1e-12);
		}
		prev = o.dist;
		p1[0] = k.p1[0], p1[1] = k.p1[1];
	}
}

/* Ends exactly on an axis or at the centre (the frame's special cases: a
 * point on the major axis inside the evolute has two nearest points, one on
 * the minor axis a far local maximum; the centre of a circle has every
 * direction), in both namings of the axes, against brute force. */
static void test_special_points(void **state)
{
	(void)state;
	const double ends[][2] = {{0, 0},      {3, 0},      {-3, 0},     {8.5, 0},  {0, 1},
	                          {0, -2.9},   {0, 2.99},   {9.05, 0},   {0, 3.02}, {-12, 0},
	                          {3, 1e-300}, {3, 1e-310}, {12, 1e-310}};
	const double others[][2] = {{20, 1}, {-4, 15}, {0, -14}, {13, 0}, {2, 0.5}};
	const double shapes[][3] = {{9, 3, 0}, {3, 9, PI / 2}, {4, 4, 0}};
	int n = 0;
	for (size_t s = 0; s < sizeof shapes / sizeof *shapes; s++)
		for (size_t i = 0; i < sizeof ends / sizeof *ends; i++)
			for (size_t j = 0; j < sizeof others / sizeof *others; j++) {
				config k = {shapes[s][0],
				            shapes[s][1],
				            {0, 0},
				            shapes[s][2],
				            {ends[i][0], ends[i][1]},
				            {others[j][0], others[j][1]}};
				if (shapes[s][2] !=
				    0) /* the same points in the frame named (c, a) */
					for (int m = 0; m < 2; m++) {
						double *p = m ? k.p1 : k.p0, t = p[0];
						p[0] = -p[1], p[1] = t;
					}
				check_brute(&k);
				n++;
			}
	printf("special points: %d configurations\n", n);
}

static void test_degenerate(void **state)
{
	(void)state;
	config k = {5.0, 2.0, {0, 0}, 0.3, {10, 0}, {10, 5}};
	bsim_body_segment_contact o;
	assert_int_equal(contact(&k, &o), BSIM_OK);
	config bad[] = {k, k, k, k, k, k};
	bad[0].a = 0.0;
	bad[1].c = -1.0;
	bad[2].a = NAN;
	bad[3].psi = INFINITY;
	bad[4].p1[0] = bad[4].p0[0], bad[4].p1[1] = bad[4].p0[1];
	bad[5].x[1] = NAN;
	for (size_t i = 0; i < sizeof bad / sizeof *bad; i++)
		assert_int_equal(contact(&bad[i], &o), BSIM_EFAIL);
	/* the segment through the centre: still an answer (the ellipse's
	 * least translation across it, along the minor axis) */
	config thru = {5.0, 2.0, {0, 0}, 0.0, {-10, 0}, {10, 0}};
	assert_int_equal(contact(&thru, &o), BSIM_OK);
	assert_true(fabs(o.dist + 2.0) < 1e-14);
	check_consistent(&thru, &o);
}

/* The cost per call, printed (not checked: the machine's load sets it):
 * N configurations, apart (offsets 1% to 200% of the minor semi-axis) or
 * overlapping (by up to 1% of it), beside the outline or tips, each called
 * REPEAT times. Instructions a call: valgrind --tool=callgrind
 * --toggle-collect=bsim_body_shape_ellipse_segment on this program with the
 * test's name as its argument, the total over N * REPEAT. */
enum { COST_N = 1000, COST_REPEAT = 100 };
static void cost(int overlapping_kind)
{
	static config ks[COST_N];
	for (int j = 0; j < COST_N; j++)
		random_config(&ks[j], j % 2,
		              overlapping_kind ? -uniform(0.0, 0.01) : uniform(0.01, 2.0));
	double sum = 0.0;
	struct timespec t0, t1;
	clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t0);
	for (int r = 0; r < COST_REPEAT; r++)
		for (int j = 0; j < COST_N; j++) {
			bsim_body_segment_contact o;
			assert_int_equal(contact(&ks[j], &o), BSIM_OK);
			sum += o.dist;
		}
	clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t1);
	double ns = ((double)(t1.tv_sec - t0.tv_sec) * 1e9 + (double)(t1.tv_nsec - t0.tv_nsec)) /
	            (COST_N * COST_REPEAT);
	printf("cost: %.0f ns of CPU time a call over %d calls, %s (sum of dist %g m)\n", ns,
	       COST_N * COST_REPEAT, overlapping_kind ? "overlapping by up to 1% of c" : "apart",
	       sum);
}

static void test_cost_apart(void **state)
{
	(void)state;
	cost(0);
}

static void test_cost_overlapping(void **state)
{
	(void)state;
	cost(1);
}

int main(int argc, char **argv)
{
	if (argc > 1) /* one test by name, e.g. test_cost_apart */
		cmocka_set_test_filter(argv[1]);
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_circle_closed_form),
	        cmocka_unit_test(test_axis_parallel_closed_form),
	        cmocka_unit_test(test_brute_force),
	        cmocka_unit_test(test_invariance),
	        cmocka_unit_test(test_continuity),
	        cmocka_unit_test(test_special_points),
	        cmocka_unit_test(test_degenerate),
	        cmocka_unit_test(test_cost_apart),
	        cmocka_unit_test(test_cost_overlapping),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
