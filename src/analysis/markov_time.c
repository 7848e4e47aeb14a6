/* Time to the outcome: walks of the semi-Markov chain (beamsim/markov.h,
 * bsim_markov_predict_time).
 *
 * With holding times the chain is semi-Markov: a body entering gate g in
 * bin a leaves it for exit x after h steps with the joint probability of
 * (x, h) among the map's single gates of bin a. The time to the outcome is
 * the sum of the holding times along the path, so its distribution is the
 * convolution of the gates' holding-time distributions over the chain's
 * paths, each weighted by its probability:
 *   P(T = t, outcome o) = sum over paths ending in o of
 *                         prod_i P(x_i, h_i | a_i) [h_1 + ... + h_n = t].
 * Summed exactly on a time grid this costs (states x transitions x
 * holding bins) per grid step; sampled, it costs a walk's gates per walk:
 * each walk draws one of the bin's single gates (its exit and steps
 * together, so a gate's time stays tied to where it leaves), adds its steps
 * and follows its exit. The walks' distribution is the chain's, with the
 * walks' own error sqrt(p (1 - p) / walks) on each probability; the mean by
 * first-step analysis (bsim_markov_predict_with's mean_time) is exact and
 * checks it.
 *
 * With the gate after the start (set->next), a walk's first single gate
 * is a start trial, and where it enters another gate its second is that
 * trial's own continuation there, or, for a trial past the continued ones,
 * the continuation of a continued trial that entered the same gate, drawn
 * uniformly (bsim_markov_predict_with's first two gates).
 *
 * The outcome is decided as a lattice trial's (docs/lattice.md): stuck when
 * a gate holds the body gate_steps steps (the map's exit 0: its single gate
 * ran out of steps) or when max_steps steps have passed in all (the trial's
 * duration; then stuck in the gate it is in), else the end or a side when
 * the walk leaves the field. */
#define _POSIX_C_SOURCE 200809L

#include "analysis/markov_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/lattice_outcome.h"

/* splitmix64: a 64-bit stream from the seed (Steele, Lea & Flood 2014). */
static uint64_t splitmix(uint64_t *s)
{
	uint64_t z = (*s += 0x9e3779b97f4a7c15ULL);
	z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
	z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
	return z ^ (z >> 31);
}

/* An integer uniform in [0, n), n < 2^32: the high half of the product
 * (Lemire 2019; the bias, at most n / 2^32, is far below the walks' error). */
static int draw(uint64_t *s, int n)
{
	return (int)(((splitmix(s) >> 32) * (uint64_t)n) >> 32);
}

/* Gates entered per walk at most: far beyond any field (a walk's every
 * gate takes at least one step, so max_steps bounds it first). */
#define WALK_GATES_MAX 100000000L

int bsim_markov_predict_time(const bsim_scene *lattice, const bsim_markov_set *set, long walks,
                             uint64_t seed, bsim_markov_prediction *p, bsim_error *err)
{
	if (!lattice->has_lattice)
		return bsim_error_set(err, BSIM_EINPUT, "%s: not a gate lattice", lattice->name);
	if (walks < 1 || walks > 100000000L)
		return bsim_error_set(err, BSIM_EINPUT, "walks: expected 1 to 1e8, got %ld", walks);
	const bsim_lattice_def *l = &lattice->lattice;
	const int cols = l->columns, rows = l->rows, G = cols * rows;
	if (set->n < 1 || p->n_locations != cols + rows + G)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "the prediction is not of this lattice's %d locations",
		                      cols + rows + G);
	for (int i = 0; i < set->n; i++)
		if (!set->maps[i].hold_exit)
			return bsim_error_set(
			        err, BSIM_EINPUT,
			        "map_%016llx (k = %g, %g N m/rad) has no holding times (built "
			        "before they were kept): beamsim markov build simulates it again",
			        (unsigned long long)set->maps[i].key, set->maps[i].k[0],
			        set->maps[i].k[1]);
	int *gate_map = malloc((size_t)G * sizeof *gate_map);
	if (!gate_map)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	if (bsim_markov_gate_maps(lattice, set, gate_map, err) != BSIM_OK) {
		free(gate_map);
		return err->code;
	}
	const double dt = lattice->dt;
	const long max_steps = lattice->max_steps > 0 ? lattice->max_steps : 0;
	/* the grid: whole steps, about 200 bins over the duration */
	const long bin_steps = max_steps > 200 ? (max_steps + 199) / 200 : 1;
	const int n_bins = max_steps > 0 ? (int)(max_steps / bin_steps + 1) : 1;
	free(p->p_time);
	free(p->p_loc_time);
	p->p_time = calloc((size_t)n_bins * 3, sizeof *p->p_time);
	p->p_loc_time = calloc((size_t)p->n_locations, sizeof *p->p_loc_time);
	if (!p->p_time || !p->p_loc_time) {
		free(gate_map);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	int sx, sy;
	bsim_lattice_gate_at(lattice, lattice->body.start, &sx, &sy);
	const int start = sy * cols + sx - l->ix_min, nb = set->maps[0].n_bins;
	double sum[3] = {0, 0, 0}, sum2[3] = {0, 0, 0};
	long n_kind[3] = {0, 0, 0};
	uint64_t rng = seed;
	/* The continued start trials by the gate they entered: pool[pool_first[g]
	 * .. pool_first[g + 1]) for gate g (a counting sort). */
	int *pool = NULL, *pool_first = NULL;
	if (set->next && set->maps[gate_map[start]].hold_exit) {
		const bsim_markov_map *sm = &set->maps[gate_map[start]];
		const int A = set->next[(size_t)gate_map[start] * set->n].trials;
		pool = malloc((size_t)A * sizeof *pool);
		pool_first = calloc((size_t)G + 1, sizeof *pool_first);
		int *entered = malloc((size_t)A * sizeof *entered),
		    *at = malloc((size_t)G * sizeof *at);
		if (!pool || !pool_first || !entered || !at) {
			free(pool);
			free(pool_first);
			free(entered);
			free(at);
			free(gate_map);
			return bsim_error_set(err, BSIM_EFAIL, "out of memory");
		}
		for (int t = 0; t < A; t++) {
			int state = -1, loc;
			if (sm->hold_exit[t] > 0)
				bsim_markov_exit_target(cols, rows, nb, start, sm->hold_exit[t],
				                        &state, &loc);
			entered[t] = state >= 0 && state / nb != start ? state / nb : -1;
			if (entered[t] >= 0)
				pool_first[entered[t] + 1]++;
		}
		for (int g = 0; g < G; g++)
			pool_first[g + 1] += pool_first[g];
		memcpy(at, pool_first, (size_t)G * sizeof *at);
		for (int t = 0; t < A; t++)
			if (entered[t] >= 0)
				pool[at[entered[t]]++] = t;
		free(entered);
		free(at);
	}
	int rc = BSIM_OK;
	for (long w = 0; w < walks && rc == BSIM_OK; w++) {
		int g = start, a = 0, loc = -1;
		long t = 0; /* steps so far */
		/* the gate after the start (set->next): the start trial drawn
		 * first goes on in the next gate as its own continuation */
		const bsim_markov_next *after = NULL;
		int trial = -1;
		for (long n = 0; loc < 0; n++) {
			if (n == WALK_GATES_MAX) {
				rc = bsim_error_set(
				        err, BSIM_EFAIL,
				        "a walk of the chain entered %ld gates without an "
				        "outcome (max_steps %ld)",
				        n, max_steps);
				break;
			}
			const bsim_markov_map *m = &set->maps[gate_map[g]];
			int x;
			if (after) {
				x = after->exit[trial];
				t += after->steps[trial];
				after = NULL;
				trial = -1;
			} else {
				const size_t u = (size_t)bsim_markov_bin_first(m, a) +
				                 (size_t)draw(&rng, bsim_markov_bin_trials(m, a));
				x = m->hold_exit[u];
				t += m->hold_steps[u];
				trial = n == 0 ? (int)u : -1; /* the start bin's units come first */
			}
			if (max_steps > 0 && t >= max_steps && (x == 0 || t > max_steps)) {
				t = max_steps; /* the trial's duration is over first */
				loc = cols + rows + g;
			} else if (x == 0) {
				loc = cols + rows + g; /* the gate's limit */
			} else {
				int state;
				bsim_markov_exit_target(cols, rows, nb, g, x, &state, &loc);
				if (state >= 0 && trial >= 0 && set->next && state / nb != g) {
					const int h = state / nb,
					          np = pool_first[h + 1] - pool_first[h];
					after = &set->next[(size_t)gate_map[g] * set->n +
					                   gate_map[h]];
					if (trial >= after->trials && np == 0)
						after = NULL; /* none continued there: bins */
					else if (trial >= after->trials)
						trial = pool[pool_first[h] + draw(&rng, np)];
				}
				if (state >= 0) {
					g = state / nb;
					a = state % nb;
				}
			}
		}
		if (rc != BSIM_OK)
			break;
		const int kind = loc < cols ? 0 : loc < cols + rows ? 1 : 2;
		const double ts = (double)t * dt;
		long b = t / bin_steps;
		b = b < n_bins ? b : n_bins - 1;
		p->p_time[b * 3 + kind] += 1.0;
		p->p_loc_time[loc] += 1.0;
		sum[kind] += ts;
		sum2[kind] += ts * ts;
		n_kind[kind]++;
	}
	free(gate_map);
	free(pool);
	free(pool_first);
	if (rc != BSIM_OK)
		return rc;
	for (int i = 0; i < n_bins * 3; i++)
		p->p_time[i] /= (double)walks;
	for (int i = 0; i < p->n_locations; i++)
		p->p_loc_time[i] /= (double)walks;
	for (int k = 0; k < 3; k++) {
		p->p_by[k] = (double)n_kind[k] / (double)walks;
		p->t_mean[k] = n_kind[k] > 0 ? sum[k] / (double)n_kind[k] : NAN;
		double var = n_kind[k] > 1 ? (sum2[k] - sum[k] * sum[k] / (double)n_kind[k]) /
		                                     (double)(n_kind[k] - 1)
		                           : NAN;
		p->t_sd[k] = var > 0 ? sqrt(var) : n_kind[k] > 1 ? 0.0 : NAN;
	}
	p->walks = walks;
	p->duration = (double)max_steps * dt;
	p->time_bin = (double)bin_steps * dt;
	p->n_time_bins = n_bins;
	return BSIM_OK;
}
