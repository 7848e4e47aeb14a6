/* The contact complementarity problem shared by impacts, persistent contact
 * and position projection (MODEL.md sections 4-5).
 *
 * Unknown impulses P_i >= 0 on contacts i. The solved normal velocity is
 *   w_i = q_i + sum_j K_ij P_j >= 0,   P_i w_i = 0,
 *   q_i = vrel_i - bound_i,   K_ij = (n_i . n_j) / M + [i = j] c_i^2 inv_i.
 * K = J M^-1 J^T is symmetric positive definite (1/M > 0 and the normals of
 * two contacts are not parallel), so the solution is unique.
 *
 * n = 1: P = max(0, -q / K). n = 2: the four index sets are tried in turn and
 * the first that satisfies all signs is the solution; Cramer's rule keeps a
 * mirrored pair of contacts exactly mirrored. n > 2 (a body among many
 * beams): projected Gauss-Seidel. */
#include <math.h>

#include "thesis/thesis.h"

static double k_entry(const struct bsim_world *w, const thesis_contact *a, const thesis_contact *b)
{
	double k = (a->n[0] * b->n[0] + a->n[1] * b->n[1]) * w->inv_mass;
	if (a == b)
		k += a->c * a->c * a->inv_i;
	return k;
}

static void lcp_two(const struct bsim_world *w, thesis_contact *c0, thesis_contact *c1)
{
	double q0 = c0->vrel - c0->bound, q1 = c1->vrel - c1->bound;
	double k00 = k_entry(w, c0, c0), k11 = k_entry(w, c1, c1);
	double k01 = k_entry(w, c0, c1);
	c0->impulse = c1->impulse = 0.0;
	if (q0 >= 0.0 && q1 >= 0.0)
		return;
	double det = k00 * k11 - k01 * k01;
	if (det > 0.0) {
		double p0 = (k01 * q1 - k11 * q0) / det;
		double p1 = (k01 * q0 - k00 * q1) / det;
		if (p0 >= 0.0 && p1 >= 0.0) {
			c0->impulse = p0;
			c1->impulse = p1;
			return;
		}
	}
	double p0 = -q0 / k00;
	if (p0 > 0.0 && q1 + k01 * p0 >= 0.0) {
		c0->impulse = p0;
		return;
	}
	double p1 = -q1 / k11;
	if (p1 > 0.0 && q0 + k01 * p1 >= 0.0)
		c1->impulse = p1;
}

static void lcp_gauss_seidel(const struct bsim_world *w, thesis_contact *cs, int n)
{
	for (int i = 0; i < n; i++)
		cs[i].impulse = 0.0;
	for (int iter = 0; iter < 100; iter++) {
		double change = 0.0;
		for (int i = 0; i < n; i++) {
			double wi = cs[i].vrel - cs[i].bound;
			for (int j = 0; j < n; j++)
				wi += k_entry(w, &cs[i], &cs[j]) * cs[j].impulse;
			double p = fmax(0.0, cs[i].impulse - wi / k_entry(w, &cs[i], &cs[i]));
			change = fmax(change, fabs(p - cs[i].impulse));
			cs[i].impulse = p;
		}
		if (change <= 1e-14)
			break;
	}
}

void thesis_lcp_solve(const struct bsim_world *w, thesis_contact *cs, int n)
{
	if (n == 1) {
		double q = cs[0].vrel - cs[0].bound;
		cs[0].impulse = q < 0.0 ? -q / k_entry(w, &cs[0], &cs[0]) : 0.0;
	} else if (n == 2) {
		lcp_two(w, &cs[0], &cs[1]);
	} else if (n > 2) {
		lcp_gauss_seidel(w, cs, n);
	}
}

void thesis_impulse_sum(const thesis_contact *cs, int n, double j[2])
{
	j[0] = j[1] = 0.0;
	if (n == 2) { /* one expression for a pair: a mirrored pair sums alike */
		j[0] = cs[0].impulse * cs[0].n[0] + cs[1].impulse * cs[1].n[0];
		j[1] = cs[0].impulse * cs[0].n[1] + cs[1].impulse * cs[1].n[1];
		return;
	}
	for (int k = 0; k < n; k++) {
		j[0] += cs[k].impulse * cs[k].n[0];
		j[1] += cs[k].impulse * cs[k].n[1];
	}
}
