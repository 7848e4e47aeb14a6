/* Internal: runs of steps (trial_steps.c). Where the forces hold between
 * the random force's draws (trial_force_holds) and nothing is recorded per
 * step, a backend that offers bsim_backend.steps makes the steps up to the
 * force's next change in one call, writing each state into the runner's
 * storage here, and the runner (trial.c) books each as it books the state
 * get_state gives after a step, with the same function: the same bits,
 * without two calls a step and the pipeline asked each step. */
#ifndef BSIM_RUN_TRIAL_STEPS_H
#define BSIM_RUN_TRIAL_STEPS_H

#include "beamsim/backend.h"
#include "beamsim/effects.h"
#include "run/trial_flight.h"

/* The most steps of one run (a run also ends where the held random force
 * takes its next value), and the most beams of a scene whose trials take
 * runs (the runner holds 2 TRIAL_STEPS_MAX states sized for the scene). */
#define TRIAL_STEPS_MAX   64
#define TRIAL_STEPS_BEAMS 64

typedef struct trial_steps {
	int on; /* the trial takes runs (trial_steps_start) */
	int (*steps)(bsim_world *w, const double force[2], double h, int n, bsim_state *out);
	bsim_effect *random;  /* the pipeline's held random force, or NULL */
	long n_max, gate_max; /* steps in all, in one gate */
	/* Two banks of states, for the beams of `cap`: a run writes into the
	 * bank that does not hold the state it starts from. */
	bsim_state bank[2][TRIAL_STEPS_MAX];
	int cap; /* -1: none allocated */
} trial_steps;

void trial_steps_init(trial_steps *t);
void trial_steps_free(trial_steps *t);

/* Sets t for a trial of scene in pipeline fx: runs when plain (nothing
 * recorded, traced or measured per step), the backend offers them, the
 * forces hold and the scene has at most TRIAL_STEPS_BEAMS beams. BSIM_EFAIL
 * out of memory for the states (t->on 0 then). */
int trial_steps_start(trial_steps *t, int plain, const bsim_backend *backend,
                      const bsim_scene *scene, bsim_effects *fx, long n_max, long gate_max);

/* For a trial t->on: a run from s0, the state after lp->n steps, under force (the
 * pipeline's for step lp->n, just asked), dwell steps in the gate: up to
 * the force's next change and the end of the trial. Returns the states
 * made, into *out (0: none, the step loop makes the step; a world the
 * backend makes none for ends the trial's runs). Inline: the runner asks
 * it once a run, about every fifth step of H1. */
static inline int trial_steps_make(trial_steps *t, bsim_world *w, const double force[2],
                                   const trial_loop *lp, long dwell, const bsim_state *s0,
                                   bsim_state **out)
{
	const long room =
	        trial_run_room(lp, dwell, t->n_max, t->gate_max, t->random, TRIAL_STEPS_MAX);
	if (room < 1)
		return 0; /* the step loop's step */
	bsim_state *bank = t->bank[s0 >= t->bank[0] && s0 < t->bank[0] + TRIAL_STEPS_MAX];
	int m = t->steps(w, force, lp->h, (int)room, bank);
	if (m == 0)
		t->on = 0; /* the backend makes none for this world */
	*out = bank;
	return m;
}

#endif
