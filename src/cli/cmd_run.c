/* beamsim run: one trial of a scene, with its outcome, end state, peak
 * angles and energy ledger; optionally the trajectory as CSV. The seed is
 * mixed from (seed, group, trial) exactly as in a sweep, so any trial of a
 * sweep can be replayed and recorded. */
#define _POSIX_C_SOURCE 200809L

#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/lattice.h"
#include "beamsim/run_output.h"
#include "beamsim/schedule.h"
#include "beamsim/trial.h"
#include "beamsim/trial_fields.h"
#include "beamsim/lattice_outcome.h"
#include "beamsim/limits.h"
#include "cli/cli_wrote.h"
#include "cli/cli_common.h"
#include "cli/cli_options.h"
#include "cli/cli_replay.h"

enum { OWN_GROUP, OWN_TRIAL, OWN_TRAJECTORY, OWN_STRIDE, OWN_JSON };

static const cli_own run_own[] = {
        [OWN_GROUP] = {"group", 1, "G",
                       "group, from 0: an experiment's grid values and the\n"
                       "seed (default 0)"},
        [OWN_TRIAL] = {"trial", 1, "I", "trial of the group, from 0 (default 0)"},
        [OWN_TRAJECTORY] = {"trajectory", 1, "FILE.csv",
                            "write the trajectory, one row per recorded step, and\n"
                            "its MATLAB twin FILE.mat; - is standard output (no\n"
                            "twin; the report then goes to standard error);\n"
                            "missing folders of FILE are created"},
        [OWN_STRIDE] = {"stride", 1, "N", "record every N-th step (default 1)"},
        [OWN_JSON] = {"json", 0, NULL, "print one JSON object instead of text"},
};

static const char *const run_help[CLI_N_OPTS] = {
        [CLI_OPT_SEED] = "experiment seed (default: the experiment's, a scene's 1;\n"
                         "not with DIR, whose seed is stored)",
        [CLI_OPT_OUT] = "write DIR/trajectory.csv, DIR/ledger.csv (the energy\n"
                        "ledger over time), their .mat twins and DIR/run.json,\n"
                        "for `beamsim plot DIR`",
};

typedef struct run_args {
	const char *scene;
	const char *backend;
	bsim_options opts;
	uint64_t seed;
	long group, trial, stride;
	int has_group;
	const char *trajectory;
	int json;
} run_args;

static int run_option(void *args, int i, const char *value)
{
	run_args *a = args;
	switch (i) {
	case OWN_GROUP:
		if (cli_parse_long(value, 0, INT32_MAX, &a->group) != 0)
			return cli_usage("run", "--group %s: expected an integer >= 0", value);
		a->has_group = 1;
		return CLI_OK;
	case OWN_TRIAL:
		if (cli_parse_long(value, 0, INT32_MAX, &a->trial) != 0)
			return cli_usage("run", "--trial %s: expected an integer >= 0", value);
		return CLI_OK;
	case OWN_TRAJECTORY:
		/* Room for the names beamsim appends (FILE.tmp.PID, the .mat twin). */
		if (strlen(value) >= BSIM_PATH_MAX - BSIM_NAME_MAX)
			return cli_usage(
			        "run",
			        "--trajectory %.40s...: path too long (%zu bytes, at most %d)",
			        value, strlen(value), BSIM_PATH_MAX - BSIM_NAME_MAX - 1);
		a->trajectory = value;
		return CLI_OK;
	case OWN_STRIDE:
		if (cli_parse_long(value, 1, INT32_MAX, &a->stride) != 0)
			return cli_usage("run", "--stride %s: expected an integer >= 1", value);
		return CLI_OK;
	case OWN_JSON:
		a->json = 1;
		return CLI_OK;
	}
	return CLI_USAGE;
}

static const cli_spec run_spec = {
        .name = "run",
        .usage = "SCENE|EXPERIMENT|DIR [OPTIONS]",
        .about = "Runs one trial and prints its outcome, end state, how far a body that\n"
                 "rotates turned, peak beam angles, the deepest overlap of body and beams,\n"
                 "and the energy ledger. The trial is\n"
                 "  of a scene file SCENE: the random-force schedule of trial I of group G\n"
                 "    of a sweep with seed N; a scene has no grid, so no grid values apply;\n"
                 "  of an experiment file EXPERIMENT: trial I of group G as `beamsim sweep\n"
                 "    EXPERIMENT` runs it, the group's grid values applied (printed), the\n"
                 "    experiment's seed unless --seed N; --backend may be a compare side,\n"
                 "    NAME:K=V..., and a --protocols side is --set lattice.protocol=P;\n"
                 "  of the output directory DIR of beamsim sweep or compare: trial I of\n"
                 "    group G as that run ran it (run.json, inputs/: its experiment, seed,\n"
                 "    backend and options, so --seed, --set and --backend-opt are\n"
                 "    refused); a comparison's side is --backend LABEL. The\n"
                 "    stored trials.csv row is printed; if the replay differs from it in\n"
                 "    outcome, type, steps, t_end, x_end or y_end the exit status is 3.\n"
                 "Groups and trials count from 0, as in trials.csv. A trial whose state stops\n"
                 "being finite, or whose ledger shows energy created beyond the bound, is\n"
                 "unstable: the reason is printed and the exit status is 1. Beams are\n"
                 "numbered from 1 in what run prints and writes (beam 1, theta1), as in\n"
                 "every output; the scene's list, and so --set, counts from 0 (beams.0).\n",
        .positional = "SCENE|EXPERIMENT|DIR",
        .common = CLI_USES(CLI_OPT_BACKEND) | CLI_USES(CLI_OPT_BACKEND_OPT) |
                  CLI_USES(CLI_OPT_SEED) | CLI_USES(CLI_OPT_SET) | CLI_USES(CLI_OPT_GRID) |
                  CLI_USES(CLI_OPT_OUT) | CLI_USES(CLI_OPT_OVERWRITE) | CLI_USES(CLI_OPT_LIMIT),
        .help = run_help,
        .own = run_own,
        .n_own = 5,
        .option = run_option,
};

/* A lattice trial's gate path and peaks (run --json has every beam's). */
static void print_lattice(FILE *out, const bsim_scene *s, const bsim_trial_result *r,
                          const bsim_trial_log *log)
{
	char label[48];
	bsim_lattice_location_label(bsim_lattice_location_of(r), label, sizeof label);
	fprintf(out, "lattice     %s protocol, ended %s in gate (%d, %d), %d gates entered:",
	        s->lattice.protocol == BSIM_PROTOCOL_ESSAY ? "essay" : "world", label, r->final_ix,
	        r->final_iy, r->gates_entered);
	for (int k = 0; k < log->n_entries; k++)
		fprintf(out, " %d:%d", log->entries[k].ix, log->entries[k].iy);
	int moved = log->n_peaks;
	double peak = 0.0;
	for (int k = 0; k < log->n_peaks; k++)
		peak = fmax(peak, log->peaks[k].peak);
	fprintf(out,
	        "\npeak theta  %d beams moved, the largest %.6g rad (run --json: every beam)\n",
	        moved, peak);
	if (s->lattice.protocol == BSIM_PROTOCOL_ESSAY)
		fprintf(out, "reset       %d entries whose beams at rest overlapped the body\n",
		        r->reset_overlaps);
}

static void print_text(FILE *out, const run_args *a, const bsim_replay *rp, uint64_t mixed,
                       const bsim_trial_result *r, const bsim_trial_log *log)
{
	const bsim_ledger *l = &r->ledger;
	const bsim_scene *s = &rp->scene;
	if (rp->kind == BSIM_REPLAY_SCENE) {
		fprintf(out, "scene       %s (%s), backend %s\n", cli_path(a->scene), s->name,
		        a->backend);
	} else {
		fprintf(out, "%-11s %s, scene %s (%s), backend %s\n",
		        rp->kind == BSIM_REPLAY_STORED ? rp->command : "experiment",
		        cli_path(rp->path), cli_path(rp->scene_path), s->name, a->backend);
		fprintf(out, "grid        %s\n", rp->grid);
	}
	fprintf(out,
	        "seed        %" PRIu64 ", group %ld, trial %ld (mixed seed %" PRIu64
	        ", %lu draws)\n",
	        a->seed, a->group, a->trial, mixed, r->draws);
	fprintf(out, "outcome     %s", bsim_trial_outcome_name(r->outcome));
	if (r->outcome == BSIM_TRAVERSED) {
		fprintf(out, ", type %s, landscape ", bsim_trial_type_name(r->type));
		if (r->landscape_beam < 0)
			fprintf(out, "none");
		else if (r->landscape_beam < 2 && s->n_beams == 2)
			fprintf(out, "%s (beam %d)", r->landscape_beam == 0 ? "left" : "right",
			        r->landscape_beam + 1);
		else
			fprintf(out, "beam %d", r->landscape_beam + 1);
	} else if (r->outcome == BSIM_STUCK) {
		fprintf(out, ", %s", r->in_contact_end ? "in contact" : "not in contact");
	}
	fprintf(out, "\nsteps       %d to the outcome at t = %.6g s, %d run\n", r->steps, r->t_end,
	        r->steps_run);
	fprintf(out, "end state   x = %.6g m, y = %.6g m, vx = %.6g m/s\n", r->x_end, r->y_end,
	        r->vx_end);
	if (s->body.rotates)
		fprintf(out,
		        "turn        heading %.6g rad, angular velocity %.6g rad/s at the end; "
		        "turned %.6g rad, at most %.6g rad\n",
		        r->heading_end, r->angular_velocity_end, r->turn_end, r->turn_max);
	if (s->has_lattice)
		print_lattice(out, s, r, log);
	else
		fprintf(out, "peak theta  beam 1 %.6g rad, beam 2 %.6g rad\n", r->max_theta[0],
		        r->max_theta[1]);
	if (isnan(r->overlap_max))
		fputs("overlap     not measured (the body is not a disk)\n", out);
	else
		fprintf(out, "overlap     deepest %.3g m of body and beams\n", r->overlap_max);
	fprintf(out, "energy      start %.6g J, end %.6g J\n", l->e_start, l->e_end);
	fprintf(out, "  work      propulsion %.6g J, random force %.6g J\n", l->w_prop, l->w_rand);
	fprintf(out,
	        "  losses    damper %.6g J, impact %.6g J, contact %.6g J, correction %.6g J\n",
	        l->damper, l->impact, l->contact, l->correction);
	if (s->effects.has_oscillation)
		fprintf(out, "  effects   oscillation work %.6g J\n", l->w_osc);
	if (s->effects.has_drag)
		fprintf(out, "  effects   drag loss %.6g J\n", l->drag);
	if (s->effects.has_ground_friction)
		fprintf(out, "  effects   ground friction loss %.6g J\n", l->friction);
	if (l->sleep != 0.0 || l->reset != 0.0)
		fprintf(out, "  at rest   sleeping %.6g J, essay resets %.6g J\n", l->sleep,
		        l->reset);
	fprintf(out,
	        "  residual  %.3g J (sum |r| %.3g J, max |r| %.3g J per step; %.4g J flowed in)\n",
	        l->residual, l->residual_abs, l->residual_max, l->inflow);
	if (r->instability) {
		char why[256];
		bsim_trial_instability_text(r, s->dt, why, sizeof why);
		fprintf(out, "unstable    %s\n", why);
	}
	if (rp->kind != BSIM_REPLAY_SCENE) {
		char row[256];
		bsim_replay_row(row, sizeof row, a->group, a->trial, r);
		int n;
		const bsim_trial_field *f = bsim_trial_fields(&n);
		fprintf(out, "row         %s (trials.csv: ", row);
		for (int c = 0; c < BSIM_REPLAY_ROW_FIELDS && c < n; c++)
			fprintf(out, "%s%s", c ? "," : "", f[c].name);
		fputs(")\n", out);
	}
}

/* The backend of --backend (default: the default backend) with the
 * --backend-opt values, then the options of a compare side's label
 * NAME:K=V... (they win, as in compare). NULL with the error printed. */
static const bsim_backend *run_backend(const cli_common *c, run_args *a)
{
	const char *spec = c->backend ? c->backend : bsim_backend_default()->name;
	/* A side of compare --protocols is named by its protocol. */
	if (strcmp(spec, "world") == 0 || strcmp(spec, "essay") == 0) {
		cli_error("--backend %s: a lattice protocol, not a backend: a side of compare "
		          "--protocols is --set lattice.protocol=%s (with --backend B)",
		          spec, spec);
		return NULL;
	}
	const bsim_backend *b = cli_backend_with_opts(c, "run", spec, &a->opts);
	a->backend = spec;
	return b;
}

int cmd_run(int argc, char **argv)
{
	cli_common c = cli_common_default();
	const bsim_run_info defaults = bsim_run_info_default();
	run_args a = {.seed = defaults.seed, .stride = defaults.stride};
	int rc = cli_parse(&run_spec, argc, argv, &c, &a, &a.scene);
	/* A stored run's directory names its own backend (--backend: a side). */
	int stored = rc < 0 && bsim_replay_is_dir(a.scene);
	const bsim_backend *backend = NULL;
	if (rc < 0 && !stored && !(backend = run_backend(&c, &a)))
		rc = CLI_USAGE;
	if (rc >= 0) {
		cli_common_free(&c);
		return rc;
	}
	bsim_replay *rp;
	rc = cli_replay_open("run", a.scene, &c, a.group, a.trial, a.has_group, defaults.seed, &rp);
	if (rc != CLI_OK) {
		cli_common_free(&c);
		return rc;
	}
	if (stored) {
		backend = rp->backend;
		a.opts = rp->opts;
		a.backend = rp->label;
	}
	a.seed = rp->seed;
	const bsim_scene *scene = &rp->scene;
	cli_estimate_line(backend, (double)scene->max_steps * scene->n_beams);
	uint64_t mixed = bsim_schedule_seed_mix(a.seed, (uint64_t)a.group, (uint64_t)a.trial);
	bsim_trial_log *log = bsim_trial_log_alloc();
	int of_scene = rp->kind == BSIM_REPLAY_SCENE;
	bsim_run_info info = {
	        .scene_path = rp->scene_path,
	        .scene = scene,
	        .sets = rp->ov,
	        .n_sets = rp->n_ov,
	        .backend = backend,
	        .opts = &a.opts,
	        .seed = a.seed,
	        .group = a.group,
	        .trial = a.trial,
	        .mixed_seed = mixed,
	        .stride = (int)a.stride,
	        .log = log,
	};
	bsim_trial_result res;
	bsim_error err;
	memset(&res, 0, sizeof res);
	if (!log)
		rc = cli_report(bsim_error_set(&err, BSIM_EFAIL, "out of memory"), &err);
	else
		rc = cli_report(
		        bsim_run_output_trial(&info, a.trajectory, c.out, c.overwrite, &res, &err),
		        &err);
	/* A trajectory on standard output keeps it to itself: the report
	 * goes to standard error. */
	FILE *out = a.trajectory && strcmp(a.trajectory, "-") == 0 ? stderr : stdout;
	if (rc == CLI_OK && a.json) {
		bsim_run_output_json(out, &info, &res, 0);
		if (!of_scene)
			cli_error("%s", rp->grid);
	} else if (rc == CLI_OK) {
		print_text(out, &a, rp, mixed, &res, log);
	}
	if (rc == CLI_OK && !a.json && c.out)
		cli_wrote(out, c.out);
	if (rc == CLI_OK)
		cli_solver_warning(backend->name, &res.solver, "run --json");
	if (rc == CLI_OK && res.outcome == BSIM_UNSTABLE) {
		char why[256];
		bsim_trial_instability_text(&res, scene->dt, why, sizeof why);
		cli_error("%s backend: unstable trial: %s", backend->name, why);
		rc = CLI_FAIL;
	}
	/* A stored run's row, against the replay (after an unstable trial's
	 * line, which has its own exit status). */
	if (rc == CLI_OK)
		rc = cli_replay_check(rp, &res, a.json ? stderr : out);
	bsim_trial_log_free(log);
	bsim_replay_free(rp);
	cli_common_free(&c);
	return rc;
}
