/* The body effects beyond the essay's, on every backend of the registry,
 * against the closed forms of a free body (far from every beam): viscous
 * drag's exponential decay, the forced response to a periodic force,
 * Coulomb friction's stopping distance and stick, and their ledger lines.
 * Where backends differ (the runner's pipeline applies an effect exactly
 * in double; a backend that takes it, Box2D, in its own float32 damping and
 * friction joint) each is held to the bound it states (bsim_backend.bounds,
 * "effects.*"); Box2D's damping and friction joint themselves are checked
 * by name at the end. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "beamsim/effects.h"
#include "beamsim/options.h"
#include "beamsim/schedule.h"
#include "beamsim/trial.h"
#include "scenes.h"
#include "support.h"

typedef struct free_track {
	double x0[2], v0[2];
	double c_over_m; /* 1/s */
	double h;
	double v_err;    /* max |v - v0 exp(-c t/m)| / |v0| over the steps */
	double x_err;    /* max |x - x0 - v0 m/c (1 - exp(-c t/m))| / path length */
	double step_err; /* max |v_(n+1) / v_n - exp(-c h/m)| over the steps */
	double v_last[2];
	long steps;
} free_track;

static void track_drag(void *user, long step, const bsim_state *s)
{
	free_track *t = user;
	double tt = step * t->h, decay = exp(-t->c_over_m * tt);
	double speed0 = hypot(t->v0[0], t->v0[1]);
	double path = speed0 / t->c_over_m * (1.0 - decay);
	for (int i = 0; i < 2; i++) {
		double dv = fabs(s->v[i] - t->v0[i] * decay) / speed0;
		double dx = fabs(s->x[i] - t->x0[i] - t->v0[i] / t->c_over_m * (1.0 - decay));
		t->v_err = fmax(t->v_err, dv);
		if (path > 0)
			t->x_err = fmax(t->x_err, dx / path);
		if (step > 0)
			t->step_err = fmax(t->step_err,
			                   fabs(s->v[i] / t->v_last[i] - exp(-t->c_over_m * t->h)));
		t->v_last[i] = s->v[i];
	}
	t->steps = step;
}

/* A disk of 2 kg launched at (3, -4) m/s away from the one beam, drag
 * c = 0.8 N s/m: v(t) = v0 exp(-c t / m) at every step (the update is exact:
 * to rounding on the thesis backend; on Box2D, whose body damping takes the
 * drag, each step multiplies v by 1 / (1 + h d) in float32: 1 + h d, near 1,
 * is spaced 2^-23, so the factor is exp(-c h / m) within 2^-24 and the
 * division's 2^-25, and the product rounds by 2^-24: 1.5 x 2^-23 relative
 * between one step and the next, and at worst steps x 1.5 x 2^-23 after
 * them);
 * x(t) = x0 + v0 m/c (1 - exp(-c t/m)) to first order in c h / m (the
 * backends' position updates); the ledger books the kinetic energy lost as
 * drag and still closes. */
static void test_drag_free_decay(void **state)
{
	const bsim_backend *be = *state;
	double v_bound = bsim_test_bound(be, "effects.drag.velocity");
	double step_bound = bsim_test_bound(be, "effects.drag.step");
	double e_bound = bsim_test_bound(be, "effects.drag.energy");
	double r_bound = bsim_test_bound(be, "effects.drag.residual");
	{
		bsim_scene s;
		scene_one_beam(&s);
		s.body.mass = 2.0;
		s.body.velocity[0] = 3.0;
		s.body.velocity[1] = -4.0;
		s.effects.has_drag = 1;
		s.effects.drag_linear = 0.8;
		s.max_steps = 1500; /* 6 s = 2.4 m/c */
		s.side_x = 1000.0;
		bsim_error err;
		assert_int_equal(bsim_scene_validate(&s, &err), BSIM_OK);
		free_track t = {.x0 = {s.body.start[0], s.body.start[1]},
		                .v0 = {3.0, -4.0},
		                .c_over_m = 0.4,
		                .h = s.dt};
		bsim_recorder rec = {.trace = track_drag, .trace_user = &t};
		bsim_trial_runner *r = bsim_trial_runner_alloc();
		bsim_trial_result out;
		assert_int_equal(bsim_trial_run(r, &s, be, NULL, 1, &rec, &out, &err), BSIM_OK);
		assert_int_equal(t.steps, 1500);
		assert_int_equal(out.instability, BSIM_STABLE);
		print_message("drag decay %s: max |v - v0 exp(-c t/m)| / |v0| %.3g, a step's "
		              "factor off by %.3g\n",
		              be->name, t.v_err, t.step_err);
		assert_true(t.v_err < v_bound);
		assert_true(t.step_err < step_bound);
		double ch_m = 0.4 * s.dt;
		assert_true(t.x_err < ch_m);
		/* a drag off by 1% would miss v by 2.4% at the end */
		double e0 = 0.5 * 2.0 * 25.0, e_end = e0 * exp(-2.0 * 0.4 * 6.0);
		assert_true(fabs(out.ledger.e_end - e_end) < e_bound * e0);
		/* the loss booked is the kinetic energy lost; what is left over is
		 * the backend's own, at most first order in c h / m (none for a
		 * position update that is the trapezoid's) */
		assert_true(fabs(out.ledger.drag - (e0 - e_end)) < ch_m * e0);
		assert_true(fabs(out.ledger.residual) < r_bound * e0);
		assert_true(out.ledger.w_prop == 0.0 && out.ledger.w_rand == 0.0);
		bsim_trial_runner_free(r);
		bsim_scene_free(&s);
	}
}

/* No drag block: no drag effect in the pipeline, nothing booked. */
/* The trace's last body speed along y. */
static void last_vy(void *user, long step, const bsim_state *st)
{
	(void)step;
	*(double *)user = st->v[1];
}

/* Drag with a constant force, on every backend: the terminal speed. The
 * exact motion of m dv/dt = F - c v reaches F/c; a step of the runner's
 * drag (the force m v (exp(-a) - 1) / h read at the step's start, a =
 * c h / m) with F added takes v to v exp(-a) + h F / m, whose fixed point
 * is
 *   v* = (F/c) a / (1 - exp(-a)) = (F/c) (1 + a/2 + a^2/12 + ...),
 * and a backend that simulates the drag itself as damping after the force
 * (bsim_backend.takes BSIM_TAKES_DRAG: Box2D's factor 1 / (1 + h d) =
 * exp(-a)) takes v to (v + h F / m) exp(-a), whose fixed point is
 *   v* = (F/c) a / (exp(a) - 1) = (F/c) (1 - a/2 + a^2/12 - ...):
 * a bias of +-c h / (2 m), first order in h. F = 2 N, c = 0.5 N s/m, m = 2
 * kg at h = 4 ms (a = 1e-3): F/c = 4 m/s, the bias 2.0e-3 m/s; after 15
 * time constants m/c the speed is the fixed point within the backend's
 * bound (effects.drag.terminal: exp(-15) in double; Box2D's float32 damping
 * factor), and F/c is farther than a/5. */
static void test_drag_terminal_speed(void **state)
{
	const bsim_backend *be = *state;
	const double bound = bsim_test_bound(be, "effects.drag.terminal");
	bsim_scene s;
	bsim_scene_init_gate(&s, 2.0, 0.0);
	s.body.mass = 2.0;
	s.body.start[0] = 500.0; /* far from the beams */
	s.side_x = 1e4;
	s.success_y = s.classify_y = 1e6;
	s.effects.has_drag = 1;
	s.effects.drag_linear = 0.5;
	s.max_steps = 15000; /* 60 s, 15 m/c */
	bsim_error err;
	assert_int_equal(bsim_scene_validate(&s, &err), BSIM_OK);
	double vy = NAN;
	bsim_recorder rec = {.trace = last_vy, .trace_user = &vy};
	bsim_trial_runner *r = bsim_trial_runner_alloc();
	bsim_trial_result out;
	assert_int_equal(bsim_trial_run(r, &s, be, NULL, 1, &rec, &out, &err), BSIM_OK);
	bsim_trial_runner_free(r);
	assert_int_equal(out.steps_run, 15000);
	const double a = 0.5 * s.dt / 2.0, terminal = 2.0 / 0.5;
	const double fixed =
	        be->takes & BSIM_TAKES_DRAG ? terminal * a / expm1(a) : terminal * a / -expm1(-a);
	print_message("%s: terminal speed %.9f m/s, the fixed point %.9f (F/c %.1f, bias %+.3g "
	              "relative)\n",
	              be->name, vy, fixed, terminal, fixed / terminal - 1.0);
	assert_true(fabs(vy - fixed) < bound * terminal);
	assert_true(fabs(vy - terminal) > 0.2 * a * terminal); /* the bias is there */
	bsim_scene_free(&s);
}

static void test_drag_absent(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 7.0, 20.0);
	bsim_effects fx;
	assert_int_equal(bsim_effects_init(&fx, &s, 1), BSIM_OK);
	assert_null(fx.drag);
	assert_int_equal(fx.n_work, fx.n);
	bsim_effects_free(&fx);
	/* an angular drag on the disk that does not turn is refused */
	s.effects.has_drag = 1;
	s.effects.drag_linear = 1.0;
	s.effects.drag_angular = 0.5;
	bsim_error err;
	assert_int_equal(bsim_scene_validate(&s, &err), BSIM_EINPUT);
	assert_non_null(strstr(err.msg, "effects.drag.angular"));
	bsim_scene_free(&s);
}

/* A backend that takes drag and ground friction (bsim_backend.takes, as
 * Box2D does) gets them in the pipeline marked taken, with no force or
 * torque: the pipeline's sum is the propulsion alone, where without taking
 * it has the drag's -c v and the friction's stop. Every registered
 * backend's pipeline marks taken exactly what it takes; a body that turns
 * has its ground friction taken only under the decoupled model. */
static void test_taken_effects(void **state)
{
	(void)state;
	bsim_scene s;
	scene_one_beam(&s);
	s.body.mass = 2.0;
	s.effects.has_propulsion = 1;
	s.effects.propulsion_force = 3.0;
	s.effects.has_drag = 1;
	s.effects.drag_linear = 0.8;
	s.effects.has_ground_friction = 1;
	s.effects.ground_mu = 0.5;
	bsim_error err;
	assert_int_equal(bsim_scene_validate(&s, &err), BSIM_OK);
	const unsigned both = BSIM_TAKES_DRAG | BSIM_TAKES_GROUND_FRICTION;
	for (const bsim_backend *const *b = bsim_backend_list(); *b; b++) {
		assert_int_equal((*b)->takes & ~both, 0u); /* nothing the pipeline lacks */
		bsim_effects fx;
		assert_int_equal(bsim_effects_init_taking(&fx, &s, 1, (*b)->takes), BSIM_OK);
		assert_int_equal(fx.drag->taken, ((*b)->takes & BSIM_TAKES_DRAG) != 0);
		assert_int_equal(fx.friction->taken,
		                 ((*b)->takes & BSIM_TAKES_GROUND_FRICTION) != 0);
		bsim_effects_free(&fx);
	}
	bsim_state at;
	assert_int_equal(bsim_state_init(&at, 1), BSIM_OK);
	at.v[0] = 1.5;
	for (int taking = 0; taking < 2; taking++) {
		bsim_effects fx;
		assert_int_equal(bsim_effects_init_taking(&fx, &s, 1, taking ? both : 0u), BSIM_OK);
		assert_non_null(fx.drag);
		assert_non_null(fx.friction);
		assert_int_equal(fx.drag->taken, taking);
		assert_int_equal(fx.friction->taken, taking);
		double f[BSIM_WRENCH];
		bsim_effects_force_at(&fx, 0, s.dt, &at, f);
		if (taking) {
			assert_true(f[0] == 0.0 && f[1] == 3.0 && f[2] == 0.0);
		} else {
			/* drag 2 x 1.5 (exp(-0.4 h) - 1) / h = -1.2 N, then the sliding
			 * friction mu m g = 9.81 N against m v / h + f = (748.8, 3) N */
			assert_true(f[0] < -9.8 && f[1] < 3.0);
		}
		bsim_effects_free(&fx);
	}
	/* A body that turns: its ground friction is taken only under the
	 * decoupled model, which is what a taking backend simulates; the
	 * coupled one is the pipeline's on every backend. */
	s.body.rotates = 1;
	for (int model = 0; model < 2; model++) {
		s.effects.ground_model = model ? BSIM_FRICTION_DECOUPLED : BSIM_FRICTION_COUPLED;
		assert_int_equal(bsim_effects_friction_takeable(&s), model);
		bsim_effects fx;
		assert_int_equal(bsim_effects_init_taking(&fx, &s, 1, both), BSIM_OK);
		assert_int_equal(fx.drag->taken, 1);
		assert_int_equal(fx.friction->taken, model);
		assert_true(model ? fx.friction->footprint == NULL
		                  : fx.friction->footprint != NULL);
		bsim_effects_free(&fx);
	}
	bsim_state_free(&at);
	bsim_scene_free(&s);
}

/* A free disk of 2 kg at rest under A = 5 N at 0.5 Hz, phase 0.3 rad, for
 * 3.5 s (v = 2 A cos(phi) / (m w) at the end). */
static void scene_oscillating(bsim_scene *s)
{
	scene_one_beam(s);
	s->body.mass = 2.0;
	s->effects.has_oscillation = 1;
	s->effects.osc_amplitude = 5.0;
	s->effects.osc_frequency = 0.5;
	s->effects.osc_phase = 0.3;
	s->max_steps = 875;
	s->side_x = 1000.0;
	bsim_error err;
	assert_int_equal(bsim_scene_validate(s, &err), BSIM_OK);
}

typedef struct osc_track {
	double x0, a_over_m, w, phi, h;
	double v_err, x_err, x_scale;
	long steps;
} osc_track;

/* v(t) = A/(m w) (cos phi - cos(w t + phi)),
 * x(t) = x0 + A/(m w) (t cos phi - (sin(w t + phi) - sin phi) / w): the
 * double integral of A sin(w t + phi) / m from rest. */
static void track_osc(void *user, long step, const bsim_state *s)
{
	osc_track *t = user;
	double tt = step * t->h, k = t->a_over_m / t->w;
	double v = k * (cos(t->phi) - cos(t->w * tt + t->phi));
	double x = t->x0 + k * (tt * cos(t->phi) - (sin(t->w * tt + t->phi) - sin(t->phi)) / t->w);
	t->v_err = fmax(t->v_err, fabs(s->v[0] - v) / k);
	t->x_err = fmax(t->x_err, fabs(s->x[0] - x));
	t->x_scale = fmax(t->x_scale, fabs(x - t->x0));
	t->steps = step;
	assert_true(s->v[1] == 0.0);
}

/* A free disk of 2 kg at rest under A = 5 N at 0.5 Hz, phase 0.3 rad, for
 * 3.5 s on every backend: the velocity at every step is the analytic one (to
 * rounding; Box2D's single precision), the position within A h / (m w) (the
 * backends' position updates, first order in h at most), and the ledger's
 * oscillation work is the kinetic energy gained. */
static void test_oscillation_free_body(void **state)
{
	const bsim_backend *be = *state;
	double v_bound = bsim_test_bound(be, "effects.oscillation.velocity");
	double r_bound = bsim_test_bound(be, "effects.oscillation.residual");
	{
		bsim_scene s;
		scene_oscillating(&s);
		bsim_error err;
		osc_track t = {.x0 = s.body.start[0],
		               .a_over_m = 2.5,
		               .w = 2.0 * 3.14159265358979323846 * 0.5,
		               .phi = 0.3,
		               .h = s.dt};
		bsim_recorder rec = {.trace = track_osc, .trace_user = &t};
		bsim_trial_runner *r = bsim_trial_runner_alloc();
		bsim_trial_result out;
		assert_int_equal(bsim_trial_run(r, &s, be, NULL, 1, &rec, &out, &err), BSIM_OK);
		assert_int_equal(t.steps, 875);
		assert_int_equal(out.instability, BSIM_STABLE);
		assert_true(t.v_err < v_bound);
		double k = t.a_over_m / t.w;
		assert_true(t.x_err < k * s.dt);
		assert_true(t.x_scale > 1.0); /* the body did move: metres */
		double e_end = out.ledger.e_end;
		assert_true(e_end > 0.1);
		/* The work over the displacement is the kinetic energy gained for
		 * a position update that is the trapezoid's; x += h v_(n+1) books
		 * h^2 F_n^2 / (2 m) more work per step (the ledger's residual is
		 * then minus their sum, first order in h:
		 * test_box2d_oscillation_ledger). */
		print_message(
		        "oscillation %s: velocity off by %.3g of A/(m w), residual %.3g of the "
		        "energy gained\n",
		        be->name, t.v_err, fabs(out.ledger.residual) / e_end);
		assert_true(fabs(out.ledger.residual) < r_bound * e_end);
		assert_true(out.ledger.w_prop == 0.0 && out.ledger.drag == 0.0);
		bsim_trial_runner_free(r);
		bsim_scene_free(&s);
	}
}

typedef struct stop_track {
	double x0[2], h, decel; /* decel = mu g, m/s^2 */
	double v0[2];
	long stop_step; /* the first step at rest, or -1 */
	double after;   /* max |v| and |x - x_stop| over the steps after it */
	double x_stop[2];
	double v_err;  /* max | |v| - (|v0| - mu g t) | while it slides */
	double turned; /* max sin of the angle between v and v0 while it slides */
} stop_track;

static void track_stop(void *user, long step, const bsim_state *s)
{
	stop_track *t = user;
	double speed = hypot(s->v[0], s->v[1]), speed0 = hypot(t->v0[0], t->v0[1]);
	if (t->stop_step < 0 && speed < 1e-12) {
		t->stop_step = step;
		t->x_stop[0] = s->x[0];
		t->x_stop[1] = s->x[1];
	} else if (t->stop_step >= 0) {
		t->after = fmax(t->after, speed);
		t->after = fmax(t->after, hypot(s->x[0] - t->x_stop[0], s->x[1] - t->x_stop[1]));
	} else if (speed > 0.1) { /* sliding (Box2D's floats blur slower ones' direction) */
		t->v_err = fmax(t->v_err, fabs(speed - (speed0 - t->decel * step * t->h)));
		double cross = s->v[0] * t->v0[1] - s->v[1] * t->v0[0];
		t->turned = fmax(t->turned, fabs(cross) / (speed0 * speed));
	}
}

/* A disk of 1 kg sliding at 5 m/s with mu = 0.5 on every backend: the
 * speed falls by mu g per second along the line it started on, the body
 * stops at v0^2 / (2 mu g) = 2.548 m from its start (within |v0| h, the
 * backends' position updates) at t = |v0| / (mu g) (within the backend's
 * bound, in steps) and then
 * stays at rest; the ledger books the kinetic energy as friction loss. */
static void test_ground_friction_stopping_distance(void **state)
{
	const bsim_backend *be = *state;
	double stop_bound = bsim_test_bound(be, "effects.friction.stop");
	double dir_bound = bsim_test_bound(be, "effects.friction.direction");
	double v_bound = bsim_test_bound(be, "effects.friction.velocity");
	double e_bound = bsim_test_bound(be, "effects.friction.energy");
	double r_bound;
	int closes = bsim_backend_bound_of(be, "effects.friction.residual", &r_bound);
	{
		bsim_scene s;
		scene_one_beam(&s);
		s.body.velocity[0] = 3.0;
		s.body.velocity[1] = -4.0;
		s.effects.has_ground_friction = 1;
		s.effects.ground_mu = 0.5;
		s.max_steps = 500; /* 2 s: stopped at 1.02 s */
		s.side_x = 1000.0;
		bsim_error err;
		assert_int_equal(bsim_scene_validate(&s, &err), BSIM_OK);
		const double mu_g = 0.5 * 9.81, v0 = 5.0;
		stop_track t = {.x0 = {s.body.start[0], s.body.start[1]},
		                .h = s.dt,
		                .decel = mu_g,
		                .v0 = {3.0, -4.0},
		                .stop_step = -1};
		bsim_recorder rec = {.trace = track_stop, .trace_user = &t};
		bsim_trial_runner *r = bsim_trial_runner_alloc();
		bsim_trial_result out;
		assert_int_equal(bsim_trial_run(r, &s, be, NULL, 1, &rec, &out, &err), BSIM_OK);
		assert_int_equal(out.instability, BSIM_STABLE);
		assert_true(t.stop_step > 0);
		/* within the backend's steps (a single-precision velocity may reach
		 * 0 a step later) */
		assert_true(fabs(t.stop_step * s.dt - v0 / mu_g) <= stop_bound * s.dt);
		double dist = hypot(t.x_stop[0] - t.x0[0], t.x_stop[1] - t.x0[1]);
		print_message(
		        "ground friction %s: stops %.5f m away (v0^2/(2 mu g) %.5f, one step's "
		        "travel %.3f) at %.3f s (v0/(mu g) %.4f); friction booked %.4f J of "
		        "12.5 J, residual %.3g J\n",
		        be->name, dist, v0 * v0 / (2.0 * mu_g), v0 * s.dt, t.stop_step * s.dt,
		        v0 / mu_g, out.ledger.friction, out.ledger.residual);
		assert_true(fabs(dist - v0 * v0 / (2.0 * mu_g)) < v0 * s.dt);
		/* along the initial direction */
		assert_true(fabs((t.x_stop[0] - t.x0[0]) / dist - 0.6) < 1e-5);
		assert_true(t.turned < dir_bound);
		assert_true(t.v_err < v_bound);
		assert_true(t.after < 1e-12);
		double e0 = 12.5;
		assert_true(fabs(out.ledger.friction - e0) < e_bound * e0);
		if (closes)
			assert_true(fabs(out.ledger.residual) < r_bound * e0);
		else
			print_message("%s: the residual not checked: it states no bound "
			              "effects.friction.residual\n",
			              be->name);
		bsim_trial_runner_free(r);
		bsim_scene_free(&s);
	}
}

typedef struct push_track {
	double h, accel;
	double v_err, moved;
} push_track;

static void track_push(void *user, long step, const bsim_state *s)
{
	push_track *t = user;
	t->v_err = fmax(t->v_err, fabs(s->v[1] - t->accel * step * t->h) + fabs(s->v[0]));
	t->moved = fmax(t->moved, fabs(s->x[0]) + fabs(s->x[1] + 100.0));
}

/* A body at rest pushed along +y by the propulsion with mu m g = 4.905 N:
 * at 4.9 N it stays at rest to the bit (stick, no chatter); at 6 N it
 * accelerates at (F - mu m g) / m. */
static void test_ground_friction_stick(void **state)
{
	const bsim_backend *be = *state;
	double v_bound = bsim_test_bound(be, "effects.friction.push");
	const double forces[2] = {4.9, 6.0};
	for (int k = 0; k < 2; k++) {
		bsim_scene s;
		scene_one_beam(&s);
		s.effects.has_propulsion = 1;
		s.effects.propulsion_force = forces[k];
		s.effects.has_ground_friction = 1;
		s.effects.ground_mu = 0.5;
		s.max_steps = 750;
		s.side_x = 1000.0;
		bsim_error err;
		assert_int_equal(bsim_scene_validate(&s, &err), BSIM_OK);
		push_track t = {.h = s.dt, .accel = k ? forces[k] - 0.5 * 9.81 : 0.0};
		bsim_recorder rec = {.trace = track_push, .trace_user = &t};
		bsim_trial_runner *r = bsim_trial_runner_alloc();
		bsim_trial_result out;
		assert_int_equal(bsim_trial_run(r, &s, be, NULL, 1, &rec, &out, &err), BSIM_OK);
		if (k == 0) {
			assert_true(t.v_err == 0.0);
			assert_true(t.moved == 0.0);
			assert_true(out.ledger.friction == 0.0);
		} else {
			assert_true(t.v_err < v_bound);
			assert_true(t.moved > 1.0);
		}
		bsim_trial_runner_free(r);
		bsim_scene_free(&s);
	}
}

/* Box2D takes drag as its body damping, d = (exp(c h / M) - 1) / h, so its
 * factor 1 / (1 + h d) per step is exp(-c h / M): a free disk's velocity
 * and an ellipse's spin decay by exactly that factor each step, to float32
 * (1.5 x 2^-23, test_drag_free_decay; four times that with substeps = 4,
 * four factors exp(-c h / 4M)). Box2D's own reading d = c / M would miss
 * by (c h / M)^2 / 2 a step, which the bound tells apart. The loss booked
 * (minus the damping impulse's work over the motion) is the kinetic energy
 * lost to first order in c h / M. */
typedef struct decay_track {
	double h, rate;   /* s; c/M or c_w/J, 1/s */
	double last, err; /* the last v_x or omega; max |ratio - exp(-rate h)| */
	int spin;
	long steps;
} decay_track;

static void track_decay(void *user, long step, const bsim_state *s)
{
	decay_track *t = user;
	double now = t->spin ? s->angular_velocity : s->v[0];
	if (step > 0)
		t->err = fmax(t->err, fabs(now / t->last - exp(-t->rate * t->h)));
	t->last = now;
	t->steps = step;
}

static void test_box2d_damping_exact(void **state)
{
	(void)state;
	const double f32 = ldexp(1.0, -23);
	for (int spin = 0; spin < 2; spin++)
		for (int sub = 0; sub < 2; sub++) {
			bsim_scene s;
			scene_one_beam(&s);
			s.body.mass = 2.0;
			s.effects.has_drag = 1;
			double rate;
			if (spin) {
				s.body.shape = BSIM_SHAPE_ELLIPSE;
				s.body.radius = 0.0;
				s.body.semi_axes[0] = 10.0;
				s.body.semi_axes[1] = 5.0;
				s.body.rotates = 1;
				s.body.angular_velocity = 3.0;
				s.effects.drag_angular = 30.0;
				rate = 30.0 / bsim_body_inertia(&s.body);
			} else {
				s.body.velocity[0] = 5.0;
				s.effects.drag_linear = 1.5;
				rate = 1.5 / 2.0;
			}
			s.max_steps = 500;
			s.side_x = 1000.0;
			bsim_error err;
			assert_int_equal(bsim_scene_validate(&s, &err), BSIM_OK);
			bsim_options o;
			memset(&o, 0, sizeof o);
			assert_int_equal(
			        bsim_options_add(&o, sub ? "substeps=4" : "substeps=1", &err),
			        BSIM_OK);
			assert_int_equal(bsim_options_add(&o, "ellipse=polygon", &err), BSIM_OK);
			decay_track t = {.h = s.dt, .rate = rate, .spin = spin};
			bsim_recorder rec = {.trace = track_decay, .trace_user = &t};
			bsim_trial_runner *r = bsim_trial_runner_alloc();
			bsim_trial_result out;
			assert_int_equal(bsim_trial_run(r, &s, bsim_test_backend("box2d"), &o, 1,
			                                &rec, &out, &err),
			                 BSIM_OK);
			assert_int_equal(t.steps, 500);
			double naive = 0.5 * (rate * s.dt) * (rate * s.dt);
			print_message(
			        "box2d damping %s substeps %d: a step's factor off exp(-%s h) "
			        "by %.3g (d = c/M would be %.3g); drag booked %.6g J of %.6g J "
			        "lost, residual %.3g J\n",
			        spin ? "angular" : "linear", sub ? 4 : 1, spin ? "c_w/J" : "c/M",
			        t.err, naive, out.ledger.drag,
			        out.ledger.e_start - out.ledger.e_end, out.ledger.residual);
			assert_true(naive > 8.0 * f32);
			assert_true(t.err < (sub ? 4.0 : 1.0) * 1.5 * f32);
			double lost = out.ledger.e_start - out.ledger.e_end;
			assert_true(lost > 0.5 * out.ledger.e_start);
			/* booked as minus the work over the motion: first order in rate h */
			assert_true(fabs(out.ledger.drag - lost) < rate * s.dt * lost);
			assert_int_equal(out.instability, BSIM_STABLE);
			bsim_trial_runner_free(r);
			bsim_scene_free(&s);
		}
}

/* A 2.7 kg disk at rest pushed along +y at 0.97 mu M g (mu = 0.37) on
 * Box2D: the friction joint holds it. Each step the push gives it
 * h F / M and the joint takes that back to float32 (a few units in the
 * last place), so in n steps it drifts less than n h (16 ulp of h F / M),
 * against the 0.5 (F - mu M g) / M t^2 = 0.03 m it would slide without the
 * joint's hold at F = 1.03 mu M g, which it does. */
static void test_box2d_friction_holds(void **state)
{
	(void)state;
	const double mu = 0.37, M = 2.7, limit = mu * M * 9.81;
	const double share[2] = {0.97, 1.03};
	for (int k = 0; k < 2; k++) {
		bsim_scene s;
		scene_one_beam(&s);
		s.body.mass = M;
		s.effects.has_propulsion = 1;
		s.effects.propulsion_force = share[k] * limit;
		s.effects.has_ground_friction = 1;
		s.effects.ground_mu = mu;
		s.max_steps = 1000;
		s.side_x = 1000.0;
		bsim_error err;
		assert_int_equal(bsim_scene_validate(&s, &err), BSIM_OK);
		push_track t = {.h = s.dt, .accel = 0.0};
		bsim_recorder rec = {.trace = track_push, .trace_user = &t};
		bsim_trial_runner *r = bsim_trial_runner_alloc();
		bsim_trial_result out;
		assert_int_equal(bsim_trial_run(r, &s, bsim_test_backend("box2d"), NULL, 1, &rec,
		                                &out, &err),
		                 BSIM_OK);
		double dv = s.dt * share[k] * limit / M;
		double bound = 1000 * s.dt * 16.0 * ldexp(dv, -23);
		double slide = 0.5 * (0.03 * limit / M) * 16.0; /* t = 4 s */
		print_message("box2d friction joint, push %.2f mu M g: moved %.3g m in 4 s "
		              "(hold bound %.3g m, a slide at 0.03 mu M g: %.3g m)\n",
		              share[k], t.moved, bound, slide);
		if (k == 0) {
			assert_true(t.moved < bound);
			assert_true(fabs(out.ledger.friction) < 1e-9);
		} else {
			assert_true(fabs(t.moved - slide) < 0.01 * slide);
		}
		bsim_trial_runner_free(r);
		bsim_scene_free(&s);
	}
}

typedef struct both_track {
	double h, v0, w0;
	long slide_stop, spin_stop; /* the first step at rest, or -1 */
} both_track;

static void track_both(void *user, long step, const bsim_state *s)
{
	both_track *t = user;
	if (t->slide_stop < 0 && hypot(s->v[0], s->v[1]) < 1e-6 * t->v0)
		t->slide_stop = step;
	if (t->spin_stop < 0 && fabs(s->angular_velocity) < 1e-6 * t->w0)
		t->spin_stop = step;
}

/* A capsule (R = 4 m, L = 12 m, 2 kg) sliding at 5 m/s and spinning at
 * 3 rad/s at once, mu = 0.4, under the decoupled model
 * (effects.ground_friction.model: decoupled). Box2D's friction joint
 * clamps its linear impulse to h mu M g and its angular one to
 * h mu M g r_s apart, and the pipeline does the same on the other backends
 * ("sliding and spinning taken apart"): each motion stops at its own
 * closed-form time, v0 / (mu g) and omega0 J / (mu M g r_s), within two
 * steps, on every backend. (The coupled model, the default, is
 * test_footprint_friction's.) */
static void test_slide_and_spin(void **state)
{
	const bsim_backend *be = *state;
	{
		bsim_scene s;
		scene_one_beam(&s);
		s.body.mass = 2.0;
		s.body.shape = BSIM_SHAPE_CAPSULE;
		s.body.radius = 4.0;
		s.body.length = 12.0;
		s.body.rotates = 1;
		s.body.velocity[0] = 5.0;
		s.body.angular_velocity = 3.0;
		s.effects.has_ground_friction = 1;
		s.effects.ground_mu = 0.4;
		s.effects.ground_model = BSIM_FRICTION_DECOUPLED;
		s.max_steps = 2000;
		s.side_x = 1000.0;
		bsim_error err;
		assert_int_equal(bsim_scene_validate(&s, &err), BSIM_OK);
		bsim_test_skip_refused(be, &s);
		const double mu_g = 0.4 * 9.81;
		double alpha =
		        mu_g * 2.0 * bsim_effects_spin_arm(&s.body) / bsim_body_inertia(&s.body);
		both_track t = {.h = s.dt, .v0 = 5.0, .w0 = 3.0, .slide_stop = -1, .spin_stop = -1};
		bsim_recorder rec = {.trace = track_both, .trace_user = &t};
		bsim_trial_runner *r = bsim_trial_runner_alloc();
		bsim_trial_result out;
		assert_int_equal(bsim_trial_run(r, &s, be, NULL, 1, &rec, &out, &err), BSIM_OK);
		print_message("slide and spin %s: slide stops at %.4f s (v0/(mu g) %.4f), spin at "
		              "%.4f s (omega0/alpha %.4f); friction booked %.4f J of %.4f J\n",
		              be->name, t.slide_stop * s.dt, 5.0 / mu_g, t.spin_stop * s.dt,
		              3.0 / alpha, out.ledger.friction, out.ledger.e_start);
		assert_true(t.slide_stop > 0 && t.spin_stop > 0);
		assert_true(fabs(t.slide_stop * s.dt - 5.0 / mu_g) <= 2 * s.dt);
		assert_true(fabs(t.spin_stop * s.dt - 3.0 / alpha) <= 2 * s.dt);
		assert_true(fabs(out.ledger.friction - out.ledger.e_start) <
		            0.02 * out.ledger.e_start);
		bsim_trial_runner_free(r);
		bsim_scene_free(&s);
	}
}

/* The essay's gate (F = 7 N, Rm = 20 N) with ground friction mu = 0.05
 * (0.49 N on the 1 kg body) and drag c = 0.1 N s/m, trials 0-4: on Box2D the
 * joint and the damping take them, and the ledger, which books their
 * losses from Box2D's impulses, closes as it does without them (|residual|
 * within 5% of the energy that flowed in, the bound of the shapes' gate
 * test); the thesis backend's pipeline, to round-off. */
static void test_gate_ledger_friction_drag(void **state)
{
	const bsim_backend *be = *state;
	double bound = bsim_test_bound(be, "effects.ledger");
	{
		double worst = 0.0, friction = 0.0, drag = 0.0;
		for (int trial = 0; trial < 5; trial++) {
			bsim_scene s;
			bsim_scene_init_gate(&s, 7.0, 20.0);
			s.effects.has_ground_friction = 1;
			s.effects.ground_mu = 0.05;
			s.effects.has_drag = 1;
			s.effects.drag_linear = 0.1;
			bsim_error err;
			assert_int_equal(bsim_scene_validate(&s, &err), BSIM_OK);
			bsim_trial_runner *r = bsim_trial_runner_alloc();
			bsim_trial_result out;
			uint64_t seed = bsim_schedule_seed_mix(1, 0, (uint64_t)trial);
			assert_int_equal(bsim_trial_run(r, &s, be, NULL, seed, NULL, &out, &err),
			                 BSIM_OK);
			assert_int_equal(out.instability, BSIM_STABLE);
			assert_true(out.ledger.friction > 0.0 && out.ledger.drag > 0.0);
			worst = fmax(worst, fabs(out.ledger.residual) / out.ledger.inflow);
			friction += out.ledger.friction;
			drag += out.ledger.drag;
			bsim_trial_runner_free(r);
			bsim_scene_free(&s);
		}
		print_message("gate with ground friction and drag, %s, 5 trials: worst "
		              "|residual| / inflow %.3g; friction %.4g J, drag %.4g J in all\n",
		              be->name, worst, friction, drag);
		assert_true(worst < bound);
	}
}

/* Box2D's position update x += h v_(n+1) books h^2 F_n^2 / (2 m) more
 * work a step than the kinetic energy it adds: under the periodic force of
 * test_oscillation_free_body its ledger's residual is minus their sum
 * (within 1%), first order in h. */
static void test_box2d_oscillation_ledger(void **state)
{
	(void)state;
	bsim_scene s;
	scene_oscillating(&s);
	bsim_error err;
	bsim_trial_runner *r = bsim_trial_runner_alloc();
	bsim_trial_result out;
	assert_int_equal(
	        bsim_trial_run(r, &s, bsim_test_backend("box2d"), NULL, 1, NULL, &out, &err),
	        BSIM_OK);
	double extra = 0.0, w = 2.0 * 3.14159265358979323846 * 0.5;
	for (long n = 0; n < 875; n++) {
		double tn = n * s.dt;
		double f = 5.0 * (cos(w * tn + 0.3) - cos(w * (tn + s.dt) + 0.3)) / (w * s.dt);
		extra += s.dt * s.dt * f * f / (2.0 * 2.0);
	}
	print_message("box2d oscillation: ledger residual %.4g J, the Euler update's extra work "
	              "%.4g J\n",
	              out.ledger.residual, extra);
	assert_true(fabs(out.ledger.residual + extra) < 0.01 * extra);
	bsim_trial_runner_free(r);
	bsim_scene_free(&s);
}

int main(void)
{
	/* what every backend does */
	const struct CMUnitTest every[] = {
	        cmocka_unit_test(test_drag_free_decay),
	        cmocka_unit_test(test_drag_terminal_speed),
	        cmocka_unit_test(test_oscillation_free_body),
	        cmocka_unit_test(test_ground_friction_stopping_distance),
	        cmocka_unit_test(test_ground_friction_stick),
	        cmocka_unit_test(test_slide_and_spin),
	        cmocka_unit_test(test_gate_ledger_friction_drag),
	};
	/* the pipeline, and Box2D's own damping and friction joint */
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_drag_absent),
	        cmocka_unit_test(test_taken_effects),
	        cmocka_unit_test(test_box2d_damping_exact),
	        cmocka_unit_test(test_box2d_friction_holds),
	        cmocka_unit_test(test_box2d_oscillation_ledger),
	};
	int rc = bsim_test_run_per_backend("body_effects", every, sizeof every / sizeof every[0]);
	return cmocka_run_group_tests(tests, NULL, NULL) || rc;
}
