/* A comparison's side read from a trials.csv made elsewhere; see
 * store/compare_read.h. */
#define _XOPEN_SOURCE 700 /* realpath */

#include "store/compare_read.h"

#include <errno.h>
#include <inttypes.h>
#include <libgen.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "beamsim/backend_registry.h"
#include "beamsim/effects.h"
#include "store/trials_csv.h"
#include "util/csv_table.h"
#include "util/hash.h"

static int read_create(const bsim_scene *scene, const bsim_options *opts, bsim_world **out,
                       bsim_error *err)
{
	(void)scene;
	(void)opts;
	*out = NULL;
	return bsim_error_set(err, BSIM_EINPUT,
	                      "a side read from trials made elsewhere (" BSIM_TRIALS_PREFIX
	                      "PATH) runs no trial in beamsim");
}

const bsim_backend bsim_compare_read_backend = {
        .name = "trials",
        .description = "trials read from a trials.csv made elsewhere (compare's " BSIM_TRIALS_PREFIX
                       "PATH), not run",
        .create = read_create,
};

/* A folder's name that can label a side: its directory in the comparison's
 * is the label, next to report.md, run.json and inputs/. */
static int label_ok(const char *name)
{
	size_t n = strlen(name);
	if (n == 0 || n >= 64 || strcmp(name, "inputs") == 0)
		return 0;
	return strspn(name, "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-+=") ==
	       n;
}

/* The file a side names: PATH, or PATH/trials.csv if PATH is a directory;
 * its folder's absolute path into folder (NULL: not wanted). */
static int side_file(const char *spec, const char *path, char *file, size_t size, char *folder,
                     bsim_error *err)
{
	struct stat st;
	if (stat(path, &st) != 0)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "--backends: side %s: %s: expected a trials.csv or a "
		                      "directory holding one, got %s",
		                      spec, path, strerror(errno));
	int dir = S_ISDIR(st.st_mode);
	int n = snprintf(file, size, dir ? "%s/trials.csv" : "%s", path);
	if (n < 0 || (size_t)n >= size)
		return bsim_error_set(err, BSIM_EINPUT, "--backends: side %s: path too long", spec);
	if (!folder)
		return BSIM_OK;
	char *real = realpath(path, NULL);
	if (!real)
		return bsim_error_set(err, BSIM_EINPUT, "--backends: side %s: %s: %s", spec, path,
		                      strerror(errno));
	snprintf(folder, BSIM_PATH_MAX, "%s", dir ? real : dirname(real));
	free(real);
	return BSIM_OK;
}

int bsim_compare_read_side(const char *spec, bsim_compare_side *side, bsim_error *err)
{
	const size_t skip = strlen(BSIM_TRIALS_PREFIX);
	size_t n = bsim_backend_spec_name(spec) - skip;
	if (spec[skip + n] == ':')
		return bsim_error_set(err, BSIM_EINPUT,
		                      "--backends: side %s: expected " BSIM_TRIALS_PREFIX
		                      "PATH alone (a side read from a file takes no options, and "
		                      "its path no ':')",
		                      spec);
	if (n == 0 || n >= sizeof side->trials)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "--backends: side %s: expected " BSIM_TRIALS_PREFIX
		                      "PATH with PATH a trials.csv or a directory holding one "
		                      "(at most %zu characters)",
		                      spec, sizeof side->trials - 1);
	snprintf(side->trials, sizeof side->trials, "%.*s", (int)n, spec + skip);
	char file[BSIM_PATH_MAX], folder[BSIM_PATH_MAX];
	if (side_file(spec, side->trials, file, sizeof file, folder, err) != BSIM_OK)
		return BSIM_EINPUT;
	side->backend = &bsim_compare_read_backend;
	const char *name = strrchr(folder, '/') ? strrchr(folder, '/') + 1 : folder;
	if (!label_ok(name)) /* at most 63 characters when it is */
		name = "trials";
	memcpy(side->label, name, strlen(name) + 1);
	return BSIM_OK;
}

void bsim_compare_read_free(compare_read *rd)
{
	free(rd->bytes);
	bsim_sweep_result_free(&rd->r);
	memset(rd, 0, sizeof *rd);
}

/* What the file does not say, as a sweep gives it: no barrier is known
 * (landscape_beam -1, not beam 0's), a deterministic group's interval is
 * its one trial's point, and only its trial 0 counts as run. */
static void result_complete(bsim_sweep_result *r, const bsim_scene *scene0)
{
	for (long i = 0; i < (long)r->n_groups * r->trials; i++)
		r->trials_out[i].landscape_beam = -1;
	r->trials_run = 0;
	r->solver = (bsim_solver_counts){0, 0};
	for (int g = 0; g < r->n_groups; g++) {
		bsim_group_result *gr = &r->groups[g];
		int det = gr->deterministic;
		bsim_sweep_group_aggregate(&r->trials_out[(size_t)g * r->trials], r->trials, gr);
		gr->deterministic = det;
		if (det && r->trials > 0) {
			gr->ci95[0] = gr->ci95[1] = gr->p_traverse;
			gr->solver = r->trials_out[(size_t)g * r->trials].solver;
		}
		r->trials_run += det && r->trials > 0 ? 1 : r->trials;
		r->solver.iteration_limit += gr->solver.iteration_limit;
		r->solver.clamped += gr->solver.clamped;
		gr->rotates = scene0->body.rotates;
	}
	r->lattice = scene0->has_lattice;
	r->lattice_def = scene0->lattice;
}

/* Per group 1 if its scene draws no random numbers (trial 0 stands for
 * every trial); scene0 gets group 0's scene. */
static int groups_one_trial(const bsim_experiment *e, const bsim_override *extra, int n_extra,
                            int *one, bsim_scene *scene0, bsim_error *err)
{
	for (int g = 0; g < e->n_groups; g++) {
		bsim_scene s;
		if (bsim_experiment_group_scene(e, g, extra, n_extra, &s, err) != BSIM_OK) {
			if (g > 0)
				bsim_scene_free(scene0);
			return BSIM_EINPUT;
		}
		one[g] = !bsim_effects_random(&s);
		if (g == 0)
			*scene0 = s;
		else
			bsim_scene_free(&s);
	}
	return BSIM_OK;
}

int bsim_compare_read_load(const bsim_compare_side *side, const bsim_experiment *e,
                           const bsim_override *extra, int n_extra, compare_read *out,
                           bsim_error *err)
{
	memset(out, 0, sizeof *out);
	char spec[BSIM_PATH_MAX + 16];
	snprintf(spec, sizeof spec, BSIM_TRIALS_PREFIX "%s", side->trials);
	if (side_file(spec, side->trials, out->given, sizeof out->given, NULL, err) != BSIM_OK)
		return BSIM_EINPUT;
	char *real = realpath(out->given, NULL);
	snprintf(out->path, sizeof out->path, "%s", real ? real : out->given);
	free(real);
	file_text ft;
	int rc = bsim_csv_text_read(out->given, &ft, err);
	if (rc != BSIM_OK)
		return rc;
	/* The bytes as read, before the parse splits them: what is hashed
	 * is what the comparison copies. */
	out->bytes = malloc(ft.len ? ft.len : 1);
	if (!out->bytes) {
		bsim_file_text_free(&ft);
		return bsim_error_set(err, BSIM_EFAIL, "%s: out of memory", out->given);
	}
	memcpy(out->bytes, ft.text, ft.len);
	out->len = ft.len;
	snprintf(out->hash, sizeof out->hash, "%016" PRIx64,
	         bsim_hash_fnv1a64(ft.text, ft.len, HASH_FNV1A64_SEED));
	if (side->trials_hash[0] && strcmp(side->trials_hash, out->hash) != 0)
		rc = bsim_error_set(err, BSIM_EINPUT,
		                    "%s: expected the bytes the comparison read (FNV-1a 64 %s, as "
		                    "its run.json records), got others (%s): the file changed "
		                    "since; restore it, or compare anew",
		                    out->given, side->trials_hash, out->hash);
	int *one = calloc(e->n_groups > 0 ? (size_t)e->n_groups : 1, sizeof *one);
	bsim_scene scene0;
	if (rc == BSIM_OK && !one)
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory for %d groups", e->n_groups);
	if (rc == BSIM_OK)
		rc = groups_one_trial(e, extra, n_extra, one, &scene0, err);
	if (rc == BSIM_OK) {
		trials_csv_shape shape = {.n_groups = e->n_groups,
		                          .trials = e->trials,
		                          .one_trial = one,
		                          .need_final_gate = scene0.has_lattice,
		                          .type_rule = 1};
		rc = bsim_trials_csv_parse(out->given, ft.text, &shape, &out->r, err);
		if (rc == BSIM_OK)
			result_complete(&out->r, &scene0);
		bsim_scene_free(&scene0);
	}
	free(one);
	bsim_file_text_free(&ft);
	if (rc != BSIM_OK) {
		free(out->bytes);
		out->bytes = NULL;
	}
	return rc;
}
