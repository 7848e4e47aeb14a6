/* beamsim bench --callgrind: instructions per step, counted by valgrind's
 * callgrind, which the load of a shared machine does not move (perf stat's
 * counters are not offered in every container; valgrind runs anywhere).
 *
 * Each figure is a difference: the measure runs as a child process (this
 * executable, bench --measure WHAT) under valgrind twice, with T and 2T
 * trials, and
 *   instructions per step = (I(2T) - I(T)) / (steps(2T) - steps(T)),
 * so what a process does once (loading, building the scenes, writing
 * nothing) cancels and what each trial costs, its setup included, stays.
 * The measures:
 *   h1        the experiment's sweep on one thread (T trials per group);
 *   free      its free flight (bench_free.c), the full runner and backend;
 *   minimal   the minimal loop of the same steps;
 *   lattice:N N x N lattice trials of 1000 steps, the world kept from trial
 *             to trial as a sweep keeps it (bench_lattice_long). */
#define _POSIX_C_SOURCE 200809L

#include "bench/bench_callgrind.h"

#include <fcntl.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "beamsim/experiment.h"
#include "beamsim/sweep.h"
#include "bench/bench_free.h"
#include "bench/bench_lattice.h"
#include "cli/cli_common.h"

extern char **environ;

int bench_measure(const bench_measure_args *a)
{
	long steps = 0;
	int rc = CLI_OK;
	if (strcmp(a->what, "h1") == 0) {
		bsim_experiment e;
		if ((rc = cli_experiment_load(a->experiment, NULL, NULL, a->trials, &e)) != CLI_OK)
			return rc;
		bsim_sweep_config cfg = {.backend = a->backend, .opts = a->opts, .threads = 1};
		bsim_sweep_result r;
		rc = cli_sweep_run(&e, &cfg, 0, &r);
		bsim_experiment_free(&e);
		if (rc != CLI_OK)
			return rc;
		steps = r.total_steps;
		bsim_sweep_result_free(&r);
	} else if (strcmp(a->what, "free") == 0 || strcmp(a->what, "minimal") == 0) {
		bench_free_args fa = {.experiment = a->experiment,
		                      .trials = a->trials,
		                      .backend = a->backend,
		                      .opts = a->opts,
		                      .only = strcmp(a->what, "free") == 0 ? 1 : 2};
		bench_free_result fr;
		if ((rc = bench_free(&fa, &fr)) != CLI_OK)
			return rc;
		steps = fr.steps;
	} else if (strncmp(a->what, "lattice:", 8) == 0) {
		char *end;
		long n = strtol(a->what + 8, &end, 10);
		double wall;
		if (*end || n < 1 || n > 101) {
			cli_error("bench: --measure: lattice:N: expected N from 1 to 101, got '%s'",
			          a->what + 8);
			return CLI_USAGE;
		}
		rc = bench_lattice_long(a->backend, a->opts, (int)n, a->trials, &steps, &wall);
		if (rc != CLI_OK)
			return rc;
	} else {
		cli_error("bench: --measure: expected h1, free, minimal or lattice:N, got '%s'",
		          a->what);
		return CLI_USAGE;
	}
	printf("steps %ld\n", steps);
	return CLI_OK;
}

/* The number after "Collected : " in valgrind's log, -1 if none. */
static double collected(const char *log)
{
	FILE *f = fopen(log, "r");
	if (!f)
		return -1.0;
	char line[512];
	double ir = -1.0;
	while (fgets(line, sizeof line, f)) {
		const char *p = strstr(line, "Collected : ");
		if (p)
			ir = strtod(p + 12, NULL);
	}
	fclose(f);
	return ir;
}

static long steps_of(const char *out)
{
	FILE *f = fopen(out, "r");
	long steps = -1;
	if (f) {
		if (fscanf(f, "steps %ld", &steps) != 1)
			steps = -1;
		fclose(f);
	}
	return steps;
}

/* One child under valgrind: its instructions and steps. */
static int child_count(const bench_callgrind_args *a, const char *exe, const char *what,
                       long trials, double *ir, long *steps)
{
	char tr[32], out[] = "/tmp/beamsim-cg-out-XXXXXX", log[] = "/tmp/beamsim-cg-log-XXXXXX";
	snprintf(tr, sizeof tr, "%ld", trials);
	int fo = mkstemp(out), fl = fo >= 0 ? mkstemp(log) : -1;
	if (fo >= 0)
		close(fo);
	if (fl >= 0)
		close(fl);
	if (fo < 0 || fl < 0) {
		if (fo >= 0)
			unlink(out);
		cli_error("bench: --callgrind: cannot create a file in /tmp");
		return CLI_FAIL;
	}
	const char *argv[] = {"valgrind",
	                      "--tool=callgrind",
	                      "--callgrind-out-file=/dev/null",
	                      exe,
	                      "bench",
	                      "--measure",
	                      what,
	                      "--trials",
	                      tr,
	                      "--experiment",
	                      a->experiment,
	                      "--backend",
	                      a->backend,
	                      NULL};
	posix_spawn_file_actions_t fa;
	posix_spawn_file_actions_init(&fa);
	posix_spawn_file_actions_addopen(&fa, 1, out, O_WRONLY | O_TRUNC, 0);
	posix_spawn_file_actions_addopen(&fa, 2, log, O_WRONLY | O_TRUNC, 0);
	pid_t pid;
	int e = posix_spawnp(&pid, "valgrind", &fa, NULL, (char *const *)argv, environ);
	posix_spawn_file_actions_destroy(&fa);
	int status = -1;
	if (e == 0)
		waitpid(pid, &status, 0);
	*ir = collected(log);
	*steps = steps_of(out);
	unlink(out);
	unlink(log);
	if (e != 0) {
		cli_error("bench: --callgrind: valgrind not found (Debian: apt-get install "
		          "valgrind)");
		return CLI_FAIL;
	}
	if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || *ir < 0.0 || *steps < 0) {
		cli_error(
		        "bench: --callgrind: bench --measure %s --trials %s under valgrind failed",
		        what, tr);
		return CLI_FAIL;
	}
	return CLI_OK;
}

/* Instructions per step of a measure: the difference of T and 2T trials. */
static int per_step(const bench_callgrind_args *a, const char *exe, const char *what, long t,
                    double *ips, long *steps)
{
	double ir1, ir2;
	long s1, s2;
	int rc = child_count(a, exe, what, t, &ir1, &s1);
	if (rc == CLI_OK)
		rc = child_count(a, exe, what, 2 * t, &ir2, &s2);
	if (rc != CLI_OK)
		return rc;
	if (s2 <= s1) {
		cli_error("bench: --callgrind: %s: %ld trials ran no more steps than %ld", what,
		          2 * t, t);
		return CLI_FAIL;
	}
	*ips = (ir2 - ir1) / (double)(s2 - s1);
	*steps = s2 - s1;
	return CLI_OK;
}

int bench_callgrind(const bench_callgrind_args *a)
{
	char exe[4096];
	ssize_t len = readlink("/proc/self/exe", exe, sizeof exe - 1);
	if (len <= 0) {
		cli_error("bench: --callgrind: cannot find this executable (/proc/self/exe)");
		return CLI_FAIL;
	}
	exe[len] = '\0';
	FILE *out = a->report;
	fprintf(out,
	        "instructions per step (valgrind --tool=callgrind; each figure the difference of "
	        "two runs,\nof T and 2T trials, over the difference of their steps: a trial's "
	        "setup counted,\nthe process's start not); backend %s, one thread\n\n"
	        "%-44s %6s %10s %14s\n",
	        a->backend, "measure", "T", "steps", "instr/step");
	struct {
		const char *what, *label;
		long t;
	} m[] = {
	        {"h1", "sweep of the experiment", a->trials > 0 ? a->trials : 4},
	        {"free", "its free flight", a->trials > 0 ? a->trials : 2},
	        {"minimal", "the minimal loop of the same steps", a->trials > 0 ? a->trials : 2},
	        {"lattice:5", "5 x 5 lattice, 1000-step trials", a->lattice_trials},
	        {"lattice:33", "33 x 33 lattice, 1000-step trials", a->lattice_trials},
	};
	double ips[5];
	for (int k = 0; k < 5; k++) {
		long steps;
		int rc = per_step(a, exe, m[k].what, m[k].t, &ips[k], &steps);
		if (rc != CLI_OK)
			return rc;
		fprintf(out, "%-44s %6ld %10ld %14.1f\n", m[k].label, m[k].t, steps, ips[k]);
		fflush(out);
	}
	fprintf(out,
	        "\n%s: free flight %.2f times the minimal loop's instructions; 33 x 33 lattice "
	        "%.3f times the 5 x 5's (setup included)\n",
	        a->experiment, ips[1] / ips[2], ips[4] / ips[3]);
	return CLI_OK;
}
