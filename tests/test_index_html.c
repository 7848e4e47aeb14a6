/* index.html of output directories with figures (store/index_html.h).
 *
 * Truths: the page shows every .png under the directory, found here by an
 * independent walk of the directory; a real browser (headless chromium)
 * loads the page and every image on it (the page's script counts the
 * images with a natural width in <body data-images="LOADED/ALL">); every
 * figure has a caption of its own, not the catch-all; manifest.json lists
 * the page; a directory without figures has only the trajectory player's
 * page (test_viewer: and without trajectories, none). */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "beamsim/key_names.h"
#include "store/index_html.h"
#include "support.h"

/* The .png files under root (relative paths, at most max). */
static int pngs(const char *root, const char *rel, char names[][256], int n, int max)
{
	char path[1400];
	snprintf(path, sizeof path, "%s%s%s", root, *rel ? "/" : "", rel);
	DIR *d = opendir(path);
	assert_non_null(d);
	struct dirent *e;
	while ((e = readdir(d)) != NULL) {
		if (e->d_name[0] == '.')
			continue;
		char sub[600], full[1700];
		snprintf(sub, sizeof sub, "%s%s%s", rel, *rel ? "/" : "", e->d_name);
		snprintf(full, sizeof full, "%s/%s", root, sub);
		struct stat st;
		assert_int_equal(stat(full, &st), 0);
		size_t len = strlen(sub);
		if (S_ISDIR(st.st_mode))
			n = pngs(root, sub, names, n, max);
		else if (len > 4 && len < sizeof names[0] && strcmp(sub + len - 4, ".png") == 0 &&
		         n < max)
			memcpy(names[n++], sub, len + 1);
	}
	closedir(d);
	return n;
}

/* chromium's dumped DOM of dir/index.html (malloc'd). */
static char *dump_dom(const char *dir)
{
	char url[1200];
	snprintf(url, sizeof url, "file://%s/index.html", dir);
	return bsim_test_browser_dom(url, NULL);
}

/* Every png under dir is on the page with a caption of its own, the page
 * is in the manifest, and a browser loads all of it. */
static void check_page(const char *dir)
{
	static char names[256][256];
	int n = pngs(dir, "", names, 0, 256);
	assert_true(n > 0);
	char *page = bsim_test_read(bsim_test_join(dir, "index.html"));
	assert_non_null(page);
	for (int i = 0; i < n; i++) {
		char want[300] = "<img src=\"";
		strcat(want, names[i]); /* names are < 256 characters */
		strcat(want, "\"");
		if (!strstr(page, want))
			fail_msg("%s/index.html does not show %s", dir, names[i]);
		const char *base = strrchr(names[i], '/');
		char caption[512];
		bsim_index_caption(base ? base + 1 : names[i], caption, sizeof caption);
		/* a row of the table, not the catch-all "figure NAME" */
		if (strncmp(caption, "figure ", 7) == 0 || !*caption)
			fail_msg("%s has no caption of its own", names[i]);
	}
	char *manifest = bsim_test_read(bsim_test_join(dir, "manifest.json"));
	assert_non_null(manifest);
	assert_non_null(strstr(manifest, "\"index.html\""));
	free(manifest);

	char *dom = dump_dom(dir);
	char want[64];
	snprintf(want, sizeof want, "data-images=\"%d/%d\"", n, n);
	if (!strstr(dom, want)) {
		const char *got = strstr(dom, "data-images=");
		fail_msg("%s/index.html in chromium: expected %s, got %.24s", dir, want,
		         got ? got : "no data-images");
	}
	free(dom);
	free(page);
}

static void test_captions(void **state)
{
	(void)state;
	char buf[512];
	bsim_index_caption("landscape_g003.png", buf, sizeof buf);
	assert_non_null(strstr(buf, "group 3:"));
	/* the axis by its display name, as the figure's x label names it */
	char label[256];
	bsim_index_caption("traversal_vs_beams_0_stiffness.png", buf, sizeof buf);
	bsim_key_label("beams.0.stiffness", 0, label, sizeof label);
	assert_non_null(strstr(buf, label));
	bsim_index_caption("traversal_vs_effects_random_force_magnitude.png", buf, sizeof buf);
	bsim_key_label("effects.random_force.magnitude", 0, label, sizeof label);
	assert_non_null(strstr(buf, label));
	bsim_index_caption("validate_g010.png", buf, sizeof buf);
	assert_non_null(strstr(buf, "group 10:"));
	bsim_index_caption("summary.json", buf, sizeof buf);
	assert_true(buf[0] != '\0');
	bsim_index_caption("something.xyz", buf, sizeof buf);
	assert_string_equal(buf, "");
}

static void test_sweep_page(void **state)
{
	(void)state;
	char dir[1024], exp[1100];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("index_sweep"));
	snprintf(exp, sizeof exp, "%s", bsim_test_gate_experiment(bsim_test_dir("index_inputs")));
	const char *sweep[] = {"sweep", exp, "--trajectories", "2", "--quiet", "--out", dir, NULL};
	assert_int_equal(bsim_test_cli(sweep, NULL, NULL), 0);
	/* no figures yet: the page is the trajectory player's alone
	 * (test_viewer checks the player) */
	char *first = bsim_test_read(bsim_test_join(dir, "index.html"));
	assert_non_null(first);
	assert_non_null(strstr(first, "<h2>Trajectories</h2>"));
	assert_null(strstr(first, "<h2>Figures</h2>"));
	free(first);
	const char *plot[] = {"plot", dir, "--quiet", NULL};
	assert_int_equal(bsim_test_cli(plot, NULL, NULL), 0);
	check_page(dir);
	/* the page links the data beside the figures */
	char *page = bsim_test_read(bsim_test_join(dir, "index.html"));
	assert_non_null(strstr(page, "href=\"summary.json\""));
	assert_non_null(strstr(page, "href=\"p_traverse.dat\""));
	assert_null(strstr(page, "<h2>Verdict</h2>")); /* a sweep has no report */
	free(page);
}

static void test_compare_page(void **state)
{
	(void)state;
	char dir[1024], exp[1100];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("index_compare"));
	snprintf(exp, sizeof exp, "%s", bsim_test_gate_experiment(bsim_test_dir("index_inputs2")));
	const char *cmp[] = {"compare", exp, "--trials", "4", "--quiet", "--out", dir, NULL};
	int rc = bsim_test_cli(cmp, NULL, NULL);
	assert_true(rc == 0 || rc == 3);
	const char *plot[] = {"plot", dir, "--quiet", NULL};
	assert_int_equal(bsim_test_cli(plot, NULL, NULL), 0);
	/* the sides' figures in their folders are on the top page */
	assert_true(bsim_test_exists(bsim_test_join(dir, "thesis/p_traverse.png")));
	check_page(dir);
	/* the verdict: report.md's headline, its bold kept, and the link */
	char *page = bsim_test_read(bsim_test_join(dir, "index.html"));
	char *report = bsim_test_read(bsim_test_join(dir, "report.md"));
	assert_non_null(page);
	assert_non_null(report);
	const char *head = strstr(report, "\n**");
	assert_non_null(head);
	char want[160];
	const char *end = strstr(head + 3, "**");
	assert_non_null(end);
	snprintf(want, sizeof want, "<h2>Verdict</h2>\n<p><b>%.*s</b>", (int)(end - head - 3),
	         head + 3);
	if (!strstr(page, want))
		fail_msg("index.html has no \"%s\"", want);
	assert_non_null(strstr(page, "<a href=\"report.md\">report.md</a>"));
	/* each group's verdict: report.md's table of groups row for row, its
	 * cells (bold dropped) the page's */
	const char *table = strstr(report, "\n| group |");
	assert_non_null(table);
	const char *html = strstr(page, "<table class=\"verdicts\">");
	assert_non_null(html);
	int rows = 0;
	for (const char *l = table + 1; *l == '|'; l = strchr(l, '\n') + 1) {
		if (strncmp(l, "|---", 4) == 0)
			continue;
		const char *tag = rows ? "<td>" : "<th>";
		html = strstr(html, "<tr>");
		assert_non_null(html);
		for (const char *c = l + 1; strchr(c, '|') && strchr(c, '|') < strchr(l, '\n');
		     c = strchr(c, '|') + 1) {
			size_t n = strcspn(c, "|");
			char cell[300], want_cell[320];
			size_t k = 0;
			for (size_t i = 0; i < n && k + 1 < sizeof cell; i++)
				if (c[i] != '*')
					cell[k++] = c[i];
			cell[k] = '\0';
			char *b = cell, *e = cell + strlen(cell);
			while (*b == ' ')
				b++;
			while (e > b && e[-1] == ' ')
				*--e = '\0';
			snprintf(want_cell, sizeof want_cell, "%s%s", tag, b);
			html = strstr(html, want_cell);
			if (!html)
				fail_msg("row %d of report.md's table of groups: no cell \"%s\" on "
				         "the page",
				         rows, b);
		}
		rows++;
	}
	assert_int_equal(rows, 1 + 2); /* the header and the experiment's 2 groups */
	free(report);
	free(page);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_captions),
	        cmocka_unit_test(test_sweep_page),
	        cmocka_unit_test(test_compare_page),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
