/* Trajectories as the figures read and draw them (figures_paths.c). */
#ifndef BSIM_FIGURES_FIGURES_PATHS_H
#define BSIM_FIGURES_FIGURES_PATHS_H

#include "beamsim/scene.h"
#include "figures/figures_toolkit.h"
#include "util/csv_table.h"

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
int bsim_fpath_class(const char *outcome, const char *type);

typedef struct fpath {
	int group, trial, cls;
	long n;
	const double *t, *x, *y; /* n each: s, m, m */
	const double *theta;     /* n * n_beams, row-major, rad */
} fpath;

/* E of a recorded state: F_prop (y0 - y) + sum 1/2 k_i theta_i^2, J. */
double bsim_fpath_energy(const bsim_scene *s, double y, const double *theta);

/* 1 if the state at (x, y) with these beam angles lies below the
 * landscape's surface: its beams' energy short of the landscape's by more
 * than FPATH_BELOW_J (a beam detached, essay Fig. 2.7). */
#define FPATH_BELOW_J 1.0
int bsim_fpath_below(const bsim_scene *s, double x, double y, const double *theta);

/* Fig. 3.2: the bundle in the plane, coloured by class, with the beams at
 * rest and the boundaries. */
int bsim_figs_bundle(figs *f, const char *name, const char *title, const bsim_scene *scene,
                     const fpath *p, int n, bsim_error *err);

/* Figs. 3.3 and 2.7: the landscape E_total(x, y) of scene seen from above
 * and in 3-D, with the paths over it at their own E, the stretches below
 * the surface in black. Draws the paths whose class is in mask (bits
 * 1 << FPATH_*). */
int bsim_figs_over_landscape(figs *f, const char *name, const char *title, const bsim_scene *scene,
                             const fpath *p, int n, unsigned mask, bsim_error *err);

/* The backend and the parameters of a figure's scene that differ from
 * its scene file's, for a title: "backend NAME, F_prop = 8 N, R_m = 30 N,
 * k_1 = 300 N m/rad" (beamsim/key_names.h), a line break after every third
 * item; backend may be NULL or "". */
void bsim_fpath_params(char *buf, size_t size, const char *backend, const char *const *keys,
                       const char *const *values, int n);

/* The paths of a trajectory table (trajectories.csv, or one trajectory
 * with group = trial = 0 when the table has no group column): the rows of
 * each (group, trial) in order. Allocates *paths (free with bsim_fpaths_free);
 * classes are FPATH_OTHER until the caller sets them. */
typedef struct fpaths {
	int n_beams;
	int n;
	fpath *p;
	double *cols; /* the numbers the paths point into */
} fpaths;

int bsim_fpaths_read(const csv_table *t, const char *path, fpaths *out, bsim_error *err);
void bsim_fpaths_free(fpaths *p);

#endif
