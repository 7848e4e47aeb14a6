/* beamsim accuracy: consistency error, energy residual, p_traverse error
 * and cost per (backend, knobs, h), after Erez, Tassa & Todorov (ICRA 2015).
 *
 * Consistency error of a setting, over pieces k = 1..N restarted from the
 * reference at t_k (a multiple of the grid h_max, so t_k / h is a whole
 * step for every h = h_max / 2^i and the random-force schedule is replayed
 * from the same value):
 *   e_k = sqrt(|x - x_ref|^2 + sum_i (2 L_i sin((theta_i - theta_ref,i)/2))^2)
 * at t_k + T, m (body centre and beam tips stacked). A method of order q
 * has e ~ C h^q in smooth motion; impacts resolved at step ends give
 * O(h) near collisions whatever the integrator.
 * Residual rate = sum over the batch of sum_steps |r| / sum of simulated
 * time, J/s. Cost = wall time of the batch / its simulated time, and the
 * same with the CPU time of the batch's thread, which other programs on the
 * machine do not inflate. */
#include "beamsim/accuracy.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "util/atomic_file.h"
#include "util/clock.h"
#include "beamsim/effects.h"
#include "beamsim/schedule.h"
#include "beamsim/trial.h"

/* The scene at step h: same physics, same simulated duration. */
static int scene_at_step(bsim_scene *dst, const bsim_scene *base, double h, bsim_error *err)
{
	if (bsim_scene_copy(dst, base))
		return bsim_error_set(err, BSIM_EFAIL, "out of memory copying the scene");
	dst->dt = h;
	dst->max_steps = (int)ceil(base->max_steps * base->dt / h - 1e-9);
	return BSIM_OK;
}

typedef struct reference_trace {
	bsim_accuracy_reference *ref;
	long stride; /* steps between stored states */
	int cap, failed;
} reference_trace;

static void reference_keep(void *user, long step, const bsim_state *s)
{
	reference_trace *t = user;
	bsim_accuracy_reference *ref = t->ref;
	if (t->failed || step % t->stride != 0)
		return;
	if (ref->n == t->cap) {
		int cap = t->cap ? 2 * t->cap : 256;
		bsim_state *grown = realloc(ref->states, (size_t)cap * sizeof *grown);
		if (!grown) {
			t->failed = 1;
			return;
		}
		ref->states = grown;
		t->cap = cap;
	}
	if (bsim_state_init(&ref->states[ref->n], s->n_beams)) {
		t->failed = 1;
		return;
	}
	bsim_state_copy(&ref->states[ref->n], s);
	ref->n++;
}

int bsim_accuracy_reference_run(bsim_accuracy_reference *ref, const bsim_scene *scene,
                                const bsim_backend *b, const bsim_options *opts, uint64_t seed,
                                double grid, bsim_error *err)
{
	memset(ref, 0, sizeof *ref);
	ref->h = scene->dt;
	ref->grid = grid;
	long stride = lround(grid / scene->dt);
	if (stride < 1 || fabs(stride * scene->dt - grid) > 1e-9 * grid)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "accuracy: grid %g s is not a whole number of steps of %g s",
		                      grid, scene->dt);
	reference_trace t = {.ref = ref, .stride = stride};
	bsim_recorder rec = {.stride = 1, .trace = reference_keep, .trace_user = &t};
	bsim_trial_runner *r = bsim_trial_runner_alloc();
	if (!r)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	bsim_trial_result res;
	int rc = bsim_trial_run(r, scene, b, opts, seed, &rec, &res, err);
	bsim_trial_runner_free(r);
	if (rc == BSIM_OK && t.failed)
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory storing the reference");
	if (rc == BSIM_OK && res.outcome == BSIM_UNSTABLE) {
		char why[256];
		bsim_trial_instability_text(&res, scene->dt, why, sizeof why);
		rc = bsim_error_set(err, BSIM_EFAIL, "%s: the reference run is unstable: %s",
		                    b->name, why);
	}
	if (rc)
		bsim_accuracy_reference_free(ref);
	return rc;
}

void bsim_accuracy_reference_free(bsim_accuracy_reference *ref)
{
	for (int i = 0; i < ref->n; i++)
		bsim_state_free(&ref->states[i]);
	free(ref->states);
	memset(ref, 0, sizeof *ref);
}

/* Distance between two states' body centres and beam tips, stacked, m. */
static double state_distance(const bsim_scene *sc, const bsim_state *a, const bsim_state *b)
{
	double dx = a->x[0] - b->x[0], dy = a->x[1] - b->x[1];
	double e2 = dx * dx + dy * dy;
	for (int i = 0; i < a->n_beams && i < sc->n_beams; i++) {
		double chord = 2.0 * sc->beams[i].length * sin(0.5 * (a->theta[i] - b->theta[i]));
		e2 += chord * chord;
	}
	return sqrt(e2);
}

/* One piece: restart from ref->states[k] and run m steps of h. The world
 * is *kept's, reset (the last piece's, of the same scene), or a new one;
 * a backend that can reset leaves it in *kept for the next piece. */
static int consistency_piece(const bsim_accuracy_reference *ref, const bsim_scene *scene,
                             const bsim_backend *b, const bsim_options *opts, uint64_t seed, int k,
                             long m, bsim_state *s, bsim_world **kept, bsim_error *err)
{
	const double h = scene->dt;
	bsim_world *w = *kept;
	const int reused = w != NULL;
	*kept = NULL;
	int rc = reused ? b->reset(w, scene, err) : b->create(scene, opts, &w, err);
	if (rc) {
		if (reused)
			b->destroy(w);
		return rc;
	}
	rc = b->set_state(w, &ref->states[k], err);
	bsim_effects fx;
	if (rc == BSIM_OK && bsim_effects_init_taking(&fx, scene, seed, b->takes))
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	if (rc) {
		b->destroy(w);
		return rc;
	}
	/* Step n of this h starts at t = n h: the piece starts at t_k. */
	long n0 = lround(k * ref->grid / h);
	double f[BSIM_WRENCH];
	const bsim_state *at = &ref->states[k]; /* the body's motion at the step's start */
	for (long j = 0; j < m && rc == BSIM_OK; j++) {
		bsim_effects_force_at(&fx, n0 + j, h, at, f);
		rc = bsim_backend_step(b, w, f, f[2], h, err);
		if (fx.n_work < fx.n) { /* effects that read the state */
			b->get_state(w, s);
			at = s;
		}
	}
	if (rc == BSIM_OK)
		rc = bsim_effects_status(&fx, err);
	b->get_state(w, s);
	bsim_effects_free(&fx);
	if (rc == BSIM_OK && b->reset)
		*kept = w;
	else
		b->destroy(w);
	return rc;
}

int bsim_accuracy_consistency(const bsim_accuracy_reference *ref, const bsim_scene *scene,
                              const bsim_backend *b, const bsim_options *opts, uint64_t seed,
                              double piece, int n_pieces, double *mean, double *max,
                              bsim_error *err)
{
	const double h = scene->dt;
	long piece_k = lround(piece / ref->grid), m = lround(piece / h);
	long last_start = ref->n - 1 - piece_k;
	if (piece_k < 1 || fabs(m * h - piece) > 1e-9 * piece || n_pieces < 1)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "accuracy: piece %g s must be a whole number of grid "
		                      "intervals (%g s) and of steps (%g s)",
		                      piece, ref->grid, h);
	if (last_start < 0)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "accuracy: the reference (%g s) is shorter than a piece",
		                      (ref->n - 1) * ref->grid);
	bsim_state s;
	if (bsim_state_init(&s, scene->n_beams))
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	double sum = 0.0, worst = 0.0;
	int rc = BSIM_OK;
	bsim_world *kept = NULL; /* the pieces' world, reset from one to the next */
	for (int i = 0; i < n_pieces && rc == BSIM_OK; i++) {
		/* Midpoints of n_pieces equal spans of [0, last_start]. */
		int k = (int)lround((i + 0.5) * (double)last_start / n_pieces);
		rc = consistency_piece(ref, scene, b, opts, seed, k, m, &s, &kept, err);
		if (rc)
			break;
		double e = state_distance(scene, &s, &ref->states[k + piece_k]);
		if (!isfinite(e))
			e = INFINITY;
		sum += e;
		worst = fmax(worst, e);
	}
	if (kept)
		b->destroy(kept);
	bsim_state_free(&s);
	*mean = sum / n_pieces;
	*max = worst;
	return rc;
}

int bsim_accuracy_settings(const bsim_backend *b, bsim_accuracy_row **out, int *n, bsim_error *err)
{
	*out = NULL;
	*n = 0;
	if (b->n_accuracy < 1)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "accuracy: backend %s lists no knob settings to study",
		                      b->name);
	bsim_accuracy_row *rows = calloc((size_t)b->n_accuracy, sizeof *rows);
	if (!rows)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	for (int i = 0; i < b->n_accuracy; i++) {
		bsim_accuracy_row *r = &rows[i];
		r->backend = b->name;
		r->reference = i == 0;
		snprintf(r->setting, sizeof r->setting, "%s", b->accuracy[i].name);
		if (bsim_options_add_setting(&r->opts, &b->accuracy[i], err) != BSIM_OK) {
			free(rows);
			return BSIM_EINPUT;
		}
	}
	*out = rows;
	*n = b->n_accuracy;
	return BSIM_OK;
}

/* The batch of trials of one row: p_traverse, residual rate and cost. */
static int row_batch(bsim_accuracy_row *row, bsim_trial_runner *runner, const bsim_scene *scene,
                     const bsim_backend *b, const bsim_accuracy_config *cfg, bsim_error *err)
{
	int traversed = 0;
	double sim = 0.0, resid = 0.0;
	double t0 = bsim_clock_seconds(), c0 = bsim_clock_thread_cpu_seconds();
	for (int t = 0; t < cfg->n_trials; t++) {
		bsim_trial_result res;
		bsim_error e;
		int rc = bsim_trial_run(runner, scene, b, &row->opts,
		                        bsim_schedule_seed_mix(cfg->seed, 0, t), NULL, &res, &e);
		if (rc) {
			*err = e;
			return rc;
		}
		if (res.outcome == BSIM_UNSTABLE) { /* counted, as not traversed */
			row->failed++;
			continue;
		}
		traversed += res.outcome == BSIM_TRAVERSED;
		sim += res.steps_run * scene->dt;
		resid += res.ledger.residual_abs;
	}
	double wall = bsim_clock_seconds() - t0;
	double cpu = bsim_clock_thread_cpu_seconds() - c0;
	row->wall_seconds += wall;
	row->cpu_seconds = cpu;
	row->sim_seconds = sim;
	row->p = (double)traversed / cfg->n_trials;
	row->residual_rate = sim > 0 ? resid / sim : NAN;
	wall = wall > 1e-9 ? wall : 1e-9; /* a clock too coarse: 1 ns */
	row->cost = sim > 0 ? wall / sim : NAN;
	row->speed = sim > 0 ? sim / wall : NAN;
	row->cpu_cost = sim > 0 ? fmax(cpu, 1e-9) / sim : NAN;
	return BSIM_OK;
}

static int row_run(bsim_accuracy_row *row, const bsim_accuracy_reference *ref,
                   const bsim_scene *base, const bsim_backend *b, const bsim_accuracy_config *cfg,
                   bsim_error *err)
{
	bsim_scene sc;
	int rc = scene_at_step(&sc, base, row->h, err);
	if (rc)
		return rc;
	double t0 = bsim_clock_seconds();
	rc = bsim_accuracy_consistency(ref, &sc, b, &row->opts,
	                               bsim_schedule_seed_mix(cfg->seed, 0, 0), cfg->piece,
	                               cfg->n_pieces, &row->err_mean, &row->err_max, err);
	row->wall_seconds = bsim_clock_seconds() - t0;
	bsim_trial_runner *runner = rc ? NULL : bsim_trial_runner_alloc();
	if (!rc && !runner)
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	/* The batch's trials share a world, as a sweep's do (sc lives,
	 * unchanged, until the runner is freed). */
	if (!rc)
		bsim_trial_runner_keep_worlds(runner, 1);
	if (!rc)
		rc = row_batch(row, runner, &sc, b, cfg, err);
	bsim_trial_runner_free(runner);
	bsim_scene_free(&sc);
	return rc;
}

/* Relative cost of a row, to start the slowest first. */
static double row_weight(const bsim_accuracy_row *r)
{
	const char *sub = bsim_options_get(&r->opts, "substeps");
	const char *vi = bsim_options_get(&r->opts, "velocity_iterations");
	double w = 1.0 / r->h;
	if (sub)
		w *= atof(sub) * (1.0 + (vi ? atof(vi) : 8) / 10.0);
	return w;
}

static const double *weights_for_sort;
static int by_weight_desc(const void *a, const void *b)
{
	double wa = weights_for_sort[*(const int *)a], wb = weights_for_sort[*(const int *)b];
	if (wa != wb)
		return wa < wb ? 1 : -1;
	return *(const int *)a - *(const int *)b;
}

/* The options extra added to every setting, and to its name. */
static int settings_extend(bsim_accuracy_row *set, int n_set, const bsim_options *extra,
                           bsim_error *err)
{
	for (int s = 0; s < n_set; s++)
		for (int k = 0; k < extra->n; k++) {
			char kv[128];
			snprintf(kv, sizeof kv, "%s=%s", extra->key[k], extra->value[k]);
			int rc = bsim_options_add(&set[s].opts, kv, err);
			if (rc)
				return rc;
			size_t len = strlen(set[s].setting), add = strlen(kv);
			if (len + 1 + add >= sizeof set[s].setting)
				return bsim_error_set(err, BSIM_EINPUT,
				                      "accuracy: setting %s with %s: name too long",
				                      set[s].setting, kv);
			set[s].setting[len] = ' ';
			memcpy(set[s].setting + len + 1, kv, add + 1);
		}
	return BSIM_OK;
}

int bsim_accuracy_run(const bsim_scene *scene, const bsim_backend *const *backends, int n_backends,
                      const bsim_accuracy_config *cfg, bsim_accuracy_result *out, bsim_error *err)
{
	memset(out, 0, sizeof *out);
	double t_start = bsim_clock_seconds();
	int n_h = 0;
	for (double h = cfg->h_max; h >= cfg->h_ref * (1 - 1e-9); h /= 2)
		n_h++;
	if (n_h < 1 || fabs(cfg->h_max / ldexp(1.0, n_h - 1) - cfg->h_ref) > 1e-9 * cfg->h_ref)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "accuracy: h_ref %g s is not h_max %g s halved a whole "
		                      "number of times",
		                      cfg->h_ref, cfg->h_max);
	bsim_accuracy_reference *refs = calloc((size_t)n_backends, sizeof *refs);
	int *row_backend = NULL;
	if (!refs)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	int rc = BSIM_OK;
	/* Rows, backend by backend: settings x steps. */
	for (int bi = 0; bi < n_backends && rc == BSIM_OK; bi++) {
		bsim_accuracy_row *set;
		int n_set;
		rc = bsim_accuracy_settings(backends[bi], &set, &n_set, err);
		if (rc)
			break;
		if (cfg->backend_opts)
			rc = settings_extend(set, n_set, &cfg->backend_opts[bi], err);
		if (rc) {
			free(set);
			break;
		}
		bsim_accuracy_row *grown =
		        realloc(out->rows, (size_t)(out->n + n_set * n_h) * sizeof *grown);
		int *gb = realloc(row_backend, (size_t)(out->n + n_set * n_h) * sizeof *gb);
		if (grown)
			out->rows = grown;
		if (gb)
			row_backend = gb;
		if (!grown || !gb) {
			free(set);
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
			break;
		}
		for (int s = 0; s < n_set; s++)
			for (int i = 0; i < n_h; i++) {
				bsim_accuracy_row *r = &out->rows[out->n];
				*r = set[s];
				r->reference = set[s].reference && i == n_h - 1;
				r->h = cfg->h_max / ldexp(1.0, i);
				row_backend[out->n++] = bi;
			}
		/* The reference: finest step, first (most accurate) knobs. */
		bsim_scene sc;
		rc = scene_at_step(&sc, scene, cfg->h_ref, err);
		if (rc == BSIM_OK) {
			rc = bsim_accuracy_reference_run(&refs[bi], &sc, backends[bi], &set[0].opts,
			                                 bsim_schedule_seed_mix(cfg->seed, 0, 0),
			                                 cfg->h_max, err);
			bsim_scene_free(&sc);
		}
		free(set);
	}
	int *order = rc ? NULL : malloc((size_t)out->n * sizeof *order);
	double *weight = rc ? NULL : malloc((size_t)out->n * sizeof *weight);
	if (!rc && (!order || !weight))
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	if (rc == BSIM_OK) {
		for (int i = 0; i < out->n; i++) {
			order[i] = i;
			weight[i] = row_weight(&out->rows[i]);
		}
		weights_for_sort = weight;
		qsort(order, (size_t)out->n, sizeof *order, by_weight_desc);
		int threads = cfg->threads > 0 ? cfg->threads : omp_get_max_threads();
		int failed = 0, done = 0;
		bsim_error first = {0};
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
		for (int j = 0; j < out->n; j++) {
			int stop;
#pragma omp atomic read
			stop = failed;
			if (stop)
				continue;
			int i = order[j];
			bsim_error e;
			int code = row_run(&out->rows[i], &refs[row_backend[i]], scene,
			                   backends[row_backend[i]], cfg, &e);
#pragma omp critical(bsim_accuracy_report)
			{
				if (code && !failed) {
					failed = code;
					first = e;
				}
				done++;
				if (cfg->progress)
					cfg->progress(cfg->progress_user, done, out->n);
			}
		}
		if (failed) {
			rc = failed;
			if (err)
				*err = first;
		}
	}
	/* p_traverse of each backend's reference row. */
	for (int i = 0; rc == BSIM_OK && i < out->n; i++) {
		double p_ref = NAN;
		for (int j = 0; j < out->n; j++)
			if (out->rows[j].reference && row_backend[j] == row_backend[i])
				p_ref = out->rows[j].p;
		out->rows[i].p_ref = p_ref;
		out->rows[i].p_err = fabs(out->rows[i].p - p_ref);
	}
	for (int bi = 0; bi < n_backends; bi++)
		bsim_accuracy_reference_free(&refs[bi]);
	free(refs);
	free(row_backend);
	free(order);
	free(weight);
	if (rc)
		bsim_accuracy_result_free(out);
	out->wall_seconds = bsim_clock_seconds() - t_start;
	return rc;
}

void bsim_accuracy_result_free(bsim_accuracy_result *r)
{
	free(r->rows);
	r->rows = NULL;
	r->n = 0;
}

int bsim_accuracy_write_csv(const char *path, const bsim_accuracy_result *r, bsim_error *err)
{
	bsim_atomic_file o;
	int rc = bsim_atomic_file_open(&o, path, err);
	if (rc)
		return rc;
	fputs("backend,setting,reference,h_s,err_mean_m,err_max_m,residual_J_per_s,p_traverse,"
	      "p_ref,p_err,sim_seconds,wall_seconds,wall_per_sim_s,speed_x_realtime,failed,"
	      "cpu_seconds,cpu_per_sim_s\n",
	      o.f);
	for (int i = 0; i < r->n; i++) {
		const bsim_accuracy_row *w = &r->rows[i];
		fprintf(o.f,
		        "%s,%s,%d,%.9g,%.6e,%.6e,%.6e,%.4f,%.4f,%.4f,%.6g,%.6g,%.6e,%.6g,%d,%.6g,"
		        "%.6e\n",
		        w->backend, w->setting, w->reference, w->h, w->err_mean, w->err_max,
		        w->residual_rate, w->p, w->p_ref, w->p_err, w->sim_seconds, w->wall_seconds,
		        w->cost, w->speed, w->failed, w->cpu_seconds, w->cpu_cost);
	}
	return bsim_atomic_file_commit(&o, err);
}

/* A row at the reference step compares a backend with itself (error 0, or
 * another setting's round-off), which says nothing of cost: it neither
 * joins the front nor pushes another row off it, as in the figure
 * (figures_accuracy.c leaves out the same rows, h <= 1.5 h_ref). */
static int on_reference_step(const bsim_accuracy_row *a, double h_ref)
{
	return a->h <= 1.5 * h_ref;
}

/* Row i is on the Pareto front of the rows off the reference step if no
 * other of them is at least as fast and as accurate and better in one. */
static int pareto(const bsim_accuracy_result *r, double h_ref, int i)
{
	const bsim_accuracy_row *a = &r->rows[i];
	if (on_reference_step(a, h_ref))
		return 0;
	for (int j = 0; j < r->n; j++) {
		const bsim_accuracy_row *b = &r->rows[j];
		if (j != i && !on_reference_step(b, h_ref) && b->speed >= a->speed &&
		    b->err_mean <= a->err_mean &&
		    (b->speed > a->speed || b->err_mean < a->err_mean))
			return 0;
	}
	return 1;
}

/* The equal-error table: per target, each backend's cheapest row reaching
 * it and its cost over the first backend's (equal_error.csv). */
static void equal_error_md(FILE *f, const bsim_accuracy_result *r, const bsim_accuracy_equal *eq,
                           int n_eq)
{
	fprintf(f,
	        "\n## At equal error\n\n"
	        "For each target of mean consistency error, each backend's cheapest setting "
	        "reaching it: the least CPU time (the thread's, per simulated second) among its "
	        "rows with err mean at most the target, leaving out the reference (its error is "
	        "0 by construction) and rows with an unstable trial. ratio: that cost over "
	        "%s's at the same target (`ratio_equal_error` in equal_error.csv).\n\n"
	        "| target (m) | backend | setting | h (s) | err mean (m) | CPU/sim | ratio |\n"
	        "|---:|---|---|---:|---:|---:|---:|\n",
	        eq[0].backend);
	for (int i = 0; i < n_eq; i++) {
		const bsim_accuracy_equal *e = &eq[i];
		if (e->row < 0) {
			fprintf(f, "| %g | %s | none reaches it | | | | |\n", e->target,
			        e->backend);
			continue;
		}
		const bsim_accuracy_row *w = &r->rows[e->row];
		fprintf(f, "| %g | %s | %s | %g | %.3g | %.3g | %.3g |\n", e->target, e->backend,
		        w->setting, w->h, w->err_mean, e->cpu_cost, e->ratio);
	}
}

int bsim_accuracy_write_md(const char *path, const bsim_accuracy_result *r,
                           const bsim_accuracy_config *cfg, const char *scene_label,
                           bsim_error *err)
{
	bsim_atomic_file o;
	int rc = bsim_atomic_file_open(&o, path, err);
	if (rc)
		return rc;
	FILE *f = o.f;
	fprintf(f,
	        "# Accuracy against cost\n\n"
	        "Scene %s. Method of Erez, Tassa & Todorov (ICRA 2015): per backend a "
	        "reference trajectory at h = %g s with the first (most accurate) knobs; "
	        "%d pieces of %g s restarted from it (set_state) give the consistency error "
	        "(body centre and beam tips, m, mean over pieces). p_traverse over %d trials "
	        "(seed %llu) against the reference setting's. Residual: energy-ledger "
	        "sum |r| per simulated second, J/s. Speed: simulated seconds per wall second "
	        "(x real time), one thread. * marks the Pareto front (error vs speed) of the "
	        "rows above the reference step (there a backend is compared with itself).\n\n",
	        scene_label, cfg->h_ref, cfg->n_pieces, cfg->piece, cfg->n_trials,
	        (unsigned long long)cfg->seed);
	fputs("| backend | setting | h (s) | err mean (m) | err max (m) | residual (J/s) | p | "
	      "p err | wall/sim | speed (x real) | front |\n"
	      "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|:-:|\n",
	      f);
	for (int i = 0; i < r->n; i++) {
		const bsim_accuracy_row *w = &r->rows[i];
		fprintf(f,
		        "| %s | %s%s | %g | %.3g | %.3g | %.3g | %.3f | %.3f | %.3g | %.4g | %s "
		        "|\n",
		        w->backend, w->setting, w->reference ? " (ref)" : "", w->h, w->err_mean,
		        w->err_max, w->residual_rate, w->p, w->p_err, w->cost, w->speed,
		        pareto(r, cfg->h_ref, i) ? "*" : "");
	}
	fputs("\n## Pareto front (all backends)\n\n| backend | setting | h (s) | err mean (m) | "
	      "speed (x real) |\n|---|---|---:|---:|---:|\n",
	      f);
	for (int i = 0; i < r->n; i++)
		if (pareto(r, cfg->h_ref, i))
			fprintf(f, "| %s | %s | %g | %.3g | %.4g |\n", r->rows[i].backend,
			        r->rows[i].setting, r->rows[i].h, r->rows[i].err_mean,
			        r->rows[i].speed);
	bsim_accuracy_equal *eq = NULL;
	int n_eq = 0;
	rc = bsim_accuracy_equal_error(r, cfg->targets, cfg->n_targets, &eq, &n_eq, err);
	if (rc == BSIM_OK && n_eq > 0)
		equal_error_md(f, r, eq, n_eq);
	free(eq);
	if (rc) {
		bsim_atomic_file_abort(&o);
		return rc;
	}
	return bsim_atomic_file_commit(&o, err);
}
