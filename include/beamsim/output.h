/* The output files of a sweep (docs/files.md "Outputs of `sweep --out DIR`",
 * a contract): summary.json, trials.csv and the text table of p_traverse.
 * Files are written through util/atomic_file.h, so a reader never sees half a
 * file and an interrupted run leaves none. */
#ifndef BSIM_OUTPUT_H
#define BSIM_OUTPUT_H

#include <stddef.h>
#include <stdio.h>

#include "beamsim/base.h"
#include "beamsim/backend.h"
#include "beamsim/experiment.h"
#include "beamsim/sweep.h"

#ifdef __cplusplus
extern "C" {
#endif

BSIM_API int bsim_output_summary_json(const char *path, const bsim_experiment *e,
                                      const char *backend, const bsim_options *opts,
                                      const bsim_sweep_result *r, bsim_error *err);
/* trials.csv, one row per trial (docs/files.md "Outputs of
 * `sweep --out DIR`", extended by appending):
 * group,trial,outcome,type,steps,t_end,x_end,y_end,vx_end,
 * max_theta1,max_theta2, then the energy ledger e_start,e_end,work_in
 * (propulsion + random force),losses (dampers + impacts + contact +
 * correction),residual (J), overlap_max (m; empty if not measured), the
 * final gate, location and path, the solver's counts, t_exit, the body's
 * turn heading_end,angular_velocity_end,turn_end,turn_max (rad, rad/s; the
 * columns trials_csv.h lists), then one column per grid axis of e (may be
 * NULL), named by its dotted key, holding the group's value. */
BSIM_API int bsim_output_trials_csv(const char *path, const bsim_experiment *e,
                                    const bsim_sweep_result *r, bsim_error *err);
/* trajectories.csv: the kept trajectories of r (r->keep per group), rows of
 * bsim_trajectory_csv_header, group by group, trial by trial. Nothing is
 * written when r keeps none. */
BSIM_API int bsim_output_trajectories_csv(const char *path, const bsim_sweep_result *r,
                                          bsim_error *err);
/* Reads a trials.csv written by bsim_output_trials_csv, by this version or
 * an earlier one, back into r (which it allocates: n_groups x trials rows,
 * each exactly once) and aggregates the groups. Columns are found by their
 * header name; the first eleven are required, the ledger columns are read
 * when present (r->has_ledger), and so are the final gate, the solver's
 * counts and the turn (r->has_turn); others are ignored. The fields not in the
 * file are zero. BSIM_EINPUT naming file, line and field, and what was
 * expected there, on a malformed, missing or repeated row. */
BSIM_API int bsim_output_trials_read(const char *path, int n_groups, int trials,
                                     bsim_sweep_result *r, bsim_error *err);

/* Whether a run could write the output directory dir now (docs/robustness.md,
 * "Directories"), found without changing anything: BSIM_OK (a directory
 * missing is fine: the run creates it), or BSIM_EINPUT naming why not: dir
 * is a file, another run is writing it, or, with overwrite 0, it holds a
 * finished result or a stopped run's journal, the message naming
 * overwrite_option (NULL: "--overwrite") as the way to replace it. The runs
 * check again when they open dir; this lets a caller with work to do first
 * (a binding, a program) refuse before it, in its own words. */
BSIM_API int bsim_output_dir_check(const char *dir, int overwrite, const char *overwrite_option,
                                   bsim_error *err);

/* For a caller that holds a sweep's trials in memory as columns of
 * trials.csv (the bindings), before any trial runs: BSIM_EINPUT "expected
 * trials that fit in memory as columns: ..." with the sizes if e's
 * n_groups x trials rows of trials.csv's columns (one more a grid axis),
 * cell_bytes each, need more than the memory available
 * (bsim_memory_available, beamsim/limits.h). trials > 0 replaces e's. */
BSIM_API int bsim_output_trials_fit(const bsim_experiment *e, long trials, double cell_bytes,
                                    bsim_error *err);

/* A lattice sweep's own files in dir (docs/lattice.md "Files"):
 * lattice_map.csv, final_locations.csv, transitions.csv, gate_entries.csv
 * and beam_peaks.csv. Nothing
 * for a sweep of gate scenes. extra: the command line's --set, to rebuild
 * the groups' stiffness maps. */
BSIM_API int bsim_output_lattice(const char *dir, const bsim_experiment *e,
                                 const bsim_override *extra, int n_extra,
                                 const bsim_sweep_result *r, bsim_error *err);

/* p_traverse over the first two grid axes (columns: axis 0, rows: axis 1),
 * one table per combination of the other axes. */
BSIM_API void bsim_output_table(FILE *f, const bsim_experiment *e, const bsim_sweep_result *r);

/* A JSON object of every knob of backend b (may be NULL) with its
 * effective value, given in opts or the default, then any option of opts
 * that b does not list: a record alone says how the backend was run.
 * Shared by summary.json, run --json and bench --json. */
BSIM_API void bsim_output_backend_options(FILE *f, const bsim_backend *b, const bsim_options *opts);

/* The JSON object {axis key: value} of group g, values as numbers where
 * they are numbers (as in summary.json); {} beyond BSIM_OUTPUT_AXES_MAX
 * axes. */
#define BSIM_OUTPUT_AXES_MAX 32
BSIM_API void bsim_output_group_params(FILE *f, const bsim_experiment *e, int g);

/* Creates dir (and parents) if missing. */
BSIM_API int bsim_output_mkdir(const char *dir, bsim_error *err);

#ifdef __cplusplus
}
#endif
#endif
