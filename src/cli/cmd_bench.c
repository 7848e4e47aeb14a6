/* beamsim bench: the speed of a backend on the essay's experiments, on one
 * thread and on all of them, the wall time of H1 + H2 together, and the
 * speed of a second backend on the same H1 trials (same scenes, same time
 * step, same schedules) with the ratio of the two. */
#define _POSIX_C_SOURCE 200809L

#include <getopt.h>
#include <omp.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "atomic_file.h"
#include "json.h"
#include "beamsim/output.h"
#include "beamsim/sweep.h"
#include "bench_lattice.h"
#include "cli_common.h"

#define BENCH_H1 "configs/thesis/h1_symmetric.yaml"
#define BENCH_H2 "configs/thesis/h2_asymmetric.yaml"

/* Where the tables go: standard output, or standard error when the JSON
 * goes to standard output (--json -). */
static FILE *report;

static const char bench_help[] =
        "Usage: beamsim bench [OPTIONS]\n"
        "\n"
        "Runs an experiment (default " BENCH_H1 ") on one thread and\n"
        "on all threads and reports wall time, steps/s, trials/s and steps/s per core;\n"
        "then runs " BENCH_H2 " on all threads and reports the\n"
        "wall time of H1 + H2. Then runs the experiment on one thread with a second\n"
        "backend (--vs, default box2d) at the same time step and prints how many\n"
        "times faster the first is, per step and per trial. The default experiment\n"
        "paths are relative to the current directory (run it from the source tree).\n"
        "\n"
        "Options:\n"
        "  --backend B            physics backend (default thesis; see beamsim backends)\n"
        "  --backend-opt K=V      a backend option, repeatable\n"
        "  --experiment FILE      benchmark this experiment instead of H1 (no H2 step)\n"
        "  --trials N             trials per group (default: the experiment's)\n"
        "  --no-h2                skip the H1 + H2 step\n"
        "  --vs B                 the backend to compare speed with (default box2d;\n"
        "                         none: skip)\n"
        "  --vs-opt K=V           an option of the --vs backend, repeatable\n"
        "  --json FILE            also write the results as JSON to FILE\n"
        "  --lattice              instead: ns per step on n x n gate lattices, n = 1 .. 33,\n"
        "                         on --backend and --vs, the same schedules at every\n"
        "                         size (--trials per size, default 200; the --vs\n"
        "                         backend a twentieth of it, default 10)\n"
        "  -h, --help             show this help\n";

enum {
	OPT_BACKEND = 256,
	OPT_BACKEND_OPT,
	OPT_EXPERIMENT,
	OPT_TRIALS,
	OPT_NO_H2,
	OPT_VS,
	OPT_VS_OPT,
	OPT_JSON,
	OPT_LATTICE
};

static const struct option bench_options[] = {
        {"backend", required_argument, NULL, OPT_BACKEND},
        {"backend-opt", required_argument, NULL, OPT_BACKEND_OPT},
        {"experiment", required_argument, NULL, OPT_EXPERIMENT},
        {"trials", required_argument, NULL, OPT_TRIALS},
        {"no-h2", no_argument, NULL, OPT_NO_H2},
        {"vs", required_argument, NULL, OPT_VS},
        {"vs-opt", required_argument, NULL, OPT_VS_OPT},
        {"json", required_argument, NULL, OPT_JSON},
        {"lattice", no_argument, NULL, OPT_LATTICE},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
};

typedef struct bench_args {
	const char *backend;
	bsim_options opts;
	const char *experiment;
	int custom; /* --experiment given */
	long trials;
	int h2;
	const char *vs; /* NULL: none */
	bsim_options vs_opts;
	const char *json;
	int lattice;
} bench_args;

typedef struct bench_run {
	const char *experiment;
	int threads;
	long trials, steps;
	double wall;
} bench_run;

#define BENCH_RUNS_MAX 4

/* Fills a; returns -1 to go on, else the exit status. */
static int bench_parse(int argc, char **argv, bench_args *a)
{
	int c;
	opterr = 0;
	while ((c = getopt_long(argc, argv, ":h", bench_options, NULL)) != -1) {
		int rc = CLI_OK;
		switch (c) {
		case 'h':
			fputs(bench_help, stdout);
			return CLI_OK;
		case OPT_BACKEND:
			a->backend = optarg;
			break;
		case OPT_BACKEND_OPT:
			rc = cli_options_add(&a->opts, "bench", optarg);
			break;
		case OPT_EXPERIMENT:
			a->experiment = optarg;
			a->custom = 1;
			break;
		case OPT_TRIALS:
			if (cli_parse_long(optarg, 1, INT32_MAX, &a->trials) != 0)
				rc = cli_usage("bench", "--trials %s: expected an integer >= 1",
				               optarg);
			break;
		case OPT_NO_H2:
			a->h2 = 0;
			break;
		case OPT_VS:
			a->vs = strcmp(optarg, "none") == 0 ? NULL : optarg;
			break;
		case OPT_VS_OPT:
			rc = cli_options_add(&a->vs_opts, "bench", optarg);
			break;
		case OPT_JSON:
			a->json = optarg;
			break;
		case OPT_LATTICE:
			a->lattice = 1;
			break;
		default:
			return cli_bad_option("bench", argv, c);
		}
		if (rc != CLI_OK)
			return rc;
	}
	if (optind != argc)
		return cli_usage("bench", "unexpected argument %s", argv[optind]);
	/* H1 + H2 is the essay's pair; it means nothing for another file. */
	if (a->custom)
		a->h2 = 0;
	return -1;
}

/* The default experiments are found relative to the current directory. */
static int bench_find(const char *path)
{
	if (access(path, R_OK) == 0)
		return CLI_OK;
	cli_error("%s not found: run beamsim bench from the source tree, or pass "
	          "--experiment FILE",
	          path);
	return CLI_USAGE;
}

static void bench_print_header(void)
{
	fprintf(report, "%-36s %7s %7s %12s %9s %10s %9s %13s\n", "experiment", "threads", "trials",
	        "steps", "wall s", "steps/s", "trials/s", "steps/s/core");
}

static void bench_print_run(const bench_run *r)
{
	double steps_per_second = cli_per_second(r->steps, r->wall);
	fprintf(report, "%-36s %7d %7ld %12ld %9.3f %10.4g %9.1f %13.4g\n", r->experiment,
	        r->threads, r->trials, r->steps, r->wall, steps_per_second,
	        cli_per_second(r->trials, r->wall), steps_per_second / r->threads);
	fflush(report);
}

/* One sweep of e on the given threads, timed. label (the path as given)
 * outlives e. */
static int bench_sweep(const bsim_backend *backend, const bsim_options *opts,
                       const bsim_experiment *e, const char *label, int threads, bench_run *out)
{
	bsim_sweep_config cfg = {.backend = backend, .opts = opts, .threads = threads};
	bsim_sweep_result r;
	int rc = cli_sweep_run(e, &cfg, 1, &r);
	if (rc != CLI_OK)
		return rc;
	*out = (bench_run){
	        .experiment = label,
	        .threads = threads,
	        .trials = r.trials_run,
	        .steps = r.total_steps,
	        .wall = r.wall_seconds,
	};
	bsim_sweep_result_free(&r);
	bench_print_run(out);
	return CLI_OK;
}

/* Runs e on each of the thread counts, appending to runs. */
static int bench_experiment(const bench_args *a, const bsim_backend *backend,
                            const bsim_experiment *e, const char *path, const int *threads,
                            int n_threads, bench_run *runs, int *n_runs)
{
	int rc = CLI_OK;
	for (int i = 0; i < n_threads && rc == CLI_OK; i++) {
		rc = bench_sweep(backend, &a->opts, e, path, threads[i], &runs[*n_runs]);
		*n_runs += rc == CLI_OK;
	}
	return rc;
}

static void bench_json_run(FILE *f, const bench_run *r)
{
	fputs("{\"experiment\": ", f);
	bsim_json_string(f, r->experiment);
	fprintf(f, ", \"threads\": %d, \"trials\": %ld, \"steps\": %ld, \"wall_seconds\": ",
	        r->threads, r->trials, r->steps);
	bsim_json_number(f, r->wall);
	fputs(", \"steps_per_second\": ", f);
	bsim_json_number(f, cli_per_second(r->steps, r->wall));
	fputs(", \"trials_per_second\": ", f);
	bsim_json_number(f, cli_per_second(r->trials, r->wall));
	fputc('}', f);
}

/* How many times faster per step the first run is than the second. */
static double bench_speedup_per_step(const bench_run *mine, const bench_run *theirs)
{
	return cli_per_second(mine->steps, mine->wall) /
	       cli_per_second(theirs->steps, theirs->wall);
}

/* h1_h2 < 0: no H1 + H2 step, written as null. vs: the second backend,
 * whose run is the last of runs (NULL: none). */
static void bench_json_write(FILE *f, const bench_args *a, const bsim_backend *backend,
                             const bsim_backend *vs, int threads, const bench_run *runs, int n_runs,
                             double h1_h2)
{
	fputs("{\"backend\": ", f);
	bsim_json_string(f, a->backend);
	fputs(", \"options\": ", f);
	bsim_output_backend_options(f, backend, &a->opts);
	fprintf(f, ", \"threads\": %d, \"runs\": [", threads);
	for (int i = 0; i < n_runs; i++) {
		fputs(i ? ",\n  " : "\n  ", f);
		bench_json_run(f, &runs[i]);
	}
	fputs("],\n \"h1_h2_seconds\": ", f);
	if (h1_h2 >= 0)
		bsim_json_number(f, h1_h2);
	else
		fputs("null", f);
	fputs(",\n \"vs\": ", f);
	if (vs) {
		const bench_run *mine = &runs[0], *theirs = &runs[n_runs - 1];
		fputs("{\"backend\": ", f);
		bsim_json_string(f, vs->name);
		fputs(", \"options\": ", f);
		bsim_output_backend_options(f, vs, &a->vs_opts);
		fputs(", \"run\": ", f);
		bench_json_run(f, theirs);
		fputs(", \"speedup_per_step\": ", f);
		bsim_json_number(f, bench_speedup_per_step(mine, theirs));
		fputs(", \"speedup_per_trial\": ", f);
		bsim_json_number(f, theirs->wall / mine->wall);
		fputc('}', f);
	} else {
		fputs("null", f);
	}
	fputs("}\n", f);
}

static int bench_json(const bench_args *a, const bsim_backend *backend, const bsim_backend *vs,
                      int threads, const bench_run *runs, int n_runs, double h1_h2)
{
	bsim_atomic_file o;
	bsim_error err;
	if (bsim_atomic_file_open(&o, a->json, &err) != BSIM_OK)
		return cli_report(BSIM_EFAIL, &err);
	bench_json_write(o.f, a, backend, vs, threads, runs, n_runs, h1_h2);
	return cli_report(bsim_atomic_file_commit(&o, &err), &err);
}

/* Both experiments are loaded before anything runs, so a bad file fails
 * at once rather than after the first timing. */
/* The second backend on the first run's trials: one thread each, so the
 * ratio compares the solvers, not the scheduling. */
static int bench_vs(const bench_args *a, const bsim_backend *vs, const bsim_experiment *h1,
                    bench_run *runs, int *n_runs)
{
	fprintf(report, "\nbackend %s, 1 thread\n\n", vs->name);
	bench_print_header();
	int rc = bench_sweep(vs, &a->vs_opts, h1, a->experiment, 1, &runs[*n_runs]);
	if (rc != CLI_OK)
		return rc;
	const bench_run *mine = &runs[0], *theirs = &runs[*n_runs];
	(*n_runs)++;
	fprintf(report,
	        "\n%s is %.1f times faster than %s per step and %.1f times per trial "
	        "(%s, same time step, 1 thread)\n",
	        a->backend, bench_speedup_per_step(mine, theirs), vs->name,
	        theirs->wall / mine->wall, a->experiment);
	return CLI_OK;
}

static int bench_main(const bench_args *a, const bsim_backend *backend, const bsim_backend *vs)
{
	int all = omp_get_max_threads();
	bsim_experiment h1, h2;
	/* A file given with --experiment is reported by the loader. */
	int rc = a->custom ? CLI_OK : bench_find(a->experiment);
	if (rc == CLI_OK && a->h2)
		rc = bench_find(BENCH_H2);
	if (rc == CLI_OK)
		rc = cli_experiment_load(a->experiment, NULL, a->trials, &h1);
	if (rc != CLI_OK)
		return rc;
	if (a->h2 && (rc = cli_experiment_load(BENCH_H2, NULL, a->trials, &h2)) != CLI_OK) {
		bsim_experiment_free(&h1);
		return rc;
	}

	bench_run runs[BENCH_RUNS_MAX];
	int n_runs = 0;
	const int h1_threads[] = {1, all};
	fprintf(report, "backend %s, %d threads\n\n", a->backend, all);
	bench_print_header();
	rc = bench_experiment(a, backend, &h1, a->experiment, h1_threads, 2, runs, &n_runs);
	if (rc == CLI_OK && a->h2)
		rc = bench_experiment(a, backend, &h2, BENCH_H2, &all, 1, runs, &n_runs);
	/* The all-threads H1 run above is the H1 half of H1 + H2. */
	double h1_h2 = -1.0;
	if (rc == CLI_OK && a->h2) {
		h1_h2 = runs[1].wall + runs[2].wall;
		fprintf(report, "\nH1 + H2 on %d threads: %.3f s\n", all, h1_h2);
	}
	if (rc == CLI_OK && vs)
		rc = bench_vs(a, vs, &h1, runs, &n_runs);
	bsim_experiment_free(&h1);
	if (a->h2)
		bsim_experiment_free(&h2);
	if (rc != CLI_OK)
		return rc;
	return a->json ? bench_json(a, backend, vs, all, runs, n_runs, h1_h2) : CLI_OK;
}

int cmd_bench(int argc, char **argv)
{
	bench_args a = {.backend = "thesis", .experiment = BENCH_H1, .h2 = 1, .vs = "box2d"};
	int rc = bench_parse(argc, argv, &a);
	if (rc >= 0)
		return rc;
	const bsim_backend *backend = cli_backend(a.backend, &a.opts);
	const bsim_backend *vs = backend && a.vs ? cli_backend(a.vs, &a.vs_opts) : NULL;
	if (!backend || (a.vs && !vs))
		return CLI_USAGE;
	report = a.json && strcmp(a.json, "-") == 0 ? stderr : stdout;
	if (a.lattice) {
		bench_lattice_args la = {
		        .backend = backend,
		        .vs = vs,
		        .opts = &a.opts,
		        .vs_opts = &a.vs_opts,
		        .trials = a.trials,
		        .vs_trials = a.trials > 0 ? (a.trials + 19) / 20 : 0,
		        .json = a.json,
		        .report = report,
		};
		return bench_lattice(&la);
	}
	return bench_main(&a, backend, vs);
}
