/* A random force's schedule kept from one trial for the next (internal to
 * the library: the runner's). A runner of many trials then allocates and
 * seeds one generator, not one a trial; the draws are those of a new
 * schedule (test_effects). */
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

/* bsim_effects_init_taking with the random force's schedule taken from
 * *spare when it holds one (*spare is then NULL), restarted for this trial;
 * and bsim_effects_free leaving the schedule in *spare (one already there
 * is freed). bsim_schedule_free(*spare) at the end. */
int bsim_effects_init_spare(bsim_effects *fx, const bsim_scene *scene, uint64_t seed,
                            unsigned taken, bsim_schedule **spare);
void bsim_effects_free_spare(bsim_effects *fx, bsim_schedule **spare);

#endif
