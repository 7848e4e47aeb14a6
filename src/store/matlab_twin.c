/* MATLAB twins of CSV and JSON files (store/matlab.h).
 *
 * Both converters build a tree of bsim_mat_field (mat.h) whose arrays live
 * in an arena or the table's columns, freed after the write. A CSV table
 * is read as a stream into the arrays written (a twin may be of a million
 * rows); JSON is read with libfyaml (JSON is YAML), the reader of every
 * other beamsim input, as events into a compact tree of its own; a number
 * is a plain scalar that reads as one, so a quoted "7" stays text. */
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
#include "beamsim/trial_fields.h"

/* ---- an arena of allocations freed together -------------------------- */

/* Small allocations are cut from blocks of ARENA_BLOCK bytes (a JSON
 * file's tree is millions of them), larger ones are their own. */
#define ARENA_BLOCK 65536

typedef struct arena {
	void **p;
	int n, cap;
	int oom;
	char *block; /* the block being cut */
	size_t used;
} arena;

/* m kept, to be freed with the arena; m or NULL. */
static void *arena_keep(arena *a, void *m)
{
	if (!m || a->oom) {
		free(m);
		a->oom = 1;
		return NULL;
	}
	if (a->n == a->cap) {
		int cap = a->cap ? 2 * a->cap : 64;
		void **p = realloc(a->p, (size_t)cap * sizeof *p);
		if (!p) {
			free(m);
			a->oom = 1;
			return NULL;
		}
		a->p = p;
		a->cap = cap;
	}
	a->p[a->n++] = m;
	return m;
}

/* size zeroed bytes, aligned for any type. */
static void *arena_alloc(arena *a, size_t size)
{
	if (a->oom)
		return NULL;
	size = (size + 15) & ~(size_t)15;
	if (size == 0 || size > ARENA_BLOCK / 8)
		return arena_keep(a, calloc(1, size ? size : 1));
	if (!a->block || a->used + size > ARENA_BLOCK) {
		if (!(a->block = arena_keep(a, calloc(1, ARENA_BLOCK))))
			return NULL;
		a->used = 0;
	}
	void *m = a->block + a->used;
	a->used += size;
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

/* The group column of a sweep's table, checked as bsim_csv_table_numbers and
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
	if (bsim_csv_number(cell, &v) != 0) {
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
		int num = bsim_csv_number(cell, &x) == 0;
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
	int rc = bsim_csv_stream_open(path, &s, err);
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
	t->over = bsim_csv_count_lines(path) - 1 > limit;
	while (!oom && (got = bsim_csv_stream_next(&s, err)) == 1) {
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
	bsim_csv_stream_close(&s);
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

/* ---- trials.csv's twin from the trials ---------------------------------- */

/* A column of trials.csv's twin: a field of the table, or a grid axis (a
 * CSV column, or one the CSV lacks, added as group_params adds it). */
typedef struct trials_col {
	const bsim_trial_field *field; /* NULL: an axis */
	int axis;
	int param; /* an axis the CSV lacks: numbers by strtod, as group_params */
} trials_col;

struct bsim_matlab_trials {
	twin_table t;
	trials_col *col;
	const bsim_experiment *e;
	int *idx; /* the group's axis indices */
	size_t cap;
	FILE *m; /* a text field's stream, its text in buf */
	char *buf;
	size_t size;
	int oom;
};

/* 1 if name is one of the first n names of t. */
static int has_name(const twin_table *t, int n, const char *name)
{
	for (int c = 0; c < n; c++)
		if (strcmp(t->names[c], name) == 0)
			return 1;
	return 0;
}

bsim_matlab_trials *bsim_matlab_trials_open(const bsim_experiment *e, int axes)
{
	bsim_matlab_trials *w = calloc(1, sizeof *w);
	int n_fields;
	const bsim_trial_field *f = bsim_trial_fields(&n_fields);
	int n = n_fields + e->n_axes;
	if (!w)
		return NULL;
	twin_table *t = &w->t;
	w->e = e;
	t->names = arena_alloc(&t->a, (size_t)n * sizeof *t->names);
	t->cols = calloc((size_t)n, sizeof *t->cols);
	w->col = calloc((size_t)n, sizeof *w->col);
	w->idx = calloc((size_t)(e->n_axes ? e->n_axes : 1), sizeof *w->idx);
	w->m = open_memstream(&w->buf, &w->size);
	if (!t->names || !t->cols || !w->col || !w->idx || !w->m) {
		bsim_matlab_trials_free(w);
		return NULL;
	}
	for (int c = 0; c < n_fields; c++) {
		t->names[t->n_cols] = f[c].name;
		t->cols[t->n_cols].text =
		        f[c].kind == BSIM_FIELD_WORD || f[c].kind == BSIM_FIELD_TEXT;
		w->col[t->n_cols++].field = &f[c];
	}
	/* the CSV's axes, then those it lacks and names no column for */
	for (int a = 0; a < e->n_axes; a++) {
		int param = a >= axes;
		if (param && has_name(t, n_fields + axes, e->axes[a].key))
			continue;
		t->names[t->n_cols] = e->axes[a].key;
		t->cols[t->n_cols].text = 1;
		w->col[t->n_cols++] = (trials_col){NULL, a, param};
	}
	return w;
}

/* Column c's cell of row: a number, or its text (interned or static). */
static void trials_cell(bsim_matlab_trials *w, int c, long r, const bsim_trial_row *row)
{
	twin_col *col = &w->t.cols[c];
	const trials_col *tc = &w->col[c];
	const bsim_trial_field *f = tc->field;
	if (!f) {
		col->s[r] = w->e->axes[tc->axis].values[w->idx[tc->axis]];
	} else if (!col->text) {
		col->v[r] = bsim_trial_field_number(f, row);
	} else if (f->kind == BSIM_FIELD_WORD) {
		int k = (int)f->value(row);
		col->s[r] = k >= 0 && k < f->n_words ? f->words[k] : "?";
	} else {
		rewind(w->m);
		bsim_trial_field_write(w->m, f, row);
		w->oom |= fputc('\0', w->m) == EOF || fflush(w->m) != 0;
		if (!w->oom && !(col->s[r] = intern_str(&w->t.a, &w->t.in, w->buf)))
			w->oom = 1;
	}
}

void bsim_matlab_trials_rows(bsim_matlab_trials *w, long first, long n, int trials,
                             const bsim_trial_result *results, const bsim_trial_log *logs)
{
	twin_table *t = &w->t;
	const double limit = bsim_limits_get()->mat_rows;
	for (long k = 0; k < n && !w->oom; k++) {
		long r = t->n_rows++;
		/* A table over the limit keeps nothing: its rows are only counted. */
		if (!t->over && (double)t->n_rows > limit) {
			t->over = 1;
			twin_drop(t);
		}
		if (t->over)
			continue;
		if ((size_t)r == w->cap) {
			w->cap = w->cap ? 2 * w->cap : 16;
			if (twin_grow(t, w->cap) != 0) {
				w->oom = 1;
				break;
			}
		}
		int g = (int)((first + k) / trials);
		const bsim_trial_row row = {g,           (int)((first + k) % trials),
		                            &results[k], logs ? &logs[k] : NULL,
		                            0,           NULL};
		if (w->e->n_axes)
			bsim_experiment_group_index(w->e, g, w->idx);
		for (int c = 0; c < t->n_cols && !w->oom; c++)
			trials_cell(w, c, r, &row);
	}
}

/* A text column as a reading of the CSV gives it: numbers if every cell
 * is one or empty (NaN), as twin_cell decides; an axis the CSV lacks:
 * numbers if every value of the axis is one, as group_params decides. */
static int trials_numbers(bsim_matlab_trials *w, int c)
{
	twin_col *col = &w->t.cols[c];
	const trials_col *tc = &w->col[c];
	long n = w->t.n_rows;
	double x;
	int numeric = 1;
	if (tc->param) {
		const bsim_grid_axis *ax = &w->e->axes[tc->axis];
		for (int i = 0; i < ax->n_values && numeric; i++) {
			char *end;
			strtod(ax->values[i], &end);
			numeric = end != ax->values[i] && *end == '\0';
		}
	}
	for (long r = 0; r < n && numeric && !tc->param; r++)
		numeric = !*col->s[r] || bsim_csv_number(col->s[r], &x) == 0;
	if (!numeric)
		return 0;
	double *v = malloc((size_t)(n ? n : 1) * sizeof *v);
	if (!v)
		return -1;
	for (long r = 0; r < n; r++)
		v[r] = tc->param                             ? strtod(col->s[r], NULL)
		       : bsim_csv_number(col->s[r], &x) == 0 ? x
		                                             : NAN;
	free(col->s);
	col->s = NULL;
	col->v = v;
	col->text = 0;
	return 0;
}

int bsim_matlab_trials_write(bsim_matlab_trials *w, const char *csv_path, bsim_error *err)
{
	char mat[BSIM_PATH_MAX];
	twin_table *t = &w->t;
	if (bsim_matlab_path(csv_path, mat, sizeof mat, err) != BSIM_OK)
		return BSIM_EFAIL;
	bsim_error_clear(err);
	if (!w->oom && t->over)
		return twin_skip(csv_path, mat, t, err);
	for (int c = 0; c < t->n_cols && !w->oom; c++)
		if (t->cols[c].text && trials_numbers(w, c) != 0)
			w->oom = 1;
	bsim_mat_field *f = w->oom ? NULL : twin_fields(t, 0);
	if (!f)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory for %s", mat);
	return write_var(mat, "trials", f, t->n_cols, err);
}

void bsim_matlab_trials_free(bsim_matlab_trials *w)
{
	if (!w)
		return;
	if (w->m)
		fclose(w->m);
	free(w->buf);
	free(w->col);
	free(w->idx);
	twin_free(&w->t);
	free(w);
}

/* ---- JSON -------------------------------------------------------------- */

/* A JSON file is read as libfyaml's events (bsim_ydoc_events_own) into a tree
 * of its own, 40 bytes a value, with each distinct string (key or value)
 * kept once: libfyaml's document of the same file costs about 44 bytes a
 * byte of JSON (summary.json of a 20,000-group sweep, 8 MB, would take
 * 360 MB), the tree about 4. The file's text is kept beside it, to give
 * a list or object that lands in a text column its flow text. */

enum { J_NUMBER, J_STRING, J_MAP, J_SEQ, J_ABSENT };

typedef struct jnode {
	int kind; /* J_NUMBER, J_STRING, J_MAP or J_SEQ */
	int n;    /* a list's items, an object's pairs */
	union {
		double v;     /* a number's value (true 1, false 0, null NaN) */
		size_t start; /* a collection's offset in the file's text */
	} u;
	union {
		const char *text; /* a scalar's text (interned) */
		size_t end;       /* a collection's end offset in the text */
	} w;
	struct jnode **kids; /* a list's items, an object's values */
	const char **keys;   /* an object's keys (interned) */
} jnode;

/* An open list or object while the events come: its node and its
 * children so far. */
typedef struct jopen {
	jnode *node;
	jnode **kids;
	const char **keys;
	int n, cap;
	const char *key; /* an object's key awaiting its value */
} jopen;

typedef struct jtree {
	arena a;
	intern in;
	const char *text; /* the file's text, for the flow text of collections */
	jnode *root;
	jopen *open;
	int depth, cap;
} jtree;

/* What a scalar is, as YAML reads JSON: a plain number, true, false and
 * null are numbers; anything else (a quoted "7" too) is text. */
static int scalar_kind(const char *t, int plain, double *v)
{
	if (!plain)
		return J_STRING;
	if (bsim_ydoc_number_text(t, v) == YDOC_NUM_OK)
		return J_NUMBER;
	if (strcmp(t, "true") == 0 || strcmp(t, "false") == 0) {
		*v = t[0] == 't';
		return J_NUMBER;
	}
	if (strcmp(t, "null") == 0) {
		*v = NAN;
		return J_NUMBER;
	}
	return J_STRING;
}

static int jopen_add(jopen *o, jnode *kid, const char *key)
{
	if (o->n == o->cap) {
		int cap = o->cap ? 2 * o->cap : 8;
		jnode **k = realloc(o->kids, (size_t)cap * sizeof *k);
		if (k)
			o->kids = k;
		const char **ks = k && o->node->kind == J_MAP
		                          ? realloc(o->keys, (size_t)cap * sizeof *ks)
		                          : o->keys;
		if (!k || (o->node->kind == J_MAP && !ks))
			return -1;
		o->keys = ks;
		o->cap = cap;
	}
	o->kids[o->n] = kid;
	if (o->node->kind == J_MAP)
		o->keys[o->n] = key;
	o->n++;
	return 0;
}

static const char *json_text(jtree *t, const jnode *n);

/* A finished value into its list or object (or the root). In an object
 * awaiting a key it is the key: its text, kept once (a list or object as
 * a key, which beamsim never writes, by its flow text). */
static int jtree_place(jtree *t, jnode *node)
{
	if (t->depth == 0) {
		t->root = node;
		return 0;
	}
	jopen *o = &t->open[t->depth - 1];
	if (o->node->kind == J_SEQ)
		return jopen_add(o, node, NULL);
	if (!o->key) {
		const char *text = json_text(t, node);
		o->key = text ? intern_str(&t->a, &t->in, text) : NULL;
		return o->key ? 0 : -1;
	}
	const char *key = o->key;
	o->key = NULL;
	return jopen_add(o, node, key);
}

/* One event into the tree; -1 if out of memory. */
static int jtree_add(jtree *t, struct fy_event *ev)
{
	if (ev->type == FYET_SCALAR) {
		size_t len = 0;
		const char *s = fy_token_get_text(ev->scalar.value, &len);
		char *z = malloc(len + 1);
		if (!z)
			return -1;
		memcpy(z, s ? s : "", len);
		z[len] = '\0';
		const char *kept = intern_str(&t->a, &t->in, z);
		int plain = fy_token_scalar_style(ev->scalar.value) == FYSS_PLAIN;
		free(z);
		if (!kept)
			return -1;
		jnode *n = arena_alloc(&t->a, sizeof *n);
		if (!n)
			return -1;
		n->kind = scalar_kind(kept, plain, &n->u.v);
		n->w.text = kept;
		return jtree_place(t, n);
	}
	if (ev->type == FYET_SEQUENCE_START || ev->type == FYET_MAPPING_START) {
		if (t->depth == t->cap) {
			int cap = t->cap ? 2 * t->cap : 16;
			jopen *o = realloc(t->open, (size_t)cap * sizeof *o);
			if (!o)
				return -1;
			t->open = o;
			t->cap = cap;
		}
		jnode *n = arena_alloc(&t->a, sizeof *n);
		if (!n)
			return -1;
		int seq = ev->type == FYET_SEQUENCE_START;
		struct fy_token *tok =
		        seq ? ev->sequence_start.sequence_start : ev->mapping_start.mapping_start;
		const struct fy_mark *m = tok ? fy_token_start_mark(tok) : NULL;
		n->kind = seq ? J_SEQ : J_MAP;
		n->u.start = m ? m->input_pos : 0;
		t->open[t->depth++] = (jopen){.node = n};
		return 0;
	}
	if (ev->type == FYET_SEQUENCE_END || ev->type == FYET_MAPPING_END) {
		jopen *o = &t->open[--t->depth];
		jnode *n = o->node;
		struct fy_token *tok = ev->type == FYET_SEQUENCE_END ? ev->sequence_end.sequence_end
		                                                     : ev->mapping_end.mapping_end;
		const struct fy_mark *m = tok ? fy_token_end_mark(tok) : NULL;
		n->w.end = m ? m->input_pos : n->u.start;
		n->n = o->n;
		size_t bytes = (size_t)(o->n ? o->n : 1) * sizeof(void *);
		n->kids = arena_alloc(&t->a, bytes);
		n->keys = n->kind == J_MAP ? arena_alloc(&t->a, bytes) : NULL;
		int rc = !n->kids || (n->kind == J_MAP && !n->keys) ? -1 : 0;
		if (!rc && o->n) {
			memcpy(n->kids, o->kids, (size_t)o->n * sizeof *n->kids);
			if (n->keys)
				memcpy(n->keys, o->keys, (size_t)o->n * sizeof *n->keys);
		}
		free(o->kids);
		free(o->keys);
		return rc ? rc : jtree_place(t, n);
	}
	return 0;
}

static int jtree_event(void *user, struct fy_event *ev, const char *text, bsim_error *err)
{
	jtree *t = user;
	t->text = text;
	if (jtree_add(t, ev) != 0)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	return BSIM_OK;
}

static void jtree_free(jtree *t)
{
	for (int i = 0; i < t->depth; i++) {
		free(t->open[i].kids);
		free(t->open[i].keys);
	}
	free(t->open);
	free(t->in.slot);
	arena_free(&t->a);
	memset(t, 0, sizeof *t);
}

static int json_kind(const jnode *n, double *v)
{
	if (!n)
		return J_ABSENT;
	if (n->kind == J_NUMBER)
		*v = n->u.v;
	return n->kind;
}

/* A node's text: a scalar's own; a list's or object's flow text on one
 * line, as libfyaml writes the node read from the file's text. */
static const char *json_text(jtree *t, const jnode *n)
{
	if (!n)
		return "";
	if (n->kind == J_NUMBER || n->kind == J_STRING)
		return n->w.text;
	struct fy_document *d =
	        fy_document_build_from_string(NULL, t->text + n->u.start, n->w.end - n->u.start);
	char *flow = d ? bsim_ydoc_flow_text(fy_document_root(d)) : NULL;
	const char *s = flow ? arena_strdup(&t->a, flow, strlen(flow)) : NULL;
	free(flow);
	if (d)
		fy_document_destroy(d);
	return s;
}

/* The value of key in object n (keys are interned: one pointer each), NULL
 * if n is no object or has none. */
static const jnode *json_lookup(const jnode *n, const char *key)
{
	for (int i = 0; n && n->kind == J_MAP && i < n->n; i++)
		if (n->keys[i] == key)
			return n->kids[i];
	return NULL;
}

static int json_value(jtree *t, const jnode *n, const char *name, bsim_mat_field *out);
static int json_column(jtree *t, const jnode **nodes, size_t n, const char *name,
                       bsim_mat_field *out);

/* Keys of the objects among nodes, in order of first appearance. */
static int map_keys(jtree *t, const jnode **nodes, size_t n, const char ***keys)
{
	int cap = 8, k = 0;
	const char **out = arena_alloc(&t->a, (size_t)cap * sizeof *out);
	for (size_t i = 0; out && i < n; i++) {
		if (!nodes[i] || nodes[i]->kind != J_MAP)
			continue;
		for (int p = 0; p < nodes[i]->n; p++) {
			const char *key = nodes[i]->keys[p];
			int seen = 0;
			for (int j = 0; j < k && !seen; j++)
				seen = out[j] == key;
			if (seen)
				continue;
			if (k == cap) {
				const char **o = arena_alloc(&t->a, (size_t)cap * 2 * sizeof *o);
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

/* nodes[i] (objects or absent) as a struct of n-row columns. */
static int json_table(jtree *t, const jnode **nodes, size_t n, const char *name,
                      bsim_mat_field *out)
{
	const char **keys;
	int k = map_keys(t, nodes, n, &keys);
	if (k < 0)
		return -1;
	bsim_mat_field *f = arena_alloc(&t->a, (size_t)k * sizeof *f);
	const jnode **col = arena_alloc(&t->a, n * sizeof *col);
	if (!f || !col)
		return -1;
	for (int j = 0; j < k; j++) {
		for (size_t i = 0; i < n; i++)
			col[i] = json_lookup(nodes[i], keys[j]);
		if (json_column(t, col, n, mat_ident(&t->a, keys[j]), &f[j]) != 0)
			return -1;
	}
	*out = bsim_mat_struct(name, f, k);
	return 0;
}

/* Length of a list of numbers, -1 if n is anything else. */
static int number_list(const jnode *n)
{
	if (!n || n->kind != J_SEQ)
		return -1;
	for (int i = 0; i < n->n; i++)
		if (n->kids[i]->kind != J_NUMBER)
			return -1;
	return n->n;
}

/* One value per row: numbers, text, nested tables or rows of a matrix. */
static int json_column(jtree *t, const jnode **nodes, size_t n, const char *name,
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
		double *v = arena_alloc(&t->a, n * sizeof *v);
		if (!v)
			return -1;
		for (size_t i = 0; i < n; i++)
			if (json_kind(nodes[i], &v[i]) != J_NUMBER)
				v[i] = NAN;
		*out = bsim_mat_column(name, v, n);
		return 0;
	}
	if (maps)
		return json_table(t, nodes, n, name, out);
	if (width > 0) {
		double *m = arena_alloc(&t->a, n * (size_t)width * sizeof *m);
		if (!m)
			return -1;
		for (size_t i = 0; i < n; i++)
			for (int j = 0; j < width; j++)
				m[(size_t)j * n + i] =
				        nodes[i] ? nodes[i]->kids[j]->u.v : NAN; /* column-major */
		*out = bsim_mat_matrix(name, m, n, (size_t)width);
		return 0;
	}
	const char **s = arena_alloc(&t->a, n * sizeof *s);
	if (!s)
		return -1;
	for (size_t i = 0; i < n; i++)
		if (!(s[i] = json_text(t, nodes[i])))
			return -1;
	*out = bsim_mat_strings(name, s, n);
	return 0;
}

static int json_value(jtree *t, const jnode *n, const char *name, bsim_mat_field *out)
{
	double v;
	if (!name)
		return -1;
	switch (json_kind(n, &v)) {
	case J_NUMBER: {
		double *d = arena_alloc(&t->a, sizeof *d);
		if (!d)
			return -1;
		*d = v;
		*out = bsim_mat_column(name, d, 1);
		return 0;
	}
	case J_MAP: {
		bsim_mat_field *f = arena_alloc(&t->a, (size_t)n->n * sizeof *f);
		if (!f)
			return -1;
		for (int j = 0; j < n->n; j++)
			if (json_value(t, n->kids[j], mat_ident(&t->a, n->keys[j]), &f[j]))
				return -1;
		*out = bsim_mat_struct(name, f, n->n);
		return 0;
	}
	case J_SEQ: {
		size_t len = (size_t)n->n;
		if (number_list(n) >= 0) { /* a row, as MATLAB writes [1 2 3] */
			double *d = arena_alloc(&t->a, (len ? len : 1) * sizeof *d);
			if (!d)
				return -1;
			for (size_t i = 0; i < len; i++)
				d[i] = n->kids[i]->u.v;
			*out = bsim_mat_matrix(name, d, len ? 1 : 0, len);
			return 0;
		}
		return json_column(t, (const jnode **)n->kids, len, name, out);
	}
	default: {
		const char **s = arena_alloc(&t->a, sizeof *s);
		if (!s || !(s[0] = json_text(t, n)))
			return -1;
		*out = bsim_mat_string(name, s);
		return 0;
	}
	}
}

int bsim_matlab_from_json(const char *json_path, const char *mat_path, const char *var,
                          bsim_error *err)
{
	jtree t;
	memset(&t, 0, sizeof t);
	char *text = NULL;
	int rc = bsim_ydoc_events_own(json_path, jtree_event, &t, &text, err);
	t.text = text;
	bsim_mat_field f;
	/* An empty file has no value: its twin holds an empty string. */
	if (rc == BSIM_OK)
		rc = json_value(&t, t.root, var, &f) != 0
		             ? bsim_error_set(err, BSIM_EFAIL, "out of memory for %s", mat_path)
		             : bsim_mat_write(mat_path, &f, 1, err);
	jtree_free(&t);
	free(text);
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

int bsim_matlab_sweep(const char *dir, const bsim_experiment *e, int with_trials, bsim_error *err)
{
	char json[BSIM_PATH_MAX], mat[BSIM_PATH_MAX], traj[BSIM_PATH_MAX];
	if (strlen(dir) + sizeof "/trajectories.csv" > sizeof json)
		return bsim_error_set(err, BSIM_EFAIL, "%s: path too long", dir);
	snprintf(json, sizeof json, "%s/summary.json", dir);
	snprintf(mat, sizeof mat, "%s/summary.mat", dir);
	int rc = bsim_matlab_from_json(json, mat, "summary", err);
	if (!rc && with_trials)
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
