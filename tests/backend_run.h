/* Running a backend under its knobs in the tests (include after cmocka.h):
 * options from "key=value" text, a trial that must succeed, and a beam
 * released from rest measured against the damped oscillator (the largest
 * error, and the decay rate and period read off the peaks). */
#ifndef BSIM_TESTS_BACKEND_RUN_H
#define BSIM_TESTS_BACKEND_RUN_H

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "beamsim/backend.h"
#include "beamsim/trial.h"
#include "scenes.h"
#include "support.h"

/* Options from up to two "key=value" (NULL: none). */
static inline bsim_options test_options(const char *kv1, const char *kv2)
{
	bsim_options o;
	bsim_error err;
	memset(&o, 0, sizeof o);
	if (kv1)
		assert_int_equal(bsim_options_add(&o, kv1, &err), BSIM_OK);
	if (kv2)
		assert_int_equal(bsim_options_add(&o, kv2, &err), BSIM_OK);
	return o;
}

/* A trial of s on b with o and the (mixed) seed; the test fails, saying
 * why, if it cannot run. */
static inline bsim_trial_result test_trial(const bsim_backend *b, const bsim_scene *s,
                                           const bsim_options *o, uint64_t seed)
{
	bsim_trial_runner *r = bsim_trial_runner_alloc();
	bsim_trial_result out;
	bsim_error err;
	int rc = bsim_trial_run(r, s, b, o, seed, NULL, &out, &err);
	if (rc)
		print_message("trial: %s\n", err.msg);
	assert_int_equal(rc, BSIM_OK);
	bsim_trial_runner_free(r);
	return out;
}

/* A Table 2.1 beam alone (no body in reach) with stiffness k and damping d,
 * released from theta0 at rest at rest angle rest_deg (its pivot kept), on
 * backend b with its defaults. */
static inline bsim_world *test_beam_released(const bsim_backend *b, bsim_scene *s, double k,
                                             double d, double theta0, double rest_deg)
{
	scene_one_beam(s);
	s->beams[0].stiffness = k;
	s->beams[0].damping = d;
	s->beams[0].initial_theta = theta0;
	s->beams[0].rest_angle_deg = rest_deg;
	return bsim_test_world(b, s, NULL);
}

/* Over 3 s from 0.1 rad: the largest |theta - exact|, and from the peaks of
 * |theta| (its local maxima, every half period) the decay rate
 * ln(A_first / A_last) / (t_last - t_first) and the period, each relative to
 * the oscillator's (zeta omega_n, 2 pi / omega_d) less 1. Each peak's time
 * and height are the vertex of the parabola through the sample at the
 * local maximum and its two neighbours: read off the samples alone, the
 * peaks' times are whole steps, which puts up to h / (t_last - t_first)
 * (0.2% at 4 ms) into the period and the rate. */
typedef struct vibration {
	double worst, rate_rel, period_rel;
} vibration;

/* A Table 2.1 beam (k 400 N m/rad, d 50 N m s/rad, I 20.83 kg m^2) alone,
 * on backend b with the option kv (NULL: none) at step h; rest_deg 180
 * puts it at (25, 0) pointing -x, the right-hand beam of a gate. */
static inline vibration beam_vibration(const bsim_backend *b, const char *kv, double h,
                                       double rest_deg)
{
	bsim_scene s;
	scene_one_beam(&s);
	const double k = 400.0, d = 50.0;
	s.beams[0].stiffness = k;
	s.beams[0].damping = d;
	s.beams[0].initial_theta = 0.1;
	s.beams[0].rest_angle_deg = rest_deg;
	if (rest_deg > 90.0)
		s.beams[0].pivot[0] = 25.0;
	bsim_options o = test_options(kv, NULL);
	bsim_world *w = bsim_test_world(b, &s, &o);
	bsim_state st;
	bsim_state_init(&st, 1);
	const double zero[2] = {0.0, 0.0}, inertia = s.beams[0].inertia;
	double worst = 0.0, damper = 0.0, prev = 0.1, prev2 = 0.1;
	double t_first = -1.0, a_first = 0.0, t_last = 0.0, a_last = 0.0;
	int peaks = 0;
	long n_steps = lround(3.0 / h);
	for (long n = 1; n <= n_steps; n++) {
		assert_int_equal(bsim_backend_step(b, w, zero, 0.0, h, NULL), BSIM_OK);
		b->get_state(w, &st);
		double t = (double)n * h;
		worst = fmax(worst, fabs(st.theta[0] - damped_oscillator(k, d, inertia, 0.1, t)));
		if (n >= 2 && fabs(prev) > fabs(prev2) && fabs(prev) >= fabs(st.theta[0])) {
			/* the parabola through (-h, y0), (0, y1), (h, y2) */
			const double y0 = fabs(prev2), y1 = fabs(prev), y2 = fabs(st.theta[0]);
			const double u = 0.5 * (y0 - y2) / (y0 - 2.0 * y1 + y2); /* in steps */
			const double t_peak = t - h + u * h, a_peak = y1 - 0.25 * (y0 - y2) * u;
			if (t_first < 0.0) {
				t_first = t_peak;
				a_first = a_peak;
			}
			t_last = t_peak;
			a_last = a_peak;
			peaks++;
		}
		prev2 = prev;
		prev = st.theta[0];
		damper += st.energy.damper;
	}
	assert_true(peaks >= 3);
	assert_true(damper > 0.0);
	double wn = sqrt(k / inertia), zeta = d / (2.0 * sqrt(k * inertia));
	double rate = log(a_first / a_last) / (t_last - t_first);
	double period = 2.0 * (t_last - t_first) / (peaks - 1);
	vibration v = {worst, rate / (zeta * wn) - 1.0,
	               period / (2.0 * 3.14159265358979323846 / (wn * sqrt(1.0 - zeta * zeta))) -
	                       1.0};
	bsim_state_free(&st);
	b->destroy(w);
	bsim_scene_free(&s);
	return v;
}

#endif
