/* Internal: a trial's recorded rows to the recorder's sinks (trial.h
 * bsim_recorder), every stride-th step and the last. */
#ifndef BSIM_RUN_TRIAL_RECORD_H
#define BSIM_RUN_TRIAL_RECORD_H

#include "beamsim/trial.h"

/* One recorded row, the state s at step `step`, to every sink of rec. */
void bsim_trial_record_row(const bsim_recorder *rec, const bsim_scene *sc, const bsim_state *s,
                           long step, double f_rand, const bsim_ledger *ledger);

/* The whole lattice's state for the recorder, in whole (a state of the
 * scene's beams), from the state s of the essay's world, whose beam i is
 * the scene's map[i]; s itself if map is NULL. */
const bsim_state *bsim_trial_record_state(bsim_state *whole, const int *map, const bsim_state *s);

#endif
