/* The paired comparison on trial outcomes built by hand, so the right
 * verdict is known: identical groups and a few discordant pairs are shown
 * equivalent when there are enough trials and inconclusive when there are
 * not, a large one-sided difference is a disagreement, a deterministic
 * group is one pair (same or different) outside the Holm family, and the
 * margin and the exact rule act as documented. */
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

	/* Deterministic groups: one pair, outside the Holm family of 4 random
	 * groups x 6 events, no p-value. */
	assert_int_equal(c.n_tests, 4 * BSIM_N_EVENTS);
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
	assert_true(t->p_holm >= t->p_value && t->beyond && !t->equivalent);
	assert_int_equal(c.groups[2].ev[BSIM_EVENT_STUCK].pairs.c, 140);
	assert_int_equal(c.groups[1].discordant, 3);
	assert_int_equal(c.groups[3].changed, 1);
	assert_int_equal(c.groups[3].discordant, 0);

	/* Detectable by hand: 24 tests at 0.05 need p < 2.08e-3; a one-way
	 * split of m pairs gives 2 (1/2)^m: 3.9e-3 for 9, 1.95e-3 for 10, so
	 * with no discordant pair the smallest flaggable difference is 10 of
	 * 200 pairs. */
	double level = 0.05 / 24.0;
	int fewest = 1;
	while (2.0 * pow(0.5, fewest) >= level)
		fewest++;
	assert_int_equal(fewest, 10);
	assert_float_equal(c.groups[0].ev[BSIM_EVENT_TRAVERSED].detectable, fewest / 200.0, 1e-15);
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

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_verdicts),       cmocka_unit_test(test_rule_knobs),
	        cmocka_unit_test(test_inconclusive),   cmocka_unit_test(test_separation_quantiles),
	        cmocka_unit_test(test_shape_mismatch),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
