/* The cache of single-gate maps (beamsim/markov.h): a map's key, the text
 * of every input it depends on, and the map directory that holds maps
 * under the hash of their keys:
 *   DIR/map_HASH.key   the key text
 *   DIR/map_HASH.csv   entry,exit,count,...: the nonzero counts
 *   DIR/map_HASH.cost  the CPU time the map took to build
 *   DIR/map_HASH.hold.csv  entry,trial,exit,steps: each single gate's exit
 *                      and the time steps it spent in the gate (a map
 *                      without it has no holding times)
 *   DIR/map_START.after_GATE.csv  trial,start_exit,exit,steps: the gate
 *                      after the start (bsim_markov_next): map START's
 *                      start trials that left into a gate, each continued
 *                      in a gate of map GATE; and its .cost beside it
 *   DIR/markov.json    the def of the last build, for bsim_markov_load
 * A map is reused only if its .key file holds the whole key text, so a
 * hash collision never reuses a map either. */
#define _POSIX_C_SOURCE 200809L

#include "analysis/markov_internal.h"
#include "analysis/markov_kdtree.h"

#include <assert.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

#include "beamsim/backend_registry.h"
#include "beamsim/output.h"
#include "beamsim/version.h"
#include "store/outdir.h"
#include "util/atomic_file.h"
#include "util/csv_table.h"
#include "util/file_read.h"
#include "util/hash.h"
#include "util/json.h"
#include "util/yaml_doc.h"
#include "beamsim/limits.h"

/* The map file format; part of every key, so a new format never reads an
 * old map. */
#define MAP_FORMAT 1

/* The hash of a lattice's layout: its size and every gate's stiffness
 * pair, row 0 first. */
static uint64_t layout_hash(const bsim_scene *lattice)
{
	const bsim_lattice_def *l = &lattice->lattice;
	uint64_t h = HASH_FNV1A64_SEED;
	int size[2] = {l->columns, l->rows};
	h = bsim_hash_fnv1a64(size, sizeof size, h);
	for (int iy = 0; iy < l->rows; iy++)
		for (int ix = l->ix_min; ix <= l->ix_max; ix++)
			for (int side = 0; side < 2; side++) {
				double k = lattice->beams[bsim_lattice_beam(l, ix, iy, side)]
				                   .stiffness;
				h = bsim_hash_fnv1a64(&k, sizeof k, h);
			}
	return h;
}

const char *bsim_markov_entries_label(const bsim_markov_def *def, const bsim_scene *lattice,
                                      char *buf, size_t size)
{
	if (def->entries)
		return def->entries->id;
	int passes = def->self_passes, flow = def->self_entries == 2;
	if (!def->self_entries && strncmp(def->entries_id, "flow ", 5) == 0) {
		/* read back from markov.json: the field is the one predicted */
		flow = 1;
		passes = atoi(def->entries_id + 5);
	}
	if (flow && lattice)
		snprintf(buf, size, "flow %d field %016llx", passes,
		         (unsigned long long)layout_hash(lattice));
	else if (flow || def->self_entries)
		snprintf(buf, size, "%s %d", flow ? "flow" : "self", passes);
	else if (bsim_markov_def_trains(def))
		return bsim_markov_train_label(lattice, def, buf, size);
	else
		return def->entries_id[0] ? def->entries_id : "none";
	return buf;
}

/* The inputs the essay's model does not have, a line each where a scene
 * has them (so that the keys of the essay's maps stay what they were):
 * the body's shape and turning, contact friction, the forcing's model and
 * the effects that read the state. */
static void markov_key_extra(FILE *f, const bsim_scene *s)
{
	const bsim_body_def *b = &s->body;
	const bsim_effects_def *e = &s->effects;
	if (b->shape != BSIM_SHAPE_DISK || b->rotates || b->heading_deg != 90)
		fprintf(f,
		        "body shape %d length %.17g semi_axes %.17g %.17g heading_deg %.17g "
		        "angular_velocity %.17g inertia %.17g rotates %d\n",
		        (int)b->shape, b->length, b->semi_axes[0], b->semi_axes[1], b->heading_deg,
		        b->angular_velocity, b->inertia, b->rotates);
	if (s->contact.friction != 0)
		fprintf(f, "contact friction %.17g\n", s->contact.friction);
	if (e->has_random_force && e->random_model != BSIM_RANDOM_HELD)
		fprintf(f, "random model %d correlation_time %.17g\n", (int)e->random_model,
		        e->random_correlation_time);
	if (e->has_propulsion && e->propulsion_along != BSIM_ALONG_Y)
		fprintf(f, "propulsion along %d\n", (int)e->propulsion_along);
	if (e->has_drag)
		fprintf(f, "drag %.17g %.17g\n", e->drag_linear, e->drag_angular);
	if (e->has_oscillation)
		fprintf(f, "oscillation %.17g %.17g %.17g\n", e->osc_amplitude, e->osc_frequency,
		        e->osc_phase);
	if (e->has_ground_friction) /* the model tells a body that turns apart */
		fprintf(f, "ground_friction %.17g %.17g%s\n", e->ground_mu, e->ground_g,
		        !b->rotates                                ? ""
		        : e->ground_model == BSIM_FRICTION_COUPLED ? " coupled"
		                                                   : " decoupled");
}

/* Every input of a map, a line each, numbers to the last bit (%.17g). */
char *bsim_markov_key_text(const bsim_scene *lattice, const bsim_markov_def *def,
                           const bsim_backend *be, const bsim_options *opts, const double k[2])
{
	markov_gate_scene g;
	bsim_markov_gate_scene_init(&g, lattice, k);
	const bsim_scene *s = &g.s;
	char *text = NULL;
	size_t size = 0;
	FILE *f = open_memstream(&text, &size);
	if (!f)
		return NULL;
	fprintf(f, "beamsim-markov-map %d\nbeamsim %s\nbackend %s ", MAP_FORMAT, BSIM_VERSION,
	        be->name);
	bsim_output_backend_options(f, be, opts);
	fprintf(f, "\ngate width %.17g depth %.17g\n", lattice->lattice.width,
	        lattice->lattice.depth);
	for (int i = 0; i < 2; i++) {
		const bsim_beam_def *b = &s->beams[i];
		fprintf(f,
		        "beam %d pivot %.17g %.17g rest_angle_deg %.17g length %.17g mass %.17g "
		        "inertia %.17g stiffness %.17g damping %.17g\n",
		        i + 1, b->pivot[0], b->pivot[1], b->rest_angle_deg, b->length, b->mass,
		        b->inertia, b->stiffness, b->damping);
	}
	fprintf(f, "body mass %.17g radius %.17g start %.17g %.17g velocity %.17g %.17g\n",
	        s->body.mass, s->body.radius, s->body.start[0], s->body.start[1],
	        s->body.velocity[0], s->body.velocity[1]);
	fprintf(f, "contact %.17g %.17g %.17g\n", s->contact.restitution,
	        s->contact.tip_restitution, s->contact.rest_threshold);
	fprintf(f, "effects propulsion %d %.17g random %d %.17g %.17g\n", s->effects.has_propulsion,
	        s->effects.propulsion_force, s->effects.has_random_force,
	        s->effects.random_magnitude, s->effects.random_frequency);
	markov_key_extra(f, s);
	fprintf(f, "dt %.17g gate_steps %d max_steps %d\n", s->dt, s->gate_steps, s->max_steps);
	char label[64];
	fprintf(f, "entries %s\n", bsim_markov_entries_label(def, lattice, label, sizeof label));
	fprintf(f, "bins %d %d %d %.17g\ntrials %d\nseed %llu\n", def->bins.n_pos,
	        def->bins.n_speed, def->bins.n_dir, def->bins.v_max, def->trials,
	        (unsigned long long)def->seed);
	/* only where it differs: a map of equal trials keeps the key it had */
	if (bsim_markov_def_start_trials(def) != def->trials)
		fprintf(f, "start_trials %d\n", bsim_markov_def_start_trials(def));
	if (fclose(f) != 0) {
		free(text);
		return NULL;
	}
	return text;
}

uint64_t bsim_markov_key(const char *key_text)
{
	return bsim_hash_fnv1a64(key_text, strlen(key_text), HASH_FNV1A64_SEED);
}

int bsim_markov_key_same(const char *path, const char *key_text)
{
	size_t len = strlen(key_text);
	file_text t;
	bsim_error ignored;
	if (bsim_file_read(path, "a map key", (double)len, NULL, &t, &ignored) != BSIM_OK)
		return 0;
	int same = t.len == len && memcmp(t.text, key_text, len) == 0;
	bsim_file_text_free(&t);
	return same;
}

/* Whether line [a, a + n) of one key text is a line of the other text t. */
static int key_has_line(const char *t, const char *a, size_t n)
{
	for (const char *c = t; *c;) {
		const char *e = strchr(c, '\n');
		size_t len = e ? (size_t)(e - c) : strlen(c);
		if (len == n && memcmp(c, a, n) == 0)
			return 1;
		c += len + (e != NULL);
	}
	return 0;
}

/* The lines of a not in b, "; "-separated, each quoted, into buf (at most
 * size); their number. */
static int key_lines_not_in(const char *a, const char *b, char *buf, size_t size)
{
	int n = 0;
	size_t used = 0;
	buf[0] = '\0';
	for (const char *c = a; *c;) {
		const char *e = strchr(c, '\n');
		size_t len = e ? (size_t)(e - c) : strlen(c);
		if (len && !key_has_line(b, c, len)) {
			int w = snprintf(buf + used, size - used, "%s'%.*s'", n ? "; " : "",
			                 (int)len, c);
			used = w > 0 && used + (size_t)w < size ? used + (size_t)w : used;
			n++;
		}
		c += len + (e != NULL);
	}
	return n;
}

void bsim_markov_key_nearest(const char *dir, const char *prefix, const char *want, char *buf,
                             size_t size)
{
	buf[0] = '\0';
	const size_t plen = strlen(prefix);
	DIR *d = opendir(dir);
	if (!d)
		return;
	int best = INT_MAX;
	const struct dirent *e;
	while ((e = readdir(d))) {
		size_t len = strlen(e->d_name);
		if (len != plen + 20 || strncmp(e->d_name, prefix, plen) != 0 ||
		    strcmp(e->d_name + plen + 16, ".key") != 0)
			continue;
		char path[BSIM_PATH_MAX];
		snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
		file_text t;
		bsim_error ignored;
		if (bsim_file_read(path, "a key", 65536.0, NULL, &t, &ignored) != BSIM_OK)
			continue;
		char has[320], wants[320];
		int n = key_lines_not_in(t.text, want, has, sizeof has) +
		        key_lines_not_in(want, t.text, wants, sizeof wants);
		if (n < best) {
			best = n;
			snprintf(buf, size,
			         "the nearest %s there, %s, has %s where this one needs %s",
			         strcmp(prefix, "map_") == 0 ? "map" : "training field", e->d_name,
			         has, wants);
		}
		bsim_file_text_free(&t);
	}
	closedir(d);
}

/* A map's file beside its key, or 0 with *absent if there is none. */
static int map_file(const char *dir, const bsim_markov_map *m, const char *ext, double max_bytes,
                    file_text *t, int *absent, bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	struct stat st;
	snprintf(path, sizeof path, "%s/map_%016llx.%s", dir, (unsigned long long)m->key, ext);
	*absent = lstat(path, &st) != 0 && errno == ENOENT;
	if (*absent)
		return BSIM_OK;
	int rc = bsim_file_read(path, "a map file", max_bytes, NULL, t, err);
	if (rc == BSIM_OK && strcmp(ext, "csv") == 0 &&
	    (rc = bsim_csv_text_check(path, t->text, t->len, err)) != BSIM_OK)
		bsim_file_text_free(t);
	return rc;
}

/* One row of a map's CSV, "entry,exit,count,entry_edge,exit_edge,p", into
 * v (entry, exit, count) and *p; the name of the first bad field, or NULL. */
static const char *map_row(char *line, const bsim_markov_map *m, long v[3], double *p,
                           const char **got)
{
	static const char *const field[6] = {"entry",      "exit",      "count",
	                                     "entry_edge", "exit_edge", "p"};
	char *f[6];
	int n = 0;
	for (char *c = line; n < 6; c++) {
		f[n++] = c;
		c = strchr(c, ',');
		if (!c)
			break;
		*c = '\0';
	}
	*got = "nothing";
	if (n < 6)
		return field[n];
	*got = f[5];
	if (strchr(f[5], ','))
		return "p";
	for (int i = 0; i < 3; i++) {
		*got = f[i];
		char *end;
		errno = 0;
		v[i] = strtol(f[i], &end, 10);
		long lo = i < 2 ? 0 : 1,
		     hi = i < 2 ? m->n_bins - 1 : bsim_markov_bin_trials(m, (int)v[0]);
		if (end == f[i] || *end || errno || v[i] < lo || v[i] > hi)
			return field[i];
	}
	*got = "nothing";
	if (!*f[3])
		return field[3];
	if (!*f[4])
		return field[4];
	*got = f[5];
	char *end;
	*p = strtod(f[5], &end);
	/* written as count / trials to 9 digits */
	if (end == f[5] || *end || !isfinite(*p) || *p < 0.0 || *p > 1.0 ||
	    fabs(*p - (double)v[2] / bsim_markov_bin_trials(m, (int)v[0])) > 1e-8)
		return "p";
	return NULL;
}

/* The line after *nl (a text checked by bsim_csv_text_check: every line
 * ends in one), four integers "a,b,c,d", into v; *nl moves to its end and
 * *lineno counts it. 0, or 1 if it is not four integers. */
static int row_of_four(char **nl, long *lineno, long v[4])
{
	char *line = *nl + 1, *end = line;
	(*lineno)++;
	if (!(*nl = strchr(line, '\n')))
		return 1;
	**nl = '\0';
	for (int k = 0; k < 4; k++) {
		errno = 0;
		v[k] = strtol(line, &end, 10);
		if (end == line || errno || *end != (k < 3 ? ',' : '\0'))
			return 1;
		line = end + 1;
	}
	return 0;
}

static const char HOLD_HEADER[] = "entry,trial,exit,steps";

/* map_HASH.hold.csv into m->hold_exit and m->hold_steps (m->counts read):
 * 1 if there, 0 if absent, -1 with err naming the line if malformed or if
 * its exits do not count up to the map's counts. */
static int hold_read(const char *dir, bsim_markov_map *m, bsim_error *err)
{
	const int nb = m->n_bins, T = m->trials;
	const long units = bsim_markov_map_units(m);
	file_text t;
	int absent = 0;
	/* a row is at most four integers of 11 characters */
	if (map_file(dir, m, "hold.csv", ((double)units + 1.0) * 48.0, &t, &absent, err) != BSIM_OK)
		return -1;
	if (absent)
		return 0;
	int *ex = malloc((size_t)units * sizeof *ex), *st = malloc((size_t)units * sizeof *st);
	char *line = t.text, *nl = strchr(line, '\n');
	long u = 0, lineno = 1;
	int bad = !ex || !st || !nl || (*nl = '\0', strcmp(line, HOLD_HEADER) != 0);
	while (!bad && u < units) {
		long v[4];
		const int a = bsim_markov_unit_bin(m, u);
		bad = row_of_four(&nl, &lineno, v) || v[0] != a ||
		      v[1] != u - bsim_markov_bin_first(m, a) || v[2] < 0 || v[2] >= nb ||
		      v[3] < 1 || v[3] > INT_MAX;
		if (!bad) {
			ex[u] = (int)v[2];
			st[u] = (int)v[3];
			u++;
		}
	}
	if (!bad && *(nl + 1))
		bad = 1, lineno++;
	/* the same single gates as the counts */
	if (!bad) {
		bsim_markov_map held = *m;
		held.count_first = held.count_exit = held.count_n = NULL;
		bad = bsim_markov_counts_of_exits(&held, ex) != 0 ? 3
		      : !bsim_markov_counts_equal(&held, m)       ? 2
		                                                  : 0;
		bsim_markov_counts_free(&held);
	}
	bsim_file_text_free(&t);
	if (bad) {
		free(ex);
		free(st);
		char path[BSIM_PATH_MAX];
		snprintf(path, sizeof path, "%s/map_%016llx.hold.csv", dir,
		         (unsigned long long)m->key);
		if (bad == 3)
			bsim_error_set(err, BSIM_EFAIL, "%s: out of memory", path);
		else if (bad == 2)
			bsim_error_set(
			        err, BSIM_EINPUT,
			        "%s: its exits do not count up to the map's counts (map_%016llx."
			        "csv): rebuild the maps with beamsim markov build",
			        path, (unsigned long long)m->key);
		else
			bsim_error_set(
			        err, BSIM_EINPUT,
			        "%s:%ld: expected a row entry,trial,exit,steps (exit 0 to %d, "
			        "steps >= 1) for the start's %d trials and each of the other %d "
			        "bins x %d trials in order",
			        path, lineno, nb - 1, m->start_trials, nb - 1, T);
		return -1;
	}
	m->hold_exit = ex;
	m->hold_steps = st;
	return 1;
}

/* map_HASH.EXT (m's key), "cpu_seconds S" and "steps N", a line each
 * (steps absent in maps built before it): what a build cost, 0 if the
 * file is absent; BSIM_EINPUT naming the file if malformed. */
static int cost_read(const char *dir, const bsim_markov_map *m, const char *ext, double *cost,
                     long long *steps, bsim_error *err)
{
	file_text t;
	int absent = 0;
	*cost = 0.0;
	*steps = 0;
	if (map_file(dir, m, ext, 256.0, &t, &absent, err) != BSIM_OK)
		return BSIM_EINPUT;
	if (absent)
		return BSIM_OK;
	char *end = NULL;
	if (strncmp(t.text, "cpu_seconds ", 12) == 0)
		*cost = strtod(t.text + 12, &end);
	int ok = end && end != t.text + 12 && (*end == '\n' || *end == '\0') && isfinite(*cost) &&
	         *cost >= 0.0;
	if (ok && *end == '\n' && end[1]) {
		char *s = end + 1, *e2 = NULL;
		errno = 0;
		if (strncmp(s, "steps ", 6) == 0 && s[6] >= '0' && s[6] <= '9')
			*steps = strtoll(s + 6, &e2, 10);
		ok = e2 && !errno && (*e2 == '\0' || (*e2 == '\n' && !e2[1]));
	}
	bsim_file_text_free(&t);
	if (ok)
		return BSIM_OK;
	return bsim_error_set(err, BSIM_EINPUT,
	                      "%s/map_%016llx.%s: expected \"cpu_seconds S\" (S >= 0 the CPU "
	                      "time of the build) and \"steps N\", a line each",
	                      dir, (unsigned long long)m->key, ext);
}

/* Whether a bin of map m of crossings may hold n single gates: n
 * crossings at least what they are topped up to, or the top-up of fewer. */
static int crossings_bin_holds(const bsim_markov_map *m, long n)
{
	if (bsim_markov_crossings_topped(m, n) <= n)
		return 1;
	const int per = m->per_crossing;
	return per > 0 && n % per == 0 && bsim_markov_crossings_topped(m, n / per) == n;
}

/* The bins of a map of crossings laid out from its CSV text (m's
 * bin_first set): each bin holds what its rows count, summed as far as
 * they read as numbers (the rows are checked after, against this). 0, or
 * -1 out of memory. */
static int crossings_layout_read(const char *text, bsim_markov_map *m)
{
	const int nb = m->n_bins;
	long *first = calloc((size_t)nb + 1, sizeof *first);
	if (!first)
		return -1;
	for (const char *c = strchr(text, '\n'); c && c[1]; c = strchr(c + 1, '\n')) {
		char *end;
		const long a = strtol(c + 1, &end, 10);
		const char *f = end && *end == ',' ? strchr(end + 1, ',') : NULL;
		const long n = f ? strtol(f + 1, &end, 10) : 0;
		if (a >= 0 && a < nb && n > 0 && n <= INT_MAX && *end == ',' &&
		    first[a + 1] <= INT_MAX - n)
			first[a + 1] += n;
	}
	for (int a = 0; a < nb; a++)
		first[a + 1] += first[a];
	free(m->bin_first);
	m->bin_first = first;
	return 0;
}

int bsim_markov_map_read(const char *dir, bsim_markov_map *m, bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	snprintf(path, sizeof path, "%s/map_%016llx.key", dir, (unsigned long long)m->key);
	if (!bsim_markov_key_same(path, m->key_text))
		return 0;
	snprintf(path, sizeof path, "%s/map_%016llx.csv", dir, (unsigned long long)m->key);
	/* At most a row per single gate (of crossings: per pair of bins), each
	 * well under 256 bytes. */
	double max_bytes = ((m->of_crossings ? (double)m->n_bins * m->n_bins
	                                     : (double)bsim_markov_map_units(m)) +
	                    1.0) *
	                   256.0;
	file_text t;
	int absent = 0;
	if (map_file(dir, m, "csv", max_bytes, &t, &absent, err) != BSIM_OK)
		return -1;
	if (absent)
		return 0;
	if (m->of_crossings && crossings_layout_read(t.text, m) != 0) {
		bsim_file_text_free(&t);
		bsim_error_set(err, BSIM_EFAIL, "%s: out of memory", path);
		return -1;
	}
	const int nb = m->n_bins;
	/* the cells as they come, a line each: cell[3 i ..] entry, exit, count */
	long *sum = calloc((size_t)nb, sizeof *sum), n = 0, room = 1024;
	int oom = 0;
	int *last = calloc((size_t)nb, sizeof *last);
	int *cell = malloc((size_t)room * 3 * sizeof *cell);
	char what[128];
	const char *bad = NULL;
	int lineno = 1;
	char *line = t.text, *nl = strchr(line, '\n');
	if (!sum || !last || !cell) {
		free(sum);
		free(last);
		free(cell);
		bsim_file_text_free(&t);
		bsim_error_set(err, BSIM_EFAIL, "%s: out of memory", path);
		return -1;
	}
	if (!nl || (*nl = '\0', strcmp(line, "entry,exit,count,entry_edge,exit_edge,p") != 0)) {
		bad = "header";
		snprintf(what, sizeof what, "entry,exit,count,entry_edge,exit_edge,p");
	}
	while (!bad && *(line = nl + 1)) {
		lineno++;
		nl = strchr(line, '\n'); /* every line has one: bsim_csv_text_check */
		*nl = '\0';
		long v[3];
		double p;
		const char *got = "";
		bad = map_row(line, m, v, &p, &got);
		if (bad && strcmp(bad, "count") == 0)
			snprintf(what, sizeof what, "a count of trials 1 to %d, got %.20s",
			         bsim_markov_bin_trials(m, (int)v[0]), got);
		else if (bad && strcmp(bad, "p") == 0)
			snprintf(what, sizeof what,
			         "a probability in [0, 1], count / %d trials, got %.20s",
			         bsim_markov_bin_trials(m, (int)v[0]), got);
		else if (bad && strstr(bad, "_edge"))
			snprintf(what, sizeof what, "the name of a bin, got %.20s", got);
		else if (bad)
			snprintf(what, sizeof what, "a bin 0 to %d, got %.20s", nb - 1, got);
		else if (n == bsim_markov_map_units(m)) { /* each row counts one at least */
			bad = "count";
			snprintf(what, sizeof what, "at most a row per single gate, %ld",
			         bsim_markov_map_units(m));
		} else {
			if (n == room) {
				int *more = realloc(cell, (size_t)room * 2 * 3 * sizeof *cell);
				if (!more) {
					oom = 1;
					break;
				}
				cell = more;
				room *= 2;
			}
			for (int i = 0; i < 3; i++)
				cell[3 * n + i] = (int)v[i];
			n++;
			sum[v[0]] += v[2];
			last[v[0]] = lineno;
		}
	}
	long again = -1;
	const int cells = bad || oom ? -oom : bsim_markov_counts_of_cells(m, n, cell, &again);
	if (cells == 1) { /* at the later line of the two, after the header */
		bad = "exit";
		snprintf(what, sizeof what, "each entry,exit pair once, got %d,%d again",
		         cell[3 * again], cell[3 * again + 1]);
		lineno = (int)again + 2;
	}
	free(cell);
	if (cells < 0) {
		free(sum);
		free(last);
		bsim_file_text_free(&t);
		bsim_error_set(err, BSIM_EFAIL, "%s: out of memory", path);
		return -1;
	}
	/* Every entry bin ran the map's trials, each ending somewhere; a map
	 * of crossings holds its crossings or what they are topped up to a
	 * bin, the start start_trials. */
	for (int a = 0; !bad && m->of_crossings && a < nb; a++)
		if (a == 0 ? sum[a] != m->start_trials : !crossings_bin_holds(m, sum[a])) {
			bad = "count";
			lineno = last[a] ? last[a] : lineno;
			if (a == 0)
				snprintf(what, sizeof what,
				         "the counts of entry bin 0 to sum to the start's %d "
				         "trials, got %ld",
				         m->start_trials, sum[a]);
			else if (m->per_crossing > 0)
				snprintf(what, sizeof what,
				         "the counts of entry bin %d to sum to the map's crossings "
				         "topped up to %d trials (%d a crossing), got %ld",
				         a, m->trials, m->per_crossing, sum[a]);
			else
				snprintf(what, sizeof what,
				         "the counts of entry bin %d to sum to the map's crossings "
				         "topped up to %d trials, got %ld",
				         a, m->trials, sum[a]);
		}
	for (int a = 0; !bad && a < nb; a++)
		if (sum[a] != bsim_markov_bin_trials(m, a)) {
			bad = "count";
			lineno = last[a] ? last[a] : lineno;
			snprintf(
			        what, sizeof what,
			        "the counts of entry bin %d to sum to the map's %d trials, got %ld",
			        a, bsim_markov_bin_trials(m, a), sum[a]);
		}
	free(sum);
	free(last);
	bsim_file_text_free(&t);
	if (bad) {
		bsim_markov_counts_free(m);
		bsim_error_set(err, BSIM_EINPUT, "%s:%d: %s: expected %s", path, lineno, bad, what);
		return -1;
	}
	/* What the map cost when it was built; a map without the file cost
	 * nothing known. */
	if (cost_read(dir, m, "cost", &m->cost, &m->steps, err) != BSIM_OK)
		return -1;
	free(m->hold_exit);
	free(m->hold_steps);
	m->hold_exit = m->hold_steps = NULL;
	return hold_read(dir, m, err) < 0 ? -1 : 1;
}

int bsim_markov_map_write(const char *stage, const bsim_markov_map *m, const bsim_markov_bins *b,
                          bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	snprintf(path, sizeof path, "%s/map_%016llx.key", stage, (unsigned long long)m->key);
	bsim_atomic_file o;
	if (bsim_atomic_file_open(&o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	fputs(m->key_text, o.f);
	if (bsim_atomic_file_commit(&o, err) != BSIM_OK)
		return BSIM_EFAIL;
	snprintf(path, sizeof path, "%s/map_%016llx.csv", stage, (unsigned long long)m->key);
	if (bsim_atomic_file_open(&o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	fputs("entry,exit,count,entry_edge,exit_edge,p\n", o.f);
	for (int a = 0; a < m->n_bins; a++) {
		const int first = m->count_first[a], end = m->count_first[a + 1];
		long total = 0;
		for (int i = first; i < end; i++)
			total += m->count_n[i];
		for (int i = first; i < end; i++) {
			const int x = m->count_exit[i], c = m->count_n[i];
			fprintf(o.f, "%d,%d,%d,%s,%s,%.9g\n", a, x, c, bsim_markov_bin_edge(b, a),
			        x == 0 ? "stuck" : bsim_markov_bin_edge(b, x), (double)c / total);
		}
	}
	if (bsim_atomic_file_commit(&o, err) != BSIM_OK)
		return BSIM_EFAIL;
	/* What the map cost, for the break-even of building it. */
	snprintf(path, sizeof path, "%s/map_%016llx.cost", stage, (unsigned long long)m->key);
	if (bsim_atomic_file_open(&o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	fprintf(o.f, "cpu_seconds %.6g\nsteps %lld\n", m->cost, m->steps);
	if (bsim_atomic_file_commit(&o, err) != BSIM_OK)
		return BSIM_EFAIL;
	if (!m->hold_exit)
		return BSIM_OK;
	/* Each single gate's exit and holding time, for the time to the
	 * outcome. */
	snprintf(path, sizeof path, "%s/map_%016llx.hold.csv", stage, (unsigned long long)m->key);
	if (bsim_atomic_file_open(&o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	fprintf(o.f, "%s\n", HOLD_HEADER);
	for (long u = 0; u < bsim_markov_map_units(m); u++) {
		const int a = bsim_markov_unit_bin(m, u);
		fprintf(o.f, "%d,%ld,%d,%d\n", a, u - bsim_markov_bin_first(m, a), m->hold_exit[u],
		        m->hold_steps[u]);
	}
	return bsim_atomic_file_commit(&o, err);
}

static const char NEXT_HEADER[] = "trial,start_exit,exit,steps";

/* What follows "map_START." in the name of a gate after the start's file
 * (bsim_markov_next_name), as map_file and cost_read take it. */
static void next_ext(char *buf, size_t size, const bsim_markov_map *start,
                     const bsim_markov_map *gate, int after, const char *what)
{
	if (after < start->start_trials)
		snprintf(buf, size, "after_%016llx.first%d.%s", (unsigned long long)gate->key,
		         after, what);
	else
		snprintf(buf, size, "after_%016llx.%s", (unsigned long long)gate->key, what);
}

void bsim_markov_next_name(char *buf, size_t size, const bsim_markov_map *start,
                           const bsim_markov_map *gate, int after, const char *what)
{
	char ext[64];
	next_ext(ext, sizeof ext, start, gate, after, what);
	snprintf(buf, size, "map_%016llx.%s", (unsigned long long)start->key, ext);
}

int bsim_markov_next_write(const char *stage, const bsim_markov_next *x,
                           const bsim_markov_map *start, const bsim_markov_map *gate,
                           bsim_error *err)
{
	char path[BSIM_PATH_MAX], name[96];
	bsim_markov_next_name(name, sizeof name, start, gate, x->trials, "csv");
	snprintf(path, sizeof path, "%s/%s", stage, name);
	bsim_atomic_file o;
	if (bsim_atomic_file_open(&o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	fprintf(o.f, "%s\n", NEXT_HEADER);
	for (int t = 0; t < x->trials; t++)
		if (x->exit[t] >= 0)
			fprintf(o.f, "%d,%d,%d,%d\n", t, start->hold_exit[t], x->exit[t],
			        x->steps[t]);
	if (bsim_atomic_file_commit(&o, err) != BSIM_OK)
		return BSIM_EFAIL;
	bsim_markov_next_name(name, sizeof name, start, gate, x->trials, "cost");
	snprintf(path, sizeof path, "%s/%s", stage, name);
	if (bsim_atomic_file_open(&o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	fprintf(o.f, "cpu_seconds %.6g\nsteps %lld\n", x->cost, x->steps_total);
	return bsim_atomic_file_commit(&o, err);
}

int bsim_markov_next_read(const char *dir, bsim_markov_next *x, const bsim_markov_map *start,
                          const bsim_markov_map *gate, bsim_error *err)
{
	/* the first T of the start's trials, as x->trials says */
	const int T = x->trials, nb = gate->n_bins;
	assert(T >= 1 && T <= start->start_trials);
	char ext[80];
	next_ext(ext, sizeof ext, start, gate, T, "csv");
	file_text t;
	int absent = 0;
	/* a row is at most four integers of 11 characters */
	if (map_file(dir, start, ext, ((double)T + 1.0) * 48.0, &t, &absent, err) != BSIM_OK)
		return -1;
	if (absent)
		return 0;
	char path[BSIM_PATH_MAX];
	snprintf(path, sizeof path, "%s/map_%016llx.%s", dir, (unsigned long long)start->key, ext);
	if (bsim_csv_text_check(path, t.text, t.len, err) != BSIM_OK) {
		bsim_file_text_free(&t);
		return -1;
	}
	free(x->exit);
	free(x->steps);
	x->exit = malloc((size_t)T * sizeof *x->exit);
	x->steps = malloc((size_t)T * sizeof *x->steps);
	char *line = t.text, *nl = strchr(line, '\n');
	long lineno = 1;
	int bad = !x->exit || !x->steps || !start->hold_exit || !nl ||
	          (*nl = '\0', strcmp(line, NEXT_HEADER) != 0);
	/* a row for each start trial that left into a gate, in order, its
	 * start exit the start map's */
	for (int u = 0; !bad && u < T; u++) {
		x->exit[u] = -1;
		x->steps[u] = 0;
		if (start->hold_exit[u] == 0)
			continue;
		long v[4];
		bad = row_of_four(&nl, &lineno, v) || v[0] != u || v[1] != start->hold_exit[u] ||
		      v[2] < 0 || v[2] >= nb || v[3] < 1 || v[3] > INT_MAX;
		if (!bad) {
			x->exit[u] = (int)v[2];
			x->steps[u] = (int)v[3];
		}
	}
	if (!bad && *(nl + 1))
		bad = 1, lineno++;
	bsim_file_text_free(&t);
	if (bad) {
		bsim_error_set(err, BSIM_EINPUT,
		               "%s:%ld: expected a row trial,start_exit,exit,steps for each of "
		               "the first %d of the start's single gates of map_%016llx.hold.csv "
		               "that left into a gate, in order (start_exit as there, exit 0 to "
		               "%d, steps >= 1)",
		               path, lineno, T, (unsigned long long)start->key, nb - 1);
		return -1;
	}
	next_ext(ext, sizeof ext, start, gate, T, "cost");
	if (cost_read(dir, start, ext, &x->cost, &x->steps_total, err) != BSIM_OK)
		return -1;
	return 1;
}

/* markov.json's backend and its options: ", \"backend\": NAME, \"options\":
 * [\"KEY=VALUE\", ...]". */
static void def_engine_write(FILE *f, const bsim_backend *be, const bsim_options *opts)
{
	fputs(", \"backend\": ", f);
	bsim_json_string(f, be->name);
	fputs(", \"options\": [", f);
	for (int i = 0; opts && i < opts->n; i++) {
		char kv[128];
		snprintf(kv, sizeof kv, "%s=%s", opts->key[i], opts->value[i]);
		fputs(i ? ", " : "", f);
		bsim_json_string(f, kv);
	}
	fputc(']', f);
}

/* stage/markov.json opened as o, its name in path (which o keeps: it must
 * outlive o), its first fields written: the format and this beamsim's
 * version, which every build's holds. */
static int def_open_write(const char *stage, char path[BSIM_PATH_MAX], bsim_atomic_file *o,
                          bsim_error *err)
{
	snprintf(path, BSIM_PATH_MAX, "%s/markov.json", stage);
	if (bsim_atomic_file_open(o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	fprintf(o->f, "{\"format\": %d, \"beamsim_version\": \"%s\", ", MAP_FORMAT, BSIM_VERSION);
	return BSIM_OK;
}

int bsim_markov_def_write(const char *stage, const bsim_markov_def *def, const bsim_backend *be,
                          const bsim_options *opts, bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	bsim_atomic_file o;
	if (def_open_write(stage, path, &o, err) != BSIM_OK)
		return BSIM_EFAIL;
	fprintf(o.f, "\"bins\": {\"position\": %d, \"speed\": %d, \"direction\": %d, \"v_max\": ",
	        def->bins.n_pos, def->bins.n_speed, def->bins.n_dir);
	bsim_json_number(o.f, def->bins.v_max);
	fprintf(o.f, "}, \"trials\": %d, \"start_trials\": %d, \"seed\": ", def->trials,
	        bsim_markov_def_start_trials(def));
	bsim_json_u64(o.f, def->seed);
	def_engine_write(o.f, be, opts);
	fputs(", \"entries\": ", o.f);
	char label[64];
	bsim_json_string(o.f, bsim_markov_entries_label(def, NULL, label, sizeof label));
	fprintf(o.f, ", \"after_start\": %d", bsim_markov_def_after_start(def));
	if (bsim_markov_def_after_start(def))
		fprintf(o.f, ", \"after_trials\": %d", bsim_markov_def_after_trials(def));
	fputs("}\n", o.f);
	return bsim_atomic_file_commit(&o, err);
}

/* One field of markov.json: the node at slash-separated path, or an error
 * "FILE:LINE:COL: FIELD: expected WHAT, got ..." naming it. */
static struct fy_node *def_field(const ydoc *d, const char *path, const char *what, bsim_error *err)
{
	struct fy_node *root = fy_document_root(d->fyd);
	struct fy_node *n = root ? fy_node_by_path(root, path, -1, FYNWF_DONT_FOLLOW) : NULL;
	if (!n || bsim_ydoc_is_null(n)) {
		bsim_ydoc_expected(d, n, root, path + 1, what, err);
		return NULL;
	}
	return n;
}

static int def_int(const ydoc *d, const char *path, int lo, int hi, int *out, bsim_error *err)
{
	char what[64];
	snprintf(what, sizeof what, "an integer %d to %d", lo, hi);
	struct fy_node *n = def_field(d, path, what, err);
	long long v;
	if (!n)
		return BSIM_EINPUT;
	if (!bsim_ydoc_int64(n, &v) || v < lo || v > hi)
		return bsim_ydoc_expected(d, n, NULL, path + 1, what, err);
	*out = (int)v;
	return BSIM_OK;
}

/* A quoted string of markov.json, into buf. */
static int def_string(const ydoc *d, const char *path, char *buf, size_t size, bsim_error *err)
{
	struct fy_node *n = def_field(d, path, "a string", err);
	if (!n)
		return BSIM_EINPUT;
	const char *t = fy_node_is_scalar(n) ? fy_node_get_scalar0(n) : NULL;
	if (!t || strlen(t) >= size)
		return bsim_ydoc_expected(d, n, NULL, path + 1, "a short string", err);
	snprintf(buf, size, "%s", t);
	return BSIM_OK;
}

/* markov.json's seed, backend and its options, the fields every build
 * writes. */
static int def_engine_read(const ydoc *d, uint64_t *seed, char *backend, size_t size,
                           bsim_options *opts, bsim_error *err)
{
	/* above 2^53 written as a string (bsim_json_u64) */
	struct fy_node *n = def_field(d, "/seed", "a seed, an integer >= 0", err);
	const char *t = n && fy_node_is_scalar(n) ? fy_node_get_scalar0(n) : NULL;
	char *end = NULL;
	errno = 0;
	*seed = t && *t >= '0' && *t <= '9' ? strtoull(t, &end, 10) : 0;
	int rc = !n ? BSIM_EINPUT
	         : !end || *end || errno
	                 ? bsim_ydoc_expected(d, n, NULL, "seed", "a seed, an integer >= 0", err)
	                 : BSIM_OK;
	if (rc == BSIM_OK)
		rc = def_string(d, "/backend", backend, size, err);
	if (rc == BSIM_OK) {
		n = def_field(d, "/options", "a list of \"KEY=VALUE\"", err);
		if (!n)
			rc = BSIM_EINPUT;
		else if (!fy_node_is_sequence(n))
			rc = bsim_ydoc_expected(d, n, NULL, "options", "a list of \"KEY=VALUE\"",
			                        err);
		void *it = NULL;
		struct fy_node *kv;
		while (rc == BSIM_OK && (kv = fy_node_sequence_iterate(n, &it))) {
			t = fy_node_is_scalar(kv) ? fy_node_get_scalar0(kv) : NULL;
			rc = t ? bsim_options_add(opts, t, err)
			       : bsim_ydoc_expected(d, kv, n, "options", "\"KEY=VALUE\"", err);
		}
	}
	return rc;
}

/* dir/markov.json loaded into d, as its last build committed it, of
 * this beamsim and format; *is_nearest: 1 for a build of the walks'
 * ("method": "nearest"), 0 for maps (the method, or none: maps built
 * before there was another). Its name in path, which d borrows: path
 * must outlive d. */
static int def_open(const char *dir, char path[BSIM_PATH_MAX], ydoc *d, int *is_nearest,
                    bsim_error *err)
{
	/* The directory as its last build committed it: with a manifest,
	 * every map file has the size and CRC-32 listed there (a map's CSV
	 * put in another's place is refused here). */
	int has_manifest = 0;
	if (bsim_outdir_verify(dir, &has_manifest, err) != BSIM_OK) {
		/* A damaged map is not repaired here: its counts are gone. */
		if (err) {
			size_t len = strlen(err->msg);
			snprintf(err->msg + len, sizeof err->msg - len,
			         "; rebuild the maps with beamsim markov build EXPERIMENT --out %s",
			         dir);
		}
		return BSIM_EINPUT;
	}
	snprintf(path, BSIM_PATH_MAX, "%s/markov.json", dir);
	/* Without blocking: a FIFO there is refused by bsim_ydoc_load. */
	int probe = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
	if (probe < 0)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: cannot read (%s): not a map directory of beamsim markov "
		                      "build",
		                      path, strerror(errno));
	close(probe);
	int rc = bsim_ydoc_load(d, path, err);
	if (rc != BSIM_OK)
		return rc;
	int format = 0;
	char version[64] = "", method[16] = "maps";
	rc = def_int(d, "/format", MAP_FORMAT, MAP_FORMAT, &format, err);
	/* Maps of another version are another simulator's: the keys name the
	 * version too, so none would be found; saying so here names why. */
	if (rc == BSIM_OK)
		rc = def_string(d, "/beamsim_version", version, sizeof version, err);
	if (rc == BSIM_OK && strcmp(version, BSIM_VERSION) != 0)
		rc = bsim_ydoc_fail(
		        d, def_field(d, "/beamsim_version", "a string", err), NULL,
		        "beamsim_version", err,
		        "expected maps of this beamsim, %s, got maps built by beamsim %s "
		        "(build them again with beamsim markov build)",
		        BSIM_VERSION, version);
	if (rc == BSIM_OK &&
	    fy_node_by_path(fy_document_root(d->fyd), "/method", -1, FYNWF_DONT_FOLLOW) &&
	    (rc = def_string(d, "/method", method, sizeof method, err)) == BSIM_OK &&
	    strcmp(method, "maps") != 0 && strcmp(method, "nearest") != 0)
		rc = bsim_ydoc_fail(d, def_field(d, "/method", "a string", err), NULL, "method",
		                    err, "expected maps or nearest, got %s", method);
	*is_nearest = strcmp(method, "nearest") == 0;
	if (rc != BSIM_OK)
		bsim_ydoc_free(d);
	return rc;
}

/* markov.json's def, read as JSON (a YAML flow document) with libfyaml:
 * every field bsim_markov_def_write writes, each fault naming its file position
 * and field. */
int bsim_markov_def_read(const char *dir, bsim_markov_def *def, bsim_options *opts, bsim_error *err)
{
	memset(opts, 0, sizeof *opts);
	char path[BSIM_PATH_MAX];
	ydoc d;
	int nearest = 0;
	int rc = def_open(dir, path, &d, &nearest, err);
	if (rc != BSIM_OK)
		return rc;
	uint64_t seed = 0;
	char backend[64] = "", id[64] = "";
	if (nearest)
		rc = bsim_error_set(err, BSIM_EINPUT,
		                    "%s: a build of nearest-neighbour walks (markov build's "
		                    "default), not of maps: beamsim markov predict and validate "
		                    "--map %s walk over it",
		                    dir, dir);
	if (rc == BSIM_OK)
		rc = def_int(&d, "/bins/position", 1, 64, &def->bins.n_pos, err);
	if (rc == BSIM_OK)
		rc = def_int(&d, "/bins/speed", 1, 64, &def->bins.n_speed, err);
	if (rc == BSIM_OK)
		rc = def_int(&d, "/bins/direction", 1, 64, &def->bins.n_dir, err);
	if (rc == BSIM_OK) {
		/* 0: each lattice's from its propulsion (bsim_markov_bins_v_max) */
		static const char speed[] = "a speed > 0, m/s, or 0 (from the propulsion)";
		struct fy_node *n = def_field(&d, "/bins/v_max", speed, err);
		rc = !n ? BSIM_EINPUT
		     : bsim_ydoc_number(n, &def->bins.v_max) != YDOC_NUM_OK ||
		                     !(def->bins.v_max >= 0) || !isfinite(def->bins.v_max)
		             ? bsim_ydoc_expected(&d, n, NULL, "bins/v_max", speed, err)
		             : BSIM_OK;
	}
	if (rc == BSIM_OK)
		rc = def_int(&d, "/trials", 1, 1000000, &def->trials, err);
	/* absent in maps built before the start bin had trials of its own */
	def->start_trials = 0;
	if (rc == BSIM_OK &&
	    fy_node_by_path(fy_document_root(d.fyd), "/start_trials", -1, FYNWF_DONT_FOLLOW))
		rc = def_int(&d, "/start_trials", 1, 1000000, &def->start_trials, err);
	if (rc == BSIM_OK)
		rc = def_engine_read(&d, &seed, backend, sizeof backend, opts, err);
	if (rc == BSIM_OK)
		rc = def_string(&d, "/entries", id, sizeof id, err);
	/* absent in maps built before the gate after the start: without it */
	def->after_start = 0;
	if (rc == BSIM_OK &&
	    fy_node_by_path(fy_document_root(d.fyd), "/after_start", -1, FYNWF_DONT_FOLLOW))
		rc = def_int(&d, "/after_start", 0, 1, &def->after_start, err);
	/* absent in maps built before fewer were continued: every start trial
	 * (without the gate after the start: none to continue, the default) */
	def->after_trials = def->after_start ? 0 : -1;
	if (rc == BSIM_OK &&
	    fy_node_by_path(fy_document_root(d.fyd), "/after_trials", -1, FYNWF_DONT_FOLLOW))
		rc = def_int(&d, "/after_trials", 1, 1000000, &def->after_trials, err);
	bsim_ydoc_free(&d);
	if (rc != BSIM_OK)
		return rc;
	/* "train N": a training field of N trials, of each lattice's kinds */
	int train = 0, used = 0;
	def->train_trials = 0;
	def->train_crossings = 0;
	def->trials_per_crossing = 0;
	if (sscanf(id, "train %d%n", &train, &used) == 1 && train > 0 &&
	    (id[used] == '\0' || id[used] == ' ')) {
		def->train_trials = train;
		def->train_crossings = strncmp(id + used, " crossings", 10) == 0;
		/* "per N": topped up to N a crossing (before it: every bin) */
		if (def->train_crossings &&
		    sscanf(id + used + 10, " per %d", &def->trials_per_crossing) != 1)
			def->trials_per_crossing = 0;
	} else if (strcmp(id, "none") != 0)
		snprintf(def->entries_id, sizeof def->entries_id, "%s", id);
	def->seed = seed;
	def->backend = bsim_backend_find(backend, err);
	def->opts = opts;
	return def->backend ? BSIM_OK : BSIM_EINPUT;
}

int bsim_markov_nearest_def_write(const char *stage, const bsim_markov_nearest_def *def,
                                  const bsim_backend *be, const bsim_options *opts, bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	bsim_atomic_file o;
	if (def_open_write(stage, path, &o, err) != BSIM_OK)
		return BSIM_EFAIL;
	fprintf(o.f, "\"method\": \"nearest\", \"train\": %d, \"k\": %d, \"seed\": ", def->trials,
	        def->k);
	bsim_json_u64(o.f, def->seed);
	def_engine_write(o.f, be, opts);
	fputs("}\n", o.f);
	return bsim_atomic_file_commit(&o, err);
}

int bsim_markov_nearest_def_read(const char *dir, bsim_markov_nearest_def *def, bsim_options *opts,
                                 int *is_nearest, bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	ydoc d;
	int rc = def_open(dir, path, &d, is_nearest, err);
	if (rc != BSIM_OK || !*is_nearest) {
		if (rc == BSIM_OK)
			bsim_ydoc_free(&d);
		return rc;
	}
	memset(opts, 0, sizeof *opts);
	char backend[64] = "";
	rc = def_int(&d, "/train", 1, 100000000, &def->trials, err);
	if (rc == BSIM_OK)
		rc = def_int(&d, "/k", 1, BSIM_MARKOV_KDTREE_K_MAX, &def->k, err);
	if (rc == BSIM_OK)
		rc = def_engine_read(&d, &def->seed, backend, sizeof backend, opts, err);
	bsim_ydoc_free(&d);
	if (rc != BSIM_OK)
		return rc;
	def->backend = bsim_backend_find(backend, err);
	def->opts = opts;
	def->read_only = 1;
	return def->backend ? BSIM_OK : BSIM_EINPUT;
}

int bsim_markov_dir_method(const char *dir, bsim_markov_method *method, bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	ydoc d;
	int is_nearest = 0;
	const int rc = def_open(dir, path, &d, &is_nearest, err);
	if (rc != BSIM_OK)
		return rc;
	bsim_ydoc_free(&d);
	*method = is_nearest ? BSIM_MARKOV_METHOD_NEAREST : BSIM_MARKOV_METHOD_MAPS;
	return BSIM_OK;
}
