/* docs/model.md check 3: the energy ledger, on every backend of the
 * registry.
 *   E = KE_body + sum(1/2 I omega^2 + 1/2 k theta^2)
 * changes by the work of F_prop and F_rand, less the dampers' and the
 * impacts' losses (and the contact and correction terms, which a solver
 * keeps small); what is left is the residual. In a conservative scene
 * (e = 1, d = 0, no forces) E itself is conserved. Each backend is held to
 * the bounds it states (bsim_backend.bounds): "ledger.drift" (|E_end -
 * E_start| / E_start, conservative), "ledger.elastic" (the impact and
 * contact terms over E_start there), "ledger.residual" (the sum of the
 * residuals' magnitudes over what flowed, driven; the largest residual over
 * E_start, conservative) and "ledger.numerical"
 * (the contact and correction terms over what flowed, driven). A
 * backend's own knobs (Box2D's torque spring, substeps) are checked in its
 * own tests. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>

#include <cmocka.h>

#include "beamsim/schedule.h"
#include "beamsim/trial.h"
#include "scenes.h"
#include "support.h"

static bsim_trial_result run(const bsim_backend *b, const bsim_scene *s, uint64_t seed)
{
	bsim_trial_runner *r = bsim_trial_runner_alloc();
	bsim_trial_result out;
	bsim_error err;
	int rc = bsim_trial_run(r, s, b, NULL, seed, NULL, &out, &err);
	if (rc)
		print_message("%s: %s\n", b->name, err.msg);
	assert_int_equal(rc, BSIM_OK);
	bsim_trial_runner_free(r);
	return out;
}

/* The body is thrown obliquely into the gate with no force acting: several
 * elastic impacts with both beams, springs but no dampers. */
static void test_conservative_scene(void **state)
{
	const bsim_backend *b = *state;
	double drift_bound = bsim_test_bound(b, "ledger.drift");
	double elastic_bound = bsim_test_bound(b, "ledger.elastic");
	double residual_bound = bsim_test_bound(b, "ledger.residual");
	bsim_scene s;
	scene_gate_conservative(&s);
	s.max_steps = 3000;
	bsim_trial_result out = run(b, &s, 1);
	const bsim_ledger *l = &out.ledger;
	double drift = (l->e_end - l->e_start) / l->e_start;
	double elastic = (fabs(l->impact) + fabs(l->contact)) / l->e_start;
	print_message("%s conservative: E %.6f -> %.6f J (drift %.2e of E, bound %.2g), impact "
	              "%.2e, contact %.2e J (%.2e of E, bound %.2g), correction %.2e, residual "
	              "max %.2e J, peak theta %.3f\n",
	              b->name, l->e_start, l->e_end, drift, drift_bound, l->impact, l->contact,
	              elastic, elastic_bound, l->correction, l->residual_max,
	              fmax(out.max_theta[0], out.max_theta[1]));
	assert_true(fmax(out.max_theta[0], out.max_theta[1]) > 0.3); /* the beams were hit */
	assert_true(l->w_prop == 0.0 && l->w_rand == 0.0 && l->damper == 0.0);
	assert_true(fabs(drift) <= drift_bound);
	assert_true(elastic <= elastic_bound);
	assert_true(l->residual_max <= residual_bound * l->e_start);
	bsim_scene_free(&s);
}

/* The essay's gate, driven, damped and noisy, 10 trials: the ledger's own
 * terms add up (the balance recomputed here from them is the residual it
 * reports), and the residual and the numerical terms stay within the
 * backend's bounds of what flowed. */
static void test_driven_damped_noisy(void **state)
{
	const bsim_backend *b = *state;
	double residual_bound = bsim_test_bound(b, "ledger.residual");
	double numerical_bound = bsim_test_bound(b, "ledger.numerical");
	double worst = 0.0, worst_numerical = 0.0;
	for (int trial = 0; trial < 10; trial++) {
		bsim_scene s;
		bsim_scene_init_gate(&s, 7.0, 20.0);
		bsim_trial_result out = run(b, &s, bsim_schedule_seed_mix(3, 0, (uint64_t)trial));
		const bsim_ledger *l = &out.ledger;
		double scale = fabs(l->w_prop) + fabs(l->w_rand) + l->damper + l->impact;
		double balance = (l->e_end - l->e_start) - (l->w_prop + l->w_rand - l->damper -
		                                            l->impact - l->contact - l->correction);
		if (trial == 0)
			print_message("%s driven: W_prop %.2f W_rand %.2f damper %.2f impact %.2f "
			              "contact %.2e correction %.2e, imbalance %.2e J, residual "
			              "%.2e J\n",
			              b->name, l->w_prop, l->w_rand, l->damper, l->impact,
			              l->contact, l->correction, balance, l->residual);
		assert_true(l->damper > 0.0 && l->impact > 0.0 && l->w_prop > 0.0);
		/* the ledger's arithmetic: what it reports is what its terms say */
		assert_true(fabs(balance - l->residual) <= 1e-9 * scale);
		worst = fmax(worst, l->residual_abs / scale);
		worst_numerical =
		        fmax(worst_numerical, (fabs(l->contact) + fabs(l->correction)) / scale);
		bsim_scene_free(&s);
	}
	print_message("%s driven, worst of 10: sum of |residual| %.2e of what flowed (bound %.2g), "
	              "contact and correction %.2e (bound %.2g)\n",
	              b->name, worst, residual_bound, worst_numerical, numerical_bound);
	assert_true(worst <= residual_bound);
	assert_true(worst_numerical <= numerical_bound);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_conservative_scene),
	        cmocka_unit_test(test_driven_damped_noisy),
	};
	return bsim_test_run_per_backend("energy_ledger", tests, sizeof tests / sizeof tests[0]);
}
