/* beamsim_sweep: every trial of every group of an experiment, as
 * `beamsim sweep` runs them, held in memory as columns.
 *
 *   s = beamsim_sweep(EXPERIMENT, NAME, VALUE, ...)
 *
 * Names: 'trials' (per group, instead of the file's), 'seed', 'threads'
 * (default: all cores; the results do not depend on it), 'backend',
 * 'backend_opt' {KEY, VALUE, ...}, 'set' {KEY, VALUE, ...}, 'grid'
 * {KEY, VALUES, ...}, 'overlap' (true: each trial's overlap_max).
 * s.groups is a struct array, one element per group with summary.json's
 * fields (its group field from 1); s.trials a struct of n x 1 columns, one
 * per trials.csv column, at full precision: numbers as doubles (group and
 * trial from 1; an empty field of the file is NaN); each text column
 * (outcome, type, location, path, a grid axis of text) as codes into its
 * labels, s.labels.COLUMN (a cell column): categorical arrays where
 * `categorical` exists (MATLAB), the codes themselves (uint8, uint16 or
 * uint32, from 1) where it does not (Octave: s.labels.outcome(
 * s.trials.outcome) is the text).
 *
 * The columns are made before the sweep, at their size, and filled as it
 * streams its trials by (bsim_sweep_config.sink): what is held is the
 * columns, 212 bytes a trial of H1's sweep (docs/bindings.md), and the
 * sweep's block of trials; a
 * sweep whose columns would not fit in the memory available is refused
 * before it runs (bsim_output_trials_fit). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bsim_mex.h"

enum { A_TRIALS, A_SEED, A_THREADS, A_BACKEND, A_BACKEND_OPT, A_SET, A_GRID, A_OVERLAP, N_ARGS };
static const char *const arg_names[N_ARGS] = {"trials",      "seed", "threads", "backend",
                                              "backend_opt", "set",  "grid",    "overlap"};

/* A number column of the trials. */
typedef double (*trial_number)(const bsim_trial_result *x);

static double c_steps(const bsim_trial_result *x)
{
	return x->steps;
}
static double c_t_end(const bsim_trial_result *x)
{
	return x->t_end;
}
static double c_x_end(const bsim_trial_result *x)
{
	return x->x_end;
}
static double c_y_end(const bsim_trial_result *x)
{
	return x->y_end;
}
static double c_vx_end(const bsim_trial_result *x)
{
	return x->vx_end;
}
static double c_max_theta1(const bsim_trial_result *x)
{
	return x->max_theta[0];
}
static double c_max_theta2(const bsim_trial_result *x)
{
	return x->max_theta[1];
}
static double c_e_start(const bsim_trial_result *x)
{
	return x->ledger.e_start;
}
static double c_e_end(const bsim_trial_result *x)
{
	return x->ledger.e_end;
}
static double c_work_in(const bsim_trial_result *x)
{
	return x->ledger.w_prop + x->ledger.w_rand;
}
/* as trials.csv: sleeping's and the essay protocol's resets too, so that
 * e_end - e_start = work_in - losses + residual */
static double c_losses(const bsim_trial_result *x)
{
	const bsim_ledger *l = &x->ledger;
	return l->damper + l->impact + l->contact + l->correction + l->sleep + l->reset;
}
static double c_residual(const bsim_trial_result *x)
{
	return x->ledger.residual;
}
static double c_overlap_max(const bsim_trial_result *x)
{
	return x->overlap_max;
}
static double c_final_ix(const bsim_trial_result *x)
{
	return x->final_ix;
}
static double c_final_iy(const bsim_trial_result *x)
{
	return x->final_iy;
}
static double c_iteration_limits(const bsim_trial_result *x)
{
	return (double)x->solver.iteration_limit;
}
static double c_clamps(const bsim_trial_result *x)
{
	return (double)x->solver.clamped;
}
/* when it left the gate (or the field); NaN (trials.csv: empty) if censored */
static double c_t_exit(const bsim_trial_result *x)
{
	return x->outcome == BSIM_TRAVERSED || x->outcome == BSIM_SIDE_EXIT ? x->t_end : NAN;
}
static double c_heading_end(const bsim_trial_result *x)
{
	return x->heading_end;
}
static double c_angular_velocity_end(const bsim_trial_result *x)
{
	return x->angular_velocity_end;
}
static double c_turn_end(const bsim_trial_result *x)
{
	return x->turn_end;
}
static double c_turn_max(const bsim_trial_result *x)
{
	return x->turn_max;
}

typedef struct number_column {
	const char *name;
	trial_number fn;
} number_column;

/* trials.csv's columns in its order (docs/files.md); group, trial, outcome,
 * type, location and path are made apart. */
static const number_column after_type[] = {
        {"steps", c_steps},
        {"t_end", c_t_end},
        {"x_end", c_x_end},
        {"y_end", c_y_end},
        {"vx_end", c_vx_end},
        {"max_theta1", c_max_theta1},
        {"max_theta2", c_max_theta2},
        {"e_start", c_e_start},
        {"e_end", c_e_end},
        {"work_in", c_work_in},
        {"losses", c_losses},
        {"residual", c_residual},
        {"overlap_max", c_overlap_max},
        {"final_ix", c_final_ix},
        {"final_iy", c_final_iy},
};
static const number_column after_path[] = {
        {"iteration_limits", c_iteration_limits},
        {"clamps", c_clamps},
        {"t_exit", c_t_exit},
        {"heading_end", c_heading_end},
        {"angular_velocity_end", c_angular_velocity_end},
        {"turn_end", c_turn_end},
        {"turn_max", c_turn_max},
};

enum { N_AFTER_TYPE = sizeof after_type / sizeof after_type[0] };
enum { N_AFTER_PATH = sizeof after_path / sizeof after_path[0] };

/* A grid value as a number, NaN if it is text. */
static double value_number(const char *text)
{
	char *end;
	double x = strtod(text, &end);
	return end != text && *end == '\0' ? x : NAN;
}

/* The trials as columns, made at their size before the sweep and filled
 * block by block as it streams them (the sink, on the calling thread). A
 * text column is codes from 1 into its labels: fixed lists for outcome and
 * type, the distinct texts in order of first appearance for location and
 * path (uint32 while the sweep runs, narrowed once their count is known). */
typedef struct trial_columns {
	const bsim_experiment *e;
	size_t n;
	int trials;
	mxArray *group, *trial, *outcome, *type;
	mxArray *number[N_AFTER_TYPE + N_AFTER_PATH];
	mxArray **axis; /* n_axes: doubles, or codes into the axis's values */
	uint32_t *location, *path;
	bmx_labels location_labels, path_labels;
	int *idx, *axis_text;
	int oom;
} trial_columns;

/* "ix:iy ix:iy ...", the gates entered in order, as trials.csv writes it,
 * into buf (grown as needed); NULL if out of memory. */
static const char *path_text(const bsim_trial_result *x, const bsim_trial_log *tl, char **buf,
                             size_t *size)
{
	size_t n = tl ? (size_t)tl->n_entries : 0, need = 24 * (n + 1);
	if (need > *size) {
		char *b = realloc(*buf, need);
		if (!b)
			return NULL;
		*buf = b;
		*size = need;
	}
	size_t len = 0;
	for (size_t j = 0; j < n; j++)
		len += (size_t)sprintf(*buf + len, "%s%d:%d", j ? " " : "", tl->entries[j].ix,
		                       tl->entries[j].iy);
	if (n == 0)
		sprintf(*buf, "%d:%d", x->final_ix, x->final_iy);
	return *buf;
}

static int columns_block(void *user, const bsim_sweep_block *b, bsim_error *err)
{
	trial_columns *c = user;
	char *buf = NULL;
	size_t size = 0;
	for (long k = 0; k < b->n && !c->oom; k++) {
		size_t at = (size_t)(b->first + k);
		const bsim_trial_result *x = &b->results[k];
		mxGetPr(c->group)[at] = (double)(at / (size_t)c->trials) + 1;
		mxGetPr(c->trial)[at] = (double)(at % (size_t)c->trials) + 1;
		((uint8_t *)mxGetData(c->outcome))[at] = (uint8_t)(x->outcome + 1);
		((uint8_t *)mxGetData(c->type))[at] = (uint8_t)(x->type + 1);
		for (int i = 0; i < N_AFTER_TYPE; i++)
			mxGetPr(c->number[i])[at] = after_type[i].fn(x);
		for (int i = 0; i < N_AFTER_PATH; i++)
			mxGetPr(c->number[N_AFTER_TYPE + i])[at] = after_path[i].fn(x);
		char label[48];
		bsim_lattice_location_label(bsim_lattice_location_of(x), label, sizeof label);
		const char *path = path_text(x, b->logs ? &b->logs[k] : NULL, &buf, &size);
		long lc = bmx_labels_code(&c->location_labels, label);
		long pc = path ? bmx_labels_code(&c->path_labels, path) : -1;
		c->oom = lc < 0 || pc < 0;
		if (!c->oom) {
			c->location[at] = (uint32_t)lc;
			c->path[at] = (uint32_t)pc;
		}
		/* One column per grid axis: its value, or its code from 1. */
		if (at % (size_t)c->trials == 0 || k == 0)
			bsim_experiment_group_index(c->e, (int)(at / (size_t)c->trials), c->idx);
		for (int a = 0; a < c->e->n_axes; a++) {
			const char *text = c->e->axes[a].values[c->idx[a]];
			if (c->axis_text[a])
				((uint32_t *)mxGetData(c->axis[a]))[at] = (uint32_t)c->idx[a] + 1;
			else
				mxGetPr(c->axis[a])[at] = value_number(text);
		}
	}
	free(buf);
	if (c->oom)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory for the trials' columns");
	return BSIM_OK;
}

/* The columns of e's trials, zeroed, for columns_block. */
static int columns_alloc(trial_columns *c, const bsim_experiment *e, bsim_error *err)
{
	memset(c, 0, sizeof *c);
	c->e = e;
	c->trials = e->trials;
	c->n = (size_t)e->n_groups * (size_t)e->trials;
	double *unused;
	c->group = bmx_column(c->n, &unused);
	c->trial = bmx_column(c->n, &unused);
	c->outcome = mxCreateNumericMatrix((mwSize)c->n, 1, mxUINT8_CLASS, mxREAL);
	c->type = mxCreateNumericMatrix((mwSize)c->n, 1, mxUINT8_CLASS, mxREAL);
	for (int i = 0; i < N_AFTER_TYPE + N_AFTER_PATH; i++)
		c->number[i] = bmx_column(c->n, &unused);
	size_t axes = (size_t)(e->n_axes > 0 ? e->n_axes : 1);
	c->axis = calloc(axes, sizeof *c->axis);
	c->idx = calloc(axes, sizeof *c->idx);
	c->axis_text = calloc(axes, sizeof *c->axis_text);
	c->location = malloc((c->n ? c->n : 1) * sizeof *c->location);
	c->path = malloc((c->n ? c->n : 1) * sizeof *c->path);
	if (!c->axis || !c->idx || !c->axis_text || !c->location || !c->path)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory for the trials' columns");
	/* an axis is numbers if every value is one, else text (codes) */
	for (int a = 0; a < e->n_axes; a++) {
		const bsim_grid_axis *ax = &e->axes[a];
		for (int i = 0; i < ax->n_values && !c->axis_text[a]; i++)
			c->axis_text[a] = isnan(value_number(ax->values[i]));
		c->axis[a] = c->axis_text[a] ? mxCreateNumericMatrix((mwSize)c->n, 1,
		                                                     mxUINT32_CLASS, mxREAL)
		                             : bmx_column(c->n, &unused);
	}
	return BSIM_OK;
}

static void columns_free(trial_columns *c)
{
	free(c->axis);
	free(c->idx);
	free(c->axis_text);
	free(c->location);
	free(c->path);
	bmx_labels_free(&c->location_labels);
	bmx_labels_free(&c->path_labels);
	memset(c, 0, sizeof *c);
}

/* s.trials (and s.labels): the columns in trials.csv's order, each text
 * column's codes with its labels, categorical where MATLAB has it. */
static void trials_fields(mxArray *s, trial_columns *c)
{
	mxArray *t = mxCreateStructMatrix(1, 1, 0, NULL), *l = mxCreateStructMatrix(1, 1, 0, NULL);
	static const char *const outcomes[] = {"traversed", "side_exit", "stuck", "unstable"};
	static const char *const types[] = {"none", "left", "right"};
	bmx_set(t, 0, "group", c->group);
	bmx_set(t, 0, "trial", c->trial);
	bmx_text_field(t, l, "outcome", c->outcome, bmx_cellstr(outcomes, 4));
	bmx_text_field(t, l, "type", c->type, bmx_cellstr(types, 3));
	for (int i = 0; i < N_AFTER_TYPE; i++)
		bmx_set(t, 0, after_type[i].name, c->number[i]);
	bmx_text_field(t, l, "location", bmx_codes(c->location, c->n, c->location_labels.n),
	               bmx_labels_cell(&c->location_labels));
	free(c->location);
	c->location = NULL;
	bmx_text_field(t, l, "path", bmx_codes(c->path, c->n, c->path_labels.n),
	               bmx_labels_cell(&c->path_labels));
	free(c->path);
	c->path = NULL;
	for (int i = 0; i < N_AFTER_PATH; i++)
		bmx_set(t, 0, after_path[i].name, c->number[N_AFTER_TYPE + i]);
	for (int a = 0; a < c->e->n_axes; a++) {
		const bsim_grid_axis *ax = &c->e->axes[a];
		char field[64];
		bmx_field_name(ax->key, field, sizeof field);
		if (!c->axis_text[a]) {
			bmx_set(t, 0, field, c->axis[a]);
			continue;
		}
		uint32_t *codes = mxGetData(c->axis[a]);
		bmx_text_field(t, l, field, bmx_codes(codes, c->n, (size_t)ax->n_values),
		               bmx_cellstr((const char *const *)ax->values, ax->n_values));
		mxDestroyArray(c->axis[a]);
	}
	bmx_set(s, 0, "trials", t);
	bmx_set(s, 0, "labels", l);
}

static mxArray *groups_struct(const bsim_experiment *e, const bsim_sweep_result *r)
{
	mxArray *s = mxCreateStructMatrix((mwSize)r->n_groups, 1, 0, NULL);
	int *idx = calloc((size_t)(e->n_axes > 0 ? e->n_axes : 1), sizeof *idx);
	for (int k = 0; k < r->n_groups; k++) {
		const bsim_group_result *g = &r->groups[k];
		mwIndex i = (mwIndex)k;
		bmx_set(s, i, "group", bmx_scalar(k + 1));
		mxArray *params = mxCreateStructMatrix(1, 1, 0, NULL);
		if (idx)
			bsim_experiment_group_index(e, k, idx);
		for (int a = 0; idx && a < e->n_axes; a++) {
			const char *text = e->axes[a].values[idx[a]];
			double x = value_number(text);
			char field[64];
			bmx_field_name(e->axes[a].key, field, sizeof field);
			bmx_set(params, 0, field, isnan(x) ? bmx_string(text) : bmx_scalar(x));
		}
		bmx_set(s, i, "params", params);
		const char *names[] = {"trials",
		                       "traversed",
		                       "side_exit",
		                       "stuck",
		                       "left",
		                       "right",
		                       "p_traverse",
		                       "stuck_in_contact",
		                       "landscape_left",
		                       "landscape_right",
		                       "steps",
		                       "unstable",
		                       "trials_iteration_limit",
		                       "trials_clamped"};
		const double values[] = {g->trials,
		                         g->traversed,
		                         g->side_exit,
		                         g->stuck,
		                         g->left,
		                         g->right,
		                         g->p_traverse,
		                         g->stuck_in_contact,
		                         g->landscape_left,
		                         g->landscape_right,
		                         (double)g->steps,
		                         g->unstable,
		                         g->trials_iteration_limit,
		                         g->trials_clamped};
		for (size_t f = 0; f < sizeof values / sizeof values[0]; f++) {
			bmx_set(s, i, names[f], bmx_scalar(values[f]));
			if (strcmp(names[f], "p_traverse") == 0)
				bmx_set(s, i, "ci95", bmx_row(g->ci95, 2));
		}
		bmx_set(s, i, "deterministic", mxCreateLogicalScalar(g->deterministic != 0));
		if (g->rotates) { /* summary.json's turn, where the body rotates */
			bmx_set(s, i, "turn_end_mean", bmx_scalar(g->turn_end_mean));
			bmx_set(s, i, "turn_end_mean_abs", bmx_scalar(g->turn_end_mean_abs));
			bmx_set(s, i, "turn_end_max_abs", bmx_scalar(g->turn_end_max_abs));
			bmx_set(s, i, "turn_max", bmx_scalar(g->turn_max));
		}
		mxArray *solver = mxCreateStructMatrix(1, 1, 0, NULL);
		bmx_set(solver, 0, "iteration_limit",
		        bmx_scalar((double)g->solver.iteration_limit));
		bmx_set(solver, 0, "clamped", bmx_scalar((double)g->solver.clamped));
		bmx_set(s, i, "solver", solver);
	}
	free(idx);
	return s;
}

static mxArray *sweep_struct(const bsim_experiment *e, const bsim_backend *b,
                             const bsim_sweep_result *r, trial_columns *c)
{
	mxArray *s = mxCreateStructMatrix(1, 1, 0, NULL);
	bmx_set(s, 0, "experiment", bmx_string(e->path));
	bmx_set(s, 0, "scene", bmx_string(e->scene_path));
	bmx_set(s, 0, "backend", bmx_string(b->name));
	bmx_set(s, 0, "seed", bmx_u64(e->seed));
	bmx_set(s, 0, "trials_per_group", bmx_scalar(r->trials));
	mxArray *axes = mxCreateCellMatrix(1, (mwSize)e->n_axes);
	for (int a = 0; a < e->n_axes; a++)
		mxSetCell(axes, (mwIndex)a, bmx_string(e->axes[a].key));
	bmx_set(s, 0, "axes", axes);
	bmx_set(s, 0, "wall_seconds", bmx_scalar(r->wall_seconds));
	bmx_set(s, 0, "total_steps", bmx_scalar((double)r->total_steps));
	bmx_set(s, 0, "trials_run", bmx_scalar((double)r->trials_run));
	bmx_set(s, 0, "groups", groups_struct(e, r));
	trials_fields(s, c);
	return s;
}

/* Unstable trials, said as `beamsim sweep` says them (it exits 1): the
 * groups' counts, and the first, which the streamed sweep keeps. */
static void unstable_line(const bsim_experiment *e, const bsim_override *sets, int n_sets,
                          const bsim_backend *b, const bsim_sweep_result *r, char *buf, size_t size)
{
	size_t n = (size_t)r->n_groups * (size_t)r->trials;
	long count = 0, first = r->first_unstable;
	for (int g = 0; g < r->n_groups; g++)
		count += r->groups[g].unstable;
	if (count == 0 || first < 0)
		return;
	char why[256] = "";
	bsim_scene scene;
	bsim_error err;
	memset(&scene, 0, sizeof scene);
	if (bsim_experiment_group_scene(e, (int)(first / r->trials), sets, n_sets, &scene, &err) ==
	    BSIM_OK)
		bsim_trial_instability_text(&r->first_unstable_result, scene.dt, why, sizeof why);
	bsim_scene_free(&scene);
	snprintf(buf, size,
	         "%ld of %zu trials unstable on the %s backend (outcome unstable in s.trials); the "
	         "first, group %ld trial %ld (from 1): %s",
	         count, n, b->name, first / r->trials + 1, first % r->trials + 1, why);
}

typedef struct sweep_call {
	bmx_pool pool;
	bsim_grid_axis *grid;
	int n_grid;
	bsim_experiment e;
	bsim_sweep_result r;
	trial_columns c;
} sweep_call;

/* A cell of the columns: 8 bytes a number, 1 to 4 a text column's code. */
#define CELL_BYTES 8.0

static int sweep(sweep_call *c, int nrhs, const mxArray *prhs[], mxArray **out, char *warning,
                 size_t warning_size, bsim_error *err)
{
	const mxArray *v[N_ARGS];
	if (nrhs < 1)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "expected an experiment file, then name-value pairs");
	if (bmx_pairs(nrhs, prhs, 1, arg_names, N_ARGS, v, err) != BSIM_OK)
		return BSIM_EINPUT;
	const char *path = NULL, *backend = NULL;
	long trials = 0, threads = 0;
	int overlap = 0;
	uint64_t seed = 0;
	bsim_override *sets = NULL, *kv = NULL;
	int n_sets = 0, n_kv = 0;
	if (bmx_text("experiment", prhs[0], &c->pool, &path, err) ||
	    (v[A_TRIALS] && bmx_long("trials", v[A_TRIALS], 1, INT32_MAX, &trials, err)) ||
	    (v[A_THREADS] && bmx_long("threads", v[A_THREADS], 1, 4096, &threads, err)) ||
	    (v[A_SEED] && bmx_seed("seed", v[A_SEED], &seed, err)) ||
	    (v[A_OVERLAP] && bmx_flag("overlap", v[A_OVERLAP], &overlap, err)) ||
	    (v[A_BACKEND] && bmx_text("backend", v[A_BACKEND], &c->pool, &backend, err)) ||
	    bmx_overrides("backend_opt", v[A_BACKEND_OPT], &c->pool, &kv, &n_kv, err) ||
	    bmx_overrides("set", v[A_SET], &c->pool, &sets, &n_sets, err) ||
	    bmx_grid("grid", v[A_GRID], &c->pool, &c->grid, &c->n_grid, err))
		return err->code;
	bsim_sweep_config cfg = bsim_sweep_config_default();
	bsim_options opts;
	if (bmx_backend(backend, kv, n_kv, &cfg.backend, &opts, err) != BSIM_OK)
		return BSIM_EINPUT;
	/* The experiment as `beamsim sweep` loads it: --set, --grid, then
	 * --trials and --seed. */
	if (bsim_experiment_load_seeded(path, sets, n_sets, c->grid, c->n_grid,
	                                v[A_SEED] ? &seed : NULL, &c->e, err) != BSIM_OK)
		return err->code ? err->code : BSIM_EINPUT;
	if (trials > 0 && bsim_experiment_check_trials(&c->e, trials, err) != BSIM_OK) {
		char msg[sizeof err->msg];
		snprintf(msg, sizeof msg, "%s", err->msg);
		return bsim_error_set(err, BSIM_EINPUT, "--trials %ld: %s", trials, msg);
	}
	if (trials > 0)
		c->e.trials = (int)trials;
	if (v[A_SEED])
		c->e.seed = seed;
	if (bsim_output_trials_fit(&c->e, 0, CELL_BYTES, err) != BSIM_OK ||
	    columns_alloc(&c->c, &c->e, err) != BSIM_OK)
		return err->code;
	cfg.opts = &opts;
	cfg.threads = (int)threads;
	cfg.extra = sets;
	cfg.n_extra = n_sets;
	cfg.measure_overlap = overlap;
	cfg.sink = columns_block;
	cfg.sink_user = &c->c;
	if (bsim_sweep_run(&c->e, &cfg, &c->r, err) != BSIM_OK)
		return err->code ? err->code : BSIM_EFAIL;
	unstable_line(&c->e, sets, n_sets, cfg.backend, &c->r, warning, warning_size);
	*out = sweep_struct(&c->e, cfg.backend, &c->r, &c->c);
	return BSIM_OK;
}

void mexFunction(int nlhs, mxArray *plhs[], int nrhs, const mxArray *prhs[])
{
	(void)nlhs;
	sweep_call c;
	memset(&c, 0, sizeof c);
	bsim_error err;
	bsim_error_clear(&err);
	char warning[512] = "";
	mxArray *out = NULL;
	int rc = sweep(&c, nrhs, prhs, &out, warning, sizeof warning, &err);
	columns_free(&c.c);
	bsim_sweep_result_free(&c.r);
	bsim_experiment_free(&c.e);
	bmx_grid_free(c.grid, c.n_grid);
	bmx_pool_free(&c.pool);
	if (rc != BSIM_OK)
		bmx_fail(&err);
	if (warning[0])
		mexWarnMsgIdAndTxt("beamsim:unstable", "%s", warning);
	plhs[0] = out;
}
