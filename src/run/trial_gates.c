/* Gate tracking for the trial runner (trial_gates.h): which gate the body
 * is in, and the record of each entry, in the entered gate's frame
 * (Eq. 2.17: x = X - width ix, y = Y - depth iy). A step that cuts a
 * corner enters two gates; the boundary it crosses first comes first
 * (model/lattice_crossing.h). */
#include "run/trial_gates.h"

#include <string.h>

#include "beamsim/lattice.h"
#include "model/lattice_crossing.h"
#include "run/trial_log.h"

void bsim_trial_gate_start(gate_track *g, const bsim_scene *scene)
{
	double p[2] = {scene->body.start[0], scene->body.start[1]};
	bsim_lattice_gate_at(scene, p, &g->ix, &g->iy);
	g->dwell = 0;
	g->entries = 1;
}

/* The entry record of gate (ix, iy) through edge, the body at s. */
static void entry_fill(bsim_gate_entry *e, const bsim_scene *scene, const int *map,
                       const bsim_state *s, int ix, int iy, bsim_edge edge, double pos, long n,
                       double h)
{
	const bsim_lattice_def *l = &scene->lattice;
	double ox = scene->has_lattice ? l->width * ix : 0.0;
	double oy = scene->has_lattice ? l->depth * iy : 0.0;
	memset(e, 0, sizeof *e);
	e->ix = ix;
	e->iy = iy;
	e->edge = edge;
	e->step = (int)n;
	e->t = (double)n * h;
	e->pos = pos;
	e->x[0] = s->x[0] - ox;
	e->x[1] = s->x[1] - oy;
	e->v[0] = s->v[0];
	e->v[1] = s->v[1];
	if (!scene->has_lattice) {
		for (int side = 0; side < 2 && side < s->n_beams; side++) {
			e->theta[side] = s->theta[side];
			e->omega[side] = s->omega[side];
		}
		return;
	}
	/* Whole world: the entered gate's beams as they are. The essay's
	 * world holds only the gate being left, whose beams are not these. */
	for (int side = 0; side < 2 && !map; side++) {
		int b = bsim_lattice_beam(l, ix, iy, side);
		e->theta[side] = s->theta[b];
		e->omega[side] = s->omega[b];
	}
}

int bsim_trial_gate_log_start(bsim_trial_log *log, const gate_track *g, const bsim_scene *scene,
                              const int *map, const bsim_state *s0, bsim_error *err)
{
	bsim_gate_entry e;
	entry_fill(&e, scene, map, s0, g->ix, g->iy, BSIM_EDGE_START,
	           s0->x[0] - (scene->has_lattice ? scene->lattice.width * g->ix : 0.0), 0,
	           scene->dt);
	if (bsim_trial_log_push(log, &e))
		return bsim_error_set(err, BSIM_EFAIL, "out of memory for the gate path");
	return BSIM_OK;
}

/* The gates the body entered in a step that took it from gate (g->ix,
 * g->iy) at p0 to gate (ix, iy) at p1: one, or two when it cut a corner
 * (the first boundary crossed first). Each goes to e[]; returns how many. */
static int entries_of_step(const bsim_scene *scene, const int *map, const gate_track *g,
                           const double p0[2], const bsim_state *s, int ix, int iy, long n,
                           double h, bsim_gate_entry e[2])
{
	const bsim_lattice_def *l = &scene->lattice;
	const double *p1 = s->x;
	double bx = l->width * (ix > g->ix ? ix : g->ix) - 0.5 * l->width;
	double by = l->depth * (iy > g->iy ? iy : g->iy);
	double fx = ix != g->ix ? lattice_crossing(p0, p1, 0, bx) : LATTICE_NO_CROSSING;
	double fy = iy != g->iy ? lattice_crossing(p0, p1, 1, by) : LATTICE_NO_CROSSING;
	bsim_edge ex = ix > g->ix ? BSIM_EDGE_LEFT : BSIM_EDGE_RIGHT;
	bsim_edge ey = iy > g->iy ? BSIM_EDGE_BOTTOM : BSIM_EDGE_TOP;
	/* the crossing point, along the edge, in the entered gate's frame */
	double pos_x = p0[0] + fy * (p1[0] - p0[0]) - l->width * ix;
	double pos_y = p0[1] + fx * (p1[1] - p0[1]) - l->depth * iy;
	if (ix == g->ix) {
		entry_fill(&e[0], scene, map, s, ix, iy, ey, pos_x, n, h);
		return 1;
	}
	if (iy == g->iy) {
		entry_fill(&e[0], scene, map, s, ix, iy, ex, pos_y, n, h);
		return 1;
	}
	if (fx <= fy) { /* across the side first, then the row boundary */
		entry_fill(&e[0], scene, map, s, ix, g->iy, ex, pos_y + l->depth * (iy - g->iy), n,
		           h);
		entry_fill(&e[1], scene, map, s, ix, iy, ey, pos_x, n, h);
	} else {
		entry_fill(&e[0], scene, map, s, g->ix, iy, ey, pos_x + l->width * (ix - g->ix), n,
		           h);
		entry_fill(&e[1], scene, map, s, ix, iy, ex, pos_y, n, h);
	}
	/* The intermediate gate's frame: the body is in (ix, iy) at the end. */
	e[0].x[0] = s->x[0] - l->width * e[0].ix;
	e[0].x[1] = s->x[1] - l->depth * e[0].iy;
	return 2;
}

int bsim_trial_gate_cross(gate_track *g, bsim_trial_log *log, const bsim_scene *scene,
                          const int *map, const double p0[2], const bsim_state *s, int ix, int iy,
                          long n, bsim_error *err)
{
	bsim_gate_entry e[2];
	int k = entries_of_step(scene, map, g, p0, s, ix, iy, n, scene->dt, e);
	for (int i = 0; i < k; i++)
		if (log && bsim_trial_log_push(log, &e[i]))
			return bsim_error_set(err, BSIM_EFAIL, "out of memory for the gate path");
	g->ix = ix;
	g->iy = iy;
	g->dwell = 0;
	g->entries += k;
	return BSIM_OK;
}
