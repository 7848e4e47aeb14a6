/* beamsim compare: an experiment on two backends with the same schedules,
 * trial by trial, and a report of where their traversal statistics agree
 * and where they do not. Exit status 3 when a group disagrees beyond the
 * rule (see beamsim/compare.h), so the command can guard CI. */
#define _POSIX_C_SOURCE 200809L

#include <getopt.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "beamsim/output.h"
#include "cli_common.h"
#include "cli_store.h"

static const char compare_help[] =
        "Usage: beamsim compare EXPERIMENT --out DIR [OPTIONS]\n"
        "\n"
        "Runs every trial of the experiment on two backends, or two settings of one,\n"
        "with the same random-force schedule, so trial t of group g is a pair, and\n"
        "reports per group: both sides' probabilities of traversed, left, right,\n"
        "side_exit, stuck and unstable with Wilson 95% intervals, their paired\n"
        "difference (Tango's 95% score interval), the exact McNemar test on the\n"
        "discordant pairs, Holm-corrected over all groups with random force and events,\n"
        "Tango's equivalence test against +-margin, the smallest difference the test\n"
        "could detect, a verdict, and the times at which paired trajectories first\n"
        "separate by more than 1% of the body radius. A group without random force is\n"
        "deterministic: it runs once and is compared as one pair, same or different.\n"
        "Disagreeing groups list example trials with the `beamsim run` lines that\n"
        "replay them on either side.\n"
        "\n"
        "A group disagrees when an event's Holm-adjusted p-value is below --alpha and\n"
        "its probabilities differ by at least --margin, or, if deterministic, when its\n"
        "pair differs. Exit status 3 if any does. On a gate lattice the report adds\n"
        "both sides' final-location distributions and a paired permutation test of\n"
        "their difference, which joins the rule.\n"
        "\n"
        "Writes DIR/report.md, DIR/report.json, DIR/pairs.csv, DIR/<label>/summary.json\n"
        "and trials.csv for each side, and DIR/run.json with DIR/inputs/ for\n"
        "`beamsim regress DIR`. The files appear together at the end (DIR/manifest.json);\n"
        "finished pairs are journaled as they end, so a stopped or killed comparison\n"
        "continues with --resume and gives the same files.\n"
        "\n"
        "Options:\n"
        "  --out DIR              output directory, created if missing (required)\n"
        "  --backends A,B         the two sides (default thesis,box2d); each a backend\n"
        "                         with options inline, NAME[:K=V]..., e.g.\n"
        "                         thesis,thesis:integrator=euler; the side's label and\n"
        "                         directory are the text (':' written '-' in the name)\n"
        "  --backend-opt B:K=V    option K=V for every side on backend B, repeatable;\n"
        "                         inline options win\n"
        "  --protocols P,Q        a lattice experiment on one backend (--backend B,\n"
        "                         default thesis) under two lattice protocols (world,\n"
        "                         essay) instead of two backends; the sides and their\n"
        "                         directories are named by protocol\n"
        "  --backend B            the backend of --protocols\n"
        "  --threads N            worker threads (default: all cores)\n"
        "  --trials N             trials per group (default: the experiment's)\n"
        "  --seed N               experiment seed (default: the experiment's)\n"
        "  --set KEY=VALUE        override a scene field in every group, repeatable\n"
        "  --alpha A              family-wise error rate (default 0.05)\n"
        "  --margin M             smallest difference that counts (default 0.05)\n"
        "  --examples N           discordant trials shown per disagreeing group (default 3)\n"
        "  --trajectories N       keep the trajectories of the first N trials of each\n"
        "                         group, per backend in DIR/<backend>/trajectories.csv\n"
        "  --trajectory-stride N  a trajectory row every N steps (default 5)\n"
        "  --quiet                no progress line, nothing on stdout\n"
        "  --resume               continue the stopped comparison in DIR (same "
        "inputs)\n" CLI_LIMIT_HELP "  -h, --help             show this help\n";

enum {
	OPT_BACKENDS = 256,
	OPT_BACKEND_OPT,
	OPT_THREADS,
	OPT_TRIALS,
	OPT_SEED,
	OPT_SET,
	OPT_OUT,
	OPT_ALPHA,
	OPT_MARGIN,
	OPT_EXAMPLES,
	OPT_QUIET,
	OPT_PROTOCOLS,
	OPT_BACKEND,
	OPT_TRAJECTORIES,
	OPT_TRAJECTORY_STRIDE,
	OPT_LIMIT,
	OPT_RESUME
};

static const struct option compare_options[] = {
        {"backends", required_argument, NULL, OPT_BACKENDS},
        {"protocols", required_argument, NULL, OPT_PROTOCOLS},
        {"backend", required_argument, NULL, OPT_BACKEND},
        {"backend-opt", required_argument, NULL, OPT_BACKEND_OPT},
        {"threads", required_argument, NULL, OPT_THREADS},
        {"trials", required_argument, NULL, OPT_TRIALS},
        {"seed", required_argument, NULL, OPT_SEED},
        {"set", required_argument, NULL, OPT_SET},
        {"out", required_argument, NULL, OPT_OUT},
        {"alpha", required_argument, NULL, OPT_ALPHA},
        {"margin", required_argument, NULL, OPT_MARGIN},
        {"examples", required_argument, NULL, OPT_EXAMPLES},
        {"quiet", no_argument, NULL, OPT_QUIET},
        {"trajectories", required_argument, NULL, OPT_TRAJECTORIES},
        {"trajectory-stride", required_argument, NULL, OPT_TRAJECTORY_STRIDE},
        {"limit", required_argument, NULL, OPT_LIMIT},
        {"resume", no_argument, NULL, OPT_RESUME},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
};

typedef struct compare_args {
	const char *experiment;
	char labels[2][128]; /* as given: NAME[:K=V]... */
	char names[2][32];   /* the backends */
	char dirs[2][128];   /* the labels as directory names */
	int has_backends;
	char backend[32];     /* --protocols: the one backend, "" if not given */
	char protocol[2][16]; /* --protocols, "" if not given */
	char protocol_set[48];
	bsim_override protocol_b;
	bsim_options opts[2];
	long threads, trials, examples, keep, keep_stride;
	int has_seed;
	uint64_t seed;
	cli_sets sets;
	const char *out;
	bsim_compare_rule rule;
	int quiet;
	int resume;
	int argc; /* the command line, for the line that resumes it */
	char **argv;
	/* --backend-opt, resolved after parsing, before the inline options */
	int n_pending;
	char pending[2 * BSIM_OPTIONS_MAX][128];
} compare_args;

static int parse_backends(compare_args *a, const char *text)
{
	const char *comma = strchr(text, ',');
	size_t n0 = comma ? (size_t)(comma - text) : 0;
	if (!comma || n0 == 0 || n0 >= sizeof a->labels[0] || strchr(comma + 1, ',') ||
	    comma[1] == '\0' || strlen(comma + 1) >= sizeof a->labels[1])
		return cli_usage("compare", "--backends %s: expected two sides A,B", text);
	snprintf(a->labels[0], sizeof a->labels[0], "%.*s", (int)n0, text);
	snprintf(a->labels[1], sizeof a->labels[1], "%s", comma + 1);
	return CLI_OK;
}

/* Side i's backend name, its directory name, and its inline options
 * (after any --backend-opt, so they win). */
static int side_resolve(compare_args *a, int i)
{
	const char *label = a->labels[i];
	size_t n = strcspn(label, ":");
	if (n == 0 || n >= sizeof a->names[i])
		return cli_usage("compare", "--backends: side %s: expected NAME[:KEY=VALUE]...",
		                 label);
	snprintf(a->names[i], sizeof a->names[i], "%.*s", (int)n, label);
	for (const char *p = label + n; *p == ':';) {
		const char *q = p + 1;
		size_t len = strcspn(q, ":");
		char kv[128];
		snprintf(kv, sizeof kv, "%.*s", (int)len, q);
		int rc = cli_options_add(&a->opts[i], "compare", kv);
		if (rc != CLI_OK)
			return rc;
		p = q + len;
	}
	cli_label_dir(label, a->dirs[i], sizeof a->dirs[i]);
	return CLI_OK;
}

/* "B:K=V" into the options of every side whose backend is B. */
static int backend_opt(compare_args *a, const char *text)
{
	const char *colon = strchr(text, ':');
	int used = 0;
	for (int i = 0; colon && i < 2; i++)
		if (strlen(a->names[i]) == (size_t)(colon - text) &&
		    strncmp(text, a->names[i], (size_t)(colon - text)) == 0) {
			int rc = cli_options_add(&a->opts[i], "compare", colon + 1);
			if (rc != CLI_OK)
				return rc;
			used = 1;
		}
	if (used)
		return CLI_OK;
	return cli_usage("compare", "--backend-opt %s: expected B:KEY=VALUE with B one of %s, %s",
	                 text, a->names[0], a->names[1]);
}

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

/* --protocols: both sides on one backend, named by their protocols. */
static int protocols_resolve(compare_args *a)
{
	if (a->has_backends)
		return cli_usage("compare", "--protocols runs one backend (--backend B), not "
		                            "--backends");
	const char *b = a->backend[0] ? a->backend : "thesis";
	for (int i = 0; i < 2; i++) {
		snprintf(a->names[i], sizeof a->names[i], "%s", b);
		snprintf(a->labels[i], sizeof a->labels[i], "%s", a->protocol[i]);
		snprintf(a->dirs[i], sizeof a->dirs[i], "%s", a->protocol[i]);
	}
	for (int i = 0; i < a->n_pending; i++) {
		int rc = backend_opt(a, a->pending[i]);
		if (rc != CLI_OK)
			return rc;
	}
	return -1;
}

static int compare_option(compare_args *a, int c)
{
	switch (c) {
	case OPT_BACKENDS:
		a->has_backends = 1;
		return parse_backends(a, optarg);
	case OPT_PROTOCOLS:
		return parse_protocols(a, optarg);
	case OPT_BACKEND:
		if (strlen(optarg) >= sizeof a->backend)
			return cli_usage("compare", "--backend %s: unknown backend", optarg);
		snprintf(a->backend, sizeof a->backend, "%s", optarg);
		return CLI_OK;
	case OPT_BACKEND_OPT:
		if (a->n_pending == (int)(sizeof a->pending / sizeof a->pending[0]) ||
		    strlen(optarg) >= sizeof a->pending[0])
			return cli_usage("compare", "--backend-opt %s: too many or too long",
			                 optarg);
		snprintf(a->pending[a->n_pending++], sizeof a->pending[0], "%s", optarg);
		return CLI_OK;
	case OPT_THREADS:
		if (cli_parse_long(optarg, 1, 4096, &a->threads) != 0)
			return cli_usage("compare", "--threads %s: expected an integer >= 1",
			                 optarg);
		return CLI_OK;
	case OPT_TRIALS:
		if (cli_parse_long(optarg, 1, INT32_MAX, &a->trials) != 0)
			return cli_usage("compare", "--trials %s: expected an integer >= 1",
			                 optarg);
		return CLI_OK;
	case OPT_SEED:
		a->has_seed = 1;
		if (cli_parse_u64(optarg, &a->seed) != 0)
			return cli_usage("compare", "--seed %s: expected an integer >= 0", optarg);
		return CLI_OK;
	case OPT_SET:
		return cli_sets_add(&a->sets, "compare", optarg);
	case OPT_OUT:
		a->out = optarg;
		return CLI_OK;
	case OPT_ALPHA:
		return cli_parse_fraction("compare", "--alpha", optarg, 1, &a->rule.alpha);
	case OPT_MARGIN:
		return cli_parse_fraction("compare", "--margin", optarg, 0, &a->rule.margin);
	case OPT_EXAMPLES:
		if (cli_parse_long(optarg, 0, 1000, &a->examples) != 0)
			return cli_usage("compare", "--examples %s: expected an integer 0..1000",
			                 optarg);
		return CLI_OK;
	case OPT_QUIET:
		a->quiet = 1;
		return CLI_OK;
	case OPT_TRAJECTORIES:
		if (cli_parse_long(optarg, 0, INT32_MAX, &a->keep) != 0)
			return cli_usage("compare", "--trajectories %s: expected an integer >= 0",
			                 optarg);
		return CLI_OK;
	case OPT_TRAJECTORY_STRIDE:
		if (cli_parse_long(optarg, 1, INT32_MAX, &a->keep_stride) != 0)
			return cli_usage("compare",
			                 "--trajectory-stride %s: expected an integer >= 1",
			                 optarg);
		return CLI_OK;
	case OPT_LIMIT:
		return cli_limit("compare", optarg);
	case OPT_RESUME:
		a->resume = 1;
		return CLI_OK;
	}
	return CLI_USAGE;
}

/* Fills a; returns -1 to go on, else the exit status. */
static int compare_parse(int argc, char **argv, compare_args *a)
{
	int c;
	opterr = 0;
	while ((c = getopt_long(argc, argv, ":h", compare_options, NULL)) != -1) {
		if (c == 'h') {
			fputs(compare_help, stdout);
			return CLI_OK;
		}
		if (c == '?' || c == ':')
			return cli_bad_option("compare", argv, c);
		int rc = compare_option(a, c);
		if (rc != CLI_OK)
			return rc;
	}
	if (optind + 1 != argc)
		return cli_usage("compare",
		                 optind == argc ? "missing EXPERIMENT"
		                                : "expected one EXPERIMENT, got %d",
		                 argc - optind);
	a->experiment = argv[optind];
	if (!a->out)
		return cli_usage("compare", "--out DIR is required");
	if (strlen(a->out) > 900)
		return cli_usage("compare", "--out DIR is longer than 900 characters");
	if (a->protocol[0][0])
		return protocols_resolve(a);
	if (a->backend[0])
		return cli_usage("compare", "--backend B goes with --protocols; two backends are "
		                            "--backends A,B");
	if (strcmp(a->labels[0], a->labels[1]) == 0)
		return cli_usage(
		        "compare",
		        "--backends %s,%s: expected two different sides (a backend against "
		        "itself takes options inline, e.g. thesis,thesis:integrator=euler)",
		        a->labels[0], a->labels[1]);
	/* names first (--backend-opt needs them), then the options in order:
	 * --backend-opt, then inline */
	bsim_options inline_opts[2];
	for (int i = 0; i < 2; i++) {
		int rc = side_resolve(a, i);
		if (rc != CLI_OK)
			return rc;
		inline_opts[i] = a->opts[i];
		memset(&a->opts[i], 0, sizeof a->opts[i]);
	}
	if (strcmp(a->dirs[0], a->dirs[1]) == 0)
		return cli_usage("compare", "--backends %s,%s: both sides would write to %s/%s",
		                 a->labels[0], a->labels[1], a->out, a->dirs[0]);
	for (int i = 0; i < a->n_pending; i++) {
		int rc = backend_opt(a, a->pending[i]);
		if (rc != CLI_OK)
			return rc;
	}
	for (int i = 0; i < 2; i++)
		for (int k = 0; k < inline_opts[i].n; k++) {
			char kv[128];
			snprintf(kv, sizeof kv, "%s=%s", inline_opts[i].key[k],
			         inline_opts[i].value[k]);
			int rc = cli_options_add(&a->opts[i], "compare", kv);
			if (rc != CLI_OK)
				return rc;
		}
	return -1;
}

/* Unstable trials on each side, over the whole comparison. */
static void unstable_counts(const bsim_comparison *cmp, int n[2])
{
	n[0] = n[1] = 0;
	for (int g = 0; g < cmp->n_groups; g++) {
		const bsim_event_test *t = &cmp->groups[g].ev[BSIM_EVENT_UNSTABLE];
		int w = cmp->groups[g].deterministic ? cmp->trials : 1;
		n[0] += w * (t->pairs.a + t->pairs.b);
		n[1] += w * (t->pairs.a + t->pairs.c);
	}
}

static void compare_summary(const compare_args *a, const bsim_experiment *e,
                            const bsim_comparison *cmp)
{
	const int *k = cmp->count;
	printf("%s vs %s on %s: %d of %d groups disagree (alpha %g, margin %g), %d x %d trials\n",
	       a->labels[0], a->labels[1], e->path, cmp->n_disagree, cmp->n_groups, cmp->rule.alpha,
	       cmp->rule.margin, e->n_groups, e->trials);
	printf("  deterministic: %d same, %d different; random: %d equivalent within +-%g, %d "
	       "inconclusive, %d small, %d disagree\n",
	       k[BSIM_VERDICT_SAME], k[BSIM_VERDICT_DIFFERENT], k[BSIM_VERDICT_EQUIVALENT],
	       cmp->rule.margin, k[BSIM_VERDICT_INCONCLUSIVE], k[BSIM_VERDICT_SMALL],
	       k[BSIM_VERDICT_DISAGREE]);
	for (int g = 0; g < cmp->n_groups; g++) {
		const bsim_compare_group *cg = &cmp->groups[g];
		const bsim_event_test *t = &cg->ev[BSIM_EVENT_TRAVERSED];
		if (cg->verdict == BSIM_VERDICT_DISAGREE)
			printf("  group %d: p_traverse %.2f vs %.2f, %d discordant pairs\n", g,
			       t->p_a, t->p_b, cg->discordant);
		else if (cg->verdict == BSIM_VERDICT_DIFFERENT)
			printf("  group %d (deterministic): the one pair differs\n", g);
	}
	int unstable[2];
	unstable_counts(cmp, unstable);
	for (int i = 0; i < 2; i++)
		if (unstable[i] > 0)
			printf("  %s: %d unstable trials (see %s/%s/trials.csv)\n", a->labels[i],
			       unstable[i], a->out, a->dirs[i]);
	printf("wrote %s/report.md, %s/report.json, %s/pairs.csv and each side's sweep in "
	       "%s/%s and %s/%s\n",
	       a->out, a->out, a->out, a->out, a->dirs[0], a->out, a->dirs[1]);
}

static int compare_main(compare_args *a, const bsim_backend *b0, const bsim_backend *b1)
{
	bsim_experiment e;
	bsim_error err;
	int protocols = a->protocol[0][0] != 0;
	/* --protocols: side a's protocol joins the --set overrides, side b's
	 * is its own override after them. */
	if (protocols) {
		snprintf(a->protocol_set, sizeof a->protocol_set, "lattice.protocol=%s",
		         a->protocol[0]);
		a->protocol_b =
		        (bsim_override){"lattice.protocol", a->protocol[1], "--protocols (side b)"};
		if (cli_sets_add(&a->sets, "compare", a->protocol_set) != CLI_OK)
			return CLI_USAGE;
	}
	int rc = cli_experiment_load(a->experiment, &a->sets, a->trials, &e);
	if (rc != CLI_OK)
		return rc;
	if (a->has_seed)
		e.seed = a->seed;
	bsim_run_record rec;
	const bsim_backend *b[2] = {b0, b1};
	const bsim_options *opts[2] = {&a->opts[0], &a->opts[1]};
	const char *labels[2] = {a->labels[0], a->labels[1]};
	cli_record_fill(&rec, "compare", &e, 2, b, opts, labels, &a->rule);
	char *inputs = bsim_run_record_inputs(&rec, &e, a->sets.ov, a->sets.n, &err);
	cli_session ss;
	rc = inputs ? cli_session_open(&ss, a->out, a->resume, inputs, bsim_sweep_record_size(1),
	                               a->argc, a->argv)
	            : cli_report(err.code, &err);
	free(inputs);
	if (rc != CLI_OK) {
		bsim_experiment_free(&e);
		return rc;
	}
	cli_compare_job job = {
	        .e = &e,
	        .backend = {b0, b1},
	        .opts = {&a->opts[0], &a->opts[1]},
	        .label = {a->labels[0], a->labels[1]},
	        .extra = a->sets.ov,
	        .n_extra = a->sets.n,
	        .protocol = {protocols ? a->protocol[0] : NULL, protocols ? a->protocol[1] : NULL},
	        .extra_b = protocols ? &a->protocol_b : NULL,
	        .n_extra_b = protocols,
	        .threads = a->threads > 0 ? (int)a->threads : omp_get_max_threads(),
	        .rule = a->rule,
	        .examples = (int)a->examples,
	        .progress = !a->quiet,
	        .out = ss.stage,
	        .journal = ss.journal,
	        .stop = &cli_stop,
	        .keep = (int)a->keep,
	        .keep_stride = (int)a->keep_stride,
	};
	bsim_comparison cmp;
	rc = cli_compare_execute(&job, &cmp);
	rc = cli_session_close(&ss, rc, "compare");
	if (rc == CLI_OK) {
		if (!a->quiet)
			compare_summary(a, &e, &cmp);
		rc = cmp.n_disagree > 0 ? CLI_DISAGREE : CLI_OK;
	}
	bsim_compare_free(&cmp);
	bsim_experiment_free(&e);
	return rc;
}

int cmd_compare(int argc, char **argv)
{
	compare_args a = {
	        .argc = argc,
	        .argv = argv,
	        .labels = {"thesis", "box2d"},
	        .rule = {BSIM_COMPARE_ALPHA, BSIM_COMPARE_MARGIN, 0},
	        .examples = 3,
	};
	int rc = compare_parse(argc, argv, &a);
	if (rc < 0) {
		const bsim_backend *b0 = cli_backend(a.names[0], &a.opts[0]);
		const bsim_backend *b1 = b0 ? cli_backend(a.names[1], &a.opts[1]) : NULL;
		rc = b0 && b1 ? compare_main(&a, b0, b1) : CLI_USAGE;
	}
	cli_sets_free(&a.sets);
	return rc;
}
