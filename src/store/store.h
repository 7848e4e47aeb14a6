/* What the stored runs (sweep_dir.c, compare_dir.c, regress.c) write alike:
 * a sweep's files in a directory, MATLAB twins, text files written by a
 * function, and the count of unstable trials. The reruns regress asks of
 * the stored sweeps and comparisons are in store/rerun.h. */
#ifndef BSIM_STORE_STORE_H
#define BSIM_STORE_STORE_H

#include <stdio.h>

#include "beamsim/backend.h"
#include "beamsim/experiment.h"
#include "beamsim/sweep.h"

/* dir/summary.json, trials.csv, trajectories.csv when trajectories were
 * kept (a stale one of an earlier run is removed, so a directory never
 * pairs trials with trajectories of another run), a lattice's files, and
 * their .mat twins; dir is created if missing. trials.csv only if r has its
 * trials (trials_out): a streamed sweep has written it as it ran. */
int bsim_store_sweep_files(const char *dir, const bsim_experiment *e, const bsim_backend *b,
                           const bsim_options *opts, const bsim_override *extra, int n_extra,
                           const bsim_sweep_result *r, bsim_error *err);

/* The same for a comparison's side read from a trials.csv made elsewhere
 * (store/compare_read.h; b its stand-in): trials.csv the len bytes at text,
 * the file as read, and what else r's trials give (summary.json, the
 * survival files, a lattice's summary in summary.json, the .mat twins);
 * none of what needs the trials' paths (a lattice's other files). */
int bsim_store_read_files(const char *dir, const bsim_experiment *e, const bsim_backend *b,
                          const bsim_override *extra, int n_extra, const bsim_sweep_result *r,
                          const char *text, size_t len, bsim_error *err);

/* dir/file (a .csv or .json) as dir/NAME.mat, variable var. */
int bsim_store_twin(const char *dir, const char *file, const char *var, bsim_error *err);

/* dir/name written by fn(f, arg) after head (may be NULL), atomically. */
typedef void (*bsim_store_text_fn)(FILE *f, const void *arg);
int bsim_store_text(const char *dir, const char *name, const char *head, bsim_store_text_fn fn,
                    const void *arg, bsim_error *err);

/* The unstable trials of r: how many, the first's index (-1 if none) and
 * why, in one line, from the scene of its group (e with extra). */
long bsim_store_unstable(const bsim_experiment *e, const bsim_override *extra, int n_extra,
                         const bsim_sweep_result *r, long *first, char *why, size_t size);

/* Loads the experiment at path with the overrides, the grid axes and the
 * seed (NULL: the file's; bsim_experiment_load_seeded) and, if trials > 0,
 * that many trials per group (BSIM_EINPUT "--trials N: ..." beyond the
 * limit). */
int bsim_store_experiment(const char *path, const bsim_override *sets, int n_sets,
                          const bsim_grid_axis *grid, int n_grid, long trials, const uint64_t *seed,
                          bsim_experiment *e, bsim_error *err);

#endif
