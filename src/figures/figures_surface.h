/* A landscape's 3-D surface as polygons that follow its steps
 * (figures_surface.c): what `beamsim landscape` (landscape_total,
 * landscape_beam) and the paths over the landscape (landscape_path,
 * landscape_gNNN, panel b) draw in 3-D. */
#ifndef BSIM_FIGURES_FIGURES_SURFACE_H
#define BSIM_FIGURES_FIGURES_SURFACE_H

#include <stdio.h>

#include "beamsim/error.h"
#include "beamsim/scene.h"

typedef struct fsurface {
	double region[4]; /* x0, x1, y0, y1 (m): the plane drawn */
	double cap;       /* J: the surface is drawn where E <= cap */
	double e_min;     /* J: the lowest E drawn; cap - e_min scales the tolerance */
	int beam_only;    /* 1: E_beam, the springs alone; 0: E_total */
	int max_polygons; /* the most polygons written (each about 100 bytes of SVG) */
} fsurface;

/* Writes the surface E(x, y) of scene s over d's region to f as gnuplot pm3d
 * quadrangles (two scans of two points each, then a scan of NaN that keeps
 * pm3d from joining one to the next): `splot FILE with pm3d` draws it,
 * depth sorted with `set pm3d depthorder`. The polygons follow the landscape's steps (the rim of
 * each beam's reach, the line behind a pivot), the pivots and the cap, so that the surface ends
 * along those curves, not on a staircase of grid cells, and are finer where the surface bends.
 * *polygons (may be NULL) gets their count, 0 when no point of the region lies at or below the cap.
 */
int bsim_fsurface_write(FILE *f, const bsim_scene *s, const fsurface *d, long *polygons,
                        bsim_error *err);

#endif
