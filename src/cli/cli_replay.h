/* The trial that `beamsim run` and `beamsim video` run, from what their one
 * argument names:
 *
 *   a scene file        the scene with the --set overrides; --group and
 *                       --trial pick only the random-force schedule (a
 *                       scene has no grid, which a note on stderr says);
 *   an experiment file  trial T of group G as `beamsim sweep EXPERIMENT`
 *                       runs it: the experiment loaded as sweep loads it
 *                       (cli_experiment_load, with the --set overrides),
 *                       the group's scene (bsim_experiment_group_scene:
 *                       set:, --set, the group's grid values), the
 *                       experiment's seed unless --seed is given;
 *   an output directory of sweep or compare
 *                       trial T of group G as that run ran it, from its
 *                       record (run.json and inputs/, read as beamsim
 *                       regress reads them): the stored experiment, seed,
 *                       backend and options; for a comparison the side
 *                       --backend LABEL names (its lattice protocol too).
 *                       The stored trials.csv row comes with it, so the
 *                       replay can be checked against it. */
#ifndef BSIM_CLI_CLI_REPLAY_H
#define BSIM_CLI_CLI_REPLAY_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "beamsim/backend.h"
#include "beamsim/experiment.h"
#include "beamsim/scene.h"
#include "beamsim/sweep_dir.h"
#include "cli/cli_options.h"

typedef enum cli_replay_kind {
	CLI_REPLAY_SCENE,
	CLI_REPLAY_EXPERIMENT,
	CLI_REPLAY_STORED
} cli_replay_kind;

typedef struct cli_replay {
	cli_replay_kind kind;
	const char *path;       /* the argument as given */
	bsim_scene scene;       /* the trial's scene */
	const char *scene_path; /* its scene file (an experiment's, or DIR/inputs/scene.yaml) */
	/* Every override the scene was built with, in the order applied (set:,
	 * --set or a stored side's protocol, the grid values): with scene_path
	 * they rebuild the scene (run --out records them). Strings borrowed. */
	bsim_override *ov;
	int n_ov;
	uint64_t seed;
	long group, trial;
	/* A stored run's side: its backend, options (every knob) and label;
	 * backend NULL otherwise (the command's --backend). */
	const bsim_backend *backend;
	bsim_options opts;
	char label[128];
	char command[16]; /* a stored run's: "sweep" or "compare" */
	/* compare --protocols, side b: its lattice.protocol override */
	char protocol[16];
	bsim_override side_ov;
	/* "group 10: effects.propulsion.force=8, ..." (the grid values
	 * applied); "" for a scene. */
	char grid[1024];
	/* A stored run's trials of the side (stored.r.trials_out[group *
	 * stored.r.trials + trial] is the row). */
	int has_stored;
	bsim_sweep_dir_result stored;
	bsim_experiment e; /* CLI_REPLAY_EXPERIMENT: the loaded experiment */
} cli_replay;

/* 1 if path is a directory (an output directory to replay from). */
int cli_replay_is_dir(const char *path);

/* Builds the trial of path (above) for command cmd: group and trial as
 * given (has_group: --group was given), c's --seed (default_seed for a
 * scene), --set and, for a directory, --backend as the side's label.
 * Prints any error and returns the exit status (2 for bad input: a group
 * or trial out of range names the range); CLI_OK with r to free. */
int cli_replay_open(const char *cmd, const char *path, const cli_common *c, long group, long trial,
                    int has_group, uint64_t default_seed, cli_replay *r);

void cli_replay_free(cli_replay *r);

/* The fields of the trial's trials.csv row that say what happened to it
 * (group, trial, outcome, type, steps, t_end, x_end, y_end), written as
 * the sweep writes them. */
void cli_replay_row(char *buf, size_t size, long group, long trial, const bsim_trial_result *x);

/* For a stored run: compares the replayed result x with the stored row
 * (those fields as written). Prints on out where the row is and whether it
 * is the same; returns CLI_OK if it is, else CLI_DISAGREE with a line on
 * stderr. CLI_OK for any other kind (nothing printed). */
int cli_replay_check(const cli_replay *r, const bsim_trial_result *x, FILE *out);

#endif
