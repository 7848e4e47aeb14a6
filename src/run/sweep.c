/* A sweep: every (group, trial) of an experiment on one backend.
 *
 * The (group, trial) pairs form one flat list, index g*trials + t, handed
 * out dynamically to OpenMP threads (trials end at very different times, so
 * a static split would leave threads idle). A trial's seed depends only on
 * (experiment seed, g, t) and its result goes to its own slot, so the
 * result is the same whatever the thread count (docs/files.md "Experiment
 * file (YAML)"). A sweep of sides runs each trial on every side (a backend
 * with options), in the same slot of each side's result (trial_sides.c).
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
#include "run/trial_sides.h"

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
	out->turn_end_mean += t->turn_end; /* sums until group_finish */
	out->turn_end_mean_abs += fabs(t->turn_end);
	out->turn_end_max_abs = fmax(out->turn_end_max_abs, fabs(t->turn_end));
	out->turn_max = fmax(out->turn_max, t->turn_max);
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
	out->turn_end_mean = n > 0 ? out->turn_end_mean / n : 0.0;
	out->turn_end_mean_abs = n > 0 ? out->turn_end_mean_abs / n : 0.0;
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

/* The side-0 scenes a sweep built (scenes_for), freed; those lent to it
 * (cfg->scenes) left to their owner. */
static void scenes_release(const bsim_sweep_config *cfg, bsim_scene *scenes, int n)
{
	if (scenes != cfg->scenes)
		scenes_free(scenes, n);
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

/* The beam-steps the trials of the groups' scenes take at most
 * (bsim_plan_fn). */
static double plan_beam_steps(const bsim_experiment *e, const bsim_scene *scenes)
{
	double total = 0.0;
	for (int g = 0; g < e->n_groups; g++) {
		const bsim_scene *s = &scenes[g];
		double n = s->effects.has_random_force ? (double)e->trials : 1.0;
		total += n * (double)s->max_steps * s->n_beams;
	}
	return total;
}

/* The scenes of every group for each of n sides, each checked against the
 * backend that runs it (bsim_experiment_group_check), so that a scene a
 * backend refuses (a body within Box2D's skin) is said where the scene
 * gave the field, before any trial runs. scenes_b (NULL for a plain sweep)
 * gets side 1's scenes when it has overrides of its own (cfg->extra_b),
 * else NULL: it shares side 0's. On failure nothing is left built. */
static int scenes_for(const bsim_experiment *e, const bsim_sweep_config *cfg, int n,
                      const bsim_backend *const *backend, const bsim_options *const *opts,
                      bsim_scene **scenes, bsim_scene **scenes_b, bsim_error *err)
{
	const int own_b = n > 1 && cfg->n_extra_b > 0;
	if (scenes_b)
		*scenes_b = NULL;
	int rc = BSIM_OK;
	if (cfg->scenes)
		*scenes = cfg->scenes; /* lent by the caller (bsim_sweep_plan_for) */
	else
		rc = scenes_build(e, cfg, 0, scenes, err);
	if (rc == BSIM_OK && own_b)
		rc = scenes_build(e, cfg, 1, scenes_b, err);
	for (int side = 0; rc == BSIM_OK && side < n; side++) {
		const int of_b = side == 1 && own_b;
		int n_ov;
		bsim_override *ov = side_overrides(cfg, of_b, &n_ov);
		if (!ov)
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
		for (int g = 0; rc == BSIM_OK && g < e->n_groups; g++)
			rc = bsim_experiment_group_check(e, g, ov, n_ov,
			                                 of_b ? &(*scenes_b)[g] : &(*scenes)[g],
			                                 backend[side], opts[side], err);
		free(ov);
	}
	if (rc != BSIM_OK) {
		if (*scenes)
			scenes_release(cfg, *scenes, e->n_groups);
		if (scenes_b && *scenes_b)
			scenes_free(*scenes_b, e->n_groups);
		*scenes = NULL;
		if (scenes_b)
			*scenes_b = NULL;
	}
	return rc;
}

/* A record of sides holds each result, then each pair's separation time:
 * for two sides the bytes of {result a, result b, double} as a struct. */
_Static_assert(sizeof(bsim_trial_result) % _Alignof(double) == 0,
               "a record of sides packs results and doubles without padding");

bsim_sweep_config bsim_sweep_config_default(void)
{
	bsim_sweep_config c;
	memset(&c, 0, sizeof c);
	c.backend = bsim_backend_default();
	return c;
}

size_t bsim_sweep_record_size(int paired)
{
	return paired ? bsim_sweep_record_size_sides(2) : sizeof(bsim_trial_result);
}

size_t bsim_sweep_record_size_sides(int n_sides)
{
	return (size_t)n_sides * sizeof(bsim_trial_result) +
	       (size_t)bsim_sweep_pairs(n_sides) * sizeof(double);
}

/* 1 if a sweep's records are lattice records (run/sweep_record.h: the
 * result, the gate path and the moved beams' peaks), 0 for records of the
 * result alone. */
static int record_lattice(const bsim_scene *scenes, const bsim_sweep_config *cfg)
{
	return !cfg->results_only && scenes[0].has_lattice;
}

/* The size of a record (lattice: a lattice record, else the result
 * alone) of n sides (1: a plain sweep). A lattice sweep of sides' record
 * is each side's lattice record in order, packed by run/sweep_record.c,
 * then each pair's separation time (a double). */
static size_t record_bytes(int lattice, int n)
{
	if (!lattice)
		return n > 1 ? bsim_sweep_record_size_sides(n) : sizeof(bsim_trial_result);
	return (size_t)n * bsim_sweep_record_bytes() + (size_t)bsim_sweep_pairs(n) * sizeof(double);
}

/* What the threads share. first_fail is the index of the lowest failed
 * trial so far (total if none, -1 if a thread could not start). */
typedef struct sweep_shared {
	const bsim_experiment *e;
	const bsim_sweep_config *cfg;
	int n_sides; /* 1: a plain sweep (cfg->backend); 2 or more: a sweep of sides */
	const bsim_scene *scenes[BSIM_SWEEP_SIDES_MAX]; /* each side's (may be side 0's) */
	const bsim_backend *backend[BSIM_SWEEP_SIDES_MAX];
	const bsim_options *opts[BSIM_SWEEP_SIDES_MAX];
	const int *deterministic; /* per group */
	bsim_trial_result *results[BSIM_SWEEP_SIDES_MAX];
	bsim_trial_log *logs[BSIM_SWEEP_SIDES_MAX];
	bsim_trajectory *kept[BSIM_SWEEP_SIDES_MAX]; /* NULL: none kept */
	int keep, keep_stride;
	/* Each pair's separation times by slot (a sweep of sides). */
	double *t_separate[BSIM_SWEEP_PAIRS_MAX];
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
	/* 1: a lattice sweep's records hold the gate path and the moved beams'
	 * peaks (run/sweep_record.h; a sweep of sides', each side's:
	 * record_bytes); record_size bytes, every record's */
	int record_lattice;
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

/* Trial i's record into buf (sh->record_size bytes, when record_of needs
 * it: a lattice's or a sweep of sides'); returns it. A plain sweep's is
 * its result, or a lattice's result with its path and peaks; a sweep of
 * sides' each side's, then each pair's separation time. */
static const void *record_of(sweep_shared *sh, long i, void *buf)
{
	long k = i - sh->first;
	if (sh->n_sides == 1 && !sh->record_lattice)
		return &sh->results[0][k];
	unsigned char *p = buf;
	size_t side = sh->record_lattice ? bsim_sweep_record_bytes() : sizeof(bsim_trial_result);
	for (int s = 0; s < sh->n_sides; s++, p += side)
		if (sh->record_lattice)
			bsim_sweep_record_pack(p, &sh->results[s][k], &sh->logs[s][k]);
		else
			memcpy(p, &sh->results[s][k], side);
	for (int q = 0; q < bsim_sweep_pairs(sh->n_sides); q++, p += sizeof(double))
		memcpy(p, &sh->t_separate[q][k], sizeof(double));
	return buf;
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
	    (sh->lattice && !cfg->results_only && !sh->record_lattice))
		return 0;
	if (sh->journaled) {
		/* Streamed: the record waits in the spill file for its block. */
		size_t size = sh->record_size;
		if (pwrite(sh->spill_fd, payload, size, (off_t)(index * size)) != (ssize_t)size)
			return -1;
		sh->done += !(sh->journaled[index / 8] & (1u << (index % 8)));
		sh->journaled[index / 8] |= (unsigned char)(1u << (index % 8));
		return 0;
	}
	const unsigned char *p = payload;
	size_t side = sh->record_lattice ? bsim_sweep_record_bytes() : sizeof(bsim_trial_result);
	for (int s = 0; s < sh->n_sides; s++, p += side) {
		if (!sh->record_lattice) {
			memcpy(&sh->results[s][index], p, side);
			continue;
		}
		/* a path too long for its record: the trial (every side) runs again */
		int got = bsim_sweep_record_unpack(p, &sh->results[s][index], &sh->logs[s][index]);
		if (got <= 0)
			return got;
	}
	for (int q = 0; q < bsim_sweep_pairs(sh->n_sides); q++, p += sizeof(double))
		memcpy(&sh->t_separate[q][index], p, sizeof(double));
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
	const int n_sides = sh->n_sides, n_pairs = bsim_sweep_pairs(n_sides);
	int leader = omp_get_thread_num() == 0;
	bsim_trial_runner *runner = bsim_trial_runner_alloc();
	/* The scenes live, unchanged, as long as the sweep. */
	if (runner)
		bsim_trial_runner_keep_worlds(runner, 1);
	trial_sides *sides = n_sides > 1 ? bsim_trial_sides_alloc(n_sides) : NULL;
	if (sides)
		bsim_trial_sides_keep_worlds(sides, 1);
	bsim_trial_log *log[BSIM_SWEEP_SIDES_MAX] = {NULL};
	int logs_ok = 1;
	for (int s = 0; s < n_sides; s++)
		logs_ok &= (log[s] = bsim_trial_log_alloc()) != NULL;
	void *record_buf = n_sides > 1 || sh->record_lattice ? malloc(sh->record_size) : NULL;
	bsim_error err;

	if (!runner || (n_sides > 1 && !sides) || !logs_ok ||
	    ((n_sides > 1 || sh->record_lattice) && !record_buf)) {
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
		const bsim_scene *scene = &sh->scenes[0][g];
		bsim_trajectory *keep = t < sh->keep ? &sh->kept[0][g * sh->keep + t] : NULL;
		bsim_recorder rec = {.stride = keep ? sh->keep_stride : 1,
		                     .record = keep ? bsim_trajectory_record : NULL,
		                     .record_user = keep,
		                     .log = log[0],
		                     .overlap = cfg->measure_overlap};
		int rc = BSIM_OK, ran = 1;
		if (t > 0 && sh->deterministic[g]) {
			ran = 0; /* a copy of trial 0, filled in after the run (and its trajectory)
			          */
		} else if (sides) {
			const bsim_scene *scenes[BSIM_SWEEP_SIDES_MAX];
			bsim_trial_result *results[BSIM_SWEEP_SIDES_MAX];
			double t_sep[BSIM_SWEEP_PAIRS_MAX];
			for (int s = 0; s < n_sides; s++) {
				scenes[s] = &sh->scenes[s][g];
				results[s] = &sh->results[s][k];
				sides->keep[s] = keep ? &sh->kept[s][g * sh->keep + t] : NULL;
			}
			sides->keep_stride = sh->keep_stride;
			rc = bsim_trial_sides_run(sides, scenes, sh->backend, sh->opts, seed,
			                          0.01 * body_size(scene), results, log, t_sep,
			                          &err);
			for (int q = 0; rc == BSIM_OK && q < n_pairs; q++)
				sh->t_separate[q][k] = t_sep[q];
		} else {
			rc = bsim_trial_run(runner, scene, cfg->backend, cfg->opts, seed, &rec,
			                    &sh->results[0][k], &err);
			if (rc == BSIM_OK && keep && keep->oom)
				rc = bsim_error_set(&err, BSIM_EFAIL,
				                    "out of memory for a kept trajectory");
		}
		for (int s = 0; rc == BSIM_OK && ran && s < n_sides; s++)
			if (bsim_trial_log_copy(&sh->logs[s][k], log[s]) != BSIM_OK)
				rc = bsim_error_set(&err, BSIM_EFAIL,
				                    "out of memory for the gate path");
		/* Only trials that ran are journaled: copies are filled in again. */
		const void *record = ran && (cfg->journal || (sh->part && sh->part->record))
		                             ? record_of(sh, i, record_buf)
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
	bsim_trial_sides_free(sides);
	for (int s = 0; s < n_sides; s++)
		bsim_trial_log_free(log[s]);
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
	r->has_turn = 1;
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
static int deterministic_fill(bsim_trial_result *res, bsim_trial_log *logs,
                              const int *deterministic, int n_groups, int trials)
{
	for (int g = 0; g < n_groups; g++) {
		if (!deterministic[g])
			continue;
		size_t first = (size_t)g * trials;
		for (int t = 1; t < trials; t++) {
			res[first + t] = res[first];
			if (bsim_trial_log_copy(&logs[first + t], &logs[first]) != BSIM_OK)
				return BSIM_EFAIL;
		}
	}
	return BSIM_OK;
}

/* A pair's separation times of a deterministic group's copies: trial 0's. */
static void separation_fill(double *t_separate, const int *deterministic, int n_groups, int trials)
{
	for (int g = 0; g < n_groups; g++)
		for (int t = 1; deterministic[g] && t < trials; t++)
			t_separate[(size_t)g * trials + t] = t_separate[(size_t)g * trials];
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

/* Which groups' bodies rotate, from their scenes: before the groups are
 * counted, which keeps it. */
static void groups_rotate(bsim_sweep_result *r, const bsim_scene *scenes)
{
	for (int g = 0; g < r->n_groups; g++)
		r->groups[g].rotates = scenes[g].body.rotates;
}

static void result_finish(bsim_sweep_result *r, const int *deterministic, int n_groups, int trials,
                          double wall)
{
	for (int g = 0; g < n_groups; g++) {
		int rotates = r->groups[g].rotates; /* groups_rotate's */
		bsim_sweep_group_aggregate(&r->trials_out[(size_t)g * trials], trials,
		                           &r->groups[g]);
		r->groups[g].rotates = rotates;
	}
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

/* ---- the one driver -----------------------------------------------------
 *
 * Every kind of sweep is one sweep_drive: planned once (the checks, each
 * side's scene of every group, the deterministic groups, the record's
 * size), its trials run in blocks of consecutive indices by every thread,
 * each block loaded from the journal before it runs and finished after,
 * then the sweep finished, and everything it holds freed by one clean-up
 * (drive_free).
 *
 * A sweep held in memory (SWEEP_WHOLE, plain or of sides) is one block of
 * every trial, its results in place; the journal's records go straight to
 * their trials' places before it runs; the deterministic groups' copies
 * and the groups' counts are made at the end.
 *
 * A streamed sweep (SWEEP_STREAMED, a sink) runs blocks of
 * BSIM_SWEEP_BLOCK: a block's slots are filled (from the journal, or by
 * running its trials), its deterministic copies filled in, its trials
 * added to their groups' counts, and the block handed to the sink; then
 * the next block reuses the slots. What stays is per group (counts, a
 * deterministic group's one trial) and one bit per trial (journaled or
 * not). A resumed run's journal is read once, before the first block:
 * each record goes to a spill file at its trial's place (unlinked at once,
 * so nothing is left behind), from which its block reads it back.
 *
 * A part (SWEEP_PART, beamsim/sweep.h) runs blocks as a streamed sweep
 * does, each thread passing over the other parts' trials; nothing is kept
 * but the records handed on, so memory does not grow with the sweep. */

typedef enum { SWEEP_WHOLE, SWEEP_STREAMED, SWEEP_PART } sweep_kind;

typedef struct drive_state {
	sweep_kind kind;
	/* SWEEP_WHOLE: each side's result, and each pair's separation times
	 * by trial (of sides); SWEEP_STREAMED: the one result */
	bsim_sweep_result *out;
	double **t_separate;
	/* what the drive holds, freed by drive_free */
	bsim_scene *scenes, *scenes_b;
	int *deterministic;           /* per group */
	bsim_trial_result *slots;     /* each side's BSIM_SWEEP_BLOCK (not whole) */
	bsim_trial_log *slot_logs;    /* the same */
	double *slot_t_separate;      /* each pair's BSIM_SWEEP_BLOCK (a part) */
	unsigned char *from_journal;  /* per slot (whole: per trial) */
	bsim_trial_result *det_first; /* streamed, per group: a deterministic */
	bsim_trial_log *det_log;      /* group's trial 0 and its log */
	sweep_shared sh;
} drive_state;

/* The results (whole, streamed) and the slots the trials go into, each
 * side's and pair's place in sh. */
static int drive_alloc(drive_state *d, int keep, bsim_error *err)
{
	sweep_shared *sh = &d->sh;
	const bsim_experiment *e = sh->e;
	const int n_sides = sh->n_sides, n_pairs = bsim_sweep_pairs(n_sides);
	const long total = sh->total;
	if (d->kind == SWEEP_WHOLE) {
		for (int s = 0; s < n_sides; s++) /* each freeable, whatever fails */
			memset(&d->out[s], 0, sizeof d->out[s]);
		for (int s = 0; s < n_sides; s++)
			if (result_alloc(&d->out[s], e->n_groups, e->trials, keep, 1, err) !=
			    BSIM_OK) {
				while (s-- > 0)
					bsim_sweep_result_free(&d->out[s]);
				return BSIM_EFAIL;
			}
		if (n_pairs > 0 &&
		    !(*d->t_separate = calloc(total ? (size_t)n_pairs * (size_t)total : 1,
		                              sizeof **d->t_separate)))
			return bsim_error_set(err, BSIM_EFAIL, "out of memory for %ld pairs",
			                      total);
		for (int s = 0; s < n_sides; s++) {
			sh->results[s] = d->out[s].trials_out;
			sh->logs[s] = d->out[s].logs;
			sh->kept[s] = d->out[s].kept;
		}
		for (int q = 0; q < n_pairs; q++)
			sh->t_separate[q] = *d->t_separate + (size_t)q * (size_t)total;
		if (sh->cfg->journal && !(d->from_journal = calloc(total ? (size_t)total : 1, 1)))
			return bsim_error_set(err, BSIM_EFAIL, "out of memory");
		sh->from_journal = d->from_journal;
		return BSIM_OK;
	}
	if (d->kind == SWEEP_STREAMED) {
		if (result_alloc(d->out, e->n_groups, e->trials, keep, 0, err) != BSIM_OK)
			return BSIM_EFAIL;
		sh->kept[0] = d->out->kept;
		d->det_first = calloc((size_t)e->n_groups, sizeof *d->det_first);
		d->det_log = calloc((size_t)e->n_groups, sizeof *d->det_log);
		if (!d->det_first || !d->det_log)
			return bsim_error_set(err, BSIM_EFAIL, "out of memory for %d groups",
			                      e->n_groups);
	}
	const size_t slots = (size_t)n_sides * BSIM_SWEEP_BLOCK;
	d->slots = calloc(slots, sizeof *d->slots);
	d->slot_logs = calloc(slots, sizeof *d->slot_logs);
	if (n_pairs > 0)
		d->slot_t_separate =
		        calloc((size_t)n_pairs * BSIM_SWEEP_BLOCK, sizeof *d->slot_t_separate);
	if (d->kind == SWEEP_STREAMED)
		d->from_journal = calloc(BSIM_SWEEP_BLOCK, 1);
	if (!d->slots || !d->slot_logs || (n_pairs > 0 && !d->slot_t_separate) ||
	    (d->kind == SWEEP_STREAMED && !d->from_journal))
		return bsim_error_set(err, BSIM_EFAIL, "out of memory for %d groups", e->n_groups);
	for (int s = 0; s < n_sides; s++) {
		sh->results[s] = d->slots + (size_t)s * BSIM_SWEEP_BLOCK;
		sh->logs[s] = d->slot_logs + (size_t)s * BSIM_SWEEP_BLOCK;
	}
	for (int q = 0; q < n_pairs; q++)
		sh->t_separate[q] = d->slot_t_separate + (size_t)q * BSIM_SWEEP_BLOCK;
	sh->from_journal = d->from_journal;
	return BSIM_OK;
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

/* What is known before the first block: the journal read (whole: into the
 * trials' places; streamed: into the spill file), a part's progress. */
static int drive_before(drive_state *d, bsim_error *err)
{
	sweep_shared *sh = &d->sh;
	const bsim_sweep_config *cfg = sh->cfg;
	if (d->kind == SWEEP_WHOLE && cfg->journal) {
		long kept = 0, cut = 0;
		return bsim_journal_replay(cfg->journal, journal_take, sh, &kept, &cut, err);
	}
	if (d->kind == SWEEP_STREAMED && cfg->journal)
		return stream_replay(sh, err);
	if (d->kind == SWEEP_PART) {
		/* Progress: this part's trials, or with collect every part's. */
		const bsim_sweep_part *part = sh->part;
		for (long i = 0; i < sh->total; i++) {
			long j = cfg->journal_first + i;
			int done = part->done && (part->done[j / 8] & (1u << (j % 8)));
			if (part->collect)
				sh->done += done;
			else
				sh->progress_total += !part_skips(part, cfg->journal_first, i);
		}
		if (part->collect)
			sh->progress_total = sh->total;
	}
	return BSIM_OK;
}

/* Block [sh->first, sh->end)'s journaled trials into their slots. */
static int stream_load(sweep_shared *sh, bsim_error *err)
{
	size_t size = sh->record_lattice ? sh->record_size : sizeof(bsim_trial_result);
	void *rec = sh->record_lattice ? malloc(size) : NULL;
	if (sh->record_lattice && !rec)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	int rc = BSIM_OK;
	for (long i = sh->first; rc == BSIM_OK && sh->journaled && i < sh->end; i++) {
		if (!(sh->journaled[i / 8] & (1u << (i % 8))))
			continue;
		long k = i - sh->first;
		if (pread(sh->spill_fd, rec ? rec : (void *)&sh->results[0][k], size,
		          (off_t)((size_t)i * size)) != (ssize_t)size) {
			rc = bsim_error_set(err, BSIM_EFAIL,
			                    "cannot read back the journal's trial %ld (%s)", i,
			                    strerror(errno));
			break;
		}
		/* a lattice's path too long for its record: the trial runs again */
		int got = rec ? bsim_sweep_record_unpack(rec, &sh->results[0][k], &sh->logs[0][k])
		              : 1;
		if (got < 0)
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
		sh->from_journal[k] = got > 0;
	}
	free(rec);
	return rc;
}

/* A streamed block before it runs: its slots emptied, then those the
 * journal holds filled. */
static int drive_block_load(drive_state *d, bsim_error *err)
{
	if (d->kind != SWEEP_STREAMED)
		return BSIM_OK;
	memset(d->slots, 0, BSIM_SWEEP_BLOCK * sizeof *d->slots);
	memset(d->from_journal, 0, BSIM_SWEEP_BLOCK);
	return stream_load(&d->sh, err);
}

/* A finished streamed block: copies filled in, counted, handed to the
 * sink. */
static int drive_block_done(drive_state *d, bsim_error *err)
{
	if (d->kind != SWEEP_STREAMED)
		return BSIM_OK;
	const sweep_shared *sh = &d->sh;
	bsim_sweep_result *out = d->out;
	bsim_trial_result *results = d->slots;
	bsim_trial_log *logs = d->slot_logs;
	int trials = sh->e->trials;
	for (long i = sh->first; i < sh->end; i++) {
		long k = i - sh->first;
		int g = (int)(i / trials), t = (int)(i % trials);
		if (sh->deterministic[g] && t == 0) {
			d->det_first[g] = results[k];
			if (bsim_trial_log_copy(&d->det_log[g], &logs[k]) != BSIM_OK)
				return bsim_error_set(err, BSIM_EFAIL, "out of memory");
		} else if (sh->deterministic[g]) {
			results[k] = d->det_first[g];
			if (bsim_trial_log_copy(&logs[k], &d->det_log[g]) != BSIM_OK)
				return bsim_error_set(err, BSIM_EFAIL, "out of memory");
		}
		group_add(&out->groups[g], &results[k]);
		if (results[k].outcome == BSIM_UNSTABLE && out->first_unstable < 0) {
			out->first_unstable = i;
			out->first_unstable_result = results[k];
		}
	}
	/* A lattice group's summary grows by the block's run of its trials. */
	for (long i = sh->first; out->lattice_summaries && i < sh->end;) {
		int g = (int)(i / trials);
		long end = (long)(g + 1) * trials < sh->end ? (long)(g + 1) * trials : sh->end;
		long k = i - sh->first;
		if (bsim_lattice_summary_add(&out->lattice_summaries[g], &results[k], &logs[k],
		                             (int)(end - i)) != BSIM_OK)
			return bsim_error_set(err, BSIM_EFAIL, "out of memory");
		i = end;
	}
	bsim_sweep_block b = {sh->first, sh->end - sh->first, results, logs};
	return sh->cfg->sink(sh->cfg->sink_user, &b, err);
}

/* After the last block: a whole sweep's deterministic copies, counts and
 * totals; a streamed sweep's groups closed and totals; a part's records
 * from the others collected. */
static int drive_after(drive_state *d, double t0, bsim_error *err)
{
	sweep_shared *sh = &d->sh;
	const bsim_experiment *e = sh->e;
	const bsim_sweep_config *cfg = sh->cfg;
	int rc = BSIM_OK;
	if (d->kind == SWEEP_WHOLE) {
		for (int s = 0; rc == BSIM_OK && s < sh->n_sides; s++)
			if (deterministic_fill(d->out[s].trials_out, d->out[s].logs,
			                       d->deterministic, e->n_groups, e->trials))
				rc = bsim_error_set(err, BSIM_EFAIL,
				                    "out of memory for the gate paths");
		for (int q = 0; rc == BSIM_OK && q < bsim_sweep_pairs(sh->n_sides); q++)
			separation_fill(sh->t_separate[q], d->deterministic, e->n_groups,
			                e->trials);
		for (int s = 0; rc == BSIM_OK && s < sh->n_sides; s++)
			rc = kept_fill(&d->out[s], d->deterministic, err);
	} else if (d->kind == SWEEP_STREAMED) {
		rc = kept_fill(d->out, d->deterministic, err);
	} else if (sh->part->collect) {
		rc = sh->part->collect(sh->part->user, 1, part_accept, sh, err);
	}
	if (rc != BSIM_OK)
		return rc;
	/* The final count may have been reached on another thread. */
	long all = sh->progress_total ? sh->progress_total : sh->total;
	if (cfg->progress)
		cfg->progress(cfg->progress_user, all, all);
	double wall = bsim_clock_seconds() - t0;
	if (d->kind == SWEEP_WHOLE)
		for (int s = 0; s < sh->n_sides; s++)
			result_finish(&d->out[s], d->deterministic, e->n_groups, e->trials, wall);
	if (d->kind == SWEEP_STREAMED) {
		for (int g = 0; g < e->n_groups; g++) {
			group_finish(&d->out->groups[g]);
			if (d->out->lattice_summaries)
				bsim_lattice_summary_end(&d->out->lattice_summaries[g]);
		}
		result_totals(d->out, d->deterministic, e->trials, d->det_first, 1, wall);
	}
	return BSIM_OK;
}

/* The one clean-up: what the drive holds; on failure (rc) the results
 * too. */
static void drive_free(drive_state *d, int rc)
{
	sweep_shared *sh = &d->sh;
	const bsim_experiment *e = sh->e;
	if (d->scenes)
		scenes_release(sh->cfg, d->scenes, e->n_groups);
	if (d->scenes_b)
		scenes_free(d->scenes_b, e->n_groups);
	for (size_t k = 0; d->slot_logs && k < (size_t)sh->n_sides * BSIM_SWEEP_BLOCK; k++)
		bsim_trial_log_clear(&d->slot_logs[k]);
	for (int g = 0; d->det_log && g < e->n_groups; g++)
		bsim_trial_log_clear(&d->det_log[g]);
	free(d->slots);
	free(d->slot_logs);
	free(d->slot_t_separate);
	free(d->from_journal);
	free(d->det_first);
	free(d->det_log);
	free(d->deterministic);
	if (sh->spill_fd >= 0)
		close(sh->spill_fd);
	free(sh->journaled);
	if (rc == BSIM_OK)
		return;
	for (int s = 0; d->out && s < (d->kind == SWEEP_WHOLE ? sh->n_sides : 1); s++)
		bsim_sweep_result_free(&d->out[s]);
	if (d->t_separate) {
		free(*d->t_separate);
		*d->t_separate = NULL;
	}
}

/* A sweep of kind: n_sides sides (1: a plain sweep, backend[0]), into out
 * and *t_separate (whole), out (streamed) or part's records (a part). */
static int sweep_drive(const bsim_experiment *e, const bsim_sweep_config *cfg, sweep_kind kind,
                       int n_sides, const bsim_backend *const *backend,
                       const bsim_options *const *opts, const bsim_sweep_part *part,
                       bsim_sweep_result *out, double **t_separate, bsim_error *err)
{
	const double t0 = bsim_clock_seconds();
	int keep = 0, rc = sweep_check(e, cfg, &keep, err);
	if (rc != BSIM_OK)
		return rc;
	if (part && (part->count < 1 || part->index < 0 || part->index >= part->count))
		return bsim_error_set(err, BSIM_EINPUT, "part %d of %d: expected 0 <= part < %d",
		                      part->index, part->count, part->count);
	const long total = (long)e->n_groups * e->trials;
	if (t_separate)
		*t_separate = NULL;
	drive_state d = {
	        .kind = kind,
	        .out = out,
	        .t_separate = bsim_sweep_pairs(n_sides) > 0 ? t_separate : NULL,
	        .sh = {.e = e,
	               .cfg = cfg,
	               .n_sides = n_sides,
	               .keep = kind == SWEEP_PART ? 0 : keep,
	               .keep_stride = cfg->keep_stride > 0 ? cfg->keep_stride : 5,
	               .total = total,
	               .spill_fd = -1,
	               .first_fail = total,
	               .part = part},
	};
	sweep_shared *sh = &d.sh;
	rc = drive_alloc(&d, sh->keep, err);
	if (rc == BSIM_OK)
		rc = scenes_for(e, cfg, n_sides, backend, opts, &d.scenes,
		                n_sides > 1 ? &d.scenes_b : NULL, err);
	if (rc == BSIM_OK &&
	    !(d.deterministic = calloc((size_t)e->n_groups, sizeof *d.deterministic)))
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory for %d groups", e->n_groups);
	for (int g = 0; rc == BSIM_OK && g < e->n_groups; g++)
		d.deterministic[g] = !bsim_effects_random(&d.scenes[g]);
	if (rc == BSIM_OK) {
		sh->deterministic = d.deterministic;
		for (int s = 0; s < n_sides; s++) {
			sh->scenes[s] = s == 1 && d.scenes_b ? d.scenes_b : d.scenes;
			sh->backend[s] = backend[s];
			sh->opts[s] = opts[s];
		}
		sh->lattice = d.scenes[0].has_lattice;
		sh->record_lattice = record_lattice(d.scenes, cfg);
		sh->record_size = record_bytes(sh->record_lattice, n_sides);
	}
	for (int s = 0; rc == BSIM_OK && kind != SWEEP_PART && s < n_sides; s++) {
		out[s].lattice = sh->scenes[s][0].has_lattice;
		out[s].lattice_def = sh->scenes[s][0].lattice;
		groups_rotate(&out[s], sh->scenes[s]);
	}
	/* a streamed lattice sweep's summaries grow block by block */
	if (rc == BSIM_OK && kind == SWEEP_STREAMED && out->lattice) {
		out->lattice_summaries =
		        calloc((size_t)e->n_groups, sizeof *out->lattice_summaries);
		for (int g = 0; out->lattice_summaries && g < e->n_groups && rc == BSIM_OK; g++)
			rc = bsim_lattice_summary_begin(&out->lattice_summaries[g],
			                                out->lattice_def.rows);
		if (!out->lattice_summaries || rc != BSIM_OK)
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory for %d groups",
			                    e->n_groups);
	}
	if (rc == BSIM_OK)
		rc = drive_before(&d, err);
	const long block = kind == SWEEP_WHOLE ? total : BSIM_SWEEP_BLOCK;
	const int threads = cfg->threads > 0 ? cfg->threads : omp_get_max_threads();
	for (long first = 0; rc == BSIM_OK && first < total; first += block) {
		sh->first = first;
		sh->end = total - first < block ? total : first + block;
		if ((rc = drive_block_load(&d, err)) != BSIM_OK)
			break;
		const long n = sh->end - sh->first;
		bsim_error_clear(&sh->fail);
#pragma omp parallel num_threads(threads < n ? threads : (int)n)
		sweep_thread(sh);
		if (sh->first_fail < total)
			rc = bsim_error_set(err, sh->fail.code, "%s", sh->fail.msg);
		else if (sh->stopped)
			rc = bsim_error_set(err, BSIM_ESTOPPED, "stopped after %ld of %ld trials",
			                    sh->done,
			                    sh->progress_total ? sh->progress_total : total);
		else
			rc = drive_block_done(&d, err);
	}
	if (rc == BSIM_OK)
		rc = drive_after(&d, t0, err);
	drive_free(&d, rc);
	return rc;
}

int bsim_sweep_run(const bsim_experiment *e, const bsim_sweep_config *cfg, bsim_sweep_result *out,
                   bsim_error *err)
{
	return sweep_drive(e, cfg, cfg->sink ? SWEEP_STREAMED : SWEEP_WHOLE, 1, &cfg->backend,
	                   &cfg->opts, NULL, out, NULL, err);
}

static int sides_check(int n_sides, bsim_error *err)
{
	if (n_sides < 2 || n_sides > BSIM_SWEEP_SIDES_MAX)
		return bsim_error_set(err, BSIM_EINPUT, "%d sides: expected 2 to %d", n_sides,
		                      BSIM_SWEEP_SIDES_MAX);
	return BSIM_OK;
}

int bsim_sweep_run_sides(const bsim_experiment *e, const bsim_sweep_config *cfg, int n_sides,
                         const bsim_backend *const *backend, const bsim_options *const *opts,
                         bsim_sweep_result *out, double **t_separate, bsim_error *err)
{
	int rc = sides_check(n_sides, err);
	return rc != BSIM_OK ? rc
	                     : sweep_drive(e, cfg, SWEEP_WHOLE, n_sides, backend, opts, NULL, out,
	                                   t_separate, err);
}

int bsim_sweep_run_paired(const bsim_experiment *e, const bsim_sweep_config *cfg,
                          const bsim_backend *backend_b, const bsim_options *opts_b,
                          bsim_sweep_result *out_a, bsim_sweep_result *out_b, double **t_separate,
                          bsim_error *err)
{
	const bsim_backend *backend[2] = {cfg->backend, backend_b};
	const bsim_options *opts[2] = {cfg->opts, opts_b};
	bsim_sweep_result out[2];
	int rc = sweep_drive(e, cfg, SWEEP_WHOLE, 2, backend, opts, NULL, out, t_separate, err);
	if (rc == BSIM_OK) {
		*out_a = out[0];
		*out_b = out[1];
	}
	return rc;
}

/* Whether the sweep's records are lattice records (record_lattice): from
 * group 0's scene, built alone (record_lattice reads no other). */
static int records_lattice(const bsim_experiment *e, const bsim_sweep_config *cfg, int *lattice,
                           bsim_error *err)
{
	int n_ov;
	bsim_override *ov = side_overrides(cfg, 0, &n_ov);
	if (!ov)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	bsim_scene s;
	int rc = bsim_experiment_group_scene(e, 0, ov, n_ov, &s, err);
	free(ov);
	if (rc != BSIM_OK)
		return rc;
	*lattice = record_lattice(&s, cfg);
	bsim_scene_free(&s);
	return BSIM_OK;
}

int bsim_sweep_record_size_for(const bsim_experiment *e, const bsim_sweep_config *cfg, size_t *size,
                               bsim_error *err)
{
	int lattice;
	int rc = records_lattice(e, cfg, &lattice, err);
	if (rc == BSIM_OK)
		*size = record_bytes(lattice, 1);
	return rc;
}

int bsim_sweep_plan_for(const bsim_experiment *e, const bsim_sweep_config *cfg, int n_sides,
                        size_t *size, bsim_scene **scenes, bsim_error *err)
{
	int rc = n_sides == 1 ? BSIM_OK : sides_check(n_sides, err);
	if (rc == BSIM_OK)
		rc = scenes_build(e, cfg, 0, scenes, err);
	if (rc != BSIM_OK)
		return rc;
	*size = record_bytes(record_lattice(*scenes, cfg), n_sides);
	if (cfg->planned)
		cfg->planned(cfg->planned_user, plan_beam_steps(e, *scenes));
	return BSIM_OK;
}

void bsim_sweep_scenes_free(bsim_scene *scenes, int n_groups)
{
	if (scenes)
		scenes_free(scenes, n_groups);
}

int bsim_sweep_record_size_sides_for(const bsim_experiment *e, const bsim_sweep_config *cfg,
                                     int n_sides, size_t *size, bsim_error *err)
{
	int lattice;
	int rc = sides_check(n_sides, err);
	if (rc == BSIM_OK)
		rc = records_lattice(e, cfg, &lattice, err);
	if (rc == BSIM_OK)
		*size = record_bytes(lattice, n_sides);
	return rc;
}

int bsim_sweep_record_size_paired_for(const bsim_experiment *e, const bsim_sweep_config *cfg,
                                      size_t *size, bsim_error *err)
{
	return bsim_sweep_record_size_sides_for(e, cfg, 2, size, err);
}

int bsim_sweep_run_part(const bsim_experiment *e, const bsim_sweep_config *cfg,
                        const bsim_sweep_part *part, bsim_error *err)
{
	return sweep_drive(e, cfg, SWEEP_PART, 1, &cfg->backend, &cfg->opts, part, NULL, NULL, err);
}

int bsim_sweep_run_part_sides(const bsim_experiment *e, const bsim_sweep_config *cfg, int n_sides,
                              const bsim_backend *const *backend, const bsim_options *const *opts,
                              const bsim_sweep_part *part, bsim_error *err)
{
	int rc = sides_check(n_sides, err);
	return rc != BSIM_OK ? rc
	                     : sweep_drive(e, cfg, SWEEP_PART, n_sides, backend, opts, part, NULL,
	                                   NULL, err);
}

int bsim_sweep_run_part_paired(const bsim_experiment *e, const bsim_sweep_config *cfg,
                               const bsim_backend *backend_b, const bsim_options *opts_b,
                               const bsim_sweep_part *part, bsim_error *err)
{
	const bsim_backend *backend[2] = {cfg->backend, backend_b};
	const bsim_options *opts[2] = {cfg->opts, opts_b};
	return sweep_drive(e, cfg, SWEEP_PART, 2, backend, opts, part, NULL, NULL, err);
}
