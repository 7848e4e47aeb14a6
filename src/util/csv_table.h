/* Internal: a CSV table of beamsim's own making read whole, columns found
 * by header name, so that a reader keeps working when columns are added.
 *
 * beamsim's CSV files are plain: a header line of names, then rows of the
 * same number of comma-separated fields; only text a user gave (a grid key
 * or value) may need quoting (bsim_csv_field_write), which bsim_csv_split and the
 * streamed reader (csv_stream.h) undo. Fields stay text; a reader asks for
 * the numbers it wants. */
#ifndef BSIM_UTIL_CSV_TABLE_H
#define BSIM_UTIL_CSV_TABLE_H

#include <stddef.h>
#include <stdio.h>

#include "beamsim/error.h"
#include "util/file_read.h"

typedef struct csv_table {
	int n_cols;
	long n_rows;
	char **names; /* n_cols, into text */
	char **cells; /* n_rows * n_cols, row-major, into text */
	char *text;   /* the file, split in place */
} csv_table;

/* The largest table read, bytes (16 GiB: 80 million trials.csv rows). */
#define CSV_TABLE_MAX_BYTES 17179869184.0

/* Writes s as one CSV field: as it is, or in double quotes (each "
 * doubled) if it holds a comma, a quote or a line break, so that text a
 * user gave (a grid key or value) cannot shift the columns. */
void bsim_csv_field_write(FILE *f, const char *s);

/* Splits one CSV line in place into at most max fields, with RFC 4180
 * quoting (the field a,"b" is written "a,""b""", as bsim_csv_field_write writes
 * it). Returns the number of fields, or -1 on a malformed quote. */
int bsim_csv_split(char *line, char **field, int max);

/* The fields of a CSV line, quoted commas not counted (a malformed quote
 * counts as the end of its field). */
int bsim_csv_count_fields(const char *line);

/* The checks every stored CSV text passes before it is split: no NUL byte,
 * and a last line that ends in a line feed (beamsim ends every line it
 * writes, so a file without one was cut mid-row). BSIM_EINPUT
 * "FILE:LINE: expected ..." naming the line otherwise. */
int bsim_csv_text_check(const char *path, const char *text, size_t len, bsim_error *err);

/* The text of path as every reader of beamsim's tables takes it: a regular
 * file (a FIFO, a device or a directory is refused at once, without
 * waiting on it or reading it) of at most CSV_TABLE_MAX_BYTES (bsim_file_read)
 * that passes bsim_csv_text_check. */
int bsim_csv_text_read(const char *path, file_text *out, bsim_error *err);

/* Reads path: a regular file (a FIFO, a device or a directory is refused
 * at once, without waiting on it) of at most CSV_TABLE_MAX_BYTES that
 * passes bsim_csv_text_check. BSIM_EINPUT "FILE:LINE: expected N fields, got M"
 * on a row of the wrong width, or naming the file if it cannot be read or
 * has no header. */
int bsim_csv_table_read(const char *path, csv_table *t, bsim_error *err);
void bsim_csv_table_free(csv_table *t);

/* The column named name, -1 if there is none. */
int bsim_csv_table_col(const csv_table *t, const char *name);

/* The text of a cell. */
const char *bsim_csv_table_cell(const csv_table *t, long row, int col);

/* A cell as a number: 0 if the whole text is a number (strtod), else -1.
 * An empty cell is no number. */
int bsim_csv_table_number(const csv_table *t, long row, int col, double *out);

/* The text s as a number, the same way: 0 if it is one, else -1. */
int bsim_csv_number(const char *s, double *out);

/* A whole column as numbers into out (n_rows entries): 0, or BSIM_EINPUT
 * "FILE:LINE: NAME: expected a number, got TEXT" at the first cell that is
 * not one; an empty cell becomes empty_value if allow_empty. path names
 * the file in the message. */
int bsim_csv_table_numbers(const csv_table *t, const char *path, int col, int allow_empty,
                           double empty_value, double *out, bsim_error *err);

/* Required columns: the index of each name in cols, or BSIM_EINPUT naming
 * the file and the first missing column. */
int bsim_csv_table_require(const csv_table *t, const char *path, const char *const *names, int n,
                           int *cols, bsim_error *err);

#endif
