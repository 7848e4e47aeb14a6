/* trials.csv read back (beamsim regress compares a stored sweep with its
 * rerun through the file, so both sides have exactly the file's
 * precision). Columns are found by their header names: a file with more
 * columns than this reader knows, in any order, reads the same, and the
 * columns added later (final_ix, final_iy) may be missing from an older
 * file (they read as 0, which is what a gate scene writes). */
#define _POSIX_C_SOURCE 200809L

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/output.h"

/* The columns read, in this order in the col[] map. */
enum {
	C_GROUP,
	C_TRIAL,
	C_OUTCOME,
	C_TYPE,
	C_STEPS,
	C_T_END,
	C_X_END,
	C_Y_END,
	C_VX_END,
	C_MAX_THETA1,
	C_MAX_THETA2,
	C_FINAL_IX,
	C_FINAL_IY,
	N_COLUMNS
};
#define N_REQUIRED C_FINAL_IX

static const char *const column_names[N_COLUMNS] = {
        "group", "trial",  "outcome",    "type",       "steps",    "t_end",   "x_end",
        "y_end", "vx_end", "max_theta1", "max_theta2", "final_ix", "final_iy"};

static int name_index(const char *s, const char *const *names, int n)
{
	for (int i = 0; i < n; i++)
		if (strcmp(s, names[i]) == 0)
			return i;
	return -1;
}

/* Splits line at commas in place; returns the number of fields (at most
 * max; -1 if there are more). */
static int split(char *line, char **f, int max)
{
	int n = 0;
	for (char *c = line;;) {
		if (n == max)
			return -1;
		f[n++] = c;
		char *comma = strchr(c, ',');
		if (!comma)
			return n;
		*comma = '\0';
		c = comma + 1;
	}
}

#define FIELDS_MAX 256

/* The header into col[] (field index of each known column, -1 if absent);
 * 0 if every required column is there. */
static int parse_header(char *line, int *col, int *n_fields)
{
	char *f[FIELDS_MAX];
	int n = split(line, f, FIELDS_MAX);
	*n_fields = n;
	for (int c = 0; c < N_COLUMNS; c++)
		col[c] = -1;
	for (int i = 0; i < n; i++) {
		int c = name_index(f[i], column_names, N_COLUMNS);
		if (c >= 0 && col[c] < 0)
			col[c] = i;
	}
	for (int c = 0; c < N_REQUIRED; c++)
		if (col[c] < 0)
			return -1;
	return n > 0 ? 0 : -1;
}

static int parse_long(const char *s, long *out)
{
	char *end;
	*out = strtol(s, &end, 10);
	return *s && !*end ? 0 : -1;
}

/* One row into r; 0 on success. */
static int parse_row(char *line, const int *col, int n_fields, const bsim_sweep_result *r,
                     bsim_trial_result *all)
{
	static const char *const outcomes[] = {"traversed", "side_exit", "stuck"};
	static const char *const types[] = {"none", "left", "right"};
	char *f[FIELDS_MAX];
	if (split(line, f, FIELDS_MAX) != n_fields)
		return -1;
	long g, t, v;
	if (parse_long(f[col[C_GROUP]], &g) || g < 0 || g >= r->n_groups)
		return -1;
	if (parse_long(f[col[C_TRIAL]], &t) || t < 0 || t >= r->trials)
		return -1;
	bsim_trial_result *x = &all[g * r->trials + t];
	if (x->steps_run) /* seen already */
		return -1;
	int o = name_index(f[col[C_OUTCOME]], outcomes, 3);
	int ty = name_index(f[col[C_TYPE]], types, 3);
	if (o < 0 || ty < 0)
		return -1;
	x->outcome = (bsim_outcome)o;
	x->type = (bsim_type)ty;
	if (parse_long(f[col[C_STEPS]], &v))
		return -1;
	x->steps = (int)v;
	double *d[6] = {&x->t_end,  &x->x_end,        &x->y_end,
	                &x->vx_end, &x->max_theta[0], &x->max_theta[1]};
	for (int i = 0; i < 6; i++) {
		char *end;
		const char *s = f[col[C_T_END + i]];
		*d[i] = strtod(s, &end);
		if (!*s || *end)
			return -1;
	}
	int *gate[2] = {&x->final_ix, &x->final_iy};
	for (int i = 0; i < 2; i++) {
		if (col[C_FINAL_IX + i] < 0)
			continue;
		if (parse_long(f[col[C_FINAL_IX + i]], &v))
			return -1;
		*gate[i] = (int)v;
	}
	x->steps_run = 1; /* marks the row as read; not in the file */
	return 0;
}

int bsim_output_trials_read(const char *path, int n_groups, int trials, bsim_sweep_result *r,
                            bsim_error *err)
{
	memset(r, 0, sizeof *r);
	FILE *f = fopen(path, "r");
	if (!f)
		return bsim_error_set(err, BSIM_EINPUT, "%s: cannot read the file", path);
	size_t total = (size_t)n_groups * (size_t)trials;
	r->n_groups = n_groups;
	r->trials = trials;
	r->trials_out = calloc(total ? total : 1, sizeof *r->trials_out);
	r->groups = calloc(n_groups > 0 ? (size_t)n_groups : 1, sizeof *r->groups);
	if (!r->trials_out || !r->groups) {
		fclose(f);
		bsim_sweep_result_free(r);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory for %zu trials", total);
	}
	char *line = NULL;
	size_t cap = 0;
	int lineno = 0, rc = BSIM_OK, col[N_COLUMNS], n_fields = 0;
	size_t rows = 0;
	while (rc == BSIM_OK && getline(&line, &cap, f) > 0) {
		lineno++;
		line[strcspn(line, "\r\n")] = '\0';
		if (lineno == 1) {
			if (parse_header(line, col, &n_fields) != 0)
				rc = bsim_error_set(
				        err, BSIM_EINPUT,
				        "%s:1: expected a header with the columns "
				        "group,trial,outcome,type,steps,t_end,x_end,y_end,"
				        "vx_end,max_theta1,max_theta2",
				        path);
			continue;
		}
		if (parse_row(line, col, n_fields, r, r->trials_out) != 0)
			rc = bsim_error_set(err, BSIM_EINPUT,
			                    "%s:%d: expected a row group,trial,... of %d groups x "
			                    "%d trials, each once",
			                    path, lineno, n_groups, trials);
		rows++;
	}
	free(line);
	fclose(f);
	if (rc == BSIM_OK && lineno == 0)
		rc = bsim_error_set(err, BSIM_EINPUT, "%s: expected a header, got an empty file",
		                    path);
	if (rc == BSIM_OK && rows != total)
		rc = bsim_error_set(err, BSIM_EINPUT, "%s: expected %zu rows, got %zu", path, total,
		                    rows);
	if (rc != BSIM_OK) {
		bsim_sweep_result_free(r);
		return rc;
	}
	for (size_t i = 0; i < total; i++)
		r->trials_out[i].steps_run = 0;
	for (int g = 0; g < n_groups; g++)
		bsim_group_aggregate(&r->trials_out[(size_t)g * trials], trials, &r->groups[g]);
	return BSIM_OK;
}
