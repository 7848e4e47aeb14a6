/* Internal: a YAML document read quietly with libfyaml, and the pieces every
 * loader needs to report one-line errors "WHERE: FIELD: expected WHAT, got
 * GOT". WHERE is the file position of the offending node, or the origin of
 * the override that put the node there (overrides tag the nodes they create
 * with fy_node_set_meta, see yaml_override.c). */
#ifndef BSIM_UTIL_YAML_DOC_H
#define BSIM_UTIL_YAML_DOC_H

#include <stddef.h>
#include <stdint.h>

#include <libfyaml.h>

#include "beamsim/error.h"
#include "beamsim/override.h"

typedef struct ydoc {
	struct fy_document *fyd;
	const char *path; /* the file name used in messages, borrowed */
} ydoc;

/* Reads and parses path: at most the limit input_bytes (beamsim/limits.h),
 * UTF-8 text without NUL, tabs, control characters or directives
 * (text_check.h), one document, no aliases (never expanded). Any fault
 * becomes BSIM_EINPUT with "FILE:LINE:COL: syntax: expected ..., got ..."
 * (or the alias's field); libfyaml prints nothing itself. */
int bsim_ydoc_load(ydoc *d, const char *path, bsim_error *err);

/* bsim_ydoc_load of a file's text already read (len bytes; copied), named path
 * in messages: the same checks but the size limit, which the read applied. */
int bsim_ydoc_load_text(ydoc *d, const char *path, const char *text, size_t len, bsim_error *err);

/* bsim_ydoc_load of a file beamsim wrote itself (summary.json, report.json,
 * run.json, manifest.json, ...): checked the same way but without the
 * input_bytes limit, which is a bound on what a user's file may ask for,
 * not on what a large run writes. Bounded by memory only. */
int bsim_ydoc_load_own(ydoc *d, const char *path, bsim_error *err);

/* A file beamsim wrote itself read as bsim_ydoc_load_own reads it (the same
 * checks and messages; an alias is refused without its field's path, and
 * a key given twice is not looked for) but without a document: each event
 * of its one document goes to fn as the parser makes it (not the stream's
 * or document's own start and end), so that memory is what fn keeps, not
 * libfyaml's nodes and tokens (about 44 bytes a byte of JSON). fn gets the
 * file's text (the events' marks are offsets into it) and returns BSIM_OK
 * or an error it set in err, which stops the parse. text: NULL, or gets
 * that text (malloc'd, NUL-terminated; NULL on failure) for the caller to
 * free. */
typedef int (*ydoc_event_fn)(void *user, struct fy_event *ev, const char *text, bsim_error *err);
int bsim_ydoc_events_own(const char *path, ydoc_event_fn fn, void *user, char **text,
                         bsim_error *err);

/* Parses YAML flow text (an override value) into a new document, checked
 * like a file. On failure returns NULL and puts in msg "expected ..., got
 * ..." saying why. */
struct fy_document *bsim_ydoc_parse_text(const char *text, char *msg, size_t size);

void bsim_ydoc_free(ydoc *d);

/* The override that created n or one of its ancestors, NULL if it came from
 * the file. */
const bsim_override *bsim_ydoc_origin(struct fy_node *n);

/* Writes where n is: the override origin, else "FILE:LINE:COL". Nodes without
 * a position of their own (an empty value, an empty mapping) use alt, usually
 * the key they belong to. */
void bsim_ydoc_where(const ydoc *d, struct fy_node *n, struct fy_node *alt, char *buf, size_t size);

/* buf = a followed by b, cut to size: field paths ("beams.0.mass") only
 * ever appear in messages. */
void bsim_ydoc_join(char *buf, size_t size, const char *a, const char *b);

/* The 1-based line of n (or of alt when n has no position), 0 if unknown;
 * for "FILE:LINE" origins of experiment values. */
int bsim_ydoc_line(struct fy_node *n, struct fy_node *alt);

/* Sets err to "WHERE: FIELD: MESSAGE" and returns BSIM_EINPUT. */
int bsim_ydoc_fail(const ydoc *d, struct fy_node *n, struct fy_node *alt, const char *field,
                   bsim_error *err, const char *fmt, ...) __attribute__((format(printf, 6, 7)));

/* Sets err to "WHERE: FIELD: expected WHAT, got <n described>". */
int bsim_ydoc_expected(const ydoc *d, struct fy_node *n, struct fy_node *alt, const char *field,
                       const char *what, bsim_error *err);

/* An absent or empty value ("key:" with nothing after it). */
int bsim_ydoc_is_null(struct fy_node *n);

/* What a node is, for the "got ..." half of a message: the scalar text
 * ("-1", ".nan", "\"7\"" for a quoted string), "a mapping", "a list of 3
 * items", "nothing". */
void bsim_ydoc_describe(struct fy_node *n, char *buf, size_t size);

/* The text of a plain scalar; NULL for anything else (a quoted string, a
 * collection, an empty value). */
const char *bsim_ydoc_plain(struct fy_node *n);

/* Number parsing: YDOC_NUM_OK, YDOC_NUM_NONE (not a plain number),
 * YDOC_NUM_NONFINITE (.nan, .inf, 1e999, "nan", ...). */
enum { YDOC_NUM_OK = 0, YDOC_NUM_NONE = 1, YDOC_NUM_NONFINITE = 2 };
int bsim_ydoc_number(struct fy_node *n, double *out);
/* The same for the text of a plain scalar (NULL: YDOC_NUM_NONE). */
int bsim_ydoc_number_text(const char *t, double *out);

/* Plain decimal integers only ("3000", "+7", "-1"); 1 on success. */
int bsim_ydoc_int64(struct fy_node *n, long long *out);
int bsim_ydoc_uint64(struct fy_node *n, uint64_t *out);
/* The same, the digits plain or quoted ("18446744073709551615": JSON
 * files write seeds above 2^53 as strings). */
int bsim_ydoc_uint64_text(struct fy_node *n, uint64_t *out);

/* The pair of a mapping whose scalar key is exactly comp[0..len). */
struct fy_node_pair *bsim_ydoc_pair(struct fy_node *map, const char *comp, size_t len);

/* A list index in a dotted path: decimal digits only; 1 on success. */
int bsim_ydoc_index(const char *comp, size_t len, int *out);

/* The child of a mapping by key or of a sequence by decimal index; NULL if
 * absent or n is a scalar. len is the length of comp. */
struct fy_node *bsim_ydoc_child(struct fy_node *n, const char *comp, size_t len);

/* The node at a dotted path ("beams.0.pivot") below root, NULL if absent. */
struct fy_node *bsim_ydoc_lookup(struct fy_node *root, const char *path);

/* Flow text of a node that re-parses to the same value: plain scalars as
 * written, anything else emitted on one line. malloc'd, NULL on failure. */
char *bsim_ydoc_flow_text(struct fy_node *n);

#endif
