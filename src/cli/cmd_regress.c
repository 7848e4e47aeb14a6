/* beamsim regress: run a stored sweep or comparison again from its record
 * and report, per side and group, what changed (beamsim/regress.h). Exit
 * status 3 beyond the rule. */
#define _POSIX_C_SOURCE 200809L

#include <stdio.h>

#include "beamsim/regress.h"
#include "cli/cli_wrote.h"
#include "cli/cli_common.h"
#include "cli/cli_options.h"
#include "cli/cli_progress.h"

static const cli_own regress_own[] = {
        {"exact", 0, NULL, "any changed trial counts"},
};

static const char *const regress_help[CLI_N_OPTS] = {
        [CLI_OPT_OUT] = "output directory for the rerun (required, not BASELINE_DIR)",
        [CLI_OPT_ALPHA] = "family-wise error rate (default: the stored rule's)",
        [CLI_OPT_MARGIN] = "smallest difference that counts (default: the stored rule's)",
};

static int regress_option(void *args, int i, const char *value)
{
	(void)i;
	(void)value;
	*(int *)args = 1;
	return CLI_OK;
}

static const cli_spec regress_spec = {
        .name = "regress",
        .usage = "BASELINE_DIR --out DIR [OPTIONS]",
        .about = "Runs the sweep or comparison stored in BASELINE_DIR (by beamsim sweep or\n"
                 "compare: run.json, inputs/, trials.csv) again with this beamsim, writes the\n"
                 "rerun to DIR as the original command would, and compares each backend's\n"
                 "trials with the stored ones pair by pair (same seed, group and trial):\n"
                 "DIR/regress.md and DIR/regress.json. Identical code and inputs reproduce\n"
                 "identical trials.\n"
                 "\n"
                 "A group has changed beyond tolerance when an event's Holm-adjusted McNemar\n"
                 "p-value is below --alpha and its probabilities differ by at least --margin\n"
                 "(defaults: the stored rule), or with --exact when any trial differs in any\n"
                 "trials.csv field. Exit status 3 if any group has.\n",
        .positional = "BASELINE_DIR",
        .common = CLI_USES(CLI_OPT_OUT) | CLI_USES(CLI_OPT_OVERWRITE) | CLI_USES(CLI_OPT_THREADS) |
                  CLI_USES(CLI_OPT_ALPHA) | CLI_USES(CLI_OPT_MARGIN) | CLI_USES(CLI_OPT_QUIET) |
                  CLI_USES(CLI_OPT_LIMIT),
        .help = regress_help,
        .out_required = 1,
        .own = regress_own,
        .n_own = 1,
        .option = regress_option,
};

int cmd_regress(int argc, char **argv)
{
	cli_common c = cli_common_default();
	int exact = 0;
	const char *baseline = NULL;
	int rc = cli_parse(&regress_spec, argc, argv, &c, &exact, &baseline);
	if (rc >= 0) {
		cli_common_free(&c);
		return rc;
	}
	cli_progress progress;
	cli_progress_init(&progress, !c.quiet, "trials");
	bsim_regress_def def = bsim_regress_def_default();
	def.baseline = baseline;
	def.out = c.out;
	def.overwrite = c.overwrite;
	def.threads = (int)c.threads;
	if (c.has_alpha)
		def.alpha = c.alpha;
	if (c.has_margin)
		def.margin = c.margin;
	def.exact = exact;
	def.progress = cli_progress_update;
	def.progress_user = &progress;
	bsim_regress_result res;
	bsim_error err;
	rc = bsim_regress_run(&def, &res, &err);
	cli_progress_finish(&progress);
	if (rc != BSIM_OK) {
		cli_common_free(&c);
		return cli_report(rc, &err);
	}
	if (!c.quiet) {
		for (int i = 0; i < res.n_sides; i++)
			printf("%s: %d of %d trials changed, %d of %d groups beyond tolerance\n",
			       res.side[i].label, res.side[i].changed, res.side[i].trials,
			       res.side[i].cmp.n_disagree, res.side[i].cmp.n_groups);
		cli_wrote(stdout, c.out);
	}
	rc = res.beyond > 0 ? CLI_DISAGREE : CLI_OK;
	bsim_regress_result_free(&res);
	cli_common_free(&c);
	return rc;
}
