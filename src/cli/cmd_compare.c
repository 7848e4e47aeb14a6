/* beamsim compare: an experiment on two or more backends (or settings of
 * one) with the same schedules, trial by trial, into DIR
 * (beamsim/compare_dir.h), and a summary of where their traversal
 * statistics agree and where they do not, and which side a disagreement
 * is due to. Exit status 3 when a group disagrees beyond the rule (see
 * beamsim/compare.h), so the command can guard CI. */
#define _POSIX_C_SOURCE 200809L

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/compare_dir.h"
#include "cli/cli_wrote.h"
#include "cli/cli_common.h"
#include "cli/cli_options.h"
#include "cli/cli_progress.h"
#include "cli/cli_mpi.h"
#include "beamsim/limits.h"

enum { OWN_BACKENDS, OWN_PROTOCOLS, OWN_EXAMPLES, OWN_SHARD };

static const cli_own compare_own[] = {
        [OWN_BACKENDS] = {"backends", 1, "A,B[,C...]",
                          "the sides, 2 to 8 (default {pair}); each a\n"
                          "backend with options inline, NAME[:K=V]..., e.g.\n"
                          "{default},{default}:{knob}; the side's label and\n"
                          "directory are the text (':' written '-' in the name);\n"
                          "or trials:PATH, read not run: the trials.csv of this\n"
                          "experiment made elsewhere (or a directory holding one),\n"
                          "labelled by its folder's name"},
        [OWN_PROTOCOLS] = {"protocols", 1, "P,Q",
                           "a lattice experiment on one backend (--backend B,\n"
                           "default {default}) under two lattice protocols (world,\n"
                           "essay) instead of two backends; the sides and their\n"
                           "directories are named by protocol"},
        [OWN_EXAMPLES] = {"examples", 1, "N",
                          "discordant trials shown per disagreeing group (default 3)"},
        [OWN_SHARD] = {"shard", 1, "I/N",
                       "run part I of N (I from 1 to N, as SLURM_ARRAY_TASK_ID of\n"
                       "--array=1-N) into DIR, a part directory; beamsim merge\n"
                       "joins the N parts' directories (docs/cluster.md)"},
};

static const char *const compare_help[CLI_N_OPTS] = {
        [CLI_OPT_BACKEND] = "the backend of --protocols",
        [CLI_OPT_BACKEND_OPT] = "option K=V for every side, B:K=V for every side on\n"
                                "backend B, repeatable; options inline in --backends win",
        [CLI_OPT_TRAJECTORIES] = "keep the trajectories of the first N trials of each\n"
                                 "group, per side in DIR/<label>/trajectories.csv",
        [CLI_OPT_RESUME] = "continue the stopped comparison in DIR (same inputs)",
};

typedef struct compare_args {
	const char *backends; /* "A,B" as given, NULL: the registry's first two */
	char protocol[2][16]; /* --protocols, "" if not given */
	long examples;
	int shard, shards; /* --shard, 1-based; 0: the whole comparison */
} compare_args;

/* "world,essay" into a->protocol. */
static int parse_protocols(compare_args *a, const char *text)
{
	const char *comma = strchr(text, ',');
	for (int i = 0; comma && i < 2; i++) {
		const char *p = i ? comma + 1 : text;
		size_t len = i ? strlen(p) : (size_t)(comma - text);
		if (len == 5 && (!strncmp(p, "world", 5) || !strncmp(p, "essay", 5)))
			snprintf(a->protocol[i], sizeof a->protocol[i], "%.*s", (int)len, p);
	}
	if (!a->protocol[0][0] || !a->protocol[1][0] || !strcmp(a->protocol[0], a->protocol[1]))
		return cli_usage("compare",
		                 "--protocols %s: expected two different lattice protocols, "
		                 "world,essay or essay,world",
		                 text);
	return CLI_OK;
}

static int compare_option(void *args, int i, const char *value)
{
	compare_args *a = args;
	switch (i) {
	case OWN_BACKENDS:
		a->backends = value;
		return CLI_OK;
	case OWN_PROTOCOLS:
		return parse_protocols(a, value);
	case OWN_EXAMPLES:
		if (cli_parse_long(value, 0, 1000, &a->examples) != 0)
			return cli_usage("compare", "--examples %s: expected an integer 0..1000",
			                 value);
		return CLI_OK;
	case OWN_SHARD:
		return cli_shard_parse("compare", value, &a->shard, &a->shards);
	}
	return CLI_USAGE;
}

static const cli_spec compare_spec = {
        .name = "compare",
        .usage = "EXPERIMENT --out DIR [OPTIONS]",
        .about = "Runs every trial of the experiment on two or more backends, or settings of\n"
                 "one, with the same random-force schedule, so trial t of group g is a pair, and\n"
                 "reports per group and pair of sides: both sides' probabilities of traversed,\n"
                 "left, right,\n"
                 "side_exit, stuck and unstable with Wilson 95% intervals, their paired\n"
                 "difference (Tango's 95% score interval), the exact McNemar test on the\n"
                 "discordant pairs, Holm-corrected over all groups with random force, events\n"
                 "and pairs of sides,\n"
                 "Tango's equivalence test against +-margin, the smallest difference the test\n"
                 "could detect, a verdict, and the times at which paired trajectories first\n"
                 "separate by more than 1% of the body radius. A group without random force is\n"
                 "deterministic: it runs once and is compared as one pair, same or different.\n"
                 "Disagreeing groups list example trials with the `beamsim run` lines that\n"
                 "replay them on either side.\n"
                 "\n"
                 "A group disagrees when an event's Holm-adjusted p-value is below --alpha and\n"
                 "its probabilities differ by at least --margin, or, if deterministic, when its\n"
                 "pair differs, in any pair of sides. Exit status 3 if any does. With three\n"
                 "sides or more each group names its odd one out: the side whose every pair\n"
                 "with another side disagrees while the others agree among themselves\n"
                 "(docs/compare.md). On a gate lattice the report adds\n"
                 "both sides' final-location distributions and a paired permutation test of\n"
                 "their difference, which joins the rule.\n"
                 "\n"
                 "Writes DIR/report.md, DIR/report.json, DIR/pairs.csv, DIR/<label>/summary.json\n"
                 "and trials.csv for each side, and DIR/run.json with DIR/inputs/ (the grid that\n"
                 "ran, --grid axes included) for `beamsim regress DIR`. The files appear\n"
                 "together at the end (DIR/manifest.json);\n"
                 "finished pairs are journaled as they end, so a stopped or killed comparison\n"
                 "continues with --resume and gives the same files.\n"
                 "\n",
        .positional = "EXPERIMENT",
        .common = CLI_USES(CLI_OPT_OUT) | CLI_USES(CLI_OPT_OVERWRITE) |
                  CLI_USES(CLI_OPT_BACKEND_OPT) | CLI_USES(CLI_OPT_BACKEND) |
                  CLI_USES(CLI_OPT_THREADS) | CLI_USES(CLI_OPT_TRIALS) | CLI_USES(CLI_OPT_SEED) |
                  CLI_USES(CLI_OPT_SET) | CLI_USES(CLI_OPT_GRID) | CLI_USES(CLI_OPT_ALPHA) |
                  CLI_USES(CLI_OPT_MARGIN) | CLI_USES(CLI_OPT_TRAJECTORIES) |
                  CLI_USES(CLI_OPT_TRAJECTORY_STRIDE) | CLI_USES(CLI_OPT_QUIET) |
                  CLI_USES(CLI_OPT_RESUME) | CLI_USES(CLI_OPT_LIMIT),
        .help = compare_help,
        .out_required = 1,
        .own = compare_own,
        .n_own = 4,
        .option = compare_option,
};

/* The sides: --backends A,B,... with options inline, or one backend under
 * --protocols; --backend-opt first, inline options after (they win). */
static int sides_resolve(const cli_common *c, const compare_args *a, bsim_compare_dir_def *def)
{
	bsim_error err;
	const char *names[BSIM_COMPARE_SIDES_MAX];
	bsim_options *opts[BSIM_COMPARE_SIDES_MAX];
	/* room for a side trials:PATH */
	char spec[BSIM_COMPARE_SIDES_MAX][BSIM_PATH_MAX + 16];
	for (int i = 0; i < BSIM_COMPARE_SIDES_MAX; i++)
		opts[i] = &def->side[i].opts;
	if (a->protocol[0][0]) {
		if (a->backends)
			return cli_usage("compare",
			                 "--protocols runs one backend (--backend B), not "
			                 "--backends");
		const char *b = c->backend ? c->backend : bsim_backend_default()->name;
		def->n_sides = 2;
		for (int i = 0; i < 2; i++) {
			bsim_compare_side *s = &def->side[i];
			memset(s, 0, sizeof *s);
			if (!(s->backend = bsim_backend_find(b, &err)))
				return cli_report(CLI_USAGE, &err);
			snprintf(s->label, sizeof s->label, "%s", a->protocol[i]);
			names[i] = s->backend->name;
			def->protocol[i] = a->protocol[i];
		}
		return cli_backend_opts(c, "compare", 2, names, opts);
	}
	if (c->backend)
		return cli_usage("compare", "--backend B goes with --protocols; two backends are "
		                            "--backends A,B");
	char pair[128];
	cli_backend_names(pair, sizeof pair, 2);
	const char *text = a->backends ? a->backends : pair;
	int n = 0;
	for (const char *p = text;; n++) {
		size_t len = strcspn(p, ",");
		if (len == 0 || len >= sizeof spec[0] || n == BSIM_COMPARE_SIDES_MAX)
			return cli_usage("compare",
			                 "--backends %s: expected 2 to %d sides A,B,... (each "
			                 "NAME[:KEY=VALUE]... or trials:PATH, none empty)",
			                 text, BSIM_COMPARE_SIDES_MAX);
		snprintf(spec[n], sizeof spec[n], "%.*s", (int)len, p);
		if (p[len] == '\0') {
			n++;
			break;
		}
		p += len + 1;
	}
	if (n < 2)
		return cli_usage("compare", "--backends %s: expected two sides A,B or more", text);
	def->n_sides = n;
	/* The backends first (--backend-opt needs them), then the options in
	 * order: --backend-opt, then inline. A side read from a file runs
	 * nothing and takes none. */
	int n_run = 0;
	for (int i = 0; i < n; i++) {
		memset(&def->side[i], 0, sizeof def->side[i]);
		if (bsim_compare_side_parse(spec[i], &def->side[i], &err) != BSIM_OK)
			return cli_usage("compare", "%s", err.msg);
		if (def->side[i].trials[0])
			continue;
		names[n_run] = def->side[i].backend->name;
		opts[n_run++] = &def->side[i].opts;
	}
	int rc = n_run > 0 ? cli_backend_opts(c, "compare", n_run, names, opts) : CLI_OK;
	for (int i = 0; rc == CLI_OK && i < n; i++)
		if (bsim_compare_side_parse(spec[i], &def->side[i], &err) != BSIM_OK)
			rc = cli_usage("compare", "%s", err.msg);
	return rc;
}

/* The label of side i. */
static const char *side_label(const bsim_compare_dir_def *def, int i)
{
	return i < 2 && def->protocol[i] ? def->protocol[i] : def->side[i].label;
}

static void compare_summary(const bsim_compare_dir_def *def, const char *out,
                            const bsim_compare_dir_result *res)
{
	const bsim_compare_sides *all = &res->cmp;
	const bsim_comparison *cmp = &all->pairs[0];
	const int *k = all->count;
	for (int i = 0; i < res->n_sides; i++)
		printf("%s%s", i ? " vs " : "", side_label(def, i));
	/* The headline counts every group: those that disagree, those shown
	 * alike (the same, equivalent, or a difference within the margin) and
	 * those left undecided (inconclusive, or every event at the floor or
	 * the ceiling), which more trials would decide. */
	const int undecided = k[BSIM_VERDICT_INCONCLUSIVE] + k[BSIM_VERDICT_UNINFORMATIVE];
	printf(" on %s: %d of %d groups disagree, %d agree, %d undecided (alpha %g, margin %g), "
	       "%d x %d trials\n",
	       res->e.path, all->n_disagree, all->n_groups,
	       all->n_groups - all->n_disagree - undecided, undecided, cmp->rule.alpha,
	       cmp->rule.margin, res->e.n_groups, res->e.trials);
	printf("  deterministic: %d same, %d different; random: %d equivalent within +-%g, %d "
	       "uninformative (at the floor or ceiling), %d inconclusive, %d small, %d disagree "
	       "(Holm over %d tests)\n",
	       k[BSIM_VERDICT_SAME], k[BSIM_VERDICT_DIFFERENT], k[BSIM_VERDICT_EQUIVALENT],
	       cmp->rule.margin, k[BSIM_VERDICT_UNINFORMATIVE], k[BSIM_VERDICT_INCONCLUSIVE],
	       k[BSIM_VERDICT_SMALL], k[BSIM_VERDICT_DISAGREE], all->n_tests);
	for (int g = 0; g < all->n_groups; g++) {
		if (all->verdict[g] != BSIM_VERDICT_DISAGREE &&
		    all->verdict[g] != BSIM_VERDICT_DIFFERENT)
			continue;
		for (int p = 0; p < all->n_pairs; p++) {
			const bsim_compare_group *cg = &all->pairs[p].groups[g];
			const bsim_event_test *t = &cg->ev[BSIM_EVENT_TRAVERSED];
			char who[300] = "";
			if (all->n_sides > 2)
				snprintf(who, sizeof who, ", %s vs %s",
				         side_label(def, all->pair[p][0]),
				         side_label(def, all->pair[p][1]));
			if (cg->verdict == BSIM_VERDICT_DISAGREE)
				printf("  group %d%s: p_traverse %.2f vs %.2f, %d discordant "
				       "pairs\n",
				       g, who, t->p_a, t->p_b, cg->discordant);
			else if (cg->verdict == BSIM_VERDICT_DIFFERENT)
				printf("  group %d (deterministic)%s: the one pair differs\n", g,
				       who);
		}
		int odd = all->odd[g];
		if (all->n_sides > 2)
			printf("  group %d: odd one out %s\n", g,
			       odd >= 0 ? side_label(def, odd) : "no single side");
	}
	for (int i = 0; i < res->n_sides; i++)
		if (res->unstable[i] > 0)
			printf("  %s: %ld unstable trials (see %s/%s/trials.csv)\n",
			       side_label(def, i), res->unstable[i], cli_path(out), res->dir[i]);
	cli_wrote(stdout, out);
}

static int compare_main(int argc, char **argv, const cli_merge *m)
{
	cli_common c = cli_common_default();
	compare_args a = {.examples = 3};
	const char *experiment = NULL;
	bsim_compare_dir_def def = bsim_compare_dir_def_default();
	int rc = cli_parse(&compare_spec, argc, argv, &c, &a, &experiment);
	if (rc < 0 && (rc = sides_resolve(&c, &a, &def)) == CLI_OK)
		rc = -1;
	if (rc < 0 && a.shards > 0 && cli_mpi_size() > 1)
		rc = cli_usage("compare",
		               "--shard runs one part in one process: not under mpirun, "
		               "which spreads the whole comparison over its %d ranks",
		               cli_mpi_size());
	if (rc >= 0) {
		cli_common_free(&c);
		return rc;
	}
	if (m) {
		cli_merge_apply(m, &c);
		a.shard = a.shards = 0;
		def.merge = m->parts;
		def.n_merge = m->n_parts;
	}
	int rank = cli_mpi_rank();
	char **stored = NULL;
	cli_progress progress;
	cli_progress_init(&progress, !c.quiet && rank == 0, "trials");
	def.experiment = experiment;
	def.out = c.out;
	def.sets = c.sets.ov;
	def.n_sets = c.sets.n;
	def.grid = c.sets.grid;
	def.n_grid = c.sets.n_grid;
	def.trials = c.trials;
	def.has_seed = c.has_seed;
	def.seed = c.seed;
	def.threads = (int)c.threads;
	if (c.has_alpha)
		def.rule.alpha = c.alpha;
	if (c.has_margin)
		def.rule.margin = c.margin;
	def.examples = (int)a.examples;
	def.keep = (int)c.keep;
	def.keep_stride = (int)c.keep_stride;
	def.resume = c.resume;
	def.overwrite = c.overwrite;
	def.progress = rank == 0 ? cli_progress_update : NULL;
	def.progress_user = &progress;
	def.stop = &cli_stop;
	if (a.shards > 0) {
		def.spread = BSIM_SPREAD_SHARD;
		def.part.index = a.shard - 1;
		def.part.count = a.shards;
		stored = cli_stored_argv(argc, argv, experiment);
		def.argc = stored ? argc : 0;
		def.argv = stored;
	}
	cli_mpi_spread(&def.spread, &def.part, &def.agree,
	               bsim_sweep_record_size_sides(def.n_sides), def.stop);
	/* Every side that runs runs every trial; the costlier backend's
	 * constant bounds the estimate. */
	const bsim_backend *costlier = NULL;
	int n_run = 0;
	for (int i = 0; i < def.n_sides; i++) {
		const bsim_backend *b = def.side[i].backend;
		if (def.side[i].trials[0])
			continue;
		if (!b)
			b = bsim_backend_default();
		if (!costlier || b->cost_ns_per_beam_step > costlier->cost_ns_per_beam_step)
			costlier = b;
		n_run++;
	}
	cli_estimate estimate = {costlier, n_run};
	if (rank == 0 && !m && costlier) {
		def.planned = cli_estimate_sides;
		def.planned_user = &estimate;
	}
	bsim_compare_dir_result res;
	bsim_error err;
	cli_signals_install();
	rc = bsim_compare_dir_run(&def, &res, &err);
	cli_signals_restore();
	cli_progress_finish(&progress);
	cli_stored_argv_free(stored, argc, argv);
	if (rc == BSIM_ESTOPPED && rank > 0) {
		/* stopped by the job's signal: rank 0 says so, and how to resume */
	} else if (rc != BSIM_OK) {
		if (rank > 0)
			cli_error("rank %d of %d: %s", rank, cli_mpi_size(), err.msg);
		else
			cli_report(rc, &err);
		rc = rank > 0 ? rc : cli_run_end(rc, res.journal, argc, argv);
		cli_common_free(&c);
		cli_mpi_abort(rc);
		return rc;
	} else if (def.spread == BSIM_SPREAD_SEND || a.shards > 0) {
		if (a.shards > 0 && !c.quiet)
			printf("part %d of %d of the comparison in %s; beamsim merge joins the %d "
			       "parts' directories\n",
			       a.shard, a.shards, c.out, a.shards);
		bsim_compare_dir_result_free(&res);
	} else {
		if (!c.quiet)
			compare_summary(&def, c.out, &res);
		for (int i = 0; i < res.n_sides; i++) {
			char where[BSIM_PATH_MAX];
			snprintf(where, sizeof where, "%s/%s/summary.json", c.out, res.dir[i]);
			cli_solver_warning(def.side[i].backend->name, &res.solver[i], where);
		}
		rc = res.cmp.n_disagree > 0 ? CLI_DISAGREE : CLI_OK;
		bsim_compare_dir_result_free(&res);
	}
	cli_common_free(&c);
	return rc;
}

int cmd_compare(int argc, char **argv)
{
	return compare_main(argc, argv, NULL);
}

int cmd_compare_merge(int argc, char **argv, const cli_merge *m)
{
	return compare_main(argc, argv, m);
}
