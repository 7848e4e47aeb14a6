/* beamsim essay and the statistics it uses: (a) Fisher's exact test,
 * Newcombe's interval of a difference of independent proportions and the
 * Cochran-Armitage trend test against published values (R's fisher.test
 * documentation, Newcombe 1998 Table II, Agresti 2002 Sec. 5.3.5); (b) the
 * command end to end with few trials: every column, one row per claim and
 * mode, each verdict what its p-value and sign say, the same file whatever
 * the threads, and bad options refused with exit status 2; (c) a gnuplot
 * that fails on the figure: exit 1 naming it, and the tables committed
 * with its script and data. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "beamsim/stats.h"
#include "support.h"

static void test_fisher_published(void **state)
{
	(void)state;
	/* Fisher's tea-tasting table [[3, 1], [1, 3]]: p = 34/70 (R 0.4857). */
	assert_float_equal(bsim_stats_fisher_exact(3, 4, 1, 4), 34.0 / 70.0, 1e-12);
	/* R's ?fisher.test "Convictions" (Fisher 1962): 2 of 17 dizygotic
	 * against 10 of 13 monozygotic twins convicted, two-sided p 0.0005367. */
	assert_float_equal(bsim_stats_fisher_exact(2, 17, 10, 13), 0.0005367, 5e-8);
	/* Symmetric in the two samples, 1 for equal proportions. */
	assert_float_equal(bsim_stats_fisher_exact(10, 13, 2, 17), 0.0005367, 5e-8);
	assert_float_equal(bsim_stats_fisher_exact(10, 100, 100, 1000), 1.0, 1e-12);
	assert_float_equal(bsim_stats_fisher_exact(0, 0, 3, 10), 1.0, 0);
}

static void test_newcombe_difference_published(void **state)
{
	(void)state;
	/* Newcombe, Statist. Med. 17 (1998) 873, Table II, method 10. */
	static const struct {
		int a, m, b, n;
		double lo, hi;
	} t[] = {
	        {56, 70, 48, 80, 0.0524, 0.3339},
	        {9, 10, 3, 10, 0.1705, 0.8090},
	        {5, 56, 0, 29, -0.0381, 0.1926},
	};
	for (size_t i = 0; i < sizeof t / sizeof t[0]; i++) {
		double lo, hi;
		bsim_stats_newcombe_diff_ci(t[i].a, t[i].m, t[i].b, t[i].n, BSIM_STATS_Z95, &lo,
		                            &hi);
		assert_float_equal(lo, t[i].lo, 5e-5);
		assert_float_equal(hi, t[i].hi, 5e-5);
	}
}

static void test_cochran_armitage_published(void **state)
{
	(void)state;
	/* Agresti, Categorical Data Analysis (2002), Table 2.7 and Sec. 5.3.5:
	 * infant malformation by the mother's alcohol consumption, scores
	 * 0, 0.5, 1.5, 4, 7: z^2 = 6.57, two-sided P = 0.01. */
	const int x[] = {48, 38, 5, 1, 1};
	const int n[] = {17066 + 48, 14464 + 38, 788 + 5, 126 + 1, 37 + 1};
	const double s[] = {0, 0.5, 1.5, 4, 7};
	bsim_stats_trend t;
	bsim_stats_cochran_armitage(x, n, s, 5, BSIM_STATS_Z95, &t);
	assert_float_equal(t.z * t.z, 6.57, 0.005);
	assert_float_equal(t.p, 0.0104, 0.0001);
	assert_true(t.slope > 0 && t.lo < t.slope && t.hi > t.slope);
	/* An exact line: p_i = 0.1 + 0.1 i in 1000 trials each has slope 0.1. */
	const int x2[] = {100, 200, 300, 400};
	const int n2[] = {1000, 1000, 1000, 1000};
	const double s2[] = {0, 1, 2, 3};
	bsim_stats_cochran_armitage(x2, n2, s2, 4, BSIM_STATS_Z95, &t);
	assert_float_equal(t.slope, 0.1, 1e-12);
	assert_true(t.p < 1e-10);
	/* No variance at all: p = 1. */
	const int x3[] = {0, 0, 0};
	bsim_stats_cochran_armitage(x3, n2, s2, 3, BSIM_STATS_Z95, &t);
	assert_float_equal(t.p, 1.0, 0);
	assert_float_equal(t.slope, 0.0, 0);
}

/* The fields of one CSV line (no quoting: the file has none). */
static int split(char *line, char **f, int max)
{
	int n = 0;
	for (char *s = line; n < max;) {
		f[n++] = s;
		char *c = strchr(s, ',');
		if (!c)
			break;
		*c = '\0';
		s = c + 1;
	}
	return n;
}

static const char *const columns[] = {
        "figure",    "quantity",      "condition", "mode",        "kind",
        "expect",    "essay_value",   "essay_n",   "essay_count", "beamsim_value",
        "beamsim_n", "beamsim_count", "ci_low",    "ci_high",     "diff_low",
        "diff_high", "test",          "p_value",   "verdict"};
#define N_COLUMNS 19

/* Per mode (0: default, 1: the other), of levels [0] and trends [1]: the
 * rows and the consistent ones. */
typedef struct mode_counts {
	int n[2][2], ok[2][2];
} mode_counts;

/* Checks essay.csv: the header, rows per mode, and every verdict against
 * its p-value (a level: consistent iff p >= 0.05; a trend: iff p < 0.05
 * and the estimate has the stated sign); counts them into *mc (may be
 * NULL). Returns the number of rows. */
static int check_csv(const char *path, int trials, mode_counts *mc)
{
	char *text = bsim_test_read(path);
	assert_non_null(text);
	char *save = NULL;
	char *line = strtok_r(text, "\n", &save);
	char *f[N_COLUMNS + 2];
	assert_int_equal(split(line, f, N_COLUMNS + 1), N_COLUMNS);
	for (int i = 0; i < N_COLUMNS; i++)
		assert_string_equal(f[i], columns[i]);
	int rows = 0, modes[2] = {0, 0};
	while ((line = strtok_r(NULL, "\n", &save))) {
		assert_int_equal(split(line, f, N_COLUMNS + 1), N_COLUMNS);
		rows++;
		modes[strcmp(f[3], "default") != 0]++;
		double p = strtod(f[17], NULL), v = strtod(f[9], NULL);
		double lo = strtod(f[12], NULL), hi = strtod(f[13], NULL);
		assert_true(p >= 0.0 && p <= 1.0);
		assert_true(lo <= v + 1e-12 && v <= hi + 1e-12);
		int consistent = strcmp(f[18], "consistent") == 0;
		assert_true(consistent || strcmp(f[18], "differs") == 0);
		if (mc) {
			const int m = strcmp(f[3], "default") != 0, t = strcmp(f[4], "trend") == 0;
			mc->n[m][t]++;
			mc->ok[m][t] += consistent;
		}
		if (strcmp(f[4], "level") == 0) {
			assert_true(f[6][0] != '\0');
			assert_int_equal(atoi(f[7]), strstr(f[2], "C-track") ? 20 : 100);
			assert_int_equal(atoi(f[10]), strstr(f[2], "C-track") ? 5 : trials);
			assert_int_equal(consistent, p >= 0.05);
		} else {
			assert_string_equal(f[4], "trend");
			assert_true(f[6][0] == '\0'); /* no essay value for a trend */
			int falls = strcmp(f[5], "falls") == 0;
			assert_int_equal(consistent, p < 0.05 && (falls ? v < 0 : v > 0));
		}
	}
	free(text);
	/* 19 levels and 21 trends in each of the two modes. */
	assert_int_equal(modes[0], 40);
	assert_int_equal(modes[1], 40);
	return rows;
}

static void test_command(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("essay");
	char out1[1024], out2[1024];
	snprintf(out1, sizeof out1, "%s/a", dir);
	snprintf(out2, sizeof out2, "%s/b", dir);
	const char *configs = bsim_test_src("configs");
	char cfg[1024];
	snprintf(cfg, sizeof cfg, "%s", configs);
	const char *a1[] = {
	        "essay",  "--out",     out1,     "--trials",           "20", "--lattice-trials",
	        "5",      "--configs", cfg,      "--threads",          "2",  "--quiet",
	        "--mode", "default",   "--mode", "contact_mode=essay", NULL};
	char *err = NULL;
	int rc = bsim_test_cli(a1, NULL, &err);
	if (rc)
		print_error("%s\n", err);
	assert_int_equal(rc, 0);
	free(err);
	assert_int_equal(check_csv(bsim_test_join(out1, "essay.csv"), 20, NULL), 80);
	assert_true(bsim_test_exists(bsim_test_join(out1, "essay.mat")));
	assert_true(bsim_test_exists(bsim_test_join(out1, "essay.md")));
	assert_true(bsim_test_exists(bsim_test_join(out1, "essay.gp")));
	assert_true(bsim_test_exists(bsim_test_join(out1, "manifest.json")));
	assert_true(bsim_test_check_figures(out1) >= 1);
	/* Same seed, same answer, whatever the threads; the command says each
	 * mode's verdicts, levels and trends apart, as essay.csv counts them. */
	const char *a2[] = {"essay",     "--out",     out2,
	                    "--trials",  "20",        "--lattice-trials",
	                    "5",         "--configs", cfg,
	                    "--threads", "1",         "--mode",
	                    "default",   "--mode",    "contact_mode=essay",
	                    NULL};
	char *printed = NULL;
	assert_int_equal(bsim_test_cli(a2, &printed, NULL), 0);
	char *c1 = bsim_test_read(bsim_test_join(out1, "essay.csv"));
	char *c2 = bsim_test_read(bsim_test_join(out2, "essay.csv"));
	assert_string_equal(c1, c2);
	free(c1);
	free(c2);
	mode_counts mc = {{{0}}, {{0}}};
	check_csv(bsim_test_join(out2, "essay.csv"), 20, &mc);
	static const char *const names[2] = {"default", "contact_mode=essay"};
	for (int m = 0; m < 2; m++) {
		char want[160];
		snprintf(want, sizeof want,
		         "  %s: consistent with %d of the essay's %d levels and %d of its %d "
		         "trends\n",
		         names[m], mc.ok[m][0], mc.n[m][0], mc.ok[m][1], mc.n[m][1]);
		if (!strstr(printed, want))
			fail_msg("no line \"%s\" in:\n%s", want, printed);
	}
	free(printed);
}

/* A gnuplot that fails: exit 1 naming the figure and quoting its line; the
 * essay's tables, the figure's script and data are committed as a result
 * (the journal of the trials with them gone). */
static void test_gnuplot_fails(void **state)
{
	(void)state;
	const char *base = bsim_test_dir("essay_gnuplot_fails");
	char bin[1100], dir[1100];
	snprintf(bin, sizeof bin, "%s/bin", base);
	snprintf(dir, sizeof dir, "%s/out", base);
	char cfg[1024];
	snprintf(cfg, sizeof cfg, "%s", bsim_test_src("configs"));
	char *old = bsim_test_fake_program(
	        bin, "gnuplot",
	        "#!/bin/sh\necho '\"essay.gp\" line 5: the stand-in fails here' >&2\nexit 1\n");
	const char *argv[] = {"essay",  "--out",     dir, "--trials",  "20", "--lattice-trials",
	                      "5",      "--configs", cfg, "--threads", "2",  "--quiet",
	                      "--mode", "default",   NULL};
	char *err = NULL;
	int rc = bsim_test_cli(argv, NULL, &err);
	bsim_test_path_restore(old);
	printf("# exit %d: %s", rc, err);
	assert_int_equal(rc, 1);
	char want[1400];
	snprintf(want, sizeof want,
	         "beamsim: figure essay: gnuplot exited with status 1: \"essay.gp\" line 5: the "
	         "stand-in fails here; its script and data are in %s: essay.gp, essay.dat\n",
	         dir);
	assert_string_equal(err, want);
	free(err);
	const char *kept[] = {"essay.csv", "essay.mat", "essay.md", "essay.gp", "essay.dat", NULL};
	const char *none[] = {"essay.png", "essay.svg", NULL};
	bsim_test_check_committed(dir, kept, none);
}

static void test_bad_options(void **state)
{
	(void)state;
	const char *dir = bsim_test_join(bsim_test_dir("essay-bad"), "out");
	/* Usage errors: exit 2, the option named, nothing run. */
	const char *a1[] = {"essay", "--out", dir, "--trials", "0", NULL};
	char *err = NULL;
	assert_int_equal(bsim_test_cli(a1, NULL, &err), 2);
	assert_non_null(strstr(err, "--trials"));
	free(err);
	static const char *const mode[] = {"no_such_knob", NULL};
	const char *a2[] = {"essay", "--out", dir, "--mode", "no_such_knob=1", NULL};
	bsim_test_expect_input_error(a2, mode);
	const char *a3[] = {"essay", "--trials", "5", NULL};
	assert_int_equal(bsim_test_cli(a3, NULL, &err), 2);
	assert_non_null(strstr(err, "--out"));
	free(err);
	const char *a4[] = {"essay", "--out", dir, "--bogus", NULL};
	assert_int_equal(bsim_test_cli(a4, NULL, &err), 2);
	assert_non_null(strstr(err, "--bogus"));
	free(err);
	/* A scene key the schema does not know, in a mode. */
	static const char *const key[] = {"contact.bogus", "unknown key", NULL};
	char cfg[1024];
	snprintf(cfg, sizeof cfg, "%s", bsim_test_src("configs"));
	const char *a5[] = {"essay",  "--out",           dir,         "--trials", "2",
	                    "--mode", "contact.bogus=1", "--configs", cfg,        NULL};
	bsim_test_expect_input_error(a5, key);
	/* Nothing was written by the refused runs. */
	assert_false(bsim_test_exists(bsim_test_join(dir, "essay.csv")));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_fisher_published),
	        cmocka_unit_test(test_newcombe_difference_published),
	        cmocka_unit_test(test_cochran_armitage_published),
	        cmocka_unit_test(test_command),
	        cmocka_unit_test(test_gnuplot_fails),
	        cmocka_unit_test(test_bad_options),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
