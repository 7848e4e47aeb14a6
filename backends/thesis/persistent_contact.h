/* One step of smooth motion with persistent contacts: the essay's constraint
 * method (docs/model.md section 5) in velocity form.
 *
 * Free velocities over the step: v* = v + h F / M, omega*_i from the beam
 * integrator. Contact impulses P_i >= 0 then give
 *   v' = v* + sum_i P_i n_i / M,   omega'_i = omega*_i - P_i c_i / (I_i D_i).
 * Positions move with the mean velocity (midpoint), so the gap changes by
 * h (v_rel + v_rel') / 2 to first order. Requiring the gap to stay >= 0,
 *   v_rel' >= -v_rel - 2 max(gap, 0) / h   (euler: v_rel' >= -max(gap, 0)/h),
 * with P_i (v_rel' - bound) = 0, is a complementarity problem; for a
 * touching contact at rest (gap 0, v_rel 0) it is v_rel' >= 0: the two bodies
 * share the normal velocity while lambda = P / h >= 0 (essay Eqs. 2.10-2.13,
 * whose curvature terms enter here through the geometry of the next step),
 * and a contact whose free motion separates gets P = 0 and detaches. A
 * contact still some way off is included too (speculative), so no step can
 * carry the body through a beam.
 *
 * Ledger: with midpoint positions the body's kinetic energy changes by
 * exactly F . dx + sum P_i n_i . v_m, a beam's energy by -h d omega_m^2 -
 * P_i c_i omega_m; the contact forces' work sum P_i (n_i . v_m - c_i
 * omega_m,i) is reported, negated, as energy.contact.
 *
 * Extended path (thesis.h's head): the body's free angular velocity w* =
 * w + h T / J under the torque T, v_rel and the bound with w cb in them,
 * K with cb^2 / J, and with friction the tangent rows: v_t' = 0 while
 * |P_t| <= mu P_n (stick), else P_t = -+mu P_n against v_t' (slide),
 * friction_solve.c; then w' = w* + sum (P_n cb + P_t cbt) / J and the
 * heading moves by h w_m (thesis_body_turn). The body's kinetic energy,
 * rotation's included, changes by F . dx + T h w_m + sum P . (contact
 * velocity at the means), so energy.contact is the contact impulses' work
 *   -sum P_n (n . v_m + cb w_m - c omega_m) + P_t (t . v_m + cbt w_m - ct omega_m),
 * friction's loss included; the runner credits T h w_m, the torque's work
 * over the heading's change.
 *
 * Inline, included by the step (thesis_step.h), which compiles it for
 * each body and each form of the step's sets (step_sets.h). */
#ifndef BSIM_THESIS_PERSISTENT_CONTACT_H
#define BSIM_THESIS_PERSISTENT_CONTACT_H

#include <math.h>
#include <stddef.h>

#include "util/fminmax.h"
#include "thesis/step_sets.h"

/* The extended path (this file's head), on the world's lists; the essay's
 * path below keeps its own loop, which this one's terms would slow. */
static inline void persistent_solve_extended(struct bsim_world *w, const double force[2],
                                             double torque, double h)
{
	double v0[2] = {w->v[0], w->v[1]};
	double vf[2] = {v0[0] + h * force[0] * w->model->inv_mass,
	                v0[1] + h * force[1] * w->model->inv_mass};
	thesis_contact *cs = w->contacts;
	int n = w->n_contacts;
	double w0 = w->angular_velocity, wf = w0;
	if (w->model->rotates)
		wf = w0 + h * torque * w->model->inv_body_inertia;

	for (int k = 0; k < n; k++) {
		thesis_contact *c = &cs[k];
		const thesis_beam_model *bm = &w->model->beams[c->beam];
		const thesis_beam *b = &w->beams[c->beam];
		double vrel0 = (v0[0] * c->n[0] + v0[1] * c->n[1]) - b->omega * c->c;
		c->omega_free = thesis_beam_free_omega(bm, b, h, w->model->integrator);
		double gap = bsim_fmax(c->gap, 0.0);
		c->inv_i = thesis_beam_response(bm, b, w->model->integrator);
		c->vrel = (vf[0] * c->n[0] + vf[1] * c->n[1]) - c->omega_free * c->c;
		vrel0 += w0 * c->cb;
		c->vrel += wf * c->cb;
		c->vrel_t =
		        (vf[1] * c->n[0] - vf[0] * c->n[1]) + wf * c->cbt - c->omega_free * c->ct;
		c->bound = w->model->integrator == THESIS_EULER ? -gap / h : -vrel0 - 2.0 * gap / h;
	}
	/* No contact (free flight): no solve, and the impulse sum of none is
	 * 0 (thesis_impulse_sum's start), added as it would be. */
	double j[2] = {0.0, 0.0}, jw = 0.0;
	if (n) {
		w->solver.iteration_limit += bsim_thesis_contact_solve(
		        w->model->inv_mass, w->model->inv_body_inertia, cs, n);
		bsim_thesis_impulse_sum_extended(cs, n, j, &jw);
	}
	double vm[2];
	thesis_body_advance(w, v0, vf, j, h, vm, w->model->integrator);
	thesis_body_turn(w, w0, torque, jw, h);
	double wm = w->model->integrator == THESIS_EULER ? w->angular_velocity
	                                                 : 0.5 * (w0 + w->angular_velocity);

	/* Beams in contact take their impulse; all others move freely. A beam
	 * at rest and untouched stays at rest and costs nothing: only the awake
	 * ones (every contact's beam among them) are visited, in ascending
	 * order, so the ledger's sums are those over all beams. */
	for (int k = 0; k < n; k++) {
		w->contact_of[cs[k].beam] = k;
		if (cs[k].impulse > 0.0)
			thesis_beam_pushed(w, cs[k].beam, cs[k].impulse);
	}
	for (int a = 0; a < w->n_awake; a++) {
		int i = w->awake[a];
		const thesis_beam_model *bm = &w->model->beams[i];
		thesis_beam *b = &w->beams[i];
		int k = w->contact_of[i];
		w->contact_of[i] = -1;
		if (k < 0 && b->theta == 0.0 && b->omega == 0.0)
			continue;
		double omega_new;
		if (k < 0) {
			omega_new = thesis_beam_free_omega(bm, b, h, w->model->integrator);
		} else {
			/* The beam's contacts: one, or a capsule's two. */
			double moment = 0.0;
			for (int q = 0; q < n; q++)
				if (cs[q].beam == i)
					moment += cs[q].impulse * cs[q].c +
					          cs[q].impulse_t * cs[q].ct;
			omega_new = cs[k].omega_free - moment * cs[k].inv_i;
			double omega_m = w->model->integrator == THESIS_EULER
			                         ? omega_new
			                         : 0.5 * (b->omega + omega_new);
			for (int q = 0; q < n; q++) {
				const thesis_contact *c = &cs[q];
				if (c->beam != i)
					continue;
				w->energy.contact -=
				        c->impulse *
				        ((c->n[0] * vm[0] + c->n[1] * vm[1]) - c->c * omega_m);
				w->energy.contact -=
				        c->impulse * (c->cb * wm) +
				        c->impulse_t * ((vm[1] * c->n[0] - vm[0] * c->n[1]) +
				                        c->cbt * wm - c->ct * omega_m);
			}
		}
		w->energy.damper += thesis_beam_advance(bm, b, omega_new, h, w->model->integrator);
	}
}

/* The essay's disk's path: the body's free velocity v + dv (dv = h F /
 * M, as the caller computes it); the dampers' loss added to *damper and
 * minus the contacts' work to *contact, J. integrator: w->model->integrator, a
 * constant where the caller gives one. */
THESIS_SPECIALISED void persistent_solve_disk(struct bsim_world *w, thesis_run *run,
                                              const double dv[2], double h, double *damper,
                                              double *contact, const int integrator)
{
	double v0[2] = {w->v[0], w->v[1]};
	double vf[2] = {v0[0] + dv[0], v0[1] + dv[1]};
	thesis_contact *cs = w->contacts;
	int n = w->n_contacts;

	for (int k = 0; k < n; k++) {
		thesis_smooth_row(&cs[k], &w->model->beams[cs[k].beam], &w->beams[cs[k].beam], v0,
		                  vf, h, integrator);
		w->contact_of[cs[k].beam] = k;
	}
	/* No contact (free flight): no solve, and the impulse sum of none is
	 * 0 (thesis_impulse_sum's start), added as it would be. */
	double j[2] = {0.0, 0.0};
	if (n) {
		w->solver.iteration_limit += thesis_lcp_disk(w->model->inv_mass, cs, n);
		thesis_impulse_sum(cs, n, j);
		for (int k = 0; k < n; k++)
			if (cs[k].impulse > 0.0)
				step_push(w, run, cs[k].beam, cs[k].impulse);
	}
	double vm[2];
	thesis_body_advance(w, v0, vf, j, h, vm, integrator);

	/* Beams in contact take their impulse; all others move freely. A beam
	 * at rest and untouched stays at rest and costs nothing: only the awake
	 * ones (every contact's beam among them) are visited, in ascending
	 * order, so the ledger's sums are those over all beams. */
	double e_damper = *damper, e_contact = *contact;
	for (int a = 0, na = step_awake_n(w, run); a < na; a++) {
		int i = step_awake_at(w, run, a);
		if (i < 0)
			continue;
		int k = w->contact_of[i];
		w->contact_of[i] = -1;
		thesis_smooth_beam(&w->model->beams[i], &w->beams[i], k < 0 ? NULL : &cs[k], vm, h,
		                   integrator, &e_damper, &e_contact);
	}
	*damper = e_damper;
	*contact = e_contact;
}

#endif
