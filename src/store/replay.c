/* The trial `beamsim run ARG --group G --trial T` runs; see
 * beamsim/replay.h. */
#define _POSIX_C_SOURCE 200809L

#include "beamsim/replay.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "beamsim/backend_registry.h"
#include "beamsim/compare_dir.h"
#include "beamsim/limits.h"
#include "beamsim/run_output.h"
#include "beamsim/trial_fields.h"
#include "beamsim/run_record.h"
#include "beamsim/schedule.h"
#include "util/text_check.h"
#include "util/yaml_doc.h"

bsim_replay_def bsim_replay_def_default(void)
{
	bsim_replay_def d;
	memset(&d, 0, sizeof d);
	d.seed = bsim_run_info_default().seed;
	return d;
}

int bsim_replay_is_dir(const char *path)
{
	struct stat st;
	return path && stat(path, &st) == 0 && S_ISDIR(st.st_mode);
}

/* path as a message may quote it: one line of printable text. */
static const char *esc(const char *path, char *buf, size_t size)
{
	snprintf(buf, size, "%s", path);
	bsim_text_escape(buf, size);
	return buf;
}

/* An experiment file has scene: and grid: at its top, as the scene loader
 * tells one apart (a file that does not parse is left to it). */
static int is_experiment(const char *path)
{
	ydoc d;
	bsim_error err;
	if (bsim_ydoc_load(&d, path, &err) != BSIM_OK)
		return 0;
	struct fy_node *root = fy_document_root(d.fyd);
	int yes = root && fy_node_is_mapping(root) && bsim_ydoc_pair(root, "scene", 5) &&
	          bsim_ydoc_pair(root, "grid", 4);
	bsim_ydoc_free(&d);
	return yes;
}

/* The group and trial within the experiment's, naming the range if not. */
static int check_range(const bsim_replay *r, const bsim_experiment *e, bsim_error *err)
{
	char p[BSIM_ERROR_MSG_MAX];
	if (r->group >= e->n_groups)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "--group %ld: expected 0 to %d (%s has %d group%s)", r->group,
		                      e->n_groups - 1, esc(r->path, p, sizeof p), e->n_groups,
		                      e->n_groups == 1 ? "" : "s");
	if (r->trial >= e->trials)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "--trial %ld: expected 0 to %d (%s has %d trial%s per group)",
		                      r->trial, e->trials - 1, esc(r->path, p, sizeof p), e->trials,
		                      e->trials == 1 ? "" : "s");
	return BSIM_OK;
}

/* The group's scene with extra after set: (as the sweep applies them),
 * the overrides it was built from and the line of its grid values. */
static int group_build(bsim_replay *r, const bsim_experiment *e, const bsim_override *extra,
                       int n_extra, bsim_error *err)
{
	int rc = bsim_experiment_group_scene(e, (int)r->group, extra, n_extra, &r->scene, err);
	if (rc != BSIM_OK)
		return rc ? rc : BSIM_EINPUT;
	int *idx = calloc((size_t)(e->n_axes ? e->n_axes : 1), sizeof *idx);
	r->ov_owned = bsim_experiment_group_overrides(e, (int)r->group, extra, n_extra, &r->n_ov);
	if (!idx || !r->ov_owned) {
		free(idx);
		bsim_scene_free(&r->scene);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	bsim_experiment_group_index(e, (int)r->group, idx);
	int len = snprintf(r->grid, sizeof r->grid, "group %ld:", r->group);
	for (int a = 0; a < e->n_axes; a++) {
		const bsim_grid_axis *ax = &e->axes[a];
		if (len >= 0 && (size_t)len < sizeof r->grid)
			len += snprintf(r->grid + len, sizeof r->grid - (size_t)len, "%s %s=%s",
			                a ? "," : "", ax->key, ax->values[idx[a]]);
	}
	free(idx);
	r->ov = r->ov_owned;
	r->scene_path = e->scene_path;
	return BSIM_OK;
}

static int open_experiment(bsim_replay *r, const bsim_replay_def *def, bsim_error *err)
{
	int rc =
	        bsim_experiment_load_seeded(r->path, def->sets, def->n_sets, def->grid, def->n_grid,
	                                    def->has_seed ? &def->seed : NULL, &r->e, err);
	if (rc != BSIM_OK)
		return rc ? rc : BSIM_EINPUT;
	r->kind = BSIM_REPLAY_EXPERIMENT;
	r->seed = def->has_seed ? def->seed : r->e.seed;
	rc = check_range(r, &r->e, err);
	if (rc == BSIM_OK)
		rc = group_build(r, &r->e, def->sets, def->n_sets, err);
	if (rc != BSIM_OK) {
		bsim_experiment_free(&r->e);
		r->kind = BSIM_REPLAY_SCENE;
	}
	return rc;
}

/* The side of a stored run want names (its label, or the directory the
 * label gives); -1 with err set if none. */
static int stored_side(const char *dir, const bsim_run_record *rec, const char *want,
                       bsim_error *err)
{
	char d[BSIM_ERROR_MSG_MAX / 4];
	esc(dir, d, sizeof d);
	if (rec->n_backends == 1) {
		if (!want || strcmp(want, rec->label[0]) == 0)
			return 0;
		bsim_error_set(err, BSIM_EINPUT,
		               "--backend %s: %s is a sweep on backend %s (run.json); to run its "
		               "trials on another backend give its experiment, "
		               "%s/inputs/experiment.yaml",
		               want, d, rec->label[0], d);
		return -1;
	}
	for (int i = 0; want && i < rec->n_backends; i++) {
		char name[128];
		bsim_compare_dir_label(rec->label[i], name, sizeof name);
		if (strcmp(want, rec->label[i]) == 0 || strcmp(want, name) == 0)
			return i;
	}
	char want_text[BSIM_ERROR_MSG_MAX / 4] = "";
	if (want)
		snprintf(want_text, sizeof want_text, "--backend %s: ", want);
	if (rec->n_backends == 2) {
		bsim_error_set(err, BSIM_EINPUT,
		               "%s%s is a comparison of two sides, %s and %s: choose one with "
		               "--backend %s or --backend %s",
		               want_text, d, rec->label[0], rec->label[1], rec->label[0],
		               rec->label[1]);
		return -1;
	}
	char sides[BSIM_ERROR_MSG_MAX / 2] = "";
	size_t len = 0;
	for (int i = 0; i < rec->n_backends && len < sizeof sides; i++) {
		int w = snprintf(sides + len, sizeof sides - len, "%s%s",
		                 i == 0                    ? ""
		                 : i + 1 < rec->n_backends ? ", "
		                                           : " and ",
		                 rec->label[i]);
		len += w > 0 ? (size_t)w : 0;
	}
	bsim_error_set(err, BSIM_EINPUT,
	               "%s%s is a comparison of %d sides, %s: choose one with --backend LABEL",
	               want_text, d, rec->n_backends, sides);
	return -1;
}

static int open_stored(bsim_replay *r, const bsim_replay_def *def, bsim_error *err)
{
	const char *dir = r->path;
	char d[BSIM_ERROR_MSG_MAX / 4];
	esc(dir, d, sizeof d);
	/* What ran is the record's: the options that would change it are
	 * refused, not quietly ignored. */
	const char *refused = def->has_seed           ? "--seed"
	                      : def->n_sets > 0       ? "--set"
	                      : def->n_grid > 0       ? "--grid"
	                      : def->has_backend_opts ? "--backend-opt"
	                                              : NULL;
	if (refused)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: %s holds a stored run, replayed with its own seed, "
		                      "overrides and options; to change them give its experiment, "
		                      "%s/inputs/experiment.yaml",
		                      refused, d, d);
	bsim_run_record rec;
	char record[BSIM_PATH_MAX];
	int n = snprintf(record, sizeof record, "%s/run.json", dir);
	if (n < 0 || (size_t)n >= sizeof record || access(record, F_OK) != 0)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: expected a YAML file, got a directory that holds no "
		                      "stored run (no run.json: the output directory of beamsim "
		                      "sweep or compare is replayed from its run.json and inputs/)",
		                      d);
	if (bsim_run_record_read(dir, &rec, err) != BSIM_OK) {
		char msg[BSIM_ERROR_MSG_MAX];
		snprintf(msg, sizeof msg, "%s", err->msg);
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s (expected the output directory of beamsim sweep or "
		                      "compare)",
		                      msg);
	}
	int side = stored_side(dir, &rec, def->side, err);
	if (side < 0)
		return BSIM_EINPUT;
	if (rec.read_from[side][0])
		return bsim_error_set(
		        err, BSIM_EINPUT,
		        "--backend %s: side %s of %s was read from %s, made "
		        "elsewhere, not run by beamsim; expected a side that ran (the "
		        "trial's scene and schedule are those of beamsim run "
		        "%s/inputs/experiment.yaml --group G --trial T)",
		        def->side ? def->side : rec.label[side], rec.label[side], d,
		        rec.read_from[side], d);
	const bsim_backend *b = bsim_run_record_backend(&rec, side, err);
	if (!b || bsim_options_check(&rec.opts[side], b->knobs, b->n_knobs, b->name, err)) {
		char msg[BSIM_ERROR_MSG_MAX];
		snprintf(msg, sizeof msg, "%s", err->msg);
		return bsim_error_set(err, BSIM_EINPUT, "%s/run.json: %s", d, msg);
	}
	r->backend = b;
	r->opts = rec.opts[side];
	snprintf(r->label, sizeof r->label, "%s", rec.label[side]);
	snprintf(r->command, sizeof r->command, "%s", rec.command);
	int rc = bsim_sweep_dir_read(dir, rec.n_backends >= 2 ? rec.label[side] : NULL, &r->stored,
	                             err);
	if (rc != BSIM_OK)
		return rc ? rc : BSIM_EINPUT;
	r->has_stored = 1;
	r->kind = BSIM_REPLAY_STORED;
	r->seed = r->stored.e.seed;
	rc = check_range(r, &r->stored.e, err);
	/* compare --protocols: side a's protocol is in the stored set:, side
	 * b's comes after it, as the comparison applied it. */
	int side_b = side == 1 && rec.protocol[1][0];
	snprintf(r->protocol, sizeof r->protocol, "%s", side_b ? rec.protocol[1] : "");
	r->side_ov = (bsim_override){"lattice.protocol", r->protocol, "--protocols (side b)"};
	if (rc == BSIM_OK)
		rc = group_build(r, &r->stored.e, side_b ? &r->side_ov : NULL, side_b, err);
	size_t len = strlen(r->grid);
	if (rc == BSIM_OK && side_b)
		snprintf(r->grid + len, sizeof r->grid - len, "; side %s: lattice.protocol=%s",
		         r->label, r->protocol);
	if (rc != BSIM_OK) {
		bsim_sweep_dir_result_free(&r->stored);
		r->has_stored = 0;
	}
	return rc;
}

static int open_scene(bsim_replay *r, const bsim_replay_def *def, bsim_error *err)
{
	char p[BSIM_ERROR_MSG_MAX / 2];
	if (def->n_grid > 0)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "--grid %s: %s is a scene, which has no grid; --grid changes "
		                      "an experiment's grid (give the experiment, or --set "
		                      "KEY=VALUE for one value)",
		                      def->grid[0].key, esc(r->path, p, sizeof p));
	int rc = bsim_scene_load(r->path, def->sets, def->n_sets, &r->scene, err);
	if (rc != BSIM_OK)
		return rc ? rc : BSIM_EINPUT;
	r->kind = BSIM_REPLAY_SCENE;
	r->scene_path = r->path;
	r->ov = def->sets;
	r->n_ov = def->n_sets;
	r->seed = def->seed;
	return BSIM_OK;
}

int bsim_replay_open(const bsim_replay_def *def, bsim_replay **out, bsim_error *err)
{
	*out = NULL;
	if (!def->path)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "expected a scene, experiment or output "
		                      "directory, got none");
	if (def->group < 0 || def->group > INT32_MAX)
		return bsim_error_set(err, BSIM_EINPUT, "--group %ld: expected an integer >= 0",
		                      def->group);
	if (def->trial < 0 || def->trial > INT32_MAX)
		return bsim_error_set(err, BSIM_EINPUT, "--trial %ld: expected an integer >= 0",
		                      def->trial);
	bsim_replay *r = calloc(1, sizeof *r);
	if (!r)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	r->path = def->path;
	r->group = def->group;
	r->trial = def->trial;
	int rc = bsim_replay_is_dir(def->path) ? open_stored(r, def, err)
	         : is_experiment(def->path)    ? open_experiment(r, def, err)
	                                       : open_scene(r, def, err);
	if (rc != BSIM_OK) {
		free(r->ov_owned);
		free(r);
		return rc;
	}
	r->mixed_seed = bsim_schedule_seed_mix(r->seed, (uint64_t)r->group, (uint64_t)r->trial);
	*out = r;
	return BSIM_OK;
}

void bsim_replay_free(bsim_replay *r)
{
	if (!r)
		return;
	bsim_scene_free(&r->scene);
	free(r->ov_owned);
	if (r->kind == BSIM_REPLAY_EXPERIMENT)
		bsim_experiment_free(&r->e);
	if (r->has_stored)
		bsim_sweep_dir_result_free(&r->stored);
	free(r);
}

int bsim_replay_run(const bsim_replay *r, const bsim_backend *backend, const bsim_options *opts,
                    const bsim_recorder *rec, bsim_trial_result *res, bsim_error *err)
{
	bsim_options none;
	memset(&none, 0, sizeof none);
	if (!backend) {
		backend = r->backend ? r->backend : bsim_backend_default();
		opts = r->backend ? &r->opts : opts;
	}
	memset(res, 0, sizeof *res);
	/* What the backend refuses of the scene, said where the scene gave it. */
	int rc = bsim_backend_check(backend, opts ? opts : &none, &r->scene, r->scene_path, r->ov,
	                            r->n_ov, err);
	if (rc != BSIM_OK)
		return rc;
	bsim_trial_runner *runner = bsim_trial_runner_alloc();
	if (!runner)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	rc = bsim_trial_run(runner, &r->scene, backend, opts ? opts : &none, r->mixed_seed, rec,
	                    res, err);
	bsim_trial_runner_free(runner);
	return rc;
}

const bsim_trial_result *bsim_replay_stored_row(const bsim_replay *r)
{
	if (!r->has_stored)
		return NULL;
	const bsim_sweep_result *s = &r->stored.r;
	return &s->trials_out[r->group * s->trials + r->trial];
}

void bsim_replay_row(char *buf, size_t size, long group, long trial, const bsim_trial_result *x)
{
	int n;
	const bsim_trial_field *f = bsim_trial_fields(&n);
	const bsim_trial_row row = {(int)group, (int)trial, x, NULL, 0, NULL};
	char *text = NULL;
	size_t len = 0;
	FILE *m = open_memstream(&text, &len);
	for (int c = 0; m && c < BSIM_REPLAY_ROW_FIELDS && c < n; c++) {
		fputs(c ? "," : "", m);
		bsim_trial_field_write(m, &f[c], &row);
	}
	if (m)
		fclose(m);
	snprintf(buf, size, "%s", text ? text : "");
	free(text);
}
