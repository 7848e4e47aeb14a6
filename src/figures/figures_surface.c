/* A landscape's 3-D surface drawn smooth (figures_surface.h).
 *
 * The landscape E(x, y) = F_prop (y0 - y) + sum 1/2 k_i th_i(x, y)^2
 * (docs/model.md section 7) is smooth but for a few curves:
 *   - the rim of beam i's reach, rho_i = L_i + R: th_i steps from phi_i to 0
 *     (the beam is free beyond it), an upright step where phi_i > 0;
 *   - the half line behind a pivot (along_i < 0, fwd_i = 0): phi_i jumps
 *     from pi to -pi;
 *   - the pivot's disk rho_i < R, where the body cannot be (not drawn);
 *   - the cap E = cap, above which the surface is not drawn (near a pivot
 *     th nears pi and E thousands of joules).
 * A grid of cells sampled at their corners draws each of them as a
 * staircase of shards. Here every cell is cut along those curves instead:
 * each edge of a cell that a curve crosses is split where it crosses
 * (bisection to 1e-12 of the edge), so the surface ends on a polyline
 * within a hair of the curve, each side of a step evaluated on its own side
 * (a point of the inside's polygon just beyond the rim is taken back
 * radially within it). The pieces within the cap are drawn; cells where
 * the surface bends (a midpoint off the straight line between its
 * neighbours by more than the tolerance) are split in four, down to
 * DEPTH_MAX levels, and a coarser neighbour takes the finer one's vertices
 * on their common edge, so that no crack opens between them.
 *
 * gnuplot's pm3d draws quadrangles: a cell left whole is the scans (v0, v1)
 * and (v3, v2), a cut one a fan of triangles about its centre, two to a
 * quadrangle, a triangle (c, a, b) the scans (c, a) and (c, b); a scan
 * without a value after each keeps pm3d from joining it to the next, and
 * `pm3d depthorder` sorts them all. */
#define _POSIX_C_SOURCE 200809L
#include "figures/figures_surface.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/landscape.h"

/* Levels a base cell may be split into (a cell 1/8 of the base's side). */
#define DEPTH_MAX 4
/* Vertices a piece of a cell may have: four corners, up to 2^DEPTH_MAX - 1
 * hanging vertices an edge, two more for each cut. */
#define PIECE_MAX 80
/* Pieces of one cell: the cuts of a few curves. */
#define PIECES_MAX 24
/* Beams whose reach one cell's rim cut decides (a piece's forced sides). */
#define FORCED_MAX 8

typedef struct svtx {
	double x, y, e; /* m, m, J */
} svtx;

typedef struct piece {
	int n, whole; /* whole: the cell's four corners, uncut */
	svtx v[PIECE_MAX];
	int n_forced;
	int forced_beam[FORCED_MAX];
	signed char forced_side[FORCED_MAX]; /* +1 beyond the beam's reach, -1 within */
} piece;

typedef struct mesher {
	const bsim_scene *s;
	const fsurface *d;
	double tol;            /* J: the most a midpoint may lie off its edge */
	int nx0, ny0;          /* base cells */
	double hx, hy;         /* m: a base cell */
	int lx, ly;            /* lattice points a side, at the finest level */
	unsigned char *corner; /* lx * ly: a corner of some leaf */
	int *leaf;             /* (level, i, j) of each leaf */
	size_t n_leaf, cap_leaf;
	piece *cur, *next; /* PIECES_MAX each: a cell's pieces as they are cut */
	FILE *out;
	long count;
	int failed; /* out of memory */
} mesher;

enum { CUT_REACH, CUT_PIVOT, CUT_BEHIND, CUT_CAP };

/* ---- the landscape on one side of its steps --------------------------------------------- */

static int forced_side(const piece *p, int beam)
{
	for (int k = 0; k < p->n_forced; k++)
		if (p->forced_beam[k] == beam)
			return p->forced_side[k];
	return 0;
}

/* E at (x, y) as piece p has it: a beam whose rim cuts p's cell on the side
 * p lies on, the others by the point. */
static double piece_energy(const mesher *m, const piece *p, double x, double y)
{
	const bsim_scene *s = m->s;
	const double R = s->body.radius;
	double eb = 0.0;
	for (int i = 0; i < s->n_beams; i++) {
		const bsim_beam_def *b = &s->beams[i];
		const int side = forced_side(p, i);
		if (side > 0)
			continue; /* beyond its reach: at rest */
		double c[2] = {x, y};
		if (side < 0) {
			const double dx = x - b->pivot[0], dy = y - b->pivot[1];
			const double r = hypot(dx, dy), reach = (b->length + R) * (1.0 - 1e-12);
			if (r >= reach) {
				c[0] = b->pivot[0] + dx * reach / r;
				c[1] = b->pivot[1] + dy * reach / r;
			}
		}
		const double th = bsim_landscape_theta(b, R, c);
		eb += 0.5 * b->stiffness * th * th;
	}
	return m->d->beam_only ? eb : eb + bsim_landscape_e_prop(s, y);
}

/* The components of (x, y) - pivot along beam b's rest direction and its
 * forward normal (as bsim_landscape_theta takes them). */
static void beam_frame(const bsim_beam_def *b, double x, double y, double *along, double *fwd)
{
	double u0[2];
	bsim_scene_beam_rest_direction(b, u0);
	const double sgn = bsim_scene_beam_forward_sign(b);
	const double dx = x - b->pivot[0], dy = y - b->pivot[1];
	*along = u0[0] * dx + u0[1] * dy;
	*fwd = sgn * (u0[0] * dy - u0[1] * dx);
}

/* The field whose sign says the side of a cut at (x, y). */
static double cut_field(const mesher *m, const piece *p, int cut, int beam, double x, double y)
{
	if (cut == CUT_CAP) {
		const double e = piece_energy(m, p, x, y);
		return e <= m->d->cap ? e - m->d->cap : 1.0; /* NaN above */
	}
	const bsim_beam_def *b = &m->s->beams[beam];
	const double R = m->s->body.radius;
	const double dx = x - b->pivot[0], dy = y - b->pivot[1], r2 = dx * dx + dy * dy;
	if (cut == CUT_REACH)
		return r2 - (b->length + R) * (b->length + R);
	if (cut == CUT_PIVOT)
		return r2 - R * R;
	double along, fwd;
	beam_frame(b, x, y, &along, &fwd);
	return fwd;
}

/* ---- cutting a piece ----------------------------------------------------------------- */

/* Where the cut crosses the segment a-b (of opposite signs): bisected from
 * the lesser end, lexicographically, so that the two cells sharing an edge
 * find the same point; *on_a and *on_b the two ends of the last bracket, on
 * a's side and on b's. */
static void crossing(const mesher *m, const piece *p, int cut, int beam, const svtx *a,
                     const svtx *b, svtx *on_a, svtx *on_b)
{
	const int swap = a->x > b->x || (a->x == b->x && a->y > b->y);
	const svtx *lo = swap ? b : a, *hi = swap ? a : b;
	const int lo_pos = cut_field(m, p, cut, beam, lo->x, lo->y) >= 0.0;
	double t0 = 0.0, t1 = 1.0;
	for (int k = 0; k < 40; k++) {
		const double t = 0.5 * (t0 + t1);
		const double f = cut_field(m, p, cut, beam, lo->x + t * (hi->x - lo->x),
		                           lo->y + t * (hi->y - lo->y));
		if ((f >= 0.0) == lo_pos)
			t0 = t;
		else
			t1 = t;
	}
	svtx at_lo = {lo->x + t0 * (hi->x - lo->x), lo->y + t0 * (hi->y - lo->y), NAN};
	svtx at_hi = {lo->x + t1 * (hi->x - lo->x), lo->y + t1 * (hi->y - lo->y), NAN};
	*on_a = swap ? at_hi : at_lo;
	*on_b = swap ? at_lo : at_hi;
}

static void push(piece *p, svtx v)
{
	if (p->n < PIECE_MAX)
		p->v[p->n++] = v;
	else
		p->n = PIECE_MAX + 1; /* too many: the piece is left out */
}

/* Splits p by the sign of a cut into pos (>= 0) and neg (< 0), either of
 * which may come out empty; the count of crossings. */
static int split(const mesher *m, const piece *p, int cut, int beam, piece *pos, piece *neg)
{
	int side[PIECE_MAX];
	int any_pos = 0, any_neg = 0;
	for (int k = 0; k < p->n; k++) {
		side[k] = cut_field(m, p, cut, beam, p->v[k].x, p->v[k].y) >= 0.0;
		any_pos |= side[k];
		any_neg |= !side[k];
	}
	*pos = *neg = *p;
	pos->n = neg->n = 0;
	pos->whole = neg->whole = 0;
	if (!any_neg) {
		*pos = *p;
		return 0;
	}
	if (!any_pos) {
		*neg = *p;
		return 0;
	}
	int crossings = 0;
	for (int k = 0; k < p->n; k++) {
		const int k1 = (k + 1) % p->n;
		piece *here = side[k] ? pos : neg, *there = side[k1] ? pos : neg;
		push(here, p->v[k]);
		if (side[k] != side[k1]) {
			svtx on_a, on_b;
			crossing(m, p, cut, beam, &p->v[k], &p->v[k1], &on_a, &on_b);
			push(here, on_a);
			push(there, on_b);
			crossings++;
		}
	}
	if (pos->n > PIECE_MAX)
		pos->n = 0;
	if (neg->n > PIECE_MAX)
		neg->n = 0;
	return crossings;
}

static void force(piece *p, int beam, int side)
{
	if (p->n_forced < FORCED_MAX) {
		p->forced_beam[p->n_forced] = beam;
		p->forced_side[p->n_forced++] = (signed char)side;
	}
}

/* The pieces of a cell's polygon (its corners and hanging vertices, counter
 * clockwise) drawn, into m->cur: cut at every rim, without the pivots'
 * disks, cut behind the pivots, within the cap; each vertex with its E.
 * Their count; *tangled: a cut crossed a piece more than twice (the cell is
 * too coarse for it). */
static int cell_pieces(mesher *m, const piece *cell, int *tangled)
{
	static const int order[] = {CUT_REACH, CUT_PIVOT, CUT_BEHIND};
	const bsim_scene *s = m->s;
	piece *cur = m->cur, *next = m->next;
	int n = 1;
	cur[0] = *cell;
	*tangled = 0;
	for (int o = 0; o < 3; o++)
		for (int i = 0; i < s->n_beams; i++) {
			const int cut = order[o];
			int n_next = 0;
			for (int k = 0; k < n; k++) {
				const piece *p = &cur[k];
				int apply = 1;
				if (cut == CUT_BEHIND) {
					/* only where the beam's phi jumps: behind its pivot,
					 * within its reach */
					const bsim_beam_def *b = &s->beams[i];
					const double reach = b->length + s->body.radius;
					apply = 0;
					for (int v = 0; v < p->n && !apply; v++) {
						double along, fwd;
						beam_frame(b, p->v[v].x, p->v[v].y, &along, &fwd);
						apply = along < 0.0 && hypot(along, fwd) < reach &&
						        forced_side(p, i) <= 0;
					}
				}
				if (!apply || n_next + 2 > PIECES_MAX) {
					if (n_next < PIECES_MAX)
						next[n_next++] = *p;
					continue;
				}
				piece *pos = &next[n_next], *neg = &next[n_next + 1];
				const int c = split(m, p, cut, i, pos, neg);
				*tangled |= c > 2;
				if (cut == CUT_REACH && c > 0) {
					force(pos, i, +1);
					force(neg, i, -1);
				}
				if (cut == CUT_PIVOT)
					neg->n = 0; /* the body would overlap the pivot */
				n_next += 2;
			}
			/* the cut's pieces replace the ones before it, empties dropped */
			n = 0;
			for (int k = 0; k < n_next; k++)
				if (next[k].n >= 3)
					cur[n++] = next[k];
		}
	/* E at the vertices, on each piece's own side, then the cap */
	int w = 0;
	for (int k = 0; k < n; k++) {
		piece *p = &cur[k];
		for (int v = 0; v < p->n; v++)
			p->v[v].e = piece_energy(m, p, p->v[v].x, p->v[v].y);
		piece *above = &next[0], *below = &next[1];
		const int c = split(m, p, CUT_CAP, 0, above, below);
		*tangled |= c > 2;
		if (below->n < 3)
			continue;
		for (int v = 0; v < below->n; v++)
			if (isnan(below->v[v].e))
				below->v[v].e =
				        piece_energy(m, below, below->v[v].x, below->v[v].y);
		below->whole = c == 0 && p->whole;
		cur[w++] = *below;
	}
	return w;
}

/* ---- the cells ----------------------------------------------------------------------- */

/* A cell's corner (lattice point li, lj) as a vertex. */
static svtx lattice_point(const mesher *m, int li, int lj)
{
	const double f = 1 << DEPTH_MAX;
	return (svtx){m->d->region[0] + li * m->hx / f, m->d->region[2] + lj * m->hy / f, NAN};
}

/* The cell (level, i, j): its four corners, or with every corner of a leaf
 * on its edges (hanging), counter clockwise from its lower left. */
static void cell_polygon(const mesher *m, int level, int i, int j, int hanging, piece *p)
{
	memset(p, 0, sizeof *p);
	const int step = 1 << (DEPTH_MAX - level);
	const int di[4] = {1, 0, -1, 0}, dj[4] = {0, 1, 0, -1};
	int li = i * step, lj = j * step;
	for (int side = 0; side < 4; side++)
		for (int k = 0; k < step; k++) {
			const int corner = k == 0;
			if (corner ||
			    (hanging && m->corner[(size_t)lj * (size_t)m->lx + (size_t)li]))
				p->v[p->n++] = lattice_point(m, li, lj);
			li += di[side];
			lj += dj[side];
		}
	p->whole = p->n == 4;
}

/* How far a piece is from flat, J: the most its edge midpoints and centre
 * lie off the straight lines between their neighbours, and a quarter of
 * the spread of E over its vertices (pm3d colours a polygon by the mean of
 * its corners: a polygon spanning much of the colour range is a band of
 * one colour). */
static double bend(const mesher *m, const piece *p)
{
	double worst = 0.0, cx = 0.0, cy = 0.0, ce = 0.0, lo = INFINITY, hi = -INFINITY;
	for (int k = 0; k < p->n; k++) {
		lo = fmin(lo, p->v[k].e);
		hi = fmax(hi, p->v[k].e);
	}
	worst = 0.25 * (hi - lo);
	for (int k = 0; k < p->n; k++) {
		const svtx *a = &p->v[k], *b = &p->v[(k + 1) % p->n];
		const double e = piece_energy(m, p, 0.5 * (a->x + b->x), 0.5 * (a->y + b->y));
		worst = fmax(worst, fabs(e - 0.5 * (a->e + b->e)));
		cx += a->x;
		cy += a->y;
		ce += a->e;
	}
	cx /= p->n;
	cy /= p->n;
	ce /= p->n;
	return fmax(worst, fabs(piece_energy(m, p, cx, cy) - ce));
}

static void add_leaf(mesher *m, int level, int i, int j)
{
	if (m->n_leaf == m->cap_leaf) {
		size_t cap = m->cap_leaf ? 2 * m->cap_leaf : 1024;
		int *l = realloc(m->leaf, 3 * cap * sizeof *l);
		if (!l) {
			m->failed = 1;
			return;
		}
		m->leaf = l;
		m->cap_leaf = cap;
	}
	int *l = m->leaf + 3 * m->n_leaf++;
	l[0] = level;
	l[1] = i;
	l[2] = j;
	const int step = 1 << (DEPTH_MAX - level);
	for (int c = 0; c < 4; c++) {
		const int li = (i + (c & 1)) * step, lj = (j + (c >> 1)) * step;
		m->corner[(size_t)lj * (size_t)m->lx + (size_t)li] = 1;
	}
}

/* Splits the cell in four while it bends more than the tolerance or a cut
 * tangles in it; its leaves recorded. */
static void refine(mesher *m, int level, int i, int j)
{
	if (level < DEPTH_MAX) {
		piece cell;
		cell_polygon(m, level, i, j, 0, &cell);
		int tangled;
		const int n = cell_pieces(m, &cell, &tangled);
		int split_it = tangled;
		for (int k = 0; k < n && !split_it; k++)
			split_it = bend(m, &m->cur[k]) > m->tol;
		if (split_it) {
			for (int c = 0; c < 4; c++)
				refine(m, level + 1, 2 * i + (c & 1), 2 * j + (c >> 1));
			return;
		}
	}
	add_leaf(m, level, i, j);
}

/* ---- writing -------------------------------------------------------------------------- */

/* A quadrangle a b c d (a triangle with d = a) as pm3d reads it: the scans
 * (a, b) and (d, c), then a scan without a value, so that pm3d draws no
 * quadrangle between it and the next one. All the polygons are then one
 * data set, which gnuplot's SVG draws at about 100 bytes each. */
static void write_quad(mesher *m, const svtx *a, const svtx *b, const svtx *c, const svtx *d)
{
	m->count++;
	if (m->out)
		fprintf(m->out,
		        "%.7g %.7g %.6g\n%.7g %.7g %.6g\n\n%.7g %.7g %.6g\n%.7g %.7g %.6g\n\n"
		        "NaN NaN NaN\nNaN NaN NaN\n\n",
		        a->x, a->y, a->e, b->x, b->y, b->e, d->x, d->y, d->e, c->x, c->y, c->e);
}

/* The triangles (hub, w[k], w[k + 1]) of a fan, each flat, so that pm3d's
 * lighting finds one normal over it (two to a quadrangle, off its plane,
 * shade as a patchwork); closed: w[n] is w[0]. */
static void write_fan(mesher *m, const svtx *hub, const svtx *w, int n, int closed)
{
	for (int k = 0; k < (closed ? n : n - 1); k++) {
		const svtx *a = &w[k], *b = &w[(k + 1) % n];
		if (a->x != b->x || a->y != b->y)
			write_quad(m, hub, a, b, hub);
	}
}

/* A piece as pm3d quadrangles: a whole cell as itself, any other as a fan
 * about its centre (or its first vertex, when its centre is not drawn). */
static void write_piece(mesher *m, const piece *p)
{
	if (p->whole && p->n == 4) {
		write_quad(m, &p->v[0], &p->v[1], &p->v[2], &p->v[3]);
		return;
	}
	svtx c = {0.0, 0.0, 0.0};
	for (int k = 0; k < p->n; k++) {
		c.x += p->v[k].x / p->n;
		c.y += p->v[k].y / p->n;
	}
	c.e = piece_energy(m, p, c.x, c.y);
	/* the centre of a piece that wraps round a pivot's disk or a rim may
	 * lie beyond it */
	int inside = c.e <= m->d->cap;
	for (int i = 0; i < m->s->n_beams && inside; i++) {
		const int side = forced_side(p, i);
		const double reach = cut_field(m, p, CUT_REACH, i, c.x, c.y);
		inside = cut_field(m, p, CUT_PIVOT, i, c.x, c.y) >= 0.0 &&
		         (side == 0 || (side > 0) == (reach >= 0.0));
	}
	if (inside)
		write_fan(m, &c, p->v, p->n, 1);
	else
		write_fan(m, &p->v[0], p->v + 1, p->n - 1, 0);
}

static void write_leaves(mesher *m)
{
	for (size_t k = 0; k < m->n_leaf; k++) {
		const int *l = m->leaf + 3 * k;
		piece cell;
		cell_polygon(m, l[0], l[1], l[2], 1, &cell);
		int tangled;
		const int n = cell_pieces(m, &cell, &tangled);
		for (int i = 0; i < n; i++)
			write_piece(m, &m->cur[i]);
	}
}

/* The leaves at tolerance tol; the count of polygons they make. */
static long mesh(mesher *m, double tol)
{
	m->tol = tol;
	m->n_leaf = 0;
	memset(m->corner, 0, (size_t)m->lx * (size_t)m->ly);
	for (int j = 0; j < m->ny0 && !m->failed; j++)
		for (int i = 0; i < m->nx0 && !m->failed; i++)
			refine(m, 0, i, j);
	FILE *out = m->out;
	m->out = NULL;
	m->count = 0;
	write_leaves(m);
	m->out = out;
	return m->count;
}

int bsim_fsurface_write(FILE *f, const bsim_scene *s, const fsurface *d, long *polygons,
                        bsim_error *err)
{
	if (polygons)
		*polygons = 0;
	const double w = d->region[1] - d->region[0], h = d->region[3] - d->region[2];
	mesher m = {.s = s, .d = d};
	/* base cells: a quarter of the polygons allowed, about square */
	const double cells = fmax(16.0, d->max_polygons / 16.0);
	double side = sqrt(w * h / cells);
	if (!(side > 0.0) || !isfinite(side))
		side = fmax(w, h);
	m.nx0 = (int)fmin(fmax(ceil(w / side), 2.0), 400.0);
	m.ny0 = (int)fmin(fmax(ceil(h / side), 2.0), 400.0);
	m.hx = w / m.nx0;
	m.hy = h / m.ny0;
	m.lx = m.nx0 * (1 << DEPTH_MAX) + 1;
	m.ly = m.ny0 * (1 << DEPTH_MAX) + 1;
	m.corner = calloc((size_t)m.lx * (size_t)m.ly, 1);
	m.cur = malloc(2 * PIECES_MAX * sizeof *m.cur);
	m.next = m.cur ? m.cur + PIECES_MAX : NULL;
	if (!m.corner || !m.cur) {
		free(m.corner);
		free(m.cur);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory for a surface");
	}
	/* The tolerance from a fiftieth of the drawn range: doubled while the
	 * polygons are too many, then made finer by sqrt(2) while they fit. */
	const double range =
	        isfinite(d->cap - d->e_min) && d->cap > d->e_min ? d->cap - d->e_min : 1.0;
	double tol = range / 50.0;
	long n = mesh(&m, tol);
	for (int k = 0; k < 8 && !m.failed && n > d->max_polygons; k++)
		n = mesh(&m, tol *= 2.0);
	for (int k = 0; k < 12 && !m.failed && n <= d->max_polygons; k++) {
		const long finer = mesh(&m, tol / 1.4142135623730951);
		if (finer > d->max_polygons)
			break;
		tol /= 1.4142135623730951;
		n = finer;
	}
	mesh(&m, tol);
	if (!m.failed) {
		m.out = f;
		m.count = 0;
		write_leaves(&m);
	}
	free(m.corner);
	free(m.leaf);
	free(m.cur);
	if (m.failed)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory for a surface");
	if (polygons)
		*polygons = m.count;
	return BSIM_OK;
}
