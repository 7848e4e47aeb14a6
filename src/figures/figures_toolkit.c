/* The figure writers' toolkit (figures_toolkit.h): data files, gnuplot
 * scripts and their rendering, notes, and the parallel loop over groups. */
#define _POSIX_C_SOURCE 200809L
#include "figures/figures_toolkit.h"

#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/key_names.h"
#include "util/figure.h"
#include "beamsim/limits.h"

int bsim_figs_data_open(const figs *f, const char *file, bsim_atomic_file *o, char *path,
                        bsim_error *err)
{
	if (snprintf(path, BSIM_PATH_MAX, "%s/%s", f->out, file) >= BSIM_PATH_MAX)
		return bsim_error_set(err, BSIM_EFAIL, "%s/%s: path too long", f->out, file);
	return bsim_atomic_file_open(o, path, err);
}

int bsim_figs_data_commit(bsim_atomic_file *o, bsim_error *err)
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

int bsim_figs_render(figs *f, const char *name, int width, int height, const char *body,
                     bsim_error *err)
{
	bsim_figure_def d = bsim_figure_def_default();
	d.dir = f->out;
	d.name = name;
	d.width = width;
	d.height = height;
	int drawn = 0;
	bsim_error e1;
	int rc = bsim_figure_render(&d, body, &drawn, &e1);
	if (rc && drawn == BSIM_FIGURE_FAILED) {
#pragma omp critical(bsim_figures_list)
		{
			if (f->res->failed++ == 0 || strcmp(name, f->failure->name) < 0) {
				f->failure->err = e1;
				snprintf(f->failure->name, sizeof f->failure->name, "%s", name);
			}
		}
		return BSIM_OK;
	}
	if (rc) {
		if (err)
			*err = e1;
		return rc;
	}
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

void bsim_figs_note(figs *f, const char *fmt, ...)
{
	char buf[512];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(buf, sizeof buf, fmt, ap);
	va_end(ap);
#pragma omp critical(bsim_figures_list)
	list_add(&f->res->notes, &f->res->n_notes, strdup(buf));
}

int bsim_figs_each_group(figs *f, int n_groups, figs_group_fn draw, void *job, bsim_error *err)
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

int bsim_gp_text_open(gp_text *t, bsim_error *err)
{
	t->buf = NULL;
	t->len = 0;
	t->f = open_memstream(&t->buf, &t->len);
	return t->f ? BSIM_OK : bsim_error_set(err, BSIM_EFAIL, "out of memory for a script");
}

char *bsim_gp_text_take(gp_text *t)
{
	if (t->f)
		fclose(t->f);
	t->f = NULL;
	return t->buf;
}

void bsim_gp_str(FILE *f, const char *s)
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

void bsim_gp_key_label(FILE *f, const char *key)
{
	char buf[400];
	bsim_key_label(key, 1, buf, sizeof buf);
	bsim_gp_str(f, buf);
	fputs(" enhanced", f);
}

void bsim_figs_key_value(const char *key, const char *value, char *buf, size_t size)
{
	bsim_key_value(key, value, 0, buf, size);
}
