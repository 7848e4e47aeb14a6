/* Nearest-neighbour walks (beamsim/markov_nearest.h): the visits of a
 * lattice's gate kinds, and walks over them.
 *
 * The visits. A training field per kind, run (markov_train.c) or read from
 * the visits directory, where each field is visits_HASH.csv (a row a
 * visit), .cost (what it took) and .key (every input, written last: a
 * field whose key is there is whole).
 *
 * The walks. The visits of each kind entered through each edge are
 * indexed by their entry states in units of the default bins' widths (an
 * exact k-d tree, markov_kdtree.cpp). A walk in gate g of kind K entered
 * through e in state s takes one of the k visits of (K, e) nearest s,
 * uniformly: the kernel estimate of the exit's distribution given the
 * exact entry, which the chain's bins approximate by a step function. Walk
 * w's draws are bsim_schedule_seed_mix(seed, w, j) for its j-th gate, so
 * that the walks and their counts (integers, summed over threads) are the
 * same on any number of threads. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "analysis/markov_internal.h"
#include "analysis/markov_kdtree.h"
#include "beamsim/backend_registry.h"
#include "beamsim/lattice.h"
#include "beamsim/output.h"
#include "beamsim/schedule.h"
#include "util/atomic_file.h"
#include "util/clock.h"
#include "util/csv_table.h"
#include "util/file_read.h"

/* ---- the visits ------------------------------------------------------------ */

/* The visits file format; part of every key. */
#define VISITS_FORMAT 1
/* Salt of the training fields' layouts and schedules, one a start kind. */
#define VISITS_SALT 0x7669736974730a31ULL

static const char HEADER[] = "k_left,k_right,edge,pos,vx,vy,exit,exit_pos,exit_vx,exit_vy,steps";

bsim_markov_nearest_def bsim_markov_nearest_def_default(void)
{
	return (bsim_markov_nearest_def){.trials = BSIM_MARKOV_NEAREST_TRIALS,
	                                 .k = BSIM_MARKOV_NEAREST_K,
	                                 .walks = BSIM_MARKOV_NEAREST_WALKS,
	                                 .seed = 1};
}

void bsim_markov_visits_free(bsim_markov_visits *v)
{
	if (!v)
		return;
	free(v->v);
	memset(v, 0, sizeof *v);
}

/* The map build's def that runs def's training fields. */
static bsim_markov_def train_def(const bsim_markov_nearest_def *def)
{
	bsim_markov_def m = bsim_markov_def_default();
	m.train_trials = def->trials;
	m.train_crossings = 0;
	m.seed = def->seed;
	m.threads = def->threads;
	m.stop = def->stop;
	m.train_progress = def->progress;
	m.train_progress_user = def->progress_user;
	return m;
}

/* The key of the training field of lattice whose start gate is of kind
 * start: a map's key of that gate (the physics, the kinds and the
 * training field's trials and seed) without the lines of a map's own
 * (its bins and single-gate trials), headed by the visits format. */
static char *visits_key(const bsim_scene *lattice, const bsim_markov_def *m, const bsim_backend *be,
                        const bsim_options *opts, const double start[2])
{
	char *map = bsim_markov_key_text(lattice, m, be, opts, start);
	char *text = NULL;
	size_t size = 0;
	FILE *f = map ? open_memstream(&text, &size) : NULL;
	if (!f) {
		free(map);
		return NULL;
	}
	fprintf(f, "beamsim-markov-visits %d\n", VISITS_FORMAT);
	for (char *c = map; *c;) {
		char *e = strchr(c, '\n');
		const size_t len = e ? (size_t)(e - c) + 1 : strlen(c);
		if (strncmp(c, "beamsim-markov-map ", 19) != 0 && strncmp(c, "bins ", 5) != 0 &&
		    strncmp(c, "trials ", 7) != 0 && strncmp(c, "start_trials ", 13) != 0)
			fwrite(c, 1, len, f);
		c += len;
	}
	free(map);
	if (fclose(f) != 0) {
		free(text);
		return NULL;
	}
	return text;
}

/* dir/visits_HASH.csv and .cost appended to out (cap its arrays'). */
static int visits_read(const char *dir, uint64_t hash, bsim_markov_visits *out, long *cap,
                       bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	snprintf(path, sizeof path, "%s/visits_%016llx.cost", dir, (unsigned long long)hash);
	file_text ct;
	if (bsim_file_read(path, "a visits cost file", 4096.0, NULL, &ct, err) != BSIM_OK)
		return BSIM_EINPUT;
	double cost;
	long long steps;
	long left_out;
	const int got = sscanf(ct.text, "cpu_seconds %lf\nsteps %lld\nleft_out %ld", &cost, &steps,
	                       &left_out);
	bsim_file_text_free(&ct);
	if (got != 3 || !(cost >= 0) || steps < 0 || left_out < 0)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: expected \"cpu_seconds S\", \"steps N\" and "
		                      "\"left_out L\", a line each (S, N, L >= 0)",
		                      path);
	snprintf(path, sizeof path, "%s/visits_%016llx.csv", dir, (unsigned long long)hash);
	csv_table t;
	int rc = bsim_csv_table_read(path, &t, err);
	if (rc != BSIM_OK)
		return rc;
	static const char *const names[] = {"k_left",  "k_right", "edge", "pos",
	                                    "vx",      "vy",      "exit", "exit_pos",
	                                    "exit_vx", "exit_vy", "steps"};
	int col[11];
	rc = bsim_csv_table_require(&t, path, names, 11, col, err);
	for (long r = 0; rc == BSIM_OK && r < t.n_rows; r++) {
		if (bsim_markov_visits_reserve(out, cap)) {
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
			break;
		}
		bsim_markov_visit *v = &out->v[out->n];
		memset(v, 0, sizeof *v);
		double x[9];
		static const int num[9] = {0, 1, 3, 4, 5, 7, 8, 9, 10};
		int bad = -1;
		for (int i = 0; i < 9 && bad < 0; i++)
			if (bsim_csv_table_number(&t, r, col[num[i]], &x[i]) != 0)
				bad = num[i];
		const char *into = bsim_csv_table_cell(&t, r, col[6]);
		const int into_edge = bsim_markov_edge_of(into);
		v->edge = bsim_markov_edge_of(bsim_csv_table_cell(&t, r, col[2]));
		/* an exit is into a gate's edge (not a start), or stuck (0) */
		v->exit_edge = strcmp(into, "stuck") == 0 ? 0 : into_edge > 0 ? into_edge : -1;
		if (bad < 0 && v->edge < 0)
			bad = 2;
		if (bad < 0 && v->exit_edge < 0)
			bad = 6;
		if (bad < 0 && !(x[8] >= 1 && x[8] <= 2147483647.0 && x[8] == (int)x[8]))
			bad = 10;
		if (bad >= 0) {
			/* the header is line 1 */
			rc = bsim_error_set(err, BSIM_EINPUT, "%s:%ld: %s: expected %s, got '%s'",
			                    path, r + 2, names[bad],
			                    bad == 2    ? "start, bottom, left, right or top"
			                    : bad == 6  ? "stuck, bottom, left, right or top"
			                    : bad == 10 ? "time steps, an integer 1 or more"
			                                : "a number",
			                    bsim_csv_table_cell(&t, r, col[bad]));
			break;
		}
		v->k[0] = x[0];
		v->k[1] = x[1];
		v->pos = x[2];
		v->v[0] = x[3];
		v->v[1] = x[4];
		v->exit_pos = x[5];
		v->exit_v[0] = x[6];
		v->exit_v[1] = x[7];
		v->steps = (int)x[8];
		out->n++;
	}
	bsim_csv_table_free(&t);
	if (rc == BSIM_OK) {
		out->cost += cost;
		out->steps += steps;
		out->left_out += left_out;
	}
	return rc;
}

/* out->v[first ..] as dir/visits_HASH.csv and .cost, then the key. */
static int visits_write(const char *dir, uint64_t hash, const char *key,
                        const bsim_markov_visits *out, long first, double cost, long long steps,
                        long left_out, bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	bsim_atomic_file o;
	snprintf(path, sizeof path, "%s/visits_%016llx.csv", dir, (unsigned long long)hash);
	if (bsim_atomic_file_open(&o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	fprintf(o.f, "%s\n", HEADER);
	for (long i = first; i < out->n; i++) {
		const bsim_markov_visit *v = &out->v[i];
		fprintf(o.f, "%.17g,%.17g,%s,%.17g,%.17g,%.17g,%s,%.17g,%.17g,%.17g,%d\n", v->k[0],
		        v->k[1], bsim_markov_edge_name(v->edge), v->pos, v->v[0], v->v[1],
		        v->exit_edge ? bsim_markov_edge_name(v->exit_edge) : "stuck", v->exit_pos,
		        v->exit_v[0], v->exit_v[1], v->steps);
	}
	if (bsim_atomic_file_commit(&o, err) != BSIM_OK)
		return BSIM_EFAIL;
	snprintf(path, sizeof path, "%s/visits_%016llx.cost", dir, (unsigned long long)hash);
	if (bsim_atomic_file_open(&o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	fprintf(o.f, "cpu_seconds %.6g\nsteps %lld\nleft_out %ld\n", cost, steps, left_out);
	if (bsim_atomic_file_commit(&o, err) != BSIM_OK)
		return BSIM_EFAIL;
	snprintf(path, sizeof path, "%s/visits_%016llx.key", dir, (unsigned long long)hash);
	if (bsim_atomic_file_open(&o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	fputs(key, o.f);
	return bsim_atomic_file_commit(&o, err);
}

/* Whether dir/visits_HASH.key holds exactly key. */
static int key_there(const char *dir, uint64_t hash, const char *key)
{
	char path[BSIM_PATH_MAX];
	snprintf(path, sizeof path, "%s/visits_%016llx.key", dir, (unsigned long long)hash);
	return bsim_markov_key_same(path, key);
}

int bsim_markov_visits_gather(const bsim_scene *lattice, const bsim_markov_nearest_def *def,
                              const char *dir, const markov_visits_io *io, bsim_markov_visits *out,
                              bsim_error *err)
{
	memset(out, 0, sizeof *out);
	if (bsim_markov_check_lattice(lattice, err) != BSIM_OK)
		return BSIM_EINPUT;
	if (def->trials < 1)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "training trials %d: expected 1 or more a gate kind",
		                      def->trials);
	const bsim_backend *be = def->backend ? def->backend : bsim_backend_default();
	const bsim_options none = {0};
	const bsim_options *opts = def->opts ? def->opts : &none;
	const bsim_markov_def m = train_def(def);
	const char *stage = io->stage ? io->stage : dir;
	/* the kinds in ascending order: the fields and their seeds do not
	 * depend on the order a lattice meets them in */
	double(*kinds)[2] = NULL;
	const int n = bsim_markov_lattice_kinds(lattice, &kinds);
	if (n < 0)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	int rc = def->read_only ? BSIM_OK : bsim_output_mkdir(stage, err);
	long cap = 0;
	for (int i = 0; rc == BSIM_OK && i < n; i++) {
		char *key = visits_key(lattice, &m, be, opts, kinds[i]);
		if (!key) {
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
			break;
		}
		const uint64_t hash = bsim_markov_key(key);
		const int there = key_there(dir, hash, key);
		const double cost0 = out->cost;
		if (there) {
			rc = visits_read(dir, hash, out, &cap, err);
			out->reused += rc == BSIM_OK;
		} else if (def->read_only) {
			/* a build's fields are used only where the whole key
			 * matches: say what differs from the nearest there */
			char near[700];
			bsim_markov_key_nearest(dir, "visits_", key, near, sizeof near);
			rc = bsim_error_set(
			        err, BSIM_EINPUT,
			        "%s: no training field for k = %g, %g N m/rad with this "
			        "scene's physics and gate kinds and the build's "
			        "settings (key %016llx)%s%s: beamsim markov build "
			        "writes it",
			        dir, kinds[i][0], kinds[i][1], (unsigned long long)hash,
			        near[0] ? "; " : "", near);
		} else {
			const long first = out->n, left0 = out->left_out;
			long long steps = 0;
			const double c0 = bsim_clock_process_cpu_seconds();
			rc = bsim_markov_train_visits(
			        lattice, &m, kinds[i],
			        bsim_schedule_seed_mix(def->seed ^ VISITS_SALT, 0, (uint64_t)i), be,
			        opts, out, &cap, &steps, err);
			const double cost = bsim_clock_process_cpu_seconds() - c0;
			if (rc == BSIM_OK)
				rc = visits_write(stage, hash, key, out, first, cost, steps,
				                  out->left_out - left0, err);
			if (rc == BSIM_OK && io->commit)
				rc = io->commit(io->user, err);
			if (rc == BSIM_OK) {
				out->built++;
				out->cost += cost;
				out->steps += steps;
			}
		}
		if (rc == BSIM_OK && io->field)
			io->field(io->user, kinds[i], hash, there, out->cost - cost0);
		out->fields += rc == BSIM_OK;
		free(key);
	}
	free(kinds);
	if (rc != BSIM_OK)
		bsim_markov_visits_free(out);
	return rc;
}

int bsim_markov_visits_build(const bsim_scene *lattice, const bsim_markov_nearest_def *def,
                             const char *dir, bsim_markov_visits *out, bsim_error *err)
{
	const markov_visits_io io = {0};
	return bsim_markov_visits_gather(lattice, def, dir, &io, out, err);
}

int bsim_markov_nearest_of_dir(const char *map_dir, const char *visits_dir,
                               const bsim_markov_nearest_def *given, bsim_markov_nearest_def *nd,
                               bsim_options *opts, const char **vdir, bsim_error *err)
{
	*nd = *given;
	*vdir = visits_dir;
	if (visits_dir || !map_dir)
		return BSIM_OK;
	int is_nearest = 0;
	const int rc = bsim_markov_nearest_def_read(map_dir, nd, opts, &is_nearest, err);
	if (rc == BSIM_OK && is_nearest)
		*vdir = map_dir;
	return rc;
}

/* ---- the walks ------------------------------------------------------------- */

/* Salt of the walks' draws. */
#define WALK_SALT 0x77616c6b73000001ULL

/* The visits of one gate kind through one edge (or the start). */
typedef struct pool {
	long n;
	long *visit;    /* indices into the visits */
	double (*f)[3]; /* their entry states, bin widths (not for the start) */
	markov_kdtree *tree;
} pool;

/* Per kind of the lattice (the order bsim_markov_lattice_pairs meets
 * them) and edge, BSIM_EDGE_START .. BSIM_EDGE_TOP. */
#define EDGES 5

static void pools_free(pool *p, int n)
{
	for (int i = 0; p && i < n; i++) {
		bsim_markov_kdtree_free(p[i].tree);
		free(p[i].visit);
		free(p[i].f);
	}
	free(p);
}

static int kind_index(double (*kinds)[2], int n, const double k[2])
{
	for (int i = 0; i < n; i++)
		if (kinds[i][0] == k[0] && kinds[i][1] == k[1])
			return i;
	return -1;
}

/* The pools of v for the n kinds; NULL out of memory. */
static pool *pools_make(const bsim_markov_visits *v, double (*kinds)[2], int n,
                        const bsim_markov_bins *b, const bsim_lattice_def *l)
{
	pool *p = calloc((size_t)n * EDGES, sizeof *p);
	long *at = calloc((size_t)n * EDGES, sizeof *at);
	int ok = p && at;
	for (long i = 0; ok && i < v->n; i++) {
		const int j = kind_index(kinds, n, v->v[i].k);
		if (j >= 0)
			p[j * EDGES + v->v[i].edge].n++;
	}
	for (int i = 0; ok && i < n * EDGES; i++) {
		const size_t m = (size_t)(p[i].n > 0 ? p[i].n : 1);
		p[i].visit = malloc(m * sizeof *p[i].visit);
		p[i].f = malloc(m * sizeof *p[i].f);
		ok = p[i].visit && p[i].f;
	}
	for (long i = 0; ok && i < v->n; i++) {
		const bsim_markov_visit *x = &v->v[i];
		const int j = kind_index(kinds, n, x->k);
		if (j < 0)
			continue;
		pool *q = &p[j * EDGES + x->edge];
		q->visit[at[j * EDGES + x->edge]] = i;
		if (x->edge != BSIM_EDGE_START)
			bsim_markov_entry_feature(b, l, x->edge, x->pos, x->v,
			                          q->f[at[j * EDGES + x->edge]]);
		at[j * EDGES + x->edge]++;
	}
	for (int i = 0; ok && i < n * EDGES; i++)
		if (i % EDGES != BSIM_EDGE_START && p[i].n > 0)
			ok = (p[i].tree = bsim_markov_kdtree_alloc((const double(*)[3])p[i].f,
			                                           p[i].n)) != NULL;
	free(at);
	if (!ok) {
		pools_free(p, n * EDGES);
		return NULL;
	}
	return p;
}

/* The visits of pool q nearest visit x's exit state (x's exit edge, and
 * in the default bins' units b): every walk that leaves by x into a gate
 * of q's kind asks the same question, so it is answered once and kept in
 * *slot (its count, then the visits' indices), installed atomically: the
 * answer is the same whichever thread gives it. NULL out of memory. */
static const int *nearest_of(int **slot, const pool *q, const bsim_markov_visit *x, int k,
                             const bsim_markov_bins *b, const bsim_lattice_def *l)
{
	int *got = __atomic_load_n(slot, __ATOMIC_ACQUIRE);
	if (got)
		return got;
	int *mine = malloc((size_t)(k + 1) * sizeof *mine);
	if (!mine)
		return NULL;
	double f[3];
	long near[BSIM_MARKOV_KDTREE_K_MAX];
	bsim_markov_entry_feature(b, l, x->exit_edge, x->exit_pos, x->exit_v, f);
	mine[0] = bsim_markov_kdtree_nearest(q->tree, f, k, near);
	for (int i = 0; i < mine[0]; i++)
		mine[1 + i] = (int)q->visit[near[i]];
	int *none = NULL;
	if (__atomic_compare_exchange_n(slot, &none, mine, 0, __ATOMIC_ACQ_REL, __ATOMIC_ACQUIRE))
		return mine;
	free(mine); /* another thread's, the same */
	return none;
}

/* Where one walk is: gate (ix, iy) entered through edge at pos with v. */
typedef struct walker {
	int ix, iy, edge;
	double pos, v[2];
} walker;

/* Follows visit x's exit out of the walker's gate: 1 into the next gate
 * (the walker moved there), else 0 with *loc its final location. */
static int step(walker *w, const bsim_markov_visit *x, const bsim_lattice_def *l, int *loc)
{
	const int cols = l->columns, rows = l->rows, g = w->iy * cols + w->ix - l->ix_min;
	int jx = w->ix, jy = w->iy;
	switch (x->exit_edge) {
	case 0:
		*loc = cols + rows + g;
		return 0;
	case BSIM_EDGE_BOTTOM: /* into the gate above */
		jy++;
		break;
	case BSIM_EDGE_LEFT: /* into the gate on the right */
		jx++;
		break;
	case BSIM_EDGE_RIGHT:
		jx--;
		break;
	default:
		jy--;
		break;
	}
	if (jy == rows) {
		*loc = w->ix - l->ix_min;
		return 0;
	}
	if (jx < l->ix_min || jx > l->ix_max) {
		*loc = cols + w->iy;
		return 0;
	}
	*w = (walker){jx, jy, x->exit_edge, x->exit_pos, {x->exit_v[0], x->exit_v[1]}};
	if (jy < 0) { /* below row 0: row 0's gate again, through its bottom */
		w->iy = 0;
		w->edge = BSIM_EDGE_BOTTOM;
		w->v[1] = -w->v[1];
	}
	return 1;
}

double bsim_markov_nearest_tv_walks(const double *p, int n, long walks)
{
	const double PI = 3.14159265358979323846;
	double tv = 0.0;
	for (int i = 0; i < n; i++)
		tv += sqrt(2.0 * p[i] * (1.0 - p[i]) / (PI * (double)walks));
	return 0.5 * tv;
}

int bsim_markov_nearest_predict(const bsim_scene *lattice, const bsim_markov_visits *v,
                                const bsim_markov_nearest_def *def, bsim_markov_prediction *out,
                                bsim_error *err)
{
	memset(out, 0, sizeof *out);
	if (bsim_markov_check_lattice(lattice, err) != BSIM_OK)
		return BSIM_EINPUT;
	if (def->k < 1 || def->k > BSIM_MARKOV_KDTREE_K_MAX)
		return bsim_error_set(err, BSIM_EINPUT, "k %d: expected 1 to %d nearest visits",
		                      def->k, BSIM_MARKOV_KDTREE_K_MAX);
	if (def->walks < 1 || def->walks > 100000000L)
		return bsim_error_set(err, BSIM_EINPUT, "walks %ld: expected 1 to 1e8", def->walks);
	const bsim_lattice_def *l = &lattice->lattice;
	bsim_markov_bins b = bsim_markov_bins_default();
	b.v_max = bsim_markov_bins_v_max(&b, lattice);
	double(*kinds)[2] = NULL;
	const int n = bsim_markov_lattice_pairs(lattice, &kinds);
	const int cols = l->columns, rows = l->rows, G = cols * rows;
	const int n_loc = cols + rows + G, most = BSIM_MARKOV_NEAREST_GATES;
	int *gate_kind = malloc((size_t)G * sizeof *gate_kind);
	pool *pools = n > 0 && gate_kind ? pools_make(v, kinds, n, &b, l) : NULL;
	int rc = pools ? BSIM_OK : bsim_error_set(err, BSIM_EFAIL, "out of memory");
	for (int iy = 0; rc == BSIM_OK && iy < rows; iy++)
		for (int ix = l->ix_min; ix <= l->ix_max; ix++) {
			const double k[2] = {
			        lattice->beams[bsim_lattice_beam(l, ix, iy, 0)].stiffness,
			        lattice->beams[bsim_lattice_beam(l, ix, iy, 1)].stiffness};
			gate_kind[iy * cols + ix - l->ix_min] = kind_index(kinds, n, k);
		}
	int ix0 = 0, iy0 = 0;
	bsim_lattice_gate_at(lattice, lattice->body.start, &ix0, &iy0);
	const int start_kind = rc == BSIM_OK ? gate_kind[iy0 * cols + ix0 - l->ix_min] : 0;
	if (rc == BSIM_OK && pools[start_kind * EDGES].n == 0)
		rc = bsim_error_set(err, BSIM_EINPUT,
		                    "no start visit of the start gate's kind (k = %g, %g N m/rad): "
		                    "the visits are of other kinds or another physics",
		                    kinds[start_kind][0], kinds[start_kind][1]);
	long *count = rc == BSIM_OK ? calloc((size_t)n_loc + most + 2, sizeof *count) : NULL;
	/* memo[x n + j]: the visits of kind j nearest visit x's exit
	 * (nearest_of) */
	int **memo = rc == BSIM_OK ? calloc((size_t)v->n * n + 1, sizeof *memo) : NULL;
	if (rc == BSIM_OK && (!count || !memo))
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	/* the first (kind, edge) without visits that a walk entered, in the
	 * pools' order, whatever the threads */
	int missing = n * EDGES, oom = 0;
	const int threads = def->threads > 0 ? def->threads : omp_get_max_threads();
	const uint64_t seed = def->seed ^ WALK_SALT;
	const long W = def->walks, run = rc == BSIM_OK ? W : 0;
#pragma omp parallel num_threads(threads) if (run > 0)
	{
		/* this thread's counts: the locations, then walks by gates
		 * visited (1 .. most), then those still in the field */
		long *mine = calloc((size_t)n_loc + most + 2, sizeof *mine);
		if (!mine) {
#pragma omp atomic write
			oom = 1;
		}
#pragma omp for schedule(dynamic, 256)
		for (long w = 0; w < run; w++) {
			if (!mine)
				continue;
			const pool *sp = &pools[start_kind * EDGES];
			const uint64_t r0 = bsim_schedule_seed_mix(seed, (uint64_t)w, 0);
			const bsim_markov_visit *x = &v->v[sp->visit[r0 % (uint64_t)sp->n]];
			walker at = {ix0, iy0, BSIM_EDGE_START, 0, {0, 0}};
			int loc = -1, gates = 1;
			while (step(&at, x, l, &loc)) {
				if (++gates > most)
					break;
				const int kp = gate_kind[at.iy * cols + at.ix - l->ix_min] * EDGES +
				               at.edge;
				const pool *q = &pools[kp];
				if (q->n == 0) {
#pragma omp critical(bsim_markov_nearest_missing)
					missing = kp < missing ? kp : missing;
					break;
				}
				const uint64_t r =
				        bsim_schedule_seed_mix(seed, (uint64_t)w, (uint64_t)gates);
				if (at.edge != x->exit_edge) {
					/* row 0 entered again from below: a state of its own */
					double f[3];
					long near[BSIM_MARKOV_KDTREE_K_MAX];
					bsim_markov_entry_feature(&b, l, at.edge, at.pos, at.v, f);
					const int got = bsim_markov_kdtree_nearest(q->tree, f,
					                                           def->k, near);
					x = &v->v[q->visit[near[r % (uint64_t)got]]];
					continue;
				}
				const int *near =
				        nearest_of(&memo[(size_t)(x - v->v) * n + kp / EDGES], q, x,
				                   def->k, &b, l);
				if (!near) {
#pragma omp atomic write
					oom = 1;
					break;
				}
				x = &v->v[near[1 + r % (uint64_t)near[0]]];
			}
			if (loc >= 0) {
				mine[loc]++;
				mine[n_loc + gates]++;
			} else if (gates > most)
				mine[n_loc + most + 1]++;
		}
#pragma omp critical(bsim_markov_nearest_sum)
		for (int i = 0; mine && count && i < n_loc + most + 2; i++)
			count[i] += mine[i];
		free(mine);
	}
	if (rc == BSIM_OK && oom)
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	if (rc == BSIM_OK && missing < n * EDGES)
		rc = bsim_error_set(err, BSIM_EINPUT,
		                    "no visit of the gate kind k = %g, %g N m/rad entered through "
		                    "its %s edge, where a walk entered it: more training trials "
		                    "give more visits",
		                    kinds[missing / EDGES][0], kinds[missing / EDGES][1],
		                    bsim_markov_edge_name(missing % EDGES));
	if (rc == BSIM_OK && count[n_loc + most + 1] > 0)
		rc = bsim_error_set(err, BSIM_EFAIL,
		                    "%ld of %ld walks still in the field after %d gates",
		                    count[n_loc + most + 1], W, most);
	if (rc == BSIM_OK) {
		int top = 1;
		for (int k = 1; k <= most; k++)
			if (count[n_loc + k])
				top = k;
		out->n_locations = n_loc;
		out->loc = malloc((size_t)n_loc * sizeof *out->loc);
		out->p = malloc((size_t)n_loc * sizeof *out->p);
		out->p_gates = calloc((size_t)top + 1, sizeof *out->p_gates);
		if (!out->loc || !out->p || !out->p_gates)
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
		else {
			bsim_markov_locations_fill(l, out->loc);
			for (int i = 0; i < n_loc; i++)
				out->p[i] = (double)count[i] / (double)W;
			out->n_gates = top;
			for (int k = 1; k <= top; k++) {
				out->p_gates[k] = (double)count[n_loc + k] / (double)W;
				out->mean_gates += k * out->p_gates[k];
			}
			for (int i = 0; i < n * EDGES; i++)
				out->n_states += (int)pools[i].n;
			out->mean_time = NAN;
			out->nearest_walks = W;
			out->nearest_k = def->k;
		}
	}
	free(count);
	for (long i = 0; memo && i < v->n * n; i++)
		free(memo[i]);
	free(memo);
	pools_free(pools, n * EDGES);
	free(gate_kind);
	free(kinds);
	if (rc != BSIM_OK)
		bsim_markov_prediction_free(out);
	return rc;
}
