/* beamsim merge: joins the directories of the parts of one run made with
 * --shard I/N into the directory one process writes (docs/cluster.md);
 * the command the parts ran does the joining. */
#define _POSIX_C_SOURCE 200809L

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/sweep_dir.h"
#include "cli/cli_common.h"
#include "cli/cli_options.h"
#include "cli/cli_mpi.h"

static const cli_spec merge_spec = {
        .name = "merge",
        .usage = "PART_DIR... --out DIR [--threads N] [--quiet]",
        .about = "Joins the directories of the N parts of one sweep, comparison, markov build,\n"
                 "markov validate or essay (beamsim sweep|compare|markov build|markov\n"
                 "validate|essay ... --shard I/N --out PART_DIR, I = 1..N) into DIR, the\n"
                 "directory the command writes in one process (trials.csv, summary.json, .mat\n"
                 "twins, run.json; a comparison's report and pairs too; the maps of a markov\n"
                 "build; a validation's or an essay's tables and figures), the same bytes but\n"
                 "for the wall and CPU times (docs/cluster.md). Every part is needed once; parts "
                 "of another\n"
                 "run (other inputs), a missing or repeated part, or a damaged part.journal\n"
                 "are refused, naming the directory. The command line is read from the parts'\n"
                 "part.json (the experiment by its absolute path); kept trajectories\n"
                 "(--trajectories) run again here.\n",
        .positional = NULL,
        .common = CLI_USES(CLI_OPT_OUT) | CLI_USES(CLI_OPT_OVERWRITE) | CLI_USES(CLI_OPT_THREADS) |
                  CLI_USES(CLI_OPT_QUIET),
        .out_required = 1,
};

int cmd_merge(int argc, char **argv)
{
	/* The part directories are the arguments that are not options. */
	cli_common c = cli_common_default();
	const char **parts = calloc((size_t)argc + 1, sizeof *parts);
	char **opts = calloc((size_t)argc + 1, sizeof *opts);
	int n_parts = 0, n_opts = 0, rc = -1;
	if (!parts || !opts) {
		cli_error("out of memory");
		rc = CLI_FAIL;
	}
	for (int i = 0; rc < 0 && i < argc; i++) {
		int takes_value =
		        strcmp(argv[i], "--out") == 0 || strcmp(argv[i], "--threads") == 0;
		if (i > 0 && argv[i][0] != '-') {
			parts[n_parts++] = argv[i];
			continue;
		}
		opts[n_opts++] = argv[i];
		if (takes_value && i + 1 < argc)
			opts[n_opts++] = argv[++i];
	}
	if (rc < 0)
		rc = cli_parse(&merge_spec, n_opts, opts, &c, NULL, NULL);
	if (rc < 0 && n_parts == 0)
		rc = cli_usage("merge", "expected the directories of the parts, got none");
	bsim_sweep_dir_part first;
	bsim_error err;
	memset(&first, 0, sizeof first);
	if (rc < 0 && bsim_sweep_dir_part_read(parts[0], &first, &err) != BSIM_OK)
		rc = cli_report(BSIM_EINPUT, &err);
	static const struct {
		const char *command;
		int (*merge)(int argc, char **argv, const cli_merge *m);
	} kinds[] = {{"sweep", cmd_sweep_merge},
	             {"compare", cmd_compare_merge},
	             {"markov build", cmd_markov_merge},
	             {"markov validate", cmd_markov_validate_merge},
	             {"essay", cmd_essay_merge}};
	int kind = -1;
	for (int k = 0; rc < 0 && k < (int)(sizeof kinds / sizeof kinds[0]); k++)
		if (strcmp(first.command, kinds[k].command) == 0)
			kind = k;
	if (rc < 0 && kind < 0)
		rc = cli_usage("merge",
		               "%s: a part of a %s; merge joins the parts of a sweep, a "
		               "comparison, a markov build, a markov validate or an essay",
		               parts[0], first.command);
	if (rc < 0) {
		cli_merge m = {c.out, c.threads, c.quiet, parts, n_parts, c.overwrite};
		rc = kinds[kind].merge(first.argc, first.argv, &m);
	}
	bsim_sweep_dir_part_free(&first);
	cli_common_free(&c);
	free(parts);
	free(opts);
	return rc;
}
