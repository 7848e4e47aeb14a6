/* trials.csv read back (beamsim regress compares a stored sweep with its
 * rerun through the file, so both sides have exactly the file's
 * precision; compare reads a side's trials made elsewhere from one).
 * Columns are found by their header name, so a file with more columns than
 * this version writes, or one written before the energy columns, the
 * lattice's final gate (final_ix, final_iy; 0 when absent, what a gate
 * scene writes), the solver's counts (iteration_limits, clamps; 0 when
 * absent) or the body's turn (heading_end, ...; all four or none, 0 when
 * absent, r->has_turn 0, so that a comparison leaves them out) existed,
 * reads the same. t_exit is not read: it is t_end for an exit and empty
 * otherwise, so outcome and t_end give it. Every refusal names the file,
 * the line and the field, and what was expected there. */
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

/* The most fields a row may have. */
#define MAX_FIELDS 256

/* One file being read: where, the shape it must have, its columns. */
typedef struct reader {
	const char *path;
	const trials_csv_shape *shape;
	bsim_sweep_result *r;
	int col[N_COLUMNS]; /* the field index of each column, -1 if the file has none */
	int n_fields;
	int line;
} reader;

static const char *column_name(int k)
{
	return bsim_trials_csv_column(column_of[k]);
}

/* The column k of this reader whose name s is, or -1. */
static int column_index(const char *s)
{
	for (int k = 0; k < N_COLUMNS; k++)
		if (strcmp(s, column_name(k)) == 0)
			return k;
	return -1;
}

/* "FILE:LINE: FIELD: expected WHAT, got 'TEXT'" */
static int field_error(const reader *rd, int k, const char *expected, const char *got,
                       bsim_error *err)
{
	return bsim_error_set(err, BSIM_EINPUT, "%s:%d: %s: expected %s, got '%s'", rd->path,
	                      rd->line, column_name(k), expected, got);
}

static int parse_double(const char *s, double *out)
{
	char *end;
	*out = strtod(s, &end);
	return *s && !*end ? 0 : -1;
}

/* Field k of a row as an integer in [lo, hi]; expected says so. */
static int int_field(const reader *rd, char **f, int k, long lo, long hi, const char *expected,
                     long *out, bsim_error *err)
{
	const char *s = f[rd->col[k]];
	char *end;
	*out = strtol(s, &end, 10);
	if (!*s || *end || *out < lo || *out > hi)
		return field_error(rd, k, expected, s, err);
	return BSIM_OK;
}

/* Field k as a number (strtod's, the whole text). */
static int number_field(const reader *rd, char **f, int k, double *out, bsim_error *err)
{
	const char *s = f[rd->col[k]];
	return parse_double(s, out) ? field_error(rd, k, "a number", s, err) : BSIM_OK;
}

/* Field k as one of n words names(i); its index into *out. */
static int word_field(const reader *rd, char **f, int k, int n, const char *(*name)(int), int *out,
                      bsim_error *err)
{
	const char *s = f[rd->col[k]];
	for (int i = 0; i < n; i++)
		if (strcmp(s, name(i)) == 0) {
			*out = i;
			return BSIM_OK;
		}
	char expected[128] = "one of ";
	for (int i = 0; i < n; i++) {
		strncat(expected, name(i), sizeof expected - strlen(expected) - 1);
		if (i + 1 < n)
			strncat(expected, ", ", sizeof expected - strlen(expected) - 1);
	}
	return field_error(rd, k, expected, s, err);
}

/* Columns first .. end - 1 (each of them the file has, every one if all)
 * into their members of x (beamsim/trial_fields.h: back, back_size): a
 * REAL as a number, an INT as an integer from lo to the member's largest
 * (expected says so). */
static int member_fields(const reader *rd, char **f, int first, int end, bsim_trial_result *x,
                         long lo, const char *expected, bsim_error *err)
{
	int n;
	const bsim_trial_field *table = bsim_trial_fields(&n);
	for (int k = first; k < end; k++) {
		const bsim_trial_field *fd = &table[column_of[k]];
		char *at = (char *)x + fd->back;
		long v;
		if (rd->col[k] < 0 || fd->back_size == 0)
			continue;
		if (fd->kind == BSIM_FIELD_REAL) {
			if (number_field(rd, f, k, (double *)at, err))
				return BSIM_EINPUT;
			continue;
		}
		int small = fd->back_size == sizeof(int);
		if (int_field(rd, f, k, lo, small ? 0x7fffffffL : 0x7fffffffffffffffL, expected, &v,
		              err))
			return BSIM_EINPUT;
		if (small)
			*(int *)at = (int)v;
		else
			*(long *)at = v;
	}
	return BSIM_OK;
}

static const char *outcome_word(int i)
{
	return bsim_trial_outcome_name((bsim_outcome)i);
}

static const char *type_word(int i)
{
	return bsim_trial_type_name((bsim_type)i);
}

/* One row into its slot of rd->r. A slot's steps_run holds the line it was
 * read from while the file is read (0: none yet), then 0 again. */
static int parse_row(const reader *rd, char **f, int n, bsim_error *err)
{
	if (n < 0)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s:%d: expected %d fields as the header names, got a "
		                      "quote that does not close",
		                      rd->path, rd->line, rd->n_fields);
	if (n != rd->n_fields)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s:%d: expected %d fields as the header names, got %d",
		                      rd->path, rd->line, rd->n_fields, n);
	const bsim_sweep_result *r = rd->r;
	char expected[96];
	long g, t;
	snprintf(expected, sizeof expected, "an integer 0 to %d (the experiment's %d groups)",
	         r->n_groups - 1, r->n_groups);
	if (int_field(rd, f, COL_GROUP, 0, r->n_groups - 1, expected, &g, err))
		return BSIM_EINPUT;
	snprintf(expected, sizeof expected, "an integer 0 to %d (%d trials a group)", r->trials - 1,
	         r->trials);
	if (int_field(rd, f, COL_TRIAL, 0, r->trials - 1, expected, &t, err))
		return BSIM_EINPUT;
	bsim_trial_result *x = &r->trials_out[g * r->trials + t];
	if (x->steps_run)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s:%d: group %ld, trial %ld: expected once, already on "
		                      "line %d",
		                      rd->path, rd->line, g, t, x->steps_run);
	int o = 0, ty = 0;
	if (word_field(rd, f, COL_OUTCOME, BSIM_N_OUTCOMES, outcome_word, &o, err) ||
	    word_field(rd, f, COL_TYPE, 3, type_word, &ty, err))
		return BSIM_EINPUT;
	/* A type says which beam a traversal went over: beamsim writes none
	 * for every other outcome, and a pair is compared by both. */
	if (rd->shape->type_rule && o != BSIM_TRAVERSED && ty != BSIM_TYPE_NONE) {
		snprintf(expected, sizeof expected,
		         "none for outcome %s (only a traversal has a type)", outcome_word(o));
		return field_error(rd, COL_TYPE, expected, f[rd->col[COL_TYPE]], err);
	}
	x->outcome = (bsim_outcome)o;
	x->type = (bsim_type)ty;
	/* The ledger's split columns come back as the ledger's first entry
	 * of each sum: enough to compare two files field by field. */
	if (member_fields(rd, f, COL_STEPS, COL_T_END, x, 0, "an integer >= 0", err) ||
	    member_fields(rd, f, COL_T_END, LEDGER_END, x, 0, "a number", err) ||
	    member_fields(rd, f, COL_FINAL_IX, COL_ITERATION_LIMITS, x, -0x7fffffffL, "an integer",
	                  err) ||
	    member_fields(rd, f, COL_ITERATION_LIMITS, COL_HEADING_END, x, 0, "an integer >= 0",
	                  err) ||
	    member_fields(rd, f, COL_HEADING_END, N_COLUMNS, x, 0, "a number", err))
		return BSIM_EINPUT;
	x->steps_run = rd->line; /* marks the row as read; not in the file */
	return BSIM_OK;
}

/* The columns first .. end - 1 of this reader the header has: all or
 * none; else the first missing one's index into *missing. */
static int all_or_none(const int *col, int first, int end, int *missing)
{
	int have = 0;
	*missing = -1;
	for (int k = first; k < end; k++) {
		have += col[k] >= 0;
		if (col[k] < 0 && *missing < 0)
			*missing = k;
	}
	return have == 0 || have == end - first ? 0 : -1;
}

/* The names of columns first .. end - 1, comma-separated, into buf. */
static void column_list(int first, int end, char *buf, size_t size)
{
	buf[0] = '\0';
	for (int k = first; k < end; k++) {
		strncat(buf, column_name(k), size - strlen(buf) - 1);
		if (k + 1 < end)
			strncat(buf, ", ", size - strlen(buf) - 1);
	}
}

/* The header: every required column once; the ledger's columns, and the
 * turn's, all or none; a lattice's final gate when the shape asks. */
static int read_header(reader *rd, char *line, bsim_error *err)
{
	char *f[MAX_FIELDS], names[400];
	int n = bsim_csv_split(line, f, MAX_FIELDS);
	for (int k = 0; k < N_COLUMNS; k++)
		rd->col[k] = -1;
	if (n <= 0 || (n == 1 && !f[0][0]))
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s:1: expected a header of column names, got %s", rd->path,
		                      n < 0 ? "a quote that does not close" : "an empty line");
	for (int i = 0; i < n && i < MAX_FIELDS; i++) {
		int k = column_index(f[i]);
		if (k >= 0 && rd->col[k] >= 0)
			return bsim_error_set(err, BSIM_EINPUT,
			                      "%s:1: column %s: expected once, got it as fields %d "
			                      "and %d",
			                      rd->path, f[i], rd->col[k] + 1, i + 1);
		if (k >= 0)
			rd->col[k] = i;
	}
	column_list(0, N_REQUIRED, names, sizeof names);
	for (int k = 0; k < N_REQUIRED; k++)
		if (rd->col[k] < 0)
			return bsim_error_set(err, BSIM_EINPUT,
			                      "%s:1: column %s: expected a header naming each of "
			                      "%s (beamsim's trials.csv; docs/files.md), none "
			                      "named %s",
			                      rd->path, column_name(k), names, column_name(k));
	static const int groups[2][2] = {{N_REQUIRED, LEDGER_END}, {COL_HEADING_END, N_COLUMNS}};
	for (int i = 0; i < 2; i++) {
		int missing;
		if (all_or_none(rd->col, groups[i][0], groups[i][1], &missing) == 0)
			continue;
		column_list(groups[i][0], groups[i][1], names, sizeof names);
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s:1: column %s: expected %s all or none, got some "
		                      "without it",
		                      rd->path, column_name(missing), names);
	}
	for (int k = COL_FINAL_IX; rd->shape->need_final_gate && k <= COL_FINAL_IY; k++)
		if (rd->col[k] < 0)
			return bsim_error_set(
			        err, BSIM_EINPUT,
			        "%s:1: column %s: expected on a gate lattice (each "
			        "trial's final gate, final_ix and final_iy, which the "
			        "comparison tests), none",
			        rd->path, column_name(k));
	rd->n_fields = n;
	return BSIM_OK;
}

/* The rows of a group whose trial 0 stands for every trial
 * (shape->one_trial): each must agree with trial 0 in what a comparison
 * compares, as the copies a sweep writes do. */
static int one_trial_check(const reader *rd, int g, bsim_error *err)
{
	const bsim_sweep_result *r = rd->r;
	const bsim_trial_result *first = &r->trials_out[(size_t)g * r->trials];
	for (int t = 1; t < r->trials; t++) {
		const bsim_trial_result *x = &first[t];
		int k = x->outcome != first->outcome     ? COL_OUTCOME
		        : x->type != first->type         ? COL_TYPE
		        : x->final_ix != first->final_ix ? COL_FINAL_IX
		        : x->final_iy != first->final_iy ? COL_FINAL_IY
		                                         : -1;
		if (k < 0)
			continue;
		char want[32], got[32];
		if (k == COL_OUTCOME || k == COL_TYPE) {
			snprintf(want, sizeof want, "%s",
			         k == COL_OUTCOME ? outcome_word(first->outcome)
			                          : type_word(first->type));
			snprintf(got, sizeof got, "%s",
			         k == COL_OUTCOME ? outcome_word(x->outcome) : type_word(x->type));
		} else {
			snprintf(want, sizeof want, "%d",
			         k == COL_FINAL_IX ? first->final_ix : first->final_iy);
			snprintf(got, sizeof got, "%d",
			         k == COL_FINAL_IX ? x->final_ix : x->final_iy);
		}
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s:%d: %s: expected %s as trial 0 of group %d (line %d): "
		                      "the group draws no random force, so each of its trials is "
		                      "its trial 0; got '%s'",
		                      rd->path, x->steps_run, column_name(k), want, g,
		                      first->steps_run, got);
	}
	return BSIM_OK;
}

/* Every (group, trial) read (rows of them), else the count and the first
 * missing one named; then each group of shape->one_trial checked. */
static int rows_complete(const reader *rd, long rows, bsim_error *err)
{
	const bsim_sweep_result *r = rd->r;
	const int *one = rd->shape->one_trial;
	for (int g = 0; g < r->n_groups; g++)
		for (int t = 0; t < r->trials; t++) {
			if (r->trials_out[(size_t)g * r->trials + t].steps_run)
				continue;
			return bsim_error_set(
			        err, BSIM_EINPUT,
			        "%s:%d: expected %ld rows (the experiment's %d groups x %d "
			        "trials), "
			        "got %ld by the end of the file: group %d, trial %d: none%s",
			        rd->path, rd->line, (long)r->n_groups * r->trials, r->n_groups,
			        r->trials, rows, g, t,
			        one && one[g]
			                ? " (a group without random force too: its trials are "
			                  "copies of its trial 0, as a sweep writes them)"
			                : "");
		}
	for (int g = 0; one && g < r->n_groups; g++)
		if (one[g] && one_trial_check(rd, g, err) != BSIM_OK)
			return BSIM_EINPUT;
	return BSIM_OK;
}

int bsim_trials_csv_parse(const char *path, char *text, const trials_csv_shape *shape,
                          bsim_sweep_result *r, bsim_error *err)
{
	memset(r, 0, sizeof *r);
	int n_groups = shape->n_groups, trials = shape->trials;
	size_t total = (size_t)n_groups * (size_t)trials;
	r->n_groups = n_groups;
	r->trials = trials;
	r->trials_out = calloc(total ? total : 1, sizeof *r->trials_out);
	r->groups = calloc(n_groups > 0 ? (size_t)n_groups : 1, sizeof *r->groups);
	if (!r->trials_out || !r->groups) {
		bsim_sweep_result_free(r);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory for %zu trials", total);
	}
	reader rd = {.path = path, .shape = shape, .r = r};
	char *next = text, *field[MAX_FIELDS];
	int rc = BSIM_OK;
	long rows = 0;
	while (rc == BSIM_OK && *next) {
		char *line = next;
		char *nl = strchr(line, '\n'); /* there is one: bsim_csv_text_check */
		*nl = '\0';
		next = nl + 1;
		rd.line++;
		line[strcspn(line, "\r")] = '\0';
		if (rd.line == 1) {
			rc = read_header(&rd, line, err);
			r->has_ledger = rd.col[COL_E_START] >= 0;
			r->has_turn = rd.col[COL_HEADING_END] >= 0;
			continue;
		}
		rc = parse_row(&rd, field, bsim_csv_split(line, field, MAX_FIELDS), err);
		rows++;
	}
	if (rc == BSIM_OK && rd.line == 0)
		rc = bsim_error_set(err, BSIM_EINPUT, "%s: empty file, expected a header", path);
	if (rc == BSIM_OK)
		rc = rows_complete(&rd, rows, err);
	if (rc != BSIM_OK) {
		bsim_sweep_result_free(r);
		return rc;
	}
	for (size_t i = 0; i < total; i++)
		r->trials_out[i].steps_run = 0;
	for (int g = 0; g < n_groups; g++) {
		bsim_sweep_group_aggregate(&r->trials_out[(size_t)g * trials], trials,
		                           &r->groups[g]);
		r->groups[g].deterministic = shape->one_trial && shape->one_trial[g];
	}
	return BSIM_OK;
}

int bsim_output_trials_read(const char *path, int n_groups, int trials, bsim_sweep_result *r,
                            bsim_error *err)
{
	memset(r, 0, sizeof *r);
	/* A regular file only (a link to /dev/zero or a FIFO is refused at
	 * once), bounded, and whole: its last row ends in a line feed. */
	file_text ft;
	int rc = bsim_csv_text_read(path, &ft, err);
	if (rc != BSIM_OK)
		return rc;
	trials_csv_shape shape = {.n_groups = n_groups, .trials = trials};
	rc = bsim_trials_csv_parse(path, ft.text, &shape, r, err);
	bsim_file_text_free(&ft);
	return rc;
}
