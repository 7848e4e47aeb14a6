/* DIR/index.html (index_html.h). The page opens with the trajectory
 * player where the set holds trajectories (store/viewer_data.h), then
 * lists the figures (every .png under the directory, top level first) each
 * with its caption and links to NAME.svg, NAME.gp and NAME.*.dat beside it,
 * then every other file. A script sets <body data-images="LOADED/ALL"> once
 * the page has loaded, so a headless browser's dumped DOM says whether
 * every image could be shown; another, first in the page, collects every
 * error of the page (window.beamsimErrors), which the player counts. */
#define _POSIX_C_SOURCE 200809L
#include "store/index_html.h"

#include <dirent.h>
#include <fnmatch.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "beamsim/key_names.h"
#include "store/viewer_data.h"
#include "util/atomic_file.h"
#include "beamsim/limits.h"
#include "beamsim/version.h"

/* Captions by file name: the first pattern that matches wins, so a
 * specific name comes before a pattern that would also match it. A figure
 * added later gets its caption by a row here. */
static const struct {
	const char *pattern;
	const char *caption;
} captions[] = {
        /* sweeps (beamsim plot of a sweep or lattice directory) */
        {"p_traverse.png", "traversal probability p_traverse of every group over the grid's "
                           "first two axes, with 95% Wilson intervals"},
        {"traversal_vs_*.png", "traversal (and its left / right types, or where a lattice's "
                               "trials ended) against the %k, 95% Wilson bands"},
        {"trajectories_g*.png", "group %s: its kept trajectories, coloured by outcome and "
                                "traversal type"},
        {"landscape_g*.png", "group %s: its traversed trajectories over the potential energy "
                             "landscape"},
        {"lattice_g*.png", "group %s: the lattice's stiffness map and its kept trajectories "
                           "(essay Fig. 3.5)"},
        {"final_locations_g*.png", "group %s: where the trials ended in the lattice, with 95% "
                                   "intervals"},
        {"survival.png", "time to leave the gate: Kaplan-Meier survival per group, and the "
                         "outcome had the trials stopped earlier"},
        /* compare */
        {"compare.png", "both backends' p_traverse per group and their paired differences "
                        "with 95% intervals against the rule's margin"},
        /* run --out */
        {"random_force.png", "the random force's draws against N(0, R_m^2) and over time"},
        {"ledger.png", "the energy ledger over time: energies, work in and out, residual"},
        {"landscape_path.png", "the trial's path over its potential energy landscape"},
        {"theta*.png", "beam %s's angle over the trial"},
        /* accuracy, essay */
        {"accuracy.png", "consistency error against speed per backend and setting, the "
                         "Pareto front marked"},
        {"essay.png", "the essay's reported traversal probabilities beside beamsim's, with "
                      "95% intervals"},
        /* landscape, markov, escape */
        {"landscape_beam.png", "3-D surface of E_beam, the springs' energy alone, over the "
                               "body's position (essay Fig. 2.6a)"},
        {"landscape_total.png", "3-D surface of E_total, springs and propulsion, over the "
                                "body's position (essay Fig. 2.6b)"},
        {"landscape_top.png", "E_total from above with contours, the passes and the paths of "
                              "least resistance (essay Fig. 2.6c)"},
        {"landscape_path_single.png", "the same trajectory over the landscape of the beam "
                                      "that carried it alone, the other left out (essay "
                                      "Fig. 2.7c)"},
        {"landscape*.png", "the potential energy landscape (%s)"},
        {"prediction.png", "final-location probabilities the Markov chain predicts, drawn as "
                           "the field, with the end / side / stuck totals"},
        {"time.png", "the time to the outcome (end, side, stuck) the Markov chain "
                     "predicts, as cumulative probabilities"},
        {"validate_g*.png", "group %s: the Markov chain's predicted final locations against "
                            "simulated ones (essay protocol, whole world) drawn as the field, "
                            "with the differences and the end / side / stuck totals"},
        {"kramers.png", "ln k, the traversal rate, against dE / D (Kramers' law) with the "
                        "fit, and its residuals"},
        {"*.png", "figure %s"},
        /* data */
        {"summary.json", "per group: counts, p_traverse and its 95% Wilson interval"},
        {"trials.csv", "one row per trial: outcome, type, times"},
        {"trials.mat", "trials.csv for MATLAB"},
        {"summary.mat", "summary.json for MATLAB"},
        {"run.json", "how the run was made: command, versions, backends and options, seed"},
        {"report.json", "the comparison: per group every side, paired differences, verdicts"},
        {"pairs.csv", "one row per trial: each side's outcome, separation times"},
        {"trajectories.csv", "the kept trajectories, a row every stride steps"},
        {"trajectory.csv", "the trial's state over time"},
        {"ledger.csv", "the trial's energy ledger over time"},
        {"survival.csv", "Kaplan-Meier survival curves per group"},
        {"horizon.csv", "outcomes had the trials stopped at each horizon"},
        {"lattice_map.csv", "the lattice: gates and their stiffnesses"},
        {"final_locations.csv", "where each group's trials ended in the lattice"},
        {"transitions.csv", "gate-to-gate transitions of the lattice trials"},
        {"gate_entries.csv", "entries of each gate"},
        {"beam_peaks.csv", "each beam's largest angle"},
        {"accuracy.csv", "consistency error and speed per backend and setting"},
        {"essay.csv", "the essay's reported values beside beamsim's"},
        {"essay.md", "the essay's numbers and trends against beamsim, as a table"},
        {"report.md", "the comparison's report as a table"},
        {"landscape.csv", "the landscape on its grid: energies and beam angles per point"},
        {"landscape.json", "the landscape's grid, beams, lowest pass and barriers"},
        {"gates.csv", "per gate of the lattice"},
        {"validate.csv", "the Markov chain's predictions against the simulation"},
        {"validate.json", "the Markov chain's validation: distances and sampling errors"},
        {"kramers.csv", "escape times against Kramers' rate"},
        {"kramers.json", "the escape study's fit and settings"},
        {"regress.json", "the rerun against the stored run"},
        {"regress.md", "the rerun against the stored run, as a table"},
        {"accuracy.md", "the accuracy tables, to read"},
        {"equal_error.csv", "cost at equal error per backend"},
        {"sensitivity.csv", "the sensitivity of each essay parameter"},
        {"prediction.csv", "every final location's probability"},
        {"prediction_gates.csv", "the distribution of gates visited"},
        {"time.csv", "the Markov chain's distribution of the time to the outcome"},
        {"time_validate.csv", "the time to the outcome, chain against simulation"},
        {"markov.json", "the settings the maps (or the walks) were built with"},
        {"map_*.exits.csv", "every single gate's entry and exit state (--entries self, flow)"},
        {"map_*.hold.csv", "each single gate's exit bin and time steps in the gate"},
        {"map_*.after_*.csv", "the start's single gates continued in the gate after the start"},
        {"map_*.after_*.cost", "the CPU time and steps the gate after the start took"},
        {"map_*.csv", "a single-gate map: entry bin, exit bin, count"},
        {"map_*.key", "everything that map depends on"},
        {"map_*.cost", "the CPU time and steps that map took"},
        {"visits_*.csv", "a training field's gate visits: entry and exit states"},
        {"visits_*.key", "everything that training field depends on"},
        {"visits_*.cost", "the CPU time and steps that training field took"},
        {"index.html", "every figure with a caption and the trajectory player, for a browser"},
        {"viewer_data.js", "the trajectories and scenes index.html plays"},
        {"viewer.js", "the trajectory player of index.html"},
        {"*.mp4", "the video"},
        {"*.gp", "gnuplot script (rerun with `gnuplot %s.gp` here)"},
        {"*.dat", "data of a figure"},
        {"*.svg", "figure as SVG"},
        {"*.mat", "the CSV of the same name for MATLAB"},
        {"*.yaml", "input as the run read it"},
};

/* 1 if name matches pattern; with one '*', star gets what it matched
 * (with more, fnmatch's glob and star ""). */
static int match(const char *pattern, const char *name, char *star, size_t size)
{
	const char *s = strchr(pattern, '*');
	if (!s || strchr(s + 1, '*')) {
		if (size)
			star[0] = '\0';
		return s ? fnmatch(pattern, name, 0) == 0 : strcmp(pattern, name) == 0;
	}
	size_t pre = (size_t)(s - pattern), post = strlen(s + 1), n = strlen(name);
	if (n < pre + post || strncmp(pattern, name, pre) != 0 ||
	    strcmp(name + n - post, s + 1) != 0)
		return 0;
	snprintf(star, size, "%.*s", (int)(n - pre - post), name + pre);
	return 1;
}

/* The scene key whose name in a file name is ident ("beams_0_stiffness":
 * each '_' is a '.' or itself), as its display label; ident itself when
 * no key of the names table matches. */
static void key_of_ident(const char *ident, char *buf, size_t size)
{
	char key[128];
	int pos[8], n = 0;
	snprintf(key, sizeof key, "%s", ident);
	for (int i = 0; key[i] && n < 8; i++)
		if (key[i] == '_')
			pos[n++] = i;
	for (unsigned m = 0; m < (1u << n); m++) {
		for (int b = 0; b < n; b++)
			key[pos[b]] = (m >> b) & 1u ? '_' : '.';
		bsim_key_name k;
		if (bsim_key_name_find(key, &k)) {
			bsim_key_label(key, 0, buf, size);
			return;
		}
	}
	snprintf(buf, size, "%s", ident);
}

void bsim_index_caption(const char *base, char *buf, size_t size)
{
	char star[256];
	for (size_t i = 0; i < sizeof captions / sizeof captions[0]; i++) {
		if (!match(captions[i].pattern, base, star, sizeof star))
			continue;
		const char *c = captions[i].caption, *p = strstr(c, "%s");
		const char *k = strstr(c, "%k");
		if (k) {
			/* a page of a figure's panels, KEY_pN: the key's, and which page */
			char label[256], page[40] = "";
			char *under = strrchr(star, '_');
			if (under && under[1] == 'p' && under[2] >= '2' && under[2] <= '9' &&
			    strspn(under + 2, "0123456789") == strlen(under + 2)) {
				snprintf(page, sizeof page, " (page %.6s of its panels)",
				         under + 2);
				*under = '\0';
			}
			key_of_ident(star, label, sizeof label);
			snprintf(buf, size, "%.*s%s%s%s", (int)(k - c), c, label, k + 2, page);
		} else if (!p) {
			snprintf(buf, size, "%s", c);
		} else {
			/* group numbers without their leading zeros */
			const char *v = star;
			while (v[0] == '0' && v[1] >= '0' && v[1] <= '9')
				v++;
			snprintf(buf, size, "%.*s%s%s", (int)(p - c), c, v, p + 2);
		}
		return;
	}
	buf[0] = '\0';
}

/* ---- the files -------------------------------------------------------------------- */

typedef struct flist {
	char **rel;
	int n, cap;
} flist;

static int flist_add(flist *l, const char *rel)
{
	for (int i = 0; i < l->n; i++)
		if (strcmp(l->rel[i], rel) == 0)
			return 0;
	if (l->n == l->cap) {
		int cap = l->cap ? 2 * l->cap : 64;
		char **r = realloc(l->rel, (size_t)cap * sizeof *r);
		if (!r)
			return -1;
		l->rel = r;
		l->cap = cap;
	}
	if (!(l->rel[l->n] = strdup(rel)))
		return -1;
	l->n++;
	return 0;
}

static void flist_free(flist *l)
{
	for (int i = 0; i < l->n; i++)
		free(l->rel[i]);
	free(l->rel);
}

/* A file of an unfinished write (NAME.tmp.PID...), the page itself or the
 * manifest (written after the page) is not listed. */
static int skipped(const char *name)
{
	return name[0] == '.' || strstr(name, ".tmp.") != NULL || strcmp(name, "index.html") == 0 ||
	       strcmp(name, "manifest.json") == 0;
}

static int collect(const char *root, const char *rel, int depth, flist *l)
{
	char path[BSIM_PATH_MAX];
	snprintf(path, sizeof path, "%s%s%s", root, *rel ? "/" : "", rel);
	DIR *d = opendir(path);
	if (!d)
		return 0;
	struct dirent *e;
	int rc = 0;
	while (!rc && (e = readdir(d)) != NULL) {
		if (skipped(e->d_name))
			continue;
		char sub[BSIM_PATH_MAX], full[2 * BSIM_PATH_MAX];
		if (snprintf(sub, sizeof sub, "%s%s%s", rel, *rel ? "/" : "", e->d_name) >=
		    (int)sizeof sub)
			continue;
		snprintf(full, sizeof full, "%s/%s", root, sub);
		struct stat st;
		if (stat(full, &st) != 0)
			continue;
		if (S_ISDIR(st.st_mode) && depth < 4)
			rc = collect(root, sub, depth + 1, l);
		else if (S_ISREG(st.st_mode))
			rc = flist_add(l, sub);
	}
	closedir(d);
	return rc;
}

static int ends_with(const char *s, const char *suffix)
{
	size_t n = strlen(s), k = strlen(suffix);
	return n >= k && strcmp(s + n - k, suffix) == 0;
}

/* Top-level files first, then by name. */
static int by_place(const void *a, const void *b)
{
	const char *x = *(const char *const *)a, *y = *(const char *const *)b;
	int dx = strchr(x, '/') != NULL, dy = strchr(y, '/') != NULL;
	return dx != dy ? dx - dy : strcmp(x, y);
}

static void html_text(FILE *f, const char *s)
{
	for (; *s; s++) {
		switch (*s) {
		case '&':
			fputs("&amp;", f);
			break;
		case '<':
			fputs("&lt;", f);
			break;
		case '>':
			fputs("&gt;", f);
			break;
		case '"':
			fputs("&quot;", f);
			break;
		default:
			fputc(*s, f);
		}
	}
}

/* A relative URL: '/' kept, anything outside a safe alphabet %-encoded. */
static void html_url(FILE *f, const char *s)
{
	for (; *s; s++) {
		unsigned char c = (unsigned char)*s;
		if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
		    c == '/' || c == '.' || c == '_' || c == '-')
			fputc(c, f);
		else
			fprintf(f, "%%%02X", c);
	}
}

static void html_link(FILE *f, const char *rel, const char *text)
{
	fputs("<a href=\"", f);
	html_url(f, rel);
	fputs("\">", f);
	html_text(f, text);
	fputs("</a>", f);
}

static const char *base_of(const char *rel)
{
	const char *s = strrchr(rel, '/');
	return s ? s + 1 : rel;
}

/* A cell of a Markdown table row as text: its ** marks dropped. */
static void cell_text(FILE *f, const char *p, size_t n)
{
	char cell[1024];
	size_t k = 0;
	for (size_t i = 0; i < n && k + 1 < sizeof cell; i++) {
		if (p[i] == '*' && i + 1 < n && p[i + 1] == '*') {
			i++;
			continue;
		}
		cell[k++] = p[i];
	}
	cell[k] = '\0';
	html_text(f, cell);
}

/* The next Markdown table of in whose first column is "group" (its lines
 * "| a | b |", the second its "|---|" rule) as an HTML table: a report's
 * per-group verdicts under its headline. Nothing if in has no such table. */
static void page_table(FILE *f, FILE *in)
{
	char line[8192];
	int row = 0, other = 0; /* other: within a table of something else */
	while (fgets(line, sizeof line, in)) {
		if (line[0] != '|') {
			if (row)
				break; /* the table's end */
			other = 0;
			continue;
		}
		if (other || (row == 0 && strncmp(line, "| group |", 9) != 0)) {
			other = 1;
			continue;
		}
		line[strcspn(line, "\n")] = '\0';
		if (row == 1 && strncmp(line, "|---", 4) == 0) {
			row++;
			continue;
		}
		fputs(row ? "<tr>" : "<table class=\"verdicts\">\n<tr>", f);
		for (char *p = line + 1; *p;) {
			size_t n = strcspn(p, "|");
			if (!p[n])
				break; /* after the last | */
			while (n && p[n - 1] == ' ')
				n--;
			while (n && *p == ' ')
				p++, n--;
			fputs(row ? "<td>" : "<th>", f);
			cell_text(f, p, n);
			fputs(row ? "</td>" : "</th>", f);
			p = strchr(p, '|') + 1;
		}
		fputs("</tr>\n", f);
		row++;
	}
	if (row)
		fputs("</table>\n", f);
}

/* The first line of report.md or regress.md (found in stage, else in dir)
 * that opens in bold: the verdict's headline ("**0 of 30 groups
 * disagree.** 6 deterministic ..."), as a paragraph with its bold kept,
 * the table that follows it (each group's verdict) and a link to the whole
 * report. Nothing if there is no such file. */
static void page_verdict(FILE *f, const flist *l, const char *stage, const char *dir)
{
	static const char *const reports[] = {"report.md", "regress.md"};
	for (size_t r = 0; r < sizeof reports / sizeof reports[0]; r++) {
		int listed = 0;
		for (int i = 0; i < l->n && !listed; i++)
			listed = strcmp(l->rel[i], reports[r]) == 0;
		if (!listed)
			continue;
		char path[BSIM_PATH_MAX];
		snprintf(path, sizeof path, "%s/%s", stage, reports[r]);
		FILE *in = fopen(path, "r");
		if (!in && dir) {
			snprintf(path, sizeof path, "%s/%s", dir, reports[r]);
			in = fopen(path, "r");
		}
		if (!in)
			continue;
		char line[8192];
		int found = 0;
		while (!found && fgets(line, sizeof line, in))
			found = strncmp(line, "**", 2) == 0;
		if (!found) {
			fclose(in);
			continue;
		}
		line[strcspn(line, "\n")] = '\0';
		fputs("<h2>Verdict</h2>\n<p>", f);
		/* **...** as bold, the rest as text */
		int bold = 0;
		for (char *p = line; *p;) {
			char *q = strstr(p, "**");
			if (q)
				*q = '\0';
			html_text(f, p);
			if (!q)
				break;
			fputs(bold ? "</b>" : "<b>", f);
			bold = !bold;
			p = q + 2;
		}
		if (bold)
			fputs("</b>", f);
		fputs("</p>\n", f);
		page_table(f, in);
		fclose(in);
		fputs("<p>The whole report, each group's verdict and the statistics: ", f);
		html_link(f, reports[r], reports[r]);
		fputs(".</p>\n", f);
		return;
	}
}

/* The player's section (store/viewer_data.h): what it plays and its caps,
 * the element it draws into, and its scripts. */
static void page_viewer(FILE *f, const bsim_viewer_summary *v)
{
	fputs("<h2>Trajectories</h2>\n<p>", f);
	if (v->kept > v->shown)
		fprintf(f, "The first %ld of the %ld trajectories kept", v->shown, v->kept);
	else if (v->shown > 1)
		fprintf(f, "The %ld trajectories kept", v->shown);
	else
		fputs("The trajectory", f);
	if (v->sides > 1)
		fprintf(f, ", a panel for each of the %d sides, all at the same time", v->sides);
	fputs(v->landscapes ? ", over the landscape E_total" : "", f);
	fprintf(f,
	        ": <b>Play</b>, <b>Pause</b>, the slider for the time%s. At most %d "
	        "trajectories a side are played, each at most %d frames and %d,%03d numbers (a "
	        "scene of many beams gets fewer frames); a longer trajectory is played every "
	        "k-th row of its file and its last",
	        v->shown > 1 ? ", the list for the trial" : "", BSIM_VIEWER_TRAJECTORIES,
	        BSIM_VIEWER_FRAMES, BSIM_VIEWER_VALUES / 1000, BSIM_VIEWER_VALUES % 1000);
	if (v->most_every > 1)
		fprintf(f, " (here k is at most %d, the longest of %ld rows)", v->most_every,
		        v->most_rows);
	else
		fputs(" (here every row is played)", f);
	fputs(". The data is <a href=\"viewer_data.js\">viewer_data.js</a>, the player "
	      "<a href=\"viewer.js\">viewer.js</a>.</p>\n"
	      "<div id=\"beamsim-viewer\" data-state=\"loading\"></div>\n"
	      "<pre id=\"beamsim-viewer-result\" hidden></pre>\n"
	      "<script src=\"viewer_data.js\"></script>\n<script src=\"viewer.js\"></script>\n",
	      f);
}

static void page(FILE *f, const flist *l, const char *stage, const char *dir, int add,
                 const char *command, char *used, int figures, const bsim_viewer_summary *v)
{
	const char *title = base_of(dir);
	fputs("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>", f);
	html_text(f, title);
	fputs(" - beamsim</title>\n<style>\n"
	      "body{font-family:sans-serif;margin:1.5em;max-width:1400px}\n"
	      "figure{margin:0 0 2em 0}\nfigure img{max-width:100%;height:auto;"
	      "border:1px solid #ddd}\nfigcaption{margin-top:.3em}\n"
	      "code{font-size:90%}\nli{margin:.15em 0}\n"
	      "table.verdicts{border-collapse:collapse;font-size:90%}\n"
	      "table.verdicts td,table.verdicts th{border:1px solid #ccc;padding:.15em .5em}\n"
	      "</style>\n"
	      /* every error of the page, also a script that fails to load,
	       * counted for the trajectory player's data-errors */
	      "<script>\nwindow.beamsimErrors = [];\n"
	      "window.addEventListener('error', function (e) {\n"
	      "  var t = e.target, src = t && t !== window && (t.src || t.href);\n"
	      "  window.beamsimErrors.push(src ? 'could not load ' + src : String(e.message));\n"
	      "}, true);\n"
	      "(function (c) {\n  var error = c.error;\n  c.error = function () {\n"
	      "    window.beamsimErrors.push([].join.call(arguments, ' '));\n"
	      "    return error.apply(c, arguments);\n  };\n})(console);\n</script>\n"
	      "</head>\n"
	      "<body data-images=\"\">\n<h1>",
	      f);
	html_text(f, title);
	fputs("</h1>\n<p>Written by <code>beamsim ", f);
	html_text(f, command ? command : "");
	fputs("</code> (beamsim " BSIM_VERSION ").", f);
	if (figures)
		fputs(" Each figure is its PNG; beside it its SVG, its gnuplot script (rerun with "
		      "<code>gnuplot NAME.gp</code> in the figure's folder) and the data it draws.",
		      f);
	fputs(" <code>manifest.json</code> lists every file with its size and CRC-32.</p>\n", f);
	page_verdict(f, l, stage, add ? dir : NULL);
	if (v->shown > 0)
		page_viewer(f, v);
	if (figures)
		fputs("<h2>Figures</h2>\n", f);
	char caption[512];
	for (int i = 0; i < l->n; i++) {
		const char *r = l->rel[i];
		if (!ends_with(r, ".png"))
			continue;
		used[i] = 1;
		size_t stem = strlen(r) - 4;
		bsim_index_caption(base_of(r), caption, sizeof caption);
		fputs("<figure id=\"", f);
		html_text(f, r);
		fputs("\">\n<a href=\"", f);
		html_url(f, r);
		fputs("\"><img src=\"", f);
		html_url(f, r);
		fputs("\" alt=\"", f);
		html_text(f, caption);
		fputs("\"></a>\n<figcaption><b>", f);
		html_text(f, r);
		fputs("</b>: ", f);
		html_text(f, caption);
		fputs(".", f);
		/* NAME.svg, NAME.gp, NAME.dat and NAME.*.dat: the figure's files */
		int k = 0;
		for (int j = 0; j < l->n; j++) {
			const char *o = l->rel[j];
			if (j == i || strncmp(o, r, stem) != 0 || o[stem] != '.' ||
			    strchr(o + stem + 1, '/'))
				continue;
			used[j] = 1;
			fputs(k++ ? " &middot; " : " Files: ", f);
			html_link(f, o, base_of(o));
		}
		fputs("</figcaption>\n</figure>\n", f);
	}
	fputs("<h2>Data and records</h2>\n<ul>\n", f);
	for (int i = 0; i < l->n; i++) {
		if (used[i])
			continue;
		fputs("<li>", f);
		html_link(f, l->rel[i], l->rel[i]);
		bsim_index_caption(base_of(l->rel[i]), caption, sizeof caption);
		if (*caption) {
			fputs(": ", f);
			html_text(f, caption);
		}
		fputs("</li>\n", f);
	}
	fputs("<li>", f);
	html_link(f, "manifest.json", "manifest.json");
	fputs(": every file of this directory with its size and CRC-32</li>\n</ul>\n", f);
	/* LOADED/ALL once every image has loaded or failed (the load event) */
	fputs("<script>\nwindow.addEventListener('load', function () {\n"
	      "  var im = document.images, ok = 0;\n"
	      "  for (var i = 0; i < im.length; i++)\n"
	      "    if (im[i].complete && im[i].naturalWidth > 0) ok++;\n"
	      "  document.body.setAttribute('data-images', ok + '/' + im.length);\n"
	      "});\n</script>\n</body>\n</html>\n",
	      f);
}

int bsim_index_html_write(const char *stage, const char *dir, int add, const char *command,
                          bsim_error *err)
{
	/* the player's files first, so that the page lists them */
	bsim_viewer_summary v;
	int rc = bsim_viewer_write(stage, dir, add, &v, err);
	if (rc != BSIM_OK)
		return rc;
	flist l = {0};
	int bad = collect(stage, "", 0, &l);
	if (!bad && add)
		bad = collect(dir, "", 0, &l);
	if (bad) {
		flist_free(&l);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory listing %s", stage);
	}
	int figures = 0;
	for (int i = 0; i < l.n; i++)
		figures += ends_with(l.rel[i], ".png");
	if (!figures && v.shown == 0) {
		flist_free(&l);
		return BSIM_OK;
	}
	qsort(l.rel, (size_t)l.n, sizeof *l.rel, by_place);
	char *used = calloc((size_t)l.n, 1);
	char path[BSIM_PATH_MAX];
	if (!used)
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	else if (snprintf(path, sizeof path, "%s/index.html", stage) >= (int)sizeof path)
		rc = bsim_error_set(err, BSIM_EFAIL, "%s/index.html: path too long", stage);
	bsim_atomic_file o;
	if (!rc)
		rc = bsim_atomic_file_open(&o, path, err);
	if (!rc) {
		page(o.f, &l, stage, dir, add, command, used, figures, &v);
		rc = bsim_atomic_file_commit(&o, err);
	}
	free(used);
	flist_free(&l);
	return rc;
}
