/* Output files and directories through the real program. The truths are
 * the contracts: "-" is standard output; a symlink, FIFO or device is
 * written through and stays what it was; an output directory that cannot
 * be written is refused (exit 2) before any work; a directory's files are
 * replaced as a set (a failed rerun leaves the previous set whole, and its
 * manifest then still matches it); files a previous run listed and this one
 * did not write are removed, files beamsim did not write are kept; a write
 * error on standard output fails the run; messages name the user's paths. */
#define _POSIX_C_SOURCE 200809L

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "beamsim/trial_fields.h"
#include "store/outdir.h"
#include "store/trials_csv.h"
#include "support.h"

static char gate[1200], h1[1200], h2[1200];

static int setup(void **state)
{
	(void)state;
	snprintf(gate, sizeof gate, "%s", bsim_test_src("configs/thesis/gate.yaml"));
	snprintf(h1, sizeof h1, "%s", bsim_test_src("configs/thesis/h1_symmetric.yaml"));
	snprintf(h2, sizeof h2, "%s", bsim_test_src("configs/thesis/h2_asymmetric.yaml"));
	return 0;
}

static void test_trajectory_to_stdout(void **state)
{
	(void)state;
	char *out = NULL, *err = NULL;
	const char *argv[] = {"run", gate, "--trajectory", "-", "--stride", "500", NULL};
	assert_int_equal(bsim_test_cli(argv, &out, &err), 0);
	assert_int_equal(strncmp(out, "t,x,y,vx,vy,", 12), 0);
	/* t = 0, every 500th of 3000 steps, the final state: 8 rows */
	assert_int_equal(bsim_test_count_lines(out), 8);
	assert_non_null(strstr(err, "outcome")); /* the report went to stderr */
	assert_int_equal(access("-", F_OK), -1); /* no file named "-" */
	free(out);
	free(err);
}

static void test_trajectory_through_symlink(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("symlink");
	char target[1400], link[1400];
	snprintf(target, sizeof target, "%s", bsim_test_join(dir, "target.csv"));
	snprintf(link, sizeof link, "%s", bsim_test_join(dir, "link.csv"));
	assert_int_equal(symlink(target, link), 0);
	const char *argv[] = {"run", gate, "--trajectory", link, NULL};
	assert_int_equal(bsim_test_cli(argv, NULL, NULL), 0);
	struct stat st;
	assert_int_equal(lstat(link, &st), 0);
	assert_true(S_ISLNK(st.st_mode));
	char *csv = bsim_test_read(target);
	assert_non_null(csv);
	assert_int_equal(bsim_test_count_lines(csv), 3002); /* header, t = 0 and 3000 steps */
	free(csv);
}

static void test_trajectory_through_fifo_and_device(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("fifo");
	char fifo[1400], copy[1400];
	snprintf(fifo, sizeof fifo, "%s", bsim_test_join(dir, "pipe"));
	snprintf(copy, sizeof copy, "%s", bsim_test_join(dir, "copy.csv"));
	assert_int_equal(mkfifo(fifo, 0600), 0);
	fflush(NULL);
	pid_t reader = fork();
	if (reader == 0) { /* cat pipe > copy.csv */
		int in = open(fifo, O_RDONLY), out = open(copy, O_WRONLY | O_CREAT | O_TRUNC, 0600);
		char buf[4096];
		ssize_t k;
		while ((k = read(in, buf, sizeof buf)) > 0)
			if (write(out, buf, (size_t)k) != k)
				_exit(1);
		_exit(close(out) != 0);
	}
	const char *argv[] = {"run", gate, "--trajectory", fifo, "--stride", "1000", NULL};
	assert_int_equal(bsim_test_cli(argv, NULL, NULL), 0);
	int status = 0;
	waitpid(reader, &status, 0);
	assert_true(WIFEXITED(status) && WEXITSTATUS(status) == 0);
	struct stat st;
	assert_int_equal(lstat(fifo, &st), 0);
	assert_true(S_ISFIFO(st.st_mode));
	char *csv = bsim_test_read(copy);
	assert_int_equal(bsim_test_count_lines(csv), 5);
	free(csv);
	const char *dev[] = {"run", gate, "--trajectory", "/dev/null", NULL};
	assert_int_equal(bsim_test_cli(dev, NULL, NULL), 0);
	assert_int_equal(stat("/dev/null", &st), 0);
	assert_true(S_ISCHR(st.st_mode));
}

/* A full standard output is a failed run, named as such. */
static void test_stdout_errors(void **state)
{
	(void)state;
	bsim_test_opts full = {.out = "/dev/full"};
	const char *cmds[][6] = {
	        {"backends", NULL},
	        {"run", gate, NULL},
	        {"run", gate, "--trajectory", "-", NULL},
	        {"--help", NULL},
	};
	for (size_t i = 0; i < sizeof cmds / sizeof cmds[0]; i++) {
		char *err = NULL;
		assert_int_equal(bsim_test_cli_with(cmds[i], &full, NULL, &err), 1);
		assert_non_null(
		        strstr(err, "standard output: write failed: No space left on device"));
		free(err);
	}
}

/* An unusable --out is refused before the sweep, which would take minutes:
 * 150,000 trials. On a terminal the sweep shows its progress from the first
 * trial it finishes (as the small sweep here shows); the refusal comes with
 * none, so it came before any trial. */
static void test_unwritable_out(void **state)
{
	(void)state;
	bsim_test_opts o = {.timeout = 60, .tty = 1};
	const char *small[] = {"sweep", h1, "--trials", "1", "--out", bsim_test_dir("shown"), NULL};
	char *err = NULL;
	assert_int_equal(bsim_test_cli_with(small, &o, NULL, &err), 0);
	if (!strstr(err, "30/30 trials"))
		fail_msg("no progress on a terminal: \"%s\"", err);
	free(err);
	const char *dir = bsim_test_dir("unwritable");
	char file[1400], under[1400], ro[1400];
	snprintf(file, sizeof file, "%s", bsim_test_write(dir, "file", "x\n"));
	snprintf(under, sizeof under, "%s", bsim_test_join(file, "sub"));
	snprintf(ro, sizeof ro, "%s", bsim_test_join(dir, "readonly"));
	mkdir(ro, 0500);
	/* root writes anywhere it has permission bits for; /proc it cannot */
	const char *locked = geteuid() == 0 ? "/proc/self/fdinfo" : ro;
	const char *const outs[][2] = {
	        {file, "expected an output directory, got a file"},
	        {under, "cannot write to the output directory: Not a directory"},
	        {locked, "cannot write to the output directory"},
	};
	for (size_t i = 0; i < 3; i++) {
		const char *argv[] = {"sweep", h1, "--trials", "5000", "--out", outs[i][0], NULL};
		const char *needles[] = {outs[i][0], outs[i][1], NULL};
		int rc = bsim_test_cli_with(argv, &o, NULL, &err);
		if (strstr(err, "/150000 trials"))
			fail_msg("progress before the refusal: \"%s\"", err);
		bsim_test_check_input_error(rc, err, needles, 1);
		free(err);
	}
	chmod(ro, 0700);
}

/* Two runs cannot write one directory at once. */
static void test_lock(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("locked");
	int fd = open(dir, O_RDONLY | O_DIRECTORY);
	assert_true(fd >= 0);
	assert_int_equal(flock(fd, LOCK_EX | LOCK_NB), 0);
	const char *argv[] = {"sweep", h1, "--trials", "1", "--quiet", "--out", dir, NULL};
	char *err = NULL;
	assert_int_equal(bsim_test_cli(argv, NULL, &err), 2);
	assert_non_null(strstr(err, "another beamsim run is writing this directory"));
	close(fd);
	assert_int_equal(bsim_test_cli(argv, NULL, NULL), 0);
	free(err);
}

/* Every entry below path (path itself included), one line each with its
 * kind, inode, size and modification time to the nanosecond, appended to
 * buf: a directory whose entries change changes its time, so two equal
 * listings mean nothing was created, removed or written in between. */
static void tree_list(const char *path, char *buf, size_t size)
{
	struct stat st;
	size_t len = strlen(buf);
	if (lstat(path, &st) != 0) {
		snprintf(buf + len, size - len, "%s missing\n", path);
		return;
	}
	snprintf(buf + len, size - len, "%s %o %llu %lld %lld.%09ld\n", path,
	         (unsigned)(st.st_mode & S_IFMT), (unsigned long long)st.st_ino,
	         (long long)st.st_size, (long long)st.st_mtim.tv_sec, st.st_mtim.tv_nsec);
	if (!S_ISDIR(st.st_mode))
		return;
	DIR *d = opendir(path);
	assert_non_null(d);
	struct dirent *e;
	char names[64][256];
	int n = 0;
	while ((e = readdir(d)) && n < 64)
		if (strcmp(e->d_name, ".") && strcmp(e->d_name, ".."))
			snprintf(names[n++], sizeof names[0], "%s", e->d_name);
	closedir(d);
	for (int i = 0; i < n; i++) /* readdir's order, the same for an unchanged directory */
		tree_list(bsim_test_join(path, names[i]), buf, size);
}

/* A run refused on a directory another run is writing touches nothing in
 * it: a sweep of H2 (two real processes) journals its first trial and is
 * stopped (SIGSTOP, so that it is still running at every check below, on
 * a machine however busy); then a second sweep, a plot, a markov build, a
 * landscape, a run --out, a comparison and the same sweep with --resume and
 * with --overwrite are each refused with exit 2 naming the directory and
 * the run that holds it, and the directory, its staging area and journal
 * included, is exactly as it was. Continued, the first sweep ends with all
 * its 16,200 trials. */
static void test_refused_run_touches_nothing(void **state)
{
	(void)state;
	char dir[1400], journal[1500], pid_text[32];
	snprintf(dir, sizeof dir, "%s", bsim_test_join(bsim_test_dir("held"), "D"));
	snprintf(journal, sizeof journal, "%s/.beamsim/journal", dir);
	const char *first[] = {"sweep", h2, "--threads", "1", "--quiet", "--out", dir, NULL};
	int pid = bsim_test_spawn(first), status = 0;
	if (!bsim_test_await_records(pid, journal, 1, &status))
		fail_msg("the sweep of H2 ended (status %d) before journaling a trial", status);
	assert_int_equal(kill(pid, SIGSTOP), 0);
	assert_int_equal(waitpid(pid, &status, WUNTRACED), pid);
	if (!WIFSTOPPED(status))
		fail_msg("the sweep of H2 ended (status %d) before it could be stopped", status);
	snprintf(pid_text, sizeof pid_text, "process %d", pid);

	static char before[16384], after[16384];
	before[0] = after[0] = '\0';
	tree_list(dir, before, sizeof before);
	assert_non_null(strstr(before, "/.beamsim/staging"));
	char figs[1500];
	snprintf(figs, sizeof figs, "%s", bsim_test_join(bsim_test_dir("held_figs"), "f"));
	const char *markov_exp = bsim_test_src("configs/markov/c_track.yaml");
	const char *refused[][12] = {
	        {"sweep", h1, "--trials", "2", "--out", dir, NULL},
	        {"sweep", h2, "--threads", "1", "--quiet", "--out", dir, "--resume", NULL},
	        {"sweep", h2, "--threads", "1", "--quiet", "--out", dir, "--overwrite", NULL},
	        {"plot", dir, NULL},
	        {"markov", "build", markov_exp, "--trials", "2", "--out", dir, NULL},
	        {"landscape", gate, "--resolution", "2", "--out", dir, NULL},
	        {"run", gate, "--out", dir, "--overwrite", NULL},
	        {"compare", h1, "--trials", "1", "--out", dir, NULL},
	};
	for (size_t i = 0; i < sizeof refused / sizeof refused[0]; i++) {
		const char *needles[] = {dir, "another beamsim run (beamsim sweep, ", pid_text,
		                         "is writing this directory", NULL};
		bsim_test_expect_input_error(refused[i], needles);
	}
	tree_list(dir, after, sizeof after);
	assert_string_equal(before, after);

	assert_int_equal(kill(pid, SIGCONT), 0);
	assert_int_equal(bsim_test_wait(pid), 0);
	char *csv = bsim_test_read(bsim_test_join(dir, "trials.csv"));
	assert_non_null(csv);
	assert_int_equal(bsim_test_count_lines(csv), 16200 + 1);
	int has = 0;
	bsim_error e;
	assert_int_equal(bsim_outdir_verify(dir, &has, &e), BSIM_OK);
	assert_int_equal(has, 1);
	assert_false(bsim_test_exists(bsim_test_join(dir, ".beamsim")));
	free(csv);
}

/* A directory holding a finished result is refused, naming it and what
 * wrote it, and stays as it was; --overwrite replaces it; --resume with
 * --overwrite is a usage error. A stopped run's journal is refused
 * likewise, naming both ways on, and --overwrite starts over. */
static void test_finished_result_needs_overwrite(void **state)
{
	(void)state;
	char dir[1400];
	snprintf(dir, sizeof dir, "%s", bsim_test_join(bsim_test_dir("finished"), "out"));
	const char *sweep[] = {"sweep", h1, "--trials", "2", "--quiet", "--out", dir, NULL};
	assert_int_equal(bsim_test_cli(sweep, NULL, NULL), 0);
	static char before[16384], after[16384];
	before[0] = after[0] = '\0';
	tree_list(dir, before, sizeof before);
	const char *again[] = {"sweep", h1, "--trials", "3", "--quiet", "--out", dir, NULL};
	const char *needles[] = {dir, "holds the finished result of beamsim sweep", "--overwrite",
	                         NULL};
	bsim_test_expect_input_error(again, needles);
	const char *other[] = {"landscape", gate, "--resolution", "2", "--out", dir, NULL};
	bsim_test_expect_input_error(other, needles);
	tree_list(dir, after, sizeof after);
	assert_string_equal(before, after);

	const char *both[] = {"sweep", h1,         "--trials",    "3", "--out",
	                      dir,     "--resume", "--overwrite", NULL};
	char *err = NULL;
	assert_int_equal(bsim_test_cli(both, NULL, &err), 2);
	assert_non_null(strstr(err, "--resume and --overwrite: expected one of them"));
	free(err);

	const char *replace[] = {"sweep", h1,  "--trials",    "3", "--quiet",
	                         "--out", dir, "--overwrite", NULL};
	assert_int_equal(bsim_test_cli(replace, NULL, NULL), 0);
	char *csv = bsim_test_read(bsim_test_join(dir, "trials.csv"));
	assert_int_equal(bsim_test_count_lines(csv), 30 * 3 + 1);
	free(csv);

	/* a stopped run: its journal is refused without --resume or --overwrite */
	char stopped[1400], journal[1500];
	snprintf(stopped, sizeof stopped, "%s", bsim_test_join(bsim_test_dir("stopped"), "out"));
	snprintf(journal, sizeof journal, "%s/.beamsim/journal", stopped);
	const char *long_run[] = {"sweep", h2, "--threads", "1", "--quiet", "--out", stopped, NULL};
	int pid = bsim_test_spawn(long_run), status = 0;
	if (!bsim_test_await_records(pid, journal, 1, &status))
		fail_msg("the sweep of H2 ended (status %d) before journaling a trial", status);
	kill(pid, SIGKILL);
	bsim_test_wait(pid);
	long kept = bsim_test_journal_records(journal);
	const char *fresh[] = {"sweep", h1, "--trials", "2", "--quiet", "--out", stopped, NULL};
	const char *j_needles[] = {stopped, "journal of a stopped run", "--resume", "--overwrite",
	                           NULL};
	bsim_test_expect_input_error(fresh, j_needles);
	assert_int_equal(bsim_test_journal_records(journal), kept);
	const char *over[] = {"sweep", h1,      "--trials",    "2", "--quiet",
	                      "--out", stopped, "--overwrite", NULL};
	assert_int_equal(bsim_test_cli(over, NULL, NULL), 0);
	assert_false(bsim_test_exists(journal));
	csv = bsim_test_read(bsim_test_join(stopped, "trials.csv"));
	assert_int_equal(bsim_test_count_lines(csv), 30 * 2 + 1);
	free(csv);
}

/* A rerun into a directory on a disk that fills up (RLIMIT_FSIZE: no file
 * may pass 30 kB, trials.csv needs 51 kB) fails naming the user's path,
 * and the directory keeps the previous run's files, whole, with their
 * manifest. regress reruns a stored sweep into --out without a journal. */
static void test_failed_rerun_keeps_previous_set(void **state)
{
	(void)state;
	const char *base1 = bsim_test_dir("base1"), *base2 = NULL;
	char b1[1400], b2[1400], out[1400];
	snprintf(b1, sizeof b1, "%s", base1);
	const char *s1[] = {"sweep", h1, "--trials", "20", "--quiet", "--out", b1, NULL};
	assert_int_equal(bsim_test_cli(s1, NULL, NULL), 0);
	base2 = bsim_test_dir("base2");
	snprintf(b2, sizeof b2, "%s", base2);
	const char *s2[] = {"sweep", h1,        "--trials", "20", "--seed",
	                    "2",     "--quiet", "--out",    b2,   NULL};
	assert_int_equal(bsim_test_cli(s2, NULL, NULL), 0);
	snprintf(out, sizeof out, "%s", bsim_test_dir("rerun"));
	const char *r1[] = {"regress", b1, "--quiet", "--out", out, NULL};
	assert_int_equal(bsim_test_cli(r1, NULL, NULL), 0);
	char *before = bsim_test_read(bsim_test_join(out, "trials.csv"));
	char *before_json = bsim_test_read(bsim_test_join(out, "regress.json"));

	const char *r2[] = {"regress", b2, "--quiet", "--out", out, "--overwrite", NULL};
	bsim_test_opts small = {.fsize = 30000};
	char *err = NULL;
	assert_int_equal(bsim_test_cli_with(r2, &small, NULL, &err), 1);
	if (!strstr(err, bsim_test_join(out, "trials.csv")) || strstr(err, ".beamsim") ||
	    strstr(err, ".tmp."))
		fail_msg("expected a message naming %s, got \"%s\"",
		         bsim_test_join(out, "trials.csv"), err);
	char *after = bsim_test_read(bsim_test_join(out, "trials.csv"));
	char *after_json = bsim_test_read(bsim_test_join(out, "regress.json"));
	assert_string_equal(before, after);
	assert_string_equal(before_json, after_json);
	int has = 0;
	bsim_error e;
	assert_int_equal(bsim_outdir_verify(out, &has, &e), BSIM_OK);
	assert_int_equal(has, 1);
	assert_int_equal(access(bsim_test_join(out, ".beamsim"), F_OK), -1); /* no staging left */
	free(before);
	free(after);
	free(before_json);
	free(after_json);
	free(err);
}

/* Rerunning a sweep into a comparison's directory removes what the
 * comparison wrote and the sweep does not (its manifest lists them), keeps
 * what beamsim never wrote, and writes through a symlinked trials.csv. */
static void test_replacing_a_set(void **state)
{
	(void)state;
	const char *d = bsim_test_dir("replace");
	char dir[1400], elsewhere[1400];
	snprintf(dir, sizeof dir, "%s", d);
	const char *cmp[] = {"compare", h1, "--trials", "1", "--quiet", "--out", dir, NULL};
	int rc = bsim_test_cli(cmp, NULL, NULL);
	assert_true(rc == 0 || rc == 3);
	assert_int_equal(access(bsim_test_join(dir, "pairs.csv"), F_OK), 0);
	bsim_test_write(dir, "notes.txt", "mine\n");
	snprintf(elsewhere, sizeof elsewhere, "%s",
	         bsim_test_join(bsim_test_dir("elsewhere"), "t.csv"));
	assert_int_equal(symlink(elsewhere, bsim_test_join(dir, "trials.csv")), 0);
	const char *sweep[] = {"sweep", h1,  "--trials",    "1", "--quiet",
	                       "--out", dir, "--overwrite", NULL};
	assert_int_equal(bsim_test_cli(sweep, NULL, NULL), 0);
	const char *gone[] = {"pairs.csv", "report.md", "report.json", "thesis/trials.csv",
	                      "box2d/summary.json"};
	for (int i = 0; i < 5; i++)
		if (access(bsim_test_join(dir, gone[i]), F_OK) == 0)
			fail_msg("%s of the comparison is still there", gone[i]);
	assert_int_equal(access(bsim_test_join(dir, "notes.txt"), F_OK), 0);
	struct stat st;
	assert_int_equal(lstat(bsim_test_join(dir, "trials.csv"), &st), 0);
	assert_true(S_ISLNK(st.st_mode));
	char *csv = bsim_test_read(elsewhere);
	assert_int_equal(bsim_test_count_lines(csv), 31); /* header and 30 groups x 1 trial */
	int has = 0;
	bsim_error e;
	assert_int_equal(bsim_outdir_verify(dir, &has, &e), BSIM_OK);
	assert_int_equal(has, 1);
	free(csv);
}

/* The reader's check: a file that is not the one the manifest lists (a mix
 * of two runs) is named. */
static void test_manifest_check(void **state)
{
	(void)state;
	const char *d = bsim_test_dir("manifest");
	char dir[1400];
	snprintf(dir, sizeof dir, "%s", d);
	const char *sweep[] = {"sweep", h1, "--trials", "1", "--quiet", "--out", dir, NULL};
	assert_int_equal(bsim_test_cli(sweep, NULL, NULL), 0);
	char *json = bsim_test_read(bsim_test_join(dir, "summary.json"));
	json[strlen(json) - 3] ^= 1; /* one bit of the last line */
	bsim_test_write(dir, "summary.json", json);
	int has = 0;
	bsim_error e;
	assert_int_equal(bsim_outdir_verify(dir, &has, &e), BSIM_EINPUT);
	assert_non_null(strstr(e.msg, "summary.json"));
	assert_non_null(strstr(e.msg, "mixes files of two runs"));
	/* a file grown past its listed size is named with its whole size */
	char grown[64];
	size_t len = strlen(json);
	json[len - 3] ^= 1;
	char *longer = malloc(len + 3);
	assert_non_null(longer);
	snprintf(longer, len + 3, "%s  ", json);
	bsim_test_write(dir, "summary.json", longer);
	free(longer);
	snprintf(grown, sizeof grown, "got %zu bytes: the directory mixes", len + 2);
	assert_int_equal(bsim_outdir_verify(dir, &has, &e), BSIM_EINPUT);
	if (!strstr(e.msg, grown))
		fail_msg("\"%s\" lacks \"%s\"", e.msg, grown);
	/* and regress refuses such a baseline */
	const char *argv[] = {"regress", dir, "--quiet", "--out", bsim_test_dir("mixed_rerun"),
	                      NULL};
	assert_int_equal(bsim_test_cli(argv, NULL, NULL), 2);
	free(json);
}

/* plot adds its figures to a sweep's set (the manifest lists them), a
 * rerun of the sweep removes them with the rest of the old set, and run
 * --out writes its directory as a set too. */
static void test_figures_join_the_set(void **state)
{
	(void)state;
	char dir[1400];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("plotted"));
	const char *sweep[] = {"sweep", h1,        "--trials", "2", "--trajectories",
	                       "1",     "--quiet", "--out",    dir, NULL};
	assert_int_equal(bsim_test_cli(sweep, NULL, NULL), 0);
	const char *plot[] = {"plot", dir, "--quiet", NULL};
	assert_int_equal(bsim_test_cli(plot, NULL, NULL), 0);
	char *manifest = bsim_test_read(bsim_test_join(dir, "manifest.json"));
	/* still the sweep's result, with the figures added */
	assert_non_null(strstr(manifest, "\"command\": \"sweep\""));
	assert_non_null(strstr(manifest, "\"path\": \"p_traverse.gp\""));
	assert_non_null(strstr(manifest, "\"path\": \"trials.csv\""));
	int has = 0;
	bsim_error e;
	assert_int_equal(bsim_outdir_verify(dir, &has, &e), BSIM_OK);
	assert_int_equal(has, 1);
	/* a rerun is refused as it stands, and replaces the set with --overwrite */
	assert_int_equal(bsim_test_cli(sweep, NULL, NULL), 2);
	assert_int_equal(access(bsim_test_join(dir, "p_traverse.gp"), F_OK), 0);
	const char *again[] = {"sweep", h1,  "--trials",    "2", "--trajectories", "1", "--quiet",
	                       "--out", dir, "--overwrite", NULL};
	assert_int_equal(bsim_test_cli(again, NULL, NULL), 0);
	assert_int_equal(access(bsim_test_join(dir, "p_traverse.gp"), F_OK), -1);
	free(manifest);

	char run_dir[1400];
	snprintf(run_dir, sizeof run_dir, "%s", bsim_test_dir("run_out"));
	const char *run[] = {"run", gate, "--out", run_dir, NULL};
	assert_int_equal(bsim_test_cli(run, NULL, NULL), 0);
	manifest = bsim_test_read(bsim_test_join(run_dir, "manifest.json"));
	assert_non_null(strstr(manifest, "\"path\": \"trajectory.csv\""));
	assert_int_equal(bsim_outdir_verify(run_dir, &has, &e), BSIM_OK);
	free(manifest);
}

/* The table of trials.csv's columns in docs/files.md against the library's
 * description of them (beamsim/trial_fields.h): every column named there,
 * in order, in the first cell of its row (a row may name several), each
 * with its unit in the row where it has one, and no other column. */
static void test_docs_trials_columns(void **state)
{
	(void)state;
	char *doc = bsim_test_read(bsim_test_src("docs/files.md"));
	assert_non_null(doc);
	char *at = strstr(doc, "`trials.csv`, one row per trial");
	assert_non_null(at);
	at = strstr(at, "| column | meaning |");
	assert_non_null(at);
	at = strchr(at, '\n') + 1; /* the rule under the header */
	at = strchr(at, '\n') + 1;
	int n;
	const bsim_trial_field *f = bsim_trial_fields(&n);
	int k = 0;
	while (at[0] == '|') {
		char *eol = strchr(at, '\n');
		assert_non_null(eol);
		*eol = '\0';
		char *cell_end = strstr(at + 1, " | ");
		assert_non_null(cell_end);
		*cell_end = '\0';
		/* the first cell's names: `name`, `name` */
		for (char *q = strchr(at, '`'); q; q = strchr(q, '`')) {
			char *close = strchr(q + 1, '`');
			assert_non_null(close);
			*close = '\0';
			if (k >= n)
				fail_msg("docs/files.md: column %s is not one of trials.csv's",
				         q + 1);
			if (strcmp(q + 1, f[k].name) != 0)
				fail_msg("docs/files.md: column %d is %s, the library's %s", k + 1,
				         q + 1, f[k].name);
			if (f[k].unit[0] && !strstr(cell_end + 3, f[k].unit))
				fail_msg("docs/files.md: %s's row does not give its unit, %s",
				         f[k].name, f[k].unit);
			k++;
			q = close + 1;
		}
		at = eol + 1;
	}
	assert_int_equal(k, n);
	free(doc);
}

/* docs/lattice.md's row of file in its table of files: the columns it
 * lists (the second cell, `a,b,...`) against the library's table of them,
 * every name in order and no other; and the file as a sweep writes it
 * (header) has that line first. */
static void docs_lattice_columns(const char *doc, const char *file, const bsim_trial_field *f,
                                 int n, const char *header)
{
	char row[64];
	snprintf(row, sizeof row, "| `%s` | `", file);
	const char *at = strstr(doc, row);
	if (!at)
		fail_msg("docs/lattice.md: no row for %s", file);
	at += strlen(row);
	size_t len = strcspn(at, "`");
	char want[512] = "";
	for (int k = 0; k < n; k++) {
		strncat(want, k ? "," : "", sizeof want - strlen(want) - 1);
		strncat(want, f[k].name, sizeof want - strlen(want) - 1);
	}
	if (len != strlen(want) || strncmp(at, want, len) != 0)
		fail_msg("docs/lattice.md: %s's columns are %.*s, the library's %s", file, (int)len,
		         at, want);
	if (strncmp(header, want, strlen(want)) != 0 || header[strlen(want)] != '\n')
		fail_msg("%s's header is not the library's columns %s", file, want);
}

/* The lattice's per-trial files, gate_entries.csv (the gate paths) and
 * beam_peaks.csv, are described once (beamsim/trial_fields.h): the
 * columns docs/lattice.md lists and a lattice sweep's files against those
 * descriptions. */
static void test_docs_lattice_columns(void **state)
{
	(void)state;
	char *doc = bsim_test_read(bsim_test_src("docs/lattice.md"));
	assert_non_null(doc);
	const char *dir = bsim_test_dir("lattice_columns");
	const char *argv[] = {"sweep",    bsim_test_src("configs/markov/c_track.yaml"),
	                      "--trials", "1",
	                      "--quiet",  "--out",
	                      dir,        NULL};
	assert_int_equal(bsim_test_cli(argv, NULL, NULL), 0);
	static const char *const files[] = {"gate_entries.csv", "beam_peaks.csv"};
	for (int i = 0; i < 2; i++) {
		int n;
		const bsim_trial_field *f =
		        i ? bsim_beam_peak_fields(&n) : bsim_gate_entry_fields(&n);
		char *text = bsim_test_read(bsim_test_join(dir, files[i]));
		assert_non_null(text);
		docs_lattice_columns(doc, files[i], f, n, text);
		free(text);
	}
	free(doc);
}

/* A comparison's pairs.csv of `backends` (trials of H1, one a group): its
 * header line, which docs/files.md gives as `line`, and each side's
 * column a trials.csv column of the library's table (beamsim/trial_fields.h)
 * with its side's letter, beside the pairs' separation times. */
static void pairs_columns(const char *doc, const char *backends, const char *name)
{
	const char *dir = bsim_test_dir(name);
	const char *argv[] = {"compare",    bsim_test_src("configs/thesis/h1_symmetric.yaml"),
	                      "--backends", backends,
	                      "--trials",   "1",
	                      "--quiet",    "--out",
	                      dir,          NULL};
	int code = bsim_test_cli(argv, NULL, NULL);
	assert_true(code == 0 || code == 3); /* 3: the sides disagree, a finding */
	char *text = bsim_test_read(bsim_test_join(dir, "pairs.csv"));
	assert_non_null(text);
	*strchr(text, '\n') = '\0';
	char quoted[600];
	snprintf(quoted, sizeof quoted, "`%s`", text);
	if (!strstr(doc, quoted))
		fail_msg("docs/files.md does not give pairs.csv's header %s", text);
	for (char *c = strtok(text, ","); c; c = strtok(NULL, ",")) {
		if (!strcmp(c, "group") || !strcmp(c, "trial") || !strncmp(c, "t_separate", 10))
			continue;
		char *side = strrchr(c, '_');
		assert_non_null(side);
		*side = '\0';
		if (!bsim_trial_field_find(c))
			fail_msg("pairs.csv's column %s_%s is not one of trials.csv's", c,
			         side + 1);
	}
	free(text);
}

/* pairs.csv's columns (two sides and three) against docs/files.md and the
 * table of trials.csv's columns, whose descriptions its sides' take. */
static void test_docs_pairs_columns(void **state)
{
	(void)state;
	char *doc = bsim_test_read(bsim_test_src("docs/files.md"));
	assert_non_null(doc);
	pairs_columns(doc, "thesis,chipmunk", "pairs_two");
	pairs_columns(doc, "thesis,chipmunk,box2d", "pairs_three");
	free(doc);
}

/* The reader's column indices (store/trials_csv.h) against the library's
 * table (beamsim/trial_fields.h), which gives each index its name: an
 * index out of step with the table would read one column as another. */
static void test_trials_csv_indices(void **state)
{
	(void)state;
	static const struct {
		int k;
		const char *name;
	} idx[] = {{TRIALS_GROUP, "group"},
	           {TRIALS_TRIAL, "trial"},
	           {TRIALS_OUTCOME, "outcome"},
	           {TRIALS_TYPE, "type"},
	           {TRIALS_STEPS, "steps"},
	           {TRIALS_T_END, "t_end"},
	           {TRIALS_X_END, "x_end"},
	           {TRIALS_Y_END, "y_end"},
	           {TRIALS_VX_END, "vx_end"},
	           {TRIALS_MAX_THETA1, "max_theta1"},
	           {TRIALS_MAX_THETA2, "max_theta2"},
	           {TRIALS_E_START, "e_start"},
	           {TRIALS_E_END, "e_end"},
	           {TRIALS_WORK_IN, "work_in"},
	           {TRIALS_LOSSES, "losses"},
	           {TRIALS_RESIDUAL, "residual"},
	           {TRIALS_OVERLAP_MAX, "overlap_max"},
	           {TRIALS_FINAL_IX, "final_ix"},
	           {TRIALS_FINAL_IY, "final_iy"},
	           {TRIALS_LOCATION, "location"},
	           {TRIALS_PATH, "path"},
	           {TRIALS_ITERATION_LIMITS, "iteration_limits"},
	           {TRIALS_CLAMPS, "clamps"},
	           {TRIALS_T_EXIT, "t_exit"},
	           {TRIALS_HEADING_END, "heading_end"},
	           {TRIALS_ANGULAR_VELOCITY_END, "angular_velocity_end"},
	           {TRIALS_TURN_END, "turn_end"},
	           {TRIALS_TURN_MAX, "turn_max"}};
	int n;
	bsim_trial_fields(&n);
	assert_int_equal(n, TRIALS_N_COLUMNS);
	assert_int_equal(sizeof idx / sizeof idx[0], TRIALS_N_COLUMNS);
	for (size_t i = 0; i < sizeof idx / sizeof idx[0]; i++)
		assert_string_equal(bsim_trials_csv_column(idx[i].k), idx[i].name);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_trajectory_to_stdout),
	        cmocka_unit_test(test_trajectory_through_symlink),
	        cmocka_unit_test(test_trajectory_through_fifo_and_device),
	        cmocka_unit_test(test_stdout_errors),
	        cmocka_unit_test(test_unwritable_out),
	        cmocka_unit_test(test_lock),
	        cmocka_unit_test(test_refused_run_touches_nothing),
	        cmocka_unit_test(test_finished_result_needs_overwrite),
	        cmocka_unit_test(test_failed_rerun_keeps_previous_set),
	        cmocka_unit_test(test_replacing_a_set),
	        cmocka_unit_test(test_manifest_check),
	        cmocka_unit_test(test_figures_join_the_set),
	        cmocka_unit_test(test_docs_trials_columns),
	        cmocka_unit_test(test_docs_lattice_columns),
	        cmocka_unit_test(test_docs_pairs_columns),
	        cmocka_unit_test(test_trials_csv_indices),
	};
	return cmocka_run_group_tests(tests, setup, NULL);
}
