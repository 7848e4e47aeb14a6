/* One trial on several sides with the same random-force schedule.
 *
 * Every run records the body centre x_k after every step k; the
 * trajectories of sides A and B separate at the first k with
 *   |x_k^A - x_k^B| > sep_distance
 * (beamsim compare uses 1% of the body radius), t = k h. Only steps both
 * runs reached count: a run that ended cannot separate any more. */
#include "run/trial_sides.h"

#include <math.h>
#include <stdlib.h>

trial_sides *bsim_trial_sides_alloc(int n)
{
	if (n < 2 || n > BSIM_SWEEP_SIDES_MAX)
		return NULL;
	trial_sides *p = calloc(1, sizeof *p);
	if (!p)
		return NULL;
	p->n = n;
	for (int s = 0; s < n; s++)
		if (!(p->runner[s] = bsim_trial_runner_alloc())) {
			bsim_trial_sides_free(p);
			return NULL;
		}
	return p;
}

void bsim_trial_sides_keep_worlds(trial_sides *p, int on)
{
	for (int s = 0; s < p->n; s++)
		bsim_trial_runner_keep_worlds(p->runner[s], on);
}

void bsim_trial_sides_free(trial_sides *p)
{
	if (!p)
		return;
	for (int s = 0; s < p->n; s++) {
		bsim_trial_runner_free(p->runner[s]);
		free(p->trace[s].xy);
	}
	free(p);
}

static void trace_push(void *user, long step, const bsim_state *s)
{
	trial_trace *tr = user;
	(void)step;
	if (tr->oom)
		return;
	if (tr->n == tr->cap) {
		long cap = tr->cap ? 2 * tr->cap : 4096;
		double *xy = realloc(tr->xy, (size_t)cap * 2 * sizeof *xy);
		if (!xy) {
			tr->oom = 1;
			return;
		}
		tr->xy = xy;
		tr->cap = cap;
	}
	tr->xy[2 * tr->n] = s->x[0];
	tr->xy[2 * tr->n + 1] = s->x[1];
	tr->n++;
}

static int run_traced(trial_sides *p, int k, const bsim_scene *scene, const bsim_backend *b,
                      const bsim_options *opts, uint64_t seed, bsim_trial_result *r,
                      bsim_trial_log *log, bsim_error *err)
{
	trial_trace *tr = &p->trace[k];
	tr->n = 0;
	tr->oom = 0;
	bsim_recorder rec = {
	        .csv = NULL, .stride = 1, .trace = trace_push, .trace_user = tr, .log = log};
	if (p->keep[k]) {
		rec.stride = p->keep_stride;
		rec.record = bsim_trajectory_record;
		rec.record_user = p->keep[k];
	}
	int rc = bsim_trial_run(p->runner[k], scene, b, opts, seed, &rec, r, err);
	if (rc == BSIM_OK && tr->oom)
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory for a %ld-step trace", tr->n);
	if (rc == BSIM_OK && p->keep[k] && p->keep[k]->oom)
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory for a kept trajectory");
	return rc;
}

/* The first time the traces of sides a and b are more than d apart; -1. */
static double separation(const trial_sides *p, int a, int b, double d, double dt)
{
	const double *xa = p->trace[a].xy, *xb = p->trace[b].xy;
	long n = p->trace[a].n < p->trace[b].n ? p->trace[a].n : p->trace[b].n;
	for (long k = 0; k < n; k++)
		if (hypot(xa[2 * k] - xb[2 * k], xa[2 * k + 1] - xb[2 * k + 1]) > d)
			return (double)k * dt;
	return -1.0;
}

int bsim_trial_sides_run(trial_sides *p, const bsim_scene *const *scene,
                         const bsim_backend *const *backend, const bsim_options *const *opts,
                         uint64_t seed, double sep_distance, bsim_trial_result *const *result,
                         bsim_trial_log *const *log, double *t_separate, bsim_error *err)
{
	for (int s = 0; s < p->n; s++) {
		int rc = run_traced(p, s, scene[s], backend[s], opts[s], seed, result[s],
		                    log ? log[s] : NULL, err);
		if (rc != BSIM_OK)
			return rc;
	}
	for (int k = 0, n = bsim_sweep_pairs(p->n); k < n; k++) {
		int side[2];
		bsim_sweep_pair(p->n, k, side);
		t_separate[k] = separation(p, side[0], side[1], sep_distance, scene[0]->dt);
	}
	return BSIM_OK;
}
