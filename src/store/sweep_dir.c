/* A sweep stored in an output directory; see beamsim/sweep_dir.h.
 *
 * The order is what makes the directory trustworthy: the inputs are
 * loaded and DIR is opened (with its journal) before any trial runs, so a
 * bad file or an unusable DIR fails at once, not after hours; the files
 * are written into the staging area and committed as one set last. */
#define _POSIX_C_SOURCE 200809L

#include "beamsim/sweep_dir.h"

#include <errno.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/backend_registry.h"
#include "beamsim/compare_dir.h"
#include "beamsim/effects.h"
#include "beamsim/output.h"
#include "beamsim/run_record.h"
#include "store/session.h"
#include "store/rerun.h"
#include "store/store.h"
#include "store/survival_files.h"
#include "store/trials_csv.h"
#include "store/lattice_files.h"
#include "store/part_dir.h"
#include "util/journal.h"
#include "util/clock.h"
#include "util/atomic_file.h"
#include "beamsim/limits.h"

bsim_sweep_dir_def bsim_sweep_dir_def_default(void)
{
	bsim_sweep_dir_def d;
	memset(&d, 0, sizeof d);
	d.backend = bsim_backend_default();
	return d;
}

void bsim_sweep_dir_result_free(bsim_sweep_dir_result *res)
{
	bsim_sweep_result_free(&res->r);
	bsim_experiment_free(&res->e);
}

/* The per-trial files written as a streamed sweep's blocks arrive:
 * trials.csv, and for a lattice gate_entries.csv and beam_peaks.csv. A
 * write error (a full disk) stops the sweep; its finished trials are in
 * the journal. */
enum { SINK_TRIALS, SINK_ENTRIES, SINK_PEAKS, SINK_FILES };
static const char *const sink_names[SINK_FILES] = {"trials.csv", "gate_entries.csv",
                                                   "beam_peaks.csv"};

typedef struct trials_sink {
	trials_csv_writer w;
	bsim_atomic_file lattice[SINK_FILES]; /* ENTRIES and PEAKS */
	char path[SINK_FILES][BSIM_PATH_MAX];
	int n_files; /* 1, or 3 for a lattice */
	int trials;
	bsim_lattice_def def; /* a lattice's: group 0's, as its outputs use */
	survival_acc surv;    /* each group's exit times: survival.csv, horizon.csv */
	int failed;
} trials_sink;

static FILE *sink_file(trials_sink *s, int k)
{
	return k == SINK_TRIALS ? s->w.o.f : s->lattice[k].f;
}

static int trials_sink_take(void *user, const bsim_sweep_block *b, bsim_error *err)
{
	trials_sink *s = user;
	bsim_trials_csv_rows(&s->w, b->first, b->n, s->trials, b->results, b->logs);
	bsim_survival_acc_add(&s->surv, b->first, b->n, s->trials, b->results);
	if (s->n_files > 1) {
		bsim_lattice_entries_rows(s->lattice[SINK_ENTRIES].f, b->first, b->n, s->trials,
		                          b->logs);
		bsim_lattice_peaks_rows(s->lattice[SINK_PEAKS].f, &s->def, b->first, b->n,
		                        s->trials, b->logs);
	}
	for (int k = 0; k < s->n_files; k++) {
		FILE *f = sink_file(s, k);
		if (fflush(f) != 0 || ferror(f)) {
			s->failed = 1;
			return bsim_error_set(err, BSIM_EFAIL, "%s: cannot write (%s)", s->path[k],
			                      strerror(errno));
		}
	}
	return BSIM_OK;
}

/* Opens the files in stage, headers written; scenes: every group's. */
static int sink_open(trials_sink *s, const char *stage, const bsim_experiment *e,
                     const bsim_scene *scenes, bsim_error *err)
{
	int rc;
	s->n_files = scenes[0].has_lattice ? SINK_FILES : 1;
	s->def = scenes[0].lattice;
	s->trials = e->trials;
	if ((rc = bsim_survival_acc_init(&s->surv, e, scenes, NULL, 0, err)) != BSIM_OK)
		return rc;
	if (bsim_output_mkdir(stage, err) != BSIM_OK)
		return BSIM_EFAIL;
	for (int k = 0; k < s->n_files; k++)
		if (bsim_session_path(s->path[k], sizeof s->path[k], stage, sink_names[k], err))
			return BSIM_EFAIL;
	if (bsim_trials_csv_open(&s->w, s->path[SINK_TRIALS], e, 1, err) != BSIM_OK)
		return BSIM_EFAIL;
	for (int k = 1; k < s->n_files; k++)
		if (bsim_atomic_file_open(&s->lattice[k], s->path[k], err) != BSIM_OK)
			return BSIM_EFAIL;
	if (s->n_files > 1) {
		bsim_lattice_entries_header(s->lattice[SINK_ENTRIES].f);
		bsim_lattice_peaks_header(s->lattice[SINK_PEAKS].f);
	}
	return BSIM_OK;
}

/* Commits the files (rc BSIM_OK) or leaves none; then the lattice files'
 * twins (trials.csv's its writer made from the trials, on commit). */
static int sink_close(trials_sink *s, int rc, const char *stage, bsim_error *err)
{
	if (rc == BSIM_OK)
		rc = bsim_trials_csv_commit(&s->w, err);
	if (rc == BSIM_OK)
		rc = bsim_survival_acc_write(&s->surv, stage, err);
	bsim_survival_acc_free(&s->surv);
	if (rc != BSIM_OK)
		bsim_trials_csv_abort(&s->w);
	for (int k = 1; k < SINK_FILES; k++) {
		if (rc == BSIM_OK && s->lattice[k].f)
			rc = bsim_atomic_file_commit(&s->lattice[k], err);
		else
			bsim_atomic_file_abort(&s->lattice[k]);
	}
	for (int k = 1; rc == BSIM_OK && k < s->n_files; k++) {
		char var[32];
		snprintf(var, sizeof var, "%.*s", (int)strcspn(sink_names[k], "."), sink_names[k]);
		rc = bsim_store_twin(stage, sink_names[k], var, err);
	}
	return rc;
}

/* res->journal names the journal if the session kept it. */
static int session_end(bsim_session *ss, int rc, const char *command, char *journal, size_t size,
                       bsim_error *err)
{
	int kept = 0;
	rc = bsim_session_close(ss, rc, command, &kept, err);
	if (kept)
		snprintf(journal, size, "%s", ss->journal_path);
	return rc;
}

/* This process's part of the sweep (part_dir_run_fn). */
typedef struct sweep_part_ctx {
	const bsim_experiment *e;
	const bsim_sweep_config *cfg;
} sweep_part_ctx;

static int sweep_part_run(void *user, const bsim_sweep_part *part, bsim_error *err)
{
	sweep_part_ctx *c = user;
	return bsim_sweep_run_part(c->e, c->cfg, part, err);
}

static int sweep_part(const bsim_sweep_dir_def *def, const bsim_experiment *e, const char *inputs,
                      bsim_sweep_config *cfg, size_t record_size, bsim_session *ss, bsim_error *err)
{
	part_dir_spread sp = {def->spread, &def->part,  def->agree,
	                      "sweep",     record_size, (long)e->n_groups * e->trials,
	                      def->argc,   def->argv};
	sweep_part_ctx c = {e, cfg};
	return bsim_part_dir_spread_run(&sp, inputs, ss, sweep_part_run, &c, err);
}

/* bsim_sweep_dir_run once planned (rc its status so far): the run of the
 * sweep over cfg's lent scenes (cfg->scenes) into def->out, its files and
 * run record. */
static int sweep_dir_planned(const bsim_sweep_dir_def *def, bsim_sweep_dir_result *res,
                             bsim_experiment *e, char *inputs, bsim_sweep_config *p_cfg,
                             size_t size, int spread, double t0, const bsim_run_record *p_rec,
                             int rc, bsim_error *err)
{
	bsim_sweep_config cfg = *p_cfg;
	const bsim_run_record rec = *p_rec;
	const bsim_backend *b = cfg.backend;
	if (rc == BSIM_OK && spread == BSIM_SPREAD_SEND) {
		/* Another rank's: its records go to the gatherer; no directory. */
		rc = sweep_part(def, e, inputs, &cfg, size, NULL, err);
		free(inputs);
		if (rc != BSIM_OK)
			bsim_experiment_free(e);
		return rc;
	}
	bsim_session ss;
	if (rc == BSIM_OK)
		rc = bsim_session_open(
		        &ss, def->out, bsim_session_mode(def->resume, def->overwrite), "sweep",
		        &(bsim_outdir_spelling){def->resume_option, def->overwrite_option}, inputs,
		        size, err);
	if (rc != BSIM_OK) {
		free(inputs);
		bsim_experiment_free(e);
		return rc;
	}
	cfg.journal = ss.journal;
	if (def->n_merge > 0) {
		char run[17];
		bsim_part_dir_run_id(inputs, run);
		long total = (long)e->n_groups * e->trials;
		rc = bsim_part_dir_join(def->merge, def->n_merge, "sweep", run, inputs, size, total,
		                        ss.journal, err);
		if (rc == BSIM_OK)
			rc = bsim_part_dir_journal_reopen(&ss, inputs, size, err);
		cfg.journal = ss.journal;
	} else if (spread == BSIM_SPREAD_SHARD || spread == BSIM_SPREAD_GATHER) {
		rc = sweep_part(def, e, inputs, &cfg, size, &ss, err);
		if (spread == BSIM_SPREAD_SHARD) {
			free(inputs);
			rc = session_end(&ss, rc, "sweep", res->journal, sizeof res->journal, err);
			if (rc != BSIM_OK)
				bsim_sweep_dir_result_free(res);
			return rc;
		}
		if (rc == BSIM_OK)
			rc = bsim_part_dir_journal_reopen(&ss, inputs, size, err);
		cfg.journal = ss.journal;
	}
	free(inputs);
	/* The trials stream into their files as they finish. */
	trials_sink sink = {0};
	int opened = rc == BSIM_OK;
	if (opened)
		rc = sink_open(&sink, ss.stage, e, cfg.scenes, err);
	cfg.sink = trials_sink_take;
	cfg.sink_user = &sink;
	if (rc == BSIM_OK)
		rc = bsim_sweep_run(e, &cfg, &res->r, err);
	/* A gathered sweep's time is its parts' and the writing's. */
	if (rc == BSIM_OK && spread == BSIM_SPREAD_GATHER)
		res->r.wall_seconds = bsim_clock_seconds() - t0;
	if (opened)
		rc = sink_close(&sink, rc, ss.stage, err);
	if (sink.failed)
		ss.done = 1; /* the trials journaled before the disk filled are kept */
	if (rc == BSIM_OK) {
		ss.done = 1;
		rc = bsim_store_sweep_files(ss.stage, e, b, &def->opts, def->sets, def->n_sets,
		                            &res->r, err);
		if (rc == BSIM_OK)
			rc = bsim_run_record_write(ss.stage, &rec, e, def->sets, def->n_sets, err);
	}
	rc = session_end(&ss, rc, "sweep", res->journal, sizeof res->journal, err);
	if (rc != BSIM_OK) {
		bsim_sweep_dir_result_free(res);
		return rc;
	}
	res->unstable =
	        bsim_store_unstable(e, def->sets, def->n_sets, &res->r, &res->first_unstable,
	                            res->unstable_why, sizeof res->unstable_why);
	return BSIM_OK;
}

int bsim_sweep_dir_run(const bsim_sweep_dir_def *def, bsim_sweep_dir_result *res, bsim_error *err)
{
	double t0 = bsim_clock_seconds();
	memset(res, 0, sizeof *res);
	res->first_unstable = -1;
	const bsim_backend *b = def->backend ? def->backend : bsim_backend_default();
	if (bsim_options_check(&def->opts, b->knobs, b->n_knobs, b->name, err) != BSIM_OK)
		return BSIM_EINPUT;
	bsim_experiment *e = &res->e;
	int rc = bsim_store_experiment(def->experiment, def->sets, def->n_sets, def->grid,
	                               def->n_grid, def->trials, def->has_seed ? &def->seed : NULL,
	                               e, err);
	if (rc != BSIM_OK)
		return rc;
	if (def->hold_cell_bytes > 0 &&
	    bsim_output_trials_fit(e, 0, def->hold_cell_bytes, err) != BSIM_OK) {
		bsim_experiment_free(e);
		return BSIM_EINPUT;
	}
	bsim_run_record rec;
	const bsim_options *opts = &def->opts;
	bsim_run_record_fill(&rec, "sweep", e, 1, &b, &opts, NULL, NULL);
	char *inputs = bsim_run_record_inputs(&rec, e, def->sets, def->n_sets, err);
	/* The overlap adds a column to every trial: a run measured so continues so. */
	if (inputs && def->overlap) {
		char *more = realloc(inputs, strlen(inputs) + sizeof "measure_overlap 1\n");
		if (more)
			strcat(more, "measure_overlap 1\n");
		else
			free(inputs);
		inputs = more;
		if (!inputs)
			bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	int spread = def->n_merge > 0 ? BSIM_SPREAD_NONE : def->spread;
	rc = inputs ? BSIM_OK : err->code;
	if (rc == BSIM_OK && def->n_merge > 0 && def->resume)
		rc = bsim_error_set(err, BSIM_EINPUT, "merge: --resume does not apply");
	res->threads = def->threads > 0 ? def->threads : omp_get_max_threads();
	bsim_sweep_config cfg = {
	        .backend = b,
	        .opts = &def->opts,
	        .threads = res->threads,
	        .extra = def->sets,
	        .n_extra = def->n_sets,
	        .progress = def->progress,
	        .progress_user = def->progress_user,
	        .planned = def->planned,
	        .planned_user = def->planned_user,
	        .measure_overlap = def->overlap,
	        .keep = def->keep,
	        .keep_stride = def->keep_stride,
	        .stop = def->stop,
	};
	/* A lattice's records hold its trials' gate paths too; the plan is
	 * said before anything is opened. */
	size_t size = bsim_sweep_record_size(0);
	bsim_scene *scenes = NULL;
	const int n_groups = e->n_groups;
	if (rc == BSIM_OK)
		rc = bsim_sweep_plan_for(e, &cfg, 1, &size, &scenes, err);
	cfg.scenes = scenes;
	rc = sweep_dir_planned(def, res, e, inputs, &cfg, size, spread, t0, &rec, rc, err);
	bsim_sweep_scenes_free(scenes, n_groups);
	return rc;
}

int bsim_store_sweep_rerun(const bsim_sweep_dir_def *def, const bsim_experiment *e,
                           const char *stage, bsim_sweep_result *r, bsim_error *err)
{
	const bsim_backend *b = def->backend ? def->backend : bsim_backend_default();
	bsim_sweep_config cfg = {
	        .backend = b,
	        .opts = &def->opts,
	        .threads = def->threads > 0 ? def->threads : omp_get_max_threads(),
	        .progress = def->progress,
	        .progress_user = def->progress_user,
	        .planned = def->planned,
	        .planned_user = def->planned_user,
	};
	int rc = bsim_sweep_run(e, &cfg, r, err);
	if (rc != BSIM_OK)
		return rc;
	bsim_run_record rec;
	const bsim_options *opts = &def->opts;
	bsim_run_record_fill(&rec, "sweep", e, 1, &b, &opts, NULL, NULL);
	rc = bsim_store_sweep_files(stage, e, b, &def->opts, NULL, 0, r, err);
	if (rc == BSIM_OK)
		rc = bsim_run_record_write(stage, &rec, e, NULL, 0, err);
	if (rc != BSIM_OK)
		bsim_sweep_result_free(r);
	return rc;
}

int bsim_sweep_dir_read(const char *dir, const char *side, bsim_sweep_dir_result *res,
                        bsim_error *err)
{
	bsim_run_record rec;
	char path[BSIM_PATH_MAX], sub[BSIM_PATH_MAX];
	int has_manifest = 0;
	memset(res, 0, sizeof *res);
	res->first_unstable = -1;
	if (bsim_outdir_verify(dir, &has_manifest, err) != BSIM_OK ||
	    bsim_run_record_read(dir, &rec, err) != BSIM_OK)
		return BSIM_EINPUT;
	if (bsim_session_path(path, sizeof path, dir, "inputs/experiment.yaml", err))
		return BSIM_EINPUT;
	int rc = bsim_store_experiment(path, NULL, 0, NULL, 0, rec.trials, NULL, &res->e, err);
	if (rc != BSIM_OK)
		return rc;
	res->e.seed = rec.seed;
	const char *from = dir;
	if (side) {
		char name[128];
		bsim_compare_dir_label(side, name, sizeof name);
		if (bsim_session_path(sub, sizeof sub, dir, name, err)) {
			bsim_experiment_free(&res->e);
			return BSIM_EINPUT;
		}
		from = sub;
	}
	if (bsim_session_path(path, sizeof path, from, "trials.csv", err) ||
	    (rc = bsim_output_trials_read(path, res->e.n_groups, res->e.trials, &res->r, err)) !=
	            BSIM_OK) {
		bsim_experiment_free(&res->e);
		return rc ? rc : BSIM_EINPUT;
	}
	/* The groups without random draws, from their scenes: each is one
	 * trial, compared as one pair (beamsim/compare.h). With --protocols
	 * the sides' scenes differ only in the lattice protocol, which does
	 * not draw. */
	for (int g = 0; g < res->e.n_groups; g++) {
		bsim_scene s;
		if ((rc = bsim_experiment_group_scene(&res->e, g, NULL, 0, &s, err)) != BSIM_OK) {
			bsim_sweep_dir_result_free(res);
			return rc;
		}
		res->r.groups[g].deterministic = !bsim_effects_random(&s);
		bsim_scene_free(&s);
	}
	res->unstable = bsim_store_unstable(&res->e, NULL, 0, &res->r, &res->first_unstable,
	                                    res->unstable_why, sizeof res->unstable_why);
	return BSIM_OK;
}
