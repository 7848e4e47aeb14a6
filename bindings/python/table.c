/* _beamsim.read_table: a CSV table of beamsim's (trials.csv, ...) as a
 * dict of NumPy arrays by column, made while the rows are read
 * (beamsim/table.h), so that what is held is the arrays and one line, not
 * the file's rows as Python objects (1.6 KB a row of trials.csv).
 *
 * A column's type is what Python would give it from its fields' text:
 * int64 if every field is an integer, float64 if every field is a number
 * or empty (NaN), else str. A column is typed as it is read: its integers
 * turn float in place when a fraction or an empty field comes; a column
 * that turns text after it held numbers has lost their text, and the file
 * is read again with that column text from the start. Numbers are kept in
 * arrays sized by the file's rows, handed to NumPy as they are; text as one
 * code a row into the column's distinct strings, which become the str
 * array at the end. */
#define _POSIX_C_SOURCE 200809L

#include "pyb.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

enum { K_INT, K_FLOAT, K_TEXT };

/* A text column's distinct strings, each once, by hash. */
typedef struct labels {
	PyObject *list; /* str objects, in order of first appearance */
	size_t *slot;   /* n_slots (a power of 2): label index + 1, 0 free */
	size_t n_slots;
} labels;

typedef struct column {
	int kind;
	int numbers; /* a number seen (not only empty fields) */
	int lost;    /* turned text after numbers: read again */
	void *data;  /* rows: int64_t, double, or uint32_t codes (text) */
	labels l;
} column;

typedef struct table {
	int n_cols;
	long rows, cap;
	column *cols;
	const unsigned char *text; /* columns to read as text from the start */
} table;

/* Python's int() of the text, for the texts beamsim writes: a sign and
 * decimal digits within int64. */
static int int_text(const char *s, int64_t *out)
{
	const char *p = s + (*s == '-' || *s == '+');
	if (*p < '0' || *p > '9')
		return 0;
	for (const char *d = p; *d; d++)
		if (*d < '0' || *d > '9')
			return 0;
	errno = 0;
	char *end;
	long long v = strtoll(s, &end, 10);
	if (errno == ERANGE || *end)
		return 0;
	*out = v;
	return 1;
}

/* Python's float() of the text: a decimal number, inf or nan; C's hex and
 * nan(...) are not Python's. */
static int float_text(const char *s, double *out)
{
	if (!*s || strpbrk(s, "xX(") != NULL)
		return 0;
	char *end;
	*out = strtod(s, &end);
	return *end == '\0';
}

static size_t text_hash(const char *s)
{
	size_t h = 1469598103934665603u; /* FNV-1a */
	for (; *s; s++)
		h = (h ^ (unsigned char)*s) * 1099511628211u;
	return h;
}

/* The code of s in l, added if new; -1 with an exception set. */
static long label_code(labels *l, const char *s)
{
	Py_ssize_t n = l->list ? PyList_GET_SIZE(l->list) : 0;
	if (2 * ((size_t)n + 1) > l->n_slots) {
		size_t size = l->n_slots ? 2 * l->n_slots : 64;
		size_t *slot = calloc(size, sizeof *slot);
		if (!slot) {
			PyErr_NoMemory();
			return -1;
		}
		for (Py_ssize_t i = 0; i < n; i++) {
			size_t k = text_hash(PyUnicode_AsUTF8(PyList_GET_ITEM(l->list, i)));
			while (slot[k & (size - 1)])
				k++;
			slot[k & (size - 1)] = (size_t)i + 1;
		}
		free(l->slot);
		l->slot = slot;
		l->n_slots = size;
	}
	if (!l->list && !(l->list = PyList_New(0)))
		return -1;
	for (size_t k = text_hash(s);; k++) {
		size_t *at = &l->slot[k & (l->n_slots - 1)];
		if (*at == 0) {
			PyObject *str = PyUnicode_DecodeUTF8(s, (Py_ssize_t)strlen(s), "replace");
			if (!str || PyList_Append(l->list, str) != 0) {
				Py_XDECREF(str);
				return -1;
			}
			Py_DECREF(str);
			*at = (size_t)n + 1;
			return (long)n;
		}
		if (strcmp(PyUnicode_AsUTF8(PyList_GET_ITEM(l->list, *at - 1)), s) == 0)
			return (long)*at - 1;
	}
}

static void column_free(column *c)
{
	free(c->data);
	free(c->l.slot);
	Py_XDECREF(c->l.list);
	memset(c, 0, sizeof *c);
}

/* Column c becomes text at row r: its earlier fields were all empty (their
 * text is "") or it is lost. 0, or -1 with an exception set. */
static int turn_text(table *t, column *c, long r)
{
	free(c->data);
	c->data = NULL;
	c->kind = K_TEXT;
	if (c->numbers) {
		c->lost = 1;
		return 0;
	}
	if (!(c->data = malloc((size_t)t->cap * sizeof(uint32_t)))) {
		PyErr_NoMemory();
		return -1;
	}
	long empty = r > 0 ? label_code(&c->l, "") : 0;
	for (long k = 0; k < r; k++)
		((uint32_t *)c->data)[k] = (uint32_t)empty;
	return empty < 0 ? -1 : 0;
}

/* One field into its column at row r. 0, or -1 with an exception set. */
static int put(table *t, column *c, long r, const char *s)
{
	int64_t v;
	double x;
	if (c->kind == K_INT && int_text(s, &v)) {
		((int64_t *)c->data)[r] = v;
		c->numbers = 1;
		return 0;
	}
	if (c->kind == K_INT && (!*s || float_text(s, &x))) {
		/* A fraction or an empty field: the integers so far as doubles. */
		int64_t *iv = c->data;
		double *dv = c->data;
		for (long k = 0; k < r; k++)
			dv[k] = (double)iv[k];
		c->kind = K_FLOAT;
	}
	if (c->kind == K_FLOAT && (!*s || float_text(s, &x))) {
		((double *)c->data)[r] = *s ? x : NAN;
		c->numbers |= *s != '\0';
		return 0;
	}
	if (c->kind != K_TEXT && turn_text(t, c, r) != 0)
		return -1;
	if (c->lost)
		return 0;
	long code = label_code(&c->l, s);
	if (code < 0)
		return -1;
	((uint32_t *)c->data)[r] = (uint32_t)code;
	return 0;
}

/* Room for cap rows in every column. */
static int grow(table *t, long cap)
{
	for (int i = 0; i < t->n_cols; i++) {
		column *c = &t->cols[i];
		if (c->lost)
			continue;
		size_t size = c->kind == K_TEXT ? sizeof(uint32_t) : 8;
		void *d = realloc(c->data, (size_t)(cap > 0 ? cap : 1) * size);
		if (!d) {
			PyErr_NoMemory();
			return -1;
		}
		c->data = d;
	}
	t->cap = cap;
	return 0;
}

static void table_free(table *t)
{
	for (int i = 0; t->cols && i < t->n_cols; i++)
		column_free(&t->cols[i]);
	free(t->cols);
	t->cols = NULL;
}

/* One reading of path into t (its columns text where t->text says so).
 * 0, or -1 with an exception set. */
static int table_pass(const char *path, table *t, PyObject **names)
{
	bsim_error err;
	bsim_table_reader *r;
	double rows = bsim_table_count_rows(path);
	if (bsim_table_open(path, &r, &err) != BSIM_OK) {
		pyb_raise(err.code, &err);
		return -1;
	}
	t->n_cols = bsim_table_columns(r);
	t->rows = 0;
	t->cols = calloc((size_t)t->n_cols, sizeof *t->cols);
	int rc = t->cols ? 0 : (PyErr_NoMemory(), -1);
	for (int i = 0; !rc && i < t->n_cols; i++)
		t->cols[i].kind = t->text && t->text[i] ? K_TEXT : K_INT;
	if (!rc && names && !(*names = PyList_New(0)))
		rc = -1;
	for (int i = 0; !rc && names && i < t->n_cols; i++) {
		const char *name = bsim_table_column(r, i);
		PyObject *s = PyUnicode_DecodeUTF8(name, (Py_ssize_t)strlen(name), "replace");
		rc = s && PyList_Append(*names, s) == 0 ? 0 : -1;
		Py_XDECREF(s);
	}
	/* Sized by the file's rows before the first: no column is copied as
	 * it grows (a quoted line break makes the count larger, never
	 * smaller; a file that grew meanwhile is grown after). */
	if (!rc)
		rc = grow(t, rows > 0 ? (long)rows : 1);
	const char *const *cells;
	int got = 0;
	while (!rc && (got = bsim_table_next(r, &cells, &err)) == 1) {
		if (t->rows == t->cap)
			rc = grow(t, 2 * t->cap);
		for (int i = 0; !rc && i < t->n_cols; i++)
			rc = put(t, &t->cols[i], t->rows, cells[i]);
		t->rows++;
	}
	bsim_table_close(r);
	if (!rc && got < 0) {
		pyb_raise(err.code, &err);
		rc = -1;
	}
	return rc;
}

/* The column as a NumPy array; its data handed over. New reference. */
static PyObject *column_array(column *c, long rows)
{
	if (c->kind == K_TEXT)
		return pyb_text_column(c->data, rows, c->l.list);
	PyObject *a = pyb_adopt(c->data, rows, c->kind == K_INT);
	if (a)
		c->data = NULL;
	return a;
}

static int any_lost(const table *t)
{
	int lost = 0;
	for (int i = 0; i < t->n_cols; i++)
		lost |= t->cols[i].lost;
	return lost;
}

PyObject *pyb_read_table(PyObject *self, PyObject *args)
{
	(void)self;
	const char *path;
	if (!PyArg_ParseTuple(args, "s", &path))
		return NULL;
	table t = {0};
	PyObject *names = NULL, *d = NULL;
	int rc = table_pass(path, &t, &names);
	if (!rc && any_lost(&t)) {
		/* again, with the columns that turned text text from the start */
		int n_cols = t.n_cols;
		unsigned char *text = malloc((size_t)n_cols);
		for (int i = 0; text && i < n_cols; i++)
			text[i] = t.cols[i].kind == K_TEXT;
		table_free(&t);
		t.text = text;
		rc = text ? table_pass(path, &t, NULL) : (PyErr_NoMemory(), -1);
		if (!rc && (t.n_cols != n_cols || any_lost(&t))) {
			PyErr_Format(PyExc_ValueError,
			             "%s: expected the same table twice, got a file that changed "
			             "while it was read",
			             path);
			rc = -1;
		}
		free(text);
	}
	if (!rc)
		d = PyDict_New();
	for (int i = 0; d && i < t.n_cols; i++) {
		PyObject *a = column_array(&t.cols[i], t.rows);
		if (!a || PyDict_SetItem(d, PyList_GET_ITEM(names, i), a) != 0)
			Py_CLEAR(d);
		Py_XDECREF(a);
		column_free(&t.cols[i]);
	}
	table_free(&t);
	Py_XDECREF(names);
	return d;
}
