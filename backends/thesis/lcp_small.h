/* The contact complementarity problem of one or two contacts (lcp_solve.c's
 * head gives the problem): inline, so that the steps that solve it every
 * step (thesis_steps.c) make no call for it; lcp_solve.c's solve uses the
 * same code. Included by thesis.h. */
#ifndef BSIM_THESIS_LCP_SMALL_H
#define BSIM_THESIS_LCP_SMALL_H

/* inv_j: the body's 1/J on the extended path (thesis.h), whose rotation
 * adds cb_i cb_j / J to K; 0 (the essay's body, which does not turn) adds
 * nothing, not even a rounding. */
THESIS_SPECIALISED double k_entry(double inv_mass, double inv_j, const thesis_contact *a,
                                  const thesis_contact *b, const int extended)
{
	double k = (a->n[0] * b->n[0] + a->n[1] * b->n[1]) * inv_mass;
	if (a == b)
		k += a->c * a->c * a->inv_i;
	else if (extended && a->two && b->two && a->beam == b->beam) /* a capsule's two */
		k += a->c * b->c * a->inv_i;
	if (extended && inv_j != 0.0)
		k += a->cb * b->cb * inv_j;
	return k;
}

THESIS_SPECIALISED void lcp_two(double inv_mass, double inv_j, thesis_contact *c0,
                                thesis_contact *c1, const int extended)
{
	double q0 = c0->vrel - c0->bound, q1 = c1->vrel - c1->bound;
	double k00 = k_entry(inv_mass, inv_j, c0, c0, extended),
	       k11 = k_entry(inv_mass, inv_j, c1, c1, extended);
	double k01 = k_entry(inv_mass, inv_j, c0, c1, extended);
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

/* The solve of n <= 2 contacts (none: nothing to do): n = 1, P = max(0, -q /
 * K); n = 2, lcp_two. */
THESIS_SPECIALISED void thesis_lcp_small(double inv_mass, double inv_j, thesis_contact *cs, int n,
                                         const int extended)
{
	if (n == 1) {
		double q = cs[0].vrel - cs[0].bound;
		cs[0].impulse =
		        q < 0.0 ? -q / k_entry(inv_mass, inv_j, &cs[0], &cs[0], extended) : 0.0;
	} else if (n == 2) {
		lcp_two(inv_mass, inv_j, &cs[0], &cs[1], extended);
	}
}

/* bsim_thesis_lcp_solve (the essay's disk's solve), one or two contacts
 * inline. */
static inline int thesis_lcp_disk(double inv_mass, thesis_contact *cs, int n)
{
	if (n > 2)
		return bsim_thesis_lcp_solve(inv_mass, cs, n);
	thesis_lcp_small(inv_mass, 0.0, cs, n, 0);
	return 0;
}

/* The total impulse sum P_i n_i on the body, N s. */
static inline void thesis_impulse_sum(const thesis_contact *cs, int n, double j[2])
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

#endif
