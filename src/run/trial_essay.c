/* The essay's lattice protocol (essay Sec. 2.6, Algorithm 1): "Each gate is
 * considered individually with the starting position from the exiting
 * position of the last neighbor gate region."
 *
 * Only the active gate is simulated. When the body enters gate (ix, iy) the
 * world is replaced by a fresh one holding that gate's two beams at rest
 * (theta = omega = 0: reset on entry) and the body with its position and
 * velocity. Positions carry over by Eq. 2.17, X = x + width ix,
 * Y = y + depth iy; the world is built in the lattice's frame, where that
 * map is the identity, so the carried-over position is the same number.
 * (The essay's pseudo-code shifts x by 25 on a side crossing, which would
 * move the body to the gate's centre line; Eq. 2.17 is what its own
 * visualisation uses, and what is done here.) The essay is silent about
 * the velocity; it is carried over, the body keeps moving.
 *
 * What this leaves out, by construction: the beams of the gate behind (a
 * beam the body pushed does not push back once the body has crossed into
 * the next gate) and of the neighbouring gates, which share pivots with the
 * active one; and a beam reset while the body overlaps its rest position
 * (entering sideways at a pivot row) starts in penetration, which the
 * backend's position correction resolves. Such entries are counted. */
#include "run/trial_essay.h"

#include <string.h>

#include "beamsim/lattice.h"
#include "model/scene_internal.h"

static void essay_scene(trial_essay *te, const bsim_scene *lattice, int ix, int iy,
                        const double x[2], const double v[2])
{
	/* A shallow copy: the beams are the two of this struct. */
	te->scene = *lattice;
	te->scene.has_lattice = 0;
	te->scene.n_beams = 2;
	te->scene.beams = te->beams;
	for (int side = 0; side < 2; side++) {
		int i = bsim_lattice_beam(&lattice->lattice, ix, iy, side);
		te->map[side] = i;
		te->beams[side] = lattice->beams[i];
		te->beams[side].initial_theta = 0.0;
		te->beams[side].initial_omega = 0.0;
	}
	memcpy(te->scene.body.start, x, sizeof te->scene.body.start);
	memcpy(te->scene.body.velocity, v, sizeof te->scene.body.velocity);
}

static int essay_create(trial_essay *te, const bsim_backend *b, const bsim_options *opts,
                        bsim_world **w, int *overlaps, bsim_error *err)
{
	double dist;
	if (bsim_scene_overlap(&te->scene, &dist) >= 0)
		(*overlaps)++;
	return b->create(&te->scene, opts, w, err);
}

int bsim_trial_essay_start(trial_essay *te, const bsim_scene *lattice, const bsim_backend *b,
                           const bsim_options *opts, int ix, int iy, bsim_world **w, int *overlaps,
                           bsim_error *err)
{
	*w = NULL;
	essay_scene(te, lattice, ix, iy, lattice->body.start, lattice->body.velocity);
	return essay_create(te, b, opts, w, overlaps, err);
}

int bsim_trial_essay_enter(trial_essay *te, const bsim_scene *lattice, const bsim_backend *b,
                           const bsim_options *opts, int ix, int iy, const bsim_state *s,
                           bsim_world **w, int *overlaps, bsim_error *err)
{
	bsim_trial_essay_release(te, b, w);
	essay_scene(te, lattice, ix, iy, s->x, s->v);
	return essay_create(te, b, opts, w, overlaps, err);
}

void bsim_trial_essay_release(trial_essay *te, const bsim_backend *b, bsim_world **w)
{
	(void)te;
	if (*w)
		b->destroy(*w);
	*w = NULL;
}
