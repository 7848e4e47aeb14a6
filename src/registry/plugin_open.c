/* A plug-in's library opened and its table checked; see plugin_open.h. */
#include "registry/plugin_open.h"

#include <ctype.h>
#include <dlfcn.h>
#include <stdio.h>
#include <string.h>

/* Why table's name cannot be a backend's, or NULL. */
static const char *name_fault(const char *name)
{
	if (!name || !name[0])
		return "is empty";
	if (strlen(name) > REGISTRY_NAME_MAX)
		return "is longer than 31 characters";
	if (!isalpha((unsigned char)name[0]))
		return "does not start with a letter";
	for (const char *p = name; *p; p++)
		if (!isalnum((unsigned char)*p) && *p != '_' && *p != '-')
			return "has a character other than a letter, a digit, '_' or '-'";
	return NULL;
}

/* The first required field of b left empty, or a count without its array,
 * or NULL. */
static const char *field_fault(const bsim_backend *b)
{
	if (!b->create)
		return "create";
	if (!b->destroy)
		return "destroy";
	if (!b->advance)
		return "advance";
	if (!b->get_state)
		return "get_state";
	if (!b->set_state)
		return "set_state";
	if (b->n_knobs < 0 || (b->n_knobs > 0 && !b->knobs))
		return "knobs (n_knobs > 0 without them)";
	if (b->n_accuracy < 0 || (b->n_accuracy > 0 && !b->accuracy))
		return "accuracy (n_accuracy > 0 without them)";
	if (b->n_bounds < 0 || (b->n_bounds > 0 && !b->bounds))
		return "bounds (n_bounds > 0 without them)";
	for (int k = 0; k < b->n_knobs; k++)
		if (!b->knobs[k].name || !b->knobs[k].name[0])
			return "knobs (a knob without a name)";
	for (int k = 0; k < b->n_bounds; k++)
		if (!b->bounds[k].check || !(b->bounds[k].bound >= 0.0))
			return "bounds (a check without a name, or a bound not >= 0)";
	return NULL;
}

const bsim_backend *bsim_registry_plugin_open(const char *path, bsim_error *err)
{
	/* Bound now (RTLD_NOW): a symbol the plug-in needs and this process
	 * lacks is said here, not at its first step. */
	void *lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
	if (!lib) {
		const char *why = dlerror();
		bsim_error_set(err, BSIM_EINPUT, "plug-in %s: cannot be loaded: %s", path,
		               why ? why : "unknown reason");
		return NULL;
	}
	const bsim_backend_plugin *p = dlsym(lib, BSIM_PLUGIN_SYMBOL);
	if (!p) {
		bsim_error_set(err, BSIM_EINPUT,
		               "plug-in %s: exports no %s: not a beamsim backend plug-in (one of "
		               "its files declares BSIM_BACKEND_PLUGIN(table), beamsim/"
		               "backend_plugin.h)",
		               path, BSIM_PLUGIN_SYMBOL);
		return NULL;
	}
	if (p->abi != BSIM_BACKEND_ABI || p->backend_size != sizeof(bsim_backend) ||
	    p->state_size != sizeof(bsim_state)) {
		bsim_error_set(err, BSIM_EINPUT,
		               "plug-in %s: built against backend interface %d (tables of %zu "
		               "bytes, states of %zu), this beamsim has %d (%zu, %zu): rebuild it "
		               "with this beamsim's headers",
		               path, p->abi, p->backend_size, p->state_size, BSIM_BACKEND_ABI,
		               sizeof(bsim_backend), sizeof(bsim_state));
		return NULL;
	}
	const bsim_backend *b = p->backend;
	if (!b) {
		bsim_error_set(err, BSIM_EINPUT, "plug-in %s: its %s names no table", path,
		               BSIM_PLUGIN_SYMBOL);
		return NULL;
	}
	char what[1100];
	snprintf(what, sizeof what, "plug-in %s", path);
	return bsim_registry_table_check(b, what, err) == BSIM_OK ? b : NULL;
}

int bsim_registry_table_check(const bsim_backend *b, const char *what, bsim_error *err)
{
	const char *fault = name_fault(b->name);
	if (fault)
		return bsim_error_set(err, BSIM_EINPUT, "%s: the backend's name \"%s\" %s", what,
		                      b->name ? b->name : "", fault);
	if ((fault = field_fault(b)))
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: backend %s: field %s is empty (every backend fills "
		                      "name, create, destroy, advance, get_state and set_state, "
		                      "beamsim/backend.h)",
		                      what, b->name, fault);
	return BSIM_OK;
}
