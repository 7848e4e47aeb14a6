/* beamsim accuracy: what accuracy costs in time, per backend, knob
 * setting and time step h (Erez, Tassa & Todorov, ICRA 2015; see
 * beamsim/accuracy.h for the measures). Steps h = 0.016 s / 2^i down to
 * 0.000125 s; --quick stops at 0.0005 s with fewer pieces and trials. */
#define _POSIX_C_SOURCE 200809L

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "beamsim/accuracy.h"
#include "beamsim/output.h"
#include "beamsim/figures.h"
#include "matlab.h"
#include "cli_common.h"
#include "cli_store.h"

#define ACC_SCENE "configs/thesis/gate.yaml"

static const char accuracy_help[] =
        "Usage: beamsim accuracy --out DIR [OPTIONS]\n"
        "\n"
        "For each backend, knob setting and time step h (0.016 s halved down to\n"
        "0.000125 s): the consistency error of pieces of 0.064 s restarted from a\n"
        "reference trajectory (finest h, most accurate knobs), the energy-ledger\n"
        "residual per simulated second, the error of p_traverse over a batch of\n"
        "trials against the reference setting's, and the wall time per simulated\n"
        "second. Writes DIR/accuracy.csv, DIR/accuracy.md and the figure DIR/accuracy.png\n"
        "(error against speed, log-log).\n"
        "\n"
        "Options:\n"
        "  --out DIR          output directory (required; created if missing)\n"
        "  --scene FILE       scene (default " ACC_SCENE " with propulsion 9 N,\n"
        "                     random force 20 N)\n"
        "  --set KEY=VALUE    override a scene field, repeatable\n"
        "  --backends LIST    comma-separated (default thesis,box2d)\n"
        "  --trials N         trials of the p_traverse batch (default 40)\n"
        "  --pieces N         restarted pieces (default 16)\n"
        "  --seed N           seed of the schedules (default 1)\n"
        "  --quick            h down to 0.0005 s, 4 pieces, 8 trials (for tests)\n"
        "  --threads N        threads (default all); results other than timings do\n"
        "                     not depend on it\n"
        "  -h, --help         show this help\n";

enum {
	OPT_OUT = 256,
	OPT_SCENE,
	OPT_SET,
	OPT_BACKENDS,
	OPT_TRIALS,
	OPT_PIECES,
	OPT_SEED,
	OPT_QUICK,
	OPT_THREADS
};

static const struct option accuracy_options[] = {
        {"out", required_argument, NULL, OPT_OUT},
        {"scene", required_argument, NULL, OPT_SCENE},
        {"set", required_argument, NULL, OPT_SET},
        {"backends", required_argument, NULL, OPT_BACKENDS},
        {"trials", required_argument, NULL, OPT_TRIALS},
        {"pieces", required_argument, NULL, OPT_PIECES},
        {"seed", required_argument, NULL, OPT_SEED},
        {"quick", no_argument, NULL, OPT_QUICK},
        {"threads", required_argument, NULL, OPT_THREADS},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
};

typedef struct accuracy_args {
	const char *out, *scene, *backends;
	int scene_given;
	cli_sets sets;
	long trials, pieces, threads;
	uint64_t seed;
	int quick;
} accuracy_args;

static int accuracy_parse(int argc, char **argv, accuracy_args *a)
{
	int c;
	opterr = 0;
	while ((c = getopt_long(argc, argv, ":h", accuracy_options, NULL)) != -1) {
		int rc = CLI_OK;
		switch (c) {
		case 'h':
			fputs(accuracy_help, stdout);
			return CLI_OK;
		case OPT_OUT:
			a->out = optarg;
			break;
		case OPT_SCENE:
			a->scene = optarg;
			a->scene_given = 1;
			break;
		case OPT_SET:
			rc = cli_sets_add(&a->sets, "accuracy", optarg);
			break;
		case OPT_BACKENDS:
			a->backends = optarg;
			break;
		case OPT_TRIALS:
			if (cli_parse_long(optarg, 1, 1000000, &a->trials))
				rc = cli_usage("accuracy", "--trials %s: expected an integer >= 1",
				               optarg);
			break;
		case OPT_PIECES:
			if (cli_parse_long(optarg, 1, 100000, &a->pieces))
				rc = cli_usage("accuracy", "--pieces %s: expected an integer >= 1",
				               optarg);
			break;
		case OPT_SEED:
			if (cli_parse_u64(optarg, &a->seed))
				rc = cli_usage("accuracy",
				               "--seed %s: expected an unsigned integer", optarg);
			break;
		case OPT_QUICK:
			a->quick = 1;
			break;
		case OPT_THREADS:
			if (cli_parse_long(optarg, 1, 4096, &a->threads))
				rc = cli_usage("accuracy", "--threads %s: expected an integer >= 1",
				               optarg);
			break;
		default:
			return cli_bad_option("accuracy", argv, c);
		}
		if (rc != CLI_OK)
			return rc;
	}
	if (optind != argc)
		return cli_usage("accuracy", "unexpected argument %s", argv[optind]);
	if (!a->out)
		return cli_usage("accuracy", "--out DIR is required");
	return -1;
}

#define ACC_BACKENDS_MAX 8

static int accuracy_main(accuracy_args *a)
{
	/* The default scene is the gate with F = 9 N, Rm = 20 N: p near 0.5. */
	bsim_override defaults[] = {
	        {"effects.propulsion.force", "9", "accuracy default"},
	        {"effects.random_force.magnitude", "20", "accuracy default"},
	};
	int n_ov = (a->scene_given ? 0 : 2) + a->sets.n;
	bsim_error err;
	bsim_override *ov = calloc((size_t)n_ov + 1, sizeof *ov);
	if (!ov)
		return cli_report(bsim_error_set(&err, BSIM_EFAIL, "out of memory"), &err);
	int k = 0;
	if (!a->scene_given) {
		ov[k++] = defaults[0];
		ov[k++] = defaults[1];
	}
	for (int i = 0; i < a->sets.n; i++)
		ov[k++] = a->sets.ov[i];
	bsim_scene scene;
	int rc = bsim_scene_load(a->scene, ov, n_ov, &scene, &err);
	free(ov);
	if (rc)
		return cli_report(rc, &err);

	const bsim_backend *backends[ACC_BACKENDS_MAX];
	int n_b = 0;
	char list[256];
	snprintf(list, sizeof list, "%s", a->backends);
	char *save = NULL;
	for (char *t = strtok_r(list, ",", &save); t; t = strtok_r(NULL, ",", &save)) {
		if (n_b == ACC_BACKENDS_MAX) {
			bsim_scene_free(&scene);
			return cli_usage("accuracy", "--backends: at most %d", ACC_BACKENDS_MAX);
		}
		bsim_options none = {0};
		backends[n_b] = cli_backend(t, &none);
		if (!backends[n_b++]) {
			bsim_scene_free(&scene);
			return CLI_USAGE;
		}
	}
	if (n_b == 0) {
		bsim_scene_free(&scene);
		return cli_usage("accuracy", "--backends: no backend named");
	}
	bsim_accuracy_config cfg = {
	        .h_ref = a->quick ? 0.0005 : 0.000125,
	        .h_max = 0.016,
	        .piece = 0.064,
	        .n_pieces = a->pieces  ? (int)a->pieces
	                    : a->quick ? 4
	                               : 16,
	        .n_trials = a->trials  ? (int)a->trials
	                    : a->quick ? 8
	                               : 40,
	        .seed = a->seed,
	        .threads = (int)a->threads,
	        .progress = isatty(STDERR_FILENO), /* a \r line is noise in a log */
	};
	cli_session ss;
	rc = cli_session_open(&ss, a->out, 0, NULL, 0, 0, NULL);
	if (rc != CLI_OK) {
		bsim_scene_free(&scene);
		return rc;
	}
	bsim_accuracy_result r = {0};
	rc = bsim_accuracy_run(&scene, backends, n_b, &cfg, &r, &err);
	char path[1200], label[1200];
	snprintf(label, sizeof label, "%s%s", a->scene,
	         a->scene_given ? "" : " (propulsion 9 N, random force 20 N)");
	if (rc == BSIM_OK) {
		char mat[1200];
		snprintf(path, sizeof path, "%s/accuracy.csv", ss.stage);
		snprintf(mat, sizeof mat, "%s/accuracy.mat", ss.stage);
		rc = bsim_accuracy_write_csv(path, &r, &err);
		if (rc == BSIM_OK)
			rc = bsim_matlab_from_csv(path, mat, "accuracy", &err);
	}
	if (rc == BSIM_OK) {
		snprintf(path, sizeof path, "%s/accuracy.md", ss.stage);
		rc = bsim_accuracy_write_md(path, &r, &cfg, label, &err);
	}
	bsim_figures_result fig = {0};
	if (rc == BSIM_OK) {
		bsim_figures_def def = bsim_figures_default();
		def.kind = BSIM_FIGURES_ACCURACY;
		rc = bsim_figures_draw(ss.stage, &def, &fig, &err);
	}
	if (rc != BSIM_OK)
		cli_report(rc, &err);
	rc = cli_session_close(&ss, rc, "accuracy");
	if (rc == BSIM_OK) {
		printf("accuracy: %d rows in %.1f s; wrote %s/accuracy.{csv,mat,md} and the figure "
		       "%s/accuracy.{png,svg,gp}\n",
		       r.n, r.wall_seconds, a->out, a->out);
		for (int i = 0; i < fig.n_notes; i++)
			cli_error("%s", fig.notes[i]);
	}
	bsim_figures_result_free(&fig);
	bsim_accuracy_result_free(&r);
	bsim_scene_free(&scene);
	return rc;
}

int cmd_accuracy(int argc, char **argv)
{
	accuracy_args a = {.scene = ACC_SCENE, .backends = "thesis,box2d", .seed = 1};
	int rc = accuracy_parse(argc, argv, &a);
	if (rc < 0)
		rc = accuracy_main(&a);
	cli_sets_free(&a.sets);
	return rc;
}
