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
#define _GNU_SOURCE /* open_memstream */

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bsim_mex.h"

enum { A_TRIALS, A_SEED, A_THREADS, A_BACKEND, A_BACKEND_OPT, A_SET, A_GRID, A_OVERLAP, N_ARGS };
static const char *const arg_names[N_ARGS] = {"trials",      "seed", "threads", "backend",
                                              "backend_opt", "set",  "grid",    "overlap"};

/* A grid value as a number, NaN if it is text. */
static double value_number(const char *text)
{
	char *end;
	double x = strtod(text, &end);
	return end != text && *end == '\0' ? x : NAN;
}

/* The trials as columns, made at their size before the sweep and filled
 * block by block as it streams them (the sink, on the calling thread), one
 * per field of trials.csv (beamsim/trial_fields.h) in its order. A number
 * is a double (an index from 1); a word of a fixed list (outcome, type) is
 * its code from 1 (uint8); a text made from the trial (location, path) is
 * a code from 1 into the distinct texts in order of first appearance
 * (uint32 while the sweep runs, narrowed once their count is known). */
typedef struct trial_columns {
	const bsim_experiment *e;
	size_t n;
	int trials;
	const bsim_trial_field *field;
	int n_fields;
	mxArray **col;      /* n_fields: numbers and words; NULL for a text */
	uint32_t **codes;   /* n_fields: a text's codes, else NULL */
	bmx_labels *labels; /* n_fields: a text's labels */
	mxArray **axis;     /* n_axes: doubles, or codes into the axis's values */
	int *idx, *axis_text;
	char *text; /* a block's stream's buffer (field_text) */
	size_t text_size;
	int oom;
} trial_columns;

/* Field f of row as a text: written from the start of the block's stream
 * m, ended by a NUL, and read from its buffer (c->text, which m keeps and
 * grows); NULL if out of memory. */
static const char *field_text(trial_columns *c, FILE *m, const bsim_trial_field *f,
                              const bsim_trial_row *row)
{
	if (fseek(m, 0, SEEK_SET) != 0)
		return NULL;
	f->text(m, row);
	if (fputc('\0', m) == EOF || fflush(m) != 0)
		return NULL;
	return c->text;
}

static int columns_block(void *user, const bsim_sweep_block *b, bsim_error *err)
{
	trial_columns *c = user;
	/* one stream for the block's texts (location, path) */
	FILE *m = open_memstream(&c->text, &c->text_size);
	c->oom = !m;
	for (long k = 0; k < b->n && !c->oom; k++) {
		size_t at = (size_t)(b->first + k);
		const bsim_trial_row row = {(int)(at / (size_t)c->trials),
		                            (int)(at % (size_t)c->trials),
		                            &b->results[k],
		                            b->logs ? &b->logs[k] : NULL,
		                            0,
		                            NULL};
		for (int i = 0; i < c->n_fields && !c->oom; i++) {
			const bsim_trial_field *f = &c->field[i];
			if (f->kind == BSIM_FIELD_TEXT) {
				const char *text = field_text(c, m, f, &row);
				long code = text ? bmx_labels_code(&c->labels[i], text) : -1;
				c->oom = code < 0;
				if (!c->oom)
					c->codes[i][at] = (uint32_t)code;
			} else if (f->kind == BSIM_FIELD_WORD) {
				((uint8_t *)mxGetData(c->col[i]))[at] =
				        (uint8_t)(f->value(&row) + 1);
			} else {
				mxGetPr(c->col[i])[at] = f->value(&row) + (f->index ? 1 : 0);
			}
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
	if (m && fclose(m) != 0)
		c->oom = 1;
	free(c->text);
	c->text = NULL;
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
	c->field = bsim_trial_fields(&c->n_fields);
	c->col = calloc((size_t)c->n_fields, sizeof *c->col);
	c->codes = calloc((size_t)c->n_fields, sizeof *c->codes);
	c->labels = calloc((size_t)c->n_fields, sizeof *c->labels);
	size_t axes = (size_t)(e->n_axes > 0 ? e->n_axes : 1);
	c->axis = calloc(axes, sizeof *c->axis);
	c->idx = calloc(axes, sizeof *c->idx);
	c->axis_text = calloc(axes, sizeof *c->axis_text);
	if (!c->col || !c->codes || !c->labels || !c->axis || !c->idx || !c->axis_text)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory for the trials' columns");
	double *unused;
	for (int i = 0; i < c->n_fields; i++) {
		const bsim_trial_field *f = &c->field[i];
		if (f->kind == BSIM_FIELD_TEXT) {
			c->codes[i] = malloc((c->n ? c->n : 1) * sizeof *c->codes[i]);
			if (!c->codes[i])
				return bsim_error_set(err, BSIM_EFAIL,
				                      "out of memory for the trials' columns");
		} else if (f->kind == BSIM_FIELD_WORD) {
			c->col[i] = mxCreateNumericMatrix((mwSize)c->n, 1, mxUINT8_CLASS, mxREAL);
		} else {
			c->col[i] = bmx_column(c->n, &unused);
		}
	}
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
	for (int i = 0; i < c->n_fields; i++) {
		if (c->codes)
			free(c->codes[i]);
		if (c->labels)
			bmx_labels_free(&c->labels[i]);
	}
	free(c->col);
	free(c->codes);
	free(c->labels);
	free(c->axis);
	free(c->idx);
	free(c->axis_text);
	free(c->text);
	memset(c, 0, sizeof *c);
}

/* s.trials (and s.labels): the columns in trials.csv's order, each text
 * column's codes with its labels, categorical where MATLAB has it. */
static void trials_fields(mxArray *s, trial_columns *c)
{
	mxArray *t = mxCreateStructMatrix(1, 1, 0, NULL), *l = mxCreateStructMatrix(1, 1, 0, NULL);
	for (int i = 0; i < c->n_fields; i++) {
		const bsim_trial_field *f = &c->field[i];
		if (f->kind == BSIM_FIELD_TEXT) {
			bmx_text_field(t, l, f->name, bmx_codes(c->codes[i], c->n, c->labels[i].n),
			               bmx_labels_cell(&c->labels[i]));
			free(c->codes[i]);
			c->codes[i] = NULL;
		} else if (f->kind == BSIM_FIELD_WORD) {
			bmx_text_field(t, l, f->name, c->col[i], bmx_cellstr(f->words, f->n_words));
		} else {
			bmx_set(t, 0, f->name, c->col[i]);
		}
	}
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

/* A member of group g (beamsim/sweep.h's lists) as field of element i of
 * s, or of its solver's counts. */
#define MX_GROUP(m)  BMX_MEMBER(s, i, g, m);
#define MX_SOLVER(m) BMX_MEMBER(solver, 0, &g->solver, m);

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
		BSIM_GROUP_RESULT_COUNTS(MX_GROUP)
		BSIM_GROUP_RESULT_SOLVER_TRIALS(MX_GROUP)
		bmx_set(s, i, "deterministic", mxCreateLogicalScalar(g->deterministic != 0));
		if (g->rotates) { /* summary.json's turn, where the body rotates */
			BSIM_GROUP_RESULT_TURN(MX_GROUP)
		}
		mxArray *solver = mxCreateStructMatrix(1, 1, 0, NULL);
		BSIM_SOLVER_COUNTS(MX_SOLVER)
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
