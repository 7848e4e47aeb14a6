/* Impact chains settle into persistent contact (docs/model.md section 5): the
 * body pushed into the symmetric gate bounces with shrinking speed, switches
 * to persistent contact with both beams, and comes to rest where the push
 * balances the springs, at the point the potential energy landscape
 * (section 7) predicts; penetration never exceeds the projection's slop,
 * 1e-6 m. The coupled body-beam mode is lightly damped (zeta ~ 0.08 about
 * the rest point), hence the long run. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>

#include <cmocka.h>

#include "beamsim/contact_flag.h"
#include "beamsim/backend.h"
#include "scenes.h"
#include "support.h"

static const double R = 10.0, L = 25.0, K = 400.0;

/* Distance from c to the segment p .. p + L (cos a, sin a). */
static double segment_distance(const double c[2], const double p[2], double a)
{
	double ux = cos(a), uy = sin(a);
	double dx = c[0] - p[0], dy = c[1] - p[1];
	double s = fmin(fmax(dx * ux + dy * uy, 0.0), L);
	return hypot(dx - s * ux, dy - s * uy);
}

/* Landscape angle of the left beam with the body at (0, y), tangent case:
 * th = phi + asin(R / rho) about the pivot (-25, 30). */
static double landscape_theta(double y)
{
	double rho = hypot(25.0, y - 30.0), phi = atan2(y - 30.0, 25.0);
	return phi + asin(R / rho);
}

/* The static balance on the midline: F = d/dy (2 * 1/2 K th^2). */
static double push_needed(double y)
{
	const double dy = 1e-6;
	double e1 = K * pow(landscape_theta(y + dy), 2), e0 = K * pow(landscape_theta(y - dy), 2);
	return (e1 - e0) / (2.0 * dy);
}

static void test_impact_chain_settles(void **state)
{
	(void)state;
	const double f_prop = 4.0;
	bsim_scene s;
	scene_gate_quiet(&s);
	s.body.start[1] = 19.0; /* 1 m short of the tips: arrives at 2.8 m/s */
	bsim_world *w = NULL;
	bsim_error err;
	assert_int_equal(bsim_test_backend("thesis")->create(&s, NULL, &w, &err), BSIM_OK);
	bsim_state st;
	bsim_state_init(&st, 2);
	const double force[2] = {0.0, f_prop};
	int impacts = 0, last_impact = -1;
	double worst = 0.0;
	for (int n = 1; n <= 30000; n++) { /* 120 s: the last creep decays as e^(-t / 11 s) */
		assert_int_equal(
		        bsim_backend_step(bsim_test_backend("thesis"), w, force, 0.0, s.dt, NULL),
		        BSIM_OK);
		bsim_test_backend("thesis")->get_state(w, &st);
		bsim_contact_flags(&s, &st);
		if (st.impacts) {
			impacts += st.impacts;
			last_impact = n;
		}
		double left = segment_distance(st.x, s.beams[0].pivot, st.theta[0]);
		double right =
		        segment_distance(st.x, s.beams[1].pivot, 3.141592653589793 - st.theta[1]);
		worst = fmax(worst, fmax(R - left, R - right));
	}
	/* the balance point on the landscape, by bisection on (20, 38) */
	double lo = 20.5, hi = 38.0;
	for (int i = 0; i < 60; i++) {
		double mid = 0.5 * (lo + hi);
		if (push_needed(mid) < f_prop)
			lo = mid;
		else
			hi = mid;
	}
	print_message("settling: %d impacts, the last at step %d; rest at y = %.6f (landscape "
	              "%.6f), theta %.6f (landscape %.6f); max penetration %.2e m\n",
	              impacts, last_impact, st.x[1], lo, st.theta[0], landscape_theta(st.x[1]),
	              worst);
	assert_true(impacts >= 3);                             /* a chain of impacts ... */
	assert_true(last_impact < 2000);                       /* ... that ends */
	assert_int_equal(st.contact[0], BSIM_CONTACT_TANGENT); /* held in contact */
	assert_int_equal(st.contact[1], BSIM_CONTACT_TANGENT);
	assert_true(st.x[0] == 0.0);
	assert_true(hypot(st.v[0], st.v[1]) < 1e-3);
	assert_true(fabs(st.x[1] - lo) < 1e-4);
	assert_true(fabs(st.theta[0] - landscape_theta(st.x[1])) < 1e-6);
	assert_true(worst <= 1e-6 + 1e-9); /* the slop, 1e-6 m */
	bsim_state_free(&st);
	bsim_test_backend("thesis")->destroy(w);
	bsim_scene_free(&s);
}

/* The projection's pass limit (position_project.h: 3 passes a step) is
 * counted exactly when it leaves penetration: a body put at rest inside
 * the one beam of scene_one_beam (pivot (0, 0), pointing +x, R = 10 m) at
 * depth 10 - d, stepped once, counts the limit if and only if the body
 * still overlaps the beam by more than the slop (1e-6 m) after the step,
 * by the geometry of its end state. Shallow cases are resolved, deep ones
 * not. */
static void test_projection_limit(void **state)
{
	(void)state;
	int resolved = 0, limited = 0;
	for (double d = 9.9; d > 0.0; d -= 1.0) {
		bsim_scene s;
		scene_one_beam(&s);
		s.body.start[0] = 12.0;
		bsim_world *w = NULL;
		bsim_error err;
		assert_int_equal(bsim_test_backend("thesis")->create(&s, NULL, &w, &err), BSIM_OK);
		bsim_state st;
		assert_int_equal(bsim_state_init(&st, 1), BSIM_OK);
		bsim_test_backend("thesis")->get_state(w, &st);
		bsim_contact_flags(&s, &st);
		st.x[0] = 12.0;
		st.x[1] = d;
		st.v[0] = st.v[1] = 0.0;
		assert_int_equal(bsim_test_backend("thesis")->set_state(w, &st, &err), BSIM_OK);
		const double zero[2] = {0.0, 0.0};
		assert_int_equal(
		        bsim_backend_step(bsim_test_backend("thesis"), w, zero, 0.0, 0.004, NULL),
		        BSIM_OK);
		bsim_test_backend("thesis")->get_state(w, &st);
		bsim_contact_flags(&s, &st);
		const double pivot[2] = {0.0, 0.0};
		double depth = R - segment_distance(st.x, pivot, st.theta[0]);
		assert_int_equal(st.solver.iteration_limit, depth > 1e-6 ? 1 : 0);
		resolved += depth <= 1e-6;
		limited += depth > 1e-6;
		bsim_state_free(&st);
		bsim_test_backend("thesis")->destroy(w);
		bsim_scene_free(&s);
	}
	assert_true(resolved > 0 && limited > 0);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_impact_chain_settles),
	        cmocka_unit_test(test_projection_limit),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
