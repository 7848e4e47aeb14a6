/* What the subcommands of the beamsim program share: error printing,
 * value parsing, --set and --backend-opt collection, backend look-up,
 * the signals that stop a run, and the line that resumes it. The shared
 * options and the parser are cli_options.h. */
#ifndef BSIM_CLI_CLI_COMMON_H
#define BSIM_CLI_CLI_COMMON_H

#include <stdint.h>
#include <stdio.h>

#include <signal.h>

#include "beamsim/backend.h"
#include "beamsim/backend_registry.h"
#include "beamsim/experiment.h"
#include "beamsim/scene.h"
#include "beamsim/sweep.h"

/* Exit statuses (docs/files.md "Command line"); they equal the bsim_error
 * codes. */
enum { CLI_OK = 0, CLI_FAIL = 1, CLI_USAGE = 2, CLI_DISAGREE = 3 };

/* One subcommand: argv[0] is its name. Returns the exit status. */
typedef int (*cli_command_fn)(int argc, char **argv);

int cmd_run(int argc, char **argv);
int cmd_sweep(int argc, char **argv);
int cmd_merge(int argc, char **argv);
int cmd_backends(int argc, char **argv);
int cmd_bench(int argc, char **argv);
int cmd_compare(int argc, char **argv);
int cmd_regress(int argc, char **argv);
int cmd_accuracy(int argc, char **argv);
int cmd_essay(int argc, char **argv);
int cmd_landscape(int argc, char **argv);
int cmd_escape(int argc, char **argv);
int cmd_plot(int argc, char **argv);
int cmd_video(int argc, char **argv);
int cmd_markov(int argc, char **argv);

/* "beamsim: MSG" on stderr, one line of printable text. */
void cli_error(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

/* A usage error of command cmd: the message, a pointer to --help, and 2. */
int cli_usage(const char *cmd, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* The getopt_long result '?' or ':' as a usage error. Call with the
 * option character getopt_long returned; names (may be NULL): the long
 * options the command knows, for "did you mean --trials?". */
int cli_bad_option(const char *cmd, char **argv, int c);
int cli_bad_option_near(const char *cmd, char **argv, int c, const char *const *names, int n);

/* Of the n names, the one word is a likely misspelling of (at most a
 * third of its letters apart, and nearer than any other), or NULL. */
const char *cli_nearest(const char *word, const char *const *names, int n);

/* Strict number parsing: the whole text, within [min, max]. 0 on success. */
int cli_parse_long(const char *text, long min, long max, long *out);
int cli_parse_u64(const char *text, uint64_t *out);

/* The --alpha and --margin of compare and regress: the whole text a number
 * in (0, 1) if open, else in [0, 1]. 0, or a usage error of cmd naming opt. */
int cli_parse_fraction(const char *cmd, const char *opt, const char *text, int open, double *out);

/* The --set KEY=VALUE overrides of one command, in order, and its --grid
 * axes, which replace or join the experiment's grid
 * (bsim_experiment_load_grid). */
typedef struct cli_sets {
	int n, cap;
	bsim_override *ov; /* key, value and origin strings owned here */
	int n_grid;
	bsim_grid_axis *grid; /* in the order given; every string owned here */
} cli_sets;

/* Adds "KEY=VALUE" with origin "--set KEY=VALUE". 0, or a usage error. */
int cli_sets_add(cli_sets *s, const char *cmd, const char *kv);
/* Adds a --grid axis: "KEY=V1,V2,..." (kept as written: numbers, or words
 * for a key whose values are words, each judged by the scene loader as an
 * experiment file's grid values are) or "KEY=A:B:STEP" (A, A + STEP, ...
 * up to B, B included when reached within 1e-9 of STEP, each written in
 * the fewest decimals that hold it, util/decimal.h), the axis's origin
 * "--grid KEY" (a value is named "--grid KEY=VALUE"). A KEY given again
 * replaces its earlier values. At most the limit groups values
 * (beamsim/limits.h). 0, or a usage error naming --grid, the text and what
 * was expected. */
int cli_grid_add(cli_sets *s, const char *cmd, const char *text);
void cli_sets_free(cli_sets *s);

/* Applies a --limit NAME=N (beamsim/limits.h) to the process. 0, or a
 * usage error of cmd. */
int cli_limit(const char *cmd, const char *text);

/* Adds a --backend-opt KEY=VALUE. 0, or a usage error. */
int cli_options_add(bsim_options *opts, const char *cmd, const char *kv);

/* The backend by name with its options checked; prints the error and
 * returns NULL (exit status 2) if unknown or an option is bad. */
const bsim_backend *cli_backend(const char *name, const bsim_options *opts);

/* Prints err's message if rc is not BSIM_OK; returns rc, which is also
 * the exit status (the codes are equal). */
int cli_report(int rc, const bsim_error *err);

/* Loads an experiment with the --set overrides and --grid axes (sets may
 * be NULL), the --seed (seed NULL: the file's) and, if trials > 0, that
 * many trials per group. Prints any error; returns the exit status (2 for
 * a bad file). */
int cli_experiment_load(const char *path, const cli_sets *sets, const uint64_t *seed, long trials,
                        bsim_experiment *e);

/* bsim_sweep_run with a progress line on stderr if show_progress (cfg's
 * own progress fields are ignored). Prints any error; returns the exit
 * status. */
int cli_sweep_run(const bsim_experiment *e, const bsim_sweep_config *cfg, int show_progress,
                  bsim_sweep_result *r);

/* Set to the signal's number by SIGINT or SIGTERM while the handlers of
 * cli_signals_install are in place: the stop flag of a long run. The
 * first signal asks the run to stop; a second ends the process at once,
 * which loses nothing the run's journal holds. */
extern volatile sig_atomic_t cli_stop;
/* The program as it was invoked (argv[0]; "beamsim" until main sets it),
 * so that a printed command line runs as typed (build/beamsim ...). */
extern const char *cli_program;
void cli_signals_install(void);
void cli_signals_restore(void);

/* The end of a run that kept its journal (journal: its path, "" if none):
 * if it was stopped (rc BSIM_ESTOPPED), the signal and the command line
 * that continues it (argv with --resume), returning 128 + the signal's
 * number; if its files could not be written, the line that writes them
 * again. Otherwise returns rc. */
int cli_run_end(int rc, const char *journal, int argc, char **argv);

/* A warning on stderr if the backend's solvers gave up on anything over
 * what ran (beamsim/state.h): what, how often, and where the counts are
 * written (where: "summary.json", ...). */
void cli_solver_warning(const char *backend, const bsim_solver_counts *c, const char *where);

/* One line on stderr before a run that may take more than an hour of one
 * core: the estimate, the beam-steps it is made of and the cost of a
 * beam-step it assumes for backend b (its table's, with that cost's
 * basis); none for a backend that states no cost. */
void cli_estimate_line(const bsim_backend *b, double beam_steps);
/* cli_estimate_line as a run's plan (bsim_plan_fn, user a cli_estimate):
 * n_run sides each run every trial (a sweep: 1), the costlier backend's
 * constant bounds the estimate. */
typedef struct cli_estimate {
	const bsim_backend *costlier;
	int n_run;
} cli_estimate;
void cli_estimate_sides(void *user, double beam_steps);

/* The names of the first max backends of the registry's default
 * comparison (bsim_backend_compared), joined by ',' into buf ("" if
 * none); for a command's default list of backends and its help. */
void cli_backend_names(char *buf, size_t size, int max);

/* path as the terminal may show it: control characters and bytes that are
 * not UTF-8 as \xNN (a newline in a file name must not start a line of
 * the report). In one of 4 static buffers used in turn, so up to 4 may be
 * given to one printf. */
const char *cli_path(const char *path);

/* text (malloc'd) with more appended, reallocated; NULL (text freed) if
 * out of memory. */
char *cli_text_append(char *text, const char *more);

/* count per second of wall time. A run too short for the clock (wall 0)
 * counts as 1 ns, so a rate is always finite. */
double cli_per_second(double count, double wall);

#endif
