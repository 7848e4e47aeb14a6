/* A body that turns and has a shape, and the effects that turn it, against
 * closed forms: spinning friction's stop angle omega0^2 / (2 alpha), a
 * sliding capsule's Coulomb stopping distance v^2 / (2 mu g), angular
 * drag's decay omega0 exp(-c_w t / J), a free capsule's constant angular
 * momentum and energy, propulsion along the heading, the ledger with
 * rotation, drag and friction; the footprint's mean arm against a grid
 * sum; Box2D's ellipse against the true outline (its shape error and the
 * contact flag's gap); a capsule and an ellipse through the essay's gate.
 * Every case runs on every backend of the registry, but the outline of
 * Box2D's ellipse (its own polygon); a backend that does not simulate a
 * turning body refuses the scene at creation, and the case is skipped for
 * it, saying so. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "beamsim/contact_flag.h"
#include "beamsim/effects.h"
#include "beamsim/trial.h"
#include "box2d/box2d_shape.h"
#include "scenes.h"
#include "support.h"

#define PI 3.14159265358979323846

/* A capsule (R = 4 m, L = 12 m) or an ellipse (a = 10 m, b = 5 m) of 2 kg
 * that turns, far below the one beam of scene_one_beam. */
static void scene_turning(bsim_scene *s, bsim_body_shape shape)
{
	scene_one_beam(s);
	s->body.mass = 2.0;
	s->body.shape = shape;
	s->body.rotates = 1;
	if (shape == BSIM_SHAPE_CAPSULE) {
		s->body.radius = 4.0;
		s->body.length = 12.0;
	} else if (shape == BSIM_SHAPE_ELLIPSE) {
		s->body.radius = 0.0;
		s->body.semi_axes[0] = 10.0;
		s->body.semi_axes[1] = 5.0;
	}
	s->side_x = 1000.0;
}

/* Runs trial seed of s on be into out. If be refuses the scene when it
 * creates the world (a backend that does not simulate a turning body: its
 * own message, naming it), frees s and skips the test of be. */
static void run_seed(const bsim_backend *be, bsim_scene *s, uint64_t seed, const bsim_recorder *rec,
                     bsim_trial_result *out)
{
	bsim_error err;
	bsim_trial_runner *r = bsim_trial_runner_alloc();
	const bsim_options o = bsim_test_body_options(be, &s->body);
	int rc = bsim_trial_run(r, s, be, &o, seed, rec, out, &err);
	bsim_trial_runner_free(r);
	if (rc == BSIM_EINPUT && strncmp(err.msg, be->name, strlen(be->name)) == 0) {
		bsim_scene_free(s);
		bsim_test_skip(be, "it refuses the scene: %s", err.msg);
	}
	assert_int_equal(rc, BSIM_OK);
}

static void run_on(const bsim_backend *be, bsim_scene *s, const bsim_recorder *rec,
                   bsim_trial_result *out)
{
	run_seed(be, s, 1, rec, out);
}

typedef struct spin_track {
	double h;
	double psi0, psi_stop, w0;
	long stop_step;
	double after; /* max |omega| after the stop */
	double x_moved;
} spin_track;

static void track_spin(void *user, long step, const bsim_state *s)
{
	spin_track *t = user;
	if (t->stop_step < 0 && fabs(s->angular_velocity) < 1e-5 * t->w0) {
		t->stop_step = step;
		t->psi_stop = s->heading;
	} else if (t->stop_step >= 0) {
		t->after = fmax(t->after, fabs(s->angular_velocity));
	}
	t->x_moved = fmax(t->x_moved, fabs(s->v[0]) + fabs(s->v[1]));
}

/* The footprint's mean distance from the centre, (1/A) integral |r| dA, by
 * a midpoint grid of n x n cells over the bounding box: the truth the
 * quadrature of bsim_effects_spin_arm is checked against. */
static double arm_grid(const bsim_body_def *b, int n)
{
	double hx, hy;
	if (b->shape == BSIM_SHAPE_CAPSULE) {
		hx = b->length / 2 + b->radius;
		hy = b->radius;
	} else {
		hx = b->semi_axes[0];
		hy = b->semi_axes[1];
	}
	double sum = 0.0, area = 0.0, cell = (2 * hx / n) * (2 * hy / n);
	for (int i = 0; i < n; i++)
		for (int j = 0; j < n; j++) {
			double x = -hx + (i + 0.5) * 2 * hx / n, y = -hy + (j + 0.5) * 2 * hy / n;
			int in;
			if (b->shape == BSIM_SHAPE_CAPSULE) {
				double dx = fmax(fabs(x) - b->length / 2, 0.0);
				in = dx * dx + y * y <= b->radius * b->radius;
			} else {
				in = x * x / (hx * hx) + y * y / (hy * hy) <= 1.0;
			}
			if (in) {
				sum += hypot(x, y) * cell;
				area += cell;
			}
		}
	return sum / area;
}

/* The footprint's arm: a disk's 2R/3 in closed form; a capsule's and an
 * ellipse's quadrature against a 2000 x 2000 grid sum (whose own error is
 * ~1e-4 relative: cells cut by the outline), and a circle's limits (an
 * ellipse with a = b, a capsule of tiny length) against 2R/3. */
static void test_spin_arm(void **state)
{
	(void)state;
	bsim_body_def b = bsim_body_def_default();
	b.radius = 3.0;
	assert_true(fabs(bsim_effects_spin_arm(&b) - 2.0) < 1e-15);
	b.shape = BSIM_SHAPE_CAPSULE;
	b.radius = 4.0;
	b.length = 12.0;
	double q = bsim_effects_spin_arm(&b), g = arm_grid(&b, 2000);
	assert_true(fabs(q - g) < 3e-4 * g);
	b.length = 1e-9;
	assert_true(fabs(bsim_effects_spin_arm(&b) - 8.0 / 3.0) < 1e-8);
	b.shape = BSIM_SHAPE_ELLIPSE;
	b.radius = 0.0;
	b.length = 0.0;
	b.semi_axes[0] = 10.0;
	b.semi_axes[1] = 5.0;
	q = bsim_effects_spin_arm(&b);
	g = arm_grid(&b, 2000);
	assert_true(fabs(q - g) < 3e-4 * g);
	b.semi_axes[1] = 10.0;
	assert_true(fabs(bsim_effects_spin_arm(&b) - 20.0 / 3.0) < 1e-10);
}

/* A body spinning in place at omega0 = 3 rad/s with ground friction mu = 0.4
 * on Box2D: the friction torque is mu g M r_s (r_s the footprint's mean arm),
 * so omega falls by alpha = mu g M r_s / J a second and the body turns
 * omega0^2 / (2 alpha) before it stops, at t = omega0 / alpha, and then
 * stays still (exact stick). Box2D's turn is symplectic Euler: within
 * h omega0 of the continuous angle; its float32 omega reaches 0 within two
 * steps. For the disk, r_s = 2R/3 and J = M R^2 / 2 in closed form. */
static void test_spin_stop_angle(void **state)
{
	const bsim_backend *be = *state;
	const bsim_body_shape shapes[] = {BSIM_SHAPE_DISK, BSIM_SHAPE_CAPSULE, BSIM_SHAPE_ELLIPSE};
	for (int k = 0; k < 3; k++) {
		bsim_scene s;
		scene_turning(&s, shapes[k]);
		s.body.angular_velocity = 3.0;
		s.effects.has_ground_friction = 1;
		s.effects.ground_mu = 0.4;
		s.max_steps = 2000; /* 8 s: the disk stops at 5.7 s */
		bsim_error err;
		assert_int_equal(bsim_scene_validate(&s, &err), BSIM_OK);
		double J = bsim_body_inertia(&s.body), arm = bsim_effects_spin_arm(&s.body);
		if (k == 0) {
			assert_true(fabs(J - 2.0 * 100.0 / 2.0) < 1e-12);
			arm = 2.0 * 10.0 / 3.0;
		}
		double alpha = 0.4 * 9.81 * 2.0 * arm / J;
		{
			spin_track t = {.h = s.dt,
			                .psi0 = bsim_body_heading(&s.body),
			                .w0 = 3.0,
			                .stop_step = -1};
			bsim_recorder rec = {.trace = track_spin, .trace_user = &t};
			bsim_trial_result out;
			run_on(be, &s, &rec, &out);
			assert_int_equal(out.instability, BSIM_STABLE);
			assert_true(t.stop_step > 0);
			assert_true(fabs(t.stop_step * s.dt - 3.0 / alpha) <= 2 * s.dt);
			double angle = t.psi_stop - t.psi0, truth = 9.0 / (2.0 * alpha);
			assert_true(fabs(angle - truth) < 3.0 * s.dt);
			printf("spin stop %s %d: t %.4f s (truth %.4f), angle %.5f rad (truth "
			       "%.5f), "
			       "|omega| after %.2g, moved %.2g\n",
			       be->name, k, t.stop_step * s.dt, 3.0 / alpha, angle, truth, t.after,
			       t.x_moved);
			assert_true(t.after < 1e-5 * 3.0); /* float32's residue of the stop */
			assert_true(t.x_moved == 0.0);     /* spinning gives no net force */
			/* the rotational energy is the friction's loss */
			double e0 = 0.5 * J * 9.0;
			assert_true(fabs(out.ledger.e_start - e0) < 1e-9 * e0);
			assert_true(fabs(out.ledger.friction - e0) < 0.02 * e0);
		}
		bsim_scene_free(&s);
	}
}

typedef struct slide_track {
	double x0[2];
	double dist_stop;
	long stop_step;
} slide_track;

static void track_slide(void *user, long step, const bsim_state *s)
{
	slide_track *t = user;
	if (t->stop_step < 0 && s->v[0] == 0.0 && s->v[1] == 0.0) {
		t->stop_step = step;
		t->dist_stop = hypot(s->x[0] - t->x0[0], s->x[1] - t->x0[1]);
	}
}

/* A capsule that turns, sliding at 5 m/s without spin, mu = 0.5 on Box2D:
 * it stops v0^2 / (2 mu g) from its start (within v0 h) and does not turn
 * (the footprint is symmetric: no torque). */
static void test_capsule_stopping_distance(void **state)
{
	const bsim_backend *be = *state;
	bsim_scene s;
	scene_turning(&s, BSIM_SHAPE_CAPSULE);
	s.body.heading_deg = 30.0;
	s.body.velocity[0] = 3.0;
	s.body.velocity[1] = -4.0;
	s.effects.has_ground_friction = 1;
	s.effects.ground_mu = 0.5;
	s.max_steps = 500;
	bsim_error err;
	assert_int_equal(bsim_scene_validate(&s, &err), BSIM_OK);
	slide_track t = {.x0 = {s.body.start[0], s.body.start[1]}, .stop_step = -1};
	bsim_recorder rec = {.trace = track_slide, .trace_user = &t};
	bsim_trial_result out;
	run_on(be, &s, &rec, &out);
	const double mu_g = 0.5 * 9.81;
	assert_true(t.stop_step > 0);
	assert_true(fabs(t.dist_stop - 25.0 / (2.0 * mu_g)) < 5.0 * s.dt);
	assert_true(fabs(out.ledger.friction - 25.0) < 0.02 * 25.0);
	bsim_scene_free(&s);
}

typedef struct decay_track {
	double h, w0, rate;
	double err;
	double L0[2]; /* angular momentum about the origin, energy at step 0 */
	double L_err, E_err;
	double mass, J;
} decay_track;

static void track_decay(void *user, long step, const bsim_state *s)
{
	decay_track *t = user;
	double truth = t->w0 * exp(-t->rate * step * t->h);
	t->err = fmax(t->err, fabs(s->angular_velocity - truth) / t->w0);
	double L = t->mass * (s->x[0] * s->v[1] - s->x[1] * s->v[0]) + t->J * s->angular_velocity;
	double E = 0.5 * t->mass * (s->v[0] * s->v[0] + s->v[1] * s->v[1]) +
	           0.5 * t->J * s->angular_velocity * s->angular_velocity;
	if (step == 0) {
		t->L0[0] = L;
		t->L0[1] = E;
	}
	t->L_err = fmax(t->L_err, fabs(L - t->L0[0]) / fabs(t->L0[0]));
	t->E_err = fmax(t->E_err, fabs(E - t->L0[1]) / t->L0[1]);
}

/* Angular drag c_w = 30 N m s/rad on a turning ellipse (J = 62.5 kg m^2)
 * spinning at 4 rad/s on Box2D: omega(t) = omega0 exp(-c_w t / J) at every
 * step (the update is exact; float32 aside); the ledger books the energy
 * lost as drag and closes. */
static void test_angular_drag_decay(void **state)
{
	const bsim_backend *be = *state;
	bsim_scene s;
	scene_turning(&s, BSIM_SHAPE_ELLIPSE);
	s.body.angular_velocity = 4.0;
	s.effects.has_drag = 1;
	s.effects.drag_angular = 30.0;
	s.max_steps = 1000;
	bsim_error err;
	assert_int_equal(bsim_scene_validate(&s, &err), BSIM_OK);
	double J = bsim_body_inertia(&s.body);
	assert_true(fabs(J - 2.0 * (100.0 + 25.0) / 4.0) < 1e-12);
	{
		decay_track t = {.h = s.dt, .w0 = 4.0, .rate = 30.0 / J, .mass = 2.0, .J = J};
		bsim_recorder rec = {.trace = track_decay, .trace_user = &t};
		bsim_trial_result out;
		run_on(be, &s, &rec, &out);
		assert_true(t.err < 1e-5);
		double e0 = 0.5 * J * 16.0, e_end = e0 * exp(-2.0 * 30.0 / J * 4.0);
		assert_true(fabs(out.ledger.e_end - e_end) < 1e-4 * e0);
		assert_true(fabs(out.ledger.drag - (e0 - e_end)) < 0.01 * e0);
		assert_true(fabs(out.ledger.residual) < 0.01 * e0);
	}
	bsim_scene_free(&s);
}

/* A free capsule on Box2D, launched at (2, -1) m/s spinning at 1.5 rad/s
 * away from the beam, no effects: its angular momentum about the origin
 * M (x v_y - y v_x) + J omega and its kinetic energy stay what they were
 * (to float32's rounding of the positions), and the ledger's residual is
 * 0 to that. */
static void test_free_capsule_conserves(void **state)
{
	const bsim_backend *be = *state;
	bsim_scene s;
	scene_turning(&s, BSIM_SHAPE_CAPSULE);
	s.body.start[0] = 5.0;
	s.body.velocity[0] = 2.0;
	s.body.velocity[1] = -1.0;
	s.body.angular_velocity = 1.5;
	s.max_steps = 1000;
	bsim_error err;
	assert_int_equal(bsim_scene_validate(&s, &err), BSIM_OK);
	double J = bsim_body_inertia(&s.body);
	{
		decay_track t = {.h = s.dt, .w0 = 1.5, .rate = 0.0, .mass = 2.0, .J = J};
		bsim_recorder rec = {.trace = track_decay, .trace_user = &t};
		bsim_trial_result out;
		run_on(be, &s, &rec, &out);
		printf("%s free capsule: |L - L0| / L0 %.3g, |E - E0| / E0 %.3g, omega %.3g\n",
		       be->name, t.L_err, t.E_err, t.err);
		/* float32 positions: their rounding (7.6e-6 m at 100 m) a step over
		 * 1000 steps, times M |v| */
		assert_true(t.L_err < 1e-4);
		assert_true(t.E_err < 1e-5);
		assert_true(t.err < 1e-6); /* omega itself */
		assert_true(fabs(out.ledger.residual) < 1e-5 * out.ledger.e_start);
	}
	bsim_scene_free(&s);
}

typedef struct thrust_track {
	double h, accel, psi, x0[2];
	double err, scale;
} thrust_track;

static void track_thrust(void *user, long step, const bsim_state *s)
{
	thrust_track *t = user;
	double tt = step * t->h, d = 0.5 * t->accel * tt * tt;
	double ex = t->x0[0] + d * cos(t->psi), ey = t->x0[1] + d * sin(t->psi);
	t->err = fmax(t->err, hypot(s->x[0] - ex, s->x[1] - ey));
	t->scale = fmax(t->scale, d);
}

/* Propulsion F = 6 N along the heading 210 deg of a 2 kg body at rest
 * (a disk whose heading is fixed, on both backends; a capsule that turns,
 * on Box2D): x(t) = x0 + F t^2 / (2 M) (cos psi, sin psi) within
 * F h t / (2 M) (the backends' position updates, first order in h). */
static void test_propulsion_along_heading(void **state)
{
	const bsim_backend *be = *state;
	for (int k = 0; k < 3; k++) {
		bsim_scene s;
		scene_turning(&s, k == 2 ? BSIM_SHAPE_CAPSULE : BSIM_SHAPE_DISK);
		s.body.rotates = k == 2;
		s.body.heading_deg = 210.0;
		s.effects.has_propulsion = 1;
		s.effects.propulsion_force = 6.0;
		s.effects.propulsion_along = BSIM_ALONG_HEADING;
		s.max_steps = 500;
		s.success_y = 1e6;
		s.classify_y = 1e6;
		bsim_error err;
		assert_int_equal(bsim_scene_validate(&s, &err), BSIM_OK);
		bsim_test_skip_refused(be, &s); /* the last, k = 2, the capsule */
		thrust_track t = {.h = s.dt,
		                  .accel = 3.0,
		                  .psi = 210.0 * PI / 180.0,
		                  .x0 = {s.body.start[0], s.body.start[1]}};
		bsim_recorder rec = {.trace = track_thrust, .trace_user = &t};
		bsim_trial_runner *r = bsim_trial_runner_alloc();
		bsim_trial_result out;
		assert_int_equal(bsim_trial_run(r, &s, be, NULL, 1, &rec, &out, &err), BSIM_OK);
		double t_end = 500 * s.dt;
		assert_true(t.scale > 5.0);
		assert_true(t.err < 3.0 * s.dt * t_end * 1.01);
		/* the thrust's work is booked as w_prop, the ledger closes */
		assert_true(out.ledger.w_prop > 0.0);
		assert_true(fabs(out.ledger.residual) < 0.01 * out.ledger.w_prop);
		bsim_trial_runner_free(r);
		bsim_scene_free(&s);
	}
}

/* A capsule that slides and spins under thrust along its heading, linear
 * and angular drag and ground friction on Box2D: e_end - e_start = w_prop -
 * drag - friction - residual with the residual below 1% of the energy that
 * flowed; drag and friction are losses (>= 0). */
static void test_ledger_turning(void **state)
{
	const bsim_backend *be = *state;
	bsim_scene s;
	scene_turning(&s, BSIM_SHAPE_CAPSULE);
	s.body.velocity[0] = 3.0;
	s.body.angular_velocity = 2.0;
	s.effects.has_propulsion = 1;
	s.effects.propulsion_force = 12.0;
	s.effects.propulsion_along = BSIM_ALONG_HEADING;
	s.effects.has_drag = 1;
	s.effects.drag_linear = 0.5;
	s.effects.drag_angular = 4.0;
	s.effects.has_ground_friction = 1;
	s.effects.ground_mu = 0.2;
	s.max_steps = 1500;
	s.success_y = 1e6;
	s.classify_y = 1e6;
	bsim_error err;
	assert_int_equal(bsim_scene_validate(&s, &err), BSIM_OK);
	{
		bsim_trial_result out;
		run_on(be, &s, NULL, &out);
		const bsim_ledger *l = &out.ledger;
		assert_int_equal(out.instability, BSIM_STABLE);
		assert_true(l->drag > 0.0 && l->friction > 0.0 && l->w_prop > 0.0);
		double lhs = l->e_end - l->e_start, rhs = l->w_prop - l->drag - l->friction;
		assert_true(fabs(lhs - rhs - l->residual) < 1e-9 * l->inflow);
		assert_true(fabs(l->residual) < 0.01 * l->inflow);
	}
	bsim_scene_free(&s);
}

/* Box2D's ellipse (a = 10 m, b = 5 m, unit_scale 1): area within 0.1% and
 * outline within 2 cm of the true ellipse's (the figures are printed for
 * docs/backends.md). */
static void test_ellipse_outline(void **state)
{
	(void)state;
	double area_rel, dist;
	assert_int_equal(bsim_box2d_ellipse_error(10.0, 5.0, 1.0, &area_rel, &dist), BSIM_OK);
	printf("box2d ellipse a = 10 m, b = 5 m: area error %+.3g, max outline distance %.3g m\n",
	       area_rel, dist);
	assert_true(fabs(area_rel) < 1e-3);
	assert_true(dist < 0.02);
	/* the gate's ellipse of the disk's area */
	assert_int_equal(bsim_box2d_ellipse_error(12.5, 8.0, 1.0, &area_rel, &dist), BSIM_OK);
	printf("box2d ellipse a = 12.5 m, b = 8 m: area error %+.3g, max outline distance %.3g m\n",
	       area_rel, dist);
	assert_true(fabs(area_rel) < 1e-3);
	assert_true(dist < 0.02);
	assert_int_equal(bsim_box2d_ellipse_error(0.005, 5.0, 1.0, &area_rel, &dist), BSIM_EINPUT);
}

/* The contact flag reads the true outline, whatever polygon a backend
 * stands it in with (Box2D's, Chipmunk's): a beam 3 mm above the
 * ellipse's or the capsule's top (its support height at headings 0, 90
 * and 30 deg) is flagged, one 9 mm above is not. */
static void test_outline_flag(void **state)
{
	const bsim_backend *be = *state;
	/* The beam along y = 0 from x = -12.5 m to 12.5 m; the body's top at
	 * heading psi is its support height: sqrt(a^2 sin^2 psi + b^2 cos^2 psi)
	 * for the ellipse, R + (L/2) |sin psi| for the capsule. */
	const double gaps[] = {0.003, 0.009}, headings[] = {0.0, 90.0, 30.0};
	for (int k = 0; k < 2; k++)
		for (int h = 0; h < 3; h++)
			for (int g = 0; g < 2; g++) {
				bsim_scene s;
				scene_turning(&s, k ? BSIM_SHAPE_CAPSULE : BSIM_SHAPE_ELLIPSE);
				s.body.heading_deg = headings[h];
				s.beams[0].pivot[0] = -12.5;
				double psi = headings[h] * PI / 180.0, sn = sin(psi), cs = cos(psi);
				double top = k ? 4.0 + 6.0 * fabs(sn)
				               : sqrt(100.0 * sn * sn + 25.0 * cs * cs);
				s.body.start[0] = 0.0;
				s.body.start[1] = -top - gaps[g];
				bsim_error err;
				assert_int_equal(bsim_scene_validate(&s, &err), BSIM_OK);
				bsim_world *w = NULL;
				const bsim_options o = bsim_test_body_options(be, &s.body);
				if (be->create(&s, &o, &w, &err) != BSIM_OK) {
					/* a backend without turning shapes refuses them
					 * (test_disk_only_refused) */
					bsim_scene_free(&s);
					bsim_test_skip(be, "it refuses the shaped body: %s",
					               err.msg);
				}
				bsim_state st;
				assert_int_equal(bsim_state_init(&st, 1), BSIM_OK);
				be->get_state(w, &st);
				bsim_contact_flags(&s, &st);
				assert_int_equal(st.contact[0],
				                 g == 0 ? BSIM_CONTACT_TANGENT : BSIM_CONTACT_NONE);
				bsim_state_free(&st);
				be->destroy(w);
				bsim_scene_free(&s);
			}
}

typedef struct slip_track {
	long from, mid; /* the step the contact has settled by; halfway to the end */
	double x_from, x_mid, x_last;
	long last;
	int touching;
} slip_track;

/* Positions only: the contact's velocity jitters by mm/s in Box2D, the
 * mean velocities over the two halves do not. */
static void track_slip(void *user, long step, const bsim_state *s)
{
	slip_track *t = user;
	if (step == t->from)
		t->x_from = s->x[0];
	if (step == t->mid)
		t->x_mid = s->x[0];
	t->x_last = s->x[0];
	t->last = step;
	if (step >= t->from)
		t->touching &= s->contact[0] != BSIM_CONTACT_NONE;
}

/* Contact friction: a disk of 2 kg (heading fixed) under a thrust
 * F = 10 N along psi pressed against a stiff horizontal beam above it
 * (k = 1e6 N m/rad: it yields 1e-4 rad) with mu = 0.5. The friction along
 * the beam passes through its pivot, so the beam holds the normal push
 * F sin psi and the friction is at most mu F sin psi (the pair's
 * coefficient is mu exactly): at psi = 70 deg (tan psi > 1/mu) the body
 * sticks, x stays put; at 50 deg it slides with
 * a = F (cos psi - mu sin psi) / M, 1.299 m/s^2. */
static void test_contact_friction_stick_slip(void **state)
{
	const bsim_backend *be = *state;
	const double psis[] = {70.0, 50.0};
	for (int k = 0; k < 2; k++) {
		bsim_scene s;
		scene_one_beam(&s);
		s.body.mass = 2.0;
		s.body.radius = 2.0;
		s.beams[0].pivot[0] = -20.0;
		s.beams[0].length = 40.0;
		s.beams[0].inertia = 0.1 * 1600.0 / 3.0;
		s.beams[0].stiffness = 1e6;
		s.beams[0].damping = 100.0;
		s.body.start[0] = 0.0;
		s.body.start[1] = -2.001;
		s.body.heading_deg = psis[k];
		s.contact.friction = 0.5;
		s.effects.has_propulsion = 1;
		s.effects.propulsion_force = 10.0;
		s.effects.propulsion_along = BSIM_ALONG_HEADING;
		s.max_steps = 500;
		s.success_y = 1e6;
		s.classify_y = 1e6;
		bsim_error err;
		assert_int_equal(bsim_scene_validate(&s, &err), BSIM_OK);
		slip_track t = {.from = 100, .mid = 300, .touching = 1};
		bsim_recorder rec = {.trace = track_slip, .trace_user = &t};
		bsim_trial_result out;
		run_on(be, &s, &rec, &out);
		assert_int_equal(t.last, 500);
		assert_true(t.touching);
		double psi = psis[k] * PI / 180.0;
		double a = fmax(10.0 * (cos(psi) - 0.5 * sin(psi)) / 2.0, 0.0);
		double half = 200 * s.dt;
		double a_meas = ((t.x_last - t.x_mid) - (t.x_mid - t.x_from)) / (half * half);
		printf("%s contact friction psi %g deg: a_x %.5f m/s^2 (truth %.5f), moved %.3g "
		       "m\n",
		       be->name, psis[k], a_meas, a, t.x_last - t.x_from);
		/* where it sticks, the backend's bound "contact.stick" (m) on how
		 * far it still moves once the contact has settled */
		double stick;
		if (a == 0.0 && !bsim_backend_bound_of(be, "contact.stick", &stick)) {
			printf("%s: the stick not checked: it states no bound contact.stick\n",
			       be->name);
		} else {
			if (a == 0.0)
				assert_true(fabs(t.x_last - t.x_from) < stick);
			assert_true(fabs(a_meas - a) < 0.003); /* 0.2% of the sliding case's */
		}
		bsim_scene_free(&s);
	}
}

typedef struct momentum_track {
	double mass, J, beam_I;
	double L0, E0, L_err, E_last, L_last;
	double spun; /* max |omega| of the body, rad/s */
	int touched;
	/* The turn as the states say it, step by step: the trapezoid sum of
	 * omega over time (h the step, s), omega's total variation, and the
	 * heading's start, end and largest departure from the start. */
	double h, turned, w_var, w_last, psi0, psi_last, psi_far;
} momentum_track;

/* Angular momentum about the beam's pivot (the origin) and kinetic energy
 * of body and beam: the beam turns freely about the pivot (no spring), so
 * only the pin acts from outside, at the pivot. */
static void track_momentum(void *user, long step, const bsim_state *s)
{
	momentum_track *t = user;
	double L = t->mass * (s->x[0] * s->v[1] - s->x[1] * s->v[0]) + t->J * s->angular_velocity +
	           t->beam_I * s->omega[0];
	double E = 0.5 * t->mass * (s->v[0] * s->v[0] + s->v[1] * s->v[1]) +
	           0.5 * t->J * s->angular_velocity * s->angular_velocity +
	           0.5 * t->beam_I * s->omega[0] * s->omega[0];
	if (step == 0) {
		t->L0 = L;
		t->E0 = E;
	}
	t->L_err = fmax(t->L_err, fabs(L - t->L0));
	t->L_last = L;
	t->E_last = E;
	t->touched |= s->contact[0] != BSIM_CONTACT_NONE;
	t->spun = fmax(t->spun, fabs(s->angular_velocity));
	if (step == 0) {
		t->psi0 = s->heading;
	} else {
		t->turned += 0.5 * t->h * (t->w_last + s->angular_velocity);
		t->w_var += fabs(s->angular_velocity - t->w_last);
	}
	t->w_last = s->angular_velocity;
	t->psi_last = s->heading;
	t->psi_far = fmax(t->psi_far, fabs(s->heading - t->psi0));
}

/* A turning capsule (R = 2 m, L = 6 m, 2 kg, heading 30 deg) thrown at
 * 3 m/s up against a beam that turns freely about its pivot (no spring or
 * damper) hits it off-centre on Box2D. Only the pin acts from outside, at
 * the pivot: the angular momentum about it, M x x v + J omega + I theta',
 * is conserved through the impact, with friction or without. Elastic and
 * frictionless (e = 1, mu = 0), the kinetic energy is conserved too; with
 * mu = 0.5 and e = 0.8 it falls, and the ledger books the loss as impact
 * and contact (to 0.1%) and closes. The hit spins the capsule.
 *
 * The trial's turn (bsim_trial_result turn_end, turn_max, heading_end,
 * angular_velocity_end) against the states the trace saw: the end state's
 * heading and angular velocity to the bit, the largest |psi - psi0| to the
 * bit (at least |turn_end|), and turn_end = the integral of omega over the
 * trial, the trapezoid sum over the steps, within h/2 times omega's total
 * variation (a step's integrator may take omega anywhere between its
 * values at the step's ends, which differ by |d omega|: the symplectic
 * Euler of all three takes the end, and meets the bound) and a float32
 * heading's rounding, 2^-24 |psi| a step (Box2D's), that bound under 2% of
 * a turn of more than 0.5 rad. The same trial run with nothing recorded
 * (as a sweep runs it) gives the same four numbers. */
static void test_capsule_impact_conserves(void **state)
{
	const bsim_backend *be = *state;
	for (int k = 0; k < 2; k++) {
		bsim_scene s;
		scene_one_beam(&s);
		s.body.mass = 2.0;
		s.body.shape = BSIM_SHAPE_CAPSULE;
		s.body.radius = 2.0;
		s.body.length = 6.0;
		s.body.rotates = 1;
		s.body.heading_deg = 30.0;
		s.body.start[0] = 15.0;
		s.body.start[1] = -8.0;
		s.body.velocity[1] = 3.0;
		s.beams[0].mass = 10.0; /* I / r^2 = 9.3 kg at the hit, r = 15 m */
		s.beams[0].inertia = 10.0 * 625.0 / 3.0;
		s.contact.restitution = k ? 0.8 : 1.0;
		s.contact.tip_restitution = k ? 0.8 : 1.0;
		s.contact.friction = k ? 0.5 : 0.0;
		s.max_steps = 750;
		s.success_y = 1e6;
		s.classify_y = 1e6;
		bsim_error err;
		assert_int_equal(bsim_scene_validate(&s, &err), BSIM_OK);
		momentum_track t = {.mass = 2.0,
		                    .J = bsim_body_inertia(&s.body),
		                    .beam_I = s.beams[0].inertia,
		                    .h = s.dt};
		bsim_recorder rec = {.trace = track_momentum, .trace_user = &t};
		bsim_trial_result out, plain;
		run_on(be, &s, &rec, &out);
		run_on(be, &s, NULL, &plain);
		printf("%s capsule impact e = %g, mu = %g: max |L - L0| / |L0| %.3g, E_end / E0 "
		       "%.5f, ledger loss %.4g J of %.4g J lost, residual %.3g J, spin %.3g "
		       "rad/s\n",
		       be->name, s.contact.restitution, s.contact.friction, t.L_err / fabs(t.L0),
		       t.E_last / t.E0, out.ledger.impact + out.ledger.contact, t.E0 - t.E_last,
		       out.ledger.residual, t.spun);
		assert_true(t.touched);
		assert_true(t.spun > 0.1); /* the off-centre hit turns the capsule */
		assert_true(t.L_err < 1e-3 * fabs(t.L0));
		if (k == 0) {
			assert_true(fabs(t.E_last - t.E0) < 0.01 * t.E0);
		} else {
			assert_true(t.E_last < 0.95 * t.E0);
			double lost = t.E0 - t.E_last,
			       booked = out.ledger.impact + out.ledger.contact;
			assert_true(fabs(booked - lost) < 1e-3 * lost);
			assert_true(fabs(out.ledger.residual) < 1e-4 * t.E0);
		}
		/* the step sums' spread, and a float32 heading's rounding each
		 * step (Box2D's: 2^-24 |psi| at most) */
		double bound = 0.5 * s.dt * t.w_var +
		               (double)out.steps_run * ldexp(1.0, -24) * (fabs(t.psi0) + t.psi_far);
		printf("%s capsule impact e = %g, mu = %g: turn_end %.9g rad, trapezoid of omega "
		       "%.9g rad (bound %.6g), turn_max %.6g rad\n",
		       be->name, s.contact.restitution, s.contact.friction, out.turn_end, t.turned,
		       bound, out.turn_max);
		assert_true(out.heading_end == t.psi_last);
		assert_true(out.angular_velocity_end == t.w_last);
		assert_true(out.turn_end == t.psi_last - t.psi0);
		assert_true(fabs(out.turn_end) > 0.5);
		assert_true(fabs(out.turn_end - t.turned) <= bound);
		assert_true(bound < 0.02 * fabs(out.turn_end));
		assert_true(out.turn_max == t.psi_far);
		assert_true(out.turn_max >= fabs(out.turn_end));
		assert_memory_equal(&plain.heading_end, &out.heading_end, sizeof out.heading_end);
		assert_memory_equal(&plain.angular_velocity_end, &out.angular_velocity_end,
		                    sizeof out.angular_velocity_end);
		assert_memory_equal(&plain.turn_end, &out.turn_end, sizeof out.turn_end);
		assert_memory_equal(&plain.turn_max, &out.turn_max, sizeof out.turn_max);
		bsim_scene_free(&s);
	}
}

typedef struct gate_track {
	int flagged;
	int finite;
	double turned;
	double psi0;
	int first;
} gate_track;

static void track_gate(void *user, long step, const bsim_state *s)
{
	gate_track *t = user;
	if (step == 0)
		t->psi0 = s->heading;
	for (int i = 0; i < s->n_beams; i++)
		t->flagged |= s->contact[i] != BSIM_CONTACT_NONE;
	t->finite &= isfinite(s->heading) && isfinite(s->angular_velocity);
	t->turned = fmax(t->turned, fabs(s->heading - t->psi0));
}

/* Smoke test: a capsule and an ellipse of the disk's area (314 m^2) that
 * turn, with contact friction 0.3, pushed through the essay's gate (F = 7 N,
 * Rm = 20 N) on Box2D: each trial finishes with a result, its energies
 * finite, the contact flags set at some step, the body turned by its
 * contacts, and the ledger's residual within 5% of the energy that flowed
 * (Box2D's own O(h) errors, docs/backends.md). */
static void test_gate_shapes(void **state)
{
	const bsim_backend *be = *state;
	for (int k = 0; k < 2; k++) {
		bsim_scene s;
		bsim_scene_init_gate(&s, 7.0, 20.0);
		s.body.rotates = 1;
		if (k == 0) {
			s.body.shape = BSIM_SHAPE_CAPSULE;
			s.body.radius = 6.0;
			s.body.length = (100.0 * PI - 36.0 * PI) / 12.0;
		} else {
			s.body.shape = BSIM_SHAPE_ELLIPSE;
			s.body.radius = 0.0;
			s.body.semi_axes[0] = 12.5;
			s.body.semi_axes[1] = 8.0;
		}
		s.contact.friction = 0.3;
		assert_true(fabs(bsim_body_area(&s.body) - 100.0 * PI) < 1e-9);
		bsim_error err;
		assert_int_equal(bsim_scene_validate(&s, &err), BSIM_OK);
		for (int trial = 0; trial < 3; trial++) {
			gate_track t = {.finite = 1};
			bsim_recorder rec = {.trace = track_gate, .trace_user = &t};
			bsim_trial_result out;
			run_seed(be, &s, bsim_schedule_seed_mix(5, 0, (uint64_t)trial), &rec, &out);
			assert_int_equal(out.instability, BSIM_STABLE);
			assert_true(t.finite);
			assert_true(t.flagged);
			assert_true(t.turned > 0.01);
			assert_true(isfinite(out.ledger.e_end) && isfinite(out.ledger.residual));
			assert_true(fabs(out.ledger.residual) < 0.05 * out.ledger.inflow);
		}
		bsim_scene_free(&s);
	}
}

/* The trajectory CSV gains heading,angular_velocity only for a body that
 * turns or is not a disk: the essay's header is as it always was. */
static void test_trajectory_columns(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 7.0, 20.0);
	assert_int_equal(bsim_trial_body_columns(&s), 0);
	char buf[512];
	FILE *f = tmpfile();
	assert_non_null(f);
	bsim_trial_trajectory_header(f, 2);
	rewind(f);
	assert_non_null(fgets(buf, sizeof buf, f));
	fclose(f);
	assert_null(strstr(buf, "heading"));
	s.body.rotates = 1;
	assert_int_equal(bsim_trial_body_columns(&s), 1);
	s.body.rotates = 0;
	s.body.shape = BSIM_SHAPE_CAPSULE;
	s.body.length = 5.0;
	assert_int_equal(bsim_trial_body_columns(&s), 1);
	f = tmpfile();
	assert_non_null(f);
	bsim_trial_trajectory_header_body(f, 2, 1);
	rewind(f);
	assert_non_null(fgets(buf, sizeof buf, f));
	fclose(f);
	assert_non_null(strstr(buf, ",e_prop,heading,angular_velocity\n"));
	bsim_scene_free(&s);
}

/* What works with the disk's centre alone refuses another shape with an
 * input error naming the key: the energy landscape (body.shape). A gate
 * scene's default success line is the shape's; a run and its trajectory
 * work, the CSV ending with the body's columns. */
static void test_disk_only_refused(void **state)
{
	const bsim_backend *be = *state;
	const char *dir = bsim_test_dir("disk_only");
	static const char scene_text[] =
	        "name: capsule\n"
	        "body: { mass: 1.0, shape: capsule, radius: 6, length: 10, rotates: true }\n"
	        "beams:\n"
	        "  - { pivot: [-25, 30], rest_angle_deg: 0, length: 25, mass: 0.1, "
	        "stiffness: 400, damping: 50 }\n"
	        "  - { pivot: [25, 30], rest_angle_deg: 180, length: 25, mass: 0.1, "
	        "stiffness: 400, damping: 50 }\n"
	        "effects: { propulsion: { force: 7, along: heading } }\n"
	        "integration: { dt: 0.004, duration: 1 }\n";
	char text[2048], scene_path[1024], bare_path[1024];
	snprintf(bare_path, sizeof bare_path, "%s", bsim_test_write(dir, "bare.yaml", scene_text));
	snprintf(text, sizeof text, "%stermination: { success_y: 80, classify_y: 95 }\n",
	         scene_text);
	snprintf(scene_path, sizeof scene_path, "%s", bsim_test_write(dir, "capsule.yaml", text));
	const char *land[] = {"landscape", scene_path, "--out", bsim_test_join(dir, "land"), NULL};
	const char *needles[] = {"body.shape", "capsule", NULL};
	bsim_test_expect_input_error(land, needles);
	/* the success line's default: the beams' forward reach 55 m plus the
	 * capsule's 5 + 6 m */
	bsim_scene loaded;
	bsim_error err;
	assert_int_equal(bsim_scene_load(bare_path, NULL, 0, &loaded, &err), BSIM_OK);
	assert_true(loaded.success_y == 66.0 && loaded.classify_y == 81.0);
	bsim_scene_free(&loaded);
	assert_int_equal(bsim_scene_load(scene_path, NULL, 0, &loaded, &err), BSIM_OK);
	assert_true(loaded.success_y == 80.0 && loaded.classify_y == 95.0);
	bsim_scene_free(&loaded);
	assert_int_equal(bsim_scene_load(scene_path, NULL, 0, &loaded, &err), BSIM_OK);
	bsim_test_skip_refused(be, &loaded);
	bsim_scene_free(&loaded);
	char traj[1024];
	snprintf(traj, sizeof traj, "%s", bsim_test_join(dir, "t.csv"));
	const char *run[] = {"run", scene_path, "--backend", be->name, "--trajectory", traj, NULL};
	assert_int_equal(bsim_test_cli(run, NULL, NULL), 0);
	char *csv = bsim_test_read(traj);
	assert_non_null(csv);
	assert_non_null(strstr(csv, ",e_prop,heading,angular_velocity\n"));
	free(csv);
}

int main(void)
{
	/* what every backend does */
	const struct CMUnitTest every[] = {
	        cmocka_unit_test(test_spin_stop_angle),
	        cmocka_unit_test(test_capsule_stopping_distance),
	        cmocka_unit_test(test_angular_drag_decay),
	        cmocka_unit_test(test_free_capsule_conserves),
	        cmocka_unit_test(test_propulsion_along_heading),
	        cmocka_unit_test(test_ledger_turning),
	        cmocka_unit_test(test_contact_friction_stick_slip),
	        cmocka_unit_test(test_capsule_impact_conserves),
	        cmocka_unit_test(test_gate_shapes),
	        cmocka_unit_test(test_disk_only_refused),
	        cmocka_unit_test(test_outline_flag),
	};
	/* the footprint, the trajectory's columns, and Box2D's own polygon */
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_spin_arm),
	        cmocka_unit_test(test_ellipse_outline),
	        cmocka_unit_test(test_trajectory_columns),
	};
	int rc = bsim_test_run_per_backend("body_turn", every, sizeof every / sizeof every[0]);
	return cmocka_run_group_tests(tests, NULL, NULL) || rc;
}
