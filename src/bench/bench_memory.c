/* beamsim bench --memory: peak resident memory of the runs that grow with
 * the work, measured on this program as a user runs it.
 *
 * Each run is a child process (this executable, /proc/self/exe) and its
 * peak resident set is the kernel's ru_maxrss of that child (wait4), so
 * nothing of the parent is counted. Two sizes of each run are measured:
 *   sweep       the essay's gate (configs/thesis/gate.yaml) with
 *               integration.max_steps = 50, one group of N trials and of
 *               N / 10 trials (N = --trials, default 2,000,000), all
 *               threads, into a fresh directory: trials.csv and
 *               summary.json, without the .mat twin of trials.csv
 *               (--limit mat_rows=1), so that what is measured is the
 *               sweep's own memory;
 *   twin        the N-trial sweep again with its trials.mat (mat_rows
 *               raised to N): what the twin adds per row beyond the
 *               sweep's own peak (it holds the table's columns while it is
 *               written; by default only up to 1,500,000 rows);
 *   trajectory  `run --trajectory` of the gate with no propulsion and no
 *               random force (the body stays where it is: nothing ends the
 *               trial before max_steps) for S and S / 10 steps (S =
 *               1,000,000), with the CSV's .mat twin.
 * The growth per trial (per step) is the difference of the two peaks over
 * the difference of the sizes: what memory costs per unit of work, apart
 * from what the program holds whatever the size. */
#define _DEFAULT_SOURCE

#include "bench/bench_memory.h"

#include <errno.h>
#include <fcntl.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <unistd.h>

#include "util/atomic_file.h"
#include "util/json.h"
#include "cli/cli_common.h"

extern char **environ;

#define BENCH_GATE "configs/thesis/gate.yaml"

typedef struct mem_run {
	const char *what; /* sweep, twin, trajectory */
	long size;        /* trials or steps */
	double rss;       /* bytes */
	double wall;
} mem_run;

/* The directory of the runs' files; their standard error goes to a file
 * in it, shown only if a run fails. */
static const char *tmp_dir;

/* argv run as a child with its output discarded; its peak resident set,
 * bytes, in *rss. */
static int child_peak(const char *const argv[], double *rss, double *wall)
{
	char log[BSIM_PATH_MAX];
	snprintf(log, sizeof log, "%s/stderr.txt", tmp_dir);
	posix_spawn_file_actions_t fa;
	posix_spawn_file_actions_init(&fa);
	posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
	posix_spawn_file_actions_addopen(&fa, 2, log, O_WRONLY | O_CREAT | O_TRUNC, 0600);
	pid_t pid;
	struct timeval t0, t1;
	gettimeofday(&t0, NULL);
	int e = posix_spawn(&pid, "/proc/self/exe", &fa, NULL, (char *const *)argv, environ);
	posix_spawn_file_actions_destroy(&fa);
	if (e != 0) {
		cli_error("bench: cannot start %s: %s", argv[0], strerror(e));
		return CLI_FAIL;
	}
	int status;
	struct rusage ru;
	while (wait4(pid, &status, 0, &ru) < 0)
		if (errno != EINTR) {
			cli_error("bench: wait: %s", strerror(errno));
			return CLI_FAIL;
		}
	gettimeofday(&t1, NULL);
	if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
		cli_error("bench: beamsim %s %s failed (status %d)", argv[1], argv[2],
		          WIFEXITED(status) ? WEXITSTATUS(status) : -1);
		FILE *f = fopen(log, "r");
		char line[512];
		while (f && fgets(line, sizeof line, f))
			fputs(line, stderr);
		if (f)
			fclose(f);
		return CLI_FAIL;
	}
	*rss = 1024.0 * (double)ru.ru_maxrss; /* Linux: kilobytes */
	*wall = (double)(t1.tv_sec - t0.tv_sec) + 1e-6 * (double)(t1.tv_usec - t0.tv_usec);
	return CLI_OK;
}

static int sweep_peak(const char *tmp, const char *gate, long trials, int twin, mem_run *out)
{
	char exp[BSIM_PATH_MAX], dir[BSIM_PATH_MAX];
	snprintf(exp, sizeof exp, "%s/sweep_%ld.yaml", tmp, trials);
	snprintf(dir, sizeof dir, "%s/sweep_%ld_%d", tmp, trials, twin);
	FILE *f = fopen(exp, "w");
	if (!f) {
		cli_error("bench: %s: %s", exp, strerror(errno));
		return CLI_FAIL;
	}
	fprintf(f,
	        "scene: %s\ntrials: %ld\nseed: 1\nset:\n  integration.max_steps: 50\n"
	        "grid:\n  effects.propulsion.force: [8]\n",
	        gate, trials);
	if (fclose(f) != 0) {
		cli_error("bench: %s: cannot write", exp);
		return CLI_FAIL;
	}
	char limit[64], rows[64];
	snprintf(limit, sizeof limit, "trials=%ld", trials);
	snprintf(rows, sizeof rows, "mat_rows=%ld", twin ? trials : 1);
	const char *argv[] = {"beamsim", "sweep", exp,       "--out", dir, "--quiet",
	                      "--limit", limit,   "--limit", rows,    NULL};
	*out = (mem_run){.what = twin ? "sweep+twin" : "sweep", .size = trials};
	return child_peak(argv, &out->rss, &out->wall);
}

static int trajectory_peak(const char *tmp, const char *gate, long steps, mem_run *out)
{
	char csv[BSIM_PATH_MAX], max[64];
	snprintf(csv, sizeof csv, "%s/trajectory_%ld.csv", tmp, steps);
	snprintf(max, sizeof max, "integration.max_steps=%ld", steps);
	const char *argv[] = {"beamsim",
	                      "run",
	                      gate,
	                      "--set",
	                      max,
	                      "--set",
	                      "effects.propulsion.force=0",
	                      "--set",
	                      "effects.random_force.magnitude=0",
	                      "--trajectory",
	                      csv,
	                      "--limit",
	                      "beam_steps=1e12",
	                      NULL};
	*out = (mem_run){.what = "trajectory", .size = steps};
	return child_peak(argv, &out->rss, &out->wall);
}

static void print_run(FILE *r, const mem_run *m, const char *unit)
{
	fprintf(r, "%-12s %10ld %-7s %10.1f MB %9.2f s\n", m->what, m->size, unit, m->rss / 1e6,
	        m->wall);
	fflush(r);
}

/* Bytes per unit of work: the slope between the two sizes. */
static double growth(const mem_run *small, const mem_run *big)
{
	return (big->rss - small->rss) / (double)(big->size - small->size);
}

static void json_run(FILE *f, const mem_run *m)
{
	fprintf(f, "{\"size\": %ld, \"peak_rss_bytes\": ", m->size);
	bsim_json_number(f, m->rss);
	fputs(", \"wall_seconds\": ", f);
	bsim_json_number(f, m->wall);
	fputc('}', f);
}

static int write_json(const char *path, const mem_run run[5])
{
	bsim_atomic_file o;
	bsim_error err;
	if (bsim_atomic_file_open(&o, path, &err) != BSIM_OK) {
		cli_error("bench: %s", err.msg);
		return CLI_FAIL;
	}
	static const char *const names[2] = {"sweep", "trajectory"};
	static const char *const per[2] = {"bytes_per_trial", "bytes_per_step"};
	fputs("{\"memory\": {", o.f);
	for (int k = 0; k < 2; k++) {
		fprintf(o.f, "%s\"%s\": {\"small\": ", k ? ", " : "", names[k]);
		json_run(o.f, &run[2 * k]);
		fputs(", \"large\": ", o.f);
		json_run(o.f, &run[2 * k + 1]);
		fprintf(o.f, ", \"%s\": ", per[k]);
		bsim_json_number(o.f, growth(&run[2 * k], &run[2 * k + 1]));
		fputc('}', o.f);
	}
	fputs(", \"twin\": ", o.f);
	json_run(o.f, &run[4]);
	fputs(", \"twin_bytes_per_row\": ", o.f);
	bsim_json_number(o.f, (run[4].rss - run[1].rss) / (double)run[1].size);
	fputs("}}\n", o.f);
	if (bsim_atomic_file_commit(&o, &err) != BSIM_OK) {
		cli_error("bench: %s", err.msg);
		return CLI_FAIL;
	}
	return CLI_OK;
}

/* Removes what the runs wrote under tmp, and tmp. */
static void tmp_remove(const char *tmp)
{
	const char *argv[] = {"rm", "-rf", tmp, NULL};
	pid_t pid;
	if (posix_spawnp(&pid, "rm", NULL, NULL, (char *const *)argv, environ) == 0)
		waitpid(pid, NULL, 0);
}

int bench_memory(const bench_memory_args *a)
{
	char gate[BSIM_PATH_MAX];
	if (!realpath(BENCH_GATE, gate)) {
		cli_error("%s not found: run beamsim bench from the source tree", BENCH_GATE);
		return CLI_USAGE;
	}
	char tmp[] = "/tmp/beamsim-bench-XXXXXX";
	if (!mkdtemp(tmp)) {
		cli_error("bench: cannot make a temporary directory: %s", strerror(errno));
		return CLI_FAIL;
	}
	tmp_dir = tmp;
	long trials = a->trials > 0 ? a->trials : 2000000;
	long steps = a->steps > 0 ? a->steps : 1000000;
	FILE *r = a->report;
	fprintf(r, "Peak resident memory (ru_maxrss of each run as a child process)\n");
	fprintf(r, "%-12s %18s %13s %11s\n", "run", "size", "peak", "wall");
	mem_run run[5];
	long small = trials / 10 > 0 ? trials / 10 : 1;
	int rc = sweep_peak(tmp, gate, small, 0, &run[0]);
	if (rc == CLI_OK) {
		print_run(r, &run[0], "trials");
		rc = sweep_peak(tmp, gate, trials, 0, &run[1]);
	}
	if (rc == CLI_OK) {
		print_run(r, &run[1], "trials");
		rc = trajectory_peak(tmp, gate, steps / 10 > 0 ? steps / 10 : 1, &run[2]);
	}
	if (rc == CLI_OK) {
		print_run(r, &run[2], "steps");
		rc = trajectory_peak(tmp, gate, steps, &run[3]);
	}
	if (rc == CLI_OK) {
		print_run(r, &run[3], "steps");
		rc = sweep_peak(tmp, gate, trials, 1, &run[4]);
	}
	if (rc == CLI_OK) {
		print_run(r, &run[4], "trials");
		fprintf(r,
		        "\ngrowth: %.1f bytes per trial (the sweep), %.1f bytes per step (the "
		        "trajectory and its twin);\nthe .mat twin of trials.csv: %.1f bytes per "
		        "row\n",
		        growth(&run[0], &run[1]), growth(&run[2], &run[3]),
		        (run[4].rss - run[1].rss) / (double)run[1].size);
	}
	tmp_remove(tmp);
	if (rc == CLI_OK && a->json)
		rc = write_json(a->json, run);
	return rc;
}
