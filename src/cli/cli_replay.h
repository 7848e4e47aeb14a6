/* The trial run and video replay, from what their one argument names (a
 * scene file, an experiment file or an output directory of sweep or
 * compare): the library's replay (beamsim/replay.h) opened from the
 * command's --seed, --set, --grid, --backend and --backend-opt, its errors
 * and notes printed, and a stored run's row checked against the replay. */
#ifndef BSIM_CLI_CLI_REPLAY_H
#define BSIM_CLI_CLI_REPLAY_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "beamsim/replay.h"
#include "cli/cli_options.h"

/* Opens the trial of path for command cmd: group and trial as given
 * (has_group: --group was given), c's --seed (default_seed for a scene),
 * --set, --grid and, for a directory, --backend as the side's label.
 * Prints any error and returns the exit status (2 for bad input: a group
 * or trial out of range names the range); CLI_OK with *r to free with
 * bsim_replay_free. */
int cli_replay_open(const char *cmd, const char *path, const cli_common *c, long group, long trial,
                    int has_group, uint64_t default_seed, bsim_replay **r);

/* For a stored run: compares the replayed result x with the stored row
 * (those fields as written, bsim_replay_row). Prints on out where the row
 * is and whether it is the same; returns CLI_OK if it is, else
 * CLI_DISAGREE with a line on stderr. CLI_OK for any other kind (nothing
 * printed). */
int cli_replay_check(const bsim_replay *r, const bsim_trial_result *x, FILE *out);

#endif
