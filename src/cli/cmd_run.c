/* beamsim run: one trial of a scene, with its outcome, end state, peak
 * angles and energy ledger; optionally the trajectory as CSV. The seed is
 * mixed from (seed, group, trial) exactly as in a sweep, so any trial of a
 * sweep can be replayed and recorded. */
#define _POSIX_C_SOURCE 200809L

#include <getopt.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "atomic_file.h"
#include "beamsim/lattice.h"
#include "matlab.h"
#include "beamsim/output.h"
#include "beamsim/run_output.h"
#include "beamsim/schedule.h"
#include "beamsim/trial.h"
#include "cli_common.h"
#include "cli_store.h"

static const char run_help[] =
        "Usage: beamsim run SCENE [OPTIONS]\n"
        "\n"
        "Runs one trial of the scene file SCENE and prints its outcome, end state,\n"
        "peak beam angles, the deepest overlap of body and beams, and the energy\n"
        "ledger. The random-force schedule is that of trial I of group G of a sweep\n"
        "with seed N, so a sweep's trial can be replayed. A trial whose state stops\n"
        "being finite, or whose ledger shows energy created beyond the bound, is\n"
        "unstable: the reason is printed and the exit status is 1.\n"
        "\n"
        "Options:\n"
        "  --backend B            physics backend (default thesis; see beamsim backends)\n"
        "  --backend-opt K=V      a backend option, repeatable\n"
        "  --seed N               experiment seed (default 1)\n"
        "  --group G              group index for the seed (default 0)\n"
        "  --trial I              trial index for the seed (default 0)\n"
        "  --set KEY=VALUE        override a scene field by dotted path, repeatable\n"
        "                         (e.g. --set effects.random_force.magnitude=30)\n"
        "  --trajectory FILE.csv  write the trajectory, one row per recorded step, and\n"
        "                         its MATLAB twin FILE.mat; - is standard output (no\n"
        "                         twin; the report then goes to standard error)\n"
        "  --out DIR              write DIR/trajectory.csv, DIR/ledger.csv (the energy\n"
        "                         ledger over time), their .mat twins and DIR/run.json,\n"
        "                         for `beamsim plot DIR`\n"
        "  --stride N             record every N-th step (default 1)\n"
        "  --json                 print one JSON object instead of text\n" CLI_LIMIT_HELP
        "  -h, --help             show this help\n";

enum {
	OPT_BACKEND = 256,
	OPT_BACKEND_OPT,
	OPT_SEED,
	OPT_GROUP,
	OPT_TRIAL,
	OPT_SET,
	OPT_TRAJECTORY,
	OPT_STRIDE,
	OPT_JSON,
	OPT_OUT,
	OPT_LIMIT
};

static const struct option run_options[] = {
        {"backend", required_argument, NULL, OPT_BACKEND},
        {"backend-opt", required_argument, NULL, OPT_BACKEND_OPT},
        {"seed", required_argument, NULL, OPT_SEED},
        {"group", required_argument, NULL, OPT_GROUP},
        {"trial", required_argument, NULL, OPT_TRIAL},
        {"set", required_argument, NULL, OPT_SET},
        {"trajectory", required_argument, NULL, OPT_TRAJECTORY},
        {"stride", required_argument, NULL, OPT_STRIDE},
        {"json", no_argument, NULL, OPT_JSON},
        {"out", required_argument, NULL, OPT_OUT},
        {"limit", required_argument, NULL, OPT_LIMIT},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
};

typedef struct run_args {
	const char *scene;
	const char *backend;
	bsim_options opts;
	uint64_t seed;
	long group, trial, stride;
	cli_sets sets;
	const char *trajectory;
	const char *out;
	int json;
} run_args;

/* Fills a; returns -1 to go on, else the exit status. */
static int run_parse(int argc, char **argv, run_args *a)
{
	int c;
	opterr = 0;
	while ((c = getopt_long(argc, argv, ":h", run_options, NULL)) != -1) {
		int rc = CLI_OK;
		switch (c) {
		case 'h':
			fputs(run_help, stdout);
			return CLI_OK;
		case OPT_BACKEND:
			a->backend = optarg;
			break;
		case OPT_BACKEND_OPT:
			rc = cli_options_add(&a->opts, "run", optarg);
			break;
		case OPT_SEED:
			if (cli_parse_u64(optarg, &a->seed) != 0)
				rc = cli_usage("run", "--seed %s: expected an integer >= 0",
				               optarg);
			break;
		case OPT_GROUP:
			if (cli_parse_long(optarg, 0, INT32_MAX, &a->group) != 0)
				rc = cli_usage("run", "--group %s: expected an integer >= 0",
				               optarg);
			break;
		case OPT_TRIAL:
			if (cli_parse_long(optarg, 0, INT32_MAX, &a->trial) != 0)
				rc = cli_usage("run", "--trial %s: expected an integer >= 0",
				               optarg);
			break;
		case OPT_SET:
			rc = cli_sets_add(&a->sets, "run", optarg);
			break;
		case OPT_TRAJECTORY:
			a->trajectory = optarg;
			break;
		case OPT_STRIDE:
			if (cli_parse_long(optarg, 1, INT32_MAX, &a->stride) != 0)
				rc = cli_usage("run", "--stride %s: expected an integer >= 1",
				               optarg);
			break;
		case OPT_JSON:
			a->json = 1;
			break;
		case OPT_OUT:
			a->out = optarg;
			break;
		case OPT_LIMIT:
			rc = cli_limit("run", optarg);
			break;
		default:
			return cli_bad_option("run", argv, c);
		}
		if (rc != CLI_OK)
			return rc;
	}
	if (optind + 1 != argc)
		return cli_usage("run",
		                 optind == argc ? "missing SCENE" : "expected one SCENE, got %d",
		                 argc - optind);
	a->scene = argv[optind];
	return -1;
}

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
	int moved = 0;
	double peak = 0.0;
	for (int i = 0; i < log->n_beams; i++) {
		moved += log->peak[i] != 0.0;
		peak = fmax(peak, log->peak[i]);
	}
	fprintf(out,
	        "\npeak theta  %d beams moved, the largest %.6g rad (run --json: every beam)\n",
	        moved, peak);
	if (s->lattice.protocol == BSIM_PROTOCOL_ESSAY)
		fprintf(out, "reset       %d entries whose beams at rest overlapped the body\n",
		        r->reset_overlaps);
}

static void print_text(FILE *out, const run_args *a, const bsim_scene *s, uint64_t mixed,
                       const bsim_trial_result *r, const bsim_trial_log *log)
{
	const bsim_ledger *l = &r->ledger;
	fprintf(out, "scene       %s (%s), backend %s\n", a->scene, s->name, a->backend);
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
	if (s->has_lattice)
		print_lattice(out, s, r, log);
	else
		fprintf(out, "peak theta  beam 1 %.6g rad, beam 2 %.6g rad\n", r->max_theta[0],
		        r->max_theta[1]);
	fprintf(out, "overlap     deepest %.3g m of body and beams\n", r->overlap_max);
	fprintf(out, "energy      start %.6g J, end %.6g J\n", l->e_start, l->e_end);
	fprintf(out, "  work      propulsion %.6g J, random force %.6g J\n", l->w_prop, l->w_rand);
	fprintf(out,
	        "  losses    damper %.6g J, impact %.6g J, contact %.6g J, correction %.6g J\n",
	        l->damper, l->impact, l->contact, l->correction);
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
}

/* Runs the trial, recording into the trajectory file and the --out
 * directory if asked for; the files appear only if the run finished. */
static int run_trial(const run_args *a, const bsim_run_info *info, bsim_trial_result *res,
                     bsim_trial_log *log)
{
	bsim_atomic_file traj = {0};
	bsim_run_output dir;
	bsim_recorder rec = {.csv = NULL, .stride = (int)a->stride, .log = log, .overlap = 1};
	bsim_recorder dir_rec = {.csv = NULL, .stride = (int)a->stride, .log = log, .overlap = 1};
	bsim_error err;
	const bsim_scene *scene = info->scene;
	if (a->trajectory) {
		if (bsim_atomic_file_open(&traj, a->trajectory, &err) != BSIM_OK)
			return cli_report(BSIM_EFAIL, &err);
		bsim_trial_trajectory_header(traj.f, scene->n_beams);
		rec.csv = traj.f;
	}
	/* DIR is checked before the trial runs and its files appear together
	 * (beamsim/outdir.h). */
	cli_session ss;
	if (a->out) {
		int src = cli_session_open(&ss, a->out, 0, NULL, 0, 0, NULL);
		if (src != CLI_OK) {
			bsim_atomic_file_abort(&traj);
			return src;
		}
		if (bsim_run_output_open(&dir, ss.stage, scene->n_beams, &dir_rec, &err)) {
			bsim_atomic_file_abort(&traj);
			cli_report(BSIM_EFAIL, &err);
			return cli_session_close(&ss, CLI_FAIL, "run");
		}
	}
	/* One recorder writes both when both are asked for: the CSV of
	 * --trajectory, and the directory's trajectory and ledger. */
	if (a->out && a->trajectory) {
		dir_rec.record = bsim_trial_trajectory_row;
		dir_rec.record_user = traj.f;
	}
	bsim_trial_runner *runner = bsim_trial_runner_alloc();
	if (!runner) {
		bsim_atomic_file_abort(&traj);
		cli_error("out of memory for a trial runner");
		if (a->out) {
			bsim_run_output_abort(&dir);
			return cli_session_close(&ss, CLI_FAIL, "run");
		}
		return CLI_FAIL;
	}
	bsim_error_clear(&err);
	const bsim_recorder *use = a->out ? &dir_rec : &rec;
	int rc = bsim_trial_run(runner, scene, info->backend, &a->opts, info->mixed_seed, use, res,
	                        &err);
	bsim_trial_runner_free(runner);
	if (rc != BSIM_OK) {
		bsim_atomic_file_abort(&traj);
		cli_report(rc, &err);
		if (a->out) {
			bsim_run_output_abort(&dir);
			return cli_session_close(&ss, rc, "run");
		}
		return rc;
	}
	if (a->trajectory) {
		char mat[1200];
		rc = bsim_atomic_file_commit(&traj, &err);
		/* The twin is read back from the file: a pipe, a terminal or
		 * standard output cannot be, and a link's twin would not be its. */
		if (rc == BSIM_OK && traj.mode == BSIM_ATOMIC_RENAME) {
			rc = bsim_matlab_path(a->trajectory, mat, sizeof mat, &err);
			if (rc == BSIM_OK)
				rc = bsim_matlab_from_csv(a->trajectory, mat, "trajectory", &err);
		}
	}
	if (rc == BSIM_OK && a->out)
		rc = bsim_run_output_commit(&dir, info, res, &err);
	else if (a->out)
		bsim_run_output_abort(&dir);
	rc = cli_report(rc, &err);
	return a->out ? cli_session_close(&ss, rc, "run") : rc;
}

int cmd_run(int argc, char **argv)
{
	run_args a = {.backend = "thesis", .seed = 1, .stride = 1};
	int rc = run_parse(argc, argv, &a);
	if (rc >= 0) {
		cli_sets_free(&a.sets);
		return rc;
	}
	const bsim_backend *backend = cli_backend(a.backend, &a.opts);
	bsim_scene scene;
	bsim_error err;
	if (!backend) {
		rc = CLI_USAGE;
	} else if (bsim_scene_load(a.scene, a.sets.ov, a.sets.n, &scene, &err) != BSIM_OK) {
		cli_error("%s", err.msg);
		rc = err.code ? err.code : CLI_USAGE;
	} else {
		uint64_t mixed =
		        bsim_schedule_seed_mix(a.seed, (uint64_t)a.group, (uint64_t)a.trial);
		bsim_run_info info = {
		        .scene_path = a.scene,
		        .scene = &scene,
		        .sets = a.sets.ov,
		        .n_sets = a.sets.n,
		        .backend = backend,
		        .opts = &a.opts,
		        .seed = a.seed,
		        .group = a.group,
		        .trial = a.trial,
		        .mixed_seed = mixed,
		        .stride = (int)a.stride,
		};
		bsim_trial_result res;
		memset(&res, 0, sizeof res);
		bsim_trial_log *log = bsim_trial_log_alloc();
		info.log = log;
		rc = log ? run_trial(&a, &info, &res, log) : CLI_FAIL;
		if (!log)
			cli_error("out of memory");
		/* A trajectory on standard output keeps it to itself: the report
		 * goes to standard error. */
		FILE *out = a.trajectory && strcmp(a.trajectory, "-") == 0 ? stderr : stdout;
		if (rc == CLI_OK && a.json)
			bsim_run_output_json(out, &info, &res, 0);
		else if (rc == CLI_OK)
			print_text(out, &a, &scene, mixed, &res, log);
		if (rc == CLI_OK && res.outcome == BSIM_UNSTABLE) {
			char why[256];
			bsim_trial_instability_text(&res, scene.dt, why, sizeof why);
			cli_error("%s backend: unstable trial: %s", backend->name, why);
			rc = CLI_FAIL;
		}
		bsim_trial_log_free(log);
		bsim_scene_free(&scene);
	}
	cli_sets_free(&a.sets);
	return rc;
}
