/* beamsim landscape through the real program: the files it writes agree
 * with the library's landscape point by point (CSV) and with each other
 * (the MATLAB file read back by libmatio's own reader, the JSON), the
 * figures are PNG and SVG under 1 MB, --resolution, --region and --set do
 * what they say, and every bad input exits 2 with a message naming it and
 * writes nothing. A figure gnuplot fails on (a stand-in that fails on one
 * figure; the real gnuplot on a region too wide to draw) exits 1 naming it
 * and gnuplot's message, and the landscape's files, the failed figure's
 * script and data among them, are committed all the same. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <matio.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "beamsim/landscape.h"
#include "support.h"
#include "util/figure.h"

static char out_dir[1024];

static int setup(void **state)
{
	(void)state;
	snprintf(out_dir, sizeof out_dir, "%s", bsim_test_dir("landscape_gate"));
	char *out = NULL, *err = NULL;
	const char *argv[] = {"landscape", bsim_test_src("configs/thesis/gate.yaml"), "--out",
	                      out_dir, NULL};
	struct timespec t0, t1;
	clock_gettime(CLOCK_MONOTONIC, &t0);
	int rc = bsim_test_cli(argv, &out, &err);
	clock_gettime(CLOCK_MONOTONIC, &t1);
	print_message("beamsim landscape configs/thesis/gate.yaml: %.2f s (this build)\n",
	              (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec));
	if (rc != 0)
		fail_msg("exit %d: %s", rc, err ? err : "");
	assert_non_null(strstr(out, "lowest pass"));
	assert_non_null(strstr(out, "over beam 2"));
	assert_true(bsim_test_check_wrote(out, out_dir) >= 10);
	free(out);
	free(err);
	return 0;
}

/* landscape.csv: the contract's columns, one row per point, each value
 * the library's landscape at that point. */
static void test_csv(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_error err;
	assert_int_equal(
	        bsim_scene_load(bsim_test_src("configs/thesis/gate.yaml"), NULL, 0, &s, &err),
	        BSIM_OK);
	FILE *f = fopen(bsim_test_join(out_dir, "landscape.csv"), "r");
	assert_non_null(f);
	char line[512];
	assert_non_null(fgets(line, sizeof line, f));
	assert_string_equal(line, "x,y,e_beam,e_prop,e_total,theta1,theta2\n");
	long rows = 0;
	double worst = 0.0;
	while (fgets(line, sizeof line, f)) {
		double v[7];
		assert_int_equal(sscanf(line, "%lf,%lf,%lf,%lf,%lf,%lf,%lf", &v[0], &v[1], &v[2],
		                        &v[3], &v[4], &v[5], &v[6]),
		                 7);
		if (rows % 97 == 0) {
			double th[2], eb, ep;
			const double e = bsim_landscape_energy(&s, v, th, &eb, &ep);
			const double ref[5] = {eb, ep, e, th[0], th[1]};
			for (int i = 0; i < 5; i++)
				worst = fmax(worst,
				             fabs(v[2 + i] - ref[i]) / fmax(1.0, fabs(ref[i])));
		}
		rows++;
	}
	fclose(f);
	print_message("landscape.csv: %ld rows, largest relative difference %.2g\n", rows, worst);
	assert_int_equal(rows, 201 * 261); /* 0.25 m over [-25, 25] x [0, 65] */
	assert_true(worst < 1e-9);         /* %.10g */
	bsim_scene_free(&s);
}

/* landscape.mat read back: the grid's columns equal the CSV's, the shape,
 * and the barrier table's lowest pass equals landscape.json's. */
static void test_mat(void **state)
{
	(void)state;
	mat_t *mat = Mat_Open(bsim_test_join(out_dir, "landscape.mat"), MAT_ACC_RDONLY);
	assert_non_null(mat);
	matvar_t *v = Mat_VarRead(mat, "landscape");
	assert_non_null(v);
	matvar_t *et = Mat_VarGetStructFieldByName(v, "e_total", 0);
	matvar_t *nx = Mat_VarGetStructFieldByName(v, "nx", 0);
	matvar_t *ny = Mat_VarGetStructFieldByName(v, "ny", 0);
	matvar_t *th2 = Mat_VarGetStructFieldByName(v, "theta2", 0);
	matvar_t *bar = Mat_VarGetStructFieldByName(v, "barriers", 0);
	assert_non_null(et);
	assert_non_null(nx);
	assert_non_null(ny);
	assert_non_null(th2);
	assert_non_null(bar);
	assert_true(((double *)nx->data)[0] == 201 && ((double *)ny->data)[0] == 261);
	assert_int_equal(et->dims[0], 201 * 261);
	/* every e_total against the CSV (printed with 10 digits) */
	FILE *f = fopen(bsim_test_join(out_dir, "landscape.csv"), "r");
	char line[512];
	assert_non_null(fgets(line, sizeof line, f));
	const double *e = et->data;
	size_t k = 0;
	double x, y, eb, ep, etot;
	while (fgets(line, sizeof line, f)) {
		assert_int_equal(sscanf(line, "%lf,%lf,%lf,%lf,%lf", &x, &y, &eb, &ep, &etot), 5);
		assert_true(fabs(e[k] - etot) <= 1e-9 * fmax(1.0, fabs(etot)));
		k++;
	}
	fclose(f);
	assert_int_equal(k, et->dims[0]);
	matvar_t *be = Mat_VarGetStructFieldByName(bar, "e_total", 0);
	matvar_t *kind = Mat_VarGetStructFieldByName(bar, "kind", 0);
	assert_non_null(be);
	assert_non_null(kind);
	assert_int_equal(be->dims[0], 3); /* lowest, beam 1, beam 2 */
	char *json = bsim_test_read(bsim_test_join(out_dir, "landscape.json"));
	assert_non_null(json);
	const char *lowest = strstr(json, "\"lowest_pass\"");
	assert_non_null(lowest);
	assert_true(((double *)be->data)[0] == bsim_test_json_number(lowest, "e_total"));
	assert_non_null(strstr(lowest, "\"kind\": \"saddle\""));
	free(json);
	Mat_VarFree(v);
	Mat_Close(mat);
}

/* Figures: PNG and SVG, each under 1 MB, scripts beside them, nothing
 * drawn to the PNG's edge (bsim_test_check_figures). */
static void test_figures(void **state)
{
	(void)state;
	assert_int_equal(bsim_test_check_figures(out_dir), 3);
	const char *names[] = {"landscape_top", "landscape_beam", "landscape_total"};
	for (int i = 0; i < 3; i++) {
		char n[64];
		snprintf(n, sizeof n, "%s.gp", names[i]);
		assert_true(bsim_test_size(bsim_test_join(out_dir, n)) > 0);
		snprintf(n, sizeof n, "%s.png", names[i]);
		const long png = bsim_test_size(bsim_test_join(out_dir, n));
		snprintf(n, sizeof n, "%s.svg", names[i]);
		const long svg = bsim_test_size(bsim_test_join(out_dir, n));
		print_message("%s: png %ld bytes, svg %ld bytes\n", names[i], png, svg);
		assert_true(png > 1000 && png < 1000000);
		assert_true(svg > 1000 && svg < 1000000);
		snprintf(n, sizeof n, "%s.png", names[i]);
		char *img = bsim_test_read(bsim_test_join(out_dir, n));
		assert_non_null(img);
		assert_memory_equal(img, "\x89PNG", 4);
		free(img);
	}
}

/* --json prints landscape.json as written, --quiet prints nothing; both
 * still write the files. */
static void test_json_quiet(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("landscape_json");
	char d[1100];
	snprintf(d, sizeof d, "%s", dir);
	char *out = NULL;
	const char *json[] = {"landscape",
	                      bsim_test_src("configs/thesis/gate.yaml"),
	                      "--resolution",
	                      "1",
	                      "--json",
	                      "--out",
	                      d,
	                      NULL};
	assert_int_equal(bsim_test_cli(json, &out, NULL), 0);
	char *file = bsim_test_read(bsim_test_join(d, "landscape.json"));
	assert_non_null(file);
	assert_string_equal(out, file);
	assert_non_null(strstr(out, "\"lowest_pass\""));
	free(out);
	free(file);
	const char *quiet[] = {"landscape",
	                       bsim_test_src("configs/thesis/gate.yaml"),
	                       "--resolution",
	                       "1",
	                       "--quiet",
	                       "--out",
	                       d,
	                       "--overwrite",
	                       NULL};
	out = NULL;
	assert_int_equal(bsim_test_cli(quiet, &out, NULL), 0);
	assert_string_equal(out, "");
	free(out);
	assert_true(bsim_test_size(bsim_test_join(d, "landscape.csv")) > 0);
}

/* --resolution, --region and --set. */
static void test_options(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("landscape_options");
	char *out = NULL, *err = NULL;
	const char *argv[] = {"landscape",
	                      bsim_test_src("configs/thesis/gate.yaml"),
	                      "--resolution",
	                      "0.5",
	                      "--region",
	                      "-25,25,15,65",
	                      "--set",
	                      "beams.0.stiffness=100",
	                      "--set",
	                      "beams.1.stiffness=500",
	                      "--out",
	                      dir,
	                      NULL};
	int rc = bsim_test_cli(argv, &out, &err);
	if (rc != 0)
		fail_msg("exit %d: %s", rc, err ? err : "");
	char *json = bsim_test_read(bsim_test_join(dir, "landscape.json"));
	assert_non_null(json);
	assert_true(bsim_test_json_number(json, "nx") == 101 &&
	            bsim_test_json_number(json, "ny") == 101);
	assert_true(bsim_test_json_number(json, "spacing") == 0.5);
	/* the softer left beam: no barrier over it at the gate's 7 N */
	const char *lowest = strstr(json, "\"lowest_pass\"");
	assert_non_null(strstr(lowest, "\"kind\": \"open\", \"crossed\": 1"));
	free(json);
	/* a square region: the surfaces' most quadrangles, still under 1 MB */
	const char *figs[] = {"landscape_top.svg", "landscape_beam.svg", "landscape_total.svg",
	                      "landscape_top.png", "landscape_beam.png", "landscape_total.png"};
	for (int i = 0; i < 6; i++) {
		const long size = bsim_test_size(bsim_test_join(dir, figs[i]));
		print_message("square region: %s %ld bytes\n", figs[i], size);
		assert_true(size > 1000 && size < 1000000);
	}
	free(out);
	free(err);
}

/* ---- the figures' conventions -------------------------------------------------- */

/* The colours of a gnuplot palette "set palette defined (v '#RRGGBB', ...)"
 * in gp, into rgb; their count. */
static int palette_colors(const char *gp, unsigned rgb[], int max)
{
	const char *p = strstr(gp, "set palette defined (");
	int n = 0;
	if (!p)
		return 0;
	const char *end = strchr(p, ')');
	for (const char *h = strchr(p, '#'); h && h < end && n < max; h = strchr(h + 1, '#'))
		rgb[n++] = (unsigned)strtoul(h + 1, NULL, 16);
	return n;
}

/* Saturation of HSV, (max - min) / max of the channels: 0 grey, 1 pure. */
static double saturation(unsigned rgb)
{
	const double r = rgb >> 16 & 255, g = rgb >> 8 & 255, b = rgb & 255;
	const double hi = fmax(r, fmax(g, b)), lo = fmin(r, fmin(g, b));
	return hi > 0 ? (hi - lo) / hi : 0.0;
}

/* Each figure: the landscapes' palette (grey to blue-green: no colour in it
 * saturated above 0.4) with a colour bar naming the potential energy and
 * its unit; the title holds the values given by --set in the model's
 * symbols and units; the path of least resistance (top view) in a colour
 * saturated above 0.6, so none of the map's; the 3-D surfaces are
 * depth-sorted pm3d with NaN (not a wall) where the body would overlap a
 * pivot (the gate's pivots at (+-25, 30) m, R = 10 m) and no two
 * neighbours drawn a wall apart (more than 0.6 of the drawn range); every
 * figure's files in the manifest. */
static void test_figure_style(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("landscape_style");
	char *out = NULL, *err = NULL;
	const char *argv[] = {"landscape", bsim_test_src("configs/thesis/gate.yaml"),
	                      "--set",     "beams.0.stiffness=150",
	                      "--set",     "effects.propulsion.force=8",
	                      "--out",     dir,
	                      NULL};
	int rc = bsim_test_cli(argv, &out, &err);
	if (rc != 0)
		fail_msg("exit %d: %s", rc, err ? err : "");
	free(out);
	free(err);
	const char *names[] = {"landscape_top", "landscape_beam", "landscape_total"};
	char *manifest = bsim_test_read(bsim_test_join(dir, "manifest.json"));
	assert_non_null(manifest);
	for (int i = 0; i < 3; i++) {
		const char *ext[] = {"gp", "dat", "png", "svg"};
		for (int k = 0; k < 4; k++) {
			char want[80];
			snprintf(want, sizeof want, "\"%s.%s\"", names[i], ext[k]);
			if (!strstr(manifest, want))
				fail_msg("%s not in the manifest", want);
		}
	}
	free(manifest);
	for (int i = 0; i < 3; i++) {
		char n[64];
		snprintf(n, sizeof n, "%s.gp", names[i]);
		char *gp = bsim_test_read(bsim_test_join(dir, n));
		assert_non_null(gp);
		unsigned pal[16];
		int np = palette_colors(gp, pal, 16);
		assert_true(np >= 2);
		for (int k = 0; k < np; k++)
			assert_true(saturation(pal[k]) < 0.4);
		assert_non_null(strstr(gp, "set colorbox"));
		assert_non_null(strstr(gp, "set cblabel 'potential energy"));
		assert_non_null(strstr(gp, "(J)'"));
		const char *title = strstr(gp, "set title");
		assert_non_null(title);
		const char *eol = strchr(title, '\n');
		char t[600];
		snprintf(t, sizeof t, "%.*s", (int)(eol - title), title);
		assert_non_null(strstr(t, "k_1 = 150 N m/rad"));
		assert_non_null(strstr(t, "k_2 = 400 N m/rad"));
		assert_non_null(strstr(t, "F_prop = 8 N"));
		assert_non_null(strstr(t, "no backend"));
		if (i == 0) {
			const char *path = strstr(gp, "title 'path of least resistance'");
			assert_non_null(path);
			const char *lc = path;
			while (lc > gp && strncmp(lc, "lc rgb '#", 9) != 0)
				lc--;
			unsigned c = (unsigned)strtoul(lc + 9, NULL, 16);
			assert_true(saturation(c) > 0.6);
			for (int k = 0; k < np; k++)
				assert_true(c != pal[k]);
		} else {
			assert_non_null(strstr(gp, "set pm3d depthorder"));
			assert_null(strstr(gp, "unset colorbox"));
		}
		free(gp);
	}
	/* The surfaces: pm3d quadrangles (two scans of two points, then a scan
	 * of NaN). None has an edge across a rim of reach (rho = L + R = 35 m
	 * about (+-25, 30)), where the landscape steps, by more than the
	 * sagitta of a polygon's chord of the rim (under 10 cm; a grid cell
	 * straddling the step would cross it by up to its side), or a corner
	 * within a pivot's disk (rho < R = 10 m) by more than 1 cm; E's
	 * steepest change along an edge is under 0.6 of the drawn range (an
	 * edge up the walls by the pivots, where th's slope grows without
	 * bound, not a step). */
	for (int i = 1; i < 3; i++) {
		char n[64];
		snprintf(n, sizeof n, "%s.dat", names[i]);
		FILE *f = fopen(bsim_test_join(dir, n), "r");
		assert_non_null(f);
		double q[4][3], lo = INFINITY, hi = -INFINITY, worst = 0.0;
		int k = 0, quads = 0, on_rim = 0;
		char line[256];
		while (fgets(line, sizeof line, f)) {
			if (line[0] == '#' || line[0] == '\n')
				continue;
			double *v = q[k];
			assert_int_equal(sscanf(line, "%lf %lf %lf", &v[0], &v[1], &v[2]), 3);
			if (isnan(v[2]))
				continue;
			lo = fmin(lo, v[2]);
			hi = fmax(hi, v[2]);
			for (int b = 0; b < 2; b++)
				assert_true(hypot(v[0] - (b ? 25 : -25), v[1] - 30) >= 10 - 1e-2);
			if (++k < 4)
				continue;
			k = 0;
			quads++;
			/* written a b d c: its edges a-b, b-c, c-d, d-a */
			static const int edge[4][2] = {{0, 1}, {1, 3}, {3, 2}, {2, 0}};
			for (int e = 0; e < 4; e++) {
				const double *a = q[edge[e][0]], *c = q[edge[e][1]];
				worst = fmax(worst, fabs(c[2] - a[2]));
				for (int b = 0; b < 2; b++) {
					const double px = b ? 25 : -25;
					const double r_a = hypot(a[0] - px, a[1] - 30) - 35;
					const double r_c = hypot(c[0] - px, c[1] - 30) - 35;
					on_rim += fabs(r_a) < 1e-3;
					if (fabs(r_a) >= 0.1 && fabs(r_c) >= 0.1 &&
					    (r_a < 0) != (r_c < 0))
						fail_msg("%s: an edge (%g, %g) - (%g, %g) across "
						         "beam %d's "
						         "rim",
						         n, a[0], a[1], c[0], c[1], b + 1);
				}
			}
		}
		fclose(f);
		print_message("%s: %d quadrangles, %d corners on a rim, steepest edge %.3g of "
		              "the range\n",
		              names[i], quads, on_rim, worst / (hi - lo));
		assert_int_equal(k, 0);
		assert_true(quads > 1000 && on_rim > 10);
		assert_true(worst < 0.6 * (hi - lo));
	}
}

/* Status 2, stderr holding every needle, and no output directory. */
static void expect_bad(const char *const argv[], const char *dir, const char *const needles[])
{
	char *out = NULL, *err = NULL;
	int rc = bsim_test_cli(argv, &out, &err);
	bsim_test_check_input_error(rc, err, needles, 0);
	assert_true(bsim_test_size(dir) < 0);
	free(out);
	free(err);
}

/* The points of a grid of spacing h over len m: x0 + i h up to x0 + len
 * (landscape.h), counted here from that definition. */
static double points(double len, double h)
{
	return floor(len / h + 1e-9) + 1.0;
}

/* Regression: --resolution 1e-300 said a 300-digit point count. It names
 * --resolution, the count in short, the largest grid allowed and the
 * finest spacing it allows over the region: a spacing that gives at most
 * BSIM_LANDSCAPE_MAX_POINTS points, where 1% finer gives more. */
static void test_resolution_too_fine(void **state)
{
	(void)state;
	const char *base = bsim_test_dir("landscape_fine");
	char gone[1100];
	snprintf(gone, sizeof gone, "%s/never", base);
	const char *argv[] = {"landscape",
	                      bsim_test_src("configs/thesis/gate.yaml"),
	                      "--resolution",
	                      "1e-300",
	                      "--out",
	                      gone,
	                      NULL};
	char *err = NULL;
	int rc = bsim_test_cli(argv, NULL, &err);
	char most[32];
	snprintf(most, sizeof most, "more than the %d", BSIM_LANDSCAPE_MAX_POINTS);
	const char *needles[] = {"--resolution 1e-300: 5e+301 x 6.5e+301 points", most, NULL};
	bsim_test_check_input_error(rc, err, needles, 1);
	assert_true(strlen(err) < 300);
	double w = 0, h = 0, finest = 0;
	const char *region = strstr(err, "over the "), *least = strstr(err, "at least ");
	assert_non_null(region);
	assert_non_null(least);
	assert_int_equal(sscanf(region, "over the %lf x %lf m region", &w, &h), 2);
	assert_int_equal(sscanf(least, "at least %lf m", &finest), 1);
	print_message("the finest spacing over the %g x %g m region: %g m\n", w, h, finest);
	assert_true(points(w, finest) * points(h, finest) <= BSIM_LANDSCAPE_MAX_POINTS);
	assert_true(points(w, 0.99 * finest) * points(h, 0.99 * finest) >
	            BSIM_LANDSCAPE_MAX_POINTS);
	assert_true(bsim_test_size(gone) < 0);
	free(err);
}

static void test_errors(void **state)
{
	(void)state;
	const char *base = bsim_test_dir("landscape_errors");
	char gone[1100];
	snprintf(gone, sizeof gone, "%s/never", base);
	const char *gate = bsim_test_src("configs/thesis/gate.yaml");
	const char *bad = bsim_test_write(base, "bad.yaml",
	                                  "body: { mass: 1, radius: 10 }\n"
	                                  "beams:\n"
	                                  "  - { pivot: [-25, 30], length: 25, mass: 0.1,\n"
	                                  "      stiffness: -4 }\n");
	char bad_path[1100];
	snprintf(bad_path, sizeof bad_path, "%s", bad);
	{
		const char *argv[] = {"landscape", bad_path, "--out", gone, NULL};
		const char *needles[] = {"bad.yaml:4:18: ", "beams.0.stiffness", NULL};
		expect_bad(argv, gone, needles);
	}
	{
		const char *argv[] = {"landscape", gate, "--set", "body.radius=-1",
		                      "--out",     gone, NULL};
		const char *needles[] = {"--set body.radius=-1", "body.radius", NULL};
		expect_bad(argv, gone, needles);
	}
	{
		const char *argv[] = {"landscape", gate, "--resolution", "-1", "--out", gone, NULL};
		const char *needles[] = {"--resolution -1", "spacing > 0", NULL};
		expect_bad(argv, gone, needles);
	}
	{
		const char *argv[] = {"landscape", gate, "--resolution", "0.001", "--out",
		                      gone,        NULL};
		const char *needles[] = {"--resolution 0.001: 50001 x 65001 points", "more than",
		                         NULL};
		expect_bad(argv, gone, needles);
	}
	{
		const char *argv[] = {"landscape", gate, "--region", "1,2,3", "--out", gone, NULL};
		const char *needles[] = {"--region 1,2,3", "X0,X1,Y0,Y1", NULL};
		expect_bad(argv, gone, needles);
	}
	{
		const char *argv[] = {"landscape", gate, "--region", "5,-5,0,65",
		                      "--out",     gone, NULL};
		const char *needles[] = {"--region 5,-5,0,65", "X0 < X1", NULL};
		expect_bad(argv, gone, needles);
	}
	{ /* the far edge at y = 40 m lies within both beams' reach */
		const char *argv[] = {"landscape", gate, "--region", "-25,25,0,40",
		                      "--out",     gone, NULL};
		const char *needles[] = {"far side", "extend the region", NULL};
		expect_bad(argv, gone, needles);
	}
	{
		const char *argv[] = {"landscape", gate, NULL};
		const char *needles[] = {"--out DIR is required", NULL};
		expect_bad(argv, gone, needles);
	}
	{
		const char *argv[] = {"landscape", gate, "--bogus", "--out", gone, NULL};
		const char *needles[] = {"unknown option --bogus", NULL};
		expect_bad(argv, gone, needles);
	}
}

/* ---- gnuplot failing ------------------------------------------------------------ */

/* beamsim landscape into dir with args; its status and one-line stderr
 * (checked to be one line). */
static int landscape_failing(const char *dir, const char *const extra[], char **err)
{
	const char *argv[16] = {"landscape", bsim_test_src("configs/thesis/gate.yaml")};
	int n = 2;
	for (int i = 0; extra[i]; i++)
		argv[n++] = extra[i];
	argv[n++] = "--out";
	argv[n++] = dir;
	argv[n] = NULL;
	char *out = NULL;
	int rc = bsim_test_cli(argv, &out, err);
	print_message("exit %d: %s", rc, *err);
	assert_int_equal(bsim_test_count_lines(*err), 1);
	free(out);
	return rc;
}

/* A gnuplot that fails on the top view (and draws the others): exit 1
 * naming the figure, quoting its line, naming its script and data in DIR;
 * DIR holds the landscape's files, the surfaces drawn, and the top view's
 * script and data but no image. */
static void test_gnuplot_fails(void **state)
{
	(void)state;
	const char *base = bsim_test_dir("landscape_gnuplot_fails");
	char bin[1100], dir[1100];
	snprintf(bin, sizeof bin, "%s/bin", base);
	snprintf(dir, sizeof dir, "%s/out", base);
	char *old = bsim_test_fake_program(
	        bin, "gnuplot",
	        "#!/bin/sh\n"
	        "if [ \"$3\" = landscape_top.gp ]; then\n"
	        "  echo '\"landscape_top.gp\" line 3: the stand-in fails here' >&2; exit 1\n"
	        "fi\n"
	        "PATH=\"${PATH#*:}\" exec gnuplot \"$@\"\n");
	char *err = NULL;
	const char *extra[] = {"--resolution", "1", NULL};
	int rc = landscape_failing(dir, extra, &err);
	bsim_test_path_restore(old);
	assert_int_equal(rc, 1);
	char want[1400];
	snprintf(want, sizeof want,
	         "beamsim: figure landscape_top: gnuplot exited with status 1: "
	         "\"landscape_top.gp\" line 3: the stand-in fails here; its script and data are "
	         "in %s: landscape_top.gp, ",
	         dir);
	assert_non_null(strstr(err, want));
	assert_non_null(strstr(err, "landscape_top.dat"));
	free(err);
	const char *kept[] = {"landscape.csv",       "landscape.json",
	                      "landscape.mat",       "landscape_top.gp",
	                      "landscape_top.dat",   "landscape_beam.png",
	                      "landscape_total.svg", NULL};
	const char *none[] = {"landscape_top.png", "landscape_top.svg", NULL};
	bsim_test_check_committed(dir, kept, none);
}

/* The real gnuplot on a region too wide for it: every energy overflows,
 * and gnuplot refuses the top view and the surface of E_beam (no point of
 * it defined). Exit 1 quoting it; the landscape's tables are committed with
 * the scripts and data. */
static void test_gnuplot_refuses_region(void **state)
{
	(void)state;
	if (!bsim_figure_available())
		skip();
	char dir[1100];
	snprintf(dir, sizeof dir, "%s/out", bsim_test_dir("landscape_region_too_wide"));
	char *err = NULL;
	const char *extra[] = {"--region=-1e300,1e300,-1e300,1e300", NULL};
	assert_int_equal(landscape_failing(dir, extra, &err), 1);
	assert_non_null(strstr(err, "figure landscape_beam: gnuplot exited with status 1: "));
	assert_non_null(strstr(err, "All points x value undefined"));
	assert_non_null(strstr(err, "landscape_beam.gp, landscape_beam.dat"));
	free(err);
	const char *kept[] = {"landscape.csv", "landscape.json", "landscape_beam.gp",
	                      "landscape_beam.dat", NULL};
	const char *none[] = {"landscape_beam.png", NULL};
	bsim_test_check_committed(dir, kept, none);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_csv),
	        cmocka_unit_test(test_mat),
	        cmocka_unit_test(test_figures),
	        cmocka_unit_test(test_options),
	        cmocka_unit_test(test_json_quiet),
	        cmocka_unit_test(test_errors),
	        cmocka_unit_test(test_resolution_too_fine),
	        cmocka_unit_test(test_figure_style),
	        cmocka_unit_test(test_gnuplot_fails),
	        cmocka_unit_test(test_gnuplot_refuses_region),
	};
	return cmocka_run_group_tests(tests, setup, NULL);
}
