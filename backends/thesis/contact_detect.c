/* Contact detection's entry points (the geometry and its tests are inline,
 * contact_geometry.h): one for any body, one compiled for the essay's
 * disk only. */
#include "thesis/thesis.h"

int bsim_thesis_contact_detect(struct bsim_world *w, int i, double margin, thesis_contact *out)
{
	return contact_detect(w, i, margin, out, 1);
}

int bsim_thesis_contact_detect_disk(struct bsim_world *w, int i, double margin, thesis_contact *out)
{
	return contact_detect(w, i, margin, out, 0);
}

int bsim_thesis_contact_redetect_disk(struct bsim_world *w, int i, double margin,
                                      thesis_contact *out)
{
	return disk_detect(w, i, margin, out, 1, 0);
}

int bsim_thesis_contact_near(const struct bsim_world *w, int i, double margin)
{
	return contact_near(w, i, margin, 1);
}

int bsim_thesis_contact_near_disk(const struct bsim_world *w, int i, double margin)
{
	return contact_near(w, i, margin, 0);
}
