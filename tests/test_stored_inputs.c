/* Stored directories read back (regress, plot, markov predict) and the
 * files a scene names are verified before use, each damage refused with
 * exit 2 and one line naming the file, the line and the field:
 *   - with a manifest, a file whose size or CRC-32 differs from the listed
 *     one (a map's CSV put in another's place) is refused, and so is a
 *     FIFO or a device in a listed file's place, without blocking; a map
 *     file with a byte flipped or cut short names itself and the rebuild,
 *     and a map file the manifest does not list is refused;
 *   - without one, the content itself: a map CSV cut mid-row, header only,
 *     a count past the trials, counts summing past them, a NaN p; a
 *     trials.csv cut mid-row (plot too) or holding only its header;
 *   - a FIFO as run.json, as a lattice's stiffness_file or as the journal
 *     --resume reads, a directory as stiffness_file, a symbolic link to
 *     /dev/zero as trials.csv.
 * Each damage is made on a real small output of the program. A FIFO must
 * be refused at once: the harness's time limit only keeps a regression
 * from hanging the suite; the assertion is the exit status and message. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "support.h"

/* The guard on a command that must not block (s). */
#define GUARD 30.0

static void expect_refused(const char *const argv[], const char *const needles[])
{
	const bsim_test_opts o = {.timeout = GUARD};
	char *out = NULL, *err = NULL;
	int rc = bsim_test_cli_with(argv, &o, &out, &err);
	bsim_test_check_input_error(rc, err, needles, 1);
	free(out);
	free(err);
}

/* A map directory of `markov build` (1 + 4 entry bins, 2 trials each),
 * made again for each damage; with_manifest 0 removes its manifest. */
static void map_build(const char *dir, int with_manifest)
{
	const char *essay = bsim_test_src("configs/lattice/c_track_essay.yaml");
	char exp[1200];
	snprintf(exp, sizeof exp, "%s", essay);
	/* the start's trials as the others': every bin's counts sum to 2 */
	const char *build[] = {
	        "markov", "build",   exp, "--bins",  "1,1,1", "--trials", "2", "--start-trials",
	        "2",      "--train", "0", "--quiet", "--out", dir,        NULL};
	assert_int_equal(bsim_test_remove(dir), 0);
	assert_int_equal(bsim_test_cli(build, NULL, NULL), 0);
	if (!with_manifest)
		assert_int_equal(bsim_test_remove(bsim_test_join(dir, "manifest.json")), 0);
}

/* The first map's CSV of dir (beside its key: not a gate after the
 * start's): its path into path, its text returned. */
static char *map_csv(const char *dir, char *path, size_t size)
{
	const char *key = bsim_test_glob_first(bsim_test_join(dir, "map_*.key"));
	assert_non_null(key);
	snprintf(path, size, "%.*s.csv", (int)(strlen(key) - 4), key);
	char *text = bsim_test_read(path);
	assert_non_null(text);
	return text;
}

static void write_file(const char *path, const char *text)
{
	FILE *f = fopen(path, "w");
	assert_non_null(f);
	fputs(text, f);
	assert_int_equal(fclose(f), 0);
}

static void predict_refused(const char *dir, const char *const needles[])
{
	char track[1200];
	snprintf(track, sizeof track, "%s", bsim_test_src("configs/lattice/c_track.yaml"));
	const char *pred[] = {"markov", "predict", track, "--map", dir, NULL};
	expect_refused(pred, needles);
}

/* The line of text (1-based) whose count field is 1: "a,x,1,...". */
static int row_of_count_one(const char *text)
{
	int line = 1;
	for (const char *p = text; *p; p++) {
		if (*p != '\n')
			continue;
		line++;
		const char *c = strchr(p + 1, ',');
		c = c ? strchr(c + 1, ',') : NULL;
		if (c && strncmp(c, ",1,", 3) == 0)
			return line;
	}
	return 0;
}

/* text with line n (1-based) replaced by its first two fields, then rest. */
static void replace_row(const char *text, int n, const char *rest, char *out, size_t size)
{
	const char *start = text;
	for (int i = 1; i < n; i++)
		start = strchr(start, '\n') + 1;
	const char *end = strchr(start, '\n');
	const char *c2 = strchr(strchr(start, ',') + 1, ',');
	snprintf(out, size, "%.*s%.*s,%s%s", (int)(start - text), text, (int)(c2 - start), start,
	         rest, end);
}

static void test_map_with_manifest(void **state)
{
	(void)state;
	char dir[1024], path[1200], other[1200];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("map_manifest"));
	map_build(dir, 1);
	char *csv = map_csv(dir, path, sizeof path);
	/* another map's CSV in this one's place */
	char *text = bsim_test_read_glob(bsim_test_join(dir, "map_*.csv"));
	assert_non_null(text);
	/* the glob's text is both maps one after the other: the second starts
	 * at the second header */
	char *second = strstr(text + 1, "entry,exit,count");
	assert_non_null(second);
	assert_true(strcmp(second, csv) != 0);
	write_file(path, second);
	const char *name = strrchr(path, '/') + 1;
	const char *swapped[] = {name, "manifest.json", "CRC-32", NULL};
	predict_refused(dir, swapped);
	free(text);

	/* a FIFO in the place of a listed file: refused at once */
	map_build(dir, 1);
	snprintf(other, sizeof other, "%s", path);
	assert_int_equal(unlink(other), 0);
	assert_int_equal(mkfifo(other, 0600), 0);
	const char *fifo[] = {name, "manifest.json", "got a FIFO", NULL};
	predict_refused(dir, fifo);
	free(csv);
}

/* One byte of a map flipped, or the map cut short: predict exits 2 naming
 * the file and the rebuild; the same build untouched predicts as a fresh
 * one does (the other path: --json of a build never damaged). A map file
 * the manifest does not list is refused too. */
static void test_map_byte_flipped(void **state)
{
	(void)state;
	char dir[1024], fresh[1024], path[1200], track[1200];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("map_flipped"));
	snprintf(fresh, sizeof fresh, "%s", bsim_test_dir("map_fresh"));
	snprintf(track, sizeof track, "%s", bsim_test_src("configs/lattice/c_track.yaml"));
	map_build(fresh, 1);
	const char *pred_fresh[] = {"markov", "predict", track, "--map", fresh, "--json", NULL};
	char *want = NULL;
	assert_int_equal(bsim_test_cli(pred_fresh, &want, NULL), 0);

	map_build(dir, 1);
	char *csv = map_csv(dir, path, sizeof path);
	const char *name = strrchr(path, '/') + 1;
	size_t len = strlen(csv);
	char *flipped = strdup(csv);
	assert_non_null(flipped);
	flipped[len - 2] ^= 1; /* a digit of the last row's p: still a number */
	write_file(path, flipped);
	const char *flip[] = {name, "manifest.json", "CRC-32",
	                      "rebuild the maps with beamsim markov build", NULL};
	predict_refused(dir, flip);

	flipped[len / 2] = '\0'; /* cut short */
	write_file(path, flipped);
	const char *cut[] = {name, "manifest.json", "bytes", "rebuild the maps", NULL};
	predict_refused(dir, cut);

	/* restored: predicts as the fresh build */
	write_file(path, csv);
	const char *pred[] = {"markov", "predict", track, "--map", dir, "--json", NULL};
	char *got = NULL;
	assert_int_equal(bsim_test_cli(pred, &got, NULL), 0);
	/* the same maps (same key, seed): the same probabilities; the timing
	 * field differs between runs and is cut off */
	char *t1 = strstr(want, "\"predict_seconds\""), *t2 = strstr(got, "\"predict_seconds\"");
	if (t1 && t2)
		*t1 = *t2 = '\0';
	assert_string_equal(got, want);

	/* a map file the manifest does not list */
	char manifest[1200];
	snprintf(manifest, sizeof manifest, "%s/manifest.json", dir);
	char *m = bsim_test_read(manifest);
	assert_non_null(m);
	char *entry = strstr(m, name);
	assert_non_null(entry);
	char *line = entry;
	while (line > m && line[-1] != '\n')
		line--;
	char *eol = strchr(entry, '\n');
	assert_non_null(eol);
	memmove(line, eol + 1, strlen(eol + 1) + 1);
	write_file(manifest, m);
	const char *unlisted[] = {name, "not listed in", "manifest.json", NULL};
	predict_refused(dir, unlisted);
	free(m);
	free(got);
	free(want);
	free(flipped);
	free(csv);
}

static void test_map_content(void **state)
{
	(void)state;
	char dir[1024], path[1200], text[8192];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("map_content"));

	/* cut mid-row: the second line without its end */
	map_build(dir, 0);
	char *csv = map_csv(dir, path, sizeof path);
	const char *name = strrchr(path, '/') + 1;
	size_t header = (size_t)(strchr(csv, '\n') - csv) + 1;
	snprintf(text, sizeof text, "%.*s", (int)header + 5, csv);
	write_file(path, text);
	const char *cut[] = {name, ":2: expected a whole line ending in a line feed", NULL};
	predict_refused(dir, cut);

	/* header only: entry bin 0's counts sum to 0, not 2 */
	snprintf(text, sizeof text, "%.*s", (int)header, csv);
	write_file(path, text);
	const char *empty[] = {name,
	                       ":1: count: expected the counts of entry bin 0 to sum to the map's "
	                       "2 trials, got 0",
	                       NULL};
	predict_refused(dir, empty);

	/* a count past the trials */
	int one = row_of_count_one(csv);
	assert_true(one >= 2);
	replace_row(csv, one, "3,a,b,1.5", text, sizeof text);
	write_file(path, text);
	char where[64];
	snprintf(where, sizeof where, ":%d: count: expected a count of trials 1 to 2, got 3", one);
	const char *over[] = {name, where, NULL};
	predict_refused(dir, over);

	/* counts that sum past the trials, each row consistent in itself */
	char *row = strchr(csv, '\n') + 1;
	for (int i = 2; i < one; i++)
		row = strchr(row, '\n') + 1;
	char rest[256];
	const char *edges = strchr(strchr(strchr(row, ',') + 1, ',') + 1, ',') + 1;
	/* entry_edge,exit_edge of the row, then p = 2 / 2 */
	const char *e2 = strchr(strchr(edges, ',') + 1, ',');
	snprintf(rest, sizeof rest, "2,%.*s,1", (int)(e2 - edges), edges);
	replace_row(csv, one, rest, text, sizeof text);
	write_file(path, text);
	const char *sum[] = {name, ": count: expected the counts of entry bin", "trials, got 3",
	                     NULL};
	predict_refused(dir, sum);

	/* a NaN p */
	snprintf(rest, sizeof rest, "1,%.*s,nan", (int)(e2 - edges), edges);
	replace_row(csv, one, rest, text, sizeof text);
	write_file(path, text);
	snprintf(where, sizeof where, ":%d: p: expected a probability in [0, 1]", one);
	const char *nan[] = {name, where, "got nan", NULL};
	predict_refused(dir, nan);

	/* a link to /dev/zero in its place, without a manifest to tell */
	assert_int_equal(unlink(path), 0);
	assert_int_equal(symlink("/dev/zero", path), 0);
	const char *zero[] = {name, "expected a map file, got a character device", NULL};
	predict_refused(dir, zero);
	free(csv);
}

static char experiment[1200];

/* A sweep of 2 groups x 3 trials into dir, without its manifest unless
 * with_manifest. */
static void sweep(const char *dir, int with_manifest)
{
	const char *argv[] = {"sweep", experiment, "--quiet", "--out", dir, NULL};
	/* afresh: a FIFO left by the last damage would be written through */
	assert_int_equal(bsim_test_remove(dir), 0);
	assert_int_equal(bsim_test_cli(argv, NULL, NULL), 0);
	if (!with_manifest)
		assert_int_equal(bsim_test_remove(bsim_test_join(dir, "manifest.json")), 0);
}

static void regress_refused(const char *dir, const char *const needles[])
{
	char base[1200];
	snprintf(base, sizeof base, "%s", dir);
	const char *argv[] = {"regress", base, "--quiet", "--out", bsim_test_dir("rerun"), NULL};
	expect_refused(argv, needles);
}

static void plot_refused(const char *dir, const char *const needles[])
{
	char base[1200];
	snprintf(base, sizeof base, "%s", dir);
	const char *argv[] = {"plot", base, "--out", bsim_test_dir("plots"), NULL};
	expect_refused(argv, needles);
}

static void test_sweep_files(void **state)
{
	(void)state;
	char dir[1024], path[1200];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("stored_sweep"));
	snprintf(path, sizeof path, "%s/trials.csv", dir);
	for (int m = 0; m < 2; m++) {
		/* trials.csv cut to 500 bytes: mid-row */
		sweep(dir, m);
		char *csv = bsim_test_read(path);
		assert_non_null(csv);
		assert_true(strlen(csv) > 600);
		assert_true(csv[499] != '\n');
		csv[500] = '\0';
		write_file(path, csv);
		const char *listed[] = {"trials.csv", "manifest.json", "got 500 bytes", NULL};
		int line = 1;
		for (int i = 0; i < 500; i++)
			line += csv[i] == '\n';
		char where[80];
		snprintf(where, sizeof where, "trials.csv:%d: expected a whole line", line);
		const char *cut[] = {where, "cut short", NULL};
		regress_refused(dir, m ? listed : cut);
		plot_refused(dir, m ? listed : cut);

		/* header only */
		*strchr(csv, '\n') = '\0';
		strcat(csv, "\n");
		write_file(path, csv);
		const char *rows[] = {"trials.csv:1: expected 6 rows", "got 0", NULL};
		const char *listed2[] = {"trials.csv", "manifest.json", "CRC-32", NULL};
		regress_refused(dir, m ? listed2 : rows);
		plot_refused(dir, m ? listed2 : rows);
		free(csv);

		/* a link to /dev/zero */
		assert_int_equal(unlink(path), 0);
		assert_int_equal(symlink("/dev/zero", path), 0);
		const char *zero[] = {"trials.csv", "got a character device", NULL};
		regress_refused(dir, zero);

		/* a FIFO as run.json */
		sweep(dir, m);
		char run[1200];
		snprintf(run, sizeof run, "%s/run.json", dir);
		assert_int_equal(unlink(run), 0);
		assert_int_equal(mkfifo(run, 0600), 0);
		const char *fifo[] = {"run.json", "got a FIFO", NULL};
		regress_refused(dir, fifo);
	}
}

/* A FIFO in the place of a stopped run's journal: --resume refuses it at
 * once (the journal is opened for reading and writing, so the open would
 * not block, the first read would). */
static void test_journal_fifo(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("journal_fifo");
	char work[1200], journal[1300], out[1200];
	snprintf(out, sizeof out, "%s", dir);
	snprintf(work, sizeof work, "%s/.beamsim", dir);
	snprintf(journal, sizeof journal, "%s/journal", work);
	assert_int_equal(mkdir(work, 0700), 0);
	assert_int_equal(mkfifo(journal, 0600), 0);
	const char *argv[] = {"sweep", experiment, "--quiet", "--out", out, "--resume", NULL};
	const char *fifo[] = {"journal: expected the journal of a stopped run, got a FIFO", NULL};
	expect_refused(argv, fifo);
}

/* The lattice's stiffness_file: a FIFO or a directory refused at open,
 * naming the scene's line and column of the field. */
static void test_stiffness_file(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("stiffness_fifo");
	char scene[1200], csv[1200];
	snprintf(scene, sizeof scene, "%s",
	         bsim_test_write(dir, "scene.yaml",
	                         "body: { mass: 1, radius: 10 }\n"
	                         "lattice:\n  columns: 3\n  rows: 3\n"
	                         "  beam: { length: 25, mass: 0.1, stiffness: 400, damping: 50 }\n"
	                         "  stiffness_file: map.csv\n"));
	snprintf(csv, sizeof csv, "%s/map.csv", dir);
	const char *argv[] = {"run", scene, NULL};
	assert_int_equal(mkfifo(csv, 0600), 0);
	const char *fifo[] = {"scene.yaml:6:19: lattice.stiffness_file",
	                      "expected a regular CSV file", "(a FIFO)", NULL};
	expect_refused(argv, fifo);
	assert_int_equal(unlink(csv), 0);
	assert_int_equal(mkdir(csv, 0700), 0);
	const char *is_dir[] = {"scene.yaml:6:19: lattice.stiffness_file",
	                        "expected a regular CSV file", "(a directory)", NULL};
	expect_refused(argv, is_dir);
}

static int setup(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("stored_exp");
	char text[2000];
	snprintf(text, sizeof text,
	         "scene: %s\ntrials: 3\nseed: 5\ngrid:\n  effects.propulsion.force: [8, 9]\n",
	         bsim_test_src("configs/thesis/gate.yaml"));
	snprintf(experiment, sizeof experiment, "%s", bsim_test_write(dir, "small.yaml", text));
	return 0;
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_map_with_manifest), cmocka_unit_test(test_map_byte_flipped),
	        cmocka_unit_test(test_map_content),       cmocka_unit_test(test_sweep_files),
	        cmocka_unit_test(test_stiffness_file),    cmocka_unit_test(test_journal_fifo),
	};
	return cmocka_run_group_tests(tests, setup, NULL);
}
