/* beamsim compare and regress through the real program: each backend's
 * half of a comparison is exactly its own sweep (the pairs share
 * schedules), results do not depend on threads, the replay lines in a
 * report reproduce the trials they name, a rerun of a stored run with the
 * same code reproduces it exactly, and a baseline whose outcomes were
 * changed is caught (exit status 3) in the groups that were changed.
 * Three sides: report.json's every pair against pairs.csv read on its own,
 * and the odd one out by its rule. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
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

static char experiment[1200];
static char cmp_dir[1200];

/* A baseline edited by hand is no longer the set of files its manifest
 * lists (regress refuses such a mix): the edit removes the manifest too. */
static void edit_in(const char *dir, const char *name, const char *text)
{
	char path[1200];
	bsim_test_write(dir, name, text);
	snprintf(path, sizeof path, "%s/manifest.json", dir);
	remove(path);
}

static char *read_in(const char *dir, const char *name)
{
	char path[1400];
	snprintf(path, sizeof path, "%s/%s", dir, name);
	char *s = bsim_test_read(path);
	assert_non_null(s);
	return s;
}

static int setup(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("exp");
	char text[2000];
	snprintf(text, sizeof text,
	         "scene: %s\ntrials: 12\nseed: 5\ngrid:\n"
	         "  effects.propulsion.force: [8, 9]\n"
	         "  effects.random_force.magnitude: [0, 30]\n",
	         bsim_test_src("configs/thesis/gate.yaml"));
	snprintf(experiment, sizeof experiment, "%s", bsim_test_write(dir, "small.yaml", text));
	snprintf(cmp_dir, sizeof cmp_dir, "%s", bsim_test_dir_held("cmp"));
	const char *argv[] = {"compare", experiment, "--threads", "2",
	                      "--quiet", "--out",    cmp_dir,     NULL};
	int status = bsim_test_cli(argv, NULL, NULL);
	return status == 0 || status == 3 ? 0 : -1;
}

/* Each backend's trials in the comparison are those of its own sweep. */
static void test_halves_are_sweeps(void **state)
{
	(void)state;
	const char *backends[] = {"thesis", "box2d"};
	for (int i = 0; i < 2; i++) {
		const char *dir = bsim_test_dir_held(backends[i]);
		const char *argv[] = {"sweep",   experiment, "--backend", backends[i],
		                      "--quiet", "--out",    dir,         NULL};
		assert_int_equal(bsim_test_cli(argv, NULL, NULL), 0);
		char sub[1300];
		snprintf(sub, sizeof sub, "%s/%s", cmp_dir, backends[i]);
		char *a = read_in(dir, "trials.csv"), *b = read_in(sub, "trials.csv");
		assert_string_equal(a, b);
		free(a);
		free(b);
	}
}

/* Every backend of the registry is a side of one comparison (`--backends
 * A,B,C,...`, the whole list), and each side is that backend's own sweep. */
static void test_every_backend_a_side(void **state)
{
	(void)state;
	const bsim_backend *const *list = bsim_backend_list();
	char sides[512] = "";
	for (int n = 0; list[n]; n++)
		snprintf(sides + strlen(sides), sizeof sides - strlen(sides), "%s%s", n ? "," : "",
		         list[n]->name);
	char dir[1200];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir_held("cmp_all"));
	const char *argv[] = {"compare", experiment, "--backends", sides, "--threads",
	                      "2",       "--quiet",  "--out",      dir,   NULL};
	int status = bsim_test_cli(argv, NULL, NULL);
	if (status != 0 && status != 3)
		fail_msg("compare --backends %s: exit %d", sides, status);
	for (int n = 0; list[n]; n++) {
		char name[64];
		snprintf(name, sizeof name, "side_sweep_%s", list[n]->name);
		const char *sweep = bsim_test_dir_held(name);
		const char *sw[] = {"sweep",   experiment, "--backend", list[n]->name,
		                    "--quiet", "--out",    sweep,       NULL};
		assert_int_equal(bsim_test_cli(sw, NULL, NULL), 0);
		char sub[1300];
		snprintf(sub, sizeof sub, "%s/%s", dir, list[n]->name);
		char *a = read_in(sweep, "trials.csv"), *b = read_in(sub, "trials.csv");
		if (strcmp(a, b) != 0)
			fail_msg("compare --backends %s: the %s side differs from its sweep", sides,
			         list[n]->name);
		free(a);
		free(b);
	}
}

/* The exit status says what report.json says; threads change nothing; the
 * headline counts every group: those that disagree, agree and are left
 * undecided (the inconclusive and uninformative of the line after it). */
static void test_status_and_threads(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir_held("cmp1");
	const char *argv[] = {"compare", experiment, "--threads", "1", "--out", dir, NULL};
	char *out = NULL;
	int status = bsim_test_cli(argv, &out, NULL);
	char *json = read_in(dir, "report.json");
	int disagreeing = -1;
	const char *p = strstr(json, "\"groups_disagreeing\": ");
	assert_non_null(p);
	sscanf(p, "\"groups_disagreeing\": %d", &disagreeing);
	assert_int_equal(status, disagreeing > 0 ? 3 : 0);
	int head[4] = {-1, -1, -1, -1}, uninformative = -1, inconclusive = -1;
	const char *h = strstr(out, " groups disagree, ");
	assert_non_null(h);
	while (h > out && h[-1] != ':')
		h--;
	assert_int_equal(sscanf(h, " %d of %d groups disagree, %d agree, %d undecided", &head[0],
	                        &head[1], &head[2], &head[3]),
	                 4);
	const char *u = strstr(out, " uninformative"), *i = strstr(out, " inconclusive");
	assert_true(u && i);
	while (u > out && u[-1] != ' ')
		u--;
	while (i > out && i[-1] != ' ')
		i--;
	uninformative = atoi(u);
	inconclusive = atoi(i);
	print_message("headline: %d of %d disagree, %d agree, %d undecided\n", head[0], head[1],
	              head[2], head[3]);
	assert_int_equal(head[0], disagreeing);
	assert_int_equal(head[0] + head[2] + head[3], head[1]);
	assert_int_equal(head[3], uninformative + inconclusive);
	free(out);
	char *pairs1 = read_in(dir, "pairs.csv"), *pairs2 = read_in(cmp_dir, "pairs.csv");
	assert_string_equal(pairs1, pairs2);
	free(json);
	free(pairs1);
	free(pairs2);
}

/* Splits a replay line (plain words, no quoting needed for these scenes)
 * after "beamsim " into argv; returns argc. */
static int split(char *line, const char *argv[], int max)
{
	int n = 0;
	assert_true(strncmp(line, "beamsim ", 8) == 0);
	assert_null(strchr(line, '\''));
	for (char *tok = strtok(line + 8, " "); tok && n < max - 2; tok = strtok(NULL, " "))
		argv[n++] = tok;
	argv[n++] = "--json";
	argv[n] = NULL;
	return n;
}

/* The JSON string value after key at or after *from (no escapes). */
static char *json_text(const char **from, const char *key)
{
	const char *p = strstr(*from, key);
	if (!p)
		return NULL;
	p += strlen(key);
	const char *end = strchr(p, '"');
	*from = end;
	char *s = malloc((size_t)(end - p) + 1);
	memcpy(s, p, (size_t)(end - p));
	s[end - p] = '\0';
	return s;
}

/* Every replay line of a report, of sides first_side..1 (0: a, 1: b),
 * gives the outcome the report states. */
static int check_replays(const char *json, int first_side)
{
	int checked = 0;
	const char *at = json;
	for (;;) {
		const char *ex = strstr(at, "{\"trial\": ");
		if (!ex)
			break;
		at = ex + 1;
		for (int side = first_side; side < 2; side++) {
			const char *from = ex;
			char *outcome = json_text(&from, side ? "\"b\": {\"outcome\": \""
			                                      : "\"a\": {\"outcome\": \"");
			char *type = json_text(&from, "\"type\": \"");
			char *line =
			        json_text(&from, side ? "\"replay_b\": \"" : "\"replay_a\": \"");
			assert_non_null(line);
			const char *argv[64];
			split(line, argv, 64);
			char *out = NULL;
			assert_int_equal(bsim_test_cli(argv, &out, NULL), 0);
			char want[128];
			snprintf(want, sizeof want, "\"outcome\": \"%s\"", outcome);
			assert_non_null(strstr(out, want));
			snprintf(want, sizeof want, "\"type\": \"%s\"", type);
			assert_non_null(strstr(out, want));
			checked++;
			free(out);
			free(outcome);
			free(type);
			free(line);
		}
	}
	return checked;
}

static void test_compare_replays(void **state)
{
	(void)state;
	char *json = read_in(cmp_dir, "report.json");
	check_replays(json, 0);
	free(json);
}

/* Same code, same inputs: every trial identical, exit 0 even with --exact. */
static void test_regress_identical(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir_held("rerun");
	const char *argv[] = {"regress", cmp_dir, "--exact", "--out", dir, NULL};
	char *out = NULL;
	assert_int_equal(bsim_test_cli(argv, &out, NULL), 0);
	assert_non_null(strstr(out, "thesis: 0 of 48 trials changed"));
	assert_non_null(strstr(out, "box2d: 0 of 48 trials changed"));
	free(out);
	/* The rerun is itself a baseline. */
	char *a = read_in(dir, "run.json");
	assert_non_null(strstr(a, "\"command\": \"compare\""));
	/* What built it: each registered backend's version (NAME_version; the
	 * Box2D backend's the Box2D CMake found), a compiler named. */
	assert_non_null(strstr(a, "\"box2d_version\": \"" BSIM_TEST_BOX2D_VERSION "\""));
	for (const bsim_backend *const *b = bsim_backend_list(); *b; b++) {
		char key[128];
		snprintf(key, sizeof key, "\"%s_version\": \"%s\"", (*b)->name, (*b)->version);
		assert_non_null(strstr(a, key));
	}
	assert_non_null(strstr(a, "\"compiler\": \"gcc ") || strstr(a, "\"compiler\": \"clang "));
	assert_non_null(strstr(a, "\"beamsim_commit\": \""));
	free(a);
}

/* A stored sweep whose group 2 (force 9, no noise) traversals were all
 * rewritten as side exits: regress flags group 2 only, as a deterministic
 * group whose one pair differs, exit 3, and its replay line reproduces the
 * rerun's (true) outcome. */
static void test_regress_catches_changes(void **state)
{
	(void)state;
	const char *base = bsim_test_dir_held("base");
	const char *sweep[] = {"sweep", experiment, "--quiet", "--out", base, NULL};
	assert_int_equal(bsim_test_cli(sweep, NULL, NULL), 0);
	char *csv = read_in(base, "trials.csv");
	char *edited = malloc(strlen(csv) * 2 + 1);
	char *w = edited;
	int changed = 0;
	for (char *line = strtok(csv, "\n"); line; line = strtok(NULL, "\n")) {
		if (strncmp(line, "2,", 2) == 0 && strstr(line, ",traversed,")) {
			char *o = strstr(line, ",traversed,");
			char *rest = strchr(o + 11, ',');
			w += sprintf(w, "%.*s,side_exit,none%s\n", (int)(o - line), line, rest);
			changed++;
		} else {
			w += sprintf(w, "%s\n", line);
		}
	}
	assert_true(changed >= 10); /* force 9 without noise traverses */
	edit_in(base, "trials.csv", edited);

	const char *dir = bsim_test_dir_held("caught");
	const char *argv[] = {"regress", base, "--quiet", "--out", dir, NULL};
	assert_int_equal(bsim_test_cli(argv, NULL, NULL), 3);
	char *json = read_in(dir, "regress.json");
	int disagree = 0;
	for (const char *p = json; (p = strstr(p, "\"verdict\": \"D")); p++)
		disagree++;
	assert_int_equal(disagree, 1);
	assert_non_null(strstr(json, "{\"group\": 2, \"params\": {\"effects.propulsion.force\": 9, "
	                             "\"effects.random_force.magnitude\": 0}, \"verdict\": "
	                             "\"DIFFERENT\", \"deterministic\": true, \"pairs\": 1"));
	/* The rerun's side replays; the baseline's was edited, so it cannot. */
	assert_int_equal(check_replays(json, 1), 1);
	free(csv);
	free(edited);
	free(json);
}

/* --exact: one end position changed in the 10th digit is a change. */
static void test_regress_exact(void **state)
{
	(void)state;
	const char *base = bsim_test_dir_held("exact");
	const char *sweep[] = {"sweep", experiment, "--quiet", "--out", base, NULL};
	assert_int_equal(bsim_test_cli(sweep, NULL, NULL), 0);
	char *csv = read_in(base, "trials.csv");
	char *row = strstr(csv, "\n0,0,");
	assert_non_null(row);
	char *field = row + 1;
	for (int i = 0; i < 6; i++) /* to x_end */
		field = strchr(field, ',') + 1;
	*field = *field == '1' ? '2' : '1';
	edit_in(base, "trials.csv", csv);
	const char *loose[] = {"regress", base, "--quiet", "--out", bsim_test_dir_held("loose"),
	                       NULL};
	assert_int_equal(bsim_test_cli(loose, NULL, NULL), 0);
	const char *exact[] = {
	        "regress", base, "--quiet", "--exact", "--out", bsim_test_dir_held("tight"), NULL};
	assert_int_equal(bsim_test_cli(exact, NULL, NULL), 3);
	free(csv);
}

/* Two settings of one backend: each side's directory is named by its
 * label, its options are recorded, and regress reruns it. --backend-opt
 * still reaches every side on its backend; inline options win. */
static void test_one_backend_two_settings(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir_held("euler");
	const char *argv[] = {"compare",
	                      experiment,
	                      "--backends",
	                      "thesis,thesis:integrator=euler",
	                      "--backend-opt",
	                      "thesis:slop=2e-6",
	                      "--backend-opt",
	                      "thesis:integrator=midpoint",
	                      "--quiet",
	                      "--out",
	                      dir,
	                      NULL};
	int status = bsim_test_cli(argv, NULL, NULL);
	assert_true(status == 0 || status == 3);
	char *a = read_in(dir, "thesis/trials.csv");
	char *b = read_in(dir, "thesis-integrator=euler/trials.csv");
	assert_string_not_equal(a, b); /* euler is another integrator */
	/* Every knob in the backend's order, numbers as numbers. */
	char *run = read_in(dir, "run.json");
	assert_non_null(strstr(run, "\"label\": \"thesis:integrator=euler\", \"options\": "
	                            "{\"integrator\": \"euler\", \"impact_order\": "
	                            "\"simultaneous\", \"projection\": 1, \"slop\": 2e-6,"));
	assert_non_null(strstr(run, "\"label\": \"thesis\", \"options\": {\"integrator\": "
	                            "\"midpoint\", \"impact_order\": \"simultaneous\", "
	                            "\"projection\": 1, \"slop\": 2e-6,"));
	char *md = read_in(dir, "report.md");
	assert_non_null(strstr(md, "# beamsim compare: thesis vs thesis:integrator=euler"));
	const char *again[] = {
	        "regress", dir, "--exact", "--out", bsim_test_dir_held("euler_rerun"), NULL};
	char *out = NULL;
	assert_int_equal(bsim_test_cli(again, &out, NULL), 0);
	assert_non_null(strstr(out, "thesis:integrator=euler: 0 of 48 trials changed"));
	free(out);
	free(a);
	free(b);
	free(run);
	free(md);
}

/* The noise-free groups are deterministic: one pair, reported as such,
 * with no interval or p-value; the others carry Tango's interval, an
 * equivalence p-value, mde80 and the smallest significant difference, and
 * the Holm family counts the events marked in it. */
static void test_report_deterministic(void **state)
{
	(void)state;
	char *json = read_in(cmp_dir, "report.json");
	assert_non_null(strstr(json, "{\"group\": 0, \"params\": {\"effects.propulsion.force\": 8, "
	                             "\"effects.random_force.magnitude\": 0}, \"verdict\": "
	                             "\"same\", \"deterministic\": true, \"pairs\": 1"));
	const char *g1 = strstr(json, "{\"group\": 1, ");
	assert_non_null(g1);
	assert_non_null(strstr(g1, "\"deterministic\": false, \"pairs\": 12"));
	assert_non_null(strstr(g1, "\"p_equivalence\": "));
	assert_non_null(strstr(g1, "\"mde80\": "));
	assert_non_null(strstr(g1, "\"min_significant\": "));
	assert_non_null(strstr(json, "\"interval\": \"tango_score\""));
	/* The family's size is the number of events in it, group by group. */
	const char *at = strstr(json, "\"tests\": ");
	assert_non_null(at);
	int tests = atoi(at + strlen("\"tests\": ")), in = 0;
	for (const char *p = json; (p = strstr(p, "\"in_family\": true")); p++)
		in++;
	assert_int_equal(tests, in);
	assert_true(tests > 0 && tests < 2 * 6);
	char *md = read_in(cmp_dir, "report.md");
	assert_non_null(strstr(md, "| 0 | 8 | 0 | stuck | stuck | deterministic | 0 of 1 |"));
	free(json);
	free(md);
}

/* Box2D's explicit spring torque on beams too stiff for it (omega_n h =
 * 2.8) blows up: the trials are unstable, an event the comparison counts
 * and flags, never an ordinary outcome. */
static void test_unstable_event(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir_held("stiff");
	const char *argv[] = {"compare",    bsim_test_src("configs/hard/stiff_beam_sweep.yaml"),
	                      "--backends", "thesis,box2d:spring=torque",
	                      "--out",      dir,
	                      NULL};
	char *out = NULL;
	assert_int_equal(bsim_test_cli(argv, &out, NULL), 3);
	assert_non_null(strstr(out, "box2d:spring=torque: "));
	assert_non_null(strstr(out, " unstable trials"));
	char *json = read_in(dir, "report.json");
	const char *ev = strstr(json, "{\"group\": 1, ");
	assert_non_null(ev);
	ev = strstr(ev, "\"unstable\": {\"p_a\": 0, ");
	assert_non_null(ev);
	char *csv = read_in(dir, "box2d-spring=torque/trials.csv");
	assert_non_null(strstr(csv, ",unstable,none,"));
	char *thesis = read_in(dir, "thesis/trials.csv");
	assert_null(strstr(thesis, ",unstable,"));
	free(out);
	free(json);
	free(csv);
	free(thesis);
}

/* A trials.csv of the first format (eleven columns, no ledger) is still a
 * baseline: columns are found by name. */
static void test_regress_old_format(void **state)
{
	(void)state;
	const char *base = bsim_test_dir_held("oldfmt");
	const char *sweep[] = {"sweep", experiment, "--quiet", "--out", base, NULL};
	assert_int_equal(bsim_test_cli(sweep, NULL, NULL), 0);
	char *csv = read_in(base, "trials.csv");
	char *old = malloc(strlen(csv) + 1), *w = old;
	for (char *line = strtok(csv, "\n"); line; line = strtok(NULL, "\n")) {
		char *p = line;
		for (int i = 0; i < 11 && p; i++)
			p = strchr(p + 1, ',');
		w += sprintf(w, "%.*s\n", (int)(p - line), line);
	}
	edit_in(base, "trials.csv", old); /* an old baseline has no manifest */
	const char *argv[] = {
	        "regress", base, "--exact", "--out", bsim_test_dir_held("oldfmt_rerun"), NULL};
	char *out = NULL;
	assert_int_equal(bsim_test_cli(argv, &out, NULL), 0);
	assert_non_null(strstr(out, "thesis: 0 of 48 trials changed"));
	free(out);
	free(csv);
	free(old);
}

static void test_bad_usage(void **state)
{
	(void)state;
	char *err = NULL;
	const char *same[] = {"compare",    experiment,
	                      "--backends", "thesis,thesis",
	                      "--out",      bsim_test_dir_held("bad1"),
	                      NULL};
	assert_int_equal(bsim_test_cli(same, NULL, &err), 2);
	assert_non_null(strstr(err, "two different sides"));
	free(err);
	const char *knob[] = {"compare",
	                      experiment,
	                      "--backend-opt",
	                      "box2d:nope=1",
	                      "--out",
	                      bsim_test_dir_held("bad2"),
	                      NULL};
	assert_int_equal(bsim_test_cli(knob, NULL, &err), 2);
	assert_non_null(strstr(err, "nope"));
	free(err);
	const char *plain[] = {"compare",    experiment, "--backend-opt",
	                       "substeps=2", "--out",    bsim_test_dir_held("bad3b"),
	                       NULL};
	assert_int_equal(bsim_test_cli(plain, NULL, &err), 2);
	assert_non_null(strstr(err, "expected B:KEY=VALUE with several backends"));
	free(err);
	const char *who[] = {"compare", experiment, "--backend-opt",
	                     "ode:x=1", "--out",    bsim_test_dir_held("bad3"),
	                     NULL};
	assert_int_equal(bsim_test_cli(who, NULL, &err), 2);
	assert_non_null(strstr(err, "B:KEY=VALUE"));
	free(err);
	const char *empty = bsim_test_dir_held("empty");
	const char *none[] = {"regress", empty, "--out", bsim_test_dir_held("bad4"), NULL};
	assert_int_equal(bsim_test_cli(none, NULL, &err), 2);
	assert_non_null(strstr(err, "run.json"));
	free(err);
}

/* ---- three sides ------------------------------------------------------------ */

enum { N3 = 3, P3 = 3, MAX_ROWS = 64 };
/* Box2D without continuous collision: with it, the two beams' simultaneous
 * times of impact are resolved one after the other, which may tip the
 * symmetric gate's deterministic traversal (F = 9 N, no random force) to a
 * side, and that group would then have no single odd side. */
static const char *const sides3[N3] = {"thesis", "box2d:continuous=off", "thesis:impact_mass=0.1"};
static const char *const dirs3[N3] = {"thesis", "box2d-continuous=off", "thesis-impact_mass=0.1"};
static const int pair3[P3][2] = {{0, 1}, {0, 2}, {1, 2}};

/* pairs.csv read on its own: per row, each side's outcome and type. */
typedef struct pairs_rows {
	int n;
	int group[MAX_ROWS];
	char outcome[MAX_ROWS][N3][16], type[MAX_ROWS][N3][16];
} pairs_rows;

static void pairs_read(const char *dir, pairs_rows *r)
{
	char *text = read_in(dir, "pairs.csv");
	char *save = NULL, *line = strtok_r(text, "\n", &save);
	assert_string_equal(line, "group,trial,outcome_a,type_a,outcome_b,type_b,outcome_c,type_c,"
	                          "t_separate,t_separate_a_c,t_separate_b_c,location_a,"
	                          "location_b,location_c");
	r->n = 0;
	while ((line = strtok_r(NULL, "\n", &save)) != NULL) {
		assert_true(r->n < MAX_ROWS);
		char *f[14];
		int k = 0;
		/* empty fields (a pair that never separated) kept: split by hand */
		for (char *p = line; k < 14; k++) {
			f[k] = p;
			char *c = strchr(p, ',');
			if (!c) {
				k++;
				break;
			}
			*c = '\0';
			p = c + 1;
		}
		assert_int_equal(k, 14);
		r->group[r->n] = atoi(f[0]);
		for (int s = 0; s < N3; s++) {
			snprintf(r->outcome[r->n][s], 16, "%s", f[2 + 2 * s]);
			snprintf(r->type[r->n][s], 16, "%s", f[3 + 2 * s]);
		}
		r->n++;
	}
	free(text);
}

/* Event e of a row's side, from the outcome and type columns. */
static int row_event(const pairs_rows *r, int i, int s, int e)
{
	static const char *const outcome[] = {"traversed", "traversed", "traversed",
	                                      "side_exit", "stuck",     "unstable"};
	if (strcmp(r->outcome[i][s], outcome[e]) != 0)
		return 0;
	return e == 1   ? strcmp(r->type[i][s], "left") == 0
	       : e == 2 ? strcmp(r->type[i][s], "right") == 0
	                : 1;
}

static int verdict_rank(const char *v)
{
	static const char *const order[] = {"same",  "equivalent", "uninformative", "inconclusive",
	                                    "small", "DISAGREE",   "DIFFERENT"};
	for (int i = 0; i < 7; i++)
		if (strcmp(v, order[i]) == 0)
			return i;
	fail_msg("unknown verdict %s", v);
	return -1;
}

/* Three sides: thesis, box2d (continuous=off) and the thesis backend
 * reading the essay's impact equation literally (a side meant to differ).
 * Checked against pairs.csv read on its own: every pair's 2x2 table of
 * every event in report.json; each side's trials.csv is its columns of
 * pairs.csv; a
 * group's verdict is its least agreeing pair's, groups_disagreeing and the
 * exit status follow; the odd one out is the side that the rule (docs/
 * compare.md), applied here to report.json's pairwise verdicts, names; the
 * replay lines of the disagreeing pairs reproduce their trials. */
static void test_three_sides(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir_held("cmp3");
	char backends[200];
	snprintf(backends, sizeof backends, "%s,%s,%s", sides3[0], sides3[1], sides3[2]);
	const char *argv[] = {"compare", experiment, "--backends", backends, "--threads",
	                      "2",       "--quiet",  "--out",      dir,      NULL};
	int status = bsim_test_cli(argv, NULL, NULL);
	assert_true(status == 0 || status == 3);
	pairs_rows rows;
	pairs_read(dir, &rows);
	/* each side's trials.csv: its own columns */
	for (int s = 0; s < N3; s++) {
		char sub[1300];
		snprintf(sub, sizeof sub, "%s/%s", dir, dirs3[s]);
		char *t = read_in(sub, "trials.csv"), *save = NULL;
		strtok_r(t, "\n", &save);
		for (int i = 0; i < rows.n; i++) {
			char *line = strtok_r(NULL, "\n", &save), want[64];
			assert_non_null(line);
			snprintf(want, sizeof want, ",%s,%s,", rows.outcome[i][s], rows.type[i][s]);
			assert_non_null(strstr(line, want));
		}
		free(t);
	}
	ydoc d;
	bsim_error err;
	char path[1400], p[200], buf[64];
	snprintf(path, sizeof path, "%s/report.json", dir);
	assert_int_equal(bsim_ydoc_load_own(&d, path, &err), BSIM_OK);
	struct fy_node *root = fy_document_root(d.fyd);
	assert_string_equal(bsim_test_json_text_at(root, "a.label", buf, sizeof buf), sides3[0]);
	assert_string_equal(bsim_test_json_text_at(root, "b.label", buf, sizeof buf), sides3[1]);
	for (int s = 0; s < N3; s++) {
		snprintf(p, sizeof p, "sides.%d.label", s);
		assert_string_equal(bsim_test_json_text_at(root, p, buf, sizeof buf), sides3[s]);
	}
	int groups = (int)bsim_test_json_at(root, "pairs_of_sides") == P3 ? 4 : -1, disagreeing = 0,
	    odd_found = 0;
	assert_int_equal(groups, 4);
	for (int g = 0; g < groups; g++) {
		snprintf(p, sizeof p, "groups.%d.deterministic", g);
		int det = strcmp(bsim_test_json_text_at(root, p, buf, sizeof buf), "true") == 0;
		int differ[P3], worst = 0;
		for (int k = 0; k < P3; k++) {
			char q[120];
			snprintf(q, sizeof q, "groups.%d.pairwise.%d", g, k);
			snprintf(p, sizeof p, "%s.a", q);
			assert_string_equal(bsim_test_json_text_at(root, p, buf, sizeof buf),
			                    sides3[pair3[k][0]]);
			snprintf(p, sizeof p, "%s.b", q);
			assert_string_equal(bsim_test_json_text_at(root, p, buf, sizeof buf),
			                    sides3[pair3[k][1]]);
			for (int e = 0; e < 6; e++) {
				static const char *const ev[] = {"traversed", "left",  "right",
				                                 "side_exit", "stuck", "unstable"};
				int n[4] = {0, 0, 0, 0}, seen = 0;
				for (int i = 0; i < rows.n; i++) {
					if (rows.group[i] != g || (det && seen++))
						continue;
					int x = row_event(&rows, i, pair3[k][0], e),
					    y = row_event(&rows, i, pair3[k][1], e);
					n[x && y ? 0 : x ? 1 : y ? 2 : 3]++;
				}
				static const char *const cell[] = {"both", "only_a", "only_b",
				                                   "neither"};
				for (int c = 0; c < 4; c++) {
					snprintf(p, sizeof p, "%s.events.%s.%s", q, ev[e], cell[c]);
					assert_int_equal((int)bsim_test_json_at(root, p), n[c]);
				}
			}
			snprintf(p, sizeof p, "%s.verdict", q);
			int v = verdict_rank(bsim_test_json_text_at(root, p, buf, sizeof buf));
			worst = v > worst ? v : worst;
			differ[k] = v >= 5; /* DISAGREE or DIFFERENT */
		}
		snprintf(p, sizeof p, "groups.%d.verdict", g);
		assert_int_equal(verdict_rank(bsim_test_json_text_at(root, p, buf, sizeof buf)),
		                 worst);
		disagreeing += worst >= 5;
		/* the odd one out by the rule: every pair with it differs, no
		 * other pair does */
		int odd = -1, candidates = 0, any = differ[0] || differ[1] || differ[2];
		for (int s = 0; s < N3; s++) {
			int ok = 1;
			for (int k = 0; k < P3; k++) {
				int with = pair3[k][0] == s || pair3[k][1] == s;
				ok &= with ? differ[k] : !differ[k];
			}
			if (ok) {
				odd = s;
				candidates++;
			}
		}
		snprintf(p, sizeof p, "groups.%d.odd_one_out.found", g);
		const char *found = bsim_test_json_text_at(root, p, buf, sizeof buf);
		if (!any) {
			assert_string_equal(found, "none");
		} else if (candidates == 1) {
			assert_string_equal(found, "side");
			snprintf(p, sizeof p, "groups.%d.odd_one_out.side", g);
			assert_string_equal(bsim_test_json_text_at(root, p, buf, sizeof buf),
			                    sides3[odd]);
			odd_found++;
		} else {
			assert_string_equal(found, "no single side");
		}
	}
	assert_int_equal((int)bsim_test_json_at(root, "groups_disagreeing"), disagreeing);
	assert_int_equal(status, disagreeing > 0 ? 3 : 0);
	/* the side meant to differ is the odd one out somewhere: the rule is
	 * exercised, not only "none" */
	assert_true(odd_found > 0);
	bsim_ydoc_free(&d);
	char *json = read_in(dir, "report.json");
	assert_true(check_replays(json, 0) > 0);
	free(json);
	/* report.md names the odd ones out; regress reruns all three sides */
	char *md = read_in(dir, "report.md");
	assert_non_null(strstr(
	        md, "# beamsim compare: thesis vs box2d:continuous=off vs thesis:impact_mass=0.1"));
	assert_non_null(strstr(md, "**Odd one out:**"));
	free(md);
	const char *rerun = bsim_test_dir_held("cmp3_rerun");
	const char *r[] = {"regress", dir, "--exact", "--out", rerun, NULL};
	char *out = NULL;
	assert_int_equal(bsim_test_cli(r, &out, NULL), 0);
	for (int s = 0; s < N3; s++) {
		char want[200];
		snprintf(want, sizeof want, "%s: 0 of 48 trials changed", sides3[s]);
		assert_non_null(strstr(out, want));
	}
	free(out);
}

/* A side given twice, or more sides than the most, is refused. */
static void test_three_sides_bad(void **state)
{
	(void)state;
	char *err = NULL;
	const char *twice[] = {"compare",    experiment,
	                       "--backends", "thesis,box2d,thesis",
	                       "--out",      bsim_test_dir_held("bad3s"),
	                       NULL};
	assert_int_equal(bsim_test_cli(twice, NULL, &err), 2);
	assert_non_null(strstr(err, "side thesis is given twice"));
	free(err);
	const char *many[] = {"compare",
	                      experiment,
	                      "--backends",
	                      "thesis,box2d,thesis:slop=1e-5,thesis:slop=2e-5,"
	                      "thesis:slop=3e-5,thesis:slop=4e-5,thesis:slop=5e-5,"
	                      "thesis:slop=6e-5,thesis:slop=7e-5",
	                      "--out",
	                      bsim_test_dir_held("bad9"),
	                      NULL};
	assert_int_equal(bsim_test_cli(many, NULL, &err), 2);
	assert_non_null(strstr(err, "expected 2 to 8 sides"));
	free(err);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_halves_are_sweeps),
	        cmocka_unit_test(test_every_backend_a_side),
	        cmocka_unit_test(test_status_and_threads),
	        cmocka_unit_test(test_compare_replays),
	        cmocka_unit_test(test_regress_identical),
	        cmocka_unit_test(test_regress_catches_changes),
	        cmocka_unit_test(test_regress_exact),
	        cmocka_unit_test(test_one_backend_two_settings),
	        cmocka_unit_test(test_report_deterministic),
	        cmocka_unit_test(test_unstable_event),
	        cmocka_unit_test(test_regress_old_format),
	        cmocka_unit_test(test_bad_usage),
	        cmocka_unit_test(test_three_sides),
	        cmocka_unit_test(test_three_sides_bad),
	};
	return cmocka_run_group_tests(tests, setup, NULL);
}
