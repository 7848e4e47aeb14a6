/* beamsim plot: the figures of a directory written by sweep, compare, run
 * --out or accuracy, drawn by gnuplot (beamsim/figures.h). */
#define _POSIX_C_SOURCE 200809L

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/figures.h"
#include "cli_common.h"
#include "cli_store.h"

static const char plot_help[] =
        "Usage: beamsim plot DIR [OPTIONS]\n"
        "\n"
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
        "            the essay's Fig. 3.5) instead of the bundle and landscape; compare of\n"
        "            lattices adds final_locations_gNNN.*, both sides side by side\n"
        "  compare   compare.*: both backends' p_traverse and their paired\n"
        "            differences; each backend's sweep figures in DIR/<backend>/\n"
        "  run --out random_force.*, ledger.*, landscape_path.*\n"
        "  accuracy  accuracy.*: error against speed, the Pareto front marked\n"
        "Without gnuplot (Debian package gnuplot-nox) the data and scripts are\n"
        "written and the images are not.\n"
        "\n"
        "Options:\n"
        "  --out ODIR             write the figures to ODIR instead of DIR\n"
        "  --select KEY=VALUE     only the groups whose grid value of KEY is VALUE,\n"
        "                         repeatable (e.g. --select effects.propulsion.force=8)\n"
        "  --threads N            figures drawn at once (default: all cores)\n"
        "  --quiet                nothing on stdout\n"
        "  -h, --help             show this help\n";

enum { OPT_OUT = 256, OPT_SELECT, OPT_THREADS, OPT_QUIET };

static const struct option plot_options[] = {
        {"out", required_argument, NULL, OPT_OUT},
        {"select", required_argument, NULL, OPT_SELECT},
        {"threads", required_argument, NULL, OPT_THREADS},
        {"quiet", no_argument, NULL, OPT_QUIET},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
};

typedef struct plot_args {
	const char *dir;
	const char *out;
	cli_sets select;
	long threads;
	int quiet;
} plot_args;

/* Fills a; returns -1 to go on, else the exit status. */
static int plot_parse(int argc, char **argv, plot_args *a)
{
	int c;
	opterr = 0;
	while ((c = getopt_long(argc, argv, ":h", plot_options, NULL)) != -1) {
		int rc = CLI_OK;
		switch (c) {
		case 'h':
			fputs(plot_help, stdout);
			return CLI_OK;
		case OPT_OUT:
			a->out = optarg;
			break;
		case OPT_SELECT:
			if (!strchr(optarg, '=') || optarg[0] == '=')
				rc = cli_usage("plot",
				               "--select %s: expected KEY=VALUE, e.g. "
				               "--select effects.propulsion.force=8",
				               optarg);
			else
				rc = cli_sets_add(&a->select, "plot", optarg);
			break;
		case OPT_THREADS:
			if (cli_parse_long(optarg, 1, 4096, &a->threads) != 0)
				rc = cli_usage("plot", "--threads %s: expected an integer >= 1",
				               optarg);
			break;
		case OPT_QUIET:
			a->quiet = 1;
			break;
		default:
			return cli_bad_option("plot", argv, c);
		}
		if (rc != CLI_OK)
			return rc;
	}
	if (optind + 1 != argc)
		return cli_usage("plot",
		                 optind == argc ? "missing DIR" : "expected one DIR, got %d",
		                 argc - optind);
	a->dir = argv[optind];
	return -1;
}

int cmd_plot(int argc, char **argv)
{
	plot_args a = {0};
	int rc = plot_parse(argc, argv, &a);
	if (rc >= 0) {
		cli_sets_free(&a.select);
		return rc;
	}
	/* A reader of DIR: a mix of two runs' files is refused. The figures are
	 * written into a staging area and join the directory's set at the end
	 * (beamsim/outdir.h): into DIR itself, beside its files; into ODIR,
	 * replacing what a previous plot left there. */
	int has_manifest = 0;
	bsim_error err;
	if (bsim_outdir_verify(a.dir, &has_manifest, &err) != BSIM_OK) {
		cli_error("%s", err.msg);
		cli_sets_free(&a.select);
		return CLI_USAGE;
	}
	cli_session ss;
	rc = cli_session_open(&ss, a.out ? a.out : a.dir, 0, NULL, 0, 0, NULL);
	if (rc != CLI_OK) {
		cli_sets_free(&a.select);
		return rc;
	}
	ss.add = a.out == NULL;
	size_t stage_len = strlen(ss.stage);
	bsim_figures_def def = bsim_figures_default();
	def.out = ss.stage;
	def.select = a.select.ov;
	def.n_select = a.select.n;
	def.threads = (int)a.threads;
	bsim_figures_result res;
	rc = bsim_figures_draw(a.dir, &def, &res, &err);
	if (rc == BSIM_OK) {
		for (int i = 0; i < res.n_notes; i++)
			cli_error("%s", res.notes[i]);
	} else {
		cli_error("%s", err.msg);
	}
	rc = cli_session_close(&ss, rc, "plot");
	if (rc == BSIM_OK && !a.quiet) {
		printf("%s of %s: %d figure%s, %d drawn\n", bsim_figures_kind_name(res.kind), a.dir,
		       res.n, res.n == 1 ? "" : "s", res.drawn);
		for (int i = 0; i < res.n; i++) {
			/* "OUT/NAME" as the user knows OUT */
			const char *name = res.paths[i] + stage_len;
			printf("  %s%s.{png,svg,gp}\n", a.out ? a.out : a.dir, name);
		}
	}
	bsim_figures_result_free(&res);
	cli_sets_free(&a.select);
	return rc;
}
