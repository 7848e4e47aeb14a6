/* Figures of a sweep (figures.h): p_traverse as a heat map over the grid's
 * first two axes (essay Fig. 3.1), traversal and its left / right types
 * against each axis with 95% bands (Fig. 3.4), and the kept trajectories
 * (Figs. 3.2, 3.3).
 *
 * The numbers come from summary.json (counts, p_traverse and its Wilson
 * interval as the sweep computed them); the left / right intervals are
 * Wilson intervals of those counts, and the landscape label (the barrier
 * crossed, bsim_landscape_label) is drawn beside the v_x type it is meant
 * to check. A selection (--select KEY=VALUE) keeps the groups that match it;
 * an axis left with one value is no longer drawn along. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "beamsim/experiment.h"
#include "beamsim/key_names.h"
#include "store/mat.h"
#include "beamsim/stats.h"
#include "figures/figures_kinds.h"
#include "figures/figures_lattice.h"
#include "figures/figures_paths.h"
#include "figures/figures_summary.h"
#include "figures/figures_survival.h"
#include "figures/figures_toolkit.h"
#include "util/csv_table.h"
#include "util/figure.h"
#include "beamsim/limits.h"

/* Positions of the selected values of each axis (-1: not selected) and
 * their number. */
typedef struct active {
	int *pos[64];
	int n[64];
} active;

static int active_build(const fsum *s, active *a, bsim_error *err)
{
	memset(a, 0, sizeof *a);
	if (s->n_axes > 64)
		return bsim_error_set(err, BSIM_EINPUT, "more than 64 grid axes");
	for (int ax = 0; ax < s->n_axes; ax++) {
		a->pos[ax] = malloc((size_t)s->axes[ax].n_values * sizeof(int));
		if (!a->pos[ax])
			return bsim_error_set(err, BSIM_EFAIL, "out of memory");
		for (int i = 0; i < s->axes[ax].n_values; i++) {
			int used = 0;
			for (int g = 0; g < s->n_groups && !used; g++)
				used = s->g[g].selected && s->g[g].idx[ax] == i;
			a->pos[ax][i] = used ? a->n[ax]++ : -1;
		}
	}
	return BSIM_OK;
}

static void active_free(active *a, int n_axes)
{
	for (int ax = 0; ax < n_axes && ax < 64; ax++)
		free(a->pos[ax]);
}

/* The panel of group g over the axes other than skip0 and skip1 (-1:
 * none): its index among the combinations of their selected values, the
 * first such axis slowest. */
static int panel_of(const fsum *s, const active *a, int g, int skip0, int skip1)
{
	int p = 0;
	for (int ax = 0; ax < s->n_axes; ax++)
		if (ax != skip0 && ax != skip1)
			p = p * a->n[ax] + a->pos[ax][s->g[g].idx[ax]];
	return p;
}

static int panels(const fsum *s, const active *a, int skip0, int skip1)
{
	int n = 1;
	for (int ax = 0; ax < s->n_axes; ax++)
		if (ax != skip0 && ax != skip1)
			n *= a->n[ax];
	return n;
}

/* "F_prop = 8 N, ..." of the other axes of group g with more than one
 * value (a single value is in the figure's title), "" if there are none. */
static void panel_label(const fsum *s, const active *a, int g, int skip0, int skip1, char *buf,
                        size_t size)
{
	size_t k = 0;
	buf[0] = '\0';
	for (int ax = 0; ax < s->n_axes && k < size; ax++) {
		if (ax == skip0 || ax == skip1 || a->n[ax] < 2)
			continue;
		char kv[200];
		bsim_figs_key_value(s->axes[ax].key, s->axes[ax].values[s->g[g].idx[ax]], kv,
		                    sizeof kv);
		int n = snprintf(buf + k, size - k, "%s%s", k ? ", " : "", kv);
		k += n > 0 ? (size_t)n : 0;
	}
}

/* A layout of n panels, about 3:2. */
static void layout(int n, int *rows, int *cols)
{
	*cols = (int)ceil(sqrt(1.5 * n));
	if (*cols > n)
		*cols = n;
	*rows = (n + *cols - 1) / *cols;
}

/* gnuplot tics naming each selected value of an axis at its position;
 * the length of the longest, in characters. */
static int tics(FILE *f, const char *which, const fsum_axis *ax, const int *pos)
{
	fprintf(f, "set %stics (", which);
	int k = 0, longest = 1;
	for (int i = 0; i < ax->n_values; i++)
		if (pos[i] >= 0) {
			fputs(k++ ? ", " : "", f);
			bsim_gp_str(f, ax->values[i]);
			fprintf(f, " %d", pos[i]);
			int n = (int)strlen(ax->values[i]);
			longest = n > longest ? n : longest;
		}
	fputs(") noenhanced\n", f);
	return longest;
}

/* The axes drawn along: the first two with more than one selected value,
 * -1 for none. */
static void axes_along(const fsum *s, const active *a, int *ax0, int *ax1)
{
	*ax0 = *ax1 = -1;
	for (int ax = 0; ax < s->n_axes; ax++)
		if (a->n[ax] >= 2) {
			if (*ax0 < 0)
				*ax0 = ax;
			else if (*ax1 < 0)
				*ax1 = ax;
		}
}

/* ---- Fig. 3.1 -------------------------------------------------------------------- */

/* The most panels one figure of traversal against an axis holds. */
#define PAGE_PANELS 12

/* Pixels of a text at the figures' 11 pt font, with a margin of 60. */
static int text_px(const char *text)
{
	return bsim_figure_text_px(text, 11) + 60;
}

static int heat_map(figs *f, const fsum *s, const active *a, int lattice, bsim_error *err)
{
	/* drawn along the axes with several values; one with a single value
	 * is named in the title instead */
	int ax0, ax1;
	axes_along(s, a, &ax0, &ax1);
	const int n0 = ax0 >= 0 ? a->n[ax0] : 1, n1 = ax1 >= 0 ? a->n[ax1] : 1;
	const int np = panels(s, a, ax0, ax1);
	char path[BSIM_PATH_MAX];
	bsim_atomic_file o;
	int rc = bsim_figs_data_open(f, "p_traverse.dat", &o, path, err);
	if (rc)
		return rc;
	fputs("# column row p_traverse ci95_lo ci95_hi traversed trials group: one block per "
	      "panel\n",
	      o.f);
	int *first = malloc((size_t)np * sizeof *first);
	if (!first) {
		bsim_atomic_file_abort(&o);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	for (int p = 0; p < np; p++) {
		first[p] = -1;
		fprintf(o.f, "%s# panel %d\n", p ? "\n\n" : "", p);
		for (int g = 0; g < s->n_groups; g++) {
			const fsum_group *G = &s->g[g];
			if (!G->selected || panel_of(s, a, g, ax0, ax1) != p)
				continue;
			if (first[p] < 0)
				first[p] = g;
			fprintf(o.f, "%d %d %.6g %.6g %.6g %d %d %d\n",
			        ax0 >= 0 ? a->pos[ax0][G->idx[ax0]] : 0,
			        ax1 >= 0 ? a->pos[ax1][G->idx[ax1]] : 0, G->p, G->lo, G->hi,
			        G->traversed, G->trials, g);
		}
	}
	if ((rc = bsim_figs_data_commit(&o, err))) {
		free(first);
		return rc;
	}
	gp_text g;
	if ((rc = bsim_gp_text_open(&g, err))) {
		free(first);
		return rc;
	}
	int rows, cols;
	layout(np, &rows, &cols);
	/* A group without random force runs one trial (copied to the others):
	 * its interval is a point, and the title says so rather than counting
	 * trials it did not run. */
	int one_trial = 0;
	for (int k = 0; k < s->n_groups; k++)
		one_trial |= s->g[k].selected && s->g[k].lo == s->g[k].hi;
	char title[1000];
	snprintf(title, sizeof title,
	         "traversal probability p_traverse%s, %d trials per group%s, [95%% Wilson "
	         "interval]\n%s",
	         lattice ? " (reached the end of the lattice)" : "", s->trials_per_group,
	         one_trial ? " (without random force: 1)" : "", s->header);
	fprintf(g.f, "set multiplot layout %d,%d title ", rows, cols);
	bsim_gp_str(g.f, title);
	fputs(" noenhanced\n"
	      "set palette defined (0 '#F7FBFF', 0.5 '#6BAED6', 1 '#08306B')\n"
	      "set cbrange [0:1]\nset cblabel 'p_{traverse}'\nset cbtics 0.2\n",
	      g.f);
	fprintf(g.f, "set xrange [-0.5:%g]\nset yrange [-0.5:%g]\n", n0 - 0.5, n1 - 0.5);
	/* a cell fits its two lines of numbers and its tick label; the panel
	 * its y labels, the colour box and its title */
	int xtic = 4, ytic = 4, ylab = 0;
	char label[400], xlab[400] = "";
	if (ax0 >= 0) {
		xtic = tics(g.f, "x", &s->axes[ax0], a->pos[ax0]);
		fputs("set xlabel ", g.f);
		bsim_gp_key_label(g.f, s->axes[ax0].key);
		fputs("\n", g.f);
		bsim_key_label(s->axes[ax0].key, 0, xlab, sizeof xlab);
	} else {
		fputs("unset xtics\n", g.f);
	}
	if (ax1 >= 0) {
		ytic = tics(g.f, "y", &s->axes[ax1], a->pos[ax1]);
		fputs("set ylabel ", g.f);
		bsim_gp_key_label(g.f, s->axes[ax1].key);
		fputs("\n", g.f);
		ylab = 1;
	} else {
		fputs("unset ytics\n", g.f);
	}
	fputs("set tics out nomirror\n", g.f);
	if (ax0 < 0)
		fputs("unset xtics\n", g.f);
	if (ax1 < 0)
		fputs("unset ytics\n", g.f);
	const int cell_w = xtic * 7 + 16 > 95 ? xtic * 7 + 16 : 95, cell_h = 62;
	int pw = 40 + (ylab ? 30 : 0) + 7 * ytic + cell_w * n0 + 130;
	int ph = 120 + cell_h * n1;
	if (pw < text_px(xlab) + 170)
		pw = text_px(xlab) + 170;
	if (ph < 300)
		ph = 300;
	if (ax0 < 0 && ax1 < 0 && np == 1) {
		/* one group: its p_traverse on a probability axis with its
		 * interval, not a cell of a map without axes */
		fputs("unset colorbox\nset xrange [-1:1]\nset yrange [0:1]\nset ytics 0.2 "
		      "nomirror\n"
		      "set ylabel 'p_{traverse}'\nset grid ytics\n",
		      g.f);
		panel_label(s, a, first[0], ax0, ax1, label, sizeof label);
		fputs("set title ", g.f);
		bsim_gp_str(g.f, label);
		fputs(" noenhanced\n"
		      "plot 'p_traverse.dat' index 0 using 1:3:4:5 with yerrorbars pt 7 ps 1.5 "
		      "lc rgb '#08306B' notitle, \\\n"
		      "     '' index 0 using ($1 + 0.1):3:($4 == $5 ? sprintf(\"%.2f (1 trial)\", "
		      "$3) : sprintf(\"%.2f [%.2f, %.2f]\", $3, $4, $5)) with labels left "
		      "font ',10' notitle\n",
		      g.f);
		pw = pw < 420 ? 420 : pw;
		ph = 380;
	}
	for (int p = 0; p < np && !(ax0 < 0 && ax1 < 0 && np == 1); p++) {
		panel_label(s, a, first[p], ax0, ax1, label, sizeof label);
		if (pw < text_px(label) + 150)
			pw = text_px(label) + 150;
		fputs("set title ", g.f);
		bsim_gp_str(g.f, label);
		fprintf(g.f,
		        " noenhanced\n"
		        "plot 'p_traverse.dat' index %d using 1:2:(0.5):(0.5):3 with boxxyerror "
		        "fs solid 1.0 fc palette notitle, \\\n"
		        "     '' index %d using 1:2:($4 == $5 ? sprintf(\"%%.2f\\n(1 trial)\", $3) "
		        ": sprintf(\"%%.2f\\n[%%.2f, %%.2f]\", $3, $4, $5)):($3 > 0.55 ? 0xFFFFFF "
		        ": "
		        "0) with labels tc rgb variable font ',9' notitle\n",
		        p, p);
	}
	fputs("unset multiplot\n", g.f);
	free(first);
	int W = pw * cols, H = ph * rows + 60;
	if (W < text_px(title))
		W = text_px(title);
	char *body = bsim_gp_text_take(&g);
	rc = body ? bsim_figs_render(f, "p_traverse", W, H, body, err)
	          : bsim_error_set(err, BSIM_EFAIL, "out of memory");
	free(body);
	return rc;
}

/* ---- Fig. 3.4 -------------------------------------------------------------------- */

/* A lattice (lattice = 1) draws where the trials ended instead of the
 * single gate's left and right types: reached the end (traversed), side
 * exit and stuck, each with its 95% band. */
static int versus(figs *f, const fsum *s, const active *a, int ax, int lattice, bsim_error *err)
{
	const fsum_axis *A = &s->axes[ax];
	const int np = panels(s, a, ax, -1);
	char ident[64], name[128], file[160], path[BSIM_PATH_MAX];
	bsim_mat_name(A->key, ident, sizeof ident);
	snprintf(name, sizeof name, "traversal_vs_%s", ident);
	snprintf(file, sizeof file, "%s.dat", name);
	bsim_atomic_file o;
	int rc = bsim_figs_data_open(f, file, &o, path, err);
	if (rc)
		return rc;
	fprintf(o.f,
	        lattice ? "# %s end lo hi side_exit lo hi stuck lo hi (fractions of the trials; "
	                  "end: traversed, reached the end of the lattice; Wilson 95%% "
	                  "intervals): one block per panel\n"
	                : "# %s traversed lo hi left lo hi right lo hi landscape_left "
	                  "landscape_right (fractions of the trials; Wilson 95%% intervals): one "
	                  "block per panel\n",
	        A->numeric ? A->key : "position");
	int *first = malloc((size_t)np * sizeof *first);
	if (!first) {
		bsim_atomic_file_abort(&o);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	for (int p = 0; p < np; p++) {
		first[p] = -1;
		fprintf(o.f, "%s# panel %d\n", p ? "\n\n" : "", p);
		/* along the axis in the order of its values */
		for (int i = 0; i < A->n_values; i++)
			for (int gi = 0; gi < s->n_groups; gi++) {
				const fsum_group *G = &s->g[gi];
				if (!G->selected || G->idx[ax] != i ||
				    panel_of(s, a, gi, ax, -1) != p)
					continue;
				if (first[p] < 0)
					first[p] = gi;
				double ll, lh, rl, rh, n = G->trials > 0 ? G->trials : 1;
				const double x = A->numeric ? A->x[i] : (double)a->pos[ax][i];
				if (lattice) {
					/* a group without random force: points */
					const int point = G->deterministic ||
					                  (G->lo == G->hi && G->trials > 1);
					bsim_stats_wilson(G->side_exit, G->trials, BSIM_STATS_Z95,
					                  &ll, &lh);
					bsim_stats_wilson(G->stuck, G->trials, BSIM_STATS_Z95, &rl,
					                  &rh);
					if (point) {
						ll = lh = G->side_exit / n;
						rl = rh = G->stuck / n;
					}
					fprintf(o.f,
					        "%.6g %.6g %.6g %.6g %.6g %.6g %.6g %.6g %.6g "
					        "%.6g\n",
					        x, G->p, G->lo, G->hi, G->side_exit / n, ll, lh,
					        G->stuck / n, rl, rh);
					continue;
				}
				bsim_stats_wilson(G->left, G->trials, BSIM_STATS_Z95, &ll, &lh);
				bsim_stats_wilson(G->right, G->trials, BSIM_STATS_Z95, &rl, &rh);
				if (G->deterministic) { /* one trial: its outcome, no interval */
					ll = lh = G->left / n;
					rl = rh = G->right / n;
				}
				fprintf(o.f,
				        "%.6g %.6g %.6g %.6g %.6g %.6g %.6g %.6g %.6g %.6g %.6g "
				        "%.6g\n",
				        A->numeric ? A->x[i] : (double)a->pos[ax][i], G->p, G->lo,
				        G->hi, G->left / n, ll, lh, G->right / n, rl, rh,
				        G->land_left / n, G->land_right / n);
			}
	}
	if ((rc = bsim_figs_data_commit(&o, err))) {
		free(first);
		return rc;
	}
	/* At most PAGE_PANELS panels a figure, readable at its size: more are
	 * pages of their own, traversal_vs_KEY_p2.png, ..., each with the key,
	 * all drawing from the one data file. */
	const int pages = (np + PAGE_PANELS - 1) / PAGE_PANELS;
	for (int page = 0; rc == BSIM_OK && page < pages; page++) {
		const int p0 = page * PAGE_PANELS;
		const int npp = np - p0 < PAGE_PANELS ? np - p0 : PAGE_PANELS;
		gp_text g;
		if ((rc = bsim_gp_text_open(&g, err)))
			break;
		/* The panels and, in the cell after them, the key; many panels get
		 * smaller ones, so that the image stays well under 1 MB. A panel is
		 * titled by the values of the other axes, named once in the title. A
		 * single panel has its key beside it in a narrower cell. */
		int rows, cols;
		layout(npp, &rows, &cols);
		if (rows * cols == npp && npp > 1)
			layout(npp + 1, &rows, &cols);
		const int pw = npp > 12 ? 400 : 520, ph = npp > 12 ? 300 : 380;
		/* a single panel's key cell: its widest entry at the key's 10 pt,
		 * the line sample beside it and a margin either side */
		const int key_w =
		        bsim_figure_text_px(lattice ? "reached the end (traversed)"
		                                    : "over the left beam (landscape label)",
		                            10) +
		        100;
		int W = npp == 1 ? 640 + key_w : pw * cols, H = npp == 1 ? 560 : ph * rows + 90;
		char title[2000], others[600] = "", axis_label[300];
		size_t L = 0;
		for (int oa = 0; oa < s->n_axes && L < sizeof others; oa++)
			if (oa != ax && a->n[oa] > 1) {
				char lab[300];
				bsim_key_label(s->axes[oa].key, 0, lab, sizeof lab);
				int w = snprintf(others + L, sizeof others - L, "%s%s",
				                 L ? ", " : "", lab);
				L += w > 0 ? (size_t)w : 0;
			}
		bsim_key_label(A->key, 0, axis_label, sizeof axis_label);
		char page_of[48] = "";
		if (pages > 1)
			snprintf(page_of, sizeof page_of, " (page %d of %d)", page + 1, pages);
		snprintf(title, sizeof title,
		         "%s against %s, %d trials per group, 95%% Wilson bands%s\n%s%s%s",
		         lattice ? "where the trials ended" : "traversal", axis_label,
		         s->trials_per_group, page_of, s->header, L ? "\npanels: " : "", others);
		if (W < text_px(title))
			W = text_px(title);
		/* a single panel placed by hand: below the title's lines */
		int title_lines = 1;
		for (const char *c = title; *c; c++)
			title_lines += *c == '\n';
		const double top = 1.0 - (18.0 * title_lines + 14.0) / H;
		if (npp == 1)
			fputs("set multiplot title ", g.f);
		else
			fprintf(g.f, "set multiplot layout %d,%d title ", rows, cols);
		bsim_gp_str(g.f, title);
		fputs(" noenhanced\nset yrange [0:1]\nset ylabel 'fraction of trials'\nset xlabel ",
		      g.f);
		bsim_gp_key_label(g.f, A->key);
		fputs("\nset grid\nset style fill transparent solid 0.15 noborder\n"
		      "unset key\n",
		      g.f);
		/* k_1 against a fixed k_2 (or the other way round): the essay's
		 * stiffness ratio k_1/k_2 (H2, Fig. 3.4) on the top axis */
		double other;
		int ratio = 0;
		if (A->numeric && strcmp(A->key, "beams.0.stiffness") == 0 &&
		    bsim_fsum_fixed_number(s, "beams.1.stiffness", &other) && other > 0) {
			fprintf(g.f, "set link x2 via x/%.17g inverse x*%.17g\n", other, other);
			ratio = 1;
		} else if (A->numeric && strcmp(A->key, "beams.1.stiffness") == 0 &&
		           bsim_fsum_fixed_number(s, "beams.0.stiffness", &other) && other > 0) {
			fprintf(g.f, "set link x2 via %.17g/x inverse %.17g/x\n", other, other);
			ratio = 1;
		}
		if (ratio)
			fputs("set x2tics nomirror\nset xtics nomirror\n"
			      "set x2label 'stiffness ratio k_{1}/k_{2}' enhanced\n",
			      g.f);
		if (npp == 1)
			fprintf(g.f, "set origin 0,0\nset size %.4f,%.4f\n", 640.0 / W, top);
		if (!A->numeric)
			tics(g.f, "x", A, a->pos[ax]);
		for (int p = p0; p < p0 + npp; p++) {
			char label[512] = "";
			size_t k = 0;
			for (int oa = 0; oa < s->n_axes && k < sizeof label; oa++)
				if (oa != ax && a->n[oa] > 1) {
					char kv[200];
					bsim_figs_key_value(
					        s->axes[oa].key,
					        s->axes[oa].values[s->g[first[p]].idx[oa]], kv,
					        sizeof kv);
					int w = snprintf(label + k, sizeof label - k, "%s%s",
					                 k ? ", " : "", kv);
					k += w > 0 ? (size_t)w : 0;
				}
			fputs("set title ", g.f);
			bsim_gp_str(g.f, label);
			if (lattice) {
				fprintf(g.f,
				        " noenhanced\n"
				        "plot '%s' index %d using 1:3:4 with filledcurves lc rgb "
				        "'%s', \\\n"
				        "     '' index %d using 1:6:7 with filledcurves lc rgb "
				        "'%s', \\\n"
				        "     '' index %d using 1:9:10 with filledcurves lc rgb "
				        "'%s', \\\n"
				        "     '' index %d using 1:2 with linespoints lw 2 pt 7 lc "
				        "rgb "
				        "'%s', \\\n"
				        "     '' index %d using 1:5 with linespoints lw 1.5 pt 5 "
				        "lc rgb "
				        "'%s', "
				        "\\\n"
				        "     '' index %d using 1:8 with linespoints lw 1.5 pt 9 "
				        "lc rgb "
				        "'%s'\n",
				        file, p, FIG_BLUE, p, FIG_GREY, p, FIG_DKGREY, p, FIG_BLUE,
				        p, FIG_GREY, p, FIG_DKGREY);
				continue;
			}
			fprintf(g.f,
			        " noenhanced\n"
			        "plot '%s' index %d using 1:3:4 with filledcurves lc rgb '%s', \\\n"
			        "     '' index %d using 1:6:7 with filledcurves lc rgb '%s', \\\n"
			        "     '' index %d using 1:9:10 with filledcurves lc rgb '%s', \\\n"
			        "     '' index %d using 1:2 with linespoints lw 2 pt 7 lc rgb "
			        "'%s', \\\n"
			        "     '' index %d using 1:5 with linespoints lw 1.5 pt 5 lc rgb "
			        "'%s', \\\n"
			        "     '' index %d using 1:8 with linespoints lw 1.5 pt 9 lc rgb "
			        "'%s', \\\n"
			        "     '' index %d using 1:11 with lines dt 2 lc rgb '%s', \\\n"
			        "     '' index %d using 1:12 with lines dt 2 lc rgb '%s'\n",
			        file, p, FIG_BLACK, p, FIG_BLUE, p, FIG_RED, p, FIG_BLACK, p,
			        FIG_BLUE, p, FIG_RED, p, FIG_BLUE, p, FIG_RED);
		}
		if (npp == 1)
			fprintf(g.f, "set origin %.4f,0\nset size %.4f,%.4f\n", 640.0 / W,
			        1.0 - 640.0 / W, top);
		fputs("unset link x2\nunset x2tics\nunset x2label\n", g.f);
		if (lattice)
			fprintf(g.f,
			        "# the key, in a cell of its own\n"
			        "unset title\nunset border\nunset tics\nunset xlabel\nunset "
			        "ylabel\n"
			        "unset grid\nset key center center vertical font ',10'\nset xrange "
			        "[0:1]\n"
			        "plot NaN with linespoints lw 2 pt 7 lc rgb '%s' title 'reached "
			        "the end "
			        "(traversed)', \\\n"
			        "     NaN with linespoints lw 1.5 pt 5 lc rgb '%s' title 'side "
			        "exit', \\\n"
			        "     NaN with linespoints lw 1.5 pt 9 lc rgb '%s' title 'stuck', "
			        "\\\n"
			        "     NaN with filledcurves lc rgb '%s' title '95%% interval'\n",
			        FIG_BLUE, FIG_GREY, FIG_DKGREY, FIG_GREY);
		else
			fprintf(g.f,
			        "# the key, in a cell of its own\n"
			        "unset title\nunset border\nunset tics\nunset xlabel\nunset "
			        "ylabel\nunset "
			        "grid\n"
			        "set key center center vertical font ',10'\nset xrange [0:1]\n"
			        "plot NaN with linespoints lw 2 pt 7 lc rgb '%s' title "
			        "'traversed', \\\n"
			        "     NaN with linespoints lw 1.5 pt 5 lc rgb '%s' title 'left "
			        "type (v_x > "
			        "0 at "
			        "classify y)', \\\n"
			        "     NaN with linespoints lw 1.5 pt 9 lc rgb '%s' title 'right "
			        "type (v_x "
			        "< 0)', "
			        "\\\n"
			        "     NaN with lines dt 2 lc rgb '%s' title 'over the left beam "
			        "(landscape "
			        "label)', \\\n"
			        "     NaN with lines dt 2 lc rgb '%s' title 'over the right beam', "
			        "\\\n"
			        "     NaN with filledcurves lc rgb '%s' title '95%% interval'\n",
			        FIG_BLACK, FIG_BLUE, FIG_RED, FIG_BLUE, FIG_RED, FIG_GREY);
		fputs("unset multiplot\n", g.f);
		char *body = bsim_gp_text_take(&g);
		char page_name[160];
		snprintf(page_name, sizeof page_name, page ? "%s_p%d" : "%s", name, page + 1);
		rc = body ? bsim_figs_render(f, page_name, W, H, body, err)
		          : bsim_error_set(err, BSIM_EFAIL, "out of memory");
		free(body);
	}
	free(first);
	return rc;
}

/* ---- Figs. 3.2, 3.3: the kept trajectories -------------------------------------------- */

typedef struct traj_job {
	const fsum *s;
	const bsim_experiment *e;
	bsim_experiment e_own;
	csv_table table; /* trajectories.csv, which paths point into */
	int have_table;
	fpaths paths;
	int *first, *count; /* per group: the first path and how many */
	char *untraversed;  /* per group: no traversed trial kept, no landscape figure */
} traj_job;

/* The classes of the paths from trials.csv (outcome and type by name). */
static int classes_read(const char *dir, const fsum *s, fpaths *ps, bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	snprintf(path, sizeof path, "%s/trials.csv", dir);
	const long per = s->trials_per_group;
	int *which = malloc(((size_t)s->n_groups * (size_t)per + 1) * sizeof *which);
	if (!which)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	for (long i = 0; i < (long)s->n_groups * per; i++)
		which[i] = -1;
	for (int i = 0; i < ps->n; i++) {
		const fpath *p = &ps->p[i];
		if (p->group >= 0 && p->group < s->n_groups && p->trial >= 0 && p->trial < per)
			which[(long)p->group * per + p->trial] = i;
	}
	csv_table t;
	int rc = bsim_csv_table_read(path, &t, err);
	if (rc) {
		free(which);
		return rc;
	}
	static const char *const need[] = {"group", "trial", "outcome", "type"};
	int col[4];
	rc = bsim_csv_table_require(&t, path, need, 4, col, err);
	for (long r = 0; !rc && r < t.n_rows; r++) {
		double g, tr;
		if (bsim_csv_table_number(&t, r, col[0], &g) ||
		    bsim_csv_table_number(&t, r, col[1], &tr) || g < 0 || g >= s->n_groups ||
		    tr < 0 || tr >= per) {
			rc = bsim_error_set(err, BSIM_EINPUT,
			                    "%s:%ld: group, trial: expected integers within the "
			                    "%d groups x %ld trials of summary.json",
			                    path, r + 2, s->n_groups, per);
			break;
		}
		int i = which[(long)g * per + (long)tr];
		if (i >= 0)
			ps->p[i].cls = bsim_fpath_class(bsim_csv_table_cell(&t, r, col[2]),
			                                bsim_csv_table_cell(&t, r, col[3]));
	}
	free(which);
	bsim_csv_table_free(&t);
	return rc;
}

static int group_figures(figs *f, traj_job *j, int g, bsim_error *err)
{
	bsim_scene scene;
	int rc = bsim_experiment_group_scene(j->e, g, NULL, 0, &scene, err);
	if (rc)
		return rc;
	char label[512], title[1400], name[64];
	bsim_fsum_label(j->s, g, label, sizeof label);
	const fpath *p = j->paths.p + j->first[g];
	/* a group without random force ran one trial, whose rows fill the
	 * group: one path, not the first n of many */
	const int det = j->s->g[g].deterministic;
	int n = det ? 1 : j->count[g], trav = 0;
	for (int i = 0; i < n; i++)
		trav += p[i].cls >= FPATH_NONE;
	if (det)
		snprintf(title, sizeof title,
		         "group %d: one deterministic trial (no random force)\n%s%s%s", g,
		         j->s->header, *label ? "\n" : "", label);
	else
		snprintf(title, sizeof title, "group %d, the first %d of %d trials\n%s%s%s", g, n,
		         j->s->g[g].trials, j->s->header, *label ? "\n" : "", label);
	snprintf(name, sizeof name, "trajectories_g%03d", g);
	rc = bsim_figs_bundle(f, name, title, &scene, p, n, err);
	if (!rc && trav > 0) {
		/* the landscape's title: backend, the experiment's set: and the
		 * group's grid values, in the model's symbols and units */
		const int nk = j->e->n_set + j->s->n_axes;
		const char **kv = malloc(2 * (size_t)(nk > 0 ? nk : 1) * sizeof *kv);
		if (!kv) {
			bsim_scene_free(&scene);
			return bsim_error_set(err, BSIM_EFAIL, "out of memory");
		}
		for (int i = 0; i < j->e->n_set; i++) {
			kv[i] = j->e->set[i].key;
			kv[nk + i] = j->e->set[i].value;
		}
		for (int a = 0; a < j->s->n_axes; a++) {
			kv[j->e->n_set + a] = j->s->axes[a].key;
			kv[nk + j->e->n_set + a] = j->s->axes[a].values[j->s->g[g].idx[a]];
		}
		bsim_fpath_params(label, sizeof label, j->s->backend, kv, kv + nk, nk);
		free(kv);
		if (det)
			snprintf(title, sizeof title,
			         "group %d: one deterministic trial (no random force), traversed, "
			         "over "
			         "the landscape\n%s",
			         g, label);
		else
			snprintf(title, sizeof title,
			         "group %d, the %d traversed of the first %d trials over the "
			         "landscape\n%s",
			         g, trav, n, label);
		snprintf(name, sizeof name, "landscape_g%03d", g);
		rc = bsim_figs_over_landscape(
		        f, name, title, &scene, p, n,
		        1u << FPATH_LEFT | 1u << FPATH_RIGHT | 1u << FPATH_NONE, err);
	}
	j->untraversed[g] = !rc && trav == 0;
	bsim_scene_free(&scene);
	return rc;
}

/* One line naming the groups drawn without a landscape figure. */
static void untraversed_note(figs *f, const char *dir, const char *flag, int n)
{
	char buf[400];
	size_t k = 0;
	int count = 0;
	for (int g = 0; flag && g < n; g++) {
		if (!flag[g])
			continue;
		count++;
		if (k < sizeof buf - 16) {
			int w = snprintf(buf + k, sizeof buf - k, "%s%d", k ? ", " : "", g);
			k += w > 0 ? (size_t)w : 0;
		}
	}
	if (count)
		bsim_figs_note(f,
		               "%s: no landscape figure for %d group%s without a traversed trial "
		               "among the kept ones: %s%s",
		               dir, count, count == 1 ? "" : "s", buf,
		               k >= sizeof buf - 16 ? ", ..." : "");
}

/* Everything the trajectory figures need, read and checked before any
 * figure is drawn: the experiment (for each group's scene), the kept
 * paths with their classes, and where each group's paths start. */
static int traj_load(figs *f, const char *dir, const char *inputs, const fsum *s, traj_job *j,
                     int *have, bsim_error *err)
{
	char path[BSIM_PATH_MAX], exp_path[BSIM_PATH_MAX];
	snprintf(path, sizeof path, "%s/trajectories.csv", dir);
	snprintf(exp_path, sizeof exp_path, "%s/experiment.yaml", inputs);
	struct stat st;
	*have = 0;
	if (stat(path, &st) != 0)
		return BSIM_OK;
	if (stat(exp_path, &st) != 0) {
		bsim_figs_note(f, "%s: no %s, so no scene to draw the trajectories on", dir,
		               exp_path);
		return BSIM_OK;
	}
	int rc = bsim_experiment_load(exp_path, NULL, 0, &j->e_own, err);
	if (rc)
		return rc;
	j->e = &j->e_own;
	*have = 1; /* from here on traj_free releases what is loaded */
	if (j->e->n_groups != s->n_groups)
		return bsim_error_set(err, BSIM_EINPUT, "%s: %d groups, but %s/summary.json has %d",
		                      exp_path, j->e->n_groups, dir, s->n_groups);
	rc = bsim_csv_table_read(path, &j->table, err);
	if (rc)
		return rc;
	j->have_table = 1;
	rc = bsim_fpaths_read(&j->table, path, &j->paths, err);
	if (!rc)
		rc = classes_read(dir, s, &j->paths, err);
	j->first = calloc((size_t)s->n_groups, sizeof *j->first);
	j->count = calloc((size_t)s->n_groups, sizeof *j->count);
	j->untraversed = calloc((size_t)s->n_groups, 1);
	if (!rc && (!j->first || !j->count || !j->untraversed))
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	for (int i = 0; !rc && i < j->paths.n; i++) {
		int g = j->paths.p[i].group;
		if (g < 0 || g >= s->n_groups)
			return bsim_error_set(err, BSIM_EINPUT, "%s: group %d: expected 0 .. %d",
			                      path, g, s->n_groups - 1);
		if (j->count[g]++ == 0)
			j->first[g] = i;
	}
	return rc;
}

static void traj_free(traj_job *j, int have)
{
	if (!have)
		return;
	free(j->untraversed);
	free(j->first);
	free(j->count);
	bsim_fpaths_free(&j->paths);
	if (j->have_table)
		bsim_csv_table_free(&j->table);
	bsim_experiment_free(&j->e_own);
}

static int traj_group(figs *f, void *job, int g, bsim_error *err)
{
	traj_job *j = job;
	if (!j->s->g[g].selected || j->count[g] == 0)
		return BSIM_OK;
	return group_figures(f, j, g, err);
}

static int traj_draw(figs *f, const char *dir, traj_job *j, bsim_error *err)
{
	int rc = bsim_figs_each_group(f, j->s->n_groups, traj_group, j, err);
	if (rc == BSIM_OK)
		untraversed_note(f, dir, j->untraversed, j->s->n_groups);
	return rc;
}

/* trials.csv whole and of this summary: every row complete (bsim_csv_table_read
 * refuses a file cut mid-row), and each trial of the groups x trials
 * summary.json counts once. The figures come from summary.json; a
 * trials.csv that does not add up to it means the directory is damaged,
 * and then no figure is drawn from it. */
static int trials_check(const char *dir, const fsum *s, bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	snprintf(path, sizeof path, "%s/trials.csv", dir);
	const long per = s->trials_per_group, total = (long)s->n_groups * per;
	csv_table t;
	int rc = bsim_csv_table_read(path, &t, err);
	if (rc)
		return rc;
	static const char *const need[] = {"group", "trial"};
	int col[2];
	char *seen = calloc((size_t)total + 1, 1);
	rc = bsim_csv_table_require(&t, path, need, 2, col, err);
	if (!rc && !seen)
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	for (long r = 0; !rc && r < t.n_rows; r++) {
		double g, tr;
		if (bsim_csv_table_number(&t, r, col[0], &g) ||
		    bsim_csv_table_number(&t, r, col[1], &tr) || g < 0 || g >= s->n_groups ||
		    tr < 0 || tr >= per || g != (long)g || tr != (long)tr ||
		    seen[(long)g * per + (long)tr]++)
			rc = bsim_error_set(err, BSIM_EINPUT,
			                    "%s:%ld: group, trial: expected each trial of the %d "
			                    "groups x %ld trials of summary.json once",
			                    path, r + 2, s->n_groups, per);
	}
	if (!rc && t.n_rows != total)
		rc = bsim_error_set(err, BSIM_EINPUT,
		                    "%s:%ld: expected %ld rows (the %d groups x %ld trials of "
		                    "summary.json), got %ld by the end of the file",
		                    path, t.n_rows + 1, total, s->n_groups, per, t.n_rows);
	free(seen);
	bsim_csv_table_free(&t);
	return rc;
}

int bsim_figs_sweep(figs *f, const char *dir, const char *inputs, bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	snprintf(path, sizeof path, "%s/summary.json", dir);
	fsum s;
	int rc = bsim_fsum_read(path, &s, err);
	if (rc)
		return rc;
	active a = {{NULL}, {0}};
	traj_job j = {.s = &s};
	int have = 0;
	/* every input read and checked first: a bad one leaves no figure */
	rc = trials_check(dir, &s, err);
	if (!rc)
		rc = bsim_fsum_select(f, &s, err);
	if (!rc)
		rc = active_build(&s, &a, err);
	if (!rc) {
		char who[128];
		snprintf(who, sizeof who, "%s backend", s.backend);
		bsim_fsum_header(&s, inputs, who);
	}
	/* a lattice gets its own trajectory figures (figures_lattice.c) */
	lat_job *lat = NULL;
	if (!rc && bsim_figs_is_lattice(dir))
		rc = bsim_figs_lattice_load(f, dir, inputs, &s, &lat, err);
	else if (!rc)
		rc = traj_load(f, dir, inputs, &s, &j, &have, err);
	/* survival.csv and horizon.csv are read whole before it draws */
	if (!rc)
		rc = bsim_figs_survival(f, dir, &s, err);
	if (!rc)
		rc = heat_map(f, &s, &a, lat != NULL, err);
	for (int ax = 0; !rc && ax < s.n_axes; ax++)
		if (a.n[ax] >= 2)
			rc = versus(f, &s, &a, ax, lat != NULL, err);
	if (!rc && have)
		rc = traj_draw(f, dir, &j, err);
	if (!rc && lat)
		rc = bsim_figs_lattice_draw(f, lat, err);
	bsim_figs_lattice_free(lat);
	traj_free(&j, have);
	active_free(&a, s.n_axes);
	bsim_fsum_free(&s);
	return rc;
}
