/* Stopping and resuming sweeps and comparisons through the real program.
 * The truth is the uninterrupted run: however often a run is killed (kill
 * -9 at moments drawn at random among what the run does: while loading,
 * once its journal has grown by some records, once it stages its files)
 * and resumed, the files it ends with are those of a
 * run never interrupted, byte for byte (trials.csv, and pairs.csv of a
 * comparison), and whenever a manifest is present it matches the files
 * beside it. SIGINT and SIGTERM stop cleanly with 128 + the signal's
 * number, keep the journal and print the line that resumes. A resume with
 * other inputs, or without a run to resume, is refused. Every kill and
 * signal waits on what the program does (its journal, its staging area),
 * never on time: the program installs its SIGINT and SIGTERM handlers
 * before it creates the journal. A stopped run's journal written by another
 * build (records of other fields, or the format before the journal named
 * them) is refused by name and left as it was. */
#define _POSIX_C_SOURCE 200809L

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <zlib.h>

#include "store/outdir.h"
#include "support.h"

#define CYCLES 10 /* kill-and-resume cycles per command */
/* A kill after the journal has grown comes after 1 to this many new
 * records: one group's trials, fewer than a sweep or a comparison of the
 * experiment below journals. */
#define MAX_RECORDS 24

static char experiment[1200];

/* A small experiment, into dir/name: 12 groups of 24 trials of at most
 * 1500 steps, the four without random force deterministic (run once,
 * copied), with seed_line ("seed: 5\n", or none). */
static void write_small(char *path, size_t size, const char *dir, const char *name,
                        const char *seed_line)
{
	char text[2400];
	snprintf(text, sizeof text,
	         "scene: %s\n"
	         "trials: 24\n"
	         "%s"
	         "set:\n"
	         "  integration.max_steps: 1500\n"
	         "grid:\n"
	         "  effects.propulsion.force: [6, 7, 8, 9]\n"
	         "  effects.random_force.magnitude: [0, 10, 30]\n",
	         bsim_test_src("configs/thesis/gate.yaml"), seed_line);
	snprintf(path, size, "%s", bsim_test_write(bsim_test_dir(dir), name, text));
}

static int setup(void **state)
{
	(void)state;
	write_small(experiment, sizeof experiment, "exp", "small.yaml", "seed: 5\n");
	return 0;
}

/* The command line of a run of cmd ("sweep", "compare", or "compare3":
 * a comparison of three sides) into dir. A comparison runs 8 of the 24
 * trials per group: Box2D is the slow side; a sweep keeps the trajectories
 * of two trials per group. */
static void command(const char **argv, const char *cmd, const char *dir, int resume)
{
	int n = 0;
	argv[n++] = strcmp(cmd, "compare3") == 0 ? "compare" : cmd;
	argv[n++] = experiment;
	if (strcmp(cmd, "compare3") == 0) {
		argv[n++] = "--backends";
		argv[n++] = "thesis,thesis:integrator=euler,box2d";
	}
	if (strncmp(cmd, "compare", 7) == 0) {
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
static const char *const compare3_files[] = {"thesis/trials.csv",
                                             "thesis-integrator=euler/trials.csv",
                                             "box2d/trials.csv", "pairs.csv", NULL};

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
		char *a = bsim_test_read(bsim_test_join(ref, files[i]));
		char *b = bsim_test_read(bsim_test_join(dir, files[i]));
		assert_non_null(a);
		if (!b || strcmp(a, b) != 0)
			fail_msg("%s differs from the uninterrupted run's",
			         bsim_test_join(dir, files[i]));
		free(a);
		free(b);
	}
}

static int done_status(int rc)
{
	return rc == 0 || rc == 3; /* compare: 3 reports disagreeing groups */
}

/* Where a run is killed: at once (while it loads), once its journal has
 * grown by 1 to MAX_RECORDS records (while trials run), or once a file is
 * staged (while it writes and commits its files). */
enum { AT_START, AT_RECORDS, AT_STAGED };

/* Starts argv and kills it at the moment at: the exit status, or that of
 * the run if it ended first. */
static int kill_at(const char *const *argv, const char *dir, int at)
{
	const char *journal = bsim_test_join(dir, ".beamsim/journal");
	long have = bsim_test_journal_records(journal);
	long want = (have > 0 ? have : 0) + 1 + rand() % MAX_RECORDS;
	char staging[1400];
	snprintf(staging, sizeof staging, "%s", bsim_test_join(dir, ".beamsim/staging"));
	/* a killed run's staging area is stale: the next run clears it; gone
	 * already, it cannot be mistaken for this run's files */
	if (at == AT_STAGED)
		assert_int_equal(bsim_test_remove(staging), 0);
	int pid = bsim_test_spawn(argv), rc = 0, running = 1;
	if (at == AT_RECORDS)
		running = bsim_test_await_records(pid, journal, want, &rc);
	else if (at == AT_STAGED)
		running = bsim_test_await_entry(pid, staging, &rc);
	if (!running)
		return rc;
	kill(pid, SIGKILL);
	return bsim_test_wait(pid);
}

/* Kills runs of cmd one to three times each cycle (the first time while
 * trials run, later at any moment), resumes until one finishes, and
 * compares with the uninterrupted run. */
static void kill_and_resume(const char *cmd, const char *const *files)
{
	char ref[1200], dir[1200];
	const char *argv[16];
	snprintf(ref, sizeof ref, "%s", bsim_test_dir(cmd));
	command(argv, cmd, ref, 0);
	assert_true(done_status(bsim_test_cli(argv, NULL, NULL)));
	srand(12345);
	int kills = 0, mid_run = 0;
	for (int c = 0; c < CYCLES; c++) {
		char name[64];
		snprintf(name, sizeof name, "%s_killed_%d", cmd, c);
		snprintf(dir, sizeof dir, "%s", bsim_test_dir(name));
		int finished = 0;
		for (int round = 0; !finished; round++) {
			int resume = bsim_test_exists(bsim_test_join(dir, ".beamsim/journal"));
			command(argv, cmd, dir, resume);
			if (round >= 1 + c % 3) { /* the last round runs to the end */
				int rc = bsim_test_cli(argv, NULL, NULL);
				if (!done_status(rc))
					fail_msg("cycle %d: the resumed %s ended with %d", c, cmd,
					         rc);
				finished = 1;
				break;
			}
			int rc = kill_at(argv, dir, round == 0 ? AT_RECORDS : rand() % 3);
			if (rc != 128 + SIGKILL) { /* it ended before the kill */
				if (!done_status(rc))
					fail_msg("cycle %d: %s ended with %d", c, cmd, rc);
				finished = 1;
				break;
			}
			kills++;
			/* a journal with records, and no finished set yet */
			long records =
			        bsim_test_journal_records(bsim_test_join(dir, ".beamsim/journal"));
			if (records > 0 && !bsim_test_exists(bsim_test_join(dir, "manifest.json")))
				mid_run++;
			check_manifest(dir);
		}
		same_files(ref, dir, files);
		check_manifest(dir);
		assert_false(bsim_test_exists(bsim_test_join(dir, ".beamsim")));
	}
	print_message("%s: %d kills (%d while trials ran) in %d cycles\n", cmd, kills, mid_run,
	              CYCLES);
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

/* Three sides: each record holds three results and three pairs'
 * separation times. */
static void test_compare3_killed(void **state)
{
	(void)state;
	kill_and_resume("compare3", compare3_files);
}

/* The uninterrupted sweep, into the test directory name (ref its path). */
static void reference_sweep(char *ref, size_t size, const char *name)
{
	const char *argv[16];
	snprintf(ref, size, "%s", bsim_test_dir(name));
	command(argv, "sweep", ref, 0);
	assert_int_equal(bsim_test_cli(argv, NULL, NULL), 0);
}

/* SIGINT and SIGTERM: a clean stop, the journal kept, the resume line. The
 * signal comes once a trial is journaled: its handler is in place. */
static void test_signals(void **state)
{
	(void)state;
	static const int sigs[] = {SIGINT, SIGTERM};
	char ref[1200], dir[1200], errfile[1400];
	const char *argv[16];
	reference_sweep(ref, sizeof ref, "signal_ref");
	for (int i = 0; i < 2; i++) {
		char name[32];
		snprintf(name, sizeof name, "signal_%d", sigs[i]);
		snprintf(dir, sizeof dir, "%s", bsim_test_dir(name));
		snprintf(errfile, sizeof errfile, "%s", bsim_test_join(dir, "../stderr.txt"));
		command(argv, "sweep", dir, 0);
		bsim_test_opts o = {.err = errfile};
		int pid = bsim_test_spawn_with(argv, &o), rc = 0;
		if (bsim_test_await_records(pid, bsim_test_join(dir, ".beamsim/journal"), 1, &rc)) {
			kill(pid, sigs[i]);
			rc = bsim_test_wait(pid);
		}
		char *err = bsim_test_read(errfile);
		if (rc == 0) { /* finished before the signal: nothing to check */
			print_message("the sweep finished before the signal\n");
			free(err);
			continue;
		}
		assert_int_equal(rc, 128 + sigs[i]);
		assert_non_null(strstr(err, sigs[i] == SIGINT ? "SIGINT" : "SIGTERM"));
		assert_non_null(strstr(err, "--resume"));
		/* The line to continue starts with the program as invoked. */
		if (!strpbrk(BSIM_EXE, " '\"$\\`"))
			assert_non_null(strstr(err, "to continue: " BSIM_EXE " sweep "));
		assert_non_null(strstr(err, "stopped after"));
		assert_true(bsim_test_exists(bsim_test_join(dir, ".beamsim/journal")));
		assert_false(bsim_test_exists(bsim_test_join(dir, "trials.csv")));
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
	/* a stopped run: SIGINT as soon as its journal is there */
	command(argv, "sweep", dir, 0);
	int pid = bsim_test_spawn(argv), rc = 0;
	if (bsim_test_await_records(pid, bsim_test_join(dir, ".beamsim/journal"), 0, &rc)) {
		kill(pid, SIGINT);
		rc = bsim_test_wait(pid);
	}
	if (rc == 0) {
		skip(); /* finished before it was seen to start */
		return;
	}
	assert_int_equal(rc, 128 + SIGINT);
	assert_int_equal(bsim_test_cli(argv, NULL, &err), 2);
	assert_non_null(strstr(err, "that run's command with --resume continues it"));
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

/* The whole file at path, *n its bytes (a journal is binary). */
static unsigned char *read_bytes(const char *path, long *n)
{
	FILE *f = fopen(path, "rb");
	assert_non_null(f);
	fseek(f, 0, SEEK_END);
	*n = ftell(f);
	rewind(f);
	unsigned char *b = malloc((size_t)*n + 1);
	assert_non_null(b);
	assert_int_equal(fread(b, 1, (size_t)*n, f), (size_t)*n);
	fclose(f);
	return b;
}

/* The journal j (format 2, util/journal.h) written again at path with
 * fields (NULL: in format 1, without them) and its own inputs and
 * records. */
static void journal_rewrite(const unsigned char *j, long n, const char *path, const char *fields)
{
	uint32_t fl, il;
	memcpy(&fl, j + 12, 4);
	memcpy(&il, j + 16 + fl, 4);
	const unsigned char *inputs = j + 20 + fl;
	long records = 20 + (long)fl + (long)il + 4;
	uint32_t nf = fields ? (uint32_t)strlen(fields) : 0;
	unsigned char *h = malloc(24 + nf + il);
	assert_non_null(h);
	memcpy(h, fields ? "BSIMJNL2" : "BSIMJNL1", 8);
	memcpy(h + 8, j + 8, 4); /* the record size */
	size_t at = 12;
	if (fields) {
		memcpy(h + at, &nf, 4);
		memcpy(h + at + 4, fields, nf);
		at += 4 + nf;
	}
	memcpy(h + at, &il, 4);
	memcpy(h + at + 4, inputs, il);
	at += 4 + il;
	uint32_t crc = (uint32_t)crc32(0L, h, (uInt)at);
	memcpy(h + at, &crc, 4);
	FILE *f = fopen(path, "wb");
	assert_non_null(f);
	assert_int_equal(fwrite(h, 1, at + 4, f), at + 4);
	assert_int_equal(fwrite(j + records, 1, (size_t)(n - records), f), (size_t)(n - records));
	assert_int_equal(fclose(f), 0);
	free(h);
}

/* --resume of a journal another build wrote: exit 2, one line naming the
 * journal and what differs, the journal as it was; then --overwrite runs
 * the sweep anew, as if never stopped. */
static void refused_then_overwritten(const char *dir, const char *journal, const char *ref,
                                     const char *const *want)
{
	const char *argv[16];
	long n0, n1;
	unsigned char *before = read_bytes(journal, &n0);
	command(argv, "sweep", dir, 1);
	char *err = NULL;
	int rc = bsim_test_cli(argv, NULL, &err);
	assert_int_equal(rc, 2);
	for (int i = 0; want[i]; i++)
		if (!strstr(err, want[i]))
			fail_msg("expected \"%s\" in: %s", want[i], err);
	assert_non_null(strstr(err, journal));
	assert_int_equal(strcspn(err, "\n"), strlen(err) - 1); /* one line */
	free(err);
	unsigned char *after = read_bytes(journal, &n1);
	assert_int_equal(n1, n0);
	assert_memory_equal(after, before, (size_t)n0);
	free(before);
	free(after);
	const char *over[] = {"sweep", experiment, "--quiet", "--out", dir, "--overwrite", NULL};
	assert_int_equal(bsim_test_cli(over, NULL, NULL), 0);
	same_files(ref, dir, (const char *const[]){"trials.csv", NULL});
}

/* A stopped sweep's journal as another build would have left it: one of
 * its records' fields other (x_end's kind), or in format 1, the format
 * before the journal named its fields. Each is refused by name. */
static void test_other_build(void **state)
{
	(void)state;
	char ref[1200], dir[1200], journal[1400];
	const char *argv[16];
	reference_sweep(ref, sizeof ref, "other_build_ref");
	for (int v = 0; v < 2; v++) {
		snprintf(dir, sizeof dir, "%s",
		         bsim_test_dir(v ? "other_build_1" : "other_build_2"));
		snprintf(journal, sizeof journal, "%s", bsim_test_join(dir, ".beamsim/journal"));
		command(argv, "sweep", dir, 0);
		int pid = bsim_test_spawn(argv), rc = 0;
		if (bsim_test_await_records(pid, journal, 1, &rc)) {
			kill(pid, SIGINT);
			rc = bsim_test_wait(pid);
		}
		if (rc == 0) {
			print_message("the sweep finished before the signal\n");
			continue;
		}
		assert_int_equal(rc, 128 + SIGINT);
		long n;
		unsigned char *j = read_bytes(journal, &n);
		assert_memory_equal(j, "BSIMJNL2", 8);
		uint32_t fl;
		memcpy(&fl, j + 12, 4);
		char *fields = strndup((const char *)j + 16, fl);
		char *x = strstr(fields, "\nx_end double ");
		assert_non_null(x);
		char line[64];
		snprintf(line, sizeof line, "%.*s", (int)strcspn(x + 1, "\n"), x + 1);
		if (v == 0) {
			/* x_end a long, where this build has a double */
			char *other = malloc(strlen(fields) + 8);
			snprintf(other, strlen(fields) + 8, "%.*sx_end long %s",
			         (int)(x + 1 - fields), fields, x + 1 + strlen("x_end double "));
			journal_rewrite(j, n, journal, other);
			char then[80], now[80];
			snprintf(then, sizeof then, "\"x_end long %s\" then",
			         line + strlen("x_end double "));
			snprintf(now, sizeof now, "\"%s\" now", line);
			refused_then_overwritten(
			        dir, journal, ref,
			        (const char *const[]){"records of other fields", then, now, NULL});
			free(other);
		} else {
			journal_rewrite(j, n, journal, NULL);
			refused_then_overwritten(
			        dir, journal, ref,
			        (const char *const[]){"--resume", "a journal of format 1",
			                              "this build reads format 2", NULL});
		}
		free(fields);
		free(j);
	}
}

/* Regression: an experiment without seed: run with --seed N said "seed:
 * missing". The seed given stands in for it: the sweep is the one of the
 * same experiment with seed: N in the file, trials.csv byte for byte,
 * whether it runs through or is stopped (SIGINT once a trial is
 * journaled) and resumed with the same --seed; the stored run records the
 * seed, so a trial of it replays to its row; without --seed the file is
 * refused, naming seed: and --seed. */
static void test_seed_beside_file(void **state)
{
	(void)state;
	char noseed[1200], ref[1200], dir[1200];
	write_small(noseed, sizeof noseed, "noseed", "noseed.yaml", "");
	snprintf(ref, sizeof ref, "%s", bsim_test_dir("noseed_ref"));
	const char *one[] = {"sweep", experiment, "--quiet", "--out", ref, NULL};
	assert_int_equal(bsim_test_cli(one, NULL, NULL), 0);
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("noseed_run"));
	const char *given[] = {"sweep", noseed,  "--seed", "5",  "--quiet", "--threads",
	                       "1",     "--out", dir,      NULL, NULL};
	char *err = NULL;
	int pid = bsim_test_spawn(given), rc = 0;
	if (bsim_test_await_records(pid, bsim_test_join(dir, ".beamsim/journal"), 1, &rc)) {
		kill(pid, SIGINT);
		rc = bsim_test_wait(pid);
	}
	if (rc == 128 + SIGINT) {
		given[9] = "--resume";
		assert_int_equal(bsim_test_cli(given, NULL, NULL), 0);
	} else {
		assert_int_equal(rc, 0); /* finished before the signal */
		print_message("the sweep finished before the signal\n");
	}
	same_files(ref, dir, (const char *const[]){"trials.csv", NULL});
	const char *replay[] = {"run", dir, "--group", "7", "--trial", "3", NULL};
	assert_int_equal(bsim_test_cli(replay, NULL, NULL), 0);
	const char *none[] = {"sweep", noseed, "--quiet", "--out", bsim_test_join(dir, "x"), NULL};
	rc = bsim_test_cli(none, NULL, &err);
	bsim_test_check_input_error(rc, err, (const char *const[]){"seed: missing", "--seed", NULL},
	                            1);
	free(err);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_sweep_killed),    cmocka_unit_test(test_compare_killed),
	        cmocka_unit_test(test_compare3_killed), cmocka_unit_test(test_signals),
	        cmocka_unit_test(test_refusals),        cmocka_unit_test(test_seed_beside_file),
	        cmocka_unit_test(test_other_build),
	};
	return cmocka_run_group_tests(tests, setup, NULL);
}
