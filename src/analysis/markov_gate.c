/* The single gates that fill a Markov map (beamsim/markov.h): the gate of
 * a stiffness pair in its own frame, one trial from a state of an entry
 * bin until the body leaves the gate's rectangle (the exit binned as the
 * entry of the gate it enters) or is stuck, and the trials of every bin
 * on the threads, counted in trial order so that the map is the same for
 * any number of threads. */
#define _POSIX_C_SOURCE 200809L

#include "analysis/markov_internal.h"

#include <assert.h>

#include <gsl/gsl_rng.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "beamsim/effects.h"
#include "beamsim/schedule.h"
#include "beamsim/state.h"
#include "model/lattice_crossing.h"

void bsim_markov_gate_scene_init(markov_gate_scene *g, const bsim_scene *lattice, const double k[2])
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

/* c clamped into [lo, hi). */
static double clamp_in(double c, double lo, double hi)
{
	return c < lo ? lo : c >= hi ? nextafter(hi, lo) : c;
}

/* The exit of a step from p0 inside the gate to s->x outside it: the entry
 * bin of the gate it enters (the boundary crossed first), and in next the
 * body's centre in that gate's frame (inside its rectangle). */
static int exit_bin(const bsim_markov_bins *b, const bsim_lattice_def *l, const double p0[2],
                    const bsim_state *s, double next[2])
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
	if (ex && (!ey || fx <= fy)) {
		next[0] = clamp_in(p1[0] + (ex == BSIM_EDGE_LEFT ? -l->width : l->width), -w2, w2);
		next[1] = clamp_in(p1[1], 0.0, d);
		return bsim_markov_bin_of(b, l, ex, p0[1] + fx * (p1[1] - p0[1]), s->v);
	}
	next[0] = clamp_in(p1[0], -w2, w2);
	next[1] = clamp_in(p1[1] + (ey == BSIM_EDGE_BOTTOM ? -d : d), 0.0, d);
	return bsim_markov_bin_of(b, l, ey, p0[0] + fy * (p1[0] - p0[0]), s->v);
}

/* Salt of the self-consistent passes' entry-state seeds. */
#define SELF_SALT 0x73656c6670617373ULL
/* Salt of the schedules of the single gates after the start. */
#define NEXT_SALT 0x6e65787467617465ULL

/* A state of bin (> 0) from the pool's exits into it, each with its
 * weight; uniformly in the bin where none arrived. */
static void pool_sample(const markov_pool *p, const bsim_markov_bins *b, const bsim_lattice_def *l,
                        double h, int bin, gsl_rng *rng, double x[2], double v[2])
{
	const int lo = p->first[bin], hi = p->first[bin + 1];
	if (hi == lo) {
		bsim_markov_bin_sample(b, l, h, bin, rng, x, v);
		return;
	}
	int j;
	const double total = p->cw[hi - 1];
	if (total > 0.0) {
		/* the first run whose cumulative weight exceeds r */
		const double r = gsl_rng_uniform(rng) * total;
		int a = lo, z = hi - 1;
		while (a < z) {
			int mid = a + (z - a) / 2;
			if (p->cw[mid] > r)
				z = mid;
			else
				a = mid + 1;
		}
		j = a;
	} else {
		j = lo + (int)gsl_rng_uniform_int(rng, (unsigned long)(hi - lo));
	}
	const markov_run *u = p->run[j];
	memcpy(x, u->exit_x, sizeof u->exit_x);
	memcpy(v, u->exit_v, sizeof u->exit_v);
}

/* What a thread keeps from one single-gate trial to the next. */
typedef struct gate_runner {
	bsim_state s0, s1;
	gsl_rng *rng;
	markov_gate_scene g;
	const markov_entry_index *ex; /* NULL: no observed entries */
	const markov_pool *pool;      /* NULL: not a self-consistent pass */
	markov_run *run;              /* NULL: not kept */
	long steps;                   /* of the last trial */
	/* The last trial's world, reset for the next (the gate's scene stays
	 * but for the body's start); NULL: none, or a backend without reset. */
	bsim_world *w;
} gate_runner;

/* One single-gate trial from entry bin `bin` (0: the start; < 0: the gate
 * after the start, from the state the caller set) with trial index t: the
 * exit bin, 0 if stuck; -1 with err on failure. */
static int gate_trial(gate_runner *r, const bsim_scene *lattice, const bsim_markov_def *def,
                      const bsim_backend *be, const bsim_options *opts, int bin, int t,
                      bsim_error *err)
{
	const bsim_lattice_def *l = &lattice->lattice;
	bsim_scene *s = &r->g.s;
	if (bin > 0 && r->pool) {
		gsl_rng_set(r->rng, bsim_schedule_seed_mix(
		                            bsim_schedule_seed_mix(def->seed ^ SELF_SALT,
		                                                   (uint64_t)r->pool->pass, 0),
		                            (uint64_t)bin, (uint64_t)t));
		pool_sample(r->pool, &def->bins, l, s->dt, bin, r->rng, s->body.start,
		            s->body.velocity);
	} else if (bin > 0) {
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
			bsim_markov_bin_sample(&def->bins, l, s->dt, bin, r->rng, s->body.start,
			                       s->body.velocity);
		}
	}
	bsim_world *w = r->w;
	const int reused = w != NULL;
	r->w = NULL;
	if ((reused ? be->reset(w, s, err) : be->create(s, opts, &w, err)) != BSIM_OK) {
		if (reused)
			be->destroy(w);
		return -1;
	}
	bsim_effects fx;
	/* bin < 0: the gate after the start, its own schedules */
	const uint64_t seed =
	        bin >= 0 ? bsim_schedule_seed_mix(def->seed, (uint64_t)bin, (uint64_t)t)
	                 : bsim_schedule_seed_mix(def->seed ^ NEXT_SALT, 0, (uint64_t)t);
	if (bsim_effects_init_taking(&fx, s, seed, be->takes)) {
		be->destroy(w);
		bsim_error_set(err, BSIM_EFAIL, "out of memory");
		return -1;
	}
	const long n_max = lattice->gate_steps > 0 ? lattice->gate_steps : lattice->max_steps;
	const double w2 = 0.5 * l->width, d = l->depth;
	be->get_state(w, &r->s0);
	if (r->run) {
		memcpy(r->run->x, s->body.start, sizeof r->run->x);
		memcpy(r->run->v, s->body.velocity, sizeof r->run->v);
	}
	double next[2];
	int out = 0;
	r->steps = n_max;
	/* the body's motion at the step's start: s0, which the swap below
	 * refills with the state each step ends in */
	const bsim_state *at = &r->s0;
	for (long n = 0; n < n_max; n++) {
		double f[BSIM_WRENCH];
		bsim_effects_force_at(&fx, n, s->dt, at, f);
		int made;
		const bsim_wrench one = {{f[0], f[1]}, f[2]};
		if (be->advance(w, &one, s->dt, 1, &r->s1, &made, err) != BSIM_OK) {
			out = -1;
			break;
		}
		if (!isfinite(r->s1.x[0]) || !isfinite(r->s1.x[1]) || !isfinite(r->s1.v[0]) ||
		    !isfinite(r->s1.v[1])) {
			char where[32] = "after the start";
			if (bin >= 0)
				snprintf(where, sizeof where, "entry bin %d", bin);
			bsim_error_set(err, BSIM_EFAIL,
			               "a single gate (k = %g, %g N m/rad, %s, trial %d) "
			               "became unstable at step %ld",
			               s->beams[0].stiffness, s->beams[1].stiffness, where, t,
			               n + 1);
			out = -1;
			break;
		}
		const double *p = r->s1.x;
		if (p[0] < -w2 || p[0] >= w2 || p[1] < 0.0 || p[1] >= d) {
			out = exit_bin(&def->bins, l, r->s0.x, &r->s1, next);
			r->steps = n + 1;
			break;
		}
		bsim_state tmp = r->s0;
		r->s0 = r->s1;
		r->s1 = tmp;
	}
	if (out >= 0 && bsim_effects_status(&fx, err) != BSIM_OK)
		out = -1;
	if (r->run && out >= 0) {
		/* stuck: the last state, in this gate's frame */
		const bsim_state *last = out > 0 ? &r->s1 : &r->s0;
		r->run->exit = out;
		memcpy(r->run->exit_x, out > 0 ? next : last->x, sizeof r->run->exit_x);
		memcpy(r->run->exit_v, last->v, sizeof r->run->exit_v);
	}
	bsim_effects_free(&fx);
	if (out >= 0 && be->reset)
		r->w = w;
	else
		be->destroy(w);
	return out;
}

void bsim_markov_trial_end(long i, const bsim_error *e, long *first, bsim_error *first_err,
                           long *done, long total, long every, bsim_progress_fn progress,
                           void *user)
{
	if (e) {
#pragma omp critical(bsim_markov_fail)
		if (i < *first) {
			*first = i;
			*first_err = *e;
		}
	}
	long now;
#pragma omp atomic capture
	now = ++*done;
	if (progress && (now % every == 0 || now == total)) {
#pragma omp critical(bsim_markov_progress)
		progress(user, now, total);
	}
}

/* Single gates 0 .. units-1 of a gate with stiffness k on def->threads
 * threads, or with todo those units todo[0 .. units-1]: unit u's exit bin
 * (0 stuck) into exit[u] and its time steps into held[u], its entry and
 * exit into runs[u] (runs may be NULL). Unit u is trial u - first of bin
 * of map m (m's bins, states drawn in the bin or from pool), or, with
 * from, the gate after the start: the body starts in from[u]'s exit
 * state, its schedule that of start trial trial[u]. The first failure in
 * unit order is the error, whatever the threads. */
static int units_run(const bsim_scene *lattice, const bsim_markov_def *def, const bsim_backend *be,
                     const bsim_options *opts, const double k[2], long units, const long *todo,
                     const bsim_markov_map *m, const markov_pool *pool, const markov_run *from,
                     const int *trial, markov_run *runs, int *exit, int *held, long long *steps,
                     long *done, long total, bsim_error *err)
{
	markov_entry_index ex = {0};
	if (def->entries && !from &&
	    bsim_markov_entry_index_init(&ex, def->entries, &def->bins, &lattice->lattice)) {
		bsim_markov_entry_index_free(&ex);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	int stopped = 0;
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
		r.pool = pool;
		bsim_markov_gate_scene_init(&r.g, lattice, k);
		const double start[2] = {r.g.s.body.start[0], r.g.s.body.start[1]};
		r.ex = def->entries && !from ? &ex : NULL;
#pragma omp for schedule(dynamic, 16)
		for (long i = 0; i < units; i++) {
			const long u = todo ? todo[i] : i;
			if (!ok || !r.rng) {
				exit[u] = -1;
#pragma omp critical(bsim_markov_fail)
				if (u < first_unit) {
					first_unit = u;
					bsim_error_set(&first, BSIM_EFAIL, "out of memory");
				}
				continue;
			}
			if (def->stop && *def->stop) {
				exit[u] = -1;
#pragma omp atomic write
				stopped = 1;
				continue;
			}
			bsim_error e;
			int bin, t;
			if (from) { /* the exit state of start trial trial[u] */
				memcpy(r.g.s.body.start, from[u].exit_x, sizeof from[u].exit_x);
				memcpy(r.g.s.body.velocity, from[u].exit_v, sizeof from[u].exit_v);
				bin = -1;
				t = trial[u];
			} else {
				r.g.s.body.start[0] = start[0];
				r.g.s.body.start[1] = start[1];
				r.g.s.body.velocity[0] = lattice->body.velocity[0];
				r.g.s.body.velocity[1] = lattice->body.velocity[1];
				bin = bsim_markov_unit_bin(m, u);
				t = (int)(u - bsim_markov_bin_first(m, bin));
			}
			r.run = runs ? &runs[u] : NULL;
			exit[u] = gate_trial(&r, lattice, def, be, opts, bin, t, &e);
			held[u] = (int)r.steps;
#pragma omp atomic
			*steps += r.steps;
			bsim_markov_trial_end(u, exit[u] < 0 ? &e : NULL, &first_unit, &first, done,
			                      total, 256, def->progress, def->progress_user);
		}
		if (r.w)
			be->destroy(r.w);
		gsl_rng_free(r.rng);
		bsim_state_free(&r.s0);
		bsim_state_free(&r.s1);
	}
	bsim_markov_entry_index_free(&ex);
	if (stopped)
		return BSIM_ESTOPPED;
	if (first_unit < units) {
		if (err)
			*err = first;
		return BSIM_EFAIL;
	}
	return BSIM_OK;
}

/* Whether crossing i of cx is of map m's gate kind. */
static int crossing_of(const markov_crossings *cx, long i, const bsim_markov_map *m)
{
	return cx->k[i][0] == m->k[0] && cx->k[i][1] == m->k[1];
}

long bsim_markov_crossings_layout(bsim_markov_map *m, const markov_crossings *cx)
{
	const int nb = m->n_bins;
	long *first = calloc((size_t)nb + 1, sizeof *first);
	if (!first)
		return -1;
	/* first[a + 1] counts bin a's crossings, then becomes its end */
	long placed = 0;
	for (long i = 0; i < cx->n; i++)
		if (crossing_of(cx, i, m))
			first[cx->entry[i] + 1]++, placed++;
	first[1] = m->start_trials;
	for (int a = 1; a < nb; a++) {
		const long c = first[a + 1], topped = bsim_markov_crossings_topped(m, c);
		first[a + 1] = first[a] + (c > topped ? c : topped);
	}
	free(m->bin_first);
	m->bin_first = first;
	return placed;
}

/* With cx, each bin's crossings of m's kind placed first in its single
 * gates, in trial order (exit and held set), and the others listed in
 * todo: how many; -1 out of memory. */
static long crossings_place(const bsim_markov_map *m, const markov_crossings *cx, int *exit,
                            int *held, long *todo)
{
	const int nb = m->n_bins;
	long *fill = calloc((size_t)nb, sizeof *fill); /* bin a's crossings placed */
	if (!fill)
		return -1;
	for (long i = 0; i < cx->n; i++)
		if (crossing_of(cx, i, m)) {
			const int a = cx->entry[i];
			const long u = bsim_markov_bin_first(m, a) + fill[a]++;
			exit[u] = cx->exit[i];
			held[u] = cx->steps[i];
		}
	long n = 0;
	for (int a = 0; a < nb; a++)
		for (long u = bsim_markov_bin_first(m, a) + fill[a];
		     u < bsim_markov_bin_first(m, a + 1); u++)
			todo[n++] = u;
	free(fill);
	return n;
}

int bsim_markov_map_simulate_runs(const bsim_scene *lattice, const bsim_markov_def *def,
                                  const bsim_backend *be, const bsim_options *opts,
                                  bsim_markov_map *m, const markov_pool *pool,
                                  const markov_crossings *cx, markov_run *runs, long *done,
                                  long total, bsim_error *err)
{
	const long units = bsim_markov_map_units(m);
	int *exit = malloc((size_t)units * sizeof *exit);
	int *held = malloc((size_t)units * sizeof *held);
	long *todo = cx ? malloc((size_t)units * sizeof *todo) : NULL;
	const long n = !exit || !held || (cx && !todo) ? -1
	               : cx                            ? crossings_place(m, cx, exit, held, todo)
	                                               : units;
	if (n < 0) {
		free(exit);
		free(held);
		free(todo);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	long long steps = 0;
	int rc = units_run(lattice, def, be, opts, m->k, n, todo, m, pool, NULL, NULL, runs, exit,
	                   held, &steps, done, total, err);
	if (rc == BSIM_OK && bsim_markov_counts_of_exits(m, exit) != 0)
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	if (rc == BSIM_OK) { /* the holding times: the map keeps both arrays */
		free(m->hold_exit);
		free(m->hold_steps);
		m->hold_exit = exit;
		m->hold_steps = held;
		exit = held = NULL;
	}
	m->steps += steps;
	free(exit);
	free(held);
	free(todo);
	return rc;
}

long bsim_markov_next_units(int after_trials, int n)
{
	return (long)after_trials * (1 + n);
}

int bsim_markov_next_simulate(const bsim_scene *lattice, const bsim_markov_def *def,
                              const bsim_backend *be, const bsim_options *opts,
                              const bsim_markov_map *start, const markov_run *start_runs,
                              const bsim_markov_map *const *gate, bsim_markov_next *const *nx,
                              int n, long *done, long total, bsim_error *err)
{
	/* the first A start trials go on: the chain pools them for the rest */
	const long A = bsim_markov_def_after_trials(def);
	assert(A >= 1 && A <= start->start_trials);
	/* the start bin's single gates alone: a map of its units only */
	bsim_markov_map sm = *start;
	sm.trials = 1;
	sm.n_bins = 1;
	sm.bin_first = NULL;
	markov_run *runs = malloc((size_t)A * sizeof *runs);
	markov_run *from = malloc((size_t)A * sizeof *from);
	int *trial = malloc((size_t)A * sizeof *trial);
	int *exit = malloc((size_t)A * sizeof *exit), *held = malloc((size_t)A * sizeof *held);
	if (!runs || !from || !trial || !exit || !held) {
		free(runs);
		free(from);
		free(trial);
		free(exit);
		free(held);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	long long steps = 0;
	clock_t c0 = clock();
	int rc = BSIM_OK;
	if (start_runs) { /* the start's single gates as the map's build left them */
		memcpy(runs, start_runs, (size_t)A * sizeof *runs);
		memcpy(exit, start->hold_exit, (size_t)A * sizeof *exit);
		memcpy(held, start->hold_steps, (size_t)A * sizeof *held);
		*done += A;
	} else
		rc = units_run(lattice, def, be, opts, start->k, A, NULL, &sm, NULL, NULL, NULL,
		               runs, exit, held, &steps, done, total, err);
	/* Run again, the same seeds as the map's start bin: the same single
	 * gates (the kept runs are the map's own). */
	for (long t = 0; rc == BSIM_OK && !start_runs && start->hold_exit && t < A; t++)
		if (exit[t] != start->hold_exit[t] || held[t] != start->hold_steps[t])
			rc = bsim_error_set(err, BSIM_EFAIL,
			                    "the start's single gate %ld of map_%016llx ran again "
			                    "to exit %d after %d steps, the map's to %d after %d",
			                    t, (unsigned long long)start->key, exit[t], held[t],
			                    start->hold_exit[t], start->hold_steps[t]);
	long left = 0;
	for (long t = 0; rc == BSIM_OK && t < A; t++)
		if (exit[t] > 0) {
			from[left] = runs[t];
			trial[left++] = (int)t;
		}
	const double start_seconds = (double)(clock() - c0) / CLOCKS_PER_SEC;
	for (int i = 0; i < n && rc == BSIM_OK; i++) {
		bsim_markov_next *x = nx[i];
		c0 = clock();
		long long gs = 0;
		x->trials = (int)A;
		x->exit = malloc((size_t)A * sizeof *x->exit);
		x->steps = malloc((size_t)A * sizeof *x->steps);
		if (!x->exit || !x->steps) {
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
			break;
		}
		rc = units_run(lattice, def, be, opts, gate[i]->k, left, NULL, NULL, NULL, from,
		               trial, NULL, exit, held, &gs, done, total, err);
		/* the start's units again count once, shared by the n gates */
		if (rc != BSIM_OK)
			break;
		for (long t = 0; t < A; t++)
			x->exit[t] = -1, x->steps[t] = 0;
		for (long u = 0; u < left; u++) {
			x->exit[trial[u]] = exit[u];
			x->steps[trial[u]] = held[u];
		}
		x->seconds = (double)(clock() - c0) / CLOCKS_PER_SEC + start_seconds / n;
		x->cost = x->seconds;
		x->steps_total = gs + steps / n;
	}
	/* counted: the units of the gates after the start that did not run */
	if (rc == BSIM_OK)
		*done += (A - left) * n;
	free(runs);
	free(from);
	free(trial);
	free(exit);
	free(held);
	return rc;
}
