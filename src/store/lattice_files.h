/* The rows of a lattice sweep's per-trial files (output_lattice.c), for
 * the whole sweep at the end or a streamed sweep's blocks as they come:
 * trials first .. first + n - 1 of a sweep of `trials` per group, logs[i]
 * the gate path and peaks of trial first + i. */
#ifndef BSIM_STORE_LATTICE_FILES_H
#define BSIM_STORE_LATTICE_FILES_H

#include <stdio.h>

#include "beamsim/lattice.h"
#include "beamsim/sweep.h"

/* gate_entries.csv: every gate entry with its state, gate frame. */
void bsim_lattice_entries_header(FILE *f);
void bsim_lattice_entries_rows(FILE *f, long first, long n, int trials, const bsim_trial_log *logs);

/* beam_peaks.csv: each trial's beams that moved, with their peak angle. */
void bsim_lattice_peaks_header(FILE *f);
void bsim_lattice_peaks_rows(FILE *f, const bsim_lattice_def *def, long first, long n, int trials,
                             const bsim_trial_log *logs);

/* Group g's summary: the streamed sweep's own (*ls points into r), or
 * summarised from its trials into **ls (the caller frees it then: *ls is
 * left pointing at the caller's summary). BSIM_EFAIL: out of memory. */
int bsim_lattice_group_summary(const bsim_sweep_result *r, int g, bsim_lattice_summary **ls);

#endif
