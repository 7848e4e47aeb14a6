/* Broad phase: which beams a step must test for contact, at a cost that
 * follows the body rather than the size of the field.
 *
 * Within one step of h a beam i and the body can close by at most
 *   m_i = 2 (h (|v| + L_i |omega_i|) + h^2 L_i (k_i |theta_i| + d_i |omega_i|) / I_i) + slop
 * (body and tip speeds, and what the force and the spring add, with a
 * factor 2 of safety; |v| already includes h |F| / M). A beam can touch the
 * body only if the body's centre C lies within L_i + R + m_i of its pivot
 * P_i; contact_geometry.h makes that test exactly, beam by beam.
 *
 * A beam at rest (theta = omega = 0) has m_i = 2 h |v| + slop, the same for
 * every such beam. The pivots sit in a uniform grid of cells of side
 *   c >= max_i L_i + R,
 * so every beam at rest that can touch the body has its pivot in a cell
 * overlapping the square [C - r, C + r]^2 with r = c + 2 h |v| + slop >=
 * L_i + R + m_i: 3 x 3 or 4 x 4 cells, whatever the number of beams. Awake
 * beams (beam_sleep.c) are few and are all tested, each with its own
 * margin. The candidates are tested in ascending beam order, so the
 * contacts come out in the order of testing every beam: the broad phase
 * changes the cost, never a bit of the result (test_lattice checks it
 * against broad_phase=0). */
#include <math.h>
#include <stdlib.h>

#include "beamsim/contact_flag.h"
#include "thesis/thesis.h"

#define BROAD_PHASE_MIN_BEAMS THESIS_BROAD_PHASE_MIN_BEAMS

/* The cell of p, clamped to [-1, n] in floating point first, so that a
 * point however far away (a body flung at 1e300 m/s) converts to int
 * without overflow. NaN goes to -1. */
static int grid_index(double t, int n)
{
	double c = floor(t);
	if (!(c > -1.0)) /* also NaN */
		return -1;
	return c > (double)n ? n : (int)c;
}

static void grid_cell_of(const thesis_grid *g, const double p[2], int *cx, int *cy)
{
	*cx = grid_index((p[0] - g->origin[0]) / g->cell, g->nx);
	*cy = grid_index((p[1] - g->origin[1]) / g->cell, g->ny);
}

void bsim_thesis_grid_build(thesis_model *m)
{
	thesis_grid *g = &m->grid;
	double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY}, reach = 0.0;
	for (int i = 0; i < m->n_beams; i++) {
		const thesis_beam_model *b = &m->beams[i];
		for (int a = 0; a < 2; a++) {
			lo[a] = fmin(lo[a], b->p[a]);
			hi[a] = fmax(hi[a], b->p[a]);
		}
		reach = fmax(reach, b->length + m->radius);
	}
	if (m->n_beams == 0)
		lo[0] = lo[1] = hi[0] = hi[1] = 0.0;
	/* A cell at least the reach wide; wider where the pivots are spread so
	 * far apart that the grid would hold many more cells than beams: at
	 * most 4 n + 16 (nx <= span / cell + 1 exactly, and ny alike), the room
	 * THESIS_BEAM_ARRAYS gives g->start. */
	g->cell = reach > 0.0 ? reach : 1.0;
	double cells_max = 4.0 * m->n_beams + 16.0;
	while (((hi[0] - lo[0]) / g->cell + 1.0) * ((hi[1] - lo[1]) / g->cell + 1.0) > cells_max)
		g->cell *= 2.0;
	g->origin[0] = lo[0];
	g->origin[1] = lo[1];
	g->nx = (int)floor((hi[0] - lo[0]) / g->cell) + 1;
	g->ny = (int)floor((hi[1] - lo[1]) / g->cell) + 1;
	size_t cells = (size_t)g->nx * (size_t)g->ny;
	/* Counting sort by cell keeps the beams of a cell in ascending order:
	 * start[c] counts cell c's beams and then sums them into the cell's
	 * end (start[cells] = n), which filling from the last beam moves back
	 * to the cell's start. */
	for (int i = 0; i < m->n_beams; i++) {
		int cx, cy;
		grid_cell_of(g, m->beams[i].p, &cx, &cy);
		g->start[(size_t)cy * g->nx + cx]++;
	}
	for (size_t c = 1; c <= cells; c++)
		g->start[c] += g->start[c - 1];
	for (int i = m->n_beams - 1; i >= 0; i--) {
		int cx, cy;
		grid_cell_of(g, m->beams[i].p, &cx, &cy);
		g->items[--g->start[(size_t)cy * g->nx + cx]] = i;
	}
}

static int cmp_int(const void *a, const void *b)
{
	int x = *(const int *)a, y = *(const int *)b;
	return (x > y) - (x < y);
}

/* Sorts the first n candidates ascending: by insertion while they are few
 * (the usual case, and the awake ones come sorted). */
static void sort_small(int *v, int n)
{
	if (n > 32) {
		qsort(v, (size_t)n, sizeof *v, cmp_int);
		return;
	}
	for (int i = 1; i < n; i++) {
		int x = v[i], j = i - 1;
		for (; j >= 0 && v[j] > x; j--)
			v[j + 1] = v[j];
		v[j + 1] = x;
	}
}

/* Free flight among beams at rest (bsim_thesis_broad_phase_clear). A beam at
 * rest is its segment S_i from P_i along its rest direction u0_i, and the
 * body can touch it within a step only if its centre comes within R + m of
 * S_i (m: the step's margin). The room around a clear body: with its
 * centre at C_c every beam has
 *   dist(C_c, S_i) >= R + D        (D = clear_room),
 * so with the centre at C, dist(C, S_i) >= R + D - |C - C_c| (the
 * distance to a fixed set moves no faster than the point), and a step
 * whose margin m has |C - C_c|_1 + m < D (|.|_1 >= |.|) finds every beam
 * out of reach, as detecting them would (their gap exceeds the margin, so
 * no contact; the body ends the step more than BSIM_CONTACT_TOL from each,
 * so no flag): the step's test is then two differences, not a beam's
 * distance each. D is cut by 1e-9 of the lengths involved (the distances,
 * the reaches, |C_c|), which covers the round-off of the test and of the
 * distances (1e-16 of the same lengths): the room may say "not clear"
 * where the beams are, then tested, clear, never the reverse. The beams
 * at rest never move, so the room holds while they stay at rest (the
 * callers ask only then: no beam awake); it is refilled wherever the
 * beams are found clear after it failed. */
static double rest_distance2(const struct bsim_world *w, const thesis_beam_model *b)
{
	int type;
	return bsim_beam_distance2(b->p, b->u0, b->length, w->x, &type);
}

static void clear_fill(struct bsim_world *w)
{
	double room = INFINITY, reach_max = 0.0;
	for (int i = 0; i < w->model->n_beams; i++) {
		const thesis_beam_model *b = &w->model->beams[i];
		room = fmin(room, sqrt(rest_distance2(w, b)) * (1.0 - 1e-9) - w->model->radius);
		reach_max = fmax(reach_max, b->length + w->model->radius);
	}
	w->clear_x[0] = w->x[0];
	w->clear_x[1] = w->x[1];
	/* No beam: INFINITY - INFINITY, NaN, never clear by the room. */
	w->clear_room = room - 1e-9 * (reach_max + fabs(room) + fabs(w->x[0]) + fabs(w->x[1]));
}

/* With every beam at rest the step's margin is 2 h |v| + slop
 * (thesis_clear_margin bounds it). NaN or overflow: not clear. */
int bsim_thesis_broad_phase_clear(struct bsim_world *w, const double force[2], double h)
{
	if (!w->model->broad_phase || w->model->n_beams > BROAD_PHASE_MIN_BEAMS)
		return 0; /* broad_phase=0: every beam tested, for checking */
	double margin = thesis_clear_margin(w, force, h);
	if (fabs(w->x[0] - w->clear_x[0]) + fabs(w->x[1] - w->clear_x[1]) + margin < w->clear_room)
		return 1; /* clear_fill below */
	for (int i = 0; i < w->model->n_beams; i++) {
		const double reach = (w->model->radius + margin) * (1.0 + 1e-9);
		if (!(rest_distance2(w, &w->model->beams[i]) > reach * reach))
			return 0;
	}
	clear_fill(w);
	return 1;
}

/* The candidate cache. One grid query lists every beam (awake or not)
 * whose pivot P lies within L + R + D of the body's centre C_c then (D =
 * near_reach, a quarter cell plus the margin asked). While the body's
 * centre C stays within D - margin of C_c, every beam the query for C
 * would find, |C - P| <= L + R + margin, has
 *   |C_c - P| <= |C_c - C| + |C - P| <= L + R + D,
 * so it is in the list: filtering the list with the query's own test finds
 * the same beams. The query's order (cells in ascending rows and columns,
 * beams ascending within a cell) does not depend on where it is centred,
 * so the list keeps it and the filtered beams come out in the order the
 * query gives them. Cushions of 1e-9 of the lengths cover round-off (the
 * list may hold more, never fewer). A step then tests the few beams of the
 * list instead of the cells around the body. NaN fails every test: the
 * list is refilled, from a query that finds nothing, as before. */
void bsim_thesis_near_forget(struct bsim_world *w)
{
	w->n_near = 0;
	w->near_reach = 0.0;
}

static void near_fill(struct bsim_world *w, double margin)
{
	const thesis_grid *g = &w->model->grid;
	double d = 0.25 * g->cell + margin;
	double r = g->cell + d;
	double lo[2] = {w->x[0] - r, w->x[1] - r}, hi[2] = {w->x[0] + r, w->x[1] + r};
	int c0x, c0y, c1x, c1y;
	w->n_near = 0;
	w->near_x[0] = w->x[0];
	w->near_x[1] = w->x[1];
	w->near_reach = d;
	if (hi[0] < g->origin[0] || hi[1] < g->origin[1] ||
	    lo[0] > g->origin[0] + g->cell * g->nx || lo[1] > g->origin[1] + g->cell * g->ny)
		return;
	grid_cell_of(g, lo, &c0x, &c0y);
	grid_cell_of(g, hi, &c1x, &c1y);
	c0x = c0x < 0 ? 0 : c0x;
	c0y = c0y < 0 ? 0 : c0y;
	c1x = c1x >= g->nx ? g->nx - 1 : c1x;
	c1y = c1y >= g->ny ? g->ny - 1 : c1y;
	for (int cy = c0y; cy <= c1y; cy++)
		for (int cx = c0x; cx <= c1x; cx++) {
			size_t c = (size_t)cy * g->nx + cx;
			for (int k = g->start[c]; k < g->start[c + 1]; k++) {
				int i = g->items[k];
				const thesis_beam_model *b = &w->model->beams[i];
				double dx = w->x[0] - b->p[0], dy = w->x[1] - b->p[1];
				double reach = (b->length + w->model->radius + d) * (1.0 + 1e-9);
				if (dx * dx + dy * dy > reach * reach)
					continue;
				w->near[w->n_near++] = i;
			}
		}
}

/* Appends to out[n..] the beams at rest (not awake) whose pivot lies
 * within L + R + margin of the body's centre, in the grid's order; returns
 * the new count, *found set if any was. */
static int near_query(struct bsim_world *w, double margin, int *out, int n, int *found)
{
	double ex = w->x[0] - w->near_x[0], ey = w->x[1] - w->near_x[1];
	double lim = (w->near_reach - margin) * (1.0 - 1e-9);
	if (!(lim > 0.0 && ex * ex + ey * ey < lim * lim))
		near_fill(w, margin);
	*found = 0;
	for (int k = 0; k < w->n_near; k++) {
		int i = w->near[k];
		if (w->is_awake[i])
			continue;
		if (beam_beyond_reach(w, &w->model->beams[i], margin))
			continue;
		out[n++] = i;
		*found = 1;
	}
	return n;
}

/* Fills w->candidates with the awake beams and those at rest within reach
 * plus margin; returns how many, *sleeping_found set if any beam at rest
 * was added (then the list is no longer in ascending order). A world of
 * few beams, or broad_phase=0, lists them all, in order. */
static int candidates_within(struct bsim_world *w, double margin, int *sleeping_found)
{
	int *out = w->candidates;
	int n = 0;
	*sleeping_found = 0;
	if (!w->model->broad_phase || w->model->n_beams <= BROAD_PHASE_MIN_BEAMS) {
		for (int i = 0; i < w->model->n_beams; i++)
			out[n++] = i;
		return n;
	}
	for (int k = 0; k < w->n_awake; k++)
		out[n++] = w->awake[k];
	return near_query(w, margin, out, n, sleeping_found);
}

/* Fills w->candidates with the beams the step must test, in ascending
 * order; returns how many. */
int bsim_thesis_broad_phase(struct bsim_world *w, double speed, double h)
{
	int sleeping_found;
	int n = candidates_within(w, 2.0 * h * speed + w->model->slop, &sleeping_found);
	if (sleeping_found)
		sort_small(w->candidates, n);
	return n;
}

/* The same query with a margin of its own. Unsorted. */
int bsim_thesis_broad_phase_near(struct bsim_world *w, double margin)
{
	int found;
	return candidates_within(w, margin, &found);
}
