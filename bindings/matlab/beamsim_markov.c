/* beamsim_markov: the Markov chain's walks' training fields or maps built,
 * a lattice predicted from them and the prediction validated against
 * direct simulation, as `beamsim markov build`, `predict` and `validate` do
 * them (beamsim/markov.h).
 *
 *   b = beamsim_markov('build', EXPERIMENT, 'out', DIR, NAME, VALUE, ...)
 *   p = beamsim_markov('predict', SCENE, 'map', DIR, NAME, VALUE, ...)
 *   v = beamsim_markov('validate', EXPERIMENT, 'map', DIR, 'out', DIR, ...)
 *
 * build's names: 'out' (the directory, required), 'method' ('nearest', the
 * default: the walks' training fields, 'train' their trials and 'k'; 'maps',
 * implied by any of the maps' names), 'trials' (single
 * gates per entry bin), 'start_trials' (of the start bin), 'after_start' (1, the default: the
 * gate after the start from each start trial's exit; 0: entry bins from the start on),
 * 'after_trials' (the first start trials continued there, default 8000; 0: every one), 'train'
 * (the training field's trials, 0: states uniform in each bin), 'crossings' (1, the default with a
 * training field: each bin counts the training field's crossings, topped up as 'per_crossing'
 * says; 0: 'trials' single gates a bin), 'per_crossing' (single gates a bin for each crossing
 * that entered it, at most 'trials'; default 5; 0: every bin 'trials'), 'bins' [P S D],
 * 'vmax' (m/s),
 * 'entries'
 * (a text or a cell of texts: gate_entries.csv paths, or 'self', 'self:N', 'flow', 'flow:N'),
 * 'seed', 'threads', 'backend', 'backend_opt', 'set', 'grid'. b.maps is a struct array, a map each
 * (group from 1, k [left right] N m/rad, key its files' name, how 'built' or 'reused').
 *
 * predict's: 'map' (a build: of the walks, then 'walks' and 'threads', or of
 * maps) or 'visits' (nearest-neighbour
 * walks over the visits kept there, as `markov predict --visits DIR`),
 * 'set', 'out', 'overwrite', 'walks'; with 'map': 'tol', 'gates' (true:
 * the distribution of gates visited; default: with 'out' only); with
 * 'visits': 'k', 'train', 'seed', 'threads'. p is what `markov predict
 * --json` prints, decoded by jsondecode, with p.p_time (time bins x 3:
 * end, side, stuck), p.time_bin (s) and p.p_loc_time.
 *
 * validate's: 'out' (required), 'map' or 'visits' (then 'k', 'train',
 * 'walks'), 'trials', 'seed', 'threads', 'set', 'grid', 'bootstrap',
 * 'resume', 'overwrite'. v is validate.json, decoded, its checks' group
 * from 1. */
#define _GNU_SOURCE /* open_memstream */

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bsim_mex.h"

enum {
	A_OUT,
	A_MAP,
	A_TRIALS,
	A_BINS,
	A_VMAX,
	A_ENTRIES,
	A_SEED,
	A_THREADS,
	A_BACKEND,
	A_BACKEND_OPT,
	A_SET,
	A_GRID,
	A_TOL,
	A_GATES,
	A_WALKS,
	A_OVERWRITE,
	A_BOOTSTRAP,
	A_RESUME,
	A_START_TRIALS,
	A_AFTER_START,
	A_TRAIN,
	A_CROSSINGS,
	A_PER_CROSSING,
	A_AFTER_TRIALS,
	A_VISITS,
	A_K,
	A_METHOD,
	N_ARGS
};
static const char *const arg_names[N_ARGS] = {
        "out",          "map",         "trials",  "bins",        "vmax",         "entries",
        "seed",         "threads",     "backend", "backend_opt", "set",          "grid",
        "tol",          "gates",       "walks",   "overwrite",   "bootstrap",    "resume",
        "start_trials", "after_start", "train",   "crossings",   "per_crossing", "after_trials",
        "visits",       "k",           "method"};

/* The names each subcommand takes, the others refused. */
static const int build_names[] = {A_OUT,          A_TRIALS,      A_BINS,      A_VMAX,
                                  A_ENTRIES,      A_SEED,        A_THREADS,   A_BACKEND,
                                  A_SET,          A_BACKEND_OPT, A_GRID,      A_START_TRIALS,
                                  A_AFTER_START,  A_TRAIN,       A_CROSSINGS, A_PER_CROSSING,
                                  A_AFTER_TRIALS, A_METHOD,      A_K};
static const int predict_names[] = {A_MAP,       A_SET,    A_TOL, A_GATES, A_WALKS, A_OUT,
                                    A_OVERWRITE, A_VISITS, A_K,   A_TRAIN, A_SEED,  A_THREADS};
static const int validate_names[] = {A_MAP,    A_OUT,  A_TRIALS,    A_SEED,   A_THREADS,
                                     A_SET,    A_GRID, A_BOOTSTRAP, A_RESUME, A_OVERWRITE,
                                     A_VISITS, A_K,    A_TRAIN,     A_WALKS};

typedef struct markov_call {
	bmx_pool pool;
	const mxArray *v[N_ARGS];
	bsim_override *sets, *opts_kv;
	int n_sets, n_opts_kv;
	bsim_grid_axis *grid;
	int n_grid;
	const char **entries;
	int n_entries;
	bsim_options opts;
	bsim_markov_build_result build;
	bsim_markov_predict_result predict;
	int built, predicted;
} markov_call;

/* The pairs after the path, each a name the subcommand takes. */
static int pairs(markov_call *c, const char *sub, const int *names, int n, int nrhs,
                 const mxArray *prhs[], bsim_error *err)
{
	if (bmx_pairs(nrhs, prhs, 2, arg_names, N_ARGS, c->v, err) != BSIM_OK)
		return BSIM_EINPUT;
	for (int i = 0; i < N_ARGS; i++) {
		int takes = 0;
		for (int k = 0; k < n; k++)
			takes |= names[k] == i;
		if (c->v[i] && !takes)
			return bsim_error_set(err, BSIM_EINPUT, "'%s': not an argument of '%s'",
			                      arg_names[i], sub);
	}
	return BSIM_OK;
}

/* 'set' and 'grid'. */
static int sets_grid(markov_call *c, bsim_error *err)
{
	if (bmx_overrides("set", c->v[A_SET], &c->pool, &c->sets, &c->n_sets, err) ||
	    (c->v[A_GRID] && bmx_grid("grid", c->v[A_GRID], &c->pool, &c->grid, &c->n_grid, err)))
		return err->code;
	return BSIM_OK;
}

/* 'entries': one text or a cell of them, each a kind (self, flow) or a
 * path. */
static int entries(markov_call *c, bsim_markov_def *def, bsim_error *err)
{
	const mxArray *a = c->v[A_ENTRIES];
	if (!a)
		return BSIM_OK;
	const size_t n = mxIsCell(a) ? mxGetNumberOfElements(a) : 1;
	c->entries = calloc(n ? n : 1, sizeof *c->entries);
	if (!c->entries)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	for (size_t i = 0; i < n; i++) {
		const mxArray *e = mxIsCell(a) ? mxGetCell(a, (mwIndex)i) : a;
		const char *text;
		int is_kind;
		if (!e || bmx_text("entries", e, &c->pool, &text, err) ||
		    bsim_markov_entries_kind(text, def, &is_kind, err))
			return e ? err->code
			         : bsim_error_set(err, BSIM_EINPUT, "'entries': expected texts");
		if (!is_kind)
			c->entries[c->n_entries++] = text;
	}
	return BSIM_OK;
}

/* 'bins' [P S D]: the library checks the counts. */
static int bins(const mxArray *a, bsim_markov_bins *b, bsim_error *err)
{
	if (!mxIsDouble(a) || mxIsComplex(a) || mxGetNumberOfElements(a) != 3)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "'bins': expected [P S D]: 1 to 64 bins of position, speed "
		                      "and direction, e.g. [4 4 3]");
	int *n[3] = {&b->n_pos, &b->n_speed, &b->n_dir};
	for (int i = 0; i < 3; i++) {
		const double x = mxGetPr(a)[i];
		if (!(x >= 1 && x <= 64) || x != (int)x)
			return bsim_error_set(err, BSIM_EINPUT,
			                      "'bins': expected [P S D]: 1 to 64 bins of position, "
			                      "speed and direction, e.g. [4 4 3]");
		*n[i] = (int)x;
	}
	return BSIM_OK;
}

static mxArray *build_struct(const bsim_markov_build_result *r, int trials)
{
	const int nearest = r->method == BSIM_MARKOV_METHOD_NEAREST;
	mxArray *s = mxCreateStructMatrix(1, 1, 0, NULL);
	static const char *const fields[] = {"group", "k", "key", "how"};
	mxArray *maps = mxCreateStructMatrix((mwSize)r->n_maps, 1, 4, (const char **)fields);
	for (int i = 0; i < r->n_maps; i++) {
		const bsim_markov_built *m = &r->maps[i];
		char key[32];
		snprintf(key, sizeof key, "%s_%016llx", nearest ? "visits" : "map",
		         (unsigned long long)m->key);
		bmx_set(maps, (mwIndex)i, "group", bmx_scalar(m->group + 1));
		bmx_set(maps, (mwIndex)i, "k", bmx_row(m->k, 2));
		bmx_set(maps, (mwIndex)i, "key", bmx_string(key));
		bmx_set(maps, (mwIndex)i, "how",
		        bmx_string(m->elsewhere ? "elsewhere"
		                   : m->copied  ? "copied"
		                   : m->cached  ? "reused"
		                                : "built"));
	}
	bmx_set(s, 0, "maps", maps);
	bmx_set(s, 0, "built", bmx_scalar(r->built));
	bmx_set(s, 0, "reused", bmx_scalar(r->reused));
	bmx_set(s, 0, "cpu_seconds", bmx_scalar(r->seconds));
	bmx_set(s, 0, "bins", bmx_scalar(r->n_bins));
	bmx_set(s, 0, "trials", bmx_scalar(trials));
	bmx_set(s, 0, "run", bmx_string(r->run));
	bmx_set(s, 0, "scope", bmx_string(r->scope));
	bmx_set(s, 0, "method", bmx_string(nearest ? "nearest" : "maps"));
	bmx_set(s, 0, "visits", bmx_scalar((double)r->visits));
	return s;
}

static int build(markov_call *c, const char *path, mxArray **out, bsim_error *err)
{
	bsim_markov_build_def def = bsim_markov_build_def_default();
	const char *backend = NULL, *method = NULL;
	long trials = 0, threads = 0, start_trials = 0, after_start = -1, train = -1,
	     crossings = -1, per_crossing = -1, after_trials = -1, k = 0;
	const mxArray *const *v = c->v;
	if (!v[A_OUT])
		return bsim_error_set(err, BSIM_EINPUT,
		                      "'build': 'out' (the map directory) is required");
	/* the method: as given, else maps if a name of theirs alone is */
	static const int maps_own[] = {A_TRIALS,    A_BINS,         A_VMAX,
	                               A_ENTRIES,   A_START_TRIALS, A_AFTER_START,
	                               A_CROSSINGS, A_PER_CROSSING, A_AFTER_TRIALS};
	const char *maps_only = NULL;
	for (size_t i = 0; !maps_only && i < sizeof maps_own / sizeof *maps_own; i++)
		if (v[maps_own[i]])
			maps_only = arg_names[maps_own[i]];
	if ((v[A_METHOD] && bmx_text("method", v[A_METHOD], &c->pool, &method, err)) ||
	    bsim_markov_build_method(method, maps_only, v[A_K] ? "k" : NULL, &def.method, err) ||
	    (v[A_K] && bmx_long("k", v[A_K], 1, 64, &k, err)))
		return err->code;
	if (bmx_text("out", v[A_OUT], &c->pool, &def.out, err) ||
	    (v[A_TRIALS] && bmx_long("trials", v[A_TRIALS], 1, 2147483647L, &trials, err)) ||
	    (v[A_BINS] && bins(v[A_BINS], &def.map.bins, err)) ||
	    (v[A_VMAX] && bmx_double("vmax", v[A_VMAX], &def.map.bins.v_max, err)) ||
	    (v[A_SEED] && bmx_seed("seed", v[A_SEED], &def.seed, err)) ||
	    (v[A_THREADS] && bmx_long("threads", v[A_THREADS], 1, 4096, &threads, err)) ||
	    (v[A_BACKEND] && bmx_text("backend", v[A_BACKEND], &c->pool, &backend, err)) ||
	    bmx_overrides("backend_opt", v[A_BACKEND_OPT], &c->pool, &c->opts_kv, &c->n_opts_kv,
	                  err) ||
	    bmx_backend(backend, c->opts_kv, c->n_opts_kv, &def.map.backend, &c->opts, err) ||
	    sets_grid(c, err) || entries(c, &def.map, err) ||
	    (v[A_START_TRIALS] &&
	     bmx_long("start_trials", v[A_START_TRIALS], 1, 1000000, &start_trials, err)) ||
	    (v[A_AFTER_START] &&
	     bmx_long("after_start", v[A_AFTER_START], 0, 1, &after_start, err)) ||
	    (v[A_TRAIN] && bmx_long("train", v[A_TRAIN], 0, 1000000, &train, err)) ||
	    (v[A_CROSSINGS] && bmx_long("crossings", v[A_CROSSINGS], 0, 1, &crossings, err)) ||
	    (v[A_PER_CROSSING] &&
	     bmx_long("per_crossing", v[A_PER_CROSSING], 0, 1000000, &per_crossing, err)) ||
	    (v[A_AFTER_TRIALS] &&
	     bmx_long("after_trials", v[A_AFTER_TRIALS], 0, 1000000, &after_trials, err)))
		return err->code;
	if (start_trials > 0) /* none: the default (self and flow entries: trials) */
		def.map.start_trials = (int)start_trials;
	if (after_start >= 0) /* none: the default (self and flow entries: 0) */
		def.map.after_start = (int)after_start;
	if (train >= 0) /* none: the default training field */
		def.map.train_trials = (int)train;
	if (crossings >= 0) /* none: the default, counted where a training field */
		def.map.train_crossings = (int)crossings;
	if (per_crossing >= 0) /* none: the default */
		def.map.trials_per_crossing = (int)per_crossing;
	if (after_trials >= 0) /* none: the default; 0: every start trial */
		def.map.after_trials = (int)after_trials;
	def.experiment = path;
	def.has_seed = v[A_SEED] != NULL;
	if (trials > 0)
		def.map.trials = (int)trials;
	def.map.threads = (int)threads;
	def.map.opts = &c->opts;
	def.entries = c->entries;
	def.n_entries = c->n_entries;
	def.sets = c->sets;
	def.n_sets = c->n_sets;
	def.grid = c->grid;
	def.n_grid = c->n_grid;
	/* the walks' training fields: train trials each, k, the same backend */
	def.nearest.backend = def.map.backend;
	def.nearest.opts = &c->opts;
	def.nearest.threads = (int)threads;
	if (train >= 0)
		def.nearest.trials = (int)train;
	if (k > 0)
		def.nearest.k = (int)k;
	if (bsim_markov_build_run(&def, &c->build, err) != BSIM_OK)
		return err->code;
	c->built = 1;
	*out = build_struct(&c->build, def.method == BSIM_MARKOV_METHOD_NEAREST ? def.nearest.trials
	                                                                        : def.map.trials);
	return BSIM_OK;
}

/* jsondecode(text): MATLAB's and Octave's own reading of the JSON. */
static int json_decode(mxArray *text, mxArray **out, bsim_error *err)
{
	if (mexCallMATLAB(1, out, 1, &text, "jsondecode") != 0)
		return bsim_error_set(err, BSIM_EFAIL, "jsondecode failed");
	mxDestroyArray(text);
	return BSIM_OK;
}

/* The prediction as markov predict --json prints it, decoded, with its
 * arrays beside. */
static int predict_struct(const char *path, const bsim_markov_predict_result *r, mxArray **out,
                          bsim_error *err)
{
	char *text = NULL;
	size_t len = 0;
	FILE *f = open_memstream(&text, &len);
	if (!f)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	bsim_markov_predict_json(f, path, r);
	if (fclose(f) != 0) {
		free(text);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	mxArray *s = NULL;
	int rc = json_decode(bmx_string(text), &s, err);
	free(text);
	if (rc != BSIM_OK)
		return rc;
	const bsim_markov_prediction *p = &r->p;
	const size_t bins = p->walks > 0 ? (size_t)p->n_time_bins : 0;
	mxArray *pt = mxCreateDoubleMatrix((mwSize)bins, 3, mxREAL);
	for (size_t b = 0; b < bins; b++)
		for (size_t k = 0; k < 3; k++)
			mxGetPr(pt)[k * bins + b] = p->p_time[b * 3 + k];
	bmx_set(s, 0, "p_time", pt);
	bmx_set(s, 0, "time_bin", bmx_scalar(p->walks > 0 ? p->time_bin : 0.0));
	double *loc;
	mxArray *pl = bmx_column(p->walks > 0 ? (size_t)p->n_locations : 0, &loc);
	for (int i = 0; p->walks > 0 && i < p->n_locations; i++)
		loc[i] = p->p_loc_time[i];
	bmx_set(s, 0, "p_loc_time", pl);
	*out = s;
	return BSIM_OK;
}

/* 'visits', 'k', 'train' and 'walks' into def (threads: c's 'threads'):
 * nearest-neighbour walks, over 'visits' or a build of the walks in 'map'
 * (*walking 1; 'walks' and 'threads' only); the maps' own names refused
 * beside them, and the walks' beside maps. */
static int nearest_args(markov_call *c, const char *sub, const char **visits,
                        bsim_markov_nearest_def *def, int *walking, bsim_error *err)
{
	const mxArray *const *v = c->v;
	if (!v[A_MAP] == !v[A_VISITS])
		return bsim_error_set(
		        err, BSIM_EINPUT,
		        "'%s': expected one of 'map' (the map directory) and 'visits' "
		        "(nearest-neighbour walks)",
		        sub);
	const int own[] = {A_K, A_TRAIN};
	for (int i = 0; i < 2 && v[A_MAP]; i++)
		if (v[own[i]])
			return bsim_error_set(err, BSIM_EINPUT, "'%s': for 'visits' only",
			                      arg_names[own[i]]);
	const char *map = NULL;
	bsim_markov_method method = BSIM_MARKOV_METHOD_NEAREST;
	if (v[A_MAP] && (bmx_text("map", v[A_MAP], &c->pool, &map, err) ||
	                 bsim_markov_dir_method(map, &method, err)))
		return err->code;
	*walking = method == BSIM_MARKOV_METHOD_NEAREST;
	if (!*walking)
		return BSIM_OK;
	long k = def->k, train = def->trials, threads = 0;
	if ((v[A_VISITS] && bmx_text("visits", v[A_VISITS], &c->pool, visits, err)) ||
	    (v[A_K] && bmx_long("k", v[A_K], 1, 64, &k, err)) ||
	    (v[A_TRAIN] && bmx_long("train", v[A_TRAIN], 1, 2147483647L, &train, err)) ||
	    (v[A_WALKS] && bmx_long("walks", v[A_WALKS], 1, 100000000L, &def->walks, err)) ||
	    (v[A_THREADS] && bmx_long("threads", v[A_THREADS], 1, 4096, &threads, err)))
		return err->code;
	def->k = (int)k;
	def->trials = (int)train;
	def->threads = (int)threads;
	return BSIM_OK;
}

static int predict(markov_call *c, const char *path, mxArray **out, bsim_error *err)
{
	bsim_markov_predict_def def = bsim_markov_predict_def_default();
	const mxArray *const *v = c->v;
	int walking = 0;
	if (nearest_args(c, "predict", &def.visits_dir, &def.nearest, &walking, err))
		return err->code;
	if (walking && (v[A_TOL] || v[A_GATES]))
		return bsim_error_set(err, BSIM_EINPUT, "'%s': for maps only",
		                      v[A_TOL] ? "tol" : "gates");
	if (v[A_VISITS] && v[A_SEED] && bmx_seed("seed", v[A_SEED], &def.nearest.seed, err))
		return err->code;
	if (v[A_MAP] && (v[A_SEED] || (!walking && v[A_THREADS])))
		return bsim_error_set(err, BSIM_EINPUT, "'%s': for 'visits' only",
		                      v[A_SEED] ? "seed" : "threads");
	if ((v[A_MAP] && bmx_text("map", v[A_MAP], &c->pool, &def.map_dir, err)) ||
	    sets_grid(c, err) || (v[A_TOL] && bmx_double("tol", v[A_TOL], &def.tol, err)) ||
	    (v[A_GATES] && bmx_flag("gates", v[A_GATES], &def.gates, err)) ||
	    (!walking && v[A_WALKS] &&
	     bmx_long("walks", v[A_WALKS], 0, 100000000L, &def.walks, err)) ||
	    (v[A_OUT] && bmx_text("out", v[A_OUT], &c->pool, &def.out, err)) ||
	    (v[A_OVERWRITE] && bmx_flag("overwrite", v[A_OVERWRITE], &def.overwrite, err)))
		return err->code;
	if (v[A_TOL] && !(def.tol > 0 && def.tol < 1))
		return bsim_error_set(
		        err, BSIM_EINPUT,
		        "'tol' %g: expected the probability left in the field at which "
		        "the solution stops, in (0, 1), e.g. 1e-12",
		        def.tol);
	def.scene = path;
	def.sets = c->sets;
	def.n_sets = c->n_sets;
	def.overwrite_option = "'overwrite', true";
	if (bsim_markov_predict_run(&def, &c->predict, err) != BSIM_OK)
		return err->code;
	c->predicted = 1;
	return predict_struct(path, &c->predict, out, err);
}

/* validate.json of dir, decoded, each check's group from 1. */
static int validation_struct(const char *dir, mxArray **out, bsim_error *err)
{
	char file[BSIM_PATH_MAX];
	snprintf(file, sizeof file, "%s/validate.json", dir);
	mxArray *name = bmx_string(file), *text = NULL;
	if (mexCallMATLAB(1, &text, 1, &name, "fileread") != 0)
		return bsim_error_set(err, BSIM_EFAIL, "%s: cannot be read", file);
	mxDestroyArray(name);
	int rc = json_decode(text, out, err);
	mxArray *checks = rc == BSIM_OK ? mxGetField(*out, 0, "checks") : NULL;
	for (size_t i = 0; checks && mxIsStruct(checks) && i < mxGetNumberOfElements(checks); i++) {
		mxArray *g = mxGetField(checks, (mwIndex)i, "group");
		if (g && mxIsDouble(g) && mxGetNumberOfElements(g) == 1)
			mxGetPr(g)[0] += 1;
	}
	return rc;
}

static int validate(markov_call *c, const char *path, mxArray **out, bsim_error *err)
{
	bsim_markov_validate_def def = bsim_markov_validate_def_default();
	const mxArray *const *v = c->v;
	long threads = 0, bootstrap = def.bootstrap;
	if (!v[A_OUT])
		return bsim_error_set(err, BSIM_EINPUT,
		                      "'validate': 'out' (the output directory) is required");
	int walking = 0;
	if (nearest_args(c, "validate", &def.visits_dir, &def.nearest, &walking, err))
		return err->code;
	if (!walking && v[A_WALKS])
		return bsim_error_set(err, BSIM_EINPUT, "'walks': for the walks only");
	if ((v[A_MAP] && bmx_text("map", v[A_MAP], &c->pool, &def.map_dir, err)) ||
	    bmx_text("out", v[A_OUT], &c->pool, &def.out, err) || sets_grid(c, err) ||
	    (v[A_TRIALS] && bmx_long("trials", v[A_TRIALS], 1, 2147483647L, &def.trials, err)) ||
	    (v[A_SEED] && bmx_seed("seed", v[A_SEED], &def.seed, err)) ||
	    (v[A_THREADS] && bmx_long("threads", v[A_THREADS], 1, 4096, &threads, err)) ||
	    (v[A_BOOTSTRAP] &&
	     bmx_long("bootstrap", v[A_BOOTSTRAP], 0, 1000000, &bootstrap, err)) ||
	    (v[A_RESUME] && bmx_flag("resume", v[A_RESUME], &def.resume, err)) ||
	    (v[A_OVERWRITE] && bmx_flag("overwrite", v[A_OVERWRITE], &def.overwrite, err)))
		return err->code;
	def.experiment = path;
	def.has_seed = v[A_SEED] != NULL;
	def.threads = (int)threads;
	def.bootstrap = (int)bootstrap;
	def.resume_option = "'resume', true";
	def.overwrite_option = "'overwrite', true";
	def.sets = c->sets;
	def.n_sets = c->n_sets;
	def.grid = c->grid;
	def.n_grid = c->n_grid;
	bsim_markov_validation val;
	int rc = bsim_markov_validate(&def, &val, err);
	bsim_markov_validation_free(&val);
	return rc == BSIM_OK ? validation_struct(def.out, out, err) : rc;
}

static int markov(markov_call *c, int nrhs, const mxArray *prhs[], mxArray **out, bsim_error *err)
{
	const char *sub = NULL, *path = NULL;
	if (nrhs < 2 || bmx_text("the first argument", prhs[0], &c->pool, &sub, err))
		return bsim_error_set(err, BSIM_EINPUT,
		                      "expected 'build', 'predict' or 'validate', then a file and "
		                      "name-value pairs");
	if (strcmp(sub, "build") == 0 || strcmp(sub, "validate") == 0) {
		const int is_build = sub[0] == 'b';
		if (pairs(c, sub, is_build ? build_names : validate_names,
		          is_build ? (int)(sizeof build_names / sizeof *build_names)
		                   : (int)(sizeof validate_names / sizeof *validate_names),
		          nrhs, prhs, err) ||
		    bmx_text("experiment", prhs[1], &c->pool, &path, err))
			return err->code;
		return is_build ? build(c, path, out, err) : validate(c, path, out, err);
	}
	if (strcmp(sub, "predict") == 0) {
		if (pairs(c, sub, predict_names,
		          (int)(sizeof predict_names / sizeof *predict_names), nrhs, prhs, err) ||
		    bmx_text("scene", prhs[1], &c->pool, &path, err))
			return err->code;
		return predict(c, path, out, err);
	}
	return bsim_error_set(err, BSIM_EINPUT, "'%s': expected 'build', 'predict' or 'validate'",
	                      sub);
}

void mexFunction(int nlhs, mxArray *plhs[], int nrhs, const mxArray *prhs[])
{
	(void)nlhs;
	markov_call c;
	memset(&c, 0, sizeof c);
	bsim_error err;
	bsim_error_clear(&err);
	mxArray *out = NULL;
	int rc = markov(&c, nrhs, prhs, &out, &err);
	if (c.built)
		bsim_markov_build_result_free(&c.build);
	if (c.predicted)
		bsim_markov_predict_result_free(&c.predict);
	free(c.entries);
	bmx_grid_free(c.grid, c.n_grid);
	bmx_pool_free(&c.pool);
	if (rc != BSIM_OK)
		bmx_fail(&err);
	plhs[0] = out;
}
