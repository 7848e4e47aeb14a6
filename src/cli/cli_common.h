/* What the subcommands of the beamsim program share: argument parsing,
 * --set and --backend-opt collection, backend look-up, error printing,
 * JSON printing and atomic file writes. */
#ifndef BEAMSIM_CLI_COMMON_H
#define BEAMSIM_CLI_COMMON_H

#include <stdint.h>
#include <stdio.h>

#include "beamsim/backend.h"
#include "beamsim/scene.h"

/* Exit statuses (DESIGN.md "Command line"); they equal the bsim_error codes. */
enum { CLI_OK = 0, CLI_FAIL = 1, CLI_USAGE = 2 };

/* One subcommand: argv[0] is its name. Returns the exit status. */
typedef int (*cli_command_fn)(int argc, char **argv);

int cmd_run(int argc, char **argv);
int cmd_sweep(int argc, char **argv);
int cmd_backends(int argc, char **argv);
int cmd_bench(int argc, char **argv);

/* "beamsim: MSG" on stderr. */
void cli_error(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

/* A usage error of command cmd: the message, a pointer to --help, and 2. */
int cli_usage(const char *cmd, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* The getopt_long result '?' or ':' as a usage error. Call with the
 * option character getopt_long returned. */
int cli_bad_option(const char *cmd, char **argv, int c);

/* Strict number parsing: the whole text, within [min, max]. 0 on success. */
int cli_parse_long(const char *text, long min, long max, long *out);
int cli_parse_u64(const char *text, uint64_t *out);

/* The --set KEY=VALUE overrides of one command, in order. */
typedef struct cli_sets {
	int n, cap;
	bsim_override *ov; /* key, value and origin strings owned here */
} cli_sets;

/* Adds "KEY=VALUE" with origin "--set KEY=VALUE". 0, or a usage error. */
int cli_sets_add(cli_sets *s, const char *cmd, const char *kv);
void cli_sets_free(cli_sets *s);

/* Adds a --backend-opt KEY=VALUE. 0, or a usage error. */
int cli_options_add(bsim_options *opts, const char *cmd, const char *kv);

/* The backend by name with its options checked; prints the error and
 * returns NULL (exit status 2) if unknown or an option is bad. */
const bsim_backend *cli_backend(const char *name, const bsim_options *opts);

/* JSON values: an escaped string, a double that reads back exactly (null
 * if not finite), and an object of every knob of backend b with its
 * effective value (given or default), so a record says how it was run. */
void cli_json_string(FILE *f, const char *s);
void cli_json_double(FILE *f, double x);
void cli_json_options(FILE *f, const bsim_backend *b, const bsim_options *opts);

/* An output file written to PATH.tmp.PID and renamed into place when
 * complete, so no reader ever sees a partial file. */
typedef struct cli_file {
	FILE *f;
	const char *path;
	char tmp[1100];
} cli_file;

/* 0, or prints the error and returns 1. */
int cli_file_open(cli_file *o, const char *path);
/* Flushes to disk and renames; 0, or prints the error, removes the
 * temporary file and returns 1. */
int cli_file_commit(cli_file *o);
/* Drops the temporary file (the run failed). */
void cli_file_abort(cli_file *o);

/* Seconds on the monotonic clock. */
double cli_now(void);

#endif
