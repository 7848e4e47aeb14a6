/* One step of the thesis world and the state it leaves, written once and
 * compiled for each world it serves (thesis_world.c's head gives the
 * step's order):
 *   - any body (extended 1) or the essay's disk (extended 0, w->model->extended
 *     0): a constant, so that the disk's copy is compiled without the
 *     extended path's tests (docs/backends.md, "Cost to the essay's disk");
 *   - the world's lists (run NULL) or a run's masks (step_sets.h): the
 *     single steps of thesis_world.c, and the runs of steps of
 *     thesis_steps.c, which a few beams' disk makes one after another in
 *     one call.
 * What a run leaves out, a constant test each: the free-flight test (a
 * step a single step would take as free flight, no beam awake and every
 * one out of reach, is the general step here, which detects nothing,
 * solves nothing and moves the body by the same operations, whose list
 * finds no beam within BSIM_CONTACT_TOL: the same state), the broad phase
 * (every beam a candidate, in order), the step size's constants (once a
 * run) and the force's terms (once for each force of the schedule), the
 * beams in contact (a mask for contact_of) and the essay's
 * contact mode, nearest-first impacts and sleeping (worlds a run does not
 * take: bsim_thesis_steps_takes). */
#ifndef BSIM_THESIS_THESIS_STEP_H
#define BSIM_THESIS_THESIS_STEP_H

#include <math.h>
#include <string.h>

#include "thesis/contact_list.h"
#include "thesis/impact_resolve.h"
#include "thesis/persistent_contact.h"
#include "thesis/position_project.h"
#include "thesis/step_sets.h"

/* contact_mode=essay: the beams held after this step's solve (touching at
 * its start and pressed by it); 1 if any is. */
static inline int essay_hold(struct bsim_world *w)
{
	int any = 0;
	for (int i = 0; i < w->model->n_beams; i++)
		w->held[i] = 0;
	for (int k = 0; k < w->n_contacts; k++) {
		const thesis_contact *c = &w->contacts[k];
		if (c->impulse > 0.0 && c->gap <= w->model->contact_tol)
			any = w->held[c->beam] = 1;
	}
	return any;
}

/* The last step's contacts are spent: their beams' contact_of cleared
 * (thesis.h), as a step starts. */
static inline void step_contacts_clear(struct bsim_world *w)
{
	for (int k = 0; k < w->n_contacts; k++)
		w->contact_of[w->contacts[k].beam] = -1;
}

/* The contacts the step can reach into w->contacts; returns how many, and
 * the speed bound of the margins in *speed. */
THESIS_SPECIALISED int step_detect(struct bsim_world *w, thesis_run *run, const double force[2],
                                   double torque, double h, double *speed, const int extended)
{
	/* A bound for the margin only: speeds and forces are far from overflow,
	 * so sqrt serves where hypot's scaling would cost a tenth of a step. */
	double v = sqrt(w->v[0] * w->v[0] + w->v[1] * w->v[1]) +
	           (run ? run->hv
	                : h * sqrt(force[0] * force[0] + force[1] * force[1]) * w->model->inv_mass);
	/* A shape that turns: its outline moves up to reach |w| faster than its
	 * centre (the disk's does not move when it turns). */
	if (extended && w->model->shaped && w->model->rotates)
		v += w->model->radius *
		     (fabs(w->angular_velocity) + h * fabs(torque) * w->model->inv_body_inertia);
	int holding = !run && w->model->contact_mode == THESIS_CONTACT_ESSAY && w->any_held;
	int m = run ? run->nb : bsim_thesis_broad_phase(w, v, h);
	int n = 0;
	for (int k = 0; k < m; k++) {
		int i = run ? k : w->candidates[k];
		if (holding && !w->held[i])
			continue; /* essay: the constraint loop tests only held beams */
		double margin = thesis_step_margin(w, &w->model->beams[i], &w->beams[i], v, h);
		int got;
		if (extended)
			got = bsim_thesis_contact_detect(w, i, margin, &w->contacts[n]);
		else if (run)
			got = disk_detect_at(w, i, run->d2[i], margin, &w->contacts[n], 0, 1);
		else
			got = bsim_thesis_contact_detect_disk(w, i, margin, &w->contacts[n]);
		if (got)
			step_wake(w, run, i);
		n += got;
	}
	*speed = v;
	return n;
}

/* A step in free flight among beams at rest (none awake or in contact, none in
 * reach: bsim_thesis_broad_phase_clear, which the caller asked) for the step
 * size the beams are prepared for: what the step does then, without its
 * general path. No contact: no impact, no projection, nothing held; the
 * contact solve's body update with a zero impulse sum (thesis_body_advance,
 * as persistent_contact.h's with none); no beam to move, sleep or prune;
 * nothing to list. */
THESIS_SPECIALISED void flight_step(struct bsim_world *w, const double force[2], double torque,
                                    double h, const int extended)
{
	w->n_contacts = 0;
	double v0[2] = {w->v[0], w->v[1]};
	double vf[2] = {v0[0] + h * force[0] * w->model->inv_mass,
	                v0[1] + h * force[1] * w->model->inv_mass};
	const double j[2] = {0.0, 0.0};
	double vm[2];
	thesis_body_advance(w, v0, vf, j, h, vm, w->model->integrator);
	if (extended)
		thesis_body_turn(w, w->angular_velocity, torque, 0.0, h);
}

/* One step: its energy flows added to *e and its impacts to *impacts
 * (the world's, or in a run the state's, zeroed by the caller). in_flight:
 * the caller found the step one of free flight (never in a run).
 * integrator: w->model->integrator, a constant where the caller gives one. */
THESIS_SPECIALISED int step_run(struct bsim_world *w, thesis_run *run, const double force[2],
                                double torque, double h, int in_flight, bsim_step_energy *e,
                                int *impacts, const int extended, const int integrator)
{
	/* The essay's disk's free flight was thesis_step's (w->model->flight_disk). */
	if (extended && in_flight && h == w->h_prepared &&
	    w->model->contact_mode != THESIS_CONTACT_ESSAY) {
		flight_step(w, force, torque, h, extended);
		return BSIM_OK;
	}
	if (run) {
		/* contact_of is the run's typed mask between steps, written when
		 * the run ends */
		run->typed = 0;
		run->pushed = 0;
	} else {
		step_contacts_clear(w);
		thesis_beams_prepare(w, h);
	}
	double speed = 0.0;
	int n = in_flight ? 0 : step_detect(w, run, force, torque, h, &speed, extended);
	w->n_contacts = n;
	if (n)
		impact_resolve(w, run, h, &e->impact, impacts, extended);
	if (extended) {
		persistent_solve_extended(w, force, torque, h);
	} else if (run) {
		persistent_solve_disk(w, run, run->dv, h, &e->damper, &e->contact, integrator);
	} else {
		const double dv[2] = {h * force[0] * w->model->inv_mass,
		                      h * force[1] * w->model->inv_mass};
		persistent_solve_disk(w, run, dv, h, &e->damper, &e->contact, integrator);
	}
	if (!run && w->model->contact_mode == THESIS_CONTACT_ESSAY)
		w->any_held = essay_hold(w);
	if (n)
		position_project(w, run, force, torque, &e->correction, extended);
	/* in flight nothing is in reach: nothing to sleep, prune or list */
	if (!in_flight) {
		if (!run && w->model->sleep)
			bsim_thesis_beams_sleep(w, speed, h);
		step_prune(w, run);
		contact_list_beams(w, run, extended);
	}
	return BSIM_OK;
}

/* The state after a step (bsim_backend.get_state): the listed beams are
 * the awake ones, each with its push and direction (where the flag may
 * mark it: pushed, or not certainly beyond BSIM_CONTACT_TOL); a run writes
 * every beam, those not listed as at rest. */
THESIS_SPECIALISED void step_state(const struct bsim_world *w, const thesis_run *run, bsim_state *s)
{
	thesis_state_body(w, s);
	/* The beams' directions are kept for the next step's detection
	 * (b->u): a cache, not the world's state, which stays as it is. */
	struct bsim_world *cache = (struct bsim_world *)w;
	if (run) {
		int na = 0;
		for (int i = 0; i < run->nb; i++) {
			if (thesis_run_has(run->awake, i)) {
				s->active[na++] = i;
				thesis_state_beam(cache, i, thesis_run_has(run->pushed, i),
				                  w->impulse[i], thesis_run_has(run->near, i), s);
			} else {
				s->theta[i] = 0.0;
				s->omega[i] = 0.0;
				s->contact[i] = BSIM_CONTACT_NONE;
				s->touched[i] = 0;
				s->impulse[i] = 0.0;
			}
		}
		s->n_active = na;
	} else {
		/* Both lists empty (free flight): the same, nothing to set. */
		if (w->n_awake || s->n_active)
			bsim_state_set_active(s, w->awake, w->n_awake);
		for (int k = 0; k < s->n_active; k++) {
			int i = s->active[k];
			thesis_state_beam(cache, i, w->impulse[i] > 0.0, w->impulse[i],
			                  bsim_thesis_contact_near(w, i, BSIM_CONTACT_TOL), s);
		}
	}
	if (!run) { /* a run's step wrote them into the state */
		s->energy = w->energy;
		s->impacts = w->impacts;
	}
	s->solver = w->solver;
}

#endif
