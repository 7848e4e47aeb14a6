/* Impacts: the essay's collision method (docs/model.md section 4).
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
 * body's M belongs (docs/model.md section 2). Such an impact conserves
 * m_i r v + I omega, not the angular momentum of body and beam, and in
 * general not energy either: the kinetic energy (with M) it removes, or
 * adds, is what energy.impact records (negative where it adds).
 *
 * Extended path (a body that turns or is not a disk, or friction; thesis.h's
 * head): v_rel = v . n + w cb - omega c, and the effective mass has the
 * body's rotation too,
 *   1/m_eff = 1/M + cb^2 / J + c^2 / I,
 * and with friction each contact's tangential impulse P_t with |P_t| <=
 * mu P_n brings the tangential relative velocity v_t to 0 (stick) or acts
 * at the cone's edge against it (slide): friction_solve.c, the bound on
 * the normal velocity as above, none on the tangential one (no tangential
 * restitution). Impulses in the kinetic energy: with u the contact
 * velocities before, E' - E = P . u + P . K P / 2. Without friction that is
 * sum P_n v_n (1 - e) / 2 <= 0. With friction and e > 0, Newton's
 * restitution can make E' > E where the normal and tangential rows are
 * coupled (K_nt != 0: Kane's paradox). The plastic impulse P_0 (every e =
 * 0) never gains energy (P . u' <= 0 by complementarity and the cone, so
 * E' - E <= -P . K P / 2); then P = P_0 + s (P_e - P_0) with the largest s
 * in [0, 1] for which E' <= E is taken, a root of a quadratic in s. Both
 * ends lie in the cone and separate (u_n' >= 0), so P does too. The
 * impacts so scaled are counted in w->impacts_scaled. The loss, friction's
 * included, is energy.impact.
 *
 * Inline, included by the step (thesis_step.h), which compiles it for
 * each body and each form of the step's sets (step_sets.h: run NULL, the
 * world's lists). */
#ifndef BSIM_THESIS_IMPACT_RESOLVE_H
#define BSIM_THESIS_IMPACT_RESOLVE_H

#include <math.h>
#include <stddef.h>

#include "util/fminmax.h"
#include "thesis/step_sets.h"

/* Contacts whose friction impact's energy is checked (a body meets 4 at
 * most in a lattice). */
#define IMPACT_CONTACTS_MAX 16

/* extended: constant (contact_geometry.h's contact_detect): 0 compiles the
 * essay's disk's copy of this file's functions without the extended path. */
THESIS_SPECIALISED void impact_apply(struct bsim_world *w, thesis_run *run,
                                     const thesis_contact *cs, int n, const int extended)
{
	double j[2], jw = 0.0;
	if (extended && w->model->extended)
		bsim_thesis_impulse_sum_extended(cs, n, j, &jw);
	else
		thesis_impulse_sum(cs, n, j);
	w->v[0] += j[0] * w->model->impact_inv_mass;
	w->v[1] += j[1] * w->model->impact_inv_mass;
	if (extended && w->model->rotates)
		w->angular_velocity += jw * w->model->inv_body_inertia;
	for (int i = 0; i < n; i++) {
		thesis_beam *b = &w->beams[cs[i].beam];
		const double inertia = w->model->beams[cs[i].beam].inertia;
		if (extended && w->model->extended && cs[i].impulse_t != 0.0)
			b->omega -=
			        (cs[i].impulse * cs[i].c + cs[i].impulse_t * cs[i].ct) / inertia;
		else
			b->omega -= cs[i].impulse * cs[i].c / inertia;
		if (cs[i].impulse > 0.0)
			step_push(w, run, cs[i].beam, cs[i].impulse);
	}
}

/* The kinetic energy's change for impulses p (2 per contact: normal,
 * tangent) from contact velocities u (q without the bounds), J:
 * P . u + P . K P / 2, K from the rows as friction_solve.c builds it. */
static inline double impact_energy_change(const struct bsim_world *w, const thesis_contact *cs,
                                          int n, const double *pn, const double *pt)
{
	double jv[2] = {0.0, 0.0}, jw = 0.0, e = 0.0;
	for (int i = 0; i < n; i++) {
		e += pn[i] * cs[i].vrel + pt[i] * cs[i].vrel_t;
		jv[0] += pn[i] * cs[i].n[0] - pt[i] * cs[i].n[1];
		jv[1] += pn[i] * cs[i].n[1] + pt[i] * cs[i].n[0];
		jw += pn[i] * cs[i].cb + pt[i] * cs[i].cbt;
		double jb = pn[i] * cs[i].c + pt[i] * cs[i].ct;
		e += 0.5 * jb * jb * cs[i].inv_i;
		/* a capsule's two contacts turn one beam: (jb_i + jb_j)^2 / 2I */
		for (int k = i + 1; k < n; k++)
			if (cs[i].two && cs[k].two && cs[i].beam == cs[k].beam)
				e += jb * (pn[k] * cs[k].c + pt[k] * cs[k].ct) * cs[i].inv_i;
	}
	e += 0.5 * (jv[0] * jv[0] + jv[1] * jv[1]) * w->model->impact_inv_mass +
	     0.5 * jw * jw * w->model->inv_body_inertia;
	return e;
}

/* The extended path's solve with friction: Newton's restitution, scaled
 * toward the plastic impulse where it would gain energy (this file's head).
 * 1 if a solve was not exact. */
static inline int impact_solve_friction(struct bsim_world *w, thesis_contact *cs, int n)
{
	double inv_j = w->model->inv_body_inertia;
	int inexact = bsim_thesis_contact_solve(w->model->impact_inv_mass, inv_j, cs, n);
	double pn[IMPACT_CONTACTS_MAX], pt[IMPACT_CONTACTS_MAX];
	if (n > IMPACT_CONTACTS_MAX)
		return inexact;
	for (int i = 0; i < n; i++)
		pn[i] = cs[i].impulse, pt[i] = cs[i].impulse_t;
	double de = impact_energy_change(w, cs, n, pn, pt);
	double ke = thesis_kinetic_energy(w, 1);
	if (!(de > 1e-12 * ke))
		return inexact;
	double bound[IMPACT_CONTACTS_MAX];
	for (int i = 0; i < n; i++) {
		bound[i] = cs[i].bound;
		cs[i].bound = 0.0;
	}
	inexact |= bsim_thesis_contact_solve(w->model->impact_inv_mass, inv_j, cs, n);
	double p0n[IMPACT_CONTACTS_MAX], p0t[IMPACT_CONTACTS_MAX], dn[IMPACT_CONTACTS_MAX],
	        dt[IMPACT_CONTACTS_MAX];
	for (int i = 0; i < n; i++) {
		cs[i].bound = bound[i];
		p0n[i] = cs[i].impulse, p0t[i] = cs[i].impulse_t;
		dn[i] = pn[i] - p0n[i], dt[i] = pt[i] - p0t[i];
	}
	/* E(s) - E = qa s^2 + qb s + c0 along P_0 + s D: <= 0 at s = 0 (the
	 * plastic impulse) and > 0 at s = 1 (Newton's); the root between. */
	double c0 = impact_energy_change(w, cs, n, p0n, p0t);
	double e1 = impact_energy_change(w, cs, n, dn, dt);       /* D . u + D K D / 2 */
	double e_newton = impact_energy_change(w, cs, n, pn, pt); /* P_0 + D */
	/* With f(P) = P . u + P K P / 2: f(P_0 + s D) = c0 + s (D . u + D K P_0)
	 * + s^2 D K D / 2; from the three values f(P_0) = c0, f(D) = e1 and
	 * f(P_0 + D) = e_newton: D K D / 2 = e1 - D . u, and the linear term
	 * is e_newton - c0 - D K D / 2. */
	double du = 0.0;
	for (int i = 0; i < n; i++)
		du += dn[i] * cs[i].vrel + dt[i] * cs[i].vrel_t;
	double qa = e1 - du, qb = e_newton - c0 - qa;
	double s = 0.0;
	if (qa > 0.0) {
		double disc = qb * qb - 4.0 * qa * c0;
		s = (-qb + sqrt(fmax(disc, 0.0))) / (2.0 * qa);
	} else if (qb > 0.0) {
		s = -c0 / qb;
	}
	s = fmin(fmax(s, 0.0), 1.0);
	for (int i = 0; i < n; i++) {
		cs[i].impulse = p0n[i] + s * dn[i];
		cs[i].impulse_t = p0t[i] + s * dt[i];
	}
	w->impacts_scaled++;
	return inexact;
}

/* The impulses of contacts cs (their bounds set) into cs; 1 if the solve
 * was not exact. */
THESIS_SPECIALISED int impact_solve(struct bsim_world *w, thesis_contact *cs, int n,
                                    const int extended)
{
	if (!(extended && w->model->extended))
		return thesis_lcp_disk(w->model->impact_inv_mass, cs, n);
	if (w->model->friction > 0.0)
		return impact_solve_friction(w, cs, n);
	return bsim_thesis_contact_solve(w->model->impact_inv_mass, w->model->inv_body_inertia, cs,
	                                 n);
}

/* Passes of the nearest-first order at most, and the approach speed, m/s,
 * left at the end that counts as the limit reached. */
#define IMPACT_PASSES_MAX   100
#define IMPACT_APPROACH_TOL 1e-9

/* The essay's order: one contact at a time, nearest first. */
THESIS_SPECIALISED void impact_nearest_first(struct bsim_world *w, thesis_run *run,
                                             thesis_contact *cs, int n, int *impacts,
                                             const int extended)
{
	for (int pass = 0; pass <= IMPACT_PASSES_MAX; pass++) {
		thesis_contact *next = NULL;
		for (int i = 0; i < n; i++) {
			thesis_contact_velocity(w, &cs[i], extended);
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
		thesis_impact_bound(w, next);
		impact_solve(w, next, 1, extended);
		impact_apply(w, run, next, 1, extended);
		if (next->impulse > 0.0 && next->vrel < -w->model->rest_threshold)
			(*impacts)++;
	}
}

/* The impacts of the step's w->n_contacts contacts; 1 if one approached.
 * The loss into *e_impact, J, and the impacts into *impacts. */
THESIS_SPECIALISED int impact_resolve(struct bsim_world *w, thesis_run *run, double h,
                                      double *e_impact, int *impacts, const int extended)
{
	/* The touching contacts go to the front of the list. */
	thesis_contact *cs = w->contacts;
	int approaching;
	int n = thesis_impacts_touching(w, w->n_contacts, h, &approaching, extended);
	if (!approaching)
		return 0;

	double ke = step_kinetic(w, run, extended);
	if (!run && w->model->impact_order == THESIS_NEAREST_FIRST) { /* a run's are simultaneous */
		impact_nearest_first(w, run, cs, n, impacts, extended);
	} else {
		for (int i = 0; i < n; i++)
			thesis_impact_bound(w, &cs[i]);
		w->solver.iteration_limit += impact_solve(w, cs, n, extended);
		impact_apply(w, run, cs, n, extended);
		for (int i = 0; i < n; i++)
			*impacts += cs[i].impulse > 0.0 && cs[i].vrel < -w->model->rest_threshold;
	}
	*e_impact += ke - step_kinetic(w, run, extended);
	return 1;
}

#endif
