/* The bounds a backend states for the checks every backend runs
 * (beamsim/backend.h, bsim_backend_bound). */
#include "beamsim/backend.h"

#include <string.h>

int bsim_backend_bound_of(const bsim_backend *b, const char *check, double *bound)
{
	for (int i = 0; i < b->n_bounds; i++)
		if (strcmp(b->bounds[i].check, check) == 0) {
			*bound = b->bounds[i].bound;
			return 1;
		}
	return 0;
}
