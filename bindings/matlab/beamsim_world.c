/* beamsim_world: a world stepped by hand (beamsim/stepper.h).
 *
 *   w = beamsim_world('open', ARG, NAME, VALUE, ...)
 *   beamsim_world('step', w)                         one step, the trial's forces
 *   beamsim_world('step', w, 'n', N, 'force', [FX FY], 'torque', TQ)
 *   s = beamsim_world('state', w)
 *   beamsim_world('reset', w)
 *   beamsim_world('close', w)
 *
 * ARG and the names of 'open' are beamsim_run's ('seed', 'group', 'trial'
 * from 1, 'backend', 'backend_opt', 'set', 'grid'): the world starts as
 * that trial starts. w is a handle (uint64) to a world the function keeps
 * until 'close' (or `clear beamsim_world`, which closes them all). 'step'
 * without 'force' applies the scene's own effects, each step's force from
 * the state it starts at: the trial's steps as beamsim_run makes them. */
#include <stdio.h>
#include <string.h>

#include "bsim_mex.h"

/* The worlds open: a handle is its slot plus 1 and, above bit 32, the
 * slot's generation, so that a closed world's handle is refused and not
 * taken for a later one's. */
#define WORLDS_MAX 256
static bsim_stepper *worlds[WORLDS_MAX];
static uint32_t generation[WORLDS_MAX];
static char labels[WORLDS_MAX][128];
static int n_open;

static void close_all(void)
{
	for (int i = 0; i < WORLDS_MAX; i++) {
		bsim_stepper_free(worlds[i]);
		worlds[i] = NULL;
	}
	n_open = 0;
}

static const char *const open_names[BMX_TRIAL_NAMES] = {BMX_TRIAL_NAME_LIST};
enum { S_N, S_FORCE, S_TORQUE, N_STEP };
static const char *const step_names[N_STEP] = {"n", "force", "torque"};

typedef struct world_call {
	bmx_pool pool;
	bmx_trial trial;
} world_call;

/* The slot of handle h (an argument), or -1 with err. */
static int slot_of(const mxArray *h, bsim_error *err)
{
	if (!h || !mxIsUint64(h) || mxGetNumberOfElements(h) != 1)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "expected a world's handle (what beamsim_world('open', ...) "
		                      "returns)"),
		       -1;
	uint64_t v = *(const uint64_t *)mxGetData(h);
	uint64_t slot = (v & 0xffffffffu) - 1;
	if (slot >= WORLDS_MAX || !worlds[slot] || generation[slot] != (uint32_t)(v >> 32))
		return bsim_error_set(err, BSIM_EINPUT,
		                      "the handle names no open world (closed, or never opened)"),
		       -1;
	return (int)slot;
}

static int world_open(world_call *c, int nrhs, const mxArray *prhs[], mxArray **out,
                      bsim_error *err)
{
	const mxArray *v[BMX_TRIAL_NAMES];
	if (nrhs < 2)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "'open': expected a scene, an experiment or an output "
		                      "directory, then name-value pairs");
	if (bmx_pairs(nrhs, prhs, 2, open_names, BMX_TRIAL_NAMES, v, err) != BSIM_OK ||
	    bmx_trial_open(prhs[1], v, &c->pool, &c->trial, err) != BSIM_OK)
		return err->code ? err->code : BSIM_EINPUT;
	const bsim_replay *rp = c->trial.rp;
	int slot = 0;
	while (slot < WORLDS_MAX && worlds[slot])
		slot++;
	if (slot == WORLDS_MAX)
		return bsim_error_set(
		        err, BSIM_EINPUT,
		        "more than %d worlds open: close some (beamsim_world('close', "
		        "w))",
		        WORLDS_MAX);
	bsim_stepper_def sd = bsim_stepper_def_default();
	sd.scene = &rp->scene;
	sd.backend = c->trial.backend;
	sd.opts = &c->trial.opts;
	sd.seed = rp->mixed_seed;
	int rc = bsim_stepper_alloc(&sd, &worlds[slot], err);
	if (rc != BSIM_OK)
		return rc;
	snprintf(labels[slot], sizeof labels[slot], "%s",
	         rp->backend ? rp->label : c->trial.backend->name);
	if (n_open++ == 0)
		mexLock();
	*out = bmx_u64(((uint64_t)++generation[slot] << 32) | (uint64_t)(slot + 1));
	return BSIM_OK;
}

static int world_step(int slot, int nrhs, const mxArray *prhs[], bsim_error *err)
{
	const mxArray *v[N_STEP];
	if (bmx_pairs(nrhs, prhs, 2, step_names, N_STEP, v, err) != BSIM_OK)
		return BSIM_EINPUT;
	long n = 1;
	double torque = 0.0;
	if ((v[S_N] && bmx_long("n", v[S_N], 1, INT32_MAX, &n, err)) ||
	    (v[S_TORQUE] && bmx_double("torque", v[S_TORQUE], &torque, err)))
		return err->code;
	if (!v[S_FORCE])
		return bsim_stepper_step(worlds[slot], n, err);
	const mxArray *f = v[S_FORCE];
	if (!mxIsDouble(f) || mxIsComplex(f) || mxGetNumberOfElements(f) != 2)
		return bsim_error_set(err, BSIM_EINPUT, "'force': expected [FX FY] in N");
	return bsim_stepper_push(worlds[slot], mxGetPr(f), torque, n, err);
}

static mxArray *int_row(const int *v, int n)
{
	mxArray *a = mxCreateDoubleMatrix(1, (mwSize)n, mxREAL);
	for (int i = 0; i < n; i++)
		mxGetPr(a)[i] = v[i];
	return a;
}

static mxArray *world_state(int slot)
{
	const bsim_stepper *w = worlds[slot];
	const bsim_state *s = bsim_stepper_state(w);
	double wrench[3], kin, elastic;
	bsim_stepper_wrench(w, wrench);
	bsim_stepper_energy(w, &kin, &elastic);
	long step = bsim_stepper_steps(w);
	mxArray *e = mxCreateStructMatrix(1, 1, 0, NULL);
	bmx_set(e, 0, "damper", bmx_scalar(s->energy.damper));
	bmx_set(e, 0, "impact", bmx_scalar(s->energy.impact));
	bmx_set(e, 0, "contact", bmx_scalar(s->energy.contact));
	bmx_set(e, 0, "correction", bmx_scalar(s->energy.correction));
	bmx_set(e, 0, "sleep", bmx_scalar(s->energy.sleep));
	mxArray *r = mxCreateStructMatrix(1, 1, 0, NULL);
	bmx_set(r, 0, "step", bmx_scalar((double)step));
	bmx_set(r, 0, "t", bmx_scalar((double)step * bsim_stepper_scene(w)->dt));
	bmx_set(r, 0, "x", bmx_row(s->x, 2));
	bmx_set(r, 0, "v", bmx_row(s->v, 2));
	bmx_set(r, 0, "heading", bmx_scalar(s->heading));
	bmx_set(r, 0, "angular_velocity", bmx_scalar(s->angular_velocity));
	bmx_set(r, 0, "theta", bmx_row(s->theta, s->n_beams));
	bmx_set(r, 0, "omega", bmx_row(s->omega, s->n_beams));
	bmx_set(r, 0, "contact", int_row(s->contact, s->n_beams));
	bmx_set(r, 0, "touched", int_row(s->touched, s->n_beams));
	bmx_set(r, 0, "impulse", bmx_row(s->impulse, s->n_beams));
	bmx_set(r, 0, "force", bmx_row(wrench, 3));
	bmx_set(r, 0, "e_kin", bmx_scalar(kin));
	bmx_set(r, 0, "e_elastic", bmx_scalar(elastic));
	bmx_set(r, 0, "energy", e);
	bmx_set(r, 0, "impacts", bmx_scalar(s->impacts));
	bmx_set(r, 0, "backend", bmx_string(labels[slot]));
	return r;
}

static int world(world_call *c, int nrhs, const mxArray *prhs[], mxArray **out, bsim_error *err)
{
	const char *cmd = NULL;
	if (nrhs < 1 || bmx_text("command", prhs[0], &c->pool, &cmd, err))
		return bsim_error_set(err, BSIM_EINPUT,
		                      "expected a command: 'open', 'step', 'state', 'reset' or "
		                      "'close'");
	if (strcmp(cmd, "open") == 0)
		return world_open(c, nrhs, prhs, out, err);
	if (strcmp(cmd, "step") != 0 && strcmp(cmd, "state") != 0 && strcmp(cmd, "reset") != 0 &&
	    strcmp(cmd, "close") != 0)
		return bsim_error_set(
		        err, BSIM_EINPUT,
		        "'%s': expected a command: 'open', 'step', 'state', 'reset' or "
		        "'close'",
		        cmd);
	int slot = slot_of(nrhs > 1 ? prhs[1] : NULL, err);
	if (slot < 0)
		return BSIM_EINPUT;
	if (strcmp(cmd, "step") == 0)
		return world_step(slot, nrhs, prhs, err);
	if (strcmp(cmd, "state") == 0) {
		*out = world_state(slot);
		return BSIM_OK;
	}
	if (strcmp(cmd, "reset") == 0)
		return bsim_stepper_reset(worlds[slot], err);
	bsim_stepper_free(worlds[slot]);
	worlds[slot] = NULL;
	if (--n_open == 0)
		mexUnlock();
	return BSIM_OK;
}

void mexFunction(int nlhs, mxArray *plhs[], int nrhs, const mxArray *prhs[])
{
	(void)nlhs;
	mexAtExit(close_all);
	world_call c;
	memset(&c, 0, sizeof c);
	bsim_error err;
	bsim_error_clear(&err);
	mxArray *out = NULL;
	int rc = world(&c, nrhs, prhs, &out, &err);
	bmx_trial_free(&c.trial);
	bmx_pool_free(&c.pool);
	if (rc != BSIM_OK)
		bmx_fail(&err);
	plhs[0] = out;
}
