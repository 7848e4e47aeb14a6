/* The barriers of a potential energy landscape (beamsim/landscape.h,
 * docs/model.md section 7): the lowest pass from the start basin to the far
 * side, over any beam and over each beam, for any number of beams.
 *
 * Definitions. E = E_total. A path moves between 4-neighbouring grid
 * points, never onto a point with |x| >= side_x (a trial ends there) nor
 * closer to a pivot than the body's radius (the fixed pivot blocks it).
 * The beams' reach is the union of the discs rho_b < L_b + R. The far
 * region F is the set of points outside the reach joined to the far side
 * (y >= far_y = min(success_y, top of the grid)) without entering the
 * reach; for the gate that is the region beyond the pivot row + L + R. A
 * path that enters F stays in it, and the step that enters F leaves the
 * reach at a point c: the path "leaves over beam b" if b holds the most
 * spring energy at c (bsim_landscape_label with every beam attached, as
 * the landscape assumes). For a set A of allowed labels (every label for the
 * lowest pass, {b} for beam b's pass):
 *
 *   m      the end of steepest descent from the start s (8 neighbours,
 *          strictly downhill, steps allowed by A). If m is in F the
 *          landscape falls from the start to the far side: OPEN.
 *   V      min over paths m -> far side (leaving over A) of max E on the
 *          path: the pass value; the path's highest point is the pass.
 *   basin  the points joined to m below V; its lowest point is the floor.
 *   height V - E(floor): the energy a body at rest in the start basin
 *          must gain to cross; V - E(s) says whether a body released at
 *          rest at s could cross if nothing were lost.
 *
 * Method. On a grid V is a bottleneck shortest path: Dijkstra's algorithm
 * with a path's cost the max of E instead of the sum, exact for the grid.
 * The grid value converges at first order in the spacing h (the path may
 * have to step a cell up a slope), so the pass is refined on nested
 * windows (see refine): each holds the stretch of the minimax path within
 * 3 h |grad E| of V, sampled 4 times finer (at most REFINE_CELLS points),
 * its edge points entering as sources with their coarser forward value
 * (those below V only: the start side) and as targets with their backward
 * value (below V only: the far side); three levels, about 4 mm at the
 * default 0.25 m. A window whose pass lands on its edge is enlarged and
 * searched again. The last level's change of V is its accuracy. A pass on
 * a cliff's top converges only like sqrt(h), th having a square-root
 * singularity there; its change says so.
 *
 * Why not a nudged elastic band, a string method or a saddle search:
 * they need the gradient of E and stop where its component across the
 * path vanishes. This landscape is not smooth where it matters: each
 * beam's energy drops to zero on the arc rho = L + R where its tip slides
 * off the body (a cliff of 1/2 k phi^2), and the essay gate's lowest pass
 * lies on such an arc, where one beam has just been released and the
 * path hugs the cliff's foot. The minimax search needs only values, finds
 * passes on cliffs, kinks (max(th, 0)) and walls alike, and is exact on
 * each grid.
 *
 * A beam's own pass. The lowest pass is the crest of the beam holding
 * the most spring energy there, b*; b* shares it. For another beam b the
 * lowest way out over b may still top out on b*'s crest (with propulsion,
 * beyond the symmetric gate's left crest the far side is open over either
 * beam), so b's pass is the lowest way out over b that never rises to the
 * lowest pass's level V* where another beam holds more spring energy
 * than b (or as much): its search treats those points as walls. If the
 * landscape is OPEN there is no V*, and b's pass is its lowest way out.
 *
 * The path of least resistance drawn in the figures is the descent from
 * s to m, then the path within the points that some minimax path below
 * the pass uses (forward and backward value <= V) from m over the pass to
 * the far side, minimising the integral of E - E_min + (V - E_min) / 50
 * along it (8 neighbours, E_min the lowest of those points): it follows
 * the valley floor up to the pass and down the far side. */
#include "beamsim/landscape.h"
#include "beamsim/landscape_barriers.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { CELL_FREE = 0, CELL_REACH = 1, CELL_FAR = 2, CELL_WALL = 3 };
enum { ALLOW_ANY = -100 };
/* Labels of reach points besides a beam's index: no beam deflected, or a
 * tie between the beams holding the most spring energy. */
enum { LABEL_NONE = -1, LABEL_TIE = -2 };
enum { REFINE_LEVELS = 3, REFINE_FACTOR = 4, REFINE_MARGIN = 4, REFINE_TRIES = 3 };
/* Most points of a refinement window. */
#define REFINE_CELLS 150000.0

/* One sampled rectangle: the whole grid (level 0) or a refinement window. */
typedef struct patch {
	double x0, y0, h;
	int nx, ny;
	double *e;          /* E_total, J */
	int *label;         /* bsim_landscape_label at reach points, else -1 */
	unsigned char *cls; /* CELL_* */
	double *src;        /* entry value of a source, INFINITY if none */
	double *dst;        /* exit value of a target, INFINITY if none */
	double *fwd, *bwd;  /* bottleneck values from the sources, to the targets */
	int *parent;        /* forward search tree: the previous point from a source */
	int *parent_b;      /* backward search tree: the next point to a target */
	double block_e;     /* J: reach points where a beam other than block_beam */
	int block_beam;     /* holds the most spring energy (or ties) and E >= block_e are walls */
} patch;

static void patch_free(patch *p)
{
	free(p->e);
	free(p->label);
	free(p->cls);
	free(p->src);
	free(p->dst);
	free(p->fwd);
	free(p->bwd);
	free(p->parent);
	free(p->parent_b);
	memset(p, 0, sizeof *p);
}

static int patch_alloc(patch *p, double x0, double y0, double h, int nx, int ny)
{
	memset(p, 0, sizeof *p);
	p->x0 = x0;
	p->y0 = y0;
	p->h = h;
	p->nx = nx;
	p->ny = ny;
	const size_t n = (size_t)nx * (size_t)ny;
	p->e = malloc(n * sizeof *p->e);
	p->label = malloc(n * sizeof *p->label);
	p->cls = malloc(n);
	p->src = malloc(n * sizeof *p->src);
	p->dst = malloc(n * sizeof *p->dst);
	p->fwd = malloc(n * sizeof *p->fwd);
	p->bwd = malloc(n * sizeof *p->bwd);
	p->parent = malloc(n * sizeof *p->parent);
	p->parent_b = malloc(n * sizeof *p->parent_b);
	if (!p->e || !p->label || !p->cls || !p->src || !p->dst || !p->fwd || !p->bwd ||
	    !p->parent || !p->parent_b) {
		patch_free(p);
		return BSIM_EFAIL;
	}
	for (size_t k = 0; k < n; k++)
		p->src[k] = p->dst[k] = INFINITY;
	p->block_e = INFINITY;
	p->block_beam = -1;
	return BSIM_OK;
}

static double patch_x(const patch *p, int k)
{
	return p->x0 + (k % p->nx) * p->h;
}

static double patch_y(const patch *p, int k)
{
	return p->y0 + (k / p->nx) * p->h;
}

/* The point nearest (x, y), or -1 if (x, y) lies outside by more than
 * half a spacing. */
static int patch_nearest(const patch *p, double x, double y)
{
	const double fi = (x - p->x0) / p->h, fj = (y - p->y0) / p->h;
	if (fi < -0.5 || fj < -0.5 || fi > p->nx - 0.5 || fj > p->ny - 0.5)
		return -1;
	int i = (int)lround(fi), j = (int)lround(fj);
	i = i < 0 ? 0 : i >= p->nx ? p->nx - 1 : i;
	j = j < 0 ? 0 : j >= p->ny ? p->ny - 1 : j;
	return j * p->nx + i;
}

/* May a path step from a to b, leaving over the allowed label? A path
 * never steps onto a wall or a blocked point (block_e), never leaves F,
 * and enters F only from a reach point of an allowed label (or, for any
 * label, from anywhere). */
static int step_ok(const patch *p, int a, int b, int allow)
{
	const unsigned char ca = p->cls[a], cb = p->cls[b];
	if (cb == CELL_WALL)
		return 0;
	if (cb == CELL_REACH && p->e[b] >= p->block_e && p->label[b] != p->block_beam &&
	    p->label[b] != LABEL_NONE)
		return 0;
	if (ca == CELL_FAR)
		return cb == CELL_FAR;
	if (cb != CELL_FAR || allow == ALLOW_ANY)
		return 1;
	return ca == CELL_REACH && p->label[a] == allow;
}

/* ---- A binary heap of (value, point), lazy deletion --------------------- */

typedef struct heap {
	double *key;
	int *idx;
	size_t n, cap;
} heap;

static int heap_before(const heap *q, size_t a, size_t b)
{
	return q->key[a] < q->key[b] || (q->key[a] == q->key[b] && q->idx[a] < q->idx[b]);
}

static void heap_swap(heap *q, size_t a, size_t b)
{
	double k = q->key[a];
	int i = q->idx[a];
	q->key[a] = q->key[b];
	q->idx[a] = q->idx[b];
	q->key[b] = k;
	q->idx[b] = i;
}

static int heap_push(heap *q, double key, int idx)
{
	if (q->n == q->cap) {
		size_t cap = q->cap ? 2 * q->cap : 1024;
		double *k = realloc(q->key, cap * sizeof *k);
		if (!k)
			return BSIM_EFAIL;
		q->key = k;
		int *i = realloc(q->idx, cap * sizeof *i);
		if (!i)
			return BSIM_EFAIL;
		q->idx = i;
		q->cap = cap;
	}
	size_t c = q->n++;
	q->key[c] = key;
	q->idx[c] = idx;
	while (c > 0 && heap_before(q, c, (c - 1) / 2)) {
		heap_swap(q, c, (c - 1) / 2);
		c = (c - 1) / 2;
	}
	return BSIM_OK;
}

static void heap_pop(heap *q, double *key, int *idx)
{
	*key = q->key[0];
	*idx = q->idx[0];
	q->n--;
	q->key[0] = q->key[q->n];
	q->idx[0] = q->idx[q->n];
	size_t c = 0;
	for (;;) {
		size_t l = 2 * c + 1, r = l + 1, m = c;
		if (l < q->n && heap_before(q, l, m))
			m = l;
		if (r < q->n && heap_before(q, r, m))
			m = r;
		if (m == c)
			break;
		heap_swap(q, c, m);
		c = m;
	}
}

static void heap_free(heap *q)
{
	free(q->key);
	free(q->idx);
	memset(q, 0, sizeof *q);
}

static const int NB4[4][2] = {{0, 1}, {-1, 0}, {1, 0}, {0, -1}};
static const int NB8[8][2] = {{0, 1}, {-1, 1}, {1, 1}, {-1, 0}, {1, 0}, {-1, -1}, {1, -1}, {0, -1}};

/* The bottleneck values: forward, out[k] = min over allowed paths from a
 * source to k of max(src, E on the path); backward, the same from k to a
 * target with dst, filling parent or parent_b. Returns the best finish
 * (forward: the target minimising max(out, dst); backward: the source
 * minimising max(out, src)) in *finish with its value in *value, -1 if
 * none is reached. With early set the search stops once no better finish
 * can come: values from the pass value up are then left unsettled. */
static int bottleneck(patch *p, int allow, int backward, int early, heap *q, int *finish,
                      double *value)
{
	const int n = p->nx * p->ny;
	double *out = backward ? p->bwd : p->fwd;
	const double *init = backward ? p->dst : p->src;
	const double *fin = backward ? p->src : p->dst;
	int *tree = backward ? p->parent_b : p->parent;
	*finish = -1;
	*value = INFINITY;
	q->n = 0;
	for (int k = 0; k < n; k++) {
		out[k] = INFINITY;
		tree[k] = -1;
	}
	for (int k = 0; k < n; k++)
		if (init[k] < INFINITY && p->cls[k] != CELL_WALL) {
			double v = fmax(init[k], p->e[k]);
			if (v < out[k]) {
				out[k] = v;
				if (heap_push(q, v, k))
					return BSIM_EFAIL;
			}
		}
	while (q->n > 0) {
		double v;
		int k;
		heap_pop(q, &v, &k);
		if (v > out[k])
			continue;
		if (early && v >= *value)
			break;
		if (fin[k] < INFINITY && fmax(v, fin[k]) < *value) {
			*value = fmax(v, fin[k]);
			*finish = k;
		}
		const int i = k % p->nx, j = k / p->nx;
		for (int d = 0; d < 4; d++) {
			const int ii = i + NB4[d][0], jj = j + NB4[d][1];
			if (ii < 0 || jj < 0 || ii >= p->nx || jj >= p->ny)
				continue;
			const int kk = jj * p->nx + ii;
			if (backward ? !step_ok(p, kk, k, allow) : !step_ok(p, k, kk, allow))
				continue;
			const double w = fmax(v, p->e[kk]);
			if (w < out[kk]) {
				out[kk] = w;
				tree[kk] = k;
				if (heap_push(q, w, kk))
					return BSIM_EFAIL;
			}
		}
	}
	return BSIM_OK;
}

/* The pass on the forward tree's path to target t: the first point of
 * highest E from the source side. *edge is set if the path's value is set
 * by a source's or the target's entry value rather than by a point of
 * the patch (the pass then lies outside it). */
static int path_pass(const patch *p, int t, double value, int *edge)
{
	int best = -1;
	for (int k = t; k >= 0; k = p->parent[k])
		if (p->e[k] == value)
			best = k; /* the last seen going back: the first from the source */
	*edge = best < 0;
	if (best < 0) { /* the nearest end point carries the value */
		int k = t;
		while (p->parent[k] >= 0)
			k = p->parent[k];
		best = p->src[k] >= value ? k : t;
	}
	return best;
}

/* The exit of the forward path to t: the last point before it enters F,
 * or -1 if it never does in this patch. */
static int path_exit(const patch *p, int t)
{
	int exit = -1;
	for (int k = t; k >= 0; k = p->parent[k]) {
		const int pk = p->parent[k];
		if (pk >= 0 && p->cls[k] == CELL_FAR && p->cls[pk] != CELL_FAR)
			exit = pk;
	}
	return exit;
}

static int exit_label(const patch *p, int k)
{
	return k >= 0 && p->cls[k] == CELL_REACH && p->label[k] >= 0 ? p->label[k] : -1;
}

/* Where the body cannot be: at or beyond the side boundary (a trial ends
 * there) or overlapping a pivot (a fixed point, docs/model.md section 3). */
static int blocked(const bsim_scene *s, const double c[2])
{
	if (fabs(c[0]) >= s->side_x)
		return 1;
	const double r2 = s->body.radius * s->body.radius;
	for (int i = 0; i < s->n_beams; i++) {
		const double dx = c[0] - s->beams[i].pivot[0], dy = c[1] - s->beams[i].pivot[1];
		if (dx * dx + dy * dy < r2)
			return 1;
	}
	return 0;
}

/* E_total at c, whether c lies within a beam's reach and its label (the
 * beam holding the most spring energy, LABEL_NONE, LABEL_TIE), from one
 * evaluation of each beam's th (the arithmetic of bsim_landscape_energy,
 * bsim_landscape_in_reach and bsim_landscape_label). */
static double point_eval(const bsim_scene *s, const double c[2], int *reach, int *label)
{
	double e_beam = 0.0, e_best = 0.0;
	int best = LABEL_NONE;
	*reach = 0;
	for (int i = 0; i < s->n_beams; i++) {
		const bsim_beam_def *b = &s->beams[i];
		if (!bsim_landscape_beam_reach(b, s->body.radius, c))
			continue;
		*reach = 1;
		const double th = bsim_landscape_theta(b, s->body.radius, c);
		const double e = 0.5 * b->stiffness * th * th;
		e_beam += e;
		if (e > e_best) {
			e_best = e;
			best = i;
		} else if (e == e_best && e > 0.0) {
			best = LABEL_TIE;
		}
	}
	*label = best;
	return bsim_landscape_e_prop(s, c[1]) + e_beam;
}

/* ---- Level 0: the grid ---------------------------------------------------- */

typedef struct search {
	const bsim_scene *scene;
	const bsim_landscape_grid *grid;
	patch g; /* the grid as a patch, with cell classes */
	double far_y;
	int start; /* grid point of the start */
	heap q;
} search;

/* Classes of the grid's points: walls (blocked), the reach, and F by a
 * flood fill from the far side through points outside the reach. */
static int classify_grid(search *S, bsim_error *err)
{
	patch *p = &S->g;
	const bsim_scene *s = S->scene;
	const int n = p->nx * p->ny;
	for (int k = 0; k < n; k++) {
		const double c[2] = {patch_x(p, k), patch_y(p, k)};
		p->label[k] = -1;
		if (blocked(s, c)) {
			p->cls[k] = CELL_WALL;
		} else {
			int reach;
			point_eval(s, c, &reach, &p->label[k]);
			p->cls[k] = reach ? CELL_REACH : CELL_FREE;
		}
	}
	int *stack = malloc((size_t)n * sizeof *stack), top = 0, n_far = 0;
	if (!stack)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	const double slack = 1e-9 * p->h;
	for (int k = 0; k < n; k++)
		if (p->cls[k] == CELL_FREE && patch_y(p, k) >= S->far_y - slack) {
			p->cls[k] = CELL_FAR;
			p->dst[k] = -INFINITY; /* a target: the far side itself */
			stack[top++] = k;
			n_far++;
		}
	while (top > 0) {
		const int k = stack[--top], i = k % p->nx, j = k / p->nx;
		for (int d = 0; d < 4; d++) {
			const int ii = i + NB4[d][0], jj = j + NB4[d][1];
			if (ii < 0 || jj < 0 || ii >= p->nx || jj >= p->ny)
				continue;
			const int kk = jj * p->nx + ii;
			if (p->cls[kk] == CELL_FREE) {
				p->cls[kk] = CELL_FAR;
				stack[top++] = kk;
			}
		}
	}
	free(stack);
	if (n_far == 0)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "landscape: no point of the region's far side (y >= %g m) "
		                      "lies beyond the beams' reach inside |x| < side_x = %g m; "
		                      "extend the region",
		                      S->far_y, s->side_x);
	return BSIM_OK;
}

/* Steepest descent from k0 (8 neighbours, strictly downhill, allowed
 * steps). Returns the end; the points visited go to path (if not NULL,
 * room for n) and their count to *n_path. */
static int descend(const patch *p, int k0, int allow, int *path, int *n_path)
{
	int k = k0, n = 0;
	if (path)
		path[n] = k;
	n++;
	for (;;) {
		const int i = k % p->nx, j = k / p->nx;
		int best = -1;
		double e_best = p->e[k];
		for (int d = 0; d < 8; d++) {
			const int ii = i + NB8[d][0], jj = j + NB8[d][1];
			if (ii < 0 || jj < 0 || ii >= p->nx || jj >= p->ny)
				continue;
			const int kk = jj * p->nx + ii;
			if (p->e[kk] < e_best && step_ok(p, k, kk, allow)) {
				e_best = p->e[kk];
				best = kk;
			}
		}
		if (best < 0 || p->cls[k] == CELL_FAR)
			break;
		k = best;
		if (path)
			path[n] = k;
		n++;
	}
	if (n_path)
		*n_path = n;
	return k;
}

/* ---- Refinement ----------------------------------------------------------- */

/* The value of array `which` (0 fwd, 1 bwd) and the class at (x, y) from
 * the finest of levels[0..n) that holds the point. */
static const patch *finest_holding(const patch *levels, int n, double x, double y, int *k)
{
	for (int l = n - 1; l >= 0; l--) {
		int kk = patch_nearest(&levels[l], x, y);
		if (kk >= 0) {
			*k = kk;
			return &levels[l];
		}
	}
	*k = -1;
	return NULL;
}

/* Is the point near k of patch p in F? Outside the reach, a point of a
 * finer window takes the class of the nearest coarser point, or, if that
 * one is in the reach, F if any of its neighbours is. */
static int coarse_far(const patch *p, int k)
{
	if (p->cls[k] == CELL_FAR)
		return 1;
	if (p->cls[k] != CELL_REACH && p->cls[k] != CELL_WALL)
		return 0;
	const int i = k % p->nx, j = k / p->nx;
	for (int d = 0; d < 8; d++) {
		const int ii = i + NB8[d][0], jj = j + NB8[d][1];
		if (ii >= 0 && jj >= 0 && ii < p->nx && jj < p->ny &&
		    p->cls[jj * p->nx + ii] == CELL_FAR)
			return 1;
	}
	return 0;
}

/* Builds the window w over box = {x0, x1, y0, y1} at spacing h, with
 * classes, sources and targets from the coarser levels (V_prev: the
 * coarser pass value). */
static int window_build(search *S, const patch *levels, int n_levels, double V_prev,
                        const double box[4], double h, const double floor_xy[2], patch *w)
{
	const bsim_scene *s = S->scene;
	const int nx = (int)floor((box[1] - box[0]) / h + 1e-9) + 1;
	const int ny = (int)floor((box[3] - box[2]) / h + 1e-9) + 1;
	if (patch_alloc(w, box[0], box[2], h, nx < 2 ? 2 : nx, ny < 2 ? 2 : ny))
		return BSIM_EFAIL;
	w->block_e = levels[0].block_e;
	w->block_beam = levels[0].block_beam;
	const double slack = 1e-9 * h;
	for (int k = 0; k < w->nx * w->ny; k++) {
		const double c[2] = {patch_x(w, k), patch_y(w, k)};
		w->label[k] = -1;
		int kc;
		const patch *pc = finest_holding(levels, n_levels, c[0], c[1], &kc);
		if (!pc || blocked(s, c)) {
			w->cls[k] = CELL_WALL;
			w->e[k] = INFINITY;
			continue;
		}
		int reach;
		w->e[k] = point_eval(s, c, &reach, &w->label[k]);
		if (reach) {
			w->cls[k] = CELL_REACH;
		} else {
			w->cls[k] = coarse_far(pc, kc) ? CELL_FAR : CELL_FREE;
		}
		if (w->cls[k] == CELL_FAR && c[1] >= S->far_y - slack)
			w->dst[k] = -INFINITY; /* the far side itself */
		const int i = k % w->nx, j = k / w->nx;
		/* An edge point takes the coarser values only from a point of its
		 * own kind: across the edge of F or of another beam's share, the
		 * coarser values would let a path leave over the wrong beam. */
		const int same = pc->cls[kc] == w->cls[k] &&
		                 (w->cls[k] != CELL_REACH || pc->label[kc] == w->label[k]);
		if (same && (i == 0 || j == 0 || i == w->nx - 1 || j == w->ny - 1)) {
			if (pc->fwd[kc] < V_prev)
				w->src[k] = pc->fwd[kc];
			if (pc->bwd[kc] < V_prev && w->dst[k] == INFINITY)
				w->dst[k] = pc->bwd[kc];
		}
	}
	int kf = patch_nearest(w, floor_xy[0], floor_xy[1]);
	if (kf >= 0 && w->cls[kf] != CELL_WALL)
		w->src[kf] = -INFINITY;
	return BSIM_OK;
}

/* |grad E| at c by central differences a hair apart (1e-7 h), so that a
 * point beside a cliff sees the slope of its own side. */
static double grad_norm(const bsim_scene *s, const double c[2], double h)
{
	const double eps = 1e-7 * h;
	double g[2];
	for (int d = 0; d < 2; d++) {
		double a[2] = {c[0], c[1]}, b[2] = {c[0], c[1]};
		a[d] -= eps;
		b[d] += eps;
		g[d] = (bsim_landscape_energy(s, b, NULL, NULL, NULL) -
		        bsim_landscape_energy(s, a, NULL, NULL, NULL)) /
		       (2 * eps);
	}
	const double n = hypot(g[0], g[1]);
	return isfinite(n) ? n : 0.0;
}

/* The box of the stretch of the minimax path through kp (the forward tree
 * back to the source, the backward tree on to a target) whose E exceeds
 * floor_v, widened by margin and to at least +-margin about kp, inside
 * the grid g. */
static void stretch_box(const patch *p, int kp, double floor_v, double margin, const patch *g,
                        double box[4])
{
	const double px = patch_x(p, kp), py = patch_y(p, kp);
	double b[4] = {px, px, py, py};
	for (int side = 0; side < 2; side++) {
		const int *tree = side ? p->parent_b : p->parent;
		for (int k = kp; k >= 0 && p->e[k] > floor_v; k = tree[k]) {
			const double x = patch_x(p, k), y = patch_y(p, k);
			b[0] = fmin(b[0], x);
			b[1] = fmax(b[1], x);
			b[2] = fmin(b[2], y);
			b[3] = fmax(b[3], y);
		}
	}
	const double gx1 = g->x0 + (g->nx - 1) * g->h, gy1 = g->y0 + (g->ny - 1) * g->h;
	box[0] = fmax(b[0] - margin, g->x0);
	box[1] = fmin(b[1] + margin, gx1);
	box[2] = fmax(b[2] - margin, g->y0);
	box[3] = fmin(b[3] + margin, gy1);
}

/* Refines a pass found on the grid. levels[0] is the searched grid (fwd,
 * bwd and both trees filled, kp its pass, V its value); on return
 * pass->x, y, e_total, e_beam, e_prop and refine_* are set.
 *
 * The grid's error is about h |grad E| at the pass (the path may have to
 * step one point up the slope beside it), call it delta. A coarser
 * level's values are trusted where they lie 3 delta below V, so a window
 * holds the stretch of the minimax path above V - 3 delta, plus 4
 * spacings, and is sampled at a quarter of the spacing, or coarser if it
 * would exceed REFINE_CELLS points. A window whose pass lands on its edge
 * (or whose value is set by an edge point) is doubled and searched again.
 * The searches stop once the pass is settled. */
static int refine(search *S, patch *levels, int allow, double V0, int k0, const double floor_xy[2],
                  bsim_landscape_pass *pass)
{
	int n_levels = 1, kp = k0;
	double V = V0, h = levels[0].h, change = NAN;
	const patch *g = &levels[0];
	const double gx1 = g->x0 + (g->nx - 1) * g->h, gy1 = g->y0 + (g->ny - 1) * g->h;
	for (int l = 1; l <= REFINE_LEVELS; l++) {
		const patch *prev = &levels[n_levels - 1];
		const double c[2] = {patch_x(prev, kp), patch_y(prev, kp)};
		const double delta = 1.5 * h * grad_norm(S->scene, c, h) + 1e-12 * fabs(V);
		double box[4];
		stretch_box(prev, kp, V - 3 * delta, REFINE_MARGIN * h, g, box);
		patch w;
		int accepted = 0, w_kp = -1;
		double w_V = V, hf = h;
		for (int tries = 0; tries < REFINE_TRIES && !accepted; tries++) {
			const double area = (box[1] - box[0]) * (box[3] - box[2]);
			hf = fmax(h / REFINE_FACTOR, sqrt(area / REFINE_CELLS));
			if (hf >= 0.5 * h)
				break; /* the window would not be finer */
			if (window_build(S, levels, n_levels, V, box, hf, floor_xy, &w))
				return BSIM_EFAIL;
			/* The last level's backward values serve no finer one. */
			int t, s_best, edge = 0;
			double v_back;
			if (bottleneck(&w, allow, 0, 1, &S->q, &t, &w_V) ||
			    (l < REFINE_LEVELS &&
			     bottleneck(&w, allow, 1, 1, &S->q, &s_best, &v_back))) {
				patch_free(&w);
				return BSIM_EFAIL;
			}
			w_kp = t >= 0 ? path_pass(&w, t, w_V, &edge) : -1;
			if (w_kp < 0) { /* nothing crosses: keep the coarser pass */
				patch_free(&w);
				break;
			}
			const int i = w_kp % w.nx, j = w_kp / w.nx;
			const double x = patch_x(&w, w_kp), y = patch_y(&w, w_kp);
			const int on_edge =
			        (i <= 1 && x > g->x0 + hf) || (i >= w.nx - 2 && x < gx1 - hf) ||
			        (j <= 1 && y > g->y0 + hf) || (j >= w.ny - 2 && y < gy1 - hf);
			if ((edge || on_edge) && tries + 1 < REFINE_TRIES) {
				const double hx = box[1] - box[0], hy = box[3] - box[2];
				box[0] = fmax(box[0] - 0.5 * hx, g->x0);
				box[1] = fmin(box[1] + 0.5 * hx, gx1);
				box[2] = fmax(box[2] - 0.5 * hy, g->y0);
				box[3] = fmin(box[3] + 0.5 * hy, gy1);
				patch_free(&w);
				continue;
			}
			accepted = 1;
		}
		if (!accepted)
			break;
		levels[n_levels++] = w;
		change = fabs(w_V - V);
		V = w_V;
		kp = w_kp;
		h = hf;
	}
	const patch *last = &levels[n_levels - 1];
	const double c[2] = {patch_x(last, kp), patch_y(last, kp)};
	pass->x = c[0];
	pass->y = c[1];
	pass->e_total = bsim_landscape_energy(S->scene, c, NULL, &pass->e_beam, &pass->e_prop);
	pass->refine_spacing = h;
	pass->refine_change = change;
	for (int l = 1; l < n_levels; l++)
		patch_free(&levels[l]);
	return BSIM_OK;
}

/* ---- One search: the lowest pass leaving over `allow` -------------------- */

/* Appends grid point k to the pass's path. */
static int path_add(bsim_landscape_pass *ps, const patch *p, int k, int *cap)
{
	if (ps->n_path == *cap) {
		int c = *cap ? 2 * *cap : 256;
		double *np = realloc(ps->path, (size_t)c * 2 * sizeof(double));
		if (!np)
			return BSIM_EFAIL;
		ps->path = np;
		*cap = c;
	}
	ps->path[2 * ps->n_path] = patch_x(p, k);
	ps->path[2 * ps->n_path + 1] = patch_y(p, k);
	ps->n_path++;
	return BSIM_OK;
}

/* One leg of the path of least resistance: Dijkstra from `from` to `to`
 * (-1: any target) within the points some minimax path uses (fwd, bwd
 * <= V), on the sum of (E - e_min + lift) times the step length;
 * appends the leg's points after `from` to the pass's path. */
static int resistance_leg(search *S, int allow, int from, int to, double V, double e_min,
                          double lift, bsim_landscape_pass *ps, int *cap)
{
	patch *p = &S->g;
	const int n = p->nx * p->ny;
	double *cost = malloc((size_t)n * sizeof *cost);
	int *prev = malloc((size_t)n * sizeof *prev);
	int *walk = malloc((size_t)n * sizeof *walk);
	int rc = cost && prev && walk ? BSIM_OK : BSIM_EFAIL, end = -1;
	for (int k = 0; rc == BSIM_OK && k < n; k++) {
		cost[k] = INFINITY;
		prev[k] = -1;
	}
	heap *q = &S->q;
	q->n = 0;
	if (rc == BSIM_OK) {
		cost[from] = 0.0;
		rc = heap_push(q, 0.0, from);
	}
	while (rc == BSIM_OK && q->n > 0) {
		double v;
		int k;
		heap_pop(q, &v, &k);
		if (v > cost[k])
			continue;
		if (to >= 0 ? k == to : p->dst[k] < INFINITY) {
			end = k;
			break;
		}
		const int i = k % p->nx, j = k / p->nx;
		for (int d = 0; d < 8 && rc == BSIM_OK; d++) {
			const int ii = i + NB8[d][0], jj = j + NB8[d][1];
			if (ii < 0 || jj < 0 || ii >= p->nx || jj >= p->ny)
				continue;
			const int kk = jj * p->nx + ii;
			if (p->fwd[kk] > V || p->bwd[kk] > V || !step_ok(p, k, kk, allow))
				continue;
			const double len = (NB8[d][0] && NB8[d][1]) ? 1.4142135623730951 : 1.0;
			const double w = v + len * p->h * (p->e[kk] - e_min + lift);
			if (w < cost[kk]) {
				cost[kk] = w;
				prev[kk] = k;
				rc = heap_push(q, w, kk);
			}
		}
	}
	if (rc == BSIM_OK && end >= 0) {
		int len = 0;
		for (int k = end; k >= 0; k = prev[k])
			walk[len++] = k;
		for (int t = len - 2; t >= 0 && rc == BSIM_OK; t--) /* `from` is already on it */
			rc = path_add(ps, p, walk[t], cap);
	}
	free(cost);
	free(prev);
	free(walk);
	return rc;
}

/* The path of least resistance from m over the pass kp to the far side
 * (see the top of this file). */
static int resistance_path(search *S, int allow, int m, int kp, double V, bsim_landscape_pass *ps,
                           int *cap)
{
	const patch *p = &S->g;
	const int n = p->nx * p->ny;
	/* Weights from the lowest point the path may use, so none is negative
	 * (the far side lies below the start basin's floor). */
	double e_min = p->e[m];
	for (int k = 0; k < n; k++)
		if (p->fwd[k] <= V && p->bwd[k] <= V && p->e[k] < e_min)
			e_min = p->e[k];
	const double lift = (V - e_min) / 50 + 1e-12;
	int rc = BSIM_OK;
	if (kp >= 0 && kp != m)
		rc = resistance_leg(S, allow, m, kp, V, e_min, lift, ps, cap);
	if (rc == BSIM_OK)
		rc = resistance_leg(S, allow, kp >= 0 ? kp : m, -1, V, e_min, lift, ps, cap);
	return rc;
}

/* An open way: no barrier; the pass is where the path leaves the reach. */
static void pass_open(search *S, int exit, double e_start, bsim_landscape_pass *ps)
{
	const patch *p = &S->g;
	ps->kind = BSIM_PASS_OPEN;
	if (ps->beam < 0 || exit_label(p, exit) >= 0)
		ps->beam = exit_label(p, exit);
	ps->x = ps->grid_x = patch_x(p, exit);
	ps->y = ps->grid_y = patch_y(p, exit);
	const double c[2] = {ps->x, ps->y};
	ps->e_total = bsim_landscape_energy(S->scene, c, NULL, &ps->e_beam, &ps->e_prop);
	ps->grid_e = ps->e_total;
	ps->height = 0.0;
	ps->above_start = ps->e_total - e_start;
	ps->refine_spacing = p->h;
	ps->refine_change = 0.0;
}

/* The basin floor off the grid: the lowest point of nested windows of
 * +-2 spacings at a quarter of the spacing, three times, among the points
 * of the floor's own kind (inside the same beams' reach with the same
 * label), so that it never slips over a cliff into another region. At a
 * smooth minimum the grid's error is second order and falls 16 times a
 * level. */
static void refine_floor(search *S, bsim_landscape_pass *ps)
{
	const bsim_scene *s = S->scene;
	double h = S->g.h, x = ps->floor[0], y = ps->floor[1], e = ps->floor_e;
	int reach0, label0;
	point_eval(s, ps->floor, &reach0, &label0);
	for (int l = 0; l < 3; l++) {
		const double hf = h / REFINE_FACTOR, x_c = x, y_c = y;
		for (int j = -2 * REFINE_FACTOR; j <= 2 * REFINE_FACTOR; j++)
			for (int i = -2 * REFINE_FACTOR; i <= 2 * REFINE_FACTOR; i++) {
				const double c[2] = {x_c + i * hf, y_c + j * hf};
				int reach, label;
				if (blocked(s, c))
					continue;
				const double v = point_eval(s, c, &reach, &label);
				if (reach != reach0 || label != label0)
					continue;
				if (v < e) {
					e = v;
					x = c[0];
					y = c[1];
				}
			}
		h = hf;
	}
	ps->floor[0] = x;
	ps->floor[1] = y;
	ps->floor_e = e;
}

static int search_pass(search *S, int allow, double block_e, bsim_landscape_pass *ps)
{
	patch *p = &S->g;
	p->block_e = block_e;
	p->block_beam = allow;
	const int n = p->nx * p->ny;
	memset(ps, 0, sizeof *ps);
	ps->kind = BSIM_PASS_NONE;
	ps->beam = allow == ALLOW_ANY ? -1 : allow;
	ps->refine_change = NAN;
	int cap = 0;

	/* The start basin: steepest descent from the start. */
	int *desc = malloc((size_t)n * sizeof *desc), n_desc = 0;
	if (!desc)
		return BSIM_EFAIL;
	const int m = descend(p, S->start, allow, desc, &n_desc);
	int rc = BSIM_OK;
	for (int t = 0; t < n_desc && rc == BSIM_OK; t++)
		rc = path_add(ps, p, desc[t], &cap);
	free(desc);
	if (rc)
		return rc;
	ps->floor[0] = patch_x(p, m);
	ps->floor[1] = patch_y(p, m);
	ps->floor_e = p->e[m];
	const double e_start = p->e[S->start];
	if (p->cls[m] == CELL_FAR) { /* downhill all the way: the descent left at n_desc - 2 */
		const double *q = &ps->path[2 * (ps->n_path > 1 ? ps->n_path - 2 : 0)];
		pass_open(S, patch_nearest(p, q[0], q[1]), e_start, ps);
		return BSIM_OK;
	}

	/* The pass: forward from m, backward from the far side. */
	for (int k = 0; k < n; k++)
		p->src[k] = INFINITY;
	p->src[m] = -INFINITY;
	int t, s_best;
	double V, V_back;
	if (bottleneck(p, allow, 0, 0, &S->q, &t, &V) ||
	    bottleneck(p, allow, 1, 0, &S->q, &s_best, &V_back))
		return BSIM_EFAIL;
	if (t < 0)
		return BSIM_OK; /* NONE: no path leaves over this beam */
	const int exit = path_exit(p, t);
	if (allow == ALLOW_ANY)
		ps->beam = exit_label(p, exit);

	/* The basin below V and its floor. */
	for (int k = 0; k < n; k++)
		if (p->fwd[k] < V && p->e[k] < ps->floor_e) {
			ps->floor_e = p->e[k];
			ps->floor[0] = patch_x(p, k);
			ps->floor[1] = patch_y(p, k);
		}
	if (V <= ps->floor_e) { /* a level path: no barrier */
		pass_open(S, exit >= 0 ? exit : t, e_start, ps);
		return resistance_path(S, allow, m, -1, V, ps, &cap);
	}
	/* The pass: the path's highest point. */
	int edge;
	const int kp = path_pass(p, t, V, &edge);
	ps->grid_x = patch_x(p, kp);
	ps->grid_y = patch_y(p, kp);
	ps->grid_e = V;
	ps->kind = BSIM_PASS_SADDLE;
	rc = resistance_path(S, allow, m, kp, V, ps, &cap);
	if (rc)
		return rc;
	refine_floor(S, ps);
	patch levels[REFINE_LEVELS + 1];
	levels[0] = *p;
	rc = refine(S, levels, allow, V, kp, ps->floor, ps);
	ps->height = ps->e_total - ps->floor_e;
	ps->above_start = ps->e_total - e_start;
	return rc;
}

static int pass_copy(bsim_landscape_pass *to, const bsim_landscape_pass *from, bsim_error *err)
{
	*to = *from;
	to->path = NULL;
	if (from->n_path > 0) {
		to->path = malloc((size_t)from->n_path * 2 * sizeof(double));
		if (!to->path)
			return bsim_error_set(err, BSIM_EFAIL, "out of memory");
		memcpy(to->path, from->path, (size_t)from->n_path * 2 * sizeof(double));
	}
	return BSIM_OK;
}

/* ---- Public ----------------------------------------------------------------- */

const char *bsim_landscape_pass_kind_name(bsim_pass_kind k)
{
	static const char *names[] = {"none", "open", "saddle"};
	return (unsigned)k < 3 ? names[k] : "?";
}

void bsim_landscape_barriers_free(bsim_landscape_barriers *b)
{
	if (!b)
		return;
	free(b->lowest.path);
	for (int i = 0; i < b->n_beams; i++)
		free(b->beam[i].path);
	free(b->beam);
	free(b);
}

int bsim_landscape_barriers_alloc(const bsim_scene *s, const bsim_landscape_grid *g,
                                  bsim_landscape_barriers **out, bsim_error *err)
{
	*out = NULL;
	search S;
	memset(&S, 0, sizeof S);
	S.scene = s;
	S.grid = g;
	const double top = g->y0 + (g->ny - 1) * g->spacing;
	S.far_y = fmin(s->success_y, top);
	if (patch_alloc(&S.g, g->x0, g->y0, g->spacing, g->nx, g->ny))
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	const int n = g->nx * g->ny;
	memcpy(S.g.e, g->e_total, (size_t)n * sizeof(double));
	int rc = classify_grid(&S, err);
	bsim_landscape_barriers *b = calloc(1, sizeof *b);
	if (!rc &&
	    (!b || !(b->beam = calloc(s->n_beams > 0 ? (size_t)s->n_beams : 1, sizeof *b->beam))))
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	if (rc) {
		patch_free(&S.g);
		if (b)
			free(b->beam);
		free(b);
		return rc;
	}
	b->n_beams = s->n_beams;
	b->far_y = S.far_y;
	/* The start, moved onto the grid if it lies outside. */
	const double gx1 = g->x0 + (g->nx - 1) * g->spacing;
	const double sx = fmin(fmax(s->body.start[0], g->x0), gx1);
	const double sy = fmin(fmax(s->body.start[1], g->y0), top);
	S.start = patch_nearest(&S.g, sx, sy);
	b->start[0] = patch_x(&S.g, S.start);
	b->start[1] = patch_y(&S.g, S.start);
	b->start_e = S.g.e[S.start];
	if (S.g.cls[S.start] == CELL_WALL)
		rc = bsim_error_set(
		        err, BSIM_EINPUT,
		        "landscape: the start (%g, %g) m lies at or beyond side_x = %g m "
		        "or on a pivot",
		        b->start[0], b->start[1], s->side_x);
	if (!rc && search_pass(&S, ALLOW_ANY, INFINITY, &b->lowest))
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory in the barrier search");
	/* The lowest pass crosses the beam whose crest it is (the exit's beam
	 * if no beam holds more spring energy there); that beam shares it,
	 * and the others' searches are walled off from the other crests at
	 * its level, less twice its refinement's change for safety. */
	int shared = -1;
	double block_e = INFINITY;
	if (!rc && b->lowest.kind == BSIM_PASS_SADDLE) {
		int reach, label;
		const double c[2] = {b->lowest.x, b->lowest.y};
		point_eval(s, c, &reach, &label);
		if (label >= 0)
			b->lowest.beam = label;
		shared = b->lowest.beam;
		const double margin =
		        isfinite(b->lowest.refine_change) ? 2 * b->lowest.refine_change : 0.0;
		block_e = b->lowest.e_total - margin - 1e-9 * fabs(b->lowest.e_total);
	} else if (!rc && b->lowest.kind == BSIM_PASS_OPEN) {
		shared = b->lowest.beam;
	}
	/* Only beams that some path can leave over: a beam whose reach never
	 * touches F has no pass of its own. */
	for (int i = 0; i < s->n_beams && !rc; i++) {
		int exits = 0;
		for (int k = 0; k < n && !exits; k++) {
			if (S.g.cls[k] != CELL_REACH || S.g.label[k] != i)
				continue;
			const int ii = k % g->nx, jj = k / g->nx;
			for (int d = 0; d < 4; d++) {
				const int i2 = ii + NB4[d][0], j2 = jj + NB4[d][1];
				if (i2 >= 0 && j2 >= 0 && i2 < g->nx && j2 < g->ny &&
				    S.g.cls[j2 * g->nx + i2] == CELL_FAR)
					exits = 1;
			}
		}
		if (!exits) {
			memset(&b->beam[i], 0, sizeof b->beam[i]);
			b->beam[i].kind = BSIM_PASS_NONE;
			b->beam[i].beam = i;
			b->beam[i].refine_change = NAN;
			continue;
		}
		if (i == shared) {
			rc = pass_copy(&b->beam[i], &b->lowest, err);
			continue;
		}
		if (search_pass(&S, i, block_e, &b->beam[i]))
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory in the barrier search");
	}
	heap_free(&S.q);
	patch_free(&S.g);
	if (rc) {
		bsim_landscape_barriers_free(b);
		return rc;
	}
	*out = b;
	return BSIM_OK;
}
