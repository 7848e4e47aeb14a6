/* docs/model.md check 1's square-on impact, shared by the check every
 * backend runs (test_impact) and a backend's own under its knobs
 * (test_box2d_oracles). Include after cmocka.h. */
#ifndef BSIM_TESTS_IMPACT_ORACLE_H
#define BSIM_TESTS_IMPACT_ORACLE_H

#include <math.h>

#include "beamsim/backend.h"
#include "scenes.h"
#include "support.h"

/* Body of speed u hits the beam at rest (no spring) square-on at lever r:
 *   mu = M r^2 / I,  v' = u (mu - e) / (1 + mu) (forward),
 *   omega' = (1 + e) u mu / (r (1 + mu)),  v_rel' = e u,
 * the angular momentum about the pivot M r v + I omega = M r u, and the
 * loss 1/2 m_eff (1 - e^2) u^2 with m_eff = M / (1 + mu). Returns the
 * largest relative error; every error within bound. The body starts 2 cm
 * from the beam (a backend may start its contact before touching: Box2D's
 * skin, 5 cm at unit_scale 1) and the run goes 20 steps of 4 ms, past the
 * impact. */
static inline double impact_tangent(const bsim_backend *b, const bsim_options *o, double r,
                                    double e, double u, double bound)
{
	bsim_scene s;
	scene_one_beam(&s);
	s.contact.restitution = e;
	s.contact.tip_restitution = 0.3; /* must not be used */
	s.body.start[0] = r;
	s.body.start[1] = -s.body.radius - 0.02;
	s.body.velocity[1] = u;
	bsim_world *w = bsim_test_world(b, &s, o);
	bsim_state st;
	bsim_state_init(&st, 1);
	const double zero[2] = {0.0, 0.0};
	int impacts = 0, tangent = 0;
	double impact_loss = 0.0;
	for (int n = 0; n < 20; n++) {
		assert_int_equal(b->step(w, zero, 0.0, 0.004, NULL), BSIM_OK);
		b->get_state(w, &st);
		impacts += st.impacts;
		impact_loss += st.energy.impact;
		tangent |= st.contact[0] == BSIM_CONTACT_TANGENT;
		assert_true(st.contact[0] != BSIM_CONTACT_TIP);
	}
	double inertia = s.beams[0].inertia, mass = s.body.mass;
	double mu = mass * r * r / inertia;
	double v_expect = u * (mu - e) / (1.0 + mu);
	double omega_expect = (1.0 + e) * u * mu / (r * (1.0 + mu));
	double err_v = fabs(st.v[1] - v_expect) / u;
	double err_w = fabs(st.omega[0] - omega_expect) * r / u;
	double err_rel = fabs((st.omega[0] * r - st.v[1]) - e * u) / u;
	double loss = 0.5 * mass / (1.0 + mu) * (1.0 - e * e) * u * u;
	double err_loss = fabs(impact_loss - loss) / (0.5 * mass * u * u);
	double err_l =
	        fabs(mass * r * st.v[1] + inertia * st.omega[0] - mass * r * u) / (mass * r * u);
	assert_int_equal(impacts, 1);
	assert_true(tangent);
	assert_true(fabs(st.v[0]) <= bound * u);
	assert_true(err_v <= bound);
	assert_true(err_w <= bound);
	assert_true(err_rel <= 2.0 * bound); /* the difference of the two above */
	assert_true(err_l <= bound);
	assert_true(err_loss <= bound);
	assert_true(impact_loss >= -bound * 0.5 * mass * u * u);
	bsim_state_free(&st);
	b->destroy(w);
	bsim_scene_free(&s);
	return fmax(fmax(err_v, err_w), fmax(err_l, err_loss));
}

#endif
