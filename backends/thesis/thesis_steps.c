/* The thesis backend's runs of steps (a path of its advance, thesis_world.c):
 * for the essay's disk among a few beams, the step of thesis_step.h with
 * the run's masks (step_sets.h), one step after another in one call, each
 * state written as get_state writes it.
 *
 * Which worlds. The essay's disk (w->model->extended 0) under contact_mode
 * physical, simultaneous impacts and no sleeping, among at most
 * THESIS_STEPS_BEAMS beams: the single gate of the essay and its variants
 * (H1, H2). There every beam is a candidate of every step, in ascending
 * order (broad_phase.c tests them all, with or without the grid). The
 * essay's gate (two beams, the midpoint rule) has a copy compiled for it.
 *
 * A run starts from the world's lists and writes them back at its end, as
 * the steps one after another leave them; every beam is marked touched
 * once (thesis_beam_touch), so that a reset restores it: a reset of a beam
 * the run did not move puts back what it holds. test_steps checks runs
 * against single steps and get_state, state by state, bit for bit. */
#include <math.h>
#include <string.h>

#include "thesis/thesis_step.h"

int bsim_thesis_steps_takes(const thesis_model *m)
{
	return !m->extended && m->contact_mode == THESIS_CONTACT_PHYSICAL &&
	       m->impact_order == THESIS_SIMULTANEOUS && !m->sleep &&
	       m->n_beams <= THESIS_STEPS_BEAMS;
}

/* The force's parts of step_detect's margin, h |F| / M, and of the smooth
 * solve's free velocity, h F / M, as they compute them. */
static inline void steps_force(const struct bsim_world *w, thesis_run *run, const double force[2],
                               double h)
{
	run->hv = h * sqrt(force[0] * force[0] + force[1] * force[1]) * w->model->inv_mass;
	run->dv[0] = h * force[0] * w->model->inv_mass;
	run->dv[1] = h * force[1] * w->model->inv_mass;
}

/* The same bits: a force whose terms need not be computed again. */
static inline int steps_same_force(const double a[2], const double b[2])
{
	return memcmp(a, b, 2 * sizeof *a) == 0;
}

/* The run of n steps, nb beams and the integrator constants where the
 * caller can give them. */
THESIS_SPECIALISED void steps_run(struct bsim_world *w, const bsim_wrench *schedule, double h,
                                  int n, bsim_state *out, const int integrator, const int nb)
{
	double d2[THESIS_STEPS_BEAMS];
	thesis_run run = {.nb = nb, .d2 = d2};
	for (int i = 0; i < nb; i++)
		run.awake |= (unsigned)w->is_awake[i] << i;
	/* No step of the run reads contact_of between steps (the typed mask,
	 * each step's, stands for it): it is cleared here and set from the
	 * last step's contacts at the end. */
	step_contacts_clear(w);
	const unsigned awake0 = run.awake;
	steps_force(w, &run, schedule[0].force, h);
	for (int i = 0; i < nb; i++)
		d2[i] = beam_pivot_distance2(w, &w->model->beams[i]);
	for (int k = 0; k < n; k++) {
		const double *force = schedule[k].force;
		if (k && !steps_same_force(force, schedule[k - 1].force))
			steps_force(w, &run, force, h);
		bsim_state *s = &out[k];
		memset(&s->energy, 0, sizeof s->energy);
		s->impacts = 0;
		step_run(w, &run, force, 0.0, h, 0, &s->energy, &s->impacts, 0, integrator);
		step_state(w, &run, s);
	}
	/* The lists as steps one after another leave them: ascending awake
	 * beams (those of the run's start where the mask is theirs), the beams
	 * in contact marked (contact_of), the last step's pushes. */
	for (int k = 0; k < w->n_contacts; k++) {
		const thesis_contact *c = &w->contacts[k];
		if (c->gap <= w->model->contact_tol)
			w->contact_of[c->beam] = k;
	}
	if (run.awake != awake0) {
		w->n_awake = 0;
		for (int i = 0; i < nb; i++) {
			w->is_awake[i] = (unsigned char)thesis_run_has(run.awake, i);
			if (w->is_awake[i])
				w->awake[w->n_awake++] = i;
		}
	}
	w->energy = out[n - 1].energy;
	w->impacts = out[n - 1].impacts;
	/* the last step's pushes, which get_state reports as touched; a beam
	 * pushed in an earlier step only keeps none */
	for (int i = 0; i < nb; i++) {
		const double p = w->impulse[i];
		w->impulse[i] = 0.0;
		if (thesis_run_has(run.pushed, i))
			thesis_beam_pushed(w, i, p);
	}
}

int bsim_thesis_steps(struct bsim_world *w, const bsim_wrench *schedule, double h, int n,
                      bsim_state *out)
{
	if (n < 1 || !w->model->steps_disk || out[0].n_beams != w->model->n_beams)
		return 0;
	thesis_contact_spent(w);
	if (w->n_touched < w->model->n_beams) /* else every beam is */
		for (int i = 0; i < w->model->n_beams; i++)
			thesis_beam_touch(w, i);
	thesis_beams_prepare(w, h);
	if (w->model->n_beams == 2 &&
	    w->model->integrator == THESIS_MIDPOINT) /* the essay's gate */
		steps_run(w, schedule, h, n, out, THESIS_MIDPOINT, 2);
	else
		steps_run(w, schedule, h, n, out, w->model->integrator, w->model->n_beams);
	return n;
}
