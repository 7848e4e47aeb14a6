/* Awake beams and sleeping: a beam at rest costs nothing.
 *
 * A beam is awake when theta or omega is not exactly 0 or it touches the
 * body; only awake beams are integrated, summed into energies and reported
 * (bsim_state.active). A beam at rest stays at rest by itself: with
 * theta = omega = 0 and no contact impulse, both integrators give
 * theta' = omega' = 0 exactly. So a beam that has never been touched is
 * asleep for free, and one the body hit wakes when the broad phase finds it
 * in contact (broad_phase.c).
 *
 * Sleeping (knob sleep) puts a beam the body has left back to rest. Its
 * spring and damper make it decay as exp(-zeta omega_n t) but never reach
 * 0 exactly, so a lattice's cost would grow with every beam the body ever
 * touched. A beam is set exactly to rest, theta = omega = 0, at the end of
 * a step when
 *   E = 1/2 I omega^2 + 1/2 k theta^2 < sleep_energy   (J),
 *   k > 0 (a beam without a spring has no rest angle to return to),
 *   it had no contact in the step, and
 *   |C - P| > L + 2 R + 2 h |v|: the body is a body radius clear of
 *   everything the beam can sweep.
 * What it changes: the beam's angle jumps by at most sqrt(2 E_s / k), its
 * tip by L times that (1.8 mm for k = 400 N m/rad at the default 1e-6 J),
 * while the body is at least a body radius away; the energy E is booked
 * in the step's ledger as energy.sleep. test_lattice checks that outcomes
 * do not change measurably against runs without sleeping. */
#include <math.h>
#include <string.h>

#include "thesis/thesis.h"

/* Inserts beam i into the ascending awake list. */
void bsim_thesis_beam_wake(struct bsim_world *w, int i)
{
	if (w->is_awake[i])
		return;
	thesis_beam_touch(w, i);
	int k = w->n_awake;
	while (k > 0 && w->awake[k - 1] > i) {
		w->awake[k] = w->awake[k - 1];
		k--;
	}
	w->awake[k] = i;
	w->n_awake++;
	w->is_awake[i] = 1;
}

/* Drops the beams that are exactly at rest and untouched from the list. */
void bsim_thesis_awake_prune(struct bsim_world *w)
{
	int m = 0;
	for (int k = 0; k < w->n_awake; k++) {
		int i = w->awake[k];
		const thesis_beam *b = &w->beams[i];
		if (b->theta == 0.0 && b->omega == 0.0 && w->contact_of[i] < 0) {
			w->is_awake[i] = 0;
			continue;
		}
		w->awake[m++] = i;
	}
	w->n_awake = m;
}

void bsim_thesis_beams_sleep(struct bsim_world *w, double speed, double h)
{
	for (int k = 0; k < w->n_awake; k++) {
		int i = w->awake[k];
		const thesis_beam_model *bm = &w->model->beams[i];
		thesis_beam *b = &w->beams[i];
		if (bm->stiffness <= 0.0 || w->contact_of[i] >= 0 ||
		    (b->theta == 0.0 && b->omega == 0.0))
			continue;
		double e = 0.5 * bm->inertia * b->omega * b->omega +
		           0.5 * bm->stiffness * b->theta * b->theta;
		if (!(e < w->model->sleep_energy))
			continue;
		double dx = w->x[0] - bm->p[0], dy = w->x[1] - bm->p[1];
		double clear = bm->length + 2.0 * w->model->radius + 2.0 * h * speed;
		if (dx * dx + dy * dy <= clear * clear)
			continue;
		b->theta = 0.0;
		b->omega = 0.0;
		w->energy.sleep += e;
	}
}
