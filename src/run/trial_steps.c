/* Runs of steps (trial_steps.h): the steps of a schedule of forces made by
 * one call of the backend's advance.
 *
 * Why the forces are the same. The step loop asks the pipeline for the
 * force before each step; where it holds (bsim_trial_force_holds: the
 * propulsion gives its constant, the held random force value j over the
 * steps [j k, (j + 1) k), and neither reads the state), the force of each
 * step ahead is known before the steps are made: the schedule is the step
 * loop's forces, each computed by the same operations, the random values
 * drawn in the same order. A run ends at the end of the trial (max_steps,
 * gate_steps, or max_steps after the outcome), which the booking finds
 * anyway, or after TRIAL_STEPS_MAX steps: a run the trial does not use to
 * its end leaves the world ahead of the trial, which then ends (a kept
 * world is reset), and the values drawn for the steps it did not use are
 * not counted as the trial's draws (bsim_trial_steps_used). */
#include "run/trial_steps.h"

#include "beamsim/schedule.h"

#include <string.h>

void bsim_trial_steps_init(trial_steps *t)
{
	t->on = 0;
	t->cap = -1;
}

void bsim_trial_steps_schedule(trial_steps *t, long n, int m)
{
	/* Every step's wrench is the trial's base (bsim_trial_steps_start) but
	 * for x, where the random force acts: its value added to the base's,
	 * bsim_effects_force_at's sum in its order. */
	const bsim_effect *er = t->random;
	if (!er)
		return;
	/* the values of the holds the steps fall in, drawn in order: step k
	 * in hold q until step `end`, where the next begins */
	const long hold = t->hold, j = n / hold;
	double value[TRIAL_STEPS_MAX];
	bsim_schedule_values(er->schedule, j, (int)((n + m - 1) / hold - j + 1), value);
	bsim_wrench *w = t->schedule;
	const double base_x = t->base_x;
	long end = 0;
	double x = 0.0, v = 0.0;
	for (int q = 0, k = 0; k < m; k++) {
		if (k == end) {
			v = value[q++];
			x = base_x + v;
			end = (j + q) * hold - n;
		}
		w[k].force[0] = x;
		t->random_at[k] = v;
	}
}

void bsim_trial_steps_used(const trial_steps *t)
{
	if (t->on && t->random)
		bsim_schedule_used(t->random->schedule,
		                   t->tried > 0 ? (t->tried - 1) / t->hold + 1 : 0);
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
		else if (e->kind == BSIM_EFFECT_HELD && e == fx->random && e->axis == 0 && !*random)
			*random = e;
		else
			holds = 0;
	}
	return holds;
}

int bsim_trial_steps_start(trial_steps *t, int plain, const bsim_scene *scene, bsim_effects *fx,
                           long n_max, long gate_max)
{
	t->propulsion = t->random = NULL;
	t->on = plain && scene->n_beams <= TRIAL_STEPS_BEAMS &&
	        bsim_trial_force_holds(scene, fx, &t->propulsion, &t->random);
	t->hold = t->on && t->random ? bsim_schedule_hold_steps(t->random->schedule, scene->dt) : 0;
	if (t->on && t->random && t->hold == 0) /* no whole number of steps a value */
		t->on = 0;
	if (t->on) {
		/* the forces but the random force's: the propulsion added to
		 * zeros, as bsim_effects_force_at adds it */
		double f[BSIM_WRENCH] = {0.0, 0.0, 0.0};
		if (t->propulsion)
			f[t->propulsion->axis] += t->propulsion->param;
		for (int k = 0; k < TRIAL_STEPS_MAX; k++)
			t->schedule[k] = (bsim_wrench){{f[0], f[1]}, f[2]};
		t->base_x = f[0];
	}
	t->tried = 0;
	t->n_max = n_max;
	t->gate_max = gate_max;
	if (t->on && steps_reserve(t, scene->n_beams)) {
		t->on = 0;
		return BSIM_EFAIL;
	}
	return BSIM_OK;
}
