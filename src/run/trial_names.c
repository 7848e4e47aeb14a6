/* The names of a trial's outcomes, types and gate edges, as trials.csv,
 * the gate path and the reports write them (trial.h). */
#include "beamsim/trial.h"

const char *bsim_trial_outcome_name(bsim_outcome o)
{
	static const char *names[] = {"traversed", "side_exit", "stuck", "unstable"};
	return (unsigned)o < BSIM_N_OUTCOMES ? names[o] : "?";
}

const char *bsim_trial_type_name(bsim_type t)
{
	static const char *names[] = {"none", "left", "right"};
	return (unsigned)t < 3 ? names[t] : "?";
}

const char *bsim_trial_edge_name(bsim_edge e)
{
	static const char *names[] = {"start", "bottom", "left", "right", "top"};
	return (unsigned)e < 5 ? names[e] : "?";
}
