/* The Chipmunk2D backend's own checks: docs/model.md section 10 under its
 * knob substeps, which the checks every backend runs with the default
 * options do not reach (test_impact, test_free_vibration,
 * test_energy_ledger, test_mirror, ...: its bounds there are in its table,
 * backends/chipmunk/chipmunk_world.c), and what only it has: its explicit
 * spring's limit, which create refuses, the version it states, reset and
 * set_state, its options' checks, the ellipse's polygon and its refusal
 * unless ellipse=polygon (impact_ellipse_refusal), and a motion beyond what
 * Chipmunk steps. Each measured value is printed so a change shows.
 *   1 free vibration:  substeps=4 against the analytic damped oscillator
 *                      (error, decay rate, period)
 *   2 stiff springs:   bounded below the explicit spring's limit, refused
 *                      at it, taken with the substeps the refusal names
 *   3 energy ledger:   substeps=4 cuts the conservative drift and the
 *                      driven residual; the long conservative run keeps
 *                      its energy within 1% either way */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "beamsim/contact_flag.h"
#include "beamsim/schedule.h"
#include "beamsim/trial.h"
#include "chipmunk/chipmunk_world.h"
#include "backend_run.h"
#include "impact_oracle.h"
#include "scenes.h"
#include "support.h"

static const bsim_backend *cm;

static int setup(void **state)
{
	(void)state;
	cm = bsim_test_backend("chipmunk");
	return 0;
}

/* The version its table states (a constant, from the header's numbers) is
 * the library's own, cpVersionString, and the engine is Chipmunk2D. */
static void test_version(void **state)
{
	(void)state;
	print_message("chipmunk: %s %s, the library says %s\n", cm->engine, cm->version,
	              cpVersionString);
	assert_string_equal(cm->engine, "Chipmunk2D");
	assert_string_equal(cm->version, cpVersionString);
}

/* ---- 1. free vibration ----------------------------------------------------- */

/* The essay's beam released from 0.1 rad at h = 4 ms, at the defaults and
 * with substeps=4 (Chipmunk's steps of h/4): the decay rate and period
 * within 0.5% of the oscillator's (measured -0.00% and +0.26% at the
 * defaults: its damper's decay is exact), the error cut by more than 3
 * (first order: measured 8.9e-4 and 2.2e-4 rad). */
static void test_substeps_vibration(void **state)
{
	(void)state;
	vibration v4 = beam_vibration(cm, NULL, 0.004, 0.0);
	vibration sub = beam_vibration(cm, "substeps=4", 0.004, 0.0);
	print_message("chipmunk free vibration at h = 4 ms: max error %.3g rad, decay rate "
	              "%+.2f%%, period %+.2f%%; substeps=4: %.3g rad, %+.2f%%, %+.2f%%\n",
	              v4.worst, 100.0 * v4.rate_rel, 100.0 * v4.period_rel, sub.worst,
	              100.0 * sub.rate_rel, 100.0 * sub.period_rel);
	assert_true(fabs(v4.rate_rel) < 0.005 && fabs(v4.period_rel) < 0.005);
	assert_true(fabs(sub.rate_rel) < 0.005 && fabs(sub.period_rel) < 0.005);
	assert_true(sub.worst < 0.3 * v4.worst);
}

/* ---- 2. stiff springs ------------------------------------------------------ */

/* Undamped springs: Chipmunk's spring is symplectic Euler, its energy
 * bounded for omega_n h below 2 and oscillating by a factor that grows
 * with omega_n h; create refuses a spring at or beyond the bound (with the
 * damper's factor: sqrt(2 + 2 exp(d h / I))), naming the beam's stiffness
 * and the substeps that hold it, and takes it with those. */
static double stiff_energy_ratio(double wh, const char *opt)
{
	const double h = 0.004;
	bsim_scene s;
	scene_one_beam(&s);
	const double inertia = s.beams[0].inertia, k = inertia * (wh / h) * (wh / h);
	s.beams[0].stiffness = k;
	s.beams[0].initial_theta = 0.2;
	bsim_options o = test_options(opt, NULL);
	bsim_world *w = bsim_test_world(cm, &s, &o);
	bsim_state st;
	bsim_state_init(&st, 1);
	const double zero[2] = {0.0, 0.0}, e0 = 0.5 * k * 0.04;
	double e_max = 0.0;
	for (int n = 0; n < 2000; n++) {
		assert_int_equal(bsim_backend_step(cm, w, zero, 0.0, h, NULL), BSIM_OK);
		cm->get_state(w, &st);
		e_max = fmax(e_max, 0.5 * k * st.theta[0] * st.theta[0] +
		                            0.5 * inertia * st.omega[0] * st.omega[0]);
	}
	bsim_state_free(&st);
	cm->destroy(w);
	bsim_scene_free(&s);
	return e_max / e0;
}

static void test_stiff_spring(void **state)
{
	(void)state;
	const double r05 = stiff_energy_ratio(0.5, NULL), r15 = stiff_energy_ratio(1.5, NULL),
	             r19 = stiff_energy_ratio(1.9, NULL);
	const double r4 = stiff_energy_ratio(4.0, "substeps=3");
	print_message("chipmunk stiff spring, undamped: max E / E0 = %.3g, %.3g, %.3g at omega_n h "
	              "= 0.5, 1.5, 1.9; %.3g at 4 with substeps=3\n",
	              r05, r15, r19, r4);
	/* symplectic: bounded (measured 1.33, 4.0, 20; 4 / 3 = 1.33 a substep: 3.0) */
	assert_true(r05 <= 1.4 && r15 <= 4.5 && r19 <= 25.0 && r4 <= 3.5);

	bsim_scene s;
	scene_one_beam(&s);
	const double h = s.dt, inertia = s.beams[0].inertia;
	s.beams[0].stiffness = inertia * (2.01 / h) * (2.01 / h); /* omega_n h = 2.01 */
	bsim_world *w = NULL;
	bsim_error err;
	char field[64];
	assert_int_equal(cm->check(&s, NULL, field, sizeof field, &err), BSIM_EINPUT);
	print_message("refused: %s: %s\n", field, err.msg);
	assert_string_equal(field, "beams.0.stiffness");
	assert_non_null(strstr(err.msg, "substeps=2"));
	assert_int_equal(cm->create(&s, NULL, &w, &err), BSIM_EINPUT);
	assert_null(w);
	/* damped, the bound is higher: zeta = 0.5 at omega_n h = 2.2 holds */
	s.beams[0].stiffness = inertia * (2.2 / h) * (2.2 / h);
	s.beams[0].damping = 2.0 * 0.5 * inertia * (2.2 / h);
	assert_int_equal(cm->check(&s, NULL, field, sizeof field, &err), BSIM_OK);
	bsim_scene_free(&s);
}

/* ---- 3. energy ledger ----------------------------------------------------- */

/* e = 1, tip e = 1, d = 0, no forces: E is conserved up to the explicit
 * spring's splitting at each impact, O(h): substeps=4 cuts the drift by
 * more than 2 (measured +1.8e-3 and +3.7e-4 of E over 12 s; the default's
 * bound is test_energy_ledger's, "ledger.drift"). */
static void test_conservative_drift(void **state)
{
	(void)state;
	const char *opt[] = {NULL, "substeps=4"};
	double drift[2];
	for (int k = 0; k < 2; k++) {
		bsim_scene s;
		scene_gate_conservative(&s);
		bsim_options o = test_options(opt[k], NULL);
		bsim_trial_result out = test_trial(cm, &s, &o, 1);
		const bsim_ledger *l = &out.ledger;
		drift[k] = (l->e_end - l->e_start) / l->e_start;
		print_message("chipmunk conservative%s: E %.4f -> %.4f J (drift %.2e of E), impact "
		              "%.2e contact %.2e correction %.2e J, residual %.2e J, peak theta "
		              "%.3f\n",
		              opt[k] ? " substeps=4" : "", l->e_start, l->e_end, drift[k],
		              l->impact, l->contact, l->correction, l->residual,
		              fmax(out.max_theta[0], out.max_theta[1]));
		assert_true(fmax(out.max_theta[0], out.max_theta[1]) > 0.3);
		assert_true(l->w_prop == 0.0 && l->w_rand == 0.0 && l->damper == 0.0);
		bsim_scene_free(&s);
	}
	assert_true(fabs(drift[1]) <= 0.5 * fabs(drift[0]));
}

/* The essay's gate, driven, damped and noisy: the residual is the
 * integrator's (the force credited over a displacement made with the
 * velocity before it, the explicit spring), O(h): substeps=4 must cut it
 * (the default's bound is test_energy_ledger's, "ledger.residual"). */
static double ledger_ratio(const char *opt, double *abs_ratio)
{
	double worst = 0.0, worst_abs = 0.0;
	for (int trial = 0; trial < 10; trial++) {
		bsim_scene s;
		bsim_scene_init_gate(&s, 7.0, 20.0);
		bsim_options o = test_options(opt, NULL);
		bsim_trial_result out =
		        test_trial(cm, &s, &o, bsim_schedule_seed_mix(3, 0, (uint64_t)trial));
		const bsim_ledger *l = &out.ledger;
		double scale = fabs(l->w_prop) + fabs(l->w_rand) + l->damper + l->impact;
		assert_true(l->damper > 0.0 && l->w_prop > 0.0);
		assert_true(l->impact >= 0.0);
		assert_int_equal(out.instability, BSIM_STABLE);
		worst = fmax(worst, fabs(l->residual) / scale);
		worst_abs = fmax(worst_abs, l->residual_abs / scale);
		bsim_scene_free(&s);
	}
	*abs_ratio = worst_abs;
	return worst;
}

static void test_driven_damped_noisy(void **state)
{
	(void)state;
	double a1, a4;
	double r1 = ledger_ratio(NULL, &a1), r4 = ledger_ratio("substeps=4", &a4);
	print_message("chipmunk ledger, |residual| / throughput (sum of |r| / throughput), worst "
	              "of 10: %.2e (%.2e), substeps=4 %.2e (%.2e)\n",
	              r1, a1, r4, a4);
	/* measured 3.1e-2 (9.6e-2), 7.8e-3 (2.2e-2) */
	assert_true(a4 < 0.5 * a1);
}

/* The long conservative run of hard case 7 (configs/hard/conservative_long.yaml,
 * 100,000 steps), which test_hard_cases skips here: the check there allows
 * a solver only to lose energy, and Chipmunk's explicit spring neither
 * loses nor gains it on average, its energy oscillating about its value
 * (measured +0.54% at the end); impacts lose nothing. */
static void test_conservative_long(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_error err;
	int rc = bsim_scene_load(bsim_test_src("configs/hard/conservative_long.yaml"), NULL, 0, &s,
	                         &err);
	if (rc)
		print_message("%s\n", err.msg);
	assert_int_equal(rc, BSIM_OK);
	bsim_trial_result out = test_trial(cm, &s, NULL, 1);
	const bsim_ledger *l = &out.ledger;
	double drift = (l->e_end - l->e_start) / l->e_start;
	print_message("chipmunk conservative, %d steps: drift %+.3e of E, impact %.2e contact %.2e "
	              "correction %.2e J\n",
	              out.steps_run, drift, l->impact, l->contact, l->correction);
	assert_int_equal(out.steps_run, 100000);
	assert_true(fabs(drift) <= 0.01);
	assert_true(fabs(l->impact) + fabs(l->contact) <= 1e-6 * l->e_start);
	bsim_scene_free(&s);
}

/* ---- the interface -------------------------------------------------------- */

/* reset gives the world create made: the same steps give the same bits
 * (after a run through contact with both beams); set_state puts the bodies
 * where asked to the bit (the restart itself is test_set_state's, every
 * backend's). */
static void test_reset_and_set_state(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 7.0, 0.0);
	bsim_world *w = bsim_test_world(cm, &s, NULL), *w2 = bsim_test_world(cm, &s, NULL);
	bsim_state st, st2;
	bsim_state_init(&st, 2);
	bsim_state_init(&st2, 2);
	const double f[2] = {3.0, 7.0};
	bsim_error err;
	for (int round = 0; round < 2; round++) {
		for (int n = 0; n < 1500; n++)
			assert_int_equal(bsim_backend_step(cm, w, f, 0.0, s.dt, NULL), BSIM_OK);
		cm->get_state(w, round ? &st2 : &st);
		assert_int_equal(cm->reset(w, &s, &err), BSIM_OK);
	}
	assert_memory_equal(st.x, st2.x, sizeof st.x);
	assert_memory_equal(st.v, st2.v, sizeof st.v);
	assert_memory_equal(st.theta, st2.theta, 2 * sizeof *st.theta);
	assert_memory_equal(st.omega, st2.omega, 2 * sizeof *st.omega);
	assert_true(st.theta[0] != 0.0 && st.theta[1] != 0.0);
	/* a fixed number of iterations, nothing clamped: no solver counts */
	assert_int_equal(st.solver.iteration_limit + st.solver.clamped, 0);

	const double g[2] = {0.0, 7.0};
	for (int n = 0; n < 700; n++) /* into contact with both beams */
		assert_int_equal(bsim_backend_step(cm, w, g, 0.0, s.dt, NULL), BSIM_OK);
	cm->get_state(w, &st);
	bsim_contact_flags(&s, &st);
	assert_true(st.theta[0] > 0.05 && st.theta[1] > 0.05);
	assert_int_equal(cm->set_state(w2, &st, &err), BSIM_OK);
	cm->get_state(w2, &st2);
	bsim_contact_flags(&s, &st2);
	assert_memory_equal(st.x, st2.x, sizeof st.x);
	assert_memory_equal(st.theta, st2.theta, 2 * sizeof *st.theta);
	assert_memory_equal(st.omega, st2.omega, 2 * sizeof *st.omega);
	assert_int_equal(st2.contact[0], st.contact[0]);

	/* states Chipmunk would abort on are refused, naming the value */
	st2.v[0] = NAN;
	assert_int_equal(cm->set_state(w2, &st2, &err), BSIM_EINPUT);
	assert_non_null(strstr(err.msg, "vx"));
	st2.v[0] = 0.0;
	st2.omega[1] = 1e300;
	assert_int_equal(cm->set_state(w2, &st2, &err), BSIM_EINPUT);
	assert_non_null(strstr(err.msg, "omega2"));
	bsim_state_free(&st);
	bsim_state_free(&st2);
	cm->destroy(w);
	cm->destroy(w2);
	bsim_scene_free(&s);
}

/* A motion beyond what Chipmunk steps (1e100 in magnitude) stops the world
 * where it is, instead of Chipmunk aborting the process at its next step;
 * a scene Chipmunk would abort on is refused. */
static void test_motion_out_of_range(void **state)
{
	(void)state;
	bsim_scene s;
	scene_gate_quiet(&s);
	s.body.start[1] = -200.0;
	bsim_world *w = bsim_test_world(cm, &s, NULL);
	bsim_state st, st2;
	bsim_state_init(&st, 2);
	bsim_state_init(&st2, 2);
	cm->get_state(w, &st);
	st.v[1] = 9e99;
	bsim_error err;
	assert_int_equal(cm->set_state(w, &st, &err), BSIM_OK);
	const double f[2] = {0.0, 1e102}; /* a step of 4 ms: 4e99 m/s more */
	assert_int_equal(bsim_backend_step(cm, w, f, 0.0, s.dt, NULL), BSIM_OK);
	cm->get_state(w, &st);
	assert_true(st.v[1] >= 1e100);
	for (int n = 0; n < 3; n++)
		assert_int_equal(bsim_backend_step(cm, w, f, 0.0, s.dt, NULL), BSIM_OK);
	cm->get_state(w, &st2);
	assert_memory_equal(st.x, st2.x, sizeof st.x);
	assert_memory_equal(st.v, st2.v, sizeof st.v);
	bsim_state_free(&st);
	bsim_state_free(&st2);
	cm->destroy(w);

	/* a scene that starts there is refused, naming the field, and so are
	 * masses whose inverse (or 1e6 times which, the beams') is not finite:
	 * Chipmunk aborted on a body of 1e303 kg */
	s.body.velocity[0] = 2e100;
	char field[64];
	assert_int_equal(cm->check(&s, NULL, field, sizeof field, &err), BSIM_EINPUT);
	assert_string_equal(field, "body.velocity.0");
	s.body.velocity[0] = 0.0;
	const double masses[] = {1e303, 1e-310};
	for (int k = 0; k < 2; k++) {
		s.body.mass = masses[k];
		assert_int_equal(cm->check(&s, NULL, field, sizeof field, &err), BSIM_EINPUT);
		assert_string_equal(field, "body.mass");
	}
	s.body.mass = 1.0;
	s.beams[1].inertia = 1e-200;
	assert_int_equal(cm->check(&s, NULL, field, sizeof field, &err), BSIM_EINPUT);
	assert_string_equal(field, "beams.1.inertia");
	bsim_scene_free(&s);
}

static void test_bad_options(void **state)
{
	(void)state;
	bsim_scene s;
	scene_gate_quiet(&s);
	const char *bad[] = {"substeps=0",         "iterations=0",          "iterations=1001",
	                     "collision_slop=-1",  "collision_bias=1.5",    "collision_bias=-0.1",
	                     "collision_slop=inf", "velocity_iterations=8", "ellipse=circle"};
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
		bsim_options o = test_options(bad[i], NULL);
		bsim_world *w = NULL;
		bsim_error err;
		assert_int_equal(cm->create(&s, &o, &w, &err), BSIM_EINPUT);
		assert_null(w);
		assert_true(strlen(err.msg) > 0);
	}
	bsim_scene_free(&s);
}

/* An ellipse refused by default, and why (impact_ellipse_refusal). */
static void test_ellipse_refused(void **state)
{
	(void)state;
	impact_ellipse_refusal(cm);
}

/* The ellipse's polygon (a = 12.5 m, b = 8 m, 128 vertices) against the
 * ellipse: every vertex and every chord's midpoint within 2 mm of the
 * outline (a point with x^2/a^2 + y^2/b^2 = q is sqrt(q) times a point of
 * the ellipse, so at most |sqrt(q) - 1| a from it), the area within
 * 1.5e-4. */
static void test_ellipse_polygon(void **state)
{
	(void)state;
	const double a = 12.5, b = 8.0;
	enum { K = 128 };
	cpVect v[K];
	bsim_chipmunk_ellipse_polygon(a, b, K, v);
	double worst = 0.0, area = 0.0;
	for (int k = 0; k < K; k++) {
		const cpVect p = v[k], q = v[(k + 1) % K];
		const cpVect m = cpv(0.5 * (p.x + q.x), 0.5 * (p.y + q.y));
		for (int j = 0; j < 2; j++) {
			const cpVect x = j ? m : p;
			const double r = sqrt(x.x * x.x / (a * a) + x.y * x.y / (b * b));
			worst = fmax(worst, fabs(r - 1.0) * a);
		}
		area += 0.5 * (p.x * q.y - q.x * p.y);
	}
	const double area_rel = area / (3.14159265358979323846 * a * b) - 1.0;
	print_message("chipmunk ellipse polygon: outline within %.2e m, area %+.2e\n", worst,
	              area_rel);
	assert_true(worst <= 2e-3);            /* measured 1.88e-3 */
	assert_true(fabs(area_rel) <= 1.5e-4); /* measured -1.0e-4 */
}

/* The flat side's impact (test_impact's "impact.shape.flat") with
 * iterations=200: the default iterations stop short of the two points'
 * simultaneous solution, which more of them reach (measured 5.7e-16). */
static void test_flat_impact_iterations(void **state)
{
	(void)state;
	bsim_options o = test_options("iterations=200", NULL);
	bsim_body_def flat = impact_flat_capsule();
	double worst = impact_sweep(cm, &o, &flat, 1e-12).worst;
	print_message("chipmunk flat capsule impact (iterations=200): worst relative error %.2e\n",
	              worst);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_version),
	        cmocka_unit_test(test_substeps_vibration),
	        cmocka_unit_test(test_stiff_spring),
	        cmocka_unit_test(test_conservative_drift),
	        cmocka_unit_test(test_driven_damped_noisy),
	        cmocka_unit_test(test_conservative_long),
	        cmocka_unit_test(test_reset_and_set_state),
	        cmocka_unit_test(test_motion_out_of_range),
	        cmocka_unit_test(test_bad_options),
	        cmocka_unit_test(test_ellipse_polygon),
	        cmocka_unit_test(test_ellipse_refused),
	        cmocka_unit_test(test_flat_impact_iterations),
	};
	return cmocka_run_group_tests(tests, setup, NULL);
}
