/* The contact problem with friction (extended path, thesis.h's head): the
 * normal rows of lcp_solve.c plus each contact's tangent row, bounded by
 * Coulomb's cone (docs/backends.md, "A body that turns, has a shape, and
 * feels friction").
 *
 * Rows r = 2i (normal) and 2i + 1 (tangent) of contact i have the Jacobian
 * (d_r on v, b_r on w, -l_r on the beam's omega): (n, cb, c) and (t, cbt,
 * ct). With P the 2n impulses, the solved relative velocities are
 *   u = q + K P,  K_rs = d_r . d_s / M + b_r b_s / J + [same beam] l_r l_s / I,
 *   q_2i = v_n,i - bound_i,  q_2i+1 = v_t,i,
 * K = J M^-1 J^T symmetric positive semi-definite. Per contact:
 *   P_n >= 0, u_n >= 0, P_n u_n = 0                    (the normal LCP)
 *   |P_t| <= mu P_n;  u_t > 0 => P_t = -mu P_n;  u_t < 0 => P_t = mu P_n;
 *   |P_t| < mu P_n => u_t = 0                          (the box: stick or slide)
 * Each contact is in one of four cases: separate (P_n = P_t = 0, u_n >= 0),
 * stick (u_n = u_t = 0, |P_t| <= mu P_n), slide forward (u_n = 0, P_t =
 * -mu P_n, u_t >= 0) or backward (P_t = mu P_n, u_t <= 0). A choice of
 * cases is one linear system of 2n equations; the cases are enumerated,
 * fewer touching contacts first and stick before slide, and the first
 * whose solution meets its inequalities (round-off tolerance 1e-12 of the
 * velocities) is the solution: exact, 4^n systems at most, for up to
 * FRICTION_EXACT_MAX contacts (the body meets 1 or 2 beams; a lattice's
 * shared pivots make 3 or 4). A contact with mu = 0 has two cases only
 * (separate, or pressed with P_t = 0), so that without friction the
 * problem is lcp_solve.c's with the body's rotation in K. Beyond that, or
 * if round-off leaves no case within tolerance, projected Gauss-Seidel on
 * the box (P_t clamped to [-mu P_n, mu P_n]) gives an approximation, and
 * the solve reports itself not exact: the caller counts it in
 * solver.iteration_limit. */
#include <math.h>

#include "thesis/thesis.h"

#define FRICTION_EXACT_MAX 4
#define FRICTION_ROWS      (2 * FRICTION_EXACT_MAX)
#define FRICTION_SWEEPS    10000

enum { CASE_SEPARATE, CASE_STICK, CASE_SLIDE_FORWARD, CASE_SLIDE_BACKWARD };

static void row_of(const thesis_contact *c, int r, double d[2], double *b, double *l)
{
	if (r % 2 == 0) {
		d[0] = c->n[0], d[1] = c->n[1], *b = c->cb, *l = c->c;
	} else {
		d[0] = -c->n[1], d[1] = c->n[0], *b = c->cbt, *l = c->ct;
	}
}

static double k_rows(double inv_mass, double inv_j, const thesis_contact *cs, int r, int s)
{
	double dr[2], ds[2], br, bs, lr, ls;
	row_of(&cs[r / 2], r, dr, &br, &lr);
	row_of(&cs[s / 2], s, ds, &bs, &ls);
	double k = (dr[0] * ds[0] + dr[1] * ds[1]) * inv_mass + br * bs * inv_j;
	const thesis_contact *a = &cs[r / 2], *b = &cs[s / 2];
	if (a == b || (a->two && b->two && a->beam == b->beam)) /* one beam */
		k += lr * ls * a->inv_i;
	return k;
}

/* Solves a x = y (m x m, row-major) by Gaussian elimination with partial
 * pivoting; 0 if a pivot is below 1e-12 of the matrix's scale (singular). */
static int solve_dense(double *a, double *y, int m)
{
	double scale = 0.0;
	for (int i = 0; i < m * m; i++)
		scale = fmax(scale, fabs(a[i]));
	for (int col = 0; col < m; col++) {
		int piv = col;
		for (int r = col + 1; r < m; r++)
			if (fabs(a[r * m + col]) > fabs(a[piv * m + col]))
				piv = r;
		if (!(fabs(a[piv * m + col]) > 1e-12 * scale))
			return 0;
		if (piv != col) {
			for (int c = 0; c < m; c++) {
				double t = a[col * m + c];
				a[col * m + c] = a[piv * m + c];
				a[piv * m + c] = t;
			}
			double t = y[col];
			y[col] = y[piv];
			y[piv] = t;
		}
		for (int r = col + 1; r < m; r++) {
			double f = a[r * m + col] / a[col * m + col];
			for (int c = col; c < m; c++)
				a[r * m + c] -= f * a[col * m + c];
			y[r] -= f * y[col];
		}
	}
	for (int r = m - 1; r >= 0; r--) {
		double s = y[r];
		for (int c = r + 1; c < m; c++)
			s -= a[r * m + c] * y[c];
		y[r] = s / a[r * m + r];
	}
	return 1;
}

/* The cases in `mode` (one per contact): 1 and the impulses in cs if they
 * solve the problem. */
static int try_cases(const double *k, const double *q, thesis_contact *cs, int n, const int *mode,
                     double tol)
{
	int m = 2 * n;
	double a[FRICTION_ROWS * FRICTION_ROWS], p[FRICTION_ROWS];
	for (int i = 0; i < n; i++) {
		int rn = 2 * i, rt = rn + 1;
		for (int c = 0; c < m; c++)
			a[rn * m + c] = a[rt * m + c] = 0.0;
		p[rn] = p[rt] = 0.0;
		if (mode[i] == CASE_SEPARATE) {
			a[rn * m + rn] = a[rt * m + rt] = 1.0;
			continue;
		}
		for (int c = 0; c < m; c++)
			a[rn * m + c] = k[rn * m + c];
		p[rn] = -q[rn];
		if (mode[i] == CASE_STICK) {
			for (int c = 0; c < m; c++)
				a[rt * m + c] = k[rt * m + c];
			p[rt] = -q[rt];
		} else {
			a[rt * m + rt] = 1.0;
			a[rt * m + rn] = mode[i] == CASE_SLIDE_FORWARD ? cs[i].mu : -cs[i].mu;
		}
	}
	if (!solve_dense(a, p, m))
		return 0;
	/* Elimination mixes the rows: a separated contact's impulses and a
	 * sliding one's P_t + -mu P_n come out as round-off, not 0; they are
	 * set exactly before the check. */
	for (int i = 0; i < n; i++) {
		if (mode[i] == CASE_SEPARATE)
			p[2 * i] = p[2 * i + 1] = 0.0;
		else if (mode[i] == CASE_SLIDE_FORWARD)
			p[2 * i + 1] = -cs[i].mu * p[2 * i];
		else if (mode[i] == CASE_SLIDE_BACKWARD)
			p[2 * i + 1] = cs[i].mu * p[2 * i];
	}
	for (int i = 0; i < n; i++) {
		double u[2];
		for (int r = 0; r < 2; r++) {
			u[r] = q[2 * i + r];
			for (int c = 0; c < m; c++)
				u[r] += k[(2 * i + r) * m + c] * p[c];
		}
		double pn = p[2 * i], pt = p[2 * i + 1];
		switch (mode[i]) {
		case CASE_SEPARATE:
			if (u[0] < -tol)
				return 0;
			break;
		case CASE_STICK:
			if (!(pn >= 0.0) || !(fabs(pt) <= cs[i].mu * pn * (1.0 + 1e-12)))
				return 0;
			break;
		case CASE_SLIDE_FORWARD:
			if (!(pn >= 0.0) || (cs[i].mu > 0.0 && u[1] < -tol))
				return 0;
			break;
		default:
			if (!(pn >= 0.0) || u[1] > tol)
				return 0;
		}
	}
	for (int i = 0; i < n; i++) {
		cs[i].impulse = p[2 * i];
		cs[i].impulse_t = p[2 * i + 1];
	}
	return 1;
}

/* The cases of one contact in the order tried after separating: stick,
 * slide forward, slide backward; without friction only "pressed". */
static int cases_of(const thesis_contact *c)
{
	return c->mu > 0.0 ? 3 : 1;
}

static int enumerate(const double *k, const double *q, thesis_contact *cs, int n, double tol)
{
	/* Contacts pressed: 0, then 1, ... n; for each set of pressed contacts
	 * every combination of their cases. */
	for (int size = 0; size <= n; size++) {
		for (unsigned set = 0; set < (1u << n); set++) {
			int count = 0;
			for (int i = 0; i < n; i++)
				count += (set >> i) & 1u;
			if (count != size)
				continue;
			int combos = 1;
			for (int i = 0; i < n; i++)
				if ((set >> i) & 1u)
					combos *= cases_of(&cs[i]);
			for (int combo = 0; combo < combos; combo++) {
				int mode[FRICTION_EXACT_MAX], rest = combo;
				for (int i = 0; i < n; i++) {
					mode[i] = CASE_SEPARATE;
					if ((set >> i) & 1u) {
						mode[i] = CASE_STICK + rest % cases_of(&cs[i]);
						rest /= cases_of(&cs[i]);
						if (cs[i].mu == 0.0)
							mode[i] = CASE_SLIDE_FORWARD; /* P_t = 0 */
					}
				}
				if (try_cases(k, q, cs, n, mode, tol))
					return 1;
			}
		}
	}
	return 0;
}

/* Projected Gauss-Seidel on the box; K's diagonal from k_rows. */
static void gauss_seidel(double inv_mass, double inv_j, thesis_contact *cs, int n)
{
	for (int i = 0; i < n; i++)
		cs[i].impulse = cs[i].impulse_t = 0.0;
	for (int sweep = 0; sweep < FRICTION_SWEEPS; sweep++) {
		double change = 0.0;
		for (int r = 0; r < 2 * n; r++) {
			thesis_contact *c = &cs[r / 2];
			double u = r % 2 ? c->vrel_t : c->vrel - c->bound;
			for (int s = 0; s < 2 * n; s++)
				u += k_rows(inv_mass, inv_j, cs, r, s) *
				     (s % 2 ? cs[s / 2].impulse_t : cs[s / 2].impulse);
			double kd = k_rows(inv_mass, inv_j, cs, r, r);
			if (r % 2 == 0) {
				double p = fmax(0.0, c->impulse - u / kd);
				change = fmax(change, fabs(p - c->impulse));
				c->impulse = p;
			} else {
				double lim = c->mu * c->impulse;
				double p = fmin(fmax(c->impulse_t - u / kd, -lim), lim);
				change = fmax(change, fabs(p - c->impulse_t));
				c->impulse_t = p;
			}
		}
		if (change <= 1e-14)
			return;
	}
}

int bsim_thesis_contact_solve(double inv_mass, double inv_j, thesis_contact *cs, int n)
{
	int friction = 0;
	for (int i = 0; i < n; i++) {
		cs[i].impulse_t = 0.0;
		friction |= cs[i].mu > 0.0;
	}
	if (!friction)
		return bsim_thesis_lcp_solve_j(inv_mass, inv_j, cs, n);
	if (n <= FRICTION_EXACT_MAX) {
		int m = 2 * n;
		double k[FRICTION_ROWS * FRICTION_ROWS], q[FRICTION_ROWS], qmax = 0.0;
		for (int r = 0; r < m; r++) {
			q[r] = r % 2 ? cs[r / 2].vrel_t : cs[r / 2].vrel - cs[r / 2].bound;
			qmax = fmax(qmax, fabs(q[r]));
			for (int s = 0; s < m; s++)
				k[r * m + s] = k_rows(inv_mass, inv_j, cs, r, s);
		}
		if (enumerate(k, q, cs, n, 1e-12 * (1.0 + qmax)))
			return 0;
	}
	gauss_seidel(inv_mass, inv_j, cs, n);
	return 1;
}

void bsim_thesis_impulse_sum_extended(const thesis_contact *cs, int n, double j[2], double *jw)
{
	thesis_impulse_sum(cs, n, j);
	*jw = 0.0;
	for (int k = 0; k < n; k++) {
		if (cs[k].impulse_t != 0.0) {
			j[0] -= cs[k].impulse_t * cs[k].n[1];
			j[1] += cs[k].impulse_t * cs[k].n[0];
		}
		*jw += cs[k].impulse * cs[k].cb + cs[k].impulse_t * cs[k].cbt;
	}
}
