/* Internal: a CSV table of beamsim's own making read row by row, for a
 * reader that must not hold the whole file (a .mat twin of a million-row
 * trajectory). The table is the CSV of util/csv_table.h, a quoted field
 * unquoted (bsim_csv_split; it may hold commas and line breaks), and is checked
 * the same way, with the same messages: a regular file (refused at once
 * otherwise, never waited on) of at most CSV_TABLE_MAX_BYTES, no NUL
 * byte, a last line ending in a line feed, every row as wide as the
 * header, a CR before a line feed dropped.
 *
 * bsim_csv_table_read checks the whole text before it splits a row, so a file
 * with several faults names the first NUL, then a cut-short last line,
 * then the first row of the wrong width. A stream keeps that order: a row
 * of the wrong width is remembered and reported at the end of the file,
 * unless a NUL or the cut-short line comes after it. Memory is one line
 * (grown to the longest line) and the header's names. */
#ifndef BSIM_UTIL_CSV_STREAM_H
#define BSIM_UTIL_CSV_STREAM_H

#include <stddef.h>

#include "beamsim/error.h"

typedef struct csv_stream {
	const char *path; /* the caller's, named in messages */
	int fd;
	char *buf; /* lines read, from start to end; cap bytes */
	size_t cap, start, end;
	double bytes; /* read so far */
	int eof;
	long line;   /* the first line of the row last returned: 1 the header, r + 2
	              * row r (later if a quoted field before held a line break) */
	long breaks; /* line feeds inside quotes of the row last returned */
	int n_cols;
	char **names;  /* n_cols, the header's (owned) */
	char **cells;  /* n_cols, the row last returned, into buf */
	long bad_line; /* the first row of the wrong width, 0 if none */
	int bad_got;
} csv_stream;

/* Opens path and reads its header. BSIM_EINPUT with bsim_csv_table_read's
 * message if the file cannot be read, is not a regular file, is too large
 * or has no header (or holds a NUL before the end of its header), BSIM_EFAIL
 * out of memory. Nothing to free on failure. */
int bsim_csv_stream_open(const char *path, csv_stream *s, bsim_error *err);

/* The next row into s->cells: 1, or 0 at the end of a sound file, or -1
 * with err set (bsim_csv_table_read's message for the first fault of the file,
 * in its order). */
int bsim_csv_stream_next(csv_stream *s, bsim_error *err);

void bsim_csv_stream_close(csv_stream *s);

/* The line feeds of the regular file path, counted without keeping a
 * line (a reader that decides before it keeps anything), or -1 if it is
 * not a regular file or cannot be read (bsim_csv_stream_open names why). */
double bsim_csv_count_lines(const char *path);

#endif
