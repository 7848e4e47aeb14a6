/* The thesis world's invariants, checked (thesis.h): what a step leaves
 * must hold before the next one reads it, as Box2D's validators check its
 * solver sets. Asserts, so the checks exist in debug builds only (the
 * sanitized test build is one); under NDEBUG there is no call (thesis.h). The
 * world calls it after it is made, reset or set to a state and after each
 * call of advance (thesis_world.c).
 *
 * The model is checked against the bytes it was sealed with when made
 * (bsim_thesis_model_seal): a step, reset or state writes none of it.
 * The lists are checked whole (their cost is that of the beams awake,
 * in contact, pushed or touched). The field is scanned for what the lists
 * and markers imply of every beam (a beam not awake is exactly at rest; a
 * beam marked in contact marks one of the contacts, and is awake; a
 * beam's impulse is 0 unless pushed; an awake beam is one a reset
 * restores) 64 beams a call,
 * from where the last call stopped: a field of 64 beams or fewer whole
 * each time, a lattice's 2,178 every 35 calls, so that a debug build's
 * step stays within a small factor of a release build's. */
#include <assert.h>

#include "thesis/thesis.h"

/* Beams of the field a validation scans. */
#define VALIDATE_SCAN 64
/* Bytes of the model a validation hashes. */
#define VALIDATE_MODEL_BYTES 4096

#ifndef NDEBUG
/* FNV-1a, 64 bits, over n bytes from p, continuing from h. */
#define MODEL_HASH_START 14695981039346656037ull
static unsigned long long model_hash(unsigned long long h, const unsigned char *p, size_t n)
{
	for (size_t k = 0; k < n; k++)
		h = (h ^ p[k]) * 1099511628211ull;
	return h;
}

void bsim_thesis_model_seal(struct bsim_world *w)
{
	w->model_sum = model_hash(MODEL_HASH_START, (const unsigned char *)w->model, w->model_size);
	w->model_sum_run = MODEL_HASH_START;
	w->model_from = 0;
}

/* The model's next VALIDATE_MODEL_BYTES into the running hash; at its end,
 * the whole model's hash against the seal's: nothing a step, reset or
 * state changes in the model (a lattice's is hashed whole every few dozen
 * calls, H1's every call). */
static void validate_model(struct bsim_world *w)
{
	size_t n = w->model_size - w->model_from;
	n = n < VALIDATE_MODEL_BYTES ? n : VALIDATE_MODEL_BYTES;
	w->model_sum_run =
	        model_hash(w->model_sum_run, (const unsigned char *)w->model + w->model_from, n);
	w->model_from += n;
	if (w->model_from == w->model_size) {
		assert(w->model_sum_run == w->model_sum);
		w->model_sum_run = MODEL_HASH_START;
		w->model_from = 0;
	}
}

void bsim_thesis_validate(struct bsim_world *w)
{
	const int nb = w->model->n_beams;
	assert(nb >= 0 && w->beams);
	validate_model(w);
	assert(w->n_contacts >= 0 && w->n_contacts <= 2 * nb);
	/* the awake list: ascending, each flagged */
	assert(w->n_awake >= 0 && w->n_awake <= nb);
	for (int k = 0; k < w->n_awake; k++) {
		int i = w->awake[k];
		assert(i >= 0 && i < nb);
		assert(k == 0 || w->awake[k - 1] < i);
		assert(w->is_awake[i] == 1);
	}
	/* the last step's contacts: each one's beam awake; a beam marked in
	 * contact (contact_of) marks one of its contacts, within contact_tol */
	for (int k = 0; k < w->n_contacts; k++) {
		const int i = w->contacts[k].beam;
		assert(i >= 0 && i < nb && w->is_awake[i] == 1);
		const int c = w->contact_of[i];
		assert(c == -1 || (c >= 0 && c < w->n_contacts && w->contacts[c].beam == i));
	}
	/* the pushed list: each with its pushes' impulse, > 0, once */
	assert(w->n_pushed >= 0 && w->n_pushed <= nb);
	for (int k = 0; k < w->n_pushed; k++) {
		int i = w->pushed_list[k];
		assert(i >= 0 && i < nb);
		assert(w->impulse[i] > 0.0);
		for (int q = 0; q < k && k < VALIDATE_SCAN; q++)
			assert(w->pushed_list[q] != i);
	}
	/* the touched list (all of them after a state was set) */
	assert(w->n_touched >= 0 && w->n_touched <= nb);
	for (int k = 0; k < w->n_touched; k++)
		assert(w->touched[w->touched_list[k]] == 1);
	/* persistent contact is held under contact_mode=essay only */
	assert(w->model->contact_mode == THESIS_CONTACT_ESSAY || !w->any_held);
	/* a window of the field */
	int awake = 0, pushed = 0;
	const int n = nb < VALIDATE_SCAN ? nb : VALIDATE_SCAN;
	int from = w->validate_from < nb ? w->validate_from : 0;
	for (int s = 0; s < n; s++) {
		int i = (from + s) % nb;
		const thesis_beam *b = &w->beams[i];
		assert(w->is_awake[i] <= 1 && w->touched[i] <= 1);
		assert(w->is_awake[i] || (b->theta == 0.0 && b->omega == 0.0));
		const int c = w->contact_of[i];
		assert(c == -1 || (c >= 0 && c < w->n_contacts && w->contacts[c].beam == i &&
		                   w->contacts[c].gap <= w->model->contact_tol && w->is_awake[i]));
		assert(w->impulse[i] >= 0.0);
		assert(!w->held[i] || w->model->contact_mode == THESIS_CONTACT_ESSAY);
		assert(!w->is_awake[i] || w->touched[i] || w->touched_all);
		awake += w->is_awake[i];
		pushed += w->impulse[i] > 0.0;
	}
	/* the whole field seen: as many awake and pushed as listed */
	assert(n < nb || (awake == w->n_awake && pushed == w->n_pushed));
	w->validate_from = nb ? (from + n) % nb : 0;
}
#endif
