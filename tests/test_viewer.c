/* The trajectory player of index.html (store/viewer_data.h, src/store/viewer.js).
 *
 * Truths: the directory's own trajectory files, read here with a parser of
 * this test's, and the scene's numbers (pivots, rest angles, lengths, the
 * body's radius, F_prop and R_m as the scene and experiment files give
 * them). A real browser (headless chromium) loads index.html#frame=I,K;
 * the player draws that frame and writes what it drew into
 * <pre id="beamsim-viewer-result">, which the dumped DOM holds. The body
 * it drew must sit at the file row's x, y, each beam's tip where the row's
 * theta puts it (tip = pivot + L (cos a, sin a), a = rest + sign theta, the
 * sign +1 for a beam pointing right at rest), a contact marker for every
 * nonzero contact flag, the random force's arrow f_rand long (one body
 * radius per max(F_prop, R_m)), all through the world-to-canvas map it
 * reports (px = ox + s x, py = oy - s y); frame K the row K every of the
 * trajectory (every k-th row and the last, at most 2000 frames), its time
 * the row's. The page writes nothing to its console and counts no error
 * (data-errors="0"); a page without its data counts one, so the count is
 * read, not assumed. */
#define _DEFAULT_SOURCE /* M_PI */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <libfyaml.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"
#include "util/yaml_doc.h"

/* ---- this test's own reading of a trajectories file --------------------------------- */

typedef struct table {
	int n_cols;
	long n_rows;
	char names[64][32];
	double *v; /* n_rows * n_cols, NAN where a cell is no number */
} table;

static table table_read(const char *path)
{
	table t = {0};
	char *text = bsim_test_read(path);
	if (!text)
		fail_msg("%s: cannot be read", path);
	char *line = strtok(text, "\n");
	assert_non_null(line);
	for (char *p = line; t.n_cols < 64;) {
		size_t n = strcspn(p, ",");
		snprintf(t.names[t.n_cols++], sizeof t.names[0], "%.*s", (int)n, p);
		if (!p[n])
			break;
		p += n + 1;
	}
	long cap = 1024;
	t.v = malloc((size_t)cap * (size_t)t.n_cols * sizeof *t.v);
	while ((line = strtok(NULL, "\n")) != NULL) {
		if (t.n_rows == cap) {
			cap *= 2;
			t.v = realloc(t.v, (size_t)cap * (size_t)t.n_cols * sizeof *t.v);
		}
		assert_non_null(t.v);
		char *p = line;
		for (int c = 0; c < t.n_cols; c++) {
			char *end;
			double x = strtod(p, &end);
			t.v[t.n_rows * t.n_cols + c] = end == p ? NAN : x;
			p = strchr(p, ',');
			if (c + 1 < t.n_cols)
				assert_non_null(p);
			p = p ? p + 1 : p;
		}
		t.n_rows++;
	}
	free(text);
	return t;
}

static int table_col(const table *t, const char *name)
{
	for (int c = 0; c < t->n_cols; c++)
		if (strcmp(t->names[c], name) == 0)
			return c;
	return -1;
}

static double cell(const table *t, long row, const char *name)
{
	int c = table_col(t, name);
	if (c < 0)
		fail_msg("no column %s", name);
	assert_true(row >= 0 && row < t->n_rows);
	return t->v[row * t->n_cols + c];
}

/* The rows of (group, trial): first and count (a run's file is all one). */
static void rows_of(const table *t, long g, long tr, long *first, long *n)
{
	*first = -1;
	*n = 0;
	int cg = table_col(t, "group"), ct = table_col(t, "trial");
	for (long r = 0; r < t->n_rows; r++) {
		if (cg >= 0 && (t->v[r * t->n_cols + cg] != g || t->v[r * t->n_cols + ct] != tr))
			continue;
		if (*first < 0)
			*first = r;
		(*n)++;
	}
	assert_true(*n > 0);
}

/* ---- the scene, as its file gives it ----------------------------------------------- */

typedef struct truth {
	double pivot[2][2], length[2], rest_deg[2];
	double extent; /* the body's farthest point from its centre, m */
	double f_prop, rm;
} truth;

/* configs/thesis/gate.yaml (essay Table 2.1): beams at (-25, 30) and
 * (25, 30), 25 m, at rest along +x and -x; a disk of 10 m. */
static truth gate(double f_prop, double rm)
{
	truth s = {{{-25, 30}, {25, 30}}, {25, 25}, {0, 180}, 10, f_prop, rm};
	return s;
}

/* ---- the page ---------------------------------------------------------------------- */

/* index.html#frame=I,K of dir in chromium: the player's result as a
 * document (free with fy_document_destroy), with the checks every load
 * passes: drawn, no error counted, nothing on the console. */
static struct fy_document *load_frame(const char *dir, int trial, long k)
{
	char url[1300];
	snprintf(url, sizeof url, "file://%s/index.html#frame=%d,%ld", dir, trial, k);
	char *console = NULL;
	char *dom = bsim_test_browser_dom(url, &console);
	if (*console)
		fail_msg("%s wrote to its console:\n%s", url, console);
	if (!strstr(dom, "id=\"beamsim-viewer\" data-state=\"drawn\" data-errors=\"0\""))
		fail_msg("%s: the player did not draw without error:\n%.600s", url,
		         strstr(dom, "beamsim-viewer") ? strstr(dom, "beamsim-viewer") : dom);
	const char *open = strstr(dom, "<pre id=\"beamsim-viewer-result\" hidden=\"\">");
	assert_non_null(open);
	open = strchr(open, '>') + 1;
	const char *close = strstr(open, "</pre>");
	assert_non_null(close);
	/* the DOM's text escapes &, < and > */
	char *json = malloc((size_t)(close - open) + 1);
	size_t n = 0;
	for (const char *p = open; p < close; p++) {
		static const struct {
			const char *entity;
			char c;
		} ents[] = {{"&amp;", '&'}, {"&lt;", '<'}, {"&gt;", '>'}};
		int hit = 0;
		for (int e = 0; e < 3 && !hit; e++)
			if (strncmp(p, ents[e].entity, strlen(ents[e].entity)) == 0) {
				json[n++] = ents[e].c;
				p += strlen(ents[e].entity) - 1;
				hit = 1;
			}
		if (!hit)
			json[n++] = *p;
	}
	json[n] = '\0';
	/* the document owns json from here, and frees it */
	struct fy_document *d = fy_document_build_from_malloc_string(NULL, json, n);
	if (!d)
		fail_msg("%s: the player's result is no JSON", url);
	free(console);
	free(dom);
	return d;
}

static double at(struct fy_document *d, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static double at(struct fy_document *d, const char *fmt, ...)
{
	char path[200];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(path, sizeof path, fmt, ap);
	va_end(ap);
	return bsim_test_json_at(fy_document_root(d), path);
}

static int is_null(struct fy_document *d, const char *path)
{
	char buf[32];
	return strcmp(bsim_test_json_text_at(fy_document_root(d), path, buf, sizeof buf), "null") ==
	       0;
}

static void near(double got, double want, double tol, const char *what, long row)
{
	if (!(fabs(got - want) <= tol))
		fail_msg("%s at row %ld: drew %.9g, the file gives %.9g", what, row, got, want);
}

/* Panel p of the result against row r of its file t (the trajectory of
 * group g, trial tr), in scene sc. */
static void check_panel(struct fy_document *d, int p, const table *t, long r, long g, long tr,
                        const truth *sc)
{
	const double s = at(d, "scale"), ox = at(d, "ox"), oy = at(d, "oy");
	const double tol = 1e-6; /* px */
	assert_true(s > 0);
	assert_int_equal((long)at(d, "panels.%d.row", p), r);
	if (table_col(t, "group") >= 0) {
		assert_int_equal((long)cell(t, r, "group"), g);
		assert_int_equal((long)cell(t, r, "trial"), tr);
	}
	near(at(d, "panels.%d.t", p), cell(t, r, "t"), 1e-12, "t", r);
	const double x = cell(t, r, "x"), y = cell(t, r, "y");
	near(at(d, "panels.%d.body.0", p), ox + s * x, tol, "the body's px", r);
	near(at(d, "panels.%d.body.1", p), oy - s * y, tol, "the body's py", r);
	/* the beams: each tip where theta puts it */
	assert_int_equal((long)at(d, "panels.%d.beams", p), 2);
	int contacts = 0;
	for (int i = 0; i < 2; i++) {
		char name[16];
		snprintf(name, sizeof name, "theta%d", i + 1);
		const double a0 = sc->rest_deg[i] * M_PI / 180.0, sign = cos(a0) > 0 ? 1.0 : -1.0;
		const double a = a0 + sign * cell(t, r, name);
		const double tip[2] = {sc->pivot[i][0] + sc->length[i] * cos(a),
		                       sc->pivot[i][1] + sc->length[i] * sin(a)};
		near(at(d, "panels.%d.tips.%d.0", p, i), ox + s * tip[0], tol, name, r);
		near(at(d, "panels.%d.tips.%d.1", p, i), oy - s * tip[1], tol, name, r);
		snprintf(name, sizeof name, "contact%d", i + 1);
		const double flag = cell(t, r, name);
		if (flag != 0) {
			/* the marker of this beam, with its flag */
			assert_int_equal((long)at(d, "panels.%d.contacts.%d.3", p, contacts),
			                 i + 1);
			near(at(d, "panels.%d.contacts.%d.2", p, contacts), flag, 0, name, r);
			contacts++;
		}
	}
	char path[64];
	snprintf(path, sizeof path, "panels.%d.contacts.%d", p, contacts);
	if (bsim_ydoc_lookup(fy_document_root(d), path))
		fail_msg("row %ld: more contact markers drawn than the %d contact flags set", r,
		         contacts);
	if (table_col(t, "heading") >= 0)
		near(at(d, "panels.%d.heading", p), cell(t, r, "heading"), 1e-12, "the heading", r);
	/* the forces: one body extent per max(F_prop, R_m) */
	const double per_n = sc->extent * s / fmax(sc->f_prop, sc->rm);
	near(at(d, "panels.%d.propulsion.0", p), 0.0, 1e-9, "the propulsive arrow's x", r);
	near(at(d, "panels.%d.propulsion.1", p), -per_n * sc->f_prop, tol,
	     "the propulsive arrow's y", r);
	snprintf(path, sizeof path, "panels.%d.lateral", p);
	if (table_col(t, "f_rand") >= 0) {
		near(at(d, "panels.%d.lateral.0", p), per_n * cell(t, r, "f_rand"), tol,
		     "the random force's arrow", r);
		near(at(d, "panels.%d.lateral.1", p), 0.0, 0.0, "the random force's arrow's y", r);
	} else if (!is_null(d, path)) {
		fail_msg("a random force drawn, but the file records none");
	}
}

/* The rows a trajectory of n rows is played at: every k-th row and the
 * last, at most 2000 frames (docs/figures.md); k here. */
static long frame_step(long n)
{
	const long cap = 2000;
	return n <= cap ? 1 : (n - 1 + cap - 3) / (cap - 2);
}

/* The row frame k plays of a trajectory of n rows from first. */
static long row_of_frame(long first, long n, long k)
{
	const long cap = 2000, every = frame_step(n);
	const long frames = (n - 1) / every + 1 + ((n - 1) % every != 0);
	assert_true(frames <= cap);
	return k >= frames - 1 ? first + n - 1 : first + k * every;
}

/* ---- the tests --------------------------------------------------------------------- */

/* A run's page plays its trajectory.csv: a row every 4 ms over 8.8 s, more
 * than the 2000 frames, so every second row. */
static void test_run(void **state)
{
	(void)state;
	char dir[1024];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("viewer_run"));
	const char *run[] = {"run",     bsim_test_src("configs/thesis/gate.yaml"),
	                     "--seed",  "3",
	                     "--trial", "2",
	                     "--out",   dir,
	                     NULL};
	assert_int_equal(bsim_test_cli(run, NULL, NULL), 0);
	const char *const files[] = {"index.html", "viewer_data.js", "viewer.js", NULL};
	bsim_test_check_committed(dir, files, NULL);
	table t = table_read(bsim_test_join(dir, "trajectory.csv"));
	assert_true(t.n_rows > 2000); /* the cap applies */
	const truth sc = gate(7, 20);
	const long ks[] = {0, 357, 1000000};
	for (int i = 0; i < 3; i++) {
		struct fy_document *d = load_frame(dir, 0, ks[i]);
		long want = row_of_frame(0, t.n_rows, ks[i]);
		check_panel(d, 0, &t, want, 0, 2, &sc);
		assert_int_equal((long)at(d, "group"), 0);
		assert_int_equal((long)at(d, "trial_in_group"), 2);
		fy_document_destroy(d);
	}
	/* a row with the beams in contact is drawn with its markers */
	const long every = frame_step(t.n_rows);
	assert_int_equal(every, 2);
	long touching = -1;
	for (long r = 0; r < t.n_rows && touching < 0; r += every)
		if (cell(&t, r, "contact1") != 0 || cell(&t, r, "contact2") != 0)
			touching = r;
	assert_true(touching >= 0);
	struct fy_document *d = load_frame(dir, 0, touching / every);
	check_panel(d, 0, &t, touching, 0, 2, &sc);
	fy_document_destroy(d);
	free(t.v);
}

/* A body that turns is drawn at the heading its row records:
 * configs/shape/gate_capsule.yaml, the gate's beams, a capsule of
 * half-width 6 m and segment 16.755 m, F_prop 7 N, R_m 20 N. */
static void test_turning_body(void **state)
{
	(void)state;
	char dir[1024];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("viewer_capsule"));
	const char *run[] = {"run", bsim_test_src("configs/shape/gate_capsule.yaml"), "--out", dir,
	                     NULL};
	assert_int_equal(bsim_test_cli(run, NULL, NULL), 0);
	table t = table_read(bsim_test_join(dir, "trajectory.csv"));
	truth sc = gate(7, 20);
	sc.extent = 6 + 16.755 / 2;
	/* the row (of those played) where it has turned farthest */
	const long every = frame_step(t.n_rows);
	long far = 0;
	for (long r = 0; r < t.n_rows; r += every)
		if (fabs(cell(&t, r, "heading") - M_PI / 2) >
		    fabs(cell(&t, far, "heading") - M_PI / 2))
			far = r;
	assert_true(fabs(cell(&t, far, "heading") - M_PI / 2) > 0.1);
	struct fy_document *d = load_frame(dir, 0, far / every);
	check_panel(d, 0, &t, far, 0, 0, &sc);
	fy_document_destroy(d);
	free(t.v);
}

/* A sweep's page plays each kept trajectory; after plot, over the
 * landscape of its group where the figure's surface is in the directory. */
static void test_sweep(void **state)
{
	(void)state;
	char dir[1024], exp[1100];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("viewer_sweep"));
	snprintf(exp, sizeof exp, "%s", bsim_test_gate_experiment(bsim_test_dir("viewer_inputs")));
	const char *sweep[] = {"sweep", exp, "--trajectories", "2", "--quiet", "--out", dir, NULL};
	assert_int_equal(bsim_test_cli(sweep, NULL, NULL), 0);
	table t = table_read(bsim_test_join(dir, "trajectories.csv"));
	/* the trials in the file's order: (0, 0), (0, 1), (1, 0), (1, 1) */
	for (int plotted = 0; plotted < 2; plotted++) {
		for (int i = 0; i < 4; i++) {
			const long g = i / 2, tr = i % 2;
			long first, n;
			rows_of(&t, g, tr, &first, &n);
			const truth sc = gate(9, g == 0 ? 0 : 30);
			const long k = plotted ? n - 1 : n / 2;
			struct fy_document *d = load_frame(dir, i, k);
			assert_int_equal((long)at(d, "group"), g);
			assert_int_equal((long)at(d, "trial_in_group"), tr);
			check_panel(d, 0, &t, row_of_frame(first, n, k), g, tr, &sc);
			char surface[64];
			snprintf(surface, sizeof surface, "landscape_g%03ld.surface.dat", g);
			const int has = bsim_test_exists(bsim_test_join(dir, surface));
			char drawn[32];
			bsim_test_json_text_at(fy_document_root(d), "panels.0.landscape", drawn,
			                       sizeof drawn);
			assert_string_equal(drawn, has ? "true" : "false");
			assert_int_equal(has, plotted);
			fy_document_destroy(d);
		}
		const char *plot[] = {"plot", dir, "--quiet", NULL};
		if (!plotted)
			assert_int_equal(bsim_test_cli(plot, NULL, NULL), 0);
	}
	free(t.v);
	/* a sweep that keeps no trajectory and has no figure has no page */
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("viewer_sweep_none"));
	const char *none[] = {"sweep", exp, "--quiet", "--out", dir, NULL};
	assert_int_equal(bsim_test_cli(none, NULL, NULL), 0);
	assert_false(bsim_test_exists(bsim_test_join(dir, "index.html")));
	assert_false(bsim_test_exists(bsim_test_join(dir, "viewer_data.js")));
}

/* A comparison's page plays both sides side by side at one time: each
 * panel its own side's row, the last at or before the time shown. */
static void test_compare(void **state)
{
	(void)state;
	char dir[1024], exp[1100];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("viewer_compare"));
	snprintf(exp, sizeof exp, "%s", bsim_test_gate_experiment(bsim_test_dir("viewer_inputs2")));
	const char *cmp[] = {"compare", exp, "--trajectories", "2", "--quiet", "--out", dir, NULL};
	int rc = bsim_test_cli(cmp, NULL, NULL);
	assert_true(rc == 0 || rc == 3);
	const char *sides[] = {"thesis", "box2d"};
	table t[2];
	for (int s = 0; s < 2; s++) {
		char rel[64];
		snprintf(rel, sizeof rel, "%s/trajectories.csv", sides[s]);
		t[s] = table_read(bsim_test_join(dir, rel));
	}
	const long g = 1, tr = 1;
	const truth sc = gate(9, 30);
	long first[2], n[2];
	for (int s = 0; s < 2; s++)
		rows_of(&t[s], g, tr, &first[s], &n[s]);
	/* the time of frame k is the longer trajectory's row */
	const int m = n[1] > n[0];
	const long k = n[m] / 3;
	struct fy_document *d = load_frame(dir, 3, k);
	const double T = at(d, "t");
	near(T, cell(&t[m], row_of_frame(first[m], n[m], k), "t"), 1e-12, "the time shown", k);
	for (int s = 0; s < 2; s++) {
		char label[32];
		char path[32];
		snprintf(path, sizeof path, "panels.%d.side", s);
		bsim_test_json_text_at(fy_document_root(d), path, label, sizeof label);
		assert_string_equal(label, sides[s]);
		/* the last row at or before T */
		long r = first[s];
		while (r + 1 < first[s] + n[s] && cell(&t[s], r + 1, "t") <= T)
			r++;
		check_panel(d, s, &t[s], r, g, tr, &sc);
	}
	fy_document_destroy(d);
	for (int s = 0; s < 2; s++)
		free(t[s].v);
}

/* A page without its data counts the error and says so: the count the
 * other tests read is a real one. */
static void test_missing_data(void **state)
{
	(void)state;
	char dir[1024];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("viewer_missing"));
	const char *run[] = {"run", bsim_test_src("configs/thesis/gate.yaml"), "--out", dir, NULL};
	assert_int_equal(bsim_test_cli(run, NULL, NULL), 0);
	char page[1200];
	snprintf(page, sizeof page, "%s", bsim_test_join(dir, "viewer_data.js"));
	assert_int_equal(remove(page), 0);
	char url[1300];
	snprintf(url, sizeof url, "file://%s/index.html", dir);
	char *dom = bsim_test_browser_dom(url, NULL);
	assert_non_null(strstr(dom, "data-state=\"failed\" data-errors=\"2\""));
	assert_non_null(strstr(dom, "could not load file://"));
	free(dom);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_run),          cmocka_unit_test(test_turning_body),
	        cmocka_unit_test(test_sweep),        cmocka_unit_test(test_compare),
	        cmocka_unit_test(test_missing_data),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
