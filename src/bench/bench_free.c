/* beamsim bench's free-flight figure: the backend's cost per step where
 * nothing happens but the flight itself, against a minimal loop that does
 * only the physics of such a step.
 *
 * Free flight is the experiment's own scene with the body started 10 km
 * below the beams and the side exit moved out of the way, so that every
 * trial runs all its max_steps without touching a beam: the full runner
 * (forces, state, energy ledger, termination) around the backend's step.
 *
 * The minimal loop integrates, for the same groups and trials and so the
 * same number of steps, what such a step must compute: the propulsion and
 * the held random force (a fresh N(0, 1) draw of GSL's ziggurat from a
 * Mersenne Twister every 1/(f h) steps, as the schedule draws), the body
 * (v' = v + h F / M, x' = x + h (v + v') / 2), both beams by the implicit
 * midpoint rule's closed form (beam_integrate.h), and each beam's reach
 * test. Nothing else: no runner, no ledger, no backend interface. */
#define _POSIX_C_SOURCE 200809L

#include "bench/bench_free.h"

#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/effects.h"
#include "beamsim/schedule.h"
#include "util/clock.h"
#include "cli/cli_common.h"

/* One group's trials of the minimal loop; returns a checksum of the final
 * states so that none of it can be optimised away. */
static double minimal_group(const bsim_scene *s, uint64_t seed, long group, long trials,
                            gsl_rng *rng)
{
	const double h = s->dt, m = s->body.mass;
	const double f_prop = s->effects.has_propulsion ? s->effects.propulsion_force : 0.0;
	const int noisy = s->effects.has_random_force;
	const double rm = s->effects.random_magnitude;
	const long hold = noisy ? lround(1.0 / (s->effects.random_frequency * h)) : 1;
	/* The midpoint rule's closed form omega' = a omega + c theta, its
	 * coefficients constants of each beam: a = (2 - D) / D, c = -h k / (I D). */
	double a[2] = {1.0, 1.0}, c[2] = {0.0, 0.0};
	for (int i = 0; i < 2 && i < s->n_beams; i++) {
		const bsim_beam_def *b = &s->beams[i];
		double d = 1.0 + h * b->damping / (2.0 * b->inertia) +
		           h * h * b->stiffness / (4.0 * b->inertia);
		a[i] = (2.0 - d) / d;
		c[i] = -h * b->stiffness / (b->inertia * d);
	}
	const double inv_m = 1.0 / m;
	double check = 0.0;
	for (long t = 0; t < trials; t++) {
		uint64_t mixed = bsim_schedule_seed_mix(seed, (uint64_t)group, (uint64_t)t);
		gsl_rng_set(rng, (unsigned long)(mixed ^ (mixed >> 32)));
		double x[2] = {s->body.start[0], s->body.start[1]};
		double v[2] = {s->body.velocity[0], s->body.velocity[1]};
		double theta[2] = {0.0, 0.0}, omega[2] = {0.0, 0.0}, f_rand = 0.0;
		long reach_hits = 0;
		long held = 0; /* steps left of the held value */
		for (long n = 0; n < s->max_steps; n++) {
			if (noisy && held-- == 0) {
				f_rand = rm * gsl_ran_gaussian_ziggurat(rng, 1.0);
				held = hold - 1;
			}
			double v0[2] = {v[0], v[1]};
			v[0] += h * f_rand * inv_m;
			v[1] += h * f_prop * inv_m;
			x[0] += h * 0.5 * (v0[0] + v[0]);
			x[1] += h * 0.5 * (v0[1] + v[1]);
			for (int i = 0; i < 2 && i < s->n_beams; i++) {
				const bsim_beam_def *b = &s->beams[i];
				double w = a[i] * omega[i] + c[i] * theta[i];
				theta[i] += h * 0.5 * (omega[i] + w);
				omega[i] = w;
				double dx = x[0] - b->pivot[0], dy = x[1] - b->pivot[1];
				double reach = b->length + s->body.radius;
				reach_hits += dx * dx + dy * dy < reach * reach;
			}
		}
		check += x[0] + x[1] + theta[0] + (double)reach_hits;
	}
	return check;
}

int bench_free(const bench_free_args *a, bench_free_result *out)
{
	memset(out, 0, sizeof *out);
	cli_sets sets = {0};
	int rc = cli_sets_add(&sets, "bench", "body.start=[0,-10000]");
	if (rc == CLI_OK)
		rc = cli_sets_add(&sets, "bench", "termination.side_x=1e9");
	bsim_experiment e;
	if (rc == CLI_OK)
		rc = cli_experiment_load(a->experiment, &sets, NULL, a->trials, &e);
	if (rc != CLI_OK) {
		cli_sets_free(&sets);
		return rc;
	}

	/* beamsim: the whole sweep on one thread */
	if (a->only != 2) {
		bsim_sweep_config cfg = {.backend = a->backend,
		                         .opts = a->opts,
		                         .threads = 1,
		                         .extra = sets.ov,
		                         .n_extra = sets.n};
		bsim_sweep_result r;
		rc = cli_sweep_run(&e, &cfg, 0, &r);
		if (rc != CLI_OK || a->only == 1) {
			if (rc == CLI_OK) {
				out->trials = r.trials_run;
				out->steps = r.total_steps;
				bsim_sweep_result_free(&r);
			}
			cli_sets_free(&sets);
			bsim_experiment_free(&e);
			return rc;
		}
		out->trials = r.trials_run;
		out->steps = r.total_steps;
		out->beamsim_seconds = r.wall_seconds;
		bsim_sweep_result_free(&r);
	}

	/* the minimal loop: the same groups, the trials each ran */
	gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
	if (!rng) {
		cli_sets_free(&sets);
		bsim_experiment_free(&e);
		cli_error("out of memory");
		return CLI_FAIL;
	}
	long steps = 0;
	double check = 0.0, t0 = bsim_clock_seconds();
	for (int g = 0; g < e.n_groups && rc == CLI_OK; g++) {
		bsim_scene s;
		bsim_error err;
		if (bsim_experiment_group_scene(&e, g, sets.ov, sets.n, &s, &err) != BSIM_OK) {
			rc = cli_report(BSIM_EINPUT, &err);
			break;
		}
		long trials = bsim_effects_random(&s) ? e.trials : 1; /* as the sweep runs them */
		check += minimal_group(&s, e.seed, g, trials, rng);
		steps += trials * s.max_steps;
		bsim_scene_free(&s);
	}
	out->minimal_seconds = bsim_clock_seconds() - t0;
	out->checksum = check;
	gsl_rng_free(rng);
	cli_sets_free(&sets);
	bsim_experiment_free(&e);
	if (rc != CLI_OK)
		return rc;
	if (a->only == 2)
		out->steps = steps;
	else if (steps != out->steps) {
		cli_error(
		        "free flight: the trials ran %ld steps, not all %ld of their max_steps (a "
		        "trial ended early: the scene is not free flight)",
		        out->steps, steps);
		return CLI_FAIL;
	}
	return CLI_OK;
}
