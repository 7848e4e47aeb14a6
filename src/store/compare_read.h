/* A comparison's side that is read, not run (beamsim/compare_dir.h): the
 * trials.csv of the same experiment made elsewhere, by a solver that cannot
 * be linked into beamsim, spelled trials:PATH among compare's sides. The
 * file is checked against the experiment as loaded before anything runs;
 * its trials then enter the comparison as a run side's do. */
#ifndef BSIM_STORE_COMPARE_READ_H
#define BSIM_STORE_COMPARE_READ_H

#include <stddef.h>

#include "beamsim/compare_dir.h"
#include "beamsim/experiment.h"
#include "beamsim/sweep.h"

/* What stands for a read side where a backend is expected (labels,
 * run.json, reports): named "trials", no knobs, in no registry; it makes
 * no world (create refuses, saying why). */
extern const bsim_backend bsim_compare_read_backend;

/* The side of spec "trials:PATH" (BSIM_TRIALS_PREFIX): side->trials =
 * PATH, side->backend the table above, and its label, the name of the
 * folder that holds the file (PATH itself if a directory), or "trials"
 * if that name is not one a label can be (letters, digits, '_', '-', '+',
 * '='; not "inputs", which the comparison's directory has). BSIM_EINPUT
 * naming the spec if PATH is empty, followed by options, too long or
 * cannot be found. */
int bsim_compare_read_side(const char *spec, bsim_compare_side *side, bsim_error *err);

typedef struct compare_read {
	char given[BSIM_PATH_MAX]; /* the file as named (PATH, or PATH/trials.csv) */
	char path[BSIM_PATH_MAX];  /* the same, absolute: what run.json records */
	char hash[17];             /* FNV-1a 64 of its bytes, 16 hex digits */
	char *bytes;               /* the file as read: its copy in the comparison */
	size_t len;
	bsim_sweep_result r; /* its trials, as a sweep of the experiment gives them */
} compare_read;

/* Reads side's file and checks it against e, every group's scene built
 * with extra after the experiment's overrides as a run side's is: the
 * columns beamsim writes that the comparison uses (a gate lattice's final
 * gate too), every (group, trial) once (in a group that draws no random
 * force, each the same as its trial 0), beamsim's outcome and type words
 * (type none unless traversed). Then r
 * is what a sweep would give: groups aggregated, the deterministic ones
 * marked, the lattice's definition set. BSIM_EINPUT "FILE:LINE: FIELD:
 * expected ..." on a file that does not fit, or if side->trials_hash is
 * given and the bytes' hash is another. */
int bsim_compare_read_load(const bsim_compare_side *side, const bsim_experiment *e,
                           const bsim_override *extra, int n_extra, compare_read *out,
                           bsim_error *err);
void bsim_compare_read_free(compare_read *rd);

#endif
