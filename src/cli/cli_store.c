/* Running and storing sweeps and comparisons; see cli_store.h. */
#define _POSIX_C_SOURCE 200809L

#include "cli_store.h"

#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "atomic_file.h"
#include "matlab.h"
#include "beamsim/output.h"
#include "progress.h"
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

void cli_record_fill(bsim_run_record *rec, const char *command, const bsim_experiment *e, int n,
                     const bsim_backend *const *b, const bsim_options *const *opts,
                     const char *const *label, const bsim_compare_rule *rule)
{
	memset(rec, 0, sizeof *rec);
	snprintf(rec->command, sizeof rec->command, "%s", command);
	rec->n_backends = n;
	for (int i = 0; i < n; i++) {
		snprintf(rec->backend[i], sizeof rec->backend[i], "%s", b[i]->name);
		snprintf(rec->label[i], sizeof rec->label[i], "%s", label ? label[i] : b[i]->name);
		bsim_options_effective(b[i]->knobs, b[i]->n_knobs, opts[i], &rec->opts[i]);
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
                       const bsim_options *opts, const bsim_override *extra, int n_extra,
                       const bsim_sweep_result *r)
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
	    bsim_output_lattice(dir, e, extra, n_extra, r, &err) != BSIM_OK ||
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
	if (sweep_files(dir, e, b, opts, extra, n_extra, r) != CLI_OK)
		return CLI_FAIL;
	cli_record_fill(&rec, "sweep", e, 1, &b, &opts, NULL, NULL);
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
	if (job->protocol[0])
		fprintf(f,
		        "The lattice protocols %s and %s on backend %s: `lattice.protocol=%s` for "
		        "one side, `=%s` for the other.\n\n",
		        job->protocol[0], job->protocol[1], job->backend[0]->name, job->protocol[0],
		        job->protocol[1]);
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
	        .extra_b = job->extra_b,
	        .n_extra_b = job->n_extra_b,
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
		    sweep_files(dir, job->e, job->backend[i], job->opts[i], job->extra,
		                job->n_extra, &r[i]))
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
	cli_record_fill(&rec, "compare", job->e, 2, job->backend, job->opts, job->label,
	                &job->rule);
	for (int i = 0; job->protocol[0] && i < 2; i++)
		snprintf(rec.protocol[i], sizeof rec.protocol[i], "%s", job->protocol[i]);
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
	        .extra_b = job->extra_b,
	        .n_extra_b = job->n_extra_b,
	        .keep = job->keep,
	        .keep_stride = job->keep_stride,
	        .journal = job->journal,
	        .stop = job->stop,
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

/* ---- sessions: output directory, journal, signals ----------------------- */

volatile sig_atomic_t cli_stop;

/* The first SIGINT or SIGTERM asks the run to stop; a second one ends the
 * process at once, which loses nothing the journal holds. */
static void on_signal(int sig)
{
	if (cli_stop) {
		signal(sig, SIG_DFL);
		raise(sig);
		return;
	}
	cli_stop = sig;
}

static void signals_install(void)
{
	struct sigaction sa;
	memset(&sa, 0, sizeof sa);
	sa.sa_handler = on_signal;
	sigemptyset(&sa.sa_mask);
	sa.sa_flags = SA_RESTART;
	sigaction(SIGINT, &sa, NULL);
	sigaction(SIGTERM, &sa, NULL);
}

/* An argument as the shell needs it: bare if it is safe, else quoted. */
static void shell_word(FILE *f, const char *w)
{
	if (*w && strspn(w, "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789"
	                    "_-+=.,:/@%") == strlen(w)) {
		fputs(w, f);
		return;
	}
	fputc('\'', f);
	for (; *w; w++)
		if (*w == '\'')
			fputs("'\\''", f);
		else
			fputc(*w, f);
	fputc('\'', f);
}

/* "beamsim sweep ... --resume": the command line that continues the run. */
static void resume_line(FILE *f, const cli_session *s)
{
	int has = 0;
	fputs("beamsim", f);
	for (int i = 0; i < s->argc; i++) {
		fputc(' ', f);
		shell_word(f, s->argv[i]);
		has |= strcmp(s->argv[i], "--resume") == 0;
	}
	if (!has)
		fputs(" --resume", f);
}

int cli_session_open(cli_session *s, const char *dir, int resume, const char *inputs,
                     size_t record_size, int argc, char **argv)
{
	bsim_error err;
	struct stat st;
	memset(s, 0, sizeof *s);
	s->dir = dir;
	s->argc = argc;
	s->argv = argv;
	if (bsim_outdir_open(&s->od, dir, &err) != BSIM_OK)
		return cli_report(err.code, &err);
	s->stage = bsim_outdir_stage(s->od);
	cli_error_paths(s->od);
	if (!inputs)
		return CLI_OK;
	if (cli_path(s->journal_path, sizeof s->journal_path, bsim_outdir_work(s->od), "journal")) {
		cli_session_close(s, CLI_USAGE, NULL);
		return CLI_USAGE;
	}
	int have = stat(s->journal_path, &st) == 0;
	int rc = BSIM_OK;
	if (resume && !have) {
		int finished = 0;
		bsim_outdir_verify(dir, &finished, &err);
		cli_error("--resume: %s holds %s", dir,
		          finished ? "a finished run, nothing to resume (run without --resume to "
		                     "replace it)"
		                   : "no stopped run to resume (run without --resume)");
		rc = BSIM_EINPUT;
	} else if (!resume && have) {
		cli_error(
		        "%s holds the journal of a stopped run (%s): add --resume to continue it, "
		        "or delete the journal to start over",
		        dir, s->journal_path);
		rc = BSIM_EINPUT;
	} else if (resume) {
		rc = bsim_journal_resume(&s->journal, s->journal_path, inputs, record_size, &err);
		if (rc != BSIM_OK)
			cli_error("--resume: %s: %s", dir, err.msg);
	} else {
		rc = bsim_journal_create(&s->journal, s->journal_path, inputs, record_size, &err);
		if (rc != BSIM_OK)
			cli_error("%s", err.msg);
	}
	if (rc != BSIM_OK) {
		cli_session_close(s, rc, NULL);
		return rc;
	}
	cli_stop = 0;
	signals_install();
	return CLI_OK;
}

int cli_session_close(cli_session *s, int rc, const char *command)
{
	bsim_error err;
	int keep = 0;
	if (rc == CLI_OK && s->od) {
		int crc = s->add ? bsim_outdir_add(s->od, command, &err)
		                 : bsim_outdir_commit(s->od, command, &err);
		if (crc != BSIM_OK) {
			cli_report(BSIM_EFAIL, &err);
			rc = CLI_FAIL;
			keep = 1; /* the trials are done: --resume writes the files again */
		}
	} else if (rc == BSIM_ESTOPPED) {
		keep = 1;
	}
	/* A journal this session did not open (another run's, refused) is never
	 * touched; this session's is kept only to be resumed. */
	int ours = s->journal != NULL;
	if (s->journal && bsim_journal_close(s->journal, &err) != BSIM_OK && rc == CLI_OK)
		rc = cli_report(BSIM_EFAIL, &err);
	s->journal = NULL;
	if (ours && !keep)
		unlink(s->journal_path);
	if (rc == BSIM_ESTOPPED) {
		int sig = cli_stop ? (int)cli_stop : SIGINT;
		fprintf(stderr, "beamsim: %s: the finished trials are kept in %s; to continue: ",
		        sig == SIGTERM ? "SIGTERM" : "SIGINT", s->journal_path);
		resume_line(stderr, s);
		fputc('\n', stderr);
		rc = 128 + sig;
	} else if (keep && s->journal_path[0]) {
		fprintf(stderr,
		        "beamsim: the finished trials are kept in %s; to write the files "
		        "again: ",
		        s->journal_path);
		resume_line(stderr, s);
		fputc('\n', stderr);
	}
	cli_error_paths(NULL);
	bsim_outdir_close(s->od);
	s->od = NULL;
	if (s->journal_path[0]) {
		signal(SIGINT, SIG_DFL);
		signal(SIGTERM, SIG_DFL);
	}
	return rc;
}
