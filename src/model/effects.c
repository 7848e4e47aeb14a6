/* The essay's body effects: constant propulsion along +y and the piecewise
 * constant lateral random force. Each is a pipeline entry only if the scene
 * lists it (beam spring, damping and restitution are the backend's). */
#include "beamsim/effects.h"

#include <string.h>

/* F_prop = (0, F): essay Eq. 2.1. */
static void propulsion_apply(bsim_effect *e, long n, double h, double f[2])
{
	(void)n;
	(void)h;
	f[1] += e->param;
	e->last = e->param;
}

/* F_rand = (Rm z_j, 0), z_j held for 1/f seconds: essay Eq. 2.3. */
static void random_force_apply(bsim_effect *e, long n, double h, double f[2])
{
	double value = bsim_schedule_at_step(e->schedule, n, h);
	f[0] += value;
	e->last = value;
}

static bsim_effect *effects_add(bsim_effects *fx, const char *name,
                                void (*apply)(bsim_effect *, long, double, double[2]), int axis,
                                double param)
{
	bsim_effect *e = &fx->e[fx->n++];
	memset(e, 0, sizeof *e);
	e->name = name;
	e->apply = apply;
	e->axis = axis;
	e->param = param;
	return e;
}

int bsim_effects_random(const bsim_scene *scene)
{
	return scene->effects.has_random_force;
}

int bsim_effects_init(bsim_effects *fx, const bsim_scene *scene, uint64_t seed)
{
	memset(fx, 0, sizeof *fx);
	const bsim_effects_def *d = &scene->effects;
	if (d->has_propulsion)
		effects_add(fx, "propulsion", propulsion_apply, 1, d->propulsion_force);
	if (d->has_random_force) {
		bsim_effect *e =
		        effects_add(fx, "random_force", random_force_apply, 0, d->random_magnitude);
		e->schedule = bsim_schedule_alloc(d->random_magnitude, d->random_frequency, seed);
		if (!e->schedule) {
			fx->n--;
			return BSIM_EFAIL;
		}
		fx->random = e;
	}
	return BSIM_OK;
}

int bsim_effects_status(const bsim_effects *fx, bsim_error *err)
{
	return fx->random ? bsim_schedule_status(fx->random->schedule, err) : BSIM_OK;
}

void bsim_effects_free(bsim_effects *fx)
{
	for (int i = 0; i < fx->n; i++)
		bsim_schedule_free(fx->e[i].schedule);
	memset(fx, 0, sizeof *fx);
}
