/* The lattice: block of a scene file (docs/files.md "Scene file (YAML)",
 * docs/model.md section 8): its keys by the schema table, then what needs the
 * lattice's shape first (the ix range, the stiffness maps, the map's CSV
 * file, the protocol), then the beams built from it. Every failure is one
 * message "WHERE: lattice.FIELD: expected WHAT, got GOT", WHERE a position in
 * the scene file or, for the CSV, in that file. */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "beamsim/lattice.h"
#include "model/scene_internal.h"
#include "util/decimal.h"
#include "util/file_read.h"

/* Gates a lattice may have: 1e5 gates is 2e5 beams, far beyond any study. */
#define LATTICE_GATES_MAX 100000

typedef struct lattice_maps {
	double *gate, *left, *right; /* rows x columns each, NULL if not given */
} lattice_maps;

static void maps_free(lattice_maps *m)
{
	free(m->gate);
	free(m->left);
	free(m->right);
}

static struct fy_node *child(struct fy_node *map, const char *key, struct fy_node **key_node)
{
	struct fy_node_pair *p = map ? bsim_ydoc_pair(map, key, strlen(key)) : NULL;
	if (key_node)
		*key_node = p ? fy_node_pair_key(p) : NULL;
	return p ? fy_node_pair_value(p) : NULL;
}

/* ix range: columns (odd, centred on 0), or ix_min and ix_max. */
static int lattice_range(scene_walk *w, struct fy_node *map, struct fy_node *key)
{
	bsim_lattice_def *l = &w->s->lattice;
	struct fy_node *kc, *kmin, *kmax;
	struct fy_node *columns = child(map, "columns", &kc);
	struct fy_node *ix_min = child(map, "ix_min", &kmin);
	struct fy_node *ix_max = child(map, "ix_max", &kmax);
	if ((ix_min != NULL) != (ix_max != NULL)) {
		struct fy_node *given = ix_min ? ix_min : ix_max;
		return bsim_ydoc_fail(w->d, given, ix_min ? kmin : kmax,
		                      ix_min ? "lattice.ix_max" : "lattice.ix_min", w->err,
		                      "missing (expected both ix_min and ix_max, or columns)");
	}
	if (ix_min) {
		if (l->ix_max < l->ix_min)
			return bsim_ydoc_fail(w->d, ix_max, kmax, "lattice.ix_max", w->err,
			                      "expected an integer >= lattice.ix_min (%d), got %d",
			                      l->ix_min, l->ix_max);
		int span = l->ix_max - l->ix_min + 1;
		if (columns && l->columns != span)
			return bsim_ydoc_fail(w->d, columns, kc, "lattice.columns", w->err,
			                      "expected %d (ix_min %d .. ix_max %d), got %d", span,
			                      l->ix_min, l->ix_max, l->columns);
		l->columns = span;
		return BSIM_OK;
	}
	if (!columns)
		return bsim_ydoc_fail(
		        w->d, map, key, "lattice.columns", w->err,
		        "missing (expected a positive odd integer, or ix_min and ix_max)");
	if (l->columns % 2 == 0)
		return bsim_ydoc_fail(w->d, columns, kc, "lattice.columns", w->err,
		                      "expected an odd number (gates ix = -(columns-1)/2 .. "
		                      "(columns-1)/2; give ix_min and ix_max otherwise), got %d",
		                      l->columns);
	l->ix_max = (l->columns - 1) / 2;
	l->ix_min = -l->ix_max;
	return BSIM_OK;
}

/* One stiffness value of a map: a finite number >= 0. */
static int map_number(scene_walk *w, struct fy_node *n, struct fy_node *alt, const char *field,
                      double *out)
{
	int rc = bsim_ydoc_number(n, out);
	if (rc == YDOC_NUM_NONFINITE)
		return bsim_ydoc_expected(w->d, n, alt, field, "a finite number >= 0", w->err);
	if (rc != YDOC_NUM_OK || !(*out >= 0.0))
		return bsim_ydoc_expected(w->d, n, alt, field, "a number >= 0 (N m/rad)", w->err);
	return BSIM_OK;
}

/* A map in the file: rows lists (iy = 0 first) of columns numbers. */
static int map_walk(scene_walk *w, struct fy_node *n, struct fy_node *key, const char *name,
                    double *out)
{
	const bsim_lattice_def *l = &w->s->lattice;
	char field[64], what[160];
	snprintf(field, sizeof field, "lattice.%s", name);
	snprintf(what, sizeof what,
	         "a list of %d rows (row iy = 0 first) of %d numbers (ix = %d .. %d)", l->rows,
	         l->columns, l->ix_min, l->ix_max);
	if (!n || !fy_node_is_sequence(n) || fy_node_sequence_item_count(n) != l->rows)
		return bsim_ydoc_expected(w->d, n, key, field, what, w->err);
	for (int iy = 0; iy < l->rows; iy++) {
		struct fy_node *row = fy_node_sequence_get_by_index(n, iy);
		char rfield[80];
		snprintf(rfield, sizeof rfield, "%s.%d", field, iy);
		snprintf(what, sizeof what, "a list of %d numbers (ix = %d .. %d)", l->columns,
		         l->ix_min, l->ix_max);
		if (!row || !fy_node_is_sequence(row) ||
		    fy_node_sequence_item_count(row) != l->columns)
			return bsim_ydoc_expected(w->d, row, n, rfield, what, w->err);
		for (int c = 0; c < l->columns; c++) {
			char vfield[96];
			snprintf(vfield, sizeof vfield, "%s.%d", rfield, c);
			int rc = map_number(w, fy_node_sequence_get_by_index(row, c), row, vfield,
			                    &out[iy * l->columns + c]);
			if (rc)
				return rc;
		}
	}
	return BSIM_OK;
}

/* "configs/lattice/c_track.yaml" + "track.csv" -> "configs/lattice/track.csv" */
static int csv_path(const char *scene, const char *rel, char *buf, size_t size)
{
	const char *slash = strrchr(scene, '/');
	int dir = slash ? (int)(slash - scene + 1) : 0;
	int n = snprintf(buf, size, "%.*s%s", dir, scene, rel);
	return n > 0 && (size_t)n < size ? 0 : -1;
}

/* A name beside the scene: relative, no ".." component, not empty. */
static int name_beside(const char *rel)
{
	if (!*rel || rel[0] == '/')
		return 0;
	for (const char *c = rel; *c;) {
		size_t len = strcspn(c, "/");
		if (len == 2 && c[0] == '.' && c[1] == '.')
			return 0;
		c += len;
		if (*c == '/')
			c++;
	}
	return 1;
}

/* Splits a CSV line in place at commas; returns the number of fields. */
static int csv_fields(char *line, char **f, int max, int *cols)
{
	int n = 0;
	char *c = line;
	while (n < max) {
		while (*c == ' ' || *c == '\t')
			c++;
		f[n] = c;
		cols[n] = (int)(c - line) + 1;
		n++;
		char *comma = strchr(c, ',');
		char *end = comma ? comma : c + strlen(c);
		while (end > c && (end[-1] == ' ' || end[-1] == '\t'))
			end--;
		if (!comma) {
			*end = '\0';
			return n;
		}
		*end = '\0';
		c = comma + 1;
	}
	return n + 1; /* more than max */
}

/* One line of f into buf (size bytes, NUL-terminated), NUL bytes in it
 * kept: its length in bytes, -1 at the end of the file, or size if the line
 * does not fit (the rest left unread). */
static long read_line(FILE *f, char *buf, size_t size)
{
	size_t n = 0;
	int c = EOF;
	while (n + 1 < size && (c = getc(f)) != EOF) {
		buf[n++] = (char)c;
		if (c == '\n')
			break;
	}
	buf[n] = '\0';
	if (n == 0 && c == EOF)
		return -1;
	if (n + 1 == size && buf[n - 1] != '\n' && (c = getc(f)) != EOF)
		return (long)size;
	return (long)n;
}

/* The stiffness map from a CSV file beside the scene: one line per row
 * (iy = 0 first), columns comma-separated values; blank lines and lines
 * starting with # are skipped. */
static int map_csv(scene_walk *w, struct fy_node *n, struct fy_node *key, double *out)
{
	const bsim_lattice_def *l = &w->s->lattice;
	const char *rel =
	        n && fy_node_is_scalar(n) && !bsim_ydoc_is_null(n) ? fy_node_get_scalar0(n) : NULL;
	if (!rel || !name_beside(rel))
		return bsim_ydoc_expected(
		        w->d, n, key, "lattice.stiffness_file",
		        "a CSV file name relative to the scene's directory (no '..')", w->err);
	if (strlen(rel) >= sizeof w->s->lattice.stiffness_file)
		return bsim_ydoc_expected(w->d, n, key, "lattice.stiffness_file",
		                          "a shorter file name", w->err);
	char path[1300];
	if (csv_path(w->d->path, rel, path, sizeof path))
		return bsim_ydoc_expected(w->d, n, key, "lattice.stiffness_file", "a shorter path",
		                          w->err);
	/* Without blocking, and checked before the first read: a FIFO would
	 * wait for a writer for ever, a directory fails only at the read. */
	struct stat st;
	int fd = bsim_file_open_checked(path, &st);
	if (fd < 0)
		return bsim_ydoc_fail(w->d, n, key, "lattice.stiffness_file", w->err,
		                      "expected a readable CSV file, got %s (%s)", path,
		                      strerror(errno));
	if (!S_ISREG(st.st_mode)) {
		close(fd);
		return bsim_ydoc_fail(w->d, n, key, "lattice.stiffness_file", w->err,
		                      "expected a regular CSV file, got %s (%s)", path,
		                      bsim_file_kind(&st));
	}
	FILE *f = fdopen(fd, "r");
	if (!f) {
		close(fd);
		return bsim_error_set(w->err, BSIM_EFAIL, "%s: out of memory", path);
	}
	snprintf(w->s->lattice.stiffness_file, sizeof w->s->lattice.stiffness_file, "%s", rel);
	char line[8192];
	long got;
	int lineno = 0, iy = 0, rc = BSIM_OK;
	int max = l->columns;
	char **fields = malloc((size_t)(max + 1) * sizeof *fields);
	int *cols = malloc((size_t)(max + 1) * sizeof *cols);
	if (!fields || !cols)
		rc = bsim_error_set(w->err, BSIM_EFAIL, "%s: out of memory", path);
	while (rc == BSIM_OK && (got = read_line(f, line, sizeof line)) >= 0) {
		lineno++;
		/* A NUL would end the line's text early, unseen. */
		const char *nul = memchr(line, '\0',
		                         got == (long)sizeof line ? sizeof line - 1 : (size_t)got);
		if (nul) {
			rc = bsim_error_set(
			        w->err, BSIM_EINPUT,
			        "%s:%d:%d: lattice.stiffness_file: expected text, got a "
			        "NUL byte",
			        path, lineno, (int)(nul - line) + 1);
			break;
		}
		if (got == (long)sizeof line) {
			rc = bsim_error_set(w->err, BSIM_EINPUT,
			                    "%s:%d: lattice.stiffness_file: expected lines shorter "
			                    "than %zu characters",
			                    path, lineno, sizeof line - 1);
			break;
		}
		line[strcspn(line, "\r\n")] = '\0';
		const char *first = line + strspn(line, " \t");
		if (*first == '\0' || *first == '#')
			continue;
		if (iy == l->rows) {
			rc = bsim_error_set(
			        w->err, BSIM_EINPUT,
			        "%s:%d: lattice.stiffness_file: expected %d rows (one per "
			        "iy, iy = 0 first), got more",
			        path, lineno, l->rows);
			break;
		}
		int given = 1;
		for (const char *c = line; *c; c++)
			given += *c == ',';
		if (given != l->columns) {
			rc = bsim_error_set(
			        w->err, BSIM_EINPUT,
			        "%s:%d: lattice.stiffness_file: expected %d values (one per "
			        "column, ix = %d .. %d), got %d",
			        path, lineno, l->columns, l->ix_min, l->ix_max, given);
			break;
		}
		int k = csv_fields(line, fields, max, cols);
		for (int c = 0; c < k && rc == BSIM_OK; c++) {
			char *end;
			errno = 0;
			double v = strtod(fields[c], &end);
			if (end == fields[c] || *end != '\0' || errno == ERANGE || !isfinite(v) ||
			    v < 0.0 || bsim_decimal_other_base(fields[c]))
				rc = bsim_error_set(w->err, BSIM_EINPUT,
				                    "%s:%d:%d: lattice.stiffness_file: expected a "
				                    "number >= 0 (N m/rad), got %.40s",
				                    path, lineno, cols[c],
				                    *fields[c] ? fields[c] : "nothing");
			out[iy * l->columns + c] = v;
		}
		iy++;
	}
	if (rc == BSIM_OK && ferror(f))
		rc = bsim_error_set(w->err, BSIM_EINPUT,
		                    "%s:%d: lattice.stiffness_file: read error: %s", path,
		                    lineno + 1, strerror(errno));
	if (rc == BSIM_OK && iy != l->rows)
		rc = bsim_error_set(w->err, BSIM_EINPUT,
		                    "%s:%d: lattice.stiffness_file: expected %d rows (one per iy, "
		                    "iy = 0 first), got %d",
		                    path, lineno, l->rows, iy);
	free(fields);
	free(cols);
	fclose(f);
	return rc;
}

static int lattice_protocol(scene_walk *w, struct fy_node *map)
{
	struct fy_node *k;
	struct fy_node *n = child(map, "protocol", &k);
	if (!n)
		return BSIM_OK;
	const char *t = bsim_ydoc_plain(n);
	if (t && !strcmp(t, "world"))
		w->s->lattice.protocol = BSIM_PROTOCOL_WORLD;
	else if (t && !strcmp(t, "essay"))
		w->s->lattice.protocol = BSIM_PROTOCOL_ESSAY;
	else
		return bsim_ydoc_expected(w->d, n, k, "lattice.protocol",
		                          "world (one world, every beam kept) or essay (only the "
		                          "active gate, reset on entry)",
		                          w->err);
	return BSIM_OK;
}

static int lattice_maps_read(scene_walk *w, struct fy_node *map, lattice_maps *m)
{
	const bsim_lattice_def *l = &w->s->lattice;
	size_t gates = (size_t)l->rows * (size_t)l->columns;
	static const char *const names[3] = {"stiffness", "stiffness_left", "stiffness_right"};
	double **dst[3] = {&m->gate, &m->left, &m->right};
	struct fy_node *kfile, *kmap;
	struct fy_node *file = child(map, "stiffness_file", &kfile);
	struct fy_node *gate_map = child(map, "stiffness", &kmap);
	if (file && gate_map)
		return bsim_ydoc_fail(w->d, file, kfile, "lattice.stiffness_file", w->err,
		                      "expected either stiffness or stiffness_file, not both");
	/* A per-gate map and a per-beam one give every beam twice: which one a
	 * reader of the scene meant is not for beamsim to guess. */
	for (int i = 1; i < 3 && (file || gate_map); i++) {
		struct fy_node *k;
		struct fy_node *n = child(map, names[i], &k);
		if (n)
			return bsim_ydoc_fail(w->d, n, k,
			                      i == 1 ? "lattice.stiffness_left"
			                             : "lattice.stiffness_right",
			                      w->err, "expected either %s or %s, not both",
			                      file ? "stiffness_file" : "stiffness", names[i]);
	}
	for (int i = 0; i < 3; i++) {
		struct fy_node *k;
		struct fy_node *n = child(map, names[i], &k);
		if (!n && !(i == 0 && file))
			continue;
		*dst[i] = malloc(gates * sizeof **dst[i]);
		if (!*dst[i])
			return bsim_error_set(w->err, BSIM_EFAIL, "%s: out of memory", w->d->path);
		int rc =
		        n ? map_walk(w, n, k, names[i], *dst[i]) : map_csv(w, file, kfile, *dst[i]);
		if (rc)
			return rc;
	}
	return BSIM_OK;
}

void bsim_scene_lattice_begin(bsim_scene *s)
{
	/* The gate's geometry at its defaults; what a file must give (columns,
	 * rows, the beam) starts at zero, the beam's inertia unset. */
	const bsim_lattice_def d = bsim_lattice_def_default();
	bsim_lattice_def *l = &s->lattice;
	memset(l, 0, sizeof *l);
	l->width = d.width;
	l->depth = d.depth;
	l->pivot_y = d.pivot_y;
	l->beam.inertia = NAN;
}

int bsim_scene_lattice_finish(scene_walk *w, struct fy_node *n, struct fy_node *key)
{
	bsim_scene *s = w->s;
	bsim_lattice_def *l = &s->lattice;
	int rc = lattice_range(w, n, key);
	if (rc)
		return rc;
	if (isnan(l->beam.inertia))
		l->beam.inertia = l->beam.mass * l->beam.length * l->beam.length / 3;
	if ((long)l->columns * l->rows > LATTICE_GATES_MAX) {
		struct fy_node *k;
		struct fy_node *rows = child(n, "rows", &k);
		return bsim_ydoc_fail(w->d, rows, k, "lattice.rows", w->err,
		                      "expected at most %d gates (columns x rows), got %d x %d",
		                      LATTICE_GATES_MAX, l->columns, l->rows);
	}
	rc = lattice_protocol(w, n);
	lattice_maps m = {0};
	if (!rc)
		rc = lattice_maps_read(w, n, &m);
	if (!rc) {
		double *left = m.left ? m.left : m.gate, *right = m.right ? m.right : m.gate;
		rc = bsim_lattice_build(s, left, right);
		if (rc == BSIM_EFAIL)
			bsim_error_set(w->err, BSIM_EFAIL, "%s: out of memory", w->d->path);
	}
	maps_free(&m);
	return rc;
}
