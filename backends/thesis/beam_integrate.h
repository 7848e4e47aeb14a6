/* Beam integration: I beta = tau_contact - k theta - d omega (essay Eq. 2.2).
 *
 * midpoint (default): the trapezoidal rule on (theta, omega),
 *   omega' = omega + h/I (tau - k theta_m - d omega_m),
 *   theta' = theta + h omega_m,   theta_m = (theta + theta')/2, omega_m alike,
 * solved in closed form: with D = 1 + h d / (2I) + h^2 k / (4I),
 *   omega' = (omega (2 - D) - h k theta / I + h tau / I) / D.
 * It is A-stable (any k, any h), conserves 1/2 I omega^2 + 1/2 k theta^2
 * exactly when d = 0 and tau = 0, and dissipates exactly h d omega_m^2 in
 * the damper, so the energy ledger closes to round-off. A contact impulse P
 * changes omega' by -P c / (I D): the spring and damper stiffen the beam
 * against a force spread over the step.
 *
 * euler: semi-implicit Euler, omega' = omega + h/I (tau - k theta - d omega),
 * theta' = theta + h omega'; the essay-style explicit update, stable only
 * for h omega_n < 2, kept for accuracy studies. */
#ifndef BSIM_THESIS_BEAM_INTEGRATE_H
#define BSIM_THESIS_BEAM_INTEGRATE_H

/* Inline: a step calls these for every awake beam, and the calls cost as
 * much as the arithmetic. Included by thesis.h. */

static inline double thesis_beam_midpoint_d(const thesis_beam_model *bm, double h)
{
	return 1.0 + h * bm->damping / (2.0 * bm->inertia) +
	       h * h * bm->stiffness / (4.0 * bm->inertia);
}

/* D and 1/(I D) for steps of h, computed once: a step reads them for every
 * beam in contact, the same bits as computing them there. */
static inline void thesis_beam_prepare(const thesis_beam_model *bm, thesis_beam *b, double h)
{
	b->d = thesis_beam_midpoint_d(bm, h);
	b->response = 1.0 / (bm->inertia * b->d);
}

/* The two below are asked within a step only, after every beam was
 * prepared for its h (thesis_beams_prepare, at the start of thesis_step
 * and of a run of steps): D and 1/(I D) are read as prepared. */
static inline double thesis_beam_response(const thesis_beam_model *bm, const thesis_beam *b,
                                          int integrator)
{
	if (integrator == THESIS_EULER)
		return 1.0 / bm->inertia;
	return b->response;
}

static inline double thesis_beam_free_omega(const thesis_beam_model *bm, const thesis_beam *b,
                                            double h, int integrator)
{
	if (integrator == THESIS_EULER)
		return b->omega -
		       h * (bm->stiffness * b->theta + bm->damping * b->omega) / bm->inertia;
	const double d = b->d;
	return (b->omega * (2.0 - d) - h * bm->stiffness * b->theta / bm->inertia) / d;
}

/* Moves theta to the end of the step; returns the damper's loss, J. */
static inline double thesis_beam_advance(const thesis_beam_model *bm, thesis_beam *b,
                                         double omega_new, double h, int integrator)
{
	double omega_m = integrator == THESIS_EULER ? omega_new : 0.5 * (b->omega + omega_new);
	b->theta += h * omega_m;
	b->omega = omega_new;
	return h * bm->damping * omega_m * omega_m;
}

#endif
