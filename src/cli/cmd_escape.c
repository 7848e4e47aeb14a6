/* beamsim escape: the escape rate of each group of a stored sweep against
 * its landscape's barrier over the noise power, and the Arrhenius/Kramers
 * fit (analysis/escape.h, docs/first_passage.md). The analysis computes and
 * writes; this parses and prints. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "analysis/escape.h"
#include "cli/cli_wrote.h"
#include "cli/cli_common.h"
#include "cli/cli_options.h"

enum { OWN_RESOLUTION };

static const cli_own escape_own[] = {
        [OWN_RESOLUTION] = {"resolution", 1, "H",
                            "landscape grid spacing in m (default: as beamsim\n"
                            "landscape, 0.25 m on the essay's gate)"},
};

typedef struct escape_args {
	const char *dir;
	bsim_landscape_grid_def grid;
} escape_args;

static int escape_option(void *args, int i, const char *value)
{
	escape_args *a = args;
	char *end;
	if (i != OWN_RESOLUTION)
		return CLI_USAGE;
	a->grid.spacing = strtod(value, &end);
	if (end == value || *end || !(a->grid.spacing > 0) || !isfinite(a->grid.spacing))
		return cli_usage("escape", "--resolution %s: expected a grid spacing > 0 in m",
		                 value);
	return CLI_OK;
}

static const char *const escape_help[CLI_N_OPTS] = {
        [CLI_OPT_OUT] = "output directory (created if missing; required)",
};

static const cli_spec escape_spec = {
        .name = "escape",
        .usage = "SWEEP_DIR --out DIR [OPTIONS]",
        .about = "Reads the sweep stored in SWEEP_DIR (single gates) and, per group, the\n"
                 "traversal rate k (traversals / time at risk after the body first reaches\n"
                 "the beams), the landscape's barrier dE (the lowest pass above the start\n"
                 "basin's floor, as beamsim landscape) and the noise power D = Rm^2 / f;\n"
                 "fits ln k = ln k0 - dE / (c D) by least squares over the groups with a\n"
                 "barrier, noise and a traversal, and writes into DIR:\n"
                 "  kramers.csv    per group: barrier, noise, rate and interval, fit, "
                 "residual\n"
                 "  kramers.mat    its twin\n"
                 "  kramers.json   the fit: ln k0, slope, c, standard errors, residuals\n"
                 "  kramers        .png .svg .gp .dat: ln k against dE / D, and the "
                 "residuals\n",
        .positional = "SWEEP_DIR",
        .common = CLI_USES(CLI_OPT_OUT) | CLI_USES(CLI_OPT_OVERWRITE),
        .help = escape_help,
        .out_required = 1,
        .own = escape_own,
        .n_own = 1,
        .option = escape_option,
};

int cmd_escape(int argc, char **argv)
{
	cli_common c = cli_common_default();
	escape_args a = {.grid = bsim_landscape_grid_def_default()};
	int rc = cli_parse(&escape_spec, argc, argv, &c, &a, &a.dir);
	if (rc >= 0) {
		cli_common_free(&c);
		return rc;
	}
	bsim_error err;
	escape_def def = {.dir = a.dir, .out = c.out, .overwrite = c.overwrite, .grid = a.grid};
	escape_summary s;
	rc = cli_report(bsim_escape_run(&def, &s, &err), &err);
	if (rc == BSIM_OK) {
		printf("escape      %s: %d groups, %d landscapes, %d groups in the fit\n",
		       cli_path(a.dir), s.groups, s.scenes, s.used);
		if (s.fitted)
			printf("fit         ln k = %.3f (+- %.3f) %+.4g (+- %.2g) dE/D; k0 = %.3g "
			       "1/s, "
			       "c = %.3g +- %.2g m/(N s)\n"
			       "residuals   rms %.3f in ln k, R^2 %.3f; against Poisson error "
			       "chi^2 %.1f on %d dof, p = %.2g\n",
			       s.fit.a, s.fit.se_a, s.fit.b, s.fit.se_b, s.fit.k0, s.fit.c,
			       s.fit.se_c, s.fit.rms, s.fit.r2, s.fit.chisq_poisson, s.fit.n - 2,
			       s.fit.p_poisson);
		if (s.fitted)
			printf("verdict     %s\n", bsim_escape_fit_verdict(&s.fit));
		else
			printf("fit         none: fewer than 3 groups with a barrier, noise and a "
			       "traversal\n");
		cli_wrote(stdout, c.out);
		if (s.fitted && !s.drawn)
			cli_error(
			        "gnuplot not found: kramers.gp and its data are in %s; install the "
			        "Debian package gnuplot-nox and run `gnuplot kramers.gp` there",
			        c.out);
	}
	cli_common_free(&c);
	return rc;
}
