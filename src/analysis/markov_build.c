/* The maps of an experiment (beamsim/markov.h, bsim_markov_build_run): every
 * group's lattice's maps built into one map directory by bsim_markov_build,
 * the parts of a spread build taking turns along all of them, a part's
 * part.json and a merge's check that its parts are this build's. */
#include "analysis/markov_internal.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/backend_registry.h"
#include "beamsim/experiment.h"
#include "beamsim/markov.h"
#include "beamsim/output.h"
#include "beamsim/sweep_dir.h"
#include "store/outdir.h"

bsim_markov_build_def bsim_markov_build_def_default(void)
{
	return (bsim_markov_build_def){.method = BSIM_MARKOV_METHOD_NEAREST,
	                               .nearest = bsim_markov_nearest_def_default(),
	                               .map = bsim_markov_def_default()};
}

int bsim_markov_entries_kind(const char *value, bsim_markov_def *def, int *is_kind, bsim_error *err)
{
	*is_kind = strcmp(value, "self") == 0 || strncmp(value, "self:", 5) == 0 ||
	           strcmp(value, "flow") == 0 || strncmp(value, "flow:", 5) == 0;
	if (!*is_kind)
		return BSIM_OK;
	long n = 1;
	if (value[4]) {
		char *end;
		errno = 0;
		n = strtol(value + 5, &end, 10);
		if (errno || end == value + 5 || *end || n > BSIM_MARKOV_SELF_PASSES_MAX)
			n = -1;
	}
	if (n < 0)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "entries %s: expected self, self:N, flow or flow:N, N "
		                      "passes 0 to %d",
		                      value, BSIM_MARKOV_SELF_PASSES_MAX);
	def->self_entries = value[0] == 's' ? 1 : 2;
	def->self_passes = (int)n;
	def->start_trials = 0; /* passes pool every bin's trials alike: the start's are trials */
	def->after_start = 0;  /* the start's exits are those of its own pass */
	return BSIM_OK;
}

void bsim_markov_build_result_free(bsim_markov_build_result *res)
{
	if (!res)
		return;
	free(res->maps);
	memset(res, 0, sizeof *res);
}

/* The spread's combination, checked before anything is read. */
static int build_check(const bsim_markov_build_def *def, bsim_error *err)
{
	if (!def->experiment || !def->out)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "markov build: expected an experiment and a map directory");
	if (def->parts < 0 || (def->parts > 0 && (def->part < 1 || def->part > def->parts)))
		return bsim_error_set(err, BSIM_EINPUT,
		                      "markov build: part %d of %d: expected a part from 1 to "
		                      "the parts",
		                      def->part, def->parts);
	if (def->round && (def->map.self_entries != 2 || (def->parts <= 0 && def->n_merge <= 0)))
		return bsim_error_set(err, BSIM_EINPUT,
		                      "markov build: a round is one pass of flow entries built in "
		                      "parts, or their merge");
	if (def->passes && !def->round)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: the merged directory of the round before, for flow "
		                      "entries built in parts",
		                      def->passes);
	if (def->n_merge > 0 && def->parts > 0)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "markov build: a merge joins the parts, it is none of them");
	return BSIM_OK;
}

/* Appends set's maps, of group g, to res. */
static int maps_add(bsim_markov_build_result *res, int g, const bsim_markov_set *set,
                    bsim_error *err)
{
	bsim_markov_built *m = realloc(res->maps, (size_t)(res->n_maps + set->n + 1) * sizeof *m);
	if (!m)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	res->maps = m;
	for (int i = 0; i < set->n; i++) {
		const bsim_markov_map *s = &set->maps[i];
		m[res->n_maps++] = (bsim_markov_built){.group = g,
		                                       .k = {s->k[0], s->k[1]},
		                                       .key = s->key,
		                                       .pass = set->pass,
		                                       .cached = s->cached,
		                                       .copied = s->copied,
		                                       .elsewhere = s->elsewhere};
	}
	return BSIM_OK;
}

/* The groups' maps, each group's set built (or read, or copied) in turn. */
static int build_groups(const bsim_markov_build_def *def, const bsim_experiment *e,
                        bsim_markov_def *md, bsim_markov_build_result *res, int *own,
                        bsim_error *err)
{
	int rc = BSIM_OK;
	for (int g = 0; g < e->n_groups && rc == BSIM_OK; g++) {
		bsim_scene scene;
		rc = bsim_experiment_group_scene(e, g, def->sets, def->n_sets, &scene, err);
		if (rc != BSIM_OK)
			break;
		bsim_markov_set set;
		md->part_first = res->n_maps; /* the parts take turns along every group's maps */
		rc = bsim_markov_build(&scene, md, def->out, &set, err);
		bsim_scene_free(&scene);
		if (rc != BSIM_OK)
			break;
		res->built += set.built;
		res->reused += set.reused;
		res->next_built += set.next_built;
		res->next_reused += set.next_reused;
		res->copied += set.copied;
		*own += set.built + set.reused;
		res->seconds += set.seconds;
		if (g == 0)
			res->pass = set.pass;
		else if (res->round && set.pass != res->pass)
			rc = bsim_error_set(err, BSIM_EINPUT,
			                    "%s: group 0's maps are at pass %d but group %d's at "
			                    "pass %d: not the merge of one round",
			                    def->passes ? def->passes : "--passes", res->pass, g,
			                    set.pass);
		const int first = res->n_maps;
		if (maps_add(res, g, &set, err) != BSIM_OK)
			rc = BSIM_EFAIL;
		else if (def->group_done)
			def->group_done(def->group_done_user, g, res->maps + first, set.n);
		bsim_markov_set_free(&set);
	}
	return rc;
}

/* The build's name from the keys of all its maps (a round's: and its
 * pass), and a merge's check that its first part carries it. */
static int build_name(const bsim_markov_build_def *def, bsim_markov_build_result *res,
                      bsim_error *err)
{
	uint64_t *keys = malloc((size_t)(res->n_maps + 1) * sizeof *keys);
	if (!keys)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	for (int i = 0; i < res->n_maps; i++)
		keys[i] = res->maps[i].key;
	if (res->round) /* a round's parts: one pass's */
		keys[res->n_maps] = (uint64_t)res->pass;
	bsim_markov_run_id(keys, res->n_maps + res->round, res->run);
	free(keys);
	if (def->n_merge <= 0)
		return BSIM_OK;
	bsim_sweep_dir_part first;
	memset(&first, 0, sizeof first);
	int rc = bsim_sweep_dir_part_read(def->merge[0], &first, err);
	if (rc == BSIM_OK && strcmp(first.run, res->run) != 0)
		rc = bsim_error_set(err, BSIM_EINPUT,
		                    "%s: part %d of %d of run %s, but the experiment read now "
		                    "makes run %s: its file changed since the parts ran",
		                    def->merge[0], first.index, first.count, first.run, res->run);
	bsim_sweep_dir_part_free(&first);
	return rc;
}

int bsim_markov_build_method(const char *method, const char *maps_option, const char *k_option,
                             bsim_markov_method *out, bsim_error *err)
{
	if (method && strcmp(method, "nearest") != 0 && strcmp(method, "maps") != 0)
		return bsim_error_set(err, BSIM_EINPUT, "method %s: expected nearest or maps",
		                      method);
	*out = method ? (method[0] == 'n' ? BSIM_MARKOV_METHOD_NEAREST : BSIM_MARKOV_METHOD_MAPS)
	       : maps_option ? BSIM_MARKOV_METHOD_MAPS
	                     : BSIM_MARKOV_METHOD_NEAREST;
	if (*out == BSIM_MARKOV_METHOD_NEAREST && maps_option)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s is for method maps: the nearest-neighbour walks' "
		                      "training fields have no entry bins",
		                      maps_option);
	if (*out == BSIM_MARKOV_METHOD_MAPS && k_option)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s is for the nearest-neighbour walks (method nearest), "
		                      "not maps",
		                      k_option);
	return BSIM_OK;
}

/* A walks' build as it goes: its directory, the group whose fields are
 * being had, and the result they join. */
typedef struct nearest_build {
	bsim_outdir *od;
	int group;
	bsim_markov_build_result *res;
	int oom;
} nearest_build;

/* A training field just written into the stage joins the directory's set
 * at once, so a build stopped or killed later keeps it. */
static int field_commit(void *user, bsim_error *err)
{
	nearest_build *nb = user;
	if (bsim_outdir_add(nb->od, "markov build", err) != BSIM_OK)
		return BSIM_EFAIL;
	return bsim_output_mkdir(bsim_outdir_stage(nb->od), err);
}

static void field_had(void *user, const double k[2], uint64_t hash, int reused, double cost)
{
	nearest_build *nb = user;
	bsim_markov_build_result *res = nb->res;
	if (!reused)
		res->seconds += cost;
	bsim_markov_built *m = realloc(res->maps, (size_t)(res->n_maps + 1) * sizeof *m);
	if (!m) {
		nb->oom = 1;
		return;
	}
	res->maps = m;
	m[res->n_maps++] = (bsim_markov_built){
	        .group = nb->group, .k = {k[0], k[1]}, .key = hash, .cached = reused};
}

/* The walks' training fields of every group into def->out, and markov.json
 * naming their settings. */
static int build_nearest(const bsim_markov_build_def *def, bsim_markov_build_result *res,
                         bsim_error *err)
{
	const char *maps_only = def->n_entries > 0 ? "entries"
	                        : def->parts > 0   ? "a part"
	                        : def->n_merge > 0 ? "a merge of parts"
	                        : def->round       ? "a round"
	                        : def->passes      ? "passes"
	                                           : NULL;
	if (maps_only)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "markov build: %s: for maps (method maps), not the "
		                      "nearest-neighbour walks' training fields",
		                      maps_only);
	bsim_markov_nearest_def nd = def->nearest;
	if (def->has_seed)
		nd.seed = def->seed;
	nd.read_only = 0;
	const bsim_backend *be = nd.backend ? nd.backend : bsim_backend_default();
	bsim_experiment e;
	int rc = bsim_experiment_load_seeded(def->experiment, def->sets, def->n_sets, def->grid,
	                                     def->n_grid, def->has_seed ? &def->seed : NULL, &e,
	                                     err);
	if (rc != BSIM_OK)
		return rc ? rc : BSIM_EINPUT;
	res->n_groups = e.n_groups;
	nearest_build nb = {.res = res};
	rc = bsim_outdir_open(&nb.od, def->out, BSIM_OUTDIR_ADD, "markov build", NULL, err);
	const markov_visits_io io = {.stage = rc == BSIM_OK ? bsim_outdir_stage(nb.od) : NULL,
	                             .commit = field_commit,
	                             .field = field_had,
	                             .user = &nb};
	for (int g = 0; g < e.n_groups && rc == BSIM_OK; g++) {
		bsim_scene scene;
		rc = bsim_experiment_group_scene(&e, g, def->sets, def->n_sets, &scene, err);
		if (rc != BSIM_OK)
			break;
		const int first = res->n_maps;
		nb.group = g;
		bsim_markov_visits v;
		rc = bsim_markov_visits_gather(&scene, &nd, def->out, &io, &v, err);
		bsim_scene_free(&scene);
		if (rc == BSIM_OK && nb.oom)
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
		if (rc != BSIM_OK)
			break;
		res->built += v.built;
		res->reused += v.reused;
		res->visits += v.n;
		bsim_markov_visits_free(&v);
		if (def->group_done)
			def->group_done(def->group_done_user, g, res->maps + first,
			                res->n_maps - first);
	}
	if (rc == BSIM_OK) /* the fields' keys name the build, as the maps' do */
		rc = build_name(def, res, err);
	if (rc == BSIM_OK)
		rc = bsim_markov_nearest_def_write(bsim_outdir_stage(nb.od), &nd, be, nd.opts, err);
	if (rc == BSIM_OK)
		rc = bsim_outdir_add(nb.od, "markov build", err);
	bsim_outdir_close(nb.od);
	bsim_experiment_free(&e);
	return rc;
}

int bsim_markov_build_run(const bsim_markov_build_def *def, bsim_markov_build_result *res,
                          bsim_error *err)
{
	memset(res, 0, sizeof *res);
	res->method = def->method;
	if (def->method == BSIM_MARKOV_METHOD_NEAREST) {
		int rc = !def->experiment || !def->out
		                 ? bsim_error_set(err, BSIM_EINPUT,
		                                  "markov build: expected an experiment and a "
		                                  "directory")
		                 : build_nearest(def, res, err);
		if (rc != BSIM_OK)
			bsim_markov_build_result_free(res);
		return rc;
	}
	if (def->method != BSIM_MARKOV_METHOD_MAPS)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "markov build: method %d: expected nearest (0) or maps (1)",
		                      (int)def->method);
	int rc = build_check(def, err);
	if (rc != BSIM_OK)
		return rc;
	bsim_markov_def md = def->map;
	if (def->has_seed)
		md.seed = def->seed;
	md.part = def->parts > 0 ? def->part - 1 : 0;
	md.parts = def->parts;
	md.from = def->n_merge > 0 ? def->merge : NULL;
	md.n_from = def->n_merge > 0 ? def->n_merge : 0;
	/* flow entries in a job array: a round, one pass of the maps */
	res->round = def->round != 0;
	md.one_pass = res->round;
	md.passes_from = def->passes;
	res->pass = md.self_passes;
	res->n_bins = bsim_markov_bins_count(&md.bins);
	res->after_trials =
	        bsim_markov_def_after_start(&md) ? bsim_markov_def_after_trials(&md) : 0;
	bsim_markov_entries entries = {0};
	if (def->n_entries > 0) {
		if ((rc = bsim_markov_entries_load(def->entries, def->n_entries, &entries, err)) !=
		    BSIM_OK)
			return rc;
		md.entries = &entries;
	}
	bsim_markov_def_scope(&md, res->scope, sizeof res->scope);
	/* the experiment's trials are not the maps' (map.trials per bin) */
	bsim_experiment e;
	rc = bsim_experiment_load_seeded(def->experiment, def->sets, def->n_sets, def->grid,
	                                 def->n_grid, def->has_seed ? &def->seed : NULL, &e, err);
	if (rc != BSIM_OK) {
		bsim_markov_entries_free(&entries);
		return rc ? rc : BSIM_EINPUT;
	}
	res->n_groups = e.n_groups;
	int own = 0; /* maps built or reused here: a part's records */
	rc = build_groups(def, &e, &md, res, &own, err);
	if (rc == BSIM_OK)
		rc = build_name(def, res, err);
	if (rc == BSIM_OK && def->parts > 0)
		rc = bsim_markov_part_write(def->out, def->part, def->parts, res->run, res->n_maps,
		                            own, def->argc, def->argv, err);
	bsim_experiment_free(&e);
	bsim_markov_entries_free(&entries);
	if (rc != BSIM_OK)
		bsim_markov_build_result_free(res);
	return rc;
}
