/* The essay comparison drawn (figures.h, beamsim essay): for every level
 * the essay reports (rows of essay.csv of kind level), beamsim's
 * probability with its 95% interval in each mode beside the essay's
 * value. Trends have their own units and stay in the table. */
#define _POSIX_C_SOURCE 200809L
#include <stdlib.h>
#include <string.h>

#include "figures/figures_kinds.h"
#include "util/figure.h"
#include "figures/figures_toolkit.h"
#include "util/csv_table.h"
#include "beamsim/limits.h"

static const char *const palette[] = {FIG_BLUE, FIG_RED, FIG_GREEN, FIG_ORANGE, FIG_PURPLE};

#define ESSAY_MODES_MAX 5

/* The backend essay.md names ("Backend NAME, seed 1, ..."), "" if none. */
static void essay_backend(const char *dir, char *buf, size_t size)
{
	char path[BSIM_PATH_MAX];
	snprintf(path, sizeof path, "%s/essay.md", dir);
	buf[0] = '\0';
	FILE *in = fopen(path, "r");
	if (!in)
		return;
	char line[512];
	while (fgets(line, sizeof line, in))
		if (strncmp(line, "Backend ", 8) == 0) {
			size_t n = strcspn(line + 8, ", \n'");
			snprintf(buf, size, "%.*s", (int)(n < 60 ? n : 60), line + 8);
			break;
		}
	fclose(in);
}

int bsim_figs_essay(figs *f, const char *dir, bsim_error *err)
{
	if (f->def->n_select > 0)
		return bsim_error_set(
		        err, BSIM_EINPUT,
		        "%s: --select chooses groups of a sweep; the essay comparison "
		        "has none",
		        dir);
	char path[BSIM_PATH_MAX], file[BSIM_PATH_MAX];
	snprintf(path, sizeof path, "%s/essay.csv", dir);
	csv_table t;
	int rc = bsim_csv_table_read(path, &t, err);
	if (rc)
		return rc;
	static const char *const need[] = {"figure",      "quantity",      "mode",   "kind",
	                                   "essay_value", "beamsim_value", "ci_low", "ci_high"};
	int col[8];
	rc = bsim_csv_table_require(&t, path, need, 8, col, err);
	/* The modes in order of appearance. */
	const char *modes[ESSAY_MODES_MAX];
	int n_modes = 0;
	for (int r = 0; !rc && r < t.n_rows; r++) {
		const char *m = bsim_csv_table_cell(&t, r, col[2]);
		int seen = 0;
		for (int k = 0; k < n_modes; k++)
			seen |= strcmp(modes[k], m) == 0;
		if (!seen && n_modes < ESSAY_MODES_MAX)
			modes[n_modes++] = m;
	}
	bsim_atomic_file o;
	if (!rc)
		rc = bsim_figs_data_open(f, "essay.dat", &o, file, err);
	if (rc) {
		bsim_csv_table_free(&t);
		return rc;
	}
	fputs("# x, beamsim p, 95% low, 95% high, essay p: one block per mode, levels only\n", o.f);
	int n_levels = 0;
	for (int k = 0; k < n_modes; k++) {
		fprintf(o.f, "%s# %s\n", k ? "\n\n" : "", modes[k]);
		int x = 0, any = 0;
		for (int r = 0; r < t.n_rows; r++) {
			if (strcmp(bsim_csv_table_cell(&t, r, col[3]), "level") != 0 ||
			    strcmp(bsim_csv_table_cell(&t, r, col[2]), modes[k]) != 0)
				continue;
			fprintf(o.f, "%.3f %s %s %s %s\n", x + 0.15 * (k - 0.5 * (n_modes - 1)),
			        bsim_csv_table_cell(&t, r, col[5]),
			        bsim_csv_table_cell(&t, r, col[6]),
			        bsim_csv_table_cell(&t, r, col[7]),
			        bsim_csv_table_cell(&t, r, col[4]));
			x++;
			any = 1;
		}
		if (!any)
			fputs("NaN NaN NaN NaN NaN\n", o.f);
		if (x > n_levels)
			n_levels = x;
	}
	rc = bsim_figs_data_commit(&o, err);
	gp_text g;
	if (!rc)
		rc = bsim_gp_text_open(&g, err);
	if (rc) {
		bsim_csv_table_free(&t);
		return rc;
	}
	char backend[64];
	essay_backend(dir, backend, sizeof backend);
	fprintf(g.f,
	        "set title 'traversal probabilities the essay reports (its n = 100; the C-track "
	        "20) "
	        "and beamsim''s%s%s%s, 95%% intervals' noenhanced\n",
	        *backend ? " (" : "", backend, *backend ? " backend)" : "");
	/* the levels' names, turned by 60 degrees at 8 pt under the axis: the
	 * bottom margin (in lines of the 11 pt font, about 17 pixels) holds the
	 * longest, and the axis label line under it */
	int longest = 0;
	for (int pass = 0; pass < 2; pass++) {
		if (pass == 1)
			fprintf(g.f,
			        "set ylabel 'probability'\nset yrange [-0.02:1.05]\n"
			        "set grid ytics\n"
			        "set key outside top center horizontal maxcols 2 noenhanced\n"
			        "set bmargin %d\n"
			        "set xtics rotate by 60 right font ',8' noenhanced (",
			        (int)(longest * 0.87 / 17.0) + 3);
		int x = 0;
		for (int r = 0; r < t.n_rows && n_modes > 0; r++) {
			if (strcmp(bsim_csv_table_cell(&t, r, col[3]), "level") != 0 ||
			    strcmp(bsim_csv_table_cell(&t, r, col[2]), modes[0]) != 0)
				continue;
			char label[160];
			snprintf(label, sizeof label, "%s %s", bsim_csv_table_cell(&t, r, col[0]),
			         bsim_csv_table_cell(&t, r, col[1]));
			const int px = bsim_figure_text_px(label, 8);
			longest = px > longest ? px : longest;
			if (pass == 1) {
				fputs(x ? ", " : "", g.f);
				bsim_gp_str(g.f, label);
				fprintf(g.f, " %d", x);
			}
			x++;
		}
	}
	fprintf(g.f, ")\nset xrange [-0.7:%g]\nplot ", n_levels - 0.3);
	for (int k = 0; k < n_modes; k++) {
		fprintf(g.f,
		        "'essay.dat' index %d using 1:2:3:4 with yerrorbars pt 7 ps 0.8 lc rgb "
		        "'%s' "
		        "title ",
		        k, palette[k % 5]);
		char label[120];
		snprintf(label, sizeof label, "beamsim, %s", modes[k]);
		bsim_gp_str(g.f, label);
		fputs(", \\\n     ", g.f);
	}
	fputs("'essay.dat' index 0 using (floor($1 + 0.5)):5 with points pt 6 ps 1.6 lw 2 lc rgb "
	      "'#000000' title 'the essay'\n",
	      g.f);
	char *body = bsim_gp_text_take(&g);
	rc = body ? bsim_figs_render(f, "essay", 1400, 700, body, err)
	          : bsim_error_set(err, BSIM_EFAIL, "out of memory");
	free(body);
	bsim_csv_table_free(&t);
	return rc;
}
