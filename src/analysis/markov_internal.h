/* Internal: what the files of the single-gate maps (beamsim/markov.h)
 * share. markov_bins.c lays out the entry bins and draws states in them,
 * markov_entries.c reads observed entries and indexes them by bin,
 * markov_train.c lists a lattice's gate kinds and runs their training field,
 * markov_gate.c runs the single gates that fill a map, markov_counts.c
 * keeps a map's counts by row, markov_cache.c keys maps and reads and
 * writes a map directory, and markov_map.c builds or loads the maps of a
 * lattice from those; markov_nearest.c keeps the training fields' visits
 * and walks over them (beamsim/markov_nearest.h). */
#ifndef BSIM_ANALYSIS_MARKOV_INTERNAL_H
#define BSIM_ANALYSIS_MARKOV_INTERNAL_H

#include <gsl/gsl_rng.h>
#include <stddef.h>
#include <stdint.h>

#include "beamsim/lattice_outcome.h"
#include "beamsim/markov.h"
#include "beamsim/markov_nearest.h"
#include "beamsim/override.h"
#include "beamsim/trial.h" /* BSIM_EDGE_* */

/* ---- bins (markov_bins.c) ---- */

/* The name of an edge, BSIM_EDGE_START .. BSIM_EDGE_TOP: "start",
 * "bottom", "left", "right", "top" (gate_entries.csv and map files). */
const char *bsim_markov_edge_name(int edge);
/* The edge of such a name, or -1. */
int bsim_markov_edge_of(const char *name);

/* The name of the edge of entry bin `bin`, "start" for bin 0. */
const char *bsim_markov_bin_edge(const bsim_markov_bins *b, int bin);

/* A state drawn uniformly in entry bin `bin` (> 0) of a gate with time
 * step h: body centre x (gate frame) and velocity v. */
void bsim_markov_bin_sample(const bsim_markov_bins *b, const bsim_lattice_def *l, double h, int bin,
                            gsl_rng *rng, double x[2], double v[2]);

/* An entry state through edge (BSIM_EDGE_BOTTOM .. TOP) in units of b's
 * bin widths (b->v_max set): f[0] position, f[1] speed, f[2] direction,
 * whose floors (clamped) are bsim_markov_bin_of's bin. */
void bsim_markov_entry_feature(const bsim_markov_bins *b, const bsim_lattice_def *l, int edge,
                               double pos, const double v[2], double f[3]);

/* ---- observed entries by bin (markov_entries.c) ---- */

/* The entries of each bin: bin b's are idx[first[b] .. first[b + 1]). */
typedef struct markov_entry_index {
	int *first, *idx;
} markov_entry_index;

/* Appends an entry to e, whose arrays hold *cap (grown as needed; 0 for
 * an empty e): 0, or -1 out of memory (e keeps what it had). */
int bsim_markov_entries_push(bsim_markov_entries *e, int *cap, int edge, double pos,
                             const double x[2], const double v[2]);

/* 0, or -1 out of memory (then bsim_markov_entry_index_free all the same). */
int bsim_markov_entry_index_init(markov_entry_index *x, const bsim_markov_entries *e,
                                 const bsim_markov_bins *b, const bsim_lattice_def *l);
void bsim_markov_entry_index_free(markov_entry_index *x);

/* The start bin's single-gate trials of def: start_trials, or trials. */
static inline int bsim_markov_def_start_trials(const bsim_markov_def *def)
{
	return def->start_trials > 0 ? def->start_trials : def->trials;
}

/* Whether def's states come from a training field (markov_train.c): the
 * default, with neither observed, self nor flow entries. */
static inline int bsim_markov_def_trains(const bsim_markov_def *def)
{
	return def->train_trials > 0 && !def->entries && !def->entries_id[0] && !def->self_entries;
}

/* Whether def's maps have the gate after the start: after_start, but never
 * with self or flow entries (their start's exits are of their own pass). */
static inline int bsim_markov_def_after_start(const bsim_markov_def *def)
{
	return def->after_start && !def->self_entries;
}

/* The start trials def's maps continue in the gate after the start, the
 * first ones: after_trials (-1: BSIM_MARKOV_AFTER_TRIALS), or every start
 * trial. */
static inline int bsim_markov_def_after_trials(const bsim_markov_def *def)
{
	const int T = bsim_markov_def_start_trials(def);
	const int A = def->after_trials < 0 ? BSIM_MARKOV_AFTER_TRIALS : def->after_trials;
	return A > 0 && A < T ? A : T;
}

/* The single gates of entry bin a of map m, and the index of its first
 * in the map's single gates (the start bin's first, then every other
 * bin's in turn); their total. */
static inline int bsim_markov_bin_trials(const bsim_markov_map *m, int a)
{
	if (m->bin_first)
		return (int)(m->bin_first[a + 1] - m->bin_first[a]);
	return a == 0 ? m->start_trials : m->trials;
}
static inline long bsim_markov_bin_first(const bsim_markov_map *m, int a)
{
	if (m->bin_first)
		return m->bin_first[a];
	return a == 0 ? 0 : m->start_trials + (long)(a - 1) * m->trials;
}
static inline long bsim_markov_map_units(const bsim_markov_map *m)
{
	if (m->bin_first)
		return m->bin_first[m->n_bins];
	return m->start_trials + (long)(m->n_bins - 1) * m->trials;
}
/* The entry bin of single gate u of map m. */
static inline int bsim_markov_unit_bin(const bsim_markov_map *m, long u)
{
	if (m->bin_first) { /* the last bin whose first is at most u */
		int lo = 0, hi = m->n_bins - 1;
		while (lo < hi) {
			const int mid = hi - (hi - lo) / 2;
			if (m->bin_first[mid] <= u)
				lo = mid;
			else
				hi = mid - 1;
		}
		return lo;
	}
	return u < m->start_trials ? 0 : 1 + (int)((u - m->start_trials) / m->trials);
}

/* The single gates a bin of map m of crossings is topped up to where c
 * crossings entered it: per_crossing for each (as for one where none did),
 * at most trials; every bin trials with per_crossing 0. The bin holds c
 * or this, whichever is more. */
static inline long bsim_markov_crossings_topped(const bsim_markov_map *m, long c)
{
	if (m->per_crossing <= 0)
		return m->trials;
	const long want = (long)m->per_crossing * (c > 1 ? c : 1);
	return want < m->trials ? want : m->trials;
}

/* Whether def's maps are counted from the training field's crossings. */
static inline int bsim_markov_def_crossings(const bsim_markov_def *def)
{
	return def->train_crossings != 0 && bsim_markov_def_trains(def);
}

/* ---- the lattice's gate kinds and its training field (markov_train.c) ---- */

/* The lattice's stiffness pairs (its gate kinds) in the order first met,
 * row 0 first, into *pairs (malloc'd): their number, or -1 out of memory. */
int bsim_markov_lattice_pairs(const bsim_scene *lattice, double (**pairs)[2]);

/* The same, in ascending order (left, then right). */
int bsim_markov_lattice_kinds(const bsim_scene *lattice, double (**kinds)[2]);

/* The id of the entries of a training field of def->train_trials trials of
 * lattice's gate kinds: "train N kinds n HASH" (HASH of the kinds sorted),
 * or "train N" without a lattice (as markov.json names it); "train N
 * crossings ..." where the maps are counted from its crossings. */
const char *bsim_markov_train_label(const bsim_scene *lattice, const bsim_markov_def *def,
                                    char *buf, size_t size);

/* A training field's crossings of its gates, in trial order, the start
 * gate's left out: crossing i entered a gate of stiffness pair k[i] in
 * entry bin entry[i] (> 0) and left it into bin exit[i] (0 stuck) after
 * steps[i] time steps (gate_steps if stuck). A gate the trial left out of
 * the field, or ended in before being stuck there, is not a crossing: its
 * exit is not known. */
typedef struct markov_crossings {
	long n;
	double (*k)[2];
	int *entry, *exit, *steps;
} markov_crossings;

void bsim_markov_crossings_free(markov_crossings *c);

/* The gate entries of lattice's training field (def->train_trials trials,
 * on def->threads threads, the same for any number), the start's left
 * out, in trial order; out->id its label; its crossings into cx (may be
 * NULL) and the time steps its trials took into *steps. BSIM_EFAIL naming
 * the first unstable trial, BSIM_ESTOPPED when def->stop was set. */
int bsim_markov_train_run(const bsim_scene *lattice, const bsim_markov_def *def,
                          const bsim_backend *be, const bsim_options *opts,
                          bsim_markov_entries *out, markov_crossings *cx, long long *steps,
                          bsim_error *err);

/* Room for one more visit in v, whose array holds *cap (grown as needed,
 * 0 for an empty v): 0, or -1 out of memory (v keeps what it had). */
int bsim_markov_visits_reserve(bsim_markov_visits *v, long *cap);

/* The visits (beamsim/markov_nearest.h) of lattice's training field whose
 * start gate is of kind start (def->train_trials trials, each trial's
 * layout of lattice's kinds at random and its schedule from seed and the
 * trial), appended to out (its arrays hold *cap), the gates
 * on the field's last row and outer columns counted in out->left_out; the
 * time steps its trials took into *steps. Errors as bsim_markov_train_run. */
int bsim_markov_train_visits(const bsim_scene *lattice, const bsim_markov_def *def,
                             const double start[2], uint64_t seed, const bsim_backend *be,
                             const bsim_options *opts, bsim_markov_visits *out, long *cap,
                             long long *steps, bsim_error *err);

/* The chain's lattice (markov_map.c): BSIM_EINPUT naming the field unless
 * s is a lattice with its side boundary at the field's edge and its end
 * at the last row's top edge, where the chain's (and the walks')
 * absorbing states are. */
int bsim_markov_check_lattice(const bsim_scene *s, bsim_error *err);

/* How bsim_markov_visits_gather writes and tells: a training field run is
 * written into stage (NULL: the directory it reads), commit(user) then
 * called (may be NULL: none; a build's, that adds the field's files to
 * its directory's set), and field(user) told of each field, run or read,
 * with the s of CPU it took when it was run (may be NULL). */
typedef struct markov_visits_io {
	const char *stage;
	int (*commit)(void *user, bsim_error *err);
	void (*field)(void *user, const double k[2], uint64_t hash, int reused, double cost);
	void *user;
} markov_visits_io;

/* bsim_markov_visits_build (markov_nearest.c) as io says. */
int bsim_markov_visits_gather(const bsim_scene *lattice, const bsim_markov_nearest_def *def,
                              const char *dir, const markov_visits_io *io, bsim_markov_visits *out,
                              bsim_error *err);

/* The walks' def of a build's directory (markov_cache.c): *is_nearest 1
 * and def's trials, k, seed, backend and opts (kept in *opts) from
 * dir/markov.json if it is a build of the walks' (markov build's default),
 * else *is_nearest 0 and def untouched (maps, or no markov.json: the
 * maps' reader says). BSIM_EINPUT naming file, line and field. */
int bsim_markov_nearest_def_read(const char *dir, bsim_markov_nearest_def *def, bsim_options *opts,
                                 int *is_nearest, bsim_error *err);

/* The walks a prediction makes: with visits_dir, given's over it (*vdir);
 * else, if map_dir is a walks' build, given's walks, threads, progress
 * and stop with the build's settings (bsim_markov_nearest_def_read, read
 * only) over map_dir; else *vdir NULL: the maps' chain. *nd is given's
 * then. */
int bsim_markov_nearest_of_dir(const char *map_dir, const char *visits_dir,
                               const bsim_markov_nearest_def *given, bsim_markov_nearest_def *nd,
                               bsim_options *opts, const char **vdir, bsim_error *err);

/* dir/markov.json of a walks' build (stage: where it is written). */
int bsim_markov_nearest_def_write(const char *stage, const bsim_markov_nearest_def *def,
                                  const bsim_backend *be, const bsim_options *opts,
                                  bsim_error *err);

/* ---- counts by row (markov_counts.c) ---- */

/* Map m's counts (its bins and trials set) from its single gates' exit
 * bins, exit[u] of unit u (bsim_markov_unit_bin's order); the old counts
 * freed. 0, or -1 out of memory (then no counts). */
int bsim_markov_counts_of_exits(bsim_markov_map *m, const int *exit);

/* Map m's counts from the n cells of a map file, in any order, cell i
 * entry cells[3 i] to exit cells[3 i + 1] counted cells[3 i + 2] times
 * (bins within m's): 0; 1 if a pair is given twice, *again the index of
 * its later cell (no counts); -1 out of memory. */
int bsim_markov_counts_of_cells(bsim_markov_map *m, long n, const int *cells, long *again);

/* to's counts a copy of from's (to->n_bins set): 0, or -1 out of memory. */
int bsim_markov_counts_copy(bsim_markov_map *to, const bsim_markov_map *from);

/* 1 if both maps have the same counts. */
int bsim_markov_counts_equal(const bsim_markov_map *a, const bsim_markov_map *b);

void bsim_markov_counts_free(bsim_markov_map *m);

/* ---- single gates (markov_gate.c) ---- */

/* The end of trial i of a loop on the threads: e (NULL: it did not fail)
 * kept in *first_err if i is the first failure in trial order so far
 * (*first), so that the error is the same for any number of threads; *done
 * counted, and progress(user, done, total) called every `every` trials and
 * at the last (progress may be NULL). */
void bsim_markov_trial_end(long i, const bsim_error *e, long *first, bsim_error *first_err,
                           long *done, long total, long every, bsim_progress_fn progress,
                           void *user);

/* The gate of the lattice's start, moved to its own frame, as the essay's
 * protocol builds it on entry: its two beams at rest, with stiffness k. */
typedef struct markov_gate_scene {
	bsim_scene s;
	bsim_beam_def beams[2];
} markov_gate_scene;

void bsim_markov_gate_scene_init(markov_gate_scene *g, const bsim_scene *lattice,
                                 const double k[2]);

/* One single-gate trial of a map: the entry state it started from and the
 * state it left with, in the frame of the gate it enters (the body at the
 * end of the step that crossed, as a lattice records an entry), or its
 * last state if stuck (exit 0). */
typedef struct markov_run {
	int exit;
	double x[2], v[2];           /* entry: body centre (gate frame), m; velocity, m/s */
	double exit_x[2], exit_v[2]; /* exit, in the next gate's frame */
} markov_run;

/* The exits of a previous pass by the bin they enter: bin b's runs are
 * run[first[b] .. first[b + 1]) in (map, trial) order, cw their cumulative
 * weights within the bin. */
typedef struct markov_pool {
	int pass;
	const markov_run **run;
	int *first;
	double *cw;
} markov_pool;

/* Map m's bins laid out for the crossings of its gate kind in cx (m's
 * bin_first set): each bin holds its crossings or what they are topped up
 * to (bsim_markov_crossings_topped), whichever is more, the start bin
 * m->start_trials. The crossings placed, or -1 out of
 * memory; the single gates left to simulate are the rest of
 * bsim_markov_map_units(m). */
long bsim_markov_crossings_layout(bsim_markov_map *m, const markov_crossings *cx);

/* Map m's counts (n_bins, k and counts allocated) from its single gates,
 * def->trials per entry bin, on def->threads threads, the states of bin
 * b > 0 drawn from pool's exits into b (pool NULL: in the bin, or among
 * def->entries); with cx (bins laid out by bsim_markov_crossings_layout),
 * each bin's crossings of cx first, in trial order, then the single gates
 * that top it up. Every trial's entry and exit kept in runs[u] of its unit
 * u (bsim_markov_unit_bin's order; runs may be NULL; a crossing's left
 * as it was); *done counts the trials run of total, for def->progress.
 * BSIM_EFAIL with the error of the first failed trial (in trial order,
 * whatever the threads); BSIM_ESTOPPED, err untouched and the counts not
 * counted, if def->stop was set. */
int bsim_markov_map_simulate_runs(const bsim_scene *lattice, const bsim_markov_def *def,
                                  const bsim_backend *be, const bsim_options *opts,
                                  bsim_markov_map *m, const markov_pool *pool,
                                  const markov_crossings *cx, markov_run *runs, long *done,
                                  long total, bsim_error *err);

/* The gate after the start (bsim_markov_next): the start bin's single
 * gates of map start again (the same seeds as the map's: the same exits,
 * BSIM_EFAIL if they differ from its holding times), or, with start_runs,
 * their runs as the map's build kept them (start_runs[t] for start trial
 * t), and from the exit state of each of the first
 * bsim_markov_def_after_trials(def) that left into a gate one single gate
 * of each of the n maps gate[i], into nx[i] (trials set, exit and steps
 * allocated). *done counts bsim_markov_next_units(that, n) units of
 * total. */
int bsim_markov_next_simulate(const bsim_scene *lattice, const bsim_markov_def *def,
                              const bsim_backend *be, const bsim_options *opts,
                              const bsim_markov_map *start, const markov_run *start_runs,
                              const bsim_markov_map *const *gate, bsim_markov_next *const *nx,
                              int n, long *done, long total, bsim_error *err);
long bsim_markov_next_units(int after_trials, int n);

/* ---- self-consistent entries (markov_self.c) ---- */

/* The entries line of a map's key and markov.json: the observed entries'
 * id, "self N" (self-consistent, N passes), "flow N" (weighted by the
 * field's flow; in a key followed by "field HASH", the hash of lattice's
 * layout of stiffness pairs, lattice NULL for markov.json) or "none". */
const char *bsim_markov_entries_label(const bsim_markov_def *def, const bsim_scene *lattice,
                                      char *buf, size_t size);

/* The passes of map m still to simulate (m's key for def->self_passes;
 * the last pass whose map and exits are in dir is reused): how many. */
int bsim_markov_self_passes_left(const bsim_scene *lattice, const bsim_markov_def *def,
                                 const bsim_backend *be, const bsim_options *opts,
                                 const bsim_markov_map *m, const char *dir);

/* The maps of set (maps[i] with key and counts allocated, have[i] those
 * read from the cache) by def's flow-weighted passes (self_entries 2): pass
 * p draws map B's states of bin b from the exits into b of every map's
 * pass p - 1 single gates, each weighted by the expected visits, in
 * lattice's chain of pass p - 1, of its entry bin in the gates of its map
 * whose neighbour across that exit is a gate of map B. Pass 0 is the
 * self-consistent pass 0 (read from dir where there); the passes simulated
 * now and the last pass of maps not in the cache written into stage. */
int bsim_markov_flow_simulate(const bsim_scene *lattice, const bsim_markov_def *def,
                              const bsim_backend *be, const bsim_options *opts,
                              bsim_markov_map *maps, int n, const char *have, const char *dir,
                              const char *stage, long *done, long total, bsim_error *err);

/* Moves from's counts and holding times into to (to's freed first). */
void bsim_markov_map_take_counts(bsim_markov_map *to, bsim_markov_map *from);

/* Map m by def's self-consistent passes, starting from the last pass in
 * dir; each pass simulated now written into stage (map and exits). */
int bsim_markov_self_simulate(const bsim_scene *lattice, const bsim_markov_def *def,
                              const bsim_backend *be, const bsim_options *opts, bsim_markov_map *m,
                              const char *dir, const char *stage, long *done, long total,
                              bsim_error *err);

/* Map m's passes 0 .. last (def's self or flow entries) copied into stage
 * by the writers that wrote them, each pass from the first of dirs[0..
 * n_dirs) (NULL ones skipped) that holds it: every pass's map but the
 * final one (m, the caller's) and every pass's exits, the same bytes.
 * BSIM_EINPUT naming dirs[0] if a pass is in none, or the file if one is
 * malformed. */
int bsim_markov_self_copy(const bsim_scene *lattice, const bsim_markov_def *def,
                          const bsim_backend *be, const bsim_options *opts,
                          const bsim_markov_map *m, int last, const char *const *dirs, int n_dirs,
                          const char *stage, bsim_error *err);

/* The pass a job array's round of flow-weighted maps makes (def
 * one_pass): the first pass that dir (NULL: none) does not hold, map and
 * exits, for every one of maps[0..n) (keys set); -1 with err if a pass's
 * exits there are malformed. */
int bsim_markov_flow_round(const bsim_scene *lattice, const bsim_markov_def *def,
                           const bsim_backend *be, const bsim_options *opts,
                           const bsim_markov_map *maps, int n, const char *dir, bsim_error *err);

/* ---- the chain's exits (markov_chain.c) ---- */

/* The final locations of lattice l in bsim_markov_prediction's order into
 * loc (columns + rows + columns rows): the ends by ix, the sides by iy, the
 * stuck gates by g = iy columns + ix - ix_min. */
void bsim_markov_locations_fill(const bsim_lattice_def *l, bsim_location *loc);

/* Where exit x (0 stuck, else an entry bin of the gate entered) of gate g =
 * iy cols + ix - ix_min of a cols x rows field leads: *state = g' nb + bin
 * (>= 0), a transient state, or *state = -1 and *loc the final location,
 * in bsim_markov_prediction's order (ends, sides, stuck gates). A body
 * leaving row 0 downwards enters row 0's gate again through its bottom. */
void bsim_markov_exit_target(int cols, int rows, int nb, int g, int x, int *state, int *loc);

/* gate_map[iy * columns + ix - ix_min]: the index in set of the map of
 * gate (ix, iy) of lattice, by its pair of beam stiffnesses. BSIM_EINPUT
 * naming the first gate no map has. */
int bsim_markov_gate_maps(const bsim_scene *lattice, const bsim_markov_set *set, int *gate_map,
                          bsim_error *err);

/* ---- the map directory (markov_cache.c) ---- */

/* Every input of the map of stiffness pair k, a line each (malloc'd; NULL
 * out of memory). */
char *bsim_markov_key_text(const bsim_scene *lattice, const bsim_markov_def *def,
                           const bsim_backend *be, const bsim_options *opts, const double k[2]);

/* Whether path, a .key file, holds exactly key_text: a file that is
 * longer (it is not read past that length), shorter or unreadable does
 * not. */
int bsim_markov_key_same(const char *path, const char *key_text);

/* The key of a key text: the map's file name, map_KEY. */
uint64_t bsim_markov_key(const char *key_text);

/* What tells the directory dir's nearest key of files prefix ("map_", or
 * "visits_": a training field's) (the key with the fewest lines unlike
 * want's) from key text want: "the nearest map there, map_HASH.key, has
 * 'LINE'; ... where this one needs 'LINE'; ...", into buf; "" if dir holds
 * no such key. */
void bsim_markov_key_nearest(const char *dir, const char *prefix, const char *want, char *buf,
                             size_t size);

/* Reads map m (key, key_text, n_bins and counts set) from dir: 1 if there
 * with the same key text, 0 if not there or another key, -1 with err if
 * its counts are malformed. */
int bsim_markov_map_read(const char *dir, bsim_markov_map *m, bsim_error *err);

/* Writes map m's key, counts and cost into stage. */
int bsim_markov_map_write(const char *stage, const bsim_markov_map *m, const bsim_markov_bins *b,
                          bsim_error *err);

/* The gate after the start x of maps start and gate (map_START.after_GATE
 * .csv and .cost) written into stage, or read from dir: 1 if there, 0 if
 * absent, -1 with err naming the line if malformed or not of start's
 * holding times. */
/* The file name of the gate after the start of maps start and gate:
 * "map_START.after_GATE.what", or where `after`, the start trials
 * continued, is fewer than the start map's,
 * "map_START.after_GATE.firstAFTER.what" (what: "csv" or "cost"). */
void bsim_markov_next_name(char *buf, size_t size, const bsim_markov_map *start,
                           const bsim_markov_map *gate, int after, const char *what);
int bsim_markov_next_write(const char *stage, const bsim_markov_next *x,
                           const bsim_markov_map *start, const bsim_markov_map *gate,
                           bsim_error *err);
int bsim_markov_next_read(const char *dir, bsim_markov_next *x, const bsim_markov_map *start,
                          const bsim_markov_map *gate, bsim_error *err);

/* Writes stage/markov.json, the def of the build. */
int bsim_markov_def_write(const char *stage, const bsim_markov_def *def, const bsim_backend *be,
                          const bsim_options *opts, bsim_error *err);

/* Reads dir/markov.json into def (its options into opts), every fault
 * naming the file position and field; a field the file leaves out keeps
 * the value def holds (the caller's defaults). Each field is checked on its own;
 * the def as a whole is checked where maps are built or loaded. */
int bsim_markov_def_read(const char *dir, bsim_markov_def *def, bsim_options *opts,
                         bsim_error *err);

/* ---- figures of final locations (markov_figure.c) ---- */

/* A panel of a field figure: the probability of each location (p), or,
 * with minus, the difference p - minus; p NULL leaves its place empty. */
typedef struct markov_field_panel {
	const char *title;
	const double *p, *minus;
} markov_field_panel;

/* Sums of p over the ends, the sides and the stuck gates. */
void bsim_markov_field_totals(const bsim_location *loc, const double *p, int n, double tot[3]);

/* "backend NAME, F_prop = 6 N, k_1 = 100 N m/rad": the backend (may be
 * NULL) and overrides in the model's symbols (beamsim/key_names.h). */
void bsim_markov_title_params(char *buf, size_t size, const char *backend, const bsim_override *ov,
                              int n);

/* Writes stage/NAME.dat and draws NAME: the n_panels panels, per_row to a
 * row, each a map of the field's n locations loc (every final location of
 * the lattice: its ends, sides and gates) with the totals of end, side and
 * stuck in the panel's title. */
int bsim_markov_field_figure(const char *stage, const char *name, const char *title,
                             const bsim_location *loc, int n, const markov_field_panel *panel,
                             int n_panels, int per_row, int *drawn, bsim_error *err);

#endif
