/* beamsim accuracy: what accuracy costs in time, per backend, knob
 * setting and time step h (Erez, Tassa & Todorov, ICRA 2015; see
 * beamsim/accuracy.h for the measures). Steps h = 0.016 s / 2^i down to
 * 0.000125 s; --quick stops at 0.0005 s with fewer pieces and trials. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/accuracy.h"
#include "cli/cli_wrote.h"
#include "cli/cli_common.h"
#include "cli/cli_options.h"
#include "cli/cli_progress.h"
#include "beamsim/limits.h"

#define ACC_SCENE "configs/thesis/gate.yaml"

enum { OWN_SCENE, OWN_BACKENDS, OWN_PIECES, OWN_QUICK, OWN_TARGETS };

static const cli_own accuracy_own[] = {
        [OWN_SCENE] = {"scene", 1, "FILE",
                       "scene (default " ACC_SCENE " with propulsion 9 N,\n"
                       "random force 20 N)"},
        [OWN_BACKENDS] = {"backends", 1, "LIST",
                          "comma-separated (default: of {backends}, those\n"
                          "with accuracy settings)"},
        [OWN_PIECES] = {"pieces", 1, "N", "restarted pieces (default 16)"},
        [OWN_QUICK] = {"quick", 0, NULL, "h down to 0.0005 s, 4 pieces, 8 trials (for tests)"},
        [OWN_TARGETS] = {"targets", 1, "LIST",
                         "comma-separated mean consistency errors (m) of the\n"
                         "equal-error comparison (default 0.02,0.01,0.005,0.002,0.001)"},
};

static const char *const accuracy_help[CLI_N_OPTS] = {
        [CLI_OPT_TRIALS] = "trials of the p_traverse batch (default 40)",
        [CLI_OPT_SEED] = "seed of the schedules (default 1)",
        [CLI_OPT_THREADS] = "threads (default all); results other than timings do\n"
                            "not depend on it",
        [CLI_OPT_OUT] = "output directory (required; created if missing)",
        [CLI_OPT_BACKEND_OPT] = "B:K=V adds option K=V to every setting of backend B\n"
                                "(e.g. {default}:{knob}), repeatable",
};

typedef struct accuracy_args {
	const char *scene, *backends;
	int scene_given;
	long pieces;
	int quick;
	int n_targets; /* 0: the default targets */
	double targets[BSIM_ACCURACY_TARGETS_MAX];
} accuracy_args;

/* --targets: up to BSIM_ACCURACY_TARGETS_MAX numbers > 0. */
static int parse_targets(accuracy_args *a, const char *value)
{
	char list[512];
	if (snprintf(list, sizeof list, "%s", value) >= (int)sizeof list)
		return cli_usage("accuracy", "--targets: list too long");
	a->n_targets = 0;
	char *save = NULL;
	for (char *t = strtok_r(list, ",", &save); t; t = strtok_r(NULL, ",", &save)) {
		char *end;
		double v = strtod(t, &end);
		if (end == t || *end != '\0' || !isfinite(v) || v <= 0.0)
			return cli_usage("accuracy", "--targets: %s: expected a number > 0 (m)", t);
		if (a->n_targets == BSIM_ACCURACY_TARGETS_MAX)
			return cli_usage("accuracy", "--targets: at most %d",
			                 BSIM_ACCURACY_TARGETS_MAX);
		a->targets[a->n_targets++] = v;
	}
	if (a->n_targets == 0)
		return cli_usage("accuracy", "--targets: no number given");
	return CLI_OK;
}

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
	case OWN_TARGETS:
		return parse_targets(a, value);
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
                 "(beamsim backends). Then, for each error target (--targets), each\n"
                 "backend's cheapest setting reaching it (CPU time per simulated second)\n"
                 "and its cost over the first backend's: the speed ratio at equal error.\n"
                 "Writes DIR/accuracy.csv, DIR/equal_error.csv, DIR/accuracy.md and the\n"
                 "figure DIR/accuracy.png (error against speed, log-log).\n",
        .common = CLI_USES(CLI_OPT_OUT) | CLI_USES(CLI_OPT_OVERWRITE) | CLI_USES(CLI_OPT_SET) |
                  CLI_USES(CLI_OPT_BACKEND_OPT) | CLI_USES(CLI_OPT_TRIALS) |
                  CLI_USES(CLI_OPT_SEED) | CLI_USES(CLI_OPT_THREADS),
        .help = accuracy_help,
        .out_required = 1,
        .own = accuracy_own,
        .n_own = 5,
        .option = accuracy_option,
};

#define ACC_BACKENDS_MAX 8

/* One line per backend after the first: its cost over the first's at each
 * target (the md report has the settings). */
static void print_equal_error(const bsim_accuracy_result *r, const bsim_accuracy_config *cfg)
{
	bsim_accuracy_equal *eq;
	int n;
	bsim_error err;
	if (bsim_accuracy_equal_error(r, cfg->targets, cfg->n_targets, &eq, &n, &err) || n == 0)
		return;
	int n_b = n / cfg->n_targets;
	for (int b = 1; b < n_b; b++) {
		printf("at equal error, %s / %s (CPU per simulated s):", eq[b].backend,
		       eq[0].backend);
		for (int t = 0; t < cfg->n_targets; t++) {
			const bsim_accuracy_equal *e = &eq[t * n_b + b];
			if (isfinite(e->ratio))
				printf(" %g m: %.3g", e->target, e->ratio);
			else
				printf(" %g m: -", e->target);
		}
		putchar('\n');
	}
	free(eq);
}

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
	const char *names[ACC_BACKENDS_MAX];
	bsim_options extra[ACC_BACKENDS_MAX] = {0};
	bsim_options *extra_of[ACC_BACKENDS_MAX];
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
		names[n_b] = t;
		extra_of[n_b] = &extra[n_b];
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
	rc = cli_backend_opts(c, "accuracy", n_b, names, extra_of);
	for (int i = 0; i < n_b && rc == CLI_OK; i++)
		if (!cli_backend(names[i], &extra[i])) /* checks the options */
			rc = CLI_USAGE;
	if (rc != CLI_OK) {
		bsim_scene_free(&scene);
		return rc;
	}
	bsim_accuracy_config cfg =
	        a->quick ? bsim_accuracy_quick() : bsim_accuracy_config_default();
	if (a->pieces)
		cfg.n_pieces = (int)a->pieces;
	if (a->n_targets) {
		cfg.n_targets = a->n_targets;
		memcpy(cfg.targets, a->targets, sizeof cfg.targets);
	}
	if (c->trials)
		cfg.n_trials = (int)c->trials;
	cfg.seed = c->has_seed ? c->seed : cfg.seed;
	cfg.threads = (int)c->threads;
	cfg.backend_opts = extra;
	cli_progress progress;
	cli_progress_init(&progress, 1, "settings");
	cfg.progress = cli_progress_update;
	cfg.progress_user = &progress;
	char label[BSIM_PATH_MAX];
	snprintf(label, sizeof label, "%s%s", a->scene,
	         a->scene_given ? "" : " (propulsion 9 N, random force 20 N)");
	bsim_accuracy_result r;
	bsim_figures_result fig;
	rc = bsim_accuracy_store(c->out, c->overwrite, &scene, label, backends, n_b, &cfg, &r, &fig,
	                         &err);
	cli_progress_finish(&progress);
	rc = cli_report(rc, &err);
	if (rc == BSIM_OK) {
		printf("accuracy: %d rows in %.1f s\n", r.n, r.wall_seconds);
		print_equal_error(&r, &cfg);
		cli_wrote(stdout, c->out);
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
	/* Every registered backend that has accuracy settings to compare. */
	char all[256] = "";
	const bsim_backend *b[ACC_BACKENDS_MAX];
	int n = bsim_backend_compared(b, ACC_BACKENDS_MAX);
	for (int i = 0; i < n; i++)
		if (b[i]->n_accuracy > 0)
			snprintf(all + strlen(all), sizeof all - strlen(all), "%s%s",
			         all[0] ? "," : "", b[i]->name);
	accuracy_args a = {.scene = ACC_SCENE, .backends = all};
	int rc = cli_parse(&accuracy_spec, argc, argv, &c, &a, NULL);
	if (rc < 0)
		rc = accuracy_main(&c, &a);
	cli_common_free(&c);
	return rc;
}
