/* Internal: a file read whole into memory, the one way beamsim does it
 * (YAML documents, CSV tables, the scene text of a run record, a Markov
 * map's key). Only a regular file is read: a directory, a FIFO, a device
 * or a socket is refused at once, never waited on, since the file is
 * opened without blocking and checked (fstat) before the first byte is
 * read. At most a given number of bytes is read, so a file too large is
 * refused without first filling memory with it. Every message names the
 * file. */
#ifndef BSIM_UTIL_FILE_READ_H
#define BSIM_UTIL_FILE_READ_H

#include <stddef.h>
#include <sys/stat.h>

#include "beamsim/error.h"

typedef struct file_text {
	char *text; /* malloc'd; a NUL after the len bytes (the file may hold NULs of its own) */
	size_t len;
} file_text;

/* Reads the regular file path whole into *out, at most max_bytes (INFINITY
 * for no limit but memory). what names the file expected, for the message
 * on anything else ("a YAML file"); limit_name, if not NULL, is the
 * `--limit NAME=N` that raises max_bytes. On failure out is empty and:
 *   BSIM_EINPUT "PATH: cannot read the file: REASON"
 *   BSIM_EINPUT "PATH: expected WHAT, got a directory" (a FIFO, a device, ...)
 *   BSIM_EINPUT "PATH: expected a file of at most N bytes, got more
 *               (limit NAME = N; raise it with --limit NAME=N)"
 *   BSIM_EFAIL  "PATH: out of memory" */
int bsim_file_read(const char *path, const char *what, double max_bytes, const char *limit_name,
                   file_text *out, bsim_error *err);

void bsim_file_text_free(file_text *t);

/* Opens path for reading without blocking (O_NONBLOCK: a FIFO waits for no
 * writer; O_NOCTTY: a terminal never becomes the controlling one) and
 * fstat's it into *st, so that a caller checks what it is before the first
 * read: the descriptor, or -1 with errno set and nothing left open. */
int bsim_file_open_checked(const char *path, struct stat *st);

/* What a file that is not a regular one is, for messages: "a directory",
 * "a FIFO", "a character device", "a block device", "a socket" or "a
 * special file". */
const char *bsim_file_kind(const struct stat *st);

#endif
