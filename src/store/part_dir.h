/* A part of a sweep run as its own process (sweep --shard I/N): the
 * directory it leaves, part.json and part.journal (docs/cluster.md), and
 * the join of every part's journal into the journal of the whole sweep,
 * from which the sweep's files are written as one process writes them. */
#ifndef BSIM_STORE_PART_DIR_H
#define BSIM_STORE_PART_DIR_H

#include <stddef.h>

#include "beamsim/error.h"
#include "beamsim/sweep.h"
#include "beamsim/sweep_dir.h"
#include "store/session.h"
#include "util/journal.h"

/* The run's name: 16 hex digits of the FNV-1a hash of its inputs
 * (bsim_run_record_inputs), so that parts of one run carry one name. */
void bsim_part_dir_run_id(const char *inputs, char out[17]);

/* Writes stage/part.json: part index (1-based) of count of run, over
 * total trials, records trials in part.journal, argv the command line. */
int bsim_part_dir_write(const char *stage, const char *command, int index, int count,
                        const char *run, long total, long records, int argc, char *const *argv,
                        bsim_error *err);

/* Reads the part.json of dirs[0..n) into parts[0..n) (freed by the
 * caller, bsim_sweep_dir_part_free) and checks that they are every part
 * of one run of command (run; NULL: the first's), each once. BSIM_EINPUT
 * naming the directory at fault: a part of another command or run, of
 * another count, given twice; the first part missing. */
int bsim_part_dir_check(const char *const *dirs, int n, const char *command, const char *run,
                        bsim_sweep_dir_part *parts, bsim_error *err);

/* Checks that dirs[0..n) are every part of run (command, inputs), each
 * once, whole, and appends every part's records to j. BSIM_EINPUT naming
 * the directory at fault: a part of another run, one missing or given
 * twice, a damaged journal. */
int bsim_part_dir_join(const char *const *dirs, int n, const char *command, const char *run,
                       const char *inputs, size_t record_size, long total, bsim_journal *j,
                       bsim_error *err);

/* How a run is spread (beamsim/sweep_dir.h): the mode, this process's
 * part, the check that every process has the same inputs, and for a shard
 * what part.json records. */
typedef struct part_dir_spread {
	int spread; /* BSIM_SPREAD_SHARD, _GATHER or _SEND */
	const bsim_sweep_part *part;
	int (*agree)(void *user, const char *inputs, unsigned char *done, size_t bytes,
	             bsim_error *err);
	const char *command; /* "sweep" or "compare" */
	size_t record_size;
	long total; /* trials of the whole run */
	int argc;
	char *const *argv;
} part_dir_spread;

/* Runs this process's part: run(user, part) with part->done the trials
 * already in ss's journal (ss NULL: no journal here; the gatherer's done
 * bits come through agree); for a shard, then, the journal moved to
 * ss->stage/part.journal beside a part.json. */
typedef int (*part_dir_run_fn)(void *user, const bsim_sweep_part *part, bsim_error *err);
int bsim_part_dir_spread_run(const part_dir_spread *sp, const char *inputs, bsim_session *ss,
                             part_dir_run_fn run, void *user, bsim_error *err);

/* ss's journal closed and opened again, to be replayed by the whole run. */
int bsim_part_dir_journal_reopen(bsim_session *ss, const char *inputs, size_t record_size,
                                 bsim_error *err);

#endif
