/* Files every stored run writes alike; see store.h. */
#define _POSIX_C_SOURCE 200809L

#include "store/store.h"

#include <stdlib.h>
#include <string.h>

#include "util/atomic_file.h"
#include "beamsim/output.h"
#include "store/matlab.h"
#include "store/session.h"
#include "store/survival_files.h"
#include "store/trials_csv.h"
#include "beamsim/limits.h"

/* path holding the len bytes at text, atomically. */
static int bytes_write(const char *path, const char *text, size_t len, bsim_error *err)
{
	bsim_atomic_file o;
	if (bsim_atomic_file_open(&o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	fwrite(text, 1, len, o.f);
	return bsim_atomic_file_commit(&o, err);
}

/* survival.csv and horizon.csv of a sweep held in memory (a streamed
 * sweep's come from its sink, sweep_dir.c). */
static int survival_files(const char *dir, const bsim_experiment *e, const bsim_override *extra,
                          int n_extra, const bsim_sweep_result *r, bsim_error *err)
{
	survival_acc a;
	int rc = bsim_survival_acc_init(&a, e, NULL, extra, n_extra, err);
	if (rc == BSIM_OK)
		bsim_survival_acc_add(&a, 0, (long)r->n_groups * r->trials, r->trials,
		                      r->trials_out);
	if (rc == BSIM_OK)
		rc = bsim_survival_acc_write(&a, dir, err);
	bsim_survival_acc_free(&a);
	return rc == BSIM_OK ? BSIM_OK : BSIM_EFAIL;
}

/* A sweep's files; trials.csv from r, or, text not NULL, those len bytes
 * (a side read from a file made elsewhere). */
static int sweep_files(const char *dir, const bsim_experiment *e, const bsim_backend *b,
                       const bsim_options *opts, const bsim_override *extra, int n_extra,
                       const bsim_sweep_result *r, const char *text, size_t len, bsim_error *err)
{
	char summary[BSIM_PATH_MAX], trials[BSIM_PATH_MAX], traj[BSIM_PATH_MAX],
	        traj_mat[BSIM_PATH_MAX];
	if (bsim_session_path(summary, sizeof summary, dir, "summary.json", err) ||
	    bsim_session_path(trials, sizeof trials, dir, "trials.csv", err) ||
	    bsim_session_path(traj, sizeof traj, dir, "trajectories.csv", err) ||
	    bsim_session_path(traj_mat, sizeof traj_mat, dir, "trajectories.mat", err))
		return BSIM_EFAIL;
	if (r->keep == 0) {
		remove(traj);
		remove(traj_mat);
	}
	if (bsim_output_mkdir(dir, err) != BSIM_OK ||
	    bsim_output_summary_json(summary, e, b->name, opts, r, err) != BSIM_OK ||
	    (r->trials_out && !text && bsim_trials_csv_write(trials, e, r, err) != BSIM_OK) ||
	    (text && bytes_write(trials, text, len, err) != BSIM_OK) ||
	    (r->trials_out && survival_files(dir, e, extra, n_extra, r, err) != BSIM_OK) ||
	    bsim_output_lattice(dir, e, extra, n_extra, r, err) != BSIM_OK ||
	    bsim_output_trajectories_csv(traj, r, err) != BSIM_OK ||
	    bsim_matlab_sweep(dir, e, text != NULL, err) != BSIM_OK)
		return BSIM_EFAIL;
	return BSIM_OK;
}

int bsim_store_sweep_files(const char *dir, const bsim_experiment *e, const bsim_backend *b,
                           const bsim_options *opts, const bsim_override *extra, int n_extra,
                           const bsim_sweep_result *r, bsim_error *err)
{
	return sweep_files(dir, e, b, opts, extra, n_extra, r, NULL, 0, err);
}

int bsim_store_read_files(const char *dir, const bsim_experiment *e, const bsim_backend *b,
                          const bsim_override *extra, int n_extra, const bsim_sweep_result *r,
                          const char *text, size_t len, bsim_error *err)
{
	bsim_options none = {0};
	return sweep_files(dir, e, b, &none, extra, n_extra, r, text, len, err);
}

int bsim_store_twin(const char *dir, const char *file, const char *var, bsim_error *err)
{
	char path[BSIM_PATH_MAX], mat[BSIM_PATH_MAX];
	if (bsim_session_path(path, sizeof path, dir, file, err))
		return BSIM_EFAIL;
	int rc = bsim_matlab_path(path, mat, sizeof mat, err);
	if (rc == BSIM_OK)
		rc = strstr(file, ".json") ? bsim_matlab_from_json(path, mat, var, err)
		                           : bsim_matlab_from_csv(path, mat, var, err);
	return rc;
}

int bsim_store_text(const char *dir, const char *name, const char *head, bsim_store_text_fn fn,
                    const void *arg, bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	bsim_atomic_file o;
	if (bsim_session_path(path, sizeof path, dir, name, err) ||
	    bsim_atomic_file_open(&o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	if (head)
		fputs(head, o.f);
	fn(o.f, arg);
	return bsim_atomic_file_commit(&o, err);
}

long bsim_store_unstable(const bsim_experiment *e, const bsim_override *extra, int n_extra,
                         const bsim_sweep_result *r, long *first, char *why, size_t size)
{
	long count = 0;
	*first = -1;
	if (size > 0)
		why[0] = '\0';
	const bsim_trial_result *x = NULL;
	if (r->trials_out) {
		for (long i = 0; i < (long)r->n_groups * r->trials; i++)
			if (r->trials_out[i].outcome == BSIM_UNSTABLE) {
				count++;
				*first = *first < 0 ? i : *first;
			}
		x = *first >= 0 ? &r->trials_out[*first] : NULL;
	} else {
		/* A streamed sweep keeps the counts and its first unstable trial. */
		for (int g = 0; g < r->n_groups; g++)
			count += r->groups[g].unstable;
		*first = r->first_unstable;
		x = *first >= 0 ? &r->first_unstable_result : NULL;
	}
	bsim_scene scene;
	bsim_error err;
	if (count > 0 && x &&
	    bsim_experiment_group_scene(e, (int)(*first / r->trials), extra, n_extra, &scene,
	                                &err) == BSIM_OK) {
		bsim_trial_instability_text(x, scene.dt, why, size);
		bsim_scene_free(&scene);
	}
	return count;
}

int bsim_store_experiment(const char *path, const bsim_override *sets, int n_sets,
                          const bsim_grid_axis *grid, int n_grid, long trials, const uint64_t *seed,
                          bsim_experiment *e, bsim_error *err)
{
	int rc = bsim_experiment_load_seeded(path, sets, n_sets, grid, n_grid, seed, e, err);
	if (rc != BSIM_OK)
		return rc ? rc : BSIM_EINPUT;
	if (trials > 0 && bsim_experiment_check_trials(e, trials, err) != BSIM_OK) {
		char msg[sizeof err->msg];
		snprintf(msg, sizeof msg, "%s", err->msg);
		bsim_experiment_free(e);
		return bsim_error_set(err, BSIM_EINPUT, "--trials %ld: %s", trials, msg);
	}
	if (trials > 0)
		e->trials = (int)trials;
	return BSIM_OK;
}
