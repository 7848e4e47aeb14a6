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
 * The file is read as the library reads its tables (beamsim/table.h): a
 * regular file of at most 16 GiB, without a NUL byte, ending in a line
 * feed, every row as wide as the header. Two columns whose names become
 * one field name (a.b and a_b; names alike in their first 63 characters,
 * Octave's namelengthmax and older MATLAB's, where the names are cut) are
 * refused, naming both, rather than one kept silently. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bsim_mex.h"

/* The table's fields, header first, row by row: their texts one after
 * another in one block (each ending in a NUL), found by offset. */
typedef struct table {
	char *text;
	size_t len, room;
	size_t *at; /* rows x nc offsets into text */
	size_t nc, rows, cap;
} table;

static const char *field(const table *t, size_t r, size_t c)
{
	return t->text + t->at[r * t->nc + c];
}

static int keep_row(table *t, const char *const *cells, bsim_error *err)
{
	if ((t->rows + 1) * t->nc > t->cap) {
		size_t cap = (t->rows + 1) * t->nc * 2;
		size_t *more = realloc(t->at, cap * sizeof *more);
		if (!more)
			return bsim_error_set(err, BSIM_EFAIL, "out of memory");
		t->at = more;
		t->cap = cap;
	}
	for (size_t c = 0; c < t->nc; c++) {
		size_t n = strlen(cells[c]) + 1;
		if (t->len + n > t->room) {
			size_t room = 2 * (t->len + n) + 4096;
			char *more = realloc(t->text, room);
			if (!more)
				return bsim_error_set(err, BSIM_EFAIL, "out of memory");
			t->text = more;
			t->room = room;
		}
		memcpy(t->text + t->len, cells[c], n);
		t->at[t->rows * t->nc + c] = t->len;
		t->len += n;
	}
	t->rows++;
	return BSIM_OK;
}

static int read_table(const char *path, table *t, bsim_error *err)
{
	bsim_table_reader *r;
	if (bsim_table_open(path, &r, err) != BSIM_OK)
		return err->code;
	t->nc = (size_t)bsim_table_columns(r);
	const char **names = malloc((t->nc + 1) * sizeof *names);
	int rc = names ? BSIM_OK : bsim_error_set(err, BSIM_EFAIL, "out of memory");
	for (size_t c = 0; rc == BSIM_OK && c < t->nc; c++)
		names[c] = bsim_table_column(r, (int)c);
	if (rc == BSIM_OK) /* row 0 is the header */
		rc = keep_row(t, names, err);
	free(names);
	const char *const *cells;
	int got = 1;
	while (rc == BSIM_OK && (got = bsim_table_next(r, &cells, err)) == 1)
		rc = keep_row(t, cells, err);
	if (rc == BSIM_OK && got < 0)
		rc = err->code;
	bsim_table_close(r);
	return rc;
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
		bmx_field_name(field(t, 0, c), names[c], sizeof names[c]);
		for (size_t d = 0; d < c; d++)
			if (strcmp(names[d], names[c]) == 0)
				return bsim_error_set(
				        err, BSIM_EINPUT,
				        "%s:1: columns %zu (%s) and %zu (%s) both become the field "
				        "%s "
				        "(letters, digits and underscores, at most 63 characters); "
				        "expected names that differ there",
				        path, d + 1, field(t, 0, d), c + 1, field(t, 0, c),
				        names[c]);
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
			numeric = field_number(field(t, r, c), &x);
		mxArray *col;
		if (numeric) {
			double *d;
			col = bmx_column(n, &d);
			for (size_t r = 0; r < n; r++)
				field_number(field(t, r + 1, c), &d[r]);
		} else {
			col = mxCreateCellMatrix((mwSize)n, 1);
			for (size_t r = 0; r < n; r++)
				mxSetCell(col, (mwIndex)r, bmx_string(field(t, r + 1, c)));
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
	free(t.at);
	free(t.text);
	bmx_pool_free(&pool);
	if (rc != BSIM_OK)
		bmx_fail(&err);
	plhs[0] = out;
}
