/* The essay's collision + constraint solver ("thesis" backend): internal
 * types shared by its files. docs/model.md sections 2-5.
 *
 * Sign conventions. Beam i turns about its pivot P_i; theta_i > 0 swings the
 * tip forward (+y). Its direction is u = R(sgn * theta) u0, with u0 the rest
 * direction and sgn = +1 if the forward swing is counter-clockwise (a beam
 * pointing right, like the left beam) and -1 otherwise. For a contact with
 * unit normal n (beam -> body) at lever a = Q - P, the generalised lever is
 * c = sgn (a x n): the body's normal velocity gains P/M per impulse P and
 * the beam's omega loses P c / I, and v_rel = v . n - omega c.
 *
 * A body that turns (body.rotates) or is not a disk, or a scene with
 * contact friction, takes the extended path (w->model->extended). The body has
 * heading psi and angular velocity w (rad, rad/s, counter-clockwise) and
 * inertia J; the contact point on its outline is r_b from its centre; the
 * tangent is t = perp(n) = (-n_y, n_x). Each contact then has two rows, the
 * normal and the tangent, each a velocity of the body's contact point
 * relative to the beam's:
 *   v_n = v . n + w cb  - omega c,    cb  = r_b x n,  c  = sgn (a x n)
 *   v_t = v . t + w cbt - omega ct,   cbt = r_b x t = r_b . n,
 *                                     ct  = sgn (a x t) = sgn (a . n)
 * and impulses P_n along n and P_t along t change
 *   v += (P_n n + P_t t) / M,  w += (P_n cb + P_t cbt) / J,
 *   omega -= (P_n c + P_t ct) / I.
 * A disk has r_b = -R n: cb = 0 and cbt = -R. A body that does not turn
 * has 1/J = 0 in every solve (w->model->inv_body_inertia). */
#ifndef BSIM_THESIS_THESIS_H
#define BSIM_THESIS_THESIS_H

#include <math.h>

#include "beamsim/backend.h"
#include "beamsim/contact_flag.h"
#include "util/fminmax.h"

/* A function written once for any body with a constant `extended` and
 * called with 1 (any body) and 0 (the essay's disk, w->model->extended 0): always
 * inlined, so that each copy is compiled for its constant and the disk's
 * has none of the extended path's tests. */
#if defined(__GNUC__)
#define THESIS_SPECIALISED static inline __attribute__((always_inline))
#else
#define THESIS_SPECIALISED static inline
#endif
/* A function kept apart from its caller (thesis_world.c's two copies of
 * the step), so that the caller's short path saves no registers for it. */
#if defined(__GNUC__)
#define THESIS_APART static __attribute__((noinline))
#else
#define THESIS_APART static
#endif

/* The geometry of the body against one beam at one configuration: the
 * body's centre x and the beam's angle theta it was computed at, and the
 * nearest point's distance, normal and lever (contact_geometry.h). */
typedef struct thesis_geometry {
	double x[2], theta; /* m, rad; theta NaN: none computed yet */
	int type;           /* BSIM_CONTACT_TANGENT or _TIP; NONE: centre on an end */
	double dist;        /* centre to segment, m */
	double n[2];        /* unit normal from the beam toward the body */
	double c;           /* generalised lever sgn (a x n), m */
	double a[2];        /* the beam's lever Q - P, m */
	/* The extended path's (a shape other than the disk): the heading the
	 * geometry was computed at, rad, and the levers cb, cbt, ct, m. */
	double psi, cb, cbt, ct;
	/* A capsule resting along the beam touches it at both ends of its core:
	 * the second end's contact (has2), in the same terms. */
	int has2, type2;
	double dist2, n2[2], c2, cb2, cbt2, ct2;
} thesis_geometry;

/* A beam's part of the world's changing data: its angle and angular
 * velocity, and what a step keeps of them to compute less. */
typedef struct thesis_beam {
	double theta; /* rad */
	double omega; /* rad/s */
	/* For the step size the world's h_prepared names: the midpoint rule's D
	 * and the response 1/(I D) (beam_integrate.h), computed once rather
	 * than per use. */
	double d, response;
	/* The direction at angle u_theta (contact_geometry.h): detection and the
	 * projection's re-detection of one step meet the same angle. */
	double u_theta; /* rad */
	double u[2];
	/* The last geometry computed against the body: reused when nothing
	 * moved, and a bound on the distance when something did. */
	thesis_geometry geo;
} thesis_beam;

/* A beam's part of the model (thesis_model): what its definition fixes.
 * As long as a thesis_beam (the rest unused): a beam's offset into the
 * model's array and into the data's is one product, which the step's
 * loops compute once for both (9 instructions a step less on H1 than
 * with its own size, docs/performance.md). */
typedef struct thesis_beam_model {
	union {
		struct {
			double p[2];    /* pivot, m */
			double u0[2];   /* rest direction, exact for multiples of 90 degrees */
			double sgn;     /* +1: forward swing is counter-clockwise */
			double length;  /* m */
			double reach;   /* L + R, m: the reach tests' L + R + margin, summed once */
			double inertia; /* kg m^2 about the pivot */
			double stiffness;   /* N m/rad */
			double damping;     /* N m s/rad */
			double inv_inertia; /* 1/I, 1/(kg m^2) */
		};
		thesis_beam size_;
	};
} thesis_beam_model;
_Static_assert(sizeof(thesis_beam_model) == sizeof(thesis_beam),
               "a beam's model and data index alike");

typedef struct thesis_contact {
	int beam;
	int type;          /* BSIM_CONTACT_TANGENT or BSIM_CONTACT_TIP */
	double gap;        /* distance to the segment minus R, m (< 0: penetration) */
	double n[2];       /* unit normal from the beam toward the body */
	double c;          /* generalised lever sgn (a x n), m */
	double inv_i;      /* 1/I for impacts and projection, 1/(I D) in a step */
	double e;          /* restitution of this contact */
	double vrel;       /* relative normal velocity, m/s (< 0: approaching) */
	double omega_free; /* the beam's omega at the step's end without contact, rad/s */
	double bound;      /* lower bound on the solved velocity, m/s */
	double impulse;    /* N s */
	/* The extended path's (thesis.h's head): the body's levers cb, cbt and
	 * the beam's tangent lever ct, m; the tangent row's relative velocity,
	 * m/s, and impulse, N s; the Coulomb coefficient mu. */
	double cb, cbt, ct;
	double vrel_t, impulse_t;
	double mu;
	/* 1: one of a capsule's two contacts with its beam (contact_geometry.h),
	 * whose impulses both turn the beam: K couples the pair. */
	int two;
} thesis_contact;

/* The broad phase's uniform grid over the pivots (broad_phase.c). */
typedef struct thesis_grid {
	double origin[2]; /* m, corner of cell (0, 0) */
	double cell;      /* m, cell side, >= the largest beam reach L + R */
	int nx, ny;       /* cells */
	int *start;       /* nx ny + 1 offsets into items */
	int *items;       /* beam indices, ascending within a cell */
} thesis_grid;

enum { THESIS_MIDPOINT = 0, THESIS_EULER = 1 };
enum { THESIS_SIMULTANEOUS = 0, THESIS_NEAREST_FIRST = 1 };
enum { THESIS_CONTACT_PHYSICAL = 0, THESIS_CONTACT_ESSAY = 1 };

/* The per-beam arrays of the model and of the data, listed once: part
 * (MODEL or DATA), name, element type, elements a beam and elements more
 * (thesis_world.c carves each part's from that part's one allocation, each
 * aligned for its type, zeroed). Their meanings are at their fields below.
 * The first of each part, the beams, is its struct's last member (its
 * address is the struct's plus a constant: no pointer to load); the
 * others follow. The
 * grid has at most 4 n + 16 cells (bsim_thesis_grid_build), and one offset
 * more. */
#define THESIS_BEAM_ARRAYS(MODEL, DATA)                                                            \
	MODEL(start_awake, int, 1, 0)                                                              \
	MODEL(grid.start, int, 4, 17)                                                              \
	MODEL(grid.items, int, 1, 0)                                                               \
	DATA(contacts, thesis_contact, 2, 0)                                                       \
	DATA(contact_of, int, 1, 0)                                                                \
	DATA(awake, int, 1, 0)                                                                     \
	DATA(is_awake, unsigned char, 1, 0)                                                        \
	DATA(candidates, int, 1, 0)                                                                \
	DATA(held, int, 1, 0)                                                                      \
	DATA(impulse, double, 1, 0)                                                                \
	DATA(pushed_list, int, 1, 0)                                                               \
	DATA(touched, unsigned char, 1, 0)                                                         \
	DATA(touched_list, int, 1, 0)                                                              \
	DATA(near, int, 1, 0)

/* The model: what the scene and the options fix when the world is made,
 * in one allocation, never changed after (the step reads it through a
 * const pointer; debug builds check its bytes, thesis_validate.c). */
typedef struct thesis_model {
	int n_beams;
	double mass, inv_mass; /* kg, 1/kg */
	/* m: the disk's radius; for another shape its reach (bsim_body_shape_reach),
	 * what every distance bound (broad phase, margins, sleep) needs. */
	double radius;
	/* The extended path (thesis.h's head): 1 if the body turns, is not a
	 * disk, or contacts have friction; the body's shape, whether it turns,
	 * its inertia J and 1/J (0 if it does not turn: no solve turns it),
	 * kg m^2, and the contacts' Coulomb mu. */
	int extended, shaped, rotates;
	bsim_body_def body;
	double body_inertia, inv_body_inertia;
	double friction;
	/* 1/impact_mass, 1/kg: the body's inverse mass in the impact solve
	 * only (impact_resolve.h); 1/M unless the knob is given. */
	double impact_inv_mass;
	double e_tangent, e_tip; /* restitution */
	double rest_threshold;   /* m/s */
	/* knobs */
	int integrator, impact_order, projection, contact_mode;
	/* 1: the essay's disk (extended 0) with contact_mode physical, whose
	 * free flight thesis_step takes at once. */
	int flight_disk;
	/* 1: a world the runs of steps take (bsim_thesis_steps_takes). */
	int steps_disk;
	double slop;         /* penetration tolerated before projection, m */
	double contact_tol;  /* gap the solver counts as touching (held, awake), m */
	int broad_phase;     /* 1: grid query for beams at rest; 0: test every beam */
	int sleep;           /* 1: beams below sleep_energy, body far, are put to rest */
	double sleep_energy; /* J */
	thesis_grid grid;    /* built when broad_phase is 1 */
	/* The beams the scene starts awake (theta or omega not 0), ascending:
	 * what a reset wakes. */
	int *start_awake;
	int n_start_awake;
	thesis_beam_model beams[]; /* n_beams */
} thesis_model;

/* The world: its model, and the data a step changes, in one allocation
 * (the struct and its per-beam arrays). */
struct bsim_world {
	/* First, 16-byte aligned as the allocation is: the body's moves and
	 * get_state's copy are two doubles at a time. */
	double x[2], v[2];         /* body centre and velocity */
	double heading;            /* rad, psi */
	double angular_velocity;   /* rad/s, w (next to the heading: get_state copies them) */
	const thesis_model *model; /* its own allocation, freed with the world */
	/* Friction impacts whose Newton impulse would have gained energy and
	 * was scaled toward the plastic one (impact_resolve.h), since creation. */
	long impacts_scaled;
	/* After a try at free flight that made no step (the body near a beam,
	 * say), the steps left before the next try, and the wait after the last
	 * failure: doubled by each, to THESIS_FLIGHT_WAIT_MAX, 0 after a run
	 * (thesis_advance). Which steps are tried changes no result, only what
	 * a stretch near the beams costs. */
	int flight_skip, flight_wait;
	/* Awake beams: every beam with theta or omega not exactly 0 or a
	 * contact this step is listed (ascending); the others are at rest and
	 * cost nothing (beam_sleep.c). */
	int *awake;
	int n_awake;
	unsigned char *is_awake; /* per beam */
	int *candidates;         /* per step: beams to test, ascending */
	/* The step's contacts: after a step, those within contact_tol where it
	 * ended (position_project.h). */
	thesis_contact *contacts; /* 2 n_beams capacity: a capsule has up to two
	                           * contacts with one beam (contact_geometry.h) */
	int n_contacts;
	/* The beams' contact markers, each kept because the physics reads it
	 * and nothing else holds it (thesis_validate.c checks them):
	 *   contact_of: per beam, its index in contacts, or -1. Between steps,
	 *     set for the beams of the last step's contacts (in contact where
	 *     it ended: kept awake, kept from sleeping, beam_sleep.c), cleared
	 *     from that list when the next step starts; within the smooth
	 *     solve, its contacts' (persistent_contact.h). It stands for the
	 *     contact type a beam had and for a list of the beams in contact:
	 *     the type is the contact's, the list is contacts.
	 *   is_awake: per beam, 1 if listed in awake (the list's membership,
	 *     so that waking a beam costs no search).
	 *   held: per beam, contact_mode=essay only: held in persistent
	 *     contact by the last solve (while any is, the next step tests only
	 *     held beams: essay_hold); the projection after that solve
	 *     overwrites the contacts' impulses, so it is kept apart.
	 *   impulse: per beam, the sum of its normal pushes (impact and
	 *     persistent contact, N s, each > 0) in the last step, 0 if none:
	 *     > 0 is what the state reports as touched, and decides with the
	 *     gap the beams listed (contact_list.h); pushed_list lists the
	 *     beams where it is > 0, so that the next step clears them.
	 *   touched: per beam, below (what a reset restores). */
	int *contact_of;
	int *held;
	int any_held;
	int *pushed_list;
	double *impulse;
	int n_pushed;
	bsim_step_energy energy;
	int impacts;
	bsim_solver_counts solver; /* since creation */
	double h_prepared;         /* the step size the beams' constants are for, s */
	/* What a reset (thesis_world.c) puts back: the beams whose angle,
	 * contact or geometry a step or a state may have changed since the
	 * world was made or last reset (woken or measured), every beam after
	 * set_state. */
	unsigned char *touched; /* per beam */
	int *touched_list;
	int n_touched;
	int touched_all;
	/* Debug builds: where the next validation's scan of the field starts,
	 * and its check of the model's bytes (thesis_validate.c). */
	int validate_from;
	size_t model_size, model_from;
	unsigned long long model_sum, model_sum_run;
	/* The broad phase's candidate cache (broad_phase.c): every beam whose
	 * pivot lies within L + R + near_reach of near_x, from one grid query. */
	int *near;
	int n_near;
	double near_x[2];  /* m */
	double near_reach; /* m; 0: no cache */
	/* The room of bsim_thesis_broad_phase_clear: every beam at rest lies
	 * farther than R + clear_room from clear_x (0: none known). */
	double clear_x[2];   /* m */
	double clear_room;   /* m */
	thesis_beam beams[]; /* model->n_beams */
};

/* Beam i may differ from how the world was made: a reset restores it. */
static inline void thesis_beam_touch(struct bsim_world *w, int i)
{
	if (w->touched[i])
		return;
	w->touched[i] = 1;
	w->touched_list[w->n_touched++] = i;
}

/* broad_phase.c */
/* A world of this many beams or fewer tests them all: the grid's query
 * costs more than the few reach tests it would save (the essay's gate has
 * two beams), and the result is the same bit for bit. */
#define THESIS_BROAD_PHASE_MIN_BEAMS 8
void bsim_thesis_near_forget(struct bsim_world *w);
/* The grid over model m's pivots, into its arrays (thesis_world.c sizes
 * them): at model creation. */
void bsim_thesis_grid_build(thesis_model *m);
int bsim_thesis_broad_phase(struct bsim_world *w, double speed, double h);
/* Fills w->candidates with every beam whose pivot may be within L + R +
 * margin of the body's centre now (awake or not); returns how many. */
int bsim_thesis_broad_phase_near(struct bsim_world *w, double margin);
/* 1 if no beam, all at rest, can reach the body this step (a world the
 * broad phase tests whole only; never with broad_phase=0); 0 if one may. */
int bsim_thesis_broad_phase_clear(struct bsim_world *w, const double force[2], double h);

/* thesis_flight.c: up to n steps of free flight, step k under
 * schedule[k], each state into out[k]; returns how many (0: the next step
 * is not one). */
int bsim_thesis_flight(struct bsim_world *w, const bsim_wrench *schedule, double h, int n,
                       bsim_state *out);
#define THESIS_FLIGHT_WAIT_MAX 64

/* thesis_steps.c: runs of steps of advance, for the worlds bsim_thesis_steps_takes
 * (1: the essay's disk, physical contacts, simultaneous impacts, no
 * sleeping, at most THESIS_STEPS_BEAMS beams): n steps, step k under
 * schedule[k], each state into out[k] (sized for the world's beams);
 * returns n, 0 for another world. */
#define THESIS_STEPS_BEAMS THESIS_BROAD_PHASE_MIN_BEAMS
int bsim_thesis_steps_takes(const thesis_model *m);
int bsim_thesis_steps(struct bsim_world *w, const bsim_wrench *schedule, double h, int n,
                      bsim_state *out);

/* thesis_validate.c: asserts the world's invariants, and seals its model
 * once made (its bytes' checksum, which every validation checks in part);
 * debug builds; under NDEBUG nothing, not even a call. */
#ifdef NDEBUG
static inline void bsim_thesis_validate(struct bsim_world *w)
{
	(void)w;
}
static inline void bsim_thesis_model_seal(struct bsim_world *w)
{
	(void)w;
}
#else
void bsim_thesis_validate(struct bsim_world *w);
void bsim_thesis_model_seal(struct bsim_world *w);
#endif

/* beam_sleep.c */
void bsim_thesis_beam_wake(struct bsim_world *w, int i);
void bsim_thesis_beams_sleep(struct bsim_world *w, double speed, double h);
void bsim_thesis_awake_prune(struct bsim_world *w);

/* contact_detect.c */
/* The contacts of beam i within margin into out (room for 2); returns how
 * many (0, 1, or 2 for a capsule along the beam). */
int bsim_thesis_contact_detect(struct bsim_world *w, int i, double margin, thesis_contact *out);
/* Each _disk function below: the same for the essay's disk (w->model->extended 0)
 * only, compiled without the extended path's tests and stores (a contact's
 * extended fields are not set); thesis_step picks once a step. */
int bsim_thesis_contact_detect_disk(struct bsim_world *w, int i, double margin,
                                    thesis_contact *out);
/* The same for a beam the step found in contact (the projection's
 * re-detection): disk_detect's near, the same result. */
int bsim_thesis_contact_redetect_disk(struct bsim_world *w, int i, double margin,
                                      thesis_contact *out);
/* shape_contact.c: a body of another shape than the disk against beam b of
 * direction u (thesis_beam_direction), into b->geo; and a capsule's second contact with the beam of
 * geometry g into out[1] (out[0] the first) if within margin: 1, else 0. */
void bsim_thesis_shape_geometry(const struct bsim_world *w, const thesis_beam_model *bm,
                                thesis_beam *b, const double u[2]);
int bsim_thesis_shape_second(const struct bsim_world *w, const thesis_geometry *g, double margin,
                             thesis_contact *out);
/* 0 if beam i certainly lies farther than R + margin from the body (its
 * reach, or the bound from its last geometry), 1 if it may not. */
int bsim_thesis_contact_near(const struct bsim_world *w, int i, double margin);
int bsim_thesis_contact_near_disk(const struct bsim_world *w, int i, double margin);

/* lcp_solve.c: 1 if the solve stopped at its iteration limit (the caller
 * counts it in w->solver), else 0. inv_mass is the body's 1/M, 1/kg (for
 * impacts, 1/impact_mass). */
int bsim_thesis_lcp_solve(double inv_mass, thesis_contact *cs, int n);
/* bsim_thesis_lcp_solve with the body's rotation: 1/J (inv_j) in K, and a
 * capsule's two contacts on one beam coupled; bsim_thesis_lcp_solve is the
 * essay's disk's (neither). */
int bsim_thesis_lcp_solve_j(double inv_mass, double inv_j, thesis_contact *cs, int n);
/* The same problem on the extended path: 1/J (the body's rotation, inv_j =
 * 0: none) in K, and with friction (any contact's mu > 0) the tangent rows
 * too (friction_solve.c); 1 if the solve was not exact (counted by the
 * caller in w->solver.iteration_limit). */
int bsim_thesis_contact_solve(double inv_mass, double inv_j, thesis_contact *cs, int n);
/* The impulses' sum on the body: sum P_n n + P_t t (N s) into j, and their
 * moment sum P_n cb + P_t cbt (N m s) into *jw. */
void bsim_thesis_impulse_sum_extended(const thesis_contact *cs, int n, double j[2], double *jw);
/* Solves with more than 2 contacts that fell back to Gauss-Seidel, all
 * worlds, since the program started. */
long bsim_thesis_lcp_fallbacks(void);

/* position_project.h: projections per step at most. */
#define THESIS_PROJECT_PASSES_MAX 3

/* The kinetic energy of body and beams, J; inline, so that the world
 * (thesis_world.c) and the impacts (impact_resolve.h) share it without
 * calling into each other. Beams at rest have omega = 0 and add nothing:
 * the awake ones, in ascending order, give the sum over all beams to the
 * bit. extended: a constant, 0 for the essay's disk (w->model->extended 0),
 * whose copy has no test of the body's rotation. */
static inline double thesis_kinetic_energy(const struct bsim_world *w, const int extended)
{
	double e = 0.5 * w->model->mass * (w->v[0] * w->v[0] + w->v[1] * w->v[1]);
	for (int k = 0; k < w->n_awake; k++) {
		const int i = w->awake[k];
		e += 0.5 * w->model->beams[i].inertia * w->beams[i].omega * w->beams[i].omega;
	}
	if (extended && w->model->rotates)
		e += 0.5 * w->model->body_inertia * w->angular_velocity * w->angular_velocity;
	return e;
}

/* The beam integrator, inline (beam_integrate.h). */
#include "thesis/beam_integrate.h"

/* Every beam's constants for steps of h (thesis_beam_prepare), unless they
 * are for h already. */
static inline void thesis_beams_prepare(struct bsim_world *w, double h)
{
	if (h == w->h_prepared)
		return;
	for (int i = 0; i < w->model->n_beams; i++)
		thesis_beam_prepare(&w->model->beams[i], &w->beams[i], h);
	w->h_prepared = h;
}

/* How far beam i and the body can close within a step (broad_phase.c
 * derives it), m; inline: every step asks it of every beam in reach. */
static inline double thesis_step_margin(const struct bsim_world *w, const thesis_beam_model *bm,
                                        const thesis_beam *b, double speed, double h)
{
	/* At rest the formula below is 2 h |v| + slop exactly (every other
	 * term is +0), without its division. The test is theta == 0 and omega
	 * == 0 (false for NaN too), written as one comparison: as two, the
	 * runs of steps kept the first's result as a value, 4 instructions a
	 * step more on H1 (docs/performance.md). */
	if (fabs(b->theta) + fabs(b->omega) == 0.0)
		return 2.0 * (h * speed) + w->model->slop;
	double accel = bm->length *
	               (bm->stiffness * fabs(b->theta) + bm->damping * fabs(b->omega)) /
	               bm->inertia;
	return 2.0 * (h * (speed + bm->length * fabs(b->omega)) + h * h * accel) + w->model->slop;
}

/* With every beam at rest the step's margin is 2 h |v| + slop, |v| = |v| +
 * h |F| / M from two square roots. |a| + |b| >= sqrt(a^2 + b^2) bounds
 * both without them; the factor 1 + 1e-12 covers the square roots'
 * rounding, so a beam out of reach of the bound is out of reach of the
 * margin, and the test changes no result. The contact flag's tolerance is
 * added, so that a clear step also ends more than BSIM_CONTACT_TOL from
 * every beam (contact_list.h). m. */
static inline double thesis_clear_margin(const struct bsim_world *w, const double force[2],
                                         double h)
{
	double speed = (fabs(w->v[0]) + fabs(w->v[1])) +
	               h * (fabs(force[0]) + fabs(force[1])) * w->model->inv_mass;
	return 2.0 * (h * (speed * (1.0 + 1e-12))) + w->model->slop + BSIM_CONTACT_TOL;
}

/* bsim_thesis_broad_phase_clear with its room's test inline, so that a step in
 * free flight is decided without a call: the same answer. */
static inline int thesis_flight_clear(struct bsim_world *w, const double force[2], double h)
{
	if (w->model->broad_phase && w->model->n_beams <= THESIS_BROAD_PHASE_MIN_BEAMS &&
	    fabs(w->x[0] - w->clear_x[0]) + fabs(w->x[1] - w->clear_x[1]) +
	                    thesis_clear_margin(w, force, h) <
	            w->clear_room)
		return 1;
	return bsim_thesis_broad_phase_clear(w, force, h);
}

/* Beam i exchanged a nonzero normal impulse (N s) with the body in this
 * step (the state reports it as touched, and the impulses' sum in the
 * order they came; contact_list.h lists the beam). */
static inline void thesis_beam_pushed(struct bsim_world *w, int i, double impulse)
{
	if (w->impulse[i] > 0.0) {
		w->impulse[i] += impulse;
		return;
	}
	w->impulse[i] = impulse;
	w->pushed_list[w->n_pushed++] = i;
}

/* The last step's pushes spent (the state reports them as touched until
 * the next step): at the start of a step. */
static inline void thesis_contact_spent(struct bsim_world *w)
{
	for (int k = 0; k < w->n_pushed; k++)
		w->impulse[w->pushed_list[k]] = 0.0;
	w->n_pushed = 0;
}

/* The body's velocity at the step's end from its free velocity vf = v +
 * h F / M (v0 = v at the start) and the contacts' impulse sum j, and its
 * move by the mean velocity (persistent_contact.h); vm receives that
 * velocity. Inline: the contact solve, a step in free flight (j = 0) and
 * the runs of steps (thesis_steps.c) share it, so all move the body by the
 * same operations. integrator: w->model->integrator, a constant where the caller
 * gives one. */
static inline void thesis_body_advance(struct bsim_world *w, const double v0[2], const double vf[2],
                                       const double j[2], double h, double vm[2], int integrator)
{
	w->v[0] = vf[0] + j[0] * w->model->inv_mass;
	w->v[1] = vf[1] + j[1] * w->model->inv_mass;
	vm[0] = 0.5 * (v0[0] + w->v[0]);
	vm[1] = 0.5 * (v0[1] + w->v[1]);
	if (integrator == THESIS_EULER) {
		vm[0] = w->v[0];
		vm[1] = w->v[1];
	}
	w->x[0] += h * vm[0];
	w->x[1] += h * vm[1];
}

/* The body's turn over a step from angular velocity w0 under torque
 * (N m) and the contacts' moment sum jw (N m s): J w' = J w0 + h torque +
 * jw, and the heading moves by the mean angular velocity (midpoint), or by
 * w' (euler), as the centre does (thesis_body_advance). */
static inline void thesis_body_turn(struct bsim_world *w, double w0, double torque, double jw,
                                    double h)
{
	if (!w->model->rotates)
		return;
	w->angular_velocity = w0 + (h * torque + jw) * w->model->inv_body_inertia;
	double wm = w->model->integrator == THESIS_EULER ? w->angular_velocity
	                                                 : 0.5 * (w0 + w->angular_velocity);
	w->heading += h * wm;
}

/* v_rel = v . n - omega c (contact_geometry.h); on the extended path plus
 * w cb, and the tangent row's v_t (extended: a constant, 0 for the essay's disk). */
static inline void thesis_contact_velocity(const struct bsim_world *w, thesis_contact *c,
                                           const int extended)
{
	c->vrel = (w->v[0] * c->n[0] + w->v[1] * c->n[1]) - w->beams[c->beam].omega * c->c;
	if (extended && w->model->extended) {
		c->vrel += w->angular_velocity * c->cb;
		c->vrel_t = (w->v[1] * c->n[0] - w->v[0] * c->n[1]) + w->angular_velocity * c->cbt -
		            w->beams[c->beam].omega * c->ct;
	}
}

/* The first pass of the impacts (impact_resolve.h) over the step's nc
 * contacts: each one's v_rel, and the touching ones (gap + h min(v_rel, 0)
 * <= slop) moved to the front in place, their 1/I set; *approaching set if
 * one of them approaches (v_rel < 0). Returns how many touch. Inline: the
 * runs of steps (thesis_steps.c) make it too. extended: a constant, 0 for
 * the essay's disk. */
THESIS_SPECIALISED int thesis_impacts_touching(struct bsim_world *w, int nc, double h,
                                               int *approaching, const int extended)
{
	thesis_contact *cs = w->contacts;
	int n = 0;
	*approaching = 0;
	for (int i = 0; i < nc; i++) {
		/* In place: a contact left behind has its velocity and 1/I set
		 * again by the contact solve. Swapped only when out of place. */
		thesis_contact *c = &cs[i];
		thesis_contact_velocity(w, c, extended);
		if (c->gap + h * bsim_fmin(c->vrel, 0.0) > w->model->slop)
			continue;
		c->inv_i = w->model->beams[c->beam].inv_inertia;
		*approaching |= c->vrel < 0.0;
		if (i != n) {
			thesis_contact t = cs[n];
			cs[n] = *c;
			*c = t;
		}
		n++;
	}
	return n;
}

/* An impact's bound on contact c's solved normal velocity (impact_resolve.h):
 * -e v_rel, or 0 (plastic) below rest_threshold. */
static inline void thesis_impact_bound(const struct bsim_world *w, thesis_contact *c)
{
	c->bound = c->vrel < -w->model->rest_threshold ? -c->e * c->vrel : 0.0;
}

/* Whether pass `pass` of the projection (position_project.h) projects the
 * n contacts cs: 1 if one is deeper than slop and the passes are not used
 * up; at the limit, still too deep, the solver's iteration limit is
 * counted and 0 returned. */
static inline int thesis_project_more(struct bsim_world *w, const thesis_contact *cs, int n,
                                      int pass)
{
	int deep = 0;
	for (int k = 0; k < n; k++)
		deep |= cs[k].gap < -w->model->slop;
	if (!deep)
		return 0;
	if (pass == THESIS_PROJECT_PASSES_MAX) { /* still deeper than slop */
		w->solver.iteration_limit++;
		return 0;
	}
	return 1;
}

/* A projection's move (position_project.h) by the position impulses of
 * cs[0 .. n): each beam's angle and the body's centre, the springs' energy
 * change and the force's work over the shift booked into *correction. */
static inline void thesis_project_move(struct bsim_world *w, const thesis_contact *cs, int n,
                                       const double force[2], double *correction)
{
	double dx = 0.0, dy = 0.0, de = 0.0;
	for (int k = 0; k < n; k++) {
		thesis_beam *b = &w->beams[cs[k].beam];
		double theta = b->theta - cs[k].impulse * cs[k].c * cs[k].inv_i;
		de += 0.5 * w->model->beams[cs[k].beam].stiffness *
		      (theta * theta - b->theta * b->theta);
		b->theta = theta;
		dx += cs[k].impulse * cs[k].n[0];
		dy += cs[k].impulse * cs[k].n[1];
	}
	dx *= w->model->inv_mass;
	dy *= w->model->inv_mass;
	w->x[0] += dx;
	w->x[1] += dy;
	*correction += (force[0] * dx + force[1] * dy) - de;
}

/* The smooth solve (persistent_contact.h) for the essay's disk: contact
 * c's row against beam b, from the body's velocity v0 at the step's start
 * and its free velocity vf = v0 + h F / M: the beam's free omega, the
 * response 1/(I D), v_rel at the free velocities and the bound that keeps
 * the gap from closing. */
static inline void thesis_smooth_row(thesis_contact *c, const thesis_beam_model *bm,
                                     const thesis_beam *b, const double v0[2], const double vf[2],
                                     double h, int integrator)
{
	double vrel0 = (v0[0] * c->n[0] + v0[1] * c->n[1]) - b->omega * c->c;
	c->omega_free = thesis_beam_free_omega(bm, b, h, integrator);
	double gap = bsim_fmax(c->gap, 0.0);
	c->inv_i = thesis_beam_response(bm, b, integrator);
	c->vrel = (vf[0] * c->n[0] + vf[1] * c->n[1]) - c->omega_free * c->c;
	c->bound = integrator == THESIS_EULER ? -gap / h : -vrel0 - 2.0 * gap / h;
}

/* The smooth solve's advance of awake beam b for the essay's disk, with its
 * solved contact c (NULL: none) and the body's mean velocity vm: a beam at
 * rest without contact stays at rest; the dampers' loss added to *damper,
 * minus the contact impulse's work to *contact, J. */
static inline void thesis_smooth_beam(const thesis_beam_model *bm, thesis_beam *b,
                                      const thesis_contact *c, const double vm[2], double h,
                                      int integrator, double *damper, double *contact)
{
	if (!c && b->theta == 0.0 && b->omega == 0.0)
		return;
	double omega_new;
	if (!c) {
		omega_new = thesis_beam_free_omega(bm, b, h, integrator);
	} else {
		omega_new = c->omega_free - c->impulse * c->c * c->inv_i;
		double omega_m =
		        integrator == THESIS_EULER ? omega_new : 0.5 * (b->omega + omega_new);
		*contact -= c->impulse * ((c->n[0] * vm[0] + c->n[1] * vm[1]) - c->c * omega_m);
	}
	*damper += thesis_beam_advance(bm, b, omega_new, h, integrator);
}

/* get_state's body: its centre, velocity, heading and angular velocity;
 * a beam here is an angle about a fixed pivot (no drift). */
static inline void thesis_state_body(const struct bsim_world *w, bsim_state *s)
{
	/* In the order of both structs: three 16-byte moves. */
	s->x[0] = w->x[0];
	s->x[1] = w->x[1];
	s->v[0] = w->v[0];
	s->v[1] = w->v[1];
	s->heading = w->heading;
	s->angular_velocity = w->angular_velocity;
}

/* Detection's geometry and tests, inline (contact_geometry.h). */
#include "thesis/contact_geometry.h"

/* The solve of one or two contacts and the impulse sum, inline
 * (lcp_small.h). */
#include "thesis/lcp_small.h"

#endif
