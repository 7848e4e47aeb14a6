/* The single-gate maps of the Markov chain (beamsim/markov.h): entry bins,
 * the single-gate trials that estimate where a gate entered in a bin is
 * left, and the cache of maps on disk keyed by everything they depend on. */
#define _POSIX_C_SOURCE 200809L

#include "beamsim/markov.h"

#include "model/lattice_crossing.h"

#include <errno.h>
#include <limits.h>
#include <gsl/gsl_rng.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "util/atomic_file.h"
#include "util/csv_table.h"
#include "beamsim/effects.h"
#include "beamsim/output.h"
#include "beamsim/schedule.h"
#include "beamsim/state.h"
#include "beamsim/trial.h"
#include "beamsim/version.h"
#include "util/json.h"
#include "store/session.h"
#include "util/yaml_doc.h"

/* The map file format; part of every key, so a new format never reads an
 * old map. */
#define MAP_FORMAT 1

static const double PI = 3.14159265358979323846;

bsim_markov_bins bsim_markov_bins_default(void)
{
	return (bsim_markov_bins){.n_pos = 4, .n_speed = 4, .n_dir = 3, .v_max = 40.0};
}

int bsim_markov_bins_count(const bsim_markov_bins *b)
{
	return 1 + 4 * b->n_pos * b->n_speed * b->n_dir;
}

bsim_markov_def bsim_markov_def_default(void)
{
	return (bsim_markov_def){.bins = bsim_markov_bins_default(), .trials = 200, .seed = 1};
}

/* ---- bins ------------------------------------------------------------------
 *
 * An edge's inward normal n and tangent t (gate frame), and the range of
 * the position along it:
 *   bottom  n = (0, 1),  t = (1, 0), pos = x in [-w/2, w/2]
 *   left    n = (1, 0),  t = (0, 1), pos = y in [0, d]
 *   right   n = (-1, 0), t = (0, 1), pos = y in [0, d]
 *   top     n = (0, -1), t = (1, 0), pos = x in [-w/2, w/2]
 * The direction is atan2(v.t, v.n), in [-pi/2, pi/2] for a body moving in. */

static void edge_frame(int edge, double n[2], double t[2])
{
	static const double N[4][2] = {{0, 1}, {1, 0}, {-1, 0}, {0, -1}};
	int e = edge - BSIM_EDGE_BOTTOM;
	n[0] = N[e][0];
	n[1] = N[e][1];
	t[0] = fabs(N[e][1]);
	t[1] = fabs(N[e][0]);
}

static void edge_range(int edge, const bsim_lattice_def *l, double *lo, double *hi)
{
	if (edge == BSIM_EDGE_BOTTOM || edge == BSIM_EDGE_TOP) {
		*lo = -0.5 * l->width;
		*hi = 0.5 * l->width;
	} else {
		*lo = 0.0;
		*hi = l->depth;
	}
}

static int clamp_bin(double u, int n)
{
	int i = (int)floor(u * n);
	return i < 0 ? 0 : i >= n ? n - 1 : i;
}

int bsim_markov_bin_of(const bsim_markov_bins *b, const bsim_lattice_def *l, int edge, double pos,
                       const double v[2])
{
	if (edge < BSIM_EDGE_BOTTOM || edge > BSIM_EDGE_TOP)
		return 0;
	double lo, hi, n[2], t[2];
	edge_range(edge, l, &lo, &hi);
	edge_frame(edge, n, t);
	int ip = clamp_bin((pos - lo) / (hi - lo), b->n_pos);
	double speed = hypot(v[0], v[1]);
	int is = clamp_bin(speed / b->v_max, b->n_speed);
	double a = atan2(v[0] * t[0] + v[1] * t[1], v[0] * n[0] + v[1] * n[1]);
	int id = clamp_bin((a + 0.5 * PI) / PI, b->n_dir);
	return 1 + (((edge - BSIM_EDGE_BOTTOM) * b->n_pos + ip) * b->n_speed + is) * b->n_dir + id;
}

/* A state drawn uniformly in entry bin (> 0): position on the edge, moved
 * inside by half a step's normal travel (the lattice sees an entry at the
 * end of the step that crossed). */
static void bin_sample(const bsim_markov_bins *b, const bsim_lattice_def *l, double h, int bin,
                       gsl_rng *rng, double x[2], double v[2])
{
	int k = bin - 1;
	int id = k % b->n_dir;
	k /= b->n_dir;
	int is = k % b->n_speed;
	k /= b->n_speed;
	int ip = k % b->n_pos;
	int edge = BSIM_EDGE_BOTTOM + k / b->n_pos;
	double lo, hi, n[2], t[2];
	edge_range(edge, l, &lo, &hi);
	edge_frame(edge, n, t);
	double pos = lo + (hi - lo) * (ip + gsl_rng_uniform(rng)) / b->n_pos;
	double speed = b->v_max * (is + gsl_rng_uniform(rng)) / b->n_speed;
	double a = -0.5 * PI + PI * (id + gsl_rng_uniform(rng)) / b->n_dir;
	v[0] = speed * (cos(a) * n[0] + sin(a) * t[0]);
	v[1] = speed * (cos(a) * n[1] + sin(a) * t[1]);
	double inset = 0.5 * fabs(v[0] * n[0] + v[1] * n[1]) * h + 1e-9;
	const double w2 = 0.5 * l->width, d = l->depth;
	switch (edge) {
	case BSIM_EDGE_BOTTOM:
		x[0] = pos;
		x[1] = inset;
		break;
	case BSIM_EDGE_TOP:
		x[0] = pos;
		x[1] = d - inset;
		break;
	case BSIM_EDGE_LEFT:
		x[0] = -w2 + inset;
		x[1] = pos;
		break;
	default:
		x[0] = w2 - inset;
		x[1] = pos;
		break;
	}
}

static const char *const edge_names[] = {"start", "bottom", "left", "right", "top"};

/* ---- observed entries ------------------------------------------------------ */

void bsim_markov_entries_free(bsim_markov_entries *e)
{
	if (!e)
		return;
	free(e->edge);
	free(e->pos);
	free(e->x);
	free(e->v);
	memset(e, 0, sizeof *e);
}

static uint64_t fnv1a_bytes(uint64_t h, const char *s, size_t n)
{
	for (size_t i = 0; i < n; i++) {
		h ^= (unsigned char)s[i];
		h *= 0x100000001b3ULL;
	}
	return h;
}

static int entries_push(bsim_markov_entries *e, int *cap, int edge, double pos, const double x[2],
                        const double v[2])
{
	if (e->n == *cap) {
		int nc = *cap ? 2 * *cap : 1024;
		int *ne = realloc(e->edge, (size_t)nc * sizeof *ne);
		if (ne)
			e->edge = ne;
		double *np = realloc(e->pos, (size_t)nc * sizeof *np);
		if (np)
			e->pos = np;
		double(*nx)[2] = realloc(e->x, (size_t)nc * sizeof *nx);
		if (nx)
			e->x = nx;
		double(*nv)[2] = realloc(e->v, (size_t)nc * sizeof *nv);
		if (nv)
			e->v = nv;
		if (!ne || !np || !nx || !nv)
			return -1;
		*cap = nc;
	}
	e->edge[e->n] = edge;
	e->pos[e->n] = pos;
	memcpy(e->x[e->n], x, sizeof e->x[0]);
	memcpy(e->v[e->n], v, sizeof e->v[0]);
	e->n++;
	return 0;
}

int bsim_markov_entries_load(const char *const *paths, int n, bsim_markov_entries *out,
                             bsim_error *err)
{
	memset(out, 0, sizeof *out);
	uint64_t h = 0xcbf29ce484222325ULL;
	int cap = 0, rc = BSIM_OK;
	static const char *const want[] = {"edge", "pos", "x", "y", "vx", "vy"};
	for (int f = 0; f < n && rc == BSIM_OK; f++) {
		char path[1200];
		struct stat st;
		if (stat(paths[f], &st) == 0 && S_ISDIR(st.st_mode))
			snprintf(path, sizeof path, "%s/gate_entries.csv", paths[f]);
		else
			snprintf(path, sizeof path, "%s", paths[f]);
		csv_table t;
		int col[6];
		if ((rc = csv_table_read(path, &t, err)) != BSIM_OK)
			break;
		rc = csv_table_require(&t, path, want, 6, col, err);
		for (long r = 0; rc == BSIM_OK && r < t.n_rows; r++) {
			const char *edge = csv_table_cell(&t, r, col[0]);
			int e = -1;
			for (int k = 0; k < 5; k++)
				if (strcmp(edge, edge_names[k]) == 0)
					e = k;
			double val[6];
			int bad = e < 0;
			for (int k = 1; k < 6 && !bad; k++)
				bad = csv_table_number(&t, r, col[k], &val[k]) != 0 ||
				      !isfinite(val[k]);
			if (bad) {
				rc = bsim_error_set(
				        err, BSIM_EINPUT,
				        "%s:%ld: expected an entry with edge (start, bottom, "
				        "left, right, top) and numbers pos, x, y, vx, vy",
				        path, r + 2);
				break;
			}
			if (e == BSIM_EDGE_START)
				continue;
			h = fnv1a_bytes(h, (const char *)&e, sizeof e);
			h = fnv1a_bytes(h, (const char *)(val + 1), 5 * sizeof val[0]);
			const double x[2] = {val[2], val[3]}, v[2] = {val[4], val[5]};
			if (entries_push(out, &cap, e, val[1], x, v))
				rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
		}
		csv_table_free(&t);
	}
	if (rc != BSIM_OK) {
		bsim_markov_entries_free(out);
		return rc;
	}
	snprintf(out->id, sizeof out->id, "%016llx %d", (unsigned long long)h, out->n);
	return BSIM_OK;
}

/* The entries of each bin: bin b's are idx[first[b] .. first[b + 1]). */
typedef struct entry_index {
	int *first, *idx;
} entry_index;

static int entry_index_init(entry_index *x, const bsim_markov_entries *e, const bsim_markov_bins *b,
                            const bsim_lattice_def *l)
{
	const int nb = bsim_markov_bins_count(b);
	x->first = calloc((size_t)nb + 1, sizeof *x->first);
	x->idx = malloc((size_t)(e && e->n ? e->n : 1) * sizeof *x->idx);
	int *bin = malloc((size_t)(e && e->n ? e->n : 1) * sizeof *bin);
	if (!x->first || !x->idx || !bin) {
		free(bin);
		return -1;
	}
	for (int i = 0; e && i < e->n; i++) {
		bin[i] = bsim_markov_bin_of(b, l, e->edge[i], e->pos[i], e->v[i]);
		x->first[bin[i] + 1]++;
	}
	for (int k = 0; k < nb; k++)
		x->first[k + 1] += x->first[k];
	int *fill = calloc((size_t)nb, sizeof *fill);
	if (!fill) {
		free(bin);
		return -1;
	}
	for (int i = 0; e && i < e->n; i++)
		x->idx[x->first[bin[i]] + fill[bin[i]]++] = i;
	free(fill);
	free(bin);
	return 0;
}

static void entry_index_free(entry_index *x)
{
	free(x->first);
	free(x->idx);
}

/* ---- one single gate ----------------------------------------------------- */

/* The gate of the lattice's start, moved to its own frame, as the essay's
 * protocol builds it on entry: its two beams at rest, with stiffness k. */
typedef struct gate_scene {
	bsim_scene s;
	bsim_beam_def beams[2];
} gate_scene;

static void gate_scene_init(gate_scene *g, const bsim_scene *lattice, const double k[2])
{
	const bsim_lattice_def *l = &lattice->lattice;
	int ix, iy;
	bsim_lattice_gate_at(lattice, lattice->body.start, &ix, &iy);
	g->s = *lattice;
	g->s.has_lattice = 0;
	g->s.n_beams = 2;
	g->s.beams = g->beams;
	for (int side = 0; side < 2; side++) {
		g->beams[side] = lattice->beams[bsim_lattice_beam(l, ix, iy, side)];
		g->beams[side].pivot[0] -= l->width * ix;
		g->beams[side].pivot[1] -= l->depth * iy;
		g->beams[side].stiffness = k[side];
		g->beams[side].initial_theta = 0.0;
		g->beams[side].initial_omega = 0.0;
	}
	g->s.body.start[0] -= l->width * ix;
	g->s.body.start[1] -= l->depth * iy;
}


/* The exit of a step from p0 inside the gate to s->x outside it: the entry
 * bin of the gate it enters (the boundary crossed first). */
static int exit_bin(const bsim_markov_bins *b, const bsim_lattice_def *l, const double p0[2],
                    const bsim_state *s)
{
	const double *p1 = s->x, w2 = 0.5 * l->width, d = l->depth;
	double fx = LATTICE_NO_CROSSING, fy = LATTICE_NO_CROSSING;
	int ex = 0, ey = 0;
	if (p1[0] < -w2) {
		fx = lattice_crossing(p0, p1, 0, -w2);
		ex = BSIM_EDGE_RIGHT; /* into the gate on the left, through its right edge */
	} else if (p1[0] >= w2) {
		fx = lattice_crossing(p0, p1, 0, w2);
		ex = BSIM_EDGE_LEFT;
	}
	if (p1[1] < 0.0) {
		fy = lattice_crossing(p0, p1, 1, 0.0);
		ey = BSIM_EDGE_TOP;
	} else if (p1[1] >= d) {
		fy = lattice_crossing(p0, p1, 1, d);
		ey = BSIM_EDGE_BOTTOM;
	}
	if (ex && (!ey || fx <= fy))
		return bsim_markov_bin_of(b, l, ex, p0[1] + fx * (p1[1] - p0[1]), s->v);
	return bsim_markov_bin_of(b, l, ey, p0[0] + fy * (p1[0] - p0[0]), s->v);
}

typedef struct gate_runner {
	bsim_state s0, s1;
	gsl_rng *rng;
	gate_scene g;
	const entry_index *ex; /* NULL: no observed entries */
} gate_runner;

/* One single-gate trial from entry bin `bin` (0: the start) with trial index
 * t: the exit bin, 0 if stuck; -1 with err on failure. */
static int gate_trial(gate_runner *r, const bsim_scene *lattice, const bsim_markov_def *def,
                      const bsim_backend *be, const bsim_options *opts, int bin, int t,
                      bsim_error *err)
{
	const bsim_lattice_def *l = &lattice->lattice;
	bsim_scene *s = &r->g.s;
	if (bin > 0) {
		gsl_rng_set(r->rng, bsim_schedule_seed_mix(def->seed ^ 0x6d61726b6f76ULL,
		                                           (uint64_t)bin, (uint64_t)t));
		const int lo = r->ex ? r->ex->first[bin] : 0,
		          hi = r->ex ? r->ex->first[bin + 1] : 0;
		if (hi > lo) { /* an observed entry of this bin */
			int i = r->ex->idx[lo + (int)gsl_rng_uniform_int(r->rng,
			                                                 (unsigned long)(hi - lo))];
			memcpy(s->body.start, def->entries->x[i], sizeof s->body.start);
			memcpy(s->body.velocity, def->entries->v[i], sizeof s->body.velocity);
		} else {
			bin_sample(&def->bins, l, s->dt, bin, r->rng, s->body.start,
			           s->body.velocity);
		}
	}
	bsim_world *w = NULL;
	if (be->create(s, opts, &w, err) != BSIM_OK)
		return -1;
	bsim_effects fx;
	if (bsim_effects_init(&fx, s,
	                      bsim_schedule_seed_mix(def->seed, (uint64_t)bin, (uint64_t)t))) {
		be->destroy(w);
		bsim_error_set(err, BSIM_EFAIL, "out of memory");
		return -1;
	}
	const long n_max = lattice->gate_steps > 0 ? lattice->gate_steps : lattice->max_steps;
	const double w2 = 0.5 * l->width, d = l->depth;
	be->get_state(w, &r->s0);
	int out = 0;
	for (long n = 0; n < n_max; n++) {
		double f[2];
		bsim_effects_force(&fx, n, s->dt, f);
		if (be->step(w, f, s->dt, err) != BSIM_OK) {
			out = -1;
			break;
		}
		be->get_state(w, &r->s1);
		if (!isfinite(r->s1.x[0]) || !isfinite(r->s1.x[1]) || !isfinite(r->s1.v[0]) ||
		    !isfinite(r->s1.v[1])) {
			bsim_error_set(err, BSIM_EFAIL,
			               "a single gate (k = %g, %g N m/rad, entry bin %d, trial %d) "
			               "became unstable at step %ld",
			               s->beams[0].stiffness, s->beams[1].stiffness, bin, t, n + 1);
			out = -1;
			break;
		}
		const double *p = r->s1.x;
		if (p[0] < -w2 || p[0] >= w2 || p[1] < 0.0 || p[1] >= d) {
			out = exit_bin(&def->bins, l, r->s0.x, &r->s1);
			break;
		}
		bsim_state tmp = r->s0;
		r->s0 = r->s1;
		r->s1 = tmp;
	}
	if (out >= 0 && bsim_effects_status(&fx, err) != BSIM_OK)
		out = -1;
	bsim_effects_free(&fx);
	be->destroy(w);
	return out;
}

/* ---- keys -----------------------------------------------------------------*/

static uint64_t fnv1a(const char *s)
{
	uint64_t h = 0xcbf29ce484222325ULL;
	for (; *s; s++) {
		h ^= (unsigned char)*s;
		h *= 0x100000001b3ULL;
	}
	return h;
}

/* Every input of a map, a line each, numbers to the last bit (%.17g). */
static char *key_text(const bsim_scene *lattice, const bsim_markov_def *def, const bsim_backend *be,
                      const bsim_options *opts, const double k[2])
{
	gate_scene g;
	gate_scene_init(&g, lattice, k);
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
	fprintf(f, "dt %.17g gate_steps %d max_steps %d\n", s->dt, s->gate_steps, s->max_steps);
	fprintf(f, "entries %s\n",
	        def->entries         ? def->entries->id
	        : def->entries_id[0] ? def->entries_id
	                             : "none");
	fprintf(f, "bins %d %d %d %.17g\ntrials %d\nseed %llu\n", def->bins.n_pos,
	        def->bins.n_speed, def->bins.n_dir, def->bins.v_max, def->trials,
	        (unsigned long long)def->seed);
	if (fclose(f) != 0) {
		free(text);
		return NULL;
	}
	return text;
}

/* ---- the lattice's pairs --------------------------------------------------- */

static int check_lattice(const bsim_scene *s, bsim_error *err)
{
	if (!s->has_lattice)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: not a gate lattice: the Markov chain is built over a "
		                      "lattice's gates (lattice: in the scene)",
		                      s->path[0] ? s->path : s->name);
	const bsim_lattice_def *l = &s->lattice;
	double edge = 0.5 * l->width * l->columns, top = l->depth * l->rows;
	if (fabs(s->side_x - edge) > 1e-9 * edge)
		return bsim_error_set(
		        err, BSIM_EINPUT,
		        "%s: termination.side_x: the chain needs the side boundary at "
		        "the field's edge, %g m, got %g m",
		        s->path[0] ? s->path : s->name, edge, s->side_x);
	if (fabs(s->success_y - top) > 1e-9 * top)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: termination.success_y: the chain needs the end at the "
		                      "last row's top edge, %g m, got %g m",
		                      s->path[0] ? s->path : s->name, top, s->success_y);
	return BSIM_OK;
}

/* The distinct (left, right) stiffness pairs of the lattice's gates, in
 * the order first met (row 0 first); returns how many, -1 out of memory. */
static int lattice_pairs(const bsim_scene *s, double (**pairs)[2])
{
	const bsim_lattice_def *l = &s->lattice;
	int n = 0, cap = l->columns * l->rows;
	double(*p)[2] = malloc((size_t)cap * sizeof *p);
	if (!p)
		return -1;
	for (int iy = 0; iy < l->rows; iy++)
		for (int ix = l->ix_min; ix <= l->ix_max; ix++) {
			double k[2] = {s->beams[bsim_lattice_beam(l, ix, iy, 0)].stiffness,
			               s->beams[bsim_lattice_beam(l, ix, iy, 1)].stiffness};
			int j = 0;
			while (j < n && !(p[j][0] == k[0] && p[j][1] == k[1]))
				j++;
			if (j == n) {
				p[n][0] = k[0];
				p[n][1] = k[1];
				n++;
			}
		}
	*pairs = p;
	return n;
}

/* ---- the cache --------------------------------------------------------------
 *
 * DIR/map_HASH.key  the key text
 * DIR/map_HASH.csv  entry,exit,count: the nonzero counts, bins as above
 * DIR/markov.json   the def of the last build, for bsim_markov_load */

static char *read_all(const char *path)
{
	FILE *f = fopen(path, "rb");
	if (!f)
		return NULL;
	size_t cap = 4096, len = 0;
	char *buf = malloc(cap);
	size_t got;
	while (buf && (got = fread(buf + len, 1, cap - len - 1, f)) > 0) {
		len += got;
		if (cap - len - 1 == 0) {
			char *nb = realloc(buf, cap *= 2);
			if (!nb) {
				free(buf);
				buf = NULL;
			}
			buf = nb;
		}
	}
	fclose(f);
	if (buf)
		buf[len] = '\0';
	return buf;
}

/* Reads map m (key and n_bins set) from dir: 1 if there with the same key,
 * 0 if not there or another key, -1 with err if its counts are malformed. */
static int map_read(const char *dir, bsim_markov_map *m, bsim_error *err)
{
	char path[1200];
	snprintf(path, sizeof path, "%s/map_%016llx.key", dir, (unsigned long long)m->key);
	char *key = read_all(path);
	int same = key && strcmp(key, m->key_text) == 0;
	free(key);
	if (!same)
		return 0;
	snprintf(path, sizeof path, "%s/map_%016llx.csv", dir, (unsigned long long)m->key);
	FILE *f = fopen(path, "r");
	if (!f)
		return 0;
	char line[256];
	int lineno = 0, ok = fgets(line, sizeof line, f) && strncmp(line, "entry,exit,", 11) == 0;
	lineno++;
	const char *bad = ok ? NULL : "header";
	while (!bad && fgets(line, sizeof line, f)) {
		lineno++;
		/* entry, exit: bins; count: trials */
		static const char *const field[3] = {"entry", "exit", "count"};
		long v[3];
		char *p = line;
		for (int i = 0; !bad && i < 3; i++) {
			char *end;
			errno = 0;
			v[i] = strtol(p, &end, 10);
			long hi = i < 2 ? m->n_bins - 1 : INT_MAX;
			if (end == p || errno || v[i] < 0 || v[i] > hi || (*end != ',' && i < 2) ||
			    (i == 2 && *end != ',' && *end != '\n' && *end != '\0'))
				bad = field[i];
			p = end + 1;
		}
		if (!bad)
			m->counts[(size_t)v[0] * m->n_bins + v[1]] = (int)v[2];
	}
	fclose(f);
	if (bad) {
		bsim_error_set(
		        err, BSIM_EINPUT, "%s:%d: %s: expected %s", path, lineno, bad,
		        strcmp(bad, "header") == 0 ? "entry,exit,count,..."
		        : strcmp(bad, "count") == 0
		                ? "a count of trials >= 0"
		                : (snprintf(line, sizeof line, "a bin 0 to %d", m->n_bins - 1),
		                   line));
		return -1;
	}
	snprintf(path, sizeof path, "%s/map_%016llx.cost", dir, (unsigned long long)m->key);
	if ((f = fopen(path, "r"))) {
		if (fscanf(f, "cpu_seconds %lf", &m->cost) != 1)
			m->cost = 0.0;
		fclose(f);
	}
	return 1;
}

static void bin_edge(const bsim_markov_bins *b, int bin, char *out, size_t size)
{
	if (bin == 0) {
		snprintf(out, size, "start");
		return;
	}
	int per = b->n_pos * b->n_speed * b->n_dir;
	snprintf(out, size, "%s", edge_names[1 + (bin - 1) / per]);
}

static int map_write(const char *stage, const bsim_markov_map *m, const bsim_markov_bins *b,
                     bsim_error *err)
{
	char path[1200];
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
		long total = 0;
		for (int x = 0; x < m->n_bins; x++)
			total += m->counts[(size_t)a * m->n_bins + x];
		for (int x = 0; x < m->n_bins; x++) {
			int c = m->counts[(size_t)a * m->n_bins + x];
			if (c == 0)
				continue;
			char ea[16], ex[16];
			bin_edge(b, a, ea, sizeof ea);
			if (x == 0)
				snprintf(ex, sizeof ex, "stuck");
			else
				bin_edge(b, x, ex, sizeof ex);
			fprintf(o.f, "%d,%d,%d,%s,%s,%.9g\n", a, x, c, ea, ex, (double)c / total);
		}
	}
	if (bsim_atomic_file_commit(&o, err) != BSIM_OK)
		return BSIM_EFAIL;
	/* What the map cost, for the break-even of building it. */
	snprintf(path, sizeof path, "%s/map_%016llx.cost", stage, (unsigned long long)m->key);
	if (bsim_atomic_file_open(&o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	fprintf(o.f, "cpu_seconds %.6g\n", m->seconds);
	return bsim_atomic_file_commit(&o, err);
}

static int def_write(const char *stage, const bsim_markov_def *def, const bsim_backend *be,
                     const bsim_options *opts, bsim_error *err)
{
	char path[1200];
	snprintf(path, sizeof path, "%s/markov.json", stage);
	bsim_atomic_file o;
	if (bsim_atomic_file_open(&o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	fprintf(o.f,
	        "{\"format\": %d, \"beamsim_version\": \"%s\", \"bins\": {\"position\": %d, "
	        "\"speed\": %d, \"direction\": %d, \"v_max\": ",
	        MAP_FORMAT, BSIM_VERSION, def->bins.n_pos, def->bins.n_speed, def->bins.n_dir);
	bsim_json_number(o.f, def->bins.v_max);
	fprintf(o.f, "}, \"trials\": %d, \"seed\": ", def->trials);
	bsim_json_u64(o.f, def->seed);
	fputs(", \"backend\": ", o.f);
	bsim_json_string(o.f, be->name);
	fputs(", \"options\": [", o.f);
	for (int i = 0; opts && i < opts->n; i++) {
		char kv[128];
		snprintf(kv, sizeof kv, "%s=%s", opts->key[i], opts->value[i]);
		fputs(i ? ", " : "", o.f);
		bsim_json_string(o.f, kv);
	}
	fputs("], \"entries\": ", o.f);
	bsim_json_string(o.f, def->entries         ? def->entries->id
	                      : def->entries_id[0] ? def->entries_id
	                                           : "none");
	fputs("}\n", o.f);
	return bsim_atomic_file_commit(&o, err);
}

/* ---- building -------------------------------------------------------------- */

static int map_simulate(const bsim_scene *lattice, const bsim_markov_def *def,
                        const bsim_backend *be, const bsim_options *opts, bsim_markov_map *m,
                        long *done, long total, bsim_error *err)
{
	const int nb = m->n_bins, T = def->trials;
	const long units = (long)nb * T;
	int *exit = malloc((size_t)units * sizeof *exit);
	if (!exit)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	entry_index ex = {0};
	if (def->entries && entry_index_init(&ex, def->entries, &def->bins, &lattice->lattice)) {
		free(exit);
		entry_index_free(&ex);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	int failed = 0;
	bsim_error first = {0};
	long first_unit = units;
	int threads = def->threads > 0 ? def->threads : 0;
#pragma omp parallel num_threads(threads > 0 ? threads : omp_get_max_threads())
	{
		gate_runner r;
		memset(&r, 0, sizeof r);
		int ok = bsim_state_init(&r.s0, 2) == BSIM_OK &&
		         bsim_state_init(&r.s1, 2) == BSIM_OK;
		r.rng = gsl_rng_alloc(gsl_rng_mt19937);
		r.ex = def->entries ? &ex : NULL;
		gate_scene_init(&r.g, lattice, m->k);
		const double start[2] = {r.g.s.body.start[0], r.g.s.body.start[1]};
#pragma omp for schedule(dynamic, 16)
		for (long u = 0; u < units; u++) {
			if (!ok || !r.rng) {
				exit[u] = -1;
#pragma omp critical(markov_fail)
				if (u < first_unit) {
					first_unit = u;
					bsim_error_set(&first, BSIM_EFAIL, "out of memory");
				}
				continue;
			}
			bsim_error e;
			r.g.s.body.start[0] = start[0];
			r.g.s.body.start[1] = start[1];
			r.g.s.body.velocity[0] = lattice->body.velocity[0];
			r.g.s.body.velocity[1] = lattice->body.velocity[1];
			exit[u] = gate_trial(&r, lattice, def, be, opts, (int)(u / T), (int)(u % T),
			                     &e);
			if (exit[u] < 0) {
#pragma omp critical(markov_fail)
				if (u < first_unit) {
					first_unit = u;
					first = e;
				}
			}
			long now;
#pragma omp atomic capture
			now = ++*done;
			if (def->progress && (now % 256 == 0 || now == total)) {
#pragma omp critical(markov_progress)
				def->progress(def->progress_user, now, total);
			}
		}
		gsl_rng_free(r.rng);
		bsim_state_free(&r.s0);
		bsim_state_free(&r.s1);
	}
	if (first_unit < units) {
		failed = 1;
		if (err)
			*err = first;
	}
	for (long u = 0; !failed && u < units; u++)
		m->counts[(u / T) * nb + exit[u]]++;
	free(exit);
	entry_index_free(&ex);
	return failed ? BSIM_EFAIL : BSIM_OK;
}

static int map_init(bsim_markov_map *m, const bsim_scene *lattice, const bsim_markov_def *def,
                    const bsim_backend *be, const bsim_options *opts, const double k[2],
                    bsim_error *err)
{
	memset(m, 0, sizeof *m);
	m->k[0] = k[0];
	m->k[1] = k[1];
	m->n_bins = bsim_markov_bins_count(&def->bins);
	m->trials = def->trials;
	m->key_text = key_text(lattice, def, be, opts, k);
	m->counts = calloc((size_t)m->n_bins * m->n_bins, sizeof *m->counts);
	if (!m->key_text || !m->counts)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	m->key = fnv1a(m->key_text);
	return BSIM_OK;
}

static int def_check(const bsim_markov_def *def, bsim_error *err)
{
	const bsim_markov_bins *b = &def->bins;
	if (b->n_pos < 1 || b->n_speed < 1 || b->n_dir < 1 || b->n_pos > 64 || b->n_speed > 64 ||
	    b->n_dir > 64 || !(b->v_max > 0) || !isfinite(b->v_max))
		return bsim_error_set(err, BSIM_EINPUT,
		                      "bins: expected 1 to 64 positions, speeds and directions and "
		                      "v_max > 0, got %d, %d, %d, %g",
		                      b->n_pos, b->n_speed, b->n_dir, b->v_max);
	if ((long)bsim_markov_bins_count(b) * bsim_markov_bins_count(b) > 20000000L)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "bins: %d entry bins make a map of more than 2e7 cells",
		                      bsim_markov_bins_count(b));
	if (def->trials < 1 || def->trials > 1000000)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "trials: expected 1 to 1000000 per bin, got %d", def->trials);
	return BSIM_OK;
}

void bsim_markov_set_free(bsim_markov_set *s)
{
	if (!s)
		return;
	for (int i = 0; i < s->n; i++) {
		free(s->maps[i].key_text);
		free(s->maps[i].counts);
	}
	free(s->maps);
	memset(s, 0, sizeof *s);
}

/* The maps of lattice's pairs: read from dir where there; with simulate,
 * the others simulated into stage; without, the first missing is an error. */
static int set_fill(const bsim_scene *lattice, const bsim_markov_def *def, const char *dir,
                    const char *stage, bsim_markov_set *out, bsim_error *err)
{
	const bsim_backend *be = def->backend ? def->backend : bsim_backend_default();
	const bsim_options none = {0};
	const bsim_options *opts = def->opts ? def->opts : &none;
	double(*pairs)[2] = NULL;
	int n = lattice_pairs(lattice, &pairs);
	if (n < 0)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	out->def = *def;
	out->maps = calloc((size_t)n, sizeof *out->maps);
	if (!out->maps) {
		free(pairs);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	out->n = n;
	int rc = BSIM_OK;
	long total = 0, done = 0;
	char *have = calloc((size_t)n, 1);
	if (!have)
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	for (int i = 0; i < n && rc == BSIM_OK; i++) {
		bsim_markov_map *m = &out->maps[i];
		rc = map_init(m, lattice, def, be, opts, pairs[i], err);
		if (rc != BSIM_OK)
			break;
		int got = map_read(dir, m, err);
		if (got < 0)
			rc = BSIM_EINPUT;
		else if (got)
			have[i] = m->cached = 1, out->reused++;
		else if (!stage)
			rc = bsim_error_set(
			        err, BSIM_EINPUT,
			        "%s: no map for k = %g, %g N m/rad with this scene's physics "
			        "and the map's settings (key %016llx): beamsim markov build "
			        "writes it",
			        dir, m->k[0], m->k[1], (unsigned long long)m->key);
		else
			total += (long)m->n_bins * def->trials;
	}
	for (int i = 0; i < n && rc == BSIM_OK && stage; i++) {
		bsim_markov_map *m = &out->maps[i];
		if (have[i])
			continue;
		clock_t c0 = clock();
		rc = map_simulate(lattice, def, be, opts, m, &done, total, err);
		m->seconds = (double)(clock() - c0) / CLOCKS_PER_SEC;
		m->cost = m->seconds;
		out->seconds += m->seconds;
		if (rc == BSIM_OK)
			rc = map_write(stage, m, &def->bins, err);
		out->built++;
	}
	free(have);
	free(pairs);
	if (rc != BSIM_OK)
		bsim_markov_set_free(out);
	return rc;
}

int bsim_markov_build(const bsim_scene *lattice, const bsim_markov_def *def, const char *dir,
                      bsim_markov_set *out, bsim_error *err)
{
	memset(out, 0, sizeof *out);
	int rc = check_lattice(lattice, err);
	if (rc == BSIM_OK)
		rc = def_check(def, err);
	if (rc != BSIM_OK)
		return rc;
	bsim_session ss;
	if ((rc = bsim_session_open(&ss, dir, 0, NULL, 0, err)) != BSIM_OK)
		return rc;
	ss.add = 1; /* the maps join those already cached */
	rc = set_fill(lattice, def, dir, ss.stage, out, err);
	if (rc == BSIM_OK)
		rc = def_write(ss.stage, def, def->backend ? def->backend : bsim_backend_default(),
		               def->opts, err);
	rc = bsim_session_close(&ss, rc, "markov build", NULL, err);
	if (rc != BSIM_OK)
		bsim_markov_set_free(out);
	return rc;
}

/* One field of markov.json: the node at slash-separated path, or an error
 * "FILE:LINE:COL: FIELD: expected WHAT, got ..." naming it. */
static struct fy_node *def_field(const ydoc *d, const char *path, const char *what, bsim_error *err)
{
	struct fy_node *root = fy_document_root(d->fyd);
	struct fy_node *n = root ? fy_node_by_path(root, path, -1, FYNWF_DONT_FOLLOW) : NULL;
	if (!n || ydoc_is_null(n)) {
		ydoc_expected(d, n, root, path + 1, what, err);
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
	if (!ydoc_int64(n, &v) || v < lo || v > hi)
		return ydoc_expected(d, n, NULL, path + 1, what, err);
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
		return ydoc_expected(d, n, NULL, path + 1, "a short string", err);
	snprintf(buf, size, "%s", t);
	return BSIM_OK;
}

/* markov.json's def, read as JSON (a YAML flow document) with libfyaml:
 * every field def_write writes, each fault naming its file position and
 * field. */
static int def_read(const char *dir, bsim_markov_def *def, bsim_options *opts, bsim_error *err)
{
	char path[1200];
	snprintf(path, sizeof path, "%s/markov.json", dir);
	FILE *probe = fopen(path, "r");
	if (!probe)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: cannot read (%s): not a map directory of beamsim markov "
		                      "build",
		                      path, strerror(errno));
	fclose(probe);
	*def = bsim_markov_def_default();
	memset(opts, 0, sizeof *opts);
	ydoc d;
	int rc = ydoc_load(&d, path, err);
	if (rc != BSIM_OK)
		return rc;
	int format = 0;
	uint64_t seed = 0;
	char backend[64] = "", id[64] = "";
	rc = def_int(&d, "/format", MAP_FORMAT, MAP_FORMAT, &format, err);
	if (rc == BSIM_OK)
		rc = def_int(&d, "/bins/position", 1, 64, &def->bins.n_pos, err);
	if (rc == BSIM_OK)
		rc = def_int(&d, "/bins/speed", 1, 64, &def->bins.n_speed, err);
	if (rc == BSIM_OK)
		rc = def_int(&d, "/bins/direction", 1, 64, &def->bins.n_dir, err);
	if (rc == BSIM_OK) {
		struct fy_node *n = def_field(&d, "/bins/v_max", "a speed > 0, m/s", err);
		rc = !n ? BSIM_EINPUT
		     : ydoc_number(n, &def->bins.v_max) != YDOC_NUM_OK || !(def->bins.v_max > 0)
		             ? ydoc_expected(&d, n, NULL, "bins/v_max", "a speed > 0, m/s", err)
		             : BSIM_OK;
	}
	if (rc == BSIM_OK)
		rc = def_int(&d, "/trials", 1, 1000000, &def->trials, err);
	if (rc == BSIM_OK) {
		/* above 2^53 written as a string (bsim_json_u64) */
		struct fy_node *n = def_field(&d, "/seed", "a seed, an integer >= 0", err);
		const char *t = n && fy_node_is_scalar(n) ? fy_node_get_scalar0(n) : NULL;
		char *end = NULL;
		errno = 0;
		seed = t && *t >= '0' && *t <= '9' ? strtoull(t, &end, 10) : 0;
		rc = !n ? BSIM_EINPUT
		     : !end || *end || errno
		             ? ydoc_expected(&d, n, NULL, "seed", "a seed, an integer >= 0", err)
		             : BSIM_OK;
	}
	if (rc == BSIM_OK)
		rc = def_string(&d, "/backend", backend, sizeof backend, err);
	if (rc == BSIM_OK) {
		struct fy_node *n = def_field(&d, "/options", "a list of \"KEY=VALUE\"", err);
		if (!n)
			rc = BSIM_EINPUT;
		else if (!fy_node_is_sequence(n))
			rc = ydoc_expected(&d, n, NULL, "options", "a list of \"KEY=VALUE\"", err);
		void *it = NULL;
		struct fy_node *kv;
		while (rc == BSIM_OK && (kv = fy_node_sequence_iterate(n, &it))) {
			const char *t = fy_node_is_scalar(kv) ? fy_node_get_scalar0(kv) : NULL;
			rc = t ? bsim_options_add(opts, t, err)
			       : ydoc_expected(&d, kv, n, "options", "\"KEY=VALUE\"", err);
		}
	}
	if (rc == BSIM_OK)
		rc = def_string(&d, "/entries", id, sizeof id, err);
	ydoc_free(&d);
	if (rc != BSIM_OK)
		return rc;
	if (strcmp(id, "none") != 0)
		snprintf(def->entries_id, sizeof def->entries_id, "%s", id);
	def->seed = seed;
	def->backend = bsim_backend_find(backend, err);
	def->opts = opts;
	return def->backend ? def_check(def, err) : BSIM_EINPUT;
}

int bsim_markov_load(const bsim_scene *lattice, const char *dir, bsim_options *opts,
                     bsim_markov_set *out, bsim_error *err)
{
	memset(out, 0, sizeof *out);
	int rc = check_lattice(lattice, err);
	if (rc != BSIM_OK)
		return rc;
	bsim_markov_def def;
	if ((rc = def_read(dir, &def, opts, err)) != BSIM_OK)
		return rc;
	return set_fill(lattice, &def, dir, NULL, out, err);
}
