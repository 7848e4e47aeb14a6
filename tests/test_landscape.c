/* The potential energy landscape (docs/model.md section 7).
 *
 * Truths: the tangent and tip branches of th(x, y) meet at
 * rho^2 = L^2 + R^2 (the tangent point is then the tip); th vanishes from
 * rho = L + R on and is never negative; the symmetric gate's landscape is
 * mirror symmetric bit for bit; a body square in front of a beam (phi = 0
 * on the tangent branch) deflects it by asin(R / rho), by geometry; and
 * E_prop is F_prop (y0 - y). */
#define _DEFAULT_SOURCE
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "beamsim/landscape.h"

static void test_branches_meet(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 7, 0);
	const bsim_beam_def *b = &s.beams[0];
	const double L = b->length, R = s.body.radius;
	const double rho = sqrt(L * L + R * R);
	for (int k = 0; k < 16; k++) {
		double phi = -0.4 + 0.1 * k;
		double c_in[2] = {b->pivot[0] + (rho - 1e-9) * cos(phi),
		                  b->pivot[1] + (rho - 1e-9) * sin(phi)};
		double c_out[2] = {b->pivot[0] + (rho + 1e-9) * cos(phi),
		                   b->pivot[1] + (rho + 1e-9) * sin(phi)};
		double t_in = bsim_landscape_theta(b, R, c_in);
		double t_out = bsim_landscape_theta(b, R, c_out);
		assert_true(fabs(t_in - t_out) < 1e-7);
		/* Both equal phi + atan(R / L) there, where the tip touches. */
		assert_true(fabs(t_in - fmax(0.0, phi + atan(R / L))) < 1e-7);
	}
	bsim_scene_free(&s);
}

static void test_reach_and_sign(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 7, 0);
	const double R = s.body.radius;
	for (int i = 0; i < 2; i++) {
		const bsim_beam_def *b = &s.beams[i];
		for (int k = 0; k < 720; k++) {
			double a = k * (M_PI / 360);
			for (double r = 0.5; r < 60; r += 1.7) {
				double c[2] = {b->pivot[0] + r * cos(a), b->pivot[1] + r * sin(a)};
				double th = bsim_landscape_theta(b, R, c);
				assert_true(th >= 0.0);
				if (r >= b->length + R)
					assert_true(th == 0.0);
			}
		}
	}
	bsim_scene_free(&s);
}

static void test_square_in_front(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 7, 0);
	const bsim_beam_def *b = &s.beams[0];
	/* The body centre on the beam's rest line, phi = 0: the beam leans
	 * forward until it is tangent to the body, sin(th) = R / rho. */
	double c[2] = {b->pivot[0] + 20, b->pivot[1]};
	assert_true(fabs(bsim_landscape_theta(b, 10, c) - asin(0.5)) < 1e-15);
	bsim_scene_free(&s);
}

static void test_mirror(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 7, 0);
	double th[2], thm[2];
	for (double x = -40; x <= 40; x += 0.37)
		for (double y = -5; y <= 75; y += 0.41) {
			double c[2] = {x, y}, m[2] = {-x, y};
			double e = bsim_landscape_energy(&s, c, th, NULL, NULL);
			double em = bsim_landscape_energy(&s, m, thm, NULL, NULL);
			assert_true(th[0] == thm[1] && th[1] == thm[0]);
			assert_true(e == em);
		}
	bsim_scene_free(&s);
}

static void test_parts(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 7, 0);
	double c[2] = {3, 41}, th[2], eb, ep;
	double e = bsim_landscape_energy(&s, c, th, &eb, &ep);
	assert_true(ep == 7 * (60 - 41.0));
	assert_true(fabs(eb - 0.5 * 400 * (th[0] * th[0] + th[1] * th[1])) < 1e-12);
	assert_true(e == ep + eb);
	s.effects.has_propulsion = 0;
	assert_true(bsim_landscape_e_prop(&s, 41) == 0.0);
	bsim_scene_free(&s);
}

/* The label: the beam holding the most spring energy among those touching;
 * on the symmetric gate's midline the two tie (mirror symmetry) and
 * neither is named; off it, the beam on whose side the body is (nearer
 * its pivot, so deflected more); a beam not touching never counts. */
static void test_label(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 7, 0);
	const int both[2] = {1, 1}, left_only[2] = {1, 0}, right_only[2] = {0, 1};
	for (double y = 21; y < 52; y += 0.7) { /* (-2, y) within both reaches */
		const double mid[2] = {0, y}, off[2] = {-2, y};
		assert_int_equal(bsim_landscape_label(&s, mid, NULL), -1);
		assert_int_equal(bsim_landscape_label(&s, mid, both), -1);
		assert_int_equal(bsim_landscape_label(&s, mid, right_only), 1);
		assert_int_equal(bsim_landscape_label(&s, off, both), 0);
		assert_int_equal(bsim_landscape_label(&s, off, right_only), 1);
		assert_int_equal(bsim_landscape_label(&s, off, left_only), 0);
	}
	const double away[2] = {0, 5}; /* behind both beams: none deflected */
	assert_int_equal(bsim_landscape_label(&s, away, NULL), -1);
	/* a stiffer right beam holds more energy on the midline */
	s.beams[1].stiffness = 500;
	const double mid[2] = {0, 40};
	assert_int_equal(bsim_landscape_label(&s, mid, NULL), 1);
	bsim_scene_free(&s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_branches_meet),   cmocka_unit_test(test_reach_and_sign),
	        cmocka_unit_test(test_square_in_front), cmocka_unit_test(test_mirror),
	        cmocka_unit_test(test_parts),           cmocka_unit_test(test_label),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
