/* An experiment: a scene, fixed overrides, a grid of parameter values whose
 * cartesian product is the groups, trials per group and a seed
 * (DESIGN.md "Experiment file"). */
#ifndef BSIM_EXPERIMENT_H
#define BSIM_EXPERIMENT_H

#include <stdint.h>

#include "beamsim/backend.h"
#include "beamsim/base.h"
#include "beamsim/error.h"
#include "beamsim/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct bsim_grid_axis {
	char *key; /* dotted scene path */
	int n_values;
	char **values;  /* YAML scalar text of each value */
	char **origins; /* "file:line" of each value, for error messages */
} bsim_grid_axis;

typedef struct bsim_experiment {
	char path[1024];
	char scene_path[1024]; /* resolved relative to the experiment file */
	int trials;
	uint64_t seed;
	int n_set;          /* fixed overrides from the `set:` block */
	bsim_override *set; /* strings owned by the experiment */
	int n_axes;
	bsim_grid_axis *axes; /* the first axis varies slowest */
	int n_groups;         /* product of the axes' sizes, >= 1 */
} bsim_experiment;

/* Loads an experiment file. Errors (unknown keys, an empty grid, ...) are
 * BSIM_EINPUT with file, line, field and what was expected. The scene of
 * every group is loaded and validated here, so a bad grid value fails before
 * any trial runs. extra: command-line --set overrides applied to every group
 * (after `set:`, before the grid values). */
BSIM_API int bsim_experiment_load(const char *path, const bsim_override *extra, int n_extra,
                                  bsim_experiment *out, bsim_error *err);

/* bsim_experiment_load with the grid changed beside the file (beamsim
 * sweep --grid KEY=...): each of the n_grid axes replaces the file's axis
 * of the same key where it stands, or, if the file has none, is appended
 * after the file's axes, in the order given; an entry of the file's set:
 * for the axis's field (or a field inside it) is dropped, the axis giving
 * that field its values. The axes are copied; each value's origin (NULL:
 * "--grid") names it in error messages. The experiment then holds the grid
 * that runs, so the record of a run (beamsim/run_record.h) repeats it.
 * With n_grid 0, bsim_experiment_load. */
BSIM_API int bsim_experiment_load_grid(const char *path, const bsim_override *extra, int n_extra,
                                       const bsim_grid_axis *grid, int n_grid, bsim_experiment *out,
                                       bsim_error *err);

/* bsim_experiment_load_grid with a seed given beside the file (beamsim
 * --seed N), or NULL: the seed replaces the file's seed:, and a file that
 * gives none takes it (without one, a file must give seed:). The
 * experiment then holds the seed that runs, so the record of a run
 * (beamsim/run_record.h) repeats it. */
BSIM_API int bsim_experiment_load_seeded(const char *path, const bsim_override *extra, int n_extra,
                                         const bsim_grid_axis *grid, int n_grid,
                                         const uint64_t *seed, bsim_experiment *out,
                                         bsim_error *err);
BSIM_API void bsim_experiment_free(bsim_experiment *e);

/* Frees what a grid axis holds (key, values, origins; origins may be NULL
 * while the values are being made) and zeroes it. */
BSIM_API void bsim_experiment_axis_free(bsim_grid_axis *ax);

/* BSIM_EINPUT with "expected at most N trials in all, got G groups x T
 * trials = ..." if n_groups x trials exceeds the limit trials
 * (beamsim/limits.h); for a --trials that replaces the file's. */
BSIM_API int bsim_experiment_check_trials(const bsim_experiment *e, long trials, bsim_error *err);

/* The value index along each axis for group g (idx has n_axes entries). */
BSIM_API void bsim_experiment_group_index(const bsim_experiment *e, int g, int *idx);

/* Builds the scene of group g: scene file + set + extra + grid values. */
BSIM_API int bsim_experiment_group_scene(const bsim_experiment *e, int g,
                                         const bsim_override *extra, int n_extra, bsim_scene *out,
                                         bsim_error *err);

/* Checks scene, group g's (bsim_experiment_group_scene with the same
 * extra), against backend b with opts (bsim_backend_check): what b refuses
 * is said where the group's scene gave the field, the scene file's line,
 * set:, extra or the grid value. */
BSIM_API int bsim_experiment_group_check(const bsim_experiment *e, int g,
                                         const bsim_override *extra, int n_extra,
                                         const bsim_scene *scene, const bsim_backend *b,
                                         const bsim_options *opts, bsim_error *err);

#ifdef __cplusplus
}
#endif
#endif
