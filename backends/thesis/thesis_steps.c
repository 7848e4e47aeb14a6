/* The thesis backend's runs of steps (a path of its advance, thesis_world.c): the steps
 * thesis_step makes for the essay's disk among a few beams, one after
 * another in one call, each state written as get_state writes it.
 *
 * Which worlds. The essay's disk (w->extended 0) under contact_mode
 * physical, simultaneous impacts and no sleeping, among at most
 * THESIS_STEPS_BEAMS beams: the single gate of the essay and its variants
 * (H1, H2). There every beam is a candidate of every step, in ascending
 * order (broad_phase.c tests them all, with or without the grid), so the
 * step needs none of the general path's lists: the awake, typed and
 * pushed beams are bit masks here, and the lists are written back when
 * the run ends, as the general path leaves them. The essay's gate (two
 * beams, the midpoint rule) has a copy compiled for it.
 *
 * Why the bits are the same. Each step is step_run's (thesis_world.c) for
 * extended 0, its functions' operations in their order, written in one
 * place from the inline pieces they share (thesis.h, contact_geometry.h,
 * lcp_small.h, beam_integrate.h): detection (contact_detect, with each
 * beam's step margin), impacts (impact_resolve.c), the smooth solve
 * (persistent_contact.c), projection with re-detection
 * (position_project.c), the typed beams, pruning (beam_sleep.c) and the
 * beams listed for the contact flag (contact_list.c). What differs is only what the general
 * path spends on its generality:
 *   - no free-flight test: a step thesis_step would take as free flight
 *     (no beam awake, every beam out of reach) is the general path's step
 *     here, which detects nothing, solves nothing and moves the body by the
 *     same operations (thesis_body_advance with a zero impulse sum), and
 *     whose report finds no beam within BSIM_CONTACT_TOL (the room's margin
 *     includes it): the same state;
 *   - the kinetic energy of the impacts sums every beam in ascending order,
 *     not the awake ones: a beam not awake has omega = +-0 and adds +0 to a
 *     sum that is never -0 (it starts at 1/2 M |v|^2), which leaves it as
 *     it is;
 *   - the force's parts of the margins' speed bound (h |F| / M) and of the
 *     free velocity (h F / M) once a run, by the operations the step makes;
 *   - every beam is marked touched once (thesis_beam_touch), so that a
 *     reset restores it: a reset of a beam the run did not move puts back
 *     what it holds.
 * test_steps checks runs against thesis_step and get_state, state by
 * state, bit for bit. */
#include <math.h>
#include <string.h>

#include "beamsim/contact_flag.h"
#include "util/fminmax.h"
#include "thesis/thesis.h"

/* 1 if beam i is in mask m. */
static inline int gate_in(unsigned m, int i)
{
	return (m >> i) & 1u;
}

int bsim_thesis_steps_takes(const struct bsim_world *w)
{
	return !w->extended && w->contact_mode == THESIS_CONTACT_PHYSICAL &&
	       w->impact_order == THESIS_SIMULTANEOUS && !w->sleep &&
	       w->n_beams <= THESIS_STEPS_BEAMS;
}

/* The kinetic energy of body and beams (thesis_kinetic_energy for the
 * disk), every beam summed: the head says why that is the same. */
static inline double gate_kinetic(const struct bsim_world *w, int nb)
{
	double e = 0.5 * w->mass * (w->v[0] * w->v[0] + w->v[1] * w->v[1]);
	for (int i = 0; i < nb; i++) {
		const thesis_beam *b = &w->beams[i];
		e += 0.5 * b->inertia * b->omega * b->omega;
	}
	return e;
}

/* bsim_thesis_lcp_solve for the disk, one or two contacts inline. */
static inline int gate_lcp(double inv_mass, thesis_contact *cs, int n)
{
	if (n > 2)
		return bsim_thesis_lcp_solve(inv_mass, cs, n);
	thesis_lcp_small(inv_mass, 0.0, cs, n, 0);
	return 0;
}

/* The masks of a run: the beams awake and typed (the step's:
 * contact_type not NONE, written when the run ends), and those pushed in
 * the last step. */
typedef struct gate_masks {
	unsigned awake, typed, pushed;
	unsigned near; /* pushed, or not certainly beyond BSIM_CONTACT_TOL */
} gate_masks;

/* thesis_beam_pushed for the masks: beam i pushed by impulse p (> 0),
 * N s; w->impulse[i] the sum of its pushes in the step where pushed, in
 * the order thesis_beam_pushed sums them. */
static inline void gate_push(struct bsim_world *w, unsigned *pushed, int i, double p)
{
	w->impulse[i] = gate_in(*pushed, i) ? w->impulse[i] + p : p;
	*pushed |= 1u << i;
}

/* impact_resolve.c's impact_resolve for the disk, simultaneous: the
 * touching contacts to the front, one solve, the impulses applied; the
 * loss into *e_impact, the impacts counted into *impacts, the beams
 * pushed into *pushed. */
static inline void gate_impacts(struct bsim_world *w, double h, int nc, unsigned *pushed,
                                double *e_impact, int *impacts, int nb)
{
	thesis_contact *cs = w->contacts;
	int approaching;
	int n = thesis_impacts_touching(w, nc, h, &approaching, 0);
	if (!approaching)
		return;
	double ke = gate_kinetic(w, nb);
	for (int i = 0; i < n; i++)
		thesis_impact_bound(w, &cs[i]);
	w->solver.iteration_limit += gate_lcp(w->impact_inv_mass, cs, n);
	double j[2];
	thesis_impulse_sum(cs, n, j);
	w->v[0] += j[0] * w->impact_inv_mass;
	w->v[1] += j[1] * w->impact_inv_mass;
	for (int i = 0; i < n; i++) {
		thesis_beam *b = &w->beams[cs[i].beam];
		b->omega -= cs[i].impulse * cs[i].c / b->inertia;
		if (cs[i].impulse > 0.0)
			gate_push(w, pushed, cs[i].beam, cs[i].impulse);
	}
	for (int i = 0; i < n; i++)
		*impacts += cs[i].impulse > 0.0 && cs[i].vrel < -w->rest_threshold;
	*e_impact += ke - gate_kinetic(w, nb);
}

/* persistent_contact.c's bsim_thesis_persistent_contact_solve_disk: the
 * contacts' solve, the body's advance, the awake beams' (mask) advance;
 * the dampers' and contacts' energies into e_damper, e_contact.
 * integrator: w->integrator, a constant where the caller gives one. */
THESIS_SPECIALISED void gate_solve(struct bsim_world *w, const double dv[2], double h, int nc,
                                   unsigned awake, unsigned *pushed, double *e_damper,
                                   double *e_contact, const int integrator, const int nb)
{
	double v0[2] = {w->v[0], w->v[1]};
	double vf[2] = {v0[0] + dv[0], v0[1] + dv[1]};
	thesis_contact *cs = w->contacts;
	int contact_of[THESIS_STEPS_BEAMS];
	for (int i = 0; i < nb; i++)
		contact_of[i] = -1;
	for (int k = 0; k < nc; k++) {
		thesis_smooth_row(&cs[k], &w->beams[cs[k].beam], v0, vf, h, integrator);
		contact_of[cs[k].beam] = k;
	}
	double j[2] = {0.0, 0.0};
	if (nc) {
		w->solver.iteration_limit += gate_lcp(w->inv_mass, cs, nc);
		thesis_impulse_sum(cs, nc, j);
		for (int k = 0; k < nc; k++)
			if (cs[k].impulse > 0.0)
				gate_push(w, pushed, cs[k].beam, cs[k].impulse);
	}
	double vm[2];
	thesis_body_advance(w, v0, vf, j, h, vm, integrator);
	double damper = *e_damper, contact = *e_contact;
	for (int i = 0; i < nb; i++)
		if (gate_in(awake, i))
			thesis_smooth_beam(&w->beams[i],
			                   contact_of[i] < 0 ? NULL : &cs[contact_of[i]], vm, h,
			                   integrator, &damper, &contact);
	*e_damper = damper;
	*e_contact = contact;
}

/* The contacts of cs[0..n)'s beams within margin, again, in place
 * (position_project.c's redetect for the disk), beams in contact. */
static inline int gate_redetect(struct bsim_world *w, int n, double margin)
{
	thesis_contact *cs = w->contacts;
	int m = 0;
	for (int k = 0; k < n; k++)
		m += disk_detect(w, cs[k].beam, margin, &cs[m], 1, 1);
	return m;
}

/* position_project.c's position_project for the disk: re-detection at the
 * new positions and projection of penetration deeper than slop; the
 * correction's energy into e_correction. Returns the contacts left. */
static inline int gate_project(struct bsim_world *w, const double force[2], int nc,
                               double *e_correction)
{
	const double margin = w->contact_tol;
	thesis_contact *cs = w->contacts;
	int n = gate_redetect(w, nc, margin);
	for (int pass = 0; w->projection && thesis_project_more(w, cs, n, pass); pass++) {
		for (int k = 0; k < n; k++) {
			cs[k].vrel = cs[k].gap;
			cs[k].bound = 0.0;
			cs[k].inv_i = w->beams[cs[k].beam].inv_inertia;
		}
		w->solver.iteration_limit += gate_lcp(w->inv_mass, cs, n);
		thesis_project_move(w, cs, n, force, e_correction);
		n = gate_redetect(w, n, margin);
	}
	return n;
}

/* contact_list.c's contact_list_beams for the disk: every beam pushed or not
 * certainly farther than R + BSIM_CONTACT_TOL woken (the candidates of a
 * world this small are all its beams, in order). d2: each beam's
 * beam_pivot_distance2 at the step's end, which the next step's detection
 * meets again. */
static inline void gate_report(struct bsim_world *w, gate_masks *mk, unsigned pushed, double *d2,
                               int nb)
{
	mk->near = 0; /* the pushed among them */
	for (int i = 0; i < nb; i++) {
		d2[i] = beam_pivot_distance2(w, &w->beams[i]);
		if (gate_in(pushed, i) || contact_near_at(w, i, d2[i], BSIM_CONTACT_TOL, 0))
			mk->near |= 1u << i;
	}
	mk->awake |= mk->near;
	mk->pushed = pushed;
}

/* One step (step_run for extended 0, the head's differences) under the
 * force, its state into s. hv: h |F| / M of the margins' speed bound; dv:
 * h F / M of the free velocity; d2: each beam's beam_pivot_distance2 where
 * the body is, for the next step at its end (nothing moves in between). */
THESIS_SPECIALISED void gate_step(struct bsim_world *w, const double force[2], double h, double hv,
                                  const double dv[2], gate_masks *mk, double *d2, bsim_state *s,
                                  const int integrator, const int nb)
{
	double e_damper = 0.0, e_impact = 0.0, e_contact = 0.0, e_correction = 0.0;
	int impacts = 0;
	unsigned pushed = 0;
	mk->typed = 0;
	/* step_detect: every beam a candidate, in order */
	double speed = sqrt(w->v[0] * w->v[0] + w->v[1] * w->v[1]) + hv;
	int nc = 0;
	for (int i = 0; i < nb; i++) {
		double margin = thesis_step_margin(w, &w->beams[i], speed, h);
		int got = disk_detect_at(w, i, d2[i], margin, &w->contacts[nc], 0, 1);
		mk->awake |= (unsigned)got << i;
		nc += got;
	}
	if (nc)
		gate_impacts(w, h, nc, &pushed, &e_impact, &impacts, nb);
	gate_solve(w, dv, h, nc, mk->awake, &pushed, &e_damper, &e_contact, integrator, nb);
	int n = nc ? gate_project(w, force, nc, &e_correction) : 0;
	w->n_contacts = n;
	for (int k = 0; k < n; k++)
		if (w->contacts[k].gap <= w->contact_tol)
			mk->typed |= 1u << w->contacts[k].beam;
	/* bsim_thesis_awake_prune */
	for (int i = 0; i < nb; i++) {
		const thesis_beam *b = &w->beams[i];
		if (gate_in(mk->awake, i) && b->theta == 0.0 && b->omega == 0.0 &&
		    !gate_in(mk->typed, i))
			mk->awake &= ~(1u << i);
	}
	gate_report(w, mk, pushed, d2, nb);
	/* get_state */
	thesis_state_body(w, s);
	int na = 0;
	for (int i = 0; i < nb; i++) {
		if (gate_in(mk->awake, i)) {
			s->active[na++] = i;
			thesis_state_beam(w, i, gate_in(pushed, i), w->impulse[i],
			                  gate_in(mk->near, i), s);
		} else {
			s->theta[i] = 0.0;
			s->omega[i] = 0.0;
			s->contact[i] = BSIM_CONTACT_NONE;
			s->touched[i] = 0;
			s->impulse[i] = 0.0;
		}
	}
	s->n_active = na;
	s->energy.damper = e_damper;
	s->energy.impact = e_impact;
	s->energy.contact = e_contact;
	s->energy.correction = e_correction;
	s->energy.sleep = 0.0;
	s->impacts = impacts;
	s->solver = w->solver;
}

/* The run of n steps, nb beams and the integrator constants where the
 * caller can give them. */
THESIS_SPECIALISED void gate_run(struct bsim_world *w, const double force[2], double h, int n,
                                 bsim_state *out, const int integrator, const int nb)
{
	/* The awake list as a mask (is_awake says which beams it holds). */
	gate_masks mk = {0, 0, 0, 0};
	for (int i = 0; i < nb; i++)
		mk.awake |= (unsigned)w->is_awake[i] << i;
	/* No step of the run reads contact_type (the typed mask, each step's,
	 * stands for it): it is cleared here and set from the last step's
	 * contacts at the end, as the steps one after another leave it. */
	for (int k = 0; k < w->n_typed; k++)
		w->contact_type[w->typed[k]] = BSIM_CONTACT_NONE;
	const unsigned awake0 = mk.awake;
	/* step_detect's h |F| / M and the smooth solve's h F / M, as they
	 * compute them */
	const double hv = h * sqrt(force[0] * force[0] + force[1] * force[1]) * w->inv_mass;
	const double dv[2] = {h * force[0] * w->inv_mass, h * force[1] * w->inv_mass};
	double d2[THESIS_STEPS_BEAMS];
	for (int i = 0; i < nb; i++)
		d2[i] = beam_pivot_distance2(w, &w->beams[i]);
	for (int k = 0; k < n; k++)
		gate_step(w, force, h, hv, dv, &mk, d2, &out[k], integrator, nb);
	/* The lists as the general path leaves them: ascending awake beams
	 * (those of the run's start where the mask is theirs), the typed ones
	 * (any order: only cleared), the last step's pushes; the last step's
	 * energy flows and impacts. */
	for (int k = 0; k < w->n_contacts; k++) {
		const thesis_contact *c = &w->contacts[k];
		if (c->gap <= w->contact_tol)
			w->contact_type[c->beam] = c->type;
	}
	if (mk.awake != awake0) {
		w->n_awake = 0;
		for (int i = 0; i < nb; i++) {
			w->is_awake[i] = (unsigned char)gate_in(mk.awake, i);
			if (w->is_awake[i])
				w->awake[w->n_awake++] = i;
		}
	}
	w->n_typed = 0;
	for (int i = 0; i < nb; i++)
		if (gate_in(mk.typed, i))
			w->typed[w->n_typed++] = i;
	/* the last step's pushes, which get_state reports as touched */
	for (int i = 0; i < nb; i++)
		if (gate_in(mk.pushed, i))
			thesis_beam_pushed(w, i, w->impulse[i]);
	w->energy = out[n - 1].energy;
	w->impacts = out[n - 1].impacts;
}

int bsim_thesis_steps(struct bsim_world *w, const double force[2], double h, int n, bsim_state *out)
{
	if (n < 1 || !w->steps_disk || out[0].n_beams != w->n_beams)
		return 0;
	thesis_contact_spent(w);
	if (w->n_touched < w->n_beams) /* else every beam is */
		for (int i = 0; i < w->n_beams; i++)
			thesis_beam_touch(w, i);
	thesis_beams_prepare(w, h);
	if (w->n_beams == 2 && w->integrator == THESIS_MIDPOINT) /* the essay's gate */
		gate_run(w, force, h, n, out, THESIS_MIDPOINT, 2);
	else
		gate_run(w, force, h, n, out, w->integrator, w->n_beams);
	return n;
}
