/* The files of a landscape (beamsim/landscape.h): the grid as CSV and as
 * a MATLAB struct, the barriers as JSON, and three figures drawn by
 * gnuplot (figure.h): the top view (essay Fig. 2.6c) and the 3-D surface
 * without and with the propulsive term (Fig. 2.6a, b; d is the same for
 * an asymmetric gate).
 *
 * The top view reads a gnuplot "nonuniform matrix" file (first row: the
 * count and the x of each column; then per row its y and the values) at
 * the grid's full resolution; points where the body cannot be (overlapping
 * a pivot) are drawn as walls at the clip level. The surfaces are polygons
 * that end along the landscape's steps (figures/figures_surface.h), at
 * most SURFACE_POLYGONS, so that an SVG of them stays under 1 MB. Colours
 * and heights are clipped a little above the highest pass, so that the
 * barriers, not the walls beside the pivots, set the scale; the titles say
 * where. */
#define _POSIX_C_SOURCE 200809L
#include "beamsim/landscape.h"
#include "beamsim/landscape_barriers.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "util/atomic_file.h"
#include "util/json.h"
#include "util/figure.h"
#include "figures/figures_surface.h"
#include "beamsim/key_names.h"
#include "store/mat.h"
#include "beamsim/limits.h"

/* Most polygons of a 3-D surface: an SVG spends about 100 bytes on each (a
 * lit fill, no mesh lines, which would triple it), so 5000 keep it under
 * 0.6 MB. */
enum { SURFACE_POLYGONS = 5000 };

/* dir/name into buf. */
static int file_path(char *buf, size_t size, const char *dir, const char *name, bsim_error *err)
{
	if ((size_t)snprintf(buf, size, "%s/%s", dir, name) >= size)
		return bsim_error_set(err, BSIM_EFAIL, "%s/%s: path too long", dir, name);
	return BSIM_OK;
}

static size_t grid_points(const bsim_landscape_grid *g)
{
	return (size_t)g->nx * (size_t)g->ny;
}

/* ---- landscape.csv ------------------------------------------------------ */

static int write_csv(const char *dir, const bsim_landscape_grid *g, bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	int rc = file_path(path, sizeof path, dir, "landscape.csv", err);
	bsim_atomic_file o;
	if (rc || (rc = bsim_atomic_file_open(&o, path, err)))
		return rc;
	const size_t n = grid_points(g);
	fputs("x,y,e_beam,e_prop,e_total", o.f);
	for (int b = 0; b < g->n_beams; b++)
		fprintf(o.f, ",theta%d", b + 1);
	fputc('\n', o.f);
	for (int j = 0; j < g->ny; j++)
		for (int i = 0; i < g->nx; i++) {
			const size_t k = (size_t)j * (size_t)g->nx + (size_t)i;
			fprintf(o.f, "%.10g,%.10g,%.10g,%.10g,%.10g", g->x0 + i * g->spacing,
			        g->y0 + j * g->spacing, g->e_beam[k], g->e_prop[k], g->e_total[k]);
			for (int b = 0; b < g->n_beams; b++)
				fprintf(o.f, ",%.10g", g->theta[(size_t)b * n + k]);
			fputc('\n', o.f);
		}
	return bsim_atomic_file_commit(&o, err);
}

/* ---- The barrier table, shared by the MAT file and the printout --------- */

/* Row 0 is the lowest pass (over any beam), row 1 + b beam b's. */
static const bsim_landscape_pass *table_row(const bsim_landscape_barriers *br, int r)
{
	return r == 0 ? &br->lowest : &br->beam[r - 1];
}

/* ---- landscape.mat ------------------------------------------------------- */

enum { TABLE_COLUMNS = 19 };

static int write_mat(const char *dir, const bsim_scene *s, const bsim_landscape_grid *g,
                     const bsim_landscape_barriers *br, bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	int rc = file_path(path, sizeof path, dir, "landscape.mat", err);
	if (rc)
		return rc;
	const size_t n = grid_points(g);
	const int nb = g->n_beams, rows = 1 + br->n_beams;
	double *xy = malloc(2 * n * sizeof *xy);
	double *tab = malloc((size_t)TABLE_COLUMNS * (size_t)rows * sizeof *tab);
	char(*names)[16] = malloc((size_t)(nb > 0 ? nb : 1) * sizeof *names);
	bsim_mat_field *f = malloc((size_t)(nb + 16) * sizeof *f);
	const char **kinds = malloc((size_t)rows * sizeof *kinds);
	if (!xy || !tab || !names || !f || !kinds) {
		free(xy);
		free(tab);
		free(names);
		free(f);
		free(kinds);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	for (int j = 0; j < g->ny; j++)
		for (int i = 0; i < g->nx; i++) {
			const size_t k = (size_t)j * (size_t)g->nx + (size_t)i;
			xy[k] = g->x0 + i * g->spacing;
			xy[n + k] = g->y0 + j * g->spacing;
		}
	/* The barrier table: a struct of columns, row 0 the lowest pass. */
	static const char *const col[TABLE_COLUMNS] = {
	        "over",           "crossed",       "x",       "y",           "e_total",
	        "e_beam",         "e_prop",        "height",  "above_start", "floor_x",
	        "floor_y",        "floor_e",       "grid_x",  "grid_y",      "grid_e",
	        "refine_spacing", "refine_change", "start_e", "far_y"};
	for (int r = 0; r < rows; r++) {
		const bsim_landscape_pass *p = table_row(br, r);
		const double v[TABLE_COLUMNS] = {r,
		                                 p->beam >= 0 ? p->beam + 1 : 0,
		                                 p->x,
		                                 p->y,
		                                 p->e_total,
		                                 p->e_beam,
		                                 p->e_prop,
		                                 p->height,
		                                 p->above_start,
		                                 p->floor[0],
		                                 p->floor[1],
		                                 p->floor_e,
		                                 p->grid_x,
		                                 p->grid_y,
		                                 p->grid_e,
		                                 p->refine_spacing,
		                                 p->refine_change,
		                                 br->start_e,
		                                 br->far_y};
		for (int c = 0; c < TABLE_COLUMNS; c++)
			tab[(size_t)c * (size_t)rows + (size_t)r] =
			        p->kind == BSIM_PASS_NONE && c >= 2 && c < 17 ? NAN : v[c];
		kinds[r] = bsim_landscape_pass_kind_name(p->kind);
	}
	bsim_mat_field tcols[TABLE_COLUMNS + 1];
	for (int c = 0; c < TABLE_COLUMNS; c++)
		tcols[c] = bsim_mat_column(col[c], tab + (size_t)c * (size_t)rows, (size_t)rows);
	tcols[TABLE_COLUMNS] = bsim_mat_strings("kind", kinds, (size_t)rows);

	const double nxd = g->nx, nyd = g->ny, h = g->spacing;
	const char *scene_path[1] = {s->path}, *scene_name[1] = {s->name};
	int m = 0;
	f[m++] = bsim_mat_column("x", xy, n);
	f[m++] = bsim_mat_column("y", xy + n, n);
	f[m++] = bsim_mat_column("e_beam", g->e_beam, n);
	f[m++] = bsim_mat_column("e_prop", g->e_prop, n);
	f[m++] = bsim_mat_column("e_total", g->e_total, n);
	for (int b = 0; b < nb; b++) {
		snprintf(names[b], sizeof names[b], "theta%d", b + 1);
		f[m++] = bsim_mat_column(names[b], g->theta + (size_t)b * n, n);
	}
	f[m++] = bsim_mat_column("nx", &nxd, 1);
	f[m++] = bsim_mat_column("ny", &nyd, 1);
	f[m++] = bsim_mat_column("spacing", &h, 1);
	f[m++] = bsim_mat_matrix("region", g->region, 1, 4);
	f[m++] = bsim_mat_string("scene", scene_path);
	f[m++] = bsim_mat_string("name", scene_name);
	f[m++] = bsim_mat_struct("barriers", tcols, TABLE_COLUMNS + 1);
	bsim_mat_field var = bsim_mat_struct("landscape", f, m);
	rc = bsim_mat_write(path, &var, 1, err);
	free(xy);
	free(tab);
	free(names);
	free(f);
	free(kinds);
	return rc;
}

/* ---- landscape.json ------------------------------------------------------ */

static void json_key_number(FILE *f, const char *key, double v, int comma)
{
	fprintf(f, "%s\"%s\": ", comma ? ", " : "", key);
	bsim_json_number(f, v);
}

static void json_point(FILE *f, const char *key, double x, double y, double e)
{
	fprintf(f, ", \"%s\": {", key);
	json_key_number(f, "x", x, 0);
	json_key_number(f, "y", y, 1);
	json_key_number(f, "e_total", e, 1);
	fputc('}', f);
}

static void json_pass(FILE *f, const bsim_landscape_pass *p)
{
	fputs("{\"kind\": ", f);
	bsim_json_string(f, bsim_landscape_pass_kind_name(p->kind));
	fputs(", \"crossed\": ", f);
	if (p->beam >= 0)
		fprintf(f, "%d", p->beam + 1);
	else
		fputs("null", f);
	if (p->kind == BSIM_PASS_NONE) {
		fputc('}', f);
		return;
	}
	json_key_number(f, "x", p->x, 1);
	json_key_number(f, "y", p->y, 1);
	json_key_number(f, "e_total", p->e_total, 1);
	json_key_number(f, "e_beam", p->e_beam, 1);
	json_key_number(f, "e_prop", p->e_prop, 1);
	json_key_number(f, "height", p->height, 1);
	json_key_number(f, "above_start", p->above_start, 1);
	json_point(f, "floor", p->floor[0], p->floor[1], p->floor_e);
	json_point(f, "grid", p->grid_x, p->grid_y, p->grid_e);
	json_key_number(f, "refine_spacing", p->refine_spacing, 1);
	json_key_number(f, "refine_change", p->refine_change, 1);
	fputs(", \"path\": [", f);
	for (int i = 0; i < p->n_path; i++) {
		fputs(i ? ", [" : "[", f);
		bsim_json_number(f, p->path[2 * i]);
		fputs(", ", f);
		bsim_json_number(f, p->path[2 * i + 1]);
		fputc(']', f);
	}
	fputs("]}", f);
}

static int write_json(const char *dir, const bsim_scene *s, const bsim_landscape_grid *g,
                      const bsim_landscape_barriers *br, bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	int rc = file_path(path, sizeof path, dir, "landscape.json", err);
	bsim_atomic_file o;
	if (rc || (rc = bsim_atomic_file_open(&o, path, err)))
		return rc;
	FILE *f = o.f;
	fputs("{\"scene\": ", f);
	bsim_json_string(f, s->path);
	fputs(", \"name\": ", f);
	bsim_json_string(f, s->name);
	fputs(",\n \"grid\": {", f);
	json_key_number(f, "x0", g->x0, 0);
	json_key_number(f, "x1", g->x0 + (g->nx - 1) * g->spacing, 1);
	json_key_number(f, "y0", g->y0, 1);
	json_key_number(f, "y1", g->y0 + (g->ny - 1) * g->spacing, 1);
	json_key_number(f, "spacing", g->spacing, 1);
	fprintf(f, ", \"nx\": %d, \"ny\": %d}", g->nx, g->ny);
	fputs(",\n \"f_prop\": ", f);
	bsim_json_number(f, s->effects.has_propulsion ? s->effects.propulsion_force : 0.0);
	json_key_number(f, "y0", s->landscape_y0, 1);
	json_key_number(f, "radius", s->body.radius, 1);
	fputs(",\n \"beams\": [", f);
	for (int b = 0; b < s->n_beams; b++) {
		const bsim_beam_def *d = &s->beams[b];
		fprintf(f, "%s{\"beam\": %d, \"pivot\": [", b ? ", " : "", b + 1);
		bsim_json_number(f, d->pivot[0]);
		fputs(", ", f);
		bsim_json_number(f, d->pivot[1]);
		fputc(']', f);
		json_key_number(f, "rest_angle_deg", d->rest_angle_deg, 1);
		json_key_number(f, "length", d->length, 1);
		json_key_number(f, "stiffness", d->stiffness, 1);
		fputc('}', f);
	}
	fputs("],\n \"start\": {", f);
	json_key_number(f, "x", br->start[0], 0);
	json_key_number(f, "y", br->start[1], 1);
	json_key_number(f, "e_total", br->start_e, 1);
	fputs("},\n \"far_y\": ", f);
	bsim_json_number(f, br->far_y);
	fputs(",\n \"lowest_pass\": ", f);
	json_pass(f, &br->lowest);
	fputs(",\n \"barriers\": [", f);
	for (int b = 0; b < br->n_beams; b++) {
		fprintf(f, "%s\n  {\"beam\": %d, \"pass\": ", b ? "," : "", b + 1);
		json_pass(f, &br->beam[b]);
		fputc('}', f);
	}
	fputs("]}\n", f);
	return bsim_atomic_file_commit(&o, err);
}

/* ---- Figures ----------------------------------------------------------------- */

/* Where the body cannot be: overlapping a pivot. */
static int on_pivot(const bsim_scene *s, double x, double y)
{
	for (int b = 0; b < s->n_beams; b++) {
		const double dx = x - s->beams[b].pivot[0], dy = y - s->beams[b].pivot[1];
		if (dx * dx + dy * dy < s->body.radius * s->body.radius)
			return 1;
	}
	return 0;
}

/* A nonuniform matrix of values v (the grid's layout) at every stride-th
 * point, with the last row and column always included; points where the
 * body would overlap a pivot get `wall`. */
static int write_matrix(const char *dir, const char *name, const bsim_scene *s,
                        const bsim_landscape_grid *g, const double *v, int stride, double wall,
                        bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	int rc = file_path(path, sizeof path, dir, name, err);
	bsim_atomic_file o;
	if (rc || (rc = bsim_atomic_file_open(&o, path, err)))
		return rc;
	int ni = 0, nj = 0;
	for (int i = 0; i < g->nx;
	     i = i + stride < g->nx || i == g->nx - 1 ? i + stride : g->nx - 1)
		ni++;
	for (int j = 0; j < g->ny;
	     j = j + stride < g->ny || j == g->ny - 1 ? j + stride : g->ny - 1)
		nj++;
	fprintf(o.f, "%d", ni);
	for (int i = 0; i < g->nx;
	     i = i + stride < g->nx || i == g->nx - 1 ? i + stride : g->nx - 1)
		fprintf(o.f, " %.8g", g->x0 + i * g->spacing);
	fputc('\n', o.f);
	for (int j = 0; j < g->ny;
	     j = j + stride < g->ny || j == g->ny - 1 ? j + stride : g->ny - 1) {
		const double y = g->y0 + j * g->spacing;
		fprintf(o.f, "%.8g", y);
		for (int i = 0; i < g->nx;
		     i = i + stride < g->nx || i == g->nx - 1 ? i + stride : g->nx - 1) {
			const double x = g->x0 + i * g->spacing;
			if (on_pivot(s, x, y))
				fprintf(o.f, " %.6g", wall);
			else
				fprintf(o.f, " %.6g", v[(size_t)j * (size_t)g->nx + (size_t)i]);
		}
		fputc('\n', o.f);
	}
	(void)nj;
	return bsim_atomic_file_commit(&o, err);
}

/* The paths of least resistance, one block per pass (gnuplot index),
 * lowest first: x, y, E_total, E_beam. */
static int write_paths(const char *dir, const bsim_scene *s, const bsim_landscape_barriers *br,
                       bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	int rc = file_path(path, sizeof path, dir, "landscape_paths.dat", err);
	bsim_atomic_file o;
	if (rc || (rc = bsim_atomic_file_open(&o, path, err)))
		return rc;
	fputs("# x y e_total e_beam: the path of least resistance of each pass, lowest first\n",
	      o.f);
	for (int r = 0; r <= br->n_beams; r++) {
		const bsim_landscape_pass *p = table_row(br, r);
		fprintf(o.f, "# %s%s\n", r == 0 ? "lowest pass" : "over beam ", "");
		for (int i = 0; i < p->n_path; i++) {
			const double c[2] = {p->path[2 * i], p->path[2 * i + 1]};
			double eb;
			const double e = bsim_landscape_energy(s, c, NULL, &eb, NULL);
			fprintf(o.f, "%.8g %.8g %.8g %.8g\n", c[0], c[1], e, eb);
		}
		if (p->n_path == 0) /* an empty block keeps the indices in step */
			fputs("NaN NaN NaN NaN\n", o.f);
		fputs("\n\n", o.f);
	}
	return bsim_atomic_file_commit(&o, err);
}

/* Text for a gnuplot string: quotes, backslashes and control characters
 * replaced, at most size - 1 bytes. */
static void gp_text(char *out, size_t size, const char *s)
{
	size_t n = 0;
	for (; *s && n + 1 < size; s++)
		out[n++] = (*s == '"' || *s == '\\' || (unsigned char)*s < 32) ? '_' : *s;
	out[n] = '\0';
}

/* The clip level: a quarter of the way above the highest pass or the
 * start, whichever is higher, over the landscape's lowest point (E_beam
 * alone: 0.6 of the way above the highest pass); never above the
 * landscape's maximum. */
static double clip_level(const bsim_landscape_grid *g, const bsim_landscape_barriers *br,
                         const double *v, double e_min, int beam_only)
{
	double top = beam_only ? -INFINITY : br->start_e, e_max = -INFINITY;
	for (int r = 0; r <= br->n_beams; r++) {
		const bsim_landscape_pass *p = table_row(br, r);
		if (p->kind != BSIM_PASS_NONE)
			top = fmax(top, beam_only ? p->e_beam : p->e_total);
	}
	for (size_t k = 0; k < grid_points(g); k++)
		e_max = fmax(e_max, v[k]);
	if (!isfinite(top))
		return e_max;
	/* E_beam alone: the ridge between the passes stands 0.4-0.5 times higher */
	const double c = top + (beam_only ? 0.6 : 0.25) * (top - e_min);
	return c > e_min && c < e_max ? c : e_max;
}

static double grid_min(const bsim_scene *s, const bsim_landscape_grid *g, const double *v)
{
	double m = INFINITY;
	for (int j = 0; j < g->ny; j++)
		for (int i = 0; i < g->nx; i++)
			if (!on_pivot(s, g->x0 + i * g->spacing, g->y0 + j * g->spacing))
				m = fmin(m, v[(size_t)j * (size_t)g->nx + (size_t)i]);
	return isfinite(m) ? m : 0.0;
}

/* A "nice" contour step near range / 12. */
static double contour_step(double range)
{
	if (!(range > 0))
		return 1.0;
	const double raw = range / 12, p = pow(10, floor(log10(raw)));
	const double m = raw / p;
	return (m < 1.5 ? 1 : m < 3.5 ? 2 : m < 7.5 ? 5 : 10) * p;
}

/* The title's first line: the scene, what the landscape is (the model's,
 * no backend: it is computed, not simulated) and the parameters that shape
 * it, as bsim_key_value writes them ("k_1 = 300 N m/rad, F_prop = 8 N"). */
static void describe_scene(char *out, size_t size, const bsim_scene *s)
{
	char name[128];
	gp_text(name, sizeof name, s->name[0] ? s->name : "scene");
	size_t n = (size_t)snprintf(out, size, "%s: landscape of the model (no backend), ", name);
	for (int b = 0; b < s->n_beams && b < 6 && n + 64 < size; b++) {
		char key[32], val[32], kv[96];
		snprintf(key, sizeof key, "beams.%d.stiffness", b);
		snprintf(val, sizeof val, "%g", s->beams[b].stiffness);
		bsim_key_value(key, val, 0, kv, sizeof kv);
		n += (size_t)snprintf(out + n, size - n, "%s, ", kv);
	}
	if (s->n_beams > 6 && n + 8 < size)
		n += (size_t)snprintf(out + n, size - n, "..., ");
	char val[32], kv[96];
	snprintf(val, sizeof val, "%g",
	         s->effects.has_propulsion ? s->effects.propulsion_force : 0.0);
	bsim_key_value("effects.propulsion.force", val, 0, kv, sizeof kv);
	if (n < size)
		snprintf(out + n, size - n, "%s", kv);
}

/* The beams at rest (grey, dashed), their reach, and the body at the
 * lowest pass with the beams at their landscape angles there (orange), as
 * gnuplot objects. */
static void draw_beams(FILE *f, const bsim_scene *s, const bsim_landscape_barriers *br)
{
	const double R = s->body.radius;
	for (int b = 0; b < s->n_beams; b++) {
		const bsim_beam_def *d = &s->beams[b];
		double u0[2];
		bsim_scene_beam_rest_direction(d, u0);
		fprintf(f,
		        "set object circle at %.6g,%.6g size %.6g fs empty border lc rgb '#404040' "
		        "dt 2 lw 1 front\n",
		        d->pivot[0], d->pivot[1], d->length + R);
		fprintf(f,
		        "set arrow from %.6g,%.6g to %.6g,%.6g nohead lw 2 lc rgb '#202020' dt 2 "
		        "front\n",
		        d->pivot[0], d->pivot[1], d->pivot[0] + d->length * u0[0],
		        d->pivot[1] + d->length * u0[1]);
		fprintf(f,
		        "set object circle at %.6g,%.6g size %.6g fs solid 1 fc rgb 'black' "
		        "front\n",
		        d->pivot[0], d->pivot[1], 0.6);
	}
	const bsim_landscape_pass *p = &br->lowest;
	if (p->kind != BSIM_PASS_SADDLE)
		return;
	const double c[2] = {p->x, p->y};
	fprintf(f,
	        "set object circle at %.6g,%.6g size %.6g fs empty border lc rgb '#202020' dt 3 lw "
	        "1.5 front\n",
	        c[0], c[1], R);
	for (int b = 0; b < s->n_beams; b++) {
		const bsim_beam_def *d = &s->beams[b];
		const double th = bsim_landscape_theta(d, R, c);
		if (th <= 0.0)
			continue;
		double u0[2];
		bsim_scene_beam_rest_direction(d, u0);
		const double sg = bsim_scene_beam_forward_sign(d), ct = cos(th), st = sin(th);
		/* u0 turned by th in the forward sense */
		const double ux = ct * u0[0] - sg * st * u0[1], uy = sg * st * u0[0] + ct * u0[1];
		fprintf(f,
		        "set arrow from %.6g,%.6g to %.6g,%.6g nohead lw 3 lc rgb '#ff7f0e' "
		        "front\n",
		        d->pivot[0], d->pivot[1], d->pivot[0] + d->length * ux,
		        d->pivot[1] + d->length * uy);
	}
}

/* Labels of the passes: the lowest pass to the left of its mark, each
 * beam's own to the right ("beam 2: 222 J"), so that two at one point
 * stay legible. */
static void label_passes(FILE *f, const bsim_landscape_barriers *br, int three_d, int beam_only)
{
	for (int r = 0; r <= br->n_beams; r++) {
		const bsim_landscape_pass *p = table_row(br, r);
		if (p->kind == BSIM_PASS_NONE)
			continue;
		/* A beam's pass that is the lowest pass is labelled once. */
		if (r > 0 && br->lowest.kind == p->kind && br->lowest.x == p->x &&
		    br->lowest.y == p->y)
			continue;
		char text[96];
		const double e = beam_only ? p->e_beam : p->e_total;
		if (r == 0 && p->kind == BSIM_PASS_OPEN)
			snprintf(text, sizeof text, "open");
		else if (r == 0)
			snprintf(text, sizeof text, "lowest pass %.0f J", e);
		else if (p->kind == BSIM_PASS_OPEN)
			snprintf(text, sizeof text, "beam %d: open", r);
		else
			snprintf(text, sizeof text, "beam %d: %.0f J", r, e);
		const char *where = r == 0 ? "right offset -1,-1" : "left offset 1,1";
		/* boxed on white (set style textbox in the callers), drawn in front
		 * of the surface, so that no part of it hides a label */
		if (three_d)
			fprintf(f,
			        "set label \"%s\" at %.6g,%.6g,%.6g %s front boxed point pt 7 ps "
			        "1.4 lc rgb '%s' tc rgb 'black'\n",
			        text, p->x, p->y, e, where, BSIM_FIGURE_PATH_RIGHT);
		else
			fprintf(f,
			        "set label \"%s\" at %.6g,%.6g %s front boxed point pt 7 ps 1.2 "
			        "lc rgb '%s' tc rgb 'black'\n",
			        text, p->x, p->y, where, BSIM_FIGURE_PATH_RIGHT);
	}
}

/* The top view: E_total as a heat map with contours, the beams, their
 * reach, the paths and the passes (essay Fig. 2.6c). */
static int figure_top(const char *dir, const bsim_scene *s, const bsim_landscape_grid *g,
                      const bsim_landscape_barriers *br, bsim_figure_def *def, char **out,
                      bsim_error *err)
{
	const double e_min = grid_min(s, g, g->e_total);
	const double clip = clip_level(g, br, g->e_total, e_min, 0);
	int rc = write_matrix(dir, "landscape_top.dat", s, g, g->e_total, 1, clip, err);
	if (rc)
		return rc;
	const double x1 = g->x0 + (g->nx - 1) * g->spacing, y1 = g->y0 + (g->ny - 1) * g->spacing;
	char what[320];
	describe_scene(what, sizeof what, s);
	char *body = NULL;
	size_t len = 0;
	FILE *f = open_memstream(&body, &len);
	if (!f)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	fputs(BSIM_FIGURE_LANDSCAPE_PALETTE, f);
	fprintf(f,
	        "set title \"%s\\nE_total = E_prop + E_beam, colours clipped at %.0f J\" "
	        "noenhanced\n",
	        what, clip);
	fprintf(f,
	        "set xrange [%.6g:%.6g]\nset yrange [%.6g:%.6g]\nset cbrange [%.6g:%.6g]\n"
	        "set size ratio -1\nset xlabel 'x (m)'\nset ylabel 'y (m)'\n"
	        "set cblabel '%s'\nset colorbox\nset key bottom left opaque box\n"
	        "set style textbox opaque fc rgb 'white' noborder\n",
	        g->x0, x1, g->y0, y1, e_min, clip, BSIM_FIGURE_LANDSCAPE_CBLABEL);
	/* Contour lines into a table, then drawn over the image. */
	const double step = contour_step(clip - e_min);
	fprintf(f,
	        "if (!exists('contoured')) {\n"
	        "  set contour base\n  set cntrparam levels incremental %.6g,%.6g,%.6g\n"
	        "  unset surface\n  set view map\n  set table 'landscape_top_contours.dat'\n"
	        "  splot 'landscape_top.dat' nonuniform matrix using 1:2:3 with lines notitle\n"
	        "  unset table\n  unset contour\n  set surface\n  unset view\n  contoured = 1\n"
	        "}\n",
	        ceil(e_min / step) * step, step, clip);
	draw_beams(f, s, br);
	label_passes(f, br, 0, 0);
	fprintf(f,
	        "set label \"start\" at %.6g,%.6g front point pt 9 ps 1.5 lc rgb 'black' offset "
	        "1,0.5 tc rgb 'black' boxed\n",
	        br->start[0], br->start[1]);
	fputs("plot 'landscape_top.dat' nonuniform matrix using 1:2:3 with image notitle, \\\n", f);
	fputs("     'landscape_top_contours.dat' using 1:2 with lines lc rgb '#606060' lw 0.5 "
	      "notitle, \\\n",
	      f);
	fputs("     'landscape_paths.dat' index 0 using 1:2 with lines lc rgb 'white' lw 5 "
	      "notitle, \\\n"
	      "     'landscape_paths.dat' index 0 using 1:2 with lines lc rgb "
	      "'" BSIM_FIGURE_PATH_RIGHT "' lw 2.5 title 'path of least resistance'",
	      f);
	for (int b = 0; b < br->n_beams; b++)
		if (br->beam[b].n_path > 0)
			fprintf(f,
			        ", \\\n     'landscape_paths.dat' index %d using 1:2 with lines "
			        "lc rgb '#000000' lw 1.2 dt 2 %s",
			        b + 1, b == 0 ? "title 'over each beam'" : "notitle");
	fputc('\n', f);
	if (fclose(f) != 0) {
		free(body);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	def->name = "landscape_top";
	def->width = 900;
	def->height = (int)fmin(1100, 900 * (y1 - g->y0) / (x1 - g->x0) + 120);
	*out = body;
	return BSIM_OK;
}

/* The surface as drawn (figures/figures_surface.h): polygons of E up to the
 * clip level that end along the landscape's steps (the rim of each beam's
 * reach, rho = L + R, docs/model.md section 7), the pivots and the clip
 * level, finer where the surface bends. A step drawn as part of the
 * surface would stand upright and hide what lies behind it. */
static int write_surface(const char *dir, const char *file, const bsim_scene *s,
                         const bsim_landscape_grid *g, int beam_only, double e_min, double clip,
                         long *polygons, bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	int rc = file_path(path, sizeof path, dir, file, err);
	bsim_atomic_file o;
	if (!rc)
		rc = bsim_atomic_file_open(&o, path, err);
	if (rc)
		return rc;
	fputs("# x y (m), E (J): the surface up to the clip level as polygons, each two "
	      "scans of two\n# points (gnuplot pm3d), cut along the steps, the pivots and the "
	      "clip level\n",
	      o.f);
	const fsurface d = {.region = {g->region[0], g->region[1], g->region[2], g->region[3]},
	                    .cap = clip,
	                    .e_min = e_min,
	                    .beam_only = beam_only,
	                    .max_polygons = SURFACE_POLYGONS};
	rc = bsim_fsurface_write(o.f, s, &d, polygons, err);
	if (!rc && *polygons == 0) /* gnuplot needs a point in a file it plots */
		fputs("NaN NaN NaN\n", o.f);
	if (rc) {
		bsim_atomic_file_abort(&o);
		return rc;
	}
	return bsim_atomic_file_commit(&o, err);
}

/* A 3-D surface of v (E_beam or E_total) with the passes marked (essay
 * Fig. 2.6a, b, d), in the landscapes' colours with a colour bar, seen
 * from the start's side a little to the left, so that both passes show
 * between the barriers. Lit without a specular highlight, which turned the
 * small polygons along the steps facing the light into white slivers. */
static int figure_surface(const char *dir, const char *name, const bsim_scene *s,
                          const bsim_landscape_grid *g, const bsim_landscape_barriers *br,
                          const double *v, int beam_only, bsim_figure_def *def, char **out,
                          bsim_error *err)
{
	char data[64];
	snprintf(data, sizeof data, "%s.dat", name);
	const double e_min = grid_min(s, g, v);
	const double clip = clip_level(g, br, v, e_min, beam_only);
	long polygons;
	int rc = write_surface(dir, data, s, g, beam_only, e_min, clip, &polygons, err);
	if (rc)
		return rc;
	char what[320];
	describe_scene(what, sizeof what, s);
	char *body = NULL;
	size_t len = 0;
	FILE *f = open_memstream(&body, &len);
	if (!f)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	fputs(BSIM_FIGURE_LANDSCAPE_PALETTE, f);
	fprintf(f,
	        "set title \"%s\\n%s; drawn up to %.0f J, cut at the steps and pivots\" "
	        "noenhanced\n",
	        what,
	        beam_only ? "E_beam, the springs alone; the passes of E_total at their E_beam"
	                  : "E_total = E_prop + E_beam",
	        clip);
	fprintf(f,
	        "set xlabel 'x (m)'\nset ylabel 'y (m)'\nset zlabel '%s (J)' rotate parallel\n"
	        "set cbrange [%.6g:%.6g]\nset zrange [%.6g:%.6g]\n"
	        "set colorbox vertical user origin 0.88,0.2 size 0.025,0.55\n"
	        "set cblabel '%s'\n"
	        "set view 50,330,1,1.05\nset xyplane relative 0.1\n"
	        "set pm3d depthorder lighting primary 0.5 specular 0\n"
	        "set grid\nset style textbox opaque fc rgb 'white' noborder\n"
	        "set rmargin at screen 0.84\n",
	        beam_only ? "E_{beam}" : "E_{total}", e_min, clip, e_min, clip,
	        beam_only ? "potential energy of the springs E_{beam} (J)"
	                  : BSIM_FIGURE_LANDSCAPE_CBLABEL);
	label_passes(f, br, 1, beam_only);
	fprintf(f, "splot '%s' using 1:2:3 with pm3d notitle\n", data);
	if (fclose(f) != 0) {
		free(body);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	def->name = name;
	def->width = 1000;
	def->height = 750;
	*out = body;
	return BSIM_OK;
}

int bsim_landscape_write(const char *dir, const bsim_scene *s, const bsim_landscape_grid *g,
                         const bsim_landscape_barriers *b, int *drawn, bsim_error *err)
{
	if (drawn)
		*drawn = 0;
	int rc = write_csv(dir, g, err);
	if (!rc)
		rc = write_mat(dir, s, g, b, err);
	if (!rc)
		rc = write_json(dir, s, g, b, err);
	if (!rc)
		rc = write_paths(dir, s, b, err);
	bsim_figure_def defs[3];
	char *bodies[3] = {NULL, NULL, NULL};
	for (int i = 0; i < 3; i++) {
		defs[i] = bsim_figure_def_default();
		defs[i].dir = dir;
	}
	if (!rc)
		rc = figure_top(dir, s, g, b, &defs[0], &bodies[0], err);
	if (!rc)
		rc = figure_surface(dir, "landscape_beam", s, g, b, g->e_beam, 1, &defs[1],
		                    &bodies[1], err);
	if (!rc)
		rc = figure_surface(dir, "landscape_total", s, g, b, g->e_total, 0, &defs[2],
		                    &bodies[2], err);
	if (!rc)
		rc = bsim_figure_render_all(defs, (const char *const *)bodies, 3, drawn, err);
	for (int i = 0; i < 3; i++)
		free(bodies[i]);
	return rc;
}
