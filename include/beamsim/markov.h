/* Predicting a gate lattice from single gates: the Markov chain of the
 * essay's Sec. 3.3 and 4.3 (Zheng, Xuan & Li, IEEE RA-L 2022).
 *
 * The single-gate map. A gate is entered across one of its edges with some
 * state and left across an edge with another, or the body stays stuck in
 * it (gate_steps steps). The entry state, in the gate's own frame (Eq.
 * 2.17), is binned:
 *   edge       bottom, left, right, top (the side it came in through), and
 *              the start, the body's initial state, as a bin of its own;
 *   position   along the edge: x in [-w/2, w/2] on the bottom and top, y in
 *              [0, d] on the sides, n_pos equal bins;
 *   speed      |v| in [0, v_max], n_speed equal bins, faster in the last;
 *   direction  the angle of v from the edge's inward normal, in
 *              [-90, 90] degrees, n_dir equal bins (beyond: the end bins).
 * For each bin, `trials` single gates (the two beams at rest, as the essay
 * resets them on entry) start from states drawn from a training field's
 * gate entries in the bin (train_trials; or uniformly in the bin), each
 * with a fresh random-force schedule, and run until the body leaves the
 * gate's rectangle or gate_steps steps pass. The exit state is binned as
 * the entry state of the gate it enters, so a map is a matrix of counts
 * from entry to exit bin, exit 0 being "stuck", kept by row (each row's
 * nonzero exits, at most its trials: bsim_markov_map). One map per pair
 * of beam stiffnesses (left, right) the lattice uses.
 *
 * The chain. The transient states are (gate, entry bin); the absorbing ones
 * the final locations of docs/model.md section 8: the end through column ix
 * (the top edge of the last row), a side at row iy (the outer edge of the
 * outer columns, where side_x lies), stuck in gate (ix, iy). With Q the
 * transient-to-transient and R the transient-to-absorbing probabilities and
 * s the start state, the final-location distribution is
 *   p = s (I - Q)^-1 R,
 * solved exactly by LU decomposition (GSL) when the chain has at most
 * BSIM_MARKOV_LU_MAX states, else by the series s (I + Q + Q^2 + ...) R
 * summed until the probability still in the field is below a tolerance
 * (BSIM_MARKOV_TOL, far below the maps' sampling error). The
 * series' k-th term is the k-th gate entered, so it also gives the
 * distribution of the number of gates visited, the start gate counted.
 *
 * What the chain assumes: the essay's protocol (beams reset on entry, the
 * gates behind and beside the body absent), and that the exit depends on
 * the entry only through its bin. A body leaving row 0 downwards re-enters
 * row 0 in the chain (the lattice keeps it in row 0's gate); a trial's
 * overall max_steps is not in p, only in bsim_markov_predict_time's walks,
 * which use the maps' holding times (the chain as a semi-Markov one). */
#ifndef BSIM_MARKOV_H
#define BSIM_MARKOV_H

#include <signal.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "beamsim/base.h"
#include "beamsim/backend.h"
#include "beamsim/error.h"
#include "beamsim/experiment.h"
#include "beamsim/lattice.h"
#include "beamsim/markov_nearest.h"
#include "beamsim/options.h"
#include "beamsim/progress.h"
#include "beamsim/scene.h"
#include "beamsim/lattice_outcome.h"
#include "beamsim/limits.h"
#include "beamsim/sweep_dir.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The entry-state bins. */
typedef struct bsim_markov_bins {
	int n_pos, n_speed, n_dir;
	/* m/s: speeds above it fall in the last speed bin; 0 (the default):
	 * from the lattice's propulsion, bsim_markov_bins_v_max */
	double v_max;
} bsim_markov_bins;

/* 14 positions, 6 speeds up to v_max, 13 directions: where in a bin a
 * lattice's entries fall matters to where the body goes next, above all
 * their position and direction, so the bins are fine, and their states
 * drawn from a training field's entries, so that maps of a physics
 * predict fields of any layout (docs/markov.md, "Maps of a physics"). */
BSIM_API bsim_markov_bins bsim_markov_bins_default(void);

/* The speed range by default: BSIM_MARKOV_V_MAX, or the propulsion's
 * acceleration F_prop / M times BSIM_MARKOV_V_MAX_TIME where that is more.
 * The speeds bodies enter gates at grow in proportion to the propulsion
 * (the training field's 90th percentile 31 m/s at 7 N, 62 m/s at 14 N),
 * and those above v_max share one bin, whatever their speed
 * (docs/markov.md, "A speed range from the propulsion"). */
#define BSIM_MARKOV_V_MAX      40.0         /* m/s */
#define BSIM_MARKOV_V_MAX_TIME (40.0 / 7.0) /* s: 40 m/s at 7 N on 1 kg */

/* The speed range of bins b for a lattice: b->v_max, or where that is 0,
 * the default above from the lattice's propulsion and body mass. */
BSIM_API double bsim_markov_bins_v_max(const bsim_markov_bins *b, const bsim_scene *lattice);

/* The number of entry bins, the start's included: 1 + 4 n_pos n_speed n_dir. */
BSIM_API int bsim_markov_bins_count(const bsim_markov_bins *b);

/* The most single gates a map may hold: every entry bin's trials, the
 * start's included (its counts and holding times are indexed by them). */
#define BSIM_MARKOV_MAX_UNITS 2147483647L

/* BSIM_OK if the bins are 1 to 64 positions, speeds and directions; else
 * BSIM_EINPUT saying what is wrong and what is accepted. A map keeps its
 * counts by row (bsim_markov_map), so its size grows as its bins times
 * its trials, which BSIM_MARKOV_MAX_UNITS bounds where the map is built.
 * v_max is not checked. */
BSIM_API int bsim_markov_bins_check(const bsim_markov_bins *b, bsim_error *err);

/* Gate entries observed in simulation (gate_entries.csv of lattice sweeps,
 * the start rows left out): when a map is built with them, the states of
 * an entry bin are drawn from the entries that fall in it (uniformly in
 * the bin only where none does), so the states within a bin are those a
 * lattice delivers. */
typedef struct bsim_markov_entries {
	int n;
	int *edge;
	double *pos;
	double (*x)[2], (*v)[2]; /* body centre (gate frame) and velocity */
	char id[64];             /* "HASH COUNT": FNV-1a of the files' bytes, entries */
} bsim_markov_entries;

/* Reads the entries of n files (a gate_entries.csv, or a directory holding
 * one). BSIM_EINPUT naming file and line if one is malformed. */
BSIM_API int bsim_markov_entries_load(const char *const *paths, int n, bsim_markov_entries *out,
                                      bsim_error *err);
BSIM_API void bsim_markov_entries_free(bsim_markov_entries *e);

/* How a map is built. */
typedef struct bsim_markov_def {
	bsim_markov_bins bins;
	int trials; /* single-gate trials per entry bin */
	/* Single-gate trials of the start bin (bin 0), <= 0: trials. Every
	 * body passes through the start bin once, so its row weighs on every
	 * prediction and is cheap to sample finely (one bin of many).
	 * Self-consistent and flow entries take only start_trials == trials. */
	int start_trials;
	uint64_t seed;                      /* of the entry states and the schedules */
	const bsim_backend *backend;        /* NULL: the default backend */
	const bsim_options *opts;           /* NULL: no options */
	int threads;                        /* <= 0: all cores; the map is the same for any */
	const bsim_markov_entries *entries; /* NULL: a training field's, or uniform in each bin */
	char entries_id[64];                /* the entries' id when read back from markov.json */
	/* With neither entries nor self or flow entries: > 0 (the default,
	 * BSIM_MARKOV_TRAIN_TRIALS) draws each bin's states from the gate
	 * entries of a training field, train_trials trials of a
	 * BSIM_MARKOV_TRAIN_SIZE-square field of the lattice's gate kinds laid
	 * out at random (seed) under the essay's protocol, run only when a map
	 * is to be built; its label ("train N kinds n HASH") is in the maps'
	 * keys, so the maps hold for every layout of the same kinds and
	 * physics. 0: states uniform in each bin. */
	int train_trials;
	/* With a training field: 1 counts every bin of a map from the
	 * field's own crossings of the gates of the map's kind that were
	 * entered in that bin (where each left and after how many time steps:
	 * under the essay's protocol a gate entered is a single gate started
	 * from the entry's state), and tops each bin up with single gates
	 * whose states are drawn from the field's entries in the bin, as far
	 * as trials_per_crossing says (bsim_markov_map.bin_first). The start
	 * bin keeps its start_trials single gates. -1 (the default): 1 where
	 * the maps have a training field, else 0. 0: `trials` single gates a
	 * bin, their states drawn from the field's entries. 1 without a
	 * training field is refused. */
	int train_crossings;
	/* With crossings counted: a bin is topped up to trials_per_crossing
	 * single gates for each crossing that entered it (as for one where
	 * none did), at most `trials`; a bin then holds its crossings or that,
	 * whichever is more. The bins bodies take hold `trials` or more, and
	 * the thousands a training field hardly enters few, where they cost
	 * most of the single gates (docs/markov.md, "Single gates where the
	 * crossings are"). Default BSIM_MARKOV_TRIALS_PER_CROSSING; 0: every
	 * bin topped up to `trials`. */
	int trials_per_crossing;
	/* The gate after the start (1, the default): each of the start bin's
	 * single gates that leaves into a gate is continued there, one single
	 * gate from its exact exit state, for every stiffness pair of the
	 * lattice (bsim_markov_next), and the chain takes the body's first two
	 * gates from those runs rather than from the entry bins. The start's
	 * exits are those a body's first gate delivers to every lattice, so
	 * these runs are of the physics, not of a layout. 0: the entry bins
	 * from the start on. Only with a training field's, uniform or observed
	 * entries (self and flow entries: 0). */
	int after_start;
	/* With the gate after the start: the first after_trials of the start
	 * bin's single gates are continued (-1, the default:
	 * BSIM_MARKOV_AFTER_TRIALS; 0 or start_trials and more: every one; set
	 * without the gate after the start: refused). The chain takes a body's
	 * second gate from those continuations that entered the same gate,
	 * pooled, for every start trial that entered it: the start's own exits
	 * keep all start_trials, and the gate after them an unbiased sample of
	 * the exact states, at a cost in proportion (docs/markov.md, "A smaller
	 * training field and fewer start trials continued"). */
	int after_trials;
	bsim_progress_fn progress; /* may be NULL; counts single-gate trials */
	void *progress_user;
	/* May be NULL; counts the training field's trials, before any single
	 * gate, a hundred times over the field at most. */
	bsim_progress_fn train_progress;
	void *train_progress_user;
	/* May be NULL. When *stop becomes nonzero (a signal handler sets it),
	 * no further single gate starts, the map under way is dropped, the
	 * maps finished are kept in the map directory, and the build returns
	 * BSIM_ESTOPPED. */
	const volatile sig_atomic_t *stop;
	/* Self-consistent entry states (entries NULL): 1 builds the map in
	 * passes 0 .. self_passes. Pass 0 is the map of states uniform in each
	 * bin; pass p draws each bin's states from the exit states the single
	 * gates of pass p - 1 left into that bin (a top exit is the next gate's
	 * bottom entry), each exit weighted by the expected visits of the bin it
	 * came from in a field of this gate alone (the first
	 * BSIM_MARKOV_SELF_GATES gates from the start). Seeds of the states from
	 * (seed, pass, bin, trial); the schedules are pass 0's. The map
	 * directory keeps every pass's map and its single gates' entry and exit
	 * states (map_HASH.exits.csv), and a later build with more passes starts
	 * from the last pass there. Flow-weighted (self_entries 2): pass p draws
	 * bin b's states of the map of pair B from the exits into b of every
	 * map of the lattice, each weighted by the expected visits (in the
	 * lattice's chain of pass p - 1) of its entry bin in the gates whose
	 * neighbour across that exit is a gate of pair B: maps for that
	 * lattice's layout only (its hash is in the key). */
	int self_entries; /* 0 off, 1 self-consistent, 2 flow-weighted (above) */
	int self_passes;  /* 0 to BSIM_MARKOV_SELF_PASSES_MAX */
	/* A build spread over processes (docs/cluster.md). parts > 1: this
	 * process builds only its maps: the lattice's stiffness pair i (in
	 * the order first met, row 0 first) is the build's map part_first + i
	 * (part_first: the maps of the groups before this lattice's), which
	 * belongs to part (part_first + i) mod parts, 0 <= part < parts, so
	 * that the parts take turns along all of a build's maps; the others
	 * are left out (their map's elsewhere set, no counts). n_from > 0: no
	 * single gate runs; every map not in dir is read from the first of the
	 * map directories from[0..n_from) (each checked against its manifest)
	 * that has it and written into dir, the same bytes; a map none has is
	 * BSIM_EINPUT naming it, and nothing is written. Self entries are
	 * spread the same way, a map's passes with it (every pass's map and
	 * exits copied from its part); flow entries need pass_exchange or one_pass. */
	int part, parts, part_first;
	const char *const *from;
	int n_from;
	/* Flow entries spread over parts (parts > 1) that meet after each pass
	 * (an MPI job's ranks; NULL: flow entries over parts are BSIM_EINPUT,
	 * since pass p + 1 of every map needs pass p of all). Called by every
	 * part after each pass but the last, with the same arguments but runs'
	 * contents: runs[i] (bytes each) holds map i's single gates of that
	 * pass on part owner[i] (i < n, the lattice's pairs as above), and on
	 * return every part must hold every map's; BSIM_OK or an error (err). */
	int (*pass_exchange)(void *user, void *const *runs, size_t bytes, const int *owner, int n,
	                     bsim_error *err);
	void *pass_exchange_user;
	/* Flow entries in a job array (docs/cluster.md): one array of parts
	 * and one merge per pass. one_pass 1: this build makes one pass, the
	 * first that the map directory passes_from (the merge of the pass
	 * before; NULL: none, pass 0) does not hold for every map of the
	 * lattice, drawing its states from the exits there. A pass before the
	 * last writes the passes' maps and exits but no final map (the set's
	 * pass says which); a merge (from) of such parts writes every map's
	 * passes up to it, the earlier ones read from passes_from. */
	int one_pass;
	const char *passes_from;
} bsim_markov_def;

#define BSIM_MARKOV_SELF_GATES      16
#define BSIM_MARKOV_SELF_PASSES_MAX 8

/* The start bin's single-gate trials by default. */
#define BSIM_MARKOV_START_TRIALS 16000
/* The training field's trials by default, and its gates across and along. */
#define BSIM_MARKOV_TRAIN_TRIALS 4000
#define BSIM_MARKOV_TRAIN_SIZE   21
/* The single gates a bin by default for each crossing of the training
 * field that entered it (at most the bin's trials). */
#define BSIM_MARKOV_TRIALS_PER_CROSSING 5
/* The start bin's single gates continued in the gate after the start by
 * default, the first ones. */
#define BSIM_MARKOV_AFTER_TRIALS 8000

/* bsim_markov_bins_default(), 50 trials per bin and BSIM_MARKOV_START_TRIALS
 * of the start bin, the first BSIM_MARKOV_AFTER_TRIALS of them continued in
 * the gate after the start, a training field of BSIM_MARKOV_TRAIN_TRIALS
 * whose crossings are counted (BSIM_MARKOV_TRIALS_PER_CROSSING), seed 1,
 * the default backend, all cores. */
BSIM_API bsim_markov_def bsim_markov_def_default(void);

/* One single-gate map. */
typedef struct bsim_markov_map {
	double k[2];      /* N m/rad, the gate's left and right beam */
	uint64_t key;     /* FNV-1a hash of key_text: the map's file name */
	char *key_text;   /* everything the map depends on, a line each */
	int n_bins;       /* bsim_markov_bins_count */
	int trials;       /* per entry bin, but the start's (with bin_first: the most a bin is
	                   * topped up to) */
	int start_trials; /* of the start bin, bin 0 (bsim_markov_bin_trials) */
	/* A map counted from a training field's crossings (def train_crossings)
	 * holds a number of single gates of its own in each bin: bin a's are
	 * [bin_first[a], bin_first[a + 1]) (n_bins + 1 entries, bin_first[0]
	 * = 0, bin_first[1] = start_trials, every other bin its crossings or
	 * what they are topped up to, per_crossing).
	 * NULL: the start bin start_trials, every other trials. */
	long *bin_first;
	int of_crossings; /* 1: counted from crossings (its key says so), bin_first set
	                   * once counted or read */
	int per_crossing; /* its def trials_per_crossing: a bin holds min(trials,
	                   * per_crossing) at least (0: trials) */
	/* The counts, a row an entry bin: row a's exits (0 = stuck) are
	 * count_exit[count_first[a] .. count_first[a + 1]), ascending, each
	 * count_n[] times; the row's other exits 0 times. A row sums to
	 * bsim_markov_bin_trials (a map of its own single gates) and holds at
	 * most that many exits, so a map's size grows as its bins, not their
	 * square (bsim_markov_map_count reads one; NULL: not counted yet). */
	int *count_first; /* n_bins + 1 */
	int *count_exit, *count_n;
	double seconds;  /* CPU time of its simulation now, s (0 if read from the cache) */
	double cost;     /* CPU time its simulation took when it was built, s: with self or
	                  * flow entries every pass's, those reused from the cache too */
	long long steps; /* single-gate time steps that simulation took, with its share
	                  * of the training field's (as cost); 0 if the map's .cost
	                  * file predates the count */
	int cached;      /* 1: read from the cache, 0: simulated now */
	/* Holding times: each single gate's exit bin (0 stuck) and the time
	 * steps it spent in the gate (to the step that left it, or gate_steps
	 * if stuck), [start_trials + (entry - 1) * trials + trial] for entry > 0,
	 * [trial] for the start (map_HASH.hold.csv). NULL for a map read
	 * without that file (built before holding times were kept):
	 * the chain then has no times, and a build simulates it again. */
	int *hold_exit, *hold_steps;
	int elsewhere; /* 1: left to another part (def parts): no counts here */
	int copied;    /* 1: read from a part's directory (def from) and written */
} bsim_markov_map;

/* The count of exit `exit` from entry bin `entry` of map m: the single
 * gates of that bin that left there (0 for a map not counted or a bin
 * not of it). */
BSIM_API int bsim_markov_map_count(const bsim_markov_map *m, int entry, int exit);

/* Sets map m's counts (m->n_bins set) from a dense n_bins x n_bins matrix
 * [entry * n_bins + exit], for maps made by hand; BSIM_EFAIL out of
 * memory. */
BSIM_API int bsim_markov_map_set_counts(bsim_markov_map *m, const int *dense, bsim_error *err);

/* The gate after the start: map `start`'s first `trials` start-bin single
 * gates each continued from its exact exit state in a gate of map `gate`
 * (both indices into the set's maps), the beams at rest: exit[t] the exit
 * bin of that gate (0 stuck) and steps[t] the time steps it took, for
 * start trial t < trials, or exit[t] = -1 where the start's single gate did
 * not leave into a gate (it was stuck). Stored as map_START.after_GATE.csv
 * and .cost in the map directory, named by both maps' keys (with
 * .firstN before the extension where N, the trials, is fewer than the
 * start map's start trials). */
typedef struct bsim_markov_next {
	int start, gate;
	int trials; /* the start trials continued: def after_trials, at most the start map's */
	int *exit, *steps;
	double seconds, cost;          /* as bsim_markov_map's */
	long long steps_total;         /* single-gate time steps, as bsim_markov_map's steps */
	int cached, copied, elsewhere; /* as bsim_markov_map's */
} bsim_markov_next;

/* The maps of one lattice: one per stiffness pair it uses. */
typedef struct bsim_markov_set {
	bsim_markov_def def; /* as built (backend and opts: the caller's) */
	int n;
	bsim_markov_map *maps;
	int built, reused; /* maps simulated now, maps read from the cache */
	double seconds;    /* CPU time of the simulation of those built, s */
	int copied;        /* maps read from the parts' directories (def from) */
	int pass; /* def one_pass: the pass made (or merged); below def self_passes, the set's
	           * maps hold no counts */
	/* def after_start: n x n, next[s * n + k] the start of map s continued
	 * in a gate of map k; else NULL. */
	bsim_markov_next *next;
	int next_built, next_reused; /* of them simulated now, read from the cache */
} bsim_markov_set;

/* The maps lattice needs, from the cache directory dir: a map whose key is
 * there is read, the others are simulated and stored there (dir/maps/
 * HASH.csv and HASH.key, and dir/markov.json, the def last used). A key
 * holds every input of the map (the gate, its beams and stiffness pair,
 * the body, contact, effects, time step, gate_steps, the backend and its
 * options, bins, trials, seed and the map format's version), so a changed
 * parameter never reuses a map. With def->after_start (and neither self
 * nor flow entries), the gates after the start of every ordered pair of
 * those maps too (out->next), read or built alike. BSIM_EINPUT if lattice
 * is not a lattice or its side boundary is not the field's edge; an
 * unstable single gate is BSIM_EFAIL, never a count. */
BSIM_API int bsim_markov_build(const bsim_scene *lattice, const bsim_markov_def *def,
                               const char *dir, bsim_markov_set *out, bsim_error *err);

/* The maps lattice needs, read from dir only, with the def stored in
 * dir/markov.json (opts: filled into *opts, which must outlive the set),
 * and their gates after the start where it says after_start 1.
 * BSIM_EINPUT naming the stiffness pair whose map is missing, or the file
 * of a missing gate after the start, with the command that builds it. */
BSIM_API int bsim_markov_load(const bsim_scene *lattice, const char *dir, bsim_options *opts,
                              bsim_markov_set *out, bsim_error *err);

BSIM_API void bsim_markov_set_free(bsim_markov_set *s);

/* The name of a spread build's run (docs/cluster.md): 16 hex digits of
 * the hash of the keys of every map it builds, in order (the maps of
 * every part, elsewhere or not), so that the parts of one build carry one
 * name and a part of another build (any other input) another. */
BSIM_API void bsim_markov_run_id(const uint64_t *keys, int n, char out[17]);

/* Writes dir/part.json of part index (1-based) of count of the build run
 * (bsim_markov_run_id), of total maps, records of them built here, argv
 * the command line (bsim_sweep_dir_part_read reads it). */
BSIM_API int bsim_markov_part_write(const char *dir, int index, int count, const char *run,
                                    long total, long records, int argc, char *const *argv,
                                    bsim_error *err);

/* ---- the maps of an experiment ----------------------------------------
 *
 * beamsim markov build EXPERIMENT --out DIR: by default the training
 * fields of the nearest-neighbour walks every group's lattice needs (a
 * field per gate kind of its physics) in one directory; with method
 * BSIM_MARKOV_METHOD_MAPS the maps every group's lattice needs built into
 * one map directory (bsim_markov_build per group, the maps of all groups
 * in one cache), as one process, one part of a spread build (a shard), or
 * the merge of the parts' directories.
 *
 *   bsim_markov_build_def def = bsim_markov_build_def_default();
 *   def.experiment = "configs/markov/c_track.yaml";
 *   def.out = "out/markov-maps";
 *   def.method = BSIM_MARKOV_METHOD_MAPS;
 *   def.map.trials = 800;
 *   bsim_markov_build_result res;
 *   if (bsim_markov_build_run(&def, &res, &err) == BSIM_OK) {
 *           ... res.maps[0 .. res.n_maps) ...
 *           bsim_markov_build_result_free(&res);
 *   }
 *
 * DIR is a cache: maps already there with the same key are reused, the
 * others join the directory's set as each is finished (a stopped or
 * failed build keeps those), so that a finished build may be run again. */

/* One map of a build, as it was had (of the walks: one training field). */
typedef struct bsim_markov_built {
	int group;    /* the experiment's group whose lattice uses it (its first) */
	double k[2];  /* N m/rad, the gate's left and right beam (a field's start gate) */
	uint64_t key; /* the map's file name, map_%016llx (a field's: visits_%016llx) */
	int pass;     /* the set's pass (below def.map.self_passes: one round's) */
	int cached, copied, elsewhere; /* as bsim_markov_map's; none: built now */
} bsim_markov_built;

/* What markov build builds. */
typedef enum bsim_markov_method {
	/* The default: the visits of the nearest-neighbour walks' training
	 * fields (beamsim/markov_nearest.h), a field per gate kind, and
	 * markov.json naming the walks' settings; markov predict and
	 * validate --map walk over them. */
	BSIM_MARKOV_METHOD_NEAREST = 0,
	/* The single-gate maps of entry bins. */
	BSIM_MARKOV_METHOD_MAPS = 1,
} bsim_markov_method;

typedef struct bsim_markov_build_def {
	const char *experiment;    /* a lattice experiment file */
	const char *out;           /* the map directory */
	const bsim_override *sets; /* applied to every group */
	int n_sets;
	const bsim_grid_axis *grid; /* axes that replace or join the file's */
	int n_grid;
	int has_seed; /* 1: seed is the maps' (map.seed) and the experiment's */
	uint64_t seed;
	/* BSIM_MARKOV_METHOD_NEAREST: the training fields as nearest says
	 * (trials, k, seed, backend, opts, threads, progress, stop; its walks
	 * are the predictions'), the fields of every group's kinds and physics
	 * written into out as each finishes; map, entries, part, parts,
	 * round, passes and merge are the maps' (BSIM_EINPUT if set).
	 * BSIM_MARKOV_METHOD_MAPS: the maps, as the fields below say. */
	bsim_markov_method method;
	bsim_markov_nearest_def nearest;
	/* How each map is built: bins, trials, seed, backend and options,
	 * threads, self or flow entries and their passes, progress, stop and
	 * pass_exchange; entries, part, parts, part_first, from, n_from,
	 * one_pass and passes_from are this call's (below). */
	bsim_markov_def map;
	/* gate_entries.csv files (or directories holding one), read with
	 * bsim_markov_entries_load: a bin's states drawn from them. */
	const char *const *entries;
	int n_entries;
	/* A spread build (docs/cluster.md): part (1-based) of parts > 0 builds
	 * its maps only, the map j of the build (every group's pairs in turn)
	 * being part j mod parts + 1's, and writes out/part.json with the
	 * command line argc, argv. */
	int part, parts;
	/* Flow entries (map.self_entries 2) in a job array, one pass of the
	 * maps a round: round 1 makes a part (parts > 0) one pass, its states
	 * from the exits of passes, the merged directory of the round before
	 * (NULL: the first round), and a merge (below) join one round's parts.
	 * 0 for the parts of an MPI job, whose ranks meet after each pass
	 * (map.pass_exchange). */
	int round;
	const char *passes;
	int argc;
	char *const *argv;
	/* n_merge > 0: no single gate runs; the part directories merge[0 ..
	 * n_merge) are joined into out (map.from), the first checked to be a
	 * part of this build. */
	const char *const *merge;
	int n_merge;
	/* May be NULL: called after each group's maps are had, with its maps
	 * (the command's lines as they come). */
	void (*group_done)(void *user, int group, const bsim_markov_built *maps, int n);
	void *group_done_user;
} bsim_markov_build_def;

/* An entries value as the command line's --entries takes it: "self",
 * "self:N", "flow" or "flow:N" (N passes, 0 to BSIM_MARKOV_SELF_PASSES_MAX,
 * default 1) set def->self_entries (1 self, 2 flow) and def->self_passes,
 * def->start_trials 0 (the start bin's trials are then def->trials, as
 * those entries need), def->after_start 0, and *is_kind 1; any other
 * value is a gate_entries path (*is_kind 0, def untouched). BSIM_EINPUT
 * naming the value for a bad N. */
BSIM_API int bsim_markov_entries_kind(const char *value, bsim_markov_def *def, int *is_kind,
                                      bsim_error *err);

/* Where maps of def were measured to fall short on layouts they were not
 * built on, one sentence into buf. Maps of the default method (states from
 * a training field, bins at least as many as the default's, the default's
 * start trials or more and the gate after the start): where they missed
 * TV 0.05 and the nearest-neighbour walks did not (docs/markov.md, "A
 * kernel over exact states"). Flow entries: maps of one layout; self-consistent
 * entries, and the default method with coarser bins, fewer start trials
 * or no gate after the start: each measured less accurate there; entries
 * observed in sweeps: maps for layouts like the sweeps' (from a random
 * field of the kinds, as close as the default's or closer). buf of 320
 * bytes holds any. markov build and validate print it as a note. */
BSIM_API const char *bsim_markov_def_scope(const bsim_markov_def *def, char *buf, size_t size);

/* The method a build's options choose (markov build, the bindings):
 * method as given, "nearest" or "maps" (NULL: not given: maps if an
 * option of the maps' own was given, else the walks); maps_option the
 * first option given that only maps have (NULL: none), k_option the
 * walks' k if given (NULL: not), each as the caller spells it. BSIM_EINPUT
 * naming the option and the method it is for. */
BSIM_API int bsim_markov_build_method(const char *method, const char *maps_option,
                                      const char *k_option, bsim_markov_method *out,
                                      bsim_error *err);

/* What the build in dir holds (its markov.json): *method. BSIM_EINPUT,
 * naming file, line and field, if dir is no build of markov build, or a
 * damaged one, or another beamsim's. */
BSIM_API int bsim_markov_dir_method(const char *dir, bsim_markov_method *method, bsim_error *err);

/* The walks (bsim_markov_nearest_def_default() as nearest);
 * bsim_markov_def_default() as map, one process, no entries. */
BSIM_API bsim_markov_build_def bsim_markov_build_def_default(void);

typedef struct bsim_markov_build_result {
	int n_groups;
	int n_maps;                  /* every group's, in order (a map may serve two groups) */
	bsim_markov_built *maps;     /* n_maps */
	int built, reused;           /* maps simulated now, maps read from the cache */
	int next_built, next_reused; /* the gates after the start (map.after_start), likewise */
	int after_trials;            /* the start trials they continue; 0 without them */
	int copied;                  /* maps read from the parts' directories (a merge) */
	double seconds;              /* CPU time of the simulation of those built, s */
	int pass;                    /* a round's (or its merge's): the pass made; else
	                              * map.self_passes */
	int round;                   /* 1: one pass of flow entries (a part's or a merge's) */
	int n_bins;                  /* entry bins of a map, the start's included */
	char run[17];                /* the build's name (bsim_markov_run_id) */
	char scope[320];             /* bsim_markov_def_scope of the maps' method */
	bsim_markov_method method;   /* def's */
	long visits;                 /* the walks': every training field's visits */
} bsim_markov_build_result;

/* Builds the maps of every group of def->experiment into def->out.
 * BSIM_EINPUT for a bad experiment, entries file, directory or
 * combination (passes without a round, a merge of another build's parts);
 * BSIM_EFAIL for an unstable single gate or a failed file; BSIM_ESTOPPED
 * when def->map.stop stopped it (the maps finished are kept: the same call
 * builds the rest). On any error res holds nothing to free. */
BSIM_API int bsim_markov_build_run(const bsim_markov_build_def *def, bsim_markov_build_result *res,
                                   bsim_error *err);
BSIM_API void bsim_markov_build_result_free(bsim_markov_build_result *res);

/* The chains small enough for the exact LU solve. */
#define BSIM_MARKOV_LU_MAX 1000

typedef struct bsim_markov_prediction {
	int n_locations;
	bsim_location *loc; /* ends by ix, sides by iy, stuck gates by (iy, ix) */
	double *p;          /* their probabilities */
	int n_gates;        /* p_gates has n_gates + 1 entries */
	double *p_gates;    /* p_gates[k]: k gates visited, the start counted */
	double mean_gates;
	double left_in_field; /* probability the series or sweeps had not absorbed:
	                       * each location's p is short by at most this */
	double tol;           /* the tolerance the sweeps and series stopped at */
	int n_states;         /* transient states (gate, entry bin) */
	int exact;            /* 1: p by LU, 0: by the sweeps */
	int sweeps;           /* Gauss-Seidel sweeps that gave p (0: the series) */
	/* Time to the outcome (the semi-Markov chain), when every map has
	 * holding times (has_time 1; else 0 and the times NAN). mean_time: the
	 * expected time of the outcome event, s (an exit, or the per-gate
	 * limit), by first-step analysis: the sum over states of the expected
	 * visits times the state's mean holding time, without the trial's
	 * duration; short like p by what is left in the field. */
	int has_time;
	double mean_time;
	/* Filled by bsim_markov_predict_time (walks 0 before): the outcome at
	 * the trial's duration, as a lattice trial ends: stuck when a gate has
	 * held the body gate_steps steps or when max_steps steps have passed
	 * (duration = max_steps dt), else out at the end or a side. */
	long walks;
	double duration;    /* s */
	double time_bin;    /* s, the width of p_time's bins */
	int n_time_bins;    /* bins covering [0, duration] */
	double *p_time;     /* [bin * 3 + kind] (end, side, stuck): probability the
	                     * outcome happens in the bin (stuck: when it is declared) */
	double p_by[3];     /* end, side, stuck at the duration */
	double t_mean[3];   /* s, mean time of each kind's outcome (NAN if none) */
	double t_sd[3];     /* s, its standard deviation over the walks */
	double *p_loc_time; /* n_locations: the final locations at the duration */
	/* > 0: p by that many nearest-neighbour walks (beamsim/markov_nearest.h)
	 * over n_states visits, each step drawn from the nearest_k nearest;
	 * 0: by the chain. */
	long nearest_walks;
	int nearest_k;
} bsim_markov_prediction;

/* The series stops when less than this is left in the field: far below
 * the maps' own sampling error (a TV of 0.02 at 800 trials per bin). */
#define BSIM_MARKOV_TOL 1e-6

/* A tolerance tied to the maps' own sampling error: a transition
 * probability estimated from T single gates has a standard error of at
 * most 0.5 / sqrt(T); stopping with less than 1/16 of that in the field,
 *   tol = 1 / (32 sqrt(T))     (1.1e-3 at 800 trials per bin),
 * moves every location's p by at most tol and the total variation from the
 * solution to 1e-12 by at most tol, against the maps' own 0.017 (mean TV of
 * chains of resampled 800-trial maps on the C-track, docs/markov.md). T:
 * the fewest trials per bin of set's maps. */
BSIM_API double bsim_markov_tol_sampling(const bsim_markov_set *set);

/* The chain of lattice composed from set's maps, solved; the series to
 * BSIM_MARKOV_TOL. */
BSIM_API int bsim_markov_predict(const bsim_scene *lattice, const bsim_markov_set *set,
                                 bsim_markov_prediction *out, bsim_error *err);
/* The same, the series summed until less than tol (in (0, 1)) is left in
 * the field; BSIM_EINPUT for another tol. */
BSIM_API int bsim_markov_predict_tol(const bsim_scene *lattice, const bsim_markov_set *set,
                                     double tol, bsim_markov_prediction *out, bsim_error *err);
/* bsim_markov_predict_with's flags: p by the series, which also gives
 * the distribution of gates visited. Without it p is by Gauss-Seidel
 * sweeps (faster), n_gates = 0, p_gates = {0}, and mean_gates is the
 * expected number of gates entered. */
#define BSIM_MARKOV_GATES 1
/* The same as bsim_markov_predict_tol (which is flags =
 * BSIM_MARKOV_GATES); flags 0 is the fastest. */
BSIM_API int bsim_markov_predict_with(const bsim_scene *lattice, const bsim_markov_set *set,
                                      double tol, int flags, bsim_markov_prediction *out,
                                      bsim_error *err);
BSIM_API void bsim_markov_prediction_free(bsim_markov_prediction *p);

/* The distribution of the time to the outcome, by walks of the semi-Markov
 * chain: each walk starts in the start state; in a gate of map m entered
 * in bin a it takes one of the map's single gates of that bin (uniformly
 * among its trials: the map's joint distribution of exit and holding
 * time), adds its steps to the walk's and follows its exit, until the
 * end, a side, a gate's limit (exit 0) or max_steps steps in all (then
 * stuck in the gate it is in). Walks seeded from seed alone, one after the
 * other: the same answer on any machine. The walks' own error on a
 * probability p is sqrt(p (1 - p) / walks). Fills p's walks, duration,
 * time_bin (the time step times an integer, about duration / 200),
 * n_time_bins, p_time, p_by, t_mean, t_sd and p_loc_time; BSIM_EINPUT if a
 * map has no holding times (naming the command that rebuilds it) or walks
 * is not 1 to 1e8. */
BSIM_API int bsim_markov_predict_time(const bsim_scene *lattice, const bsim_markov_set *set,
                                      long walks, uint64_t seed, bsim_markov_prediction *p,
                                      bsim_error *err);
#define BSIM_MARKOV_WALKS 100000

/* Writes p, the prediction of lattice by the chain of set's maps, into
 * the output directory dir (overwrite 1: replacing the result it holds;
 * 0: refusing it, BSIM_EINPUT): prediction.csv (location, kind, ix, iy, p:
 * every final location of the field), prediction_gates.csv (gates, p),
 * their .mat twins and the figure prediction (.png .svg .gp .dat): the
 * final locations drawn as the field with the totals of end, side and
 * stuck. */
BSIM_API int bsim_markov_prediction_store(const char *dir, int overwrite, const bsim_scene *lattice,
                                          const bsim_markov_set *set,
                                          const bsim_markov_prediction *p, bsim_error *err);

/* ---- a prediction from a map directory ---------------------------------
 *
 * beamsim markov predict LATTICE_SCENE --map DIR [--out OUT]: the scene
 * loaded, the maps read from DIR (bsim_markov_load), the chain solved
 * (bsim_markov_predict_with), the time to the outcome by walks
 * (bsim_markov_predict_time, when the maps have holding times) and, with
 * out, the prediction's files (bsim_markov_prediction_store). */
typedef struct bsim_markov_predict_def {
	const char *scene; /* a lattice scene file */
	const bsim_override *sets;
	int n_sets;
	const char *map_dir; /* the map directory of a build */
	const char *out;     /* NULL: no files */
	int overwrite;       /* 1: replace the result out holds; 0: refuse it */
	/* How the caller spells overwrite in the refusal (NULL: "--overwrite"). */
	const char *overwrite_option;
	double tol; /* in (0, 1); <= 0: bsim_markov_tol_sampling of the maps */
	int gates;  /* 1: the distribution of gates visited (the series); 0: not;
	             * -1: with out only */
	long walks; /* walks of the semi-Markov chain, 0 to 1e8; 0: none */
	/* NULL: the chain of the maps in map_dir. Else the prediction is by
	 * nearest-neighbour walks (beamsim/markov_nearest.h, as nearest says)
	 * over the visits in this directory, their training fields run there
	 * where missing (bsim_markov_visits_build); map_dir, tol, gates and
	 * walks are not used. */
	const char *visits_dir;
	bsim_markov_nearest_def nearest;
} bsim_markov_predict_def;

/* The maps' sampling tolerance, gates with out only, BSIM_MARKOV_WALKS. */
BSIM_API bsim_markov_predict_def bsim_markov_predict_def_default(void);

typedef struct bsim_markov_predict_result {
	bsim_scene scene; /* as loaded, the sets applied */
	int n_maps;
	bsim_markov_prediction p; /* p.tol: the tolerance used */
	double total[3];          /* p summed by kind: end, side, stuck */
	double seconds;           /* wall time of the chain composed and solved (maps read) */
	double cpu_seconds;       /* the thread's CPU time of the same (of the walks: the
	                           * process's, on every thread) */
	/* With visits_dir: the training fields (n_maps of them), those run now
	 * and what all took when they were run (s of CPU). */
	int fields_built;
	double fields_cost;
	double tv_walks; /* the walks' own sampling error (bsim_markov_nearest_tv_walks) */
} bsim_markov_predict_result;

/* Predicts def->scene from the maps in def->map_dir. BSIM_EINPUT for a bad
 * scene, map directory, tol or walks, or an out that is refused (before
 * the chain is solved); BSIM_EFAIL for a file that fails. On any error res
 * holds nothing to free. */
BSIM_API int bsim_markov_predict_run(const bsim_markov_predict_def *def,
                                     bsim_markov_predict_result *res, bsim_error *err);
BSIM_API void bsim_markov_predict_result_free(bsim_markov_predict_result *res);

/* res as one JSON object on f, with a newline (markov predict --json):
 * scene (the path scene_path as given), name, columns, rows, maps,
 * states, solve, totals, mean_gates, left_in_field, tol, sweeps,
 * mean_time, with walks: walks, duration and at_duration; predict_seconds,
 * predict_cpu_seconds, locations (location, kind, p) and p_gates. */
BSIM_API void bsim_markov_predict_json(FILE *f, const char *scene_path,
                                       const bsim_markov_predict_result *res);

/* The entry bin of a state in a gate's frame entered through edge
 * (BSIM_EDGE_BOTTOM .. BSIM_EDGE_TOP) at pos along it with velocity v; the
 * start is bin 0. For tools that bin a simulation's gate entries. */
BSIM_API int bsim_markov_bin_of(const bsim_markov_bins *b, const bsim_lattice_def *l, int edge,
                                double pos, const double v[2]);

/* ---- validation against the simulation ---------------------------------
 *
 * beamsim markov validate: every group of a lattice experiment simulated
 * directly (bsim_sweep_run, on the maps' backend) under the essay's
 * protocol and the whole world, and predicted by the chain from the maps
 * in map_dir. The distance is the total variation
 *   TV(p, q) = 1/2 sum over final locations |p - q|.
 * Beside it, the simulation's own sampling error: the mean (and 95th
 * percentile) of TV between the simulated distribution and multinomial
 * resamples of it with the same number of trials (a parametric bootstrap),
 * and the map's: the mean TV between the chain and chains of maps whose
 * rows are resampled the same way. Cost: the simulation's CPU time against
 * the prediction's (the mean of repeated predictions), and the number of
 * lattices after which building the maps pays off. */

typedef struct bsim_markov_validate_def {
	const char *experiment; /* a lattice experiment file */
	const char *map_dir;
	const char *out;           /* the output directory */
	const bsim_override *sets; /* --set, every group */
	int n_sets;
	/* Grid axes that replace or join the file's (bsim_experiment_load_grid). */
	const bsim_grid_axis *grid;
	int n_grid;
	long trials;  /* 0: the experiment's */
	int has_seed; /* 1: seed replaces the experiment's */
	uint64_t seed;
	int threads;               /* <= 0: all cores */
	int bootstrap;             /* resamples of the simulation; default 2000 */
	int map_resamples;         /* resamples of the maps; default 40 */
	bsim_progress_fn progress; /* may be NULL; counts trials simulated */
	void *progress_user;
	/* The simulated trials are journaled in out as they end (both
	 * protocols' sweeps, one journal): with resume a stopped or killed
	 * run continues (same inputs), losing no finished trial. */
	int resume;
	/* 1: replace the finished result or stopped run in out; 0: refuse it */
	int overwrite;
	const char *resume_option;    /* as bsim_sweep_dir_def's (NULL: "--resume") */
	const char *overwrite_option; /* as bsim_sweep_dir_def's (NULL: "--overwrite") */
	/* NULL, or a flag (a signal handler's): once nonzero no trial starts,
	 * nor another of the maps' resamples, and the run returns
	 * BSIM_ESTOPPED with the journal kept. */
	const volatile sig_atomic_t *stop;
	/* Spread over processes (beamsim/sweep_dir.h, docs/cluster.md): a
	 * shard writes a part directory into out, an MPI rank other than 0
	 * writes nothing; merge joins the parts. All zero: one process. */
	bsim_sweep_spread spread;
	/* NULL: the chain of the maps in map_dir. Else the prediction is by
	 * nearest-neighbour walks over the visits in this directory, as
	 * markov predict's (bsim_markov_predict_def), their training fields
	 * run there first where missing, before any trial; the simulation on
	 * nearest's backend. A check's tv_map is then the walks' own sampling
	 * error (bsim_markov_nearest_tv_walks), predict the walks' CPU time,
	 * and the validation's map_cost the training fields'. */
	const char *visits_dir;
	bsim_markov_nearest_def nearest;
} bsim_markov_validate_def;

BSIM_API bsim_markov_validate_def bsim_markov_validate_def_default(void);

/* One group under one protocol. */
typedef struct bsim_markov_check {
	int group;
	bsim_protocol protocol;
	int trials;
	double tv;                     /* chain against simulation */
	double tv_sampling;            /* mean TV of the simulation's resamples */
	double tv_sampling95;          /* their 95th percentile */
	double tv_map;                 /* mean TV of the chain from resampled maps */
	double gates_sim, gates_chain; /* mean gates visited */
	double sim_cpu;                /* s, the direct simulation */
	double predict; /* s of CPU, one prediction as markov predict makes it by default */
	int n_states, exact;
	/* Time to the outcome, when the maps have holding times (has_time; else
	 * the times NAN): the trials out (the end or a side) by the trial's
	 * duration, simulated (t_exit, trials.csv's) against the chain's
	 * BSIM_MARKOV_WALKS walks (bsim_markov_predict_time). Intervals: 95%,
	 * Wilson's for shares, 1.96 standard errors for means; the walks' and
	 * the simulation's sampling errors in the difference's, the maps' not. */
	int has_time;
	double out_sim, out_sim_lo, out_sim_hi; /* share out by the duration */
	double out_chain;                       /* the walks' */
	double t_out_sim, t_out_sim_ci;         /* s, mean exit time of those out, +- */
	double t_out_chain, t_out_chain_ci;     /* s, the walks' */
	double t_out_diff_ci;                   /* s, +- of t_out_chain - t_out_sim */
	double t_ks;   /* sup over the time grid of |P(out by t) simulated - chain| */
	double t_ks95; /* the simulation's own 95% band on it (Dvoretzky-Kiefer-Wolfowitz,
	                * sqrt(ln(2 / 0.05) / (2 trials))) */
} bsim_markov_check;

typedef struct bsim_markov_validation {
	int n;
	bsim_markov_check *checks; /* group-major, essay then world */
	double map_cost;           /* s of CPU the maps took to build (every pass) */
	long long map_steps;       /* single-gate steps those builds took */
	int bins, trials_per_bin;
	/* 1: the bins count a training field's crossings, topped up to
	 * per_crossing single gates a crossing (0: to trials_per_bin), as the
	 * maps' bsim_markov_map of_crossings and per_crossing */
	int of_crossings, per_crossing;
	char scope[320]; /* bsim_markov_def_scope of the maps' method ("" the default) */
	/* The walks' (0 for maps): their number, k and the training fields'
	 * trials, as given or as the build in map_dir set them. */
	long nearest_walks;
	int nearest_k, nearest_trials;
	/* When the run stopped or failed after finishing trials: the journal
	 * that resume continues from ("" otherwise). */
	char journal[BSIM_PATH_MAX];
} bsim_markov_validation;

/* Runs the validation and writes out: validate.json (every check),
 * time_validate.csv (group, protocol, t, P(out by t) simulated and by the
 * chain, on the chain's time grid; with holding times),
 * validate.csv (group, protocol, location, simulated p with its Wilson 95%
 * interval, predicted p), gates.csv (the distribution of gates visited,
 * simulated and predicted), their .mat twins, and the figure
 * validate_gNNN (.png .svg .gp) per group. */
BSIM_API int bsim_markov_validate(const bsim_markov_validate_def *def, bsim_markov_validation *out,
                                  bsim_error *err);
BSIM_API void bsim_markov_validation_free(bsim_markov_validation *v);

#ifdef __cplusplus
}
#endif
#endif
