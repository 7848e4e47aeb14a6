/* The essay comparison's run shared by essay_compare.c and essay_store.c:
 * its sweeps run as one batch (store/sweep_batch.h), journaled when the
 * batch has an output directory. */
#ifndef BSIM_ANALYSIS_ESSAY_INTERNAL_H
#define BSIM_ANALYSIS_ESSAY_INTERNAL_H

#include "beamsim/essay_compare.h"
#include "store/sweep_batch.h"

/* Runs every sweep of cfg through sb (bsim_sweep_batch_run) and, when sb->writes,
 * fills out's rows; otherwise (a shard, another rank) out holds nothing.
 * The caller ends sb (bsim_sweep_batch_end). */
int bsim_essay_compare_batch(const bsim_essay_config *cfg, sweep_batch *sb, bsim_essay_result *out,
                             bsim_error *err);

#endif
