/* A part of a sweep run as its own process (sweep --shard I/N): the
 * directory it leaves, part.json and part.journal (docs/cluster.md), and
 * the join of every part's journal into the journal of the whole sweep,
 * from which the sweep's files are written as one process writes them. */
#ifndef BSIM_STORE_PART_DIR_H
#define BSIM_STORE_PART_DIR_H

#include <stddef.h>

#include "beamsim/error.h"
#include "util/journal.h"

/* The run's name: 16 hex digits of the FNV-1a hash of its inputs
 * (bsim_run_record_inputs), so that parts of one run carry one name. */
void part_dir_run_id(const char *inputs, char out[17]);

/* Writes stage/part.json: part index (1-based) of count of run, over
 * total trials, records trials in part.journal, argv the command line. */
int part_dir_write(const char *stage, const char *command, int index, int count, const char *run,
                   long total, long records, int argc, char *const *argv, bsim_error *err);

/* Checks that dirs[0..n) are every part of run (command, inputs), each
 * once, whole, and appends every part's records to j. BSIM_EINPUT naming
 * the directory at fault: a part of another run, one missing or given
 * twice, a damaged journal. */
int part_dir_join(const char *const *dirs, int n, const char *command, const char *run,
                  const char *inputs, size_t record_size, long total, bsim_journal *j,
                  bsim_error *err);

#endif
