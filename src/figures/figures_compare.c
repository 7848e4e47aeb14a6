/* Figures of a comparison (figures.h): every side's p_traverse per group
 * side by side with their Wilson intervals, and the paired differences
 * p_A - p_B with the report's paired intervals (Tango's score interval) for
 * traversal, the left and right types, side exits, getting stuck and
 * instability, against the rule's margin; a difference beyond the rule is
 * marked; the title counts the verdicts, uninformative groups (every event
 * at the floor or the ceiling) apart from equivalent ones. With more than
 * two sides the difference panels hold every pair of sides, and the sides
 * and pairs take their colours from a palette by their index. The numbers
 * are report.json's. Each side's own sweep figures go to OUT/<label>/. */
#define _POSIX_C_SOURCE 200809L
#include <stdlib.h>
#include <string.h>

#include "beamsim/compare_dir.h"
#include "beamsim/key_names.h"
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
	struct fy_node *n = bsim_ydoc_lookup(root, path);
	if (!n || bsim_ydoc_number(n, &v) != YDOC_NUM_OK)
		*bad = 1;
	return v;
}

/* A number that may be absent: an interval bound of a deterministic
 * group is then its point, the value at field `point` of the event. */
static double num_or(struct fy_node *root, const char *path, const char *point, int g,
                     const char *event, int *bad)
{
	double v = 0.0;
	struct fy_node *n = bsim_ydoc_lookup(root, path);
	if (n && bsim_ydoc_number(n, &v) == YDOC_NUM_OK)
		return v;
	char p[200];
	snprintf(p, sizeof p, "groups.%d.events.%s.%s", g, event, point);
	return num(root, p, bad);
}

static void text(struct fy_node *root, const char *path, char *buf, size_t size)
{
	struct fy_node *n = bsim_ydoc_lookup(root, path);
	size_t len = 0;
	const char *t = n && fy_node_is_scalar(n) ? fy_node_get_scalar(n, &len) : NULL;
	snprintf(buf, size, "%.*s", t ? (int)len : 0, t ? t : "");
}

/* Pixels of the widest line of a text at the figures' 11 pt font. */
static int text_px(const char *t)
{
	int w = 0;
	while (*t) {
		int n = (int)strcspn(t, "\n");
		w = n > w ? n : w;
		t += n + (t[n] == '\n');
	}
	return 15 * w / 2 + 60;
}

static const char *const events[] = {"traversed", "left",  "right",
                                     "side_exit", "stuck", "unstable"};
enum { N_EV = 6 };

/* The colours of sides (and of pairs of sides) by index: the first two are
 * those of two sides, red is kept for "beyond the rule". */
static const char *const palette[] = {FIG_BLUE, FIG_ORANGE, FIG_GREEN,  FIG_PURPLE,
                                      FIG_SKY,  FIG_BLACK,  FIG_DKGREY, FIG_YELLOW};
enum { N_PALETTE = 8 };

/* The data: one row per selected group. Columns: 1 position, 2 group,
 * 3-8 p and Wilson interval of traversal on A then B, then per event
 * (traversed, left, right, side_exit, stuck, unstable) 4 columns from
 * 9 + 4 e: p_A - p_B, its 95% interval, beyond the rule (1/0); 33 the
 * label. A group without random force is one trial, compared as one pair
 * with no interval (report.json gives none): its interval is the point,
 * and a pair that differs ("DIFFERENT") is beyond the rule. */
typedef struct cmp_layout {
	int n;            /* groups drawn */
	double x_max;     /* the last position */
	int any[N_EV];    /* an event with a difference or an interval off zero */
	int beyond[N_EV]; /* an event with a group beyond the rule */
	gp_text tics;     /* "set xtics (...)" naming the fast axes' values */
	gp_text blank;    /* the same positions, unnamed */
	gp_text blocks;   /* "set x2tics (...)" naming the first axis's value per block */
	int longest;      /* longest tick label, characters */
} cmp_layout;

/* The axes drawn along: those with more than one selected value. With two
 * or more, the first of them makes blocks of groups and the others label
 * the ticks; with one, it labels the ticks. -1: none. */
static int block_axis(const fsum *s)
{
	int first = -1, n = 0;
	for (int a = 0; a < s->n_axes; a++)
		if (s->axes[a].n_selected > 1) {
			if (first < 0)
				first = a;
			n++;
		}
	return n >= 2 ? first : -1;
}

/* Group g's tick label: the values of the varying axes other than the
 * block's, named by the x label. */
static void fast_label(const fsum *s, int g, char *buf, size_t size)
{
	size_t L = 0;
	buf[0] = '\0';
	const int skip = block_axis(s);
	for (int a = 0; a < s->n_axes && L < size; a++) {
		if (s->axes[a].n_selected <= 1 || a == skip)
			continue;
		int w = snprintf(buf + L, size - L, "%s%s", L ? ", " : "",
		                 s->axes[a].values[s->g[g].idx[a]]);
		L += w > 0 ? (size_t)w : 0;
	}
	if (!buf[0])
		snprintf(buf, size, "group %d", g);
}

/* Event e's last cell under ev (report.json's "...events.E"): beyond, as
 * report.json says or by a DIFFERENT verdict with a nonzero difference;
 * and in lay whether the event is beyond somewhere and gets its panel (it
 * happened on either side, or beyond). */
static void event_beyond(FILE *o, struct fy_node *root, const char *ev, int e, const char *verdict,
                         double difference, cmp_layout *lay)
{
	char p[240], b[16];
	snprintf(p, sizeof p, "%s.beyond", ev);
	text(root, p, b, sizeof b);
	int beyond =
	        strcmp(b, "true") == 0 || (strcmp(verdict, "DIFFERENT") == 0 && difference != 0);
	fprintf(o, " %d", beyond);
	lay->beyond[e] |= beyond;
	lay->any[e] |= beyond;
	for (int side = 0; side < 2; side++) {
		int absent = 0;
		snprintf(p, sizeof p, "%s.%s", ev, side ? "p_b" : "p_a");
		double pv = num(root, p, &absent);
		lay->any[e] |= absent || pv != 0;
	}
}

/* Group g's row of two sides after its position and number: traversal on
 * A and B, then each event's difference, interval and beyond. *bad on a
 * missing field. */
static void two_row(FILE *o, struct fy_node *root, int g, cmp_layout *lay, int *bad)
{
	char p[200], verdict[32];
	snprintf(p, sizeof p, "groups.%d.verdict", g);
	text(root, p, verdict, sizeof verdict);
	double v[6];
	static const char *const fields[] = {"p_a", "ci95_a.0", "ci95_a.1",
	                                     "p_b", "ci95_b.0", "ci95_b.1"};
	for (int i = 0; i < 6; i++) {
		snprintf(p, sizeof p, "groups.%d.events.traversed.%s", g, fields[i]);
		v[i] = num_or(root, p, i < 3 ? "p_a" : "p_b", g, "traversed", bad);
	}
	for (int i = 0; i < 6; i++)
		fprintf(o, " %.6g", v[i]);
	for (int e = 0; e < N_EV; e++) {
		static const char *const df[] = {"difference", "difference_ci95.0",
		                                 "difference_ci95.1"};
		double dv[3];
		for (int i = 0; i < 3; i++) {
			snprintf(p, sizeof p, "groups.%d.events.%s.%s", g, events[e], df[i]);
			dv[i] = num_or(root, p, "difference", g, events[e], bad);
			fprintf(o, " %.6g", dv[i]);
		}
		snprintf(p, sizeof p, "groups.%d.events.%s", g, events[e]);
		event_beyond(o, root, p, e, verdict, dv[0], lay);
	}
}

/* Group g's row of more than two sides (report.json's groups.G.sides and
 * .pairwise): each side's p_traverse and interval, then each pair's
 * difference, interval and beyond for each event. */
static void sides_row(FILE *o, struct fy_node *root, int g, int n_sides, cmp_layout *lay, int *bad)
{
	char p[200];
	for (int side = 0; side < n_sides; side++) {
		static const char *const fields[] = {"p_traverse", "ci95.0", "ci95.1"};
		for (int i = 0; i < 3; i++) {
			snprintf(p, sizeof p, "groups.%d.sides.%d.%s", g, side, fields[i]);
			fprintf(o, " %.6g", num(root, p, bad));
		}
	}
	for (int k = 0; k < n_sides * (n_sides - 1) / 2; k++) {
		char q[160], verdict[32];
		snprintf(q, sizeof q, "groups.%d.pairwise.%d", g, k);
		snprintf(p, sizeof p, "%s.verdict", q);
		text(root, p, verdict, sizeof verdict);
		for (int e = 0; e < N_EV; e++) {
			static const char *const df[] = {"difference", "difference_ci95.0",
			                                 "difference_ci95.1"};
			double dv[3];
			for (int i = 0; i < 3; i++) {
				int absent = 0;
				snprintf(p, sizeof p, "%s.events.%s.%s", q, events[e], df[i]);
				dv[i] = num(root, p, &absent);
				/* a deterministic pair has no interval: its point */
				if (absent && i > 0)
					dv[i] = dv[0];
				else if (absent)
					*bad = 1;
				fprintf(o, " %.6g", dv[i]);
			}
			snprintf(p, sizeof p, "%s.events.%s", q, events[e]);
			event_beyond(o, root, p, e, verdict, dv[0], lay);
		}
	}
}

static int compare_data(figs *f, const ydoc *d, const fsum *s, int n_sides, cmp_layout *lay,
                        bsim_error *err)
{
	struct fy_node *root = fy_document_root(d->fyd);
	char path[BSIM_PATH_MAX];
	bsim_atomic_file o;
	int rc = bsim_figs_data_open(f, "compare.dat", &o, path, err);
	if (rc)
		return rc;
	if (n_sides == 2)
		fputs("# position group p_a lo hi p_b lo hi (traversed, Wilson 95%), then for "
		      "traversed, left, right, side_exit, stuck, unstable: p_a - p_b lo hi (the "
		      "report's paired 95% interval) beyond (1: beyond the rule), label\n",
		      o.f);
	else
		fprintf(o.f,
		        "# position group, then for each of the %d sides p_traverse lo hi (Wilson "
		        "95%%), then for each pair of sides (report.json pairwise) and each of "
		        "traversed, left, right, side_exit, stuck, unstable: p_a - p_b lo hi (the "
		        "report's paired 95%% interval) beyond (1: beyond the rule), label\n",
		        n_sides);
	int k = 0, prev_block = -1, block_start = 0;
	double x = -1.0;
	/* blocks of the first axis when there are two or more, a gap between */
	const int bx = block_axis(s), blocked = bx >= 0;
	fputs("set xtics (", lay->tics.f);
	fputs("set xtics (", lay->blank.f);
	fputs("set x2tics (", lay->blocks.f);
	for (int g = 0; g < s->n_groups; g++) {
		if (!s->g[g].selected)
			continue;
		const int block = blocked ? s->g[g].idx[bx] : 0;
		if (block != prev_block && prev_block >= 0) {
			char kv[200];
			bsim_figs_key_value(s->axes[bx].key, s->axes[bx].values[prev_block], kv,
			                    sizeof kv);
			fputs(block_start ? ", " : "", lay->blocks.f);
			bsim_gp_str(lay->blocks.f, kv);
			fprintf(lay->blocks.f, " %g", 0.5 * (block_start + x));
			x += 1.0;
		}
		if (block != prev_block)
			block_start = (int)(x + 1.0);
		prev_block = block;
		x += 1.0;
		int bad = 0;
		fprintf(o.f, "%g %d", x, g);
		k++;
		if (n_sides == 2)
			two_row(o.f, root, g, lay, &bad);
		else
			sides_row(o.f, root, g, n_sides, lay, &bad);
		if (bad) {
			bsim_atomic_file_abort(&o);
			return bsim_error_set(
			        err, BSIM_EINPUT,
			        n_sides == 2
			                ? "%s: groups.%d.events: expected p_a, p_b and difference "
			                  "of traversed, left, right, side_exit, stuck and unstable"
			                : "%s: groups.%d: expected sides with p_traverse and ci95, "
			                  "and pairwise with the events' differences",
			        d->path, g);
		}
		char label[256];
		fast_label(s, g, label, sizeof label);
		fprintf(o.f, " \"%s\"\n", label);
		fputs(k > 1 ? ", " : "", lay->tics.f);
		bsim_gp_str(lay->tics.f, label);
		fprintf(lay->tics.f, " %g", x);
		fprintf(lay->blank.f, "%s'' %g", k > 1 ? ", " : "", x);
		int len = (int)strlen(label);
		lay->longest = len > lay->longest ? len : lay->longest;
	}
	if (blocked && prev_block >= 0) {
		char kv[200];
		bsim_figs_key_value(s->axes[bx].key, s->axes[bx].values[prev_block], kv, sizeof kv);
		fputs(block_start ? ", " : "", lay->blocks.f);
		bsim_gp_str(lay->blocks.f, kv);
		fprintf(lay->blocks.f, " %g", 0.5 * (block_start + x));
	}
	fputs(") noenhanced\n", lay->tics.f);
	fputs(")\n", lay->blank.f);
	fputs(") noenhanced\n", lay->blocks.f);
	lay->x_max = x;
	lay->n = k;
	return bsim_figs_data_commit(&o, err);
}

/* One event's differences: points within the rule in colour, beyond in
 * red. */
static void diff_series(FILE *o, int e, int pt, const char *color, const char *title, int beyond)
{
	int c = 9 + 4 * e;
	fprintf(o,
	        "     'compare.dat' using 1:($%d > 0 ? NaN : $%d):%d:%d with yerrorbars "
	        "pt %d ps 0.7 lc rgb '%s' title '%s', \\\n"
	        "     '' using 1:($%d > 0 ? $%d : NaN):%d:%d with yerrorbars pt %d ps 0.9 "
	        "lc rgb '" FIG_RED "' %s\n",
	        c + 3, c, c + 1, c + 2, pt, color, title, c + 3, c, c + 1, c + 2, pt,
	        beyond ? "title 'beyond the rule'" : "notitle");
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

/* One event's differences of every pair of n sides (columns from sides_row),
 * each pair offset along x and in its palette colour; those beyond the
 * rule in red. */
static void diff_series_sides(FILE *o, int e, int n, char (*label)[128], int pt, int beyond)
{
	const int n_pairs = n * (n - 1) / 2;
	for (int k = 0, i = 0; i < n; i++)
		for (int j = i + 1; j < n; j++, k++) {
			int c = 3 + 3 * n + 4 * (k * N_EV + e);
			double dx = 0.5 * ((k + 0.5) / n_pairs - 0.5);
			char title[300];
			snprintf(title, sizeof title, "%s - %s", label[i], label[j]);
			fprintf(o,
			        ", \\\n     'compare.dat' using ($1 + %.4f):($%d > 0 ? NaN : "
			        "$%d):%d:%d "
			        "with yerrorbars pt %d ps 0.6 lc rgb '%s' title ",
			        dx, c + 3, c, c + 1, c + 2, pt, palette[k % N_PALETTE]);
			bsim_gp_str(o, title);
			fprintf(o,
			        " noenhanced, \\\n     '' using ($1 + %.4f):($%d > 0 ? $%d : "
			        "NaN):%d:%d "
			        "with yerrorbars pt %d ps 0.9 lc rgb '" FIG_RED "' %s",
			        dx, c + 3, c, c + 1, c + 2, pt,
			        beyond && k == 0 ? "title 'beyond the rule'" : "notitle");
		}
	fputc('\n', o);
}

static int compare_figure(figs *f, const ydoc *d, fsum *s, const char *inputs, int n_sides,
                          char (*label)[128], bsim_error *err)
{
	cmp_layout lay;
	memset(&lay, 0, sizeof lay);
	int rc = bsim_gp_text_open(&lay.tics, err);
	if (!rc)
		rc = bsim_gp_text_open(&lay.blank, err);
	if (!rc)
		rc = bsim_gp_text_open(&lay.blocks, err);
	if (!rc)
		rc = compare_data(f, d, s, n_sides, &lay, err);
	char *tics = bsim_gp_text_take(&lay.tics), *blank = bsim_gp_text_take(&lay.blank),
	     *blocks = bsim_gp_text_take(&lay.blocks);
	if (!rc && (!tics || !blank || !blocks))
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	if (rc) {
		free(tics);
		free(blank);
		free(blocks);
		return rc;
	}
	struct fy_node *root = fy_document_root(d->fyd);
	char la[64], lb[64], who[600];
	text(root, "a.label", la, sizeof la);
	text(root, "b.label", lb, sizeof lb);
	snprintf(who, sizeof who, "A: %s backend, B: %s backend", la, lb);
	for (int i = 0, len = 0; n_sides > 2 && i < n_sides && len < (int)sizeof who; i++) {
		int w = snprintf(who + len, sizeof who - (size_t)len, "%s%s", i ? ", " : "sides ",
		                 label[i]);
		len += w > 0 ? w : 0;
	}
	bsim_fsum_header(s, inputs, who);
	int bad = 0;
	double margin = num(root, "rule.margin", &bad);
	if (bad)
		margin = 0.0;
	/* one panel per event that happened; the others named in the title */
	static const char *const names[] = {"traversed", "left type", "right type",
	                                    "side exit", "stuck",     "unstable"};
	static const char *const colours[] = {FIG_BLACK, FIG_BLUE,   FIG_ORANGE,
	                                      FIG_GREY,  FIG_DKGREY, FIG_PURPLE};
	static const int points[] = {7, 5, 9, 7, 13, 11};
	char none[200] = "";
	size_t NL = 0;
	int rows = 2;
	for (int e = 1; e < N_EV; e++) {
		if (lay.any[e]) {
			rows++;
			continue;
		}
		int w = snprintf(none + NL, sizeof none - NL, "%s%s", NL ? ", " : "", names[e]);
		NL += w > 0 ? (size_t)w : 0;
	}
	char xlabel[600] = "";
	size_t XL = 0;
	for (int a = 0, bx = block_axis(s); a < s->n_axes && XL < sizeof xlabel; a++) {
		if (s->axes[a].n_selected <= 1 || a == bx)
			continue;
		char lab[300];
		bsim_key_label(s->axes[a].key, 1, lab, sizeof lab);
		int w = snprintf(xlabel + XL, sizeof xlabel - XL, "%s%s", XL ? ", " : "", lab);
		XL += w > 0 ? (size_t)w : 0;
	}
	gp_text g;
	if ((rc = bsim_gp_text_open(&g, err))) {
		free(tics);
		free(blank);
		free(blocks);
		return rc;
	}
	FILE *o = g.f;
	char title[1400], verdicts[200];
	verdict_counts(root, verdicts, sizeof verdicts);
	snprintf(title, sizeof title,
	         "%s, %d paired trials per group\n%s%s%s%s\nprobabilities with Wilson 95%% "
	         "intervals, paired differences p_A - p_B with the report's paired 95%% "
	         "intervals; red: beyond the rule",
	         s->header, s->trials_per_group, verdicts + (verdicts[0] == '\n'),
	         NL ? (verdicts[0] ? "; " : "") : "",
	         NL ? (n_sides > 2 ? "on no side: " : "on neither side: ") : "", none);
	/* the panels placed by hand, all the same height: the last one also
	 * holds the tick labels and the x label below it */
	int title_lines = 1;
	for (const char *c = title; *c; c++)
		title_lines += *c == '\n';
	const int ph = 210, top = 18 * title_lines + 20, bottom = 7 * lay.longest + 50;
	const int blocks_px = block_axis(s) >= 0 ? 24 : 0; /* (a)'s block names */
	const int h = top + rows * ph + bottom + blocks_px;
	/* the key's room: 26 characters, or the longest pair's "A - B" */
	int key = 26;
	for (int i = 0; n_sides > 2 && i < n_sides; i++)
		for (int j = i + 1; j < n_sides; j++) {
			int len = 3 * (int)(strlen(label[i]) + strlen(label[j]) + 3) / 4 + 6;
			key = len > key ? len : key;
		}
	fputs("set multiplot title ", o);
	bsim_gp_str(o, title);
	fprintf(o,
	        " noenhanced\nset xrange [-0.7:%g]\nset grid ytics\nset key outside right top "
	        "font ',9'\nset lmargin 10\nset rmargin %d\nmargin = %.17g\n"
	        "set style fill transparent solid 0.15 noborder\nset tics nomirror\n"
	        "unset xlabel\n",
	        lay.x_max + 0.7, key, margin);
	/* (a): the blocks of the first axis named above */
	if (block_axis(s) >= 0)
		fprintf(o, "set x2range [-0.7:%g]\n%sset x2tics scale 0 font ',10'\n",
		        lay.x_max + 0.7, blocks);
	fputs(blank, o);
	fprintf(o, "set origin 0,%.5f\nset size 1,%.5f\n", (double)(bottom + (rows - 1) * ph) / h,
	        (double)(ph + blocks_px) / h);
	fputs("set title '(a) p_{traverse}'\nset yrange [0:1]\n"
	      "set ylabel 'p_{traverse}'\n",
	      o);
	if (n_sides == 2) {
		fputs("plot 'compare.dat' using ($1 - 0.12):3:4:5 with yerrorbars pt 7 ps 0.6 lc "
		      "rgb "
		      "'" FIG_BLUE "' title ",
		      o);
		bsim_gp_str(o, la);
		fputs(" noenhanced, \\\n     '' using ($1 + 0.12):6:7:8 with yerrorbars pt 9 ps "
		      "0.7 "
		      "lc rgb '" FIG_ORANGE "' title ",
		      o);
		bsim_gp_str(o, lb);
		fputs(" noenhanced\n", o);
	} else {
		/* every side, offset along x, in its palette colour */
		for (int i = 0; i < n_sides; i++) {
			fprintf(o,
			        "%s'compare.dat' using ($1 + %.4f):%d:%d:%d with yerrorbars pt %d "
			        "ps "
			        "0.6 lc rgb '%s' title ",
			        i ? ", \\\n     " : "plot ", 0.5 * ((i + 0.5) / n_sides - 0.5),
			        3 + 3 * i, 4 + 3 * i, 5 + 3 * i, i % 2 ? 9 : 7,
			        palette[i % N_PALETTE]);
			bsim_gp_str(o, label[i]);
			fputs(" noenhanced", o);
		}
		fputc('\n', o);
	}
	fputs("unset x2tics\nset yrange [*:*]\nset ylabel 'p_A - p_B'\n", o);
	char panel = 'b';
	int drawn = 1;
	for (int e = 0; e < N_EV; e++) {
		if (e > 0 && !lay.any[e])
			continue;
		drawn++;
		if (drawn < rows)
			fprintf(o, "set origin 0,%.5f\nset size 1,%.5f\n",
			        (double)(bottom + (rows - drawn) * ph) / h, (double)ph / h);
		else
			fprintf(o, "set origin 0,0\nset size 1,%.5f\n", (double)(ph + bottom) / h);
		if (drawn == rows) {
			fputs(tics, o);
			fputs("set xtics rotate by 90 right font ',9'\nset xlabel ", o);
			bsim_gp_str(o, xlabel);
			fputs(" enhanced\n", o);
		}
		fprintf(o, "set title '(%c) %s%s: p_A - p_B'\n", panel++,
		        e == 1 || e == 2 ? "traversed, " : "", names[e]);
		if (n_sides > 2) {
			fputs("plot '+' using 1:(-margin):(margin) with filledcurves lc rgb "
			      "'#808080' "
			      "title '+- margin'",
			      o);
			diff_series_sides(o, e, n_sides, label, points[e], lay.beyond[e]);
			continue;
		}
		fputs("plot '+' using 1:(-margin):(margin) with filledcurves lc rgb '#808080' "
		      "title '+- margin', \\\n",
		      o);
		diff_series(o, e, points[e], colours[e], names[e], lay.beyond[e]);
	}
	fputs("unset multiplot\n", o);
	free(tics);
	free(blank);
	free(blocks);
	char *body = bsim_gp_text_take(&g);
	int w = 360 + 24 * (int)(lay.x_max + 1) + 8 * (key - 26);
	if (w < text_px(title))
		w = text_px(title);
	rc = body ? bsim_figs_render(f, "compare",
	                             w < 1000   ? 1000
	                             : w > 2600 ? 2600
	                                        : w,
	                             h, body, err)
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

/* The final-location test lines of group g of more than two sides, each
 * pair's (report.json groups.G.pairwise.K.final_locations), one a line. */
static void lattice_test_lines(struct fy_node *root, int g, int n_sides, char (*label)[128],
                               char *buf, size_t size)
{
	size_t len = 0;
	buf[0] = '\0';
	for (int k = 0, i = 0; i < n_sides; i++)
		for (int j = i + 1; j < n_sides && len < size; j++, k++) {
			char p[200], v[4][32];
			static const char *const fields[] = {"p", "p_holm", "total_variation",
			                                     "beyond"};
			for (int x = 0; x < 4; x++) {
				snprintf(p, sizeof p, "groups.%d.pairwise.%d.final_locations.%s", g,
				         k, fields[x]);
				text(root, p, v[x], sizeof v[x]);
			}
			int w = snprintf(buf + len, size - len,
			                 "%s%s vs %s: total variation %s, p = %s (Holm %s)%s",
			                 len ? "\n" : "", label[i], label[j], v[2], v[0], v[1],
			                 strcmp(v[3], "true") == 0 ? ": beyond the rule" : "");
			len += w > 0 ? (size_t)w : 0;
		}
}

/* A lattice comparison's final-location figures, one per selected group:
 * every side's distribution on the same scales. */
static int lattice_figures(figs *f, const ydoc *d, const fsum *s, const char *dir, int n_sides,
                           char (*backend)[128], char (*labels)[128], bsim_error *err)
{
	struct fy_node *root = fy_document_root(d->fyd);
	const size_t line = n_sides > 2 ? 160 * (size_t)(n_sides * (n_sides - 1) / 2) : 400;
	char *lines = calloc(((size_t)s->n_groups + 1) * line, 1);
	const char **tests = calloc((size_t)s->n_groups + 1, sizeof *tests);
	char dirs[BSIM_COMPARE_SIDES_MAX][BSIM_PATH_MAX];
	const char *dv[BSIM_COMPARE_SIDES_MAX], *lv[BSIM_COMPARE_SIDES_MAX];
	int rc = BSIM_OK;
	if (!lines || !tests)
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	for (int g = 0; !rc && g < s->n_groups; g++) {
		char *l = lines + (size_t)g * line;
		if (n_sides > 2)
			lattice_test_lines(root, g, n_sides, labels, l, line);
		else
			lattice_test_line(root, g, l, line);
		tests[g] = l;
	}
	for (int i = 0; i < n_sides; i++) {
		snprintf(dirs[i], sizeof dirs[i], "%s/%s", dir, backend[i]);
		dv[i] = dirs[i];
		lv[i] = labels[i];
	}
	if (!rc)
		rc = bsim_figs_lattice_compare(f, n_sides, dv, lv, s, tests, err);
	free(lines);
	free(tests);
	return rc;
}

int bsim_figs_compare(figs *f, const char *dir, bsim_error *err)
{
	char path[BSIM_PATH_MAX], sub[BSIM_PATH_MAX], out[BSIM_PATH_MAX], inputs[BSIM_PATH_MAX];
	snprintf(path, sizeof path, "%s/report.json", dir);
	ydoc d;
	int rc = bsim_ydoc_load_own(&d, path, err);
	if (rc)
		return rc;
	struct fy_node *root = fy_document_root(d.fyd);
	/* The sides: report.json's sides (more than two), else a and b. Each
	 * side's sweep is in DIR/<label>, ':' and '/' of the label written '-'
	 * (beamsim compare's directories). */
	char label[BSIM_COMPARE_SIDES_MAX][128], backend[BSIM_COMPARE_SIDES_MAX][128];
	struct fy_node *sides = bsim_ydoc_lookup(root, "sides");
	int n_sides = sides && fy_node_is_sequence(sides) ? fy_node_sequence_item_count(sides) : 2;
	if (n_sides < 2 || n_sides > BSIM_COMPARE_SIDES_MAX) {
		bsim_ydoc_free(&d);
		return bsim_error_set(err, BSIM_EINPUT, "%s: sides: expected 2 to %d sides", path,
		                      BSIM_COMPARE_SIDES_MAX);
	}
	for (int i = 0; i < n_sides; i++) {
		char p[64];
		if (n_sides > 2)
			snprintf(p, sizeof p, "sides.%d.label", i);
		else
			snprintf(p, sizeof p, "%s.label", i ? "b" : "a");
		text(root, p, label[i], sizeof label[i]);
		if (!*label[i]) {
			bsim_ydoc_free(&d);
			return bsim_error_set(err, BSIM_EINPUT,
			                      n_sides > 2
			                              ? "%s: %s: expected the side's label"
			                              : "%s: a.label, b.label: expected the two "
			                                "sides' labels",
			                      path, p);
		}
		bsim_compare_dir_label(label[i], backend[i], sizeof backend[i]);
	}
	/* Groups, labels and the selection from the first side's summary. */
	snprintf(sub, sizeof sub, "%s/%s/summary.json", dir, backend[0]);
	fsum s;
	rc = bsim_fsum_read(sub, &s, err);
	if (rc) {
		bsim_ydoc_free(&d);
		return rc;
	}
	rc = bsim_fsum_select(f, &s, err);
	snprintf(inputs, sizeof inputs, "%s/inputs", dir);
	if (!rc)
		rc = compare_figure(f, &d, &s, inputs, n_sides, label, err);
	snprintf(sub, sizeof sub, "%s/%s", dir, backend[0]);
	if (!rc && bsim_figs_is_lattice(sub))
		rc = lattice_figures(f, &d, &s, dir, n_sides, backend, label, err);
	bsim_fsum_free(&s);
	bsim_ydoc_free(&d);
	snprintf(inputs, sizeof inputs, "%s/inputs", dir);
	for (int i = 0; !rc && i < n_sides; i++) {
		snprintf(sub, sizeof sub, "%s/%s", dir, backend[i]);
		snprintf(out, sizeof out, "%s/%s", f->out, backend[i]);
		figs one = *f;
		one.out = out;
		rc = bsim_output_mkdir(out, err);
		if (!rc)
			rc = bsim_figs_sweep(&one, sub, inputs, err);
	}
	return rc;
}
