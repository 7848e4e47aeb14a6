/* The backend registry. */
#include "beamsim/backend.h"

#include <stdlib.h>
#include <string.h>

static const bsim_backend *const registry[] = {
        &bsim_backend_thesis,
        &bsim_backend_box2d,
        &bsim_backend_chipmunk,
        NULL,
};

const bsim_backend *const *bsim_backend_list(void)
{
	return registry;
}

const bsim_backend *bsim_backend_default(void)
{
	return &bsim_backend_thesis;
}

const bsim_backend *bsim_backend_find(const char *name, bsim_error *err)
{
	char known[256] = "";
	for (int i = 0; registry[i]; i++) {
		if (strcmp(registry[i]->name, name) == 0)
			return registry[i];
		if (i)
			strncat(known, ", ", sizeof known - strlen(known) - 1);
		strncat(known, registry[i]->name, sizeof known - strlen(known) - 1);
	}
	bsim_error_set(err, BSIM_EINPUT, "--backend %s: unknown backend (expected one of %s)", name,
	               known);
	return NULL;
}
