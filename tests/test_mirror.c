/* docs/model.md check 4, on every backend of the registry: a scene mirrored
 * in x, run with the random force negated, gives the mirrored trajectory.
 * The gate is made asymmetric (k1 = 300, k2 = 500) so that the mirror is a
 * different scene. How close the image stays is the backend's bound
 * (bsim_backend.bounds, m for positions, rad for the beams' angles times
 * their length), 0 meaning bit for bit: "mirror.free.disk" before the first
 * contact, "mirror.contact.disk" over the first second of contact,
 * "mirror.trial.disk" over the whole run and, through the runner, for the
 * trials' ends. A backend whose images part in contact (Box2D solves the
 * beams' rows in creation order, which the mirror swaps, and rounds in
 * float32; repeated impacts then grow the difference) states no whole-run
 * bound, and the whole-run checks are skipped for it, saying so. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "beamsim/contact_flag.h"
#include "beamsim/schedule.h"
#include "beamsim/trial.h"
#include "scenes.h"
#include "support.h"

static void asymmetric_gate(bsim_scene *s, double f_prop, double rm)
{
	bsim_scene_init_gate(s, f_prop, rm);
	s->beams[0].stiffness = 300.0;
	s->beams[1].stiffness = 500.0;
	s->body.start[0] = 1.5;
}

/* Steps both worlds with mirrored forces and compares every step: the
 * departure from the mirror image (position, and the beams' angles as
 * tip displacements; where the bound is 0, the velocities too, to the
 * bit), and the contact flags exchanged. */
static void test_mirror_steps(void **state)
{
	const bsim_backend *be = *state;
	double free_bound = bsim_test_bound(be, "mirror.free.disk");
	double contact_bound = bsim_test_bound(be, "mirror.contact.disk");
	double trial_bound;
	int whole = bsim_backend_bound_of(be, "mirror.trial.disk", &trial_bound);
	bsim_scene a, b;
	asymmetric_gate(&a, 8.0, 30.0);
	scene_mirror(&a, &b);
	bsim_world *wa = bsim_test_world(be, &a, NULL), *wb = bsim_test_world(be, &b, NULL);
	bsim_schedule *sched = bsim_schedule_alloc(30.0, 50.0, bsim_schedule_seed_mix(5, 0, 0));
	bsim_state sa, sb;
	bsim_state_init(&sa, 2);
	bsim_state_init(&sb, 2);
	double dev_free = 0.0, dev_contact = 0.0, dev_all = 0.0;
	double vel_free = 0.0, vel_contact = 0.0, vel_all = 0.0;
	int contact_steps = 0, first_contact = -1, flags_differ = 0;
	for (long n = 0; n < 3000; n++) {
		double fr = bsim_schedule_value(sched, bsim_schedule_index(sched, n, a.dt));
		const double fa[2] = {fr, 8.0}, fb[2] = {-fr, 8.0};
		assert_int_equal(bsim_backend_step(be, wa, fa, 0.0, a.dt, NULL), BSIM_OK);
		assert_int_equal(bsim_backend_step(be, wb, fb, 0.0, b.dt, NULL), BSIM_OK);
		be->get_state(wa, &sa);
		bsim_contact_flags(&a, &sa);
		be->get_state(wb, &sb);
		bsim_contact_flags(&b, &sb);
		double dev = fmax(fmax(fabs(sa.x[0] + sb.x[0]), fabs(sa.x[1] - sb.x[1])),
		                  fmax(fabs(sa.theta[0] - sb.theta[1]) * 25.0,
		                       fabs(sa.theta[1] - sb.theta[0]) * 25.0));
		double vel = fmax(
		        fmax(fabs(sa.v[0] + sb.v[0]), fabs(sa.v[1] - sb.v[1])),
		        fmax(fabs(sa.omega[0] - sb.omega[1]), fabs(sa.omega[1] - sb.omega[0])));
		flags_differ += sa.contact[0] != sb.contact[1] || sa.contact[1] != sb.contact[0];
		int touching = sa.contact[0] || sa.contact[1];
		if (touching && first_contact < 0)
			first_contact = (int)n;
		contact_steps += touching;
		if (first_contact < 0) {
			dev_free = fmax(dev_free, dev);
			vel_free = fmax(vel_free, vel);
		} else if (n < first_contact + 250) {
			dev_contact = fmax(dev_contact, dev);
			vel_contact = fmax(vel_contact, vel);
		}
		dev_all = fmax(dev_all, dev);
		vel_all = fmax(vel_all, vel);
	}
	print_message("%s mirror: max departure %.2e before contact (bound %.2g), %.2e in the "
	              "first second of contact (bound %.2g), %.2e over 12 s; %d contact steps, "
	              "%d with flags not exchanged\n",
	              be->name, dev_free, free_bound, dev_contact, contact_bound, dev_all,
	              contact_steps, flags_differ);
	assert_true(contact_steps > 100); /* the comparison covered contact */
	assert_true(dev_free <= free_bound && (free_bound > 0.0 || vel_free == 0.0));
	assert_true(dev_contact <= contact_bound && (contact_bound > 0.0 || vel_contact == 0.0));
	if (whole) {
		assert_true(dev_all <= trial_bound);
		if (trial_bound == 0.0) {
			assert_true(vel_all == 0.0);
			assert_int_equal(flags_differ, 0);
		}
	} else {
		print_message("%s: the whole run not checked: it states no bound "
		              "mirror.trial.disk\n",
		              be->name);
	}
	bsim_schedule_free(sched);
	bsim_state_free(&sa);
	bsim_state_free(&sb);
	be->destroy(wa);
	be->destroy(wb);
	bsim_scene_free(&a);
	bsim_scene_free(&b);
}

/* Through the runner: a negative magnitude negates the schedule; outcomes
 * and steps match, left and right types swap, the end state mirrors
 * within the whole-run bound (exactly where it is 0). */
static void test_mirror_trials(void **state)
{
	const bsim_backend *be = *state;
	double bound = bsim_test_bound(be, "mirror.trial.disk");
	bsim_trial_runner *r = bsim_trial_runner_alloc();
	int traversed = 0;
	double worst = 0.0;
	for (int t = 0; t < 40; t++) {
		bsim_scene a, b;
		asymmetric_gate(&a, 8.0, 30.0);
		scene_mirror(&a, &b);
		b.effects.random_magnitude = -a.effects.random_magnitude;
		bsim_trial_result ra, rb;
		bsim_error err;
		uint64_t seed = bsim_schedule_seed_mix(9, 1, (uint64_t)t);
		assert_int_equal(bsim_trial_run(r, &a, be, NULL, seed, NULL, &ra, &err), BSIM_OK);
		assert_int_equal(bsim_trial_run(r, &b, be, NULL, seed, NULL, &rb, &err), BSIM_OK);
		assert_int_equal(ra.outcome, rb.outcome);
		assert_int_equal(ra.steps, rb.steps);
		worst = fmax(worst, fmax(fabs(ra.x_end + rb.x_end), fabs(ra.vx_end + rb.vx_end)));
		worst = fmax(worst, fabs(ra.max_theta[0] - rb.max_theta[1]) * 25.0);
		if (ra.outcome == BSIM_TRAVERSED) {
			traversed++;
			assert_int_equal(ra.type == BSIM_TYPE_LEFT, rb.type == BSIM_TYPE_RIGHT);
		}
		bsim_scene_free(&a);
		bsim_scene_free(&b);
	}
	print_message("%s mirror: %d of 40 trials traversed; the ends depart by at most %.2e "
	              "(bound %.2g)\n",
	              be->name, traversed, worst, bound);
	assert_true(worst <= bound);
	bsim_trial_runner_free(r);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_mirror_steps),
	        cmocka_unit_test(test_mirror_trials),
	};
	return bsim_test_run_per_backend("mirror", tests, sizeof tests / sizeof tests[0]);
}
