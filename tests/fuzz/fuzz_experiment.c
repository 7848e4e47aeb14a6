/* Fuzz target: an experiment file (its `scene: gate.yaml` is the essay's
 * gate beside it), loaded as `beamsim sweep` loads it: every group's scene
 * is built and checked. An accepted experiment's first and last groups
 * then run briefly. The grid is held to 1000 groups (as `--limit
 * groups=1000` holds it): loading costs about 60 microseconds a group
 * (84,000 groups in 4.9 s, Release), so the default limit's 100,000 let a
 * few hundred bytes of lists take longer than a fuzz input may; the limit
 * itself, and the refusal beyond it, are the same code at any value. */
#include "fuzz_common.h"

#include <stdio.h>
#include <stdlib.h>

#include "beamsim/experiment.h"
#include "beamsim/limits.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	static int limited;
	if (!limited) {
		bsim_limits l = bsim_limits_default();
		l.groups = 1000;
		bsim_limits_set(&l);
		limited = 1;
	}
	bsim_experiment e;
	bsim_error err;
	bsim_error_clear(&err);
	const char *path = fuzz_write("input.yaml", data, size);
	int rc = bsim_experiment_load(path, NULL, 0, &e, &err);
	if (rc != BSIM_OK) {
		fuzz_check_error(rc, &err);
		return 0;
	}
	fuzz_accepted();
	int groups[2] = {0, e.n_groups - 1};
	for (int i = 0; i < 2; i++) {
		bsim_scene s;
		rc = bsim_experiment_group_scene(&e, groups[i], NULL, 0, &s, &err);
		if (rc != BSIM_OK) {
			/* Every group was checked at load: it must build again. */
			fprintf(stderr, "fuzz: group %d failed after a clean load: %s\n", groups[i],
			        err.msg);
			abort();
		}
		fuzz_run_scene(&s);
		bsim_scene_free(&s);
	}
	bsim_experiment_free(&e);
	return 0;
}
