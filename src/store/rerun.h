/* A stored sweep or comparison run again (beamsim/regress.h): what
 * regress.c asks of sweep_dir.c and compare_dir.c. */
#ifndef BSIM_STORE_RERUN_H
#define BSIM_STORE_RERUN_H

#include "beamsim/compare_dir.h"
#include "beamsim/experiment.h"
#include "beamsim/sweep.h"
#include "beamsim/sweep_dir.h"

/* A stored run repeated (beamsim/regress.h) into the staging area stage:
 * the loaded experiment e as it is (its set: holds the original run's
 * overrides, def's sets and seed are not applied), no journal. The
 * comparison's result holds no experiment. */
int bsim_store_sweep_rerun(const bsim_sweep_dir_def *def, const bsim_experiment *e,
                           const char *stage, bsim_sweep_result *r, bsim_error *err);
int bsim_store_compare_rerun(const bsim_compare_dir_def *def, const bsim_experiment *e,
                             const char *stage, bsim_compare_dir_result *res, bsim_error *err);

#endif
