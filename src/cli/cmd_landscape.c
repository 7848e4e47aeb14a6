/* beamsim landscape: the potential energy landscape of a scene on a grid,
 * its barriers, and the files and figures that show them. The library
 * computes and writes (beamsim/landscape.h); this parses and prints. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/landscape.h"
#include "beamsim/landscape_barriers.h"
#include "beamsim/limits.h"
#include "cli/cli_wrote.h"
#include "cli/cli_common.h"
#include "cli/cli_options.h"
#include "util/file_read.h"

enum { OWN_RESOLUTION, OWN_REGION, OWN_JSON };

static const cli_own landscape_own[] = {
        [OWN_RESOLUTION] = {"resolution", 1, "H",
                            "grid spacing in m (default: the region's longer side\n"
                            "/ 260, 0.25 m on the essay's gate)"},
        [OWN_REGION] = {"region", 1, "X0,X1,Y0,Y1",
                        "the region in m (default: x within the side\n"
                        "boundaries, y from the body's start to success_y)"},
        [OWN_JSON] = {"json", 0, NULL,
                      "print DIR/landscape.json (the grid, the start and every\n"
                      "pass with its path) instead of the table"},
};

typedef struct landscape_args {
	const char *scene;
	bsim_landscape_grid_def grid;
	int json;
} landscape_args;

/* Four numbers separated by commas, each finite. 0 on success. */
static int parse_region(const char *text, double r[4])
{
	const char *p = text;
	for (int i = 0; i < 4; i++) {
		char *end;
		r[i] = strtod(p, &end);
		if (end == p || !isfinite(r[i]))
			return -1;
		if (i < 3 && *end != ',')
			return -1;
		p = end + (i < 3);
		if (i == 3 && *end != '\0')
			return -1;
	}
	return 0;
}

static int landscape_option(void *args, int i, const char *value)
{
	landscape_args *a = args;
	char *end;
	switch (i) {
	case OWN_RESOLUTION:
		a->grid.spacing = strtod(value, &end);
		if (end == value || *end || !(a->grid.spacing > 0) || !isfinite(a->grid.spacing))
			return cli_usage("landscape",
			                 "--resolution %s: expected a grid spacing > 0 in m",
			                 value);
		return CLI_OK;
	case OWN_REGION:
		a->grid.has_region = 1;
		if (parse_region(value, a->grid.region) != 0 ||
		    !(a->grid.region[0] < a->grid.region[1]) ||
		    !(a->grid.region[2] < a->grid.region[3]))
			return cli_usage("landscape",
			                 "--region %s: expected X0,X1,Y0,Y1 in m with X0 < X1 "
			                 "and Y0 < Y1, e.g. --region -25,25,0,65",
			                 value);
		return CLI_OK;
	case OWN_JSON:
		a->json = 1;
		return CLI_OK;
	}
	return CLI_USAGE;
}

static const char *const landscape_help[CLI_N_OPTS] = {
        [CLI_OPT_OUT] = "output directory (created if missing; required)",
};

static const cli_spec landscape_spec = {
        .name = "landscape",
        .usage = "SCENE --out DIR [OPTIONS]",
        .about = "Samples the potential energy landscape of the scene file SCENE on a grid,\n"
                 "E_total(x, y) = F_prop (y0 - y) + sum 1/2 k_i th_i(x, y)^2 (docs/model.md\n"
                 "section 7), finds the lowest pass from the start basin to the far side over\n"
                 "any beam and over each beam, prints the barrier table and writes into DIR:\n"
                 "  landscape.csv    x,y,e_beam,e_prop,e_total,theta1,...,thetaN per grid "
                 "point\n"
                 "  landscape.mat    the same columns, the grid's shape and the barrier "
                 "table\n"
                 "  landscape.json   the grid, the start and every pass with its path\n"
                 "  landscape_top, landscape_beam, landscape_total: .png .svg .gp and data,\n"
                 "                   the top view and the surfaces without and with "
                 "propulsion\n",
        .positional = "SCENE",
        .common = CLI_USES(CLI_OPT_OUT) | CLI_USES(CLI_OPT_OVERWRITE) | CLI_USES(CLI_OPT_SET) |
                  CLI_USES(CLI_OPT_LIMIT) | CLI_USES(CLI_OPT_QUIET),
        .help = landscape_help,
        .out_required = 1,
        .own = landscape_own,
        .n_own = 3,
        .option = landscape_option,
};

static void print_row(const char *what, const bsim_landscape_pass *p)
{
	char crossed[32];
	if (p->beam >= 0)
		snprintf(crossed, sizeof crossed, "beam %d", p->beam + 1);
	else
		snprintf(crossed, sizeof crossed, "-");
	printf("%-12s %-7s %-8s", what, bsim_landscape_pass_kind_name(p->kind), crossed);
	if (p->kind == BSIM_PASS_NONE) {
		printf("  no path to the far side leaves the beams' reach over this beam\n");
		return;
	}
	printf(" %8.3f %8.3f %10.2f %9.2f %9.2f %10.2f", p->x, p->y, p->e_total, p->e_beam,
	       p->height, p->above_start);
	if (p->kind == BSIM_PASS_SADDLE && isfinite(p->refine_change))
		printf("   %.2g\n", p->refine_change);
	else
		printf("   -\n");
}

static void print_table(const landscape_args *a, const bsim_scene *s, const bsim_landscape_grid *g,
                        const bsim_landscape_barriers *b)
{
	printf("landscape   %s (%s): %d x %d points, spacing %g m, x %g..%g m, y %g..%g m\n",
	       a->scene, s->name, g->nx, g->ny, g->spacing, g->x0, g->x0 + (g->nx - 1) * g->spacing,
	       g->y0, g->y0 + (g->ny - 1) * g->spacing);
	printf("start       (%g, %g) m, E_total %.2f J; far side y >= %g m beyond the beams' "
	       "reach\n\n",
	       b->start[0], b->start[1], b->start_e, b->far_y);
	printf("%-12s %-7s %-8s %8s %8s %10s %9s %9s %10s   %s\n", "barrier", "kind", "crossed",
	       "x (m)", "y (m)", "E_total J", "E_beam J", "height J", "vs start J", "+- J");
	print_row("lowest pass", &b->lowest);
	for (int i = 0; i < b->n_beams; i++) {
		char what[32];
		snprintf(what, sizeof what, "over beam %d", i + 1);
		print_row(what, &b->beam[i]);
	}
	if (b->lowest.kind == BSIM_PASS_SADDLE)
		printf("\nheight: above the start basin's floor, (%.3f, %.3f) m at E_total %.2f J "
		       "for "
		       "the lowest pass;\nvs start: E_total at the pass minus at the start (below "
		       "0: "
		       "a body released at rest could cross if it lost nothing)\n",
		       b->lowest.floor[0], b->lowest.floor[1], b->lowest.floor_e);
	else if (b->lowest.kind == BSIM_PASS_OPEN)
		printf("\nopen: the landscape falls from the start to the far side; the pass "
		       "columns "
		       "give where the descent leaves the beams' reach\n");
}

/* --json: the landscape.json just written, as it is. */
static int print_json(const char *dir)
{
	char path[BSIM_PATH_MAX];
	file_text t;
	bsim_error err;
	snprintf(path, sizeof path, "%s/landscape.json", dir);
	if (bsim_file_read(path, "landscape.json", INFINITY, NULL, &t, &err) != BSIM_OK)
		return cli_report(err.code, &err);
	fwrite(t.text, 1, t.len, stdout);
	bsim_file_text_free(&t);
	return CLI_OK;
}

int cmd_landscape(int argc, char **argv)
{
	cli_common c = cli_common_default();
	landscape_args a = {.grid = bsim_landscape_grid_def_default()};
	int rc = cli_parse(&landscape_spec, argc, argv, &c, &a, &a.scene);
	if (rc >= 0) {
		cli_common_free(&c);
		return rc;
	}
	bsim_scene scene;
	bsim_error err;
	bsim_landscape_grid *g = NULL;
	bsim_landscape_barriers *b = NULL;
	if (bsim_scene_load(a.scene, c.sets.ov, c.sets.n, &scene, &err) != BSIM_OK) {
		cli_error("%s", err.msg);
		cli_common_free(&c);
		return err.code ? err.code : CLI_USAGE;
	}
	int drawn = 0;
	rc = cli_report(
	        bsim_landscape_store(c.out, c.overwrite, &scene, &a.grid, &g, &b, &drawn, &err),
	        &err);
	if (rc == BSIM_OK && !c.quiet && a.json)
		rc = print_json(c.out);
	else if (rc == BSIM_OK && !c.quiet) {
		print_table(&a, &scene, g, b);
		printf("\n");
		cli_wrote(stdout, c.out);
	}
	/* The figures' note is a warning: --quiet keeps stdout quiet, not it. */
	if (rc == BSIM_OK && !drawn)
		cli_error("gnuplot not found: the figures' .gp scripts and data are in %s; "
		          "install the Debian package gnuplot-nox and run `gnuplot NAME.gp` "
		          "there",
		          c.out);
	bsim_landscape_barriers_free(b);
	bsim_landscape_grid_free(g);
	bsim_scene_free(&scene);
	cli_common_free(&c);
	return rc;
}
