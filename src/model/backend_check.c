/* A backend's check of a scene, said where the scene gave the field it
 * refuses (beamsim/backend.h); in the model, below the backends, which
 * call it (the registry is above them). */
#include "beamsim/backend.h"

#include <stdio.h>
#include <string.h>

#include "util/yaml_doc.h"
#include "util/yaml_override.h"

int bsim_backend_check(const bsim_backend *b, const bsim_options *opts, const bsim_scene *scene,
                       const char *path, const bsim_override *ov, int n_ov, bsim_error *err)
{
	char field[64] = "";
	if (!b->check || b->check(scene, opts, field, sizeof field, err) == BSIM_OK)
		return BSIM_OK;
	if (err->code != BSIM_EINPUT || !field[0])
		return err->code;
	char msg[sizeof err->msg];
	snprintf(msg, sizeof msg, "%s", err->msg);
	/* The scene document as it was built, overrides tagging the nodes
	 * they put there: the field's node, or the nearest block holding it
	 * (a field at its default, a beam of a lattice), says where. */
	ydoc d;
	bsim_error ignore;
	if (!path || !path[0] || bsim_ydoc_load(&d, path, &ignore) != BSIM_OK)
		return bsim_error_set(err, BSIM_EINPUT, "%s: %s", field, msg);
	struct fy_node *n = NULL;
	if (bsim_yov_apply(&d, ov, n_ov, &ignore) == BSIM_OK) {
		struct fy_node *root = fy_document_root(d.fyd);
		char key[sizeof field];
		snprintf(key, sizeof key, "%s", field);
		n = bsim_ydoc_lookup(root, key);
		for (char *dot; !n && (dot = strrchr(key, '.'));) {
			*dot = '\0';
			n = bsim_ydoc_lookup(root, key);
		}
		if (!n)
			n = root;
	}
	int rc = n ? bsim_ydoc_fail(&d, n, NULL, field, err, "%s", msg)
	           : bsim_error_set(err, BSIM_EINPUT, "%s: %s", field, msg);
	bsim_ydoc_free(&d);
	return rc;
}
