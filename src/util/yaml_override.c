/* Overrides by dotted path: "beams.0.stiffness=250", "body.start=[1, 2]",
 * "effects.propulsion={force: 3}". The value is parsed by libfyaml and its
 * node copied into the scene document, so the result is validated exactly
 * like a file. */
#include "util/yaml_override.h"

#include <ctype.h>
#include <string.h>

/* Where the node being edited hangs: a mapping pair, a list item, or the
 * document root (neither). */
typedef struct slot {
	struct fy_node *node;
	struct fy_node_pair *pair;
	struct fy_node *seq;
} slot;

/* Nodes created for an override point at it, so errors about them (or about
 * anything below them) name the override instead of a file position. */
static void tag(struct fy_node *n, const bsim_override *o)
{
	fy_node_set_meta(n, (void *)o);
}

static int replace(ydoc *d, slot *s, struct fy_node *with)
{
	int rc;
	if (s->pair) {
		rc = fy_node_pair_set_value(s->pair, with);
	} else if (s->seq) {
		rc = fy_node_sequence_insert_before(s->seq, s->node, with);
		if (rc == 0)
			fy_node_free(fy_node_sequence_remove(s->seq, s->node));
	} else {
		rc = fy_document_set_root(d->fyd, with);
	}
	s->node = with;
	return rc;
}

static int fail(const bsim_override *o, const char *field, int len, bsim_error *err,
                const char *what)
{
	if (o->origin)
		return bsim_error_set(err, BSIM_EINPUT, "%s: %.*s: %s", o->origin, len, field,
		                      what);
	return bsim_error_set(err, BSIM_EINPUT, "--set %s=%s: %.*s: %s", o->key, o->value, len,
	                      field, what);
}

/* A dotted key is scene keys and list indices joined by dots: letters,
 * digits and '_', no empty component ("a..b", ".a" and "a." are typos). */
static int key_ok(const char *key)
{
	size_t n = strlen(key);
	if (!n || key[0] == '.' || key[n - 1] == '.' || strstr(key, ".."))
		return 0;
	for (size_t i = 0; i < n; i++)
		if (!isalnum((unsigned char)key[i]) && key[i] != '_' && key[i] != '.')
			return 0;
	return 1;
}

/* The key without the spaces around it ("body.mass = 2" is the override
 * body.mass=2), into buf; 0 if it does not fit. */
static int key_trim(const char *key, char *buf, size_t size)
{
	while (*key == ' ')
		key++;
	size_t n = strlen(key);
	while (n && key[n - 1] == ' ')
		n--;
	if (n >= size)
		return 0;
	memcpy(buf, key, n);
	buf[n] = '\0';
	return 1;
}

/* One step down a mapping: the child at comp, created (an empty mapping, or
 * the value itself at the last step) when missing. */
static int step_mapping(ydoc *d, slot *s, const char *comp, size_t len, struct fy_node *value,
                        const bsim_override *o)
{
	struct fy_node_pair *p = bsim_ydoc_pair(s->node, comp, len);
	if (!p) {
		struct fy_node *k = fy_node_create_scalar_copy(d->fyd, comp, len);
		struct fy_node *v = value ? value : fy_node_create_mapping(d->fyd);
		if (k && v) {
			tag(k, o);
			tag(v, o);
		}
		if (!k || !v || fy_node_mapping_append(s->node, k, v)) {
			/* value, if it is v, stays the caller's to free. */
			fy_node_free(k);
			if (v != value)
				fy_node_free(v);
			return -1;
		}
		p = bsim_ydoc_pair(s->node, comp, len);
		*s = (slot){v, p, NULL};
		return 0;
	}
	*s = (slot){fy_node_pair_value(p), p, NULL};
	return value ? replace(d, s, value) : 0;
}

/* One step down a list: the item at index comp, which must exist. */
static int step_list(ydoc *d, slot *s, const char *comp, size_t len, struct fy_node *value,
                     const bsim_override *o, const char *key, bsim_error *err)
{
	int i = -1;
	int count = fy_node_sequence_item_count(s->node);
	char what[256];
	if (!bsim_ydoc_index(comp, len, &i) || i >= count) {
		if (count == 0)
			snprintf(what, sizeof what,
			         "expected an index into a list, got %.*s (the list is empty)",
			         (int)len, comp);
		else
			snprintf(what, sizeof what, "expected an index from 0 to %d, got %.*s",
			         count - 1, (int)len, comp);
		return fail(o, key, (int)(comp + len - key), err, what);
	}
	struct fy_node *seq = s->node;
	*s = (slot){fy_node_sequence_get_by_index(seq, i), NULL, seq};
	return value && replace(d, s, value) ? -1 : 0;
}

/* Walks the dotted key from the root and puts value at its end. */
static int place(ydoc *d, const bsim_override *o, const char *key, struct fy_node *value,
                 bsim_error *err)
{
	slot s = {fy_document_root(d->fyd), NULL, NULL};
	for (const char *c = key;; c++) {
		size_t len = strcspn(c, ".");
		struct fy_node *v = c[len] ? NULL : value;
		int rc;
		if (bsim_ydoc_is_null(s.node)) {
			/* "effects:" with nothing under it is an empty mapping. */
			struct fy_node *map = fy_node_create_mapping(d->fyd);
			if (!map || replace(d, &s, map))
				return bsim_error_set(err, BSIM_EFAIL, "out of memory");
			tag(map, o);
		}
		if (fy_node_is_mapping(s.node)) {
			rc = step_mapping(d, &s, c, len, v, o);
		} else if (fy_node_is_sequence(s.node)) {
			rc = step_list(d, &s, c, len, v, o, key, err);
			if (rc == BSIM_EINPUT)
				return rc;
		} else {
			char what[256], got[96];
			bsim_ydoc_describe(s.node, got, sizeof got);
			snprintf(what, sizeof what, "expected a mapping or list at %.*s, got %s",
			         (int)(c - key - 1), key, got);
			return fail(o, key, (int)strlen(key), err, what);
		}
		if (rc)
			return bsim_error_set(err, BSIM_EFAIL, "out of memory applying %s", key);
		if (!c[len])
			return BSIM_OK;
		c += len;
	}
}

static int apply_one(ydoc *d, const bsim_override *o, bsim_error *err)
{
	char key[256];
	if (!o->key || !o->value || !key_trim(o->key, key, sizeof key) || !key_ok(key)) {
		const char *k = o->key ? o->key : "";
		char what[600];
		snprintf(what, sizeof what,
		         "expected a dotted key like beams.0.stiffness, got \"%.500s\"", k);
		return fail(o, k, (int)strlen(k), err, what);
	}
	char msg[400], what[600];
	struct fy_document *vd = bsim_ydoc_parse_text(o->value, msg, sizeof msg);
	if (!vd || !fy_document_root(vd)) {
		if (vd)
			fy_document_destroy(vd);
		if (!vd)
			snprintf(what, sizeof what, "%s", msg);
		else
			snprintf(what, sizeof what, "expected a YAML value, got nothing");
		return fail(o, key, (int)strlen(key), err, what);
	}
	struct fy_node *value = fy_node_copy(d->fyd, fy_document_root(vd));
	fy_document_destroy(vd);
	if (!value)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory applying %s", key);
	tag(value, o);
	int rc = place(d, o, key, value, err);
	if (rc && !fy_node_get_parent(value) && !fy_node_is_attached(value))
		fy_node_free(value);
	return rc;
}

int bsim_yov_apply(ydoc *d, const bsim_override *ov, int n, bsim_error *err)
{
	struct fy_node *root = fy_document_root(d->fyd);
	if (!root || !fy_node_is_mapping(root))
		return BSIM_OK;
	for (int i = 0; i < n; i++) {
		int rc = apply_one(d, &ov[i], err);
		if (rc)
			return rc;
	}
	return BSIM_OK;
}
