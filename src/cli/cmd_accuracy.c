/* beamsim accuracy: what accuracy costs in time, per backend, knob
 * setting and time step h (Erez, Tassa & Todorov, ICRA 2015; see
 * beamsim/accuracy.h for the measures). Steps h = 0.016 s / 2^i down to
 * 0.000125 s; --quick stops at 0.0005 s with fewer pieces and trials. */
#define _POSIX_C_SOURCE 200809L

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/accuracy.h"
#include "cli/cli_common.h"
#include "cli/cli_options.h"
#include "cli/cli_progress.h"
#include "beamsim/limits.h"

#define ACC_SCENE "configs/thesis/gate.yaml"

enum { OWN_SCENE, OWN_BACKENDS, OWN_PIECES, OWN_QUICK };

static const cli_own accuracy_own[] = {
        [OWN_SCENE] = {"scene", 1, "FILE",
                       "scene (default " ACC_SCENE " with propulsion 9 N,\n"
                       "random force 20 N)"},
        [OWN_BACKENDS] = {"backends", 1, "LIST", "comma-separated (default thesis,box2d)"},
        [OWN_PIECES] = {"pieces", 1, "N", "restarted pieces (default 16)"},
        [OWN_QUICK] = {"quick", 0, NULL, "h down to 0.0005 s, 4 pieces, 8 trials (for tests)"},
};

static const char *const accuracy_help[CLI_N_OPTS] = {
        [CLI_OPT_TRIALS] = "trials of the p_traverse batch (default 40)",
        [CLI_OPT_SEED] = "seed of the schedules (default 1)",
        [CLI_OPT_THREADS] = "threads (default all); results other than timings do\n"
                            "not depend on it",
        [CLI_OPT_OUT] = "output directory (required; created if missing)",
};

typedef struct accuracy_args {
	const char *scene, *backends;
	int scene_given;
	long pieces;
	int quick;
} accuracy_args;

static int accuracy_option(void *args, int i, const char *value)
{
	accuracy_args *a = args;
	switch (i) {
	case OWN_SCENE:
		a->scene = value;
		a->scene_given = 1;
		return CLI_OK;
	case OWN_BACKENDS:
		a->backends = value;
		return CLI_OK;
	case OWN_PIECES:
		if (cli_parse_long(value, 1, 100000, &a->pieces))
			return cli_usage("accuracy", "--pieces %s: expected an integer >= 1",
			                 value);
		return CLI_OK;
	case OWN_QUICK:
		a->quick = 1;
		return CLI_OK;
	}
	return CLI_USAGE;
}

static const cli_spec accuracy_spec = {
        .name = "accuracy",
        .usage = "--out DIR [OPTIONS]",
        .about = "For each backend, knob setting and time step h (0.016 s halved down to\n"
                 "0.000125 s): the consistency error of pieces of 0.064 s restarted from a\n"
                 "reference trajectory (finest h, most accurate knobs), the energy-ledger\n"
                 "residual per simulated second, the error of p_traverse over a batch of\n"
                 "trials against the reference setting's, and the wall time per simulated\n"
                 "second. The knob settings of each backend are listed beside its knobs\n"
                 "(beamsim backends). Writes DIR/accuracy.csv, DIR/accuracy.md and the\n"
                 "figure DIR/accuracy.png (error against speed, log-log).\n",
        .common = CLI_USES(CLI_OPT_OUT) | CLI_USES(CLI_OPT_SET) | CLI_USES(CLI_OPT_TRIALS) |
                  CLI_USES(CLI_OPT_SEED) | CLI_USES(CLI_OPT_THREADS),
        .help = accuracy_help,
        .out_required = 1,
        .own = accuracy_own,
        .n_own = 4,
        .option = accuracy_option,
};

#define ACC_BACKENDS_MAX 8

static int accuracy_main(const cli_common *c, accuracy_args *a)
{
	/* The default scene is the gate with F = 9 N, Rm = 20 N: p near 0.5. */
	bsim_override defaults[] = {
	        {"effects.propulsion.force", "9", "accuracy default"},
	        {"effects.random_force.magnitude", "20", "accuracy default"},
	};
	int n_ov = (a->scene_given ? 0 : 2) + c->sets.n;
	bsim_error err;
	bsim_override *ov = calloc((size_t)n_ov + 1, sizeof *ov);
	if (!ov)
		return cli_report(bsim_error_set(&err, BSIM_EFAIL, "out of memory"), &err);
	int k = 0;
	if (!a->scene_given) {
		ov[k++] = defaults[0];
		ov[k++] = defaults[1];
	}
	for (int i = 0; i < c->sets.n; i++)
		ov[k++] = c->sets.ov[i];
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
	bsim_accuracy_config cfg =
	        a->quick ? bsim_accuracy_quick() : bsim_accuracy_config_default();
	if (a->pieces)
		cfg.n_pieces = (int)a->pieces;
	if (c->trials)
		cfg.n_trials = (int)c->trials;
	cfg.seed = c->has_seed ? c->seed : cfg.seed;
	cfg.threads = (int)c->threads;
	cli_progress progress;
	cli_progress_init(&progress, 1, "settings");
	cfg.progress = cli_progress_update;
	cfg.progress_user = &progress;
	char label[BSIM_PATH_MAX];
	snprintf(label, sizeof label, "%s%s", a->scene,
	         a->scene_given ? "" : " (propulsion 9 N, random force 20 N)");
	bsim_accuracy_result r;
	bsim_figures_result fig;
	rc = bsim_accuracy_store(c->out, &scene, label, backends, n_b, &cfg, &r, &fig, &err);
	cli_progress_finish(&progress);
	rc = cli_report(rc, &err);
	if (rc == BSIM_OK) {
		printf("accuracy: %d rows in %.1f s; wrote %s/accuracy.{csv,mat,md} and the figure "
		       "%s/accuracy.{png,svg,gp}\n",
		       r.n, r.wall_seconds, cli_path(c->out), cli_path(c->out));
		for (int i = 0; i < fig.n_notes; i++)
			cli_error("%s", fig.notes[i]);
		bsim_figures_result_free(&fig);
		bsim_accuracy_result_free(&r);
	}
	bsim_scene_free(&scene);
	return rc;
}

int cmd_accuracy(int argc, char **argv)
{
	cli_common c = cli_common_default();
	accuracy_args a = {.scene = ACC_SCENE, .backends = "thesis,box2d"};
	int rc = cli_parse(&accuracy_spec, argc, argv, &c, &a, NULL);
	if (rc < 0)
		rc = accuracy_main(&c, &a);
	cli_common_free(&c);
	return rc;
}
