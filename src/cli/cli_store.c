/* Running and storing sweeps and comparisons; see cli_store.h. */
#define _POSIX_C_SOURCE 200809L

#include "cli_store.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/atomic_file.h"
#include "beamsim/matlab.h"
#include "beamsim/output.h"
#include "beamsim/progress.h"
#include "beamsim/report.h"
#include "cli_common.h"

void cli_label_dir(const char *label, char *buf, size_t size)
{
	size_t k = 0;
	for (; *label && k + 1 < size; label++)
		buf[k++] = *label == ':' || *label == '/' ? '-' : *label;
	if (size > 0)
		buf[k] = '\0';
}

int cli_path(char *buf, size_t size, const char *dir, const char *name)
{
	int n = snprintf(buf, size, "%s/%s", dir, name);
	if (n < 0 || (size_t)n >= size) {
		cli_error("%s/%s: path too long", dir, name);
		return CLI_FAIL;
	}
	return CLI_OK;
}

static void record_fill(bsim_run_record *rec, const char *command, const bsim_experiment *e, int n,
                        const bsim_backend *const *b, const bsim_options *const *opts,
                        const char *const *label, const bsim_compare_rule *rule)
{
	memset(rec, 0, sizeof *rec);
	snprintf(rec->command, sizeof rec->command, "%s", command);
	rec->n_backends = n;
	for (int i = 0; i < n; i++) {
		snprintf(rec->backend[i], sizeof rec->backend[i], "%s", b[i]->name);
		snprintf(rec->label[i], sizeof rec->label[i], "%s", label ? label[i] : b[i]->name);
		bsim_options_effective(b[i], opts[i], &rec->opts[i]);
	}
	rec->seed = e->seed;
	rec->trials = e->trials;
	if (rule)
		rec->rule = *rule;
	else
		rec->rule = (bsim_compare_rule){BSIM_COMPARE_ALPHA, BSIM_COMPARE_MARGIN, 0};
}

/* summary.json, trials.csv, trajectories.csv when trajectories were kept
 * (a stale one of an earlier run is removed, so the directory never pairs
 * trials with trajectories of another run), and their .mat twins. */
static int sweep_files(const char *dir, const bsim_experiment *e, const bsim_backend *b,
                       const bsim_options *opts, const bsim_sweep_result *r)
{
	char summary[1100], trials[1100], traj[1100], traj_mat[1100];
	bsim_error err;
	if (cli_path(summary, sizeof summary, dir, "summary.json") ||
	    cli_path(trials, sizeof trials, dir, "trials.csv") ||
	    cli_path(traj, sizeof traj, dir, "trajectories.csv") ||
	    cli_path(traj_mat, sizeof traj_mat, dir, "trajectories.mat"))
		return CLI_FAIL;
	if (r->keep == 0) {
		remove(traj);
		remove(traj_mat);
	}
	if (bsim_output_mkdir(dir, &err) != BSIM_OK ||
	    bsim_output_summary_json(summary, e, b->name, opts, r, &err) != BSIM_OK ||
	    bsim_output_trials_csv(trials, e, r, &err) != BSIM_OK ||
	    bsim_output_trajectories_csv(traj, r, &err) != BSIM_OK ||
	    bsim_matlab_sweep(dir, e, &err) != BSIM_OK) {
		cli_error("%s", err.msg);
		return CLI_FAIL;
	}
	return CLI_OK;
}

/* DIR/NAME.csv or .json as DIR/NAME.mat, variable NAME. */
static int twin_file(const char *dir, const char *file, const char *var)
{
	char path[1100], mat[1100];
	bsim_error err;
	if (cli_path(path, sizeof path, dir, file))
		return CLI_FAIL;
	int rc = bsim_matlab_path(path, mat, sizeof mat, &err);
	if (rc == BSIM_OK)
		rc = strstr(file, ".json") ? bsim_matlab_from_json(path, mat, var, &err)
		                           : bsim_matlab_from_csv(path, mat, var, &err);
	return cli_report(rc, &err);
}

int cli_store_sweep(const char *dir, const bsim_experiment *e, const bsim_backend *b,
                    const bsim_options *opts, const bsim_override *extra, int n_extra,
                    const bsim_sweep_result *r)
{
	bsim_run_record rec;
	bsim_error err;
	if (sweep_files(dir, e, b, opts, r) != CLI_OK)
		return CLI_FAIL;
	record_fill(&rec, "sweep", e, 1, &b, &opts, NULL, NULL);
	if (bsim_run_record_write(dir, &rec, e, extra, n_extra, &err) != BSIM_OK) {
		cli_error("%s", err.msg);
		return CLI_FAIL;
	}
	return CLI_OK;
}

typedef void (*report_fn)(FILE *f, const bsim_report *r);

static int report_file(const char *dir, const char *name, const char *title, report_fn fn,
                       const bsim_report *r)
{
	char path[1100];
	bsim_atomic_file o;
	bsim_error err;
	if (cli_path(path, sizeof path, dir, name))
		return CLI_FAIL;
	if (bsim_atomic_file_open(&o, path, &err) != BSIM_OK) {
		cli_error("%s", err.msg);
		return CLI_FAIL;
	}
	if (title)
		fputs(title, o.f);
	fn(o.f, r);
	if (bsim_atomic_file_commit(&o, &err) != BSIM_OK) {
		cli_error("%s", err.msg);
		return CLI_FAIL;
	}
	return CLI_OK;
}

/* The report's heading: what was compared, how to reproduce it. */
static char *compare_title(const cli_compare_job *job)
{
	char *buf = NULL;
	size_t len = 0;
	FILE *f = open_memstream(&buf, &len);
	if (!f)
		return NULL;
	fprintf(f, "# beamsim compare: %s vs %s\n\n", job->label[0], job->label[1]);
	fprintf(f,
	        "Experiment `%s` (scene `%s`), seed %llu, %d groups x %d trials; both sides "
	        "ran every trial with the same random-force schedule, so trial t of group g is "
	        "a pair.\n\n",
	        job->e->path, job->e->scene_path, (unsigned long long)job->e->seed,
	        job->e->n_groups, job->e->trials);
	for (int i = 0; i < 2; i++) {
		fprintf(f, "- %s: backend %s, options ", job->label[i], job->backend[i]->name);
		bsim_output_backend_options(f, job->backend[i], job->opts[i]);
		fputc('\n', f);
	}
	fputc('\n', f);
	fclose(f);
	return buf;
}

static int compare_write(const cli_compare_job *job, const bsim_sweep_result r[2],
                         const double *t_sep, const bsim_comparison *cmp)
{
	bsim_report rep = {
	        .e = job->e,
	        .extra = job->extra,
	        .n_extra = job->n_extra,
	        .t_separate = t_sep,
	        .cmp = cmp,
	        .examples = job->examples,
	};
	for (int i = 0; i < 2; i++) {
		char dir[1100], name[128];
		rep.side[i] =
		        (bsim_report_side){job->label[i], job->backend[i], job->opts[i], &r[i]};
		cli_label_dir(job->label[i], name, sizeof name);
		if (cli_path(dir, sizeof dir, job->out, name) ||
		    sweep_files(dir, job->e, job->backend[i], job->opts[i], &r[i]))
			return CLI_FAIL;
	}
	char *title = compare_title(job);
	int rc = report_file(job->out, "pairs.csv", NULL, bsim_report_pairs_csv, &rep);
	if (rc == CLI_OK)
		rc = report_file(job->out, "report.json", NULL, bsim_report_json, &rep);
	if (rc == CLI_OK)
		rc = report_file(job->out, "report.md", title ? title : "", bsim_report_md, &rep);
	free(title);
	if (rc == CLI_OK)
		rc = twin_file(job->out, "pairs.csv", "pairs");
	if (rc == CLI_OK)
		rc = twin_file(job->out, "report.json", "report");
	if (rc != CLI_OK)
		return rc;
	bsim_run_record rec;
	bsim_error err;
	record_fill(&rec, "compare", job->e, 2, job->backend, job->opts, job->label, &job->rule);
	if (bsim_run_record_write(job->out, &rec, job->e, job->extra, job->n_extra, &err) !=
	    BSIM_OK) {
		cli_error("%s", err.msg);
		return CLI_FAIL;
	}
	return CLI_OK;
}

int cli_compare_execute(const cli_compare_job *job, bsim_comparison *cmp)
{
	bsim_progress progress;
	bsim_error err;
	bsim_sweep_result r[2];
	double *t_sep = NULL;
	bsim_sweep_config cfg = {
	        .backend = job->backend[0],
	        .opts = job->opts[0],
	        .threads = job->threads,
	        .extra = job->extra,
	        .n_extra = job->n_extra,
	        .progress = bsim_progress_update,
	        .progress_user = &progress,
	        .keep = job->keep,
	        .keep_stride = job->keep_stride,
	};
	memset(cmp, 0, sizeof *cmp);
	bsim_progress_init(&progress, job->progress);
	int rc = bsim_sweep_run_paired(job->e, &cfg, job->backend[1], job->opts[1], &r[0], &r[1],
	                               &t_sep, &err);
	bsim_progress_finish(&progress);
	if (rc != BSIM_OK)
		return cli_report(rc, &err);
	rc = bsim_compare_analyse(&r[0], &r[1], t_sep, &job->rule, cmp, &err);
	if (rc != BSIM_OK)
		rc = cli_report(rc, &err);
	else
		rc = compare_write(job, r, t_sep, cmp);
	bsim_sweep_result_free(&r[0]);
	bsim_sweep_result_free(&r[1]);
	free(t_sep);
	return rc;
}
