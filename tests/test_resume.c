/* Stopping and resuming sweeps and comparisons through the real program.
 * The truth is the uninterrupted run: however often a run is killed (kill
 * -9 at random moments: while loading, running trials, writing or
 * committing its files) and resumed, the files it ends with are those of a
 * run never interrupted, byte for byte (trials.csv, and pairs.csv of a
 * comparison), and whenever a manifest is present it matches the files
 * beside it. SIGINT and SIGTERM stop cleanly with 128 + the signal's
 * number, keep the journal and print the line that resumes. A resume with
 * other inputs, or without a run to resume, is refused. */
#define _POSIX_C_SOURCE 200809L

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "store/outdir.h"
#include "support.h"

#define CYCLES 10 /* kill-and-resume cycles per command */

static char experiment[1200];

/* A small experiment: 12 groups of 24 trials of at most 1500 steps, the
 * four without random force deterministic (run once, copied). */
static int setup(void **state)
{
	(void)state;
	char text[2400];
	snprintf(text, sizeof text,
	         "scene: %s\n"
	         "trials: 24\n"
	         "seed: 5\n"
	         "set:\n"
	         "  integration.max_steps: 1500\n"
	         "grid:\n"
	         "  effects.propulsion.force: [6, 7, 8, 9]\n"
	         "  effects.random_force.magnitude: [0, 10, 30]\n",
	         bsim_test_src("configs/thesis/gate.yaml"));
	snprintf(experiment, sizeof experiment, "%s",
	         bsim_test_write(bsim_test_dir("exp"), "small.yaml", text));
	return 0;
}

static double now(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static void sleep_for(double s)
{
	struct timespec t = {(time_t)s, (long)((s - (double)(time_t)s) * 1e9)};
	nanosleep(&t, NULL);
}

static char *join(const char *dir, const char *name)
{
	static char buf[4][1400];
	static int k;
	k = (k + 1) % 4;
	if (snprintf(buf[k], sizeof buf[k], "%s/%s", dir, name) >= (int)sizeof buf[k])
		fail_msg("path too long");
	return buf[k];
}

static int exists(const char *path)
{
	return access(path, F_OK) == 0;
}

/* The command line of a run of cmd ("sweep" or "compare") into dir. A
 * comparison runs 8 of the 24 trials per group: Box2D is the slow side; a
 * sweep keeps the trajectories of two trials per group. */
static void command(const char **argv, const char *cmd, const char *dir, int resume)
{
	int n = 0;
	argv[n++] = cmd;
	argv[n++] = experiment;
	if (strcmp(cmd, "compare") == 0) {
		argv[n++] = "--trials";
		argv[n++] = "8";
	} else {
		/* kept trajectories are not journaled: their trials run again */
		argv[n++] = "--trajectories";
		argv[n++] = "2";
	}
	argv[n++] = "--quiet";
	argv[n++] = "--threads";
	argv[n++] = "2";
	argv[n++] = "--out";
	argv[n++] = dir;
	if (resume)
		argv[n++] = "--resume";
	argv[n] = NULL;
}

/* What must be identical: the files holding trials. */
static const char *const sweep_files[] = {"trials.csv", "trajectories.csv", NULL};
static const char *const compare_files[] = {"thesis/trials.csv", "box2d/trials.csv", "pairs.csv",
                                            NULL};

/* Whenever there is a manifest, it lists exactly the files beside it. */
static void check_manifest(const char *dir)
{
	int has = 0;
	bsim_error err;
	if (bsim_outdir_verify(dir, &has, &err) != BSIM_OK)
		fail_msg("after a kill: %s", err.msg);
}

static void same_files(const char *ref, const char *dir, const char *const *files)
{
	for (int i = 0; files[i]; i++) {
		char *a = bsim_test_read(join(ref, files[i]));
		char *b = bsim_test_read(join(dir, files[i]));
		assert_non_null(a);
		if (!b || strcmp(a, b) != 0)
			fail_msg("%s differs from the uninterrupted run's", join(dir, files[i]));
		free(a);
		free(b);
	}
}

static int done_status(int rc)
{
	return rc == 0 || rc == 3; /* compare: 3 reports disagreeing groups */
}

/* Kills runs of cmd at random moments (uniform over 1.2 times the length
 * of an uninterrupted run), one to three times, resumes until one
 * finishes, and compares with the uninterrupted run. */
static void kill_and_resume(const char *cmd, const char *const *files)
{
	char ref[1200], dir[1200];
	const char *argv[16];
	snprintf(ref, sizeof ref, "%s", bsim_test_dir(cmd));
	command(argv, cmd, ref, 0);
	double t0 = now();
	assert_true(done_status(bsim_test_cli(argv, NULL, NULL)));
	double full = now() - t0;
	srand(12345);
	int kills = 0, mid_run = 0;
	for (int c = 0; c < CYCLES; c++) {
		char name[64];
		snprintf(name, sizeof name, "%s_killed_%d", cmd, c);
		snprintf(dir, sizeof dir, "%s", bsim_test_dir(name));
		int finished = 0;
		for (int round = 0; !finished; round++) {
			int resume = exists(join(dir, ".beamsim/journal"));
			command(argv, cmd, dir, resume);
			if (round >= 1 + c % 3) { /* the last round runs to the end */
				int rc = bsim_test_cli(argv, NULL, NULL);
				if (!done_status(rc))
					fail_msg("cycle %d: the resumed %s ended with %d", c, cmd,
					         rc);
				finished = 1;
				break;
			}
			int pid = bsim_test_spawn(argv);
			sleep_for(1.2 * full * rand() / RAND_MAX);
			kill(pid, SIGKILL);
			int rc = bsim_test_wait(pid);
			if (rc != 128 + SIGKILL) { /* it ended before the kill */
				if (!done_status(rc))
					fail_msg("cycle %d: %s ended with %d", c, cmd, rc);
				finished = 1;
				break;
			}
			kills++;
			/* a journal with records, and no finished set yet */
			struct stat st;
			if (stat(join(dir, ".beamsim/journal"), &st) == 0 && st.st_size > 2000 &&
			    !exists(join(dir, "manifest.json")))
				mid_run++;
			check_manifest(dir);
		}
		same_files(ref, dir, files);
		check_manifest(dir);
		assert_false(exists(join(dir, ".beamsim")));
	}
	print_message("%s: %d kills (%d while trials ran) in %d cycles; an uninterrupted run "
	              "takes %.2f s\n",
	              cmd, kills, mid_run, CYCLES, full);
	assert_true(kills >= CYCLES);
	assert_true(mid_run >= CYCLES / 2);
}

static void test_sweep_killed(void **state)
{
	(void)state;
	kill_and_resume("sweep", sweep_files);
}

static void test_compare_killed(void **state)
{
	(void)state;
	kill_and_resume("compare", compare_files);
}

/* SIGINT and SIGTERM: a clean stop, the journal kept, the resume line. */
static void test_signals(void **state)
{
	(void)state;
	static const int sigs[] = {SIGINT, SIGTERM};
	char ref[1200], dir[1200], errfile[1400];
	const char *argv[16];
	snprintf(ref, sizeof ref, "%s", bsim_test_dir("signal_ref"));
	command(argv, "sweep", ref, 0);
	double t0 = now();
	assert_int_equal(bsim_test_cli(argv, NULL, NULL), 0);
	double full = now() - t0;
	for (int i = 0; i < 2; i++) {
		char name[32];
		snprintf(name, sizeof name, "signal_%d", sigs[i]);
		snprintf(dir, sizeof dir, "%s", bsim_test_dir(name));
		snprintf(errfile, sizeof errfile, "%s", join(dir, "../stderr.txt"));
		command(argv, "sweep", dir, 0);
		fflush(NULL);
		pid_t pid = fork();
		if (pid == 0) {
			int fd = open(errfile, O_WRONLY | O_CREAT | O_TRUNC, 0600);
			dup2(fd, 2);
			char *args[18] = {(char *)BSIM_EXE};
			for (int k = 0; argv[k]; k++)
				args[k + 1] = (char *)argv[k];
			execv(BSIM_EXE, args);
			_exit(127);
		}
		sleep_for(0.5 * full);
		kill(pid, sigs[i]);
		int rc = bsim_test_wait((int)pid);
		char *err = bsim_test_read(errfile);
		if (rc == 0) { /* finished before the signal: nothing to check */
			free(err);
			continue;
		}
		assert_int_equal(rc, 128 + sigs[i]);
		assert_non_null(strstr(err, sigs[i] == SIGINT ? "SIGINT" : "SIGTERM"));
		assert_non_null(strstr(err, "--resume"));
		assert_non_null(strstr(err, "stopped after"));
		assert_true(exists(join(dir, ".beamsim/journal")));
		assert_false(exists(join(dir, "trials.csv")));
		command(argv, "sweep", dir, 1);
		assert_int_equal(bsim_test_cli(argv, NULL, NULL), 0);
		same_files(ref, dir, sweep_files);
		free(err);
	}
}

/* Resuming with other inputs, with nothing to resume, or starting afresh
 * over a stopped run's journal is refused, saying why. */
static void test_refusals(void **state)
{
	(void)state;
	char dir[1200];
	const char *argv[16];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("refusals"));
	command(argv, "sweep", dir, 1);
	char *err = NULL;
	assert_int_equal(bsim_test_cli(argv, NULL, &err), 2);
	assert_non_null(strstr(err, "no stopped run to resume"));
	free(err);
	/* a stopped run: SIGINT right after it starts */
	command(argv, "sweep", dir, 0);
	int pid = bsim_test_spawn(argv);
	for (int k = 0; k < 500 && !exists(join(dir, ".beamsim/journal")); k++)
		sleep_for(0.002);
	kill(pid, SIGINT);
	int rc = bsim_test_wait(pid);
	if (rc == 0) {
		skip(); /* finished within the time it took to see the journal */
		return;
	}
	assert_int_equal(rc, 128 + SIGINT);
	assert_int_equal(bsim_test_cli(argv, NULL, &err), 2);
	assert_non_null(strstr(err, "add --resume to continue it"));
	free(err);
	const char *other[] = {"sweep",    experiment, "--quiet", "--out", dir,
	                       "--resume", "--seed",   "6",       NULL};
	assert_int_equal(bsim_test_cli(other, NULL, &err), 2);
	assert_non_null(strstr(err, "\"seed: 5\" then, \"seed: 6\" now"));
	free(err);
	const char *set[] = {"sweep",    experiment, "--quiet",     "--out", dir,
	                     "--resume", "--set",    "body.mass=2", NULL};
	assert_int_equal(bsim_test_cli(set, NULL, &err), 2);
	assert_non_null(strstr(err, "other inputs"));
	free(err);
	command(argv, "sweep", dir, 1);
	assert_int_equal(bsim_test_cli(argv, NULL, NULL), 0);
	assert_int_equal(bsim_test_cli(argv, NULL, &err), 2);
	assert_non_null(strstr(err, "finished run, nothing to resume"));
	free(err);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_sweep_killed),
	        cmocka_unit_test(test_compare_killed),
	        cmocka_unit_test(test_signals),
	        cmocka_unit_test(test_refusals),
	};
	return cmocka_run_group_tests(tests, setup, NULL);
}
