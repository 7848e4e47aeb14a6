/* beamsim plot: the figures of a directory written by sweep, compare, run
 * --out or accuracy, drawn by gnuplot (beamsim/figures.h). */
#define _POSIX_C_SOURCE 200809L

#include <stdio.h>
#include <string.h>

#include "beamsim/figures.h"
#include "cli/cli_common.h"
#include "cli/cli_options.h"

static const cli_own plot_own[] = {
        {"select", 1, "KEY=VALUE",
         "only the groups whose grid value of KEY is VALUE,\n"
         "repeatable (e.g. --select effects.propulsion.force=8);\n"
         "lists every grid axis with what the selection kept"},
};

static const char *const plot_help[CLI_N_OPTS] = {
        [CLI_OPT_OUT] = "write the figures to ODIR instead of DIR",
        [CLI_OPT_THREADS] = "figures drawn at once (default: all cores)",
        [CLI_OPT_QUIET] = "nothing on stdout",
};

static int plot_option(void *args, int i, const char *value)
{
	(void)i;
	if (!strchr(value, '=') || value[0] == '=')
		return cli_usage("plot",
		                 "--select %s: expected KEY=VALUE, e.g. "
		                 "--select effects.propulsion.force=8",
		                 value);
	return cli_sets_add(args, "plot", value);
}

static const cli_spec plot_spec = {
        .name = "plot",
        .usage = "DIR [OPTIONS]",
        .about =
                "Draws the figures of DIR, the output directory of beamsim sweep, compare,\n"
                "run --out or accuracy, as NAME.png and NAME.svg with the data and the gnuplot\n"
                "script NAME.gp beside them (rerun `gnuplot NAME.gp` there to redraw):\n"
                "  sweep     p_traverse.*: p_traverse over the first two grid axes with 95%\n"
                "            intervals; traversal_vs_KEY.*: traversed, left and right type\n"
                "            against each axis with 95% bands, a panel per value of the other\n"
                "            axes; with kept trajectories (sweep --trajectories N),\n"
                "            trajectories_gNNN.* (each group's bundle by outcome and type) and\n"
                "            landscape_gNNN.* (the traversed ones over the energy landscape)\n"
                "  lattice   a sweep of a gate lattice: per group final_locations_gNNN.* (where\n"
                "            the trials ended, laid out as the field, with 95% intervals) and\n"
                "            lattice_gNNN.* (the stiffness map and the kept trajectories over it,\n"
                "            the essay's Fig. 3.5) instead of the bundle and landscape; compare "
                "of\n"
                "            lattices adds final_locations_gNNN.*, both sides side by side\n"
                "  compare   compare.*: both backends' p_traverse and their paired\n"
                "            differences; each backend's sweep figures in DIR/<backend>/\n"
                "  run --out random_force.*, ledger.*, landscape_path.*\n"
                "  accuracy  accuracy.*: error against speed, the Pareto front marked\n"
                "Without gnuplot (Debian package gnuplot-nox) the data and scripts are\n"
                "written and the images are not.\n",
        .positional = "DIR",
        .common = CLI_USES(CLI_OPT_OUT) | CLI_USES(CLI_OPT_OVERWRITE) | CLI_USES(CLI_OPT_THREADS) |
                  CLI_USES(CLI_OPT_QUIET),
        .help = plot_help,
        .out_arg = "ODIR",
        .own = plot_own,
        .n_own = 1,
        .option = plot_option,
};

int cmd_plot(int argc, char **argv)
{
	cli_common c = cli_common_default();
	cli_sets select = {0};
	const char *dir = NULL;
	int rc = cli_parse(&plot_spec, argc, argv, &c, &select, &dir);
	if (rc >= 0) {
		cli_sets_free(&select);
		cli_common_free(&c);
		return rc;
	}
	bsim_figures_def def = bsim_figures_def_default();
	def.out = c.out;
	def.overwrite = c.overwrite;
	def.select = select.ov;
	def.n_select = select.n;
	def.threads = (int)c.threads;
	bsim_figures_result res;
	bsim_error err;
	rc = cli_report(bsim_figures_plot(dir, &def, &res, &err), &err);
	if (rc == BSIM_OK) {
		for (int i = 0; i < res.n_notes; i++)
			cli_error("%s", res.notes[i]);
		if (!c.quiet) {
			printf("%s of %s: %d figure%s, %d drawn\n",
			       bsim_figures_kind_name(res.kind), cli_path(dir), res.n,
			       res.n == 1 ? "" : "s", res.drawn);
			/* every axis: what the selection kept of it */
			for (const char *p = res.selection; p && *p;) {
				size_t len = strcspn(p, "\n");
				int first = p == res.selection;
				printf("%s%.*s%s\n", first ? "  " : "    ", (int)len, p,
				       first ? ":" : "");
				p += len + (p[len] != '\0');
			}
			for (int i = 0; i < res.n; i++)
				printf("  %s.{png,svg,gp}\n", cli_path(res.paths[i]));
			if (res.drawn > 0)
				printf("  %s/index.html: every figure with a caption\n",
				       cli_path(c.out ? c.out : dir));
		}
		bsim_figures_result_free(&res);
	}
	cli_sets_free(&select);
	cli_common_free(&c);
	return rc;
}
