/* The trial run and video replay; see cli_replay.h. */
#define _POSIX_C_SOURCE 200809L

#include "cli/cli_replay.h"

#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "beamsim/compare_dir.h"
#include "beamsim/limits.h"
#include "beamsim/run_record.h"
#include "util/yaml_doc.h"

int cli_replay_is_dir(const char *path)
{
	struct stat st;
	return stat(path, &st) == 0 && S_ISDIR(st.st_mode);
}

/* An experiment file has scene: and grid: at its top, as the scene loader
 * tells one apart (a file that does not parse is left to it). */
static int is_experiment(const char *path)
{
	ydoc d;
	bsim_error err;
	if (ydoc_load(&d, path, &err) != BSIM_OK)
		return 0;
	struct fy_node *root = fy_document_root(d.fyd);
	int yes = root && fy_node_is_mapping(root) && ydoc_pair(root, "scene", 5) &&
	          ydoc_pair(root, "grid", 4);
	ydoc_free(&d);
	return yes;
}

/* --group and --trial within the experiment's, naming the range if not. */
static int check_range(const cli_replay *r, const bsim_experiment *e)
{
	if (r->group >= e->n_groups) {
		cli_error("--group %ld: expected 0 to %d (%s has %d group%s)", r->group,
		          e->n_groups - 1, cli_path(r->path), e->n_groups,
		          e->n_groups == 1 ? "" : "s");
		return CLI_USAGE;
	}
	if (r->trial >= e->trials) {
		cli_error("--trial %ld: expected 0 to %d (%s has %d trial%s per group)", r->trial,
		          e->trials - 1, cli_path(r->path), e->trials, e->trials == 1 ? "" : "s");
		return CLI_USAGE;
	}
	return CLI_OK;
}

/* The group's scene with extra after set: (as the sweep applies them),
 * the overrides it was built from and the line of its grid values. */
static int group_build(cli_replay *r, const bsim_experiment *e, const bsim_override *extra,
                       int n_extra)
{
	bsim_error err;
	if (bsim_experiment_group_scene(e, (int)r->group, extra, n_extra, &r->scene, &err) !=
	    BSIM_OK) {
		cli_error("%s", err.msg);
		return err.code ? err.code : CLI_USAGE;
	}
	int n = e->n_set + n_extra + e->n_axes;
	int *idx = calloc((size_t)(e->n_axes ? e->n_axes : 1), sizeof *idx);
	r->ov = calloc((size_t)(n ? n : 1), sizeof *r->ov);
	if (!idx || !r->ov) {
		free(idx);
		bsim_scene_free(&r->scene);
		cli_error("out of memory");
		return CLI_FAIL;
	}
	bsim_experiment_group_index(e, (int)r->group, idx);
	for (int i = 0; i < e->n_set; i++)
		r->ov[r->n_ov++] = e->set[i];
	for (int i = 0; i < n_extra; i++)
		r->ov[r->n_ov++] = extra[i];
	int len = snprintf(r->grid, sizeof r->grid, "group %ld:", r->group);
	for (int a = 0; a < e->n_axes; a++) {
		const bsim_grid_axis *ax = &e->axes[a];
		r->ov[r->n_ov++] =
		        (bsim_override){ax->key, ax->values[idx[a]], ax->origins[idx[a]]};
		if (len >= 0 && (size_t)len < sizeof r->grid)
			len += snprintf(r->grid + len, sizeof r->grid - (size_t)len, "%s %s=%s",
			                a ? "," : "", ax->key, ax->values[idx[a]]);
	}
	free(idx);
	r->scene_path = e->scene_path;
	return CLI_OK;
}

static int open_experiment(cli_replay *r, const cli_common *c)
{
	int rc = cli_experiment_load(r->path, &c->sets, 0, &r->e);
	if (rc != CLI_OK)
		return rc;
	r->kind = CLI_REPLAY_EXPERIMENT;
	r->seed = c->has_seed ? c->seed : r->e.seed;
	rc = check_range(r, &r->e);
	if (rc == CLI_OK)
		rc = group_build(r, &r->e, c->sets.ov, c->sets.n);
	if (rc != CLI_OK)
		bsim_experiment_free(&r->e);
	return rc;
}

/* The side of a stored run --backend names (its label, or the directory
 * the label gives); -1 with the error printed if none. */
static int stored_side(const char *dir, const bsim_run_record *rec, const char *want)
{
	if (rec->n_backends == 1) {
		if (!want || strcmp(want, rec->label[0]) == 0)
			return 0;
		cli_error("--backend %s: %s is a sweep on backend %s (run.json); to run its trials "
		          "on another backend give its experiment, %s/inputs/experiment.yaml",
		          want, cli_path(dir), rec->label[0], cli_path(dir));
		return -1;
	}
	for (int i = 0; want && i < 2; i++) {
		char name[128];
		bsim_compare_dir_label(rec->label[i], name, sizeof name);
		if (strcmp(want, rec->label[i]) == 0 || strcmp(want, name) == 0)
			return i;
	}
	if (want)
		cli_error("--backend %s: %s is a comparison of two sides, %s and %s: choose one "
		          "with --backend %s or --backend %s",
		          want, cli_path(dir), rec->label[0], rec->label[1], rec->label[0],
		          rec->label[1]);
	else
		cli_error("%s is a comparison of two sides, %s and %s: choose one with --backend "
		          "%s or --backend %s",
		          cli_path(dir), rec->label[0], rec->label[1], rec->label[0],
		          rec->label[1]);
	return -1;
}

static int open_stored(cli_replay *r, const cli_common *c)
{
	const char *dir = r->path;
	/* What ran is the record's: the options that would change it are
	 * refused, not quietly ignored. */
	const char *refused = c->has_seed             ? "--seed"
	                      : c->sets.n > 0         ? "--set"
	                      : c->sets.n_grid > 0    ? "--grid"
	                      : c->n_backend_opts > 0 ? "--backend-opt"
	                                              : NULL;
	if (refused) {
		cli_error("%s: %s holds a stored run, replayed with its own seed, overrides and "
		          "options; to change them give its experiment, %s/inputs/experiment.yaml",
		          refused, cli_path(dir), cli_path(dir));
		return CLI_USAGE;
	}
	bsim_run_record rec;
	bsim_error err;
	char record[BSIM_PATH_MAX];
	int n = snprintf(record, sizeof record, "%s/run.json", dir);
	if (n < 0 || (size_t)n >= sizeof record || access(record, F_OK) != 0) {
		cli_error("%s: expected a YAML file, got a directory that holds no stored run (no "
		          "run.json: the output directory of beamsim sweep or compare is replayed "
		          "from its run.json and inputs/)",
		          cli_path(dir));
		return CLI_USAGE;
	}
	if (bsim_run_record_read(dir, &rec, &err) != BSIM_OK) {
		cli_error("%s (expected the output directory of beamsim sweep or compare)",
		          err.msg);
		return CLI_USAGE;
	}
	int side = stored_side(dir, &rec, c->backend);
	if (side < 0)
		return CLI_USAGE;
	const bsim_backend *b = bsim_backend_find(rec.backend[side], &err);
	if (!b || bsim_options_check(&rec.opts[side], b->knobs, b->n_knobs, b->name, &err)) {
		cli_error("%s/run.json: %s", cli_path(dir), err.msg);
		return CLI_USAGE;
	}
	r->backend = b;
	r->opts = rec.opts[side];
	snprintf(r->label, sizeof r->label, "%s", rec.label[side]);
	snprintf(r->command, sizeof r->command, "%s", rec.command);
	if (bsim_sweep_dir_read(dir, rec.n_backends == 2 ? rec.label[side] : NULL, &r->stored,
	                        &err) != BSIM_OK) {
		cli_error("%s", err.msg);
		return err.code ? err.code : CLI_USAGE;
	}
	r->has_stored = 1;
	r->kind = CLI_REPLAY_STORED;
	r->seed = r->stored.e.seed;
	int rc = check_range(r, &r->stored.e);
	/* compare --protocols: side a's protocol is in the stored set:, side
	 * b's comes after it, as the comparison applied it. */
	int side_b = side == 1 && rec.protocol[1][0];
	snprintf(r->protocol, sizeof r->protocol, "%s", side_b ? rec.protocol[1] : "");
	r->side_ov = (bsim_override){"lattice.protocol", r->protocol, "--protocols (side b)"};
	if (rc == CLI_OK)
		rc = group_build(r, &r->stored.e, side_b ? &r->side_ov : NULL, side_b);
	size_t len = strlen(r->grid);
	if (rc == CLI_OK && side_b)
		snprintf(r->grid + len, sizeof r->grid - len, "; side %s: lattice.protocol=%s",
		         r->label, r->protocol);
	if (rc != CLI_OK) {
		bsim_sweep_dir_result_free(&r->stored);
		r->has_stored = 0;
	}
	return rc;
}

int cli_replay_open(const char *cmd, const char *path, const cli_common *c, long group, long trial,
                    int has_group, uint64_t default_seed, cli_replay *r)
{
	memset(r, 0, sizeof *r);
	r->path = path;
	r->group = group;
	r->trial = trial;
	if (cli_replay_is_dir(path))
		return open_stored(r, c);
	if (is_experiment(path))
		return open_experiment(r, c);
	if (c->sets.n_grid > 0) {
		cli_error(
		        "--grid %s: %s is a scene, which has no grid; --grid changes an "
		        "experiment's grid (give the experiment, or --set KEY=VALUE for one value)",
		        c->sets.grid[0].key, cli_path(path));
		return CLI_USAGE;
	}
	bsim_error err;
	if (bsim_scene_load(path, c->sets.ov, c->sets.n, &r->scene, &err) != BSIM_OK) {
		cli_error("%s", err.msg);
		return err.code ? err.code : CLI_USAGE;
	}
	r->kind = CLI_REPLAY_SCENE;
	r->scene_path = path;
	r->ov = NULL;
	r->seed = c->has_seed ? c->seed : default_seed;
	if (has_group)
		cli_error(
		        "note: %s is a scene, which has no grid: --group %ld picks only the "
		        "random-force schedule (the seed is mixed from seed, group and trial) and "
		        "applies no grid values; to replay a trial of a sweep give its experiment "
		        "or its output directory: beamsim %s EXPERIMENT|DIR --group G --trial T",
		        cli_path(path), group, cmd);
	return CLI_OK;
}

void cli_replay_free(cli_replay *r)
{
	bsim_scene_free(&r->scene);
	free(r->ov);
	if (r->kind == CLI_REPLAY_EXPERIMENT)
		bsim_experiment_free(&r->e);
	if (r->has_stored)
		bsim_sweep_dir_result_free(&r->stored);
	memset(r, 0, sizeof *r);
}

void cli_replay_row(char *buf, size_t size, long group, long trial, const bsim_trial_result *x)
{
	snprintf(buf, size, "%ld,%ld,%s,%s,%d,%.10g,%.10g,%.10g", group, trial,
	         bsim_trial_outcome_name(x->outcome), bsim_trial_type_name(x->type), x->steps,
	         x->t_end, x->x_end, x->y_end);
}

int cli_replay_check(const cli_replay *r, const bsim_trial_result *x, FILE *out)
{
	if (!r->has_stored)
		return CLI_OK;
	const bsim_sweep_result *s = &r->stored.r;
	const bsim_trial_result *y = &s->trials_out[r->group * s->trials + r->trial];
	char mine[256], theirs[256], where[BSIM_PATH_MAX + 160];
	cli_replay_row(mine, sizeof mine, r->group, r->trial, x);
	cli_replay_row(theirs, sizeof theirs, r->group, r->trial, y);
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
