/* beamsim_run: one trial, as `beamsim run` runs it.
 *
 *   r = beamsim_run(ARG, NAME, VALUE, ...)
 *
 * ARG is a scene file, an experiment file or the output directory of a
 * sweep or a comparison (beamsim/replay.h says which trial each names).
 * Names: 'seed', 'group' and 'trial' (from 1: trials.csv's group and trial
 * plus 1), 'backend' (a stored comparison's side by its label),
 * 'backend_opt' {KEY, VALUE, ...}, 'set' {KEY, VALUE, ...}, 'grid'
 * {KEY, VALUES, ...}, 'trajectory' (true: the recorded rows), 'stride'.
 * r holds what `beamsim run --json` prints; with 'trajectory' also
 * r.trajectory, the columns of run --trajectory's CSV, and r.ledger_rows,
 * those of run --out's ledger.csv, each a column vector. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bsim_mex.h"

/* The trial's names (bsim_mex.h), then the run's. */
enum { A_TRAJECTORY = BMX_TRIAL_NAMES, A_STRIDE, N_ARGS };
static const char *const arg_names[N_ARGS] = {BMX_TRIAL_NAME_LIST, "trajectory", "stride"};

/* The ledger.csv columns after t (bsim_trial_ledger_header). */
#define LEDGER_COLUMNS 13

/* The recorded rows, row by row: the trajectory's columns, then the
 * ledger's. */
typedef struct rows {
	int n_beams, width;
	int body; /* 1: heading, angular_velocity after e_prop (bsim_trial_body_columns) */
	long n, cap;
	double *v;
	int oom;
} rows;

static int traj_width(int n_beams, int body)
{
	return 5 + 2 * n_beams + 1 + n_beams + 3 + 2 * body;
}

static void rows_record(void *user, const bsim_record_row *row)
{
	rows *r = user;
	const bsim_state *s = row->state;
	if (r->oom)
		return;
	if (r->n == r->cap) {
		long cap = r->cap ? 2 * r->cap : 1024;
		double *more = realloc(r->v, (size_t)cap * (size_t)r->width * sizeof *more);
		if (!more) {
			r->oom = 1;
			return;
		}
		r->v = more;
		r->cap = cap;
	}
	double *d = r->v + (size_t)r->n * (size_t)r->width;
	int k = 0;
	d[k++] = row->t;
	d[k++] = s->x[0];
	d[k++] = s->x[1];
	d[k++] = s->v[0];
	d[k++] = s->v[1];
	for (int i = 0; i < r->n_beams; i++) {
		d[k++] = s->theta[i];
		d[k++] = s->omega[i];
	}
	d[k++] = row->f_rand;
	for (int i = 0; i < r->n_beams; i++)
		d[k++] = s->contact[i];
	d[k++] = row->e_kin;
	d[k++] = row->e_beam;
	d[k++] = row->e_prop;
	if (r->body) {
		d[k++] = s->heading;
		d[k++] = s->angular_velocity;
	}
	const bsim_ledger *l = row->ledger;
	const double ledger[LEDGER_COLUMNS] = {
	        row->t,     row->e_kin,    row->e_beam, row->e_kin + row->e_beam,
	        l->w_prop,  l->w_rand,     l->damper,   l->impact,
	        l->contact, l->correction, l->residual, l->sleep,
	        l->reset};
	memcpy(d + k, ledger, sizeof ledger);
	r->n++;
}

/* Column c of the rows as a field of s. */
static void rows_field(mxArray *s, const rows *r, int c, const char *name)
{
	double *d;
	mxArray *col = bmx_column((size_t)r->n, &d);
	for (long i = 0; i < r->n; i++)
		d[i] = r->v[(size_t)i * (size_t)r->width + (size_t)c];
	bmx_set(s, 0, name, col);
}

/* r.trajectory and r.ledger_rows, named as the CSV headers name them. */
static void rows_structs(mxArray *out, const rows *r)
{
	mxArray *t = mxCreateStructMatrix(1, 1, 0, NULL);
	char name[32];
	int c = 0;
	static const char *const head[] = {"t", "x", "y", "vx", "vy"};
	for (int i = 0; i < 5; i++)
		rows_field(t, r, c++, head[i]);
	for (int i = 1; i <= r->n_beams; i++) {
		snprintf(name, sizeof name, "theta%d", i);
		rows_field(t, r, c++, name);
		snprintf(name, sizeof name, "omega%d", i);
		rows_field(t, r, c++, name);
	}
	rows_field(t, r, c++, "f_rand");
	for (int i = 1; i <= r->n_beams; i++) {
		snprintf(name, sizeof name, "contact%d", i);
		rows_field(t, r, c++, name);
	}
	static const char *const tail[] = {"e_kin", "e_beam", "e_prop", "heading",
	                                   "angular_velocity"};
	for (int i = 0; i < 3 + 2 * r->body; i++)
		rows_field(t, r, c++, tail[i]);
	bmx_set(out, 0, "trajectory", t);
	mxArray *l = mxCreateStructMatrix(1, 1, 0, NULL);
	static const char *const ledger[LEDGER_COLUMNS] = {
	        "t",      "e_kin",   "e_beam",     "e_mech",   "w_prop", "w_rand", "damper",
	        "impact", "contact", "correction", "residual", "sleep",  "reset"};
	for (int i = 0; i < LEDGER_COLUMNS; i++)
		rows_field(l, r, c++, ledger[i]);
	bmx_set(out, 0, "ledger_rows", l);
}

#define MX_RESULT(m) BMX_MEMBER(s, 0, r, m);
#define MX_LEDGER(m) BMX_MEMBER(ledger, 0, &r->ledger, m);
#define MX_SOLVER(m) BMX_MEMBER(solver, 0, &r->solver, m);

/* The gates a lattice trial entered, one row each: ix, iy, t, pos, vx, vy
 * (run --json's path), and each beam's peak angle. */
static void path_fields(mxArray *out, const bsim_trial_log *log)
{
	mxArray *p = mxCreateDoubleMatrix((mwSize)log->n_entries, 6, mxREAL);
	double *d = mxGetPr(p);
	size_t n = (size_t)log->n_entries;
	for (size_t k = 0; k < n; k++) {
		const bsim_gate_entry *e = &log->entries[k];
		const double row[6] = {e->ix, e->iy, e->t, e->pos, e->v[0], e->v[1]};
		for (size_t j = 0; j < 6; j++)
			d[j * n + k] = row[j];
	}
	bmx_set(out, 0, "path", p);
	mxArray *edges = mxCreateCellMatrix((mwSize)log->n_entries, 1);
	for (size_t k = 0; k < n; k++)
		mxSetCell(edges, (mwIndex)k,
		          bmx_string(bsim_trial_edge_name(log->entries[k].edge)));
	bmx_set(out, 0, "path_edge", edges);
	/* every beam's peak: the moved beams', 0 for the others */
	mxArray *peak = mxCreateDoubleMatrix(1, (mwSize)log->n_beams, mxREAL);
	double *pd = mxGetPr(peak);
	for (int k = 0; k < log->n_peaks; k++)
		pd[log->peaks[k].beam] = log->peaks[k].peak;
	bmx_set(out, 0, "peak_theta", peak);
}

static mxArray *result_struct(const bsim_replay *rp, const bsim_backend *b,
                              const bsim_options *opts, const bsim_trial_result *r,
                              const bsim_trial_log *log)
{
	mxArray *s = mxCreateStructMatrix(1, 1, 0, NULL);
	bmx_set(s, 0, "scene", bmx_string(rp->scene_path ? rp->scene_path : ""));
	bmx_set(s, 0, "name", bmx_string(rp->scene.name));
	bmx_set(s, 0, "backend", bmx_string(b->name));
	mxArray *o = mxCreateStructMatrix(1, 1, 0, NULL);
	bsim_options eff;
	bsim_options_effective(b->knobs, b->n_knobs, opts, &eff);
	for (int i = 0; i < eff.n; i++) {
		char field[64];
		bmx_field_name(eff.key[i], field, sizeof field);
		/* numbers as numbers, as run --json writes them */
		char *end;
		double x = strtod(eff.value[i], &end);
		int number = end != eff.value[i] && *end == '\0';
		bmx_set(o, 0, field, number ? bmx_scalar(x) : bmx_string(eff.value[i]));
	}
	bmx_set(s, 0, "backend_options", o);
	bmx_set(s, 0, "seed", bmx_u64(rp->seed));
	bmx_set(s, 0, "group", bmx_scalar((double)rp->group + 1));
	bmx_set(s, 0, "trial", bmx_scalar((double)rp->trial + 1));
	bmx_set(s, 0, "mixed_seed", bmx_u64(rp->mixed_seed));
	/* The grid values applied, without the replay's "group G: " (G from 0). */
	const char *grid = strncmp(rp->grid, "group ", 6) == 0 ? strchr(rp->grid, ':') : NULL;
	grid = grid ? grid + 1 + (grid[1] == ' ') : rp->grid;
	bmx_set(s, 0, "grid", bmx_string(grid));
	bmx_set(s, 0, "outcome", bmx_string(bsim_trial_outcome_name(r->outcome)));
	bmx_set(s, 0, "type", bmx_string(bsim_trial_type_name(r->type)));
	bmx_set(s, 0, "landscape_beam", bmx_scalar(r->landscape_beam + 1));
	BSIM_TRIAL_RESULT_PLAIN(MX_RESULT)
	const double gate[2] = {r->final_ix, r->final_iy};
	bmx_set(s, 0, "final_gate", bmx_row(gate, 2));
	char label[48];
	bsim_lattice_location_label(bsim_lattice_location_of(r), label, sizeof label);
	bmx_set(s, 0, "location", bmx_string(label));
	bmx_set(s, 0, "reset_overlaps", bmx_scalar(r->reset_overlaps));
	path_fields(s, log);
	mxArray *ledger = mxCreateStructMatrix(1, 1, 0, NULL);
	BSIM_LEDGER_SHOWN(MX_LEDGER)
	bmx_set(s, 0, "ledger", ledger);
	mxArray *solver = mxCreateStructMatrix(1, 1, 0, NULL);
	BSIM_SOLVER_COUNTS(MX_SOLVER)
	bmx_set(s, 0, "solver", solver);
	char why[256] = "";
	if (r->instability)
		bsim_trial_instability_text(r, rp->scene.dt, why, sizeof why);
	bmx_set(s, 0, "instability", bmx_string(why));
	return s;
}

/* A stored run's row against the replay, as `beamsim run DIR` checks it. */
static int stored_check(const bsim_replay *rp, const bsim_trial_result *x, bsim_error *err)
{
	const bsim_trial_result *y = bsim_replay_stored_row(rp);
	if (!y)
		return BSIM_OK;
	char mine[256], theirs[256], where[BSIM_PATH_MAX + 160];
	bsim_replay_row(mine, sizeof mine, rp->group, rp->trial, x);
	bsim_replay_row(theirs, sizeof theirs, rp->group, rp->trial, y);
	if (strcmp(mine, theirs) == 0)
		return BSIM_OK;
	if (strcmp(rp->command, "compare") == 0) {
		char name[128];
		bsim_compare_dir_label(rp->label, name, sizeof name);
		snprintf(where, sizeof where, "%s/%s/trials.csv", rp->path, name);
	} else {
		snprintf(where, sizeof where, "%s/trials.csv", rp->path);
	}
	return bsim_error_set(err, BSIM_EDISAGREE,
	                      "the replay of group %ld, trial %ld (from 1; trials.csv's %ld, %ld) "
	                      "differs from its row in %s: %s, stored %s",
	                      rp->group + 1, rp->trial + 1, rp->group, rp->trial, where, mine,
	                      theirs);
}

typedef struct run_call {
	bmx_pool pool;
	bmx_trial trial;
	bsim_trial_log *log;
	rows traj;
} run_call;

static int run(run_call *c, int nrhs, const mxArray *prhs[], mxArray **out, char *warning,
               size_t warning_size, bsim_error *err)
{
	const mxArray *v[N_ARGS];
	if (nrhs < 1)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "expected a scene, an experiment or an output directory, "
		                      "then name-value pairs");
	if (bmx_pairs(nrhs, prhs, 1, arg_names, N_ARGS, v, err) != BSIM_OK)
		return BSIM_EINPUT;
	long stride = 1;
	int trajectory = 0;
	if ((v[A_STRIDE] && bmx_long("stride", v[A_STRIDE], 1, INT32_MAX, &stride, err)) ||
	    (v[A_TRAJECTORY] && bmx_flag("trajectory", v[A_TRAJECTORY], &trajectory, err)) ||
	    bmx_trial_open(prhs[0], v, &c->pool, &c->trial, err))
		return err->code;
	const bsim_replay *rp = c->trial.rp;
	const bsim_backend *b = c->trial.backend;
	bsim_options opts = c->trial.opts;
	if (!(c->log = bsim_trial_log_alloc()))
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	bsim_recorder rec = {.stride = (int)stride, .log = c->log, .overlap = 1};
	if (trajectory) {
		c->traj.n_beams = rp->scene.n_beams;
		c->traj.body = bsim_trial_body_columns(&rp->scene);
		c->traj.width = traj_width(rp->scene.n_beams, c->traj.body) + LEDGER_COLUMNS;
		rec.record = rows_record;
		rec.record_user = &c->traj;
	}
	bsim_trial_result res;
	memset(&res, 0, sizeof res);
	if (bsim_replay_run(rp, b, &opts, &rec, &res, err) != BSIM_OK)
		return err->code ? err->code : BSIM_EFAIL;
	if (c->traj.oom)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory for the trajectory");
	if (res.outcome == BSIM_UNSTABLE) {
		char why[256];
		bsim_trial_instability_text(&res, rp->scene.dt, why, sizeof why);
		snprintf(warning, warning_size, "%s backend: unstable trial: %s", b->name, why);
	}
	if (stored_check(rp, &res, err) != BSIM_OK)
		return err->code;
	*out = result_struct(rp, b, &opts, &res, c->log);
	if (trajectory)
		rows_structs(*out, &c->traj);
	return BSIM_OK;
}

void mexFunction(int nlhs, mxArray *plhs[], int nrhs, const mxArray *prhs[])
{
	(void)nlhs;
	run_call c;
	memset(&c, 0, sizeof c);
	bsim_error err;
	bsim_error_clear(&err);
	char warning[512] = "";
	mxArray *out = NULL;
	int rc = run(&c, nrhs, prhs, &out, warning, sizeof warning, &err);
	bmx_trial_free(&c.trial);
	bsim_trial_log_free(c.log);
	free(c.traj.v);
	bmx_pool_free(&c.pool);
	if (rc != BSIM_OK)
		bmx_fail(&err);
	/* An unstable trial is said, as the program says it (and exits 1). */
	if (warning[0])
		mexWarnMsgIdAndTxt("beamsim:unstable", "%s", warning);
	plhs[0] = out;
}
