/* Fuzz target: a lattice's stiffness file (the scene's
 * lattice.stiffness_file, one CSV row of gate stiffnesses per lattice row),
 * read as `beamsim run SCENE` reads it for a fixed 3 x 3 lattice scene;
 * if it is accepted, a short run of the lattice on both backends. */
#include "fuzz_common.h"

#include <stdio.h>

static const char lattice_yaml[] =
        "name: fuzz-lattice\n"
        "body: { mass: 1.0, radius: 10.0, start: [0, 0] }\n"
        "lattice:\n"
        "  columns: 3\n"
        "  rows: 3\n"
        "  gate: { width: 50, depth: 60, pivot_y: 30 }\n"
        "  beam: { length: 25, mass: 0.1, stiffness: 400, damping: 50 }\n"
        "  stiffness_file: stiffness.csv\n"
        "effects:\n"
        "  propulsion: { force: 8.0 }\n"
        "  random_force: { magnitude: 30.0, frequency: 50.0 }\n"
        "termination: { success_y: 180, side_x: 75, gate_steps: 1000 }\n";

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	static char scene[400];
	if (!scene[0])
		snprintf(scene, sizeof scene, "%s",
		         fuzz_write("lattice.yaml", (const uint8_t *)lattice_yaml,
		                    sizeof lattice_yaml - 1));
	fuzz_write("stiffness.csv", data, size);
	fuzz_load_and_run(scene, NULL, 0);
	return 0;
}
