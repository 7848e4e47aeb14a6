/* The paired comparison on trial outcomes built by hand, so the right
 * verdict is known: identical groups are "same", a few discordant pairs
 * are not evidence, a large one-sided difference is a disagreement, and
 * the margin and the exact rule act as documented. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "beamsim/compare.h"

enum { G = 4, N = 40 };

static bsim_trial_result A[G * N], B[G * N];
static bsim_sweep_result ra = {.n_groups = G, .trials = N, .trials_out = A};
static bsim_sweep_result rb = {.n_groups = G, .trials = N, .trials_out = B};

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

/* Group 0: identical. Group 1: 3 pairs traversed on A only (not evidence).
 * Group 2: 30 of 40 traversed on A, 2 on B. Group 3: same outcomes, one
 * trial's end position differs. */
static void build(void)
{
	for (int i = 0; i < G * N; i++) {
		traversed(&A[i], i % 2 ? BSIM_TYPE_LEFT : BSIM_TYPE_RIGHT);
		B[i] = A[i];
	}
	for (int t = 0; t < 3; t++)
		stuck(&B[1 * N + t]);
	for (int t = 0; t < N; t++) {
		if (t >= 30)
			stuck(&A[2 * N + t]);
		if (t >= 2)
			stuck(&B[2 * N + t]);
	}
	B[3 * N + 7].x_end = 1e-3;
}

static void test_verdicts(void **state)
{
	(void)state;
	build();
	bsim_comparison c;
	bsim_error err;
	bsim_compare_rule rule = {0.05, 0.05, 0};
	assert_int_equal(bsim_compare_analyse(&ra, &rb, NULL, &rule, &c, &err), BSIM_OK);
	assert_int_equal(c.groups[0].verdict, BSIM_VERDICT_SAME);
	assert_int_equal(c.groups[1].verdict, BSIM_VERDICT_AGREE);
	assert_int_equal(c.groups[2].verdict, BSIM_VERDICT_DISAGREE);
	assert_int_equal(c.groups[3].verdict, BSIM_VERDICT_SAME);
	assert_int_equal(c.n_disagree, 1);

	/* Group 2 by hand: 28 pairs traversed only on A, none only on B. */
	const bsim_event_test *t = &c.groups[2].ev[BSIM_EVENT_TRAVERSED];
	assert_int_equal(t->pairs.a, 2);
	assert_int_equal(t->pairs.b, 28);
	assert_int_equal(t->pairs.c, 0);
	assert_float_equal(t->p_a, 0.75, 1e-15);
	assert_float_equal(t->p_b, 0.05, 1e-15);
	assert_float_equal(t->diff, 0.7, 1e-15);
	assert_float_equal(t->p_value, bsim_mcnemar_exact(28, 0), 1e-300);
	assert_true(t->p_holm >= t->p_value && t->beyond);
	assert_int_equal(c.groups[2].ev[BSIM_EVENT_STUCK].pairs.c, 28);
	assert_int_equal(c.groups[1].discordant, 3);
	assert_int_equal(c.groups[3].changed, 1);
	assert_int_equal(c.groups[3].discordant, 0);
	bsim_comparison_free(&c);
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
	assert_int_equal(c.n_disagree, 0);
	bsim_comparison_free(&c);

	bsim_compare_rule exact = {0.05, 0.05, 1};
	assert_int_equal(bsim_compare_analyse(&ra, &rb, NULL, &exact, &c, &err), BSIM_OK);
	assert_int_equal(c.groups[3].verdict, BSIM_VERDICT_DISAGREE);
	assert_int_equal(c.groups[1].verdict, BSIM_VERDICT_DISAGREE);
	assert_int_equal(c.groups[0].verdict, BSIM_VERDICT_SAME);
	bsim_comparison_free(&c);
}

/* Separation quantiles by nearest rank over the separated pairs only. */
static void test_separation_quantiles(void **state)
{
	(void)state;
	build();
	static double ts[G * N];
	for (int i = 0; i < G * N; i++)
		ts[i] = -1.0;
	for (int t = 0; t < 10; t++) /* group 0: 0.1 .. 1.0 s */
		ts[t] = 0.1 * (10 - t);
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
	assert_int_equal(c.separated, 10);
	bsim_comparison_free(&c);
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
	        cmocka_unit_test(test_verdicts),
	        cmocka_unit_test(test_rule_knobs),
	        cmocka_unit_test(test_separation_quantiles),
	        cmocka_unit_test(test_shape_mismatch),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
