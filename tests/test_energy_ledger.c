/* docs/model.md check 3: the energy ledger.
 *   E = KE_body + sum(1/2 I omega^2 + 1/2 k theta^2)
 * changes by exactly the work of F_prop and F_rand, less the dampers' and
 * the impacts' losses (and the contact and correction terms, which the
 * solver keeps near zero). In a conservative scene (e = 1, d = 0, no forces)
 * E itself is conserved. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>

#include <cmocka.h>

#include "beamsim/schedule.h"
#include "beamsim/trial.h"
#include "scenes.h"

static bsim_trial_result run(const bsim_scene *s, uint64_t seed)
{
	bsim_trial_runner *r = bsim_trial_runner_alloc();
	bsim_trial_result out;
	bsim_error err;
	assert_int_equal(bsim_trial_run(r, s, &bsim_backend_thesis, NULL, seed, NULL, &out, &err),
	                 BSIM_OK);
	bsim_trial_runner_free(r);
	return out;
}

/* The body is thrown obliquely into the gate with no force acting: several
 * elastic impacts with both beams, springs but no dampers. */
static void test_conservative_scene(void **state)
{
	(void)state;
	bsim_scene s;
	scene_gate_conservative(&s);
	s.max_steps = 3000;
	bsim_trial_result out = run(&s, 1);
	const bsim_ledger *l = &out.ledger;
	print_message("conservative: E %.6f -> %.6f J (drift %.2e), impact %.2e, contact %.2e, "
	              "correction %.2e, residual max %.2e J, peak theta %.3f\n",
	              l->e_start, l->e_end, l->e_end - l->e_start, l->impact, l->contact,
	              l->correction, l->residual_max, fmax(out.max_theta[0], out.max_theta[1]));
	assert_true(fmax(out.max_theta[0], out.max_theta[1]) > 0.3); /* the beams were hit */
	assert_true(l->w_prop == 0.0 && l->w_rand == 0.0 && l->damper == 0.0);
	assert_true(fabs(l->e_end - l->e_start) <= 1e-9 * l->e_start);
	assert_true(fabs(l->impact) <= 1e-9 * l->e_start);
	assert_true(l->residual_max <= 1e-10 * l->e_start);
	bsim_scene_free(&s);
}

/* The essay's gate, driven, damped and noisy: every joule is accounted for. */
static void test_driven_damped_noisy(void **state)
{
	(void)state;
	for (int trial = 0; trial < 10; trial++) {
		bsim_scene s;
		bsim_scene_init_gate(&s, 7.0, 20.0);
		bsim_trial_result out = run(&s, bsim_schedule_seed_mix(3, 0, (uint64_t)trial));
		const bsim_ledger *l = &out.ledger;
		double scale = fabs(l->w_prop) + fabs(l->w_rand) + l->damper + l->impact;
		double balance = (l->e_end - l->e_start) - (l->w_prop + l->w_rand - l->damper -
		                                            l->impact - l->contact - l->correction);
		if (trial == 0)
			print_message("driven: W_prop %.2f W_rand %.2f damper %.2f impact %.2f "
			              "contact %.2e correction %.2e, imbalance %.2e J\n",
			              l->w_prop, l->w_rand, l->damper, l->impact, l->contact,
			              l->correction, balance);
		assert_true(l->damper > 0.0 && l->impact > 0.0 && l->w_prop > 0.0);
		assert_true(fabs(balance) <= 1e-9 * scale);
		assert_true(l->residual_abs <= 1e-9 * scale);
		/* the numerical terms stay small beside the physical ones */
		assert_true(fabs(l->contact) + fabs(l->correction) <= 0.02 * scale);
		bsim_scene_free(&s);
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_conservative_scene),
	        cmocka_unit_test(test_driven_damped_noisy),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
