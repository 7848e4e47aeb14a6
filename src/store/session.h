/* One run's output directory (outdir.h) and, for the runs that journal
 * their trials (sweeps and comparisons), its journal (journal.h): what the
 * directory-writing workflows (sweep_dir.c, compare_dir.c, regress.c,
 * run_output.c, landscape_store.c, accuracy_store.c, figures_plot.c)
 * share. Files are written into stage and appear in dir at the end. */
#ifndef BSIM_STORE_SESSION_H
#define BSIM_STORE_SESSION_H

#include <stddef.h>

#include "beamsim/error.h"
#include "util/journal.h"
#include "store/outdir.h"
#include "beamsim/limits.h"

typedef struct bsim_session {
	const char *dir;   /* as the caller gave it */
	const char *stage; /* where to write */
	bsim_outdir *od;
	bsim_journal *journal;
	char journal_path[BSIM_PATH_MAX];
	int add;  /* the files join DIR's set (bsim_outdir_add): mode BSIM_OUTDIR_ADD */
	int done; /* set once every trial is journaled: a later failure keeps the journal */
	bsim_error deferred; /* the first failure deferred to close (bsim_session_defer) */
	int n_deferred;
} bsim_session;

/* Opens dir in mode (outdir.h; BSIM_EINPUT if it cannot be used, another
 * run holds it, or it holds a result the mode may not replace), command
 * naming the run, and, if inputs is not NULL, the journal for records of
 * record_size bytes: with BSIM_OUTDIR_RESUME the journal of the stopped
 * run in dir, which must have these inputs; otherwise a new one (with
 * BSIM_OUTDIR_OVERWRITE, in the place of a stopped run's). With
 * BSIM_OUTDIR_ADD the files join dir's set at the close. spelling (may be
 * NULL) is how the caller names --resume and --overwrite in the messages. */
int bsim_session_open(bsim_session *s, const char *dir, bsim_outdir_mode mode, const char *command,
                      const bsim_outdir_spelling *spelling, const char *inputs, size_t record_size,
                      bsim_error *err);

/* The mode of a run with the user's resume and overwrite flags. */
static inline bsim_outdir_mode bsim_session_mode(int resume, int overwrite)
{
	return resume ? BSIM_OUTDIR_RESUME : overwrite ? BSIM_OUTDIR_OVERWRITE : BSIM_OUTDIR_NEW;
}

/* Ends the session with the run's status rc (err holding its message if
 * rc is not BSIM_OK): if BSIM_OK, commits the files (and removes the
 * journal once they are in place; a failed commit keeps it, so a resumed
 * run writes the files again), and then returns a failure deferred by
 * bsim_session_defer if there is one. Finished work is never thrown away: the
 * journal is kept if the run was stopped (BSIM_ESTOPPED), if it failed
 * after its trials were done (s->done: writing the files, a full disk),
 * or if the journal itself could not be written (a full disk: what was
 * appended before is kept). Only after a trial that failed (it fails again
 * when resumed) is it removed. The staging area is always discarded.
 * Returns the final status, with err naming files by their place in dir,
 * not in the staging area; *kept (may be NULL) is 1 if the journal was
 * kept, its path in s->journal_path. */
int bsim_session_close(bsim_session *s, int rc, const char *command, int *kept, bsim_error *err);

/* Defers a failure that leaves what the run made sound to the session's
 * end: a figure gnuplot failed on (drawn BSIM_FIGURE_FAILED, util/figure.h)
 * has its script and data staged beside the tables computed before it.
 * With rc a failure and deferrable set, records it (the first one; later
 * ones are counted) and returns BSIM_OK, so the run goes on to write its
 * other files; else returns rc. bsim_session_close then commits the staged
 * files as on success and returns the deferred failure, its message naming
 * files by their place in dir. */
int bsim_session_defer(bsim_session *s, int rc, int deferrable, const bsim_error *err);

/* "dir/name" into buf; BSIM_EFAIL naming both if it does not fit. */
int bsim_session_path(char *buf, size_t size, const char *dir, const char *name, bsim_error *err);

#endif
