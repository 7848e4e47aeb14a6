/* beamsim bench: the speed of a backend on the essay's experiments, on one
 * thread and on all of them, the wall time of H1 + H2 together, and the
 * speed of a second backend on the same H1 trials (same scenes, same time
 * step, same schedules) with the ratio of the two. */
#define _POSIX_C_SOURCE 200809L

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
#include "cli_options.h"

#define BENCH_H1 "configs/thesis/h1_symmetric.yaml"
#define BENCH_H2 "configs/thesis/h2_asymmetric.yaml"

/* Where the tables go: standard output, or standard error when the JSON
 * goes to standard output (--json -). */
static FILE *report;

enum { OWN_EXPERIMENT, OWN_NO_H2, OWN_VS, OWN_VS_OPT, OWN_JSON, OWN_LATTICE };

static const cli_own bench_own[] = {
        [OWN_EXPERIMENT] = {"experiment", 1, "FILE",
                            "benchmark this experiment instead of H1 (no H2 step)"},
        [OWN_NO_H2] = {"no-h2", 0, NULL, "skip the H1 + H2 step"},
        [OWN_VS] = {"vs", 1, "B", "the backend to compare speed with (default box2d;\nnone: skip)"},
        [OWN_VS_OPT] = {"vs-opt", 1, "K=V", "an option of the --vs backend, repeatable"},
        [OWN_JSON] = {"json", 1, "FILE", "also write the results as JSON to FILE"},
        [OWN_LATTICE] = {"lattice", 0, NULL,
                         "instead: ns per step on n x n gate lattices, n = 1 .. 33,\n"
                         "on --backend and --vs, the same schedules at every\n"
                         "size (--trials per size, default 200; the --vs\n"
                         "backend a twentieth of it, default 10)"},
};

static const char *const bench_help[CLI_N_OPTS] = {
        [CLI_OPT_BACKEND_OPT] = "an option of --backend, repeatable (--vs-opt for --vs)",
};

typedef struct bench_args {
	const char *backend; /* --backend */
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

static int bench_option(void *args, int i, const char *value)
{
	bench_args *a = args;
	switch (i) {
	case OWN_EXPERIMENT:
		a->experiment = value;
		a->custom = 1;
		/* H1 + H2 is the essay's pair; it means nothing for another file. */
		a->h2 = 0;
		return CLI_OK;
	case OWN_NO_H2:
		a->h2 = 0;
		return CLI_OK;
	case OWN_VS:
		a->vs = strcmp(value, "none") == 0 ? NULL : value;
		return CLI_OK;
	case OWN_VS_OPT:
		return cli_options_add(&a->vs_opts, "bench", value);
	case OWN_JSON:
		a->json = value;
		return CLI_OK;
	case OWN_LATTICE:
		a->lattice = 1;
		return CLI_OK;
	}
	return CLI_USAGE;
}

static const cli_spec bench_spec = {
        .name = "bench",
        .usage = "[OPTIONS]",
        .about = "Runs an experiment (default " BENCH_H1 ") on one thread and\n"
                 "on all threads and reports wall time, steps/s, trials/s and steps/s per "
                 "core;\n"
                 "then runs " BENCH_H2 " on all threads and reports the\n"
                 "wall time of H1 + H2. Then runs the experiment on one thread with a second\n"
                 "backend (--vs, default box2d) at the same time step and prints how many\n"
                 "times faster the first is, per step and per trial. The default experiment\n"
                 "paths are relative to the current directory (run it from the source "
                 "tree).\n",
        .common = CLI_USES(CLI_OPT_BACKEND) | CLI_USES(CLI_OPT_BACKEND_OPT) |
                  CLI_USES(CLI_OPT_TRIALS),
        .help = bench_help,
        .own = bench_own,
        .n_own = 6,
        .option = bench_option,
};

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
	cli_common c = cli_common_default();
	bench_args a = {.experiment = BENCH_H1, .h2 = 1, .vs = "box2d"};
	int rc = cli_parse(&bench_spec, argc, argv, &c, &a, NULL);
	a.backend = c.backend ? c.backend : bsim_backend_default()->name;
	a.trials = c.trials;
	/* --backend-opt is --backend's, --vs-opt --vs's. */
	const bsim_backend *backend = NULL, *vs = NULL;
	if (rc < 0 && cli_backend_opts(&c, "bench", 1, &a.backend,
	                               (bsim_options *const[]){&a.opts}) != CLI_OK)
		rc = CLI_USAGE;
	if (rc < 0 && !(backend = cli_backend(a.backend, &a.opts)))
		rc = CLI_USAGE;
	if (rc < 0 && a.vs && !(vs = cli_backend(a.vs, &a.vs_opts)))
		rc = CLI_USAGE;
	cli_common_free(&c);
	if (rc >= 0)
		return rc;
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
