/* The record of a run for beamsim regress (beamsim/run_record.h).
 *
 * The stored experiment is regenerated from the loaded one rather than
 * copied: its `scene:` must name the copied scene, and the command line's
 * --set overrides, applied after `set:` and before the grid, become the
 * last entries of `set:`, which is where they act; its --grid axes are
 * in `grid:`, where they replaced or joined the file's. run.json is JSON, which
 * is YAML, so it reads back through libfyaml like every other input. */
#define _POSIX_C_SOURCE 200809L

#include "beamsim/run_record.h"

#include <inttypes.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "util/atomic_file.h"
#include "util/file_read.h"
#include "util/json.h"
#include "beamsim/backend_plugin.h"
#include "beamsim/backend_registry.h"
#include "beamsim/limits.h"
#include "beamsim/output.h"
#include "beamsim/version.h"
#include "util/yaml_doc.h"
#include "store/compare_read.h"

void bsim_run_record_fill(bsim_run_record *rec, const char *command, const bsim_experiment *e,
                          int n, const bsim_backend *const *b, const bsim_options *const *opts,
                          const char *const *label, const bsim_compare_rule *rule)
{
	memset(rec, 0, sizeof *rec);
	snprintf(rec->command, sizeof rec->command, "%s", command);
	rec->n_backends = n;
	for (int i = 0; i < n; i++) {
		snprintf(rec->backend[i], sizeof rec->backend[i], "%s", b[i]->name);
		snprintf(rec->label[i], sizeof rec->label[i], "%s", label ? label[i] : b[i]->name);
		const char *lib = bsim_backend_plugin_path(b[i]);
		snprintf(rec->plugin[i], sizeof rec->plugin[i], "%s", lib ? lib : "");
		bsim_options_effective(b[i]->knobs, b[i]->n_knobs, opts[i], &rec->opts[i]);
	}
	rec->seed = e->seed;
	rec->trials = e->trials;
	rec->rule = rule ? *rule : bsim_compare_rule_default();
}

static int path_join(char *buf, size_t size, const char *dir, const char *name, bsim_error *err)
{
	int n = snprintf(buf, size, "%s/%s", dir, name);
	if (n < 0 || (size_t)n >= size)
		return bsim_error_set(err, BSIM_EFAIL, "%s/%s: path too long", dir, name);
	return BSIM_OK;
}

/* The experiment as it ran, without a word about where it came from. */
static void experiment_body(FILE *f, const bsim_experiment *e, const bsim_override *extra,
                            int n_extra)
{
	fprintf(f, "scene: scene.yaml\ntrials: %d\nseed: %" PRIu64 "\n", e->trials, e->seed);
	if (e->n_set + n_extra > 0)
		fputs("set:\n", f);
	for (int i = 0; i < e->n_set; i++)
		fprintf(f, "  %s: %s\n", e->set[i].key, e->set[i].value);
	for (int i = 0; i < n_extra; i++)
		fprintf(f, "  %s: %s  # %s\n", extra[i].key, extra[i].value, extra[i].origin);
	fputs("grid:\n", f);
	for (int a = 0; a < e->n_axes; a++) {
		fprintf(f, "  %s: [", e->axes[a].key);
		for (int i = 0; i < e->axes[a].n_values; i++)
			fprintf(f, "%s%s", i ? ", " : "", e->axes[a].values[i]);
		/* an axis of the command line says so, as a --set does */
		const char *origin = e->axes[a].origin;
		if (!origin || strncmp(origin, "--", 2) == 0) {
			char where[256];
			bsim_experiment_axis_origin(&e->axes[a], where, sizeof where);
			fprintf(f, "]  # %s\n", where);
		} else {
			fputs("]\n", f);
		}
	}
}

static int write_experiment(const char *path, const bsim_experiment *e, const bsim_override *extra,
                            int n_extra, bsim_error *err)
{
	bsim_atomic_file o;
	if (bsim_atomic_file_open(&o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	fprintf(o.f, "# The experiment of a stored run, written by beamsim %s from\n# %s\n",
	        BSIM_VERSION, e->path);
	experiment_body(o.f, e, extra, n_extra);
	return bsim_atomic_file_commit(&o, err);
}

/* The scene file's text into f, at most the input limit: the text the
 * experiment read at load where it holds it (what the run's groups are
 * made of), else the file's. */
static int scene_text(FILE *f, const bsim_experiment *e, bsim_error *err)
{
	if (e->scene_text) {
		fwrite(e->scene_text, 1, e->scene_len, f);
		return BSIM_OK;
	}
	file_text t;
	int rc = bsim_file_read(e->scene_path, "a scene file", bsim_limits_get()->input_bytes,
	                        "input_bytes", &t, err);
	if (rc != BSIM_OK)
		return rc;
	fwrite(t.text, 1, t.len, f);
	bsim_file_text_free(&t);
	return BSIM_OK;
}

/* inputs/scene.yaml at path: the scene's text as scene_text gives it. */
static int scene_copy(const char *path, const bsim_experiment *e, bsim_error *err)
{
	if (!e->scene_text)
		return bsim_atomic_file_copy(e->scene_path, path, err);
	bsim_atomic_file o;
	if (bsim_atomic_file_open(&o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	scene_text(o.f, e, err);
	return bsim_atomic_file_commit(&o, err);
}

char *bsim_run_record_inputs(const bsim_run_record *rec, const bsim_experiment *e,
                             const bsim_override *extra, int n_extra, bsim_error *err)
{
	char *text = NULL;
	size_t len = 0;
	FILE *f = open_memstream(&text, &len);
	if (!f) {
		bsim_error_set(err, BSIM_EFAIL, "out of memory");
		return NULL;
	}
	fprintf(f, "beamsim %s\ncommand %s\n", BSIM_VERSION, rec->command);
	for (int i = 0; i < rec->n_backends; i++) {
		fprintf(f, "backend %s", rec->backend[i]);
		for (int k = 0; k < rec->opts[i].n; k++)
			fprintf(f, " %s=%s", rec->opts[i].key[k], rec->opts[i].value[k]);
		/* a side read: its file's bytes are what its trials depend on */
		if (rec->read_from[i][0])
			fprintf(f, " read %s fnv1a64 %s", rec->read_from[i], rec->read_hash[i]);
		fputc('\n', f);
	}
	fprintf(f, "groups %d\n--- experiment\n", e->n_groups);
	experiment_body(f, e, extra, n_extra);
	fputs("--- scene\n", f);
	int rc = scene_text(f, e, err);
	if (fclose(f) != 0 && rc == BSIM_OK)
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	if (rc != BSIM_OK) {
		free(text);
		return NULL;
	}
	return text;
}

static int write_json(const char *path, const bsim_run_record *rec, const bsim_experiment *e,
                      bsim_error *err)
{
	bsim_atomic_file o;
	if (bsim_atomic_file_open(&o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	FILE *f = o.f;
	fputs("{\n  \"command\": ", f);
	bsim_json_string(f, rec->command);
	fputs(",\n  \"beamsim_version\": ", f);
	bsim_json_string(f, BSIM_VERSION);
	/* What made the record, beyond the version: the checkout's commit ("" if
	 * not built from one), the version of what each registered backend is
	 * built on (NAME_version; the Box2D backend's was the first), the
	 * compiler. */
	fputs(",\n  \"beamsim_commit\": ", f);
	bsim_json_string(f, bsim_version_commit());
	for (const bsim_backend *const *b = bsim_backend_list(); *b; b++) {
		fprintf(f, ",\n  \"%s_version\": ", (*b)->name);
		bsim_json_string(f, (*b)->version ? (*b)->version : "");
	}
	fputs(",\n  \"compiler\": ", f);
	bsim_json_string(f, bsim_version_compiler());
	fputs(",\n  \"source_experiment\": ", f);
	bsim_json_string(f, e->path);
	fputs(",\n  \"experiment\": \"inputs/experiment.yaml\",\n  \"backends\": [", f);
	for (int i = 0; i < rec->n_backends; i++) {
		fputs(i ? ", " : "", f);
		fputs("{\"name\": ", f);
		bsim_json_string(f, rec->backend[i]);
		fputs(", \"label\": ", f);
		bsim_json_string(f, rec->label[i][0] ? rec->label[i] : rec->backend[i]);
		fputs(", \"options\": ", f);
		bsim_output_backend_options(f, bsim_backend_find(rec->backend[i], NULL),
		                            &rec->opts[i]);
		if (rec->plugin[i][0]) {
			fputs(", \"plugin\": ", f);
			bsim_json_string(f, rec->plugin[i]);
		}
		if (rec->read_from[i][0]) {
			fputs(", \"read_from\": ", f);
			bsim_json_string(f, rec->read_from[i]);
			fputs(", \"read_fnv1a64\": ", f);
			bsim_json_string(f, rec->read_hash[i]);
		}
		fputc('}', f);
	}
	fputc(']', f);
	if (rec->protocol[0][0]) {
		fputs(",\n  \"protocols\": [", f);
		bsim_json_string(f, rec->protocol[0]);
		fputs(", ", f);
		bsim_json_string(f, rec->protocol[1]);
		fputc(']', f);
	}
	fputs(",\n  \"seed\": ", f);
	bsim_json_u64(f, rec->seed);
	fprintf(f, ",\n  \"trials\": %d", rec->trials);
	fputs(",\n  \"rule\": {\"alpha\": ", f);
	bsim_json_number(f, rec->rule.alpha);
	fputs(", \"margin\": ", f);
	bsim_json_number(f, rec->rule.margin);
	fprintf(f, ", \"exact\": %s}\n}\n", rec->rule.exact ? "true" : "false");
	return bsim_atomic_file_commit(&o, err);
}

/* A lattice's stiffness_file goes beside the copied scene, under the name
 * the scene (or an override) gives it, for every group that names one. */
static int copy_stiffness_files(const char *inputs, const bsim_experiment *e,
                                const bsim_override *extra, int n_extra, bsim_error *err)
{
	for (int g = 0; g < e->n_groups; g++) {
		bsim_scene s;
		if (bsim_experiment_group_scene(e, g, extra, n_extra, &s, err) != BSIM_OK)
			return BSIM_EFAIL;
		char name[sizeof s.lattice.stiffness_file];
		int lattice = s.has_lattice;
		snprintf(name, sizeof name, "%s", s.lattice.stiffness_file);
		bsim_scene_free(&s);
		if (!lattice)
			return BSIM_OK; /* a gate experiment: no group is a lattice */
		if (!name[0])
			continue;
		char from[BSIM_PATH_MAX], to[BSIM_PATH_MAX];
		const char *slash = strrchr(e->scene_path, '/');
		int dir = slash ? (int)(slash - e->scene_path + 1) : 0;
		snprintf(from, sizeof from, "%.*s%s", dir, e->scene_path, name);
		if (path_join(to, sizeof to, inputs, name, err))
			return BSIM_EFAIL;
		char *last = strrchr(to, '/');
		*last = '\0';
		int rc = bsim_output_mkdir(to, err);
		*last = '/';
		if (rc != BSIM_OK || bsim_atomic_file_copy(from, to, err) != BSIM_OK)
			return BSIM_EFAIL;
	}
	return BSIM_OK;
}

int bsim_run_record_write(const char *dir, const bsim_run_record *rec, const bsim_experiment *e,
                          const bsim_override *extra, int n_extra, bsim_error *err)
{
	char inputs[BSIM_PATH_MAX], path[BSIM_PATH_MAX];
	if (path_join(inputs, sizeof inputs, dir, "inputs", err) ||
	    bsim_output_mkdir(inputs, err) != BSIM_OK)
		return BSIM_EFAIL;
	if (path_join(path, sizeof path, inputs, "scene.yaml", err) ||
	    scene_copy(path, e, err) != BSIM_OK)
		return BSIM_EFAIL;
	if (copy_stiffness_files(inputs, e, extra, n_extra, err) != BSIM_OK)
		return BSIM_EFAIL;
	if (path_join(path, sizeof path, inputs, "experiment.yaml", err) ||
	    write_experiment(path, e, extra, n_extra, err) != BSIM_OK)
		return BSIM_EFAIL;
	if (path_join(path, sizeof path, dir, "run.json", err) ||
	    write_json(path, rec, e, err) != BSIM_OK)
		return BSIM_EFAIL;
	return BSIM_OK;
}

/* Reading: every field named in the message as it appears in run.json. */
static int need_text(const ydoc *d, struct fy_node *root, const char *field, char *buf, size_t size,
                     bsim_error *err)
{
	struct fy_node *n = bsim_ydoc_lookup(root, field);
	size_t len;
	const char *t = n && fy_node_is_scalar(n) ? fy_node_get_scalar(n, &len) : NULL;
	if (!t || len == 0 || len >= size)
		return bsim_ydoc_expected(d, n, NULL, field, "a string", err);
	memcpy(buf, t, len);
	buf[len] = '\0';
	return BSIM_OK;
}

static int need_number(const ydoc *d, struct fy_node *root, const char *field, double *out,
                       bsim_error *err)
{
	struct fy_node *n = bsim_ydoc_lookup(root, field);
	if (!n || bsim_ydoc_number(n, out) != YDOC_NUM_OK)
		return bsim_ydoc_expected(d, n, NULL, field, "a number", err);
	return BSIM_OK;
}

static int read_backend(const ydoc *d, struct fy_node *root, int i, bsim_run_record *rec,
                        bsim_error *err)
{
	char field[64];
	snprintf(field, sizeof field, "backends.%d.name", i);
	if (need_text(d, root, field, rec->backend[i], sizeof rec->backend[i], err))
		return BSIM_EINPUT;
	snprintf(field, sizeof field, "backends.%d.label", i);
	if (!bsim_ydoc_lookup(root, field)) /* written before labels existed */
		snprintf(rec->label[i], sizeof rec->label[i], "%s", rec->backend[i]);
	else if (need_text(d, root, field, rec->label[i], sizeof rec->label[i], err))
		return BSIM_EINPUT;
	snprintf(field, sizeof field, "backends.%d.plugin", i);
	if (bsim_ydoc_lookup(root, field) &&
	    need_text(d, root, field, rec->plugin[i], sizeof rec->plugin[i], err))
		return BSIM_EINPUT;
	snprintf(field, sizeof field, "backends.%d.read_from", i);
	if (bsim_ydoc_lookup(root, field) &&
	    need_text(d, root, field, rec->read_from[i], sizeof rec->read_from[i], err))
		return BSIM_EINPUT;
	snprintf(field, sizeof field, "backends.%d.read_fnv1a64", i);
	if (rec->read_from[i][0] &&
	    (need_text(d, root, field, rec->read_hash[i], sizeof rec->read_hash[i], err) ||
	     strlen(rec->read_hash[i]) != 16 ||
	     strspn(rec->read_hash[i], "0123456789abcdef") != 16))
		return bsim_ydoc_expected(d, bsim_ydoc_lookup(root, field), NULL, field,
		                          "16 hex digits (the FNV-1a 64 hash of the file read)",
		                          err);
	snprintf(field, sizeof field, "backends.%d.options", i);
	struct fy_node *opts = bsim_ydoc_lookup(root, field);
	if (!opts || !fy_node_is_mapping(opts) ||
	    fy_node_mapping_item_count(opts) > BSIM_OPTIONS_MAX)
		return bsim_ydoc_expected(d, opts, NULL, field, "a mapping of knobs", err);
	void *it = NULL;
	struct fy_node_pair *p;
	while ((p = fy_node_mapping_iterate(opts, &it)) != NULL) {
		size_t kl, vl;
		const char *k = fy_node_get_scalar(fy_node_pair_key(p), &kl);
		const char *v = fy_node_get_scalar(fy_node_pair_value(p), &vl);
		bsim_options *o = &rec->opts[i];
		if (!k || !v || kl >= sizeof o->key[0] || vl >= sizeof o->value[0])
			return bsim_ydoc_expected(d, fy_node_pair_value(p), NULL, field,
			                          "knob: value strings", err);
		snprintf(o->key[o->n], sizeof o->key[0], "%.*s", (int)kl, k);
		snprintf(o->value[o->n], sizeof o->value[0], "%.*s", (int)vl, v);
		o->n++;
	}
	return BSIM_OK;
}

const bsim_backend *bsim_run_record_backend(const bsim_run_record *rec, int i, bsim_error *err)
{
	if (rec->read_from[i][0])
		return &bsim_compare_read_backend;
	const bsim_backend *b = bsim_backend_find(rec->backend[i], err);
	if (b || !rec->plugin[i][0])
		return b;
	bsim_error e;
	if (!(b = bsim_backend_load(rec->plugin[i], &e)))
		bsim_error_set(err, BSIM_EINPUT,
		               "backend %s: not registered, and its plug-in cannot be loaded "
		               "again: %s",
		               rec->backend[i], e.msg);
	else if (strcmp(b->name, rec->backend[i]) != 0)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "backend %s: its plug-in %s now defines backend %s",
		                      rec->backend[i], rec->plugin[i], b->name),
		       NULL;
	return b;
}

int bsim_run_record_read(const char *dir, bsim_run_record *rec, bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	ydoc d;
	memset(rec, 0, sizeof *rec);
	if (path_join(path, sizeof path, dir, "run.json", err))
		return BSIM_EINPUT;
	if (bsim_ydoc_load_own(&d, path, err) != BSIM_OK) {
		char msg[sizeof err->msg];
		snprintf(msg, sizeof msg, "%s", err->msg);
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s (is %s the --out directory of beamsim sweep or compare?)",
		                      msg, dir);
	}
	struct fy_node *root = fy_document_root(d.fyd);
	double alpha = 0, margin = 0;
	int rc = need_text(&d, root, "command", rec->command, sizeof rec->command, err);
	if (!rc)
		rc = need_text(&d, root, "beamsim_version", rec->version, sizeof rec->version, err);
	struct fy_node *b = bsim_ydoc_lookup(root, "backends");
	if (!rc && (!b || !fy_node_is_sequence(b) || fy_node_sequence_item_count(b) < 1 ||
	            fy_node_sequence_item_count(b) > BSIM_COMPARE_SIDES_MAX)) {
		char want[64];
		snprintf(want, sizeof want, "a list of 1 to %d backends", BSIM_COMPARE_SIDES_MAX);
		rc = bsim_ydoc_expected(&d, b, NULL, "backends", want, err);
	}
	if (!rc)
		rec->n_backends = fy_node_sequence_item_count(b);
	for (int i = 0; !rc && i < rec->n_backends; i++)
		rc = read_backend(&d, root, i, rec, err);
	if (!rc && strcmp(rec->command, "compare") == 0 && rec->n_backends < 2)
		rc = bsim_ydoc_expected(&d, b, NULL, "backends", "a comparison's 2 or more sides",
		                        err);
	struct fy_node *pn = bsim_ydoc_lookup(root, "protocols");
	if (!rc && pn &&
	    (!fy_node_is_sequence(pn) || fy_node_sequence_item_count(pn) != 2 ||
	     rec->n_backends != 2))
		rc = bsim_ydoc_expected(&d, pn, NULL, "protocols", "a list of 2 lattice protocols",
		                        err);
	for (int i = 0; !rc && pn && i < 2; i++) {
		char field[32];
		snprintf(field, sizeof field, "protocols.%d", i);
		rc = need_text(&d, root, field, rec->protocol[i], sizeof rec->protocol[i], err);
	}
	struct fy_node *sn = bsim_ydoc_lookup(root, "seed"), *tn = bsim_ydoc_lookup(root, "trials");
	long long trials = 0;
	if (!rc && (!sn || !bsim_ydoc_uint64_text(sn, &rec->seed)))
		rc = bsim_ydoc_expected(&d, sn, NULL, "seed", "an integer >= 0", err);
	if (!rc && (!tn || !bsim_ydoc_int64(tn, &trials) || trials < 1 || trials > INT32_MAX))
		rc = bsim_ydoc_expected(&d, tn, NULL, "trials", "an integer >= 1", err);
	if (!rc)
		rc = need_number(&d, root, "rule.alpha", &alpha, err);
	if (!rc)
		rc = need_number(&d, root, "rule.margin", &margin, err);
	if (!rc) {
		struct fy_node *ex = bsim_ydoc_lookup(root, "rule.exact");
		const char *t = ex ? bsim_ydoc_plain(ex) : NULL;
		rec->rule.exact = t && strcmp(t, "true") == 0;
		rec->trials = (int)trials;
		rec->rule.alpha = alpha;
		rec->rule.margin = margin;
		if (strcmp(rec->command, "sweep") != 0 && strcmp(rec->command, "compare") != 0)
			rc = bsim_ydoc_expected(&d, bsim_ydoc_lookup(root, "command"), NULL,
			                        "command", "\"sweep\" or \"compare\"", err);
	}
	bsim_ydoc_free(&d);
	return rc;
}
