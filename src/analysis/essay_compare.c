/* The essay's numbers and trends against beamsim (beamsim/essay_compare.h).
 *
 * The essay's claims are a table here (claims below), each with its
 * section or figure and the essay's trials per group (100 in H1 and H2,
 * 20 on the C-track). Every claim is measured by the sweep API on groups
 * built in code from the shipped scenes (thesis/gate.yaml with the
 * essay's settings as overrides, lattice/c_track.yaml), in each mode.
 *
 * Statistics and verdicts (alpha = 0.05, two-sided):
 * - A level (a probability the essay reports as x% of n trials): beamsim's
 *   x_b / n_b with its Wilson 95% interval, Fisher's exact test of x_b / n_b
 *   against the essay's round(x% n) / n, and Newcombe's hybrid score interval
 *   of the difference. `consistent` when p >= 0.05: the essay's count is
 *   not rejected as a sample of beamsim's probability; `differs` otherwise.
 * - A monotone trend (p rises or falls over a range of one parameter): the
 *   least-squares slope of the groups' probabilities on the parameter with
 *   its Wald 95% interval and the Cochran-Armitage trend test. `consistent`
 *   when the slope has the stated sign and the test's p < 0.05 (beamsim
 *   shows the trend the essay states); `differs` otherwise, which includes
 *   "no trend detected". H1's "rises from 0 to 20 N and falls from 20 to
 *   40 N" is two rows per F_prop, one per half.
 * - A stated change of a difference (Fig. 3.4b: the left-right difference
 *   shrinks as Rm grows; H1: the fall from 20 to 40 N is largest at 9 N):
 *   the difference of the two differences with its Wald 95% interval
 *   (multinomial variance within a group, (pL + pR - (pL - pR)^2) / n;
 *   binomial between groups) and the z test; verdict as for a trend. */
#define _POSIX_C_SOURCE 200809L /* strtok_r */
#include "beamsim/essay_compare.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/backend.h"
#include "beamsim/backend_registry.h"
#include "beamsim/experiment.h"
#include "beamsim/options.h"
#include "beamsim/stats.h"
#include "beamsim/sweep.h"
#include "util/clock.h"
#include "analysis/essay_internal.h"

#define ALPHA 0.05

/* The sweeps of one mode. Each is the shipped scene, fixed overrides and
 * at most two grid axes. */
enum { EX_H1, EX_K1, EX_F7, EX_RM, EX_CTRACK, EX_N };

typedef struct ex_def {
	const char *scene;  /* under cfg->configs */
	const char *set[4]; /* KEY=VALUE */
	const char *axis[2];
	const char *values[2]; /* comma-separated */
	int lattice;
} ex_def;

static const ex_def experiments[EX_N] = {
        /* Sec. 3.1 (Table 3.1): H1, k = 400. */
        [EX_H1] = {"thesis/gate.yaml",
                   {NULL},
                   {"effects.propulsion.force", "effects.random_force.magnitude"},
                   {"4,5,6,7,8,9", "0,10,20,30,40"},
                   0},
        /* Figs. 3.2 and 3.4a: F 8 N, Rm 30 N, k1 100..500, k2 500. */
        [EX_K1] = {"thesis/gate.yaml",
                   {"beams.1.stiffness=500", "effects.propulsion.force=8",
                    "effects.random_force.magnitude=30", NULL},
                   {"beams.0.stiffness", NULL},
                   {"500,450,400,350,300,250,200,150,100", NULL},
                   0},
        /* Fig. 3.3: F 7 N, Rm 10 N. */
        [EX_F7] = {"thesis/gate.yaml",
                   {"beams.1.stiffness=500", "effects.propulsion.force=7",
                    "effects.random_force.magnitude=10", NULL},
                   {"beams.0.stiffness", NULL},
                   {"500,300,100", NULL},
                   0},
        /* Fig. 3.4b: F 8 N, 300 : 500, Rm 10..60. */
        [EX_RM] = {"thesis/gate.yaml",
                   {"beams.1.stiffness=500", "beams.0.stiffness=300", "effects.propulsion.force=8",
                    NULL},
                   {"effects.random_force.magnitude", NULL},
                   {"10,20,30,40,50,60", NULL},
                   0},
        /* Sec. 3.3: the C-track, F 6 N, Rm 30 N. */
        [EX_CTRACK] = {"lattice/c_track.yaml", {NULL}, {NULL, NULL}, {NULL, NULL}, 1},
};

/* The sensitivity study: each parameter the essay leaves unstated over a
 * plausible range (the shipped value first marked), at the two symmetric
 * groups whose totals the essay reports. A key with a '.' is a scene key,
 * one without a backend option: impact_mass 0.1 kg is essay Eq. 2.4 read
 * literally (the beam's mass in the impact solve), 1 kg the body's mass. */
typedef struct sens_def {
	const char *key;
	const char *values[7];
	const char *shipped;
} sens_def;

static const sens_def sens_params[] = {
        {"contact.rest_threshold", {"0", "0.01", "0.05", "0.2", "0.5", "1", NULL}, "0.05"},
        {"contact.restitution", {"0.5", "0.7", "0.8", "0.9", "1", NULL}, "0.8"},
        {"contact.tip_restitution", {"0.8", "1", NULL}, "1"},
        {"integration.duration", {"6", "12", "24", "60", NULL}, "12"},
        {"termination.side_x", {"25", "35", "50", "1000", NULL}, "25"},
        {"impact_mass", {"0.1", "1", NULL}, "1"},
};
#define N_SENS ((int)(sizeof sens_params / sizeof sens_params[0]))

typedef struct sens_group {
	const char *set[2];
	const char *condition;
	double essay; /* left + right, Sec. 3.2.2 */
} sens_group;

static const sens_group sens_groups[] = {
        {{"effects.propulsion.force=7", "effects.random_force.magnitude=10"},
         "F 7 N; Rm 10 N; k1:k2 500:500",
         0.31},
        {{"effects.propulsion.force=8", "effects.random_force.magnitude=30"},
         "F 8 N; Rm 30 N; k1:k2 500:500",
         0.41},
};
#define N_SENS_GROUPS 2

bsim_essay_config bsim_essay_config_default(void)
{
	static const char *const modes[] = {"", "contact_mode=essay",
	                                    "contact_mode=essay:contact.tip_restitution=0.8"};
	return (bsim_essay_config){
	        .configs = "configs",
	        .backend = bsim_backend_default()->name,
	        .n_modes = 3,
	        .modes = modes,
	        .trials = 1000,
	        .lattice_trials = 1000,
	        .seed = 1,
	};
}

void bsim_essay_result_free(bsim_essay_result *r)
{
	if (!r)
		return;
	free(r->rows);
	free(r->sens);
	memset(r, 0, sizeof *r);
}

/* ---- building experiments in memory ---- */

static char *dup_str(const char *s)
{
	size_t n = strlen(s) + 1;
	char *d = malloc(n);
	if (d)
		memcpy(d, s, n);
	return d;
}

static int add_set(bsim_experiment *e, const char *kv, bsim_error *err)
{
	const char *eq = strchr(kv, '=');
	bsim_override *ov = &e->set[e->n_set];
	char key[128];
	snprintf(key, sizeof key, "%.*s", (int)(eq - kv), kv);
	ov->key = dup_str(key);
	ov->value = dup_str(eq + 1);
	ov->origin = dup_str("beamsim essay");
	e->n_set++;
	if (!ov->key || !ov->value || !ov->origin)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	return BSIM_OK;
}

static int add_axis(bsim_experiment *e, const char *key, const char *values, bsim_error *err)
{
	bsim_grid_axis *a = &e->axes[e->n_axes++];
	int n = 1;
	for (const char *c = values; *c; c++)
		n += *c == ',';
	char origin[160];
	snprintf(origin, sizeof origin, "beamsim essay: %s", key);
	a->key = dup_str(key);
	a->origin = dup_str(origin);
	a->values = calloc((size_t)n, sizeof *a->values);
	if (!a->key || !a->origin || !a->values)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	const char *s = values;
	for (int i = 0; i < n; i++) {
		size_t len = strcspn(s, ",");
		char v[32];
		snprintf(v, sizeof v, "%.*s", (int)len, s);
		a->values[i] = dup_str(v);
		a->n_values++;
		if (!a->values[i])
			return bsim_error_set(err, BSIM_EFAIL, "out of memory");
		s += len + (s[len] == ',');
	}
	e->n_groups *= n;
	return BSIM_OK;
}

#define SETS_MAX 10

/* An experiment of scene with the overrides sets (n_sets, KEY=VALUE) and
 * at most two axes; freed by bsim_experiment_free. */
static int exp_build(bsim_experiment *e, const char *configs, const char *scene,
                     const char *const *sets, int n_sets, const char *const *axes,
                     const char *const *values, int trials, uint64_t seed, bsim_error *err)
{
	memset(e, 0, sizeof *e);
	snprintf(e->path, sizeof e->path, "beamsim essay (%s)", scene);
	int len = snprintf(e->scene_path, sizeof e->scene_path, "%s/%s", configs, scene);
	if (len < 0 || (size_t)len >= sizeof e->scene_path)
		return bsim_error_set(err, BSIM_EINPUT, "--configs %s: path too long", configs);
	e->trials = trials;
	e->seed = seed;
	e->n_groups = 1;
	e->set = calloc(SETS_MAX, sizeof *e->set);
	e->axes = calloc(2, sizeof *e->axes);
	if (!e->set || !e->axes)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	int rc = BSIM_OK;
	for (int i = 0; i < n_sets && i < SETS_MAX && sets[i] && rc == BSIM_OK; i++)
		rc = add_set(e, sets[i], err);
	for (int i = 0; i < 2 && axes[i] && rc == BSIM_OK; i++)
		rc = add_axis(e, axes[i], values[i], err);
	return rc;
}

/* ---- the claims ---- */

typedef struct rows {
	bsim_essay_row *v;
	int n, cap;
	const char *mode;
} rows;

static bsim_essay_row *row_new(rows *r, const char *figure, const char *quantity,
                               const char *condition)
{
	if (r->n == r->cap) {
		int cap = r->cap ? 2 * r->cap : 64;
		bsim_essay_row *v = realloc(r->v, (size_t)cap * sizeof *v);
		if (!v)
			return NULL;
		r->v = v;
		r->cap = cap;
	}
	bsim_essay_row *w = &r->v[r->n++];
	memset(w, 0, sizeof *w);
	snprintf(w->figure, sizeof w->figure, "%s", figure);
	snprintf(w->quantity, sizeof w->quantity, "%s", quantity);
	snprintf(w->condition, sizeof w->condition, "%s", condition);
	snprintf(w->mode, sizeof w->mode, "%s", r->mode);
	w->essay_value = NAN;
	w->diff_lo = w->diff_hi = NAN;
	w->count = -1;
	return w;
}

/* A level: count of n against the essay's value of essay_n trials. */
static int level(rows *r, const char *figure, const char *quantity, const char *condition,
                 int count, int n, double essay, int essay_n)
{
	bsim_essay_row *w = row_new(r, figure, quantity, condition);
	if (!w)
		return -1;
	w->kind = BSIM_ESSAY_LEVEL;
	w->essay_value = essay;
	w->essay_n = essay_n;
	w->essay_count = (int)lround(essay * essay_n);
	w->count = count;
	w->n = n;
	w->value = n > 0 ? (double)count / n : 0.0;
	bsim_stats_wilson(count, n, BSIM_STATS_Z95, &w->ci_lo, &w->ci_hi);
	bsim_stats_newcombe_diff_ci(count, n, w->essay_count, essay_n, BSIM_STATS_Z95, &w->diff_lo,
	                            &w->diff_hi);
	w->p = bsim_stats_fisher_exact(count, n, w->essay_count, essay_n);
	snprintf(w->test, sizeof w->test, "fisher");
	w->consistent = w->p >= ALPHA;
	return 0;
}

/* A trend of k groups' counts x over scores s; sign +1 if the essay says
 * it rises, -1 if it falls. */
static int trend(rows *r, const char *figure, const char *quantity, const char *condition,
                 const char *expect, int sign, const int *x, int n, const double *s, int k)
{
	bsim_essay_row *w = row_new(r, figure, quantity, condition);
	if (!w)
		return -1;
	int nn[16];
	for (int i = 0; i < k; i++)
		nn[i] = n;
	bsim_stats_trend t;
	bsim_stats_cochran_armitage(x, nn, s, k, BSIM_STATS_Z95, &t);
	w->kind = BSIM_ESSAY_TREND;
	snprintf(w->expect, sizeof w->expect, "%s", expect);
	w->n = n;
	w->value = t.slope;
	w->ci_lo = t.lo;
	w->ci_hi = t.hi;
	w->p = t.p;
	snprintf(w->test, sizeof w->test, "cochran-armitage");
	w->consistent = t.p < ALPHA && sign * t.slope > 0;
	return 0;
}

/* A stated change with estimate est and its variance (Wald, z test). */
static int change(rows *r, const char *figure, const char *quantity, const char *condition,
                  const char *expect, double est, double var, int n)
{
	bsim_essay_row *w = row_new(r, figure, quantity, condition);
	if (!w)
		return -1;
	double se = sqrt(var);
	w->kind = BSIM_ESSAY_TREND;
	snprintf(w->expect, sizeof w->expect, "%s", expect);
	w->n = n;
	w->value = est;
	w->ci_lo = est - BSIM_STATS_Z95 * se;
	w->ci_hi = est + BSIM_STATS_Z95 * se;
	w->p = se > 0.0 ? erfc(fabs(est) / se / sqrt(2.0)) : 1.0;
	snprintf(w->test, sizeof w->test, "wald");
	w->consistent = w->p < ALPHA && est > 0.0;
	return 0;
}

static double pv(int x, int n)
{
	return n > 0 ? (double)x / n : 0.0;
}

/* The claims of one mode from its sweeps' groups. */
static int claims(rows *r, bsim_group_result *const *g, int trials, int lattice_trials)
{
	int bad = 0;
	const int n = trials;
	/* Fig. 3.2 (Sec. 3.2.2): F 8 N, Rm 30 N; k1 = 500, 300, 100 are EX_K1's
	 * groups 0, 4, 8. Fig. 3.3: F 7 N, Rm 10 N, EX_F7's 0, 1, 2. The totals
	 * are left + right as the essay gives them, except Fig. 3.3c, whose
	 * total the essay states as 100%. */
	static const struct {
		const char *fig;
		int ex, g;
		const char *cond;
		double left, right, total;
	} lv[] = {
	        {"Fig. 3.2a", EX_K1, 0, "F 8 N; Rm 30 N; k1:k2 500:500", 0.22, 0.19, 0.41},
	        {"Fig. 3.2b", EX_K1, 4, "F 8 N; Rm 30 N; k1:k2 300:500", 0.46, 0.18, 0.64},
	        {"Fig. 3.2c", EX_K1, 8, "F 8 N; Rm 30 N; k1:k2 100:500", 0.40, 0.46, 0.86},
	        {"Fig. 3.3a", EX_F7, 0, "F 7 N; Rm 10 N; k1:k2 500:500", 0.13, 0.18, 0.31},
	        {"Fig. 3.3b", EX_F7, 1, "F 7 N; Rm 10 N; k1:k2 300:500", 0.52, 0.00, 0.52},
	        {"Fig. 3.3c", EX_F7, 2, "F 7 N; Rm 10 N; k1:k2 100:500", 0.12, 0.86, 1.00},
	};
	for (size_t i = 0; i < sizeof lv / sizeof lv[0]; i++) {
		const bsim_group_result *q = &g[lv[i].ex][lv[i].g];
		bad |= level(r, lv[i].fig, "p_left", lv[i].cond, q->left, n, lv[i].left, 100);
		bad |= level(r, lv[i].fig, "p_right", lv[i].cond, q->right, n, lv[i].right, 100);
		bad |= level(r, lv[i].fig, "p_traverse", lv[i].cond, q->traversed, n, lv[i].total,
		             100);
	}
	bad |= level(r, "Sec. 3.3", "p_traverse (reached y = 540 m)",
	             "C-track; F 6 N; Rm 30 N; 9 x 9 lattice", g[EX_CTRACK][0].traversed,
	             lattice_trials, 0.35, 20);

	/* H1 (Sec. 3.1.2). EX_H1 group = iF * 5 + iRm, F 4..9, Rm 0..40. */
	const bsim_group_result *h = g[EX_H1];
	char cond[96];
	for (int iR = 0; iR < 5; iR++) {
		int x[6];
		double s[6];
		for (int iF = 0; iF < 6; iF++) {
			x[iF] = h[iF * 5 + iR].traversed;
			s[iF] = 4 + iF;
		}
		snprintf(cond, sizeof cond, "k 400; Rm %d N; F 4..9 N", 10 * iR);
		bad |= trend(r, "Sec. 3.1.2", "slope of p_traverse per N of F_prop", cond, "rises",
		             +1, x, n, s, 6);
	}
	for (int half = 0; half < 2; half++)
		for (int iF = 0; iF < 6; iF++) {
			int x[3];
			double s[3];
			for (int j = 0; j < 3; j++) {
				x[j] = h[iF * 5 + 2 * half + j].traversed;
				s[j] = 2 * half + j;
			}
			snprintf(cond, sizeof cond, "k 400; F %d N; Rm %s N", 4 + iF,
			         half ? "20..40" : "0..20");
			bad |= trend(r, "Sec. 3.1.2", "slope of p_traverse per 10 N of Rm", cond,
			             half ? "falls" : "rises", half ? -1 : +1, x, n, s, 3);
		}
	/* "Most at 9 N": the fall from 20 to 40 N at 9 N less the largest fall
	 * at another F_prop. */
	double drop[6], var[6];
	int most = 0;
	for (int iF = 0; iF < 6; iF++) {
		double a = pv(h[iF * 5 + 2].traversed, n), b = pv(h[iF * 5 + 4].traversed, n);
		drop[iF] = a - b;
		var[iF] = (a * (1 - a) + b * (1 - b)) / n;
		if (iF < 5 && drop[iF] > drop[most])
			most = iF;
	}
	snprintf(cond, sizeof cond, "k 400; fall of p_traverse Rm 20 -> 40 N; 9 N vs %d N",
	         4 + most);
	bad |= change(r, "Sec. 3.1.2", "fall at 9 N minus the largest other fall", cond, "largest",
	              drop[5] - drop[most], var[5] + var[most], n);

	/* Fig. 3.4a: EX_K1 groups k1 = 500 - 50 i. Left rises from 500 to 350,
	 * right rises from 350 to 100; score: k1 lowered, per 100 N m/rad. */
	{
		const bsim_group_result *k = g[EX_K1];
		int x[9];
		double s[9];
		for (int i = 0; i < 4; i++) {
			x[i] = k[i].left;
			s[i] = 0.5 * i;
		}
		bad |= trend(r, "Fig. 3.4a", "slope of p_left per 100 N m/rad lower k1",
		             "F 8 N; Rm 30 N; k1 500..350; k2 500", "rises", +1, x, n, s, 4);
		for (int i = 3; i < 9; i++) {
			x[i - 3] = k[i].right;
			s[i - 3] = 0.5 * i;
		}
		bad |= trend(r, "Fig. 3.4a", "slope of p_right per 100 N m/rad lower k1",
		             "F 8 N; Rm 30 N; k1 350..100; k2 500", "rises", +1, x, n, s, 6);
	}
	/* Fig. 3.4b: (p_left - p_right) at Rm 10 less at Rm 60. */
	{
		const bsim_group_result *a = &g[EX_RM][0], *b = &g[EX_RM][5];
		double la = pv(a->left, n), ra = pv(a->right, n), lb = pv(b->left, n),
		       rb = pv(b->right, n);
		double da = la - ra, db = lb - rb;
		double v = (la + ra - da * da) / n + (lb + rb - db * db) / n;
		bad |= change(r, "Fig. 3.4b", "(p_left - p_right) at Rm 10 N minus at 60 N",
		              "F 8 N; k1:k2 300:500; Rm 10 vs 60 N", "shrinks", da - db, v, n);
	}
	return bad ? -1 : 0;
}

/* A mode "KEY=VALUE:KEY=VALUE": a key with a dot is a scene key (an
 * override of every group, e.g. contact.tip_restitution=0.8), any other a
 * backend option. */
#define MODE_SETS_MAX 4

typedef struct mode_def {
	bsim_options opts;
	char sets[MODE_SETS_MAX][96];
	int n_sets;
} mode_def;

static int mode_parse(const bsim_essay_config *cfg, const bsim_backend *b, const char *mode,
                      mode_def *md, bsim_error *err)
{
	memset(md, 0, sizeof *md);
	char buf[256];
	if (strchr(mode, ',') || strchr(mode, '\n') || strchr(mode, '|'))
		return bsim_error_set(err, BSIM_EINPUT,
		                      "--mode %s: expected KEY=VALUE:KEY=VALUE without ',', '|' "
		                      "or a newline (it names a column of essay.csv)",
		                      mode);
	if (strlen(mode) >= sizeof buf)
		return bsim_error_set(err, BSIM_EINPUT, "--mode %s: too long", mode);
	snprintf(buf, sizeof buf, "%s", mode);
	char *save = NULL;
	for (char *t = strtok_r(buf, ":", &save); t; t = strtok_r(NULL, ":", &save)) {
		const char *eq = strchr(t, '=');
		if (!eq || eq == t)
			return bsim_error_set(err, BSIM_EINPUT, "--mode %s: %s: expected KEY=VALUE",
			                      mode, t);
		if (memchr(t, '.', (size_t)(eq - t))) {
			if (md->n_sets == MODE_SETS_MAX || strlen(t) >= sizeof md->sets[0])
				return bsim_error_set(err, BSIM_EINPUT,
				                      "--mode %s: at most %d scene keys", mode,
				                      MODE_SETS_MAX);
			snprintf(md->sets[md->n_sets++], sizeof md->sets[0], "%s", t);
			continue;
		}
		int rc = bsim_options_add(&md->opts, t, err);
		if (rc != BSIM_OK)
			return rc;
	}
	return bsim_options_check(&md->opts, b->knobs, b->n_knobs, cfg->backend, err);
}

/* The overrides of a group: base (NULL-terminated, at most 4) and then the
 * mode's, into sets. */
static int join_sets(const char *const *base, int n_base, const mode_def *md, const char **sets)
{
	int n = 0;
	for (int i = 0; i < n_base && base[i]; i++)
		sets[n++] = base[i];
	for (int i = 0; i < md->n_sets; i++)
		sets[n++] = md->sets[i];
	return n;
}

/* The values of d the study runs on backend b: none for a backend option
 * b does not have (impact_mass on a backend without it). */
static long sens_values(const sens_def *d, const bsim_backend *b)
{
	if (!strchr(d->key, '.')) {
		int known = 0;
		for (int i = 0; i < b->n_knobs; i++)
			known |= strcmp(b->knobs[i].name, d->key) == 0;
		if (!known)
			return 0;
	}
	long k = 0;
	while (k < 7 && d->values[k])
		k++;
	return k;
}

/* One sweep of the run: an experiment of a mode (EX_H1 .. EX_CTRACK), or
 * a group of the sensitivity study (kind EX_N: parameter p, group q,
 * value v). */
typedef struct essay_job {
	bsim_experiment e;
	bsim_options opts;
	int mode, kind, p, q, v;
} essay_job;

/* Every sweep of the run, in the order they ran one after another: by
 * mode, its experiments, then its study by parameter, group and value. */
static int jobs_build(const bsim_essay_config *cfg, const bsim_backend *b, const mode_def *md,
                      essay_job **out, int *n_out, bsim_error *err)
{
	int cap = cfg->n_modes * (EX_N + N_SENS * N_SENS_GROUPS * 7), n = 0;
	essay_job *jobs = calloc((size_t)cap, sizeof *jobs);
	if (!jobs)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	int rc = BSIM_OK;
	for (int m = 0; m < cfg->n_modes && rc == BSIM_OK; m++) {
		for (int i = 0; i < EX_N && rc == BSIM_OK; i++) {
			const ex_def *d = &experiments[i];
			const char *sets[SETS_MAX];
			int n_set = join_sets(d->set, 4, &md[m], sets);
			essay_job *j = &jobs[n++];
			j->mode = m;
			j->kind = i;
			j->opts = md[m].opts;
			rc = exp_build(&j->e, cfg->configs, d->scene, sets, n_set, d->axis,
			               d->values, d->lattice ? cfg->lattice_trials : cfg->trials,
			               cfg->seed, err);
		}
		/* The sensitivity study: one sweep per parameter, value and
		 * group, k1 = k2 = 500. Each is group 0 of its sweep, so every
		 * value runs with the same random-force schedules (common random
		 * numbers): the values differ by the parameter, not the draws. */
		for (int p = 0; p < N_SENS && rc == BSIM_OK && cfg->sens_trials > 0; p++) {
			const sens_def *d = &sens_params[p];
			for (int q = 0; q < N_SENS_GROUPS && rc == BSIM_OK; q++)
				for (long v = 0; v < sens_values(d, b) && rc == BSIM_OK; v++) {
					char kv[96];
					snprintf(kv, sizeof kv, "%s=%s", d->key, d->values[v]);
					const char *base[5] = {
					        "beams.0.stiffness=500", "beams.1.stiffness=500",
					        sens_groups[q].set[0], sens_groups[q].set[1], NULL};
					const char *sets[SETS_MAX];
					int n_set = join_sets(base, 4, &md[m], sets);
					essay_job *j = &jobs[n++];
					j->mode = m;
					j->kind = EX_N;
					j->p = p;
					j->q = q;
					j->v = (int)v;
					j->opts = md[m].opts;
					if (strchr(d->key, '.'))
						sets[n_set++] = kv; /* after the mode's */
					else
						rc = bsim_options_add(&j->opts, kv, err);
					const char *none[2] = {NULL, NULL};
					if (rc == BSIM_OK)
						rc = exp_build(&j->e, cfg->configs,
						               "thesis/gate.yaml", sets, n_set,
						               none, none, cfg->sens_trials,
						               cfg->seed, err);
				}
		}
	}
	*out = jobs;
	*n_out = n;
	return rc;
}

static void jobs_free(essay_job *jobs, int n)
{
	for (int i = 0; jobs && i < n; i++)
		bsim_experiment_free(&jobs[i].e);
	free(jobs);
}

/* A sensitivity row from its sweep's group. */
static void sens_row(bsim_essay_sens_row *w, const essay_job *j, const char *mode,
                     const bsim_group_result *gr)
{
	const sens_def *d = &sens_params[j->p];
	snprintf(w->parameter, sizeof w->parameter, "%s", d->key);
	snprintf(w->value, sizeof w->value, "%s", d->values[j->v]);
	w->is_default = strcmp(d->values[j->v], d->shipped) == 0;
	snprintf(w->condition, sizeof w->condition, "%s", sens_groups[j->q].condition);
	snprintf(w->mode, sizeof w->mode, "%s", mode);
	w->n = gr->trials;
	w->traversed = gr->traversed;
	w->left = gr->left;
	w->right = gr->right;
	w->side_exit = gr->side_exit;
	w->stuck = gr->stuck;
	w->p = pv(gr->traversed, gr->trials);
	bsim_stats_wilson(gr->traversed, gr->trials, BSIM_STATS_Z95, &w->lo, &w->hi);
	w->essay_value = sens_groups[j->q].essay;
	w->reaches = w->hi >= w->essay_value;
}

int bsim_essay_compare_batch(const bsim_essay_config *cfg, sweep_batch *sb, bsim_essay_result *out,
                             bsim_error *err)
{
	memset(out, 0, sizeof *out);
	if (cfg->trials < 1 || cfg->lattice_trials < 1 || cfg->sens_trials < 0 || cfg->n_modes < 1)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "essay: expected at least one trial per group and one mode");
	const bsim_backend *b = bsim_backend_find(cfg->backend, err);
	if (!b)
		return BSIM_EINPUT;
	mode_def *md = calloc((size_t)cfg->n_modes, sizeof *md);
	if (!md)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	int rc = BSIM_OK;
	for (int m = 0; m < cfg->n_modes && rc == BSIM_OK; m++)
		rc = mode_parse(cfg, b, cfg->modes[m], &md[m], err);
	double t0 = bsim_clock_seconds();
	essay_job *jobs = NULL;
	int n = 0;
	if (rc == BSIM_OK)
		rc = jobs_build(cfg, b, md, &jobs, &n, err);
	const bsim_experiment **es = calloc((size_t)n + 1, sizeof *es);
	bsim_sweep_config *sc = calloc((size_t)n + 1, sizeof *sc);
	bsim_sweep_result *res = calloc((size_t)n + 1, sizeof *res);
	if (rc == BSIM_OK && (!es || !sc || !res))
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	for (int i = 0; rc == BSIM_OK && i < n; i++) {
		es[i] = &jobs[i].e;
		sc[i] = bsim_sweep_config_default();
		sc[i].backend = b;
		sc[i].opts = &jobs[i].opts;
		sc[i].threads = cfg->threads;
	}
	if (rc == BSIM_OK)
		rc = bsim_sweep_batch_run(sb, es, sc, n, res, err);
	rows r = {0};
	bsim_essay_sens_row *sv = NULL;
	int n_sens = 0;
	if (rc == BSIM_OK && sb->writes && cfg->sens_trials > 0) {
		sv = calloc((size_t)n + 1, sizeof *sv);
		if (!sv)
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	long trials_run = 0;
	for (int i = 0; rc == BSIM_OK && sb->writes && i < n; i++) {
		const essay_job *j = &jobs[i];
		r.mode = cfg->modes[j->mode][0] ? cfg->modes[j->mode] : "default";
		trials_run += (long)j->e.n_groups * j->e.trials;
		if (j->kind == EX_N) {
			sens_row(&sv[n_sens++], j, r.mode, &res[i].groups[0]);
		} else if (j->kind == EX_N - 1) {
			/* the mode's experiments are jobs i - EX_N + 1 .. i */
			bsim_group_result *g[EX_N];
			for (int k = 0; k < EX_N; k++)
				g[k] = res[i - EX_N + 1 + k].groups;
			if (claims(&r, g, cfg->trials, cfg->lattice_trials) != 0)
				rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
		}
	}
	for (int i = 0; res && i < n; i++)
		bsim_sweep_result_free(&res[i]);
	free(res);
	free(sc);
	free(es);
	jobs_free(jobs, n);
	free(md);
	if (rc != BSIM_OK || !sb->writes) {
		free(r.v);
		free(sv);
		return rc;
	}
	out->rows = r.v;
	out->n = r.n;
	out->sens = sv;
	out->n_sens = n_sens;
	out->trials_run = trials_run;
	out->wall_seconds = bsim_clock_seconds() - t0;
	return BSIM_OK;
}

int bsim_essay_compare_run(const bsim_essay_config *cfg, bsim_essay_result *out, bsim_error *err)
{
	/* in memory: no directory, no journal */
	sweep_batch sb = {.command = "essay",
	                  .progress = cfg->progress,
	                  .progress_user = cfg->progress_user,
	                  .stop = cfg->stop};
	return bsim_essay_compare_batch(cfg, &sb, out, err);
}
