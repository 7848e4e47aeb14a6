/* The Markov chain of a gate lattice (beamsim/markov.h) against
 * independent truths:
 *   - on one gate the chain is the map itself, and on a column of two
 *     gates with a loop between them it is the closed form of a geometric
 *     series, by LU and by the series alike;
 *   - probability is conserved: the final locations and the gates visited
 *     each sum to one on the C-track;
 *   - on a field of one gate, where the essay's protocol is exact, the
 *     chain's probability of each outcome agrees with direct simulation of
 *     independent trials within their sampling error; on a column of two,
 *     with the gate after the start, where the entry bins alone do not;
 *   - the map is the same with 1 and 2 threads; its cache reuses a map only
 *     when nothing it depends on changed;
 *   - self-consistent and flow-weighted entry states are exits of the
 *     previous pass's single gates into the bin, as that pass's own record
 *     says;
 *   - the time to the outcome: on hand-made maps with fixed holding times
 *     the first-step mean is the hand-solved one (two gates passed
 *     straight through: the sum) and the walks agree with it; on one gate
 *     the first-step mean is the map's own samples', and the walks' exit
 *     time agrees with direct simulation within the sampling errors;
 *   - a bad input exits 2 naming what is wrong and writes nothing. */
#define _POSIX_C_SOURCE 200809L

#include <dirent.h>
#include <math.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmocka.h>

#include "beamsim/lattice.h"
#include "beamsim/markov.h"
#include "beamsim/schedule.h"
#include "beamsim/trial.h"
#include "beamsim/version.h"
#include "beamsim/lattice_outcome.h"
#include "support.h"

static void near(double a, double b, double eps, int line)
{
	if (!(fabs(a - b) <= eps))
		fail_msg("line %d: %.17g is not %.17g within %g", line, a, b, eps);
}
#define assert_double_equal(a, b, eps) near((a), (b), (eps), __LINE__)

/* Bins of one position, speed and direction: bin 0 the start, 1 bottom, 2
 * left, 3 right, 4 top (the edge the next gate is entered through). */
enum { START = 0, BOTTOM = 1, LEFT = 2, RIGHT = 3, TOP = 4, NB = 5 };

static bsim_markov_set hand_set(double k, const int rows[][NB], int n_rows, const int *which)
{
	bsim_markov_set s = {0};
	s.def = bsim_markov_def_default();
	s.def.bins = (bsim_markov_bins){1, 1, 1, 40.0};
	s.n = 1;
	s.maps = calloc(1, sizeof *s.maps);
	s.maps[0].k[0] = s.maps[0].k[1] = k;
	s.maps[0].n_bins = NB;
	int dense[NB * NB] = {0};
	for (int i = 0; i < n_rows; i++)
		memcpy(dense + which[i] * NB, rows[i], sizeof rows[i]);
	bsim_error err;
	assert_int_equal(bsim_markov_map_set_counts(&s.maps[0], dense, &err), BSIM_OK);
	return s;
}

/* Whether maps a and b count the same exits from entry bin `row` (every
 * row: row -1). */
static int counts_same(const bsim_markov_map *a, const bsim_markov_map *b, int row)
{
	for (int r = row < 0 ? 0 : row; r < (row < 0 ? a->n_bins : row + 1); r++)
		for (int x = 0; x < a->n_bins; x++)
			if (bsim_markov_map_count(a, r, x) != bsim_markov_map_count(b, r, x))
				return 0;
	return a->n_bins == b->n_bins;
}

/* Holding times for hand_set's map, its rows of 100 trials: each trial of
 * row which[i] with exit x holds steps[i][x] steps (rows not given: stuck
 * after 1 step, never visited). */
static void hand_hold(bsim_markov_set *s, const int steps[][NB], int n_rows, const int *which)
{
	bsim_markov_map *m = &s->maps[0];
	m->trials = m->start_trials = 100;
	m->hold_exit = calloc(NB * 100, sizeof(int));
	m->hold_steps = malloc(NB * 100 * sizeof(int));
	for (int u = 0; u < NB * 100; u++)
		m->hold_steps[u] = 1;
	for (int i = 0; i < n_rows; i++) {
		const int a = which[i];
		int t = 0;
		for (int x = 0; x < NB; x++)
			for (int c = 0; c < bsim_markov_map_count(m, a, x); c++, t++) {
				m->hold_exit[a * 100 + t] = x;
				m->hold_steps[a * 100 + t] = steps[i][x];
			}
		assert_int_equal(t, 100);
	}
}

static double p_of(const bsim_markov_prediction *p, bsim_location_kind kind, int ix, int iy)
{
	for (int i = 0; i < p->n_locations; i++)
		if (p->loc[i].kind == kind && p->loc[i].ix == ix && p->loc[i].iy == iy)
			return p->p[i];
	fail_msg("no location %d %d %d", kind, ix, iy);
	return NAN;
}

/* One gate: the chain's final locations are the start row of the map. */
static void test_one_gate_is_the_map(void **state)
{
	(void)state;
	bsim_scene s;
	assert_int_equal(bsim_lattice_scene_init(&s, 1, 1, 6, 30), BSIM_OK);
	/* counts out of 100: stuck 40, on into the gate above (the end) 30,
	 * out left 20 (a side), out right 10 (a side) */
	const int rows[][NB] = {{40, 30, 10, 20, 0}};
	const int which[] = {START};
	bsim_markov_set set = hand_set(400, rows, 1, which);
	bsim_markov_prediction p;
	bsim_error err;
	assert_int_equal(bsim_markov_predict(&s, &set, &p, &err), BSIM_OK);
	assert_true(p.exact);
	assert_double_equal(p_of(&p, BSIM_LOCATION_END, 0, 0), 0.30, 1e-15);
	assert_double_equal(p_of(&p, BSIM_LOCATION_SIDE, 0, 0), 0.30, 1e-15);
	assert_double_equal(p_of(&p, BSIM_LOCATION_STUCK, 0, 0), 0.40, 1e-15);
	assert_double_equal(p.p_gates[1], 1.0, 1e-15);
	assert_double_equal(p.mean_gates, 1.0, 1e-15);
	bsim_markov_prediction_free(&p);
	bsim_markov_set_free(&set);
	bsim_scene_free(&s);
}

/* Two gates in a column with a loop: from the start, a goes up into gate
 * (0, 1) (its bottom bin), the rest is stuck; from its bottom bin gate 1
 * sends b to the end, c back down into gate 0 (its top bin), the rest
 * stuck; from its top bin gate 0 sends d up again, the rest out to a side.
 * With r = c d the loop's gain:
 *   P(end) = a b / (1 - r), P(side:0) = a c (1 - d) / (1 - r),
 *   P(k gates) = a b r^j for k = 2 + 2 j, a c (1 - d) r^j for k = 3 + 2 j. */
static void test_two_gates_geometric(void **state)
{
	(void)state;
	const double a = 0.6, b = 0.5, c = 0.3, d = 0.7, r = c * d;
	bsim_scene s;
	assert_int_equal(bsim_lattice_scene_init(&s, 1, 2, 6, 30), BSIM_OK);
	const int rows[][NB] = {
	        {40, 60, 0, 0, 0},  /* start: stuck 0.4, up 0.6 */
	        {20, 50, 0, 0, 30}, /* bottom bin: stuck 0.2, end 0.5, down 0.3 */
	        {0, 70, 30, 0, 0},  /* top bin: up 0.7, out right 0.3 (a side) */
	};
	const int which[] = {START, BOTTOM, TOP};
	bsim_markov_set set = hand_set(400, rows, 3, which);
	bsim_markov_prediction p;
	bsim_error err;
	assert_int_equal(bsim_markov_predict_tol(&s, &set, 1e-12, &p, &err), BSIM_OK);
	assert_true(p.exact);
	assert_double_equal(p_of(&p, BSIM_LOCATION_END, 0, 0), a * b / (1 - r), 1e-13);
	assert_double_equal(p_of(&p, BSIM_LOCATION_SIDE, 0, 0), a * c * (1 - d) / (1 - r), 1e-13);
	assert_double_equal(p_of(&p, BSIM_LOCATION_STUCK, 0, 0), 0.4, 1e-13);
	assert_double_equal(p_of(&p, BSIM_LOCATION_STUCK, 0, 1), a * 0.2 / (1 - r), 1e-13);
	for (int j = 0; j < 5; j++) {
		assert_double_equal(p.p_gates[2 + 2 * j], a * b * pow(r, j) + a * 0.2 * pow(r, j),
		                    1e-13);
		assert_double_equal(p.p_gates[3 + 2 * j], a * c * (1 - d) * pow(r, j), 1e-13);
	}
	/* The series alone gives the same: the LU's answer is not the only one. */
	double sum = 0.0;
	for (int k = 1; k <= p.n_gates; k++)
		sum += p.p_gates[k];
	assert_double_equal(sum, 1.0, 1e-12);
	bsim_markov_prediction_free(&p);
	bsim_markov_set_free(&set);
	bsim_scene_free(&s);
}

/* A set of states never left. Reached: a column of two gates whose start
 * goes up and whose bins pass the body up and down between them with
 * probability 1 (as a bin of few single gates can): the series and the
 * sweeps stop within a few thousand steps, not at their limit of 1e6,
 * and say that all of it is left in the field; the LU of the singular
 * I - Q is not taken for an answer. Not reached: two gates side by side
 * whose side bins pass the body to each other, the start going straight
 * to the end: the iterative answer stands (the end 1), I - Q singular. */
static void test_closed_loop_said(void **state)
{
	(void)state;
	bsim_scene s;
	assert_int_equal(bsim_lattice_scene_init(&s, 1, 2, 6, 30), BSIM_OK);
	const int rows[][NB] = {
	        {0, 100, 0, 0, 0}, /* start: up */
	        {0, 0, 0, 0, 100}, /* bottom bin: down, into the top bin below */
	        {0, 100, 0, 0, 0}, /* top bin: up, into the bottom bin above */
	};
	const int which[] = {START, BOTTOM, TOP};
	bsim_markov_set set = hand_set(400, rows, 3, which);
	bsim_error err;
	for (int gates = 0; gates < 2; gates++) {
		bsim_markov_prediction p;
		assert_int_equal(bsim_markov_predict_with(&s, &set, 1e-9,
		                                          gates ? BSIM_MARKOV_GATES : 0, &p, &err),
		                 BSIM_OK);
		const int steps = gates ? p.n_gates : p.sweeps;
		print_message("closed loop, %s: %d steps, %g left in the field\n",
		              gates ? "series" : "sweeps", steps, p.left_in_field);
		assert_true(steps < 10000);
		assert_double_equal(p.left_in_field, 1.0, 1e-12);
		assert_false(p.exact);
		for (int i = 0; i < p.n_locations; i++)
			assert_double_equal(p.p[i], 0.0, 1e-12);
		bsim_markov_prediction_free(&p);
	}
	bsim_markov_set_free(&set);
	bsim_scene_free(&s);

	assert_int_equal(bsim_lattice_scene_init(&s, 2, 1, 6, 30), BSIM_OK);
	const int side[][NB] = {
	        {0, 100, 0, 0, 0}, /* start: up, the end */
	        {0, 0, 0, 100, 0}, /* left bin: back to the left, into its right bin */
	        {0, 0, 100, 0, 0}, /* right bin: back to the right, into its left bin */
	};
	const int at[] = {START, LEFT, RIGHT};
	set = hand_set(400, side, 3, at);
	bsim_markov_prediction p;
	assert_int_equal(bsim_markov_predict_tol(&s, &set, 1e-12, &p, &err), BSIM_OK);
	assert_false(p.exact);
	assert_double_equal(p.left_in_field, 0.0, 1e-12);
	double end = 0.0;
	for (int i = 0; i < p.n_locations; i++)
		end += p.loc[i].kind == BSIM_LOCATION_END ? p.p[i] : 0.0;
	assert_double_equal(end, 1.0, 1e-12);
	bsim_markov_prediction_free(&p);
	bsim_markov_set_free(&set);
	bsim_scene_free(&s);
}

/* W walks of the time to the outcome (seed 3) against the chain's
 * solution p of s: their totals of end, side and stuck are p's, and their
 * mean time the first-step mean, within 4.5 of the walks' standard errors. */
static void walks_agree(const bsim_scene *s, const bsim_markov_set *set, bsim_markov_prediction *p,
                        long W)
{
	bsim_error err;
	assert_int_equal(bsim_markov_predict_time(s, set, W, 3, p, &err), BSIM_OK);
	double mean = 0.0, m2 = 0.0;
	for (int k = 0; k < 3; k++) {
		mean += p->p_by[k] * p->t_mean[k];
		m2 += p->p_by[k] * (p->t_sd[k] * p->t_sd[k] + p->t_mean[k] * p->t_mean[k]);
		double tot = 0.0;
		for (int i = 0; i < p->n_locations; i++)
			tot += (int)p->loc[i].kind == k ? p->p[i] : 0.0;
		assert_double_equal(p->p_by[k], tot, 4.5 * sqrt(tot * (1 - tot) / W) + 1e-12);
	}
	const double se = sqrt((m2 - mean * mean) / W);
	print_message("mean time: first step %.4f s, walks %.4f s (se %.4f)\n", p->mean_time, mean,
	              se);
	assert_true(se > 0);
	assert_double_equal(mean, p->mean_time, 4.5 * se);
}

/* Time to the outcome on hand-made maps with fixed holding times (steps):
 * - two gates passed straight through (the start up after 500 steps, the
 *   gate above to the end after 700): the time is the sum, 1200 steps,
 *   by first-step analysis and in every walk; with a duration of 1000
 *   steps every walk is stuck in the second gate at 1000 steps;
 * - the loop of test_two_gates_geometric with times: the expected steps
 *   from first-step equations solved by hand,
 *     E0 = 0.4 3000 + 0.6 (500 + E1),
 *     E1 = 0.2 3000 + 0.5 700 + 0.3 (400 + E2),
 *     E2 = 0.7 (300 + E1) + 0.3 200,
 *   so E1 = (1070 + 0.3 270) / (1 - 0.3 0.7); the walks' mean within 4.5 of
 *   their standard errors, and their totals the chain's p within 4.5. */
static void test_time_by_hand(void **state)
{
	(void)state;
	bsim_scene s;
	assert_int_equal(bsim_lattice_scene_init(&s, 1, 2, 6, 30), BSIM_OK);
	const double dt = s.dt;
	bsim_error err;
	{
		const int rows[][NB] = {{0, 100, 0, 0, 0}, {0, 100, 0, 0, 0}};
		const int steps[][NB] = {{1, 500, 1, 1, 1}, {1, 700, 1, 1, 1}};
		const int which[] = {START, BOTTOM};
		bsim_markov_set set = hand_set(400, rows, 2, which);
		hand_hold(&set, steps, 2, which);
		bsim_markov_prediction p;
		assert_int_equal(bsim_markov_predict(&s, &set, &p, &err), BSIM_OK);
		assert_true(p.has_time);
		assert_double_equal(p.mean_time, 1200 * dt, 1e-9);
		assert_int_equal(bsim_markov_predict_time(&s, &set, 1000, 7, &p, &err), BSIM_OK);
		assert_double_equal(p.p_by[0], 1.0, 0.0);
		assert_double_equal(p.t_mean[0], 1200 * dt, 1e-9);
		assert_double_equal(p.t_sd[0], 0.0, 1e-9);
		double in_bin = 0.0; /* all of it in the bin of 1200 steps */
		const int b = (int)floor(1200 * dt / p.time_bin + 1e-9);
		in_bin = p.p_time[b * 3];
		assert_double_equal(in_bin, 1.0, 1e-12);
		bsim_scene short_s = s;
		short_s.max_steps = 1000;
		assert_int_equal(bsim_markov_predict_time(&short_s, &set, 1000, 7, &p, &err),
		                 BSIM_OK);
		assert_double_equal(p.p_by[2], 1.0, 0.0);
		assert_double_equal(p.t_mean[2], 1000 * dt, 1e-9);
		assert_double_equal(p.duration, 1000 * dt, 1e-12);
		for (int i = 0; i < p.n_locations; i++)
			assert_double_equal(
			        p.p_loc_time[i],
			        p.loc[i].kind == BSIM_LOCATION_STUCK && p.loc[i].iy == 1, 0.0);
		bsim_markov_prediction_free(&p);
		bsim_markov_set_free(&set);
	}
	{
		const int rows[][NB] = {{40, 60, 0, 0, 0}, {20, 50, 0, 0, 30}, {0, 70, 30, 0, 0}};
		const int steps[][NB] = {
		        {3000, 500, 1, 1, 1}, {3000, 700, 1, 1, 400}, {1, 300, 200, 1, 1}};
		const int which[] = {START, BOTTOM, TOP};
		bsim_markov_set set = hand_set(400, rows, 3, which);
		hand_hold(&set, steps, 3, which);
		bsim_markov_prediction p;
		assert_int_equal(bsim_markov_predict_tol(&s, &set, 1e-12, &p, &err), BSIM_OK);
		const double e2_free = 0.7 * 300 + 0.3 * 200; /* E2 = 270 + 0.7 E1 */
		const double e1 = (0.2 * 3000 + 0.5 * 700 + 0.3 * 400 + 0.3 * e2_free) /
		                  (1 - 0.3 * 0.7),
		             e0 = 0.4 * 3000 + 0.6 * (500 + e1);
		assert_double_equal(p.mean_time, e0 * dt, 1e-9 * e0 * dt);
		/* the sweeps' expected visits give the same */
		bsim_markov_prediction q;
		assert_int_equal(bsim_markov_predict_with(&s, &set, 1e-12, 0, &q, &err), BSIM_OK);
		assert_double_equal(q.mean_time, e0 * dt, 1e-9 * e0 * dt);
		bsim_markov_prediction_free(&q);
		walks_agree(&s, &set, &p, 40000);
		bsim_markov_prediction_free(&p);
		bsim_markov_set_free(&set);
	}
	bsim_scene_free(&s);
}

static const char *exe_dir(const char *name)
{
	static char buf[1024];
	snprintf(buf, sizeof buf, "%s", bsim_test_dir(name));
	return buf;
}

/* The C-track with maps of few trials: everything sums to one, by the
 * series (too many states for LU), and the answer is a distribution over
 * the field's own locations. */
static void test_conservation(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_error err;
	assert_int_equal(
	        bsim_scene_load(bsim_test_src("configs/lattice/c_track.yaml"), NULL, 0, &s, &err),
	        BSIM_OK);
	bsim_markov_def def = bsim_markov_def_default();
	def.train_trials = 20; /* a small training field: conservation holds for any */
	def.bins = (bsim_markov_bins){2, 2, 2, 40.0};
	def.trials = 4;
	def.start_trials = 0; /* the start's as the others': conservation holds for any */
	bsim_markov_set set;
	const char *dir = exe_dir("conservation");
	assert_int_equal(bsim_markov_build(&s, &def, dir, &set, &err), BSIM_OK);
	assert_int_equal(set.n, 2); /* k = 100 and 400 */
	bsim_markov_prediction p;
	assert_int_equal(bsim_markov_predict_tol(&s, &set, 1e-12, &p, &err), BSIM_OK);
	double sum = 0.0, sum_gates = 0.0;
	for (int i = 0; i < p.n_locations; i++) {
		assert_true(p.p[i] >= 0.0);
		sum += p.p[i];
	}
	for (int k = 1; k <= p.n_gates; k++)
		sum_gates += p.p_gates[k];
	assert_int_equal(p.n_locations, 9 + 9 + 81);
	assert_false(p.exact);
	assert_true(p.left_in_field <= 1e-12);
	assert_double_equal(sum, 1.0, 1e-11);
	assert_double_equal(sum_gates, 1.0, 1e-11);
	bsim_markov_prediction_free(&p);
	bsim_markov_set_free(&set);
	bsim_scene_free(&s);
}

/* The C-track and its maps of 4 trials per bin (4,4,3 bins, the start's
 * trials as the others': what the tests of the solution check holds for
 * any maps), built into the test's folder name. */
static void c_track_maps(const char *name, bsim_scene *s, bsim_markov_set *set)
{
	bsim_error err;
	assert_int_equal(
	        bsim_scene_load(bsim_test_src("configs/lattice/c_track.yaml"), NULL, 0, s, &err),
	        BSIM_OK);
	bsim_markov_def def = bsim_markov_def_default();
	def.train_trials = 0; /* states uniform in each bin */
	def.bins = (bsim_markov_bins){4, 4, 3, def.bins.v_max};
	def.trials = 4;
	def.start_trials = 0;
	assert_int_equal(bsim_markov_build(s, &def, exe_dir(name), set, &err), BSIM_OK);
}

/* The series' tolerance: on the C-track (maps of 4 trials per bin), the
 * prediction stopped at the default tolerance differs
 * from the one summed to 1e-12 by no more than the probability it left in
 * the field, location by location and in all (each partial sum only
 * grows), and what it left plus what it placed is the whole. */
static void test_tolerance(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_markov_set set;
	bsim_error err;
	c_track_maps("tolerance", &s, &set);
	bsim_markov_prediction fine, p;
	assert_int_equal(bsim_markov_predict_tol(&s, &set, 1e-12, &fine, &err), BSIM_OK);
	assert_int_equal(bsim_markov_predict(&s, &set, &p, &err), BSIM_OK);
	assert_false(p.exact);
	assert_true(p.tol == BSIM_MARKOV_TOL && fine.tol == 1e-12);
	assert_true(p.left_in_field <= BSIM_MARKOV_TOL && fine.left_in_field <= 1e-12);
	assert_true(p.left_in_field > fine.left_in_field);
	assert_true(p.n_gates < fine.n_gates);
	double sum = 0.0, diff = 0.0;
	for (int i = 0; i < p.n_locations; i++) {
		double d = fine.p[i] - p.p[i];
		assert_true(d >= -1e-15 && d <= p.left_in_field + 1e-15);
		diff += fabs(d);
		sum += p.p[i];
	}
	assert_true(diff <= p.left_in_field - fine.left_in_field + 1e-14);
	assert_double_equal(sum + p.left_in_field, 1.0, 1e-12);
	/* the terms both sums share are the same terms */
	for (int k = 1; k <= p.n_gates; k++)
		assert_double_equal(p.p_gates[k], fine.p_gates[k], 1e-15);
	bsim_error bad;
	bsim_markov_prediction q;
	assert_int_equal(bsim_markov_predict_tol(&s, &set, 0.0, &q, &bad), BSIM_EINPUT);
	bsim_markov_prediction_free(&fine);
	bsim_markov_prediction_free(&p);
	bsim_markov_set_free(&set);
	bsim_scene_free(&s);
}

/* The sweeps against the other path through the chain, the series to
 * 1e-12, on the C-track (maps of 4 trials per bin): at
 * every location within the sweeps' bound (left_in_field, plus the
 * series' own 1e-12), both short of the exact p, the probabilities plus
 * the bound at least one and at most one; the sweeps' expected visits
 * are the series' mean of gates visited. */
static void test_sweeps_against_series(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_markov_set set;
	bsim_error err;
	c_track_maps("sweeps", &s, &set);
	bsim_markov_prediction ser, fast, gates;
	assert_int_equal(bsim_markov_predict_with(&s, &set, 1e-12, BSIM_MARKOV_GATES, &ser, &err),
	                 BSIM_OK);
	assert_int_equal(bsim_markov_predict_with(&s, &set, BSIM_MARKOV_TOL, 0, &fast, &err),
	                 BSIM_OK);
	assert_int_equal(bsim_markov_predict_with(&s, &set, BSIM_MARKOV_TOL, BSIM_MARKOV_GATES,
	                                          &gates, &err),
	                 BSIM_OK);
	assert_int_equal(ser.sweeps, 0);
	assert_true(ser.left_in_field <= 1e-12);
	assert_true(fast.sweeps > 0 && fast.left_in_field <= BSIM_MARKOV_TOL);
	assert_int_equal(fast.n_gates, 0);
	double sum = 0.0;
	for (int i = 0; i < fast.n_locations; i++) {
		/* both short of the exact p by at most what they left */
		double d = ser.p[i] - fast.p[i];
		assert_true(fabs(d) <= fast.left_in_field + ser.left_in_field);
		assert_true(d >= -ser.left_in_field - 1e-15);
		sum += fast.p[i];
	}
	assert_true(sum + fast.left_in_field >= 1.0 - 1e-12 && sum <= 1.0 + 1e-12);
	assert_true(gates.sweeps == 0 && gates.n_gates > 0 && fast.p_gates[0] == 0.0);
	assert_double_equal(fast.mean_gates, ser.mean_gates, 1e-3);
	/* markov predict's default: the sweeps to the maps' sampling tolerance.
	 * Every location short of the exact p, in all by at most what was
	 * left (the distance from the exact distribution), itself at most the
	 * tolerance, 1 / (32 sqrt(trials)). */
	bsim_markov_prediction lean;
	const double tol = bsim_markov_tol_sampling(&set);
	assert_double_equal(tol, 1.0 / (32.0 * sqrt((double)set.maps[0].trials)), 1e-15);
	assert_int_equal(bsim_markov_predict_with(&s, &set, tol, 0, &lean, &err), BSIM_OK);
	assert_true(lean.sweeps > 0 && lean.left_in_field <= tol);
	double short_by = 0.0;
	for (int i = 0; i < lean.n_locations; i++) {
		const double d = ser.p[i] - lean.p[i];
		assert_true(d >= -ser.left_in_field - 1e-15);
		short_by += fabs(d);
	}
	assert_true(short_by <= lean.left_in_field + 1e-12);
	bsim_markov_prediction_free(&lean);
	bsim_markov_prediction_free(&ser);
	bsim_markov_prediction_free(&fast);
	bsim_markov_prediction_free(&gates);
	bsim_markov_set_free(&set);
	bsim_scene_free(&s);
}

/* What a map cost, against what its single gates must have taken: a
 * stuck trial runs gate_steps steps, any other at least one, so a map's
 * steps lie between stuck * gate_steps + the others and trials *
 * gate_steps; read back from the map's .cost file they are the same. With
 * self entries each pass's cost holds the passes before it: pass 0 runs
 * the uniform map's single gates again (the same steps), and a build with
 * one more pass adds just that pass's steps to the cached passes'. */
static void check_steps(const bsim_markov_map *m, long long steps, long gate_steps)
{
	long stuck = 0, total = (long)m->n_bins * m->trials;
	for (int a = 0; a < m->n_bins; a++)
		stuck += bsim_markov_map_count(m, a, 0);
	assert_true(steps >= (long long)stuck * gate_steps + (total - stuck));
	assert_true(steps <= (long long)total * gate_steps);
}

static void test_map_cost(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_error err;
	assert_int_equal(
	        bsim_scene_load(bsim_test_src("configs/lattice/c_track.yaml"), NULL, 0, &s, &err),
	        BSIM_OK);
	const long gate_steps = s.gate_steps > 0 ? s.gate_steps : s.max_steps;
	bsim_markov_def def = bsim_markov_def_default();
	def.train_trials = 0; /* states uniform in each bin */
	def.bins = (bsim_markov_bins){1, 1, 1, 40.0};
	def.trials = 8;
	def.start_trials = 0; /* the self-consistent maps' pass 0 is this map */
	def.threads = 1;
	char uni[1024], self[1024];
	snprintf(uni, sizeof uni, "%s", exe_dir("cost_uniform"));
	snprintf(self, sizeof self, "%s", exe_dir("cost_self"));
	bsim_markov_set u, back, s1, s2;
	assert_int_equal(bsim_markov_build(&s, &def, uni, &u, &err), BSIM_OK);
	bsim_options opts;
	assert_int_equal(bsim_markov_load(&s, uni, &opts, &back, &err), BSIM_OK);
	assert_int_equal(back.n, u.n);
	for (int i = 0; i < u.n; i++) {
		check_steps(&u.maps[i], u.maps[i].steps, gate_steps);
		assert_true(u.maps[i].cost == u.maps[i].seconds && u.maps[i].cost > 0.0);
		assert_true(back.maps[i].steps == u.maps[i].steps);
		assert_true(fabs(back.maps[i].cost - u.maps[i].cost) <= 1e-5 * u.maps[i].cost);
	}
	def.self_entries = 1;
	def.self_passes = 1;
	assert_int_equal(bsim_markov_build(&s, &def, self, &s1, &err), BSIM_OK);
	def.self_passes = 2;
	assert_int_equal(bsim_markov_build(&s, &def, self, &s2, &err), BSIM_OK);
	for (int i = 0; i < u.n; i++) {
		/* the same stiffness pair in all three sets */
		assert_true(s1.maps[i].k[0] == u.maps[i].k[0] && s2.maps[i].k[1] == u.maps[i].k[1]);
		check_steps(&s1.maps[i], s1.maps[i].steps - u.maps[i].steps, gate_steps);
		check_steps(&s2.maps[i], s2.maps[i].steps - s1.maps[i].steps, gate_steps);
		/* pass 2 alone simulated now, passes 0 and 1 in its cost too */
		assert_true(s2.maps[i].cost >= s1.maps[i].cost + s2.maps[i].seconds - 1e-5);
	}
	bsim_markov_set_free(&u);
	bsim_markov_set_free(&back);
	bsim_markov_set_free(&s1);
	bsim_markov_set_free(&s2);
	bsim_scene_free(&s);
}

/* The start bin's trials are part of a map's key, only where they differ
 * from the other bins' (a map built before keeps its key): a map of other
 * start trials is built, never reused. A map directory without the map a
 * scene needs is refused naming the lines of the nearest map's key that
 * differ. */
static void test_start_trials_key(void **state)
{
	(void)state;
	bsim_scene s, s5;
	assert_int_equal(bsim_lattice_scene_init(&s, 1, 1, 6, 30), BSIM_OK);
	assert_int_equal(bsim_lattice_scene_init(&s5, 1, 1, 5, 30), BSIM_OK);
	const char *dir = exe_dir("start_trials");
	bsim_markov_def def = bsim_markov_def_default();
	def.train_trials = 0; /* states uniform in each bin */
	def.bins = (bsim_markov_bins){1, 1, 1, 40.0};
	def.trials = 20;
	const int starts[] = {20, 60, 20};
	uint64_t key[3];
	for (int i = 0; i < 3; i++) {
		def.start_trials = starts[i];
		bsim_markov_set set;
		bsim_error err;
		assert_int_equal(bsim_markov_build(&s, &def, dir, &set, &err), BSIM_OK);
		const bsim_markov_map *m = &set.maps[0];
		key[i] = m->key;
		assert_int_equal(m->start_trials, starts[i]);
		assert_int_equal(set.built, i < 2);
		assert_int_equal(set.reused, i == 2);
		assert_int_equal(strstr(m->key_text, "start_trials 60\n") != NULL, starts[i] == 60);
		assert_null(strstr(m->key_text, "start_trials 20"));
		long row0 = 0;
		for (int x = 0; x < NB; x++)
			row0 += bsim_markov_map_count(m, START, x);
		assert_int_equal(row0, starts[i]);
		bsim_markov_set_free(&set);
	}
	assert_true(key[0] != key[1]);
	assert_true(key[0] == key[2]);
	/* a scene of another force: no map of its key; the refusal names the
	 * line of the key that differs, both ways */
	bsim_options opts = {0};
	bsim_markov_set set;
	bsim_error err;
	assert_int_equal(bsim_markov_load(&s5, dir, &opts, &set, &err), BSIM_EINPUT);
	print_message("%s\n", err.msg);
	assert_non_null(strstr(err.msg, "has 'effects propulsion 1 6 "));
	assert_non_null(strstr(err.msg, "needs 'effects propulsion 1 5 "));
	bsim_scene_free(&s);
	bsim_scene_free(&s5);
}

/* One gate, where the essay's protocol is the whole world: the chain from a
 * map of 1600 start trials (the other bins' 400: the start row counted and
 * weighed as its own) against 400 independent trials of the lattice run
 * directly, each outcome within 4.5 standard errors of the difference
 * (the maps' and the simulation's sampling errors together). */
static void test_one_gate_against_simulation(void **state)
{
	(void)state;
	bsim_scene s;
	assert_int_equal(bsim_lattice_scene_init(&s, 1, 1, 6, 30), BSIM_OK);
	bsim_markov_def def = bsim_markov_def_default();
	def.train_trials = 0; /* states uniform in each bin */
	def.bins = (bsim_markov_bins){1, 1, 1, 40.0};
	def.trials = 400;
	def.start_trials = 1600;
	def.seed = 11;
	def.after_start = 0; /* one gate: no gate after the start to take */
	bsim_markov_set set;
	bsim_error err;
	assert_int_equal(bsim_markov_build(&s, &def, exe_dir("one_gate"), &set, &err), BSIM_OK);
	bsim_markov_prediction p;
	assert_int_equal(bsim_markov_predict(&s, &set, &p, &err), BSIM_OK);
	const int N = 400;
	double sim[3] = {0, 0, 0}, t_out = 0.0, t_out2 = 0.0;
	int n_out = 0;
	bsim_trial_runner *r = bsim_trial_runner_alloc();
	const bsim_options none = {0};
	for (int t = 0; t < N; t++) {
		bsim_trial_result res;
		assert_int_equal(bsim_trial_run(r, &s, bsim_backend_default(), &none,
		                                bsim_schedule_seed_mix(99, 0, (uint64_t)t), NULL,
		                                &res, &err),
		                 BSIM_OK);
		const bsim_location_kind kind = bsim_lattice_location_of(&res).kind;
		sim[kind] += 1.0 / N;
		if (kind != BSIM_LOCATION_STUCK) {
			n_out++;
			t_out += res.t_end;
			t_out2 += res.t_end * res.t_end;
		}
	}
	bsim_trial_runner_free(r);
	const double chain[3] = {p_of(&p, BSIM_LOCATION_END, 0, 0),
	                         p_of(&p, BSIM_LOCATION_SIDE, 0, 0),
	                         p_of(&p, BSIM_LOCATION_STUCK, 0, 0)};
	int informative = 0;
	for (int k = 0; k < 3; k++) {
		double q = 0.5 * (sim[k] + chain[k]);
		double se = sqrt(2.0 * q * (1.0 - q) / N) + 1e-9;
		print_message("outcome %d: chain %.3f, simulation %.3f (se %.3f)\n", k, chain[k],
		              sim[k], se);
		assert_true(fabs(sim[k] - chain[k]) <= 4.5 * se);
		informative += q > 0.05 && q < 0.95;
	}
	assert_true(informative >= 2); /* the test can tell outcomes apart */

	/* Time. First-step analysis by hand on the map's own samples: from the
	 * start (bin 0) the body leaves after h0 on average; down (bin TOP,
	 * through the top edge of the gate below) it enters row 0 again
	 * through its bottom (bin BOTTOM), whose mean time is h1, returning with
	 * probability back: E = h0 + P(0 -> TOP) h1 / (1 - back). */
	const bsim_markov_map *m = &set.maps[0];
	assert_non_null(m->hold_steps);
	assert_int_equal(m->start_trials, 1600);
	int row0 = 0;
	for (int x = 0; x < NB; x++)
		row0 += bsim_markov_map_count(m, START, x);
	assert_int_equal(row0, 1600);
	/* the start's single gates first, then bin BOTTOM's */
	double h[2] = {0, 0};
	for (int t = 0; t < m->start_trials; t++)
		h[0] += m->hold_steps[t] * s.dt / m->start_trials;
	for (int t = 0; t < m->trials; t++)
		h[1] += m->hold_steps[m->start_trials + t] * s.dt / m->trials;
	const double down = (double)bsim_markov_map_count(m, START, TOP) / m->start_trials,
	             back = (double)bsim_markov_map_count(m, BOTTOM, TOP) / m->trials;
	const double e = h[0] + (down > 0 ? down * h[1] / (1 - back) : 0.0);
	assert_true(p.has_time);
	assert_double_equal(p.mean_time, e, 1e-9 * e);
	/* The walks' time of the trials out (end or side) against the direct
	 * trials' exit times: within 4.5 standard errors of the difference,
	 * the simulation's, the map's (its samples out) and the walks'. */
	const long W = 20000;
	assert_int_equal(bsim_markov_predict_time(&s, &set, W, 5, &p, &err), BSIM_OK);
	const double w_out = p.p_by[0] + p.p_by[1];
	const double c_mean = (p.p_by[0] * p.t_mean[0] + p.p_by[1] * p.t_mean[1]) / w_out;
	double c_var = 0.0;
	for (int k = 0; k < 2; k++)
		c_var += p.p_by[k] / w_out *
		         (p.t_sd[k] * p.t_sd[k] + (p.t_mean[k] - c_mean) * (p.t_mean[k] - c_mean));
	const double s_mean = t_out / n_out, s_var = t_out2 / n_out - s_mean * s_mean;
	const double se = sqrt(s_var / n_out + c_var / (w_out * m->trials) + c_var / (w_out * W));
	print_message("time out: chain %.3f s, simulation %.3f s (se %.3f); first step %.3f s\n",
	              c_mean, s_mean, se, p.mean_time);
	assert_true(n_out > 50 && se > 0);
	assert_double_equal(c_mean, s_mean, 4.5 * se);
	bsim_markov_prediction_free(&p);
	bsim_markov_set_free(&set);
	bsim_scene_free(&s);
}

/* How many of p's locations lie beyond 4.5 standard errors of the
 * difference from sim, N direct trials (the maps' T start trials' and the
 * simulation's sampling errors together). */
static int outcomes_off(const bsim_markov_prediction *p, const double *sim, int T, int N)
{
	int off = 0;
	for (int i = 0; i < p->n_locations; i++) {
		const double q = 0.5 * (sim[i] + p->p[i]);
		const double se = sqrt(q * (1.0 - q) * (1.0 / N + 1.0 / T)) + 1e-9;
		print_message("location %d (%d, %d, %d): chain %.3f, simulation %.3f (se %.3f)\n",
		              i, p->loc[i].kind, p->loc[i].ix, p->loc[i].iy, p->p[i], sim[i], se);
		off += !(fabs(sim[i] - p->p[i]) <= 4.5 * se);
	}
	return off;
}

/* The gate after the start against direct simulation: a column of two
 * gates of two stiffness pairs under the essay's protocol, where a body's
 * gates are single gates (each entered with its beams at rest). One bin
 * an edge: a bin's states, uniform over the edge, every speed to 40 m/s
 * and every direction, are nothing like a body leaving the start, so the
 * chain without the gate after the start is off on at least one outcome;
 * with it, the upper gate is run from each start trial's own exit and
 * every outcome agrees with 600 direct trials within 4.5 standard
 * errors; so it does with only the first 150 start trials continued, the
 * others taking their continuations pooled. The pairs of maps are those
 * the build names, read back alike; a pair short of a row is refused. */
static void test_after_start_against_simulation(void **state)
{
	(void)state;
	bsim_scene s;
	assert_int_equal(bsim_lattice_scene_init(&s, 1, 2, 6, 30), BSIM_OK);
	const double kl[2] = {100, 400}, kr[2] = {100, 300};
	assert_int_equal(bsim_lattice_build(&s, kl, kr), BSIM_OK);
	s.lattice.protocol = BSIM_PROTOCOL_ESSAY;
	bsim_markov_def def = bsim_markov_def_default();
	def.train_trials = 0; /* states uniform in each bin */
	def.bins = (bsim_markov_bins){1, 1, 1, 40.0};
	def.trials = 50;
	def.start_trials = 600;
	def.seed = 5;
	const char *dir = exe_dir("after_start");
	const int N = 600;
	double *sim = NULL;
	int off[3];
	/* none, every start trial continued, the first 150 (A) */
	const int A = 150;
	for (int v = 0; v < 3; v++) {
		const int after = v > 0;
		def.after_start = after;
		def.after_trials = v == 2 ? A : after ? 0 : -1; /* -1: none to continue */
		bsim_markov_set set;
		bsim_error err;
		assert_int_equal(bsim_markov_build(&s, &def, dir, &set, &err), BSIM_OK);
		assert_int_equal(set.n, 2);
		assert_int_equal(set.next != NULL, after);
		assert_int_equal(set.next_built, after ? 4 : 0);
		bsim_markov_prediction p;
		assert_int_equal(bsim_markov_predict(&s, &set, &p, &err), BSIM_OK);
		if (!sim) { /* one simulation for both: the same locations */
			sim = calloc((size_t)p.n_locations, sizeof *sim);
			bsim_test_simulate_locations(&s, p.loc, p.n_locations, N, 99, sim);
		}
		off[v] = outcomes_off(&p, sim, def.start_trials, N);
		if (after) {
			/* each continued start trial's continuation where it left
			 * into a gate */
			for (int i = 0; i < 4; i++) {
				const bsim_markov_next *x = &set.next[i];
				const bsim_markov_map *m = &set.maps[x->start];
				assert_int_equal(x->trials, v == 2 ? A : m->start_trials);
				for (int t = 0; t < x->trials; t++)
					assert_int_equal(x->exit[t] >= 0, m->hold_exit[t] > 0);
			}
			/* the walks take the same first two gates */
			walks_agree(&s, &set, &p, 20000);
			/* read back: the same prediction */
			bsim_markov_set again;
			bsim_options opts = {0};
			assert_int_equal(bsim_markov_load(&s, dir, &opts, &again, &err), BSIM_OK);
			assert_int_equal(again.next_reused, 4);
			bsim_markov_prediction q;
			assert_int_equal(bsim_markov_predict(&s, &again, &q, &err), BSIM_OK);
			for (int i = 0; i < p.n_locations; i++)
				assert_double_equal(q.p[i], p.p[i], 0.0);
			bsim_markov_prediction_free(&q);
			bsim_markov_set_free(&again);
		}
		bsim_markov_prediction_free(&p);
		bsim_markov_set_free(&set);
	}
	print_message("outcomes off: %d without the gate after the start, %d with, %d with the "
	              "first %d continued\n",
	              off[0], off[1], off[2], A);
	assert_true(off[0] >= 1);
	assert_int_equal(off[1], 0);
	assert_int_equal(off[2], 0);
	free(sim);

	/* The pairs of the first A are files of their own, beside those of
	 * every start trial; one short of its last row is refused, naming the
	 * file and the count. */
	const char *pair = bsim_test_glob_first(bsim_test_join(dir, "map_*.after_*.first150.csv"));
	assert_non_null(pair);
	char *text = bsim_test_read(pair);
	assert_non_null(text);
	const size_t len = strlen(text);
	assert_true(len > 2 && text[len - 1] == '\n');
	size_t cut = len - 1;
	while (cut > 0 && text[cut - 1] != '\n')
		cut--;
	char *shorter = strndup(text, cut), *name = strdup(strrchr(pair, '/') + 1);
	bsim_test_write(dir, name, shorter);
	{
		def.after_trials = A;
		bsim_markov_set again;
		bsim_error err;
		assert_int_equal(bsim_markov_build(&s, &def, dir, &again, &err), BSIM_EINPUT);
		print_message("%s\n", err.msg);
		assert_non_null(strstr(err.msg, name));
		assert_non_null(strstr(err.msg, "the first 150 of the start's single gates"));
		bsim_markov_set_free(&again);
	}
	bsim_test_write(dir, name, text);
	free(shorter);
	free(name);
	free(text);
	def.after_trials = 0;

	/* A pair the directory lacks: a column of another kind alone, then
	 * the column with that kind above the start. Both maps are there, the
	 * start's continuation in the new kind is not: refused, naming the
	 * file. */
	bsim_scene one;
	assert_int_equal(bsim_lattice_scene_init(&one, 1, 2, 6, 30), BSIM_OK);
	const double k1[2] = {250, 250};
	assert_int_equal(bsim_lattice_build(&one, k1, k1), BSIM_OK);
	bsim_markov_set set;
	bsim_error err;
	assert_int_equal(bsim_markov_build(&one, &def, dir, &set, &err), BSIM_OK);
	bsim_markov_set_free(&set);
	const double kl2[2] = {100, 250}, kr2[2] = {100, 250};
	assert_int_equal(bsim_lattice_build(&s, kl2, kr2), BSIM_OK);
	bsim_options opts = {0};
	assert_int_equal(bsim_markov_load(&s, dir, &opts, &set, &err), BSIM_EINPUT);
	print_message("%s\n", err.msg);
	assert_non_null(strstr(err.msg, ".after_"));
	assert_non_null(strstr(err.msg, "absent: the gate after the start"));
	bsim_scene_free(&one);
	bsim_scene_free(&s);
}

/* The training field against direct simulation: a column of three gates
 * of two stiffness pairs under the essay's protocol, one bin an edge and
 * no gate after the start, so that the gates above the start are
 * entered with a bin's states. States uniform over the edge, every speed
 * to 40 m/s and every direction, are nothing like a body's, and the chain
 * is off on at least one outcome; a training field of the same two kinds
 * (a 21 x 21 field, not the column), its entries the single gates'
 * states or its crossings counted, puts every outcome within 4.5
 * standard errors of 400 direct trials. */
static void test_training_against_simulation(void **state)
{
	(void)state;
	bsim_scene s;
	assert_int_equal(bsim_lattice_scene_init(&s, 1, 3, 6, 30), BSIM_OK);
	const double kl[3] = {100, 400, 100}, kr[3] = {100, 300, 100};
	assert_int_equal(bsim_lattice_build(&s, kl, kr), BSIM_OK);
	s.lattice.protocol = BSIM_PROTOCOL_ESSAY;
	bsim_markov_def def = bsim_markov_def_default();
	def.bins = (bsim_markov_bins){1, 1, 1, 40.0};
	def.trials = 100;
	def.start_trials = 600;
	def.after_start = 0;
	def.seed = 3;
	const char *dir = exe_dir("training");
	const int N = 400, train[3] = {0, 200, 200};
	double *sim = NULL;
	int off[3];
	for (int i = 0; i < 3; i++) {
		def.train_trials = train[i];
		def.train_crossings = i == 2;
		bsim_markov_set set;
		bsim_error err;
		assert_int_equal(bsim_markov_build(&s, &def, dir, &set, &err), BSIM_OK);
		assert_int_equal(set.built, 2);
		bsim_markov_prediction p;
		assert_int_equal(bsim_markov_predict(&s, &set, &p, &err), BSIM_OK);
		if (!sim) { /* one simulation for both: the same locations */
			sim = calloc((size_t)p.n_locations, sizeof *sim);
			bsim_test_simulate_locations(&s, p.loc, p.n_locations, N, 99, sim);
		}
		off[i] = outcomes_off(&p, sim, def.trials, N);
		bsim_markov_prediction_free(&p);
		bsim_markov_set_free(&set);
	}
	print_message("outcomes off: %d with uniform states, %d from the training field's "
	              "entries, %d from its crossings\n",
	              off[0], off[1], off[2]);
	assert_true(off[0] >= 1);
	assert_int_equal(off[1], 0);
	assert_int_equal(off[2], 0);
	free(sim);
	bsim_scene_free(&s);
}

/* A training field's crossings are single gates: under the essay's
 * protocol a gate entered is a gate at rest started from the entry's
 * state, so the crossings of a bin leave as single gates started from
 * states drawn among the same entries. A field of one gate kind (all its
 * entries of that kind), one bin an edge: the map counted from the
 * crossings (topped up to 1 single gate a bin) against the map of 400
 * single gates a bin from the field's entries, every exit of the bottom
 * bin (most entries) within 4.5 standard errors, and the mean time in the
 * gate too. The layout of a map of crossings reads back from its files,
 * and a bin topped up per crossing holds what the rule says. */
static void test_crossings_are_single_gates(void **state)
{
	(void)state;
	bsim_scene s;
	assert_int_equal(bsim_lattice_scene_init(&s, 3, 2, 6, 30), BSIM_OK);
	const double k[6] = {200, 200, 200, 200, 200, 200};
	assert_int_equal(bsim_lattice_build(&s, k, k), BSIM_OK);
	bsim_markov_def def = bsim_markov_def_default();
	def.bins = (bsim_markov_bins){1, 1, 1, 40.0};
	def.start_trials = 20;
	def.after_start = 0;
	def.train_trials = 300;
	def.seed = 7;
	const char *dir = exe_dir("crossings");
	bsim_markov_set set[2];
	bsim_error err;
	for (int i = 0; i < 2; i++) {
		def.train_crossings = 1 - i;
		def.trials = i ? 400 : 1;
		assert_int_equal(bsim_markov_build(&s, &def, dir, &set[i], &err), BSIM_OK);
		assert_int_equal(set[i].n, 1);
	}
	const bsim_markov_map *cx = &set[0].maps[0], *sg = &set[1].maps[0];
	assert_non_null(cx->bin_first);
	assert_null(sg->bin_first);
	const int nb = cx->n_bins;
	int a = 1; /* the bin most crossings entered */
	for (int b = 2; b < nb; b++)
		if (cx->bin_first[b + 1] - cx->bin_first[b] >
		    cx->bin_first[a + 1] - cx->bin_first[a])
			a = b;
	const long n = cx->bin_first[a + 1] - cx->bin_first[a], T = sg->trials;
	print_message("bin %d: %ld crossings\n", a, n);
	assert_true(n >= 200);
	int off = 0;
	for (int x = 0; x < nb; x++) {
		const double p = (double)bsim_markov_map_count(cx, a, x) / n,
		             q = (double)bsim_markov_map_count(sg, a, x) / T, m = 0.5 * (p + q);
		const double se = sqrt(m * (1.0 - m) * (1.0 / n + 1.0 / T)) + 1e-9;
		print_message("exit %d: crossings %.3f, single gates %.3f (se %.3f)\n", x, p, q,
		              se);
		off += !(fabs(p - q) <= 4.5 * se);
	}
	assert_int_equal(off, 0);
	/* the mean time in the gate, crossings against single gates */
	double mean[2] = {0, 0}, sq[2] = {0, 0};
	const bsim_markov_map *both[2] = {cx, sg};
	const long cnt[2] = {n, T};
	for (int i = 0; i < 2; i++) {
		const long u0 = both[i]->bin_first ? both[i]->bin_first[a]
		                                   : both[i]->start_trials + (long)(a - 1) * T;
		for (long u = u0; u < u0 + cnt[i]; u++) {
			mean[i] += both[i]->hold_steps[u];
			sq[i] += (double)both[i]->hold_steps[u] * both[i]->hold_steps[u];
		}
		mean[i] /= cnt[i];
		sq[i] = sq[i] / cnt[i] - mean[i] * mean[i];
	}
	const double se = sqrt(sq[0] / n + sq[1] / T);
	print_message("steps in the gate: crossings %.1f, single gates %.1f (se %.1f)\n", mean[0],
	              mean[1], se);
	assert_true(fabs(mean[0] - mean[1]) <= 4.5 * se);
	/* read back from the directory: the same layout and counts */
	def.train_crossings = 1;
	def.trials = 1;
	bsim_markov_set again;
	assert_int_equal(bsim_markov_build(&s, &def, dir, &again, &err), BSIM_OK);
	assert_int_equal(again.reused, 1);
	for (int b = 0; b <= nb; b++)
		assert_int_equal(again.maps[0].bin_first[b], cx->bin_first[b]);
	assert_true(counts_same(&again.maps[0], cx, -1));
	bsim_markov_set_free(&again);
	/* its start row one count over the start's trials: refused, naming
	 * the file, the line and the field */
	char name[64];
	snprintf(name, sizeof name, "map_%016llx.csv", (unsigned long long)cx->key);
	char *csv = bsim_test_read(bsim_test_join(dir, name));
	assert_non_null(csv);
	char *row = strchr(csv, '\n') + 1; /* "0,EXIT,COUNT,..." */
	char *count = strchr(strchr(row, ',') + 1, ',') + 1;
	assert_int_equal(row[0], '0');
	char text[16384];
	snprintf(text, sizeof text, "%.*s%d%s", (int)(count - csv), csv, atoi(count) + 1,
	         strchr(count, ','));
	bsim_test_write(dir, name, text);
	assert_int_equal(bsim_markov_build(&s, &def, dir, &again, &err), BSIM_EINPUT);
	print_message("%s\n", err.msg);
	assert_non_null(strstr(err.msg, name));
	assert_non_null(strstr(err.msg, ".csv:2: p: expected a probability in [0, 1], count / 21 "
	                                "trials"));
	bsim_test_write(dir, name, csv);
	free(csv);
	/* topped up per crossing: a bin of c crossings (c of the map above,
	 * whose bins hold their crossings or 1) holds c or 2 single gates a
	 * crossing (2 where none entered), at most 200, whichever is more; it
	 * reads back the same */
	def.trials = 200;
	def.trials_per_crossing = 2;
	bsim_markov_set per;
	assert_int_equal(bsim_markov_build(&s, &def, dir, &per, &err), BSIM_OK);
	assert_int_equal(per.built, 1);
	const bsim_markov_map *pm = &per.maps[0];
	assert_non_null(pm->bin_first);
	assert_int_equal(pm->bin_first[1], def.start_trials);
	int cut = 0, full = 0;
	for (int b = 1; b < nb; b++) {
		const long c = cx->bin_first[b + 1] - cx->bin_first[b];
		const long topped = 2 * c < 200 ? 2 * c : 200, want = c > topped ? c : topped;
		print_message("bin %d: %ld crossings, %ld single gates\n", b, c,
		              pm->bin_first[b + 1] - pm->bin_first[b]);
		assert_int_equal(pm->bin_first[b + 1] - pm->bin_first[b], want);
		cut += want > c && want < 200; /* topped up, short of trials */
		full += want == c;             /* its crossings alone */
	}
	assert_true(cut >= 1 && full >= 1);
	assert_int_equal(bsim_markov_build(&s, &def, dir, &again, &err), BSIM_OK);
	assert_int_equal(again.reused, 1);
	for (int b = 0; b <= nb; b++)
		assert_int_equal(again.maps[0].bin_first[b], pm->bin_first[b]);
	assert_true(counts_same(&again.maps[0], pm, -1));
	bsim_markov_set_free(&again);
	/* a bin topped up short of trials, one count over (its p's made
	 * count / its new sum): a sum the rule cannot give, refused naming the
	 * file, the line and the rule */
	int top = 1;
	while (top < nb && !(pm->bin_first[top + 1] - pm->bin_first[top] < 200 &&
	                     pm->bin_first[top + 1] - pm->bin_first[top] >
	                             cx->bin_first[top + 1] - cx->bin_first[top]))
		top++;
	assert_true(top < nb);
	const long held = pm->bin_first[top + 1] - pm->bin_first[top];
	snprintf(name, sizeof name, "map_%016llx.csv", (unsigned long long)pm->key);
	char *pcsv = bsim_test_read(bsim_test_join(dir, name));
	assert_non_null(pcsv);
	char *damaged = malloc(strlen(pcsv) + 4096), *o = damaged;
	int first_row = 1;
	for (char *line = pcsv; *line;) {
		char *end = strchr(line, '\n');
		const size_t len = end ? (size_t)(end - line) : strlen(line);
		int entry, exit_bin, row_count;
		char edges[64];
		if (sscanf(line, "%d,%d,%d,%63[^,\n],", &entry, &exit_bin, &row_count, edges) ==
		            4 &&
		    entry == top) {
			row_count += first_row;
			first_row = 0;
			const char *e2 =
			        strchr(strchr(strchr(strchr(line, ',') + 1, ',') + 1, ',') + 1,
			               ','); /* ",EXIT_EDGE,p" */
			const char *pp = strchr(e2 + 1, ',');
			o += sprintf(o, "%d,%d,%d,%s%.*s,%.12g\n", entry, exit_bin, row_count,
			             edges, (int)(pp - e2), e2,
			             (double)row_count / (double)(held + 1));
		} else {
			o += sprintf(o, "%.*s\n", (int)len, line);
		}
		line += len + (end != NULL);
	}
	*o = '\0';
	bsim_test_write(dir, name, damaged);
	assert_int_equal(bsim_markov_build(&s, &def, dir, &again, &err), BSIM_EINPUT);
	print_message("%s\n", err.msg);
	assert_non_null(strstr(err.msg, name));
	char says[160];
	snprintf(says, sizeof says,
	         "the counts of entry bin %d to sum to the map's crossings topped up to 200 trials "
	         "(2 a crossing), got %ld",
	         top, held + 1);
	assert_non_null(strstr(err.msg, says));
	bsim_test_write(dir, name, pcsv);
	free(damaged);
	free(pcsv);
	bsim_markov_set_free(&per);
	for (int i = 0; i < 2; i++)
		bsim_markov_set_free(&set[i]);
	bsim_scene_free(&s);
}

/* The training field depends on the set of a lattice's gate kinds only:
 * another layout of the same kinds, met in another order, has the same
 * maps (reused: no training field run, no CPU), and a lattice of other
 * kinds its own; the maps read back from the directory serve every
 * layout whose kinds they were trained on. */
static void test_training_kinds(void **state)
{
	(void)state;
	bsim_scene a, b, c;
	const double A[2] = {100, 400}, B[2] = {400, 300}, C[2] = {200, 200};
	const double *lay[3][3] = {{A, B, A}, {B, A, A}, {A, C, C}};
	bsim_scene *sc[3] = {&a, &b, &c};
	for (int f = 0; f < 3; f++) {
		assert_int_equal(bsim_lattice_scene_init(sc[f], 3, 1, 6, 30), BSIM_OK);
		double kl[3], kr[3];
		for (int g = 0; g < 3; g++)
			kl[g] = lay[f][g][0], kr[g] = lay[f][g][1];
		assert_int_equal(bsim_lattice_build(sc[f], kl, kr), BSIM_OK);
	}
	bsim_markov_def def = bsim_markov_def_default();
	def.bins = (bsim_markov_bins){2, 2, 2, 40.0};
	def.trials = 3;
	def.start_trials = 6;
	def.train_trials = 20;
	const char *dir = exe_dir("training_kinds");
	bsim_markov_set sa, sb, sc2;
	bsim_error err;
	assert_int_equal(bsim_markov_build(&a, &def, dir, &sa, &err), BSIM_OK);
	assert_int_equal(sa.built, 2);
	assert_true(sa.seconds > 0.0);
	assert_int_equal(bsim_markov_build(&b, &def, dir, &sb, &err), BSIM_OK);
	assert_int_equal(sb.built, 0);
	assert_int_equal(sb.reused, 2);
	assert_true(sb.seconds == 0.0);
	for (int i = 0; i < 2; i++) /* b meets B first */
		assert_true(sb.maps[i].key == sa.maps[1 - i].key);
	assert_int_equal(bsim_markov_build(&c, &def, dir, &sc2, &err), BSIM_OK);
	assert_int_equal(sc2.built, 2); /* A's map too: another training field */
	assert_true(sc2.maps[0].key != sa.maps[0].key);
	/* markov.json names the training field's trials; the kinds are each
	 * lattice's own */
	for (int f = 0; f < 3; f++) {
		bsim_markov_set back;
		bsim_options opts = {0};
		assert_int_equal(bsim_markov_load(sc[f], dir, &opts, &back, &err), BSIM_OK);
		assert_int_equal(back.def.train_trials, 20);
		/* the default counts the crossings, 5 single gates a crossing */
		assert_int_equal(back.def.train_crossings, 1);
		assert_int_equal(back.def.trials_per_crossing, BSIM_MARKOV_TRIALS_PER_CROSSING);
		bsim_markov_set_free(&back);
	}
	/* a lattice of kinds no build trained on together: refused, naming
	 * the training field's kinds that differ */
	bsim_scene d;
	assert_int_equal(bsim_lattice_scene_init(&d, 3, 1, 6, 30), BSIM_OK);
	const double kl[3] = {400, 200, 200}, kr[3] = {300, 200, 200};
	assert_int_equal(bsim_lattice_build(&d, kl, kr), BSIM_OK);
	bsim_markov_set none;
	bsim_options opts = {0};
	assert_int_equal(bsim_markov_load(&d, dir, &opts, &none, &err), BSIM_EINPUT);
	print_message("%s\n", err.msg);
	assert_non_null(strstr(err.msg, "'entries train 20 crossings per 5 kinds 2 "));
	bsim_markov_set_free(&sa);
	bsim_markov_set_free(&sb);
	bsim_markov_set_free(&sc2);
	for (int f = 0; f < 3; f++)
		bsim_scene_free(sc[f]);
	bsim_scene_free(&d);
}

static char *map_text(const char *dir)
{
	char *text = bsim_test_read_glob(bsim_test_join(dir, "map_*.csv"));
	assert_non_null(text);
	return text;
}

/* markov predict's printed totals are prediction.csv's probabilities
 * summed by kind (to the 4 printed decimals), as are --json's, to within
 * what the default solution states it left in the field; the
 * per-location list comes only with --locations or --json, and --quiet
 * prints nothing. csv: written by the series to 1e-12 (--out --tol
 * 1e-12), the exact p to within 1e-12. pred: the predict command line
 * without --out or --tol. */
static void check_predict_totals(const char *printed, const char *csv, const char *const *pred)
{
	static const char *const kinds[] = {"end", "side", "stuck"};
	double sum[3] = {0, 0, 0};
	char *text = bsim_test_read(csv), *save = NULL;
	assert_non_null(text);
	strtok_r(text, "\n", &save); /* the header */
	for (char *line; (line = strtok_r(NULL, "\n", &save));) {
		char kind[16];
		assert_int_equal(sscanf(line, "%*[^,],%15[^,]", kind), 1);
		for (int k = 0; k < 3; k++)
			if (strcmp(kind, kinds[k]) == 0)
				sum[k] += atof(strrchr(line, ',') + 1);
	}
	free(text);
	const char *argv[20];
	int n = 0;
	while (pred[n] && n < 12) {
		argv[n] = pred[n];
		n++;
	}
	argv[n + 1] = NULL;
	char *json = NULL, *quiet = NULL, *list = NULL;
	argv[n] = "--json";
	assert_int_equal(bsim_test_cli(argv, &json, NULL), 0);
	argv[n] = "--quiet";
	assert_int_equal(bsim_test_cli(argv, &quiet, NULL), 0);
	argv[n] = "--locations";
	assert_int_equal(bsim_test_cli(argv, &list, NULL), 0);
	/* The default: the sweeps to the maps' sampling tolerance, 1 / (32
	 * sqrt(trials per bin)), no distribution of gates visited; each total
	 * short of the exact one by at most what was left, itself at most the
	 * tolerance. */
	assert_non_null(strstr(json, "\"solve\": \"sweeps\""));
	assert_non_null(strstr(json, "\"p_gates\": [0]"));
	assert_true(bsim_test_json_number(json, "sweeps") > 0);
	const double tol = bsim_test_json_number(json, "tol"),
	             left = bsim_test_json_number(json, "left_in_field");
	assert_true(tol > 1e-4 && tol < 0.1 && left <= tol && left > 0.0);
	const char *totals = strstr(json, "\"totals\": {");
	assert_non_null(totals);
	for (int k = 0; k < 3; k++) {
		const double d = sum[k] - bsim_test_json_number(totals, kinds[k]);
		assert_true(d >= -1e-9 && d <= left + 1e-9);
	}
	/* --gates: the series to the same tolerance, with the distribution */
	char *series = NULL;
	argv[n] = "--json";
	argv[n + 1] = "--gates";
	argv[n + 2] = NULL;
	assert_int_equal(bsim_test_cli(argv, &series, NULL), 0);
	assert_non_null(strstr(series, "\"solve\": \"series\""));
	assert_null(strstr(series, "\"p_gates\": [0]"));
	const double series_left = bsim_test_json_number(series, "left_in_field");
	assert_true(series_left <= tol);
	const char *series_totals = strstr(series, "\"totals\": {");
	assert_non_null(series_totals);
	for (int k = 0; k < 3; k++) {
		const double d = sum[k] - bsim_test_json_number(series_totals, kinds[k]);
		assert_true(d >= -1e-9 && d <= series_left + 1e-9);
	}
	free(series);
	/* --tol 1e-6: the sweeps to within 1e-6 */
	char *tight = NULL;
	argv[n + 1] = "--tol";
	argv[n + 2] = "1e-6";
	argv[n + 3] = NULL;
	assert_int_equal(bsim_test_cli(argv, &tight, NULL), 0);
	const char *tight_totals = strstr(tight, "\"totals\": {");
	assert_non_null(tight_totals);
	for (int k = 0; k < 3; k++)
		near(bsim_test_json_number(tight_totals, kinds[k]), sum[k], 1e-6 + 1e-9, __LINE__);
	free(tight);
	for (int k = 0; k < 3; k++) {
		char head[32];
		snprintf(head, sizeof head, "\n%-12s ", kinds[k]);
		const char *line = strstr(printed, head);
		if (!line)
			fail_msg("no '%s' total in:\n%s", kinds[k], printed);
		const double d = sum[k] - atof(line + strlen(head));
		assert_true(d >= -5.1e-5 && d <= left + 5.1e-5);
	}
	assert_null(strstr(printed, "\nstuck:"));
	assert_non_null(strstr(printed, "--out DIR writes prediction.csv"));
	assert_non_null(strstr(list, "\nstuck:"));
	assert_non_null(strstr(json, "\"locations\": [{\"location\": "));
	assert_string_equal(quiet, "");
	free(json);
	free(quiet);
	free(list);
}

/* Threads change nothing; the cache reuses only what nothing changed. */
static void test_threads_and_cache(void **state)
{
	(void)state;
	char d1[1024], d2[1024];
	snprintf(d1, sizeof d1, "%s", bsim_test_dir("threads1"));
	snprintf(d2, sizeof d2, "%s", bsim_test_dir("threads2"));
	const char *exp = bsim_test_src("configs/lattice/c_track_essay.yaml");
	/* 4,4,3 bins, 3 start trials and a training field of 30 trials: cheap
	 * maps (the default's 4,369 bins, 16,000 start trials and 4,000 training
	 * trials are other keys alike); the training field's trials run on the
	 * threads too */
	const char *b1[] = {"markov", "build",    exp,     "--bins",  "4,4,3", "--start-trials",
	                    "3",      "--trials", "3",     "--train", "30",    "--threads",
	                    "1",      "--quiet",  "--out", d1,        NULL};
	const char *b2[] = {"markov", "build",    exp,     "--bins",  "4,4,3", "--start-trials",
	                    "3",      "--trials", "3",     "--train", "30",    "--threads",
	                    "2",      "--quiet",  "--out", d2,        NULL};
	assert_int_equal(bsim_test_cli(b1, NULL, NULL), 0);
	assert_int_equal(bsim_test_cli(b2, NULL, NULL), 0);
	char *t1 = map_text(d1), *t2 = map_text(d2);
	assert_true(strlen(t1) > 1000);
	assert_string_equal(t1, t2);
	free(t1);
	free(t2);
	/* maps topped up to 1 single gate a crossing, maps of single gates
	 * alone (no crossings counted), and the first 2 of the start trials
	 * continued, alike: the crossings in trial order, whatever the threads */
	const char *how[3][2] = {
	        {"--per-crossing", "1"}, {"--crossings", "0"}, {"--after-trials", "2"}};
	for (int h = 0; h < 3; h++) {
		char c[2][1024];
		char *t[2];
		for (int n = 0; n < 2; n++) {
			char name[32];
			snprintf(name, sizeof name, "threads_crossings%d%d", h, n);
			snprintf(c[n], sizeof c[n], "%s", bsim_test_dir(name));
			const char *x[] = {"markov",  "build",     exp,
			                   "--bins",  "4,4,3",     "--start-trials",
			                   "3",       "--trials",  "3",
			                   "--train", "30",        how[h][0],
			                   how[h][1], "--threads", n ? "2" : "1",
			                   "--quiet", "--out",     c[n],
			                   NULL};
			assert_int_equal(bsim_test_cli(x, NULL, NULL), 0);
			t[n] = map_text(c[n]);
		}
		assert_true(strlen(t[0]) > 1000);
		assert_string_equal(t[0], t[1]);
		assert_int_equal(bsim_test_glob_first(bsim_test_join(c[0], "map_*.first2.csv")) !=
		                         NULL,
		                 h == 2);
		free(t[0]);
		free(t[1]);
	}

	/* The same again: both maps reused, no training field run, and a note
	 * that these training trials, bins and start trials are fewer than the
	 * default method's. */
	char *out = NULL, *note = NULL;
	const char *again[] = {"markov", "build",    exp, "--bins",  "4,4,3", "--start-trials",
	                       "3",      "--trials", "3", "--train", "30",    "--out",
	                       d1,       NULL};
	assert_int_equal(bsim_test_cli(again, &out, &note), 0);
	assert_non_null(strstr(out, "0 maps built (0.0 s of CPU)"));
	assert_non_null(strstr(out, "2 reused"));
	assert_null(strstr(out, "training field"));
	assert_non_null(strstr(note, "note: maps with 30 training trials (the default 4000), "
	                             "4,4,3 bins (the default 14,6,13), 3 start trials (the "
	                             "default 16000): measured less accurate"));
	free(out);
	free(note);
	/* Fewer start trials continued: the maps reused, the gates after the
	 * start built anew beside the others, and a note. */
	const char *fewer[] = {"markov", "build",    exp, "--bins",  "4,4,3", "--start-trials",
	                       "3",      "--trials", "3", "--train", "30",    "--after-trials",
	                       "2",      "--out",    d1,  NULL};
	assert_int_equal(bsim_test_cli(fewer, &out, &note), 0);
	/* (the CPU said is the new pairs') */
	assert_non_null(strstr(out, "0 maps built ("));
	assert_non_null(strstr(out, "2 reused"));
	assert_non_null(strstr(out, "the gate after the start (2 of the start trials continued): "
	                            "4 pairs of maps built, 0 reused"));
	assert_non_null(strstr(note, "2 start trials continued (the default 8000)"));
	assert_non_null(bsim_test_glob_first(bsim_test_join(d1, "map_*.after_*.first2.csv")));
	assert_non_null(bsim_test_glob_first(bsim_test_join(d1, "map_*.after_*[0-9a-f].csv")));
	free(out);
	free(note);
	/* Anything the maps depend on: new maps, none reused. */
	const char *changes[][4] = {{"--trials", "3", "--set", "contact.restitution=0.7"},
	                            {"--trials", "3", "--set", "lattice.beam.damping=40"},
	                            {"--trials", "3", "--set", "integration.dt=0.002"},
	                            {"--trials", "3", "--seed", "2"},
	                            {"--trials", "4", "--threads", "2"},
	                            {"--trials", "3", "--backend-opt", "integrator=euler"},
	                            {"--trials", "3", "--train", "31"},
	                            {"--trials", "3", "--train", "0"},
	                            {"--trials", "3", "--crossings", "0"},
	                            {"--trials", "3", "--per-crossing", "3"}};
	for (int i = 0; i < 10; i++) {
		const char *argv[] = {"markov",
		                      "build",
		                      exp,
		                      "--bins",
		                      "4,4,3",
		                      "--start-trials",
		                      "3",
		                      changes[i][0],
		                      changes[i][1],
		                      changes[i][2],
		                      changes[i][3],
		                      strcmp(changes[i][2], "--train") ? "--train" : "--threads",
		                      strcmp(changes[i][2], "--train") ? "30" : "1",
		                      "--out",
		                      d1,
		                      NULL};
		out = NULL;
		char *progress = NULL;
		/* off a terminal, every progress line */
		setenv("BEAMSIM_PROGRESS_SECONDS", "0", 1);
		assert_int_equal(bsim_test_cli(argv, &out, &progress), 0);
		unsetenv("BEAMSIM_PROGRESS_SECONDS");
		if (!strstr(out, "2 maps built") || !strstr(out, "0 reused"))
			print_error("%s %s: %s\n", changes[i][2], changes[i][3], out);
		assert_non_null(strstr(out, "2 maps built"));
		assert_non_null(strstr(out, "0 reused"));
		/* the training field's trials counted first, then the single
		 * gates; none without a training field */
		const char *trained = strstr(progress, "beamsim: progress: 1/3"),
		           *gates = strstr(progress, " single gates ");
		assert_non_null(gates);
		if (strcmp(changes[i][2], "--train") == 0 && strcmp(changes[i][3], "0") == 0) {
			assert_null(strstr(progress, "training trials"));
		} else {
			assert_non_null(trained);
			assert_true(strncmp(trained + 22, "0 training trials", 17) == 0 ||
			            strncmp(trained + 22, "1 training trials", 17) == 0);
			assert_true(trained < gates);
		}
		free(progress);
		free(out);
	}
	/* predict reads only what the last build's settings and this scene's
	 * physics key: a scene the maps were not built for is refused. */
	char *err = NULL;
	const char *pred[] = {"markov",
	                      "predict",
	                      bsim_test_src("configs/lattice/c_track.yaml"),
	                      "--set",
	                      "effects.random_force.magnitude=29",
	                      "--map",
	                      d2,
	                      NULL};
	assert_int_equal(bsim_test_cli(pred, NULL, &err), 2);
	assert_non_null(strstr(err, "no map for k = 400, 400 N m/rad"));
	assert_non_null(strstr(err, "beamsim markov build"));
	free(err);
	out = NULL;
	const char *pred_ok[] = {"markov", "predict", bsim_test_src("configs/lattice/c_track.yaml"),
	                         "--map",  d2,        NULL};
	assert_int_equal(bsim_test_cli(pred_ok, &out, NULL), 0);
	assert_non_null(strstr(out, "gates visited: mean"));
	char *totals_text = out;
	/* --out: every location of the field once, the probabilities summing to 1 */
	char pdir[1100];
	snprintf(pdir, sizeof pdir, "%s/prediction", d1);
	const char *pred_out[] = {
	        "markov", "predict", bsim_test_src("configs/lattice/c_track.yaml"),
	        "--map",  d2,        "--out",
	        pdir,     "--tol",   "1e-12",
	        NULL};
	out = NULL;
	assert_int_equal(bsim_test_cli(pred_out, &out, NULL), 0);
	/* prediction*.csv and .mat, prediction.{png,svg,gp,dat}, index.html and
	 * the time to the outcome: time.{csv,mat,png,svg,gp} */
	assert_int_equal(bsim_test_check_wrote(out, pdir), 14);
	free(out);
	char csv[1200];
	snprintf(csv, sizeof csv, "%s/prediction.csv", pdir);
	char *text = bsim_test_read(csv);
	assert_non_null(text);
	int rows = 0;
	double sum = 0.0;
	char *save = NULL;
	strtok_r(text, "\n", &save); /* the header */
	for (char *line; (line = strtok_r(NULL, "\n", &save));) {
		sum += atof(strrchr(line, ',') + 1);
		rows++;
	}
	free(text);
	assert_int_equal(rows, 9 + 9 + 81);
	/* short of 1 by what the series left in the field, at most its tolerance */
	assert_true(sum <= 1.0 + 1e-9 && sum > 1.0 - 1e-12 - 1e-9);
	check_predict_totals(totals_text, csv, pred_ok);
	free(totals_text);
	snprintf(csv, sizeof csv, "%s/prediction.mat", pdir);
	struct stat st;
	assert_int_equal(stat(csv, &st), 0);
}

/* ---- the figures of the field ------------------------------------------------- */

/* Block `block` of a field figure's data (x y value location "text"): the
 * value of location loc, NAN if absent. */
static double field_value(const char *dat, int block, const char *loc)
{
	FILE *f = fopen(dat, "r");
	assert_non_null(f);
	char line[512];
	int b = 0, blank = 0;
	double v = NAN;
	while (fgets(line, sizeof line, f)) {
		if (line[0] == '\n') {
			blank++;
			continue;
		}
		if (blank >= 2)
			b++;
		blank = 0;
		if (line[0] == '#' || b != block)
			continue;
		double x, y, val;
		char name[64];
		if (sscanf(line, "%lf %lf %lf %63s", &x, &y, &val, name) == 4 &&
		    strcmp(name, loc) == 0)
			v = val;
	}
	fclose(f);
	return v;
}

/* "end 3.8%, side 20.0%, stuck 76.3%" of the probabilities by location. */
static void totals_text(char *buf, size_t size, const double tot[3])
{
	snprintf(buf, size, "end %.1f%%, side %.1f%%, stuck %.1f%%", 100 * tot[0], 100 * tot[1],
	         100 * tot[2]);
}

static int kind_of(const char *loc)
{
	return strncmp(loc, "end:", 4) == 0 ? 0 : strncmp(loc, "side:", 5) == 0 ? 1 : 2;
}

/* Maps of experiment exp into maps: 4,4,3 bins of 10 single gates, 10
 * from the start, states uniform in each bin (with 3, most bins empty, the
 * chain's map resamples take a minute). */
static void build_small_maps(const char *exp, const char *maps)
{
	const char *build[] = {
	        "markov", "build",   exp, "--bins",  "4,4,3", "--trials", "10", "--start-trials",
	        "10",     "--train", "0", "--quiet", "--out", maps,       NULL};
	assert_int_equal(bsim_test_cli(build, NULL, NULL), 0);
}

/* markov predict --out and markov validate draw the final locations as
 * the field: the figure files are there and in the manifest, every cell's
 * value is the location's probability in the CSV the command writes (the
 * difference panels the chain's less the simulation's), the panels' titles
 * hold the totals of end, side and stuck summed here from those CSVs, the
 * figure's title the backend and the propulsive force, and no tic label is
 * rotated (the field has none to rotate). */
static void test_field_figures(void **state)
{
	(void)state;
	char maps[1024], pdir[1100], vdir[1100], path[1200];
	snprintf(maps, sizeof maps, "%s", bsim_test_dir("field_maps"));
	snprintf(pdir, sizeof pdir, "%s/prediction", maps);
	snprintf(vdir, sizeof vdir, "%s/validation", maps);
	char exp[1200]; /* bsim_test_src's buffer is reused by the next call */
	snprintf(exp, sizeof exp, "%s", bsim_test_src("configs/markov/c_track.yaml"));
	build_small_maps(exp, maps);
	const char *pred[] = {"markov", "predict", bsim_test_src("configs/lattice/c_track.yaml"),
	                      "--map",  maps,      "--out",
	                      pdir,     NULL};
	assert_int_equal(bsim_test_cli(pred, NULL, NULL), 0);
	const char *val[] = {"markov",      "validate", exp,       "--map", maps, "--trials", "30",
	                     "--bootstrap", "50",       "--quiet", "--out", vdir, NULL};
	char *err = NULL;
	int rc = bsim_test_cli(val, NULL, &err);
	if (rc != 0)
		fail_msg("validate: exit %d: %s", rc, err ? err : "");
	/* the maps' method named, as the build named it, and in validate.json */
	assert_non_null(strstr(err, "note: maps with states uniform in each bin (no training "
	                            "field), 4,4,3 bins (the default 14,6,13), 10 start"));
	free(err);
	snprintf(path, sizeof path, "%s/validate.json", vdir);
	char *vjson = bsim_test_read(path);
	assert_non_null(vjson);
	assert_non_null(strstr(vjson, "\"maps_scope\": \"maps with states uniform in each bin"));
	/* no training field: no crossings counted */
	assert_non_null(strstr(vjson, "\"of_crossings\": 0, \"per_crossing\": 0"));
	free(vjson);
	assert_int_equal(bsim_test_check_figures(pdir), 2); /* prediction and time */
	assert_int_equal(bsim_test_check_figures(vdir), 1);

	/* predict: prediction.dat against prediction.csv */
	snprintf(path, sizeof path, "%s/prediction.csv", pdir);
	char *csv = bsim_test_read(path);
	assert_non_null(csv);
	char dat[1200];
	snprintf(dat, sizeof dat, "%s/prediction.dat", pdir);
	double tot[3] = {0, 0, 0};
	int n = 0;
	char *save = NULL;
	strtok_r(csv, "\n", &save);
	for (char *line; (line = strtok_r(NULL, "\n", &save)); n++) {
		char loc[64];
		assert_int_equal(sscanf(line, "%63[^,]", loc), 1);
		const double p = atof(strrchr(line, ',') + 1);
		tot[kind_of(loc)] += p;
		assert_true(fabs(field_value(dat, 0, loc) - p) <= 1e-7 * fmax(p, 1e-3));
	}
	free(csv);
	assert_int_equal(n, 99);
	snprintf(path, sizeof path, "%s/prediction.gp", pdir);
	char *gp = bsim_test_read(path);
	assert_non_null(gp);
	char want[120];
	totals_text(want, sizeof want, tot);
	assert_non_null(strstr(gp, want));
	assert_non_null(strstr(gp, "backend thesis"));
	assert_non_null(strstr(gp, "F_prop = 6 N"));
	assert_non_null(strstr(gp, "set colorbox"));
	free(gp);

	/* validate: the simulated panels (b, c) and the differences (d, e,
	 * blocks 4 and 5 after an empty place) against validate.csv */
	snprintf(path, sizeof path, "%s/validate.csv", vdir);
	csv = bsim_test_read(path);
	assert_non_null(csv);
	snprintf(dat, sizeof dat, "%s/validate_g000.dat", vdir);
	double sim_tot[2][3] = {{0}};
	n = 0;
	save = NULL;
	strtok_r(csv, "\n", &save);
	for (char *line; (line = strtok_r(NULL, "\n", &save)); n++) {
		int g;
		char proto[16], loc[64];
		double ps, lo, hi, pc;
		assert_int_equal(sscanf(line, "%d,%15[^,],%63[^,],%lf,%lf,%lf,%lf", &g, proto, loc,
		                        &ps, &lo, &hi, &pc),
		                 7);
		const int pr = strcmp(proto, "essay") == 0 ? 0 : 1;
		sim_tot[pr][kind_of(loc)] += ps;
		assert_true(fabs(field_value(dat, 0, loc) - pc) <= 1e-7 * fmax(pc, 1e-3));
		assert_true(fabs(field_value(dat, 1 + pr, loc) - ps) <= 1e-7 * fmax(ps, 1e-3));
		assert_true(fabs(field_value(dat, 4 + pr, loc) - (pc - ps)) <= 1e-6);
	}
	free(csv);
	assert_int_equal(n, 2 * 99);
	snprintf(path, sizeof path, "%s/validate_g000.gp", vdir);
	gp = bsim_test_read(path);
	assert_non_null(gp);
	for (int pr = 0; pr < 2; pr++) {
		totals_text(want, sizeof want, sim_tot[pr]);
		assert_non_null(strstr(gp, want));
	}
	assert_null(strstr(gp, "rotate"));
	assert_non_null(strstr(gp, "backend thesis"));
	free(gp);

	/* the figures in the manifests */
	const char *ext[] = {"gp", "png", "svg", "dat"};
	for (int k = 0; k < 4; k++) {
		snprintf(path, sizeof path, "%s/manifest.json", pdir);
		char *m = bsim_test_read(path);
		snprintf(want, sizeof want, "\"prediction.%s\"", ext[k]);
		assert_non_null(strstr(m, want));
		free(m);
		snprintf(path, sizeof path, "%s/manifest.json", vdir);
		m = bsim_test_read(path);
		snprintf(want, sizeof want, "\"validate_g000.%s\"", ext[k]);
		assert_non_null(strstr(m, want));
		free(m);
	}
}

/* Bad inputs: exit 2, one line naming the thing, nothing written. */
static void test_bad_inputs(void **state)
{
	(void)state;
	const char *dir = exe_dir("bad");
	char target[1100];
	snprintf(target, sizeof target, "%s/out", dir);
	/* bsim_test_src's buffer is static: a copy per path */
	char *h1 = strdup(bsim_test_src("configs/thesis/h1_symmetric.yaml"));
	char *essay = strdup(bsim_test_src("configs/lattice/c_track_essay.yaml"));
	char *track = strdup(bsim_test_src("configs/lattice/c_track.yaml"));
	struct {
		const char *argv[12];
		const char *says;
	} cases[] = {
	        {{"markov", "build", h1, "--out", target, NULL}, "not a gate lattice"},
	        {{"markov", "build", essay, "--bins", "4,0,3", "--out", target, NULL},
	         "--bins 4,0,3: expected P,S,D"},
	        /* 2^32 + 2: sscanf's %d once read it as 2 (found by reading the fuzzed parser) */
	        {{"markov", "build", essay, "--bins", "4294967298,2,2", "--out", target, NULL},
	         "--bins 4294967298,2,2: expected P,S,D"},
	        {{"markov", "build", essay, "--bins", "4, 4,3", "--out", target, NULL},
	         "--bins 4, 4,3: expected P,S,D"},
	        {{"markov", "build", essay, "--set", "termination.side_x=300", "--out", target,
	          NULL},
	         "termination.side_x: the chain needs the side boundary"},
	        {{"markov", "predict", track, NULL}, "expected one of --map DIR and --visits DIR"},
	        {{"markov", "predict", track, "--map", dir, NULL}, "markov.json: cannot read"},
	        {{"markov", "validate", essay, "--map", dir, "--out", target, NULL},
	         "markov.json: cannot read"},
	        {{"markov", "buld", NULL}, "did you mean 'build'"},
	        {{"markov", "build", essay, "--start-trials", "0", "--out", target, NULL},
	         "--start-trials 0: expected an integer 1 to 1000000"},
	        {{"markov", "build", essay, "--entries", "self:1", "--start-trials", "300", "--out",
	          target, NULL},
	         "start trials: self-consistent and flow entries take the start bin's trials "
	         "equal to every bin's (50), got 300"},
	        {{"markov", "build", essay, "--train", "0", "--crossings", "1", "--out", target,
	          NULL},
	         "crossings: a map counts a training field's crossings only with a training "
	         "field (training trials > 0, got 0)"},
	        {{"markov", "build", essay, "--entries", "self", "--crossings", "1", "--out",
	          target, NULL},
	         "crossings: a map counts a training field's crossings only with a training "
	         "field"},
	        {{"markov", "build", essay, "--per-crossing", "-1", "--out", target, NULL},
	         "--per-crossing -1: expected an integer 0 to 1000000"},
	        {{"markov", "build", essay, "--after-trials", "-1", "--out", target, NULL},
	         "--after-trials -1: expected an integer 0 to 1000000"},
	        {{"markov", "build", essay, "--after-start", "0", "--after-trials", "4000", "--out",
	          target, NULL},
	         "start trials continued after the start (4000): maps without the gate after the "
	         "start (after_start 0) have none to continue"},
	        {{"markov", "build", essay, "--entries", "self", "--after-trials", "0", "--out",
	          target, NULL},
	         "(self or flow entries) have none to continue"},
	};
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		char *err = NULL;
		int rc = bsim_test_cli(cases[i].argv, NULL, &err);
		if (rc != 2 || !strstr(err ? err : "", cases[i].says))
			print_error("case %zu: exit %d, %s\n", i, rc, err ? err : "");
		assert_int_equal(rc, 2);
		assert_non_null(strstr(err, cases[i].says));
		free(err);
		struct stat st;
		assert_int_not_equal(stat(target, &st), 0);
	}
	/* A map keeps its counts by row: any bins of 1 to 64 a coordinate may
	 * be built (they were bounded by the square of their number, P S D at
	 * most 1117), and what bounds a map is its single gates, which index
	 * its counts: 4 x 64^3 bins x 2048 trials are 2^31 and more. */
	const char *big[] = {"markov",   "build", essay,   "--bins", "64,64,64",
	                     "--trials", "2048",  "--out", target,   NULL};
	char *err = NULL;
	int rc = bsim_test_cli(big, NULL, &err);
	bsim_test_check_input_error(
	        rc, err,
	        (const char *const[]){"1048576 entry bins x 2048 trials (the start's 16000) make "
	                              "2147499648 single gates a map, more than 2147483647",
	                              NULL},
	        0);
	free(err);
	long wrong = 0;
	for (int p = 0; p <= 65; p++)
		for (int q = 0; q <= 65; q++)
			for (int d = 0; d <= 65; d++) {
				bsim_markov_bins bins = {p, q, d, 40.0};
				bsim_error e;
				const int fits =
				        p >= 1 && p <= 64 && q >= 1 && q <= 64 && d >= 1 && d <= 64;
				wrong += (bsim_markov_bins_check(&bins, &e) == BSIM_OK) != fits;
			}
	assert_int_equal(wrong, 0);
	free(h1);
	free(essay);
	free(track);
}

/* A damaged map directory: the file, line (and column) and field named,
 * exit 2. Each damage is made on a fresh build and undone. */
static void test_bad_map_files(void **state)
{
	(void)state;
	char dir[1024], path[1200];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("bad_maps"));
	/* bsim_test_src's buffer is static: a copy per path */
	char *essay = strdup(bsim_test_src("configs/lattice/c_track_essay.yaml"));
	char *track = strdup(bsim_test_src("configs/lattice/c_track.yaml"));
	/* the start's trials as the others': the damaged files fit a buffer */
	const char *build[] = {
	        "markov", "build",   essay, "--bins",  "1,1,1", "--trials", "2", "--start-trials",
	        "2",      "--train", "0",   "--quiet", "--out", dir,        NULL};
	assert_int_equal(bsim_test_cli(build, NULL, NULL), 0);
	const char *pred[] = {"markov", "predict", track, "--map", dir, NULL};
	/* Without the manifest, which would refuse any edit by its CRC-32
	 * first (test_stored_inputs): the content's own checks. */
	assert_int_equal(bsim_test_remove(bsim_test_join(dir, "manifest.json")), 0);

	/* markov.json: a field of the wrong kind, a bin count out of range */
	snprintf(path, sizeof path, "%s/markov.json", dir);
	char *json = bsim_test_read(path);
	assert_non_null(json);
	struct {
		const char *from, *to, *says;
	} json_cases[] = {
	        {"\"trials\": 2", "\"trials\": \"two\"",
	         "trials: expected an integer 1 to 1000000, got \"two\""},
	        {"\"speed\": 1", "\"speed\": 0", "bins/speed: expected an integer 1 to 64, got 0"},
	        {"\"beamsim_version\": \"" BSIM_VERSION "\"", "\"beamsim_version\": \"0.0.0-old\"",
	         "beamsim_version: expected maps of this beamsim, " BSIM_VERSION
	         ", got maps built by beamsim 0.0.0-old"},
	};
	for (int i = 0; i < 3; i++) {
		char *at = strstr(json, json_cases[i].from);
		assert_non_null(at);
		char text[2048];
		snprintf(text, sizeof text, "%.*s%s%s", (int)(at - json), json, json_cases[i].to,
		         at + strlen(json_cases[i].from));
		bsim_test_write(dir, "markov.json", text);
		char *err = NULL;
		assert_int_equal(bsim_test_cli(pred, NULL, &err), 2);
		if (!strstr(err, "markov.json:1:") || !strstr(err, json_cases[i].says))
			print_error("case %d: %s\n", i, err);
		assert_non_null(strstr(err, "markov.json:1:"));
		assert_non_null(strstr(err, json_cases[i].says));
		free(err);
	}
	bsim_test_write(dir, "markov.json", json);
	assert_int_equal(bsim_test_cli(pred, NULL, NULL), 0);
	free(json);

	/* a map's CSV: an exit bin past the last of 1 + 4 bins */
	const char *key = bsim_test_glob_first(bsim_test_join(dir, "map_*.key"));
	assert_non_null(key);
	char first[1024];
	snprintf(first, sizeof first, "%.*s.csv", (int)(strlen(key) - 4), key);
	snprintf(path, sizeof path, "%s", first);
	char *csv = bsim_test_read(path);
	assert_non_null(csv);
	char *row2 = strchr(csv, '\n');
	assert_non_null(row2);
	char *comma = strchr(row2 + 1, ',');
	assert_non_null(comma);
	char text[8192];
	snprintf(text, sizeof text, "%.*s,9%s", (int)(comma - csv), csv, strchr(comma + 1, ','));
	const char *name = strrchr(path, '/') + 1;
	bsim_test_write(dir, name, text);
	char *err = NULL;
	assert_int_equal(bsim_test_cli(pred, NULL, &err), 2);
	if (!strstr(err, ":2: exit: expected a bin 0 to 4"))
		print_error("%s\n", err);
	assert_non_null(strstr(err, name));
	assert_non_null(strstr(err, ":2: exit: expected a bin 0 to 4"));
	free(err);
	/* a row given twice, last: named at its second line, whatever the
	 * order the rows come in */
	int lines = 0;
	for (const char *c = csv; *c; c++)
		lines += *c == '\n';
	const char *row2_end = strchr(row2 + 1, '\n');
	snprintf(text, sizeof text, "%s%.*s", csv, (int)(row2_end - row2), row2 + 1);
	bsim_test_write(dir, name, text);
	err = NULL;
	assert_int_equal(bsim_test_cli(pred, NULL, &err), 2);
	char says[64];
	snprintf(says, sizeof says, ":%d: exit: expected each entry,exit pair once", lines + 1);
	if (!strstr(err, says))
		print_error("%s\n", err);
	assert_non_null(strstr(err, says));
	free(err);
	bsim_test_write(dir, name, csv);
	assert_int_equal(bsim_test_cli(pred, NULL, NULL), 0);

	/* a map's holding times: a malformed row, then an exit that no
	 * longer counts up to the map's counts */
	snprintf(path, sizeof path, "%.*s.hold.csv", (int)(strlen(first) - 4), first);
	char *hold = bsim_test_read(path);
	assert_non_null(hold);
	const char *hname = strrchr(path, '/') + 1;
	char *h2 = strchr(hold, '\n') + 1; /* "0,0,EXIT,STEPS" */
	char *c3 = strchr(strchr(strchr(h2, ',') + 1, ',') + 1, ',');
	snprintf(text, sizeof text, "%.*s,x%s", (int)(c3 - hold), hold, c3);
	bsim_test_write(dir, hname, text);
	err = NULL;
	assert_int_equal(bsim_test_cli(pred, NULL, &err), 2);
	if (!strstr(err, ".hold.csv:2: expected a row entry,trial,exit,steps"))
		print_error("%s\n", err);
	assert_non_null(strstr(err, ".hold.csv:2: expected a row entry,trial,exit,steps"));
	free(err);
	char *c2 = strchr(strchr(h2, ',') + 1, ','); /* the exit */
	const int ex = atoi(c2 + 1);
	snprintf(text, sizeof text, "%.*s,%d%s", (int)(c2 - hold), hold, ex == 0 ? 1 : 0, c3);
	bsim_test_write(dir, hname, text);
	err = NULL;
	assert_int_equal(bsim_test_cli(pred, NULL, &err), 2);
	assert_non_null(strstr(err, "do not count up to the map's counts"));
	free(err);
	bsim_test_write(dir, hname, hold);
	assert_int_equal(bsim_test_cli(pred, NULL, NULL), 0);

	/* the gate after the start: a row whose start exit is not the start
	 * map's */
	snprintf(path, sizeof path, "%s",
	         bsim_test_glob_first(bsim_test_join(dir, "map_*.after_*.csv")));
	char *after = bsim_test_read(path);
	assert_non_null(after);
	char *a2 = strchr(after, '\n') + 1; /* "TRIAL,START_EXIT,EXIT,STEPS" */
	char *a3 = strchr(strchr(a2, ',') + 1, ',');
	snprintf(text, sizeof text, "%.*s,0%s", (int)(strchr(a2, ',') - after), after, a3);
	const char *aname = strrchr(path, '/') + 1;
	bsim_test_write(dir, aname, text);
	err = NULL;
	assert_int_equal(bsim_test_cli(pred, NULL, &err), 2);
	if (!strstr(err, ".csv:2: expected a row trial,start_exit,exit,steps"))
		print_error("%s\n", err);
	assert_non_null(strstr(err, aname));
	assert_non_null(strstr(err, ".csv:2: expected a row trial,start_exit,exit,steps"));
	free(err);
	free(after);
	free(hold);
	free(csv);
	free(essay);
	free(track);
}

/* Bins: the edges, positions, speeds and directions land where the
 * header says. */
static void test_bins(void **state)
{
	(void)state;
	bsim_scene s;
	assert_int_equal(bsim_lattice_scene_init(&s, 1, 1, 6, 30), BSIM_OK);
	const bsim_markov_bins b = {4, 4, 3, 40.0};
	assert_int_equal(bsim_markov_bins_count(&b), 1 + 4 * 48);
	const double up[2] = {0.0, 1.0}, fast_left[2] = {-39.0, 0.5}, back[2] = {-5.0, 0.0};
	/* bottom edge, first position bin, slowest, straight in: the middle direction */
	assert_int_equal(bsim_markov_bin_of(&b, &s.lattice, BSIM_EDGE_BOTTOM, -24.0, up), 1 + 1);
	/* right edge (moving -x), last position bin, last speed bin, straight in */
	assert_int_equal(bsim_markov_bin_of(&b, &s.lattice, BSIM_EDGE_RIGHT, 59.0, fast_left),
	                 1 + ((2 * 4 + 3) * 4 + 3) * 3 + 1);
	/* a body moving out is clamped to an end direction bin */
	int k = bsim_markov_bin_of(&b, &s.lattice, BSIM_EDGE_LEFT, 30.0, back);
	assert_true((k - 1) % 3 == 0 || (k - 1) % 3 == 2);
	bsim_scene_free(&s);
}

/* Observed entries: a bin's states are drawn from them (a map built from
 * entries that all lie in one bin differs from the uniform one in that bin
 * and nowhere else), they are part of the key, and a malformed file is
 * named with its line. */
static void test_entries(void **state)
{
	(void)state;
	bsim_scene s;
	assert_int_equal(bsim_lattice_scene_init(&s, 1, 1, 6, 30), BSIM_OK);
	const char *dir = exe_dir("entries");
	/* every entry: bottom edge near x = 20, straight up at 1 m/s */
	char text[4096] = "group,trial,seq,ix,iy,edge,step,t,pos,x,y,vx,vy\n"
	                  "0,0,0,0,0,start,0,0,0,0,0,0,0\n";
	for (int i = 0; i < 20; i++) {
		char row[128];
		snprintf(row, sizeof row, "0,%d,1,0,0,bottom,10,0.04,%g,%g,0.01,0,1\n", i,
		         20.0 + 0.1 * i, 20.0 + 0.1 * i);
		strcat(text, row);
	}
	char path[1200];
	snprintf(path, sizeof path, "%s", bsim_test_write(dir, "gate_entries.csv", text));
	bsim_markov_entries e;
	bsim_error err;
	const char *paths[] = {dir};
	assert_int_equal(bsim_markov_entries_load(paths, 1, &e, &err), BSIM_OK);
	assert_int_equal(e.n, 20); /* the start rows left out */
	const bsim_markov_bins b = {2, 1, 1, 40.0};
	const int bin = bsim_markov_bin_of(&b, &s.lattice, BSIM_EDGE_BOTTOM, 20.0, e.v[0]);
	bsim_markov_def def = bsim_markov_def_default();
	def.train_trials = 0; /* states uniform in each bin */
	def.bins = b;
	def.trials = 60;
	def.start_trials = 0; /* the start's as the others': only bin `bin` differs */
	bsim_markov_set uni, obs;
	char d1[1100], d2[1100];
	snprintf(d1, sizeof d1, "%s/uniform", dir);
	snprintf(d2, sizeof d2, "%s/observed", dir);
	assert_int_equal(bsim_markov_build(&s, &def, d1, &uni, &err), BSIM_OK);
	def.entries = &e;
	assert_int_equal(bsim_markov_build(&s, &def, d2, &obs, &err), BSIM_OK);
	assert_true(uni.maps[0].key != obs.maps[0].key);
	const int nb = uni.maps[0].n_bins;
	int differ = 0;
	for (int a = 0; a < nb; a++) {
		int same = counts_same(&uni.maps[0], &obs.maps[0], a);
		if (a != bin)
			assert_true(same);
		differ += !same;
	}
	assert_int_equal(differ, 1);
	bsim_markov_set_free(&uni);
	bsim_markov_set_free(&obs);
	bsim_markov_entries_free(&e);
	/* a malformed row: file and line */
	strcat(text, "0,99,1,0,0,sideways,10,0.04,1,1,1,0,1\n");
	bsim_test_write(dir, "gate_entries.csv", text);
	assert_int_equal(bsim_markov_entries_load(paths, 1, &e, &err), BSIM_EINPUT);
	assert_non_null(strstr(err.msg, "gate_entries.csv:23: expected an entry"));
	bsim_scene_free(&s);
}

/* The rows of a map's exits file (map_HASH.exits.csv) of dir: each row's
 * fields as text, 11 per row; returns the number of rows. */
static int exits_rows(const char *dir, uint64_t key, char ***fields)
{
	char name[64];
	snprintf(name, sizeof name, "map_%016llx.exits.csv", (unsigned long long)key);
	char *text = bsim_test_read(bsim_test_join(dir, name));
	assert_non_null(text);
	int n = bsim_test_count_lines(text) - 1, r = 0;
	char **f = calloc((size_t)n * 11, sizeof *f);
	assert_non_null(f);
	char *save = NULL, *line = strtok_r(text, "\n", &save);
	assert_string_equal(line, "entry,trial,x,y,vx,vy,exit,exit_x,exit_y,exit_vx,exit_vy");
	while ((line = strtok_r(NULL, "\n", &save)) && r < n) {
		char *s2 = NULL, *c = strtok_r(line, ",", &s2);
		for (int k = 0; k < 11; k++, c = strtok_r(NULL, ",", &s2)) {
			assert_non_null(c);
			f[r * 11 + k] = strdup(c);
		}
		r++;
	}
	assert_int_equal(r, n);
	free(text);
	*fields = f;
	return n;
}

static void exits_free(char **f, int n)
{
	for (int i = 0; i < n * 11; i++)
		free(f[i]);
	free(f);
}

/* Self-consistent entries (--entries self:N): pass 0 is the uniform map
 * (other key, same counts); pass 1's states of a bin are exits of pass 0's
 * single gates into that bin, as pass 0's own file of exits records them
 * and its counts agree; the map is the same with 1 and 2 threads and
 * whether pass 0 is reused from the directory or simulated again; the
 * passes are part of the key. */
static void test_self_entries(void **state)
{
	(void)state;
	bsim_scene s;
	assert_int_equal(bsim_lattice_scene_init(&s, 1, 1, 6, 30), BSIM_OK);
	const char *dir = exe_dir("self");
	char du[1100], d0[1100], d1[1100];
	snprintf(du, sizeof du, "%s/uniform", dir);
	snprintf(d0, sizeof d0, "%s/pass0", dir);
	snprintf(d1, sizeof d1, "%s/pass1", dir);
	bsim_markov_def def = bsim_markov_def_default();
	def.train_trials = 0; /* states uniform in each bin: pass 0's */
	def.bins = (bsim_markov_bins){2, 2, 2, 40.0};
	def.trials = 30;
	def.start_trials = 0; /* the passes take every bin's trials alike */
	def.threads = 2;
	bsim_error err;
	bsim_markov_set uni, p0, p1a, p1b, again;
	assert_int_equal(bsim_markov_build(&s, &def, du, &uni, &err), BSIM_OK);
	def.self_entries = 1;
	def.self_passes = 0;
	assert_int_equal(bsim_markov_build(&s, &def, d0, &p0, &err), BSIM_OK);
	const int nb = uni.maps[0].n_bins, T = def.trials;
	assert_true(p0.maps[0].key != uni.maps[0].key);
	assert_true(counts_same(&p0.maps[0], &uni.maps[0], -1));
	/* pass 1 from scratch on one thread, and on two from d0's pass 0 */
	def.self_passes = 1;
	def.threads = 1;
	assert_int_equal(bsim_markov_build(&s, &def, d1, &p1a, &err), BSIM_OK);
	def.threads = 2;
	assert_int_equal(bsim_markov_build(&s, &def, d0, &p1b, &err), BSIM_OK);
	const uint64_t k0 = p0.maps[0].key, k1 = p1a.maps[0].key;
	assert_true(k1 != k0 && k1 != uni.maps[0].key);
	assert_int_equal(p1b.maps[0].key, k1);
	char name[64];
	for (int f = 0; f < 3; f++) {
		static const char *const ext[] = {"key", "csv", "exits.csv"};
		snprintf(name, sizeof name, "map_%016llx.%s", (unsigned long long)k1, ext[f]);
		char *a = bsim_test_read(bsim_test_join(d1, name));
		char *b = bsim_test_read(bsim_test_join(d0, name));
		assert_non_null(a);
		assert_non_null(b);
		assert_string_equal(a, b);
		free(a);
		free(b);
	}
	/* the same passes again: reused; more passes: built */
	assert_int_equal(bsim_markov_build(&s, &def, d1, &again, &err), BSIM_OK);
	assert_int_equal(again.reused, 1);
	bsim_markov_set_free(&again);
	def.self_passes = 2;
	assert_int_equal(bsim_markov_build(&s, &def, d1, &again, &err), BSIM_OK);
	assert_int_equal(again.built, 1);
	assert_true(again.maps[0].key != k1);
	bsim_markov_set_free(&again);

	/* pass 0's exits, against its map's counts */
	char **e0, **e1;
	const int n0 = exits_rows(d0, k0, &e0), n1 = exits_rows(d0, k1, &e1);
	assert_int_equal(n0, nb * T);
	assert_int_equal(n1, nb * T);
	int *count = calloc((size_t)nb * nb, sizeof *count),
	    *into = calloc((size_t)nb, sizeof *into);
	assert_non_null(count);
	assert_non_null(into);
	for (int r = 0; r < n0; r++) {
		int a = atoi(e0[r * 11]), x = atoi(e0[r * 11 + 6]);
		count[a * nb + x]++;
		into[x]++;
	}
	for (int a = 0; a < nb; a++)
		for (int x = 0; x < nb; x++)
			assert_int_equal(count[a * nb + x],
			                 bsim_markov_map_count(&p0.maps[0], a, x));
	/* each pass-1 state of bin b > 0 is the exit state of a pass-0 trial
	 * that left into b; states drawn uniformly only in bins none left into */
	int matched = 0;
	for (int r = 0; r < n1; r++) {
		const int b = atoi(e1[r * 11]);
		if (b == 0 || into[b] == 0)
			continue;
		int found = 0;
		for (int q = 0; q < n0 && !found; q++)
			found = atoi(e0[q * 11 + 6]) == b &&
			        strcmp(e0[q * 11 + 7], e1[r * 11 + 2]) == 0 &&
			        strcmp(e0[q * 11 + 8], e1[r * 11 + 3]) == 0 &&
			        strcmp(e0[q * 11 + 9], e1[r * 11 + 4]) == 0 &&
			        strcmp(e0[q * 11 + 10], e1[r * 11 + 5]) == 0;
		if (!found)
			fail_msg("pass 1, bin %d, trial %s: state %s %s %s %s is no exit of pass 0 "
			         "into it",
			         b, e1[r * 11 + 1], e1[r * 11 + 2], e1[r * 11 + 3], e1[r * 11 + 4],
			         e1[r * 11 + 5]);
		matched++;
	}
	assert_true(matched > n1 / 4);
	free(count);
	free(into);
	exits_free(e0, n0);
	exits_free(e1, n1);
	bsim_markov_set_free(&uni);
	bsim_markov_set_free(&p0);
	bsim_markov_set_free(&p1a);
	bsim_markov_set_free(&p1b);

	/* the command line: self:N beyond the passes, and self with observed
	 * entries, refused */
	const char *exp = bsim_test_src("configs/lattice/c_track_essay.yaml");
	char target[1200];
	snprintf(target, sizeof target, "%s/refused", dir);
	const char *too_many[] = {"markov", "build", exp,    "--entries",
	                          "self:9", "--out", target, NULL};
	char *err_text = NULL;
	assert_int_equal(bsim_test_cli(too_many, NULL, &err_text), 2);
	assert_non_null(strstr(err_text, "--entries self:9: expected self, self:N"));
	free(err_text);
	const char *obs = bsim_test_write(dir, "gate_entries.csv",
	                                  "group,trial,seq,ix,iy,edge,step,t,pos,x,y,vx,vy\n"
	                                  "0,0,1,0,0,bottom,10,0.04,20,20,0.01,0,1\n");
	const char *both[] = {"markov",    "build", exp,     "--entries", "self",
	                      "--entries", obs,     "--out", target,      NULL};
	const char *need2[] = {"self-consistent entries", NULL};
	bsim_test_expect_input_error(both, need2);
	assert_false(bsim_test_exists(target));
	bsim_scene_free(&s);
}

/* The maps files of dir (key, counts; not the CPU times) concatenated. */
static char *maps_of(const char *dir)
{
	char *keys = bsim_test_read_glob(bsim_test_join(dir, "map_*.key"));
	char *csv = map_text(dir);
	assert_non_null(keys);
	char *both = malloc(strlen(keys) + strlen(csv) + 1);
	assert_non_null(both);
	strcpy(both, keys);
	strcat(both, csv);
	free(keys);
	free(csv);
	return both;
}

/* The speed bins' range by default is the propulsion's (40 m/s at 7 N on
 * 1 kg and below, in proportion above): a lattice at 14 N gets 80 m/s, its
 * maps those of --vmax 80 file for file, and the directory says 0 (from
 * the propulsion), so a lattice of another force reads it with its own;
 * at 7 N the maps of --vmax 40, the range before. */
static void test_speed_range(void **state)
{
	(void)state;
	const bsim_markov_bins dflt = bsim_markov_bins_default(), given = {2, 2, 2, 55.0};
	const double force[4] = {3.5, 7.0, 14.0, 21.0}, want[4] = {40.0, 40.0, 80.0, 120.0};
	for (int i = 0; i < 4; i++) {
		bsim_scene s;
		assert_int_equal(bsim_lattice_scene_init(&s, 1, 2, force[i], 25), BSIM_OK);
		assert_double_equal(bsim_markov_bins_v_max(&dflt, &s), want[i], 1e-12);
		assert_double_equal(bsim_markov_bins_v_max(&given, &s), 55.0, 0.0);
		s.body.mass = 2.0; /* the acceleration, not the force */
		assert_double_equal(bsim_markov_bins_v_max(&dflt, &s), fmax(40.0, want[i] / 2),
		                    1e-12);
		bsim_scene_free(&s);
	}
	const char *dir = exe_dir("speed_range");
	const double vmax[3] = {0.0, 80.0, 40.0};
	for (int f = 0; f < 2; f++) {
		char own[1100], at80[1100], at40[1100];
		snprintf(own, sizeof own, "%s/own%d", dir, f);
		snprintf(at80, sizeof at80, "%s/vmax80_%d", dir, f);
		snprintf(at40, sizeof at40, "%s/vmax40_%d", dir, f);
		const char *dirs[3] = {own, at80, at40};
		bsim_scene s;
		assert_int_equal(bsim_lattice_scene_init(&s, 1, 2, f ? 14.0 : 7.0, 25), BSIM_OK);
		s.lattice.protocol = BSIM_PROTOCOL_ESSAY;
		char *maps[3];
		for (int v = 0; v < 3; v++) {
			bsim_markov_def def = bsim_markov_def_default();
			def.bins = (bsim_markov_bins){2, 2, 2, vmax[v]};
			def.trials = 3;
			def.start_trials = 20;
			def.train_trials = 30;
			def.seed = 4;
			bsim_markov_set set;
			bsim_error err;
			assert_int_equal(bsim_markov_build(&s, &def, dirs[v], &set, &err), BSIM_OK);
			assert_double_equal(set.def.bins.v_max, v ? vmax[v] : f ? 80.0 : 40.0, 0.0);
			bsim_markov_set_free(&set);
			maps[v] = maps_of(dirs[v]);
			if (v == 0) { /* read back with this lattice's range */
				bsim_options opts;
				assert_int_equal(bsim_markov_load(&s, own, &opts, &set, &err),
				                 BSIM_OK);
				assert_double_equal(set.def.bins.v_max, f ? 80.0 : 40.0, 0.0);
				bsim_markov_set_free(&set);
				char *json = bsim_test_read(bsim_test_join(own, "markov.json"));
				assert_non_null(strstr(json, "\"v_max\": 0}"));
				free(json);
			}
		}
		/* 14 N: --vmax 80's maps, not 40's; 7 N: 40's, not 80's */
		assert_string_equal(maps[0], maps[f ? 1 : 2]);
		assert_string_not_equal(maps[0], maps[f ? 2 : 1]);
		for (int v = 0; v < 3; v++)
			free(maps[v]);
		bsim_scene_free(&s);
	}
}

/* Flow-weighted entries (--entries flow:N) on a column of two gates of
 * different stiffness pairs: the maps are the same with 1 and 2 threads;
 * each pass-1 state of a bin is the exit state of a pass-0 single gate of
 * either map into that bin; the lattice's layout is part of the key. */
static void test_flow_entries(void **state)
{
	(void)state;
	bsim_scene s;
	assert_int_equal(bsim_lattice_scene_init(&s, 1, 2, 6, 30), BSIM_OK);
	for (int side = 0; side < 2; side++) /* gate (0, 1): 100, 400 */
		s.beams[bsim_lattice_beam(&s.lattice, 0, 1, side)].stiffness = side ? 400 : 100;
	const char *dir = exe_dir("flow");
	char d1[1100], d2[1100], d3[1100];
	snprintf(d1, sizeof d1, "%s/threads1", dir);
	snprintf(d2, sizeof d2, "%s/threads2", dir);
	snprintf(d3, sizeof d3, "%s/swapped", dir);
	bsim_markov_def def = bsim_markov_def_default();
	def.bins = (bsim_markov_bins){2, 2, 2, 40.0};
	def.trials = 20;
	def.self_entries = 2;
	def.start_trials = 0; /* the passes take every bin's trials alike */
	def.self_passes = 1;
	def.threads = 1;
	bsim_error err;
	bsim_markov_set a, b, c;
	assert_int_equal(bsim_markov_build(&s, &def, d1, &a, &err), BSIM_OK);
	def.threads = 2;
	assert_int_equal(bsim_markov_build(&s, &def, d2, &b, &err), BSIM_OK);
	assert_int_equal(a.n, 2);
	char *t1 = maps_of(d1), *t2 = maps_of(d2);
	assert_string_equal(t1, t2);
	free(t1);
	free(t2);
	const int nb = a.maps[0].n_bins, T = def.trials;
	/* pass 0's exits of both maps (the self-consistent pass 0's keys) */
	bsim_markov_def d0 = def;
	d0.self_entries = 1;
	d0.self_passes = 0;
	bsim_markov_set p0;
	assert_int_equal(bsim_markov_build(&s, &d0, d1, &p0, &err), BSIM_OK);
	assert_int_equal(p0.reused, 2); /* written by the flow build */
	char **e0[2], **e1[2];
	int n0[2], n1[2];
	for (int i = 0; i < 2; i++) {
		n0[i] = exits_rows(d1, p0.maps[i].key, &e0[i]);
		n1[i] = exits_rows(d1, a.maps[i].key, &e1[i]);
		assert_int_equal(n0[i], nb * T);
		assert_int_equal(n1[i], nb * T);
	}
	int matched = 0;
	for (int i = 0; i < 2; i++)
		for (int r = 0; r < n1[i]; r++) {
			const int bin = atoi(e1[i][r * 11]);
			int into = 0, found = 0;
			for (int j = 0; j < 2; j++)
				for (int q = 0; q < n0[j] && !found; q++) {
					char **f = e0[j] + q * 11;
					if (atoi(f[6]) != bin)
						continue;
					into++;
					found = strcmp(f[7], e1[i][r * 11 + 2]) == 0 &&
					        strcmp(f[8], e1[i][r * 11 + 3]) == 0 &&
					        strcmp(f[9], e1[i][r * 11 + 4]) == 0 &&
					        strcmp(f[10], e1[i][r * 11 + 5]) == 0;
				}
			if (bin == 0 || into == 0)
				continue;
			if (!found)
				fail_msg("map %d, bin %d, trial %s: no exit of pass 0 into the bin",
				         i, bin, e1[i][r * 11 + 1]);
			matched++;
		}
	assert_true(matched > (n1[0] + n1[1]) / 4);
	for (int i = 0; i < 2; i++) {
		exits_free(e0[i], n0[i]);
		exits_free(e1[i], n1[i]);
	}
	/* the layout swapped: other maps */
	for (int iy = 0; iy < 2; iy++)
		for (int side = 0; side < 2; side++)
			s.beams[bsim_lattice_beam(&s.lattice, 0, iy, side)].stiffness =
			        iy == side ? 400 : 100;
	assert_int_equal(bsim_markov_build(&s, &def, d3, &c, &err), BSIM_OK);
	for (int i = 0; i < c.n; i++)
		for (int j = 0; j < a.n; j++)
			assert_true(c.maps[i].key != a.maps[j].key);
	bsim_markov_set_free(&a);
	bsim_markov_set_free(&b);
	bsim_markov_set_free(&c);
	bsim_markov_set_free(&p0);
	bsim_scene_free(&s);
}

/* The fields of the maps of a physics (configs/markov/kinds, docs/markov.md
 * "Maps of a physics"): every experiment there loads, simulates its field
 * under the physics the docs give (F_prop = 7 N, Rm = 25 N), and every
 * gate of its field is of kind A = (150, 600), B = (600, 300) or C = (300,
 * 150) N m/rad; those of the held-out physics (other_*, "A held-out
 * physics") at F_prop = 8 N, Rm = 20 N, of kind D = (200, 500), E = (700,
 * 250) or G = (400, 120); the training fields alone under the essay's
 * protocol. */
static void test_kinds_configs(void **state)
{
	(void)state;
	char dir[1100];
	snprintf(dir, sizeof dir, "%s", bsim_test_src("configs/markov/kinds"));
	DIR *d = opendir(dir);
	assert_non_null(d);
	/* A, B, C; the held-out physics' D, E, G (exp_other_*); and the third
	 * physics' H, I, J (exp_third_*) */
	const double kinds[3][3][2] = {{{150, 600}, {600, 300}, {300, 150}},
	                               {{200, 500}, {700, 250}, {400, 120}},
	                               {{250, 450}, {550, 180}, {350, 350}}};
	const double force[3] = {7.0, 8.0, 10.0}, magnitude[3] = {25.0, 20.0, 25.0};
	int n_exp = 0, n_other = 0, n_third = 0;
	struct dirent *de;
	while ((de = readdir(d))) {
		if (strncmp(de->d_name, "exp_", 4) != 0)
			continue;
		char path[1400];
		snprintf(path, sizeof path, "%s/%s", dir, de->d_name);
		bsim_experiment e;
		bsim_error err;
		if (bsim_experiment_load(path, NULL, 0, &e, &err) != BSIM_OK)
			fail_msg("%s: %s", de->d_name, err.msg);
		assert_int_equal(e.n_groups, 1);
		bsim_scene s;
		assert_int_equal(bsim_experiment_group_scene(&e, 0, NULL, 0, &s, &err), BSIM_OK);
		assert_true(s.has_lattice);
		const int other = strncmp(de->d_name, "exp_other_", 10) == 0   ? 1
		                  : strncmp(de->d_name, "exp_third_", 10) == 0 ? 2
		                                                               : 0;
		const double(*kind)[2] = kinds[other];
		n_other += other == 1;
		n_third += other == 2;
		assert_true(s.effects.has_propulsion && s.effects.propulsion_force == force[other]);
		assert_true(s.effects.has_random_force &&
		            s.effects.random_magnitude == magnitude[other]);
		const int train = strcmp(de->d_name, "exp_train_r21.yaml") == 0 ||
		                  strcmp(de->d_name, "exp_other_train.yaml") == 0;
		assert_int_equal(s.lattice.protocol,
		                 train ? BSIM_PROTOCOL_ESSAY : BSIM_PROTOCOL_WORLD);
		for (int iy = 0; iy < s.lattice.rows; iy++)
			for (int ix = s.lattice.ix_min; ix <= s.lattice.ix_max; ix++) {
				const double kl =
				        s.beams[bsim_lattice_beam(&s.lattice, ix, iy, 0)].stiffness;
				const double kr =
				        s.beams[bsim_lattice_beam(&s.lattice, ix, iy, 1)].stiffness;
				int of = 0;
				for (int k = 0; k < 3; k++)
					of += kl == kind[k][0] && kr == kind[k][1];
				if (of != 1)
					fail_msg("%s: gate (%d, %d) is %g, %g N m/rad", de->d_name,
					         ix, iy, kl, kr);
			}
		bsim_scene_free(&s);
		bsim_experiment_free(&e);
		n_exp++;
	}
	closedir(d);
	assert_true(n_exp >= 18);
	assert_true(n_other >= 6);
	assert_true(n_third >= 3);
}

/* The note on a method's scope names what keeps it from the maps of a
 * physics; for the default method or finer settings, where its maps
 * missed and the nearest-neighbour walks did not. */
static const char DEFAULT_SCOPE[] =
        "maps of entry bins: measured beyond TV 0.05 on 7 of 40 fields, columns and a random "
        "field of a physics they were not chosen on among them, where the nearest-neighbour "
        "walks (markov build's default) were within 0.05 on all 40 (docs/markov.md, \"A kernel "
        "over exact states\")";

static void test_scope(void **state)
{
	(void)state;
	char buf[320];
	const bsim_markov_def d0 = bsim_markov_def_default();
	assert_string_equal(bsim_markov_def_scope(&d0, buf, sizeof buf), DEFAULT_SCOPE);
	bsim_markov_def d = d0;
	d.bins.n_pos = 20;
	d.bins.n_speed = 6;
	d.bins.n_dir = 18; /* more bins, not fewer */
	d.start_trials = 32000;
	d.train_trials = 20000;
	d.trials = 20; /* the maps' sampling error, which validate reports */
	assert_string_equal(bsim_markov_def_scope(&d, buf, sizeof buf), DEFAULT_SCOPE);
	d = d0;
	d.train_trials = 0;
	assert_string_equal(bsim_markov_def_scope(&d, buf, sizeof buf),
	                    "maps with states uniform in each bin (no training field): measured "
	                    "less accurate than with the maps' defaults on layouts they were not "
	                    "built on "
	                    "(docs/markov.md, \"What each part does\")");
	d.bins = (bsim_markov_bins){8, 8, 9, 40.0}; /* the default before the training field */
	assert_non_null(strstr(bsim_markov_def_scope(&d, buf, sizeof buf),
	                       "maps with states uniform in each bin (no training field), 8,8,9 "
	                       "bins (the default 14,6,13): "));
	d = d0;
	d.train_trials = 2000;
	assert_non_null(strstr(bsim_markov_def_scope(&d, buf, sizeof buf),
	                       "maps with 2000 training trials (the default 4000): "));
	d = d0;
	d.after_start = 0;
	assert_string_equal(bsim_markov_def_scope(&d, buf, sizeof buf),
	                    "maps with no gate after the start: measured less accurate than with "
	                    "the maps' defaults on layouts they were not built on (docs/markov.md, "
	                    "\"What each part does\")");
	d.start_trials = 50;
	assert_non_null(strstr(bsim_markov_def_scope(&d, buf, sizeof buf),
	                       "maps with 50 start trials (the default 16000), no gate after the "
	                       "start: "));
	/* fewer start trials continued than the default's: said; every one,
	 * or all of fewer start trials (which that part of the note says): not */
	d = d0;
	d.after_trials = 4000;
	assert_non_null(strstr(bsim_markov_def_scope(&d, buf, sizeof buf),
	                       "maps with 4000 start trials continued (the default 8000): "));
	d.after_trials = 0;
	assert_string_equal(bsim_markov_def_scope(&d, buf, sizeof buf), DEFAULT_SCOPE);
	d = d0;
	d.start_trials = 3000;
	assert_null(strstr(bsim_markov_def_scope(&d, buf, sizeof buf), "continued"));
	d = d0;
	int is_kind;
	bsim_error err;
	assert_int_equal(bsim_markov_entries_kind("flow:2", &d, &is_kind, &err), BSIM_OK);
	assert_non_null(strstr(bsim_markov_def_scope(&d, buf, sizeof buf), "layout only"));
	d = d0;
	assert_int_equal(bsim_markov_entries_kind("self", &d, &is_kind, &err), BSIM_OK);
	assert_non_null(strstr(bsim_markov_def_scope(&d, buf, sizeof buf),
	                       "self-consistent entries: measured above TV 0.05"));
	/* as markov.json gives them back */
	d = d0;
	snprintf(d.entries_id, sizeof d.entries_id, "flow 1");
	assert_non_null(strstr(bsim_markov_def_scope(&d, buf, sizeof buf), "layout only"));
	snprintf(d.entries_id, sizeof d.entries_id, "self 2");
	assert_non_null(strstr(bsim_markov_def_scope(&d, buf, sizeof buf), "self-consistent"));
	snprintf(d.entries_id, sizeof d.entries_id, "0123abcd 20");
	assert_non_null(
	        strstr(bsim_markov_def_scope(&d, buf, sizeof buf), "entries observed in sweeps"));
	/* cut short, never past the buffer */
	char small[8];
	assert_string_equal(bsim_markov_def_scope(&d, small, sizeof small), "entries");
}

/* A build stopped by SIGINT or SIGTERM once its first map is committed
 * (the manifest appears with it) exits 128 + the signal, keeping that map;
 * one killed (SIGKILL) keeps it too; the same command then builds only the
 * other, and the directory's maps are those of a build never stopped. */
static void test_interrupted_build(void **state)
{
	(void)state;
	const char *exp = bsim_test_src("configs/lattice/c_track_essay.yaml");
	char whole[1024];
	snprintf(whole, sizeof whole, "%s", bsim_test_dir("build_whole"));
	/* the start's trials as the others' (the test is of the stop, not the
	 * maps) */
	const char *b[] = {"markov", "build",  exp,     "--trials", "200", "--start-trials",
	                   "200",    "--bins", "2,2,2", "--train",  "10",  "--quiet",
	                   "--out",  whole,    NULL};
	assert_int_equal(bsim_test_cli(b, NULL, NULL), 0);
	char *want = maps_of(whole);
	static const int sigs[] = {SIGINT, SIGTERM, SIGKILL};
	for (int i = 0; i < 3; i++) {
		char dir[1024], errfile[1100];
		snprintf(dir, sizeof dir, "%s", bsim_test_dir("build_stopped"));
		snprintf(errfile, sizeof errfile, "%s.err", dir);
		const char *argv[] = {"markov",   "build",   "--start-trials", "200",   exp,
		                      "--trials", "200",     "--bins",         "2,2,2", "--train",
		                      "10",       "--quiet", "--out",          dir,     NULL};
		const bsim_test_opts o = {.err = errfile};
		int pid = bsim_test_spawn_with(argv, &o);
		int status = -1;
		assert_int_equal(
		        bsim_test_await_glob(pid, bsim_test_join(dir, "manifest.json"), 1, &status),
		        1);
		kill(pid, sigs[i]);
		status = bsim_test_wait(pid);
		assert_int_equal(status, 128 + sigs[i]);
		char *err = bsim_test_read(errfile);
		assert_non_null(err);
		if (sigs[i] != SIGKILL) {
			assert_non_null(strstr(err, "stopped after 1 of the 2 maps to build"));
			assert_non_null(strstr(err, "the same command builds the rest"));
		}
		free(err);
		unlink(errfile);
		const char *again[] = {
		        "markov", "build",  exp,     "--trials", "200", "--start-trials",
		        "200",    "--bins", "2,2,2", "--train",  "10",  "--out",
		        dir,      NULL};
		char *out = NULL;
		assert_int_equal(bsim_test_cli(again, &out, NULL), 0);
		assert_non_null(strstr(out, "1 maps built"));
		assert_non_null(strstr(out, "1 reused"));
		free(out);
		char *got = maps_of(dir);
		assert_string_equal(got, want);
		free(got);
		assert_true(bsim_test_exists(bsim_test_join(dir, "markov.json")));
	}
	free(want);
}

/* The validation's last trial sets the stop flag, as a signal would:
 * the maps' resamples that follow stop at the first (each a chain solve,
 * a minute's work on a field of many gates), BSIM_ESTOPPED with the trials
 * journaled and nothing else written; resumed, the run ends as one never
 * stopped. */
static void stop_at_last_trial(void *user, long done, long total)
{
	if (done == total)
		*(volatile sig_atomic_t *)user = 1;
}

static void test_validation_stopped_in_resamples(void **state)
{
	(void)state;
	char maps[1024], dir[1100], whole[1100], exp[1200];
	snprintf(maps, sizeof maps, "%s", bsim_test_dir("stopped_maps"));
	snprintf(dir, sizeof dir, "%s/stopped", maps);
	snprintf(whole, sizeof whole, "%s/whole", maps);
	snprintf(exp, sizeof exp, "%s", bsim_test_src("configs/markov/c_track.yaml"));
	build_small_maps(exp, maps);
	static volatile sig_atomic_t flag;
	flag = 0;
	bsim_markov_validate_def def = bsim_markov_validate_def_default();
	def.experiment = exp;
	def.map_dir = maps;
	def.trials = 30;
	def.bootstrap = 50;
	def.threads = 2;
	def.out = dir;
	def.progress = stop_at_last_trial;
	def.progress_user = (void *)&flag;
	def.stop = &flag;
	bsim_markov_validation v, w;
	bsim_error err;
	assert_int_equal(bsim_markov_validate(&def, &v, &err), BSIM_ESTOPPED);
	assert_non_null(strstr(err.msg, "stopped in the maps' resample 1 of 40"));
	assert_true(v.journal[0] && bsim_test_exists(v.journal));
	assert_false(bsim_test_exists(bsim_test_join(dir, "validate.json")));
	def.progress = NULL;
	flag = 0;
	def.resume = 1;
	assert_int_equal(bsim_markov_validate(&def, &v, &err), BSIM_OK);
	def.resume = 0;
	def.out = whole;
	assert_int_equal(bsim_markov_validate(&def, &w, &err), BSIM_OK);
	assert_int_equal(v.n, w.n);
	for (int i = 0; i < v.n; i++) {
		assert_double_equal(v.checks[i].tv, w.checks[i].tv, 0.0);
		assert_double_equal(v.checks[i].tv_sampling, w.checks[i].tv_sampling, 0.0);
		assert_double_equal(v.checks[i].tv_map, w.checks[i].tv_map, 0.0);
	}
	bsim_markov_validation_free(&v);
	bsim_markov_validation_free(&w);
}

/* ctest runs the long tests (against direct simulation, and a build
 * stopped by signals) as test_markov_long, `test_markov long`, each with
 * its own time limit; any other argument runs the tests of that name. */
int main(int argc, char **argv)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_one_gate_is_the_map),
	        cmocka_unit_test(test_two_gates_geometric),
	        cmocka_unit_test(test_time_by_hand),
	        cmocka_unit_test(test_bins),
	        cmocka_unit_test(test_scope),
	        cmocka_unit_test(test_kinds_configs),
	        cmocka_unit_test(test_conservation),
	        cmocka_unit_test(test_tolerance),
	        cmocka_unit_test(test_sweeps_against_series),
	        cmocka_unit_test(test_map_cost),
	        cmocka_unit_test(test_training_kinds),
	        cmocka_unit_test(test_crossings_are_single_gates),
	        cmocka_unit_test(test_start_trials_key),
	        cmocka_unit_test(test_speed_range),
	        cmocka_unit_test(test_threads_and_cache),
	        cmocka_unit_test(test_entries),
	        cmocka_unit_test(test_self_entries),
	        cmocka_unit_test(test_flow_entries),
	        cmocka_unit_test(test_bad_inputs),
	        cmocka_unit_test(test_bad_map_files),
	        cmocka_unit_test(test_field_figures),
	};
	const struct CMUnitTest long_tests[] = {
	        cmocka_unit_test(test_one_gate_against_simulation),
	        cmocka_unit_test(test_closed_loop_said),
	        cmocka_unit_test(test_after_start_against_simulation),
	        cmocka_unit_test(test_training_against_simulation),
	        cmocka_unit_test(test_interrupted_build),
	        cmocka_unit_test(test_validation_stopped_in_resamples),
	};
	if (argc > 1 && strcmp(argv[1], "long") == 0)
		return cmocka_run_group_tests_name("markov_long", long_tests, NULL, NULL);
	if (argc > 1) { /* one test by name, e.g. test_training_kinds */
		cmocka_set_test_filter(argv[1]);
		return cmocka_run_group_tests(tests, NULL, NULL) |
		       cmocka_run_group_tests_name("markov_long", long_tests, NULL, NULL);
	}
	return cmocka_run_group_tests(tests, NULL, NULL);
}
