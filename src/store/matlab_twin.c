/* MATLAB twins of CSV and JSON files (store/matlab.h).
 *
 * Both converters build a tree of bsim_mat_field (mat.h) whose arrays live
 * in an arena freed after the write. JSON is read with libfyaml (JSON is
 * YAML), the reader of every other beamsim input; a number is a plain
 * scalar that reads as one, so a quoted "7" stays text. */
#define _POSIX_C_SOURCE 200809L
#include "store/matlab.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

/* Column c of t as a field: doubles if every non-empty cell is a number
 * (empty ones NaN), else text. */
static int csv_column(arena *a, const csv_table *t, int c, bsim_mat_field *out)
{
	const char *name = mat_ident(a, t->names[c]);
	int numeric = 1;
	for (long r = 0; r < t->n_rows && numeric; r++) {
		double v;
		numeric = !*csv_table_cell(t, r, c) || csv_table_number(t, r, c, &v) == 0;
	}
	if (numeric) {
		double *v = arena_alloc(a, (size_t)t->n_rows * sizeof *v);
		if (!v || !name)
			return -1;
		for (long r = 0; r < t->n_rows; r++)
			if (csv_table_number(t, r, c, &v[r]) != 0)
				v[r] = NAN;
		*out = bsim_mat_column(name, v, (size_t)t->n_rows);
		return 0;
	}
	const char **s = arena_alloc(a, (size_t)t->n_rows * sizeof *s);
	if (!s || !name)
		return -1;
	for (long r = 0; r < t->n_rows; r++)
		s[r] = csv_table_cell(t, r, c);
	*out = bsim_mat_strings(name, s, (size_t)t->n_rows);
	return 0;
}

/* The fields of every column, plus room for n_extra more at the end. */
static bsim_mat_field *csv_fields(arena *a, const csv_table *t, int n_extra)
{
	bsim_mat_field *f = arena_alloc(a, (size_t)(t->n_cols + n_extra) * sizeof *f);
	for (int c = 0; f && c < t->n_cols; c++)
		if (csv_column(a, t, c, &f[c]) != 0)
			return NULL;
	return f;
}

static int write_var(const char *mat_path, const char *var, bsim_mat_field *fields, int n,
                     bsim_error *err)
{
	bsim_mat_field v = bsim_mat_struct(var, fields, n);
	return bsim_mat_write(mat_path, &v, 1, err);
}

int bsim_matlab_from_csv(const char *csv_path, const char *mat_path, const char *var,
                         bsim_error *err)
{
	csv_table t;
	int rc = csv_table_read(csv_path, &t, err);
	if (rc)
		return rc;
	arena a = {0};
	bsim_mat_field *f = csv_fields(&a, &t, 0);
	rc = f ? write_var(mat_path, var, f, t.n_cols, err)
	       : bsim_error_set(err, BSIM_EFAIL, "out of memory for %s", mat_path);
	arena_free(&a);
	csv_table_free(&t);
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
static int group_params(arena *a, const csv_table *t, const char *path, const bsim_experiment *e,
                        bsim_mat_field *out, int *added, bsim_error *err)
{
	int gc = csv_table_col(t, "group");
	double *g = arena_alloc(a, (size_t)t->n_rows * sizeof *g);
	int *idx = arena_alloc(a, (size_t)(e->n_axes ? e->n_axes : 1) * sizeof *idx);
	*added = 0;
	if (!g || !idx)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory for %s", path);
	int rc = csv_table_numbers(t, path, gc, 0, 0.0, g, err);
	if (rc)
		return rc;
	for (long r = 0; r < t->n_rows; r++)
		if (g[r] != floor(g[r]) || g[r] < 0 || g[r] >= e->n_groups)
			return bsim_error_set(err, BSIM_EINPUT,
			                      "%s:%ld: group: expected 0 .. %d, got %s", path,
			                      r + 2, e->n_groups - 1, csv_table_cell(t, r, gc));
	for (int ax = 0; ax < e->n_axes; ax++) {
		const bsim_grid_axis *axis = &e->axes[ax];
		if (csv_table_col(t, axis->key) >= 0)
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
	csv_table t;
	int rc = csv_table_read(csv, &t, err);
	if (rc)
		return rc;
	arena a = {0};
	int has_group = csv_table_col(&t, "group") >= 0, added = 0;
	bsim_mat_field *f = csv_fields(&a, &t, has_group ? e->n_axes : 0);
	if (!f)
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory for %s", mat);
	if (!rc && has_group)
		rc = group_params(&a, &t, csv, e, f + t.n_cols, &added, err);
	if (!rc)
		rc = write_var(mat, name, f, t.n_cols + added, err);
	arena_free(&a);
	csv_table_free(&t);
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
	return rc;
}
