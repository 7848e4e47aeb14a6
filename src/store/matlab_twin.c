/* MATLAB twins of CSV and JSON files (store/matlab.h).
 *
 * Both converters build a tree of bsim_mat_field (mat.h) whose arrays live
 * in an arena or the table's columns, freed after the write. A CSV table
 * is read as a stream into the arrays written (a twin may be of a million
 * rows); JSON is read with libfyaml (JSON is YAML), the reader of every
 * other beamsim input; a number is a plain scalar that reads as one, so a
 * quoted "7" stays text. */
#define _POSIX_C_SOURCE 200809L
#include "store/matlab.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "util/csv_stream.h"
#include "util/csv_table.h"
#include "store/mat.h"
#include "util/yaml_doc.h"
#include "beamsim/limits.h"

/* ---- an arena of allocations freed together -------------------------- */

typedef struct arena {
	void **p;
	int n, cap;
	int oom;
} arena;

static void *arena_alloc(arena *a, size_t size)
{
	if (a->oom)
		return NULL;
	if (a->n == a->cap) {
		int cap = a->cap ? 2 * a->cap : 64;
		void **p = realloc(a->p, (size_t)cap * sizeof *p);
		if (!p) {
			a->oom = 1;
			return NULL;
		}
		a->p = p;
		a->cap = cap;
	}
	void *m = calloc(1, size ? size : 1);
	if (!m) {
		a->oom = 1;
		return NULL;
	}
	a->p[a->n++] = m;
	return m;
}

static char *arena_strdup(arena *a, const char *s, size_t len)
{
	char *d = arena_alloc(a, len + 1);
	if (d)
		memcpy(d, s, len);
	return d;
}

static void arena_free(arena *a)
{
	for (int i = 0; i < a->n; i++)
		free(a->p[i]);
	free(a->p);
	memset(a, 0, sizeof *a);
}

/* A MATLAB identifier for key, in the arena. */
static const char *mat_ident(arena *a, const char *key)
{
	char buf[64];
	bsim_mat_name(key, buf, sizeof buf);
	return arena_strdup(a, buf, strlen(buf));
}

int bsim_matlab_path(const char *path, char *out, size_t size, bsim_error *err)
{
	size_t n = strlen(path);
	static const char *const ext[] = {".csv", ".json"};
	for (int i = 0; i < 2; i++) {
		size_t e = strlen(ext[i]);
		if (n > e && strcmp(path + n - e, ext[i]) == 0) {
			n -= e;
			break;
		}
	}
	if (n + sizeof ".mat" > size)
		return bsim_error_set(err, BSIM_EFAIL, "%s: path too long for its .mat twin", path);
	memcpy(out, path, n);
	memcpy(out + n, ".mat", sizeof ".mat");
	return BSIM_OK;
}

/* ---- CSV --------------------------------------------------------------- */

/* A CSV table is read as a stream, row by row, each column kept as it
 * will be written: numbers as one array of doubles (8 bytes a cell), text
 * as a pointer a cell to one copy of each distinct string. A column is
 * numbers if every non-empty cell is one (an empty cell is NaN), else text,
 * decided on the whole table: a column read as numbers whose later cell is
 * text has lost the text of its earlier numbers, so the table is read a
 * second time with that column as text from the start (a column empty
 * until its first text needs no second reading: its earlier cells are ""). */

typedef struct twin_col {
	double *v;      /* numbers, while the column is numeric */
	const char **s; /* text (interned), once it is text */
	int text;
	int numbers; /* a number seen while numeric */
} twin_col;

/* Strings kept once each, in arena blocks that never move. */
typedef struct intern {
	const char **slot; /* n_slots (a power of 2), NULL free */
	size_t n_slots, n;
	char *block;
	size_t used, size;
} intern;

/* The group column of a sweep's table, checked as csv_table_numbers and
 * the group range check did: the first cell that is no number, else the
 * first out of range, reported once the file is known to be sound. */
typedef struct group_check {
	int col;
	long bad_line, range_line;
	char *bad, *range; /* the cells' text */
} group_check;

typedef struct twin_table {
	arena a;
	int n_cols;
	long n_rows;
	const char **names;
	twin_col *cols;
	intern in;
	int over; /* more rows than the limit mat_rows: nothing kept */
	int lost; /* a column turned text after numbers: nothing kept, read again */
} twin_table;

static size_t str_hash(const char *s)
{
	size_t h = 1469598103934665603u; /* FNV-1a */
	for (; *s; s++)
		h = (h ^ (unsigned char)*s) * 1099511628211u;
	return h;
}

static const char *intern_str(arena *a, intern *in, const char *s)
{
	size_t len = strlen(s);
	if (2 * (in->n + 1) > in->n_slots) {
		size_t n = in->n_slots ? 2 * in->n_slots : 256;
		const char **grown = calloc(n, sizeof *grown);
		if (!grown)
			return NULL;
		for (size_t k = 0; k < in->n_slots; k++) {
			if (!in->slot[k])
				continue;
			size_t m = str_hash(in->slot[k]) & (n - 1);
			while (grown[m])
				m = (m + 1) & (n - 1);
			grown[m] = in->slot[k];
		}
		free(in->slot);
		in->slot = grown;
		in->n_slots = n;
	}
	size_t j = str_hash(s) & (in->n_slots - 1);
	while (in->slot[j] && strcmp(in->slot[j], s) != 0)
		j = (j + 1) & (in->n_slots - 1);
	if (in->slot[j])
		return in->slot[j];
	if (in->used + len + 1 > in->size) {
		size_t size = len + 1 > 65536 ? len + 1 : 65536;
		if (!(in->block = arena_alloc(a, size)))
			return NULL;
		in->used = 0;
		in->size = size;
	}
	char *d = in->block + in->used;
	memcpy(d, s, len + 1);
	in->used += len + 1;
	in->n++;
	return in->slot[j] = d;
}

static void twin_drop(twin_table *t)
{
	for (int c = 0; t->cols && c < t->n_cols; c++) {
		free(t->cols[c].v);
		free(t->cols[c].s);
		t->cols[c].v = NULL;
		t->cols[c].s = NULL;
	}
}

static void twin_free(twin_table *t)
{
	twin_drop(t);
	free(t->cols);
	free(t->in.slot);
	arena_free(&t->a);
	memset(t, 0, sizeof *t);
}

static void group_check_row(group_check *g, const csv_stream *s, int n_groups)
{
	const char *cell = s->cells[g->col];
	double v;
	if (csv_number(cell, &v) != 0) {
		if (!g->bad_line) {
			g->bad_line = s->line;
			g->bad = strdup(cell);
		}
	} else if (!g->range_line && (v != floor(v) || v < 0 || v >= n_groups)) {
		g->range_line = s->line;
		g->range = strdup(cell);
	}
}

/* Grows every kept column to cap rows. */
static int twin_grow(twin_table *t, size_t cap)
{
	for (int c = 0; c < t->n_cols; c++) {
		twin_col *col = &t->cols[c];
		void *p = col->text ? realloc(col->s, cap * sizeof *col->s)
		                    : realloc(col->v, cap * sizeof *col->v);
		if (!p)
			return -1;
		if (col->text)
			col->s = p;
		else
			col->v = p;
	}
	return 0;
}

/* Cell c of row r into its column; 1 if a numeric column turned text
 * after holding numbers (the table must be read again), -1 out of memory. */
static int twin_cell(twin_table *t, int c, long r, size_t cap, const char *cell)
{
	twin_col *col = &t->cols[c];
	int keep = !t->over && !t->lost;
	if (!col->text) {
		double x;
		int num = csv_number(cell, &x) == 0;
		if (num || !*cell) {
			if (keep)
				col->v[r] = num ? x : NAN;
			col->numbers |= num;
			return 0;
		}
		col->text = 1;
		free(col->v);
		col->v = NULL;
		if (col->numbers) {
			twin_drop(t);
			t->lost = 1;
			return 1;
		}
		if (keep) {
			if (!(col->s = malloc(cap * sizeof *col->s)))
				return -1;
			for (long k = 0; k < r; k++)
				col->s[k] = "";
		}
	}
	if (keep && !(col->s[r] = intern_str(&t->a, &t->in, cell)))
		return -1;
	return 0;
}

/* One reading of csv_path into t; columns with text[c] set are text from
 * the start. t->lost is set if a column must be read again as text. */
static int twin_pass(const char *path, twin_table *t, const unsigned char *text, group_check *g,
                     int n_groups, bsim_error *err)
{
	memset(t, 0, sizeof *t);
	csv_stream s;
	int rc = csv_stream_open(path, &s, err);
	if (rc)
		return rc;
	t->n_cols = s.n_cols;
	t->names = arena_alloc(&t->a, (size_t)s.n_cols * sizeof *t->names);
	t->cols = calloc((size_t)s.n_cols, sizeof *t->cols);
	for (int c = 0; t->names && c < s.n_cols; c++)
		t->names[c] = arena_strdup(&t->a, s.names[c], strlen(s.names[c]));
	if (g) {
		g->col = -1;
		for (int c = s.n_cols - 1; c >= 0; c--)
			if (strcmp(s.names[c], "group") == 0)
				g->col = c;
	}
	const double limit = bsim_limits_get()->mat_rows;
	size_t cap = 0;
	int got = 0, oom = !t->cols || t->a.oom;
	for (int c = 0; !oom && c < t->n_cols; c++)
		t->cols[c].text = text ? text[c] : 0;
	/* A table over the limit keeps nothing: it is only checked. */
	t->over = csv_count_lines(path) - 1 > limit;
	while (!oom && (got = csv_stream_next(&s, err)) == 1) {
		long r = t->n_rows++;
		if (g && g->col >= 0)
			group_check_row(g, &s, n_groups);
		if (!t->over && (double)t->n_rows > limit) {
			t->over = 1;
			twin_drop(t);
		}
		if (!t->over && !t->lost && (size_t)r == cap) {
			cap = cap ? 2 * cap : 16;
			oom = twin_grow(t, cap) != 0;
		}
		for (int c = 0; !oom && !t->over && c < t->n_cols; c++) {
			oom = twin_cell(t, c, r, cap, s.cells[c]) < 0;
		}
	}
	csv_stream_close(&s);
	if (oom)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory reading %s", path);
	return got < 0 ? (err ? err->code : BSIM_EINPUT) : BSIM_OK;
}

/* Reads csv_path into t, a second time if a column turned text late. */
static int twin_read(const char *path, twin_table *t, group_check *g, int n_groups, bsim_error *err)
{
	if (g)
		memset(g, 0, sizeof *g);
	int rc = twin_pass(path, t, NULL, g, n_groups, err);
	if (rc == BSIM_OK && t->lost && !t->over) {
		unsigned char *text = malloc((size_t)t->n_cols);
		for (int c = 0; text && c < t->n_cols; c++)
			text[c] = (unsigned char)t->cols[c].text;
		twin_free(t);
		if (g) {
			free(g->bad);
			free(g->range);
			memset(g, 0, sizeof *g);
		}
		rc = text ? twin_pass(path, t, text, g, n_groups, err)
		          : bsim_error_set(err, BSIM_EFAIL, "out of memory reading %s", path);
		free(text);
		if (rc == BSIM_OK && t->lost && !t->over)
			rc = bsim_error_set(err, BSIM_EINPUT,
			                    "%s: expected the same table twice, got "
			                    "a file that changed while it was read",
			                    path);
	}
	if (rc != BSIM_OK)
		twin_free(t);
	return rc;
}

/* The fields of every column, plus room for n_extra more at the end. */
static bsim_mat_field *twin_fields(twin_table *t, int n_extra)
{
	bsim_mat_field *f = arena_alloc(&t->a, (size_t)(t->n_cols + n_extra) * sizeof *f);
	for (int c = 0; f && c < t->n_cols; c++) {
		const char *name = mat_ident(&t->a, t->names[c]);
		if (!name)
			return NULL;
		const twin_col *col = &t->cols[c];
		f[c] = col->text ? bsim_mat_strings(name, col->s, (size_t)t->n_rows)
		                 : bsim_mat_column(name, col->v, (size_t)t->n_rows);
	}
	return f;
}

static const char *base_name(const char *path)
{
	const char *slash = strrchr(path, '/');
	return slash ? slash + 1 : path;
}

/* A table over the limit: no twin (and none left of an earlier table), a
 * note (bsim_note), and the note in err with BSIM_OK. */
static int twin_skip(const char *csv_path, const char *mat_path, const twin_table *t,
                     bsim_error *err)
{
	remove(mat_path);
	char note[BSIM_ERROR_MSG_MAX];
	snprintf(note, sizeof note,
	         "%s: %ld rows, over the limit mat_rows = %.15g: no %s; MATLAB's readtable "
	         "reads the CSV (raise with --limit mat_rows=%ld)",
	         base_name(csv_path), t->n_rows, bsim_limits_get()->mat_rows, base_name(mat_path),
	         t->n_rows);
	bsim_error_set(err, BSIM_OK, "%s", note);
	bsim_note("%s", note);
	return BSIM_OK;
}

/* A table with a group or trial column gets a second variable, note: its
 * indices are beamsim's, 0-based, and MATLAB's start at 1. */
static const char *index_note(const bsim_mat_field *fields, int n)
{
	int group = 0, trial = 0;
	for (int i = 0; i < n; i++) {
		group |= strcmp(fields[i].name, "group") == 0;
		trial |= strcmp(fields[i].name, "trial") == 0;
	}
	if (group && trial)
		return "group and trial are 0-based, as in the CSV: group g is row g+1 of "
		       "summary.mat's groups fields (summary.groups.p_traverse(g+1)), and "
		       "`beamsim run DIR --group g --trial t` (DIR: this sweep's directory) "
		       "replays "
		       "trial t of group g";
	if (group)
		return "group is 0-based, as in the CSV: group g is row g+1 of summary.mat's "
		       "groups fields (summary.groups.p_traverse(g+1))";
	if (trial)
		return "trial is 0-based, as in the CSV: `beamsim run DIR --trial t` (DIR: "
		       "this run's directory) replays trial t";
	return NULL;
}

static int write_var(const char *mat_path, const char *var, bsim_mat_field *fields, int n,
                     bsim_error *err)
{
	const char *note = index_note(fields, n);
	bsim_mat_field v[2] = {bsim_mat_struct(var, fields, n), bsim_mat_string("note", &note)};
	return bsim_mat_write(mat_path, v, note ? 2 : 1, err);
}

int bsim_matlab_from_csv(const char *csv_path, const char *mat_path, const char *var,
                         bsim_error *err)
{
	twin_table t;
	int rc = twin_read(csv_path, &t, NULL, 0, err);
	if (rc)
		return rc;
	bsim_error_clear(err);
	if (t.over) {
		rc = twin_skip(csv_path, mat_path, &t, err);
	} else {
		bsim_mat_field *f = twin_fields(&t, 0);
		rc = f ? write_var(mat_path, var, f, t.n_cols, err)
		       : bsim_error_set(err, BSIM_EFAIL, "out of memory for %s", mat_path);
	}
	twin_free(&t);
	return rc;
}

/* ---- JSON -------------------------------------------------------------- */

enum { J_NUMBER, J_STRING, J_MAP, J_SEQ, J_ABSENT };

/* What a node is; a number (true, false and null too) goes to *v. */
static int json_kind(struct fy_node *n, double *v)
{
	if (!n)
		return J_ABSENT;
	if (fy_node_is_mapping(n))
		return J_MAP;
	if (fy_node_is_sequence(n))
		return J_SEQ;
	const char *p = ydoc_plain(n);
	if (p && ydoc_number(n, v) == YDOC_NUM_OK)
		return J_NUMBER;
	if (p && (strcmp(p, "true") == 0 || strcmp(p, "false") == 0)) {
		*v = p[0] == 't';
		return J_NUMBER;
	}
	if (p && strcmp(p, "null") == 0) {
		*v = NAN;
		return J_NUMBER;
	}
	return J_STRING;
}

static const char *json_text(arena *a, struct fy_node *n)
{
	if (!n)
		return "";
	if (fy_node_is_scalar(n)) {
		size_t len;
		const char *s = fy_node_get_scalar(n, &len);
		return s ? arena_strdup(a, s, len) : "";
	}
	char *flow = ydoc_flow_text(n);
	const char *s = flow ? arena_strdup(a, flow, strlen(flow)) : NULL;
	free(flow);
	return s;
}

static int json_value(arena *a, struct fy_node *n, const char *name, bsim_mat_field *out);
static int json_column(arena *a, struct fy_node **nodes, size_t n, const char *name,
                       bsim_mat_field *out);

/* Keys of the mappings among nodes, in order of first appearance. */
static int map_keys(arena *a, struct fy_node **nodes, size_t n, const char ***keys)
{
	int cap = 8, k = 0;
	const char **out = arena_alloc(a, (size_t)cap * sizeof *out);
	for (size_t i = 0; out && i < n; i++) {
		if (!nodes[i] || !fy_node_is_mapping(nodes[i]))
			continue;
		void *it = NULL;
		struct fy_node_pair *p;
		while ((p = fy_node_mapping_iterate(nodes[i], &it)) != NULL) {
			const char *key = json_text(a, fy_node_pair_key(p));
			int seen = 0;
			for (int j = 0; key && j < k && !seen; j++)
				seen = strcmp(out[j], key) == 0;
			if (!key || seen)
				continue;
			if (k == cap) {
				const char **o = arena_alloc(a, (size_t)cap * 2 * sizeof *o);
				if (!o)
					return -1;
				memcpy(o, out, (size_t)cap * sizeof *o);
				out = o;
				cap *= 2;
			}
			out[k++] = key;
		}
	}
	*keys = out;
	return out ? k : -1;
}

/* nodes[i] (mappings or absent) as a struct of n-row columns. */
static int json_table(arena *a, struct fy_node **nodes, size_t n, const char *name,
                      bsim_mat_field *out)
{
	const char **keys;
	int k = map_keys(a, nodes, n, &keys);
	if (k < 0)
		return -1;
	bsim_mat_field *f = arena_alloc(a, (size_t)k * sizeof *f);
	struct fy_node **col = arena_alloc(a, n * sizeof *col);
	if (!f || !col)
		return -1;
	for (int j = 0; j < k; j++) {
		for (size_t i = 0; i < n; i++)
			col[i] = nodes[i] && fy_node_is_mapping(nodes[i])
			                 ? fy_node_mapping_lookup_by_string(nodes[i], keys[j], -1)
			                 : NULL;
		if (json_column(a, col, n, mat_ident(a, keys[j]), &f[j]) != 0)
			return -1;
	}
	*out = bsim_mat_struct(name, f, k);
	return 0;
}

/* Length of a list of numbers, -1 if n is anything else. */
static int number_list(struct fy_node *n)
{
	if (!n || !fy_node_is_sequence(n))
		return -1;
	int len = fy_node_sequence_item_count(n);
	for (int i = 0; i < len; i++) {
		double v;
		if (json_kind(fy_node_sequence_get_by_index(n, i), &v) != J_NUMBER)
			return -1;
	}
	return len;
}

/* One value per row: numbers, text, nested tables or rows of a matrix. */
static int json_column(arena *a, struct fy_node **nodes, size_t n, const char *name,
                       bsim_mat_field *out)
{
	int numbers = 1, maps = 1, width = -2;
	for (size_t i = 0; i < n; i++) {
		double v;
		int kind = json_kind(nodes[i], &v);
		if (kind == J_ABSENT)
			continue;
		numbers &= kind == J_NUMBER;
		maps &= kind == J_MAP;
		int w = number_list(nodes[i]);
		width = w < 0 || (width != -2 && w != width) ? -1 : w;
	}
	if (!name)
		return -1;
	if (numbers) {
		double *v = arena_alloc(a, n * sizeof *v);
		if (!v)
			return -1;
		for (size_t i = 0; i < n; i++)
			if (json_kind(nodes[i], &v[i]) != J_NUMBER)
				v[i] = NAN;
		*out = bsim_mat_column(name, v, n);
		return 0;
	}
	if (maps)
		return json_table(a, nodes, n, name, out);
	if (width > 0) {
		double *m = arena_alloc(a, n * (size_t)width * sizeof *m);
		if (!m)
			return -1;
		for (size_t i = 0; i < n; i++)
			for (int j = 0; j < width; j++) {
				double v = NAN;
				if (nodes[i])
					json_kind(fy_node_sequence_get_by_index(nodes[i], j), &v);
				m[(size_t)j * n + i] = v; /* column-major */
			}
		*out = bsim_mat_matrix(name, m, n, (size_t)width);
		return 0;
	}
	const char **s = arena_alloc(a, n * sizeof *s);
	if (!s)
		return -1;
	for (size_t i = 0; i < n; i++)
		if (!(s[i] = json_text(a, nodes[i])))
			return -1;
	*out = bsim_mat_strings(name, s, n);
	return 0;
}

static int json_value(arena *a, struct fy_node *n, const char *name, bsim_mat_field *out)
{
	double v;
	if (!name)
		return -1;
	switch (json_kind(n, &v)) {
	case J_NUMBER: {
		double *d = arena_alloc(a, sizeof *d);
		if (!d)
			return -1;
		*d = v;
		*out = bsim_mat_column(name, d, 1);
		return 0;
	}
	case J_MAP: {
		int k = fy_node_mapping_item_count(n);
		bsim_mat_field *f = arena_alloc(a, (size_t)k * sizeof *f);
		if (!f)
			return -1;
		void *it = NULL;
		struct fy_node_pair *p;
		int j = 0;
		while ((p = fy_node_mapping_iterate(n, &it)) != NULL && j < k) {
			const char *key = json_text(a, fy_node_pair_key(p));
			if (!key || json_value(a, fy_node_pair_value(p), mat_ident(a, key), &f[j]))
				return -1;
			j++;
		}
		*out = bsim_mat_struct(name, f, j);
		return 0;
	}
	case J_SEQ: {
		size_t len = (size_t)fy_node_sequence_item_count(n);
		struct fy_node **items = arena_alloc(a, (len ? len : 1) * sizeof *items);
		if (!items)
			return -1;
		for (size_t i = 0; i < len; i++)
			items[i] = fy_node_sequence_get_by_index(n, (int)i);
		if (number_list(n) >= 0) { /* a row, as MATLAB writes [1 2 3] */
			double *d = arena_alloc(a, (len ? len : 1) * sizeof *d);
			if (!d)
				return -1;
			for (size_t i = 0; i < len; i++)
				json_kind(items[i], &d[i]);
			*out = bsim_mat_matrix(name, d, len ? 1 : 0, len);
			return 0;
		}
		return json_column(a, items, len, name, out);
	}
	default: {
		const char **s = arena_alloc(a, sizeof *s);
		if (!s || !(s[0] = json_text(a, n)))
			return -1;
		*out = bsim_mat_string(name, s);
		return 0;
	}
	}
}

int bsim_matlab_from_json(const char *json_path, const char *mat_path, const char *var,
                          bsim_error *err)
{
	ydoc d;
	int rc = ydoc_load_own(&d, json_path, err);
	if (rc)
		return rc;
	arena a = {0};
	bsim_mat_field f;
	if (json_value(&a, fy_document_root(d.fyd), var, &f) != 0)
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory for %s", mat_path);
	else
		rc = bsim_mat_write(mat_path, &f, 1, err);
	arena_free(&a);
	ydoc_free(&d);
	return rc;
}

/* ---- a sweep's directory ------------------------------------------------ */

/* The grid values of each row's group, as columns named by their keys,
 * for the axes the table does not already hold (trials.csv names them
 * itself): numbers where every value of the axis is one. *added gets how
 * many fields went to out. */
static int group_params(twin_table *t, int gc, const char *path, const bsim_experiment *e,
                        bsim_mat_field *out, int *added, bsim_error *err)
{
	arena *a = &t->a;
	const double *g = t->cols[gc].v;
	int *idx = arena_alloc(a, (size_t)(e->n_axes ? e->n_axes : 1) * sizeof *idx);
	*added = 0;
	if (!idx)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory for %s", path);
	for (int ax = 0; ax < e->n_axes; ax++) {
		const bsim_grid_axis *axis = &e->axes[ax];
		int held = 0;
		for (int c = 0; c < t->n_cols && !held; c++)
			held = strcmp(t->names[c], axis->key) == 0;
		if (held)
			continue;
		int numeric = 1;
		for (int i = 0; i < axis->n_values && numeric; i++) {
			char *end;
			strtod(axis->values[i], &end);
			numeric = end != axis->values[i] && *end == '\0';
		}
		const char *name = mat_ident(a, axis->key);
		double *v = numeric ? arena_alloc(a, (size_t)t->n_rows * sizeof *v) : NULL;
		const char **s = numeric ? NULL : arena_alloc(a, (size_t)t->n_rows * sizeof *s);
		if (!name || (!v && !s))
			return bsim_error_set(err, BSIM_EFAIL, "out of memory for %s", path);
		for (long r = 0; r < t->n_rows; r++) {
			bsim_experiment_group_index(e, (int)g[r], idx);
			const char *text = axis->values[idx[ax]];
			if (numeric)
				v[r] = strtod(text, NULL);
			else
				s[r] = text;
		}
		out[(*added)++] = numeric ? bsim_mat_column(name, v, (size_t)t->n_rows)
		                          : bsim_mat_strings(name, s, (size_t)t->n_rows);
	}
	return BSIM_OK;
}

/* DIR/NAME.csv as DIR/NAME.mat, variable NAME, with the grid values by
 * name if it has a group column. */
static int sweep_table(const char *dir, const char *name, const bsim_experiment *e, bsim_error *err)
{
	char csv[BSIM_PATH_MAX], mat[BSIM_PATH_MAX];
	snprintf(csv, sizeof csv, "%s/%s.csv", dir, name);
	snprintf(mat, sizeof mat, "%s/%s.mat", dir, name);
	twin_table t;
	group_check g;
	int rc = twin_read(csv, &t, &g, e->n_groups, err);
	if (rc == BSIM_OK && g.bad_line)
		rc = bsim_error_set(err, BSIM_EINPUT, "%s:%ld: %s: expected a number, got '%s'",
		                    csv, g.bad_line, "group", g.bad ? g.bad : "");
	else if (rc == BSIM_OK && g.range_line)
		rc = bsim_error_set(err, BSIM_EINPUT, "%s:%ld: group: expected 0 .. %d, got %s",
		                    csv, g.range_line, e->n_groups - 1, g.range ? g.range : "");
	free(g.bad);
	free(g.range);
	if (rc) {
		twin_free(&t);
		return rc;
	}
	bsim_error_clear(err);
	if (t.over) {
		rc = twin_skip(csv, mat, &t, err);
		twin_free(&t);
		return rc;
	}
	int has_group = g.col >= 0, added = 0;
	bsim_mat_field *f = twin_fields(&t, has_group ? e->n_axes : 0);
	if (!f)
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory for %s", mat);
	if (!rc && has_group)
		rc = group_params(&t, g.col, csv, e, f + t.n_cols, &added, err);
	if (!rc)
		rc = write_var(mat, name, f, t.n_cols + added, err);
	twin_free(&t);
	return rc;
}

int bsim_matlab_sweep(const char *dir, const bsim_experiment *e, bsim_error *err)
{
	char json[BSIM_PATH_MAX], mat[BSIM_PATH_MAX], traj[BSIM_PATH_MAX];
	if (strlen(dir) + sizeof "/trajectories.csv" > sizeof json)
		return bsim_error_set(err, BSIM_EFAIL, "%s: path too long", dir);
	snprintf(json, sizeof json, "%s/summary.json", dir);
	snprintf(mat, sizeof mat, "%s/summary.mat", dir);
	int rc = bsim_matlab_from_json(json, mat, "summary", err);
	if (!rc)
		rc = sweep_table(dir, "trials", e, err);
	snprintf(traj, sizeof traj, "%s/trajectories.csv", dir);
	FILE *f = rc ? NULL : fopen(traj, "r");
	if (f) {
		fclose(f);
		rc = sweep_table(dir, "trajectories", e, err);
	}
	/* the time to leave the gate (store/survival_files.h), when written */
	const char *more[] = {"survival", "horizon"};
	for (int k = 0; k < 2 && !rc; k++) {
		snprintf(traj, sizeof traj, "%s/%s.csv", dir, more[k]);
		if ((f = fopen(traj, "r")) != NULL) {
			fclose(f);
			rc = sweep_table(dir, more[k], e, err);
		}
	}
	return rc;
}
