/* Quiet YAML documents with positions and origins for one-line errors
 * (see yaml_doc.h). */
#include "util/yaml_doc.h"

#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/limits.h"
#include "util/decimal.h"
#include "util/file_read.h"
#include "util/text_check.h"

typedef struct first_error {
	int have;
	int line, col; /* 1-based */
	char msg[256];
} first_error;

static void diag_discard(struct fy_diag *diag, void *user, const char *buf, size_t len)
{
	(void)diag;
	(void)user;
	(void)buf;
	(void)len;
}

/* libfyaml prints diagnostics to stderr unless told otherwise; collect them
 * instead so that the caller reports one message of its own. */
static struct fy_diag *quiet_diag(void)
{
	struct fy_diag_cfg dc;
	fy_diag_cfg_default(&dc);
	dc.fp = NULL;
	dc.output_fn = diag_discard;
	dc.colorize = false;
	struct fy_diag *diag = fy_diag_create(&dc);
	if (diag)
		fy_diag_set_collect_errors(diag, true);
	return diag;
}

/* Parses text (malloc'd, len bytes; libfyaml takes it over) quietly, the
 * first document only, noting in *more whether a second one follows (which
 * libfyaml would otherwise drop without a word). Aliases are left as alias
 * nodes, never expanded: see find_alias. */
static struct fy_document *parse_quiet(char *text, size_t len, first_error *fe, int *more)
{
	memset(fe, 0, sizeof *fe);
	*more = 0;
	struct fy_diag *diag = quiet_diag();
	if (!diag) {
		free(text);
		return NULL;
	}
	struct fy_parse_cfg cfg;
	memset(&cfg, 0, sizeof cfg);
	cfg.flags = FYPCF_QUIET | FYPCF_COLLECT_DIAG;
	cfg.diag = diag;
	struct fy_parser *fyp = fy_parser_create(&cfg);
	struct fy_document *fyd = NULL;
	if (!fyp || fy_parser_set_malloc_string(fyp, text, len) != 0) {
		free(text);
	} else {
		fyd = fy_parse_load_document(fyp);
		struct fy_document *next = fyd ? fy_parse_load_document(fyp) : NULL;
		if (next) {
			*more = 1;
			fy_parse_document_destroy(fyp, next);
		}
	}
	void *it = NULL;
	struct fy_diag_error *e = fy_diag_errors_iterate(diag, &it);
	if (e) {
		fe->have = 1;
		fe->line = e->line;
		fe->col = e->column;
		snprintf(fe->msg, sizeof fe->msg, "%s", e->msg ? e->msg : "invalid YAML");
	}
	/* Turning collection off frees the collected errors (0.7.12 leaks them
	 * otherwise). */
	fy_diag_set_collect_errors(diag, false);
	if (fyp)
		fy_parser_destroy(fyp);
	fy_diag_unref(diag);
	if (fe->have && fyd) {
		fy_document_destroy(fyd);
		fyd = NULL;
	}
	return fyd;
}

/* The first alias node below n, with the dotted path of keys leading to it
 * in path. libfyaml expands aliases by copying, so nine nested aliases of
 * ten make 10^9 nodes from 400 bytes; scene and experiment files spell
 * their values out instead. The depth is bounded by libfyaml (64). */
static struct fy_node *find_alias(struct fy_node *n, char *path, size_t size)
{
	if (!n)
		return NULL;
	if (fy_node_is_alias(n))
		return n;
	size_t used = strlen(path);
	void *it = NULL;
	if (fy_node_is_mapping(n)) {
		struct fy_node_pair *p;
		while ((p = fy_node_mapping_iterate(n, &it))) {
			struct fy_node *k = fy_node_pair_key(p);
			const char *name = k && fy_node_is_scalar(k) && !fy_node_is_alias(k)
			                           ? fy_node_get_scalar0(k)
			                           : "?";
			snprintf(path + used, size - used, "%s%s", used ? "." : "",
			         name ? name : "?");
			struct fy_node *a = find_alias(k, path, size);
			if (!a)
				a = find_alias(fy_node_pair_value(p), path, size);
			if (a)
				return a;
			path[used] = '\0';
		}
	} else if (fy_node_is_sequence(n)) {
		struct fy_node *c;
		for (int i = 0; (c = fy_node_sequence_iterate(n, &it)); i++) {
			snprintf(path + used, size - used, "%s%d", used ? "." : "", i);
			struct fy_node *a = find_alias(c, path, size);
			if (a)
				return a;
			path[used] = '\0';
		}
	}
	return NULL;
}

static int node_mark(struct fy_node *n, int *line, int *col);

/* Why a text was refused, before or by the parser. */
typedef enum { PF_OK, PF_TEXT, PF_SYNTAX, PF_MORE, PF_ALIAS } parse_kind;

typedef struct parse_fault {
	parse_kind kind;
	int line, col;   /* PF_TEXT, PF_SYNTAX */
	char what[256];  /* PF_TEXT, PF_SYNTAX: what was found */
	char field[512]; /* PF_ALIAS: the dotted path to the alias */
	char alias[64];  /* PF_ALIAS: its name */
	int alias_line, alias_col;
} parse_fault;

/* Text check, parse, one document, no aliases. text is taken over. On a
 * fault d->fyd is NULL and *pf says why. */
static parse_kind parse_checked(ydoc *d, char *text, size_t len, parse_fault *pf)
{
	memset(pf, 0, sizeof *pf);
	text_fault tf;
	if (!bsim_text_check(text, len, &tf)) {
		free(text);
		pf->line = tf.line;
		pf->col = tf.col;
		snprintf(pf->what, sizeof pf->what, "%s", tf.what);
		return pf->kind = PF_TEXT;
	}
	len = bsim_text_strip_cr(text, len);
	first_error fe;
	int more = 0;
	d->fyd = parse_quiet(text, len, &fe, &more);
	if (fe.have) {
		pf->line = fe.line;
		pf->col = fe.col;
		snprintf(pf->what, sizeof pf->what, "%s", fe.msg);
		return pf->kind = PF_SYNTAX;
	}
	if (more) {
		bsim_ydoc_free(d);
		return pf->kind = PF_MORE;
	}
	struct fy_node *alias =
	        d->fyd ? find_alias(fy_document_root(d->fyd), pf->field, sizeof pf->field) : NULL;
	if (alias) {
		const char *name = fy_node_get_scalar0(alias);
		snprintf(pf->alias, sizeof pf->alias, "%s", name ? name : "");
		if (node_mark(alias, &pf->alias_line, &pf->alias_col)) {
			pf->alias_line++;
			pf->alias_col++;
		}
		bsim_ydoc_free(d);
		return pf->kind = PF_ALIAS;
	}
	return PF_OK;
}

/* The message of a fault in the file or value called name. */
static int fault_error(const char *name, const parse_fault *pf, bsim_error *err)
{
	switch (pf->kind) {
	case PF_TEXT:
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s:%d:%d: syntax: expected UTF-8 YAML text, got %s", name,
		                      pf->line, pf->col, pf->what);
	case PF_SYNTAX:
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s:%d:%d: syntax: expected valid YAML, got %s", name,
		                      pf->line, pf->col, pf->what);
	case PF_MORE:
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: syntax: expected one YAML document, got a second after "
		                      "---",
		                      name);
	case PF_ALIAS:
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s:%d:%d: %s: expected the value written out, got the "
		                      "alias *%s (beamsim does not expand YAML aliases)",
		                      name, pf->alias_line, pf->alias_col,
		                      pf->field[0] ? pf->field : "document", pf->alias);
	case PF_OK:
		break;
	}
	return BSIM_OK;
}

/* Reads path, at most max_bytes (the limit limit_name, or INFINITY). */
/* text (len bytes, a copy parse_checked takes) parsed as the file path. */
static int load_parsed(ydoc *d, const char *path, char *text, size_t len, bsim_error *err)
{
	parse_fault pf;
	if (parse_checked(d, text, len, &pf) != PF_OK)
		return fault_error(path, &pf, err);
	/* An empty file (or only comments) has no document at all: treat it as
	 * a document with no root, which the loaders report as "got nothing". */
	if (!d->fyd)
		d->fyd = fy_document_create(NULL);
	if (!d->fyd)
		return bsim_error_set(err, BSIM_EFAIL, "%s: out of memory", path);
	return BSIM_OK;
}

static int load(ydoc *d, const char *path, double max_bytes, const char *limit_name,
                bsim_error *err)
{
	memset(d, 0, sizeof *d);
	d->path = path;
	file_text f;
	int rc = bsim_file_read(path, "a YAML file", max_bytes, limit_name, &f, err);
	if (rc != BSIM_OK)
		return rc;
	return load_parsed(d, path, f.text, f.len, err);
}

int bsim_ydoc_load(ydoc *d, const char *path, bsim_error *err)
{
	return load(d, path, bsim_limits_get()->input_bytes, "input_bytes", err);
}

int bsim_ydoc_load_text(ydoc *d, const char *path, const char *text, size_t len, bsim_error *err)
{
	memset(d, 0, sizeof *d);
	d->path = path;
	char *copy = malloc(len + 1);
	if (!copy)
		return bsim_error_set(err, BSIM_EFAIL, "%s: out of memory", path);
	memcpy(copy, text, len);
	copy[len] = '\0';
	return load_parsed(d, path, copy, len, err);
}

int bsim_ydoc_load_own(ydoc *d, const char *path, bsim_error *err)
{
	return load(d, path, INFINITY, NULL, err);
}

/* An alias event as parse_checked reports an alias node (its path is not
 * known without a document). */
static void alias_fault(struct fy_event *ev, parse_fault *pf)
{
	struct fy_token *t = ev->alias.anchor;
	size_t len = 0;
	const char *name = t ? fy_token_get_text(t, &len) : NULL;
	const struct fy_mark *m = t ? fy_token_start_mark(t) : NULL;
	pf->kind = PF_ALIAS;
	snprintf(pf->alias, sizeof pf->alias, "%.*s", name ? (int)len : 0, name ? name : "");
	pf->alias_line = m ? m->line + 1 : 0;
	pf->alias_col = m ? m->column + 1 : 0;
}

int bsim_ydoc_events_own(const char *path, ydoc_event_fn fn, void *user, char **text,
                         bsim_error *err)
{
	if (text)
		*text = NULL;
	file_text f;
	int rc = bsim_file_read(path, "a YAML file", INFINITY, NULL, &f, err);
	if (rc != BSIM_OK)
		return rc;
	parse_fault pf;
	memset(&pf, 0, sizeof pf);
	text_fault tf;
	if (!bsim_text_check(f.text, f.len, &tf)) {
		free(f.text);
		pf.kind = PF_TEXT;
		pf.line = tf.line;
		pf.col = tf.col;
		snprintf(pf.what, sizeof pf.what, "%s", tf.what);
		return fault_error(path, &pf, err);
	}
	f.len = bsim_text_strip_cr(f.text, f.len);
	f.text[f.len] = '\0';
	struct fy_diag *diag = quiet_diag();
	struct fy_parse_cfg cfg;
	memset(&cfg, 0, sizeof cfg);
	cfg.flags = FYPCF_QUIET | FYPCF_COLLECT_DIAG;
	cfg.diag = diag;
	struct fy_parser *fyp = diag ? fy_parser_create(&cfg) : NULL;
	if (!fyp || fy_parser_set_string(fyp, f.text, f.len) != 0)
		rc = bsim_error_set(err, BSIM_EFAIL, "%s: out of memory", path);
	int docs = 0, ended = 0;
	struct fy_event *ev;
	while (rc == BSIM_OK && pf.kind == PF_OK && (ev = fy_parser_parse(fyp)) != NULL) {
		ended = ev->type == FYET_STREAM_END;
		if (ev->type == FYET_DOCUMENT_START && ++docs > 1)
			pf.kind = PF_MORE;
		else if (ev->type == FYET_ALIAS)
			alias_fault(ev, &pf);
		else if (ev->type != FYET_STREAM_START && ev->type != FYET_STREAM_END &&
		         ev->type != FYET_DOCUMENT_START && ev->type != FYET_DOCUMENT_END)
			rc = fn(user, ev, f.text, err);
		fy_parser_event_free(fyp, ev);
	}
	void *it = NULL;
	struct fy_diag_error *e = diag ? fy_diag_errors_iterate(diag, &it) : NULL;
	if (rc == BSIM_OK && e) {
		pf.kind = PF_SYNTAX;
		pf.line = e->line;
		pf.col = e->column;
		snprintf(pf.what, sizeof pf.what, "%s", e->msg ? e->msg : "invalid YAML");
	}
	if (rc == BSIM_OK && pf.kind != PF_OK)
		rc = fault_error(path, &pf, err);
	/* The parser stops without a word when it cannot allocate: a stream
	 * without its end is not taken for the whole file. */
	if (rc == BSIM_OK && !ended)
		rc = bsim_error_set(err, BSIM_EFAIL, "%s: out of memory", path);
	if (diag)
		fy_diag_set_collect_errors(diag, false);
	if (fyp)
		fy_parser_destroy(fyp);
	if (diag)
		fy_diag_unref(diag);
	if (rc == BSIM_OK && text)
		*text = f.text;
	else
		free(f.text);
	return rc;
}

struct fy_document *bsim_ydoc_parse_text(const char *text, char *msg, size_t size)
{
	size_t len = strlen(text);
	double limit = bsim_limits_get()->input_bytes;
	if ((double)len > limit) {
		char hint[160];
		bsim_limits_hint(hint, sizeof hint, "input_bytes", limit);
		snprintf(msg, size, "expected a value of at most %.15g bytes, got %zu (%s)", limit,
		         len, hint);
		return NULL;
	}
	char *copy = malloc(len + 1);
	if (!copy) {
		snprintf(msg, size, "out of memory");
		return NULL;
	}
	memcpy(copy, text, len + 1);
	ydoc d = {NULL, "value"};
	parse_fault pf;
	switch (parse_checked(&d, copy, len, &pf)) {
	case PF_TEXT:
		snprintf(msg, size, "expected UTF-8 YAML text, got %s at column %d", pf.what,
		         pf.col);
		return NULL;
	case PF_SYNTAX:
		snprintf(msg, size, "expected a YAML value, got %s (%s)", text, pf.what);
		return NULL;
	case PF_MORE:
		snprintf(msg, size, "expected one YAML value, got a second document after ---");
		return NULL;
	case PF_ALIAS:
		snprintf(msg, size,
		         "expected the value written out, got the alias *%s (beamsim does not "
		         "expand YAML aliases)",
		         pf.alias);
		return NULL;
	case PF_OK:
		break;
	}
	if (!d.fyd)
		snprintf(msg, size, "no value");
	return d.fyd;
}
void bsim_ydoc_free(ydoc *d)
{
	if (d->fyd)
		fy_document_destroy(d->fyd);
	d->fyd = NULL;
}

const bsim_override *bsim_ydoc_origin(struct fy_node *n)
{
	/* Only nodes an override inserted carry meta (a pointer to its
	 * bsim_override); their descendants find it through their parents. */
	for (; n; n = fy_node_get_parent(n)) {
		void *meta = fy_node_get_meta(n);
		if (meta)
			return (const bsim_override *)meta;
	}
	return NULL;
}

/* The 0-based start of n: its own token for a scalar, its first child for a
 * collection (libfyaml keeps no public start mark for collections). */
static int node_mark(struct fy_node *n, int *line, int *col)
{
	if (!n)
		return 0;
	if (fy_node_is_scalar(n)) {
		struct fy_token *t = fy_node_get_scalar_token(n);
		const struct fy_mark *m = t ? fy_token_start_mark(t) : NULL;
		if (!m)
			return 0;
		*line = m->line;
		*col = m->column;
		return 1;
	}
	if (fy_node_is_mapping(n)) {
		struct fy_node_pair *p = fy_node_mapping_get_by_index(n, 0);
		return p && node_mark(fy_node_pair_key(p), line, col);
	}
	return node_mark(fy_node_sequence_get_by_index(n, 0), line, col);
}

static void origin_text(const bsim_override *o, char *buf, size_t size)
{
	if (o->origin)
		snprintf(buf, size, "%s", o->origin);
	else
		snprintf(buf, size, "--set %s=%s", o->key ? o->key : "", o->value ? o->value : "");
}

void bsim_ydoc_where(const ydoc *d, struct fy_node *n, struct fy_node *alt, char *buf, size_t size)
{
	/* Keys have no parent in libfyaml: a key an override brought in finds
	 * its origin through alt (its mapping). */
	const bsim_override *o = bsim_ydoc_origin(n);
	if (!o)
		o = bsim_ydoc_origin(alt);
	if (o) {
		origin_text(o, buf, size);
		return;
	}
	int line = 0, col = 0;
	if (!node_mark(n, &line, &col) && !node_mark(alt, &line, &col))
		line = col = 0;
	snprintf(buf, size, "%s:%d:%d", d->path, line + 1, col + 1);
}

void bsim_ydoc_join(char *buf, size_t size, const char *a, const char *b)
{
	if (snprintf(buf, size, "%s%s", a, b) < 0)
		buf[0] = '\0';
}

int bsim_ydoc_line(struct fy_node *n, struct fy_node *alt)
{
	int line = 0, col = 0;
	if (node_mark(n, &line, &col) || node_mark(alt, &line, &col))
		return line + 1;
	return 0;
}

int bsim_ydoc_fail(const ydoc *d, struct fy_node *n, struct fy_node *alt, const char *field,
                   bsim_error *err, const char *fmt, ...)
{
	char where[512], what[512];
	bsim_ydoc_where(d, n, alt, where, sizeof where);
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(what, sizeof what, fmt, ap);
	va_end(ap);
	return bsim_error_set(err, BSIM_EINPUT, "%s: %s: %s", where, field, what);
}

int bsim_ydoc_expected(const ydoc *d, struct fy_node *n, struct fy_node *alt, const char *field,
                       const char *what, bsim_error *err)
{
	char got[128];
	bsim_ydoc_describe(n, got, sizeof got);
	return bsim_ydoc_fail(d, n, alt, field, err, "expected %s, got %s", what, got);
}

int bsim_ydoc_is_null(struct fy_node *n)
{
	return !n || (fy_node_is_scalar(n) && fy_node_get_style(n) == FYNS_PLAIN &&
	              fy_node_get_scalar_length(n) == 0);
}

void bsim_ydoc_describe(struct fy_node *n, char *buf, size_t size)
{
	if (bsim_ydoc_is_null(n)) {
		snprintf(buf, size, "nothing");
	} else if (fy_node_is_mapping(n)) {
		int k = fy_node_mapping_item_count(n);
		snprintf(buf, size, k ? "a mapping" : "an empty mapping");
	} else if (fy_node_is_sequence(n)) {
		int k = fy_node_sequence_item_count(n);
		if (k == 0)
			snprintf(buf, size, "an empty list");
		else
			snprintf(buf, size, "a list of %d item%s", k, k == 1 ? "" : "s");
	} else {
		/* Long text is cut so the message stays one readable line. */
		size_t len = 0;
		const char *t = fy_node_get_scalar(n, &len);
		int cut = len > 60;
		int shown = cut ? 60 : (int)len;
		const char *q = fy_node_get_style(n) == FYNS_PLAIN ? "" : "\"";
		snprintf(buf, size, "%s%.*s%s%s", q, shown, t ? t : "", cut ? "..." : "", q);
	}
}

const char *bsim_ydoc_plain(struct fy_node *n)
{
	if (!n || !fy_node_is_scalar(n) || fy_node_get_style(n) != FYNS_PLAIN)
		return NULL;
	const char *t = fy_node_get_scalar0(n);
	return t && *t ? t : NULL;
}

/* YAML's spellings of the non-finite floats: .inf, -.Inf, .NaN, ... */
static int yaml_nonfinite(const char *t)
{
	if (*t == '+' || *t == '-')
		t++;
	char low[5] = {0};
	for (int i = 0; i < 4 && t[i]; i++)
		low[i] = (char)tolower((unsigned char)t[i]);
	return strlen(t) == 4 && (!strcmp(low, ".inf") || !strcmp(low, ".nan"));
}

int bsim_ydoc_number(struct fy_node *n, double *out)
{
	return bsim_ydoc_number_text(bsim_ydoc_plain(n), out);
}

int bsim_ydoc_number_text(const char *t, double *out)
{
	if (!t || !*t)
		return YDOC_NUM_NONE;
	if (yaml_nonfinite(t))
		return YDOC_NUM_NONFINITE;
	char *end = NULL;
	double v = strtod(t, &end);
	if (end == t || *end != '\0' || isspace((unsigned char)*t) || bsim_decimal_other_base(t))
		return YDOC_NUM_NONE;
	if (!isfinite(v))
		return YDOC_NUM_NONFINITE; /* "nan", "inf", or an overflow like 1e999 */
	*out = v;
	return YDOC_NUM_OK;
}

/* Sign and magnitude of a plain decimal integer; 0 if t is not one or the
 * magnitude does not fit 64 bits. */
static int parse_decimal(const char *t, int *neg, uint64_t *mag)
{
	*neg = 0;
	if (*t == '+' || *t == '-')
		*neg = *t++ == '-';
	if (!isdigit((unsigned char)*t) || bsim_decimal_other_base(t))
		return 0;
	uint64_t v = 0;
	for (; isdigit((unsigned char)*t); t++) {
		unsigned digit = (unsigned)(*t - '0');
		if (v > (UINT64_MAX - digit) / 10)
			return 0;
		v = v * 10 + digit;
	}
	*mag = v;
	return *t == '\0';
}

int bsim_ydoc_int64(struct fy_node *n, long long *out)
{
	const char *t = bsim_ydoc_plain(n);
	int neg;
	uint64_t mag;
	if (!t || !parse_decimal(t, &neg, &mag) || mag > (uint64_t)INT64_MAX)
		return 0;
	*out = neg ? -(long long)mag : (long long)mag;
	return 1;
}

int bsim_ydoc_uint64(struct fy_node *n, uint64_t *out)
{
	const char *t = bsim_ydoc_plain(n);
	int neg;
	uint64_t mag;
	if (!t || !parse_decimal(t, &neg, &mag) || (neg && mag != 0))
		return 0;
	*out = mag;
	return 1;
}

int bsim_ydoc_uint64_text(struct fy_node *n, uint64_t *out)
{
	if (!n || !fy_node_is_scalar(n))
		return 0;
	const char *t = fy_node_get_scalar0(n);
	int neg;
	uint64_t mag;
	if (!t || !*t || !parse_decimal(t, &neg, &mag) || (neg && mag != 0))
		return 0;
	*out = mag;
	return 1;
}

int bsim_ydoc_index(const char *comp, size_t len, int *out)
{
	if (len == 0 || len > 9)
		return 0;
	int v = 0;
	for (size_t i = 0; i < len; i++) {
		if (!isdigit((unsigned char)comp[i]))
			return 0;
		v = v * 10 + (comp[i] - '0');
	}
	*out = v;
	return 1;
}

/* libfyaml's lookup_by_string parses the key as YAML (and may complain
 * about it); a key from a dotted path is plain text, so compare text. */
struct fy_node_pair *bsim_ydoc_pair(struct fy_node *map, const char *comp, size_t len)
{
	void *it = NULL;
	struct fy_node_pair *p;
	while ((p = fy_node_mapping_iterate(map, &it))) {
		size_t klen = 0;
		struct fy_node *k = fy_node_pair_key(p);
		const char *t = k && fy_node_is_scalar(k) ? fy_node_get_scalar(k, &klen) : NULL;
		if (t && klen == len && !memcmp(t, comp, len))
			return p;
	}
	return NULL;
}

struct fy_node *bsim_ydoc_child(struct fy_node *n, const char *comp, size_t len)
{
	if (n && fy_node_is_mapping(n)) {
		struct fy_node_pair *p = bsim_ydoc_pair(n, comp, len);
		return p ? fy_node_pair_value(p) : NULL;
	}
	int i;
	if (n && fy_node_is_sequence(n) && bsim_ydoc_index(comp, len, &i))
		return fy_node_sequence_get_by_index(n, i);
	return NULL;
}

struct fy_node *bsim_ydoc_lookup(struct fy_node *root, const char *path)
{
	struct fy_node *n = root;
	while (n && *path) {
		size_t len = strcspn(path, ".");
		n = bsim_ydoc_child(n, path, len);
		path += len;
		if (*path == '.')
			path++;
	}
	return n;
}

char *bsim_ydoc_flow_text(struct fy_node *n)
{
	const char *t = bsim_ydoc_plain(n);
	if (t) {
		char *copy = malloc(strlen(t) + 1);
		if (copy)
			strcpy(copy, t);
		return copy;
	}
	char *s = fy_emit_node_to_string(n, FYECF_MODE_FLOW_ONELINE | FYECF_NO_ENDING_NEWLINE |
	                                            FYECF_WIDTH_INF);
	if (!s)
		return NULL;
	/* Trim the emitter's surrounding whitespace, if any. */
	size_t len = strlen(s);
	while (len && isspace((unsigned char)s[len - 1]))
		s[--len] = '\0';
	size_t lead = strspn(s, " \t");
	memmove(s, s + lead, len - lead + 1);
	return s;
}
