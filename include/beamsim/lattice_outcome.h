/* Where the trials of a gate lattice ended (docs/model.md section 8): a trial's
 * final location, and a group's locations, gate-to-gate transitions and
 * time per row, from the runner's results (beamsim/trial.h) over the
 * lattice's geometry (beamsim/lattice.h). */
#ifndef BSIM_LATTICE_OUTCOME_H
#define BSIM_LATTICE_OUTCOME_H

#include <stddef.h>

#include "beamsim/base.h"
#include "beamsim/lattice.h"
#include "beamsim/trial.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Where a trial ended (docs/model.md section 8): through the end boundary in
 * column ix, out through a side at row iy, or stuck in gate (ix, iy). */
typedef enum bsim_location_kind {
	BSIM_LOCATION_END = 0,
	BSIM_LOCATION_SIDE = 1,
	BSIM_LOCATION_STUCK = 2,
} bsim_location_kind;

typedef struct bsim_location {
	bsim_location_kind kind;
	int ix, iy; /* END: ix (iy = 0); SIDE: iy (ix = 0); STUCK: both */
} bsim_location;

BSIM_API bsim_location bsim_lattice_location_of(const bsim_trial_result *r);
/* 1 if a and b are the same location. */
BSIM_API int bsim_lattice_location_equal(bsim_location a, bsim_location b);
/* "end:-2", "side:3", "stuck:0:2"; the labels of trials.csv, summary.json
 * and the final-location CSV. */
BSIM_API void bsim_lattice_location_label(bsim_location loc, char *buf, size_t size);

/* ---- a group of lattice trials ------------------------------------------ */

typedef struct bsim_location_count {
	bsim_location loc;
	int count;
	double p, ci95[2]; /* count / trials, Wilson 95% */
} bsim_location_count;

typedef struct bsim_transition {
	int from[2], to[2]; /* gates (ix, iy): one entry of the path to the next */
	int count;
} bsim_transition;

typedef struct bsim_lattice_summary {
	int trials;
	int n_locations;                /* distinct final locations, ends by ix, sides by iy, */
	bsim_location_count *locations; /* then stuck gates by (iy, ix) */
	int n_transitions;              /* distinct gate-to-gate steps, by from */
	bsim_transition *transitions;   /* then to, (iy, ix) order */
	int rows;
	int *row_trials;  /* per row iy: trials whose path entered it */
	double *row_time; /* per row: their mean time spent in it, s */
} bsim_lattice_summary;

/* Summarises n trials of one group (logs: their gate paths, may be NULL:
 * no transitions or row times) of a lattice of `rows` rows. */
BSIM_API int bsim_lattice_summarise(const bsim_trial_result *trials, const bsim_trial_log *logs,
                                    int n, int rows, bsim_lattice_summary *out);
BSIM_API void bsim_lattice_summary_free(bsim_lattice_summary *s);

/* The same summary built a block of trials at a time (a streamed sweep):
 * begin, add each block in trial order, end; the result is what
 * bsim_lattice_summarise gives for all the trials at once. Until end,
 * p and ci95 are not set and row_time holds sums. BSIM_EFAIL: out of
 * memory (free s with bsim_lattice_summary_free). */
BSIM_API int bsim_lattice_summary_begin(bsim_lattice_summary *s, int rows);
BSIM_API int bsim_lattice_summary_add(bsim_lattice_summary *s, const bsim_trial_result *trials,
                                      const bsim_trial_log *logs, int n);
BSIM_API void bsim_lattice_summary_end(bsim_lattice_summary *s);

/* Time the trial spent in each row, s: row_time[iy] for iy < rows, from
 * the log's entries (a row not entered gets 0). */
BSIM_API void bsim_lattice_row_times(const bsim_trial_result *r, const bsim_trial_log *log,
                                     int rows, double *row_time);

#ifdef __cplusplus
}
#endif
#endif
