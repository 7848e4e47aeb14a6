/* Shared parts of the fuzz targets; see fuzz_common.h. */
#define _XOPEN_SOURCE 700

#include "fuzz_common.h"

#include <dirent.h>
#include <ftw.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include "beamsim/backend.h"
#include "beamsim/backend_registry.h"
#include "beamsim/trial.h"

/* The essay's gate (Table 2.1), for experiments' `scene: gate.yaml`. */
static const char gate_yaml[] =
        "name: thesis-gate\n"
        "body: { mass: 1.0, radius: 10.0, start: [0, 0] }\n"
        "beams:\n"
        "  - { pivot: [-25, 30], rest_angle_deg: 0, length: 25, mass: 0.1, stiffness: 400, "
        "damping: 50 }\n"
        "  - { pivot: [25, 30], rest_angle_deg: 180, length: 25, mass: 0.1, stiffness: 400, "
        "damping: 50 }\n"
        "effects:\n"
        "  propulsion: { force: 7.0 }\n"
        "  random_force: { magnitude: 20.0, frequency: 50.0 }\n";

int fuzz_verbose;

static char dir[256];

void fuzz_accepted(void)
{
	if (fuzz_verbose)
		printf("  accepted\n");
}

static int remove_one(const char *path, const struct stat *st, int flag, struct FTW *ftw)
{
	(void)st;
	(void)flag;
	(void)ftw;
	remove(path);
	return 0;
}

/* The scratch directory and everything the targets wrote into it. */
static void cleanup(void)
{
	nftw(dir, remove_one, 16, FTW_DEPTH | FTW_PHYS);
}

const char *fuzz_dir(void)
{
	if (dir[0])
		return dir;
	const char *tmp = getenv("TMPDIR");
	snprintf(dir, sizeof dir, "%s/beamsim-fuzz-XXXXXX", tmp && *tmp ? tmp : "/tmp");
	if (!mkdtemp(dir)) {
		perror("fuzz: mkdtemp");
		abort();
	}
	atexit(cleanup);
	fuzz_write("gate.yaml", (const uint8_t *)gate_yaml, sizeof gate_yaml - 1);
	return dir;
}

const char *fuzz_write(const char *name, const uint8_t *data, size_t size)
{
	static char path[300];
	snprintf(path, sizeof path, "%s/%s", fuzz_dir(), name);
	FILE *f = fopen(path, "wb");
	if (!f || fwrite(data, 1, size, f) != size || fclose(f) != 0) {
		perror("fuzz: writing the input");
		abort();
	}
	return path;
}

/* Whole file into a malloc'd buffer; aborts on error (the fixture is the
 * target's own). */
static uint8_t *slurp(const char *path, size_t *size)
{
	FILE *f = fopen(path, "rb");
	if (!f || fseek(f, 0, SEEK_END) != 0) {
		perror(path);
		abort();
	}
	long n = ftell(f);
	uint8_t *buf = malloc(n > 0 ? (size_t)n : 1);
	rewind(f);
	if (n < 0 || !buf || fread(buf, 1, (size_t)n, f) != (size_t)n) {
		perror(path);
		abort();
	}
	fclose(f);
	*size = (size_t)n;
	return buf;
}

static int by_name(const void *a, const void *b)
{
	return strcmp(((const fuzz_file *)a)->rel, ((const fuzz_file *)b)->rel);
}

/* Copies src/rel (a directory) into fx->root/rel, listing its regular
 * files in fx with their bytes. */
static void copy_tree(fuzz_fixture *fx, const char *src, const char *rel)
{
	char from[600];
	snprintf(from, sizeof from, "%s/%s", src, rel);
	DIR *d = opendir(from);
	if (!d) {
		perror(from);
		abort();
	}
	struct dirent *ent;
	while ((ent = readdir(d))) {
		if (ent->d_name[0] == '.')
			continue;
		char sub[300], path[600];
		snprintf(sub, sizeof sub, "%s%s%s", rel, *rel ? "/" : "", ent->d_name);
		snprintf(path, sizeof path, "%s/%s", src, sub);
		struct stat st;
		if (stat(path, &st) != 0)
			continue;
		char to[700];
		snprintf(to, sizeof to, "%s/%s", fx->root, sub);
		if (S_ISDIR(st.st_mode)) {
			if (mkdir(to, 0700) != 0) {
				perror(to);
				abort();
			}
			copy_tree(fx, src, sub);
			continue;
		}
		if (fx->n == FUZZ_FIXTURE_FILES)
			abort();
		fuzz_file *f = &fx->file[fx->n++];
		snprintf(f->rel, sizeof f->rel, "%s", sub);
		snprintf(f->path, sizeof f->path, "%s", to);
		f->data = slurp(path, &f->size);
		FILE *out = fopen(to, "wb");
		if (!out || fwrite(f->data, 1, f->size, out) != f->size || fclose(out) != 0) {
			perror(to);
			abort();
		}
	}
	closedir(d);
}

void fuzz_fixture_open(fuzz_fixture *fx, const char *name)
{
	memset(fx, 0, sizeof *fx);
	snprintf(fx->root, sizeof fx->root, "%s/%s", fuzz_dir(), name);
	if (mkdir(fx->root, 0700) != 0) {
		perror(fx->root);
		abort();
	}
	char src[300];
	snprintf(src, sizeof src, "%s/%s", BSIM_FUZZ_STORED, name);
	copy_tree(fx, src, "");
	qsort(fx->file, (size_t)fx->n, sizeof fx->file[0], by_name);
	fx->manifest = -1;
	for (int i = 0; i < fx->n; i++)
		if (strcmp(fx->file[i].rel, "manifest.json") == 0)
			fx->manifest = i;
}

static void put(const char *path, const uint8_t *data, size_t size)
{
	FILE *f = fopen(path, "wb");
	if (!f || fwrite(data, 1, size, f) != size || fclose(f) != 0) {
		perror(path);
		abort();
	}
}

/* The fixture's manifest.json with file i's entry made to match data,
 * so that the readers, which check the manifest first, read the file: a
 * directory as beamsim would have committed it with these bytes. */
static void manifest_update(fuzz_fixture *fx, int i, const uint8_t *data, size_t size)
{
	const fuzz_file *m = &fx->file[fx->manifest];
	char key[340];
	snprintf(key, sizeof key, "{\"path\": \"%s\", ", fx->file[i].rel);
	char *text = malloc(m->size + 1);
	if (!text)
		abort();
	memcpy(text, m->data, m->size);
	text[m->size] = '\0';
	char *at = strstr(text, key);
	char *end = at ? strchr(at, '}') : NULL;
	if (end) {
		uLong crc =
		        crc32(crc32(0L, Z_NULL, 0), size ? data : (const Bytef *)"", (uInt)size);
		FILE *f = fopen(m->path, "wb");
		if (!f ||
		    fprintf(f, "%.*s%s\"bytes\": %zu, \"crc32\": \"%08lx\"%s", (int)(at - text),
		            text, key, size, (unsigned long)crc, end) < 0 ||
		    fclose(f) != 0) {
			perror(m->path);
			abort();
		}
		fx->dirty[fx->manifest] = 1;
	}
	free(text);
}

void fuzz_fixture_replace(fuzz_fixture *fx, int i, const uint8_t *data, size_t size)
{
	for (int k = 0; k < fx->n; k++)
		if (fx->dirty[k]) {
			put(fx->file[k].path, fx->file[k].data, fx->file[k].size);
			fx->dirty[k] = 0;
		}
	if (i < 0)
		return;
	put(fx->file[i].path, data, size);
	fx->dirty[i] = 1;
	if (fx->manifest >= 0 && i != fx->manifest)
		manifest_update(fx, i, data, size);
}

void fuzz_check_error(int rc, const bsim_error *err)
{
	if (rc != BSIM_EINPUT && rc != BSIM_EFAIL) {
		fprintf(stderr, "fuzz: unexpected code %d: %s\n", rc, err->msg);
		abort();
	}
	if (!err->msg[0] || strchr(err->msg, '\n')) {
		fprintf(stderr, "fuzz: expected one line of message, got \"%s\"\n", err->msg);
		abort();
	}
	if (fuzz_verbose)
		printf("  refused: %s\n", err->msg);
}

void fuzz_run_scene(const bsim_scene *scene)
{
	bsim_scene s;
	if (bsim_scene_copy(&s, scene) != BSIM_OK)
		return;
	/* Enough steps for contacts at the start, few enough to stay fast. */
	if (s.max_steps > 200)
		s.max_steps = 200;
	bsim_trial_runner *r = bsim_trial_runner_alloc();
	/* Every backend compiled in. */
	for (const bsim_backend *const *b = bsim_backend_list(); r && *b; b++) {
		bsim_trial_result res;
		bsim_error err;
		bsim_error_clear(&err);
		int rc = bsim_trial_run(r, &s, *b, NULL, 1, NULL, &res, &err);
		if (rc != BSIM_OK)
			fuzz_check_error(rc, &err);
	}
	bsim_trial_runner_free(r);
	bsim_scene_free(&s);
}

void fuzz_load_and_run(const char *path, const bsim_override *ov, int n_ov)
{
	bsim_scene s;
	bsim_error err;
	bsim_error_clear(&err);
	int rc = bsim_scene_load(path, ov, n_ov, &s, &err);
	if (rc != BSIM_OK) {
		fuzz_check_error(rc, &err);
		return;
	}
	fuzz_accepted();
	fuzz_run_scene(&s);
	bsim_scene_free(&s);
}
