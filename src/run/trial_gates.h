/* Internal: the gate of a lattice the body is in (docs/model.md section 8,
 * lattice.h), followed step by step, and the path of gates it entered
 * (bsim_gate_entry, the trial log). A scene without a lattice is one gate,
 * (0, 0). */
#ifndef BSIM_RUN_TRIAL_GATES_H
#define BSIM_RUN_TRIAL_GATES_H

#include "beamsim/trial.h"

typedef struct gate_track {
	int ix, iy;  /* the gate the body is in */
	long dwell;  /* steps since it entered */
	int entries; /* gates entered, the start gate included */
} gate_track;

/* The gate where the body starts, entered. */
void bsim_trial_gate_start(gate_track *g, const bsim_scene *scene);

/* The start gate's entry (edge START, the body at s0) to log. map: the
 * world's beam i is the scene's map[i] (the essay's world), NULL: the same. */
int bsim_trial_gate_log_start(bsim_trial_log *log, const gate_track *g, const bsim_scene *scene,
                              const int *map, const bsim_state *s0, bsim_error *err);

/* The body, at p0 before step n and at s after it, is in gate (ix, iy),
 * not g's: the gates it entered to log (NULL: none), and g follows. */
int bsim_trial_gate_cross(gate_track *g, bsim_trial_log *log, const bsim_scene *scene,
                          const int *map, const double p0[2], const bsim_state *s, int ix, int iy,
                          long n, bsim_error *err);

#endif
