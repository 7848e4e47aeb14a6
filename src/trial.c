/* The trial runner (MODEL.md section 6, DESIGN.md "The flow of one
 * experiment"): time, forces from the effect pipeline, termination,
 * outcomes, the energy ledger and recording. Everything here is the same
 * code for every backend. */
#include "beamsim/trial.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/effects.h"
#include "beamsim/landscape.h"

/* A beam as the overlap measure sees it: pivot, rest direction, forward
 * sign, length and the square of the reach L + R within which the body can
 * touch it. */
typedef struct beam_shape {
	double p[2], u0[2], sgn, length, reach2;
} beam_shape;

struct bsim_runner {
	bsim_state s0, s1; /* before and after a step */
	beam_shape *shape; /* per beam */
	int *touching;     /* contacts at the last touching step before success_y */
	int cap;           /* beams the states hold */
};

bsim_runner *bsim_runner_alloc(void)
{
	return calloc(1, sizeof(bsim_runner));
}

void bsim_runner_free(bsim_runner *r)
{
	if (!r)
		return;
	bsim_state_free(&r->s0);
	bsim_state_free(&r->s1);
	free(r->shape);
	free(r->touching);
	free(r);
}

static int runner_reserve(bsim_runner *r, int n_beams)
{
	if (r->cap == n_beams && r->s0.theta)
		return BSIM_OK;
	bsim_state_free(&r->s0);
	bsim_state_free(&r->s1);
	free(r->shape);
	free(r->touching);
	r->cap = 0;
	r->shape = malloc((size_t)(n_beams > 0 ? n_beams : 1) * sizeof *r->shape);
	r->touching = malloc((size_t)(n_beams > 0 ? n_beams : 1) * sizeof *r->touching);
	if (!r->shape || !r->touching || bsim_state_alloc(&r->s0, n_beams) ||
	    bsim_state_alloc(&r->s1, n_beams))
		return BSIM_EFAIL;
	r->cap = n_beams;
	return BSIM_OK;
}

static void shapes_init(beam_shape *shape, const bsim_scene *sc)
{
	for (int i = 0; i < sc->n_beams; i++) {
		const bsim_beam_def *b = &sc->beams[i];
		beam_shape *q = &shape[i];
		q->p[0] = b->pivot[0];
		q->p[1] = b->pivot[1];
		bsim_beam_rest_direction(b, q->u0);
		q->sgn = bsim_beam_forward_sign(b);
		q->length = b->length;
		q->reach2 = (b->length + sc->body.radius) * (b->length + sc->body.radius);
	}
}

/* How deep the body of radius R overlaps the beams, m (0 if it does not):
 * R - min_i |C - Q_i|, Q_i the point of beam i's segment nearest the centre
 * C (MODEL.md section 3). A beam whose reach L + R does not hold the
 * centre costs one distance test. */
static double overlap_depth(const beam_shape *shape, int n, double radius, const bsim_state *s)
{
	double depth = 0.0;
	for (int i = 0; i < n; i++) {
		const beam_shape *q = &shape[i];
		double dx = s->x[0] - q->p[0], dy = s->x[1] - q->p[1];
		if (dx * dx + dy * dy >= q->reach2)
			continue;
		double cs = cos(s->theta[i]), sn = q->sgn * sin(s->theta[i]);
		double ux = q->u0[0] * cs - q->u0[1] * sn, uy = q->u0[1] * cs + q->u0[0] * sn;
		double along = fmin(fmax(dx * ux + dy * uy, 0.0), q->length);
		double dist = hypot(dx - along * ux, dy - along * uy);
		depth = fmax(depth, radius - dist);
	}
	return depth;
}

const char *bsim_outcome_name(bsim_outcome o)
{
	static const char *names[] = {"traversed", "side_exit", "stuck", "unstable"};
	return (unsigned)o < BSIM_N_OUTCOMES ? names[o] : "?";
}

const char *bsim_type_name(bsim_type t)
{
	static const char *names[] = {"none", "left", "right"};
	return (unsigned)t < 3 ? names[t] : "?";
}

/* Kinetic energy of body and beams, J. */
static double energy_kinetic(const bsim_scene *sc, const bsim_state *s)
{
	double e = 0.5 * sc->body.mass * (s->v[0] * s->v[0] + s->v[1] * s->v[1]);
	for (int i = 0; i < s->n_beams; i++)
		e += 0.5 * sc->beams[i].inertia * s->omega[i] * s->omega[i];
	return e;
}

/* Elastic energy of the beam springs, J. */
static double energy_springs(const bsim_scene *sc, const bsim_state *s)
{
	double e = 0.0;
	for (int i = 0; i < s->n_beams; i++)
		e += 0.5 * sc->beams[i].stiffness * s->theta[i] * s->theta[i];
	return e;
}

void bsim_recorder_header(FILE *f, int n_beams)
{
	fputs("t,x,y,vx,vy", f);
	for (int i = 1; i <= n_beams; i++)
		fprintf(f, ",theta%d,omega%d", i, i);
	fputs(",f_rand", f);
	for (int i = 1; i <= n_beams; i++)
		fprintf(f, ",contact%d", i);
	fputs(",e_kin,e_beam,e_prop\n", f);
}

void bsim_recorder_ledger_header(FILE *f)
{
	fputs("t,e_kin,e_beam,e_mech,w_prop,w_rand,damper,impact,contact,correction,residual\n", f);
}

void bsim_recorder_csv_record(void *file, const bsim_record_row *row)
{
	FILE *f = file;
	const bsim_state *s = row->state;
	fprintf(f, "%.6f,%.10g,%.10g,%.10g,%.10g", row->t, s->x[0], s->x[1], s->v[0], s->v[1]);
	for (int i = 0; i < s->n_beams; i++)
		fprintf(f, ",%.10g,%.10g", s->theta[i], s->omega[i]);
	fprintf(f, ",%.10g", row->f_rand);
	for (int i = 0; i < s->n_beams; i++)
		fprintf(f, ",%d", s->contact[i]);
	fprintf(f, ",%.10g,%.10g,%.10g\n", row->e_kin, row->e_beam, row->e_prop);
}

static void ledger_row(FILE *f, const bsim_record_row *row)
{
	const bsim_ledger *l = row->ledger;
	fprintf(f, "%.6f,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g\n", row->t,
	        row->e_kin, row->e_beam, row->e_kin + row->e_beam, l->w_prop, l->w_rand, l->damper,
	        l->impact, l->contact, l->correction, l->residual);
}

/* One recorded row to every sink of rec. */
static void record(const bsim_recorder *rec, const bsim_scene *sc, const bsim_state *s, long step,
                   double f_rand, const bsim_ledger *ledger)
{
	bsim_record_row row = {
	        .step = step,
	        .t = (double)step * sc->dt,
	        .state = s,
	        .f_rand = f_rand,
	        .ledger = ledger,
	        .e_kin = energy_kinetic(sc, s),
	        .e_beam = energy_springs(sc, s),
	        .e_prop = bsim_landscape_e_prop(sc, s->x[1]),
	};
	if (rec->csv)
		bsim_recorder_csv_record(rec->csv, &row);
	if (rec->ledger)
		ledger_row(rec->ledger, &row);
	if (rec->record)
		rec->record(rec->record_user, &row);
}

/* One step's entry in the ledger: the work of each force over the body's
 * displacement, the backend's losses, and what is left over. */
static void ledger_step(bsim_ledger *l, const bsim_effects *fx, const bsim_state *s0,
                        const bsim_state *s1, double e0, double e1)
{
	const double d[2] = {s1->x[0] - s0->x[0], s1->x[1] - s0->x[1]};
	double w_prop = 0.0, w_rand = 0.0;
	for (int i = 0; i < fx->n; i++) {
		double work = fx->e[i].last * d[fx->e[i].axis];
		if (&fx->e[i] == fx->random)
			w_rand += work;
		else
			w_prop += work;
	}
	const bsim_step_energy *se = &s1->energy;
	double r = (e1 - e0) -
	           (w_prop + w_rand - se->damper - se->impact - se->contact - se->correction);
	l->w_prop += w_prop;
	l->w_rand += w_rand;
	l->damper += se->damper;
	l->impact += se->impact;
	l->contact += se->contact;
	l->correction += se->correction;
	l->residual += r;
	l->residual_abs += fabs(r);
	l->residual_max = fmax(l->residual_max, fabs(r));
	l->inflow += fabs(w_prop) + fabs(w_rand);
}

void bsim_trial_instability_text(const bsim_trial_result *r, double dt, char *buf, size_t size)
{
	const bsim_ledger *l = &r->ledger;
	switch (r->instability) {
	case BSIM_UNSTABLE_NONFINITE:
		snprintf(buf, size, "non-finite state at step %d (t = %g s)", r->unstable_step,
		         r->unstable_step * dt);
		break;
	case BSIM_UNSTABLE_ENERGY:
		snprintf(buf, size,
		         "energy created: ledger residual %.3g J > %g x %.4g J that flowed in "
		         "(start %.4g J, end %.4g J)",
		         l->residual, BSIM_LEDGER_BOUND, l->inflow, l->e_start, l->e_end);
		break;
	default:
		snprintf(buf, size, "%s", "");
	}
}

static int state_finite(const bsim_state *s)
{
	double sum = s->x[0] + s->x[1] + s->v[0] + s->v[1];
	for (int i = 0; i < s->n_beams; i++)
		sum += s->theta[i] + s->omega[i];
	return isfinite(sum);
}

static int any_contact(const bsim_state *s)
{
	for (int i = 0; i < s->n_beams; i++)
		if (s->contact[i])
			return 1;
	return 0;
}

static double random_value(const bsim_effects *fx)
{
	return fx->random ? fx->random->last : 0.0;
}

int bsim_trial_run(bsim_runner *r, const bsim_scene *scene, const bsim_backend *backend,
                   const bsim_options *opts, uint64_t seed, const bsim_recorder *rec,
                   bsim_trial_result *out, bsim_error *err)
{
	memset(out, 0, sizeof *out);
	out->landscape_beam = -1;
	if (runner_reserve(r, scene->n_beams))
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	bsim_world *w = NULL;
	int rc = backend->create(scene, opts, &w, err);
	if (rc)
		return rc;
	bsim_effects fx;
	if (bsim_effects_init(&fx, scene, seed)) {
		backend->destroy(w);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}

	bsim_state *s0 = &r->s0, *s1 = &r->s1;
	backend->get_state(w, s0);
	if (rec && rec->overlap)
		shapes_init(r->shape, scene);
	const double h = scene->dt;
	const int n_max = scene->max_steps;
	double e0 = energy_kinetic(scene, s0) + energy_springs(scene, s0);
	out->ledger.e_start = e0;
	out->ledger.inflow = e0;
	for (int i = 0; i < 2 && i < scene->n_beams; i++)
		out->max_theta[i] = s0->theta[i];
	int stride = rec && rec->stride > 0 ? rec->stride : 1;
	int recording = rec && (rec->csv || rec->ledger || rec->record);
	bsim_trace_fn trace = rec ? rec->trace : NULL;
	int overlap = rec && rec->overlap;
	out->overlap_max = overlap ? 0.0 : NAN;
	double f[2];
	if (trace)
		trace(rec->trace_user, 0, s0);

	int done = 0; /* the outcome is known; running on to classify_y */
	/* The last step before success_y at which the body touched a beam:
	 * where and which beams (for the landscape label). */
	int touched = 0;
	double last_touch[2] = {0.0, 0.0};
	long recorded = -1;
	long n = 0, run_on = 0;
	out->outcome = BSIM_STUCK;
	while (1) {
		int stop = done ? s0->x[1] >= scene->classify_y || run_on >= n_max : n >= n_max;
		if (stop)
			break;
		bsim_effects_force(&fx, n, h, f);
		if (recording && n % stride == 0) {
			record(rec, scene, s0, n, random_value(&fx), &out->ledger);
			recorded = n;
		}
		backend->step(w, f, h);
		backend->get_state(w, s1);
		double e1 = energy_kinetic(scene, s1) + energy_springs(scene, s1);
		if (!state_finite(s1) || !isfinite(e1)) {
			/* s0 stays the last finite state, the one reported. */
			out->instability = BSIM_UNSTABLE_NONFINITE;
			out->unstable_step = (int)(n + 1);
			break;
		}
		n++;
		run_on += done;
		if (trace)
			trace(rec->trace_user, n, s1);
		ledger_step(&out->ledger, &fx, s0, s1, e0, e1);
		e0 = e1;
		bsim_state *t = s0;
		s0 = s1;
		s1 = t;
		if (overlap)
			out->overlap_max =
			        fmax(out->overlap_max, overlap_depth(r->shape, scene->n_beams,
			                                             scene->body.radius, s0));
		if (done)
			continue;
		for (int i = 0; i < 2 && i < scene->n_beams; i++)
			out->max_theta[i] = fmax(out->max_theta[i], s0->theta[i]);
		if (any_contact(s0)) {
			touched = 1;
			last_touch[0] = s0->x[0];
			last_touch[1] = s0->x[1];
			memcpy(r->touching, s0->contact, (size_t)s0->n_beams * sizeof *r->touching);
		}
		if (fabs(s0->x[0]) >= scene->side_x) {
			out->outcome = BSIM_SIDE_EXIT;
			break;
		}
		if (s0->x[1] >= scene->success_y) {
			out->outcome = BSIM_TRAVERSED;
			out->steps = (int)n;
			out->t_end = (double)n * h;
			done = 1;
		}
	}
	if (recording && recorded != n) /* the final state, whatever the stride */
		record(rec, scene, s0, n, random_value(&fx), &out->ledger);
	if (out->outcome != BSIM_TRAVERSED) {
		out->steps = (int)n;
		out->t_end = (double)n * h;
	}
	if (out->outcome == BSIM_STUCK)
		out->in_contact_end = any_contact(s0);
	if (out->outcome == BSIM_TRAVERSED) {
		const double band = scene->classify_deadband;
		out->type = s0->v[0] > band    ? BSIM_TYPE_LEFT
		            : s0->v[0] < -band ? BSIM_TYPE_RIGHT
		                               : BSIM_TYPE_NONE;
		out->landscape_beam =
		        touched ? bsim_landscape_label(scene, last_touch, r->touching) : -1;
	}
	out->x_end = s0->x[0];
	out->y_end = s0->x[1];
	out->vx_end = s0->v[0];
	out->steps_run = (int)n;
	out->ledger.e_end = e0;
	const bsim_ledger *l = &out->ledger;
	if (!out->instability && l->residual > BSIM_LEDGER_BOUND * l->inflow + BSIM_LEDGER_FLOOR) {
		out->instability = BSIM_UNSTABLE_ENERGY;
		out->unstable_step = (int)n;
	}
	if (out->instability) {
		out->outcome = BSIM_UNSTABLE;
		out->type = BSIM_TYPE_NONE;
		out->landscape_beam = -1;
		out->in_contact_end = 0;
	}
	out->draws = fx.random ? bsim_schedule_draws(fx.random->schedule) : 0;
	bsim_effects_free(&fx);
	backend->destroy(w);
	return rc;
}
