/* The backend registry; see beamsim/backend_registry.h and, for the
 * plug-ins it adds at run time, beamsim/backend_plugin.h. */
#define _XOPEN_SOURCE 700 /* realpath */
#include "beamsim/backend_registry.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "registry/plugin_open.h"

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

/* Room for the plug-ins a process loads. */
#define REGISTRY_MAX 64

/* The built-in backends, then the plug-ins in the order they loaded; NULL
 * after the last. A plug-in is added under the lock and only ever appended
 * (the NULL after it is there already), so a reader that walks the list
 * without the lock sees it whole or not at all. */
static const bsim_backend *registry[REGISTRY_MAX + 1] = {BSIM_BACKENDS(BSIM_BACKEND_ENTRY) NULL};
/* The absolute path of each entry's library (NULL: compiled in). */
static char *registry_path[REGISTRY_MAX];
static pthread_mutex_t registry_lock = PTHREAD_MUTEX_INITIALIZER;

/* BEAMSIM_PLUGINS, loaded once: the first refusal, if any. */
static pthread_once_t env_once = PTHREAD_ONCE_INIT;
static bsim_error env_error;
static int env_rc = BSIM_OK;

static int registry_count(void)
{
	int n = 0;
	while (registry[n])
		n++;
	return n;
}

/* The table registered under name, or NULL. */
static const bsim_backend *registry_named(const char *name)
{
	for (int i = 0; registry[i]; i++)
		if (strcmp(registry[i]->name, name) == 0)
			return registry[i];
	return NULL;
}

/* Adds b, checked, to the registry (once: b again is b), the caller
 * holding the lock; what names it in errors, path its library (NULL: none). */
static const bsim_backend *add_locked(const bsim_backend *b, const char *what, const char *path,
                                      bsim_error *err)
{
	const bsim_backend *same = registry_named(b->name);
	if (same == b)
		return b; /* added before */
	if (same) {
		bsim_error_set(err, BSIM_EINPUT,
		               "%s: a backend named %s is registered already (each backend's name "
		               "is its own)",
		               what, b->name);
		return NULL;
	}
	int n = registry_count();
	if (n == REGISTRY_MAX) {
		bsim_error_set(err, BSIM_EFAIL, "%s: more than %d backends", what, REGISTRY_MAX);
		return NULL;
	}
	registry_path[n] = path ? realpath(path, NULL) : NULL;
	__atomic_store_n(&registry[n], b, __ATOMIC_RELEASE);
	return b;
}

/* Loads path's plug-in and registers it (bsim_backend_load), the caller
 * holding the lock. */
static const bsim_backend *load_locked(const char *path, bsim_error *err)
{
	const bsim_backend *b = bsim_registry_plugin_open(path, err);
	if (!b)
		return NULL;
	char what[4200];
	snprintf(what, sizeof what, "plug-in %s", path);
	return add_locked(b, what, path, err);
}

static void env_load(void)
{
	const char *list = getenv(BSIM_PLUGINS_ENV);
	if (!list)
		return;
	pthread_mutex_lock(&registry_lock);
	for (const char *p = list; *p;) {
		size_t len = strcspn(p, ":");
		if (len > 0) {
			char path[4096];
			if (len >= sizeof path) {
				env_rc = bsim_error_set(&env_error, BSIM_EINPUT,
				                        "%s: a path longer than %zu characters",
				                        BSIM_PLUGINS_ENV, sizeof path - 1);
				break;
			}
			memcpy(path, p, len);
			path[len] = '\0';
			bsim_error e;
			if (!load_locked(path, &e)) {
				env_rc = bsim_error_set(&env_error, BSIM_EINPUT, "%s: %s",
				                        BSIM_PLUGINS_ENV, e.msg);
				break;
			}
		}
		p += len + (p[len] == ':');
	}
	pthread_mutex_unlock(&registry_lock);
}

static void env_ensure(void)
{
	pthread_once(&env_once, env_load);
}

int bsim_backend_plugins_status(bsim_error *err)
{
	env_ensure();
	if (env_rc != BSIM_OK && err)
		*err = env_error;
	return env_rc;
}

const bsim_backend *bsim_backend_load(const char *path, bsim_error *err)
{
	env_ensure();
	pthread_mutex_lock(&registry_lock);
	const bsim_backend *b = load_locked(path, err);
	pthread_mutex_unlock(&registry_lock);
	return b;
}

const bsim_backend *bsim_backend_register(const bsim_backend *b, bsim_error *err)
{
	env_ensure();
	char what[64];
	snprintf(what, sizeof what, "backend %.40s", b->name ? b->name : "");
	if (bsim_registry_table_check(b, what, err) != BSIM_OK)
		return NULL;
	pthread_mutex_lock(&registry_lock);
	const bsim_backend *r = add_locked(b, what, NULL, err);
	pthread_mutex_unlock(&registry_lock);
	return r;
}

const char *bsim_backend_plugin_path(const bsim_backend *b)
{
	env_ensure();
	for (int i = 0; registry[i]; i++)
		if (registry[i] == b)
			return registry_path[i];
	return NULL;
}

const bsim_backend *const *bsim_backend_list(void)
{
	env_ensure();
	return registry;
}

const bsim_backend *bsim_backend_default(void)
{
	return registry[0];
}

size_t bsim_backend_spec_name(const char *spec)
{
	/* A path follows these: the name runs to the ':' after it. */
	static const char *const prefixed[] = {BSIM_PLUGIN_PREFIX, BSIM_TRIALS_PREFIX};
	for (int i = 0; i < 2; i++) {
		size_t n = strlen(prefixed[i]);
		if (strncmp(spec, prefixed[i], n) == 0)
			return n + strcspn(spec + n, ":");
	}
	return strcspn(spec, ":");
}

int bsim_backend_spec_options(const char *spec, bsim_options *opts, bsim_error *err)
{
	for (const char *p = spec + bsim_backend_spec_name(spec); *p == ':';) {
		size_t len = strcspn(p + 1, ":");
		char kv[128];
		snprintf(kv, sizeof kv, "%.*s", (int)(len < sizeof kv ? len : sizeof kv - 1),
		         p + 1);
		if (bsim_options_add(opts, kv, err) != BSIM_OK)
			return BSIM_EINPUT;
		p += len + 1;
	}
	return BSIM_OK;
}

const bsim_backend *bsim_backend_find(const char *name, bsim_error *err)
{
	bsim_error e;
	if (bsim_backend_plugins_status(&e) != BSIM_OK) {
		if (err)
			*err = e;
		return NULL;
	}
	static const char plugin[] = BSIM_PLUGIN_PREFIX;
	if (strncmp(name, plugin, strlen(plugin)) == 0) {
		const bsim_backend *b = bsim_backend_load(name + strlen(plugin), &e);
		if (!b && err)
			bsim_error_set(err, e.code, "--backend %s: %s", name, e.msg);
		return b;
	}
	if (strncmp(name, BSIM_TRIALS_PREFIX, strlen(BSIM_TRIALS_PREFIX)) == 0) {
		bsim_error_set(err, BSIM_EINPUT,
		               "--backend %s: a side of beamsim compare read from trials made "
		               "elsewhere (--backends A," BSIM_TRIALS_PREFIX "PATH), not a backend "
		               "that runs",
		               name);
		return NULL;
	}
	const bsim_backend *b = registry_named(name);
	if (b)
		return b;
	char known[512] = "";
	for (int i = 0; registry[i]; i++) {
		if (i)
			strncat(known, ", ", sizeof known - strlen(known) - 1);
		strncat(known, registry[i]->name, sizeof known - strlen(known) - 1);
	}
	bsim_error_set(err, BSIM_EINPUT,
	               "--backend %s: unknown backend (expected one of %s, or " BSIM_PLUGIN_PREFIX
	               "PATH of a plug-in; a plug-in's backend is found by its name when %s "
	               "lists its library)",
	               name, known, BSIM_PLUGINS_ENV);
	return NULL;
}

int bsim_backend_compared(const bsim_backend **out, int max)
{
	/* The default is the registry's first, so the registry's order is
	 * already the default followed by every other backend. */
	env_ensure();
	int n = 0;
	for (; n < max && registry[n]; n++)
		out[n] = registry[n];
	return n;
}
