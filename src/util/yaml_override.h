/* Internal: applying "--set KEY=VALUE" overrides to a YAML document by
 * dotted path (docs/files.md "Command line"). */
#ifndef BSIM_UTIL_YAML_OVERRIDE_H
#define BSIM_UTIL_YAML_OVERRIDE_H

#include "util/yaml_doc.h"

/* Applies ov[0..n) in order (later ones win). Each value is YAML flow text;
 * it replaces the node at its key, or is inserted when the last key (or any
 * mapping on the way) is missing. The new nodes remember their override so
 * that later errors about them name its origin. A bad value, a list index
 * out of range or a path through a scalar is BSIM_EINPUT naming the
 * override. A document whose root is not a mapping is left alone (the
 * loader reports it). */
int bsim_yov_apply(ydoc *d, const bsim_override *ov, int n, bsim_error *err);

#endif
