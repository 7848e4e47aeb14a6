/* trials.csv read back (beamsim regress compares a stored sweep with its
 * rerun through the file, so both sides have exactly the file's
 * precision). Columns are found by their header name, so a file with more
 * columns than this version writes, or one written before the energy
 * columns, the lattice's final gate (final_ix, final_iy; 0 when absent,
 * what a gate scene writes), the solver's counts (iteration_limits,
 * clamps; 0 when absent) or the body's turn (heading_end, ...; all four or
 * none, 0 when absent, r->has_turn 0, so that a comparison leaves them out)
 * existed, reads the same. t_exit is not read: it is t_end for an exit and
 * empty otherwise, so outcome and t_end give it. */
#define _POSIX_C_SOURCE 200809L

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/output.h"
#include "store/trials_csv.h"
#include "util/csv_table.h"
#include "util/file_read.h"

enum {
	COL_GROUP,
	COL_TRIAL,
	COL_OUTCOME,
	COL_TYPE,
	COL_STEPS,
	COL_T_END,
	COL_X_END,
	COL_Y_END,
	COL_VX_END,
	COL_MAX_THETA1,
	COL_MAX_THETA2,
	N_REQUIRED,
	COL_E_START = N_REQUIRED,
	COL_E_END,
	COL_WORK_IN,
	COL_LOSSES,
	COL_RESIDUAL,
	LEDGER_END,
	COL_FINAL_IX = LEDGER_END,
	COL_FINAL_IY,
	COL_ITERATION_LIMITS,
	COL_CLAMPS,
	COL_HEADING_END,
	COL_ANGULAR_VELOCITY_END,
	COL_TURN_END,
	COL_TURN_MAX,
	N_COLUMNS
};

/* Each column's place in the list of trials.csv (trials_csv.h). */
static const int column_of[N_COLUMNS] = {
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
        TRIALS_FINAL_IX,
        TRIALS_FINAL_IY,
        TRIALS_ITERATION_LIMITS,
        TRIALS_CLAMPS,
        TRIALS_HEADING_END,
        TRIALS_ANGULAR_VELOCITY_END,
        TRIALS_TURN_END,
        TRIALS_TURN_MAX,
};

/* The column k of this reader whose name s is, or -1. */
static int column_index(const char *s)
{
	for (int k = 0; k < N_COLUMNS; k++)
		if (strcmp(s, bsim_trials_csv_columns[column_of[k]]) == 0)
			return k;
	return -1;
}

static int parse_double(const char *s, double *out)
{
	char *end;
	*out = strtod(s, &end);
	return *s && !*end ? 0 : -1;
}

/* One row into r; 0 on success. col[k]: the field index of column k, -1
 * if the file has none. */
static int parse_row(char **f, int n, const int *col, const bsim_sweep_result *r,
                     bsim_trial_result *all)
{
	for (int k = 0; k < N_COLUMNS; k++)
		if (col[k] >= n)
			return -1;
	char *end;
	long g = strtol(f[col[COL_GROUP]], &end, 10);
	if (*end || g < 0 || g >= r->n_groups)
		return -1;
	long t = strtol(f[col[COL_TRIAL]], &end, 10);
	if (*end || t < 0 || t >= r->trials)
		return -1;
	bsim_trial_result *x = &all[g * r->trials + t];
	if (x->steps_run) /* seen already */
		return -1;
	int o = -1, ty = -1;
	for (int i = 0; i < BSIM_N_OUTCOMES; i++)
		o = strcmp(f[col[COL_OUTCOME]], bsim_trial_outcome_name((bsim_outcome)i)) ? o : i;
	for (int i = 0; i < 3; i++)
		ty = strcmp(f[col[COL_TYPE]], bsim_trial_type_name((bsim_type)i)) ? ty : i;
	if (o < 0 || ty < 0)
		return -1;
	x->outcome = (bsim_outcome)o;
	x->type = (bsim_type)ty;
	x->steps = (int)strtol(f[col[COL_STEPS]], &end, 10);
	if (*end)
		return -1;
	double *v[6] = {&x->t_end,  &x->x_end,        &x->y_end,
	                &x->vx_end, &x->max_theta[0], &x->max_theta[1]};
	for (int i = 0; i < 6; i++)
		if (parse_double(f[col[COL_T_END + i]], v[i]))
			return -1;
	if (col[COL_E_START] >= 0) {
		/* The split columns come back as the ledger's first entry of
		 * each sum: enough to compare two files field by field. */
		bsim_ledger *l = &x->ledger;
		double *lv[5] = {&l->e_start, &l->e_end, &l->w_prop, &l->damper, &l->residual};
		for (int i = 0; i < 5; i++)
			if (parse_double(f[col[COL_E_START + i]], lv[i]))
				return -1;
	}
	int *gate[2] = {&x->final_ix, &x->final_iy};
	for (int i = 0; i < 2; i++) {
		if (col[COL_FINAL_IX + i] < 0)
			continue;
		*gate[i] = (int)strtol(f[col[COL_FINAL_IX + i]], &end, 10);
		if (*end)
			return -1;
	}
	long *solver[2] = {&x->solver.iteration_limit, &x->solver.clamped};
	for (int i = 0; i < 2; i++) {
		if (col[COL_ITERATION_LIMITS + i] < 0)
			continue;
		*solver[i] = strtol(f[col[COL_ITERATION_LIMITS + i]], &end, 10);
		if (*end || *solver[i] < 0)
			return -1;
	}
	double *turn[4] = {&x->heading_end, &x->angular_velocity_end, &x->turn_end, &x->turn_max};
	for (int i = 0; i < 4 && col[COL_HEADING_END] >= 0; i++)
		if (parse_double(f[col[COL_HEADING_END + i]], turn[i]))
			return -1;
	x->steps_run = 1; /* marks the row as read; not in the file */
	return 0;
}

/* The columns first .. end - 1 of this reader the header has: all or
 * none (-1). */
static int all_or_none(const int *col, int first, int end)
{
	int have = 0;
	for (int k = first; k < end; k++)
		have += col[k] >= 0;
	return have == 0 || have == end - first ? 0 : -1;
}

/* The header: every required column once; the ledger's columns, and the
 * turn's, all or none. */
static int read_header(char *line, int *col, int *n_fields)
{
	char *f[256];
	int n = csv_split(line, f, 256);
	for (int k = 0; k < N_COLUMNS; k++)
		col[k] = -1;
	for (int i = 0; i < n; i++) {
		int k = column_index(f[i]);
		if (k >= 0 && col[k] >= 0)
			return -1;
		if (k >= 0)
			col[k] = i;
	}
	for (int k = 0; k < N_REQUIRED; k++)
		if (col[k] < 0)
			return -1;
	if (all_or_none(col, N_REQUIRED, LEDGER_END) ||
	    all_or_none(col, COL_HEADING_END, N_COLUMNS))
		return -1;
	*n_fields = n;
	return n > 0 ? 0 : -1;
}

int bsim_output_trials_read(const char *path, int n_groups, int trials, bsim_sweep_result *r,
                            bsim_error *err)
{
	memset(r, 0, sizeof *r);
	/* A regular file only (a link to /dev/zero or a FIFO is refused at
	 * once), bounded, and whole: its last row ends in a line feed. */
	file_text ft;
	int rc = csv_text_read(path, &ft, err);
	if (rc != BSIM_OK)
		return rc;
	size_t total = (size_t)n_groups * (size_t)trials;
	r->n_groups = n_groups;
	r->trials = trials;
	r->trials_out = calloc(total ? total : 1, sizeof *r->trials_out);
	r->groups = calloc(n_groups > 0 ? (size_t)n_groups : 1, sizeof *r->groups);
	if (!r->trials_out || !r->groups) {
		file_text_free(&ft);
		bsim_sweep_result_free(r);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory for %zu trials", total);
	}
	char *line, *next = ft.text, *field[256];
	int lineno = 0, col[N_COLUMNS], n_fields = 0;
	size_t rows = 0;
	while (rc == BSIM_OK && *next) {
		line = next;
		char *nl = strchr(line, '\n'); /* there is one: csv_text_check */
		*nl = '\0';
		next = nl + 1;
		lineno++;
		line[strcspn(line, "\r")] = '\0';
		if (lineno == 1) {
			if (read_header(line, col, &n_fields) != 0)
				rc = bsim_error_set(
				        err, BSIM_EINPUT,
				        "%s:1: expected a header naming each of group, trial, "
				        "outcome, type, steps, t_end, x_end, y_end, vx_end, "
				        "max_theta1, max_theta2 once (e_start, e_end, work_in, "
				        "losses, residual all or none; heading_end, "
				        "angular_velocity_end, turn_end, turn_max all or none)",
				        path);
			r->has_ledger = col[COL_E_START] >= 0;
			r->has_turn = col[COL_HEADING_END] >= 0;
			continue;
		}
		int n = csv_split(line, field, 256);
		if (n != n_fields || parse_row(field, n, col, r, r->trials_out) != 0)
			rc = bsim_error_set(
			        err, BSIM_EINPUT,
			        "%s:%d: expected a row of %d fields group,trial,... of %d "
			        "groups x %d trials, each once",
			        path, lineno, n_fields, n_groups, trials);
		rows++;
	}
	file_text_free(&ft);
	if (rc == BSIM_OK && lineno == 0)
		rc = bsim_error_set(err, BSIM_EINPUT, "%s: empty file, expected a header", path);
	if (rc == BSIM_OK && rows != total)
		rc = bsim_error_set(err, BSIM_EINPUT,
		                    "%s:%d: expected %zu rows (%d groups x %d trials), got %zu "
		                    "by the end of the file",
		                    path, lineno, total, n_groups, trials, rows);
	if (rc != BSIM_OK) {
		bsim_sweep_result_free(r);
		return rc;
	}
	for (size_t i = 0; i < total; i++)
		r->trials_out[i].steps_run = 0;
	for (int g = 0; g < n_groups; g++)
		bsim_sweep_group_aggregate(&r->trials_out[(size_t)g * trials], trials,
		                           &r->groups[g]);
	return BSIM_OK;
}
