/* What the thesis step keeps from one step to the next only saves work: a
 * world kept from trial to trial and reset (bsim_trial_runner_keep_worlds)
 * runs each trial as a world built for it; a
 * world that has stepped a whole trial (its beams' geometry against the
 * body, the distance bound that skips far beams, the beam constants for the
 * step size, the random force's held value) steps exactly as a world
 * created afresh from the same state, which has none of them. Also the
 * inlined fmax/fmin against IEEE 754's maximumNumber/minimumNumber and the
 * C library, and the schedule's held value against its definition,
 * value(index(n)). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>

#include "beamsim/contact_flag.h"
#include "beamsim/backend.h"
#include "beamsim/effects.h"
#include "beamsim/lattice.h"
#include "beamsim/schedule.h"
#include "beamsim/trial.h"
#include "util/fminmax.h"
#include "support.h"
#include "thesis/thesis.h"

/* maximumNumber / minimumNumber (IEEE 754-2019): the larger (smaller) of
 * the two in the order -inf < ... < -0 < +0 < ... < +inf, a NaN operand
 * ignored; so commutative to the bit, and equal to the C library's fmax and
 * fmin wherever C fixes their result (all but a pair of zeros). */
static int order_less(double a, double b)
{
	return a < b || (a == b && signbit(a) && !signbit(b));
}

static void test_fminmax_ieee(void **state)
{
	(void)state;
	const double v[] = {0.0, -0.0, 1.0, -1.0, NAN, -NAN, INFINITY, -INFINITY, 1e-310, 3.5};
	const int n = (int)(sizeof v / sizeof v[0]);
	double (*volatile lib_max)(double, double) = fmax;
	double (*volatile lib_min)(double, double) = fmin;
	for (int i = 0; i < n; i++)
		for (int j = 0; j < n; j++) {
			double a = v[i], b = v[j];
			double mx = bsim_fmax(a, b), mn = bsim_fmin(a, b);
			double mx2 = bsim_fmax(b, a), mn2 = bsim_fmin(b, a);
			if (isnan(a) && isnan(b)) {
				assert_true(isnan(mx) && isnan(mn));
				continue;
			}
			double want_max = isnan(a) ? b : isnan(b) ? a : order_less(a, b) ? b : a;
			double want_min = isnan(a) ? b : isnan(b) ? a : order_less(a, b) ? a : b;
			assert_memory_equal(&mx, &want_max, sizeof mx);
			assert_memory_equal(&mn, &want_min, sizeof mn);
			assert_memory_equal(&mx, &mx2, sizeof mx);
			assert_memory_equal(&mn, &mn2, sizeof mn);
			if (!(a == 0.0 && b == 0.0)) {
				double lx = lib_max(a, b), ln = lib_min(a, b);
				assert_memory_equal(&mx, &lx, sizeof mx);
				assert_memory_equal(&mn, &ln, sizeof mn);
			}
		}
}

/* The held value read at step n is value(index(n)), for steps that divide
 * the hold (50 Hz at 4 ms: 5 steps) and steps that do not (50 Hz at 3 ms),
 * read in order, backwards and at random. */
static void test_schedule_held_value(void **state)
{
	(void)state;
	const double hs[] = {0.004, 0.003};
	for (int k = 0; k < 2; k++) {
		bsim_schedule *held = bsim_schedule_alloc(20.0, 50.0, 7);
		bsim_schedule *ref = bsim_schedule_alloc(20.0, 50.0, 7);
		assert_non_null(held);
		assert_non_null(ref);
		double h = hs[k];
		long order[3000];
		for (long n = 0; n < 1000; n++) {
			order[n] = n;
			order[1000 + n] = 999 - n;
			order[2000 + n] = (n * 7919) % 1000;
		}
		for (int m = 0; m < 3000; m++) {
			long n = order[m];
			double a = bsim_schedule_at_step(held, n, h);
			double b = bsim_schedule_value(ref, bsim_schedule_index(ref, n, h));
			assert_memory_equal(&a, &b, sizeof a);
		}
		bsim_schedule_free(held);
		bsim_schedule_free(ref);
	}
}

/* The pipeline's forces, the held random force read inline between its
 * refreshes (bsim_effects_force_at), against the definition: 0 + F_prop
 * along y, 0 + value(index(n)) along x, read in order, backwards and at
 * random, at a step that divides the hold and one that does not. */
static void test_effects_held_inline(void **state)
{
	(void)state;
	const double hs[] = {0.004, 0.003};
	for (int k = 0; k < 2; k++) {
		bsim_scene s;
		bsim_scene_init_gate(&s, 7.0, 20.0);
		bsim_effects fx;
		assert_int_equal(bsim_effects_init(&fx, &s, 11), BSIM_OK);
		bsim_schedule *ref = bsim_schedule_alloc(20.0, s.effects.random_frequency, 11);
		assert_non_null(ref);
		double h = hs[k];
		long order[3000];
		for (long n = 0; n < 1000; n++) {
			order[n] = n;
			order[1000 + n] = 999 - n;
			order[2000 + n] = (n * 7919) % 1000;
		}
		const bsim_state rest = {0};
		for (int m = 0; m < 3000; m++) {
			long n = order[m];
			double f[BSIM_WRENCH];
			bsim_effects_force_at(&fx, n, h, &rest, f);
			double want[BSIM_WRENCH] = {0.0, 0.0, 0.0};
			want[0] += bsim_schedule_value(ref, bsim_schedule_index(ref, n, h));
			want[1] += 7.0;
			assert_memory_equal(f, want, sizeof f);
			assert_memory_equal(&fx.random->last, &want[0], sizeof want[0]);
		}
		bsim_schedule_free(ref);
		bsim_effects_free(&fx);
		bsim_scene_free(&s);
	}
}

static void assert_same_step(const bsim_state *a, const bsim_state *b)
{
	assert_memory_equal(a->x, b->x, sizeof a->x);
	assert_memory_equal(a->v, b->v, sizeof a->v);
	assert_memory_equal(a->theta, b->theta, (size_t)a->n_beams * sizeof *a->theta);
	assert_memory_equal(a->omega, b->omega, (size_t)a->n_beams * sizeof *a->omega);
	assert_memory_equal(a->contact, b->contact, (size_t)a->n_beams * sizeof *a->contact);
	assert_memory_equal(&a->energy, &b->energy, sizeof a->energy);
	assert_int_equal(a->impacts, b->impacts);
}

/* Steps world A through n_steps of the scene; before each step a world B is
 * created from A's state, and both take the step: B's (nothing kept) must
 * equal A's to the bit. Returns the steps in which the body touched. */
static int step_against_fresh(const bsim_scene *sc, uint64_t seed, int n_steps)
{
	const bsim_backend *be = bsim_test_backend("thesis");
	bsim_error err;
	bsim_world *a = NULL;
	assert_int_equal(be->create(sc, NULL, &a, &err), BSIM_OK);
	bsim_effects fx;
	assert_int_equal(bsim_effects_init(&fx, sc, seed), BSIM_OK);
	bsim_state sa, sb;
	assert_int_equal(bsim_state_init(&sa, sc->n_beams), BSIM_OK);
	assert_int_equal(bsim_state_init(&sb, sc->n_beams), BSIM_OK);
	int touching = 0;
	for (int n = 0; n < n_steps; n++) {
		double f[BSIM_WRENCH];
		bsim_effects_force(&fx, n, sc->dt, f);
		be->get_state(a, &sa);
		bsim_contact_flags(sc, &sa);
		bsim_world *b = NULL;
		assert_int_equal(be->create(sc, NULL, &b, &err), BSIM_OK);
		assert_int_equal(be->set_state(b, &sa, &err), BSIM_OK);
		assert_int_equal(bsim_backend_step(be, a, f, 0.0, sc->dt, &err), BSIM_OK);
		assert_int_equal(bsim_backend_step(be, b, f, 0.0, sc->dt, &err), BSIM_OK);
		be->get_state(a, &sa);
		bsim_contact_flags(sc, &sa);
		be->get_state(b, &sb);
		bsim_contact_flags(sc, &sb);
		assert_same_step(&sa, &sb);
		be->destroy(b);
		for (int k = 0; k < sa.n_active; k++)
			if (sa.contact[sa.active[k]]) {
				touching++;
				break;
			}
	}
	bsim_state_free(&sa);
	bsim_state_free(&sb);
	bsim_effects_free(&fx);
	be->destroy(a);
	return touching;
}

/* The essay's gate: the body swings the beams, touches both, and in some
 * trials gets through (F = 9 N) or stays pressed (F = 6 N). */
static void test_gate_as_fresh(void **state)
{
	(void)state;
	const double forces[] = {6.0, 9.0};
	for (int k = 0; k < 2; k++) {
		bsim_scene s;
		bsim_scene_init_gate(&s, forces[k], 30.0);
		int touching = step_against_fresh(&s, 11 + (uint64_t)k, 2000);
		assert_true(touching > 100); /* the caches were used in contact */
		bsim_scene_free(&s);
	}
}

/* A lattice: the grid's broad phase and sleeping beams besides. */
static void test_lattice_as_fresh(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_error err;
	if (bsim_scene_load(bsim_test_src("configs/lattice/uniform_9x9.yaml"), NULL, 0, &s, &err))
		fail_msg("%s", err.msg);
	assert_true(step_against_fresh(&s, 3, 3000) > 100);
	bsim_scene_free(&s);
}

/* Free flight's shortcut (no beam in reach, none moving: no detection)
 * against detection every step (broad_phase=0): the same trials to the bit,
 * from starts below the gate at which the body flies free, then meets the
 * beams. */
static void test_free_flight_as_detection(void **state)
{
	(void)state;
	bsim_options every;
	bsim_error err;
	memset(&every, 0, sizeof every);
	assert_int_equal(bsim_options_add(&every, "broad_phase=0", &err), BSIM_OK);
	bsim_trial_runner *r = bsim_trial_runner_alloc();
	for (int k = 0; k < 4; k++) {
		bsim_scene s;
		bsim_scene_init_gate(&s, 6.0 + k, k ? 10.0 : 0.0);
		s.body.start[1] = -15.0 * k;
		bsim_trial_result a, b;
		assert_int_equal(bsim_trial_run(r, &s, bsim_test_backend("thesis"), NULL,
		                                5 + (uint64_t)k, NULL, &a, &err),
		                 BSIM_OK);
		assert_int_equal(bsim_trial_run(r, &s, bsim_test_backend("thesis"), &every,
		                                5 + (uint64_t)k, NULL, &b, &err),
		                 BSIM_OK);
		assert_true(a.max_theta[0] > 0.0 || a.max_theta[1] > 0.0); /* the beams were met */
		assert_memory_equal(&a.ledger, &b.ledger, sizeof a.ledger);
		assert_memory_equal(&a.x_end, &b.x_end, sizeof a.x_end);
		assert_memory_equal(&a.y_end, &b.y_end, sizeof a.y_end);
		assert_memory_equal(a.max_theta, b.max_theta, sizeof a.max_theta);
		assert_int_equal(a.steps_run, b.steps_run);
		assert_int_equal(a.outcome, b.outcome);
		bsim_scene_free(&s);
	}
	bsim_trial_runner_free(r);
}

/* The distance from x to beam b's segment at rest (P to P + L u0), m:
 * the nearest point by the clamped projection, written here apart from the
 * library's. */
static double rest_segment_distance(const thesis_beam_model *b, const double x[2])
{
	double dx = x[0] - b->p[0], dy = x[1] - b->p[1];
	double s = dx * b->u0[0] + dy * b->u0[1];
	s = s < 0.0 ? 0.0 : s > b->length ? b->length : s;
	double qx = dx - s * b->u0[0], qy = dy - s * b->u0[1];
	return sqrt(qx * qx + qy * qy);
}

/* What a clear step must be, for the body at w->x with speed bound speed
 * (|v| + h |F| / M) among beams at rest: every beam's segment farther than
 * R + its step margin (the step's detection finds no contact) and farther
 * than R + BSIM_CONTACT_TOL + 2 h speed (the body ends the step more than
 * BSIM_CONTACT_TOL from it: no contact flag). */
static void assert_clear_truly(const bsim_world *w, double speed, double h)
{
	for (int i = 0; i < w->model->n_beams; i++) {
		const thesis_beam_model *c = &w->model->beams[i];
		double d = rest_segment_distance(c, w->x);
		assert_true(d >
		            w->model->radius + thesis_step_margin(w, c, &w->beams[i], speed, h));
		assert_true(d > w->model->radius + BSIM_CONTACT_TOL + 2.0 * h * speed);
	}
}

/* The body's centre x at distance r from the segment from p along u (unit)
 * of the given length: off its side (t % 4 = 0 or 1, one side each, at a
 * random point along it: the nearest point inside), or off one of its ends
 * (2: the pivot's, 3: the tip's, at a random angle, away from the
 * segment). */
static void place_off_segment(gsl_rng *rng, int t, const double p[2], const double u[2],
                              double length, double r, double x[2])
{
	double along, dir[2];
	if (t % 4 < 2) {
		along = gsl_ran_flat(rng, 0.0, length);
		double side = t % 4 ? 1.0 : -1.0;
		dir[0] = -side * u[1];
		dir[1] = side * u[0];
	} else {
		int tip = t % 4 == 3;
		along = tip ? length : 0.0;
		double phi = gsl_ran_flat(rng, -1.5707963267948966, 1.5707963267948966);
		double out = tip ? 1.0 : -1.0;
		dir[0] = out * (u[0] * cos(phi) - u[1] * sin(phi));
		dir[1] = out * (u[1] * cos(phi) + u[0] * sin(phi));
	}
	x[0] = p[0] + along * u[0] + r * dir[0];
	x[1] = p[1] + along * u[1] + r * dir[1];
}

/* The free-flight test itself, at the edge of reach: the body's centre
 * placed at random within 1% of R + m of a point of a beam's segment (m
 * the test's own margin, thesis_clear_margin), at speeds that make the
 * margin matter. Whenever the test calls
 * the step clear, the beams truly are out of reach (assert_clear_truly);
 * and it does call many steps clear. */
static void test_free_flight_bound(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 7.0, 20.0);
	bsim_world *w = NULL;
	bsim_error err;
	assert_int_equal(bsim_test_backend("thesis")->create(&s, NULL, &w, &err), BSIM_OK);
	gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
	const double h = s.dt;
	int clear = 0;
	for (int t = 0; t < 200000; t++) {
		double f[2] = {gsl_ran_gaussian(rng, 30.0), 7.0};
		w->v[0] = gsl_ran_gaussian(rng, 50.0);
		w->v[1] = gsl_ran_gaussian(rng, 50.0);
		double speed = sqrt(w->v[0] * w->v[0] + w->v[1] * w->v[1]) +
		               h * sqrt(f[0] * f[0] + f[1] * f[1]) * w->model->inv_mass;
		const thesis_beam_model *b = &w->model->beams[(t / 4) % 2];
		double reach = w->model->radius + thesis_clear_margin(w, f, h);
		double r = reach * (1.0 + gsl_ran_flat(rng, -1e-2, 1e-2));
		place_off_segment(rng, t, b->p, b->u0, b->length, r, w->x);
		if (!bsim_thesis_broad_phase_clear(w, f, h))
			continue;
		clear++;
		assert_clear_truly(w, speed, h);
	}
	assert_true(clear > 20000);
	gsl_rng_free(rng);
	bsim_test_backend("thesis")->destroy(w);
	bsim_scene_free(&s);
}

/* The projection's re-detection (bsim_thesis_contact_redetect_disk) skips the
 * distance bound geometry_far, which only saves the exact test: it finds
 * the contact detection finds, bit for bit. The body is placed near a beam
 * at a small angle, its last geometry computed at a configuration a little
 * away (a random step of the body and of the angle), so that the bound is
 * stale and often decides; each case is detected both ways from the same
 * cached geometry: the same count, and a contact found the same to the
 * bit. The bound rejects many of the cases, and the contacts found are
 * many too. */
static void test_redetect_as_detect(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 7.0, 20.0);
	bsim_world *w = NULL;
	bsim_error err;
	assert_int_equal(bsim_test_backend("thesis")->create(&s, NULL, &w, &err), BSIM_OK);
	gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
	int far = 0, found = 0;
	for (int t = 0; t < 100000; t++) {
		int i = (t / 4) % 2;
		const thesis_beam_model *bm = &w->model->beams[i];
		thesis_beam *b = &w->beams[i];
		const double margin = gsl_ran_flat(rng, 1e-4, 5e-3);
		/* the configuration of the cached geometry: the body's centre
		 * off the segment's side or off an end, within a few margins of
		 * R + margin */
		b->theta = gsl_ran_flat(rng, -0.3, 0.3);
		double u[2];
		thesis_beam_direction(bm, b, u);
		double r = w->model->radius + margin * gsl_ran_flat(rng, 0.0, 4.0);
		place_off_segment(rng, t, bm->p, u, bm->length, r, w->x);
		thesis_contact c0, c1;
		bsim_thesis_contact_detect_disk(w, i, margin, &c0); /* the geometry cached */
		/* the configuration detected: a step away */
		double step = margin * gsl_ran_flat(rng, 0.0, 2.0);
		w->x[0] += gsl_ran_flat(rng, -step, step);
		w->x[1] += gsl_ran_flat(rng, -step, step);
		b->theta += gsl_ran_flat(rng, -1e-3, 1e-3);
		far += geometry_far(w, bm, b, w->x, w->model->radius, margin, 0);
		const thesis_beam kept = *b;
		memset(&c0, 0, sizeof c0);
		memset(&c1, 0, sizeof c1);
		int n0 = bsim_thesis_contact_detect_disk(w, i, margin, &c0);
		*b = kept;
		int n1 = bsim_thesis_contact_redetect_disk(w, i, margin, &c1);
		assert_int_equal(n0, n1);
		if (n1) /* without a contact out's fields say nothing */
			assert_memory_equal(&c0, &c1, sizeof c0);
		found += n1;
	}
	print_message("redetection: %d of 100000 cases rejected by the bound, %d contacts\n", far,
	              found);
	assert_true(far > 3000);
	assert_true(found > 10000);
	gsl_rng_free(rng);
	bsim_test_backend("thesis")->destroy(w);
	bsim_scene_free(&s);
}

/* The free-flight room (broad_phase.c clear_fill): a body wandering in
 * small random steps under the middle of beam 0, in and out of its reach,
 * at speeds that make the margin matter, so that most steps are decided
 * by the room kept from an earlier step. Whenever the step is called
 * clear, the beams truly are out of reach. */
static void test_free_flight_room(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 7.0, 20.0);
	bsim_world *w = NULL;
	bsim_error err;
	assert_int_equal(bsim_test_backend("thesis")->create(&s, NULL, &w, &err), BSIM_OK);
	gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
	const double h = s.dt;
	/* R + 5 cm under the middle of beam 0 (it points along +x) */
	const thesis_beam_model *b0 = &w->model->beams[0];
	const double home[2] = {b0->p[0] + 0.5 * b0->length, b0->p[1] - w->model->radius - 0.05};
	w->x[0] = home[0];
	w->x[1] = home[1];
	int clear = 0, by_room = 0;
	for (int t = 0; t < 200000; t++) {
		double f[2] = {gsl_ran_gaussian(rng, 30.0), 7.0};
		w->v[0] = gsl_ran_gaussian(rng, 5.0);
		w->v[1] = gsl_ran_gaussian(rng, 5.0);
		w->x[0] += gsl_ran_gaussian(rng, 2e-3);
		w->x[1] += gsl_ran_gaussian(rng, 2e-3);
		/* kept within 10 cm of home: in and out of reach */
		double ex = w->x[0] - home[0], ey = w->x[1] - home[1];
		if (ex * ex + ey * ey > 0.01) {
			w->x[0] = home[0];
			w->x[1] = home[1];
		}
		double room_before = w->clear_room, cx = w->clear_x[0], cy = w->clear_x[1];
		if (!bsim_thesis_broad_phase_clear(w, f, h))
			continue;
		clear++;
		by_room +=
		        w->clear_room == room_before && w->clear_x[0] == cx && w->clear_x[1] == cy;
		double speed = sqrt(w->v[0] * w->v[0] + w->v[1] * w->v[1]) +
		               h * sqrt(f[0] * f[0] + f[1] * f[1]) * w->model->inv_mass;
		assert_clear_truly(w, speed, h);
	}
	assert_true(clear > 20000);
	assert_true(by_room > clear / 2);
	gsl_rng_free(rng);
	bsim_test_backend("thesis")->destroy(w);
	bsim_scene_free(&s);
}

/* Steps a and b side by side through n steps of sc's effects (seed): the
 * same states to the bit. Returns the steps in which the body touched. */
static int step_pair_same(bsim_world *a, bsim_world *b, const bsim_scene *sc, uint64_t seed, int n)
{
	const bsim_backend *be = bsim_test_backend("thesis");
	bsim_error err;
	bsim_effects fx;
	assert_int_equal(bsim_effects_init(&fx, sc, seed), BSIM_OK);
	bsim_state sa, sb;
	assert_int_equal(bsim_state_init(&sa, sc->n_beams), BSIM_OK);
	assert_int_equal(bsim_state_init(&sb, sc->n_beams), BSIM_OK);
	int touched = 0;
	for (int k = 0; k < n; k++) {
		double f[BSIM_WRENCH];
		be->get_state(a, &sa);
		bsim_contact_flags(sc, &sa);
		bsim_effects_force_at(&fx, k, sc->dt, &sa, f);
		assert_int_equal(bsim_backend_step(be, a, f, f[2], sc->dt, &err), BSIM_OK);
		assert_int_equal(bsim_backend_step(be, b, f, f[2], sc->dt, &err), BSIM_OK);
		be->get_state(a, &sa);
		bsim_contact_flags(sc, &sa);
		be->get_state(b, &sb);
		bsim_contact_flags(sc, &sb);
		assert_same_step(&sa, &sb);
		touched += sa.contact[0] || sa.contact[1];
	}
	bsim_state_free(&sa);
	bsim_state_free(&sb);
	bsim_effects_free(&fx);
	return touched;
}

/* A world reset to its scene with the body started elsewhere (markov's
 * single-gate trials), and one reset and then set to a state (accuracy's
 * restarted pieces), step as worlds created for them. */
static void test_reset_as_created(void **state)
{
	(void)state;
	const bsim_backend *be = bsim_test_backend("thesis");
	bsim_error err;
	bsim_scene s;
	bsim_scene_init_gate(&s, 7.0, 20.0);
	bsim_world *kept = NULL, *fresh = NULL;
	assert_int_equal(be->create(&s, NULL, &kept, &err), BSIM_OK);
	int touched = 0;
	for (int t = 0; t < 6; t++) {
		/* the last trial's steps, then the body moved */
		bsim_state st;
		assert_int_equal(bsim_state_init(&st, s.n_beams), BSIM_OK);
		for (int k = 0; k < 400; k++) {
			double f[2] = {0.0, 7.0};
			assert_int_equal(bsim_backend_step(be, kept, f, 0.0, s.dt, &err), BSIM_OK);
		}
		be->get_state(kept, &st);
		s.body.start[0] = 0.01 * (t - 3);
		s.body.velocity[0] = 0.2 * (t - 2);
		s.body.velocity[1] = 0.5 + 0.1 * t;
		assert_int_equal(be->reset(kept, &s, &err), BSIM_OK);
		assert_int_equal(be->create(&s, NULL, &fresh, &err), BSIM_OK);
		touched += step_pair_same(kept, fresh, &s, 100 + (uint64_t)t, 600);
		be->destroy(fresh);
		/* reset, then set to the state of a step that touched */
		assert_int_equal(be->reset(kept, &s, &err), BSIM_OK);
		assert_int_equal(be->create(&s, NULL, &fresh, &err), BSIM_OK);
		assert_int_equal(be->set_state(kept, &st, &err), BSIM_OK);
		assert_int_equal(be->set_state(fresh, &st, &err), BSIM_OK);
		touched += step_pair_same(kept, fresh, &s, 200 + (uint64_t)t, 300);
		be->destroy(fresh);
		bsim_state_free(&st);
	}
	assert_true(touched > 0); /* the beams were met */
	be->destroy(kept);
	bsim_scene_free(&s);
}

/* Trials of one scene in a world kept and reset between them against each
 * in a world built for it: the same results and beam peaks to the bit. On
 * a 5 x 5 lattice (the body pushes, wakes and leaves many beams; whole
 * world and the essay's protocol) and on a gate whose beam 1 starts
 * deflected and swinging (beams awake at the start). */
static void kept_against_built(const bsim_scene *s, int trials)
{
	bsim_trial_runner *kept = bsim_trial_runner_alloc(), *built = bsim_trial_runner_alloc();
	bsim_trial_log *la = bsim_trial_log_alloc(), *lb = bsim_trial_log_alloc();
	bsim_error err;
	bsim_trial_runner_keep_worlds(kept, 1);
	bsim_recorder ra = {.stride = 1, .log = la}, rb = {.stride = 1, .log = lb};
	long gates = 0;
	for (int t = 0; t < trials; t++) {
		uint64_t seed = bsim_schedule_seed_mix(4, 0, (uint64_t)t);
		bsim_trial_result a, b;
		assert_int_equal(bsim_trial_run(kept, s, bsim_test_backend("thesis"), NULL, seed,
		                                &ra, &a, &err),
		                 BSIM_OK);
		assert_int_equal(bsim_trial_run(built, s, bsim_test_backend("thesis"), NULL, seed,
		                                &rb, &b, &err),
		                 BSIM_OK);
		assert_memory_equal(&a.ledger, &b.ledger, sizeof a.ledger);
		assert_memory_equal(&a.x_end, &b.x_end, sizeof a.x_end);
		assert_memory_equal(&a.y_end, &b.y_end, sizeof a.y_end);
		assert_memory_equal(&a.vx_end, &b.vx_end, sizeof a.vx_end);
		assert_memory_equal(a.max_theta, b.max_theta, sizeof a.max_theta);
		assert_memory_equal(&a.solver, &b.solver, sizeof a.solver);
		assert_int_equal(a.steps_run, b.steps_run);
		assert_int_equal(a.outcome, b.outcome);
		assert_int_equal(a.gates_entered, b.gates_entered);
		assert_int_equal(la->n_beams, lb->n_beams);
		assert_int_equal(la->n_peaks, lb->n_peaks);
		for (int k = 0; k < la->n_peaks; k++) {
			assert_int_equal(la->peaks[k].beam, lb->peaks[k].beam);
			assert_memory_equal(&la->peaks[k].peak, &lb->peaks[k].peak, sizeof(double));
		}
		gates += a.gates_entered;
	}
	if (s->has_lattice)
		assert_true(gates > trials); /* the body went through several gates */
	bsim_trial_log_free(la);
	bsim_trial_log_free(lb);
	bsim_trial_runner_free(kept);
	bsim_trial_runner_free(built);
}

static void test_kept_world_as_built(void **state)
{
	(void)state;
	bsim_scene s;
	assert_int_equal(bsim_lattice_scene_init(&s, 5, 5, 6.0, 30.0), BSIM_OK);
	kept_against_built(&s, 12);
	s.lattice.protocol = BSIM_PROTOCOL_ESSAY;
	kept_against_built(&s, 6);
	bsim_scene_free(&s);
	bsim_scene_init_gate(&s, 6.0, 30.0);
	s.beams[1].initial_theta = 0.2;
	s.beams[1].initial_omega = -1.0;
	kept_against_built(&s, 6);
	bsim_scene_free(&s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_fminmax_ieee),
	        cmocka_unit_test(test_schedule_held_value),
	        cmocka_unit_test(test_gate_as_fresh),
	        cmocka_unit_test(test_lattice_as_fresh),
	        cmocka_unit_test(test_free_flight_as_detection),
	        cmocka_unit_test(test_kept_world_as_built),
	        cmocka_unit_test(test_free_flight_bound),
	        cmocka_unit_test(test_free_flight_room),
	        cmocka_unit_test(test_redetect_as_detect),
	        cmocka_unit_test(test_effects_held_inline),
	        cmocka_unit_test(test_reset_as_created),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
