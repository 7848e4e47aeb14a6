/* The thesis world's invariants, checked (thesis.h): what a step leaves
 * must hold before the next one reads it, as Box2D's validators check its
 * solver sets. Asserts, so the checks exist in debug builds only (the
 * sanitized test build is one); under NDEBUG there is no call (thesis.h). The
 * world calls it after it is made, reset or set to a state and after each
 * call of advance (thesis_world.c).
 *
 * The lists are checked whole (their cost is that of the beams awake,
 * typed, pushed or touched). The field is scanned for what the lists
 * imply of every beam (a beam not awake is exactly at rest; a typed beam
 * is awake; no beam keeps a contact index between steps) 64 beams a call,
 * from where the last call stopped: a field of 64 beams or fewer whole
 * each time, a lattice's 2,178 every 35 calls, so that a debug build's
 * step stays within a small factor of a release build's. */
#include <assert.h>

#include "thesis/thesis.h"

/* Beams of the field a validation scans. */
#define VALIDATE_SCAN 64

#ifndef NDEBUG
void bsim_thesis_validate(struct bsim_world *w)
{
	const int nb = w->n_beams;
	assert(nb >= 0 && w->beams);
	assert(w->n_contacts >= 0 && w->n_contacts <= 2 * nb);
	/* the awake list: ascending, each flagged */
	assert(w->n_awake >= 0 && w->n_awake <= nb);
	for (int k = 0; k < w->n_awake; k++) {
		int i = w->awake[k];
		assert(i >= 0 && i < nb);
		assert(k == 0 || w->awake[k - 1] < i);
		assert(w->is_awake[i] == 1);
	}
	/* the typed list: a contact type each, once */
	assert(w->n_typed >= 0 && w->n_typed <= nb);
	for (int k = 0; k < w->n_typed; k++) {
		int i = w->typed[k];
		assert(i >= 0 && i < nb);
		assert(w->contact_type[i] != BSIM_CONTACT_NONE);
		for (int q = 0; q < k; q++)
			assert(w->typed[q] != i);
	}
	/* the pushed list: each flagged, with its impulse */
	assert(w->n_pushed >= 0 && w->n_pushed <= nb);
	for (int k = 0; k < w->n_pushed; k++) {
		int i = w->pushed_list[k];
		assert(i >= 0 && i < nb);
		assert(w->pushed[i] == 1);
		assert(w->impulse[i] > 0.0);
	}
	/* the touched list (all of them after a state was set) */
	assert(w->n_touched >= 0 && w->n_touched <= nb);
	for (int k = 0; k < w->n_touched; k++)
		assert(w->touched[w->touched_list[k]] == 1);
	/* persistent contact is held under contact_mode=essay only */
	assert(w->contact_mode == THESIS_CONTACT_ESSAY || !w->any_held);
	/* a window of the field */
	int awake = 0;
	const int n = nb < VALIDATE_SCAN ? nb : VALIDATE_SCAN;
	int from = w->validate_from < nb ? w->validate_from : 0;
	for (int s = 0; s < n; s++) {
		int i = (from + s) % nb;
		const thesis_beam *b = &w->beams[i];
		assert(w->is_awake[i] <= 1 && w->pushed[i] <= 1 && w->touched[i] <= 1);
		assert(w->is_awake[i] || (b->theta == 0.0 && b->omega == 0.0));
		assert(w->contact_type[i] == BSIM_CONTACT_NONE || w->is_awake[i]);
		assert(w->contact_of[i] == -1);
		assert(!w->held[i] || w->contact_mode == THESIS_CONTACT_ESSAY);
		awake += w->is_awake[i];
	}
	/* the whole field seen: as many flagged as listed */
	assert(n < nb || awake == w->n_awake);
	w->validate_from = nb ? (from + n) % nb : 0;
}
#endif
