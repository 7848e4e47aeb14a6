/* Experiment files (docs/files.md "Experiment file (YAML)"): a scene, fixed
 * overrides, a grid whose cartesian product is the groups (first axis
 * slowest), trials per group and a seed. Every group's scene is built and
 * validated at load, so a bad grid value fails before any trial runs; each
 * value is tried first in one group of its own, so a bad one is named before
 * the product is counted or expanded. */
#include "beamsim/experiment.h"

#include <errno.h>
#include <libfyaml.h>
#include <pthread.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/limits.h"
#include "model/scene_internal.h"
#include "util/file_read.h"

static const char experiment_keys[] = "name, scene, trials, seed, set, grid";

static char *dup_text(const char *t)
{
	char *s = t ? malloc(strlen(t) + 1) : NULL;
	if (s)
		strcpy(s, t);
	return s;
}

/* "EXPFILE:LINE" of a value: the origin its override carries. */
static char *value_origin(const ydoc *d, struct fy_node *n, struct fy_node *key)
{
	char buf[BSIM_PATH_MAX];
	snprintf(buf, sizeof buf, "%s:%d", d->path, bsim_ydoc_line(n, key));
	return dup_text(buf);
}

static const char *key_text(struct fy_node *k)
{
	const char *t = k && fy_node_is_scalar(k) ? fy_node_get_scalar0(k) : NULL;
	return t && *t ? t : NULL;
}

/* The scene path is relative to the experiment file's directory. */
static int walk_scene_path(const ydoc *d, struct fy_node *n, struct fy_node *key,
                           bsim_experiment *e, bsim_error *err)
{
	const char *t =
	        bsim_ydoc_is_null(n) || !fy_node_is_scalar(n) ? NULL : fy_node_get_scalar0(n);
	if (!t)
		return bsim_ydoc_expected(d, n, key, "scene", "a scene file name", err);
	const char *slash = strrchr(d->path, '/');
	int dir = t[0] == '/' || !slash ? 0 : (int)(slash - d->path + 1);
	int len = snprintf(e->scene_path, sizeof e->scene_path, "%.*s%s", dir, d->path, t);
	if (len < 0 || (size_t)len >= sizeof e->scene_path)
		return bsim_ydoc_expected(d, n, key, "scene", "a shorter path", err);
	/* Read here, once: every group's scene is made from this text
	 * (bsim_experiment.scene_text). */
	file_text f;
	bsim_error fe;
	int rc = bsim_file_read(e->scene_path, "a YAML file", bsim_limits_get()->input_bytes,
	                        "input_bytes", &f, &fe);
	if (rc == BSIM_EFAIL) {
		*err = fe;
		return rc;
	}
	if (rc != BSIM_OK) {
		char what[BSIM_PATH_MAX];
		snprintf(what, sizeof what, "a readable scene file (%s)", fe.msg);
		return bsim_ydoc_expected(d, n, key, "scene", what, err);
	}
	free(e->scene_text);
	e->scene_text = f.text;
	e->scene_len = f.len;
	return BSIM_OK;
}

static int walk_set(const ydoc *d, struct fy_node *n, struct fy_node *key, bsim_experiment *e,
                    bsim_error *err)
{
	if (bsim_ydoc_is_null(n))
		return BSIM_OK;
	if (!fy_node_is_mapping(n))
		return bsim_ydoc_expected(d, n, key, "set", "a mapping of dotted keys to values",
		                          err);
	int count = fy_node_mapping_item_count(n);
	e->set = calloc((size_t)count, sizeof *e->set);
	if (!e->set)
		return bsim_error_set(err, BSIM_EFAIL, "%s: out of memory", d->path);
	for (int i = 0; i < count; i++) {
		struct fy_node_pair *p = fy_node_mapping_get_by_index(n, i);
		struct fy_node *k = fy_node_pair_key(p), *v = fy_node_pair_value(p);
		const char *name = key_text(k);
		char field[512];
		bsim_ydoc_join(field, sizeof field, "set.", name ? name : "?");
		if (!name)
			return bsim_ydoc_expected(d, k, n, "set", "a dotted scene key", err);
		if (bsim_ydoc_is_null(v))
			return bsim_ydoc_expected(d, v, k, field, "a value", err);
		bsim_override *o = &e->set[e->n_set++];
		o->key = dup_text(name);
		o->value = bsim_ydoc_flow_text(v);
		o->origin = value_origin(d, v, k);
		if (!o->key || !o->value || !o->origin)
			return bsim_error_set(err, BSIM_EFAIL, "%s: out of memory", d->path);
	}
	return BSIM_OK;
}

static int walk_axis(const ydoc *d, struct fy_node *k, struct fy_node *v, bsim_grid_axis *a,
                     bsim_error *err)
{
	const char *name = key_text(k);
	char field[512];
	bsim_ydoc_join(field, sizeof field, "grid.", name ? name : "?");
	if (!name)
		return bsim_ydoc_expected(d, k, NULL, "grid", "a dotted scene key", err);
	int count = v && fy_node_is_sequence(v) ? fy_node_sequence_item_count(v) : 0;
	if (count == 0)
		return bsim_ydoc_expected(d, v, k, field, "a non-empty list of values", err);
	/* The file is said once for the axis, each value by its line. */
	a->key = dup_text(name);
	a->origin = dup_text(d->path);
	a->values = calloc((size_t)count, sizeof *a->values);
	a->lines = calloc((size_t)count, sizeof *a->lines);
	if (!a->key || !a->origin || !a->values || !a->lines)
		return bsim_error_set(err, BSIM_EFAIL, "%s: out of memory", d->path);
	for (int i = 0; i < count; i++) {
		struct fy_node *item = fy_node_sequence_get_by_index(v, i);
		if (!item || !fy_node_is_scalar(item) || bsim_ydoc_is_null(item)) {
			char f[540], idx[16];
			snprintf(idx, sizeof idx, ".%d", i);
			bsim_ydoc_join(f, sizeof f, field, idx);
			return bsim_ydoc_expected(d, item, k, f, "a scalar value", err);
		}
		a->values[i] = bsim_ydoc_flow_text(item);
		a->lines[i] = bsim_ydoc_line(item, k);
		a->n_values = i + 1;
		if (!a->values[i])
			return bsim_error_set(err, BSIM_EFAIL, "%s: out of memory", d->path);
	}
	return BSIM_OK;
}

/* The groups are the cartesian product of the axes: at least one axis
 * with at least one value (their count is checked by check_counts, once
 * the values have been). */
static int walk_grid(const ydoc *d, struct fy_node *n, struct fy_node *key, bsim_experiment *e,
                     bsim_error *err)
{
	int count = n && fy_node_is_mapping(n) ? fy_node_mapping_item_count(n) : 0;
	if (count == 0)
		return bsim_ydoc_expected(
		        d, n, key, "grid",
		        "at least one axis (a dotted scene key with a list of values)", err);
	e->axes = calloc((size_t)count, sizeof *e->axes);
	if (!e->axes)
		return bsim_error_set(err, BSIM_EFAIL, "%s: out of memory", d->path);
	for (int i = 0; i < count; i++) {
		struct fy_node_pair *p = fy_node_mapping_get_by_index(n, i);
		int rc = walk_axis(d, fy_node_pair_key(p), fy_node_pair_value(p), &e->axes[i], err);
		e->n_axes = i + 1;
		if (rc)
			return rc;
	}
	return BSIM_OK;
}

static int walk_trials(const ydoc *d, struct fy_node *n, struct fy_node *key, bsim_experiment *e,
                       bsim_error *err)
{
	long long v = 0;
	if (!bsim_ydoc_int64(n, &v) || v <= 0 || v > INT_MAX)
		return bsim_ydoc_expected(d, n, key, "trials", "a positive integer", err);
	e->trials = (int)v;
	return BSIM_OK;
}

static int walk_key(const ydoc *d, const char *name, struct fy_node *k, struct fy_node *v,
                    bsim_experiment *e, bsim_error *err)
{
	if (!strcmp(name, "name"))
		return v && fy_node_is_scalar(v) && !bsim_ydoc_is_null(v)
		               ? BSIM_OK
		               : bsim_ydoc_expected(d, v, k, "name", "a non-empty string", err);
	if (!strcmp(name, "scene"))
		return walk_scene_path(d, v, k, e, err);
	if (!strcmp(name, "trials"))
		return walk_trials(d, v, k, e, err);
	if (!strcmp(name, "seed"))
		return bsim_ydoc_uint64(v, &e->seed)
		               ? BSIM_OK
		               : bsim_ydoc_expected(d, v, k, "seed", "an integer >= 0", err);
	if (!strcmp(name, "set"))
		return walk_set(d, v, k, e, err);
	if (!strcmp(name, "grid"))
		return walk_grid(d, v, k, e, err);
	/* A scene given where an experiment belongs (beamsim sweep SCENE). */
	struct fy_node *root = fy_document_root(d->fyd);
	if (bsim_ydoc_pair(root, "body", 4) &&
	    (bsim_ydoc_pair(root, "beams", 5) || bsim_ydoc_pair(root, "lattice", 7)))
		return bsim_ydoc_fail(
		        d, k, NULL, name, err,
		        "this is a scene file (body: and beams: or lattice:), not an "
		        "experiment: run it with beamsim run, or name it in an experiment's "
		        "scene: with a grid:");
	return bsim_ydoc_fail(d, k, NULL, name, err, "unknown key (expected one of %s)",
	                      experiment_keys);
}

/* has_seed: a seed given beside the file stands in for its seed:. */
static int walk_experiment(const ydoc *d, int has_seed, bsim_experiment *e, bsim_error *err)
{
	static const char *const required[] = {"scene", "trials", "seed", "grid"};
	static const char *const phrase[] = {"a scene file name", "a positive integer",
	                                     "an integer >= 0, or give one with --seed N",
	                                     "a mapping of dotted keys to lists"};
	struct fy_node *root = fy_document_root(d->fyd);
	if (!root || !fy_node_is_mapping(root))
		return bsim_ydoc_expected(
		        d, root, NULL, "experiment",
		        "a mapping of experiment keys (scene, trials, seed, grid)", err);
	void *it = NULL;
	struct fy_node_pair *p;
	while ((p = fy_node_mapping_iterate(root, &it))) {
		struct fy_node *k = fy_node_pair_key(p);
		const char *name = key_text(k);
		int rc = walk_key(d, name ? name : "?", k, fy_node_pair_value(p), e, err);
		if (rc)
			return rc;
	}
	for (int i = 0; i < 4; i++)
		if (!bsim_ydoc_pair(root, required[i], strlen(required[i])) &&
		    !(has_seed && !strcmp(required[i], "seed")))
			return bsim_ydoc_fail(d, root, NULL, required[i], err,
			                      "missing (expected %s)", phrase[i]);
	return BSIM_OK;
}

void bsim_experiment_axis_free(bsim_grid_axis *ax)
{
	for (int i = 0; ax->values && i < ax->n_values; i++)
		free(ax->values[i]);
	free(ax->key);
	free(ax->values);
	free(ax->origin);
	free(ax->lines);
	memset(ax, 0, sizeof *ax);
}

int bsim_experiment_value_origin(const bsim_grid_axis *ax, int i, char *buf, size_t size)
{
	if (ax->origin && ax->lines)
		return snprintf(buf, size, "%s:%d", ax->origin, ax->lines[i]);
	if (ax->origin)
		return snprintf(buf, size, "%s=%s", ax->origin, ax->values[i]);
	return snprintf(buf, size, "--grid %s=%s", ax->key, ax->values[i]);
}

void bsim_experiment_axis_origin(const bsim_grid_axis *ax, char *buf, size_t size)
{
	if (ax->origin && ax->lines && ax->n_values > 0)
		snprintf(buf, size, "%s:%d", ax->origin, ax->lines[0]);
	else if (ax->origin)
		snprintf(buf, size, "%s", ax->origin);
	else
		snprintf(buf, size, "--grid %s", ax->key);
}

/* 1 if ax was given on the command line (or by a program as an option),
 * not in the experiment file. */
static int axis_from_option(const bsim_grid_axis *ax)
{
	return !ax->origin || strncmp(ax->origin, "--", 2) == 0;
}

/* A copy of from into to (which holds nothing): its values, and its origin
 * once. */
static int axis_copy(bsim_grid_axis *to, const bsim_grid_axis *from)
{
	size_t n = (size_t)(from->n_values > 0 ? from->n_values : 1);
	to->key = dup_text(from->key);
	to->values = calloc(n, sizeof *to->values);
	if (!to->key || !to->values)
		return -1;
	if (from->origin && !(to->origin = dup_text(from->origin)))
		return -1;
	if (from->lines) {
		if (!(to->lines = malloc(n * sizeof *to->lines)))
			return -1;
		memcpy(to->lines, from->lines, (size_t)from->n_values * sizeof *to->lines);
	}
	for (int i = 0; i < from->n_values; i++) {
		to->values[i] = dup_text(from->values[i]);
		to->n_values = i + 1;
		if (!to->values[i])
			return -1;
	}
	return 0;
}

/* 1 if key names the field axis or a field inside it ("beams.0.stiffness"
 * inside "beams.0"): the grid's value, applied later, replaces all of it. */
static int key_within(const char *key, const char *axis)
{
	size_t n = strlen(axis);
	return strncmp(key, axis, n) == 0 && (key[n] == '\0' || key[n] == '.');
}

/* The axes given beside the file (beamsim --grid): each replaces the
 * file's axis of its key where it stands, or is appended after the file's
 * in the order given; a set: entry of its field (or inside it) is dropped,
 * as the axis gives that field its values now. */
static int apply_grid(bsim_experiment *e, const bsim_grid_axis *grid, int n_grid, bsim_error *err)
{
	for (int k = 0; k < n_grid; k++) {
		const bsim_grid_axis *g = &grid[k];
		if (!g->key || !g->key[0] || g->n_values < 1 || !g->values)
			return bsim_error_set(err, BSIM_EINPUT,
			                      "%s: expected a dotted scene key with a non-empty "
			                      "list of values",
			                      g->origin ? g->origin : "--grid");
		int a = 0;
		while (a < e->n_axes && strcmp(e->axes[a].key, g->key) != 0)
			a++;
		if (a == e->n_axes) {
			bsim_grid_axis *axes = realloc(e->axes, (size_t)(a + 1) * sizeof *axes);
			if (!axes)
				return bsim_error_set(err, BSIM_EFAIL, "%s: out of memory",
				                      e->path);
			e->axes = axes;
			memset(&e->axes[a], 0, sizeof e->axes[a]);
			e->n_axes = a + 1;
		}
		bsim_experiment_axis_free(&e->axes[a]);
		if (axis_copy(&e->axes[a], g) != 0)
			return bsim_error_set(err, BSIM_EFAIL, "%s: out of memory", e->path);
		int kept = 0;
		for (int i = 0; i < e->n_set; i++) {
			bsim_override *o = &e->set[i];
			if (key_within(o->key, g->key)) {
				free((char *)o->key);
				free((char *)o->value);
				free((char *)o->origin);
			} else {
				e->set[kept++] = *o;
			}
		}
		e->n_set = kept;
	}
	return BSIM_OK;
}

/* The product of the lists' lengths within the limit groups (a few hundred
 * bytes of lists can ask for 10^9 groups, each a scene to build and check)
 * and an int, then groups x trials within the limit trials. */
static int check_counts(const ydoc *d, bsim_experiment *e, int n_grid, bsim_error *err)
{
	struct fy_node *root = fy_document_root(d->fyd);
	double groups = 1, limit = bsim_limits_get()->groups;
	for (int a = 0; a < e->n_axes; a++)
		groups *= e->axes[a].n_values;
	if (groups > limit || groups > INT_MAX) {
		struct fy_node_pair *gp = bsim_ydoc_pair(root, "grid", 4);
		char hint[160];
		bsim_limits_hint(hint, sizeof hint, "groups", limit);
		if (n_grid > 0) {
			/* the options that made the grid this large, with their
			 * counts */
			char given[512] = "";
			for (int k = 0; k < e->n_axes; k++) {
				const bsim_grid_axis *ax = &e->axes[k];
				char o[256];
				size_t at = strlen(given);
				bsim_experiment_axis_origin(ax, o, sizeof o);
				if (axis_from_option(ax) && at < sizeof given)
					snprintf(given + at, sizeof given - at, "%s%s (%d values)",
					         at ? ", " : "", o, ax->n_values);
			}
			return bsim_error_set(
			        err, BSIM_EINPUT,
			        "%s: expected at most %.15g groups (the product of the lists' "
			        "lengths, with %s's grid), got %.15g (%s)",
			        given, limit < INT_MAX ? limit : INT_MAX, d->path, groups, hint);
		}
		return bsim_ydoc_fail(
		        d, fy_node_pair_value(gp), fy_node_pair_key(gp), "grid", err,
		        "expected at most %.15g groups (the product of the lists' lengths), "
		        "got %.15g (%s)",
		        limit < INT_MAX ? limit : INT_MAX, groups, hint);
	}
	e->n_groups = (int)groups;
	bsim_error why;
	if (bsim_experiment_check_trials(e, e->trials, &why) != BSIM_OK) {
		struct fy_node_pair *tp = bsim_ydoc_pair(root, "trials", 6);
		return bsim_ydoc_fail(d, fy_node_pair_value(tp), fy_node_pair_key(tp), "trials",
		                      err, "%s", why.msg);
	}
	return BSIM_OK;
}

int bsim_experiment_check_trials(const bsim_experiment *e, long trials, bsim_error *err)
{
	double total = (double)e->n_groups * (double)trials, limit = bsim_limits_get()->trials;
	if (total <= limit)
		return BSIM_OK;
	char hint[160];
	bsim_limits_hint(hint, sizeof hint, "trials", limit);
	return bsim_error_set(err, BSIM_EINPUT,
	                      "expected at most %.15g trials in all, got %d groups x %ld trials = "
	                      "%.15g (%s)",
	                      limit, e->n_groups, trials, total, hint);
}

void bsim_experiment_group_index(const bsim_experiment *e, int g, int *idx)
{
	for (int a = e->n_axes - 1; a >= 0; a--) {
		idx[a] = g % e->axes[a].n_values;
		g /= e->axes[a].n_values;
	}
}

/* set, then extra (the command line), then the grid values of index idx:
 * later overrides win. The keys and values are borrowed from e and extra;
 * the grid values' origins are made here, after the array in the same
 * allocation, so that an axis holds one origin for all its values. */
static bsim_override *group_overrides(const bsim_experiment *e, const int *idx,
                                      const bsim_override *extra, int n_extra, int *n)
{
	*n = e->n_set + n_extra + e->n_axes;
	size_t head = (size_t)(*n ? *n : 1) * sizeof(bsim_override), text = 0;
	for (int a = 0; a < e->n_axes; a++)
		text += (size_t)bsim_experiment_value_origin(&e->axes[a], idx[a], NULL, 0) + 1;
	bsim_override *ov = malloc(head + text);
	if (!ov)
		return NULL;
	for (int i = 0; i < e->n_set; i++)
		ov[i] = e->set[i];
	for (int i = 0; i < n_extra; i++)
		ov[e->n_set + i] = extra[i];
	char *at = (char *)ov + head;
	for (int a = 0; a < e->n_axes; a++) {
		const bsim_grid_axis *ax = &e->axes[a];
		size_t len = (size_t)bsim_experiment_value_origin(ax, idx[a], at, text) + 1;
		ov[e->n_set + n_extra + a] = (bsim_override){ax->key, ax->values[idx[a]], at};
		at += len;
		text -= len;
	}
	return ov;
}

bsim_override *bsim_experiment_group_overrides(const bsim_experiment *e, int g,
                                               const bsim_override *extra, int n_extra, int *n)
{
	*n = 0;
	if (g < 0 || g >= e->n_groups)
		return NULL;
	int *idx = malloc((size_t)(e->n_axes ? e->n_axes : 1) * sizeof *idx);
	if (!idx)
		return NULL;
	bsim_experiment_group_index(e, g, idx);
	bsim_override *ov = group_overrides(e, idx, extra, n_extra, n);
	free(idx);
	return ov;
}

/* The scene of the group with value index idx[a] on each axis. */
static int load_at(const ydoc *scene, const bsim_experiment *e, const int *idx,
                   const bsim_override *extra, int n_extra, bsim_scene *out, bsim_error *err)
{
	int n = 0;
	bsim_override *ov = group_overrides(e, idx, extra, n_extra, &n);
	if (!ov)
		return bsim_error_set(err, BSIM_EFAIL, "%s: out of memory", e->path);
	int rc = bsim_scene_load_parsed(scene, ov, n, out, err);
	free(ov);
	return rc;
}

static int load_group(const ydoc *scene, const bsim_experiment *e, int g,
                      const bsim_override *extra, int n_extra, bsim_scene *out, bsim_error *err)
{
	int *idx = malloc((size_t)(e->n_axes ? e->n_axes : 1) * sizeof *idx);
	if (!idx)
		return bsim_error_set(err, BSIM_EFAIL, "%s: out of memory", e->path);
	bsim_experiment_group_index(e, g, idx);
	int rc = load_at(scene, e, idx, extra, n_extra, out, err);
	free(idx);
	return rc;
}

static void overrides_free(bsim_override *ov, int n)
{
	for (int i = 0; ov && i < n; i++) {
		free((char *)ov[i].key);
		free((char *)ov[i].value);
		free((char *)ov[i].origin);
	}
	free(ov);
}

/* The overrides extra[0..n) copied into *copy (strings owned by it). */
static int overrides_copy(const bsim_override *extra, int n, bsim_override **copy)
{
	*copy = calloc((size_t)(n ? n : 1), sizeof **copy);
	if (!*copy)
		return BSIM_EFAIL;
	for (int i = 0; i < n; i++) {
		(*copy)[i].key = dup_text(extra[i].key);
		(*copy)[i].value = dup_text(extra[i].value);
		(*copy)[i].origin = extra[i].origin ? dup_text(extra[i].origin) : NULL;
		if (!(*copy)[i].key || !(*copy)[i].value ||
		    (extra[i].origin && !(*copy)[i].origin)) {
			overrides_free(*copy, i + 1);
			*copy = NULL;
			return BSIM_EFAIL;
		}
	}
	return BSIM_OK;
}

/* The same keys and values, in the same order: the same scenes (where an
 * override came from names it in messages, and changes no value). */
static int overrides_same(const bsim_override *a, int n_a, const bsim_override *b, int n_b)
{
	if (n_a != n_b)
		return 0;
	for (int i = 0; i < n_a; i++)
		if (strcmp(a[i].key, b[i].key) || strcmp(a[i].value, b[i].value))
			return 0;
	return 1;
}

/* Guards an experiment's parsed scene and every document cloned from it:
 * libfyaml's copies share the parsed input, counted without atomics, so
 * threads making their groups' scenes (the figures do) make them one at a
 * time. */
static pthread_mutex_t scene_doc_lock = PTHREAD_MUTEX_INITIALIZER;

/* The scene file parsed: a copy of the document parsed at load, else the
 * text read at load parsed, else the file. */
static int scene_parse(const bsim_experiment *e, ydoc *scene, bsim_error *err)
{
	if (e->scene_doc) {
		memset(scene, 0, sizeof *scene);
		scene->path = e->scene_path;
		scene->fyd = fy_document_clone(e->scene_doc);
		return scene->fyd ? BSIM_OK
		                  : bsim_error_set(err, BSIM_EFAIL, "%s: out of memory", e->path);
	}
	if (e->scene_text)
		return bsim_ydoc_load_text(scene, e->scene_path, e->scene_text, e->scene_len, err);
	return bsim_ydoc_load(scene, e->scene_path, err);
}

int bsim_experiment_group_scene(const bsim_experiment *e, int g, const bsim_override *extra,
                                int n_extra, bsim_scene *out, bsim_error *err)
{
	if (g < 0 || g >= e->n_groups)
		return bsim_error_set(err, BSIM_EINPUT, "%s: group %d: expected 0 to %d", e->path,
		                      g, e->n_groups - 1);
	/* the scene the load built, for the same overrides */
	if (e->group_scenes && overrides_same(extra, n_extra, e->group_extra, e->n_group_extra))
		return bsim_scene_copy(out, &e->group_scenes[g]) == BSIM_OK
		               ? BSIM_OK
		               : bsim_error_set(err, BSIM_EFAIL, "%s: out of memory", e->path);
	ydoc scene;
	pthread_mutex_lock(&scene_doc_lock);
	int rc = scene_parse(e, &scene, err);
	if (rc == BSIM_OK) {
		rc = load_group(&scene, e, g, extra, n_extra, out, err);
		bsim_ydoc_free(&scene);
	}
	pthread_mutex_unlock(&scene_doc_lock);
	return rc;
}

int bsim_experiment_group_check(const bsim_experiment *e, int g, const bsim_override *extra,
                                int n_extra, const bsim_scene *scene, const bsim_backend *b,
                                const bsim_options *opts, bsim_error *err)
{
	if (!b->check)
		return BSIM_OK;
	int n = 0, *idx = malloc((size_t)(e->n_axes ? e->n_axes : 1) * sizeof *idx);
	bsim_override *ov = NULL;
	if (idx) {
		bsim_experiment_group_index(e, g, idx);
		ov = group_overrides(e, idx, extra, n_extra, &n);
	}
	free(idx);
	if (!ov)
		return bsim_error_set(err, BSIM_EFAIL, "%s: out of memory", e->path);
	int rc = bsim_backend_check(b, opts, scene, e->scene_path, ov, n, err);
	free(ov);
	return rc;
}

/* A fixed override (set: or --set) of a field the grid varies would be
 * overwritten in every group without a word: refused. One of a block that
 * holds the axis (set body.start, grid body.start.1) keeps its other
 * fields, so it stands, and the grid's value acts inside it. */
static int check_conflicts(const bsim_experiment *e, const bsim_override *extra, int n_extra,
                           bsim_error *err)
{
	for (int a = 0; a < e->n_axes; a++) {
		const bsim_grid_axis *ax = &e->axes[a];
		char where[256];
		bsim_experiment_axis_origin(ax, where, sizeof where);
		for (int i = 0; i < e->n_set; i++)
			if (key_within(e->set[i].key, ax->key))
				return bsim_error_set(
				        err, BSIM_EINPUT,
				        "%s: set.%s: the grid varies %s (%s), which would "
				        "overwrite it in every group; expected a key the "
				        "grid does not vary",
				        e->set[i].origin, e->set[i].key, ax->key, where);
		for (int i = 0; i < n_extra; i++)
			if (key_within(extra[i].key, ax->key))
				return bsim_error_set(
				        err, BSIM_EINPUT,
				        "%s: the experiment's grid varies %s (%s), which "
				        "would overwrite it in every group; expected a key "
				        "the grid does not vary (to run one value, give "
				        "--grid %s=VALUE)",
				        extra[i].origin ? extra[i].origin : extra[i].key, ax->key,
				        where, ax->key);
	}
	return BSIM_OK;
}

/* The scene of the group with value index idx[a] on each axis built and
 * validated; kept as that group's (bsim_experiment.group_scenes) where the
 * experiment keeps them. */
static int value_check(const ydoc *scene, bsim_experiment *e, const int *idx,
                       const bsim_override *extra, int n_extra, bsim_error *err)
{
	bsim_scene s;
	int rc = load_at(scene, e, idx, extra, n_extra, &s, err);
	if (rc || !e->group_scenes) {
		bsim_scene_free(&s);
		return rc;
	}
	int g = 0;
	for (int a = 0; a < e->n_axes; a++)
		g = g * e->axes[a].n_values + idx[a];
	e->group_scenes[g] = s;
	return BSIM_OK;
}

/* Each grid value in one group before the product is counted or expanded:
 * the first group, then every other value of each axis with the other axes
 * at their first. A value bad in itself is bad in every group that holds
 * it, and the first of those in group order is this one's: taken fastest
 * axis first, values in order (the order of their group numbers), the
 * first bad value found is the one the whole product would have named
 * first, with the same message. At most 1 + sum(n_values - 1) scenes, which
 * is at most the number of groups: beyond the limit groups, check_counts
 * refuses without them. */
static int check_values(const ydoc *scene, bsim_experiment *e, const bsim_override *extra,
                        int n_extra, bsim_error *err)
{
	double scenes = 1;
	for (int a = 0; a < e->n_axes; a++)
		scenes += e->axes[a].n_values - 1;
	if (scenes > bsim_limits_get()->groups)
		return BSIM_OK;
	int *idx = calloc((size_t)(e->n_axes ? e->n_axes : 1), sizeof *idx);
	if (!idx)
		return bsim_error_set(err, BSIM_EFAIL, "%s: out of memory", e->path);
	int rc = value_check(scene, e, idx, extra, n_extra, err);
	for (int a = e->n_axes - 1; !rc && a >= 0; a--) {
		for (int i = 1; !rc && i < e->axes[a].n_values; i++) {
			idx[a] = i;
			rc = value_check(scene, e, idx, extra, n_extra, err);
		}
		idx[a] = 0;
	}
	free(idx);
	return rc;
}

static void group_scenes_free(bsim_experiment *e)
{
	for (int g = 0; e->group_scenes && g < e->n_groups; g++)
		bsim_scene_free(&e->group_scenes[g]);
	free(e->group_scenes);
	e->group_scenes = NULL;
	overrides_free(e->group_extra, e->n_group_extra);
	e->group_extra = NULL;
	e->n_group_extra = 0;
}

/* Room for every group's scene (bsim_experiment.group_scenes), with the
 * overrides they are built with, where the groups are within the limit
 * and memory allows; else none kept. */
static void group_scenes_keep(bsim_experiment *e, const bsim_override *extra, int n_extra)
{
	double groups = 1; /* the product check_counts will count */
	for (int a = 0; a < e->n_axes; a++)
		groups *= e->axes[a].n_values;
	if (groups > bsim_limits_get()->groups || groups > INT_MAX)
		return;
	e->n_groups = (int)groups; /* for group_scenes_free, before check_counts sets it */
	e->group_scenes = calloc((size_t)groups, sizeof *e->group_scenes);
	if (e->group_scenes && overrides_copy(extra, n_extra, &e->group_extra) == BSIM_OK)
		e->n_group_extra = n_extra;
	else
		group_scenes_free(e);
}

/* Builds and validates every group's scene from the scene file read once
 * (but those check_values built and kept: a scene has beams once built),
 * and keeps them where the experiment does. */
static int check_groups(const ydoc *scene, bsim_experiment *e, const bsim_override *extra,
                        int n_extra, bsim_error *err)
{
	int rc = BSIM_OK;
	for (int g = 0; !rc && g < e->n_groups; g++) {
		if (e->group_scenes && e->group_scenes[g].beams)
			continue;
		bsim_scene s;
		rc = load_group(scene, e, g, extra, n_extra, &s, err);
		if (!rc && e->group_scenes)
			e->group_scenes[g] = s;
		else
			bsim_scene_free(&s);
	}
	return rc;
}

int bsim_experiment_load(const char *path, const bsim_override *extra, int n_extra,
                         bsim_experiment *out, bsim_error *err)
{
	return bsim_experiment_load_grid(path, extra, n_extra, NULL, 0, out, err);
}

int bsim_experiment_load_grid(const char *path, const bsim_override *extra, int n_extra,
                              const bsim_grid_axis *grid, int n_grid, bsim_experiment *out,
                              bsim_error *err)
{
	return bsim_experiment_load_seeded(path, extra, n_extra, grid, n_grid, NULL, out, err);
}

int bsim_experiment_load_seeded(const char *path, const bsim_override *extra, int n_extra,
                                const bsim_grid_axis *grid, int n_grid, const uint64_t *seed,
                                bsim_experiment *out, bsim_error *err)
{
	memset(out, 0, sizeof *out);
	if (strlen(path) >= sizeof out->path)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: expected a path shorter than %zu characters", path,
		                      sizeof out->path);
	snprintf(out->path, sizeof out->path, "%s", path);
	ydoc d, scene = {0};
	int rc = bsim_ydoc_load(&d, out->path, err);
	if (rc)
		return rc;
	rc = walk_experiment(&d, seed != NULL, out, err);
	if (!rc && seed)
		out->seed = *seed;
	if (!rc)
		rc = apply_grid(out, grid, n_grid, err);
	if (!rc)
		rc = scene_parse(out, &scene, err);
	if (!rc) { /* kept: every group's scene is made from it */
		out->scene_doc = fy_document_clone(scene.fyd);
		if (!out->scene_doc)
			rc = bsim_error_set(err, BSIM_EFAIL, "%s: out of memory", out->path);
	}
	if (!rc)
		group_scenes_keep(out, extra, n_extra);
	if (!rc)
		rc = check_values(&scene, out, extra, n_extra, err);
	if (!rc)
		rc = check_counts(&d, out, n_grid, err);
	bsim_ydoc_free(&d);
	if (!rc)
		rc = check_conflicts(out, extra, n_extra, err);
	if (!rc)
		rc = check_groups(&scene, out, extra, n_extra, err);
	if (scene.fyd)
		bsim_ydoc_free(&scene);
	if (rc)
		bsim_experiment_free(out);
	return rc;
}

void bsim_experiment_free(bsim_experiment *e)
{
	if (!e)
		return;
	group_scenes_free(e);
	overrides_free(e->set, e->n_set);
	for (int a = 0; a < e->n_axes; a++)
		bsim_experiment_axis_free(&e->axes[a]);
	free(e->axes);
	free(e->scene_text);
	if (e->scene_doc)
		fy_document_destroy(e->scene_doc);
	memset(e, 0, sizeof *e);
}
