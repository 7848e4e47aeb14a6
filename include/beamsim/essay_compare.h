/* The essay's reported numbers and stated trends against beamsim
 * (beamsim essay): every traversal probability the essay's text gives
 * (Sec. 3.2.2: Figs. 3.2 and 3.3; Sec. 3.3: the C-track) and every trend
 * it states (Sec. 3.1.2: H1; Sec. 3.2.2: Fig. 3.4a and b), run on one
 * backend in one or more modes (backend option settings), each a row with
 * beamsim's estimate, its 95% interval, a test against the essay and a
 * verdict. Optionally the levels' sensitivity to what the essay leaves
 * unstated (rest threshold, restitution, time limit, side boundary) at the
 * symmetric groups. Probabilities are fractions of trials; forces in N,
 * stiffnesses in N m/rad. */
#ifndef BSIM_ESSAY_COMPARE_H
#define BSIM_ESSAY_COMPARE_H

#include <signal.h>
#include <stdint.h>

#include "beamsim/base.h"
#include "beamsim/error.h"
#include "beamsim/figures.h"
#include "beamsim/progress.h"
#include "beamsim/limits.h"
#include "beamsim/sweep_dir.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum { BSIM_ESSAY_LEVEL = 0, BSIM_ESSAY_TREND } bsim_essay_kind;

/* One number or trend of the essay in one mode. */
typedef struct bsim_essay_row {
	char figure[24];    /* where the essay states it: "Fig. 3.2a", "Sec. 3.1.2" */
	char quantity[80];  /* "p_left", "slope of p_traverse per N of F_prop" */
	char condition[96]; /* "F 8 N, Rm 30 N, k1:k2 500:500" */
	char mode[96];      /* "default" or the backend options */
	bsim_essay_kind kind;
	char expect[16];         /* a trend's stated direction: "rises", "falls", "shrinks", ... */
	double essay_value;      /* a level's proportion; NaN for a trend */
	int essay_n;             /* the essay's trials per group (100; 20 for the C-track) */
	int essay_count;         /* round(essay_value * essay_n) */
	double value;            /* beamsim's proportion, or the trend's estimate */
	int n;                   /* beamsim's trials per group */
	int count;               /* a level's count (-1 for a trend) */
	double ci_lo, ci_hi;     /* 95%: Wilson for a level, Wald for a trend's estimate */
	double diff_lo, diff_hi; /* a level: Newcombe 95% interval of beamsim - essay; NaN else */
	double p;                /* Fisher's exact test, or the trend test */
	char test[24];           /* "fisher", "cochran-armitage", "wald" */
	int consistent;          /* the verdict (see essay_compare.c) */
} bsim_essay_row;

/* One group of the sensitivity study: a parameter the essay leaves
 * unstated set to one value, at a symmetric group, in one mode. */
typedef struct bsim_essay_sens_row {
	char parameter[48]; /* the scene key varied */
	char value[24];
	int is_default;     /* the value the shipped scene has */
	char condition[64]; /* "F 7 N, Rm 10 N, k1:k2 500:500" */
	char mode[96];
	int n, traversed, left, right, side_exit, stuck;
	double p, lo, hi;   /* p_traverse and its Wilson 95% interval */
	double essay_value; /* the essay's total at the group (0.31, 0.41) */
	int reaches;        /* 1: the interval reaches the essay's value (hi >= it) */
} bsim_essay_sens_row;

typedef struct bsim_essay_config {
	const char *configs; /* the directory of thesis/gate.yaml, lattice/c_track.yaml */
	const char *backend; /* by name (beamsim/backend.h) */
	int n_modes;
	/* "KEY=VALUE:KEY=VALUE", "" the default: backend options, and scene keys
	 * (a key with a dot) set in every group of the mode */
	const char *const *modes;
	int trials;         /* per single-gate group */
	int lattice_trials; /* of the C-track */
	int sens_trials;    /* per group of the sensitivity study; 0: no study */
	uint64_t seed;
	int threads;               /* <= 0: all; results do not depend on it */
	bsim_progress_fn progress; /* may be NULL: trials done of all */
	void *progress_user;
	const volatile sig_atomic_t *stop; /* NULL, or a flag that stops the run (BSIM_ESTOPPED) */
	/* bsim_essay_compare_store: every sweep's trials are journaled in out
	 * as they end (one journal), so with resume a stopped or killed run
	 * continues (same inputs), losing no finished trial. */
	int resume;
	/* 1: replace the finished result or stopped run in out; 0: refuse it */
	int overwrite;
	/* bsim_essay_compare_store spread over processes (beamsim/sweep_dir.h,
	 * docs/cluster.md): a shard writes a part directory into out, an MPI
	 * rank other than 0 writes nothing; merge joins the parts. All zero:
	 * one process. */
	bsim_sweep_spread spread;
} bsim_essay_config;

/* configs "configs", the thesis backend in its default, with
 * contact_mode=essay, and with contact_mode=essay and the essay's CoR 0.8
 * at the beams' tips too (contact.tip_restitution=0.8), 1000 trials a group, 1000 of the C-track,
 * no sensitivity study, seed 1, all threads. */
BSIM_API bsim_essay_config bsim_essay_config_default(void);

typedef struct bsim_essay_result {
	int n;
	bsim_essay_row *rows; /* by mode, then in the essay's order */
	int n_sens;
	bsim_essay_sens_row *sens; /* by mode, parameter, value, group */
	long trials_run;
	double wall_seconds;
	/* bsim_essay_compare_store stopped, or failed after finishing trials:
	 * the journal that resume continues from ("" otherwise). */
	char journal[BSIM_PATH_MAX];
} bsim_essay_result;

/* Runs every sweep and fills the rows. */
BSIM_API int bsim_essay_compare_run(const bsim_essay_config *cfg, bsim_essay_result *out,
                                    bsim_error *err);
BSIM_API void bsim_essay_result_free(bsim_essay_result *r);

/* Runs every sweep, its trials journaled in out (cfg->resume continues a
 * stopped run), and writes essay.csv (and sensitivity.csv when the study
 * ran), with .mat twins, essay.md (both tables and the definitions) and
 * the figure essay (.png, .svg, .gp, .dat) into out as one set once every
 * sweep is done: an interrupted or failed run leaves none of them, and
 * its journal (res->journal). A shard (cfg->spread) writes its part
 * directory, an MPI rank other than 0 nothing; res then holds no rows.
 * fig gets the figure's result; free it and res on BSIM_OK. */
BSIM_API int bsim_essay_compare_store(const char *out, const bsim_essay_config *cfg,
                                      bsim_essay_result *res, bsim_figures_result *fig,
                                      bsim_error *err);

#ifdef __cplusplus
}
#endif
#endif
