/* docs/model.md check 1's square-on impact, shared by the check every
 * backend runs (test_impact) and a backend's own under its knobs
 * (test_box2d_oracles, test_chipmunk_oracles). Include after cmocka.h. */
#ifndef BSIM_TESTS_IMPACT_ORACLE_H
#define BSIM_TESTS_IMPACT_ORACLE_H

#include <math.h>

#include "beamsim/contact_flag.h"
#include "beamsim/backend.h"
#include "scenes.h"
#include "support.h"

/* What one square-on impact measured against its closed form. */
typedef struct impact_figures {
	double worst;       /* the largest relative error of v', omega', L, the loss and the
	                     * body's spin (its speed at the body's reach, over u) */
	double restitution; /* the relative normal velocity after over before */
	double spin;        /* the body's angular velocity after, rad/s */
	double spin_expect; /* and the closed form's */
} impact_figures;

/* A body of speed u hits the beam at rest (no spring) square-on at lever r.
 * body: NULL for the scene's disk, else the shape, size, mass, inertia,
 * heading and rotates of the body to use (its start and velocity are set
 * here); its heading a multiple of 90 deg, so that the contact is either
 *   central: the disk, a capsule's rounded end, an ellipse's semi-axis
 *     along the motion. The normal passes through the body's centre, the
 *     impulse has no moment about it: the body keeps its spin 0 and its
 *     inertia J does not enter;
 *   flat: a turning capsule lying across the motion, its flat side on the
 *     beam at r - L/2 and r + L/2. Newton's law at both points (v_rel' =
 *     e u at each) makes the body turn with the beam, w' = omega', so its
 *     turn adds J to the beam's inertia: the central form with I + J for
 *     I, while both impulses push, r <= L (I + J) / (2 J) (the nearer
 *     point's is the larger; asserted);
 * with
 *   mu = M r^2 / I,  v' = u (mu - e) / (1 + mu) (forward),
 *   omega' = (1 + e) u mu / (r (1 + mu)),  v_rel' = e u,
 * the angular momentum about the pivot M x v + J w + I omega = M r u, the
 * loss 1/2 m_eff (1 - e^2) u^2 with m_eff = M / (1 + mu), and the normal
 * impulse the beam reports (bsim_state.impulse, summed over the steps)
 * M (u - v): the body's momentum change, which it alone changes, and the
 * closed form's M u (1 + e) / (1 + mu). Fills f
 * (may be NULL) and returns the largest relative error; every error within
 * bound. The body starts 2 cm from the beam (a backend may start its
 * contact before touching: Box2D's skin, 5 cm at unit_scale 1) and the run
 * goes 20 steps of 4 ms, past the impact. */
static inline double impact_square_on(const bsim_backend *b, const bsim_options *o,
                                      const bsim_body_def *body, double r, double e, double u,
                                      double bound, impact_figures *f)
{
	bsim_scene s;
	scene_one_beam(&s);
	s.contact.restitution = e;
	s.contact.tip_restitution = 0.3; /* must not be used */
	int flat = 0;
	double reach = s.body.radius, ahead = s.body.radius; /* ahead: along the motion */
	if (body) {
		s.body.shape = body->shape;
		s.body.mass = body->mass;
		s.body.radius = body->radius;
		s.body.length = body->length;
		s.body.semi_axes[0] = body->semi_axes[0];
		s.body.semi_axes[1] = body->semi_axes[1];
		s.body.heading_deg = body->heading_deg;
		s.body.inertia = body->inertia;
		s.body.rotates = body->rotates;
		double psi = bsim_body_heading(&s.body), c = fabs(cos(psi)), sn = fabs(sin(psi));
		assert_true(fabs(sin(2.0 * psi)) < 1e-12); /* the axes along and across */
		if (body->shape == BSIM_SHAPE_CAPSULE) {
			reach = body->radius + 0.5 * body->length;
			ahead = body->radius + 0.5 * body->length * sn;
			flat = sn < 0.5;
			assert_true(!flat || body->rotates);
		} else if (body->shape == BSIM_SHAPE_ELLIPSE) {
			reach = fmax(body->semi_axes[0], body->semi_axes[1]);
			ahead = body->semi_axes[0] * sn + body->semi_axes[1] * c;
		}
	}
	s.body.start[0] = r;
	s.body.start[1] = -ahead - 0.02;
	s.body.velocity[1] = u;
	bsim_world *w = bsim_test_world(b, &s, o);
	bsim_state st;
	bsim_state_init(&st, 1);
	const double zero[2] = {0.0, 0.0};
	int impacts = 0, tangent = 0;
	double impact_loss = 0.0, impulse = 0.0;
	for (int n = 0; n < 20; n++) {
		assert_int_equal(bsim_backend_step(b, w, zero, 0.0, 0.004, NULL), BSIM_OK);
		b->get_state(w, &st);
		bsim_contact_flags(&s, &st);
		impacts += st.impacts;
		impact_loss += st.energy.impact;
		/* the impulse reported where, and only where, the beam was touched */
		assert_true(st.touched[0] ? st.impulse[0] > 0.0 : st.impulse[0] == 0.0);
		impulse += st.impulse[0];
		tangent |= st.contact[0] == BSIM_CONTACT_TANGENT;
		assert_true(st.contact[0] != BSIM_CONTACT_TIP);
	}
	double inertia = s.beams[0].inertia, mass = s.body.mass;
	double j = s.body.rotates ? bsim_body_inertia(&s.body) : 0.0;
	double inertia_eff = flat ? inertia + j : inertia;
	if (flat) /* the farther point's impulse, (P - 2 J omega' / L) / 2, >= 0 */
		assert_true(2.0 * j * r <= s.body.length * inertia_eff);
	double mu = mass * r * r / inertia_eff;
	double v_expect = u * (mu - e) / (1.0 + mu);
	double omega_expect = (1.0 + e) * u * mu / (r * (1.0 + mu));
	double spin_expect = flat ? omega_expect : 0.0;
	double spin = st.angular_velocity;
	double err_v = fabs(st.v[1] - v_expect) / u;
	double err_w = fabs(st.omega[0] - omega_expect) * r / u;
	double err_rel = fabs((st.omega[0] * r - st.v[1]) - e * u) / u;
	double err_spin = fabs(spin - spin_expect) * reach / u;
	double loss = 0.5 * mass / (1.0 + mu) * (1.0 - e * e) * u * u;
	double err_loss = fabs(impact_loss - loss) / (0.5 * mass * u * u);
	double l1 =
	        mass * (st.x[0] * st.v[1] - st.x[1] * st.v[0]) + j * spin + inertia * st.omega[0];
	/* The normal impulses the beam reported: the body's momentum change
	 * along the normal (-y: no other force acts), and the closed form's
	 * P = M (u - v'). */
	double err_p = fabs(impulse - mass * (u - st.v[1])) / (mass * u);
	double err_p_closed = fabs(impulse - mass * (u - v_expect)) / (mass * u);
	double err_l = fabs(l1 - mass * r * u) / (mass * r * u);
	if (f) {
		f->restitution = (st.omega[0] * r - st.v[1]) / u;
		f->spin = spin;
		f->spin_expect = spin_expect;
	}
	/* A shape may meet the beam at two contacts at once, each counted (the
	 * flat side's two points, two pieces of a polygon sharing the tip). */
	assert_true(impacts >= 1);
	assert_true(body || impacts == 1);
	assert_true(tangent);
	assert_true(fabs(st.v[0]) <= bound * u);
	assert_true(err_v <= bound);
	assert_true(err_w <= bound);
	assert_true(err_rel <= 2.0 * bound); /* the difference of the two above */
	assert_true(err_l <= bound);
	assert_true(err_p <= bound);
	assert_true(err_p_closed <= bound);
	assert_true(err_loss <= bound);
	assert_true(err_spin <= bound);
	assert_true(impact_loss >= -bound * 0.5 * mass * u * u);
	bsim_state_free(&st);
	b->destroy(w);
	bsim_scene_free(&s);
	double worst = fmax(fmax(fmax(err_v, err_w), fmax(err_l, err_loss)),
	                    fmax(err_spin, fmax(err_p, err_p_closed)));
	if (f)
		f->worst = worst;
	return worst;
}

/* The flat side's body: a turning capsule (R = 1 m, L = 4 m) lying across
 * the motion, light enough (0.5 kg, J = 1.47 kg m^2) that both points push
 * up to r = 30 m. */
static inline bsim_body_def impact_flat_capsule(void)
{
	bsim_body_def body = {.mass = 0.5,
	                      .shape = BSIM_SHAPE_CAPSULE,
	                      .radius = 1.0,
	                      .length = 4.0,
	                      .heading_deg = 0.0,
	                      .rotates = 1};
	return body;
}

/* What impact_sweep measured: the worst relative error, the effective
 * restitution's range at each e and the body's spin's largest departure
 * from the closed form's, rad/s. */
typedef struct impact_sweep_figures {
	double worst, e_lo[3], e_hi[3], spin;
} impact_sweep_figures;

/* A body (as impact_square_on takes it) at levers 5, 12.5 and 20 m with
 * e = 0.5, 0.8 and 1 (e_lo, e_hi in that order) and u = 2 m/s, every
 * impact within bound. */
static inline impact_sweep_figures impact_sweep(const bsim_backend *b, const bsim_options *o,
                                                const bsim_body_def *body, double bound)
{
	const double levers[] = {5.0, 12.5, 20.0}, es[] = {0.5, 0.8, 1.0};
	impact_sweep_figures s = {0};
	for (int i = 0; i < 3; i++) {
		s.e_lo[i] = INFINITY;
		s.e_hi[i] = -INFINITY;
		for (int l = 0; l < 3; l++) {
			impact_figures f;
			impact_square_on(b, o, body, levers[l], es[i], 2.0, bound, &f);
			s.worst = fmax(s.worst, f.worst);
			s.e_lo[i] = fmin(s.e_lo[i], f.restitution);
			s.e_hi[i] = fmax(s.e_hi[i], f.restitution);
			s.spin = fmax(s.spin, fabs(f.spin - f.spin_expect));
		}
	}
	return s;
}

/* The essay's disk (impact_square_on with no body). */
static inline double impact_tangent(const bsim_backend *b, const bsim_options *o, double r,
                                    double e, double u, double bound)
{
	return impact_square_on(b, o, NULL, r, e, u, bound, NULL);
}

#endif
