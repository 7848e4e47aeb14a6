/* The output files of a sweep (docs/files.md "Outputs of
 * `sweep --out DIR`"): summary.json, trials.csv and the p_traverse table.
 * Both files go through bsim_atomic_file, so a reader never sees a torn
 * one. */
#define _POSIX_C_SOURCE 200809L

#include "beamsim/output.h"

#include <errno.h>
#include <math.h>
#include <inttypes.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "beamsim/backend_registry.h"
#include "util/atomic_file.h"
#include "store/survival_files.h"
#include "store/matlab.h"
#include "store/trials_csv.h"
#include "store/lattice_files.h"
#include "util/csv_table.h"
#include "util/json.h"
#include "beamsim/lattice.h"
#include "beamsim/version.h"
#include "beamsim/lattice_outcome.h"

/* A grid value is a JSON number when its YAML text is a finite number. */
static int text_number(const char *s, double *out)
{
	char *end;
	while (*s == ' ' || *s == '\t')
		s++;
	if (*s == '\0')
		return 0;
	errno = 0;
	*out = strtod(s, &end);
	while (*end == ' ' || *end == '\t')
		end++;
	return errno == 0 && *end == '\0' && isfinite(*out);
}

/* "key": "value", after a comma unless it is the first member. */
static void json_member(FILE *f, int *first, const char *key, const char *value)
{
	fputs(*first ? "" : ", ", f);
	bsim_json_string(f, key);
	fputs(": ", f);
	bsim_json_string(f, value);
	*first = 0;
}

/* 1 if s is a number as JSON writes one: -?(0|[1-9][0-9]*)(.[0-9]+)?([eE][+-]?[0-9]+)? */
static int json_number_text(const char *s)
{
	const char *p = s + (*s == '-');
	if (*p == '0')
		p++;
	else if (*p >= '1' && *p <= '9')
		p += strspn(p, "0123456789");
	else
		return 0;
	if (*p == '.') {
		size_t n = strspn(p + 1, "0123456789");
		if (n == 0)
			return 0;
		p += 1 + n;
	}
	if (*p == 'e' || *p == 'E') {
		p += 1 + (p[1] == '+' || p[1] == '-');
		size_t n = strspn(p, "0123456789");
		if (n == 0)
			return 0;
		p += n;
	}
	return *p == '\0';
}

/* A knob's value: a number where the knob is a number (as given, if JSON
 * can read it so: "1e-6" stays 1e-6), else a string. */
static void json_knob(FILE *f, int *first, const bsim_knob *k, const char *value)
{
	double x;
	if (k->type == BSIM_KNOB_CHOICE || !text_number(value, &x)) {
		json_member(f, first, k->name, value);
		return;
	}
	fputs(*first ? "" : ", ", f);
	bsim_json_string(f, k->name);
	fputs(": ", f);
	if (json_number_text(value))
		fputs(value, f);
	else
		bsim_json_number(f, x);
	*first = 0;
}

/* Knobs first, in the backend's order, so records of one backend line up
 * (a knob without a default value, not given, is left out: its absence is
 * its default, as in bsim_options_effective); then any option the backend
 * does not list (none once checked), so nothing given is hidden. */
void bsim_output_backend_options(FILE *f, const bsim_backend *b, const bsim_options *opts)
{
	int first = 1;
	fputc('{', f);
	for (int i = 0; b && i < b->n_knobs; i++) {
		const char *v = bsim_options_get(opts, b->knobs[i].name);
		if (!v)
			v = b->knobs[i].default_value;
		if (v)
			json_knob(f, &first, &b->knobs[i], v);
	}
	for (int i = 0; opts && i < opts->n; i++) {
		int known = 0;
		for (int j = 0; b && j < b->n_knobs; j++)
			known |= strcmp(b->knobs[j].name, opts->key[i]) == 0;
		if (!known)
			json_member(f, &first, opts->key[i], opts->value[i]);
	}
	fputc('}', f);
}

static void json_params(FILE *f, const bsim_experiment *e, const int *idx)
{
	fputc('{', f);
	for (int a = 0; a < e->n_axes; a++) {
		const char *text = e->axes[a].values[idx[a]];
		double x;
		fputs(a ? ", " : "", f);
		bsim_json_string(f, e->axes[a].key);
		fputs(": ", f);
		if (text_number(text, &x))
			bsim_json_number(f, x);
		else
			bsim_json_string(f, text);
	}
	fputc('}', f);
}

void bsim_output_group_params(FILE *f, const bsim_experiment *e, int g)
{
	int idx[BSIM_OUTPUT_AXES_MAX];
	if (e->n_axes > BSIM_OUTPUT_AXES_MAX) {
		fputs("{}", f);
		return;
	}
	bsim_experiment_group_index(e, g, idx);
	json_params(f, e, idx);
}

/* A lattice group's final-location distribution, transitions and time per
 * row (beamsim/lattice.h). */
static void json_lattice(FILE *f, const bsim_sweep_result *r, int group)
{
	bsim_lattice_summary own, *s = &own;
	if (bsim_lattice_group_summary(r, group, &s) != BSIM_OK) {
		fputs(", \"lattice\": null", f);
		return;
	}
	const bsim_lattice_summary ls = *s;
	fputs(", \"lattice\": {\"final_locations\": [", f);
	for (int k = 0; k < ls.n_locations; k++) {
		const bsim_location_count *c = &ls.locations[k];
		char label[48];
		bsim_lattice_location_label(c->loc, label, sizeof label);
		static const char *const kinds[] = {"end", "side", "stuck"};
		fprintf(f, "%s{\"location\": \"%s\", \"kind\": \"%s\", \"ix\": ", k ? ", " : "",
		        label, kinds[c->loc.kind]);
		if (c->loc.kind == BSIM_LOCATION_SIDE)
			fputs("null", f);
		else
			fprintf(f, "%d", c->loc.ix);
		fputs(", \"iy\": ", f);
		if (c->loc.kind == BSIM_LOCATION_END)
			fputs("null", f);
		else
			fprintf(f, "%d", c->loc.iy);
		fprintf(f, ", \"count\": %d, \"p\": ", c->count);
		bsim_json_number(f, c->p);
		fputs(", \"ci95\": [", f);
		bsim_json_number(f, c->ci95[0]);
		fputs(", ", f);
		bsim_json_number(f, c->ci95[1]);
		fputs("]}", f);
	}
	fputs("], \"transitions\": [", f);
	for (int k = 0; k < ls.n_transitions; k++) {
		const bsim_transition *x = &ls.transitions[k];
		fprintf(f, "%s{\"from\": [%d, %d], \"to\": [%d, %d], \"count\": %d}", k ? ", " : "",
		        x->from[0], x->from[1], x->to[0], x->to[1], x->count);
	}
	fputs("], \"rows\": [", f);
	for (int iy = 0; iy < ls.rows; iy++) {
		fprintf(f, "%s{\"iy\": %d, \"trials\": %d, \"mean_time_s\": ", iy ? ", " : "", iy,
		        ls.row_trials[iy]);
		if (ls.row_trials[iy] > 0)
			bsim_json_number(f, ls.row_time[iy]);
		else
			fputs("null", f);
		fputc('}', f);
	}
	fputs("]}", f);
	if (s == &own)
		bsim_lattice_summary_free(&own);
}

/* What the backend's solvers gave up on (beamsim/state.h). */
#define JSON_COUNT(m) BSIM_JSON_MEMBER(f, sep, c, m);

static void json_solver(FILE *f, const bsim_solver_counts *c)
{
	const char *sep = "";
	fputs(", \"solver\": {", f);
	BSIM_SOLVER_COUNTS(JSON_COUNT)
	fputc('}', f);
}

#define JSON_GROUP(m) BSIM_JSON_MEMBER(f, sep, g, m);

static void json_group(FILE *f, const bsim_experiment *e, const bsim_sweep_result *r, int group,
                       int *idx)
{
	const bsim_group_result *g = &r->groups[group];
	fputs("{\"params\": ", f);
	json_params(f, e, idx);
	const char *sep = ", ";
	BSIM_GROUP_RESULT_COUNTS(JSON_GROUP)
	fprintf(f, ", \"deterministic\": %s", g->deterministic ? "true" : "false");
	json_solver(f, &g->solver);
	BSIM_GROUP_RESULT_SOLVER_TRIALS(JSON_GROUP)
	/* how far a group's bodies turned (a body that rotates): the mean
	 * final turn (a bias to one side), the mean and largest of its size,
	 * and the largest turn during a trial, rad */
	if (g->rotates) {
		BSIM_GROUP_RESULT_TURN(JSON_GROUP)
	}
	if (r->lattice)
		json_lattice(f, r, group);
	fputc('}', f);
}

/* An index per grid axis for bsim_experiment_group_index; never a
 * zero-size calloc, so NULL always means out of memory. */
static int *group_index_alloc(const bsim_experiment *e)
{
	return calloc(e->n_axes > 0 ? (size_t)e->n_axes : 1, sizeof(int));
}

/* One group per line: the file stays small, diffs line up with groups, and
 * the wall_seconds line is the only one that differs between equal runs. */
static void json_groups(FILE *f, const bsim_experiment *e, const bsim_sweep_result *r, int *idx)
{
	fputs(",\n  \"groups\": [", f);
	for (int g = 0; g < r->n_groups; g++) {
		bsim_experiment_group_index(e, g, idx);
		fputs(g ? ",\n    " : "\n    ", f);
		json_group(f, e, r, g, idx);
	}
	fputs("\n  ]", f);
}

static void json_summary(FILE *f, const bsim_experiment *e, const char *backend,
                         const bsim_options *opts, const bsim_sweep_result *r, int *idx)
{
	fputs("{\n  \"backend\": ", f);
	bsim_json_string(f, backend);
	fputs(",\n  \"backend_options\": ", f);
	bsim_output_backend_options(f, bsim_backend_find(backend, NULL), opts);
	fputs(",\n  \"experiment\": ", f);
	bsim_json_string(f, e->path);
	fputs(",\n  \"seed\": ", f);
	bsim_json_u64(f, e->seed);
	fprintf(f, ",\n  \"trials_per_group\": %d", r->trials);
	fprintf(f, ",\n  \"wall_seconds\": %.3f", r->wall_seconds);
	json_groups(f, e, r, idx);
	fputs(",\n  \"totals\": {\"steps\": ", f);
	fprintf(f, "%ld, \"trials_run\": %ld", r->total_steps, r->trials_run);
	json_solver(f, &r->solver);
	fputc('}', f);
	fputs(",\n  \"version\": ", f);
	bsim_json_string(f, BSIM_VERSION);
	fputs(",\n  \"scene\": ", f);
	bsim_json_string(f, e->scene_path);
	fputs("\n}\n", f);
}

int bsim_output_summary_json(const char *path, const bsim_experiment *e, const char *backend,
                             const bsim_options *opts, const bsim_sweep_result *r, bsim_error *err)
{
	bsim_atomic_file o;
	if (bsim_atomic_file_open(&o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	int *idx = group_index_alloc(e);
	if (!idx) {
		bsim_atomic_file_abort(&o);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	json_summary(o.f, e, backend, opts, r, idx);
	free(idx);
	return bsim_atomic_file_commit(&o, err);
}

/* ---- trials.csv -------------------------------------------------------- */

const char *bsim_trials_csv_column(int k)
{
	int n;
	const bsim_trial_field *f = bsim_trial_fields(&n);
	return k >= 0 && k < n ? f[k].name : "?";
}

int bsim_trials_csv_open(trials_csv_writer *w, const char *path, const bsim_experiment *e, int twin,
                         bsim_error *err)
{
	memset(w, 0, sizeof *w);
	if (bsim_atomic_file_open(&w->o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	w->e = e;
	w->axes = e && e->n_axes <= BSIM_OUTPUT_AXES_MAX ? e->n_axes : 0;
	if (twin && e && !(w->twin = bsim_matlab_trials_open(e, w->axes))) {
		bsim_atomic_file_abort(&w->o);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory for %s's twin", path);
	}
	w->group = -1;
	for (int c = 0; c < TRIALS_N_COLUMNS; c++)
		fprintf(w->o.f, "%s%s", c ? "," : "", bsim_trials_csv_column(c));
	for (int a = 0; a < w->axes; a++) {
		fputc(',', w->o.f);
		bsim_csv_field_write(w->o.f, e->axes[a].key);
	}
	fputc('\n', w->o.f);
	return BSIM_OK;
}

void bsim_trials_csv_rows(trials_csv_writer *w, long first, long n, int trials,
                          const bsim_trial_result *results, const bsim_trial_log *logs)
{
	FILE *f = w->o.f;
	int n_fields;
	const bsim_trial_field *fields = bsim_trial_fields(&n_fields);
	if (w->twin)
		bsim_matlab_trials_rows(w->twin, first, n, trials, results, logs);
	for (long k = 0; k < n; k++) {
		int g = (int)((first + k) / trials), t = (int)((first + k) % trials);
		if (w->axes && g != w->group)
			bsim_experiment_group_index(w->e, g, w->idx);
		w->group = g;
		const bsim_trial_row row = {g, t, &results[k], logs ? &logs[k] : NULL, 0, NULL};
		for (int c = 0; c < n_fields; c++) {
			if (c)
				fputc(',', f);
			bsim_trial_field_write(f, &fields[c], &row);
		}
		for (int a = 0; a < w->axes; a++) {
			fputc(',', f);
			bsim_csv_field_write(f, w->e->axes[a].values[w->idx[a]]);
		}
		fputc('\n', f);
	}
}

int bsim_trials_csv_commit(trials_csv_writer *w, bsim_error *err)
{
	const char *path = w->o.path;
	int rc = bsim_atomic_file_commit(&w->o, err);
	if (rc == BSIM_OK && w->twin)
		rc = bsim_matlab_trials_write(w->twin, path, err);
	bsim_matlab_trials_free(w->twin);
	w->twin = NULL;
	return rc;
}

void bsim_trials_csv_abort(trials_csv_writer *w)
{
	bsim_atomic_file_abort(&w->o);
	bsim_matlab_trials_free(w->twin);
	w->twin = NULL;
}

static int trials_csv_write(const char *path, const bsim_experiment *e, const bsim_sweep_result *r,
                            int twin, bsim_error *err)
{
	trials_csv_writer w;
	if (bsim_trials_csv_open(&w, path, e, twin, err) != BSIM_OK)
		return BSIM_EFAIL;
	for (int g = 0; g < r->n_groups; g++)
		bsim_trials_csv_rows(&w, (long)g * r->trials, r->trials, r->trials,
		                     &r->trials_out[(size_t)g * r->trials],
		                     r->logs ? &r->logs[(size_t)g * r->trials] : NULL);
	return bsim_trials_csv_commit(&w, err);
}

int bsim_output_trials_csv(const char *path, const bsim_experiment *e, const bsim_sweep_result *r,
                           bsim_error *err)
{
	return trials_csv_write(path, e, r, 0, err);
}

int bsim_trials_csv_write(const char *path, const bsim_experiment *e, const bsim_sweep_result *r,
                          bsim_error *err)
{
	return trials_csv_write(path, e, r, 1, err);
}

int bsim_output_trials_fit(const bsim_experiment *e, long trials, double cell_bytes,
                           bsim_error *err)
{
	double rows = (double)e->n_groups * (double)(trials > 0 ? trials : e->trials);
	int columns = TRIALS_N_COLUMNS + e->n_axes;
	double need = rows * columns * cell_bytes, have = bsim_memory_available();
	if (need <= have)
		return BSIM_OK;
	return bsim_error_set(err, BSIM_EINPUT,
	                      "%s: expected trials that fit in memory as columns: %.15g trials "
	                      "x %d columns x %.15g bytes = %.3g GB, and %.3g GB is available "
	                      "(beamsim sweep writes trials.csv without holding it)",
	                      e->path, rows, columns, cell_bytes, need / 1e9, have / 1e9);
}

/* ---- the p_traverse table ------------------------------------------------ */

/* Where each group sits in the tables: cell[(rest * n1 + i1) * n0 + i0] is
 * the group at axis-0 value i0, axis-1 value i1 and index rest over the
 * remaining axes (axis 2 slowest). Built from bsim_experiment_group_index,
 * so it does not assume an order of groups. */
typedef struct table_layout {
	int n0, n1, n_rest;
	int *cell;
} table_layout;

static int layout_build(table_layout *l, const bsim_experiment *e)
{
	l->n0 = e->n_axes > 0 ? e->axes[0].n_values : 1;
	l->n1 = e->n_axes > 1 ? e->axes[1].n_values : 1;
	l->n_rest = 1;
	for (int a = 2; a < e->n_axes; a++)
		l->n_rest *= e->axes[a].n_values;
	size_t n = (size_t)l->n0 * l->n1 * l->n_rest;
	int *idx = group_index_alloc(e);
	l->cell = malloc(n * sizeof *l->cell);
	if (!idx || !l->cell) {
		free(idx);
		free(l->cell);
		return -1;
	}
	for (size_t i = 0; i < n; i++)
		l->cell[i] = -1;
	for (int g = 0; g < e->n_groups; g++) {
		bsim_experiment_group_index(e, g, idx);
		int rest = 0;
		for (int a = 2; a < e->n_axes; a++)
			rest = rest * e->axes[a].n_values + idx[a];
		int i0 = e->n_axes > 0 ? idx[0] : 0, i1 = e->n_axes > 1 ? idx[1] : 0;
		l->cell[((size_t)rest * l->n1 + i1) * l->n0 + i0] = g;
	}
	free(idx);
	return 0;
}

static int max_len(const bsim_grid_axis *axis, int floor)
{
	int w = floor;
	for (int i = 0; i < axis->n_values; i++) {
		int len = (int)strlen(axis->values[i]);
		w = len > w ? len : w;
	}
	return w;
}

/* "beams.0.stiffness = 100, contact.restitution = 0.8" for table rest. */
static void table_heading(FILE *f, const bsim_experiment *e, int rest)
{
	int div = 1;
	for (int a = 2; a < e->n_axes; a++)
		div *= e->axes[a].n_values;
	for (int a = 2; a < e->n_axes; a++) {
		div /= e->axes[a].n_values;
		int i = (rest / div) % e->axes[a].n_values;
		fprintf(f, "%s%s = %s", a > 2 ? ", " : "", e->axes[a].key, e->axes[a].values[i]);
	}
	fputc('\n', f);
}

static void table_rule(FILE *f, int w, char c)
{
	for (int i = 0; i < w; i++)
		fputc(c, f);
}

/* One table: a header naming both axes, column values, a rule, and one row
 * of p_traverse per axis-1 value.
 *
 *                                 | effects.propulsion.force
 *  effects.random_force.magnitude |    4     5     6
 *  -------------------------------+------------------
 *                               0 | 0.00  0.12  0.40 */
static void table_one(FILE *f, const bsim_experiment *e, const bsim_sweep_result *r,
                      const table_layout *l, int rest)
{
	const bsim_grid_axis *a0 = &e->axes[0];
	const bsim_grid_axis *a1 = e->n_axes > 1 ? &e->axes[1] : NULL;
	const char *row_key = a1 ? a1->key : "p_traverse";
	int cw = max_len(a0, 4);
	int rw = a1 ? max_len(a1, (int)strlen(row_key)) : (int)strlen(row_key);

	fprintf(f, "%*s | %s\n%-*s |", rw, "", a0->key, rw, a1 ? row_key : "");
	for (int i0 = 0; i0 < l->n0; i0++)
		fprintf(f, "%s%*s", i0 ? "  " : " ", cw, a0->values[i0]);
	fputc('\n', f);
	table_rule(f, rw + 1, '-');
	fputc('+', f);
	table_rule(f, l->n0 * (cw + 2), '-');
	fputc('\n', f);
	for (int i1 = 0; i1 < l->n1; i1++) {
		fprintf(f, "%*s |", rw, a1 ? a1->values[i1] : row_key);
		for (int i0 = 0; i0 < l->n0; i0++) {
			int g = l->cell[((size_t)rest * l->n1 + i1) * l->n0 + i0];
			if (g >= 0 && g < r->n_groups)
				fprintf(f, "%s%*.2f", i0 ? "  " : " ", cw, r->groups[g].p_traverse);
			else
				fprintf(f, "%s%*s", i0 ? "  " : " ", cw, "-");
		}
		fputc('\n', f);
	}
}

void bsim_output_table(FILE *f, const bsim_experiment *e, const bsim_sweep_result *r)
{
	fprintf(f, "p_traverse, %d trials per group\n", r->trials);
	if (e->n_axes == 0) {
		if (r->n_groups > 0)
			fprintf(f, "%.2f [%.2f, %.2f]\n", r->groups[0].p_traverse,
			        r->groups[0].ci95[0], r->groups[0].ci95[1]);
		return;
	}
	table_layout l;
	if (layout_build(&l, e) != 0) {
		fputs("(out of memory for the table)\n", f);
		return;
	}
	for (int rest = 0; rest < l.n_rest; rest++) {
		fputc('\n', f);
		if (e->n_axes > 2)
			table_heading(f, e, rest);
		table_one(f, e, r, &l, rest);
	}
	free(l.cell);
}

/* ---- directories ---------------------------------------------------------- */

int bsim_output_mkdir(const char *dir, bsim_error *err)
{
	char path[1024];
	struct stat st;
	int n = snprintf(path, sizeof path, "%s", dir);
	if (n <= 0 || (size_t)n >= sizeof path)
		return bsim_error_set(err, BSIM_EFAIL, "%s: bad directory name", dir);
	/* Each parent in turn, like mkdir -p; existing ones are fine. */
	for (char *p = path + 1; *p; p++) {
		if (*p != '/')
			continue;
		*p = '\0';
		if (mkdir(path, 0777) != 0 && errno != EEXIST)
			return bsim_error_set(err, BSIM_EFAIL, "%s: cannot create: %s", path,
			                      strerror(errno));
		*p = '/';
	}
	if (mkdir(path, 0777) != 0 && errno != EEXIST)
		return bsim_error_set(err, BSIM_EFAIL, "%s: cannot create: %s", dir,
		                      strerror(errno));
	if (stat(path, &st) != 0 || !S_ISDIR(st.st_mode))
		return bsim_error_set(err, BSIM_EFAIL, "%s: not a directory", dir);
	return BSIM_OK;
}
