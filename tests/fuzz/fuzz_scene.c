/* Fuzz target: a scene file, loaded as `beamsim run SCENE` loads it, and
 * if it is accepted, a short run on both backends. */
#include "fuzz_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	bsim_scene s;
	bsim_error err;
	bsim_error_clear(&err);
	const char *path = fuzz_write("input.yaml", data, size);
	int rc = bsim_scene_load(path, NULL, 0, &s, &err);
	if (rc != BSIM_OK) {
		fuzz_check_error(rc, &err);
		return 0;
	}
	fuzz_accepted();
	fuzz_run_scene(&s);
	bsim_scene_free(&s);
	return 0;
}
