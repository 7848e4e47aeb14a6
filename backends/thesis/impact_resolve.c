/* Impacts: the essay's collision method (MODEL.md section 4).
 *
 * A contact that touches, or will touch within this step (gap + h v_rel <=
 * slop), and approaches (v_rel < 0) takes an instantaneous frictionless
 * impulse along n. With the effective mass 1/m_eff = 1/M + c^2/I,
 *   J = -(1 + e) m_eff v_rel,  v += J n / M,  omega -= J c / I,
 * which reverses v_rel scaled by e and conserves the angular momentum of
 * body and beam about the pivot (essay Eqs. 2.4-2.9). Restitution is e for
 * tangent contacts and tip_restitution for tip contacts. An approach slower
 * than rest_threshold gets e = 0: the contact turns persistent (essay
 * Sec. 2.4); its velocity jump is the plastic impulse rather than the
 * essay's bare reset of omega, so momentum stays conserved.
 *
 * Several contacts at once: simultaneous (default) solves all impulses as
 * one complementarity problem with the bound v_rel+ >= -e v_rel- (exactly
 * mirror symmetric); nearest_first is the essay's order: the contact with
 * the smaller gap first, then the others, repeated while any approaches.
 *
 * The knob impact_mass puts m_i in place of M in this solve only (1/m_eff
 * and v += J n / m_i): essay Eq. 2.4 read literally, m_i r v_ni + I omega_i
 * = m_i r v_nf + I omega_f, with m_i = 0.1 kg the beam's mass where the
 * body's M belongs (MODEL.md section 2). Such an impact conserves
 * m_i r v + I omega, not the angular momentum of body and beam, and in
 * general not energy either: the kinetic energy (with M) it removes, or
 * adds, is what energy.impact records (negative where it adds). */
#include <math.h>
#include <stddef.h>

#include "util/fminmax.h"
#include "thesis/thesis.h"

static void impact_bounds(const struct bsim_world *w, thesis_contact *c)
{
	c->bound = c->vrel < -w->rest_threshold ? -c->e * c->vrel : 0.0;
}

static void impact_apply(struct bsim_world *w, const thesis_contact *cs, int n)
{
	double j[2];
	thesis_impulse_sum(cs, n, j);
	w->v[0] += j[0] * w->impact_inv_mass;
	w->v[1] += j[1] * w->impact_inv_mass;
	for (int i = 0; i < n; i++) {
		thesis_beam *b = &w->beams[cs[i].beam];
		b->omega -= cs[i].impulse * cs[i].c / b->inertia;
		if (cs[i].impulse > 0.0)
			thesis_beam_pushed(w, cs[i].beam);
	}
}

/* Passes of the nearest-first order at most, and the approach speed, m/s,
 * left at the end that counts as the limit reached. */
#define IMPACT_PASSES_MAX   100
#define IMPACT_APPROACH_TOL 1e-9

/* The essay's order: one contact at a time, nearest first. */
static void impact_nearest_first(struct bsim_world *w, thesis_contact *cs, int n)
{
	for (int pass = 0; pass <= IMPACT_PASSES_MAX; pass++) {
		thesis_contact *next = NULL;
		for (int i = 0; i < n; i++) {
			thesis_contact_velocity(w, &cs[i]);
			if (cs[i].vrel < 0.0 && (!next || cs[i].gap < next->gap))
				next = &cs[i];
		}
		if (!next)
			return;
		if (pass == IMPACT_PASSES_MAX) {
			/* The limit, not a solution, unless what approaches is
			 * round-off: a plastic impulse leaves v_rel at -1e-15
			 * m/s, which this loop chases to the limit in most
			 * trials (1.8e-15 m/s at most over H2). */
			w->solver.iteration_limit += next->vrel < -IMPACT_APPROACH_TOL;
			return;
		}
		impact_bounds(w, next);
		thesis_lcp_solve(w->impact_inv_mass, next, 1);
		impact_apply(w, next, 1);
		if (next->impulse > 0.0 && next->vrel < -w->rest_threshold)
			w->impacts++;
	}
}

int thesis_impact_resolve(struct bsim_world *w, double h)
{
	/* The touching contacts go to the front of the list. */
	thesis_contact *cs = w->contacts;
	int n = 0, approaching = 0;
	for (int i = 0; i < w->n_contacts; i++) {
		thesis_contact c = cs[i];
		thesis_contact_velocity(w, &c);
		if (c.gap + h * bsim_fmin(c.vrel, 0.0) > w->slop)
			continue;
		c.inv_i = w->beams[c.beam].inv_inertia;
		approaching |= c.vrel < 0.0;
		cs[i] = cs[n];
		cs[n++] = c;
	}
	if (!approaching)
		return 0;

	double ke = thesis_kinetic_energy(w);
	if (w->impact_order == THESIS_NEAREST_FIRST) {
		impact_nearest_first(w, cs, n);
	} else {
		for (int i = 0; i < n; i++)
			impact_bounds(w, &cs[i]);
		w->solver.iteration_limit += thesis_lcp_solve(w->impact_inv_mass, cs, n);
		impact_apply(w, cs, n);
		for (int i = 0; i < n; i++)
			w->impacts += cs[i].impulse > 0.0 && cs[i].vrel < -w->rest_threshold;
	}
	w->energy.impact += ke - thesis_kinetic_energy(w);
	return 1;
}
