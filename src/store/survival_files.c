/* A sweep's time to leave the gate: counted per group as the trials
 * stream by, written as survival.csv and horizon.csv; see
 * survival_files.h.
 *
 * Memory: per group n_bins x 4 counters of 4 bytes, n_bins at most
 * SURVIVAL_BINS_MAX + 1 (the essay's 3000-step trial: 3001 bins, 48 kB, at
 * exact step times) and, over the sweep, about SURVIVAL_BINS_TOTAL bins
 * (16 MiB) however many trials run; many groups share them out coarser,
 * never below SURVIVAL_BINS_MIN a group. */
#define _POSIX_C_SOURCE 200809L

#include "store/survival_files.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/limits.h"
#include "beamsim/stats.h"
#include "store/session.h"
#include "util/atomic_file.h"
#include "util/survival.h"

/* Points of the horizon grid of each group: h = H j / HORIZON_POINTS. */
#define HORIZON_POINTS 48

int bsim_survival_acc_init(survival_acc *a, const bsim_experiment *e, const bsim_scene *scenes,
                           const bsim_override *sets, int n_sets, bsim_error *err)
{
	memset(a, 0, sizeof *a);
	a->e = e;
	a->n_groups = e->n_groups;
	a->g = calloc(e->n_groups > 0 ? (size_t)e->n_groups : 1, sizeof *a->g);
	if (!a->g)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory for survival counts");
	long share = SURVIVAL_BINS_TOTAL / (e->n_groups > 0 ? e->n_groups : 1);
	int cap = share > SURVIVAL_BINS_MAX   ? SURVIVAL_BINS_MAX
	          : share < SURVIVAL_BINS_MIN ? SURVIVAL_BINS_MIN
	                                      : (int)share;
	for (int k = 0; k < e->n_groups; k++) {
		bsim_scene s;
		if (!scenes) {
			int rc = bsim_experiment_group_scene(e, k, sets, n_sets, &s, err);
			if (rc != BSIM_OK)
				return rc;
		}
		const bsim_scene *sk = scenes ? &scenes[k] : &s;
		survival_group *g = &a->g[k];
		g->dt = sk->dt;
		g->max_steps = sk->max_steps > 0 ? sk->max_steps : 1;
		if (!scenes)
			bsim_scene_free(&s);
		g->width = (g->max_steps + cap - 1) / cap;
		g->n_bins = (g->max_steps + g->width - 1) / g->width + 1;
		g->count = calloc((size_t)g->n_bins * SURV_KINDS, sizeof *g->count);
		if (!g->count)
			return bsim_error_set(err, BSIM_EFAIL, "out of memory for survival counts");
	}
	return BSIM_OK;
}

void bsim_survival_acc_free(survival_acc *a)
{
	for (int k = 0; a->g && k < a->n_groups; k++)
		free(a->g[k].count);
	free(a->g);
	memset(a, 0, sizeof *a);
}

static int kind_of(bsim_outcome o)
{
	switch (o) {
	case BSIM_TRAVERSED:
		return SURV_TRAVERSED;
	case BSIM_SIDE_EXIT:
		return SURV_SIDE_EXIT;
	case BSIM_UNSTABLE:
		return SURV_UNSTABLE;
	default:
		return SURV_STUCK;
	}
}

void bsim_survival_acc_add(survival_acc *a, long first, long n, int trials,
                           const bsim_trial_result *results)
{
	for (long k = 0; k < n; k++) {
		long gi = (first + k) / trials;
		if (gi < 0 || gi >= a->n_groups)
			continue;
		survival_group *g = &a->g[gi];
		const bsim_trial_result *r = &results[k];
		long steps = r->steps < 0 ? 0 : r->steps > g->max_steps ? g->max_steps : r->steps;
		long b = (steps + g->width - 1) / g->width;
		g->count[b * SURV_KINDS + kind_of(r->outcome)]++;
		g->n++;
	}
}

/* The time of bin b, s: the end of its steps, the horizon at most. */
static long bin_steps(const survival_group *g, int b)
{
	long s = (long)b * g->width;
	return s < g->max_steps ? s : g->max_steps;
}

static void survival_rows(FILE *f, int k, const survival_group *g)
{
	survival_km km;
	bsim_survival_km_start(&km, g->n);
	fprintf(f, "%d,0,%ld,0,1,1,1,0\n", k, g->n);
	for (int b = 0; b < g->n_bins; b++) {
		const uint32_t *c = &g->count[(size_t)b * SURV_KINDS];
		long d = (long)c[SURV_TRAVERSED] + c[SURV_SIDE_EXIT];
		long cens = (long)c[SURV_UNSTABLE] + c[SURV_STUCK];
		if (d == 0 && cens == 0)
			continue;
		long at_risk = km.at_risk;
		bsim_survival_km_step(&km, d, cens);
		double lo, hi;
		bsim_survival_km_interval(&km, BSIM_STATS_Z95, &lo, &hi);
		fprintf(f, "%d,%.10g,%ld,%ld,%.10g,%.10g,%.10g,%ld\n", k, bin_steps(g, b) * g->dt,
		        at_risk, d, km.s, lo, hi, cens);
	}
}

static void share(FILE *f, long k, long n)
{
	double lo, hi;
	bsim_stats_wilson((int)k, (int)n, BSIM_STATS_Z95, &lo, &hi);
	fprintf(f, ",%ld,%.6g,%.6g,%.6g", k, n > 0 ? (double)k / n : 0.0, lo, hi);
}

static void horizon_rows(FILE *f, int k, const survival_group *g)
{
	long by[SURV_KINDS] = {0}, last = -1;
	int b = 0;
	for (int j = 1; j <= HORIZON_POINTS; j++) {
		long h = (long)g->max_steps * j / HORIZON_POINTS;
		if (h == last || h == 0)
			continue;
		last = h;
		for (; b < g->n_bins && bin_steps(g, b) <= h; b++)
			for (int i = 0; i < SURV_KINDS; i++)
				by[i] += g->count[(size_t)b * SURV_KINDS + i];
		/* with horizon h a trial still going at h would be stuck */
		long stuck = g->n - by[SURV_TRAVERSED] - by[SURV_SIDE_EXIT] - by[SURV_UNSTABLE];
		fprintf(f, "%d,%.10g", k, h * g->dt);
		share(f, by[SURV_TRAVERSED], g->n);
		share(f, by[SURV_SIDE_EXIT], g->n);
		share(f, stuck, g->n);
		fprintf(f, ",%ld\n", by[SURV_UNSTABLE]);
	}
}

static int write_table(const survival_acc *a, const char *dir, const char *name, const char *header,
                       void (*rows)(FILE *, int, const survival_group *), bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	bsim_atomic_file o;
	if (bsim_session_path(path, sizeof path, dir, name, err) ||
	    bsim_atomic_file_open(&o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	fputs(header, o.f);
	for (int k = 0; k < a->n_groups; k++)
		rows(o.f, k, &a->g[k]);
	return bsim_atomic_file_commit(&o, err);
}

int bsim_survival_acc_write(const survival_acc *a, const char *dir, bsim_error *err)
{
	if (write_table(a, dir, "survival.csv",
	                "group,t,at_risk,events,survival,ci_low,ci_high,censored\n", survival_rows,
	                err) != BSIM_OK)
		return BSIM_EFAIL;
	return write_table(a, dir, "horizon.csv",
	                   "group,h,traversed,p_traverse,traverse_lo,traverse_hi,side_exit,"
	                   "p_side_exit,side_exit_lo,side_exit_hi,stuck,p_stuck,stuck_lo,stuck_hi,"
	                   "unstable\n",
	                   horizon_rows, err);
}
