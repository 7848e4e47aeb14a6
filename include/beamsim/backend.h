/* The physics backend interface (DESIGN.md "The backend interface").
 *
 * A backend owns bodies, beams, joints (spring + damper), contacts and
 * integration; nothing else. The runner owns time, the external force on the
 * body, termination and recording, so that every backend runs the same
 * scenes with the same random-force schedules. */
#ifndef BEAMSIM_BACKEND_H
#define BEAMSIM_BACKEND_H

#include "beamsim/error.h"
#include "beamsim/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

enum { BSIM_CONTACT_NONE = 0, BSIM_CONTACT_TANGENT = 1, BSIM_CONTACT_TIP = 2 };

/* Energy flows of the last step, J, as measured by the backend. With the
 * runner's work of the external force they close the energy ledger:
 * dE = W_ext - damper - impact - contact - correction - sleep. */
typedef struct bsim_step_energy {
	double damper;     /* dissipated by the beam dampers (>= 0) */
	double impact;     /* lost in impacts, incl. plastic entry to rest (>= 0) */
	double contact;    /* -(work of persistent contact forces), ~0 */
	double correction; /* energy change from position correction */
	double sleep;      /* of beams put exactly to rest by sleeping (>= 0) */
} bsim_step_energy;

typedef struct bsim_state {
	double x[2]; /* body centre, m */
	double v[2]; /* body velocity, m/s */
	int n_beams;
	double *theta;           /* n_beams, rad, forward positive */
	double *omega;           /* n_beams, rad/s */
	int *contact;            /* n_beams, BSIM_CONTACT_* at the end of the step */
	bsim_step_energy energy; /* of the last step */
	int impacts;             /* impacts resolved in the last step */
	double pivot_drift;      /* m, largest distance of a beam's pinned point from
	                          * its pivot (0 where the pin is exact by construction) */
	/* The beams that may be away from rest, ascending: every beam not
	 * listed has theta = omega = 0 and no contact, and so have its entries
	 * in theta, omega and contact. A backend may list more than it must
	 * (all n_beams, say); readers that loop over active[] instead of all
	 * beams cost what the beams near the body cost. */
	int n_active;
	int *active; /* n_beams capacity */
} bsim_state;

int bsim_state_alloc(bsim_state *s, int n_beams);
void bsim_state_free(bsim_state *s);
void bsim_state_copy(bsim_state *dst, const bsim_state *src);
/* For a backend's get_state: zeroes the entries of the beams s lists now,
 * then lists the n given ones (ascending), whose entries the backend then
 * writes. Costs the two lists, not n_beams. */
void bsim_state_set_active(bsim_state *s, const int *active, int n);

/* Backend options: typed key/value knobs, `--backend-opt key=value`. */
#define BSIM_OPTIONS_MAX 16
typedef struct bsim_options {
	int n;
	char key[BSIM_OPTIONS_MAX][32];
	char value[BSIM_OPTIONS_MAX][64];
} bsim_options;

/* Parses "key=value" into opts (later wins). BSIM_EINPUT on bad syntax. */
int bsim_options_add(bsim_options *opts, const char *kv, bsim_error *err);
/* The value of key, or NULL. */
const char *bsim_options_get(const bsim_options *opts, const char *key);

typedef enum { BSIM_KNOB_INT, BSIM_KNOB_DOUBLE, BSIM_KNOB_CHOICE } bsim_knob_type;

typedef struct bsim_knob {
	const char *name;
	bsim_knob_type type;
	const char *default_value;
	const char *choices; /* "a|b|c" for BSIM_KNOB_CHOICE, else NULL */
	const char *help;
} bsim_knob;

/* Checks every option names a knob and parses as its type (BSIM_EINPUT
 * naming the option and what was expected otherwise). */
int bsim_options_check(const bsim_options *opts, const bsim_knob *knobs, int n_knobs,
                       const char *backend, bsim_error *err);
/* Typed look-ups with the knob's default. */
double bsim_options_double(const bsim_options *opts, const bsim_knob *knob);
long bsim_options_int(const bsim_options *opts, const bsim_knob *knob);
/* Index of the chosen value in knob->choices. */
int bsim_options_choice(const bsim_options *opts, const bsim_knob *knob);

typedef struct bsim_world bsim_world; /* opaque, one per backend */

typedef struct bsim_backend {
	const char *name;
	const char *description;
	const bsim_knob *knobs;
	int n_knobs;
	int (*create)(const bsim_scene *scene, const bsim_options *opts, bsim_world **out,
	              bsim_error *err);
	void (*destroy)(bsim_world *w);
	/* Advance one step of h seconds with force (N) on the body centre. */
	void (*step)(bsim_world *w, const double force[2], double h);
	void (*get_state)(const bsim_world *w, bsim_state *out);
	int (*set_state)(bsim_world *w, const bsim_state *s, bsim_error *err);
} bsim_backend;

/* The registry: all backends compiled in, NULL-terminated. */
const bsim_backend *const *bsim_backends(void);
/* By name; NULL and BSIM_EINPUT naming the known ones if unknown. */
const bsim_backend *bsim_backend_find(const char *name, bsim_error *err);

extern const bsim_backend bsim_backend_thesis;
extern const bsim_backend bsim_backend_box2d;

#ifdef __cplusplus
}
#endif
#endif
