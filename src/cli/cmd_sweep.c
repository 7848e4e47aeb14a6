/* beamsim sweep: every group and trial of an experiment, in parallel, into
 * DIR/summary.json and DIR/trials.csv, with the p_traverse table on stdout. */
#define _POSIX_C_SOURCE 200809L

#include <getopt.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "beamsim/output.h"
#include "beamsim/sweep.h"
#include "cli_common.h"
#include "cli_store.h"

static const char sweep_help[] =
        "Usage: beamsim sweep EXPERIMENT --out DIR [OPTIONS]\n"
        "\n"
        "Runs every trial of every group of the experiment file EXPERIMENT and writes\n"
        "DIR/summary.json (per-group counts, p_traverse and its 95% Wilson interval)\n"
        "and DIR/trials.csv (one row per trial). The results do not depend on --threads.\n"
        "DIR/run.json and DIR/inputs/ record the run, so `beamsim regress DIR` can\n"
        "repeat it. A group without random force is deterministic: its one trial runs\n"
        "once and fills every row. Unstable trials (non-finite state, or energy\n"
        "created beyond the ledger's bound) are counted and written like the others,\n"
        "and make the exit status 1. The files appear together when the sweep is done\n"
        "(DIR/manifest.json lists them); finished trials are journaled as they end, so a\n"
        "stopped or killed sweep continues with --resume and gives the same files.\n"
        "\n"
        "Options:\n"
        "  --out DIR              output directory, created if missing (required)\n"
        "  --backend B            physics backend (default thesis; see beamsim backends)\n"
        "  --backend-opt K=V      a backend option, repeatable\n"
        "  --threads N            worker threads (default: all cores)\n"
        "  --trials N             trials per group (default: the experiment's)\n"
        "  --seed N               experiment seed (default: the experiment's)\n"
        "  --set KEY=VALUE        override a scene field in every group, repeatable\n"
        "  --overlap              measure each trial's deepest body-beam overlap\n"
        "                         (trials.csv overlap_max; costs time)\n"
        "  --trajectories N       keep the trajectories of the first N trials of each\n"
        "                         group in DIR/trajectories.csv (and .mat), for\n"
        "                         `beamsim plot DIR`\n"
        "  --trajectory-stride N  a trajectory row every N steps (default 5)\n"
        "  --quiet                no progress line, nothing on stdout\n"
        "  --resume               continue the stopped run in DIR (same inputs)\n" CLI_LIMIT_HELP
        "  -h, --help             show this help\n"
        "\n"
        "A lattice experiment also writes DIR/lattice_map.csv, final_locations.csv,\n"
        "transitions.csv, gate_entries.csv and beam_peaks.csv (docs/lattice.md).\n";

enum {
	OPT_BACKEND = 256,
	OPT_BACKEND_OPT,
	OPT_THREADS,
	OPT_TRIALS,
	OPT_SEED,
	OPT_SET,
	OPT_OUT,
	OPT_OVERLAP,
	OPT_QUIET,
	OPT_TRAJECTORIES,
	OPT_TRAJECTORY_STRIDE,
	OPT_LIMIT,
	OPT_RESUME
};

static const struct option sweep_options[] = {
        {"backend", required_argument, NULL, OPT_BACKEND},
        {"backend-opt", required_argument, NULL, OPT_BACKEND_OPT},
        {"threads", required_argument, NULL, OPT_THREADS},
        {"trials", required_argument, NULL, OPT_TRIALS},
        {"seed", required_argument, NULL, OPT_SEED},
        {"set", required_argument, NULL, OPT_SET},
        {"out", required_argument, NULL, OPT_OUT},
        {"overlap", no_argument, NULL, OPT_OVERLAP},
        {"quiet", no_argument, NULL, OPT_QUIET},
        {"trajectories", required_argument, NULL, OPT_TRAJECTORIES},
        {"trajectory-stride", required_argument, NULL, OPT_TRAJECTORY_STRIDE},
        {"limit", required_argument, NULL, OPT_LIMIT},
        {"resume", no_argument, NULL, OPT_RESUME},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
};

typedef struct sweep_args {
	const char *experiment;
	const char *backend;
	bsim_options opts;
	long threads; /* 0: all */
	long trials;  /* 0: the experiment's */
	int has_seed;
	uint64_t seed;
	cli_sets sets;
	const char *out;
	int overlap;
	int quiet;
	long keep, keep_stride;
	int resume;
	int argc; /* the command line, for the line that resumes it */
	char **argv;
} sweep_args;

/* Fills a; returns -1 to go on, else the exit status. */
static int sweep_parse(int argc, char **argv, sweep_args *a)
{
	int c;
	opterr = 0;
	while ((c = getopt_long(argc, argv, ":h", sweep_options, NULL)) != -1) {
		int rc = CLI_OK;
		switch (c) {
		case 'h':
			fputs(sweep_help, stdout);
			return CLI_OK;
		case OPT_BACKEND:
			a->backend = optarg;
			break;
		case OPT_BACKEND_OPT:
			rc = cli_options_add(&a->opts, "sweep", optarg);
			break;
		case OPT_THREADS:
			if (cli_parse_long(optarg, 1, 4096, &a->threads) != 0)
				rc = cli_usage("sweep", "--threads %s: expected an integer >= 1",
				               optarg);
			break;
		case OPT_TRIALS:
			if (cli_parse_long(optarg, 1, INT32_MAX, &a->trials) != 0)
				rc = cli_usage("sweep", "--trials %s: expected an integer >= 1",
				               optarg);
			break;
		case OPT_SEED:
			if (cli_parse_u64(optarg, &a->seed) != 0)
				rc = cli_usage("sweep", "--seed %s: expected an integer >= 0",
				               optarg);
			a->has_seed = 1;
			break;
		case OPT_SET:
			rc = cli_sets_add(&a->sets, "sweep", optarg);
			break;
		case OPT_OUT:
			a->out = optarg;
			break;
		case OPT_OVERLAP:
			a->overlap = 1;
			break;
		case OPT_QUIET:
			a->quiet = 1;
			break;
		case OPT_TRAJECTORIES:
			if (cli_parse_long(optarg, 0, INT32_MAX, &a->keep) != 0)
				rc = cli_usage("sweep",
				               "--trajectories %s: expected an integer >= 0",
				               optarg);
			break;
		case OPT_TRAJECTORY_STRIDE:
			if (cli_parse_long(optarg, 1, INT32_MAX, &a->keep_stride) != 0)
				rc = cli_usage("sweep",
				               "--trajectory-stride %s: expected an integer >= 1",
				               optarg);
			break;
		case OPT_LIMIT:
			rc = cli_limit("sweep", optarg);
			break;
		case OPT_RESUME:
			a->resume = 1;
			break;
		default:
			return cli_bad_option("sweep", argv, c);
		}
		if (rc != CLI_OK)
			return rc;
	}
	if (optind + 1 != argc)
		return cli_usage("sweep",
		                 optind == argc ? "missing EXPERIMENT"
		                                : "expected one EXPERIMENT, got %d",
		                 argc - optind);
	a->experiment = argv[optind];
	if (!a->out)
		return cli_usage("sweep", "--out DIR is required");
	if (strlen(a->out) > 1000) /* DIR/summary.json must fit the path buffers */
		return cli_usage("sweep", "--out DIR is longer than 1000 characters");
	return -1;
}

static void sweep_report(const sweep_args *a, const bsim_experiment *e, const bsim_sweep_result *r,
                         int threads)
{
	long n = r->trials_run, rows = (long)r->n_groups * r->trials;
	bsim_output_table(stdout, e, r);
	printf("\n%ld trials, %ld steps in %.3f s on %d thread%s: %.0f trials/s, %.3g steps/s\n", n,
	       r->total_steps, r->wall_seconds, threads, threads == 1 ? "" : "s",
	       cli_per_second(n, r->wall_seconds), cli_per_second(r->total_steps, r->wall_seconds));
	if (n != rows)
		printf("(%ld rows: the groups without random force ran one trial each)\n", rows);
	printf("wrote %s/summary.json and %s/trials.csv%s (and their .mat twins)\n", a->out, a->out,
	       r->keep ? ", trajectories.csv" : "");
}

/* Unstable trials fail the sweep (after its files are written): one line
 * with their number and the first one's reason and replay. */
static int sweep_unstable(const sweep_args *a, const bsim_experiment *e,
                          const bsim_backend *backend, const bsim_sweep_result *r)
{
	long count = 0, first = -1;
	for (long i = 0; i < (long)r->n_groups * r->trials; i++)
		if (r->trials_out[i].outcome == BSIM_UNSTABLE) {
			count++;
			first = first < 0 ? i : first;
		}
	if (count == 0)
		return CLI_OK;
	bsim_scene scene;
	bsim_error err;
	char why[256] = "";
	long g = first / r->trials, t = first % r->trials;
	if (bsim_experiment_group_scene(e, (int)g, a->sets.ov, a->sets.n, &scene, &err) ==
	    BSIM_OK) {
		bsim_trial_instability_text(&r->trials_out[first], scene.dt, why, sizeof why);
		bsim_scene_free(&scene);
	}
	cli_error("%ld of %ld trials unstable on the %s backend (outcome unstable in "
	          "%s/trials.csv); the first, group %ld trial %ld: %s",
	          count, (long)r->n_groups * r->trials, backend->name, a->out, g, t, why);
	return CLI_FAIL;
}

/* Loads, opens DIR (before the run, so an unusable DIR fails at once, not
 * after hours) with the journal, runs, writes into the staging area and
 * commits. A failed or stopped sweep leaves DIR as it was. */
static int sweep_main(const sweep_args *a, const bsim_backend *backend)
{
	bsim_experiment e;
	bsim_error err;
	int rc = cli_experiment_load(a->experiment, &a->sets, a->trials, &e);
	if (rc != CLI_OK)
		return rc;
	if (a->has_seed)
		e.seed = a->seed;
	bsim_run_record rec;
	const bsim_options *opts = &a->opts;
	cli_record_fill(&rec, "sweep", &e, 1, &backend, &opts, NULL, NULL);
	char *inputs = bsim_run_record_inputs(&rec, &e, a->sets.ov, a->sets.n, &err);
	/* --overlap adds a column to every trial: a run measured so continues so. */
	if (inputs && a->overlap)
		inputs = cli_text_append(inputs, "measure_overlap 1\n");
	cli_session ss;
	rc = inputs ? cli_session_open(&ss, a->out, a->resume, inputs, bsim_sweep_record_size(0),
	                               a->argc, a->argv)
	            : cli_report(err.code, &err);
	free(inputs);
	if (rc != CLI_OK) {
		bsim_experiment_free(&e);
		return rc;
	}
	int threads = a->threads > 0 ? (int)a->threads : omp_get_max_threads();
	bsim_sweep_config cfg = {
	        .backend = backend,
	        .opts = &a->opts,
	        .threads = threads,
	        .extra = a->sets.ov,
	        .n_extra = a->sets.n,
	        .measure_overlap = a->overlap,
	        .keep = (int)a->keep,
	        .keep_stride = (int)a->keep_stride,
	        .journal = ss.journal,
	        .stop = &cli_stop,
	};
	bsim_sweep_result r;
	rc = cli_sweep_run(&e, &cfg, !a->quiet, &r);
	if (rc == CLI_OK) {
		rc = cli_store_sweep(ss.stage, &e, backend, &a->opts, a->sets.ov, a->sets.n, &r);
		rc = cli_session_close(&ss, rc, "sweep");
		if (rc == CLI_OK && !a->quiet)
			sweep_report(a, &e, &r, threads);
		if (rc == CLI_OK)
			rc = sweep_unstable(a, &e, backend, &r);
		bsim_sweep_result_free(&r);
	} else {
		rc = cli_session_close(&ss, rc, "sweep");
	}
	bsim_experiment_free(&e);
	return rc;
}

int cmd_sweep(int argc, char **argv)
{
	sweep_args a = {.backend = "thesis", .argc = argc, .argv = argv};
	int rc = sweep_parse(argc, argv, &a);
	if (rc < 0) {
		const bsim_backend *backend = cli_backend(a.backend, &a.opts);
		rc = backend ? sweep_main(&a, backend) : CLI_USAGE;
	}
	cli_sets_free(&a.sets);
	return rc;
}
