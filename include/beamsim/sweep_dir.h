/* A sweep stored in an output directory (beamsim sweep EXPERIMENT --out
 * DIR): the experiment loaded with its overrides, every trial run
 * (beamsim/sweep.h), and DIR written as one set (docs/files.md):
 * summary.json, trials.csv, trajectories.csv when trajectories are kept,
 * the lattice's files for a lattice, their .mat twins, and the record that
 * lets the run be repeated, run.json and inputs/ (beamsim/run_record.h).
 *
 *   bsim_sweep_dir_def def = bsim_sweep_dir_def_default();
 *   def.experiment = "configs/thesis/h1_symmetric.yaml";
 *   def.out = "out/h1";
 *   bsim_sweep_dir_result res;
 *   if (bsim_sweep_dir_run(&def, &res, &err) == BSIM_OK) {
 *           ... res.e, res.r ...
 *           bsim_sweep_dir_result_free(&res);
 *   }
 *
 * DIR is checked (created if missing, writable, not in use by another run)
 * before any trial runs. The files appear together when the whole sweep has
 * succeeded; until then DIR holds what it held. Finished trials are
 * journaled as they end (DIR/.beamsim/journal), so a run stopped through
 * def.stop or killed continues with def.resume and writes the files an
 * uninterrupted run writes, byte for byte. */
#ifndef BSIM_SWEEP_DIR_H
#define BSIM_SWEEP_DIR_H

#include <signal.h>
#include <stdint.h>

#include "beamsim/base.h"
#include "beamsim/limits.h"
#include "beamsim/backend.h"
#include "beamsim/experiment.h"
#include "beamsim/sweep.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct bsim_sweep_dir_def {
	const char *experiment;    /* the experiment file */
	const char *out;           /* the output directory */
	const bsim_override *sets; /* applied to every group, after the file's set: */
	int n_sets;
	/* Grid axes that replace or join the file's (bsim_experiment_load_grid). */
	const bsim_grid_axis *grid;
	int n_grid;
	long trials;  /* > 0: trials per group instead of the file's */
	int has_seed; /* 1: seed instead of the file's */
	uint64_t seed;
	const bsim_backend *backend; /* default: bsim_backend_default() */
	bsim_options opts;           /* the backend's options (beamsim/options.h) */
	int threads;                 /* <= 0: all cores */
	int overlap;                 /* 1: each trial's deepest body-beam overlap */
	int keep;                    /* trajectories kept per group (trajectories.csv) */
	int keep_stride;             /* a kept row every keep_stride steps (<= 0: 5) */
	int resume;                  /* 1: continue the stopped run in out (same inputs) */
	int overwrite; /* 1: replace the finished result, or a stopped run's journal, in
	                * out; 0: such an out is refused (BSIM_EINPUT) */
	/* How the caller spells resume and overwrite in messages about them
	 * ("add --resume to continue it"): NULL the command line's "--resume"
	 * and "--overwrite"; a binding names its own arguments ("resume=True"). */
	const char *resume_option;
	const char *overwrite_option;
	bsim_progress_fn progress; /* may be NULL */
	void *progress_user;
	bsim_plan_fn planned; /* may be NULL: the sweep's plan, before its first trial */
	void *planned_user;
	/* NULL, or a flag (set by a signal handler, say): once nonzero no trial
	 * starts, those running finish and are journaled, and the run returns
	 * BSIM_ESTOPPED with the journal kept for resume. */
	const volatile sig_atomic_t *stop;
	/* Spreading the sweep over processes (docs/cluster.md):
	 *   BSIM_SPREAD_NONE    the whole sweep here (default);
	 *   BSIM_SPREAD_SHARD   part.index of part.count (a job-array task): out
	 *                       becomes a part directory (part.json and
	 *                       part.journal, no results) for merge below;
	 *   BSIM_SPREAD_GATHER  this process's part, the others' records taken
	 *                       through part.collect and journaled; then out is
	 *                       written as one process writes it (MPI rank 0);
	 *   BSIM_SPREAD_SEND    this process's part, its records handed to
	 *                       part.record; out is not touched (other ranks).
	 * part.done is the run's own. A lattice sweep's records hold its
	 * trials' gate paths and peaks (bsim_sweep_record_size_for), so it is
	 * split as any other. */
	int spread;
	bsim_sweep_part part;
	/* GATHER and SEND: called in every process once the inputs are known,
	 * before any trial: checks that every process has these inputs and
	 * gives every process the gatherer's done bits (bytes of them). */
	int (*agree)(void *user, const char *inputs, unsigned char *done, size_t bytes,
	             bsim_error *err);
	/* SHARD: the command line that ran the part, kept in part.json for
	 * merge (argv[0] the command's name). */
	int argc;
	char *const *argv;
	/* n_merge > 0: no trial runs; the part directories merge[0..n_merge)
	 * (all the parts of this sweep, each once) are joined and out is
	 * written as one process writes it. */
	const char *const *merge;
	int n_merge;
	/* > 0: the caller will hold the trials in memory as columns of
	 * trials.csv, this many bytes a cell (a binding's arrays): the run is
	 * refused before any trial if they would need more than the memory
	 * available (bsim_output_trials_fit, beamsim/output.h). */
	double hold_cell_bytes;
} bsim_sweep_dir_def;

enum { BSIM_SPREAD_NONE, BSIM_SPREAD_SHARD, BSIM_SPREAD_GATHER, BSIM_SPREAD_SEND };

/* How a command that runs several sweeps with one journal (beamsim markov
 * validate, beamsim essay) is spread over processes: the fields of
 * bsim_sweep_dir_def of the same names, with the same meaning. Its trials
 * are numbered along its sweeps in turn (the first sweep's g * trials + t,
 * then the next's after them), and trial j belongs to part j mod count.
 * All zero: one process. */
typedef struct bsim_sweep_spread {
	int spread;
	bsim_sweep_part part;
	int (*agree)(void *user, const char *inputs, unsigned char *done, size_t bytes,
	             bsim_error *err);
	int argc;
	char *const *argv;
	const char *const *merge;
	int n_merge;
} bsim_sweep_spread;

/* What a part directory's part.json says: the part (1-based, as given to
 * --shard), of how many, the run (a hash of its inputs), the trials its
 * journal holds and the command line that ran it. */
typedef struct bsim_sweep_dir_part {
	char command[16];
	int index, count;
	char run[17];
	long records;
	int argc;
	char **argv;
} bsim_sweep_dir_part;

/* Reads DIR/part.json; BSIM_EINPUT naming the file and field. */
BSIM_API int bsim_sweep_dir_part_read(const char *dir, bsim_sweep_dir_part *p, bsim_error *err);
BSIM_API void bsim_sweep_dir_part_free(bsim_sweep_dir_part *p);

/* The thesis backend, no options, all cores, nothing kept. */
BSIM_API bsim_sweep_dir_def bsim_sweep_dir_def_default(void);

typedef struct bsim_sweep_dir_result {
	bsim_experiment e;   /* as run: --trials and --seed applied */
	bsim_sweep_result r; /* every trial and group */
	int threads;         /* threads used */
	/* Unstable trials (bsim_instability): how many, the first's index
	 * g * trials + t (-1 if none) and why, in one line. */
	long unstable, first_unstable;
	char unstable_why[256];
	/* When the run stopped (BSIM_ESTOPPED), or its files could not be
	 * committed after every trial had run: the journal that resume
	 * continues from. "" otherwise. */
	char journal[BSIM_PATH_MAX];
} bsim_sweep_dir_result;

/* Runs the sweep into def->out. BSIM_OK with res filled (free it with
 * bsim_sweep_dir_result_free; unstable trials are an ordinary result,
 * counted); BSIM_EINPUT for a bad experiment, backend option or directory,
 * or a refused resume; BSIM_EFAIL when the run or a file fails;
 * BSIM_ESTOPPED when def->stop stopped it. On any error res holds nothing
 * to free but res->journal. */
BSIM_API int bsim_sweep_dir_run(const bsim_sweep_dir_def *def, bsim_sweep_dir_result *res,
                                bsim_error *err);

/* Reads a stored sweep back: DIR's run.json (beamsim/run_record.h), the
 * experiment of DIR/inputs/ and the trials of trials.csv, with each
 * group's deterministic flag from its scene. side: NULL for a sweep's
 * directory, or the label of one side of a comparison's (its trials are in
 * DIR/<bsim_compare_dir_label(side)>/). BSIM_EINPUT naming the file and
 * field if DIR is not such a directory or its files do not match its
 * manifest. */
BSIM_API int bsim_sweep_dir_read(const char *dir, const char *side, bsim_sweep_dir_result *res,
                                 bsim_error *err);

BSIM_API void bsim_sweep_dir_result_free(bsim_sweep_dir_result *res);

#ifdef __cplusplus
}
#endif
#endif
