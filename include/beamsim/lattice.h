/* Gate lattices (docs/model.md section 8, essay Sec. 2.6): the gates' geometry
 * and which gate a point lies in. Where a trial ended and a group's
 * summary: beamsim/lattice_outcome.h.
 *
 * Gate (ix, iy) spans X in [w ix - w/2, w ix + w/2), Y in [d iy, d (iy + 1))
 * with w = width, d = depth: a point's gate is
 *   ix = floor((X + w/2) / w),   iy = floor(Y / d)
 * and its position in the gate's own frame is Eq. 2.17 read backwards,
 *   x = X - w ix,   y = Y - d iy.
 * A scene without a lattice is one gate, (0, 0), covering the plane. */
#ifndef BSIM_LATTICE_H
#define BSIM_LATTICE_H

#include <stddef.h>

#include "beamsim/base.h"
#include "beamsim/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

enum { BSIM_SIDE_LEFT = 0, BSIM_SIDE_RIGHT = 1 };

/* Index in scene->beams of the left (side 0) or right (side 1) beam of
 * gate (ix, iy); -1 outside the lattice. */
BSIM_API int bsim_lattice_beam(const bsim_lattice_def *l, int ix, int iy, int side);
/* The gate and side of beam index i (the inverse of bsim_lattice_beam). */
BSIM_API void bsim_lattice_beam_gate(const bsim_lattice_def *l, int i, int *ix, int *iy, int *side);

/* The gate holding point p, clamped into the lattice (a body below row 0
 * is in row 0, one beyond the last column in the last column); (0, 0)
 * for a scene without a lattice. */
BSIM_API void bsim_lattice_gate_at(const bsim_scene *s, const double p[2], int *ix, int *iy);

/* The field's centre line X = w (ix_min + ix_max) / 2, from which side_x
 * is measured; 0 for a scene without a lattice. */
BSIM_API double bsim_lattice_centre_x(const bsim_scene *s);

/* Builds s->beams from s->lattice: every beam gets lattice.beam, then its
 * stiffness from k_left / k_right (rows x columns, row iy = 0 first, NULL:
 * lattice.beam.stiffness). Sets has_lattice and columns from ix_min/max. */
BSIM_API int bsim_lattice_build(bsim_scene *s, const double *k_left, const double *k_right);

/* The essay's lattice (docs/model.md section 8) built in code: columns x rows
 * gates (columns odd, centred on ix = 0) of the Table 2.1 gate, k = 400,
 * with the lattice's termination defaults and the given propulsion and
 * random force (0 = absent). The body starts at (0, 0). */
BSIM_API int bsim_lattice_scene_init(bsim_scene *s, int columns, int rows, double f_prop,
                                     double rm);

#ifdef __cplusplus
}
#endif
#endif
