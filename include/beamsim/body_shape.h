/* A body's outline against a beam's segment: the gap the contact flag
 * (beamsim/contact_flag.h) is measured by for a capsule or an ellipse, and
 * the overlap the runner refuses at a scene's start. A backend whose body is
 * not a disk reports, for beam i at the step's end,
 *   contact[i] = pushed_i || c.dist < BSIM_CONTACT_TOL ? type : NONE,
 * type TIP if c.at_end else TANGENT, with c from bsim_body_shape_segment on
 * the segment from the beam's pivot to its tip. For a disk the gap is
 * |C - Q| - R, bsim_beam_distance less the radius (docs/model.md section
 * 3). The body is its shape (bsim_body_def, beamsim/scene.h) at centre x
 * (m) with heading psi (rad, the state's body angle). */
#ifndef BSIM_BODY_SHAPE_H
#define BSIM_BODY_SHAPE_H

#include "beamsim/base.h"
#include "beamsim/error.h"
#include "beamsim/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct bsim_body_segment_contact {
	double dist;          /* m, outline to segment; < 0: overlap, its depth along n */
	double n[2];          /* unit normal from the segment toward the body */
	double on_body[2];    /* m, the outline's point nearest the segment (deepest in overlap) */
	double on_segment[2]; /* m, the segment's point nearest the body */
	int at_end;           /* 1: on_segment is an end of the segment, 0: inside it */
} bsim_body_segment_contact;

/* The body against the segment p0-p1 (p0 != p1): BSIM_OK, or BSIM_EFAIL if
 * no separating normal exists (the segment passes through the body's
 * centre line), out then undefined. */
BSIM_API int bsim_body_shape_segment(const bsim_body_def *b, const double x[2], double psi,
                                     const double p0[2], const double p1[2],
                                     bsim_body_segment_contact *out);

/* The largest distance from the centre to the outline, m. */
BSIM_API double bsim_body_shape_reach(const bsim_body_def *b);

/* An ellipse with semi-axes a (along psi) and c (m) against the segment;
 * the same contract as bsim_body_shape_segment, which calls it for
 * BSIM_SHAPE_ELLIPSE. */
BSIM_API int bsim_body_shape_ellipse_segment(double a, double c, const double x[2], double psi,
                                             const double p0[2], const double p1[2],
                                             bsim_body_segment_contact *out);

#ifdef __cplusplus
}
#endif
#endif
