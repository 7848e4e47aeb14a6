/* What the runner defines and the chipmunk backend reports (beamsim/state.h):
 * the energy flows of each substep, and at a step's end the contact flag and
 * the pivot drift. Kept here, apart from the world, in one function
 * (bsim_chipmunk_measure) and its helpers.
 *
 * Energy. A Chipmunk substep of h first moves every body with the velocity
 * it ends the last substep with (plus the position correction's bias
 * velocity), then finds the contacts and changes velocities only: the
 * force's impulse h F, the spring's explicit impulse j_s = -k a h (a the
 * beam's Chipmunk angle after the move), the damper's and the contacts' and
 * pins' impulses, warm start and iterations alike. A change of velocity
 * v- -> v+ by impulses P_r on rows r (P_r = J_r^T applied, M v+ = M v- +
 * sum_r J_r^T P_r) changes the kinetic energy by exactly
 *   dK = (v+ - v-) . M (v+ + v-) / 2 = sum_r P_r (J_r v- + J_r v+) / 2,
 * whatever order the solver applied them in, so each row's share of the
 * substep's change is P_r times its mean velocity:
 *   damper:  the spring constraint's angular impulse on the beam is
 *            j_s - (jAcc - j_s) (jAcc its accumulated impulse,
 *            cpConstraintGetImpulse: j_s plus the damper's); the damper's
 *            -(jAcc - j_s), so it dissipates (jAcc - j_s)(w- + w+)/2;
 *   contact: the arbiter's impulse P on the body (cpArbiterTotalImpulse)
 *            and its angular impulse on the beam about the pivot,
 *            C = I (w+ - w-) - (2 j_s - jAcc) (the pin acts at the pivot,
 *            the beam's centre, and adds none), do
 *              P . (v- + v+)/2 + C (w- + w+)/2
 *            plus, on a body that turns, A (om- + om+)/2 with its angular
 *            impulse A = -C + (Q - X) x P + d x P about its centre X (Q the
 *            pivot, d the mean offset K_j - Q_j of the points on the body
 *            from those on the beam: exact for one point, and for two
 *            points without friction); minus that work is the impact's
 *            loss if the contact approached faster than rest_threshold at
 *            the substep's start, else the contact's;
 *   the pins and the beams' translation: not in the ledger's energy (a
 *            pinned beam's is its rotation), and their shares cancel.
 * The force's share h F . (v- + v+)/2 against the runner's F . dx =
 * h F . v- (the body moved with v-), and the spring's j_s (w- + w+)/2
 * against the springs' energy change, are the integrator's own errors:
 * the ledger's residual, O(h) per unit time (substeps shrink it).
 * Correction: the contact solve's bias velocities move bodies in the next
 * substep without changing their velocities: the body by dx = x+ - x- -
 * h v- beyond its velocity, a beam by da = a+ - a- - h w-. The runner
 * credits the force with F . dx and sees the springs' energy change by
 * k ((a+)^2 - (a- + h w-)^2) / 2; their difference is booked as the
 * correction (F . dx + T dpsi minus that change), as the thesis backend
 * books its projection.
 *
 * The contact flag is the one every backend reports (beamsim/contact_flag.h):
 * from the reported state (x, theta) by the shared geometry, the outline's
 * gap (beamsim/body_shape.h) for a body that is not a disk, or a nonzero
 * normal impulse in any substep of the step. */
#include <math.h>

#include "chipmunk/chipmunk_world.h"
#include "beamsim/body_shape.h"
#include "beamsim/contact_flag.h"

/* The energy flows of the substep of h just taken, into w->energy. */
static void measure_energy(struct bsim_world *w, double h)
{
	const cpVect x1 = cpBodyGetPosition(w->body), v1 = cpBodyGetVelocity(w->body);
	const double w1 = cpBodyGetAngularVelocity(w->body);
	const double rest = w->scene.contact.rest_threshold;
	const cpVect vsum = cpvadd(w->v0, v1);
	for (int k = 0; k < w->n_live; k++) {
		chip_beam *b = &w->beams[w->live[k]];
		const double a1 = cpBodyGetAngle(b->body), bw1 = cpBodyGetAngularVelocity(b->body);
		/* Chipmunk's spring impulse, as its preStep computes it (the
		 * static body's angle is 0, the rest angle 0) */
		const double j_s = (0.0 - a1) * b->stiffness * h;
		const double j_acc = cpConstraintGetImpulse(b->spring);
		w->energy.damper += (j_acc - j_s) * 0.5 * (b->w0 + bw1);
		const double a_free = b->a0 + h * b->w0;
		w->energy.correction -= 0.5 * b->stiffness * (a1 * a1 - a_free * a_free);
		if (!b->touched)
			continue;
		b->touched = 0;
		const double c = b->inertia * (bw1 - b->w0) - (2.0 * j_s - j_acc);
		double work = 0.5 * cpvdot(b->impulse, vsum) + 0.5 * c * (b->w0 + bw1);
		if (w->rotates) {
			const cpVect q = cpBodyGetPosition(b->body);
			const double a = -c + cpvcross(cpvsub(q, x1), b->impulse) +
			                 cpvcross(b->offset, b->impulse);
			work += 0.5 * a * (w->w0 + w1);
		}
		if (b->approach > rest) {
			w->energy.impact -= work;
			w->impacts += b->normal_impulse > 0.0;
		} else {
			w->energy.contact -= work;
		}
		if (b->normal_impulse > 0.0) {
			b->impulse_step =
			        b->pushed ? b->impulse_step + b->normal_impulse : b->normal_impulse;
			if (!b->pushed) {
				b->pushed = 1;
				w->pushed[w->n_pushed++] = w->live[k];
			}
		}
	}
	const cpVect dx = cpvsub(cpvsub(x1, w->x0), cpvmult(w->v0, h));
	w->energy.correction += w->force[0] * dx.x + w->force[1] * dx.y;
	if (w->rotates)
		w->energy.correction += w->torque * (cpBodyGetAngle(w->body) - w->psi0 - h * w->w0);
}

/* The body's heading as the state reports it, rad. */
static double body_heading(const struct bsim_world *w)
{
	return w->rotates ? cpBodyGetAngle(w->body) : bsim_body_heading(&w->scene.body);
}

/* Whether beam i is to be listed at the step's end: the contact flag
 * (beamsim/contact_flag.h) of the state get_state reports, which the
 * runner then computes from that state; a beam it flags must be listed. */
static int flag_of(const struct bsim_world *w, int i, const double x[2], double psi)
{
	const chip_beam *b = &w->beams[i];
	double u[2];
	bsim_beam_direction(b->u0, b->sgn, b->sgn * cpBodyGetAngle(b->body), u);
	return bsim_contact_flag_of(&w->scene.body, x, psi, b->pivot, u, b->length, b->pushed);
}

/* Beam i flagged: listed, and live. */
static void flag_set(struct bsim_world *w, int i, int flag)
{
	w->contact_type[i] = flag;
	w->typed[w->n_typed++] = i;
	chipmunk_mark_live(w, i);
}

typedef struct flag_query {
	struct bsim_world *w;
	double x[2], psi;
} flag_query;

static void flag_found(cpShape *shape, void *data)
{
	flag_query *q = data;
	const int i = chip_beam_of(shape);
	if (i < 0 || q->w->contact_type[i] != BSIM_CONTACT_NONE)
		return;
	const int flag = flag_of(q->w, i, q->x, q->psi);
	if (flag != BSIM_CONTACT_NONE)
		flag_set(q->w, i, flag);
}

/* The contact flag of every beam at the step's end; the step's pushes are
 * then spent. In a lattice only the beams whose bounding box meets the
 * body's, grown by the tolerance, and the pushed ones can be flagged. */
static void measure_flags(struct bsim_world *w)
{
	const cpVect c = cpBodyGetPosition(w->body);
	flag_query q = {w, {c.x, c.y}, body_heading(w)};
	for (int k = 0; k < w->n_typed; k++)
		w->contact_type[w->typed[k]] = BSIM_CONTACT_NONE;
	w->n_typed = 0;
	if (w->track_live) {
		cpBB bb = cpShapeGetBB(w->body_shape);
		bb = cpBBNew(bb.l - BSIM_CONTACT_TOL, bb.b - BSIM_CONTACT_TOL,
		             bb.r + BSIM_CONTACT_TOL, bb.t + BSIM_CONTACT_TOL);
		cpSpaceBBQuery(w->space, bb, cpShapeGetFilter(w->body_shape), flag_found, &q);
		for (int k = 0; k < w->n_pushed; k++)
			if (w->contact_type[w->pushed[k]] == BSIM_CONTACT_NONE)
				flag_set(w, w->pushed[k], flag_of(w, w->pushed[k], q.x, q.psi));
	} else {
		for (int i = 0; i < w->n_beams; i++) {
			const chip_beam *b = &w->beams[i];
			const double dx = c.x - b->pivot[0], dy = c.y - b->pivot[1];
			const double reach = b->length + w->reach + 1.0; /* m, generous */
			if (dx * dx + dy * dy > reach * reach && !b->pushed)
				continue;
			const int flag = flag_of(w, i, q.x, q.psi);
			if (flag != BSIM_CONTACT_NONE)
				flag_set(w, i, flag);
		}
	}
	/* The pushes spent: the state reports them as touched until the next
	 * step's. */
	for (int k = 0; k < w->n_reported; k++) {
		w->beams[w->reported[k]].reported = 0;
		w->beams[w->reported[k]].impulse_reported = 0.0;
	}
	w->n_reported = 0;
	for (int k = 0; k < w->n_pushed; k++) {
		chip_beam *b = &w->beams[w->pushed[k]];
		b->pushed = 0;
		b->reported = 1;
		b->impulse_reported = b->impulse_step;
		w->reported[w->n_reported++] = w->pushed[k];
	}
	w->n_pushed = 0;
}

void bsim_chipmunk_measure(struct bsim_world *w, double h, int last)
{
	if (h > 0.0)
		measure_energy(w, h);
	if (!last)
		return;
	measure_flags(w);
}
