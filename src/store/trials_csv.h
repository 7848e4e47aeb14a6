/* The columns of trials.csv by index, in the order they are written
 * (beamsim/trial_fields.h, which describes each; docs/files.md "Outputs of
 * `sweep --out DIR`"): the indices the reader (trials_read.c) finds them
 * by. After them come the grid axes of the experiment, one column each. */
#ifndef BSIM_STORE_TRIALS_CSV_H
#define BSIM_STORE_TRIALS_CSV_H

#include "beamsim/experiment.h"
#include "beamsim/output.h"
#include "beamsim/trial.h"
#include "beamsim/trial_fields.h"
#include "util/atomic_file.h"

enum {
	TRIALS_GROUP,
	TRIALS_TRIAL,
	TRIALS_OUTCOME,
	TRIALS_TYPE,
	TRIALS_STEPS,
	TRIALS_T_END,
	TRIALS_X_END,
	TRIALS_Y_END,
	TRIALS_VX_END,
	TRIALS_MAX_THETA1,
	TRIALS_MAX_THETA2,
	TRIALS_E_START,
	TRIALS_E_END,
	TRIALS_WORK_IN,
	TRIALS_LOSSES,
	TRIALS_RESIDUAL,
	TRIALS_OVERLAP_MAX,
	TRIALS_FINAL_IX,
	TRIALS_FINAL_IY,
	TRIALS_LOCATION,
	TRIALS_PATH,
	TRIALS_ITERATION_LIMITS,
	TRIALS_CLAMPS,
	TRIALS_T_EXIT,
	TRIALS_HEADING_END,
	TRIALS_ANGULAR_VELOCITY_END,
	TRIALS_TURN_END,
	TRIALS_TURN_MAX,
	TRIALS_N_COLUMNS
};

/* Column k's name, as in the header line: beamsim/trial_fields.h's k-th
 * field, whose order these indices follow (test_output_files,
 * test_trials_csv_indices, checks each index's name). */
const char *bsim_trials_csv_column(int k);

/* trials.csv written as the trials come (a streamed sweep hands them over
 * block by block): open writes the header, rows appends trials first ..
 * first + n - 1 of a sweep of `trials` per group (logs may be NULL), commit
 * puts the whole file in place (util/atomic_file.h), abort leaves nothing.
 * With twin set the writer makes trials.mat beside it too, from the same
 * trials (store/matlab.h, bsim_matlab_trials), written on commit. */
typedef struct trials_csv_writer {
	bsim_atomic_file o;
	const bsim_experiment *e;
	int axes;
	int group; /* the group whose axis values idx holds */
	int idx[BSIM_OUTPUT_AXES_MAX];
	struct bsim_matlab_trials *twin; /* NULL: none */
} trials_csv_writer;

int bsim_trials_csv_open(trials_csv_writer *w, const char *path, const bsim_experiment *e, int twin,
                         bsim_error *err);
void bsim_trials_csv_rows(trials_csv_writer *w, long first, long n, int trials,
                          const bsim_trial_result *results, const bsim_trial_log *logs);
int bsim_trials_csv_commit(trials_csv_writer *w, bsim_error *err);
void bsim_trials_csv_abort(trials_csv_writer *w);

/* A sweep's trials.csv and its twin trials.mat, from r held in memory. */
int bsim_trials_csv_write(const char *path, const bsim_experiment *e, const bsim_sweep_result *r,
                          bsim_error *err);

/* The shape a trials.csv read back must have: every (group, trial) of
 * n_groups x trials once (bsim_output_trials_read asks no more), and what
 * a file made elsewhere is held to besides (compare's trials:PATH side). */
typedef struct trials_csv_shape {
	int n_groups, trials;
	/* NULL, or per group 1 if its trial 0 stands for every trial of it (a
	 * group that draws no random force, beamsim/sweep.h): the other rows
	 * are its copies, as a sweep writes them, and each must agree with
	 * trial 0 in outcome, type and final gate. Such a group is marked
	 * deterministic in the result. */
	const int *one_trial;
	int need_final_gate; /* 1: final_ix and final_iy required (a gate lattice) */
	int type_rule;       /* 1: type none unless the outcome is traversed, as beamsim
	                      * writes it */
} trials_csv_shape;

/* The text of the trials.csv at path (whole and checked: bsim_csv_text_read;
 * split in place) into r, its groups aggregated. BSIM_EINPUT "PATH:LINE:
 * FIELD: expected ..., got ..." at the first field that does not fit the
 * shape, a (group, trial) read twice (naming the line of the first) or
 * missing (named, at the end of the file). */
int bsim_trials_csv_parse(const char *path, char *text, const trials_csv_shape *shape,
                          bsim_sweep_result *r, bsim_error *err);

#endif
