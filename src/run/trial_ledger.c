/* The close of a trial's energy ledger and why a trial is unstable, in
 * words (trial.h bsim_instability): the energy tests at the end of a trial
 * (energy created, energy vanished),
 * which the finiteness test of each step (trial_ledger.h) precedes. */
#include "run/trial_ledger.h"

#include <stdio.h>

void bsim_trial_ledger_close(bsim_trial_result *out, double e_end, long n)
{
	out->ledger.e_end = e_end;
	const bsim_ledger *l = &out->ledger;
	if (out->instability)
		return;
	if (l->residual > BSIM_LEDGER_BOUND * l->inflow + BSIM_LEDGER_FLOOR) {
		out->instability = BSIM_UNSTABLE_ENERGY;
		out->unstable_step = (int)n;
	} else if (l->residual < -(BSIM_LEDGER_LOST_BOUND * l->inflow + BSIM_LEDGER_FLOOR)) {
		out->instability = BSIM_UNSTABLE_ENERGY_LOST;
		out->unstable_step = (int)n;
	}
}

void bsim_trial_instability_text(const bsim_trial_result *r, double dt, char *buf, size_t size)
{
	const bsim_ledger *l = &r->ledger;
	switch (r->instability) {
	case BSIM_UNSTABLE_NONFINITE:
		snprintf(buf, size, "non-finite state at step %d (t = %g s)", r->unstable_step,
		         r->unstable_step * dt);
		break;
	case BSIM_UNSTABLE_ENERGY:
		snprintf(buf, size,
		         "energy created: ledger residual %.3g J > %g x %.4g J that flowed in "
		         "(start %.4g J, end %.4g J)",
		         l->residual, BSIM_LEDGER_BOUND, l->inflow, l->e_start, l->e_end);
		break;
	case BSIM_UNSTABLE_ENERGY_LOST:
		snprintf(buf, size,
		         "energy vanished: ledger residual %.3g J < -%g x %.4g J that flowed in, "
		         "beyond the losses booked (start %.4g J, end %.4g J)",
		         l->residual, BSIM_LEDGER_LOST_BOUND, l->inflow, l->e_start, l->e_end);
		break;
	default:
		snprintf(buf, size, "%s", "");
	}
}
