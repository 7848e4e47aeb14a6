/* beamsim sweep: every group and trial of an experiment, in parallel, into
 * DIR (beamsim/sweep_dir.h), with the p_traverse table and the groups'
 * splits (cli_outcomes.h) on stdout. */
#define _POSIX_C_SOURCE 200809L

#include <stdio.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/output.h"
#include "beamsim/sweep_dir.h"
#include "beamsim/limits.h"
#include "cli/cli_wrote.h"
#include "cli/cli_common.h"
#include "cli/cli_options.h"
#include "cli/cli_outcomes.h"
#include "cli/cli_progress.h"
#include "cli/cli_mpi.h"

static const cli_own sweep_own[] = {
        {"overlap", 0, NULL,
         "measure each trial's deepest body-beam overlap\n(trials.csv overlap_max; costs time)"},
        {"shard", 1, "I/N",
         "run part I of N (I from 1 to N, as SLURM_ARRAY_TASK_ID of\n--array=1-N): trial "
         "g*trials+t is part (g*trials+t) mod N + 1's;\nDIR gets part.json and part.journal, "
         "beamsim merge joins\nthe N parts' directories into the sweep's (docs/cluster.md)"},
};

typedef struct sweep_args {
	int overlap;
	int shard, shards; /* 1-based part of shards; 0: the whole sweep */
} sweep_args;

static int sweep_option(void *args, int i, const char *value)
{
	sweep_args *a = args;
	if (i == 0) {
		a->overlap = 1;
		return CLI_OK;
	}
	return cli_shard_parse("sweep", value, &a->shard, &a->shards);
}

static const cli_spec sweep_spec = {
        .name = "sweep",
        .usage = "EXPERIMENT --out DIR [OPTIONS]",
        .about = "Runs every trial of every group of the experiment file EXPERIMENT and writes\n"
                 "DIR/summary.json (per-group counts, p_traverse and its 95% Wilson interval)\n"
                 "and DIR/trials.csv (one row per trial). The results do not depend on "
                 "--threads.\n"
                 "DIR/run.json and DIR/inputs/ record the run (the grid that ran, --grid\n"
                 "axes and --set included), so `beamsim regress DIR` can repeat it. A group\n"
                 "without random force is deterministic: its one trial runs once and fills\n"
                 "every row. Unstable trials (non-finite state, or energy\n"
                 "created beyond the ledger's bound) are counted and written like the others,\n"
                 "and make the exit status 1. The files appear together when the sweep is "
                 "done\n"
                 "(DIR/manifest.json lists them); finished trials are journaled as they end, "
                 "so a\n"
                 "stopped or killed sweep continues with --resume and gives the same files.\n",
        .positional = "EXPERIMENT",
        .common = CLI_USES(CLI_OPT_OUT) | CLI_USES(CLI_OPT_OVERWRITE) | CLI_USES(CLI_OPT_BACKEND) |
                  CLI_USES(CLI_OPT_BACKEND_OPT) | CLI_USES(CLI_OPT_THREADS) |
                  CLI_USES(CLI_OPT_TRIALS) | CLI_USES(CLI_OPT_SEED) | CLI_USES(CLI_OPT_SET) |
                  CLI_USES(CLI_OPT_GRID) | CLI_USES(CLI_OPT_TRAJECTORIES) |
                  CLI_USES(CLI_OPT_TRAJECTORY_STRIDE) | CLI_USES(CLI_OPT_QUIET) |
                  CLI_USES(CLI_OPT_RESUME) | CLI_USES(CLI_OPT_LIMIT),
        .out_required = 1,
        .own = sweep_own,
        .n_own = 2,
        .option = sweep_option,
        .after = "Under the p_traverse table: each group's left/right split of the traversals\n"
                 "(when some group has both types or the beams differ), or for a lattice its\n"
                 "end/side/stuck split, as fractions with 95% Wilson intervals.\n"
                 "A lattice experiment also writes DIR/lattice_map.csv, final_locations.csv,\n"
                 "transitions.csv, gate_entries.csv and beam_peaks.csv (docs/lattice.md).\n",
};

/* "3 ranks x " */
static const char *cli_ranks_text(int ranks)
{
	static char text[32];
	snprintf(text, sizeof text, "%d ranks x ", ranks);
	return text;
}

static void sweep_report(const char *out, const bsim_sweep_dir_result *res, const cli_sets *sets)
{
	const bsim_sweep_result *r = &res->r;
	long n = r->trials_run, rows = (long)r->n_groups * r->trials;
	bsim_output_table(stdout, &res->e, r);
	cli_outcomes_print(stdout, &res->e, r,
	                   !r->lattice && cli_outcomes_asymmetric(&res->e, sets));
	int ranks = cli_mpi_size();
	printf("\n%ld trials, %ld steps in %.3f s on %s%d thread%s: %.0f trials/s, %.3g steps/s\n",
	       n, r->total_steps, r->wall_seconds, ranks > 1 ? cli_ranks_text(ranks) : "",
	       res->threads, res->threads == 1 ? "" : "s", cli_per_second(n, r->wall_seconds),
	       cli_per_second(r->total_steps, r->wall_seconds));
	if (n != rows)
		printf("(%ld rows: the groups without random force ran one trial each)\n", rows);
	/* A table over mat_rows has no twin (a note said so): the list
	 * shows the files there are. */
	cli_wrote(stdout, out);
}

static int sweep_main(int argc, char **argv, const cli_merge *m)
{
	cli_common c = cli_common_default();
	sweep_args a = {0};
	const char *experiment = NULL;
	char **stored = NULL;
	int rc = cli_parse(&sweep_spec, argc, argv, &c, &a, &experiment);
	bsim_sweep_dir_def def = bsim_sweep_dir_def_default();
	if (rc < 0) {
		def.backend = cli_backend_with_opts(
		        &c, "sweep", c.backend ? c.backend : bsim_backend_default()->name,
		        &def.opts);
		rc = def.backend ? -1 : CLI_USAGE;
	}
	if (rc < 0 && a.shards > 0 && cli_mpi_size() > 1)
		rc = cli_usage("sweep",
		               "--shard runs one part in one process: not under mpirun, "
		               "which spreads the whole sweep over its %d ranks",
		               cli_mpi_size());
	if (rc >= 0) {
		cli_common_free(&c);
		return rc;
	}
	if (m) {
		cli_merge_apply(m, &c);
		a.shard = a.shards = 0;
		def.merge = m->parts;
		def.n_merge = m->n_parts;
	}
	int rank = cli_mpi_rank();
	cli_progress progress;
	cli_progress_init(&progress, !c.quiet && rank == 0, "trials");
	def.experiment = experiment;
	def.out = c.out;
	def.sets = c.sets.ov;
	def.n_sets = c.sets.n;
	def.grid = c.sets.grid;
	def.n_grid = c.sets.n_grid;
	def.trials = c.trials;
	def.has_seed = c.has_seed;
	def.seed = c.seed;
	def.threads = (int)c.threads;
	def.overlap = a.overlap;
	def.keep = (int)c.keep;
	def.keep_stride = (int)c.keep_stride;
	def.resume = c.resume;
	def.overwrite = c.overwrite;
	def.progress = rank == 0 ? cli_progress_update : NULL;
	def.progress_user = &progress;
	def.stop = &cli_stop;
	if (a.shards > 0) {
		def.spread = BSIM_SPREAD_SHARD;
		def.part.index = a.shard - 1;
		def.part.count = a.shards;
		stored = cli_stored_argv(argc, argv, experiment);
		def.argc = stored ? argc : 0;
		def.argv = stored;
	}
	cli_mpi_spread(&def.spread, &def.part, &def.agree, bsim_sweep_record_size(0), def.stop);
	cli_estimate estimate = {def.backend, 1};
	if (rank == 0 && !m) {
		def.planned = cli_estimate_sides;
		def.planned_user = &estimate;
	}
	bsim_sweep_dir_result res;
	bsim_error err;
	cli_signals_install();
	rc = bsim_sweep_dir_run(&def, &res, &err);
	cli_signals_restore();
	cli_progress_finish(&progress);
	cli_stored_argv_free(stored, argc, argv);
	if (rc == BSIM_ESTOPPED && rank > 0) {
		/* stopped by the job's signal: rank 0 says so, and how to resume */
		cli_common_free(&c);
		return rc;
	}
	if (rc != BSIM_OK) {
		if (rank > 0)
			cli_error("rank %d of %d: %s", rank, cli_mpi_size(), err.msg);
		else
			cli_report(rc, &err);
		rc = rank > 0 ? rc : cli_run_end(rc, res.journal, argc, argv);
		cli_common_free(&c);
		cli_mpi_abort(rc);
		return rc;
	}
	if (def.spread == BSIM_SPREAD_SEND) {
		bsim_sweep_dir_result_free(&res);
		cli_common_free(&c);
		return CLI_OK;
	}
	if (a.shards > 0) {
		if (!c.quiet)
			printf("part %d of %d of the sweep in %s; beamsim merge joins the %d "
			       "parts' "
			       "directories\n",
			       a.shard, a.shards, c.out, a.shards);
		bsim_sweep_dir_result_free(&res);
		cli_common_free(&c);
		return CLI_OK;
	}
	if (!c.quiet)
		sweep_report(c.out, &res, &c.sets);
	cli_solver_warning(def.backend->name, &res.r.solver, "summary.json");
	/* Unstable trials fail the sweep (after its files are written): one line
	 * with their number and the first one's reason and replay. */
	if (res.unstable > 0) {
		long rows = (long)res.r.n_groups * res.r.trials;
		cli_error("%ld of %ld trials unstable on the %s backend (outcome unstable in "
		          "%s/trials.csv); the first, group %ld trial %ld: %s",
		          res.unstable, rows, def.backend->name, c.out,
		          res.first_unstable / res.r.trials, res.first_unstable % res.r.trials,
		          res.unstable_why);
		rc = CLI_FAIL;
	}
	bsim_sweep_dir_result_free(&res);
	cli_common_free(&c);
	return rc;
}

int cmd_sweep(int argc, char **argv)
{
	return sweep_main(argc, argv, NULL);
}

/* sweep's command line (argv[0] "sweep") run as the merge m of its parts
 * (cmd_merge.c). */
int cmd_sweep_merge(int argc, char **argv, const cli_merge *m)
{
	return sweep_main(argc, argv, m);
}
