/* Paired comparison of two sweeps, group by group.
 *
 * For each group and event (traversed, left, right, side exit, stuck,
 * unstable) the n trial pairs form a 2x2 table: a both, b only A, c only
 * B, d neither.
 *   p_A = (a + b)/n, p_B = (a + c)/n        Wilson 95% each
 *   p_A - p_B = (b - c)/n                   Tango's score 95% (stats.h)
 *   McNemar exact: b ~ Binomial(b + c, 1/2) under "no difference"
 *   equivalence: Tango's two one-sided tests against +-margin
 * The McNemar p-values of the random groups' tests are Holm-adjusted
 * together, so the chance that any agreeing group is called disagreeing
 * stays below alpha however many groups an experiment has. The family
 * leaves out each group's events whose hypotheses the others imply
 * (bsim_compare_family, beamsim/compare.h): an event that never occurs,
 * the complement of the other outcomes, and traversed when it is left +
 * right (the components tell which beam, and are symmetric).
 *
 * mde80, the minimum detectable difference: the |p_A - p_B| that the exact
 * McNemar test at alpha / (family size), Holm's first and strictest step,
 * detects with power 0.8 when a pair is discordant with the event's
 * observed probability psi = (b + c) / n (bsim_stats_mcnemar_mde, with the
 * exact power; where the difference would exceed psi, psi is taken as the
 * difference: every discordant pair one way). min_significant, a bound and
 * not a power: with m = b + c discordant pairs (at least the fewest that
 * can reach significance at all), the test flags a split of k against
 * m - k only when its exact p-value is below alpha / (family size); the
 * largest such k gives |p_A - p_B| >= (m - 2k) / n.
 *
 * An event at the floor or the ceiling (both p within the margin of 0, or
 * both of 1) is not informative: there any two backends agree within the
 * margin. A group is equivalent when at least one event is informative and
 * every informative one is shown within the margin; uninformative when
 * none is.
 *
 * A deterministic group (no random draws on either side) is one trial run
 * once: one pair, same or different, outside the family.
 *
 * For a lattice, the final-location test (bsim_location_test) of each random
 * group joins the Holm family. */
#include "beamsim/compare.h"

#include <gsl/gsl_rng.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/lattice.h"
#include "beamsim/lattice_outcome.h"

static const char *const event_names[BSIM_N_EVENTS] = {"traversed", "left",  "right",
                                                       "side_exit", "stuck", "unstable"};

bsim_compare_rule bsim_compare_rule_default(void)
{
	return (bsim_compare_rule){.alpha = 0.05, .margin = 0.05, .exact = 0};
}

const char *bsim_compare_event_name(bsim_event ev)
{
	return ev >= 0 && ev < BSIM_N_EVENTS ? event_names[ev] : "?";
}

int bsim_compare_event_of(const bsim_trial_result *r, bsim_event ev)
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

const char *bsim_compare_verdict_name(bsim_verdict v)
{
	switch (v) {
	case BSIM_VERDICT_SAME:
		return "same";
	case BSIM_VERDICT_EQUIVALENT:
		return "equivalent";
	case BSIM_VERDICT_UNINFORMATIVE:
		return "uninformative";
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

int bsim_compare_discordant(const bsim_trial_result *a, const bsim_trial_result *b)
{
	return a->outcome != b->outcome || a->type != b->type ||
	       !bsim_lattice_location_equal(bsim_lattice_location_of(a),
	                                    bsim_lattice_location_of(b));
}

int bsim_compare_known(const bsim_sweep_result *a, const bsim_sweep_result *b)
{
	return (a->has_ledger && b->has_ledger ? BSIM_COMPARE_LEDGER : 0) |
	       (a->has_turn && b->has_turn ? BSIM_COMPARE_TURN : 0);
}

int bsim_compare_identical(const bsim_trial_result *a, const bsim_trial_result *b, int known)
{
	const bsim_ledger *la = &a->ledger, *lb = &b->ledger;
	int same = !bsim_compare_discordant(a, b) && a->steps == b->steps && a->t_end == b->t_end &&
	           a->x_end == b->x_end && a->y_end == b->y_end && a->vx_end == b->vx_end &&
	           a->max_theta[0] == b->max_theta[0] && a->max_theta[1] == b->max_theta[1] &&
	           a->final_ix == b->final_ix && a->final_iy == b->final_iy;
	if (same && (known & BSIM_COMPARE_LEDGER))
		same = la->e_start == lb->e_start && la->e_end == lb->e_end &&
		       la->w_prop + la->w_rand == lb->w_prop + lb->w_rand &&
		       la->damper + la->impact + la->contact + la->correction ==
		               lb->damper + lb->impact + lb->contact + lb->correction &&
		       la->residual == lb->residual;
	if (same && (known & BSIM_COMPARE_TURN))
		same = a->heading_end == b->heading_end &&
		       a->angular_velocity_end == b->angular_velocity_end &&
		       a->turn_end == b->turn_end && a->turn_max == b->turn_max;
	return same;
}

static void event_table(const bsim_trial_result *a, const bsim_trial_result *b, int n,
                        bsim_event ev, bsim_event_test *t)
{
	memset(t, 0, sizeof *t);
	for (int i = 0; i < n; i++) {
		int x = bsim_compare_event_of(&a[i], ev), y = bsim_compare_event_of(&b[i], ev);
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
	bsim_stats_wilson(ka, n, BSIM_STATS_Z95, &t->ci_a[0], &t->ci_a[1]);
	bsim_stats_wilson(kb, n, BSIM_STATS_Z95, &t->ci_b[0], &t->ci_b[1]);
	bsim_stats_tango_ci(&t->pairs, BSIM_STATS_Z95, &t->diff_ci[0], &t->diff_ci[1]);
	t->p_value = bsim_stats_mcnemar_exact(t->pairs.b, t->pairs.c);
	t->p_equivalence = bsim_stats_tango_tost(&t->pairs, margin);
}

/* A deterministic group's event: the one pair, no statistics. */
static void event_point(bsim_event_test *t)
{
	t->ci_a[0] = t->ci_a[1] = t->p_a;
	t->ci_b[0] = t->ci_b[1] = t->p_b;
	t->diff_ci[0] = t->diff_ci[1] = t->diff;
	t->p_value = t->p_holm = t->p_equivalence = NAN;
	t->mde80 = t->min_significant = NAN;
}

/* The smallest |p_A - p_B| the family's test can flag with the event's
 * discordant pairs, k[m] the test's split of m pairs at the family's level
 * (bsim_stats_mcnemar_splits); NaN if no split of n pairs can be flagged. */
static double event_min_significant(const bsim_event_test *t, int n, const int *k)
{
	int m = t->pairs.b + t->pairs.c;
	int fewest = 1;
	while (fewest <= n && k[fewest] < 0)
		fewest++;
	if (fewest > n)
		return NAN;
	if (m < fewest)
		m = fewest;
	return (double)(m - 2 * k[m]) / n;
}

/* ---- the Holm family ----------------------------------------------------- */

/* A trial's outcome cell: traversed left, right or none, side exit, stuck,
 * unstable (the bits of bsim_compare_family's mask). */
static int cell_of(const bsim_trial_result *r)
{
	switch (r->outcome) {
	case BSIM_TRAVERSED:
		return r->type == BSIM_TYPE_LEFT ? 0 : r->type == BSIM_TYPE_RIGHT ? 1 : 2;
	case BSIM_SIDE_EXIT:
		return 3;
	case BSIM_STUCK:
		return 4;
	default:
		return 5;
	}
}

enum { N_CELLS = 6 };

/* Each event's cells, and the order in which the family takes them. */
static const unsigned event_cells[BSIM_N_EVENTS] = {
        [BSIM_EVENT_TRAVERSED] = 07,  [BSIM_EVENT_LEFT] = 01,   [BSIM_EVENT_RIGHT] = 02,
        [BSIM_EVENT_SIDE_EXIT] = 010, [BSIM_EVENT_STUCK] = 020, [BSIM_EVENT_UNSTABLE] = 040};
static const bsim_event family_order[BSIM_N_EVENTS] = {BSIM_EVENT_UNSTABLE,  BSIM_EVENT_LEFT,
                                                       BSIM_EVENT_RIGHT,     BSIM_EVENT_SIDE_EXIT,
                                                       BSIM_EVENT_TRAVERSED, BSIM_EVENT_STUCK};

/* Reduces v against the rows taken (each with its pivot column) and adds
 * it as a row if anything is left: Gaussian elimination on 0/1 vectors of
 * at most 6 cells, exact in doubles. 1 if v was independent. */
static int basis_add(double rows[][N_CELLS], int *pivot, int *n_rows, double v[N_CELLS])
{
	for (int r = 0; r < *n_rows; r++) {
		double f = v[pivot[r]] / rows[r][pivot[r]];
		for (int c = 0; c < N_CELLS; c++)
			v[c] -= f * rows[r][c];
	}
	for (int c = 0; c < N_CELLS; c++)
		if (fabs(v[c]) > 1e-9) {
			memcpy(rows[*n_rows], v, sizeof rows[0]);
			pivot[(*n_rows)++] = c;
			return 1;
		}
	return 0;
}

unsigned bsim_compare_family(unsigned cells)
{
	double rows[N_CELLS + 1][N_CELLS], v[N_CELLS];
	int pivot[N_CELLS + 1], n_rows = 0;
	unsigned family = 0;
	/* The constant 1 first: an event that occurs in every trial (or in
	 * none) says nothing. */
	for (int c = 0; c < N_CELLS; c++)
		v[c] = cells >> c & 1u;
	basis_add(rows, pivot, &n_rows, v);
	for (int i = 0; i < BSIM_N_EVENTS; i++) {
		bsim_event e = family_order[i];
		for (int c = 0; c < N_CELLS; c++)
			v[c] = (cells & event_cells[e]) >> c & 1u;
		if (basis_add(rows, pivot, &n_rows, v))
			family |= 1u << e;
	}
	return family;
}

/* The cells occurring in n pairs, on either side. */
static unsigned cells_of(const bsim_trial_result *a, const bsim_trial_result *b, int n)
{
	unsigned cells = 0;
	for (int i = 0; i < n; i++)
		cells |= 1u << cell_of(&a[i]) | 1u << cell_of(&b[i]);
	return cells;
}

/* ---- the final-location permutation test ------------------------------- */

static int location_sort_cmp(const void *x, const void *y)
{
	const bsim_location *a = x, *b = y;
	if (a->kind != b->kind)
		return a->kind < b->kind ? -1 : 1;
	if (a->iy != b->iy)
		return a->iy < b->iy ? -1 : 1;
	return (a->ix > b->ix) - (a->ix < b->ix);
}

/* The category of loc among the sorted distinct locs[0..m). */
static int location_index(const bsim_location *locs, int m, bsim_location loc)
{
	int lo = 0, hi = m - 1;
	while (lo <= hi) {
		int mid = (lo + hi) / 2, c = location_sort_cmp(&locs[mid], &loc);
		if (c == 0)
			return mid;
		if (c < 0)
			lo = mid + 1;
		else
			hi = mid - 1;
	}
	return -1;
}

/* The swap of discordant pair k (categories ca -> A, cb -> B) changes
 * diff = count_A - count_B by -2 at ca and +2 at cb, and T by the change of
 * those two terms. */
static long swap_pair(long *diff, int ca, int cb, long t)
{
	t -= labs(diff[ca]) + labs(diff[cb]);
	diff[ca] -= 2;
	diff[cb] += 2;
	return t + labs(diff[ca]) + labs(diff[cb]);
}

void bsim_compare_location_test(const bsim_trial_result *a, const bsim_trial_result *b, int n,
                                uint64_t seed, bsim_location_test *out)
{
	memset(out, 0, sizeof *out);
	out->p_value = out->p_holm = 1.0;
	out->exact = 1;
	bsim_location *locs = malloc((2 * (size_t)n + 1) * sizeof *locs);
	int *ca = malloc(((size_t)n + 1) * sizeof *ca), *cb = malloc(((size_t)n + 1) * sizeof *cb);
	long *diff = calloc(2 * (size_t)n + 1, sizeof *diff);
	long *work = calloc(2 * (size_t)n + 1, sizeof *work);
	if (!locs || !ca || !cb || !diff || !work)
		goto done;
	for (int i = 0; i < n; i++) {
		locs[2 * i] = bsim_lattice_location_of(&a[i]);
		locs[2 * i + 1] = bsim_lattice_location_of(&b[i]);
	}
	qsort(locs, 2 * (size_t)n, sizeof *locs, location_sort_cmp);
	int m = 0;
	for (int i = 0; i < 2 * n; i++)
		if (m == 0 || location_sort_cmp(&locs[m - 1], &locs[i]) != 0)
			locs[m++] = locs[i];
	int d = 0;
	for (int i = 0; i < n; i++) {
		int x = location_index(locs, m, bsim_lattice_location_of(&a[i]));
		int y = location_index(locs, m, bsim_lattice_location_of(&b[i]));
		diff[x]++;
		diff[y]--;
		if (x != y) {
			ca[d] = x;
			cb[d] = y;
			d++;
		}
	}
	long t_obs = 0;
	for (int c = 0; c < m; c++)
		t_obs += labs(diff[c]);
	out->discordant = d;
	out->tv = n > 0 ? 0.5 * (double)t_obs / n : 0.0;
	if (d == 0)
		goto done;
	long ge = 0;
	if (d <= BSIM_LOCATION_EXACT_MAX) {
		/* every subset of swaps, in Gray-code order: one swap per step */
		memcpy(work, diff, (size_t)m * sizeof *work);
		long t = t_obs, total = 1L << d;
		ge = 1; /* the identity */
		for (long k = 1; k < total; k++) {
			/* Gray code g(k) = k ^ (k >> 1) differs from g(k - 1) in
			 * bit j = ctz(k); the pair is swapped in g(k) when bit
			 * j + 1 of k is 0, and swapped back otherwise. */
			int j = __builtin_ctzl((unsigned long)k);
			int swapped = ((k >> (j + 1)) & 1) == 0;
			t = swapped ? swap_pair(work, ca[j], cb[j], t)
			            : swap_pair(work, cb[j], ca[j], t);
			ge += t >= t_obs;
		}
		out->p_value = (double)ge / (double)total;
		out->resamples = total;
	} else {
		gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
		if (!rng)
			goto done;
		gsl_rng_set(rng, (unsigned long)(seed ? seed : 1));
		for (long r = 0; r < BSIM_LOCATION_RESAMPLES; r++) {
			memcpy(work, diff, (size_t)m * sizeof *work);
			long t = t_obs;
			for (int k = 0; k < d; k++)
				if (gsl_rng_get(rng) & 1)
					t = swap_pair(work, ca[k], cb[k], t);
			ge += t >= t_obs;
		}
		gsl_rng_free(rng);
		out->exact = 0;
		out->resamples = BSIM_LOCATION_RESAMPLES;
		out->p_value = (1.0 + (double)ge) / (1.0 + BSIM_LOCATION_RESAMPLES);
	}
	out->p_holm = out->p_value;
done:
	free(locs);
	free(ca);
	free(cb);
	free(diff);
	free(work);
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

static void group_verdict(bsim_compare_group *g, const bsim_compare_rule *rule, int lattice)
{
	if (g->deterministic) {
		g->verdict = rule->exact && g->changed > 0 ? BSIM_VERDICT_DISAGREE
		             : g->discordant > 0           ? BSIM_VERDICT_DIFFERENT
		                                           : BSIM_VERDICT_SAME;
		return;
	}
	int significant = 0, beyond = 0, equivalent = 1, informative = 0;
	for (int e = 0; e < BSIM_N_EVENTS; e++) {
		bsim_event_test *t = &g->ev[e];
		int sig = t->in_family && t->p_holm < rule->alpha;
		t->beyond = sig && fabs(t->diff) >= rule->margin;
		t->equivalent = t->p_equivalence < rule->alpha;
		/* by counts, so that 5 of 100 is within a margin of 0.05 */
		int ka = t->pairs.a + t->pairs.b, kb = t->pairs.a + t->pairs.c, n = g->pairs;
		int floor = n <= 0 ||
		            ((double)ka / n <= rule->margin && (double)kb / n <= rule->margin);
		int ceiling = (double)(n - ka) / n <= rule->margin &&
		              (double)(n - kb) / n <= rule->margin;
		t->informative = !floor && !ceiling;
		significant |= sig;
		beyond |= t->beyond;
		if (t->informative) {
			informative = 1;
			equivalent &= t->equivalent;
		}
	}
	if (lattice) {
		int sig = g->loc.p_holm < rule->alpha;
		g->loc.beyond = sig && g->loc.tv >= rule->margin;
		significant |= sig;
		beyond |= g->loc.beyond;
	}
	if (beyond || (rule->exact && g->changed > 0))
		g->verdict = BSIM_VERDICT_DISAGREE;
	else if (significant)
		g->verdict = BSIM_VERDICT_SMALL;
	else if (!informative)
		g->verdict = BSIM_VERDICT_UNINFORMATIVE;
	else
		g->verdict = equivalent ? BSIM_VERDICT_EQUIVALENT : BSIM_VERDICT_INCONCLUSIVE;
}

/* One pair's tables and tests, before Holm's correction: its family's
 * p-values appended to p at *n_p (in group order, events in enum order,
 * then the final-location test), its separation times' quantiles from
 * buf (n_groups x trials doubles). */
static int pair_tables(const bsim_sweep_result *a, const bsim_sweep_result *b,
                       const double *t_separate, const bsim_compare_rule *rule,
                       bsim_comparison *out, double *p, int *n_p, double *buf, bsim_error *err)
{
	memset(out, 0, sizeof *out);
	if (a->n_groups != b->n_groups || a->trials != b->trials)
		return bsim_error_set(
		        err, BSIM_EINPUT,
		        "cannot pair %d groups x %d trials with %d groups x %d trials", a->n_groups,
		        a->trials, b->n_groups, b->trials);
	int G = a->n_groups, n = a->trials;
	int known = bsim_compare_known(a, b);
	out->n_groups = G;
	out->trials = n;
	out->rule = *rule;
	out->lattice = a->lattice && b->lattice;
	out->groups = calloc(G > 0 ? (size_t)G : 1, sizeof *out->groups);
	if (!out->groups)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory comparing %d groups", G);
	for (int g = 0; g < G; g++) {
		const bsim_trial_result *ra = &a->trials_out[(size_t)g * n];
		const bsim_trial_result *rb = &b->trials_out[(size_t)g * n];
		bsim_compare_group *cg = &out->groups[g];
		cg->deterministic = (a->groups && a->groups[g].deterministic) ||
		                    (b->groups && b->groups[g].deterministic);
		cg->pairs = cg->deterministic && n > 0 ? 1 : n;
		if (!cg->deterministic)
			cg->family = bsim_compare_family(cells_of(ra, rb, cg->pairs));
		for (int e = 0; e < BSIM_N_EVENTS; e++) {
			bsim_event_test *t = &cg->ev[e];
			event_table(ra, rb, cg->pairs, (bsim_event)e, t);
			if (cg->deterministic) {
				event_point(t);
				continue;
			}
			event_stats(t, cg->pairs, rule->margin);
			t->in_family = (cg->family >> e & 1u) != 0;
			t->p_holm = NAN;
			if (t->in_family)
				p[(*n_p)++] = t->p_value;
		}
		if (out->lattice && !cg->deterministic) {
			bsim_compare_location_test(ra, rb, cg->pairs, 0x5eed0000u + (uint64_t)g,
			                           &cg->loc);
			p[(*n_p)++] = cg->loc.p_value;
		}
		for (int i = 0; i < cg->pairs; i++)
			cg->discordant += bsim_compare_discordant(&ra[i], &rb[i]);
		/* Over every trial, copies included: a stored file edited in
		 * any row is a change. */
		for (int i = 0; i < n; i++)
			cg->changed += !bsim_compare_identical(&ra[i], &rb[i], known);
		out->pairs += cg->pairs;
		cg->t_sep[0] = cg->t_sep[1] = cg->t_sep[2] = -1.0;
		if (t_separate) {
			cg->separated = separated_times(&t_separate[(size_t)g * n], cg->pairs, buf);
			quantiles(buf, cg->separated, cg->t_sep);
		}
	}
	out->t_sep[0] = out->t_sep[1] = out->t_sep[2] = -1.0;
	if (t_separate) {
		int n_sep = 0;
		for (int g = 0; g < G; g++)
			n_sep += separated_times(&t_separate[(size_t)g * n], out->groups[g].pairs,
			                         buf + n_sep);
		out->separated = n_sep;
		quantiles(buf, n_sep, out->t_sep);
	}
	return BSIM_OK;
}

/* One pair's tests after Holm's correction over the whole family of
 * n_tests tests: p_holm its adjusted p-values in pair_tables' order,
 * splits the exact McNemar test's at the family's level; the verdicts. */
static void pair_finish(bsim_comparison *out, const double *p_holm, int n_tests, const int *splits)
{
	const bsim_compare_rule *rule = &out->rule;
	out->n_tests = n_tests;
	for (int g = 0, k = 0; g < out->n_groups; g++) {
		bsim_compare_group *cg = &out->groups[g];
		for (int e = 0; !cg->deterministic && e < BSIM_N_EVENTS; e++) {
			bsim_event_test *t = &cg->ev[e];
			if (t->in_family)
				t->p_holm = p_holm[k++];
			double psi =
			        cg->pairs > 0 ? (double)(t->pairs.b + t->pairs.c) / cg->pairs : 0.0;
			t->mde80 = bsim_stats_mcnemar_mde(cg->pairs, splits, psi, 0.8);
			t->min_significant = event_min_significant(t, cg->pairs, splits);
		}
		if (out->lattice && !cg->deterministic)
			cg->loc.p_holm = p_holm[k++];
		group_verdict(cg, rule, out->lattice && !cg->deterministic);
		out->count[cg->verdict]++;
		out->n_disagree += cg->verdict == BSIM_VERDICT_DISAGREE ||
		                   cg->verdict == BSIM_VERDICT_DIFFERENT;
	}
}

int bsim_compare_odd_one_out(int n_sides, const int *differ)
{
	int any = 0, odd = -1, n_odd = 0;
	const int n_pairs = bsim_sweep_pairs(n_sides);
	for (int k = 0; k < n_pairs; k++)
		any |= differ[k] != 0;
	if (!any)
		return BSIM_ODD_NONE;
	for (int s = 0; s < n_sides; s++) {
		int ok = 1;
		for (int k = 0; ok && k < n_pairs; k++) {
			int side[2];
			bsim_sweep_pair(n_sides, k, side);
			int with_s = side[0] == s || side[1] == s;
			/* every pair with s differs, no pair of the others does */
			ok = with_s ? differ[k] != 0 : differ[k] == 0;
		}
		if (ok) {
			odd = s;
			n_odd++;
		}
	}
	return n_odd == 1 ? odd : BSIM_ODD_NO_SINGLE;
}

static int disagrees(bsim_verdict v)
{
	return v == BSIM_VERDICT_DISAGREE || v == BSIM_VERDICT_DIFFERENT;
}

int bsim_compare_analyse_sides(const bsim_sweep_result *side, int n_sides, const double *t_separate,
                               const bsim_compare_rule *rule, bsim_compare_sides *out,
                               bsim_error *err)
{
	memset(out, 0, sizeof *out);
	if (n_sides < 2 || n_sides > BSIM_COMPARE_SIDES_MAX)
		return bsim_error_set(err, BSIM_EINPUT, "%d sides: expected 2 to %d", n_sides,
		                      BSIM_COMPARE_SIDES_MAX);
	int G = side[0].n_groups, n = side[0].trials;
	for (int s = 1; s < n_sides; s++)
		if (side[s].n_groups != G || side[s].trials != n)
			return bsim_error_set(
			        err, BSIM_EINPUT,
			        "cannot pair %d groups x %d trials with %d groups x %d "
			        "trials",
			        G, n, side[s].n_groups, side[s].trials);
	long total = (long)G * n;
	out->n_sides = n_sides;
	out->n_pairs = bsim_sweep_pairs(n_sides);
	out->n_groups = G;
	out->trials = n;
	const size_t per_pair = (size_t)(G > 0 ? G : 1) * (BSIM_N_EVENTS + 1);
	double *p = calloc((size_t)out->n_pairs * per_pair, sizeof *p);
	double *buf = malloc((size_t)(total > 0 ? total : 1) * sizeof *buf);
	int *splits = malloc(((size_t)(n > 0 ? n : 0) + 1) * sizeof *splits);
	int *first = calloc((size_t)out->n_pairs + 1, sizeof *first);
	out->verdict = calloc(G > 0 ? (size_t)G : 1, sizeof *out->verdict);
	out->odd = calloc(G > 0 ? (size_t)G : 1, sizeof *out->odd);
	int rc = !p || !buf || !splits || !first || !out->verdict || !out->odd
	                 ? bsim_error_set(err, BSIM_EFAIL, "out of memory comparing %d groups", G)
	                 : BSIM_OK;
	/* Every pair's tests, then Holm over all of them: one family. */
	for (int k = 0; rc == BSIM_OK && k < out->n_pairs; k++) {
		bsim_sweep_pair(n_sides, k, out->pair[k]);
		first[k] = out->n_tests;
		rc = pair_tables(&side[out->pair[k][0]], &side[out->pair[k][1]],
		                 t_separate ? t_separate + (size_t)k * (size_t)total : NULL, rule,
		                 &out->pairs[k], p, &out->n_tests, buf, err);
	}
	if (rc == BSIM_OK) {
		bsim_stats_holm(p, out->n_tests, p);
		double level = out->n_tests > 0 ? rule->alpha / out->n_tests : rule->alpha;
		bsim_stats_mcnemar_splits(n, level, splits);
		for (int k = 0; k < out->n_pairs; k++)
			pair_finish(&out->pairs[k], p + first[k], out->n_tests, splits);
	}
	/* Each group's verdict is its least agreeing pair's. */
	for (int g = 0; rc == BSIM_OK && g < G; g++) {
		int differ[BSIM_SWEEP_PAIRS_MAX];
		bsim_verdict v = BSIM_VERDICT_SAME;
		for (int k = 0; k < out->n_pairs; k++) {
			bsim_verdict w = out->pairs[k].groups[g].verdict;
			v = w > v ? w : v;
			differ[k] = disagrees(w);
		}
		out->verdict[g] = v;
		out->count[v]++;
		out->n_disagree += disagrees(v);
		out->odd[g] = bsim_compare_odd_one_out(n_sides, differ);
	}
	free(p);
	free(buf);
	free(splits);
	free(first);
	if (rc != BSIM_OK)
		bsim_compare_sides_free(out);
	return rc;
}

void bsim_compare_sides_free(bsim_compare_sides *c)
{
	if (!c)
		return;
	for (int k = 0; k < c->n_pairs; k++)
		bsim_compare_free(&c->pairs[k]);
	free(c->verdict);
	free(c->odd);
	memset(c, 0, sizeof *c);
}

int bsim_compare_analyse(const bsim_sweep_result *a, const bsim_sweep_result *b,
                         const double *t_separate, const bsim_compare_rule *rule,
                         bsim_comparison *out, bsim_error *err)
{
	memset(out, 0, sizeof *out);
	bsim_sweep_result side[2] = {*a, *b};
	bsim_compare_sides s;
	int rc = bsim_compare_analyse_sides(side, 2, t_separate, rule, &s, err);
	if (rc != BSIM_OK)
		return rc;
	/* The one pair's comparison is the result: taken from s. */
	*out = s.pairs[0];
	memset(&s.pairs[0], 0, sizeof s.pairs[0]);
	bsim_compare_sides_free(&s);
	return BSIM_OK;
}

void bsim_compare_free(bsim_comparison *c)
{
	if (!c)
		return;
	free(c->groups);
	memset(c, 0, sizeof *c);
}
