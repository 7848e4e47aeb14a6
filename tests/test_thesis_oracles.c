/* The thesis backend's own checks, of what the essay's solver promises
 * beyond the checks every backend runs (test_impact, test_free_vibration,
 * test_mirror, ...): its knobs and the exactness of its integrator.
 *   - impact_order=simultaneous: the body on the midline meets both tips
 *     at once and the two impulses mirror each other to the bit;
 *   - impact_mass (essay Eq. 2.4 read literally) against Eqs. 2.4-2.5
 *     solved by hand, and the default's identity to the bit;
 *   - the implicit midpoint update of a beam: stable and non-expansive for
 *     stiff springs (omega_n h up to 4), the undamped energy kept to
 *     round-off (check 2's stability claim for this integrator). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>

#include <cmocka.h>

#include "backend_run.h"
#include "scenes.h"
#include "support.h"

static const double h = 0.004;
static const bsim_backend *thesis;

static int setup(void **state)
{
	(void)state;
	thesis = bsim_test_backend("thesis");
	return 0;
}

/* The body on the midline meets both tips at once: both beams take the same
 * impulse and the lateral velocity stays exactly zero; offsets of +-1e-6 m
 * give mirrored results and a lateral velocity of the order of the offset.
 * Off the midline one beam is met just inside its tip (a tangent contact)
 * and the other just past it (a tip contact); the model gives these
 * different restitutions, so the results are continuous in the offset only
 * when tip_restitution = restitution. */
static void run_midline(double offset, double e_tip, bsim_state *st)
{
	bsim_scene s;
	scene_gate_quiet(&s);
	s.contact.tip_restitution = e_tip;
	s.body.start[0] = offset;
	s.body.start[1] = 19.99;
	s.body.velocity[1] = 5.0;
	bsim_world *w = NULL;
	bsim_error err;
	assert_int_equal(thesis->create(&s, NULL, &w, &err), BSIM_OK);
	const double zero[2] = {0.0, 0.0};
	int impacts = 0;
	for (int n = 0; n < 40; n++) {
		assert_int_equal(bsim_backend_step(thesis, w, zero, 0.0, h, NULL), BSIM_OK);
		thesis->get_state(w, st);
		impacts += st->impacts;
	}
	assert_true(impacts >= 2);
	thesis->destroy(w);
	bsim_scene_free(&s);
}

static void test_simultaneous_double_impact(void **state)
{
	(void)state;
	bsim_state c, l, r;
	bsim_state_init(&c, 2);
	bsim_state_init(&l, 2);
	bsim_state_init(&r, 2);
	for (int same_e = 0; same_e < 2; same_e++) {
		double e_tip = same_e ? 0.8 : 1.0;
		run_midline(0.0, e_tip, &c);
		run_midline(-1e-6, e_tip, &l);
		run_midline(1e-6, e_tip, &r);
		assert_true(c.v[0] == 0.0 && c.x[0] == 0.0);
		assert_true(c.theta[0] == c.theta[1] && c.omega[0] == c.omega[1]);
		assert_true(c.theta[0] > 0.0);
		assert_true(l.v[0] == -r.v[0] && l.x[0] == -r.x[0]);
		assert_true(l.theta[0] == r.theta[1] && l.theta[1] == r.theta[0]);
		assert_true(fabs(r.v[0]) < 1e-6);
		if (same_e) {
			assert_true(fabs(r.theta[0] - c.theta[0]) < 1e-6);
			assert_true(fabs(r.v[1] - c.v[1]) < 1e-6);
		}
	}
	bsim_state_free(&c);
	bsim_state_free(&l);
	bsim_state_free(&r);
}

/* Steps the world once with no force under opts. */
static void step_once_with(const bsim_scene *s, const bsim_options *opts, bsim_state *st)
{
	bsim_world *w = NULL;
	bsim_error err;
	assert_int_equal(thesis->create(s, opts, &w, &err), BSIM_OK);
	const double zero[2] = {0.0, 0.0};
	assert_int_equal(bsim_backend_step(thesis, w, zero, 0.0, h, NULL), BSIM_OK);
	thesis->get_state(w, st);
	thesis->destroy(w);
}

/* impact_mass = m: a body of speed u meets the beam at rest square-on at
 * lever r. Essay Eq. 2.4 with the beam's mass m and Eq. 2.5 (omega_i = 0,
 * v_ni = u) are two linear equations in v_nf and omega_f:
 *   m r v_nf + I omega_f = m r u
 *   -v_nf + r omega_f   = e u
 * whose determinant is m r^2 + I, so (Cramer)
 *   v_nf = u (m r^2 - e I) / (m r^2 + I),  omega_f = (1 + e) m r u / (m r^2 + I). */
static void check_eq24_literal(double m, double r, double e, double u)
{
	bsim_scene s;
	scene_one_beam(&s);
	s.contact.restitution = e;
	s.body.start[0] = r;
	s.body.start[1] = -s.body.radius - 1e-9;
	s.body.velocity[1] = u;
	bsim_options opts = {0};
	char kv[64];
	snprintf(kv, sizeof kv, "impact_mass=%.17g", m);
	assert_int_equal(bsim_options_add(&opts, kv, NULL), BSIM_OK);
	bsim_state st;
	bsim_state_init(&st, 1);
	step_once_with(&s, &opts, &st);

	double inertia = s.beams[0].inertia, det = m * r * r + inertia;
	double v_nf = u * (m * r * r - e * inertia) / det;
	double omega_f = (1.0 + e) * m * r * u / det;
	double tol = 1e-12 * u;
	assert_true(fabs(st.v[1] - v_nf) <= tol);
	assert_true(fabs(st.v[0]) <= tol);
	assert_true(fabs(st.omega[0] - omega_f) <= tol / r);
	assert_int_equal(st.impacts, 1);
	/* the ledger's impact term is the kinetic energy (with the body's
	 * mass M) the impact removed */
	double ke0 = 0.5 * s.body.mass * u * u;
	double ke1 = 0.5 * s.body.mass * v_nf * v_nf + 0.5 * inertia * omega_f * omega_f;
	assert_true(fabs(st.energy.impact - (ke0 - ke1)) <= 1e-11 * ke0);
	bsim_state_free(&st);
	bsim_scene_free(&s);
}

static void test_impact_mass_eq24(void **state)
{
	(void)state;
	/* r = 25, m = 0.1: m r^2 / I = 3, so v_nf = 0.55 u (M would keep
	 * 0.942 u) and omega_f r = 1.35 u */
	check_eq24_literal(0.1, 24.999, 0.8, 1.0);
	check_eq24_literal(0.1, 10.0, 0.8, 3.0);
	check_eq24_literal(0.1, 20.0, 1.0, 2.0);
	check_eq24_literal(0.1, 5.0, 0.5, 1.5);
	double det = 0.1 * 625.0 + 0.1 * 625.0 / 3.0;
	assert_true(fabs((0.1 * 625.0 - 0.8 * 0.1 * 625.0 / 3.0) / det - 0.55) < 1e-12);
	assert_true(fabs(1.8 * 0.1 * 625.0 / det - 1.35) < 1e-12);
}

/* impact_mass equal to the body's mass is the default, bit for bit: the
 * same states over a run through the gate with impacts on both beams and
 * persistent contact; 0 and negative masses are refused. */
static void test_impact_mass_identity(void **state)
{
	(void)state;
	bsim_scene s;
	scene_gate_quiet(&s);
	s.body.start[0] = 3.0;
	s.body.start[1] = -40.0;
	s.body.velocity[1] = 6.0;
	bsim_options opts = {0};
	char kv[64];
	snprintf(kv, sizeof kv, "impact_mass=%.17g", s.body.mass);
	assert_int_equal(bsim_options_add(&opts, kv, NULL), BSIM_OK);
	bsim_world *a = NULL, *b = NULL;
	bsim_error err;
	assert_int_equal(thesis->create(&s, NULL, &a, &err), BSIM_OK);
	assert_int_equal(thesis->create(&s, &opts, &b, &err), BSIM_OK);
	bsim_state sa, sb;
	bsim_state_init(&sa, 2);
	bsim_state_init(&sb, 2);
	const double force[2] = {1.5, 8.0};
	int impacts = 0;
	for (int n = 0; n < 3000; n++) {
		assert_int_equal(bsim_backend_step(thesis, a, force, 0.0, h, NULL), BSIM_OK);
		assert_int_equal(bsim_backend_step(thesis, b, force, 0.0, h, NULL), BSIM_OK);
		thesis->get_state(a, &sa);
		thesis->get_state(b, &sb);
		assert_memory_equal(sa.x, sb.x, sizeof sa.x);
		assert_memory_equal(sa.v, sb.v, sizeof sa.v);
		assert_memory_equal(sa.theta, sb.theta, 2 * sizeof *sa.theta);
		assert_memory_equal(sa.omega, sb.omega, 2 * sizeof *sa.omega);
		assert_memory_equal(&sa.energy, &sb.energy, sizeof sa.energy);
		assert_int_equal(sa.impacts, sb.impacts);
		impacts += sa.impacts;
	}
	assert_true(impacts >= 2);
	thesis->destroy(a);
	thesis->destroy(b);
	bsim_state_free(&sa);
	bsim_state_free(&sb);

	static const char *const bad[] = {"impact_mass=0", "impact_mass=-0.1"};
	for (int i = 0; i < 2; i++) {
		bsim_options o = {0};
		assert_int_equal(bsim_options_add(&o, bad[i], NULL), BSIM_OK);
		bsim_world *w = NULL;
		assert_int_equal(thesis->create(&s, &o, &w, &err), BSIM_EINPUT);
		assert_null(w);
	}
	bsim_scene_free(&s);
}

/* omega_n h from 0.05 to 4: no growth of the beam's energy, with and without
 * the damper; the undamped energy is kept to round-off. */
static void test_stiff_spring_stable(void **state)
{
	(void)state;
	const double wh[] = {0.05, 0.5, 2.0, 4.0};
	for (int damped = 0; damped < 2; damped++) {
		for (size_t c = 0; c < sizeof wh / sizeof wh[0]; c++) {
			const double inertia = 0.1 * 625.0 / 3.0; /* scene_one_beam's beam */
			double k = inertia * (wh[c] / h) * (wh[c] / h);
			bsim_scene s;
			bsim_world *w = test_beam_released(
			        thesis, &s, k, damped ? 2.0 * 0.05 * sqrt(k * inertia) : 0.0, 0.2,
			        0.0);
			assert_true(s.beams[0].inertia == inertia);
			bsim_state st;
			bsim_state_init(&st, 1);
			const double zero[2] = {0.0, 0.0};
			double e0 = 0.5 * k * 0.04, e_prev = e0;
			for (int n = 0; n < 5000; n++) {
				assert_int_equal(bsim_backend_step(thesis, w, zero, 0.0, h, NULL),
				                 BSIM_OK);
				thesis->get_state(w, &st);
				double e = 0.5 * k * st.theta[0] * st.theta[0] +
				           0.5 * inertia * st.omega[0] * st.omega[0];
				assert_true(isfinite(e));
				assert_true(e <= e_prev * (1.0 + 1e-12) + 1e-300);
				e_prev = e;
			}
			if (!damped)
				assert_true(fabs(e_prev - e0) <= 1e-10 * e0);
			bsim_state_free(&st);
			thesis->destroy(w);
			bsim_scene_free(&s);
		}
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_simultaneous_double_impact),
	        cmocka_unit_test(test_impact_mass_eq24),
	        cmocka_unit_test(test_impact_mass_identity),
	        cmocka_unit_test(test_stiff_spring_stable),
	};
	return cmocka_run_group_tests(tests, setup, NULL);
}
