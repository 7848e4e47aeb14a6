/* A file that appears whole or not at all. The text is written to
 * PATH.tmp.PID, flushed to disk and renamed over PATH: rename is atomic,
 * so a reader (or a resumed run) sees either the old file or the whole new
 * one, never a torn one, and a run that fails leaves no file behind.
 *
 *   bsim_atomic_file o;
 *   if (bsim_atomic_file_open(&o, path, err) != BSIM_OK) return ...;
 *   fprintf(o.f, ...);
 *   return bsim_atomic_file_commit(&o, err); // or bsim_atomic_file_abort(&o)
 */
#ifndef BEAMSIM_ATOMIC_FILE_H
#define BEAMSIM_ATOMIC_FILE_H

#include <stdio.h>

#include "beamsim/error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Room for a 1 KiB path plus ".tmp." and a process id. */
#define BSIM_ATOMIC_FILE_TMP_MAX 1100

typedef struct bsim_atomic_file {
	FILE *f;          /* write here; NULL once committed or aborted */
	const char *path; /* the final name, not copied: must outlive o */
	char tmp[BSIM_ATOMIC_FILE_TMP_MAX];
} bsim_atomic_file;

/* Creates PATH.tmp.PID for writing. BSIM_EFAIL naming the path if it is
 * too long or cannot be created (o->f is then NULL). */
int bsim_atomic_file_open(bsim_atomic_file *o, const char *path, bsim_error *err);

/* Flushes to disk and renames over PATH. On any error (including an
 * earlier failed write on o->f) the temporary file is removed, PATH is
 * left as it was and BSIM_EFAIL names PATH and the cause. */
int bsim_atomic_file_commit(bsim_atomic_file *o, bsim_error *err);

/* Closes and removes the temporary file, leaving PATH as it was. Does
 * nothing if o is not open, so it is safe on a zeroed o. */
void bsim_atomic_file_abort(bsim_atomic_file *o);

/* Copies the file from to the path to, atomically as above. BSIM_EFAIL
 * naming the file that cannot be read or written. */
int bsim_atomic_file_copy(const char *from, const char *to, bsim_error *err);

#ifdef __cplusplus
}
#endif
#endif
