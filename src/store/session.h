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
	int add;  /* set before closing: the files join DIR's set (bsim_outdir_add) */
	int done; /* set once every trial is journaled: a later failure keeps the journal */
} bsim_session;

/* Opens dir (BSIM_EINPUT if it cannot be used) and, if inputs is not NULL,
 * the journal for records of record_size bytes: with resume the journal of
 * the stopped run in dir, which must have these inputs; without, a new
 * one, refusing a dir that holds a stopped run's journal. resume_option
 * is how the caller spells resume in those messages (NULL: the command
 * line's "--resume"; "resume=True" from Python). */
int bsim_session_open(bsim_session *s, const char *dir, int resume, const char *resume_option,
                      const char *inputs, size_t record_size, bsim_error *err);

/* Ends the session with the run's status rc (err holding its message if
 * rc is not BSIM_OK): if BSIM_OK, commits the files (and removes the
 * journal once they are in place; a failed commit keeps it, so a resumed
 * run writes the files again). Finished work is never thrown away: the
 * journal is kept if the run was stopped (BSIM_ESTOPPED), if it failed
 * after its trials were done (s->done: writing the files, a full disk),
 * or if the journal itself could not be written (a full disk: what was
 * appended before is kept). Only after a trial that failed (it fails again
 * when resumed) is it removed. The staging area is always discarded.
 * Returns the final status, with err naming files by their place in dir,
 * not in the staging area; *kept (may be NULL) is 1 if the journal was
 * kept, its path in s->journal_path. */
int bsim_session_close(bsim_session *s, int rc, const char *command, int *kept, bsim_error *err);

/* "dir/name" into buf; BSIM_EFAIL naming both if it does not fit. */
int bsim_session_path(char *buf, size_t size, const char *dir, const char *name, bsim_error *err);

#endif
