/* The single-gate maps of a lattice (beamsim/markov.h): one per stiffness
 * pair its gates use, each read from the map directory when a map with
 * the same key is there and simulated into it otherwise (build), or read
 * only (load). */
#define _POSIX_C_SOURCE 200809L

#include "analysis/markov_internal.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "beamsim/backend_registry.h"
#include "store/outdir.h"
#include "store/part_dir.h"
#include "store/session.h"
#include "beamsim/limits.h"

bsim_markov_def bsim_markov_def_default(void)
{
	return (bsim_markov_def){.bins = bsim_markov_bins_default(),
	                         .trials = 50,
	                         .start_trials = BSIM_MARKOV_START_TRIALS,
	                         .train_trials = BSIM_MARKOV_TRAIN_TRIALS,
	                         .train_crossings = -1,
	                         .trials_per_crossing = BSIM_MARKOV_TRIALS_PER_CROSSING,
	                         .after_start = 1,
	                         .after_trials = -1,
	                         .seed = 1};
}

/* The chain's lattice: its side boundary at the field's edge and its end
 * at the last row's top edge, where the chain's absorbing states are. */
int bsim_markov_check_lattice(const bsim_scene *s, bsim_error *err)
{
	if (!s->has_lattice)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: not a gate lattice: the Markov chain is built over a "
		                      "lattice's gates (lattice: in the scene)",
		                      s->path[0] ? s->path : s->name);
	const bsim_lattice_def *l = &s->lattice;
	double edge = 0.5 * l->width * l->columns, top = l->depth * l->rows;
	if (fabs(s->side_x - edge) > 1e-9 * edge)
		return bsim_error_set(
		        err, BSIM_EINPUT,
		        "%s: termination.side_x: the chain needs the side boundary at "
		        "the field's edge, %g m, got %g m",
		        s->path[0] ? s->path : s->name, edge, s->side_x);
	if (fabs(s->success_y - top) > 1e-9 * top)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: termination.success_y: the chain needs the end at the "
		                      "last row's top edge, %g m, got %g m",
		                      s->path[0] ? s->path : s->name, top, s->success_y);
	return BSIM_OK;
}

static int map_init(bsim_markov_map *m, const bsim_scene *lattice, const bsim_markov_def *def,
                    const bsim_backend *be, const bsim_options *opts, const double k[2],
                    bsim_error *err)
{
	memset(m, 0, sizeof *m);
	m->k[0] = k[0];
	m->k[1] = k[1];
	m->n_bins = bsim_markov_bins_count(&def->bins);
	m->trials = def->trials;
	m->start_trials = bsim_markov_def_start_trials(def);
	m->of_crossings = bsim_markov_def_crossings(def);
	m->per_crossing = m->of_crossings ? def->trials_per_crossing : 0;
	m->key_text = bsim_markov_key_text(lattice, def, be, opts, k);
	if (!m->key_text)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	m->key = bsim_markov_key(m->key_text);
	return BSIM_OK;
}

static int def_check(const bsim_markov_def *def, bsim_error *err)
{
	const bsim_markov_bins *b = &def->bins;
	bsim_error why;
	if (bsim_markov_bins_check(b, &why) != BSIM_OK)
		return bsim_error_set(err, BSIM_EINPUT, "bins: %s", why.msg);
	if (!(b->v_max >= 0) || !isfinite(b->v_max))
		return bsim_error_set(err, BSIM_EINPUT,
		                      "bins: v_max %g: expected a speed > 0 in m/s (0: from the "
		                      "propulsion)",
		                      b->v_max);
	if (def->self_entries && (def->entries || def->self_entries > 2 || def->self_passes < 0 ||
	                          def->self_passes > BSIM_MARKOV_SELF_PASSES_MAX))
		return bsim_error_set(err, BSIM_EINPUT,
		                      "entries: self-consistent entries take 0 to %d passes and no "
		                      "observed entries, got %d passes%s",
		                      BSIM_MARKOV_SELF_PASSES_MAX, def->self_passes,
		                      def->entries ? " and observed entries" : "");
	/* A self-consistent map's passes are its own: spread whole. A flow
	 * map's pass p + 1 needs every map's pass p: its parts must meet after
	 * each pass (pass_exchange), or make one pass a round (one_pass). */
	if (def->parts > 1 && def->self_entries == 2 && !def->pass_exchange && !def->one_pass)
		return bsim_error_set(
		        err, BSIM_EINPUT,
		        "entries: flow-weighted maps (flow or flow:N) over parts need "
		        "each pass's parts to meet (under mpirun) or one pass a "
		        "round of parts (--shard with --passes)");
	if (def->parts > 1 && (def->part < 0 || def->part >= def->parts))
		return bsim_error_set(err, BSIM_EINPUT, "part %d of %d: expected 0 to %d",
		                      def->part, def->parts, def->parts - 1);
	if (def->trials < 1 || def->trials > 1000000)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "trials: expected 1 to 1000000 per bin, got %d", def->trials);
	if (def->train_trials < 0 || def->train_trials > 1000000)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "training trials: expected 0 to 1000000, got %d",
		                      def->train_trials);
	if (def->start_trials > 1000000)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "start trials: expected 1 to 1000000, got %d",
		                      def->start_trials);
	const double units = (double)(bsim_markov_bins_count(b) - 1) * def->trials +
	                     bsim_markov_def_start_trials(def);
	if (units > (double)BSIM_MARKOV_MAX_UNITS)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "bins and trials: %d entry bins x %d trials (the start's %d) "
		                      "make %.0f single gates a map, more than %.0f; expected "
		                      "fewer bins or trials",
		                      bsim_markov_bins_count(b) - 1, def->trials,
		                      bsim_markov_def_start_trials(def), units,
		                      (double)BSIM_MARKOV_MAX_UNITS);
	if (def->train_crossings < -1 || def->train_crossings > 1)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "crossings: expected -1 (where a training field), 0 or 1, "
		                      "got %d",
		                      def->train_crossings);
	if (def->after_trials < -1 || def->after_trials > 1000000)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "start trials continued after the start: expected 0 (every "
		                      "one) to 1000000, got %d",
		                      def->after_trials);
	/* set where nothing continues them, it would be ignored without a word */
	if (def->after_trials >= 0 && !bsim_markov_def_after_start(def))
		return bsim_error_set(err, BSIM_EINPUT,
		                      "start trials continued after the start (%d): maps without "
		                      "the gate after the start (%s) have none to continue",
		                      def->after_trials,
		                      def->self_entries ? "self or flow entries" : "after_start 0");
	if (def->trials_per_crossing < 0 || def->trials_per_crossing > 1000000)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "trials per crossing: expected 0 to 1000000, got %d",
		                      def->trials_per_crossing);
	if (def->train_crossings == 1 && !bsim_markov_def_trains(def))
		return bsim_error_set(err, BSIM_EINPUT,
		                      "crossings: a map counts a training field's crossings only "
		                      "with a training field (training trials > 0, got %d) and "
		                      "neither observed, self nor flow entries",
		                      def->train_trials);
	/* The passes' exits are kept and pooled per trial of every bin alike. */
	if (def->self_entries && bsim_markov_def_start_trials(def) != def->trials)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "start trials: self-consistent and flow entries take the "
		                      "start bin's trials equal to every bin's (%d), got %d",
		                      def->trials, def->start_trials);
	return BSIM_OK;
}

const char *bsim_markov_def_scope(const bsim_markov_def *def, char *buf, size_t size)
{
	static const char *const each_part = "docs/markov.md, \"What each part does\"";
	const bsim_markov_def d0 = bsim_markov_def_default();
	/* a def read back from markov.json names its entries in entries_id */
	const char *id = def->entries_id;
	if (def->self_entries == 2 || strncmp(id, "flow ", 5) == 0) {
		snprintf(buf, size,
		         "flow-weighted entries: these maps hold for this lattice's layout only "
		         "(its hash is in their keys)");
		return buf;
	}
	if (def->self_entries == 1 || strncmp(id, "self ", 5) == 0) {
		snprintf(buf, size,
		         "self-consistent entries: measured above TV 0.05 on layouts the maps were "
		         "not built on (%s)",
		         each_part);
		return buf;
	}
	if (def->entries || id[0]) {
		snprintf(buf, size,
		         "entries observed in sweeps: the maps hold for layouts like the sweeps' "
		         "(those of a random field of the gate kinds, as the default's training "
		         "field, were measured as close; docs/markov.md, \"A training field\")");
		return buf;
	}
	/* The default method's parts, each measured without the others. */
	char part[4][64] = {"", "", "", ""};
	if (!bsim_markov_def_trains(def))
		snprintf(part[0], sizeof part[0], "states uniform in each bin (no training field)");
	else if (def->train_trials < d0.train_trials)
		snprintf(part[0], sizeof part[0], "%d training trials (the default %d)",
		         def->train_trials, d0.train_trials);
	if (bsim_markov_bins_count(&def->bins) < bsim_markov_bins_count(&d0.bins))
		snprintf(part[1], sizeof part[1], "%d,%d,%d bins (the default %d,%d,%d)",
		         def->bins.n_pos, def->bins.n_speed, def->bins.n_dir, d0.bins.n_pos,
		         d0.bins.n_speed, d0.bins.n_dir);
	if (bsim_markov_def_start_trials(def) < d0.start_trials)
		snprintf(part[2], sizeof part[2], "%d start trials (the default %d)",
		         bsim_markov_def_start_trials(def), d0.start_trials);
	if (!def->after_start)
		snprintf(part[3], sizeof part[3], "no gate after the start");
	else if (bsim_markov_def_after_trials(def) <
	         (BSIM_MARKOV_AFTER_TRIALS < bsim_markov_def_start_trials(def)
	                  ? BSIM_MARKOV_AFTER_TRIALS
	                  : bsim_markov_def_start_trials(def)))
		snprintf(part[3], sizeof part[3], "%d start trials continued (the default %d)",
		         bsim_markov_def_after_trials(def), BSIM_MARKOV_AFTER_TRIALS);
	char list[4 * 64 + 8] = "";
	size_t len = 0;
	for (int k = 0; k < 4; k++)
		if (part[k][0])
			len += (size_t)snprintf(list + len, sizeof list - len, "%s%s",
			                        len ? ", " : "", part[k]);
	if (!len) /* the default method, or finer */
		snprintf(buf, size,
		         "maps of entry bins: measured beyond TV 0.05 on 7 of 40 fields, columns "
		         "and "
		         "a random field of a physics they were not chosen on among them, where "
		         "the nearest-neighbour walks (markov build's default) were within 0.05 "
		         "on all 40 (docs/markov.md, \"A kernel over exact states\")");
	else
		snprintf(buf, size,
		         "maps with %s: measured less accurate than with the maps' defaults on "
		         "layouts they were not built on (%s)",
		         list, each_part);
	return buf;
}

void bsim_markov_set_free(bsim_markov_set *s)
{
	if (!s)
		return;
	for (int i = 0; i < s->n; i++) {
		free(s->maps[i].key_text);
		bsim_markov_counts_free(&s->maps[i]);
		free(s->maps[i].bin_first);
		free(s->maps[i].hold_exit);
		free(s->maps[i].hold_steps);
	}
	for (int i = 0; s->next && i < s->n * s->n; i++) {
		free(s->next[i].exit);
		free(s->next[i].steps);
	}
	free(s->next);
	free(s->maps);
	memset(s, 0, sizeof *s);
}

/* A map just written into the session's stage joins the directory's set
 * at once, so a build stopped or killed later keeps it; the stage is made
 * again for the next. */
static int map_commit(bsim_session *ss, bsim_error *err)
{
	if (bsim_outdir_add(ss->od, "markov build", err) != BSIM_OK)
		return BSIM_EFAIL;
	if (mkdir(ss->stage, 0777) != 0 && errno != EEXIST)
		return bsim_error_set(err, BSIM_EFAIL, "%s: cannot create: %s", ss->stage,
		                      strerror(errno));
	return BSIM_OK;
}

/* A job array's round of flow-weighted maps that makes pass out->pass,
 * before the last: a part simulates its maps' pass into stage (the passes
 * before read from def->passes_from); a merge copies every map's passes
 * up to it, the earlier ones from def->passes_from, that one from the
 * part that made it. No final map. */
static int round_fill(const bsim_scene *lattice, const bsim_markov_def *def, const bsim_backend *be,
                      const bsim_options *opts, bsim_markov_set *out, const char *stage,
                      bsim_error *err)
{
	const int n = out->n;
	int rc = BSIM_OK;
	if (def->n_from > 0) {
		const char **dirs = malloc((size_t)(def->n_from + 1) * sizeof *dirs);
		if (!dirs)
			return bsim_error_set(err, BSIM_EFAIL, "out of memory");
		memcpy(dirs, def->from, (size_t)def->n_from * sizeof *dirs);
		dirs[def->n_from] = def->passes_from;
		for (int i = 0; i < n && rc == BSIM_OK; i++) {
			rc = bsim_markov_self_copy(lattice, def, be, opts, &out->maps[i], out->pass,
			                           dirs, def->n_from + 1, stage, err);
			out->maps[i].copied = 1;
			out->copied++;
		}
		free(dirs);
		return rc;
	}
	char *have = calloc((size_t)n, 1);
	if (!have)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	long total = 0, done = 0;
	int own = 0;
	for (int i = 0; i < n; i++)
		if (!out->maps[i].elsewhere) {
			total += bsim_markov_map_units(&out->maps[i]);
			own++;
		}
	clock_t c0 = clock();
	rc = bsim_markov_flow_simulate(lattice, def, be, opts, out->maps, n, have, def->passes_from,
	                               stage, &done, total, err);
	out->seconds = (double)(clock() - c0) / CLOCKS_PER_SEC;
	if (rc == BSIM_OK)
		out->built = own;
	free(have);
	return rc;
}

/* The path in dir of the gate after the start of maps a and k, of a's
 * first `after` start trials: its file `what` ("csv" or "cost"). */
static void next_path(char *buf, size_t size, const char *dir, const bsim_markov_map *a,
                      const bsim_markov_map *k, int after, const char *what)
{
	char name[96];
	bsim_markov_next_name(name, sizeof name, a, k, after, what);
	snprintf(buf, size, "%s/%s", dir, name);
}

/* The single gates of the gates after the start that dir does not hold,
 * of the start maps this process builds. */
static long next_units_missing(const bsim_markov_set *set, const bsim_markov_def *def,
                               const char *dir)
{
	const int after = bsim_markov_def_after_trials(def);
	long units = 0;
	for (int a = 0; a < set->n; a++) {
		int missing = 0;
		for (int k = 0; k < set->n && !set->maps[a].elsewhere; k++) {
			char path[BSIM_PATH_MAX];
			struct stat st;
			next_path(path, sizeof path, dir, &set->maps[a], &set->maps[k], after,
			          "csv");
			missing += lstat(path, &st) != 0;
		}
		units += missing ? bsim_markov_next_units(after, missing) : 0;
	}
	return units;
}

/* The gates after the start of out's maps (def->after_start), every start
 * map continued in a gate of every map: read from dir where there; in a
 * merge, from the part that holds it (written into the stage); with a
 * session, the others simulated into its stage, a start map's at once,
 * and committed; without, the first missing is an error. A part makes
 * those of its own start maps. */
static int next_fill(const bsim_scene *lattice, const bsim_markov_def *def, const bsim_backend *be,
                     const bsim_options *opts, const char *dir, bsim_session *ss,
                     bsim_markov_set *out, markov_run *const *start_runs, long *done, long total,
                     bsim_error *err)
{
	const int n = out->n;
	const char *stage = ss ? ss->stage : NULL;
	out->next = calloc((size_t)n * n, sizeof *out->next);
	bsim_markov_next **todo = malloc((size_t)n * sizeof *todo);
	const bsim_markov_map **gate = malloc((size_t)n * sizeof *gate);
	int rc = out->next && todo && gate ? BSIM_OK
	                                   : bsim_error_set(err, BSIM_EFAIL, "out of memory");
	for (int a = 0; a < n && rc == BSIM_OK; a++) {
		const bsim_markov_map *sm = &out->maps[a];
		int nt = 0;
		for (int k = 0; k < n && rc == BSIM_OK; k++) {
			bsim_markov_next *x = &out->next[(size_t)a * n + k];
			x->start = a;
			x->gate = k;
			x->trials = bsim_markov_def_after_trials(def);
			if ((x->elsewhere = sm->elsewhere))
				continue;
			int got = bsim_markov_next_read(dir, x, sm, &out->maps[k], err);
			for (int j = 0; got == 0 && j < def->n_from; j++)
				if ((got = bsim_markov_next_read(def->from[j], x, sm, &out->maps[k],
				                                 err)) > 0)
					x->copied = 1;
			char path[BSIM_PATH_MAX];
			next_path(path, sizeof path, dir, sm, &out->maps[k], x->trials, "csv");
			if (got < 0)
				rc = BSIM_EINPUT;
			else if (got > 0 && x->copied) {
				rc = bsim_markov_next_write(stage, x, sm, &out->maps[k], err);
				if (rc == BSIM_OK)
					rc = map_commit(ss, err);
			} else if (got > 0) {
				x->cached = 1;
				out->next_reused++;
			} else if (def->n_from > 0)
				rc = bsim_error_set(
				        err, BSIM_EINPUT,
				        "no part holds %s, the gate after the start: the "
				        "parts are of another build, or one is missing",
				        path);
			else if (!stage)
				rc = bsim_error_set(
				        err, BSIM_EINPUT,
				        "%s: absent: the gate after the start (k = %g, %g N m/rad, "
				        "then k = %g, %g N m/rad) of maps built with after_start "
				        "1: "
				        "beamsim markov build writes it",
				        path, sm->k[0], sm->k[1], out->maps[k].k[0],
				        out->maps[k].k[1]);
			else {
				todo[nt] = x;
				gate[nt++] = &out->maps[k];
			}
		}
		if (rc != BSIM_OK || nt == 0)
			continue;
		rc = def->stop && *def->stop
		             ? BSIM_ESTOPPED
		             : bsim_markov_next_simulate(lattice, def, be, opts, sm, start_runs[a],
		                                         gate, todo, nt, done, total, err);
		for (int i = 0; i < nt && rc == BSIM_OK; i++) {
			out->seconds += todo[i]->seconds;
			rc = bsim_markov_next_write(stage, todo[i], sm, gate[i], err);
		}
		if (rc == BSIM_OK)
			rc = map_commit(ss, err);
		if (rc == BSIM_OK)
			out->next_built += nt;
	}
	free(todo);
	free(gate);
	return rc;
}

/* The maps of lattice's pairs: read from dir where there; with a session,
 * the others simulated into its stage and committed one by one (def->stop
 * is looked at between single gates); without, the first missing is an
 * error. */
static int set_fill(const bsim_scene *lattice, const bsim_markov_def *given, const char *dir,
                    bsim_session *ss, bsim_markov_set *out, bsim_error *err)
{
	/* the speed range of this lattice's physics: in every key and bin */
	bsim_markov_def resolved = *given;
	resolved.bins.v_max = bsim_markov_bins_v_max(&given->bins, lattice);
	const bsim_markov_def *def = &resolved;
	const char *stage = ss ? ss->stage : NULL;
	const bsim_backend *be = def->backend ? def->backend : bsim_backend_default();
	const bsim_options none = {0};
	const bsim_options *opts = def->opts ? def->opts : &none;
	double(*pairs)[2] = NULL;
	int n = bsim_markov_lattice_pairs(lattice, &pairs);
	if (n < 0)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	out->def = *def;
	out->maps = calloc((size_t)n, sizeof *out->maps);
	if (!out->maps) {
		free(pairs);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	out->n = n;
	int rc = BSIM_OK;
	long total = 0, done = 0;
	char *have = calloc((size_t)n, 1);
	int *src = calloc((size_t)n, sizeof *src); /* a copied map's part: from[src[i]] */
	/* the start bin's single gates of each map simulated now, for the
	 * gate after the start (NULL: run again from the map's seeds) */
	markov_run **start_runs = calloc((size_t)n, sizeof *start_runs);
	if (!have || !src || !start_runs)
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	for (int i = 0; i < n && rc == BSIM_OK; i++) {
		rc = map_init(&out->maps[i], lattice, def, be, opts, pairs[i], err);
		if (def->parts > 1 && (def->part_first + i) % def->parts != def->part)
			out->maps[i].elsewhere = 1; /* another part's */
	}
	/* A job array's round of flow-weighted maps: one pass; one before the
	 * last makes no final map. */
	const int round = def->self_entries == 2 && def->one_pass && stage;
	out->pass = def->self_passes;
	if (round && rc == BSIM_OK &&
	    (out->pass = bsim_markov_flow_round(lattice, def, be, opts, out->maps, n,
	                                        def->passes_from, err)) < 0)
		rc = BSIM_EINPUT;
	const int made = round && rc == BSIM_OK && out->pass < def->self_passes;
	if (made) {
		rc = round_fill(lattice, def, be, opts, out, stage, err);
		if (rc == BSIM_OK && (out->built || out->copied)) /* else nothing staged */
			rc = map_commit(ss, err);
	}
	for (int i = 0; i < n && rc == BSIM_OK && !made; i++) {
		bsim_markov_map *m = &out->maps[i];
		if (m->elsewhere)
			continue;
		int got = bsim_markov_map_read(dir, m, err);
		/* A spread build's merge: the map from the part that built it. */
		for (int j = 0; got == 0 && j < def->n_from; j++)
			if ((got = bsim_markov_map_read(def->from[j], m, err)) > 0)
				m->copied = 1, src[i] = j;
		if (got > 0 && m->copied && !m->hold_exit)
			rc = bsim_error_set(err, BSIM_EINPUT,
			                    "%s: the map for k = %g, %g N m/rad has no holding "
			                    "times: not a part of this build",
			                    dir, m->k[0], m->k[1]);
		else if (got == 0 && def->n_from > 0)
			rc = bsim_error_set(err, BSIM_EINPUT,
			                    "no part holds the map for k = %g, %g N m/rad (key "
			                    "%016llx): the parts are of another build, or one is "
			                    "missing",
			                    m->k[0], m->k[1], (unsigned long long)m->key);
		if (rc != BSIM_OK)
			break;
		if (got > 0 && stage && !m->hold_exit) {
			/* built before holding times were kept: simulated again
			 * (the same seeds: the same counts) with them */
			bsim_markov_counts_free(m);
			m->cost = 0.0;
			m->steps = 0;
			got = 0;
		}
		if (got < 0)
			rc = BSIM_EINPUT;
		else if (got && !m->copied)
			have[i] = m->cached = 1, out->reused++;
		else if (got)
			out->copied++;
		else if (!stage) {
			/* a map is used only where its whole key matches: say what
			 * differs from the nearest one there */
			char near[700];
			bsim_markov_key_nearest(dir, "map_", m->key_text, near, sizeof near);
			rc = bsim_error_set(
			        err, BSIM_EINPUT,
			        "%s: no map for k = %g, %g N m/rad with this scene's physics "
			        "and the map's settings (key %016llx)%s%s: beamsim markov build "
			        "writes it",
			        dir, m->k[0], m->k[1], (unsigned long long)m->key,
			        near[0] ? "; " : "", near);
		} else
			total += bsim_markov_map_units(m) *
			         (def->self_entries == 1 ? bsim_markov_self_passes_left(
			                                           lattice, def, be, opts, m, dir) +
			                                           1
			          : def->self_entries == 2 ? def->self_passes + 1
			                                   : 1);
	}
	/* the gates after the start to simulate, counted in the progress */
	if (rc == BSIM_OK && bsim_markov_def_after_start(def) && stage && !made && def->n_from == 0)
		total += next_units_missing(out, def, dir);
	int to_build = made ? 0 : n - out->reused - out->copied;
	for (int i = 0; i < n && !made; i++)
		to_build -= out->maps[i].elsewhere;
	/* The training field, run only when a map is to be simulated here:
	 * its entries the states of every map this set builds. */
	bsim_markov_entries train = {0};
	markov_crossings cx = {0};
	const int crossings = bsim_markov_def_crossings(def);
	bsim_markov_def with_train;
	double train_share = 0.0;  /* a built map's part of the field's CPU, s */
	long long train_steps = 0; /* and of its time steps */
	if (rc == BSIM_OK && stage && !made && to_build > 0 && bsim_markov_def_trains(def)) {
		clock_t c0 = clock();
		rc = bsim_markov_train_run(lattice, def, be, opts, &train, crossings ? &cx : NULL,
		                           &train_steps, err);
		train_share = (double)(clock() - c0) / CLOCKS_PER_SEC / to_build;
		train_steps /= to_build;
		with_train = *def;
		with_train.entries = &train;
		def = &with_train;
		/* the bins hold the crossings: only the rest is simulated */
		for (int i = 0; i < n && rc == BSIM_OK && crossings; i++) {
			bsim_markov_map *m = &out->maps[i];
			if (have[i] || m->elsewhere || m->copied)
				continue;
			total -= bsim_markov_map_units(m);
			const long placed = bsim_markov_crossings_layout(m, &cx);
			if (placed < 0)
				rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
			total += bsim_markov_map_units(m) - placed;
		}
	}
	/* Flow-weighted entries: every map's passes at once, the lattice's
	 * chain weighting each pass's states. Parts that meet after each pass
	 * all take part, those with no map of this lattice too. */
	const int flow = def->self_entries == 2 && stage && rc == BSIM_OK &&
	                 (to_build > 0 || (def->parts > 1 && def->pass_exchange));
	if (flow)
		rc = bsim_markov_flow_simulate(lattice, def, be, opts, out->maps, n, have,
		                               round ? def->passes_from : dir, stage, &done, total,
		                               err);
	for (int i = 0; i < n && rc == BSIM_OK && stage && !made; i++) {
		bsim_markov_map *m = &out->maps[i];
		if (have[i] || m->elsewhere)
			continue;
		if (m->copied) {
			/* read from a part: written again as it was, with its
			 * passes' maps and exits when built in passes */
			const char *dirs[2] = {def->from[src[i]], round ? def->passes_from : NULL};
			if (def->self_entries)
				rc = bsim_markov_self_copy(lattice, def, be, opts, m,
				                           def->self_passes, dirs, 2, stage, err);
			if (rc == BSIM_OK)
				rc = bsim_markov_map_write(stage, m, &def->bins, err);
			if (rc == BSIM_OK)
				rc = map_commit(ss, err);
			continue;
		}
		clock_t c0 = clock();
		markov_run *runs = NULL;
		if (!flow && !def->self_entries && bsim_markov_def_after_start(def) &&
		    !(runs = malloc((size_t)bsim_markov_map_units(m) * sizeof *runs)))
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
		else
			rc = flow                      ? BSIM_OK
			     : def->stop && *def->stop ? BSIM_ESTOPPED
			     : def->self_entries
			             ? bsim_markov_self_simulate(lattice, def, be, opts, m, dir,
			                                         stage, &done, total, err)
			             : bsim_markov_map_simulate_runs(lattice, def, be, opts, m,
			                                             NULL, crossings ? &cx : NULL,
			                                             runs, &done, total, err);
		if (runs && rc == BSIM_OK) { /* the start bin's come first */
			markov_run *kept = realloc(runs, (size_t)m->start_trials * sizeof *runs);
			start_runs[i] = kept ? kept : runs;
		} else
			free(runs);
		if (!flow) /* else the CPU time of its passes */
			m->seconds = (double)(clock() - c0) / CLOCKS_PER_SEC + train_share;
		m->steps += train_steps;
		/* with self or flow entries, m->cost holds what the passes
		 * reused from the cache cost */
		m->cost = m->seconds + (def->self_entries ? m->cost : 0.0);
		out->seconds += m->seconds;
		if (rc == BSIM_OK)
			rc = bsim_markov_map_write(stage, m, &def->bins, err);
		if (rc == BSIM_OK)
			rc = map_commit(ss, err);
		if (rc == BSIM_OK)
			out->built++;
	}
	if (rc == BSIM_OK && bsim_markov_def_after_start(def) && !made)
		rc = next_fill(lattice, def, be, opts, dir, ss, out, start_runs, &done, total, err);
	if (rc == BSIM_ESTOPPED && made)
		bsim_error_set(err, BSIM_ESTOPPED, "stopped in pass %d; nothing of it is kept",
		               out->pass);
	else if (rc == BSIM_ESTOPPED)
		bsim_error_set(err, BSIM_ESTOPPED,
		               "stopped after %d of the %d maps to build; those are kept in %s",
		               out->built, to_build, dir);
	bsim_markov_entries_free(&train);
	bsim_markov_crossings_free(&cx);
	for (int i = 0; start_runs && i < n; i++)
		free(start_runs[i]);
	free(start_runs);
	free(have);
	free(src);
	free(pairs);
	if (rc != BSIM_OK)
		bsim_markov_set_free(out);
	return rc;
}

int bsim_markov_build(const bsim_scene *lattice, const bsim_markov_def *def, const char *dir,
                      bsim_markov_set *out, bsim_error *err)
{
	memset(out, 0, sizeof *out);
	int rc = bsim_markov_check_lattice(lattice, err);
	if (rc == BSIM_OK)
		rc = def_check(def, err);
	if (rc != BSIM_OK)
		return rc;
	if (def->n_from > 0) {
		/* every part of one spread build, each once */
		bsim_sweep_dir_part *parts = calloc((size_t)def->n_from, sizeof *parts);
		if (!parts)
			return bsim_error_set(err, BSIM_EFAIL, "out of memory");
		rc = bsim_part_dir_check(def->from, def->n_from, "markov build", NULL, parts, err);
		for (int j = 0; j < def->n_from; j++)
			bsim_sweep_dir_part_free(&parts[j]);
		free(parts);
		if (rc != BSIM_OK)
			return rc;
	}
	for (int j = 0; j < def->n_from; j++) {
		int has_manifest = 0;
		if (bsim_outdir_verify(def->from[j], &has_manifest, err) != BSIM_OK)
			return BSIM_EINPUT;
		if (!has_manifest)
			return bsim_error_set(
			        err, BSIM_EINPUT,
			        "%s: no manifest.json: not a part directory of beamsim "
			        "markov build --shard",
			        def->from[j]);
	}
	bsim_session ss;
	/* the maps join those already cached */
	if ((rc = bsim_session_open(&ss, dir, BSIM_OUTDIR_ADD, "markov build", NULL, NULL, 0,
	                            err)) != BSIM_OK)
		return rc;
	rc = set_fill(lattice, def, dir, &ss, out, err);
	if (rc == BSIM_OK)
		rc = bsim_markov_def_write(ss.stage, def,
		                           def->backend ? def->backend : bsim_backend_default(),
		                           def->opts, err);
	rc = bsim_session_close(&ss, rc, "markov build", NULL, err);
	if (rc != BSIM_OK)
		bsim_markov_set_free(out);
	return rc;
}

/* BSIM_EINPUT unless name, a file in dir, is one of the manifest's files. */
static int file_listed(char *const *files, size_t n, const char *dir, const char *name,
                       bsim_error *err)
{
	for (size_t j = 0; j < n; j++)
		if (strcmp(files[j], name) == 0)
			return BSIM_OK;
	return bsim_error_set(err, BSIM_EINPUT,
	                      "%s/%s: not listed in %s/manifest.json, so not checked against it: "
	                      "rebuild the maps with beamsim markov build EXPERIMENT --out %s",
	                      dir, name, dir, dir);
}

/* With a manifest, every map file read must be one it lists (and so was
 * checked against its size and CRC-32 by bsim_markov_def_read): a map copied
 * in from elsewhere after the build is not used unchecked. The gates after
 * the start likewise. */
static int maps_listed(const char *dir, const bsim_markov_set *set, bsim_error *err)
{
	char **files = NULL;
	size_t n = 0;
	int rc = bsim_outdir_files(dir, &files, &n, err);
	static const char *const ext[] = {"key", "csv", "cost", "hold.csv"};
	for (int i = 0; rc == BSIM_OK && n > 0 && i < set->n; i++)
		for (int e = 0; rc == BSIM_OK && e < 4; e++) {
			char name[64];
			snprintf(name, sizeof name, "map_%016llx.%s",
			         (unsigned long long)set->maps[i].key, ext[e]);
			struct stat st;
			char path[BSIM_PATH_MAX];
			snprintf(path, sizeof path, "%s/%s", dir, name);
			if (lstat(path, &st) ==
			    0) /* a map without a .cost file: its cost unknown */
				rc = file_listed(files, n, dir, name, err);
		}
	for (int a = 0; rc == BSIM_OK && n > 0 && set->next && a < set->n; a++)
		for (int k = 0; rc == BSIM_OK && k < set->n * 2; k++) {
			char name[96];
			bsim_markov_next_name(name, sizeof name, &set->maps[a], &set->maps[k / 2],
			                      set->next[(size_t)a * set->n + k / 2].trials,
			                      k % 2 ? "cost" : "csv");
			rc = file_listed(files, n, dir, name, err);
		}
	bsim_outdir_files_free(files, n);
	return rc;
}

int bsim_markov_load(const bsim_scene *lattice, const char *dir, bsim_options *opts,
                     bsim_markov_set *out, bsim_error *err)
{
	memset(out, 0, sizeof *out);
	int rc = bsim_markov_check_lattice(lattice, err);
	if (rc != BSIM_OK)
		return rc;
	bsim_markov_def def = bsim_markov_def_default();
	if ((rc = bsim_markov_def_read(dir, &def, opts, err)) != BSIM_OK ||
	    (rc = def_check(&def, err)) != BSIM_OK)
		return rc;
	if ((rc = set_fill(lattice, &def, dir, NULL, out, err)) != BSIM_OK)
		return rc;
	if ((rc = maps_listed(dir, out, err)) != BSIM_OK)
		bsim_markov_set_free(out);
	return rc;
}

void bsim_markov_run_id(const uint64_t *keys, int n, char out[17])
{
	/* the keys as text, in order: the name bsim_part_dir_run_id gives it */
	char *text = malloc((size_t)n * 17 + 16);
	if (!text) {
		snprintf(out, 17, "%016x", 0u);
		return;
	}
	size_t len = (size_t)sprintf(text, "markov build\n");
	for (int i = 0; i < n; i++)
		len += (size_t)sprintf(text + len, "%016llx\n", (unsigned long long)keys[i]);
	bsim_part_dir_run_id(text, out);
	free(text);
}

int bsim_markov_part_write(const char *dir, int index, int count, const char *run, long total,
                           long records, int argc, char *const *argv, bsim_error *err)
{
	return bsim_part_dir_write(dir, "markov build", index, count, run, total, records, argc,
	                           argv, err);
}
