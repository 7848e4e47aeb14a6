/* Scene files: read with libfyaml, apply the overrides to the document, walk
 * it into a bsim_scene by the schema tables (scene_schema.c), then the
 * checks that involve several fields. Every failure is one BSIM_EINPUT
 * message "WHERE: FIELD: expected WHAT, got GOT" (yaml_doc.h). */
#include "beamsim/scene.h"

#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "beamsim/limits.h"
#include "beamsim/body_shape.h"
#include "model/scene_internal.h"
#include "util/yaml_override.h"

typedef scene_walk walk;

#define walk_table bsim_scene_walk_table

/* "expected WHAT, got <the node>" at node n (or its key), field at. */
static int expected(walk *w, struct fy_node *n, struct fy_node *key, const scene_path *at,
                    const char *what)
{
	char field[300];
	bsim_scene_path_format(at, field, sizeof field);
	return bsim_ydoc_expected(w->d, n, key, field, what, w->err);
}

/* bsim_ydoc_fail with the field at path at. */
static int walk_fail(walk *w, struct fy_node *n, struct fy_node *alt, const scene_path *at,
                     const char *fmt, ...) __attribute__((format(printf, 5, 6)));
static int walk_fail(walk *w, struct fy_node *n, struct fy_node *alt, const scene_path *at,
                     const char *fmt, ...)
{
	char field[300], what[600];
	bsim_scene_path_format(at, field, sizeof field);
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(what, sizeof what, fmt, ap);
	va_end(ap);
	return bsim_ydoc_fail(w->d, n, alt, field, w->err, "%s", what);
}

static int walk_number(walk *w, const scene_field *f, struct fy_node *n, struct fy_node *key,
                       const scene_path *field, double *out)
{
	int rc = bsim_ydoc_number(n, out);
	if (rc == YDOC_NUM_NONFINITE)
		return expected(w, n, key, field, "a finite number");
	if (rc != YDOC_NUM_OK || !bsim_scene_in_range(f->range, *out))
		return expected(w, n, key, field, bsim_scene_phrase(f));
	return BSIM_OK;
}

static int walk_int(walk *w, const scene_field *f, struct fy_node *n, struct fy_node *key,
                    const scene_path *field, int *out)
{
	long long v = 0;
	long long lo = f->kind == SK_INDEX ? -1000000 : f->range == SR_NONNEG ? 0 : 1;
	long long hi = f->kind == SK_INDEX ? 1000000 : INT_MAX;
	if (!bsim_ydoc_int64(n, &v) || v < lo || v > hi)
		return expected(w, n, key, field, bsim_scene_phrase(f));
	*out = (int)v;
	return BSIM_OK;
}

static int walk_vec2(walk *w, const scene_field *f, struct fy_node *n, struct fy_node *key,
                     const scene_path *field, double *out)
{
	if (!n || !fy_node_is_sequence(n) || fy_node_sequence_item_count(n) != 2)
		return expected(w, n, key, field, bsim_scene_phrase(f));
	static const scene_field coord = {"", SK_NUMBER, SR_ANY, 0, 0, NULL};
	for (int i = 0; i < 2; i++) {
		const scene_path item = {field, NULL, i};
		int rc = walk_number(w, &coord, fy_node_sequence_get_by_index(n, i), n, &item,
		                     &out[i]);
		if (rc)
			return rc;
	}
	return BSIM_OK;
}

static int walk_name(walk *w, const scene_field *f, struct fy_node *n, struct fy_node *key,
                     const scene_path *field, char *out)
{
	size_t len = 0;
	const char *t = n && fy_node_is_scalar(n) ? fy_node_get_scalar(n, &len) : NULL;
	if (!t || len == 0 || bsim_ydoc_is_null(n))
		return expected(w, n, key, field, bsim_scene_phrase(f));
	if (len >= sizeof w->s->name)
		return expected(w, n, key, field, "a name of at most 127 characters");
	memcpy(out, t, len);
	out[len] = '\0';
	return BSIM_OK;
}

/* Each list item is one beam: defaults first, then its keys. The inertia
 * default (a uniform rod about its end, m L^2 / 3) needs mass and length, so
 * it is filled in after the walk. */
static int walk_beams(walk *w, const scene_field *f, struct fy_node *n, struct fy_node *key,
                      const scene_path *field)
{
	int count = n && fy_node_is_sequence(n) ? fy_node_sequence_item_count(n) : 0;
	if (count == 0)
		return expected(w, n, key, field, bsim_scene_phrase(f));
	if (bsim_scene_set_beams(w->s, count) != BSIM_OK)
		return bsim_error_set(w->err, BSIM_EFAIL, "%s: out of memory", w->d->path);
	for (int i = 0; i < count; i++) {
		struct fy_node *item = fy_node_sequence_get_by_index(n, i);
		bsim_beam_def *b = &w->s->beams[i];
		const scene_path at = {field, NULL, i};
		if (!item || !fy_node_is_mapping(item))
			return expected(w, item, key, &at, "a mapping (one beam)");
		memset(b, 0, sizeof *b);
		b->inertia = NAN; /* not given yet */
		int rc = walk_table(w, f->sub, item, key, (char *)b, &at);
		if (rc)
			return rc;
		if (isnan(b->inertia))
			b->inertia = b->mass * b->length * b->length / 3;
	}
	return BSIM_OK;
}

static int walk_block(walk *w, const scene_field *f, struct fy_node *n, struct fy_node *key,
                      char *base, const scene_path *field)
{
	/* "effects:" with nothing under it is an empty block. */
	if (!bsim_ydoc_is_null(n) && !fy_node_is_mapping(n))
		return expected(w, n, key, field, bsim_scene_phrase(f));
	if (f->offset != SCENE_NO_FLAG)
		*(int *)(base + f->offset) = 1;
	return walk_table(w, f->sub, bsim_ydoc_is_null(n) ? NULL : n, key, base, field);
}

/* The lattice: block: its keys as a table, between the lattice module's
 * defaults and its checks and beams (scene_lattice.c). */
static int walk_lattice(walk *w, const scene_field *f, struct fy_node *n, struct fy_node *key,
                        const scene_path *field)
{
	if (!n || !fy_node_is_mapping(n))
		return bsim_ydoc_expected(w->d, n, key, "lattice",
		                          "a mapping (columns, rows, gate, beam, stiffness, ...)",
		                          w->err);
	bsim_scene_lattice_begin(w->s);
	int rc = walk_table(w, f->sub, n, key, (char *)w->s, field);
	return rc ? rc : bsim_scene_lattice_finish(w, n, key);
}

static int walk_field(walk *w, const scene_field *f, struct fy_node *n, struct fy_node *key,
                      char *base, const scene_path *field)
{
	switch (f->kind) {
	case SK_NUMBER:
		return walk_number(w, f, n, key, field, (double *)(base + f->offset));
	case SK_INT:
		return walk_int(w, f, n, key, field, (int *)(base + f->offset));
	case SK_VEC2:
		return walk_vec2(w, f, n, key, field, (double *)(base + f->offset));
	case SK_NAME:
		return walk_name(w, f, n, key, field, base + f->offset);
	case SK_BLOCK:
		return walk_block(w, f, n, key, base, field);
	case SK_BEAMS:
		return walk_beams(w, f, n, key, field);
	case SK_INDEX:
		return walk_int(w, f, n, key, field, (int *)(base + f->offset));
	case SK_LATTICE:
		return walk_lattice(w, f, n, key, field);
	case SK_LATER:
		return BSIM_OK;
	}
	return BSIM_OK;
}

static int find_field(const scene_table *t, const char *key)
{
	for (int i = 0; key && i < t->n_fields; i++)
		if (!strcmp(t->fields[i].key, key))
			return i;
	return -1;
}

/* Walks one mapping (NULL: an empty one) against table t: unknown keys are
 * errors, known ones are stored, missing required ones are reported at the
 * mapping (or at alt, the key naming it, when it is empty). */
int bsim_scene_walk_table(walk *w, const scene_table *t, struct fy_node *map, struct fy_node *alt,
                          char *base, const scene_path *at)
{
	unsigned seen = 0;
	void *it = NULL;
	struct fy_node_pair *p;
	while (map && (p = fy_node_mapping_iterate(map, &it))) {
		struct fy_node *k = fy_node_pair_key(p);
		const char *name = k && fy_node_is_scalar(k) ? fy_node_get_scalar0(k) : NULL;
		const scene_path field = {at, name ? name : "?", 0};
		int i = find_field(t, name);
		/* An experiment given where a scene belongs (beamsim run EXP). */
		if (i < 0 && !at && bsim_ydoc_pair(map, "scene", 5) &&
		    bsim_ydoc_pair(map, "grid", 4))
			return walk_fail(
			        w, k, map, &field,
			        "this is an experiment file (scene: and grid:), not a scene: "
			        "run it with beamsim sweep or compare, or run its scene");
		if (i < 0) {
			char keys[512];
			bsim_scene_keys(t, keys, sizeof keys);
			return walk_fail(w, k, map, &field, "unknown key (expected one of %s)",
			                 keys);
		}
		seen |= 1u << i;
		int rc = walk_field(w, &t->fields[i], fy_node_pair_value(p), k, base, &field);
		if (rc)
			return rc;
	}
	for (int i = 0; i < t->n_fields; i++) {
		const scene_field *f = &t->fields[i];
		if (f->required && !(seen & (1u << i))) {
			const scene_path field = {at, f->key, 0};
			return walk_fail(w, map, alt, &field, "missing (expected %s)",
			                 bsim_scene_phrase(f));
		}
	}
	return BSIM_OK;
}

/* Of the nodes at paths (some may be absent), the one an override set last,
 * or NULL when none came from an override: errors that involve several
 * fields blame the latest change. All overrides of one load are one array,
 * so a later one has the higher address. */
static struct fy_node *latest_override(const ydoc *d, const char *const *paths, int n)
{
	struct fy_node *root = fy_document_root(d->fyd), *best = NULL;
	const bsim_override *best_o = NULL;
	for (int i = 0; i < n; i++) {
		struct fy_node *node = bsim_ydoc_lookup(root, paths[i]);
		const bsim_override *o = node ? bsim_ydoc_origin(node) : NULL;
		if (o && (!best_o || o > best_o)) {
			best = node;
			best_o = o;
		}
	}
	return best;
}

/* classify_y >= success_y: blame the one an override changed last, else
 * classify_y (or success_y when only it is in the file). */
static int check_termination(walk *w)
{
	const bsim_scene *s = w->s;
	if (s->classify_y >= s->success_y)
		return BSIM_OK;
	const char *paths[] = {"termination.classify_y", "termination.success_y"};
	struct fy_node *root = fy_document_root(w->d->fyd);
	struct fy_node *classify = bsim_ydoc_lookup(root, paths[0]);
	struct fy_node *n = latest_override(w->d, paths, 2);
	if (!n)
		n = classify ? classify : bsim_ydoc_lookup(root, paths[1]);
	char got[128];
	bsim_ydoc_describe(n, got, sizeof got);
	if (n == classify)
		return bsim_ydoc_fail(w->d, n, NULL, paths[0], w->err,
		                      "expected a number >= termination.success_y (%g), got %s",
		                      s->success_y, got);
	return bsim_ydoc_fail(w->d, n, NULL, paths[1], w->err,
	                      "expected a number <= termination.classify_y (%g), got %s",
	                      s->classify_y, got);
}

/* The default success line, 65 m, is the essay's gate's for its disk of
 * radius 10 m: the beams' forward reach (pivot row 30 + beam 25) plus R.
 * For another shape it is that reach plus the outline's farthest point
 * from the centre (bsim_body_shape_reach), so that a beam swung forward no
 * longer reaches the body; classify_y stays 15 m beyond it. What the file
 * gives is kept. */
static void success_line_default(walk *w, struct fy_node *root)
{
	bsim_scene *s = w->s;
	if (s->has_lattice || s->body.shape == BSIM_SHAPE_DISK ||
	    bsim_ydoc_lookup(root, "termination.success_y"))
		return;
	s->success_y = 55.0 + bsim_body_shape_reach(&s->body);
	if (!bsim_ydoc_lookup(root, "termination.classify_y"))
		s->classify_y = s->success_y + 15.0;
}

/* The body must not start inside a beam (docs/model.md section 3). The message
 * points at body.start, or at the override that last moved the body or that
 * beam. */
static int check_overlap(walk *w)
{
	double dist = 0;
	int beam = bsim_scene_overlap(w->s, &dist);
	if (beam < 0)
		return BSIM_OK;
	char p[4][64];
	static const char *const keys[4] = {"pivot", "rest_angle_deg", "length", "initial_theta"};
	for (int i = 0; i < 4; i++)
		snprintf(p[i], sizeof p[i], "beams.%d.%s", beam, keys[i]);
	const char *paths[] = {"body.start", "body.radius", p[0], p[1], p[2], p[3]};
	struct fy_node *root = fy_document_root(w->d->fyd);
	struct fy_node *n = latest_override(w->d, paths, 6);
	if (!n)
		n = bsim_ydoc_lookup(root, "body.start");
	if (!n)
		n = bsim_ydoc_lookup(root, "body");
	return bsim_ydoc_fail(
	        w->d, n, NULL, "body.start", w->err,
	        "the body (radius %g) overlaps beam %d (beams.%d) at the start (distance %.3g m)",
	        w->s->body.radius, beam + 1, beam, dist);
}

/* A valid scene that asks for more than a limit allows: the message
 * blames the override that changed one of the fields involved last, else
 * the field itself, else the block it would be in. */
static int check_limits(walk *w)
{
	scene_excess x;
	if (!bsim_scene_excess_find(w->s, &x))
		return BSIM_OK;
	static const char *const schedule[] = {"effects.random_force.frequency", "integration.dt",
	                                       "integration.max_steps", "integration.duration"};
	static const char *const steps[] = {"integration.max_steps", "integration.duration",
	                                    "beams", "lattice.columns", "lattice.rows"};
	int is_schedule = !strcmp(x.limit, "schedule");
	const char *const *paths = is_schedule ? schedule : steps;
	int n = is_schedule ? 4 : 5;
	struct fy_node *root = fy_document_root(w->d->fyd);
	struct fy_node *node = latest_override(w->d, paths, n);
	const char *field = paths[0];
	for (int i = 0; i < n; i++) {
		struct fy_node *at = bsim_ydoc_lookup(root, paths[i]);
		if (node ? at == node : at != NULL) {
			node = at;
			field = paths[i];
			break;
		}
	}
	if (!node) /* all defaults: the block the first field would be in */
		node = bsim_ydoc_lookup(root, is_schedule ? "effects.random_force" : "integration");
	char hint[160], detail[128];
	bsim_limits_hint(hint, sizeof hint, x.limit, x.max);
	bsim_scene_excess_detail(w->s, &x, detail, sizeof detail);
	return bsim_ydoc_fail(w->d, node ? node : root, NULL, field, w->err,
	                      "expected at most %.15g %s, got %.3g%s (%s)", x.max, x.what, x.got,
	                      detail, hint);
}

/* A step the scene cannot be resolved at (scene_timestep.c): always said
 * of integration.dt, at the override that changed dt or a field of the
 * bound last, else at dt in the file, else at the first of the bound's
 * fields the file gives, else at the integration block or the root. */
static int check_timestep(walk *w)
{
	scene_dt_bound b;
	if (!bsim_scene_dt_find(w->s, &b))
		return BSIM_OK;
	const char *paths[1 + SCENE_DT_PATHS] = {"integration.dt"};
	for (int i = 0; i < b.n_paths; i++)
		paths[1 + i] = b.paths[i];
	int n = 1 + b.n_paths;
	struct fy_node *root = fy_document_root(w->d->fyd);
	struct fy_node *node = latest_override(w->d, paths, n);
	for (int i = 0; !node && i < n; i++)
		node = bsim_ydoc_lookup(root, paths[i]);
	if (!node)
		node = bsim_ydoc_lookup(root, "integration");
	char msg[640];
	bsim_scene_dt_message(w->s, &b, msg, sizeof msg);
	return bsim_ydoc_fail(w->d, node ? node : root, NULL, "integration.dt", w->err, "%s", msg);
}

/* The file's base name without its extension: "configs/gate.yaml" -> "gate". */
static void default_name(bsim_scene *s, const char *path)
{
	const char *base = strrchr(path, '/');
	base = base ? base + 1 : path;
	size_t len = strcspn(base, ".");
	if (len == 0)
		len = strlen(base);
	if (len >= sizeof s->name)
		len = sizeof s->name - 1;
	memcpy(s->name, base, len);
	s->name[len] = '\0';
}

/* An effect block that asks for nothing simulates nothing: "Rm = 0 means no
 * random force at all (no draws)" (docs/model.md section 2), and likewise a
 * propulsion of 0 N. */
static void effects_present(bsim_scene *s)
{
	if (s->effects.propulsion_force == 0)
		s->effects.has_propulsion = 0;
	if (s->effects.random_magnitude == 0)
		s->effects.has_random_force = 0;
	if (s->effects.drag_linear == 0 && s->effects.drag_angular == 0)
		s->effects.has_drag = 0;
	if (s->effects.osc_amplitude == 0)
		s->effects.has_oscillation = 0;
	if (s->effects.ground_mu == 0)
		s->effects.has_ground_friction = 0;
}

/* effects.random_force.model: held (the essay's, the default), ou or
 * white. */
static int random_model(walk *w, struct fy_node *root)
{
	struct fy_node *n = bsim_ydoc_lookup(root, "effects.random_force.model");
	if (!n)
		return BSIM_OK;
	const char *t = bsim_ydoc_plain(n);
	static const char *const names[] = {"held", "ou", "white"};
	for (int i = 0; t && i < 3; i++)
		if (!strcmp(t, names[i])) {
			w->s->effects.random_model = (bsim_random_model)i;
			return BSIM_OK;
		}
	return bsim_ydoc_expected(
	        w->d, n, NULL, "effects.random_force.model",
	        "held (the essay's piecewise constant force), ou (Ornstein-Uhlenbeck, "
	        "correlation_time s) or white (a new value each step)",
	        w->err);
}

/* One of names[0 .. n) at path, or nothing; what names the value is
 * stored in *out. */
static int scene_word(walk *w, struct fy_node *root, const char *path, const char *const *names,
                      int n, const char *what, int *out, int *given)
{
	struct fy_node *node = bsim_ydoc_lookup(root, path);
	*given = node != NULL;
	if (!node)
		return BSIM_OK;
	const char *t = bsim_ydoc_plain(node);
	for (int i = 0; t && i < n; i++)
		if (!strcmp(t, names[i])) {
			*out = i;
			return BSIM_OK;
		}
	return bsim_ydoc_expected(w->d, node, NULL, path, what, w->err);
}

/* effects.ground_friction.model: coupled (the default) or decoupled. */
static int ground_model(walk *w, struct fy_node *root)
{
	static const char *const names[] = {"coupled", "decoupled"};
	int model = BSIM_FRICTION_COUPLED, given = 0;
	int rc = scene_word(w, root, "effects.ground_friction.model", names, 2,
	                    "coupled (each patch of the footprint against its own velocity) or "
	                    "decoupled (the sliding and the spinning each within its own limit)",
	                    &model, &given);
	w->s->effects.ground_model = (bsim_friction_model)model;
	return rc;
}

/* body.shape (disk, the default; capsule; ellipse), the size keys that go
 * with it, body.rotates (default: false for a disk, true otherwise) and
 * effects.propulsion.along (y, the default, or heading). */
static int body_shape(walk *w, struct fy_node *root)
{
	static const char *const shapes[] = {"disk", "capsule", "ellipse"};
	static const char *const flags[] = {"false", "true"};
	static const char *const along[] = {"y", "heading"};
	bsim_body_def *b = &w->s->body;
	int shape = BSIM_SHAPE_DISK, rotates = 0, given = 0, rotates_given = 0, dir = BSIM_ALONG_Y;
	int rc = scene_word(w, root, "body.shape", shapes, 3,
	                    "disk, capsule (body.radius and body.length) or ellipse "
	                    "(body.semi_axes)",
	                    &shape, &given);
	if (!rc)
		rc = scene_word(w, root, "body.rotates", flags, 2, "true or false", &rotates,
		                &rotates_given);
	if (!rc)
		rc = scene_word(
		        w, root, "effects.propulsion.along", along, 2,
		        "y (the essay's forward push) or heading (the thrust follows the body)",
		        &dir, &given);
	if (rc)
		return rc;
	b->shape = (bsim_body_shape)shape;
	b->rotates = rotates_given ? rotates : shape != BSIM_SHAPE_DISK;
	w->s->effects.propulsion_along = (bsim_propulsion_along)dir;
	/* The sizes a shape must be given, positive, and none it does not
	 * have; said at the key (or the override) that gives them. */
	struct fy_node *body = bsim_ydoc_lookup(root, "body");
	static const char *const names[] = {"a disk", "a capsule", "an ellipse"};
	static const struct {
		const char *key, *what;
		int shape_mask; /* the shapes that need it, 1 << shape */
	} sizes[] = {
	        {"radius", "a positive number (the disk's radius or the capsule's half-width, m)",
	         1 << BSIM_SHAPE_DISK | 1 << BSIM_SHAPE_CAPSULE},
	        {"length", "a positive number (the capsule's segment, m)", 1 << BSIM_SHAPE_CAPSULE},
	        {"semi_axes",
	         "a list of 2 positive numbers [a, b] (the semi-axes along and across the "
	         "heading, m)",
	         1 << BSIM_SHAPE_ELLIPSE},
	};
	const double *value[] = {&b->radius, &b->length, b->semi_axes};
	for (int i = 0; i < 3; i++) {
		char field[32];
		snprintf(field, sizeof field, "body.%s", sizes[i].key);
		struct fy_node *n = bsim_ydoc_lookup(root, field);
		int needed = sizes[i].shape_mask >> shape & 1;
		if (!needed && n)
			return bsim_ydoc_fail(w->d, n, body, field, w->err,
			                      "expected none for %s (it is %s)", names[shape],
			                      i == 0   ? "sized by body.semi_axes"
			                      : i == 1 ? "only a capsule that has a length"
			                               : "only an ellipse that has semi-axes");
		if (needed && !n)
			return bsim_ydoc_fail(w->d, body, root, field, w->err,
			                      "missing (expected %s)", sizes[i].what);
		if (needed && !(value[i][0] > 0 && (i < 2 || value[i][1] > 0)))
			return bsim_ydoc_expected(w->d, n, body, field, sizes[i].what, w->err);
	}
	return BSIM_OK;
}

/* A scene has beams: or lattice:, not both, not neither. */
static int check_beams_or_lattice(walk *w, struct fy_node *root)
{
	struct fy_node_pair *beams = bsim_ydoc_pair(root, "beams", 5);
	struct fy_node_pair *lattice = bsim_ydoc_pair(root, "lattice", 7);
	if (beams && lattice)
		return bsim_ydoc_fail(w->d, fy_node_pair_key(lattice), root, "lattice", w->err,
		                      "expected either beams: or lattice:, not both");
	if (!beams && !lattice)
		return bsim_ydoc_fail(w->d, root, NULL, "beams", w->err,
		                      "missing (expected a non-empty list of beams, or a lattice: "
		                      "block)");
	return BSIM_OK;
}

/* The lattice's termination defaults where the file and overrides leave a
 * key out (bsim_scene_lattice_defaults); a length given in seconds counts as
 * given (bsim_scene_horizon has made it steps). */
static void lattice_defaults(walk *w, struct fy_node *root)
{
	bsim_scene *s = w->s, given = *s;
	bsim_scene_lattice_defaults(s);
	static const char *const keys[] = {"termination.success_y",  "termination.side_x",
	                                   "termination.classify_y", "landscape.y0",
	                                   "termination.gate_steps", "integration.max_steps",
	                                   "termination.gate_time",  "integration.duration"};
	if (bsim_ydoc_lookup(root, keys[0]))
		s->success_y = given.success_y;
	if (bsim_ydoc_lookup(root, keys[1]))
		s->side_x = given.side_x;
	if (bsim_ydoc_lookup(root, keys[2]))
		s->classify_y = given.classify_y;
	else
		s->classify_y = s->success_y;
	if (bsim_ydoc_lookup(root, keys[3]))
		s->landscape_y0 = given.landscape_y0;
	if (bsim_ydoc_lookup(root, keys[4]) || bsim_ydoc_lookup(root, keys[6]))
		s->gate_steps = given.gate_steps;
	if (bsim_ydoc_lookup(root, keys[5]) || bsim_ydoc_lookup(root, keys[7]))
		s->max_steps = given.max_steps;
	else
		s->max_steps = s->gate_steps * (s->lattice.rows + s->lattice.columns);
}

static int walk_scene(walk *w, const ydoc *file)
{
	struct fy_node *root = fy_document_root(w->d->fyd);
	if (!root || !fy_node_is_mapping(root))
		return bsim_ydoc_expected(w->d, root, NULL, "scene",
		                          "a mapping of scene keys (body, beams, ...)", w->err);
	int rc = walk_table(w, &bsim_scene_top_table, root, NULL, (char *)w->s, NULL);
	if (!rc)
		rc = random_model(w, root);
	if (!rc)
		rc = body_shape(w, root);
	if (!rc)
		rc = ground_model(w, root);
	if (!rc)
		rc = check_beams_or_lattice(w, root);
	if (!rc)
		rc = bsim_scene_horizon(w, file);
	if (!rc && w->s->has_lattice)
		lattice_defaults(w, root);
	if (!rc)
		success_line_default(w, root);
	if (!rc)
		rc = check_termination(w);
	if (!rc)
		rc = check_overlap(w);
	effects_present(w->s);
	if (!rc)
		rc = check_timestep(w);
	if (!rc)
		rc = check_limits(w);
	return rc;
}

int bsim_scene_load_parsed(const ydoc *file, const bsim_override *ov, int n, bsim_scene *out,
                           bsim_error *err)
{
	bsim_scene_defaults(out);
	if (strlen(file->path) >= sizeof out->path)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: expected a path shorter than %zu characters", file->path,
		                      sizeof out->path);
	ydoc d = *file;
	d.fyd = fy_document_clone(file->fyd);
	if (!d.fyd)
		return bsim_error_set(err, BSIM_EFAIL, "%s: out of memory", file->path);
	walk w = {&d, out, err};
	int rc = bsim_yov_apply(&d, ov, n, err);
	if (!rc)
		rc = walk_scene(&w, file);
	bsim_ydoc_free(&d);
	if (!rc) {
		snprintf(out->path, sizeof out->path, "%s", file->path);
		if (!out->name[0])
			default_name(out, file->path);
		rc = bsim_scene_validate(out, err);
	}
	if (rc) {
		bsim_scene_free(out);
		bsim_scene_defaults(out);
	}
	return rc;
}

int bsim_scene_load(const char *path, const bsim_override *overrides, int n_overrides,
                    bsim_scene *out, bsim_error *err)
{
	ydoc d;
	bsim_scene_defaults(out);
	int rc = bsim_ydoc_load(&d, path, err);
	if (rc)
		return rc;
	rc = bsim_scene_load_parsed(&d, overrides, n_overrides, out, err);
	bsim_ydoc_free(&d);
	return rc;
}
