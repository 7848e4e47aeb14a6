/* The body effects beyond the essay's, on both backends, against the closed
 * forms of a free body (far from every beam): viscous drag's exponential
 * decay, the forced response to a periodic force, Coulomb friction's
 * stopping distance and stick, and their ledger lines. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "beamsim/effects.h"
#include "beamsim/trial.h"
#include "scenes.h"

static const bsim_backend *const backends[] = {&bsim_backend_thesis, &bsim_backend_box2d};

typedef struct free_track {
	double x0[2], v0[2];
	double c_over_m; /* 1/s */
	double h;
	double v_err; /* max |v - v0 exp(-c t/m)| / |v0| over the steps */
	double x_err; /* max |x - x0 - v0 m/c (1 - exp(-c t/m))| / path length */
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
	}
	t->steps = step;
}

/* A disk of 2 kg launched at (3, -4) m/s away from the one beam, drag
 * c = 0.8 N s/m: v(t) = v0 exp(-c t / m) at every step (the update is exact:
 * to rounding on the thesis backend, to Box2D's single precision on it);
 * x(t) = x0 + v0 m/c (1 - exp(-c t/m)) to first order in c h / m (the
 * backends' position updates); the ledger books the kinetic energy lost as
 * drag and still closes. */
static void test_drag_free_decay(void **state)
{
	(void)state;
	for (int b = 0; b < 2; b++) {
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
		assert_int_equal(bsim_trial_run(r, &s, backends[b], NULL, 1, &rec, &out, &err),
		                 BSIM_OK);
		assert_int_equal(t.steps, 1500);
		assert_int_equal(out.instability, BSIM_STABLE);
		assert_true(t.v_err < (b == 0 ? 1e-12 : 1e-5));
		double ch_m = 0.4 * s.dt;
		assert_true(t.x_err < ch_m);
		/* a drag off by 1% would miss v by 2.4% at the end */
		double e0 = 0.5 * 2.0 * 25.0, e_end = e0 * exp(-2.0 * 0.4 * 6.0);
		assert_true(fabs(out.ledger.e_end - e_end) < (b == 0 ? 1e-9 : 1e-4) * e0);
		/* the loss booked is the kinetic energy lost; what is left over is
		 * the backends' own, first order in c h / m (none on the thesis
		 * backend, whose position update is the trapezoid's) */
		assert_true(fabs(out.ledger.drag - (e0 - e_end)) < ch_m * e0);
		assert_true(fabs(out.ledger.residual) < (b == 0 ? 1e-9 : ch_m) * e0);
		assert_true(out.ledger.w_prop == 0.0 && out.ledger.w_rand == 0.0);
		bsim_trial_runner_free(r);
		bsim_scene_free(&s);
	}
}

/* No drag block: no drag effect in the pipeline, nothing booked. */
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
 * 3.5 s on both backends: the velocity at every step is the analytic one (to
 * rounding; Box2D's single precision), the position within A h / (m w) (the
 * backends' position updates, first order in h at most), and the ledger's
 * oscillation work is the kinetic energy gained. */
static void test_oscillation_free_body(void **state)
{
	(void)state;
	for (int b = 0; b < 2; b++) {
		bsim_scene s;
		scene_one_beam(&s);
		s.body.mass = 2.0;
		s.effects.has_oscillation = 1;
		s.effects.osc_amplitude = 5.0;
		s.effects.osc_frequency = 0.5;
		s.effects.osc_phase = 0.3;
		s.max_steps = 875; /* 3.5 s: v = 2 A cos(phi) / (m w) at the end */
		s.side_x = 1000.0;
		bsim_error err;
		assert_int_equal(bsim_scene_validate(&s, &err), BSIM_OK);
		osc_track t = {.x0 = s.body.start[0],
		               .a_over_m = 2.5,
		               .w = 2.0 * 3.14159265358979323846 * 0.5,
		               .phi = 0.3,
		               .h = s.dt};
		bsim_recorder rec = {.trace = track_osc, .trace_user = &t};
		bsim_trial_runner *r = bsim_trial_runner_alloc();
		bsim_trial_result out;
		assert_int_equal(bsim_trial_run(r, &s, backends[b], NULL, 1, &rec, &out, &err),
		                 BSIM_OK);
		assert_int_equal(t.steps, 875);
		assert_int_equal(out.instability, BSIM_STABLE);
		assert_true(t.v_err < (b == 0 ? 1e-12 : 1e-5));
		double k = t.a_over_m / t.w;
		assert_true(t.x_err < k * s.dt);
		assert_true(t.x_scale > 1.0); /* the body did move: metres */
		double e_end = out.ledger.e_end;
		assert_true(e_end > 0.1);
		/* The thesis backend's position update is the trapezoid's, so the
		 * work over the displacement is the kinetic energy gained; Box2D's
		 * x += h v_(n+1) books h^2 F_n^2 / (2 m) more work per step (its
		 * ledger residual is minus their sum, first order in h). */
		double extra = 0.0;
		for (long n = 0; n < 875; n++) {
			double tn = n * s.dt, w = t.w;
			double f =
			        5.0 * (cos(w * tn + 0.3) - cos(w * (tn + s.dt) + 0.3)) / (w * s.dt);
			extra += s.dt * s.dt * f * f / (2.0 * 2.0);
		}
		if (b == 0) {
			assert_true(fabs(out.ledger.w_osc - e_end) < 1e-9 * e_end);
			assert_true(fabs(out.ledger.residual) < 1e-9 * e_end);
		} else {
			assert_true(fabs(out.ledger.residual + extra) < 0.01 * extra);
		}
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

/* A disk of 1 kg sliding at 5 m/s with mu = 0.5 on both backends: the
 * speed falls by mu g per second along the line it started on, the body
 * stops at v0^2 / (2 mu g) = 2.548 m from its start (within |v0| h, the
 * backends' position updates) at t = |v0| / (mu g) (within a step; two on Box2D) and then
 * stays at rest; the ledger books the kinetic energy as friction loss. */
static void test_ground_friction_stopping_distance(void **state)
{
	(void)state;
	for (int b = 0; b < 2; b++) {
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
		assert_int_equal(bsim_trial_run(r, &s, backends[b], NULL, 1, &rec, &out, &err),
		                 BSIM_OK);
		assert_int_equal(out.instability, BSIM_STABLE);
		assert_true(t.stop_step > 0);
		/* Box2D's single-precision velocity reaches 0 a step later */
		assert_true(fabs(t.stop_step * s.dt - v0 / mu_g) <= (b == 0 ? 1 : 2) * s.dt);
		double dist = hypot(t.x_stop[0] - t.x0[0], t.x_stop[1] - t.x0[1]);
		assert_true(fabs(dist - v0 * v0 / (2.0 * mu_g)) < v0 * s.dt);
		/* along the initial direction */
		assert_true(fabs((t.x_stop[0] - t.x0[0]) / dist - 0.6) < 1e-5);
		assert_true(t.turned < (b == 0 ? 1e-12 : 1e-5));
		assert_true(t.v_err < (b == 0 ? 1e-9 : 1e-5));
		assert_true(t.after < 1e-12);
		double e0 = 12.5;
		assert_true(fabs(out.ledger.friction - e0) < (b == 0 ? 1e-9 : 0.02) * e0);
		if (b == 0)
			assert_true(fabs(out.ledger.residual) < 1e-9 * e0);
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
 * accelerates at (F - mu m g) / m. Both backends. */
static void test_ground_friction_stick(void **state)
{
	(void)state;
	const double forces[2] = {4.9, 6.0};
	for (int b = 0; b < 2; b++)
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
			assert_int_equal(
			        bsim_trial_run(r, &s, backends[b], NULL, 1, &rec, &out, &err),
			        BSIM_OK);
			if (k == 0) {
				assert_true(t.v_err == 0.0);
				assert_true(t.moved == 0.0);
				assert_true(out.ledger.friction == 0.0);
			} else {
				assert_true(t.v_err < (b == 0 ? 1e-9 : 1e-4));
				assert_true(t.moved > 1.0);
			}
			bsim_trial_runner_free(r);
			bsim_scene_free(&s);
		}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_drag_free_decay),
	        cmocka_unit_test(test_drag_absent),
	        cmocka_unit_test(test_oscillation_free_body),
	        cmocka_unit_test(test_ground_friction_stopping_distance),
	        cmocka_unit_test(test_ground_friction_stick),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
