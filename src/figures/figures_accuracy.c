/* The accuracy study drawn (figures.h, beamsim accuracy): consistency
 * error against speed on log-log axes, one series per backend and knob
 * setting (rows of accuracy.csv with the same backend and setting, h from
 * coarse to fine), and the Pareto front over the points drawn: a point is
 * on it when no other is at least as fast and as accurate and better in
 * one. The reference step is left out: there a backend is compared with
 * itself (error 0 or float32 round-off), which says nothing of cost. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/backend_registry.h"
#include "figures/figures_kinds.h"
#include "figures/figures_toolkit.h"
#include "util/csv_table.h"
#include "beamsim/limits.h"

static const char *const palette[] = {FIG_BLUE, FIG_RED,    FIG_GREEN, FIG_ORANGE,
                                      FIG_SKY,  FIG_PURPLE, FIG_BLACK, "#8C6D31"};

/* A series' point type by its backend's place in the registry (filled
 * circle, triangle, square, ...): the colours tell a backend's settings
 * apart, the points the backends. A name the registry does not hold (a
 * directory stored by another build) gets an open circle. */
static int backend_mark(const char *name)
{
	static const int mark[] = {7, 9, 5, 11, 13, 15};
	const bsim_backend *const *all = bsim_backend_list();
	for (int i = 0; all[i]; i++)
		if (strcmp(all[i]->name, name) == 0)
			return mark[i % 6];
	return 6;
}

typedef struct acc_point {
	double speed, err, h;
	int series;
} acc_point;

/* Fastest first; of equally fast points the more accurate first. */
static int cmp_speed(const void *a, const void *b)
{
	const acc_point *x = a, *y = b;
	if (x->speed != y->speed)
		return (x->speed < y->speed) - (x->speed > y->speed);
	return (x->err > y->err) - (x->err < y->err);
}

int bsim_figs_accuracy(figs *f, const char *dir, bsim_error *err)
{
	if (f->def->n_select > 0)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: --select chooses groups of a sweep; the accuracy study "
		                      "has none",
		                      dir);
	char path[BSIM_PATH_MAX], file[BSIM_PATH_MAX];
	snprintf(path, sizeof path, "%s/accuracy.csv", dir);
	csv_table t;
	int rc = bsim_csv_table_read(path, &t, err);
	if (rc)
		return rc;
	static const char *const need[] = {"backend", "setting", "h_s", "err_mean_m",
	                                   "speed_x_realtime"};
	int col[5];
	rc = bsim_csv_table_require(&t, path, need, 5, col, err);
	const size_t n = (size_t)t.n_rows;
	double *v = malloc((3 * n + 1) * sizeof *v);
	acc_point *pt = malloc((n + 1) * sizeof *pt);
	int *series = malloc((n + 1) * sizeof *series);
	if (!rc && (!v || !pt || !series))
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	for (int c = 0; !rc && c < 3; c++)
		rc = bsim_csv_table_numbers(&t, path, col[2 + c], 0, 0.0, v + (size_t)c * n, err);
	double h_ref = INFINITY;
	for (size_t r = 0; !rc && r < n; r++)
		h_ref = fmin(h_ref, v[r]);
	/* Series: consecutive rows of one backend and setting. */
	int n_series = 0;
	for (size_t r = 0; !rc && r < n; r++) {
		int same = r > 0 &&
		           strcmp(bsim_csv_table_cell(&t, r, col[0]),
		                  bsim_csv_table_cell(&t, r - 1, col[0])) == 0 &&
		           strcmp(bsim_csv_table_cell(&t, r, col[1]),
		                  bsim_csv_table_cell(&t, r - 1, col[1])) == 0;
		series[r] = same ? series[r - 1] : n_series++;
	}
	size_t n_pt = 0;
	for (size_t r = 0; !rc && r < n; r++) {
		double h = v[r], e = v[n + r], sp = v[2 * n + r];
		if (h > 1.5 * h_ref && e > 0 && sp > 0 && isfinite(e) && isfinite(sp) &&
		    series[r] < 256)
			pt[n_pt++] = (acc_point){sp, e, h, series[r]};
	}
	bsim_atomic_file o;
	if (!rc)
		rc = bsim_figs_data_open(f, "accuracy.dat", &o, file, err);
	if (rc) {
		free(v);
		free(pt);
		free(series);
		bsim_csv_table_free(&t);
		return rc;
	}
	fputs("# speed (simulated s per wall s), consistency error (m), h (s): one block per "
	      "backend and setting, then the Pareto front by speed\n",
	      o.f);
	int first_row[256];
	int drawn_series = n_series < 256 ? n_series : 256;
	for (int s = 0; s < drawn_series; s++) {
		first_row[s] = -1;
		for (size_t r = 0; r < n && first_row[s] < 0; r++)
			if (series[r] == s)
				first_row[s] = (int)r;
		fprintf(o.f, "%s# %s %s\n", s ? "\n\n" : "",
		        bsim_csv_table_cell(&t, first_row[s], col[0]),
		        bsim_csv_table_cell(&t, first_row[s], col[1]));
		int any = 0;
		for (size_t i = 0; i < n_pt; i++)
			if (pt[i].series == s) {
				fprintf(o.f, "%.6g %.6g %.6g\n", pt[i].speed, pt[i].err, pt[i].h);
				any = 1;
			}
		if (!any)
			fputs("NaN NaN NaN\n", o.f);
	}
	/* The front: by falling speed, a point joins when it is more accurate
	 * than every faster one. */
	qsort(pt, n_pt, sizeof *pt, cmp_speed);
	fputs("\n\n# Pareto front: speed error h backend setting\n", o.f);
	double best = INFINITY;
	int on_front = 0;
	for (size_t i = 0; i < n_pt; i++) {
		if (pt[i].err < best) {
			best = pt[i].err;
			int r = first_row[pt[i].series];
			fprintf(o.f, "%.6g %.6g %.6g %s \"%s\"\n", pt[i].speed, pt[i].err, pt[i].h,
			        bsim_csv_table_cell(&t, r, col[0]),
			        bsim_csv_table_cell(&t, r, col[1]));
			on_front++;
		}
	}
	if (!on_front)
		fputs("NaN NaN NaN\n", o.f);
	rc = bsim_figs_data_commit(&o, err);
	gp_text g;
	if (!rc)
		rc = bsim_gp_text_open(&g, err);
	if (!rc) {
		fputs("set title 'consistency error against speed, h from 0.016 s halved down to "
		      "the "
		      "reference step (not drawn)'\n"
		      "set logscale xy\nset format x '10^{%L}'\nset format y '10^{%L}'\n"
		      "set xlabel 'speed: simulated s per wall s (x real time, one thread)'\n"
		      "set ylabel 'consistency error after 0.064 s pieces (m)'\n"
		      "set grid\nset key outside right top font ',9' noenhanced\nset rmargin 36\n"
		      "plot ",
		      g.f);
		for (int s = 0; s < drawn_series; s++) {
			int r = first_row[s];
			fprintf(g.f,
			        "'accuracy.dat' index %d using 1:2 with linespoints lw 1.5 dt %d "
			        "pt %d "
			        "ps 0.9 lc rgb '%s' title ",
			        s, s / 8 % 2 ? 2 : 1,
			        backend_mark(bsim_csv_table_cell(&t, r, col[0])), palette[s % 8]);
			char label[200];
			snprintf(label, sizeof label, "%s %s", bsim_csv_table_cell(&t, r, col[0]),
			         bsim_csv_table_cell(&t, r, col[1]));
			bsim_gp_str(g.f, label);
			fputs(", \\\n     ", g.f);
		}
		fprintf(g.f,
		        "'accuracy.dat' index %d using 1:2 with linespoints lw 5 lc rgb "
		        "'#55000000' "
		        "pt 6 ps 2.2 title 'Pareto front'\n",
		        drawn_series);
		char *body = bsim_gp_text_take(&g);
		rc = body ? bsim_figs_render(f, "accuracy", 1200, 700, body, err)
		          : bsim_error_set(err, BSIM_EFAIL, "out of memory");
		free(body);
	}
	free(v);
	free(pt);
	free(series);
	bsim_csv_table_free(&t);
	return rc;
}
