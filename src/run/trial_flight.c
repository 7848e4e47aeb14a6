/* Free-flight runs (trial_flight.h): a backend's bsim_backend.flight steps,
 * booked as trial.c's step loop books each step.
 *
 * Why the bits are the same. The force: the step loop asks the pipeline
 * for it before each step; propulsion along y gives its constant, the held
 * random force its held value until the step its hold ends, and neither
 * reads the state, so the force asked once before the run, which ends
 * before that step, is the force of every step of it (and asking it again
 * there, after a run that was not made, gives the same: the held value is
 * drawn once). The state after a step: the backend's (xv), with no beam
 * active, no impact and zero energy flows (bsim_backend.flight). Then
 * each step books, as the step loop does with that state:
 *   - the energy and finiteness test (state_energy_finite): no active beam
 *     adds nothing, the spring sum stays 0.0 and is added;
 *   - the ledger (ledger_step): the work of each force over d as the
 *     loop sums it, from 0.0; the residual with the backend's losses, all
 *     +0, whose subtraction leaves any value as it is (x - (+0) = x, -0
 *     included) and so is left out; the losses' lines gain +0, which
 *     changes a -0 to +0 the first time and nothing after: added once per
 *     run;
 *   - the peaks (trial_peaks_step) with the beams as they are, at rest;
 *   - the outcome and the end of the run by the loop's tests (trial_over,
 *     outcome_at), in their order.
 * A run the trial does not use to its end (it ends in it) leaves the world
 * ahead of the trial; the runner steps it no further (a kept world is
 * reset). */
#include "run/trial_flight.h"

#include <math.h>
#include <string.h>

#include "run/trial_ledger.h"
#include "util/fminmax.h"

void trial_flight_start(trial_flight *f, int plain, const bsim_backend *backend, bsim_world *w,
                        const bsim_scene *scene, bsim_effects *fx, bsim_trial_result *out,
                        trial_peaks *peaks, long n_max, long gate_max, double centre)
{
	f->on = plain && backend->flight && !scene->has_lattice && !scene->body.rotates &&
	        fx->n_work == fx->n;
	int constant = 0, held = 0;
	for (int i = 0; i < fx->n && f->on; i++) {
		const bsim_effect *e = &fx->e[i];
		if (e->kind == BSIM_EFFECT_CONSTANT && !constant++)
			continue;
		if (e->kind == BSIM_EFFECT_HELD && e == fx->random && !held++)
			continue;
		f->on = 0;
	}
	f->flight = backend->flight;
	f->w = w;
	f->scene = scene;
	f->fx = fx;
	f->out = out;
	f->peaks = peaks;
	f->n_max = n_max;
	f->gate_max = gate_max;
	f->centre = centre;
}

/* What a run books, held in locals while it runs: the energy after the
 * last step kept, the body's position then, the ledger's sums. */
typedef struct flight_books {
	double e0, x0, x1;
	double w_prop, w_rand, residual, residual_abs, residual_max, inflow;
} flight_books;

/* The energy, finiteness test and ledger entry of the step to q (x, y, vx,
 * vy) from the books' state: 0 if q is not finite (nothing booked). The
 * work of the forces: propulsion cp along axis ap (has_p), random force
 * cr along ar (has_r); inline, so that a call with constants is the
 * essay's pipeline unrolled. */
static inline int flight_book(flight_books *b, const double *q, double half_mass, int has_p,
                              double cp, int ap, int has_r, double cr, int ar)
{
	/* state_energy_finite */
	double kin = half_mass * (q[2] * q[2] + q[3] * q[3]);
	double spring = 0.0;
	double sum = q[0] + q[1] + q[2] + q[3];
	double e1 = kin + spring;
	if (!(isfinite(sum) && isfinite(e1)))
		return 0;
	/* ledger_step */
	const double d0 = q[0] - b->x0, d1 = q[1] - b->x1;
	double w_prop = 0.0, w_rand = 0.0;
	if (has_p)
		w_prop += cp * (ap ? d1 : d0);
	if (has_r)
		w_rand += cr * (ar ? d1 : d0);
	double r = (e1 - b->e0) - (w_prop + w_rand);
	b->w_prop += w_prop;
	b->w_rand += w_rand;
	b->residual += r;
	b->residual_abs += fabs(r);
	b->residual_max = bsim_fmax(b->residual_max, fabs(r));
	b->inflow += fabs(w_prop) + fabs(w_rand);
	b->e0 = e1;
	b->x0 = q[0];
	b->x1 = q[1];
	return 1;
}

/* The steps of a run from step k of xv (m in all) before the outcome is
 * known: booked until one is not finite (*end), the body leaves by a side
 * (*end) or crosses success_y (the outcome known: the step after it is
 * returned). Returns the steps kept. */
static inline int flight_open(trial_flight *f, flight_books *b, int m, double half_mass, int has_p,
                              double cp, int ap, int has_r, double cr, int ar, int *end,
                              int *traversed)
{
	const double centre = f->centre, side_x = f->scene->side_x;
	const double success_y = f->scene->success_y;
	int k = 0;
	for (; k < m; k++) {
		if (!flight_book(b, f->xv[k], half_mass, has_p, cp, ap, has_r, cr, ar)) {
			*end = -1;
			return k;
		}
		/* outcome_at */
		if (fabs(b->x0 - centre) >= side_x) {
			*end = 1;
			return k + 1;
		}
		if (b->x1 >= success_y) {
			*traversed = 1;
			return k + 1;
		}
	}
	return k;
}

int trial_flight_run(trial_flight *f, trial_loop *lp, long *dwell, bsim_state *s0)
{
	bsim_effects *fx = f->fx;
	const double h = lp->h;
	double force[BSIM_WRENCH];
	bsim_effects_force_at(fx, lp->n, h, s0, force);
	/* The steps the run may take: to the end of the hold, of the trial. */
	long room = lp->done ? f->n_max - lp->run_on : f->n_max - lp->n;
	if (!lp->done && f->gate_max - *dwell < room)
		room = f->gate_max - *dwell;
	room = room < TRIAL_FLIGHT_MAX ? room : TRIAL_FLIGHT_MAX;
	/* The work of each force over d: the propulsion's (cp along ap), the
	 * random force's (cr along ar), if there is one. */
	int has_p = 0, has_r = 0, ap = 0, ar = 0;
	double cp = 0.0, cr = 0.0;
	for (int i = 0; i < fx->n; i++) {
		const bsim_effect *e = &fx->e[i];
		if (e->kind == BSIM_EFFECT_HELD) {
			if (!(lp->n >= e->held[0] && lp->n < e->held[1] && h == e->held_h))
				return -1; /* not held: the force is not one for a run */
			if (e->held[1] - lp->n < room)
				room = e->held[1] - lp->n;
			has_r = 1;
			ar = e->axis;
			cr = e->last;
		} else {
			has_p = 1;
			ap = e->axis;
			cp = e->last;
		}
	}
	if (room < 1)
		return -1;
	const int m = f->flight(f->w, force, h, (int)room, f->xv);
	if (m == 0)
		return -1;

	const bsim_scene *sc = f->scene;
	bsim_trial_result *out = f->out;
	bsim_ledger *l = &out->ledger;
	const double half_mass = 0.5 * sc->body.mass;
	flight_books b = {lp->e0,      s0->x[0],        s0->x[1],        l->w_prop, l->w_rand,
	                  l->residual, l->residual_abs, l->residual_max, l->inflow};
	int end = 0, k = 0; /* k: the steps the trial keeps */
	int traversed = 0;
	if (!lp->done) {
		if (has_p && has_r && ap == 1 && ar == 0) /* the essay's pipeline */
			k = flight_open(f, &b, m, half_mass, 1, cp, 1, 1, cr, 0, &end, &traversed);
		else
			k = flight_open(f, &b, m, half_mass, has_p, cp, ap, has_r, cr, ar, &end,
			                &traversed);
		/* The step loop updates the peaks after each step kept, before
		 * the outcome. The beams of a run's steps are at rest, s0's:
		 * their peaks again are the same peaks, so once is all. */
		if (k > 0)
			trial_peaks_step(f->peaks, sc, NULL, s0);
		lp->n += k;
		*dwell += k;
		if (end == 1)
			out->outcome = BSIM_SIDE_EXIT;
		if (traversed) {
			out->outcome = BSIM_TRAVERSED;
			out->steps = (int)lp->n;
			out->t_end = (double)lp->n * h;
			lp->done = 1;
		}
	}
	/* The outcome known: on to classify_y (trial_over after each step,
	 * the step that crossed success_y included). */
	if (lp->done && !end && !(traversed && (b.x1 >= sc->classify_y || lp->run_on >= f->n_max)))
		while (k < m) {
			if (!flight_book(&b, f->xv[k], half_mass, has_p, cp, ap, has_r, cr, ar)) {
				end = -1;
				break;
			}
			k++;
			lp->n++;
			(*dwell)++;
			lp->run_on++;
			if (b.x1 >= sc->classify_y || lp->run_on >= f->n_max)
				break;
		}
	if (end == -1) {
		/* s0 stays the last finite state, the one reported */
		out->instability = BSIM_UNSTABLE_NONFINITE;
		out->unstable_step = (int)(lp->n + 1);
	}
	if (k) {
		const double *q = f->xv[k - 1];
		s0->x[0] = q[0];
		s0->x[1] = q[1];
		s0->v[0] = q[2];
		s0->v[1] = q[3];
		memset(&s0->energy, 0, sizeof s0->energy);
		s0->impacts = 0;
		l->damper += 0.0;
		l->impact += 0.0;
		l->contact += 0.0;
		l->correction += 0.0;
		l->sleep += 0.0;
	}
	l->w_prop = b.w_prop;
	l->w_rand = b.w_rand;
	l->residual = b.residual;
	l->residual_abs = b.residual_abs;
	l->residual_max = b.residual_max;
	l->inflow = b.inflow;
	lp->e0 = b.e0;
	return end != 0;
}
