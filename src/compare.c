/* Paired comparison of two sweeps, group by group.
 *
 * For each group and event (traversed, left, right, side exit, stuck,
 * unstable) the n trial pairs form a 2x2 table: a both, b only A, c only
 * B, d neither.
 *   p_A = (a + b)/n, p_B = (a + c)/n        Wilson 95% each
 *   p_A - p_B = (b - c)/n                   Tango's score 95% (stats.h)
 *   McNemar exact: b ~ Binomial(b + c, 1/2) under "no difference"
 *   equivalence: Tango's two one-sided tests against +-margin
 * The McNemar p-values of all random groups' tests are Holm-adjusted
 * together, so the chance that any agreeing group is called disagreeing
 * stays below alpha however many groups an experiment has.
 *
 * The smallest detectable difference of a test: with m = b + c discordant
 * pairs (at least the fewest that can reach significance at all), the
 * test flags a split of k against m - k only when its exact p-value is
 * below alpha / (family size), Holm's first and strictest step; the
 * largest such k gives |p_A - p_B| >= (m - 2k) / n.
 *
 * A deterministic group (no random draws on either side) is one trial run
 * once: one pair, same or different, outside the family. */
#include "beamsim/compare.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char *const event_names[BSIM_N_EVENTS] = {"traversed", "left",  "right",
                                                       "side_exit", "stuck", "unstable"};

const char *bsim_event_name(bsim_event ev)
{
	return ev >= 0 && ev < BSIM_N_EVENTS ? event_names[ev] : "?";
}

int bsim_event_of(const bsim_trial_result *r, bsim_event ev)
{
	switch (ev) {
	case BSIM_EVENT_TRAVERSED:
		return r->outcome == BSIM_TRAVERSED;
	case BSIM_EVENT_LEFT:
		return r->outcome == BSIM_TRAVERSED && r->type == BSIM_TYPE_LEFT;
	case BSIM_EVENT_RIGHT:
		return r->outcome == BSIM_TRAVERSED && r->type == BSIM_TYPE_RIGHT;
	case BSIM_EVENT_SIDE_EXIT:
		return r->outcome == BSIM_SIDE_EXIT;
	case BSIM_EVENT_STUCK:
		return r->outcome == BSIM_STUCK;
	case BSIM_EVENT_UNSTABLE:
		return r->outcome == BSIM_UNSTABLE;
	default:
		return 0;
	}
}

const char *bsim_verdict_name(bsim_verdict v)
{
	switch (v) {
	case BSIM_VERDICT_SAME:
		return "same";
	case BSIM_VERDICT_EQUIVALENT:
		return "equivalent";
	case BSIM_VERDICT_INCONCLUSIVE:
		return "inconclusive";
	case BSIM_VERDICT_SMALL:
		return "small";
	case BSIM_VERDICT_DISAGREE:
		return "DISAGREE";
	case BSIM_VERDICT_DIFFERENT:
		return "DIFFERENT";
	case BSIM_N_VERDICTS:
		break;
	}
	return "?";
}

int bsim_trial_discordant(const bsim_trial_result *a, const bsim_trial_result *b)
{
	return a->outcome != b->outcome || a->type != b->type;
}

int bsim_trial_identical(const bsim_trial_result *a, const bsim_trial_result *b, int ledger)
{
	const bsim_ledger *la = &a->ledger, *lb = &b->ledger;
	int same = !bsim_trial_discordant(a, b) && a->steps == b->steps && a->t_end == b->t_end &&
	           a->x_end == b->x_end && a->y_end == b->y_end && a->vx_end == b->vx_end &&
	           a->max_theta[0] == b->max_theta[0] && a->max_theta[1] == b->max_theta[1];
	if (same && ledger)
		same = la->e_start == lb->e_start && la->e_end == lb->e_end &&
		       la->w_prop + la->w_rand == lb->w_prop + lb->w_rand &&
		       la->damper + la->impact + la->contact + la->correction ==
		               lb->damper + lb->impact + lb->contact + lb->correction &&
		       la->residual == lb->residual;
	return same;
}

static void event_table(const bsim_trial_result *a, const bsim_trial_result *b, int n,
                        bsim_event ev, bsim_event_test *t)
{
	memset(t, 0, sizeof *t);
	for (int i = 0; i < n; i++) {
		int x = bsim_event_of(&a[i], ev), y = bsim_event_of(&b[i], ev);
		t->pairs.a += x && y;
		t->pairs.b += x && !y;
		t->pairs.c += !x && y;
		t->pairs.d += !x && !y;
	}
	int ka = t->pairs.a + t->pairs.b, kb = t->pairs.a + t->pairs.c;
	t->p_a = n > 0 ? (double)ka / n : 0.0;
	t->p_b = n > 0 ? (double)kb / n : 0.0;
	t->diff = n > 0 ? (double)(t->pairs.b - t->pairs.c) / n : 0.0;
}

/* The statistics of a random group's event. */
static void event_stats(bsim_event_test *t, int n, double margin)
{
	int ka = t->pairs.a + t->pairs.b, kb = t->pairs.a + t->pairs.c;
	bsim_wilson(ka, n, BSIM_Z95, &t->ci_a[0], &t->ci_a[1]);
	bsim_wilson(kb, n, BSIM_Z95, &t->ci_b[0], &t->ci_b[1]);
	bsim_tango_ci(&t->pairs, BSIM_Z95, &t->diff_ci[0], &t->diff_ci[1]);
	t->p_value = bsim_mcnemar_exact(t->pairs.b, t->pairs.c);
	t->p_equivalence = bsim_tango_tost(&t->pairs, margin);
}

/* A deterministic group's event: the one pair, no statistics. */
static void event_point(bsim_event_test *t)
{
	t->ci_a[0] = t->ci_a[1] = t->p_a;
	t->ci_b[0] = t->ci_b[1] = t->p_b;
	t->diff_ci[0] = t->diff_ci[1] = t->diff;
	t->p_value = t->p_holm = t->p_equivalence = NAN;
	t->detectable = NAN;
}

/* The smallest |p_A - p_B| the family's test can flag with the event's
 * discordant pairs; NaN if no split of n pairs can be flagged at all. */
static double event_detectable(const bsim_event_test *t, int n, double level)
{
	int m = t->pairs.b + t->pairs.c;
	int fewest = 1;
	while (fewest <= n && bsim_mcnemar_split(fewest, level) < 0)
		fewest++;
	if (fewest > n)
		return NAN;
	if (m < fewest)
		m = fewest;
	int k = bsim_mcnemar_split(m, level);
	return (double)(m - 2 * k) / n;
}

static int cmp_double(const void *x, const void *y)
{
	double a = *(const double *)x, b = *(const double *)y;
	return (a > b) - (a < b);
}

/* Nearest-rank quantiles 10%, 50%, 90% of the n >= 0 values in v (sorted
 * in place); -1 when n = 0. */
static void quantiles(double *v, int n, double q[3])
{
	static const double at[3] = {0.1, 0.5, 0.9};
	qsort(v, (size_t)n, sizeof *v, cmp_double);
	for (int k = 0; k < 3; k++) {
		int r = (int)ceil(at[k] * n);
		q[k] = n > 0 ? v[r > 0 ? r - 1 : 0] : -1.0;
	}
}

/* Separated pairs of trials [0, n) of t (times >= 0) appended to buf;
 * count. */
static int separated_times(const double *t, long n, double *buf)
{
	int k = 0;
	for (long i = 0; i < n; i++)
		if (t[i] >= 0.0)
			buf[k++] = t[i];
	return k;
}

static void group_verdict(bsim_compare_group *g, const bsim_compare_rule *rule)
{
	if (g->deterministic) {
		g->verdict = rule->exact && g->changed > 0 ? BSIM_VERDICT_DISAGREE
		             : g->discordant > 0           ? BSIM_VERDICT_DIFFERENT
		                                           : BSIM_VERDICT_SAME;
		return;
	}
	int significant = 0, beyond = 0, equivalent = 1;
	for (int e = 0; e < BSIM_N_EVENTS; e++) {
		bsim_event_test *t = &g->ev[e];
		int sig = t->p_holm < rule->alpha;
		t->beyond = sig && fabs(t->diff) >= rule->margin;
		t->equivalent = t->p_equivalence < rule->alpha;
		significant |= sig;
		beyond |= t->beyond;
		equivalent &= t->equivalent;
	}
	if (beyond || (rule->exact && g->changed > 0))
		g->verdict = BSIM_VERDICT_DISAGREE;
	else if (significant)
		g->verdict = BSIM_VERDICT_SMALL;
	else
		g->verdict = equivalent ? BSIM_VERDICT_EQUIVALENT : BSIM_VERDICT_INCONCLUSIVE;
}

int bsim_compare_analyse(const bsim_sweep_result *a, const bsim_sweep_result *b,
                         const double *t_separate, const bsim_compare_rule *rule,
                         bsim_comparison *out, bsim_error *err)
{
	memset(out, 0, sizeof *out);
	if (a->n_groups != b->n_groups || a->trials != b->trials)
		return bsim_error_set(
		        err, BSIM_EINPUT,
		        "cannot pair %d groups x %d trials with %d groups x %d trials", a->n_groups,
		        a->trials, b->n_groups, b->trials);
	int G = a->n_groups, n = a->trials;
	long total = (long)G * n;
	int ledger = a->has_ledger && b->has_ledger;
	out->n_groups = G;
	out->trials = n;
	out->rule = *rule;
	out->groups = calloc(G > 0 ? (size_t)G : 1, sizeof *out->groups);
	double *p = calloc((size_t)(G > 0 ? G : 1) * BSIM_N_EVENTS, sizeof *p);
	double *buf = malloc((size_t)(total > 0 ? total : 1) * sizeof *buf);
	if (!out->groups || !p || !buf) {
		free(p);
		free(buf);
		bsim_comparison_free(out);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory comparing %d groups", G);
	}
	int n_sep = 0;
	for (int g = 0; g < G; g++) {
		const bsim_trial_result *ra = &a->trials_out[(size_t)g * n];
		const bsim_trial_result *rb = &b->trials_out[(size_t)g * n];
		bsim_compare_group *cg = &out->groups[g];
		cg->deterministic = (a->groups && a->groups[g].deterministic) ||
		                    (b->groups && b->groups[g].deterministic);
		cg->pairs = cg->deterministic && n > 0 ? 1 : n;
		for (int e = 0; e < BSIM_N_EVENTS; e++) {
			bsim_event_test *t = &cg->ev[e];
			event_table(ra, rb, cg->pairs, (bsim_event)e, t);
			if (cg->deterministic) {
				event_point(t);
			} else {
				event_stats(t, cg->pairs, rule->margin);
				p[out->n_tests++] = t->p_value;
			}
		}
		for (int i = 0; i < cg->pairs; i++)
			cg->discordant += bsim_trial_discordant(&ra[i], &rb[i]);
		/* Over every trial, copies included: a stored file edited in
		 * any row is a change. */
		for (int i = 0; i < n; i++)
			cg->changed += !bsim_trial_identical(&ra[i], &rb[i], ledger);
		out->pairs += cg->pairs;
		cg->t_sep[0] = cg->t_sep[1] = cg->t_sep[2] = -1.0;
		if (t_separate) {
			cg->separated = separated_times(&t_separate[(size_t)g * n], cg->pairs, buf);
			quantiles(buf, cg->separated, cg->t_sep);
		}
	}
	bsim_holm(p, out->n_tests, p);
	double level = out->n_tests > 0 ? rule->alpha / out->n_tests : rule->alpha;
	for (int g = 0, k = 0; g < G; g++) {
		bsim_compare_group *cg = &out->groups[g];
		for (int e = 0; !cg->deterministic && e < BSIM_N_EVENTS; e++) {
			cg->ev[e].p_holm = p[k++];
			cg->ev[e].detectable = event_detectable(&cg->ev[e], cg->pairs, level);
		}
		group_verdict(cg, rule);
		out->count[cg->verdict]++;
		out->n_disagree += cg->verdict == BSIM_VERDICT_DISAGREE ||
		                   cg->verdict == BSIM_VERDICT_DIFFERENT;
	}
	out->t_sep[0] = out->t_sep[1] = out->t_sep[2] = -1.0;
	if (t_separate) {
		for (int g = 0; g < G; g++)
			n_sep += separated_times(&t_separate[(size_t)g * n], out->groups[g].pairs,
			                         buf + n_sep);
		out->separated = n_sep;
		quantiles(buf, n_sep, out->t_sep);
	}
	free(p);
	free(buf);
	return BSIM_OK;
}

void bsim_comparison_free(bsim_comparison *c)
{
	if (!c)
		return;
	free(c->groups);
	memset(c, 0, sizeof *c);
}
