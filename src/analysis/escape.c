/* The escape rate out of the gate against barrier over noise power, and
 * its Arrhenius/Kramers fit; see escape.h.
 *
 * The rate. A trial is at risk of leaving from the moment its body first
 * touches the beams, t0 (before that it only runs up: the random force is
 * lateral and cannot bring it forward sooner), until it leaves or is
 * censored at its end, t_end. With a constant hazard the likelihood of a
 * group with d traversals and exposure T = sum max(0, t_end - t0) is
 * maximal at k = d / T; side exits compete and are, for the traversal
 * rate, censoring at their time (the cause-specific hazard). The interval
 * is the exact Poisson one of d at exposure T (util/survival.h).
 *
 * The noise. The random force is Rm z held for 1/f, z standard normal,
 * renewed at fixed times: its autocorrelation is Rm^2 (1 - |s| f) within
 * one hold, so its power spectral density at low frequency (two-sided,
 * the D of <F(t) F(t')> = D delta(t - t') for a white force) is
 * D = Rm^2 / f, N^2 s. For a Langevin body with friction gamma, kT = D /
 * (2 gamma); c in dE / (c D) is then 1 / (2 gamma): a mobility, m/(N s). */
#define _POSIX_C_SOURCE 200809L

#include "analysis/escape.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_fit.h>

#include "beamsim/landscape_barriers.h"
#include "beamsim/key_names.h"
#include "beamsim/limits.h"
#include "beamsim/run_record.h"
#include "beamsim/sweep_dir.h"
#include "store/session.h"
#include "store/store.h"
#include "util/atomic_file.h"
#include "util/csv_table.h"
#include "util/figure.h"
#include "util/survival.h"

int bsim_escape_fit_line(const double *x, const double *y, const double *events, int n,
                         escape_fit *out, bsim_error *err)
{
	memset(out, 0, sizeof *out);
	out->n = n;
	if (n < 3)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "expected at least 3 groups with a barrier, noise and a "
		                      "traversal to fit, got %d",
		                      n);
	double c00, c01, c11, sumsq;
	gsl_fit_linear(x, 1, y, 1, (size_t)n, &out->a, &out->b, &c00, &c01, &c11, &sumsq);
	if (!isfinite(out->a) || !isfinite(out->b) || !(c11 >= 0.0))
		return bsim_error_set(err, BSIM_EINPUT, "the groups' dE / D do not spread: no fit");
	out->se_a = sqrt(c00);
	out->se_b = sqrt(c11);
	out->cov_ab = c01;
	out->k0 = exp(out->a);
	out->c = out->b != 0.0 ? -1.0 / out->b : INFINITY;
	out->se_c = out->b != 0.0 ? out->se_b / (out->b * out->b) : INFINITY;
	out->rms = sqrt(sumsq / n);
	double mean = 0.0, tss = 0.0, chi = 0.0;
	for (int i = 0; i < n; i++)
		mean += y[i] / n;
	for (int i = 0; i < n; i++) {
		tss += (y[i] - mean) * (y[i] - mean);
		double r = y[i] - (out->a + out->b * x[i]);
		chi += (events ? events[i] : 1.0) * r * r;
	}
	out->r2 = tss > 0.0 ? 1.0 - sumsq / tss : 1.0;
	out->chisq_poisson = chi;
	out->p_poisson = gsl_cdf_chisq_Q(chi, (double)(n - 2));
	return BSIM_OK;
}

const char *bsim_escape_fit_verdict(const escape_fit *f)
{
	const int rejected = f->p_poisson < ESCAPE_P_REJECT, little = f->r2 < ESCAPE_R2_LITTLE;
	if (rejected && little)
		return "the line explains little of ln k (R^2 < 0.5) and its residuals exceed "
		       "their "
		       "Poisson sampling error (p < 0.01): k0 and c do not describe these groups";
	if (rejected)
		return "the residuals exceed their Poisson sampling error (p < 0.01): the line "
		       "summarises these groups, k0 and c are not their law";
	if (little)
		return "the line explains little of ln k (R^2 < 0.5): k0 and c are weakly "
		       "determined";
	return "consistent with the line (R^2 >= 0.5, Poisson p >= 0.01)";
}

/* The distance from c to the segment of beam b at rest, m. */
static double beam_distance(const bsim_beam_def *b, const double c[2])
{
	double u[2] = {cos(b->rest_angle_deg * M_PI / 180.0),
	               sin(b->rest_angle_deg * M_PI / 180.0)};
	double d[2] = {c[0] - b->pivot[0], c[1] - b->pivot[1]};
	double s = d[0] * u[0] + d[1] * u[1];
	s = s < 0.0 ? 0.0 : s > b->length ? b->length : s;
	return hypot(d[0] - s * u[0], d[1] - s * u[1]);
}

double bsim_escape_contact_time(const bsim_scene *s)
{
	const double a =
	        s->effects.has_propulsion ? s->effects.propulsion_force / s->body.mass : 0.0;
	const double v0 = s->body.velocity[1];
	/* the forward distance to the first touch, to 1 mm, within success_y */
	double reach = -1.0;
	for (double d = 0.0; d <= s->success_y - s->body.start[1] + 1e-9; d += 1e-3) {
		double c[2] = {s->body.start[0], s->body.start[1] + d};
		for (int i = 0; i < s->n_beams && reach < 0.0; i++)
			if (beam_distance(&s->beams[i], c) <= s->body.radius)
				reach = d;
		if (reach >= 0.0)
			break;
	}
	if (reach <= 0.0)
		return 0.0;
	if (a > 0.0)
		return (-v0 + sqrt(v0 * v0 + 2.0 * a * reach)) / a;
	return v0 > 0.0 ? reach / v0 : 0.0;
}

/* One group's numbers. */
typedef struct esc_group {
	int scene;                                  /* index of its landscape */
	double noise;                               /* D = Rm^2 / f, N^2 s */
	double t0, exposure;                        /* s */
	long traversed, side_exit, censored, early; /* early: exits before t0 */
	double rate, lo, hi;                        /* traversals / exposure, 1/s */
	double exit_rate;                           /* (traversed + side_exit) / exposure */
	double x;                                   /* barrier / noise */
	int used;
	double fit, residual; /* ln k */
} esc_group;

/* A distinct landscape: what the barrier search reads of a scene. */
typedef struct esc_scene {
	char *key;
	bsim_pass_kind kind;
	double height, above_start; /* J */
} esc_scene;

static char *landscape_key(const bsim_scene *s)
{
	size_t cap = 256 + (size_t)s->n_beams * 160, len = 0;
	char *k = malloc(cap);
	if (!k)
		return NULL;
	len += (size_t)snprintf(k + len, cap - len, "%.17g %.17g %.17g %.17g %.17g %.17g %.17g %d",
	                        s->body.radius, s->body.start[0], s->body.start[1],
	                        s->effects.has_propulsion ? s->effects.propulsion_force : 0.0,
	                        s->landscape_y0, s->side_x, s->success_y, s->n_beams);
	for (int i = 0; i < s->n_beams && len < cap; i++) {
		const bsim_beam_def *b = &s->beams[i];
		len += (size_t)snprintf(k + len, cap - len, " %.17g %.17g %.17g %.17g %.17g",
		                        b->pivot[0], b->pivot[1], b->rest_angle_deg, b->length,
		                        b->stiffness);
	}
	return k;
}

static int barrier_of(const bsim_scene *s, const bsim_landscape_grid_def *def, esc_scene *out,
                      bsim_error *err)
{
	bsim_landscape_grid *g = NULL;
	bsim_landscape_barriers *b = NULL;
	int rc = bsim_landscape_grid_alloc(s, def, &g, err);
	if (rc == BSIM_OK)
		rc = bsim_landscape_barriers_alloc(s, g, &b, err);
	if (rc == BSIM_OK) {
		out->kind = b->lowest.kind;
		out->height = b->lowest.kind == BSIM_PASS_NONE ? NAN : b->lowest.height;
		out->above_start = b->lowest.kind == BSIM_PASS_NONE ? NAN : b->lowest.above_start;
	}
	bsim_landscape_barriers_free(b);
	bsim_landscape_grid_free(g);
	return rc;
}

static void num(FILE *f, double v)
{
	if (isfinite(v))
		fprintf(f, "%.10g", v);
}

static void json_num(FILE *f, const char *name, double v, const char *sep)
{
	if (isfinite(v))
		fprintf(f, "  \"%s\": %.10g%s\n", name, v, sep);
	else
		fprintf(f, "  \"%s\": null%s\n", name, sep);
}

typedef struct esc_job {
	const bsim_experiment *e;
	const char *backend; /* the sweep's backend label, from run.json */
	esc_group *g;
	esc_scene *sc;
	const escape_summary *sum;
} esc_job;

static int write_csv(const char *stage, const esc_job *j, bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	bsim_atomic_file o;
	if (bsim_session_path(path, sizeof path, stage, "kramers.csv", err) ||
	    bsim_atomic_file_open(&o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	const bsim_experiment *e = j->e;
	fputs("group,barrier,above_start,kind,noise,barrier_over_noise,trials,traversed,side_exit,"
	      "censored,exits_before_contact,t_contact,exposure,rate,rate_lo,rate_hi,exit_rate,"
	      "used,fit,residual",
	      o.f);
	for (int a = 0; a < e->n_axes; a++) {
		fputc(',', o.f);
		bsim_csv_field_write(o.f, e->axes[a].key);
	}
	fputc('\n', o.f);
	int idx[64];
	for (int k = 0; k < e->n_groups; k++) {
		const esc_group *g = &j->g[k];
		const esc_scene *s = &j->sc[g->scene];
		fprintf(o.f, "%d,", k);
		num(o.f, s->height);
		fputc(',', o.f);
		num(o.f, s->above_start);
		fprintf(o.f, ",%s,", bsim_landscape_pass_kind_name(s->kind));
		num(o.f, g->noise);
		fputc(',', o.f);
		num(o.f, g->x);
		fprintf(o.f, ",%ld,%ld,%ld,%ld,%ld,", e->trials > 0 ? (long)e->trials : 0L,
		        g->traversed, g->side_exit, g->censored, g->early);
		double v[6] = {g->t0, g->exposure, g->rate, g->lo, g->hi, g->exit_rate};
		for (int i = 0; i < 6; i++) {
			num(o.f, v[i]);
			fputc(',', o.f);
		}
		fprintf(o.f, "%d,", g->used);
		num(o.f, g->used ? g->fit : NAN);
		fputc(',', o.f);
		num(o.f, g->used ? g->residual : NAN);
		if (e->n_axes > 0 && e->n_axes <= 64)
			bsim_experiment_group_index(e, k, idx);
		for (int a = 0; a < e->n_axes && a < 64; a++) {
			fputc(',', o.f);
			bsim_csv_field_write(o.f, e->axes[a].values[idx[a]]);
		}
		fputc('\n', o.f);
	}
	return bsim_atomic_file_commit(&o, err);
}

static int write_json(const char *stage, const esc_job *j, bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	bsim_atomic_file o;
	if (bsim_session_path(path, sizeof path, stage, "kramers.json", err) ||
	    bsim_atomic_file_open(&o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	const escape_summary *s = j->sum;
	const escape_fit *f = &s->fit;
	fputs("{\n  \"model\": \"ln k = ln k0 - barrier / (c noise)\",\n"
	      "  \"rate\": \"traversals / sum over trials of max(0, t_end - t_contact), 1/s\",\n"
	      "  \"barrier\": \"lowest pass height above the start basin's floor, J\",\n"
	      "  \"noise\": \"Rm^2 / f, N^2 s\",\n",
	      o.f);
	fprintf(o.f,
	        "  \"groups\": %d,\n  \"used\": %d,\n  \"landscapes\": %d,\n  \"fitted\": %s,\n",
	        s->groups, s->used, s->scenes, s->fitted ? "true" : "false");
	json_num(o.f, "ln_k0", s->fitted ? f->a : NAN, ",");
	json_num(o.f, "ln_k0_se", s->fitted ? f->se_a : NAN, ",");
	json_num(o.f, "slope", s->fitted ? f->b : NAN, ",");
	json_num(o.f, "slope_se", s->fitted ? f->se_b : NAN, ",");
	json_num(o.f, "cov_ln_k0_slope", s->fitted ? f->cov_ab : NAN, ",");
	json_num(o.f, "k0", s->fitted ? f->k0 : NAN, ",");
	json_num(o.f, "c", s->fitted ? f->c : NAN, ",");
	json_num(o.f, "c_se", s->fitted ? f->se_c : NAN, ",");
	json_num(o.f, "residual_rms", s->fitted ? f->rms : NAN, ",");
	json_num(o.f, "r2", s->fitted ? f->r2 : NAN, ",");
	json_num(o.f, "chisq_poisson", s->fitted ? f->chisq_poisson : NAN, ",");
	json_num(o.f, "dof", s->fitted ? f->n - 2 : NAN, ",");
	json_num(o.f, "p_poisson", s->fitted ? f->p_poisson : NAN, ",");
	fprintf(o.f, "  \"verdict\": ");
	if (s->fitted)
		fprintf(o.f, "\"%s\"\n", bsim_escape_fit_verdict(f));
	else
		fprintf(o.f, "null\n");
	fputs("}\n", o.f);
	return bsim_atomic_file_commit(&o, err);
}

static int write_figure(const char *stage, const esc_job *j, int *drawn, bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	bsim_atomic_file o;
	if (bsim_session_path(path, sizeof path, stage, "kramers.dat", err) ||
	    bsim_atomic_file_open(&o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	fputs("# barrier_over_noise ln_rate ln_lo ln_hi fit residual group: block 0 the groups in "
	      "the fit, block 1 those with a barrier and noise but no traversal (at ln of the "
	      "upper bound)\n",
	      o.f);
	for (int pass = 0; pass < 2; pass++) {
		if (pass)
			fputs("\n\n", o.f);
		for (int k = 0; k < j->e->n_groups; k++) {
			const esc_group *g = &j->g[k];
			if (pass == 0 && g->used)
				fprintf(o.f, "%.8g %.8g %.8g %.8g %.8g %.8g %d\n", g->x,
				        log(g->rate), log(g->lo), log(g->hi), g->fit, g->residual,
				        k);
			else if (pass == 1 && !g->used && isfinite(g->x) && g->x > 0 &&
			         g->traversed == 0 && isfinite(g->hi))
				fprintf(o.f, "%.8g %.8g %.8g %.8g 0 0 %d\n", g->x, log(g->hi),
				        log(g->hi), log(g->hi), k);
		}
	}
	fputs("# no point\nNaN NaN NaN NaN NaN NaN -1\n", o.f);
	int rc = bsim_atomic_file_commit(&o, err);
	if (rc)
		return rc;
	const escape_fit *f = &j->sum->fit;
	/* the line over the groups it was fitted to */
	double lo = INFINITY, hi = -INFINITY;
	for (int k = 0; k < j->e->n_groups; k++)
		if (j->g[k].used) {
			lo = fmin(lo, j->g[k].x);
			hi = fmax(hi, j->g[k].x);
		}
	/* the title's second line: the backend and the experiment's fixed
	 * values, in the model's symbols */
	char fixed[600];
	int used = snprintf(fixed, sizeof fixed, "%s backend", j->backend);
	for (int i = 0; i < j->e->n_set && used > 0 && (size_t)used < sizeof fixed; i++) {
		char kv[160];
		bsim_key_value(j->e->set[i].key, j->e->set[i].value, 0, kv, sizeof kv);
		used += snprintf(fixed + used, sizeof fixed - (size_t)used, "%s %s", i ? "," : ";",
		                 kv);
	}
	for (char *c = fixed; *c; c++)
		if (*c == '\'')
			*c = ' ';
	char body[2700];
	snprintf(body, sizeof body,
	         "set multiplot layout 1,2 title 'escape rate against barrier / noise power: "
	         "ln k = ln k0 - dE / (c D), k0 = %.3g 1/s, c = %.3g +- %.2g m/(N s), n = %d, "
	         "R^2 = %.2f'.\"\\n\".'%s' noenhanced\n"
	         "set grid\nset xlabel 'dE / D (J / (N^2 s))'\nset ylabel 'ln k (k in 1/s)'\n"
	         /* the key below the left panel, off the points; both panels
	          * as high */
	         "set bmargin at screen 0.17\n"
	         "set key at screen 0.27, screen 0.01 center bottom horizontal font ',9'\n"
	         "set title 'traversal rate (95%% Poisson interval) and the fit'\n"
	         "plot 'kramers.dat' index 0 using 1:2:3:4 with yerrorbars pt 7 lc rgb '#0072B2' "
	         "title 'groups with a traversal', \\\n"
	         "     '' index 1 using 1:2 with points pt 10 lc rgb '#9A9A9A' "
	         "title 'no traversal: upper bound', \\\n"
	         "     [%.10g:%.10g] '+' using 1:(%.10g + %.10g * $1) with lines lw 2 "
	         "lc rgb '#D55E00' title 'least squares'\n"
	         "set title 'residuals of ln k'\nset ylabel 'ln k - fit'\nunset key\n"
	         "plot 'kramers.dat' index 0 using 1:6 with points pt 7 lc rgb '#0072B2', "
	         "0 with lines lc rgb '#5A5A5A'\n"
	         "unset multiplot\n",
	         f->k0, f->c, f->se_c, f->n, f->r2, fixed, lo, hi, f->a, f->b);
	bsim_figure_def d = bsim_figure_def_default();
	d.dir = stage;
	d.name = "kramers";
	d.width = 1300;
	d.height = 600;
	return bsim_figure_render(&d, body, drawn, err);
}

/* Every group's rate and barrier. */
static int measure(const escape_def *def, const bsim_sweep_dir_result *res, esc_group *gs,
                   esc_scene **scenes, int *n_scenes, bsim_error *err)
{
	const bsim_experiment *e = &res->e;
	int rc = BSIM_OK;
	for (int k = 0; rc == BSIM_OK && k < e->n_groups; k++) {
		bsim_scene s;
		if ((rc = bsim_experiment_group_scene(e, k, NULL, 0, &s, err)) != BSIM_OK)
			break;
		if (s.has_lattice) {
			bsim_scene_free(&s);
			rc = bsim_error_set(err, BSIM_EINPUT,
			                    "%s: a sweep of gate lattices: escape measures single "
			                    "gates (docs/first_passage.md)",
			                    def->dir);
			break;
		}
		esc_group *g = &gs[k];
		char *key = landscape_key(&s);
		if (!key) {
			bsim_scene_free(&s);
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
			break;
		}
		g->scene = -1;
		for (int i = 0; i < *n_scenes; i++)
			if (strcmp((*scenes)[i].key, key) == 0)
				g->scene = i;
		if (g->scene < 0) {
			esc_scene *more = realloc(*scenes, (size_t)(*n_scenes + 1) * sizeof *more);
			if (!more) {
				free(key);
				bsim_scene_free(&s);
				rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
				break;
			}
			*scenes = more;
			more[*n_scenes] = (esc_scene){.key = key};
			key = NULL;
			rc = barrier_of(&s, &def->grid, &more[*n_scenes], err);
			g->scene = (*n_scenes)++;
		}
		free(key);
		g->noise = s.effects.has_random_force
		                   ? s.effects.random_magnitude * s.effects.random_magnitude /
		                             s.effects.random_frequency
		                   : 0.0;
		g->t0 = bsim_escape_contact_time(&s);
		bsim_scene_free(&s);
		for (int t = 0; t < e->trials; t++) {
			const bsim_trial_result *r = &res->r.trials_out[(size_t)k * e->trials + t];
			g->traversed += r->outcome == BSIM_TRAVERSED;
			g->side_exit += r->outcome == BSIM_SIDE_EXIT;
			g->censored += r->outcome == BSIM_STUCK || r->outcome == BSIM_UNSTABLE;
			g->early += r->outcome == BSIM_SIDE_EXIT && r->t_end < g->t0;
			g->exposure += fmax(0.0, r->t_end - g->t0);
		}
		bsim_survival_rate(g->traversed, g->exposure, &g->rate, &g->lo, &g->hi);
		g->exit_rate = g->exposure > 0.0
		                       ? (double)(g->traversed + g->side_exit) / g->exposure
		                       : NAN;
	}
	return rc;
}

int bsim_escape_run(const escape_def *def, escape_summary *sum, bsim_error *err)
{
	memset(sum, 0, sizeof *sum);
	bsim_sweep_dir_result res;
	int rc = bsim_sweep_dir_read(def->dir, NULL, &res, err);
	if (rc != BSIM_OK)
		return rc;
	const bsim_experiment *e = &res.e;
	bsim_session ss;
	if ((rc = bsim_session_open(&ss, def->out, bsim_session_mode(0, def->overwrite), "escape",
	                            NULL, NULL, 0, err)) != BSIM_OK) {
		bsim_sweep_dir_result_free(&res);
		return rc;
	}
	esc_group *gs = calloc((size_t)e->n_groups, sizeof *gs);
	esc_scene *scenes = NULL;
	int n_scenes = 0;
	double *x = calloc((size_t)e->n_groups + 1, sizeof *x);
	double *y = calloc((size_t)e->n_groups + 1, sizeof *y);
	double *w = calloc((size_t)e->n_groups + 1, sizeof *w);
	int *at = calloc((size_t)e->n_groups + 1, sizeof *at);
	if (!gs || !x || !y || !w || !at)
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	if (rc == BSIM_OK)
		rc = measure(def, &res, gs, &scenes, &n_scenes, err);
	sum->groups = e->n_groups;
	sum->scenes = n_scenes;
	/* the fit: groups with a barrier to climb, noise and a traversal */
	int n = 0;
	for (int k = 0; rc == BSIM_OK && k < e->n_groups; k++) {
		esc_group *g = &gs[k];
		const esc_scene *s = &scenes[g->scene];
		g->x = g->noise > 0.0 && isfinite(s->height) ? s->height / g->noise : NAN;
		g->used = s->kind == BSIM_PASS_SADDLE && g->noise > 0.0 && g->traversed > 0;
		if (g->used) {
			x[n] = g->x;
			y[n] = log(g->rate);
			w[n] = (double)g->traversed;
			at[n++] = k;
		}
	}
	sum->used = n;
	if (rc == BSIM_OK) {
		bsim_error fe;
		sum->fitted = bsim_escape_fit_line(x, y, w, n, &sum->fit, &fe) == BSIM_OK;
		for (int i = 0; sum->fitted && i < n; i++) {
			esc_group *g = &gs[at[i]];
			g->fit = sum->fit.a + sum->fit.b * g->x;
			g->residual = y[i] - g->fit;
		}
	}
	bsim_run_record rec;
	bsim_error ignore;
	const char *backend =
	        bsim_run_record_read(def->dir, &rec, &ignore) == BSIM_OK && rec.n_backends > 0
	                ? rec.label[0]
	                : "?";
	esc_job j = {.e = e, .backend = backend, .g = gs, .sc = scenes, .sum = sum};
	if (rc == BSIM_OK)
		rc = write_csv(ss.stage, &j, err);
	if (rc == BSIM_OK)
		rc = bsim_store_twin(ss.stage, "kramers.csv", "kramers", err);
	if (rc == BSIM_OK)
		rc = write_json(ss.stage, &j, err);
	if (rc == BSIM_OK && sum->fitted) {
		/* the tables are kept beside a figure gnuplot failed on */
		rc = write_figure(ss.stage, &j, &sum->drawn, err);
		rc = bsim_session_defer(&ss, rc, sum->drawn == BSIM_FIGURE_FAILED, err);
	}
	rc = bsim_session_close(&ss, rc, "escape", NULL, err);
	for (int i = 0; i < n_scenes; i++)
		free(scenes[i].key);
	free(scenes);
	free(gs);
	free(x);
	free(y);
	free(w);
	free(at);
	bsim_sweep_dir_result_free(&res);
	return rc;
}
