/* Body-beam Coulomb friction in the thesis backend (contact.friction,
 * docs/backends.md "A body that turns, has a shape, and feels friction"):
 * impacts that stick and impacts that slide against the impulse analysis
 * solved by hand (a turning disk, whose tangent row
 * the beam does not feel, and a tilted capsule, whose normal and tangent
 * rows are coupled through its rotation); persistent contact holding a
 * capsule at rest under a force inside the cone and letting it slide,
 * decelerated by mu F_n, outside it; and no impact with e <= 1 and friction
 * ever creating energy, over seeded random impacts. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "beamsim/contact_flag.h"
#include "beamsim/backend.h"
#include "beamsim/body_shape.h"
#include "scenes.h"
#include "thesis/thesis.h"
#include "support.h"

static const double h = 0.004;
static const double M_PI_VALUE = 3.14159265358979323846;
static const double zero[2] = {0.0, 0.0};

static bsim_world *make(const bsim_scene *s)
{
	bsim_world *w = NULL;
	bsim_error err;
	int rc = bsim_test_backend("thesis")->create(s, NULL, &w, &err);
	if (rc)
		fprintf(stderr, "%s\n", err.msg);
	assert_int_equal(rc, BSIM_OK);
	return w;
}

/* The one free beam along +x (scene_one_beam), contact at x = 12 on its
 * underside: n = (0, -1), t = (1, 0), the beam's levers c = -12, ct = 0.
 * The body's levers cb, cbt (contact point r_b from its centre), inertia J;
 * velocities v, w before. The hand solution of one impact: K P = -(q_n (1 +
 * e), q_t) for stick, else P_t = -mu s P_n, s the sign of the sliding
 * v_t'; returns 1 if it sticks. */
typedef struct hand_impact {
	double pn, pt, v[2], w, omega;
	int sticks;
} hand_impact;

static hand_impact solve_by_hand(double mass, double inertia, double ib, double cb, double cbt,
                                 const double v[2], double w, double e, double mu)
{
	const double c = -12.0;
	double vn = -v[1] + w * cb, vt = v[0] + w * cbt;
	double knn = 1.0 / mass + cb * cb / inertia + c * c / ib;
	double ktt = 1.0 / mass + cbt * cbt / inertia, knt = cb * cbt / inertia;
	double bn = -(1.0 + e) * vn, bt = -vt;
	double det = knn * ktt - knt * knt;
	hand_impact r;
	r.pn = (bn * ktt - knt * bt) / det;
	r.pt = (knn * bt - knt * bn) / det;
	r.sticks = fabs(r.pt) <= mu * r.pn;
	if (!r.sticks) {
		/* slide: the sign of v_t' that P_t = -mu s P_n leaves */
		for (int s = -1; s <= 1; s += 2) {
			double pn = bn / (knn - mu * s * knt), pt = -mu * s * pn;
			double vt_after = vt + knt * pn + ktt * pt;
			if (vt_after * s >= 0.0) {
				r.pn = pn;
				r.pt = pt;
				break;
			}
		}
	}
	r.v[0] = v[0] + r.pt / mass;
	r.v[1] = v[1] - r.pn / mass;
	r.w = w + (r.pn * cb + r.pt * cbt) / inertia;
	r.omega = -r.pn * c / ib;
	return r;
}

/* One step from the scene; the state after, and the world's count of
 * scaled impacts. */
static void step_once(const bsim_scene *s, bsim_state *st, long *scaled)
{
	bsim_world *w = make(s);
	assert_int_equal(bsim_backend_step(bsim_test_backend("thesis"), w, zero, 0.0, h, NULL),
	                 BSIM_OK);
	bsim_test_backend("thesis")->get_state(w, st);
	*scaled = w->impacts_scaled;
	bsim_test_backend("thesis")->destroy(w);
}

static double worst_error; /* m/s, rad/s: the largest difference from the hand solution */

static void check_against_hand(const bsim_state *st, const hand_impact *r, double scale)
{
	double tol = 1e-12 * scale;
	worst_error = fmax(worst_error, fabs(st->v[0] - r->v[0]));
	worst_error = fmax(worst_error, fabs(st->v[1] - r->v[1]));
	worst_error = fmax(worst_error, fabs(st->angular_velocity - r->w));
	worst_error = fmax(worst_error, fabs(st->omega[0] - r->omega));
	assert_true(fabs(st->v[0] - r->v[0]) < tol);
	assert_true(fabs(st->v[1] - r->v[1]) < tol);
	assert_true(fabs(st->angular_velocity - r->w) < tol);
	assert_true(fabs(st->omega[0] - r->omega) < tol);
}

/* A turning disk of radius 10: r_b = (0, 10), cb = 0, cbt = -10. */
static void disk_case(double vx, double w0, double mu, int expect_stick)
{
	const double e = 0.7, u = 2.0, radius = 10.0;
	bsim_scene s;
	scene_one_beam(&s);
	s.body.rotates = 1;
	s.body.angular_velocity = w0;
	s.contact.restitution = e;
	s.contact.friction = mu;
	s.body.start[0] = 12.0;
	s.body.start[1] = -radius - 1e-9;
	s.body.velocity[0] = vx;
	s.body.velocity[1] = u;
	double v[2] = {vx, u};
	hand_impact r = solve_by_hand(s.body.mass, bsim_body_inertia(&s.body), s.beams[0].inertia,
	                              0.0, -radius, v, w0, e, mu);
	assert_int_equal(r.sticks, expect_stick);
	bsim_state st;
	bsim_state_init(&st, 1);
	long scaled;
	step_once(&s, &st, &scaled);
	check_against_hand(&st, &r, 10.0);
	if (expect_stick) /* the contact point moves with the beam's: v_t' = 0 */
		assert_true(fabs(st.v[0] - radius * st.angular_velocity) < 1e-12 * 10);
	else /* the cone's edge */
		assert_true(fabs(fabs(r.pt) - mu * r.pn) < 1e-15 * r.pn);
	assert_int_equal(scaled, 0);
	assert_true(st.energy.impact > 0.0);
	bsim_state_free(&st);
	bsim_scene_free(&s);
}

static void test_disk_stick_slide(void **state)
{
	(void)state;
	disk_case(0.3, 0.0, 0.5, 1);
	disk_case(3.0, 0.0, 0.5, 0);
	disk_case(-2.0, 0.1, 0.2, 0);
	disk_case(0.5, 0.08, 0.3, 1);
}

/* A capsule (r = 2, l = 8) at heading 20 deg touching with its upper cap:
 * r_b = ((l/2) cos psi, (l/2) sin psi + r), cb = -(l/2) cos psi, cbt =
 * -((l/2) sin psi + r): the rows are coupled (K_nt = cb cbt / J). */
static void capsule_case(double vx, double w0, double mu, int expect_stick)
{
	const double r = 2.0, l = 8.0, psi = 20.0 * M_PI_VALUE / 180.0, e = 0.5, u = 1.5;
	bsim_scene s;
	scene_one_beam(&s);
	s.body.shape = BSIM_SHAPE_CAPSULE;
	s.body.radius = r;
	s.body.length = l;
	s.body.heading_deg = 20.0;
	s.body.rotates = 1;
	s.body.angular_velocity = w0;
	s.contact.restitution = e;
	s.contact.friction = mu;
	s.body.start[0] = 12.0 - 0.5 * l * cos(psi);
	s.body.start[1] = -r - 1e-9 - 0.5 * l * sin(psi);
	s.body.velocity[0] = vx;
	s.body.velocity[1] = u;
	double v[2] = {vx, u};
	double cb = -0.5 * l * cos(psi), cbt = -(0.5 * l * sin(psi) + r);
	hand_impact hr = solve_by_hand(s.body.mass, bsim_body_inertia(&s.body), s.beams[0].inertia,
	                               cb, cbt, v, w0, e, mu);
	assert_int_equal(hr.sticks, expect_stick);
	bsim_state st;
	bsim_state_init(&st, 1);
	long scaled;
	step_once(&s, &st, &scaled);
	assert_int_equal(scaled, 0);
	check_against_hand(&st, &hr, 10.0);
	double vt_after = st.v[0] + st.angular_velocity * cbt;
	if (expect_stick)
		assert_true(fabs(vt_after) < 1e-12 * 10);
	else
		assert_true(fabs(fabs(hr.pt) - mu * hr.pn) < 1e-15 * hr.pn);
	assert_true(st.energy.impact > 0.0);
	bsim_state_free(&st);
	bsim_scene_free(&s);
}

static void test_capsule_stick_slide(void **state)
{
	(void)state;
	capsule_case(0.1, 0.0, 0.8, 1);
	capsule_case(1.2, 0.0, 0.3, 0);
	capsule_case(-1.0, 0.2, 0.2, 0);
	printf("stick and slide impacts (disk, capsule): largest difference from the hand "
	       "solution %.3g (m/s, rad/s)\n",
	       worst_error);
}

/* A capsule (r = 2, l = 8, lying along x; turning or not) pressed up
 * against the beam along +x (stiff spring, damper) by F = (F_x, F_y): at
 * rest within the cone (|F_x| <= mu F_y: static friction holds it, the
 * body does not move along the beam), sliding outside it with the
 * acceleration (F_x - mu F_n) / M. F_n is F_y to within the beam's
 * response to the moving contact: its deflection under the body, F_y s^2 /
 * k, grows as the contact slides out along it (s from 12 m to 14 m), and
 * its damper resists that, which changes F_n by a few parts in 1e3
 * (tolerance 5e-3). */
static void press_case(double ratio, int rotates, double *accel, double *drift)
{
	const double mu = 0.4, fy = 10.0;
	bsim_scene s;
	scene_one_beam(&s);
	s.beams[0].stiffness = 1e6;
	s.beams[0].damping = 5e3;
	s.body.shape = BSIM_SHAPE_CAPSULE;
	s.body.radius = 2.0;
	s.body.length = 8.0;
	s.body.heading_deg = 0.0;
	s.body.rotates = rotates;
	s.contact.friction = mu;
	s.body.start[0] = 12.0;
	s.body.start[1] = -2.0 - 1e-9;
	bsim_world *w = make(&s);
	bsim_state st;
	bsim_state_init(&st, 1);
	const double f[2] = {ratio * mu * fy, fy};
	/* settle under the normal force alone, then push along */
	const double fn[2] = {0.0, fy};
	for (int k = 0; k < 500; k++)
		assert_int_equal(
		        bsim_backend_step(bsim_test_backend("thesis"), w, fn, 0.0, h, NULL),
		        BSIM_OK);
	bsim_test_backend("thesis")->get_state(w, &st);
	bsim_contact_flags(&s, &st);
	double x0 = st.x[0];
	int n = 250;
	double v_mid = 0.0;
	for (int k = 0; k < 2 * n; k++) {
		assert_int_equal(bsim_backend_step(bsim_test_backend("thesis"), w, f, 0.0, h, NULL),
		                 BSIM_OK);
		if (k == n - 1) {
			bsim_test_backend("thesis")->get_state(w, &st);
			bsim_contact_flags(&s, &st);
			v_mid = st.v[0];
		}
	}
	bsim_test_backend("thesis")->get_state(w, &st);
	bsim_contact_flags(&s, &st);
	*accel = (st.v[0] - v_mid) / (n * h);
	*drift = st.x[0] - x0;
	/* A capsule that turns stands on both ends of its core: held, it does
	 * not rock; sliding, it turns only with the beam under it, whose angle
	 * F_y s / k grows as the contact slides out: F_y v / k ~ 4e-5 rad/s. */
	assert_true(fabs(st.angular_velocity) < (fabs(ratio) <= 1.0 ? 1e-9 : 1e-4));
	assert_true(st.solver.iteration_limit == 0);
	assert_true(st.contact[0] != BSIM_CONTACT_NONE); /* still pressed on the beam */
	bsim_test_backend("thesis")->destroy(w);
	bsim_state_free(&st);
	bsim_scene_free(&s);
}

static void test_persistent_hold_slide(void **state)
{
	(void)state;
	const double mu = 0.4, fy = 10.0;
	for (int rotates = 0; rotates <= 1; rotates++) {
		double accel, drift;
		press_case(0.5, rotates, &accel, &drift);
		printf("%s, inside the cone (F_x = 0.5 mu F_y): drift %.3g m, acceleration %.3g "
		       "m/s^2\n",
		       rotates ? "turning" : "not turning", drift, accel);
		/* Held: no acceleration. A capsule that turns carries the
		 * friction's moment R F_x by unequal loads on its two ends,
		 * which turn the stiff beam by about dF s / k ~ 1e-5 rad and
		 * the capsule with it: its centre moves by about R times that
		 * once, then stays. */
		double hold = rotates ? 1e-4 : 1e-9;
		assert_true(fabs(drift) < hold);
		assert_true(fabs(accel) < 1e-9);
		press_case(-0.9, rotates, &accel, &drift);
		assert_true(fabs(drift) < hold);
		assert_true(fabs(accel) < 1e-9);
		press_case(1.5, rotates, &accel, &drift);
		double expect = (1.5 * mu * fy - mu * fy) / 1.0;
		printf("%s, outside (F_x = 1.5 mu F_y): acceleration %.6g m/s^2, (F_x - mu F_y)/M "
		       "= "
		       "%.6g\n",
		       rotates ? "turning" : "not turning", accel, expect);
		assert_true(fabs(accel - expect) < 5e-3 * expect);
		assert_true(drift > 0.0);
		press_case(-1.2, rotates, &accel, &drift);
		assert_true(fabs(accel - (-1.2 * mu * fy + mu * fy)) < 5e-3 * 0.2 * mu * fy);
	}
}

/* A deterministic uniform in [0, 1) (a 64-bit LCG's top bits). */
static double uniform(uint64_t *s)
{
	*s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
	return (double)(*s >> 11) * (1.0 / 9007199254740992.0);
}

/* Seeded random impacts of a turning capsule on the free beam (random
 * heading, place along the beam including past the tip, velocity, spin,
 * beam omega, e in [0, 1], mu in [0, 1.5]): the kinetic energy after the
 * step never exceeds that before (nothing else acts), and energy.impact is
 * what was lost, >= 0. */
static void test_no_energy_created(void **state)
{
	(void)state;
	uint64_t seed = 26;
	int cases = 0, met = 0, two_point = 0;
	long scaled = 0;
	double worst = -INFINITY;
	for (int k = 0; k < 3000; k++) {
		bsim_scene s;
		scene_one_beam(&s);
		s.body.shape = BSIM_SHAPE_CAPSULE;
		s.body.radius = 1.0 + 2.0 * uniform(&seed);
		s.body.length = 2.0 + 10.0 * uniform(&seed);
		/* every 4th lies along the beam: two contacts with it */
		s.body.heading_deg = k % 4 == 0 ? 180.0 * (k % 8 == 0) : 360.0 * uniform(&seed);
		s.body.rotates = 1;
		s.body.angular_velocity = 2.0 * uniform(&seed) - 1.0;
		s.contact.restitution = k % 7 == 0 ? 1.0 : uniform(&seed);
		s.contact.tip_restitution = k % 5 == 0 ? 1.0 : uniform(&seed);
		s.contact.friction = k % 11 == 0 ? 0.0 : 1.5 * uniform(&seed);
		s.beams[0].initial_omega = 0.2 * uniform(&seed) - 0.1;
		/* a point beside the beam (below or above), then moved along -n
		 * until the outline touches */
		double x[2] = {-5.0 + 35.0 * uniform(&seed), 0.0};
		double side = uniform(&seed) < 0.5 ? -1.0 : 1.0;
		x[1] = side * (bsim_body_shape_reach(&s.body) + 0.5);
		double psi = bsim_body_heading(&s.body), p0[2] = {0.0, 0.0}, p1[2] = {25.0, 0.0};
		bsim_body_segment_contact bc;
		if (bsim_body_shape_segment(&s.body, x, psi, p0, p1, &bc) != BSIM_OK ||
		    bc.dist > 20.0) {
			bsim_scene_free(&s);
			continue;
		}
		double shift = bc.dist + 1e-9;
		x[0] -= shift * bc.n[0];
		x[1] -= shift * bc.n[1];
		s.body.start[0] = x[0];
		s.body.start[1] = x[1];
		double speed = 0.2 + 3.0 * uniform(&seed), ang = 2.0 * M_PI_VALUE * uniform(&seed);
		/* approaching: against the normal, plus a random part */
		double side_part = k % 4 == 0 ? 0.0 : 0.7; /* flat: straight on, both ends */
		s.body.velocity[0] = -speed * bc.n[0] + side_part * speed * cos(ang);
		s.body.velocity[1] = -speed * bc.n[1] + side_part * speed * sin(ang);
		if (k % 4 == 0)
			s.body.angular_velocity = 0.0;
		bsim_world *w = make(&s);
		bsim_state st;
		bsim_state_init(&st, 1);
		bsim_test_backend("thesis")->get_state(w, &st);
		double j = bsim_body_inertia(&s.body), ib = s.beams[0].inertia;
		double e0 = 0.5 * (st.v[0] * st.v[0] + st.v[1] * st.v[1]) +
		            0.5 * j * st.angular_velocity * st.angular_velocity +
		            0.5 * ib * s.beams[0].initial_omega * s.beams[0].initial_omega;
		assert_int_equal(
		        bsim_backend_step(bsim_test_backend("thesis"), w, zero, 0.0, h, NULL),
		        BSIM_OK);
		bsim_test_backend("thesis")->get_state(w, &st);
		double e1 = 0.5 * (st.v[0] * st.v[0] + st.v[1] * st.v[1]) +
		            0.5 * j * st.angular_velocity * st.angular_velocity +
		            0.5 * ib * st.omega[0] * st.omega[0];
		cases++;
		met += st.impacts > 0;
		two_point += st.impacts == 2; /* one beam, both ends of the core */
		scaled += w->impacts_scaled;
		worst = fmax(worst, (e1 - e0) / e0);
		assert_true(e1 <= e0 * (1.0 + 1e-12));
		assert_true(st.energy.impact >= -1e-12 * e0);
		bsim_test_backend("thesis")->destroy(w);
		bsim_state_free(&st);
		bsim_scene_free(&s);
	}
	printf("%d impacts tried, %d met the beam (%d on two points), %ld scaled toward plastic; "
	       "largest relative energy change %.3g\n",
	       cases, met, two_point, scaled, worst);
	assert_true(met > cases / 2);
	assert_true(two_point > 100);
}

/* bsim_thesis_contact_solve on random problems of 1 to 4 contacts (the body's
 * mass and inertia, normals, body and beam levers, beams' inertias, free
 * velocities and mu drawn at random; K built by the solver from them):
 * every solution meets the conditions it solves, checked here from the
 * impulses alone: P_n >= 0, u_n >= 0, P_n u_n = 0, |P_t| <= mu P_n, stick
 * (u_t = 0) inside the cone, P_t = -mu P_n sign(u_t) on its edge; the
 * solver reports each solve exact. 5 contacts: not exact, and said so. */
static void test_solve_conditions(void **state)
{
	(void)state;
	uint64_t seed = 11;
	int solved = 0, sliding = 0, sticking = 0;
	for (int k = 0; k < 4000; k++) {
		int n = 1 + k % 4;
		thesis_contact cs[5];
		double inv_mass = 0.5 + uniform(&seed), inv_j = 0.05 * uniform(&seed);
		for (int i = 0; i < n; i++) {
			double a = 2.0 * 3.14159265358979 * uniform(&seed);
			memset(&cs[i], 0, sizeof cs[i]);
			cs[i].beam = i; /* one contact a beam */
			cs[i].n[0] = cos(a);
			cs[i].n[1] = sin(a);
			cs[i].cb = 10.0 * uniform(&seed) - 5.0;
			cs[i].cbt = 10.0 * uniform(&seed) - 5.0;
			cs[i].c = 30.0 * uniform(&seed) - 15.0;
			cs[i].ct = 4.0 * uniform(&seed) - 2.0;
			cs[i].inv_i = 0.05 * uniform(&seed);
			cs[i].vrel = 4.0 * uniform(&seed) - 3.0;
			cs[i].bound = uniform(&seed) < 0.5 ? 0.0 : 0.8 * fmax(-cs[i].vrel, 0.0);
			cs[i].vrel_t = 4.0 * uniform(&seed) - 2.0;
			cs[i].mu = uniform(&seed) < 0.1 ? 0.0 : 1.5 * uniform(&seed);
		}
		assert_int_equal(bsim_thesis_contact_solve(inv_mass, inv_j, cs, n), 0);
		/* the contact velocities after, from the impulses: v, w and
		 * each beam's omega (one beam per contact) */
		double jv[2] = {0.0, 0.0}, jw = 0.0;
		for (int i = 0; i < n; i++) {
			jv[0] += cs[i].impulse * cs[i].n[0] - cs[i].impulse_t * cs[i].n[1];
			jv[1] += cs[i].impulse * cs[i].n[1] + cs[i].impulse_t * cs[i].n[0];
			jw += cs[i].impulse * cs[i].cb + cs[i].impulse_t * cs[i].cbt;
		}
		for (int i = 0; i < n; i++) {
			const thesis_contact *c = &cs[i];
			double jb = c->impulse * c->c + c->impulse_t * c->ct;
			double un = c->vrel - c->bound +
			            (jv[0] * c->n[0] + jv[1] * c->n[1]) * inv_mass +
			            jw * c->cb * inv_j + jb * c->c * c->inv_i;
			double ut = c->vrel_t + (jv[1] * c->n[0] - jv[0] * c->n[1]) * inv_mass +
			            jw * c->cbt * inv_j + jb * c->ct * c->inv_i;
			double tol = 1e-9;
			assert_true(c->impulse >= 0.0);
			assert_true(un >= -tol);
			assert_true(c->impulse * un <= tol * (1.0 + c->impulse));
			assert_true(fabs(c->impulse_t) <=
			            c->mu * c->impulse * (1.0 + 1e-9) + 1e-15);
			if (c->impulse > 1e-9 && c->mu > 0.0) {
				if (fabs(c->impulse_t) < c->mu * c->impulse * (1.0 - 1e-9)) {
					assert_true(fabs(ut) <= tol);
					sticking++;
				} else if (fabs(ut) > tol) {
					assert_true(c->impulse_t * ut < 0.0);
					sliding++;
				}
			}
		}
		solved++;
	}
	printf("%d problems of 1-4 contacts solved exactly: %d contacts sticking, %d sliding\n",
	       solved, sticking, sliding);
	assert_true(sticking > 100 && sliding > 100);
	/* 5 contacts: beyond the enumeration, the approximation is reported */
	thesis_contact cs[5];
	for (int i = 0; i < 5; i++) {
		memset(&cs[i], 0, sizeof cs[i]);
		cs[i].n[0] = cos(i), cs[i].n[1] = sin(i);
		cs[i].c = 1.0, cs[i].inv_i = 0.1, cs[i].vrel = -1.0, cs[i].mu = 0.5;
	}
	assert_int_equal(bsim_thesis_contact_solve(1.0, 0.1, cs, 5), 1);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_disk_stick_slide),
	        cmocka_unit_test(test_capsule_stick_slide),
	        cmocka_unit_test(test_persistent_hold_slide),
	        cmocka_unit_test(test_no_energy_created),
	        cmocka_unit_test(test_solve_conditions),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
