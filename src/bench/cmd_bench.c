/* beamsim bench: the speed of a backend on the essay's experiments, on one
 * thread (--repeat times, with the median) and on all of them, the wall
 * time of H1 + H2 together, free flight against a minimal loop
 * (bench_free.c), and the speed of a second backend on the same H1 trials
 * (same scenes, same time step, same schedules) with the ratio of the two
 * and the share of the second backend's time spent reading the clock for
 * its own profiling (bench_clock.c). */
#define _POSIX_C_SOURCE 200809L

#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "util/atomic_file.h"
#include "util/clock.h"
#include "util/json.h"
#include "beamsim/output.h"
#include "beamsim/sweep.h"
#include "bench/bench_clock.h"
#include "bench/bench_callgrind.h"
#include "bench/bench_free.h"
#include "bench/bench_lattice.h"
#include "bench/bench_memory.h"
#include "cli/cli_common.h"
#include "cli/cli_options.h"

#define BENCH_H1 "configs/thesis/h1_symmetric.yaml"
#define BENCH_H2 "configs/thesis/h2_asymmetric.yaml"

/* Where the tables go: standard output, or standard error when the JSON
 * goes to standard output (--json -). */
static FILE *report;

enum {
	OWN_EXPERIMENT,
	OWN_NO_H2,
	OWN_VS,
	OWN_VS_OPT,
	OWN_JSON,
	OWN_LATTICE,
	OWN_REPEAT,
	OWN_MEMORY,
	OWN_PAIRS,
	OWN_CALLGRIND,
	OWN_MEASURE
};

static const cli_own bench_own[] = {
        [OWN_EXPERIMENT] = {"experiment", 1, "FILE",
                            "benchmark this experiment instead of H1 (no H2 step)"},
        [OWN_NO_H2] = {"no-h2", 0, NULL, "skip the H1 + H2 step"},
        [OWN_VS] = {"vs", 1, "B",
                    "the backend to compare speed with (default {second};\nnone: skip)"},
        [OWN_VS_OPT] = {"vs-opt", 1, "K=V", "an option of the --vs backend, repeatable"},
        [OWN_JSON] = {"json", 1, "FILE", "also write the results as JSON to FILE"},
        [OWN_LATTICE] = {"lattice", 0, NULL,
                         "instead: ns per step on n x n gate lattices, n = 1 .. 33,\n"
                         "on --backend and --vs, the same schedules at every\n"
                         "size (--trials per size, default 200; the --vs\n"
                         "backend a twentieth of it, default 10)"},
        [OWN_REPEAT] = {"repeat", 1, "N",
                        "run the experiment on one thread N times (default 1)\n"
                        "and report the median, minimum and maximum"},
        [OWN_MEMORY] = {"memory", 0, NULL,
                        "instead: peak resident memory of a sweep of --trials\n"
                        "trials (default 2,000,000) and of a tenth of it (without\n"
                        "and with the .mat twin of trials.csv), of run\n"
                        "--trajectory over 1,000,000 and 100,000 steps, of sweep\n"
                        "--grid with 20,000 and 2,000 values and the replay of\n"
                        "its last group, and of a sweep from Python of 200,000\n"
                        "and 20,000 trials (with the module built), each a child\n"
                        "process; the growth per trial, per row, per step and\n"
                        "per value"},
        [OWN_PAIRS] = {"pairs", 1, "N",
                       "after the --vs run, N pairs of one-thread runs of the\n"
                       "experiment, the two backends interleaved (default 5;\n"
                       "0: none): the median of the pairs' ratios per step, by\n"
                       "wall time and by CPU time"},
        [OWN_CALLGRIND] = {"callgrind", 0, NULL,
                           "instead: instructions per step, counted by valgrind's\n"
                           "callgrind in child processes (perf stat's counters are\n"
                           "not offered everywhere): the experiment's sweep, its\n"
                           "free flight and the minimal loop (--trials per group,\n"
                           "default 4, 2, 2), and 1000-step trials on 5 x 5 and\n"
                           "33 x 33 lattices, setup included; each the difference\n"
                           "of runs of T and 2T trials (--backend with its default\n"
                           "options)"},
        [OWN_MEASURE] = {"measure", 1, "WHAT",
                         "run one measure of --callgrind and print its steps\n"
                         "(h1, free, minimal, lattice:N)"},
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
	int memory;
	int repeat; /* one-thread runs of the experiment */
	int pairs;  /* interleaved runs of the two backends */
	int callgrind;
	const char *measure; /* NULL: none */
} bench_args;

typedef struct bench_run {
	const char *experiment;
	int threads;
	long trials, steps;
	double wall;
	double cpu; /* s, the process's CPU time: what other programs' load does not inflate */
} bench_run;

#define BENCH_REPEAT_MAX 100
#define BENCH_PAIRS_MAX  100
#define BENCH_RUNS_MAX   (BENCH_REPEAT_MAX + 3)

/* What the second backend's run spent reading the clock for its own
 * profiling (Box2D's b2Timer; none for the thesis backend). */
typedef struct bench_timers {
	unsigned long reads; /* during its run */
	double read_seconds; /* one read, s */
} bench_timers;

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
	case OWN_MEMORY:
		a->memory = 1;
		return CLI_OK;
	case OWN_CALLGRIND:
		a->callgrind = 1;
		return CLI_OK;
	case OWN_MEASURE:
		a->measure = value;
		return CLI_OK;
	case OWN_PAIRS: {
		char *end;
		long n = strtol(value, &end, 10);
		if (*end || end == value || n < 0 || n > BENCH_PAIRS_MAX) {
			cli_error("bench: --pairs: expected a whole number from 0 to %d, got '%s'",
			          BENCH_PAIRS_MAX, value);
			return CLI_USAGE;
		}
		a->pairs = (int)n;
		return CLI_OK;
	}
	case OWN_REPEAT: {
		char *end;
		long n = strtol(value, &end, 10);
		if (*end || n < 1 || n > BENCH_REPEAT_MAX) {
			cli_error("bench: --repeat: expected a whole number from 1 to %d, got '%s'",
			          BENCH_REPEAT_MAX, value);
			return CLI_USAGE;
		}
		a->repeat = (int)n;
		return CLI_OK;
	}
	}
	return CLI_USAGE;
}

static const cli_spec bench_spec = {
        .name = "bench",
        .usage = "[OPTIONS]",
        .about = "Runs an experiment (default " BENCH_H1 ") on one thread\n"
                 "(--repeat times) and on all threads and reports wall time, steps/s,\n"
                 "trials/s and steps/s per core; then runs " BENCH_H2 " on\n"
                 "all threads and reports the wall time of H1 + H2. Then the experiment as\n"
                 "free flight (the body far below every beam) on one thread against a\n"
                 "minimal loop of the same steps' physics. Then the experiment on one thread\n"
                 "with a second backend (--vs, default {second}) at the same time step: how\n"
                 "many times faster the first is, per step and per trial, and what share of\n"
                 "the second's time went to reading the clock for its own profiling. The\n"
                 "default experiment paths are relative to the current directory (run it\n"
                 "from the source tree).\n",
        .common = CLI_USES(CLI_OPT_BACKEND) | CLI_USES(CLI_OPT_BACKEND_OPT) |
                  CLI_USES(CLI_OPT_TRIALS),
        .help = bench_help,
        .own = bench_own,
        .n_own = 11,
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
	double cpu0 = bsim_clock_process_cpu_seconds();
	int rc = cli_sweep_run(e, &cfg, 1, &r);
	double cpu = bsim_clock_process_cpu_seconds() - cpu0;
	if (rc != CLI_OK)
		return rc;
	*out = (bench_run){
	        .experiment = label,
	        .threads = threads,
	        .trials = r.trials_run,
	        .steps = r.total_steps,
	        .wall = r.wall_seconds,
	        .cpu = cpu,
	};
	bsim_sweep_result_free(&r);
	bench_print_run(out);
	return CLI_OK;
}

static void bench_json_run(FILE *f, const bench_run *r)
{
	fputs("{\"experiment\": ", f);
	bsim_json_string(f, r->experiment);
	fprintf(f, ", \"threads\": %d, \"trials\": %ld, \"steps\": %ld, \"wall_seconds\": ",
	        r->threads, r->trials, r->steps);
	bsim_json_number(f, r->wall);
	fputs(", \"cpu_seconds\": ", f);
	bsim_json_number(f, r->cpu);
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

/* Everything one bench run measured. */
typedef struct bench_results {
	bench_run runs[BENCH_RUNS_MAX]; /* in order: one thread, all, H2, the second backend */
	int n_runs, n_single;
	int median;   /* index of the median one-thread run (by wall time) */
	int all, h2;  /* index of the all-threads H1 and H2 runs, -1: none */
	int vs;       /* index of the second backend's run, -1: none */
	double h1_h2; /* s, < 0: not run */
	int have_free;
	bench_free_result free;
	bench_timers timers;
	/* The interleaved pairs: each pair's ratio per step (first backend's
	 * steps/s over the second's), in the order run. */
	int n_pairs;
	double pair_ratio[BENCH_PAIRS_MAX];
	double pair_ratio_cpu[BENCH_PAIRS_MAX]; /* the same by CPU time per step */
} bench_results;

/* The time the second backend's run spent reading the clock, s. */
static double bench_timer_seconds(const bench_results *b)
{
	return (double)b->timers.reads * b->timers.read_seconds;
}

static void bench_json_free(FILE *f, const bench_free_result *r)
{
	double ns = 1e9 * r->beamsim_seconds / (double)r->steps;
	double ns_min = 1e9 * r->minimal_seconds / (double)r->steps;
	fprintf(f, "{\"trials\": %ld, \"steps\": %ld, \"ns_per_step\": ", r->trials, r->steps);
	bsim_json_number(f, ns);
	fputs(", \"minimal_ns_per_step\": ", f);
	bsim_json_number(f, ns_min);
	fputs(", \"ratio\": ", f);
	bsim_json_number(f, ns / ns_min);
	fputc('}', f);
}

static int cmp_double(const void *x, const void *y)
{
	double a = *(const double *)x, b = *(const double *)y;
	return (a > b) - (a < b);
}

/* The median of the pairs' ratios (the mean of the middle two for an even
 * count). */
static double bench_median(const double *ratio, int n)
{
	double r[BENCH_PAIRS_MAX];
	memcpy(r, ratio, (size_t)n * sizeof *r);
	qsort(r, (size_t)n, sizeof *r, cmp_double);
	return n % 2 ? r[n / 2] : 0.5 * (r[n / 2 - 1] + r[n / 2]);
}

static void bench_json_ratios(FILE *f, const char *name, const double *ratio, int n)
{
	fprintf(f, ", \"%s\": [", name);
	for (int i = 0; i < n; i++) {
		fputs(i ? ", " : "", f);
		bsim_json_number(f, ratio[i]);
	}
	fputc(']', f);
}

static void bench_json_write(FILE *f, const bench_args *a, const bsim_backend *backend,
                             const bsim_backend *vs, int threads, const bench_results *b)
{
	fputs("{\"backend\": ", f);
	bsim_json_string(f, a->backend);
	fputs(", \"options\": ", f);
	bsim_output_backend_options(f, backend, &a->opts);
	fprintf(f, ", \"threads\": %d, \"runs\": [", threads);
	for (int i = 0; i < b->n_runs; i++) {
		fputs(i ? ",\n  " : "\n  ", f);
		bench_json_run(f, &b->runs[i]);
	}
	fprintf(f, "],\n \"repeat\": %d, \"one_thread_median\": ", b->n_single);
	bench_json_run(f, &b->runs[b->median]);
	fputs(",\n \"h1_h2_seconds\": ", f);
	if (b->h1_h2 >= 0)
		bsim_json_number(f, b->h1_h2);
	else
		fputs("null", f);
	fputs(",\n \"free_flight\": ", f);
	if (b->have_free)
		bench_json_free(f, &b->free);
	else
		fputs("null", f);
	fputs(",\n \"vs\": ", f);
	if (vs) {
		const bench_run *mine = &b->runs[b->median], *theirs = &b->runs[b->vs];
		double timer_s = bench_timer_seconds(b);
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
		fprintf(f, ", \"clock_reads\": %lu, \"clock_reads_per_step\": ", b->timers.reads);
		bsim_json_number(f, (double)b->timers.reads / (double)theirs->steps);
		fputs(", \"clock_read_ns\": ", f);
		bsim_json_number(f, 1e9 * b->timers.read_seconds);
		fputs(", \"clock_share\": ", f);
		bsim_json_number(f, timer_s / theirs->wall);
		fputs(", \"speedup_per_trial_without_clock\": ", f);
		bsim_json_number(f, (theirs->wall - timer_s) / mine->wall);
		fprintf(f, ", \"pairs\": %d", b->n_pairs);
		bench_json_ratios(f, "pair_ratios", b->pair_ratio, b->n_pairs);
		fputs(", \"ratio_paired\": ", f);
		if (b->n_pairs > 0)
			bsim_json_number(f, bench_median(b->pair_ratio, b->n_pairs));
		else
			fputs("null", f);
		bench_json_ratios(f, "pair_ratios_cpu", b->pair_ratio_cpu, b->n_pairs);
		fputs(", \"ratio_paired_cpu\": ", f);
		if (b->n_pairs > 0)
			bsim_json_number(f, bench_median(b->pair_ratio_cpu, b->n_pairs));
		else
			fputs("null", f);
		fputc('}', f);
	} else {
		fputs("null", f);
	}
	fputs("}\n", f);
}

static int bench_json(const bench_args *a, const bsim_backend *backend, const bsim_backend *vs,
                      int threads, const bench_results *b)
{
	bsim_atomic_file o;
	bsim_error err;
	if (bsim_atomic_file_open(&o, a->json, &err) != BSIM_OK)
		return cli_report(BSIM_EFAIL, &err);
	bench_json_write(o.f, a, backend, vs, threads, b);
	return cli_report(bsim_atomic_file_commit(&o, &err), &err);
}

/* The second backend on the first run's trials: one thread each, so the
 * ratio compares the solvers, not the scheduling; its clock reads counted. */
static int bench_vs(const bench_args *a, const bsim_backend *vs, const bsim_experiment *h1,
                    bench_results *b)
{
	fprintf(report, "\nbackend %s, 1 thread\n\n", vs->name);
	bench_print_header();
	unsigned long reads0 = bench_clock_reads();
	int rc = bench_sweep(vs, &a->vs_opts, h1, a->experiment, 1, &b->runs[b->n_runs]);
	if (rc != CLI_OK)
		return rc;
	b->timers.reads = bench_clock_reads() - reads0;
	b->timers.read_seconds = bench_clock_read_seconds();
	b->vs = b->n_runs++;
	const bench_run *mine = &b->runs[b->median], *theirs = &b->runs[b->vs];
	double timer_s = bench_timer_seconds(b);
	fprintf(report,
	        "\n%s is %.1f times faster than %s per step and %.1f times per trial "
	        "(%s, same time step, 1 thread)\n",
	        a->backend, bench_speedup_per_step(mine, theirs), vs->name,
	        theirs->wall / mine->wall, a->experiment);
	fprintf(report,
	        "%s read the clock %.1f times a step for its own profiling (%.1f ns a read): "
	        "%.0f%% of its time;\nwithout those reads %s would be %.1f times faster per "
	        "trial\n",
	        vs->name, (double)b->timers.reads / (double)theirs->steps,
	        1e9 * b->timers.read_seconds, 100.0 * timer_s / theirs->wall, a->backend,
	        (theirs->wall - timer_s) / mine->wall);
	return CLI_OK;
}

static void bench_pairs_print(const bench_args *a, const bsim_backend *vs, const char *what,
                              const double *ratio, int n)
{
	double lo = ratio[0], hi = lo;
	for (int i = 1; i < n; i++) {
		lo = ratio[i] < lo ? ratio[i] : lo;
		hi = ratio[i] > hi ? ratio[i] : hi;
	}
	fprintf(report,
	        "paired: %s is %.2f times faster than %s %s, the median of %d pairs' ratios "
	        "(%.2f .. %.2f)\n",
	        a->backend, bench_median(ratio, n), vs->name, what, n, lo, hi);
}

/* The ratio per step measured fairly on a shared machine: the two backends
 * run one after the other, a pair at a time, so that a change of load
 * between runs moves both sides of a pair alike; the median of the pairs'
 * ratios is the figure (ratio_paired), their spread says how noisy the
 * machine was. The same by the process's CPU time (ratio_paired_cpu), which
 * the other programs of a shared machine inflate far less than wall time. */
static int bench_pairs(const bench_args *a, const bsim_backend *backend, const bsim_backend *vs,
                       const bsim_experiment *h1, bench_results *b)
{
	if (a->pairs <= 0)
		return CLI_OK;
	fprintf(report, "\n%d pairs, one thread, %s then %s:\n\n", a->pairs, a->backend, vs->name);
	bench_print_header();
	for (int i = 0; i < a->pairs; i++) {
		bench_run mine, theirs;
		int rc = bench_sweep(backend, &a->opts, h1, a->experiment, 1, &mine);
		if (rc == CLI_OK)
			rc = bench_sweep(vs, &a->vs_opts, h1, a->experiment, 1, &theirs);
		if (rc != CLI_OK)
			return rc;
		b->pair_ratio_cpu[b->n_pairs] =
		        (theirs.cpu / (double)theirs.steps) / (mine.cpu / (double)mine.steps);
		b->pair_ratio[b->n_pairs++] = bench_speedup_per_step(&mine, &theirs);
	}
	fprintf(report, "\n");
	bench_pairs_print(a, vs, "per step", b->pair_ratio, b->n_pairs);
	bench_pairs_print(a, vs, "in CPU time per step", b->pair_ratio_cpu, b->n_pairs);
	return CLI_OK;
}

static int cmp_wall(const void *x, const void *y)
{
	double a = ((const bench_run *)x)->wall, b = ((const bench_run *)y)->wall;
	return (a > b) - (a < b);
}

/* The one-thread runs, --repeat of them, and the index of the median. */
static int bench_single(const bench_args *a, const bsim_backend *backend, const bsim_experiment *h1,
                        bench_results *b)
{
	for (int i = 0; i < a->repeat; i++) {
		int rc = bench_sweep(backend, &a->opts, h1, a->experiment, 1, &b->runs[b->n_runs]);
		if (rc != CLI_OK)
			return rc;
		b->n_runs++;
	}
	b->n_single = a->repeat;
	bench_run sorted[BENCH_REPEAT_MAX];
	memcpy(sorted, b->runs, (size_t)a->repeat * sizeof *sorted);
	qsort(sorted, (size_t)a->repeat, sizeof *sorted, cmp_wall);
	b->median = 0;
	for (int i = 0; i < a->repeat; i++)
		if (b->runs[i].wall == sorted[a->repeat / 2].wall)
			b->median = i;
	if (a->repeat > 1) {
		double med =
		        cli_per_second(sorted[a->repeat / 2].steps, sorted[a->repeat / 2].wall);
		fprintf(report, "%-36s one thread, %d runs: median %.4g steps/s (%.4g .. %.4g)\n",
		        "", a->repeat, med,
		        cli_per_second(sorted[a->repeat - 1].steps, sorted[a->repeat - 1].wall),
		        cli_per_second(sorted[0].steps, sorted[0].wall));
	}
	return CLI_OK;
}

static int bench_free_flight(const bench_args *a, const bsim_backend *backend, bench_results *b)
{
	bench_free_args fa = {
	        .experiment = a->experiment,
	        .trials = a->trials,
	        .backend = backend,
	        .opts = &a->opts,
	};
	int rc = bench_free(&fa, &b->free);
	if (rc != CLI_OK)
		return rc;
	b->have_free = 1;
	double ns = 1e9 * b->free.beamsim_seconds / (double)b->free.steps;
	double ns_min = 1e9 * b->free.minimal_seconds / (double)b->free.steps;
	fprintf(report,
	        "\nfree flight (%s, the body 10 km below the beams, 1 thread, %ld steps): "
	        "%s %.1f ns/step,\nminimal loop %.1f ns/step: %.1f times the minimal loop\n",
	        a->experiment, b->free.steps, a->backend, ns, ns_min, ns / ns_min);
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
		rc = cli_experiment_load(a->experiment, NULL, NULL, a->trials, &h1);
	if (rc != CLI_OK)
		return rc;
	if (a->h2 && (rc = cli_experiment_load(BENCH_H2, NULL, NULL, a->trials, &h2)) != CLI_OK) {
		bsim_experiment_free(&h1);
		return rc;
	}

	bench_results *b = calloc(1, sizeof *b);
	if (!b) {
		bsim_experiment_free(&h1);
		if (a->h2)
			bsim_experiment_free(&h2);
		cli_error("out of memory");
		return CLI_FAIL;
	}
	b->all = b->h2 = b->vs = -1;
	b->h1_h2 = -1.0;
	fprintf(report, "backend %s, %d threads\n\n", a->backend, all);
	bench_print_header();
	rc = bench_single(a, backend, &h1, b);
	if (rc == CLI_OK && (rc = bench_sweep(backend, &a->opts, &h1, a->experiment, all,
	                                      &b->runs[b->n_runs])) == CLI_OK)
		b->all = b->n_runs++;
	if (rc == CLI_OK && a->h2 &&
	    (rc = bench_sweep(backend, &a->opts, &h2, BENCH_H2, all, &b->runs[b->n_runs])) ==
	            CLI_OK)
		b->h2 = b->n_runs++;
	/* The all-threads H1 run above is the H1 half of H1 + H2. */
	if (rc == CLI_OK && a->h2) {
		b->h1_h2 = b->runs[b->all].wall + b->runs[b->h2].wall;
		fprintf(report, "\nH1 + H2 on %d threads: %.3f s\n", all, b->h1_h2);
	}
	if (rc == CLI_OK)
		rc = bench_free_flight(a, backend, b);
	if (rc == CLI_OK && vs)
		rc = bench_vs(a, vs, &h1, b);
	if (rc == CLI_OK && vs)
		rc = bench_pairs(a, backend, vs, &h1, b);
	bsim_experiment_free(&h1);
	if (a->h2)
		bsim_experiment_free(&h2);
	if (rc == CLI_OK && a->json)
		rc = bench_json(a, backend, vs, all, b);
	free(b);
	return rc;
}

int cmd_bench(int argc, char **argv)
{
	cli_common c = cli_common_default();
	/* --vs: the registry's second backend, none if it has one. */
	const bsim_backend *pair[2];
	bench_args a = {.experiment = BENCH_H1,
	                .h2 = 1,
	                .vs = bsim_backend_compared(pair, 2) == 2 ? pair[1]->name : NULL,
	                .repeat = 1,
	                .pairs = 5};
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
	if (a.memory) {
		bench_memory_args ma = {.trials = a.trials, .json = a.json, .report = report};
		return bench_memory(&ma);
	}
	if (a.measure) {
		bench_measure_args ma = {.what = a.measure,
		                         .experiment = a.experiment,
		                         .trials = a.trials,
		                         .backend = backend,
		                         .opts = &a.opts};
		return bench_measure(&ma);
	}
	if (a.callgrind) {
		bench_callgrind_args ca = {.experiment = a.experiment,
		                           .backend = a.backend,
		                           .trials = a.trials,
		                           .lattice_trials = 100,
		                           .report = report};
		return bench_callgrind(&ca);
	}
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
