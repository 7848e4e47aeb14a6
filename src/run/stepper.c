/* A world stepped by hand; see beamsim/stepper.h. */
#include "beamsim/stepper.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/backend_registry.h"
#include "beamsim/contact_flag.h"
#include "beamsim/effects.h"
#include "run/trial_ledger.h"

struct bsim_stepper {
	bsim_scene scene;
	const bsim_backend *backend;
	bsim_options opts;
	uint64_t seed;
	bsim_world *w;
	bsim_effects fx;
	int fx_on;
	bsim_state state;
	long n;
	double wrench[BSIM_WRENCH];
};

bsim_stepper_def bsim_stepper_def_default(void)
{
	return (bsim_stepper_def){.seed = 1};
}

/* The effects restarted for the stepper's seed. */
static int effects_start(bsim_stepper *s, bsim_error *err)
{
	if (s->fx_on)
		bsim_effects_free(&s->fx);
	s->fx_on = 0;
	if (bsim_effects_init_taking(&s->fx, &s->scene, s->seed, s->backend->takes))
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	s->fx_on = 1;
	return BSIM_OK;
}

/* The state at step 0 of the world as it is now. */
static void state_start(bsim_stepper *s)
{
	s->backend->get_state(s->w, &s->state);
	bsim_contact_flags(&s->scene, &s->state);
	s->n = 0;
	memset(s->wrench, 0, sizeof s->wrench);
}

void bsim_stepper_free(bsim_stepper *s)
{
	if (!s)
		return;
	if (s->w)
		s->backend->destroy(s->w);
	if (s->fx_on)
		bsim_effects_free(&s->fx);
	bsim_state_free(&s->state);
	bsim_scene_free(&s->scene);
	free(s);
}

int bsim_stepper_alloc(const bsim_stepper_def *def, bsim_stepper **out, bsim_error *err)
{
	*out = NULL;
	if (!def->scene)
		return bsim_error_set(err, BSIM_EINPUT, "stepper: no scene");
	bsim_stepper *s = calloc(1, sizeof *s);
	if (!s)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	s->backend = def->backend ? def->backend : bsim_backend_default();
	if (def->opts)
		s->opts = *def->opts;
	s->seed = def->seed;
	int rc = bsim_scene_copy(&s->scene, def->scene);
	if (rc == BSIM_OK && bsim_state_init(&s->state, s->scene.n_beams) != BSIM_OK)
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	else if (rc != BSIM_OK)
		bsim_error_set(err, rc, "out of memory");
	if (rc == BSIM_OK)
		rc = bsim_backend_check(s->backend, &s->opts, &s->scene, NULL, NULL, 0, err);
	if (rc == BSIM_OK)
		rc = s->backend->create(&s->scene, &s->opts, &s->w, err);
	if (rc == BSIM_OK)
		rc = effects_start(s, err);
	if (rc != BSIM_OK) {
		bsim_stepper_free(s);
		return rc;
	}
	state_start(s);
	*out = s;
	return BSIM_OK;
}

int bsim_stepper_reset(bsim_stepper *s, bsim_error *err)
{
	int rc;
	if (s->backend->reset) {
		rc = s->backend->reset(s->w, &s->scene, err);
	} else {
		s->backend->destroy(s->w);
		s->w = NULL;
		rc = s->backend->create(&s->scene, &s->opts, &s->w, err);
	}
	if (rc == BSIM_OK)
		rc = effects_start(s, err);
	if (rc == BSIM_OK)
		state_start(s);
	return rc;
}

/* One step under wrench f (the runner's: advance of one step from the
 * state it starts at), its state checked. */
static int step_one(bsim_stepper *s, const double f[BSIM_WRENCH], bsim_error *err)
{
	int made = 0;
	const bsim_wrench one = {{f[0], f[1]}, f[2]};
	int rc = s->backend->advance(s->w, &one, s->scene.dt, 1, &s->state, &made, err);
	if (rc != BSIM_OK)
		return rc;
	s->n++;
	memcpy(s->wrench, f, sizeof s->wrench);
	bsim_contact_flags(&s->scene, &s->state);
	double e;
	if (!state_energy_finite(&s->scene, &s->state, &e))
		return bsim_error_set(err, BSIM_EFAIL,
		                      "%s: the state is not finite after step %ld (t = %g s)",
		                      s->backend->name, s->n, (double)s->n * s->scene.dt);
	return BSIM_OK;
}

int bsim_stepper_step(bsim_stepper *s, long n, bsim_error *err)
{
	for (long k = 0; k < n; k++) {
		double f[BSIM_WRENCH];
		bsim_effects_force_at(&s->fx, s->n, s->scene.dt, &s->state, f);
		int rc = bsim_effects_status(&s->fx, err);
		if (rc == BSIM_OK)
			rc = step_one(s, f, err);
		if (rc != BSIM_OK)
			return rc;
	}
	return BSIM_OK;
}

int bsim_stepper_push(bsim_stepper *s, const double force[2], double torque, long n,
                      bsim_error *err)
{
	const double f[BSIM_WRENCH] = {force[0], force[1], torque};
	for (long k = 0; k < n; k++) {
		int rc = step_one(s, f, err);
		if (rc != BSIM_OK)
			return rc;
	}
	return BSIM_OK;
}

const bsim_state *bsim_stepper_state(const bsim_stepper *s)
{
	return &s->state;
}

long bsim_stepper_steps(const bsim_stepper *s)
{
	return s->n;
}

void bsim_stepper_wrench(const bsim_stepper *s, double wrench[3])
{
	memcpy(wrench, s->wrench, sizeof s->wrench);
}

void bsim_stepper_energy(const bsim_stepper *s, double *kinetic, double *elastic)
{
	*kinetic = energy_kinetic(&s->scene, &s->state);
	*elastic = energy_springs(&s->scene, &s->state);
}

const bsim_scene *bsim_stepper_scene(const bsim_stepper *s)
{
	return &s->scene;
}

const bsim_backend *bsim_stepper_backend(const bsim_stepper *s)
{
	return s->backend;
}
