/* The time to leave the gate and the escape-rate fit against independent
 * truths: the Kaplan-Meier estimate and Greenwood's variance of a small
 * set of event and censoring times computed by hand, both from the
 * estimator and from the survival.csv the sweep's counter writes; the
 * estimate of exponential event times against exp(-k t) within its own
 * interval, and the maximum-likelihood rate against k; the
 * Arrhenius/Kramers line recovered from synthetic rates, exactly without
 * noise and within its standard errors with Poisson noise; the time the
 * essay's body first reaches the beams against sqrt(2 M d / F). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>

#include "analysis/escape.h"
#include "beamsim/beamsim.h"
#include "store/survival_files.h"
#include "util/csv_table.h"
#include "util/survival.h"
#include "support.h"

/* Six trials: events at 1 s; at 2 s one event and one censored; two events
 * at 3 s; one censored at 5 s. By hand:
 *   S(1) = 5/6, S(2) = 5/6 * 4/5 = 2/3, S(3) = 2/3 * (1 - 2/3) = 2/9;
 *   Greenwood at 3: 1/(6*5) + 1/(5*4) + 2/(3*1) = 3/4. */
static void test_km_by_hand(void **state)
{
	(void)state;
	survival_km k;
	bsim_survival_km_start(&k, 6);
	bsim_survival_km_step(&k, 1, 0);
	assert_true(fabs(k.s - 5.0 / 6.0) < 1e-15);
	assert_int_equal(k.at_risk, 5);
	bsim_survival_km_step(&k, 1, 1);
	assert_true(fabs(k.s - 2.0 / 3.0) < 1e-15);
	assert_int_equal(k.at_risk, 3);
	bsim_survival_km_step(&k, 2, 0);
	assert_true(fabs(k.s - 2.0 / 9.0) < 1e-15);
	assert_true(fabs(k.greenwood - 0.75) < 1e-15);
	/* the log-log interval: S^exp(-+z sqrt(G) / |ln S|) */
	double lo, hi, sig = sqrt(0.75) / fabs(log(2.0 / 9.0));
	bsim_survival_km_interval(&k, 1.959963984540054, &lo, &hi);
	assert_true(fabs(lo - pow(2.0 / 9.0, exp(1.959963984540054 * sig))) < 1e-14);
	assert_true(fabs(hi - pow(2.0 / 9.0, exp(-1.959963984540054 * sig))) < 1e-14);
	assert_true(lo < 2.0 / 9.0 && 2.0 / 9.0 < hi);
	bsim_survival_km_step(&k, 0, 1);
	assert_true(fabs(k.s - 2.0 / 9.0) < 1e-15);
	assert_int_equal(k.at_risk, 0);
	/* S = 1 and S = 0 are points */
	bsim_survival_km_start(&k, 3);
	bsim_survival_km_interval(&k, 1.96, &lo, &hi);
	assert_true(lo == 1.0 && hi == 1.0);
	bsim_survival_km_step(&k, 3, 0);
	bsim_survival_km_interval(&k, 1.96, &lo, &hi);
	assert_true(k.s == 0.0 && lo == 0.0 && hi == 0.0);
}

/* The same six trials through the sweep's counter and survival.csv /
 * horizon.csv (dt 0.5 s, horizon 10 steps = 5 s: the censored one is
 * stuck at the horizon, the one at 2 s unstable). */
static void test_km_file(void **state)
{
	(void)state;
	survival_group g = {.dt = 0.5, .max_steps = 10, .width = 1, .n_bins = 11};
	g.count = calloc((size_t)g.n_bins * SURV_KINDS, sizeof *g.count);
	survival_acc a = {.n_groups = 1, .g = &g};
	const struct {
		bsim_outcome o;
		int steps;
	} trials[6] = {{BSIM_TRAVERSED, 2}, {BSIM_SIDE_EXIT, 4}, {BSIM_UNSTABLE, 4},
	               {BSIM_TRAVERSED, 6}, {BSIM_SIDE_EXIT, 6}, {BSIM_STUCK, 10}};
	bsim_trial_result r[6];
	memset(r, 0, sizeof r);
	for (int i = 0; i < 6; i++) {
		r[i].outcome = trials[i].o;
		r[i].steps = trials[i].steps;
		r[i].t_end = trials[i].steps * 0.5;
	}
	assert_true(bsim_survival_exit_time(&r[0]) == 1.0);
	assert_true(isnan(bsim_survival_exit_time(&r[2])) && isnan(bsim_survival_exit_time(&r[5])));
	bsim_survival_acc_add(&a, 0, 6, 6, r);
	const char *dir = bsim_test_dir("survival_file");
	bsim_error err;
	if (bsim_survival_acc_write(&a, dir, &err) != BSIM_OK)
		fail_msg("%s", err.msg);
	free(g.count);
	csv_table t;
	if (bsim_csv_table_read(bsim_test_join(dir, "survival.csv"), &t, &err) != BSIM_OK)
		fail_msg("%s", err.msg);
	/* t = 0, 1, 2, 3, 5 */
	assert_int_equal(t.n_rows, 5);
	const double want[5][4] = {{0, 6, 0, 1},
	                           {1, 6, 1, 5.0 / 6},
	                           {2, 5, 1, 2.0 / 3},
	                           {3, 3, 2, 2.0 / 9},
	                           {5, 1, 0, 2.0 / 9}};
	const char *cols[4] = {"t", "at_risk", "events", "survival"};
	for (int row = 0; row < 5; row++)
		for (int c = 0; c < 4; c++) {
			double v;
			assert_int_equal(
			        bsim_csv_table_number(&t, row, bsim_csv_table_col(&t, cols[c]), &v),
			        0);
			assert_true(fabs(v - want[row][c]) < 1e-9);
		}
	bsim_csv_table_free(&t);
	/* horizon.csv at 5 s: 2 traversed, 2 side exits, 1 stuck (the
	 * unstable one is neither); at 2 s: 1 traversed, 1 side exit, 3 stuck */
	if (bsim_csv_table_read(bsim_test_join(dir, "horizon.csv"), &t, &err) != BSIM_OK)
		fail_msg("%s", err.msg);
	assert_int_equal(t.n_rows, 10);
	int ch = bsim_csv_table_col(&t, "h"), ct = bsim_csv_table_col(&t, "traversed"),
	    cs = bsim_csv_table_col(&t, "side_exit"), ck = bsim_csv_table_col(&t, "stuck");
	for (long row = 0; row < t.n_rows; row++) {
		double h, tr, se, st;
		bsim_csv_table_number(&t, row, ch, &h);
		bsim_csv_table_number(&t, row, ct, &tr);
		bsim_csv_table_number(&t, row, cs, &se);
		bsim_csv_table_number(&t, row, ck, &st);
		if (fabs(h - 5.0) < 1e-12)
			assert_true(tr == 2 && se == 2 && st == 1);
		if (fabs(h - 2.0) < 1e-12)
			assert_true(tr == 1 && se == 1 && st == 3);
		if (fabs(h - 0.5) < 1e-12)
			assert_true(tr == 0 && se == 0 && st == 6);
	}
	bsim_csv_table_free(&t);
}

/* 20,000 exponential times of rate k = 0.5 /s, censored at 4 s: the
 * estimate lies within 4 of its Greenwood standard errors of exp(-k t) at
 * every event time, and the rate's 95% interval holds k. */
static void test_km_exponential(void **state)
{
	(void)state;
	const int n = 20000;
	const double k = 0.5, horizon = 4.0, h = 0.001;
	gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
	gsl_rng_set(rng, 7);
	/* times on a 1 ms grid, as the sweep's steps */
	const int bins = (int)(horizon / h) + 1;
	long *d = calloc((size_t)bins, sizeof *d), *c = calloc((size_t)bins, sizeof *c);
	long events = 0;
	double exposure = 0.0;
	for (int i = 0; i < n; i++) {
		double t = gsl_ran_exponential(rng, 1.0 / k);
		long b = (long)ceil(t / h);
		if (b >= bins - 1) {
			c[bins - 1]++;
			exposure += horizon;
		} else {
			d[b]++;
			events++;
			exposure += b * h;
		}
	}
	survival_km km;
	bsim_survival_km_start(&km, n);
	double worst = 0.0;
	for (int b = 0; b < bins; b++) {
		bsim_survival_km_step(&km, d[b], c[b]);
		if (d[b] == 0 || km.s <= 0.0)
			continue;
		double se = km.s * sqrt(km.greenwood);
		double z = fabs(km.s - exp(-k * b * h)) / se;
		worst = z > worst ? z : worst;
	}
	assert_true(worst < 4.0);
	double rate, lo, hi;
	bsim_survival_rate(events, exposure, &rate, &lo, &hi);
	assert_true(lo < k && k < hi);
	assert_true(fabs(rate - k) < 0.02);
	bsim_survival_rate(0, 10.0, &rate, &lo, &hi);
	/* no event in 10 s: [0, -ln(0.025) / 10] */
	assert_true(rate == 0.0 && lo == 0.0 && fabs(hi + log(0.025) / 10.0) < 1e-9);
	free(d);
	free(c);
	gsl_rng_free(rng);
}

/* ln k = ln k0 - x / c with k0 = 3 /s, c = 0.25: exact rates give the line
 * to round-off; Poisson counts at exposure T give it within 3 standard
 * errors, and the Poisson chi-square is not extreme. */
static void test_kramers_fit(void **state)
{
	(void)state;
	enum { N = 12 };
	const double k0 = 3.0, c = 0.25;
	double x[N], y[N], w[N];
	for (int i = 0; i < N; i++) {
		x[i] = 0.1 + 0.1 * i;
		y[i] = log(k0) - x[i] / c;
		w[i] = 1.0;
	}
	escape_fit f;
	bsim_error err;
	assert_int_equal(bsim_escape_fit_line(x, y, w, N, &f, &err), BSIM_OK);
	assert_true(fabs(f.k0 - k0) < 1e-9 && fabs(f.c - c) < 1e-9 && f.rms < 1e-12);
	gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
	gsl_rng_set(rng, 11);
	const double T = 2000.0; /* s of exposure per group */
	for (int i = 0; i < N; i++) {
		unsigned d = gsl_ran_poisson(rng, k0 * exp(-x[i] / c) * T);
		y[i] = log(d / T);
		w[i] = d;
	}
	assert_int_equal(bsim_escape_fit_line(x, y, w, N, &f, &err), BSIM_OK);
	assert_true(fabs(f.a - log(k0)) < 3.0 * f.se_a);
	assert_true(fabs(f.b + 1.0 / c) < 3.0 * f.se_b);
	assert_true(fabs(f.c - c) < 3.0 * f.se_c);
	assert_true(f.p_poisson > 0.001);
	/* the verdict: Poisson rates on the line are consistent with it when
	 * the line explains them (R^2 >= 0.5); rates scattered by a factor
	 * e^N(0, 1) about a constant, with 10^4 events each, are rejected and
	 * explained by no line */
	print_message("on the line: R^2 %.3f, p %.3g: %s\n", f.r2, f.p_poisson,
	              bsim_escape_fit_verdict(&f));
	assert_true(f.r2 >= ESCAPE_R2_LITTLE && f.p_poisson >= ESCAPE_P_REJECT);
	assert_non_null(strstr(bsim_escape_fit_verdict(&f), "consistent"));
	for (int i = 0; i < N; i++) {
		y[i] = log(k0) + gsl_ran_ugaussian(rng);
		w[i] = 1e4;
	}
	assert_int_equal(bsim_escape_fit_line(x, y, w, N, &f, &err), BSIM_OK);
	print_message("scatter: R^2 %.3f, p %.3g: %s\n", f.r2, f.p_poisson,
	              bsim_escape_fit_verdict(&f));
	assert_true(f.p_poisson < ESCAPE_P_REJECT);
	assert_non_null(strstr(bsim_escape_fit_verdict(&f), f.r2 < ESCAPE_R2_LITTLE
	                                                            ? "do not describe these groups"
	                                                            : "are not their law"));
	/* under three points: no fit */
	assert_int_equal(bsim_escape_fit_line(x, y, w, 2, &f, &err), BSIM_EINPUT);
	gsl_rng_free(rng);
}

/* The essay's gate: the body's front meets the resting beams after 20 m,
 * at t = sqrt(2 M 20 / F). */
static void test_contact_time(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_error err;
	bsim_override o = {"effects.propulsion.force", "8", NULL};
	if (bsim_scene_load(bsim_test_src("configs/thesis/gate.yaml"), &o, 1, &s, &err))
		fail_msg("%s", err.msg);
	assert_true(fabs(bsim_escape_contact_time(&s) - sqrt(5.0)) < 1e-3);
	bsim_scene_free(&s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_km_by_hand),     cmocka_unit_test(test_km_file),
	        cmocka_unit_test(test_km_exponential), cmocka_unit_test(test_kramers_fit),
	        cmocka_unit_test(test_contact_time),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
