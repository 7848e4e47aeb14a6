/* A comparison stored in an output directory (beamsim compare EXPERIMENT
 * --out DIR): every trial of an experiment run on two or more sides with
 * the same random-force schedules, so that trial t of group g of any two
 * sides is a pair (beamsim/sweep.h), every pair of sides analysed
 * (beamsim/compare.h), and DIR written as one set: report.md, report.json,
 * pairs.csv, each side's sweep files in DIR/<label>/
 * (beamsim/sweep_dir.h), their .mat twins, and run.json with inputs/
 * (beamsim/run_record.h). DIR, the journal and resume behave as for a
 * sweep (beamsim/sweep_dir.h).
 *
 * A side is a backend with options, written NAME[:KEY=VALUE]... as on the
 * command line (a name `beamsim backends` lists, alone or with options:
 * "NAME:KEY=VALUE:KEY=VALUE", or a plug-in's plugin:PATH in place of
 * NAME); that text, with the backend's own name for plugin:PATH, is its
 * label. Or, on a gate
 * lattice, the two sides are one backend under two lattice protocols
 * (protocol), and the protocols label them.
 *
 * A side may also be read rather than run: "trials:PATH", the trials.csv
 * (or a directory holding one) of the same experiment run elsewhere on the
 * same schedules (`beamsim run EXPERIMENT --group G --trial T` gives trial
 * T of group G). It is checked against the experiment as loaded before
 * anything runs, and its trials enter the comparison as a run side's do;
 * it is labelled by its folder's name (docs/compare.md, "Results made
 * elsewhere"). */
#ifndef BSIM_COMPARE_DIR_H
#define BSIM_COMPARE_DIR_H

#include <signal.h>
#include <stddef.h>
#include <stdint.h>

#include "beamsim/sweep_dir.h"

#include "beamsim/base.h"
#include "beamsim/limits.h"
#include "beamsim/backend.h"
#include "beamsim/compare.h"
#include "beamsim/experiment.h"
#include "beamsim/sweep.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct bsim_compare_side {
	const bsim_backend *backend;
	bsim_options opts;
	char label[128]; /* NAME[:K=V]..., the protocol, or a read side's folder */
	/* A side read, not run: PATH of trials:PATH as given (a trials.csv or
	 * a directory holding one); "" for a side that runs. Its backend is
	 * then a stand-in named "trials" that runs nothing. */
	char trials[BSIM_PATH_MAX];
	/* "", or the FNV-1a 64 hash (16 hex digits) the file's bytes must
	 * have: a stored comparison rerun (beamsim regress) reads the file it
	 * read, and refuses one that changed. */
	char trials_hash[17];
} bsim_compare_side;

/* Parses a side "NAME[:KEY=VALUE]..." into side (label = spec with the
 * backend's name for NAME, backend found by name or loaded from
 * plugin:PATH, options in order, later ones win), after the options
 * already in side->opts, which the spec's override; or a side read from
 * "trials:PATH" (side->trials; no options). BSIM_EINPUT naming the spec
 * and what was expected. */
BSIM_API int bsim_compare_side_parse(const char *spec, bsim_compare_side *side, bsim_error *err);

/* The directory of a side's files in DIR: the label with ':' and '/'
 * written '-' ("NAME:KEY=VALUE" -> "NAME-KEY=VALUE"). */
BSIM_API void bsim_compare_dir_label(const char *label, char *buf, size_t size);

typedef struct bsim_compare_dir_def {
	const char *experiment; /* the experiment file */
	const char *out;        /* the output directory */
	const bsim_override *sets;
	int n_sets;
	/* Grid axes that replace or join the file's (bsim_experiment_load_grid). */
	const bsim_grid_axis *grid;
	int n_grid;
	long trials; /* > 0: trials per group instead of the file's */
	int has_seed;
	uint64_t seed;
	/* The sides, 2 to BSIM_COMPARE_SIDES_MAX, each label different. */
	int n_sides;
	bsim_compare_side side[BSIM_COMPARE_SIDES_MAX];
	/* "world" and "essay" (lattice.protocol), or both NULL: the sides
	 * differ by backend and options. With protocols there are two sides,
	 * and both must name one backend. */
	const char *protocol[2];
	int threads; /* <= 0: all cores */
	bsim_compare_rule rule;
	int examples;          /* discordant trials listed per disagreeing group */
	int keep, keep_stride; /* trajectories kept per group, see bsim_sweep_config */
	int resume;
	int overwrite;                /* as bsim_sweep_dir_def's */
	const char *resume_option;    /* as bsim_sweep_dir_def's */
	const char *overwrite_option; /* as bsim_sweep_dir_def's */
	bsim_progress_fn progress;
	void *progress_user;
	/* may be NULL: the beam-steps one side's trials take at most (every
	 * side that runs runs them all), said once before anything runs or
	 * opens (bsim_plan_fn) */
	bsim_plan_fn planned;
	void *planned_user;
	const volatile sig_atomic_t *stop;
	/* Spreading the comparison over processes, as a sweep is spread
	 * (beamsim/sweep_dir.h, docs/cluster.md): spread, part, agree, argc and
	 * argv for a shard's part.json, the part directories to merge. */
	int spread;
	bsim_sweep_part part;
	int (*agree)(void *user, const char *inputs, unsigned char *done, size_t bytes,
	             bsim_error *err);
	int argc;
	char *const *argv;
	const char *const *merge;
	int n_merge;
} bsim_compare_dir_def;

/* The registry's default comparison, its first two backends
 * (bsim_backend_compared), no options, bsim_compare_rule_default(), 3
 * examples, all cores. */
BSIM_API bsim_compare_dir_def bsim_compare_dir_def_default(void);

typedef struct bsim_compare_dir_result {
	bsim_experiment e;
	bsim_compare_sides cmp; /* every pair of sides; two sides: cmp.pairs[0] */
	int threads;
	int n_sides;
	char dir[BSIM_COMPARE_SIDES_MAX][128];             /* each side's directory in DIR */
	int read[BSIM_COMPARE_SIDES_MAX];                  /* 1: the side was read, not run */
	long unstable[BSIM_COMPARE_SIDES_MAX];             /* unstable trials on each side */
	bsim_solver_counts solver[BSIM_COMPARE_SIDES_MAX]; /* what each side's solvers gave up on */
	char journal[BSIM_PATH_MAX];                       /* as in bsim_sweep_dir_result */
} bsim_compare_dir_result;

/* Runs the comparison into def->out. BSIM_OK whatever the verdicts
 * (res->cmp.n_disagree says whether any group disagrees); the errors as
 * bsim_sweep_dir_run's, and BSIM_EINPUT for sides that are the same or
 * would write to the same directory. */
BSIM_API int bsim_compare_dir_run(const bsim_compare_dir_def *def, bsim_compare_dir_result *res,
                                  bsim_error *err);
BSIM_API void bsim_compare_dir_result_free(bsim_compare_dir_result *res);

#ifdef __cplusplus
}
#endif
#endif
