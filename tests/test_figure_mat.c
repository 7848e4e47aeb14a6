/* The figure driver (gnuplot) and the MATLAB writer (libmatio).
 *
 * Truths: a .mat file read back by libmatio's own reader holds every value
 * written, exactly (doubles bit for bit, strings byte for byte, nested
 * structs by field name); a figure's PNG starts with the PNG signature and
 * its IHDR gives the requested size; its SVG is an <svg> document; without
 * gnuplot the script is still written and nothing claims to be drawn. A
 * gnuplot that fails (the real one on a missing data file; a stand-in that
 * exits 1 with a message; one that exits 0 leaving images cut short, as a
 * full disk does) is a failure naming the figure and quoting gnuplot's
 * line, with the script and its data left in place and no image. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <matio.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "util/figure.h"
#include "store/mat.h"
#include "support.h"

static void test_mat_roundtrip(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("mat");
	char path[1024];
	snprintf(path, sizeof path, "%s/t.mat", dir);

	const double col[4] = {0.1, -2.5e-300, 1e300, 3.0};
	const double mx[6] = {1, 2, 3, 4, 5, 6}; /* 3 x 2, column-major */
	const char *const words[3] = {"traversed", "", "side_exit"};
	const char *const backend[1] = {"thesis"};
	const double f_prop = 7.0;
	bsim_mat_field params[1] = {bsim_mat_column("effects_propulsion_force", &f_prop, 1)};
	bsim_mat_field fields[5] = {
	        bsim_mat_column("x", col, 4),          bsim_mat_matrix("m", mx, 3, 2),
	        bsim_mat_strings("outcome", words, 3), bsim_mat_string("backend", backend),
	        bsim_mat_struct("params", params, 1),
	};
	bsim_mat_field var = bsim_mat_struct("t", fields, 5);
	bsim_error err;
	assert_int_equal(bsim_mat_write(path, &var, 1, &err), 0);

	mat_t *mat = Mat_Open(path, MAT_ACC_RDONLY);
	assert_non_null(mat);
	matvar_t *t = Mat_VarRead(mat, "t");
	assert_non_null(t);
	assert_int_equal(t->class_type, MAT_C_STRUCT);

	matvar_t *x = Mat_VarGetStructFieldByName(t, "x", 0);
	assert_non_null(x);
	assert_int_equal(x->dims[0], 4);
	assert_int_equal(x->dims[1], 1);
	assert_memory_equal(x->data, col, sizeof col);

	matvar_t *m = Mat_VarGetStructFieldByName(t, "m", 0);
	assert_int_equal(m->dims[0], 3);
	assert_int_equal(m->dims[1], 2);
	assert_memory_equal(m->data, mx, sizeof mx);

	matvar_t *o = Mat_VarGetStructFieldByName(t, "outcome", 0);
	assert_int_equal(o->class_type, MAT_C_CELL);
	assert_int_equal(o->dims[0], 3);
	for (int i = 0; i < 3; i++) {
		matvar_t *c = Mat_VarGetCell(o, i);
		assert_non_null(c);
		size_t n = c->dims[0] * c->dims[1];
		assert_int_equal(n, strlen(words[i]));
		if (n)
			assert_memory_equal(c->data, words[i], n);
	}
	matvar_t *b = Mat_VarGetStructFieldByName(t, "backend", 0);
	assert_int_equal(b->class_type, MAT_C_CHAR);
	assert_int_equal(b->dims[1], 6);
	assert_memory_equal(b->data, "thesis", 6);

	matvar_t *p = Mat_VarGetStructFieldByName(t, "params", 0);
	matvar_t *pf = Mat_VarGetStructFieldByName(p, "effects_propulsion_force", 0);
	assert_non_null(pf);
	assert_true(((double *)pf->data)[0] == 7.0);
	Mat_VarFree(t);
	Mat_Close(mat);

	/* Nothing but the file itself is left in the directory. */
	char tmp[1100];
	snprintf(tmp, sizeof tmp, "%s.tmp.%ld", path, (long)getpid());
	assert_int_not_equal(access(tmp, F_OK), 0);
}

static void test_mat_unwritable(void **state)
{
	(void)state;
	const double v = 1.0;
	bsim_mat_field f = bsim_mat_column("v", &v, 1);
	bsim_error err;
	assert_int_equal(bsim_mat_write("/nonexistent-dir/x.mat", &f, 1, &err), BSIM_EFAIL);
	assert_non_null(strstr(err.msg, "/nonexistent-dir/x.mat"));
}

static void test_mat_name(void **state)
{
	(void)state;
	char out[64];
	bsim_mat_name("effects.propulsion.force", out, sizeof out);
	assert_string_equal(out, "effects_propulsion_force");
	bsim_mat_name("0.5", out, sizeof out);
	assert_string_equal(out, "x0_5");
	bsim_mat_name("beams.0.stiffness", out, sizeof out);
	assert_string_equal(out, "beams_0_stiffness");
	char longkey[200];
	memset(longkey, 'a', sizeof longkey - 1);
	longkey[sizeof longkey - 1] = '\0';
	bsim_mat_name(longkey, out, sizeof out);
	assert_int_equal(strlen(out), 63);
}

static void test_figure_drawn(void **state)
{
	(void)state;
	if (!bsim_figure_available())
		skip();
	const char *dir = bsim_test_dir("figure");
	bsim_test_write(dir, "sine.dat", "0 0\n1 0.84\n2 0.91\n3 0.14\n");
	bsim_figure_def d = bsim_figure_def_default();
	d.dir = dir;
	d.name = "sine";
	d.width = 640;
	d.height = 400;
	int drawn = -1;
	bsim_error err;
	int rc = bsim_figure_render(&d, "set title 'sine'\nplot 'sine.dat' with lines\n", &drawn,
	                            &err);
	assert_int_equal(rc, 0);
	assert_int_equal(drawn, 1);

	char path[1024];
	snprintf(path, sizeof path, "%s/sine.png", dir);
	FILE *f = fopen(path, "rb");
	assert_non_null(f);
	unsigned char h[24];
	assert_int_equal(fread(h, 1, sizeof h, f), sizeof h);
	fclose(f);
	static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
	assert_memory_equal(h, sig, 8);
	assert_memory_equal(h + 12, "IHDR", 4);
	uint32_t w = (uint32_t)h[16] << 24 | (uint32_t)h[17] << 16 | (uint32_t)h[18] << 8 | h[19];
	uint32_t ht = (uint32_t)h[20] << 24 | (uint32_t)h[21] << 16 | (uint32_t)h[22] << 8 | h[23];
	assert_int_equal(w, 640);
	assert_int_equal(ht, 400);

	snprintf(path, sizeof path, "%s/sine.svg", dir);
	char *svg = bsim_test_read(path);
	assert_non_null(svg);
	assert_non_null(strstr(svg, "<svg"));
	free(svg);
	snprintf(path, sizeof path, "%s/sine.gp", dir);
	char *gp = bsim_test_read(path);
	assert_non_null(strstr(gp, "plot 'sine.dat' with lines"));
	free(gp);
}

static void test_figure_error_named(void **state)
{
	(void)state;
	if (!bsim_figure_available())
		skip();
	const char *dir = bsim_test_dir("figure_bad");
	bsim_figure_def d = bsim_figure_def_default();
	d.dir = dir;
	d.name = "bad";
	bsim_error err;
	int drawn = 0;
	/* A data file that does not exist: gnuplot fails, the error names the
	 * figure and quotes gnuplot's last line, and no image is left behind. */
	assert_int_equal(bsim_figure_render(&d, "plot 'missing.dat'\n", &drawn, &err), BSIM_EFAIL);
	printf("# %s\n", err.msg);
	assert_int_equal(drawn, BSIM_FIGURE_FAILED);
	assert_non_null(strstr(err.msg, "figure bad: gnuplot exited with status 1: "));
	assert_non_null(strstr(err.msg, "No data in plot"));
	assert_non_null(strstr(err.msg, "bad.gp"));
	char path[1024];
	snprintf(path, sizeof path, "%s/bad.png", dir);
	assert_int_not_equal(access(path, F_OK), 0);
}

/* The files in dir whose names hold ".tmp.": none may be left. */
static int temporaries(const char *dir)
{
	char pattern[1100];
	snprintf(pattern, sizeof pattern, "%s/*.tmp.*", dir);
	char *all = bsim_test_read_glob(pattern);
	int any = all != NULL;
	free(all);
	return any;
}

/* A figure of dir named "wave" reading wave.dat, drawn by the stand-in
 * gnuplot script (in dir/bin): its status, drawn and message. */
static int render_with(const char *dir, const char *fake, int *drawn, bsim_error *err)
{
	char bin[1100];
	snprintf(bin, sizeof bin, "%s/bin", dir);
	bsim_test_write(dir, "wave.dat", "0 0\n1 1\n");
	char *old = bsim_test_fake_program(bin, "gnuplot", fake);
	bsim_figure_def d = bsim_figure_def_default();
	d.dir = dir;
	d.name = "wave";
	int rc = bsim_figure_render(
	        &d, "set title 'wave'\nplot 'wave.dat' with lines title \"x\"\n", drawn, err);
	bsim_test_path_restore(old);
	printf("# %s\n", rc ? err->msg : "drawn");
	return rc;
}

/* A gnuplot that says what went wrong and exits 1: its line is quoted, the
 * script and the data it reads are named, they stay, no image does. */
static void test_figure_gnuplot_message_quoted(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("figure_fails");
	int drawn = 0;
	bsim_error err;
	assert_int_equal(render_with(dir,
	                             "#!/bin/sh\necho 'plot it' >&2\n"
	                             "echo '\"wave.gp\" line 9: the stand-in fails here' >&2\n"
	                             "exit 1\n",
	                             &drawn, &err),
	                 BSIM_EFAIL);
	assert_int_equal(drawn, BSIM_FIGURE_FAILED);
	char want[1400];
	snprintf(want, sizeof want,
	         "figure wave: gnuplot exited with status 1: \"wave.gp\" line 9: the stand-in "
	         "fails here; its script and data are in %s: wave.gp, wave.dat",
	         dir);
	assert_string_equal(err.msg, want);
	assert_true(bsim_test_exists(bsim_test_join(dir, "wave.gp")));
	assert_true(bsim_test_exists(bsim_test_join(dir, "wave.dat")));
	assert_false(bsim_test_exists(bsim_test_join(dir, "wave.png")));
	assert_false(temporaries(dir));
}

/* A gnuplot that exits 0 but leaves its images cut short (a full disk:
 * gnuplot does not check its writes) fails all the same. */
static void test_figure_cut_short(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("figure_cut");
	int drawn = 0;
	bsim_error err;
	/* $2 is outbase="NAME.tmp.PID": the images' temporary base name. */
	assert_int_equal(render_with(dir,
	                             "#!/bin/sh\nb=${2#outbase=\\\"}; b=${b%\\\"}\n"
	                             "printf '\\211PNG\\r\\n\\032\\nIHDR' > \"$b.png\"\n"
	                             "printf '<svg>' > \"$b.svg\"\n",
	                             &drawn, &err),
	                 BSIM_EFAIL);
	assert_int_equal(drawn, BSIM_FIGURE_FAILED);
	assert_non_null(strstr(err.msg, "figure wave: gnuplot exited with status 0 but "));
	assert_non_null(
	        strstr(err.msg, "wave.png is cut short (12 bytes, no IEND chunk at its end)"));
	assert_non_null(strstr(err.msg, "wave.gp, wave.dat"));
	assert_false(bsim_test_exists(bsim_test_join(dir, "wave.png")));
	assert_false(bsim_test_exists(bsim_test_join(dir, "wave.svg")));
	assert_false(temporaries(dir));
}

static void take_note(void *user, const char *text)
{
	snprintf(user, 512, "%s", text);
}

/* What a gnuplot that succeeds says (a warning) is passed on as a note
 * naming the figure; the figure is drawn. */
static void test_figure_warning_noted(void **state)
{
	(void)state;
	if (!bsim_figure_available())
		skip();
	const char *dir = bsim_test_dir("figure_warns");
	char note[512] = "";
	bsim_note_set_handler(take_note, note);
	int drawn = 0;
	bsim_error err;
	int rc = render_with(dir,
	                     "#!/bin/sh\necho 'a stand-in warning' >&2\n"
	                     "PATH=\"${PATH#*:}\" exec gnuplot \"$@\"\n",
	                     &drawn, &err);
	bsim_note_set_handler(NULL, NULL);
	assert_int_equal(rc, BSIM_OK);
	assert_int_equal(drawn, BSIM_FIGURE_DRAWN);
	assert_string_equal(note, "gnuplot on wave.gp: a stand-in warning");
	assert_true(bsim_test_exists(bsim_test_join(dir, "wave.png")));
}

static void test_figure_without_gnuplot(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("figure_nognuplot");
	char *old = getenv("PATH") ? strdup(getenv("PATH")) : NULL;
	setenv("PATH", dir, 1); /* an empty directory: no gnuplot */
	bsim_figure_def d = bsim_figure_def_default();
	d.dir = dir;
	d.name = "f";
	int drawn = -1;
	bsim_error err;
	int rc = bsim_figure_render(&d, "plot x\n", &drawn, &err);
	if (old) {
		setenv("PATH", old, 1);
		free(old);
	}
	assert_int_equal(rc, 0);
	assert_int_equal(drawn, 0);
	char path[1024];
	snprintf(path, sizeof path, "%s/f.gp", dir);
	assert_int_equal(access(path, F_OK), 0);
	snprintf(path, sizeof path, "%s/f.png", dir);
	assert_int_not_equal(access(path, F_OK), 0);
	assert_non_null(strstr(bsim_figure_missing_hint(), "gnuplot-nox"));
}

static void test_figure_bad_name(void **state)
{
	(void)state;
	bsim_figure_def d = bsim_figure_def_default();
	d.dir = "/tmp";
	d.name = "a'b";
	bsim_error err;
	assert_int_equal(bsim_figure_render(&d, "plot x\n", NULL, &err), BSIM_EFAIL);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_mat_roundtrip),
	        cmocka_unit_test(test_mat_unwritable),
	        cmocka_unit_test(test_mat_name),
	        cmocka_unit_test(test_figure_drawn),
	        cmocka_unit_test(test_figure_error_named),
	        cmocka_unit_test(test_figure_gnuplot_message_quoted),
	        cmocka_unit_test(test_figure_cut_short),
	        cmocka_unit_test(test_figure_warning_noted),
	        cmocka_unit_test(test_figure_without_gnuplot),
	        cmocka_unit_test(test_figure_bad_name),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
