/* The record of one trial (beamsim run): its JSON object, and the output
 * directory of `beamsim run --out DIR`:
 *
 *   trajectory.csv     the trajectory, the columns of `run --trajectory`
 *   ledger.csv         the energy ledger at the same times
 *                      (bsim_trial_ledger_header)
 *   trajectory.mat, ledger.mat   their MATLAB twins
 *   run.json           what ran and what came of it: the object of
 *                      `run --json` and "command": "run", "stride", "set"
 *                      (the --set overrides) and "scene_copy"
 *   inputs/scene.yaml  the scene file as it was, so that with "set" the
 *                      scene can be rebuilt (beamsim plot draws the
 *                      landscape from it)
 *
 * The directory is written as one set (DIR/manifest.json last) once the
 * trial has run: a failed trial leaves none of its files. */
#ifndef BSIM_RUN_OUTPUT_H
#define BSIM_RUN_OUTPUT_H

#include <stdint.h>
#include <stdio.h>

#include "beamsim/base.h"
#include "beamsim/backend.h"
#include "beamsim/scene.h"
#include "beamsim/trial.h"

#ifdef __cplusplus
extern "C" {
#endif

/* What was run. */
typedef struct bsim_run_info {
	const char *scene_path;
	const bsim_scene *scene;
	const bsim_override *sets; /* the --set overrides, in order */
	int n_sets;
	const bsim_backend *backend;
	const bsim_options *opts;
	uint64_t seed;             /* the experiment seed */
	long group, trial;         /* of the schedule */
	uint64_t mixed_seed;       /* bsim_schedule_seed_mix(seed, group, trial) */
	int stride;                /* recorded every stride-th step */
	const bsim_trial_log *log; /* the trial's gate path and peaks, or NULL */
} bsim_run_info;

/* What `beamsim run` runs when told nothing: the default backend
 * (bsim_backend_default) without options, trial 0 of group 0 of experiment
 * seed 1, every step recorded. scene_path, scene and mixed_seed are the
 * caller's to set (bsim_schedule_seed_mix(seed, group, trial)). */
BSIM_API bsim_run_info bsim_run_info_default(void);

/* The JSON object of a trial (one line, with a newline): scene, name,
 * backend, backend_options, seed, group, trial, mixed_seed, outcome, type,
 * landscape_left, landscape_beam (the barrier crossed, 1-based, or null),
 * in_contact_end, steps, steps_run, draws, t_end, x_end, y_end, vx_end,
 * heading_end, angular_velocity_end, turn_end, turn_max, max_theta, overlap_max, final_gate,
 * location, reset_overlaps, path and peak_theta (with a log), ledger, instability (null or why the
 * trial was unstable). record adds command, beamsim_version, stride, set and scene_copy, for
 * run.json. */
BSIM_API void bsim_run_output_json(FILE *f, const bsim_run_info *info, const bsim_trial_result *r,
                                   int record);

/* Runs the trial info describes (bsim_trial_run with the mixed seed,
 * recording every info->stride-th step, info->log filled if not NULL) and
 * writes what is asked for:
 *   trajectory  FILE.csv with the trajectory (bsim_trial_trajectory_header)
 *               and, when FILE is a regular file, its twin FILE.mat; "-" is
 *               standard output; NULL: none;
 *   out         the directory above, checked before the trial runs and
 *               written as one set (docs/files.md); NULL: none. With
 *               overwrite 1 it replaces the result out holds; with 0 such
 *               an out is refused.
 * The files appear only if the trial ran (an unstable trial did run: its
 * outcome says so). res gets the result. BSIM_EINPUT if out cannot be
 * used or an option is bad; BSIM_EFAIL if the trial or a file fails. */
BSIM_API int bsim_run_output_trial(const bsim_run_info *info, const char *trajectory,
                                   const char *out, int overwrite, bsim_trial_result *res,
                                   bsim_error *err);

#ifdef __cplusplus
}
#endif
#endif
