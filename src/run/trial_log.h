/* Internal: how the runner fills a trial's log (trial.h bsim_trial_log). */
#ifndef BSIM_RUN_TRIAL_LOG_H
#define BSIM_RUN_TRIAL_LOG_H

#include "beamsim/trial.h"

/* Appends gate entry e to the path. */
int bsim_trial_log_push(bsim_trial_log *l, const bsim_gate_entry *e);

/* The n beams' peak angles, rad. */
int bsim_trial_log_peaks(bsim_trial_log *l, const double *peak, int n);

#endif
