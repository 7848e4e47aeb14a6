/* The state a backend reports after each step (beamsim/backend.h): body,
 * beams, contacts, the step's energy flows, and the beams that may be away
 * from rest. The caller owns a state's storage: bsim_state_init sizes it for
 * a scene's beams, bsim_state_free releases it. */
#ifndef BSIM_STATE_H
#define BSIM_STATE_H

#include "beamsim/base.h"
#include "beamsim/error.h"

#ifdef __cplusplus
extern "C" {
#endif

enum { BSIM_CONTACT_NONE = 0, BSIM_CONTACT_TANGENT = 1, BSIM_CONTACT_TIP = 2 };

/* The contact flag, the same on every backend because the runner computes
 * it from the state's raw facts (bsim_contact_flags, beamsim/contact_flag.h):
 * beam i is in contact in a step (contact[i] not NONE) when at the step's
 * end the gap between the body's outline and the beam's segment is below
 * BSIM_CONTACT_TOL, or when the beam exchanged a nonzero impulse with the
 * body during the step (touched[i]: an impact is flagged on the step it
 * happens in). contact[i] is then the contact's type at the step's end:
 * TANGENT when the nearest point of the segment lies inside it, TIP at
 * either end. 6 mm: above the gaps at which the solvers hold a resting
 * contact, the thesis backend's within 1e-6 m, Box2D's anywhere below
 * b2_linearSlop / unit_scale = 5 mm (float32 adds 2e-6 m), Chipmunk's at an
 * overlap, and 0.06% of the body's radius (docs/backends.md, "The contact
 * flag"). */
#define BSIM_CONTACT_TOL 6e-3 /* m */

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

/* What a backend's solvers had to give up on, counted since the world was
 * created. A count is never a failure by itself: the runner reports it
 * (beamsim run warns, summary.json counts), and the trial's ledger and
 * finiteness checks still judge the trial (beamsim/trial.h). */
typedef struct bsim_solver_counts {
	long iteration_limit; /* solves that stopped at their iteration limit
	                       * before they converged */
	long clamped;         /* (sub)steps in which a motion was clamped to a
	                       * solver's limit (Box2D's b2_maxTranslation and
	                       * b2_maxRotation) */
} bsim_solver_counts;

typedef struct bsim_state {
	double x[2]; /* body centre, m */
	double v[2]; /* body velocity, m/s */
	/* The body's heading, rad from +x counter-clockwise (the scene's
	 * body.heading_deg at the start), and its angular velocity, rad/s:
	 * constant for a body that does not rotate. */
	double heading;
	double angular_velocity;
	int n_beams;
	double *theta;             /* n_beams, rad, forward positive */
	double *omega;             /* n_beams, rad/s */
	bsim_step_energy energy;   /* of the last step */
	int impacts;               /* impacts resolved in the last step */
	bsim_solver_counts solver; /* since the world was created */
	/* Raw facts of the active beams (below), from which the runner
	 * derives what it defines (the contact flag, the pivot drift):
	 *   touched[i]      1 if beam i exchanged a nonzero normal impulse
	 *                   with the body during the last step (an impact or
	 *                   a resting contact's impulse), else 0;
	 *   impulse[i]      N s, the normal impulse beam i exchanged with the
	 *                   body during the last step, summed over its
	 *                   contacts, impacts and resting contact alike (>= 0;
	 *                   > 0 exactly where touched; position corrections,
	 *                   which move no momentum, and friction not in it);
	 *   direction[2i..] the unit vector from beam i's pivot to its tip at
	 *                   the step's end (bsim_beam_direction of its angle),
	 *                   or NaN (both) for a beam not touched that the
	 *                   backend knows lies farther than BSIM_CONTACT_TOL
	 *                   from the body (its broad phase: no sine and cosine
	 *                   needed), which is then not in contact;
	 *   pin[2i..]       m, where beam i's joint holds it, the point that
	 *                   should be its pivot (not written by a backend
	 *                   whose pins are exact, bsim_backend.exact_pins). */
	int *touched;      /* n_beams */
	double *impulse;   /* n_beams */
	double *direction; /* 2 n_beams */
	double *pin;       /* 2 n_beams */
	/* The contact flag of each active beam (above), written by the runner
	 * from the raw facts (bsim_contact_flags), not by a backend. */
	int *contact; /* n_beams */
	/* The beams that may be away from rest, ascending: every beam not
	 * listed has theta = omega = 0 and no contact, and so have its entries
	 * in theta, omega and contact. A backend may list more than it must
	 * (all n_beams, say); readers that loop over active[] instead of all
	 * beams cost what the beams near the body cost. */
	int n_active;
	int *active; /* n_beams capacity */
	/* J, of the last step: taken by the drag and by the ground friction of
	 * a backend that simulates them itself (bsim_backend.takes), minus the
	 * work of their impulses over the body's displacement and turn; 0 (never
	 * written) on a backend that does not. */
	double drag_loss;
	double friction_loss;
} bsim_state;

/* Sizes s for n_beams beams, everything zero. BSIM_EFAIL out of memory
 * (s is then empty, and bsim_state_free on it is harmless). */
BSIM_API int bsim_state_init(bsim_state *s, int n_beams);
BSIM_API void bsim_state_free(bsim_state *s);
BSIM_API void bsim_state_copy(bsim_state *dst, const bsim_state *src);
/* For a backend's get_state: zeroes the entries of the beams s lists now,
 * then lists the n given ones (ascending), whose entries the backend then
 * writes. Costs the two lists, not n_beams. */
BSIM_API void bsim_state_set_active(bsim_state *s, const int *active, int n);

#ifdef __cplusplus
}
#endif
#endif
