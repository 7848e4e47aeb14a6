/* The backend registry: the backends compiled in (src/registry/, a layer
 * above the backends and below the runner). Everything above the backends
 * reaches a backend through it, by name or in a loop over the list, never
 * by its table's symbol; adding a backend is its folder under backends/ and
 * one line of the registry (docs/architecture.md, "Where a new thing
 * goes"). */
#ifndef BSIM_BACKEND_REGISTRY_H
#define BSIM_BACKEND_REGISTRY_H

#include "beamsim/backend.h"

#ifdef __cplusplus
extern "C" {
#endif

/* All backends compiled in, in the registry's order, NULL-terminated. */
BSIM_API const bsim_backend *const *bsim_backend_list(void);

/* The backend a run uses when none is named: the registry's first. */
BSIM_API const bsim_backend *bsim_backend_default(void);

/* By name; NULL and BSIM_EINPUT naming the known ones if unknown. */
BSIM_API const bsim_backend *bsim_backend_find(const char *name, bsim_error *err);

/* The backends a comparison runs when none are named (compare's sides,
 * the accuracy study, bench --vs): the default first, then every other
 * registered backend in the registry's order; the first max of them into
 * out. Returns how many (at most max). */
BSIM_API int bsim_backend_compared(const bsim_backend **out, int max);

#ifdef __cplusplus
}
#endif
#endif
