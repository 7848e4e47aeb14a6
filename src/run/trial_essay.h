/* Internal: the essay's lattice protocol for the runner (trial.c). */
#ifndef BSIM_RUN_TRIAL_ESSAY_H
#define BSIM_RUN_TRIAL_ESSAY_H

#include "beamsim/backend.h"
#include "beamsim/scene.h"

/* The world of the active gate: a copy of the lattice scene holding only
 * that gate's two beams. map[i] is world beam i's index in the lattice. */
typedef struct trial_essay {
	bsim_scene scene;
	bsim_beam_def beams[2];
	int map[2];
} trial_essay;

/* The world of gate (ix, iy) at the start of a trial: the lattice scene's
 * body, the gate's beams. */
int bsim_trial_essay_start(trial_essay *te, const bsim_scene *lattice, const bsim_backend *b,
                           const bsim_options *opts, int ix, int iy, bsim_world **w, int *overlaps,
                           bsim_error *err);

/* Replaces *w by the world of gate (ix, iy): its beams at rest, the body's
 * position and velocity those of s. Counts in *overlaps an entry whose
 * beams at rest overlap the body. */
int bsim_trial_essay_enter(trial_essay *te, const bsim_scene *lattice, const bsim_backend *b,
                           const bsim_options *opts, int ix, int iy, const bsim_state *s,
                           bsim_world **w, int *overlaps, bsim_error *err);

/* Destroys *w if any. */
void bsim_trial_essay_release(trial_essay *te, const bsim_backend *b, bsim_world **w);

#endif
