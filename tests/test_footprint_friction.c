/* Ground friction on a body that slides and spins at once, on every
 * backend of the registry, against an integration over the footprint done
 * here: the footprint cut into equal-area patches (polar midpoint rule about
 * the centre, rays at (j + 1/2) 2 pi / n, rings at rho sqrt((k + 1/2) / m)),
 * each patch rubbing at mu (M g / A) against its own velocity
 * v + omega z x r, and the body's motion under that force and torque
 * integrated by classical Runge-Kutta at a step of 2 ms until it stops.
 * Nothing here calls the library's friction code in the integration; the
 * library uses the disk's closed form in elliptic integrals, and a table
 * over the twist's direction for a capsule and an ellipse
 * (model/footprint_table.h), and steps backward Euler at the scene's dt.
 *
 * Checked: a disk, a capsule and an ellipse, each sliding and spinning,
 * stop at the integration's time and place (1%); they stay at rest after
 * it, friction never gains them energy and books what they had. The
 * pipeline's friction at a given twist (a tiny step, so that the step's end
 * twist is its start's): sliding alone mu M g against v and no torque,
 * spinning alone the disk's 2/3 mu M g R and the other shapes' mu M g r_s
 * (r_s integrated here), and in between the disk's force and torque against
 * the integration's at five ratios eps = |v| / (R |omega|) and the capsule's
 * and ellipse's at four twists. The table: the integrals its nodes hold
 * against the patches at twists all over the octant; the table against
 * those integrals at 3000 twists (its interpolation), its Hessian against
 * its gradient's differences, mirrored twists to the bit, a table grown by
 * other twists giving the same bits; and the step at the limit set: held
 * to the bit just inside, sliding just outside. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "beamsim/effects.h"
#include "beamsim/trial.h"
#include "model/footprint_friction.h"
#include "scenes.h"
#include "support.h"

#define PI 3.14159265358979323846
#define MU 0.4
#define G  9.81

/* ---- the footprint as patches ---- */

/* The outline's distance from the centre along phi in the body's frame
 * (the heading along +x): a capsule's segment (-l, 0)-(l, 0) swept by r
 * meets the ray on its side y = r or on the end cap it points to. */
static double outline(const bsim_body_def *b, double phi)
{
	double c = cos(phi), s = sin(phi);
	if (b->shape == BSIM_SHAPE_DISK)
		return b->radius;
	if (b->shape == BSIM_SHAPE_ELLIPSE) {
		double a = b->semi_axes[0], e = b->semi_axes[1];
		return 1.0 / sqrt(c * c / (a * a) + s * s / (e * e));
	}
	double l = b->length / 2, r = b->radius;
	if (fabs(s) > 0 && fabs(r / s * c) <= l)
		return r / fabs(s);
	return l * fabs(c) + sqrt(r * r - l * l * s * s); /* |t e - (l sgn c, 0)| = r */
}

typedef struct patches {
	int n;
	double *x, *y, *a; /* m, m, m^2 */
	double area;       /* m^2 */
} patches;

static void patches_make(patches *p, const bsim_body_def *b, int rays, int rings)
{
	p->n = rays * rings;
	p->x = malloc(3 * (size_t)p->n * sizeof *p->x);
	assert_non_null(p->x);
	p->y = p->x + p->n;
	p->a = p->y + p->n;
	p->area = 0.0;
	int i = 0;
	for (int j = 0; j < rays; j++) {
		double phi = (j + 0.5) * 2.0 * PI / rays, rho = outline(b, phi);
		for (int k = 0; k < rings; k++, i++) {
			double r = rho * sqrt((k + 0.5) / rings);
			p->x[i] = r * cos(phi);
			p->y[i] = r * sin(phi);
			p->a[i] = 0.5 * rho * rho * (2.0 * PI / rays) / rings;
			p->area += p->a[i];
		}
	}
}

/* The friction on the footprint of mass M at body-frame velocity v and
 * spin w: force (body frame) and torque. */
static void patches_friction(const patches *p, double mass, const double v[2], double w,
                             double out[3])
{
	double fx = 0, fy = 0, t = 0;
	for (int i = 0; i < p->n; i++) {
		double ux = v[0] - w * p->y[i], uy = v[1] + w * p->x[i];
		double m = sqrt(ux * ux + uy * uy);
		if (m == 0)
			continue;
		fx -= p->a[i] * ux / m;
		fy -= p->a[i] * uy / m;
		t -= p->a[i] * (p->x[i] * uy - p->y[i] * ux) / m;
	}
	double k = MU * mass * G / p->area;
	out[0] = k * fx;
	out[1] = k * fy;
	out[2] = k * t;
}

/* The footprint's mean distance from its centre, r_s = (1/A) integral |r|
 * dA = (1/A) integral rho^3 / 3 dphi, by the midpoint rule over 2^20 rays. */
static double mean_arm(const bsim_body_def *b)
{
	const int n = 1 << 20;
	double sum = 0.0, area = 0.0;
	for (int j = 0; j < n; j++) {
		double rho = outline(b, (j + 0.5) * 2.0 * PI / n);
		sum += rho * rho * rho / 3.0;
		area += rho * rho / 2.0;
	}
	return sum / area;
}

/* ---- the motion, by Runge-Kutta ---- */

typedef struct motion {
	double t_stop; /* s */
	double x[2];   /* m, where it stops */
	double psi;    /* rad, its heading there */
} motion;

/* d/dt of (x, y, vx, vy, psi, w). */
static void rates(const patches *p, double mass, double inertia, const double s[6], double d[6])
{
	double c = cos(s[4]), sn = sin(s[4]), vb[2] = {c * s[2] + sn * s[3], -sn * s[2] + c * s[3]};
	double f[3];
	patches_friction(p, mass, vb, s[5], f);
	d[0] = s[2];
	d[1] = s[3];
	d[2] = (c * f[0] - sn * f[1]) / mass;
	d[3] = (sn * f[0] + c * f[1]) / mass;
	d[4] = s[5];
	d[5] = f[2] / inertia;
}

static double kinetic(double mass, double inertia, const double s[6])
{
	return 0.5 * mass * (s[2] * s[2] + s[3] * s[3]) + 0.5 * inertia * s[5] * s[5];
}

/* From the body's start to rest. Near the stop the deceleration is nearly
 * constant and sqrt(E) falls along a line: the stop is where the line
 * through the last two steps meets 0, taken once it does so within the
 * next step (a step across the stop would meet friction's jump there). */
static motion integrate(const bsim_body_def *b, const patches *p)
{
	const double h = 2e-3, mass = b->mass, inertia = bsim_body_inertia(b);
	double s[6] = {b->start[0],
	               b->start[1],
	               b->velocity[0],
	               b->velocity[1],
	               b->heading_deg * PI / 180,
	               b->angular_velocity};
	double t = 0.0, root_prev = 0.0;
	for (long n = 0; n < 100000; n++) {
		double root = sqrt(kinetic(mass, inertia, s)), fall = root_prev - root;
		if (n > 0 && fall > 0 && root <= fall) {
			double tau = h * root / fall; /* to the stop */
			motion m = {t + tau,
			            {s[0] + 0.5 * s[2] * tau, s[1] + 0.5 * s[3] * tau},
			            s[4] + 0.5 * s[5] * tau};
			return m;
		}
		double k[4][6], tmp[6];
		rates(p, mass, inertia, s, k[0]);
		for (int i = 0; i < 6; i++)
			tmp[i] = s[i] + 0.5 * h * k[0][i];
		rates(p, mass, inertia, tmp, k[1]);
		for (int i = 0; i < 6; i++)
			tmp[i] = s[i] + 0.5 * h * k[1][i];
		rates(p, mass, inertia, tmp, k[2]);
		for (int i = 0; i < 6; i++)
			tmp[i] = s[i] + h * k[2][i];
		rates(p, mass, inertia, tmp, k[3]);
		for (int i = 0; i < 6; i++)
			s[i] += h / 6.0 * (k[0][i] + 2 * k[1][i] + 2 * k[2][i] + k[3][i]);
		root_prev = root;
		t += h;
	}
	fail_msg("the integration did not stop");
	motion none = {0};
	return none;
}

/* ---- the cases ---- */

enum { DISK, CAPSULE, ELLIPSE, N_CASES };
static const char *const case_name[N_CASES] = {"disk", "capsule", "ellipse"};

/* A body of 2 kg far from the scene's one beam, turning, on ground
 * friction mu = 0.4: a disk (R = 4 m) at 5 m/s and 3 rad/s; the capsule
 * (R = 4 m, segment 12 m) across its motion at 5 m/s and 3 rad/s; an
 * ellipse (8 m x 4 m) at 30 deg moving at (-2, 4) m/s and -2.5 rad/s. */
static void scene_case(bsim_scene *s, int c)
{
	scene_one_beam(s);
	bsim_body_def *b = &s->body;
	b->mass = 2.0;
	b->rotates = 1;
	b->velocity[0] = 5.0;
	b->angular_velocity = 3.0;
	if (c == DISK) {
		b->radius = 4.0;
	} else if (c == CAPSULE) {
		b->shape = BSIM_SHAPE_CAPSULE;
		b->radius = 4.0;
		b->length = 12.0;
	} else {
		b->shape = BSIM_SHAPE_ELLIPSE;
		b->radius = 0.0;
		b->semi_axes[0] = 8.0;
		b->semi_axes[1] = 4.0;
		b->heading_deg = 30.0;
		b->velocity[0] = -2.0;
		b->velocity[1] = 4.0;
		b->angular_velocity = -2.5;
	}
	s->effects.has_ground_friction = 1;
	s->effects.ground_mu = MU;
	s->effects.ground_g = G;
	s->max_steps = 2000; /* 8 s */
	s->side_x = 1000.0;
	bsim_error err;
	assert_int_equal(bsim_scene_validate(s, &err), BSIM_OK);
}

/* The integration's stop of each case, made once for every backend. */
static motion truth[N_CASES];
static int truth_made;

static void make_truth(void)
{
	if (truth_made)
		return;
	for (int c = 0; c < N_CASES; c++) {
		bsim_scene s;
		scene_case(&s, c);
		patches p;
		patches_make(&p, &s.body, 256, 48);
		truth[c] = integrate(&s.body, &p);
		free(p.x);
		bsim_scene_free(&s);
	}
	truth_made = 1;
}

typedef struct stop_track {
	double v0, w0, mass, inertia;
	long stop;        /* the first step at rest, or -1 */
	double x[2], psi; /* there */
	double rise;      /* the most the kinetic energy rose in a step, J */
	double after;     /* the largest |v| + |omega| after the stop */
	double e_last;
} stop_track;

static void track_stop(void *user, long step, const bsim_state *s)
{
	stop_track *t = user;
	double v = hypot(s->v[0], s->v[1]), w = fabs(s->angular_velocity);
	double e = 0.5 * t->mass * v * v + 0.5 * t->inertia * w * w;
	if (step > 0)
		t->rise = fmax(t->rise, e - t->e_last);
	t->e_last = e;
	if (t->stop < 0 && v < 1e-6 * t->v0 && w < 1e-6 * t->w0) {
		t->stop = step;
		t->x[0] = s->x[0];
		t->x[1] = s->x[1];
		t->psi = s->heading;
	} else if (t->stop >= 0) {
		t->after = fmax(t->after, v + w);
	}
}

/* Each case's stop time and place against the integration's, within 1%
 * (of the time; of the distance travelled, for the place); at rest after
 * it (float32's residue on Box2D); the kinetic energy never rising (by
 * more than float32 rounds, 1e-6 J); the ledger's friction booking the
 * start's kinetic energy (2%, Box2D's position update). */
static void test_slide_and_spin_stop(void **state)
{
	const bsim_backend *be = *state;
	make_truth();
	for (int c = 0; c < N_CASES; c++) {
		bsim_scene s;
		scene_case(&s, c);
		const bsim_body_def *b = &s.body;
		stop_track t = {.v0 = hypot(b->velocity[0], b->velocity[1]),
		                .w0 = fabs(b->angular_velocity),
		                .mass = b->mass,
		                .inertia = bsim_body_inertia(b),
		                .stop = -1};
		bsim_recorder rec = {.trace = track_stop, .trace_user = &t};
		bsim_trial_runner *r = bsim_trial_runner_alloc();
		bsim_trial_result out;
		bsim_error err;
		const bsim_options o = bsim_test_body_options(be, b);
		int rc = bsim_trial_run(r, &s, be, &o, 1, &rec, &out, &err);
		if (rc == BSIM_EINPUT) { /* a backend that does not take the shape */
			print_message("%s %s: skipped (%s)\n", be->name, case_name[c], err.msg);
			bsim_trial_runner_free(r);
			bsim_scene_free(&s);
			continue;
		}
		assert_int_equal(rc, BSIM_OK);
		const motion *m = &truth[c];
		double dist = hypot(m->x[0] - b->start[0], m->x[1] - b->start[1]);
		double miss = hypot(t.x[0] - m->x[0], t.x[1] - m->x[1]);
		double t_stop = t.stop * s.dt;
		print_message("%s %s: stops at %.4f s (integration %.4f s), %.4f m from its start "
		              "(%.4f m), %.3g m from the integration's stop; heading %.4f rad "
		              "(%.4f); energy rose at most %.2g J a step; after the stop %.2g; "
		              "friction %.4f J of %.4f J\n",
		              be->name, case_name[c], t_stop, m->t_stop,
		              hypot(t.x[0] - b->start[0], t.x[1] - b->start[1]), dist, miss, t.psi,
		              m->psi, t.rise, t.after, out.ledger.friction, out.ledger.e_start);
		assert_true(t.stop > 0);
		assert_true(fabs(t_stop - m->t_stop) < 0.01 * m->t_stop);
		assert_true(miss < 0.01 * dist);
		assert_true(t.after < 1e-5);
		assert_true(t.rise < 1e-6);
		assert_true(fabs(out.ledger.friction - out.ledger.e_start) <
		            0.02 * out.ledger.e_start);
		bsim_trial_runner_free(r);
		bsim_scene_free(&s);
	}
}

/* ---- the friction at a twist ---- */

/* The pipeline's force and torque on the body of case c at velocity v
 * (world), spin w, heading psi, over a step of 1e-9 s: the wrench that
 * stops the body is then M v / h, so large that the step's end twist is
 * its start's to 1e-9, and the friction is that of the twist. */
static void pipeline_friction(const bsim_scene *s, const double v[2], double w, double psi,
                              double f[3])
{
	bsim_effects fx;
	assert_int_equal(bsim_effects_init(&fx, s, 1), BSIM_OK);
	bsim_state at;
	assert_int_equal(bsim_state_init(&at, s->n_beams), BSIM_OK);
	at.v[0] = v[0];
	at.v[1] = v[1];
	at.angular_velocity = w;
	at.heading = psi;
	bsim_effects_force_at(&fx, 0, 1e-9, &at, f);
	bsim_state_free(&at);
	bsim_effects_free(&fx);
}

/* Sliding alone, spinning alone, and both. */
static void test_friction_at_twist(void **state)
{
	(void)state;
	for (int c = 0; c < N_CASES; c++) {
		bsim_scene s;
		scene_case(&s, c);
		const bsim_body_def *b = &s.body;
		const double limit = MU * b->mass * G;
		patches p;
		patches_make(&p, b, 2048, 512);
		const double arm = mean_arm(b);
		double f[3];
		/* sliding alone: mu M g against v, no torque */
		const double v[2] = {3.0, -4.0}, still[2] = {0.0, 0.0};
		pipeline_friction(&s, v, 0.0, 0.7, f);
		assert_true(fabs(f[0] + 0.6 * limit) < 1e-12 * limit);
		assert_true(fabs(f[1] - 0.8 * limit) < 1e-12 * limit);
		assert_true(f[2] == 0.0);
		/* spinning alone: the torque mu M g r_s, no force */
		pipeline_friction(&s, still, 2.0, 0.7, f);
		double torque = c == DISK ? 2.0 / 3.0 * limit * b->radius : limit * arm;
		print_message("%s spinning: torque %.10g N m (%s %.10g)\n", case_name[c], -f[2],
		              c == DISK ? "2/3 mu M g R" : "mu M g r_s integrated here", torque);
		assert_true(f[0] == 0.0 && f[1] == 0.0);
		assert_true(fabs(-f[2] - torque) < (c == DISK ? 1e-12 : 1e-9) * torque);
		/* both: the disk at eps = |v| / (R w) across the rim; the other
		 * shapes at twists whose centre of rotation lies inside and outside
		 * the footprint, at a heading of 0.7 rad */
		static const double eps[5] = {0.2, 0.7, 1.0, 1.5, 4.0};
		static const double twist[4][3] = {
		        {1.0, 2.0, 0.3}, {3.0, -1.0, 2.0}, {-2.0, 0.5, -0.1}, {0.5, 0.5, -1.0}};
		const int n = c == DISK ? 5 : 4;
		double worst_f = 0.0, worst_t = 0.0;
		for (int k = 0; k < n; k++) {
			double vw[2], w, psi = 0.7;
			if (c == DISK) {
				w = 1.5;
				vw[0] = eps[k] * b->radius * w * cos(0.3);
				vw[1] = eps[k] * b->radius * w * sin(0.3);
			} else {
				vw[0] = twist[k][0];
				vw[1] = twist[k][1];
				w = twist[k][2];
			}
			pipeline_friction(&s, vw, w, psi, f);
			double cs = cos(psi), sn = sin(psi), want[3];
			double vb[2] = {cs * vw[0] + sn * vw[1], -sn * vw[0] + cs * vw[1]};
			patches_friction(&p, b->mass, vb, w, want);
			double fw[2] = {cs * want[0] - sn * want[1], sn * want[0] + cs * want[1]};
			double reach = c == DISK      ? b->radius
			               : c == CAPSULE ? b->length / 2 + b->radius
			                              : b->semi_axes[0];
			worst_f = fmax(worst_f, hypot(f[0] - fw[0], f[1] - fw[1]) / limit);
			worst_t = fmax(worst_t, fabs(f[2] - want[2]) / (limit * reach));
		}
		print_message("%s sliding and spinning: force within %.3g mu M g, torque within "
		              "%.3g mu M g reach of the patches'\n",
		              case_name[c], worst_f, worst_t);
		/* the disk in closed form, the others by the table (docs/files.md) */
		double bound = c == DISK ? 1e-5 : 1e-3;
		assert_true(worst_f < bound);
		assert_true(worst_t < bound);
		free(p.x);
		bsim_scene_free(&s);
	}
}

/* ---- the table ---- */

/* The outlines whose table is checked: the capsule and the ellipse above,
 * the shape study's capsule (R 6 m, segment 16.755 m) and a thin ellipse
 * (12 m x 2 m). */
enum { N_TABLES = 4 };
static const char *const table_name[N_TABLES] = {"capsule 4 m x 12 m", "ellipse 8 m x 4 m",
                                                 "capsule 6 m x 16.755 m", "ellipse 12 m x 2 m"};

static void table_body(int k, bsim_body_def *b)
{
	memset(b, 0, sizeof *b);
	b->mass = 2.0;
	b->rotates = 1;
	b->shape = k % 2 ? BSIM_SHAPE_ELLIPSE : BSIM_SHAPE_CAPSULE;
	static const double size[N_TABLES][2] = {
	        {4.0, 12.0}, {8.0, 4.0}, {6.0, 16.755}, {12.0, 2.0}};
	if (k % 2) {
		b->semi_axes[0] = size[k][0];
		b->semi_axes[1] = size[k][1];
	} else {
		b->radius = size[k][0];
		b->length = size[k][1];
	}
}

/* Outline t's body and its ground friction. */
static bsim_footprint_friction *table_friction(int t, bsim_body_def *b)
{
	table_body(t, b);
	bsim_footprint_friction *fr = bsim_footprint_friction_alloc(b, MU, G, NULL);
	assert_non_null(fr);
	return fr;
}

/* A twist direction q >= 0 (v_x, v_y, omega a) from a uniform draw: the
 * test's own generator, so that the directions are the same on every run. */
static void twist_draw(uint64_t *state, double q[3])
{
	for (int k = 0; k < 3; k++) {
		*state = *state * 6364136223846793005ull + 1442695040888963407ull;
		q[k] = ((*state >> 11) + 0.5) / 9007199254740992.0;
	}
}

/* The integrals a node holds (bsim_footprint_table_exact: D's gradient
 * from integrals about the centre of rotation) against the patches' sum
 * at 60 twist directions, the centre of rotation inside and outside the
 * outline: force and torque within 3e-5 of mu M g and of mu M g a. */
static void test_table_integrals(void **state)
{
	(void)state;
	for (int t = 0; t < N_TABLES; t++) {
		bsim_body_def b;
		bsim_footprint_friction *fr = table_friction(t, &b);
		const double *k = fr->table->scale, a = fr->table->arm, limit = MU * b.mass * G;
		patches p;
		patches_make(&p, &b, 1024, 256);
		uint64_t draw = 7;
		double worst_f = 0.0, worst_t = 0.0;
		for (int i = 0; i < 60; i++) {
			double q[3], g[3], want[3];
			twist_draw(&draw, q);
			bsim_footprint_table_exact(fr->table, q, g);
			const double v[2] = {k[0] * q[0], k[1] * q[1]};
			patches_friction(&p, b.mass, v, k[2] * q[2], want);
			worst_f = fmax(worst_f, hypot(g[0] / k[0] * limit + want[0],
			                              g[1] / k[1] * limit + want[1]));
			worst_t = fmax(worst_t, fabs(g[2] / k[2] * limit + want[2]) / a);
		}
		print_message(
		        "%s: the nodes' integrals within %.2g mu M g (force) and %.2g mu M g a "
		        "(torque) of the patches at 60 twists\n",
		        table_name[t], worst_f / limit, worst_t / limit);
		assert_true(worst_f < 3e-5 * limit);
		assert_true(worst_t < 3e-5 * limit);
		free(p.x);
		bsim_footprint_friction_free(fr);
	}
}

/* The table's friction (bsim_footprint_friction_of_twist) against the
 * integrals at 3000 twist directions drawn over the octant: within 1e-3
 * of mu M g (force) and of mu M g a (torque); its Hessian against central
 * differences of its gradient at 300 of them (the step's Newton method
 * needs it); twists mirrored in either axis of the body, or turned by pi,
 * give the friction mirrored or turned to the bit; a table that has grown
 * over other twists gives the same bits as a new one. */
static void test_table_interpolation(void **state)
{
	(void)state;
	for (int t = 0; t < N_TABLES; t++) {
		bsim_body_def b;
		bsim_footprint_friction *fr = table_friction(t, &b);
		const double *k = fr->table->scale, a = fr->table->arm, limit = MU * b.mass * G;
		uint64_t draw = 11;
		double worst_f = 0.0, worst_t = 0.0, worst_h = 0.0, at[3] = {0};
		for (int i = 0; i < 3000; i++) {
			double q[3], g[3], out[3];
			twist_draw(&draw, q);
			const double twist[3] = {k[0] * q[0], k[1] * q[1], k[2] * q[2]};
			bsim_footprint_friction_of_twist(fr, twist, out);
			bsim_footprint_table_exact(fr->table, q, g);
			const double ef =
			        hypot(out[0] + g[0] / k[0] * limit, out[1] + g[1] / k[1] * limit) /
			        limit;
			const double et = fabs(out[2] + g[2] / k[2] * limit) / (limit * a);
			if (fmax(ef, et) > fmax(worst_f, worst_t))
				memcpy(at, q, sizeof at);
			worst_f = fmax(worst_f, ef);
			worst_t = fmax(worst_t, et);
			if (i % 10)
				continue;
			/* the Hessian: H e_j against (g(q + h e_j) - g(q - h e_j)) / 2h */
			double gt[3], H[6];
			bsim_footprint_table_eval(fr->table, q, gt, H);
			static const int slot[3][3] = {{0, 1, 2}, {1, 3, 4}, {2, 4, 5}};
			for (int j = 0; j < 3; j++) {
				double up[3] = {q[0], q[1], q[2]}, down[3] = {q[0], q[1], q[2]};
				double gu[3], gd[3];
				const double h = 1e-6;
				up[j] += h;
				down[j] -= h;
				bsim_footprint_table_eval(fr->table, up, gu, NULL);
				bsim_footprint_table_eval(fr->table, down, gd, NULL);
				for (int l = 0; l < 3; l++)
					worst_h = fmax(worst_h, fabs((gu[l] - gd[l]) / (2 * h) -
					                             H[slot[j][l]]) /
					                                (k[j] * k[l]));
			}
		}
		print_message(
		        "%s: the table within %.2g mu M g (force) and %.2g mu M g a (torque) of "
		        "the integrals at 3000 twists (the worst at q = %.3f %.3f %.3f); its "
		        "Hessian within %.2g of its gradient's differences; %ld nodes\n",
		        table_name[t], worst_f, worst_t, at[0], at[1], at[2], worst_h,
		        fr->table->nodes_built);
		assert_true(worst_f < 1e-3);
		assert_true(worst_t < 1e-3);
		assert_true(worst_h < 1e-5);
		/* mirrored and turned twists, and a table grown by other twists
		 * against a new one */
		bsim_footprint_friction *fresh = bsim_footprint_friction_alloc(&b, MU, G, NULL);
		assert_non_null(fresh);
		draw = 13;
		for (int i = 0; i < 200; i++) {
			double q[3], base[3], image[3], again[3];
			twist_draw(&draw, q);
			const double twist[3] = {k[0] * (q[0] - 0.5), k[1] * (q[1] - 0.5),
			                         k[2] * (q[2] - 0.5)};
			bsim_footprint_friction_of_twist(fr, twist, base);
			static const double flip[3][3] = {{1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
			for (int m = 0; m < 3; m++) {
				const double turned[3] = {flip[m][0] * twist[0],
				                          flip[m][1] * twist[1],
				                          flip[m][2] * twist[2]};
				bsim_footprint_friction_of_twist(fr, turned, image);
				for (int l = 0; l < 3; l++)
					assert_true(image[l] == flip[m][l] * base[l]);
			}
			bsim_footprint_friction_of_twist(fresh, twist, again);
			for (int l = 0; l < 3; l++)
				assert_true(again[l] == base[l]);
		}
		bsim_footprint_friction_free(fresh);
		bsim_footprint_friction_free(fr);
	}
}

/* The step (bsim_footprint_friction_wrench) on each shape: at the edge of
 * the limit set, the wrench lambda W(n) of a twist direction n, W(n) its
 * friction (on the limit set's boundary), is held to the bit at
 * lambda = 0.999 (friction -P exactly: the body stays at rest) and not at
 * 1.01; and at 200 stopping wrenches P from 0.3 to 300 times the limits, the
 * body either stays at rest (friction -P to the bit, then within the
 * limits) or ends the step at a twist xi' = h M^-1 (P + W) whose own
 * friction W is (backward Euler: within 1e-6 of the limits), each of whose
 * components in the body's frame has the sign of P's or is 0 (it never
 * passes rest). */
static void test_step(void **state)
{
	(void)state;
	for (int c = 0; c < N_CASES; c++) {
		bsim_scene s;
		scene_case(&s, c);
		const bsim_body_def *b = &s.body;
		bsim_footprint_friction *fr = bsim_footprint_friction_alloc(b, MU, G, NULL);
		assert_non_null(fr);
		const double mass = b->mass, inertia = bsim_body_inertia(b), h = 0.004;
		const double limit = MU * mass * G, spin = fr->spin_limit;
		const double reach = c == ELLIPSE ? b->semi_axes[0] : b->radius;
		uint64_t draw = 17;
		for (int i = 0; i < 40; i++) {
			double q[3], w[3], out[3];
			twist_draw(&draw, q);
			const double n[3] = {q[0] - 0.5, q[1] - 0.5, (q[2] - 0.5) / reach};
			bsim_footprint_friction_of_twist(fr, n, w);
			const double in[2] = {-0.999 * w[0], -0.999 * w[1]};
			bsim_footprint_friction_wrench(fr, 0.0, in, -0.999 * w[2], out);
			assert_true(out[0] == -in[0] && out[1] == -in[1] && out[2] == 0.999 * w[2]);
			const double past[2] = {-1.01 * w[0], -1.01 * w[1]};
			bsim_footprint_friction_wrench(fr, 0.0, past, -1.01 * w[2], out);
			assert_false(out[0] == -past[0] && out[1] == -past[1] &&
			             out[2] == 1.01 * w[2]);
		}
		int held = 0;
		double worst = 0.0;
		for (int i = 0; i < 200; i++) {
			double q[3], out[3];
			twist_draw(&draw, q);
			const double size = 0.3 * pow(1000.0, q[2]), heading = 6.0 * q[0];
			const double dir = 2.0 * PI * q[1], lean = 1.5 * (q[0] - 0.5);
			const double p[2] = {size * limit * cos(dir) * cos(lean),
			                     size * limit * sin(dir) * cos(lean)};
			const double pq = size * spin * sin(lean) * (i % 2 ? 1.0 : -1.0);
			bsim_footprint_friction_wrench(fr, heading, p, pq, out);
			if (out[0] == -p[0] && out[1] == -p[1] && out[2] == -pq) {
				held++;
				assert_true(hypot(p[0], p[1]) <= limit && fabs(pq) <= spin);
				continue;
			}
			const double end[3] = {h * (p[0] + out[0]) / mass,
			                       h * (p[1] + out[1]) / mass,
			                       h * (pq + out[2]) / inertia};
			/* in the body's frame */
			const double cs = cos(heading), sn = sin(heading);
			const double pb[3] = {cs * p[0] + sn * p[1], cs * p[1] - sn * p[0], pq};
			const double eb[3] = {cs * end[0] + sn * end[1], cs * end[1] - sn * end[0],
			                      end[2]};
			double own[3];
			bsim_footprint_friction_of_twist(fr, eb, own);
			const double ob[3] = {cs * out[0] + sn * out[1], cs * out[1] - sn * out[0],
			                      out[2]};
			worst = fmax(worst, fmax(hypot(own[0] - ob[0], own[1] - ob[1]) / limit,
			                         fabs(own[2] - ob[2]) / spin));
			for (int l = 0; l < 3; l++)
				assert_true(eb[l] * pb[l] >= -1e-12 * fabs(pb[l]));
		}
		print_message("%s: %d of 200 stopping wrenches held; the others' friction within "
		              "%.2g of the limits of their end twist's\n",
		              case_name[c], held, worst);
		assert_true(worst < 1e-6);
		assert_true(held > 0 && held < 200);
		bsim_footprint_friction_free(fr);
		bsim_scene_free(&s);
	}
}

int main(void)
{
	const struct CMUnitTest every[] = {
	        cmocka_unit_test(test_slide_and_spin_stop),
	};
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_friction_at_twist),
	        cmocka_unit_test(test_table_integrals),
	        cmocka_unit_test(test_table_interpolation),
	        cmocka_unit_test(test_step),
	};
	int rc = bsim_test_run_per_backend("footprint_friction", every,
	                                   sizeof every / sizeof every[0]);
	return cmocka_run_group_tests(tests, NULL, NULL) || rc;
}
