/* Running and storing a sweep or a comparison in an output directory, with
 * the record that lets `beamsim regress` run it again. Shared by sweep,
 * compare and regress, so a rerun writes exactly what the first run did. */
#ifndef BEAMSIM_CLI_STORE_H
#define BEAMSIM_CLI_STORE_H

#include <signal.h>

#include "beamsim/compare.h"
#include "beamsim/experiment.h"
#include "journal.h"
#include "outdir.h"
#include "beamsim/run_record.h"
#include "beamsim/sweep.h"

/* What a comparison runs: two sides, each a backend with its options as
 * given, a label for the reports and a directory name under out. */
typedef struct cli_compare_job {
	const bsim_experiment *e;
	const bsim_backend *backend[2];
	const bsim_options *opts[2];
	const char *label[2];       /* NAME[:K=V]...; its directory: cli_label_dir */
	const bsim_override *extra; /* command-line --set */
	int n_extra;
	/* compare --protocols: the lattice protocol of each side, which then
	 * labels the sides and their directories ({NULL, NULL}: the backends
	 * do); extra_b sets side b's, after extra (which sets side a's). */
	const char *protocol[2];
	const bsim_override *extra_b;
	int n_extra_b;
	int threads;
	bsim_compare_rule rule;
	int examples;
	int progress; /* a progress line on a terminal */
	const char *out;
	int keep, keep_stride;             /* trajectories kept per group, see bsim_sweep_config */
	bsim_journal *journal;             /* NULL: none (bsim_sweep_config) */
	const volatile sig_atomic_t *stop; /* NULL: none */
} cli_compare_job;

/* One run's output directory (beamsim/outdir.h) and, for sweep and
 * compare, its journal (beamsim/journal.h) and the signals that stop it
 * cleanly. Files are written into stage and appear in dir at the end. */
typedef struct cli_session {
	const char *dir;   /* as the user gave it */
	const char *stage; /* where to write */
	bsim_outdir *od;
	bsim_journal *journal;
	char journal_path[1100];
	int argc; /* the command line, for the line that resumes it */
	char **argv;
	int add; /* set before closing: the files join DIR's set (bsim_outdir_add) */
} cli_session;

/* Set to the signal's number by SIGINT or SIGTERM during a session: the
 * sweep's stop flag. */
extern volatile sig_atomic_t cli_stop;

/* Opens dir (exit 2 if it cannot be used) and, if inputs is not NULL, the
 * journal for records of record_size bytes: with resume the journal of the
 * stopped run in dir, which must have these inputs; without, a new one,
 * refusing a dir that holds a stopped run's journal. Installs the signal
 * handlers. Prints any error; returns the exit status. */
int cli_session_open(cli_session *s, const char *dir, int resume, const char *inputs,
                     size_t record_size, int argc, char **argv);

/* Ends the session with the run's status rc: if 0, commits the files (and
 * removes the journal once they are in place; a failed commit keeps it, so
 * --resume writes the files again); if the run was stopped, keeps the
 * journal and prints the line that resumes it, returning 128 + the
 * signal's number; after any other failure (a trial that failed is failed
 * again by a resume) the journal is removed. Prints any error; returns the
 * exit status. */
int cli_session_close(cli_session *s, int rc, const char *command);

/* The run record of a sweep (one backend) or comparison (two). */
void cli_record_fill(bsim_run_record *rec, const char *command, const bsim_experiment *e, int n,
                     const bsim_backend *const *b, const bsim_options *const *opts,
                     const char *const *label, const bsim_compare_rule *rule);

/* DIR/summary.json, DIR/trials.csv and the run record of a sweep. */
int cli_store_sweep(const char *dir, const bsim_experiment *e, const bsim_backend *b,
                    const bsim_options *opts, const bsim_override *extra, int n_extra,
                    const bsim_sweep_result *r);

/* Runs the pairs, writes DIR/<dir>/{summary.json,trials.csv},
 * DIR/pairs.csv, DIR/report.md, DIR/report.json and the run record; the
 * analysis goes to cmp (free with bsim_compare_free). Returns the exit
 * status of the run (0, 1 or 2), not the verdict. */
int cli_compare_execute(const cli_compare_job *job, bsim_comparison *cmp);

/* The directory name of a compare side's label: the label with ':' and
 * '/' written '-' ("thesis:integrator=euler" -> "thesis-integrator=euler"). */
void cli_label_dir(const char *label, char *buf, size_t size);

/* "dir/name", 0 or a message and CLI_FAIL if it does not fit. */
int cli_path(char *buf, size_t size, const char *dir, const char *name);

#endif
