/* The beams the thesis backend lists in its state for the contact flag,
 * which the runner computes from the state (beamsim/contact_flag.h,
 * beamsim/state.h): every beam the flag may mark must be listed. The flag
 * marks a beam within BSIM_CONTACT_TOL (6 mm) of the body at the step's
 * end, or one that took a nonzero impact or persistent-contact impulse in
 * the step (w->impulse > 0, impact_resolve.h and persistent_contact.h, which
 * the state reports as touched). So after each step the world wakes, and
 * its state lists, the pushed beams and those the broad phase finds within
 * L + R + 6 mm of the body, minus those whose last geometry bounds them
 * farther (bsim_thesis_contact_near: no trigonometry). A beam woken at rest
 * stays at rest (nothing acts on it) and is pruned again once it is
 * neither near nor touching: waking moves nothing.
 *
 * A step in free flight (bsim_thesis_broad_phase_clear, whose margin includes
 * BSIM_CONTACT_TOL) ends more than 6 mm from every beam and pushes none,
 * so it lists nothing.
 *
 * A run (step_sets.h) has every beam a candidate: each one's distance from
 * the body is measured here, where the step ends, for the next step's
 * detection, which starts there; and the beams near or pushed are kept
 * for the state (thesis_step.h), which lists the awake ones.
 *
 * Inline, included by the step (thesis_step.h), which compiles it for
 * each body and each form of the step's sets. */
#ifndef BSIM_THESIS_CONTACT_LIST_H
#define BSIM_THESIS_CONTACT_LIST_H

#include "beamsim/contact_flag.h"
#include "thesis/step_sets.h"

/* extended: constant (contact_geometry.h's contact_detect): 0 compiles the
 * essay's disk's copy without the shape's test. */
THESIS_SPECIALISED void contact_list_beams(struct bsim_world *w, thesis_run *run,
                                           const int extended)
{
	if (run) {
		run->near = 0;
		for (int i = 0; i < run->nb; i++) {
			run->d2[i] = beam_pivot_distance2(w, &w->model->beams[i]);
			if (thesis_run_has(run->pushed, i) ||
			    contact_near_at(w, i, run->d2[i], BSIM_CONTACT_TOL, 0))
				run->near |= 1u << i;
		}
		run->awake |= run->near;
		return;
	}
	int n = bsim_thesis_broad_phase_near(w, BSIM_CONTACT_TOL);
	for (int k = 0; k < n; k++) {
		int i = w->candidates[k];
		if (!w->is_awake[i] &&
		    (extended ? bsim_thesis_contact_near(w, i, BSIM_CONTACT_TOL)
		              : bsim_thesis_contact_near_disk(w, i, BSIM_CONTACT_TOL)))
			bsim_thesis_beam_wake(w, i);
	}
	for (int k = 0; k < w->n_pushed; k++)
		bsim_thesis_beam_wake(w, w->pushed_list[k]);
}

#endif
