/* An experiment: a scene, fixed overrides, a grid of parameter values whose
 * cartesian product is the groups, trials per group and a seed
 * (docs/files.md "Experiment file (YAML)"). */
#ifndef BSIM_EXPERIMENT_H
#define BSIM_EXPERIMENT_H

#include <stddef.h>
#include <stdint.h>

#include "beamsim/backend.h"
#include "beamsim/base.h"
#include "beamsim/error.h"
#include "beamsim/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* One axis of the grid. What it holds grows with its values' text alone:
 * where it came from is said once for all its values (a --grid option of
 * 20,000 values is not repeated 20,000 times), and a value's origin is
 * made when a message needs it (bsim_experiment_value_origin). */
typedef struct bsim_grid_axis {
	char *key; /* dotted scene path */
	int n_values;
	char **values; /* YAML scalar text of each value */
	/* Where the axis was given, for error messages: an experiment file
	 * (with lines), or an option such as "--grid body.mass"; NULL is
	 * "--grid KEY". */
	char *origin;
	int *lines; /* NULL, or the line of each value in the file origin (from 1) */
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
	/* The scene file's text as it was read once at load (owned; NULL: read
	 * the file each time), from which every group's scene is made: a run
	 * reads its scene file once, and every group sees the same text. */
	char *scene_text;
	size_t scene_len;
	void *scene_doc; /* that text parsed once (internal: a libfyaml document) */
	/* Every group's scene as the load built and validated it, with the
	 * load's extra overrides (copied here), so that a group's scene is
	 * built once: bsim_experiment_group_scene gives a copy of it for the
	 * same overrides (internal; NULL: none kept). */
	bsim_scene *group_scenes;
	bsim_override *group_extra;
	int n_group_extra;
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
 * that field its values. The axes are copied; their origins name their
 * values in error messages ("--grid body.mass=7"). The experiment then holds the grid
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

/* Frees what a grid axis holds (key, values, origin, lines; each may be
 * NULL while the axis is being made) and zeroes it. */
BSIM_API void bsim_experiment_axis_free(bsim_grid_axis *ax);

/* Where value i of ax came from, for a message: "FILE:LINE" when ax has
 * lines, else "ORIGIN=VALUE" ("--grid body.mass=7", as a --set names
 * itself). Written into buf as snprintf would; returns the length of the
 * whole text (buf may be too small: size it with a first call). */
BSIM_API int bsim_experiment_value_origin(const bsim_grid_axis *ax, int i, char *buf, size_t size);

/* Where ax came from as a whole: "FILE:LINE" of its first value, or its
 * origin ("--grid body.mass"), into buf (cut to size). */
BSIM_API void bsim_experiment_axis_origin(const bsim_grid_axis *ax, char *buf, size_t size);

/* BSIM_EINPUT with "expected at most N trials in all, got G groups x T
 * trials = ..." if n_groups x trials exceeds the limit trials
 * (beamsim/limits.h); for a --trials that replaces the file's. */
BSIM_API int bsim_experiment_check_trials(const bsim_experiment *e, long trials, bsim_error *err);

/* The value index along each axis for group g (idx has n_axes entries). */
BSIM_API void bsim_experiment_group_index(const bsim_experiment *e, int g, int *idx);

/* The overrides that build group g's scene, in the order they apply: set,
 * then extra, then the group's grid values, each value with its origin
 * (bsim_experiment_value_origin). *n gets their count. One allocation,
 * freed with free(); keys and values are borrowed from e and extra (valid
 * while they are). NULL if out of memory, or if g is out of range. */
BSIM_API bsim_override *bsim_experiment_group_overrides(const bsim_experiment *e, int g,
                                                        const bsim_override *extra, int n_extra,
                                                        int *n);

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
