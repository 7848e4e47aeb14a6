/* Shared parts of the fuzz targets; see fuzz_common.h. */
#define _POSIX_C_SOURCE 200809L

#include "fuzz_common.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "beamsim/backend.h"
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

static void cleanup(void)
{
	char path[300];
	snprintf(path, sizeof path, "%s/input.yaml", dir);
	unlink(path);
	snprintf(path, sizeof path, "%s/gate.yaml", dir);
	unlink(path);
	rmdir(dir);
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
	static const char *const names[] = {"thesis", "box2d"};
	bsim_scene s;
	if (bsim_scene_copy(&s, scene) != BSIM_OK)
		return;
	/* Enough steps for contacts at the start, few enough to stay fast. */
	if (s.max_steps > 200)
		s.max_steps = 200;
	bsim_trial_runner *r = bsim_trial_runner_alloc();
	for (int i = 0; r && i < 2; i++) {
		const bsim_backend *b = bsim_backend_find(names[i], NULL);
		bsim_trial_result res;
		bsim_error err;
		bsim_error_clear(&err);
		int rc = b ? bsim_trial_run(r, &s, b, NULL, 1, NULL, &res, &err) : BSIM_OK;
		if (rc != BSIM_OK)
			fuzz_check_error(rc, &err);
	}
	bsim_trial_runner_free(r);
	bsim_scene_free(&s);
}
