/* The trajectory player of an output directory's index.html (viewer_data.c,
 * docs/figures.md "The trajectory player"): DIR/viewer_data.js, the data
 * it plays as one JavaScript object (a page opened from file:// may load a
 * script beside it but may not read a file beside it), and DIR/viewer.js,
 * the player itself (src/store/viewer.js, built into the library).
 *
 * What it plays: a run's trajectory.csv (`run --out`), a sweep's
 * trajectories.csv (`--trajectories N`), or each side's of a comparison
 * side by side; each in the scene it ran in (a run's inputs/scene.yaml
 * with run.json's "set", a sweep's group scene from inputs/experiment.yaml)
 * over its landscape where the directory holds that figure's surface
 * (landscape_path.surface.dat, landscape_gNNN.surface.dat). */
#ifndef BSIM_STORE_VIEWER_DATA_H
#define BSIM_STORE_VIEWER_DATA_H

#include "beamsim/error.h"

/* Caps, so that the page stays small enough for a browser to load at
 * once: at most BSIM_VIEWER_TRAJECTORIES trajectories a side (the first of
 * its file), each at most BSIM_VIEWER_FRAMES frames and at most
 * BSIM_VIEWER_VALUES numbers (a scene of many beams gets fewer frames); a
 * trajectory of more rows is played every k-th row, and its last. */
#define BSIM_VIEWER_TRAJECTORIES 64
#define BSIM_VIEWER_FRAMES       2000
#define BSIM_VIEWER_VALUES       100000

typedef struct bsim_viewer_summary {
	int sides;        /* panels side by side: 1, or a comparison's sides with trajectories */
	long shown, kept; /* trajectories played, and kept in the first side's file */
	long most_rows;   /* the most rows of any trajectory played */
	int most_every;   /* the largest k (every k-th row played), 1 if all */
	int landscapes;   /* landscapes drawn under the trajectories */
} bsim_viewer_summary;

/* Writes stage/viewer_data.js and stage/viewer.js if the set (stage, and
 * with add also dir, stage's files first) holds a trajectory to play;
 * sum->shown is 0 and nothing is written otherwise. BSIM_EINPUT naming the
 * file, line and field if a file it reads is malformed, BSIM_EFAIL if out
 * of memory or a file cannot be written. */
int bsim_viewer_write(const char *stage, const char *dir, int add, bsim_viewer_summary *sum,
                      bsim_error *err);

#endif
