/* Self-consistent entry states of a single-gate map (beamsim/markov.h):
 * one gate's exit state is the next gate's entry state, so pass p draws
 * the states of each entry bin from the exits that pass p - 1's single
 * gates left into that bin, weighted by how often a field of this gate
 * alone visits the bin each came from. Pass 0 is the map of states uniform
 * in each bin. Every pass's map is kept with its single gates' entry and
 * exit states (map_HASH.exits.csv), so a build with more passes starts
 * from the last one there. */
#define _POSIX_C_SOURCE 200809L

#include "analysis/markov_internal.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "util/atomic_file.h"
#include "util/file_read.h"
#include "beamsim/limits.h"

static const char EXITS_HEADER[] = "entry,trial,x,y,vx,vy,exit,exit_x,exit_y,exit_vx,exit_vy";

/* map_HASH.exits.csv: every trial's entry and exit state, to the last bit. */
static int runs_write(const char *stage, uint64_t key, const markov_run *runs, int nb, int T,
                      bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	snprintf(path, sizeof path, "%s/map_%016llx.exits.csv", stage, (unsigned long long)key);
	bsim_atomic_file o;
	if (bsim_atomic_file_open(&o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	fprintf(o.f, "%s\n", EXITS_HEADER);
	for (long u = 0; u < (long)nb * T; u++) {
		const markov_run *r = &runs[u];
		fprintf(o.f, "%ld,%ld,%.17g,%.17g,%.17g,%.17g,%d,%.17g,%.17g,%.17g,%.17g\n", u / T,
		        u % T, r->x[0], r->x[1], r->v[0], r->v[1], r->exit, r->exit_x[0],
		        r->exit_x[1], r->exit_v[0], r->exit_v[1]);
	}
	return bsim_atomic_file_commit(&o, err);
}

/* Reads runs back from dir's map_HASH.exits.csv: 1 if there, 0 if absent,
 * -1 with err naming the line if malformed. */
static int runs_read(const char *dir, uint64_t key, markov_run *runs, int nb, int T,
                     bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	snprintf(path, sizeof path, "%s/map_%016llx.exits.csv", dir, (unsigned long long)key);
	FILE *probe = fopen(path, "r");
	if (!probe)
		return errno == ENOENT ? 0 : -1;
	fclose(probe);
	file_text t;
	/* a row is at most 11 numbers of 25 characters */
	if (bsim_file_read(path, "a map's exits", ((double)nb * T + 1.0) * 320.0, NULL, &t, err) !=
	    BSIM_OK)
		return -1;
	char *line = t.text, *nl = strchr(line, '\n');
	long u = 0, lineno = 1;
	int bad = !nl || (*nl = '\0', strcmp(line, EXITS_HEADER) != 0);
	while (!bad && u < (long)nb * T) {
		line = nl + 1;
		lineno++;
		nl = strchr(line, '\n');
		if (!nl) {
			bad = 1;
			break;
		}
		*nl = '\0';
		markov_run *r = &runs[u];
		char *c = line, *end;
		long entry = strtol(c, &end, 10), trial = -1, ex = -1;
		double *d[8] = {&r->x[0],      &r->x[1],      &r->v[0],      &r->v[1],
		                &r->exit_x[0], &r->exit_x[1], &r->exit_v[0], &r->exit_v[1]};
		bad = end == c || *end != ',';
		if (!bad)
			trial = strtol(c = end + 1, &end, 10), bad = end == c || *end != ',';
		for (int k = 0; k < 4 && !bad; k++)
			*d[k] = strtod(c = end + 1, &end), bad = end == c || *end != ',';
		if (!bad)
			ex = strtol(c = end + 1, &end, 10), bad = end == c || *end != ',';
		for (int k = 4; k < 8 && !bad; k++)
			*d[k] = strtod(c = end + 1, &end),
			bad = end == c || *end != (k < 7 ? ',' : '\0');
		bad = bad || entry != u / T || trial != u % T || ex < 0 || ex >= nb;
		r->exit = (int)ex;
		u++;
	}
	if (!bad && *(nl + 1))
		bad = 1, lineno++;
	bsim_file_text_free(&t);
	if (bad) {
		bsim_error_set(err, BSIM_EINPUT,
		               "%s:%ld: expected a row entry,trial,x,y,vx,vy,exit,exit_x,exit_y,"
		               "exit_vx,exit_vy for each of the %d bins x %d trials in order",
		               path, lineno, nb, T);
		return -1;
	}
	return 1;
}

/* A pool's bins from the exits of n_src run arrays with weights w (NULL:
 * all 1), exits into bin b in (source, trial) order. */
static int pool_fill(markov_pool *p, const markov_run *const *src, const double *const *w,
                     int n_src, int nb, int T, int pass)
{
	const long units = (long)nb * T;
	memset(p, 0, sizeof *p);
	p->pass = pass;
	p->first = calloc((size_t)nb + 1, sizeof *p->first);
	p->run = malloc((size_t)(units * n_src) * sizeof *p->run);
	p->cw = malloc((size_t)(units * n_src) * sizeof *p->cw);
	int *fill = calloc((size_t)nb, sizeof *fill);
	if (!p->first || !p->run || !p->cw || !fill) {
		free(fill);
		return -1;
	}
	for (int i = 0; i < n_src; i++)
		for (long u = 0; u < units; u++)
			if (src[i][u].exit > 0)
				p->first[src[i][u].exit + 1]++;
	for (int b = 0; b < nb; b++)
		p->first[b + 1] += p->first[b];
	for (int i = 0; i < n_src; i++)
		for (long u = 0; u < units; u++) {
			int b = src[i][u].exit;
			if (b <= 0)
				continue;
			int j = p->first[b] + fill[b]++;
			p->run[j] = &src[i][u];
			p->cw[j] = (j > p->first[b] ? p->cw[j - 1] : 0.0) + (w ? w[i][u] : 1.0);
		}
	free(fill);
	return 0;
}

/* The pool of a pass's runs: the exits into each bin, each weighted by the
 * expected visits of its entry bin in the first BSIM_MARKOV_SELF_GATES
 * gates of a field of this gate alone, started at the start (bin 0). */
static int pool_init(markov_pool *p, const markov_run *runs, int nb, int T, int pass)
{
	const long units = (long)nb * T;
	double *visits = calloc((size_t)nb, sizeof *visits), *y = calloc((size_t)nb, sizeof *y),
	       *y1 = calloc((size_t)nb, sizeof *y1), *w = malloc((size_t)units * sizeof *w);
	int rc = -1;
	if (visits && y && y1 && w) {
		y[0] = 1.0;
		for (int g = 0; g < BSIM_MARKOV_SELF_GATES; g++) {
			for (int a = 0; a < nb; a++)
				visits[a] += y[a];
			memset(y1, 0, (size_t)nb * sizeof *y1);
			for (long u = 0; u < units; u++)
				if (runs[u].exit > 0)
					y1[runs[u].exit] += y[u / T] / T;
			double *tmp = y;
			y = y1;
			y1 = tmp;
		}
		for (long u = 0; u < units; u++)
			w[u] = visits[u / T];
		const double *wp = w;
		rc = pool_fill(p, &runs, &wp, 1, nb, T, pass);
	}
	free(visits);
	free(y);
	free(y1);
	free(w);
	return rc;
}

static void pool_free(markov_pool *p)
{
	free(p->first);
	free(p->run);
	free(p->cw);
}

/* Map m's key and key text for pass q of def. */
static int pass_map(bsim_markov_map *q_map, const bsim_scene *lattice, const bsim_markov_def *def,
                    const bsim_backend *be, const bsim_options *opts, const bsim_markov_map *m,
                    int q)
{
	bsim_markov_def dq = *def;
	dq.self_passes = q;
	if (q == 0)
		dq.self_entries = 1; /* pass 0 is the same map either way */
	memset(q_map, 0, sizeof *q_map);
	q_map->k[0] = m->k[0];
	q_map->k[1] = m->k[1];
	q_map->n_bins = m->n_bins;
	q_map->trials = m->trials;
	q_map->start_trials = m->start_trials;
	q_map->key_text = bsim_markov_key_text(lattice, &dq, be, opts, m->k);
	if (!q_map->key_text)
		return -1;
	q_map->key = bsim_markov_key(q_map->key_text);
	return 0;
}

static void pass_map_free(bsim_markov_map *q)
{
	free(q->key_text);
	bsim_markov_counts_free(q);
	free(q->hold_exit);
	free(q->hold_steps);
}

/* The last pass below def->self_passes whose map and exits are in dir,
 * read into runs (if not NULL): its number, -1 if none, -2 with err if its
 * exits are malformed. */
static int last_cached(const bsim_scene *lattice, const bsim_markov_def *def,
                       const bsim_backend *be, const bsim_options *opts, const bsim_markov_map *m,
                       const char *dir, markov_run *runs, bsim_markov_map *cost, bsim_error *err)
{
	for (int q = def->self_passes - 1; q >= 0 && dir; q--) {
		bsim_markov_map mq;
		int got = -1;
		if (pass_map(&mq, lattice, def, be, opts, m, q) == 0) {
			bsim_error ignored;
			got = bsim_markov_map_read(dir, &mq, &ignored) == 1
			              ? runs ? runs_read(dir, mq.key, runs, m->n_bins, m->trials,
			                                 err)
			                     : 1
			              : 0;
		}
		if (got == 1 && cost) { /* what it and the passes before it cost */
			cost->cost = mq.cost;
			cost->steps = mq.steps;
		}
		pass_map_free(&mq);
		if (got == 1)
			return q;
		if (got < 0)
			return -2;
	}
	return -1;
}

void bsim_markov_map_take_counts(bsim_markov_map *to, bsim_markov_map *from)
{
	bsim_markov_counts_free(to);
	to->count_first = from->count_first;
	to->count_exit = from->count_exit;
	to->count_n = from->count_n;
	from->count_first = from->count_exit = from->count_n = NULL;
	free(to->hold_exit);
	free(to->hold_steps);
	to->hold_exit = from->hold_exit;
	to->hold_steps = from->hold_steps;
	from->hold_exit = from->hold_steps = NULL;
}

int bsim_markov_self_passes_left(const bsim_scene *lattice, const bsim_markov_def *def,
                                 const bsim_backend *be, const bsim_options *opts,
                                 const bsim_markov_map *m, const char *dir)
{
	int q = last_cached(lattice, def, be, opts, m, dir, NULL, NULL, NULL);
	return def->self_passes - (q < 0 ? -1 : q);
}

int bsim_markov_self_simulate(const bsim_scene *lattice, const bsim_markov_def *def,
                              const bsim_backend *be, const bsim_options *opts, bsim_markov_map *m,
                              const char *dir, const char *stage, long *done, long total,
                              bsim_error *err)
{
	const int nb = m->n_bins, T = m->trials;
	const long units = (long)nb * T;
	markov_run *prev = calloc((size_t)units, sizeof *prev),
	           *cur = calloc((size_t)units, sizeof *cur);
	if (!prev || !cur) {
		free(prev);
		free(cur);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	int rc = BSIM_OK;
	m->cost = 0.0;
	m->steps = 0;
	int q0 = last_cached(lattice, def, be, opts, m, dir, prev, m, err) + 1;
	/* each pass's .cost holds it and every pass before it */
	double cum = m->cost;
	long long cum_steps = m->steps;
	if (q0 < 0)
		rc = BSIM_EINPUT; /* a cached pass whose exits are malformed: err says which */
	for (int q = q0; q <= def->self_passes && rc == BSIM_OK; q++) {
		bsim_markov_map mq;
		markov_pool pool;
		int have_pool = q > 0;
		if (pass_map(&mq, lattice, def, be, opts, m, q) != 0 ||
		    (have_pool && pool_init(&pool, prev, nb, T, q) != 0)) {
			pass_map_free(&mq);
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
			break;
		}
		clock_t c0 = clock();
		rc = def->stop && *def->stop
		             ? BSIM_ESTOPPED
		             : bsim_markov_map_simulate_runs(lattice, def, be, opts, &mq,
		                                             have_pool ? &pool : NULL, NULL, cur,
		                                             done, total, err);
		mq.seconds = (double)(clock() - c0) / CLOCKS_PER_SEC;
		cum += mq.seconds;
		cum_steps += mq.steps;
		mq.cost = cum;
		mq.steps = cum_steps;
		if (have_pool)
			pool_free(&pool);
		if (rc == BSIM_OK && q < def->self_passes)
			rc = bsim_markov_map_write(stage, &mq, &def->bins, err);
		if (rc == BSIM_OK)
			rc = runs_write(stage, mq.key, cur, nb, T, err);
		if (rc == BSIM_OK && q == def->self_passes) {
			bsim_markov_map_take_counts(m, &mq);
		}
		pass_map_free(&mq);
		markov_run *tmp = prev;
		prev = cur;
		cur = tmp;
	}
	free(prev);
	free(cur);
	/* the caller adds this build's CPU time */
	m->steps = cum_steps;
	return rc;
}

int bsim_markov_self_copy(const bsim_scene *lattice, const bsim_markov_def *def,
                          const bsim_backend *be, const bsim_options *opts,
                          const bsim_markov_map *m, int last, const char *const *dirs, int n_dirs,
                          const char *stage, bsim_error *err)
{
	const int nb = m->n_bins, T = m->trials;
	markov_run *runs = calloc((size_t)nb * T, sizeof *runs);
	int rc = runs ? BSIM_OK : bsim_error_set(err, BSIM_EFAIL, "out of memory");
	for (int q = 0; q <= last && rc == BSIM_OK; q++) {
		bsim_markov_map mq;
		if (pass_map(&mq, lattice, def, be, opts, m, q) != 0) {
			pass_map_free(&mq);
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
			break;
		}
		/* every pass's map but the final one (m, the caller's) and every
		 * pass's exits, from the first directory that has both */
		int got = 0;
		for (int d = 0; d < n_dirs && got == 0; d++) {
			if (!dirs[d])
				continue;
			got = q < def->self_passes ? bsim_markov_map_read(dirs[d], &mq, err) : 1;
			if (got == 1)
				got = runs_read(dirs[d], mq.key, runs, nb, T, err);
		}
		if (got == 0)
			rc = bsim_error_set(
			        err, BSIM_EINPUT,
			        "%s: pass %d of the map for k = %g, %g N m/rad "
			        "(map_%016llx: its map and exits) is missing: not a part "
			        "of this build",
			        dirs[0], q, m->k[0], m->k[1], (unsigned long long)mq.key);
		else if (got < 0)
			rc = BSIM_EINPUT; /* err names the file and line */
		if (rc == BSIM_OK && q < def->self_passes)
			rc = bsim_markov_map_write(stage, &mq, &def->bins, err);
		if (rc == BSIM_OK)
			rc = runs_write(stage, mq.key, runs, nb, T, err);
		pass_map_free(&mq);
	}
	free(runs);
	return rc;
}

/* The passes every one of the n maps has in dir: the first pass some map
 * lacks (0 if none, or dir NULL), each map's runs of the pass before it
 * read into runs[i] (runs NULL: each read and checked, then dropped) and
 * what that pass and those before it cost into prior[i] (prior NULL: not
 * kept); -1 with err if a cached pass's exits are malformed. */
static int passes_cached(const bsim_scene *lattice, const bsim_markov_def *def,
                         const bsim_backend *be, const bsim_options *opts,
                         const bsim_markov_map *maps, int n, const char *dir, markov_run **runs,
                         bsim_markov_map *prior, bsim_error *err)
{
	const long units = (long)maps[0].n_bins * maps[0].trials;
	markov_run *scratch = dir && !runs ? calloc((size_t)units, sizeof *scratch) : NULL;
	if (dir && !runs && !scratch) {
		bsim_error_set(err, BSIM_EFAIL, "out of memory");
		return -1;
	}
	int first = 0;
	for (int q = def->self_passes - 1; q >= 0 && dir && !first; q--) {
		int all = 1;
		for (int i = 0; i < n && all; i++) {
			bsim_markov_def dq = *def;
			dq.self_passes = q + 1;
			int got = last_cached(lattice, &dq, be, opts, &maps[i], dir,
			                      runs ? runs[i] : scratch, prior ? &prior[i] : NULL,
			                      err);
			if (got == -2) {
				free(scratch);
				return -1;
			}
			all = got == q;
		}
		if (all)
			first = q + 1;
	}
	free(scratch);
	return first;
}

int bsim_markov_flow_round(const bsim_scene *lattice, const bsim_markov_def *def,
                           const bsim_backend *be, const bsim_options *opts,
                           const bsim_markov_map *maps, int n, const char *dir, bsim_error *err)
{
	/* as bsim_markov_flow_simulate finds the passes it starts after */
	return passes_cached(lattice, def, be, opts, maps, n, dir, NULL, NULL, err);
}

/* ---- flow-weighted passes over a field ---- */

/* Where exit bin x (> 0) of gate g leads in a cols x rows field: the gate
 * entered, or -1 past the field's edge (the end, a side) and for a body
 * leaving row 0 downwards (the chain's re-entry of row 0, whose state is
 * not the exit's). */
static int next_gate(int g, int x, int cols, int rows, int per_edge)
{
	int ix = g % cols, iy = g / cols;
	switch (BSIM_EDGE_BOTTOM + (x - 1) / per_edge) {
	case BSIM_EDGE_BOTTOM: /* into the gate above */
		iy++;
		break;
	case BSIM_EDGE_TOP:
		iy--;
		break;
	case BSIM_EDGE_LEFT: /* into the gate on the right */
		ix++;
		break;
	default:
		ix--;
		break;
	}
	return ix < 0 || ix >= cols || iy < 0 || iy >= rows ? -1 : iy * cols + ix;
}

/* visits[g * nb + a]: the expected visits of (gate g, entry bin a) in the
 * chain of the field from runs (the maps' single gates), by the series
 * from the start until less than 1e-12 is left in the field. The row-0
 * re-entry is followed as the chain follows it. */
static void field_visits(const markov_run *const *runs, const int *gate_map, int cols, int rows,
                         int start_gate, int nb, int T, double *visits)
{
	const int G = cols * rows, per_edge = (nb - 1) / 4;
	double *y = calloc((size_t)G * nb, sizeof *y), *y1 = calloc((size_t)G * nb, sizeof *y1);
	if (!y || !y1) {
		free(y);
		free(y1);
		return;
	}
	y[start_gate * nb] = 1.0;
	for (int it = 0; it < 100000; it++) {
		double left = 0.0;
		for (long i = 0; i < (long)G * nb; i++) {
			visits[i] += y[i];
			left += y[i];
		}
		if (left < 1e-12)
			break;
		memset(y1, 0, (size_t)G * nb * sizeof *y1);
		for (int g = 0; g < G; g++) {
			const markov_run *r = runs[gate_map[g]];
			for (long u = 0; u < (long)nb * T; u++) {
				const double pa = y[g * nb + u / T];
				const int x = r[u].exit;
				if (pa == 0.0 || x == 0)
					continue;
				int h = next_gate(g, x, cols, rows, per_edge), xb = x;
				if (h < 0 && g / cols == 0 && (x - 1) / per_edge == 3) {
					h = g; /* row 0 downwards: in again through its bottom */
					xb = x - 3 * per_edge;
				}
				if (h >= 0)
					y1[h * nb + xb] += pa / T;
			}
		}
		double *tmp = y;
		y = y1;
		y1 = tmp;
	}
	free(y);
	free(y1);
}

/* Every map's runs of a pass from the part that simulated it: map i of
 * the lattice is the build's map part_first + i (bsim_markov_def). */
static int runs_exchange(const bsim_markov_def *def, markov_run **runs, int n, long units,
                         bsim_error *err)
{
	int *owner = malloc((size_t)n * sizeof *owner);
	if (!owner)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	for (int i = 0; i < n; i++)
		owner[i] = (def->part_first + i) % def->parts;
	int rc = def->pass_exchange(def->pass_exchange_user, (void *const *)runs,
	                            (size_t)units * sizeof **runs, owner, n, err);
	free(owner);
	return rc;
}

int bsim_markov_flow_simulate(const bsim_scene *lattice, const bsim_markov_def *def,
                              const bsim_backend *be, const bsim_options *opts,
                              bsim_markov_map *maps, int n, const char *have, const char *dir,
                              const char *stage, long *done, long total, bsim_error *err)
{
	const bsim_lattice_def *l = &lattice->lattice;
	const int nb = maps[0].n_bins, T = maps[0].trials, cols = l->columns, rows = l->rows;
	const int G = cols * rows, per_edge = (nb - 1) / 4;
	const long units = (long)nb * T;
	markov_run **prev = calloc((size_t)n, sizeof *prev), **cur = calloc((size_t)n, sizeof *cur);
	double **w = calloc((size_t)n, sizeof *w);
	int *gate_map = malloc((size_t)G * sizeof *gate_map);
	double *visits = malloc((size_t)G * nb * sizeof *visits);
	int rc = prev && cur && w && gate_map && visits ? BSIM_OK : BSIM_EFAIL;
	for (int i = 0; i < n && rc == BSIM_OK; i++) {
		prev[i] = calloc((size_t)units, sizeof **prev);
		cur[i] = calloc((size_t)units, sizeof **cur);
		w[i] = malloc((size_t)units * sizeof **w);
		if (!prev[i] || !cur[i] || !w[i])
			rc = BSIM_EFAIL;
	}
	if (rc != BSIM_OK)
		bsim_error_set(err, BSIM_EFAIL, "out of memory");
	for (int iy = 0; iy < rows && rc == BSIM_OK; iy++)
		for (int ix = l->ix_min; ix <= l->ix_max; ix++) {
			double k[2] = {lattice->beams[bsim_lattice_beam(l, ix, iy, 0)].stiffness,
			               lattice->beams[bsim_lattice_beam(l, ix, iy, 1)].stiffness};
			int j = 0;
			while (j < n && !(maps[j].k[0] == k[0] && maps[j].k[1] == k[1]))
				j++;
			gate_map[iy * cols + ix - l->ix_min] = j;
		}
	int sx, sy;
	bsim_lattice_gate_at(lattice, lattice->body.start, &sx, &sy);
	const int start_gate = sy * cols + sx - l->ix_min;
	/* The last pass every map has in dir; what that pass and those before
	 * it cost, into the cost of each map to build (the caller adds this
	 * build's CPU time). */
	int q0 = 0;
	/* Parts that meet after each pass start together from pass 0: the
	 * same passes on every part, whatever each part's directory holds. */
	const int meet = def->parts > 1 && def->pass_exchange;
	bsim_markov_map *prior = calloc((size_t)n, sizeof *prior);
	if (!prior)
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	if (rc == BSIM_OK && !meet &&
	    (q0 = passes_cached(lattice, def, be, opts, maps, n, dir, prev, prior, err)) < 0) {
		rc = BSIM_EINPUT; /* a cached pass's exits malformed: err says which */
		q0 = 0;
	}
	for (int i = 0; i < n && prior; i++)
		if (!have[i]) {
			maps[i].cost = q0 > 0 ? prior[i].cost : 0.0;
			maps[i].steps = q0 > 0 ? prior[i].steps : 0;
		}
	free(prior);
	/* one pass of a job array's round, or all those left */
	const int q_end = def->one_pass ? q0 : def->self_passes;
	for (int q = q0; q <= q_end && rc == BSIM_OK; q++) {
		if (q > 0) {
			memset(visits, 0, (size_t)G * nb * sizeof *visits);
			field_visits((const markov_run *const *)prev, gate_map, cols, rows,
			             start_gate, nb, T, visits);
		}
		for (int b = 0; b < n && rc == BSIM_OK; b++) {
			markov_pool pool;
			if (q == def->self_passes && have[b])
				continue; /* its map is in the cache */
			if (maps[b].elsewhere)
				continue; /* another part's: its runs come by pass_exchange */
			if (q > 0) {
				/* each exit's weight: its entry bin's visits in the
				 * gates of its map whose neighbour across it is map b's */
				for (int i = 0; i < n; i++)
					memset(w[i], 0, (size_t)units * sizeof **w);
				for (int g = 0; g < G; g++) {
					const int a = gate_map[g];
					for (long u = 0; u < units; u++) {
						const double v = visits[g * nb + u / T];
						const int x = prev[a][u].exit;
						if (v == 0.0 || x == 0)
							continue;
						int h = next_gate(g, x, cols, rows, per_edge);
						if (h >= 0 && gate_map[h] == b)
							w[a][u] += v / T;
					}
				}
				if (pool_fill(&pool, (const markov_run *const *)prev,
				              (const double *const *)w, n, nb, T, q) != 0) {
					pool_free(&pool);
					rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
					break;
				}
			}
			bsim_markov_map mq;
			if (pass_map(&mq, lattice, def, be, opts, &maps[b], q) != 0) {
				pass_map_free(&mq);
				if (q > 0)
					pool_free(&pool);
				rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
				break;
			}
			clock_t c0 = clock();
			rc = def->stop && *def->stop
			             ? BSIM_ESTOPPED
			             : bsim_markov_map_simulate_runs(lattice, def, be, opts, &mq,
			                                             q > 0 ? &pool : NULL, NULL,
			                                             cur[b], done, total, err);
			mq.seconds = (double)(clock() - c0) / CLOCKS_PER_SEC;
			maps[b].seconds += mq.seconds;
			maps[b].steps += mq.steps;
			/* each pass's .cost: it and every pass before it */
			mq.cost = maps[b].cost + maps[b].seconds;
			mq.steps = maps[b].steps;
			if (q > 0)
				pool_free(&pool);
			const int last = q == def->self_passes;
			if (rc == BSIM_OK && !last)
				rc = bsim_markov_map_write(stage, &mq, &def->bins, err);
			if (rc == BSIM_OK && (!last || !have[b]))
				rc = runs_write(stage, mq.key, cur[b], nb, T, err);
			if (rc == BSIM_OK && last) {
				bsim_markov_map_take_counts(&maps[b], &mq);
			}
			pass_map_free(&mq);
		}
		if (meet && q < def->self_passes && rc == BSIM_OK)
			rc = runs_exchange(def, cur, n, units, err);
		markov_run **tmp = prev;
		prev = cur;
		cur = tmp;
	}
	for (int i = 0; i < n; i++) {
		free(prev ? prev[i] : NULL);
		free(cur ? cur[i] : NULL);
		free(w ? w[i] : NULL);
	}
	free(prev);
	free(cur);
	free(w);
	free(gate_map);
	free(visits);
	return rc;
}
