/* Contact detection between the body (a disk of radius R about C) and a
 * beam (the segment P .. P + L u). docs/model.md section 3.
 *
 *   s = clamp((C - P) . u, 0, L),  Q = P + s u,  gap = |C - Q| - R
 *   tangent (0 < s < L):  n = +-perp(u) toward the body, lever a = s u
 *   tip (s = L):          n = (C - Q) / |C - Q|,          lever a = L u
 *   pivot end (s = 0):    n = (C - P) / |C - P|,          lever a = 0
 *   c = sgn (a x n),  v_rel = v . n - omega c
 *
 * Every expression is written so that mirroring the scene in x (x -> -x,
 * sgn -> -sgn) mirrors each intermediate value bit for bit (docs/model.md
 * check 4): products and sums keep the same operands in the same order.
 *
 * A body of another shape (extended path, thesis.h's head) meets the beam
 * through its outline (beamsim/body_shape.h): the outline's point K nearest
 * the segment, the segment's point Q nearest the outline, the normal n from
 * Q toward the body, gap = |K - Q| signed (< 0: overlap). Then
 *   a = Q - P,  c = sgn (a x n),  ct = sgn (a . n),
 *   r_b = K - C,  cb = r_b x n,  cbt = r_b . n,
 * tip when Q is an end of the segment, tangent otherwise. The geometry
 * keeps dist = gap + reach (w->model->radius is the shape's reach), so that every
 * bound below, written for a disk of radius `reach`, holds: the outline
 * lies within the reach of the centre. A turn of the body by dpsi moves no
 * point of its outline farther than reach |dpsi|, which the bound on the
 * distance adds. That geometry, and a capsule's second contact when it
 * lies along the beam, is shape_contact.c's. The disk keeps its own code
 * (the bits of the essay's runs); on the extended path it has r_b = -R n:
 * cb = 0, cbt = -R. */
#ifndef BSIM_THESIS_CONTACT_GEOMETRY_H
#define BSIM_THESIS_CONTACT_GEOMETRY_H

/* Inline, included by thesis.h: the step's detection (contact_detect.c's
 * entry points) and the runs of steps of the essay's disk (thesis_steps.c)
 * call these for every beam in reach, and share one copy. */

/* The direction u of beam b at its angle. */
static inline void thesis_beam_direction(const thesis_beam_model *bm, thesis_beam *b, double u[2])
{
	/* At rest the rotation is the identity: u0 exactly, as the formula
	 * below gives it (u0 - u0_perp * (+-0) = u0), without the sine and
	 * cosine; a lattice has many beams at rest near the body. */
	if (b->theta == 0.0) {
		u[0] = bm->u0[0];
		u[1] = bm->u0[1];
		return;
	}
	/* The same angle gives the same bits: the sine and cosine once per
	 * angle, however often a step asks (NaN never equals itself). */
	if (b->theta != b->u_theta) {
		double cs = cos(b->theta), sn = bm->sgn * sin(b->theta);
		b->u[0] = bm->u0[0] * cs - bm->u0[1] * sn;
		b->u[1] = bm->u0[1] * cs + bm->u0[0] * sn;
		b->u_theta = b->theta;
	}
	u[0] = b->u[0];
	u[1] = b->u[1];
}

/* thesis_beam_direction without keeping what it computes, for a world it
 * may not change (get_state): the kept direction where it is the angle's. */
static inline void thesis_beam_direction_of(const thesis_beam_model *bm, const thesis_beam *b,
                                            double u[2])
{
	if (b->theta == 0.0) {
		u[0] = bm->u0[0];
		u[1] = bm->u0[1];
	} else if (b->theta == b->u_theta) {
		u[0] = b->u[0];
		u[1] = b->u[1];
	} else {
		double cs = cos(b->theta), sn = bm->sgn * sin(b->theta);
		u[0] = bm->u0[0] * cs - bm->u0[1] * sn;
		u[1] = bm->u0[1] * cs + bm->u0[0] * sn;
	}
}

/* The state's raw facts of beam i (beamsim/state.h): its angle, angular
 * velocity, whether it was pushed in the step and the normal impulse it
 * took then (impulse, read where pushed), its direction, NaN where
 * it is neither pushed nor near (bsim_thesis_contact_near: the broad phase and
 * the last geometry bound it farther than BSIM_CONTACT_TOL, so no sine and
 * cosine); no pin (exact by construction: bsim_backend.exact_pins). A
 * near beam's direction is the next step's detection's too: kept (b->u). */
static inline void thesis_state_beam(struct bsim_world *w, int i, int pushed, double impulse,
                                     int near, bsim_state *s)
{
	thesis_beam *b = &w->beams[i];
	s->theta[i] = b->theta;
	s->omega[i] = b->omega;
	s->touched[i] = pushed;
	s->impulse[i] = pushed ? impulse : 0.0;
	if (pushed || near) {
		thesis_beam_direction(&w->model->beams[i], b, &s->direction[2 * i]);
	} else {
		s->direction[2 * i] = NAN;
		s->direction[2 * i + 1] = NAN;
	}
}

/* The body's centre x against the beam at its angle: b->geo; the lever a
 * kept for the extended path only (extended: a constant, see below, which
 * the compiler gives each copy). Kept apart from its callers (it may call
 * the sine and cosine): inline, the detection and the runs of steps around
 * it compiled to 30 instructions a step more on H1 (bench --callgrind),
 * most of their calls reusing a geometry or bounding it far instead. */
THESIS_APART void geometry_compute(const thesis_beam_model *bm, thesis_beam *b, const double x[2],
                                   const int extended)
{
	thesis_geometry *g = &b->geo;
	double dx = x[0] - bm->p[0], dy = x[1] - bm->p[1];
	/* where it is computed, before the direction's sine and cosine: x
	 * need not be kept across their call */
	g->x[0] = x[0];
	g->x[1] = x[1];
	g->theta = b->theta;
	double u[2];
	thesis_beam_direction(bm, b, u);
	double s = dx * u[0] + dy * u[1];
	double a[2];
	if (s > 0.0 && s < bm->length) {
		double cross = u[0] * dy - u[1] * dx; /* u x (C - P) */
		double side = cross >= 0.0 ? 1.0 : -1.0;
		g->dist = fabs(cross);
		g->n[0] = -side * u[1];
		g->n[1] = side * u[0];
		a[0] = s * u[0];
		a[1] = s * u[1];
		g->type = BSIM_CONTACT_TANGENT;
	} else {
		double l = s > 0.0 ? bm->length : 0.0;
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
	g->c = bm->sgn * (a[0] * g->n[1] - a[1] * g->n[0]);
	if (extended) {
		g->a[0] = a[0];
		g->a[1] = a[1];
	}
}

/* 1 if the body certainly lies farther than R + margin from the beam,
 * judged from the last geometry without trigonometry. The distance from a
 * point to the segment changes by at most how far the point moves, and
 * turning the beam by dtheta moves no point of it farther than L |dtheta|:
 *   dist >= dist_g - |x - x_g| - L |theta - theta_g|.
 * A cushion of 1e-9 of the lengths involved covers the round-off of both
 * distances, so the bound never rejects what the exact test would keep. */
THESIS_SPECIALISED int geometry_far(const struct bsim_world *w, const thesis_beam_model *bm,
                                    const thesis_beam *b, const double x[2], double radius,
                                    double margin, const int extended)
{
	const thesis_geometry *g = &b->geo;
	double ex = x[0] - g->x[0], ey = x[1] - g->x[1];
	double cushion = 1e-9 * (g->dist + bm->length + radius + margin);
	double slack = g->dist - bm->length * fabs(b->theta - g->theta) - radius - margin - cushion;
	if (extended && w->model->shaped)
		slack -= radius * fabs(w->heading - g->psi);
	return slack > 0.0 && ex * ex + ey * ey < slack * slack; /* false for NaN */
}

/* Beam i's contact from its geometry g, for a body of reach R (the disk's
 * radius) within margin, into out: gap, normal, lever, restitution, no
 * impulse yet (the disk's fields; the extended path's are contact_detect's).
 * 1, or 0 if g has none within margin. */
THESIS_SPECIALISED int contact_from_geometry(const thesis_geometry *g, int i, double radius,
                                             double margin, double e_tip, double e_tangent,
                                             thesis_contact *out)
{
	if (g->type == BSIM_CONTACT_NONE)
		return 0;
	out->gap = g->dist - radius;
	if (out->gap > margin)
		return 0;
	out->beam = i;
	out->type = g->type;
	out->n[0] = g->n[0];
	out->n[1] = g->n[1];
	out->c = g->c;
	out->e = g->type == BSIM_CONTACT_TIP ? e_tip : e_tangent;
	out->impulse = 0.0;
	return 1;
}

/* |C - P|^2, m^2: the body's centre from beam b's pivot. */
static inline double beam_pivot_distance2(const struct bsim_world *w, const thesis_beam_model *bm)
{
	double dx = w->x[0] - bm->p[0], dy = w->x[1] - bm->p[1];
	return dx * dx + dy * dy;
}

/* 1 if the body's centre, at d2 = |C - P|^2 from beam b's pivot
 * (beam_pivot_distance2), lies outside the beam's disc of radius L + R +
 * margin about the pivot, where no point of the beam, at any angle, comes
 * within R + margin: no trigonometry needed. */
static inline int beam_beyond(const thesis_beam_model *bm, double d2, double margin)
{
	double reach = bm->reach + margin; /* L + R + margin */
	return d2 > reach * reach;
}

/* beam_beyond for the body where it is. */
static inline int beam_beyond_reach(const struct bsim_world *w, const thesis_beam_model *bm,
                                    double margin)
{
	return beam_beyond(bm, beam_pivot_distance2(w, bm), margin);
}

/* 1 if beam b's geometry is the body's at its angle now (and, for a shaped
 * body on the extended path, at its heading): the same configuration gives
 * the same bits, so a step's detection meets the geometry the last step's
 * projection computed. extended: a constant, as in contact_detect. */
static inline int geometry_fresh(const struct bsim_world *w, const thesis_beam *b,
                                 const int extended)
{
	const thesis_geometry *g = &b->geo;
	return g->x[0] == w->x[0] && g->x[1] == w->x[1] && g->theta == b->theta &&
	       (!extended || !w->model->shaped || g->psi == w->heading);
}

/* The essay's disk (w->model->extended 0) against beam i: its contact within
 * margin into out, 1, or 0; the geometry kept in the beam. contact_detect's
 * path for the disk, apart from the extended path's, whose tests it has
 * none of. near (a constant): beam i is one the step found in contact
 * (the projection's re-detection), which geometry_far seldom rejects;
 * that test only saves the exact one, so it is not asked there (the same
 * result). d2: the body's |C - P|^2 from the beam's pivot where it is
 * (beam_pivot_distance2), which a caller may hold from before. touched (a
 * constant): every beam is touched already (thesis_beam_touch; a run of
 * steps touches them all first). */
THESIS_SPECIALISED int disk_detect_at(struct bsim_world *w, int i, double d2, double margin,
                                      thesis_contact *out, const int near, const int touched)
{
	const thesis_beam_model *bm = &w->model->beams[i];
	thesis_beam *b = &w->beams[i]; /* its geometry kept */
	if (beam_beyond(bm, d2, margin))
		return 0;
	const thesis_geometry *g = &b->geo;
	if (!geometry_fresh(w, b, 0)) {
		if (!near && geometry_far(w, bm, b, w->x, w->model->radius, margin, 0))
			return 0;
		if (!touched)
			thesis_beam_touch(w, i);
		geometry_compute(bm, b, w->x, 0);
	}
	return contact_from_geometry(g, i, w->model->radius, margin, w->model->e_tip,
	                             w->model->e_tangent, out);
}

/* disk_detect_at for the body where it is. */
THESIS_SPECIALISED int disk_detect(struct bsim_world *w, int i, double margin, thesis_contact *out,
                                   const int near, const int touched)
{
	return disk_detect_at(w, i, beam_pivot_distance2(w, &w->model->beams[i]), margin, out, near,
	                      touched);
}

/* Detection for any body (extended 1: the world's flags decide) or for the
 * essay's disk (extended 0, w->model->extended 0): a constant, so that the disk's
 * copy is compiled without the extended path's tests and stores. */
THESIS_SPECIALISED int contact_detect(struct bsim_world *w, int i, double margin,
                                      thesis_contact *out, const int extended)
{
	if (!extended)
		return disk_detect(w, i, margin, out, 0, 0);
	const thesis_beam_model *bm = &w->model->beams[i];
	thesis_beam *b = &w->beams[i]; /* its geometry kept */
	if (beam_beyond_reach(w, bm, margin))
		return 0;
	const thesis_geometry *g = &b->geo;
	if (!geometry_fresh(w, b, 1)) {
		if (geometry_far(w, bm, b, w->x, w->model->radius, margin, 1))
			return 0;
		thesis_beam_touch(w, i);
		if (w->model->shaped) {
			double u[2];
			thesis_beam_direction(bm, b, u);
			bsim_thesis_shape_geometry(w, bm, b, u);
		} else {
			geometry_compute(bm, b, w->x, 1);
		}
	}
	if (!contact_from_geometry(g, i, w->model->radius, margin, w->model->e_tip,
	                           w->model->e_tangent, out))
		return 0;
	out->two = 0; /* read by the extended path's solves only */
	if (w->model->extended) {
		out->mu = w->model->friction;
		out->impulse_t = 0.0;
		if (w->model->shaped) {
			out->cb = g->cb;
			out->cbt = g->cbt;
			out->ct = g->ct;
		} else {
			out->cb = 0.0;
			out->cbt = -w->model->radius;
			out->ct = bm->sgn * (g->a[0] * g->n[0] + g->a[1] * g->n[1]);
		}
	}
	if (w->model->shaped && g->has2)
		return 1 + bsim_thesis_shape_second(w, g, margin, out);
	return 1;
}

/* 0 if the body certainly lies farther than R + margin from beam i
 * (beyond its reach, or far by the bound), 1 if it may not: the contact
 * flag's test before it measures the distance. d2: as disk_detect_at's;
 * extended: a constant, as in contact_detect. */
THESIS_SPECIALISED int contact_near_at(const struct bsim_world *w, int i, double d2, double margin,
                                       const int extended)
{
	const thesis_beam_model *bm = &w->model->beams[i];
	if (beam_beyond(bm, d2, margin))
		return 0;
	return !geometry_far(w, bm, &w->beams[i], w->x, w->model->radius, margin, extended);
}

/* contact_near_at for the body where it is. */
THESIS_SPECIALISED int contact_near(const struct bsim_world *w, int i, double margin,
                                    const int extended)
{
	return contact_near_at(w, i, beam_pivot_distance2(w, &w->model->beams[i]), margin,
	                       extended);
}

#endif
