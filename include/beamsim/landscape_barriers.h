/* The passes of a potential energy landscape (beamsim/landscape.h) from
 * the start basin to the far side, and a landscape's files and figures:
 * the analysis over the sampled grid. */
#ifndef BSIM_LANDSCAPE_BARRIERS_H
#define BSIM_LANDSCAPE_BARRIERS_H

#include "beamsim/base.h"
#include "beamsim/landscape.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- Barriers (src/analysis/landscape_barrier.c) ---------------------- */

typedef enum {
	BSIM_PASS_NONE = 0,  /* no path leaves over this beam to the far side */
	BSIM_PASS_OPEN = 1,  /* the landscape falls from the start to the far side: no barrier */
	BSIM_PASS_SADDLE = 2 /* a barrier: the path's highest point, x, y, is the pass */
} bsim_pass_kind;

/* The lowest pass from the start basin to the far side, over any beam or
 * over one beam (the beam the path leaves the beams' reach over, as
 * bsim_landscape_label). */
typedef struct bsim_landscape_pass {
	bsim_pass_kind kind;
	int beam;                       /* the beam crossed, 0-based; -1 none or a tie */
	double x, y;                    /* m: the pass (SADDLE, refined), the exit (OPEN) */
	double e_total, e_beam, e_prop; /* J at (x, y) */
	double floor[2], floor_e;       /* m, J: the lowest point of the start basin */
	double height;                  /* J, e_total - floor_e: the barrier (0 when OPEN) */
	double above_start;             /* J, e_total - E_total(start) */
	double grid_x, grid_y, grid_e;  /* m, m, J: the pass on the grid, before refinement */
	double refine_spacing;          /* m, spacing of the finest refinement level */
	double refine_change;           /* J, change of e_total at the last level: its accuracy */
	int n_path;                     /* points of the path of least resistance */
	double *path;                   /* (x, y) pairs, m: start, basin floor, pass, far side */
} bsim_landscape_pass;

typedef struct bsim_landscape_barriers {
	double start[2], start_e;   /* m, J: the body's start (moved into the grid if outside) */
	double far_y;               /* m: the far side is y >= far_y beyond the beams' reach */
	bsim_landscape_pass lowest; /* over any beam */
	int n_beams;
	bsim_landscape_pass *beam; /* n_beams: the lowest pass leaving over beam b */
} bsim_landscape_barriers;

/* Finds the passes of the landscape g of scene s (see landscape_barrier.c
 * for the definitions and the method). BSIM_EINPUT if the grid has no far
 * side beyond the beams' reach; BSIM_EFAIL out of memory. */
BSIM_API int bsim_landscape_barriers_alloc(const bsim_scene *s, const bsim_landscape_grid *g,
                                           bsim_landscape_barriers **out, bsim_error *err);
BSIM_API void bsim_landscape_barriers_free(bsim_landscape_barriers *b);

BSIM_API const char *bsim_landscape_pass_kind_name(bsim_pass_kind k);

/* ---- Files (src/analysis/landscape_write.c, landscape_store.c) -------- */

/* Writes into the existing directory dir: landscape.csv (x, y, e_beam,
 * e_prop, e_total, theta1..thetaN, one row per grid point), landscape.mat
 * (the same columns, the grid's shape and the barrier table),
 * landscape.json (grid, start, passes) and the figures landscape_top
 * (heat map, contours, beams), landscape_beam and landscape_total (3-D
 * surfaces without and with the propulsive term), each .gp + data + .png +
 * .svg, the figures last. drawn (may be NULL) is 1 if gnuplot drew the
 * figures, 0 if gnuplot is missing, -1 if it failed on one: BSIM_EFAIL
 * naming it and quoting gnuplot, every other file written. */
BSIM_API int bsim_landscape_write(const char *dir, const bsim_scene *s,
                                  const bsim_landscape_grid *g, const bsim_landscape_barriers *b,
                                  int *drawn, bsim_error *err);

/* The landscape of s on the grid def, its barriers and files, computed and
 * written into the output directory out as one set (out is checked before
 * anything is computed; overwrite 1 replaces the result it holds, 0
 * refuses it). *g and *b get the grid and the barriers (free them
 * on BSIM_OK); BSIM_EINPUT for an unusable out or a bad grid, naming it.
 * A figure gnuplot fails on (drawn -1) is BSIM_EFAIL, and the files are
 * committed all the same, its script and data among them. */
BSIM_API int bsim_landscape_store(const char *out, int overwrite, const bsim_scene *s,
                                  const bsim_landscape_grid_def *def, bsim_landscape_grid **g,
                                  bsim_landscape_barriers **b, int *drawn, bsim_error *err);

#ifdef __cplusplus
}
#endif
#endif
