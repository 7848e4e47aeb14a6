/* Several sweeps run as one job with one journal: the simulations of
 * beamsim markov validate and beamsim essay, which keep their trials'
 * results in memory and write their own files from them.
 *
 * The sweeps' trials are numbered along the sweeps in turn (the first
 * sweep's g * trials + t, then the next's after them) and journaled under
 * that number in DIR/.beamsim/journal, whose inputs are every sweep's
 * (bsim_run_record_inputs, one after another), so a stopped or killed run
 * continues with resume and loses no finished trial. Spread over processes
 * (beamsim/sweep_dir.h bsim_sweep_spread) trial j belongs to part j mod
 * count, as a sweep's trial does: a shard leaves a part directory
 * (part.json, part.journal; store/part_dir.h), an MPI job's rank 0 journals
 * every rank's records, and a merge joins the parts' journals. The
 * results are then each sweep run again from the journal
 * (bsim_sweep_config.journal_first, results_only), so they are one
 * process's to the bit. */
#ifndef BSIM_STORE_SWEEP_BATCH_H
#define BSIM_STORE_SWEEP_BATCH_H

#include <signal.h>

#include "beamsim/error.h"
#include "beamsim/limits.h"
#include "beamsim/progress.h"
#include "beamsim/sweep.h"
#include "beamsim/sweep_dir.h"
#include "store/session.h"

typedef struct sweep_batch {
	const char *command; /* "markov validate", "essay": the journal's and part.json's */
	const char *out;     /* the output directory; NULL: no directory, no journal */
	int resume;
	int overwrite;                        /* 1: replace what out holds (outdir.h) */
	const bsim_outdir_spelling *spelling; /* how refusals name resume, overwrite; may be NULL */
	const bsim_sweep_spread *spread;      /* NULL: one process */
	bsim_progress_fn progress;            /* trials done of every sweep's; may be NULL */
	void *progress_user;
	const volatile sig_atomic_t *stop;
	/* Set by bsim_sweep_batch_run: */
	bsim_session ss; /* out's session, when open: the caller writes into ss.stage */
	int open;
	/* 1: this process has the results and writes out's files (not a
	 * shard, not an MPI rank other than 0) */
	int writes;
	/* the journal kept by bsim_sweep_batch_end ("" if none): resume continues it */
	char journal[BSIM_PATH_MAX];
	/* progress over the sweeps */
	long done_before, total;
} sweep_batch;

/* Runs the n sweeps e[s] with cfg[s] (its journal, part and progress
 * fields are the batch's) into res[0..n) (bsim_sweep_run's results,
 * trials_out without logs), with out opened first (b->ss). With b->writes
 * 0 (a shard, another rank) res holds nothing. On error res holds nothing;
 * call bsim_sweep_batch_end in every case where b->open. */
int bsim_sweep_batch_run(sweep_batch *b, const bsim_experiment *const *e,
                         const bsim_sweep_config *cfg, int n, bsim_sweep_result *res,
                         bsim_error *err);

/* With cpu not NULL, cpu[0..n) gets the CPU time, s, this process spent
 * on each sweep (clock(): its part and the final run from the journal). */
int bsim_sweep_batch_run_cpu(sweep_batch *b, const bsim_experiment *const *e,
                             const bsim_sweep_config *cfg, int n, bsim_sweep_result *res,
                             double *cpu, bsim_error *err);

/* Ends out's session with status rc (bsim_session_close): the files the
 * caller wrote into b->ss.stage (a shard's part.json and part.journal)
 * committed when rc is BSIM_OK, the journal kept when the run stopped or
 * failed after finishing trials (its path in b->journal). */
int bsim_sweep_batch_end(sweep_batch *b, int rc, bsim_error *err);

#endif
