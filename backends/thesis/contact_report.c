/* The contact flag the thesis backend reports in its state, the one every
 * backend reports (beamsim/contact_flag.h, beamsim/state.h): beam i is in
 * contact during a step when at the step's end its gap to the body is below
 * BSIM_CONTACT_TOL (6 mm), or when it took a nonzero impact or
 * persistent-contact impulse in the step (w->pushed, impact_resolve.c and
 * persistent_contact.c), so that an impact is flagged on its own step even
 * when the body has bounced off by the step's end.
 *
 * The gap is measured from the step's final positions with the shared
 * geometry (bsim_beam_distance2), not from the solver's contacts: a beam the
 * solver did not test in the step (beyond its margin) is still flagged if
 * the body ends within 6 mm of it. The beams measured are those the broad
 * phase finds within L + R + 6 mm of the body, minus those whose last
 * geometry bounds them farther (thesis_contact_near: no trigonometry), plus
 * the pushed ones. A flagged beam is woken, so that the state lists it.
 * Nothing here moves anything: the solver's own touching test, which keeps
 * beams awake and from sleeping, is contact_type (contact_tol).
 *
 * A step in free flight (thesis_broad_phase_clear, whose margin includes
 * BSIM_CONTACT_TOL) ends more than 6 mm from every beam and pushes none, so
 * it only clears the last step's flags (thesis_contact_clear). */
#include "beamsim/contact_flag.h"
#include "thesis/thesis.h"

/* extended: constant (contact_geometry.h's contact_detect): 0 compiles the
 * essay's disk's copy without the shape's test. */
THESIS_SPECIALISED void report_beam(struct bsim_world *w, int i, const int extended)
{
	thesis_beam *b = &w->beams[i];
	int pushed = w->pushed[i];
	if (w->flag[i] != BSIM_CONTACT_NONE ||
	    (!pushed && !(extended ? thesis_contact_near(w, i, BSIM_CONTACT_TOL)
	                           : thesis_contact_near_disk(w, i, BSIM_CONTACT_TOL))))
		return;
	double u[2];
	int type, flag;
	thesis_beam_direction(b, u);
	if (extended && w->shaped) {
		flag = bsim_contact_flag_of(&w->body, w->x, w->heading, b->p, u, b->length, pushed);
	} else {
		double dist2 = bsim_beam_distance2(b->p, u, b->length, w->x, &type);
		flag = bsim_contact_flag(dist2, w->radius, type, pushed);
	}
	if (flag == BSIM_CONTACT_NONE)
		return;
	w->flag[i] = flag;
	w->flagged[w->n_flagged++] = i;
	thesis_beam_wake(w, i);
}

void thesis_contact_clear(struct bsim_world *w)
{
	for (int k = 0; k < w->n_flagged; k++)
		w->flag[w->flagged[k]] = BSIM_CONTACT_NONE;
	w->n_flagged = 0;
}

THESIS_SPECIALISED void contact_report(struct bsim_world *w, const int extended)
{
	thesis_contact_clear(w);
	int n = thesis_broad_phase_near(w, BSIM_CONTACT_TOL);
	for (int k = 0; k < n; k++)
		report_beam(w, w->candidates[k], extended);
	for (int k = 0; k < w->n_pushed; k++) {
		int i = w->pushed_list[k];
		report_beam(w, i, extended);
		w->pushed[i] = 0;
	}
	w->n_pushed = 0;
}

void thesis_contact_report(struct bsim_world *w)
{
	contact_report(w, 1);
}

void thesis_contact_report_disk(struct bsim_world *w)
{
	contact_report(w, 0);
}
