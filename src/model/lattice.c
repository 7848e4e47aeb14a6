/* Gate lattices: geometry, the lattice built in code, and final locations
 * (beamsim/lattice.h, docs/model.md section 8). */
#include "beamsim/lattice.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model/scene_internal.h"

int bsim_lattice_beam(const bsim_lattice_def *l, int ix, int iy, int side)
{
	if (ix < l->ix_min || ix > l->ix_max || iy < 0 || iy >= l->rows || side < 0 || side > 1)
		return -1;
	return 2 * (iy * l->columns + (ix - l->ix_min)) + side;
}

void bsim_lattice_beam_gate(const bsim_lattice_def *l, int i, int *ix, int *iy, int *side)
{
	int gate = i / 2;
	*side = i % 2;
	*iy = gate / l->columns;
	*ix = l->ix_min + gate % l->columns;
}

static int clamp_int(double v, int lo, int hi)
{
	if (!(v >= lo)) /* NaN too */
		return lo;
	if (v > hi)
		return hi;
	return (int)v;
}

void bsim_lattice_gate_at(const bsim_scene *s, const double p[2], int *ix, int *iy)
{
	if (!s->has_lattice) {
		*ix = *iy = 0;
		return;
	}
	const bsim_lattice_def *l = &s->lattice;
	*ix = clamp_int(floor((p[0] + 0.5 * l->width) / l->width), l->ix_min, l->ix_max);
	*iy = clamp_int(floor(p[1] / l->depth), 0, l->rows - 1);
}

double bsim_lattice_centre_x(const bsim_scene *s)
{
	if (!s->has_lattice)
		return 0.0;
	return 0.5 * s->lattice.width * (s->lattice.ix_min + s->lattice.ix_max);
}

int bsim_lattice_build(bsim_scene *s, const double *k_left, const double *k_right)
{
	bsim_lattice_def *l = &s->lattice;
	l->columns = l->ix_max - l->ix_min + 1;
	if (l->columns < 1 || l->rows < 1)
		return BSIM_EINPUT;
	int n = 2 * l->columns * l->rows;
	if (bsim_scene_set_beams(s, n) != BSIM_OK)
		return BSIM_EFAIL;
	s->has_lattice = 1;
	for (int iy = 0; iy < l->rows; iy++)
		for (int ix = l->ix_min; ix <= l->ix_max; ix++) {
			int g = iy * l->columns + (ix - l->ix_min);
			for (int side = 0; side < 2; side++) {
				bsim_beam_def *b = &s->beams[bsim_lattice_beam(l, ix, iy, side)];
				*b = l->beam;
				b->pivot[0] = l->width * ix + (side ? 0.5 : -0.5) * l->width;
				b->pivot[1] = l->depth * iy + l->pivot_y;
				b->rest_angle_deg = side ? 180.0 : 0.0; /* pointing into the gate */
				b->initial_theta = 0.0;
				b->initial_omega = 0.0;
				const double *k = side ? k_right : k_left;
				if (k)
					b->stiffness = k[g];
			}
		}
	return BSIM_OK;
}

/* The termination defaults of a lattice: the end boundary, the sides, the
 * zero of the propulsive potential at the end, no run-on past the end. */
void bsim_scene_lattice_defaults(bsim_scene *s)
{
	const bsim_lattice_def *l = &s->lattice;
	s->success_y = l->depth * l->rows;
	s->side_x = 0.5 * l->width * l->columns;
	s->classify_y = s->success_y;
	s->landscape_y0 = s->success_y;
	s->gate_steps = 3000; /* the essay's max iterations of one gate */
	s->max_steps = s->gate_steps * (l->rows + l->columns);
}

int bsim_lattice_scene_init(bsim_scene *s, int columns, int rows, double f_prop, double rm)
{
	bsim_scene_init_gate(s, f_prop, rm);
	bsim_lattice_def *l = &s->lattice;
	memset(l, 0, sizeof *l);
	snprintf(s->name, sizeof s->name, "lattice-%dx%d", columns, rows);
	l->beam = s->beams[0]; /* the essay's beam, Table 2.1 */
	l->ix_max = (columns - 1) / 2;
	l->ix_min = l->ix_max - columns + 1;
	l->rows = rows;
	l->width = 50;   /* m */
	l->depth = 60;   /* m */
	l->pivot_y = 30; /* m */
	int rc = bsim_lattice_build(s, NULL, NULL);
	if (rc == BSIM_OK)
		bsim_scene_lattice_defaults(s);
	return rc;
}
