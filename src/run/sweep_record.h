/* A plain lattice sweep's journal record: the trial's result, then its
 * gate path (at most SWEEP_RECORD_ENTRIES entries) and the peak angles of
 * the beams it moved (at most SWEEP_RECORD_PEAKS), so that a part's trials
 * carry what the lattice's files are written from (gate_entries.csv,
 * beam_peaks.csv, the transitions and row times) and a resumed or merged
 * lattice sweep takes them from the journal.
 *
 *   result            bsim_trial_result, as in memory
 *   int32 n_entries   -1: the path or the peaks did not fit (the trial runs
 *                     again where the files are written; it is the same trial)
 *   int32 n_beams     the scene's
 *   int32 n_peaks
 *   entries           SWEEP_RECORD_ENTRIES bsim_gate_entry, n_entries used
 *   peaks             SWEEP_RECORD_PEAKS bsim_beam_peak, n_peaks used
 *
 * The record's size is the same for every sweep, whatever its field's
 * size, as the journal needs (one size a journal). */
#ifndef BSIM_RUN_SWEEP_RECORD_H
#define BSIM_RUN_SWEEP_RECORD_H

#include <stddef.h>

#include "beamsim/scene.h"
#include "beamsim/trial.h"

/* Gate entries a record holds: longer paths are rare (the most of 1000
 * trials of configs/markov/c_track.yaml was 27) and run again instead. */
#define SWEEP_RECORD_ENTRIES 32

/* Moved beams a record holds: more are rare (the most of 1000 trials of
 * configs/markov/c_track.yaml was 30) and run again instead. */
#define SWEEP_RECORD_PEAKS 64

/* The record's size. */
size_t bsim_sweep_record_bytes(void);

/* r and log packed into rec (bsim_sweep_record_bytes() bytes). */
void bsim_sweep_record_pack(void *rec, const bsim_trial_result *r, const bsim_trial_log *log);

/* rec into r and log (grown as needed): 1; 0 if the record's path or peaks
 * did not fit (nothing filled: the trial runs again); -1 out of memory. */
int bsim_sweep_record_unpack(const void *rec, bsim_trial_result *r, bsim_trial_log *log);

#endif
