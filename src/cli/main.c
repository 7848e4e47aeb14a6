/* The beamsim program: dispatch to one subcommand per file. */
#include <errno.h>
#include <stdio.h>
#include <string.h>

#include "beamsim/backend_plugin.h"
#include "beamsim/version.h"
#include "cli/cli_common.h"
#include "cli/cli_mpi.h"

typedef struct cli_command {
	const char *name;
	cli_command_fn run;
	const char *summary;
} cli_command;

static const cli_command commands[] = {
        {"run", cmd_run, "run one trial of a scene, print its outcome, record a trajectory"},
        {"sweep", cmd_sweep, "run every group and trial of an experiment in parallel"},
        {"merge", cmd_merge,
         "join the parts of a run as a job array (sweep|compare|essay|markov build|markov "
         "validate --shard I/N)"},
        {"compare", cmd_compare,
         "run an experiment on two backends, or two settings of one, pair by pair"},
        {"regress", cmd_regress, "rerun a stored sweep or comparison and report what changed"},
        {"backends", cmd_backends, "list the physics backends and their options"},
        {"bench", cmd_bench, "measure the speed of a backend on the essay's experiments"},
        {"accuracy", cmd_accuracy,
         "what accuracy costs in time: error against speed per backend and step"},
        {"essay", cmd_essay,
         "the essay's reported numbers and trends against beamsim, mode by mode"},
        {"landscape", cmd_landscape,
         "the potential energy landscape of a scene, its barriers and figures"},
        {"escape", cmd_escape,
         "escape rate of a sweep's groups against barrier over noise power (Kramers)"},
        {"markov", cmd_markov,
         "predict a gate lattice from single-gate maps: build, predict, validate"},
        {"plot", cmd_plot,
         "draw the figures of a sweep, comparison, run, accuracy study or essay comparison"},
        {"video", cmd_video, "an MP4 of one trial, on one backend or side by side"},
};

#define N_COMMANDS ((int)(sizeof commands / sizeof commands[0]))

static void usage(FILE *f)
{
	fputs("Usage: beamsim COMMAND [OPTIONS]\n"
	      "       beamsim COMMAND --help   (or: beamsim help COMMAND)\n"
	      "       beamsim --version\n"
	      "\n"
	      "Simulates a self-propelled disk traversing elastic beam gates.\n"
	      "\n"
	      "Commands:\n",
	      f);
	for (int i = 0; i < N_COMMANDS; i++)
		fprintf(f, "  %-10s %s\n", commands[i].name, commands[i].summary);
	fputs("\n"
	      "Exit status: 0 success, 1 a run failed, 2 bad usage or a bad scene or\n"
	      "experiment file, 3 compare or regress found disagreement beyond tolerance,\n"
	      "130 or 143 stopped by SIGINT or SIGTERM (sweep and compare keep their\n"
	      "finished trials: rerun with --resume).\n"
	      "\n"
	      "Guide: README.md and docs/ of the source tree. Scenes and experiments to\n"
	      "start from: configs/ there, installed in share/beamsim/configs (thesis/ the\n"
	      "essay's gate and experiments, lattice/ its 9 x 9 field, hard/ hard cases).\n",
	      f);
}

/* What the command printed must have reached standard output: a full disk
 * or a closed pipe is a failed run, not a success with a lost report. */
static int close_stdout(int rc)
{
	int saved = 0;
	errno = 0;
	if (ferror(stdout)) {
		clearerr(stdout); /* flushing again tells why the write failed */
		saved = fflush(stdout) != 0 && errno ? errno : EIO;
	} else if (fflush(stdout) != 0) {
		saved = errno ? errno : EIO;
	}
	if (fclose(stdout) != 0 && !saved)
		saved = errno ? errno : EIO;
	if (!saved)
		return rc;
	fprintf(stderr, "beamsim: standard output: write failed: %s\n", strerror(saved));
	return rc != CLI_OK ? rc : CLI_FAIL;
}

/* The command called name, or NULL after saying it is unknown (with the
 * nearest name, or the usage). */
static const cli_command *find_command(const char *name)
{
	const char *names[N_COMMANDS];
	for (int i = 0; i < N_COMMANDS; i++) {
		if (strcmp(name, commands[i].name) == 0)
			return &commands[i];
		names[i] = commands[i].name;
	}
	const char *near = cli_nearest(name, names, N_COMMANDS);
	if (near) {
		cli_error("unknown command '%s'; did you mean '%s'? (beamsim --help lists them)",
		          name, near);
		return NULL;
	}
	cli_error("unknown command '%s'", name);
	fputc('\n', stderr);
	usage(stderr);
	return NULL;
}

static int dispatch(int argc, char **argv)
{
	if (argc < 2) {
		usage(stderr);
		return CLI_USAGE;
	}
	const char *name = argv[1];
	if (strcmp(name, "help") == 0 && argc > 2) {
		/* beamsim help COMMAND [SUBCOMMAND]: the command's own help, as
		 * COMMAND [SUBCOMMAND] --help. */
		if (argc > 4) {
			cli_error("help: expected a command and at most a subcommand, got %d words",
			          argc - 2);
			return CLI_USAGE;
		}
		const cli_command *c = find_command(argv[2]);
		char help[] = "--help";
		char *help_argv[4] = {argv[2], argc > 3 ? argv[3] : help, argc > 3 ? help : NULL,
		                      NULL};
		return c ? c->run(argc - 1, help_argv) : CLI_USAGE;
	}
	if (strcmp(name, "--help") == 0 || strcmp(name, "-h") == 0 || strcmp(name, "help") == 0) {
		usage(stdout);
		return CLI_OK;
	}
	if (strcmp(name, "--version") == 0 || strcmp(name, "-V") == 0) {
		const char *commit = bsim_version_commit();
		printf("beamsim %s\n", bsim_version());
		printf("commit %s\n", commit[0] ? commit : "unknown");
		for (const bsim_backend *const *b = bsim_backend_list(); *b; b++)
			printf("backend %s: %s %s\n", (*b)->name, (*b)->engine ? (*b)->engine : "",
			       (*b)->version ? (*b)->version : "");
		printf("compiler %s\n", bsim_version_compiler());
		return CLI_OK;
	}
	/* A plug-in BEAMSIM_PLUGINS names and that fails to load stops every
	 * command: what it would run is not there. */
	bsim_error err;
	if (bsim_backend_plugins_status(&err) != BSIM_OK) {
		cli_error("%s", err.msg);
		return CLI_USAGE;
	}
	const cli_command *c = find_command(name);
	/* Only sweep, compare, essay, markov build and markov validate spread
	 * their work over an MPI job's ranks (docs/cluster.md): any other
	 * command would run whole in every rank. */
	int spread = c && (c->run == cmd_sweep || c->run == cmd_compare || c->run == cmd_essay ||
	                   (c->run == cmd_markov && argc > 2 &&
	                    (strcmp(argv[2], "build") == 0 || strcmp(argv[2], "validate") == 0)));
	if (c && !spread && cli_mpi_size() > 1) {
		cli_error("%s runs in one process: start it without mpirun (of the commands, "
		          "sweep, compare, essay, markov build and markov validate spread over MPI "
		          "ranks; docs/cluster.md)",
		          name);
		cli_mpi_abort(CLI_USAGE);
		return CLI_USAGE;
	}
	return c ? c->run(argc - 1, argv + 1) : CLI_USAGE;
}

int main(int argc, char **argv)
{
	if (argc > 0 && argv[0] && argv[0][0])
		cli_program = argv[0];
	int rc = cli_mpi_init(&argc, &argv);
	if (rc == CLI_OK)
		rc = close_stdout(dispatch(argc, argv));
	cli_mpi_finish();
	return rc;
}
