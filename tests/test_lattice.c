/* The gate lattice (docs/model.md section 8) against independent truths:
 *   - its geometry is the essay's (Eq. 2.17, Fig. 2.8), loaded from the
 *     shipped configs;
 *   - the broad phase changes no bit of any result (against testing every
 *     beam every step), and the gates beyond the body's reach change no bit
 *     either (locality: the same trial in a 3 x 3 and a 33 x 33 field);
 *   - sleeping does not change the outcomes measurably (against the same
 *     trials without sleeping), on every backend, and what it removes is
 *     bounded by its threshold;
 *   - the essay's protocol on a field of one gate is the whole world (bit
 *     for bit, every backend), and on two rows it removes exactly the energy
 *     of the gate it leaves behind, with the ledger still closed;
 *   - the complementarity solve with more than two contacts satisfies the
 *     complementarity conditions, agrees with Gauss-Seidel iterated to
 *     convergence, and brings a body pressed into three beams to the static
 *     equilibrium sum_i k theta_i / s_i n_i = -F;
 *   - the paired permutation test equals McNemar's exact test when there are
 *     two locations, and the final-location summary counts a hand-built
 *     group correctly. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "beamsim/compare.h"
#include "beamsim/lattice.h"
#include "beamsim/schedule.h"
#include "beamsim/stats.h"
#include "beamsim/trial.h"
#include "beamsim/lattice_outcome.h"
#include "run/sweep_record.h"
#include "support.h"
#include "thesis/thesis.h"

static void load(const char *rel, const bsim_override *ov, int n, bsim_scene *s)
{
	bsim_error err;
	int rc = bsim_scene_load(rel[0] == '/' ? rel : bsim_test_src(rel), ov, n, s, &err);
	if (rc)
		fail_msg("%s", err.msg);
}

/* ---- geometry ------------------------------------------------------------ */

static void geometry_is_the_essays(void **state)
{
	(void)state;
	bsim_scene s;
	load("configs/lattice/uniform_9x9.yaml", NULL, 0, &s);
	const bsim_lattice_def *l = &s.lattice;
	assert_true(s.has_lattice);
	assert_int_equal(s.n_beams, 2 * 9 * 9);
	assert_int_equal(l->ix_min, -4);
	assert_int_equal(l->ix_max, 4);
	/* docs/model.md section 8: pivots at (50 ix -/+ 25, 60 iy + 30) */
	for (int iy = 0; iy < 9; iy++)
		for (int ix = -4; ix <= 4; ix++) {
			const bsim_beam_def *bl = &s.beams[bsim_lattice_beam(l, ix, iy, 0)];
			const bsim_beam_def *br = &s.beams[bsim_lattice_beam(l, ix, iy, 1)];
			assert_true(bl->pivot[0] == 50.0 * ix - 25 &&
			            bl->pivot[1] == 60.0 * iy + 30);
			assert_true(br->pivot[0] == 50.0 * ix + 25 &&
			            br->pivot[1] == 60.0 * iy + 30);
			assert_true(bl->rest_angle_deg == 0 && br->rest_angle_deg == 180);
			assert_true(bl->stiffness == 400 && br->damping == 50);
			int gx, gy, side;
			bsim_lattice_beam_gate(l, bsim_lattice_beam(l, ix, iy, 1), &gx, &gy, &side);
			assert_true(gx == ix && gy == iy && side == 1);
			/* neighbouring gates share pivots */
			if (ix > -4) {
				const bsim_beam_def *nb =
				        &s.beams[bsim_lattice_beam(l, ix - 1, iy, 1)];
				assert_true(nb->pivot[0] == bl->pivot[0] &&
				            nb->pivot[1] == bl->pivot[1]);
			}
		}
	/* the termination of the essay's run: Y = 540, |X| = 225 */
	assert_true(s.success_y == 540 && s.side_x == 225 && s.gate_steps == 3000);
	/* Eq. 2.17: X = x + 50 ix, Y = y + 60 iy, gates clamped into the field */
	const double pts[][2] = {{0, 0},      {24.9, 59.9}, {25, 60},
	                         {-25.1, 61}, {-300, -5},   {300, 600}};
	const int want[][2] = {{0, 0}, {0, 0}, {1, 1}, {-1, 1}, {-4, 0}, {4, 8}};
	for (int k = 0; k < 6; k++) {
		int ix, iy;
		bsim_lattice_gate_at(&s, pts[k], &ix, &iy);
		assert_int_equal(ix, want[k][0]);
		assert_int_equal(iy, want[k][1]);
	}
	bsim_scene_free(&s);
}

/* The C-track's map from its CSV: the soft gates of the drawing in
 * configs/lattice/c_track.yaml, both beams of each. */
static void c_track_map_from_csv(void **state)
{
	(void)state;
	bsim_scene s;
	load("configs/lattice/c_track.yaml", NULL, 0, &s);
	static const int soft[][2] = {{-2, 0}, {-1, 0}, {0, 0},  {-3, 1}, {-2, 1}, {-3, 2},
	                              {-3, 3}, {-3, 4}, {-3, 5}, {-3, 6}, {-3, 7}, {-2, 7},
	                              {-2, 8}, {-1, 8}, {0, 8},  {1, 8}};
	int n_soft = 0;
	for (int iy = 0; iy < 9; iy++)
		for (int ix = -4; ix <= 4; ix++) {
			int is_soft = 0;
			for (size_t k = 0; k < sizeof soft / sizeof soft[0]; k++)
				is_soft |= soft[k][0] == ix && soft[k][1] == iy;
			for (int side = 0; side < 2; side++) {
				double k = s.beams[bsim_lattice_beam(&s.lattice, ix, iy, side)]
				                   .stiffness;
				assert_true(k == (is_soft ? 100.0 : 400.0));
			}
			n_soft += is_soft;
		}
	assert_int_equal(n_soft, 16);
	assert_string_equal(s.lattice.stiffness_file, "c_track.csv");
	bsim_scene_free(&s);
}

/* ---- trials ---------------------------------------------------------- */

typedef struct run_out {
	bsim_trial_result r;
	bsim_trial_log *log;
} run_out;

static void run(const bsim_scene *s, const bsim_backend *b, const char *opt, uint64_t trial,
                run_out *o)
{
	bsim_options opts = {0};
	bsim_error err;
	if (opt)
		assert_int_equal(bsim_options_add(&opts, opt, &err), BSIM_OK);
	bsim_trial_runner *runner = bsim_trial_runner_alloc();
	o->log = bsim_trial_log_alloc();
	bsim_recorder rec = {.stride = 1, .log = o->log};
	int rc = bsim_trial_run(runner, s, b, &opts, bsim_schedule_seed_mix(1, 0, trial), &rec,
	                        &o->r, &err);
	if (rc)
		fail_msg("%s", err.msg);
	bsim_trial_runner_free(runner);
}

static void run_free(run_out *o)
{
	bsim_trial_log_free(o->log);
}

static int same_trial(const run_out *a, const run_out *b)
{
	const bsim_trial_result *x = &a->r, *y = &b->r;
	if (x->outcome != y->outcome || x->steps_run != y->steps_run || x->x_end != y->x_end ||
	    x->y_end != y->y_end || x->vx_end != y->vx_end || x->final_ix != y->final_ix ||
	    x->final_iy != y->final_iy || x->ledger.damper != y->ledger.damper ||
	    x->ledger.impact != y->ledger.impact || a->log->n_entries != b->log->n_entries)
		return 0;
	for (int k = 0; k < a->log->n_entries; k++)
		if (memcmp(&a->log->entries[k], &b->log->entries[k], sizeof a->log->entries[k]))
			return 0;
	if (a->log->n_peaks != b->log->n_peaks)
		return 0;
	for (int k = 0; k < a->log->n_peaks; k++)
		if (a->log->peaks[k].beam != b->log->peaks[k].beam ||
		    memcmp(&a->log->peaks[k].peak, &b->log->peaks[k].peak, sizeof(double)))
			return 0;
	return 1;
}

/* The broad phase is exact: every beam tested every step gives the same
 * trials to the bit. */
static void broad_phase_is_exact(void **state)
{
	(void)state;
	bsim_scene s;
	load("configs/lattice/c_track.yaml", NULL, 0, &s);
	int contacts = 0;
	for (uint64_t t = 0; t < 12; t++) {
		run_out a, b;
		run(&s, bsim_test_backend("thesis"), NULL, t, &a);
		run(&s, bsim_test_backend("thesis"), "broad_phase=0", t, &b);
		assert_true(same_trial(&a, &b));
		contacts += a.r.ledger.impact > 0.0;
		run_free(&a);
		run_free(&b);
	}
	assert_true(contacts >= 10); /* the trials pushed beams */
	bsim_scene_free(&s);
}

/* Every beam's largest angle over a trial's states (its trace), rad. */
typedef struct dense_peaks {
	double *peak; /* every beam's */
} dense_peaks;

static void trace_peaks(void *user, long step, const bsim_state *s)
{
	(void)step;
	dense_peaks *d = user;
	for (int k = 0; k < s->n_active; k++) {
		int i = s->active[k];
		if (s->theta[i] > d->peak[i])
			d->peak[i] = s->theta[i];
	}
}

/* A trial's log keeps the peaks of the beams it moved only: against every
 * beam's largest angle taken from the trace of its states (every beam of
 * the field, the beams at rest at 0), the same beams in ascending order,
 * each to the bit. Its journal record (run/sweep_record.h) gives back the
 * same log, whatever the field's size; a log of more moved beams than a
 * record holds is marked to run again. */
static void peaks_of_moved_beams(void **state)
{
	(void)state;
	bsim_scene s;
	load("configs/lattice/c_track.yaml", NULL, 0, &s);
	int moved = 0;
	for (uint64_t t = 0; t < 3; t++) {
		dense_peaks d = {calloc((size_t)s.n_beams, sizeof(double))};
		assert_non_null(d.peak);
		bsim_trial_runner *runner = bsim_trial_runner_alloc();
		bsim_trial_log *log = bsim_trial_log_alloc();
		bsim_recorder rec = {
		        .stride = 1, .log = log, .trace = trace_peaks, .trace_user = &d};
		bsim_trial_result r;
		bsim_error err;
		bsim_options opts = {0};
		if (bsim_trial_run(runner, &s, bsim_test_backend("thesis"), &opts,
		                   bsim_schedule_seed_mix(1, 0, t), &rec, &r, &err))
			fail_msg("%s", err.msg);
		assert_int_equal(log->n_beams, s.n_beams);
		int k = 0;
		for (int i = 0; i < s.n_beams; i++) {
			if (d.peak[i] == 0.0)
				continue;
			assert_true(k < log->n_peaks);
			assert_int_equal(log->peaks[k].beam, i);
			assert_memory_equal(&log->peaks[k].peak, &d.peak[i], sizeof(double));
			k++;
		}
		assert_int_equal(k, log->n_peaks);
		moved += k;

		unsigned char *buf = malloc(bsim_sweep_record_bytes());
		assert_non_null(buf);
		bsim_sweep_record_pack(buf, &r, log);
		bsim_trial_log *back = bsim_trial_log_alloc();
		bsim_trial_result rb;
		assert_int_equal(bsim_sweep_record_unpack(buf, &rb, back), 1);
		assert_memory_equal(&rb, &r, sizeof r);
		assert_int_equal(back->n_beams, log->n_beams);
		assert_int_equal(back->n_entries, log->n_entries);
		assert_int_equal(back->n_peaks, log->n_peaks);
		assert_memory_equal(back->peaks, log->peaks,
		                    (size_t)log->n_peaks * sizeof *log->peaks);

		/* one moved beam more than a record holds */
		bsim_beam_peak many[SWEEP_RECORD_PEAKS + 1];
		for (int q = 0; q <= SWEEP_RECORD_PEAKS; q++)
			many[q] = (bsim_beam_peak){q, 0.1};
		bsim_trial_log over = *log;
		over.peaks = many;
		over.n_peaks = SWEEP_RECORD_PEAKS + 1;
		bsim_sweep_record_pack(buf, &r, &over);
		assert_int_equal(bsim_sweep_record_unpack(buf, &rb, back), 0);

		free(buf);
		free(d.peak);
		bsim_trial_log_free(back);
		bsim_trial_log_free(log);
		bsim_trial_runner_free(runner);
	}
	assert_true(moved >= 6); /* the trials pushed beams */
	bsim_scene_free(&s);
}

/* Locality: a trial that stays in gate (0, 0) is the same in a 3 x 3 and a
 * 33 x 33 field, to the bit, with the same beams awake per step. */
static void far_gates_change_nothing(void **state)
{
	(void)state;
	bsim_scene small, big;
	bsim_lattice_scene_init(&small, 3, 3, 6.0, 30.0);
	bsim_lattice_scene_init(&big, 33, 33, 6.0, 30.0);
	bsim_scene *both[2] = {&small, &big};
	for (int k = 0; k < 2; k++) { /* end where the body leaves gate (0, 0) */
		both[k]->success_y = 60;
		both[k]->side_x = 25;
		both[k]->classify_y = 60;
	}
	for (uint64_t t = 0; t < 8; t++) {
		run_out a, b;
		run(&small, bsim_test_backend("thesis"), NULL, t, &a);
		run(&big, bsim_test_backend("thesis"), NULL, t, &b);
		assert_true(a.r.outcome == b.r.outcome && a.r.steps_run == b.r.steps_run);
		assert_true(a.r.x_end == b.r.x_end && a.r.y_end == b.r.y_end);
		assert_true(a.r.ledger.damper == b.r.ledger.damper);
		run_free(&a);
		run_free(&b);
	}
	bsim_scene_free(&small);
	bsim_scene_free(&big);
}

/* Sleeping against no sleeping, on the same schedules: the final-location
 * distributions must not differ (paired permutation test), nor traversal
 * (McNemar); what sleeping removed is bounded by its threshold per event. */
static void sleeping_keeps_outcomes(const bsim_backend *b, const char *scene, int trials)
{
	bsim_scene s;
	/* 24 s of trial: the beams the body pushed first have long decayed */
	const bsim_override ov[] = {{"integration.max_steps", "6000", "test"}};
	load(scene, ov, 1, &s);
	bsim_trial_result *on = calloc((size_t)trials, sizeof *on);
	bsim_trial_result *off = calloc((size_t)trials, sizeof *off);
	int changed = 0;
	double slept = 0.0;
	for (int t = 0; t < trials; t++) {
		run_out a, c;
		run(&s, b, "sleep=on", (uint64_t)t, &a);
		run(&s, b, "sleep=off", (uint64_t)t, &c);
		on[t] = a.r;
		off[t] = c.r;
		changed += !bsim_lattice_location_equal(bsim_lattice_location_of(&a.r),
		                                        bsim_lattice_location_of(&c.r));
		slept += a.r.ledger.sleep;
		assert_true(c.r.ledger.sleep == 0.0);
		run_free(&a);
		run_free(&c);
	}
	bsim_location_test lt;
	bsim_compare_location_test(on, off, trials, 7, &lt);
	int b_only = 0, c_only = 0;
	for (int t = 0; t < trials; t++) {
		b_only += on[t].outcome == BSIM_TRAVERSED && off[t].outcome != BSIM_TRAVERSED;
		c_only += on[t].outcome != BSIM_TRAVERSED && off[t].outcome == BSIM_TRAVERSED;
	}
	double p_mcnemar = bsim_stats_mcnemar_exact(b_only, c_only);
	print_message("%s: sleeping changed the final location of %d of %d trials; permutation "
	              "p = %.3g, traversal McNemar p = %.3g (%d / %d); energy put to rest %.3g J "
	              "per trial\n",
	              b->name, changed, trials, lt.p_value, p_mcnemar, b_only, c_only,
	              slept / trials);
	assert_true(lt.p_value > 0.01);
	assert_true(p_mcnemar > 0.01);
	assert_true(changed < trials / 4);
	/* thesis: each sleep removes less than sleep_energy (1e-6 J) */
	if (b == bsim_test_backend("thesis"))
		assert_true(slept / trials < 1e-3);
	free(on);
	free(off);
	bsim_scene_free(&s);
}

static void sleeping_thesis(void **state)
{
	(void)state;
	sleeping_keeps_outcomes(bsim_test_backend("thesis"), "configs/lattice/c_track.yaml", 80);
}

/* Box2D and Chipmunk without sleeping integrate every beam of the field
 * every step: a 3 x 3 field keeps the test short. Chipmunk's beams only
 * start asleep (a woken one stays awake), which changes the order its
 * solver meets simultaneous contacts in, nothing else. */
static void sleeping_on_3x3(const bsim_backend *b)
{
	const char *dir = bsim_test_dir("lattice_sleep_3x3");
	const char *path =
	        bsim_test_write(dir, "lattice3.yaml",
	                        "body: { mass: 1, radius: 10 }\n"
	                        "lattice:\n"
	                        "  columns: 3\n"
	                        "  rows: 3\n"
	                        "  beam: { length: 25, mass: 0.1, stiffness: 400, damping: 50 }\n"
	                        "effects:\n"
	                        "  propulsion: { force: 6 }\n"
	                        "  random_force: { magnitude: 30 }\n");
	char abs_path[1200];
	snprintf(abs_path, sizeof abs_path, "%s", path);
	bsim_scene s;
	bsim_error err;
	assert_int_equal(bsim_scene_load(abs_path, NULL, 0, &s, &err), BSIM_OK);
	bsim_scene_free(&s);
	sleeping_keeps_outcomes(b, abs_path, 16);
}

/* Every other backend of the registry that has the knob sleep, on the
 * 3 x 3 field. */
static void sleeping_others(void **state)
{
	(void)state;
	for (const bsim_backend *const *be = bsim_backend_list(); *be; be++) {
		int sleeps = 0;
		for (int i = 0; i < (*be)->n_knobs; i++)
			sleeps |= strcmp((*be)->knobs[i].name, "sleep") == 0;
		if (sleeps && *be != bsim_test_backend("thesis"))
			sleeping_on_3x3(*be);
	}
}

/* The essay's protocol on one gate: its world is the whole world, on
 * every backend of the registry (with sleeping off where it has the knob). */
static void essay_is_world_on_one_gate(void **state)
{
	(void)state;
	for (const bsim_backend *const *be = bsim_backend_list(); *be; be++) {
		const char *opts = NULL;
		for (int i = 0; i < (*be)->n_knobs; i++)
			if (strcmp((*be)->knobs[i].name, "sleep") == 0)
				opts = "sleep=off";
		for (uint64_t t = 0; t < 4; t++) {
			bsim_scene w, e;
			bsim_lattice_scene_init(&w, 1, 1, 6.0, 30.0);
			bsim_lattice_scene_init(&e, 1, 1, 6.0, 30.0);
			e.lattice.protocol = BSIM_PROTOCOL_ESSAY;
			run_out a, b;
			run(&w, *be, opts, t, &a);
			run(&e, *be, opts, t, &b);
			assert_true(same_trial(&a, &b));
			assert_true(b.r.ledger.reset == 0.0);
			run_free(&a);
			run_free(&b);
			bsim_scene_free(&w);
			bsim_scene_free(&e);
		}
	}
}

/* Two rows, the body launched fast through row 0: entering row 1 the essay
 * protocol drops row 0's beams, still swinging, and books exactly their
 * energy as reset; the ledger stays closed. The whole world keeps them. */
typedef struct beam_watch {
	const bsim_scene *s;
	int entry_step;
	double e_at_entry; /* the world's beam energy after the entry step */
	double theta_row0; /* whole world: |theta| of row 0's left beam after entry */
} beam_watch;

static void watch(void *user, long step, const bsim_state *st)
{
	beam_watch *w = user;
	if (step != w->entry_step)
		return;
	double e = 0.0;
	for (int k = 0; k < st->n_active; k++) {
		int i = st->active[k];
		const bsim_beam_def *b = &w->s->beams[i]; /* row 0's beams are 0 and 1 */
		e += 0.5 * b->inertia * st->omega[i] * st->omega[i] +
		     0.5 * b->stiffness * st->theta[i] * st->theta[i];
	}
	w->e_at_entry = e;
	w->theta_row0 = fabs(st->theta[0]);
}

static void essay_resets_the_gate_left(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_lattice_scene_init(&s, 1, 2, 0.0, 0.0);
	for (int i = 0; i < s.n_beams; i++)
		s.beams[i].stiffness = 100.0;
	s.body.velocity[1] = 30.0; /* m/s: through row 0's beams at once */
	s.body.start[0] = 3.0;
	for (int protocol = 0; protocol < 2; protocol++) {
		s.lattice.protocol = protocol ? BSIM_PROTOCOL_ESSAY : BSIM_PROTOCOL_WORLD;
		/* the step of the entry into row 1, from a first run */
		run_out o;
		run(&s, bsim_test_backend("thesis"), "sleep=off", 0, &o);
		assert_true(o.log->n_entries >= 2);
		assert_int_equal(o.log->entries[1].iy, 1);
		beam_watch w = {&s, o.log->entries[1].step, 0.0, 0.0};
		bsim_trial_runner *runner = bsim_trial_runner_alloc();
		bsim_recorder rec = {.stride = 1, .trace = watch, .trace_user = &w};
		bsim_trial_result r;
		bsim_error err;
		assert_int_equal(bsim_trial_run(runner, &s, bsim_test_backend("thesis"), NULL,
		                                bsim_schedule_seed_mix(1, 0, 0), &rec, &r, &err),
		                 BSIM_OK);
		bsim_trial_runner_free(runner);
		assert_true(w.e_at_entry > 1.0); /* row 0's beams were swinging */
		assert_true(fabs(r.ledger.residual) < 1e-9);
		if (protocol) {
			print_message(
			        "essay: reset %.6g J, row 0's beams held %.6g J at the entry\n",
			        r.ledger.reset, w.e_at_entry);
			assert_true(fabs(r.ledger.reset - w.e_at_entry) < 1e-9 * w.e_at_entry);
		} else {
			assert_true(r.ledger.reset == 0.0);
			assert_true(w.theta_row0 > 0.0);
		}
		run_free(&o);
	}
	bsim_scene_free(&s);
}

/* ---- the complementarity solve with more than two contacts ------------- */

static double urand(unsigned *seed)
{
	*seed = *seed * 1103515245u + 12345u;
	return ((*seed >> 8) & 0xffffff) / 16777216.0;
}

/* Random problems of 3 to 8 contacts: P >= 0, w >= 0, P w = 0, and the
 * same solution as Gauss-Seidel iterated to convergence. */
static void lcp_many_contacts(void **state)
{
	(void)state;
	const double inv_mass = 1.0; /* 1/kg */
	unsigned seed = 11;
	thesis_contact cs[8], gs[8];
	int solved_with_impulse = 0;
	for (int trial = 0; trial < 300; trial++) {
		int n = 3 + trial % 6;
		for (int i = 0; i < n; i++) {
			double a = 6.283185307179586 * urand(&seed);
			memset(&cs[i], 0, sizeof cs[i]);
			cs[i].n[0] = cos(a);
			cs[i].n[1] = sin(a);
			cs[i].c = 25.0 * (urand(&seed) - 0.5);
			cs[i].inv_i = 1.0 / 20.83;
			cs[i].vrel = 4.0 * (urand(&seed) - 0.7);
			cs[i].bound = 0.0;
		}
		/* every 7th problem: two identical pivot-end contacts (c = 0, the
		 * same normal), which make K only semi-definite */
		if (trial % 7 == 0) {
			cs[1] = cs[0];
			cs[0].c = cs[1].c = 0.0;
		}
		memcpy(gs, cs, sizeof cs);
		assert_int_equal(bsim_thesis_lcp_solve(inv_mass, cs, n), 0); /* converged */
		double scale = 0.0;
		for (int i = 0; i < n; i++) {
			double wi = cs[i].vrel - cs[i].bound;
			for (int j = 0; j < n; j++) {
				double k = (cs[i].n[0] * cs[j].n[0] + cs[i].n[1] * cs[j].n[1]) *
				           inv_mass;
				if (i == j)
					k += cs[i].c * cs[i].c * cs[i].inv_i;
				wi += k * cs[j].impulse;
			}
			assert_true(cs[i].impulse >= 0.0);
			assert_true(wi >= -1e-9);
			assert_true(fabs(cs[i].impulse * wi) < 1e-9);
			scale = fmax(scale, cs[i].impulse);
		}
		solved_with_impulse += scale > 0.0;
		/* the body's velocity change is unique even where impulses are not */
		double j[2], jg[2];
		thesis_impulse_sum(cs, n, j);
		for (int i = 0; i < n; i++)
			gs[i].impulse = 0.0;
		/* projected Gauss-Seidel to convergence, the reference */
		for (int it = 0; it < 200000; it++) {
			double change = 0.0;
			for (int i = 0; i < n; i++) {
				double wi = gs[i].vrel - gs[i].bound, kii = 0.0;
				for (int k2 = 0; k2 < n; k2++) {
					double k = (gs[i].n[0] * gs[k2].n[0] +
					            gs[i].n[1] * gs[k2].n[1]) *
					           inv_mass;
					if (i == k2) {
						k += gs[i].c * gs[i].c * gs[i].inv_i;
						kii = k;
					}
					wi += k * gs[k2].impulse;
				}
				double p = fmax(0.0, gs[i].impulse - wi / kii);
				change = fmax(change, fabs(p - gs[i].impulse));
				gs[i].impulse = p;
			}
			if (change < 1e-15)
				break;
		}
		thesis_impulse_sum(gs, n, jg);
		assert_true(fabs(j[0] - jg[0]) < 1e-7 && fabs(j[1] - jg[1]) < 1e-7);
	}
	assert_true(solved_with_impulse > 150);
	assert_int_equal(bsim_thesis_lcp_fallbacks(), 0);
}

/* A body pushed up by F into three overlapping beams (a "ceiling" of three
 * springs) comes to rest touching all three, in static equilibrium: each
 * beam's spring torque k theta_i equals its contact force P_i times the
 * lever s_i, and the contact forces balance F: sum_i P_i n_i = -F. */
static void three_beams_static_equilibrium(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 0.0, 0.0);
	bsim_scene_set_beams(&s, 3);
	const double px[3] = {-20.0, 18.0, -6.0}, deg[3] = {0.0, 180.0, 0.0},
	             k[3] = {400, 600, 500};
	for (int i = 0; i < 3; i++) {
		bsim_beam_def *b = &s.beams[i];
		memset(b, 0, sizeof *b);
		b->pivot[0] = px[i];
		b->pivot[1] = 12.0;
		b->rest_angle_deg = deg[i];
		b->length = 25.0;
		b->mass = 0.1;
		b->inertia = 0.1 * 625.0 / 3.0;
		b->stiffness = k[i];
		b->damping = 400.0; /* heavily damped: the lateral mode settles */
	}
	s.effects.has_propulsion = 1;
	s.effects.propulsion_force = 40.0; /* N, up into the beams */
	s.body.start[0] = 0.0;
	s.body.start[1] = 0.0;
	s.max_steps = 12500; /* 50 s */
	s.success_y = 1e9;
	s.classify_y = 1e9;
	s.side_x = 1e9;
	bsim_world *w = NULL;
	bsim_error err;
	assert_int_equal(bsim_test_backend("thesis")->create(&s, NULL, &w, &err), BSIM_OK);
	const double f[2] = {0.0, 40.0};
	for (int n = 0; n < s.max_steps; n++)
		assert_int_equal(
		        bsim_backend_step(bsim_test_backend("thesis"), w, f, 0.0, s.dt, NULL),
		        BSIM_OK);
	/* contacts of the final state, and the spring torques */
	double sum[2] = {0.0, 0.0};
	int touching = 0;
	for (int i = 0; i < 3; i++) {
		thesis_contact c;
		if (!bsim_thesis_contact_detect(w, i, 1e-3, &c))
			continue;
		touching++;
		const thesis_beam_model *bm = &w->model->beams[i];
		thesis_beam *b = &w->beams[i];
		double u[2];
		thesis_beam_direction(bm, b, u);
		double lever = (w->x[0] - bm->p[0]) * u[0] + (w->x[1] - bm->p[1]) * u[1];
		double force = bm->stiffness * b->theta / lever; /* N, P_i = k theta / s */
		assert_true(c.type == BSIM_CONTACT_TANGENT);
		assert_true(c.gap > -2e-6);
		sum[0] += force * c.n[0];
		sum[1] += force * c.n[1];
	}
	print_message("three beams: %d touching, sum P n = (%.3g, %.3g) N against F = (0, -40), "
	              "body at rest (|v| = %.2g m/s)\n",
	              touching, sum[0], sum[1], hypot(w->v[0], w->v[1]));
	assert_int_equal(touching, 3);
	assert_true(hypot(w->v[0], w->v[1]) < 1e-6);
	assert_true(fabs(sum[0]) < 1e-6 && fabs(sum[1] + 40.0) < 1e-6);
	assert_int_equal(bsim_thesis_lcp_fallbacks(), 0); /* solved by enumeration */
	bsim_test_backend("thesis")->destroy(w);
	bsim_scene_free(&s);
}

/* ---- statistics ------------------------------------------------------------ */

static void fill_pairs(bsim_trial_result *a, bsim_trial_result *b, int n, int b_count, int c_count)
{
	memset(a, 0, (size_t)n * sizeof *a);
	memset(b, 0, (size_t)n * sizeof *b);
	for (int i = 0; i < n; i++) {
		a[i].outcome = b[i].outcome = BSIM_STUCK;
		a[i].final_ix = b[i].final_ix = 1;
	}
	for (int i = 0; i < b_count; i++) /* A ended at the end, B stuck */
		a[i].outcome = BSIM_TRAVERSED;
	for (int i = b_count; i < b_count + c_count; i++)
		b[i].outcome = BSIM_TRAVERSED;
}

/* Two locations: the permutation test is the exact sign test, McNemar's. */
static void permutation_is_mcnemar_for_two_locations(void **state)
{
	(void)state;
	bsim_trial_result a[80], b[80];
	static const int cases[][2] = {{0, 0}, {3, 0}, {5, 2}, {1, 9}, {7, 7}, {12, 4}, {20, 0}};
	for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
		fill_pairs(a, b, 80, cases[k][0], cases[k][1]);
		bsim_location_test t;
		bsim_compare_location_test(a, b, 80, 1, &t);
		double want = bsim_stats_mcnemar_exact(cases[k][0], cases[k][1]);
		assert_true(t.exact);
		assert_int_equal(t.discordant, cases[k][0] + cases[k][1]);
		assert_true(fabs(t.p_value - want) < 1e-12);
	}
	/* more than 20 discordant pairs: Monte Carlo, within its error */
	fill_pairs(a, b, 80, 21, 9);
	bsim_location_test t;
	bsim_compare_location_test(a, b, 80, 1, &t);
	assert_false(t.exact);
	double want = bsim_stats_mcnemar_exact(21, 9);
	print_message("Monte Carlo p = %.4f, exact McNemar %.4f\n", t.p_value, want);
	assert_true(fabs(t.p_value - want) < 0.01);
	assert_true(fabs(t.tv - 12.0 / 80.0) < 1e-12);
}

/* A hand-built group: locations counted, transitions and time per row from
 * the entries. */
static void summary_counts(void **state)
{
	(void)state;
	bsim_trial_result r[3];
	bsim_trial_log logs[3];
	memset(r, 0, sizeof r);
	memset(logs, 0, sizeof logs);
	bsim_gate_entry e0[] = {{.ix = 0, .iy = 0, .t = 0}, {.ix = 0, .iy = 1, .t = 4}};
	bsim_gate_entry e1[] = {
	        {.ix = 0, .iy = 0, .t = 0}, {.ix = 1, .iy = 0, .t = 2}, {.ix = 1, .iy = 1, .t = 5}};
	bsim_gate_entry e2[] = {{.ix = 0, .iy = 0, .t = 0}, {.ix = 0, .iy = 1, .t = 3}};
	logs[0] = (bsim_trial_log){.n_entries = 2, .entries = e0};
	logs[1] = (bsim_trial_log){.n_entries = 3, .entries = e1};
	logs[2] = (bsim_trial_log){.n_entries = 2, .entries = e2};
	r[0] = (bsim_trial_result){
	        .outcome = BSIM_TRAVERSED, .t_end = 6, .final_ix = 0, .final_iy = 1};
	r[1] = (bsim_trial_result){
	        .outcome = BSIM_STUCK, .t_end = 17, .final_ix = 1, .final_iy = 1};
	r[2] = (bsim_trial_result){
	        .outcome = BSIM_TRAVERSED, .t_end = 5, .final_ix = 0, .final_iy = 1};
	bsim_lattice_summary ls;
	assert_int_equal(bsim_lattice_summarise(r, logs, 3, 2, &ls), BSIM_OK);
	assert_int_equal(ls.n_locations, 2);
	char label[48];
	bsim_lattice_location_label(ls.locations[0].loc, label, sizeof label);
	assert_string_equal(label, "end:0");
	assert_int_equal(ls.locations[0].count, 2);
	bsim_lattice_location_label(ls.locations[1].loc, label, sizeof label);
	assert_string_equal(label, "stuck:1:1");
	/* by from, then to, rows first: (0,0)->(1,0), (0,0)->(0,1) twice,
	 * (1,0)->(1,1) */
	assert_int_equal(ls.n_transitions, 3);
	assert_int_equal(ls.transitions[0].count, 1);
	assert_int_equal(ls.transitions[0].to[0], 1);
	assert_int_equal(ls.transitions[1].count, 2);
	assert_int_equal(ls.transitions[1].to[1], 1);
	assert_int_equal(ls.transitions[2].from[0], 1);
	/* row 0: 4, 5, 3 s; row 1: 2, 12, 2 s */
	assert_int_equal(ls.row_trials[0], 3);
	assert_true(fabs(ls.row_time[0] - 4.0) < 1e-12);
	assert_true(fabs(ls.row_time[1] - 16.0 / 3.0) < 1e-12);
	double lo, hi;
	bsim_stats_wilson(2, 3, BSIM_STATS_Z95, &lo, &hi);
	assert_true(ls.locations[0].ci95[0] == lo && ls.locations[0].ci95[1] == hi);
	bsim_lattice_summary_free(&ls);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(geometry_is_the_essays),
	        cmocka_unit_test(c_track_map_from_csv),
	        cmocka_unit_test(broad_phase_is_exact),
	        cmocka_unit_test(far_gates_change_nothing),
	        cmocka_unit_test(sleeping_thesis),
	        cmocka_unit_test(sleeping_others),
	        cmocka_unit_test(essay_is_world_on_one_gate),
	        cmocka_unit_test(essay_resets_the_gate_left),
	        cmocka_unit_test(lcp_many_contacts),
	        cmocka_unit_test(three_beams_static_equilibrium),
	        cmocka_unit_test(permutation_is_mcnemar_for_two_locations),
	        cmocka_unit_test(summary_counts),
	        cmocka_unit_test(peaks_of_moved_beams),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
