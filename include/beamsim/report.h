/* The report of a paired comparison (docs/files.md "Outputs of
 * `compare --out DIR`": report.md for people, report.json for tools) and
 * the per-pair table pairs.csv, of two sides or more. beamsim regress
 * reuses the sections for a stored run against its rerun. */
#ifndef BSIM_REPORT_H
#define BSIM_REPORT_H

#include <stdio.h>

#include "beamsim/base.h"
#include "beamsim/backend.h"
#include "beamsim/compare.h"
#include "beamsim/experiment.h"
#include "beamsim/sweep.h"

#ifdef __cplusplus
extern "C" {
#endif

/* One side of a comparison. */
typedef struct bsim_report_side {
	const char *label;           /* a backend's name, "baseline", ... */
	const bsim_backend *backend; /* the backend that ran it */
	const bsim_options *opts;    /* as given, for the replay lines */
	const bsim_sweep_result *run;
	const char *read_from; /* NULL: run; else the trials.csv it was read from */
} bsim_report_side;

typedef struct bsim_report {
	const bsim_experiment *e;
	const bsim_override *extra; /* command-line --set, for the replay lines */
	int n_extra;
	const bsim_override *extra_b; /* side b's own overrides (compare --protocols) */
	int n_extra_b;
	bsim_report_side side[2];
	const double *t_separate; /* NULL: no trajectories compared */
	const bsim_comparison *cmp;
	int examples; /* discordant trials shown per disagreeing group */
	/* More than two sides: n_sides > 2, every side in sides, the comparison
	 * of every pair in all, and t_separate every pair's in turn
	 * (bsim_sweep_run_sides); side and cmp are then the first pair's
	 * (sides 0 and 1). n_sides <= 2: the two sides above alone. */
	int n_sides;
	const bsim_report_side *sides;
	const bsim_compare_sides *all;
} bsim_report;

/* The body of report.md: the verdict, the rule, the separation times, one
 * table row per group, then each disagreeing group in detail with example
 * trials and the `beamsim run` lines that replay them. More than two
 * sides: each side's p_traverse per group with the group's verdict and odd
 * one out, then every pair's row per group, and each disagreeing group's
 * disagreeing pairs in detail. */
BSIM_API void bsim_report_md(FILE *f, const bsim_report *r);
/* report.json: the same content as one JSON object. More than two sides:
 * the fields of two sides, of the first pair, but for groups_disagreeing,
 * verdicts and each group's verdict, which are over every pair; then
 * "sides", "pairwise" and "odd_one_out", at the top and in each group
 * (docs/files.md). */
BSIM_API void bsim_report_json(FILE *f, const bsim_report *r);
/* pairs.csv: group,trial,outcome_a,type_a,outcome_b,type_b,t_separate,
 * location_a,location_b (t_separate empty when the pair never separated;
 * the final locations as in trials.csv). More than two sides, lettered a,
 * b, c, ... in order: every side's outcome_X,type_X, then t_separate (of
 * a and b), then t_separate_X_Y of every other pair in bsim_sweep_pair's
 * order, then every side's location_X. */
BSIM_API void bsim_report_pairs_csv(FILE *f, const bsim_report *r);

#ifdef __cplusplus
}
#endif
#endif
