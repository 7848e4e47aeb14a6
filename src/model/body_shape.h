/* Internal: the body's outline against a beam's segment, for the start's
 * overlap check (scene.c) and the thesis backend's contact detection. The
 * body is its shape (bsim_body_def) at centre x with heading psi (rad). */
#ifndef BSIM_MODEL_BODY_SHAPE_H
#define BSIM_MODEL_BODY_SHAPE_H

#include "beamsim/scene.h"

typedef struct body_segment_contact {
	double dist;          /* m, outline to segment; < 0: overlap, its depth along n */
	double n[2];          /* unit normal from the segment toward the body */
	double on_body[2];    /* m, the outline's point nearest the segment (deepest in overlap) */
	double on_segment[2]; /* m, the segment's point nearest the body */
	int at_end;           /* 1: on_segment is an end of the segment, 0: inside it */
} body_segment_contact;

/* The body against the segment p0-p1 (p0 != p1): BSIM_OK, or BSIM_EFAIL if
 * no separating normal exists (the segment passes through the body's
 * centre line), out then undefined. */
int body_shape_segment(const bsim_body_def *b, const double x[2], double psi, const double p0[2],
                       const double p1[2], body_segment_contact *out);

/* The largest distance from the centre to the outline, m. */
double body_shape_reach(const bsim_body_def *b);

/* An ellipse with semi-axes a (along psi) and c against the segment
 * (body_shape_ellipse.c); the same contract as body_shape_segment. */
int body_shape_ellipse_segment(double a, double c, const double x[2], double psi,
                               const double p0[2], const double p1[2], body_segment_contact *out);

#endif
