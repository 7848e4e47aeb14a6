/* What accuracy costs in time (beamsim accuracy), by the method of Erez,
 * Tassa & Todorov, "Simulation tools for model-based robotics", ICRA 2015.
 *
 * For each backend a reference trajectory x_ref(t) is run at the finest
 * step h_ref with the most accurate knobs. For a setting (knobs, h) pieces
 * of duration T are restarted from reference states (set_state) at N
 * times t_k on a grid of h_max (a whole number of steps of every h), with
 * the same random-force schedule, and the consistency error is
 *   e = mean_k | p(t_k + T) - p_ref(t_k + T) |,
 * p the stacked positions of the body centre and the beam tips (m); a tip
 * of a beam of length L whose angles differ by dtheta is 2 L |sin(dtheta/2)|
 * apart. Restarting from the reference keeps chaos (divergence of nearby
 * trajectories) out of the error. A batch of trials per setting then gives
 * p_traverse (against the reference setting's, same seeds), the energy
 * ledger residual per simulated second (sum |r| / sum t, J/s) and the cost
 * (wall seconds per simulated second). All times in s, lengths in m. */
#ifndef BSIM_ACCURACY_H
#define BSIM_ACCURACY_H

#include <stdint.h>
#include <stdio.h>

#include "beamsim/base.h"
#include "beamsim/backend.h"
#include "beamsim/figures.h"
#include "beamsim/progress.h"
#include "beamsim/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* States of a reference trajectory at t = k * grid, k = 0 .. n-1. */
typedef struct bsim_accuracy_reference {
	double h;    /* s, its step */
	double grid; /* s, between stored states: a whole number of steps */
	int n;
	bsim_state *states;
} bsim_accuracy_reference;

/* Runs one trial of scene (its dt is the step; grid a multiple of it) with
 * the schedule of seed and keeps the states on the grid. */
BSIM_API int bsim_accuracy_reference_run(bsim_accuracy_reference *ref, const bsim_scene *scene,
                                         const bsim_backend *b, const bsim_options *opts,
                                         uint64_t seed, double grid, bsim_error *err);
BSIM_API void bsim_accuracy_reference_free(bsim_accuracy_reference *ref);

/* The consistency error of (b, opts, scene->dt): n_pieces pieces of
 * duration piece (a multiple of ref->grid) restarted at evenly spaced grid
 * points, and its mean and largest value over the pieces (m). */
BSIM_API int bsim_accuracy_consistency(const bsim_accuracy_reference *ref, const bsim_scene *scene,
                                       const bsim_backend *b, const bsim_options *opts,
                                       uint64_t seed, double piece, int n_pieces, double *mean,
                                       double *max, bsim_error *err);

#define BSIM_ACCURACY_TARGETS_MAX 16

typedef struct bsim_accuracy_config {
	double h_ref;              /* s, finest step and the reference's (0.000125) */
	double h_max;              /* s, coarsest step (0.016); steps are h_max / 2^i */
	double piece;              /* s, duration of restarted pieces (0.064) */
	int n_pieces;              /* restart points (16) */
	int n_trials;              /* trials of the p_traverse batch (40) */
	uint64_t seed;             /* schedules: bsim_schedule_seed_mix(seed, 0, trial) */
	int threads;               /* <= 0: all */
	bsim_progress_fn progress; /* may be NULL: settings done of all */
	void *progress_user;
	/* NULL, or one per backend: options added to every setting of that
	 * backend, the reference's included (they win over the setting's), and
	 * named after the setting in its rows (e.g. continuous=off). */
	const bsim_options *backend_opts;
	/* The error targets of the equal-error comparison, m (0.02, 0.01,
	 * 0.005, 0.002, 0.001). */
	int n_targets;
	double targets[BSIM_ACCURACY_TARGETS_MAX];
} bsim_accuracy_config;

/* The study of docs/accuracy.md: h from 0.016 s halved down to 0.000125 s,
 * 16 pieces of 0.064 s, 40 trials, seed 1, all threads; error targets
 * 0.02, 0.01, 0.005, 0.002 and 0.001 m. */
BSIM_API bsim_accuracy_config bsim_accuracy_config_default(void);
/* A quick study for tests: h down to 0.0005 s, 4 pieces, 8 trials. */
BSIM_API bsim_accuracy_config bsim_accuracy_quick(void);

/* One row: a backend, a knob setting and a time step. */
typedef struct bsim_accuracy_row {
	const char *backend;
	char setting[96]; /* knob values, e.g. "midpoint simultaneous" */
	bsim_options opts;
	int reference;            /* 1: the reference knobs (p_ref comes from h_ref here) */
	double h;                 /* s */
	double err_mean, err_max; /* consistency error, m */
	double residual_rate;     /* energy-ledger residual, J per simulated s */
	double p, p_ref, p_err;   /* p_traverse, the reference's, |p - p_ref| */
	double sim_seconds;       /* simulated by the batch, s */
	double wall_seconds;      /* wall time of the batch and pieces, s */
	double cpu_seconds;       /* CPU time of the batch (its thread's), s */
	double cost;              /* wall s per simulated s */
	double cpu_cost;          /* CPU s of the batch per simulated s */
	double speed;             /* simulated s per wall s (x real time) */
	int failed;               /* trials that ended unstable (bsim_instability) */
} bsim_accuracy_row;

typedef struct bsim_accuracy_result {
	int n;
	bsim_accuracy_row *rows; /* by backend, setting, then h from coarse to fine */
	double wall_seconds;
} bsim_accuracy_result;

/* The knob settings studied for backend b, its accuracy list
 * (beamsim/backend.h): n settings into a malloc'd array (caller frees), the
 * first the reference. BSIM_EINPUT if b lists none. */
BSIM_API int bsim_accuracy_settings(const bsim_backend *b, bsim_accuracy_row **out, int *n,
                                    bsim_error *err);

/* The whole study over the backends. Results other than the timings do not
 * depend on the number of threads. */
BSIM_API int bsim_accuracy_run(const bsim_scene *scene, const bsim_backend *const *backends,
                               int n_backends, const bsim_accuracy_config *cfg,
                               bsim_accuracy_result *out, bsim_error *err);
BSIM_API void bsim_accuracy_result_free(bsim_accuracy_result *r);

/* Equal error: for a target mean consistency error and a backend, the
 * cheapest row of that backend reaching it (err_mean <= target) by CPU time
 * per simulated second, among rows that are not the reference (whose error
 * is 0 by construction) and had no unstable trial; and the ratio of its
 * cost to the first backend's (the first of r's rows) at the same target. */
typedef struct bsim_accuracy_equal {
	double target;       /* m */
	const char *backend; /* the row's backend name */
	int row;             /* in r->rows; -1: no row of the backend reaches the target */
	double cpu_cost;     /* CPU s per simulated s of that row; NAN if none */
	double ratio;        /* cpu_cost / the first backend's; NAN if either has none */
} bsim_accuracy_equal;

/* The equal-error picks of r for n_targets targets (m, > 0): n_targets x
 * (backends in r, in order of first appearance) entries, target by target,
 * into a malloc'd array (caller frees). */
BSIM_API int bsim_accuracy_equal_error(const bsim_accuracy_result *r, const double *targets,
                                       int n_targets, bsim_accuracy_equal **out, int *n,
                                       bsim_error *err);

/* equal_error.csv of the picks: target_m, backend, setting, h_s, err_mean_m,
 * cpu_per_sim_s and ratio_equal_error (this backend's cost over the first
 * backend's); a target a backend does not reach has empty cells. */
BSIM_API int bsim_accuracy_write_equal_csv(const char *path, const bsim_accuracy_result *r,
                                           const bsim_accuracy_equal *eq, int n_eq,
                                           bsim_error *err);

/* accuracy.csv and accuracy.md of a result; the figure is drawn from
 * accuracy.csv (beamsim/figures.h). */
BSIM_API int bsim_accuracy_write_csv(const char *path, const bsim_accuracy_result *r,
                                     bsim_error *err);
BSIM_API int bsim_accuracy_write_md(const char *path, const bsim_accuracy_result *r,
                                    const bsim_accuracy_config *cfg, const char *scene_label,
                                    bsim_error *err);

/* The study written into the output directory out as one set (checked
 * before the study runs; overwrite 1 replaces the result it holds, 0
 * refuses it): accuracy.csv, accuracy.mat, equal_error.csv (at
 * cfg's targets), accuracy.md (naming the scene by scene_label, with the
 * equal-error table) and the figure accuracy (.png, .svg, .gp, .dat). fig gets the figure's result
 * (its notes say what gnuplot could not draw); free it and res on BSIM_OK. */
BSIM_API int bsim_accuracy_store(const char *out, int overwrite, const bsim_scene *scene,
                                 const char *scene_label, const bsim_backend *const *backends,
                                 int n_backends, const bsim_accuracy_config *cfg,
                                 bsim_accuracy_result *res, bsim_figures_result *fig,
                                 bsim_error *err);

#ifdef __cplusplus
}
#endif
#endif
