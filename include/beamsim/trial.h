/* The trial runner (docs/model.md section 6): owns time, the effect pipeline,
 * termination, outcomes, the energy ledger and optional recording. */
#ifndef BSIM_TRIAL_H
#define BSIM_TRIAL_H

#include <stdint.h>
#include <stdio.h>

#include "beamsim/base.h"
#include "beamsim/backend.h"
#include "beamsim/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
	BSIM_TRAVERSED = 0, /* y >= success_y with |x - x_c| < side_x */
	BSIM_SIDE_EXIT = 1, /* |x - x_c| >= side_x before traversing */
	BSIM_STUCK = 2,     /* max_steps reached, or gate_steps in one gate */
	BSIM_UNSTABLE = 3,  /* the backend failed: see bsim_instability */
} bsim_outcome;

#define BSIM_N_OUTCOMES 4

typedef enum {
	BSIM_TYPE_NONE = 0,  /* |v_x| at classify_y below the scene's classify_deadband */
	BSIM_TYPE_LEFT = 1,  /* v_x > 0 at classify_y: crossed the left barrier */
	BSIM_TYPE_RIGHT = 2, /* v_x < 0 at classify_y */
} bsim_type;

/* Why a trial is unstable. A trial is never given an ordinary outcome
 * when its numbers cannot be trusted:
 *   nonfinite: the state or its energy stopped being a finite number; the
 *              trial ends at that step, the reported state is the last
 *              finite one;
 *   energy:    the ledger's residual at the end is positive and larger than
 *              BSIM_LEDGER_BOUND times the energy that flowed in (the
 *              starting energy plus the absolute work of the external
 *              forces, step by step): the backend created more energy than
 *              the forces put in;
 *   energy_lost: the residual is negative and larger in magnitude than
 *              BSIM_LEDGER_LOST_BOUND times the energy that flowed in: most
 *              of what came in vanished beyond the losses the ledger books
 *              (a solver's clamp that stopped the body, say). A smaller
 *              negative residual (an implicit spring's numerical damping)
 *              is an accuracy matter, measured by beamsim accuracy. */
typedef enum {
	BSIM_STABLE = 0,
	BSIM_UNSTABLE_NONFINITE = 1,
	BSIM_UNSTABLE_ENERGY = 2,
	BSIM_UNSTABLE_ENERGY_LOST = 3,
} bsim_instability;

/* The bound of the energy test above. Measured (H1 and H2, 19,200 trials
 * each): residual / inflow at most 3e-14 on the essay's solver (its midpoint
 * integrator), 0.04 on its euler and on Box2D weld, 0.07 on Box2D torque; 0.47 with Box2D
 * torque springs of 3e6 N m/rad (omega_n h = 1.5, inaccurate but bounded);
 * 1.9 and above once an explicit spring passes its stability limit
 * (omega_n h > 2), where the energy grows without bound. */
#define BSIM_LEDGER_BOUND 1.0
/* The bound on the other side: energy vanished without account, as a
 * fraction of what flowed in. The residual cannot fall below minus the
 * inflow (the end energy and the booked losses are not negative), which it
 * reaches when everything vanished. Measured on the stored reference runs
 * (docs/robustness.md), residual / (start energy + net work) at its most
 * negative: -3e-14 on the essay's solver (midpoint), -0.43 on its euler
 * (H2), -0.34 on Box2D weld (H1); the inflow, which counts the work of every step in
 * absolute value, is at least that denominator. */
#define BSIM_LEDGER_LOST_BOUND 0.75
/* A floor under the bound, J, so that round-off in a scene through which
 * no energy flows is not a failure. */
#define BSIM_LEDGER_FLOOR 1e-6

/* The energy ledger of a trial, J (docs/model.md section 10, check 3).
 * E = body KE + sum(1/2 I omega^2 + 1/2 k theta^2). Each step:
 *   E' - E = w_prop + w_rand - damper - impact - contact - correction - sleep + r
 * with r the step's residual; |r| summed and at its largest are kept. The
 * essay's lattice protocol resets the beams of each gate entered; the energy
 * they held leaves the world there and is booked as reset. */
typedef struct bsim_ledger {
	double e_start, e_end;
	double w_prop, w_rand; /* work of the propulsive and random forces */
	double damper, impact, contact, correction;
	double sleep;        /* energy of beams put to rest by the backend's sleeping */
	double reset;        /* energy of beams reset by the essay protocol */
	double residual;     /* sum of r */
	double residual_max; /* max |r| over steps */
	double residual_abs; /* sum of |r| */
	double inflow;       /* e_start + sum over steps of |w_prop| + |w_rand| */
	double drag;         /* energy taken by effects.drag: minus its work */
	double w_osc;        /* work of effects.oscillation (in inflow too) */
	double friction;     /* energy taken by effects.ground_friction: minus its work */
} bsim_ledger;

/* Plain data, no pointers: a sweep's journal (util/journal.h) stores it
 * byte for byte, and a resumed sweep reads it back so. */
typedef struct bsim_trial_result {
	bsim_outcome outcome;
	bsim_type type;
	int landscape_beam;          /* traversed: the beam whose barrier it crossed, 0-based, -1
	                              * none (bsim_landscape_label at the last step before
	                              * success_y at which it touched a beam) */
	int steps;                   /* steps to the outcome event */
	double t_end;                /* s, time of the outcome event */
	double x_end, y_end, vx_end; /* at the end of the run (classify_y for traversed) */
	double max_theta[2];         /* peak theta of beams 0 and 1, rad */
	int in_contact_end;          /* stuck: 1 if any beam touched the body at the end */
	int steps_run;               /* all steps integrated, incl. those to classify_y */
	unsigned long draws;         /* standard-normal draws made */
	bsim_ledger ledger;
	bsim_instability instability; /* BSIM_STABLE unless the outcome is unstable */
	int unstable_step;            /* the step it was found at (nonfinite), or the last */
	double overlap_max;           /* m, the deepest the body overlapped a beam over the
	                               * trial; NaN unless the recorder asked for it */
	/* The gate where the trial ended (a lattice, lattice.h; (0, 0) for any
	 * other scene): the last gate entered before the outcome. */
	int final_ix, final_iy;
	int gates_entered;  /* gates in the path, the start gate included */
	int reset_overlaps; /* essay protocol: entries whose reset beams overlapped the body */
	/* What the backend's solvers gave up on over the trial (beamsim/
	 * state.h), summed over the worlds it ran in. */
	bsim_solver_counts solver;
	/* The body's turn. At the end of the run, as x_end: its heading, rad
	 * from +x counter-clockwise (bsim_state.heading, not wrapped), and
	 * angular velocity, rad/s; turn_end, rad, the heading's change since
	 * the start (counter-clockwise positive). turn_max, rad: the largest
	 * |heading - heading at the start| over the run's steps (>= |turn_end|).
	 * A body that does not rotate (body.rotates 0) keeps its heading:
	 * angular_velocity_end, turn_end and turn_max are 0. */
	double heading_end, angular_velocity_end, turn_end, turn_max;
} bsim_trial_result;

/* Every member of bsim_trial_result named once, as X-macros (X(member)),
 * so that what lists them is made from here: a journal's header (beamsim/
 * trial_fields.h: bsim_trial_members), `run --json` and MATLAB's
 * beamsim_run. A member added to the struct goes into one of them
 * (test_journal fails on a member in none).
 *
 * The members run --json and beamsim_run give as they are, by name, in
 * this order (a number each; max_theta a pair): */
#define BSIM_TRIAL_RESULT_PLAIN(X)                                                                 \
	X(in_contact_end)                                                                          \
	X(steps)                                                                                   \
	X(steps_run)                                                                               \
	X(draws)                                                                                   \
	X(t_end)                                                                                   \
	X(x_end)                                                                                   \
	X(y_end)                                                                                   \
	X(vx_end)                                                                                  \
	X(heading_end)                                                                             \
	X(angular_velocity_end)                                                                    \
	X(turn_end)                                                                                \
	X(turn_max)                                                                                \
	X(max_theta)                                                                               \
	X(overlap_max)
/* the others, which they give in a form of their own (outcome and type as
 * words, the beam from 1, the final gate with its label, the instability
 * as a text) or not at all: */
#define BSIM_TRIAL_RESULT_OTHER(X)                                                                 \
	X(outcome)                                                                                 \
	X(type)                                                                                    \
	X(landscape_beam)                                                                          \
	X(instability)                                                                             \
	X(unstable_step)                                                                           \
	X(final_ix)                                                                                \
	X(final_iy)                                                                                \
	X(gates_entered)                                                                           \
	X(reset_overlaps)
/* the ledger's terms they give, in this order, then those they leave out: */
#define BSIM_LEDGER_SHOWN(X)                                                                       \
	X(e_start)                                                                                 \
	X(e_end)                                                                                   \
	X(w_prop)                                                                                  \
	X(w_rand)                                                                                  \
	X(damper)                                                                                  \
	X(impact)                                                                                  \
	X(contact)                                                                                 \
	X(correction)                                                                              \
	X(sleep)                                                                                   \
	X(reset)                                                                                   \
	X(residual)                                                                                \
	X(residual_max)                                                                            \
	X(residual_abs)                                                                            \
	X(inflow)
#define BSIM_LEDGER_OTHER(X) X(drag) X(w_osc) X(friction)
/* the solver's counts (bsim_solver_counts, beamsim/state.h), all given: */
#define BSIM_SOLVER_COUNTS(X) X(iteration_limit) X(clamped)

/* Which edge of a gate the body crossed to enter it. */
typedef enum {
	BSIM_EDGE_START = 0,  /* the gate the trial starts in */
	BSIM_EDGE_BOTTOM = 1, /* from the gate below (iy - 1) */
	BSIM_EDGE_LEFT = 2,   /* from the gate on the left (ix - 1) */
	BSIM_EDGE_RIGHT = 3,  /* from the gate on the right (ix + 1) */
	BSIM_EDGE_TOP = 4,    /* from the gate above (iy + 1) */
} bsim_edge;

BSIM_API const char *bsim_trial_edge_name(bsim_edge e);

/* One entry into a gate: the state with which a single-gate map (entry ->
 * exit) would start, in the gate's own frame (Eq. 2.17: x = X - width ix,
 * y = Y - depth iy). The beams are the entered gate's as the body arrived:
 * the state it left them in (whole world), before the essay protocol
 * resets them. */
typedef struct bsim_gate_entry {
	int ix, iy;
	bsim_edge edge;
	int step;        /* the step at whose end the body was inside */
	double t;        /* s */
	double pos;      /* m, where the path crossed the edge: x on a bottom or top
	                  * edge, y on a left or right one, gate frame; START: x */
	double x[2];     /* m, body centre at the end of that step, gate frame */
	double v[2];     /* m/s */
	double theta[2]; /* rad, the gate's left and right beam */
	double omega[2]; /* rad/s */
} bsim_gate_entry;

/* A beam that moved in a trial and its peak angle. */
typedef struct bsim_beam_peak {
	int beam;    /* the scene's, 0-based */
	double peak; /* rad, the largest theta over the trial, not 0 */
} bsim_beam_peak;

/* What a trial can leave beyond its result (bsim_recorder.log): the gate
 * path with each entry's state, and the peak angle of every beam that
 * moved; every other beam of the scene's n_beams kept a peak of 0. Its
 * memory follows the beams the trial touched, not the field's. Reused
 * from trial to trial; alloc/free pair. */
typedef struct bsim_trial_log {
	int n_entries, cap_entries;
	bsim_gate_entry *entries;
	int n_beams; /* the scene's */
	int n_peaks, cap_peaks;
	bsim_beam_peak *peaks; /* n_peaks, in ascending order of beam */
} bsim_trial_log;

BSIM_API bsim_trial_log *bsim_trial_log_alloc(void);
BSIM_API void bsim_trial_log_free(bsim_trial_log *l);
/* dst = a copy of src's entries and peaks, in dst's own memory (dst
 * zeroed or a log from here, whose memory is reused). */
BSIM_API int bsim_trial_log_copy(bsim_trial_log *dst, const bsim_trial_log *src);
/* Frees what a log holds, not the log itself (for logs in arrays). */
BSIM_API void bsim_trial_log_clear(bsim_trial_log *l);

/* Called with the state at t = 0 and after every step (step = 1, 2, ...),
 * whatever the stride; for in-memory use of a trajectory (compare). */
typedef void (*bsim_trace_fn)(void *user, long step, const bsim_state *s);

/* One recorded row: the state at time t = step h, the random force that
 * acts during the step from there, and the energy ledger summed over
 * [0, t]. */
typedef struct bsim_record_row {
	long step;
	double t;                  /* s */
	const bsim_state *state;   /* at t */
	double f_rand;             /* N, lateral, acting on [t, t + h) */
	const bsim_ledger *ledger; /* summed over the steps before t */
	double e_kin, e_beam;      /* J: body and beams' kinetic, springs' elastic */
	double e_prop;             /* J: F_prop (y0 - y), docs/model.md section 7 */
	/* 1: the trajectory CSV's rows end with heading,angular_velocity
	 * (bsim_trial_body_columns) */
	int body_columns;
} bsim_record_row;

/* Called at every recorded row (the rows of the CSV, whatever it is). */
typedef void (*bsim_record_fn)(void *user, const bsim_record_row *row);

/* Trajectory recording (docs/files.md "`run`"). Rows are the state at
 * t = 0, after every stride-th step, and after the last step. */
typedef struct bsim_recorder {
	FILE *csv;           /* NULL: no trajectory CSV */
	int stride;          /* record every stride-th step (>= 1) */
	bsim_trace_fn trace; /* NULL: none; called after every step, whatever the stride */
	void *trace_user;
	/* Under the essay's lattice protocol the trace sees the active gate's
	 * world (two beams) unless this is 1: then the whole lattice's state,
	 * as recorded rows are (beams of gates left keep their last angles),
	 * for observers that draw the whole field (video). */
	int trace_whole;
	FILE *ledger;          /* NULL: none; the ledger CSV, one row per recorded row */
	bsim_record_fn record; /* NULL: none */
	void *record_user;
	bsim_trial_log *log; /* NULL: none */
	/* 1: measure overlap_max, the deepest overlap of the body with any beam
	 * after each step (R minus the distance from the centre to the beam's
	 * segment). A solver that keeps contacts apart holds it near 0; it
	 * costs about a fifth of a step of the essay's solver, so sweeps ask only
	 * when told. */
	int overlap;
} bsim_recorder;

/* Writes the trajectory CSV header for a scene of n_beams beams. */
BSIM_API void bsim_trial_trajectory_header(FILE *f, int n_beams);

/* 1 if the scene's body turns or is not a disk: its trajectory CSV then
 * ends with the columns heading (rad) and angular_velocity (rad/s); 0 for
 * the essay's disk, whose CSV is as it always was. */
BSIM_API int bsim_trial_body_columns(const bsim_scene *scene);

/* The trajectory CSV header of a scene of n_beams beams, with the body's
 * columns if body_columns (bsim_trial_body_columns). */
BSIM_API void bsim_trial_trajectory_header_body(FILE *f, int n_beams, int body_columns);

/* A bsim_record_fn writing the row to the trajectory CSV file (a FILE *):
 * what rec->csv receives, for a second file with the same rows. */
BSIM_API void bsim_trial_trajectory_row(void *file, const bsim_record_row *row);

/* The ledger CSV (beamsim run --out): at each recorded time t, s,
 *   t,e_kin,e_beam,e_mech,w_prop,w_rand,damper,impact,contact,correction,residual,
 *   sleep,reset
 * in J, every flow summed over [0, t], so that at every row
 *   e_mech(t) - e_mech(0) = w_prop + w_rand - damper - impact - contact
 *                           - correction - sleep - reset + residual
 * (sleep and reset: beams put to rest by sleeping and by the essay's lattice
 * protocol; 0 elsewhere). */
BSIM_API void bsim_trial_ledger_header(FILE *f);

typedef struct bsim_trial_runner bsim_trial_runner;

/* A runner holds the reusable per-thread memory (state buffers, schedule). */
BSIM_API bsim_trial_runner *bsim_trial_runner_alloc(void);
BSIM_API void bsim_trial_runner_free(bsim_trial_runner *r);
/* on != 0: the runner keeps a trial's world for the next trial, which
 * resets it (bsim_backend.reset, where the backend offers it) instead of
 * building the world anew, when it runs the same scene (the same pointer),
 * backend and options (the same pointers) under the whole-world protocol:
 * a trial then costs what the beams it touches cost, not the field. The
 * caller promises that while it is on a scene pointer it passes names one
 * scene, unchanged, and likewise the options; results are the same bit for
 * bit. 0 (the default): every trial builds its world; the kept one is
 * freed. */
BSIM_API void bsim_trial_runner_keep_worlds(bsim_trial_runner *r, int on);

/* Runs one trial. seed: the mixed seed (bsim_schedule_seed_mix). rec may be NULL.
 * A lattice scene runs under its lattice.protocol: the whole world, or the
 * essay's (each gate entered gets a fresh world of its two beams at rest,
 * the body's state carried over; the trace then sees that world's state
 * unless rec->trace_whole).
 * Returns BSIM_OK (an unstable trial included: its outcome says so),
 * BSIM_EINPUT (backend options) or BSIM_EFAIL (out of memory, in the
 * runner, the schedule or the backend's step: never a result). */
BSIM_API int bsim_trial_run(bsim_trial_runner *r, const bsim_scene *scene,
                            const bsim_backend *backend, const bsim_options *opts, uint64_t seed,
                            const bsim_recorder *rec, bsim_trial_result *out, bsim_error *err);

BSIM_API const char *bsim_trial_outcome_name(bsim_outcome o);
BSIM_API const char *bsim_trial_type_name(bsim_type t);

/* Why trial r (run with time step dt, s) is unstable, in one line:
 * "non-finite state at step 512 (t = 2.048 s)", "energy created: ledger
 * residual 3.67e+06 J > 1 x 1061 J that flowed in" or "energy vanished:
 * ledger residual -5e+39 J < -0.75 x 5e+39 J that flowed in"; "" if it is
 * not. */
BSIM_API void bsim_trial_instability_text(const bsim_trial_result *r, double dt, char *buf,
                                          size_t size);

#ifdef __cplusplus
}
#endif
#endif
