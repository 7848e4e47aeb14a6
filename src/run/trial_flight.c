/* Free-flight runs (trial_flight.h): a backend's bsim_backend.flight steps,
 * booked as trial.c's step loop books each step.
 *
 * A stretch of flight is a sequence of runs, one per value of the force:
 * the force of step n (drawn there if a hold starts there, as the step
 * loop draws it), then the backend's run of the steps it holds for, then
 * their booking; on to the next run while the trial goes on and the
 * backend made every step asked.
 *
 * Why the bits are the same. The force: the step loop asks the pipeline
 * for it before each step; propulsion along y gives its constant, the held
 * random force its held value until the step its hold ends, and neither
 * reads the state, so the force asked before a run, which ends before
 * that step, is the force of every step of it (and asking it again there,
 * after a run that was not made, gives the same: the held value is drawn
 * once). The state after a step: the backend's (xv), with no beam active,
 * no impact and zero energy flows (bsim_backend.flight). Each step books,
 * as the step loop does with that state:
 *   - the energy and finiteness test (state_energy_finite): no active beam
 *     adds nothing, the spring sum stays 0.0 and is added;
 *   - the ledger (ledger_step): the work of each force over d as the loop
 *     sums it from 0.0, the 0.0 left out: 0.0 + w differs from w only for
 *     w = -0, which gives +0, and the sums of w start at +0 (so are never
 *     -0: rounding to nearest, x + y is -0 only for x = y = -0), as e1 - e0
 *     is never -0 (e1 = kin + 0.0 is not), so -0 and +0 give the same sums
 *     and residual. The backend's losses are all +0: subtracting them
 *     leaves any value as it is (x - (+0) = x, -0 included), and adding
 *     them to their lines, which start at +0 and so are never -0, too: both
 *     left out. The largest |r| as bsim_fmax keeps it (flight_book);
 *   - the peaks (trial_peaks_step) with the beams as they are, at rest,
 *     once per stretch: the same beams again give the same peaks;
 *   - the outcome and the end of the trial by the loop's tests (trial_over,
 *     outcome_at), in their order.
 * A run the trial does not use to its end (the trial ends in it) leaves
 * the world ahead of the trial; the runner steps it no further (a kept
 * world is reset). */
#include "run/trial_flight.h"

#include <math.h>
#include <string.h>

int trial_force_holds(const bsim_scene *scene, bsim_effects *fx, bsim_effect **propulsion,
                      bsim_effect **random)
{
	int holds = !scene->has_lattice && !scene->body.rotates && !scene->effects.has_drag &&
	            !scene->effects.has_ground_friction && fx->n_work == fx->n;
	/* the pipeline: the propulsion along y, then the held random force,
	 * either or both */
	*propulsion = *random = NULL;
	for (int i = 0; i < fx->n && holds; i++) {
		bsim_effect *e = &fx->e[i];
		if (e->kind == BSIM_EFFECT_CONSTANT && !*propulsion && !*random)
			*propulsion = e;
		else if (e->kind == BSIM_EFFECT_HELD && e == fx->random && !*random)
			*random = e;
		else
			holds = 0;
	}
	return holds;
}

void trial_flight_start(trial_flight *f, int plain, const bsim_backend *backend, bsim_world *w,
                        const bsim_scene *scene, bsim_effects *fx, bsim_trial_result *out,
                        trial_peaks *peaks, long n_max, long gate_max, double centre)
{
	f->on = trial_force_holds(scene, fx, &f->propulsion, &f->random) && plain &&
	        backend->flight;
	f->skip = f->wait = 0;
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

/* bsim_effects_force_at for the runs' pipelines (trial_flight_start):
 * the propulsion, then the random force, held or drawn by its apply. */
static inline void flight_force(trial_flight *f, long n, double h, const bsim_state *s0,
                                double force[BSIM_WRENCH])
{
	bsim_effect *ep = f->propulsion, *er = f->random;
	force[0] = 0.0;
	force[1] = 0.0;
	force[2] = 0.0;
	if (ep) {
		force[ep->axis] += ep->param;
		ep->last = ep->param;
	}
	if (er) {
		if (n >= er->held[0] && n < er->held[1] && h == er->held_h)
			force[er->axis] += er->last;
		else
			er->apply(er, n, h, s0, force);
	}
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
	const double w_prop = has_p ? cp * (ap ? d1 : d0) : 0.0;
	const double w_rand = has_r ? cr * (ar ? d1 : d0) : 0.0;
	double r = (e1 - b->e0) - (w_prop + w_rand);
	b->w_prop += w_prop;
	b->w_rand += w_rand;
	b->residual += r;
	b->residual_abs += fabs(r);
	/* bsim_fmax(residual_max, |r|): |r| is never -0 and residual_max,
	 * which starts at +0 and only ever takes a value of |r|, neither -0
	 * nor NaN, so it is the larger of the two, |r| NaN ignored */
	const double r_abs = fabs(r);
	b->residual_max = r_abs > b->residual_max ? r_abs : b->residual_max;
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
	flight_books books = *b; /* in registers */
	int k = 0;
	for (; k < m; k++) {
		if (!flight_book(&books, f->xv[k], half_mass, has_p, cp, ap, has_r, cr, ar)) {
			*end = -1;
			break;
		}
		/* outcome_at */
		if (fabs(books.x0 - centre) >= side_x) {
			*end = 1;
			k++;
			break;
		}
		if (books.x1 >= success_y) {
			*traversed = 1;
			k++;
			break;
		}
	}
	*b = books;
	return k;
}

/* The steps of a run from step k of xv (m in all) after the outcome is
 * known, on to classify_y: booked until one is not finite (*end) or the
 * trial is over (trial_over). Returns the steps kept, k included. */
static int flight_done(trial_flight *f, flight_books *b, trial_loop *lp, long *dwell, int k, int m,
                       double half_mass, int has_p, double cp, int ap, int has_r, double cr, int ar,
                       int *end)
{
	const double classify_y = f->scene->classify_y;
	flight_books books = *b;
	while (k < m) {
		if (!flight_book(&books, f->xv[k], half_mass, has_p, cp, ap, has_r, cr, ar)) {
			*end = -1;
			break;
		}
		k++;
		lp->n++;
		(*dwell)++;
		lp->run_on++;
		if (books.x1 >= classify_y || lp->run_on >= f->n_max)
			break;
	}
	*b = books;
	return k;
}

int trial_flight_run(trial_flight *f, trial_loop *lp, long *dwell, bsim_state *s0)
{
	const double h = lp->h;
	const bsim_scene *sc = f->scene;
	bsim_trial_result *out = f->out;
	bsim_ledger *l = &out->ledger;
	const double half_mass = 0.5 * sc->body.mass;
	/* The work of each force over d: the propulsion's (along ap), the
	 * random force's (along ar), if there is one. */
	const bsim_effect *ep = f->propulsion, *er = f->random;
	const int has_p = ep != NULL, has_r = er != NULL;
	const int ap = ep ? ep->axis : 0, ar = er ? er->axis : 0;
	const int essay = has_p && has_r && ap == 1 && ar == 0;
	flight_books b = {lp->e0,      s0->x[0],        s0->x[1],        l->w_prop, l->w_rand,
	                  l->residual, l->residual_abs, l->residual_max, l->inflow};
	double last[4]; /* the body after the last step kept */
	long kept = 0;
	int end = 0, peaked = 0;
	for (;;) {
		/* A run: the force of step n, and the steps it holds for, to the
		 * end of the trial at most. */
		double force[BSIM_WRENCH];
		flight_force(f, lp->n, h, s0, force);
		const long room =
		        trial_run_room(lp, *dwell, f->n_max, f->gate_max, er, TRIAL_FLIGHT_MAX);
		const int m = room < 1 ? 0 : f->flight(f->w, force, h, (int)room, f->xv);
		if (m == 0)
			break;
		const double cp = ep ? ep->last : 0.0, cr = er ? er->last : 0.0;
		int k = 0, traversed = 0; /* k: the steps the trial keeps */
		if (!lp->done) {
			if (essay)
				k = flight_open(f, &b, m, half_mass, 1, cp, 1, 1, cr, 0, &end,
				                &traversed);
			else
				k = flight_open(f, &b, m, half_mass, has_p, cp, ap, has_r, cr, ar,
				                &end, &traversed);
			/* The step loop updates the peaks after each step kept,
			 * before the outcome. The beams of the runs' steps are at
			 * rest, s0's: their peaks again are the same peaks, so
			 * once is all. */
			if (k > 0 && !peaked) {
				trial_peaks_step(f->peaks, sc, NULL, s0);
				peaked = 1;
			}
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
		/* The outcome known: on to classify_y (trial_over after each
		 * step, the step that crossed success_y included). */
		if (lp->done && !end &&
		    !(traversed && (b.x1 >= sc->classify_y || lp->run_on >= f->n_max)))
			k = flight_done(f, &b, lp, dwell, k, m, half_mass, has_p, cp, ap, has_r, cr,
			                ar, &end);
		if (k) {
			memcpy(last, f->xv[k - 1], sizeof last);
			kept += k;
		}
		/* The trial over (trial_over), or the backend stopped short (a
		 * beam may be in reach): the step loop's turn. */
		if (end || k < m || m < room ||
		    (lp->done ? b.x1 >= sc->classify_y || lp->run_on >= f->n_max
		              : lp->n >= f->n_max || *dwell >= f->gate_max))
			break;
	}
	if (end == -1) {
		/* s0 stays the last finite state, the one reported */
		out->instability = BSIM_UNSTABLE_NONFINITE;
		out->unstable_step = (int)(lp->n + 1);
	}
	if (kept) {
		s0->x[0] = last[0];
		s0->x[1] = last[1];
		s0->v[0] = last[2];
		s0->v[1] = last[3];
		memset(&s0->energy, 0, sizeof s0->energy);
		s0->impacts = 0;
	}
	l->w_prop = b.w_prop;
	l->w_rand = b.w_rand;
	l->residual = b.residual;
	l->residual_abs = b.residual_abs;
	l->residual_max = b.residual_max;
	l->inflow = b.inflow;
	lp->e0 = b.e0;
	return end ? 1 : kept ? 0 : -1;
}
