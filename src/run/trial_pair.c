/* One trial on two backends with the same random-force schedule.
 *
 * Both runs record the body centre x_k after every step k; the paired
 * trajectories separate at the first k with
 *   |x_k^A - x_k^B| > sep_distance
 * (beamsim compare uses 1% of the body radius), t = k h. Only steps both
 * runs reached count: a run that ended cannot separate any more. */
#include "run/trial_pair.h"

#include <math.h>
#include <stdlib.h>

trial_pair *trial_pair_alloc(void)
{
	trial_pair *p = calloc(1, sizeof *p);
	if (p && (!(p->runner[0] = bsim_trial_runner_alloc()) ||
	          !(p->runner[1] = bsim_trial_runner_alloc()))) {
		bsim_trial_runner_free(p->runner[0]);
		free(p);
		p = NULL;
	}
	return p;
}

void trial_pair_keep_worlds(trial_pair *p, int on)
{
	bsim_trial_runner_keep_worlds(p->runner[0], on);
	bsim_trial_runner_keep_worlds(p->runner[1], on);
}

void trial_pair_free(trial_pair *p)
{
	if (!p)
		return;
	bsim_trial_runner_free(p->runner[0]);
	bsim_trial_runner_free(p->runner[1]);
	free(p->trace[0].xy);
	free(p->trace[1].xy);
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

static int run_traced(trial_pair *p, int k, const bsim_scene *scene, const bsim_backend *b,
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

int trial_pair_run(trial_pair *p, const bsim_scene *scene, const bsim_scene *scene_b,
                   const bsim_backend *a, const bsim_options *opts_a, const bsim_backend *b,
                   const bsim_options *opts_b, uint64_t seed, double sep_distance,
                   bsim_trial_result *ra, bsim_trial_result *rb, bsim_trial_log *logs[2],
                   double *t_separate, bsim_error *err)
{
	int rc = run_traced(p, 0, scene, a, opts_a, seed, ra, logs ? logs[0] : NULL, err);
	if (rc == BSIM_OK)
		rc = run_traced(p, 1, scene_b, b, opts_b, seed, rb, logs ? logs[1] : NULL, err);
	if (rc != BSIM_OK)
		return rc;
	const double *xa = p->trace[0].xy, *xb = p->trace[1].xy;
	long n = p->trace[0].n < p->trace[1].n ? p->trace[0].n : p->trace[1].n;
	*t_separate = -1.0;
	for (long k = 0; k < n; k++)
		if (hypot(xa[2 * k] - xb[2 * k], xa[2 * k + 1] - xb[2 * k + 1]) > sep_distance) {
			*t_separate = (double)k * scene->dt;
			break;
		}
	return BSIM_OK;
}
