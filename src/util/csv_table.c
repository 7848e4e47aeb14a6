/* CSV tables read by header name (csv_table.h). */
#define _POSIX_C_SOURCE 200809L
#include "util/csv_table.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "util/decimal.h"
#include "util/file_read.h"

/* Splits line in place at commas into out (at most max fields); the
 * number of fields found (may exceed max). */
static int split(char *line, char **out, int max)
{
	int n = 0;
	for (char *p = line;; p++) {
		char *c = strchr(p, ',');
		if (n < max)
			out[n] = p;
		n++;
		if (!c)
			break;
		*c = '\0';
		p = c;
	}
	return n;
}

static int count_fields(const char *line)
{
	int n = 1;
	for (; *line; line++)
		n += *line == ',';
	return n;
}

void bsim_csv_field_write(FILE *f, const char *s)
{
	if (!strpbrk(s, ",\"\r\n")) {
		fputs(s, f);
		return;
	}
	fputc('"', f);
	for (; *s; s++) {
		if (*s == '"')
			fputc('"', f);
		fputc(*s, f);
	}
	fputc('"', f);
}

int bsim_csv_split(char *line, char **field, int max)
{
	int n = 0;
	char *r = line, *w = line;
	while (n < max) {
		field[n++] = w;
		if (*r == '"') {
			r++;
			while (1) {
				if (*r == '\0')
					return -1;
				if (*r == '"' && r[1] == '"') {
					*w++ = '"';
					r += 2;
				} else if (*r == '"') {
					r++;
					break;
				} else {
					*w++ = *r++;
				}
			}
			if (*r != ',' && *r != '\0')
				return -1;
		} else {
			while (*r && *r != ',')
				*w++ = *r++;
		}
		if (*r == '\0') {
			*w = '\0';
			return n;
		}
		*w++ = '\0';
		r++;
	}
	return n;
}

int bsim_csv_count_fields(const char *line)
{
	int n = 1, quoted = 0;
	for (; *line; line++) {
		if (*line == '"')
			quoted = !quoted; /* a doubled quote turns it twice */
		else if (*line == ',' && !quoted)
			n++;
	}
	return n;
}

int bsim_csv_text_check(const char *path, const char *text, size_t len, bsim_error *err)
{
	/* A NUL would end a line's text early, unseen: named where it is. */
	long line = 1, col = 1;
	for (size_t i = 0; i < len; i++, col++) {
		if (text[i] == '\0')
			return bsim_error_set(err, BSIM_EINPUT,
			                      "%s:%ld:%ld: expected text, got a NUL byte", path,
			                      line, col);
		if (text[i] == '\n') {
			line++;
			col = 0;
		}
	}
	/* Every line beamsim writes ends in a line feed: a last line without
	 * one is a row cut short (a full disk, a copy interrupted), whose last
	 * field may still read as a number. */
	if (len > 0 && text[len - 1] != '\n')
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s:%ld: expected a whole line ending in a line feed, got "
		                      "the file cut short in this line",
		                      path, line);
	return BSIM_OK;
}

void bsim_csv_table_free(csv_table *t)
{
	free(t->names);
	free(t->cells);
	free(t->text);
	memset(t, 0, sizeof *t);
}

int bsim_csv_text_read(const char *path, file_text *out, bsim_error *err)
{
	/* Only a regular file, never waited on, and at most CSV_TABLE_MAX_BYTES
	 * of it: a link to /dev/zero or a file that keeps growing must not
	 * fill memory. */
	int rc = bsim_file_read(path, "a CSV file", CSV_TABLE_MAX_BYTES, NULL, out, err);
	if (rc == BSIM_OK && (rc = bsim_csv_text_check(path, out->text, out->len, err)) != BSIM_OK)
		bsim_file_text_free(out);
	return rc;
}

int bsim_csv_table_read(const char *path, csv_table *t, bsim_error *err)
{
	memset(t, 0, sizeof *t);
	file_text f;
	int rc = bsim_csv_text_read(path, &f, err);
	if (rc != BSIM_OK)
		return rc;
	t->text = f.text;
	size_t len = f.len;
	/* Lines, in place: strip \r\n, skip a last empty line. */
	long n_lines = 0;
	for (size_t i = 0; i < len; i++)
		n_lines += t->text[i] == '\n';
	n_lines += len > 0 && t->text[len - 1] != '\n';
	if (n_lines < 1) {
		bsim_csv_table_free(t);
		return bsim_error_set(err, BSIM_EINPUT, "%s:1: expected a header line", path);
	}
	char **lines = malloc((size_t)n_lines * sizeof *lines);
	if (!lines) {
		bsim_csv_table_free(t);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory reading %s", path);
	}
	long k = 0;
	for (char *p = t->text; *p && k < n_lines;) {
		char *nl = strchr(p, '\n');
		lines[k++] = p;
		if (nl)
			*nl = '\0';
		size_t l = strlen(p);
		if (l && p[l - 1] == '\r')
			p[l - 1] = '\0';
		if (!nl)
			break;
		p = nl + 1;
	}
	n_lines = k;
	t->n_cols = count_fields(lines[0]);
	t->n_rows = n_lines - 1;
	t->names = malloc((size_t)t->n_cols * sizeof *t->names);
	t->cells = malloc(((size_t)t->n_rows * t->n_cols + 1) * sizeof *t->cells);
	if (!t->names || !t->cells) {
		free(lines);
		bsim_csv_table_free(t);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory reading %s", path);
	}
	split(lines[0], t->names, t->n_cols);
	for (long r = 0; r < t->n_rows; r++) {
		int got = split(lines[r + 1], t->cells + (size_t)r * t->n_cols, t->n_cols);
		if (got != t->n_cols) {
			int cols = t->n_cols;
			free(lines);
			bsim_csv_table_free(t);
			return bsim_error_set(err, BSIM_EINPUT,
			                      "%s:%ld: expected %d fields, got %d", path, r + 2,
			                      cols, got);
		}
	}
	free(lines);
	return BSIM_OK;
}

int bsim_csv_table_col(const csv_table *t, const char *name)
{
	for (int c = 0; c < t->n_cols; c++)
		if (strcmp(t->names[c], name) == 0)
			return c;
	return -1;
}

const char *bsim_csv_table_cell(const csv_table *t, long row, int col)
{
	return t->cells[(size_t)row * t->n_cols + col];
}

int bsim_csv_table_number(const csv_table *t, long row, int col, double *out)
{
	return bsim_csv_number(bsim_csv_table_cell(t, row, col), out);
}

int bsim_csv_number(const char *s, double *out)
{
	char *end;
	if (!*s || bsim_decimal_other_base(s))
		return -1;
	*out = strtod(s, &end); /* an underflow to 0 or subnormal is still that number */
	return *end == '\0' ? 0 : -1;
}

int bsim_csv_table_numbers(const csv_table *t, const char *path, int col, int allow_empty,
                           double empty_value, double *out, bsim_error *err)
{
	for (long r = 0; r < t->n_rows; r++) {
		if (allow_empty && !*bsim_csv_table_cell(t, r, col)) {
			out[r] = empty_value;
			continue;
		}
		if (bsim_csv_table_number(t, r, col, &out[r]) != 0)
			return bsim_error_set(err, BSIM_EINPUT,
			                      "%s:%ld: %s: expected a number, got '%s'", path,
			                      r + 2, t->names[col], bsim_csv_table_cell(t, r, col));
	}
	return BSIM_OK;
}

int bsim_csv_table_require(const csv_table *t, const char *path, const char *const *names, int n,
                           int *cols, bsim_error *err)
{
	for (int i = 0; i < n; i++) {
		cols[i] = bsim_csv_table_col(t, names[i]);
		if (cols[i] < 0)
			return bsim_error_set(err, BSIM_EINPUT, "%s:1: expected a column '%s'",
			                      path, names[i]);
	}
	return BSIM_OK;
}
