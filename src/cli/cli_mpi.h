/* A run spread over processes (docs/cluster.md): the processes of an MPI
 * job, in the one file of the program that speaks MPI, built in when CMake
 * finds MPI (BSIM_HAVE_MPI); and the job-array parts' --shard I/N and
 * stored command line. The library knows nothing of MPI: a sweep or a
 * comparison is spread through its parts (beamsim/sweep.h bsim_sweep_part,
 * beamsim/sweep_dir.h spread), and this file moves the parts' journal
 * records to rank 0, which journals them and writes the output directory
 * as one process writes it.
 *
 * Records go in batches: a rank's threads queue each finished trial's
 * record, and its main thread sends the queue between its own trials (MPI
 * called from one thread only: MPI_THREAD_FUNNELED). Rank 0 receives
 * between its own trials and, once they are done, until every rank has
 * sent its last batch. A rank that dies ends the job (mpirun kills the
 * others); rank 0's journal then holds every record it received, and the
 * same command with --resume continues. */
#ifndef BSIM_CLI_CLI_MPI_H
#define BSIM_CLI_CLI_MPI_H

#include "beamsim/sweep_dir.h"

/* Called first by main: starts MPI when the program runs under mpirun
 * (and MPI is built in). CLI_OK, or CLI_USAGE (printed) when it runs as
 * one of several processes of a job and MPI is not built in. */
int cli_mpi_init(int *argc, char ***argv);

/* Called last by main: ends MPI. */
void cli_mpi_finish(void);

/* This process's rank and the job's size (0 and 1 without MPI). */
int cli_mpi_rank(void);
int cli_mpi_size(void);

/* The agreement of the ranks on a run's inputs (bsim_sweep_dir_def.agree). */
typedef int (*cli_mpi_agree_fn)(void *user, const char *inputs, unsigned char *done, size_t bytes,
                                bsim_error *err);

/* In a job of several ranks, a run spread over them: rank 0 gathers and
 * writes, the others send (*spread, *part, *agree of a sweep's or a
 * comparison's def, whose journal records are record_size bytes, or as
 * many as the run says before it starts: bsim_sweep_part.sized). */
void cli_mpi_spread(int *spread, bsim_sweep_part *part, cli_mpi_agree_fn *agree, size_t record_size,
                    const volatile sig_atomic_t *stop);

/* --shard I/N of cmd: CLI_OK with *index (1-based) and *count, or a usage
 * error (printed). */
int cli_shard_parse(const char *cmd, const char *value, int *index, int *count);

/* The command line a part's part.json keeps: argv with the positional
 * argument pos made absolute (merge may run elsewhere); free with
 * cli_stored_argv_free. NULL if out of memory. */
char **cli_stored_argv(int argc, char **argv, const char *pos);
/* The same with each of the arguments pos[0..n_pos) made absolute (a
 * positional argument, an option's directory). */
char **cli_stored_argv_paths(int argc, char **argv, const char *const *pos, int n_pos);

/* What merge sets on the command line its parts recorded: the output
 * directory, threads, quiet, the part directories. */
typedef struct cli_merge {
	const char *out;
	long threads;
	int quiet;
	const char *const *parts;
	int n_parts;
	int overwrite; /* merge --overwrite: the joined run may replace out's result */
} cli_merge;

struct cli_common;
/* Sets merge m's output directory, threads, quiet and overwrite on the
 * parts' command line c, which is not resumed: the parts' journals are the
 * run. */
void cli_merge_apply(const cli_merge *m, struct cli_common *c);

/* compare's command line (argv[0] "compare") run as the merge m of its
 * parts (cmd_compare.c). */
int cmd_compare_merge(int argc, char **argv, const cli_merge *m);
/* sweep's, as the merge m of its parts (cmd_sweep.c). */
int cmd_sweep_merge(int argc, char **argv, const cli_merge *m);
/* markov build's (argv[0] "build"): the maps copied from the parts
 * (cmd_markov.c). */
int cmd_markov_merge(int argc, char **argv, const cli_merge *m);
void cli_stored_argv_free(char **stored, int argc, char **argv);
/* markov validate's (argv[0] "validate") and essay's, as the merge m of
 * their parts (cmd_markov.c, cmd_essay.c). */
int cmd_markov_validate_merge(int argc, char **argv, const cli_merge *m);
int cmd_essay_merge(int argc, char **argv, const cli_merge *m);

/* The end of a spread run that reports nothing here: a failure printed
 * (by rank 0 with the resume line of journal, argv the command line; by
 * another rank with its number) and the job ended; a shard's part said
 * (unless quiet). Returns the exit status. */
int cli_spread_end(const char *cmd, int rc, bsim_error *err, const char *journal, int argc,
                   char **argv, int shard, int shards, const char *out, int quiet);

/* Gathers every rank's directory on rank 0 (their files, not
 * subdirectories): rank 0's dirs[0..size) (allocated, freed by the
 * caller) are mine and rank r's copy in mine.rankR; the other ranks send
 * theirs and set nothing. One process: dirs[0] is mine. CLI_OK, or
 * CLI_FAIL printed. */
int cli_mpi_gather_dir(const char *mine, char **dirs);

/* bsim_markov_def.pass_exchange of an MPI job's ranks: each map's runs
 * broadcast from its owner's rank (MPI_Ibcast, waiting idle), so every
 * rank holds every map's pass. One process: nothing to do. */
int cli_mpi_pass_exchange(void *user, void *const *runs, size_t bytes, const int *owner, int n,
                          bsim_error *err);

/* Ends the whole job with status rc (after a rank's failure, printed):
 * the other ranks would wait for it for ever. Returns if one process. */
void cli_mpi_abort(int rc);

#endif
