/* Internal: a sweep's time to leave the gate, kept per group while its
 * trials stream by and written as survival.csv (the Kaplan-Meier curve)
 * and horizon.csv (the outcome shares as functions of the horizon), with
 * their .mat twins (docs/first_passage.md).
 *
 * A trial leaves the gate when its outcome is decided: it reaches
 * success_y (traversed) or the side boundary (side_exit); on a lattice,
 * when it leaves the field (the end or a side). A trial that is stuck or
 * unstable is censored at its t_end. */
#ifndef BSIM_STORE_SURVIVAL_FILES_H
#define BSIM_STORE_SURVIVAL_FILES_H

#include <stdint.h>

#include "beamsim/experiment.h"
#include "beamsim/override.h"
#include "beamsim/trial.h"

/* The kinds a trial's end is counted as. */
enum { SURV_TRAVERSED, SURV_SIDE_EXIT, SURV_UNSTABLE, SURV_STUCK, SURV_KINDS };

/* One group's ends by time: bin b holds the trials whose end step lies in
 * ((b - 1) w, b w] (w steps a bin; bin 0: step 0), each of the SURV_KINDS
 * counted apart. w = 1 (exact times) unless the trial is longer than
 * SURVIVAL_BINS_MAX steps or the sweep has many groups. */
typedef struct survival_group {
	double dt;       /* s, the group's time step */
	int max_steps;   /* the group's horizon in steps */
	int width;       /* w, steps a bin */
	int n_bins;      /* ceil(max_steps / w) + 1 */
	long n;          /* trials counted */
	uint32_t *count; /* n_bins * SURV_KINDS */
} survival_group;

/* Most bins a group keeps, and in all (the memory bound: 16 bytes a bin,
 * 16 MiB for the sweep; a group keeps at least SURVIVAL_BINS_MIN). */
#define SURVIVAL_BINS_MAX   4096
#define SURVIVAL_BINS_TOTAL (1L << 20)
#define SURVIVAL_BINS_MIN   16

typedef struct survival_acc {
	int n_groups;
	const bsim_experiment *e;
	survival_group *g;
} survival_acc;

/* Sets up the bins of every group of e from its scene's dt and max_steps:
 * scenes[k] (every group's, built with sets), or, scenes NULL, each group's
 * scene built here with sets. BSIM_EFAIL out of memory; free with
 * bsim_survival_acc_free either way. */
int bsim_survival_acc_init(survival_acc *a, const bsim_experiment *e, const bsim_scene *scenes,
                           const bsim_override *sets, int n_sets, bsim_error *err);
void bsim_survival_acc_free(survival_acc *a);

/* Counts trials first .. first + n - 1 of a sweep of `trials` per group. */
void bsim_survival_acc_add(survival_acc *a, long first, long n, int trials,
                           const bsim_trial_result *results);

/* Writes dir/survival.csv and dir/horizon.csv (their twins come with the
 * sweep's, bsim_matlab_sweep). */
int bsim_survival_acc_write(const survival_acc *a, const char *dir, bsim_error *err);

/* The trial's exit time t_exit, s, or NaN when it is censored (stuck,
 * unstable): what trials.csv's t_exit column holds (defined with that
 * column, in trial_fields.c, which the journal's writers call: so the
 * field table calls nothing that calls them). */
double bsim_survival_exit_time(const bsim_trial_result *r);

#endif
