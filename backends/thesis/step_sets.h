/* A step's sets of beams, in either of two forms, so that the step
 * (thesis_step.h) is written once and compiled for each.
 *
 * The world's lists (run NULL, a constant where the caller gives it): the
 * ascending awake list with its flags, the pushed list with each beam's
 * impulse, each beam's contact_of (thesis.h); what any world keeps, a lattice's thousands of
 * beams included.
 *
 * A run's masks (thesis_run): for a world of at most THESIS_STEPS_BEAMS
 * beams, every one a candidate of every step (broad_phase.c tests them all
 * there), the same sets as bits of one word, and what a run of steps
 * computes once for each force of its schedule (thesis_steps.c): the
 * force's parts of the margins' speed bound and of the free velocity, and
 * each beam's distance
 * from the body, measured where the last step ended, where the next one
 * starts. The lists are written back when the run ends, as steps one after
 * another leave them. Both forms hold the same beams after every step:
 * test_steps checks runs against single steps, state by state, bit for
 * bit. */
#ifndef BSIM_THESIS_STEP_SETS_H
#define BSIM_THESIS_STEP_SETS_H

#include "thesis/thesis.h"

typedef struct thesis_run {
	int nb;          /* beams: every one, in ascending order */
	unsigned awake;  /* the awake list */
	unsigned typed;  /* in contact where the step ended (contact_of), this step's */
	unsigned pushed; /* pushed in this step */
	unsigned near;   /* pushed, or not certainly beyond BSIM_CONTACT_TOL */
	double hv;       /* h |F| / M, the force's part of the margins' speed bound */
	double dv[2];    /* h F / M, the force's part of the free velocity */
	double *d2;      /* per beam: beam_pivot_distance2 where the body is */
} thesis_run;

/* 1 if beam i is in mask m. */
static inline int thesis_run_has(unsigned m, int i)
{
	return (m >> i) & 1u;
}

/* Beam i found in contact by the step's detection: awake. */
THESIS_SPECIALISED void step_wake(struct bsim_world *w, thesis_run *run, int i)
{
	if (run)
		run->awake |= 1u << i;
	else
		bsim_thesis_beam_wake(w, i);
}

/* Beam i pushed by impulse p > 0, N s (thesis_beam_pushed). */
THESIS_SPECIALISED void step_push(struct bsim_world *w, thesis_run *run, int i, double p)
{
	if (!run) {
		thesis_beam_pushed(w, i, p);
		return;
	}
	w->impulse[i] = thesis_run_has(run->pushed, i) ? w->impulse[i] + p : p;
	run->pushed |= 1u << i;
}

/* Beam i in contact k (within contact_tol) at the step's end. */
THESIS_SPECIALISED void step_type(struct bsim_world *w, thesis_run *run, int i, int k)
{
	if (run)
		run->typed |= 1u << i;
	else
		w->contact_of[i] = k;
}

/* How many places the awake set's walk visits (step_awake_at names the
 * beam at each): the list's length, or every beam. */
THESIS_SPECIALISED int step_awake_n(const struct bsim_world *w, const thesis_run *run)
{
	return run ? run->nb : w->n_awake;
}

/* The beam at place a of the awake set's walk, ascending; -1 if that
 * place holds none (a beam not awake in a run). */
THESIS_SPECIALISED int step_awake_at(const struct bsim_world *w, const thesis_run *run, int a)
{
	if (run)
		return thesis_run_has(run->awake, a) ? a : -1;
	return w->awake[a];
}

/* The awake beams exactly at rest and untouched (contact_of -1) put
 * to rest: out of the set (bsim_thesis_awake_prune). */
THESIS_SPECIALISED void step_prune(struct bsim_world *w, thesis_run *run)
{
	if (!run) {
		bsim_thesis_awake_prune(w);
		return;
	}
	for (int i = 0; i < run->nb; i++) {
		const thesis_beam *b = &w->beams[i];
		if (thesis_run_has(run->awake, i) && b->theta == 0.0 && b->omega == 0.0 &&
		    !thesis_run_has(run->typed, i))
			run->awake &= ~(1u << i);
	}
}

/* The kinetic energy of body and beams (thesis_kinetic_energy). A run
 * sums every beam: one not awake has omega = +-0 and adds +0 to a sum
 * that is never -0 (it starts at 1/2 M |v|^2), which leaves it as it is. */
THESIS_SPECIALISED double step_kinetic(const struct bsim_world *w, const thesis_run *run,
                                       const int extended)
{
	if (!run)
		return thesis_kinetic_energy(w, extended);
	double e = 0.5 * w->model->mass * (w->v[0] * w->v[0] + w->v[1] * w->v[1]);
	for (int i = 0; i < run->nb; i++) {
		const thesis_beam *b = &w->beams[i];
		e += 0.5 * w->model->beams[i].inertia * b->omega * b->omega;
	}
	return e;
}

#endif
