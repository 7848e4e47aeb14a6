/* beamsim plot (beamsim/figures.h).
 *
 * Truths: a figure's numbers are those of the run it draws, recomputed
 * here independently: p_traverse and Wilson's interval (Wilson 1927, the
 * closed form) from the outcomes in trials.csv, left / right fractions from
 * the types; E along a path is F_prop (y0 - y) + 1/2 k (theta1^2 +
 * theta2^2) of the recorded angles, and a state lies below the landscape
 * exactly when its beams' energy is short of docs/model.md section 7's
 * th(x, y), implemented here again, by more than 1 J; the random-force
 * histogram holds every draw the runner made once and integrates to 1;
 * the Pareto front of a hand-made accuracy table is the one worked out by
 * hand. Every figure is PNG + SVG + script + data, none over 1 MB, and
 * without gnuplot the scripts and data are still written and the message
 * names the package. */
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

#include "beamsim/key_names.h"
#include "util/figure.h"
#include "figures/figures_paths.h"
#include "support.h"
#include "store/index_html.h"

/* ---- helpers --------------------------------------------------------------------- */

static int run_cli(const char *const *argv, char **out, char **err)
{
	char *o_own = NULL, *e_own = NULL;
	char **o = out ? out : &o_own, **e = err ? err : &e_own;
	int rc = bsim_test_cli(argv, o, e);
	if (rc != 0 && rc != 3)
		print_error("%s\n%s\n", *o ? *o : "", *e ? *e : "");
	free(o_own);
	free(e_own);
	return rc;
}

/* ---- the landscape of docs/model.md section 7, written again ----------------------------- */

/* th of a beam with pivot (px, 30) pointing at the midline: the left one
 * (px < 0) points +x, the right one -x; phi measured from it, forward
 * (+y) positive. */
static double th_model(double px, double x, double y)
{
	const double L = 25, R = 10;
	double along = px < 0 ? x - px : px - x, fwd = y - 30;
	double rho = hypot(along, fwd), phi = atan2(fwd, along), th;
	if (rho >= L + R)
		return 0;
	if (rho * rho <= L * L + R * R)
		th = phi + (rho <= R ? 1.5707963267948966 : asin(R / rho));
	else
		th = phi + acos((rho * rho + L * L - R * R) / (2 * rho * L));
	return th > 0 ? th : 0;
}

/* ---- colours and titles of a landscape figure ---------------------------------------- */

/* Saturation of HSV, (max - min) / max of the channels: 0 grey, 1 pure. */
static double saturation(unsigned rgb)
{
	const double r = rgb >> 16 & 255, g = rgb >> 8 & 255, b = rgb & 255;
	const double hi = fmax(r, fmax(g, b)), lo = fmin(r, fmin(g, b));
	return hi > 0 ? (hi - lo) / hi : 0.0;
}

/* A landscape figure's script: a colour bar naming the potential energy,
 * its palette grey to blue-green (nothing in it saturated above 0.4), each
 * traversal's path in a colour saturated above 0.6 and none of the
 * palette's, and every needle in the figure's title. */
static void check_landscape_script(const char *gp, const char *const needles[])
{
	assert_non_null(strstr(gp, "set colorbox"));
	assert_non_null(strstr(gp, "set cblabel 'potential energy"));
	const char *p = strstr(gp, "set palette defined (");
	assert_non_null(p);
	unsigned pal[16];
	int np = 0;
	for (const char *h = strchr(p, '#'); h && h < strchr(p, ')') && np < 16;
	     h = strchr(h + 1, '#'))
		pal[np++] = (unsigned)strtoul(h + 1, NULL, 16);
	assert_true(np >= 2);
	for (int k = 0; k < np; k++)
		assert_true(saturation(pal[k]) < 0.4);
	int paths = 0;
	for (const char *t = strstr(gp, "title 'traversed"); t;
	     t = strstr(t + 1, "title 'traversed")) {
		const char *lc = t;
		while (lc > gp && strncmp(lc, "lc rgb '#", 9) != 0)
			lc--;
		unsigned c = (unsigned)strtoul(lc + 9, NULL, 16);
		assert_true(saturation(c) > 0.6);
		for (int k = 0; k < np; k++)
			assert_true(c != pal[k]);
		paths++;
	}
	assert_true(paths > 0);
	const char *title = strstr(gp, "set multiplot title ");
	assert_non_null(title);
	char t[800];
	snprintf(t, sizeof t, "%.*s", (int)strcspn(title, "\n"), title);
	for (int i = 0; needles[i]; i++)
		if (!strstr(t, needles[i]))
			fail_msg("'%s' not in the title %s", needles[i], t);
}

/* Rows of a landscape's NAME.surface.dat: x y E_total E_drawn. E_total
 * must be f(x, y) (the model, written here again); E_drawn is E_total cut
 * at one level, *cap. The count of rows. */
static int check_surface(const char *path, double (*f)(double x, double y), double *cap)
{
	FILE *in = fopen(path, "r");
	assert_non_null(in);
	char line[256];
	int n = 0, cut = 0;
	*cap = -INFINITY;
	while (fgets(line, sizeof line, in)) {
		if (line[0] == '#' || line[0] == '\n')
			continue;
		double x, y, e, d;
		assert_int_equal(sscanf(line, "%lf %lf %lf %lf", &x, &y, &e, &d), 4);
		const double want = f(x, y);
		assert_true(fabs(e - want) <= 1e-4 * fmax(1.0, fabs(want)));
		assert_true(d <= e);
		cut += d < e;
		*cap = fmax(*cap, d);
		n++;
	}
	fclose(in);
	assert_true(cut > 0); /* near the pivots */
	return n;
}

/* The 3-D surface NAME.mesh.dat: pm3d quadrangles (two scans of two
 * points, then a scan of NaN), every vertex a point of the landscape f at
 * or below the cap and outside the pivots' disks (rho >= R = 10 m about
 * (+-25, 30), less the sagitta of a polygon's chord of a disk, under 1 cm). A vertex within 1 mm of
 * a rim of reach (rho = L + R = 35 m) may carry the other side's value of the step, and one within
 * 1 mm of a pivot's disk lies where th's slope is infinite, as its coordinates are printed to 7
 * digits: those are left out. Vertices near the rims and the cap there are (the surface ends along
 * them, not a grid cell away). */
static void check_mesh(const char *path, double (*f)(double x, double y), double cap)
{
	FILE *in = fopen(path, "r");
	assert_non_null(in);
	char line[256];
	int n = 0, nan_rows = 0, near_rim = 0, near_cap = 0;
	while (fgets(line, sizeof line, in)) {
		if (line[0] == '#' || line[0] == '\n')
			continue;
		double x, y, e;
		assert_int_equal(sscanf(line, "%lf %lf %lf", &x, &y, &e), 3);
		if (isnan(e)) {
			nan_rows++;
			continue;
		}
		n++;
		const double r1 = hypot(x + 25, y - 30), r2 = hypot(x - 25, y - 30);
		/* a vertex on a chord of a disk, within it by the chord's sagitta */
		assert_true(r1 >= 10 - 1e-2 && r2 >= 10 - 1e-2);
		assert_true(e <= cap * (1 + 1e-5) + 1e-5);
		near_cap += fabs(e - cap) < 1e-3 * fmax(1.0, fabs(cap));
		if (fabs(r1 - 35) < 1e-3 || fabs(r2 - 35) < 1e-3) {
			near_rim++;
			continue;
		}
		if (fabs(r1 - 10) < 1e-3 || fabs(r2 - 10) < 1e-3)
			continue; /* th's slope is infinite at the pivot's disk */
		const double want = f(x, y);
		if (fabs(e - want) > 1e-4 * fmax(1.0, fabs(want)))
			fail_msg("%s: (%g, %g): E %g, the landscape %g", path, x, y, e, want);
	}
	fclose(in);
	print_message("%s: %d vertices, %d on a rim, %d at the cap\n", path, n, near_rim, near_cap);
	assert_int_equal(nan_rows, n / 2); /* a scan of NaN after each quadrangle's two */
	assert_true(n > 1000 && near_rim > 10 && near_cap > 10);
}

/* E_total of the gate at F_prop = 9 N (k = 400 N m/rad each), of beam 2
 * alone at F_prop = 6 N. */
static double e_gate_f9(double x, double y)
{
	return 9.0 * (60 - y) + 200 * (pow(th_model(-25, x, y), 2) + pow(th_model(25, x, y), 2));
}

static double e_beam2_f6(double x, double y)
{
	return 6.0 * (60 - y) + 200 * pow(th_model(25, x, y), 2);
}

static void test_below_surface(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 7.0, 0.0);
	const double pts[][2] = {{0, 30}, {-8, 38}, {5, 45}, {0, 52}, {12, 25}};
	for (size_t i = 0; i < sizeof pts / sizeof pts[0]; i++) {
		double x = pts[i][0], y = pts[i][1];
		double th[2] = {th_model(-25, x, y), th_model(25, x, y)};
		/* on the surface: both beams resting against the body */
		assert_false(bsim_fpath_below(&s, x, y, th));
		double e = 7.0 * (60 - y) + 200 * (th[0] * th[0] + th[1] * th[1]);
		assert_true(fabs(bsim_fpath_energy(&s, y, th) - e) < 1e-9);
		/* a beam left behind (detached) where it would be deflected */
		for (int b = 0; b < 2; b++) {
			double d[2] = {th[0], th[1]};
			d[b] = 0.0;
			int deep = 200 * th[b] * th[b] > FPATH_BELOW_J;
			assert_int_equal(bsim_fpath_below(&s, x, y, d), deep);
		}
		/* a beam swung past the body lies above, never below */
		double up[2] = {th[0] + 0.2, th[1] + 0.2};
		assert_false(bsim_fpath_below(&s, x, y, up));
	}
	bsim_scene_free(&s);
}

/* ---- a sweep ------------------------------------------------------------------------- */

/* A small H1: F_prop 7 and 9 N, Rm 0, 20 and 40 N; group g has F index
 * g / 3 and Rm index g % 3 (the first axis varies slowest). */
static const char *sweep_dir(void)
{
	static char dir[1024];
	if (dir[0])
		return dir;
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("sweep"));
	char yaml[2048], exp[1100];
	snprintf(yaml, sizeof yaml,
	         "scene: %s\ntrials: 12\nseed: 1\ngrid:\n"
	         "  effects.propulsion.force: [7, 9]\n"
	         "  effects.random_force.magnitude: [0, 20, 40]\n",
	         bsim_test_src("configs/thesis/gate.yaml"));
	snprintf(exp, sizeof exp, "%s", bsim_test_write(dir, "small_h1.yaml", yaml));
	const char *argv[] = {"sweep", exp, "--trajectories", "3", "--quiet", "--out", dir, NULL};
	assert_int_equal(run_cli(argv, NULL, NULL), 0);
	return dir;
}

/* The sweep, drawn once for the tests that read its figures. */
static const char *sweep_plotted(void)
{
	static int plotted;
	const char *dir = sweep_dir();
	if (!plotted) {
		char *out = NULL;
		const char *argv[] = {"plot", dir, NULL};
		assert_int_equal(run_cli(argv, &out, NULL), 0);
		assert_non_null(strstr(out, "sweep of"));
		free(out);
		plotted = 1;
	}
	return dir;
}

/* A figure holds at most 12 panels: traversal against F_prop over 13
 * values of Rm is two pages, the second holding the 13th panel alone (the
 * data file's block 12), each page a PNG of its own with its caption;
 * traversal against Rm (2 panels) is one. */
static void test_pages(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("pages");
	char yaml[2048], exp[1100];
	snprintf(yaml, sizeof yaml,
	         "scene: %s\ntrials: 1\nseed: 1\nset:\n  integration.duration: 0.2\ngrid:\n"
	         "  effects.propulsion.force: [8, 9]\n"
	         "  effects.random_force.magnitude: [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12]\n",
	         bsim_test_src("configs/thesis/gate.yaml"));
	snprintf(exp, sizeof exp, "%s", bsim_test_write(dir, "pages.yaml", yaml));
	char out_dir[1100];
	snprintf(out_dir, sizeof out_dir, "%s", bsim_test_join(dir, "out"));
	const char *sweep[] = {"sweep", exp, "--quiet", "--out", out_dir, NULL};
	assert_int_equal(run_cli(sweep, NULL, NULL), 0);
	const char *plot[] = {"plot", out_dir, NULL};
	assert_int_equal(run_cli(plot, NULL, NULL), 0);
	const char *f = "traversal_vs_effects_propulsion_force";
	char path[1400];
	snprintf(path, sizeof path, "%s/%s.png", out_dir, f);
	assert_true(bsim_test_exists(path));
	snprintf(path, sizeof path, "%s/%s_p2.png", out_dir, f);
	assert_true(bsim_test_exists(path));
	snprintf(path, sizeof path, "%s/%s_p3.png", out_dir, f);
	assert_false(bsim_test_exists(path));
	snprintf(path, sizeof path, "%s/%s_p2.gp", out_dir, f);
	char *gp = bsim_test_read(path);
	assert_non_null(gp);
	assert_non_null(strstr(gp, "index 12 "));
	assert_null(strstr(gp, "index 11 "));
	assert_non_null(strstr(gp, "(page 2 of 2)"));
	free(gp);
	snprintf(path, sizeof path, "%s/traversal_vs_effects_random_force_magnitude_p2.png",
	         out_dir);
	assert_false(bsim_test_exists(path));
	char caption[512];
	bsim_index_caption("traversal_vs_effects_propulsion_force_p2.png", caption, sizeof caption);
	assert_non_null(strstr(caption, "propulsive force"));
	assert_non_null(strstr(caption, "(page 2 of its panels)"));
	assert_true(bsim_test_check_figures(out_dir) >= 4);
}

static void test_sweep_figures(void **state)
{
	(void)state;
	const char *dir = sweep_plotted();
	/* p_traverse, two traversal_vs_*, and per group a bundle, plus a
	 * landscape where a kept trial traversed (F = 9 N, Rm = 0 does) */
	int n = bsim_test_check_figures(dir);
	assert_true(n >= 3 + 6 + 1);

	/* The heat map's numbers from the outcomes of trials.csv. */
	char path[1200];
	snprintf(path, sizeof path, "%s/trials.csv", dir);
	char *trials = bsim_test_read(path);
	int trav[6] = {0}, left[6] = {0}, right[6] = {0};
	char *save = NULL;
	for (char *l = strtok_r(trials, "\n", &save); l; l = strtok_r(NULL, "\n", &save)) {
		int g, t;
		char outcome[32], type[32];
		if (sscanf(l, "%d,%d,%31[^,],%31[^,]", &g, &t, outcome, type) != 4)
			continue;
		trav[g] += strcmp(outcome, "traversed") == 0;
		left[g] += strcmp(type, "left") == 0;
		right[g] += strcmp(type, "right") == 0;
	}
	free(trials);
	static double rows[64][16];
	snprintf(path, sizeof path, "%s/p_traverse.dat", dir);
	int nr = bsim_test_data_rows(path, 0, rows, 64);
	assert_int_equal(nr, 6);
	for (int i = 0; i < nr; i++) {
		int g = (int)rows[i][7];
		double lo, hi;
		bsim_test_wilson(trav[g], 12, &lo, &hi);
		if (g % 3 == 0) /* Rm = 0: one trial run and copied, its interval a point */
			lo = hi = trav[g] / 12.0;
		assert_int_equal((int)rows[i][0], g / 3);              /* column: F_prop */
		assert_int_equal((int)rows[i][1], g % 3);              /* row: Rm */
		assert_true(fabs(rows[i][2] - trav[g] / 12.0) < 1e-6); /* %.6g */
		assert_true(fabs(rows[i][3] - lo) < 1e-5 && fabs(rows[i][4] - hi) < 1e-5);
	}
	/* Traversal against Rm, panel F_prop = 9 N (the second): left and
	 * right fractions from the types. */
	snprintf(path, sizeof path, "%s/traversal_vs_effects_random_force_magnitude.dat", dir);
	nr = bsim_test_data_rows(path, 1, rows, 64);
	assert_int_equal(nr, 3);
	for (int i = 0; i < 3; i++) {
		int g = 3 + i;
		assert_true(rows[i][0] == 20.0 * i);
		assert_true(fabs(rows[i][1] - trav[g] / 12.0) < 1e-6);
		assert_true(fabs(rows[i][4] - left[g] / 12.0) < 1e-6);
		assert_true(fabs(rows[i][7] - right[g] / 12.0) < 1e-6);
	}
}

/* E along the paths and the below-surface flags against the model's
 * landscape written above. */
static void test_paths_over_landscape(void **state)
{
	(void)state;
	const char *dir = sweep_plotted();
	char path[1200];
	snprintf(path, sizeof path, "%s/landscape_g003.dat", dir); /* F 9 N, Rm 0: traverses */
	static double rows[20000][16];
	int nr = bsim_test_data_rows(path, 0, rows, 20000);
	assert_true(nr > 50);
	/* each row: x y E class below, thinned from the rows of the
	 * traversed trials in trajectories.csv, in their order */
	snprintf(path, sizeof path, "%s/trajectories.csv", dir);
	char *traj = bsim_test_read(path);
	int k = 0, below = 0;
	char *save = NULL;
	for (char *l = strtok_r(traj, "\n", &save); l && k < nr; l = strtok_r(NULL, "\n", &save)) {
		int g, t;
		double tt, x, y, t1, t2;
		if (sscanf(l, "%d,%d,%lf,%lf,%lf,%lf,%lf", &g, &t, &tt, &x, &y, &t1, &t2) != 7 ||
		    g != 3)
			continue;
		double land = 200 * (pow(th_model(-25, x, y), 2) + pow(th_model(25, x, y), 2));
		double beam = 200 * (t1 * t1 + t2 * t2);
		below += land - beam > 1.0;
		if (fabs(rows[k][0] - x) > 1e-4 || fabs(rows[k][1] - y) > 1e-4)
			continue; /* a row the figure leaves out */
		double e = 9.0 * (60 - y) + beam;
		assert_true(fabs(rows[k][2] - e) <= 1e-5 * fmax(1.0, fabs(e)));
		assert_int_equal((int)rows[k][4], land - beam > 1.0);
		k++;
	}
	free(traj);
	assert_int_equal(k, nr);
	/* every state below the surface is in the stretches of block 1 */
	snprintf(path, sizeof path, "%s/landscape_g003.dat", dir);
	int nb = bsim_test_data_rows(path, 1, rows, 20000);
	assert_true(nb >= below);
	/* the surface is the model's; the script's colours and title */
	snprintf(path, sizeof path, "%s/landscape_g003.surface.dat", dir);
	double cap;
	assert_true(check_surface(path, e_gate_f9, &cap) > 1000);
	snprintf(path, sizeof path, "%s/landscape_g003.mesh.dat", dir);
	check_mesh(path, e_gate_f9, cap);
	snprintf(path, sizeof path, "%s/landscape_g003.gp", dir);
	char *gp = bsim_test_read(path);
	assert_non_null(gp);
	const char *const needles[] = {"backend thesis", "F_prop = 9 N", "R_m = 0 N", NULL};
	check_landscape_script(gp, needles);
	free(gp);
}

/* Fig. 2.7 as docs/figures.md reproduces it: landscape_path titled with
 * the backend and the --set values, and landscape_path_single, the path
 * over beam 2's landscape alone (Fig. 2.7c), its surface F_prop (60 - y) +
 * 1/2 k th_2^2 and fewer of its states below it than below the whole
 * landscape; all six files of both figures in the manifest. */
static void test_fig27(void **state)
{
	(void)state;
	char dir[1024];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("fig2.7"));
	const char *run[] = {"run",     bsim_test_src("configs/thesis/gate.yaml"),
	                     "--seed",  "1",
	                     "--group", "13",
	                     "--trial", "15",
	                     "--set",   "effects.propulsion.force=6",
	                     "--set",   "effects.random_force.magnitude=30",
	                     "--out",   dir,
	                     NULL};
	assert_int_equal(run_cli(run, NULL, NULL), 0);
	const char *argv[] = {"plot", dir, "--quiet", NULL};
	assert_int_equal(run_cli(argv, NULL, NULL), 0);
	assert_int_equal(bsim_test_check_figures(dir), 4);
	char path[1200];
	const char *const needles[] = {"backend thesis", "F_prop = 6 N", "R_m = 30 N", NULL};
	const char *const single[] = {"F_prop = 6 N", "over beam 2", NULL};
	const char *names[] = {"landscape_path", "landscape_path_single"};
	for (int i = 0; i < 2; i++) {
		snprintf(path, sizeof path, "%s/%s.gp", dir, names[i]);
		char *gp = bsim_test_read(path);
		assert_non_null(gp);
		check_landscape_script(gp, i ? single : needles);
		free(gp);
	}
	snprintf(path, sizeof path, "%s/landscape_path_single.surface.dat", dir);
	double cap;
	check_surface(path, e_beam2_f6, &cap);
	snprintf(path, sizeof path, "%s/landscape_path_single.mesh.dat", dir);
	check_mesh(path, e_beam2_f6, cap);
	static double rows[20000][16];
	snprintf(path, sizeof path, "%s/landscape_path.dat", dir);
	const int below = bsim_test_data_rows(path, 1, rows, 20000);
	snprintf(path, sizeof path, "%s/landscape_path_single.dat", dir);
	const int below_single = bsim_test_data_rows(path, 1, rows, 20000);
	print_message("rows below the surface: %d whole, %d beam 2 alone\n", below, below_single);
	assert_true(below > 10 && below_single < below);
	snprintf(path, sizeof path, "%s/manifest.json", dir);
	char *manifest = bsim_test_read(path);
	assert_non_null(manifest);
	const char *ext[] = {"gp", "png", "svg", "dat", "surface.dat", "mesh.dat"};
	for (int i = 0; i < 2; i++)
		for (int k = 0; k < 6; k++) {
			char want[100];
			snprintf(want, sizeof want, "\"%s.%s\"", names[i], ext[k]);
			if (!strstr(manifest, want))
				fail_msg("%s not in the manifest", want);
		}
	free(manifest);
}

static void test_select(void **state)
{
	(void)state;
	const char *dir = sweep_dir();
	char out_dir[1100];
	snprintf(out_dir, sizeof out_dir, "%s/f7", dir);
	const char *argv[] = {"plot",  dir,     "--select", "effects.propulsion.force=7.0",
	                      "--out", out_dir, "--quiet",  NULL};
	assert_int_equal(run_cli(argv, NULL, NULL), 0);
	static double rows[64][16];
	char path[1200];
	snprintf(path, sizeof path, "%s/p_traverse.dat", out_dir);
	int nr = bsim_test_data_rows(path, 0, rows, 64);
	assert_int_equal(nr, 3); /* the three Rm of F = 7 N, groups 0-2 */
	for (int i = 0; i < nr; i++)
		assert_true(rows[i][7] >= 0 && rows[i][7] <= 2);
	/* one value of F left: nothing drawn against it */
	snprintf(path, sizeof path, "%s/traversal_vs_effects_propulsion_force.gp", out_dir);
	assert_null(bsim_test_read(path));
	assert_true(bsim_test_check_figures(out_dir) >= 0);

	char *err = NULL;
	const char *bad[] = {"plot",  dir,     "--select",    "beams.0.mass=1",
	                     "--out", out_dir, "--overwrite", NULL};
	assert_int_equal(run_cli(bad, NULL, &err), 2);
	assert_non_null(strstr(err, "beams.0.mass is not a grid axis"));
	free(err);
	const char *none[] = {"plot", dir, "--select", "effects.propulsion.force=3", NULL};
	assert_int_equal(run_cli(none, NULL, &err), 2);
	assert_non_null(strstr(err, "has no value 3"));
	free(err);
}

/* The text of OUT/NAME.gp, which the test frees. */
static char *script(const char *dir, const char *name)
{
	char path[1200];
	snprintf(path, sizeof path, "%s/%s.gp", dir, name);
	char *t = bsim_test_read(path);
	if (!t)
		fail_msg("no %s", path);
	return t;
}

/* The PNG size a script asks for: "size W*scale,H*scale". */
static void script_size(const char *gp, int *w, int *h)
{
	const char *at = strstr(gp, "pngcairo size ");
	assert_non_null(at);
	assert_int_equal(sscanf(at, "pngcairo size %d*scale,%d*scale", w, h), 2);
}

/* Axes, panels and titles name keys by the names table (key_names.h), the
 * backend and the fixed values; a group without random force is one
 * trial; a figure with one row of cells or one panel is sized for it. */
static void test_names_and_titles(void **state)
{
	(void)state;
	const char *dir = sweep_plotted();
	char want[400], kv[200];
	char *gp = script(dir, "p_traverse");
	bsim_key_label("effects.propulsion.force", 1, want, sizeof want);
	assert_non_null(strstr(gp, want));
	bsim_key_label("effects.random_force.magnitude", 1, want, sizeof want);
	assert_non_null(strstr(gp, want));
	assert_null(strstr(gp, "set xlabel 'effects.propulsion.force'"));
	assert_non_null(strstr(gp, "thesis backend"));
	free(gp);
	/* panels of traversal against F titled by Rm's values */
	gp = script(dir, "traversal_vs_effects_propulsion_force");
	bsim_key_value("effects.random_force.magnitude", "20", 0, kv, sizeof kv);
	snprintf(want, sizeof want, "set title '%s'", kv);
	assert_non_null(strstr(gp, want));
	free(gp);
	/* group 0 (Rm = 0) ran one trial; group 1 (Rm = 20 N) twelve */
	gp = script(dir, "trajectories_g000");
	assert_non_null(strstr(gp, "one deterministic trial"));
	assert_null(strstr(gp, "the first"));
	free(gp);
	gp = script(dir, "trajectories_g001");
	assert_non_null(strstr(gp, "the first 3 of 12 trials"));
	free(gp);

	/* F = 9 N alone: one row of cells, no 1 x 1 panels; the fixed value
	 * in the title; one panel against Rm, its key beside it */
	char out_dir[1100];
	snprintf(out_dir, sizeof out_dir, "%s/f9", dir);
	const char *argv[] = {"plot",  dir,     "--select", "effects.propulsion.force=9",
	                      "--out", out_dir, "--quiet",  NULL};
	assert_int_equal(run_cli(argv, NULL, NULL), 0);
	gp = script(out_dir, "p_traverse");
	assert_non_null(strstr(gp, "set multiplot layout 1,1 "));
	bsim_key_value("effects.propulsion.force", "9", 0, kv, sizeof kv);
	assert_non_null(strstr(gp, kv));
	int w, h;
	script_size(gp, &w, &h);
	assert_true(w < 2 * h + 1000 && h < 600); /* one row of three cells */
	free(gp);
	gp = script(out_dir, "traversal_vs_effects_random_force_magnitude");
	assert_null(strstr(gp, "layout"));
	script_size(gp, &w, &h);
	assert_true(w <= 1200);
	free(gp);
}

/* A malformed file is named with its line, exit 2, and no figure is drawn. */
static void test_bad_input(void **state)
{
	(void)state;
	char dir[1024];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("bad"));
	const char *sweep[] = {"sweep",
	                       bsim_test_src("configs/thesis/h1_symmetric.yaml"),
	                       "--trials",
	                       "1",
	                       "--trajectories",
	                       "1",
	                       "--quiet",
	                       "--out",
	                       dir,
	                       NULL};
	assert_int_equal(run_cli(sweep, NULL, NULL), 0);
	char path[1200];
	snprintf(path, sizeof path, "%s/trajectories.csv", dir);
	char *text = bsim_test_read(path);
	int lines = 0;
	for (char *p = text; *p; p++)
		lines += *p == '\n';
	FILE *f = fopen(path, "a");
	fputs("29,0,1.5,0,0\n", f); /* too few fields */
	fclose(f);
	free(text);
	/* An edited file no longer matches the manifest, which plot checks
	 * first; without one, the file itself is read and checked. */
	snprintf(path, sizeof path, "%s/manifest.json", dir);
	remove(path);
	char *err = NULL;
	const char *argv[] = {"plot", dir, NULL};
	assert_int_equal(run_cli(argv, NULL, &err), 2);
	char want[64];
	snprintf(want, sizeof want, "trajectories.csv:%d: expected 9 fields, got 5", lines + 1);
	assert_non_null(strstr(err, want));
	free(err);
	snprintf(path, sizeof path, "%s/p_traverse.gp", dir);
	assert_null(bsim_test_read(path));
}

static void test_not_an_output(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("empty");
	char *err = NULL;
	const char *argv[] = {"plot", dir, NULL};
	assert_int_equal(run_cli(argv, NULL, &err), 2);
	assert_non_null(strstr(err, dir));
	assert_non_null(strstr(err, "summary.json"));
	free(err);
}

/* ---- a run ---------------------------------------------------------------------------- */

static void test_run_figures(void **state)
{
	(void)state;
	char dir[1024];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("run"));
	char *out = NULL;
	const char *run[] = {
	        "run", bsim_test_src("configs/thesis/gate.yaml"), "--json", "--out", dir, NULL};
	assert_int_equal(run_cli(run, &out, NULL), 0);
	char *p = strstr(out, "\"draws\": ");
	assert_non_null(p);
	long draws = strtol(p + 9, NULL, 10);
	free(out);
	const char *argv[] = {"plot", dir, "--quiet", NULL};
	assert_int_equal(run_cli(argv, NULL, NULL), 0);
	assert_int_equal(bsim_test_check_figures(dir), 3);
	/* The histogram: every draw of the runner once, density integrating
	 * to 1. */
	static double rows[64][16];
	char path[1200];
	snprintf(path, sizeof path, "%s/random_force.dat", dir);
	int nr = bsim_test_data_rows(path, 0, rows, 64);
	assert_int_equal(nr, 32);
	double width = rows[1][0] - rows[0][0], integral = 0.0;
	long count = 0;
	for (int i = 0; i < nr; i++) {
		integral += rows[i][1] * width;
		count += (long)rows[i][2];
	}
	assert_int_equal(count, draws);
	assert_true(fabs(integral - 1.0) < 1e-5); /* densities at %.6g */
	/* The ledger's sum of flows is E(t) - E(0) less the residual. */
	static double led[4000][16];
	snprintf(path, sizeof path, "%s/ledger.dat", dir);
	nr = bsim_test_data_rows(path, 0, led, 4000);
	assert_true(nr > 100);
	for (int i = 0; i < nr; i++)
		assert_true(fabs(led[i][4] - led[i][11] - led[i][12]) < 1e-6);
}

/* ---- the accuracy study ------------------------------------------------------------------- */

static void test_accuracy_front(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("accuracy");
	/* speed, error: a (1000, 1e-3), b (100, 1e-4), c (500, 2e-3) dominated
	 * by a, d (2000, 5e-3), e (50, 5e-4) dominated by b; the rows at the
	 * reference step (0.000125 s) are not drawn. Front by speed: d, a, b. */
	bsim_test_write(dir, "accuracy.csv",
	                "backend,setting,reference,h_s,err_mean_m,speed_x_realtime\n"
	                "thesis,s1,1,0.004,1e-3,1000\n"
	                "thesis,s1,1,0.001,1e-4,100\n"
	                "thesis,s1,1,0.000125,0,10\n"
	                "box2d,s2,0,0.004,2e-3,500\n"
	                "box2d,s2,0,0.008,5e-3,2000\n"
	                "box2d,s2,0,0.001,5e-4,50\n"
	                "box2d,s2,0,0.000125,1e-9,5\n");
	const char *argv[] = {"plot", dir, "--quiet", NULL};
	assert_int_equal(run_cli(argv, NULL, NULL), 0);
	static double rows[16][16];
	char path[1200];
	snprintf(path, sizeof path, "%s/accuracy.dat", dir);
	int nr = bsim_test_data_rows(path, 2, rows, 16);
	assert_int_equal(nr, 3);
	const double speed[3] = {2000, 1000, 100}, err[3] = {5e-3, 1e-3, 1e-4};
	for (int i = 0; i < 3; i++) {
		assert_true(rows[i][0] == speed[i]);
		assert_true(rows[i][1] == err[i]);
	}
	assert_int_equal(bsim_test_data_rows(path, 0, rows, 16),
	                 2); /* s1 without its reference row */
	assert_int_equal(bsim_test_data_rows(path, 1, rows, 16), 3);
	assert_true(bsim_test_check_figures(dir) >= 0);
}

/* ---- a comparison ------------------------------------------------------------------------- */

static void test_compare_figures(void **state)
{
	(void)state;
	char dir[1024];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("compare"));
	const char *cmp[] = {"compare",  bsim_test_src("configs/thesis/h1_symmetric.yaml"),
	                     "--trials", "6",
	                     "--quiet",  "--out",
	                     dir,        NULL};
	int rc = run_cli(cmp, NULL, NULL);
	assert_true(rc == 0 || rc == 3);
	const char *argv[] = {"plot", dir, "--quiet", NULL};
	assert_int_equal(run_cli(argv, NULL, NULL), 0);
	assert_int_equal(bsim_test_check_figures(dir), 1);
	char sub[1100];
	for (int b = 0; b < 2; b++) {
		snprintf(sub, sizeof sub, "%s/%s", dir, b ? "box2d" : "thesis");
		assert_int_equal(bsim_test_check_figures(sub), 4); /* survival too */
	}
	/* The paired difference is p_A - p_B of the two probabilities drawn. */
	static double rows[64][16];
	char path[1200];
	snprintf(path, sizeof path, "%s/compare.dat", dir);
	int nr = bsim_test_data_rows(path, 0, rows, 64);
	assert_int_equal(nr, 30);
	for (int i = 0; i < nr; i++)
		assert_true(fabs(rows[i][8] - (rows[i][2] - rows[i][5])) < 1e-6);
	/* the title names both backends; the groups are in blocks of F_prop
	 * named above, the ticks Rm's values (not "4,0") */
	char *gp = script(dir, "compare");
	assert_non_null(strstr(gp, "A: thesis backend, B: box2d backend"));
	char kv[200];
	bsim_key_value("effects.propulsion.force", "4", 0, kv, sizeof kv);
	assert_non_null(strstr(gp, kv));
	assert_null(strstr(gp, "'4,0'"));
	free(gp);
}

/* ---- without gnuplot ---------------------------------------------------------------------- */

static void test_without_gnuplot(void **state)
{
	(void)state;
	char dir[1024];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("no_gnuplot"));
	const char *run[] = {"run", bsim_test_src("configs/thesis/gate.yaml"), "--out", dir, NULL};
	assert_int_equal(run_cli(run, NULL, NULL), 0);
	char *old = strdup(getenv("PATH") ? getenv("PATH") : "/usr/bin:/bin");
	setenv("PATH", bsim_test_dir("empty_path"), 1);
	char *err = NULL;
	const char *argv[] = {"plot", dir, "--quiet", NULL};
	int rc = run_cli(argv, NULL, &err);
	setenv("PATH", old, 1);
	free(old);
	assert_int_equal(rc, 0);
	assert_non_null(strstr(err, "gnuplot-nox"));
	free(err);
	static const char *const files[] = {"ledger.gp", "ledger.dat", "random_force.gp",
	                                    "landscape_path.gp", "landscape_path.surface.dat"};
	char path[1200];
	for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
		snprintf(path, sizeof path, "%s/%s", dir, files[i]);
		char *t = bsim_test_read(path);
		assert_non_null(t);
		free(t);
	}
	snprintf(path, sizeof path, "%s/ledger.png", dir);
	assert_null(bsim_test_read(path));
}

/* ---- the edge check ------------------------------------------------------------------- */

/* bsim_test_check_figures' edge check against figures made to fail it: a
 * title three times wider than its 400-pixel canvas runs off both sides,
 * the same title wrapped in lines fits, and so does a short one. */
static void test_edge_check(void **state)
{
	(void)state;
	if (!bsim_figure_available())
		skip();
	const char *dir = bsim_test_dir("edge");
	static const char *const body[] = {
	        "set title 'a title of a hundred and fifty characters, three times as wide as the "
	        "canvas of four hundred pixels that gnuplot centres on it and cuts at both ends'\n"
	        "plot x\n",
	        "set title \"a title of a hundred and fifty characters,\\nthree times as wide "
	        "as the canvas\\nof four hundred pixels that gnuplot\\ncentres on it and cuts "
	        "at both ends\"\nplot x\n",
	        "set title 'short'\nplot x\n"};
	for (int i = 0; i < 3; i++) {
		char name[16], png[1200];
		snprintf(name, sizeof name, "edge%d", i);
		bsim_figure_def d = bsim_figure_def_default();
		d.dir = dir;
		d.name = name;
		d.width = 400;
		d.height = 300;
		assert_int_equal(bsim_figure_render(&d, body[i], NULL, NULL), BSIM_OK);
		snprintf(png, sizeof png, "%s/%s.png", dir, name);
		const char *edge = bsim_test_png_edge(png);
		print_message("%s: %s\n", name, edge ? edge : "clear of the edges");
		if (i == 0)
			assert_string_equal(edge, "left, right");
		else
			assert_null(edge);
	}
	assert_int_equal(bsim_test_check_figures(dir), -1); /* edge0 */
}

/* ---- gnuplot failing ------------------------------------------------------------------- */

/* A gnuplot that fails on one figure of a run's directory (and draws the
 * others): plot exits 1 naming it, quoting its line and naming its script
 * and data; they join the directory's set with the figures drawn, beside
 * the run's own files. */
static void test_gnuplot_fails(void **state)
{
	(void)state;
	const char *base = bsim_test_dir("gnuplot_fails");
	char bin[1100], dir[1100];
	snprintf(bin, sizeof bin, "%s/bin", base);
	snprintf(dir, sizeof dir, "%s/run", base);
	const char *run[] = {"run", bsim_test_src("configs/thesis/gate.yaml"), "--out", dir, NULL};
	assert_int_equal(run_cli(run, NULL, NULL), 0);
	char *old = bsim_test_fake_program(
	        bin, "gnuplot",
	        "#!/bin/sh\n"
	        "if [ \"$3\" = ledger.gp ]; then\n"
	        "  echo '\"ledger.gp\" line 7: the stand-in fails here' >&2; exit 1\n"
	        "fi\n"
	        "PATH=\"${PATH#*:}\" exec gnuplot \"$@\"\n");
	char *err = NULL;
	const char *argv[] = {"plot", dir, "--quiet", NULL};
	int rc = bsim_test_cli(argv, NULL, &err);
	bsim_test_path_restore(old);
	printf("# exit %d: %s", rc, err);
	assert_int_equal(rc, 1);
	assert_int_equal(bsim_test_count_lines(err), 1);
	char want[1400];
	snprintf(want, sizeof want,
	         "beamsim: figure ledger: gnuplot exited with status 1: \"ledger.gp\" line 7: the "
	         "stand-in fails here; its script and data are in %s: ledger.gp, ledger.dat\n",
	         dir);
	assert_string_equal(err, want);
	free(err);
	const char *kept[] = {"trajectory.csv",  "ledger.csv",       "ledger.gp", "ledger.dat",
	                      "random_force.gp", "random_force.png", NULL};
	const char *none[] = {"ledger.png", "ledger.svg", NULL};
	bsim_test_check_committed(dir, kept, none);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_below_surface),
	        cmocka_unit_test(test_sweep_figures),
	        cmocka_unit_test(test_paths_over_landscape),
	        cmocka_unit_test(test_select),
	        cmocka_unit_test(test_pages),
	        cmocka_unit_test(test_names_and_titles),
	        cmocka_unit_test(test_not_an_output),
	        cmocka_unit_test(test_bad_input),
	        cmocka_unit_test(test_run_figures),
	        cmocka_unit_test(test_accuracy_front),
	        cmocka_unit_test(test_compare_figures),
	        cmocka_unit_test(test_without_gnuplot),
	        cmocka_unit_test(test_fig27),
	        cmocka_unit_test(test_gnuplot_fails),
	        cmocka_unit_test(test_edge_check),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
