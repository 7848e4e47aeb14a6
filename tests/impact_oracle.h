/* docs/model.md check 1's square-on impact, shared by the check every
 * backend runs (test_impact) and a backend's own under its knobs
 * (test_box2d_oracles, test_chipmunk_oracles). Include after cmocka.h. */
#ifndef BSIM_TESTS_IMPACT_ORACLE_H
#define BSIM_TESTS_IMPACT_ORACLE_H

#include <math.h>
#include <stdio.h>
#include <string.h>

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

/* Newton's law where the normal misses the centre: an ellipse (a = 12.5 m,
 * b = 8 m, 1 kg) at headings 0 to 90 deg in steps of 1.25 deg, square-on
 * at 2 m/s with e = 0.8, its true outline's point nearest the beam (its
 * support along +y) placed at r = 5, 12.5 or 20 m. The relative normal
 * velocity at that point after the impact's step over before is e (the
 * impulse along the beam's normal there); a polygon's vertex nearest the
 * beam is off that point by up to half a vertex's spacing, and the
 * impulse's moment about the centre with it. Each |e_eff - e| within bound;
 * the range of e_eff and the centre line's ratio (omega r - v) / u at
 * 87.5 deg, r = 12.5 m, which is no restitution: the normal misses the
 * centre and the body turns, so it is below e on the true outline too. */
typedef struct impact_off_axis_figures {
	double lo, hi, centre_87;
} impact_off_axis_figures;

/* The scene of one of those impacts, at heading_deg and lever r: the
 * body's true contact point is at x = r, its centre at start[0]. */
static inline void impact_off_axis_scene(bsim_scene *s, double heading_deg, double r)
{
	const double a = 12.5, bb = 8.0;
	scene_one_beam(s);
	s->contact.restitution = 0.8;
	s->contact.tip_restitution = 0.3; /* must not be used */
	s->body.shape = BSIM_SHAPE_ELLIPSE;
	s->body.semi_axes[0] = a;
	s->body.semi_axes[1] = bb;
	s->body.heading_deg = heading_deg;
	s->body.rotates = 1;
	double psi = bsim_body_heading(&s->body), c = cos(psi), sn = sin(psi);
	/* the outline's point whose outward normal is +y: (sn, c) in the
	 * body's frame, the point a^2 n_x, b^2 n_y over its norm */
	double nn = hypot(a * sn, bb * c);
	double px = a * a * sn / nn, py = bb * bb * c / nn;
	double off = c * px - sn * py; /* its x from the centre's */
	s->body.start[0] = r - off;
	s->body.start[1] = -nn - 0.02; /* nn: the support height */
	s->body.velocity[1] = 2.0;
}

static inline impact_off_axis_figures impact_off_axis(const bsim_backend *b, const bsim_options *o,
                                                      double bound)
{
	const double e = 0.8, u = 2.0, levers[] = {5.0, 12.5, 20.0};
	impact_off_axis_figures f = {INFINITY, -INFINITY, NAN};
	for (int l = 0; l < 3; l++) {
		for (int k = 0; k <= 72; k++) {
			bsim_scene s;
			impact_off_axis_scene(&s, 1.25 * k, levers[l]);
			const double off = levers[l] - s.body.start[0];
			bsim_world *w = bsim_test_world(b, &s, o);
			bsim_state st;
			bsim_state_init(&st, 1);
			const double zero[2] = {0.0, 0.0};
			int impacts = 0;
			for (int n = 0; n < 20 && !impacts; n++) {
				assert_int_equal(bsim_backend_step(b, w, zero, 0.0, 0.004, NULL),
				                 BSIM_OK);
				b->get_state(w, &st);
				impacts += st.impacts;
			}
			assert_true(impacts >= 1);
			double eff = (st.omega[0] * (st.x[0] + off) -
			              (st.v[1] + st.angular_velocity * off)) /
			             u;
			f.lo = fmin(f.lo, eff);
			f.hi = fmax(f.hi, eff);
			if (l == 1 && k == 70)
				f.centre_87 = (st.omega[0] * st.x[0] - st.v[1]) / u;
			assert_true(fabs(eff - e) <= bound);
			bsim_state_free(&st);
			b->destroy(w);
			bsim_scene_free(&s);
		}
	}
	return f;
}

/* A backend that holds the ellipse as a polygon refuses it unless told
 * (knob ellipse=polygon), and why: check names body.shape, the knob, and
 * the polygon's restitution off the axes for e = 0.8, "is LO to HI for e =
 * 0.8"; taken as the polygon, impact_off_axis measures that range (to the
 * 3 digits stated) and a departure beyond 2% of e, the refusal's reason. */
static inline impact_off_axis_figures impact_ellipse_refusal(const bsim_backend *b)
{
	bsim_scene s;
	impact_off_axis_scene(&s, 0.0, 5.0);
	char field[64];
	bsim_error err;
	assert_int_equal(b->check(&s, NULL, field, sizeof field, &err), BSIM_EINPUT);
	bsim_scene_free(&s);
	print_message("refused: %s: %s\n", field, err.msg);
	assert_string_equal(field, "body.shape");
	assert_non_null(strstr(err.msg, "--backend-opt ellipse=polygon"));
	const char *at = strstr(err.msg, "contact point is ");
	assert_non_null(at);
	double lo, hi;
	assert_int_equal(sscanf(at, "contact point is %lf to %lf for e = 0.8", &lo, &hi), 2);
	bsim_options o;
	memset(&o, 0, sizeof o);
	assert_int_equal(bsim_options_add(&o, "ellipse=polygon", &err), BSIM_OK);
	impact_off_axis_figures f = impact_off_axis(b, &o, INFINITY);
	const double e = 0.8, departs = fmax(f.hi - e, e - f.lo);
	print_message("%s ellipse=polygon off its axes (e = 0.8): restitution at the true contact "
	              "point %.5f to %.5f, departs by %.3f of e\n",
	              b->name, f.lo, f.hi, departs / e);
	assert_true(fabs(f.lo - lo) <= 5e-4 && fabs(f.hi - hi) <= 5e-4);
	assert_true(departs > 0.02 * e);
	return f;
}

#endif
