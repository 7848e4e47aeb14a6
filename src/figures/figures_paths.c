/* Trajectories drawn: a group's bundle in the plane (essay Fig. 3.2) and
 * the paths over the potential energy landscape (Figs. 2.7, 3.3).
 *
 * Over the landscape a recorded state at (x, y) with beam angles theta_i
 * sits at its own energy
 *   E = F_prop (y0 - y) + sum_i 1/2 k_i theta_i^2,
 * the same E_total as the surface's (docs/model.md section 7) but with the
 * beams' actual angles instead of th_i(x, y), the angle of a beam resting
 * against the body. With every beam that the body can reach in contact the
 * two agree; a beam swung past the body (after an impact) lifts the path
 * above the surface, and a beam left behind while the body is inside its
 * reach (it detached) drops the path below: the "penetration" of the
 * essay's Fig. 2.7. A state is counted below when its beams' energy is
 * short of the landscape's by more than FPATH_BELOW_J. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/landscape.h"
#include "figures/figures_paths.h"
#include "figures/figures_surface.h"
#include "figures/figures_toolkit.h"
#include "util/csv_table.h"
#include "beamsim/limits.h"
#include "util/figure.h"
#include "beamsim/key_names.h"

static const struct {
	const char *name, *color;
	double width;
} classes[FPATH_N] = {
        [FPATH_OTHER] = {"other outcome", FIG_PURPLE, 1.0},
        [FPATH_STUCK] = {"stuck", FIG_DKGREY, 1.0},
        [FPATH_SIDE_EXIT] = {"side exit", FIG_GREY, 1.0},
        [FPATH_NONE] = {"traversed, v_x = 0", BSIM_FIGURE_PATH_NONE, 1.5},
        [FPATH_RIGHT] = {"traversed, right type", BSIM_FIGURE_PATH_RIGHT, 1.5},
        [FPATH_LEFT] = {"traversed, left type", BSIM_FIGURE_PATH_LEFT, 1.5},
};

int bsim_fpath_class(const char *outcome, const char *type)
{
	if (strcmp(outcome, "traversed") == 0)
		return strcmp(type, "left") == 0    ? FPATH_LEFT
		       : strcmp(type, "right") == 0 ? FPATH_RIGHT
		                                    : FPATH_NONE;
	if (strcmp(outcome, "side_exit") == 0)
		return FPATH_SIDE_EXIT;
	if (strcmp(outcome, "stuck") == 0)
		return FPATH_STUCK;
	return FPATH_OTHER;
}

double bsim_fpath_energy(const bsim_scene *s, double y, const double *theta)
{
	double e = bsim_landscape_e_prop(s, y);
	for (int i = 0; i < s->n_beams; i++)
		e += 0.5 * s->beams[i].stiffness * theta[i] * theta[i];
	return e;
}

int bsim_fpath_below(const bsim_scene *s, double x, double y, const double *theta)
{
	const double c[2] = {x, y};
	double e_land;
	bsim_landscape_energy(s, c, NULL, &e_land, NULL);
	double e_beam = bsim_fpath_energy(s, y, theta) - bsim_landscape_e_prop(s, y);
	return e_land - e_beam > FPATH_BELOW_J;
}

void bsim_fpath_params(char *buf, size_t size, const char *backend, const char *const *keys,
                       const char *const *values, int n)
{
	size_t k = 0;
	buf[0] = '\0';
	if (backend && *backend)
		k = (size_t)snprintf(buf, size, "backend %s", backend);
	const int first = k > 0; /* the backend is the line's first item */
	for (int i = 0; i < n && k < size; i++) {
		char kv[200];
		bsim_key_value(keys[i], values[i], 0, kv, sizeof kv);
		/* three items to a line, to fit a figure's width */
		const int item = i + first;
		int m = snprintf(buf + k, size - k, "%s%s",
		                 item == 0       ? ""
		                 : item % 3 == 0 ? ",\n"
		                                 : ", ",
		                 kv);
		if (m < 0)
			break;
		k += (size_t)m;
	}
}

/* ---- reading --------------------------------------------------------------------- */

void bsim_fpaths_free(fpaths *p)
{
	free(p->p);
	free(p->cols);
	memset(p, 0, sizeof *p);
}

int bsim_fpaths_read(const csv_table *t, const char *path, fpaths *out, bsim_error *err)
{
	memset(out, 0, sizeof *out);
	static const char *const need[] = {"t", "x", "y"};
	int col[3];
	int rc = bsim_csv_table_require(t, path, need, 3, col, err);
	if (rc)
		return rc;
	int gc = bsim_csv_table_col(t, "group"), tc = bsim_csv_table_col(t, "trial");
	int nb = 0;
	char name[32];
	for (;; nb++) {
		snprintf(name, sizeof name, "theta%d", nb + 1);
		if (bsim_csv_table_col(t, name) < 0)
			break;
	}
	const size_t n = (size_t)t->n_rows;
	/* t, x, y, group, trial columns, then theta row-major */
	out->cols = malloc((n * (5 + (size_t)nb) + 1) * sizeof *out->cols);
	if (!out->cols)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory reading %s", path);
	out->n_beams = nb;
	double *tt = out->cols, *xx = tt + n, *yy = xx + n, *gg = yy + n, *rr = gg + n,
	       *th = rr + n;
	for (int k = 0; !rc && k < 3; k++)
		rc = bsim_csv_table_numbers(t, path, col[k], 0, 0.0, out->cols + (size_t)k * n,
		                            err);
	if (!rc && gc >= 0)
		rc = bsim_csv_table_numbers(t, path, gc, 0, 0.0, gg, err);
	if (!rc && tc >= 0)
		rc = bsim_csv_table_numbers(t, path, tc, 0, 0.0, rr, err);
	if (gc < 0)
		memset(gg, 0, n * sizeof *gg);
	if (tc < 0)
		memset(rr, 0, n * sizeof *rr);
	double *col_buf = nb ? malloc(n * sizeof *col_buf + 1) : NULL;
	if (nb && !col_buf && !rc)
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory reading %s", path);
	for (int b = 0; !rc && b < nb; b++) {
		snprintf(name, sizeof name, "theta%d", b + 1);
		rc = bsim_csv_table_numbers(t, path, bsim_csv_table_col(t, name), 0, 0.0, col_buf,
		                            err);
		for (size_t r = 0; !rc && r < n; r++)
			th[r * (size_t)nb + (size_t)b] = col_buf[r];
	}
	free(col_buf);
	/* Paths: runs of rows with the same (group, trial). */
	int cap = 0;
	for (size_t r = 0; !rc && r < n;) {
		size_t e = r + 1;
		while (e < n && gg[e] == gg[r] && rr[e] == rr[r])
			e++;
		if (out->n == cap) {
			cap = cap ? 2 * cap : 64;
			fpath *p = realloc(out->p, (size_t)cap * sizeof *p);
			if (!p) {
				rc = bsim_error_set(err, BSIM_EFAIL, "out of memory reading %s",
				                    path);
				break;
			}
			out->p = p;
		}
		out->p[out->n++] = (fpath){
		        .group = (int)gg[r],
		        .trial = (int)rr[r],
		        .cls = FPATH_OTHER,
		        .n = (long)(e - r),
		        .t = tt + r,
		        .x = xx + r,
		        .y = yy + r,
		        .theta = th + r * (size_t)nb,
		};
		r = e;
	}
	if (rc)
		bsim_fpaths_free(out);
	return rc;
}

/* ---- the scene in a figure ---------------------------------------------------------- */

/* The beams at rest, their pivots, the body at its start and the
 * boundaries, as gnuplot objects (for a 2-D plot or a map view). */
static void scene_objects(FILE *f, const bsim_scene *s)
{
	for (int i = 0; i < s->n_beams; i++) {
		const bsim_beam_def *b = &s->beams[i];
		double u[2];
		bsim_scene_beam_rest_direction(b, u);
		fprintf(f,
		        "set arrow from %g,%g to %g,%g nohead front lw 3 lc rgb '%s'\n"
		        "set object circle at %g,%g size 0.9 front fc rgb '%s' fs solid 1.0\n",
		        b->pivot[0], b->pivot[1], b->pivot[0] + b->length * u[0],
		        b->pivot[1] + b->length * u[1], FIG_BLACK, b->pivot[0], b->pivot[1],
		        FIG_BLACK);
	}
	fprintf(f,
	        "set object circle at %g,%g size %g front fs empty border lc rgb '%s' dt 2\n"
	        "set arrow from %g,%g to %g,%g nohead front dt 3 lc rgb '%s'\n"
	        "set arrow from %g,graph 0 to %g,graph 1 nohead front dt 3 lc rgb '%s'\n"
	        "set arrow from %g,graph 0 to %g,graph 1 nohead front dt 3 lc rgb '%s'\n",
	        s->body.start[0], s->body.start[1], s->body.radius, FIG_DKGREY, -s->side_x,
	        s->success_y, s->side_x, s->success_y, FIG_DKGREY, -s->side_x, -s->side_x,
	        FIG_DKGREY, s->side_x, s->side_x, FIG_DKGREY);
}

/* The plane shown: the side boundaries and a margin, from below the start
 * to classify_y. */
static void scene_box(const bsim_scene *s, double box[4])
{
	double y0 = s->body.start[1] - s->body.radius;
	for (int i = 0; i < s->n_beams; i++)
		y0 = fmin(y0, s->beams[i].pivot[1] - s->beams[i].length);
	box[0] = -s->side_x - 3.0;
	box[1] = s->side_x + 3.0;
	box[2] = fmin(y0, 0.0) - 2.0;
	box[3] = s->classify_y + 2.0;
}

/* ---- thinning ------------------------------------------------------------------------- */

/* A drawn path leaves out a row within step_m of the last row drawn (and,
 * over the landscape, within step_j in E) unless it ends the path or goes
 * below the surface or back. In the bundle 0.5 m is 4 pixels of a
 * 700-pixel plot of 95 m; over the landscape, where the plane is 500
 * pixels tall and each path is drawn twice in both panels (its white
 * outline, then its colour), 0.8 m is 4 pixels. Both keep the SVG of a
 * hundred paths under 1 MB. The recorded rows are all in the trajectory
 * file. */
#define BUNDLE_STEP_M 0.5
#define OVER_STEP_M   0.8
#define OVER_STEP_J   8.0

typedef struct thin {
	double x, y, e;
	int below, started;
} thin;

static int thin_keep(thin *t, double x, double y, double e, int below, int last, double step_m,
                     double step_j)
{
	int keep = !t->started || last || below != t->below ||
	           hypot(x - t->x, y - t->y) >= step_m || fabs(e - t->e) >= step_j;
	if (keep)
		*t = (thin){x, y, e, below, 1};
	return keep;
}

/* ---- Fig. 3.2: the bundle ------------------------------------------------------------ */

int bsim_figs_bundle(figs *f, const char *name, const char *title, const bsim_scene *scene,
                     const fpath *p, int n, bsim_error *err)
{
	char file[200], path[BSIM_PATH_MAX];
	snprintf(file, sizeof file, "%s.dat", name);
	bsim_atomic_file o;
	int rc = bsim_figs_data_open(f, file, &o, path, err);
	if (rc)
		return rc;
	int count[FPATH_N] = {0}, block[FPATH_N], n_blocks = 0;
	for (int i = 0; i < n; i++)
		count[p[i].cls]++;
	fputs("# x y (m): the trajectories of each class, one block per class (gnuplot index),\n"
	      "# one blank line between trials\n",
	      o.f);
	for (int c = 0; c < FPATH_N; c++) {
		block[c] = -1;
		if (!count[c])
			continue;
		fprintf(o.f, "%s# %s\n", n_blocks ? "\n\n" : "", classes[c].name);
		block[c] = n_blocks++;
		int first = 1;
		for (int i = 0; i < n; i++) {
			if (p[i].cls != c)
				continue;
			fprintf(o.f, "%s# group %d trial %d\n", first ? "" : "\n", p[i].group,
			        p[i].trial);
			first = 0;
			thin t = {0};
			for (long k = 0; k < p[i].n; k++)
				if (thin_keep(&t, p[i].x[k], p[i].y[k], 0.0, 0, k == p[i].n - 1,
				              BUNDLE_STEP_M, INFINITY))
					fprintf(o.f, "%.6g %.6g\n", p[i].x[k], p[i].y[k]);
		}
	}
	if ((rc = bsim_figs_data_commit(&o, err)))
		return rc;

	gp_text g;
	if ((rc = bsim_gp_text_open(&g, err)))
		return rc;
	double box[4];
	scene_box(scene, box);
	fputs("set title ", g.f);
	bsim_gp_str(g.f, title);
	fprintf(g.f,
	        " noenhanced\nset size ratio -1\nset xrange [%g:%g]\nset yrange [%g:%g]\n"
	        "set xlabel 'x (m)'\nset ylabel 'y (m)'\nset key below maxrows 3\n",
	        box[0], box[1], box[2], box[3]);
	scene_objects(g.f, scene);
	fputs("plot ", g.f);
	int k = 0;
	for (int c = 0; c < FPATH_N; c++) {
		if (block[c] < 0)
			continue;
		fprintf(g.f,
		        "%s'%s' index %d using 1:2 with lines lw %g lc rgb '%s' title '%s (%d)'",
		        k++ ? ", \\\n     " : "", file, block[c], classes[c].width,
		        classes[c].color, classes[c].name, count[c]);
	}
	if (!k)
		fputs("NaN notitle", g.f);
	fputc('\n', g.f);
	char *body = bsim_gp_text_take(&g);
	rc = body ? bsim_figs_render(f, name, 720, 900, body, err)
	          : bsim_error_set(err, BSIM_EFAIL, "out of memory");
	free(body);
	return rc;
}

/* ---- Figs. 2.7 and 3.3: over the landscape ------------------------------------------- */

/* Polygons of the 3-D surface: about 110 bytes of SVG each, so that with
 * the map and a hundred paths the SVG stays under 1 MB. */
#define SURFACE_POLYGONS 3500

/* The surface E_total(x, y) on a grid of about 0.5 m over the shown plane,
 * one y row per block (gnuplot's grid format): x y E_total, E_drawn (cut
 * at cap, for the map: near a pivot th(x, y) nears pi and E_total climbs
 * to thousands of joules where no path goes); and in mesh, the 3-D surface
 * up to cap as polygons that end along the landscape's steps, the pivots
 * and the cap (figures/figures_surface.h). e_min gets the lowest value. */
static int surface_write(figs *f, const char *file, const char *mesh, const bsim_scene *s,
                         const double box[4], double cap, double *e_min, bsim_error *err)
{
	const int nx = 101;
	const double dx = (box[1] - box[0] - 6.0) / (nx - 1);
	const int ny = (int)ceil((box[3] - box[2]) / dx) + 1;
	const double dy = (box[3] - box[2]) / (ny - 1);
	double *e = malloc((size_t)nx * (size_t)ny * sizeof *e);
	if (!e)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	*e_min = INFINITY;
	for (int j = 0; j < ny; j++)
		for (int i = 0; i < nx; i++) {
			const double c[2] = {box[0] + 3.0 + i * dx, box[2] + j * dy};
			const size_t k = (size_t)j * (size_t)nx + (size_t)i;
			e[k] = bsim_landscape_energy(s, c, NULL, NULL, NULL);
			*e_min = fmin(*e_min, e[k]);
		}
	char path[BSIM_PATH_MAX];
	bsim_atomic_file o;
	int rc = bsim_figs_data_open(f, file, &o, path, err);
	if (!rc) {
		fprintf(o.f,
		        "# x y (m), E_total (J): the landscape F_prop (y0 - y) + sum 1/2 k "
		        "th(x, y)^2,\n# then E_total as drawn on the map, cut at %.6g J\n",
		        cap);
		for (int j = 0; j < ny; j++) {
			for (int i = 0; i < nx; i++) {
				const size_t k = (size_t)j * (size_t)nx + (size_t)i;
				fprintf(o.f, "%.5g %.5g %.6g %.6g\n", box[0] + 3.0 + i * dx,
				        box[2] + j * dy, e[k], fmin(e[k], cap));
			}
			fputc('\n', o.f);
		}
		rc = bsim_figs_data_commit(&o, err);
	}
	free(e);
	if (!rc)
		rc = bsim_figs_data_open(f, mesh, &o, path, err);
	if (rc)
		return rc;
	fprintf(o.f,
	        "# x y (m), E_total (J): the surface up to %.6g J as polygons, each two scans of "
	        "two\n# points (gnuplot pm3d), cut along the steps, the pivots and that level\n",
	        cap);
	const fsurface d = {.region = {box[0] + 3.0, box[1] - 3.0, box[2], box[3]},
	                    .cap = cap,
	                    .e_min = *e_min,
	                    .beam_only = 0,
	                    .max_polygons = SURFACE_POLYGONS};
	long polygons = 0;
	rc = bsim_fsurface_write(o.f, s, &d, &polygons, err);
	if (!rc && polygons == 0) /* gnuplot needs a point in a file it plots */
		fputs("NaN NaN NaN\n", o.f);
	if (rc) {
		bsim_atomic_file_abort(&o);
		return rc;
	}
	return bsim_figs_data_commit(&o, err);
}

/* Where the surface is cut: a quarter above the highest energy the paths
 * reach, on the surface or along them, and never below the energy at the
 * start. */
static double surface_cap(const bsim_scene *s, const fpath *p, int n, unsigned mask)
{
	double top = bsim_landscape_energy(s, s->body.start, NULL, NULL, NULL);
	for (int i = 0; i < n; i++) {
		if (!(mask & 1u << p[i].cls))
			continue;
		for (long k = 0; k < p[i].n; k++) {
			const double c[2] = {p[i].x[k], p[i].y[k]};
			const double *th = p[i].theta + (size_t)k * (size_t)s->n_beams;
			top = fmax(top, bsim_landscape_energy(s, c, NULL, NULL, NULL));
			top = fmax(top, bsim_fpath_energy(s, c[1], th));
		}
	}
	return 1.25 * top;
}

/* The paths' data: block 0 every path (x, y, E), thinned, a blank line
 * between paths; block 1 the stretches below the surface, every state of
 * them and the state before, so that each joins its path. Counts the
 * states below, of all recorded. */
static int paths_write(figs *f, const char *file, const bsim_scene *s, const fpath *p, int n,
                       unsigned mask, long *below, long *total, bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	bsim_atomic_file o;
	int rc = bsim_figs_data_open(f, file, &o, path, err);
	if (rc)
		return rc;
	const int nb = s->n_beams;
	*below = *total = 0;
	fputs("# block 0: x y (m) E (J) of each path: F_prop (y0 - y) + sum 1/2 k theta^2 with\n"
	      "# the recorded angles, class (FPATH order), below (1: under the surface)\n",
	      o.f);
	int first = 1;
	for (int i = 0; i < n; i++) {
		if (!(mask & 1u << p[i].cls))
			continue;
		fprintf(o.f, "%s# group %d trial %d\n", first ? "" : "\n", p[i].group, p[i].trial);
		first = 0;
		thin t = {0};
		for (long k = 0; k < p[i].n; k++) {
			const double *th = p[i].theta + (size_t)k * (size_t)nb;
			int b = bsim_fpath_below(s, p[i].x[k], p[i].y[k], th);
			double e = bsim_fpath_energy(s, p[i].y[k], th);
			*below += b;
			if (thin_keep(&t, p[i].x[k], p[i].y[k], e, b, k == p[i].n - 1, OVER_STEP_M,
			              OVER_STEP_J))
				fprintf(o.f, "%.6g %.6g %.6g %d %d\n", p[i].x[k], p[i].y[k], e,
				        p[i].cls, b);
		}
		*total += p[i].n;
	}
	fputs("\n\n# block 1: the stretches below the surface, x y E\n", o.f);
	int any = 0;
	for (int i = 0; i < n; i++) {
		if (!(mask & 1u << p[i].cls))
			continue;
		int in = 0;
		for (long k = 0; k < p[i].n; k++) {
			const double *th = p[i].theta + (size_t)k * (size_t)nb;
			int b = bsim_fpath_below(s, p[i].x[k], p[i].y[k], th);
			long from = k > 0 ? k - 1 : k;
			if (b && !in) { /* a stretch starts: from the state before */
				fputs(any ? "\n" : "", o.f);
				const double *t0 = p[i].theta + (size_t)from * (size_t)nb;
				fprintf(o.f, "%.6g %.6g %.6g\n", p[i].x[from], p[i].y[from],
				        bsim_fpath_energy(s, p[i].y[from], t0));
				any = 1;
			}
			if (b || in)
				fprintf(o.f, "%.6g %.6g %.6g\n", p[i].x[k], p[i].y[k],
				        bsim_fpath_energy(s, p[i].y[k], th));
			in = b;
		}
	}
	if (!any) /* gnuplot needs a point in every block it plots */
		fputs("NaN NaN NaN\n", o.f);
	return bsim_figs_data_commit(&o, err);
}

/* A class's colour over the landscape: the traversals in the landscapes'
 * path colours (util/figure.h), the rest orange, none of them grey or
 * blue-green like the map. */
static const char *class_color_over(int c)
{
	switch (c) {
	case FPATH_LEFT:
		return BSIM_FIGURE_PATH_LEFT;
	case FPATH_RIGHT:
		return BSIM_FIGURE_PATH_RIGHT;
	case FPATH_NONE:
		return BSIM_FIGURE_PATH_NONE;
	default:
		return FIG_ORANGE;
	}
}

int bsim_figs_over_landscape(figs *f, const char *name, const char *title, const bsim_scene *scene,
                             const fpath *p, int n, unsigned mask, bsim_error *err)
{
	char surf[200], mesh[200], file[200];
	snprintf(surf, sizeof surf, "%s.surface.dat", name);
	snprintf(mesh, sizeof mesh, "%s.mesh.dat", name);
	snprintf(file, sizeof file, "%s.dat", name);
	double box[4], e_min = 0.0, e_max = surface_cap(scene, p, n, mask);
	long below, total;
	scene_box(scene, box);
	int rc = surface_write(f, surf, mesh, scene, box, e_max, &e_min, err);
	if (!rc)
		rc = paths_write(f, file, scene, p, n, mask, &below, &total, err);
	if (rc)
		return rc;
	int count[FPATH_N] = {0};
	for (int i = 0; i < n; i++)
		count[p[i].cls] += (mask & 1u << p[i].cls) != 0;

	gp_text g;
	if ((rc = bsim_gp_text_open(&g, err)))
		return rc;
	FILE *s = g.f;
	/* Two panels side by side, placed by hand: (a) as tall as the plane
	 * at 1:1, its colour bar at its right, (b) from there to the right
	 * edge, so that no strip of the figure stays empty. */
	fputs("set multiplot title ", s);
	bsim_gp_str(s, title);
	fprintf(s,
	        " noenhanced\n" BSIM_FIGURE_LANDSCAPE_PALETTE
	        "set cbrange [%g:%g]\nset cblabel '" BSIM_FIGURE_LANDSCAPE_CBLABEL "'\n"
	        "# (a) from above: the landscape, its contours every 50 J, the paths\n"
	        "set origin 0,0\nset size 0.42,0.9\nset colorbox\n"
	        "set title '(a) from above; below the surface in black'\n"
	        "set view map\nset size ratio -1\nset xrange [%g:%g]\nset yrange [%g:%g]\n"
	        "set xlabel 'x (m)'\nset ylabel 'y (m)'\nunset key\n"
	        "set contour base\nunset clabel\nset cntrparam levels incremental %g,50,%g\n",
	        e_min, e_max, box[0] + 3.0, box[1] - 3.0, box[2], box[3], 50.0 * floor(e_min / 50),
	        e_max);
	scene_objects(s, scene);
	fprintf(s,
	        "splot '%s' using 1:2:4 with image, \\\n"
	        "      '' using 1:2:4 with lines nosurface lw 0.5 lc rgb '#80404040', \\\n",
	        surf);
	/* every class over a white outline first, then the class's colour */
	for (int c = 0; c < FPATH_N; c++)
		if (count[c])
			fprintf(s,
			        "      '%s' index 0 using 1:2:($4 == %d ? 0 : NaN) with lines "
			        "nocontour lw %g lc rgb '" BSIM_FIGURE_PATH_OUTLINE "', \\\n",
			        file, c, classes[c].width + 2.5);
	for (int c = 0; c < FPATH_N; c++)
		if (count[c])
			fprintf(s,
			        "      '%s' index 0 using 1:2:($4 == %d ? 0 : NaN) with lines "
			        "nocontour lw %g lc rgb '%s', \\\n",
			        file, c, classes[c].width, class_color_over(c));
	fprintf(s,
	        "      '%s' index 1 using 1:2:(0) with lines nocontour lw 2.5 lc rgb '%s'\n"
	        "unset contour\nunset arrow\nunset object\n",
	        file, FIG_BLACK);
	/* (b): the surface, then the paths in a second plot over it with the
	 * same view and ranges: pm3d draws its depth-sorted quadrangles after
	 * every line of its plot, so that in one plot the paths would be
	 * under a translucent surface. */
	fprintf(s,
	        "# (b) in 3-D: the surface up to the top of the colours, ending along its\n"
	        "# steps; then, over it, each path at its own energy, a stretch below the\n"
	        "# surface in black\n"
	        "set origin 0.36,0.06\nset size 0.64,0.84\nunset colorbox\n"
	        "set title '(b) E along the paths over the surface E_{total}(x, y)'\n"
	        "set view 55,300,1,1.05\nset size noratio\nset xyplane relative 0.1\n"
	        "set zlabel 'E (J)' rotate parallel\nset zrange [%g:%g]\n"
	        "set pm3d depthorder lighting primary 0.5 specular 0\n"
	        "splot '%s' using 1:2:3 with pm3d notitle\n"
	        "unset title\nunset border\nunset tics\nunset xlabel\nunset ylabel\n"
	        "unset zlabel\nunset grid\n"
	        "set key at screen 0.99, screen 0.05 right bottom horizontal maxrows 1\n"
	        "splot ",
	        e_min, e_max, mesh);
	int k = 0;
	for (int c = 0; c < FPATH_N; c++)
		if (count[c])
			fprintf(s,
			        "%s'%s' index 0 using 1:2:($4 == %d ? $3 : NaN) with lines lw %g "
			        "lc rgb '" BSIM_FIGURE_PATH_OUTLINE "' notitle",
			        k++ ? ", \\\n      " : "", file, c, classes[c].width + 2.0);
	for (int c = 0; c < FPATH_N; c++)
		if (count[c])
			fprintf(s,
			        "%s'%s' index 0 using 1:2:($4 == %d ? $3 : NaN) with lines lw %g "
			        "lc rgb '%s' title '%s (%d)'",
			        k++ ? ", \\\n      " : "", file, c, classes[c].width,
			        class_color_over(c), classes[c].name, count[c]);
	fprintf(s,
	        "%s'%s' index 1 using 1:2:3 with lines lw 2.5 lc rgb '%s' "
	        "title 'below the surface: %.0f%% of the states'\n"
	        "unset multiplot\n",
	        k ? ", \\\n      " : "", file, FIG_BLACK,
	        total ? 100.0 * (double)below / (double)total : 0.0);
	char *body = bsim_gp_text_take(&g);
	rc = body ? bsim_figs_render(f, name, 1400, 760, body, err)
	          : bsim_error_set(err, BSIM_EFAIL, "out of memory");
	free(body);
	return rc;
}
