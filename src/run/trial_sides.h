/* Internal: one trial run on several sides (backends, or settings of one)
 * with the same schedule, and the time at which each pair of sides' body
 * trajectories first separate (beamsim compare). */
#ifndef BSIM_RUN_TRIAL_SIDES_H
#define BSIM_RUN_TRIAL_SIDES_H

#include <stdint.h>

#include "beamsim/backend.h"
#include "beamsim/sweep.h"
#include "beamsim/trajectory.h"
#include "beamsim/trial.h"

/* The body centre after every step of one run. */
typedef struct trial_trace {
	double *xy; /* 2 * n, m */
	long n, cap;
	int oom; /* a push failed: the trace is incomplete */
} trial_trace;

/* Per-thread memory: a runner and a trace per side, reused trial after
 * trial. */
typedef struct trial_sides {
	int n; /* sides, 2 .. BSIM_SWEEP_SIDES_MAX */
	bsim_trial_runner *runner[BSIM_SWEEP_SIDES_MAX];
	trial_trace trace[BSIM_SWEEP_SIDES_MAX];
	bsim_trajectory *keep[BSIM_SWEEP_SIDES_MAX]; /* NULL, or where each run's rows are kept */
	int keep_stride;
} trial_sides;

trial_sides *bsim_trial_sides_alloc(int n);
void bsim_trial_sides_free(trial_sides *p);
/* bsim_trial_runner_keep_worlds on every runner: each backend's world kept
 * from one trial to the next of the same scene (the scenes must live,
 * unchanged, while it is on). */
void bsim_trial_sides_keep_worlds(trial_sides *p, int on);

/* Trial `seed` of scene[s] (one scene, or ones that differ only in what the
 * comparison is about) on backend[s] with opts[s], for each side s in
 * order, into *result[s]; log[s] (log may be NULL) receives side s's log.
 * t_separate[k], for each pair k of sides in bsim_sweep_pair's order: the
 * first time, s, at which the two body centres are more than sep_distance
 * apart (m), compared while both runs go on; -1 if they never are. */
int bsim_trial_sides_run(trial_sides *p, const bsim_scene *const *scene,
                         const bsim_backend *const *backend, const bsim_options *const *opts,
                         uint64_t seed, double sep_distance, bsim_trial_result *const *result,
                         bsim_trial_log *const *log, double *t_separate, bsim_error *err);

#endif
