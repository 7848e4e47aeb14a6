/* Internal: runs of steps (trial_steps.c). Where the forces hold between
 * the random force's draws (bsim_trial_force_holds) and nothing is recorded per
 * step, the runner hands the backend the schedule of the forces of up to
 * TRIAL_STEPS_MAX steps in one call (bsim_backend.advance), each state
 * written into the runner's storage here, and books them in one pass
 * (trial.c's run_book, the step loop's operations for such a trial): the
 * same bits, without a call and the pipeline asked each step.
 *
 * Also the loop's state (trial_loop), which trial.c's step loop and the
 * runs share. */
#ifndef BSIM_RUN_TRIAL_STEPS_H
#define BSIM_RUN_TRIAL_STEPS_H

#include "beamsim/backend.h"
#include "beamsim/effects.h"

/* What the step loop carries from step to step. Apart from the context,
 * whose address the backend's calls see, so that the loop can hold it in
 * registers. */
typedef struct trial_loop {
	double h;    /* s, the time step */
	long n;      /* steps done */
	double e0;   /* J, the energy after step n */
	int done;    /* the outcome is known; running on to classify_y */
	long run_on; /* steps since */
} trial_loop;

/* The most steps of one run, and the most beams of a scene whose trials
 * take runs (the runner holds 2 TRIAL_STEPS_MAX states sized for the
 * scene). */
#define TRIAL_STEPS_MAX   64
#define TRIAL_STEPS_BEAMS 64

typedef struct trial_steps {
	int on;                  /* the trial takes runs (bsim_trial_steps_start) */
	bsim_effect *propulsion; /* the pipeline's propulsion, or NULL */
	bsim_effect *random;     /* the pipeline's held random force, or NULL */
	long hold;               /* steps a value of the random force holds */
	long n_max, gate_max;    /* steps in all, in one gate */
	long tried;              /* steps the trial made or tried: booked, or failed */
	/* A run's schedule of forces, and the random force's value in each
	 * of its steps (N), which the ledger books apart from the propulsion;
	 * base_x: the force along x but the random force's (N). */
	bsim_wrench schedule[TRIAL_STEPS_MAX];
	double base_x;
	double random_at[TRIAL_STEPS_MAX];
	/* Two banks of states, for the beams of `cap`: a run writes into the
	 * bank that does not hold the state it starts from. */
	bsim_state bank[2][TRIAL_STEPS_MAX];
	int cap; /* -1: none allocated */
} trial_steps;

void bsim_trial_steps_init(trial_steps *t);
void bsim_trial_steps_free(trial_steps *t);

/* 1 if the forces of the scene's pipeline fx hold between the random
 * force's draws and read nothing of the state, so that the forces of the
 * steps ahead are known before them (0 if not): no lattice, a body that
 * does not turn, and every effect one that holds (a constant force, the
 * propulsion, then the held random force, along x), at most one of each (no drag or
 * ground friction, in the pipeline or simulated by the backend). The two
 * effects into *propulsion and *random (NULL: absent). */
int bsim_trial_force_holds(const bsim_scene *scene, bsim_effects *fx, bsim_effect **propulsion,
                           bsim_effect **random);

/* Sets t for a trial of scene in pipeline fx: runs when plain (nothing
 * recorded, traced or measured per step), the forces hold, the random
 * force's values hold over a whole number of steps and the scene has at
 * most TRIAL_STEPS_BEAMS beams. BSIM_EFAIL out of memory for the states
 * (t->on 0 then). */
int bsim_trial_steps_start(trial_steps *t, int plain, const bsim_scene *scene, bsim_effects *fx,
                           long n_max, long gate_max);

/* Fills t->schedule[0..m) and t->random_at[0..m) with the forces of steps
 * n .. n + m - 1 at the scene's step, as bsim_effects_force_at gives them
 * step by step: the same operations in the same order, each random value
 * drawn in its turn (values drawn ahead of the steps that use them:
 * bsim_trial_steps_used). */
void bsim_trial_steps_schedule(trial_steps *t, long n, int m);

/* The random force's values the trial's steps used, as the step loop
 * would have drawn them: those of the holds up to the last step made or
 * tried (t->tried). */
void bsim_trial_steps_used(const trial_steps *t);

/* The steps a run from step lp->n may make, the gate's dwell steps so
 * far: to the end of the trial (max_steps n_max, or after the outcome
 * max_steps more; gate_steps gate_max in one gate), max at most. */
static inline long trial_run_room(const trial_loop *lp, long dwell, long n_max, long gate_max,
                                  long max)
{
	long room = lp->done ? n_max - lp->run_on : n_max - lp->n;
	if (!lp->done && gate_max - dwell < room)
		room = gate_max - dwell;
	return room < max ? room : max;
}

/* For a trial t->on: the steps a run from s0, the state after lp->n steps,
 * may make (trial_run_room) and the bank its states go into, the one that
 * does not hold s0. Inline: the runner asks it once a run. */
static inline long trial_steps_room(trial_steps *t, const trial_loop *lp, long dwell,
                                    const bsim_state *s0, bsim_state **bank)
{
	*bank = t->bank[s0 >= t->bank[0] && s0 < t->bank[0] + TRIAL_STEPS_MAX];
	return trial_run_room(lp, dwell, t->n_max, t->gate_max, TRIAL_STEPS_MAX);
}

#endif
