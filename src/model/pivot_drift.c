/* How far a backend's joints let the beams drift from their pivots
 * (beamsim/backend.h, bsim_backend_pivot_drift), from the pinned points a
 * state reports. */
#include <math.h>

#include "beamsim/backend.h"

double bsim_backend_pivot_drift(const bsim_backend *b, const bsim_scene *scene, const bsim_state *s)
{
	double drift = 0.0;
	if (b->exact_pins)
		return drift;
	for (int k = 0; k < s->n_active; k++) {
		const int i = s->active[k];
		const double *p = scene->beams[i].pivot;
		drift = fmax(drift, hypot(s->pin[2 * i] - p[0], s->pin[2 * i + 1] - p[1]));
	}
	return drift;
}
