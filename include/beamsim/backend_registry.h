/* The backend registry: the backends compiled in (src/registry/, a layer
 * above the backends and below the runner), then the plug-ins loaded at run
 * time (beamsim/backend_plugin.h). Everything above the backends
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

/* A backend's name on the command line that loads a plug-in:
 * "plugin:PATH" (bsim_backend_find). */
#define BSIM_PLUGIN_PREFIX "plugin:"

/* A comparison's side that is read, not run: "trials:PATH", the trials.csv
 * of the same experiment made elsewhere (beamsim/compare_dir.h). No backend
 * has this name; bsim_backend_find refuses it saying so. */
#define BSIM_TRIALS_PREFIX "trials:"

/* All backends, in the registry's order, NULL-terminated: those compiled
 * in, then the plug-ins loaded so far (those of BEAMSIM_PLUGINS first). */
BSIM_API const bsim_backend *const *bsim_backend_list(void);

/* The backend a run uses when none is named: the registry's first. */
BSIM_API const bsim_backend *bsim_backend_default(void);

/* By name, or "plugin:PATH" to load (once) and register the plug-in at
 * PATH (bsim_backend_load); NULL and BSIM_EINPUT naming the known ones if
 * unknown, the plug-in's refusal, or that of a plug-in of BEAMSIM_PLUGINS
 * (bsim_backend_plugins_status). err may be NULL. */
BSIM_API const bsim_backend *bsim_backend_find(const char *name, bsim_error *err);

/* The length of the backend's name at the start of a backend spec
 * "NAME[:KEY=VALUE]..." (compare's sides, run's --backend): up to the
 * first ':', or for "plugin:PATH[:KEY=VALUE]..." and "trials:PATH..." up
 * to the ':' after PATH (a path has no ':'). */
BSIM_API size_t bsim_backend_spec_name(const char *spec);

/* The options a backend spec gives after its name ("...:KEY=VALUE:..."),
 * added to opts in order (after those it holds, so they win):
 * BSIM_OK, or bsim_options_add's BSIM_EINPUT and message. */
BSIM_API int bsim_backend_spec_options(const char *spec, bsim_options *opts, bsim_error *err);

/* The backends a comparison runs when none are named (compare's sides,
 * the accuracy study, bench --vs): the default first, then every other
 * registered backend in the registry's order; the first max of them into
 * out. Returns how many (at most max). */
BSIM_API int bsim_backend_compared(const bsim_backend **out, int max);

#ifdef __cplusplus
}
#endif
#endif
