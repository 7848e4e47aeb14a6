/* A stored run's directory read (store/stored_run.h). The scene of
 * `beamsim run --out DIR` is the scene file the run copied to
 * DIR/inputs/scene.yaml with the --set overrides run.json records, applied
 * in their order as the run applied them. */
#define _POSIX_C_SOURCE 200809L
#include "store/stored_run.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "beamsim/compare_dir.h"
#include "beamsim/limits.h"
#include "util/yaml_doc.h"

void bsim_compare_dir_label(const char *label, char *buf, size_t size)
{
	size_t k = 0;
	for (; *label && k + 1 < size; label++)
		buf[k++] = *label == ':' || *label == '/' ? '-' : *label;
	if (size > 0)
		buf[k] = '\0';
}

void bsim_run_scene_free(bsim_run_scene *rs)
{
	for (int i = 0; i < rs->n_sets; i++) {
		free(rs->keys[i]);
		free(rs->values[i]);
	}
	free(rs->keys);
	free(rs->values);
	bsim_scene_free(&rs->scene);
	memset(rs, 0, sizeof *rs);
}

/* The text of root's scalar name into buf (32 bytes), "" if none. */
static void record_text(struct fy_node *root, const char *name, char *buf)
{
	struct fy_node *n = bsim_ydoc_lookup(root, name);
	size_t len = 0;
	const char *t = n && fy_node_is_scalar(n) ? fy_node_get_scalar(n, &len) : "";
	snprintf(buf, 32, "%.*s", (int)(len < 31 ? len : 31), t ? t : "");
}

static long record_long(struct fy_node *root, const char *name)
{
	long long v = 0;
	struct fy_node *n = bsim_ydoc_lookup(root, name);
	return n && bsim_ydoc_int64(n, &v) ? (long)v : 0;
}

int bsim_run_scene_load(const char *dir, bsim_run_scene *rs, int *found, bsim_error *err)
{
	char path[BSIM_PATH_MAX], scene_path[BSIM_PATH_MAX];
	memset(rs, 0, sizeof *rs);
	snprintf(path, sizeof path, "%s/run.json", dir);
	snprintf(scene_path, sizeof scene_path, "%s/inputs/scene.yaml", dir);
	struct stat st;
	*found = stat(path, &st) == 0 && stat(scene_path, &st) == 0;
	if (!*found)
		return BSIM_OK;
	ydoc d;
	int rc = bsim_ydoc_load_own(&d, path, err);
	if (rc)
		return rc;
	struct fy_node *root = fy_document_root(d.fyd);
	struct fy_node *set = bsim_ydoc_lookup(root, "set");
	record_text(root, "outcome", rs->outcome);
	record_text(root, "type", rs->type);
	record_text(root, "backend", rs->backend);
	rs->group = record_long(root, "group");
	rs->trial = record_long(root, "trial");
	int n = set && fy_node_is_mapping(set) ? fy_node_mapping_item_count(set) : 0;
	bsim_override *ov = calloc((size_t)n + 1, sizeof *ov);
	rs->keys = calloc((size_t)n + 1, sizeof *rs->keys);
	rs->values = calloc((size_t)n + 1, sizeof *rs->values);
	if (!ov || !rs->keys || !rs->values)
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	else
		rs->n_sets = n;
	void *it = NULL;
	struct fy_node_pair *p;
	for (int i = 0; !rc && i < n && (p = fy_node_mapping_iterate(set, &it)); i++) {
		char **text[2] = {&rs->keys[i], &rs->values[i]};
		for (int k = 0; k < 2; k++) {
			struct fy_node *sn = k ? fy_node_pair_value(p) : fy_node_pair_key(p);
			size_t len = 0;
			const char *t =
			        sn && fy_node_is_scalar(sn) ? fy_node_get_scalar(sn, &len) : NULL;
			*text[k] = t ? strndup(t, len) : NULL;
		}
		if (!rs->keys[i] || !rs->values[i])
			rc = bsim_ydoc_expected(&d, fy_node_pair_value(p), set, "set",
			                        "a mapping of KEY: VALUE strings", err);
		ov[i] = (bsim_override){rs->keys[i], rs->values[i], path};
	}
	if (!rc)
		rc = bsim_scene_load(scene_path, ov, n, &rs->scene, err);
	free(ov);
	bsim_ydoc_free(&d);
	if (rc) {
		/* the scene is not loaded: only the texts to free */
		for (int i = 0; i < rs->n_sets; i++) {
			free(rs->keys[i]);
			free(rs->values[i]);
		}
		free(rs->keys);
		free(rs->values);
		memset(rs, 0, sizeof *rs);
	}
	return rc;
}
