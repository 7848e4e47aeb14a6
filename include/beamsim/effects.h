/* The effect pipeline (docs/architecture.md "Where a new thing goes"):
 * built once from the scene's list; an effect that is not listed is not in
 * the pipeline at all, so it costs nothing per step and a scene without
 * random force never draws. */
#ifndef BSIM_EFFECTS_H
#define BSIM_EFFECTS_H

#include <stdint.h>

#include "beamsim/base.h"
#include "beamsim/scene.h"
#include "beamsim/schedule.h"
#include "beamsim/state.h"

#ifdef __cplusplus
extern "C" {
#endif

#define BSIM_EFFECTS_MAX 8

/* The force and torque on the body an effect adds: f[0], f[1] the force on
 * its centre (N), f[2] the torque about it (N m, counter-clockwise). */
enum { BSIM_WRENCH = 3 };

/* How bsim_effects_force_at computes an effect's force: by its apply, or
 * inline for the two that every trial of the essay's scenes calls each
 * step (the same operations as their apply: the same bits). */
enum {
	BSIM_EFFECT_APPLY = 0,    /* apply */
	BSIM_EFFECT_CONSTANT = 1, /* param along axis (propulsion along y) */
	BSIM_EFFECT_HELD = 2      /* last along axis while step n is in [held[0], held[1]) at
	                           * step size held_h (the held random force), else apply */
};

typedef struct bsim_effect {
	const char *name;
	int kind; /* BSIM_EFFECT_* */
	/* Adds this effect's force and torque on the body at step n of size h
	 * (s) into f (BSIM_WRENCH), given the body's motion at the step's
	 * start: s's position x, velocity v, heading and angular_velocity (the
	 * other fields of s are not read); f holds what the effects before it
	 * in the pipeline gave. */
	void (*apply)(struct bsim_effect *e, long n, double h, const bsim_state *s, double f[3]);
	int axis;                /* the body axis the force acts along: 0 = x, 1 = y */
	double param;            /* force or magnitude, N */
	bsim_schedule *schedule; /* random_force only */
	double last;             /* last force value applied along its axis, N */
	/* The ou and white random forces (their schedule draws z_n ~ N(0,1),
	 * one per step): the step size h (s) the coefficients are for, the
	 * coefficients, and the ou force's value at step `at` (N). */
	double h;
	double coef[2];
	double value;
	long at;
	/* The effects booked on their own ledger lines (propulsion along the
	 * heading, oscillation, drag, ground friction): the body's mass (kg),
	 * the force applied in the step along x and y (N) and the torque (N m);
	 * the body's moment of inertia (kg m^2) for those that turn it. */
	double mass;
	double applied[2];
	double applied_torque;
	double inertia;
	/* The turning part's coefficient (angular drag's c_w, N m s/rad;
	 * ground friction's torque limit, N m) and the angular drag's step
	 * coefficient for h. */
	double param_turn;
	double coef_turn;
	/* BSIM_EFFECT_HELD: the steps over which last holds at step size
	 * held_h (s), as the schedule's bsim_schedule_at_step_held gives them. */
	long held[2];
	double held_h;
	/* Ground friction on a body that turns, the coupled model: the
	 * footprint and its limits (model/footprint_friction.h), else NULL. */
	struct bsim_footprint_friction *footprint;
	/* 1: the backend simulates this effect itself (bsim_effects_init_taking):
	 * apply adds nothing, and the ledger books the loss the backend reports
	 * in the step's state (bsim_state drag_loss, friction_loss). */
	int taken;
} bsim_effect;

typedef struct bsim_effects {
	int n;
	bsim_effect e[BSIM_EFFECTS_MAX];
	bsim_effect *random; /* the random-force effect, or NULL */
	/* e[0 .. n_work) book their work along their axis (last) as w_prop or
	 * w_rand; e[n_work .. n) their work (applied over the displacement,
	 * applied_torque over the turn) on their own lines: the propulsion
	 * along the heading's w_prop, the oscillation's w_osc, the drag's and
	 * the ground friction's losses. */
	int n_work;
	bsim_effect *heading;     /* the propulsion along the heading, or NULL */
	bsim_effect *drag;        /* the drag effect, or NULL */
	bsim_effect *oscillation; /* the oscillation effect, or NULL */
	bsim_effect *friction;    /* the ground friction effect (the last), or NULL */
} bsim_effects;

/* 1 if the scene's effects draw random numbers, so that a trial depends on
 * its seed; 0 if every trial of the scene is the same trial. */
BSIM_API int bsim_effects_random(const bsim_scene *scene);

/* The effects a backend may simulate itself instead of taking their force
 * from the pipeline (bsim_backend.takes): viscous drag, ground friction
 * (where bsim_effects_friction_takeable). */
enum { BSIM_TAKES_DRAG = 1u, BSIM_TAKES_GROUND_FRICTION = 2u };

/* 1 if a backend that takes ground friction (BSIM_TAKES_GROUND_FRICTION)
 * takes this scene's: such a backend's friction is the decoupled model,
 * the sliding and the spinning each within its own limit, which is
 * Coulomb's for a body that does not turn; a body that turns gets it
 * only if the scene asks for it (effects.ground_friction.model:
 * decoupled). Else the pipeline gives ground friction on every backend. */
BSIM_API int bsim_effects_friction_takeable(const bsim_scene *scene);

/* Builds the pipeline from scene->effects; seed is the trial's mixed seed. */
BSIM_API int bsim_effects_init(bsim_effects *fx, const bsim_scene *scene, uint64_t seed);
/* bsim_effects_init for a backend that simulates the effects in taken
 * (BSIM_TAKES_*, its bsim_backend.takes) itself: those stay in the
 * pipeline, marked taken, so that the ledger books their losses on their
 * lines, but give no force or torque. taken 0 is bsim_effects_init. */
BSIM_API int bsim_effects_init_taking(bsim_effects *fx, const bsim_scene *scene, uint64_t seed,
                                      unsigned taken);
BSIM_API void bsim_effects_free(bsim_effects *fx);

/* BSIM_OK, or BSIM_EFAIL if an effect could not give its force (the random
 * force's schedule, bsim_schedule_status): the forces applied are not the
 * scene's, so the trial is not a result. */
BSIM_API int bsim_effects_status(const bsim_effects *fx, bsim_error *err);

/* Sum of all effects' forces and torques on the body at step n of size h
 * (s), in f (BSIM_WRENCH: force N, torque N m), the body's motion s at the
 * step's start. */
static inline void bsim_effects_force_at(bsim_effects *fx, long n, double h, const bsim_state *s,
                                         double f[3])
{
	f[0] = 0.0;
	f[1] = 0.0;
	f[2] = 0.0;
	/* The essay's pipeline, propulsion then the held random force, within
	 * a hold: the loop below unrolled, the same operations. */
	bsim_effect *e0 = &fx->e[0], *e1 = &fx->e[1];
	if (fx->n == 2 && e0->kind == BSIM_EFFECT_CONSTANT && e1->kind == BSIM_EFFECT_HELD &&
	    n >= e1->held[0] && n < e1->held[1] && h == e1->held_h) {
		f[e0->axis] += e0->param;
		e0->last = e0->param;
		f[e1->axis] += e1->last;
		return;
	}
	for (int i = 0; i < fx->n; i++) {
		bsim_effect *e = &fx->e[i];
		if (e->kind == BSIM_EFFECT_CONSTANT) {
			f[e->axis] += e->param;
			e->last = e->param;
		} else if (e->kind == BSIM_EFFECT_HELD && n >= e->held[0] && n < e->held[1] &&
		           h == e->held_h) {
			f[e->axis] += e->last;
		} else {
			e->apply(e, n, h, s, f);
		}
	}
}

/* bsim_effects_force_at for a body at rest at the origin, heading +x: the
 * same forces for a scene whose effects do not read the state (propulsion
 * along y, random force, oscillation). */
static inline void bsim_effects_force(bsim_effects *fx, long n, double h, double f[3])
{
#ifdef __cplusplus
	static const bsim_state rest{};
#else
	static const bsim_state rest;
#endif
	bsim_effects_force_at(fx, n, h, &rest, f);
}

/* The mean distance of the body's footprint from its centre, m: the
 * integral of |r| over the uniform body's area divided by the area (disk
 * 2R/3; capsule and ellipse by quadrature of the outline's radius rho(phi),
 * (1/A) integral of rho^3 / 3 dphi). Ground friction's torque limit on a
 * turning body is mu g M times this. */
BSIM_API double bsim_effects_spin_arm(const bsim_body_def *body);

#ifdef __cplusplus
}
#endif
#endif
