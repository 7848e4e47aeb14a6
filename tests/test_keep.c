/* Nothing finished is thrown away, through the real program.
 *
 * A large run's own files are read back (their .mat twins, the manifest)
 * without the input_bytes limit, which bounds a user's files: a sweep of
 * 3000 groups writes a summary.json over 1 MiB, a comparison of 576 groups
 * a report.json over 1 MiB, and both succeed with the default limits.
 *
 * A file that cannot be written is simulated with a real mechanism that
 * needs no privilege: the child's RLIMIT_FSIZE (bsim_test_opts.fsize), so
 * a write beyond it fails with EFBIG, as a full disk fails with ENOSPC.
 * When the journal itself cannot grow, or a file cannot be written after
 * every trial ran, the run fails with exit status 1, a message naming the
 * cause (strerror of the errno, never a generic I/O error) and the line
 * that resumes it, and keeps its journal; resumed without the limit, it
 * ends with the files of an uninterrupted run (the truth), byte for byte
 * but for the wall-clock time in summary.json. This holds in a fresh
 * directory and over a previous run's files, which stay as they were until
 * the resumed run replaces them. */
#define _POSIX_C_SOURCE 200809L

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "store/outdir.h"
#include "support.h"

#define MIB 1048576L

static char small[1200]; /* 12 groups of 24 trials of at most 300 steps */

static const char *experiment(const char *name, const char *grid, int trials)
{
	char text[4000];
	snprintf(text, sizeof text,
	         "scene: %s\n"
	         "trials: %d\n"
	         "seed: 5\n"
	         "set:\n"
	         "  integration.max_steps: 300\n"
	         "grid:\n%s",
	         bsim_test_src("configs/thesis/gate.yaml"), trials, grid);
	return bsim_test_write(bsim_test_dir(name), "experiment.yaml", text);
}

/* "  KEY: [from, from + step, ...]" of n values. */
static void axis(char *buf, size_t size, const char *key, double from, double step, int n)
{
	size_t len = (size_t)snprintf(buf, size, "  %s: [", key);
	for (int i = 0; i < n && len < size; i++)
		len += (size_t)snprintf(buf + len, size - len, "%s%.6g", i ? ", " : "",
		                        from + step * i);
	if (len < size)
		snprintf(buf + len, size - len, "]\n");
}

static int setup(void **state)
{
	(void)state;
	snprintf(small, sizeof small, "%s",
	         experiment("exp_small",
	                    "  effects.propulsion.force: [6, 7, 8, 9]\n"
	                    "  effects.random_force.magnitude: [0, 10, 30]\n",
	                    24));
	return 0;
}

/* The grid force x magnitude of nf x nm groups. */
static const char *big_experiment(const char *name, int nf, int nm)
{
	char grid[3000], f[1400], m[1400];
	axis(f, sizeof f, "effects.propulsion.force", 4, 0.1, nf);
	axis(m, sizeof m, "effects.random_force.magnitude", 0, 1, nm);
	snprintf(grid, sizeof grid, "%s%s", f, m);
	return experiment(name, grid, 2);
}

static void test_large_sweep(void **state)
{
	(void)state;
	const char *exp = big_experiment("exp_big_sweep", 60, 50);
	const char *out = bsim_test_dir("big_sweep");
	const char *argv[] = {"sweep", exp, "--quiet", "--threads", "2", "--out", out, NULL};
	char *err = NULL;
	int rc = bsim_test_cli(argv, NULL, &err);
	if (rc != 0)
		fail_msg("sweep of 3000 groups: exit %d: %s", rc, err);
	long n = bsim_test_size(bsim_test_join(out, "summary.json"));
	if (n <= MIB)
		fail_msg("expected summary.json over 1 MiB, got %ld bytes", n);
	assert_true(bsim_test_size(bsim_test_join(out, "summary.mat")) > 0);
	assert_false(bsim_test_exists(bsim_test_join(out, ".beamsim")));
	int has = 0;
	bsim_error e;
	assert_int_equal(bsim_outdir_verify(out, &has, &e), BSIM_OK);
	assert_int_equal(has, 1);
	free(err);
}

static void test_large_compare(void **state)
{
	(void)state;
	const char *exp = big_experiment("exp_big_compare", 24, 24);
	const char *out = bsim_test_dir("big_compare");
	const char *argv[] = {"compare", exp, "--quiet", "--threads", "2", "--out", out, NULL};
	char *err = NULL;
	int rc = bsim_test_cli(argv, NULL, &err);
	if (rc != 0 && rc != 3) /* 3: groups that disagree, reported */
		fail_msg("compare of 576 groups: exit %d: %s", rc, err);
	long n = bsim_test_size(bsim_test_join(out, "report.json"));
	if (n <= MIB)
		fail_msg("expected report.json over 1 MiB, got %ld bytes", n);
	assert_true(bsim_test_size(bsim_test_join(out, "report.mat")) > 0);
	assert_false(bsim_test_exists(bsim_test_join(out, ".beamsim")));
	free(err);
}

/* text without its lines holding "wall_seconds" (malloc'd). */
static char *without_wall(const char *text)
{
	char *s = malloc(strlen(text) + 1), *o = s;
	assert_non_null(s);
	while (*text) {
		const char *end = strchr(text, '\n');
		size_t len = end ? (size_t)(end - text) + 1 : strlen(text);
		char line[4096];
		snprintf(line, sizeof line, "%.*s",
		         (int)(len < sizeof line ? len : sizeof line - 1), text);
		if (!strstr(line, "\"wall_seconds\"")) {
			memcpy(o, text, len);
			o += len;
		}
		text += len;
	}
	*o = '\0';
	return s;
}

/* dir's trials.csv, trajectories.csv and summary.json are ref's. */
static void same_as(const char *ref, const char *dir)
{
	const char *files[] = {"trials.csv", "trajectories.csv", "summary.json", NULL};
	for (int i = 0; files[i]; i++) {
		char *a = bsim_test_read(bsim_test_join(ref, files[i]));
		char *b = bsim_test_read(bsim_test_join(dir, files[i]));
		assert_non_null(a);
		if (!b)
			fail_msg("%s: missing", bsim_test_join(dir, files[i]));
		char *wa = without_wall(a), *wb = without_wall(b);
		if (strcmp(wa, wb) != 0)
			fail_msg("%s differs from the uninterrupted run's",
			         bsim_test_join(dir, files[i]));
		free(a);
		free(b);
		free(wa);
		free(wb);
	}
	int has = 0;
	bsim_error e;
	assert_int_equal(bsim_outdir_verify(dir, &has, &e), BSIM_OK);
	assert_int_equal(has, 1);
	assert_false(bsim_test_exists(bsim_test_join(dir, ".beamsim")));
}

/* The sweep into dir; then: 0 nothing, 1 --resume, 2 --overwrite. */
enum { FRESH, RESUME, OVERWRITE };
static void sweep_argv(const char **argv, const char *dir, int then)
{
	int n = 0;
	argv[n++] = "sweep";
	argv[n++] = small;
	argv[n++] = "--trajectories";
	argv[n++] = "4";
	argv[n++] = "--quiet";
	argv[n++] = "--threads";
	argv[n++] = "2";
	argv[n++] = "--out";
	argv[n++] = dir;
	if (then == RESUME)
		argv[n++] = "--resume";
	if (then == OVERWRITE)
		argv[n++] = "--overwrite";
	argv[n] = NULL;
}

/* Runs the sweep into dir with files limited to fsize bytes: it fails
 * with exit 1 and a message naming the cause and the resume, keeps its
 * journal (of at least min_records records), and the resumed run without
 * the limit gives ref's files. Returns the failed run's message. */
static char *fail_then_resume(const char *ref, const char *dir, long fsize, long min_records,
                              const char *names)
{
	const char *argv[16];
	sweep_argv(argv, dir, FRESH);
	bsim_test_opts limited = {.fsize = fsize};
	char *err = NULL;
	int rc = bsim_test_cli_with(argv, &limited, NULL, &err);
	if (rc != 1)
		fail_msg("with files of at most %ld bytes: expected exit 1, got %d: %s", fsize, rc,
		         err);
	const char *cause = strerror(EFBIG);
	if (!strstr(err, cause) || !strstr(err, "--resume") || !strstr(err, names) ||
	    strstr(err, strerror(EIO)))
		fail_msg("expected a message naming %s, \"%s\" and --resume, got \"%s\"", names,
		         cause, err);
	const char *journal = bsim_test_join(dir, ".beamsim/journal");
	long records = bsim_test_journal_records(journal);
	if (records < min_records)
		fail_msg("expected the journal kept with at least %ld records, got %ld",
		         min_records, records);
	assert_false(bsim_test_exists(bsim_test_join(dir, ".beamsim/staging")));

	sweep_argv(argv, dir, RESUME);
	char *err2 = NULL;
	rc = bsim_test_cli(argv, NULL, &err2);
	if (rc != 0)
		fail_msg("--resume: exit %d: %s", rc, err2);
	free(err2);
	same_as(ref, dir);
	return err;
}

/* The uninterrupted run, the truth. */
static const char *reference(void)
{
	static char ref[1400];
	snprintf(ref, sizeof ref, "%s", bsim_test_dir("ref"));
	const char *argv[16];
	sweep_argv(argv, ref, FRESH);
	assert_int_equal(bsim_test_cli(argv, NULL, NULL), 0);
	return ref;
}

/* The journal cannot grow past 20 kB (of some 54 kB): the trials
 * journaled before are kept, in a fresh directory and over a previous
 * run's files, which stay as they were until the resumed run ends. */
static void test_journal_full(void **state)
{
	(void)state;
	const char *ref = reference();
	char dir[1400];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("journal_full"));
	assert_int_equal(bsim_test_remove(dir), 0);
	free(fail_then_resume(ref, dir, 20000, 1, "cannot append to the journal"));

	/* over the run just finished: its files stay while the next fails */
	char *before = bsim_test_read(bsim_test_join(dir, "trials.csv"));
	assert_non_null(before);
	const char *argv[16];
	sweep_argv(argv, dir, OVERWRITE);
	bsim_test_opts limited = {.fsize = 20000};
	char *err = NULL;
	assert_int_equal(bsim_test_cli_with(argv, &limited, NULL, &err), 1);
	char *during = bsim_test_read(bsim_test_join(dir, "trials.csv"));
	assert_non_null(during);
	assert_string_equal(before, during);
	assert_true(bsim_test_journal_records(bsim_test_join(dir, ".beamsim/journal")) > 0);
	sweep_argv(argv, dir, RESUME);
	assert_int_equal(bsim_test_cli(argv, NULL, NULL), 0);
	same_as(ref, dir);
	free(before);
	free(during);
	free(err);
}

/* Every trial is journaled (some 54 kB), then trajectories.csv (some
 * 90 kB) cannot be written: the journal is kept whole and the resumed run
 * writes the files. */
static void test_files_full(void **state)
{
	(void)state;
	const char *ref = reference();
	long limit = 70000;
	if (bsim_test_size(bsim_test_join(ref, "trajectories.csv")) <= limit)
		fail_msg("expected trajectories.csv over %ld bytes", limit);
	char dir[1400];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("files_full"));
	/* 8 groups of 24 trials with random force, 4 of one trial without */
	char *err = fail_then_resume(ref, dir, limit, 8 * 24 + 4, "trajectories.csv");
	if (strstr(err, "staging"))
		fail_msg("expected the file named in %s, not its staging area: \"%s\"", dir, err);
	free(err);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_large_sweep),
	        cmocka_unit_test(test_large_compare),
	        cmocka_unit_test(test_journal_full),
	        cmocka_unit_test(test_files_full),
	};
	return cmocka_run_group_tests(tests, setup, NULL);
}
