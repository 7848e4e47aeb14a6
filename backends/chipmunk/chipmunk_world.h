/* Internal: the Chipmunk2D 7 backend's world (bsim_backend_chipmunk), shared
 * by its files:
 *   chipmunk_world.c    the world: bodies, joints, springs, the step, the
 *                       state, reset, the knobs and what check refuses
 *   chipmunk_contact.c  the collision handler: each contact's restitution,
 *                       friction and rest threshold, and what the solve did
 *   chipmunk_measure.c  what the runner defines and the backend reports:
 *                       energy flows, the contact flag, pivot drift
 * The model and its mapping onto Chipmunk are in chipmunk_world.c's head. */
#ifndef BSIM_CHIPMUNK_CHIPMUNK_WORLD_H
#define BSIM_CHIPMUNK_CHIPMUNK_WORLD_H

#include <chipmunk/chipmunk.h>

#include <stdint.h>

#include "beamsim/backend.h"

/* One beam: its Chipmunk body (origin and centre of gravity at the pivot),
 * segment, pin and damped rotary spring, and what a substep measures. */
typedef struct chip_beam {
	cpBody *body;
	cpShape *shape;
	cpConstraint *pin, *spring;
	double pivot[2]; /* m */
	double u0[2];    /* rest direction */
	double sgn;      /* Chipmunk angle = sgn theta (theta > 0 swings the tip to +y) */
	double inertia;  /* kg m^2 about the pivot */
	double stiffness, damping, length;
	/* before the substep in progress: Chipmunk angle (rad), angular
	 * velocity (rad/s), the centre's position (m) and velocity (m/s) */
	double a0, w0;
	cpVect p0, u0_v;
	/* the substep's contact with the body (chipmunk_contact.c): touched in
	 * it, the fastest approach at its start (m/s, > 0 approaching), the
	 * impulse the body took (N s), its normal part (>= 0), and the mean
	 * offset of the contact points on the body from those on the beam (m) */
	int touched;
	double approach;
	cpVect impulse_start; /* Chipmunk's total at the solve's start */
	int first;            /* the pair's first contact (no warm start) */
	cpVect impulse;
	double normal_impulse;
	cpVect offset;
	int pushed;   /* a nonzero normal impulse with the body in the step (the flag) */
	int reported; /* pushed in the last step, as the state reports it (touched) */
	/* the normal impulses of this step's pushes (every substep's), and
	 * those of the last step as the state reports them, N s */
	double impulse_step, impulse_reported;
} chip_beam;

struct bsim_world {
	bsim_scene scene; /* a copy: the world is rebuilt from it (reset, set_state) */
	/* knobs */
	int iterations, substeps;
	double slop, bias;
	int sleep; /* beams at rest start asleep */
	/* Chipmunk */
	cpSpace *space;
	cpBody *body;
	cpShape *body_shape;
	int n_beams;
	chip_beam *beams;
	int rotates;    /* the body turns: finite moment */
	double inertia; /* kg m^2, the body's (bsim_body_inertia) */
	double reach;   /* m, the outline's farthest point from the centre */
	/* Live beams, ascending: those that may have moved. A lattice lists
	 * only them in the state; elsewhere every beam is listed. */
	int track_live;
	int n_live;
	int *live;
	char *is_live;
	/* the contact flag (beamsim/contact_flag.h), which decides the beams
	 * listed, and the beams it set */
	int *contact_type;
	int n_typed;
	int *typed;
	int n_pushed;
	int *pushed; /* beams whose pushed is set */
	int n_reported;
	int *reported; /* beams whose reported is set */
	/* the substep in progress: the force (N) and torque (N m), the body
	 * before it (m, m/s, rad, rad/s) */
	double force[2], torque;
	cpVect x0, v0;
	double psi0, w0;
	/* Chipmunk's warm start factor dt / dt_last of the substep (0 after a
	 * space's first step: dt_last 0), and dt_last, s */
	double warm_coef, h_last;
	/* results of the last step */
	bsim_step_energy energy;
	int impacts;
	bsim_solver_counts solver; /* Chipmunk reports none: stays 0 */
	int diverged;              /* the motion left the range Chipmunk can step */
};

/* Beam i's index + 1 in its shape's user data; the body's shape holds 0. */
static inline int chip_beam_of(const cpShape *shape)
{
	return (int)(intptr_t)cpShapeGetUserData(shape) - 1;
}

/* Adds beam i to the ascending live list, its substep start read now (a
 * beam that was not live has not moved since it was built). Inline: the
 * collision handler and the measures call it. */
static inline void chipmunk_mark_live(struct bsim_world *w, int i)
{
	if (w->is_live[i])
		return;
	w->is_live[i] = 1;
	int k = w->n_live++;
	for (; k > 0 && w->live[k - 1] > i; k--)
		w->live[k] = w->live[k - 1];
	w->live[k] = i;
	chip_beam *b = &w->beams[i];
	b->a0 = cpBodyGetAngle(b->body);
	b->w0 = cpBodyGetAngularVelocity(b->body);
	b->p0 = cpBodyGetPosition(b->body);
	b->u0_v = cpBodyGetVelocity(b->body);
}

/* The ellipse of semi-axes a (along +x) and b as the body's polygon of n
 * vertices (chipmunk_world.c's head), into out[0 .. n). */
void bsim_chipmunk_ellipse_polygon(double a, double b, int n, cpVect *out);

/* The collision types of the body's shape and the beams' (set as the shapes
 * are made: setting one wakes a sleeping body), and their collision handler
 * (chipmunk_contact.c). */
enum { CHIP_TYPE_BODY = 1, CHIP_TYPE_BEAM = 2 };
void bsim_chipmunk_contact_install(struct bsim_world *w);

/* What the runner defines, measured after a substep of h (chipmunk_measure.c):
 * the energy flows into w->energy; after the step's last substep (last),
 * the contact flag of every beam and the pivot drift. */
void bsim_chipmunk_measure(struct bsim_world *w, double h, int last);

#endif
