/* A backend from outside the tree: a shared library (a plug-in) that
 * defines a bsim_backend table (beamsim/backend.h) and exports it with
 * BSIM_BACKEND_PLUGIN, loaded at run time (docs/backends.md, "Your own
 * solver"):
 *   - by a command's --backend plugin:PATH.so[:KEY=VALUE]..., or a compare
 *     side of that form (bsim_backend_find takes "plugin:PATH");
 *   - for every command and binding of a process, from the paths in the
 *     environment variable BEAMSIM_PLUGINS (separated by ':'), read when
 *     the registry is first used; such a backend is then listed, found and
 *     compared by its own name like a built-in one.
 *
 * A plug-in's table is checked when it loads: the interface version it was
 * built against, the sizes of the structures it shares, the fields every
 * backend fills and a name no other backend has; a library that fails is
 * refused with the file and the reason. A plug-in stays loaded until the
 * process ends. It may call any function of libbeamsim (the helpers of
 * beamsim/backend.h, beamsim/contact_flag.h, beamsim/body_shape.h), linking
 * libbeamsim.so. */
#ifndef BSIM_BACKEND_PLUGIN_H
#define BSIM_BACKEND_PLUGIN_H

#include <stddef.h>

#include "beamsim/backend.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The version of the backend interface: of bsim_backend, bsim_state and
 * what they hold. It changes whenever their layout or meaning does, and a
 * plug-in built against another is refused. */
#define BSIM_BACKEND_ABI 2 /* 2: advance takes a schedule of wrenches */

/* The environment variable of the plug-ins every command loads. */
#define BSIM_PLUGINS_ENV "BEAMSIM_PLUGINS"

/* What a plug-in exports, under the name BSIM_PLUGIN_SYMBOL. */
typedef struct bsim_backend_plugin {
	int abi;             /* BSIM_BACKEND_ABI of the headers it was built with */
	size_t backend_size; /* sizeof(bsim_backend) there */
	size_t state_size;   /* sizeof(bsim_state) there */
	const bsim_backend *backend;
} bsim_backend_plugin;

#define BSIM_PLUGIN_SYMBOL "bsim_plugin"

#if defined(_WIN32)
#define BSIM_PLUGIN_EXPORT __declspec(dllexport)
#elif defined(__GNUC__)
#define BSIM_PLUGIN_EXPORT __attribute__((visibility("default")))
#else
#define BSIM_PLUGIN_EXPORT
#endif

/* In one file of a plug-in, at file scope: exports table (a bsim_backend)
 * as the plug-in's backend. */
#define BSIM_BACKEND_PLUGIN(table)                                                                 \
	BSIM_PLUGIN_EXPORT extern const bsim_backend_plugin bsim_plugin;                           \
	const bsim_backend_plugin bsim_plugin = {BSIM_BACKEND_ABI, sizeof(bsim_backend),           \
	                                         sizeof(bsim_state), &(table)}

/* Loads the plug-in at path (once: the same file again gives the same
 * table), checks its table and adds it to the registry, listed after the
 * backends before it. NULL and BSIM_EINPUT naming path and what is wrong
 * if it is not a loadable library, exports no BSIM_PLUGIN_SYMBOL, was built
 * against another interface, leaves a required field empty, or has a name
 * another backend has; BSIM_EFAIL if the registry is full. */
BSIM_API const bsim_backend *bsim_backend_load(const char *path, bsim_error *err);

/* Adds a table the program made itself (a binding's backend written in
 * Python, docs/bindings.md) to the registry, checked as a plug-in's is
 * (its name, the required fields); b must outlive its use. b again gives
 * b; NULL and BSIM_EINPUT if it fails a check or its name is taken. */
BSIM_API const bsim_backend *bsim_backend_register(const bsim_backend *b, bsim_error *err);

/* The absolute path of the library plug-in b was loaded from, for the
 * records of a run (run.json's backends.N.plugin, which beamsim regress
 * loads again); NULL for a backend compiled in. */
BSIM_API const char *bsim_backend_plugin_path(const bsim_backend *b);

/* What loading the plug-ins of BEAMSIM_PLUGINS gave: BSIM_OK (also when
 * the variable is unset or empty), or the first refusal (BSIM_EINPUT,
 * naming the variable and the file). bsim_backend_find fails with it too,
 * so that a plug-in asked for is never silently missing. */
BSIM_API int bsim_backend_plugins_status(bsim_error *err);

#ifdef __cplusplus
}
#endif
#endif
