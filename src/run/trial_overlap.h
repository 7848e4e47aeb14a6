/* Internal: how deep the body overlaps the beams (bsim_recorder.overlap,
 * the trial's overlap_max), from the beams' shapes taken once per world. */
#ifndef BSIM_RUN_TRIAL_OVERLAP_H
#define BSIM_RUN_TRIAL_OVERLAP_H

#include "beamsim/scene.h"
#include "beamsim/state.h"

/* A beam as the overlap measure sees it: pivot, rest direction, forward
 * sign, length and the square of the reach L + R within which the body can
 * touch it. */
typedef struct beam_shape {
	double p[2], u0[2], sgn, length, reach2;
} beam_shape;

/* The shapes of sc's beams, shape[sc->n_beams]. */
void bsim_trial_overlap_shapes(beam_shape *shape, const bsim_scene *sc);

/* How deep the body of radius R overlaps the n beams at s, m (0 if it
 * does not). */
double bsim_trial_overlap_depth(const beam_shape *shape, int n, double radius, const bsim_state *s);

#endif
