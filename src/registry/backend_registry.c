/* The backend registry; see beamsim/backend_registry.h. */
#include "beamsim/backend_registry.h"

#include <string.h>

/* The backends compiled in, one line each, X(NAME) for the table
 * bsim_backend_NAME that backends/NAME/ defines; `beamsim backends` lists
 * them in this order and the first is the default (the essay's solver). A
 * new backend adds its line here and nothing else outside its folder. */
#define BSIM_BACKENDS(X)                                                                           \
	X(thesis)                                                                                  \
	X(box2d)                                                                                   \
	X(chipmunk)

#define BSIM_BACKEND_DECLARE(name) extern const bsim_backend bsim_backend_##name;
#define BSIM_BACKEND_ENTRY(name)   &bsim_backend_##name,

BSIM_BACKENDS(BSIM_BACKEND_DECLARE)

static const bsim_backend *const registry[] = {BSIM_BACKENDS(BSIM_BACKEND_ENTRY) NULL};

const bsim_backend *const *bsim_backend_list(void)
{
	return registry;
}

const bsim_backend *bsim_backend_default(void)
{
	return registry[0];
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

int bsim_backend_compared(const bsim_backend **out, int max)
{
	/* The default is the registry's first, so the registry's order is
	 * already the default followed by every other backend. */
	int n = 0;
	for (; n < max && registry[n]; n++)
		out[n] = registry[n];
	return n;
}
