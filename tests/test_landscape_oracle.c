/* docs/model.md check 5 on every backend of the registry: a body pushed slowly against a
 * heavily damped beam keeps the beam at the landscape's th(x, y) while they
 * touch, through the tangent branch, the tip branch and the release at
 * rho = L + R, and comes to rest where th(x, y) says; and a body pushed
 * into the damped symmetric gate comes to rest at the floor of the start
 * basin that the barrier search reports.
 *
 * The truth is the contact geometry each backend enforces on its own
 * (the thesis solver's contact solve, Box2D's edge-circle manifold)
 * against the landscape's closed forms (docs/model.md section 7), which share
 * no code with either. How far a backend holds the beam from th is its own
 * bound (bsim_backend.bounds: "landscape.theta", "landscape.release"; Box2D
 * holds contacts to its linear slop, 5 mm at unit_scale 1, in float32, so
 * its bound is wider); each run prints what it measures. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "beamsim/contact_flag.h"
#include "beamsim/backend.h"
#include "beamsim/landscape.h"
#include "beamsim/landscape_barriers.h"
#include "scenes.h"
#include "support.h"

typedef struct push_result {
	double worst;        /* rad, max |theta - th(x, y)| while touching, rho < L + R - 0.1 m */
	double worst_near;   /* rad, the same within 0.1 m of the release */
	double worst_gap;    /* m, max |distance to the beam - R| while touching */
	int tangent, tip;    /* steps in tangent and in tip contact */
	int branch_mismatch; /* steps whose contact type is not the landscape's branch */
	double release_rho;  /* m, pivot distance at the last touching step */
} push_result;

/* Distance from c to beam b at angle theta. */
static double beam_distance(const bsim_beam_def *b, double theta, const double c[2])
{
	const double u[2] = {cos(theta), sin(theta)}; /* the beam points along +x at rest */
	const double d[2] = {c[0] - b->pivot[0], c[1] - b->pivot[1]};
	const double s = fmin(fmax(d[0] * u[0] + d[1] * u[1], 0.0), b->length);
	return hypot(d[0] - s * u[0], d[1] - s * u[1]);
}

/* One beam along +x from the origin (L = 25 m, k = 400 N m/rad, d = 200
 * N m s/rad: critically damped, zeta = 1.1), plastic contacts, and the
 * body (R = 10 m) starting 1 m below it at x = 20 m, driven at a steady
 * 0.25 m/s along +y by a stiff velocity feedback (200 N per m/s): a slow
 * push that no contact force stops, through the tangent branch, the tip
 * branch and off the tip. */
static void push(const bsim_backend *be, push_result *r)
{
	bsim_scene s;
	scene_one_beam(&s);
	bsim_beam_def *b = &s.beams[0];
	b->stiffness = 400.0;
	b->damping = 200.0;
	s.contact.restitution = 0.0;
	s.contact.tip_restitution = 0.0;
	s.body.start[0] = 20.0;
	s.body.start[1] = -11.0;
	s.body.velocity[1] = 0.25;
	bsim_world *w = NULL;
	bsim_error err;
	assert_int_equal(be->create(&s, NULL, &w, &err), BSIM_OK);
	bsim_state st;
	assert_int_equal(bsim_state_init(&st, 1), BSIM_OK);
	be->get_state(w, &st);
	bsim_contact_flags(&s, &st);
	memset(r, 0, sizeof *r);
	const double L = b->length, R = s.body.radius;
	for (int n = 0; n < 45000 && st.x[1] < 40; n++) {
		const double force[2] = {-200.0 * st.v[0], 200.0 * (0.25 - st.v[1])};
		assert_int_equal(bsim_backend_step(be, w, force, 0.0, s.dt, NULL), BSIM_OK);
		be->get_state(w, &st);
		bsim_contact_flags(&s, &st);
		if (!st.contact[0])
			continue;
		const double rho2 = st.x[0] * st.x[0] + st.x[1] * st.x[1];
		r->release_rho = sqrt(rho2);
		if (rho2 >= (L + R) * (L + R))
			continue; /* the landscape has released the beam: th = 0 */
		const double th = bsim_landscape_theta(b, R, st.x);
		const double dev = fabs(st.theta[0] - th);
		if (sqrt(rho2) < L + R - 0.1)
			r->worst = fmax(r->worst, dev);
		else
			r->worst_near = fmax(r->worst_near, dev);
		r->worst_gap = fmax(r->worst_gap, fabs(beam_distance(b, st.theta[0], st.x) - R));
		const int tangent = st.contact[0] == BSIM_CONTACT_TANGENT;
		r->tangent += tangent;
		r->tip += !tangent;
		/* the landscape's branch, except within 1 cm of the branch point */
		const double edge = fabs(sqrt(rho2) - sqrt(L * L + R * R));
		if (edge > 0.01 && tangent != (rho2 <= L * L + R * R))
			r->branch_mismatch++;
	}
	bsim_state_free(&st);
	be->destroy(w);
	bsim_scene_free(&s);
}

/* tol: |theta - th| bound up to 0.1 m before the release, where a
 * contact held gap open turns the beam about gap / lever short of th;
 * tol_near: within 0.1 m of it, where th falls like the square root of
 * L + R - rho and the sprung beam lags it by a step or so. */
static void sweep_branches(const bsim_backend *be, double tol, double tol_near)
{
	push_result r;
	push(be, &r);
	print_message("%s: |theta - th| <= %.3g rad (contact gap <= %.3g m), within 0.1 m of the "
	              "release %.3g rad, over %d tangent + %d tip steps; released at rho = %.4f m "
	              "(L + R = 35)\n",
	              be->name, r.worst, r.worst_gap, r.worst_near, r.tangent, r.tip,
	              r.release_rho);
	assert_true(r.tangent > 1000 && r.tip > 100);
	assert_int_equal(r.branch_mismatch, 0);
	assert_true(r.worst < tol);
	assert_true(r.worst_near < tol_near);
	assert_true(fabs(r.release_rho - 35.0) < 0.01);
}

static void test_branches(void **state)
{
	const bsim_backend *be = *state;
	double tol = bsim_test_bound(be, "landscape.theta");
	double tol_near = bsim_test_bound(be, "landscape.release");
	sweep_branches(be, tol, tol_near);
}

/* The essay gate, dampers 500 N m s/rad, plastic contacts, pushed by 8 N
 * from (0, 19): the body settles in the start basin at the basin floor of
 * the landscape's lowest pass (on the midline, a minimum of E_total at
 * 8 N). tol: distance in m. */
static void rest_at_basin_floor(const bsim_backend *be, double tol)
{
	bsim_scene s;
	scene_gate_quiet(&s);
	s.effects.has_propulsion = 1;
	s.effects.propulsion_force = 8.0;
	s.beams[0].damping = s.beams[1].damping = 500.0;
	s.contact.restitution = s.contact.tip_restitution = 0.0;
	bsim_landscape_grid *g;
	bsim_landscape_barriers *br;
	bsim_error err;
	bsim_landscape_grid_def def = bsim_landscape_grid_def_default();
	assert_int_equal(bsim_landscape_grid_alloc(&s, &def, &g, &err), BSIM_OK);
	assert_int_equal(bsim_landscape_barriers_alloc(&s, g, &br, &err), BSIM_OK);
	assert_int_equal(br->lowest.kind, BSIM_PASS_SADDLE);

	s.body.start[1] = 19.0;
	bsim_world *w = NULL;
	assert_int_equal(be->create(&s, NULL, &w, &err), BSIM_OK);
	bsim_state st;
	assert_int_equal(bsim_state_init(&st, 2), BSIM_OK);
	const double force[2] = {0.0, 8.0};
	for (int n = 0; n < 10000; n++) { /* 40 s; d / k = 1.25 s */
		assert_int_equal(bsim_backend_step(be, w, force, 0.0, s.dt, NULL), BSIM_OK);
		be->get_state(w, &st);
		bsim_contact_flags(&s, &st);
	}
	const double *fl = br->lowest.floor;
	print_message("%s: at rest at (%.5f, %.5f) m, speed %.2g m/s; the basin floor (%.5f, "
	              "%.5f) m, E_total %.4f J there, %.4f J at the rest point\n",
	              be->name, st.x[0], st.x[1], hypot(st.v[0], st.v[1]), fl[0], fl[1],
	              br->lowest.floor_e, bsim_landscape_energy(&s, st.x, NULL, NULL, NULL));
	assert_true(hypot(st.v[0], st.v[1]) < 1e-3);
	assert_true(hypot(st.x[0] - fl[0], st.x[1] - fl[1]) < tol);
	bsim_state_free(&st);
	be->destroy(w);
	bsim_landscape_barriers_free(br);
	bsim_landscape_grid_free(g);
	bsim_scene_free(&s);
}

/* The floor is refined to 4 mm; a backend holds its contacts to its slop
 * (Box2D's 5 mm; measured 1 mm). */
static void test_floor(void **state)
{
	rest_at_basin_floor(*state, 0.01);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_branches),
	        cmocka_unit_test(test_floor),
	};
	return bsim_test_run_per_backend("landscape_oracle", tests, sizeof tests / sizeof tests[0]);
}
