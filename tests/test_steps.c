/* Runs of steps (bsim_backend.advance of many steps: the thesis backend's
 * runs, backends/thesis/thesis_steps.c, its free flight and its steps one
 * after another) against the step they stand in for, which is the truth
 * here: two worlds of one scene and one set of knobs take the same forces,
 * one a step at a time (advance of one step, no state written, then
 * get_state), the other in runs of 1 to 64 steps under a schedule of
 * forces, and
 * every state of the runs must equal the
 * stepped one to the bit (body, active beams, angles, velocities, contact
 * flags, energy flows, impacts, solver counts). Between runs the second
 * world also takes single steps, so the lists a run leaves must be the
 * ones the step leaves. The forces are drawn here (the runner's pipeline
 * is not involved): propulsion along +y and a lateral force held for 1
 * to 8 steps, as the essay's force is held between its draws (so that it
 * changes within a run), with a pull toward
 * the centre line so that the body stays among the beams.
 *
 * The scenes: the essay's gate at the forces of H1, H2's asymmetric
 * stiffness, elastic impacts without dampers, beams that start swinging and
 * a body that starts touching, a world of 6 beams (the general count),
 * each knob the runs take (integrator, projection, impact_mass, slop,
 * contact_tol, broad_phase), a state that stops being finite, and worlds
 * the disk's runs do not take (contact_mode=essay, nearest_first, sleep, a
 * body that turns), whose runs are the step's one after another. Each
 * case counts the steps it compared in runs
 * and contacts among them, so that a case which never reached the beams
 * fails rather than passes unseen.
 *
 * Then the runner (src/run/trial_steps.c): a trial it books in runs gives
 * the same result to the bit as the same trial stepped one step at a time
 * (a trace, which sees every step, keeps the runner on the step loop):
 * H1's forces over seeds with every outcome, a sequence of trials in one
 * runner that keeps its world (a run the trial ends inside leaves the
 * world ahead, and the reset must put it back), knobs, six beams, a state
 * that stops being finite inside a run, and a world the disk's runs
 * decline. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "beamsim/contact_flag.h"
#include "beamsim/backend.h"
#include "beamsim/scene.h"
#include "beamsim/trial.h"
#include "scenes.h"
#include "support.h"

#define RUN_MAX 64

/* the test's own forces, reproducible */
static uint64_t rng_state;

static double rng_uniform(void)
{
	return bsim_test_uniform(&rng_state);
}

/* A normal deviate (Box-Muller), for the lateral force. */
static double rng_normal(void)
{
	double u = rng_uniform(), v = rng_uniform();
	return sqrt(-2.0 * log(u + 1e-300)) * cos(6.283185307179586 * v);
}

static void assert_same_state(const bsim_state *a, const bsim_state *b, long step)
{
	if (memcmp(a->x, b->x, sizeof a->x) || memcmp(a->v, b->v, sizeof a->v))
		fail_msg("step %ld: body (%.17g, %.17g) v (%.17g, %.17g) against (%.17g, %.17g) "
		         "v (%.17g, %.17g)",
		         step, b->x[0], b->x[1], b->v[0], b->v[1], a->x[0], a->x[1], a->v[0],
		         a->v[1]);
	assert_memory_equal(&a->heading, &b->heading, sizeof a->heading);
	assert_memory_equal(&a->angular_velocity, &b->angular_velocity, sizeof a->heading);
	assert_int_equal(a->n_beams, b->n_beams);
	if (a->n_active != b->n_active)
		fail_msg("step %ld: %d active beams against %d", step, b->n_active, a->n_active);
	assert_memory_equal(a->active, b->active, (size_t)a->n_active * sizeof *a->active);
	size_t nb = (size_t)a->n_beams;
	if (memcmp(a->theta, b->theta, nb * sizeof *a->theta) ||
	    memcmp(a->omega, b->omega, nb * sizeof *a->omega))
		fail_msg("step %ld: beam 1 theta %.17g omega %.17g against %.17g %.17g", step,
		         b->theta[0], b->omega[0], a->theta[0], a->omega[0]);
	assert_memory_equal(a->contact, b->contact, nb * sizeof *a->contact);
	for (int k = 0; k < a->n_active; k++) {
		const int i = a->active[k];
		if (memcmp(&a->impulse[i], &b->impulse[i], sizeof a->impulse[i]))
			fail_msg("step %ld beam %d: impulse %.17g against %.17g", step, i,
			         b->impulse[i], a->impulse[i]);
		if (a->touched[i] != b->touched[i])
			fail_msg("step %ld beam %d: touched %d against %d", step, i, b->touched[i],
			         a->touched[i]);
		/* the direction where the flag is the gap's or the touch's (it is
		 * not read beyond the body's reach) */
		if (a->contact[i] != BSIM_CONTACT_NONE)
			assert_memory_equal(&a->direction[2 * i], &b->direction[2 * i],
			                    2 * sizeof *a->direction);
		assert_memory_equal(&a->pin[2 * i], &b->pin[2 * i], 2 * sizeof *a->pin);
	}
	if (memcmp(&a->energy, &b->energy, sizeof a->energy))
		fail_msg("step %ld: energy flows damper %.17g impact %.17g contact %.17g "
		         "correction %.17g against %.17g %.17g %.17g %.17g",
		         step, b->energy.damper, b->energy.impact, b->energy.contact,
		         b->energy.correction, a->energy.damper, a->energy.impact,
		         a->energy.contact, a->energy.correction);
	assert_int_equal(a->impacts, b->impacts);
	assert_memory_equal(&a->solver, &b->solver, sizeof a->solver);
}

typedef struct tally {
	long in_runs;  /* steps compared that a run made */
	long touching; /* of them, with a contact flag */
	long impacts;  /* impacts among them */
} tally;

/* `steps` steps of the scene's worlds under the knobs kv (NULL-ended)
 * with forces of propulsion f_prop and lateral magnitude rm held for runs
 * of random lengths; the second world makes most of them in runs. */
static void compare_worlds(const bsim_scene *s, const char *const *kv, double f_prop, double rm,
                           long steps, uint64_t seed, tally *t)
{
	const bsim_backend *be = bsim_test_backend("thesis");
	bsim_options o = {0};
	bsim_error err;
	for (int k = 0; kv && kv[k]; k++)
		assert_int_equal(bsim_options_add(&o, kv[k], &err), BSIM_OK);
	bsim_world *wa, *wb;
	assert_int_equal(be->create(s, &o, &wa, &err), BSIM_OK);
	assert_int_equal(be->create(s, &o, &wb, &err), BSIM_OK);
	bsim_state sa, sb, run[RUN_MAX];
	assert_int_equal(bsim_state_init(&sa, s->n_beams), BSIM_OK);
	assert_int_equal(bsim_state_init(&sb, s->n_beams), BSIM_OK);
	for (int k = 0; k < RUN_MAX; k++)
		assert_int_equal(bsim_state_init(&run[k], s->n_beams), BSIM_OK);
	rng_state = seed * 0x9E3779B97F4A7C15ull + 1;
	const double h = s->dt;
	long n = 0;
	while (n < steps) {
		int len = 1 + (int)(rng_uniform() * RUN_MAX);
		if (len > steps - n)
			len = (int)(steps - n);
		/* held for the run; pulled back toward the gate's centre line,
		 * so that the body meets the beams rather than leaving by a side */
		be->get_state(wa, &sa);
		bsim_contact_flags(s, &sa);
		bsim_wrench schedule[RUN_MAX];
		for (int k = 0, hold = 0; k < len; k++, hold--) {
			if (hold == 0) { /* a new lateral force every 1 to 8 steps */
				hold = 1 + (int)(rng_uniform() * 8);
				schedule[k] = (bsim_wrench){
				        {rm * rng_normal() - 0.5 * f_prop * sa.x[0], f_prop}, 0.0};
			} else
				schedule[k] = schedule[k - 1];
		}
		const double *force = schedule[0].force;
		/* one in four: a single step of the second world's own (thesis_step) */
		int single = rng_uniform() < 0.25;
		/* the rest asked again where a path ends short (free flight) */
		for (int made = 0, m; !single && made < len; made += m) {
			assert_int_equal(be->advance(wb, &schedule[made], h, len - made, &run[made],
			                             &m, &err),
			                 BSIM_OK);
			assert_true(m >= 1 && m <= len - made);
		}
		for (int k = 0; k < len; k++, n++) {
			assert_int_equal(bsim_backend_step(be, wa, schedule[k].force, 0.0, h, &err),
			                 BSIM_OK);
			be->get_state(wa, &sa);
			bsim_contact_flags(s, &sa);
			const bsim_state *b;
			if (single) {
				assert_int_equal(bsim_backend_step(be, wb, force, 0.0, h, &err),
				                 BSIM_OK);
				be->get_state(wb, &sb);
				bsim_contact_flags(s, &sb);
				b = &sb;
			} else {
				bsim_contact_flags(s, &run[k]);
				b = &run[k];
				t->in_runs++;
				for (int q = 0; q < b->n_active; q++)
					t->touching +=
					        b->contact[b->active[q]] != BSIM_CONTACT_NONE;
				t->impacts += b->impacts;
			}
			assert_same_state(&sa, b, n + 1);
			if (single)
				break;
		}
		if (single)
			n++;
	}
	/* the world after the runs: get_state agrees with the last one */
	be->get_state(wa, &sa);
	bsim_contact_flags(s, &sa);
	be->get_state(wb, &sb);
	bsim_contact_flags(s, &sb);
	assert_same_state(&sa, &sb, n);
	for (int k = 0; k < RUN_MAX; k++)
		bsim_state_free(&run[k]);
	bsim_state_free(&sa);
	bsim_state_free(&sb);
	be->destroy(wa);
	be->destroy(wb);
}

/* The essay's gate at H1's forces: every propulsion and noise level, the
 * body from the start to well past the beams or stuck. */
static void test_h1_forces(void **state)
{
	(void)state;
	tally t = {0};
	const double fp[] = {4, 6, 7, 9}, rm[] = {0, 10, 20, 40};
	uint64_t seed = 1;
	for (int i = 0; i < 4; i++)
		for (int j = 0; j < 4; j++) {
			bsim_scene s;
			bsim_scene_init_gate(&s, fp[i], rm[j]);
			compare_worlds(&s, NULL, fp[i], rm[j], 1500, seed++, &t);
			bsim_scene_free(&s);
		}
	assert_true(t.in_runs > 15000);
	assert_true(t.touching > 3000);
	assert_true(t.impacts > 10);
}

/* H2's asymmetric beams: the left one soft, the right one stiff. */
static void test_asymmetric(void **state)
{
	(void)state;
	tally t = {0};
	const double k_left[] = {100, 200, 800};
	for (int i = 0; i < 3; i++) {
		bsim_scene s;
		bsim_scene_init_gate(&s, 8.0, 20.0);
		s.beams[0].stiffness = k_left[i];
		compare_worlds(&s, NULL, 8.0, 30.0, 2000, 100 + (uint64_t)i, &t);
		bsim_scene_free(&s);
	}
	assert_true(t.touching > 1000);
}

/* Elastic impacts, no dampers (scenes.h), and beams that start swinging
 * with the body touching one of them. */
static void test_impacts_and_starts(void **state)
{
	(void)state;
	tally t = {0};
	bsim_scene s;
	scene_gate_conservative(&s);
	compare_worlds(&s, NULL, 0.0, 5.0, 1500, 7, &t);
	bsim_scene_free(&s);
	assert_true(t.impacts > 0);
	bsim_scene_init_gate(&s, 6.0, 20.0);
	s.beams[0].initial_theta = 0.3;
	s.beams[1].initial_omega = -1.0;
	s.body.start[0] = -10.0;
	s.body.start[1] = 30.0 - 10.0 - 1e-4; /* 0.1 mm under the left beam */
	compare_worlds(&s, NULL, 6.0, 20.0, 1500, 8, &t);
	bsim_scene_free(&s);
	assert_true(t.touching > 100);
}

/* Six beams: two gates one above the other and a pair of stubs between
 * them, so a body meets up to three at once; the run's general count. */
static void test_six_beams(void **state)
{
	(void)state;
	tally t = {0};
	bsim_scene s;
	assert_int_equal(scene_six_beams(&s, 7.0, 20.0), BSIM_OK);
	s.success_y = 1e9;
	compare_worlds(&s, NULL, 9.0, 30.0, 3000, 11, &t);
	bsim_scene_free(&s);
	assert_true(t.touching > 500);
}

/* Every knob the runs take, set away from its default. */
static void test_knobs(void **state)
{
	(void)state;
	static const char *const knobs[][3] = {
	        {"integrator=euler", NULL}, {"projection=0", NULL},
	        {"impact_mass=0.1", NULL},  {"slop=1e-3", "contact_tol=2e-3"},
	        {"broad_phase=0", NULL},    {"sleep=off", NULL},
	};
	for (size_t k = 0; k < sizeof knobs / sizeof knobs[0]; k++) {
		tally t = {0};
		bsim_scene s;
		bsim_scene_init_gate(&s, 8.0, 20.0);
		compare_worlds(&s, knobs[k], 8.0, 30.0, 1500, 20 + k, &t);
		bsim_scene_free(&s);
		/* impact_mass=0.1 flings the body off the beams: fewer */
		assert_true(t.touching >= 10);
	}
}

/* A force that makes the state overflow: the runs go on as the steps do
 * (no hang, the same non-finite bits). */
static void test_nonfinite(void **state)
{
	(void)state;
	tally t = {0};
	bsim_scene s;
	bsim_scene_init_gate(&s, 1e300, 0.0);
	compare_worlds(&s, NULL, 1e306, 1e306, 200, 30, &t);
	bsim_scene_free(&s);
	assert_true(t.in_runs > 100);
}

/* The worlds the runs leave to thesis_step. */
static void test_declined(void **state)
{
	(void)state;
	static const char *const knobs[][2] = {{"contact_mode=essay", NULL},
	                                       {"impact_order=nearest_first", NULL},
	                                       {"sleep=on", NULL}};
	for (size_t k = 0; k < 4; k++) {
		bsim_scene s;
		bsim_scene_init_gate(&s, 7.0, 20.0);
		if (k == 3)
			s.body.rotates = 1;
		tally t = {0};
		compare_worlds(&s, k < 3 ? knobs[k] : NULL, 7.0, 20.0, 3000, 11 + k, &t);
		assert_true(t.in_runs > 1000);
		assert_true(t.touching > 100);
		bsim_scene_free(&s);
	}
}

static void no_trace(void *user, long step, const bsim_state *s)
{
	(void)user;
	(void)step;
	(void)s;
}

/* Trial `trial` of seed through runs in runner (which may keep its world
 * from the trial before) into r, and stepped in a fresh runner into
 * r_step; returns the steps the first made in runs. */
static long trial_both(const bsim_scene *s, const bsim_options *o, uint64_t seed,
                       bsim_trial_runner *runner, bsim_trial_result *r, bsim_trial_result *r_step)
{
	bsim_backend counted = *bsim_test_backend("thesis");
	counted.advance = bsim_test_counted_advance;
	bsim_error err;
	bsim_test_run_steps = 0;
	assert_int_equal(bsim_trial_run(runner, s, &counted, o, seed, NULL, r, &err), BSIM_OK);
	long made = bsim_test_run_steps;
	bsim_trial_runner *fresh = bsim_trial_runner_alloc();
	assert_non_null(fresh);
	bsim_recorder rec = {.stride = 1, .trace = no_trace};
	assert_int_equal(bsim_trial_run(fresh, s, &counted, o, seed, &rec, r_step, &err), BSIM_OK);
	assert_int_equal(bsim_test_run_steps, made); /* the trace kept it on the step loop */
	bsim_trial_runner_free(fresh);
	return made;
}

static void assert_same_result(const bsim_trial_result *a, const bsim_trial_result *b)
{
	assert_int_equal(a->outcome, b->outcome);
	assert_int_equal(a->steps_run, b->steps_run);
	assert_int_equal(a->instability, b->instability);
	assert_memory_equal(a, b, sizeof *a);
}

/* The trials of a scene for seeds 1 .. n through one runner that keeps
 * its world, each against the trial stepped; the outcomes seen counted
 * into seen[], the steps made in runs returned. */
static long trials_both(const bsim_scene *s, const bsim_options *o, int n, int seen[5])
{
	bsim_trial_runner *runner = bsim_trial_runner_alloc();
	assert_non_null(runner);
	bsim_trial_runner_keep_worlds(runner, 1);
	long made = 0;
	for (int k = 1; k <= n; k++) {
		bsim_trial_result r, r_step;
		made += trial_both(s, o, (uint64_t)k, runner, &r, &r_step);
		assert_same_result(&r, &r_step);
		if (seen && r.outcome >= 0 && r.outcome < 5)
			seen[r.outcome]++;
	}
	bsim_trial_runner_free(runner);
	return made;
}

/* H1's propulsion and noise levels: traversals (run on to classify_y),
 * trials stuck to max_steps, side exits. */
static void test_runner_h1(void **state)
{
	(void)state;
	const double fp[] = {4, 6, 9}, rm[] = {0, 20, 40};
	int seen[5] = {0};
	long made = 0;
	bsim_options o = {0};
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++) {
			bsim_scene s;
			bsim_scene_init_gate(&s, fp[i], rm[j]);
			made += trials_both(&s, &o, 6, seen);
			bsim_scene_free(&s);
		}
	assert_true(made > 50000);
	assert_true(seen[BSIM_TRAVERSED] > 0);
	assert_true(seen[BSIM_STUCK] > 0);
	assert_true(seen[BSIM_SIDE_EXIT] > 0);
}

/* Trials that end inside a run (max_steps two steps into a hold of five),
 * one after another in one runner: the world a cut run leaves ahead is
 * reset for the next trial. */
static void test_runner_cut_runs(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 8.0, 30.0);
	s.max_steps = 1202;
	bsim_options o = {0};
	assert_true(trials_both(&s, &o, 10, NULL) > 5000);
	bsim_scene_free(&s);
}

/* Knobs, and six beams (the runs' general count). */
static void test_runner_worlds(void **state)
{
	(void)state;
	static const char *const knobs[] = {"integrator=euler", "projection=0", "impact_mass=0.1"};
	bsim_error err;
	for (size_t k = 0; k < sizeof knobs / sizeof knobs[0]; k++) {
		bsim_scene s;
		bsim_scene_init_gate(&s, 8.0, 20.0);
		bsim_options o = {0};
		assert_int_equal(bsim_options_add(&o, knobs[k], &err), BSIM_OK);
		assert_true(trials_both(&s, &o, 4, NULL) > 1000);
		bsim_scene_free(&s);
	}
	bsim_scene s;
	assert_int_equal(scene_six_beams(&s, 9.0, 30.0), BSIM_OK);
	s.success_y = 115.0;
	s.classify_y = 130.0;
	bsim_options o = {0};
	assert_true(trials_both(&s, &o, 4, NULL) > 1000);
	bsim_scene_free(&s);
}

/* The overflowing body of scene_gate_overflow below a beam that swings
 * (an awake beam keeps the trial off free flight, on the runs): the fifth
 * step, inside a run, is not finite; the trial ends unstable there, with
 * the same last finite state. */
static void test_runner_nonfinite(void **state)
{
	(void)state;
	bsim_scene s;
	scene_gate_overflow(&s);
	s.beams[0].initial_omega = 1.0;
	bsim_options o = {0};
	bsim_trial_runner *runner = bsim_trial_runner_alloc();
	assert_non_null(runner);
	bsim_trial_result r, r_step;
	long made = trial_both(&s, &o, 1, runner, &r, &r_step);
	assert_same_result(&r, &r_step);
	assert_int_equal(r.instability, BSIM_UNSTABLE_NONFINITE);
	assert_int_equal(r.unstable_step, 5);
	assert_true(made >= 5); /* made, not all kept: the world runs ahead */
	bsim_trial_runner_free(runner);
	bsim_scene_free(&s);
}

/* contact_mode=essay: the disk's runs decline; the runner's runs are the
 * step's one after another, the trial the step loop's to the bit. */
static void test_runner_declined(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 7.0, 20.0);
	bsim_options o = {0};
	bsim_error err;
	assert_int_equal(bsim_options_add(&o, "contact_mode=essay", &err), BSIM_OK);
	assert_true(trials_both(&s, &o, 2, NULL) > 1000);
	bsim_scene_free(&s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_h1_forces),
	        cmocka_unit_test(test_asymmetric),
	        cmocka_unit_test(test_impacts_and_starts),
	        cmocka_unit_test(test_six_beams),
	        cmocka_unit_test(test_knobs),
	        cmocka_unit_test(test_nonfinite),
	        cmocka_unit_test(test_declined),
	        cmocka_unit_test(test_runner_h1),
	        cmocka_unit_test(test_runner_cut_runs),
	        cmocka_unit_test(test_runner_worlds),
	        cmocka_unit_test(test_runner_nonfinite),
	        cmocka_unit_test(test_runner_declined),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
