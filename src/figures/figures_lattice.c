/* Figures of a gate lattice (figures.h, docs/figures.md "A gate lattice").
 *
 * For each group of a lattice sweep:
 *
 *   lattice_gNNN          the essay's Fig. 3.5: (a) the stiffness map, each
 *                         gate's left and right half coloured by the beam that
 *                         sweeps it (the left beam hangs on the gate's left
 *                         edge and reaches across its left half, the right
 *                         beam its right half), the beams at rest over it, the
 *                         gates' columns i_x and rows i_y marked; (b) the kept
 *                         trajectories over the same map, paled, those that
 *                         reached the end in blue and the rest in red, as the
 *                         essay draws them.
 *   final_locations_gNNN  where the trials ended, laid out as the field: the
 *                         gates they were stuck in as a map in the middle, the
 *                         ends above it by column, the side exits left and
 *                         right of it by row, each with its Wilson 95%
 *                         interval.
 *
 * and for a comparison of two lattice runs, final_locations_gNNN with both
 * sides' distributions side by side on the same scales, titled by the
 * report's paired permutation test.
 *
 * The counts come from trials.csv: its location (end:ix, side:iy,
 * stuck:ix:iy) and, for a side exit, which side of the field's centre line
 * X = (x_min + x_max) / 2 the body ended on (x_end), which the location does
 * not record. The map comes from lattice_map.csv, the beams' length from the
 * group's scene. A group without random force is one trial run and copied,
 * so its fractions are points (their interval is the point), as summary.json
 * has them. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "beamsim/compare.h"
#include "beamsim/experiment.h"
#include "beamsim/lattice.h"
#include "beamsim/stats.h"
#include "figures/figures_lattice.h"
#include "figures/figures_summary.h"
#include "figures/figures_toolkit.h"
#include "util/csv_table.h"
#include "util/figure.h"
#include "beamsim/limits.h"

/* ---- the data of a lattice run -------------------------------------------------------- */

typedef struct flat_gate {
	double x_min, x_max, y_min, y_max, pivot_y; /* m, the field's X, Y */
	double k[2];                                /* N m/rad, left and right beam */
	int seen;
} flat_gate;

/* Where a trial ended, per trial of the group. */
enum { FLAT_END = 1, FLAT_SIDE, FLAT_STUCK };

typedef struct flat {
	int ix_min, ix_max, cols, rows;
	flat_gate *gate; /* rows x cols, row iy = 0 first, gate (ix, iy) at
	                  * iy cols + ix - ix_min */
	double centre_x; /* m, the field's centre line */
	int trials, unstable;
	int point;   /* 1: a group without random force, its fractions points */
	int *end;    /* cols: reached the end through column ix */
	int *side;   /* 2 rows: left (side 0) then right exits, by row iy */
	int *stuck;  /* rows x cols, like gate */
	char *where; /* trials: FLAT_* of trial t (0: not in trials.csv) */
} flat;

typedef struct flats {
	int n_groups;
	flat *g;
} flats;

static void flats_free(flats *l)
{
	for (int g = 0; l->g && g < l->n_groups; g++) {
		flat *a = &l->g[g];
		free(a->gate);
		free(a->end);
		free(a->side);
		free(a->stuck);
		free(a->where);
	}
	free(l->g);
	memset(l, 0, sizeof *l);
}

static int file_exists(const char *dir, const char *file)
{
	char path[BSIM_PATH_MAX];
	struct stat st;
	snprintf(path, sizeof path, "%s/%s", dir, file);
	return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

/* lattice_map.csv: every gate of every group once. */
static int map_read(const char *dir, flats *l, bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	snprintf(path, sizeof path, "%s/lattice_map.csv", dir);
	csv_table t;
	int rc = bsim_csv_table_read(path, &t, err);
	if (rc)
		return rc;
	static const char *const need[] = {"group", "ix",    "iy",      "x_min",  "x_max",
	                                   "y_min", "y_max", "pivot_y", "k_left", "k_right"};
	int col[10];
	double *v = NULL;
	rc = bsim_csv_table_require(&t, path, need, 10, col, err);
	if (!rc && !(v = malloc(((size_t)t.n_rows + 1) * 10 * sizeof *v)))
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory reading %s", path);
	for (int c = 0; !rc && c < 10; c++)
		rc = bsim_csv_table_numbers(&t, path, col[c], 0, 0.0,
		                            v + (size_t)c * (size_t)t.n_rows, err);
	const size_t n = (size_t)t.n_rows;
#define MAP(c, r) v[(size_t)(c)*n + (size_t)(r)]
	/* the extent of each group's lattice */
	for (int g = 0; g < l->n_groups; g++)
		l->g[g].rows = -1;
	for (size_t r = 0; !rc && r < n; r++) {
		double g = MAP(0, r), ix = MAP(1, r), iy = MAP(2, r);
		if (g != floor(g) || g < 0 || g >= l->n_groups || ix != floor(ix) ||
		    fabs(ix) > 1e6 || iy != floor(iy) || iy < 0 || iy > 1e6) {
			rc = bsim_error_set(
			        err, BSIM_EINPUT,
			        "%s:%zu: group, ix, iy: expected a group of summary.json "
			        "(0 .. %d) and integer gate indices",
			        path, r + 2, l->n_groups - 1);
			break;
		}
		flat *a = &l->g[(int)g];
		if (a->rows < 0) {
			a->ix_min = a->ix_max = (int)ix;
			a->rows = 0;
		}
		a->ix_min = (int)fmin(a->ix_min, ix);
		a->ix_max = (int)fmax(a->ix_max, ix);
		a->rows = (int)fmax(a->rows, iy + 1);
	}
	for (int g = 0; !rc && g < l->n_groups; g++) {
		flat *a = &l->g[g];
		if (a->rows < 0) {
			rc = bsim_error_set(err, BSIM_EINPUT, "%s: no gate of group %d", path, g);
			break;
		}
		a->cols = a->ix_max - a->ix_min + 1;
		if ((long)a->cols * a->rows > 1000000) {
			rc = bsim_error_set(err, BSIM_EINPUT, "%s: group %d: more than 10^6 gates",
			                    path, g);
			break;
		}
		a->gate = calloc((size_t)(a->cols * a->rows), sizeof *a->gate);
		if (!a->gate)
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory reading %s", path);
	}
	for (size_t r = 0; !rc && r < n; r++) {
		flat *a = &l->g[(int)MAP(0, r)];
		flat_gate *q = &a->gate[(int)MAP(2, r) * a->cols + (int)MAP(1, r) - a->ix_min];
		if (q->seen++) {
			rc = bsim_error_set(err, BSIM_EINPUT,
			                    "%s:%zu: gate (%g, %g) of group %g twice", path, r + 2,
			                    MAP(1, r), MAP(2, r), MAP(0, r));
			break;
		}
		*q = (flat_gate){MAP(3, r), MAP(4, r), MAP(5, r),
		                 MAP(6, r), MAP(7, r), {MAP(8, r), MAP(9, r)},
		                 1};
	}
#undef MAP
	for (int g = 0; !rc && g < l->n_groups; g++) {
		flat *a = &l->g[g];
		for (int i = 0; i < a->cols * a->rows && !rc; i++)
			if (!a->gate[i].seen)
				rc = bsim_error_set(
				        err, BSIM_EINPUT,
				        "%s: group %d: expected every gate of ix %d .. %d, "
				        "iy 0 .. %d; gate (%d, %d) is missing",
				        path, g, a->ix_min, a->ix_max, a->rows - 1,
				        a->ix_min + i % a->cols, i / a->cols);
		if (!rc)
			a->centre_x = 0.5 * (a->gate[0].x_min + a->gate[a->cols - 1].x_max);
	}
	free(v);
	bsim_csv_table_free(&t);
	return rc;
}

/* An integer of a location ("end:-3"), digits with an optional minus sign
 * up to sep, read in full: sscanf's %d has no defined result beyond int's
 * range (it read 4294967296 as 0). *next: past sep. */
static int loc_int(const char *s, char sep, const char **next, int *out)
{
	char *end;
	errno = 0;
	long v = strtol(s, &end, 10);
	if (end == s || (*s != '-' && (*s < '0' || *s > '9')) || *end != sep || errno == ERANGE ||
	    v < INT_MIN || v > INT_MAX)
		return -1;
	*out = (int)v;
	*next = end + (sep != '\0');
	return 0;
}

/* trials.csv: each trial's final location counted. */
static int locations_read(const char *dir, const fsum *s, flats *l, bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	snprintf(path, sizeof path, "%s/trials.csv", dir);
	csv_table t;
	int rc = bsim_csv_table_read(path, &t, err);
	if (rc)
		return rc;
	static const char *const need[] = {"group", "trial", "outcome", "x_end", "location"};
	int col[5];
	rc = bsim_csv_table_require(&t, path, need, 5, col, err);
	const int per = s->trials_per_group;
	for (int g = 0; !rc && g < l->n_groups; g++) {
		flat *a = &l->g[g];
		a->end = calloc((size_t)a->cols, sizeof *a->end);
		a->side = calloc(2 * (size_t)a->rows, sizeof *a->side);
		a->stuck = calloc((size_t)(a->cols * a->rows), sizeof *a->stuck);
		a->where = calloc((size_t)per + 1, 1);
		a->point = s->g[g].lo == s->g[g].hi && s->g[g].trials > 1;
		if (!a->end || !a->side || !a->stuck || !a->where)
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory reading %s", path);
	}
	for (long r = 0; !rc && r < t.n_rows; r++) {
		double g, tr, x_end;
		if (bsim_csv_table_number(&t, r, col[0], &g) ||
		    bsim_csv_table_number(&t, r, col[1], &tr) || g != floor(g) || g < 0 ||
		    g >= l->n_groups || tr != floor(tr) || tr < 0 || tr >= per) {
			rc = bsim_error_set(err, BSIM_EINPUT,
			                    "%s:%ld: group, trial: expected integers within the %d "
			                    "groups x %d trials of summary.json",
			                    path, r + 2, l->n_groups, per);
			break;
		}
		flat *a = &l->g[(int)g];
		const char *loc = bsim_csv_table_cell(&t, r, col[4]);
		int ix = 0, iy = 0, ok = 0;
		const char *p;
		if (!strncmp(loc, "end:", 4) && !loc_int(loc + 4, '\0', &p, &ix)) {
			ok = ix >= a->ix_min && ix <= a->ix_max;
			if (ok) {
				a->end[ix - a->ix_min]++;
				a->where[(int)tr] = FLAT_END;
			}
		} else if (!strncmp(loc, "side:", 5) && !loc_int(loc + 5, '\0', &p, &iy)) {
			ok = iy >= 0 && iy < a->rows &&
			     !bsim_csv_table_number(&t, r, col[3], &x_end);
			if (ok) {
				a->side[(x_end < a->centre_x ? 0 : a->rows) + iy]++;
				a->where[(int)tr] = FLAT_SIDE;
			}
		} else if (!strncmp(loc, "stuck:", 6) && !loc_int(loc + 6, ':', &p, &ix) &&
		           !loc_int(p, '\0', &p, &iy)) {
			ok = ix >= a->ix_min && ix <= a->ix_max && iy >= 0 && iy < a->rows;
			if (ok) {
				a->stuck[iy * a->cols + ix - a->ix_min]++;
				a->where[(int)tr] = FLAT_STUCK;
			}
		}
		if (!ok) {
			rc = bsim_error_set(err, BSIM_EINPUT,
			                    "%s:%ld: location: expected end:IX, side:IY (with a "
			                    "number in x_end) or stuck:IX:IY within the gates of "
			                    "lattice_map.csv (ix %d .. %d, iy 0 .. %d), got '%s'",
			                    path, r + 2, a->ix_min, a->ix_max, a->rows - 1, loc);
			break;
		}
		a->trials++;
		a->unstable += strcmp(bsim_csv_table_cell(&t, r, col[2]), "unstable") == 0;
	}
	bsim_csv_table_free(&t);
	return rc;
}

/* Reads a lattice run's map and final locations (dir holds summary.json's
 * groups s). */
static int flats_read(const char *dir, const fsum *s, flats *l, bsim_error *err)
{
	memset(l, 0, sizeof *l);
	l->g = calloc((size_t)s->n_groups + 1, sizeof *l->g);
	if (!l->g)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	l->n_groups = s->n_groups;
	int rc = map_read(dir, l, err);
	if (!rc)
		rc = locations_read(dir, s, l, err);
	if (rc)
		flats_free(l);
	return rc;
}

/* A count of a group as p and its 95% interval. */
static void fraction(const flat *a, int k, double v[3])
{
	const int n = a->trials > 0 ? a->trials : 1;
	v[0] = (double)k / n;
	if (a->point) {
		v[1] = v[2] = v[0];
		return;
	}
	bsim_stats_wilson(k, n, BSIM_STATS_Z95, &v[1], &v[2]);
}

static int sum_ints(const int *x, int n)
{
	int s = 0;
	for (int i = 0; i < n; i++)
		s += x[i];
	return s;
}

/* ---- the colour scale of stiffness ----------------------------------------------------- */

/* Viridis at u = 0, 1/8, ..., 1 (dark purple to yellow), as the video's
 * stiffness colours: the softest beams light, the stiffest dark. */
static const unsigned char viridis[9][3] = {
        {68, 1, 84},    {71, 44, 122}, {59, 81, 139},  {44, 113, 142}, {33, 144, 141},
        {39, 173, 129}, {92, 200, 99}, {170, 220, 50}, {253, 231, 37},
};

/* A gnuplot palette from soft (0, viridis 0.9) to stiff (1, viridis 0),
 * blended toward white by pale (0: none, 1: white). */
static void stiffness_palette(FILE *g, double pale)
{
	fputs("set palette defined (", g);
	for (int j = 0; j <= 8; j++) {
		double x = 0.9 * (1.0 - j / 8.0) * 8.0;
		int i = (int)floor(x);
		if (i >= 8)
			i = 7;
		double f = x - i;
		int c[3];
		for (int ch = 0; ch < 3; ch++) {
			double vv = viridis[i][ch] + f * (viridis[i + 1][ch] - viridis[i][ch]);
			c[ch] = (int)lround(vv + pale * (255.0 - vv));
		}
		fprintf(g, "%s%g '#%02X%02X%02X'", j ? ", " : "", j / 8.0, c[0], c[1], c[2]);
	}
	fputs(")\n", g);
}

/* ---- Fig. 3.5 ----------------------------------------------------------------------- */

/* A kept trajectory: rows of (x, y) in trajectories.csv, and whether its
 * trial reached the end. */
typedef struct lpath {
	int group, trial, end;
	long n;
	const double *x, *y;
} lpath;

/* A drawn path leaves out a row within d metres of the last row drawn (a
 * path's first and last rows are always drawn): d starts at 1 m, about a
 * pixel of the 560 m field, and doubles until the drawn rows are at most
 * PATH_ROWS_MAX, so that the SVG stays well under 1 MB however many
 * trajectories were kept (40,000 rows are about 0.6 MB of SVG). The data
 * file holds the rows drawn; every recorded row is in trajectories.csv. */
#define PATH_ROWS_MAX 40000

static long thinned(const lpath *p, int n, double d, FILE *out, int end)
{
	long kept = 0;
	int first = 1;
	for (int i = 0; i < n; i++) {
		if (end >= 0 && p[i].end != end)
			continue;
		if (out)
			fprintf(out, "%s# group %d trial %d\n", first ? "" : "\n", p[i].group,
			        p[i].trial);
		first = 0;
		double lx = 0.0, ly = 0.0;
		for (long k = 0; k < p[i].n; k++) {
			if (k > 0 && k < p[i].n - 1 && hypot(p[i].x[k] - lx, p[i].y[k] - ly) < d)
				continue;
			lx = p[i].x[k];
			ly = p[i].y[k];
			kept++;
			if (out)
				fprintf(out, "%.7g %.7g\n", lx, ly);
		}
	}
	if (out && first) /* gnuplot needs a point in every block it plots */
		fputs("NaN NaN\n", out);
	return kept;
}

/* The field shown: every gate, the start and the end line, a margin. */
static void field_box(const flat *a, const bsim_scene *sc, double box[4])
{
	box[0] = a->gate[0].x_min;
	box[1] = a->gate[a->cols - 1].x_max;
	box[2] = fmin(0.0, sc->body.start[1] - sc->body.radius);
	box[3] = fmax(a->gate[(a->rows - 1) * a->cols].y_max, sc->success_y);
	double m = 0.02 * (box[1] - box[0]);
	box[0] -= m;
	box[1] += m;
	box[2] -= m;
	box[3] += m;
}

/* The gates' columns and rows: dashed boundaries (the essay's Fig. 2.8) and
 * tics naming i_x and i_y at their centres on the top and right axes. */
static void gate_marks(FILE *g, const flat *a, const bsim_scene *sc, const double box[4])
{
	const double y0 = a->gate[0].y_min, y1 = a->gate[(a->rows - 1) * a->cols].y_max;
	const double x0 = a->gate[0].x_min, x1 = a->gate[a->cols - 1].x_max;
	for (int c = 0; c <= a->cols; c++) {
		double x = c < a->cols ? a->gate[c].x_min : x1;
		fprintf(g, "set arrow from %g,%g to %g,%g nohead front dt 2 lw 0.8 lc rgb '%s'\n",
		        x, y0, x, y1, FIG_GREEN);
	}
	for (int r = 0; r <= a->rows; r++) {
		double y = r < a->rows ? a->gate[r * a->cols].y_min : y1;
		fprintf(g, "set arrow from %g,%g to %g,%g nohead front dt 2 lw 0.8 lc rgb '%s'\n",
		        x0, y, x1, y, FIG_GREEN);
	}
	/* the end line and the side boundaries */
	const double cx = a->centre_x;
	fprintf(g,
	        "set arrow from %g,%g to %g,%g nohead front lw 1.5 lc rgb '%s'\n"
	        "set arrow from %g,%g to %g,%g nohead front dt 3 lw 1.2 lc rgb '%s'\n"
	        "set arrow from %g,%g to %g,%g nohead front dt 3 lw 1.2 lc rgb '%s'\n",
	        box[0], sc->success_y, box[1], sc->success_y, FIG_GREEN, cx - sc->side_x, box[2],
	        cx - sc->side_x, box[3], FIG_DKGREY, cx + sc->side_x, box[2], cx + sc->side_x,
	        box[3], FIG_DKGREY);
	fputs("set x2tics (", g);
	for (int c = 0; c < a->cols; c++)
		fprintf(g, "%s'%d' %g", c ? ", " : "", a->ix_min + c,
		        0.5 * (a->gate[c].x_min + a->gate[c].x_max));
	fputs(") out nomirror\nset y2tics (", g);
	for (int r = 0; r < a->rows; r++)
		fprintf(g, "%s'%d' %g", r ? ", " : "", r,
		        0.5 * (a->gate[r * a->cols].y_min + a->gate[r * a->cols].y_max));
	fprintf(g,
	        ") out nomirror\nset xtics out nomirror\nset ytics out nomirror\n"
	        "set x2range [%g:%g]\nset y2range [%g:%g]\n"
	        "set xlabel 'X (m)'\nset ylabel 'Y (m)'\n"
	        "set x2label 'gate column i_x'\nset y2label 'gate row i_y'\n",
	        box[0], box[1], box[2], box[3]);
}

static int lattice_map_figure(figs *f, int gi, const char *label, const flat *a,
                              const bsim_scene *sc, const lpath *p, int n, bsim_error *err)
{
	char name[64], file[80], path[BSIM_PATH_MAX];
	snprintf(name, sizeof name, "lattice_g%03d", gi);
	snprintf(file, sizeof file, "%s.dat", name);
	bsim_atomic_file o;
	int rc = bsim_figs_data_open(f, file, &o, path, err);
	if (rc)
		return rc;
	double k_min = INFINITY, k_max = -INFINITY;
	fputs("# block 0: x_lo x_hi y_lo y_hi (m) k (N m/rad) ix iy side: the half of each gate\n"
	      "# its beam sweeps (side 0 the left beam, left half), coloured by the beam's k\n",
	      o.f);
	for (int r = 0; r < a->rows; r++)
		for (int c = 0; c < a->cols; c++) {
			const flat_gate *q = &a->gate[r * a->cols + c];
			const double xm = 0.5 * (q->x_min + q->x_max);
			for (int side = 0; side < 2; side++) {
				fprintf(o.f, "%.10g %.10g %.10g %.10g %.10g %d %d %d\n",
				        side ? xm : q->x_min, side ? q->x_max : xm, q->y_min,
				        q->y_max, q->k[side], a->ix_min + c, r, side);
				k_min = fmin(k_min, q->k[side]);
				k_max = fmax(k_max, q->k[side]);
			}
		}
	fputs("\n\n# block 1: x y dx dy (m): each beam at rest, pivot to tip\n", o.f);
	const bsim_lattice_def *L = &sc->lattice;
	for (int r = 0; r < a->rows; r++)
		for (int c = 0; c < a->cols; c++)
			for (int side = 0; side < 2; side++) {
				int i = bsim_lattice_beam(L, a->ix_min + c, r, side);
				if (i < 0)
					continue;
				const bsim_beam_def *b = &sc->beams[i];
				double u[2];
				bsim_scene_beam_rest_direction(b, u);
				fprintf(o.f, "%.10g %.10g %.10g %.10g\n", b->pivot[0], b->pivot[1],
				        b->length * u[0], b->length * u[1]);
			}
	double d = 1.0;
	while (thinned(p, n, d, NULL, -1) > PATH_ROWS_MAX)
		d *= 2.0;
	int n_end = 0;
	for (int i = 0; i < n; i++)
		n_end += p[i].end;
	fprintf(o.f,
	        "\n\n# block 2: x y (m) of the kept trajectories that reached the end, a blank "
	        "line\n# between trials, rows within %g m of the last drawn left out\n",
	        d);
	thinned(p, n, d, o.f, 1);
	fputs("\n\n# block 3: x y (m) of the other kept trajectories\n", o.f);
	thinned(p, n, d, o.f, 0);
	if ((rc = bsim_figs_data_commit(&o, err)))
		return rc;

	gp_text g;
	if ((rc = bsim_gp_text_open(&g, err)))
		return rc;
	FILE *s = g.f;
	double box[4];
	field_box(a, sc, box);
	if (!(k_max > k_min)) { /* one stiffness: the middle of the scale */
		k_min -= 1.0;
		k_max += 1.0;
	}
	const int ends = sum_ints(a->end, a->cols);
	/* the map alone, without kept trajectories, is one panel, narrower: its
	 * title is broken into lines that fit it */
	const int width = n > 0 ? 1400 : 760;
	char title[1800], wrapped[1900];
	snprintf(title, sizeof title,
	         "group %d: %d of %d trials reached the end (%.0f%%)\n%s\n"
	         "each gate's left and right half coloured by the stiffness of the beam that "
	         "sweeps it; gate columns i_x on top, rows i_y on the right",
	         gi, ends, a->trials, a->trials ? 100.0 * ends / a->trials : 0.0, label);
	bsim_figure_wrap(title, 11, width - 40, wrapped, sizeof wrapped);
	fprintf(s, "set multiplot layout 1,%d title ", n > 0 ? 2 : 1);
	bsim_gp_str(s, wrapped);
	fprintf(s,
	        " noenhanced\nset size ratio -1\nset xrange [%g:%g]\nset yrange [%g:%g]\n"
	        "set cbrange [%.10g:%.10g]\nset cblabel 'k (N m/rad)'\nset style fill solid 1.0 "
	        "noborder\nunset key\n",
	        box[0], box[1], box[2], box[3], k_min, k_max);
	gate_marks(s, a, sc, box);
	stiffness_palette(s, 0.0);
	fprintf(s,
	        "set title '%sthe stiffness map'\n"
	        "plot '%s' index 0 using (($1+$2)/2):(($3+$4)/2):(($2-$1)/2):(($4-$3)/2):5 with "
	        "boxxyerror fc palette, \\\n"
	        "     '' index 1 using 1:2:3:4 with vectors nohead lw 2 lc rgb '%s', \\\n"
	        "     '+' using (%g):(%g):(%g) every ::0::0 with circles fs empty lc rgb '%s' lw "
	        "1.5\n",
	        n > 0 ? "(a) " : "", file, FIG_GREY, sc->body.start[0], sc->body.start[1],
	        sc->body.radius, FIG_BLACK);
	if (n > 0) {
		fprintf(s,
		        "set title '(b) the paths of the first %d of the %d trials'\n"
		        "unset colorbox\nset key below horizontal\n",
		        n, a->trials);
		stiffness_palette(s, 0.7);
		fprintf(s,
		        "plot '%s' index 0 using (($1+$2)/2):(($3+$4)/2):(($2-$1)/2):(($4-$3)/2):5 "
		        "with boxxyerror fc palette notitle, \\\n"
		        "     '' index 1 using 1:2:3:4 with vectors nohead lw 1 lc rgb '%s' "
		        "notitle, \\\n"
		        "     '' index 3 using 1:2 with lines lw 1.2 lc rgb '%s' title "
		        "'did not reach the end (%d)', \\\n"
		        "     '' index 2 using 1:2 with lines lw 1.6 lc rgb '%s' title "
		        "'reached the end (%d)'\n",
		        file, FIG_GREY, FIG_RED, n - n_end, FIG_BLUE, n_end);
	}
	fputs("unset multiplot\n", s);
	char *body = bsim_gp_text_take(&g);
	rc = body ? bsim_figs_render(f, name, width, 860, body, err)
	          : bsim_error_set(err, BSIM_EFAIL, "out of memory");
	free(body);
	return rc;
}

/* ---- the final locations --------------------------------------------------------------- */

/* Three blocks of the data file for one run:
 *   ends:        ix p lo hi count            (every column)
 *   side exits:  iy p lo hi count (left) p lo hi count (right)   (every row)
 *   stuck:       ix iy p lo hi count         (every gate) */
static void locations_blocks(FILE *o, const flat *a, const char *label, int first)
{
	double v[3], w[3];
	fprintf(o,
	        "%s# %s: %d trials\n# ends: ix p ci95_lo ci95_hi count (reached the end "
	        "through column ix)\n",
	        first ? "" : "\n\n", label, a->trials);
	for (int c = 0; c < a->cols; c++) {
		fraction(a, a->end[c], v);
		fprintf(o, "%d %.6g %.6g %.6g %d\n", a->ix_min + c, v[0], v[1], v[2], a->end[c]);
	}
	fprintf(o,
	        "\n\n# %s: side exits: iy, left: p ci95_lo ci95_hi count, right: p ci95_lo "
	        "ci95_hi count\n",
	        label);
	for (int r = 0; r < a->rows; r++) {
		fraction(a, a->side[r], v);
		fraction(a, a->side[a->rows + r], w);
		fprintf(o, "%d %.6g %.6g %.6g %d %.6g %.6g %.6g %d\n", r, v[0], v[1], v[2],
		        a->side[r], w[0], w[1], w[2], a->side[a->rows + r]);
	}
	fprintf(o, "\n\n# %s: stuck: ix iy p ci95_lo ci95_hi count (stuck in gate (ix, iy))\n",
	        label);
	for (int r = 0; r < a->rows; r++)
		for (int c = 0; c < a->cols; c++) {
			int k = a->stuck[r * a->cols + c];
			fraction(a, k, v);
			fprintf(o, "%d %d %.6g %.6g %.6g %d\n", a->ix_min + c, r, v[0], v[1], v[2],
			        k);
		}
}

/* The largest upper bound of ends, side exits and stuck fractions. */
static void locations_top(const flat *a, double top[3])
{
	double v[3];
	for (int c = 0; c < a->cols; c++) {
		fraction(a, a->end[c], v);
		top[0] = fmax(top[0], v[2]);
	}
	for (int i = 0; i < 2 * a->rows; i++) {
		fraction(a, a->side[i], v);
		top[1] = fmax(top[1], v[2]);
	}
	for (int i = 0; i < a->rows * a->cols; i++) {
		fraction(a, a->stuck[i], v);
		top[2] = fmax(top[2], v[0]);
	}
}

/* "end 6.1% [4.8, 7.8], side exit 16.1%, stuck 77.8% of 1000 trials" */
static void locations_line(const flat *a, char *buf, size_t size)
{
	double v[3];
	const int ends = sum_ints(a->end, a->cols), sides = sum_ints(a->side, 2 * a->rows);
	const int stuck = sum_ints(a->stuck, a->rows * a->cols);
	fraction(a, ends, v);
	const double n = a->trials > 0 ? a->trials : 1;
	int k = snprintf(buf, size,
	                 "reached the end %.1f%% [%.1f, %.1f], side exit %.1f%%, stuck %.1f%% "
	                 "of %d trials",
	                 100.0 * v[0], 100.0 * v[1], 100.0 * v[2], 100.0 * sides / n,
	                 100.0 * stuck / n, a->trials);
	if (a->unstable && k > 0 && (size_t)k < size)
		snprintf(buf + k, size - (size_t)k, " (%d unstable, counted where they stopped)",
		         a->unstable);
}

/* A tic step of 1, 2 or 5 times a power of ten giving at most 3 steps
 * up to top (> 0). */
static double tic_step(double top)
{
	double p = pow(10.0, floor(log10(top / 3.0)));
	for (int i = 0; i < 3; i++) {
		static const double m[3] = {1.0, 2.0, 5.0};
		if (top / (m[i] * p) <= 3.0)
			return m[i] * p;
	}
	return 10.0 * p;
}

/* Sets the plot's margins to a rectangle of the screen. */
static void at(FILE *g, double x0, double x1, double y0, double y1)
{
	fprintf(g,
	        "set lmargin at screen %.4f\nset rmargin at screen %.4f\n"
	        "set bmargin at screen %.4f\nset tmargin at screen %.4f\n",
	        x0, x1, y0, y1);
}

/* One run's final locations laid out as the field, in the screen region
 * x in [ox, ox + w], y in [0, top]: blocks b0 (ends), b0 + 1 (side exits),
 * b0 + 2 (stuck) of file; scales top3 (fractions) shared by every region. */
static void locations_region(FILE *g, const char *file, int b0, const flat *a, double ox, double w,
                             double top_y, const double top3[3], const char *label,
                             const char *line)
{
	const double mx0 = ox + 0.24 * w, mx1 = ox + 0.76 * w; /* the map */
	const double my0 = 0.09, my1 = 0.09 + 0.62 * top_y;
	const double ey0 = my1 + 0.025, ey1 = top_y - 0.075; /* the ends above */
	const double pe = 100.0 * fmax(top3[0], 0.01) * 1.1, ps = 100.0 * fmax(top3[1], 0.01) * 1.1;
	const double pk = fmax(top3[2], 1e-9);
	fprintf(g,
	        "# ---- %s ----\nunset arrow\nunset label\nunset key\nunset colorbox\nunset "
	        "x2tics\nunset y2tics\nset grid\n",
	        label);
	/* the ends, above the map, by column */
	at(g, mx0, mx1, ey0, ey1);
	fputs("set title ", g);
	char title[700];
	snprintf(title, sizeof title, "%s\n%s", label, line);
	bsim_gp_str(g, title);
	fprintf(g,
	        " noenhanced\nset xrange [%g:%g]\nset yrange [0:%g]\nset xtics 1 format ''\n"
	        "set ytics auto format '%%g'\nunset xlabel\nset ylabel 'end (%%)'\n"
	        "set boxwidth 0.7\n"
	        "plot '%s' index %d using 1:(100*$2) with boxes fs solid 0.8 lc rgb '%s', \\\n"
	        "     '' index %d using 1:($5 > 0 ? 100*$2 : NaN):(100*$3):(100*$4) with "
	        "yerrorbars pt 7 ps 0.4 lc rgb '%s'\n",
	        a->ix_min - 0.5, a->ix_max + 0.5, pe, file, b0, FIG_BLUE, b0, FIG_BLACK);
	/* the side exits, left and right of the map, by row (the left one's
	 * axis reversed, so that both grow away from the field) */
	for (int side = 0; side < 2; side++) {
		const int c = side ? 6 : 2; /* p's column */
		if (side)
			at(g, mx1 + 0.02 * w, ox + 0.97 * w, my0, my1);
		else
			at(g, ox + 0.09 * w, mx0 - 0.02 * w, my0, my1);
		fprintf(g,
		        "unset title\nset xrange [%g:%g]\nset yrange [-0.5:%g]\nset ytics 1 format "
		        "'%s'\nset xtics %g format '%%g'\nset xlabel '%s side exit (%%)'\n"
		        "set ylabel '%s'\n"
		        "plot '%s' index %d using (50*$%d):1:(50*$%d):(0.35) with boxxyerror fs "
		        "solid 0.8 lc rgb '%s', \\\n"
		        "     '' index %d using ($%d > 0 ? 100*$%d : NaN):1:(100*$%d):(100*$%d) "
		        "with xerrorbars pt 7 ps 0.4 lc rgb '%s'\n",
		        side ? 0.0 : ps, side ? ps : 0.0, a->rows - 0.5, side ? "" : "%g",
		        tic_step(ps), side ? "right" : "left", side ? "" : "gate row i_y", file,
		        b0 + 1, c, c, FIG_GREY, b0 + 1, c + 3, c, c + 1, c + 2, FIG_BLACK);
	}
	/* the stuck gates as a map */
	at(g, mx0, mx1, my0, my1);
	fprintf(g,
	        "set xrange [%g:%g]\nset yrange [-0.5:%g]\nset xtics 1 format '%%g'\n"
	        "set ytics 1 format ''\nunset grid\nset xlabel 'gate column i_x: stuck in gate "
	        "(i_x, i_y)'\nunset ylabel\n"
	        "set palette defined (0 '#FFFFFF', 1 '#5A5A5A')\nset cbrange [0:%.6g]\n"
	        "plot '%s' index %d using 1:2:(0.5):(0.5):3 with boxxyerror fs solid 1.0 "
	        "border lc rgb '#D0D0D0' fc palette, \\\n"
	        "     '' index %d using 1:2:($6 > 0 ? sprintf(\"%%.1f%%%%\\n[%%.1f, %%.1f]\", "
	        "100*$3, 100*$4, 100*$5) : ''):($3 > 0.6*%.6g ? 0xFFFFFF : 0) with labels tc rgb "
	        "variable font ',%d'\n",
	        a->ix_min - 0.5, a->ix_max + 0.5, a->rows - 0.5, pk, file, b0 + 2, b0 + 2, pk,
	        a->cols > 11 ? 6 : 8);
}

static int locations_figure(figs *f, const char *name, const char *title, const flat *const *runs,
                            const char *const *labels, int n_runs, bsim_error *err)
{
	char file[200], path[BSIM_PATH_MAX];
	snprintf(file, sizeof file, "%s.dat", name);
	bsim_atomic_file o;
	int rc = bsim_figs_data_open(f, file, &o, path, err);
	if (rc)
		return rc;
	double top[3] = {0.0, 0.0, 0.0};
	for (int i = 0; i < n_runs; i++) {
		locations_blocks(o.f, runs[i], labels[i], i == 0);
		locations_top(runs[i], top);
	}
	if ((rc = bsim_figs_data_commit(&o, err)))
		return rc;
	gp_text g;
	if ((rc = bsim_gp_text_open(&g, err)))
		return rc;
	/* the note on intervals: a location never reached is drawn without one */
	char full[8400]; /* the title of many sides: a line per pair */
	double zero[3];
	fraction(runs[0], 0, zero);
	snprintf(full, sizeof full,
	         "%s\nWilson 95%% intervals, drawn where a location was reached (0 of %d trials: "
	         "up to %.2g%%)",
	         title, runs[0]->trials, 100.0 * zero[2]);
	fputs("set multiplot title ", g.f);
	bsim_gp_str(g.f, full);
	fputs(" noenhanced\n", g.f);
	int lines = 1;
	for (const char *c = full; *c; c++)
		lines += *c == '\n';
	const double top_y = 1.0 - 0.03 * lines;
	for (int i = 0; i < n_runs; i++) {
		char line[300];
		locations_line(runs[i], line, sizeof line);
		locations_region(g.f, file, 3 * i, runs[i], (double)i / n_runs, 1.0 / n_runs, top_y,
		                 top, labels[i], line);
	}
	fputs("unset multiplot\n", g.f);
	char *body = bsim_gp_text_take(&g);
	rc = body ? bsim_figs_render(f, name, 980 * n_runs, 820, body, err)
	          : bsim_error_set(err, BSIM_EFAIL, "out of memory");
	free(body);
	return rc;
}

/* ---- a lattice sweep ------------------------------------------------------------------ */

struct lat_job {
	const fsum *s;
	flats l;
	bsim_experiment e;
	int have_e;
	csv_table table;
	int have_table;
	double *cols; /* group, trial, x, y of trajectories.csv, n_rows each */
	lpath *paths;
	int n_paths;
	int *first, *count; /* per group: its first path and how many */
};

static void lat_free(lat_job *j)
{
	flats_free(&j->l);
	if (j->have_e)
		bsim_experiment_free(&j->e);
	if (j->have_table)
		bsim_csv_table_free(&j->table);
	free(j->cols);
	free(j->paths);
	free(j->first);
	free(j->count);
}

/* The kept trajectories as paths: runs of rows of one (group, trial). */
static int paths_read(const char *dir, lat_job *j, bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	snprintf(path, sizeof path, "%s/trajectories.csv", dir);
	int rc = bsim_csv_table_read(path, &j->table, err);
	if (rc)
		return rc;
	j->have_table = 1;
	static const char *const need[] = {"group", "trial", "x", "y"};
	int col[4];
	if ((rc = bsim_csv_table_require(&j->table, path, need, 4, col, err)))
		return rc;
	const size_t n = (size_t)j->table.n_rows;
	j->cols = malloc((4 * n + 1) * sizeof *j->cols);
	j->paths = malloc((n + 1) * sizeof *j->paths);
	j->first = calloc((size_t)j->s->n_groups + 1, sizeof *j->first);
	j->count = calloc((size_t)j->s->n_groups + 1, sizeof *j->count);
	if (!j->cols || !j->paths || !j->first || !j->count)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory reading %s", path);
	for (int c = 0; !rc && c < 4; c++)
		rc = bsim_csv_table_numbers(&j->table, path, col[c], 0, 0.0,
		                            j->cols + (size_t)c * n, err);
	const double *gg = j->cols, *tt = gg + n, *xx = tt + n, *yy = xx + n;
	for (size_t r = 0; !rc && r < n;) {
		size_t e = r + 1;
		while (e < n && gg[e] == gg[r] && tt[e] == tt[r])
			e++;
		const double g = gg[r], t = tt[r];
		if (g != floor(g) || g < 0 || g >= j->s->n_groups || t != floor(t) || t < 0 ||
		    t >= j->s->trials_per_group)
			return bsim_error_set(
			        err, BSIM_EINPUT,
			        "%s:%zu: group, trial: expected integers within the %d "
			        "groups x %d trials of summary.json",
			        path, r + 2, j->s->n_groups, j->s->trials_per_group);
		const flat *a = &j->l.g[(int)g];
		if (j->count[(int)g]++ == 0)
			j->first[(int)g] = j->n_paths;
		else if (j->paths[j->n_paths - 1].group != (int)g)
			return bsim_error_set(
			        err, BSIM_EINPUT,
			        "%s:%zu: group %g: expected each group's rows together", path,
			        r + 2, g);
		j->paths[j->n_paths++] = (lpath){
		        .group = (int)g,
		        .trial = (int)t,
		        .end = a->where[(int)t] == FLAT_END,
		        .n = (long)(e - r),
		        .x = xx + r,
		        .y = yy + r,
		};
		r = e;
	}
	return rc;
}

/* The run's header and group g's values on one line, for a title. */
static void group_label(const fsum *s, int g, char *buf, size_t size)
{
	char l[512];
	bsim_fsum_label(s, g, l, sizeof l);
	for (char *c = l; *c; c++)
		*c = *c == '\n' ? ' ' : *c;
	snprintf(buf, size, "%s%s%s", s->header, *l ? "; " : "", l);
}

/* Both figures of group g. */
static int lat_group(figs *f, lat_job *j, int g, bsim_error *err)
{
	const fsum *s = j->s;
	const flat *a = &j->l.g[g];
	char label[1300], title[1500], name[64];
	group_label(s, g, label, sizeof label);
	snprintf(name, sizeof name, "final_locations_g%03d", g);
	snprintf(title, sizeof title, "where the trials of group %d ended\n%s", g, label);
	const char *run_label = *s->backend ? s->backend : "trials";
	int rc = locations_figure(f, name, title, &a, &run_label, 1, err);
	if (rc || !j->have_e)
		return rc;
	bsim_scene scene;
	if ((rc = bsim_experiment_group_scene(&j->e, g, NULL, 0, &scene, err)))
		return rc;
	const bsim_lattice_def *L = &scene.lattice;
	if (!scene.has_lattice || L->ix_min != a->ix_min || L->ix_max != a->ix_max ||
	    L->rows != a->rows)
		rc = bsim_error_set(err, BSIM_EINPUT,
		                    "group %d: the scene of the stored experiment is not the "
		                    "lattice of lattice_map.csv (ix %d .. %d, %d rows)",
		                    g, a->ix_min, a->ix_max, a->rows);
	if (!rc)
		rc = lattice_map_figure(f, g, label, a, &scene,
		                        j->paths ? j->paths + j->first[g] : NULL,
		                        j->count ? j->count[g] : 0, err);
	bsim_scene_free(&scene);
	return rc;
}

int bsim_figs_lattice_load(figs *f, const char *dir, const char *inputs, const fsum *s,
                           lat_job **out, bsim_error *err)
{
	lat_job *j = calloc(1, sizeof *j);
	*out = NULL;
	if (!j)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	j->s = s;
	int rc = flats_read(dir, s, &j->l, err);
	char exp_path[BSIM_PATH_MAX];
	snprintf(exp_path, sizeof exp_path, "%s/experiment.yaml", inputs);
	struct stat st;
	if (!rc && stat(exp_path, &st) == 0) {
		rc = bsim_experiment_load(exp_path, NULL, 0, &j->e, err);
		j->have_e = rc == BSIM_OK;
		if (!rc && j->e.n_groups != s->n_groups)
			rc = bsim_error_set(err, BSIM_EINPUT,
			                    "%s: %d groups, but %s/summary.json has %d", exp_path,
			                    j->e.n_groups, dir, s->n_groups);
	} else if (!rc) {
		bsim_figs_note(f, "%s: no %s, so no scene to draw the stiffness map's beams on",
		               dir, exp_path);
	}
	if (!rc && j->have_e && file_exists(dir, "trajectories.csv"))
		rc = paths_read(dir, j, err);
	if (rc)
		bsim_figs_lattice_free(j);
	else
		*out = j;
	return rc;
}

void bsim_figs_lattice_free(lat_job *j)
{
	if (!j)
		return;
	lat_free(j);
	free(j);
}

static int lat_group_fn(figs *f, void *job, int g, bsim_error *err)
{
	lat_job *j = job;
	return j->s->g[g].selected ? lat_group(f, j, g, err) : BSIM_OK;
}

int bsim_figs_lattice_draw(figs *f, lat_job *j, bsim_error *err)
{
	return bsim_figs_each_group(f, j->s->n_groups, lat_group_fn, j, err);
}

int bsim_figs_is_lattice(const char *dir)
{
	return file_exists(dir, "lattice_map.csv");
}

/* ---- a comparison of two lattice runs -------------------------------------------------- */

int bsim_figs_lattice_compare(figs *f, int n, const char *const *dirs, const char *const *labels,
                              const fsum *s, const char *const *tests, bsim_error *err)
{
	flats l[BSIM_COMPARE_SIDES_MAX];
	int rc = BSIM_OK, read = 0;
	for (; !rc && read < n; read++)
		if ((rc = flats_read(dirs[read], s, &l[read], err)))
			break;
	for (int g = 0; !rc && g < s->n_groups; g++) {
		if (!s->g[g].selected)
			continue;
		const flat *runs[BSIM_COMPARE_SIDES_MAX];
		for (int i = 0; !rc && i < n; i++) {
			runs[i] = &l[i].g[g];
			if (runs[i]->cols != runs[0]->cols || runs[i]->rows != runs[0]->rows ||
			    runs[i]->ix_min != runs[0]->ix_min)
				rc = bsim_error_set(err, BSIM_EINPUT,
				                    "%s and %s: group %d: the two sides' "
				                    "lattice_map.csv are not the same lattice",
				                    dirs[0], dirs[i], g);
		}
		if (rc)
			break;
		char label[1300], title[8192], who[600] = "", name[64];
		group_label(s, g, label, sizeof label);
		if (n == 2)
			snprintf(who, sizeof who, "%s against %s", labels[0], labels[1]);
		for (int i = 0, len = 0; n > 2 && i < n && len < (int)sizeof who; i++) {
			int w = snprintf(who + len, sizeof who - (size_t)len, "%s%s",
			                 i == 0      ? ""
			                 : i + 1 < n ? ", "
			                             : " and ",
			                 labels[i]);
			len += w > 0 ? w : 0;
		}
		snprintf(title, sizeof title,
		         "where the trials of group %d ended, %s on the same schedules\n%s\n%s", g,
		         who, label, tests[g]);
		snprintf(name, sizeof name, "final_locations_g%03d", g);
		rc = locations_figure(f, name, title, runs, labels, n, err);
	}
	for (int i = 0; i < read; i++)
		flats_free(&l[i]);
	return rc;
}
