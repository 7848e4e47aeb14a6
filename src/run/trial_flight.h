/* Internal: free-flight runs (trial_flight.c). Where the body flies free
 * among beams at rest, a backend that offers bsim_backend.flight makes the
 * steps of each value of the force in one call, and the runner books them
 * (energies, finiteness, ledger, peaks, outcome, termination) in a loop
 * over the body states it returns, with the operations of its step loop
 * (trial.c) in their order: the same bits, without a call, a state copy
 * and the bookkeeping's calls per step.
 *
 * Also the loop's state (trial_loop), which trial.c's step loop and the
 * runs share. */
#ifndef BSIM_RUN_TRIAL_FLIGHT_H
#define BSIM_RUN_TRIAL_FLIGHT_H

#include "beamsim/backend.h"
#include "beamsim/effects.h"
#include "beamsim/trial.h"
#include "run/trial_peaks.h"

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

/* The most steps of one run. A run also ends where the held random force
 * takes its next value (a run has one force). */
#define TRIAL_FLIGHT_MAX 64

typedef struct trial_flight {
	int on; /* the trial takes runs (trial_flight_start) */
	int (*flight)(bsim_world *w, const double force[2], double h, int n, double (*xv)[4]);
	bsim_world *w;
	const bsim_scene *scene;
	bsim_effects *fx;
	bsim_effect *propulsion, *random; /* fx's, or NULL */
	bsim_trial_result *out;
	trial_peaks *peaks;
	long n_max, gate_max; /* steps in all, in one gate */
	double centre;        /* m, the field's centre line */
	/* After a try that made no run (the body near a beam, say), the steps
	 * left before the next try, and the wait after the last failure:
	 * doubled by each, to TRIAL_FLIGHT_MAX, 0 after a run. Which steps are
	 * tried changes no result, only what a stretch near the beams costs. */
	int skip, wait;
	double xv[TRIAL_FLIGHT_MAX][4];
} trial_flight;

/* 1 if the forces of the scene's pipeline fx hold between the random
 * force's draws, so that the force asked before a step is the force of the
 * steps after it up to the hold's end (0 if not): no lattice, a body that
 * does not turn, and every effect one that holds (propulsion along y, the
 * held random force), at most one of each (no drag or ground friction, in
 * the pipeline or simulated by the backend). The two effects into
 * *propulsion and *random (NULL: absent). */
int trial_force_holds(const bsim_scene *scene, bsim_effects *fx, bsim_effect **propulsion,
                      bsim_effect **random);

/* Sets f for a trial in world w of scene (no lattice: the whole scene's
 * world) and whether it takes runs (f->on): when the backend offers them,
 * plain is set (nothing recorded, traced or measured per step: no
 * trajectory, trace or overlap), and the forces hold (trial_force_holds). */
void trial_flight_start(trial_flight *f, int plain, const bsim_backend *backend, bsim_world *w,
                        const bsim_scene *scene, bsim_effects *fx, bsim_trial_result *out,
                        trial_peaks *peaks, long n_max, long gate_max, double centre);

/* A stretch of runs from s0, the state after lp->n steps (the trial not
 * over): -1 if none was made (the next step is not one of free flight, or
 * the force does not hold: the step loop makes it); else their steps are
 * booked (lp, *dwell, f->out, f->peaks), s0 is the state after the last
 * step the trial keeps, and the return is 1 if the trial ends there (a
 * side exit, a non-finite state: s0 then the last finite one), 0 if the
 * step loop goes on (to its test whether the trial is over). */
int trial_flight_run(trial_flight *f, trial_loop *lp, long *dwell, bsim_state *s0);

/* trial_flight_run where it may make a run: the trial takes runs, no beam
 * is active (s0), and no try failed too recently (f->skip); -1 else. */
static inline int trial_flight_try(trial_flight *f, trial_loop *lp, long *dwell, bsim_state *s0)
{
	if (!f->on || s0->n_active)
		return -1;
	if (f->skip > 0) {
		f->skip--;
		return -1;
	}
	int run = trial_flight_run(f, lp, dwell, s0);
	if (run >= 0) {
		f->wait = 0;
		return run;
	}
	f->wait = f->wait ? (2 * f->wait < TRIAL_FLIGHT_MAX ? 2 * f->wait : TRIAL_FLIGHT_MAX) : 1;
	f->skip = f->wait;
	return -1;
}

/* The steps a run from step lp->n may make under the force just asked, the
 * gate's dwell steps so far: to the end of the trial (max_steps n_max, or
 * after the outcome max_steps more; gate_steps gate_max in one gate), to
 * the end of the held random force's hold (er, NULL: none), max at most;
 * 0 if er does not hold at lp->n (the force is not one for a run). */
static inline long trial_run_room(const trial_loop *lp, long dwell, long n_max, long gate_max,
                                  const bsim_effect *er, long max)
{
	long room = lp->done ? n_max - lp->run_on : n_max - lp->n;
	if (!lp->done && gate_max - dwell < room)
		room = gate_max - dwell;
	if (er) {
		if (!(lp->n >= er->held[0] && lp->n < er->held[1] && lp->h == er->held_h))
			return 0;
		if (er->held[1] - lp->n < room)
			room = er->held[1] - lp->n;
	}
	return room < max ? room : max;
}

/* Steps the trial made by other means (a run of steps, trial_steps.h)
 * after a try: they pass the wait for the next try as many steps of the
 * step loop would. */
static inline void trial_flight_passed(trial_flight *f, long steps)
{
	f->skip = f->skip > steps ? f->skip - (int)steps : 0;
}

#endif
