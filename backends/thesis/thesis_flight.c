/* The thesis backend's free-flight runs (a path of its advance,
 * thesis_world.c): the steps thesis_step makes by its flight path
 * (thesis_world.c's flight_step), one after another in one call, for as
 * long as that path would be taken, each state written as get_state
 * writes it after such a step.
 *
 * thesis_step takes the flight path when no beam is awake (nor in contact), the
 * room test finds every beam out of reach (thesis_flight_clear), the beams
 * are prepared for h and contact_mode is physical (a run prepares them for
 * h first, as the step would before a flight step otherwise: the flight
 * reads none of their constants). A flight step changes
 * none of these but the body's position and velocity, so all but the room
 * test hold for the whole run and are asked once; the room test is asked
 * before every step, as thesis_step asks it: its inline part here on the
 * body held in locals (the same operations, with the step's own force),
 * and where that fails bsim_thesis_broad_phase_clear,
 * which asks it again and then tests the beams, as thesis_flight_clear
 * does. (A world that the room test cannot serve, broad_phase=0 or more
 * than THESIS_BROAD_PHASE_MIN_BEAMS beams, is never clear: no run.)
 *
 * Each step then moves the body as thesis_body_advance does with a zero
 * impulse sum (v = vf + 0 / M, which turns a -0 into +0, is kept), and
 * clears what flight_step clears (the energy flows, the impacts, the
 * contacts), which after the first step stay cleared: cleared once,
 * after the run. Its state is get_state's with no beam awake: the body,
 * no beam listed, zero energy flows and impacts. A body that turns is left
 * to thesis_step (its heading moves too). */
#include <string.h>

#include "thesis/thesis.h"

int bsim_thesis_flight(bsim_world *w, const bsim_wrench *schedule, double h, int n, bsim_state *out)
{
	if (w->n_awake || w->model->contact_mode == THESIS_CONTACT_ESSAY || w->model->rotates ||
	    !w->model->broad_phase || w->model->n_beams > THESIS_BROAD_PHASE_MIN_BEAMS)
		return 0;
	/* The beams' constants for h, as the step would prepare them before
	 * its flight (a step in flight reads none of them). */
	thesis_beams_prepare(w, h);
	const double inv_mass = w->model->inv_mass, zero = 0.0 * inv_mass;
	/* The largest |F|_1 of the run's steps (a force not finite makes it
	 * NaN: then no step is sure), for a bound on each step's thesis_clear_margin force term h
	 * |F|_1 / M and on its |h F / M|_1, which differs from that by the
	 * round-off of its products alone. */
	double f_max = 0.0, nan = 0.0;
	for (int k = 0; k < n; k++) {
		const double f = fabs(schedule[k].force[0]) + fabs(schedule[k].force[1]);
		f_max = f > f_max ? f : f_max;
		nan += f - f; /* 0, or NaN for a force not finite */
	}
	const double push_max = h * (f_max + nan) * inv_mass * (1.0 + 1e-12), d_max = push_max;
	const double slop = w->model->slop;
	const int euler = w->model->integrator == THESIS_EULER;
	double cx0 = w->clear_x[0], cx1 = w->clear_x[1], room = w->clear_room;
	double x0 = w->x[0], x1 = w->x[1], v0 = w->v[0], v1 = w->v[1];
	/* what a flight step leaves as it is, for the states */
	const double heading = w->heading, angular_velocity = w->angular_velocity;
	const bsim_solver_counts solver = w->solver;
	/* The room test of every step of the run at once. Step k starts at
	 * speed |v_k|_1 <= s + k d (s = |v|_1 now, d the largest |h F / M|_1
	 * of a step) and |x_k - C_c|_1 <= |x - C_c|_1 + h k (s + k d) (each
	 * step moves by h times a speed of at most that), so the test's left
	 * side is at most its value for those bounds at k = n - 1 with the
	 * largest force term; a cushion of 1e-9 of the lengths involved covers
	 * the round-off of the steps and of the test (1e-16 of the same
	 * lengths a step). If that passes, every step's test would: the same
	 * steps. */
	const double s = fabs(v0) + fabs(v1), d = d_max, kn = (double)(n - 1);
	const double reach = fabs(x0 - cx0) + fabs(x1 - cx1) + h * kn * (s + kn * d) +
	                     2.0 * (h * ((s + kn * d + push_max) * (1.0 + 1e-12))) + slop +
	                     BSIM_CONTACT_TOL;
	const int sure =
	        reach + 1e-9 * (reach + fabs(x0) + fabs(x1) + fabs(cx0) + fabs(cx1)) < room;
	int k = 0;
	for (; k < n; k++) {
		const double *force = schedule[k].force;
		const double dv0 = h * force[0] * inv_mass, dv1 = h * force[1] * inv_mass;
		if (!sure) {
			const double push = h * (fabs(force[0]) + fabs(force[1])) * inv_mass;
			double speed = (fabs(v0) + fabs(v1)) + push;
			double margin =
			        2.0 * (h * (speed * (1.0 + 1e-12))) + slop + BSIM_CONTACT_TOL;
			if (!(fabs(x0 - cx0) + fabs(x1 - cx1) + margin < room)) {
				w->x[0] = x0;
				w->x[1] = x1;
				w->v[0] = v0;
				w->v[1] = v1;
				if (!bsim_thesis_broad_phase_clear(w, force, h))
					break;
				cx0 = w->clear_x[0];
				cx1 = w->clear_x[1];
				room = w->clear_room;
			}
		}
		/* thesis_body_advance(w, v, v + h F / M, 0, h, vm) */
		double vf0 = v0 + dv0, vf1 = v1 + dv1;
		double u0 = vf0 + zero, u1 = vf1 + zero;
		double vm0 = 0.5 * (v0 + u0), vm1 = 0.5 * (v1 + u1);
		if (euler) {
			vm0 = u0;
			vm1 = u1;
		}
		x0 += h * vm0;
		x1 += h * vm1;
		v0 = u0;
		v1 = u1;
		bsim_state *st = &out[k];
		st->x[0] = x0;
		st->x[1] = x1;
		st->v[0] = v0;
		st->v[1] = v1;
		st->heading = heading;
		st->angular_velocity = angular_velocity;
		if (st->n_active)
			bsim_state_set_active(st, NULL, 0);
		memset(&st->energy, 0, sizeof st->energy);
		st->impacts = 0;
		st->solver = solver;
	}
	w->x[0] = x0;
	w->x[1] = x1;
	w->v[0] = v0;
	w->v[1] = v1;
	if (k) {
		memset(&w->energy, 0, sizeof w->energy);
		w->impacts = 0;
		w->n_contacts = 0;
	}
	return k;
}
