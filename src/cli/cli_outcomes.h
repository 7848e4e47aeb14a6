/* What a sweep's groups came to, printed from their counts (the group
 * results summary.json holds, bsim_group_result): for a gate experiment
 * the left/right split of the traversals, for a gate lattice the end /
 * side / stuck split of the trials, each with its 95% Wilson interval. */
#ifndef BSIM_CLI_CLI_OUTCOMES_H
#define BSIM_CLI_CLI_OUTCOMES_H

#include <stdio.h>

#include "beamsim/experiment.h"
#include "beamsim/sweep.h"
#include "cli/cli_common.h"

/* 1 if some group's two beams differ in length, mass, inertia, stiffness
 * or damping (sets: the command line's --set, may be NULL): then which
 * beam the body goes over is the experiment's question. */
int cli_outcomes_asymmetric(const bsim_experiment *e, const cli_sets *sets);

/* The split of every group of r, one line each under a header: for a
 * lattice the end / side / stuck fractions of the trials; for gates the
 * left / right split of the traversals, printed only when some group has
 * traversals of both types or asymmetric is 1. Nothing otherwise. */
void cli_outcomes_print(FILE *f, const bsim_experiment *e, const bsim_sweep_result *r,
                        int asymmetric);

#endif
