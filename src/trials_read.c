/* trials.csv read back (beamsim regress compares a stored sweep with its
 * rerun through the file, so both sides have exactly the file's
 * precision). */
#define _POSIX_C_SOURCE 200809L

#include <stdlib.h>
#include <string.h>

#include "beamsim/output.h"

static const char header[] =
        "group,trial,outcome,type,steps,t_end,x_end,y_end,vx_end,max_theta1,max_theta2";

static int name_index(const char *s, const char *const *names, int n)
{
	for (int i = 0; i < n; i++)
		if (strcmp(s, names[i]) == 0)
			return i;
	return -1;
}

/* One row into r; 0 on success. */
static int parse_row(char *line, const bsim_sweep_result *r, bsim_trial_result *all)
{
	static const char *const outcomes[] = {"traversed", "side_exit", "stuck"};
	static const char *const types[] = {"none", "left", "right"};
	char *f[11], *save = NULL;
	int n = 0;
	for (char *tok = strtok_r(line, ",", &save); tok && n < 11;
	     tok = strtok_r(NULL, ",", &save))
		f[n++] = tok;
	if (n != 11 || strtok_r(NULL, ",", &save))
		return -1;
	char *end;
	long g = strtol(f[0], &end, 10);
	if (*end || g < 0 || g >= r->n_groups)
		return -1;
	long t = strtol(f[1], &end, 10);
	if (*end || t < 0 || t >= r->trials)
		return -1;
	bsim_trial_result *x = &all[g * r->trials + t];
	if (x->steps_run) /* seen already */
		return -1;
	int o = name_index(f[2], outcomes, 3), ty = name_index(f[3], types, 3);
	if (o < 0 || ty < 0)
		return -1;
	x->outcome = (bsim_outcome)o;
	x->type = (bsim_type)ty;
	x->steps = (int)strtol(f[4], &end, 10);
	if (*end)
		return -1;
	double *v[6] = {&x->t_end,  &x->x_end,        &x->y_end,
	                &x->vx_end, &x->max_theta[0], &x->max_theta[1]};
	for (int i = 0; i < 6; i++) {
		*v[i] = strtod(f[5 + i], &end);
		if (*end)
			return -1;
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
	char line[1024];
	int lineno = 0, rc = BSIM_OK;
	size_t rows = 0;
	while (rc == BSIM_OK && fgets(line, sizeof line, f)) {
		lineno++;
		line[strcspn(line, "\r\n")] = '\0';
		if (lineno == 1) {
			if (strcmp(line, header) != 0)
				rc = bsim_error_set(err, BSIM_EINPUT,
				                    "%s:1: expected the header %s", path, header);
			continue;
		}
		if (parse_row(line, r, r->trials_out) != 0)
			rc = bsim_error_set(err, BSIM_EINPUT,
			                    "%s:%d: expected a row group,trial,... of %d groups x "
			                    "%d trials, each once",
			                    path, lineno, n_groups, trials);
		rows++;
	}
	fclose(f);
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
