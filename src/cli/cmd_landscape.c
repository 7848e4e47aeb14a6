/* beamsim landscape: the potential energy landscape of a scene on a grid,
 * its barriers, and the files and figures that show them. The library
 * computes and writes (beamsim/landscape.h); this parses and prints. */
#define _POSIX_C_SOURCE 200809L

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/landscape.h"
#include "beamsim/output.h"
#include "cli_common.h"
#include "cli_store.h"

static const char landscape_help[] =
        "Usage: beamsim landscape SCENE --out DIR [OPTIONS]\n"
        "\n"
        "Samples the potential energy landscape of the scene file SCENE on a grid,\n"
        "E_total(x, y) = F_prop (y0 - y) + sum 1/2 k_i th_i(x, y)^2 (MODEL.md section 7),\n"
        "finds the lowest pass from the start basin to the far side over any beam and\n"
        "over each beam, prints the barrier table and writes into DIR:\n"
        "  landscape.csv    x,y,e_beam,e_prop,e_total,theta1,...,thetaN per grid point\n"
        "  landscape.mat    the same columns, the grid's shape and the barrier table\n"
        "  landscape.json   the grid, the start and every pass with its path\n"
        "  landscape_top, landscape_beam, landscape_total: .png .svg .gp and data,\n"
        "                   the top view and the surfaces without and with propulsion\n"
        "\n"
        "Options:\n"
        "  --out DIR              output directory (created if missing)\n"
        "  --set KEY=VALUE        override a scene field by dotted path, repeatable\n"
        "                         (e.g. --set beams.0.stiffness=100)\n"
        "  --resolution H         grid spacing in m (default: the region's longer side\n"
        "                         / 260, 0.25 m on the essay's gate)\n"
        "  --region X0,X1,Y0,Y1   the region in m (default: x within the side\n"
        "                         boundaries, y from the body's start to "
        "success_y)\n" CLI_LIMIT_HELP "  -h, --help             show this help\n";

enum { OPT_OUT = 256, OPT_SET, OPT_RESOLUTION, OPT_REGION, OPT_LIMIT };

static const struct option landscape_options[] = {
        {"out", required_argument, NULL, OPT_OUT},
        {"set", required_argument, NULL, OPT_SET},
        {"resolution", required_argument, NULL, OPT_RESOLUTION},
        {"region", required_argument, NULL, OPT_REGION},
        {"limit", required_argument, NULL, OPT_LIMIT},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
};

typedef struct landscape_args {
	const char *scene;
	const char *out;
	cli_sets sets;
	bsim_landscape_grid_def grid;
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

/* Fills a; returns -1 to go on, else the exit status. */
static int landscape_parse(int argc, char **argv, landscape_args *a)
{
	int c;
	opterr = 0;
	while ((c = getopt_long(argc, argv, ":h", landscape_options, NULL)) != -1) {
		int rc = CLI_OK;
		char *end;
		switch (c) {
		case 'h':
			fputs(landscape_help, stdout);
			return CLI_OK;
		case OPT_OUT:
			a->out = optarg;
			break;
		case OPT_SET:
			rc = cli_sets_add(&a->sets, "landscape", optarg);
			break;
		case OPT_RESOLUTION:
			a->grid.spacing = strtod(optarg, &end);
			if (end == optarg || *end || !(a->grid.spacing > 0) ||
			    !isfinite(a->grid.spacing))
				rc = cli_usage("landscape",
				               "--resolution %s: expected a grid spacing > 0 in m",
				               optarg);
			break;
		case OPT_REGION:
			if (parse_region(optarg, a->grid.region) != 0 ||
			    !(a->grid.region[0] < a->grid.region[1]) ||
			    !(a->grid.region[2] < a->grid.region[3]))
				rc = cli_usage(
				        "landscape",
				        "--region %s: expected X0,X1,Y0,Y1 in m with X0 < X1 "
				        "and Y0 < Y1, e.g. --region -25,25,0,65",
				        optarg);
			a->grid.has_region = 1;
			break;
		case OPT_LIMIT:
			rc = cli_limit("landscape", optarg);
			break;
		default:
			return cli_bad_option("landscape", argv, c);
		}
		if (rc != CLI_OK)
			return rc;
	}
	if (optind + 1 != argc)
		return cli_usage("landscape",
		                 optind == argc ? "missing SCENE" : "expected one SCENE, got %d",
		                 argc - optind);
	if (!a->out)
		return cli_usage("landscape", "missing --out DIR");
	a->scene = argv[optind];
	return -1;
}

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

int cmd_landscape(int argc, char **argv)
{
	landscape_args a = {.grid = bsim_landscape_grid_default()};
	int rc = landscape_parse(argc, argv, &a);
	if (rc >= 0) {
		cli_sets_free(&a.sets);
		return rc;
	}
	bsim_scene scene;
	bsim_error err;
	bsim_landscape_grid *g = NULL;
	bsim_landscape_barriers *b = NULL;
	if (bsim_scene_load(a.scene, a.sets.ov, a.sets.n, &scene, &err) != BSIM_OK) {
		cli_error("%s", err.msg);
		cli_sets_free(&a.sets);
		return err.code ? err.code : CLI_USAGE;
	}
	/* DIR is checked before the grid is computed, and its files appear
	 * together (beamsim/outdir.h). */
	cli_session ss;
	rc = cli_session_open(&ss, a.out, 0, NULL, 0, 0, NULL);
	if (rc != CLI_OK) {
		bsim_scene_free(&scene);
		cli_sets_free(&a.sets);
		return rc;
	}
	rc = bsim_landscape_grid_alloc(&scene, &a.grid, &g, &err);
	if (rc == BSIM_EINPUT) {
		rc = cli_usage("landscape", "%s", err.msg);
	} else if (rc == BSIM_OK) {
		rc = bsim_landscape_barriers_alloc(&scene, g, &b, &err);
		if (rc == BSIM_EINPUT)
			rc = cli_usage("landscape", "%s", err.msg);
		else if (rc)
			rc = cli_report(rc, &err);
	} else {
		rc = cli_report(rc, &err);
	}
	int drawn = 0;
	if (rc == BSIM_OK) {
		rc = bsim_landscape_write(ss.stage, &scene, g, b, &drawn, &err);
		rc = cli_report(rc, &err);
	}
	rc = cli_session_close(&ss, rc, "landscape");
	if (rc == BSIM_OK) {
		print_table(&a, &scene, g, b);
		printf("\nwrote       %s/: landscape.csv, landscape.mat, landscape.json, "
		       "landscape_top, landscape_beam, landscape_total (.png .svg .gp)\n",
		       a.out);
		if (!drawn)
			cli_error(
			        "gnuplot not found: the figures' .gp scripts and data are in %s; "
			        "install the Debian package gnuplot-nox and run `gnuplot NAME.gp` "
			        "there",
			        a.out);
	}
	bsim_landscape_barriers_free(b);
	bsim_landscape_grid_free(g);
	bsim_scene_free(&scene);
	cli_sets_free(&a.sets);
	return rc;
}
