/* A comparison stored in an output directory; see beamsim/compare_dir.h.
 * The same order as a stored sweep (sweep_dir.c): inputs, then DIR and its
 * journal, then the pairs, then the files as one set. */
#define _POSIX_C_SOURCE 200809L

#include "beamsim/compare_dir.h"

#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/backend_registry.h"
#include "beamsim/output.h"
#include "beamsim/report.h"
#include "beamsim/run_record.h"
#include "store/compare_read.h"
#include "store/session.h"
#include "store/rerun.h"
#include "store/store.h"
#include "beamsim/limits.h"
#include "store/part_dir.h"
#include "util/clock.h"

bsim_compare_dir_def bsim_compare_dir_def_default(void)
{
	bsim_compare_dir_def d;
	memset(&d, 0, sizeof d);
	/* The registry's default comparison, its first two: with one backend
	 * registered, it against itself (which the run refuses unless the
	 * sides' options differ). */
	d.n_sides = 2;
	const bsim_backend *b[2];
	int n = bsim_backend_compared(b, 2);
	for (int i = 0; i < 2; i++) {
		d.side[i].backend = b[i < n ? i : 0];
		snprintf(d.side[i].label, sizeof d.side[i].label, "%s", d.side[i].backend->name);
	}
	d.rule = bsim_compare_rule_default();
	d.examples = 3;
	return d;
}

int bsim_compare_side_parse(const char *spec, bsim_compare_side *side, bsim_error *err)
{
	if (strncmp(spec, BSIM_TRIALS_PREFIX, strlen(BSIM_TRIALS_PREFIX)) == 0)
		return bsim_compare_read_side(spec, side, err);
	side->trials[0] = '\0';
	size_t n = bsim_backend_spec_name(spec);
	char name[1024];
	if (n == 0 || n >= sizeof name)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "--backends: side %s: expected NAME[:KEY=VALUE]...", spec);
	snprintf(name, sizeof name, "%.*s", (int)n, spec);
	bsim_error e;
	side->backend = bsim_backend_find(name, &e);
	if (!side->backend)
		return bsim_error_set(err, BSIM_EINPUT, "--backends: side %s: %s", spec, e.msg);
	/* The label: the backend's name (a plug-in's, not its path) and the
	 * options as given. */
	if (strlen(side->backend->name) + strlen(spec + n) >= sizeof side->label)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "--backends: side %s: its options are longer than %zu "
		                      "characters",
		                      spec, sizeof side->label - 1);
	if (bsim_backend_spec_options(spec, &side->opts, err) != BSIM_OK)
		return BSIM_EINPUT;
	snprintf(side->label, sizeof side->label, "%s%s", side->backend->name, spec + n);
	return BSIM_OK;
}

void bsim_compare_dir_result_free(bsim_compare_dir_result *res)
{
	bsim_compare_sides_free(&res->cmp);
	bsim_experiment_free(&res->e);
}

typedef struct compare_job {
	const bsim_compare_dir_def *def;
	const bsim_experiment *e;
	int n; /* sides */
	const bsim_backend *backend[BSIM_COMPARE_SIDES_MAX];
	const bsim_options *opts[BSIM_COMPARE_SIDES_MAX];
	const char *label[BSIM_COMPARE_SIDES_MAX];
	const char *dir[BSIM_COMPARE_SIDES_MAX];
	const bsim_override *sets; /* every group's, side a's protocol included */
	int n_sets;
	bsim_override protocol_b; /* side b's protocol, after the sets */
	const char *out;          /* the staging area */
	bsim_journal *journal;    /* NULL: none */
	int *done;                /* NULL, or set to 1 once every pair is journaled */
	bsim_run_record rec;
	double started; /* > 0: a gathered run's start (bsim_clock_seconds) */
	/* The sides read, not run (def->side[i].trials): read[i] holds the
	 * file and its trials; 0 for a side that runs. */
	int is_read[BSIM_COMPARE_SIDES_MAX];
	int n_read;
	compare_read read[BSIM_COMPARE_SIDES_MAX];
} compare_job;

/* The sides that run: their indices into idx, in order; how many. */
static int run_sides(const compare_job *job, int *idx)
{
	int n = 0;
	for (int i = 0; i < job->n; i++)
		if (!job->is_read[i])
			idx[n++] = i;
	return n;
}

/* The report's heading: what was compared, how to reproduce it. */
static char *compare_title(const compare_job *job)
{
	char *buf = NULL;
	size_t len = 0;
	FILE *f = open_memstream(&buf, &len);
	if (!f)
		return NULL;
	const char *const *protocol = job->def->protocol;
	fputs("# beamsim compare: ", f);
	for (int i = 0; i < job->n; i++)
		fprintf(f, "%s%s", i ? " vs " : "", job->label[i]);
	fputs("\n\n", f);
	if (protocol[0])
		fprintf(f,
		        "The lattice protocols %s and %s on backend %s: `lattice.protocol=%s` for "
		        "one side, `=%s` for the other.\n\n",
		        protocol[0], protocol[1], job->backend[0]->name, protocol[0], protocol[1]);
	fprintf(f,
	        "Experiment `%s` (scene `%s`), seed %llu, %d groups x %d trials; %s%s "
	        "ran every trial with the same random-force schedule, so trial t of group g is "
	        "a pair.\n\n",
	        job->e->path, job->e->scene_path, (unsigned long long)job->e->seed,
	        job->e->n_groups, job->e->trials, job->n == 2 ? "both sides" : "every side",
	        job->n_read == 0   ? ""
	        : job->n_read == 1 ? " (the one read from a file elsewhere)"
	                           : " (those read from files elsewhere)");
	for (int i = 0; i < job->n; i++) {
		if (job->is_read[i]) {
			fprintf(f,
			        "- %s: read from `%s` (FNV-1a 64 %s), made elsewhere: not run by "
			        "beamsim\n",
			        job->label[i], job->read[i].path, job->read[i].hash);
			continue;
		}
		fprintf(f, "- %s: backend %s, options ", job->label[i], job->backend[i]->name);
		bsim_output_backend_options(f, job->backend[i], job->opts[i]);
		fputc('\n', f);
	}
	fputc('\n', f);
	if (job->n_read > 0)
		fprintf(f,
		        "%s read rather than run: %s trials are taken as this experiment's on "
		        "the same schedules, checked to be every group and trial of it once in "
		        "beamsim's words. Separation times need both trajectories of a pair, and "
		        "are not measured.\n\n",
		        job->n_read == 1 ? "One side was" : "Sides were",
		        job->n_read == 1 ? "its" : "their");
	fclose(f);
	return buf;
}

static void write_pairs(FILE *f, const void *r)
{
	bsim_report_pairs_csv(f, r);
}

static void write_json(FILE *f, const void *r)
{
	bsim_report_json(f, r);
}

static void write_md(FILE *f, const void *r)
{
	bsim_report_md(f, r);
}

/* Each side's files in its directory: a sweep's, or a side read's. */
static int sides_write(const compare_job *job, const bsim_sweep_result *r, bsim_error *err)
{
	for (int i = 0; i < job->n; i++) {
		char dir[BSIM_PATH_MAX];
		const compare_read *rd = job->is_read[i] ? &job->read[i] : NULL;
		if (bsim_session_path(dir, sizeof dir, job->out, job->dir[i], err))
			return BSIM_EFAIL;
		if (rd ? bsim_store_read_files(dir, job->e, job->backend[i], job->sets, job->n_sets,
		                               &r[i], rd->bytes, rd->len, err)
		       : bsim_store_sweep_files(dir, job->e, job->backend[i], job->opts[i],
		                                job->sets, job->n_sets, &r[i], err))
			return BSIM_EFAIL;
	}
	return BSIM_OK;
}

/* With a side read from a file, the sides that ran are compared as their
 * trials.csv just written reads back (into out; the others lent from r):
 * every side then has the file's precision, so that the same trial is the
 * same in every field (a group's `changed`), as regress compares. */
static int sides_at_file_precision(const compare_job *job, const bsim_sweep_result *r,
                                   bsim_sweep_result *out, bsim_error *err)
{
	for (int i = 0; i < job->n; i++) {
		char dir[BSIM_PATH_MAX], path[BSIM_PATH_MAX];
		out[i] = r[i];
		if (job->is_read[i])
			continue;
		if (bsim_session_path(dir, sizeof dir, job->out, job->dir[i], err) ||
		    bsim_session_path(path, sizeof path, dir, "trials.csv", err) ||
		    bsim_output_trials_read(path, r[i].n_groups, r[i].trials, &out[i], err)) {
			while (i-- > 0)
				if (!job->is_read[i])
					bsim_sweep_result_free(&out[i]);
			return BSIM_EFAIL;
		}
		for (int g = 0; g < r[i].n_groups; g++)
			out[i].groups[g].deterministic = r[i].groups[g].deterministic;
		out[i].lattice = r[i].lattice;
		out[i].lattice_def = r[i].lattice_def;
	}
	return BSIM_OK;
}

static int compare_write(const compare_job *job, const bsim_sweep_result *r, const double *t_sep,
                         const bsim_compare_sides *cmp, bsim_error *err)
{
	const bsim_compare_dir_def *def = job->def;
	int protocols = def->protocol[0] != NULL;
	bsim_report_side sides[BSIM_COMPARE_SIDES_MAX];
	bsim_report rep = {
	        .e = job->e,
	        .extra = job->sets,
	        .n_extra = job->n_sets,
	        .extra_b = protocols ? &job->protocol_b : NULL,
	        .n_extra_b = protocols,
	        .t_separate = t_sep,
	        .cmp = &cmp->pairs[0],
	        .examples = def->examples,
	        .n_sides = job->n,
	        .sides = sides,
	        .all = cmp,
	};
	for (int i = 0; i < job->n; i++) {
		sides[i] = (bsim_report_side){job->label[i], job->backend[i], job->opts[i], &r[i],
		                              job->is_read[i] ? job->read[i].path : NULL};
		if (i < 2)
			rep.side[i] = sides[i];
	}
	char *title = compare_title(job);
	int rc = bsim_store_text(job->out, "pairs.csv", NULL, write_pairs, &rep, err);
	if (rc == BSIM_OK)
		rc = bsim_store_text(job->out, "report.json", NULL, write_json, &rep, err);
	if (rc == BSIM_OK)
		rc = bsim_store_text(job->out, "report.md", title ? title : "", write_md, &rep,
		                     err);
	free(title);
	if (rc == BSIM_OK)
		rc = bsim_store_twin(job->out, "pairs.csv", "pairs", err);
	if (rc == BSIM_OK)
		rc = bsim_store_twin(job->out, "report.json", "report", err);
	if (rc == BSIM_OK)
		rc = bsim_run_record_write(job->out, &job->rec, job->e, job->sets, job->n_sets,
		                           err);
	return rc;
}

/* Unstable trials on a side, over the whole comparison (copies of a
 * deterministic group's trial included). */
static long unstable_count(const bsim_sweep_result *r)
{
	long n = 0;
	for (int g = 0; g < r->n_groups; g++)
		n += r->groups[g].unstable;
	return n;
}

/* The sweep of the sides that run into r (their slots; a read side's slot
 * is left for its file's trials), their pairs' separation times into
 * *t_sep when every side runs. */
static int sides_sweep(const compare_job *job, const bsim_sweep_config *cfg, bsim_sweep_result *r,
                       double **t_sep, bsim_error *err)
{
	int idx[BSIM_COMPARE_SIDES_MAX], n_run = run_sides(job, idx);
	const bsim_backend *b[BSIM_COMPARE_SIDES_MAX];
	const bsim_options *o[BSIM_COMPARE_SIDES_MAX];
	bsim_sweep_result run[BSIM_COMPARE_SIDES_MAX];
	for (int k = 0; k < n_run; k++) {
		b[k] = job->backend[idx[k]];
		o[k] = job->opts[idx[k]];
	}
	*t_sep = NULL;
	int rc = BSIM_OK;
	if (n_run >= 2) {
		rc = bsim_sweep_run_sides(job->e, cfg, n_run, b, o, run, t_sep, err);
	} else if (n_run == 1) {
		bsim_sweep_config one = *cfg;
		one.backend = b[0];
		one.opts = o[0];
		rc = bsim_sweep_run(job->e, &one, &run[0], err);
	}
	if (rc != BSIM_OK)
		return rc;
	for (int k = 0; k < n_run; k++)
		r[idx[k]] = run[k];
	if (n_run < job->n) {
		/* The separation of a pair needs both its trajectories. */
		free(*t_sep);
		*t_sep = NULL;
	}
	return BSIM_OK;
}

static int compare_pairs(const compare_job *job, bsim_compare_dir_result *res, bsim_error *err)
{
	const bsim_compare_dir_def *def = job->def;
	int protocols = def->protocol[0] != NULL;
	bsim_sweep_result r[BSIM_COMPARE_SIDES_MAX];
	double *t_sep = NULL;
	bsim_sweep_config cfg = {
	        .threads = res->threads,
	        .extra = job->sets,
	        .n_extra = job->n_sets,
	        .progress = def->progress,
	        .progress_user = def->progress_user,
	        .extra_b = protocols ? &job->protocol_b : NULL,
	        .n_extra_b = protocols,
	        .keep = def->keep,
	        .keep_stride = def->keep_stride,
	        .journal = job->journal,
	        .stop = def->stop,
	};
	int rc = sides_sweep(job, &cfg, r, &t_sep, err);
	if (rc != BSIM_OK)
		return rc;
	if (job->done)
		*job->done = 1;
	res->n_sides = job->n;
	/* A gathered comparison's time is its parts' and the writing's. */
	double wall = job->started > 0 ? bsim_clock_seconds() - job->started : 0.0;
	for (int i = 0; i < job->n; i++) {
		if (job->is_read[i])
			r[i] = job->read[i].r; /* lent: freed with job->read */
		else if (job->started > 0)
			r[i].wall_seconds = wall;
		res->solver[i] = r[i].solver;
		res->unstable[i] = unstable_count(&r[i]);
	}
	rc = sides_write(job, r, err);
	bsim_sweep_result at[BSIM_COMPARE_SIDES_MAX];
	if (rc == BSIM_OK && job->n_read > 0)
		rc = sides_at_file_precision(job, r, at, err);
	if (rc == BSIM_OK) {
		rc = bsim_compare_analyse_sides(job->n_read > 0 ? at : r, job->n, t_sep, &def->rule,
		                                &res->cmp, err);
		for (int i = 0; job->n_read > 0 && i < job->n; i++)
			if (!job->is_read[i])
				bsim_sweep_result_free(&at[i]);
	}
	if (rc == BSIM_OK)
		rc = compare_write(job, r, t_sep, &res->cmp, err);
	for (int i = 0; i < job->n; i++)
		if (!job->is_read[i])
			bsim_sweep_result_free(&r[i]);
	free(t_sep);
	return rc;
}

/* "--backends A,B,C" as given, for messages. */
static void sides_text(const compare_job *job, char *buf, size_t size)
{
	size_t len = 0;
	buf[0] = '\0';
	for (int i = 0; i < job->n && len < size; i++) {
		int w = snprintf(buf + len, size - len, "%s%s", i ? "," : "", job->label[i]);
		len += w > 0 ? (size_t)w : 0;
	}
}

/* BSIM_EINPUT: sides i and j, one of them read from a file, have one
 * label. */
static int read_label_clash(const bsim_compare_dir_def *def, const compare_job *job, int i, int j,
                            const char *given, bsim_error *err)
{
	char side[2][BSIM_PATH_MAX + 16];
	for (int k = 0; k < 2; k++) {
		int s = k ? j : i;
		snprintf(side[k], sizeof side[k], "%s%s", job->is_read[s] ? BSIM_TRIALS_PREFIX : "",
		         job->is_read[s] ? def->side[s].trials : job->label[s]);
	}
	return bsim_error_set(err, BSIM_EINPUT,
	                      "--backends %s: sides %s and %s are both labelled %s (a side read "
	                      "from a file is labelled by the name of its folder); expected "
	                      "different labels: move the file to a folder of another name",
	                      given, side[0], side[1], job->label[i]);
}

/* The sides' backends, options, labels and directories; BSIM_EINPUT if
 * they cannot be told apart. */
static int sides_check(const bsim_compare_dir_def *def, compare_job *job,
                       bsim_compare_dir_result *res, bsim_error *err)
{
	job->n = def->n_sides;
	if (job->n < 2 || job->n > BSIM_COMPARE_SIDES_MAX || (def->protocol[0] && job->n != 2))
		return def->protocol[0]
		               ? bsim_error_set(err, BSIM_EINPUT,
		                                "--protocols: %d sides; expected 2", job->n)
		               : bsim_error_set(err, BSIM_EINPUT,
		                                "--backends: %d sides; expected 2 to %d", job->n,
		                                BSIM_COMPARE_SIDES_MAX);
	for (int i = 0; i < job->n; i++) {
		const bsim_compare_side *s = &def->side[i];
		job->is_read[i] = res->read[i] = s->trials[0] != '\0';
		job->n_read += job->is_read[i];
		if (job->is_read[i] && (def->protocol[0] || s->opts.n > 0))
			return bsim_error_set(err, BSIM_EINPUT,
			                      "--backends: side " BSIM_TRIALS_PREFIX
			                      "%s: expected a side read as it was made, %s",
			                      s->trials,
			                      def->protocol[0]
			                              ? "not a --protocols side"
			                              : "without options (it runs nothing)");
		job->backend[i] = job->is_read[i] ? &bsim_compare_read_backend
		                  : s->backend    ? s->backend
		                                  : bsim_backend_default();
		job->opts[i] = &s->opts;
		job->label[i] = def->protocol[0] ? def->protocol[i]
		                : s->label[0]    ? s->label
		                                 : job->backend[i]->name;
		if (strlen(job->label[i]) >= sizeof res->dir[i])
			return bsim_error_set(err, BSIM_EINPUT, "side %s: label too long",
			                      job->label[i]);
		bsim_compare_dir_label(job->label[i], res->dir[i], sizeof res->dir[i]);
		job->dir[i] = res->dir[i];
		const bsim_backend *b = job->backend[i];
		if (bsim_options_check(&s->opts, b->knobs, b->n_knobs, b->name, err) != BSIM_OK)
			return BSIM_EINPUT;
	}
	if (def->protocol[0]) {
		static const char *const known[] = {"world", "essay"};
		int ok = def->protocol[1] && strcmp(def->protocol[0], def->protocol[1]) != 0;
		for (int i = 0; ok && i < 2; i++)
			ok = strcmp(def->protocol[i], known[0]) == 0 ||
			     strcmp(def->protocol[i], known[1]) == 0;
		if (!ok)
			return bsim_error_set(err, BSIM_EINPUT,
			                      "--protocols %s,%s: expected two different lattice "
			                      "protocols, world,essay or essay,world",
			                      def->protocol[0],
			                      def->protocol[1] ? def->protocol[1] : "");
		if (job->backend[0] != job->backend[1])
			return bsim_error_set(err, BSIM_EINPUT,
			                      "--protocols runs one backend, not %s and %s",
			                      job->backend[0]->name, job->backend[1]->name);
		return BSIM_OK;
	}
	char given[BSIM_ERROR_MSG_MAX / 2];
	sides_text(job, given, sizeof given);
	for (int i = 0; i < job->n; i++)
		for (int j = i + 1; j < job->n; j++) {
			if (strcmp(job->label[i], job->label[j]) == 0 &&
			    (job->is_read[i] || job->is_read[j]))
				return read_label_clash(def, job, i, j, given, err);
			if (strcmp(job->label[i], job->label[j]) == 0 && job->n == 2)
				return bsim_error_set(
				        err, BSIM_EINPUT,
				        "--backends %s: expected two different sides (a backend "
				        "against itself takes options inline, e.g. "
				        "%s,%s:KEY=VALUE)",
				        given, job->backend[i]->name, job->backend[i]->name);
			if (strcmp(job->label[i], job->label[j]) == 0)
				return bsim_error_set(
				        err, BSIM_EINPUT,
				        "--backends %s: side %s is given twice; expected different "
				        "sides (a backend against itself takes options inline, "
				        "e.g. %s,%s:KEY=VALUE)",
				        given, job->label[i], job->backend[i]->name,
				        job->backend[i]->name);
			if (strcmp(res->dir[i], res->dir[j]) == 0)
				return bsim_error_set(
				        err, BSIM_EINPUT,
				        "--backends %s: sides %s and %s would write to %s/%s",
				        given, job->label[i], job->label[j], def->out, res->dir[i]);
		}
	return BSIM_OK;
}

/* The record of the run in job->rec. */
static void record_fill(compare_job *job)
{
	const bsim_compare_dir_def *def = job->def;
	bsim_run_record_fill(&job->rec, "compare", job->e, job->n, job->backend, job->opts,
	                     job->label, &def->rule);
	for (int i = 0; i < job->n; i++)
		if (job->is_read[i]) {
			snprintf(job->rec.read_from[i], sizeof job->rec.read_from[i], "%s",
			         job->read[i].path);
			snprintf(job->rec.read_hash[i], sizeof job->rec.read_hash[i], "%s",
			         job->read[i].hash);
		}
	for (int i = 0; def->protocol[0] && i < 2; i++)
		snprintf(job->rec.protocol[i], sizeof job->rec.protocol[i], "%s", def->protocol[i]);
}

/* This process's part of the pairs (part_dir_run_fn). */
static int compare_part_run(void *user, const bsim_sweep_part *part, bsim_error *err)
{
	const compare_job *job = user;
	const bsim_compare_dir_def *def = job->def;
	int protocols = def->protocol[0] != NULL;
	bsim_sweep_config cfg = {
	        .threads = def->threads > 0 ? def->threads : omp_get_max_threads(),
	        .extra = job->sets,
	        .n_extra = job->n_sets,
	        .progress = def->progress,
	        .progress_user = def->progress_user,
	        .extra_b = protocols ? &job->protocol_b : NULL,
	        .n_extra_b = protocols,
	        .journal = job->journal,
	        .stop = def->stop,
	};
	return bsim_sweep_run_part_sides(job->e, &cfg, job->n, job->backend, job->opts, part, err);
}

/* A spread comparison's part (def->spread, def->n_merge; see
 * beamsim/sweep_dir.h): *finished 1 when this process has nothing more to
 * do (a shard written, another rank's part sent). */
static int compare_spread(const bsim_compare_dir_def *def, compare_job *job, const char *inputs,
                          bsim_session *ss, size_t size, int *finished, bsim_error *err)
{
	long total = (long)job->e->n_groups * job->e->trials;
	part_dir_spread sp = {def->spread, &def->part, def->agree, "compare",
	                      size,        total,      def->argc,  def->argv};
	int rc;
	*finished = 0;
	if (def->n_merge > 0) {
		char run[17];
		bsim_part_dir_run_id(inputs, run);
		rc = bsim_part_dir_join(def->merge, def->n_merge, "compare", run, inputs, size,
		                        total, ss->journal, err);
		return rc == BSIM_OK ? bsim_part_dir_journal_reopen(ss, inputs, size, err) : rc;
	}
	job->journal = ss ? ss->journal : NULL;
	rc = bsim_part_dir_spread_run(&sp, inputs, ss, compare_part_run, job, err);
	if (rc != BSIM_OK || def->spread != BSIM_SPREAD_GATHER) {
		*finished = 1;
		return rc;
	}
	return bsim_part_dir_journal_reopen(ss, inputs, size, err);
}

/* Reads the files of the sides read, against job->e as it runs. */
static int reads_load(compare_job *job, bsim_error *err)
{
	for (int i = 0; i < job->n; i++)
		if (job->is_read[i] &&
		    bsim_compare_read_load(&job->def->side[i], job->e, job->sets, job->n_sets,
		                           &job->read[i], err) != BSIM_OK)
			return BSIM_EINPUT;
	return BSIM_OK;
}

static void reads_free(compare_job *job)
{
	for (int i = 0; i < job->n; i++)
		if (job->is_read[i])
			bsim_compare_read_free(&job->read[i]);
}

/* The size of the journal's records: those of the sweep of the sides
 * that run (none, one, or several), with cfg's overrides; and, where
 * cfg->planned is given and a side runs, the plan said from the groups'
 * scenes, built for it (bsim_sweep_plan_for, which sizes the records too). */
static int journal_record_size(const compare_job *job, const bsim_sweep_config *cfg, size_t *size,
                               bsim_error *err)
{
	int idx[BSIM_COMPARE_SIDES_MAX], n_run = run_sides(job, idx);
	*size = bsim_sweep_record_size(0);
	if (n_run >= 1 && cfg->planned) {
		bsim_scene *scenes = NULL;
		int rc = bsim_sweep_plan_for(job->e, cfg, n_run, size, &scenes, err);
		bsim_sweep_scenes_free(scenes, job->e->n_groups);
		return rc;
	}
	if (n_run == 1)
		return bsim_sweep_record_size_for(job->e, cfg, size, err);
	if (n_run >= 2)
		return bsim_sweep_record_size_sides_for(job->e, cfg, n_run, size, err);
	return BSIM_OK;
}

int bsim_compare_dir_run(const bsim_compare_dir_def *def, bsim_compare_dir_result *res,
                         bsim_error *err)
{
	double t0 = bsim_clock_seconds();
	memset(res, 0, sizeof *res);
	compare_job job = {.def = def, .sets = def->sets, .n_sets = def->n_sets};
	int rc = sides_check(def, &job, res, err);
	if (rc != BSIM_OK)
		return rc;
	if (job.n_read > 0 && (def->spread != BSIM_SPREAD_NONE || def->n_merge > 0))
		return bsim_error_set(err, BSIM_EINPUT,
		                      "--backends: a comparison with a side read from a file "
		                      "(" BSIM_TRIALS_PREFIX "PATH) runs in one process: expected "
		                      "no --shard, merge or mpirun");
	/* --protocols: side a's protocol joins the overrides of every group,
	 * written as the --set it amounts to; side b's is its own override
	 * after them. */
	bsim_override *sets = NULL;
	char origin[64];
	if (def->protocol[0]) {
		sets = calloc((size_t)def->n_sets + 1, sizeof *sets);
		if (!sets)
			return bsim_error_set(err, BSIM_EFAIL, "out of memory");
		for (int i = 0; i < def->n_sets; i++)
			sets[i] = def->sets[i];
		snprintf(origin, sizeof origin, "--set lattice.protocol=%s", def->protocol[0]);
		sets[def->n_sets] = (bsim_override){"lattice.protocol", def->protocol[0], origin};
		job.sets = sets;
		job.n_sets = def->n_sets + 1;
		job.protocol_b = (bsim_override){"lattice.protocol", def->protocol[1],
		                                 "--protocols (side b)"};
	}
	rc = bsim_store_experiment(def->experiment, job.sets, job.n_sets, def->grid, def->n_grid,
	                           def->trials, def->has_seed ? &def->seed : NULL, &res->e, err);
	if (rc != BSIM_OK) {
		free(sets);
		return rc;
	}
	job.e = &res->e;
	/* The files read are checked before anything runs or is written. */
	if ((rc = reads_load(&job, err)) != BSIM_OK) {
		reads_free(&job);
		free(sets);
		bsim_compare_dir_result_free(res);
		return rc;
	}
	record_fill(&job);
	char *inputs = bsim_run_record_inputs(&job.rec, &res->e, job.sets, job.n_sets, err);
	int spread = def->n_merge > 0 ? BSIM_SPREAD_NONE : def->spread;
	rc = inputs ? BSIM_OK : err->code;
	/* A lattice's records hold both sides' gate paths and peaks too. */
	size_t size = bsim_sweep_record_size_sides(job.n);
	if (rc == BSIM_OK) {
		bsim_sweep_config cfg = {
		        .extra = job.sets,
		        .n_extra = job.n_sets,
		        .extra_b = def->protocol[0] ? &job.protocol_b : NULL,
		        .n_extra_b = def->protocol[0] != NULL,
		        .planned = def->planned,
		        .planned_user = def->planned_user,
		};
		rc = journal_record_size(&job, &cfg, &size, err);
	}
	if (rc == BSIM_OK && def->n_merge > 0 && def->resume)
		rc = bsim_error_set(err, BSIM_EINPUT, "merge: --resume does not apply");
	res->threads = def->threads > 0 ? def->threads : omp_get_max_threads();
	int finished = 0;
	if (rc == BSIM_OK && spread == BSIM_SPREAD_SEND) {
		rc = compare_spread(def, &job, inputs, NULL, size, &finished, err);
		free(inputs);
		free(sets);
		reads_free(&job);
		if (rc != BSIM_OK)
			bsim_compare_dir_result_free(res);
		return rc;
	}
	bsim_session ss;
	if (rc == BSIM_OK)
		rc = bsim_session_open(
		        &ss, def->out, bsim_session_mode(def->resume, def->overwrite), "compare",
		        &(bsim_outdir_spelling){def->resume_option, def->overwrite_option}, inputs,
		        size, err);
	if (rc == BSIM_OK) {
		if (spread != BSIM_SPREAD_NONE || def->n_merge > 0)
			rc = compare_spread(def, &job, inputs, &ss, size, &finished, err);
		if (spread == BSIM_SPREAD_GATHER)
			job.started = t0;
		job.out = ss.stage;
		job.journal = ss.journal;
		job.done = &ss.done;
		if (rc == BSIM_OK && !finished)
			rc = compare_pairs(&job, res, err);
		int kept = 0;
		rc = bsim_session_close(&ss, rc, "compare", &kept, err);
		if (kept)
			snprintf(res->journal, sizeof res->journal, "%s", ss.journal_path);
	}
	free(inputs);
	free(sets);
	reads_free(&job);
	if (rc == BSIM_OK && finished)
		return BSIM_OK; /* a shard: res holds the experiment only */
	if (rc != BSIM_OK) {
		bsim_compare_dir_result_free(res);
		return rc;
	}
	return BSIM_OK;
}

int bsim_store_compare_rerun(const bsim_compare_dir_def *def, const bsim_experiment *e,
                             const char *stage, bsim_compare_dir_result *res, bsim_error *err)
{
	memset(res, 0, sizeof *res);
	compare_job job = {
	        .def = def, .e = e, .sets = def->sets, .n_sets = def->n_sets, .out = stage};
	int rc = sides_check(def, &job, res, err);
	if (rc != BSIM_OK)
		return rc;
	if (def->protocol[0])
		job.protocol_b = (bsim_override){"lattice.protocol", def->protocol[1],
		                                 "--protocols (side b)"};
	/* A side read is read again, and must be the file it was. */
	rc = reads_load(&job, err);
	if (rc == BSIM_OK) {
		record_fill(&job);
		res->threads = def->threads > 0 ? def->threads : omp_get_max_threads();
		rc = compare_pairs(&job, res, err);
	}
	reads_free(&job);
	if (rc != BSIM_OK)
		bsim_compare_sides_free(&res->cmp);
	return rc;
}
