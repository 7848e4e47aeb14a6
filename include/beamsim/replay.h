/* One trial named the way `beamsim run ARG --group G --trial T` names it,
 * by what ARG is:
 *
 *   a scene file        the scene with the overrides; group and trial pick
 *                       only the random-force schedule (a scene has no
 *                       grid);
 *   an experiment file  trial T of group G as `beamsim sweep EXPERIMENT`
 *                       runs it: the experiment loaded with the overrides
 *                       and grid axes, the group's scene (its set:, the
 *                       overrides, the group's grid values), the
 *                       experiment's seed unless one is given;
 *   an output directory of sweep or compare
 *                       trial T of group G as that run ran it, from its
 *                       record (run.json and inputs/): the stored
 *                       experiment, seed, backend and options; for a
 *                       comparison the side def.side names. The stored
 *                       trials.csv row comes with it, so the replay can
 *                       be checked against it.
 *
 *   bsim_replay_def def = bsim_replay_def_default();
 *   def.path = "configs/thesis/h1_symmetric.yaml";
 *   def.group = 3;
 *   def.trial = 17;
 *   bsim_replay *rp;
 *   if (bsim_replay_open(&def, &rp, &err) == BSIM_OK) {
 *           bsim_trial_result res;
 *           bsim_replay_run(rp, NULL, NULL, NULL, &res, &err);
 *           bsim_replay_free(rp);
 *   }
 *
 * Errors are those of `beamsim run`, one line naming the option (--group,
 * --seed, --backend, ...) the field stands for. */
#ifndef BSIM_REPLAY_H
#define BSIM_REPLAY_H

#include <stddef.h>
#include <stdint.h>

#include "beamsim/base.h"
#include "beamsim/backend.h"
#include "beamsim/error.h"
#include "beamsim/experiment.h"
#include "beamsim/scene.h"
#include "beamsim/sweep_dir.h"
#include "beamsim/trial.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum bsim_replay_kind {
	BSIM_REPLAY_SCENE = 0,
	BSIM_REPLAY_EXPERIMENT = 1,
	BSIM_REPLAY_STORED = 2,
} bsim_replay_kind;

/* What to replay. Every string and array is borrowed: it must outlive the
 * replay opened from it. */
typedef struct bsim_replay_def {
	const char *path;  /* a scene file, an experiment file or an output directory */
	long group, trial; /* from 0, as in trials.csv */
	int has_seed;      /* 1: seed instead of the experiment's (refused for a directory) */
	uint64_t seed;     /* a scene's seed when has_seed is 0 (default 1, as run's) */
	const bsim_override *sets; /* --set overrides, in order (refused for a directory) */
	int n_sets;
	const bsim_grid_axis *grid; /* --grid axes of an experiment (refused otherwise) */
	int n_grid;
	/* A stored run's side: its backend label (a comparison's side, or the
	 * directory named after it); NULL: a sweep's only side. */
	const char *side;
	/* 1: the caller has backend options of its own (--backend-opt), which a
	 * stored run refuses: it runs with its own. */
	int has_backend_opts;
} bsim_replay_def;

/* Trial 0 of group 0, a scene's seed that of bsim_run_info_default, no
 * overrides. */
BSIM_API bsim_replay_def bsim_replay_def_default(void);

typedef struct bsim_replay {
	bsim_replay_kind kind;
	const char *path;       /* def.path */
	bsim_scene scene;       /* the trial's scene */
	const char *scene_path; /* its scene file (an experiment's, or DIR/inputs/scene.yaml) */
	/* Every override the scene was built with, in the order applied (set:,
	 * the overrides or a stored side's protocol, the grid values): with
	 * scene_path they rebuild the scene (bsim_run_info.sets). */
	const bsim_override *ov;
	int n_ov;
	uint64_t seed; /* the experiment seed */
	long group, trial;
	uint64_t mixed_seed; /* bsim_schedule_seed_mix(seed, group, trial) */
	/* A stored run's side: its backend, options (every knob) and label;
	 * backend NULL otherwise (the caller's choice). */
	const bsim_backend *backend;
	bsim_options opts;
	char label[128];
	char command[16]; /* a stored run's: "sweep" or "compare" */
	/* "group 10: effects.propulsion.force=8, ..." (the grid values
	 * applied, and a compare --protocols side's protocol); "" for a
	 * scene. */
	char grid[1024];
	/* A stored run: 1, and the stored trials of the side
	 * (stored.r.trials_out[group * stored.r.trials + trial] is the row,
	 * bsim_replay_stored_row). */
	int has_stored;
	bsim_sweep_dir_result stored;
	bsim_experiment e; /* an experiment file's experiment as loaded */
	/* Internal. */
	bsim_override *ov_owned;
	bsim_override side_ov;
	char protocol[16];
} bsim_replay;

/* Opens the trial def names (above). BSIM_OK with *out to free with
 * bsim_replay_free; BSIM_EINPUT for bad input (a group or trial out of
 * range names the range), BSIM_EFAIL if out of memory; *out NULL then. */
BSIM_API int bsim_replay_open(const bsim_replay_def *def, bsim_replay **out, bsim_error *err);

BSIM_API void bsim_replay_free(bsim_replay *r);

/* 1 if path is a directory (an output directory to replay from). */
BSIM_API int bsim_replay_is_dir(const char *path);

/* Runs the trial with the mixed seed on backend with opts (NULL: none);
 * backend NULL: a stored run's own backend and options, else the default
 * backend (bsim_backend_default) with opts. rec may be NULL
 * (beamsim/trial.h: the trajectory's rows through rec->record, e.g. into a
 * bsim_trajectory with bsim_trajectory_record; the log). Returns what
 * bsim_trial_run returns; an unstable trial is BSIM_OK with its outcome
 * saying so. */
BSIM_API int bsim_replay_run(const bsim_replay *r, const bsim_backend *backend,
                             const bsim_options *opts, const bsim_recorder *rec,
                             bsim_trial_result *res, bsim_error *err);

/* The stored trials.csv row of a stored run's trial; NULL for any other. */
BSIM_API const bsim_trial_result *bsim_replay_stored_row(const bsim_replay *r);

/* The fields of a trials.csv row that say what happened to a trial, its
 * first BSIM_REPLAY_ROW_FIELDS (beamsim/trial_fields.h: group, trial,
 * outcome, type, steps, t_end, x_end, y_end), written as the sweep writes
 * them: two results are the same trial's if these are equal. */
#define BSIM_REPLAY_ROW_FIELDS 8
BSIM_API void bsim_replay_row(char *buf, size_t size, long group, long trial,
                              const bsim_trial_result *x);

#ifdef __cplusplus
}
#endif
#endif
