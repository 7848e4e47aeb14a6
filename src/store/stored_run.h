/* A stored run's directory read for what it shows, not run again
 * (stored_run.c): the scene of a trial's directory, `beamsim run --out
 * DIR`, which the figures of the run and the trajectory player
 * (store/viewer_data.h) draw it in; and where a comparison's side keeps
 * its files (bsim_compare_dir_label, beamsim/compare_dir.h). Nothing here
 * writes a directory, so the page written at a run's end
 * (store/index_html.h) may call it. */
#ifndef BSIM_STORE_STORED_RUN_H
#define BSIM_STORE_STORED_RUN_H

#include "beamsim/error.h"
#include "beamsim/scene.h"

typedef struct bsim_run_scene {
	bsim_scene scene; /* DIR/inputs/scene.yaml with run.json's "set" applied */
	int n_sets;
	char **keys, **values; /* n_sets each: run.json's "set", in order */
	/* run.json's outcome, type and backend ("" if missing) */
	char outcome[32], type[32], backend[32];
	long group, trial; /* run.json's (0 if missing) */
} bsim_run_scene;

/* Loads the scene of dir as the run built it. *found is 0 (and nothing
 * loaded, BSIM_OK) if dir has no run.json or no inputs/scene.yaml; else
 * BSIM_OK with rs to free with bsim_run_scene_free, or BSIM_EINPUT naming
 * the file and field (a "set" that is not a mapping of strings, a scene
 * that does not load), BSIM_EFAIL out of memory, rs then holding nothing. */
int bsim_run_scene_load(const char *dir, bsim_run_scene *rs, int *found, bsim_error *err);
void bsim_run_scene_free(bsim_run_scene *rs);

#endif
