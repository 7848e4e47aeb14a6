/* Random-force schedules (docs/model.md section 2; the seed of a trial:
 * docs/files.md "Experiment file (YAML)").
 *
 * F_rand(t) = Rm * z_j for t in [j/f, (j+1)/f), z_j ~ N(0,1) drawn from a GSL
 * generator seeded by bsim_schedule_seed_mix(experiment seed, group, trial). Values
 * are drawn lazily in order and kept, so a schedule can be replayed from any
 * step and costs nothing in a trial that ends early. */
#ifndef BSIM_SCHEDULE_H
#define BSIM_SCHEDULE_H

#include <stdint.h>

#include "beamsim/base.h"
#include "beamsim/error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The fixed mixing function: a SplitMix64 finaliser over the three inputs.
 * It never changes; summary.json of every version depends on it. */
BSIM_API uint64_t bsim_schedule_seed_mix(uint64_t seed, uint64_t group, uint64_t trial);

typedef struct bsim_schedule bsim_schedule;

/* magnitude Rm in N, frequency f in Hz (> 0), seed from bsim_schedule_seed_mix. */
BSIM_API bsim_schedule *bsim_schedule_alloc(double magnitude, double frequency, uint64_t seed);
BSIM_API void bsim_schedule_free(bsim_schedule *s);

/* Restarts the schedule with a new seed (no allocation: reuse across trials). */
BSIM_API void bsim_schedule_reset(bsim_schedule *s, double magnitude, uint64_t seed);

/* Index j of the value that applies at step n of size h. */
BSIM_API long bsim_schedule_index(const bsim_schedule *s, long n, double h);

/* The force value j (N): Rm * z_j. Draws z up to j if not drawn yet. A
 * value that cannot be had (no memory for it, or j outside 0 .. 2^40) is
 * 0, and bsim_schedule_status then fails: never a NaN. */
BSIM_API double bsim_schedule_value(bsim_schedule *s, long j);

/* The force values j .. j + n - 1 (N) into out[0..n): bsim_schedule_value
 * of each, in order, the same bits. */
BSIM_API void bsim_schedule_values(bsim_schedule *s, long j, int n, double *out);

/* The force value at step n of size h (N): bsim_schedule_value of
 * bsim_schedule_index, the same bits, with the value held over its steps
 * kept so that the steps between two refreshes read it at no cost. */
BSIM_API double bsim_schedule_at_step(bsim_schedule *s, long n, double h);

/* bsim_schedule_at_step, and in held[0], held[1] the steps [held[0],
 * held[1]) at this h over which the value returned holds (held[0] =
 * held[1] = 0 when no such steps are known), so that a caller can read the
 * value over them without calling again: the same bits. */
BSIM_API double bsim_schedule_at_step_held(bsim_schedule *s, long n, double h, long held[2]);

/* The steps of size h that one value holds: 1 / (f h) when that is a
 * whole number of steps (5 for 50 Hz at 4 ms; value j then holds over
 * steps [j k, (j + 1) k)), else 0. */
BSIM_API long bsim_schedule_hold_steps(const bsim_schedule *s, double h);

/* The values before index n are all a trial used: those drawn ahead of it
 * (for a schedule of forces handed to a backend before the steps that
 * would use them) no longer count among bsim_schedule_draws. The values
 * themselves stay as drawn. */
BSIM_API void bsim_schedule_used(bsim_schedule *s, long n);

/* BSIM_OK, or BSIM_EFAIL saying which value could not be had and why,
 * since the last reset. */
BSIM_API int bsim_schedule_status(const bsim_schedule *s, bsim_error *err);

/* Number of standard-normal draws made since alloc/reset. */
BSIM_API unsigned long bsim_schedule_draws(const bsim_schedule *s);

/* Total draws made by all schedules of this process that have since been
 * reset, freed or kept (for tests that prove a scene without random force
 * makes none; a trial frees its schedule when it ends, or keeps it for the
 * next: model/schedule_spare.h). */
BSIM_API unsigned long bsim_schedule_total_draws(void);

#ifdef __cplusplus
}
#endif
#endif
