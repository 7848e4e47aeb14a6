/* The survival figure of a sweep: left, the Kaplan-Meier estimate S(t) of
 * the time to leave the gate with its Greenwood band; right, the shares
 * traversed and still in the gate (stuck) had the trials been stopped at
 * horizon h, with Wilson bands and the scene's horizon marked. A reader
 * sees whether p_traverse still climbs at the horizon the sweep used. */
#define _POSIX_C_SOURCE 200809L

#include "figures/figures_survival.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "util/csv_table.h"

static const char *const colour[FIGS_SURVIVAL_GROUPS] = {
        FIG_BLUE, FIG_RED, FIG_GREEN, FIG_ORANGE, FIG_PURPLE, FIG_SKY, FIG_BLACK, FIG_DKGREY};

/* Reads the named columns of dir/name into t and col. */
static int table(const char *dir, const char *name, const char *const *need, int n, csv_table *t,
                 int *col, char *path, bsim_error *err)
{
	snprintf(path, BSIM_PATH_MAX, "%s/%s", dir, name);
	int rc = bsim_csv_table_read(path, t, err);
	if (rc)
		return rc;
	if ((rc = bsim_csv_table_require(t, path, need, n, col, err)))
		bsim_csv_table_free(t);
	return rc;
}

/* Rows of table t for group g as "v1 v2 ..." lines of the columns col[1..n-1]
 * (col[0] is the group). */
static int block(FILE *o, const csv_table *t, const char *path, const int *col, int n, int g,
                 bsim_error *err)
{
	for (long r = 0; r < t->n_rows; r++) {
		double v, gr;
		if (bsim_csv_table_number(t, r, col[0], &gr))
			return bsim_error_set(err, BSIM_EINPUT, "%s:%ld: group: expected a number",
			                      path, r + 2);
		if ((int)gr != g)
			continue;
		for (int k = 1; k < n; k++) {
			if (bsim_csv_table_number(t, r, col[k], &v))
				return bsim_error_set(err, BSIM_EINPUT,
				                      "%s:%ld: expected a number in column %d",
				                      path, r + 2, col[k] + 1);
			fprintf(o, "%s%.8g", k > 1 ? " " : "", v);
		}
		fputc('\n', o);
	}
	return BSIM_OK;
}

int bsim_figs_survival(figs *f, const char *dir, const fsum *s, bsim_error *err)
{
	char path[BSIM_PATH_MAX], spath[BSIM_PATH_MAX], hpath[BSIM_PATH_MAX];
	snprintf(path, sizeof path, "%s/survival.csv", dir);
	FILE *probe = fopen(path, "r");
	if (!probe)
		return BSIM_OK;
	fclose(probe);
	static const char *const sneed[] = {"group", "t", "survival", "ci_low", "ci_high"};
	static const char *const hneed[] = {"group",       "h",       "p_traverse", "traverse_lo",
	                                    "traverse_hi", "p_stuck", "stuck_lo",   "stuck_hi"};
	csv_table st, ht;
	int scol[5], hcol[8];
	int rc = table(dir, "survival.csv", sneed, 5, &st, scol, spath, err);
	if (rc)
		return rc;
	if ((rc = table(dir, "horizon.csv", hneed, 8, &ht, hcol, hpath, err))) {
		bsim_csv_table_free(&st);
		return rc;
	}
	/* the groups shown: the selected ones with the most exits by the horizon */
	int shown[FIGS_SURVIVAL_GROUPS], n_shown = 0, n_sel = 0;
	for (int g = 0; g < s->n_groups; g++) {
		if (!s->g[g].selected)
			continue;
		n_sel++;
		int exits = s->g[g].traversed + s->g[g].side_exit;
		int at = n_shown < FIGS_SURVIVAL_GROUPS ? n_shown++ : -1;
		if (at < 0) {
			int worst = 0;
			for (int k = 1; k < n_shown; k++)
				if (s->g[shown[k]].traversed + s->g[shown[k]].side_exit <
				    s->g[shown[worst]].traversed + s->g[shown[worst]].side_exit)
					worst = k;
			if (s->g[shown[worst]].traversed + s->g[shown[worst]].side_exit >= exits)
				continue;
			at = worst;
		}
		shown[at] = g;
	}
	/* in group order */
	for (int i = 1; i < n_shown; i++)
		for (int k = i; k > 0 && shown[k - 1] > shown[k]; k--) {
			int x = shown[k];
			shown[k] = shown[k - 1];
			shown[k - 1] = x;
		}
	if (n_sel > n_shown)
		bsim_figs_note(f,
		               "survival: %d of the %d selected groups drawn (those with the most "
		               "exits); --select KEY=VALUE draws others",
		               n_shown, n_sel);
	bsim_atomic_file o;
	rc = bsim_figs_data_open(f, "survival.dat", &o, path, err);
	if (!rc) {
		fputs("# t S lo hi (Kaplan-Meier, Greenwood 95%), one block per group shown; then "
		      "h p_traverse lo hi p_stuck lo hi (Wilson 95%), one block per group\n",
		      o.f);
		for (int i = 0; !rc && i < n_shown; i++) {
			fprintf(o.f, "%s# group %d\n", i ? "\n\n" : "", shown[i]);
			rc = block(o.f, &st, spath, scol, 5, shown[i], err);
		}
		for (int i = 0; !rc && i < n_shown; i++) {
			fprintf(o.f, "\n\n# group %d\n", shown[i]);
			rc = block(o.f, &ht, hpath, hcol, 8, shown[i], err);
		}
		if (rc)
			bsim_atomic_file_abort(&o);
		else
			rc = bsim_figs_data_commit(&o, err);
	}
	/* the horizon each group ran to: the last h of its block */
	double horizon = 0.0;
	for (long r = 0; !rc && r < ht.n_rows; r++) {
		double h;
		if (bsim_csv_table_number(&ht, r, hcol[1], &h) == 0 && h > horizon)
			horizon = h;
	}
	bsim_csv_table_free(&st);
	bsim_csv_table_free(&ht);
	if (rc || n_shown == 0)
		return rc;
	/* the panels' height and, below them, the key's rows of 4 entries */
	const int key_rows = (n_shown + 3) / 4, height = 560 + 18 * key_rows;
	const double key_bottom = (70.0 + 18.0 * key_rows) / height;
	gp_text g;
	if ((rc = bsim_gp_text_open(&g, err)))
		return rc;
	char title[900];
	snprintf(title, sizeof title, "time to leave the gate, %d trials per group\n%s",
	         s->trials_per_group, s->header);
	fputs("set multiplot layout 1,2 title ", g.f);
	bsim_gp_str(g.f, title);
	fprintf(g.f,
	        " noenhanced\n"
	        "set grid\nset style fill transparent solid 0.12 noborder\n"
	        "set yrange [0:1]\nset xrange [0:%.6g]\n"
	        /* the key below both panels, not on the curves; both panels
	         * end as high above it */
	        "set bmargin at screen %.4f\nset tmargin at screen %.4f\n"
	        "set key at screen 0.5, screen 0.01 center bottom horizontal maxcols 4 "
	        "font ',9' noenhanced\n"
	        "set arrow 1 from %.6g, graph 0 to %.6g, graph 1 nohead lw 2 dt 3 lc rgb '%s'\n"
	        "set title 'still in the gate, S(t) (Kaplan-Meier, 95%% Greenwood band)'\n"
	        "set xlabel 't (s)'\nset ylabel 'S(t)'\nplot ",
	        horizon * 1.02, key_bottom, 1.0 - 110.0 / height, horizon, horizon, FIG_GREY);
	for (int i = 0; i < n_shown; i++) {
		/* the key's one line: every axis, ", " where the label breaks */
		char text[300], label[450];
		size_t k = 0;
		bsim_fsum_label(s, shown[i], text, sizeof text);
		for (const char *c = text; *c && k + 3 < sizeof label; c++) {
			if (*c == '\n') {
				label[k++] = ',';
				label[k++] = ' ';
			} else {
				label[k++] = *c;
			}
		}
		label[k] = '\0';
		fprintf(g.f,
		        "%s'survival.dat' index %d using 1:3:4 with filledcurves lc rgb '%s' "
		        "notitle, "
		        "\\\n     '' index %d using 1:2 with steps lw 2 lc rgb '%s' title ",
		        i ? ", \\\n     " : "", i, colour[i], i, colour[i]);
		bsim_gp_str(g.f, label);
	}
	fprintf(g.f,
	        "\nset title \"had the trials stopped at h: traversed (solid), stuck (dashed)\\n"
	        "dotted: where the trials end, %.6g s\"\n"
	        "set xlabel 'horizon h (s)'\nset ylabel 'fraction of trials'\nunset key\nplot ",
	        horizon);
	for (int i = 0; i < n_shown; i++)
		fprintf(g.f,
		        "%s'survival.dat' index %d using 1:3:4 with filledcurves lc rgb '%s', \\\n"
		        "     '' index %d using 1:2 with lines lw 2 lc rgb '%s', \\\n"
		        "     '' index %d using 1:6:7 with filledcurves lc rgb '%s', \\\n"
		        "     '' index %d using 1:5 with lines lw 2 dt 2 lc rgb '%s'",
		        i ? ", \\\n     " : "", n_shown + i, colour[i], n_shown + i, colour[i],
		        n_shown + i, colour[i], n_shown + i, colour[i]);
	fputs("\nunset multiplot\n", g.f);
	char *body = bsim_gp_text_take(&g);
	rc = body ? bsim_figs_render(f, "survival", 1300, height, body, err)
	          : bsim_error_set(err, BSIM_EFAIL, "out of memory");
	free(body);
	return rc;
}
