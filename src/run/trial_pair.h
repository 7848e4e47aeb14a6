/* Internal: one trial run on two backends with the same schedule, and the
 * time at which their body trajectories first separate (beamsim compare). */
#ifndef BSIM_RUN_TRIAL_PAIR_H
#define BSIM_RUN_TRIAL_PAIR_H

#include <stdint.h>

#include "beamsim/backend.h"
#include "beamsim/trajectory.h"
#include "beamsim/trial.h"

/* The body centre after every step of one run. */
typedef struct trial_trace {
	double *xy; /* 2 * n, m */
	long n, cap;
	int oom; /* a push failed: the trace is incomplete */
} trial_trace;

/* Per-thread memory: a runner and a trace per backend, reused trial after
 * trial. */
typedef struct trial_pair {
	bsim_trial_runner *runner[2];
	trial_trace trace[2];
	bsim_trajectory *keep[2]; /* NULL, or where each run's rows are kept */
	int keep_stride;
} trial_pair;

trial_pair *trial_pair_alloc(void);
void trial_pair_free(trial_pair *p);
/* bsim_trial_runner_keep_worlds on both runners: each backend's world kept
 * from one trial to the next of the same scene (the scenes must live,
 * unchanged, while it is on). */
void trial_pair_keep_worlds(trial_pair *p, int on);

/* Trial `seed` of scene on backend a then of scene_b (scene, or one that
 * differs only in what the comparison is about) on b; logs[0] and [1] (may
 * be NULL) receive the two runs' logs. t_separate: the first time,
 * s, at which the body centres are more than sep_distance apart (m),
 * compared while both runs go on; -1 if they never are. */
int trial_pair_run(trial_pair *p, const bsim_scene *scene, const bsim_scene *scene_b,
                   const bsim_backend *a, const bsim_options *opts_a, const bsim_backend *b,
                   const bsim_options *opts_b, uint64_t seed, double sep_distance,
                   bsim_trial_result *ra, bsim_trial_result *rb, bsim_trial_log *logs[2],
                   double *t_separate, bsim_error *err);

#endif
