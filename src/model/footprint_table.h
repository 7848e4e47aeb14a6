/* The rate at which ground friction dissipates on a capsule's or an
 * ellipse's footprint, tabulated over the twist's direction
 * (footprint_table.c; footprint_friction.c steps with it). Internal to
 * the library. */
#ifndef BSIM_MODEL_FOOTPRINT_TABLE_H
#define BSIM_MODEL_FOOTPRINT_TABLE_H

#include "beamsim/scene.h"

/* The footprint's outline and its table over the positive octant of the
 * scaled twist q = (v_x, v_y, omega a) (body frame, heading along +x), in
 * units of mu M g = 1. Each node is computed the first time a twist needs
 * it, so that a table holds only the directions a body has moved in. */
typedef struct bsim_footprint_table {
	bsim_body_shape shape; /* BSIM_SHAPE_CAPSULE or BSIM_SHAPE_ELLIPSE */
	double half[2];   /* m: a capsule's half-segment l and radius r; an ellipse's a and b */
	double area;      /* m^2 */
	double arm;       /* m: r_s = (1/A) integral |r| dA, the mean distance from the centre */
	double scale[3];  /* the twist (v_x, v_y, omega) is (scale_k q_k): L_y m, L_x m, 1 */
	int cells;        /* N: cells along each edge of a face */
	double tolerance; /* of the integrals a node holds, relative to their scales */
	double *node;     /* [3][N + 1][N + 1][4]: d, d_u, d_v, d_uv */
	unsigned char *built;      /* [3][N + 1][N + 1]: 1 once the node is computed */
	double *cell;              /* [3][N][N][16]: each cell's bicubic, from its corners */
	unsigned char *cell_built; /* [3][N][N] */
	long nodes_built;          /* how many (the cost of the table so far) */
} bsim_footprint_table;

/* The table of body's footprint (a capsule or an ellipse), no node
 * computed yet; NULL if out of memory. */
bsim_footprint_table *bsim_footprint_table_alloc(const bsim_body_def *body);
void bsim_footprint_table_free(bsim_footprint_table *t);

/* 1 if t is the table of body's footprint (the same outline). */
int bsim_footprint_table_fits(const bsim_footprint_table *t, const bsim_body_def *body);

/* The dissipation rate D(q) / (mu M g) at the scaled twist q (any signs,
 * not 0; m/s), its gradient g (the friction's force and torque / a, in
 * units of mu M g, against q) and, if H is not NULL, the upper triangle of
 * its Hessian (00 01 02 11 12 22; s/m), from the table. */
double bsim_footprint_table_eval(bsim_footprint_table *t, const double q[3], double g[3],
                                 double H[6]);

/* D and its gradient from the integrals over the footprint themselves
 * (what a node holds), for q >= 0 with q[2] > 0: the reference the table
 * is checked against. */
double bsim_footprint_table_exact(const bsim_footprint_table *t, const double q[3], double g[3]);

#endif
