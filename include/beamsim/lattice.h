/* Gate lattices (MODEL.md section 8, essay Sec. 2.6): the gates' geometry,
 * which gate a point lies in, and where a trial ended.
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
#include "beamsim/trial.h"

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

/* The essay's lattice (MODEL.md section 8) built in code: columns x rows
 * gates (columns odd, centred on ix = 0) of the Table 2.1 gate, k = 400,
 * with the lattice's termination defaults and the given propulsion and
 * random force (0 = absent). The body starts at (0, 0). */
BSIM_API int bsim_lattice_scene_init(bsim_scene *s, int columns, int rows, double f_prop,
                                     double rm);

/* Where a trial ended (MODEL.md section 8): through the end boundary in
 * column ix, out through a side at row iy, or stuck in gate (ix, iy). */
typedef enum bsim_location_kind {
	BSIM_LOCATION_END = 0,
	BSIM_LOCATION_SIDE = 1,
	BSIM_LOCATION_STUCK = 2,
} bsim_location_kind;

typedef struct bsim_location {
	bsim_location_kind kind;
	int ix, iy; /* END: ix (iy = 0); SIDE: iy (ix = 0); STUCK: both */
} bsim_location;

BSIM_API bsim_location bsim_lattice_location_of(const bsim_trial_result *r);
/* 1 if a and b are the same location. */
BSIM_API int bsim_lattice_location_equal(bsim_location a, bsim_location b);
/* "end:-2", "side:3", "stuck:0:2"; the labels of trials.csv, summary.json
 * and the final-location CSV. */
BSIM_API void bsim_lattice_location_label(bsim_location loc, char *buf, size_t size);

/* ---- a group of lattice trials ------------------------------------------ */

typedef struct bsim_location_count {
	bsim_location loc;
	int count;
	double p, ci95[2]; /* count / trials, Wilson 95% */
} bsim_location_count;

typedef struct bsim_transition {
	int from[2], to[2]; /* gates (ix, iy): one entry of the path to the next */
	int count;
} bsim_transition;

typedef struct bsim_lattice_summary {
	int trials;
	int n_locations;                /* distinct final locations, ends by ix, sides by iy, */
	bsim_location_count *locations; /* then stuck gates by (iy, ix) */
	int n_transitions;              /* distinct gate-to-gate steps, by from */
	bsim_transition *transitions;   /* then to, (iy, ix) order */
	int rows;
	int *row_trials;  /* per row iy: trials whose path entered it */
	double *row_time; /* per row: their mean time spent in it, s */
} bsim_lattice_summary;

/* Summarises n trials of one group (logs: their gate paths, may be NULL:
 * no transitions or row times) of a lattice of `rows` rows. */
BSIM_API int bsim_lattice_summarise(const bsim_trial_result *trials, const bsim_trial_log *logs,
                                    int n, int rows, bsim_lattice_summary *out);
BSIM_API void bsim_lattice_summary_free(bsim_lattice_summary *s);

/* Time the trial spent in each row, s: row_time[iy] for iy < rows, from
 * the log's entries (a row not entered gets 0). */
BSIM_API void bsim_lattice_row_times(const bsim_trial_result *r, const bsim_trial_log *log,
                                     int rows, double *row_time);

#ifdef __cplusplus
}
#endif
#endif
