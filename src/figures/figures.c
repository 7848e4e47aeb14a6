/* beamsim plot: what a directory holds, and the helpers every figure
 * writer shares (figures.h, figures_internal.h). */
#define _POSIX_C_SOURCE 200809L
#include "beamsim/figures.h"

#include <omp.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "beamsim/output.h"
#include "util/figure.h"
#include "figures/figures_internal.h"

const char *bsim_figures_kind_name(bsim_figures_kind k)
{
	static const char *names[] = {"auto", "sweep", "compare", "run", "accuracy"};
	return (unsigned)k < 5 ? names[k] : "?";
}

bsim_figures_def bsim_figures_default(void)
{
	bsim_figures_def d = {.kind = BSIM_FIGURES_AUTO};
	return d;
}

void bsim_figures_result_free(bsim_figures_result *r)
{
	for (int i = 0; i < r->n; i++)
		free(r->paths[i]);
	for (int i = 0; i < r->n_notes; i++)
		free(r->notes[i]);
	free(r->paths);
	free(r->notes);
	memset(r, 0, sizeof *r);
}

/* ---- files and rendering ------------------------------------------------------ */

int figs_data_open(const figs *f, const char *file, bsim_atomic_file *o, char *path,
                   bsim_error *err)
{
	if (snprintf(path, 1100, "%s/%s", f->out, file) >= 1100)
		return bsim_error_set(err, BSIM_EFAIL, "%s/%s: path too long", f->out, file);
	return bsim_atomic_file_open(o, path, err);
}

int figs_data_commit(bsim_atomic_file *o, bsim_error *err)
{
	return bsim_atomic_file_commit(o, err);
}

/* Appends s (copied) to a list under the figures' lock. */
static void list_add(char ***list, int *n, char *s)
{
	if (!s)
		return;
	char **l = realloc(*list, (size_t)(*n + 1) * sizeof *l);
	if (!l) {
		free(s);
		return;
	}
	l[(*n)++] = s;
	*list = l;
}

int figs_render(figs *f, const char *name, int width, int height, const char *body, bsim_error *err)
{
	bsim_figure_def d = bsim_figure_default();
	d.dir = f->out;
	d.name = name;
	d.width = width;
	d.height = height;
	int drawn = 0;
	int rc = bsim_figure_render(&d, body, &drawn, err);
	if (rc)
		return rc;
	size_t len = strlen(f->out) + strlen(name) + 2;
	char *path = malloc(len);
	if (path)
		snprintf(path, len, "%s/%s", f->out, name);
#pragma omp critical(bsim_figures_list)
	{
		list_add(&f->res->paths, &f->res->n, path);
		f->res->drawn += drawn;
	}
	return BSIM_OK;
}

void figs_note(figs *f, const char *fmt, ...)
{
	char buf[512];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(buf, sizeof buf, fmt, ap);
	va_end(ap);
#pragma omp critical(bsim_figures_list)
	list_add(&f->res->notes, &f->res->n_notes, strdup(buf));
}

int figs_each_group(figs *f, int n_groups, figs_group_fn draw, void *job, bsim_error *err)
{
	int failed = n_groups;
	bsim_error first_err;
	bsim_error_clear(&first_err);
#pragma omp parallel for schedule(dynamic) num_threads(f->threads)
	for (int g = 0; g < n_groups; g++) {
		bsim_error e1;
		if (draw(f, job, g, &e1) == BSIM_OK)
			continue;
#pragma omp critical(bsim_figures_fail)
		if (g < failed) {
			failed = g;
			first_err = e1;
		}
	}
	if (failed < n_groups)
		return bsim_error_set(err, first_err.code, "%s", first_err.msg);
	return BSIM_OK;
}

int gp_text_open(gp_text *t, bsim_error *err)
{
	t->buf = NULL;
	t->len = 0;
	t->f = open_memstream(&t->buf, &t->len);
	return t->f ? BSIM_OK : bsim_error_set(err, BSIM_EFAIL, "out of memory for a script");
}

char *gp_text_take(gp_text *t)
{
	if (t->f)
		fclose(t->f);
	t->f = NULL;
	return t->buf;
}

void gp_str(FILE *f, const char *s)
{
	fputc('\'', f);
	for (; *s; s++) {
		if (*s == '\'')
			fputc('\'', f);
		if (*s == '\n')
			fputs("'.\"\\n\".'", f); /* single quotes know no escapes */
		else if (*s != '\r')
			fputc(*s, f);
	}
	fputc('\'', f);
}

/* ---- what a directory holds ------------------------------------------------------- */

static int has(const char *dir, const char *file)
{
	char path[1200];
	struct stat st;
	snprintf(path, sizeof path, "%s/%s", dir, file);
	return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

static bsim_figures_kind recognise(const char *dir)
{
	if (has(dir, "report.json") && has(dir, "pairs.csv"))
		return BSIM_FIGURES_COMPARE;
	if (has(dir, "summary.json") && has(dir, "trials.csv"))
		return BSIM_FIGURES_SWEEP;
	if (has(dir, "trajectory.csv") && has(dir, "ledger.csv"))
		return BSIM_FIGURES_RUN;
	if (has(dir, "accuracy.csv"))
		return BSIM_FIGURES_ACCURACY;
	return BSIM_FIGURES_AUTO;
}

int bsim_figures_draw(const char *dir, const bsim_figures_def *def, bsim_figures_result *out,
                      bsim_error *err)
{
	memset(out, 0, sizeof *out);
	bsim_figures_def d = def ? *def : bsim_figures_default();
	if (strlen(dir) > 900 || (d.out && strlen(d.out) > 900))
		return bsim_error_set(err, BSIM_EINPUT, "%s: path too long", dir);
	struct stat st;
	if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode))
		return bsim_error_set(err, BSIM_EINPUT, "%s: no such directory", dir);
	bsim_figures_kind kind = d.kind ? d.kind : recognise(dir);
	if (kind == BSIM_FIGURES_AUTO)
		return bsim_error_set(
		        err, BSIM_EINPUT,
		        "%s: no output of beamsim found (expected summary.json and "
		        "trials.csv of a sweep, report.json and pairs.csv of compare, "
		        "trajectory.csv and ledger.csv of run --out, or accuracy.csv)",
		        dir);
	figs f = {
	        .out = d.out ? d.out : dir,
	        .def = &d,
	        .res = out,
	        .threads = d.threads > 0 ? d.threads : omp_get_max_threads(),
	};
	out->kind = kind;
	int rc = bsim_output_mkdir(f.out, err);
	if (rc)
		return rc;
	char inputs[1100];
	snprintf(inputs, sizeof inputs, "%s/inputs", dir);
	switch (kind) {
	case BSIM_FIGURES_SWEEP:
		rc = figs_sweep(&f, dir, inputs, err);
		break;
	case BSIM_FIGURES_COMPARE:
		rc = figs_compare(&f, dir, err);
		break;
	case BSIM_FIGURES_RUN:
		rc = figs_run(&f, dir, err);
		break;
	case BSIM_FIGURES_ACCURACY:
		rc = figs_accuracy(&f, dir, err);
		break;
	default:
		break;
	}
	if (rc == BSIM_OK && out->n > 0 && out->drawn < out->n)
		figs_note(&f, "%s", bsim_figure_missing_hint());
	return rc;
}
