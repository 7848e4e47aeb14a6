/* An output directory whose files appear together: a run writes its files
 * into a staging area and commits them as a set, so a reader never sees
 * some files of one run beside files of another.
 *
 *   bsim_outdir *od;
 *   if (bsim_outdir_open(&od, "out/h1", BSIM_OUTDIR_NEW, "sweep", NULL, err) != BSIM_OK)
 *           return ...; // exit 2
 *   ... write files into bsim_outdir_stage(od) under their final names,
 *       subdirectories included (DIR/thesis/trials.csv) ...
 *   rc = bsim_outdir_commit(od, "sweep", err);
 *   bsim_outdir_close(od);
 *
 * Open checks before any work that DIR is a directory that can be written
 * (creating it and its parents if missing), takes a lock so that two runs
 * never write one DIR at once, refuses to replace a result the user did
 * not ask to replace (bsim_outdir_mode), and creates DIR/.beamsim/staging/.
 * Until the lock is held it changes nothing in DIR, and only the run that
 * holds the lock ever removes what is in DIR/.beamsim.
 *
 * Commit moves every staged file into DIR (one rename each, or written
 * through if DIR already holds a symlink, FIFO or device under that name),
 * removes the files the previous run listed that this one did not write,
 * and last writes DIR/manifest.json: every file of the set with its size
 * and CRC-32. The previous manifest is removed first, so at every moment
 * either a manifest describes exactly the files beside it or there is
 * none: bsim_outdir_verify is the reader's check. A run that fails or is
 * stopped before its commit leaves DIR exactly as it was.
 *
 * DIR/.beamsim/ also holds what a stopped run keeps for `--resume` (its
 * journal, util/journal.h); it is removed with the last of its contents. */
#ifndef BSIM_STORE_OUTDIR_H
#define BSIM_STORE_OUTDIR_H

#include <stddef.h>

#include "beamsim/error.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct bsim_outdir bsim_outdir;

#define BSIM_OUTDIR_MANIFEST "manifest.json"

/* What a run may do to what DIR holds. Whatever the mode, a directory
 * another run holds is refused, and a run refused touches nothing in it. */
typedef enum bsim_outdir_mode {
	BSIM_OUTDIR_NEW = 0,   /* refuse a finished result (a manifest) or a stopped
	                        * run (a journal): the user did not ask to replace it */
	BSIM_OUTDIR_OVERWRITE, /* the result there is replaced at the commit */
	BSIM_OUTDIR_RESUME,    /* the stopped run there continues (session.h checks it) */
	BSIM_OUTDIR_ADD,       /* the files join the result there (plot, a map cache) */
} bsim_outdir_mode;

/* How the caller spells the options a refusal names: NULL (or a NULL
 * field) is the command line's "--resume" and "--overwrite"; a binding
 * names its own arguments ("resume=True", "'overwrite', true"). */
typedef struct bsim_outdir_spelling {
	const char *resume;
	const char *overwrite;
} bsim_outdir_spelling;

static inline const char *bsim_outdir_resume_option(const bsim_outdir_spelling *s)
{
	return s && s->resume ? s->resume : "--resume";
}

static inline const char *bsim_outdir_overwrite_option(const bsim_outdir_spelling *s)
{
	return s && s->overwrite ? s->overwrite : "--overwrite";
}

/* Prepares dir as above; command ("sweep") names the run to a run refused
 * while this one holds DIR (DIR/.beamsim/owner). BSIM_EINPUT naming dir and
 * the cause if it is not a directory, cannot be created or written,
 * another run holds it, or, with mode NEW, it holds a result. */
int bsim_outdir_open(bsim_outdir **out, const char *dir, bsim_outdir_mode mode, const char *command,
                     const bsim_outdir_spelling *spelling, bsim_error *err);

/* Whether bsim_outdir_open(dir, mode) would refuse dir, found without
 * creating, locking for long or changing anything: for a run that must
 * know before work that is not its own (the processes of a job, before
 * they make their parts in dir). BSIM_OK, or the refusal open would give
 * (a directory missing is no refusal). The answer may change before the
 * open. */
int bsim_outdir_probe(const char *dir, bsim_outdir_mode mode, const bsim_outdir_spelling *spelling,
                      bsim_error *err);

/* The directory as the user named it. */
const char *bsim_outdir_dir(const bsim_outdir *od);

/* The staging directory: write here, under the final names. */
const char *bsim_outdir_stage(const bsim_outdir *od);

/* DIR/.beamsim, where a run keeps what must outlive it (a journal). */
const char *bsim_outdir_work(const bsim_outdir *od);

/* Commits the staged files as above; command names the run in the
 * manifest. BSIM_EFAIL naming the final path on any error: DIR then has no
 * manifest until a later commit succeeds. */
int bsim_outdir_commit(bsim_outdir *od, const char *command, bsim_error *err);

/* Commits the staged files as additions to the set already in DIR (beamsim
 * plot's figures beside a sweep's files): the files the previous manifest
 * lists stay, and stay listed; staged files of the same names replace
 * them. The new manifest lists both. */
int bsim_outdir_add(bsim_outdir *od, const char *command, bsim_error *err);

/* Rewrites text (of capacity size) so that it names the files by their
 * place in DIR, not in the staging area: for messages of writers that were
 * given staged paths. */
void bsim_outdir_explain(const bsim_outdir *od, char *text, size_t size);

/* Removes the staging area (if not committed), releases the lock, and
 * removes DIR/.beamsim if empty, and DIR itself if open created it and it
 * is empty. NULL is fine. */
void bsim_outdir_close(bsim_outdir *od);

/* The reader's check of a directory: BSIM_OK if DIR/manifest.json lists
 * only files that are there with their size and CRC-32, and *has_manifest
 * = 1; BSIM_OK with *has_manifest = 0 if there is no manifest (a directory
 * being committed, or written by an older beamsim); BSIM_EINPUT naming the
 * first file that does not match (files of two runs). */
int bsim_outdir_verify(const char *dir, int *has_manifest, bsim_error *err);

/* The files DIR/manifest.json lists, in its order (by path): *paths a
 * malloc'd array of *n malloc'd paths below DIR (free with
 * bsim_outdir_files_free); none if there is no manifest. BSIM_EINPUT if
 * the manifest cannot be read. */
int bsim_outdir_files(const char *dir, char ***paths, size_t *n, bsim_error *err);
void bsim_outdir_files_free(char **paths, size_t n);

#ifdef __cplusplus
}
#endif
#endif
