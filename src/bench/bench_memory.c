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
 *               1,000,000), with the CSV's .mat twin;
 *   grid axis   `sweep --grid body.mass=1,2,...,V` of a one-group
 *               experiment of the gate (one trial of two steps a group),
 *               V = 20,000 and 2,000 values, with every file and twin: an
 *               axis costs its values, not its values times the option;
 *   replay      `run DIR --group V-1 --trial 0` of the V = 20,000 sweep;
 *   python      beamsim.sweep of the one-group sweep above from Python
 *               (the python3 the module is built for, the module beside
 *               this program), 200,000 and 20,000 trials: its trials as
 *               NumPy columns; left out without the module;
 *   lattice     the uniform lattice (configs/markov/uniform.yaml) at 5 x 5
 *               and 33 x 33 gates, N / 100 trials of 1000 steps each
 *               (20,000 by default), all threads, with every file: a
 *               lattice trial should cost the beams it touched, not the
 *               field's, so the two peaks and the wall times per step
 *               (setup and output included; the steps from the sweep's
 *               summary.json) are compared as ratios.
 * The growth per trial (per step, per value) is the difference of the two
 * peaks over the difference of the sizes: what memory costs per unit of
 * work, apart from what the program holds whatever the size. */
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
#include "util/yaml_doc.h"
#include "cli/cli_common.h"

extern char **environ;

#define BENCH_GATE    "configs/thesis/gate.yaml"
#define BENCH_LATTICE "configs/markov/uniform.yaml"

/* The large grid axis's values and Python sweep's trials (the small: a
 * tenth). */
#define AXIS_VALUES   20000
#define PYTHON_TRIALS 200000

typedef struct mem_run {
	const char *what; /* sweep, twin, trajectory, grid axis, replay, python, lattice */
	long size;        /* trials, steps or values; a lattice's gates a side */
	double rss;       /* bytes */
	double wall;
	double steps; /* a lattice's: every trial's steps */
} mem_run;

/* The directory of the runs' files; their standard error goes to a file
 * in it, shown only if a run fails. */
static const char *tmp_dir;

/* argv run as a child with its output discarded (file: a program found on
 * PATH or by its path, NULL: this program); its peak resident set, bytes,
 * in *rss. */
static int child_run(const char *file, const char *const argv[], double *rss, double *wall)
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
	int e = file ? posix_spawnp(&pid, file, &fa, NULL, (char *const *)argv, environ)
	             : posix_spawn(&pid, "/proc/self/exe", &fa, NULL, (char *const *)argv, environ);
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
		cli_error("bench: %s %s %.60s failed (status %d)", argv[0], argv[1], argv[2],
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

static int child_peak(const char *const argv[], double *rss, double *wall)
{
	return child_run(NULL, argv, rss, wall);
}

/* The one-group experiment of the gate in tmp (trials a group, steps
 * each), its path in exp. */
static int one_group(const char *tmp, const char *gate, const char *name, long trials, long steps,
                     char *exp, size_t size)
{
	snprintf(exp, size, "%s/%s.yaml", tmp, name);
	FILE *f = fopen(exp, "w");
	if (!f) {
		cli_error("bench: %s: %s", exp, strerror(errno));
		return CLI_FAIL;
	}
	fprintf(f,
	        "scene: %s\ntrials: %ld\nseed: 1\nset:\n  integration.max_steps: %ld\n"
	        "grid:\n  effects.propulsion.force: [8]\n",
	        gate, trials, steps);
	if (fclose(f) != 0) {
		cli_error("bench: %s: cannot write", exp);
		return CLI_FAIL;
	}
	return CLI_OK;
}

/* sweep --grid body.mass=1,...,values into tmp/axis_VALUES; then, with
 * replay, run of that directory's last group. */
static int axis_peak(const char *tmp, const char *gate, long values, mem_run *out, mem_run *replay)
{
	char exp[BSIM_PATH_MAX], dir[BSIM_PATH_MAX];
	if (one_group(tmp, gate, "axis", 1, 2, exp, sizeof exp) != CLI_OK)
		return CLI_FAIL;
	snprintf(dir, sizeof dir, "%s/axis_%ld", tmp, values);
	size_t size = (size_t)values * 12 + 32;
	char *option = malloc(size);
	if (!option) {
		cli_error("out of memory");
		return CLI_FAIL;
	}
	size_t at = (size_t)snprintf(option, size, "body.mass=");
	for (long i = 1; i <= values; i++)
		at += (size_t)snprintf(option + at, size - at, "%s%ld", i > 1 ? "," : "", i);
	const char *argv[] = {"beamsim", "sweep",  exp,    "--out", dir,
	                      "--quiet", "--grid", option, NULL};
	*out = (mem_run){.what = "grid axis", .size = values};
	int rc = child_peak(argv, &out->rss, &out->wall);
	free(option);
	if (rc != CLI_OK || !replay)
		return rc;
	char group[32];
	snprintf(group, sizeof group, "%ld", values - 1);
	const char *run[] = {"beamsim", "run", dir, "--group", group, "--trial", "0", NULL};
	*replay = (mem_run){.what = "replay", .size = values};
	return child_peak(run, &replay->rss, &replay->wall);
}

/* The Python module beside this program (build/python), or "" without it. */
static void python_dir(char *dir, size_t size)
{
	char self[BSIM_PATH_MAX], test[BSIM_PATH_MAX + 32];
	dir[0] = '\0';
	ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
	self[n > 0 ? n : 0] = '\0';
	char *slash = strrchr(self, '/');
	int len = slash ? snprintf(dir, size, "%.*s/python", (int)(slash - self), self) : -1;
	snprintf(test, sizeof test, "%s/beamsim/__init__.py", dir);
	if (n <= 0 || len < 0 || (size_t)len >= size || access(test, R_OK) != 0)
		dir[0] = '\0';
}

/* beamsim.sweep of the one-group experiment of trials trials, from Python. */
static int python_peak(const char *tmp, const char *gate, const char *module, long trials,
                       mem_run *out)
{
#ifdef BSIM_PYTHON_EXECUTABLE
	char exp[BSIM_PATH_MAX], name[32], code[BSIM_PATH_MAX * 2];
	snprintf(name, sizeof name, "python_%ld", trials);
	if (one_group(tmp, gate, name, trials, 50, exp, sizeof exp) != CLI_OK)
		return CLI_FAIL;
	snprintf(code, sizeof code,
	         "import sys; sys.path.insert(0, '%s'); import beamsim; "
	         "s = beamsim.sweep('%s'); assert len(s['trials']['outcome']) == %ld",
	         module, exp, trials);
	const char *argv[] = {BSIM_PYTHON_EXECUTABLE, "-c", code, NULL};
	*out = (mem_run){.what = "python", .size = trials};
	return child_run(BSIM_PYTHON_EXECUTABLE, argv, &out->rss, &out->wall);
#else
	(void)tmp, (void)gate, (void)module, (void)trials, (void)out;
	return CLI_FAIL;
#endif
}

static int sweep_peak(const char *tmp, const char *gate, long trials, int twin, mem_run *out)
{
	char exp[BSIM_PATH_MAX], dir[BSIM_PATH_MAX], name[32];
	snprintf(name, sizeof name, "sweep_%ld", trials);
	snprintf(dir, sizeof dir, "%s/sweep_%ld_%d", tmp, trials, twin);
	if (one_group(tmp, gate, name, trials, 50, exp, sizeof exp) != CLI_OK)
		return CLI_FAIL;
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

/* The uniform lattice of n x n gates, trials trials of 1000 steps, into
 * tmp/lattice_N; its steps from the sweep's summary.json. */
static int lattice_peak(const char *tmp, const char *config, int n, long trials, mem_run *out)
{
	char dir[BSIM_PATH_MAX], cols[64], rows[64], t[32], summary[BSIM_PATH_MAX + 16];
	snprintf(dir, sizeof dir, "%s/lattice_%d", tmp, n);
	snprintf(cols, sizeof cols, "lattice.columns=%d", n);
	snprintf(rows, sizeof rows, "lattice.rows=%d", n);
	snprintf(t, sizeof t, "%ld", trials);
	const char *argv[] = {"beamsim",  "sweep",   config,
	                      "--set",    cols,      "--set",
	                      rows,       "--set",   "integration.duration=4",
	                      "--trials", t,         "--out",
	                      dir,        "--quiet", NULL};
	*out = (mem_run){.what = "lattice", .size = n};
	int rc = child_peak(argv, &out->rss, &out->wall);
	if (rc != CLI_OK)
		return rc;
	snprintf(summary, sizeof summary, "%s/summary.json", dir);
	ydoc d;
	bsim_error err;
	long long steps = 0;
	if (bsim_ydoc_load(&d, summary, &err) != BSIM_OK) {
		cli_error("bench: %s", err.msg);
		return CLI_FAIL;
	}
	struct fy_node *node =
	        fy_node_by_path(fy_document_root(d.fyd), "/totals/steps", -1, FYNWF_DONT_FOLLOW);
	if (!node || !bsim_ydoc_int64(node, &steps) || steps <= 0) {
		cli_error("bench: %s: no totals.steps", summary);
		rc = CLI_FAIL;
	}
	bsim_ydoc_free(&d);
	out->steps = (double)steps;
	return rc;
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
	if (m->steps > 0) {
		fputs(", \"steps\": ", f);
		bsim_json_number(f, m->steps);
	}
	fputc('}', f);
}

/* The runs measured, in the order they run. */
enum {
	SWEEP_SMALL,
	SWEEP_LARGE,
	TRAJ_SHORT,
	TRAJ_LONG,
	TWIN,
	AXIS_SMALL,
	AXIS_LARGE,
	REPLAY,
	PY_SMALL,
	PY_LARGE,
	LATTICE_SMALL,
	LATTICE_LARGE,
	N_RUNS
};

/* The lattice's sizes, gates a side. */
#define LATTICE_SMALL_N 5
#define LATTICE_LARGE_N 33

/* The large lattice's peak memory and wall time per step over the small's. */
static double lattice_memory_ratio(const mem_run run[N_RUNS])
{
	return run[LATTICE_LARGE].rss / run[LATTICE_SMALL].rss;
}

static double lattice_wall_ratio(const mem_run run[N_RUNS])
{
	return (run[LATTICE_LARGE].wall / run[LATTICE_LARGE].steps) /
	       (run[LATTICE_SMALL].wall / run[LATTICE_SMALL].steps);
}

/* "name": {"small": ..., "large": ..., "per": growth} */
static void json_pair(FILE *f, const char *name, const mem_run *small, const mem_run *big,
                      const char *per)
{
	fprintf(f, ", \"%s\": {\"small\": ", name);
	json_run(f, small);
	fputs(", \"large\": ", f);
	json_run(f, big);
	fprintf(f, ", \"%s\": ", per);
	bsim_json_number(f, growth(small, big));
	fputc('}', f);
}

static int write_json(const char *path, const mem_run run[N_RUNS], int python)
{
	bsim_atomic_file o;
	bsim_error err;
	if (bsim_atomic_file_open(&o, path, &err) != BSIM_OK) {
		cli_error("bench: %s", err.msg);
		return CLI_FAIL;
	}
	fputs("{\"memory\": {\"sweep\": {\"small\": ", o.f);
	json_run(o.f, &run[SWEEP_SMALL]);
	fputs(", \"large\": ", o.f);
	json_run(o.f, &run[SWEEP_LARGE]);
	fputs(", \"bytes_per_trial\": ", o.f);
	bsim_json_number(o.f, growth(&run[SWEEP_SMALL], &run[SWEEP_LARGE]));
	fputc('}', o.f);
	json_pair(o.f, "trajectory", &run[TRAJ_SHORT], &run[TRAJ_LONG], "bytes_per_step");
	fputs(", \"twin\": ", o.f);
	json_run(o.f, &run[TWIN]);
	fputs(", \"twin_bytes_per_row\": ", o.f);
	bsim_json_number(o.f,
	                 (run[TWIN].rss - run[SWEEP_LARGE].rss) / (double)run[SWEEP_LARGE].size);
	json_pair(o.f, "grid_axis", &run[AXIS_SMALL], &run[AXIS_LARGE], "bytes_per_value");
	fputs(", \"replay\": ", o.f);
	json_run(o.f, &run[REPLAY]);
	if (python)
		json_pair(o.f, "python_sweep", &run[PY_SMALL], &run[PY_LARGE], "bytes_per_trial");
	fputs(", \"lattice\": {\"small\": ", o.f);
	json_run(o.f, &run[LATTICE_SMALL]);
	fputs(", \"large\": ", o.f);
	json_run(o.f, &run[LATTICE_LARGE]);
	fputs(", \"memory_ratio\": ", o.f);
	bsim_json_number(o.f, lattice_memory_ratio(run));
	fputs(", \"wall_per_step_ratio\": ", o.f);
	bsim_json_number(o.f, lattice_wall_ratio(run));
	fputs("}}}\n", o.f);
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
	char gate[BSIM_PATH_MAX], lattice[BSIM_PATH_MAX];
	if (!realpath(BENCH_GATE, gate) || !realpath(BENCH_LATTICE, lattice)) {
		cli_error("%s or %s not found: run beamsim bench from the source tree", BENCH_GATE,
		          BENCH_LATTICE);
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
	mem_run run[N_RUNS];
	memset(run, 0, sizeof run);
	long small = trials / 10 > 0 ? trials / 10 : 1;
	int rc = sweep_peak(tmp, gate, small, 0, &run[SWEEP_SMALL]);
	if (rc == CLI_OK) {
		print_run(r, &run[SWEEP_SMALL], "trials");
		rc = sweep_peak(tmp, gate, trials, 0, &run[SWEEP_LARGE]);
	}
	if (rc == CLI_OK) {
		print_run(r, &run[SWEEP_LARGE], "trials");
		rc = trajectory_peak(tmp, gate, steps / 10 > 0 ? steps / 10 : 1, &run[TRAJ_SHORT]);
	}
	if (rc == CLI_OK) {
		print_run(r, &run[TRAJ_SHORT], "steps");
		rc = trajectory_peak(tmp, gate, steps, &run[TRAJ_LONG]);
	}
	if (rc == CLI_OK) {
		print_run(r, &run[TRAJ_LONG], "steps");
		rc = sweep_peak(tmp, gate, trials, 1, &run[TWIN]);
	}
	if (rc == CLI_OK) {
		print_run(r, &run[TWIN], "trials");
		rc = axis_peak(tmp, gate, AXIS_VALUES / 10, &run[AXIS_SMALL], NULL);
	}
	if (rc == CLI_OK) {
		print_run(r, &run[AXIS_SMALL], "values");
		rc = axis_peak(tmp, gate, AXIS_VALUES, &run[AXIS_LARGE], &run[REPLAY]);
	}
	char module[BSIM_PATH_MAX];
	python_dir(module, sizeof module);
#ifndef BSIM_PYTHON_EXECUTABLE
	module[0] = '\0';
#endif
	if (rc == CLI_OK) {
		print_run(r, &run[AXIS_LARGE], "values");
		print_run(r, &run[REPLAY], "values");
		if (module[0])
			rc = python_peak(tmp, gate, module, PYTHON_TRIALS / 10, &run[PY_SMALL]);
	}
	if (rc == CLI_OK && module[0]) {
		print_run(r, &run[PY_SMALL], "trials");
		rc = python_peak(tmp, gate, module, PYTHON_TRIALS, &run[PY_LARGE]);
		if (rc == CLI_OK)
			print_run(r, &run[PY_LARGE], "trials");
	}
	long lattice_trials = trials / 100 > 0 ? trials / 100 : 1;
	if (rc == CLI_OK)
		rc = lattice_peak(tmp, lattice, LATTICE_SMALL_N, lattice_trials,
		                  &run[LATTICE_SMALL]);
	if (rc == CLI_OK) {
		print_run(r, &run[LATTICE_SMALL], "gates");
		rc = lattice_peak(tmp, lattice, LATTICE_LARGE_N, lattice_trials,
		                  &run[LATTICE_LARGE]);
	}
	if (rc == CLI_OK)
		print_run(r, &run[LATTICE_LARGE], "gates");
	if (rc == CLI_OK) {
		fprintf(r,
		        "\ngrowth: %.1f bytes per trial (the sweep), %.1f bytes per step (the "
		        "trajectory and its twin);\nthe .mat twin of trials.csv: %.1f bytes per "
		        "row; %.1f bytes per value of a grid axis",
		        growth(&run[SWEEP_SMALL], &run[SWEEP_LARGE]),
		        growth(&run[TRAJ_SHORT], &run[TRAJ_LONG]),
		        (run[TWIN].rss - run[SWEEP_LARGE].rss) / (double)run[SWEEP_LARGE].size,
		        growth(&run[AXIS_SMALL], &run[AXIS_LARGE]));
		if (module[0])
			fprintf(r, ";\n%.1f bytes per trial of a sweep from Python (NumPy columns)",
			        growth(&run[PY_SMALL], &run[PY_LARGE]));
		else
			fputs(";\nno sweep from Python: no Python module beside this program", r);
		fprintf(r,
		        ";\n%ld lattice trials at %d x %d against %d x %d: %.2f times the peak "
		        "memory, %.2f times the wall time a step",
		        lattice_trials, LATTICE_LARGE_N, LATTICE_LARGE_N, LATTICE_SMALL_N,
		        LATTICE_SMALL_N, lattice_memory_ratio(run), lattice_wall_ratio(run));
		fputc('\n', r);
	}
	tmp_remove(tmp);
	if (rc == CLI_OK && a->json)
		rc = write_json(a->json, run, module[0] != '\0');
	return rc;
}
