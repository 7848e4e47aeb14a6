/* A file that appears whole or not at all. The text is written to
 * PATH.tmp.PID, flushed to disk and renamed over PATH: rename is atomic,
 * so a reader (or a resumed run) sees either the old file or the whole new
 * one, never a torn one, and a run that fails leaves no file behind.
 *
 * What is not a regular file is never replaced: "-" is standard output,
 * and a path that is a symlink, a FIFO or a device is opened and written
 * through (to the link's target, the pipe, the terminal), so
 * `--trajectory /dev/stdout` or a link into a results tree does what it
 * says. Such writes are not atomic; errors, of writing and of closing, are
 * reported all the same. Every message names PATH, never the temporary
 * name.
 *
 *   bsim_atomic_file o;
 *   if (bsim_atomic_file_open(&o, path, err) != BSIM_OK) return ...;
 *   fprintf(o.f, ...);
 *   return bsim_atomic_file_commit(&o, err); // or bsim_atomic_file_abort(&o)
 */
#ifndef BSIM_UTIL_ATOMIC_FILE_H
#define BSIM_UTIL_ATOMIC_FILE_H

#include <stdio.h>

#include "beamsim/error.h"
#include "beamsim/limits.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
	BSIM_ATOMIC_RENAME = 0, /* a regular file (or none yet): temporary + rename */
	BSIM_ATOMIC_THROUGH,    /* a symlink, FIFO or device: written in place */
	BSIM_ATOMIC_STDOUT,     /* "-": standard output, flushed, never closed */
} bsim_atomic_mode;

typedef struct bsim_atomic_file {
	FILE *f;                 /* write here; NULL once committed or aborted */
	const char *path;        /* the final name, not copied: must outlive o */
	char tmp[BSIM_PATH_MAX]; /* path + ".tmp." + a process id */
	bsim_atomic_mode mode;
} bsim_atomic_file;

/* Opens PATH for writing as above. BSIM_EFAIL naming the path if it is too
 * long, a directory, or cannot be written (o->f is then NULL). */
int bsim_atomic_file_open(bsim_atomic_file *o, const char *path, bsim_error *err);

/* Flushes to disk and renames over PATH (or, written through, flushes and
 * closes). On any error (including an earlier failed write on o->f) the
 * temporary file is removed, PATH is left as it was and BSIM_EFAIL names
 * PATH and the cause. */
int bsim_atomic_file_commit(bsim_atomic_file *o, bsim_error *err);

/* Closes and removes the temporary file, leaving PATH as it was. Does
 * nothing if o is not open, so it is safe on a zeroed o. */
void bsim_atomic_file_abort(bsim_atomic_file *o);

/* 1 if path is "-" or an existing symlink, FIFO, socket or device: what
 * bsim_atomic_file writes through rather than replaces. */
int bsim_atomic_file_is_through(const char *path);

/* Copies the file from to the path to, atomically as above. BSIM_EFAIL
 * naming the file that cannot be read or written. */
int bsim_atomic_file_copy(const char *from, const char *to, bsim_error *err);

#ifdef __cplusplus
}
#endif
#endif
