/* The command line's options: those the commands share, each with one
 * name, one help line and one check of its value (cli_options.c), and the
 * parser every command runs, which joins them with the command's own.
 *
 *   static const cli_own own[] = {{"json", 0, NULL, "print one JSON object"}};
 *   static const cli_spec spec = {.name = "run", .positional = "SCENE",
 *           .common = CLI_USES(CLI_OPT_BACKEND) | ..., .own = own, .n_own = 1,
 *           .option = run_option};
 *   cli_common c = cli_common_default();
 *   int rc = cli_parse(&spec, argc, argv, &c, &my_args);  // -1: go on
 */
#ifndef BSIM_CLI_CLI_OPTIONS_H
#define BSIM_CLI_CLI_OPTIONS_H

#include <stdint.h>

#include "beamsim/backend.h"
#include "cli/cli_common.h"

typedef enum cli_opt {
	CLI_OPT_BACKEND,
	CLI_OPT_BACKEND_OPT,
	CLI_OPT_THREADS,
	CLI_OPT_TRIALS,
	CLI_OPT_SEED,
	CLI_OPT_SET,
	CLI_OPT_GRID,
	CLI_OPT_OUT,
	CLI_OPT_QUIET,
	CLI_OPT_LIMIT,
	CLI_OPT_RESUME,
	CLI_OPT_OVERWRITE,
	CLI_OPT_TRAJECTORIES,
	CLI_OPT_TRAJECTORY_STRIDE,
	CLI_OPT_ALPHA,
	CLI_OPT_MARGIN,
	CLI_N_OPTS
} cli_opt;

#define CLI_USES(o) (1u << (o))

#define CLI_BACKEND_OPTS_MAX (4 * BSIM_OPTIONS_MAX)
#define CLI_GRID_MAX         64

/* The values of the shared options. */
typedef struct cli_common {
	const char *backend; /* --backend; NULL: not given */
	int n_backend_opts;  /* --backend-opt as given, resolved with cli_backend_opts */
	const char *backend_opt[CLI_BACKEND_OPTS_MAX];
	long threads; /* 0: all cores */
	long trials;  /* 0: the input's */
	int has_seed;
	uint64_t seed;
	/* --set, and --grid's axes: those are expanded once every option is
	 * read, so that a --limit groups=N anywhere on the line counts */
	cli_sets sets;
	int n_grid;
	const char *grid[CLI_GRID_MAX];
	const char *out;
	int quiet, resume, overwrite;
	long keep, keep_stride;
	int has_alpha, has_margin;
	double alpha, margin;
} cli_common;

cli_common cli_common_default(void);
void cli_common_free(cli_common *c);

/* One option of a command's own. */
typedef struct cli_own {
	const char *name; /* "json" for --json */
	int has_arg;      /* 0 or 1 */
	const char *arg;  /* its value's name in the help, "N" */
	const char *help; /* lines after the first start a new line of the help */
} cli_own;

typedef struct cli_spec {
	const char *name;       /* the command */
	const char *usage;      /* after "beamsim NAME ": "EXPERIMENT --out DIR [OPTIONS]" */
	const char *about;      /* what it does, before "Options:" */
	const char *positional; /* the one argument it takes, "SCENE"; NULL: none */
	unsigned common;        /* CLI_USES(...) of the shared options it takes */
	/* Help lines of shared options where this command says more (indexed
	 * by cli_opt; NULL: the shared line). */
	const char *const *help;
	const char *out_arg; /* "DIR" (default) or "FILE.mp4": --out's value */
	int out_required;
	const cli_own *own;
	int n_own;
	/* Takes own option i with its value (NULL if it has none). CLI_OK, or
	 * an exit status. */
	int (*option)(void *args, int i, const char *value);
	const char *after; /* text after the options, or NULL */
} cli_spec;

/* Parses argv (argv[0]: the command) by spec: shared options into c, own
 * ones through spec->option(args, ...), the positional argument into *pos.
 * Prints the help for -h and --help (returns 0); -1 to go on, else the
 * exit status of a usage error (printed). */
int cli_parse(const cli_spec *spec, int argc, char **argv, cli_common *c, void *args,
              const char **pos);

/* The --backend-opt values, in the order given, into opts[i] for each of
 * the n backends a command runs (names[i]; a name may repeat, as for the
 * two sides of compare A,A:KEY=VALUE). B:K=V sets K on
 * backend B; K=V is short for it when the command runs one backend.
 * CLI_OK, or a usage error (a B that is not one of the backends, K=V with
 * several backends, bad syntax). */
int cli_backend_opts(const cli_common *c, const char *cmd, int n, const char *const *names,
                     bsim_options *const *opts);

/* The backend of a spec NAME[:KEY=VALUE]... (or plugin:PATH[:KEY=VALUE]...,
 * bsim_backend_spec_name) with the --backend-opt values for it, then the
 * spec's own options (they win, as in compare's sides), into opts (cleared
 * first), checked; prints the error and returns NULL (exit status 2) if
 * unknown or an option is bad. */
const bsim_backend *cli_backend_with_opts(const cli_common *c, const char *cmd, const char *spec,
                                          bsim_options *opts);

#endif
