/* The chain against the simulation it replaces (beamsim markov validate;
 * beamsim/markov.h): distances with the sampling errors beside them, the
 * cost of both, and the files and figure that show them. */
#define _POSIX_C_SOURCE 200809L

#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <gsl/gsl_sort.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "analysis/markov_internal.h"
#include "beamsim/backend_registry.h"
#include "util/atomic_file.h"
#include "beamsim/backend.h"
#include "beamsim/experiment.h"
#include "beamsim/markov.h"
#include "beamsim/output.h"
#include "beamsim/stats.h"
#include "beamsim/sweep.h"
#include "beamsim/lattice_outcome.h"
#include "util/clock.h"
#include "util/figure.h"
#include "util/json.h"
#include "store/matlab.h"
#include "store/session.h"
#include "store/sweep_batch.h"
#include "beamsim/limits.h"

bsim_markov_validate_def bsim_markov_validate_def_default(void)
{
	return (bsim_markov_validate_def){.bootstrap = 2000,
	                                  .map_resamples = 40,
	                                  .nearest = bsim_markov_nearest_def_default()};
}

void bsim_markov_validation_free(bsim_markov_validation *v)
{
	if (!v)
		return;
	free(v->checks);
	memset(v, 0, sizeof *v);
}

/* The index of a final location in a prediction's list (its order). */
static int loc_index(const bsim_lattice_def *l, bsim_location loc)
{
	switch (loc.kind) {
	case BSIM_LOCATION_END:
		return loc.ix - l->ix_min;
	case BSIM_LOCATION_SIDE:
		return l->columns + loc.iy;
	default:
		return l->columns + l->rows + loc.iy * l->columns + loc.ix - l->ix_min;
	}
}

static double tv(const double *p, const double *q, int n)
{
	double s = 0.0;
	for (int i = 0; i < n; i++)
		s += fabs(p[i] - q[i]);
	return 0.5 * s;
}

/* Mean and 95th percentile of TV(p, resample of p with n trials). */
static void bootstrap_sim(gsl_rng *rng, const double *p, int n_loc, int trials, int B, double *mean,
                          double *q95)
{
	unsigned int *k = malloc((size_t)n_loc * sizeof *k);
	double *q = malloc((size_t)n_loc * sizeof *q), *d = malloc((size_t)B * sizeof *d);
	*mean = NAN;
	*q95 = NAN;
	if (k && q && d && B > 0) {
		double s = 0.0;
		for (int b = 0; b < B; b++) {
			gsl_ran_multinomial(rng, (size_t)n_loc, (unsigned)trials, p, k);
			for (int i = 0; i < n_loc; i++)
				q[i] = (double)k[i] / trials;
			d[b] = tv(p, q, n_loc);
			s += d[b];
		}
		gsl_sort(d, 1, (size_t)B);
		*mean = s / B;
		*q95 = d[(size_t)(0.95 * (B - 1))];
	}
	free(k);
	free(q);
	free(d);
}

/* Mean TV between the chain of set and chains of its maps with each row
 * resampled multinomially (the same number of trials per bin). A chain a
 * resample, so stop (may be NULL) is looked at before each. */
static int bootstrap_maps(gsl_rng *rng, const bsim_scene *scene, const bsim_markov_set *set,
                          const bsim_markov_prediction *pred, int B,
                          const volatile sig_atomic_t *stop, double *mean, bsim_error *err)
{
	*mean = NAN;
	if (B <= 0 || set->n == 0)
		return BSIM_OK;
	bsim_markov_set rs = *set;
	rs.maps = calloc((size_t)set->n, sizeof *rs.maps);
	/* a row's exits are at most its trials: the start's the most */
	int most = 1;
	for (int i = 0; i < set->n; i++) {
		const bsim_markov_map *m = &set->maps[i];
		for (int a = 0; a < m->n_bins; a++)
			if (m->count_first[a + 1] - m->count_first[a] > most)
				most = m->count_first[a + 1] - m->count_first[a];
	}
	double *p = malloc((size_t)most * sizeof *p);
	unsigned int *k = malloc((size_t)most * sizeof *k);
	int rc = rs.maps && p && k ? BSIM_OK : bsim_error_set(err, BSIM_EFAIL, "out of memory");
	for (int i = 0; rc == BSIM_OK && i < set->n; i++) {
		rs.maps[i] = set->maps[i];
		rs.maps[i].count_first = rs.maps[i].count_exit = rs.maps[i].count_n = NULL;
		if (bsim_markov_counts_copy(&rs.maps[i], &set->maps[i]) != 0)
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	double s = 0.0;
	for (int b = 0; rc == BSIM_OK && b < B; b++) {
		if (stop && *stop) {
			rc = bsim_error_set(
			        err, BSIM_ESTOPPED,
			        "stopped in the maps' resample %d of %d (their sampling "
			        "error), the trials done",
			        b + 1, B);
			break;
		}
		/* each row resampled over its own exits: an exit it never had
		 * has probability 0 */
		for (int i = 0; i < set->n; i++) {
			const bsim_markov_map *m = &set->maps[i];
			for (int a = 0; a < m->n_bins; a++) {
				const int first = m->count_first[a],
				          n = m->count_first[a + 1] - first;
				long total = 0;
				for (int x = 0; x < n; x++) {
					total += m->count_n[first + x];
					p[x] = (double)m->count_n[first + x];
				}
				gsl_ran_multinomial(rng, (size_t)n, (unsigned)total, p, k);
				for (int x = 0; x < n; x++)
					rs.maps[i].count_n[first + x] = (int)k[x];
			}
		}
		bsim_markov_prediction q;
		rc = bsim_markov_predict(scene, &rs, &q, err);
		if (rc == BSIM_OK)
			s += tv(pred->p, q.p, pred->n_locations);
		bsim_markov_prediction_free(&q);
	}
	if (rc == BSIM_OK)
		*mean = s / B;
	for (int i = 0; rs.maps && i < set->n; i++)
		bsim_markov_counts_free(&rs.maps[i]);
	free(rs.maps);
	free(p);
	free(k);
	return rc;
}

/* The CPU seconds of one prediction as `markov predict` makes it by
 * default (the sweeps to the maps' sampling tolerance, no distribution of
 * gates; bsim_markov_tol_sampling): the mean of as many as fit in 0.2 s of
 * the thread's CPU (at least 3). */
static int time_predict(const bsim_scene *scene, const bsim_markov_set *set, double *seconds,
                        bsim_error *err)
{
	const double tol = bsim_markov_tol_sampling(set);
	int n = 0;
	double t0 = bsim_clock_thread_cpu_seconds(), t;
	do {
		bsim_markov_prediction q;
		int rc = bsim_markov_predict_with(scene, set, tol, 0, &q, err);
		bsim_markov_prediction_free(&q);
		if (rc != BSIM_OK)
			return rc;
		n++;
		t = bsim_clock_thread_cpu_seconds() - t0;
	} while (n < 3 || t < 0.2);
	*seconds = t / n;
	return BSIM_OK;
}

static const char *const protocol_names[] = {"essay", "world"};

/* The time to the outcome of T simulated trials t against the chain's
 * walks in pred: the checks' time fields, and *cdf (allocated) the
 * simulated P(out by the end of each of pred's time bins). */
static int time_check(const bsim_markov_prediction *pred, const bsim_trial_result *t, int T,
                      double **cdf, bsim_markov_check *c, bsim_error *err)
{
	const int nb = pred->n_time_bins;
	double *f = calloc((size_t)nb, sizeof *f);
	if (!f)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	long out = 0;
	double sum = 0.0, sum2 = 0.0;
	for (int i = 0; i < T; i++) {
		if (bsim_lattice_location_of(&t[i]).kind == BSIM_LOCATION_STUCK)
			continue;
		out++;
		sum += t[i].t_end;
		sum2 += t[i].t_end * t[i].t_end;
		/* the walks' bin: [b bin, (b + 1) bin) */
		long b = (long)floor(t[i].t_end / pred->time_bin + 1e-9);
		b = b < 0 ? 0 : b >= nb ? nb - 1 : b;
		f[b] += 1.0 / T;
	}
	for (int b = 1; b < nb; b++)
		f[b] += f[b - 1];
	c->has_time = 1;
	c->out_sim = (double)out / T;
	bsim_stats_wilson((int)out, T, BSIM_STATS_Z95, &c->out_sim_lo, &c->out_sim_hi);
	c->out_chain = pred->p_by[0] + pred->p_by[1];
	c->t_out_sim = out > 0 ? sum / out : NAN;
	double var = out > 1 ? (sum2 - sum * sum / out) / (out - 1) : NAN;
	c->t_out_sim_ci = out > 1 ? 1.96 * sqrt(fmax(var, 0.0) / out) : NAN;
	/* the walks out: end and side pooled */
	const double w = (double)pred->walks, n0 = pred->p_by[0] * w, n1 = pred->p_by[1] * w;
	const double nw = n0 + n1;
	double m = NAN, s2 = 0.0;
	if (nw > 0) {
		const double m0 = n0 > 0 ? pred->t_mean[0] : 0.0,
		             m1 = n1 > 0 ? pred->t_mean[1] : 0.0;
		m = (n0 * m0 + n1 * m1) / nw;
		/* pooled variance: within kinds plus between */
		const double v0 = n0 > 1 ? pred->t_sd[0] * pred->t_sd[0] : 0.0,
		             v1 = n1 > 1 ? pred->t_sd[1] * pred->t_sd[1] : 0.0;
		s2 = (fmax(n0 - 1, 0) * v0 + fmax(n1 - 1, 0) * v1 + n0 * (m0 - m) * (m0 - m) +
		      n1 * (m1 - m) * (m1 - m)) /
		     fmax(nw - 1, 1);
	}
	c->t_out_chain = m;
	c->t_out_chain_ci = nw > 1 ? 1.96 * sqrt(s2 / nw) : NAN;
	c->t_out_diff_ci = hypot(c->t_out_sim_ci, c->t_out_chain_ci);
	double chain = 0.0, ks = 0.0;
	for (int b = 0; b < nb; b++) {
		chain += pred->p_time[b * 3] + pred->p_time[b * 3 + 1];
		ks = fmax(ks, fabs(f[b] - chain));
	}
	c->t_ks = ks;
	c->t_ks95 = sqrt(log(2.0 / 0.05) / (2.0 * T));
	*cdf = f;
	return BSIM_OK;
}

/* ---- files ------------------------------------------------------------------ */

typedef struct group_data {
	bsim_markov_prediction pred;
	double *p_sim[2];
	int trials[2];
	double *gates_sim[2]; /* [k] for k = 0 .. n_gates_sim[i] */
	int n_gates_sim[2];
	char title[400];        /* backend and parameters, for the figure */
	double *cdf_out_sim[2]; /* P(out by the end of each time bin), simulated */
} group_data;

static int write_csv(const char *stage, const bsim_experiment *e, const bsim_markov_validation *v,
                     const group_data *gd, bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	snprintf(path, sizeof path, "%s/validate.csv", stage);
	bsim_atomic_file o;
	if (bsim_atomic_file_open(&o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	fputs("group,protocol,location,p_sim,lo,hi,p_chain,trials\n", o.f);
	for (int g = 0; g < e->n_groups; g++)
		for (int pr = 0; pr < 2; pr++) {
			const bsim_markov_prediction *p = &gd[g].pred;
			for (int i = 0; i < p->n_locations; i++) {
				int n = gd[g].trials[pr];
				double ps = gd[g].p_sim[pr][i], lo, hi;
				bsim_stats_wilson((int)lround(ps * n), n, BSIM_STATS_Z95, &lo, &hi);
				char label[48];
				bsim_lattice_location_label(p->loc[i], label, sizeof label);
				fprintf(o.f, "%d,%s,%s,%.9g,%.9g,%.9g,%.9g,%d\n", g,
				        protocol_names[pr], label, ps, lo, hi, p->p[i], n);
			}
		}
	if (bsim_atomic_file_commit(&o, err) != BSIM_OK)
		return BSIM_EFAIL;
	snprintf(path, sizeof path, "%s/gates.csv", stage);
	if (bsim_atomic_file_open(&o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	fputs("group,source,gates,p\n", o.f);
	for (int g = 0; g < e->n_groups; g++) {
		for (int pr = 0; pr < 2; pr++)
			for (int k = 1; k <= gd[g].n_gates_sim[pr]; k++)
				fprintf(o.f, "%d,%s,%d,%.9g\n", g, protocol_names[pr], k,
				        gd[g].gates_sim[pr][k]);
		for (int k = 1; k <= gd[g].pred.n_gates; k++)
			if (gd[g].pred.p_gates[k] > 1e-12)
				fprintf(o.f, "%d,chain,%d,%.9g\n", g, k, gd[g].pred.p_gates[k]);
	}
	(void)v;
	if (bsim_atomic_file_commit(&o, err) != BSIM_OK)
		return BSIM_EFAIL;
	if (!gd[0].pred.walks)
		return BSIM_OK;
	snprintf(path, sizeof path, "%s/time_validate.csv", stage);
	if (bsim_atomic_file_open(&o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	fputs("group,protocol,t,out_sim,out_chain\n", o.f);
	for (int g = 0; g < e->n_groups; g++) {
		const bsim_markov_prediction *p = &gd[g].pred;
		for (int pr = 0; pr < 2 && gd[g].cdf_out_sim[pr]; pr++) {
			double chain = 0.0;
			for (int b = 0; b < p->n_time_bins; b++) {
				chain += p->p_time[b * 3] + p->p_time[b * 3 + 1];
				fprintf(o.f, "%d,%s,%.9g,%.9g,%.9g\n", g, protocol_names[pr],
				        (b + 1) * p->time_bin, gd[g].cdf_out_sim[pr][b], chain);
			}
		}
	}
	return bsim_atomic_file_commit(&o, err);
}

static int write_json(const char *stage, const bsim_markov_validate_def *def,
                      const bsim_experiment *e, const bsim_markov_validation *v, bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	snprintf(path, sizeof path, "%s/validate.json", stage);
	bsim_atomic_file o;
	if (bsim_atomic_file_open(&o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	FILE *f = o.f;
	fputs("{\"experiment\": ", f);
	bsim_json_string(f, e->path);
	/* the walks over a cache (--visits) or a build's directory (--map) */
	const int walks = def->visits_dir != NULL, cache = walks && !def->nearest.read_only;
	fputs(cache ? ", \"visits_dir\": " : ", \"map_dir\": ", f);
	bsim_json_string(f, walks ? def->visits_dir : def->map_dir);
	fprintf(f, ", \"method\": \"%s\"", walks ? "nearest" : "maps");
	if (def->visits_dir) /* the maps' fields below are the training fields' */
		fprintf(f, ", \"nearest_walks\": %ld, \"nearest_k\": %d, \"train_trials\": %d",
		        def->nearest.walks, def->nearest.k, def->nearest.trials);
	fprintf(f,
	        ", \"entry_bins\": %d, \"trials_per_bin\": %d, \"of_crossings\": %d, "
	        "\"per_crossing\": %d, \"map_cpu_seconds\": ",
	        v->bins, v->trials_per_bin, v->of_crossings, v->per_crossing);
	bsim_json_number(f, v->map_cost);
	fprintf(f, ", \"map_steps\": %lld, \"maps_scope\": ", v->map_steps);
	bsim_json_string(f, v->scope);
	fputs(", \"checks\": [", f);
	for (int i = 0; i < v->n; i++) {
		const bsim_markov_check *c = &v->checks[i];
		double saved = c->sim_cpu - c->predict;
		fprintf(f, "%s\n  {\"group\": %d, \"protocol\": \"%s\", \"trials\": %d, \"tv\": ",
		        i ? "," : "", c->group,
		        c->protocol == BSIM_PROTOCOL_ESSAY ? "essay" : "world", c->trials);
		bsim_json_number(f, c->tv);
		fputs(", \"tv_sampling\": ", f);
		bsim_json_number(f, c->tv_sampling);
		fputs(", \"tv_sampling95\": ", f);
		bsim_json_number(f, c->tv_sampling95);
		fputs(", \"tv_map\": ", f);
		bsim_json_number(f, c->tv_map);
		fputs(", \"gates_sim\": ", f);
		bsim_json_number(f, c->gates_sim);
		fputs(", \"gates_chain\": ", f);
		bsim_json_number(f, c->gates_chain);
		fputs(", \"sim_cpu_seconds\": ", f);
		bsim_json_number(f, c->sim_cpu);
		fputs(", \"predict_cpu_seconds\": ", f);
		bsim_json_number(f, c->predict);
		fputs(", \"speedup\": ", f);
		bsim_json_number(f, c->sim_cpu / c->predict);
		fputs(", \"break_even_lattices\": ", f);
		bsim_json_number(f, saved > 0 ? ceil(v->map_cost / saved) : NAN);
		fprintf(f, ", \"states\": %d, \"exact\": %s", c->n_states,
		        c->exact ? "true" : "false");
		if (c->has_time) {
			const char *const key[] = {"out_sim",     "out_sim_lo",     "out_sim_hi",
			                           "out_chain",   "t_out_sim",      "t_out_sim_ci",
			                           "t_out_chain", "t_out_chain_ci", "t_out_diff_ci",
			                           "t_ks",        "t_ks95"};
			const double val[] = {c->out_sim,     c->out_sim_lo,     c->out_sim_hi,
			                      c->out_chain,   c->t_out_sim,      c->t_out_sim_ci,
			                      c->t_out_chain, c->t_out_chain_ci, c->t_out_diff_ci,
			                      c->t_ks,        c->t_ks95};
			fputs(", \"time\": {", f);
			for (int k = 0; k < 11; k++) {
				fprintf(f, "%s\"%s\": ", k ? ", " : "", key[k]);
				bsim_json_number(f, val[k]);
			}
			fputc('}', f);
		}
		fputc('}', f);
	}
	fputs("\n]}\n", f);
	return bsim_atomic_file_commit(&o, err);
}

/* validate_gNNN: the field three times, the chain's prediction and the
 * simulated final locations of both protocols, on one scale, and under the
 * simulations the chain's difference from each; the totals of end, side
 * and stuck in every panel's title, the distances in the figure's. */
static int write_figure(const char *stage, int g, const group_data *d,
                        const bsim_markov_validation *v, int *drawn, bsim_error *err)
{
	char name[32], title[900];
	snprintf(name, sizeof name, "validate_g%03d", g);
	const bsim_markov_check *c = &v->checks[2 * g];
	const bsim_markov_prediction *p = &d->pred;
	snprintf(title, sizeof title,
	         "group %d: final locations predicted by the chain and simulated (%d trials "
	         "per protocol)\n%s\nTV essay protocol %.3f (simulation's sampling %.3f, "
	         "map's %.3f); whole world %.3f (sampling %.3f)",
	         g, d->trials[0], d->title, c[0].tv, c[0].tv_sampling, c[0].tv_map, c[1].tv,
	         c[1].tv_sampling);
	/* (d) and (e) under (b) and (c): the second row's first place empty */
	const markov_field_panel panel[6] = {
	        {"(a) predicted by the chain", p->p, NULL},
	        {"(b) simulated, essay protocol", d->p_sim[0], NULL},
	        {"(c) simulated, whole world", d->p_sim[1], NULL},
	        {"", NULL, NULL},
	        {"(d) chain - essay protocol", p->p, d->p_sim[0]},
	        {"(e) chain - whole world", p->p, d->p_sim[1]},
	};
	return bsim_markov_field_figure(stage, name, title, p->loc, p->n_locations, panel, 6, 3,
	                                drawn, err);
}

/* ---- the run ------------------------------------------------------------------ */

/* The overrides of protocol pr's sweep: --set, then lattice.protocol
 * (ov of n_sets + 1, malloc'd). */
static bsim_override *protocol_sets(const bsim_markov_validate_def *def, int pr)
{
	bsim_override *ov = malloc((size_t)(def->n_sets + 1) * sizeof *ov);
	if (!ov)
		return NULL;
	if (def->n_sets > 0) /* sets is NULL without --set */
		memcpy(ov, def->sets, (size_t)def->n_sets * sizeof *ov);
	ov[def->n_sets] =
	        (bsim_override){"lattice.protocol", protocol_names[pr], "markov validate"};
	return ov;
}

/* The chain of the maps in set for scene into pred (with the time to the
 * outcome where they have holding times), the CPU of one prediction as
 * markov predict makes it, the maps' own sampling error (tv_map) and what
 * the maps are (v's bins, trials, scope and cost). */
static int predict_maps(const bsim_markov_validate_def *def, const bsim_scene *scene,
                        const bsim_markov_set *set, gsl_rng *rng, bsim_markov_prediction *pred,
                        double *predict, double *tv_map, bsim_markov_validation *v, bsim_error *err)
{
	int rc = bsim_markov_predict(scene, set, pred, err);
	if (rc == BSIM_OK && pred->has_time)
		rc = bsim_markov_predict_time(scene, set, BSIM_MARKOV_WALKS, set->def.seed, pred,
		                              err);
	if (rc == BSIM_OK)
		rc = time_predict(scene, set, predict, err);
	if (rc == BSIM_OK)
		rc = bootstrap_maps(rng, scene, set, pred, def->map_resamples, def->stop, tv_map,
		                    err);
	if (rc != BSIM_OK)
		return rc;
	v->bins = set->n ? set->maps[0].n_bins : 0;
	v->trials_per_bin = set->def.trials;
	v->of_crossings = set->n ? set->maps[0].of_crossings : 0;
	v->per_crossing = set->n ? set->maps[0].per_crossing : 0;
	bsim_markov_def_scope(&set->def, v->scope, sizeof v->scope);
	for (int i = 0; i < set->n; i++) {
		v->map_cost += set->maps[i].cost;
		v->map_steps += set->maps[i].steps;
	}
	for (int i = 0; set->next && i < set->n * set->n; i++) {
		v->map_cost += set->next[i].cost; /* the gates after the start */
		v->map_steps += set->next[i].steps_total;
	}
	return BSIM_OK;
}

/* The nearest-neighbour walks over the visits in def->visits_dir (read:
 * they were run before the simulation) for scene into pred, their CPU
 * time, their own sampling error (tv_map) and what they are (v's scope
 * and the training fields' cost). */
static int predict_nearest(const bsim_markov_validate_def *def, const bsim_scene *scene,
                           bsim_markov_prediction *pred, double *predict, double *tv_map,
                           bsim_markov_validation *v, bsim_error *err)
{
	bsim_markov_visits vs;
	int rc = bsim_markov_visits_build(scene, &def->nearest, def->visits_dir, &vs, err);
	if (rc != BSIM_OK)
		return rc;
	const double c0 = bsim_clock_process_cpu_seconds();
	rc = bsim_markov_nearest_predict(scene, &vs, &def->nearest, pred, err);
	*predict = bsim_clock_process_cpu_seconds() - c0;
	if (rc == BSIM_OK) {
		*tv_map = bsim_markov_nearest_tv_walks(pred->p, pred->n_locations,
		                                       pred->nearest_walks);
		v->map_cost += vs.cost;
		v->map_steps += vs.steps;
	}
	bsim_markov_visits_free(&vs);
	return rc;
}

static int group_validate(const bsim_markov_validate_def *def, const bsim_experiment *e, int g,
                          const bsim_sweep_result res[2], const double cpu[2], gsl_rng *rng,
                          group_data *d, bsim_markov_validation *v, bsim_error *err)
{
	bsim_scene scene;
	int rc = bsim_experiment_group_scene(e, g, def->sets, def->n_sets, &scene, err);
	if (rc != BSIM_OK)
		return rc;
	bsim_options opts;
	bsim_markov_set set = {0};
	double predict = 0.0, tv_map = NAN;
	const bsim_backend *be = def->nearest.backend;
	if (def->visits_dir)
		rc = predict_nearest(def, &scene, &d->pred, &predict, &tv_map, v, err);
	else {
		rc = bsim_markov_load(&scene, def->map_dir, &opts, &set, err);
		if (rc == BSIM_OK)
			rc = predict_maps(def, &scene, &set, rng, &d->pred, &predict, &tv_map, v,
			                  err);
		be = set.def.backend;
	}
	if (rc == BSIM_OK) {
		/* the figure's title: the backend, the experiment's set:, the
		 * command line's --set and the group's grid values */
		const int na = e->n_axes, n = e->n_set + def->n_sets + na;
		bsim_override *ov = malloc((size_t)(n > 0 ? n : 1) * sizeof *ov);
		int *idx = malloc((size_t)(na > 0 ? na : 1) * sizeof *idx);
		if (ov && idx) {
			bsim_experiment_group_index(e, g, idx);
			if (e->n_set > 0)
				memcpy(ov, e->set, (size_t)e->n_set * sizeof *ov);
			if (def->n_sets > 0)
				memcpy(ov + e->n_set, def->sets, (size_t)def->n_sets * sizeof *ov);
			for (int a = 0; a < na; a++)
				ov[e->n_set + def->n_sets + a] = (bsim_override){
				        e->axes[a].key, e->axes[a].values[idx[a]], NULL};
			const bsim_backend *b = be ? be : bsim_backend_default();
			bsim_markov_title_params(d->title, sizeof d->title, b ? b->name : NULL, ov,
			                         n);
		}
		free(ov);
		free(idx);
	}
	const bsim_lattice_def *l = &scene.lattice;
	const int nl = d->pred.n_locations;
	for (int pr = 0; rc == BSIM_OK && pr < 2; pr++) {
		const int T = res[pr].trials;
		const bsim_trial_result *t = res[pr].trials_out + (size_t)g * T;
		d->trials[pr] = T;
		d->p_sim[pr] = calloc((size_t)nl, sizeof *d->p_sim[pr]);
		int max_gates = 1;
		for (int i = 0; i < T; i++)
			max_gates = t[i].gates_entered > max_gates ? t[i].gates_entered : max_gates;
		d->gates_sim[pr] = calloc((size_t)max_gates + 1, sizeof *d->gates_sim[pr]);
		d->n_gates_sim[pr] = max_gates;
		if (!d->p_sim[pr] || !d->gates_sim[pr]) {
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
			break;
		}
		double gates = 0.0;
		for (int i = 0; i < T; i++) {
			d->p_sim[pr][loc_index(l, bsim_lattice_location_of(&t[i]))] += 1.0 / T;
			d->gates_sim[pr][t[i].gates_entered] += 1.0 / T;
			gates += (double)t[i].gates_entered / T;
		}
		bsim_markov_check *c = &v->checks[2 * g + pr];
		c->group = g;
		c->protocol = pr == 0 ? BSIM_PROTOCOL_ESSAY : BSIM_PROTOCOL_WORLD;
		c->trials = T;
		c->tv = tv(d->p_sim[pr], d->pred.p, nl);
		bootstrap_sim(rng, d->p_sim[pr], nl, T, def->bootstrap, &c->tv_sampling,
		              &c->tv_sampling95);
		c->tv_map = tv_map;
		c->gates_sim = gates;
		c->gates_chain = d->pred.mean_gates;
		c->sim_cpu = cpu[pr] / e->n_groups;
		c->predict = predict;
		c->n_states = d->pred.n_states;
		c->exact = d->pred.exact;
		if (d->pred.walks > 0)
			rc = time_check(&d->pred, t, T, &d->cdf_out_sim[pr], c, err);
	}
	bsim_markov_set_free(&set);
	bsim_scene_free(&scene);
	return rc;
}

static int validate_run(const bsim_markov_validate_def *def, bsim_markov_validation *out,
                        bsim_error *err)
{
	bsim_experiment e;
	int rc = bsim_experiment_load_seeded(def->experiment, def->sets, def->n_sets, def->grid,
	                                     def->n_grid, def->has_seed ? &def->seed : NULL, &e,
	                                     err);
	if (rc != BSIM_OK)
		return rc;
	if (def->trials > 0 &&
	    (rc = bsim_experiment_check_trials(&e, def->trials, err)) != BSIM_OK) {
		bsim_experiment_free(&e);
		return rc;
	}
	if (def->trials > 0)
		e.trials = (int)def->trials;
	if (def->has_seed)
		e.seed = def->seed;
	/* The maps of every group first: a missing one is an input error
	 * before any trial runs. */
	bsim_markov_set set0 = {0};
	bsim_options opts0;
	for (int g = 0; g < e.n_groups && rc == BSIM_OK; g++) {
		bsim_scene scene;
		rc = bsim_experiment_group_scene(&e, g, def->sets, def->n_sets, &scene, err);
		if (rc != BSIM_OK)
			break;
		bsim_markov_set_free(&set0);
		if (def->visits_dir) { /* the training fields run now, if missing */
			bsim_markov_visits vs;
			rc = bsim_markov_visits_build(&scene, &def->nearest, def->visits_dir, &vs,
			                              err);
			bsim_markov_visits_free(&vs);
		} else
			rc = bsim_markov_load(&scene, def->map_dir, &opts0, &set0, err);
		bsim_scene_free(&scene);
	}
	const bsim_options no_opts = {0};
	if (def->visits_dir) { /* the simulation on the training fields' backend */
		set0.def.backend =
		        def->nearest.backend ? def->nearest.backend : bsim_backend_default();
		set0.def.opts = def->nearest.opts ? def->nearest.opts : &no_opts;
	}
	/* Both protocols' sweeps, journaled in out as one job. */
	bsim_override *ov[2] = {protocol_sets(def, 0), protocol_sets(def, 1)};
	bsim_sweep_config cfg[2];
	const bsim_experiment *es[2] = {&e, &e};
	for (int pr = 0; pr < 2; pr++)
		cfg[pr] = (bsim_sweep_config){.backend = set0.def.backend,
		                              .opts = set0.def.opts,
		                              .threads = def->threads,
		                              .extra = ov[pr],
		                              .n_extra = def->n_sets + 1};
	const bsim_sweep_spread *sp = &def->spread;
	const bsim_outdir_spelling spelling = {def->resume_option, def->overwrite_option};
	sweep_batch b = {.command = "markov validate",
	                 .out = def->out,
	                 .resume = def->resume,
	                 .overwrite = def->overwrite,
	                 .spelling = &spelling,
	                 .spread = sp->spread != BSIM_SPREAD_NONE || sp->n_merge > 0 ? sp : NULL,
	                 .progress = def->progress,
	                 .progress_user = def->progress_user,
	                 .stop = def->stop};
	bsim_sweep_result res[2];
	memset(res, 0, sizeof res);
	double cpu[2] = {0, 0};
	if (rc == BSIM_OK && (!ov[0] || !ov[1]))
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	if (rc == BSIM_OK)
		rc = bsim_sweep_batch_run_cpu(&b, es, cfg, 2, res, cpu, err);
	if (!b.writes) {
		/* a shard's part directory, or another rank's part: no results */
		rc = bsim_sweep_batch_end(&b, rc, err);
		snprintf(out->journal, sizeof out->journal, "%s", b.journal);
		free(ov[0]);
		free(ov[1]);
		bsim_markov_set_free(&set0);
		bsim_experiment_free(&e);
		return rc;
	}
	group_data *gd = calloc((size_t)e.n_groups, sizeof *gd);
	out->checks = calloc((size_t)2 * e.n_groups, sizeof *out->checks);
	if (rc == BSIM_OK && (!gd || !out->checks))
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	out->n = 2 * e.n_groups;
	gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
	if (rng)
		gsl_rng_set(rng, (unsigned long)e.seed);
	else if (rc == BSIM_OK)
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	for (int g = 0; g < e.n_groups && rc == BSIM_OK; g++)
		rc = group_validate(def, &e, g, res, cpu, rng, &gd[g], out, err);
	if (rc == BSIM_OK) {
		out->map_cost /= e.n_groups;
		out->map_steps /= e.n_groups;
	}
	if (rc == BSIM_OK)
		rc = write_csv(b.ss.stage, &e, out, gd, err);
	if (rc == BSIM_OK)
		rc = write_json(b.ss.stage, def, &e, out, err);
	const char *const twins[][2] = {{"validate.csv", "validate"},
	                                {"gates.csv", "gates"},
	                                {"validate.json", "validate"}};
	for (int i = 0; i < 3 && rc == BSIM_OK; i++) {
		char src[BSIM_PATH_MAX], mat[BSIM_PATH_MAX];
		snprintf(src, sizeof src, "%s/%s", b.ss.stage, twins[i][0]);
		snprintf(mat, sizeof mat, "%s/%.*s%s", b.ss.stage, (int)strcspn(twins[i][0], "."),
		         twins[i][0], i == 2 ? "_summary.mat" : ".mat");
		rc = i == 2 ? bsim_matlab_from_json(src, mat, twins[i][1], err)
		            : bsim_matlab_from_csv(src, mat, twins[i][1], err);
	}
	if (rc == BSIM_OK && e.n_groups > 0 && gd[0].pred.walks > 0) {
		char src[BSIM_PATH_MAX], mat[BSIM_PATH_MAX];
		snprintf(src, sizeof src, "%s/time_validate.csv", b.ss.stage);
		snprintf(mat, sizeof mat, "%s/time_validate.mat", b.ss.stage);
		rc = bsim_matlab_from_csv(src, mat, "time_validate", err);
	}
	/* A figure gnuplot fails on is reported at the end, the tables and the
	 * other groups' figures kept beside its script and data. */
	for (int g = 0; g < e.n_groups && rc == BSIM_OK; g++) {
		int drawn = BSIM_FIGURE_UNDRAWN;
		rc = write_figure(b.ss.stage, g, &gd[g], out, &drawn, err);
		rc = bsim_session_defer(&b.ss, rc, drawn == BSIM_FIGURE_FAILED, err);
	}
	rc = bsim_sweep_batch_end(&b, rc, err);
	for (int g = 0; gd && g < e.n_groups; g++) {
		bsim_markov_prediction_free(&gd[g].pred);
		for (int pr = 0; pr < 2; pr++) {
			free(gd[g].p_sim[pr]);
			free(gd[g].gates_sim[pr]);
			free(gd[g].cdf_out_sim[pr]);
		}
	}
	free(gd);
	gsl_rng_free(rng);
	for (int pr = 0; pr < 2; pr++)
		bsim_sweep_result_free(&res[pr]);
	free(ov[0]);
	free(ov[1]);
	bsim_markov_set_free(&set0);
	bsim_experiment_free(&e);
	if (rc != BSIM_OK)
		bsim_markov_validation_free(out);
	snprintf(out->journal, sizeof out->journal, "%s", b.journal);
	return rc;
}

int bsim_markov_validate(const bsim_markov_validate_def *def, bsim_markov_validation *out,
                         bsim_error *err)
{
	memset(out, 0, sizeof *out);
	/* walks: over visits_dir, or map_dir if a walks' build */
	bsim_markov_validate_def d = *def;
	bsim_options opts = {0};
	int rc = bsim_markov_nearest_of_dir(def->map_dir, def->visits_dir, &def->nearest,
	                                    &d.nearest, &opts, &d.visits_dir, err);
	if (rc == BSIM_OK)
		rc = validate_run(&d, out, err);
	if (d.visits_dir) {
		out->nearest_walks = d.nearest.walks;
		out->nearest_k = d.nearest.k;
		out->nearest_trials = d.nearest.trials;
	}
	return rc;
}
