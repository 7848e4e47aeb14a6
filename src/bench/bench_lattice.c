/* beamsim bench --lattice: the cost of a step against the size of the
 * field. For n = 1, 3, 5, 9, 17, 33 the essay's lattice of n x n gates
 * (bsim_lattice_scene_init: the Table 2.1 gate, k = 400 N m/rad, F_prop =
 * 6 N, Rm = 30 N) runs the same trials (seed 1, group 0, trials 0 .. N-1:
 * the same schedules at every size) on one thread, on each backend, and the
 * wall time per integrated step is reported with its ratio to the 1 x 1
 * field, twice:
 *   same trials: every field ends a trial where the 1 x 1 field does (the
 *     body leaves gate (0, 0): success_y = depth, side_x = width / 2), so
 *     the body does the same thing in every field and only the number of
 *     gates around it changes (and, from 3 x 3 on, the neighbours' beams
 *     at the shared pivots, which it can touch): the cost of the field's
 *     size. The target, the essay's solver within 1.2 x from 1 x 1 to
 *     33 x 33, is on this table.
 *   own field: each field's own termination; the body goes as far as it
 *     gets, with the beams it pushed still swinging behind it, so the cost
 *     also follows how many beams are awake near its path.
 * Setting up a trial (building the world: every beam of the field) is
 * timed apart, by the same trials run for 0 steps, and taken out of the
 * cost per step; it is reported per trial. The machine is shared and
 * noisy, so on the first backend every size is timed in each of 5 rounds,
 * the sizes of a round one after the other, and the fastest round counts
 * (the second, whose growth is far beyond the noise, once). A separate untimed
 * pass over the first trials counts the beams the runner saw awake per
 * step. */
#define _POSIX_C_SOURCE 200809L

#include "bench/bench_lattice.h"

#include <stdio.h>
#include <string.h>

#include "util/atomic_file.h"
#include "util/clock.h"
#include "util/json.h"
#include "beamsim/lattice.h"
#include "beamsim/output.h"
#include "beamsim/schedule.h"
#include "beamsim/trial.h"
#include "cli/cli_common.h"

static const int sizes[] = {1, 3, 5, 9, 17, 33};
#define N_SIZES ((int)(sizeof sizes / sizeof sizes[0]))

#define ROUNDS 5

typedef struct lattice_row {
	int n, beams;
	long trials, steps;
	double wall;        /* s, the steps alone (setup taken out), fastest round */
	double setup;       /* s per trial, fastest round */
	double active_mean; /* beams listed active per step (untimed pass) */
	double ns_per_step; /* ns */
	double ratio;       /* to the 1 x 1 field */
} lattice_row;

static void count_active(void *user, long step, const bsim_state *s)
{
	double *acc = user; /* {sum of n_active, steps} */
	(void)step;
	acc[0] += s->n_active;
	acc[1] += 1.0;
}

/* Runs trials 0 .. trials-1 of scene; their steps into *steps, the wall
 * time returned. */
static double time_trials(bsim_trial_runner *runner, const bsim_scene *scene, const bsim_backend *b,
                          const bsim_options *opts, long trials, long *steps, int *rc,
                          bsim_error *err)
{
	*steps = 0;
	double t0 = bsim_clock_seconds();
	for (long t = 0; t < trials && *rc == BSIM_OK; t++) {
		bsim_trial_result res;
		*rc = bsim_trial_run(runner, scene, b, opts,
		                     bsim_schedule_seed_mix(1, 0, (uint64_t)t), NULL, &res, err);
		*steps += res.steps_run;
	}
	return bsim_clock_seconds() - t0;
}

static int bench_one(const bsim_backend *b, const bsim_options *opts, int n, long trials,
                     int same_trials, int round, lattice_row *row)
{
	bsim_scene scene;
	bsim_error err;
	if (round == 0)
		memset(row, 0, sizeof *row);
	if (bsim_lattice_scene_init(&scene, n, n, 6.0, 30.0) != BSIM_OK) {
		bsim_scene_free(&scene);
		cli_error("out of memory for a %d x %d lattice", n, n);
		return CLI_FAIL;
	}
	if (same_trials) { /* the 1 x 1 field's termination */
		bsim_scene one;
		if (bsim_lattice_scene_init(&one, 1, 1, 6.0, 30.0) != BSIM_OK) {
			bsim_scene_free(&one);
			bsim_scene_free(&scene);
			cli_error("out of memory for a 1 x 1 lattice");
			return CLI_FAIL;
		}
		scene.success_y = one.success_y;
		scene.side_x = one.side_x;
		scene.classify_y = one.classify_y;
		scene.max_steps = one.max_steps;
		scene.gate_steps = one.gate_steps;
		bsim_scene_free(&one);
	}
	bsim_trial_runner *runner = bsim_trial_runner_alloc();
	if (!runner) {
		bsim_scene_free(&scene);
		cli_error("out of memory for a trial runner");
		return CLI_FAIL;
	}
	bsim_trial_runner_keep_worlds(runner, 1); /* as a sweep runs its trials */
	int rc = BSIM_OK;
	row->n = n;
	row->beams = scene.n_beams;
	row->trials = trials;
	long steps, none;
	double wall = time_trials(runner, &scene, b, opts, trials, &steps, &rc, &err);
	bsim_scene setup = scene; /* shares the beams: the same world, 0 steps */
	setup.max_steps = 0;
	double wall0 = time_trials(runner, &setup, b, opts, trials, &none, &rc, &err);
	row->steps = steps;
	double per_trial = wall0 / (double)(trials > 0 ? trials : 1);
	double stepping = wall - wall0 > 0.0 ? wall - wall0 : 0.0;
	if (round == 0 || stepping < row->wall)
		row->wall = stepping;
	if (round == 0 || per_trial < row->setup)
		row->setup = per_trial;
	if (round > 0) {
		bsim_trial_runner_free(runner);
		bsim_scene_free(&scene);
		if (rc != BSIM_OK)
			return cli_report(rc, &err);
		row->ns_per_step = row->steps > 0 ? 1e9 * row->wall / (double)row->steps : 0.0;
		return CLI_OK;
	}
	double acc[2] = {0.0, 0.0};
	bsim_recorder rec = {.stride = 1, .trace = count_active, .trace_user = acc};
	for (long t = 0; t < (trials < 10 ? trials : 10) && rc == BSIM_OK; t++) {
		bsim_trial_result res;
		rc = bsim_trial_run(runner, &scene, b, opts,
		                    bsim_schedule_seed_mix(1, 0, (uint64_t)t), &rec, &res, &err);
	}
	bsim_trial_runner_free(runner);
	bsim_scene_free(&scene);
	if (rc != BSIM_OK)
		return cli_report(rc, &err);
	row->active_mean = acc[1] > 0.0 ? acc[0] / acc[1] : 0.0;
	row->ns_per_step = row->steps > 0 ? 1e9 * row->wall / (double)row->steps : 0.0;
	return CLI_OK;
}

/* Trials of LONG_STEPS steps (max_steps; the field's own end and sides,
 * which the body does not reach in that time at F_prop = 6 N), setup
 * included: the world kept from trial to trial as a sweep keeps it. */
#define LONG_STEPS 1000

int bench_lattice_long(const bsim_backend *b, const bsim_options *opts, int n, long trials,
                       long *steps, double *wall)
{
	bsim_scene scene;
	bsim_error err;
	*steps = 0;
	*wall = 0.0;
	if (bsim_lattice_scene_init(&scene, n, n, 6.0, 30.0) != BSIM_OK) {
		bsim_scene_free(&scene);
		cli_error("out of memory for a %d x %d lattice", n, n);
		return CLI_FAIL;
	}
	scene.max_steps = LONG_STEPS;
	bsim_trial_runner *runner = bsim_trial_runner_alloc();
	if (!runner) {
		bsim_scene_free(&scene);
		cli_error("out of memory for a trial runner");
		return CLI_FAIL;
	}
	bsim_trial_runner_keep_worlds(runner, 1);
	int rc = BSIM_OK;
	*wall = time_trials(runner, &scene, b, opts, trials, steps, &rc, &err);
	bsim_trial_runner_free(runner);
	bsim_scene_free(&scene);
	return rc == BSIM_OK ? CLI_OK : cli_report(rc, &err);
}

/* The LONG_STEPS-step trials on every size, the fastest of ROUNDS rounds;
 * the cost per step, setup included, against the 5 x 5 field's. */
static int bench_long(FILE *out, const bsim_backend *b, const bsim_options *opts, long trials,
                      double ns[N_SIZES])
{
	long steps[N_SIZES];
	fprintf(out,
	        "\n%d-step trials, setup included (the world kept from trial to trial, as a "
	        "sweep keeps it)\n\n%-8s %11s %7s %11s %9s %9s %8s\n",
	        LONG_STEPS, "backend", "gates", "trials", "steps", "wall s", "ns/step", "x 5x5");
	for (int round = 0; round < ROUNDS; round++)
		for (int i = 0; i < N_SIZES; i++) {
			double wall;
			int rc = bench_lattice_long(b, opts, sizes[i], trials, &steps[i], &wall);
			if (rc != CLI_OK)
				return rc;
			double v = steps[i] > 0 ? 1e9 * wall / (double)steps[i] : 0.0;
			if (round == 0 || v < ns[i])
				ns[i] = v;
		}
	for (int i = 0; i < N_SIZES; i++)
		fprintf(out, "%-8s %5d x %-3d %7ld %11ld %9.3f %9.1f %8.2f\n", b->name, sizes[i],
		        sizes[i], trials, steps[i], 1e-9 * ns[i] * (double)steps[i], ns[i],
		        ns[i] / ns[2]);
	return CLI_OK;
}

static void print_row(FILE *f, const char *backend, const lattice_row *r)
{
	fprintf(f, "%-8s %5d x %-3d %6d %7ld %11ld %9.3f %9.1f %8.2f %11.1f %11.2f\n", backend,
	        r->n, r->n, r->beams, r->trials, r->steps, r->wall, r->ns_per_step, r->ratio,
	        1e6 * r->setup, r->active_mean);
	fflush(f);
}

static void json_rows(FILE *f, const char *backend, const char *mode, const lattice_row *rows,
                      int first)
{
	for (int k = 0; k < N_SIZES; k++) {
		const lattice_row *r = &rows[k];
		fprintf(f,
		        "%s\n  {\"trials_end\": \"%s\", \"backend\": ", first && k == 0 ? "" : ",",
		        mode);
		bsim_json_string(f, backend);
		fprintf(f,
		        ", \"gates\": [%d, %d], \"beams\": %d, \"trials\": %ld, \"steps\": %ld, ",
		        r->n, r->n, r->beams, r->trials, r->steps);
		fputs("\"wall_seconds\": ", f);
		bsim_json_number(f, r->wall);
		fputs(", \"ns_per_step\": ", f);
		bsim_json_number(f, r->ns_per_step);
		fputs(", \"setup_us_per_trial\": ", f);
		bsim_json_number(f, 1e6 * r->setup);
		fputs(", \"ratio_to_1x1\": ", f);
		bsim_json_number(f, r->ratio);
		fputs(", \"active_beams_per_step\": ", f);
		bsim_json_number(f, r->active_mean);
		fputc('}', f);
	}
}

static const char *const mode_names[2] = {"same_trials", "own_field"};

int bench_lattice(const bench_lattice_args *a)
{
	lattice_row rows[2][2][N_SIZES]; /* mode, backend, size */
	const bsim_backend *b[2] = {a->backend, a->vs};
	const bsim_options *o[2] = {a->opts, a->vs_opts};
	long trials[2] = {a->trials > 0 ? a->trials : 200, a->vs_trials > 0 ? a->vs_trials : 10};
	static const char *const titles[2] = {
	        "same trials: every field ends a trial where the 1 x 1 field does (the body leaves "
	        "gate (0, 0))",
	        "own field: each field's own end and sides; the body goes as far as it gets"};
	FILE *out = a->report ? a->report : stdout;
	fprintf(out,
	        "the essay's lattice, n x n gates of k = 400 N m/rad, F_prop = 6 N, Rm = 30 N,\n"
	        "the same schedules (seed 1) at every size, one thread\n");
	for (int m = 0; m < 2; m++) {
		fprintf(out, "\n%s\n\n%-8s %11s %6s %7s %11s %9s %9s %8s %11s %11s\n", titles[m],
		        "backend", "gates", "beams", "trials", "steps", "wall s", "ns/step",
		        "x 1x1", "setup us", "awake/step");
		for (int k = 0; k < 2; k++) {
			if (!b[k])
				continue;
			/* the slower --vs backend is timed once: its growth is far
			 * beyond the noise */
			for (int round = 0; round < (k == 0 ? ROUNDS : 1); round++)
				for (int i = 0; i < N_SIZES; i++) {
					int rc = bench_one(b[k], o[k], sizes[i], trials[k], m == 0,
					                   round, &rows[m][k][i]);
					if (rc != CLI_OK)
						return rc;
				}
			for (int i = 0; i < N_SIZES; i++) {
				lattice_row *r = &rows[m][k][i];
				r->ratio = r->ns_per_step / rows[m][k][0].ns_per_step;
				print_row(out, b[k]->name, r);
			}
		}
	}
	fprintf(out, "\ncost per step at 33 x 33 against 1 x 1:");
	for (int k = 0; k < 2; k++)
		if (b[k])
			fprintf(out, " %s %.2f x (same trials), %.2f x (own field);", b[k]->name,
			        rows[0][k][N_SIZES - 1].ratio, rows[1][k][N_SIZES - 1].ratio);
	fprintf(out, "\n");
	double ns_long[N_SIZES];
	int rc = bench_long(out, b[0], o[0], trials[0], ns_long);
	if (rc != CLI_OK)
		return rc;
	fprintf(out,
	        "\ncost per step, setup included, %d-step trials, 33 x 33 against 5 x 5: %s %.2f "
	        "x\n",
	        LONG_STEPS, b[0]->name, ns_long[N_SIZES - 1] / ns_long[2]);
	if (!a->json)
		return CLI_OK;
	bsim_atomic_file jf;
	bsim_error err;
	if (bsim_atomic_file_open(&jf, a->json, &err) != BSIM_OK)
		return cli_report(BSIM_EFAIL, &err);
	fputs("{\"lattice\": [", jf.f);
	int first = 1;
	for (int m = 0; m < 2; m++)
		for (int k = 0; k < 2; k++)
			if (b[k]) {
				json_rows(jf.f, b[k]->name, mode_names[m], rows[m][k], first);
				first = 0;
			}
	fputs("\n], \"long_trials\": [", jf.f);
	for (int i = 0; i < N_SIZES; i++) {
		fprintf(jf.f, "%s\n  {\"backend\": ", i ? "," : "");
		bsim_json_string(jf.f, b[0]->name);
		fprintf(jf.f, ", \"gates\": [%d, %d], \"steps_per_trial\": %d, \"ns_per_step\": ",
		        sizes[i], sizes[i], LONG_STEPS);
		bsim_json_number(jf.f, ns_long[i]);
		fputs(", \"ratio_to_5x5\": ", jf.f);
		bsim_json_number(jf.f, ns_long[i] / ns_long[2]);
		fputc('}', jf.f);
	}
	fputs("\n]}\n", jf.f);
	return cli_report(bsim_atomic_file_commit(&jf, &err), &err);
}
