/* Runs of steps (trial_steps.h): the steps over which the force holds,
 * made by one call of the backend's advance.
 *
 * Why the force is the same. The step loop asks the pipeline for the
 * force before each step; where it holds (bsim_trial_force_holds: propulsion
 * gives its constant, the held random force its held value until
 * the step its hold ends, and neither reads the state), the force asked
 * before a run is the force of each step of it up to the hold's end, and
 * asking it again after the run gives what the step loop would get there
 * (the held value, or the next draw, drawn once, in order). So a run ends
 * at the hold's end at the latest, and at the end of the trial (max_steps,
 * gate_steps, or max_steps after the outcome), which the booking finds
 * anyway: a run the trial does not use to its end leaves the world ahead
 * of the trial, which then ends (a kept world is reset). */
#include "run/trial_steps.h"

#include <string.h>

void bsim_trial_steps_init(trial_steps *t)
{
	t->on = 0;
	t->cap = -1;
}

void bsim_trial_steps_free(trial_steps *t)
{
	if (t->cap < 0)
		return;
	for (int b = 0; b < 2; b++)
		for (int k = 0; k < TRIAL_STEPS_MAX; k++)
			bsim_state_free(&t->bank[b][k]);
	t->cap = -1;
}

/* The banks sized for n_beams beams. */
static int steps_reserve(trial_steps *t, int n_beams)
{
	if (t->cap == n_beams)
		return BSIM_OK;
	bsim_trial_steps_free(t);
	/* empty states first: bsim_state_free of one is harmless */
	memset(t->bank, 0, sizeof t->bank);
	t->cap = n_beams;
	for (int b = 0; b < 2; b++)
		for (int k = 0; k < TRIAL_STEPS_MAX; k++)
			if (bsim_state_init(&t->bank[b][k], n_beams)) {
				bsim_trial_steps_free(t);
				return BSIM_EFAIL;
			}
	return BSIM_OK;
}

int bsim_trial_force_holds(const bsim_scene *scene, bsim_effects *fx, bsim_effect **propulsion,
                           bsim_effect **random)
{
	int holds = !scene->has_lattice && !scene->body.rotates && !scene->effects.has_drag &&
	            !scene->effects.has_ground_friction && fx->n_work == fx->n;
	/* the pipeline: the propulsion, then the held random force, either
	 * or both */
	*propulsion = *random = NULL;
	for (int i = 0; i < fx->n && holds; i++) {
		bsim_effect *e = &fx->e[i];
		if (e->kind == BSIM_EFFECT_CONSTANT && !*propulsion && !*random)
			*propulsion = e;
		else if (e->kind == BSIM_EFFECT_HELD && e == fx->random && !*random)
			*random = e;
		else
			holds = 0;
	}
	return holds;
}

int bsim_trial_steps_start(trial_steps *t, int plain, const bsim_scene *scene, bsim_effects *fx,
                           long n_max, long gate_max)
{
	t->on = plain && scene->n_beams <= TRIAL_STEPS_BEAMS &&
	        bsim_trial_force_holds(scene, fx, &t->propulsion, &t->random);
	t->n_max = n_max;
	t->gate_max = gate_max;
	if (t->on && steps_reserve(t, scene->n_beams)) {
		t->on = 0;
		return BSIM_EFAIL;
	}
	return BSIM_OK;
}
