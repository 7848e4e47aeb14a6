/* The thesis backend's body that turns and has a shape (docs/backends.md,
 * "A body that turns, has a shape, and feels friction"): the capsule's outline
 * against a segment against a sampled outline; a free capsule's angular
 * momentum and energy (constant), and its heading under a constant torque
 * (the closed form); an off-centre frictionless impact of a capsule on a beam
 * against the impulse equations with the body's inertia solved by hand, and
 * against the angular momentum about the pivot; a turning disk without
 * friction against the essay's disk bit for bit (no contact can turn a
 * frictionless disk); the energy ledger of a turning capsule among beams with
 * friction, closed. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "beamsim/backend.h"
#include "beamsim/body_shape.h"
#include "beamsim/contact_flag.h"
#include "scenes.h"
#include "support.h"

static const double h = 0.004;
static const double M_PI_VALUE = 3.14159265358979323846;
static const double zero[2] = {0.0, 0.0};

static bsim_world *make_with(const bsim_scene *s, const char *knob)
{
	bsim_world *w = NULL;
	bsim_error err;
	bsim_options opts = {0};
	if (knob)
		assert_int_equal(bsim_options_add(&opts, knob, NULL), BSIM_OK);
	int rc = bsim_test_backend("thesis")->create(s, knob ? &opts : NULL, &w, &err);
	if (rc)
		fprintf(stderr, "%s\n", err.msg);
	assert_int_equal(rc, BSIM_OK);
	return w;
}

static bsim_world *make(const bsim_scene *s)
{
	return make_with(s, NULL);
}

/* A capsule of half-width r and segment l that turns, at rest far below
 * the one beam of scene_one_beam. */
static void scene_capsule(bsim_scene *s, double r, double l, double heading_deg)
{
	scene_one_beam(s);
	s->body.shape = BSIM_SHAPE_CAPSULE;
	s->body.radius = r;
	s->body.length = l;
	s->body.heading_deg = heading_deg;
	s->body.rotates = 1;
}

/* A deterministic uniform in [0, 1) (a 64-bit LCG's top bits). */
static double uniform(uint64_t *s)
{
	*s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
	return (double)(*s >> 11) * (1.0 / 9007199254740992.0);
}

/* The nearest distance from the capsule's outline to the segment by
 * sampling the outline (the circle of radius r about every point of the
 * core; the outline of the union is the nearest of them): an independent
 * truth for the capsule's case of bsim_body_shape_segment. */
static double sampled_gap(double r, double l, const double x[2], double psi, const double p0[2],
                          const double p1[2])
{
	double best = INFINITY;
	for (int i = 0; i <= 2000; i++) {
		double f = -0.5 + i / 2000.0;
		double k[2] = {x[0] + f * l * cos(psi), x[1] + f * l * sin(psi)};
		for (int j = 0; j <= 400; j++) {
			double t = j / 400.0;
			double q[2] = {p0[0] + t * (p1[0] - p0[0]), p0[1] + t * (p1[1] - p0[1])};
			best = fmin(best, hypot(k[0] - q[0], k[1] - q[1]) - r);
		}
	}
	return best;
}

static void test_capsule_outline(void **state)
{
	(void)state;
	bsim_body_def b = bsim_body_def_default();
	b.shape = BSIM_SHAPE_CAPSULE;
	b.radius = 2.0;
	b.length = 8.0;
	const double p0[2] = {0.0, 0.0}, p1[2] = {25.0, 0.0};
	/* headings and centres: beside the beam, off its tip, off its pivot */
	const double cases[][3] = {
	        {12.0, -9.0, 20.0},  {12.0, -7.5, 90.0}, {30.0, 3.0, 45.0},
	        {-4.0, -5.0, -30.0}, {27.0, -1.0, 80.0}, {5.0, 6.5, 0.0},
	};
	for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
		double x[2] = {cases[c][0], cases[c][1]}, psi = cases[c][2] * M_PI_VALUE / 180.0;
		bsim_body_segment_contact bc;
		assert_int_equal(bsim_body_shape_segment(&b, x, psi, p0, p1, &bc), BSIM_OK);
		double truth = sampled_gap(b.radius, b.length, x, psi, p0, p1);
		/* sampling the core at l/2000 and the beam at 25/400 m */
		assert_true(fabs(bc.dist - truth) < 2e-3);
		/* the outline's point lies on the outline, the segment's on it,
		 * and they are dist apart along n */
		double gap[2] = {bc.on_body[0] - bc.on_segment[0],
		                 bc.on_body[1] - bc.on_segment[1]};
		assert_true(fabs(gap[0] - bc.dist * bc.n[0]) < 1e-12 * 30);
		assert_true(fabs(gap[1] - bc.dist * bc.n[1]) < 1e-12 * 30);
		assert_true(fabs(hypot(bc.n[0], bc.n[1]) - 1.0) < 1e-15);
		assert_true(fabs(bc.on_segment[1]) < 1e-12);
	}
	/* the reach: the half-length plus the half-width */
	assert_true(bsim_body_shape_reach(&b) == 6.0);
	/* a beam through the core: no normal */
	double x[2] = {12.0, 0.0};
	bsim_body_segment_contact bc;
	assert_int_equal(bsim_body_shape_segment(&b, x, 1.0, p0, p1, &bc), BSIM_EFAIL);
}

/* The start's overlap check by the outline: a capsule along x (r = 2, l =
 * 8) whose centre is 4 m below the beam along +x overlaps it when its
 * heading tilts an end up by more than 2 m (sin psi > 2 / 4: psi > 30 deg),
 * not below; a disk's test (centre within r) would see neither. */
static void test_start_overlap(void **state)
{
	(void)state;
	bsim_scene s;
	scene_capsule(&s, 2.0, 8.0, 25.0);
	s.body.start[0] = 12.0;
	s.body.start[1] = -4.0;
	bsim_error err;
	assert_int_equal(bsim_scene_validate(&s, &err), BSIM_OK);
	s.body.heading_deg = 35.0;
	assert_int_equal(bsim_scene_validate(&s, &err), BSIM_EINPUT);
	assert_non_null(strstr(err.msg, "overlaps beam 1"));
	assert_non_null(strstr(err.msg, "capsule"));
	s.body.heading_deg = -35.0; /* the other end up */
	assert_int_equal(bsim_scene_validate(&s, &err), BSIM_EINPUT);
	bsim_scene_free(&s);
}

/* No force, no torque, nothing in reach: J w and M v constant, the heading
 * psi0 + w t and the energy constant, to round-off; with a constant torque
 * T, w = w0 + T t / J and psi = psi0 + w0 t + T t^2 / (2 J) (the midpoint
 * rule is exact for a constant torque). */
static void test_free_capsule(void **state)
{
	(void)state;
	bsim_scene s;
	scene_capsule(&s, 2.0, 8.0, 30.0);
	s.body.start[1] = -400.0;
	s.body.velocity[0] = 0.7;
	s.body.velocity[1] = -0.4;
	s.body.angular_velocity = 2.5;
	double inertia = bsim_body_inertia(&s.body);
	/* the capsule's inertia from its parts: rectangle 2 r l, two half
	 * disks (a disk of radius r) at distance l / 2 plus 4 r / (3 pi) */
	double area = 2 * 2.0 * 8.0 + M_PI_VALUE * 4.0, m_r = 32.0 / area, m_d = 1.0 - m_r;
	double i_hand = m_r * (64.0 + 16.0) / 12.0 +
	                m_d * (4.0 / 2.0 + 16.0 + 4.0 * 2.0 * 8.0 / (3.0 * M_PI_VALUE));
	assert_true(fabs(inertia - i_hand) < 1e-12 * i_hand);

	bsim_world *w = make(&s);
	bsim_state st;
	bsim_state_init(&st, 1);
	bsim_test_backend("thesis")->get_state(w, &st);
	double psi0 = st.heading, e0 = 0.5 * (0.49 + 0.16) + 0.5 * inertia * 2.5 * 2.5;
	int n = 2000;
	for (int k = 0; k < n; k++)
		assert_int_equal(
		        bsim_backend_step(bsim_test_backend("thesis"), w, zero, 0.0, h, NULL),
		        BSIM_OK);
	bsim_test_backend("thesis")->get_state(w, &st);
	assert_true(st.angular_velocity == 2.5); /* J w: nothing acts on it */
	assert_true(st.v[0] == 0.7 && st.v[1] == -0.4);
	double t = n * h;
	assert_true(fabs(st.heading - (psi0 + 2.5 * t)) < 1e-12 * 2.5 * t);
	double e = 0.5 * (st.v[0] * st.v[0] + st.v[1] * st.v[1]) +
	           0.5 * inertia * st.angular_velocity * st.angular_velocity;
	printf("free capsule, %d steps: J w %s, energy off by %.3g relative, heading off by "
	       "%.3g rad\n",
	       n, st.angular_velocity == 2.5 ? "exactly constant" : "changed", fabs(e - e0) / e0,
	       fabs(st.heading - (psi0 + 2.5 * t)));
	assert_true(fabs(e - e0) < 1e-14 * e0);
	assert_true(fabs(st.x[0] - 0.7 * t) < 1e-12 * t);

	/* a constant torque from here */
	const double torque = -0.3;
	double w0 = st.angular_velocity, p0 = st.heading;
	for (int k = 0; k < n; k++)
		assert_int_equal(
		        bsim_backend_step(bsim_test_backend("thesis"), w, zero, torque, h, NULL),
		        BSIM_OK);
	bsim_test_backend("thesis")->get_state(w, &st);
	double w_hand = w0 + torque * t / inertia;
	double p_hand = p0 + w0 * t + torque * t * t / (2.0 * inertia);
	assert_true(fabs(st.angular_velocity - w_hand) < 1e-12 * fabs(w0));
	assert_true(fabs(st.heading - p_hand) < 1e-11 * fabs(p_hand));
	bsim_test_backend("thesis")->destroy(w);

	/* integrator=euler: psi moves by h w' each step, psi_n = psi0 + w0 n h
	 * + T h^2 n (n + 1) / (2 J) */
	w = make_with(&s, "integrator=euler");
	bsim_test_backend("thesis")->get_state(w, &st);
	p0 = st.heading;
	for (int k = 0; k < n; k++)
		assert_int_equal(
		        bsim_backend_step(bsim_test_backend("thesis"), w, zero, torque, h, NULL),
		        BSIM_OK);
	bsim_test_backend("thesis")->get_state(w, &st);
	p_hand = p0 + 2.5 * n * h + torque * h * h * n * (n + 1.0) / (2.0 * inertia);
	assert_true(fabs(st.heading - p_hand) < 1e-11 * fabs(p_hand));
	assert_true(fabs(st.angular_velocity - (2.5 + torque * t / inertia)) < 1e-12 * 2.5);
	bsim_test_backend("thesis")->destroy(w);
	bsim_state_free(&st);
	bsim_scene_free(&s);
}

/* A capsule of half-width r = 2 and segment l = 8 at heading 20 deg moves
 * up at u into the free beam along +x (pivot at the origin, no spring),
 * touching it with the top of its upper cap at x = 12: contact point
 * K = E + r (0, 1), E = C + (l/2)(cos psi, sin psi), normal n = (0, -1),
 * r_b = K - C = ((l/2) cos psi, (l/2) sin psi + r),
 *   cb = r_b x n = -(l/2) cos psi,  c = sgn (a x n) = -12 (a = (12, 0)),
 *   v_rel = -u,  1/m = 1/M + cb^2/J + c^2/I,  P = (1 + e) u m,
 *   v' = v + P n / M,  w' = P cb / J,  omega' = -P c / I.
 * By hand, and the angular momentum about the pivot, M (C x v) + J w +
 * I omega, conserved. */
static void offcentre_impact(const char *knob)
{
	const double r = 2.0, l = 8.0, deg = 20.0, u = 1.5, e = 0.6;
	double psi = deg * M_PI_VALUE / 180.0;
	bsim_scene s;
	scene_capsule(&s, r, l, deg);
	s.contact.restitution = e;
	double c_pos[2] = {12.0 - 0.5 * l * cos(psi), -r - 1e-9 - 0.5 * l * sin(psi)};
	s.body.start[0] = c_pos[0];
	s.body.start[1] = c_pos[1];
	s.body.velocity[1] = u;
	double mass = s.body.mass, inertia = bsim_body_inertia(&s.body), ib = s.beams[0].inertia;

	bsim_world *w = make_with(&s, knob);
	bsim_state st;
	bsim_state_init(&st, 1);
	assert_int_equal(bsim_backend_step(bsim_test_backend("thesis"), w, zero, 0.0, h, NULL),
	                 BSIM_OK);
	bsim_test_backend("thesis")->get_state(w, &st);

	double cb = -0.5 * l * cos(psi), c = -12.0;
	double m_eff = 1.0 / (1.0 / mass + cb * cb / inertia + c * c / ib);
	double p = (1.0 + e) * u * m_eff;
	double v_hand = u - p / mass, w_hand = p * cb / inertia, omega_hand = -p * c / ib;
	printf("off-centre impact (%s): v %.3g, w %.3g, omega %.3g relative to the hand "
	       "solution\n",
	       knob ? knob : "defaults", fabs(st.v[1] - v_hand) / fabs(v_hand),
	       fabs(st.angular_velocity - w_hand) / fabs(w_hand),
	       fabs(st.omega[0] - omega_hand) / fabs(omega_hand));
	assert_int_equal(st.impacts, 1);
	assert_true(fabs(st.v[1] - v_hand) < 1e-12 * u);
	assert_true(fabs(st.v[0]) < 1e-12 * u);
	assert_true(fabs(st.angular_velocity - w_hand) < 1e-12 * fabs(w_hand));
	assert_true(fabs(st.omega[0] - omega_hand) < 1e-12 * fabs(omega_hand));
	/* the body turns clockwise: its right end is pushed down */
	assert_true(w_hand < 0.0);
	/* angular momentum about the pivot, before (at the start) and after
	 * (at the step's end: no force, the body's momentum is constant) */
	double l_before = mass * (c_pos[0] * u - c_pos[1] * 0.0);
	double l_after = mass * (st.x[0] * st.v[1] - st.x[1] * st.v[0]) +
	                 inertia * st.angular_velocity + ib * st.omega[0];
	assert_true(fabs(l_after - l_before) < 1e-11 * fabs(l_before));
	/* the loss is the restitution's: (1 - e^2) m u^2 / 2 */
	double loss = 0.5 * (1.0 - e * e) * m_eff * u * u;
	assert_true(fabs(st.energy.impact - loss) < 1e-12 * loss);
	bsim_test_backend("thesis")->destroy(w);
	bsim_state_free(&st);
	bsim_scene_free(&s);
}

/* Seeded random elastic (e = 1), frictionless impacts of a turning capsule
 * and ellipse on the free beam (no spring): energy and the angular
 * momentum about the pivot, M (C x v) + J w + I omega, are both conserved
 * by the impulse whatever the contact point (docs/model.md section 4 with the
 * body's rotation). */
static void test_elastic_impacts_conserve(void **state)
{
	(void)state;
	uint64_t seed = 3;
	int met = 0, two_point = 0;
	double worst_e = 0.0, worst_l = 0.0;
	for (int k = 0; k < 2000; k++) {
		bsim_scene s;
		scene_one_beam(&s);
		if (k % 2) {
			s.body.shape = BSIM_SHAPE_ELLIPSE;
			s.body.radius = 0.0;
			s.body.semi_axes[0] = 2.0 + 8.0 * uniform(&seed);
			s.body.semi_axes[1] = 1.0 + 4.0 * uniform(&seed);
		} else {
			s.body.shape = BSIM_SHAPE_CAPSULE;
			s.body.radius = 1.0 + 3.0 * uniform(&seed);
			s.body.length = 2.0 + 10.0 * uniform(&seed);
		}
		/* every 4th capsule lies along the beam, not spinning: both
		 * ends of its core hit at once */
		int flat = k % 4 == 0;
		s.body.heading_deg = flat ? 0.0 : 360.0 * uniform(&seed);
		s.body.rotates = 1;
		s.body.angular_velocity = flat ? 0.0 : 2.0 * uniform(&seed) - 1.0;
		s.contact.restitution = s.contact.tip_restitution = 1.0;
		s.contact.rest_threshold = 0.0; /* every approach elastic */
		s.beams[0].initial_omega = 0.2 * uniform(&seed) - 0.1;
		double x[2] = {-5.0 + 35.0 * uniform(&seed), 0.0};
		x[1] = (uniform(&seed) < 0.5 ? -1.0 : 1.0) * (bsim_body_shape_reach(&s.body) + 0.5);
		double psi = bsim_body_heading(&s.body), p0[2] = {0.0, 0.0}, p1[2] = {25.0, 0.0};
		bsim_body_segment_contact bc;
		assert_int_equal(bsim_body_shape_segment(&s.body, x, psi, p0, p1, &bc), BSIM_OK);
		if (bc.dist > 20.0) {
			bsim_scene_free(&s);
			continue;
		}
		x[0] -= (bc.dist + 1e-9) * bc.n[0];
		x[1] -= (bc.dist + 1e-9) * bc.n[1];
		s.body.start[0] = x[0];
		s.body.start[1] = x[1];
		double speed = 0.2 + 3.0 * uniform(&seed);
		s.body.velocity[0] = -speed * bc.n[0];
		s.body.velocity[1] = -speed * bc.n[1];
		double j = bsim_body_inertia(&s.body), ib = s.beams[0].inertia, m = s.body.mass;
		double om0 = s.beams[0].initial_omega;
		double e0 = 0.5 * m * speed * speed +
		            0.5 * j * s.body.angular_velocity * s.body.angular_velocity +
		            0.5 * ib * om0 * om0;
		double l0 = m * (x[0] * s.body.velocity[1] - x[1] * s.body.velocity[0]) +
		            j * s.body.angular_velocity + ib * om0;
		bsim_world *w = make(&s);
		bsim_state st;
		bsim_state_init(&st, 1);
		assert_int_equal(
		        bsim_backend_step(bsim_test_backend("thesis"), w, zero, 0.0, h, NULL),
		        BSIM_OK);
		bsim_test_backend("thesis")->get_state(w, &st);
		double e1 = 0.5 * m * (st.v[0] * st.v[0] + st.v[1] * st.v[1]) +
		            0.5 * j * st.angular_velocity * st.angular_velocity +
		            0.5 * ib * st.omega[0] * st.omega[0];
		double l1 = m * (st.x[0] * st.v[1] - st.x[1] * st.v[0]) + j * st.angular_velocity +
		            ib * st.omega[0];
		met += st.impacts > 0;
		two_point += st.impacts == 2;
		worst_e = fmax(worst_e, fabs(e1 - e0) / e0);
		double lscale = m * speed * (fabs(x[0]) + fabs(x[1])) + j + ib;
		worst_l = fmax(worst_l, fabs(l1 - l0) / lscale);
		bsim_test_backend("thesis")->destroy(w);
		bsim_state_free(&st);
		bsim_scene_free(&s);
	}
	printf("elastic impacts of capsules and ellipses: %d met the beam (%d on two points); "
	       "energy within %.3g, angular momentum within %.3g relative\n",
	       met, two_point, worst_e, worst_l);
	assert_true(met > 1000);
	assert_true(two_point > 100);
	assert_true(worst_e < 1e-12);
	assert_true(worst_l < 1e-12);
}

/* The same with the essay's impact order and with the Euler integrator: one
 * contact, the same impulse; the step's smooth part has no force. */
static void test_offcentre_impact(void **state)
{
	(void)state;
	offcentre_impact(NULL);
	offcentre_impact("impact_order=nearest_first");
	offcentre_impact("integrator=euler");
}

/* The essay's gate with propulsion and a random force: a disk that turns,
 * without friction, against the essay's disk; no contact can turn it (its
 * contact forces pass through its centre), so the two runs are one. */
static void test_turning_disk_bits(void **state)
{
	(void)state;
	bsim_scene a, b;
	bsim_scene_init_gate(&a, 3.0, 0.0);
	a.body.start[0] = 4.0;
	a.body.velocity[0] = 0.6;
	a.body.velocity[1] = 5.0;
	bsim_scene_copy(&b, &a);
	b.body.rotates = 1;
	bsim_world *wa = make(&a), *wb = make(&b);
	bsim_state sa, sb;
	bsim_state_init(&sa, 2);
	bsim_state_init(&sb, 2);
	const double f[2] = {0.8, 3.0};
	long impacts = 0;
	for (int k = 0; k < 6000; k++) {
		double fk[2] = {k % 500 < 250 ? f[0] : -f[0], f[1]};
		assert_int_equal(
		        bsim_backend_step(bsim_test_backend("thesis"), wa, fk, 0.0, h, NULL),
		        BSIM_OK);
		assert_int_equal(
		        bsim_backend_step(bsim_test_backend("thesis"), wb, fk, 0.0, h, NULL),
		        BSIM_OK);
		bsim_test_backend("thesis")->get_state(wa, &sa);
		bsim_test_backend("thesis")->get_state(wb, &sb);
		impacts += sa.impacts;
		assert_memory_equal(sa.x, sb.x, sizeof sa.x);
		assert_memory_equal(sa.v, sb.v, sizeof sa.v);
		for (int i = 0; i < 2; i++) {
			assert_memory_equal(&sa.theta[i], &sb.theta[i], sizeof(double));
			assert_memory_equal(&sa.omega[i], &sb.omega[i], sizeof(double));
		}
		assert_true(sb.angular_velocity == 0.0);
	}
	assert_true(impacts > 0); /* the run met the beams */
	bsim_test_backend("thesis")->destroy(wa);
	bsim_test_backend("thesis")->destroy(wb);
	bsim_state_free(&sa);
	bsim_state_free(&sb);
	bsim_scene_free(&a);
	bsim_scene_free(&b);
}

/* Kinetic (with J w^2 / 2) plus elastic energy, J. */
static double energy_of(const bsim_scene *s, const bsim_state *st)
{
	double e = 0.5 * s->body.mass * (st->v[0] * st->v[0] + st->v[1] * st->v[1]) +
	           0.5 * bsim_body_inertia(&s->body) * st->angular_velocity * st->angular_velocity;
	for (int i = 0; i < s->n_beams; i++)
		e += 0.5 * s->beams[i].inertia * st->omega[i] * st->omega[i] +
		     0.5 * s->beams[i].stiffness * st->theta[i] * st->theta[i];
	return e;
}

/* The ledger dE = F . dx + T dpsi - damper - impact - contact - correction
 * - sleep, step by step, for a capsule that turns under a torque, driven
 * through the gate with friction; it closes to round-off of the energies
 * involved (docs/model.md check 3's ledger). */
static void test_ledger_closes(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 0.0, 0.0);
	s.body.shape = BSIM_SHAPE_CAPSULE;
	s.body.radius = 4.0;
	s.body.length = 10.0;
	s.body.rotates = 1;
	s.body.start[0] = 2.0;
	s.body.velocity[1] = 4.0;
	s.body.angular_velocity = 0.3;
	s.contact.friction = 0.4;
	bsim_world *w = make(&s);
	bsim_state s0, s1;
	bsim_state_init(&s0, 2);
	bsim_state_init(&s1, 2);
	bsim_test_backend("thesis")->get_state(w, &s0);
	double worst = 0.0, flow = 0.0, friction_loss = 0.0;
	long impacts = 0;
	for (int k = 0; k < 5000; k++) {
		double force[2] = {1.5 * sin(0.01 * k), 6.0}, torque = 2.0 * cos(0.003 * k);
		assert_int_equal(
		        bsim_backend_step(bsim_test_backend("thesis"), w, force, torque, h, NULL),
		        BSIM_OK);
		bsim_test_backend("thesis")->get_state(w, &s1);
		double work = force[0] * (s1.x[0] - s0.x[0]) + force[1] * (s1.x[1] - s0.x[1]) +
		              torque * (s1.heading - s0.heading);
		const bsim_step_energy *se = &s1.energy;
		double losses = se->damper + se->impact + se->contact + se->correction + se->sleep;
		double de = energy_of(&s, &s1) - energy_of(&s, &s0);
		worst = fmax(worst, fabs(de - (work - losses)));
		flow += fabs(work) + fabs(losses);
		friction_loss += se->contact;
		impacts += s1.impacts;
		bsim_state_copy(&s0, &s1);
	}
	printf("ledger: worst step residual %.3g J, flows %.3g J, contact line %.3g J, "
	       "%ld impacts\n",
	       worst, flow, friction_loss, impacts);
	assert_true(impacts > 0);
	assert_true(worst < 1e-9 * flow);
	bsim_test_backend("thesis")->destroy(w);
	bsim_state_free(&s0);
	bsim_state_free(&s1);
	bsim_scene_free(&s);
}

/* A turning capsule or ellipse driven through the gate by propulsion and a
 * held random lateral force, with and without friction: its outline never
 * enters a beam deeper than the projection's slop (1e-6 m), measured with
 * the shape's own geometry from the state, and no solve gives up. */
static void test_capsule_penetration(void **state)
{
	(void)state;
	const double mus[] = {0.0, 0.0, 0.3, 0.3, 1.0, 1.0, 2.0, 2.0};
	double deepest = 0.0;
	uint64_t seed = 7;
	for (int trial = 0; trial < 8; trial++) {
		bsim_scene s;
		bsim_scene_init_gate(&s, 8.0, 0.0);
		if (trial % 2 == 0) {
			s.body.shape = BSIM_SHAPE_CAPSULE;
			s.body.radius = 5.0;
			s.body.length = 12.0;
		} else {
			s.body.shape = BSIM_SHAPE_ELLIPSE;
			s.body.radius = 0.0;
			s.body.semi_axes[0] = 11.0;
			s.body.semi_axes[1] = 5.0;
		}
		s.body.heading_deg = 90.0 + 10.0 * sin(trial);
		s.body.rotates = 1;
		s.contact.friction = mus[trial];
		bsim_world *w = make(&s);
		bsim_state st;
		bsim_state_init(&st, 2);
		double lateral = 0.0;
		for (int k = 0; k < 3000; k++) {
			if (k % 5 == 0) /* held 5 steps, uniform in [-40, 40] N */
				lateral = 80.0 * uniform(&seed) - 40.0;
			double f[2] = {lateral, 8.0};
			assert_int_equal(
			        bsim_backend_step(bsim_test_backend("thesis"), w, f, 0.0, h, NULL),
			        BSIM_OK);
			bsim_test_backend("thesis")->get_state(w, &st);
			for (int i = 0; i < 2; i++) {
				double u0[2], u[2];
				bsim_scene_beam_rest_direction(&s.beams[i], u0);
				bsim_beam_direction(u0, bsim_scene_beam_forward_sign(&s.beams[i]),
				                    st.theta[i], u);
				const double *p = s.beams[i].pivot;
				double tip[2] = {p[0] + s.beams[i].length * u[0],
				                 p[1] + s.beams[i].length * u[1]};
				bsim_body_segment_contact c;
				assert_int_equal(bsim_body_shape_segment(&s.body, st.x, st.heading,
				                                         p, tip, &c),
				                 BSIM_OK);
				deepest = fmin(deepest, c.dist);
			}
		}
		assert_int_equal(st.solver.iteration_limit, 0);
		bsim_test_backend("thesis")->destroy(w);
		bsim_state_free(&st);
		bsim_scene_free(&s);
	}
	printf("capsule and ellipse at the gate, 8 trials of 3000 steps: deepest overlap %.3g m\n",
	       -deepest);
	assert_true(deepest > -1e-6 * (1.0 + 1e-6));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_capsule_outline),
	        cmocka_unit_test(test_start_overlap),
	        cmocka_unit_test(test_free_capsule),
	        cmocka_unit_test(test_offcentre_impact),
	        cmocka_unit_test(test_turning_disk_bits),
	        cmocka_unit_test(test_ledger_closes),
	        cmocka_unit_test(test_elastic_impacts_conserve),
	        cmocka_unit_test(test_capsule_penetration),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
