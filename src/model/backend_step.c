/* One step of a world, through the one call that moves it, and that call
 * for a backend that makes its steps one by one (beamsim/backend.h). */
#include "beamsim/backend.h"

int bsim_backend_advance_each(bsim_world *w, bsim_step_fn step, bsim_get_state_fn get_state,
                              const bsim_wrench *schedule, double h, int n, bsim_state *out,
                              int *made, bsim_error *err)
{
	*made = 0;
	for (int k = 0; k < n; k++) {
		int rc = step(w, schedule[k].force, schedule[k].torque, h, err);
		if (rc)
			return rc;
		if (out)
			get_state(w, &out[k]);
		*made = k + 1;
	}
	return BSIM_OK;
}

int bsim_backend_step(const bsim_backend *b, bsim_world *w, const double force[2], double torque,
                      double h, bsim_error *err)
{
	const bsim_wrench one = {{force[0], force[1]}, torque};
	int made = 0;
	return b->advance(w, &one, h, 1, NULL, &made, err);
}
