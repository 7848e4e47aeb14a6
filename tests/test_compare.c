/* The paired comparison on trial outcomes built by hand, so the right
 * verdict is known: identical groups and a few discordant pairs are shown
 * equivalent when there are enough trials and inconclusive when there are
 * not, a large one-sided difference is a disagreement, a deterministic
 * group is one pair (same or different) outside the Holm family, and the
 * margin and the exact rule act as documented; the Holm family by its
 * definition, groups at the floor uninformative, and the smaller family
 * flagging what the redundant one missed. More than two sides: one Holm
 * family over every pair's tests against Holm's and McNemar's definitions
 * computed here, and the odd one out on constructed verdicts and outcomes
 * (one side flipped, two sides flipped, all alike). Trials identical but
 * for the turn, compared only where both sides know it. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "beamsim/compare.h"

enum { G = 6, N = 200 };

static bsim_trial_result A[G * N], B[G * N];
static bsim_group_result GA[G], GB[G];
static bsim_sweep_result ra = {.n_groups = G, .trials = N, .trials_out = A, .groups = GA};
static bsim_sweep_result rb = {.n_groups = G, .trials = N, .trials_out = B, .groups = GB};

static void traversed(bsim_trial_result *r, bsim_type type)
{
	memset(r, 0, sizeof *r);
	r->outcome = BSIM_TRAVERSED;
	r->type = type;
}

static void stuck(bsim_trial_result *r)
{
	memset(r, 0, sizeof *r);
	r->outcome = BSIM_STUCK;
}

/* Group 0: identical. Group 1: 3 pairs traversed on A only. Group 2: 150
 * of 200 traversed on A, 10 on B. Group 3: same outcomes, one trial's end
 * position differs. Groups 4 and 5 are deterministic (every trial a copy
 * of one): 4 traverses on A and is stuck on B, 5 is alike. */
static void build(void)
{
	memset(GA, 0, sizeof GA);
	memset(GB, 0, sizeof GB);
	for (int i = 0; i < G * N; i++) {
		traversed(&A[i], i % 2 ? BSIM_TYPE_LEFT : BSIM_TYPE_RIGHT);
		B[i] = A[i];
	}
	for (int t = 0; t < 3; t++)
		stuck(&B[1 * N + t]);
	for (int t = 0; t < N; t++) {
		if (t >= 150)
			stuck(&A[2 * N + t]);
		if (t >= 10)
			stuck(&B[2 * N + t]);
		traversed(&A[4 * N + t], BSIM_TYPE_NONE);
		stuck(&B[4 * N + t]);
		traversed(&A[5 * N + t], BSIM_TYPE_NONE);
		traversed(&B[5 * N + t], BSIM_TYPE_NONE);
	}
	B[3 * N + 7].x_end = 1e-3;
	GA[4].deterministic = GB[4].deterministic = 1;
	GA[5].deterministic = 1; /* either side's flag makes the group one pair */
}

static void test_verdicts(void **state)
{
	(void)state;
	build();
	bsim_comparison c;
	bsim_error err;
	bsim_compare_rule rule = {0.05, 0.05, 0};
	assert_int_equal(bsim_compare_analyse(&ra, &rb, NULL, &rule, &c, &err), BSIM_OK);
	assert_int_equal(c.groups[0].verdict, BSIM_VERDICT_EQUIVALENT);
	assert_int_equal(c.groups[1].verdict, BSIM_VERDICT_EQUIVALENT);
	assert_int_equal(c.groups[2].verdict, BSIM_VERDICT_DISAGREE);
	assert_int_equal(c.groups[3].verdict, BSIM_VERDICT_EQUIVALENT);
	assert_int_equal(c.groups[4].verdict, BSIM_VERDICT_DIFFERENT);
	assert_int_equal(c.groups[5].verdict, BSIM_VERDICT_SAME);
	assert_int_equal(c.n_disagree, 2);
	assert_int_equal(c.count[BSIM_VERDICT_EQUIVALENT], 3);

	/* Deterministic groups: one pair, outside the Holm family, no p-value.
	 * The family (bsim_compare_family): groups 0 and 3 only traverse, left
	 * or right, so traversed is always and right is 1 - left: left alone;
	 * groups 1 and 2 traverse or get stuck: left and right (traversed =
	 * left + right, stuck = 1 - left - right). */
	assert_int_equal(c.groups[0].family, 1u << BSIM_EVENT_LEFT);
	assert_int_equal(c.groups[1].family, 1u << BSIM_EVENT_LEFT | 1u << BSIM_EVENT_RIGHT);
	assert_int_equal(c.groups[4].family, 0);
	assert_int_equal(c.n_tests, 6);
	assert_true(isnan(c.groups[0].ev[BSIM_EVENT_TRAVERSED].p_holm));
	assert_false(c.groups[0].ev[BSIM_EVENT_TRAVERSED].in_family);
	assert_int_equal(c.groups[4].pairs, 1);
	assert_int_equal(c.groups[4].discordant, 1);
	assert_true(isnan(c.groups[4].ev[BSIM_EVENT_TRAVERSED].p_value));
	assert_float_equal(c.groups[4].ev[BSIM_EVENT_TRAVERSED].diff, 1.0, 0);
	assert_int_equal(c.pairs, 4 * N + 2);

	/* Group 2 by hand: 140 pairs traversed only on A, none only on B. */
	const bsim_event_test *t = &c.groups[2].ev[BSIM_EVENT_TRAVERSED];
	assert_int_equal(t->pairs.a, 10);
	assert_int_equal(t->pairs.b, 140);
	assert_int_equal(t->pairs.c, 0);
	assert_float_equal(t->p_a, 0.75, 1e-15);
	assert_float_equal(t->p_b, 0.05, 1e-15);
	assert_float_equal(t->diff, 0.7, 1e-15);
	assert_float_equal(t->p_value, bsim_stats_mcnemar_exact(140, 0), 1e-300);
	/* traversed = left + right: out of the family, which flags its parts */
	assert_true(!t->in_family && isnan(t->p_holm) && !t->beyond && !t->equivalent);
	const bsim_event_test *l = &c.groups[2].ev[BSIM_EVENT_LEFT];
	assert_int_equal(l->pairs.b, 70);
	assert_true(l->in_family && l->p_holm >= l->p_value && l->beyond);
	assert_int_equal(c.groups[2].ev[BSIM_EVENT_STUCK].pairs.c, 140);
	assert_int_equal(c.groups[1].discordant, 3);
	assert_int_equal(c.groups[3].changed, 1);
	assert_int_equal(c.groups[3].discordant, 0);

	/* The smallest significant difference by hand: 6 tests at 0.05 need
	 * p < 8.3e-3; a one-way split of m pairs gives 2 (1/2)^m: 1.56e-2 for
	 * 7, 7.8e-3 for 8, so with no discordant pair the bound is 8 of 200
	 * pairs. */
	double level = 0.05 / 6.0;
	int fewest = 1;
	while (2.0 * pow(0.5, fewest) >= level)
		fewest++;
	assert_int_equal(fewest, 8);
	assert_float_equal(c.groups[0].ev[BSIM_EVENT_TRAVERSED].min_significant, fewest / 200.0,
	                   1e-15);
	/* mde80 with no discordant pair: every discordant pair one way (psi =
	 * delta), the power P(m >= 8) for m ~ Binomial(200, delta) is 0.8. */
	double mde = c.groups[0].ev[BSIM_EVENT_TRAVERSED].mde80, tail = 0.0;
	for (int m = 0; m < fewest; m++)
		tail += exp(lgamma(201.0) - lgamma(m + 1.0) - lgamma(201.0 - m) + m * log(mde) +
		            (200 - m) * log1p(-mde));
	assert_float_equal(1.0 - tail, 0.8, 1e-9);
	bsim_compare_free(&c);
}

/* A margin above the difference turns the disagreement into "small"; the
 * exact rule flags the group whose trial changed in a field. */
static void test_rule_knobs(void **state)
{
	(void)state;
	build();
	bsim_comparison c;
	bsim_error err;
	bsim_compare_rule wide = {0.05, 0.75, 0};
	assert_int_equal(bsim_compare_analyse(&ra, &rb, NULL, &wide, &c, &err), BSIM_OK);
	assert_int_equal(c.groups[2].verdict, BSIM_VERDICT_SMALL);
	assert_int_equal(c.n_disagree, 1); /* the deterministic pair that differs */
	bsim_compare_free(&c);

	bsim_compare_rule exact = {0.05, 0.05, 1};
	assert_int_equal(bsim_compare_analyse(&ra, &rb, NULL, &exact, &c, &err), BSIM_OK);
	assert_int_equal(c.groups[3].verdict, BSIM_VERDICT_DISAGREE);
	assert_int_equal(c.groups[1].verdict, BSIM_VERDICT_DISAGREE);
	assert_int_equal(c.groups[0].verdict, BSIM_VERDICT_EQUIVALENT);
	assert_int_equal(c.groups[5].verdict, BSIM_VERDICT_SAME);
	bsim_compare_free(&c);
}

/* Too few trials to show anything: identical outcomes over 20 pairs are
 * inconclusive at +-0.05 (Tango's 90% interval is +-0.12), and equivalent
 * at +-0.15. */
static void test_inconclusive(void **state)
{
	(void)state;
	build();
	bsim_sweep_result small_a = {.n_groups = 1, .trials = 20, .trials_out = A, .groups = GA};
	bsim_sweep_result small_b = {.n_groups = 1, .trials = 20, .trials_out = B, .groups = GB};
	bsim_comparison c;
	bsim_error err;
	bsim_compare_rule rule = {0.05, 0.05, 0};
	assert_int_equal(bsim_compare_analyse(&small_a, &small_b, NULL, &rule, &c, &err), BSIM_OK);
	assert_int_equal(c.groups[0].verdict, BSIM_VERDICT_INCONCLUSIVE);
	assert_int_equal(c.n_disagree, 0);
	bsim_compare_free(&c);
	rule.margin = 0.15;
	assert_int_equal(bsim_compare_analyse(&small_a, &small_b, NULL, &rule, &c, &err), BSIM_OK);
	assert_int_equal(c.groups[0].verdict, BSIM_VERDICT_EQUIVALENT);
	bsim_compare_free(&c);
}

/* Separation quantiles by nearest rank over the separated pairs only; a
 * deterministic group contributes its one pair. */
static void test_separation_quantiles(void **state)
{
	(void)state;
	build();
	static double ts[G * N];
	for (int i = 0; i < G * N; i++)
		ts[i] = -1.0;
	for (int t = 0; t < 10; t++) /* group 0: 0.1 .. 1.0 s */
		ts[t] = 0.1 * (10 - t);
	for (int t = 0; t < N; t++) /* group 4: every copy separated at 2 s */
		ts[4 * N + t] = 2.0;
	bsim_comparison c;
	bsim_error err;
	bsim_compare_rule rule = {0.05, 0.05, 0};
	assert_int_equal(bsim_compare_analyse(&ra, &rb, ts, &rule, &c, &err), BSIM_OK);
	assert_int_equal(c.groups[0].separated, 10);
	assert_float_equal(c.groups[0].t_sep[0], 0.1, 1e-12);
	assert_float_equal(c.groups[0].t_sep[1], 0.5, 1e-12);
	assert_float_equal(c.groups[0].t_sep[2], 0.9, 1e-12);
	assert_int_equal(c.groups[1].separated, 0);
	assert_true(c.groups[1].t_sep[1] == -1.0);
	assert_int_equal(c.groups[4].separated, 1);
	assert_int_equal(c.separated, 11);
	bsim_compare_free(&c);
}

/* The Holm family by its definition: of the events whose cells occur, those
 * not a linear combination of the ones before (unstable, left, right,
 * side_exit, traversed, stuck) and the constant. Cells: bit 0 traversed
 * left, 1 right, 2 none, 3 side exit, 4 stuck, 5 unstable. */
static void test_family_by_hand(void **state)
{
	(void)state;
	enum { L = 1, R = 2, NONE = 4, X = 8, S = 16, U = 32 };
	const unsigned T = 1u << BSIM_EVENT_TRAVERSED, EL = 1u << BSIM_EVENT_LEFT,
	               ER = 1u << BSIM_EVENT_RIGHT, EX = 1u << BSIM_EVENT_SIDE_EXIT,
	               EU = 1u << BSIM_EVENT_UNSTABLE;
	assert_int_equal(bsim_compare_family(0), 0);
	assert_int_equal(bsim_compare_family(S), 0);      /* every trial stuck: nothing varies */
	assert_int_equal(bsim_compare_family(X | S), EX); /* stuck = 1 - side_exit */
	assert_int_equal(bsim_compare_family(L | R | S), EL | ER); /* traversed = left + right */
	assert_int_equal(bsim_compare_family(L | R | X), EL | ER); /* side_exit = 1 - both */
	assert_int_equal(bsim_compare_family(L | S), EL);          /* traversed = left */
	assert_int_equal(bsim_compare_family(L | R | NONE | S), EL | ER | T);
	assert_int_equal(bsim_compare_family(S | U), EU);
	assert_int_equal(bsim_compare_family(L | R | X | S | U), EU | EL | ER | EX);
	/* All six cells: five free probabilities. */
	assert_int_equal(bsim_compare_family(L | R | NONE | X | S | U), EU | T | EX | EL | ER);
}

/* Groups at the floor or the ceiling. Group 0: every trial stuck on both
 * sides (never traverses: the floor of traversed, left, right, side_exit,
 * unstable, the ceiling of stuck). Group 1: 3 of 100 traverse on A, 2 on B,
 * the rest stuck: still every event within 0.05 of 0 or 1. Both are
 * uninformative, not equivalent, and outside the Holm family but for
 * group 1's left. Group 2: as group 1, but half the trials leave by a
 * side: side exits are informative and equivalent, so the group is. */
static void test_uninformative(void **state)
{
	(void)state;
	enum { G3 = 3, N3 = 100 };
	static bsim_trial_result a[G3 * N3], b[G3 * N3];
	for (int i = 0; i < G3 * N3; i++)
		stuck(&a[i]);
	for (int t = 0; t < 3; t++)
		traversed(&a[N3 + t], BSIM_TYPE_LEFT), traversed(&a[2 * N3 + t], BSIM_TYPE_LEFT);
	memcpy(b, a, sizeof a);
	stuck(&b[N3 + 2]);
	stuck(&b[2 * N3 + 2]);
	for (int t = 50; t < N3; t++)
		a[2 * N3 + t].outcome = b[2 * N3 + t].outcome = BSIM_SIDE_EXIT;
	bsim_sweep_result x = {.n_groups = G3, .trials = N3, .trials_out = a};
	bsim_sweep_result y = {.n_groups = G3, .trials = N3, .trials_out = b};
	bsim_comparison c;
	bsim_error err;
	bsim_compare_rule rule = {0.05, 0.05, 0};
	assert_int_equal(bsim_compare_analyse(&x, &y, NULL, &rule, &c, &err), BSIM_OK);
	assert_int_equal(c.groups[0].verdict, BSIM_VERDICT_UNINFORMATIVE);
	assert_int_equal(c.groups[1].verdict, BSIM_VERDICT_UNINFORMATIVE);
	assert_int_equal(c.groups[2].verdict, BSIM_VERDICT_EQUIVALENT);
	assert_int_equal(c.count[BSIM_VERDICT_UNINFORMATIVE], 2);
	assert_int_equal(c.count[BSIM_VERDICT_EQUIVALENT], 1);
	assert_int_equal(c.n_disagree, 0);
	for (int e = 0; e < BSIM_N_EVENTS; e++) {
		assert_false(c.groups[0].ev[e].informative);
		assert_false(c.groups[1].ev[e].informative);
		/* the floor's equivalence is shown, and still says nothing */
		assert_true(c.groups[0].ev[e].equivalent);
	}
	assert_true(c.groups[2].ev[BSIM_EVENT_SIDE_EXIT].informative);
	assert_false(c.groups[2].ev[BSIM_EVENT_TRAVERSED].informative);
	/* Family: group 0 none; group 1 left (traversed = left, stuck = 1 -
	 * left); group 2 left and side_exit. */
	assert_int_equal(c.groups[0].family, 0);
	assert_int_equal(c.groups[1].family, 1u << BSIM_EVENT_LEFT);
	assert_int_equal(c.groups[2].family, 1u << BSIM_EVENT_LEFT | 1u << BSIM_EVENT_SIDE_EXIT);
	assert_int_equal(c.n_tests, 3);
	bsim_compare_free(&c);
}

/* A difference the redundant family missed: 7 of 100 pairs traverse (left)
 * on A and get stuck on B, the rest stuck on both; McNemar p = 2 (1/2)^7 =
 * 0.0156 for traversed, left and stuck alike. Holm over the old family of
 * all 6 events makes it 6 x 0.0156 = 0.094: not flagged. The family is
 * left alone (traversed = left, stuck = 1 - left, the rest never occur):
 * 0.0156 < 0.05 and 0.07 >= the margin, so the group disagrees. */
static void test_family_power(void **state)
{
	(void)state;
	enum { N1 = 100 };
	static bsim_trial_result a[N1], b[N1];
	for (int t = 0; t < N1; t++) {
		stuck(&a[t]);
		stuck(&b[t]);
	}
	for (int t = 0; t < 7; t++)
		traversed(&a[t], BSIM_TYPE_LEFT);
	bsim_sweep_result x = {.n_groups = 1, .trials = N1, .trials_out = a};
	bsim_sweep_result y = {.n_groups = 1, .trials = N1, .trials_out = b};
	bsim_comparison c;
	bsim_error err;
	bsim_compare_rule rule = {0.05, 0.05, 0};
	assert_int_equal(bsim_compare_analyse(&x, &y, NULL, &rule, &c, &err), BSIM_OK);
	double old[BSIM_N_EVENTS];
	for (int e = 0; e < BSIM_N_EVENTS; e++)
		old[e] = c.groups[0].ev[e].p_value;
	bsim_stats_holm(old, BSIM_N_EVENTS, old);
	assert_true(old[BSIM_EVENT_TRAVERSED] >= 0.05);
	assert_int_equal(c.n_tests, 1);
	assert_float_equal(c.groups[0].ev[BSIM_EVENT_LEFT].p_holm, 2.0 / 128.0, 1e-15);
	assert_true(c.groups[0].ev[BSIM_EVENT_LEFT].beyond);
	assert_int_equal(c.groups[0].verdict, BSIM_VERDICT_DISAGREE);
	bsim_compare_free(&c);
}

static void test_shape_mismatch(void **state)
{
	(void)state;
	bsim_sweep_result small = {.n_groups = 1, .trials = N, .trials_out = B};
	bsim_comparison c;
	bsim_error err;
	bsim_compare_rule rule = {0.05, 0.05, 0};
	assert_int_equal(bsim_compare_analyse(&ra, &small, NULL, &rule, &c, &err), BSIM_EINPUT);
	assert_non_null(strstr(err.msg, "cannot pair"));
}

/* Two trials that differ only in how far the body turned (a field of
 * trials.csv that files written before it lack) are identical unless both
 * sides know the turn: bsim_compare_known says so only when both results
 * have it. */
static void test_identical_turn(void **state)
{
	(void)state;
	bsim_trial_result a, b;
	traversed(&a, BSIM_TYPE_LEFT);
	b = a;
	assert_true(bsim_compare_identical(&a, &b, BSIM_COMPARE_LEDGER | BSIM_COMPARE_TURN));
	double *field[4] = {&b.heading_end, &b.angular_velocity_end, &b.turn_end, &b.turn_max};
	for (int k = 0; k < 4; k++) {
		b = a;
		*field[k] = 0.25; /* a field of b */
		assert_true(bsim_compare_identical(&a, &b, BSIM_COMPARE_LEDGER));
		assert_false(bsim_compare_identical(&a, &b, BSIM_COMPARE_TURN));
	}
	bsim_sweep_result x = {.has_ledger = 1, .has_turn = 1}, y = {.has_ledger = 1};
	assert_int_equal(bsim_compare_known(&x, &x), BSIM_COMPARE_LEDGER | BSIM_COMPARE_TURN);
	assert_int_equal(bsim_compare_known(&x, &y), BSIM_COMPARE_LEDGER);
	assert_int_equal(bsim_compare_known(&y, &x), BSIM_COMPARE_LEDGER);
}

/* ---- more than two sides ---------------------------------------------------- */

/* Whether trial r shows event e, written out here from the events'
 * definitions (beamsim/compare.h) rather than taken from the library. */
static int shows(const bsim_trial_result *r, int e)
{
	switch (e) {
	case BSIM_EVENT_TRAVERSED:
		return r->outcome == BSIM_TRAVERSED;
	case BSIM_EVENT_LEFT:
		return r->outcome == BSIM_TRAVERSED && r->type == BSIM_TYPE_LEFT;
	case BSIM_EVENT_RIGHT:
		return r->outcome == BSIM_TRAVERSED && r->type == BSIM_TYPE_RIGHT;
	case BSIM_EVENT_SIDE_EXIT:
		return r->outcome == BSIM_SIDE_EXIT;
	case BSIM_EVENT_STUCK:
		return r->outcome == BSIM_STUCK;
	default:
		return r->outcome == BSIM_UNSTABLE;
	}
}

/* The exact McNemar p-value from its definition: b ~ Binomial(b + c, 1/2),
 * two-sided, min(1, 2 P(X <= min(b, c))). */
static double mcnemar_by_hand(int b, int c)
{
	int m = b + c, k = b < c ? b : c;
	double tail = 0.0;
	for (int i = 0; i <= k; i++)
		tail += exp(lgamma(m + 1.0) - lgamma(i + 1.0) - lgamma(m - i + 1.0) - m * log(2.0));
	return m == 0 ? 1.0 : fmin(1.0, 2.0 * tail);
}

/* Holm's step-down adjustment from its definition: the i-th smallest of n
 * p-values times (n - i), the running maximum, at most 1. Quadratic, and
 * apart from bsim_stats_holm. */
static void holm_by_hand(const double *p, int n, double *adj)
{
	for (int i = 0; i < n; i++) {
		double worst = 0.0;
		/* adj_i = max over the p_j <= p_i (ties by index) of (n - rank_j) p_j */
		for (int j = 0; j < n; j++) {
			int rank = 0;
			for (int k = 0; k < n; k++)
				rank += p[k] < p[j] || (p[k] == p[j] && k < j);
			int before = p[j] < p[i] || (p[j] == p[i] && j <= i);
			if (before)
				worst = fmax(worst, fmin(1.0, (n - rank) * p[j]));
		}
		adj[i] = worst;
	}
}

enum { S3 = 3, G3 = 4, N3 = 120 };
static bsim_trial_result T3[S3][G3 * N3];

/* Three sides of four groups. Side 1 is side 0; side 2 is side 0 but for
 * group 1, where 60 of 120 pairs traverse on sides 0 and 1 and get stuck
 * on side 2 (side 2 is flipped), and group 2, where 5 trials of 120 are
 * flipped (too few to show). Group 3 flips sides 1 and 2 alike in 60
 * trials: side 0 is the one apart. Group 0 is alike everywhere. */
static void build_sides(void)
{
	for (int i = 0; i < G3 * N3; i++) {
		if (i % 3 == 2)
			stuck(&T3[0][i]);
		else
			traversed(&T3[0][i], i % 3 ? BSIM_TYPE_LEFT : BSIM_TYPE_RIGHT);
		T3[1][i] = T3[2][i] = T3[0][i];
	}
	for (int t = 0; t < 60; t++) {
		traversed(&T3[0][1 * N3 + 2 * t], BSIM_TYPE_LEFT);
		T3[1][1 * N3 + 2 * t] = T3[0][1 * N3 + 2 * t];
		stuck(&T3[2][1 * N3 + 2 * t]);
		traversed(&T3[0][3 * N3 + 2 * t], BSIM_TYPE_RIGHT);
		stuck(&T3[1][3 * N3 + 2 * t]);
		stuck(&T3[2][3 * N3 + 2 * t]);
	}
	for (int t = 0; t < 5; t++)
		stuck(&T3[2][2 * N3 + 3 * t]), traversed(&T3[0][2 * N3 + 3 * t], BSIM_TYPE_LEFT),
		        T3[1][2 * N3 + 3 * t] = T3[0][2 * N3 + 3 * t];
}

/* One Holm family over every pair's tests: each pair's family events'
 * McNemar p-values, computed here from the trials, adjusted together by
 * Holm's definition, are the p_holm of every pair; the family's size is
 * the sum of the pairs' family sizes, and every pair states it. */
static void test_sides_one_family(void **state)
{
	(void)state;
	build_sides();
	bsim_sweep_result r[S3];
	for (int s = 0; s < S3; s++)
		r[s] = (bsim_sweep_result){.n_groups = G3, .trials = N3, .trials_out = T3[s]};
	bsim_compare_sides c;
	bsim_error err;
	bsim_compare_rule rule = {0.05, 0.05, 0};
	assert_int_equal(bsim_compare_analyse_sides(r, S3, NULL, &rule, &c, &err), BSIM_OK);
	assert_int_equal(c.n_pairs, 3);
	static const int pairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};
	double p[3 * G3 * BSIM_N_EVENTS], adj[3 * G3 * BSIM_N_EVENTS];
	int at[3][G3][BSIM_N_EVENTS], n = 0;
	for (int k = 0; k < 3; k++) {
		assert_int_equal(c.pair[k][0], pairs[k][0]);
		assert_int_equal(c.pair[k][1], pairs[k][1]);
		const bsim_trial_result *a = T3[pairs[k][0]], *b = T3[pairs[k][1]];
		for (int g = 0; g < G3; g++) {
			unsigned cells = 0;
			for (int t = 0; t < N3; t++)
				for (int side = 0; side < 2; side++) {
					const bsim_trial_result *x =
					        side ? &b[g * N3 + t] : &a[g * N3 + t];
					cells |= x->outcome == BSIM_STUCK    ? 16u
					         : x->type == BSIM_TYPE_LEFT ? 1u
					                                     : 2u;
				}
			unsigned family = bsim_compare_family(cells);
			assert_int_equal(c.pairs[k].groups[g].family, family);
			for (int e = 0; e < BSIM_N_EVENTS; e++) {
				at[k][g][e] = -1;
				if (!(family >> e & 1u))
					continue;
				int only_a = 0, only_b = 0;
				for (int t = 0; t < N3; t++) {
					int x = shows(&a[g * N3 + t], e),
					    y = shows(&b[g * N3 + t], e);
					only_a += x && !y;
					only_b += !x && y;
				}
				at[k][g][e] = n;
				p[n++] = mcnemar_by_hand(only_a, only_b);
			}
		}
	}
	assert_int_equal(c.n_tests, n);
	holm_by_hand(p, n, adj);
	for (int k = 0; k < 3; k++) {
		assert_int_equal(c.pairs[k].n_tests, n);
		for (int g = 0; g < G3; g++)
			for (int e = 0; e < BSIM_N_EVENTS; e++)
				if (at[k][g][e] >= 0)
					assert_float_equal(c.pairs[k].groups[g].ev[e].p_holm,
					                   adj[at[k][g][e]],
					                   1e-12 * adj[at[k][g][e]]);
				else
					assert_true(isnan(c.pairs[k].groups[g].ev[e].p_holm));
	}
	bsim_compare_sides_free(&c);
}

/* The odd one out from constructed pairwise verdicts (pairs in the order
 * (0,1), (0,2), (1,2) for three sides; (0,1), (0,2), (0,3), (1,2), (1,3),
 * (2,3) for four). */
static void test_odd_one_out_rule(void **state)
{
	(void)state;
	/* all agree */
	assert_int_equal(bsim_compare_odd_one_out(3, (int[]){0, 0, 0}), BSIM_ODD_NONE);
	assert_int_equal(bsim_compare_odd_one_out(2, (int[]){0}), BSIM_ODD_NONE);
	/* one side flipped: it differs from both others, which agree */
	assert_int_equal(bsim_compare_odd_one_out(3, (int[]){1, 1, 0}), 0);
	assert_int_equal(bsim_compare_odd_one_out(3, (int[]){1, 0, 1}), 1);
	assert_int_equal(bsim_compare_odd_one_out(3, (int[]){0, 1, 1}), 2);
	assert_int_equal(bsim_compare_odd_one_out(4, (int[]){0, 0, 1, 0, 1, 1}), 3);
	/* two sides flipped alike among four: two against two, no single side */
	assert_int_equal(bsim_compare_odd_one_out(4, (int[]){0, 1, 1, 1, 1, 0}),
	                 BSIM_ODD_NO_SINGLE);
	/* side 0 differs from every other, but sides 1 and 2 differ too: the
	 * others do not agree among themselves */
	assert_int_equal(bsim_compare_odd_one_out(4, (int[]){1, 1, 1, 1, 0, 0}),
	                 BSIM_ODD_NO_SINGLE);
	/* a side that differs from one other only, or everything differing */
	assert_int_equal(bsim_compare_odd_one_out(3, (int[]){1, 0, 0}), BSIM_ODD_NO_SINGLE);
	assert_int_equal(bsim_compare_odd_one_out(3, (int[]){1, 1, 1}), BSIM_ODD_NO_SINGLE);
	/* two sides that differ: either could be the odd one */
	assert_int_equal(bsim_compare_odd_one_out(2, (int[]){1}), BSIM_ODD_NO_SINGLE);
}

/* The odd one out of constructed outcomes (build_sides): group 1's
 * flipped side 2, group 3's side 0 (sides 1 and 2 flipped alike agree),
 * none in group 0 (all alike) and group 2 (too few flips to show). Four
 * sides, the fourth a copy of side 0: in group 3 two sides against two, no
 * single side; in group 1 side 2 still. A group's verdict is its least
 * agreeing pair's. */
static void test_odd_one_out_flipped(void **state)
{
	(void)state;
	build_sides();
	bsim_sweep_result r[4];
	for (int s = 0; s < 4; s++)
		r[s] = (bsim_sweep_result){
		        .n_groups = G3, .trials = N3, .trials_out = T3[s < S3 ? s : 0]};
	bsim_compare_sides c;
	bsim_error err;
	bsim_compare_rule rule = {0.05, 0.05, 0};
	assert_int_equal(bsim_compare_analyse_sides(r, 3, NULL, &rule, &c, &err), BSIM_OK);
	assert_int_equal(c.odd[0], BSIM_ODD_NONE);
	assert_int_equal(c.odd[1], 2);
	assert_int_equal(c.odd[2], BSIM_ODD_NONE);
	assert_int_equal(c.odd[3], 0);
	assert_int_equal(c.verdict[1], BSIM_VERDICT_DISAGREE);
	assert_int_equal(c.pairs[0].groups[1].verdict, BSIM_VERDICT_EQUIVALENT);
	assert_int_equal(c.n_disagree, 2);
	for (int g = 0; g < G3; g++) {
		bsim_verdict worst = BSIM_VERDICT_SAME;
		for (int k = 0; k < c.n_pairs; k++)
			if (c.pairs[k].groups[g].verdict > worst)
				worst = c.pairs[k].groups[g].verdict;
		assert_int_equal(c.verdict[g], worst);
	}
	bsim_compare_sides_free(&c);
	assert_int_equal(bsim_compare_analyse_sides(r, 4, NULL, &rule, &c, &err), BSIM_OK);
	assert_int_equal(c.n_pairs, 6);
	assert_int_equal(c.odd[1], 2);
	assert_int_equal(c.odd[3], BSIM_ODD_NO_SINGLE);
	assert_int_equal(c.odd[0], BSIM_ODD_NONE);
	bsim_compare_sides_free(&c);
	/* two sides: the pair disagrees in groups 1 and 3, no single side */
	assert_int_equal(bsim_compare_analyse_sides(r + 1, 2, NULL, &rule, &c, &err), BSIM_OK);
	assert_int_equal(c.odd[1], BSIM_ODD_NO_SINGLE);
	assert_int_equal(c.odd[0], BSIM_ODD_NONE);
	bsim_compare_sides_free(&c);
	assert_int_equal(bsim_compare_analyse_sides(r, 9, NULL, &rule, &c, &err), BSIM_EINPUT);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_verdicts),
	        cmocka_unit_test(test_rule_knobs),
	        cmocka_unit_test(test_inconclusive),
	        cmocka_unit_test(test_separation_quantiles),
	        cmocka_unit_test(test_shape_mismatch),
	        cmocka_unit_test(test_identical_turn),
	        cmocka_unit_test(test_family_by_hand),
	        cmocka_unit_test(test_uninformative),
	        cmocka_unit_test(test_family_power),
	        cmocka_unit_test(test_sides_one_family),
	        cmocka_unit_test(test_odd_one_out_rule),
	        cmocka_unit_test(test_odd_one_out_flipped),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
