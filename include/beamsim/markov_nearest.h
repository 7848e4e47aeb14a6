/* Nearest-neighbour walks: a lattice's final locations predicted from the
 * exact gate visits of training fields, without bins (docs/markov.md, "A
 * kernel over exact states").
 *
 * The visits. For each gate kind (stiffness pair) of the lattice, a
 * training field: a BSIM_MARKOV_TRAIN_SIZE-square field of the lattice's
 * kinds laid out at random, its start gate of that kind, the lattice's
 * physics under the essay's protocol, `trials` trials. Every gate a trial
 * entered is a visit: its kind, the edge it was entered through (or the
 * start) and the exact entry state (position along the edge, velocity, in
 * the gate's frame), and its exit: the state the trial entered the next
 * gate in, or stuck (the trial's last gate, held gate_steps steps). A gate
 * the trial left out of the field or ended in otherwise has no known exit
 * and is no visit; nor is any gate on the training field's last row or
 * outer columns, where a gate left out of the field would be dropped and
 * one stuck kept (so that the visits kept there would be stuck too often).
 * The visits depend on the lattice only through its set of kinds and its
 * physics: every layout of the same kinds shares them. They are cached in
 * a directory, a file per training field named by the hash of its key
 * (visits_HASH.csv and .key), reused where the key matches.
 *
 * A walk, under the essay's protocol as the chain: the start gate's exit
 * is one of its kind's start visits at random; then, in gate g of kind K
 * entered through edge e in state s, one of the k visits of kind K through
 * e nearest to s is drawn at random, and its exit is g's: stuck in g, into
 * the neighbour across the exit's edge in the exit's exact state, or out of
 * the field (the end, a side). The distance is in the default entry bins'
 * widths (position / (edge / 14), speed / (v_max / 6), direction / (pi /
 * 13)). A body leaving row 0 downwards enters it
 * again through its bottom, as in the chain. Walk w draws from
 * bsim_schedule_seed_mix(seed, w, gate): the same answer on any number of
 * threads. */
#ifndef BSIM_MARKOV_NEAREST_H
#define BSIM_MARKOV_NEAREST_H

#include <signal.h>
#include <stdint.h>
#include <stdio.h>

#include "beamsim/base.h"
#include "beamsim/backend.h"
#include "beamsim/error.h"
#include "beamsim/options.h"
#include "beamsim/progress.h"
#include "beamsim/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

struct bsim_markov_prediction; /* beamsim/markov.h */

/* One gate visit of a training field. */
typedef struct bsim_markov_visit {
	double k[2];      /* N m/rad, the gate's kind */
	int edge;         /* entered through (BSIM_EDGE_START: the trial's start) */
	double pos, v[2]; /* m, m/s: where along the edge, the velocity (gate frame) */
	int exit_edge;    /* the edge the next gate was entered through; 0: stuck */
	double exit_pos, exit_v[2];
	int steps; /* time steps in the gate (gate_steps if stuck) */
} bsim_markov_visit;

typedef struct bsim_markov_visits {
	long n;
	bsim_markov_visit *v; /* every training field's, in the order of the kinds */
	int fields;           /* training fields: the lattice's kinds */
	int built, reused;    /* of them run now, read from the directory */
	double cost;          /* s of CPU the fields took when they were run */
	long long steps;      /* their time steps */
	long left_out;        /* gates entered on the fields' last row and outer columns */
} bsim_markov_visits;

/* How the visits are had and the walks made. */
typedef struct bsim_markov_nearest_def {
	int trials; /* of each training field */
	int k;      /* visits a walk draws its step from */
	long walks; /* 1 to 1e8 */
	uint64_t seed;
	const bsim_backend *backend; /* NULL: the default backend */
	const bsim_options *opts;    /* NULL: no options */
	int threads;                 /* <= 0: all cores; the answer is the same for any */
	bsim_progress_fn progress;   /* may be NULL: counts the training fields' trials */
	void *progress_user;
	/* May be NULL: once nonzero no training trial starts, the fields
	 * finished are kept, and BSIM_ESTOPPED is returned. */
	const volatile sig_atomic_t *stop;
	/* 1: the directory is a build's (beamsim markov build), read only: a
	 * training field missing there is refused, naming what tells it from
	 * the nearest there. 0: a cache, the fields missing run into it. */
	int read_only;
} bsim_markov_nearest_def;

#define BSIM_MARKOV_NEAREST_TRIALS 10000
#define BSIM_MARKOV_NEAREST_K      20
#define BSIM_MARKOV_NEAREST_WALKS  200000
/* A walk still in the field after this many gates is a failure, said. */
#define BSIM_MARKOV_NEAREST_GATES 10000

/* BSIM_MARKOV_NEAREST_TRIALS, _K and _WALKS, seed 1, the default backend,
 * all cores. */
BSIM_API bsim_markov_nearest_def bsim_markov_nearest_def_default(void);

/* The visits of lattice's kinds, read from dir where a training field's key
 * is there, else run and written there (a field at a time, as it
 * finishes; with def->read_only refused). A key holds every input of the field: the physics (as a
 * map's key), the kinds, the start's, trials, seed and the file format.
 * BSIM_EINPUT if lattice is not a lattice or def is out of range, or a
 * file there is malformed (naming file and line); BSIM_EFAIL for an
 * unstable trial; BSIM_ESTOPPED. */
BSIM_API int bsim_markov_visits_build(const bsim_scene *lattice, const bsim_markov_nearest_def *def,
                                      const char *dir, bsim_markov_visits *out, bsim_error *err);
BSIM_API void bsim_markov_visits_free(bsim_markov_visits *v);

/* The final locations of lattice by def->walks walks over v (out's loc, p,
 * n_gates and p_gates, mean_gates; n_states: the visits; walks, has_time
 * 0). BSIM_EINPUT if a gate kind, or an edge of it a walk enters, has no
 * visit (naming it), or def->k or walks is out of range; BSIM_EFAIL if a
 * walk is still in the field after BSIM_MARKOV_NEAREST_GATES gates. */
BSIM_API int bsim_markov_nearest_predict(const bsim_scene *lattice, const bsim_markov_visits *v,
                                         const bsim_markov_nearest_def *def,
                                         struct bsim_markov_prediction *out, bsim_error *err);

/* The expected total variation between W walks' distribution and its own
 * limit, from the walks' p (n locations): sum sqrt(2 p (1 - p) / (pi W)) / 2,
 * the walks' sampling error beside a TV against the simulation. */
BSIM_API double bsim_markov_nearest_tv_walks(const double *p, int n, long walks);

#ifdef __cplusplus
}
#endif
#endif
