/* The physics backend interface (how to add one: docs/architecture.md,
 * "Where a new thing goes"); the backends compiled in are reached through
 * the registry, beamsim/backend_registry.h.
 *
 * A backend owns bodies, beams, joints (spring + damper), contacts and
 * integration; nothing else. The runner owns time, the external force on the
 * body, termination and recording, so that every backend runs the same
 * scenes with the same random-force schedules. */
#ifndef BSIM_BACKEND_H
#define BSIM_BACKEND_H

#include <stddef.h>

#include "beamsim/base.h"
#include "beamsim/error.h"
#include "beamsim/options.h"
#include "beamsim/scene.h"
#include "beamsim/state.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct bsim_world bsim_world; /* opaque, one per backend */

/* What the runner applies to the body over one step: a force (N) on its
 * centre and a torque (N m, counter-clockwise) about it. A schedule is
 * one a step. */
typedef struct bsim_wrench {
	double force[2];
	double torque;
} bsim_wrench;

/* A bound a backend holds itself to in a check that the tests run on every
 * registered backend (docs/tests.md, "Every backend"): the check's name,
 * the largest departure from the check's truth it allows (0: none, to the
 * bit) and what it rests on (what was measured, and why the backend does
 * not do better). A check whose name the backend does not list is skipped
 * for it, and the test says so. */
typedef struct bsim_backend_bound {
	const char *check; /* "impact", "mirror.contact.ellipse", ... */
	double bound;      /* in the check's unit (docs/tests.md) */
	const char *basis; /* "measured 3e-7 (float32)" */
} bsim_backend_bound;

typedef struct bsim_backend {
	const char *name;
	const char *description;
	const bsim_knob *knobs;
	int n_knobs;
	int (*create)(const bsim_scene *scene, const bsim_options *opts, bsim_world **out,
	              bsim_error *err);
	void (*destroy)(bsim_world *w);
	/* The one call that moves a world: n >= 1 steps of h seconds each,
	 * step k under the wrench schedule[k] (a body that does not rotate,
	 * body.rotates 0, ignores the torque); the state after each into out[k]
	 * as get_state writes it (each sized for the world's beams by
	 * bsim_state_init), or, out NULL, no state written. The steps made into
	 * *made: n, or fewer (at least 1) where the backend's own paths part
	 * (free flight ending near a beam, say); the caller asks again for the
	 * rest. Whatever path makes them, each step is the step that a call for
	 * that one step would make, to the bit. BSIM_OK, or BSIM_EFAIL with err
	 * saying why (out of memory): the world cannot go on. What a solver
	 * gave up on without failing is counted in the state's solver counts. */
	int (*advance)(bsim_world *w, const bsim_wrench *schedule, double h, int n, bsim_state *out,
	               int *made, bsim_error *err);
	void (*get_state)(const bsim_world *w, bsim_state *out);
	int (*set_state)(bsim_world *w, const bsim_state *s, bsim_error *err);
	/* The knob settings the accuracy study compares (beamsim/accuracy.h),
	 * beside the knobs they set; the first is the most accurate, whose run
	 * at the finest step is the study's reference. */
	const bsim_knob_setting *accuracy;
	int n_accuracy;
	/* Optional (NULL: not offered). Puts w back to the world create made
	 * from scene, which must be the scene w was created from, unchanged
	 * but for the body's start and velocity, which it reads again: the
	 * same steps then give the same bits. What the world derived from
	 * the beams' definitions (its grid, their rest directions) is kept, so
	 * a trial pays for the beams it touched, not for the field
	 * (bsim_trial_runner_keep_worlds). */
	int (*reset)(bsim_world *w, const bsim_scene *scene, bsim_error *err);
	/* The effects the backend simulates itself (BSIM_TAKES_* of
	 * beamsim/effects.h), 0: none. The runner builds its pipeline with
	 * bsim_effects_init_taking(..., takes): such an effect gives the step no
	 * force, and the backend reports its loss in the step's state
	 * (bsim_state drag_loss, friction_loss). */
	unsigned takes;
	/* Optional (NULL: create refuses no valid scene for itself). What
	 * create refuses of a scene valid on its own, for this backend's
	 * limits (a body within Box2D's skin, a number beyond float32), and
	 * of opts: BSIM_OK, or BSIM_EINPUT with err's message and, in
	 * field[0..size), the dotted scene key to blame ("body.radius"; ""
	 * for an option), so that a caller who knows where the scene came
	 * from names the place (bsim_backend_check). */
	int (*check)(const bsim_scene *scene, const bsim_options *opts, char *field, size_t size,
	             bsim_error *err);
	/* What the backend is built on, for the records that say what made a
	 * run (run.json's NAME_version) and `beamsim --version`: the engine
	 * ("Box2D") and its version ("2.4.1"). */
	const char *engine;
	const char *version;
	/* The cost of one beam-step (a step of one beam) with the default
	 * options, ns of one core, and the measurement it comes from: the
	 * constant of the one-hour estimate a command prints before a long run
	 * (0: not stated, no estimate). */
	double cost_ns_per_beam_step;
	const char *cost_basis;
	/* The bounds it holds itself to in the checks every backend runs
	 * (bsim_backend_bound); n_bounds 0: none stated, and those checks are
	 * skipped for it, saying so. */
	const bsim_backend_bound *bounds;
	int n_bounds;
	/* 1: the backend's joints hold every beam at its pivot exactly, by
	 * construction, and its states leave bsim_state.pin unwritten; 0: its
	 * states report where the joints hold the beams (bsim_state.pin). */
	int exact_pins;
} bsim_backend;

/* Checks scene against b with opts (b->check) before a run, as a scene
 * error is said: BSIM_EINPUT "WHERE: MESSAGE", WHERE the place that gave
 * the field b refuses, as a scene loader names it: the --set, set: line or
 * grid value (ov, the overrides the scene was built with from the file
 * path, in order) that set it last, else the file's line
 * ("gate.yaml:4:22"). Without path, or where b blames no field, b's
 * message alone. BSIM_OK if b has no check. */
BSIM_API int bsim_backend_check(const bsim_backend *b, const bsim_options *opts,
                                const bsim_scene *scene, const char *path, const bsim_override *ov,
                                int n_ov, bsim_error *err);

/* The largest distance of an active beam's pinned point from its pivot in
 * scene, m, in a state s of a world of b: how far b's joints let the beams
 * drift (s->pin), 0 where b's pins are exact (exact_pins). */
BSIM_API double bsim_backend_pivot_drift(const bsim_backend *b, const bsim_scene *scene,
                                         const bsim_state *s);

/* The bound b states for check (bsim_backend_bound) into *bound: 1, or
 * 0 if b states none. */
BSIM_API int bsim_backend_bound_of(const bsim_backend *b, const char *check, double *bound);

/* A backend's single step (force N, torque N m, h s), and its get_state. */
typedef int (*bsim_step_fn)(bsim_world *w, const double force[2], double torque, double h,
                            bsim_error *err);
typedef void (*bsim_get_state_fn)(const bsim_world *w, bsim_state *out);

/* bsim_backend.advance for a backend that makes its steps one by one: n
 * steps of step, step k under schedule[k], each followed, where out is
 * given, by get_state into out[k]; into *made the steps made. The first
 * failing step's status, else BSIM_OK. */
BSIM_API int bsim_backend_advance_each(bsim_world *w, bsim_step_fn step,
                                       bsim_get_state_fn get_state, const bsim_wrench *schedule,
                                       double h, int n, bsim_state *out, int *made,
                                       bsim_error *err);

/* One step of world w of b (b->advance for one step, no state written):
 * BSIM_OK, or BSIM_EFAIL with err. get_state then gives the state after
 * it. */
BSIM_API int bsim_backend_step(const bsim_backend *b, bsim_world *w, const double force[2],
                               double torque, double h, bsim_error *err);

#ifdef __cplusplus
}
#endif
#endif
