/* MATLAB twins (store/matlab.h) and the trajectories that sweeps keep.
 *
 * Truths: every .mat file read back with libmatio holds, field by field,
 * exactly the values of the CSV or JSON file it twins (numbers as the
 * CSV's text reads, text byte for byte, JSON null as NaN); the group
 * parameters of each row are the grid values of its group (the first axis
 * varying slowest, as the experiment file defines); a trajectory kept by
 * `sweep --trajectories` is the trajectory `run` records for the same
 * (seed, group, trial), the replay contract. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <libfyaml.h>
#include <matio.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "beamsim/limits.h"
#include "store/matlab.h"
#include "store/mat.h"
#include "support.h"

/* ---- a CSV read by the test itself ------------------------------------------ */

typedef struct tcsv {
	int cols, rows;
	char **name;
	char **cell; /* rows * cols */
	char *text;
} tcsv;

static tcsv tcsv_read(const char *path)
{
	tcsv t = {0};
	t.text = bsim_test_read(path);
	assert_non_null(t.text);
	int lines = 0;
	for (char *p = t.text; *p; p++)
		lines += *p == '\n';
	char **line = calloc((size_t)lines + 1, sizeof *line);
	int n = 0;
	for (char *save = NULL, *l = strtok_r(t.text, "\n", &save); l;
	     l = strtok_r(NULL, "\n", &save))
		line[n++] = l;
	t.cols = 1;
	for (char *p = line[0]; *p; p++)
		t.cols += *p == ',';
	t.rows = n - 1;
	t.name = calloc((size_t)t.cols, sizeof *t.name);
	t.cell = calloc((size_t)t.rows * t.cols + 1, sizeof *t.cell);
	for (int r = 0; r < n; r++) {
		char **dst = r ? t.cell + (size_t)(r - 1) * t.cols : t.name;
		int c = 0;
		char *p = line[r];
		for (;;) {
			char *comma = strchr(p, ',');
			assert_true(c < t.cols);
			dst[c++] = p;
			if (!comma)
				break;
			*comma = '\0';
			p = comma + 1;
		}
		assert_int_equal(c, t.cols);
	}
	free(line);
	return t;
}

static void tcsv_free(tcsv *t)
{
	free(t->name);
	free(t->cell);
	free(t->text);
}

static int tcsv_col(const tcsv *t, const char *name)
{
	for (int c = 0; c < t->cols; c++)
		if (strcmp(t->name[c], name) == 0)
			return c;
	return -1;
}

/* ---- .mat reading --------------------------------------------------------------- */

static matvar_t *mat_var(const char *path, const char *name, mat_t **mat)
{
	*mat = Mat_Open(path, MAT_ACC_RDONLY);
	assert_non_null(*mat);
	matvar_t *v = Mat_VarRead(*mat, name);
	assert_non_null(v);
	return v;
}

static matvar_t *field(matvar_t *st, const char *name)
{
	assert_int_equal(st->class_type, MAT_C_STRUCT);
	matvar_t *f = Mat_VarGetStructFieldByName(st, name, 0);
	if (!f)
		print_error("no field %s\n", name);
	assert_non_null(f);
	return f;
}

static void check_string(matvar_t *v, const char *want)
{
	assert_int_equal(v->class_type, MAT_C_CHAR);
	size_t n = v->dims[0] * v->dims[1];
	assert_int_equal(n, strlen(want));
	if (n)
		assert_memory_equal(v->data, want, n);
}

/* Every column of the CSV equals its field of the struct st: numbers as
 * strtod reads the text (an empty cell NaN), text byte for byte. */
static void check_table(const tcsv *t, matvar_t *st)
{
	for (int c = 0; c < t->cols; c++) {
		char ident[64];
		bsim_mat_name(t->name[c], ident, sizeof ident);
		matvar_t *f = field(st, ident);
		assert_int_equal(f->dims[0], t->rows);
		assert_int_equal(f->dims[1], 1);
		if (f->class_type == MAT_C_DOUBLE) {
			const double *d = f->data;
			for (int r = 0; r < t->rows; r++) {
				const char *s = t->cell[(size_t)r * t->cols + c];
				if (!*s) {
					assert_true(isnan(d[r]));
					continue;
				}
				char *end;
				double want = strtod(s, &end);
				assert_true(*end == '\0');
				if (!(d[r] == want || (isnan(d[r]) && isnan(want))))
					print_error("%s row %d: %.17g in the .mat, %s in the CSV\n",
					            t->name[c], r, d[r], s);
				assert_true(d[r] == want || (isnan(d[r]) && isnan(want)));
			}
		} else {
			assert_int_equal(f->class_type, MAT_C_CELL);
			for (int r = 0; r < t->rows; r++)
				check_string(Mat_VarGetCell(f, r),
				             t->cell[(size_t)r * t->cols + c]);
		}
	}
}

/* ---- JSON values by path (libfyaml reads JSON) ------------------------------------- */

static double json_number(struct fy_document *d, const char *path)
{
	struct fy_node *n = fy_node_by_path(fy_document_root(d), path, FY_NT, FYNWF_DONT_FOLLOW);
	assert_non_null(n);
	const char *t = fy_node_get_scalar0(n);
	assert_non_null(t);
	if (strcmp(t, "null") == 0)
		return NAN;
	char *end;
	double v = strtod(t, &end);
	assert_true(*end == '\0');
	return v;
}

/* ---- the tests ------------------------------------------------------------------------ */

static const double f_prop[6] = {4, 5, 6, 7, 8, 9};
static const double r_m[5] = {0, 10, 20, 30, 40};

static const char *h1_sweep(const char *name, int keep, char *dir, size_t size)
{
	snprintf(dir, size, "%s", bsim_test_dir(name));
	char keep_s[16];
	snprintf(keep_s, sizeof keep_s, "%d", keep);
	const char *argv[] = {"sweep",
	                      bsim_test_src("configs/thesis/h1_symmetric.yaml"),
	                      "--trials",
	                      "3",
	                      "--trajectories",
	                      keep_s,
	                      "--trajectory-stride",
	                      "25",
	                      "--quiet",
	                      "--out",
	                      dir,
	                      NULL};
	char *err = NULL;
	int rc = bsim_test_cli(argv, NULL, &err);
	if (rc)
		print_error("%s", err);
	free(err);
	assert_int_equal(rc, 0);
	return dir;
}

/* The .mat at path holds the variable note saying that its group and
 * trial columns are 0-based (want 1), or has no note (want 0). */
static void check_note(const char *path, int want)
{
	mat_t *mat = Mat_Open(path, MAT_ACC_RDONLY);
	assert_non_null(mat);
	matvar_t *v = Mat_VarRead(mat, "note");
	if (!want) {
		assert_null(v);
	} else {
		assert_non_null(v);
		assert_int_equal(v->class_type, MAT_C_CHAR);
		size_t n = v->dims[0] * v->dims[1];
		char text[512];
		snprintf(text, sizeof text, "%.*s", (int)n, (const char *)v->data);
		if (!strstr(text, "0-based") || !strstr(text, "g+1"))
			fail_msg("%s: note \"%s\"", path, text);
	}
	Mat_VarFree(v);
	Mat_Close(mat);
}

/* trials.mat and trajectories.mat against their CSVs; the grid values of
 * each row (trials.csv's own columns, added to trajectories.mat) against
 * the grid. */
static void check_sweep_table(const char *dir, const char *name)
{
	char csv[1100], path[1100];
	snprintf(csv, sizeof csv, "%s/%s.csv", dir, name);
	snprintf(path, sizeof path, "%s/%s.mat", dir, name);
	tcsv t = tcsv_read(csv);
	assert_true(t.rows > 0);
	mat_t *mat;
	matvar_t *st = mat_var(path, name, &mat);
	check_table(&t, st);
	check_note(path, 1);
	const double *F = field(st, "effects_propulsion_force")->data;
	const double *R = field(st, "effects_random_force_magnitude")->data;
	int gc = tcsv_col(&t, "group");
	for (int r = 0; r < t.rows; r++) {
		int g = atoi(t.cell[(size_t)r * t.cols + gc]);
		assert_true(F[r] == f_prop[g / 5]);
		assert_true(R[r] == r_m[g % 5]);
	}
	Mat_VarFree(st);
	Mat_Close(mat);
	tcsv_free(&t);
}

static void test_sweep_twins(void **state)
{
	(void)state;
	char dir[1024];
	h1_sweep("sweep", 2, dir, sizeof dir);
	check_sweep_table(dir, "trials");
	check_sweep_table(dir, "trajectories");

	char path[1100];
	snprintf(path, sizeof path, "%s/summary.json", dir);
	struct fy_document *d = fy_document_build_from_file(NULL, path);
	assert_non_null(d);
	snprintf(path, sizeof path, "%s/summary.mat", dir);
	mat_t *mat;
	matvar_t *s = mat_var(path, "summary", &mat);
	check_string(field(s, "backend"), "thesis");
	assert_true(*(double *)field(s, "seed")->data == json_number(d, "/seed"));
	assert_true(*(double *)field(s, "trials_per_group")->data == 3);
	check_string(field(field(s, "backend_options"), "integrator"), "midpoint");
	matvar_t *g = field(s, "groups");
	static const char *const counts[] = {"trials", "traversed", "side_exit",  "stuck",
	                                     "left",   "right",     "p_traverse", "steps"};
	for (size_t k = 0; k < sizeof counts / sizeof counts[0]; k++) {
		matvar_t *col = field(g, counts[k]);
		assert_int_equal(col->dims[0], 30);
		for (int i = 0; i < 30; i++) {
			char p[128];
			snprintf(p, sizeof p, "/groups/%d/%s", i, counts[k]);
			assert_true(((double *)col->data)[i] == json_number(d, p));
		}
	}
	/* What trials.mat's note says: group g (0-based) is row g+1 of the
	 * groups' fields, here C index g: its trials count its rows. */
	snprintf(path, sizeof path, "%s/trials.mat", dir);
	mat_t *tm;
	matvar_t *tr = mat_var(path, "trials", &tm);
	const double *tg = field(tr, "group")->data;
	const double *gt = field(g, "trials")->data;
	for (int i = 0; i < 30; i++) {
		int rows = 0;
		for (size_t r = 0; r < field(tr, "group")->dims[0]; r++)
			rows += tg[r] == i;
		assert_true(gt[i] == rows);
	}
	Mat_VarFree(tr);
	Mat_Close(tm);
	snprintf(path, sizeof path, "%s/summary.mat", dir);
	check_note(path, 0); /* no group column: groups are its rows */
	matvar_t *ci = field(g, "ci95");
	assert_int_equal(ci->dims[0], 30);
	assert_int_equal(ci->dims[1], 2);
	matvar_t *pf = field(field(g, "params"), "effects_propulsion_force");
	for (int i = 0; i < 30; i++) {
		char p[128];
		snprintf(p, sizeof p, "/groups/%d/ci95/0", i);
		assert_true(((double *)ci->data)[i] == json_number(d, p));
		snprintf(p, sizeof p, "/groups/%d/ci95/1", i);
		assert_true(((double *)ci->data)[30 + i] == json_number(d, p));
		assert_true(((double *)pf->data)[i] == f_prop[i / 5]);
	}
	Mat_VarFree(s);
	Mat_Close(mat);
	fy_document_destroy(d);
}

/* A sweep that keeps no trajectories leaves none of an earlier run. */
static void test_sweep_without_trajectories(void **state)
{
	(void)state;
	char dir[1024];
	h1_sweep("sweep_stale", 1, dir, sizeof dir);
	char path[1100];
	snprintf(path, sizeof path, "%s/trajectories.csv", dir);
	char *t = bsim_test_read(path);
	assert_non_null(t);
	free(t);
	const char *argv[] = {"sweep",    bsim_test_src("configs/thesis/h1_symmetric.yaml"),
	                      "--trials", "2",
	                      "--quiet",  "--out",
	                      dir,        "--overwrite",
	                      NULL};
	assert_int_equal(bsim_test_cli(argv, NULL, NULL), 0);
	assert_null(bsim_test_read(path));
	snprintf(path, sizeof path, "%s/trajectories.mat", dir);
	assert_null(bsim_test_read(path));
}

/* Trial (g, t) of the sweep replayed by `run` gives the same rows. */
static void test_kept_trajectory_is_the_run(void **state)
{
	(void)state;
	char dir[1024];
	h1_sweep("replay", 2, dir, sizeof dir);
	char path[1100];
	snprintf(path, sizeof path, "%s/trajectories.csv", dir);
	tcsv kept = tcsv_read(path);
	const int g = 28, tr = 1; /* F = 9 N, Rm = 30 N: contacts and noise */
	char run_csv[1100], group[8], trial[8], fset[64], rset[64];
	snprintf(run_csv, sizeof run_csv, "%s/run.csv", dir);
	snprintf(group, sizeof group, "%d", g);
	snprintf(trial, sizeof trial, "%d", tr);
	snprintf(fset, sizeof fset, "effects.propulsion.force=%g", f_prop[g / 5]);
	snprintf(rset, sizeof rset, "effects.random_force.magnitude=%g", r_m[g % 5]);
	const char *argv[] = {"run",
	                      bsim_test_src("configs/thesis/gate.yaml"),
	                      "--seed",
	                      "1",
	                      "--group",
	                      group,
	                      "--trial",
	                      trial,
	                      "--set",
	                      fset,
	                      "--set",
	                      rset,
	                      "--stride",
	                      "25",
	                      "--trajectory",
	                      run_csv,
	                      NULL};
	assert_int_equal(bsim_test_cli(argv, NULL, NULL), 0);
	tcsv run = tcsv_read(run_csv);
	static const char *const cols[] = {"t",      "x",        "y",       "theta1",
	                                   "theta2", "contact1", "contact2"};
	int rows = 0;
	for (int r = 0; r < kept.rows; r++) {
		const char *const *row = (const char *const *)kept.cell + (size_t)r * kept.cols;
		if (atoi(row[tcsv_col(&kept, "group")]) != g ||
		    atoi(row[tcsv_col(&kept, "trial")]) != tr)
			continue;
		assert_true(rows < run.rows);
		const char *const *rr = (const char *const *)run.cell + (size_t)rows * run.cols;
		for (size_t c = 0; c < sizeof cols / sizeof cols[0]; c++) {
			double a = strtod(row[tcsv_col(&kept, cols[c])], NULL);
			double b = strtod(rr[tcsv_col(&run, cols[c])], NULL);
			/* 7 significant digits kept against 10 */
			assert_true(fabs(a - b) <= 1e-6 * fmax(1.0, fabs(b)));
		}
		rows++;
	}
	assert_int_equal(rows, run.rows);
	assert_true(rows > 20);
	tcsv_free(&kept);
	tcsv_free(&run);

	/* and run --trajectory FILE.csv has its twin FILE.mat */
	run = tcsv_read(run_csv);
	snprintf(path, sizeof path, "%s/run.mat", dir);
	mat_t *mat;
	matvar_t *st = mat_var(path, "trajectory", &mat);
	check_table(&run, st);
	Mat_VarFree(st);
	Mat_Close(mat);
	tcsv_free(&run);
}

static void test_run_out_twins(void **state)
{
	(void)state;
	char dir[1024];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("run_out"));
	const char *argv[] = {"run",      bsim_test_src("configs/thesis/gate.yaml"),
	                      "--seed",   "3",
	                      "--trial",  "2",
	                      "--stride", "10",
	                      "--out",    dir,
	                      NULL};
	assert_int_equal(bsim_test_cli(argv, NULL, NULL), 0);
	static const char *const names[] = {"trajectory", "ledger"};
	for (int i = 0; i < 2; i++) {
		char csv[1100], path[1100];
		snprintf(csv, sizeof csv, "%s/%s.csv", dir, names[i]);
		snprintf(path, sizeof path, "%s/%s.mat", dir, names[i]);
		tcsv t = tcsv_read(csv);
		mat_t *mat;
		matvar_t *st = mat_var(path, names[i], &mat);
		check_table(&t, st);
		Mat_VarFree(st);
		Mat_Close(mat);
		tcsv_free(&t);
	}
	/* The ledger closes at every row (docs/model.md check 3): the change of
	 * the mechanical energy is the work in minus the losses, to round-off. */
	char csv[1100];
	snprintf(csv, sizeof csv, "%s/ledger.csv", dir);
	tcsv l = tcsv_read(csv);
	double e0 = strtod(l.cell[tcsv_col(&l, "e_mech")], NULL);
	for (int r = 0; r < l.rows; r++) {
#define L(name) strtod(l.cell[(size_t)r * l.cols + tcsv_col(&l, name)], NULL)
		double de = L("e_mech") - e0;
		double flows = L("w_prop") + L("w_rand") - L("damper") - L("impact") -
		               L("contact") - L("correction");
		assert_true(fabs(de - flows) < 1e-6);
		assert_true(fabs(L("e_mech") - L("e_kin") - L("e_beam")) < 1e-6);
#undef L
	}
	tcsv_free(&l);
}

static void test_compare_twins(void **state)
{
	(void)state;
	char dir[1024];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("compare"));
	const char *argv[] = {"compare",  bsim_test_src("configs/thesis/h1_symmetric.yaml"),
	                      "--trials", "2",
	                      "--quiet",  "--out",
	                      dir,        NULL};
	int rc = bsim_test_cli(argv, NULL, NULL);
	assert_true(rc == 0 || rc == 3);
	char csv[1100], path[1100];
	snprintf(csv, sizeof csv, "%s/pairs.csv", dir);
	snprintf(path, sizeof path, "%s/pairs.mat", dir);
	tcsv t = tcsv_read(csv);
	mat_t *mat;
	matvar_t *st = mat_var(path, "pairs", &mat);
	check_table(&t, st);
	Mat_VarFree(st);
	Mat_Close(mat);
	tcsv_free(&t);

	snprintf(path, sizeof path, "%s/report.json", dir);
	struct fy_document *d = fy_document_build_from_file(NULL, path);
	assert_non_null(d);
	snprintf(path, sizeof path, "%s/report.mat", dir);
	matvar_t *r = mat_var(path, "report", &mat);
	matvar_t *ev = field(field(field(r, "groups"), "events"), "traversed");
	matvar_t *pa = field(ev, "p_a"), *dci = field(ev, "difference_ci95");
	assert_int_equal(dci->dims[1], 2);
	int intervals = 0;
	for (int i = 0; i < 30; i++) {
		char p[128];
		snprintf(p, sizeof p, "/groups/%d/events/traversed/p_a", i);
		assert_true(((double *)pa->data)[i] == json_number(d, p));
		/* a group without random force has no interval: NaN in the table */
		snprintf(p, sizeof p, "/groups/%d/events/traversed/difference_ci95/1", i);
		if (fy_node_by_path(fy_document_root(d), p, FY_NT, FYNWF_DONT_FOLLOW)) {
			assert_true(((double *)dci->data)[30 + i] == json_number(d, p));
			intervals++;
		} else {
			assert_true(isnan(((double *)dci->data)[30 + i]));
		}
	}
	assert_int_equal(intervals, 24); /* the groups with Rm > 0 */
	for (int b = 0; b < 2; b++) {
		snprintf(path, sizeof path, "%s/%s/trials.mat", dir, b ? "box2d" : "thesis");
		char *m = bsim_test_read(path);
		assert_non_null(m);
		free(m);
	}
	Mat_VarFree(r);
	Mat_Close(mat);
	fy_document_destroy(d);
}

/* The JSON mapping of matlab.h on a file written here. */
static void test_json_shapes(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("json");
	char in[1100], out[1100];
	snprintf(in, sizeof in, "%s",
	         bsim_test_write(dir, "x.json",
	                         "{\"name\": \"gate\", \"quoted\": \"7\", \"ok\": true, \"n\": "
	                         "null, \"row\": [1, 2.5, -3],\n"
	                         " \"rows\": [{\"a\": 1, \"ab\": [1, 2], \"s\": \"x\", \"m\": "
	                         "{\"k\": 5}},\n"
	                         "          {\"a\": 2, \"ab\": [3, 4], \"s\": \"yy\"}],\n"
	                         " \"nested\": {\"effects.propulsion.force\": 8}}\n"));
	snprintf(out, sizeof out, "%s/x.mat", dir);
	bsim_error err;
	assert_int_equal(bsim_matlab_from_json(in, out, "x", &err), 0);
	mat_t *mat;
	matvar_t *x = mat_var(out, "x", &mat);
	check_string(field(x, "name"), "gate");
	check_string(field(x, "quoted"), "7");
	assert_true(*(double *)field(x, "ok")->data == 1.0);
	assert_true(isnan(*(double *)field(x, "n")->data));
	matvar_t *row = field(x, "row");
	assert_int_equal(row->dims[0], 1);
	assert_int_equal(row->dims[1], 3);
	assert_true(((double *)row->data)[1] == 2.5);
	matvar_t *rows = field(x, "rows");
	matvar_t *a = field(rows, "a"), *ab = field(rows, "ab"), *s = field(rows, "s");
	assert_int_equal(a->dims[0], 2);
	assert_true(((double *)a->data)[1] == 2.0);
	assert_int_equal(ab->dims[0], 2);
	assert_int_equal(ab->dims[1], 2);
	const double want[4] = {1, 3, 2, 4}; /* column-major */
	assert_memory_equal(ab->data, want, sizeof want);
	check_string(Mat_VarGetCell(s, 1), "yy");
	matvar_t *k = field(field(rows, "m"), "k"); /* the second row has no m: NaN */
	assert_true(((double *)k->data)[0] == 5.0);
	assert_true(isnan(((double *)k->data)[1]));
	assert_true(*(double *)field(field(x, "nested"), "effects_propulsion_force")->data == 8);
	Mat_VarFree(x);
	Mat_Close(mat);

	/* A malformed CSV is named with its line; nothing is written. */
	snprintf(in, sizeof in, "%s", bsim_test_write(dir, "bad.csv", "a,b\n1,2\n3\n"));
	snprintf(out, sizeof out, "%s/bad.mat", dir);
	assert_int_equal(bsim_matlab_from_csv(in, out, "bad", &err), BSIM_EINPUT);
	assert_non_null(strstr(err.msg, "bad.csv:3"));
	assert_null(bsim_test_read(out));
}

/* A table written row by row for the streaming converter: numbers with an
 * empty cell now and then (NaN), text of three words from the first row,
 * a column of numbers that turns text near the end (read a second time),
 * one empty until its first text, and one row longer than the converter's
 * first read (256 KiB) so that a line spans reads. */
static void write_table(const char *path, int rows)
{
	FILE *f = fopen(path, "w");
	assert_non_null(f);
	static const char *const words[] = {"traversed", "stuck", "unstable"};
	fputs("i,x,word,late,gap,hole\n", f);
	for (int r = 0; r < rows; r++) {
		fprintf(f, "%d,%.17g,", r, (r - 2500) * 1.25e-3 / 3);
		if (r == rows / 3) {
			for (int k = 0; k < 300000; k++)
				fputc('a' + k % 26, f);
		} else {
			fputs(words[r % 3], f);
		}
		if (r < rows - 100)
			fprintf(f, ",%d.5", r);
		else
			fprintf(f, ",w%d", r % 5);
		fprintf(f, r < rows / 2 ? "," : ",g%d", r % 4);
		fprintf(f, r % 7 ? ",%de-3\n" : ",\n", r);
	}
	assert_int_equal(fclose(f), 0);
}

/* The streaming converter's twin holds every cell of the CSV, read back
 * with libmatio: numbers as strtod reads them, NaN for an empty cell, text
 * byte for byte; a column is numbers only if every non-empty cell is. */
static void test_streamed_csv(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("streamed");
	char csv[1100], mat[1100];
	snprintf(csv, sizeof csv, "%s/t.csv", dir);
	snprintf(mat, sizeof mat, "%s/t.mat", dir);
	write_table(csv, 5000);
	bsim_error err;
	assert_int_equal(bsim_matlab_from_csv(csv, mat, "t", &err), BSIM_OK);
	assert_string_equal(err.msg, "");
	tcsv t = tcsv_read(csv);
	assert_int_equal(t.rows, 5000);
	mat_t *m;
	matvar_t *st = mat_var(mat, "t", &m);
	check_table(&t, st);
	static const char *const numbers[] = {"i", "x", "hole"}, *const text[] = {"word", "late",
	                                                                          "gap"};
	for (int i = 0; i < 3; i++) {
		assert_int_equal(field(st, numbers[i])->class_type, MAT_C_DOUBLE);
		assert_int_equal(field(st, text[i])->class_type, MAT_C_CELL);
	}
	assert_true(isnan(((double *)field(st, "hole")->data)[0]));
	check_string(Mat_VarGetCell(field(st, "gap"), 0), "");
	check_string(Mat_VarGetCell(field(st, "late"), 0), "0.5");
	Mat_VarFree(st);
	Mat_Close(m);
	tcsv_free(&t);
}

/* Quoted fields, as bsim_csv_field_write writes a user's text (a grid value
 * holding a comma, a quote or a line break), come back unquoted: the text
 * written here, byte for byte; the rows after a line break inside quotes
 * keep their columns; a quote not closed where its field ends is refused
 * naming its line. */
static void test_quoted_csv(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("quoted");
	char csv[1100], mat[1100];
	snprintf(csv, sizeof csv, "%s",
	         bsim_test_write(dir, "q.csv",
	                         "a,b,c\n1,\"x, y\",3\n2,\"say \"\"hi\"\"\",4\n"
	                         "3,\"two\nlines\",5\n4,plain,6\n"));
	snprintf(mat, sizeof mat, "%s/q.mat", dir);
	bsim_error err;
	assert_int_equal(bsim_matlab_from_csv(csv, mat, "q", &err), BSIM_OK);
	mat_t *m;
	matvar_t *st = mat_var(mat, "q", &m);
	static const char *const b[] = {"x, y", "say \"hi\"", "two\nlines", "plain"};
	const double a[] = {1, 2, 3, 4}, c[] = {3, 4, 5, 6};
	assert_int_equal(field(st, "b")->dims[0], 4);
	for (int r = 0; r < 4; r++) {
		check_string(Mat_VarGetCell(field(st, "b"), r), b[r]);
		assert_true(((double *)field(st, "a")->data)[r] == a[r]);
		assert_true(((double *)field(st, "c")->data)[r] == c[r]);
	}
	Mat_VarFree(st);
	Mat_Close(m);
	snprintf(csv, sizeof csv, "%s",
	         bsim_test_write(dir, "open.csv", "a,b\n1,2\n3,\"x\"y\n5,6\n"));
	snprintf(mat, sizeof mat, "%s/open.mat", dir);
	assert_int_equal(bsim_matlab_from_csv(csv, mat, "open", &err), BSIM_EINPUT);
	assert_string_equal(strstr(err.msg, "open.csv:3"),
	                    "open.csv:3: expected 2 fields, got a quoted field not closed where "
	                    "its field ends");
	assert_false(bsim_test_exists(mat));
}

/* The virtual memory of this process, bytes (/proc/self/statm). */
static long vm_size(void)
{
	FILE *f = fopen("/proc/self/statm", "r");
	long pages = 0;
	assert_non_null(f);
	assert_int_equal(fscanf(f, "%ld", &pages), 1);
	fclose(f);
	return pages * sysconf(_SC_PAGESIZE);
}

/* The twin of a JSON file holds what it needs, not a document of it: the
 * summary.json of a 20,000-group sweep (8 MB, written here) converts in a
 * child whose address space may grow by 150 MB (RLIMIT_AS) beyond this
 * process's; libfyaml's document of it took 360 MB. The twin's groups are
 * the rows written. Not under AddressSanitizer, whose shadow memory takes
 * terabytes of address space. */
static void test_json_twin_memory(void **state)
{
	(void)state;
#if defined(__SANITIZE_ADDRESS__)
	skip();
#endif
	enum { GROUPS = 20000 };
	const char *dir = bsim_test_dir("json_memory");
	char json[1100], mat[1100];
	snprintf(json, sizeof json, "%s/summary.json", dir);
	snprintf(mat, sizeof mat, "%s/summary.mat", dir);
	FILE *f = fopen(json, "w");
	assert_non_null(f);
	fputs("{\n  \"backend\": \"thesis\",\n  \"groups\": [\n", f);
	for (int g = 0; g < GROUPS; g++)
		fprintf(f,
		        "    {\"params\": {\"effects.propulsion.force\": 8, \"body.mass\": %d}, "
		        "\"trials\": 1, \"traversed\": %d, \"side_exit\": 0, \"stuck\": %d, "
		        "\"left\": 0, \"right\": 0, \"p_traverse\": %d, \"ci95\": [0, "
		        "0.7934506856227626], \"stuck_in_contact\": 0, \"landscape_left\": 0, "
		        "\"landscape_right\": 0, \"steps\": %d, \"unstable\": 0, "
		        "\"deterministic\": false, \"solver\": {\"iteration_limit\": 0, "
		        "\"clamped\": 0}, \"trials_iteration_limit\": 0, \"trials_clamped\": "
		        "0}%s\n",
		        g + 1, g % 2, 1 - g % 2, g % 2, 2 + g % 7, g + 1 < GROUPS ? "," : "");
	fputs("  ]\n}\n", f);
	assert_int_equal(fclose(f), 0);
	long limit = vm_size() + (150L << 20);
	fflush(NULL);
	pid_t pid = fork();
	assert_true(pid >= 0);
	if (pid == 0) {
		struct rlimit rl = {(rlim_t)limit, (rlim_t)limit};
		setrlimit(RLIMIT_AS, &rl);
		bsim_error err;
		int rc = bsim_matlab_from_json(json, mat, "summary", &err);
		if (rc != BSIM_OK)
			fprintf(stderr, "%s\n", err.msg);
		_exit(rc == BSIM_OK ? 0 : 1);
	}
	int status = 0;
	assert_int_equal(waitpid(pid, &status, 0), pid);
	assert_true(WIFEXITED(status) && WEXITSTATUS(status) == 0);
	mat_t *m;
	matvar_t *st = mat_var(mat, "summary", &m);
	matvar_t *groups = field(st, "groups");
	matvar_t *mass = field(field(groups, "params"), "body_mass");
	const double *p = field(groups, "p_traverse")->data, *steps = field(groups, "steps")->data;
	assert_int_equal(mass->dims[0], GROUPS);
	for (int g = 0; g < GROUPS; g++) {
		assert_true(((double *)mass->data)[g] == g + 1);
		assert_true(p[g] == g % 2 && steps[g] == 2 + g % 7);
	}
	Mat_VarFree(st);
	Mat_Close(m);
}

/* What bsim_note passed to the handler the test set. */
static char noted[BSIM_ERROR_MSG_MAX];
static int notes;

static void note_keep(void *user, const char *text)
{
	(void)user;
	snprintf(noted, sizeof noted, "%s", text);
	notes++;
}

/* A table over the limit mat_rows: no twin (an earlier one removed), one
 * note saying so (to the handler a program sets), BSIM_OK; at the limit the twin is written; a
 * malformed table over the limit is still an error. A sweep over the limit finishes (exit 0)
 * without trials.mat, and regress reads it back. */
static void test_mat_rows_limit(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("mat_rows");
	char csv[1100], mat[1100];
	snprintf(csv, sizeof csv, "%s/t11.csv", dir);
	snprintf(mat, sizeof mat, "%s/t11.mat", dir);
	write_table(csv, 11);
	bsim_test_write(dir, "t11.mat", "an earlier table's twin");
	bsim_limits l = bsim_limits_default();
	l.mat_rows = 10;
	bsim_limits_set(&l);
	bsim_error err;
	bsim_note_set_handler(note_keep, NULL);
	assert_int_equal(bsim_matlab_from_csv(csv, mat, "t", &err), BSIM_OK);
	bsim_note_set_handler(NULL, NULL);
	assert_string_equal(err.msg, "t11.csv: 11 rows, over the limit mat_rows = 10: no t11.mat; "
	                             "MATLAB's readtable reads the CSV (raise with --limit "
	                             "mat_rows=11)");
	assert_int_equal(notes, 1);
	assert_string_equal(noted, err.msg);
	assert_false(bsim_test_exists(mat));
	snprintf(csv, sizeof csv, "%s/t10.csv", dir);
	snprintf(mat, sizeof mat, "%s/t10.mat", dir);
	write_table(csv, 10);
	assert_int_equal(bsim_matlab_from_csv(csv, mat, "t", &err), BSIM_OK);
	assert_string_equal(err.msg, "");
	assert_true(bsim_test_exists(mat));
	snprintf(csv, sizeof csv, "%s",
	         bsim_test_write(dir, "bad.csv",
	                         "a,b\n1,2\n3\n4,5\n6,7\n8,9\n1,2\n3,4\n5,6\n7,8\n"
	                         "9,0\n1,2\n"));
	snprintf(mat, sizeof mat, "%s/bad.mat", dir);
	assert_int_equal(bsim_matlab_from_csv(csv, mat, "bad", &err), BSIM_EINPUT);
	assert_string_equal(strstr(err.msg, "bad.csv:3"), "bad.csv:3: expected 2 fields, got 1");
	bsim_limits_set(NULL);

	char out[1100], again[1100];
	snprintf(out, sizeof out, "%s/sweep", dir);
	snprintf(again, sizeof again, "%s/regress", dir);
	const char *argv[] = {"sweep",    bsim_test_src("configs/thesis/h1_symmetric.yaml"),
	                      "--trials", "3",
	                      "--limit",  "mat_rows=50",
	                      "--quiet",  "--out",
	                      out,        NULL};
	char *text = NULL;
	assert_int_equal(bsim_test_cli(argv, NULL, &text), 0);
	assert_string_equal(text,
	                    "beamsim: trials.csv: 90 rows, over the limit mat_rows = 50: no "
	                    "trials.mat; MATLAB's readtable reads the CSV (raise with "
	                    "--limit mat_rows=90)\n"
	                    "beamsim: survival.csv: 97 rows, over the limit mat_rows = 50: no "
	                    "survival.mat; MATLAB's readtable reads the CSV (raise with "
	                    "--limit mat_rows=97)\n"
	                    "beamsim: horizon.csv: 1440 rows, over the limit mat_rows = 50: no "
	                    "horizon.mat; MATLAB's readtable reads the CSV (raise with "
	                    "--limit mat_rows=1440)\n");
	free(text);
	assert_false(bsim_test_exists(bsim_test_join(out, "trials.mat")));
	assert_true(bsim_test_exists(bsim_test_join(out, "summary.mat")));
	text = bsim_test_read(bsim_test_join(out, "manifest.json"));
	assert_non_null(strstr(text, "\"trials.csv\""));
	assert_null(strstr(text, "trials.mat"));
	free(text);
	const char *re[] = {"regress", out, "--exact", "--quiet", "--out", again, NULL};
	assert_int_equal(bsim_test_cli(re, NULL, NULL), 0);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_sweep_twins),
	        cmocka_unit_test(test_sweep_without_trajectories),
	        cmocka_unit_test(test_kept_trajectory_is_the_run),
	        cmocka_unit_test(test_run_out_twins),
	        cmocka_unit_test(test_compare_twins),
	        cmocka_unit_test(test_json_shapes),
	        cmocka_unit_test(test_streamed_csv),
	        cmocka_unit_test(test_quoted_csv),
	        cmocka_unit_test(test_json_twin_memory),
	        cmocka_unit_test(test_mat_rows_limit),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
