/* The contact geometry of a body of another shape than the disk against a
 * beam (extended path, thesis.h's head; contact_detect.c's head gives the
 * levers): the outline's nearest point from model/body_shape.h, and a
 * capsule's second contact when it lies along the beam. Apart from
 * contact_detect.c, so that the disk's detection is compiled as it was. */
#include <math.h>

#include "model/body_shape.h"
#include "thesis/thesis.h"

/* One end E of a capsule's core (cap radius R) against the segment p-tip,
 * as a contact: Q the segment's point nearest E, n = (E - Q) / |E - Q|,
 * gap |E - Q| - R, K = E - R n. 0 if E lies on the segment. */
static int cap_contact(const struct bsim_world *w, const thesis_beam *b, const double tip[2],
                       const double e[2], double *dist, double n[2], double lev[4], int *type)
{
	double d[2] = {tip[0] - b->p[0], tip[1] - b->p[1]};
	double s =
	        ((e[0] - b->p[0]) * d[0] + (e[1] - b->p[1]) * d[1]) / (d[0] * d[0] + d[1] * d[1]);
	*type = s > 0.0 && s < 1.0 ? BSIM_CONTACT_TANGENT : BSIM_CONTACT_TIP;
	s = fmin(fmax(s, 0.0), 1.0);
	double q[2] = {b->p[0] + s * d[0], b->p[1] + s * d[1]};
	double len = hypot(e[0] - q[0], e[1] - q[1]);
	if (!(len > 0.0))
		return 0;
	n[0] = (e[0] - q[0]) / len;
	n[1] = (e[1] - q[1]) / len;
	*dist = len - w->body.radius;
	double a[2] = {q[0] - b->p[0], q[1] - b->p[1]};
	double r[2] = {e[0] - w->body.radius * n[0] - w->x[0],
	               e[1] - w->body.radius * n[1] - w->x[1]};
	lev[0] = b->sgn * (a[0] * n[1] - a[1] * n[0]); /* c */
	lev[1] = b->sgn * (a[0] * n[0] + a[1] * n[1]); /* ct */
	lev[2] = r[0] * n[1] - r[1] * n[0];            /* cb */
	lev[3] = r[0] * n[0] + r[1] * n[1];            /* cbt */
	return 1;
}

/* A capsule's core ends A and B against the beam. Where the outline's
 * nearest point (body_shape_segment) lies on one end's cap (or on the
 * middle of a flat overlap), the capsule rests along the beam on both
 * ends: the geometry becomes the two ends' contacts, the nearer first (the
 * first in g, the other in g's second), so that a capsule pressed flat on a
 * beam stands on two points rather than rocking on one. Where the nearest
 * point is a beam's end against the capsule's flank, that one contact
 * stays. */
static void capsule_ends(const struct bsim_world *w, const thesis_beam *b, const double tip[2],
                         thesis_geometry *g)
{
	double half = 0.5 * w->body.length;
	double hu[2] = {half * cos(w->heading), half * sin(w->heading)};
	double ends[2][2] = {{w->x[0] - hu[0], w->x[1] - hu[1]},
	                     {w->x[0] + hu[0], w->x[1] + hu[1]}};
	double dist[2], n[2][2], lev[2][4];
	int type[2];
	for (int e = 0; e < 2; e++)
		if (!cap_contact(w, b, tip, ends[e], &dist[e], n[e], lev[e], &type[e]))
			return;
	int near = dist[1] < dist[0];
	double gap = g->dist - w->radius; /* the outline's nearest */
	/* The nearest point on an end's cap: that end's gap is the nearest. */
	if (!(dist[near] <= gap + 1e-9 * (1.0 + fabs(gap))))
		return;
	for (int k = 0; k < 2; k++) {
		int e = k == 0 ? near : 1 - near;
		double *dst_n = k == 0 ? g->n : g->n2;
		dst_n[0] = n[e][0];
		dst_n[1] = n[e][1];
		if (k == 0) {
			g->dist = dist[e] + w->radius;
			g->type = type[e];
			g->c = lev[e][0], g->ct = lev[e][1], g->cb = lev[e][2], g->cbt = lev[e][3];
		} else {
			g->dist2 = dist[e] + w->radius;
			g->type2 = type[e];
			g->c2 = lev[e][0], g->ct2 = lev[e][1], g->cb2 = lev[e][2],
			g->cbt2 = lev[e][3];
		}
	}
	g->has2 = 1;
}

/* A body of another shape against the beam: b->geo (thesis.h, the head of
 * this file). */
void thesis_shape_geometry(const struct bsim_world *w, thesis_beam *b, const double u[2])
{
	thesis_geometry *g = &b->geo;
	double tip[2] = {b->p[0] + b->length * u[0], b->p[1] + b->length * u[1]};
	g->x[0] = w->x[0];
	g->x[1] = w->x[1];
	g->theta = b->theta;
	g->psi = w->heading;
	body_segment_contact sc;
	if (body_shape_segment(&w->body, w->x, w->heading, b->p, tip, &sc) != BSIM_OK) {
		/* The beam crosses the body's centre line: no normal. */
		g->type = BSIM_CONTACT_NONE;
		g->dist = 0.0;
		return;
	}
	g->type = sc.at_end ? BSIM_CONTACT_TIP : BSIM_CONTACT_TANGENT;
	g->dist = sc.dist + w->radius;
	g->n[0] = sc.n[0];
	g->n[1] = sc.n[1];
	double a[2] = {sc.on_segment[0] - b->p[0], sc.on_segment[1] - b->p[1]};
	double r[2] = {sc.on_body[0] - w->x[0], sc.on_body[1] - w->x[1]};
	g->a[0] = a[0];
	g->a[1] = a[1];
	g->c = b->sgn * (a[0] * sc.n[1] - a[1] * sc.n[0]);
	g->ct = b->sgn * (a[0] * sc.n[0] + a[1] * sc.n[1]);
	g->cb = r[0] * sc.n[1] - r[1] * sc.n[0];
	g->cbt = r[0] * sc.n[0] + r[1] * sc.n[1];
	g->has2 = 0;
	if (w->body.shape == BSIM_SHAPE_CAPSULE)
		capsule_ends(w, b, tip, g);
}

int thesis_shape_second(const struct bsim_world *w, const thesis_geometry *g, double margin,
                        thesis_contact *out)
{
	if (!(g->dist2 - w->radius <= margin))
		return 0;
	thesis_contact *o = out + 1;
	out->two = 1;
	*o = *out;
	o->gap = g->dist2 - w->radius;
	o->type = g->type2;
	o->n[0] = g->n2[0];
	o->n[1] = g->n2[1];
	o->c = g->c2;
	o->cb = g->cb2;
	o->cbt = g->cbt2;
	o->ct = g->ct2;
	o->e = g->type2 == BSIM_CONTACT_TIP ? w->e_tip : w->e_tangent;
	return 1;
}
