/* The record a sweep or comparison leaves in its output directory, so that
 * `beamsim regress DIR` can run it again: DIR/run.json (command, version,
 * backends with every knob's effective value, seed, trials, the comparison
 * rule) and DIR/inputs/ (the scene file as it was, and the experiment with
 * its command-line --set overrides folded into `set:`). */
#ifndef BSIM_RUN_RECORD_H
#define BSIM_RUN_RECORD_H

#include <stdint.h>

#include "beamsim/base.h"
#include "beamsim/backend.h"
#include "beamsim/compare.h"
#include "beamsim/experiment.h"
#include "beamsim/limits.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct bsim_run_record {
	char command[16]; /* "sweep" or "compare" */
	char version[32]; /* of the beamsim that wrote it */
	int n_backends;   /* 1 (sweep), or compare's sides (2 to BSIM_COMPARE_SIDES_MAX) */
	char backend[BSIM_COMPARE_SIDES_MAX][32];
	/* compare's side labels (NAME[:K=V]...); the name if none */
	char label[BSIM_COMPARE_SIDES_MAX][128];
	/* the library of a plug-in backend (bsim_backend_plugin_path), "" for
	 * one compiled in */
	char plugin[BSIM_COMPARE_SIDES_MAX][1024];
	bsim_options opts[BSIM_COMPARE_SIDES_MAX]; /* every knob, effective value */
	/* compare's sides read, not run (trials:PATH): the file's absolute
	 * path and the FNV-1a 64 hash of its bytes (16 hex digits); "" for a
	 * side that ran */
	char read_from[BSIM_COMPARE_SIDES_MAX][BSIM_PATH_MAX];
	char read_hash[BSIM_COMPARE_SIDES_MAX][17];
	uint64_t seed;
	int trials;
	bsim_compare_rule rule; /* compare only */
	/* compare --protocols: the lattice protocol of each side ("" if not) */
	char protocol[2][16];
} bsim_run_record;

/* The record of a sweep (n = 1 backend) or comparison (n sides, 2 to
 * BSIM_COMPARE_SIDES_MAX):
 * each side's backend, label (NULL: the backend's name) and every knob's
 * effective value, the experiment's seed and trials, and the rule (NULL:
 * bsim_compare_rule_default()). */
BSIM_API void bsim_run_record_fill(bsim_run_record *rec, const char *command,
                                   const bsim_experiment *e, int n, const bsim_backend *const *b,
                                   const bsim_options *const *opts, const char *const *label,
                                   const bsim_compare_rule *rule);

/* Side i's backend: the one registered under its name, else, for a
 * plug-in's, the one its recorded library (plugin[i]) registers when
 * loaded, or for a side read from a file (read_from[i]) the stand-in that
 * runs nothing; NULL and BSIM_EINPUT saying which if neither. */
BSIM_API const bsim_backend *bsim_run_record_backend(const bsim_run_record *rec, int i,
                                                     bsim_error *err);

/* Writes DIR/inputs/scene.yaml, DIR/inputs/experiment.yaml and, last,
 * DIR/run.json, each atomically: a directory with run.json is complete. */
BSIM_API int bsim_run_record_write(const char *dir, const bsim_run_record *rec,
                                   const bsim_experiment *e, const bsim_override *extra,
                                   int n_extra, bsim_error *err);

/* What the trials of a run depend on, as text (malloc'd; NULL and err on
 * failure): version, command, backends with every option, the number of
 * groups, the experiment as it ran (seed, trials, every override, the grid)
 * and the scene file's text. Two runs with equal texts have equal trials;
 * a resumed run must have the text of the run it continues
 * (util/journal.h). The comparison rule is not in it: it changes the
 * report, not the trials. */
BSIM_API char *bsim_run_record_inputs(const bsim_run_record *rec, const bsim_experiment *e,
                                      const bsim_override *extra, int n_extra, bsim_error *err);

/* Reads DIR/run.json. BSIM_EINPUT naming the file and field on a missing
 * or malformed record. The experiment to load is DIR/inputs/experiment.yaml. */
BSIM_API int bsim_run_record_read(const char *dir, bsim_run_record *rec, bsim_error *err);

#ifdef __cplusplus
}
#endif
#endif
