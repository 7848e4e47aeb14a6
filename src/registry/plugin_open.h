/* Internal: a plug-in's library opened and its table checked
 * (beamsim/backend_plugin.h), before the registry adds it. */
#ifndef BSIM_REGISTRY_PLUGIN_OPEN_H
#define BSIM_REGISTRY_PLUGIN_OPEN_H

#include "beamsim/backend_plugin.h"

/* The longest name a backend may have, characters: the records and the
 * command line hold names in buffers of 32. */
#define REGISTRY_NAME_MAX 31

/* Opens the library at path and checks the table it exports: its interface
 * version and structure sizes, its name (REGISTRY_NAME_MAX characters at
 * most of letters, digits, '_' and '-', a letter first) and the fields
 * every backend fills. The table, or NULL with BSIM_EINPUT naming path and
 * the reason. The library stays open. */
const bsim_backend *bsim_registry_plugin_open(const char *path, bsim_error *err);

/* The checks of a table a process adds at run time (a plug-in's or a
 * binding's): its name and the fields every backend fills. BSIM_OK, or
 * BSIM_EINPUT "WHAT: ..." saying what is wrong. */
int bsim_registry_table_check(const bsim_backend *b, const char *what, bsim_error *err);

#endif
