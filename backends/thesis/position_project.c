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
 * normals only); the torque's work over dpsi joins the correction. */
#include "thesis/thesis.h"

/* extended: constant (contact_geometry.h's contact_detect): 0 compiles the
 * essay's disk's copy of this file's functions without the extended path. */
THESIS_SPECIALISED void project_once(struct bsim_world *w, thesis_contact *cs, int n,
                                     const double force[2], double torque, const int extended)
{
	for (int k = 0; k < n; k++) {
		cs[k].vrel = cs[k].gap;
		cs[k].bound = 0.0;
		cs[k].inv_i = w->beams[cs[k].beam].inv_inertia;
	}
	if (extended && w->extended)
		w->solver.iteration_limit +=
		        bsim_thesis_lcp_solve_j(w->inv_mass, w->inv_body_inertia, cs, n);
	else
		w->solver.iteration_limit += bsim_thesis_lcp_solve(w->inv_mass, cs, n);
	if (extended && w->rotates) {
		double dpsi = 0.0;
		for (int k = 0; k < n; k++)
			dpsi += cs[k].impulse * cs[k].cb;
		dpsi *= w->inv_body_inertia;
		w->heading += dpsi;
		w->energy.correction += torque * dpsi;
	}
	thesis_project_move(w, cs, n, force, &w->energy.correction);
}

/* The contacts of the beams of cs[0..n) detected again into cs, each beam
 * once (a capsule may have two contacts with one beam, and may have one
 * where it had two, or two where it had one): the beams are listed first
 * (in w->candidates, free after the step's detection). */
THESIS_SPECIALISED int redetect(struct bsim_world *w, thesis_contact *cs, int n, double margin,
                                const int extended)
{
	if (!extended) { /* the essay's disk */
		int m = 0;
		for (int k = 0; k < n; k++)
			m += bsim_thesis_contact_redetect_disk(w, cs[k].beam, margin, &cs[m]);
		return m;
	}
	if (!w->shaped) { /* one contact a beam: in place, in order */
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
 * beams the step could have reached) and projects out penetration. */
THESIS_SPECIALISED void position_project(struct bsim_world *w, const double force[2], double torque,
                                         const int extended)
{
	double margin = w->contact_tol;
	thesis_contact *cs = w->contacts;
	int n = redetect(w, cs, w->n_contacts, margin, extended);
	for (int pass = 0; w->projection && thesis_project_more(w, cs, n, pass); pass++) {
		project_once(w, cs, n, force, torque, extended);
		n = redetect(w, cs, n, margin, extended);
	}
	w->n_contacts = n;
	for (int k = 0; k < n; k++)
		if (cs[k].gap <= w->contact_tol)
			w->contact_type[cs[k].beam] = cs[k].type;
}

void bsim_thesis_position_project(struct bsim_world *w, const double force[2], double torque)
{
	position_project(w, force, torque, 1);
}

void bsim_thesis_position_project_disk(struct bsim_world *w, const double force[2])
{
	position_project(w, force, 0.0, 0);
}
