/* The contact complementarity problem shared by impacts, persistent contact
 * and position projection (docs/model.md sections 4-5).
 *
 * Unknown impulses P_i >= 0 on contacts i. The solved normal velocity is
 *   w_i = q_i + sum_j K_ij P_j >= 0,   P_i w_i = 0,
 *   q_i = vrel_i - bound_i,   K_ij = (n_i . n_j) / M + [same beam] c_i c_j inv_i,
 * (contacts on one beam: i = j, or a capsule's two, thesis_contact.two)
 * with 1/M from the caller (impacts pass 1/impact_mass, impact_resolve.h).
 * K = J M^-1 J^T is symmetric positive definite (1/M > 0 and the normals of
 * two contacts are not parallel), so the solution is unique.
 *
 * n = 1: P = max(0, -q / K). n = 2: the four index sets are tried in turn and
 * the first that satisfies all signs is the solution; Cramer's rule keeps a
 * mirrored pair of contacts exactly mirrored.
 *
 * n > 2 happens in a lattice, where neighbouring gates share pivot points
 * and a body can touch three or four beams at once. Up to LCP_EXACT_MAX
 * contacts the active sets S are enumerated the same way, smallest first:
 *   P_S = -K_SS^-1 q_S (LU, GSL),  P_S >= 0,  w_j >= 0 for j not in S;
 * the first that holds is the solution (unique, K being positive definite;
 * where K is only semi-definite, as for two pivot-end contacts at one shared
 * pivot, an S with K_SS singular is skipped and the solution with linearly
 * independent rows is found). Beyond that, or if round-off leaves no set
 * within tolerance, projected Gauss-Seidel iterates to convergence; each
 * such solve is counted (bsim_thesis_lcp_fallbacks), and one that reaches its
 * iteration limit first is reported to the caller, which counts it in the
 * world's solver counts. test_lattice checks both paths against the
 * complementarity conditions. */
#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_permutation.h>
#include <math.h>

#include "thesis/thesis.h"

/* Contacts solved exactly by enumeration: 2^n active sets. */
#define LCP_EXACT_MAX 10
/* Projected Gauss-Seidel's sweeps at most. */
#define LCP_ITERATIONS_MAX 100000

/* Sweeps until no impulse changes by more than 1e-14 N s; 1 if it stopped
 * at its iteration limit instead. */
THESIS_SPECIALISED int lcp_gauss_seidel(double inv_mass, double inv_j, thesis_contact *cs, int n,
                                        const int extended)
{
	for (int i = 0; i < n; i++)
		cs[i].impulse = 0.0;
	for (int iter = 0; iter < LCP_ITERATIONS_MAX; iter++) {
		double change = 0.0;
		for (int i = 0; i < n; i++) {
			double wi = cs[i].vrel - cs[i].bound;
			for (int j = 0; j < n; j++)
				wi += k_entry(inv_mass, inv_j, &cs[i], &cs[j], extended) *
				      cs[j].impulse;
			double p = fmax(0.0, cs[i].impulse - wi / k_entry(inv_mass, inv_j, &cs[i],
			                                                  &cs[i], extended));
			change = fmax(change, fabs(p - cs[i].impulse));
			cs[i].impulse = p;
		}
		if (change <= 1e-14)
			return 0;
	}
	return 1;
}

static int popcount(unsigned v)
{
	int c = 0;
	for (; v; v &= v - 1)
		c++;
	return c;
}

/* Tries active set `mask`: 1 and the impulses in cs if it solves the LCP. */
THESIS_SPECIALISED int lcp_try_set(double inv_mass, double inv_j, thesis_contact *cs, int n,
                                   unsigned mask, const double *q, double tol, const int extended)
{
	double kss[LCP_EXACT_MAX * LCP_EXACT_MAX], p[LCP_EXACT_MAX], rhs[LCP_EXACT_MAX];
	int idx[LCP_EXACT_MAX], m = 0;
	for (int i = 0; i < n; i++)
		if (mask & (1u << i))
			idx[m++] = i;
	for (int a = 0; a < m; a++) {
		rhs[a] = -q[idx[a]];
		for (int b = 0; b < m; b++)
			kss[a * m + b] =
			        k_entry(inv_mass, inv_j, &cs[idx[a]], &cs[idx[b]], extended);
	}
	if (m > 0) {
		/* LU with partial pivoting; a pivot below round-off of the
		 * diagonal marks K_SS singular (checked here, so GSL's error
		 * handler never sees a singular solve). */
		double scale = 0.0;
		for (int a = 0; a < m; a++)
			scale = fmax(scale, kss[a * m + a]);
		size_t perm_data[LCP_EXACT_MAX];
		gsl_permutation perm = {(size_t)m, perm_data};
		int sign;
		gsl_matrix_view kv = gsl_matrix_view_array(kss, (size_t)m, (size_t)m);
		gsl_vector_view rv = gsl_vector_view_array(rhs, (size_t)m);
		gsl_vector_view pv = gsl_vector_view_array(p, (size_t)m);
		if (gsl_linalg_LU_decomp(&kv.matrix, &perm, &sign) != GSL_SUCCESS)
			return 0;
		for (int a = 0; a < m; a++)
			if (!(fabs(kss[a * m + a]) > 1e-12 * scale))
				return 0;
		if (gsl_linalg_LU_solve(&kv.matrix, &perm, &rv.vector, &pv.vector) != GSL_SUCCESS)
			return 0;
	}
	for (int a = 0; a < m; a++)
		if (!(p[a] >= 0.0))
			return 0;
	for (int j = 0; j < n; j++) {
		if (mask & (1u << j))
			continue;
		double wj = q[j];
		for (int a = 0; a < m; a++)
			wj += k_entry(inv_mass, inv_j, &cs[j], &cs[idx[a]], extended) * p[a];
		if (wj < -tol)
			return 0;
	}
	for (int i = 0; i < n; i++)
		cs[i].impulse = 0.0;
	for (int a = 0; a < m; a++)
		cs[idx[a]].impulse = p[a];
	return 1;
}

THESIS_SPECIALISED int lcp_enumerate(double inv_mass, double inv_j, thesis_contact *cs, int n,
                                     const int extended)
{
	double q[LCP_EXACT_MAX], qmax = 0.0;
	for (int i = 0; i < n; i++) {
		q[i] = cs[i].vrel - cs[i].bound;
		qmax = fmax(qmax, fabs(q[i]));
	}
	double tol = 1e-12 * (1.0 + qmax); /* m/s */
	unsigned sets = 1u << n;
	for (int size = 0; size <= n; size++)
		for (unsigned mask = 0; mask < sets; mask++)
			if (popcount(mask) == size &&
			    lcp_try_set(inv_mass, inv_j, cs, n, mask, q, tol, extended))
				return 1;
	return 0;
}

static long lcp_fallbacks;

long bsim_thesis_lcp_fallbacks(void)
{
	long n;
#pragma omp atomic read
	n = lcp_fallbacks;
	return n;
}

/* The solve for both entry points below: inline, so that the essay's
 * (inv_j = 0) is compiled with the rotation's terms gone. */
THESIS_SPECIALISED int lcp_solve(double inv_mass, double inv_j, thesis_contact *cs, int n,
                                 const int extended)
{
	if (n <= 2) {
		thesis_lcp_small(inv_mass, inv_j, cs, n, extended);
	} else {
		if (n <= LCP_EXACT_MAX && lcp_enumerate(inv_mass, inv_j, cs, n, extended))
			return 0;
#pragma omp atomic update
		lcp_fallbacks++;
		return lcp_gauss_seidel(inv_mass, inv_j, cs, n, extended);
	}
	return 0;
}

int bsim_thesis_lcp_solve(double inv_mass, thesis_contact *cs, int n)
{
	return lcp_solve(inv_mass, 0.0, cs, n, 0);
}

int bsim_thesis_lcp_solve_j(double inv_mass, double inv_j, thesis_contact *cs, int n)
{
	return lcp_solve(inv_mass, inv_j, cs, n, 1);
}
