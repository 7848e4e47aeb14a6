/* The barriers of the landscape (landscape_barrier.c) against truths that
 * do not use the barrier search:
 *
 * - On the symmetric gate the lowest pass lies where the right beam has
 *   just been released (on its reach circle rho_2 = L + R, outside it) and
 *   the path crosses the left beam's crest there: it is the highest point
 *   of E_prop + 1/2 k th_1^2 along that circle, a 1-D maximum found here
 *   by a fine scan, with and without propulsion.
 * - Mirror symmetry: the symmetric gate's two beams have mirrored passes.
 * - Scaling with k: without propulsion E is k times a geometric function,
 *   so doubling every k doubles every pass exactly (a power of two scales
 *   the arithmetic exactly) and moves none; with k1 : k2 = 300 : 500 each
 *   beam's pass, where the other beam is released, is k_i / 400 of the
 *   400 : 400 gate's.
 * - Propulsion and asymmetry: the lowest pass against a brute-force
 *   minimax on a fine grid (0.05 m), by union-find flooding (Kruskal's
 *   order, not Dijkstra's), within that grid's own error.
 * - Translation: moving the whole scene along y moves every pass along
 *   with it and changes no energy, bit for bit.
 * - Any number of beams: a third beam out of the region changes nothing
 *   and has no pass; one short beam leaves a free lane, an open way. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "beamsim/landscape.h"
#include "beamsim/landscape_barriers.h"
#include "scenes.h"

/* The essay gate with stiffnesses k1, k2 and propulsion f (0: none). */
static void gate(bsim_scene *s, double k1, double k2, double f)
{
	scene_gate_quiet(s);
	s->beams[0].stiffness = k1;
	s->beams[1].stiffness = k2;
	s->effects.has_propulsion = f != 0.0;
	s->effects.propulsion_force = f;
}

static bsim_landscape_barriers *barriers(const bsim_scene *s, double spacing)
{
	bsim_landscape_grid_def def = bsim_landscape_grid_def_default();
	def.spacing = spacing;
	bsim_landscape_grid *g;
	bsim_landscape_barriers *b;
	bsim_error err;
	assert_int_equal(bsim_landscape_grid_alloc(s, &def, &g, &err), BSIM_OK);
	int rc = bsim_landscape_barriers_alloc(s, g, &b, &err);
	if (rc)
		print_message("%s\n", err.msg);
	assert_int_equal(rc, BSIM_OK);
	bsim_landscape_grid_free(g);
	return b;
}

/* The refinement's stated accuracy, never below 0.01 J. */
static double tol_of(const bsim_landscape_pass *p)
{
	return fmax(2.0 * p->refine_change, 0.01);
}

/* ---- the release circle ----------------------------------------------- */

/* max over the right beam's reach circle (pivot (25, 30), radius 35, just
 * outside, angle a from the -x direction) of E_prop + 1/2 k th_1^2. */
static double circle_max(const bsim_scene *s, double *x, double *y)
{
	const bsim_beam_def *left = &s->beams[0], *right = &s->beams[1];
	const double r = right->length + s->body.radius + 1e-9;
	double best = -INFINITY;
	for (int i = 1; i < 70000; i++) {
		const double a = i * 1e-5;
		const double c[2] = {right->pivot[0] - r * cos(a), right->pivot[1] + r * sin(a)};
		const double th = bsim_landscape_theta(left, s->body.radius, c);
		const double e = bsim_landscape_e_prop(s, c[1]) + 0.5 * left->stiffness * th * th;
		if (e > best) {
			best = e;
			*x = c[0];
			*y = c[1];
		}
	}
	return best;
}

static void test_release_circle(void **state)
{
	(void)state;
	const double forces[] = {0, 4, 7, 9};
	for (int i = 0; i < 4; i++) {
		bsim_scene s;
		gate(&s, 400, 400, forces[i]);
		double x = NAN, y = NAN;
		const double truth = circle_max(&s, &x, &y);
		bsim_landscape_barriers *b = barriers(&s, 0);
		const bsim_landscape_pass *p = &b->lowest;
		print_message(
		        "F = %g N: pass %.4f J at (%.3f, %.3f), circle maximum %.4f J at (%.3f, "
		        "%.3f); grid %.3f J; refinement change %.3g J\n",
		        forces[i], p->e_total, p->x, p->y, truth, x, y, p->grid_e,
		        p->refine_change);
		assert_int_equal(p->kind, BSIM_PASS_SADDLE);
		assert_int_equal(p->beam, 0); /* the left beam's crest, right beam released */
		assert_true(fabs(p->e_total - truth) <= tol_of(p));
		assert_true(hypot(p->x - x, p->y - y) < 0.1);
		/* refinement gains at least ten times on the grid */
		assert_true(fabs(p->grid_e - truth) > 10 * fabs(p->e_total - truth));
		bsim_landscape_barriers_free(b);
		bsim_scene_free(&s);
	}
}

/* ---- mirror symmetry --------------------------------------------------------- */

static void test_mirror(void **state)
{
	(void)state;
	const double forces[] = {0, 7};
	for (int i = 0; i < 2; i++) {
		bsim_scene s;
		gate(&s, 400, 400, forces[i]);
		bsim_landscape_barriers *b = barriers(&s, 0);
		const bsim_landscape_pass *p0 = &b->beam[0], *p1 = &b->beam[1];
		print_message(
		        "F = %g N: beam 1 %.4f J at (%.4f, %.4f), beam 2 %.4f J at (%.4f, %.4f)\n",
		        forces[i], p0->e_total, p0->x, p0->y, p1->e_total, p1->x, p1->y);
		assert_int_equal(p0->kind, BSIM_PASS_SADDLE);
		assert_int_equal(p1->kind, BSIM_PASS_SADDLE);
		assert_int_equal(p0->beam, 0);
		assert_int_equal(p1->beam, 1);
		assert_true(p0->x < 0 && p1->x > 0);
		assert_true(fabs(p0->e_total - p1->e_total) <= fmax(tol_of(p0), tol_of(p1)));
		/* along the crest E is flat, so the position is known to less
		 * than the value: 0.1 m, as against the release circle */
		assert_true(hypot(p0->x + p1->x, p0->y - p1->y) < 0.1);
		/* the floor of the start basin is on the midline */
		assert_true(fabs(b->lowest.floor[0]) < 1e-9 || forces[i] == 0.0);
		bsim_landscape_barriers_free(b);
		bsim_scene_free(&s);
	}
}

/* ---- scaling with k ----------------------------------------------------- */

static void test_scaling_exact(void **state)
{
	(void)state;
	bsim_scene s1, s2;
	gate(&s1, 100, 500, 0);
	gate(&s2, 200, 1000, 0);
	bsim_landscape_barriers *b1 = barriers(&s1, 0), *b2 = barriers(&s2, 0);
	for (int r = 0; r <= 2; r++) {
		const bsim_landscape_pass *p = r ? &b1->beam[r - 1] : &b1->lowest;
		const bsim_landscape_pass *q = r ? &b2->beam[r - 1] : &b2->lowest;
		print_message("pass %d: %.6f J -> %.6f J at (%.4f, %.4f)\n", r, p->e_total,
		              q->e_total, q->x, q->y);
		assert_int_equal(p->kind, BSIM_PASS_SADDLE);
		assert_true(q->e_total == 2.0 * p->e_total);
		assert_true(q->height == 2.0 * p->height);
		assert_true(q->x == p->x && q->y == p->y);
	}
	bsim_landscape_barriers_free(b1);
	bsim_landscape_barriers_free(b2);
	bsim_scene_free(&s1);
	bsim_scene_free(&s2);
}

static void test_scaling_per_beam(void **state)
{
	(void)state;
	bsim_scene s0, s1;
	gate(&s0, 400, 400, 0);
	gate(&s1, 300, 500, 0);
	bsim_landscape_barriers *b0 = barriers(&s0, 0), *b1 = barriers(&s1, 0);
	const double k[2] = {300, 500};
	for (int i = 0; i < 2; i++) {
		const bsim_landscape_pass *p = &b0->beam[i], *q = &b1->beam[i];
		print_message("beam %d: %.4f J at k = 400, %.4f J at k = %g (ratio %.5f)\n", i + 1,
		              p->e_total, q->e_total, k[i], q->e_total / p->e_total);
		assert_true(fabs(q->e_total - k[i] / 400 * p->e_total) <= tol_of(p) + tol_of(q));
	}
	/* the softer beam's barrier is the lowest pass */
	assert_int_equal(b1->lowest.beam, 0);
	assert_true(b1->beam[0].e_total < b1->beam[1].e_total);
	bsim_landscape_barriers_free(b0);
	bsim_landscape_barriers_free(b1);
	bsim_scene_free(&s0);
	bsim_scene_free(&s1);
}

/* ---- brute force with propulsion ---------------------------------------- */

static int uf_find(int *parent, int k)
{
	while (parent[k] != k) {
		parent[k] = parent[parent[k]];
		k = parent[k];
	}
	return k;
}

typedef struct cell {
	double e;
	int k;
} cell;

static int cell_cmp(const void *a, const void *b)
{
	const double x = ((const cell *)a)->e, y = ((const cell *)b)->e;
	return (x > y) - (x < y);
}

/* The minimax from the point nearest `from` to the row y = y1 over the
 * region [x0, x1] x [y0, y1] at spacing h: points are added lowest first
 * and joined to their added neighbours until `from` and the top row meet;
 * the level then is the pass. Points beyond side_x or on a pivot are
 * never added. */
static double flood(const bsim_scene *s, const double from[2], double x0, double x1, double y0,
                    double y1, double h)
{
	const int nx = (int)lround((x1 - x0) / h) + 1, ny = (int)lround((y1 - y0) / h) + 1;
	const int n = nx * ny, top = n; /* a virtual point joined to the top row */
	cell *c = malloc((size_t)n * sizeof *c);
	int *parent = malloc((size_t)(n + 1) * sizeof *parent);
	unsigned char *in = calloc((size_t)n, 1);
	assert_non_null(c);
	assert_non_null(parent);
	assert_non_null(in);
	int m = 0;
	for (int k = 0; k < n; k++) {
		const double p[2] = {x0 + (k % nx) * h, y0 + (k / nx) * h};
		int open = fabs(p[0]) < s->side_x;
		for (int b = 0; b < s->n_beams; b++)
			open &= hypot(p[0] - s->beams[b].pivot[0], p[1] - s->beams[b].pivot[1]) >=
			        s->body.radius;
		if (open) {
			c[m].e = bsim_landscape_energy(s, p, NULL, NULL, NULL);
			c[m++].k = k;
		}
	}
	for (int k = 0; k <= n; k++)
		parent[k] = k;
	qsort(c, (size_t)m, sizeof *c, cell_cmp);
	const int kf = (int)lround((from[1] - y0) / h) * nx + (int)lround((from[0] - x0) / h);
	double level = NAN;
	for (int t = 0; t < m && isnan(level); t++) {
		const int k = c[t].k, i = k % nx, j = k / nx;
		in[k] = 1;
		if (j == ny - 1)
			parent[uf_find(parent, k)] = uf_find(parent, top);
		const int nb[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
		for (int d = 0; d < 4; d++) {
			const int ii = i + nb[d][0], jj = j + nb[d][1];
			if (ii >= 0 && jj >= 0 && ii < nx && jj < ny && in[jj * nx + ii])
				parent[uf_find(parent, k)] = uf_find(parent, jj * nx + ii);
		}
		if (in[kf] && uf_find(parent, kf) == uf_find(parent, top))
			level = c[t].e;
	}
	free(c);
	free(parent);
	free(in);
	return level;
}

static void test_brute_force(void **state)
{
	(void)state;
	const double cases[][3] = {{400, 400, 7}, {300, 500, 8}};
	for (int i = 0; i < 2; i++) {
		bsim_scene s;
		gate(&s, cases[i][0], cases[i][1], cases[i][2]);
		bsim_landscape_barriers *b = barriers(&s, 0);
		const bsim_landscape_pass *p = &b->lowest;
		/* from y = 15 m: the basin floor (y about 25 m) and all above it */
		const double h = 0.05;
		const double v = flood(&s, p->floor, -25, 25, 15, 65, h);
		/* the brute force's own error: a step of h up the slope at the pass */
		const double eps = 1e-6, c[2] = {p->x, p->y};
		double gx[2] = {c[0] + eps, c[1]}, gy[2] = {c[0], c[1] + eps};
		const double e = bsim_landscape_energy(&s, c, NULL, NULL, NULL);
		const double grad = hypot(bsim_landscape_energy(&s, gx, NULL, NULL, NULL) - e,
		                          bsim_landscape_energy(&s, gy, NULL, NULL, NULL) - e) /
		                    eps;
		print_message(
		        "k %g : %g, F = %g N: pass %.3f J, brute force at %g m %.3f J (its error "
		        "h |grad E| = %.3f J)\n",
		        cases[i][0], cases[i][1], cases[i][2], p->e_total, h, v, h * grad);
		assert_true(fabs(p->e_total - v) <= h * grad + tol_of(p));
		bsim_landscape_barriers_free(b);
		bsim_scene_free(&s);
	}
}

/* ---- translation and any number of beams --------------------------------- */

static void pass_equal_shifted(const bsim_landscape_pass *p, const bsim_landscape_pass *q,
                               double dy)
{
	assert_int_equal(p->kind, q->kind);
	assert_int_equal(p->beam, q->beam);
	if (p->kind == BSIM_PASS_NONE)
		return;
	assert_true(p->e_total == q->e_total && p->height == q->height);
	assert_true(p->x == q->x && fabs(p->y + dy - q->y) < 1e-9);
}

static void test_translation(void **state)
{
	(void)state;
	bsim_scene s, t;
	gate(&s, 300, 500, 8);
	gate(&t, 300, 500, 8);
	const double dy = 7.0;
	for (int i = 0; i < 2; i++)
		t.beams[i].pivot[1] += dy;
	t.body.start[1] += dy;
	t.success_y += dy;
	t.classify_y += dy;
	t.landscape_y0 += dy;
	bsim_landscape_barriers *a = barriers(&s, 0), *b = barriers(&t, 0);
	pass_equal_shifted(&a->lowest, &b->lowest, dy);
	for (int i = 0; i < 2; i++)
		pass_equal_shifted(&a->beam[i], &b->beam[i], dy);
	bsim_landscape_barriers_free(a);
	bsim_landscape_barriers_free(b);
	bsim_scene_free(&s);
	bsim_scene_free(&t);
}

static void test_third_beam(void **state)
{
	(void)state;
	bsim_scene s, t;
	gate(&s, 300, 500, 8);
	gate(&t, 300, 500, 8);
	assert_int_equal(bsim_scene_set_beams(&t, 3), BSIM_OK);
	t.beams[2] = t.beams[1];
	t.beams[2].pivot[1] = 300; /* its reach ends 265 m beyond the region */
	bsim_landscape_barriers *a = barriers(&s, 0), *b = barriers(&t, 0);
	pass_equal_shifted(&a->lowest, &b->lowest, 0);
	for (int i = 0; i < 2; i++)
		pass_equal_shifted(&a->beam[i], &b->beam[i], 0);
	assert_int_equal(b->n_beams, 3);
	assert_int_equal(b->beam[2].kind, BSIM_PASS_NONE);
	bsim_landscape_barriers_free(a);
	bsim_landscape_barriers_free(b);
	bsim_scene_free(&s);
	bsim_scene_free(&t);
}

/* One beam of the gate alone: its reach ends at x = 10 m, so the lane
 * x in (10, 25) m holds no barrier: open, whatever the propulsion. */
static void test_free_lane(void **state)
{
	(void)state;
	const double forces[] = {0, 7};
	for (int i = 0; i < 2; i++) {
		bsim_scene s;
		gate(&s, 400, 400, forces[i]);
		assert_int_equal(bsim_scene_set_beams(&s, 1), BSIM_OK);
		bsim_landscape_barriers *b = barriers(&s, 0);
		print_message("F = %g N: %s, crossed %d\n", forces[i],
		              bsim_landscape_pass_kind_name(b->lowest.kind), b->lowest.beam);
		assert_int_equal(b->lowest.kind, BSIM_PASS_OPEN);
		assert_true(b->lowest.height == 0.0);
		bsim_landscape_barriers_free(b);
		bsim_scene_free(&s);
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_release_circle), cmocka_unit_test(test_mirror),
	        cmocka_unit_test(test_scaling_exact),  cmocka_unit_test(test_scaling_per_beam),
	        cmocka_unit_test(test_brute_force),    cmocka_unit_test(test_translation),
	        cmocka_unit_test(test_third_beam),     cmocka_unit_test(test_free_lane),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
