/* Internal: the energy ledger of a trial (trial.h bsim_ledger, docs/model.md
 * section 10) and the two tests that find a trial's numbers untrustworthy
 * (bsim_instability). The runner calls the energies, the ledger's step and
 * the finiteness test every step: they are inline, so that its loop makes
 * no call for them.
 *
 * The energies visit only the beams the backend lists as active
 * (bsim_state.active: the others are exactly at rest), so in a lattice they
 * cost what the beams near the body cost. Summed over the active beams in
 * ascending order they are the sums over all beams to the bit (a beam at
 * rest adds +0). */
#ifndef BSIM_RUN_TRIAL_LEDGER_H
#define BSIM_RUN_TRIAL_LEDGER_H

#include <math.h>

#include "beamsim/effects.h"
#include "beamsim/trial.h"

/* Kinetic energy of body and beams, J: the body's translation, and its
 * rotation 1/2 J omega^2 if it turns. Beams at rest add nothing. */
static inline double energy_kinetic(const bsim_scene *sc, const bsim_state *s)
{
	double e = 0.5 * sc->body.mass * (s->v[0] * s->v[0] + s->v[1] * s->v[1]);
	if (sc->body.rotates)
		e += 0.5 * bsim_body_inertia(&sc->body) * s->angular_velocity * s->angular_velocity;
	for (int k = 0; k < s->n_active; k++) {
		int i = s->active[k];
		e += 0.5 * sc->beams[i].inertia * s->omega[i] * s->omega[i];
	}
	return e;
}

/* Elastic energy of the beam springs, J. */
static inline double energy_springs(const bsim_scene *sc, const bsim_state *s)
{
	double e = 0.0;
	for (int k = 0; k < s->n_active; k++) {
		int i = s->active[k];
		e += 0.5 * sc->beams[i].stiffness * s->theta[i] * s->theta[i];
	}
	return e;
}

/* The ledger's E: kinetic plus elastic, J. */
static inline double energy_mech(const bsim_scene *sc, const bsim_state *s)
{
	return energy_kinetic(sc, s) + energy_springs(sc, s);
}

/* Whether every number of s that can move is finite (one sum: a NaN or an
 * infinity anywhere makes it non-finite). A turning body's angular
 * velocity is in the kinetic energy the runner tests too, and its heading
 * moves only by it. */
static inline int state_finite(const bsim_state *s)
{
	double sum = s->x[0] + s->x[1] + s->v[0] + s->v[1];
	for (int k = 0; k < s->n_active; k++)
		sum += s->theta[s->active[k]] + s->omega[s->active[k]];
	return isfinite(sum);
}

/* energy_mech(sc, s) into *e and whether s is finite (state_finite, and e
 * too), in one pass over the active beams: the same operations in the
 * same order as the three, each sum kept apart. */
static inline int state_energy_finite(const bsim_scene *sc, const bsim_state *s, double *e)
{
	double kin = 0.5 * sc->body.mass * (s->v[0] * s->v[0] + s->v[1] * s->v[1]);
	if (sc->body.rotates)
		kin += 0.5 * bsim_body_inertia(&sc->body) * s->angular_velocity *
		       s->angular_velocity;
	double spring = 0.0;
	double sum = s->x[0] + s->x[1] + s->v[0] + s->v[1];
	for (int k = 0; k < s->n_active; k++) {
		int i = s->active[k];
		const double theta = s->theta[i], omega = s->omega[i];
		kin += 0.5 * sc->beams[i].inertia * omega * omega;
		spring += 0.5 * sc->beams[i].stiffness * theta * theta;
		sum += theta + omega;
	}
	*e = kin + spring;
	return isfinite(sum) && isfinite(*e);
}

/* What is left of a step's energy change e0 -> e1 when the work of the
 * forces (w_prop, w_rand) and the backend's losses se are booked, J. */
static inline double ledger_residual(double e0, double e1, double w_prop, double w_rand,
                                     const bsim_step_energy *se)
{
	return (e1 - e0) - (w_prop + w_rand - se->damper - se->impact - se->contact -
	                    se->correction - se->sleep);
}

/* The lines every step adds to, in L (an lvalue with bsim_ledger's names
 * for them: the ledger itself, or a run's copy of them held in locals,
 * trial.c's run_book), from the step's work w_prop, w_rand, losses se and
 * residual r. The largest |r| as bsim_fmax keeps it: |r| is never -0, and
 * residual_max, which starts at +0 and only ever takes a value of |r|,
 * neither -0 nor NaN, so it is the larger of the two, |r| NaN not taken. */
#define LEDGER_LINES_ADD(L, w_prop_, w_rand_, se_, r_)                                             \
	do {                                                                                       \
		const double r_abs_ = fabs(r_);                                                    \
		(L).w_prop += (w_prop_);                                                           \
		(L).w_rand += (w_rand_);                                                           \
		(L).damper += (se_)->damper;                                                       \
		(L).impact += (se_)->impact;                                                       \
		(L).contact += (se_)->contact;                                                     \
		(L).correction += (se_)->correction;                                               \
		(L).sleep += (se_)->sleep;                                                         \
		(L).residual += (r_);                                                              \
		(L).residual_abs += r_abs_;                                                        \
		(L).residual_max = r_abs_ > (L).residual_max ? r_abs_ : (L).residual_max;          \
		(L).inflow += fabs(w_prop_) + fabs(w_rand_);                                       \
	} while (0)

/* One step's entry in the ledger, s0 -> s1 with energies e0 -> e1: the work
 * of each force over the body's displacement and of each torque over its
 * turn, the backend's losses, and what is left over. The drag and ground
 * friction of a backend that simulates them (bsim_effect.taken) are booked
 * on their lines from the losses it reports (bsim_state drag_loss,
 * friction_loss). */
static inline void ledger_step(bsim_ledger *l, const bsim_effects *fx, const bsim_state *s0,
                               const bsim_state *s1, double e0, double e1)
{
	const double d[2] = {s1->x[0] - s0->x[0], s1->x[1] - s0->x[1]};
	double w_prop = 0.0, w_rand = 0.0;
	if (fx->n_work == 2 && fx->random == &fx->e[1]) {
		/* the essay's pipeline: the loop below unrolled */
		w_prop += fx->e[0].last * d[fx->e[0].axis];
		w_rand += fx->e[1].last * d[fx->e[1].axis];
	} else
		for (int i = 0; i < fx->n_work; i++) {
			double work = fx->e[i].last * d[fx->e[i].axis];
			if (&fx->e[i] == fx->random)
				w_rand += work;
			else
				w_prop += work;
		}
	const bsim_step_energy *se = &s1->energy;
	double r = ledger_residual(e0, e1, w_prop, w_rand, se);
	if (fx->n_work < fx->n) { /* the effects booked on their own lines */
		const double turn = s1->heading - s0->heading;
		for (int i = fx->n_work; i < fx->n; i++) {
			const bsim_effect *e = &fx->e[i];
			/* an effect the backend simulates: minus its work is the
			 * backend's (drag and ground friction only) */
			double work = e->taken
			                      ? -(e == fx->drag ? s1->drag_loss : s1->friction_loss)
			                      : e->applied[0] * d[0] + e->applied[1] * d[1] +
			                                e->applied_torque * turn;
			r -= work;
			if (e == fx->heading) {
				l->w_prop += work;
				l->inflow += fabs(work);
			} else if (e == fx->drag) {
				l->drag -= work;
			} else if (e == fx->friction) {
				l->friction -= work;
			} else {
				l->w_osc += work;
				l->inflow += fabs(work);
			}
		}
	}
	LEDGER_LINES_ADD(*l, w_prop, w_rand, se, r);
}

/* The ledger's close after step n, the energy e_end: an ordinary result
 * whose residual exceeds the bound becomes unstable (energy created), and
 * so does one whose residual is below minus the lost bound (energy
 * vanished). */
void bsim_trial_ledger_close(bsim_trial_result *out, double e_end, long n);

#endif
