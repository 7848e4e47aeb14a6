/* Internal: how the runner fills a trial's log (trial.h bsim_trial_log). */
#ifndef BSIM_RUN_TRIAL_LOG_H
#define BSIM_RUN_TRIAL_LOG_H

#include "beamsim/trial.h"

/* Appends gate entry e to the path. */
int bsim_trial_log_push(bsim_trial_log *l, const bsim_gate_entry *e);

/* The peaks of a scene of n_beams beams: peak[g] (rad) for the n_list
 * beams of list, the only ones whose peak may not be 0 (any order); those
 * not 0 are kept, in ascending order of beam. */
int bsim_trial_log_peaks(bsim_trial_log *l, const double *peak, const int *list, int n_list,
                         int n_beams);

#endif
