/* One step of a world, through the one call that moves it, and that call
 * for a backend that makes its steps one by one (beamsim/backend.h). */
#include "beamsim/backend.h"

int bsim_backend_advance_each(bsim_world *w, bsim_step_fn step, bsim_get_state_fn get_state,
                              const double force[2], double torque, double h, int n,
                              bsim_state *out, int *made, bsim_error *err)
{
	*made = 0;
	for (int k = 0; k < n; k++) {
		int rc = step(w, force, torque, h, err);
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
	int made = 0;
	return b->advance(w, force, torque, h, 1, NULL, &made, err);
}
