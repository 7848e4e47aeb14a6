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

#ifdef __cplusplus
}
#endif
#endif
