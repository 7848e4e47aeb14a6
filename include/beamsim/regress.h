/* A stored sweep or comparison run again (beamsim regress BASELINE --out
 * DIR): the run recorded in BASELINE (run.json and inputs/, beamsim/
 * run_record.h) is repeated with this beamsim into DIR, written as the
 * original run wrote it, and each side's trials are compared with the
 * stored ones pair by pair (same seed, group and trial) with the paired
 * tests of beamsim/compare.h: DIR/regress.md and DIR/regress.json. Both
 * sides are read from their trials.csv, so they have the file's precision;
 * identical code and inputs give identical trials. */
#ifndef BSIM_REGRESS_H
#define BSIM_REGRESS_H

#include "beamsim/base.h"
#include "beamsim/compare.h"
#include "beamsim/experiment.h"
#include "beamsim/run_record.h"
#include "beamsim/sweep.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct bsim_regress_def {
	const char *baseline; /* the stored run's directory */
	const char *out;      /* the rerun's; not the baseline */
	int overwrite;        /* 1: replace the result out holds; 0: refuse it */
	int threads;          /* <= 0: all cores */
	double alpha, margin; /* < 0: the stored rule's */
	int exact;            /* 1: any trial that differs in any trials.csv field counts */
	bsim_progress_fn progress;
	void *progress_user;
} bsim_regress_def;

/* The stored rule, all cores. */
BSIM_API bsim_regress_def bsim_regress_def_default(void);

typedef struct bsim_regress_side {
	char label[128];
	int trials;          /* compared */
	int changed;         /* not identical in every field both files hold */
	bsim_comparison cmp; /* stored as side a, the rerun as side b */
} bsim_regress_side;

typedef struct bsim_regress_result {
	bsim_run_record rec; /* the baseline's */
	bsim_experiment e;
	int n_sides;
	bsim_regress_side side[BSIM_COMPARE_SIDES_MAX];
	int beyond; /* groups beyond the rule, over the sides */
} bsim_regress_result;

/* Reruns and compares. BSIM_OK with res filled whatever it found
 * (res->beyond > 0: changed beyond the rule; the files are written all the
 * same); BSIM_EINPUT if the baseline is not a stored run, its files do not
 * match their manifest, or out cannot be used; BSIM_EFAIL if the rerun
 * fails. */
BSIM_API int bsim_regress_run(const bsim_regress_def *def, bsim_regress_result *res,
                              bsim_error *err);
BSIM_API void bsim_regress_result_free(bsim_regress_result *res);

#ifdef __cplusplus
}
#endif
#endif
