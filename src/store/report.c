/* The comparison report (beamsim/report.h).
 *
 * Every number in report.md is also in report.json; the Markdown rounds
 * for reading, the JSON keeps full precision. Replay lines name the scene,
 * the backend with the options given, the seed, group and trial, and every
 * override in the order the experiment applied it (set:, --set, grid), so
 * `beamsim run` rebuilds exactly the scene and schedule of that trial. */
#define _POSIX_C_SOURCE 200809L

#include "beamsim/report.h"

#include <inttypes.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "util/json.h"
#include "beamsim/lattice.h"
#include "beamsim/output.h"
#include "beamsim/lattice_outcome.h"
#include "beamsim/trial_fields.h"
#include "util/text_check.h"

static void set_word(FILE *f, const char *key, const char *value)
{
	char buf[1200];
	snprintf(buf, sizeof buf, "%s=%s", key, value);
	fputs(" --set ", f);
	bsim_text_shell_word(f, buf);
}

static void replay_line(FILE *f, const bsim_report *r, int side, int g, int t)
{
	const bsim_experiment *e = r->e;
	const bsim_report_side *s = &r->side[side];
	int idx[BSIM_OUTPUT_AXES_MAX] = {0};
	/* A side read from a file ran elsewhere: the line gives the trial's
	 * scene and schedule, as a comment, with no backend of beamsim's. */
	if (s->read_from) {
		fprintf(f, "# %s: row group %d, trial %d of ", s->label, g, t);
		bsim_text_shell_word(f, s->read_from);
		fputs(", made elsewhere on the scene and schedule of: ", f);
	}
	fputs("beamsim run ", f);
	bsim_text_shell_word(f, e->scene_path);
	if (!s->read_from)
		fprintf(f, " --backend %s", s->backend->name);
	for (int i = 0; s->opts && i < s->opts->n; i++) {
		char buf[128];
		snprintf(buf, sizeof buf, "%s=%s", s->opts->key[i], s->opts->value[i]);
		fputs(" --backend-opt ", f);
		bsim_text_shell_word(f, buf);
	}
	fprintf(f, " --seed %" PRIu64 " --group %d --trial %d", e->seed, g, t);
	for (int i = 0; i < e->n_set; i++)
		set_word(f, e->set[i].key, e->set[i].value);
	for (int i = 0; i < r->n_extra; i++)
		set_word(f, r->extra[i].key, r->extra[i].value);
	for (int i = 0; side == 1 && i < r->n_extra_b; i++)
		set_word(f, r->extra_b[i].key, r->extra_b[i].value);
	if (e->n_axes <= BSIM_OUTPUT_AXES_MAX)
		bsim_experiment_group_index(e, g, idx);
	for (int a = 0; a < e->n_axes && a < BSIM_OUTPUT_AXES_MAX; a++)
		set_word(f, e->axes[a].key, e->axes[a].values[idx[a]]);
}

static const bsim_trial_result *trial_of(const bsim_report *r, int side, int g, int t)
{
	const bsim_sweep_result *run = r->side[side].run;
	return &run->trials_out[(size_t)g * run->trials + t];
}

/* "traversed (left) at 3.24 s"; on a lattice "... at 3.24 s, end:-2" */
static void outcome_text(FILE *f, const bsim_report *r, const bsim_trial_result *x)
{
	fputs(bsim_trial_outcome_name(x->outcome), f);
	if (x->outcome == BSIM_TRAVERSED)
		fprintf(f, " (%s)", bsim_trial_type_name(x->type));
	fprintf(f, " at %.3f s", x->t_end);
	if (r->cmp->lattice) {
		char label[48];
		bsim_lattice_location_label(bsim_lattice_location_of(x), label, sizeof label);
		fprintf(f, ", %s", label);
	}
}

static void params_text(FILE *f, const bsim_experiment *e, int g)
{
	int idx[BSIM_OUTPUT_AXES_MAX] = {0};
	if (e->n_axes <= BSIM_OUTPUT_AXES_MAX)
		bsim_experiment_group_index(e, g, idx);
	for (int a = 0; a < e->n_axes && a < BSIM_OUTPUT_AXES_MAX; a++)
		fprintf(f, "%s%s = %s", a ? ", " : "", e->axes[a].key, e->axes[a].values[idx[a]]);
}

/* The event of the family with the smallest adjusted p-value: what a row
 * shows; -1 if the family has none of the group's events. */
static int key_event(const bsim_compare_group *cg)
{
	int k = -1;
	for (int ev = 0; ev < BSIM_N_EVENTS; ev++)
		if (cg->ev[ev].in_family && (k < 0 || cg->ev[ev].p_holm < cg->ev[k].p_holm))
			k = ev;
	return k;
}

static void md_separation(FILE *f, const bsim_report *r)
{
	const bsim_comparison *c = r->cmp;
	long pairs = c->pairs;
	if (!r->t_separate)
		return;
	fprintf(f,
	        "Paired trajectories (same scene, same random-force schedule) separated by more "
	        "than 1%% of the body radius in %d of %ld pairs",
	        c->separated, pairs);
	if (c->separated > 0)
		fprintf(f, "; separation time quantiles 10%% / 50%% / 90%%: %.3f / %.3f / %.3f s",
		        c->t_sep[0], c->t_sep[1], c->t_sep[2]);
	fputs(". Per pair: pairs.csv.\n\n", f);
}

/* One event's paired tables of the groups with random force, summed: under
 * "no difference in any group" every discordant pair is still equally
 * likely to go either way, so McNemar's test and Tango's interval apply to
 * the sum. 0 if no group has random force. */
static int pooled(const bsim_comparison *c, int ev, bsim_pairs *t, double ci[2], double *p)
{
	int groups = 0;
	*t = (bsim_pairs){0, 0, 0, 0};
	for (int g = 0; g < c->n_groups; g++) {
		const bsim_compare_group *cg = &c->groups[g];
		if (cg->deterministic)
			continue;
		groups++;
		t->a += cg->ev[ev].pairs.a;
		t->b += cg->ev[ev].pairs.b;
		t->c += cg->ev[ev].pairs.c;
		t->d += cg->ev[ev].pairs.d;
	}
	bsim_stats_tango_ci(t, BSIM_STATS_Z95, &ci[0], &ci[1]);
	*p = bsim_stats_mcnemar_exact(t->b, t->c);
	return groups;
}

static void md_pooled(FILE *f, const bsim_report *r)
{
	const bsim_comparison *c = r->cmp;
	bsim_pairs t;
	double ci[2], p;
	int groups = pooled(c, 0, &t, ci, &p);
	if (groups == 0)
		return;
	fprintf(f,
	        "Pooled over the %d group%s with random force (%d pairs; outside the rule, which "
	        "is group by group):\n\n| event | only %s | only %s | difference [95%%] | "
	        "McNemar p |\n|---|---|---|---|---|\n",
	        groups, groups == 1 ? "" : "s", t.a + t.b + t.c + t.d, r->side[0].label,
	        r->side[1].label);
	for (int ev = 0; ev < BSIM_N_EVENTS; ev++) {
		pooled(c, ev, &t, ci, &p);
		int n = t.a + t.b + t.c + t.d;
		fprintf(f, "| %s | %d | %d | %+.4f [%+.4f, %+.4f] | %.2g |\n",
		        bsim_compare_event_name((bsim_event)ev), t.b, t.c,
		        n > 0 ? (double)(t.b - t.c) / n : 0.0, ci[0], ci[1], p);
	}
	fputc('\n', f);
}

/* "traversed (none)" for a deterministic group's one trial. */
static void outcome_short(FILE *f, const bsim_trial_result *x)
{
	fputs(bsim_trial_outcome_name(x->outcome), f);
	if (x->outcome == BSIM_TRAVERSED)
		fprintf(f, " (%s)", bsim_trial_type_name(x->type));
}

/* The largest equivalence p-value over the events: the group's, since it
 * is equivalent only if every event is. */
static double group_equivalence(const bsim_compare_group *cg)
{
	double p = 0.0;
	for (int ev = 0; ev < BSIM_N_EVENTS; ev++)
		p = fmax(p, cg->ev[ev].p_equivalence);
	return p;
}

static void md_number(FILE *f, const char *fmt, double x)
{
	if (isnan(x))
		fputs(" - |", f);
	else
		fprintf(f, fmt, x);
}

static void md_row_random(FILE *f, const bsim_compare_group *cg)
{
	const bsim_event_test *t = &cg->ev[BSIM_EVENT_TRAVERSED];
	int k = key_event(cg);
	fprintf(f, " %.2f [%.2f, %.2f] | %.2f [%.2f, %.2f] | %+.2f [%+.2f, %+.2f] | %d of %d |",
	        t->p_a, t->ci_a[0], t->ci_a[1], t->p_b, t->ci_b[0], t->ci_b[1], t->diff,
	        t->diff_ci[0], t->diff_ci[1], cg->discordant, cg->pairs);
	if (k >= 0)
		fprintf(f, " %.2g, %s |", cg->ev[k].p_holm, bsim_compare_event_name((bsim_event)k));
	else
		fputs(" - (no event varies) |", f);
	fprintf(f, " %.2g |", group_equivalence(cg));
	md_number(f, " %.2f |", t->mde80);
}

static void md_row_deterministic(FILE *f, const bsim_report *r, int g, const bsim_compare_group *cg)
{
	fputc(' ', f);
	outcome_short(f, trial_of(r, 0, g, 0));
	fputs(" | ", f);
	outcome_short(f, trial_of(r, 1, g, 0));
	fprintf(f, " | deterministic | %d of 1 | - | - | - |", cg->discordant);
}

/* A group row's last two cells: the median separation time (or -) and the
 * verdict, in the two-side and the many-side tables alike. */
static void md_row_end(FILE *f, const bsim_compare_group *cg)
{
	if (cg->t_sep[1] >= 0.0)
		fprintf(f, " %.3f |", cg->t_sep[1]);
	else
		fputs(" - |", f);
	fprintf(f, " %s |\n", bsim_compare_verdict_name(cg->verdict));
}

static void md_table(FILE *f, const bsim_report *r)
{
	const bsim_experiment *e = r->e;
	const char *la = r->side[0].label, *lb = r->side[1].label;
	fputs("| group |", f);
	for (int a = 0; a < e->n_axes; a++)
		fprintf(f, " %s |", e->axes[a].key);
	fprintf(f,
	        " p_traverse %s [95%%] | p_traverse %s [95%%] | difference [95%%] | discordant "
	        "| min p (Holm), event | equivalence p | mde80 traversed | t_sep median (s) | "
	        "verdict |\n|---|",
	        la, lb);
	for (int a = 0; a < e->n_axes; a++)
		fputs("---|", f);
	fputs("---|---|---|---|---|---|---|---|---|\n", f);
	int idx[BSIM_OUTPUT_AXES_MAX] = {0};
	for (int g = 0; g < r->cmp->n_groups; g++) {
		const bsim_compare_group *cg = &r->cmp->groups[g];
		if (e->n_axes <= BSIM_OUTPUT_AXES_MAX)
			bsim_experiment_group_index(e, g, idx);
		fprintf(f, "| %d |", g);
		for (int a = 0; a < e->n_axes && a < BSIM_OUTPUT_AXES_MAX; a++)
			fprintf(f, " %s |", e->axes[a].values[idx[a]]);
		if (cg->deterministic)
			md_row_deterministic(f, r, g, cg);
		else
			md_row_random(f, cg);
		md_row_end(f, cg);
	}
	fputc('\n', f);
}

static void md_events(FILE *f, const bsim_report *r, const bsim_compare_group *cg)
{
	fprintf(f,
	        "| event | %s | %s | difference [95%%] | only %s | only %s | McNemar p | Holm p "
	        "| equivalence p | informative | mde80 | min significant | beyond "
	        "|\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
	        r->side[0].label, r->side[1].label, r->side[0].label, r->side[1].label);
	for (int ev = 0; ev < BSIM_N_EVENTS; ev++) {
		const bsim_event_test *t = &cg->ev[ev];
		fprintf(f, "| %s | %.2f | %.2f | %+.2f [%+.2f, %+.2f] | %d | %d | %.3g |",
		        bsim_compare_event_name((bsim_event)ev), t->p_a, t->p_b, t->diff,
		        t->diff_ci[0], t->diff_ci[1], t->pairs.b, t->pairs.c, t->p_value);
		if (t->in_family)
			fprintf(f, " %.3g |", t->p_holm);
		else
			fputs(" not in the family |", f);
		fprintf(f, " %.3g | %s |", t->p_equivalence,
		        t->informative ? "yes" : "no (floor or ceiling)");
		md_number(f, " %.2f |", t->mde80);
		md_number(f, " %.2f |", t->min_significant);
		fprintf(f, " %s |\n", t->beyond ? "yes" : "no");
	}
	fputc('\n', f);
}

static void md_examples(FILE *f, const bsim_report *r, int g)
{
	int shown = 0;
	for (int t = 0; t < r->cmp->groups[g].pairs && shown < r->examples; t++) {
		const bsim_trial_result *a = trial_of(r, 0, g, t), *b = trial_of(r, 1, g, t);
		if (!bsim_compare_discordant(a, b))
			continue;
		shown++;
		fprintf(f, "- trial %d: %s ", t, r->side[0].label);
		outcome_text(f, r, a);
		fprintf(f, ", %s ", r->side[1].label);
		outcome_text(f, r, b);
		if (r->t_separate) {
			double ts = r->t_separate[(size_t)g * r->cmp->trials + t];
			if (ts >= 0.0)
				fprintf(f, "; separated at %.3f s", ts);
		}
		fputs("\n\n  ```\n", f);
		for (int s = 0; s < 2; s++) {
			fputs("  ", f);
			replay_line(f, r, s, g, t);
			fputc('\n', f);
		}
		fputs("  ```\n", f);
	}
	fputc('\n', f);
}

static int shows_detail(const bsim_compare_group *cg)
{
	return cg->verdict == BSIM_VERDICT_DISAGREE || cg->verdict == BSIM_VERDICT_DIFFERENT;
}

/* One side's distribution of final locations of group g. */
static int side_locations(const bsim_report *r, int side, int g, bsim_lattice_summary *ls)
{
	const bsim_sweep_result *run = r->side[side].run;
	return bsim_lattice_summarise(&run->trials_out[(size_t)g * run->trials], NULL, run->trials,
	                              run->lattice_def.rows, ls);
}

static const char *location_test_name(const bsim_location_test *t)
{
	return t->exact ? "exact (all swaps)" : "Monte Carlo (20,000 swaps)";
}

/* Both sides' final-location distributions (lattices), group by group, and
 * the paired permutation test of their difference. */
static void md_locations(FILE *f, const bsim_report *r, const char *pair)
{
	const bsim_comparison *c = r->cmp;
	fprintf(f,
	        "## Final locations%s\n\nWhere each trial ended: `end:ix` reached the end through "
	        "column ix, `side:iy` left the field through a side at row iy, `stuck:ix:iy` "
	        "stuck in gate (ix, iy). Test of the difference: a paired permutation test on "
	        "the final locations (the two locations of a discordant pair swapped with "
	        "probability 1/2; statistic: the total variation distance), exact when at "
	        "most %d pairs are discordant, else Monte Carlo; in the Holm family above.\n\n",
	        pair, BSIM_LOCATION_EXACT_MAX);
	for (int g = 0; g < c->n_groups; g++) {
		const bsim_location_test *t = &c->groups[g].loc;
		bsim_lattice_summary ls[2];
		if (c->groups[g].deterministic)
			continue; /* one pair: its locations are in the group's row */
		if (side_locations(r, 0, g, &ls[0]) != BSIM_OK)
			return;
		if (side_locations(r, 1, g, &ls[1]) != BSIM_OK) {
			bsim_lattice_summary_free(&ls[0]);
			return;
		}
		fprintf(f, "### Group %d: ", g);
		params_text(f, r->e, g);
		fprintf(f,
		        "\n\n%d discordant pairs; total variation %.3f; permutation p = %.3g "
		        "(%s), Holm %.3g%s.\n\n| location | %s [95%%] | %s [95%%] "
		        "|\n|---|---|---|\n",
		        t->discordant, t->tv, t->p_value, location_test_name(t), t->p_holm,
		        t->beyond ? ", **beyond the rule**" : "", r->side[0].label,
		        r->side[1].label);
		/* the union of both sides' locations, in the summaries' order */
		int i = 0, j = 0;
		while (i < ls[0].n_locations || j < ls[1].n_locations) {
			const bsim_location_count *x =
			        i < ls[0].n_locations ? &ls[0].locations[i] : NULL;
			const bsim_location_count *y =
			        j < ls[1].n_locations ? &ls[1].locations[j] : NULL;
			char la[48], lb[48];
			if (x)
				bsim_lattice_location_label(x->loc, la, sizeof la);
			if (y)
				bsim_lattice_location_label(y->loc, lb, sizeof lb);
			int order = !x ? 1 : !y ? -1 : 0;
			if (x && y) {
				bsim_location p = x->loc, q = y->loc;
				order = p.kind != q.kind ? (p.kind < q.kind ? -1 : 1)
				        : p.iy != q.iy   ? (p.iy < q.iy ? -1 : 1)
				        : p.ix != q.ix   ? (p.ix < q.ix ? -1 : 1)
				                         : 0;
			}
			const bsim_location_count *show = order <= 0 ? x : y;
			fprintf(f, "| %s |", order <= 0 ? la : lb);
			if (order <= 0)
				fprintf(f, " %.3f [%.3f, %.3f] |", x->p, x->ci95[0], x->ci95[1]);
			else
				fputs(" 0 |", f);
			if (order >= 0)
				fprintf(f, " %.3f [%.3f, %.3f] |\n", y->p, y->ci95[0], y->ci95[1]);
			else
				fputs(" 0 |\n", f);
			(void)show;
			i += order <= 0;
			j += order >= 0;
		}
		fputc('\n', f);
		bsim_lattice_summary_free(&ls[0]);
		bsim_lattice_summary_free(&ls[1]);
	}
}

/* The trials of group g on one side whose solver hit an iteration limit,
 * and those it clamped. */
static void solver_trials(const bsim_report *r, int side, int g, int *limited, int *clamped)
{
	const bsim_sweep_result *run = r->n_sides > 2 ? r->sides[side].run : r->side[side].run;
	*limited = *clamped = 0;
	for (int t = 0; t < run->trials; t++) {
		const bsim_trial_result *x = &run->trials_out[(size_t)g * run->trials + t];
		*limited += x->solver.iteration_limit > 0;
		*clamped += x->solver.clamped > 0;
	}
}

/* The groups with trials whose motion is partly a solver's limit rather
 * than the model's (trials.csv iteration_limits, clamps): their
 * probabilities compare the solvers' give-ups as much as the physics. */
static void md_solver(FILE *f, const bsim_report *r)
{
	int any = 0;
	const int sides = r->n_sides > 2 ? r->n_sides : 2;
	for (int g = 0; g < r->cmp->n_groups; g++) {
		int n[BSIM_COMPARE_SIDES_MAX][2], some = 0;
		for (int s = 0; s < sides; s++) {
			solver_trials(r, s, g, &n[s][0], &n[s][1]);
			some |= n[s][0] || n[s][1];
		}
		if (!some)
			continue;
		if (!any)
			fputs("**Solver limits.** Groups with trials whose motion was partly a "
			      "solver's limit, not the model's (trials.csv iteration_limits, "
			      "clamps):\n\n",
			      f);
		any = 1;
		fprintf(f, "- group %d: ", g);
		for (int s = 0; s < sides; s++)
			fprintf(f, "%s%s %d hit an iteration limit, %d clamped", s ? "; " : "",
			        r->n_sides > 2 ? r->sides[s].label : r->side[s].label, n[s][0],
			        n[s][1]);
		fputs("\n", f);
	}
	if (any)
		fputc('\n', f);
}

/* Equivalent groups whose traversal is at the floor or the ceiling on both
 * sides: equivalent in their other events, not in traversal. */
static int equivalent_untraversed(const bsim_comparison *c)
{
	int k = 0;
	for (int g = 0; g < c->n_groups; g++)
		k += c->groups[g].verdict == BSIM_VERDICT_EQUIVALENT &&
		     !c->groups[g].ev[BSIM_EVENT_TRAVERSED].informative;
	return k;
}

/* The summary sentence: groups by verdict (k), n_disagree of them
 * disagreeing, untraversed the equivalent ones with traversal at the
 * floor or the ceiling on `every` side. */
static void md_counts(FILE *f, const bsim_comparison *c, int n_disagree, const int *k,
                      int untraversed, const char *every)
{
	int det = k[BSIM_VERDICT_SAME] + k[BSIM_VERDICT_DIFFERENT];
	fprintf(f,
	        "**%d of %d groups disagree.** %d deterministic (no random force: one trial each, "
	        "compared as one pair): %d same, %d different. %d with random force, %d trials "
	        "each: %d equivalent within +-%g (%d of them with p_traverse at the floor or the "
	        "ceiling on %s: equivalent in their other events, not in traversal), %d "
	        "uninformative (every event at the floor or the ceiling), %d inconclusive (no "
	        "difference detected, none excluded), %d significantly different but within the "
	        "margin, %d disagree.\n\n",
	        n_disagree, c->n_groups, det, k[BSIM_VERDICT_SAME], k[BSIM_VERDICT_DIFFERENT],
	        c->n_groups - det, c->trials, k[BSIM_VERDICT_EQUIVALENT], c->rule.margin,
	        untraversed, every, k[BSIM_VERDICT_UNINFORMATIVE], k[BSIM_VERDICT_INCONCLUSIVE],
	        k[BSIM_VERDICT_SMALL], k[BSIM_VERDICT_DISAGREE]);
}

/* The rule, as it applies to each pair of sides; c->n_tests is the Holm
 * family's size. */
static void md_rule(FILE *f, const bsim_comparison *c)
{
	fprintf(f,
	        "Rule: a group with random force disagrees when, for one of its events in the "
	        "family, the exact McNemar test on the paired trials gives a p-value below %g "
	        "after Holm's correction over the family's %d tests, and the two probabilities "
	        "differ by at least %g. The family holds each group's events (traversed, left, "
	        "right, side_exit, stuck, unstable) whose hypotheses the others do not imply: not "
	        "an event that occurs on neither side, not the outcome that is the complement of "
	        "the others, and not traversed when it is left + right (the components are "
	        "kept). An event is informative unless both probabilities lie within %g of 0 or "
	        "both within %g of 1. A group is equivalent when at least one event is "
	        "informative and, for every informative event, Tango's two one-sided score tests "
	        "put the paired difference within +-%g at level %g (equivalence p below it); "
	        "uninformative when no event is; otherwise inconclusive. `mde80` is the difference "
	        "the McNemar test at level %g / %d detects with power 0.8 at the event's observed "
	        "rate of discordant pairs (exact power; with the rate taken as the difference "
	        "where it is smaller); `min significant`, a bound and not a power, the smallest "
	        "difference significant at that level with the event's number of discordant "
	        "pairs. A deterministic group disagrees when its one pair differs in outcome or "
	        "type. Intervals: Wilson for each probability, Tango's score interval for the "
	        "paired difference",
	        c->rule.alpha, c->n_tests, c->rule.margin, c->rule.margin, c->rule.margin,
	        c->rule.margin, c->rule.alpha, c->rule.alpha, c->n_tests > 0 ? c->n_tests : 1);
	fputs(c->rule.exact ? "; any trial that differs in any trials.csv field also disagrees.\n\n"
	                    : ".\n\n",
	      f);
	if (c->lattice)
		fputs("On a lattice a group with random force also disagrees when its "
		      "final-location "
		      "test (in the Holm family above) has a p-value below alpha and the total "
		      "variation distance between the two distributions is at least the margin "
		      "(section Final locations).\n\n",
		      f);
}

static void md_sides(FILE *f, const bsim_report *r);

void bsim_report_md(FILE *f, const bsim_report *r)
{
	const bsim_comparison *c = r->cmp;
	if (r->n_sides > 2) {
		md_sides(f, r);
		return;
	}
	md_counts(f, c, c->n_disagree, c->count, equivalent_untraversed(c), "both sides");
	md_rule(f, c);
	md_separation(f, r);
	md_pooled(f, r);
	md_table(f, r);
	md_solver(f, r);
	if (c->lattice)
		md_locations(f, r, "");
	for (int g = 0; g < c->n_groups; g++) {
		const bsim_compare_group *cg = &c->groups[g];
		if (!shows_detail(cg))
			continue;
		fprintf(f, "### Group %d: ", g);
		params_text(f, r->e, g);
		fprintf(f, "\n\n%d of %d pairs discordant, %d changed in any field.\n\n",
		        cg->discordant, cg->pairs, cg->changed);
		if (!cg->deterministic)
			md_events(f, r, cg);
		md_examples(f, r, g);
	}
}

/* ---- more than two sides ------------------------------------------------ */

/* Pair k of a comparison of more than two sides as a report of two sides:
 * its sides, its comparison and its separation times. */
static bsim_report pair_view(const bsim_report *r, int k)
{
	const bsim_compare_sides *all = r->all;
	bsim_report v = *r;
	v.n_sides = 0;
	v.sides = NULL;
	v.all = NULL;
	v.extra_b = NULL; /* --protocols has two sides */
	v.n_extra_b = 0;
	v.side[0] = r->sides[all->pair[k][0]];
	v.side[1] = r->sides[all->pair[k][1]];
	v.cmp = &all->pairs[k];
	v.t_separate = r->t_separate ? r->t_separate + (size_t)k * (size_t)all->n_groups *
	                                                       (size_t)all->trials
	                             : NULL;
	return v;
}

/* A side's label, "none" or "no single side": a group's odd one out. */
static const char *odd_text(const bsim_report *r, int odd)
{
	return odd >= 0 ? r->sides[odd].label : odd == BSIM_ODD_NONE ? "none" : "no single side";
}

/* Equivalent groups (every pair equivalent) whose traversal is at the
 * floor or the ceiling in every pair. */
static int equivalent_untraversed_all(const bsim_compare_sides *all)
{
	int k = 0;
	for (int g = 0; g < all->n_groups; g++) {
		int untraversed = all->verdict[g] == BSIM_VERDICT_EQUIVALENT;
		for (int p = 0; untraversed && p < all->n_pairs; p++)
			untraversed = !all->pairs[p].groups[g].ev[BSIM_EVENT_TRAVERSED].informative;
		k += untraversed;
	}
	return k;
}

static void md_sides_table(FILE *f, const bsim_report *r)
{
	const bsim_experiment *e = r->e;
	const bsim_compare_sides *all = r->all;
	fputs("## Sides\n\nEach side's p_traverse (Wilson 95%; a deterministic group's one "
	      "trial), the group's verdict (its least agreeing pair's) and its odd one out.\n\n"
	      "| group |",
	      f);
	for (int a = 0; a < e->n_axes; a++)
		fprintf(f, " %s |", e->axes[a].key);
	for (int s = 0; s < r->n_sides; s++)
		fprintf(f, " p_traverse %s [95%%] |", r->sides[s].label);
	fputs(" verdict | odd one out |\n|---|", f);
	for (int a = 0; a < e->n_axes + r->n_sides + 2; a++)
		fputs("---|", f);
	fputc('\n', f);
	int idx[BSIM_OUTPUT_AXES_MAX] = {0};
	for (int g = 0; g < all->n_groups; g++) {
		if (e->n_axes <= BSIM_OUTPUT_AXES_MAX)
			bsim_experiment_group_index(e, g, idx);
		fprintf(f, "| %d |", g);
		for (int a = 0; a < e->n_axes && a < BSIM_OUTPUT_AXES_MAX; a++)
			fprintf(f, " %s |", e->axes[a].values[idx[a]]);
		for (int s = 0; s < r->n_sides; s++) {
			const bsim_group_result *gr = &r->sides[s].run->groups[g];
			fprintf(f, " %.2f [%.2f, %.2f] |", gr->p_traverse, gr->ci95[0],
			        gr->ci95[1]);
		}
		fprintf(f, " %s | %s |\n", bsim_compare_verdict_name(all->verdict[g]),
		        odd_text(r, all->odd[g]));
	}
	fputc('\n', f);
}

static void md_pairs_table(FILE *f, const bsim_report *r)
{
	const bsim_experiment *e = r->e;
	const bsim_compare_sides *all = r->all;
	fputs("## Pairs\n\nEvery pair of sides, group by group, as a comparison of two sides: "
	      "p_A - p_B of traversal (Tango's 95%), the discordant pairs of trials, the "
	      "family's smallest Holm p and its event, the equivalence p, the traversal's "
	      "mde80, the median separation time and the pair's verdict.\n\n| group |",
	      f);
	for (int a = 0; a < e->n_axes; a++)
		fprintf(f, " %s |", e->axes[a].key);
	fputs(" A | B | difference [95%] | discordant | min p (Holm), event | equivalence p | "
	      "mde80 traversed | t_sep median (s) | verdict |\n|---|",
	      f);
	for (int a = 0; a < e->n_axes + 9; a++)
		fputs("---|", f);
	fputc('\n', f);
	int idx[BSIM_OUTPUT_AXES_MAX] = {0};
	for (int g = 0; g < all->n_groups; g++) {
		if (e->n_axes <= BSIM_OUTPUT_AXES_MAX)
			bsim_experiment_group_index(e, g, idx);
		for (int k = 0; k < all->n_pairs; k++) {
			const bsim_compare_group *cg = &all->pairs[k].groups[g];
			const bsim_event_test *t = &cg->ev[BSIM_EVENT_TRAVERSED];
			fprintf(f, "| %d |", g);
			for (int a = 0; a < e->n_axes && a < BSIM_OUTPUT_AXES_MAX; a++)
				fprintf(f, " %s |", e->axes[a].values[idx[a]]);
			fprintf(f, " %s | %s | %+.2f [%+.2f, %+.2f] | %d of %d |",
			        r->sides[all->pair[k][0]].label, r->sides[all->pair[k][1]].label,
			        t->diff, t->diff_ci[0], t->diff_ci[1], cg->discordant, cg->pairs);
			int ev = key_event(cg);
			if (cg->deterministic)
				fputs(" deterministic | - | - |", f);
			else if (ev >= 0)
				fprintf(f, " %.2g, %s | %.2g |", cg->ev[ev].p_holm,
				        bsim_compare_event_name((bsim_event)ev),
				        group_equivalence(cg));
			else
				fprintf(f, " - (no event varies) | %.2g |", group_equivalence(cg));
			if (!cg->deterministic)
				md_number(f, " %.2f |", t->mde80);
			md_row_end(f, cg);
		}
	}
	fputc('\n', f);
}

static void md_sides(FILE *f, const bsim_report *r)
{
	const bsim_compare_sides *all = r->all;
	const bsim_comparison *c = &all->pairs[0];
	md_counts(f, c, all->n_disagree, all->count, equivalent_untraversed_all(all), "every side");
	md_rule(f, c);
	fprintf(f,
	        "With %d sides every pair of sides (%d pairs) is compared so, and the Holm family "
	        "holds every pair's tests: %d tests. A group disagrees when any of its pairs "
	        "does; its verdict is its least agreeing pair's (in the order same, equivalent, "
	        "uninformative, inconclusive, small, DISAGREE, DIFFERENT). The odd one out of a "
	        "group is the side whose every pair with another side disagrees while no pair "
	        "of the other sides does: the disagreement is that side's. `none`: no pair "
	        "disagrees; `no single side`: pairs disagree, but not so (two sides against the "
	        "rest, or others that disagree among themselves).\n\n",
	        all->n_sides, all->n_pairs, all->n_tests);
	int none = 0, unattributed = 0;
	for (int g = 0; g < all->n_groups; g++) {
		none += all->odd[g] == BSIM_ODD_NONE;
		unattributed += all->odd[g] == BSIM_ODD_NO_SINGLE;
	}
	fputs("**Odd one out:**", f);
	for (int s = 0; s < all->n_sides; s++) {
		int n = 0;
		for (int g = 0; g < all->n_groups; g++)
			n += all->odd[g] == s;
		fprintf(f, " %s in %d group%s;", r->sides[s].label, n, n == 1 ? "" : "s");
	}
	fprintf(f, " no single side in %d; none in %d.\n\n", unattributed, none);
	for (int k = 0; k < all->n_pairs; k++) {
		bsim_report v = pair_view(r, k);
		if (!v.t_separate)
			break;
		fprintf(f, "%s vs %s: ", v.side[0].label, v.side[1].label);
		md_separation(f, &v);
	}
	md_sides_table(f, r);
	md_pairs_table(f, r);
	for (int k = 0; k < all->n_pairs; k++) {
		bsim_report v = pair_view(r, k);
		bsim_pairs t;
		double ci[2], p;
		if (pooled(v.cmp, 0, &t, ci, &p) == 0)
			break; /* no group with random force */
		fprintf(f, "### Pooled: %s vs %s\n\n", v.side[0].label, v.side[1].label);
		md_pooled(f, &v);
	}
	md_solver(f, r);
	for (int k = 0; c->lattice && k < all->n_pairs; k++) {
		bsim_report v = pair_view(r, k);
		char title[300];
		snprintf(title, sizeof title, ": %s vs %s", v.side[0].label, v.side[1].label);
		md_locations(f, &v, title);
	}
	for (int g = 0; g < all->n_groups; g++) {
		if (all->verdict[g] != BSIM_VERDICT_DISAGREE &&
		    all->verdict[g] != BSIM_VERDICT_DIFFERENT)
			continue;
		fprintf(f, "### Group %d: ", g);
		params_text(f, r->e, g);
		fprintf(f, "\n\nOdd one out: %s.\n\n", odd_text(r, all->odd[g]));
		for (int k = 0; k < all->n_pairs; k++) {
			bsim_report v = pair_view(r, k);
			const bsim_compare_group *cg = &v.cmp->groups[g];
			if (!shows_detail(cg))
				continue;
			fprintf(f,
			        "#### %s vs %s\n\n%d of %d pairs discordant, %d changed in any "
			        "field.\n\n",
			        v.side[0].label, v.side[1].label, cg->discordant, cg->pairs,
			        cg->changed);
			if (!cg->deterministic)
				md_events(f, &v, cg);
			md_examples(f, &v, g);
		}
	}
}

/* ---- report.json ---------------------------------------------------------- */

static void json_quantiles(FILE *f, const double q[3])
{
	if (q[0] < 0.0) {
		fputs("null", f);
		return;
	}
	fputc('[', f);
	for (int k = 0; k < 3; k++) {
		fputs(k ? ", " : "", f);
		bsim_json_number(f, q[k]);
	}
	fputc(']', f);
}

static void json_event(FILE *f, const bsim_event_test *t, int deterministic)
{
	fputs("{\"p_a\": ", f);
	bsim_json_number(f, t->p_a);
	if (!deterministic) {
		fputs(", \"ci95_a\": ", f);
		bsim_json_pair(f, t->ci_a);
	}
	fputs(", \"p_b\": ", f);
	bsim_json_number(f, t->p_b);
	if (!deterministic) {
		fputs(", \"ci95_b\": ", f);
		bsim_json_pair(f, t->ci_b);
	}
	fputs(", \"difference\": ", f);
	bsim_json_number(f, t->diff);
	fprintf(f, ", \"both\": %d, \"only_a\": %d, \"only_b\": %d, \"neither\": %d", t->pairs.a,
	        t->pairs.b, t->pairs.c, t->pairs.d);
	if (deterministic) {
		fputc('}', f);
		return;
	}
	fputs(", \"difference_ci95\": ", f);
	bsim_json_pair(f, t->diff_ci);
	fputs(", \"p_mcnemar\": ", f);
	bsim_json_number(f, t->p_value);
	fputs(", \"p_holm\": ", f);
	bsim_json_number(f, t->p_holm);
	fputs(", \"p_equivalence\": ", f);
	bsim_json_number(f, t->p_equivalence);
	fputs(", \"mde80\": ", f);
	bsim_json_number(f, t->mde80);
	fputs(", \"min_significant\": ", f);
	bsim_json_number(f, t->min_significant);
	fprintf(f,
	        ", \"in_family\": %s, \"informative\": %s, \"beyond\": %s, \"equivalent\": "
	        "%s}",
	        t->in_family ? "true" : "false", t->informative ? "true" : "false",
	        t->beyond ? "true" : "false", t->equivalent ? "true" : "false");
}

static void json_outcome(FILE *f, const bsim_trial_result *x)
{
	fputs("{\"outcome\": ", f);
	bsim_json_string(f, bsim_trial_outcome_name(x->outcome));
	fputs(", \"type\": ", f);
	bsim_json_string(f, bsim_trial_type_name(x->type));
	fputs(", \"t_end\": ", f);
	bsim_json_number(f, x->t_end);
	fputc('}', f);
}

/* The replay line as a JSON string: written to memory first. */
static void json_replay(FILE *f, const bsim_report *r, int side, int g, int t)
{
	char *buf = NULL;
	size_t len = 0;
	FILE *m = open_memstream(&buf, &len);
	if (!m) {
		fputs("null", f);
		return;
	}
	replay_line(m, r, side, g, t);
	fclose(m);
	bsim_json_string(f, buf);
	free(buf);
}

static void json_examples(FILE *f, const bsim_report *r, int g)
{
	int shown = 0;
	fputs(", \"examples\": [", f);
	for (int t = 0; t < r->cmp->groups[g].pairs && shown < r->examples; t++) {
		const bsim_trial_result *a = trial_of(r, 0, g, t), *b = trial_of(r, 1, g, t);
		if (!bsim_compare_discordant(a, b))
			continue;
		fprintf(f, "%s\n      {\"trial\": %d, \"a\": ", shown ? "," : "", t);
		json_outcome(f, a);
		fputs(", \"b\": ", f);
		json_outcome(f, b);
		fputs(", \"t_separate\": ", f);
		double ts = r->t_separate ? r->t_separate[(size_t)g * r->cmp->trials + t] : -1.0;
		if (ts >= 0.0)
			bsim_json_number(f, ts);
		else
			fputs("null", f);
		fputs(", \"replay_a\": ", f);
		json_replay(f, r, 0, g, t);
		fputs(", \"replay_b\": ", f);
		json_replay(f, r, 1, g, t);
		fputc('}', f);
		shown++;
	}
	fputc(']', f);
}

static void json_location_list(FILE *f, const bsim_lattice_summary *ls)
{
	fputc('[', f);
	for (int k = 0; k < ls->n_locations; k++) {
		const bsim_location_count *c = &ls->locations[k];
		char label[48];
		bsim_lattice_location_label(c->loc, label, sizeof label);
		fprintf(f, "%s{\"location\": \"%s\", \"count\": %d, \"p\": ", k ? ", " : "", label,
		        c->count);
		bsim_json_number(f, c->p);
		fputs(", \"ci95\": ", f);
		bsim_json_pair(f, c->ci95);
		fputc('}', f);
	}
	fputc(']', f);
}

static void json_locations(FILE *f, const bsim_report *r, int g)
{
	const bsim_location_test *t = &r->cmp->groups[g].loc;
	bsim_lattice_summary ls[2];
	fputs(",\n     \"final_locations\": {\"test\": ", f);
	bsim_json_string(f, t->exact ? "paired permutation, exact"
	                             : "paired permutation, monte carlo");
	fprintf(f, ", \"resamples\": %ld, \"discordant\": %d, \"total_variation\": ", t->resamples,
	        t->discordant);
	bsim_json_number(f, t->tv);
	fputs(", \"p\": ", f);
	bsim_json_number(f, t->p_value);
	fputs(", \"p_holm\": ", f);
	bsim_json_number(f, t->p_holm);
	fprintf(f, ", \"beyond\": %s", t->beyond ? "true" : "false");
	for (int side = 0; side < 2; side++) {
		fputs(side ? ", \"b\": " : ", \"a\": ", f);
		if (side_locations(r, side, g, &ls[side]) != BSIM_OK) {
			fputs("null", f);
			continue;
		}
		json_location_list(f, &ls[side]);
		bsim_lattice_summary_free(&ls[side]);
	}
	fputc('}', f);
}

static void json_pooled(FILE *f, const bsim_comparison *c)
{
	bsim_pairs t;
	double ci[2], p;
	fputs(",\n  \"pooled\": ", f);
	if (pooled(c, 0, &t, ci, &p) == 0) {
		fputs("null", f);
		return;
	}
	for (int ev = 0; ev < BSIM_N_EVENTS; ev++) {
		pooled(c, ev, &t, ci, &p);
		int n = t.a + t.b + t.c + t.d;
		fputs(ev ? ", " : "{", f);
		bsim_json_string(f, bsim_compare_event_name((bsim_event)ev));
		fprintf(f, ": {\"pairs\": %d, \"only_a\": %d, \"only_b\": %d, \"difference\": ", n,
		        t.b, t.c);
		bsim_json_number(f, n > 0 ? (double)(t.b - t.c) / n : 0.0);
		fputs(", \"difference_ci95\": ", f);
		bsim_json_pair(f, ci);
		fputs(", \"p_mcnemar\": ", f);
		bsim_json_number(f, p);
		fputc('}', f);
	}
	fputc('}', f);
}

static void json_side(FILE *f, const bsim_report_side *s)
{
	fputs("{\"label\": ", f);
	bsim_json_string(f, s->label);
	fputs(", \"backend\": ", f);
	bsim_json_string(f, s->backend->name);
	fputs(", \"backend_options\": ", f);
	bsim_output_backend_options(f, s->backend, s->opts);
	if (s->read_from) {
		fputs(", \"read_from\": ", f);
		bsim_json_string(f, s->read_from);
	}
	fputs(", \"wall_seconds\": ", f);
	bsim_json_number(f, s->run->wall_seconds);
	fputc('}', f);
}

/* The verdicts' counts as a JSON object. */
static void json_verdicts(FILE *f, const int *count)
{
	fputc('{', f);
	for (int v = 0; v < BSIM_N_VERDICTS; v++) {
		fputs(v ? ", " : "", f);
		bsim_json_string(f, bsim_compare_verdict_name((bsim_verdict)v));
		fprintf(f, ": %d", count[v]);
	}
	fputc('}', f);
}

static void json_separation(FILE *f, const bsim_report *r)
{
	const bsim_comparison *c = r->cmp;
	if (r->t_separate) {
		fprintf(f,
		        "{\"distance\": \"0.01 body radius\", \"separated\": %d, \"pairs\": %ld, "
		        "\"quantiles_10_50_90_s\": ",
		        c->separated, (long)c->pairs);
		json_quantiles(f, c->t_sep);
		fputc('}', f);
	} else {
		fputs("null", f);
	}
}

/* A group's pair as in the groups of two sides: verdict, counts, events
 * (the fields after "params"). */
static void json_group_pair(FILE *f, const bsim_report *r, int g, bsim_verdict verdict)
{
	const bsim_comparison *c = r->cmp;
	const bsim_compare_group *cg = &c->groups[g];
	fputs(", \"verdict\": ", f);
	bsim_json_string(f, bsim_compare_verdict_name(verdict));
	fprintf(f,
	        ", \"deterministic\": %s, \"pairs\": %d, \"discordant\": %d, \"changed\": "
	        "%d, "
	        "\"separated\": %d, ",
	        cg->deterministic ? "true" : "false", cg->pairs, cg->discordant, cg->changed,
	        cg->separated);
	fputs("\"t_separate_quantiles_s\": ", f);
	json_quantiles(f, cg->t_sep);
	fputs(",\n     \"events\": {", f);
	for (int ev = 0; ev < BSIM_N_EVENTS; ev++) {
		fputs(ev ? ",\n       " : "\n       ", f);
		bsim_json_string(f, bsim_compare_event_name((bsim_event)ev));
		fputs(": ", f);
		json_event(f, &cg->ev[ev], cg->deterministic);
	}
	fputc('}', f);
	if (c->lattice && !cg->deterministic)
		json_locations(f, r, g);
	if (shows_detail(cg))
		json_examples(f, r, g);
}

static void json_odd(FILE *f, const bsim_report *r, int odd)
{
	fputs("{\"side\": ", f);
	if (odd >= 0)
		bsim_json_string(f, r->sides[odd].label);
	else
		fputs("null", f);
	fputs(", \"found\": ", f);
	bsim_json_string(f, odd >= 0 ? "side" : odd == BSIM_ODD_NONE ? "none" : "no single side");
	fputc('}', f);
}

/* More than two sides, at the top: every side, every pair's summary, the
 * odd ones out. */
static void json_sides_top(FILE *f, const bsim_report *r)
{
	const bsim_compare_sides *all = r->all;
	fputs(",\n  \"sides\": [", f);
	for (int s = 0; s < r->n_sides; s++) {
		fputs(s ? ",\n    " : "\n    ", f);
		json_side(f, &r->sides[s]);
	}
	fprintf(f, "],\n  \"pairs_of_sides\": %d,\n  \"pairwise\": [", all->n_pairs);
	for (int k = 0; k < all->n_pairs; k++) {
		bsim_report v = pair_view(r, k);
		fputs(k ? ",\n    {\"a\": " : "\n    {\"a\": ", f);
		bsim_json_string(f, v.side[0].label);
		fputs(", \"b\": ", f);
		bsim_json_string(f, v.side[1].label);
		fprintf(f, ", \"groups_disagreeing\": %d, \"verdicts\": ", v.cmp->n_disagree);
		json_verdicts(f, v.cmp->count);
		fputs(", \"separation\": ", f);
		json_separation(f, &v);
		json_pooled(f, v.cmp);
		fputc('}', f);
	}
	fputs("],\n  \"odd_one_out\": {\"rule\": ", f);
	bsim_json_string(f, "the side whose every pair with another side disagrees (DISAGREE or "
	                    "DIFFERENT) while no pair of the other sides does");
	fputs(", \"groups\": {", f);
	for (int s = -2; s < r->n_sides; s++) {
		int n = 0;
		for (int g = 0; g < all->n_groups; g++)
			n += all->odd[g] == s;
		fputs(s > -2 ? ", " : "", f);
		bsim_json_string(f, s >= 0               ? r->sides[s].label
		                    : s == BSIM_ODD_NONE ? "none"
		                                         : "no single side");
		fprintf(f, ": %d", n);
	}
	fputs("}}", f);
}

/* More than two sides, in group g: each side's p_traverse, every pair,
 * the odd one out. */
static void json_sides_group(FILE *f, const bsim_report *r, int g)
{
	const bsim_compare_sides *all = r->all;
	fputs(",\n     \"sides\": [", f);
	for (int s = 0; s < r->n_sides; s++) {
		const bsim_group_result *gr = &r->sides[s].run->groups[g];
		fputs(s ? ", " : "", f);
		fputs("{\"label\": ", f);
		bsim_json_string(f, r->sides[s].label);
		fputs(", \"p_traverse\": ", f);
		bsim_json_number(f, gr->p_traverse);
		fputs(", \"ci95\": ", f);
		bsim_json_pair(f, gr->ci95);
		fputc('}', f);
	}
	fputs("],\n     \"pairwise\": [", f);
	for (int k = 0; k < all->n_pairs; k++) {
		bsim_report v = pair_view(r, k);
		fputs(k ? ",\n     {\"a\": " : "\n     {\"a\": ", f);
		bsim_json_string(f, v.side[0].label);
		fputs(", \"b\": ", f);
		bsim_json_string(f, v.side[1].label);
		json_group_pair(f, &v, g, v.cmp->groups[g].verdict);
		fputc('}', f);
	}
	fputs("],\n     \"odd_one_out\": ", f);
	json_odd(f, r, all->odd[g]);
}

void bsim_report_json(FILE *f, const bsim_report *r)
{
	const bsim_comparison *c = r->cmp;
	/* More than two sides: the fields of two sides are the first pair's,
	 * but for the verdicts, which are over every pair. */
	const bsim_compare_sides *all = r->n_sides > 2 ? r->all : NULL;
	fputs("{\n  \"experiment\": ", f);
	bsim_json_string(f, r->e->path);
	fputs(",\n  \"seed\": ", f);
	bsim_json_u64(f, r->e->seed);
	fprintf(f, ",\n  \"trials_per_group\": %d,\n  \"a\": ", c->trials);
	json_side(f, &r->side[0]);
	fputs(",\n  \"b\": ", f);
	json_side(f, &r->side[1]);
	fputs(",\n  \"rule\": {\"alpha\": ", f);
	bsim_json_number(f, c->rule.alpha);
	fputs(", \"margin\": ", f);
	bsim_json_number(f, c->rule.margin);
	fprintf(f,
	        ", \"exact\": %s, \"correction\": \"holm\", \"tests\": %d, \"test\": "
	        "\"mcnemar_exact\", \"interval\": \"tango_score\", \"equivalence\": "
	        "\"tango_two_one_sided\", \"mde_power\": 0.8",
	        c->rule.exact ? "true" : "false", c->n_tests);
	if (c->lattice)
		fputs(", \"final_location_test\": \"paired_permutation\"", f);
	fputc('}', f);
	fprintf(f, ",\n  \"groups_disagreeing\": %d,\n  \"verdicts\": ",
	        all ? all->n_disagree : c->n_disagree);
	json_verdicts(f, all ? all->count : c->count);
	fputs(",\n  \"separation\": ", f);
	json_separation(f, r);
	json_pooled(f, c);
	if (all)
		json_sides_top(f, r);
	fputs(",\n  \"groups\": [", f);
	for (int g = 0; g < c->n_groups; g++) {
		fprintf(f, "%s\n    {\"group\": %d, \"params\": ", g ? "," : "", g);
		bsim_output_group_params(f, r->e, g);
		json_group_pair(f, r, g, all ? all->verdict[g] : c->groups[g].verdict);
		if (all)
			json_sides_group(f, r, g);
		fputc('}', f);
	}
	fputs("\n  ]\n}\n", f);
}

/* pairs.csv's columns of each side, lettered by side: trials.csv's, before
 * and after the pairs' separation times. */
static const char *const pairs_side_first[] = {"outcome", "type"};
static const char *const pairs_side_last[] = {"location"};

static void pairs_side_header(FILE *f, const char *const *names, int n_names, int n_sides)
{
	for (int s = 0; s < n_sides; s++)
		for (int k = 0; k < n_names; k++)
			fprintf(f, ",%s_%c", names[k], 'a' + s);
}

static void pairs_side_values(FILE *f, const char *const *names, int n_names,
                              const bsim_report_side *sides, int n_sides, int g, int t, size_t i)
{
	for (int s = 0; s < n_sides; s++) {
		const bsim_trial_row row = {g, t, &sides[s].run->trials_out[i], NULL, 0, NULL};
		for (int k = 0; k < n_names; k++) {
			fputc(',', f);
			bsim_trial_field_write(f, bsim_trial_field_find(names[k]), &row);
		}
	}
}

void bsim_report_pairs_csv(FILE *f, const bsim_report *r)
{
	const bsim_comparison *c = r->cmp;
	const int n = r->n_sides > 2 ? r->n_sides : 2, n_pairs = bsim_sweep_pairs(n);
	const bsim_report_side *sides = r->n_sides > 2 ? r->sides : r->side;
	const size_t total = (size_t)c->n_groups * (size_t)c->trials;
	const int n_first = (int)(sizeof pairs_side_first / sizeof *pairs_side_first);
	const int n_last = (int)(sizeof pairs_side_last / sizeof *pairs_side_last);
	fputs("group,trial", f);
	pairs_side_header(f, pairs_side_first, n_first, n);
	fputs(",t_separate", f);
	for (int k = 1; k < n_pairs; k++) {
		int p[2];
		bsim_sweep_pair(n, k, p);
		fprintf(f, ",t_separate_%c_%c", 'a' + p[0], 'a' + p[1]);
	}
	pairs_side_header(f, pairs_side_last, n_last, n);
	fputc('\n', f);
	for (int g = 0; g < c->n_groups; g++)
		for (int t = 0; t < c->trials; t++) {
			size_t i = (size_t)g * c->trials + t;
			fprintf(f, "%d,%d", g, t);
			pairs_side_values(f, pairs_side_first, n_first, sides, n, g, t, i);
			for (int k = 0; k < n_pairs; k++) {
				double ts =
				        r->t_separate ? r->t_separate[(size_t)k * total + i] : -1.0;
				fputc(',', f);
				if (ts >= 0.0)
					fprintf(f, "%.10g", ts);
			}
			pairs_side_values(f, pairs_side_last, n_last, sides, n, g, t, i);
			fputc('\n', f);
		}
}
