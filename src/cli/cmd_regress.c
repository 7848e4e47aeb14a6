/* beamsim regress: run a stored sweep or comparison again from its record
 * (DIR/run.json, DIR/inputs/) and report, per backend and group, what
 * changed. The stored trials and the rerun's are pairs (same seed, group,
 * trial), so the same paired tests as compare apply; --exact asks for
 * identical trials instead. Exit status 3 beyond the rule. */
#define _POSIX_C_SOURCE 200809L

#include <getopt.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "atomic_file.h"
#include "beamsim/effects.h"
#include "json.h"
#include "outdir.h"
#include "beamsim/output.h"
#include "beamsim/report.h"
#include "beamsim/version.h"
#include "cli_common.h"
#include "cli_store.h"

static const char regress_help[] =
        "Usage: beamsim regress BASELINE_DIR --out DIR [OPTIONS]\n"
        "\n"
        "Runs the sweep or comparison stored in BASELINE_DIR (by beamsim sweep or\n"
        "compare: run.json, inputs/, trials.csv) again with this beamsim, writes the\n"
        "rerun to DIR as the original command would, and compares each backend's\n"
        "trials with the stored ones pair by pair (same seed, group and trial):\n"
        "DIR/regress.md and DIR/regress.json. Identical code and inputs reproduce\n"
        "identical trials.\n"
        "\n"
        "A group has changed beyond tolerance when an event's Holm-adjusted McNemar\n"
        "p-value is below --alpha and its probabilities differ by at least --margin\n"
        "(defaults: the stored rule), or with --exact when any trial differs in any\n"
        "trials.csv field. Exit status 3 if any group has.\n"
        "\n"
        "Options:\n"
        "  --out DIR              output directory for the rerun (required, not BASELINE_DIR)\n"
        "  --threads N            worker threads (default: all cores)\n"
        "  --alpha A              family-wise error rate\n"
        "  --margin M             smallest difference that counts\n"
        "  --exact                any changed trial counts\n"
        "  --quiet                no progress line, nothing on stdout\n" CLI_LIMIT_HELP
        "  -h, --help             show this help\n";

enum { OPT_OUT = 256, OPT_THREADS, OPT_ALPHA, OPT_MARGIN, OPT_EXACT, OPT_QUIET, OPT_LIMIT };

static const struct option regress_options[] = {
        {"out", required_argument, NULL, OPT_OUT},
        {"threads", required_argument, NULL, OPT_THREADS},
        {"alpha", required_argument, NULL, OPT_ALPHA},
        {"margin", required_argument, NULL, OPT_MARGIN},
        {"exact", no_argument, NULL, OPT_EXACT},
        {"quiet", no_argument, NULL, OPT_QUIET},
        {"limit", required_argument, NULL, OPT_LIMIT},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
};

typedef struct regress_args {
	const char *baseline, *out;
	const char *stage; /* where the rerun is written before it appears in out */
	long threads;
	double alpha, margin; /* < 0: the stored rule */
	int exact, quiet;
} regress_args;

static int regress_parse(int argc, char **argv, regress_args *a)
{
	int c;
	opterr = 0;
	while ((c = getopt_long(argc, argv, ":h", regress_options, NULL)) != -1) {
		int rc = CLI_OK;
		switch (c) {
		case 'h':
			fputs(regress_help, stdout);
			return CLI_OK;
		case OPT_OUT:
			a->out = optarg;
			break;
		case OPT_THREADS:
			if (cli_parse_long(optarg, 1, 4096, &a->threads) != 0)
				rc = cli_usage("regress", "--threads %s: expected an integer >= 1",
				               optarg);
			break;
		case OPT_ALPHA:
			rc = cli_parse_fraction("regress", "--alpha", optarg, 1, &a->alpha);
			break;
		case OPT_MARGIN:
			rc = cli_parse_fraction("regress", "--margin", optarg, 0, &a->margin);
			break;
		case OPT_EXACT:
			a->exact = 1;
			break;
		case OPT_QUIET:
			a->quiet = 1;
			break;
		case OPT_LIMIT:
			rc = cli_limit("regress", optarg);
			break;
		default:
			return cli_bad_option("regress", argv, c);
		}
		if (rc != CLI_OK)
			return rc;
	}
	if (optind + 1 != argc)
		return cli_usage("regress",
		                 optind == argc ? "missing BASELINE_DIR"
		                                : "expected one BASELINE_DIR, got %d",
		                 argc - optind);
	a->baseline = argv[optind];
	if (!a->out)
		return cli_usage("regress", "--out DIR is required");
	if (strlen(a->out) > 900 || strlen(a->baseline) > 900)
		return cli_usage("regress", "a directory name is longer than 900 characters");
	struct stat sb, so;
	if (stat(a->baseline, &sb) == 0 && stat(a->out, &so) == 0 && sb.st_ino == so.st_ino &&
	    sb.st_dev == so.st_dev)
		return cli_usage("regress",
		                 "--out %s: expected a directory other than the baseline", a->out);
	return -1;
}

/* What the rerun needs, from the record. */
typedef struct regress_run {
	bsim_run_record rec;
	bsim_experiment e;
	const bsim_backend *backend[2];
	bsim_compare_rule rule;
	bsim_override protocol_b; /* compare --protocols: side b's protocol */
} regress_run;

static int regress_load(const regress_args *a, regress_run *run)
{
	bsim_error err;
	char path[1100];
	int has_manifest = 0;
	if (bsim_outdir_verify(a->baseline, &has_manifest, &err) != BSIM_OK) {
		cli_error("%s", err.msg);
		return CLI_USAGE;
	}
	if (bsim_run_record_read(a->baseline, &run->rec, &err) != BSIM_OK) {
		cli_error("%s", err.msg);
		return CLI_USAGE;
	}
	for (int i = 0; i < run->rec.n_backends; i++)
		if (!(run->backend[i] = cli_backend(run->rec.backend[i], &run->rec.opts[i])))
			return CLI_USAGE;
	if (cli_path(path, sizeof path, a->baseline, "inputs/experiment.yaml"))
		return CLI_USAGE;
	int rc = cli_experiment_load(path, NULL, run->rec.trials, &run->e);
	if (rc != CLI_OK)
		return rc;
	run->e.seed = run->rec.seed;
	run->rule = run->rec.rule;
	if (a->alpha >= 0.0)
		run->rule.alpha = a->alpha;
	if (a->margin >= 0.0)
		run->rule.margin = a->margin;
	run->rule.exact |= a->exact;
	return CLI_OK;
}

/* The rerun into a->out, written as the original command writes it. */
static int regress_rerun(const regress_args *a, regress_run *run)
{
	int threads = a->threads > 0 ? (int)a->threads : omp_get_max_threads();
	if (run->rec.n_backends == 2) {
		int protocols = run->rec.protocol[0][0] != 0;
		run->protocol_b = (bsim_override){"lattice.protocol", run->rec.protocol[1],
		                                  "--protocols (side b)"};
		cli_compare_job job = {
		        .e = &run->e,
		        .backend = {run->backend[0], run->backend[1]},
		        .opts = {&run->rec.opts[0], &run->rec.opts[1]},
		        .label = {run->rec.label[0], run->rec.label[1]},
		        .protocol = {protocols ? run->rec.protocol[0] : NULL,
		                     protocols ? run->rec.protocol[1] : NULL},
		        .extra_b = protocols ? &run->protocol_b : NULL,
		        .n_extra_b = protocols,
		        .threads = threads,
		        .rule = run->rec.rule,
		        .examples = 3,
		        .progress = !a->quiet,
		        .out = a->stage,
		};
		bsim_comparison cmp;
		int rc = cli_compare_execute(&job, &cmp);
		bsim_compare_free(&cmp);
		return rc;
	}
	bsim_sweep_config cfg = {
	        .backend = run->backend[0],
	        .opts = &run->rec.opts[0],
	        .threads = threads,
	};
	bsim_sweep_result r;
	int rc = cli_sweep_run(&run->e, &cfg, !a->quiet, &r);
	if (rc != CLI_OK)
		return rc;
	rc = cli_store_sweep(a->stage, &run->e, run->backend[0], &run->rec.opts[0], NULL, 0, &r);
	bsim_sweep_result_free(&r);
	return rc;
}

/* Stored and new trials of backend i, read back from the two trials.csv
 * files so both sides have the file's precision. */
static int regress_read(const regress_args *a, const regress_run *run, int i,
                        bsim_sweep_result r[2])
{
	const char *dirs[2] = {a->baseline, a->stage};
	for (int k = 0; k < 2; k++) {
		char path[1200], sub[1100];
		bsim_error err;
		const char *dir = dirs[k];
		if (run->rec.n_backends == 2) {
			char name[128];
			cli_label_dir(run->rec.label[i], name, sizeof name);
			if (cli_path(sub, sizeof sub, dirs[k], name))
				return CLI_FAIL;
			dir = sub;
		}
		if (cli_path(path, sizeof path, dir, "trials.csv"))
			return CLI_FAIL;
		if (bsim_output_trials_read(path, run->e.n_groups, run->e.trials, &r[k], &err) !=
		    BSIM_OK) {
			if (k == 1)
				bsim_sweep_result_free(&r[0]);
			cli_error("%s", err.msg);
			return err.code;
		}
	}
	return CLI_OK;
}

typedef struct regress_part {
	bsim_sweep_result r[2];
	bsim_comparison cmp;
	bsim_report rep;
	int changed; /* trials not identical in every field both files hold */
} regress_part;

/* The groups without random draws, from their scenes: each is one trial,
 * compared as one pair (beamsim/compare.h). */
static int mark_deterministic(const bsim_experiment *e, bsim_sweep_result r[2])
{
	for (int g = 0; g < e->n_groups; g++) {
		bsim_scene s;
		bsim_error err;
		if (bsim_experiment_group_scene(e, g, NULL, 0, &s, &err) != BSIM_OK)
			return cli_report(err.code, &err);
		int det = !bsim_effects_random(&s);
		bsim_scene_free(&s);
		r[0].groups[g].deterministic = r[1].groups[g].deterministic = det;
	}
	return CLI_OK;
}

static int trials_changed(const bsim_sweep_result r[2])
{
	int changed = 0, ledger = r[0].has_ledger && r[1].has_ledger;
	for (long i = 0; i < (long)r[0].n_groups * r[0].trials; i++)
		changed +=
		        !bsim_compare_identical(&r[0].trials_out[i], &r[1].trials_out[i], ledger);
	return changed;
}

static void regress_md(FILE *f, const regress_args *a, const regress_run *run, regress_part *parts)
{
	fprintf(f,
	        "# beamsim regress\n\nBaseline `%s` (%s by beamsim %s), rerun `%s` by beamsim "
	        "%s: experiment `%s`, seed %llu, %d groups x %d trials.\n\n",
	        a->baseline, run->rec.command, run->rec.version, a->out, BSIM_VERSION, run->e.path,
	        (unsigned long long)run->e.seed, run->e.n_groups, run->e.trials);
	for (int i = 0; i < run->rec.n_backends; i++) {
		fprintf(f, "## %s\n\n%d of %d trials changed in some trials.csv field.\n\n",
		        run->rec.label[i], parts[i].changed, run->e.n_groups * run->e.trials);
		bsim_report_md(f, &parts[i].rep);
	}
}

static void regress_json(FILE *f, const regress_run *run, regress_part *parts)
{
	fputs("{\"baseline_version\": ", f);
	bsim_json_string(f, run->rec.version);
	fputs(", \"version\": ", f);
	bsim_json_string(f, BSIM_VERSION);
	fputs(", \"backends\": [\n", f);
	for (int i = 0; i < run->rec.n_backends; i++) {
		fputs(i ? ",\n" : "", f);
		bsim_report_json(f, &parts[i].rep);
	}
	fputs("]}\n", f);
}

static int regress_write(const regress_args *a, const regress_run *run, regress_part *parts)
{
	char md[1100], js[1100];
	bsim_atomic_file o;
	bsim_error err;
	if (cli_path(md, sizeof md, a->stage, "regress.md") ||
	    cli_path(js, sizeof js, a->stage, "regress.json"))
		return CLI_FAIL;
	int rc = bsim_atomic_file_open(&o, js, &err);
	if (rc == BSIM_OK) {
		regress_json(o.f, run, parts);
		rc = bsim_atomic_file_commit(&o, &err);
	}
	if (rc == BSIM_OK)
		rc = bsim_atomic_file_open(&o, md, &err);
	if (rc == BSIM_OK) {
		regress_md(o.f, a, run, parts);
		rc = bsim_atomic_file_commit(&o, &err);
	}
	return rc == BSIM_OK ? CLI_OK : cli_report(CLI_FAIL, &err);
}

static int regress_compare(const regress_args *a, regress_run *run)
{
	regress_part parts[2];
	int n = 0, rc = CLI_OK, beyond = 0;
	memset(parts, 0, sizeof parts);
	for (; n < run->rec.n_backends && rc == CLI_OK; n++) {
		bsim_error err;
		regress_part *p = &parts[n];
		rc = regress_read(a, run, n, p->r);
		if (rc == CLI_OK)
			rc = mark_deterministic(&run->e, p->r);
		if (rc != CLI_OK)
			break;
		p->changed = trials_changed(p->r);
		if (bsim_compare_analyse(&p->r[0], &p->r[1], NULL, &run->rule, &p->cmp, &err) !=
		    BSIM_OK)
			rc = cli_report(CLI_FAIL, &err);
		int side_b = n == 1 && run->rec.protocol[1][0];
		p->rep = (bsim_report){
		        .e = &run->e,
		        .extra = side_b ? &run->protocol_b : NULL,
		        .n_extra = side_b,
		        .side = {{"baseline", run->backend[n], &run->rec.opts[n], &p->r[0]},
		                 {"rerun", run->backend[n], &run->rec.opts[n], &p->r[1]}},
		        .cmp = &p->cmp,
		        .examples = 3,
		};
		beyond += p->cmp.n_disagree;
	}
	if (rc == CLI_OK)
		rc = regress_write(a, run, parts);
	if (rc == CLI_OK && !a->quiet) {
		for (int i = 0; i < n; i++) {
			printf("%s: %d of %d trials changed, %d of %d groups beyond tolerance\n",
			       run->rec.label[i], parts[i].changed, run->e.n_groups * run->e.trials,
			       parts[i].cmp.n_disagree, parts[i].cmp.n_groups);
		}
		printf("wrote %s/regress.md and %s/regress.json\n", a->out, a->out);
	}
	for (int i = 0; i < 2; i++) {
		bsim_sweep_result_free(&parts[i].r[0]);
		bsim_sweep_result_free(&parts[i].r[1]);
		bsim_compare_free(&parts[i].cmp);
	}
	return rc != CLI_OK ? rc : beyond > 0 ? CLI_DISAGREE : CLI_OK;
}

int cmd_regress(int argc, char **argv)
{
	regress_args a = {.alpha = -1.0, .margin = -1.0};
	int rc = regress_parse(argc, argv, &a);
	if (rc >= 0)
		return rc;
	regress_run run;
	memset(&run, 0, sizeof run);
	rc = regress_load(&a, &run);
	cli_session ss;
	if (rc == CLI_OK)
		rc = cli_session_open(&ss, a.out, 0, NULL, 0, argc, argv);
	if (rc == CLI_OK) {
		a.stage = ss.stage;
		rc = regress_rerun(&a, &run);
		int beyond = CLI_OK;
		if (rc == CLI_OK)
			rc = regress_compare(&a, &run);
		if (rc == CLI_DISAGREE) { /* a finding: the files are written all the same */
			beyond = rc;
			rc = CLI_OK;
		}
		rc = cli_session_close(&ss, rc, "regress");
		if (rc == CLI_OK)
			rc = beyond;
	}
	bsim_experiment_free(&run.e);
	return rc;
}
