/* The trial run and video replay; see cli_replay.h. */
#define _POSIX_C_SOURCE 200809L

#include "cli/cli_replay.h"

#include <stdio.h>
#include <string.h>

#include "beamsim/compare_dir.h"
#include "beamsim/limits.h"

int cli_replay_open(const char *cmd, const char *path, const cli_common *c, long group, long trial,
                    int has_group, uint64_t default_seed, bsim_replay **r)
{
	bsim_replay_def def = bsim_replay_def_default();
	def.path = path;
	def.group = group;
	def.trial = trial;
	def.has_seed = c->has_seed;
	def.seed = c->has_seed ? c->seed : default_seed;
	def.sets = c->sets.ov;
	def.n_sets = c->sets.n;
	def.grid = c->sets.grid;
	def.n_grid = c->sets.n_grid;
	def.side = c->backend;
	def.has_backend_opts = c->n_backend_opts > 0;
	bsim_error err;
	int rc = bsim_replay_open(&def, r, &err);
	if (rc != BSIM_OK) {
		cli_error("%s", err.msg);
		return rc;
	}
	if ((*r)->kind == BSIM_REPLAY_SCENE && has_group)
		cli_error(
		        "note: %s is a scene, which has no grid: --group %ld picks only the "
		        "random-force schedule (the seed is mixed from seed, group and trial) and "
		        "applies no grid values; to replay a trial of a sweep give its experiment "
		        "or its output directory: beamsim %s EXPERIMENT|DIR --group G --trial T",
		        cli_path(path), group, cmd);
	return CLI_OK;
}

int cli_replay_check(const bsim_replay *r, const bsim_trial_result *x, FILE *out)
{
	const bsim_trial_result *y = bsim_replay_stored_row(r);
	if (!y)
		return CLI_OK;
	char mine[256], theirs[256], where[BSIM_PATH_MAX + 160];
	bsim_replay_row(mine, sizeof mine, r->group, r->trial, x);
	bsim_replay_row(theirs, sizeof theirs, r->group, r->trial, y);
	if (strcmp(r->command, "compare") == 0) {
		char name[128];
		bsim_compare_dir_label(r->label, name, sizeof name);
		snprintf(where, sizeof where, "%s/%s/trials.csv", cli_path(r->path), name);
	} else {
		snprintf(where, sizeof where, "%s/trials.csv", cli_path(r->path));
	}
	int same = strcmp(mine, theirs) == 0;
	fprintf(out, "stored      %s: %s (%s)\n", where, theirs,
	        same ? "the same" : "differs from the replay");
	if (same)
		return CLI_OK;
	cli_error("the replay of group %ld, trial %ld differs from its row in %s: %s, stored %s",
	          r->group, r->trial, where, mine, theirs);
	return CLI_DISAGREE;
}
