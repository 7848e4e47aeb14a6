/* A CSV table of beamsim's (trials.csv, pairs.csv, a trajectory, ...) read
 * row by row, for a reader that keeps columns of its own (the Python
 * module's NumPy arrays) and must not hold the file as well: memory is the
 * longest line and the header.
 *
 *   bsim_table_reader *t;
 *   const char *const *cells;
 *   if (bsim_table_open("out/h1/trials.csv", &t, &err) == BSIM_OK) {
 *           while ((got = bsim_table_next(t, &cells, &err)) == 1)
 *                   ... cells[c] of column bsim_table_column(t, c) ...
 *           bsim_table_close(t);    (got -1: err says why)
 *   }
 *
 * The file is checked as beamsim checks a table it reads back: a regular
 * file (refused at once otherwise) of at most 16 GiB, no NUL byte, every
 * row as wide as the header, a last line ending in a line feed. A quoted
 * field (text a user gave, such as a grid value holding a comma) comes
 * back unquoted. A fault is BSIM_EINPUT naming the file and line. */
#ifndef BSIM_TABLE_H
#define BSIM_TABLE_H

#include "beamsim/base.h"
#include "beamsim/error.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct bsim_table_reader bsim_table_reader;

/* Opens path and reads its header. Nothing to close on failure. */
BSIM_API int bsim_table_open(const char *path, bsim_table_reader **out, bsim_error *err);

/* The header: its number of columns and the name of column c. */
BSIM_API int bsim_table_columns(const bsim_table_reader *t);
BSIM_API const char *bsim_table_column(const bsim_table_reader *t, int c);

/* The next row: 1 with *cells its bsim_table_columns texts (valid until
 * the next call), 0 at the end of a sound file, -1 with err set. */
BSIM_API int bsim_table_next(bsim_table_reader *t, const char *const **cells, bsim_error *err);

/* The line of the file where the row last returned starts (2 the first). */
BSIM_API long bsim_table_line(const bsim_table_reader *t);

BSIM_API void bsim_table_close(bsim_table_reader *t);

/* The rows of the table at path, counted without keeping a line (a reader
 * that sizes its columns before it reads: the lines after the header, an
 * upper bound if a quoted field holds a line break), or -1 if it cannot
 * be read (bsim_table_open says why). */
BSIM_API double bsim_table_count_rows(const char *path);

#ifdef __cplusplus
}
#endif
#endif
