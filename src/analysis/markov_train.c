/* A lattice's gate kinds (its stiffness pairs), and the training field of
 * a map build (beamsim/markov.h, train_trials): a
 * BSIM_MARKOV_TRAIN_SIZE x BSIM_MARKOV_TRAIN_SIZE field of the lattice's
 * gate kinds laid out at random, run under the essay's protocol, whose gate
 * entries are the states the maps' single gates start from. The field
 * depends on the lattice only through its set of gate kinds (sorted, so
 * not on the order they are met in) and its physics, so the maps stay of
 * the physics: every layout of the same kinds shares them. */
#define _POSIX_C_SOURCE 200809L

#include "analysis/markov_internal.h"

#include <gsl/gsl_rng.h>
#include <limits.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/lattice.h"
#include "beamsim/limits.h"
#include "beamsim/schedule.h"
#include "model/scene_internal.h"
#include "util/hash.h"

/* Salt of the training field's layout and schedules. */
#define TRAIN_SALT 0x747261696e696e67ULL

/* The distinct (left, right) stiffness pairs of the lattice's gates, in
 * the order first met (row 0 first); returns how many, -1 out of memory. */
int bsim_markov_lattice_pairs(const bsim_scene *s, double (**pairs)[2])
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

static int pair_less(const void *a, const void *b)
{
	const double *p = a, *q = b;
	return p[0] != q[0] ? (p[0] > q[0]) - (p[0] < q[0]) : (p[1] > q[1]) - (p[1] < q[1]);
}

int bsim_markov_lattice_kinds(const bsim_scene *lattice, double (**kinds)[2])
{
	const int n = bsim_markov_lattice_pairs(lattice, kinds);
	if (n > 0)
		qsort(*kinds, (size_t)n, sizeof **kinds, pair_less);
	return n;
}

const char *bsim_markov_train_label(const bsim_scene *lattice, const bsim_markov_def *def,
                                    char *buf, size_t size)
{
	const int trials = def->train_trials;
	/* crossings topped up to every bin's trials name no "per" (the key
	 * such maps had) */
	char how[48] = "";
	if (bsim_markov_def_crossings(def) && def->trials_per_crossing > 0)
		snprintf(how, sizeof how, " crossings per %d", def->trials_per_crossing);
	else if (bsim_markov_def_crossings(def))
		snprintf(how, sizeof how, " crossings");
	double(*kinds)[2] = NULL;
	const int n = lattice ? bsim_markov_lattice_kinds(lattice, &kinds) : 0;
	uint64_t h = HASH_FNV1A64_SEED;
	for (int i = 0; i < n; i++)
		h = bsim_hash_fnv1a64(kinds[i], sizeof kinds[i], h);
	free(kinds);
	if (n > 0)
		snprintf(buf, size, "train %d%s kinds %d %016llx", trials, how, n,
		         (unsigned long long)h);
	else
		snprintf(buf, size, "train %d%s", trials, how);
	return buf;
}

/* The training field of lattice into s: its physics, gate and body start
 * (in the start gate's frame, moved to gate (0, 0)), every gate a kind of
 * lattice drawn at random (from seed) but the start gate's, kind start
 * where that is not NULL, the essay's protocol and a lattice's ends. */
static int train_scene(const bsim_scene *lattice, uint64_t seed, const double *start, bsim_scene *s,
                       bsim_error *err)
{
	double(*kinds)[2] = NULL;
	const int n = bsim_markov_lattice_kinds(lattice, &kinds);
	const int size = BSIM_MARKOV_TRAIN_SIZE, gates = size * size;
	double *k = malloc(2 * (size_t)gates * sizeof *k);
	gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
	int rc = n > 0 && k && rng && bsim_scene_copy(s, lattice) == BSIM_OK ? BSIM_OK : BSIM_EFAIL;
	if (rc == BSIM_OK) {
		gsl_rng_set(rng, bsim_schedule_seed_mix(seed, 0, 0));
		for (int g = 0; g < gates; g++) {
			const int j = (int)gsl_rng_uniform_int(rng, (unsigned long)n);
			k[g] = kinds[j][0];
			k[gates + g] = kinds[j][1];
		}
		if (start) { /* gate (0, 0): row 0's middle */
			k[size / 2] = start[0];
			k[gates + size / 2] = start[1];
		}
		int ix, iy;
		bsim_lattice_gate_at(lattice, lattice->body.start, &ix, &iy);
		s->body.start[0] -= lattice->lattice.width * ix;
		s->body.start[1] -= lattice->lattice.depth * iy;
		bsim_lattice_def *l = &s->lattice;
		l->rows = size;
		l->ix_min = -(size / 2);
		l->ix_max = size / 2;
		l->protocol = BSIM_PROTOCOL_ESSAY;
		l->stiffness_file[0] = '\0';
		rc = bsim_lattice_build(s, k, k + gates);
	}
	if (rc == BSIM_OK) {
		const int gate_steps = lattice->gate_steps;
		bsim_scene_lattice_defaults(s);
		if (gate_steps > 0) /* the lattice's own stuck limit, a gate's */
			s->gate_steps = gate_steps;
		/* a body stuck in no row crosses them all: a gate's limit a row,
		 * within the beam-steps a trial may take (a trial that reaches it
		 * ends, its entries kept) */
		const double most = bsim_limits_get()->beam_steps / s->n_beams;
		s->max_steps = (int)fmin((double)s->gate_steps * s->lattice.rows, most);
		s->path[0] = '\0'; /* built here, from the lattice's file */
		snprintf(s->name, sizeof s->name, "the training field of %.90s", lattice->name);
		rc = bsim_scene_validate(s, err);
	} else {
		bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	gsl_rng_free(rng);
	free(k);
	free(kinds);
	return rc;
}

void bsim_markov_crossings_free(markov_crossings *c)
{
	free(c->k);
	free(c->entry);
	free(c->exit);
	free(c->steps);
	memset(c, 0, sizeof *c);
}

/* Whether the exit of trial log g's entry j is known: the gate was left
 * into the next entry, or the trial's last gate held it gate_steps steps
 * (res: stuck); *steps the time steps it spent there (gate_steps if
 * stuck). A gate the trial left the field from, or ended in otherwise, has
 * no known exit. */
static int exit_known(const bsim_scene *s, const bsim_trial_log *g, const bsim_trial_result *res,
                      int j, int *steps)
{
	const bsim_gate_entry *e = &g->entries[j];
	*steps = s->gate_steps;
	if (j + 1 < g->n_entries) {
		const int next = g->entries[j + 1].step;
		/* a gate crossed at a corner, within one step, held it one */
		*steps = next > e->step ? next - e->step : 1;
		return 1;
	}
	return res->outcome == BSIM_STUCK && res->steps_run - e->step >= s->gate_steps;
}

/* The stiffness pair of the lattice s's gate (ix, iy) into k. */
static void gate_kind(const bsim_scene *s, int ix, int iy, double k[2])
{
	for (int side = 0; side < 2; side++)
		k[side] = s->beams[bsim_lattice_beam(&s->lattice, ix, iy, side)].stiffness;
}

/* Trial log g's crossings (but the start gate's) appended to c, whose
 * arrays hold *cap: the gate entered by each entry but the last left into
 * the next entry's bin; the last, in a trial stuck there for gate_steps
 * (res), was stuck; else its exit is not known. 0, or -1 out of memory. */
static int crossings_push(markov_crossings *c, long *cap, const bsim_scene *s,
                          const bsim_markov_def *def, const bsim_trial_log *g,
                          const bsim_trial_result *res)
{
	const bsim_lattice_def *l = &s->lattice;
	for (int j = 1; j < g->n_entries; j++) {
		const bsim_gate_entry *e = &g->entries[j],
		                      *next = j + 1 < g->n_entries ? e + 1 : NULL;
		int steps;
		if (!exit_known(s, g, res, j, &steps))
			break;
		const int exit = next ? bsim_markov_bin_of(&def->bins, l, (int)next->edge,
		                                           next->pos, next->v)
		                      : 0;
		if (c->n == *cap) {
			const long more = *cap ? 2 * *cap : 1024;
			double(*k)[2] = realloc(c->k, (size_t)more * sizeof *k);
			int ok = k != NULL;
			if (k)
				c->k = k;
			int **a[3] = {&c->entry, &c->exit, &c->steps};
			for (int i = 0; i < 3; i++) {
				int *p = realloc(*a[i], (size_t)more * sizeof *p);
				if (p)
					*a[i] = p;
				ok = ok && p;
			}
			if (!ok)
				return -1;
			*cap = more;
		}
		gate_kind(s, e->ix, e->iy, c->k[c->n]);
		c->entry[c->n] = bsim_markov_bin_of(&def->bins, l, (int)e->edge, e->pos, e->v);
		c->exit[c->n] = exit;
		c->steps[c->n] = steps;
		c->n++;
	}
	return 0;
}

/* A layout of its own for each trial of a training field: every gate one
 * of n kinds at random, from (seed, t), but the start gate (0, 0), of kind
 * start. */
typedef struct train_layout {
	double (*kinds)[2];
	int n;
	uint64_t seed;
	const double *start;
} train_layout;

/* Trial t's layout of L into s's beams (s the training field); 0, or -1
 * out of memory. */
static int layout_draw(const train_layout *L, long t, bsim_scene *s)
{
	gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
	if (!rng)
		return -1;
	gsl_rng_set(rng, bsim_schedule_seed_mix(L->seed, 2, (uint64_t)t));
	const bsim_lattice_def *l = &s->lattice;
	for (int iy = 0; iy < l->rows; iy++)
		for (int ix = l->ix_min; ix <= l->ix_max; ix++) {
			const int j = (int)gsl_rng_uniform_int(rng, (unsigned long)L->n);
			const double *k = ix == 0 && iy == 0 ? L->start : L->kinds[j];
			for (int side = 0; side < 2; side++)
				s->beams[bsim_lattice_beam(l, ix, iy, side)].stiffness = k[side];
		}
	gsl_rng_free(rng);
	return 0;
}

/* T trials of the training field s (trial t seeded by seed and t; laid
 * out by L where that is not NULL) into logs and results, on def->threads
 * threads (the same for any number), stopped by def->stop, counted by
 * def->train_progress. BSIM_EFAIL naming the first unstable trial in trial
 * order, BSIM_ESTOPPED when stopped. */
static int train_trials(const bsim_scene *s, const train_layout *L, uint64_t seed, long T,
                        const bsim_markov_def *def, const bsim_backend *be,
                        const bsim_options *opts, bsim_trial_log *logs, bsim_trial_result *results,
                        bsim_error *err)
{
	int rc = BSIM_OK;
	/* the first failure in trial order, whatever the threads */
	long first = T, done = 0;
	const long every = T >= 100 ? T / 100 : 1; /* trials between progress calls */
	bsim_error fail = {0};
	int stopped = 0;
	const int threads = def->threads > 0 ? def->threads : omp_get_max_threads();
#pragma omp parallel num_threads(threads)
	{
		bsim_trial_runner *r = bsim_trial_runner_alloc();
		bsim_trial_log *log = bsim_trial_log_alloc();
		/* the thread's own field, its layout redrawn for each trial */
		bsim_scene mine;
		memset(&mine, 0, sizeof mine);
		const int copied = L && bsim_scene_copy(&mine, s) == BSIM_OK;
		const bsim_scene *field = L ? &mine : s;
#pragma omp for schedule(dynamic, 4)
		for (long t = 0; t < T; t++) {
			bsim_error e = {0};
			int trc = BSIM_OK;
			if (def->stop && *def->stop) {
#pragma omp atomic write
				stopped = 1;
				continue;
			}
			bsim_trial_result res;
			bsim_recorder rec = {.stride = 1, .log = log};
			if (!r || !log || (L && (!copied || layout_draw(L, t, &mine))))
				trc = bsim_error_set(&e, BSIM_EFAIL, "out of memory");
			else
				trc = bsim_trial_run(r, field, be, opts,
				                     bsim_schedule_seed_mix(seed, 1, (uint64_t)t),
				                     &rec, &res, &e);
			if (trc == BSIM_OK && res.outcome == BSIM_UNSTABLE) {
				char why[160];
				bsim_trial_instability_text(&res, s->dt, why, sizeof why);
				trc = bsim_error_set(&e, BSIM_EFAIL,
				                     "trial %ld of a training field became "
				                     "unstable: %s",
				                     t, why);
			}
			if (trc == BSIM_OK && bsim_trial_log_copy(&logs[t], log) != BSIM_OK)
				trc = bsim_error_set(&e, BSIM_EFAIL, "out of memory");
			if (trc == BSIM_OK)
				results[t] = res;
			bsim_markov_trial_end(t, trc != BSIM_OK ? &e : NULL, &first, &fail, &done,
			                      T, every, def->train_progress,
			                      def->train_progress_user);
		}
		bsim_trial_log_free(log);
		bsim_trial_runner_free(r);
		bsim_scene_free(&mine);
	}
	if (stopped)
		rc = bsim_error_set(err, BSIM_ESTOPPED, "stopped in a training field");
	else if (first < T) {
		rc = BSIM_EFAIL;
		if (err)
			*err = fail;
	}
	return rc;
}

/* The training field s and its trials' logs and results (*logs, *results
 * malloc'd, T each; freed by train_free), as train_trials runs them. */
static int train_field(const bsim_scene *lattice, uint64_t seed, const double *start,
                       const train_layout *L, long T, const bsim_markov_def *def,
                       const bsim_backend *be, const bsim_options *opts, bsim_scene *s,
                       bsim_trial_log **logs, bsim_trial_result **results, bsim_error *err)
{
	memset(s, 0, sizeof *s);
	*logs = NULL;
	*results = NULL;
	int rc = train_scene(lattice, seed, start, s, err);
	if (rc == BSIM_OK) {
		*logs = calloc((size_t)T, sizeof **logs);
		*results = calloc((size_t)T, sizeof **results);
		if (!*logs || !*results)
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	if (rc == BSIM_OK)
		rc = train_trials(s, L, seed, T, def, be, opts, *logs, *results, err);
	return rc;
}

static void train_free(bsim_scene *s, bsim_trial_log *logs, bsim_trial_result *results, long T)
{
	for (long t = 0; logs && t < T; t++)
		bsim_trial_log_clear(&logs[t]);
	free(logs);
	free(results);
	bsim_scene_free(s);
}

int bsim_markov_train_run(const bsim_scene *lattice, const bsim_markov_def *def,
                          const bsim_backend *be, const bsim_options *opts,
                          bsim_markov_entries *out, markov_crossings *cx, long long *steps,
                          bsim_error *err)
{
	memset(out, 0, sizeof *out);
	if (cx)
		memset(cx, 0, sizeof *cx);
	bsim_scene s;
	bsim_trial_log *logs;
	bsim_trial_result *results;
	const long T = def->train_trials;
	int rc = train_field(lattice, def->seed ^ TRAIN_SALT, NULL, NULL, T, def, be, opts, &s,
	                     &logs, &results, err);
	/* every entry but the start's, and every crossing, in trial order */
	int cap = 0;
	long cx_cap = 0;
	*steps = 0;
	for (long t = 0; rc == BSIM_OK && t < T; t++) {
		*steps += results[t].steps_run;
		for (int j = 0; rc == BSIM_OK && j < logs[t].n_entries; j++) {
			const bsim_gate_entry *g = &logs[t].entries[j];
			if (g->edge != BSIM_EDGE_START &&
			    (out->n == INT_MAX ||
			     bsim_markov_entries_push(out, &cap, (int)g->edge, g->pos, g->x, g->v)))
				rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
		}
		if (rc == BSIM_OK && cx &&
		    crossings_push(cx, &cx_cap, &s, def, &logs[t], &results[t]))
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	train_free(&s, logs, results, T);
	if (rc != BSIM_OK) {
		bsim_markov_entries_free(out);
		if (cx)
			bsim_markov_crossings_free(cx);
	} else
		bsim_markov_train_label(lattice, def, out->id, sizeof out->id);
	return rc;
}

int bsim_markov_visits_reserve(bsim_markov_visits *v, long *cap)
{
	if (v->n < *cap)
		return 0;
	const long more = *cap ? 2 * *cap : 4096;
	bsim_markov_visit *grown = realloc(v->v, (size_t)more * sizeof *grown);
	if (!grown)
		return -1;
	v->v = grown;
	*cap = more;
	return 0;
}

/* Trial log g's visits appended to out (see bsim_markov_train_visits). */
static int visits_push(bsim_markov_visits *out, long *cap, const bsim_scene *s,
                       const bsim_trial_log *g, const bsim_trial_result *res)
{
	const bsim_lattice_def *l = &s->lattice;
	for (int j = 0; j < g->n_entries; j++) {
		const bsim_gate_entry *e = &g->entries[j],
		                      *next = j + 1 < g->n_entries ? e + 1 : NULL;
		int steps;
		if (!exit_known(s, g, res, j, &steps))
			break;
		if (e->iy == l->rows - 1 || e->ix == l->ix_min || e->ix == l->ix_max) {
			out->left_out++;
			continue;
		}
		if (bsim_markov_visits_reserve(out, cap))
			return -1;
		bsim_markov_visit *v = &out->v[out->n++];
		memset(v, 0, sizeof *v);
		gate_kind(s, e->ix, e->iy, v->k);
		v->edge = (int)e->edge;
		v->pos = e->pos;
		v->v[0] = e->v[0];
		v->v[1] = e->v[1];
		v->steps = steps;
		if (next) {
			v->exit_edge = (int)next->edge;
			v->exit_pos = next->pos;
			v->exit_v[0] = next->v[0];
			v->exit_v[1] = next->v[1];
		}
	}
	return 0;
}

int bsim_markov_train_visits(const bsim_scene *lattice, const bsim_markov_def *def,
                             const double start[2], uint64_t seed, const bsim_backend *be,
                             const bsim_options *opts, bsim_markov_visits *out, long *cap,
                             long long *steps, bsim_error *err)
{
	bsim_scene s;
	memset(&s, 0, sizeof s);
	bsim_trial_log *logs = NULL;
	bsim_trial_result *results = NULL;
	const long T = def->train_trials;
	double(*kinds)[2] = NULL;
	const int n = bsim_markov_lattice_kinds(lattice, &kinds);
	const train_layout L = {kinds, n, seed, start};
	int rc = n > 0 ? train_field(lattice, seed, start, &L, T, def, be, opts, &s, &logs,
	                             &results, err)
	               : bsim_error_set(err, BSIM_EFAIL, "out of memory");
	*steps = 0;
	for (long t = 0; rc == BSIM_OK && t < T; t++) {
		*steps += results[t].steps_run;
		if (layout_draw(&L, t, &s) || visits_push(out, cap, &s, &logs[t], &results[t]))
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	train_free(&s, logs, results, T);
	free(kinds);
	return rc;
}
