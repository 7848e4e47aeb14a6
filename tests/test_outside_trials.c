/* beamsim compare with a side read, not run (--backends A,trials:PATH):
 * trials made elsewhere, written as beamsim's trials.csv, against a backend
 * of beamsim's. The "elsewhere" here is a sweep of H1 by the thesis backend,
 * so the truths are independent of the comparison: the file against the
 * thesis backend is the same trials, every pair concordant and identical
 * in every field; with the outcomes of one group flipped by the test, that
 * group and no other disagrees, by exactly the pairs flipped; against a
 * third side (box2d) the read side's pairs are thesis's pairs. Files that
 * do not fit the experiment are refused (exit 2) naming file, line and
 * field, with nothing written; the record names the file and the FNV-1a
 * 64 hash of its bytes (computed here from the formula), and regress
 * reads the same file again or refuses one that changed. */
#define _POSIX_C_SOURCE 200809L

#include <limits.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "support.h"
#include "util/yaml_doc.h"

enum { TRIALS = 20, GROUPS = 30 };

static char experiment[1200];
static char made[1200];     /* the sweep standing for results made elsewhere */
static char made_csv[1300]; /* its trials.csv */
static char same_dir[1200]; /* the comparison of test_same_trials */
static char trials_arg[16];

static int setup(void **state)
{
	(void)state;
	snprintf(experiment, sizeof experiment, "%s",
	         bsim_test_src("configs/thesis/h1_symmetric.yaml"));
	snprintf(trials_arg, sizeof trials_arg, "%d", TRIALS);
	snprintf(made, sizeof made, "%s", bsim_test_dir_held("made"));
	snprintf(made_csv, sizeof made_csv, "%s/trials.csv", made);
	const char *argv[] = {"sweep",  experiment,  "--trials", trials_arg, "--backend",
	                      "thesis", "--threads", "2",        "--quiet",  "--overwrite",
	                      "--out",  made,        NULL};
	return bsim_test_cli(argv, NULL, NULL) == 0 ? 0 : -1;
}

/* beamsim compare EXPERIMENT --trials TRIALS --backends sides --out out
 * [more...]: its exit status, stderr into *err (may be NULL). */
static int compare(const char *sides, const char *out, const char *const *more, char **err)
{
	const char *argv[24] = {"compare",    experiment,    "--trials",  trials_arg,
	                        "--backends", sides,         "--threads", "2",
	                        "--quiet",    "--overwrite", "--out",     out};
	int n = 12;
	for (int i = 0; more && more[i]; i++)
		argv[n++] = more[i];
	argv[n] = NULL;
	return bsim_test_cli(argv, NULL, err);
}

/* ---- a trials.csv as lines --------------------------------------------- */

typedef struct lines {
	char *text;
	char *line[GROUPS * TRIALS + 8];
	int n; /* the header is line[0], file line 1 */
} lines;

static void lines_read_n(const char *path, lines *l, int rows)
{
	l->text = bsim_test_read(path);
	assert_non_null(l->text);
	l->n = 0;
	char *save = NULL;
	for (char *s = strtok_r(l->text, "\n", &save); s; s = strtok_r(NULL, "\n", &save)) {
		assert_true(l->n < (int)(sizeof l->line / sizeof l->line[0]));
		l->line[l->n++] = s;
	}
	assert_int_equal(l->n, 1 + rows);
}

static void lines_read(const char *path, lines *l)
{
	lines_read_n(path, l, GROUPS * TRIALS);
}

/* Field k (0-based) of a CSV line of beamsim's (no quoting in the
 * columns read here) into buf. */
static const char *field(const char *line, int k, char *buf, size_t size)
{
	for (int i = 0; i < k; i++) {
		line = strchr(line, ',');
		assert_non_null(line);
		line++;
	}
	size_t len = strcspn(line, ",");
	snprintf(buf, size, "%.*s", (int)(len < size ? len : size - 1), line);
	return buf;
}

/* The column named name in the header. */
static int column(const lines *l, const char *name)
{
	char buf[64];
	for (int k = 0;; k++) /* field fails the test past the last column */
		if (strcmp(field(l->line[0], k, buf, sizeof buf), name) == 0)
			return k;
}

/* The lines joined into dir/trials.csv, line skip (file line skip + 1)
 * left out (-1: none), extra appended (NULL: none), line at replaced by
 * with (at < 0: none). Returns dir. */
static const char *write_variant(const char *name, const lines *l, int skip, int at,
                                 const char *with, const char *extra)
{
	const char *dir = bsim_test_dir_held(name);
	size_t size = 4096 + (with ? strlen(with) : 0) + (extra ? strlen(extra) : 0);
	for (int i = 0; i < l->n; i++)
		size += strlen(l->line[i]) + 1;
	char *text = malloc(size);
	assert_non_null(text);
	size_t len = 0;
	for (int i = 0; i < l->n; i++)
		if (i != skip)
			len += (size_t)snprintf(text + len, size - len, "%s\n",
			                        i == at ? with : l->line[i]);
	if (extra)
		snprintf(text + len, size - len, "%s\n", extra);
	bsim_test_write(dir, "trials.csv", text);
	free(text);
	return dir;
}

/* The file line (1-based) of the row of group g, trial t. */
static int row_of(const lines *l, int g, int t)
{
	char want[32], buf[32];
	snprintf(want, sizeof want, "%d,%d,", g, t);
	for (int i = 1; i < l->n; i++) {
		snprintf(buf, sizeof buf, "%s", l->line[i]);
		if (strncmp(buf, want, strlen(want)) == 0)
			return i + 1;
	}
	fail_msg("no row of group %d, trial %d", g, t);
	return -1;
}

/* The lines without the columns named a and b (b may be NULL) into
 * dir/trials.csv. Returns dir. */
static const char *write_without(const char *name, const lines *l, const char *a, const char *b)
{
	int ka = column(l, a), kb = b ? column(l, b) : -1;
	lines cut = *l;
	size_t size = 1;
	for (int i = 0; i < l->n; i++)
		size += strlen(l->line[i]) + 1;
	char *text = malloc(size), *w = text;
	assert_non_null(text);
	for (int i = 0; i < l->n; i++) {
		cut.line[i] = w;
		const char *r = l->line[i];
		for (int k = 0; r; k++) {
			const char *comma = strchr(r, ',');
			size_t len = comma ? (size_t)(comma - r) : strlen(r);
			if (k != ka && k != kb)
				w += sprintf(w, "%s%.*s", w > cut.line[i] ? "," : "", (int)len, r);
			r = comma ? comma + 1 : NULL;
		}
		*w++ = '\0';
	}
	const char *dir = write_variant(name, &cut, -1, -1, NULL, NULL);
	free(text);
	return dir;
}

/* 64-bit FNV-1a of a file's bytes: h = (h ^ byte) * 0x100000001b3 from
 * 0xcbf29ce484222325. */
static void fnv1a64_text(const char *path, char out[17])
{
	FILE *f = fopen(path, "rb");
	assert_non_null(f);
	uint64_t h = 0xcbf29ce484222325ULL;
	for (int c; (c = fgetc(f)) != EOF;)
		h = (h ^ (uint64_t)(unsigned char)c) * 0x100000001b3ULL;
	fclose(f);
	snprintf(out, 17, "%016llx", (unsigned long long)h);
}

/* ---- report.json ---------------------------------------------------------- */

static struct fy_node *json_open(const char *dir, const char *name, ydoc *d)
{
	char path[1400];
	bsim_error err;
	snprintf(path, sizeof path, "%s/%s", dir, name);
	if (bsim_ydoc_load_own(d, path, &err) != BSIM_OK)
		fail_msg("%s: %s", path, err.msg);
	return fy_document_root(d->fyd);
}

static int disagrees(const char *verdict)
{
	return strcmp(verdict, "DISAGREE") == 0 || strcmp(verdict, "DIFFERENT") == 0;
}

/* ---- the tests --------------------------------------------------------- */

/* The file against the backend that made it: the same trials. */
static void test_same_trials(void **state)
{
	(void)state;
	snprintf(same_dir, sizeof same_dir, "%s", bsim_test_dir_held("same"));
	char sides[1400];
	snprintf(sides, sizeof sides, "thesis,trials:%s", made);
	assert_int_equal(compare(sides, same_dir, NULL, NULL), 0);
	ydoc d;
	struct fy_node *root = json_open(same_dir, "report.json", &d);
	char p[120], buf[1400];
	assert_int_equal((int)bsim_test_json_at(root, "groups_disagreeing"), 0);
	assert_string_equal(bsim_test_json_text_at(root, "b.label", buf, sizeof buf), "made");
	assert_string_equal(bsim_test_json_text_at(root, "b.read_from", buf, sizeof buf) +
	                            strlen(buf) - strlen("/made/trials.csv"),
	                    "/made/trials.csv");
	lines l;
	lines_read(made_csv, &l);
	int mag = column(&l, "effects.random_force.magnitude");
	for (int g = 0; g < GROUPS; g++) {
		snprintf(p, sizeof p, "groups.%d.discordant", g);
		assert_int_equal((int)bsim_test_json_at(root, p), 0);
		/* identical in every field both files hold */
		snprintf(p, sizeof p, "groups.%d.changed", g);
		assert_int_equal((int)bsim_test_json_at(root, p), 0);
		/* a group without random force is one pair, the same */
		char m[32];
		field(l.line[row_of(&l, g, 0) - 1], mag, m, sizeof m);
		snprintf(p, sizeof p, "groups.%d.verdict", g);
		bsim_test_json_text_at(root, p, buf, sizeof buf);
		if (strcmp(m, "0") == 0)
			assert_string_equal(buf, "same");
		assert_false(disagrees(buf));
	}
	bsim_ydoc_free(&d);
	free(l.text);
	/* pairs.csv: every pair's outcome and type the same */
	char path[1400];
	snprintf(path, sizeof path, "%s/pairs.csv", same_dir);
	lines pl;
	lines_read(path, &pl);
	int oa = column(&pl, "outcome_a"), ob = column(&pl, "outcome_b");
	int ta = column(&pl, "type_a"), tb = column(&pl, "type_b");
	for (int i = 1; i < pl.n; i++) {
		char x[32], y[32];
		assert_string_equal(field(pl.line[i], oa, x, sizeof x),
		                    field(pl.line[i], ob, y, sizeof y));
		assert_string_equal(field(pl.line[i], ta, x, sizeof x),
		                    field(pl.line[i], tb, y, sizeof y));
	}
	free(pl.text);
	/* the side's directory: the file as read, and what trials give */
	snprintf(path, sizeof path, "%s/made/trials.csv", same_dir);
	char *copy = bsim_test_read(path), *orig = bsim_test_read(made_csv);
	assert_non_null(copy);
	assert_string_equal(copy, orig);
	free(copy);
	free(orig);
	const char *files[] = {"made/trials.csv",
	                       "made/summary.json",
	                       "made/survival.csv",
	                       "thesis/trials.csv",
	                       "run.json",
	                       "report.md",
	                       NULL};
	bsim_test_check_committed(same_dir, files, NULL);
	/* run.json: the side read, its file and the hash of its bytes */
	root = json_open(same_dir, "run.json", &d);
	char hash[17];
	fnv1a64_text(made_csv, hash);
	assert_string_equal(
	        bsim_test_json_text_at(root, "backends.1.read_fnv1a64", buf, sizeof buf), hash);
	assert_string_equal(bsim_test_json_text_at(root, "backends.1.label", buf, sizeof buf),
	                    "made");
	bsim_test_json_text_at(root, "backends.1.read_from", buf, sizeof buf);
	assert_non_null(strstr(buf, "/made/trials.csv"));
	assert_int_equal(buf[0], '/');
	assert_null(bsim_ydoc_lookup(root, "backends.0.read_from"));
	bsim_ydoc_free(&d);
	/* report.md says which side was read */
	snprintf(path, sizeof path, "%s/report.md", same_dir);
	char *md = bsim_test_read(path);
	assert_non_null(md);
	char said[200];
	snprintf(said, sizeof said, "(FNV-1a 64 %s), made elsewhere: not run by beamsim", hash);
	assert_non_null(strstr(md, said));
	free(md);
}

/* The outcomes of one group with random force flipped (traversed <->
 * stuck, a traversal's type left): that group disagrees, by the pairs
 * flipped, and no other group does. The group is the one with the most
 * trials stuck, which become traversals over the left beam: one event of
 * the family, all its discordant pairs one way. */
static void test_one_group_flipped(void **state)
{
	(void)state;
	lines l;
	lines_read(made_csv, &l);
	int mag = column(&l, "effects.random_force.magnitude");
	/* the group with random force with the most stuck trials */
	int best = -1, most = -1;
	for (int g = 0; g < GROUPS; g++) {
		char m[32], o[32];
		field(l.line[row_of(&l, g, 0) - 1], mag, m, sizeof m);
		if (strcmp(m, "0") == 0)
			continue;
		int k = 0;
		for (int t = 0; t < TRIALS; t++) {
			field(l.line[row_of(&l, g, t) - 1], 2, o, sizeof o);
			k += strcmp(o, "stuck") == 0;
		}
		if (k > most) {
			most = k;
			best = g;
		}
	}
	/* enough to disagree: k pairs one way, 2^(1 - k) far below 0.05 / 100 */
	assert_true(most >= 15);
	int flips = 0;
	char *owned[TRIALS] = {NULL};
	for (int t = 0; t < TRIALS; t++) {
		char *line = l.line[row_of(&l, best, t) - 1], o[32];
		field(line, 2, o, sizeof o);
		const char *to = strcmp(o, "traversed") == 0 ? "stuck,none"
		                 : strcmp(o, "stuck") == 0   ? "traversed,left"
		                                             : NULL;
		if (!to)
			continue;
		flips++;
		/* group,trial,outcome,type,rest */
		char *rest = strchr(strchr(strchr(strchr(line, ',') + 1, ',') + 1, ',') + 1, ',');
		char *flipped = malloc(strlen(line) + 32);
		assert_non_null(flipped);
		sprintf(flipped, "%d,%d,%s%s", best, t, to, rest);
		l.line[row_of(&l, best, t) - 1] = owned[t] = flipped;
	}
	const char *dir = write_variant("flipped", &l, -1, -1, NULL, NULL);
	char sides[1400];
	snprintf(sides, sizeof sides, "thesis,trials:%s", dir);
	const char *out = bsim_test_dir_held("flipped_cmp");
	assert_int_equal(compare(sides, out, NULL, NULL), 3);
	ydoc d;
	struct fy_node *root = json_open(out, "report.json", &d);
	char p[120], buf[64];
	assert_int_equal((int)bsim_test_json_at(root, "groups_disagreeing"), 1);
	for (int g = 0; g < GROUPS; g++) {
		snprintf(p, sizeof p, "groups.%d.verdict", g);
		bsim_test_json_text_at(root, p, buf, sizeof buf);
		snprintf(p, sizeof p, "groups.%d.discordant", g);
		if (g == best) {
			assert_string_equal(buf, "DISAGREE");
			assert_int_equal((int)bsim_test_json_at(root, p), flips);
		} else {
			assert_false(disagrees(buf));
			assert_int_equal((int)bsim_test_json_at(root, p), 0);
		}
	}
	bsim_ydoc_free(&d);
	for (int t = 0; t < TRIALS; t++)
		free(owned[t]);
	free(l.text);
}

/* A refused comparison: exit 2, one line naming each of needles (usage:
 * the line, then one saying where help is), no output directory. */
static void refused_as(const char *sides, const char *const *more, const char *const needles[],
                       int usage)
{
	const char *out = bsim_test_join(bsim_test_dir_held("refused"), "out");
	char *err = NULL;
	int rc = compare(sides, out, more, &err);
	bsim_test_check_input_error(rc, err, needles, !usage);
	if (usage)
		assert_non_null(strstr(err, "\nTry 'beamsim compare --help'.\n"));
	free(err);
	assert_false(bsim_test_exists(out));
}

static void refused(const char *sides, const char *const *more, const char *const needles[])
{
	refused_as(sides, more, needles, 0);
}

static void test_refusals(void **state)
{
	(void)state;
	lines l;
	lines_read(made_csv, &l);
	char sides[1400], where[1400], at[64];
	const char *dir;

	/* a column the comparison uses is missing: type, cut from every line */
	{
		dir = write_without("no_type", &l, "type", NULL);
		snprintf(sides, sizeof sides, "thesis,trials:%s", dir);
		snprintf(where, sizeof where, "%s/trials.csv:1: column type: expected", dir);
		const char *needles[] = {where, NULL};
		refused(sides, NULL, needles);
	}
	/* a (group, trial) missing: group 7, trial 11 */
	dir = write_variant("missing", &l, row_of(&l, 7, 11) - 1, -1, NULL, NULL);
	snprintf(sides, sizeof sides, "thesis,trials:%s", dir);
	snprintf(where, sizeof where, "%s/trials.csv:%d:", dir, l.n - 1);
	{
		const char *needles[] = {where, "group 7, trial 11: none", NULL};
		refused(sides, NULL, needles);
	}
	/* one repeated: group 3, trial 2 again at the end */
	dir = write_variant("repeated", &l, -1, -1, NULL, l.line[row_of(&l, 3, 2) - 1]);
	snprintf(sides, sizeof sides, "thesis,trials:%s", dir);
	snprintf(where, sizeof where, "%s/trials.csv:%d: group 3, trial 2: expected once", dir,
	         l.n + 1);
	snprintf(at, sizeof at, "already on line %d", row_of(&l, 3, 2));
	{
		const char *needles[] = {where, at, NULL};
		refused(sides, NULL, needles);
	}
	/* an outcome that is no word of beamsim's */
	{
		int line = row_of(&l, 12, 5);
		char *row = l.line[line - 1], with[2000], o[32];
		field(row, 2, o, sizeof o);
		const char *rest = strchr(strchr(strchr(row, ',') + 1, ',') + 1, ',');
		snprintf(with, sizeof with, "12,5,jammed%s", rest);
		dir = write_variant("jammed", &l, -1, line - 1, with, NULL);
		snprintf(sides, sizeof sides, "thesis,trials:%s", dir);
		snprintf(where, sizeof where,
		         "%s/trials.csv:%d: outcome: expected one of traversed, side_exit, stuck, "
		         "unstable, got 'jammed'",
		         dir, line);
		const char *needles[] = {where, NULL};
		refused(sides, NULL, needles);
	}
	/* a type for an outcome other than a traversal */
	{
		int line = 0;
		for (int i = 1; i < l.n && !line; i++)
			line = strstr(l.line[i], ",stuck,none,") ? i + 1 : 0;
		char *row = l.line[line - 1], with[2000];
		const char *none = strstr(row, ",stuck,none,");
		snprintf(with, sizeof with, "%.*s,stuck,left,%s", (int)(none - row), row,
		         none + strlen(",stuck,none,"));
		dir = write_variant("stuck_left", &l, -1, line - 1, with, NULL);
		snprintf(sides, sizeof sides, "thesis,trials:%s", dir);
		snprintf(where, sizeof where,
		         "%s/trials.csv:%d: type: expected none for outcome stuck", dir, line);
		const char *needles[] = {where, "got 'left'", NULL};
		refused(sides, NULL, needles);
	}
	/* a group without random force (magnitude 0: group 0) whose trial 4
	 * is not its trial 0 */
	{
		int line = row_of(&l, 0, 4);
		char *row = l.line[line - 1], with[2000], o[32];
		field(row, 2, o, sizeof o);
		assert_string_equal(o, "stuck"); /* H1's group 0, 4 N without noise */
		const char *rest = strchr(strchr(strchr(row, ',') + 1, ',') + 1, ',');
		snprintf(with, sizeof with, "0,4,side_exit%s", rest);
		dir = write_variant("copy_differs", &l, -1, line - 1, with, NULL);
		snprintf(sides, sizeof sides, "thesis,trials:%s", dir);
		snprintf(
		        where, sizeof where,
		        "%s/trials.csv:%d: outcome: expected stuck as trial 0 of group 0 (line %d)",
		        dir, line, row_of(&l, 0, 0));
		const char *needles[] = {where, "got 'side_exit'", NULL};
		refused(sides, NULL, needles);
	}
	/* a file of another experiment's group count: H1 with two forces has
	 * 2 x 5 groups, the file 30 */
	{
		const char *grid[] = {"--grid", "effects.propulsion.force=4,5", NULL};
		snprintf(sides, sizeof sides, "thesis,trials:%s", made);
		snprintf(where, sizeof where,
		         "%s:%d: group: expected an integer 0 to 9 (the experiment's 10 groups), "
		         "got '10'",
		         made_csv, row_of(&l, 10, 0));
		const char *needles[] = {where, NULL};
		refused(sides, grid, needles);
	}
	/* trials a group: the file's 20 against 21 */
	{
		const char *more[] = {"--trials", "21", NULL};
		snprintf(sides, sizeof sides, "thesis,trials:%s", made);
		snprintf(where, sizeof where, "%s:%d: expected %d rows", made_csv, l.n,
		         GROUPS * 21);
		const char *needles[] = {where, "group 0, trial 20: none", NULL};
		refused(sides, more, needles);
	}
	free(l.text);
}

/* Three sides, the read one between two that run: its pairs are those of
 * the thesis backend, whose trials it holds. */
static void test_three_sides(void **state)
{
	(void)state;
	char sides[1400];
	snprintf(sides, sizeof sides, "thesis,trials:%s,box2d", made);
	const char *out = bsim_test_dir_held("three");
	int rc = compare(sides, out, NULL, NULL);
	assert_true(rc == 0 || rc == 3);
	ydoc d;
	struct fy_node *root = json_open(out, "report.json", &d);
	char p[160], a[64], b[64];
	assert_string_equal(bsim_test_json_text_at(root, "sides.1.label", a, sizeof a), "made");
	assert_non_null(bsim_ydoc_lookup(root, "sides.1.read_from"));
	assert_null(bsim_ydoc_lookup(root, "sides.2.read_from"));
	static const char *const ev[] = {"traversed", "left", "right", "side_exit", "stuck"};
	static const char *const cell[] = {"both", "only_a", "only_b", "neither"};
	for (int g = 0; g < GROUPS; g++) {
		/* pairs (thesis, made), (thesis, box2d), (made, box2d) */
		snprintf(p, sizeof p, "groups.%d.pairwise.0.discordant", g);
		assert_int_equal((int)bsim_test_json_at(root, p), 0);
		for (int e = 0; e < 5; e++)
			for (int c = 0; c < 4; c++) {
				snprintf(p, sizeof p, "groups.%d.pairwise.1.events.%s.%s", g, ev[e],
				         cell[c]);
				double n1 = bsim_test_json_at(root, p);
				snprintf(p, sizeof p, "groups.%d.pairwise.2.events.%s.%s", g, ev[e],
				         cell[c]);
				assert_true(n1 == bsim_test_json_at(root, p));
			}
		/* a disagreement is never the read side's alone */
		snprintf(p, sizeof p, "groups.%d.odd_one_out.found", g);
		if (strcmp(bsim_test_json_text_at(root, p, a, sizeof a), "side") == 0) {
			snprintf(p, sizeof p, "groups.%d.odd_one_out.side", g);
			assert_string_equal(bsim_test_json_text_at(root, p, b, sizeof b), "box2d");
		}
	}
	assert_int_equal(rc, (int)bsim_test_json_at(root, "groups_disagreeing") > 0 ? 3 : 0);
	bsim_ydoc_free(&d);
}

/* The comparison of a backend's own sweep read from its file is the
 * comparison that runs that backend: box2d's sweep as the side read
 * against thesis gives compare thesis,box2d's verdicts, discordant pairs,
 * event tables and p-values in every group (its half is its own sweep,
 * test_compare_cli). */
static void test_read_is_run(void **state)
{
	(void)state;
	const char *box = bsim_test_dir_held("box2d_made");
	const char *argv[] = {"sweep", experiment,  "--trials", trials_arg, "--backend",
	                      "box2d", "--threads", "2",        "--quiet",  "--overwrite",
	                      "--out", box,         NULL};
	assert_int_equal(bsim_test_cli(argv, NULL, NULL), 0);
	char sides[1400], dirs[2][1200];
	snprintf(sides, sizeof sides, "thesis,trials:%s", box);
	snprintf(dirs[0], sizeof dirs[0], "%s", bsim_test_dir_held("box2d_read"));
	snprintf(dirs[1], sizeof dirs[1], "%s", bsim_test_dir_held("box2d_run"));
	int rc0 = compare(sides, dirs[0], NULL, NULL),
	    rc1 = compare("thesis,box2d", dirs[1], NULL, NULL);
	assert_int_equal(rc0, rc1);
	ydoc d[2];
	struct fy_node *root[2] = {json_open(dirs[0], "report.json", &d[0]),
	                           json_open(dirs[1], "report.json", &d[1])};
	static const char *const ev[] = {"traversed", "left",  "right",
	                                 "side_exit", "stuck", "unstable"};
	static const char *const num[] = {"both", "only_a", "only_b", "neither", "p_a", "p_b"};
	char p[160], a[64], b[64];
	assert_true(bsim_test_json_at(root[0], "rule.tests") ==
	            bsim_test_json_at(root[1], "rule.tests"));
	assert_true(bsim_test_json_at(root[0], "groups_disagreeing") ==
	            bsim_test_json_at(root[1], "groups_disagreeing"));
	for (int g = 0; g < GROUPS; g++) {
		snprintf(p, sizeof p, "groups.%d.verdict", g);
		assert_string_equal(bsim_test_json_text_at(root[0], p, a, sizeof a),
		                    bsim_test_json_text_at(root[1], p, b, sizeof b));
		snprintf(p, sizeof p, "groups.%d.discordant", g);
		assert_true(bsim_test_json_at(root[0], p) == bsim_test_json_at(root[1], p));
		for (int e = 0; e < 6; e++)
			for (int k = 0; k < 6; k++) {
				snprintf(p, sizeof p, "groups.%d.events.%s.%s", g, ev[e], num[k]);
				assert_true(bsim_test_json_at(root[0], p) ==
				            bsim_test_json_at(root[1], p));
			}
		for (int e = 0; e < 6; e++) {
			/* a deterministic group's events have no p-value */
			snprintf(p, sizeof p, "groups.%d.events.%s.p_mcnemar", g, ev[e]);
			struct fy_node *n0 = bsim_ydoc_lookup(root[0], p),
			               *n1 = bsim_ydoc_lookup(root[1], p);
			assert_true((n0 == NULL) == (n1 == NULL));
			if (n0)
				assert_string_equal(
				        bsim_test_json_text_at(root[0], p, a, sizeof a),
				        bsim_test_json_text_at(root[1], p, b, sizeof b));
		}
	}
	bsim_ydoc_free(&d[0]);
	bsim_ydoc_free(&d[1]);
}

/* regress reads the recorded file again and reruns the other side; a file
 * changed since is refused, nothing written. A side read is not replayed. */
static void test_regress_and_replay(void **state)
{
	(void)state;
	/* a comparison of a copy of the file, which this test then changes */
	lines l;
	lines_read(made_csv, &l);
	const char *dir = write_variant("copy", &l, -1, -1, NULL, NULL);
	char copy_dir[1200], sides[1400], cmp[1200], where[1400];
	snprintf(copy_dir, sizeof copy_dir, "%s", dir);
	snprintf(sides, sizeof sides, "thesis,trials:%s", copy_dir);
	snprintf(cmp, sizeof cmp, "%s", bsim_test_dir_held("copy_cmp"));
	assert_int_equal(compare(sides, cmp, NULL, NULL), 0);
	const char *reg = bsim_test_dir_held("regress");
	const char *argv[] = {"regress", cmp, "--overwrite", "--out", reg, NULL};
	char *out = NULL;
	assert_int_equal(bsim_test_cli(argv, &out, NULL), 0);
	assert_non_null(strstr(out, "copy: 0 of 600 trials changed"));
	free(out);
	char *md = bsim_test_read(bsim_test_join(reg, "regress.md"));
	assert_non_null(md);
	assert_non_null(strstr(md, "Read, not run:"));
	free(md);
	/* one field of one row changed: the bytes differ */
	int line = row_of(&l, 20, 3);
	char with[2000];
	snprintf(with, sizeof with, "%s0", l.line[line - 1]);
	write_variant("copy", &l, -1, line - 1, with, NULL);
	const char *gone = bsim_test_join(bsim_test_dir_held("regress_refused"), "out");
	const char *argv2[] = {"regress", cmp, "--out", gone, NULL};
	snprintf(where, sizeof where, "%s/trials.csv: expected the bytes the comparison read",
	         copy_dir);
	const char *needles[] = {where, "the file changed since", NULL};
	bsim_test_expect_input_error(argv2, needles);
	assert_false(bsim_test_exists(gone));
	free(l.text);
	/* run DIR --backend LABEL of the side read */
	const char *argv3[] = {"run", same_dir,  "--backend", "made", "--group",
	                       "3",   "--trial", "1",         NULL};
	const char *read[] = {"--backend made: side made of", "was read from", NULL};
	bsim_test_expect_input_error(argv3, read);
}

/* A gate lattice: the final gate is read and compared (one trial's
 * moved is one discordant pair), and required. */
static void test_lattice(void **state)
{
	(void)state;
	char lat_exp[1200], lat[1200], sides[1400], where[1400];
	snprintf(lat_exp, sizeof lat_exp, "%s",
	         bsim_test_src("tests/data/compare_two_sides/c_track.yaml"));
	snprintf(lat, sizeof lat, "%s", bsim_test_dir_held("lat"));
	const char *argv[] = {"sweep",       lat_exp, "--trials", "3", "--quiet",
	                      "--overwrite", "--out", lat,        NULL};
	assert_int_equal(bsim_test_cli(argv, NULL, NULL), 0);
	lines l;
	lines_read_n(bsim_test_join(lat, "trials.csv"), &l, 3);
	int iy = column(&l, "final_iy");
	char *row = l.line[1], with[4000], v[32];
	/* trial 0 ends one row of gates further */
	field(row, iy, v, sizeof v);
	const char *at = row;
	for (int k = 0; k < iy; k++)
		at = strchr(at, ',') + 1;
	snprintf(with, sizeof with, "%.*s%d%s", (int)(at - row), row, atoi(v) + 1, strchr(at, ','));
	char moved[1200], cut[1200];
	snprintf(moved, sizeof moved, "%s", write_variant("lat_moved", &l, -1, 1, with, NULL));
	snprintf(cut, sizeof cut, "%s", write_without("lat_cut", &l, "final_ix", "final_iy"));
	static const char *const dirs[2] = {"lat_same", "lat_moved_cmp"};
	for (int m = 0; m < 2; m++) {
		snprintf(sides, sizeof sides, "thesis,trials:%s", m ? moved : lat);
		const char *out = bsim_test_dir_held(dirs[m]);
		const char *cmp[] = {"compare", lat_exp,   "--trials", "3", "--backends",
		                     sides,     "--quiet", "--out",    out, NULL};
		int rc = bsim_test_cli(cmp, NULL, NULL);
		assert_true(rc == 0 || rc == 3);
		ydoc d;
		struct fy_node *root = json_open(out, "report.json", &d);
		assert_int_equal((int)bsim_test_json_at(root, "groups.0.discordant"), m);
		assert_int_equal(
		        (int)bsim_test_json_at(root, "groups.0.final_locations.discordant"), m);
		bsim_ydoc_free(&d);
	}
	snprintf(sides, sizeof sides, "thesis,trials:%s", cut);
	const char *gone = bsim_test_join(bsim_test_dir_held("lat_refused"), "out");
	const char *cmp[] = {"compare", lat_exp, "--trials", "3", "--backends",
	                     sides,     "--out", gone,       NULL};
	snprintf(where, sizeof where,
	         "%s/trials.csv:1: column final_ix: expected on a gate lattice", cut);
	const char *needles[] = {where, NULL};
	bsim_test_expect_input_error(cmp, needles);
	assert_false(bsim_test_exists(gone));
	free(l.text);
}

/* The spelling: trials:PATH alone, PATH found; not a backend of run. */
static void test_spelling(void **state)
{
	(void)state;
	char sides[1400];
	snprintf(sides, sizeof sides, "thesis,trials:%s:k=v", made);
	const char *opts[] = {"takes no options", NULL};
	refused_as(sides, NULL, opts, 1);
	const char *none[] = {"side trials:: expected trials:PATH", NULL};
	refused_as("thesis,trials:", NULL, none, 1);
	snprintf(sides, sizeof sides, "thesis,trials:%s/nothing", made);
	const char *missing[] = {"/nothing: expected a trials.csv or a directory holding one",
	                         NULL};
	refused_as(sides, NULL, missing, 1);
	/* labelled by its folder: one named as another side is refused, one
	 * that is not a label is labelled trials */
	lines l;
	lines_read(made_csv, &l);
	snprintf(sides, sizeof sides, "thesis,trials:%s",
	         write_variant("thesis", &l, -1, -1, NULL, NULL));
	const char *clash[] = {"are both labelled thesis", "move the file to a folder", NULL};
	refused(sides, NULL, clash);
	snprintf(sides, sizeof sides, "thesis,trials:%s/trials.csv",
	         write_variant("made.v2", &l, -1, -1, NULL, NULL));
	const char *out = bsim_test_dir_held("label_cmp");
	assert_int_equal(compare(sides, out, NULL, NULL), 0);
	assert_true(bsim_test_exists(bsim_test_join(out, "trials/trials.csv")));
	free(l.text);
	const char *argv[] = {"run", experiment, "--backend", "trials:x", NULL};
	const char *not_run[] = {"--backend trials:x: a side of beamsim compare read from", NULL};
	bsim_test_expect_input_error(argv, not_run);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_same_trials), cmocka_unit_test(test_one_group_flipped),
	        cmocka_unit_test(test_refusals),    cmocka_unit_test(test_three_sides),
	        cmocka_unit_test(test_read_is_run), cmocka_unit_test(test_regress_and_replay),
	        cmocka_unit_test(test_lattice),     cmocka_unit_test(test_spelling),
	};
	return cmocka_run_group_tests(tests, setup, NULL);
}
