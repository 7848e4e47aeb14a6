/* The collision handler of the body (collision type CHIP_TYPE_BODY) and the
 * beams (CHIP_TYPE_BEAM): the contact law of docs/model.md section 4 on Chipmunk's arbiters.
 *
 * preSolve runs once a substep for each pair whose shapes overlap, after
 * Chipmunk has moved the bodies and before its solve, so the velocities it
 * reads are those the solve starts from (before the substep's force). For
 * each contact point j, with the normal n from the body to the beam and the
 * relative velocity of the beam's point against the body's,
 *   v_j = (u_beam(Q_j) - v_body(K_j)) . n,     approach = max_j (-v_j);
 * Chipmunk's restitution is the arbiter's e (its own product of the shapes'
 * elasticities is overwritten: the shapes' are 0), its target
 * v_j' = -e v_j per point, so
 *   e = 0                   if approach <= contact.rest_threshold (persistent),
 *   e = tip_restitution     if every point Q_j lies at an end of the beam's
 *                           segment (its tip, or its pivot end),
 *   e = restitution         otherwise;
 * and the friction coefficient mu = contact.friction (Chipmunk would take the
 * product of the shapes'). A capsule or polygon lying across a beam's end can
 * hold two points, one at the end and one inside: Chipmunk has one e per
 * arbiter, so such a contact takes the tangent restitution (the thesis
 * backend gives each point its own).
 *
 * postSolve reads what the solve did: the arbiter's total impulse on the
 * body (friction included) and its normal part; bsim_chipmunk_measure turns them
 * into energy. */
#include <math.h>

#include "chipmunk/chipmunk_world.h"

/* 1e-9 of the beam's length: Chipmunk puts a contact at a segment's end
 * exactly at the end (its closest point clamped to t = 0 or 1). */
#define END_TOL 1e-9

/* Whether point q lies at an end of beam b's segment. */
static int at_end(const chip_beam *b, cpVect q)
{
	const cpVect p = cpBodyGetPosition(b->body), rot = cpBodyGetRotation(b->body);
	const cpVect u = cpvrotate(rot, cpv(b->u0[0], b->u0[1]));
	const double s = cpvdot(cpvsub(q, p), u) / b->length;
	return s <= END_TOL || s >= 1.0 - END_TOL;
}

static cpBool contact_pre_solve(cpArbiter *arb, cpSpace *space, cpDataPointer data)
{
	(void)space;
	struct bsim_world *w = data;
	CP_ARBITER_GET_SHAPES(arb, body_shape, beam_shape);
	(void)body_shape;
	const int i = chip_beam_of(beam_shape);
	chip_beam *b = &w->beams[i];
	chipmunk_mark_live(w, i);
	const cpContactPointSet set = cpArbiterGetContactPointSet(arb);
	double approach = -INFINITY;
	int ends = 0;
	for (int j = 0; j < set.count; j++) {
		const cpVect vk = cpBodyGetVelocityAtWorldPoint(w->body, set.points[j].pointA);
		const cpVect vq = cpBodyGetVelocityAtWorldPoint(b->body, set.points[j].pointB);
		approach = fmax(approach, -cpvdot(cpvsub(vq, vk), set.normal));
		ends += at_end(b, set.points[j].pointB);
	}
	const bsim_contact_def *law = &w->scene.contact;
	double e = 0.0;
	if (approach > law->rest_threshold)
		e = set.count > 0 && ends == set.count ? law->tip_restitution : law->restitution;
	cpArbiterSetRestitution(arb, e);
	cpArbiterSetFriction(arb, law->friction);
	b->touched = 1;
	b->approach = approach;
	/* the impulse Chipmunk's totals start from (below) */
	b->impulse_start = cpArbiterTotalImpulse(arb);
	b->first = cpArbiterIsFirstContact(arb);
	b->impulse = cpvzero;
	b->normal_impulse = 0.0;
	b->offset = cpvzero;
	return cpTrue;
}

static void contact_post_solve(cpArbiter *arb, cpSpace *space, cpDataPointer data)
{
	(void)space;
	struct bsim_world *w = data;
	CP_ARBITER_GET_SHAPES(arb, body_shape, beam_shape);
	(void)body_shape;
	chip_beam *b = &w->beams[chip_beam_of(beam_shape)];
	/* The impulse on the handler's first body, the body (pushed against
	 * the normal, body -> beam). Chipmunk's totals (cpArbiterTotalImpulse)
	 * start from the impulses of the pair's last contact: applied again at
	 * the start (warm start, times dt / dt_last) unless the pair had
	 * separated (a first contact), which keeps them in the total all the
	 * same. What the solve applied is the total less that start, plus the
	 * warm start. */
	const cpVect start = b->impulse_start;
	b->impulse = cpvadd(cpvsub(cpArbiterTotalImpulse(arb), start),
	                    b->first ? cpvzero : cpvmult(start, w->warm_coef));
	b->normal_impulse = fmax(0.0, -cpvdot(b->impulse, cpArbiterGetNormal(arb)));
	const cpContactPointSet set = cpArbiterGetContactPointSet(arb);
	b->offset = cpvzero;
	for (int j = 0; j < set.count; j++)
		b->offset = cpvadd(b->offset, cpvsub(set.points[j].pointA, set.points[j].pointB));
	if (set.count > 1)
		b->offset = cpvmult(b->offset, 1.0 / set.count);
}

void bsim_chipmunk_contact_install(struct bsim_world *w)
{
	cpCollisionHandler *h =
	        cpSpaceAddCollisionHandler(w->space, CHIP_TYPE_BODY, CHIP_TYPE_BEAM);
	h->preSolveFunc = contact_pre_solve;
	h->postSolveFunc = contact_post_solve;
	h->userData = w;
}
