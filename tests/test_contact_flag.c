/* The contact flag (beamsim/state.h, beamsim/contact_flag.h) against
 * independent truths, on every backend of the registry: beam i is flagged in a step when
 * at the step's end the body is within BSIM_CONTACT_TOL (6 mm) of it, or
 * when it exchanged an impulse with the body in the step.
 *
 * - A head-on impact in free flight: the body, at speed u with a gap g0 to
 *   the beam and no force, touches it at t* = g0 / u. The first flagged
 *   step is the first that ends within the tolerance or holds t*, whichever
 *   comes first, on every backend; at 10 m/s the body has bounced clear by
 *   more than the tolerance at the impact step's end, so the impulse alone
 *   flags it, on a backend whose impact acts before the shapes overlap.
 * - A grazing pass parallel to the beam, from beside it to past its tip:
 *   the gap is known all along the straight path (the clearance c beside
 *   the beam, the distance to the tip beyond it); with c = 8 mm no step is
 *   flagged, with c = 3 mm exactly the steps that end with the analytic gap
 *   under the tolerance, tangent beside the beam and tip beyond it. No
 *   impulse acts (the motion is parallel), so this is the gap part alone.
 * - Every backend agrees with the default one on the flag step by step
 *   through an impact.
 * - The rule for a body that is not a disk (bsim_contact_flag_of, which
 *   every backend calls) against the gap measured by sampling: the
 *   capsule's and the ellipse's outlines and the beam's segment at many
 *   points, the gap the smallest distance between them, over random
 *   placements whose sampled gap is not within 2 mm of the tolerance; a
 *   segment through the body's centre line is in contact.
 * - What a backend reports for the runner's flag, on every backend, over
 *   trials of the gate at H1's forces: a beam it reports with a NaN
 *   direction (apart, its broad phase says) was not touched and lies
 *   beyond the tolerance by the exact gap from its angle; every flag the
 *   runner computed equals the rule applied to the direction from the
 *   beam's angle (so the reported direction is the angle's). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>

#include <cmocka.h>

#include "beamsim/backend.h"
#include "beamsim/contact_flag.h"
#include "beamsim/trial.h"
#include "scenes.h"
#include "support.h"

/* Runs the scene with no force for n steps; flags[k] the flag of beam 0
 * after step k + 1. */
static void run_flags(const bsim_backend *b, const bsim_scene *s, int n, int *flags)
{
	bsim_world *w = NULL;
	bsim_error err;
	assert_int_equal(b->create(s, NULL, &w, &err), BSIM_OK);
	bsim_state st;
	assert_int_equal(bsim_state_init(&st, s->n_beams), BSIM_OK);
	const double force[2] = {0.0, 0.0};
	for (int k = 0; k < n; k++) {
		assert_int_equal(bsim_backend_step(b, w, force, 0.0, s->dt, &err), BSIM_OK);
		b->get_state(w, &st);
		bsim_contact_flags(s, &st);
		flags[k] = st.contact[0];
	}
	bsim_state_free(&st);
	b->destroy(w);
}

/* The beam of scene_one_beam (pivot (0, 0), along +x, L = 25 m, R = 10 m,
 * no spring) and the body below it at x = 12.5 m (lever 12.5 m), gap g0,
 * moving up at u. */
static void scene_head_on(bsim_scene *s, double g0, double u)
{
	scene_one_beam(s);
	s->body.start[0] = 12.5;
	s->body.start[1] = -(s->body.radius + g0);
	s->body.velocity[1] = u;
}

/* The gap of beam 0 (scene_one_beam's, turned by theta) to a body centred
 * at x, from the geometry of the segment (0, 0)..L (cos theta, sin theta). */
static double gap_of(const bsim_scene *s, double theta, const double x[2])
{
	double ux = cos(theta), uy = sin(theta), L = s->beams[0].length;
	double a = fmin(fmax(x[0] * ux + x[1] * uy, 0.0), L);
	return hypot(x[0] - a * ux, x[1] - a * uy) - s->body.radius;
}

static void test_head_on_impact(void **state)
{
	const bsim_backend *b = *state;
	const double h = 0.004;
	/* speed, and where in its step the impact falls (steps from 1) */
	const struct {
		double u, where;
	} cases[] = {{2.0, 8.9}, {2.0, 4.3}, {10.0, 4.5}, {10.0, 2.2}};
	for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
		const double u = cases[c].u, t_star = cases[c].where * h, g0 = u * t_star;
		int step = (int)ceil(t_star / h); /* the step that holds t* */
		int near = (int)floor((g0 - BSIM_CONTACT_TOL) / (u * h)) + 1; /* ends within */
		int want = near < step ? near : step;
		bsim_scene s;
		scene_head_on(&s, g0, u);
		{
			bsim_world *w = NULL;
			bsim_error err;
			assert_int_equal(b->create(&s, NULL, &w, &err), BSIM_OK);
			bsim_state st;
			assert_int_equal(bsim_state_init(&st, 1), BSIM_OK);
			const double force[2] = {0.0, 0.0};
			int first = 0;
			double gap_at_impact = 0.0;
			for (int n = 1; n <= step; n++) {
				assert_int_equal(bsim_backend_step(b, w, force, 0.0, s.dt, &err),
				                 BSIM_OK);
				b->get_state(w, &st);
				bsim_contact_flags(&s, &st);
				if (st.contact[0] != BSIM_CONTACT_NONE && !first)
					first = n;
				if (n == step) {
					gap_at_impact = gap_of(&s, st.theta[0], st.x);
					assert_int_equal(st.contact[0], BSIM_CONTACT_TANGENT);
				}
			}
			print_message(
			        "%s: u = %g m/s, impact at t* = %.4f s (step %d), first ending "
			        "within %g m: step %d; first flagged step %d; gap at the impact "
			        "step's end %.4f m\n",
			        b->name, u, t_star, step, BSIM_CONTACT_TOL, near, first,
			        gap_at_impact);
			assert_int_equal(first, want);
			/* at 10 m/s a backend that resolves the impact before the
			 * shapes meet (the thesis backend's speculative contact,
			 * Box2D's skin) ends the impact step with the body clear: the
			 * impulse is what flags it. One whose contact acts once the
			 * shapes overlap (Chipmunk) ends it overlapping, flagged by
			 * the gap too. */
			if (u == 10.0 && near >= step) {
				if (gap_at_impact >= 0.0)
					assert_true(gap_at_impact > BSIM_CONTACT_TOL);
				else
					print_message(
					        "%s: the impact step ends overlapping (%.4f m): "
					        "the gap flags it too\n",
					        b->name, gap_at_impact);
			}
			bsim_state_free(&st);
			b->destroy(w);
		}
		bsim_scene_free(&s);
	}
}

/* The gap of the body centred at (x, y) to the segment (0, 0)..(L, 0), and
 * its type, computed here from the straight path. */
static double gap_along(double x, double y, double L, double R, int *type)
{
	*type = x > 0.0 && x < L ? BSIM_CONTACT_TANGENT : BSIM_CONTACT_TIP;
	double dx = x < 0.0 ? x : x > L ? x - L : 0.0;
	return hypot(dx, y) - R;
}

static void test_grazing_pass(void **state)
{
	const bsim_backend *b = *state;
	/* From beside the beam: approaching its pivot end from x < 0 at a
	 * clearance under 5 mm, Box2D's contact, which starts there, would push
	 * the body (a real impulse, flagged as it should be), and the gap
	 * would not be known. */
	const double clearance[] = {8e-3, 3e-3}, v = 5.0, x0 = 1.01;
	const int n = 2000; /* 40 m at 5 m/s: from x = 1.01 to 41.01 m, past the tip */
	static int flags[2000];
	for (size_t c = 0; c < 2; c++) {
		bsim_scene s;
		scene_one_beam(&s);
		const double R = s.body.radius, L = s.beams[0].length;
		s.body.start[0] = x0;
		s.body.start[1] = -(R + clearance[c]);
		s.body.velocity[0] = v;
		{
			run_flags(b, &s, n, flags);
			int flagged = 0, expected = 0, judged = 0;
			for (int i = 0; i < n; i++) {
				int type;
				double x = x0 + v * s.dt * (double)(i + 1);
				double gap = gap_along(x, s.body.start[1], L, R, &type);
				flagged += flags[i] != BSIM_CONTACT_NONE;
				/* Box2D keeps positions in float32 (1e-6 m here):
				 * steps that end within 1e-5 m of the tolerance are
				 * left unjudged. */
				if (fabs(gap - BSIM_CONTACT_TOL) < 1e-5)
					continue;
				judged++;
				int want = gap < BSIM_CONTACT_TOL ? type : BSIM_CONTACT_NONE;
				expected += want != BSIM_CONTACT_NONE;
				if (flags[i] != want)
					fail_msg("%s, clearance %g m: step %d (x = %.4f m, gap "
					         "%.6f m): "
					         "flag %d, expected %d",
					         b->name, clearance[c], i + 1, x, gap, flags[i],
					         want);
			}
			print_message("%s, clearance %g m: %d of %d steps flagged (%d expected, %d "
			              "judged)\n",
			              b->name, clearance[c], flagged, n, expected, judged);
			if (c == 0)
				assert_int_equal(flagged, 0);
			else
				assert_true(expected > 24 * 50); /* 24 m of beam at 0.02 m a step */
		}
		bsim_scene_free(&s);
	}
}

static void test_backends_agree(void **state)
{
	const bsim_backend *b = *state, *ref = bsim_backend_default();
	if (b == ref)
		bsim_test_skip(b, "the default backend is the reference the others agree with");
	bsim_scene s;
	scene_head_on(&s, 10.0 * 0.004 * 3.5, 10.0); /* impact in step 4 */
	int fa[60], fb[60];
	run_flags(ref, &s, 60, fa);
	run_flags(b, &s, 60, fb);
	for (int i = 0; i < 60; i++)
		if (fa[i] != fb[i])
			fail_msg("step %d: %s flag %d, %s %d", i + 1, ref->name, fa[i], b->name,
			         fb[i]);
	bsim_scene_free(&s);
}

/* A deterministic uniform deviate in [0, 1). */
static double unit_draw(unsigned long long *st)
{
	*st = *st * 6364136223846793005ull + 1442695040888963407ull;
	return (double)(*st >> 11) * 0x1.0p-53;
}

/* The outline's point at parameter t in [0, 1), m: the capsule (segment
 * 2 l along the heading e, radius r) walked as two sides and two half
 * circles; the ellipse (semi-axes a along e, c) by its angle. */
static void outline_point(const bsim_body_def *b, const double x[2], double psi, double t,
                          double q[2])
{
	const double e[2] = {cos(psi), sin(psi)}, n[2] = {-e[1], e[0]};
	double lx, ly;
	if (b->shape == BSIM_SHAPE_ELLIPSE) {
		const double phi = 2.0 * 3.14159265358979323846 * t;
		lx = b->semi_axes[0] * cos(phi);
		ly = b->semi_axes[1] * sin(phi);
	} else {
		const double l = b->length / 2, r = b->radius;
		const double side = 2.0 * l, arc = 3.14159265358979323846 * r,
		             total = 2.0 * (side + arc);
		double d = t * total;
		if (d < side) {
			lx = -l + d;
			ly = -r;
		} else if ((d -= side) < arc) {
			lx = l + r * sin(d / r);
			ly = -r * cos(d / r);
		} else if ((d -= arc) < side) {
			lx = l - d;
			ly = r;
		} else {
			d -= side;
			lx = -l - r * sin(d / r);
			ly = r * cos(d / r);
		}
	}
	q[0] = x[0] + lx * e[0] + ly * n[0];
	q[1] = x[1] + lx * e[1] + ly * n[1];
}

enum { OUTLINE = 1440, SEGMENT = 600 };

/* The smallest distance between the outline's and the segment's sampled
 * points (the segment from p along u, len long), m, and in near the vector
 * from the segment's nearest point to the outline's. */
static double sampled_gap(const bsim_body_def *b, const double x[2], double psi, const double p[2],
                          const double u[2], double len, double near[2])
{
	double gap = INFINITY;
	for (int i = 0; i < OUTLINE; i++) {
		double q[2];
		outline_point(b, x, psi, (double)i / OUTLINE, q);
		for (int j = 0; j <= SEGMENT; j++) {
			const double t = len * j / SEGMENT;
			const double d[2] = {q[0] - p[0] - t * u[0], q[1] - p[1] - t * u[1]};
			const double g = hypot(d[0], d[1]);
			if (g < gap) {
				gap = g;
				near[0] = d[0];
				near[1] = d[1];
			}
		}
	}
	return gap;
}

static void test_outline_rule(void **state)
{
	const bsim_backend *b = *state;
	if (b != bsim_backend_default())
		bsim_test_skip(b, "the rule is the library's, the same for every backend");
	bsim_body_def bodies[2] = {bsim_body_def_default(), bsim_body_def_default()};
	bodies[0].shape = BSIM_SHAPE_CAPSULE;
	bodies[0].radius = 1.0;
	bodies[0].length = 3.0;
	bodies[1].shape = BSIM_SHAPE_ELLIPSE;
	bodies[1].semi_axes[0] = 3.0;
	bodies[1].semi_axes[1] = 1.0;
	enum { PLACEMENTS = 100 };
	unsigned long long st = 12345;
	int checked = 0, touching = 0;
	for (int k = 0; k < 2; k++)
		for (int m = 0; m < PLACEMENTS; m++) {
			const double psi = 2.0 * 3.14159265358979323846 * unit_draw(&st);
			const double x[2] = {0.0, 0.0};
			double p[2] = {-6.0 + 12.0 * unit_draw(&st), -4.0 + 1.0 * unit_draw(&st)};
			const double a = 3.14159265358979323846 * (0.1 + 0.8 * unit_draw(&st)),
			             len = 8.0;
			const double u[2] = {cos(a), sin(a)};
			/* moved toward the body along the nearest points' line, which
			 * takes the gap down by the move: to 1-4 mm either side of the
			 * tolerance */
			double near[2] = {0.0, 0.0};
			double g0 = sampled_gap(&bodies[k], x, psi, p, u, len, near);
			if (g0 < 0.05)
				continue; /* an overlap, which sampling does not measure */
			const double side = unit_draw(&st) < 0.5 ? -1.0 : 1.0;
			const double target =
			        BSIM_CONTACT_TOL + side * (1e-3 + 3e-3 * unit_draw(&st));
			p[0] += (g0 - target) * near[0] / g0;
			p[1] += (g0 - target) * near[1] / g0;
			const double gap = sampled_gap(&bodies[k], x, psi, p, u, len, near);
			if (fabs(gap - BSIM_CONTACT_TOL) < 1e-3)
				continue; /* within sampling's error of the tolerance */
			const int flag = bsim_contact_flag_of(&bodies[k], x, psi, p, u, len, 0);
			if ((flag != BSIM_CONTACT_NONE) != (gap < BSIM_CONTACT_TOL))
				fail_msg("body %d placement %d: sampled gap %.6f m, flag %d", k, m,
				         gap, flag);
			assert_int_equal(bsim_contact_flag_of(&bodies[k], x, psi, p, u, len, 1) ==
			                         BSIM_CONTACT_NONE,
			                 0); /* pushed: in contact whatever the gap */
			checked++;
			touching += gap < BSIM_CONTACT_TOL;
		}
	assert_true(checked > PLACEMENTS && touching > PLACEMENTS / 4 &&
	            checked - touching > PLACEMENTS / 4); /* both sides, most placements */
	/* a segment through the centre line: in contact */
	for (int k = 0; k < 2; k++) {
		const double x[2] = {0.0, 0.0}, p[2] = {0.0, -5.0}, u[2] = {0.0, 1.0};
		assert_int_not_equal(bsim_contact_flag_of(&bodies[k], x, 0.3, p, u, 10.0, 0),
		                     BSIM_CONTACT_NONE);
	}
	print_message("%d placements checked, %d of them within the tolerance\n", checked,
	              touching);
}

typedef struct apart_watch {
	const bsim_scene *s;
	long states, nan, flagged;
} apart_watch;

static void apart_fn(void *user, long step, const bsim_state *st)
{
	apart_watch *a = user;
	const bsim_scene *s = a->s;
	a->states++;
	for (int k = 0; k < st->n_active; k++) {
		const int i = st->active[k];
		const bsim_beam_def *d = &s->beams[i];
		double u0[2], u[2];
		int type;
		bsim_scene_beam_rest_direction(d, u0);
		bsim_beam_direction(u0, bsim_scene_beam_forward_sign(d), st->theta[i], u);
		const double dist = bsim_beam_distance(d->pivot, u, d->length, st->x, &type);
		const int flag = st->touched[i] || dist - s->body.radius < BSIM_CONTACT_TOL
		                         ? type
		                         : BSIM_CONTACT_NONE;
		if (isnan(st->direction[2 * i])) {
			a->nan++;
			if (st->touched[i] || !(dist - s->body.radius >= BSIM_CONTACT_TOL))
				fail_msg(
				        "step %ld beam %d: NaN direction at gap %.9g m, touched %d",
				        step, i, dist - s->body.radius, st->touched[i]);
		} else if (flag != st->contact[i]) {
			fail_msg("step %ld beam %d: flag %d, %d from its angle", step, i,
			         st->contact[i], flag);
		}
		a->flagged += st->contact[i] != BSIM_CONTACT_NONE;
	}
}

static void test_reported_facts(void **state)
{
	const bsim_backend *b = *state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 6.0, 20.0);
	apart_watch a = {.s = &s};
	bsim_recorder rec = {.stride = 1, .trace = apart_fn, .trace_user = &a};
	bsim_trial_runner *r = bsim_trial_runner_alloc();
	assert_non_null(r);
	for (int t = 0; t < 4; t++) {
		bsim_trial_result out;
		bsim_error err;
		assert_int_equal(bsim_trial_run(r, &s, b, NULL, 11 + t, &rec, &out, &err), BSIM_OK);
	}
	bsim_trial_runner_free(r);
	print_message("%s: %ld states, %ld flagged beam-states, %ld reported apart (NaN)\n",
	              b->name, a.states, a.flagged, a.nan);
	assert_true(a.flagged > 0);
	bsim_scene_free(&s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_head_on_impact), cmocka_unit_test(test_grazing_pass),
	        cmocka_unit_test(test_backends_agree), cmocka_unit_test(test_outline_rule),
	        cmocka_unit_test(test_reported_facts),
	};
	return bsim_test_run_per_backend("contact_flag", tests, sizeof tests / sizeof tests[0]);
}
