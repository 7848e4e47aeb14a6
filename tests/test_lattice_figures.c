/* beamsim plot of a gate lattice (docs/figures.md "A gate lattice").
 *
 * Truths, recomputed here from the run's own files and the scene's inputs,
 * independently of the figure code: the final-location distribution from
 * the location column of trials.csv (and pairs.csv for a comparison), a
 * side exit's side from the sign of x_end (the C-track's field is centred
 * on X = 0), Wilson's interval in its closed form (Wilson 1927), and a
 * group without random force drawn as points; the stiffness map against
 * the C-track's own CSV (configs/lattice/c_track.csv) and the geometry of
 * Eq. 2.17 (gate (ix, iy) spans X in [50 ix - 25, 50 ix + 25), Y in
 * [60 iy, 60 iy + 60), its beams hang at Y = 60 iy + 30); the drawn paths
 * are rows of trajectories.csv in order, split by whether their trial
 * reached the end. Every figure is PNG + SVG + script + data under 1 MB;
 * a malformed lattice file is named with its line, exit 2, no figure. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "util/figure.h"
#include "support.h"

/* ---- helpers ---------------------------------------------------------------------------- */

static int run_cli(const char *const *argv, char **out, char **err)
{
	char *o_own = NULL, *e_own = NULL;
	char **o = out ? out : &o_own, **e = err ? err : &e_own;
	int rc = bsim_test_cli(argv, o, e);
	if (rc != 0 && rc != 3 && rc != 2)
		print_error("%s\n%s\n", *o ? *o : "", *e ? *e : "");
	free(o_own);
	free(e_own);
	return rc;
}

/* ---- a CSV file by column name ---------------------------------------------------------- */

typedef struct table {
	char *text;
	int n_cols, n_rows;
	char *names[400];
	char **cell; /* n_rows x n_cols */
} table;

static void table_read(const char *path, table *t)
{
	memset(t, 0, sizeof *t);
	t->text = bsim_test_read(path);
	assert_non_null(t->text);
	int lines = 0;
	for (char *p = t->text; *p; p++)
		lines += *p == '\n';
	char *save = NULL, *line = strtok_r(t->text, "\n", &save);
	assert_non_null(line);
	for (char *c = line;; c++) {
		char *comma = strchr(c, ',');
		t->names[t->n_cols++] = c;
		if (!comma)
			break;
		*comma = '\0';
		c = comma;
	}
	t->cell = calloc((size_t)lines * (size_t)t->n_cols + 1, sizeof *t->cell);
	while ((line = strtok_r(NULL, "\n", &save))) {
		/* split keeping empty fields */
		int k = 0;
		char *f = line;
		for (;;) {
			char *comma = strchr(f, ',');
			if (k < t->n_cols)
				t->cell[(size_t)t->n_rows * (size_t)t->n_cols + (size_t)k] = f;
			k++;
			if (!comma)
				break;
			*comma = '\0';
			f = comma + 1;
		}
		assert_int_equal(k, t->n_cols);
		t->n_rows++;
	}
}

static int table_col(const table *t, const char *name)
{
	for (int i = 0; i < t->n_cols; i++)
		if (strcmp(t->names[i], name) == 0)
			return i;
	print_error("no column %s\n", name);
	fail();
	return -1;
}

static const char *table_cell(const table *t, int r, int c)
{
	return t->cell[(size_t)r * (size_t)t->n_cols + (size_t)c];
}

static void table_free(table *t)
{
	free(t->cell);
	free(t->text);
}

/* ---- final locations recounted ------------------------------------------------------------ */

enum { COLS = 9, ROWS = 9, IX_MIN = -4 };

typedef struct counts {
	int n;
	int end[COLS];
	int side[2][ROWS];
	int stuck[ROWS][COLS];
} counts;

/* Counts group g of a trials.csv by its location column, the side of a
 * side exit by the sign of x_end. */
static void count_trials(const char *path, int g, counts *c)
{
	memset(c, 0, sizeof *c);
	table t;
	table_read(path, &t);
	const int cg = table_col(&t, "group"), cl = table_col(&t, "location"),
	          cx = table_col(&t, "x_end");
	for (int r = 0; r < t.n_rows; r++) {
		if (atoi(table_cell(&t, r, cg)) != g)
			continue;
		const char *loc = table_cell(&t, r, cl);
		int ix, iy;
		c->n++;
		if (sscanf(loc, "end:%d", &ix) == 1) {
			c->end[ix - IX_MIN]++;
		} else if (sscanf(loc, "side:%d", &iy) == 1) {
			c->side[atof(table_cell(&t, r, cx)) < 0.0 ? 0 : 1][iy]++;
		} else {
			assert_int_equal(sscanf(loc, "stuck:%d:%d", &ix, &iy), 2);
			c->stuck[iy][ix - IX_MIN]++;
		}
	}
	table_free(&t);
}

static void check_fraction(const double *row, int k, int n, int point)
{
	double lo, hi;
	bsim_test_wilson(k, n, &lo, &hi);
	if (point)
		lo = hi = (double)k / n;
	assert_true(fabs(row[0] - (double)k / n) < 1e-6);
	assert_true(fabs(row[1] - lo) < 1e-5 && fabs(row[2] - hi) < 1e-5);
}

/* Blocks b0 .. b0 + 2 of a final_locations_gNNN.dat against the counts. */
static void check_locations(const char *path, int b0, const counts *c, int point)
{
	static double rows[128][16];
	int total = 0;
	assert_int_equal(bsim_test_data_rows(path, b0, rows, 128), COLS);
	for (int i = 0; i < COLS; i++) {
		assert_int_equal((int)rows[i][0], IX_MIN + i);
		assert_int_equal((int)rows[i][4], c->end[i]);
		check_fraction(&rows[i][1], c->end[i], c->n, point);
		total += c->end[i];
	}
	assert_int_equal(bsim_test_data_rows(path, b0 + 1, rows, 128), ROWS);
	for (int i = 0; i < ROWS; i++) {
		assert_int_equal((int)rows[i][0], i);
		for (int s = 0; s < 2; s++) {
			assert_int_equal((int)rows[i][4 + 4 * s], c->side[s][i]);
			check_fraction(&rows[i][1 + 4 * s], c->side[s][i], c->n, point);
			total += c->side[s][i];
		}
	}
	assert_int_equal(bsim_test_data_rows(path, b0 + 2, rows, 128), ROWS * COLS);
	for (int i = 0; i < ROWS * COLS; i++) {
		int ix = (int)rows[i][0], iy = (int)rows[i][1];
		assert_true(ix >= IX_MIN && ix < IX_MIN + COLS && iy >= 0 && iy < ROWS);
		int k = c->stuck[iy][ix - IX_MIN];
		assert_int_equal((int)rows[i][5], k);
		check_fraction(&rows[i][2], k, c->n, point);
		total += k;
	}
	/* every trial has exactly one final location */
	assert_int_equal(total, c->n);
}

/* ---- a lattice sweep ------------------------------------------------------------------------ */

/* The C-track at F_prop = 6 N with Rm = 0 (group 0: deterministic, one
 * trial run and copied) and the essay's Rm = 30 N (group 1), 20 trials,
 * 20 kept trajectories each, plotted. */
static const char *lattice_sweep(void)
{
	static char dir[1024];
	if (dir[0])
		return dir;
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("sweep"));
	char yaml[2048], exp[1100];
	snprintf(yaml, sizeof yaml,
	         "scene: %s\ntrials: 20\nseed: 1\ngrid:\n"
	         "  effects.propulsion.force: [6]\n"
	         "  effects.random_force.magnitude: [0, 30]\n",
	         bsim_test_src("configs/lattice/c_track.yaml"));
	snprintf(exp, sizeof exp, "%s", bsim_test_write(dir, "c_track_two.yaml", yaml));
	const char *sweep[] = {"sweep", exp,       "--trajectories", "20", "--trajectory-stride",
	                       "25",    "--quiet", "--out",          dir,  NULL};
	assert_int_equal(run_cli(sweep, NULL, NULL), 0);
	char *out = NULL;
	const char *plot[] = {"plot", dir, NULL};
	assert_int_equal(run_cli(plot, &out, NULL), 0);
	assert_non_null(strstr(out, "final_locations_g001"));
	free(out);
	return dir;
}

static void test_sweep_figures(void **state)
{
	(void)state;
	const char *dir = lattice_sweep();
	/* p_traverse, traversal against Rm, and per group final_locations and
	 * lattice; not the single gate's bundle and landscape */
	assert_int_equal(bsim_test_check_figures(dir), 3 + 2 * 2);
	assert_true(bsim_test_exists(bsim_test_join(dir, "lattice_g001.png")) ||
	            !bsim_figure_available());
	assert_false(bsim_test_exists(bsim_test_join(dir, "trajectories_g000.gp")));
	assert_false(bsim_test_exists(bsim_test_join(dir, "landscape_g001.gp")));
}

static void test_final_locations(void **state)
{
	(void)state;
	const char *dir = lattice_sweep();
	char trials[1200], path[1200];
	snprintf(trials, sizeof trials, "%s/trials.csv", dir);
	for (int g = 0; g < 2; g++) {
		counts c;
		count_trials(trials, g, &c);
		assert_int_equal(c.n, 20);
		snprintf(path, sizeof path, "%s/final_locations_g%03d.dat", dir, g);
		check_locations(path, 0, &c, g == 0);
	}
	/* where the trials ended against Rm: end, side exit and stuck */
	static double rows[8][16];
	snprintf(path, sizeof path, "%s/traversal_vs_effects_random_force_magnitude.dat", dir);
	assert_int_equal(bsim_test_data_rows(path, 0, rows, 8), 2);
	for (int g = 0; g < 2; g++) {
		counts c;
		count_trials(trials, g, &c);
		int k[3] = {0, 0, 0};
		for (int i = 0; i < COLS; i++)
			k[0] += c.end[i];
		for (int i = 0; i < ROWS; i++)
			k[1] += c.side[0][i] + c.side[1][i];
		k[2] = c.n - k[0] - k[1];
		assert_true(rows[g][0] == 30.0 * g);
		for (int e = 0; e < 3; e++)
			check_fraction(&rows[g][1 + 3 * e], k[e], c.n, g == 0);
	}
	/* group 0 is one trial: all 20 rows end in the same place */
	counts c;
	count_trials(trials, 0, &c);
	int max = 0;
	for (int i = 0; i < ROWS * COLS; i++)
		max = c.stuck[i / COLS][i % COLS] > max ? c.stuck[i / COLS][i % COLS] : max;
	for (int i = 0; i < COLS; i++)
		max = c.end[i] > max ? c.end[i] : max;
	assert_int_equal(max, 20);
}

/* The map against c_track.csv and Eq. 2.17; the beams at rest. */
static void test_stiffness_map(void **state)
{
	(void)state;
	const char *dir = lattice_sweep();
	double k[ROWS][COLS];
	char *csv = bsim_test_read(bsim_test_src("configs/lattice/c_track.csv"));
	assert_non_null(csv);
	int iy = 0;
	char *save = NULL;
	for (char *l = strtok_r(csv, "\n", &save); l; l = strtok_r(NULL, "\n", &save)) {
		if (*l == '#' || !*l)
			continue;
		char *p = l;
		for (int ix = 0; ix < COLS; ix++) {
			k[iy][ix] = strtod(p, &p);
			p += *p == ',';
		}
		iy++;
	}
	free(csv);
	assert_int_equal(iy, ROWS);
	static double rows[400][16];
	char path[1200];
	snprintf(path, sizeof path, "%s/lattice_g001.dat", dir);
	int n = bsim_test_data_rows(path, 0, rows, 400);
	assert_int_equal(n, 2 * ROWS * COLS);
	int soft = 0;
	for (int i = 0; i < n; i++) {
		const double *r = rows[i];
		int ix = (int)r[5], y = (int)r[6], side = (int)r[7];
		assert_true(r[4] == k[y][ix - IX_MIN]);
		soft += r[4] < 400;
		assert_true(r[0] == 50.0 * ix - 25 + 25 * side && r[1] == r[0] + 25);
		assert_true(r[2] == 60.0 * y && r[3] == 60.0 * y + 60);
	}
	assert_int_equal(soft, 2 * 16); /* the C: 16 soft gates */
	n = bsim_test_data_rows(path, 1, rows, 400);
	assert_int_equal(n, 2 * ROWS * COLS);
	for (int i = 0; i < n; i++) {
		const double *r = rows[i];
		/* the beam reaches from its pivot on the gate's edge to the gate's
		 * centre line X = 50 ix */
		double gx = (r[0] + r[2]) / 50.0;
		assert_true(fabs(gx - round(gx)) < 1e-12);
		assert_true(fmod(r[1] - 30.0, 60.0) == 0.0 && r[3] == 0.0 && fabs(r[2]) == 25.0);
	}
}

/* "# group G trial T" headers of a block of the figure's data, in order. */
static int path_headers(const char *path, int block, int (*gt)[2], int max)
{
	char *text = bsim_test_read(path);
	assert_non_null(text);
	int b = 0, n = 0;
	for (char *p = text; *p;) {
		char *nl = strchr(p, '\n');
		if (!nl)
			nl = p + strlen(p);
		if (nl == p) {
			if (nl[1] == '\n')
				b++, p = nl + 2;
			else
				p = nl + 1;
			continue;
		}
		int g, t;
		if (b == block && n < max && sscanf(p, "# group %d trial %d", &g, &t) == 2) {
			gt[n][0] = g;
			gt[n][1] = t;
			n++;
		}
		p = *nl ? nl + 1 : nl;
	}
	free(text);
	return n;
}

/* The paths: blue those whose trial reached the end, red the rest, every
 * point a row of trajectories.csv in order, the first and last included. */
static void test_paths(void **state)
{
	(void)state;
	const char *dir = lattice_sweep();
	char path[1200], fig[1200];
	snprintf(path, sizeof path, "%s/trials.csv", dir);
	table t;
	table_read(path, &t);
	int reached[20] = {0};
	const int cg = table_col(&t, "group"), ct = table_col(&t, "trial"),
	          cl = table_col(&t, "location");
	for (int r = 0; r < t.n_rows; r++)
		if (atoi(table_cell(&t, r, cg)) == 1)
			reached[atoi(table_cell(&t, r, ct))] =
			        strncmp(table_cell(&t, r, cl), "end:", 4) == 0;
	table_free(&t);
	snprintf(fig, sizeof fig, "%s/lattice_g001.dat", dir);
	int gt[2][40][2], n[2];
	for (int b = 0; b < 2; b++) {
		n[b] = path_headers(fig, 2 + b, gt[b], 40);
		for (int i = 0; i < n[b]; i++) {
			assert_int_equal(gt[b][i][0], 1);
			assert_int_equal(reached[gt[b][i][1]], b == 0);
		}
	}
	assert_int_equal(n[0] + n[1], 20);

	/* the drawn points of block 3 are rows of their trials, in order */
	snprintf(path, sizeof path, "%s/trajectories.csv", dir);
	table tr;
	table_read(path, &tr);
	const int tg = table_col(&tr, "group"), tt = table_col(&tr, "trial"),
	          tx = table_col(&tr, "x"), ty = table_col(&tr, "y");
	static double rows[50000][16];
	int nr = bsim_test_data_rows(fig, 3, rows, 50000), k = 0, first = 1;
	long recorded = 0;
	double last[2] = {NAN, NAN};
	for (int i = 0; i < n[1]; i++) {
		int trial = gt[1][i][1];
		first = 1;
		for (int r = 0; r < tr.n_rows; r++) {
			if (atoi(table_cell(&tr, r, tg)) != 1 ||
			    atoi(table_cell(&tr, r, tt)) != trial)
				continue;
			recorded++;
			double x = atof(table_cell(&tr, r, tx)), y = atof(table_cell(&tr, r, ty));
			last[0] = x;
			last[1] = y;
			if (k < nr && fabs(rows[k][0] - x) < 1e-9 * fmax(1, fabs(x)) &&
			    fabs(rows[k][1] - y) < 1e-9 * fmax(1, fabs(y))) {
				k++;
				first = 0;
			} else {
				assert_false(first); /* the first row is always drawn */
			}
		}
		/* and the last */
		assert_true(rows[k - 1][0] == last[0] && rows[k - 1][1] == last[1]);
	}
	table_free(&tr);
	assert_int_equal(k, nr);
	assert_true(nr > 100 && nr <= recorded);
}

/* ---- a comparison of the two protocols --------------------------------------------------- */

static void test_compare(void **state)
{
	(void)state;
	char dir[1024];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("compare"));
	const char *cmp[] = {"compare",     bsim_test_src("configs/lattice/c_track_essay.yaml"),
	                     "--protocols", "world,essay",
	                     "--quiet",     "--out",
	                     dir,           NULL};
	int rc = run_cli(cmp, NULL, NULL);
	assert_true(rc == 0 || rc == 3);
	char *out = NULL;
	const char *plot[] = {"plot", dir, NULL};
	assert_int_equal(run_cli(plot, &out, NULL), 0);
	free(out);
	assert_int_equal(bsim_test_check_figures(dir), 2); /* compare and final_locations_g000 */
	char sub[1100], path[1200], pairs[1200];
	snprintf(pairs, sizeof pairs, "%s/pairs.csv", dir);
	snprintf(path, sizeof path, "%s/final_locations_g000.dat", dir);
	for (int s = 0; s < 2; s++) {
		snprintf(sub, sizeof sub, "%s/%s", dir, s ? "essay" : "world");
		assert_int_equal(bsim_test_check_figures(sub),
		                 4); /* p_traverse, survival, final_locations, lattice */
		char trials[1200];
		snprintf(trials, sizeof trials, "%s/trials.csv", sub);
		counts c;
		count_trials(trials, 0, &c);
		check_locations(path, 3 * s, &c, 0);
		/* pairs.csv's locations agree on the ends and stuck gates */
		table p;
		table_read(pairs, &p);
		const int cl = table_col(&p, s ? "location_b" : "location_a");
		int ends = 0, stuck = 0, end_c = 0, stuck_c = 0;
		for (int r = 0; r < p.n_rows; r++) {
			ends += strncmp(table_cell(&p, r, cl), "end:", 4) == 0;
			stuck += strncmp(table_cell(&p, r, cl), "stuck:", 6) == 0;
		}
		table_free(&p);
		for (int i = 0; i < COLS * ROWS; i++)
			stuck_c += c.stuck[i / COLS][i % COLS];
		for (int i = 0; i < COLS; i++)
			end_c += c.end[i];
		assert_int_equal(ends, end_c);
		assert_int_equal(stuck, stuck_c);
	}
	/* the title quotes the report's permutation test */
	snprintf(path, sizeof path, "%s/final_locations_g000.gp", dir);
	char *gp = bsim_test_read(path);
	snprintf(path, sizeof path, "%s/report.json", dir);
	char *report = bsim_test_read(path);
	assert_non_null(gp);
	assert_non_null(report);
	const char *fl = strstr(report, "\"final_locations\"");
	assert_non_null(fl);
	const char *pp = strstr(fl, "\"p\":");
	assert_non_null(pp);
	char want[64];
	snprintf(want, sizeof want, "test: p = %.3g ", strtod(pp + 4, NULL));
	assert_non_null(strstr(gp, want));
	assert_non_null(strstr(gp, "permutation"));
	free(gp);
	free(report);
}

/* ---- bad input -------------------------------------------------------------------------- */

/* Appends text to dir/file and removes the manifest, which plot checks
 * first: without one, the file itself is read and checked. */
static void spoil(const char *dir, const char *file, const char *text)
{
	char path[1200];
	snprintf(path, sizeof path, "%s/%s", dir, file);
	FILE *f = fopen(path, "a");
	assert_non_null(f);
	fputs(text, f);
	fclose(f);
	snprintf(path, sizeof path, "%s/manifest.json", dir);
	remove(path);
}

static int file_lines(const char *dir, const char *file)
{
	char path[1200];
	snprintf(path, sizeof path, "%s/%s", dir, file);
	char *t = bsim_test_read(path);
	int n = 0;
	for (char *p = t; p && *p; p++)
		n += *p == '\n';
	free(t);
	return n;
}

static void test_bad_input(void **state)
{
	(void)state;
	static const struct {
		const char *file, *line, *loc, *want;
	} cases[] = {
	        {"trials.csv", NULL, "stuck:7:0", "location: expected end:IX, side:IY"},
	        {"lattice_map.csv", "0,2,3,75,125,180,240,210,400,400\n", NULL, "group 0 twice"},
	        /* 2^32: sscanf's %d once read it as gate ix 0 */
	        {"trials.csv", NULL, "stuck:4294967296:0", "location: expected end:IX, side:IY"},
	};
	static const char *const dirs[] = {"bad_trials", "bad_map", "bad_trials_2p32"};
	for (int i = 0; i < 3; i++) {
		char dir[1024];
		snprintf(dir, sizeof dir, "%s", bsim_test_dir(dirs[i]));
		const char *sweep[] = {
		        "sweep",    bsim_test_src("configs/lattice/c_track_essay.yaml"),
		        "--trials", "2",
		        "--quiet",  "--out",
		        dir,        NULL};
		assert_int_equal(run_cli(sweep, NULL, NULL), 0);
		int line = file_lines(dir, cases[i].file) + 1;
		if (cases[i].line) {
			spoil(dir, cases[i].file, cases[i].line);
		} else { /* a trial whose location lies outside the field */
			char path[1200];
			snprintf(path, sizeof path, "%s/trials.csv", dir);
			char *text = bsim_test_read(path);
			char *last = strrchr(text, '\n');
			*last = '\0';
			last = strrchr(text, '\n') + 1;
			char *loc = strstr(last, ",end:");
			if (!loc)
				loc = strstr(last, ",side:");
			if (!loc)
				loc = strstr(last, ",stuck:");
			assert_non_null(loc);
			char *rest = strchr(loc + 1, ',');
			char edited[8192];
			snprintf(edited, sizeof edited, "%.*s,%s%s\n", (int)(loc - text), text,
			         cases[i].loc, rest);
			FILE *f = fopen(path, "w");
			fputs(edited, f);
			fclose(f);
			free(text);
			line -= 1;
			spoil(dir, "trials.csv", "");
		}
		char *err = NULL;
		const char *plot[] = {"plot", dir, NULL};
		assert_int_equal(run_cli(plot, NULL, &err), 2);
		char where[64];
		snprintf(where, sizeof where, "%s:%d:", cases[i].file, line);
		if (!strstr(err, where) || !strstr(err, cases[i].want))
			print_error("%s\n", err);
		assert_non_null(strstr(err, where));
		assert_non_null(strstr(err, cases[i].want));
		free(err);
		assert_false(bsim_test_exists(bsim_test_join(dir, "p_traverse.gp")));
		assert_false(bsim_test_exists(bsim_test_join(dir, "final_locations_g000.gp")));
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_sweep_figures), cmocka_unit_test(test_final_locations),
	        cmocka_unit_test(test_stiffness_map), cmocka_unit_test(test_paths),
	        cmocka_unit_test(test_compare),       cmocka_unit_test(test_bad_input),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
