/* beamsim through its library: one trial of the essay's gate built in code,
 * on every backend with the same random-force schedule, then a sweep of an
 * experiment file.
 *
 *   trial_and_sweep EXPERIMENT.yaml [TRIALS]
 *
 * e.g. trial_and_sweep PREFIX/share/beamsim/configs/thesis/h1_symmetric.yaml 100 */
#include <stdio.h>
#include <stdlib.h>

#include <beamsim/beamsim.h>

static int fail(const bsim_error *err)
{
	fprintf(stderr, "trial_and_sweep: %s\n", err->msg);
	return 1;
}

/* The gate of docs/model.md section 1 pushed with 8 N and shaken with
 * Rm = 30 N: group 0, trial 0 of seed 1, as `beamsim run` runs it. */
static int one_trial(void)
{
	bsim_error err;
	bsim_scene scene = bsim_scene_default();
	bsim_scene_init_gate(&scene, 8.0, 30.0);
	if (bsim_scene_validate(&scene, &err) != BSIM_OK) {
		bsim_scene_free(&scene);
		return fail(&err);
	}
	bsim_trial_runner *runner = bsim_trial_runner_alloc();
	const uint64_t seed = bsim_schedule_seed_mix(1, 0, 0);
	const bsim_options none = {0};
	int rc = runner ? 0 : 1;
	for (const bsim_backend *const *b = bsim_backend_list(); rc == 0 && *b; b++) {
		bsim_trial_result r;
		if (bsim_trial_run(runner, &scene, *b, &none, seed, NULL, &r, &err) != BSIM_OK) {
			rc = fail(&err);
			break;
		}
		printf("%-7s %s at t = %.3f s, x = %.3f m, y = %.3f m\n", (*b)->name,
		       bsim_trial_outcome_name(r.outcome), r.t_end, r.x_end, r.y_end);
	}
	bsim_trial_runner_free(runner);
	bsim_scene_free(&scene);
	return rc;
}

/* Every group of the experiment with TRIALS trials, on the default backend. */
static int sweep(const char *path, int trials)
{
	bsim_error err;
	bsim_experiment e;
	if (bsim_experiment_load(path, NULL, 0, &e, &err) != BSIM_OK)
		return fail(&err);
	e.trials = trials;
	bsim_sweep_config cfg = bsim_sweep_config_default();
	bsim_sweep_result res;
	int rc = bsim_sweep_run(&e, &cfg, &res, &err);
	if (rc != BSIM_OK) {
		bsim_experiment_free(&e);
		return fail(&err);
	}
	printf("%s: %d groups x %d trials on %s in %.2f s\n", path, res.n_groups, res.trials,
	       cfg.backend->name, res.wall_seconds);
	for (int g = 0; g < res.n_groups; g++) {
		const bsim_group_result *G = &res.groups[g];
		printf("group %2d  p_traverse %.3f  [%.3f, %.3f]\n", g, G->p_traverse, G->ci95[0],
		       G->ci95[1]);
	}
	bsim_sweep_result_free(&res);
	bsim_experiment_free(&e);
	return 0;
}

int main(int argc, char **argv)
{
	if (argc < 2 || argc > 3) {
		fprintf(stderr, "usage: %s EXPERIMENT.yaml [TRIALS]\n", argv[0]);
		return 2;
	}
	printf("beamsim %s (library %s)\n", BSIM_VERSION, bsim_version());
	int trials = argc == 3 ? atoi(argv[2]) : 100;
	if (trials < 1) {
		fprintf(stderr, "%s: TRIALS: expected an integer >= 1, got %s\n", argv[0], argv[2]);
		return 2;
	}
	int rc = one_trial();
	return rc ? rc : sweep(argv[1], trials);
}
