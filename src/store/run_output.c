/* The record of one trial and the directory of `beamsim run --out`
 * (beamsim/run_output.h). */
#define _POSIX_C_SOURCE 200809L
#include "beamsim/run_output.h"

#include <inttypes.h>
#include <string.h>

#include "beamsim/backend_registry.h"
#include "util/atomic_file.h"
#include "util/json.h"
#include "beamsim/lattice.h"
#include "store/matlab.h"
#include "beamsim/output.h"
#include "beamsim/version.h"
#include "beamsim/lattice_outcome.h"
#include "store/session.h"
#include "beamsim/limits.h"

bsim_run_info bsim_run_info_default(void)
{
	bsim_run_info i;
	memset(&i, 0, sizeof i);
	i.backend = bsim_backend_default();
	i.seed = 1;
	i.stride = 1;
	return i;
}

#define JSON_RESULT(m) BSIM_JSON_MEMBER(f, sep, r, m);
#define JSON_LEDGER(m) BSIM_JSON_MEMBER(f, sep, &r->ledger, m);
#define JSON_SOLVER(m) BSIM_JSON_MEMBER(f, sep, &r->solver, m);

/* The final gate and location, the gate path and every beam's peak (the
 * lattice's per-trial data; the path and peaks only with a log). */
static void path_json(FILE *f, const bsim_trial_result *r, const bsim_trial_log *log)
{
	char label[48];
	bsim_lattice_location_label(bsim_lattice_location_of(r), label, sizeof label);
	fprintf(f, ", \"final_gate\": [%d, %d], \"location\": \"%s\", \"reset_overlaps\": %d",
	        r->final_ix, r->final_iy, label, r->reset_overlaps);
	if (!log)
		return;
	fputs(", \"path\": [", f);
	for (int k = 0; k < log->n_entries; k++) {
		const bsim_gate_entry *e = &log->entries[k];
		fprintf(f, "%s{\"gate\": [%d, %d], \"edge\": \"%s\", \"t\": ", k ? ", " : "", e->ix,
		        e->iy, bsim_trial_edge_name(e->edge));
		bsim_json_number(f, e->t);
		fputs(", \"pos\": ", f);
		bsim_json_number(f, e->pos);
		fputs(", \"v\": [", f);
		bsim_json_number(f, e->v[0]);
		fputs(", ", f);
		bsim_json_number(f, e->v[1]);
		fputs("]}", f);
	}
	fputs("], \"peak_theta\": [", f);
	for (int i = 0, k = 0; i < log->n_beams; i++) {
		/* the moved beams in ascending order; every other beam's is 0 */
		int moved = k < log->n_peaks && log->peaks[k].beam == i;
		fputs(i ? ", " : "", f);
		bsim_json_number(f, moved ? log->peaks[k++].peak : 0.0);
	}
	fputc(']', f);
}

static void record_json(FILE *f, const bsim_run_info *info)
{
	fputs(", \"command\": \"run\", \"beamsim_version\": ", f);
	bsim_json_string(f, BSIM_VERSION);
	fprintf(f, ", \"stride\": %d, \"scene_copy\": \"inputs/scene.yaml\", \"set\": {",
	        info->stride);
	for (int i = 0; i < info->n_sets; i++) {
		fputs(i ? ", " : "", f);
		bsim_json_string(f, info->sets[i].key);
		fputs(": ", f);
		bsim_json_string(f, info->sets[i].value);
	}
	fputc('}', f);
}

void bsim_run_output_json(FILE *f, const bsim_run_info *info, const bsim_trial_result *r,
                          int record)
{
	fputs("{\"scene\": ", f);
	bsim_json_string(f, info->scene_path);
	fputs(", \"name\": ", f);
	bsim_json_string(f, info->scene->name);
	fputs(", \"backend\": ", f);
	bsim_json_string(f, info->backend->name);
	fputs(", \"backend_options\": ", f);
	bsim_output_backend_options(f, info->backend, info->opts);
	fputs(", \"seed\": ", f);
	bsim_json_u64(f, info->seed);
	fprintf(f, ", \"group\": %ld, \"trial\": %ld, \"mixed_seed\": ", info->group, info->trial);
	bsim_json_u64(f, info->mixed_seed);
	fputs(", \"outcome\": ", f);
	bsim_json_string(f, bsim_trial_outcome_name(r->outcome));
	fputs(", \"type\": ", f);
	bsim_json_string(f, bsim_trial_type_name(r->type));
	fprintf(f, ", \"landscape_left\": %d, \"landscape_beam\": ", r->landscape_beam == 0);
	if (r->landscape_beam >= 0)
		fprintf(f, "%d", r->landscape_beam + 1);
	else
		fputs("null", f);
	const char *sep = ", ";
	BSIM_TRIAL_RESULT_PLAIN(JSON_RESULT)
	path_json(f, r, info->log);
	fputs(", \"ledger\": {", f);
	sep = "";
	BSIM_LEDGER_SHOWN(JSON_LEDGER)
	fputs("}, \"solver\": {", f);
	sep = "";
	BSIM_SOLVER_COUNTS(JSON_SOLVER)
	fputc('}', f);
	fputs(", \"instability\": ", f);
	if (r->instability) {
		char why[256];
		bsim_trial_instability_text(r, info->scene->dt, why, sizeof why);
		bsim_json_string(f, why);
	} else {
		fputs("null", f);
	}
	if (record)
		record_json(f, info);
	fputs("}\n", f);
}

/* The open files of `run --out DIR`, in the staging area. */
typedef struct run_dir {
	char dir[BSIM_PATH_MAX - BSIM_NAME_MAX];
	char traj_path[BSIM_PATH_MAX], ledger_path[BSIM_PATH_MAX];
	bsim_atomic_file traj, ledger;
} run_dir;

static int run_dir_open(run_dir *o, const char *dir, int n_beams, int body_columns,
                        bsim_recorder *rec, bsim_error *err)
{
	memset(o, 0, sizeof *o);
	if (strlen(dir) >= sizeof o->dir - 32)
		return bsim_error_set(err, BSIM_EFAIL, "%s: path too long", dir);
	snprintf(o->dir, sizeof o->dir, "%s", dir);
	snprintf(o->traj_path, sizeof o->traj_path, "%s/trajectory.csv", dir);
	snprintf(o->ledger_path, sizeof o->ledger_path, "%s/ledger.csv", dir);
	if (bsim_output_mkdir(dir, err) != BSIM_OK)
		return BSIM_EFAIL;
	if (bsim_atomic_file_open(&o->traj, o->traj_path, err) != BSIM_OK)
		return BSIM_EFAIL;
	if (bsim_atomic_file_open(&o->ledger, o->ledger_path, err) != BSIM_OK) {
		bsim_atomic_file_abort(&o->traj);
		return BSIM_EFAIL;
	}
	bsim_trial_trajectory_header_body(o->traj.f, n_beams, body_columns);
	bsim_trial_ledger_header(o->ledger.f);
	rec->csv = o->traj.f;
	rec->ledger = o->ledger.f;
	return BSIM_OK;
}

static void run_dir_abort(run_dir *o)
{
	bsim_atomic_file_abort(&o->traj);
	bsim_atomic_file_abort(&o->ledger);
}

/* Once the trial has run: trajectory.csv and ledger.csv, their twins,
 * inputs/scene.yaml and, last, run.json. */
static int run_dir_commit(run_dir *o, const bsim_run_info *info, const bsim_trial_result *r,
                          bsim_error *err)
{
	char path[BSIM_PATH_MAX], mat[BSIM_PATH_MAX];
	int rc = bsim_atomic_file_commit(&o->traj, err);
	if (rc) {
		bsim_atomic_file_abort(&o->ledger);
		return rc;
	}
	rc = bsim_atomic_file_commit(&o->ledger, err);
	if (!rc)
		rc = bsim_matlab_path(o->traj_path, mat, sizeof mat, err);
	if (!rc)
		rc = bsim_matlab_from_csv(o->traj_path, mat, "trajectory", err);
	if (!rc)
		rc = bsim_matlab_path(o->ledger_path, mat, sizeof mat, err);
	if (!rc)
		rc = bsim_matlab_from_csv(o->ledger_path, mat, "ledger", err);
	snprintf(path, sizeof path, "%s/inputs", o->dir);
	if (!rc)
		rc = bsim_output_mkdir(path, err);
	snprintf(path, sizeof path, "%s/inputs/scene.yaml", o->dir);
	if (!rc && info->scene_path)
		rc = bsim_atomic_file_copy(info->scene_path, path, err);
	snprintf(path, sizeof path, "%s/run.json", o->dir);
	bsim_atomic_file f;
	if (!rc)
		rc = bsim_atomic_file_open(&f, path, err);
	if (!rc) {
		bsim_run_output_json(f.f, info, r, 1);
		rc = bsim_atomic_file_commit(&f, err);
	}
	return rc;
}

/* The trajectory file's twin: read back from the file, so only for a
 * regular file (a pipe, a terminal or standard output cannot be, and a
 * link's twin would not be its). */
static int trajectory_commit(bsim_atomic_file *traj, const char *path, bsim_error *err)
{
	char mat[BSIM_PATH_MAX];
	int through = traj->mode != BSIM_ATOMIC_RENAME;
	int rc = bsim_atomic_file_commit(traj, err);
	if (rc == BSIM_OK && !through) {
		rc = bsim_matlab_path(path, mat, sizeof mat, err);
		if (rc == BSIM_OK)
			rc = bsim_matlab_from_csv(path, mat, "trajectory", err);
	}
	return rc;
}

/* The folders above the trajectory file, created if missing as --out's
 * are (mkdir -p): a new folder for one file should not need its own step. */
static int trajectory_parent(const char *path, bsim_error *err)
{
	char dir[BSIM_PATH_MAX];
	const char *slash = strrchr(path, '/');
	if (strcmp(path, "-") == 0 || !slash || slash == path)
		return BSIM_OK;
	if ((size_t)(slash - path) >= sizeof dir)
		return bsim_error_set(err, BSIM_EFAIL, "%s: path too long", path);
	snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path);
	return bsim_output_mkdir(dir, err);
}

int bsim_run_output_trial(const bsim_run_info *info, const char *trajectory, const char *out,
                          int overwrite, bsim_trial_result *res, bsim_error *err)
{
	bsim_atomic_file traj = {0};
	run_dir dir;
	bsim_trial_log *log = (bsim_trial_log *)info->log;
	int stride = info->stride > 0 ? info->stride : 1;
	bsim_recorder rec = {.stride = stride, .log = log, .overlap = 1};
	const bsim_scene *scene = info->scene;
	memset(res, 0, sizeof *res);
	/* What the backend refuses of the scene, said where the scene gave it,
	 * before any file is opened. */
	int rc0 = bsim_backend_check(info->backend, info->opts, scene, info->scene_path, info->sets,
	                             info->n_sets, err);
	if (rc0 != BSIM_OK)
		return rc0;
	if (trajectory) {
		if (trajectory_parent(trajectory, err) != BSIM_OK ||
		    bsim_atomic_file_open(&traj, trajectory, err) != BSIM_OK)
			return BSIM_EFAIL;
		bsim_trial_trajectory_header_body(traj.f, scene->n_beams,
		                                  bsim_trial_body_columns(scene));
		rec.csv = traj.f;
	}
	/* DIR is checked before the trial runs and its files appear together. */
	bsim_session ss;
	if (out) {
		int rc = bsim_session_open(&ss, out, bsim_session_mode(0, overwrite), "run", NULL,
		                           NULL, 0, err);
		if (rc != BSIM_OK) {
			bsim_atomic_file_abort(&traj);
			return rc;
		}
		if (run_dir_open(&dir, ss.stage, scene->n_beams, bsim_trial_body_columns(scene),
		                 &rec, err)) {
			bsim_atomic_file_abort(&traj);
			return bsim_session_close(&ss, BSIM_EFAIL, "run", NULL, err);
		}
		/* One recorder writes both: the directory's trajectory and
		 * ledger, and the CSV of the trajectory file. */
		if (trajectory) {
			rec.record = bsim_trial_trajectory_row;
			rec.record_user = traj.f;
		}
	}
	int rc = BSIM_OK;
	bsim_trial_runner *runner = bsim_trial_runner_alloc();
	if (!runner)
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory for a trial runner");
	if (rc == BSIM_OK)
		rc = bsim_trial_run(runner, scene, info->backend, info->opts, info->mixed_seed,
		                    &rec, res, err);
	bsim_trial_runner_free(runner);
	if (rc == BSIM_OK && trajectory)
		rc = trajectory_commit(&traj, trajectory, err);
	else
		bsim_atomic_file_abort(&traj);
	if (!out)
		return rc;
	if (rc == BSIM_OK)
		rc = run_dir_commit(&dir, info, res, err);
	else
		run_dir_abort(&dir);
	return bsim_session_close(&ss, rc, "run", NULL, err);
}
