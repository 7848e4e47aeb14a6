/* The absorbing Markov chain of a gate lattice composed from single-gate
 * maps, and its solution (beamsim/markov.h).
 *
 * States. Transient: (gate, entry bin), index g n_bins + bin with g = iy
 * columns + (ix - ix_min). Absorbing: the final locations, index
 *   ix - ix_min                              the end through column ix
 *   columns + iy                             a side at row iy
 *   columns + rows + iy columns + ix - ix_min  stuck in gate (ix, iy)
 * Gate g's map row `bin` sends probability counts / trials to each exit: 0
 * to stuck in g; an entry bin of the gate the body enters, or, past the
 * field's edge, the end (the top of the last row) or a side (the outer
 * edge of an outer column). A body leaving row 0 downwards stays in row 0's
 * gate in the lattice; the chain lets it enter that gate again through its
 * bottom edge, with the same position, speed and direction bins.
 *
 * The start. s is the start state (the start gate's bin 0), or, with the
 * gate after the start (set->next), the probability entering each state
 * once a body's first two gates are behind, taken from the start's single
 * gates and their continuations (chain_start_init); what those two gates
 * absorbed is added to p.
 *
 * Solution. p = s (I - Q)^-1 R. Exactly: y (I - Q) = s, i.e. (I - Q)^T y^T
 * = s^T, by LU (GSL) for at most BSIM_MARKOV_LU_MAX states; y is the
 * expected number of visits of each state and p = y R. Always, one of
 * two iterations, which stop when less than tol is left in the field (or
 * after 1e6 steps, or when STALL_STEPS steps leave it where it was), said
 * in left_in_field: each location's probability is
 * short by at most left_in_field. With BSIM_MARKOV_GATES (the default),
 * the series s Q^(k-1) R, k = 1, 2, ..., whose k-th term is the
 * probability of ending after the k-th gate entered: p and the
 * distribution of gates visited (what is left would have ended somewhere).
 * Without, Gauss-Seidel sweeps for y (sweeps(), the bound proved there):
 * p and the mean of gates visited, in about half as many steps. The series
 * walks each map's own rows (compressed sparse rows, contiguous exits and
 * probabilities) through a table of where each gate's exits lead, built
 * once; Q is composed only for the LU. */
#include "analysis/markov_internal.h"
#include "beamsim/lattice_outcome.h"

#include <assert.h>
#include <gsl/gsl_linalg.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define SERIES_MAX 1000000
/* The series and the sweeps look every STALL_STEPS steps at the probability
 * left in the field: if it has not fallen by a relative 1e-9 since, it is
 * held by a set of states that are never left (rows of the maps that lead
 * only into each other, as a few single gates a bin can give), the
 * remaining steps up to SERIES_MAX would not move it, and they stop, said
 * in left_in_field. */
#define STALL_STEPS 1024

/* A map's rows in compressed sparse rows: row a's nonzero transitions are
 * exit[first[a] .. first[a + 1]) with probabilities p[], contiguous;
 * first and exit are the map's own count_first and count_exit (the set
 * outlives the chain). */
typedef struct sparse_map {
	const int *first, *exit;
	double *p;
	double *hold; /* s, each row's mean holding time; NULL without holding times */
} sparse_map;

/* Row a's mean holding time, s: its single gates' steps times dt. */
static int sparse_hold(sparse_map *s, const bsim_markov_map *m, double dt)
{
	const int nb = m->n_bins;
	if (!m->hold_steps)
		return 0;
	s->hold = malloc((size_t)nb * sizeof *s->hold);
	if (!s->hold)
		return -1;
	for (int a = 0; a < nb; a++) {
		const int T = bsim_markov_bin_trials(m, a);
		const long u0 = bsim_markov_bin_first(m, a);
		long long sum = 0;
		for (int t = 0; t < T; t++)
			sum += m->hold_steps[u0 + t];
		s->hold[a] = (double)sum / T * dt;
	}
	return 0;
}

static int sparse_init(sparse_map *s, const bsim_markov_map *m)
{
	const int nb = m->n_bins, nnz = m->count_first[nb];
	s->first = m->count_first;
	s->exit = m->count_exit;
	s->p = malloc((size_t)(nnz > 0 ? nnz : 1) * sizeof *s->p);
	if (!s->p)
		return -1;
	for (int a = 0; a < nb; a++) {
		long total = 0;
		for (int i = m->count_first[a]; i < m->count_first[a + 1]; i++)
			total += m->count_n[i];
		for (int i = m->count_first[a]; i < m->count_first[a + 1]; i++)
			s->p[i] = (double)m->count_n[i] / (double)total;
	}
	return 0;
}

/* Where exit x of gate (ix, iy) leads: *state >= 0 a transient state, else
 * *loc an absorbing location. */
typedef struct chain {
	const bsim_lattice_def *l;
	const bsim_markov_bins *b;
	int nb, cols, rows, n_loc, n_states;
	int per_edge;   /* bins per edge */
	int *gate_map;  /* gate -> map index */
	int has_time;   /* every map has holding times */
	sparse_map *sm; /* per map */
	/* Where exit x of gate g leads, tgt[g nb + x]: a state, or n_states +
	 * location. The series walks the maps' own rows through this table
	 * (both small enough to stay in cache) rather than a composed Q. */
	int *tgt;
	/* The composed chain, for the LU only (at most BSIM_MARKOV_LU_MAX
	 * states): state s's arcs are to[first[s] .. first[s + 1]) with
	 * probabilities p[]; to >= 0 a state, else -1 - location. */
	int *first, *to;
	double *p;
} chain;

void bsim_markov_exit_target(int cols, int rows, int nb, int g, int x, int *state, int *loc)
{
	const int ix = g % cols, iy = g / cols, per_edge = (nb - 1) / 4;
	*state = -1;
	*loc = -1;
	if (x == 0) {
		*loc = cols + rows + g;
		return;
	}
	int edge = BSIM_EDGE_BOTTOM + (x - 1) / per_edge;
	int jx = ix, jy = iy;
	switch (edge) {
	case BSIM_EDGE_BOTTOM: /* into the gate above */
		if (++jy == rows) {
			*loc = ix;
			return;
		}
		break;
	case BSIM_EDGE_TOP: /* into the gate below */
		if (--jy < 0) {
			jy = 0;
			x -= (BSIM_EDGE_TOP - BSIM_EDGE_BOTTOM) * per_edge;
		}
		break;
	case BSIM_EDGE_LEFT: /* into the gate on the right */
		if (++jx == cols) {
			*loc = cols + iy;
			return;
		}
		break;
	default: /* into the gate on the left */
		if (--jx < 0) {
			*loc = cols + iy;
			return;
		}
		break;
	}
	*state = (jy * cols + jx) * nb + x;
}

void bsim_markov_locations_fill(const bsim_lattice_def *l, bsim_location *loc)
{
	const int cols = l->columns, rows = l->rows;
	for (int i = 0; i < cols; i++)
		loc[i] = (bsim_location){BSIM_LOCATION_END, l->ix_min + i, 0};
	for (int i = 0; i < rows; i++)
		loc[cols + i] = (bsim_location){BSIM_LOCATION_SIDE, 0, i};
	for (int g = 0; g < cols * rows; g++)
		loc[cols + rows + g] =
		        (bsim_location){BSIM_LOCATION_STUCK, l->ix_min + g % cols, g / cols};
}

static void target(const chain *c, int g, int x, int *state, int *loc)
{
	bsim_markov_exit_target(c->cols, c->rows, c->nb, g, x, state, loc);
}

void bsim_markov_prediction_free(bsim_markov_prediction *p)
{
	if (!p)
		return;
	free(p->loc);
	free(p->p);
	free(p->p_gates);
	free(p->p_time);
	free(p->p_loc_time);
	memset(p, 0, sizeof *p);
}

static void chain_free(chain *c, int n_maps)
{
	for (int i = 0; c->sm && i < n_maps; i++) {
		free(c->sm[i].p);
		free(c->sm[i].hold);
	}
	free(c->sm);
	free(c->gate_map);
	free(c->tgt);
	free(c->first);
	free(c->to);
	free(c->p);
}

int bsim_markov_gate_maps(const bsim_scene *lattice, const bsim_markov_set *set, int *gate_map,
                          bsim_error *err)
{
	const bsim_lattice_def *l = &lattice->lattice;
	for (int iy = 0; iy < l->rows; iy++)
		for (int ix = l->ix_min; ix <= l->ix_max; ix++) {
			double k[2] = {lattice->beams[bsim_lattice_beam(l, ix, iy, 0)].stiffness,
			               lattice->beams[bsim_lattice_beam(l, ix, iy, 1)].stiffness};
			int j = 0;
			while (j < set->n &&
			       !(set->maps[j].k[0] == k[0] && set->maps[j].k[1] == k[1]))
				j++;
			if (j == set->n)
				return bsim_error_set(
				        err, BSIM_EINPUT,
				        "no map for gate (%d, %d), k = %g, %g N m/rad", ix, iy,
				        k[0], k[1]);
			gate_map[iy * l->columns + ix - l->ix_min] = j;
		}
	return BSIM_OK;
}

/* targets: build tgt (the series and the LU walk it; the sweeps do not). */
static int chain_init(chain *c, const bsim_scene *lattice, const bsim_markov_set *set, int targets,
                      bsim_error *err)
{
	memset(c, 0, sizeof *c);
	const bsim_lattice_def *l = &lattice->lattice;
	c->l = l;
	c->b = &set->def.bins;
	c->nb = bsim_markov_bins_count(c->b);
	c->per_edge = c->b->n_pos * c->b->n_speed * c->b->n_dir;
	c->cols = l->columns;
	c->rows = l->rows;
	c->n_loc = c->cols + c->rows + c->cols * c->rows;
	c->n_states = c->cols * c->rows * c->nb;
	c->gate_map = malloc((size_t)c->cols * c->rows * sizeof *c->gate_map);
	c->sm = calloc((size_t)(set->n > 0 ? set->n : 1), sizeof *c->sm);
	if (!c->gate_map || !c->sm)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	for (int i = 0; i < set->n; i++) {
		if (set->maps[i].n_bins != c->nb)
			return bsim_error_set(err, BSIM_EINPUT, "map %d has %d bins, the set %d", i,
			                      set->maps[i].n_bins, c->nb);
		if (sparse_init(&c->sm[i], &set->maps[i]) != 0 ||
		    sparse_hold(&c->sm[i], &set->maps[i], lattice->dt) != 0)
			return bsim_error_set(err, BSIM_EFAIL, "out of memory");
		c->has_time = i == 0 ? c->sm[i].hold != NULL : c->has_time && c->sm[i].hold;
	}
	if (bsim_markov_gate_maps(lattice, set, c->gate_map, err) != BSIM_OK)
		return err->code;
	if (!targets && c->n_states > BSIM_MARKOV_LU_MAX)
		return BSIM_OK;
	/* Every exit of every gate resolved once. */
	const int G = c->cols * c->rows;
	c->tgt = malloc((size_t)G * c->nb * sizeof *c->tgt);
	if (!c->tgt)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	for (int g = 0; g < G; g++)
		for (int x = 0; x < c->nb; x++) {
			int state, loc;
			target(c, g, x, &state, &loc);
			c->tgt[(size_t)g * c->nb + x] = state >= 0 ? state : c->n_states + loc;
		}
	if (c->n_states > BSIM_MARKOV_LU_MAX)
		return BSIM_OK;
	/* Compose for the LU: every state's arcs. */
	long nnz = 0;
	for (int g = 0; g < G; g++) {
		const sparse_map *sm = &c->sm[c->gate_map[g]];
		nnz += sm->first[c->nb];
	}
	c->first = malloc(((size_t)c->n_states + 1) * sizeof *c->first);
	c->to = malloc((size_t)(nnz > 0 ? nnz : 1) * sizeof *c->to);
	c->p = malloc((size_t)(nnz > 0 ? nnz : 1) * sizeof *c->p);
	if (!c->first || !c->to || !c->p)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	int k = 0;
	for (int s = 0; s < c->n_states; s++) {
		c->first[s] = k;
		int g = s / c->nb, a = s % c->nb;
		const sparse_map *sm = &c->sm[c->gate_map[g]];
		for (int j = sm->first[a]; j < sm->first[a + 1]; j++, k++) {
			int t = c->tgt[(size_t)g * c->nb + sm->exit[j]];
			c->to[k] = t < c->n_states ? t : -1 - (t - c->n_states);
			c->p[k] = sm->p[j];
		}
	}
	c->first[c->n_states] = k;
	return BSIM_OK;
}

/* Where the chain starts: the probability entering each transient state
 * once the first `gates` gates are behind (init, n_states; the gates
 * [glo, ghi) hold it, in_field in all), what those gates absorbed (p_loc,
 * and p_gates[k] in the k-th), the gates they entered (visits, the start
 * counted) and their expected holding time, s. Without the gate after the
 * start: the start state, no gate behind. */
typedef struct chain_start {
	double *init, *p_loc;
	double p_gates[3];
	int gates, glo, ghi;
	double in_field, visits, time;
} chain_start;

/* Mass w leaving gate g (the second gate) by exit x into st. */
static void start_place(chain_start *st, const chain *c, int g, int x, double w)
{
	int state, loc = c->cols + c->rows + g; /* x = 0: stuck in g */
	if (x > 0)
		bsim_markov_exit_target(c->cols, c->rows, c->nb, g, x, &state, &loc);
	if (x > 0 && state >= 0) {
		st->init[state] += w;
	} else {
		st->p_loc[loc] += w;
		st->p_gates[2] += w;
	}
}

/* Mass w entering state (gate g, bin a) after the start, on through the
 * bin's row of g's map. */
static void start_by_bin(chain_start *st, const chain *c, int state, double w)
{
	const int g = state / c->nb, a = state % c->nb;
	const sparse_map *sm = &c->sm[c->gate_map[g]];
	if (sm->hold)
		st->time += w * sm->hold[a];
	for (int j = sm->first[a]; j < sm->first[a + 1]; j++)
		start_place(st, c, g, sm->exit[j], w * sm->p[j]);
}

/* The state start trial t of map m enters on leaving gate g0, or -1 (loc
 * then where it ended: stuck in g0 or out of the field). */
static int start_entered(const chain *c, const bsim_markov_map *m, int g0, int t, int *loc)
{
	const int x1 = m->hold_exit[t]; /* the start bin's units come first */
	int state = -1;
	*loc = c->cols + c->rows + g0;
	if (x1 > 0)
		bsim_markov_exit_target(c->cols, c->rows, c->nb, g0, x1, &state, loc);
	return state;
}

/* The first two gates from the gate after the start (set->next): start
 * trial t of the start gate's map (weight 1 / T) ends there, stuck or out
 * of the field, or enters gate g, where its own continuation in g's map
 * (the exact state it entered with, not its bin) leaves by exit x2. Only
 * the first A trials are continued (bsim_markov_next.trials): a trial t >=
 * A that entered g takes the continuations of the trials t' < A that
 * entered g, each an equal share, an unbiased sample of the exact states
 * entering g (where none of them entered g, g's bin row). A body leaving
 * the start gate downwards enters it again through its bottom, as
 * everywhere in the chain: that bin's row. Exact for the mixture at A = T:
 * no bin stands between the first gate and the second. */
static int chain_start_init(chain_start *st, const chain *c, const bsim_markov_set *set, int g0,
                            double dt)
{
	memset(st, 0, sizeof *st);
	const int nb = c->nb, n = c->n_states, S = c->gate_map[g0], G = c->cols * c->rows;
	st->init = calloc((size_t)n, sizeof *st->init);
	st->p_loc = calloc((size_t)c->n_loc, sizeof *st->p_loc);
	if (!st->init || !st->p_loc)
		return -1;
	const bsim_markov_map *m = &set->maps[S];
	if (!set->next || !m->hold_exit) {
		st->init[(size_t)g0 * nb] = 1.0;
	} else {
		const int T = m->start_trials, A = set->next[(size_t)S * set->n].trials;
		const double w = 1.0 / T;
		/* the continued trials that entered each gate, and the weight of
		 * the others that take their share */
		int *count = calloc((size_t)G, sizeof *count);
		double *pooled = calloc((size_t)G, sizeof *pooled);
		if (!count || !pooled) {
			free(count);
			free(pooled);
			return -1;
		}
		int loc;
		for (int t = 0; t < A; t++) {
			const int state = start_entered(c, m, g0, t, &loc);
			if (state >= 0 && state / nb != g0)
				count[state / nb]++;
		}
		st->gates = 2;
		for (int t = 0; t < T; t++) {
			st->visits += w;
			st->time += w * m->hold_steps[t] * dt;
			const int state = start_entered(c, m, g0, t, &loc);
			if (state < 0) {
				st->p_loc[loc] += w;
				st->p_gates[1] += w;
				continue;
			}
			const int g = state / nb;
			st->visits += w;
			if (g == g0 || (t >= A && count[g] == 0)) {
				start_by_bin(st, c, state, w);
				continue;
			}
			if (t >= A) {
				pooled[g] += w;
				continue;
			}
			const bsim_markov_next *x = &set->next[(size_t)S * set->n + c->gate_map[g]];
			assert(x->trials == A && x->exit && x->exit[t] >= 0);
			st->time += w * x->steps[t] * dt;
			start_place(st, c, g, x->exit[t], w);
		}
		for (int t = 0; t < A; t++) { /* the pooled shares */
			const int state = start_entered(c, m, g0, t, &loc), g = state / nb;
			if (state < 0 || g == g0 || pooled[g] == 0.0)
				continue;
			const bsim_markov_next *x = &set->next[(size_t)S * set->n + c->gate_map[g]];
			const double share = pooled[g] / count[g];
			st->time += share * x->steps[t] * dt;
			start_place(st, c, g, x->exit[t], share);
		}
		free(count);
		free(pooled);
	}
	st->glo = G;
	for (int g = 0; g < G; g++)
		for (int a = 0; a < nb; a++)
			if (st->init[(size_t)g * nb + a] != 0.0) {
				st->glo = g < st->glo ? g : st->glo;
				st->ghi = g + 1;
				st->in_field += st->init[(size_t)g * nb + a];
			}
	if (st->ghi == 0)
		st->glo = 0;
	return 0;
}

static void chain_start_free(chain_start *st)
{
	free(st->init);
	free(st->p_loc);
}

/* The series from the start state, until less than tol is left in the
 * field: p_loc (n_loc), p_gates (grown as needed), the probability left.
 * Every buffer is allocated before the loop. A term walks the gates that
 * hold probability (a band of rows that moves up the field), each state's
 * map row through the gate's target table; the absorbing locations are
 * the last n_loc entries of next, emptied into p_loc after each term. */
/* Out of line (as sweeps()): both inlined into their one caller, the
 * series took 2.2 times as long (perf stat, C-track, 800-trial maps). */
__attribute__((noinline)) static int series(const chain *c, const chain_start *st, double tol,
                                            double *p_loc, double **p_gates, int *n_gates,
                                            double *left, double *time)
{
	double tm = st->time; /* s, the sum of each state's mass times its mean holding time */
	const int n = c->n_states, nb = c->nb, G = c->cols * c->rows;
	double *cur = calloc((size_t)n + c->n_loc, sizeof *cur);
	double *next = calloc((size_t)n + c->n_loc, sizeof *next);
	int cap = 128;
	double *pg = calloc((size_t)cap + 1, sizeof *pg);
	if (!cur || !next || !pg) {
		free(cur);
		free(next);
		free(pg);
		return -1;
	}
	memcpy(cur, st->init, (size_t)n * sizeof *cur);
	for (int g = 0; g <= st->gates && g <= cap; g++)
		pg[g] = st->p_gates[g];
	/* the gates that may hold probability: [glo, ghi) */
	int glo = st->glo, ghi = st->ghi;
	double in_field = st->in_field, was = in_field;
	int k = st->gates;
	while (in_field > tol && k < SERIES_MAX) {
		if ((k + 1) % STALL_STEPS == 0) {
			if (in_field >= was * (1.0 - 1e-9))
				break;
			was = in_field;
		}
		k++;
		if (k > cap) {
			double *np = realloc(pg, ((size_t)2 * cap + 1) * sizeof *pg);
			if (!np) {
				free(cur);
				free(next);
				free(pg);
				return -1;
			}
			memset(np + cap + 1, 0, (size_t)cap * sizeof *np);
			pg = np;
			cap *= 2;
		}
		for (int g = glo; g < ghi; g++) {
			const sparse_map *sm = &c->sm[c->gate_map[g]];
			const int *restrict first = sm->first, *restrict ex = sm->exit;
			const double *restrict pr = sm->p;
			const int *restrict tg = c->tgt + (size_t)g * nb;
			double *restrict cg = cur + (size_t)g * nb;
			const double *restrict hb = sm->hold;
			for (int a = 0; a < nb; a++) {
				const double m = cg[a];
				if (m == 0.0)
					continue;
				cg[a] = 0.0;
				if (hb)
					tm += m * hb[a];
				const int j1 = first[a + 1];
				for (int j = first[a]; j < j1; j++)
					next[tg[ex[j]]] += m * pr[j];
			}
		}
		double absorbed = 0.0;
		for (int l = 0; l < c->n_loc; l++) {
			absorbed += next[n + l];
			p_loc[l] += next[n + l];
			next[n + l] = 0.0;
		}
		pg[k] = absorbed;
		/* a gate's exits reach its neighbours and, from row 0, row 0 */
		glo = glo - c->cols > 0 ? glo - c->cols : 0;
		ghi = ghi + c->cols < G ? ghi + c->cols : G;
		in_field = 0.0;
		int nlo = G, nhi = 0;
		for (int g = glo; g < ghi; g++) {
			double mg = 0.0;
			const double *ng = next + (size_t)g * nb;
			for (int a = 0; a < nb; a++)
				mg += ng[a];
			if (mg != 0.0) {
				nlo = g < nlo ? g : nlo;
				nhi = g + 1;
			}
			in_field += mg;
		}
		glo = nlo;
		ghi = nhi;
		double *t = cur;
		cur = next;
		next = t;
	}
	free(cur);
	free(next);
	*p_gates = pg;
	*n_gates = k;
	*left = in_field;
	*time = tm;
	return 0;
}

/* Gauss-Seidel sweeps for p = y R, y (I - Q) = s, in residual ("push")
 * form. r is the probability entered into states but not yet passed on:
 * r = s at first, p_loc = 0. Passing on state a's residual m = r_a adds m
 * to y_a, m Q[a][b] to r_b and m R[a][l] to p_loc[l], and leaves r_a = 0.
 * Invariant: the exact answer is p* = p_loc + r (I - Q)^-1 R. Every term
 * is >= 0 and each row of (I - Q)^-1 R is a probability distribution
 * (every state is left for a location with probability 1), so at every
 * location
 *     0 <= p*_l - p_loc[l] = (r (I - Q)^-1 R)_l <= sum_a r_a = left,
 * the series' bound (short by at most left_in_field), and sum_l p_loc[l]
 * = 1 - left (every push conserves probability). Odd sweeps pass on the
 * states in index order, gate by gate up the rows (g = iy columns + ix -
 * ix_min): a body moving forward (up a row) or to the right lands in a
 * state later in the sweep, resolved in the same sweep; even sweeps go in
 * the reverse order, resolving moves down and to the left the same way
 * (on the C-track with 800-trial maps: 29 sweeps to 1e-6, 26 forward
 * only, but faster: the mass coming back is passed on sooner). A body
 * going back and forth between two gates still needs a sweep per return,
 * against 56 terms of the series. Over-relaxation (pushing 1.2 r_a) cut
 * the sweeps to 21 but made r negative somewhere, and with it p no longer
 * a lower bound summing to at most 1: not used. The sweeps stop when left
 * <= tol; the order of every operation is fixed, so the result is the
 * same at any thread count. y is summed into *visits: the expected number
 * of gates entered, the start counted, short by what r has still to
 * visit. */
/* The sweeps' layout. The field is padded with a ring of ghost gates,
 * W = cols + 2 to a row, and each gate holds S = nb + 1 doubles: its entry
 * bins and, last, the probability stuck in it. Exit x of any gate then
 * lands at a fixed offset from the gate's first bin:
 *   x = 0 (stuck)                  nb
 *   bottom-edge bins (gate above)  W S + x
 *   left-edge bins (gate right)    S + x
 *   right-edge bins (gate left)    -S + x
 *   top-edge bins (gate below)     -W S + x
 * so each map's row is a list of (offset, probability) and the inner loop
 * is one load of each and one add, with no table per gate and no test for
 * the field's edge. After each sweep the ghosts are emptied: those above
 * the last row into the ends, those beside the outer columns into the
 * sides, the stuck slots into the stuck gates, and those below row 0 back
 * into row 0 through its bottom edge (same position, speed and direction
 * bins) to be passed on in the next sweep. */
static int exit_offset(int x, int nb, int W)
{
	const int S = nb + 1, per_edge = (nb - 1) / 4;
	if (x == 0)
		return nb;
	switch (BSIM_EDGE_BOTTOM + (x - 1) / per_edge) {
	case BSIM_EDGE_BOTTOM:
		return W * S + x;
	case BSIM_EDGE_LEFT:
		return S + x;
	case BSIM_EDGE_RIGHT:
		return -S + x;
	default:
		return -W * S + x;
	}
}

__attribute__((noinline)) static int sweeps(const chain *c, int n_maps, const chain_start *st,
                                            double tol, double *p_loc, double *visits, double *left,
                                            int *n_sweeps, double *time)
{
	double tm = st->time; /* s, as vis with each push weighted by its mean holding time */
	const int nb = c->nb, cols = c->cols, rows = c->rows, G = cols * rows;
	const int W = cols + 2, S = nb + 1, per_edge = (nb - 1) / 4;
	double *r = calloc((size_t)W * (rows + 2) * S, sizeof *r);
	int **off = calloc((size_t)n_maps, sizeof *off);
	int *base = malloc((size_t)G * sizeof *base);
	int ok = r && off && base;
	for (int i = 0; ok && i < n_maps; i++) {
		const sparse_map *sm = &c->sm[i];
		const int nnz = sm->first[nb];
		off[i] = malloc((size_t)(nnz > 0 ? nnz : 1) * sizeof **off);
		ok = off[i] != NULL;
		for (int j = 0; ok && j < nnz; j++)
			off[i][j] = exit_offset(sm->exit[j], nb, W);
	}
	if (!ok) {
		for (int i = 0; off && i < n_maps; i++)
			free(off[i]);
		free(off);
		free(base);
		free(r);
		return -1;
	}
	for (int g = 0; g < G; g++)
		base[g] = ((g / cols + 1) * W + g % cols + 1) * S;
	for (int g = st->glo; g < st->ghi; g++)
		for (int a = 0; a < nb; a++)
			r[base[g] + a] = st->init[(size_t)g * nb + a];
	double in_field = st->in_field, vis = st->visits, was = in_field;
	int k = 0;
	while (in_field > tol && k < SERIES_MAX) {
		if ((k + 1) % STALL_STEPS == 0) {
			if (in_field >= was * (1.0 - 1e-9))
				break;
			was = in_field;
		}
		k++;
		const int back = !(k & 1);
		for (int gi = 0; gi < G; gi++) {
			const int g = back ? G - 1 - gi : gi;
			const int mi = c->gate_map[g];
			const sparse_map *sm = &c->sm[mi];
			const int *restrict first = sm->first, *restrict of = off[mi];
			const double *restrict pr = sm->p, *restrict hb = sm->hold;
			double *rg = r + base[g];
			for (int ai = 0; ai < nb; ai++) {
				const int a = back ? nb - 1 - ai : ai;
				const double m = rg[a];
				if (m == 0.0)
					continue;
				rg[a] = 0.0;
				vis += m;
				if (hb)
					tm += m * hb[a];
				const int j1 = first[a + 1];
				for (int j = first[a]; j < j1; j++)
					rg[of[j]] += m * pr[j];
			}
		}
		/* the ghosts and the stuck slots emptied */
		for (int ix = 0; ix < cols; ix++) {
			double *end = r + ((size_t)(rows + 1) * W + ix + 1) * S;
			double *below = r + ((size_t)ix + 1) * S, *row0 = r + base[ix];
			for (int x = 0; x < S; x++) {
				p_loc[ix] += end[x];
				end[x] = 0.0;
			}
			for (int x = 1 + 3 * per_edge; x < nb; x++) {
				row0[x - 3 * per_edge] += below[x];
				below[x] = 0.0;
			}
		}
		for (int iy = 0; iy < rows; iy++)
			for (int side = 0; side < 2; side++) {
				double *gh = r + ((size_t)(iy + 1) * W + (side ? W - 1 : 0)) * S;
				for (int x = 0; x < S; x++) {
					p_loc[cols + iy] += gh[x];
					gh[x] = 0.0;
				}
			}
		in_field = 0.0;
		for (int g = 0; g < G; g++) {
			double *rg = r + base[g];
			p_loc[cols + rows + g] += rg[nb];
			rg[nb] = 0.0;
			for (int a = 0; a < nb; a++)
				in_field += rg[a];
		}
	}
	for (int i = 0; i < n_maps; i++)
		free(off[i]);
	free(off);
	free(base);
	free(r);
	*visits = vis;
	*left = in_field;
	*n_sweeps = k;
	*time = tm;
	return 0;
}

/* p_loc by LU of (I - Q)^T y = init (st's), added to what the first
 * gates absorbed; *time the sum of the visits y times each state's mean
 * holding time (with holding times), st's first gates' included. 0; 1,
 * p_loc and *time unfinished, if I - Q is singular; -1 on failure. */
static int lu_solve(const chain *c, const chain_start *st, double *p_loc, double *time)
{
	*time = st->time;
	for (int l = 0; l < c->n_loc; l++)
		p_loc[l] = st->p_loc[l];
	const int n = c->n_states;
	gsl_matrix *A = gsl_matrix_calloc((size_t)n, (size_t)n);
	gsl_vector *e = gsl_vector_calloc((size_t)n);
	gsl_vector *y = gsl_vector_alloc((size_t)n);
	gsl_permutation *perm = gsl_permutation_alloc((size_t)n);
	int rc = -1, sign;
	if (!A || !e || !y || !perm)
		goto done;
	for (int s = 0; s < n; s++) {
		gsl_matrix_set(A, (size_t)s, (size_t)s, 1.0);
		for (int j = c->first[s]; j < c->first[s + 1]; j++) {
			int to = c->to[j];
			if (to >= 0) /* A = (I - Q)^T: A[to][s] -= Q[s][to] */
				gsl_matrix_set(A, (size_t)to, (size_t)s,
				               gsl_matrix_get(A, (size_t)to, (size_t)s) - c->p[j]);
		}
	}
	for (int s = 0; s < n; s++)
		gsl_vector_set(e, (size_t)s, st->init[s]);
	if (gsl_linalg_LU_decomp(A, perm, &sign))
		goto done;
	/* a zero pivot: I - Q singular, a set of states never left (whether
	 * or not the start reaches it); GSL's solve would call its error
	 * handler, which aborts */
	for (int s = 0; s < n; s++)
		if (gsl_matrix_get(A, (size_t)s, (size_t)s) == 0.0) {
			rc = 1;
			goto done;
		}
	if (gsl_linalg_LU_solve(A, perm, e, y))
		goto done;
	for (int s = 0; s < n; s++) {
		double visits = gsl_vector_get(y, (size_t)s);
		if (visits == 0.0)
			continue;
		const sparse_map *sm = &c->sm[c->gate_map[s / c->nb]];
		if (sm->hold)
			*time += visits * sm->hold[s % c->nb];
		for (int j = c->first[s]; j < c->first[s + 1]; j++)
			if (c->to[j] < 0)
				p_loc[-1 - c->to[j]] += visits * c->p[j];
	}
	rc = 0;
done:
	gsl_matrix_free(A);
	gsl_vector_free(e);
	gsl_vector_free(y);
	gsl_permutation_free(perm);
	return rc;
}

double bsim_markov_tol_sampling(const bsim_markov_set *set)
{
	int T = set->n > 0 ? set->maps[0].trials : set->def.trials;
	for (int i = 1; i < set->n; i++)
		T = set->maps[i].trials < T ? set->maps[i].trials : T;
	return 1.0 / (32.0 * sqrt(T > 1 ? (double)T : 1.0));
}

int bsim_markov_predict(const bsim_scene *lattice, const bsim_markov_set *set,
                        bsim_markov_prediction *out, bsim_error *err)
{
	return bsim_markov_predict_tol(lattice, set, BSIM_MARKOV_TOL, out, err);
}

int bsim_markov_predict_tol(const bsim_scene *lattice, const bsim_markov_set *set, double tol,
                            bsim_markov_prediction *out, bsim_error *err)
{
	return bsim_markov_predict_with(lattice, set, tol, BSIM_MARKOV_GATES, out, err);
}

int bsim_markov_predict_with(const bsim_scene *lattice, const bsim_markov_set *set, double tol,
                             int flags, bsim_markov_prediction *out, bsim_error *err)
{
	memset(out, 0, sizeof *out);
	if (!lattice->has_lattice)
		return bsim_error_set(err, BSIM_EINPUT, "%s: not a gate lattice", lattice->name);
	if (!(tol > 0.0 && tol < 1.0))
		return bsim_error_set(err, BSIM_EINPUT,
		                      "tolerance %g: expected the probability left in the field "
		                      "at which the series stops, in (0, 1)",
		                      tol);
	chain c;
	chain_start st = {0};
	int rc = chain_init(&c, lattice, set, flags & BSIM_MARKOV_GATES, err);
	const bsim_lattice_def *l = &lattice->lattice;
	if (rc == BSIM_OK) {
		out->n_locations = c.n_loc;
		out->n_states = c.n_states;
		out->tol = tol;
		out->loc = malloc((size_t)c.n_loc * sizeof *out->loc);
		out->p = calloc((size_t)c.n_loc, sizeof *out->p);
		if (!out->loc || !out->p)
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	if (rc == BSIM_OK) {
		bsim_markov_locations_fill(l, out->loc);
		int ix, iy;
		bsim_lattice_gate_at(lattice, lattice->body.start, &ix, &iy);
		if (chain_start_init(&st, &c, set, iy * c.cols + ix - l->ix_min, lattice->dt))
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
		else
			memcpy(out->p, st.p_loc, (size_t)c.n_loc * sizeof *out->p);
	}
	if (rc == BSIM_OK) {
		if (flags & BSIM_MARKOV_GATES) {
			/* The series: p and the distribution of gates visited. */
			if (series(&c, &st, tol, out->p, &out->p_gates, &out->n_gates,
			           &out->left_in_field, &out->mean_time))
				rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
			for (int k = 1; rc == BSIM_OK && k <= out->n_gates; k++)
				out->mean_gates += k * out->p_gates[k];
		} else {
			/* The sweeps: p and the expected visits alone. */
			if (sweeps(&c, set->n, &st, tol, out->p, &out->mean_gates,
			           &out->left_in_field, &out->sweeps, &out->mean_time) ||
			    !(out->p_gates = calloc(1, sizeof *out->p_gates)))
				rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
		}
		if (rc == BSIM_OK && c.n_states <= BSIM_MARKOV_LU_MAX) {
			/* Two solutions of one chain: they must agree to within what
			 * the series or the sweeps left in the field. */
			double *by_series = malloc((size_t)c.n_loc * sizeof *by_series);
			const double iter_time = out->mean_time;
			int lu = -1;
			if (!by_series)
				rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
			else {
				memcpy(by_series, out->p, (size_t)c.n_loc * sizeof *out->p);
				memset(out->p, 0, (size_t)c.n_loc * sizeof *out->p);
				lu = lu_solve(&c, &st, out->p, &out->mean_time);
				if (lu < 0)
					rc = bsim_error_set(
					        err, BSIM_EFAIL,
					        "the chain's LU solve failed: out of memory");
				if (lu > 0) {
					/* a set of states never left: the iterative
					 * solution stands, and what it left in the field
					 * (all that reaches that set) is said */
					memcpy(out->p, by_series, (size_t)c.n_loc * sizeof *out->p);
					out->mean_time = iter_time;
				}
				for (int i = 0; rc == BSIM_OK && lu == 0 && i < c.n_loc; i++)
					if (!(fabs(out->p[i] - by_series[i]) <=
					      1e-9 + out->left_in_field))
						rc = bsim_error_set(
						        err, BSIM_EFAIL,
						        "the chain's LU and iterative solutions "
						        "differ "
						        "at location %d: %.12g against %.12g",
						        i, out->p[i], by_series[i]);
				free(by_series);
			}
			out->exact = lu == 0;
		}
		out->has_time = c.has_time;
		if (!c.has_time)
			out->mean_time = NAN;
	}
	chain_free(&c, set->n);
	chain_start_free(&st);
	if (rc != BSIM_OK)
		bsim_markov_prediction_free(out);
	return rc;
}
