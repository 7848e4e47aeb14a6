/* What every figure writer of beamsim plot uses (figures_toolkit.c).
 *
 * A writer makes the data files of a figure with bsim_figs_data_open /
 * bsim_figs_data_commit and its gnuplot commands in a gp_text, then hands both
 * to bsim_figs_render, which writes NAME.gp and has gnuplot draw NAME.png and
 * NAME.svg (util/figure.h). Every file goes through these two calls, so a
 * different way of committing files changes them alone. The toolkit calls
 * no figure writer: the writers call it, and the dispatcher (figures.c)
 * calls the writers. */
#ifndef BSIM_FIGURES_FIGURES_TOOLKIT_H
#define BSIM_FIGURES_FIGURES_TOOLKIT_H

#include <stdio.h>

#include "beamsim/figures.h"
#include "util/atomic_file.h"
#include "beamsim/limits.h"

/* Colours that stay apart for colour-blind readers (Okabe & Ito) and in
 * grey print, as gnuplot colour specs. */
#define FIG_BLUE   "#0072B2"
#define FIG_RED    "#D55E00"
#define FIG_GREEN  "#009E73"
#define FIG_ORANGE "#E69F00"
#define FIG_SKY    "#56B4E9"
#define FIG_PURPLE "#CC79A7"
#define FIG_YELLOW "#F0E442"
#define FIG_BLACK  "#000000"
#define FIG_GREY   "#9A9A9A"
#define FIG_DKGREY "#5A5A5A"

/* Of the figures gnuplot failed on (res->failed), the first by name,
 * whatever the order they were drawn in: bsim_figures_draw's error. */
typedef struct figs_failure {
	bsim_error err;
	char name[128];
} figs_failure;

typedef struct figs {
	const char *out; /* where the figures go */
	const bsim_figures_def *def;
	bsim_figures_result *res;
	int threads;
	figs_failure *failure; /* shared by the copies of f made for a subdirectory */
} figs;

/* Files. */

/* Opens OUT/file for writing; path (BSIM_PATH_MAX bytes) gets its name. */
int bsim_figs_data_open(const figs *f, const char *file, bsim_atomic_file *o, char *path,
                        bsim_error *err);
int bsim_figs_data_commit(bsim_atomic_file *o, bsim_error *err);

/* Writes OUT/NAME.gp around body and draws it (width x height pixels);
 * records the figure. A figure gnuplot fails on is counted (res->failed,
 * f->failure) and BSIM_OK returned, so the writers draw the others and
 * bsim_figures_draw reports it at the end. Safe to call from several
 * threads. */
int bsim_figs_render(figs *f, const char *name, int width, int height, const char *body,
                     bsim_error *err);

/* Draws group g's figures of job; BSIM_OK also for a group with nothing
 * to draw. */
typedef int (*figs_group_fn)(figs *f, void *job, int g, bsim_error *err);

/* draw for every group, as many at a time as f's threads (each is mostly
 * gnuplot's drawing). The error kept is the lowest group's, whatever the
 * thread count. */
int bsim_figs_each_group(figs *f, int n_groups, figs_group_fn draw, void *job, bsim_error *err);

/* Records a line about what was not drawn and why. */
void bsim_figs_note(figs *f, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* Scripts. */

/* A growing text: fprintf to t.f, then bsim_gp_text_take for the string. */
typedef struct gp_text {
	FILE *f;
	char *buf;
	size_t len;
} gp_text;

int bsim_gp_text_open(gp_text *t, bsim_error *err);
/* The text (malloc'd, caller frees); the stream is closed. */
char *bsim_gp_text_take(gp_text *t);

/* s as a gnuplot string expression: single-quoted, a quote doubled, a
 * newline joined in as "\n". Used
 * with `noenhanced` wherever the text is a key or value, so that "_" and
 * "^" stay characters. */
void bsim_gp_str(FILE *f, const char *s);

/* Display names of scene keys (beamsim/key_names.h). */

/* The axis label of a scene key ("propulsive force F_{prop} (N)"), quoted
 * and followed by " enhanced": written after "set xlabel ". */
void bsim_gp_key_label(FILE *f, const char *key);
/* "F_prop = 8 N", plain text for a title or key drawn noenhanced. */
void bsim_figs_key_value(const char *key, const char *value, char *buf, size_t size);

#endif
