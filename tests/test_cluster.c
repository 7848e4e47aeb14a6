/* A sweep spread over processes (docs/cluster.md) through the real program.
 * The truth is the same sweep run by one process: trials are seeded from
 * (seed, group, trial), so however the trials are split the directory must
 * be that process's, byte for byte, but for the sweep's wall time
 * (summary.json's wall_seconds, the summary.mat that holds it, and the
 * manifest's sizes and CRCs of those two). Checked for three job-array
 * parts (sweep --shard I/3) joined by merge, for mpirun -np 3, and for an
 * MPI job one of whose ranks is killed (kill -9, once rank 0's journal holds
 * some records: an event, never a time), resumed by a job of 2 ranks. merge
 * refuses parts of another run, a missing or repeated part, a damaged part
 * journal, naming them, with exit status 2 and nothing written.
 *
 * The MPI tests (ctest's test_cluster_mpi) need the program built with MPI
 * (CMake found it): without it they are skipped, and ctest says so, unless
 * BSIM_REQUIRE_MPI is set (scripts/test.sh sets it, since scripts/deps.sh
 * installs OpenMPI), when they fail. */
#define _XOPEN_SOURCE 700

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <dirent.h>
#include <ftw.h>
#include <glob.h>
#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <fcntl.h>
#include <time.h>
#include <unistd.h>

#include "support.h"

extern char **environ;

static char experiment[1200];

/* 12 groups of TRIALS trials of at most 1500 steps, the four without random
 * force deterministic (run once, copied): a group count that 3 parts do not
 * divide, so parts hold unequal shares of some groups. */
static int setup(void **state)
{
	(void)state;
	char text[2400];
	snprintf(text, sizeof text,
	         "scene: %s\n"
	         "trials: 10\n"
	         "seed: 3\n"
	         "set:\n"
	         "  integration.max_steps: 1500\n"
	         "grid:\n"
	         "  effects.propulsion.force: [6, 7, 8, 9]\n"
	         "  effects.random_force.magnitude: [0, 10, 30]\n",
	         bsim_test_src("configs/thesis/gate.yaml"));
	snprintf(experiment, sizeof experiment, "%s",
	         bsim_test_write(bsim_test_dir("exp"), "small.yaml", text));
	/* mpirun refuses root without these (a CI container runs as root) */
	setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
	setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
	return 0;
}

/* ---- comparing two output directories ---------------------------------- */

static char *file_bytes(const char *path, long *n)
{
	FILE *f = fopen(path, "rb");
	if (!f)
		return NULL;
	fseek(f, 0, SEEK_END);
	*n = ftell(f);
	fseek(f, 0, SEEK_SET);
	char *b = malloc((size_t)*n + 1);
	if (b && fread(b, 1, (size_t)*n, f) != (size_t)*n) {
		free(b);
		b = NULL;
	}
	if (b)
		b[*n] = '\0';
	fclose(f);
	return b;
}

/* A JSON text with every value of "name" cut out. */
static void drop_key(char *text, const char *name)
{
	char key[64];
	snprintf(key, sizeof key, "\"%s\": ", name);
	for (char *w = strstr(text, key); w; w = strstr(w + 1, key)) {
		char *v = w + strlen(key);
		size_t n = strcspn(v, ",}\n");
		memmove(v, v + n, strlen(v + n) + 1);
	}
}

/* The wall time cut out of summary.json and report.json. */
static void drop_wall(char *text)
{
	drop_key(text, "wall_seconds");
}

/* The CPU times and what is computed from them cut out of validate.json
 * (the simulation's and one prediction's, as two runs of one process
 * differ). */
static void drop_cpu(char *text)
{
	static const char *const keys[] = {"sim_cpu_seconds", "predict_cpu_seconds", "speedup",
	                                   "break_even_lattices"};
	for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++)
		drop_key(text, keys[i]);
}

/* essay.md's "568 trials in 1.4 s." without the time. */
static void drop_essay_time(char *text)
{
	for (char *w = strstr(text, " trials in "); w; w = strstr(w + 1, " trials in ")) {
		char *v = w + strlen(" trials in "), *end = strstr(v, " s.");
		if (end)
			memmove(v, end, strlen(end) + 1);
	}
}

static const char *ref_root, *other_root;
static int n_compared, n_differ;

static int compare_one(const char *path, const struct stat *st, int type, struct FTW *ftw)
{
	(void)st;
	(void)ftw;
	if (type != FTW_F)
		return 0;
	const char *rel = path + strlen(ref_root) + 1;
	if (strncmp(rel, ".beamsim", 8) == 0)
		return 0;
	const char *name = strrchr(rel, '/') ? strrchr(rel, '/') + 1 : rel;
	/* the files that hold the wall time */
	if (strcmp(name, "manifest.json") == 0 || strcmp(name, "summary.mat") == 0 ||
	    strcmp(name, "report.mat") == 0 || strcmp(name, "validate_summary.mat") == 0)
		return 0;
	/* a Markov map's CPU time (map_HASH.cost) */
	if (strlen(name) > 5 && strcmp(name + strlen(name) - 5, ".cost") == 0)
		return 0;
	char other[2048];
	snprintf(other, sizeof other, "%s/%s", other_root, rel);
	long na = 0, nb = -1;
	char *a = file_bytes(path, &na), *b = file_bytes(other, &nb);
	void (*drop)(char *) = strcmp(name, "summary.json") == 0 || strcmp(name, "report.json") == 0
	                               ? drop_wall
	                       : strcmp(name, "validate.json") == 0 ? drop_cpu
	                       : strcmp(name, "essay.md") == 0      ? drop_essay_time
	                                                            : NULL;
	if (a && b && drop) {
		drop(a);
		drop(b);
		na = (long)strlen(a);
		nb = (long)strlen(b);
	}
	int same = a && b && na == nb && memcmp(a, b, (size_t)na) == 0;
	if (!same) {
		print_error("%s differs from %s\n", other, path);
		n_differ++;
	}
	n_compared++;
	free(a);
	free(b);
	return 0;
}

/* The number a shell command prints (a count of wc -l), -1 if none. */
static int command_count(const char *cmd)
{
	FILE *p = popen(cmd, "r");
	int n = -1;
	if (p) {
		if (fscanf(p, "%d", &n) != 1)
			n = -1;
		pclose(p);
	}
	return n;
}

static int count_files(const char *dir)
{
	char cmd[2200];
	snprintf(cmd, sizeof cmd, "find '%s' -type f -not -path '*/.beamsim/*' | wc -l", dir);
	return command_count(cmd);
}

/* Every file of ref is in dir with the same bytes (but the wall time),
 * and dir has no other file. */
static void assert_same_dir(const char *ref, const char *dir)
{
	ref_root = ref;
	other_root = dir;
	n_compared = n_differ = 0;
	assert_int_equal(nftw(ref, compare_one, 16, FTW_PHYS), 0);
	assert_true(n_compared >= 5); /* trials.csv, summary.json, run.json, inputs ... */
	assert_int_equal(n_differ, 0);
	assert_int_equal(count_files(dir), count_files(ref));
}

/* The one-process sweep of the experiment with trials per group. */
static const char *reference(const char *name, const char *trials)
{
	static char out[1024];
	snprintf(out, sizeof out, "%s", bsim_test_join(bsim_test_dir(name), "one"));
	const char *argv[] = {"sweep", experiment, "--trials", trials,    "--threads",
	                      "2",     "--out",    out,        "--quiet", NULL};
	assert_int_equal(bsim_test_cli(argv, NULL, NULL), 0);
	return out;
}

/* ---- job arrays: --shard I/N and merge --------------------------------- */

static void shard(const char *out, const char *part, const char *seed, const char *threads)
{
	const char *argv[] = {"sweep", experiment, "--trials", "6",         "--seed",
	                      seed,    "--shard",  part,       "--threads", threads,
	                      "--out", out,        "--quiet",  NULL};
	char *err = NULL;
	int rc = bsim_test_cli(argv, NULL, &err);
	if (rc != 0)
		print_error("%s", err ? err : "");
	free(err);
	assert_int_equal(rc, 0);
	assert_true(bsim_test_exists(bsim_test_join(out, "part.json")));
	assert_true(bsim_test_exists(bsim_test_join(out, "part.journal")));
	assert_false(bsim_test_exists(bsim_test_join(out, "trials.csv")));
}

static char parts[6][1024];

/* Parts 1..3 of the sweep (seed 3) with 1, 2, 1 threads, and part 2 of 3
 * of seed 4 and part 2 of 4 of seed 3. */
static void make_parts(const char *dir)
{
	const char *names[6] = {"p1", "p2", "p3", "other_seed", "of_four", "damaged"};
	for (int i = 0; i < 6; i++)
		snprintf(parts[i], sizeof parts[i], "%s/%s", dir, names[i]);
	shard(parts[0], "1/3", "3", "1");
	shard(parts[1], "2/3", "3", "2");
	shard(parts[2], "3/3", "3", "1");
	shard(parts[3], "2/3", "4", "1");
	shard(parts[4], "2/4", "3", "1");
	shard(parts[5], "3/3", "3", "2");
	/* a torn last record, as a copy cut short would leave */
	const char *journal = bsim_test_join(parts[5], "part.journal");
	assert_int_equal(truncate(journal, bsim_test_size(journal) - 7), 0);
}

static void test_shards_merged(void **state)
{
	(void)state;
	const char *one = reference("shards", "6");
	char dir[1024];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("shards_parts"));
	make_parts(dir);
	/* the parts given in any order */
	char out[1100];
	snprintf(out, sizeof out, "%s/merged", dir);
	const char *argv[] = {"merge", parts[2], parts[0], parts[1], "--out", out, "--quiet", NULL};
	assert_int_equal(bsim_test_cli(argv, NULL, NULL), 0);
	assert_same_dir(one, out);
}

/* A comparison of the sides backends in 3 parts, merged: the one-process
 * comparison's files and exit status (3 if a group disagrees: Box2D's
 * float32 may tip the symmetric gate's deterministic traversal to a side,
 * docs/compare.md), each part's 0. */
static void compare_shards_merged(const char *name, const char *backends)
{
	char dir[1024], one[1100], out[1100], part[3][1100];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir(name));
	snprintf(one, sizeof one, "%s/one", dir);
	const char *argv1[] = {"compare", experiment, "--trials", "4",          "--threads", "2",
	                       "--out",   one,        "--quiet",  "--backends", backends,    NULL};
	const int status = bsim_test_cli(argv1, NULL, NULL);
	assert_true(status == 0 || status == 3);
	for (int i = 0; i < 3; i++) {
		char shard_arg[16];
		snprintf(part[i], sizeof part[i], "%s/p%d", dir, i + 1);
		snprintf(shard_arg, sizeof shard_arg, "%d/3", i + 1);
		const char *argv[] = {"compare", experiment,   "--trials", "4",     "--threads",
		                      "1",       "--shard",    shard_arg,  "--out", part[i],
		                      "--quiet", "--backends", backends,   NULL};
		assert_int_equal(bsim_test_cli(argv, NULL, NULL), 0);
	}
	snprintf(out, sizeof out, "%s/merged", dir);
	const char *argv[] = {"merge", part[1], part[2], part[0], "--out", out, "--quiet", NULL};
	assert_int_equal(bsim_test_cli(argv, NULL, NULL), status);
	assert_same_dir(one, out);
}

/* thesis against box2d */
static void test_compare_shards_merged(void **state)
{
	(void)state;
	compare_shards_merged("compare_parts", "thesis,box2d");
}

/* three sides: each record every side's result and every pair's
 * separation time */
static void test_compare3_shards_merged(void **state)
{
	(void)state;
	compare_shards_merged("compare3_parts", "thesis,thesis:integrator=euler,box2d");
}

/* merge refuses: the status 2, one line naming the culprit, no DIR. */
static void refused(const char *a, const char *b, const char *c, const char *const needles[])
{
	char out[1100];
	snprintf(out, sizeof out, "%s/refused", bsim_test_dir("shards_refused"));
	const char *argv[] = {"merge", a, b, c, "--out", out, NULL};
	bsim_test_expect_input_error(argv, needles);
	assert_false(bsim_test_exists(bsim_test_join(out, "trials.csv")));
}

static void test_merge_refuses(void **state)
{
	(void)state;
	char dir[1024];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("refuse_parts"));
	make_parts(dir);
	refused(parts[0], parts[3], parts[2],
	        (const char *const[]){parts[3], "parts of different runs", NULL});
	refused(parts[0], parts[4], parts[2], (const char *const[]){parts[4], "2 of 4", NULL});
	refused(parts[0], parts[1], parts[1],
	        (const char *const[]){parts[1], "both part 2 of 3", NULL});
	refused(parts[0], parts[1], parts[5],
	        (const char *const[]){parts[5], "part.journal", "damaged", NULL});
	/* a part missing: two of three given */
	char out[1100];
	snprintf(out, sizeof out, "%s/refused", bsim_test_dir("shards_missing"));
	const char *argv[] = {"merge", parts[0], parts[2], "--out", out, NULL};
	bsim_test_expect_input_error(argv, (const char *const[]){"part 2 of 3 is missing", NULL});
	/* not a part's directory */
	const char *one = reference("not_a_part", "2");
	const char *argv2[] = {"merge", one, "--out", out, NULL};
	bsim_test_expect_input_error(argv2, (const char *const[]){one, "part.json", NULL});
	/* Regression: the first part's part.json edited (its run) was said to
	 * be of another run than its own ("p1 is part 1 of 3 of run R', not of
	 * run R (p1's)"). It is said against the run its command line gives
	 * the inputs, which the other parts share. */
	char *json = bsim_test_read(bsim_test_join(parts[0], "part.json"));
	assert_non_null(json);
	char *run = strstr(json, "\"run\": \"");
	assert_non_null(run);
	run += strlen("\"run\": \"");
	const char was = run[0];
	run[0] = was == '0' ? '1' : '0';
	bsim_test_write(parts[0], "part.json", json);
	char says[1100], self[1100];
	snprintf(says, sizeof says, "%s/part.json says part 1 of 3 of run ", parts[0]);
	snprintf(self, sizeof self, "(%s's)", parts[0]);
	const char *argv3[] = {"merge", parts[0], parts[1], parts[2], "--out", out, NULL};
	char *err = NULL;
	int rc = bsim_test_cli(argv3, NULL, &err);
	bsim_test_check_input_error(
	        rc, err, (const char *const[]){says, "but its command line gives run", NULL}, 1);
	assert_null(strstr(err, self));
	free(err);
	run[0] = was;
	bsim_test_write(parts[0], "part.json", json);
	free(json);
}

/* ---- markov build: its maps spread over parts --------------------------- */

static void run_ok(const char *const *argv);

static const char *markov_lattice(void)
{
	return bsim_test_src("configs/lattice/c_track_essay.yaml");
}

/* markov build of the lattice's maps (3 trials per bin) at two propulsion
 * forces (two groups of two stiffness pairs: four maps) into out, with
 * extra arguments a and b (NULL: none). */
#define MARKOV_GRID "effects.propulsion.force=6,7"

static void markov_build(const char *out, const char *threads, const char *a, const char *b)
{
	/* 4,4,3 bins, 3 start trials and 20 of the training field: cheap
	 * maps; each part runs the training field of its maps, the same */
	const char *argv[] = {"markov",    "build",     markov_lattice(),
	                      "--bins",    "4,4,3",     "--start-trials",
	                      "3",         "--trials",  "3",
	                      "--train",   "20",        "--grid",
	                      MARKOV_GRID, "--threads", threads,
	                      "--out",     out,         "--quiet",
	                      a,           b,           NULL};
	run_ok(argv);
}

/* How many maps dir holds (their .key files). */
static int count_maps(const char *dir)
{
	char cmd[4600];
	snprintf(cmd, sizeof cmd, "find '%s' -maxdepth 1 -name 'map_*.key' | wc -l", dir);
	return command_count(cmd);
}

/* The four maps in 3 parts, merged: the one-process map directory but for
 * the maps' CPU times. The parts take turns along both groups' maps: 2,
 * 1 and 1 (each group's pairs from part 1 would leave part 3 none). */
static void test_markov_shards_merged(void **state)
{
	(void)state;
	char dir[1024], one[1100], out[1100], part[4][1100];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("markov_parts"));
	snprintf(one, sizeof one, "%s/one", dir);
	markov_build(one, "2", NULL, NULL);
	assert_int_equal(count_maps(one), 4);
	for (int i = 0; i < 3; i++) {
		char shard_arg[16];
		snprintf(part[i], sizeof part[i], "%s/p%d", dir, i + 1);
		snprintf(shard_arg, sizeof shard_arg, "%d/3", i + 1);
		markov_build(part[i], i == 1 ? "2" : "1", "--shard", shard_arg);
		assert_true(bsim_test_exists(bsim_test_join(part[i], "part.json")));
		assert_int_equal(count_maps(part[i]), i == 0 ? 2 : 1);
	}
	/* a part of another build: another seed */
	snprintf(part[3], sizeof part[3], "%s/seed2", dir);
	const char *argv_seed[] = {"markov",    "build",    markov_lattice(),
	                           "--bins",    "4,4,3",    "--start-trials",
	                           "3",         "--trials", "3",
	                           "--train",   "20",       "--grid",
	                           MARKOV_GRID, "--seed",   "2",
	                           "--shard",   "2/3",      "--out",
	                           part[3],     "--quiet",  NULL};
	assert_int_equal(bsim_test_cli(argv_seed, NULL, NULL), 0);
	snprintf(out, sizeof out, "%s/merged", dir);
	const char *argv[] = {"merge", part[2], part[0], part[1], "--out", out, "--quiet", NULL};
	assert_int_equal(bsim_test_cli(argv, NULL, NULL), 0);
	assert_same_dir(one, out);
	/* refused: a part of another build, a part missing */
	char bad[1100];
	snprintf(bad, sizeof bad, "%s/refused", dir);
	const char *other[] = {"merge", part[0], part[3], part[2], "--out", bad, NULL};
	bsim_test_expect_input_error(
	        other, (const char *const[]){part[3], "parts of different runs", NULL});
	const char *missing[] = {"merge", part[0], part[2], "--out", bad, NULL};
	bsim_test_expect_input_error(missing,
	                             (const char *const[]){"part 2 of 3 is missing", NULL});
	assert_false(bsim_test_exists(bsim_test_join(bad, "markov.json")));
}

/* ---- markov build: maps built in passes -------------------------------- */

/* markov build of the four maps in passes (entries "self:1" or "flow:1":
 * pass 0, then pass 1 from its exits) at 2 x 2 x 2 entry bins of 3 trials
 * into out, with the extra arguments a, b, c and d (NULL: none). */
static void markov_passes_build4(const char *out, const char *entries, const char *threads,
                                 const char *a, const char *b, const char *c, const char *d)
{
	const char *argv[] = {"markov",   "build",     markov_lattice(),
	                      "--trials", "3",         "--bins",
	                      "2,2,2",    "--entries", entries,
	                      "--grid",   MARKOV_GRID, "--threads",
	                      threads,    "--out",     out,
	                      "--quiet",  a,           b,
	                      c,          d,           NULL};
	run_ok(argv);
}

static void markov_passes_build(const char *out, const char *entries, const char *threads,
                                const char *a, const char *b)
{
	markov_passes_build4(out, entries, threads, a, b, NULL, NULL);
}

/* How many files of dir end in suffix. */
static int count_suffix(const char *dir, const char *suffix)
{
	char cmd[4600];
	snprintf(cmd, sizeof cmd, "find '%s' -maxdepth 1 -name '*%s' | wc -l", dir, suffix);
	return command_count(cmd);
}

/* Self-consistent maps (self:1) in 3 parts, merged: the one-process map
 * directory, every pass's map and exits with it, but for the CPU times. A
 * part that lacks a pass's exits is refused, naming it. */
static void test_markov_self_shards_merged(void **state)
{
	(void)state;
	char dir[1024], one[1100], out[1100], part[3][1100];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("markov_self_parts"));
	snprintf(one, sizeof one, "%s/one", dir);
	markov_passes_build(one, "self:1", "2", NULL, NULL);
	/* four maps of two passes each: 8 maps, 8 exits */
	assert_int_equal(count_maps(one), 8);
	assert_int_equal(count_suffix(one, ".exits.csv"), 8);
	for (int i = 0; i < 3; i++) {
		char shard_arg[16];
		snprintf(part[i], sizeof part[i], "%s/p%d", dir, i + 1);
		snprintf(shard_arg, sizeof shard_arg, "%d/3", i + 1);
		markov_passes_build(part[i], "self:1", i == 1 ? "2" : "1", "--shard", shard_arg);
		assert_int_equal(count_maps(part[i]), i == 0 ? 4 : 2);
	}
	snprintf(out, sizeof out, "%s/merged", dir);
	const char *argv[] = {"merge", part[1], part[2], part[0], "--out", out, "--quiet", NULL};
	assert_int_equal(bsim_test_cli(argv, NULL, NULL), 0);
	assert_same_dir(one, out);
	/* a part without one of its passes' exits: refused, naming it */
	char cut[1100], bad[1100], cmd[4000];
	snprintf(cut, sizeof cut, "%s/cut", dir);
	snprintf(bad, sizeof bad, "%s/refused", dir);
	snprintf(cmd, sizeof cmd, "cp -r '%s' '%s' && rm \"$(ls '%s'/map_*.exits.csv | head -1)\"",
	         part[2], cut, cut);
	assert_int_equal(system(cmd), 0);
	const char *argv_cut[] = {"merge", part[0], part[1], cut, "--out", bad, NULL};
	bsim_test_expect_input_error(argv_cut, (const char *const[]){cut, NULL});
	assert_false(bsim_test_exists(bsim_test_join(bad, "markov.json")));
}

/* Flow-weighted maps (flow:1) as a job array, one round a pass: 3 parts
 * of pass 0 merged, then 3 parts of pass 1 reading that merge (--passes),
 * merged: the one-process map directory, every pass's map and exits, but
 * for the CPU times. A merge of parts of different rounds is refused, as
 * is --passes without a round. */
static void test_markov_flow_rounds_merged(void **state)
{
	(void)state;
	char dir[1024], one[1100], merged[2][1100], part[2][3][1100];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("markov_flow_rounds"));
	snprintf(one, sizeof one, "%s/one", dir);
	markov_passes_build(one, "flow:1", "2", NULL, NULL);
	assert_int_equal(count_suffix(one, ".exits.csv"), 8);
	for (int r = 0; r < 2; r++) {
		for (int i = 0; i < 3; i++) {
			char shard_arg[16];
			snprintf(part[r][i], sizeof part[r][i], "%s/r%d_p%d", dir, r, i + 1);
			snprintf(shard_arg, sizeof shard_arg, "%d/3", i + 1);
			/* pass 1 from the merge of pass 0 */
			markov_passes_build4(part[r][i], "flow:1", i == 1 ? "2" : "1", "--shard",
			                     shard_arg, r ? "--passes" : NULL,
			                     r ? merged[0] : NULL);
		}
		snprintf(merged[r], sizeof merged[r], "%s/merged%d", dir, r);
		const char *argv[] = {"merge", part[r][2], part[r][0], part[r][1],
		                      "--out", merged[r],  "--quiet",  NULL};
		assert_int_equal(bsim_test_cli(argv, NULL, NULL), 0);
		/* pass 0 of every map, no final map; then everything */
		assert_int_equal(count_suffix(merged[r], ".exits.csv"), r == 0 ? 4 : 8);
	}
	assert_same_dir(one, merged[1]);
	char bad[1100];
	snprintf(bad, sizeof bad, "%s/refused", dir);
	const char *mixed[] = {"merge", part[0][0], part[1][1], part[1][2], "--out", bad, NULL};
	bsim_test_expect_input_error(
	        mixed, (const char *const[]){part[1][1], "parts of different runs", NULL});
	assert_false(bsim_test_exists(bsim_test_join(bad, "markov.json")));
	const char *no_round[] = {"markov",   "build",   markov_lattice(), "--entries", "self:1",
	                          "--passes", merged[0], "--out",          bad,         NULL};
	char *err = NULL;
	int rc = bsim_test_cli(no_round, NULL, &err);
	bsim_test_check_input_error(rc, err, (const char *const[]){"--passes", "--shard", NULL}, 0);
	free(err);
	assert_false(bsim_test_exists(bad));
}

/* ---- MPI ----------------------------------------------------------------- */

/* ---- a lattice sweep: its records hold the gate paths -------------------- */

/* The C-track of the essay's lattice run (F 6 N) as a whole world, Rm 100
 * N, each gate held up to the whole duration: 12 trials, one of whose paths
 * enters more gates (38) than a journal record holds (32), so that trial
 * runs again where the files are written. argv filled, out and the
 * extra arguments a, b (NULL: none) its last. */
static void lattice_argv(const char **argv, char *exp, size_t size, const char *out,
                         const char *threads, const char *a, const char *b)
{
	snprintf(exp, size, "%s", bsim_test_src("configs/lattice/c_track_essay.yaml"));
	const char *v[] = {"sweep",     exp,
	                   "--trials",  "12",
	                   "--set",     "termination.gate_time=216",
	                   "--set",     "lattice.protocol=world",
	                   "--grid",    "effects.random_force.magnitude=100",
	                   "--threads", threads,
	                   "--out",     out,
	                   "--quiet",   a,
	                   b,           NULL};
	memcpy(argv, v, sizeof v);
}

/* The lattice sweep in 3 parts, merged: the one-process trials.csv,
 * gate_entries.csv, beam_peaks.csv, final_locations.csv,
 * transitions.csv, lattice_map.csv, summary.json (but its wall time) and
 * twins, the trials whose paths did not fit their records included. */
static void test_lattice_shards_merged(void **state)
{
	(void)state;
	char dir[1024], one[1100], out[1100], part[3][1100], exp[1200];
	const char *argv[20];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("lattice_parts"));
	snprintf(one, sizeof one, "%s/one", dir);
	lattice_argv(argv, exp, sizeof exp, one, "2", NULL, NULL);
	run_ok(argv);
	/* the case holds a path longer than a record's */
	char *entries = bsim_test_read(bsim_test_join(one, "gate_entries.csv"));
	assert_non_null(entries);
	int longest = 0;
	for (char *line = strchr(entries, '\n'); line && line[1]; line = strchr(line + 1, '\n')) {
		int g, t, seq;
		if (sscanf(line + 1, "%d,%d,%d", &g, &t, &seq) == 3 && seq + 1 > longest)
			longest = seq + 1;
	}
	free(entries);
	assert_true(longest > 32);
	for (int i = 0; i < 3; i++) {
		char shard_arg[16];
		snprintf(part[i], sizeof part[i], "%s/p%d", dir, i + 1);
		snprintf(shard_arg, sizeof shard_arg, "%d/3", i + 1);
		lattice_argv(argv, exp, sizeof exp, part[i], i == 1 ? "2" : "1", "--shard",
		             shard_arg);
		run_ok(argv);
	}
	snprintf(out, sizeof out, "%s/merged", dir);
	const char *m[] = {"merge", part[2], part[1], part[0], "--out", out, "--quiet", NULL};
	run_ok(m);
	assert_same_dir(one, out);
	assert_true(bsim_test_exists(bsim_test_join(out, "transitions.csv")));
}

/* ---- a lattice comparison: its records hold both sides' gate paths ------ */

static const char *group_prefix; /* below */

/* A 3 x 3 gate lattice (beams k 150 N/m, F 6 N, sides at |X| 150 m), 5
 * pairs a group of Rm 0 (deterministic) and 30 N: paths of up to 8 gates,
 * most trials traversed, some stuck. Written once; its path. */
static const char *lattice_compare_experiment(void)
{
	static char path[1200];
	if (!path[0]) {
		char name[64];
		snprintf(name, sizeof name, "%slattice_compare_exp", group_prefix);
		const char *dir = bsim_test_dir(name);
		bsim_test_write(
		        dir, "scene.yaml",
		        "name: lattice-3x3\n"
		        "body: { mass: 1.0, radius: 10.0, start: [0, 0], velocity: [0, 0] }\n"
		        "lattice:\n"
		        "  columns: 3\n"
		        "  rows: 3\n"
		        "  gate: { width: 50, depth: 60, pivot_y: 30 }\n"
		        "  beam: { length: 25, mass: 0.1, stiffness: 150, damping: 50 }\n"
		        "contact: { restitution: 0.8, tip_restitution: 1.0, "
		        "rest_threshold: 0.05 }\n"
		        "effects:\n"
		        "  propulsion: { force: 6.0 }\n"
		        "  random_force: { magnitude: 30.0, frequency: 50.0 }\n"
		        "integration: { dt: 0.004, duration: 40 }\n"
		        "termination: { success_y: 180, side_x: 150, gate_time: 12 }\n");
		snprintf(path, sizeof path, "%s",
		         bsim_test_write(dir, "exp.yaml",
		                         "scene: scene.yaml\n"
		                         "trials: 5\n"
		                         "seed: 5\n"
		                         "grid:\n"
		                         "  effects.random_force.magnitude: [0, 30]\n"));
	}
	return path;
}

/* compare of the lattice (sides NULL: thesis against box2d; "P,Q" of
 * protocols: --protocols sides; else --backends sides) into out, extra
 * arguments a, b (NULL: none) last: argv filled. */
static void lattice_compare_argv(const char **argv, const char *out, const char *threads,
                                 const char *sides, const char *a, const char *b)
{
	const char *opt = !sides ? NULL
	                  : strncmp(sides, "world", 5) == 0 || strncmp(sides, "essay", 5) == 0
	                          ? "--protocols"
	                          : "--backends";
	const char *v[] = {"compare",         lattice_compare_experiment(),
	                   "--threads",       threads,
	                   "--out",           out,
	                   "--quiet",         sides ? opt : a,
	                   sides ? sides : b, sides ? a : NULL,
	                   sides ? b : NULL,  NULL};
	memcpy(argv, v, sizeof v);
}

/* The status of the program run with argv (0, or 3 when a group
 * disagrees), its error printed when it is neither. */
static int run_status(const char *const *argv)
{
	char *err = NULL;
	int rc = bsim_test_cli(argv, NULL, &err);
	if (rc != 0 && rc != 3)
		print_error("%s: exit %d: %s", argv[0], rc, err ? err : "");
	free(err);
	return rc;
}

/* The lattice comparison in 3 parts, merged: the one-process directory
 * (report, pairs, each side's trials.csv, summary.json and lattice files),
 * of two backends, of two protocols (whose side b has scenes of its own)
 * and of three sides (records of three sides' gate paths and peaks). */
static void test_lattice_compare_shards_merged(void **state)
{
	(void)state;
	static const char *const protocols[] = {NULL, "world,essay",
	                                        "thesis,box2d,thesis:integrator=euler"};
	static const char *const names[] = {"lattice_compare", "lattice_compare_protocols",
	                                    "lattice_compare3"};
	static const char *const lattice_file[] = {"box2d/gate_entries.csv",
	                                           "world/transitions.csv",
	                                           "thesis-integrator=euler/gate_entries.csv"};
	for (int k = 0; k < 3; k++) {
		char dir[1024], one[1100], out[1100], part[3][1100];
		const char *argv[16];
		snprintf(dir, sizeof dir, "%s", bsim_test_dir(names[k]));
		snprintf(one, sizeof one, "%s/one", dir);
		lattice_compare_argv(argv, one, "2", protocols[k], NULL, NULL);
		int want = run_status(argv);
		assert_true(want == 0 || want == 3);
		assert_true(bsim_test_exists(bsim_test_join(one, lattice_file[k])));
		for (int i = 0; i < 3; i++) {
			char shard_arg[16];
			snprintf(part[i], sizeof part[i], "%s/p%d", dir, i + 1);
			snprintf(shard_arg, sizeof shard_arg, "%d/3", i + 1);
			lattice_compare_argv(argv, part[i], i == 1 ? "2" : "1", protocols[k],
			                     "--shard", shard_arg);
			run_ok(argv);
			assert_false(bsim_test_exists(bsim_test_join(part[i], "pairs.csv")));
		}
		snprintf(out, sizeof out, "%s/merged", dir);
		const char *m[] = {"merge", part[1], part[0],   part[2],
		                   "--out", out,     "--quiet", NULL};
		assert_int_equal(run_status(m), want);
		assert_same_dir(one, out);
	}
}

/* A lattice comparison of 60 pairs a group killed (SIGKILL once its
 * journal holds 5 records) and resumed: the one-process directory, its
 * lattice files written from the journal's and the resumed run's pairs. */
static void test_lattice_compare_killed_resumed(void **state)
{
	(void)state;
	char dir[1024], one[1100], out[1100], journal[1200];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("lattice_compare_killed"));
	snprintf(one, sizeof one, "%s/one", dir);
	snprintf(out, sizeof out, "%s/killed", dir);
	snprintf(journal, sizeof journal, "%s/.beamsim/journal", out);
	const char *argv1[] = {"compare",   lattice_compare_experiment(),
	                       "--trials",  "60",
	                       "--threads", "2",
	                       "--out",     one,
	                       "--quiet",   NULL};
	int want = run_status(argv1);
	assert_true(want == 0 || want == 3);
	const char *argv[] = {"compare",   lattice_compare_experiment(),
	                      "--trials",  "60",
	                      "--threads", "1",
	                      "--out",     out,
	                      "--quiet",   NULL,
	                      NULL};
	int pid = bsim_test_spawn(argv), status = 0;
	if (!bsim_test_await_records(pid, journal, 5, &status))
		fail_msg("the comparison ended (status %d) before its journal held 5 records",
		         status);
	kill(pid, SIGKILL);
	bsim_test_wait(pid);
	assert_true(bsim_test_journal_records(journal) >= 5);
	assert_false(bsim_test_exists(bsim_test_join(out, "pairs.csv")));
	argv[9] = "--resume";
	assert_int_equal(run_status(argv), want);
	assert_same_dir(one, out);
}

/* ---- markov validate and essay: several sweeps, one journal ------------- */

/* "mpi_" in test_cluster mpi: its directories apart from test_cluster's,
 * which ctest may run at the same time. */
static const char *group_prefix = "";

/* The maps of the C-track (configs/markov/c_track.yaml, 2 x 2 x 2 entry
 * bins of 5 trials: a chain quick to solve) that markov validate reads,
 * built once. */
static const char *validate_maps(void)
{
	static char maps[1024];
	if (!maps[0]) {
		char name[64];
		snprintf(name, sizeof name, "%svalidate_maps", group_prefix);
		snprintf(maps, sizeof maps, "%s", bsim_test_dir(name));
		char exp[1200];
		snprintf(exp, sizeof exp, "%s", bsim_test_src("configs/markov/c_track.yaml"));
		const char *argv[] = {"markov", "build",   exp,     "--trials",
		                      "5",      "--bins",  "2,2,2", "--start-trials",
		                      "5",      "--train", "20",    "--quiet",
		                      "--out",  maps,      NULL};
		assert_int_equal(bsim_test_cli(argv, NULL, NULL), 0);
	}
	return maps;
}

/* markov validate of the C-track (its essay protocol's and whole world's
 * sweeps of trials each) into out with extra arguments a, b, c (NULL:
 * none): argv filled, pointing into exp. */
static void validate_argv(const char **argv, char *exp, size_t size, const char *out,
                          const char *trials, const char *threads, const char *a, const char *b,
                          const char *c)
{
	snprintf(exp, size, "%s", bsim_test_src("configs/markov/c_track.yaml"));
	const char *v[] = {"markov",   "validate", exp,           "--map",   validate_maps(),
	                   "--trials", trials,     "--bootstrap", "20",      "--threads",
	                   threads,    "--out",    out,           "--quiet", a,
	                   b,          c,          NULL};
	memcpy(argv, v, sizeof v);
}

static void run_ok(const char *const *argv)
{
	char *err = NULL;
	int rc = bsim_test_cli(argv, NULL, &err);
	if (rc != 0)
		print_error("%s: exit %d: %s", argv[0], rc, err ? err : "");
	free(err);
	assert_int_equal(rc, 0);
}

/* dir/name/out: the reference and each spread run in a directory of the
 * same name (index.html titles the figures with it). */
static void named_out(char *buf, size_t size, const char *dir, const char *name)
{
	int n = snprintf(buf, size, "%s/%s/out", dir, name);
	assert_true(n > 0 && (size_t)n < size);
	buf[n - 4] = '\0';
	mkdir(buf, 0755);
	buf[n - 4] = '/';
}

/* The validation in 3 parts (1, 2, 1 threads), merged: the one-process
 * directory (validate.csv, gates.csv, time_validate.csv, the figures...)
 * but for the CPU times. */
static void test_validate_shards_merged(void **state)
{
	(void)state;
	char dir[1024], one[1100], out[1100], part[3][1100], exp[1200];
	const char *argv[20];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("validate_parts"));
	named_out(one, sizeof one, dir, "one");
	validate_argv(argv, exp, sizeof exp, one, "8", "2", NULL, NULL, NULL);
	run_ok(argv);
	for (int i = 0; i < 3; i++) {
		char shard_arg[16];
		snprintf(part[i], sizeof part[i], "%s/p%d", dir, i + 1);
		snprintf(shard_arg, sizeof shard_arg, "%d/3", i + 1);
		validate_argv(argv, exp, sizeof exp, part[i], "8", i == 1 ? "2" : "1", "--shard",
		              shard_arg, NULL);
		run_ok(argv);
		assert_true(bsim_test_exists(bsim_test_join(part[i], "part.journal")));
		assert_false(bsim_test_exists(bsim_test_join(part[i], "validate.csv")));
	}
	named_out(out, sizeof out, dir, "merged");
	const char *m[] = {"merge", part[2], part[0], part[1], "--out", out, "--quiet", NULL};
	run_ok(m);
	assert_same_dir(one, out);
	/* an essay's part is not a validation's */
	char other[1100];
	snprintf(other, sizeof other, "%s/refused", dir);
	const char *argv2[] = {"essay",    "--configs", bsim_test_src("configs"),
	                       "--trials", "1",         "--mode",
	                       "default",  "--shard",   "2/3",
	                       "--out",    other,       "--quiet",
	                       NULL};
	run_ok(argv2);
	const char *bad[] = {"merge", part[0], other, part[2], "--out", out, "--overwrite", NULL};
	bsim_test_expect_input_error(bad, (const char *const[]){other, "essay", NULL});
}

/* essay (one mode, the sensitivity study too: 51 sweeps) with extra
 * arguments a, b (NULL: none) into out. */
static void essay_argv(const char **argv, char *configs, size_t size, const char *out,
                       const char *trials, const char *threads, const char *a, const char *b)
{
	snprintf(configs, size, "%s", bsim_test_src("configs"));
	const char *v[] = {"essay",     "--configs",
	                   configs,     "--trials",
	                   trials,      "--lattice-trials",
	                   "2",         "--mode",
	                   "default",   "--sensitivity",
	                   "--threads", threads,
	                   "--out",     out,
	                   "--quiet",   a,
	                   b,           NULL};
	memcpy(argv, v, sizeof v);
}

/* The essay in 3 parts, merged: the one-process essay.csv, essay.md (but
 * its wall time), sensitivity.csv, their twins and the figure. */
static void test_essay_shards_merged(void **state)
{
	(void)state;
	char dir[1024], one[1100], out[1100], part[3][1100], configs[1100];
	const char *argv[20];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("essay_parts"));
	named_out(one, sizeof one, dir, "one");
	essay_argv(argv, configs, sizeof configs, one, "2", "2", NULL, NULL);
	run_ok(argv);
	for (int i = 0; i < 3; i++) {
		char shard_arg[16];
		snprintf(part[i], sizeof part[i], "%s/p%d", dir, i + 1);
		snprintf(shard_arg, sizeof shard_arg, "%d/3", i + 1);
		essay_argv(argv, configs, sizeof configs, part[i], "2", i == 1 ? "2" : "1",
		           "--shard", shard_arg);
		run_ok(argv);
	}
	named_out(out, sizeof out, dir, "merged");
	const char *m[] = {"merge", part[1], part[2], part[0], "--out", out, "--quiet", NULL};
	run_ok(m);
	assert_same_dir(one, out);
	assert_true(bsim_test_exists(bsim_test_join(out, "sensitivity.csv")));
}

/* A validation killed (SIGKILL) once its journal holds 5 of its 80
 * simulated trials, resumed: the uninterrupted run's files. */
static void test_validate_killed_resumed(void **state)
{
	(void)state;
	char dir[1024], one[1100], out[1100], exp[1200], journal[1200];
	const char *argv[20];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("validate_killed"));
	named_out(one, sizeof one, dir, "one");
	validate_argv(argv, exp, sizeof exp, one, "40", "2", NULL, NULL, NULL);
	run_ok(argv);
	named_out(out, sizeof out, dir, "killed");
	snprintf(journal, sizeof journal, "%s/.beamsim/journal", out);
	validate_argv(argv, exp, sizeof exp, out, "40", "1", NULL, NULL, NULL);
	int pid = bsim_test_spawn(argv), status = 0;
	if (!bsim_test_await_records(pid, journal, 5, &status))
		fail_msg("the validation ended (status %d) before its journal held 5 records",
		         status);
	kill(pid, SIGKILL);
	bsim_test_wait(pid);
	assert_true(bsim_test_journal_records(journal) >= 5);
	assert_false(bsim_test_exists(bsim_test_join(out, "validate.csv")));
	validate_argv(argv, exp, sizeof exp, out, "40", "2", "--resume", NULL, NULL);
	run_ok(argv);
	assert_same_dir(one, out);
}

/* Fails the test when the program has no MPI though it is required
 * (main skips the MPI tests otherwise). */
static int have_mpi(void)
{
	if (BSIM_TEST_MPIEXEC[0])
		return 1;
	fail_msg("beamsim was built without MPI, but BSIM_REQUIRE_MPI is set (scripts/"
	         "deps.sh installs libopenmpi-dev: CMake should have found it)");
	return 0;
}

/* Starts mpirun -np ranks beamsim cmd ... in the background, its stderr
 * into err_path; returns mpirun's pid. */
static pid_t spawn_mpirun(const char *const *argv, const char *err_path);
static pid_t spawn_ranks(const char *ranks, const char *const *args, const char *err_path);

static pid_t mpirun_command(const char *cmd, const char *ranks, const char *out, const char *trials,
                            int resume, const char *err_path)
{
	const char *argv[] = {BSIM_TEST_MPIEXEC,
	                      "--oversubscribe",
	                      "-np",
	                      ranks,
	                      BSIM_EXE,
	                      cmd,
	                      experiment,
	                      "--trials",
	                      trials,
	                      "--threads",
	                      "1",
	                      "--out",
	                      out,
	                      "--quiet",
	                      resume ? "--resume" : NULL,
	                      NULL};
	return spawn_mpirun(argv, err_path);
}

/* Starts beamsim with args (a NULL-terminated list, at most 32) under
 * mpirun --oversubscribe -np ranks, its stderr into err_path. */
static pid_t spawn_ranks(const char *ranks, const char *const *args, const char *err_path)
{
	const char *job[40] = {BSIM_TEST_MPIEXEC, "--oversubscribe", "-np", ranks, BSIM_EXE};
	int n = 0;
	while (args[n])
		n++;
	assert_true(n <= 32);
	memcpy(job + 5, args, (size_t)(n + 1) * sizeof *args);
	return spawn_mpirun(job, err_path);
}

/* Starts argv (mpirun ...) in the background, its stderr into err_path. */
static pid_t spawn_mpirun(const char *const *argv, const char *err_path)
{
	posix_spawn_file_actions_t fa;
	posix_spawn_file_actions_init(&fa);
	posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
	posix_spawn_file_actions_addopen(&fa, 2, err_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
	/* OpenMPI's components leak at MPI_Finalize and are unloaded, so that
	 * LeakSanitizer cannot even name them for a suppression: under ASan the
	 * ranks run without leak detection (the same library code is leak-checked
	 * by the shards and the one-process runs here). */
	int n = 0;
	while (environ[n])
		n++;
	char **env = calloc((size_t)n + 2, sizeof *env);
	assert_non_null(env);
	char asan[1024];
	const char *was = getenv("ASAN_OPTIONS");
	snprintf(asan, sizeof asan, "ASAN_OPTIONS=%s%sdetect_leaks=0", was ? was : "",
	         was && *was ? ":" : "");
	int k = 0;
	for (int i = 0; i < n; i++)
		if (strncmp(environ[i], "ASAN_OPTIONS=", 13) != 0)
			env[k++] = environ[i];
	env[k] = asan;
	pid_t pid = -1;
	int rc = posix_spawn(&pid, BSIM_TEST_MPIEXEC, &fa, NULL, (char *const *)argv, env);
	posix_spawn_file_actions_destroy(&fa);
	free(env);
	assert_int_equal(rc, 0);
	return pid;
}

static pid_t mpirun(const char *ranks, const char *out, const char *trials, int resume,
                    const char *err_path)
{
	return mpirun_command("sweep", ranks, out, trials, resume, err_path);
}

static void print_stderr(const char *path)
{
	char *text = bsim_test_read(path);
	print_error("%s", text ? text : "");
	free(text);
}

static int wait_status(pid_t pid)
{
	int st = 0;
	while (waitpid(pid, &st, 0) < 0)
		;
	return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
}

/* mpirun -np 2 beamsim compare: the one-process comparison. */
static void test_mpi_compare(void **state)
{
	(void)state;
	if (!have_mpi())
		return;
	char dir[1024], one[1100], out[1100], err_path[1200];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("mpi_compare"));
	snprintf(one, sizeof one, "%s/one", dir);
	snprintf(out, sizeof out, "%s/ranks2", dir);
	snprintf(err_path, sizeof err_path, "%s.err", out);
	const char *argv1[] = {"compare", experiment, "--trials", "6",       "--threads",
	                       "2",       "--out",    one,        "--quiet", NULL};
	const int status = bsim_test_cli(argv1, NULL, NULL); /* 3: a group disagrees */
	assert_true(status == 0 || status == 3);
	int rc = wait_status(mpirun_command("compare", "2", out, "6", 0, err_path));
	if (rc != status)
		print_stderr(err_path);
	assert_int_equal(rc, status);
	assert_same_dir(one, out);
}

/* markov build over 3 ranks (four maps: 2, 1 and 1 a rank): the
 * one-process map directory but for the maps' CPU times, and no
 * temporary directory left behind. */
static void test_mpi_markov_build(void **state)
{
	(void)state;
	if (!have_mpi())
		return;
	char dir[1024], one[1100], out[1100], err_path[1200], tmp[1100];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("mpi_markov"));
	snprintf(one, sizeof one, "%s/one", dir);
	snprintf(out, sizeof out, "%s/ranks3", dir);
	snprintf(tmp, sizeof tmp, "%s/tmp", dir);
	snprintf(err_path, sizeof err_path, "%s.err", out);
	assert_int_equal(mkdir(tmp, 0755), 0);
	markov_build(one, "2", NULL, NULL);
	const char *argv[] = {BSIM_TEST_MPIEXEC,
	                      "--oversubscribe",
	                      "-np",
	                      "3",
	                      BSIM_EXE,
	                      "markov",
	                      "build",
	                      markov_lattice(),
	                      "--bins",
	                      "4,4,3",
	                      "--start-trials",
	                      "3",
	                      "--trials",
	                      "3",
	                      "--train",
	                      "20",
	                      "--grid",
	                      MARKOV_GRID,
	                      "--threads",
	                      "1",
	                      "--out",
	                      out,
	                      "--quiet",
	                      NULL};
	setenv("TMPDIR", tmp, 1);
	int rc = wait_status(spawn_mpirun(argv, err_path));
	unsetenv("TMPDIR");
	if (rc != 0)
		print_stderr(err_path);
	assert_int_equal(rc, 0);
	assert_same_dir(one, out);
	assert_int_equal(count_files(tmp), 0);
	assert_int_equal(rmdir(tmp), 0); /* nor any directory */
	/* the ranks' parts, merged, are gone */
	assert_false(bsim_test_exists(bsim_test_join(out, ".beamsim")));
	/* the walks' training fields (markov build's default) run in one
	 * process: under mpirun refused, naming the maps, nothing written */
	char walks[1100];
	snprintf(walks, sizeof walks, "%s/walks", dir);
	const char *argv_walks[] = {
	        BSIM_TEST_MPIEXEC, "--oversubscribe", "-np", "2",     BSIM_EXE, "markov", "build",
	        markov_lattice(),  "--train",         "20",  "--out", walks,    NULL};
	rc = wait_status(spawn_mpirun(argv_walks, err_path));
	long n = 0;
	char *said = file_bytes(err_path, &n);
	assert_int_not_equal(rc, 0);
	assert_non_null(said);
	assert_non_null(strstr(said, "not under mpirun (2 ranks); --method maps spreads"));
	free(said);
	assert_false(bsim_test_exists(walks));
}

/* A wait for a file's text: the text at path once it holds needle. */
typedef struct text_wait {
	const char *path, *needle;
	char *text;
} text_wait;

static int text_ready(void *ctx)
{
	text_wait *tw = ctx;
	long n = 0;
	free(tw->text);
	tw->text = file_bytes(tw->path, &n);
	return tw->text && strstr(tw->text, tw->needle);
}

/* Waits until the file at path holds needle and returns the text then (a
 * later look may find the file rewritten); NULL with *status if the job
 * ends first (bsim_test_await). */
static char *await_text(pid_t job, const char *path, const char *needle, int *status)
{
	text_wait tw = {path, needle, NULL};
	char what[4200];
	snprintf(what, sizeof what, "%s in %s", needle, path);
	if (bsim_test_await((int)job, text_ready, &tw, what, status))
		return tw.text;
	free(tw.text);
	return NULL;
}

/* The bytes of file path (NULL if unreadable), for comparison. */
static pid_t await_rank(pid_t job, int rank);

static char *file_text(const char *path)
{
	long n = 0;
	return file_bytes(path, &n);
}

/* markov build of six maps over 2 ranks, rank 1 killed once it has
 * finished one of its three: the map stays in its part
 * (out/.beamsim/parts/2-of-2), and the same command reuses it (its .cost,
 * the CPU time of the run that built it, comes through to out unchanged),
 * giving the one-process directory. */
static void test_mpi_markov_killed_reused(void **state)
{
	(void)state;
	if (!have_mpi())
		return;
	char dir[1024], one[1100], out[1100], err_path[1200];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("mpi_markov_killed"));
	snprintf(one, sizeof one, "%s/one", dir);
	snprintf(out, sizeof out, "%s/killed", dir);
	snprintf(err_path, sizeof err_path, "%s.err", out);
	const char *one_argv[] = {"markov",
	                          "build",
	                          markov_lattice(),
	                          "--bins",
	                          "4,4,3",
	                          "--start-trials",
	                          "20",
	                          "--trials",
	                          "20",
	                          "--train",
	                          "20",
	                          "--grid",
	                          "effects.propulsion.force=6,7,8",
	                          "--threads",
	                          "2",
	                          "--out",
	                          one,
	                          "--quiet",
	                          NULL};
	run_ok(one_argv);
	const char *argv[] = {BSIM_TEST_MPIEXEC,
	                      "--oversubscribe",
	                      "-np",
	                      "2",
	                      BSIM_EXE,
	                      "markov",
	                      "build",
	                      markov_lattice(),
	                      "--bins",
	                      "4,4,3",
	                      "--start-trials",
	                      "20",
	                      "--trials",
	                      "20",
	                      "--train",
	                      "20",
	                      "--grid",
	                      "effects.propulsion.force=6,7,8",
	                      "--threads",
	                      "1",
	                      "--out",
	                      out,
	                      "--quiet",
	                      NULL};
	pid_t job = spawn_mpirun(argv, err_path);
	char manifest[1400];
	snprintf(manifest, sizeof manifest, "%s/.beamsim/parts/2-of-2/manifest.json", out);
	/* the event: a map committed in rank 1's part, its files listed in
	 * the part's manifest (written after them); those files stay as they
	 * are while the rank goes on (later maps join the set) */
	int status = 0;
	char *listed = await_text(job, manifest, ".cost\"", &status);
	if (!listed) {
		print_stderr(err_path);
		fail_msg("the job ended (status %d) before rank 1 finished a map", status);
	}
	/* the maps listed then, with their CPU times */
	size_t kept = 0;
	char *cost[8], *name[8];
	for (char *at = strstr(listed, "\"map_"); at && kept < 8; at = strstr(at + 1, "\"map_")) {
		char *end = strchr(at + 1, '"'), path[1400];
		if (!end || end - at < 6 || strncmp(end - 5, ".cost", 5) != 0)
			continue;
		name[kept] = strndup(at + 1, (size_t)(end - 5 - (at + 1)));
		snprintf(path, sizeof path, "%s/.beamsim/parts/2-of-2/%s.cost", out, name[kept]);
		cost[kept] = file_text(path);
		assert_non_null(cost[kept]);
		kept++;
	}
	free(listed);
	assert_true(kept >= 1);
	kill(await_rank(job, 1), SIGKILL);
	assert_int_not_equal(wait_status(job), 0);
	int rc = wait_status(spawn_mpirun(argv, err_path));
	if (rc != 0)
		print_stderr(err_path);
	assert_int_equal(rc, 0);
	assert_same_dir(one, out);
	for (size_t i = 0; i < kept; i++) {
		char path[1400];
		snprintf(path, sizeof path, "%s/%s.cost", out, name[i]);
		char *now = file_text(path);
		assert_non_null(now);
		assert_string_equal(now, cost[i]); /* reused, not built again */
		free(now);
		free(cost[i]);
		free(name[i]);
	}
	assert_false(bsim_test_exists(bsim_test_join(out, ".beamsim")));
}

/* markov build of maps in passes over 3 ranks: self:1 (each map's passes
 * on its rank) and flow:1 (the ranks meet after pass 0, each with every
 * map's single gates): the one-process map directory, every pass's map
 * and exits, but for the CPU times. */
static void test_mpi_markov_passes(void **state)
{
	(void)state;
	if (!have_mpi())
		return;
	static const char *const entries[] = {"self:1", "flow:1"};
	for (int k = 0; k < 2; k++) {
		char dir[1024], one[1100], out[1100], err_path[1200];
		snprintf(dir, sizeof dir, "%s",
		         bsim_test_dir(k ? "mpi_markov_flow" : "mpi_markov_self"));
		snprintf(one, sizeof one, "%s/one", dir);
		snprintf(out, sizeof out, "%s/ranks3", dir);
		snprintf(err_path, sizeof err_path, "%s.err", out);
		markov_passes_build(one, entries[k], "2", NULL, NULL);
		assert_int_equal(count_suffix(one, ".exits.csv"), 8);
		const char *argv[] = {BSIM_TEST_MPIEXEC,
		                      "--oversubscribe",
		                      "-np",
		                      "3",
		                      BSIM_EXE,
		                      "markov",
		                      "build",
		                      markov_lattice(),
		                      "--trials",
		                      "3",
		                      "--bins",
		                      "2,2,2",
		                      "--entries",
		                      entries[k],
		                      "--grid",
		                      MARKOV_GRID,
		                      "--threads",
		                      "1",
		                      "--out",
		                      out,
		                      "--quiet",
		                      NULL};
		int rc = wait_status(spawn_mpirun(argv, err_path));
		if (rc != 0)
			print_stderr(err_path);
		assert_int_equal(rc, 0);
		assert_same_dir(one, out);
	}
}

static void test_mpi_identical(void **state)
{
	(void)state;
	if (!have_mpi())
		return;
	const char *one = reference("mpi", "40");
	char out[1100], err_path[1200];
	snprintf(out, sizeof out, "%s/ranks3", bsim_test_dir("mpi_run"));
	snprintf(err_path, sizeof err_path, "%s.err", out);
	int rc = wait_status(mpirun("3", out, "40", 0, err_path));
	if (rc != 0)
		print_stderr(err_path);
	assert_int_equal(rc, 0);
	assert_same_dir(one, out);
}

/* The pid of the process of the given rank among mpirun's children: the
 * one whose environment says OMPI_COMM_WORLD_RANK=rank; -1 if none. */
static pid_t rank_pid(pid_t parent, int rank)
{
	char want[64];
	snprintf(want, sizeof want, "OMPI_COMM_WORLD_RANK=%d", rank);
	DIR *d = opendir("/proc");
	pid_t found = -1;
	struct dirent *e;
	while (d && found < 0 && (e = readdir(d))) {
		char path[300];
		long pid = strtol(e->d_name, NULL, 10), ppid = -1;
		if (pid <= 0)
			continue;
		snprintf(path, sizeof path, "/proc/%ld/stat", pid);
		FILE *f = fopen(path, "r");
		if (!f)
			continue;
		/* pid (comm) state ppid: comm may hold spaces, so from the last ')' */
		char line[1024];
		if (fgets(line, sizeof line, f) && strrchr(line, ')'))
			sscanf(strrchr(line, ')') + 1, " %*c %ld", &ppid);
		fclose(f);
		if (ppid != parent)
			continue;
		snprintf(path, sizeof path, "/proc/%ld/environ", pid);
		long n = 0;
		char *env = NULL;
		FILE *g = fopen(path, "rb");
		if (g) {
			env = malloc(1 << 20);
			n = env ? (long)fread(env, 1, (1 << 20) - 1, g) : 0;
			fclose(g);
		}
		for (long i = 0; env && i < n; i += (long)strlen(env + i) + 1)
			if (strcmp(env + i, want) == 0)
				found = (pid_t)pid;
		free(env);
	}
	if (d)
		closedir(d);
	return found;
}

/* A wait for an MPI rank's process: its pid once found. */
typedef struct rank_wait {
	pid_t job, pid;
	int rank;
} rank_wait;

static int rank_ready(void *ctx)
{
	rank_wait *rw = ctx;
	return (rw->pid = rank_pid(rw->job, rw->rank)) >= 0;
}

/* The pid of the job's rank once it is running (the event is the rank's
 * process appearing, bsim_test_await); the test fails if the job ends
 * first. */
static pid_t await_rank(pid_t job, int rank)
{
	rank_wait rw = {job, -1, rank};
	char what[64];
	snprintf(what, sizeof what, "rank %d of job %d", rank, (int)job);
	int status = 0;
	if (!bsim_test_await((int)job, rank_ready, &rw, what, &status))
		fail_msg("the job ended (status %d) before its rank %d was found", status, rank);
	return rw.pid;
}

static void test_mpi_rank_killed_resumed(void **state)
{
	(void)state;
	if (!have_mpi())
		return;
	const char *one = reference("mpi_kill", "120");
	char out[1100], err_path[1200], journal[1200];
	snprintf(out, sizeof out, "%s/killed", bsim_test_dir("mpi_killed"));
	snprintf(err_path, sizeof err_path, "%s.err", out);
	snprintf(journal, sizeof journal, "%s/.beamsim/journal", out);
	pid_t job = mpirun("3", out, "120", 0, err_path);
	/* rank 0 journals the others' records as they come: once it holds 20
	 * (of the 964 trials that run), rank 2 dies */
	int status = 0;
	if (!bsim_test_await_records(job, journal, 20, &status)) {
		print_stderr(err_path);
		fail_msg("the job ended (status %d) before its journal held 20 records", status);
	}
	pid_t victim = await_rank(job, 2);
	kill(victim, SIGKILL);
	int rc = wait_status(job);
	assert_int_not_equal(rc, 0);
	char *err = bsim_test_read(err_path);
	assert_non_null(strstr(err, "rank 2"));
	free(err);
	long kept = bsim_test_journal_records(journal);
	assert_true(kept >= 20);
	assert_false(bsim_test_exists(bsim_test_join(out, "trials.csv")));
	/* resumed by a job of 2 ranks */
	rc = wait_status(mpirun("2", out, "120", 1, err_path));
	if (rc != 0)
		print_stderr(err_path);
	assert_int_equal(rc, 0);
	assert_same_dir(one, out);
}

/* mpirun -np 3 beamsim sweep of the lattice: the one-process files. */
static void test_mpi_lattice(void **state)
{
	(void)state;
	if (!have_mpi())
		return;
	char dir[1024], one[1100], out[1100], err_path[1200], exp[1200];
	const char *argv[20];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("mpi_lattice"));
	snprintf(one, sizeof one, "%s/one", dir);
	snprintf(out, sizeof out, "%s/ranks3", dir);
	snprintf(err_path, sizeof err_path, "%s.err", out);
	lattice_argv(argv, exp, sizeof exp, one, "2", NULL, NULL);
	run_ok(argv);
	lattice_argv(argv, exp, sizeof exp, out, "1", NULL, NULL);
	int rc = wait_status(spawn_ranks("3", argv, err_path));
	if (rc != 0)
		print_stderr(err_path);
	assert_int_equal(rc, 0);
	assert_same_dir(one, out);
}

/* mpirun -np 3 beamsim compare of the lattice: the one-process
 * directory. */
static void test_mpi_lattice_compare(void **state)
{
	(void)state;
	if (!have_mpi())
		return;
	char dir[1024], one[1100], out[1100], err_path[1200];
	const char *argv[16];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("mpi_lattice_compare"));
	snprintf(one, sizeof one, "%s/one", dir);
	snprintf(out, sizeof out, "%s/ranks3", dir);
	snprintf(err_path, sizeof err_path, "%s.err", out);
	lattice_compare_argv(argv, one, "2", NULL, NULL, NULL);
	int want = run_status(argv);
	assert_true(want == 0 || want == 3);
	lattice_compare_argv(argv, out, "1", NULL, NULL, NULL);
	int rc = wait_status(spawn_ranks("3", argv, err_path));
	if (rc != want)
		print_stderr(err_path);
	assert_int_equal(rc, want);
	assert_same_dir(one, out);
}

/* mpirun -np 3 beamsim markov validate and essay: the one-process
 * directories. */
static void test_mpi_validate_essay(void **state)
{
	(void)state;
	if (!have_mpi())
		return;
	char dir[1024], one[1100], out[1100], err_path[1200], exp[1200], configs[1100];
	const char *argv[20];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("mpi_validate"));
	for (int k = 0; k < 2; k++) {
		const char *name = k ? "essay" : "validate";
		char sub[1100];
		snprintf(sub, sizeof sub, "%s/%s", dir, name);
		mkdir(sub, 0755);
		named_out(one, sizeof one, sub, "one");
		named_out(out, sizeof out, sub, "ranks3");
		snprintf(err_path, sizeof err_path, "%s/%s.err", dir, name);
		if (k)
			essay_argv(argv, configs, sizeof configs, one, "2", "2", NULL, NULL);
		else
			validate_argv(argv, exp, sizeof exp, one, "8", "2", NULL, NULL, NULL);
		run_ok(argv);
		if (k)
			essay_argv(argv, configs, sizeof configs, out, "2", "1", NULL, NULL);
		else
			validate_argv(argv, exp, sizeof exp, out, "8", "1", NULL, NULL, NULL);
		int rc = wait_status(spawn_ranks("3", argv, err_path));
		if (rc != 0)
			print_stderr(err_path);
		assert_int_equal(rc, 0);
		assert_same_dir(one, out);
	}
}

/* An essay job of 3 ranks (one mode, 8 trials a group: 344 trials run, the
 * 6 groups without random force once) whose rank 2 is killed once rank 0's
 * journal holds 20 records, resumed by 2 ranks: the one-process essay. */
static void test_mpi_essay_killed_resumed(void **state)
{
	(void)state;
	if (!have_mpi())
		return;
	char dir[1024], one[1100], out[1100], err_path[1200], journal[1200], configs[1100];
	const char *argv[20];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("mpi_essay_killed"));
	named_out(one, sizeof one, dir, "one");
	essay_argv(argv, configs, sizeof configs, one, "8", "2", NULL, NULL);
	argv[9] = "--quiet"; /* no sensitivity study */
	run_ok(argv);
	named_out(out, sizeof out, dir, "killed");
	snprintf(err_path, sizeof err_path, "%s/killed.err", dir);
	snprintf(journal, sizeof journal, "%s/.beamsim/journal", out);
	essay_argv(argv, configs, sizeof configs, out, "8", "1", NULL, NULL);
	argv[9] = "--quiet";
	pid_t pid = spawn_ranks("3", argv, err_path);
	int status = 0;
	if (!bsim_test_await_records(pid, journal, 20, &status)) {
		print_stderr(err_path);
		fail_msg("the job ended (status %d) before its journal held 20 records", status);
	}
	pid_t victim = await_rank(pid, 2);
	kill(victim, SIGKILL);
	assert_int_not_equal(wait_status(pid), 0);
	assert_true(bsim_test_journal_records(journal) >= 20);
	assert_false(bsim_test_exists(bsim_test_join(out, "essay.csv")));
	/* resumed by a job of 2 ranks */
	int n = 0;
	while (argv[n])
		n++;
	argv[n] = "--resume";
	argv[n + 1] = NULL;
	int rc = wait_status(spawn_ranks("2", argv, err_path));
	if (rc != 0)
		print_stderr(err_path);
	assert_int_equal(rc, 0);
	assert_same_dir(one, out);
}

/* test_cluster: the job arrays; test_cluster mpi: the MPI job, which ctest
 * reports as skipped (status 77) when the program has no MPI. */
int main(int argc, char **argv)
{
	const struct CMUnitTest shards[] = {
	        cmocka_unit_test(test_shards_merged),
	        cmocka_unit_test(test_compare_shards_merged),
	        cmocka_unit_test(test_compare3_shards_merged),
	        cmocka_unit_test(test_merge_refuses),
	        cmocka_unit_test(test_markov_shards_merged),
	        cmocka_unit_test(test_markov_self_shards_merged),
	        cmocka_unit_test(test_markov_flow_rounds_merged),
	        cmocka_unit_test(test_lattice_shards_merged),
	        cmocka_unit_test(test_lattice_compare_shards_merged),
	        cmocka_unit_test(test_lattice_compare_killed_resumed),
	        cmocka_unit_test(test_validate_shards_merged),
	        cmocka_unit_test(test_essay_shards_merged),
	        cmocka_unit_test(test_validate_killed_resumed),
	};
	const struct CMUnitTest mpi[] = {
	        cmocka_unit_test(test_mpi_identical),
	        cmocka_unit_test(test_mpi_compare),
	        cmocka_unit_test(test_mpi_markov_build),
	        cmocka_unit_test(test_mpi_markov_killed_reused),
	        cmocka_unit_test(test_mpi_markov_passes),
	        cmocka_unit_test(test_mpi_rank_killed_resumed),
	        cmocka_unit_test(test_mpi_lattice),
	        cmocka_unit_test(test_mpi_lattice_compare),
	        cmocka_unit_test(test_mpi_validate_essay),
	        cmocka_unit_test(test_mpi_essay_killed_resumed),
	};
	if (argc < 2 || strcmp(argv[1], "mpi") != 0)
		return cmocka_run_group_tests(shards, setup, NULL);
	if (!BSIM_TEST_MPIEXEC[0] && !(getenv("BSIM_REQUIRE_MPI") && *getenv("BSIM_REQUIRE_MPI"))) {
		printf("skipped: beamsim is built without MPI (CMake did not find it)\n");
		return 77;
	}
	group_prefix = "mpi_";
	return cmocka_run_group_tests(mpi, setup, NULL);
}
