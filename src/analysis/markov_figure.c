/* The final locations of a lattice drawn as the field (markov_internal.h):
 * a map of the gates with, in each, the probability to be stuck there, the
 * ends as a row above the last row and the sides as a column beside the
 * field, the value of every cell of at least 0.5% written in it. Panels
 * side by side: probabilities (predicted, simulated) on one scale, their
 * differences on a diverging one, the colour bars in % as the cells. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "analysis/markov_internal.h"
#include "beamsim/key_names.h"
#include "beamsim/limits.h"
#include "util/atomic_file.h"
#include "util/figure.h"

/* The ends' row stands this far above the last row of gates and the sides'
 * column this far right of the last column, cells apart: a gap that says
 * they are not gates. */
#define OUTSIDE_GAP 1.6

/* Cells drawn as squares of this half width, in cells. */
#define CELL_HALF 0.47

/* A cell's value is written in it from this probability (0.5%) on. */
#define LABEL_FROM 0.005

void bsim_markov_title_params(char *buf, size_t size, const char *backend, const bsim_override *ov,
                              int n)
{
	size_t k = 0;
	buf[0] = '\0';
	if (backend && *backend)
		k = (size_t)snprintf(buf, size, "backend %s", backend);
	for (int i = 0; i < n && k < size; i++) {
		char kv[200];
		bsim_key_value(ov[i].key, ov[i].value, 0, kv, sizeof kv);
		int m = snprintf(buf + k, size - k, "%s%s", k ? ", " : "", kv);
		if (m < 0)
			break;
		k += (size_t)m;
	}
}

/* The field's extent from its locations: columns ix_min..ix_max (the ends),
 * rows 0..rows-1 (the sides). */
static void extent(const bsim_location *loc, int n, int *ix_min, int *ix_max, int *rows)
{
	*ix_min = 0;
	*ix_max = 0;
	*rows = 0;
	int first = 1;
	for (int i = 0; i < n; i++) {
		if (loc[i].kind == BSIM_LOCATION_SIDE && loc[i].iy + 1 > *rows)
			*rows = loc[i].iy + 1;
		if (loc[i].kind == BSIM_LOCATION_SIDE)
			continue;
		if (first || loc[i].ix < *ix_min)
			*ix_min = loc[i].ix;
		if (first || loc[i].ix > *ix_max)
			*ix_max = loc[i].ix;
		if (loc[i].kind == BSIM_LOCATION_STUCK && loc[i].iy + 1 > *rows)
			*rows = loc[i].iy + 1;
		first = 0;
	}
}

void bsim_markov_field_totals(const bsim_location *loc, const double *p, int n, double tot[3])
{
	tot[0] = tot[1] = tot[2] = 0.0;
	for (int i = 0; i < n; i++)
		tot[loc[i].kind == BSIM_LOCATION_END    ? 0
		    : loc[i].kind == BSIM_LOCATION_SIDE ? 1
		                                        : 2] += p[i];
}

int bsim_markov_field_figure(const char *stage, const char *name, const char *title,
                             const bsim_location *loc, int n, const markov_field_panel *panel,
                             int n_panels, int per_row, int *drawn, bsim_error *err)
{
	int ix_min, ix_max, rows;
	extent(loc, n, &ix_min, &ix_max, &rows);
	char path[BSIM_PATH_MAX];
	snprintf(path, sizeof path, "%s/%s.dat", stage, name);
	bsim_atomic_file o;
	if (bsim_atomic_file_open(&o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	fputs("# one block per panel (gnuplot index): x y (cell centre: x = column ix, y = row "
	      "iy;\n# the ends at y = rows + 0.6, the sides at x = ix_max + 1.6), value "
	      "(probability or difference), location, value in % where |value| >= 0.5%\n",
	      o.f);
	double vmax = 0.0, dmax = 0.0;
	for (int k = 0; k < n_panels; k++) {
		fprintf(o.f, "%s# %s\n", k ? "\n\n" : "", panel[k].p ? panel[k].title : "(empty)");
		if (!panel[k].p) { /* an empty place: a block all the same */
			fputs("NaN NaN NaN none \"\"\n", o.f);
			continue;
		}
		for (int i = 0; i < n; i++) {
			const double v = panel[k].p[i] - (panel[k].minus ? panel[k].minus[i] : 0.0);
			double x = loc[i].ix, y = loc[i].iy;
			if (loc[i].kind == BSIM_LOCATION_END)
				y = rows - 1 + OUTSIDE_GAP;
			else if (loc[i].kind == BSIM_LOCATION_SIDE)
				x = ix_max + OUTSIDE_GAP;
			char label[48], text[32] = "\"\"";
			bsim_lattice_location_label(loc[i], label, sizeof label);
			if (fabs(v) >= LABEL_FROM)
				snprintf(text, sizeof text, "\"%.*f\"", fabs(v) >= 0.1 ? 0 : 1,
				         100.0 * v);
			fprintf(o.f, "%g %g %.8g %s %s\n", x, y, v, label, text);
			if (panel[k].minus)
				dmax = fmax(dmax, fabs(v));
			else
				vmax = fmax(vmax, v);
		}
	}
	if (bsim_atomic_file_commit(&o, err) != BSIM_OK)
		return BSIM_EFAIL;

	char *body = NULL;
	size_t len = 0;
	FILE *f = open_memstream(&body, &len);
	if (!f)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	const int n_rows = (n_panels + per_row - 1) / per_row;
	/* the title as a gnuplot string in double quotes: a line break as \n */
	char t[1200];
	size_t m = 0;
	for (const char *c = title; *c && m + 3 < sizeof t; c++) {
		if (*c == '\n') {
			t[m++] = '\\';
			t[m++] = 'n';
		} else
			t[m++] = *c == '"' || *c == '\\' ? '\'' : *c;
	}
	t[m] = '\0';
	fprintf(f, "set multiplot layout %d,%d title \"%s\" noenhanced\n", n_rows, per_row, t);
	fprintf(f, "set size ratio -1\nset xrange [%g:%g]\nset yrange [%g:%g]\n", ix_min - 0.6,
	        ix_max + OUTSIDE_GAP + 0.6, -0.6, rows - 1 + OUTSIDE_GAP + 0.6);
	/* tics: every column and row, "side" and "end" for the cells outside */
	fputs("set xtics (", f);
	for (int ix = ix_min; ix <= ix_max; ix++)
		fprintf(f, "\"%d\" %d, ", ix, ix);
	fprintf(f, "\"side\" %g) scale 0\nset ytics (", ix_max + OUTSIDE_GAP);
	for (int iy = 0; iy < rows; iy++)
		fprintf(f, "\"%d\" %d, ", iy, iy);
	fprintf(f,
	        "\"end\" %g) scale 0\nset xlabel 'column ix'\nset ylabel 'row iy'\n"
	        "set border 0\nunset key\nset style fill solid 1.0 border lc rgb '#D0D0D0'\n"
	        "set colorbox\nset rmargin 13\n", /* room for the colour bar's label */
	        rows - 1 + OUTSIDE_GAP);
	for (int k = 0; k < n_panels; k++) {
		if (!panel[k].p) {
			fputs("set multiplot next\n", f);
			continue;
		}
		double tot[3];
		bsim_markov_field_totals(loc, panel[k].p, n, tot);
		if (panel[k].minus) {
			double t2[3];
			bsim_markov_field_totals(loc, panel[k].minus, n, t2);
			for (int j = 0; j < 3; j++)
				tot[j] -= t2[j];
			fprintf(f,
			        "set palette defined (-1 '#B2182B', 0 '#F7F7F7', 1 '#2166AC')\n"
			        "set cbrange [%g:%g]\nset cblabel 'difference (%% points)'\n"
			        "set title \"%s\\nend %+.1f%%, side %+.1f%%, stuck %+.1f%%\" "
			        "noenhanced\n",
			        -100 * fmax(dmax, 1e-3), 100 * fmax(dmax, 1e-3), panel[k].title,
			        100 * tot[0], 100 * tot[1], 100 * tot[2]);
		} else
			fprintf(f,
			        "set palette defined (0 '#FFFFFF', 0.5 '#9ECAE1', 1 '#3182BD')\n"
			        "set cbrange [0:%g]\nset cblabel 'probability (%%)'\n"
			        "set title \"%s\\nend %.1f%%, side %.1f%%, stuck %.1f%%\" "
			        "noenhanced\n",
			        100 * fmax(vmax, 1e-3), panel[k].title, 100 * tot[0], 100 * tot[1],
			        100 * tot[2]);
		fprintf(f,
		        "plot '%s.dat' index %d using 1:2:(%g):(%g):(100 * $3) with boxxyerror "
		        "fc palette, \\\n"
		        "     '' index %d using 1:2:5 with labels font ',8' tc rgb 'black'\n",
		        name, k, CELL_HALF, CELL_HALF, k);
	}
	fputs("unset multiplot\n", f);
	if (fclose(f) != 0) {
		free(body);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	bsim_figure_def fd = bsim_figure_def_default();
	fd.dir = stage;
	fd.name = name;
	fd.width = per_row > 1 ? 560 * per_row : 760;
	fd.height = 110 + 520 * n_rows;
	int rc = bsim_figure_render(&fd, body, drawn, err);
	free(body);
	return rc;
}
