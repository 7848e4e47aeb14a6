/* The trial runner (docs/model.md section 6): time, forces from the effect
 * pipeline, termination and outcomes, around a backend's step. Everything
 * here is the same code for every backend. What the runner keeps besides the
 * state has a file each: the energy ledger and instability (trial_ledger),
 * the beams' peaks and last contacts (trial_peaks), the gate path
 * (trial_gates, trial_log), recording (trial_record) and the overlap measure
 * (trial_overlap).
 *
 * One call moves the world (bsim_backend.advance): one step at a time in
 * the step loop, which books each state with all the runner defines; or,
 * in a plain trial (nothing recorded, traced or measured per step, no
 * lattice) whose forces hold between the random force's draws, up to
 * TRIAL_STEPS_MAX steps of the schedule of forces in one call, booked by
 * run_book, which gives the same bits as the step loop (test_steps,
 * test_flight).
 *
 * Cost. A step's bookkeeping visits only the beams the backend lists as
 * active (bsim_state.active: the others are exactly at rest), so in a
 * lattice it costs what the beams near the body cost, like the backend's
 * step; what it calls every step is inline.
 *
 * Lattices (docs/model.md section 8). The runner follows the gate the body is
 * in (lattice.h), records each entry (bsim_gate_entry), ends the trial as
 * stuck when the body has spent gate_steps steps in one gate, and measures
 * side exits from the field's centre line. Under the essay's protocol
 * (lattice.protocol: essay, trial_essay.c) each entry replaces the world by
 * one holding only the entered gate's two beams, at rest. */
#include "beamsim/trial.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/contact_flag.h"
#include "beamsim/effects.h"
#include "beamsim/lattice.h"
#include "model/schedule_spare.h"
#include "run/trial_essay.h"
#include "run/trial_gates.h"
#include "run/trial_ledger.h"
#include "run/trial_log.h"
#include "run/trial_overlap.h"
#include "run/trial_peaks.h"
#include "run/trial_record.h"
#include "run/trial_steps.h"

struct bsim_trial_runner {
	bsim_state s0, s1; /* before and after a step */
	beam_shape *shape; /* per beam of the world */
	int cap;           /* beams the states hold */
	bsim_state whole;  /* the whole lattice's state, for recording (essay protocol) */
	trial_peaks peaks;
	trial_essay essay;
	trial_steps steps;        /* runs of steps */
	bsim_effects_spare spare; /* the last trial's schedule and footprint, for the next */
	/* The world of the last trial, kept for the next trial of the same
	 * scene, backend and options (bsim_trial_runner_keep_worlds). */
	int keep;
	bsim_world *kept;
	const bsim_scene *kept_scene;
	const bsim_backend *kept_backend;
	const bsim_options *kept_opts;
};

static void runner_forget_world(bsim_trial_runner *r)
{
	if (r->kept)
		r->kept_backend->destroy(r->kept);
	r->kept = NULL;
	r->kept_scene = NULL;
}

void bsim_trial_runner_keep_worlds(bsim_trial_runner *r, int on)
{
	r->keep = on != 0;
	if (!r->keep)
		runner_forget_world(r);
}

bsim_trial_runner *bsim_trial_runner_alloc(void)
{
	bsim_trial_runner *r = calloc(1, sizeof(bsim_trial_runner));
	if (r)
		bsim_trial_steps_init(&r->steps);
	return r;
}

void bsim_trial_runner_free(bsim_trial_runner *r)
{
	if (!r)
		return;
	bsim_state_free(&r->s0);
	bsim_state_free(&r->s1);
	bsim_state_free(&r->whole);
	bsim_trial_peaks_free(&r->peaks);
	bsim_trial_steps_free(&r->steps);
	bsim_effects_spare_free(&r->spare);
	runner_forget_world(r);
	free(r->shape);
	free(r);
}

static int runner_reserve(bsim_trial_runner *r, int n_beams)
{
	if (r->cap == n_beams && r->s0.theta)
		return BSIM_OK;
	bsim_state_free(&r->s0);
	bsim_state_free(&r->s1);
	free(r->shape);
	r->cap = 0;
	r->shape = malloc((size_t)(n_beams > 0 ? n_beams : 1) * sizeof *r->shape);
	if (!r->shape || bsim_state_init(&r->s0, n_beams) || bsim_state_init(&r->s1, n_beams))
		return BSIM_EFAIL;
	r->cap = n_beams;
	return BSIM_OK;
}

/* One trial: its inputs, its world, and what the run keeps on the side. */
typedef struct trial_ctx {
	bsim_trial_runner *r;
	const bsim_scene *scene;
	const bsim_backend *backend;
	const bsim_options *opts;
	const bsim_recorder *rec;
	bsim_trial_result *out;
	bsim_trial_log *log;
	bsim_world *w;
	const bsim_scene *ws; /* the scene the world holds: the scene, or one gate's */
	const int *map;       /* world beam -> scene beam, NULL: the same */
	bsim_effects *fx;     /* the forces on the body */
	gate_track gate;
	bsim_solver_counts solver; /* of the worlds replaced so far (essay protocol) */
	long n_max, gate_max;      /* steps in all, steps in one gate */
	double centre;             /* m, the field's centre line */
	int overlap;               /* the recorder asked for overlap_max */
	int measure;               /* overlap, or a body that rotates: measured every step */
	int recording, stride;     /* rows to the recorder's sinks, every stride-th step */
	bsim_trace_fn trace;
	int trace_whole; /* the trace sees the whole lattice (essay protocol) */
	long recorded;   /* the last step recorded, -1: none */
} trial_ctx;

/* The world the trial starts in (the whole scene, or the essay's start
 * gate) and the runner's memory for it. */
static int trial_world(trial_ctx *c, bsim_error *err)
{
	const bsim_scene *scene = c->scene;
	bsim_trial_runner *r = c->r;
	int essay = scene->has_lattice && scene->lattice.protocol == BSIM_PROTOCOL_ESSAY;
	int world_beams = essay ? 2 : scene->n_beams;
	if (runner_reserve(r, world_beams) || bsim_trial_peaks_reserve(&r->peaks, scene->n_beams))
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	if (essay && (c->recording || c->trace_whole) && r->whole.n_beams != scene->n_beams) {
		bsim_state_free(&r->whole);
		if (bsim_state_init(&r->whole, scene->n_beams))
			return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	c->ws = scene;
	c->map = NULL;
	bsim_trial_gate_start(&c->gate, scene);
	if (!essay && r->kept && r->kept_scene == scene && r->kept_backend == c->backend &&
	    r->kept_opts == c->opts) {
		c->w = r->kept;
		r->kept = NULL;
		int rc = c->backend->reset(c->w, scene, err);
		if (rc) {
			c->backend->destroy(c->w);
			c->w = NULL;
		}
		return rc;
	}
	runner_forget_world(r);
	if (!essay)
		return c->backend->create(scene, c->opts, &c->w, err);
	int rc = bsim_trial_essay_start(&r->essay, scene, c->backend, c->opts, c->gate.ix,
	                                c->gate.iy, &c->w, &c->out->reset_overlaps, err);
	c->ws = &r->essay.scene;
	c->map = r->essay.map;
	return rc;
}

/* The trial's world and effects, from the inputs in c; on failure
 * nothing is left to release. */
static int trial_open(trial_ctx *c, uint64_t seed, bsim_error *err)
{
	const bsim_recorder *rec = c->rec;
	memset(c->out, 0, sizeof *c->out);
	c->out->landscape_beam = -1;
	c->log = rec ? rec->log : NULL;
	if (c->log)
		c->log->n_entries = 0;
	/* the overlap is the disk's (R less the centre's distance): not
	 * measured for another shape (overlap_max NaN) */
	c->overlap = rec && rec->overlap && c->scene->body.shape == BSIM_SHAPE_DISK;
	c->measure = c->overlap || c->scene->body.rotates;
	c->recording = rec && (rec->csv || rec->ledger || rec->record);
	c->stride = rec && rec->stride > 0 ? rec->stride : 1;
	c->trace = rec ? rec->trace : NULL;
	c->trace_whole = c->trace && rec->trace_whole;
	int rc = trial_world(c, err);
	if (rc) {
		bsim_trial_essay_release(&c->r->essay, c->backend, &c->w);
		return rc;
	}
	if (bsim_effects_init_spare(c->fx, c->scene, seed, c->backend->takes, &c->r->spare)) {
		c->backend->destroy(c->w);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	return BSIM_OK;
}

/* The state the trace sees: the world's, or mapped onto the whole
 * lattice's (trace_whole under the essay's protocol). */
static const bsim_state *trial_trace_state(trial_ctx *c, const bsim_state *s)
{
	return c->trace_whole ? bsim_trial_record_state(&c->r->whole, c->map, s) : s;
}

/* Whether a beam s lists is in contact (bsim_contact_flag_in), its flags
 * not written: the first one found ends the test. */
static inline int trial_touches(const bsim_scene *ws, const bsim_state *s)
{
	for (int k = 0; k < s->n_active; k++)
		if (bsim_contact_flag_in(ws, s, s->active[k]) != BSIM_CONTACT_NONE)
			return 1;
	return 0;
}

/* The state at t = 0 in s0, and all that starts from it: the ledger, the
 * peaks, the gate path. */
static int trial_begin(trial_ctx *c, trial_loop *lp, bsim_state *s0, bsim_error *err)
{
	const bsim_scene *scene = c->scene;
	bsim_trial_result *out = c->out;
	int rc = BSIM_OK;
	c->backend->get_state(c->w, s0);
	bsim_contact_flags(c->ws, s0);
	if (c->overlap)
		bsim_trial_overlap_shapes(c->r->shape, c->ws);
	c->n_max = scene->max_steps;
	c->gate_max = scene->gate_steps > 0 ? scene->gate_steps : c->n_max;
	c->centre = bsim_lattice_centre_x(scene);
	*lp = (trial_loop){.h = scene->dt, .e0 = energy_mech(c->ws, s0)};
	out->ledger.e_start = lp->e0;
	out->ledger.inflow = lp->e0;
	/* Peaks start at the initial angles: every beam of the scene (the
	 * essay's world holds one gate; the others start at rest). */
	bsim_trial_peaks_start(&c->r->peaks, scene, c->map, s0);
	if (c->log)
		rc = bsim_trial_gate_log_start(c->log, &c->gate, scene, c->map, s0, err);
	out->overlap_max = c->overlap ? 0.0 : NAN;
	if (c->trace)
		c->trace(c->rec->trace_user, 0, trial_trace_state(c, s0));
	c->recorded = -1;
	out->outcome = BSIM_STUCK;
	return rc;
}

/* The state s after step n to the recorder's sinks. */
static void trial_record(trial_ctx *c, const bsim_state *s, long n)
{
	double f_rand = c->fx->random ? c->fx->random->last : 0.0;
	bsim_trial_record_row(c->rec, c->scene, bsim_trial_record_state(&c->r->whole, c->map, s), n,
	                      f_rand, &c->out->ledger);
	c->recorded = n;
}

/* Whether the run is over before step n + 1: the outcome known, at
 * classify_y or max_steps after it; or max_steps, or gate_steps in one gate. */
static inline int trial_over(const trial_ctx *c, const trial_loop *lp, const bsim_state *s0)
{
	if (lp->done)
		return s0->x[1] >= c->scene->classify_y || lp->run_on >= c->n_max;
	return lp->n >= c->n_max || c->gate.dwell >= c->gate_max;
}

/* The body entered gate (ix, iy) in step n, from p0 to s: the path
 * follows; under the essay's protocol the world is replaced by that gate's
 * (s its state), the energy of the beams left behind booked as reset. */
static int gate_enter(trial_ctx *c, trial_loop *lp, bsim_state *s, const double p0[2], int ix,
                      int iy, bsim_error *err)
{
	int rc = bsim_trial_gate_cross(&c->gate, c->log, c->scene, c->map, p0, s, ix, iy, lp->n,
	                               err);
	if (rc || c->scene->lattice.protocol != BSIM_PROTOCOL_ESSAY)
		return rc;
	double e_before = lp->e0;
	/* The world is replaced: what its solvers gave up on stays counted. */
	c->solver.iteration_limit += s->solver.iteration_limit;
	c->solver.clamped += s->solver.clamped;
	rc = bsim_trial_essay_enter(&c->r->essay, c->scene, c->backend, c->opts, ix, iy, s, &c->w,
	                            &c->out->reset_overlaps, err);
	if (rc)
		return rc;
	c->backend->get_state(c->w, s);
	bsim_contact_flags(c->ws, s);
	if (c->overlap) /* the new world's two beams */
		bsim_trial_overlap_shapes(c->r->shape, c->ws);
	lp->e0 = energy_mech(c->ws, s);
	c->out->ledger.reset += e_before - lp->e0;
	return BSIM_OK;
}

/* The gate of a lattice the body is in after step n (s; p0 before it).
 * A body that leaves the field ends in the gate it left from (gates are
 * clamped into the field). */
static inline int gate_follow(trial_ctx *c, trial_loop *lp, bsim_state *s, const double p0[2],
                              bsim_error *err)
{
	int ix, iy;
	bsim_lattice_gate_at(c->scene, s->x, &ix, &iy);
	if (ix == c->gate.ix && iy == c->gate.iy)
		return BSIM_OK;
	return gate_enter(c, lp, s, p0, ix, iy, err);
}

/* The outcome of the body at s after step n: a side exit ends the run
 * (returns 1); a traversal is known there, the run goes on to classify_y. */
static inline int outcome_at(trial_ctx *c, trial_loop *lp, const bsim_state *s)
{
	const bsim_scene *scene = c->scene;
	if (fabs(s->x[0] - c->centre) >= scene->side_x) {
		c->out->outcome = BSIM_SIDE_EXIT;
		return 1;
	}
	if (s->x[1] >= scene->success_y) {
		c->out->outcome = BSIM_TRAVERSED;
		c->out->steps = (int)lp->n;
		c->out->t_end = (double)lp->n * lp->h;
		lp->done = 1;
	}
	return 0;
}

/* The result from the last state s0 (the last finite one), the ledger
 * closed. */
static void trial_result(trial_ctx *c, const trial_loop *lp, bsim_state *s0)
{
	const bsim_scene *scene = c->scene;
	bsim_trial_result *out = c->out;
	const trial_peaks *p = &c->r->peaks;
	if (out->outcome != BSIM_TRAVERSED) {
		out->steps = (int)lp->n;
		out->t_end = (double)lp->n * lp->h;
	}
	if (out->outcome == BSIM_STUCK) {
		bsim_contact_flags(c->ws, s0); /* a plain run's last state has none yet */
		out->in_contact_end = any_contact(s0);
	}
	for (int i = 0; i < 2 && i < scene->n_beams; i++)
		out->max_theta[i] = p->peak[i];
	if (out->outcome == BSIM_TRAVERSED) {
		const double band = scene->classify_deadband;
		out->type = s0->v[0] > band    ? BSIM_TYPE_LEFT
		            : s0->v[0] < -band ? BSIM_TYPE_RIGHT
		                               : BSIM_TYPE_NONE;
		out->landscape_beam = bsim_trial_peaks_label(p, scene);
	}
	out->x_end = s0->x[0];
	out->y_end = s0->x[1];
	out->vx_end = s0->v[0];
	bsim_trial_peaks_turn_end(p, s0, out);
	out->steps_run = (int)lp->n;
	bsim_trial_ledger_close(out, lp->e0, lp->n);
	if (out->instability) {
		out->outcome = BSIM_UNSTABLE;
		out->type = BSIM_TYPE_NONE;
		out->landscape_beam = -1;
		out->in_contact_end = 0;
	}
	bsim_trial_steps_used(&c->r->steps);
	out->draws = c->fx->random ? bsim_schedule_draws(c->fx->random->schedule) : 0;
	out->solver = c->solver;
	out->solver.iteration_limit += s0->solver.iteration_limit;
	out->solver.clamped += s0->solver.clamped;
	out->final_ix = c->gate.ix;
	out->final_iy = c->gate.iy;
	out->gates_entered = c->gate.entries;
}

/* After the last step (rc: how the run ended): the final row, the result,
 * the log's peaks; the world and effects released. */
static int trial_close(trial_ctx *c, const trial_loop *lp, bsim_state *s0, int rc, bsim_error *err)
{
	if (c->recording && c->recorded != lp->n && rc == BSIM_OK) /* whatever the stride */
		trial_record(c, s0, lp->n);
	trial_result(c, lp, s0);
	if (rc == BSIM_OK)
		rc = bsim_effects_status(c->fx, err);
	if (rc == BSIM_OK && c->log &&
	    bsim_trial_log_peaks(c->log, c->r->peaks.peak, c->r->peaks.list, c->r->peaks.n_list,
	                         c->scene->n_beams))
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory for the peaks");
	bsim_trial_runner *r = c->r;
	bsim_effects_free_spare(c->fx, &r->spare);
	if (r->keep && c->backend->reset && c->map == NULL && c->w && rc == BSIM_OK) {
		r->kept = c->w; /* the next trial of this scene resets it */
		r->kept_scene = c->scene;
		r->kept_backend = c->backend;
		r->kept_opts = c->opts;
		c->w = NULL;
	}
	bsim_trial_essay_release(&r->essay, c->backend, &c->w);
	return rc;
}

/* What a step measures beyond the essay's needs, s1 the state after it:
 * the overlap (when asked for) and the turn of a body that rotates. Out of
 * the step loop, which tests one flag for both (c->measure): a step that
 * measures neither runs the loop's code as it was (bench --callgrind). */
__attribute__((noinline)) static void trial_measure(trial_ctx *c, const bsim_state *s1)
{
	if (c->overlap)
		c->out->overlap_max = fmax(c->out->overlap_max,
		                           bsim_trial_overlap_depth(c->r->shape, c->ws->n_beams,
		                                                    c->scene->body.radius, s1));
	trial_peaks_turn(&c->r->peaks, s1);
}

/* What booking a state gives (trial_book, run_book). */
enum { BOOK_ON = 0, BOOK_END = 1, BOOK_NONFINITE = 2 };

/* Books s1, the state after step lp->n + 1 of the step loop, from s0, the
 * state before it: its energy and finiteness, the step's count, its
 * contact flags, the trace, the ledger, the overlap, and before the
 * outcome is known the peaks, the gate and the outcome. BOOK_NONFINITE: s1
 * is not finite and not kept (s0 stays the last finite state, the one
 * reported); else s1 is kept (the caller makes it the state s0), BOOK_END
 * if the trial ends there (a side exit, or *rc failed). Inline: the step
 * loop makes no call for it. */
static inline int trial_book(trial_ctx *c, trial_loop *lp, const bsim_state *s0, bsim_state *s1,
                             int *rc, bsim_error *err)
{
	bsim_trial_result *out = c->out;
	const bsim_scene *ws = c->ws;
	double e1;
	if (!state_energy_finite(ws, s1, &e1)) {
		out->instability = BSIM_UNSTABLE_NONFINITE;
		out->unstable_step = (int)(lp->n + 1);
		return BOOK_NONFINITE;
	}
	lp->n++;
	c->gate.dwell++;
	lp->run_on += lp->done;
	/* The flags of every state the trace, the recording, the overlap and
	 * the peaks see (a run computes them for its last touching state and
	 * the trial's last state only: bsim_trial_run, trial_result). */
	bsim_contact_flags(ws, s1);
	if (c->trace)
		c->trace(c->rec->trace_user, lp->n, trial_trace_state(c, s1));
	ledger_step(&out->ledger, c->fx, s0, s1, lp->e0, e1);
	lp->e0 = e1;
	if (c->measure)
		trial_measure(c, s1);
	if (lp->done)
		return BOOK_ON;
	trial_peaks_step(&c->r->peaks, c->scene, c->map, s1);
	/* The gate first: a body that leaves the field ends in its gate. */
	if (c->scene->has_lattice && (*rc = gate_follow(c, lp, s1, s0->x, err)) != BSIM_OK)
		return BOOK_END;
	return outcome_at(c, lp, s1) ? BOOK_END : BOOK_ON;
}

/* Always inlined: a copy for the essay's pipeline, its axes constants,
 * and one for any pipeline that holds. */
#if defined(__GNUC__)
#define TRIAL_BOOK static inline __attribute__((always_inline))
#else
#define TRIAL_BOOK static inline
#endif

/* The ledger's lines a step adds to (LEDGER_LINES_ADD), held in locals
 * while a run is booked. */
typedef struct run_lines {
	double w_prop, w_rand, damper, impact, contact, correction, sleep;
	double residual, residual_abs, residual_max, inflow;
} run_lines;

/* Books a run's states[0..m) after *s0p (the state after lp->n steps) as
 * the step loop books a state of a plain trial (nothing recorded, traced
 * or measured, no lattice: trial_book without the flags, the trace, the
 * measures and the gate), the operations in their order, with what the run
 * does not change held in locals: the ledger's lines, the loop's counters
 * and the pipeline's forces, propulsion cp along axis ap (has_p) and the
 * held random force cr[k] in step k along ar (has_r), constants where the
 * caller gives them; each force's work is summed from 0.0, as
 * ledger_step's loop sums it. Before each state, the step loop's
 * test whether the trial is over (trial_over), once the outcome is known;
 * after it, the step loop's outcome (outcome_at). The peaks
 * take no contacts here (the caller gives them the run's last touching
 * state), and the test of a state that lists no beam (trial_peaks_note) is
 * asked again only after a booking that updated them. Returns what the
 * last booking gave (BOOK_ON: every state booked, or the trial over); *s0p
 * the last state kept, *listed 0 if no state booked lists a beam. */
TRIAL_BOOK int run_book(trial_ctx *c, trial_loop *lp, bsim_state **s0p, bsim_state *states, int m,
                        int *listed, const double cp, const double *cr, const int has_p,
                        const int ap, const int has_r, const int ar)
{
	const bsim_scene *sc = c->scene;
	bsim_trial_result *out = c->out;
	bsim_ledger *l = &out->ledger;
	trial_peaks *peaks = &c->r->peaks;
	bsim_state *s0 = *s0p;
	trial_loop L = *lp; /* the loop's counters, in locals */
	long dwell = c->gate.dwell;
	run_lines lines = {l->w_prop,       l->w_rand,       l->damper, l->impact,
	                   l->contact,      l->correction,   l->sleep,  l->residual,
	                   l->residual_abs, l->residual_max, l->inflow};
	int quiet = peaks->n_negative == 0 && peaks->settled01;
	int any = 0;
	int b = BOOK_ON;
	for (int k = 0; k < m; k++) {
		if (L.done && trial_over(c, &L, s0))
			break;
		bsim_state *s1 = &states[k];
		double e1;
		if (!state_energy_finite(sc, s1, &e1)) {
			out->instability = BSIM_UNSTABLE_NONFINITE;
			out->unstable_step = (int)(L.n + 1);
			b = BOOK_NONFINITE;
			break;
		}
		L.n++;
		dwell++;
		L.run_on += L.done;
		any |= s1->n_active;
		/* ledger_step, the pipeline's forces held */
		const double d[2] = {s1->x[0] - s0->x[0], s1->x[1] - s0->x[1]};
		double w_prop = 0.0, w_rand = 0.0;
		if (has_p)
			w_prop += cp * d[ap];
		if (has_r)
			w_rand += cr[k] * d[ar];
		const bsim_step_energy *se = &s1->energy;
		const double r = ledger_residual(L.e0, e1, w_prop, w_rand, se);
		LEDGER_LINES_ADD(lines, w_prop, w_rand, se, r);
		L.e0 = e1;
		s0 = s1;
		if (L.done)
			continue;
		if (s1->n_active || !quiet) {
			trial_peaks_note(peaks, sc, NULL, s1);
			quiet = peaks->n_negative == 0 && peaks->settled01;
		}
		if (outcome_at(c, &L, s1)) {
			b = BOOK_END;
			break;
		}
	}
	l->w_prop = lines.w_prop;
	l->w_rand = lines.w_rand;
	l->damper = lines.damper;
	l->impact = lines.impact;
	l->contact = lines.contact;
	l->correction = lines.correction;
	l->sleep = lines.sleep;
	l->residual = lines.residual;
	l->residual_abs = lines.residual_abs;
	l->residual_max = lines.residual_max;
	l->inflow = lines.inflow;
	*lp = L;
	c->gate.dwell = dwell;
	*s0p = s0;
	*listed = any;
	return b;
}

int bsim_trial_run(bsim_trial_runner *r, const bsim_scene *scene, const bsim_backend *backend,
                   const bsim_options *opts, uint64_t seed, const bsim_recorder *rec,
                   bsim_trial_result *out, bsim_error *err)
{
	bsim_effects fx;
	trial_ctx c = {.r = r,
	               .scene = scene,
	               .backend = backend,
	               .opts = opts,
	               .rec = rec,
	               .out = out,
	               .fx = &fx};
	r->steps.on = 0; /* until this trial's are set */
	int rc = trial_open(&c, seed, err);
	if (rc)
		return rc;
	bsim_state *s0 = &r->s0, *s1 = &r->s1;
	trial_loop lp;
	rc = trial_begin(&c, &lp, s0, err);
	const int plain = !c.recording && !c.trace && !c.measure && !c.map;
	if (rc == BSIM_OK &&
	    bsim_trial_steps_start(&r->steps, plain, scene, &fx, c.n_max, c.gate_max))
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	trial_steps *ts = &r->steps;
	while (rc == BSIM_OK && !trial_over(&c, &lp, s0)) {
		int m = 0;
		if (ts->on) {
			bsim_state *states;
			int room = (int)trial_steps_room(ts, &lp, c.gate.dwell, s0, &states);
			bsim_trial_steps_schedule(ts, lp.n, room);
			/* a world that fails part-way: the steps made before are
			 * booked, then the trial ends */
			rc = backend->advance(c.w, ts->schedule, lp.h, room, states, &m, err);
			/* The run's states, booked until the trial ends. The run's
			 * room keeps max_steps and gate_steps: before the outcome
			 * is known, only a booking ends it. */
			const long n0 = lp.n;
			const int open_at_start = !lp.done;
			bsim_state *kept = s0;
			const double cp = ts->propulsion ? ts->propulsion->param : 0.0;
			int b, listed;
			if (ts->propulsion && ts->random && ts->propulsion->axis == 1 &&
			    ts->random->axis == 0) /* the essay's */
				b = run_book(&c, &lp, &kept, states, m, &listed, cp, ts->random_at,
				             1, 1, 1, 0);
			else
				b = run_book(&c, &lp, &kept, states, m, &listed, cp, ts->random_at,
				             ts->propulsion != NULL,
				             ts->propulsion ? ts->propulsion->axis : 0,
				             ts->random != NULL, ts->random ? ts->random->axis : 0);
			s0 = kept;
			/* the steps made or tried: a state not finite, or a step
			 * that failed after every state before it was booked */
			ts->tried = lp.n + (b == BOOK_NONFINITE || (b == BOOK_ON && rc != BSIM_OK));
			/* The states kept before the outcome was known: to the
			 * traversal's step, or all kept. */
			const long open = !open_at_start ? 0 : (lp.done ? out->steps : lp.n) - n0;
			/* The last of them in which the body touches a beam gives
			 * the peaks' contacts, as the step loop would have left
			 * them: found from the end, most often at once. */
			for (long k = listed ? open - 1 : -1; k >= 0; k--)
				if (trial_touches(scene, &states[k])) {
					bsim_contact_flags(scene, &states[k]);
					trial_peaks_contacts(&r->peaks, NULL, &states[k]);
					break;
				}
			if (b != BOOK_ON || rc != BSIM_OK)
				break;
			continue;
		}
		double f[BSIM_WRENCH];
		bsim_effects_force_at(&fx, lp.n, lp.h, s0, f);
		if (c.recording && lp.n % c.stride == 0)
			trial_record(&c, s0, lp.n);
		const bsim_wrench step = {{f[0], f[1]}, f[2]};
		if ((rc = backend->advance(c.w, &step, lp.h, 1, s1, &m, err)) != BSIM_OK)
			break;
		int b = trial_book(&c, &lp, s0, s1, &rc, err);
		if (b == BOOK_NONFINITE)
			break;
		/* s1 is always one of the runner's two states (a run's states
		 * are its banks'): the next step's is the other one. */
		s0 = s1;
		s1 = s0 == &r->s0 ? &r->s1 : &r->s0;
		if (b != BOOK_ON)
			break;
	}
	return trial_close(&c, &lp, s0, rc, err);
}
