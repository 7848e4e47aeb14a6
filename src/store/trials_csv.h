/* The columns of trials.csv, in the order they are written (docs/files.md:
 * the eleven of DESIGN.md "Outputs", then those appended since): the one
 * list the writer (output.c) and the reader (trials_read.c) share. After
 * them come the grid axes of the experiment, one column each. */
#ifndef BSIM_STORE_TRIALS_CSV_H
#define BSIM_STORE_TRIALS_CSV_H

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
	TRIALS_N_COLUMNS
};

/* Their names, as in the header line. */
extern const char *const bsim_trials_csv_columns[TRIALS_N_COLUMNS];

#endif
