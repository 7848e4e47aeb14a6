/* A random force's schedule kept from one trial for the next (internal to
 * the library: the runner's). A runner of many trials then allocates and
 * seeds one generator, not one a trial; the draws are those of a new
 * schedule (test_effects). The coupled ground friction's footprint is kept
 * the same way: its table (model/footprint_table.h) grows over the trials
 * of the same outline and gives what a new one would. */
#ifndef BSIM_MODEL_SCHEDULE_SPARE_H
#define BSIM_MODEL_SCHEDULE_SPARE_H

#include <stdint.h>

#include "beamsim/effects.h"
#include "beamsim/schedule.h"

/* bsim_schedule_reset at frequency f (Hz, > 0) too: the schedule
 * bsim_schedule_alloc(magnitude, frequency, seed) would give, the same
 * draws, without its allocation and first seeding. */
void bsim_schedule_restart(bsim_schedule *s, double magnitude, double frequency, uint64_t seed);

/* Counts the draws of s in bsim_schedule_total_draws, as freeing it would:
 * for a schedule kept for another trial. */
void bsim_schedule_keep(bsim_schedule *s);

/* What a runner keeps from one trial's effects for the next. */
typedef struct bsim_effects_spare {
	bsim_schedule *schedule;
	struct bsim_footprint_friction *footprint;
} bsim_effects_spare;

/* bsim_effects_init_taking with the random force's schedule and the
 * footprint taken from *spare when it holds them (they are then NULL
 * there), the schedule restarted for this trial; and bsim_effects_free
 * leaving them in *spare (those already there are freed).
 * bsim_effects_spare_free(spare) at the end. */
int bsim_effects_init_spare(bsim_effects *fx, const bsim_scene *scene, uint64_t seed,
                            unsigned taken, bsim_effects_spare *spare);
void bsim_effects_free_spare(bsim_effects *fx, bsim_effects_spare *spare);
void bsim_effects_spare_free(bsim_effects_spare *spare);

#endif
