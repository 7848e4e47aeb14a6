/* beamsim_sweep: every trial of every group of an experiment, as
 * `beamsim sweep` runs them, held in memory.
 *
 *   s = beamsim_sweep(EXPERIMENT, NAME, VALUE, ...)
 *
 * Names: 'trials' (per group, instead of the file's), 'seed', 'threads'
 * (default: all cores; the results do not depend on it), 'backend',
 * 'backend_opt' {KEY, VALUE, ...}, 'set' {KEY, VALUE, ...}, 'grid'
 * {KEY, VALUES, ...}, 'overlap' (true: each trial's overlap_max).
 * s.groups is a struct array, one element per group with summary.json's
 * fields (its group field from 1); s.trials a struct of column vectors, one
 * per trials.csv column (group and trial from 1; text columns as cells;
 * an empty field of the file is NaN), at full precision. */
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
};

static void number_field(mxArray *s, const bsim_sweep_result *r, const number_column *c)
{
	size_t n = (size_t)r->n_groups * (size_t)r->trials;
	double *d;
	mxArray *col = bmx_column(n, &d);
	for (size_t k = 0; k < n; k++)
		d[k] = c->fn(&r->trials_out[k]);
	bmx_set(s, 0, c->name, col);
}

/* "ix:iy ix:iy ...", the gates entered in order, as trials.csv writes it. */
static mxArray *path_text(const bsim_trial_result *x, const bsim_trial_log *tl)
{
	size_t n = tl ? (size_t)tl->n_entries : 0;
	char *s = malloc(24 * (n + 1));
	if (!s)
		return bmx_string("");
	size_t len = 0;
	for (size_t j = 0; j < n; j++)
		len += (size_t)sprintf(s + len, "%s%d:%d", j ? " " : "", tl->entries[j].ix,
		                       tl->entries[j].iy);
	if (n == 0)
		sprintf(s, "%d:%d", x->final_ix, x->final_iy);
	mxArray *a = bmx_string(s);
	free(s);
	return a;
}

/* A grid value as a number, NaN if it is text. */
static double value_number(const char *text)
{
	char *end;
	double x = strtod(text, &end);
	return end != text && *end == '\0' ? x : NAN;
}

static mxArray *trials_struct(const bsim_experiment *e, const bsim_sweep_result *r)
{
	mxArray *s = mxCreateStructMatrix(1, 1, 0, NULL);
	size_t n = (size_t)r->n_groups * (size_t)r->trials;
	double *g, *t;
	mxArray *gc = bmx_column(n, &g), *tc = bmx_column(n, &t);
	mxArray *outcome = mxCreateCellMatrix((mwSize)n, 1),
	        *type = mxCreateCellMatrix((mwSize)n, 1);
	mxArray *location = mxCreateCellMatrix((mwSize)n, 1),
	        *path = mxCreateCellMatrix((mwSize)n, 1);
	for (size_t k = 0; k < n; k++) {
		const bsim_trial_result *x = &r->trials_out[k];
		g[k] = (double)(k / (size_t)r->trials) + 1;
		t[k] = (double)(k % (size_t)r->trials) + 1;
		mxSetCell(outcome, (mwIndex)k, bmx_string(bsim_trial_outcome_name(x->outcome)));
		mxSetCell(type, (mwIndex)k, bmx_string(bsim_trial_type_name(x->type)));
		char label[48];
		bsim_lattice_location_label(bsim_lattice_location_of(x), label, sizeof label);
		mxSetCell(location, (mwIndex)k, bmx_string(label));
		mxSetCell(path, (mwIndex)k, path_text(x, r->logs ? &r->logs[k] : NULL));
	}
	bmx_set(s, 0, "group", gc);
	bmx_set(s, 0, "trial", tc);
	bmx_set(s, 0, "outcome", outcome);
	bmx_set(s, 0, "type", type);
	for (size_t c = 0; c < sizeof after_type / sizeof after_type[0]; c++)
		number_field(s, r, &after_type[c]);
	bmx_set(s, 0, "location", location);
	bmx_set(s, 0, "path", path);
	for (size_t c = 0; c < sizeof after_path / sizeof after_path[0]; c++)
		number_field(s, r, &after_path[c]);
	/* One column per grid axis: numbers if every value is one, else text. */
	int *idx = calloc((size_t)(e->n_axes > 0 ? e->n_axes : 1), sizeof *idx);
	for (int a = 0; idx && a < e->n_axes; a++) {
		const bsim_grid_axis *ax = &e->axes[a];
		int numeric = 1;
		for (int i = 0; i < ax->n_values; i++)
			numeric = numeric && !isnan(value_number(ax->values[i]));
		mxArray *col;
		double *d = NULL;
		col = numeric ? bmx_column(n, &d) : mxCreateCellMatrix((mwSize)n, 1);
		for (int grp = 0; grp < r->n_groups; grp++) {
			bsim_experiment_group_index(e, grp, idx);
			const char *text = ax->values[idx[a]];
			for (int k = 0; k < r->trials; k++) {
				size_t at = (size_t)grp * (size_t)r->trials + (size_t)k;
				if (numeric)
					d[at] = value_number(text);
				else
					mxSetCell(col, (mwIndex)at, bmx_string(text));
			}
		}
		char field[64];
		bmx_field_name(ax->key, field, sizeof field);
		bmx_set(s, 0, field, col);
	}
	free(idx);
	return s;
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
                             const bsim_sweep_result *r)
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
	bmx_set(s, 0, "trials", trials_struct(e, r));
	return s;
}

/* Unstable trials, said as `beamsim sweep` says them (it exits 1). */
static void unstable_line(const bsim_experiment *e, const bsim_override *sets, int n_sets,
                          const bsim_backend *b, const bsim_sweep_result *r, char *buf, size_t size)
{
	size_t n = (size_t)r->n_groups * (size_t)r->trials;
	long count = 0, first = -1;
	for (size_t k = 0; k < n; k++)
		if (r->trials_out[k].outcome == BSIM_UNSTABLE && count++ == 0)
			first = (long)k;
	if (count == 0)
		return;
	char why[256] = "";
	bsim_scene scene;
	bsim_error err;
	memset(&scene, 0, sizeof scene);
	if (bsim_experiment_group_scene(e, (int)(first / r->trials), sets, n_sets, &scene, &err) ==
	    BSIM_OK)
		bsim_trial_instability_text(&r->trials_out[first], scene.dt, why, sizeof why);
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
} sweep_call;

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
	cfg.opts = &opts;
	cfg.threads = (int)threads;
	cfg.extra = sets;
	cfg.n_extra = n_sets;
	cfg.measure_overlap = overlap;
	if (bsim_sweep_run(&c->e, &cfg, &c->r, err) != BSIM_OK)
		return err->code ? err->code : BSIM_EFAIL;
	unstable_line(&c->e, sets, n_sets, cfg.backend, &c->r, warning, warning_size);
	*out = sweep_struct(&c->e, cfg.backend, &c->r);
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
