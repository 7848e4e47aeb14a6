/* A sweep: every (group, trial) of an experiment on one backend, in parallel
 * (OpenMP), with results independent of the number of threads. */
#ifndef BSIM_SWEEP_H
#define BSIM_SWEEP_H

#include <signal.h>
#include <stddef.h>

#include "beamsim/base.h"
#include "beamsim/backend.h"
#include "beamsim/experiment.h"
#include "beamsim/lattice_outcome.h"
#include "beamsim/options.h"
#include "beamsim/trajectory.h"
#include "beamsim/progress.h"
#include "beamsim/trial.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A journal of finished trials (kept inside the library: bsim_sweep_dir_run
 * and bsim_compare_dir_run give a sweep one). */
typedef struct bsim_journal bsim_journal;

typedef struct bsim_group_result {
	int trials, traversed, side_exit, stuck, left, right;
	int unstable;      /* trials whose backend failed (bsim_instability) */
	int deterministic; /* 1: the scene draws no random numbers, so every trial
	                    * is the same trial: it ran once, the others are copies,
	                    * and ci95 is the point p_traverse */
	int stuck_in_contact;
	int landscape_left, landscape_right; /* traversed over beam 0's / 1's barrier */
	double p_traverse, ci95[2];          /* Wilson 95% */
	long steps;                          /* steps integrated in the group */
	bsim_solver_counts solver;           /* of the trials integrated (beamsim/state.h) */
	/* Trials (copies too) that hit an iteration limit, and a clamp: the
	 * trials whose motion is partly the solver's, not the model's. */
	int trials_iteration_limit, trials_clamped;
	/* The body's turn over the group's trials (copies too), rad: the mean
	 * of turn_end (a bias to one side), of |turn_end| (how far the bodies
	 * ended turned), the largest |turn_end| and the largest turn_max
	 * (beamsim/trial.h). rotates: the group's body rotates (body.rotates),
	 * so that summary.json gives them; set by the sweep from its scenes (0
	 * for groups read back from trials.csv). */
	int rotates;
	double turn_end_mean, turn_end_mean_abs, turn_end_max_abs, turn_max;
} bsim_group_result;

/* The members summary.json and MATLAB's beamsim_sweep give of each group
 * as they are, by their names, named once here as X-macros (X(member)): the
 * counts, in this order (ci95 a pair); the trials the solver gave up on;
 * the turn, where the body rotates. deterministic, solver, rotates they
 * give in a form of their own. */
#define BSIM_GROUP_RESULT_COUNTS(X)                                                                \
	X(trials)                                                                                  \
	X(traversed)                                                                               \
	X(side_exit)                                                                               \
	X(stuck)                                                                                   \
	X(left)                                                                                    \
	X(right)                                                                                   \
	X(p_traverse)                                                                              \
	X(ci95)                                                                                    \
	X(stuck_in_contact)                                                                        \
	X(landscape_left)                                                                          \
	X(landscape_right)                                                                         \
	X(steps)                                                                                   \
	X(unstable)
#define BSIM_GROUP_RESULT_SOLVER_TRIALS(X) X(trials_iteration_limit) X(trials_clamped)
#define BSIM_GROUP_RESULT_TURN(X)                                                                  \
	X(turn_end_mean) X(turn_end_mean_abs) X(turn_end_max_abs) X(turn_max)

/* Consecutive trials of a sweep, handed to a sink (bsim_sweep_config.sink)
 * in index order: trial first + k is results[k], with its gate path and
 * peaks in logs[k]. Valid only during the call. */
typedef struct bsim_sweep_block {
	long first; /* index g * trials + t of results[0] */
	long n;
	const bsim_trial_result *results;
	const bsim_trial_log *logs;
} bsim_sweep_block;

/* A sink's answer other than BSIM_OK (err set) stops the sweep with it. */
typedef int (*bsim_sweep_sink_fn)(void *user, const bsim_sweep_block *block, bsim_error *err);

typedef struct bsim_sweep_result {
	int n_groups, trials;
	bsim_trial_result *trials_out; /* n_groups * trials, index g*trials + t */
	bsim_group_result *groups;     /* n_groups */
	double wall_seconds;
	long total_steps;          /* steps integrated (a deterministic group's one trial) */
	long trials_run;           /* trials integrated: copies of a deterministic group's not */
	bsim_solver_counts solver; /* over the trials integrated */
	int has_ledger;            /* 1: the trials' ledgers are known (a run, or a trials.csv
	                            * with the energy columns) */
	int has_turn;              /* 1: the trials' turns are known (a run, or a trials.csv
	                            * with heading_end, ...) */
	int keep;                  /* trajectories kept per group (its first trials) */
	bsim_trajectory *kept;     /* n_groups * keep, index g*keep + t; NULL if keep = 0 */
	/* Each trial's gate path with entry states and the peaks of every
	 * beam; same index as trials_out. NULL when read back from trials.csv. */
	bsim_trial_log *logs;
	int lattice;                  /* 1: the groups' scenes are gate lattices */
	bsim_lattice_def lattice_def; /* group 0's, when lattice */
	/* A streamed sweep's first unstable trial (its index, -1 none) and its
	 * result, since trials_out is not kept. */
	long first_unstable;
	bsim_trial_result first_unstable_result;
	/* A streamed lattice sweep's final locations, transitions and time per
	 * row, per group (n_groups), since its trials are not kept; NULL
	 * otherwise (bsim_lattice_summarise them from trials_out and logs). */
	bsim_lattice_summary *lattice_summaries;
} bsim_sweep_result;

typedef struct bsim_sweep_config {
	const bsim_backend *backend;
	const bsim_options *opts;
	int threads;                /* <= 0: all available */
	const bsim_override *extra; /* command-line --set, applied to every group */
	int n_extra;
	bsim_progress_fn progress; /* may be NULL */
	void *progress_user;
	bsim_plan_fn planned; /* may be NULL: said by bsim_sweep_plan_for */
	void *planned_user;
	/* NULL, or every group's scene with extra applied (bsim_sweep_plan_for's):
	 * lent to the sweep, which reads them and neither builds them again nor
	 * frees them. */
	bsim_scene *scenes;
	int measure_overlap; /* 1: each trial's overlap_max (plain sweeps only) */
	int keep;            /* keep the trajectories of the first keep trials of each group */
	int keep_stride;     /* of those, a row every keep_stride steps (<= 0: 5) */
	/* A sweep of sides only: overrides applied after extra to the second
	 * side's scenes (e.g. lattice.protocol=essay), so that side can differ
	 * from the others in the scene while sharing every schedule. */
	const bsim_override *extra_b;
	int n_extra_b;
	/* NULL, or a journal of records of
	 * bsim_sweep_record_size bytes, created or resumed for this sweep's
	 * inputs: the trials it holds are taken from it, not run again, and
	 * each trial run is appended as it ends. */
	bsim_journal *journal;
	/* NULL, or a flag a signal handler sets: once it is nonzero no trial
	 * starts, those running finish (and are journaled), and the sweep
	 * returns BSIM_ESTOPPED. */
	const volatile sig_atomic_t *stop;
	/* NULL, or where a plain sweep (bsim_sweep_run) streams its trials:
	 * they run in blocks of BSIM_SWEEP_BLOCK consecutive indices, each
	 * block goes to sink once it is finished, in index order, and is then
	 * forgotten, so memory does not grow with the number of trials. The
	 * result then has no trials_out and no logs, only the groups (and any
	 * kept trajectories), and for a lattice each group's summary
	 * (lattice_summaries). */
	bsim_sweep_sink_fn sink;
	void *sink_user;
	/* One of several sweeps sharing one journal (beamsim markov validate,
	 * essay; unstreamed sweeps and parts): trial i is the journal's record
	 * journal_first + i, and the journal's records are indices 0 ..
	 * journal_total - 1 (0: this sweep's alone). A part's trial i is part
	 * (journal_first + i) mod count's, and its done bits, records and the
	 * records collected from other parts are by journal index. */
	long journal_first, journal_total;
	/* 1: the caller uses the trials' results only, not their gate paths
	 * (trials_out, not logs): a lattice's trials are taken from the
	 * journal too, instead of running again. */
	int results_only;
} bsim_sweep_config;

/* Trials per block of a streamed sweep: about 30 MB of results and gate
 * paths in memory at a time, and few enough blocks that the threads wait
 * at a block's end only for its slowest trial. */
#define BSIM_SWEEP_BLOCK 65536

/* The default backend (beamsim/backend.h) with its default options, all
 * threads, no overrides, no progress, nothing kept, no journal, no stop
 * flag. */
BSIM_API bsim_sweep_config bsim_sweep_config_default(void);

/* A sweep of sides (beamsim compare) runs every trial on 2 to this many
 * sides (backends, or settings of one) with the same schedule. */
#define BSIM_SWEEP_SIDES_MAX 8
/* Pairs of sides: BSIM_SWEEP_SIDES_MAX choose 2. */
#define BSIM_SWEEP_PAIRS_MAX (BSIM_SWEEP_SIDES_MAX * (BSIM_SWEEP_SIDES_MAX - 1) / 2)

/* The pairs of n sides, n (n - 1) / 2, and pair k's two sides (side[0] <
 * side[1]): the pairs in the order (0, 1), (0, 2), ..., (0, n-1), (1, 2),
 * ..., so that the pair of two sides is pair 0 and a side's pairs with the
 * sides before it come first. */
BSIM_API int bsim_sweep_pairs(int n_sides);
BSIM_API void bsim_sweep_pair(int n_sides, int k, int side[2]);

/* The size of one journal record: a bsim_trial_result, or for a sweep of
 * paired = 1 two sides both results and the separation time. The record
 * is the result's bytes as they are in memory, so a resumed sweep's
 * results are the uninterrupted sweep's to the bit. */
BSIM_API size_t bsim_sweep_record_size(int paired);
/* The same for a sweep of n_sides >= 2 sides: each side's result in order,
 * then each pair's separation time (a double) in bsim_sweep_pair's order;
 * for two sides bsim_sweep_record_size(1). */
BSIM_API size_t bsim_sweep_record_size_sides(int n_sides);

/* The size of the journal records of the plain sweep of e with cfg (its
 * --set in cfg->extra): bsim_sweep_record_size(0), or for a lattice (unless
 * cfg->results_only) the result, then its gate path (a fixed number of
 * entries) and the peaks of the beams it moved (a fixed number: a longer
 * path or more moved beams are marked, and the trial runs again where the
 * records are read), so that the lattice's files can be written from the
 * journal. BSIM_EINPUT if a group's scene cannot be built. */
BSIM_API int bsim_sweep_record_size_for(const bsim_experiment *e, const bsim_sweep_config *cfg,
                                        size_t *size, bsim_error *err);

/* A sweep of n_sides sides (1: a plain sweep) planned once: every group's
 * scene built (cfg's extra applied) into *scenes, for cfg->scenes and the
 * caller's files, the record's size as bsim_sweep_record_size_for (or
 * _sides_for) gives it, and the plan said to cfg->planned (bsim_plan_fn:
 * the beam-steps one side's trials take at most) where it is given,
 * before any trial runs or any file is opened. The scenes are the
 * caller's: bsim_sweep_scenes_free. */
BSIM_API int bsim_sweep_plan_for(const bsim_experiment *e, const bsim_sweep_config *cfg,
                                 int n_sides, size_t *size, bsim_scene **scenes, bsim_error *err);
BSIM_API void bsim_sweep_scenes_free(bsim_scene *scenes, int n_groups);

/* The same for the sweep of e on n_sides sides with cfg (the second side's
 * overrides in cfg->extra_b): bsim_sweep_record_size_sides(n_sides), or
 * for a lattice each side's result, gate path and peaks, then the pairs'
 * separation times. bsim_sweep_record_size_paired_for is n_sides = 2. */
BSIM_API int bsim_sweep_record_size_sides_for(const bsim_experiment *e,
                                              const bsim_sweep_config *cfg, int n_sides,
                                              size_t *size, bsim_error *err);
BSIM_API int bsim_sweep_record_size_paired_for(const bsim_experiment *e,
                                               const bsim_sweep_config *cfg, size_t *size,
                                               bsim_error *err);

/* Runs the sweep. e->trials and e->seed are used as they are (the caller
 * applies --trials/--seed). BSIM_ESTOPPED (see cfg->stop) says how many
 * trials were finished. */
BSIM_API int bsim_sweep_run(const bsim_experiment *e, const bsim_sweep_config *cfg,
                            bsim_sweep_result *out, bsim_error *err);

/* The same sweep run on n_sides sides (beamsim compare), 2 to
 * BSIM_SWEEP_SIDES_MAX: every trial runs on backend[s] with opts[s] into
 * out[s] for each side s, with the same schedule (cfg->backend and
 * cfg->opts are not used). t_separate (malloc'd, pairs x n_groups x
 * trials, index (k * n_groups + g) * trials + t for pair k in
 * bsim_sweep_pair's order) gets the time, s, at which the two sides' body
 * centres first lie more than 1% of the body radius apart, -1 if never
 * while both ran. Each out[s] equals what bsim_sweep_run gives for its
 * side. */
BSIM_API int bsim_sweep_run_sides(const bsim_experiment *e, const bsim_sweep_config *cfg,
                                  int n_sides, const bsim_backend *const *backend,
                                  const bsim_options *const *opts, bsim_sweep_result *out,
                                  double **t_separate, bsim_error *err);

/* Two sides: cfg->backend into out_a, backend_b into out_b. */
BSIM_API int bsim_sweep_run_paired(const bsim_experiment *e, const bsim_sweep_config *cfg,
                                   const bsim_backend *backend_b, const bsim_options *opts_b,
                                   bsim_sweep_result *out_a, bsim_sweep_result *out_b,
                                   double **t_separate, bsim_error *err);
BSIM_API void bsim_sweep_result_free(bsim_sweep_result *r);

/* ---- a sweep spread over processes (MPI ranks, job-array tasks) ---------
 *
 * Trial i (= g * trials + t) belongs to part i mod count: parts take turns
 * along the flat (group, trial) list, so each part holds about the same
 * share of every group (groups differ in cost, so contiguous blocks would
 * not). A part runs its trials and hands their journal records on (to
 * cfg->journal, to record); the whole sweep is then the ordinary sweep
 * resumed from a journal holding every part's records, so its results are
 * one process's to the bit whatever the number of parts. */

/* Hands one received record to the part runner (collect's accept). */
typedef int (*bsim_sweep_accept_fn)(void *ctx, long index, const void *payload, bsim_error *err);

typedef struct bsim_sweep_part {
	int index, count; /* this part, 0 <= index < count */
	/* NULL, or a bit per trial (bit i % 8 of byte i / 8) of the trials
	 * already done (in a journal): not run again by any part. */
	const unsigned char *done;
	/* NULL, or called with each trial's journal record as it ends, from
	 * any thread (the callee serialises); nonzero stops the part with err. */
	int (*record)(void *user, long index, const void *payload, bsim_error *err);
	/* NULL, or called on the calling thread (the one that called
	 * bsim_sweep_run_part) between trials with wait 0, and once after this
	 * part's own trials with wait 1, to hand the records other parts sent
	 * to accept(ctx, ...) (appended to cfg->journal); with wait 1 it
	 * returns once every other part has ended, with the first one's error
	 * if one failed. */
	int (*collect)(void *user, int wait, bsim_sweep_accept_fn accept, void *ctx,
	               bsim_error *err);
	void *user;
	/* NULL, or told the size of the records that record and collect carry
	 * before the part runs (bsim_sweep_record_size_for: a lattice's are
	 * larger); called by the spreading of bsim_sweep_dir_run. */
	void (*sized)(void *user, size_t record_size);
} bsim_sweep_part;

/* Runs part's trials of the sweep of e (cfg->sink and keep are not used): each trial not marked in
 * part->done runs and its record goes to cfg->journal (if not NULL; already replayed) and to
 * part->record. A deterministic group's copies are not run (its trial 0 stands for them).
 * cfg->progress gets this part's trials done and its total, or with collect the trials of every
 * part (done bits and records received included) and the sweep's total. BSIM_ESTOPPED when
 * cfg->stop stopped it. */
BSIM_API int bsim_sweep_run_part(const bsim_experiment *e, const bsim_sweep_config *cfg,
                                 const bsim_sweep_part *part, bsim_error *err);

/* The same for a sweep of sides (beamsim compare): each trial runs on
 * every side as bsim_sweep_run_sides runs it, its record every side's
 * result and the pairs' separation times (bsim_sweep_record_size_sides_for:
 * a lattice's hold every side's gate path and peaks too). The paired part
 * is two sides, cfg->backend's and backend_b's. */
BSIM_API int bsim_sweep_run_part_sides(const bsim_experiment *e, const bsim_sweep_config *cfg,
                                       int n_sides, const bsim_backend *const *backend,
                                       const bsim_options *const *opts, const bsim_sweep_part *part,
                                       bsim_error *err);
BSIM_API int bsim_sweep_run_part_paired(const bsim_experiment *e, const bsim_sweep_config *cfg,
                                        const bsim_backend *backend_b, const bsim_options *opts_b,
                                        const bsim_sweep_part *part, bsim_error *err);

/* Aggregates one group's trials into counts, the Wilson interval and the
 * turn's statistics (rotates, which the trials do not say, left 0). */
BSIM_API void bsim_sweep_group_aggregate(const bsim_trial_result *trials, int n,
                                         bsim_group_result *out);

#ifdef __cplusplus
}
#endif
#endif
