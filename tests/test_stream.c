/* A streamed sweep (bsim_sweep_config.sink) against the same sweep held in
 * memory: the trials handed to the sink, block by block, are the in-memory
 * sweep's trials, in index order, none missing or repeated; the groups'
 * counts are the same; a deterministic group whose copies span a block
 * boundary is filled in across it; a sweep stopped half-way and resumed
 * from its journal streams the same trials; a sink that fails stops the
 * sweep with its error. The experiment has more trials than one block
 * (BSIM_SWEEP_BLOCK), so the block boundaries are crossed. A lattice's
 * summaries built block by block equal those of all its trials at once. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/beamsim.h"
#include "util/journal.h"
#include "support.h"

/* Group 0 draws random forces; group 1 has none, so it is deterministic,
 * and its trials (35,000 .. 69,999) straddle the block boundary at 65,536.
 * Trials of 20 steps keep the 70,000 of them quick. */
#define TRIALS 35000

static bsim_experiment exp_;
static bsim_sweep_result whole; /* the sweep in memory: the reference */

static int setup(void **state)
{
	(void)state;
	char text[1024];
	snprintf(text, sizeof text,
	         "scene: %s\ntrials: %d\nseed: 5\nset:\n  integration.max_steps: 20\n"
	         "grid:\n  effects.random_force.magnitude: [30, 0]\n",
	         bsim_test_src("configs/thesis/gate.yaml"), TRIALS);
	const char *path = bsim_test_write(bsim_test_dir("stream"), "exp.yaml", text);
	bsim_error err;
	bsim_limits l = bsim_limits_default();
	l.trials = 1e6;
	bsim_limits_set(&l);
	if (bsim_experiment_load(path, NULL, 0, &exp_, &err) != BSIM_OK)
		fail_msg("%s", err.msg);
	bsim_sweep_config cfg = bsim_sweep_config_default();
	if (bsim_sweep_run(&exp_, &cfg, &whole, &err) != BSIM_OK)
		fail_msg("%s", err.msg);
	return 0;
}

static int teardown(void **state)
{
	(void)state;
	bsim_sweep_result_free(&whole);
	bsim_experiment_free(&exp_);
	bsim_limits_set(NULL);
	return 0;
}

/* What a sink saw: the next index it expects, and any disagreement. */
typedef struct seen {
	long next;
	long blocks;
	long differ; /* trials not identical to the in-memory sweep's */
	long paths;  /* trials whose gate path is not the in-memory one */
	int fail_at; /* > 0: fail on this block (1-based) */
} seen;

static int take(void *user, const bsim_sweep_block *b, bsim_error *err)
{
	seen *s = user;
	s->blocks++;
	if (s->fail_at == s->blocks)
		return bsim_error_set(err, BSIM_EFAIL, "the disk is full (a test)");
	assert_int_equal(b->first, s->next);
	assert_true(b->n > 0 && b->n <= BSIM_SWEEP_BLOCK);
	for (long k = 0; k < b->n; k++) {
		const bsim_trial_result *x = &whole.trials_out[b->first + k];
		const bsim_trial_log *lx = &whole.logs[b->first + k];
		s->differ += !bsim_compare_identical(&b->results[k], x,
		                                     BSIM_COMPARE_LEDGER | BSIM_COMPARE_TURN) ||
		             b->results[k].steps_run != x->steps_run ||
		             b->results[k].draws != x->draws;
		s->paths += b->logs[k].n_entries != lx->n_entries;
	}
	s->next += b->n;
	return BSIM_OK;
}

static void groups_equal(const bsim_sweep_result *r)
{
	for (int g = 0; g < exp_.n_groups; g++) {
		const bsim_group_result *a = &r->groups[g], *b = &whole.groups[g];
		assert_int_equal(a->trials, b->trials);
		assert_int_equal(a->traversed, b->traversed);
		assert_int_equal(a->side_exit, b->side_exit);
		assert_int_equal(a->stuck, b->stuck);
		assert_int_equal(a->unstable, b->unstable);
		assert_int_equal(a->left, b->left);
		assert_int_equal(a->stuck_in_contact, b->stuck_in_contact);
		assert_int_equal(a->deterministic, b->deterministic);
		assert_int_equal(a->steps, b->steps);
		assert_true(a->p_traverse == b->p_traverse);
		assert_true(a->ci95[0] == b->ci95[0] && a->ci95[1] == b->ci95[1]);
	}
	assert_int_equal(r->total_steps, whole.total_steps);
	assert_int_equal(r->trials_run, whole.trials_run);
}

static void streams_the_same_trials(void **state)
{
	(void)state;
	assert_true(whole.groups[1].deterministic && !whole.groups[0].deterministic);
	assert_true((long)exp_.n_groups * TRIALS > BSIM_SWEEP_BLOCK);
	seen s = {0};
	bsim_sweep_config cfg = bsim_sweep_config_default();
	cfg.sink = take;
	cfg.sink_user = &s;
	cfg.threads = 2;
	bsim_sweep_result r;
	bsim_error err;
	assert_int_equal(bsim_sweep_run(&exp_, &cfg, &r, &err), BSIM_OK);
	assert_int_equal(s.next, (long)exp_.n_groups * TRIALS);
	assert_int_equal(s.blocks, 2);
	assert_int_equal(s.differ, 0);
	assert_int_equal(s.paths, 0);
	assert_null(r.trials_out);
	assert_null(r.logs);
	groups_equal(&r);
	bsim_sweep_result_free(&r);
}

/* Stops the sweep once `after` trials are done (the progress callback
 * runs on the leading thread as trials end). */
typedef struct stopper {
	volatile sig_atomic_t flag;
	long after;
} stopper;

static void stop_after(void *user, long done, long total)
{
	(void)total;
	stopper *st = user;
	if (done >= st->after)
		st->flag = 1;
}

static void resumed_from_the_journal(void **state)
{
	(void)state;
	char path[1200];
	snprintf(path, sizeof path, "%s/journal", bsim_test_dir("stream_resume"));
	size_t size = bsim_sweep_record_size(0);
	bsim_journal *j;
	bsim_error err;
	assert_int_equal(bsim_journal_create(&j, path, bsim_trial_record_fields(), "stream test\n",
	                                     size, &err),
	                 BSIM_OK);
	long cut = 0, kept = 0;
	assert_int_equal(bsim_journal_replay(j, NULL, NULL, &kept, &cut, &err), BSIM_OK);

	/* First run: stopped past the first block, so the journal holds
	 * trials of both blocks. One thread: the progress callback (on the
	 * leading thread) sees every trial end, so the stop comes at the same
	 * trial however busy the machine is. */
	seen s1 = {0};
	stopper st = {0, BSIM_SWEEP_BLOCK + 100};
	bsim_sweep_config cfg = bsim_sweep_config_default();
	cfg.sink = take;
	cfg.sink_user = &s1;
	cfg.journal = j;
	cfg.threads = 1;
	cfg.stop = &st.flag;
	cfg.progress = stop_after;
	cfg.progress_user = &st;
	bsim_sweep_result r;
	assert_int_equal(bsim_sweep_run(&exp_, &cfg, &r, &err), BSIM_ESTOPPED);
	assert_int_equal(s1.differ, 0);
	assert_int_equal(bsim_journal_close(j, &err), BSIM_OK);

	/* Resumed: every trial streamed once, the same as in memory. */
	assert_int_equal(bsim_journal_resume(&j, path, bsim_trial_record_fields(), "stream test\n",
	                                     size, &err),
	                 BSIM_OK);
	seen s2 = {0};
	cfg = bsim_sweep_config_default();
	cfg.sink = take;
	cfg.sink_user = &s2;
	cfg.journal = j;
	assert_int_equal(bsim_sweep_run(&exp_, &cfg, &r, &err), BSIM_OK);
	assert_int_equal(bsim_journal_close(j, &err), BSIM_OK);
	assert_int_equal(s2.next, (long)exp_.n_groups * TRIALS);
	assert_int_equal(s2.differ, 0);
	groups_equal(&r);
	bsim_sweep_result_free(&r);
}

static void failing_sink_stops_the_sweep(void **state)
{
	(void)state;
	seen s = {.fail_at = 1};
	bsim_sweep_config cfg = bsim_sweep_config_default();
	cfg.sink = take;
	cfg.sink_user = &s;
	bsim_sweep_result r;
	bsim_error err;
	assert_int_equal(bsim_sweep_run(&exp_, &cfg, &r, &err), BSIM_EFAIL);
	assert_non_null(strstr(err.msg, "the disk is full"));
	assert_int_equal(s.blocks, 1); /* nothing after the failed block ran */
}

/* A lattice group's summary built block by block (a streamed lattice
 * sweep) against the same trials summarised at once: the same locations,
 * transitions and counts, and the same times per row to the bit, however
 * the trials are split. */
static void lattice_summary_in_blocks(void **state)
{
	(void)state;
	char text[1024];
	snprintf(text, sizeof text,
	         "scene: %s\ntrials: 300\nseed: 9\nset:\n  integration.max_steps: 2000\n"
	         "grid:\n  effects.random_force.magnitude: [30]\n",
	         bsim_test_src("configs/lattice/uniform_9x9.yaml"));
	const char *path = bsim_test_write(bsim_test_dir("stream_lattice"), "exp.yaml", text);
	bsim_experiment e;
	bsim_error err;
	if (bsim_experiment_load(path, NULL, 0, &e, &err) != BSIM_OK)
		fail_msg("%s", err.msg);
	bsim_sweep_config cfg = bsim_sweep_config_default();
	bsim_sweep_result r;
	assert_int_equal(bsim_sweep_run(&e, &cfg, &r, &err), BSIM_OK);
	assert_true(r.lattice);
	int n = r.trials, rows = r.lattice_def.rows;
	bsim_lattice_summary all;
	assert_int_equal(bsim_lattice_summarise(r.trials_out, r.logs, n, rows, &all), BSIM_OK);
	assert_true(all.n_transitions > 1 && all.n_locations > 1);
	static const int pieces[] = {1, 7, 64, 299};
	for (size_t p = 0; p < sizeof pieces / sizeof pieces[0]; p++) {
		bsim_lattice_summary s;
		assert_int_equal(bsim_lattice_summary_begin(&s, rows), BSIM_OK);
		for (int i = 0; i < n; i += pieces[p]) {
			int m = n - i < pieces[p] ? n - i : pieces[p];
			assert_int_equal(
			        bsim_lattice_summary_add(&s, &r.trials_out[i], &r.logs[i], m),
			        BSIM_OK);
		}
		bsim_lattice_summary_end(&s);
		assert_int_equal(s.trials, all.trials);
		assert_int_equal(s.n_locations, all.n_locations);
		for (int k = 0; k < s.n_locations; k++) {
			assert_true(bsim_lattice_location_equal(s.locations[k].loc,
			                                        all.locations[k].loc));
			assert_int_equal(s.locations[k].count, all.locations[k].count);
			assert_true(s.locations[k].p == all.locations[k].p);
			assert_true(s.locations[k].ci95[0] == all.locations[k].ci95[0]);
		}
		assert_int_equal(s.n_transitions, all.n_transitions);
		for (int k = 0; k < s.n_transitions; k++) {
			assert_memory_equal(s.transitions[k].from, all.transitions[k].from,
			                    sizeof s.transitions[k].from);
			assert_memory_equal(s.transitions[k].to, all.transitions[k].to,
			                    sizeof s.transitions[k].to);
			assert_int_equal(s.transitions[k].count, all.transitions[k].count);
		}
		for (int iy = 0; iy < rows; iy++) {
			assert_int_equal(s.row_trials[iy], all.row_trials[iy]);
			assert_true(s.row_time[iy] == all.row_time[iy]);
		}
		bsim_lattice_summary_free(&s);
	}
	bsim_lattice_summary_free(&all);
	bsim_sweep_result_free(&r);
	bsim_experiment_free(&e);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(streams_the_same_trials),
	        cmocka_unit_test(resumed_from_the_journal),
	        cmocka_unit_test(failing_sink_stops_the_sweep),
	        cmocka_unit_test(lattice_summary_in_blocks),
	};
	return cmocka_run_group_tests(tests, setup, teardown);
}
