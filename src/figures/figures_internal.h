/* Internal: what the figure writers of beamsim plot share (figures.h).
 *
 * A writer makes the data files of a figure with figs_data_open /
 * figs_data_commit and its gnuplot commands in a gp_text, then hands both
 * to figs_render, which writes NAME.gp and has gnuplot draw NAME.png and
 * NAME.svg (figure.h). Every file goes through these two calls, so a
 * different way of committing files changes them alone. */
#ifndef BSIM_FIGURES_FIGURES_INTERNAL_H
#define BSIM_FIGURES_FIGURES_INTERNAL_H

#include <stdio.h>

#include "util/atomic_file.h"
#include "beamsim/figures.h"
#include "beamsim/scene.h"
#include "util/csv_table.h"

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

typedef struct figs {
	const char *out; /* where the figures go */
	const bsim_figures_def *def;
	bsim_figures_result *res;
	int threads;
} figs;

/* ---- files ---------------------------------------------------------------- */

/* Opens OUT/file for writing; path (size >= 1100) gets its name. */
int figs_data_open(const figs *f, const char *file, bsim_atomic_file *o, char *path,
                   bsim_error *err);
int figs_data_commit(bsim_atomic_file *o, bsim_error *err);

/* Writes OUT/NAME.gp around body and draws it (width x height pixels);
 * records the figure. Safe to call from several threads. */
int figs_render(figs *f, const char *name, int width, int height, const char *body,
                bsim_error *err);

/* Draws group g's figures of job; BSIM_OK also for a group with nothing
 * to draw. */
typedef int (*figs_group_fn)(figs *f, void *job, int g, bsim_error *err);

/* draw for every group, as many at a time as f's threads (each is mostly
 * gnuplot's drawing). The error kept is the lowest group's, whatever the
 * thread count. */
int figs_each_group(figs *f, int n_groups, figs_group_fn draw, void *job, bsim_error *err);

/* Records a line about what was not drawn and why. */
void figs_note(figs *f, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* ---- scripts -------------------------------------------------------------- */

/* A growing text: fprintf to t.f, then gp_text_take for the string. */
typedef struct gp_text {
	FILE *f;
	char *buf;
	size_t len;
} gp_text;

int gp_text_open(gp_text *t, bsim_error *err);
/* The text (malloc'd, caller frees); the stream is closed. */
char *gp_text_take(gp_text *t);

/* s as a gnuplot string expression: single-quoted, a quote doubled, a
 * newline joined in as "\n". Used
 * with `noenhanced` wherever the text is a key or value, so that "_" and
 * "^" stay characters. */
void gp_str(FILE *f, const char *s);

/* ---- a sweep's summary.json -------------------------------------------------- */

typedef struct fsum_group {
	int *idx; /* value index per axis */
	int trials, traversed, side_exit, stuck, left, right;
	int land_left, land_right; /* traversed, by the larger peak angle */
	double p, lo, hi;          /* p_traverse and its Wilson 95% interval */
	int selected;              /* matches every KEY=VALUE of the selection */
} fsum_group;

typedef struct fsum_axis {
	char *key;
	int n_values;
	char **values; /* text as in summary.json, in order of first appearance */
	int numeric;   /* every value a number */
	double *x;     /* the numbers, when numeric */
} fsum_axis;

typedef struct fsum {
	char backend[64];
	int trials_per_group;
	int n_axes;
	fsum_axis *axes; /* in the order of the groups' params: the first slowest */
	int n_groups;
	fsum_group *g;
} fsum;

/* Reads path (a summary.json). BSIM_EINPUT naming file and field. */
int fsum_read(const char *path, fsum *s, bsim_error *err);
void fsum_free(fsum *s);
/* Marks the groups matching the selection of f->def; BSIM_EINPUT if a key
 * is no axis or a value matches no group. */
int fsum_select(const figs *f, fsum *s, bsim_error *err);
/* "key = value, key = value" of group g over the axes, into buf, two to
 * a line. */
void fsum_label(const fsum *s, int g, char *buf, size_t size);
/* 1 if two value texts name the same value (numerically where both are
 * numbers). */
int fsum_same_value(const char *a, const char *b);

/* ---- trajectories (figures_paths.c) ------------------------------------------ */

/* Classes of a trial, in drawing order (failures first, under the rest). */
enum {
	FPATH_OTHER = 0, /* an outcome this reader does not know */
	FPATH_STUCK,
	FPATH_SIDE_EXIT,
	FPATH_NONE, /* traversed, v_x = 0 at classify_y */
	FPATH_RIGHT,
	FPATH_LEFT,
	FPATH_N
};

/* The class of an outcome and type as trials.csv spells them. */
int fpath_class(const char *outcome, const char *type);

typedef struct fpath {
	int group, trial, cls;
	long n;
	const double *t, *x, *y; /* n each: s, m, m */
	const double *theta;     /* n * n_beams, row-major, rad */
} fpath;

/* E of a recorded state: F_prop (y0 - y) + sum 1/2 k_i theta_i^2, J. */
double fpath_energy(const bsim_scene *s, double y, const double *theta);

/* 1 if the state at (x, y) with these beam angles lies below the
 * landscape's surface: its beams' energy short of the landscape's by more
 * than FPATH_BELOW_J (a beam detached, essay Fig. 2.7). */
#define FPATH_BELOW_J 1.0
int fpath_below(const bsim_scene *s, double x, double y, const double *theta);

/* Fig. 3.2: the bundle in the plane, coloured by class, with the beams at
 * rest and the boundaries. */
int figs_bundle(figs *f, const char *name, const char *title, const bsim_scene *scene,
                const fpath *p, int n, bsim_error *err);

/* Figs. 3.3 and 2.7: the landscape E_total(x, y) of scene seen from above
 * and in 3-D, with the paths over it at their own E, the stretches below
 * the surface in black. Draws the paths whose class is in mask (bits
 * 1 << FPATH_*). */
int figs_over_landscape(figs *f, const char *name, const char *title, const bsim_scene *scene,
                        const fpath *p, int n, unsigned mask, bsim_error *err);

/* The paths of a trajectory table (trajectories.csv, or one trajectory
 * with group = trial = 0 when the table has no group column): the rows of
 * each (group, trial) in order. Allocates *paths (free with fpaths_free);
 * classes are FPATH_OTHER until the caller sets them. */
typedef struct fpaths {
	int n_beams;
	int n;
	fpath *p;
	double *cols; /* the numbers the paths point into */
} fpaths;

int fpaths_read(const csv_table *t, const char *path, fpaths *out, bsim_error *err);
void fpaths_free(fpaths *p);

/* ---- the kinds ------------------------------------------------------------------ */

/* inputs: the directory holding experiment.yaml and scene.yaml of the run
 * (DIR/inputs, or the comparison's for one of its backends). */
int figs_sweep(figs *f, const char *dir, const char *inputs, bsim_error *err);
int figs_compare(figs *f, const char *dir, bsim_error *err);
int figs_run(figs *f, const char *dir, bsim_error *err);
int figs_accuracy(figs *f, const char *dir, bsim_error *err);

/* ---- a gate lattice (figures_lattice.c) ----------------------------------------------- */

/* 1 if dir holds a lattice run (lattice_map.csv beside trials.csv). */
int figs_is_lattice(const char *dir);

/* A lattice sweep's own figures per selected group: final_locations_gNNN
 * (where the trials ended, laid out as the field) and lattice_gNNN (the
 * essay's Fig. 3.5: the stiffness map and the kept trajectories over it),
 * drawn instead of the single gate's trajectory and landscape figures.
 * figs_lattice_load reads and checks every input (lattice_map.csv,
 * trials.csv, the stored experiment, trajectories.csv) before any figure
 * is drawn; s must outlive the job. */
typedef struct lat_job lat_job;
int figs_lattice_load(figs *f, const char *dir, const char *inputs, const fsum *s, lat_job **out,
                      bsim_error *err);
int figs_lattice_draw(figs *f, lat_job *j, bsim_error *err);
void figs_lattice_free(lat_job *j);

/* final_locations_gNNN of a comparison: both sides' final locations side
 * by side on the same scales; dirs are the sides' sweep directories, s the
 * groups (with the selection), tests[g] a line on the group's test. */
int figs_lattice_compare(figs *f, const char *const dirs[2], const char *const labels[2],
                         const fsum *s, const char *const *tests, bsim_error *err);

#endif
