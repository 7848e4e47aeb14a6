/* The trial runner (MODEL.md section 6, DESIGN.md "The flow of one
 * experiment"): time, forces from the effect pipeline, termination,
 * outcomes, the energy ledger and recording. Everything here is the same
 * code for every backend.
 *
 * Cost. A step's bookkeeping visits only the beams the backend lists as
 * active (bsim_state.active: the others are exactly at rest), so in a
 * lattice it costs what the beams near the body cost, like the backend's
 * step. Energies summed over the active beams in ascending order are the
 * sums over all beams to the bit (a beam at rest adds +0).
 *
 * Lattices (MODEL.md section 8). The runner follows the gate the body is
 * in (lattice.h), records each entry (bsim_gate_entry), ends the trial as
 * stuck when the body has spent gate_steps steps in one gate, and measures
 * side exits from the field's centre line. Under the essay's protocol
 * (lattice.protocol: essay, trial_essay.c) each entry replaces the world by
 * one holding only the entered gate's two beams, at rest. */
#include "beamsim/trial.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/effects.h"
#include "beamsim/landscape.h"
#include "beamsim/lattice.h"
#include "model/lattice_crossing.h"
#include "util/fminmax.h"
#include "run/trial_essay.h"

/* A beam as the overlap measure sees it: pivot, rest direction, forward
 * sign, length and the square of the reach L + R within which the body can
 * touch it. */
typedef struct beam_shape {
	double p[2], u0[2], sgn, length, reach2;
} beam_shape;

struct bsim_trial_runner {
	bsim_state s0, s1; /* before and after a step */
	beam_shape *shape; /* per beam */
	int *touching;     /* per beam of the scene: contacts at the last touching step
	                    * before success_y (for the landscape label) */
	int *touch_list;   /* the beams touching[] holds non-zero */
	int n_touch;
	int cap;          /* beams the states hold */
	bsim_state whole; /* the whole lattice's state, for recording (essay protocol) */
	double *peak;     /* per beam of the scene */
	int *negative;    /* beams whose peak starts below 0 */
	int peak_cap;
	trial_essay essay;
};

bsim_trial_runner *bsim_trial_runner_alloc(void)
{
	return calloc(1, sizeof(bsim_trial_runner));
}

void bsim_trial_runner_free(bsim_trial_runner *r)
{
	if (!r)
		return;
	bsim_state_free(&r->s0);
	bsim_state_free(&r->s1);
	bsim_state_free(&r->whole);
	free(r->peak);
	free(r->negative);
	free(r->shape);
	free(r->touching);
	free(r->touch_list);
	free(r);
}

static int runner_reserve(bsim_trial_runner *r, int n_beams)
{
	if (r->cap == n_beams && r->s0.theta)
		return BSIM_OK;
	bsim_state_free(&r->s0);
	bsim_state_free(&r->s1);
	free(r->shape);
	r->cap = 0;
	r->shape = malloc((size_t)(n_beams > 0 ? n_beams : 1) * sizeof *r->shape);
	if (!r->shape || bsim_state_init(&r->s0, n_beams) || bsim_state_init(&r->s1, n_beams))
		return BSIM_EFAIL;
	r->cap = n_beams;
	return BSIM_OK;
}

static void touching_clear(bsim_trial_runner *r)
{
	for (int k = 0; k < r->n_touch; k++)
		r->touching[r->touch_list[k]] = 0;
	r->n_touch = 0;
}

/* Per beam of the scene: peaks and the touching beams (all zero between
 * trials: touching_update clears what it set). */
static int peaks_reserve(bsim_trial_runner *r, int n_beams)
{
	if (r->peak_cap >= n_beams && r->peak) {
		touching_clear(r);
		return BSIM_OK;
	}
	free(r->peak);
	free(r->negative);
	free(r->touching);
	free(r->touch_list);
	size_t n = n_beams > 0 ? (size_t)n_beams : 1;
	r->peak = malloc(n * sizeof *r->peak);
	r->negative = malloc(n * sizeof *r->negative);
	r->touching = calloc(n, sizeof *r->touching);
	r->touch_list = malloc(n * sizeof *r->touch_list);
	r->n_touch = 0;
	r->peak_cap = r->peak && r->negative && r->touching && r->touch_list ? n_beams : 0;
	return r->peak_cap ? BSIM_OK : BSIM_EFAIL;
}

static void shapes_init(beam_shape *shape, const bsim_scene *sc)
{
	for (int i = 0; i < sc->n_beams; i++) {
		const bsim_beam_def *b = &sc->beams[i];
		beam_shape *q = &shape[i];
		q->p[0] = b->pivot[0];
		q->p[1] = b->pivot[1];
		bsim_scene_beam_rest_direction(b, q->u0);
		q->sgn = bsim_scene_beam_forward_sign(b);
		q->length = b->length;
		q->reach2 = (b->length + sc->body.radius) * (b->length + sc->body.radius);
	}
}

/* How deep the body of radius R overlaps the beams, m (0 if it does not):
 * R - min_i |C - Q_i|, Q_i the point of beam i's segment nearest the centre
 * C (MODEL.md section 3). A beam whose reach L + R does not hold the
 * centre costs one distance test. */
static double overlap_depth(const beam_shape *shape, int n, double radius, const bsim_state *s)
{
	double depth = 0.0;
	for (int i = 0; i < n; i++) {
		const beam_shape *q = &shape[i];
		double dx = s->x[0] - q->p[0], dy = s->x[1] - q->p[1];
		if (dx * dx + dy * dy >= q->reach2)
			continue;
		double cs = cos(s->theta[i]), sn = q->sgn * sin(s->theta[i]);
		double ux = q->u0[0] * cs - q->u0[1] * sn, uy = q->u0[1] * cs + q->u0[0] * sn;
		double along = fmin(fmax(dx * ux + dy * uy, 0.0), q->length);
		double dist = hypot(dx - along * ux, dy - along * uy);
		depth = fmax(depth, radius - dist);
	}
	return depth;
}

const char *bsim_trial_outcome_name(bsim_outcome o)
{
	static const char *names[] = {"traversed", "side_exit", "stuck", "unstable"};
	return (unsigned)o < BSIM_N_OUTCOMES ? names[o] : "?";
}

const char *bsim_trial_type_name(bsim_type t)
{
	static const char *names[] = {"none", "left", "right"};
	return (unsigned)t < 3 ? names[t] : "?";
}

const char *bsim_trial_edge_name(bsim_edge e)
{
	static const char *names[] = {"start", "bottom", "left", "right", "top"};
	return (unsigned)e < 5 ? names[e] : "?";
}

/* ---- the trial log ----------------------------------------------------- */

bsim_trial_log *bsim_trial_log_alloc(void)
{
	return calloc(1, sizeof(bsim_trial_log));
}

void bsim_trial_log_clear(bsim_trial_log *l)
{
	if (!l)
		return;
	free(l->entries);
	free(l->peak);
	memset(l, 0, sizeof *l);
}

void bsim_trial_log_free(bsim_trial_log *l)
{
	bsim_trial_log_clear(l);
	free(l);
}

/* A malloc'd copy of n items of size bytes (NULL for none). */
static void *dup_items(const void *src, size_t n, size_t size, int *oom)
{
	if (n == 0)
		return NULL;
	void *p = malloc(n * size);
	if (!p) {
		*oom = 1;
		return NULL;
	}
	memcpy(p, src, n * size);
	return p;
}

int bsim_trial_log_copy(bsim_trial_log *dst, const bsim_trial_log *src)
{
	int oom = 0;
	memset(dst, 0, sizeof *dst);
	dst->entries = dup_items(src->entries, (size_t)src->n_entries, sizeof *src->entries, &oom);
	dst->peak = dup_items(src->peak, (size_t)src->n_beams, sizeof *src->peak, &oom);
	if (oom) {
		bsim_trial_log_clear(dst);
		return BSIM_EFAIL;
	}
	dst->n_entries = dst->cap_entries = src->n_entries;
	dst->n_beams = dst->cap_beams = src->n_beams;
	return BSIM_OK;
}

static int log_push(bsim_trial_log *l, const bsim_gate_entry *e)
{
	if (l->n_entries == l->cap_entries) {
		int cap = l->cap_entries ? 2 * l->cap_entries : 16;
		bsim_gate_entry *p = realloc(l->entries, (size_t)cap * sizeof *p);
		if (!p)
			return BSIM_EFAIL;
		l->entries = p;
		l->cap_entries = cap;
	}
	l->entries[l->n_entries++] = *e;
	return BSIM_OK;
}

static int log_peaks(bsim_trial_log *l, const double *peak, int n)
{
	if (l->cap_beams < n) {
		double *p = realloc(l->peak, (size_t)n * sizeof *p);
		if (!p)
			return BSIM_EFAIL;
		l->peak = p;
		l->cap_beams = n;
	}
	memcpy(l->peak, peak, (size_t)n * sizeof *peak);
	l->n_beams = n;
	return BSIM_OK;
}

/* ---- energies and recording ------------------------------------------- */

/* Kinetic energy of body and beams, J. Beams at rest add nothing. */
static double energy_kinetic(const bsim_scene *sc, const bsim_state *s)
{
	double e = 0.5 * sc->body.mass * (s->v[0] * s->v[0] + s->v[1] * s->v[1]);
	for (int k = 0; k < s->n_active; k++) {
		int i = s->active[k];
		e += 0.5 * sc->beams[i].inertia * s->omega[i] * s->omega[i];
	}
	return e;
}

/* Elastic energy of the beam springs, J. */
static double energy_springs(const bsim_scene *sc, const bsim_state *s)
{
	double e = 0.0;
	for (int k = 0; k < s->n_active; k++) {
		int i = s->active[k];
		e += 0.5 * sc->beams[i].stiffness * s->theta[i] * s->theta[i];
	}
	return e;
}

void bsim_trial_trajectory_header(FILE *f, int n_beams)
{
	fputs("t,x,y,vx,vy", f);
	for (int i = 1; i <= n_beams; i++)
		fprintf(f, ",theta%d,omega%d", i, i);
	fputs(",f_rand", f);
	for (int i = 1; i <= n_beams; i++)
		fprintf(f, ",contact%d", i);
	fputs(",e_kin,e_beam,e_prop\n", f);
}

void bsim_trial_ledger_header(FILE *f)
{
	fputs("t,e_kin,e_beam,e_mech,w_prop,w_rand,damper,impact,contact,correction,residual,sleep,"
	      "reset\n",
	      f);
}

void bsim_trial_trajectory_row(void *file, const bsim_record_row *row)
{
	FILE *f = file;
	const bsim_state *s = row->state;
	fprintf(f, "%.6f,%.10g,%.10g,%.10g,%.10g", row->t, s->x[0], s->x[1], s->v[0], s->v[1]);
	for (int i = 0; i < s->n_beams; i++)
		fprintf(f, ",%.10g,%.10g", s->theta[i], s->omega[i]);
	fprintf(f, ",%.10g", row->f_rand);
	for (int i = 0; i < s->n_beams; i++)
		fprintf(f, ",%d", s->contact[i]);
	fprintf(f, ",%.10g,%.10g,%.10g\n", row->e_kin, row->e_beam, row->e_prop);
}

static void ledger_row(FILE *f, const bsim_record_row *row)
{
	const bsim_ledger *l = row->ledger;
	fprintf(f, "%.6f,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g\n",
	        row->t, row->e_kin, row->e_beam, row->e_kin + row->e_beam, l->w_prop, l->w_rand,
	        l->damper, l->impact, l->contact, l->correction, l->residual, l->sleep, l->reset);
}

/* One recorded row to every sink of rec. */
static void record(const bsim_recorder *rec, const bsim_scene *sc, const bsim_state *s, long step,
                   double f_rand, const bsim_ledger *ledger)
{
	bsim_record_row row = {
	        .step = step,
	        .t = (double)step * sc->dt,
	        .state = s,
	        .f_rand = f_rand,
	        .ledger = ledger,
	        .e_kin = energy_kinetic(sc, s),
	        .e_beam = energy_springs(sc, s),
	        .e_prop = bsim_landscape_e_prop(sc, s->x[1]),
	};
	if (rec->csv)
		bsim_trial_trajectory_row(rec->csv, &row);
	if (rec->ledger)
		ledger_row(rec->ledger, &row);
	if (rec->record)
		rec->record(rec->record_user, &row);
}

/* One step's entry in the ledger: the work of each force over the body's
 * displacement, the backend's losses, and what is left over. */
static void ledger_step(bsim_ledger *l, const bsim_effects *fx, const bsim_state *s0,
                        const bsim_state *s1, double e0, double e1)
{
	const double d[2] = {s1->x[0] - s0->x[0], s1->x[1] - s0->x[1]};
	double w_prop = 0.0, w_rand = 0.0;
	for (int i = 0; i < fx->n; i++) {
		double work = fx->e[i].last * d[fx->e[i].axis];
		if (&fx->e[i] == fx->random)
			w_rand += work;
		else
			w_prop += work;
	}
	const bsim_step_energy *se = &s1->energy;
	double r = (e1 - e0) - (w_prop + w_rand - se->damper - se->impact - se->contact -
	                        se->correction - se->sleep);
	l->w_prop += w_prop;
	l->w_rand += w_rand;
	l->damper += se->damper;
	l->impact += se->impact;
	l->contact += se->contact;
	l->correction += se->correction;
	l->sleep += se->sleep;
	l->residual += r;
	l->residual_abs += fabs(r);
	l->residual_max = bsim_fmax(l->residual_max, fabs(r));
	l->inflow += fabs(w_prop) + fabs(w_rand);
}

void bsim_trial_instability_text(const bsim_trial_result *r, double dt, char *buf, size_t size)
{
	const bsim_ledger *l = &r->ledger;
	switch (r->instability) {
	case BSIM_UNSTABLE_NONFINITE:
		snprintf(buf, size, "non-finite state at step %d (t = %g s)", r->unstable_step,
		         r->unstable_step * dt);
		break;
	case BSIM_UNSTABLE_ENERGY:
		snprintf(buf, size,
		         "energy created: ledger residual %.3g J > %g x %.4g J that flowed in "
		         "(start %.4g J, end %.4g J)",
		         l->residual, BSIM_LEDGER_BOUND, l->inflow, l->e_start, l->e_end);
		break;
	default:
		snprintf(buf, size, "%s", "");
	}
}

static int state_finite(const bsim_state *s)
{
	double sum = s->x[0] + s->x[1] + s->v[0] + s->v[1];
	for (int k = 0; k < s->n_active; k++)
		sum += s->theta[s->active[k]] + s->omega[s->active[k]];
	return isfinite(sum);
}

static int any_contact(const bsim_state *s)
{
	for (int k = 0; k < s->n_active; k++)
		if (s->contact[s->active[k]])
			return 1;
	return 0;
}

static double random_value(const bsim_effects *fx)
{
	return fx->random ? fx->random->last : 0.0;
}

/* ---- peaks --------------------------------------------------------------- */

/* The world's beam i is the scene's beam map[i] (map NULL: the same). */
static int scene_beam(const int *map, int i)
{
	return map ? map[i] : i;
}

/* Every beam's peak theta over the steps so far: the active beams, beams 0
 * and 1 (trials.csv's two columns), and any beam whose peak is still below
 * 0 (a beam at rest has theta 0). */
static void peaks_update(bsim_trial_runner *r, const bsim_scene *scene, const int *map,
                         const bsim_state *s, int *n_negative)
{
	double *peak = r->peak;
	for (int k = 0; k < s->n_active; k++) {
		int i = s->active[k], g = scene_beam(map, i);
		peak[g] = bsim_fmax(peak[g], s->theta[i]);
	}
	if (!map)
		for (int i = 0; i < 2 && i < scene->n_beams; i++)
			peak[i] = bsim_fmax(peak[i], s->theta[i]);
	int m = 0; /* only without a map: the essay's beams all start at rest */
	for (int k = 0; k < *n_negative; k++) {
		int i = r->negative[k];
		peak[i] = bsim_fmax(peak[i], s->theta[i]);
		if (peak[i] < 0.0)
			r->negative[m++] = i;
	}
	*n_negative = m;
}

/* The contacts of s in touching[] (scene beams: map[i] for the world's beam
 * i, map NULL: the same), as a copy of the whole contact array would leave
 * it, at the cost of the beams listed. */
static void touching_update(bsim_trial_runner *r, const int *map, const bsim_state *s)
{
	touching_clear(r);
	for (int k = 0; k < s->n_active; k++) {
		int i = s->active[k];
		if (!s->contact[i])
			continue;
		int g = scene_beam(map, i);
		r->touching[g] = s->contact[i];
		r->touch_list[r->n_touch++] = g;
	}
}

/* ---- gates ------------------------------------------------------------- */

typedef struct gate_track {
	int ix, iy;  /* the gate the body is in */
	long dwell;  /* steps since it entered */
	int entries; /* gates entered, the start gate included */
} gate_track;

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

/* ---- the run ------------------------------------------------------------- */

typedef struct trial_ctx {
	bsim_trial_runner *r;
	const bsim_scene *scene;
	const bsim_backend *backend;
	const bsim_options *opts;
	const bsim_recorder *rec;
	bsim_trial_log *log;
	bsim_world *w;
	const bsim_scene *ws; /* the scene the world holds: the scene, or one gate's */
	const int *map;       /* world beam -> scene beam, NULL: the same */
	gate_track gate;
	bsim_trial_result *out;
	int overlap;               /* the recorder asked for overlap_max */
	bsim_solver_counts solver; /* of the worlds replaced so far (essay protocol) */
} trial_ctx;

/* A full-lattice state for the recorder from the world's state. */
static const bsim_state *whole_state(trial_ctx *c, const bsim_state *s)
{
	if (!c->map)
		return s;
	bsim_state *g = &c->r->whole;
	int local[2];
	for (int k = 0; k < s->n_active && k < 2; k++)
		local[k] = c->map[s->active[k]];
	bsim_state_set_active(g, local, s->n_active < 2 ? s->n_active : 2);
	memcpy(g->x, s->x, sizeof g->x);
	memcpy(g->v, s->v, sizeof g->v);
	for (int k = 0; k < s->n_active && k < 2; k++) {
		int i = s->active[k];
		g->theta[c->map[i]] = s->theta[i];
		g->omega[c->map[i]] = s->omega[i];
		g->contact[c->map[i]] = s->contact[i];
	}
	g->energy = s->energy;
	g->impacts = s->impacts;
	return g;
}

/* The body entered gate (ix, iy) at the end of step n (s: the state). */
static int gate_enter(trial_ctx *c, bsim_state **s0, const double p0[2], int ix, int iy, long n,
                      double *e0, bsim_error *err)
{
	bsim_gate_entry e[2];
	int k = entries_of_step(c->scene, c->map, &c->gate, p0, *s0, ix, iy, n, c->scene->dt, e);
	for (int i = 0; i < k; i++)
		if (c->log && log_push(c->log, &e[i]))
			return bsim_error_set(err, BSIM_EFAIL, "out of memory for the gate path");
	c->gate.ix = ix;
	c->gate.iy = iy;
	c->gate.dwell = 0;
	c->gate.entries += k;
	if (c->scene->lattice.protocol != BSIM_PROTOCOL_ESSAY)
		return BSIM_OK;
	double e_before = *e0;
	/* The world is replaced: what its solvers gave up on stays counted. */
	c->solver.iteration_limit += (*s0)->solver.iteration_limit;
	c->solver.clamped += (*s0)->solver.clamped;
	int rc = trial_essay_enter(&c->r->essay, c->scene, c->backend, c->opts, ix, iy, *s0, &c->w,
	                           &c->out->reset_overlaps, err);
	if (rc)
		return rc;
	c->backend->get_state(c->w, *s0);
	if (c->overlap) /* the new world's two beams */
		shapes_init(c->r->shape, c->ws);
	*e0 = energy_kinetic(c->ws, *s0) + energy_springs(c->ws, *s0);
	c->out->ledger.reset += e_before - *e0;
	return BSIM_OK;
}

static int trial_setup(trial_ctx *c, bsim_error *err)
{
	const bsim_scene *scene = c->scene;
	bsim_trial_runner *r = c->r;
	int essay = scene->has_lattice && scene->lattice.protocol == BSIM_PROTOCOL_ESSAY;
	int world_beams = essay ? 2 : scene->n_beams;
	if (runner_reserve(r, world_beams) || peaks_reserve(r, scene->n_beams))
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	int recording = c->rec && (c->rec->csv || c->rec->ledger || c->rec->record);
	if (essay && recording && r->whole.n_beams != scene->n_beams) {
		bsim_state_free(&r->whole);
		if (bsim_state_init(&r->whole, scene->n_beams))
			return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	c->ws = scene;
	c->map = NULL;
	double p[2] = {scene->body.start[0], scene->body.start[1]};
	bsim_lattice_gate_at(scene, p, &c->gate.ix, &c->gate.iy);
	if (!essay)
		return c->backend->create(scene, c->opts, &c->w, err);
	int rc = trial_essay_start(&r->essay, scene, c->backend, c->opts, c->gate.ix, c->gate.iy,
	                           &c->w, &c->out->reset_overlaps, err);
	c->ws = &r->essay.scene;
	c->map = r->essay.map;
	return rc;
}

int bsim_trial_run(bsim_trial_runner *r, const bsim_scene *scene, const bsim_backend *backend,
                   const bsim_options *opts, uint64_t seed, const bsim_recorder *rec,
                   bsim_trial_result *out, bsim_error *err)
{
	memset(out, 0, sizeof *out);
	out->landscape_beam = -1;
	trial_ctx c = {.r = r,
	               .scene = scene,
	               .backend = backend,
	               .opts = opts,
	               .rec = rec,
	               .log = rec ? rec->log : NULL,
	               .out = out,
	               .overlap = rec && rec->overlap};
	if (c.log)
		c.log->n_entries = 0;
	int rc = trial_setup(&c, err);
	if (rc) {
		trial_essay_release(&r->essay, backend, &c.w);
		return rc;
	}
	bsim_effects fx;
	if (bsim_effects_init(&fx, scene, seed)) {
		backend->destroy(c.w);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}

	bsim_state *s0 = &r->s0, *s1 = &r->s1;
	backend->get_state(c.w, s0);
	if (rec && rec->overlap)
		shapes_init(r->shape, c.ws);
	const double h = scene->dt;
	const int n_max = scene->max_steps;
	const long gate_max = scene->gate_steps > 0 ? scene->gate_steps : n_max;
	const double centre = bsim_lattice_centre_x(scene);
	double e0 = energy_kinetic(c.ws, s0) + energy_springs(c.ws, s0);
	out->ledger.e_start = e0;
	/* Peaks start at the initial angles: every beam of the scene (the
	 * essay's world holds one gate; the others start at rest). */
	int n_negative = 0;
	for (int i = 0; i < scene->n_beams; i++)
		r->peak[i] = c.map ? 0.0 : s0->theta[i];
	for (int i = 0; !c.map && i < scene->n_beams; i++)
		if (r->peak[i] < 0.0)
			r->negative[n_negative++] = i;
	if (c.log) {
		bsim_gate_entry e;
		entry_fill(&e, scene, c.map, s0, c.gate.ix, c.gate.iy, BSIM_EDGE_START,
		           s0->x[0] - (scene->has_lattice ? scene->lattice.width * c.gate.ix : 0.0),
		           0, h);
		if (log_push(c.log, &e))
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory for the gate path");
	}
	c.gate.entries = 1;
	out->ledger.inflow = e0;
	int stride = rec && rec->stride > 0 ? rec->stride : 1;
	int recording = rec && (rec->csv || rec->ledger || rec->record);
	bsim_trace_fn trace = rec ? rec->trace : NULL;
	int overlap = rec && rec->overlap;
	out->overlap_max = overlap ? 0.0 : NAN;
	double f[2];
	if (trace)
		trace(rec->trace_user, 0, s0);

	int done = 0; /* the outcome is known; running on to classify_y */
	/* The last step before success_y at which the body touched a beam:
	 * where and which beams (for the landscape label). */
	int touched = 0;
	double last_touch[2] = {0.0, 0.0};
	long recorded = -1;
	long n = 0, run_on = 0;
	out->outcome = BSIM_STUCK;
	while (rc == BSIM_OK) {
		int stop = done ? s0->x[1] >= scene->classify_y || run_on >= n_max
		                : n >= n_max || c.gate.dwell >= gate_max;
		if (stop)
			break;
		bsim_effects_force(&fx, n, h, f);
		if (recording && n % stride == 0) {
			record(rec, scene, whole_state(&c, s0), n, random_value(&fx), &out->ledger);
			recorded = n;
		}
		if ((rc = backend->step(c.w, f, h, err)) != BSIM_OK)
			break;
		backend->get_state(c.w, s1);
		double e1 = energy_kinetic(c.ws, s1) + energy_springs(c.ws, s1);
		if (!state_finite(s1) || !isfinite(e1)) {
			/* s0 stays the last finite state, the one reported. */
			out->instability = BSIM_UNSTABLE_NONFINITE;
			out->unstable_step = (int)(n + 1);
			break;
		}
		n++;
		c.gate.dwell++;
		run_on += done;
		if (trace)
			trace(rec->trace_user, n, s1);
		ledger_step(&out->ledger, &fx, s0, s1, e0, e1);
		e0 = e1;
		double p0[2] = {s0->x[0], s0->x[1]};
		bsim_state *t = s0;
		s0 = s1;
		s1 = t;
		if (overlap)
			out->overlap_max =
			        fmax(out->overlap_max, overlap_depth(r->shape, c.ws->n_beams,
			                                             scene->body.radius, s0));
		if (done)
			continue;
		peaks_update(r, scene, c.map, s0, &n_negative);
		if (any_contact(s0)) {
			touched = 1;
			last_touch[0] = s0->x[0];
			last_touch[1] = s0->x[1];
			touching_update(r, c.map, s0);
		}
		/* The gate first: a body that leaves the field ends in the gate it
		 * left from (gates are clamped into the field). */
		if (scene->has_lattice) {
			int ix, iy;
			bsim_lattice_gate_at(scene, s0->x, &ix, &iy);
			if ((ix != c.gate.ix || iy != c.gate.iy) &&
			    (rc = gate_enter(&c, &s0, p0, ix, iy, n, &e0, err)) != BSIM_OK)
				break;
		}
		if (fabs(s0->x[0] - centre) >= scene->side_x) {
			out->outcome = BSIM_SIDE_EXIT;
			break;
		}
		if (s0->x[1] >= scene->success_y) {
			out->outcome = BSIM_TRAVERSED;
			out->steps = (int)n;
			out->t_end = (double)n * h;
			done = 1;
		}
	}
	if (recording && recorded != n && rc == BSIM_OK) /* the final state, whatever the stride */
		record(rec, scene, whole_state(&c, s0), n, random_value(&fx), &out->ledger);
	if (out->outcome != BSIM_TRAVERSED) {
		out->steps = (int)n;
		out->t_end = (double)n * h;
	}
	if (out->outcome == BSIM_STUCK)
		out->in_contact_end = any_contact(s0);
	for (int i = 0; i < 2 && i < scene->n_beams; i++)
		out->max_theta[i] = r->peak[i];
	if (out->outcome == BSIM_TRAVERSED) {
		const double band = scene->classify_deadband;
		out->type = s0->v[0] > band    ? BSIM_TYPE_LEFT
		            : s0->v[0] < -band ? BSIM_TYPE_RIGHT
		                               : BSIM_TYPE_NONE;
		out->landscape_beam =
		        touched ? bsim_landscape_label(scene, last_touch, r->touching) : -1;
	}
	out->x_end = s0->x[0];
	out->y_end = s0->x[1];
	out->vx_end = s0->v[0];
	out->steps_run = (int)n;
	out->ledger.e_end = e0;
	const bsim_ledger *l = &out->ledger;
	if (!out->instability && l->residual > BSIM_LEDGER_BOUND * l->inflow + BSIM_LEDGER_FLOOR) {
		out->instability = BSIM_UNSTABLE_ENERGY;
		out->unstable_step = (int)n;
	}
	if (out->instability) {
		out->outcome = BSIM_UNSTABLE;
		out->type = BSIM_TYPE_NONE;
		out->landscape_beam = -1;
		out->in_contact_end = 0;
	}
	out->draws = fx.random ? bsim_schedule_draws(fx.random->schedule) : 0;
	out->solver = c.solver;
	out->solver.iteration_limit += s0->solver.iteration_limit;
	out->solver.clamped += s0->solver.clamped;
	if (rc == BSIM_OK)
		rc = bsim_effects_status(&fx, err);
	out->final_ix = c.gate.ix;
	out->final_iy = c.gate.iy;
	out->gates_entered = c.gate.entries;
	if (rc == BSIM_OK && c.log && log_peaks(c.log, r->peak, scene->n_beams))
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory for the peaks");
	bsim_effects_free(&fx);
	trial_essay_release(&r->essay, backend, &c.w);
	return rc;
}
