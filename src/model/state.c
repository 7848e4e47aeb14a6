/* The state buffers every backend fills (beamsim/state.h). */
#include "beamsim/state.h"

#include <stdlib.h>
#include <string.h>

int bsim_state_init(bsim_state *s, int n_beams)
{
	memset(s, 0, sizeof *s);
	s->n_beams = n_beams;
	size_t n = n_beams > 0 ? (size_t)n_beams : 1;
	s->theta = calloc(n, sizeof *s->theta);
	s->omega = calloc(n, sizeof *s->omega);
	s->contact = calloc(n, sizeof *s->contact);
	s->active = calloc(n, sizeof *s->active);
	s->touched = calloc(n, sizeof *s->touched);
	s->impulse = calloc(n, sizeof *s->impulse);
	s->direction = calloc(2 * n, sizeof *s->direction);
	s->pin = calloc(2 * n, sizeof *s->pin);
	if (!s->theta || !s->omega || !s->contact || !s->active || !s->touched || !s->impulse ||
	    !s->direction || !s->pin) {
		bsim_state_free(s);
		return BSIM_EFAIL;
	}
	return BSIM_OK;
}

void bsim_state_free(bsim_state *s)
{
	free(s->theta);
	free(s->omega);
	free(s->contact);
	free(s->active);
	free(s->touched);
	free(s->impulse);
	free(s->direction);
	free(s->pin);
	memset(s, 0, sizeof *s);
}

void bsim_state_copy(bsim_state *dst, const bsim_state *src)
{
	int n = src->n_beams < dst->n_beams ? src->n_beams : dst->n_beams;
	memcpy(dst->x, src->x, sizeof dst->x);
	memcpy(dst->v, src->v, sizeof dst->v);
	dst->heading = src->heading;
	dst->angular_velocity = src->angular_velocity;
	memcpy(dst->theta, src->theta, (size_t)n * sizeof *dst->theta);
	memcpy(dst->omega, src->omega, (size_t)n * sizeof *dst->omega);
	memcpy(dst->contact, src->contact, (size_t)n * sizeof *dst->contact);
	memcpy(dst->touched, src->touched, (size_t)n * sizeof *dst->touched);
	memcpy(dst->impulse, src->impulse, (size_t)n * sizeof *dst->impulse);
	memcpy(dst->direction, src->direction, 2 * (size_t)n * sizeof *dst->direction);
	memcpy(dst->pin, src->pin, 2 * (size_t)n * sizeof *dst->pin);
	dst->n_active = 0;
	for (int k = 0; k < src->n_active; k++)
		if (src->active[k] < dst->n_beams)
			dst->active[dst->n_active++] = src->active[k];
	dst->energy = src->energy;
	dst->drag_loss = src->drag_loss;
	dst->friction_loss = src->friction_loss;
	dst->impacts = src->impacts;
	dst->solver = src->solver;
}

void bsim_state_set_active(bsim_state *s, const int *active, int n)
{
	/* The same list as now (a step's usual case): its entries are about to
	 * be written, and the others are already zero. */
	if (n == s->n_active) {
		int k = 0;
		while (k < n && active[k] == s->active[k])
			k++;
		if (k == n)
			return;
	}
	for (int k = 0; k < s->n_active; k++) {
		int i = s->active[k];
		s->theta[i] = 0.0;
		s->omega[i] = 0.0;
		s->contact[i] = BSIM_CONTACT_NONE;
		s->touched[i] = 0;
		s->impulse[i] = 0.0;
	}
	s->n_active = 0;
	for (int k = 0; k < n; k++)
		if (active[k] >= 0 && active[k] < s->n_beams)
			s->active[s->n_active++] = active[k];
}
