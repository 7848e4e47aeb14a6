/* Running and storing a sweep or a comparison in an output directory, with
 * the record that lets `beamsim regress` run it again. Shared by sweep,
 * compare and regress, so a rerun writes exactly what the first run did. */
#ifndef BEAMSIM_CLI_STORE_H
#define BEAMSIM_CLI_STORE_H

#include "beamsim/compare.h"
#include "beamsim/experiment.h"
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
	int threads;
	bsim_compare_rule rule;
	int examples;
	int progress; /* a progress line on a terminal */
	const char *out;
	int keep, keep_stride; /* trajectories kept per group, see bsim_sweep_config */
} cli_compare_job;

/* DIR/summary.json, DIR/trials.csv and the run record of a sweep. */
int cli_store_sweep(const char *dir, const bsim_experiment *e, const bsim_backend *b,
                    const bsim_options *opts, const bsim_override *extra, int n_extra,
                    const bsim_sweep_result *r);

/* Runs the pairs, writes DIR/<dir>/{summary.json,trials.csv},
 * DIR/pairs.csv, DIR/report.md, DIR/report.json and the run record; the
 * analysis goes to cmp (free with bsim_comparison_free). Returns the exit
 * status of the run (0, 1 or 2), not the verdict. */
int cli_compare_execute(const cli_compare_job *job, bsim_comparison *cmp);

/* The directory name of a compare side's label: the label with ':' and
 * '/' written '-' ("thesis:integrator=euler" -> "thesis-integrator=euler"). */
void cli_label_dir(const char *label, char *buf, size_t size);

/* "dir/name", 0 or a message and CLI_FAIL if it does not fit. */
int cli_path(char *buf, size_t size, const char *dir, const char *name);

#endif
