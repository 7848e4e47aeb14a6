/* A sweep: every (group, trial) of an experiment on one backend.
 *
 * The (group, trial) pairs form one flat list, index g*trials + t, handed
 * out dynamically to OpenMP threads (trials end at very different times, so
 * a static split would leave threads idle). A trial's seed depends only on
 * (experiment seed, g, t) and its result goes to its own slot, so the
 * result is the same whatever the thread count (docs/files.md "Experiment
 * file (YAML)"). A paired sweep runs each trial on a second backend too, in
 * the same slot of a second result (trial_pair.c).
 *
 * A group whose scene draws no random numbers (bsim_effects_random) is
 * deterministic: every trial of it is the same trial. It runs once, as
 * trial 0, and the other slots are copies, so trials.csv keeps its shape
 * and its values (identical code and inputs give identical trials), and
 * nothing downstream counts one trial as many. */

#define _POSIX_C_SOURCE 200809L
#include "beamsim/sweep.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "beamsim/backend_registry.h"
#include "util/clock.h"
#include "util/journal.h"
#include "beamsim/effects.h"
#include "beamsim/schedule.h"
#include "beamsim/stats.h"
#include "run/sweep_record.h"
#include "run/trial_pair.h"

/* The length compare's separation is 1% of: the disk's radius, or the
 * radius of the disk of the body's area for another shape. */
static double body_size(const bsim_scene *scene)
{
	if (scene->body.shape == BSIM_SHAPE_DISK)
		return scene->body.radius;
	return sqrt(bsim_body_area(&scene->body) / 3.14159265358979323846);
}

/* One trial into its group's counts (group_finish completes them). */
static void group_add(bsim_group_result *out, const bsim_trial_result *t)
{
	out->trials++;
	out->steps += t->steps_run;
	out->solver.iteration_limit += t->solver.iteration_limit;
	out->solver.clamped += t->solver.clamped;
	out->trials_iteration_limit += t->solver.iteration_limit > 0;
	out->trials_clamped += t->solver.clamped > 0;
	switch (t->outcome) {
	case BSIM_TRAVERSED:
		out->traversed++;
		out->left += t->type == BSIM_TYPE_LEFT;
		out->right += t->type == BSIM_TYPE_RIGHT;
		/* The barrier crossed (bsim_landscape_label); a trial whose
		 * last touch was of no deflected beam, or of two holding
		 * equal energy, counts as neither. */
		out->landscape_left += t->landscape_beam == 0;
		out->landscape_right += t->landscape_beam == 1;
		break;
	case BSIM_SIDE_EXIT:
		out->side_exit++;
		break;
	case BSIM_STUCK:
		out->stuck++;
		out->stuck_in_contact += t->in_contact_end != 0;
		break;
	case BSIM_UNSTABLE:
		out->unstable++;
		break;
	}
}

static void group_finish(bsim_group_result *out)
{
	int n = out->trials;
	out->p_traverse = n > 0 ? (double)out->traversed / n : 0.0;
	bsim_stats_wilson(out->traversed, n, BSIM_STATS_Z95, &out->ci95[0], &out->ci95[1]);
}

void bsim_sweep_group_aggregate(const bsim_trial_result *trials, int n, bsim_group_result *out)
{
	memset(out, 0, sizeof *out);
	for (int i = 0; i < n; i++)
		group_add(out, &trials[i]);
	group_finish(out);
}

void bsim_sweep_result_free(bsim_sweep_result *r)
{
	if (!r)
		return;
	if (r->logs)
		for (size_t i = 0; i < (size_t)r->n_groups * r->trials; i++)
			bsim_trial_log_clear(&r->logs[i]);
	free(r->logs);
	for (size_t i = 0; r->kept && i < (size_t)r->n_groups * (size_t)r->keep; i++)
		bsim_trajectory_free(&r->kept[i]);
	free(r->kept);
	free(r->trials_out);
	for (int g = 0; r->lattice_summaries && g < r->n_groups; g++)
		bsim_lattice_summary_free(&r->lattice_summaries[g]);
	free(r->lattice_summaries);
	free(r->groups);
	memset(r, 0, sizeof *r);
}

static void scenes_free(bsim_scene *scenes, int n)
{
	for (int g = 0; g < n; g++)
		bsim_scene_free(&scenes[g]);
	free(scenes);
}

/* The overrides a side's scenes are built with after the experiment's:
 * extra, then the second side's own of a paired sweep. malloc'd. */
static bsim_override *side_overrides(const bsim_sweep_config *cfg, int side_b, int *n_ov)
{
	*n_ov = cfg->n_extra + (side_b ? cfg->n_extra_b : 0);
	bsim_override *ov = calloc(*n_ov > 0 ? (size_t)*n_ov : 1, sizeof *ov);
	for (int i = 0; ov && i < *n_ov; i++)
		ov[i] = i < cfg->n_extra ? cfg->extra[i] : cfg->extra_b[i - cfg->n_extra];
	return ov;
}

/* Every group's scene, built once: a trial only reads its scene. The
 * second side of a paired sweep adds its own overrides after extra. */
static int scenes_build(const bsim_experiment *e, const bsim_sweep_config *cfg, int side_b,
                        bsim_scene **out, bsim_error *err)
{
	bsim_scene *scenes = calloc((size_t)e->n_groups, sizeof *scenes);
	*out = NULL;
	if (!scenes)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory for %d scenes", e->n_groups);
	int n_ov;
	bsim_override *ov = side_overrides(cfg, side_b, &n_ov);
	if (!ov) {
		free(scenes);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory for %d scenes", e->n_groups);
	}
	for (int g = 0; g < e->n_groups; g++) {
		int rc = bsim_experiment_group_scene(e, g, ov, n_ov, &scenes[g], err);
		if (rc != BSIM_OK) {
			scenes_free(scenes, g);
			free(ov);
			return rc;
		}
	}
	free(ov);
	*out = scenes;
	return BSIM_OK;
}

/* The scenes of every group for each side, each checked against the
 * backend that runs it (bsim_experiment_group_check), so that a scene a
 * backend refuses (a body within Box2D's skin) is said where the scene
 * gave the field, before any trial runs: side b's scenes (scenes_b, NULL
 * when not paired) are side a's unless it has overrides of its own. On
 * failure nothing is left built. */
static int scenes_for(const bsim_experiment *e, const bsim_sweep_config *cfg,
                      const bsim_backend *backend_b, const bsim_options *opts_b,
                      bsim_scene **scenes, bsim_scene **scenes_b, bsim_error *err)
{
	const int own_b = backend_b && cfg->n_extra_b > 0;
	if (scenes_b)
		*scenes_b = NULL;
	int rc = scenes_build(e, cfg, 0, scenes, err);
	if (rc == BSIM_OK && own_b)
		rc = scenes_build(e, cfg, 1, scenes_b, err);
	for (int side = 0; rc == BSIM_OK && side < (backend_b ? 2 : 1); side++) {
		const int of_b = side == 1 && own_b;
		int n_ov;
		bsim_override *ov = side_overrides(cfg, of_b, &n_ov);
		if (!ov)
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
		for (int g = 0; rc == BSIM_OK && g < e->n_groups; g++)
			rc = bsim_experiment_group_check(
			        e, g, ov, n_ov, of_b ? &(*scenes_b)[g] : &(*scenes)[g],
			        side ? backend_b : cfg->backend, side ? opts_b : cfg->opts, err);
		free(ov);
	}
	if (rc != BSIM_OK) {
		if (*scenes)
			scenes_free(*scenes, e->n_groups);
		if (scenes_b && *scenes_b)
			scenes_free(*scenes_b, e->n_groups);
		*scenes = NULL;
		if (scenes_b)
			*scenes_b = NULL;
	}
	return rc;
}

/* A paired sweep's journal record. */
typedef struct pair_record {
	bsim_trial_result a, b;
	double t_separate;
} pair_record;

bsim_sweep_config bsim_sweep_config_default(void)
{
	bsim_sweep_config c;
	memset(&c, 0, sizeof c);
	c.backend = bsim_backend_default();
	return c;
}

size_t bsim_sweep_record_size(int paired)
{
	return paired ? sizeof(pair_record) : sizeof(bsim_trial_result);
}

/* The beams of a lattice sweep's records (run/sweep_record.h), 0 for
 * records of the result alone; a paired sweep's are the most of both
 * sides' scenes (scenes_b NULL: the sides share scenes). */
static int record_beams(const bsim_scene *scenes, const bsim_scene *scenes_b, int n_groups,
                        const bsim_sweep_config *cfg)
{
	if (cfg->results_only || !scenes[0].has_lattice)
		return 0;
	int beams = sweep_record_beams(scenes, n_groups);
	int beams_b = scenes_b ? sweep_record_beams(scenes_b, n_groups) : 0;
	beams = beams_b > beams ? beams_b : beams;
	return beams > 0 ? beams : 1;
}

/* The size of a record of beams beams (0: the result alone). A paired
 * lattice sweep's record is side a's lattice record, then side b's, then
 * the separation time (a double), both sides packed by run/sweep_record.c. */
static size_t record_bytes(int beams, int paired)
{
	if (!beams)
		return bsim_sweep_record_size(paired);
	return paired ? 2 * sweep_record_size(beams) + sizeof(double) : sweep_record_size(beams);
}

/* What the threads share. first_fail is the index of the lowest failed
 * trial so far (total if none, -1 if a thread could not start). */
typedef struct sweep_shared {
	const bsim_experiment *e;
	const bsim_sweep_config *cfg;
	const bsim_scene *scenes;
	const bsim_scene *scenes_b; /* the second side's (may be scenes) */
	const int *deterministic;   /* per group */
	bsim_trial_result *results;
	bsim_trial_log *logs;
	const bsim_backend *backend_b; /* NULL: not paired */
	const bsim_options *opts_b;
	bsim_trial_result *results_b;
	bsim_trial_log *logs_b;
	bsim_trajectory *kept, *kept_b; /* NULL: none kept */
	int keep, keep_stride;
	double *t_separate;
	long total;
	long first, end; /* the trials of this block; slot k holds trial first + k */
	long done;
	long first_fail;
	bsim_error fail;
	unsigned char *from_journal; /* per slot: the result came from the journal */
	/* A streamed sweep's journal records, by trial index, in a file of
	 * their own (-1: none), and which trials have one (a bit each). */
	int spill_fd;
	unsigned char *journaled;
	int lattice;                 /* the scenes are lattices: every trial runs */
	int stopped;                 /* a trial was not started because of cfg->stop */
	const bsim_sweep_part *part; /* NULL: every trial is this process's */
	long progress_total;         /* what progress counts up to */
	/* > 0: a lattice sweep's records hold the gate path and the peaks of
	 * this many beams (run/sweep_record.h; a paired sweep's, each side's:
	 * record_bytes), record_size bytes */
	int record_beams;
	size_t record_size;
} sweep_shared;

/* Trial i is another part's, or done before this part began (by journal
 * index j, bsim_sweep_config.journal_first). */
static int part_skips(const bsim_sweep_part *p, long first, long i)
{
	long j = first + i;
	return p && (j % p->count != p->index || (p->done && (p->done[j / 8] & (1u << (j % 8)))));
}

/* A record another part sent (bsim_sweep_accept_fn): into the journal,
 * counted as done. Called on the thread that called the part runner. */
static int part_accept(void *ctx, long index, const void *payload, bsim_error *err)
{
	sweep_shared *sh = ctx;
	long total = sh->cfg->journal_total > 0 ? sh->cfg->journal_total : sh->total;
	if (index < 0 || index >= total)
		return bsim_error_set(err, BSIM_EFAIL, "a part sent trial %ld of a sweep of %ld",
		                      index, total);
	if (sh->cfg->journal &&
	    bsim_journal_append(sh->cfg->journal, (uint64_t)index, payload, err) != BSIM_OK)
		return BSIM_EFAIL;
#pragma omp atomic
	sh->done++;
	return BSIM_OK;
}

static void shared_fail(sweep_shared *sh, long i, int code, const char *msg)
{
#pragma omp critical(bsim_sweep_fail)
	{
		if (i < sh->first_fail) {
			if (i < 0)
				bsim_error_set(&sh->fail, code, "%s", msg);
			else
				bsim_error_set(&sh->fail, code, "group %ld, trial %ld: %s",
				               i / sh->e->trials, i % sh->e->trials, msg);
#pragma omp atomic write
			sh->first_fail = i;
		}
	}
}

/* Trial i's record (its result; both results and the separation time; a
 * lattice's result with its path and peaks) into buf, which holds
 * sh->record_size bytes when a lattice's; returns it. */
static const void *record_of(sweep_shared *sh, long i, void *buf, pair_record *pair)
{
	long k = i - sh->first;
	if (sh->backend_b && sh->record_beams) {
		size_t side = sweep_record_size(sh->record_beams);
		unsigned char *p = buf;
		sweep_record_pack(p, sh->record_beams, &sh->results[k], &sh->logs[k]);
		sweep_record_pack(p + side, sh->record_beams, &sh->results_b[k], &sh->logs_b[k]);
		memcpy(p + 2 * side, &sh->t_separate[k], sizeof sh->t_separate[k]);
		return buf;
	}
	if (sh->backend_b) {
		*pair = (pair_record){sh->results[k], sh->results_b[k], sh->t_separate[k]};
		return pair;
	}
	if (sh->record_beams) {
		sweep_record_pack(buf, sh->record_beams, &sh->results[k], &sh->logs[k]);
		return buf;
	}
	return &sh->results[k];
}

/* A journal record back into its slots (bsim_journal_fn). */
static int journal_take(void *user, uint64_t index, const void *payload)
{
	sweep_shared *sh = user;
	const bsim_sweep_config *cfg = sh->cfg;
	/* A journal shared by several sweeps: the others' records are passed over. */
	if (cfg->journal_total > 0) {
		if (index >= (uint64_t)cfg->journal_total)
			return 1;
		if (index < (uint64_t)cfg->journal_first ||
		    index - (uint64_t)cfg->journal_first >= (uint64_t)sh->total)
			return 0;
		index -= (uint64_t)cfg->journal_first;
	}
	if (index >= (uint64_t)sh->total)
		return 1;
	/* A trial whose trajectory is kept runs again (trajectories are not
	 * journaled; the trial is the same): its record is passed over. So
	 * does every trial of a lattice, whose gate path is not journaled,
	 * unless only the results are wanted. */
	if ((long)(index % (uint64_t)sh->e->trials) < sh->keep ||
	    (sh->lattice && !cfg->results_only && !sh->record_beams))
		return 0;
	if (sh->journaled) {
		/* Streamed: the record waits in the spill file for its block. */
		size_t size = sh->record_beams ? sh->record_size : sizeof(bsim_trial_result);
		if (pwrite(sh->spill_fd, payload, size, (off_t)(index * size)) != (ssize_t)size)
			return -1;
		sh->done += !(sh->journaled[index / 8] & (1u << (index % 8)));
		sh->journaled[index / 8] |= (unsigned char)(1u << (index % 8));
		return 0;
	}
	if (sh->record_beams && sh->backend_b) {
		/* either side's path too long for its record: the pair runs again */
		size_t side = sweep_record_size(sh->record_beams);
		const unsigned char *p = payload;
		int got = sweep_record_unpack(p, sh->record_beams, &sh->results[index],
		                              &sh->logs[index]);
		if (got > 0)
			got = sweep_record_unpack(p + side, sh->record_beams, &sh->results_b[index],
			                          &sh->logs_b[index]);
		if (got <= 0)
			return got;
		memcpy(&sh->t_separate[index], p + 2 * side, sizeof sh->t_separate[index]);
	} else if (sh->record_beams) {
		/* a path too long for its record: the trial runs again */
		int got = sweep_record_unpack(payload, sh->record_beams, &sh->results[index],
		                              &sh->logs[index]);
		if (got <= 0)
			return got;
	} else if (sh->backend_b) {
		pair_record p;
		memcpy(&p, payload, sizeof p);
		sh->results[index] = p.a;
		sh->results_b[index] = p.b;
		sh->t_separate[index] = p.t_separate;
	} else {
		memcpy(&sh->results[index], payload, sizeof sh->results[index]);
	}
	sh->done += !sh->from_journal[index];
	sh->from_journal[index] = 1;
	return 0;
}

/* Trials are handed out in index order, so when trial i fails every trial
 * before it has started; skipping only those after it lets the others
 * finish and makes the reported error the first by (g, t) whatever the
 * thread count. */
static void sweep_thread(sweep_shared *sh)
{
	const bsim_experiment *e = sh->e;
	const bsim_sweep_config *cfg = sh->cfg;
	int leader = omp_get_thread_num() == 0;
	bsim_trial_runner *runner = bsim_trial_runner_alloc();
	/* The scenes live, unchanged, as long as the sweep. */
	if (runner)
		bsim_trial_runner_keep_worlds(runner, 1);
	trial_pair *pair = sh->backend_b ? trial_pair_alloc() : NULL;
	if (pair)
		trial_pair_keep_worlds(pair, 1);
	bsim_trial_log *log[2] = {bsim_trial_log_alloc(), bsim_trial_log_alloc()};
	void *record_buf = sh->record_beams ? malloc(sh->record_size) : NULL;
	pair_record pr;
	bsim_error err;

	if (!runner || (sh->backend_b && !pair) || !log[0] || !log[1] ||
	    (sh->record_beams && !record_buf)) {
		bsim_trial_runner_free(runner);
		runner = NULL;
		shared_fail(sh, -1, BSIM_EFAIL, "out of memory for a trial runner");
	}
#pragma omp for schedule(dynamic)
	for (long i = sh->first; i < sh->end; i++) {
		long stop, k = i - sh->first;
#pragma omp atomic read
		stop = sh->first_fail;
		if (!runner || i > stop || (sh->from_journal && sh->from_journal[k]) ||
		    part_skips(sh->part, cfg->journal_first, i))
			continue;
		if (cfg->stop && *cfg->stop) {
#pragma omp atomic write
			sh->stopped = 1;
			continue;
		}
		long g = i / e->trials, t = i % e->trials;
		uint64_t seed = bsim_schedule_seed_mix(e->seed, (uint64_t)g, (uint64_t)t);
		bsim_error_clear(&err);
		const bsim_scene *scene = &sh->scenes[g];
		bsim_trajectory *keep = t < sh->keep ? &sh->kept[g * sh->keep + t] : NULL;
		bsim_recorder rec = {.stride = keep ? sh->keep_stride : 1,
		                     .record = keep ? bsim_trajectory_record : NULL,
		                     .record_user = keep,
		                     .log = log[0],
		                     .overlap = cfg->measure_overlap};
		int rc = BSIM_OK, ran = 1;
		if (t > 0 && sh->deterministic[g]) {
			ran = 0; /* a copy of trial 0, filled in after the run (and its trajectory)
			          */
		} else if (pair) {
			pair->keep[0] = keep;
			pair->keep[1] = keep ? &sh->kept_b[g * sh->keep + t] : NULL;
			pair->keep_stride = sh->keep_stride;
			rc = trial_pair_run(pair, scene, &sh->scenes_b[g], cfg->backend, cfg->opts,
			                    sh->backend_b, sh->opts_b, seed,
			                    0.01 * body_size(scene), &sh->results[k],
			                    &sh->results_b[k], log, &sh->t_separate[k], &err);
		} else {
			rc = bsim_trial_run(runner, scene, cfg->backend, cfg->opts, seed, &rec,
			                    &sh->results[k], &err);
			if (rc == BSIM_OK && keep && keep->oom)
				rc = bsim_error_set(&err, BSIM_EFAIL,
				                    "out of memory for a kept trajectory");
		}
		if (rc == BSIM_OK && ran && bsim_trial_log_copy(&sh->logs[k], log[0]) != BSIM_OK)
			rc = bsim_error_set(&err, BSIM_EFAIL, "out of memory for the gate path");
		if (rc == BSIM_OK && ran && pair &&
		    bsim_trial_log_copy(&sh->logs_b[k], log[1]) != BSIM_OK)
			rc = bsim_error_set(&err, BSIM_EFAIL, "out of memory for the gate path");
		/* Only trials that ran are journaled: copies are filled in again. */
		const void *record = ran && (cfg->journal || (sh->part && sh->part->record))
		                             ? record_of(sh, i, record_buf, &pr)
		                             : NULL;
		if (rc == BSIM_OK && record && cfg->journal)
			rc = bsim_journal_append(cfg->journal, (uint64_t)(cfg->journal_first + i),
			                         record, &err);
		if (rc == BSIM_OK && record && sh->part && sh->part->record)
			rc = sh->part->record(sh->part->user, cfg->journal_first + i, record, &err);
		if (rc != BSIM_OK)
			shared_fail(sh, i, rc, err.msg);
		if (leader && sh->part && sh->part->collect &&
		    sh->part->collect(sh->part->user, 0, part_accept, sh, &err) != BSIM_OK)
			shared_fail(sh, -1, err.code, err.msg);
		long done;
#pragma omp atomic capture
		done = ++sh->done;
		if (leader && cfg->progress)
			cfg->progress(cfg->progress_user, done,
			              sh->progress_total ? sh->progress_total : sh->total);
	}
	bsim_trial_runner_free(runner);
	trial_pair_free(pair);
	bsim_trial_log_free(log[0]);
	bsim_trial_log_free(log[1]);
	free(record_buf);
}

/* The result's arrays; the per-trial ones (trials_out, logs) only if
 * per_trial (a streamed sweep keeps none). */
static int result_alloc(bsim_sweep_result *r, int n_groups, int trials, int keep, int per_trial,
                        bsim_error *err)
{
	size_t n = (size_t)n_groups * (size_t)trials;
	memset(r, 0, sizeof *r);
	r->n_groups = n_groups;
	r->trials = trials;
	r->has_ledger = 1;
	r->first_unstable = -1;
	if (per_trial) {
		r->trials_out = calloc(n ? n : 1, sizeof *r->trials_out);
		r->logs = calloc(n ? n : 1, sizeof *r->logs);
	}
	r->groups = calloc(n_groups ? (size_t)n_groups : 1, sizeof *r->groups);
	if (keep > 0) {
		r->keep = keep;
		r->kept = calloc((size_t)n_groups * (size_t)keep, sizeof *r->kept);
	}
	if ((per_trial && (!r->trials_out || !r->logs)) || !r->groups || (keep > 0 && !r->kept)) {
		bsim_sweep_result_free(r);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory for %zu trial results", n);
	}
	return BSIM_OK;
}

/* The copies of a deterministic group's trial 0, its log included. */
static int deterministic_fill(bsim_trial_result *res, bsim_trial_log *logs, double *t_separate,
                              const int *deterministic, int n_groups, int trials)
{
	for (int g = 0; g < n_groups; g++) {
		if (!deterministic[g])
			continue;
		size_t first = (size_t)g * trials;
		for (int t = 1; t < trials; t++) {
			res[first + t] = res[first];
			if (t_separate)
				t_separate[first + t] = t_separate[first];
			if (bsim_trial_log_copy(&logs[first + t], &logs[first]) != BSIM_OK)
				return BSIM_EFAIL;
		}
	}
	return BSIM_OK;
}

/* The kept trajectories of a deterministic group's copies: trial 0's. */
static int kept_fill(bsim_sweep_result *r, const int *deterministic, bsim_error *err)
{
	for (int g = 0; r->kept && g < r->n_groups; g++) {
		if (!deterministic[g])
			continue;
		const bsim_trajectory *first = &r->kept[(size_t)g * r->keep];
		for (int t = 1; t < r->keep; t++)
			if (bsim_trajectory_copy(&r->kept[(size_t)g * r->keep + t], first) !=
			    BSIM_OK)
				return bsim_error_set(err, BSIM_EFAIL,
				                      "out of memory for kept trajectories");
	}
	return BSIM_OK;
}

/* The totals once every group's counts are in (group_finish done):
 * first[g] is group g's trial 0. No draws, no sampling: a deterministic
 * group's p_traverse is exactly what the one trial gave, so its interval
 * is that point, not a Wilson interval over copies; and only that trial's
 * steps were integrated. */
static void result_totals(bsim_sweep_result *r, const int *deterministic, int trials,
                          const bsim_trial_result *first, size_t first_stride, double wall)
{
	r->total_steps = 0;
	r->trials_run = 0;
	r->solver = (bsim_solver_counts){0, 0};
	for (int g = 0; g < r->n_groups; g++) {
		bsim_group_result *gr = &r->groups[g];
		const bsim_trial_result *f = &first[(size_t)g * first_stride];
		gr->deterministic = deterministic[g];
		if (gr->deterministic && trials > 0) {
			gr->ci95[0] = gr->ci95[1] = gr->p_traverse;
			gr->steps = f->steps_run;
			gr->solver = f->solver;
		}
		r->total_steps += gr->steps;
		r->solver.iteration_limit += gr->solver.iteration_limit;
		r->solver.clamped += gr->solver.clamped;
		r->trials_run += gr->deterministic && trials > 0 ? 1 : trials;
	}
	r->wall_seconds = wall;
}

static void result_finish(bsim_sweep_result *r, const int *deterministic, int n_groups, int trials,
                          double wall)
{
	for (int g = 0; g < n_groups; g++)
		bsim_sweep_group_aggregate(&r->trials_out[(size_t)g * trials], trials,
		                           &r->groups[g]);
	result_totals(r, deterministic, trials, r->trials_out, (size_t)trials, wall);
}

/* What both kinds of sweep check first: e's groups and trials, and the
 * trajectories kept per group (cfg->keep, at most the trials). */
static int sweep_check(const bsim_experiment *e, const bsim_sweep_config *cfg, int *keep,
                       bsim_error *err)
{
	if (e->trials < 0 || e->n_groups < 1)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: expected at least one group and trials >= 0", e->path);
	bsim_error why;
	if (bsim_experiment_check_trials(e, e->trials, &why) != BSIM_OK)
		return bsim_error_set(err, BSIM_EINPUT, "%s: %s", e->path, why.msg);
	*keep = cfg->keep < e->trials ? cfg->keep : e->trials;
	if (*keep < 0)
		*keep = 0;
	return BSIM_OK;
}

/* A plain sweep (backend_b NULL) or a paired one. */
static int sweep_common(const bsim_experiment *e, const bsim_sweep_config *cfg,
                        const bsim_backend *backend_b, const bsim_options *opts_b,
                        bsim_sweep_result *out, bsim_sweep_result *out_b, double **t_separate,
                        bsim_error *err)
{
	double t0 = bsim_clock_seconds();
	int keep = 0, rc0 = sweep_check(e, cfg, &keep, err);
	if (rc0 != BSIM_OK)
		return rc0;
	long total = (long)e->n_groups * e->trials;
	if (result_alloc(out, e->n_groups, e->trials, keep, 1, err) != BSIM_OK)
		return BSIM_EFAIL;
	if (backend_b) {
		*t_separate = calloc(total ? (size_t)total : 1, sizeof **t_separate);
		if (!*t_separate ||
		    result_alloc(out_b, e->n_groups, e->trials, keep, 1, err) != BSIM_OK) {
			free(*t_separate);
			*t_separate = NULL;
			bsim_sweep_result_free(out);
			return bsim_error_set(err, BSIM_EFAIL, "out of memory for %ld pairs",
			                      total);
		}
	}
	bsim_scene *scenes, *scenes_b = NULL;
	int rc = scenes_for(e, cfg, backend_b, opts_b, &scenes, &scenes_b, err);
	int *deterministic = calloc((size_t)e->n_groups, sizeof *deterministic);
	if (rc == BSIM_OK && !deterministic) {
		scenes_free(scenes, e->n_groups);
		if (scenes_b)
			scenes_free(scenes_b, e->n_groups);
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory for %d groups", e->n_groups);
	}
	for (int g = 0; rc == BSIM_OK && g < e->n_groups; g++)
		deterministic[g] = !bsim_effects_random(&scenes[g]);
	sweep_shared sh = {
	        .e = e,
	        .cfg = cfg,
	        .scenes = scenes,
	        .scenes_b = scenes_b ? scenes_b : scenes,
	        .deterministic = deterministic,
	        .results = out->trials_out,
	        .logs = out->logs,
	        .backend_b = backend_b,
	        .opts_b = opts_b,
	        .results_b = backend_b ? out_b->trials_out : NULL,
	        .logs_b = backend_b ? out_b->logs : NULL,
	        .kept = out->kept,
	        .kept_b = backend_b ? out_b->kept : NULL,
	        .keep = keep,
	        .keep_stride = cfg->keep_stride > 0 ? cfg->keep_stride : 5,
	        .t_separate = backend_b ? *t_separate : NULL,
	        .total = total,
	        .end = total,
	        .spill_fd = -1,
	};
	if (rc == BSIM_OK && cfg->journal) {
		sh.lattice = scenes[0].has_lattice;
		sh.record_beams = record_beams(scenes, scenes_b, e->n_groups, cfg);
		sh.record_size = record_bytes(sh.record_beams, backend_b != NULL);
		sh.from_journal = calloc(total ? (size_t)total : 1, 1);
		long kept = 0, cut = 0;
		rc = !sh.from_journal ? bsim_error_set(err, BSIM_EFAIL, "out of memory")
		                      : bsim_journal_replay(cfg->journal, journal_take, &sh, &kept,
		                                            &cut, err);
		if (rc != BSIM_OK) {
			scenes_free(scenes, e->n_groups);
			if (scenes_b)
				scenes_free(scenes_b, e->n_groups);
		}
	}
	if (rc == BSIM_OK) {
		sh.first_fail = sh.total;
		bsim_error_clear(&sh.fail);
		int threads = cfg->threads > 0 ? cfg->threads : omp_get_max_threads();
		if (threads > sh.total)
			threads = sh.total > 0 ? (int)sh.total : 1;
#pragma omp parallel num_threads(threads)
		sweep_thread(&sh);
		out->lattice = scenes[0].has_lattice;
		out->lattice_def = scenes[0].lattice;
		if (backend_b) {
			out_b->lattice = sh.scenes_b[0].has_lattice;
			out_b->lattice_def = sh.scenes_b[0].lattice;
		}
		scenes_free(scenes, e->n_groups);
		if (scenes_b)
			scenes_free(scenes_b, e->n_groups);
		if (sh.first_fail < sh.total)
			rc = bsim_error_set(err, sh.fail.code, "%s", sh.fail.msg);
		else if (sh.stopped)
			rc = bsim_error_set(err, BSIM_ESTOPPED, "stopped after %ld of %ld trials",
			                    sh.done, sh.total);
	}
	free(sh.from_journal);
	if (rc != BSIM_OK) {
		free(deterministic);
		bsim_sweep_result_free(out);
		if (backend_b) {
			bsim_sweep_result_free(out_b);
			free(*t_separate);
			*t_separate = NULL;
		}
		return rc;
	}
	/* The final count may have been reached on another thread. */
	if (cfg->progress)
		cfg->progress(cfg->progress_user, sh.total, sh.total);
	rc = BSIM_OK;
	if (deterministic_fill(out->trials_out, out->logs, backend_b ? *t_separate : NULL,
	                       deterministic, e->n_groups, e->trials) ||
	    (backend_b && deterministic_fill(out_b->trials_out, out_b->logs, NULL, deterministic,
	                                     e->n_groups, e->trials)))
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory for the gate paths");
	if (rc == BSIM_OK)
		rc = kept_fill(out, deterministic, err);
	if (rc == BSIM_OK && backend_b)
		rc = kept_fill(out_b, deterministic, err);
	if (rc != BSIM_OK) {
		free(deterministic);
		bsim_sweep_result_free(out);
		if (backend_b) {
			bsim_sweep_result_free(out_b);
			free(*t_separate);
			*t_separate = NULL;
		}
		return rc;
	}
	double wall = bsim_clock_seconds() - t0;
	result_finish(out, deterministic, e->n_groups, e->trials, wall);
	if (backend_b)
		result_finish(out_b, deterministic, e->n_groups, e->trials, wall);
	free(deterministic);
	return BSIM_OK;
}

/* ---- a streamed sweep ---------------------------------------------------
 *
 * The trials run in blocks of BSIM_SWEEP_BLOCK consecutive indices: a
 * block's slots are filled (from the journal, or by running the trials on
 * every thread), its deterministic copies filled in, its trials added to
 * their groups' counts, and the block handed to the sink; then the next
 * block reuses the slots. What stays is per group (counts, a deterministic
 * group's one trial) and one bit per trial (journaled or not). A resumed
 * run's journal is read once, before the first block: each record goes to
 * a spill file at its trial's place (unlinked at once, so nothing is left
 * behind), from which its block reads it back. */

typedef struct stream_state {
	bsim_trial_result *results; /* BSIM_SWEEP_BLOCK slots */
	bsim_trial_log *logs;
	unsigned char *from_journal;
	bsim_trial_result *det_first; /* per group: a deterministic group's trial 0 */
	bsim_trial_log *det_log;
} stream_state;

static void stream_free(stream_state *st, int n_groups)
{
	for (long k = 0; st->logs && k < BSIM_SWEEP_BLOCK; k++)
		bsim_trial_log_clear(&st->logs[k]);
	for (int g = 0; st->det_log && g < n_groups; g++)
		bsim_trial_log_clear(&st->det_log[g]);
	free(st->results);
	free(st->logs);
	free(st->from_journal);
	free(st->det_first);
	free(st->det_log);
}

/* The journal's records into the spill file, a bit per trial. */
static int stream_replay(sweep_shared *sh, bsim_error *err)
{
	char path[2048];
	const char *jp = bsim_journal_path(sh->cfg->journal);
	if (snprintf(path, sizeof path, "%s.byindex", jp) >= (int)sizeof path)
		return bsim_error_set(err, BSIM_EFAIL, "%s: path too long", jp);
	sh->spill_fd = open(path, O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
	if (sh->spill_fd < 0)
		return bsim_error_set(err, BSIM_EFAIL, "%s: cannot create (%s)", path,
		                      strerror(errno));
	unlink(path);
	sh->journaled = calloc((size_t)sh->total / 8 + 1, 1);
	if (!sh->journaled)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	long kept = 0, cut = 0;
	return bsim_journal_replay(sh->cfg->journal, journal_take, sh, &kept, &cut, err);
}

/* Block [sh->first, sh->end)'s journaled trials into their slots. */
static int stream_load(sweep_shared *sh, bsim_error *err)
{
	size_t size = sh->record_beams ? sh->record_size : sizeof(bsim_trial_result);
	void *rec = sh->record_beams ? malloc(size) : NULL;
	if (sh->record_beams && !rec)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	int rc = BSIM_OK;
	for (long i = sh->first; rc == BSIM_OK && sh->journaled && i < sh->end; i++) {
		if (!(sh->journaled[i / 8] & (1u << (i % 8))))
			continue;
		long k = i - sh->first;
		if (pread(sh->spill_fd, rec ? rec : (void *)&sh->results[k], size,
		          (off_t)((size_t)i * size)) != (ssize_t)size) {
			rc = bsim_error_set(err, BSIM_EFAIL,
			                    "cannot read back the journal's trial %ld (%s)", i,
			                    strerror(errno));
			break;
		}
		/* a lattice's path too long for its record: the trial runs again */
		int got = rec ? sweep_record_unpack(rec, sh->record_beams, &sh->results[k],
		                                    &sh->logs[k])
		              : 1;
		if (got < 0)
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
		sh->from_journal[k] = got > 0;
	}
	free(rec);
	return rc;
}

/* A finished block: copies filled in, counted, handed to the sink. */
static int stream_block(sweep_shared *sh, stream_state *st, bsim_sweep_result *out, bsim_error *err)
{
	int trials = sh->e->trials;
	for (long i = sh->first; i < sh->end; i++) {
		long k = i - sh->first;
		int g = (int)(i / trials), t = (int)(i % trials);
		if (sh->deterministic[g] && t == 0) {
			st->det_first[g] = st->results[k];
			if (bsim_trial_log_copy(&st->det_log[g], &st->logs[k]) != BSIM_OK)
				return bsim_error_set(err, BSIM_EFAIL, "out of memory");
		} else if (sh->deterministic[g]) {
			st->results[k] = st->det_first[g];
			if (bsim_trial_log_copy(&st->logs[k], &st->det_log[g]) != BSIM_OK)
				return bsim_error_set(err, BSIM_EFAIL, "out of memory");
		}
		group_add(&out->groups[g], &st->results[k]);
		if (st->results[k].outcome == BSIM_UNSTABLE && out->first_unstable < 0) {
			out->first_unstable = i;
			out->first_unstable_result = st->results[k];
		}
	}
	/* A lattice group's summary grows by the block's run of its trials. */
	for (long i = sh->first; out->lattice_summaries && i < sh->end;) {
		int g = (int)(i / trials);
		long end = (long)(g + 1) * trials < sh->end ? (long)(g + 1) * trials : sh->end;
		long k = i - sh->first;
		if (bsim_lattice_summary_add(&out->lattice_summaries[g], &st->results[k],
		                             &st->logs[k], (int)(end - i)) != BSIM_OK)
			return bsim_error_set(err, BSIM_EFAIL, "out of memory");
		i = end;
	}
	bsim_sweep_block b = {sh->first, sh->end - sh->first, st->results, st->logs};
	return sh->cfg->sink(sh->cfg->sink_user, &b, err);
}

static int sweep_streamed(const bsim_experiment *e, const bsim_sweep_config *cfg,
                          bsim_sweep_result *out, bsim_error *err)
{
	double t0 = bsim_clock_seconds();
	int keep = 0, rc0 = sweep_check(e, cfg, &keep, err);
	if (rc0 != BSIM_OK)
		return rc0;
	long total = (long)e->n_groups * e->trials;
	if (result_alloc(out, e->n_groups, e->trials, keep, 0, err) != BSIM_OK)
		return BSIM_EFAIL;

	bsim_scene *scenes = NULL;
	stream_state st = {0};
	int *deterministic = NULL;
	int rc = scenes_for(e, cfg, NULL, NULL, &scenes, NULL, err);
	if (rc == BSIM_OK && scenes[0].has_lattice) {
		out->lattice = 1;
		out->lattice_def = scenes[0].lattice;
		out->lattice_summaries =
		        calloc((size_t)e->n_groups, sizeof *out->lattice_summaries);
		for (int g = 0; out->lattice_summaries && g < e->n_groups && rc == BSIM_OK; g++)
			rc = bsim_lattice_summary_begin(&out->lattice_summaries[g],
			                                out->lattice_def.rows);
		if (!out->lattice_summaries || rc != BSIM_OK)
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory for %d groups",
			                    e->n_groups);
	}
	if (rc == BSIM_OK) {
		deterministic = calloc((size_t)e->n_groups, sizeof *deterministic);
		st.results = calloc(BSIM_SWEEP_BLOCK, sizeof *st.results);
		st.logs = calloc(BSIM_SWEEP_BLOCK, sizeof *st.logs);
		st.from_journal = calloc(BSIM_SWEEP_BLOCK, 1);
		st.det_first = calloc((size_t)e->n_groups, sizeof *st.det_first);
		st.det_log = calloc((size_t)e->n_groups, sizeof *st.det_log);
		if (!deterministic || !st.results || !st.logs || !st.from_journal ||
		    !st.det_first || !st.det_log)
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory for %d groups",
			                    e->n_groups);
	}
	for (int g = 0; rc == BSIM_OK && g < e->n_groups; g++)
		deterministic[g] = !bsim_effects_random(&scenes[g]);
	sweep_shared sh = {
	        .e = e,
	        .cfg = cfg,
	        .scenes = scenes,
	        .scenes_b = scenes,
	        .deterministic = deterministic,
	        .results = st.results,
	        .logs = st.logs,
	        .kept = out->kept,
	        .keep = keep,
	        .keep_stride = cfg->keep_stride > 0 ? cfg->keep_stride : 5,
	        .total = total,
	        .from_journal = st.from_journal,
	        .spill_fd = -1,
	        .first_fail = total,
	        .lattice = out->lattice,
	};
	if (rc == BSIM_OK) {
		sh.record_beams = record_beams(scenes, NULL, e->n_groups, cfg);
		sh.record_size = record_bytes(sh.record_beams, 0);
	}
	if (rc == BSIM_OK && cfg->journal)
		rc = stream_replay(&sh, err);
	int threads = cfg->threads > 0 ? cfg->threads : omp_get_max_threads();
	if (threads > BSIM_SWEEP_BLOCK)
		threads = BSIM_SWEEP_BLOCK;
	for (long first = 0; rc == BSIM_OK && first < total; first += BSIM_SWEEP_BLOCK) {
		sh.first = first;
		sh.end = total - first < BSIM_SWEEP_BLOCK ? total : first + BSIM_SWEEP_BLOCK;
		memset(st.results, 0, BSIM_SWEEP_BLOCK * sizeof *st.results);
		memset(st.from_journal, 0, BSIM_SWEEP_BLOCK);
		rc = stream_load(&sh, err);
		if (rc != BSIM_OK)
			break;
		long n = sh.end - sh.first;
		bsim_error_clear(&sh.fail);
#pragma omp parallel num_threads(threads < n ? threads : (int)n)
		sweep_thread(&sh);
		if (sh.first_fail < total)
			rc = bsim_error_set(err, sh.fail.code, "%s", sh.fail.msg);
		else if (sh.stopped)
			rc = bsim_error_set(err, BSIM_ESTOPPED, "stopped after %ld of %ld trials",
			                    sh.done, total);
		else
			rc = stream_block(&sh, &st, out, err);
	}
	if (sh.spill_fd >= 0)
		close(sh.spill_fd);
	free(sh.journaled);
	if (rc == BSIM_OK && cfg->progress)
		cfg->progress(cfg->progress_user, total, total);
	if (rc == BSIM_OK)
		rc = kept_fill(out, deterministic, err);
	if (rc == BSIM_OK) {
		for (int g = 0; g < e->n_groups; g++) {
			group_finish(&out->groups[g]);
			if (out->lattice_summaries)
				bsim_lattice_summary_end(&out->lattice_summaries[g]);
		}
		result_totals(out, deterministic, e->trials, st.det_first, 1,
		              bsim_clock_seconds() - t0);
	}
	if (scenes)
		scenes_free(scenes, e->n_groups);
	stream_free(&st, e->n_groups);
	free(deterministic);
	if (rc != BSIM_OK)
		bsim_sweep_result_free(out);
	return rc;
}

int bsim_sweep_run(const bsim_experiment *e, const bsim_sweep_config *cfg, bsim_sweep_result *out,
                   bsim_error *err)
{
	if (cfg->sink)
		return sweep_streamed(e, cfg, out, err);
	return sweep_common(e, cfg, NULL, NULL, out, NULL, NULL, err);
}

int bsim_sweep_run_paired(const bsim_experiment *e, const bsim_sweep_config *cfg,
                          const bsim_backend *backend_b, const bsim_options *opts_b,
                          bsim_sweep_result *out_a, bsim_sweep_result *out_b, double **t_separate,
                          bsim_error *err)
{
	return sweep_common(e, cfg, backend_b, opts_b, out_a, out_b, t_separate, err);
}

int bsim_sweep_record_size_for(const bsim_experiment *e, const bsim_sweep_config *cfg, size_t *size,
                               bsim_error *err)
{
	bsim_scene *scenes = NULL;
	int rc = scenes_build(e, cfg, 0, &scenes, err);
	if (rc != BSIM_OK)
		return rc;
	int beams = record_beams(scenes, NULL, e->n_groups, cfg);
	*size = record_bytes(beams, 0);
	scenes_free(scenes, e->n_groups);
	return BSIM_OK;
}

int bsim_sweep_record_size_paired_for(const bsim_experiment *e, const bsim_sweep_config *cfg,
                                      size_t *size, bsim_error *err)
{
	bsim_scene *scenes = NULL, *scenes_b = NULL;
	int rc = scenes_build(e, cfg, 0, &scenes, err);
	if (rc != BSIM_OK)
		return rc;
	if (cfg->n_extra_b > 0 && (rc = scenes_build(e, cfg, 1, &scenes_b, err)) != BSIM_OK) {
		scenes_free(scenes, e->n_groups);
		return rc;
	}
	int beams = record_beams(scenes, scenes_b, e->n_groups, cfg);
	*size = record_bytes(beams, 1);
	scenes_free(scenes, e->n_groups);
	if (scenes_b)
		scenes_free(scenes_b, e->n_groups);
	return BSIM_OK;
}

/* ---- a part of a sweep (beamsim/sweep.h) ---------------------------------
 *
 * The trials run in blocks of BSIM_SWEEP_BLOCK indices as a streamed
 * sweep's do, each thread passing over the other parts' trials; nothing is
 * kept but the records handed on, so memory does not grow with the sweep. */

static int run_part(const bsim_experiment *e, const bsim_sweep_config *cfg,
                    const bsim_backend *backend_b, const bsim_options *opts_b,
                    const bsim_sweep_part *part, bsim_error *err)
{
	int keep = 0, rc = sweep_check(e, cfg, &keep, err);
	if (rc != BSIM_OK)
		return rc;
	if (part->count < 1 || part->index < 0 || part->index >= part->count)
		return bsim_error_set(err, BSIM_EINPUT, "part %d of %d: expected 0 <= part < %d",
		                      part->index, part->count, part->count);
	long total = (long)e->n_groups * e->trials;
	bsim_scene *scenes = NULL;
	int *deterministic = calloc((size_t)e->n_groups, sizeof *deterministic);
	bsim_trial_result *results = calloc(BSIM_SWEEP_BLOCK, sizeof *results);
	bsim_trial_log *logs = calloc(BSIM_SWEEP_BLOCK, sizeof *logs);
	/* a paired part's second side */
	bsim_scene *scenes_b = NULL;
	bsim_trial_result *results_b = NULL;
	bsim_trial_log *logs_b = NULL;
	double *t_separate = NULL;
	if (backend_b) {
		results_b = calloc(BSIM_SWEEP_BLOCK, sizeof *results_b);
		logs_b = calloc(BSIM_SWEEP_BLOCK, sizeof *logs_b);
		t_separate = calloc(BSIM_SWEEP_BLOCK, sizeof *t_separate);
	}
	if (!deterministic || !results || !logs ||
	    (backend_b && (!results_b || !logs_b || !t_separate)))
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory for %d groups", e->n_groups);
	if (rc == BSIM_OK)
		rc = scenes_for(e, cfg, backend_b, opts_b, &scenes, &scenes_b, err);
	for (int g = 0; rc == BSIM_OK && g < e->n_groups; g++)
		deterministic[g] = !bsim_effects_random(&scenes[g]);
	sweep_shared sh = {
	        .e = e,
	        .cfg = cfg,
	        .scenes = scenes,
	        .scenes_b = scenes_b ? scenes_b : scenes,
	        .deterministic = deterministic,
	        .results = results,
	        .logs = logs,
	        .backend_b = backend_b,
	        .opts_b = opts_b,
	        .results_b = results_b,
	        .logs_b = logs_b,
	        .t_separate = t_separate,
	        .keep_stride = 5,
	        .total = total,
	        .spill_fd = -1,
	        .first_fail = total,
	        .part = part,
	};
	if (rc == BSIM_OK) {
		sh.record_beams = record_beams(scenes, scenes_b, e->n_groups, cfg);
		sh.record_size = record_bytes(sh.record_beams, backend_b != NULL);
	}
	/* Progress: this part's trials, or with collect every part's. */
	for (long i = 0; i < total; i++) {
		long j = cfg->journal_first + i;
		int done = part->done && (part->done[j / 8] & (1u << (j % 8)));
		if (part->collect)
			sh.done += done;
		else
			sh.progress_total += !part_skips(part, cfg->journal_first, i);
	}
	if (part->collect)
		sh.progress_total = total;
	int threads = cfg->threads > 0 ? cfg->threads : omp_get_max_threads();
	for (long first = 0; rc == BSIM_OK && first < total; first += BSIM_SWEEP_BLOCK) {
		sh.first = first;
		sh.end = total - first < BSIM_SWEEP_BLOCK ? total : first + BSIM_SWEEP_BLOCK;
		long n = sh.end - sh.first;
		bsim_error_clear(&sh.fail);
#pragma omp parallel num_threads(threads < n ? threads : (int)n)
		sweep_thread(&sh);
		if (sh.first_fail < total)
			rc = bsim_error_set(err, sh.fail.code, "%s", sh.fail.msg);
		else if (sh.stopped)
			rc = bsim_error_set(err, BSIM_ESTOPPED, "stopped after %ld of %ld trials",
			                    sh.done, sh.progress_total);
	}
	if (rc == BSIM_OK && part->collect)
		rc = part->collect(part->user, 1, part_accept, &sh, err);
	if (rc == BSIM_OK && cfg->progress)
		cfg->progress(cfg->progress_user, sh.progress_total, sh.progress_total);
	if (scenes)
		scenes_free(scenes, e->n_groups);
	if (scenes_b)
		scenes_free(scenes_b, e->n_groups);
	for (long k = 0; logs && k < BSIM_SWEEP_BLOCK; k++)
		bsim_trial_log_clear(&logs[k]);
	for (long k = 0; logs_b && k < BSIM_SWEEP_BLOCK; k++)
		bsim_trial_log_clear(&logs_b[k]);
	free(logs);
	free(results);
	free(logs_b);
	free(results_b);
	free(t_separate);
	free(deterministic);
	return rc;
}

int bsim_sweep_run_part(const bsim_experiment *e, const bsim_sweep_config *cfg,
                        const bsim_sweep_part *part, bsim_error *err)
{
	return run_part(e, cfg, NULL, NULL, part, err);
}

int bsim_sweep_run_part_paired(const bsim_experiment *e, const bsim_sweep_config *cfg,
                               const bsim_backend *backend_b, const bsim_options *opts_b,
                               const bsim_sweep_part *part, bsim_error *err)
{
	return run_part(e, cfg, backend_b, opts_b, part, err);
}
