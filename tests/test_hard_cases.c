/* Numerically hard cases (the scenes in configs/hard/), each run on every
 * backend of the registry with explicit pass criteria; every measured value
 * is printed.
 *   1 Zeno settling against sprung beams, e = 0.9 and 0.5
 *   2 simultaneous double impact on the midline, and offset by +-1e-6 m
 *   3 mass-ratio extremes (1000:1, 1:1000) x omega_n h from 0.05 to 4
 *   4 a wedged body, pushed slowly, and from a 1 cm initial overlap
 *   5 impact phase (16 phases in a step), approach speed, tip grazing
 *   6 violent noise (Rm = 1000 N): no tunnelling, no NaN
 *   7 a long conservative run (100,000 steps): energy drift
 * Where a backend misses a criterion by its design, it states the bound it
 * meets (bsim_backend.bounds, "hard.*": its file says why, e.g. Box2D's
 * float32 and its 5 mm skin), a little above what was measured. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "beamsim/contact_flag.h"
#include "beamsim/schedule.h"
#include "beamsim/trial.h"
#include "support.h"

static void load(const char *rel, bsim_scene *s)
{
	bsim_error err;
	int rc = bsim_scene_load(bsim_test_src(rel), NULL, 0, s, &err);
	if (rc)
		print_message("%s\n", err.msg);
	assert_int_equal(rc, BSIM_OK);
}

static bsim_world *create(const bsim_backend *b, const bsim_scene *s)
{
	bsim_world *w = NULL;
	bsim_error err;
	int rc = b->create(s, NULL, &w, &err);
	if (rc)
		print_message("create: %s\n", err.msg);
	assert_int_equal(rc, BSIM_OK);
	return w;
}

/* Beam i's direction at angle theta (theta > 0 swings the tip to +y). */
static void beam_dir(const bsim_beam_def *d, double theta, double u[2])
{
	double a = d->rest_angle_deg * 0.017453292519943295;
	double u0x = cos(a), u0y = sin(a), sg = u0x >= -1e-12 ? 1.0 : -1.0;
	double cs = cos(theta), sn = sg * sin(theta);
	u[0] = u0x * cs - u0y * sn;
	u[1] = u0y * cs + u0x * sn;
}

/* Distance from the body centre to beam i's segment; *s_out the projection
 * along it, *side the sign of u x (C - P). */
static double beam_distance(const bsim_beam_def *d, double theta, const double c[2], double *s_out,
                            double *side)
{
	double u[2];
	beam_dir(d, theta, u);
	double dx = c[0] - d->pivot[0], dy = c[1] - d->pivot[1];
	double s = dx * u[0] + dy * u[1];
	if (s_out)
		*s_out = s;
	if (side)
		*side = u[0] * dy - u[1] * dx >= 0.0 ? 1.0 : -1.0;
	double sc = fmin(fmax(s, 0.0), d->length);
	return hypot(dx - sc * u[0], dy - sc * u[1]);
}

/* The smallest gap (distance - R) over all beams. */
static double min_gap(const bsim_scene *sc, const bsim_state *st)
{
	double g = INFINITY;
	for (int i = 0; i < sc->n_beams; i++)
		g = fmin(g, beam_distance(&sc->beams[i], st->theta[i], st->x, NULL, NULL) -
		                    sc->body.radius);
	return g;
}

static double energy_of(const bsim_scene *sc, const bsim_state *st)
{
	double e = 0.5 * sc->body.mass * (st->v[0] * st->v[0] + st->v[1] * st->v[1]);
	for (int i = 0; i < sc->n_beams; i++)
		e += 0.5 * sc->beams[i].inertia * st->omega[i] * st->omega[i] +
		     0.5 * sc->beams[i].stiffness * st->theta[i] * st->theta[i];
	return e;
}

/* ---- 1. Zeno settling ---------------------------------------------------- */

static void zeno_one(const bsim_backend *b, double e)
{
	const char *bname = b->name;
	double apex_bound = bsim_test_bound(b, "hard.apex");
	bsim_scene s;
	load("configs/hard/zeno_settle.yaml", &s);
	s.contact.restitution = s.contact.tip_restitution = e;
	bsim_world *w = create(b, &s);
	bsim_state st;
	bsim_state_init(&st, 2);
	const double force[2] = {0.0, s.effects.propulsion_force};
	const int steps = 5000;
	/* apex: the largest gap between two touches; the total energy at an apex
	 * (E + F (y0 - y)) never rises either */
	double g_prev = 0.0, g_prev2 = 0.0, apex[64], apex_rise = 0.0;
	int n_apex = 0, impacts = 0, max_per_step = 0, last_impact = 0, persistent_from = 0;
	for (int n = 1; n <= steps; n++) {
		assert_int_equal(bsim_backend_step(b, w, force, 0.0, s.dt, NULL), BSIM_OK);
		b->get_state(w, &st);
		bsim_contact_flags(&s, &st);
		double g = min_gap(&s, &st);
		if (n >= 3 && g_prev > 1e-3 && g_prev > g_prev2 && g_prev >= g && n_apex < 64) {
			if (n_apex > 0)
				apex_rise = fmax(apex_rise, g_prev - apex[n_apex - 1]);
			apex[n_apex++] = g_prev;
		}
		g_prev2 = g_prev;
		g_prev = g;
		impacts += st.impacts;
		if (st.impacts) {
			last_impact = n;
			max_per_step = st.impacts > max_per_step ? st.impacts : max_per_step;
		}
		int touching =
		        st.contact[0] != BSIM_CONTACT_NONE && st.contact[1] != BSIM_CONTACT_NONE;
		if (!touching)
			persistent_from = 0;
		else if (!persistent_from)
			persistent_from = n;
	}
	double speed = hypot(st.v[0], st.v[1]);
	print_message("zeno %s e=%.1f: %d impacts (max %d in a step), last at step %d; %d apexes "
	              "(first %.3e m, last %.3e m), largest apex rise %.2e m; persistent from "
	              "step %d; end speed %.2e m/s, x %.2e m\n",
	              bname, e, impacts, max_per_step, last_impact, n_apex, n_apex ? apex[0] : 0.0,
	              n_apex ? apex[n_apex - 1] : 0.0, apex_rise, persistent_from, speed, st.x[0]);
	assert_true(impacts >= 2);
	assert_true(max_per_step <= 2); /* at most one per contact */
	/* apexes never rise (but by round-off of the positions: float32's ulp is
	 * 2e-6 m at 20 m) */
	assert_true(apex_rise <= apex_bound);
	/* clean hand-off: the contacts hold from (at the latest) the step after
	 * the last impact to the end, and the chain ends early */
	assert_true(persistent_from > 0 && persistent_from <= last_impact + 1);
	assert_true(last_impact < steps / 4);
	/* the coupled body-beam mode about the rest point is lightly damped
	 * (tests/test_persistent_contact.h: zeta ~ 0.08) and still rings */
	assert_true(speed < 0.2);
	/* on the midline, to the round-off of positions (Box2D's float32
	 * breaks the tie a little, by which beam it solves first) */
	assert_true(fabs(st.x[0]) <= apex_bound);
	bsim_state_free(&st);
	b->destroy(w);
	bsim_scene_free(&s);
}

static void test_zeno_settling(void **state)
{
	zeno_one(*state, 0.9);
	zeno_one(*state, 0.5);
}

/* ---- 2. simultaneous double impact --------------------------------------- */

typedef struct {
	double vx_max, vx_end, x_end, y_end;
} double_run;

static double_run double_one(const bsim_backend *b, double dx)
{
	bsim_scene s;
	load("configs/hard/double_impact.yaml", &s);
	s.body.start[0] += dx;
	bsim_world *w = create(b, &s);
	bsim_state st;
	bsim_state_init(&st, 2);
	const double zero[2] = {0.0, 0.0};
	double_run r = {0, 0, 0, 0};
	for (int n = 0; n < s.max_steps; n++) {
		assert_int_equal(bsim_backend_step(b, w, zero, 0.0, s.dt, NULL), BSIM_OK);
		b->get_state(w, &st);
		r.vx_max = fmax(r.vx_max, fabs(st.v[0]));
	}
	r.vx_end = st.v[0];
	r.x_end = st.x[0];
	r.y_end = st.x[1];
	bsim_state_free(&st);
	b->destroy(w);
	bsim_scene_free(&s);
	return r;
}

static void test_double_impact(void **state)
{
	const double d = 1e-6;
	const bsim_backend *b = *state;
	double centred = bsim_test_bound(b, "hard.centred");
	{
		double_run m = double_one(b, -d), z = double_one(b, 0.0), p = double_one(b, d);
		double asym = fabs((p.vx_end - z.vx_end) + (m.vx_end - z.vx_end));
		double gain = fmax(fabs(p.vx_end - z.vx_end), fabs(m.vx_end - z.vx_end)) / d;
		print_message(
		        "double impact %s: centred max|vx| %.2e m/s, x_end %.2e; offset +-1e-6: "
		        "vx_end %.3e / %.3e m/s (gain %.3g 1/s, antisymmetry defect %.2e), "
		        "x_end %.3e / %.3e, y_end spread %.2e m\n",
		        b->name, z.vx_max, z.x_end, p.vx_end, m.vx_end, gain, asym, p.x_end,
		        m.x_end, fmax(fabs(p.y_end - z.y_end), fabs(m.y_end - z.y_end)));
		/* centred: lateral velocity at round-off */
		assert_true(z.vx_max <= centred);
		/* smooth: the outcome is linear in the offset (antisymmetric) and a
		 * 1e-6 m offset moves it by O(1e-4): the centred motion is an
		 * unstable balance (the tips splay apart), gain ~ 86 1/s by the
		 * model, not a jump */
		assert_true(gain <= 200.0);
		assert_true(asym <= 0.05 * gain * d + 1e-12);
		assert_true(fabs(p.x_end - z.x_end) <= 1e-3 && fabs(m.x_end - z.x_end) <= 1e-3);
		assert_true(fabs(p.y_end - z.y_end) <= 1e-2 && fabs(m.y_end - z.y_end) <= 1e-2);
	}
}

/* ---- trial-runner helpers (cases 3, 6, 7) --------------------------------- */

typedef struct {
	const bsim_backend *b;
	const bsim_scene *s;
	double pen_max;   /* max (R - distance), m */
	int tunnels;      /* side flips while inside the beam's span */
	int nonfinite;    /* steps with a non-finite value */
	double side[8];   /* last side per beam (0: unknown) */
	double e_max;     /* max energy seen, J */
	double pivot_max; /* max distance of a pinned point from its pivot, m */
} watch;

static void watch_fn(void *user, long step, const bsim_state *st)
{
	watch *wt = user;
	(void)step;
	int fin = isfinite(st->x[0]) && isfinite(st->x[1]) && isfinite(st->v[0]) &&
	          isfinite(st->v[1]);
	for (int i = 0; i < st->n_beams; i++)
		fin = fin && isfinite(st->theta[i]) && isfinite(st->omega[i]);
	if (!fin) {
		wt->nonfinite++;
		return;
	}
	wt->e_max = fmax(wt->e_max, energy_of(wt->s, st));
	wt->pivot_max = fmax(wt->pivot_max, bsim_backend_pivot_drift(wt->b, wt->s, st));
	for (int i = 0; i < st->n_beams && i < 8; i++) {
		const bsim_beam_def *d = &wt->s->beams[i];
		double s, side;
		double dist = beam_distance(d, st->theta[i], st->x, &s, &side);
		wt->pen_max = fmax(wt->pen_max, wt->s->body.radius - dist);
		int inside = s > 0.0 && s < d->length && dist < wt->s->body.radius + 5.0;
		if (inside && wt->side[i] != 0.0 && side != wt->side[i])
			wt->tunnels++;
		wt->side[i] = inside ? side : 0.0;
	}
}

static int run_trial(const bsim_backend *b, const bsim_scene *s, uint64_t seed, watch *wt,
                     bsim_trial_result *res)
{
	memset(wt, 0, sizeof *wt);
	wt->b = b;
	wt->s = s;
	wt->pen_max = -INFINITY;
	bsim_recorder rec = {.stride = 1, .trace = watch_fn, .trace_user = wt};
	bsim_trial_runner *r = bsim_trial_runner_alloc();
	assert_non_null(r);
	bsim_error err;
	int rc = bsim_trial_run(r, s, b, NULL, seed, &rec, res, &err);
	if (rc)
		print_message("trial: %s\n", err.msg);
	bsim_trial_runner_free(r);
	return rc;
}

/* ---- 3. mass-ratio extremes ---------------------------------------------- */

static void test_mass_ratio(void **state)
{
	const double beam_mass[2] = {0.001, 1000.0}; /* body 1 kg: 1000:1 and 1:1000 */
	const double wnh[4] = {0.05, 0.5, 1.5, 4.0};
	const bsim_backend *b = *state;
	double pen_bound = bsim_test_bound(b, "hard.penetration");
	double pivot_bound = bsim_test_bound(b, "hard.pivot");
	/* energy: a backend whose solver may add energy by design (one that
	 * pushes overlaps out by moving positions) states no bound, and the
	 * check is skipped for it, saying so */
	double energy_bound;
	int energy = bsim_backend_bound_of(b, "hard.energy", &energy_bound);
	if (!energy)
		print_message("%s: energy not checked: it states no bound hard.energy\n", b->name);
	int ran = 0;
	{
		for (int m = 0; m < 2; m++) {
			for (int j = 0; j < 4; j++) {
				bsim_scene s;
				load("configs/hard/mass_ratio.yaml", &s);
				for (int i = 0; i < 2; i++) {
					bsim_beam_def *d = &s.beams[i];
					d->mass = beam_mass[m];
					d->inertia = d->mass * d->length * d->length / 3.0;
					double wn = wnh[j] / s.dt;
					d->stiffness = d->inertia * wn * wn;
					d->damping = 0.1 * 2.0 * d->inertia * wn; /* zeta = 0.1 */
				}
				/* a scene beyond the backend's own limits (its check,
				 * which create applies) is not run on it, saying why */
				bsim_error err;
				char field[64];
				if (b->check &&
				    b->check(&s, NULL, field, sizeof field, &err) != BSIM_OK) {
					print_message(
					        "mass ratio %s 1:%g wn*h %.2f: refused (%s: %s)\n",
					        b->name, beam_mass[m], wnh[j], field, err.msg);
					bsim_scene_free(&s);
					continue;
				}
				ran++;
				watch wt;
				bsim_trial_result res;
				int rc = run_trial(b, &s, bsim_schedule_seed_mix(1, 0, 0), &wt,
				                   &res);
				const bsim_ledger *l = &res.ledger;
				double input = l->w_prop + l->w_rand;
				double excess = l->e_end - (l->e_start + input);
				double scale = fabs(l->w_prop) + fabs(l->w_rand) + l->e_start;
				print_message(
				        "mass ratio %s 1:%g wn*h %.2f: rc %d, %s after %d "
				        "steps, max "
				        "|theta| %.3g, penetration %.3e m, pivot drift %.3e m, "
				        "E_end - (E_0 + W) = %.3e J (W throughput %.3g J, "
				        "correction %.3g J)\n",
				        b->name, beam_mass[m], wnh[j], rc,
				        bsim_trial_outcome_name(res.outcome), res.steps,
				        fmax(fabs(res.max_theta[0]), fabs(res.max_theta[1])),
				        wt.pen_max, wt.pivot_max, excess, scale, l->correction);
				assert_int_equal(rc, BSIM_OK);
				assert_int_equal(wt.nonfinite, 0);
				assert_int_equal(wt.tunnels, 0);
				/* penetration: how deep a body may sink (a solver that
				 * projects to a slop, or rests contacts at a skin and lets
				 * a hard impact sink in within a step) */
				assert_true(wt.pen_max <= pen_bound);
				/* the pin: exact, or a joint whose rows converge
				 * iteratively and let a pivot be pushed off it */
				assert_true(wt.pivot_max <= pivot_bound);
				/* energy never rises above what the forces put in */
				if (energy)
					assert_true(excess <= energy_bound * scale + 1e-9);
				bsim_scene_free(&s);
			}
		}
	}
	assert_true(ran >= 4); /* the check covers both mass ratios */
}

/* ---- 4. a wedged body ---------------------------------------------------- */

static void wedge_one(const bsim_backend *b, double overlap)
{
	const char *bname = b->name;
	bsim_scene s;
	load("configs/hard/wedge.yaml", &s);
	bsim_world *w = create(b, &s);
	bsim_state st;
	bsim_state_init(&st, 2);
	if (overlap > 0.0) {
		/* both beams touch a centred body at y0 = 2 (20 sin 60 - R):
		 * distance 20 sin 60 - y/2; y0 + 2 overlap sinks it by overlap */
		b->get_state(w, &st);
		bsim_contact_flags(&s, &st);
		st.x[1] = 2.0 * (20.0 * sin(60.0 * 0.017453292519943295) - s.body.radius) +
		          2.0 * overlap;
		st.v[1] = 0.0;
		bsim_error err;
		assert_int_equal(b->set_state(w, &st, &err), BSIM_OK);
	}
	const double force[2] = {0.0, s.effects.propulsion_force};
	double vmax = 0.0, y_half = 0.0, x_half = 0.0, pen_end = 0.0;
	int n = 0;
	for (n = 1; n <= s.max_steps; n++) {
		assert_int_equal(bsim_backend_step(b, w, force, 0.0, s.dt, NULL), BSIM_OK);
		b->get_state(w, &st);
		bsim_contact_flags(&s, &st);
		vmax = fmax(vmax, hypot(st.v[0], st.v[1]));
		if (n == s.max_steps / 2) {
			x_half = st.x[0];
			y_half = st.x[1];
		}
	}
	pen_end = -min_gap(&s, &st);
	double drift = hypot(st.x[0] - x_half, st.x[1] - y_half), speed = hypot(st.v[0], st.v[1]);
	print_message("wedge %s overlap %.0e m: max speed %.3e m/s, resting drift over the last %g "
	              "s %.2e m, end speed %.2e m/s, end (%.2e, %.6f), penetration %.2e m, "
	              "contacts %d %d\n",
	              bname, overlap, vmax, s.max_steps / 2 * s.dt, drift, speed, st.x[0], st.x[1],
	              pen_end, st.contact[0], st.contact[1]);
	assert_true(drift < 0.01);
	assert_true(speed < 0.05);
	assert_true(vmax < 0.5); /* no popping apart */
	assert_true(st.contact[0] != BSIM_CONTACT_NONE && st.contact[1] != BSIM_CONTACT_NONE);
	assert_true(pen_end < 0.01);
	bsim_state_free(&st);
	b->destroy(w);
	bsim_scene_free(&s);
}

static void test_wedge(void **state)
{
	wedge_one(*state, 0.0);
	wedge_one(*state, 0.01);
}

/* ---- 5. impact phase, approach speed, grazing ----------------------------- */

/* Body of speed u square-on into the free beam at lever 15 m, the contact
 * reached at phase (in steps) after the start; returns the effective
 * restitution (omega r - v_y) / u after the impact. */
static double phase_one(const bsim_backend *b, double u, double phase, int *impacts)
{
	bsim_scene s;
	load("configs/hard/impact_phase.yaml", &s);
	const double r = s.body.start[0];
	s.body.velocity[1] = u;
	s.body.start[1] = -s.body.radius - u * s.dt * phase;
	bsim_world *w = create(b, &s);
	bsim_state st;
	bsim_state_init(&st, 1);
	const double zero[2] = {0.0, 0.0};
	*impacts = 0;
	int steps = (int)phase + 20;
	for (int n = 0; n < steps; n++) {
		assert_int_equal(bsim_backend_step(b, w, zero, 0.0, s.dt, NULL), BSIM_OK);
		b->get_state(w, &st);
		*impacts += st.impacts;
	}
	double e = (st.omega[0] * r - st.v[1]) / u;
	bsim_state_free(&st);
	b->destroy(w);
	bsim_scene_free(&s);
	return e;
}

/* Grazing: the body passes the tip (25, 0) with its centre at x = 25 +
 * R (1 - eps); returns the relative change of energy and of the angular
 * momentum about the pivot, and whether only tip contacts were seen. */
static void graze_one(const bsim_backend *b, double eps)
{
	const char *bname = b->name;
	double e_bound = bsim_test_bound(b, "hard.graze.energy");
	double l_bound = bsim_test_bound(b, "hard.graze.momentum");
	double pen_bound = bsim_test_bound(b, "hard.graze.penetration");
	bsim_scene s;
	load("configs/hard/impact_phase.yaml", &s);
	const double u = 4.0;
	s.body.start[0] = 25.0 + s.body.radius * (1.0 - eps);
	s.body.start[1] = -5.0; /* clear of the tip: 10 m from it at eps <= 0.05 */
	s.body.velocity[1] = u;
	bsim_world *w = create(b, &s);
	bsim_state st;
	bsim_state_init(&st, 1);
	b->get_state(w, &st);
	bsim_contact_flags(&s, &st);
	double e0 = energy_of(&s, &st);
	double l0 = s.body.mass * (st.x[0] * st.v[1] - st.x[1] * st.v[0]) +
	            s.beams[0].inertia * st.omega[0];
	const double zero[2] = {0.0, 0.0};
	int tangent = 0, tip = 0, impacts = 0;
	double pen = -INFINITY;
	for (int n = 0; n < 400; n++) {
		assert_int_equal(bsim_backend_step(b, w, zero, 0.0, s.dt, NULL), BSIM_OK);
		b->get_state(w, &st);
		bsim_contact_flags(&s, &st);
		tangent |= st.contact[0] == BSIM_CONTACT_TANGENT;
		tip |= st.contact[0] == BSIM_CONTACT_TIP;
		impacts += st.impacts;
		pen = fmax(pen, -min_gap(&s, &st));
	}
	double de = (energy_of(&s, &st) - e0) / e0;
	double l1 = s.body.mass * (st.x[0] * st.v[1] - st.x[1] * st.v[0]) +
	            s.beams[0].inertia * st.omega[0];
	double dl = (l1 - l0) / fabs(l0);
	print_message("graze %s eps %.0e: %d impacts, tip %d tangent %d, omega %.4e, vx %.4e, "
	              "dE/E %.2e, dL/L %.2e, penetration %.2e m\n",
	              bname, eps, impacts, tip, tangent, st.omega[0], st.v[0], de, dl, pen);
	/* a tip hit, never tangent (the thesis backend resolves it at the start
	 * of the step, before the gap closes, so the flag may stay NONE) */
	assert_true(impacts >= 1 && !tangent);
	(void)tip;
	assert_true(st.omega[0] > 0.0 && st.v[0] > 0.0); /* pushed the tip forward, deflected */
	/* elastic tip impact: energy and angular momentum about the pivot kept,
	 * to the backend's bounds */
	assert_true(fabs(de) <= e_bound);
	assert_true(fabs(dl) <= l_bound);
	assert_true(pen <= pen_bound);
	bsim_state_free(&st);
	b->destroy(w);
	bsim_scene_free(&s);
}

static void test_impact_phase(void **state)
{
	const double e = 0.8, thr = 0.05;
	const bsim_backend *b = *state;
	{
		double lo = INFINITY, hi = -INFINITY, worst = 0.0;
		for (int p = 0; p < 16; p++) {
			int imp;
			double ee = phase_one(b, 2.0, 5.0 + p / 16.0, &imp);
			lo = fmin(lo, ee);
			hi = fmax(hi, ee);
			worst = fmax(worst, fabs(ee - e));
		}
		print_message("phase %s: 16 phases, e_eff in [%.5f, %.5f], max |e_eff - e| %.2e, "
		              "spread %.2e\n",
		              b->name, lo, hi, worst, hi - lo);
		assert_true(worst <= 0.02);
		assert_true(hi - lo <= 0.05);

		const double mult[4] = {0.5, 1.5, 2.0, 4.0};
		for (int j = 0; j < 4; j++) {
			int imp;
			double u = mult[j] * thr, expect = mult[j] < 1.0 ? 0.0 : e;
			double ee = phase_one(b, u, 5.5, &imp);
			print_message("speed %s: u = %.2f x threshold: e_eff %.5f (model %.1f), %d "
			              "impacts\n",
			              b->name, mult[j], ee, expect, imp);
			assert_true(fabs(ee - expect) <= 0.02);
		}
		for (int j = 0; j < 3; j++)
			graze_one(b, j == 0 ? 0.05 : j == 1 ? 0.01 : 0.002);
	}
}

/* ---- 6. violent noise ---------------------------------------------------- */

static void test_violent_noise(void **state)
{
	bsim_scene s;
	const bsim_backend *b = *state;
	double pen_bound = bsim_test_bound(b, "hard.noise.penetration");
	load("configs/hard/violent_noise.yaml", &s);
	{
		int tunnels = 0, nonfinite = 0, failed = 0, hit = 0;
		double pen = -INFINITY, vmax = 0.0;
		for (int t = 0; t < 40; t++) {
			watch wt;
			bsim_trial_result res;
			failed += run_trial(b, &s, bsim_schedule_seed_mix(6, 0, (uint64_t)t), &wt,
			                    &res) != 0;
			tunnels += wt.tunnels;
			nonfinite += wt.nonfinite;
			pen = fmax(pen, wt.pen_max);
			hit += res.max_theta[0] != 0.0 || res.max_theta[1] != 0.0;
			vmax = fmax(vmax, fabs(res.vx_end));
		}
		print_message(
		        "violent noise %s: 40 trials, %d touched a beam, %d failed, %d "
		        "non-finite steps, %d tunnellings, max penetration %.3e m, max |vx_end| "
		        "%.1f m/s\n",
		        b->name, hit, failed, nonfinite, tunnels, pen, vmax);
		assert_true(hit >= 10);
		assert_int_equal(failed, 0);
		assert_int_equal(nonfinite, 0);
		assert_int_equal(tunnels, 0);
		assert_true(pen <= pen_bound);
	}
	bsim_scene_free(&s);
}

/* ---- 7. long conservative run --------------------------------------------- */

static void test_conservative_long(void **state)
{
	bsim_scene s;
	const bsim_backend *b = *state;
	double drift_bound = bsim_test_bound(b, "hard.conservative.drift");
	double tunnel_bound;
	int caged = bsim_backend_bound_of(b, "hard.conservative.tunnels", &tunnel_bound);
	load("configs/hard/conservative_long.yaml", &s);
	{
		watch wt;
		bsim_trial_result res;
		int rc = run_trial(b, &s, 1, &wt, &res);
		const bsim_ledger *l = &res.ledger;
		double drift = (l->e_end - l->e_start) / l->e_start;
		double rise = (wt.e_max - l->e_start) / l->e_start;
		print_message("conservative %s: %d steps, %s, end (%.3g, %.3g), energy drift %.3e "
		              "(max rise %.2e), ledger impact %.3e contact %.3e correction %.3e "
		              "residual %.3e J, penetration %.2e m, tunnels %d\n",
		              b->name, res.steps_run, bsim_trial_outcome_name(res.outcome),
		              res.x_end, res.y_end, drift, rise, l->impact, l->contact,
		              l->correction, l->residual, wt.pen_max, wt.tunnels);
		assert_int_equal(rc, BSIM_OK);
		assert_int_equal(res.steps_run, 100000);
		assert_int_equal(wt.nonfinite, 0);
		/* The model conserves energy here; a solver may only lose it (the
		 * backends' files say how much and why), never gain it. */
		assert_true(drift <= 0.0 && fabs(drift) <= drift_bound);
		/* a backend whose body stays in the cage states how often it may
		 * cross a beam (0); one whose body leaves it states none */
		if (caged)
			assert_true(wt.tunnels <= tunnel_bound);
		else
			print_message("%s: tunnelling not checked: it states no bound "
			              "hard.conservative.tunnels\n",
			              b->name);
	}
	bsim_scene_free(&s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_zeno_settling),     cmocka_unit_test(test_double_impact),
	        cmocka_unit_test(test_mass_ratio),        cmocka_unit_test(test_wedge),
	        cmocka_unit_test(test_impact_phase),      cmocka_unit_test(test_violent_noise),
	        cmocka_unit_test(test_conservative_long),
	};
	return bsim_test_run_per_backend("hard_cases", tests, sizeof tests / sizeof tests[0]);
}
