/* trajectories.csv of a sweep (beamsim/output.h): the kept trajectories in
 * one long table, so that one read gives every trial and a group's bundle
 * is the rows of its group. */
#include "util/atomic_file.h"
#include "beamsim/output.h"

int bsim_output_trajectories_csv(const char *path, const bsim_sweep_result *r, bsim_error *err)
{
	if (r->keep <= 0 || !r->kept)
		return BSIM_OK;
	bsim_atomic_file o;
	if (bsim_atomic_file_open(&o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	bsim_trajectory_csv_header(o.f, r->kept[0].n_beams);
	for (int g = 0; g < r->n_groups; g++)
		for (int t = 0; t < r->keep; t++)
			bsim_trajectory_csv_rows(o.f, g, t, &r->kept[(size_t)g * r->keep + t]);
	return bsim_atomic_file_commit(&o, err);
}
