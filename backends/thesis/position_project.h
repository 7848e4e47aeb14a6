/* Position projection: keeps the drift of persistent contacts bounded
 * (docs/model.md section 5).
 *
 * The velocity-level contact holds v_rel = 0, but the contact geometry
 * turns within a step, so a gap drifts at second order (about h^2 v^2 / R
 * per step). After the step, contacts that penetrate by more than slop are
 * pushed apart with position impulses mu_i >= 0 that solve the same
 * complementarity problem as impacts, on positions:
 *   gap_i + sum_j K_ij mu_j >= 0,   dx = sum mu_i n_i / M,   dtheta_i = -mu_i c_i / I_i.
 * Velocities are untouched, so no energy is injected into the motion; the
 * springs' energy change, and the work the runner credits to the external
 * force over the shift dx, are reported as energy.correction.
 *
 * Extended path (thesis.h's head): the body turns too, dpsi = sum mu_i cb_i
 * / J, and K has cb_i cb_j / J (frictionless: a projection moves along the
 * normals only); the torque's work over dpsi joins the correction.
 *
 * Inline, included by the step (thesis_step.h), which compiles it for
 * each body and each form of the step's sets (step_sets.h). */
#ifndef BSIM_THESIS_POSITION_PROJECT_H
#define BSIM_THESIS_POSITION_PROJECT_H

#include "thesis/step_sets.h"

/* extended: constant (contact_geometry.h's contact_detect): 0 compiles the
 * essay's disk's copy of this file's functions without the extended path. */
THESIS_SPECIALISED void project_once(struct bsim_world *w, thesis_contact *cs, int n,
                                     const double force[2], double torque, double *correction,
                                     const int extended)
{
	for (int k = 0; k < n; k++) {
		cs[k].vrel = cs[k].gap;
		cs[k].bound = 0.0;
		cs[k].inv_i = w->model->beams[cs[k].beam].inv_inertia;
	}
	if (extended && w->model->extended)
		w->solver.iteration_limit += bsim_thesis_lcp_solve_j(
		        w->model->inv_mass, w->model->inv_body_inertia, cs, n);
	else
		w->solver.iteration_limit += thesis_lcp_disk(w->model->inv_mass, cs, n);
	if (extended && w->model->rotates) {
		double dpsi = 0.0;
		for (int k = 0; k < n; k++)
			dpsi += cs[k].impulse * cs[k].cb;
		dpsi *= w->model->inv_body_inertia;
		w->heading += dpsi;
		*correction += torque * dpsi;
	}
	thesis_project_move(w, cs, n, force, correction);
}

/* The contacts of the beams of cs[0..n) detected again into cs, each beam
 * once (a capsule may have two contacts with one beam, and may have one
 * where it had two, or two where it had one): the beams are listed first
 * (in w->candidates, free after the step's detection). A run touched
 * every beam at its start (run not NULL). */
THESIS_SPECIALISED int redetect(struct bsim_world *w, const thesis_run *run, thesis_contact *cs,
                                int n, double margin, const int extended)
{
	if (!extended) { /* the essay's disk */
		int m = 0;
		for (int k = 0; k < n; k++)
			m += run ? disk_detect(w, cs[k].beam, margin, &cs[m], 1, 1)
			         : disk_detect(w, cs[k].beam, margin, &cs[m], 1, 0);
		return m;
	}
	if (!w->model->shaped) { /* one contact a beam: in place, in order */
		int m = 0;
		for (int k = 0; k < n; k++)
			m += bsim_thesis_contact_detect(w, cs[k].beam, margin, &cs[m]);
		return m;
	}
	int nb = 0;
	for (int k = 0; k < n; k++) {
		int seen = 0;
		for (int q = 0; q < nb && !seen; q++)
			seen = w->candidates[q] == cs[k].beam;
		if (!seen)
			w->candidates[nb++] = cs[k].beam;
	}
	int m = 0;
	for (int q = 0; q < nb; q++)
		m += bsim_thesis_contact_detect(w, w->candidates[q], margin, &cs[m]);
	return m;
}

/* Re-detects the step's contacts at the new positions (they are the only
 * beams the step could have reached) and projects out penetration; the
 * correction's energy added to *correction, J. */
THESIS_SPECIALISED void position_project(struct bsim_world *w, thesis_run *run,
                                         const double force[2], double torque, double *correction,
                                         const int extended)
{
	double margin = w->model->contact_tol;
	thesis_contact *cs = w->contacts;
	int n = redetect(w, run, cs, w->n_contacts, margin, extended);
	for (int pass = 0; w->model->projection && thesis_project_more(w, cs, n, pass); pass++) {
		project_once(w, cs, n, force, torque, correction, extended);
		n = redetect(w, run, cs, n, margin, extended);
	}
	w->n_contacts = n;
	for (int k = 0; k < n; k++)
		if (cs[k].gap <= w->model->contact_tol)
			step_type(w, run, cs[k].beam, k);
}

#endif
