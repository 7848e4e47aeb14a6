/* The contact geometry of a body of another shape than the disk against a
 * beam (extended path, thesis.h's head; contact_geometry.h's head gives the
 * levers): the outline's nearest point from beamsim/body_shape.h, and a
 * capsule's second contact when it lies along the beam. Apart from
 * contact_geometry.h, so that the disk's detection is compiled as it was. */
#include <math.h>

#include "beamsim/body_shape.h"
#include "thesis/thesis.h"

/* A pair of points, K on the capsule's core and Q on the beam, as a contact
 * of the outline: n = (K - Q) / |K - Q|, gap |K - Q| - R, the outline's
 * point K - R n; s the place of Q along the beam (0 at the pivot, 1 at the
 * tip). 0 if K lies on the beam. */
typedef struct cap_pair {
	double dist, n[2], lev[4], s; /* lev: c, ct, cb, cbt */
	int type;
} cap_pair;

static int pair_contact(const struct bsim_world *w, const thesis_beam_model *b, const double k[2],
                        const double q[2], double s, cap_pair *out)
{
	double len = hypot(k[0] - q[0], k[1] - q[1]);
	if (!(len > 0.0))
		return 0;
	double *n = out->n;
	n[0] = (k[0] - q[0]) / len;
	n[1] = (k[1] - q[1]) / len;
	out->dist = len - w->model->body.radius;
	out->s = s;
	out->type = s > 0.0 && s < 1.0 ? BSIM_CONTACT_TANGENT : BSIM_CONTACT_TIP;
	double a[2] = {q[0] - b->p[0], q[1] - b->p[1]};
	double r[2] = {k[0] - w->model->body.radius * n[0] - w->x[0],
	               k[1] - w->model->body.radius * n[1] - w->x[1]};
	out->lev[0] = b->sgn * (a[0] * n[1] - a[1] * n[0]);
	out->lev[1] = b->sgn * (a[0] * n[0] + a[1] * n[1]);
	out->lev[2] = r[0] * n[1] - r[1] * n[0];
	out->lev[3] = r[0] * n[0] + r[1] * n[1];
	return 1;
}

/* The parameter in [0, 1] of the point of segment p0-p1 nearest q, unclamped. */
static double along(const double p0[2], const double p1[2], const double q[2])
{
	double d[2] = {p1[0] - p0[0], p1[1] - p0[1]};
	return ((q[0] - p0[0]) * d[0] + (q[1] - p0[1]) * d[1]) / (d[0] * d[0] + d[1] * d[1]);
}

/* A capsule along the beam stands on the two ends of their overlap. The
 * core A-B and the beam P-T, projected on each other, overlap between two
 * extremes, each a core end over the beam (A or B against its nearest
 * beam point) or a beam end beside the core (P or T against its nearest
 * core point): the pairs with the parameter strictly inside the other
 * segment. Where the nearest of them is the outline's nearest (the
 * geometry computed from bsim_body_shape_segment), it is the first contact and
 * the other extreme, if apart along the beam, the second (g's has2): a
 * capsule pressed flat on a beam stands on two points rather than rocking
 * on one, and where it crosses the beam the second lies far and is
 * outside the step's margin. Otherwise (the nearest pair is end to end)
 * the one contact stays. */
static void capsule_pairs(const struct bsim_world *w, const thesis_beam_model *b,
                          const double tip[2], thesis_geometry *g)
{
	double half = 0.5 * w->model->body.length;
	double hu[2] = {half * cos(w->heading), half * sin(w->heading)};
	double core[2][2] = {{w->x[0] - hu[0], w->x[1] - hu[1]},
	                     {w->x[0] + hu[0], w->x[1] + hu[1]}};
	const double *beam[2] = {b->p, tip};
	double d[2] = {tip[0] - b->p[0], tip[1] - b->p[1]}, c[2] = {2 * hu[0], 2 * hu[1]};
	cap_pair cand[4];
	int m = 0;
	for (int e = 0; e < 2; e++) {
		double t = along(b->p, tip, core[e]);
		double q[2] = {b->p[0] + t * d[0], b->p[1] + t * d[1]};
		if (t > 0.0 && t < 1.0 && pair_contact(w, b, core[e], q, t, &cand[m]))
			m++;
	}
	for (int e = 0; e < 2; e++) {
		double t = along(core[0], core[1], beam[e]);
		double k[2] = {core[0][0] + t * c[0], core[0][1] + t * c[1]};
		if (t > 0.0 && t < 1.0 && pair_contact(w, b, k, beam[e], (double)e, &cand[m]))
			m++;
	}
	if (m < 2)
		return;
	int first = 0;
	for (int k = 1; k < m; k++)
		if (cand[k].dist < cand[first].dist)
			first = k;
	double gap = g->dist - w->model->radius; /* the outline's nearest */
	if (!(cand[first].dist <= gap + 1e-9 * (1.0 + fabs(gap))))
		return;
	int second = -1;
	double apart = 1e-9;
	for (int k = 0; k < m; k++)
		if (k != first && fabs(cand[k].s - cand[first].s) > apart) {
			apart = fabs(cand[k].s - cand[first].s);
			second = k;
		}
	if (second < 0)
		return;
	const cap_pair *f = &cand[first], *o = &cand[second];
	g->dist = f->dist + w->model->radius;
	g->type = f->type;
	g->n[0] = f->n[0], g->n[1] = f->n[1];
	g->c = f->lev[0], g->ct = f->lev[1], g->cb = f->lev[2], g->cbt = f->lev[3];
	g->dist2 = o->dist + w->model->radius;
	g->type2 = o->type;
	g->n2[0] = o->n[0], g->n2[1] = o->n[1];
	g->c2 = o->lev[0], g->ct2 = o->lev[1], g->cb2 = o->lev[2], g->cbt2 = o->lev[3];
	g->has2 = 1;
}

/* A body of another shape against the beam: b->geo (thesis.h, the head of
 * this file). */
void bsim_thesis_shape_geometry(const struct bsim_world *w, const thesis_beam_model *bm,
                                thesis_beam *b, const double u[2])
{
	thesis_geometry *g = &b->geo;
	double tip[2] = {bm->p[0] + bm->length * u[0], bm->p[1] + bm->length * u[1]};
	g->x[0] = w->x[0];
	g->x[1] = w->x[1];
	g->theta = b->theta;
	g->psi = w->heading;
	bsim_body_segment_contact sc;
	g->has2 = 0;
	if (bsim_body_shape_segment(&w->model->body, w->x, w->heading, bm->p, tip, &sc) !=
	    BSIM_OK) {
		/* The beam crosses the body's centre line: no normal. */
		g->type = BSIM_CONTACT_NONE;
		g->dist = 0.0;
		return;
	}
	g->type = sc.at_end ? BSIM_CONTACT_TIP : BSIM_CONTACT_TANGENT;
	g->dist = sc.dist + w->model->radius;
	g->n[0] = sc.n[0];
	g->n[1] = sc.n[1];
	double a[2] = {sc.on_segment[0] - bm->p[0], sc.on_segment[1] - bm->p[1]};
	double r[2] = {sc.on_body[0] - w->x[0], sc.on_body[1] - w->x[1]};
	g->a[0] = a[0];
	g->a[1] = a[1];
	g->c = bm->sgn * (a[0] * sc.n[1] - a[1] * sc.n[0]);
	g->ct = bm->sgn * (a[0] * sc.n[0] + a[1] * sc.n[1]);
	g->cb = r[0] * sc.n[1] - r[1] * sc.n[0];
	g->cbt = r[0] * sc.n[0] + r[1] * sc.n[1];
	if (w->model->body.shape == BSIM_SHAPE_CAPSULE)
		capsule_pairs(w, bm, tip, g);
}

int bsim_thesis_shape_second(const struct bsim_world *w, const thesis_geometry *g, double margin,
                             thesis_contact *out)
{
	if (!(g->dist2 - w->model->radius <= margin))
		return 0;
	thesis_contact *o = out + 1;
	out->two = 1;
	*o = *out;
	o->gap = g->dist2 - w->model->radius;
	o->type = g->type2;
	o->n[0] = g->n2[0];
	o->n[1] = g->n2[1];
	o->c = g->c2;
	o->cb = g->cb2;
	o->cbt = g->cbt2;
	o->ct = g->ct2;
	o->e = g->type2 == BSIM_CONTACT_TIP ? w->model->e_tip : w->model->e_tangent;
	return 1;
}
