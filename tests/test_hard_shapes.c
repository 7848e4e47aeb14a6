/* Hard cases of the turning, shaped, frictional body (configs/hard/), each
 * run on every backend of the registry through the trial runner with
 * explicit criteria, the same for every backend;
 * every measured value is printed.
 *   8  a capsule wedged between both beams (capsule_wedge.yaml)
 *   9  friction at a high normal force: stick inside the cone, slide
 *      outside it (friction_press.yaml)
 *   10 a spinning capsule at a beam's tip (spin_tip.yaml)
 * The gap is the true outline's (beamsim/body_shape.h), not the disk's. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "beamsim/trial.h"
#include "beamsim/body_shape.h"
#include "support.h"

static void load(const char *rel, const bsim_override *ov, int n, bsim_scene *s)
{
	bsim_error err;
	int rc = bsim_scene_load(bsim_test_src(rel), ov, n, s, &err);
	if (rc)
		print_message("%s\n", err.msg);
	assert_int_equal(rc, BSIM_OK);
}

/* What a trial's steps showed. */
typedef struct {
	const bsim_scene *s;
	double pen_max; /* m, the deepest overlap of the outline with a beam */
	int tunnels;    /* steps in which the body's centre crossed a beam's line within its span */
	int nonfinite;  /* steps with a non-finite value */
	double side[4]; /* the centre's side of each beam, 0: unknown */
	double x_min[2]; /* m, the centre's extent */
	double x_max[2];
	long steps;
	double late[2]; /* m, the centre's smallest and largest x after the first second */
} watch;

static void watch_fn(void *user, long step, const bsim_state *st)
{
	watch *wt = user;
	wt->steps = step;
	int fin = isfinite(st->x[0]) && isfinite(st->x[1]) && isfinite(st->v[0]) &&
	          isfinite(st->v[1]) && isfinite(st->heading) && isfinite(st->angular_velocity);
	if (!fin) {
		wt->nonfinite++;
		return;
	}
	for (int k = 0; k < 2; k++) {
		wt->x_min[k] = fmin(wt->x_min[k], st->x[k]);
		wt->x_max[k] = fmax(wt->x_max[k], st->x[k]);
	}
	if (step * wt->s->dt > 1.0) {
		wt->late[0] = fmin(wt->late[0], st->x[0]);
		wt->late[1] = fmax(wt->late[1], st->x[0]);
	}
	for (int i = 0; i < wt->s->n_beams && i < 4; i++) {
		const bsim_beam_def *d = &wt->s->beams[i];
		double u0[2], sg = bsim_scene_beam_forward_sign(d);
		bsim_scene_beam_rest_direction(d, u0);
		double c = cos(st->theta[i]), sn = sg * sin(st->theta[i]);
		double u[2] = {u0[0] * c - u0[1] * sn, u0[1] * c + u0[0] * sn};
		double p1[2] = {d->pivot[0] + d->length * u[0], d->pivot[1] + d->length * u[1]};
		bsim_body_segment_contact bc;
		if (bsim_body_shape_segment(&wt->s->body, st->x, st->heading, d->pivot, p1, &bc) ==
		    BSIM_OK)
			wt->pen_max = fmax(wt->pen_max, -bc.dist);
		double dx = st->x[0] - d->pivot[0], dy = st->x[1] - d->pivot[1];
		double along = dx * u[0] + dy * u[1],
		       side = u[0] * dy - u[1] * dx >= 0 ? 1.0 : -1.0;
		int inside = along > 0.0 && along < d->length;
		if (inside && wt->side[i] != 0.0 && side != wt->side[i])
			wt->tunnels++;
		wt->side[i] = inside ? side : 0.0;
	}
}

/* Why the last run's backend refused its scene. */
static char refusal[sizeof((bsim_error *)0)->msg];

/* Runs trial 1 of s on b: 1, or 0 if b refuses the scene (a backend that
 * does not simulate a turning or shaped body: its own message, naming it,
 * in refusal), for the caller to free the scene and skip. */
static int run(const bsim_backend *b, const bsim_scene *s, watch *wt, bsim_trial_result *res)
{
	memset(wt, 0, sizeof *wt);
	wt->s = s;
	wt->pen_max = -INFINITY;
	wt->x_min[0] = wt->x_min[1] = INFINITY;
	wt->x_max[0] = wt->x_max[1] = -INFINITY;
	wt->late[0] = INFINITY;
	wt->late[1] = -INFINITY;
	bsim_recorder rec = {.stride = 1, .trace = watch_fn, .trace_user = wt};
	bsim_trial_runner *r = bsim_trial_runner_alloc();
	assert_non_null(r);
	bsim_error err;
	int rc = bsim_trial_run(r, s, b, NULL, 1, &rec, res, &err);
	bsim_trial_runner_free(r);
	if (rc == BSIM_EINPUT && strncmp(err.msg, b->name, strlen(b->name)) == 0) {
		snprintf(refusal, sizeof refusal, "%s", err.msg);
		return 0;
	}
	if (rc)
		print_message("%s: %s\n", b->name, err.msg);
	assert_int_equal(rc, BSIM_OK);
	assert_int_equal(wt->nonfinite, 0);
	assert_int_not_equal(res->outcome, BSIM_UNSTABLE);
	return 1;
}

/* Frees s and skips the test of b, which refused it. */
static void refused(const bsim_backend *b, bsim_scene *s)
{
	bsim_scene_free(s);
	bsim_test_skip(b, "it refuses the scene: %s", refusal);
}

/* The ledger's residual against what flowed: the energy the trial started
 * with and every force's work, in and out. */
static double ledger_relative(const bsim_ledger *l)
{
	double flow = l->inflow + fabs(l->damper) + fabs(l->impact) + fabs(l->contact) +
	              fabs(l->correction) + fabs(l->drag) + fabs(l->friction);
	return fabs(l->residual) / flow;
}

/* ---- 8. a capsule wedged between both beams ------------------------------ */

static void test_capsule_wedge(void **state)
{
	const bsim_backend *b = *state;
	const char *bname = b->name;
	bsim_scene s;
	load("configs/hard/capsule_wedge.yaml", NULL, 0, &s);
	watch wt;
	bsim_trial_result res;
	if (!run(b, &s, &wt, &res))
		refused(b, &s);
	double rel = ledger_relative(&res.ledger);
	print_message("capsule wedge %s: %s, end (%.4f, %.4f) vx %.2e, in contact %d, deepest "
	              "overlap %.2e m, tunnels %d, ledger residual %.2e of the flow\n",
	              bname, bsim_trial_outcome_name(res.outcome), res.x_end, res.y_end, res.vx_end,
	              res.in_contact_end, wt.pen_max, wt.tunnels, rel);
	/* jammed: held at rest in the V, touching, never through a beam */
	assert_int_equal(res.outcome, BSIM_STUCK);
	assert_true(res.in_contact_end);
	assert_true(fabs(res.vx_end) < 0.05);
	assert_true(res.y_end < 21.65); /* the tips' row: it never got through */
	assert_int_equal(wt.tunnels, 0);
	assert_true(wt.pen_max < 0.1); /* 1% of the half-width */
	assert_true(rel < 0.05);
	bsim_scene_free(&s);
}

/* ---- 9. friction at a high normal force ---------------------------------- */

static void test_friction_press(void **state)
{
	const bsim_backend *b = *state;
	const char *bname = b->name;
	/* 40 N inside the cone mu N = 50 N: sticks; 70 N outside: slides. */
	const char *amp[2] = {"40", "70"};
	double moved[2];
	for (int k = 0; k < 2; k++) {
		bsim_override ov[] = {{"effects.oscillation.amplitude", amp[k], "test"}};
		bsim_scene s;
		load("configs/hard/friction_press.yaml", ov, 1, &s);
		watch wt;
		bsim_trial_result res;
		if (!run(b, &s, &wt, &res))
			refused(b, &s);
		moved[k] = wt.x_max[0] - wt.x_min[0];
		double creep = wt.late[1] - wt.late[0];
		print_message(
		        "friction press %s, push %s N: x range %.3e m, after the first second "
		        "%.3e m, deepest overlap %.2e m, ledger residual %.2e of the flow\n",
		        bname, amp[k], moved[k], creep, wt.pen_max, ledger_relative(&res.ledger));
		assert_int_equal(wt.tunnels, 0);
		assert_true(res.in_contact_end);
		if (k == 0)
			assert_true(creep < 1e-3); /* settled, it neither creeps nor chatters */
		bsim_scene_free(&s);
	}
	assert_true(moved[0] < 0.05);
	assert_true(moved[1] > 0.5);
}

/* ---- 10. a spinning capsule at a beam's tip ------------------------------ */

static void test_spin_tip(void **state)
{
	const bsim_backend *b = *state;
	const char *bname = b->name;
	bsim_scene s;
	load("configs/hard/spin_tip.yaml", NULL, 0, &s);
	watch wt;
	bsim_trial_result res;
	if (!run(b, &s, &wt, &res))
		refused(b, &s);
	double rel = ledger_relative(&res.ledger);
	print_message("spin tip %s: %s after %.3f s, deepest overlap %.2e m, tunnels %d, ledger "
	              "residual %.2e of the flow, impact loss %.3f J\n",
	              bname, bsim_trial_outcome_name(res.outcome), res.t_end, wt.pen_max,
	              wt.tunnels, rel, res.ledger.impact);
	assert_int_equal(wt.tunnels, 0);
	assert_true(wt.pen_max < 0.1);
	/* impacts take energy, never give it, but by the round-off of an
	 * elastic impulse's (the bound "ledger.elastic", of what flowed) */
	double elastic = 0.0;
	bsim_backend_bound_of(b, "ledger.elastic", &elastic);
	assert_true(res.ledger.impact >= -1e-9 - elastic * res.ledger.inflow);
	assert_true(rel < 0.05);
	bsim_scene_free(&s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_capsule_wedge),
	        cmocka_unit_test(test_friction_press),
	        cmocka_unit_test(test_spin_tip),
	};
	return bsim_test_run_per_backend("hard_shapes", tests, sizeof tests / sizeof tests[0]);
}
