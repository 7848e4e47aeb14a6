/* beamsim essay: every number the essay's text reports and every trend it
 * states, run in beamsim's modes, each with an interval, a test against
 * the essay and a verdict (beamsim/essay_compare.h). Parses and prints. */
#define _POSIX_C_SOURCE 200809L

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/essay_compare.h"
#include "cli/cli_wrote.h"
#include "cli/cli_common.h"
#include "cli/cli_options.h"
#include "cli/cli_progress.h"
#include "cli/cli_mpi.h"

enum { OWN_MODE, OWN_LATTICE_TRIALS, OWN_SENSITIVITY, OWN_CONFIGS, OWN_SHARD };

#define ESSAY_MODES_MAX 5

static const cli_own essay_own[] = {
        [OWN_MODE] = {"mode", 1, "OPTS",
                      "a mode: KEY=VALUE:KEY=VALUE, backend options and scene keys\n"
                      "(a key with a dot, e.g. contact.tip_restitution=0.8), or\n"
                      "`default`; repeat for several (default: default,\n"
                      "contact_mode=essay, and\n"
                      "contact_mode=essay:contact.tip_restitution=0.8)"},
        [OWN_LATTICE_TRIALS] = {"lattice-trials", 1, "N",
                                "trials of the C-track (default: as --trials)"},
        [OWN_SENSITIVITY] = {"sensitivity", 0, NULL,
                             "also vary what the essay leaves unstated (rest threshold,\n"
                             "restitution, tip restitution, duration, side boundary, the\n"
                             "backend option impact_mass where the backend has it) at\n"
                             "the symmetric groups:\n"
                             "sensitivity.csv"},
        [OWN_CONFIGS] = {"configs", 1, "DIR",
                         "the shipped configs (thesis/gate.yaml, lattice/c_track.yaml;\n"
                         "default configs)"},
        [OWN_SHARD] = {"shard", 1, "I/N",
                       "run part I of N (I from 1 to N, as SLURM_ARRAY_TASK_ID of\n"
                       "--array=1-N): trial j of the sweeps, numbered along them in\n"
                       "turn, is part j mod N + 1's; DIR gets part.json and\n"
                       "part.journal, beamsim merge joins the N parts' directories\n"
                       "into the essay's (docs/cluster.md)"},
};

static const char *const essay_help[CLI_N_OPTS] = {
        [CLI_OPT_BACKEND] = "backend (default {default})",
        [CLI_OPT_TRIALS] = "trials per group (default 1000; the essay's 100)",
        [CLI_OPT_SEED] = "seed of the schedules (default 1)",
        [CLI_OPT_THREADS] = "threads (default all); results do not depend on it",
        [CLI_OPT_OUT] = "output directory (required; created if missing)",
};

typedef struct essay_args {
	const char *modes[ESSAY_MODES_MAX];
	int n_modes;
	long lattice_trials;
	int sensitivity;
	const char *configs;
	int configs_given;
	int shard, shards; /* 1-based part of shards; 0: the whole run */
} essay_args;

static int essay_option(void *args, int i, const char *value)
{
	essay_args *a = args;
	switch (i) {
	case OWN_MODE:
		if (a->n_modes == ESSAY_MODES_MAX)
			return cli_usage("essay", "--mode: at most %d modes", ESSAY_MODES_MAX);
		a->modes[a->n_modes++] = strcmp(value, "default") == 0 ? "" : value;
		return CLI_OK;
	case OWN_LATTICE_TRIALS:
		if (cli_parse_long(value, 1, 1000000, &a->lattice_trials))
			return cli_usage("essay", "--lattice-trials %s: expected an integer >= 1",
			                 value);
		return CLI_OK;
	case OWN_SENSITIVITY:
		a->sensitivity = 1;
		return CLI_OK;
	case OWN_CONFIGS:
		a->configs = value;
		a->configs_given = 1;
		return CLI_OK;
	case OWN_SHARD:
		return cli_shard_parse("essay", value, &a->shard, &a->shards);
	}
	return CLI_USAGE;
}

static const cli_spec essay_spec = {
        .name = "essay",
        .usage = "--out DIR [OPTIONS]",
        .about = "Every traversal probability the essay's text reports (Figs. 3.2 and 3.3: left\n"
                 "and right types at 500:500, 300:500, 100:500; Sec. 3.3: the C-track) and\n"
                 "every trend it states (H1: p rises with F_prop, rises with Rm from 0 to 20 N\n"
                 "and falls from 20 to 40 N, most at 9 N; Fig. 3.4a and b), run in each mode.\n"
                 "A level is tested against the essay's count (Fisher's exact test), a trend\n"
                 "by Cochran-Armitage or a Wald z test; `consistent` or `differs` at 0.05\n"
                 "(docs/essay.md). Writes DIR/essay.csv (+ .mat), DIR/essay.md, the figure\n"
                 "DIR/essay.png and with --sensitivity DIR/sensitivity.csv (+ .mat).\n"
                 "Every sweep's trials are journaled as they end, so a stopped or killed run\n"
                 "continues with --resume; under `mpirun -np N` they are spread over the\n"
                 "ranks, with --shard I/N over N processes joined by beamsim merge, the\n"
                 "files those of one process (docs/cluster.md).\n",
        .common = CLI_USES(CLI_OPT_OUT) | CLI_USES(CLI_OPT_OVERWRITE) | CLI_USES(CLI_OPT_BACKEND) |
                  CLI_USES(CLI_OPT_TRIALS) | CLI_USES(CLI_OPT_SEED) | CLI_USES(CLI_OPT_THREADS) |
                  CLI_USES(CLI_OPT_QUIET) | CLI_USES(CLI_OPT_RESUME),
        .help = essay_help,
        .out_required = 1,
        .own = essay_own,
        .n_own = 5,
        .option = essay_option,
};

/* The command line a shard keeps for merge: --configs made absolute, and
 * given when it was not (merge may run in another directory). */
static char **essay_stored_argv(int argc, char **argv, const essay_args *a, int *n,
                                char ***extended)
{
	*extended = calloc((size_t)argc + 3, sizeof **extended);
	if (!*extended)
		return NULL;
	memcpy(*extended, argv, (size_t)argc * sizeof *argv);
	*n = argc;
	const char *configs = a->configs;
	if (!a->configs_given) {
		(*extended)[(*n)++] = "--configs";
		(*extended)[(*n)++] = (char *)a->configs;
		configs = (*extended)[*n - 1];
	}
	return cli_stored_argv_paths(*n, *extended, &configs, 1);
}

/* Each mode's verdicts, as the README states the default physics': of its
 * levels and of its trends, how many are consistent with the essay's. The
 * modes in the order of their first row. */
static void essay_modes_print(const bsim_essay_result *r)
{
	for (int i = 0; i < r->n; i++) {
		const char *mode = r->rows[i].mode;
		int seen = 0;
		for (int j = 0; j < i && !seen; j++)
			seen = strcmp(r->rows[j].mode, mode) == 0;
		if (seen)
			continue;
		int n[2] = {0, 0}, ok[2] = {0, 0};
		for (int j = i; j < r->n; j++) {
			if (strcmp(r->rows[j].mode, mode) != 0)
				continue;
			const int t = r->rows[j].kind == BSIM_ESSAY_TREND;
			n[t]++;
			ok[t] += r->rows[j].consistent != 0;
		}
		printf("  %s: consistent with %d of the essay's %d levels and %d of its %d "
		       "trends\n",
		       mode, ok[0], n[0], ok[1], n[1]);
	}
}

static int essay_main(int argc, char **argv, const cli_merge *m)
{
	cli_common c = cli_common_default();
	essay_args a = {.configs = "configs"};
	int rc = cli_parse(&essay_spec, argc, argv, &c, &a, NULL);
	if (rc < 0 && a.shards > 0 && cli_mpi_size() > 1)
		rc = cli_usage("essay",
		               "--shard runs one part in one process: not under mpirun, which "
		               "spreads the whole run over its %d ranks",
		               cli_mpi_size());
	if (rc >= 0) {
		cli_common_free(&c);
		return rc;
	}
	bsim_essay_config cfg = bsim_essay_config_default();
	if (m) {
		cli_merge_apply(m, &c);
		a.shard = a.shards = 0;
		cfg.spread.merge = m->parts;
		cfg.spread.n_merge = m->n_parts;
	}
	char **stored = NULL, **extended = NULL;
	int n_stored = 0;
	if (a.shards > 0) {
		cfg.spread.spread = BSIM_SPREAD_SHARD;
		cfg.spread.part.index = a.shard - 1;
		cfg.spread.part.count = a.shards;
		stored = essay_stored_argv(argc, argv, &a, &n_stored, &extended);
		cfg.spread.argc = stored ? n_stored : 0;
		cfg.spread.argv = stored;
	}
	int rank = cli_mpi_rank();
	cfg.configs = a.configs;
	if (c.backend)
		cfg.backend = c.backend;
	if (a.n_modes > 0) {
		cfg.modes = a.modes;
		cfg.n_modes = a.n_modes;
	}
	if (c.trials)
		cfg.trials = (int)c.trials;
	cfg.lattice_trials = a.lattice_trials ? (int)a.lattice_trials : cfg.trials;
	cfg.sens_trials = a.sensitivity ? cfg.trials : 0;
	if (c.has_seed)
		cfg.seed = c.seed;
	cfg.threads = (int)c.threads;
	cfg.resume = c.resume;
	cfg.overwrite = c.overwrite;
	cfg.stop = &cli_stop;
	cli_mpi_spread(&cfg.spread.spread, &cfg.spread.part, &cfg.spread.agree,
	               bsim_sweep_record_size(0), cfg.stop);
	cli_progress progress;
	cli_progress_init(&progress, !c.quiet && rank == 0, "trials");
	cfg.progress = rank == 0 ? cli_progress_update : NULL;
	cfg.progress_user = &progress;
	cli_signals_install();
	bsim_essay_result r;
	bsim_figures_result fig;
	bsim_error err;
	rc = bsim_essay_compare_store(c.out, &cfg, &r, &fig, &err);
	cli_progress_finish(&progress);
	cli_signals_restore();
	cli_stored_argv_free(stored, n_stored, extended);
	free(extended);
	if (rc != BSIM_OK || cfg.spread.spread == BSIM_SPREAD_SEND || a.shards > 0) {
		rc = cli_spread_end("essay", rc, &err, r.journal, argc, argv, a.shard, a.shards,
		                    c.out, c.quiet);
		if (rc == CLI_OK) {
			bsim_figures_result_free(&fig);
			bsim_essay_result_free(&r);
		}
		cli_common_free(&c);
		return rc;
	}
	rc = cli_report(rc, &err);
	if (rc == BSIM_OK) {
		if (!c.quiet) {
			printf("essay: %d rows, %ld trials in %.1f s\n", r.n, r.trials_run,
			       r.wall_seconds);
			essay_modes_print(&r);
			cli_wrote(stdout, c.out);
		}
		for (int i = 0; i < fig.n_notes; i++)
			cli_error("%s", fig.notes[i]);
		bsim_figures_result_free(&fig);
		bsim_essay_result_free(&r);
	}
	cli_common_free(&c);
	return rc;
}

int cmd_essay(int argc, char **argv)
{
	return essay_main(argc, argv, NULL);
}

int cmd_essay_merge(int argc, char **argv, const cli_merge *m)
{
	return essay_main(argc, argv, m);
}
