/* Figures of a comparison (figures.h): both backends' p_traverse per group
 * side by side with their Wilson intervals, and the paired differences
 * p_A - p_B with the report's paired intervals (Tango's score interval) for
 * traversal, the left and right types, side exits, getting stuck and
 * instability, against the rule's margin; a difference beyond the rule is
 * marked; the title counts the verdicts, uninformative groups (every event
 * at the floor or the ceiling) apart from equivalent ones. The numbers are
 * report.json's. Each side's own sweep figures go to OUT/<label>/. */
#define _POSIX_C_SOURCE 200809L
#include <stdlib.h>
#include <string.h>

#include "beamsim/output.h"
#include "figures/figures_kinds.h"
#include "figures/figures_lattice.h"
#include "figures/figures_summary.h"
#include "figures/figures_toolkit.h"
#include "util/yaml_doc.h"
#include "beamsim/limits.h"

static double num(struct fy_node *root, const char *path, int *bad)
{
	double v = 0.0;
	struct fy_node *n = ydoc_lookup(root, path);
	if (!n || ydoc_number(n, &v) != YDOC_NUM_OK)
		*bad = 1;
	return v;
}

/* A number that may be absent: an interval bound of a deterministic
 * group is then its point, the value at field `point` of the event. */
static double num_or(struct fy_node *root, const char *path, const char *point, int g,
                     const char *event, int *bad)
{
	double v = 0.0;
	struct fy_node *n = ydoc_lookup(root, path);
	if (n && ydoc_number(n, &v) == YDOC_NUM_OK)
		return v;
	char p[200];
	snprintf(p, sizeof p, "groups.%d.events.%s.%s", g, event, point);
	return num(root, p, bad);
}

static void text(struct fy_node *root, const char *path, char *buf, size_t size)
{
	struct fy_node *n = ydoc_lookup(root, path);
	size_t len = 0;
	const char *t = n && fy_node_is_scalar(n) ? fy_node_get_scalar(n, &len) : NULL;
	snprintf(buf, size, "%.*s", t ? (int)len : 0, t ? t : "");
}

static const char *const events[] = {"traversed", "left",  "right",
                                     "side_exit", "stuck", "unstable"};
enum { N_EV = 6 };

/* The data: one row per selected group. Columns: 1 position, 2 group,
 * 3-8 p and Wilson interval of traversal on A then B, then per event
 * (traversed, left, right, side_exit, stuck, unstable) 4 columns from
 * 9 + 4 e: p_A - p_B, its 95% interval, beyond the rule (1/0); 33 the
 * label. A group without random force is one trial, compared as one pair
 * with no interval (report.json gives none): its interval is the point,
 * and a pair that differs ("DIFFERENT") is beyond the rule. */
static int compare_data(figs *f, const ydoc *d, const fsum *s, int *n_rows, bsim_error *err)
{
	struct fy_node *root = fy_document_root(d->fyd);
	char path[BSIM_PATH_MAX];
	bsim_atomic_file o;
	int rc = figs_data_open(f, "compare.dat", &o, path, err);
	if (rc)
		return rc;
	fputs("# position group p_a lo hi p_b lo hi (traversed, Wilson 95%), then for traversed, "
	      "left, right, side_exit, stuck, unstable: p_a - p_b lo hi (the report's paired 95% "
	      "interval) beyond (1: beyond the rule), label\n",
	      o.f);
	int k = 0;
	for (int g = 0; g < s->n_groups; g++) {
		if (!s->g[g].selected)
			continue;
		char p[200], verdict[32];
		int bad = 0;
		snprintf(p, sizeof p, "groups.%d.verdict", g);
		text(root, p, verdict, sizeof verdict);
		double v[6];
		static const char *const fields[] = {"p_a", "ci95_a.0", "ci95_a.1",
		                                     "p_b", "ci95_b.0", "ci95_b.1"};
		for (int i = 0; i < 6; i++) {
			snprintf(p, sizeof p, "groups.%d.events.traversed.%s", g, fields[i]);
			v[i] = num_or(root, p, i < 3 ? "p_a" : "p_b", g, "traversed", &bad);
		}
		fprintf(o.f, "%d %d", k++, g);
		for (int i = 0; i < 6; i++)
			fprintf(o.f, " %.6g", v[i]);
		for (int e = 0; e < N_EV; e++) {
			static const char *const df[] = {"difference", "difference_ci95.0",
			                                 "difference_ci95.1"};
			for (int i = 0; i < 3; i++) {
				snprintf(p, sizeof p, "groups.%d.events.%s.%s", g, events[e],
				         df[i]);
				fprintf(o.f, " %.6g",
				        num_or(root, p, "difference", g, events[e], &bad));
			}
			char b[16];
			snprintf(p, sizeof p, "groups.%d.events.%s.beyond", g, events[e]);
			text(root, p, b, sizeof b);
			snprintf(p, sizeof p, "groups.%d.events.%s.difference", g, events[e]);
			int beyond = strcmp(b, "true") == 0 ||
			             (strcmp(verdict, "DIFFERENT") == 0 && num(root, p, &bad) != 0);
			fprintf(o.f, " %d", beyond);
		}
		if (bad) {
			bsim_atomic_file_abort(&o);
			return bsim_error_set(
			        err, BSIM_EINPUT,
			        "%s: groups.%d.events: expected p_a, p_b and difference "
			        "of traversed, left, right, side_exit, stuck and unstable",
			        d->path, g);
		}
		char label[256] = "";
		size_t L = 0;
		for (int a = 0; a < s->n_axes && L < sizeof label; a++) {
			int w = snprintf(label + L, sizeof label - L, "%s%s", a ? "," : "",
			                 s->axes[a].values[s->g[g].idx[a]]);
			L += w > 0 ? (size_t)w : 0;
		}
		fprintf(o.f, " \"%s\"\n", label);
	}
	*n_rows = k;
	return figs_data_commit(&o, err);
}

/* One event's differences: points within the rule in colour, beyond in
 * red, offset dx from the group's position. */
static void diff_series(FILE *o, int e, double dx, int pt, const char *color, const char *title,
                        int tics)
{
	int c = 9 + 4 * e;
	fprintf(o,
	        "     'compare.dat' using ($1 + %g):($%d > 0 ? NaN : $%d):%d:%d%s with yerrorbars "
	        "pt %d ps 0.6 lc rgb '%s' title '%s', \\\n"
	        "     '' using ($1 + %g):($%d > 0 ? $%d : NaN):%d:%d with yerrorbars pt %d ps 0.9 "
	        "lc rgb '" FIG_RED "' notitle",
	        dx, c + 3, c, c + 1, c + 2, tics ? ":xtic(33)" : "", pt, color, title, dx, c + 3, c,
	        c + 1, c + 2, pt);
}

/* "\nverdicts: 6 same, 15 equivalent, 6 uninformative, ..." from report.json's
 * verdicts, uninformative (both sides at the floor or the ceiling) counted
 * apart from equivalent; empty if the report has no verdict counts. */
static void verdict_counts(struct fy_node *root, char *buf, size_t size)
{
	static const char *const names[] = {"same",          "different",    "equivalent",
	                                    "uninformative", "inconclusive", "small",
	                                    "disagree"};
	static const char *const keys[] = {"same",          "DIFFERENT",    "equivalent",
	                                   "uninformative", "inconclusive", "small",
	                                   "DISAGREE"};
	size_t L = 0;
	buf[0] = '\0';
	for (size_t i = 0; i < sizeof keys / sizeof keys[0] && L < size; i++) {
		char p[64];
		int bad = 0;
		snprintf(p, sizeof p, "verdicts.%s", keys[i]);
		double v = num(root, p, &bad);
		if (bad)
			continue;
		int w = snprintf(buf + L, size - L, "%s%.0f %s", L ? ", " : "\nverdicts: ", v,
		                 names[i]);
		L += w > 0 ? (size_t)w : 0;
	}
}

static int compare_figure(figs *f, const ydoc *d, const fsum *s, bsim_error *err)
{
	int n = 0, rc = compare_data(f, d, s, &n, err);
	if (rc)
		return rc;
	struct fy_node *root = fy_document_root(d->fyd);
	char la[64], lb[64];
	text(root, "a.label", la, sizeof la);
	text(root, "b.label", lb, sizeof lb);
	int bad = 0;
	double margin = num(root, "rule.margin", &bad);
	if (bad)
		margin = 0.0;
	char keys[400] = "";
	size_t L = 0;
	for (int a = 0; a < s->n_axes && L < sizeof keys; a++) {
		int w = snprintf(keys + L, sizeof keys - L, "%s%s", a ? ", " : "", s->axes[a].key);
		L += w > 0 ? (size_t)w : 0;
	}
	gp_text g;
	if ((rc = gp_text_open(&g, err)))
		return rc;
	FILE *o = g.f;
	fprintf(o, "set multiplot layout 3,1 title ");
	char title[600], verdicts[200];
	verdict_counts(root, verdicts, sizeof verdicts);
	snprintf(title, sizeof title,
	         "%s (A) against %s (B), %d paired trials per group%s\nprobabilities with Wilson "
	         "95%% intervals, paired differences with the report's paired 95%% intervals; red: "
	         "beyond the rule",
	         la, lb, s->trials_per_group, verdicts);
	gp_str(o, title);
	fprintf(o,
	        " noenhanced\nset xrange [-0.7:%g]\nset grid ytics\nset key outside right top\n"
	        "set lmargin 10\nset rmargin 24\n"
	        "set xtics rotate by 90 right font ',%d' noenhanced\n"
	        "margin = %.17g\nset style fill transparent solid 0.15 noborder\n",
	        n - 0.3, n > 60 ? 7 : 9, margin);
	fputs("set title '(a) p_{traverse}'\nset yrange [0:1]\nset ylabel 'p_{traverse}'\n"
	      "unset xlabel\n",
	      o);
	fputs("plot 'compare.dat' using ($1 - 0.15):3:4:5:xtic(33) with yerrorbars pt 7 ps 0.6 "
	      "lc rgb '" FIG_BLUE "' title ",
	      o);
	gp_str(o, la);
	fputs(" noenhanced, \\\n     '' using ($1 + 0.15):6:7:8 with yerrorbars pt 9 ps 0.7 lc "
	      "rgb '" FIG_ORANGE "' title ",
	      o);
	gp_str(o, lb);
	fputs(" noenhanced\n", o);
	fputs("set title '(b) traversed: p_A - p_B'\nset yrange [*:*]\nset ylabel 'p_A - p_B'\n"
	      "plot '+' using 1:(-margin):(margin) with filledcurves lc rgb '#808080' "
	      "title '+- margin', \\\n",
	      o);
	diff_series(o, 0, 0.0, 7, FIG_BLACK, "traversed", 1);
	fputs("\nset title '(c) traversed left type, right type, side exit, stuck, unstable: "
	      "p_A - p_B'\n"
	      "set xlabel ",
	      o);
	gp_str(o, keys);
	fputs(" noenhanced\n"
	      "plot '+' using 1:(-margin):(margin) with filledcurves lc rgb '#808080' "
	      "title '+- margin', \\\n",
	      o);
	diff_series(o, 1, -0.3, 5, FIG_BLUE, "left type", 1);
	fputs(", \\\n", o);
	diff_series(o, 2, -0.15, 9, FIG_ORANGE, "right type", 0);
	fputs(", \\\n", o);
	diff_series(o, 3, 0.0, 7, FIG_GREY, "side exit", 0);
	fputs(", \\\n", o);
	diff_series(o, 4, 0.15, 13, FIG_DKGREY, "stuck", 0);
	fputs(", \\\n", o);
	diff_series(o, 5, 0.3, 11, FIG_PURPLE, "unstable", 0);
	fputs("\nunset multiplot\n", o);
	char *body = gp_text_take(&g);
	int w = 300 + 24 * n;
	rc = body ? figs_render(f, "compare",
	                        w < 1000   ? 1000
	                        : w > 2600 ? 2600
	                                   : w,
	                        1000, body, err)
	          : bsim_error_set(err, BSIM_EFAIL, "out of memory");
	free(body);
	return rc;
}

/* One line on the final-location test of group g of a lattice comparison
 * (report.json groups.G.final_locations). */
static void lattice_test_line(struct fy_node *root, int g, char *buf, size_t size)
{
	char p[200], test[80], beyond[16];
	snprintf(p, sizeof p, "groups.%d.final_locations.test", g);
	text(root, p, test, sizeof test);
	int bad = 0;
	double v[4];
	static const char *const fields[] = {"p", "p_holm", "total_variation", "discordant"};
	for (int i = 0; i < 4; i++) {
		snprintf(p, sizeof p, "groups.%d.final_locations.%s", g, fields[i]);
		v[i] = num(root, p, &bad);
	}
	snprintf(p, sizeof p, "groups.%d.final_locations.beyond", g);
	text(root, p, beyond, sizeof beyond);
	if (!*test || bad) {
		snprintf(buf, size, "(report.json gives no test of the final locations)");
		return;
	}
	snprintf(buf, size,
	         "%.0f discordant pairs; total variation %.3f; %s test: p = %.3g (Holm %.3g)%s",
	         v[3], v[2], test, v[0], v[1],
	         strcmp(beyond, "true") == 0 ? ": beyond the rule" : "");
}

/* A lattice comparison's final-location figures, one per selected group. */
static int lattice_figures(figs *f, const ydoc *d, const fsum *s, const char *dir,
                           char backend[2][128], bsim_error *err)
{
	struct fy_node *root = fy_document_root(d->fyd);
	char(*lines)[400] = calloc((size_t)s->n_groups + 1, sizeof *lines);
	const char **tests = calloc((size_t)s->n_groups + 1, sizeof *tests);
	char dirs[2][BSIM_PATH_MAX], labels[2][128];
	int rc = BSIM_OK;
	if (!lines || !tests)
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	for (int g = 0; !rc && g < s->n_groups; g++) {
		lattice_test_line(root, g, lines[g], sizeof lines[g]);
		tests[g] = lines[g];
	}
	text(root, "a.label", labels[0], sizeof labels[0]);
	text(root, "b.label", labels[1], sizeof labels[1]);
	for (int i = 0; i < 2; i++)
		snprintf(dirs[i], sizeof dirs[i], "%s/%s", dir, backend[i]);
	const char *const dv[2] = {dirs[0], dirs[1]}, *const lv[2] = {labels[0], labels[1]};
	if (!rc)
		rc = figs_lattice_compare(f, dv, lv, s, tests, err);
	free(lines);
	free(tests);
	return rc;
}

int figs_compare(figs *f, const char *dir, bsim_error *err)
{
	char path[BSIM_PATH_MAX], sub[BSIM_PATH_MAX], out[BSIM_PATH_MAX], inputs[BSIM_PATH_MAX];
	snprintf(path, sizeof path, "%s/report.json", dir);
	ydoc d;
	int rc = ydoc_load_own(&d, path, err);
	if (rc)
		return rc;
	struct fy_node *root = fy_document_root(d.fyd);
	/* Each side's sweep is in DIR/<label>, ':' and '/' of the label
	 * written '-' (beamsim compare's directories). */
	char backend[2][128];
	text(root, "a.label", backend[0], sizeof backend[0]);
	text(root, "b.label", backend[1], sizeof backend[1]);
	if (!*backend[0] || !*backend[1]) {
		ydoc_free(&d);
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: a.label, b.label: expected the two sides' labels", path);
	}
	for (int i = 0; i < 2; i++)
		for (char *c = backend[i]; *c; c++)
			if (*c == ':' || *c == '/')
				*c = '-';
	/* Groups, labels and the selection from the first backend's summary. */
	snprintf(sub, sizeof sub, "%s/%s/summary.json", dir, backend[0]);
	fsum s;
	rc = fsum_read(sub, &s, err);
	if (rc) {
		ydoc_free(&d);
		return rc;
	}
	rc = fsum_select(f, &s, err);
	if (!rc)
		rc = compare_figure(f, &d, &s, err);
	snprintf(sub, sizeof sub, "%s/%s", dir, backend[0]);
	if (!rc && figs_is_lattice(sub))
		rc = lattice_figures(f, &d, &s, dir, backend, err);
	fsum_free(&s);
	ydoc_free(&d);
	snprintf(inputs, sizeof inputs, "%s/inputs", dir);
	for (int i = 0; !rc && i < 2; i++) {
		snprintf(sub, sizeof sub, "%s/%s", dir, backend[i]);
		snprintf(out, sizeof out, "%s/%s", f->out, backend[i]);
		figs one = *f;
		one.out = out;
		rc = bsim_output_mkdir(out, err);
		if (!rc)
			rc = figs_sweep(&one, sub, inputs, err);
	}
	return rc;
}
