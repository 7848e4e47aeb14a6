/* How long runs report progress: a callback, called now and then from one
 * thread with how much of the work is done (sweeps, comparisons and
 * regressions count trials; the accuracy study counts settings). The
 * beamsim program draws it as a line with an ETA on a terminal. */
#ifndef BSIM_PROGRESS_H
#define BSIM_PROGRESS_H

#include "beamsim/base.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef void (*bsim_progress_fn)(void *user, long done, long total);

/* What a sweep plans, said once before its first trial and before it
 * opens any file: the beam-steps its trials take at most (each group's
 * trials, or one where the group has no random force, times its max_steps
 * and its beams), from its groups' scenes. The beamsim program turns it into its estimate of the
 * run's time with the backend's stated cost a beam-step. */
typedef void (*bsim_plan_fn)(void *user, double beam_steps);

#ifdef __cplusplus
}
#endif
#endif
