/* Contact detection between the body (a disk of radius R about C) and a
 * beam (the segment P .. P + L u). MODEL.md section 3.
 *
 *   s = clamp((C - P) . u, 0, L),  Q = P + s u,  gap = |C - Q| - R
 *   tangent (0 < s < L):  n = +-perp(u) toward the body, lever a = s u
 *   tip (s = L):          n = (C - Q) / |C - Q|,          lever a = L u
 *   pivot end (s = 0):    n = (C - P) / |C - P|,          lever a = 0
 *   c = sgn (a x n),  v_rel = v . n - omega c
 *
 * Every expression is written so that mirroring the scene in x (x -> -x,
 * sgn -> -sgn) mirrors each intermediate value bit for bit (MODEL.md
 * oracle 4): products and sums keep the same operands in the same order.
 *
 * A body of another shape (extended path, thesis.h's head) meets the beam
 * through its outline (model/body_shape.h): the outline's point K nearest
 * the segment, the segment's point Q nearest the outline, the normal n from
 * Q toward the body, gap = |K - Q| signed (< 0: overlap). Then
 *   a = Q - P,  c = sgn (a x n),  ct = sgn (a . n),
 *   r_b = K - C,  cb = r_b x n,  cbt = r_b . n,
 * tip when Q is an end of the segment, tangent otherwise. The geometry
 * keeps dist = gap + reach (w->radius is the shape's reach), so that every
 * bound below, written for a disk of radius `reach`, holds: the outline
 * lies within the reach of the centre. A turn of the body by dpsi moves no
 * point of its outline farther than reach |dpsi|, which the bound on the
 * distance adds. The disk keeps its own code (the bits of the essay's
 * runs); on the extended path it has r_b = -R n: cb = 0, cbt = -R. */
#include <math.h>

#include "model/body_shape.h"
#include "thesis/thesis.h"

void thesis_beam_direction(thesis_beam *b, double u[2])
{
	/* At rest the rotation is the identity: u0 exactly, as the formula
	 * below gives it (u0 - u0_perp * (+-0) = u0), without the sine and
	 * cosine; a lattice has many beams at rest near the body. */
	if (b->theta == 0.0) {
		u[0] = b->u0[0];
		u[1] = b->u0[1];
		return;
	}
	/* The same angle gives the same bits: the sine and cosine once per
	 * angle, however often a step asks (NaN never equals itself). */
	if (b->theta != b->u_theta) {
		double cs = cos(b->theta), sn = b->sgn * sin(b->theta);
		b->u[0] = b->u0[0] * cs - b->u0[1] * sn;
		b->u[1] = b->u0[1] * cs + b->u0[0] * sn;
		b->u_theta = b->theta;
	}
	u[0] = b->u[0];
	u[1] = b->u[1];
}

/* The body's centre x against the beam at its angle: b->geo. */
static void geometry_compute(thesis_beam *b, const double x[2])
{
	thesis_geometry *g = &b->geo;
	double dx = x[0] - b->p[0], dy = x[1] - b->p[1];
	double u[2];
	thesis_beam_direction(b, u);
	double s = dx * u[0] + dy * u[1];
	double a[2];
	g->x[0] = x[0];
	g->x[1] = x[1];
	g->theta = b->theta;
	if (s > 0.0 && s < b->length) {
		double cross = u[0] * dy - u[1] * dx; /* u x (C - P) */
		double side = cross >= 0.0 ? 1.0 : -1.0;
		g->dist = fabs(cross);
		g->n[0] = -side * u[1];
		g->n[1] = side * u[0];
		a[0] = s * u[0];
		a[1] = s * u[1];
		g->type = BSIM_CONTACT_TANGENT;
	} else {
		double l = s > 0.0 ? b->length : 0.0;
		a[0] = l * u[0];
		a[1] = l * u[1];
		double qx = dx - a[0], qy = dy - a[1];
		g->dist = sqrt(qx * qx + qy * qy);
		if (g->dist == 0.0) {
			g->type = BSIM_CONTACT_NONE; /* centre on the segment's end: no normal */
			return;
		}
		g->n[0] = qx / g->dist;
		g->n[1] = qy / g->dist;
		g->type = BSIM_CONTACT_TIP;
	}
	g->c = b->sgn * (a[0] * g->n[1] - a[1] * g->n[0]);
	g->a[0] = a[0];
	g->a[1] = a[1];
}

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
static void geometry_compute_shape(const struct bsim_world *w, thesis_beam *b)
{
	thesis_geometry *g = &b->geo;
	double u[2];
	thesis_beam_direction(b, u);
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

/* 1 if the body certainly lies farther than R + margin from the beam,
 * judged from the last geometry without trigonometry. The distance from a
 * point to the segment changes by at most how far the point moves, and
 * turning the beam by dtheta moves no point of it farther than L |dtheta|:
 *   dist >= dist_g - |x - x_g| - L |theta - theta_g|.
 * A cushion of 1e-9 of the lengths involved covers the round-off of both
 * distances, so the bound never rejects what the exact test would keep. */
static int geometry_far(const struct bsim_world *w, const thesis_beam *b, const double x[2],
                        double radius, double margin)
{
	const thesis_geometry *g = &b->geo;
	double ex = x[0] - g->x[0], ey = x[1] - g->x[1];
	double cushion = 1e-9 * (g->dist + b->length + radius + margin);
	double slack = g->dist - b->length * fabs(b->theta - g->theta) - radius - margin - cushion;
	if (w->shaped)
		slack -= radius * fabs(w->heading - g->psi);
	return slack > 0.0 && ex * ex + ey * ey < slack * slack; /* false for NaN */
}

int thesis_contact_detect(struct bsim_world *w, int i, double margin, thesis_contact *out)
{
	thesis_beam *b = &w->beams[i]; /* its geometry kept */
	double dx = w->x[0] - b->p[0], dy = w->x[1] - b->p[1];
	double reach = b->length + w->radius + margin;
	if (dx * dx + dy * dy > reach * reach)
		return 0; /* outside the beam's disc: no trigonometry needed */
	const thesis_geometry *g = &b->geo;
	/* The same configuration gives the same bits: a step's detection
	 * meets the geometry the last step's projection computed. */
	if (!(g->x[0] == w->x[0] && g->x[1] == w->x[1] && g->theta == b->theta &&
	      (!w->shaped || g->psi == w->heading))) {
		if (geometry_far(w, b, w->x, w->radius, margin))
			return 0;
		thesis_beam_touch(w, i);
		if (w->shaped)
			geometry_compute_shape(w, b);
		else
			geometry_compute(b, w->x);
	}
	if (g->type == BSIM_CONTACT_NONE)
		return 0;
	out->gap = g->dist - w->radius;
	if (out->gap > margin)
		return 0;
	out->beam = i;
	out->type = g->type;
	out->n[0] = g->n[0];
	out->n[1] = g->n[1];
	out->c = g->c;
	out->e = g->type == BSIM_CONTACT_TIP ? w->e_tip : w->e_tangent;
	out->impulse = 0.0;
	out->two = 0;
	if (w->extended) {
		out->mu = w->friction;
		out->impulse_t = 0.0;
		if (w->shaped) {
			out->cb = g->cb;
			out->cbt = g->cbt;
			out->ct = g->ct;
		} else {
			out->cb = 0.0;
			out->cbt = -w->radius;
			out->ct = b->sgn * (g->a[0] * g->n[0] + g->a[1] * g->n[1]);
		}
	}
	if (!(w->shaped && g->has2 && g->dist2 - w->radius <= margin))
		return 1;
	/* A capsule's second end along the beam. */
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
	return 2;
}

int thesis_contact_near(const struct bsim_world *w, int i, double margin)
{
	const thesis_beam *b = &w->beams[i];
	double dx = w->x[0] - b->p[0], dy = w->x[1] - b->p[1];
	double reach = b->length + w->radius + margin;
	if (dx * dx + dy * dy > reach * reach)
		return 0;
	return !geometry_far(w, b, w->x, w->radius, margin);
}
