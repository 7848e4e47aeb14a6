/* beamsim_read_csv: one CSV table of beamsim's into a struct of columns,
 * for beamsim_load.m (a table of 16,200 rows is read in milliseconds; the
 * same in M code took seconds).
 *
 *   t = beamsim_read_csv(FILE)
 *
 * One field per column, named by the header (bmx_field_name); a column
 * whose every field is a number, empty or nan is a double column (empty
 * and nan are NaN), any other a cell column of text. Fields may be quoted
 * ("a, b", "" for a quote). The file's numbers as they are: beamsim_load
 * adds 1 to the group and trial columns.
 *
 * The file is read as the library reads its tables
 * (bsim_output_table_text): a regular file of at most 16 GiB, without a
 * NUL byte, ending in a line feed. Two columns whose names become one field
 * name (a.b and a_b; names alike in their first 63 characters, Octave's
 * namelengthmax and older MATLAB's, where the names are cut) are refused,
 * naming both, rather than one kept silently. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bsim_mex.h"

typedef struct table {
	char *text;    /* the file, split in place */
	char **fields; /* rows x nc, row by row; the header first */
	size_t nc, rows, cap;
} table;

/* Splits the line at *at (ending at a newline or the end) into fields in
 * place, unquoting them; *at moves past the line. Returns the number of
 * fields, each appended to out (NULL: counted only). */
static size_t split_line(char **at, char **out, size_t room)
{
	char *p = *at, *w = *at;
	size_t n = 0;
	char *start = w;
	int quoted = 0;
	for (;;) {
		char c = *p;
		if (quoted) {
			if (c == '\0') {
				quoted = 0;
				continue;
			}
			p++;
			if (c == '"' && *p == '"') {
				*w++ = '"';
				p++;
			} else if (c == '"') {
				quoted = 0;
			} else {
				*w++ = c;
			}
			continue;
		}
		if (c == '"') {
			quoted = 1;
			p++;
			continue;
		}
		if (c == ',' || c == '\n' || c == '\0') {
			if (n < room)
				out[n] = start;
			n++;
			int end = c != ',';
			if (c != '\0')
				p++;
			*w = '\0';
			w = p;
			start = p;
			if (end)
				break;
			continue;
		}
		if (c != '\r')
			*w++ = c;
		p++;
	}
	*at = p;
	return n;
}

static int read_table(const char *path, table *t, bsim_error *err)
{
	size_t bytes;
	if (bsim_output_table_text(path, &t->text, &bytes, err) != BSIM_OK)
		return err->code;
	if (t->text[0] == '\0' || t->text[0] == '\n')
		return bsim_error_set(err, BSIM_EINPUT, "%s:1: expected a header line", path);
	/* The header's fields counted on a copy of its line (splitting
	 * writes into the line). */
	size_t len = strcspn(t->text, "\n");
	char *copy = malloc(len + 1);
	if (!copy)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	memcpy(copy, t->text, len);
	copy[len] = '\0';
	char *probe = copy;
	t->nc = split_line(&probe, NULL, 0);
	free(copy);
	/* Row 0 is the header. */
	char *at = t->text;
	for (long line = 1; *at; line++) {
		if ((t->rows + 1) * t->nc > t->cap) {
			size_t cap = (t->rows + 1) * t->nc * 2;
			char **more = realloc(t->fields, cap * sizeof *more);
			if (!more)
				return bsim_error_set(err, BSIM_EFAIL, "out of memory");
			t->fields = more;
			t->cap = cap;
		}
		size_t n = split_line(&at, t->fields + t->rows * t->nc, t->nc);
		if (n != t->nc)
			return bsim_error_set(err, BSIM_EINPUT,
			                      "%s:%ld: expected %zu fields, got %zu", path, line,
			                      t->nc, n);
		t->rows++;
	}
	return BSIM_OK;
}

/* A field as a number: 1 if it is one (empty and nan are NaN). */
static int field_number(const char *s, double *x)
{
	if (*s == '\0') {
		*x = NAN;
		return 1;
	}
	char *end;
	*x = strtod(s, &end);
	return end != s && *end == '\0';
}

/* Each column's field name (bmx_field_name, cut to 63 characters, the
 * namelengthmax of Octave and of older MATLAB) into names: BSIM_EINPUT
 * naming both columns if two become one name, which would keep only the
 * later column. */
typedef char field_name[64];
static int field_names(const char *path, const table *t, field_name *names, bsim_error *err)
{
	for (size_t c = 0; c < t->nc; c++) {
		bmx_field_name(t->fields[c], names[c], sizeof names[c]);
		for (size_t d = 0; d < c; d++)
			if (strcmp(names[d], names[c]) == 0)
				return bsim_error_set(
				        err, BSIM_EINPUT,
				        "%s:1: columns %zu (%s) and %zu (%s) both become the field "
				        "%s "
				        "(letters, digits and underscores, at most 63 characters); "
				        "expected names that differ there",
				        path, d + 1, t->fields[d], c + 1, t->fields[c], names[c]);
	}
	return BSIM_OK;
}

static mxArray *table_struct(const table *t, const field_name *names)
{
	mxArray *s = mxCreateStructMatrix(1, 1, 0, NULL);
	size_t n = t->rows > 0 ? t->rows - 1 : 0;
	for (size_t c = 0; c < t->nc; c++) {
		int numeric = 1;
		double x;
		for (size_t r = 1; numeric && r < t->rows; r++)
			numeric = field_number(t->fields[r * t->nc + c], &x);
		mxArray *col;
		if (numeric) {
			double *d;
			col = bmx_column(n, &d);
			for (size_t r = 0; r < n; r++)
				field_number(t->fields[(r + 1) * t->nc + c], &d[r]);
		} else {
			col = mxCreateCellMatrix((mwSize)n, 1);
			for (size_t r = 0; r < n; r++)
				mxSetCell(col, (mwIndex)r,
				          bmx_string(t->fields[(r + 1) * t->nc + c]));
		}
		bmx_set(s, 0, names[c], col);
	}
	return s;
}

void mexFunction(int nlhs, mxArray *plhs[], int nrhs, const mxArray *prhs[])
{
	(void)nlhs;
	bmx_pool pool = {0};
	table t = {0};
	bsim_error err;
	bsim_error_clear(&err);
	const char *path = NULL;
	mxArray *out = NULL;
	int rc = nrhs == 1 ? bmx_text("file", prhs[0], &pool, &path, &err)
	                   : bsim_error_set(&err, BSIM_EINPUT, "expected one file name");
	if (rc == BSIM_OK)
		rc = read_table(path, &t, &err);
	field_name *names = rc == BSIM_OK ? calloc(t.nc + 1, sizeof *names) : NULL;
	if (rc == BSIM_OK && !names)
		rc = bsim_error_set(&err, BSIM_EFAIL, "out of memory");
	if (rc == BSIM_OK)
		rc = field_names(path, &t, names, &err);
	if (rc == BSIM_OK)
		out = table_struct(&t, names);
	free(names);
	free(t.fields);
	bsim_output_table_text_free(t.text);
	bmx_pool_free(&pool);
	if (rc != BSIM_OK)
		bmx_fail(&err);
	plhs[0] = out;
}
