/* A sweep's summary.json read for its figures (figures_summary.h): the
 * groups' counts, p_traverse and interval, and the grid axes rebuilt from
 * the groups' params, the first axis varying slowest, the values in the
 * order they first appear. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "figures/figures_summary.h"
#include "beamsim/limits.h"
#include "util/yaml_doc.h"

static int text_number(const char *s, double *x)
{
	char *end;
	if (!s || !*s)
		return 0;
	*x = strtod(s, &end);
	return *end == '\0' && isfinite(*x);
}

int bsim_fsum_same_value(const char *a, const char *b)
{
	double x, y;
	if (text_number(a, &x) && text_number(b, &y))
		return x == y;
	return strcmp(a, b) == 0;
}

void bsim_fsum_free(fsum *s)
{
	for (int a = 0; a < s->n_axes; a++) {
		free(s->axes[a].key);
		for (int i = 0; i < s->axes[a].n_values; i++)
			free(s->axes[a].values[i]);
		free(s->axes[a].values);
		free(s->axes[a].x);
	}
	for (int g = 0; g < s->n_groups; g++)
		free(s->g[g].idx);
	free(s->axes);
	free(s->g);
	memset(s, 0, sizeof *s);
}

static char *scalar_dup(struct fy_node *n)
{
	size_t len;
	const char *t = n && fy_node_is_scalar(n) ? fy_node_get_scalar(n, &len) : NULL;
	if (!t)
		return NULL;
	char *s = malloc(len + 1);
	if (s) {
		memcpy(s, t, len);
		s[len] = '\0';
	}
	return s;
}

/* The index of value v on axis a, added if new; -1 out of memory. */
static int axis_value(fsum_axis *a, const char *v)
{
	for (int i = 0; i < a->n_values; i++)
		if (strcmp(a->values[i], v) == 0)
			return i;
	char **vals = realloc(a->values, (size_t)(a->n_values + 1) * sizeof *vals);
	if (!vals)
		return -1;
	a->values = vals;
	if (!(vals[a->n_values] = strdup(v)))
		return -1;
	return a->n_values++;
}

static int group_count(const ydoc *d, struct fy_node *gn, const char *field, int g, int *out,
                       bsim_error *err)
{
	long long v;
	struct fy_node *n = bsim_ydoc_lookup(gn, field);
	char where[64];
	snprintf(where, sizeof where, "groups.%d.%s", g, field);
	if (!n || !bsim_ydoc_int64(n, &v) || v < 0 || v > 2147483647)
		return bsim_ydoc_expected(d, n, gn, where, "an integer >= 0", err);
	*out = (int)v;
	return BSIM_OK;
}

static int read_group(const ydoc *d, struct fy_node *gn, int g, fsum *s, bsim_error *err)
{
	fsum_group *G = &s->g[g];
	char where[64];
	snprintf(where, sizeof where, "groups.%d.params", g);
	struct fy_node *params = bsim_ydoc_lookup(gn, "params");
	if (!params || !fy_node_is_mapping(params) ||
	    (g > 0 && fy_node_mapping_item_count(params) != s->n_axes))
		return bsim_ydoc_expected(d, params, gn, where, "a mapping of the grid's keys",
		                          err);
	if (g == 0) {
		s->n_axes = fy_node_mapping_item_count(params);
		s->axes = calloc((size_t)(s->n_axes ? s->n_axes : 1), sizeof *s->axes);
		if (!s->axes)
			return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	G->idx = calloc((size_t)(s->n_axes ? s->n_axes : 1), sizeof *G->idx);
	if (!G->idx)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	void *it = NULL;
	struct fy_node_pair *p;
	for (int a = 0; (p = fy_node_mapping_iterate(params, &it)) != NULL; a++) {
		char *key = scalar_dup(fy_node_pair_key(p));
		char *val = scalar_dup(fy_node_pair_value(p));
		int bad = !key || !val;
		if (!bad && g == 0)
			s->axes[a].key = key, key = NULL;
		else if (!bad)
			bad = strcmp(s->axes[a].key, key) != 0;
		if (!bad)
			bad = (G->idx[a] = axis_value(&s->axes[a], val)) < 0;
		free(key);
		free(val);
		if (bad)
			return bsim_ydoc_expected(d, fy_node_pair_key(p), params, where,
			                          "the grid's keys in the order of group 0", err);
	}
	int rc = BSIM_OK;
	struct {
		const char *field;
		int *out;
	} counts[] = {
	        {"trials", &G->trials},
	        {"traversed", &G->traversed},
	        {"side_exit", &G->side_exit},
	        {"stuck", &G->stuck},
	        {"left", &G->left},
	        {"right", &G->right},
	        {"landscape_left", &G->land_left},
	        {"landscape_right", &G->land_right},
	};
	for (size_t i = 0; !rc && i < sizeof counts / sizeof counts[0]; i++)
		rc = group_count(d, gn, counts[i].field, g, counts[i].out, err);
	struct fy_node *pn = bsim_ydoc_lookup(gn, "p_traverse"),
	               *lo = bsim_ydoc_lookup(gn, "ci95.0"), *hi = bsim_ydoc_lookup(gn, "ci95.1");
	snprintf(where, sizeof where, "groups.%d.p_traverse", g);
	if (!rc && (!pn || bsim_ydoc_number(pn, &G->p)))
		rc = bsim_ydoc_expected(d, pn, gn, where, "a number", err);
	snprintf(where, sizeof where, "groups.%d.ci95", g);
	if (!rc && (!lo || !hi || bsim_ydoc_number(lo, &G->lo) || bsim_ydoc_number(hi, &G->hi)))
		rc = bsim_ydoc_expected(d, bsim_ydoc_lookup(gn, "ci95"), gn, where, "[lo, hi]",
		                        err);
	G->selected = 1;
	struct fy_node *det = bsim_ydoc_lookup(gn, "deterministic");
	const char *dt = det ? bsim_ydoc_plain(det) : NULL;
	G->deterministic = dt && strcmp(dt, "true") == 0;
	return rc;
}

int bsim_fsum_read(const char *path, fsum *s, bsim_error *err)
{
	memset(s, 0, sizeof *s);
	ydoc d;
	int rc = bsim_ydoc_load_own(&d, path, err);
	if (rc)
		return rc;
	struct fy_node *root = fy_document_root(d.fyd);
	struct fy_node *groups = bsim_ydoc_lookup(root, "groups");
	struct fy_node *b = bsim_ydoc_lookup(root, "backend");
	struct fy_node *tpg = bsim_ydoc_lookup(root, "trials_per_group");
	long long trials = 0;
	const char *bt = b ? bsim_ydoc_plain(b) : NULL;
	size_t blen = 0;
	if (b && fy_node_is_scalar(b))
		bt = fy_node_get_scalar(b, &blen);
	if (!groups || !fy_node_is_sequence(groups) || fy_node_sequence_item_count(groups) < 1)
		rc = bsim_ydoc_expected(&d, groups, root, "groups", "a list of groups", err);
	else if (!tpg || !bsim_ydoc_int64(tpg, &trials) || trials < 0)
		rc = bsim_ydoc_expected(&d, tpg, root, "trials_per_group", "an integer >= 0", err);
	if (!rc) {
		snprintf(s->backend, sizeof s->backend, "%.*s", bt ? (int)blen : 0, bt ? bt : "");
		s->trials_per_group = (int)trials;
		s->n_groups = fy_node_sequence_item_count(groups);
		s->g = calloc((size_t)s->n_groups, sizeof *s->g);
		if (!s->g)
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	for (int g = 0; !rc && g < s->n_groups; g++)
		rc = read_group(&d, fy_node_sequence_get_by_index(groups, g), g, s, err);
	for (int a = 0; !rc && a < s->n_axes; a++) {
		fsum_axis *ax = &s->axes[a];
		ax->x = calloc((size_t)ax->n_values, sizeof *ax->x);
		if (!ax->x) {
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
			break;
		}
		ax->numeric = 1;
		for (int i = 0; i < ax->n_values; i++)
			ax->numeric &= text_number(ax->values[i], &ax->x[i]);
	}
	bsim_ydoc_free(&d);
	if (rc)
		bsim_fsum_free(s);
	return rc;
}

/* Values shown of one axis in a line; more are counted, not listed. */
#define FSUM_LIST_MAX 12

/* "k1, k2, k3": every axis. */
static void list_axes(FILE *f, const fsum *s)
{
	for (int a = 0; a < s->n_axes; a++)
		fprintf(f, "%s%s", a ? ", " : "", s->axes[a].key);
	if (s->n_axes == 0)
		fputs("none", f);
}

/* "v1, v2, ...": the values of ax with mark[i] (mark NULL: all). */
static void list_values(FILE *f, const fsum_axis *ax, const int *mark)
{
	int k = 0;
	for (int i = 0; i < ax->n_values; i++) {
		if (mark && !mark[i])
			continue;
		if (k < FSUM_LIST_MAX)
			fprintf(f, "%s%s", k ? ", " : "", ax->values[i]);
		else if (k == FSUM_LIST_MAX)
			fputs(", ...", f);
		k++;
	}
}

/* The lines of bsim_figures_result.selection: every axis, the selected
 * ones with their value, the others with the values left. */
static char *selection_text(const figs *f, const fsum *s)
{
	char *text = NULL;
	size_t len = 0;
	FILE *m = open_memstream(&text, &len);
	if (!m)
		return NULL;
	int groups = 0;
	for (int g = 0; g < s->n_groups; g++)
		groups += s->g[g].selected;
	fprintf(m, "%d of %d groups selected", groups, s->n_groups);
	for (int a = 0; a < s->n_axes; a++) {
		const fsum_axis *ax = &s->axes[a];
		int *left = calloc((size_t)ax->n_values, sizeof *left), n_left = 0, named = 0;
		if (!left) {
			fclose(m);
			free(text);
			return NULL;
		}
		for (int g = 0; g < s->n_groups; g++)
			if (s->g[g].selected)
				left[s->g[g].idx[a]] = 1;
		for (int i = 0; i < ax->n_values; i++)
			n_left += left[i];
		for (int i = 0; i < f->def->n_select; i++)
			named |= strcmp(f->def->select[i].key, ax->key) == 0;
		fprintf(m, "\n%s%s", ax->key, named ? " = " : ": ");
		list_values(m, ax, left);
		if (named)
			fprintf(m, " (selected of %d value%s)", ax->n_values,
			        ax->n_values == 1 ? "" : "s");
		else if (n_left == ax->n_values)
			fprintf(m, " (all %d value%s)", ax->n_values, ax->n_values == 1 ? "" : "s");
		else
			fprintf(m, " (%d of %d values)", n_left, ax->n_values);
		free(left);
	}
	if (fclose(m) != 0) {
		free(text);
		return NULL;
	}
	return text;
}

/* Each axis's number of values among the selected groups. */
static void count_selected(fsum *s)
{
	for (int a = 0; a < s->n_axes; a++) {
		fsum_axis *ax = &s->axes[a];
		ax->n_selected = 0;
		for (int i = 0; i < ax->n_values; i++) {
			int used = 0;
			for (int g = 0; g < s->n_groups && !used; g++)
				used = s->g[g].selected && s->g[g].idx[a] == i;
			ax->n_selected += used;
		}
	}
}

int bsim_fsum_select(const figs *f, fsum *s, bsim_error *err)
{
	count_selected(s);
	for (int i = 0; i < f->def->n_select; i++) {
		const bsim_override *o = &f->def->select[i];
		int a = 0;
		while (a < s->n_axes && strcmp(s->axes[a].key, o->key) != 0)
			a++;
		char *list = NULL;
		size_t len = 0;
		FILE *m = open_memstream(&list, &len);
		if (!m)
			return bsim_error_set(err, BSIM_EFAIL, "out of memory");
		if (a == s->n_axes)
			list_axes(m, s);
		else
			list_values(m, &s->axes[a], NULL);
		if (fclose(m) != 0) {
			free(list);
			return bsim_error_set(err, BSIM_EFAIL, "out of memory");
		}
		int any = 0;
		for (int g = 0; a < s->n_axes && g < s->n_groups; g++) {
			int match =
			        bsim_fsum_same_value(s->axes[a].values[s->g[g].idx[a]], o->value);
			s->g[g].selected &= match;
			any |= match;
		}
		int rc = BSIM_OK;
		if (a == s->n_axes)
			rc = bsim_error_set(err, BSIM_EINPUT,
			                    "--select %s=%s: %s is not a grid axis of this run "
			                    "(its axes: %s)",
			                    o->key, o->value, o->key, list);
		else if (!any)
			rc = bsim_error_set(err, BSIM_EINPUT,
			                    "--select %s=%s: %s has no value %s in this run (its "
			                    "values: %s)",
			                    o->key, o->value, o->key, o->value, list);
		free(list);
		if (rc)
			return rc;
	}
	count_selected(s);
	/* once: a comparison's sides are selected the same way */
	if (f->def->n_select > 0 && !f->res->selection &&
	    !(f->res->selection = selection_text(f, s)))
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	return BSIM_OK;
}

/* Records key = value for the header; a later value of a key replaces
 * the earlier one (--set after the file's set:). */
static void fixed_add(fsum *s, const char *key, const char *value)
{
	int i = 0;
	while (i < s->n_fixed && strcmp(s->fixed_key[i], key) != 0)
		i++;
	if (i == 16)
		return;
	snprintf(s->fixed_key[i], sizeof s->fixed_key[0], "%s", key);
	snprintf(s->fixed_value[i], sizeof s->fixed_value[0], "%s", value);
	if (i == s->n_fixed)
		s->n_fixed++;
}

int bsim_fsum_fixed_number(const fsum *s, const char *key, double *x)
{
	for (int i = 0; i < s->n_fixed; i++)
		if (strcmp(s->fixed_key[i], key) == 0)
			return text_number(s->fixed_value[i], x);
	return 0;
}

void bsim_fsum_header(fsum *s, const char *inputs, const char *who)
{
	s->n_fixed = 0;
	char path[BSIM_PATH_MAX];
	snprintf(path, sizeof path, "%s/experiment.yaml", inputs ? inputs : "");
	ydoc d;
	bsim_error ignore;
	if (inputs && bsim_ydoc_load_own(&d, path, &ignore) == BSIM_OK) {
		struct fy_node *set = bsim_ydoc_lookup(fy_document_root(d.fyd), "set");
		void *it = NULL;
		struct fy_node_pair *p;
		while (set && fy_node_is_mapping(set) &&
		       (p = fy_node_mapping_iterate(set, &it)) != NULL) {
			char *key = scalar_dup(fy_node_pair_key(p));
			char *val = bsim_ydoc_flow_text(fy_node_pair_value(p));
			if (key && val)
				fixed_add(s, key, val);
			free(key);
			free(val);
		}
		bsim_ydoc_free(&d);
	}
	for (int a = 0; a < s->n_axes; a++) {
		if (s->axes[a].n_selected != 1)
			continue;
		for (int g = 0; g < s->n_groups; g++)
			if (s->g[g].selected) {
				fixed_add(s, s->axes[a].key, s->axes[a].values[s->g[g].idx[a]]);
				break;
			}
	}
	int n = snprintf(s->header, sizeof s->header, "%s", who);
	size_t k = n > 0 ? (size_t)n : 0;
	for (int i = 0; i < s->n_fixed && k < sizeof s->header; i++) {
		char kv[200];
		bsim_figs_key_value(s->fixed_key[i], s->fixed_value[i], kv, sizeof kv);
		n = snprintf(s->header + k, sizeof s->header - k, "%s%s", i ? ", " : "; ", kv);
		k += n > 0 ? (size_t)n : 0;
	}
}

void bsim_fsum_label(const fsum *s, int g, char *buf, size_t size)
{
	size_t k = 0;
	int shown = 0;
	buf[0] = '\0';
	for (int a = 0; a < s->n_axes && k < size; a++) {
		if (s->axes[a].n_selected == 1)
			continue;
		char kv[200];
		bsim_figs_key_value(s->axes[a].key, s->axes[a].values[s->g[g].idx[a]], kv,
		                    sizeof kv);
		/* a line of its own from the third on, to fit a figure's width */
		int n = snprintf(buf + k, size - k, "%s%s",
		                 shown == 0  ? ""
		                 : shown % 2 ? ", "
		                             : "\n",
		                 kv);
		if (n < 0)
			break;
		k += (size_t)n;
		shown++;
	}
}
