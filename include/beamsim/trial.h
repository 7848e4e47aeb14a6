/* The trial runner (MODEL.md section 6): owns time, the effect pipeline,
 * termination, outcomes, the energy ledger and optional recording. */
#ifndef BEAMSIM_TRIAL_H
#define BEAMSIM_TRIAL_H

#include <stdint.h>
#include <stdio.h>

#include "beamsim/backend.h"
#include "beamsim/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
	BSIM_TRAVERSED = 0, /* y >= success_y with |x| < side_x */
	BSIM_SIDE_EXIT = 1, /* |x| >= side_x before traversing */
	BSIM_STUCK = 2,     /* max_steps reached */
} bsim_outcome;

typedef enum {
	BSIM_TYPE_NONE = 0,
	BSIM_TYPE_LEFT = 1,  /* v_x > 0 at classify_y: crossed the left barrier */
	BSIM_TYPE_RIGHT = 2, /* v_x < 0 at classify_y */
} bsim_type;

/* The energy ledger of a trial, J (MODEL.md section 10, oracle 3).
 * E = body KE + sum(1/2 I omega^2 + 1/2 k theta^2). Each step:
 *   E' - E = w_prop + w_rand - damper - impact - contact - correction + r
 * with r the step's residual; |r| summed and at its largest are kept. */
typedef struct bsim_ledger {
	double e_start, e_end;
	double w_prop, w_rand; /* work of the propulsive and random forces */
	double damper, impact, contact, correction;
	double residual;     /* sum of r */
	double residual_max; /* max |r| over steps */
	double residual_abs; /* sum of |r| */
} bsim_ledger;

typedef struct bsim_trial_result {
	bsim_outcome outcome;
	bsim_type type;
	int landscape_beam;          /* traversed: the beam whose barrier it crossed, 0-based, -1
	                              * none (bsim_landscape_label at the last step before
	                              * success_y at which it touched a beam) */
	int steps;                   /* steps to the outcome event */
	double t_end;                /* s, time of the outcome event */
	double x_end, y_end, vx_end; /* at the end of the run (classify_y for traversed) */
	double max_theta[2];         /* peak theta of beams 0 and 1, rad */
	int in_contact_end;          /* stuck: 1 if any beam touched the body at the end */
	int steps_run;               /* all steps integrated, incl. those to classify_y */
	unsigned long draws;         /* standard-normal draws made */
	bsim_ledger ledger;
} bsim_trial_result;

/* Called with the state at t = 0 and after every step (step = 1, 2, ...),
 * whatever the stride; for in-memory use of a trajectory (compare). */
typedef void (*bsim_trace_fn)(void *user, long step, const bsim_state *s);

/* Trajectory recording: one CSV row per step (DESIGN.md "Outputs"). */
typedef struct bsim_recorder {
	FILE *csv;           /* NULL: no recording */
	int stride;          /* record every stride-th step (>= 1) */
	bsim_trace_fn trace; /* NULL: none */
	void *trace_user;
} bsim_recorder;

/* Writes the trajectory CSV header for a scene of n_beams beams. */
void bsim_recorder_header(FILE *f, int n_beams);

typedef struct bsim_runner bsim_runner;

/* A runner holds the reusable per-thread memory (state buffers, schedule). */
bsim_runner *bsim_runner_alloc(void);
void bsim_runner_free(bsim_runner *r);

/* Runs one trial. seed: the mixed seed (bsim_seed_mix). rec may be NULL.
 * Returns BSIM_OK, BSIM_EINPUT (backend options), BSIM_EFAIL (non-finite
 * state: the message says at which step). */
int bsim_trial_run(bsim_runner *r, const bsim_scene *scene, const bsim_backend *backend,
                   const bsim_options *opts, uint64_t seed, const bsim_recorder *rec,
                   bsim_trial_result *out, bsim_error *err);

const char *bsim_outcome_name(bsim_outcome o);
const char *bsim_type_name(bsim_type t);

#ifdef __cplusplus
}
#endif
#endif
