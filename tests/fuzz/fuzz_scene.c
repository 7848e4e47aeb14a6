/* Fuzz target: a scene file, loaded as `beamsim run SCENE` loads it, and
 * if it is accepted, a short run on both backends. */
#include "fuzz_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	fuzz_load_and_run(fuzz_write("input.yaml", data, size), NULL, 0);
	return 0;
}
