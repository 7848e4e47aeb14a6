/* A world stepped by hand: any backend's world of a scene, advanced a step
 * at a time by the caller, under a force of the caller's or under the
 * scene's own effects with the random-force schedule of a trial, its state
 * read after each call (docs/backends.md, "A world stepped by hand").
 *
 * With the scene's effects and the trial's mixed seed
 * (bsim_schedule_seed_mix(seed, group, trial)), n steps are the first n
 * steps of that trial as the runner makes them (bsim_trial_run): the same
 * forces, each from the state its step starts at, and the same states, to
 * the bit (test_stepper). The runner's bookkeeping (outcome, ledger,
 * peaks) is not kept: a stepped world stops where its caller stops. A
 * lattice under the essay's protocol is the whole lattice in one world
 * (the world protocol): the runner's replacement of the world at each gate
 * is not made.
 *
 *   bsim_stepper_def def = bsim_stepper_def_default();
 *   def.scene = &scene;
 *   def.seed = bsim_schedule_seed_mix(1, 0, 3);
 *   bsim_stepper *s;
 *   if (bsim_stepper_alloc(&def, &s, &err) == BSIM_OK) {
 *           bsim_stepper_step(s, 100, &err);
 *           printf("%g\n", bsim_stepper_state(s)->x[1]);
 *           bsim_stepper_free(s);
 *   } */
#ifndef BSIM_STEPPER_H
#define BSIM_STEPPER_H

#include <stdint.h>

#include "beamsim/base.h"
#include "beamsim/backend.h"
#include "beamsim/error.h"
#include "beamsim/options.h"
#include "beamsim/scene.h"
#include "beamsim/state.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct bsim_stepper bsim_stepper; /* opaque */

typedef struct bsim_stepper_def {
	const bsim_scene *scene;     /* copied: the caller's may go */
	const bsim_backend *backend; /* NULL: the default (bsim_backend_default) */
	const bsim_options *opts;    /* the backend's options; NULL: its defaults */
	uint64_t seed;               /* the effects' mixed seed: a trial's random-force schedule */
} bsim_stepper_def;

/* No scene, the default backend with its defaults, seed 1. */
BSIM_API bsim_stepper_def bsim_stepper_def_default(void);

/* The world of def->scene on def->backend at step 0, and the scene's
 * effects for def->seed. BSIM_EINPUT with the backend's message if it
 * refuses the scene or an option (as bsim_backend_check says it), BSIM_EFAIL
 * out of memory. */
BSIM_API int bsim_stepper_alloc(const bsim_stepper_def *def, bsim_stepper **out, bsim_error *err);
BSIM_API void bsim_stepper_free(bsim_stepper *s);

/* n >= 1 steps of the scene's dt under the scene's effects, each step's
 * force and torque from the state it starts at (bsim_effects_force_at).
 * BSIM_OK; BSIM_EFAIL with err if the backend fails or a state stops
 * being finite (the step named; the world is left at that state). */
BSIM_API int bsim_stepper_step(bsim_stepper *s, long n, bsim_error *err);

/* n >= 1 steps of the scene's dt under force (N, on the body's centre) and
 * torque (N m) held over them, in place of the scene's effects; errors as
 * bsim_stepper_step's. */
BSIM_API int bsim_stepper_push(bsim_stepper *s, const double force[2], double torque, long n,
                               bsim_error *err);

/* Back to step 0: the world as alloc made it (the backend's reset, or a
 * new world), the effects restarted. */
BSIM_API int bsim_stepper_reset(bsim_stepper *s, bsim_error *err);

/* The state after the last step (at step 0: the world's start), its
 * contact flags computed (bsim_contact_flags). Valid until the next call
 * on s. */
BSIM_API const bsim_state *bsim_stepper_state(const bsim_stepper *s);

/* Steps made since step 0. */
BSIM_API long bsim_stepper_steps(const bsim_stepper *s);

/* The force (N, x and y) and torque (N m) of the last step; zero at step 0. */
BSIM_API void bsim_stepper_wrench(const bsim_stepper *s, double wrench[3]);

/* The kinetic energy of body and beams and the beams' elastic energy in
 * the state, J (the energy ledger's E, beamsim/trial.h). */
BSIM_API void bsim_stepper_energy(const bsim_stepper *s, double *kinetic, double *elastic);

/* The scene the world was made from (the stepper's copy) and its
 * backend. */
BSIM_API const bsim_scene *bsim_stepper_scene(const bsim_stepper *s);
BSIM_API const bsim_backend *bsim_stepper_backend(const bsim_stepper *s);

#ifdef __cplusplus
}
#endif
#endif
