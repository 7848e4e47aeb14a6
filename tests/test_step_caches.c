/* What the thesis step keeps from one step to the next only saves work: a
 * world that has stepped a whole trial (its beams' geometry against the
 * body, the distance bound that skips far beams, the beam constants for the
 * step size, the random force's held value) steps exactly as a world
 * created afresh from the same state, which has none of them. Also the
 * inlined fmax/fmin against the C library's, and the schedule's held value
 * against its definition, value(index(n)). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "beamsim/backend.h"
#include "beamsim/effects.h"
#include "beamsim/schedule.h"
#include "fminmax.h"
#include "support.h"

static void test_fminmax_as_libm(void **state)
{
	(void)state;
	const double v[] = {0.0, -0.0, 1.0, -1.0, NAN, -NAN, INFINITY, -INFINITY, 1e-310, 3.5};
	const int n = (int)(sizeof v / sizeof v[0]);
	/* volatile: the library's functions are called, not folded */
	double (*volatile lib_max)(double, double) = fmax;
	double (*volatile lib_min)(double, double) = fmin;
	for (int i = 0; i < n; i++)
		for (int j = 0; j < n; j++) {
			double a = lib_max(v[i], v[j]), b = bsim_fmax(v[i], v[j]);
			double c = lib_min(v[i], v[j]), d = bsim_fmin(v[i], v[j]);
			assert_memory_equal(&a, &b, sizeof a);
			assert_memory_equal(&c, &d, sizeof c);
		}
}

/* The held value read at step n is value(index(n)), for steps that divide
 * the hold (50 Hz at 4 ms: 5 steps) and steps that do not (50 Hz at 3 ms),
 * read in order, backwards and at random. */
static void test_schedule_held_value(void **state)
{
	(void)state;
	const double hs[] = {0.004, 0.003};
	for (int k = 0; k < 2; k++) {
		bsim_schedule *held = bsim_schedule_alloc(20.0, 50.0, 7);
		bsim_schedule *ref = bsim_schedule_alloc(20.0, 50.0, 7);
		assert_non_null(held);
		assert_non_null(ref);
		double h = hs[k];
		long order[3000];
		for (long n = 0; n < 1000; n++) {
			order[n] = n;
			order[1000 + n] = 999 - n;
			order[2000 + n] = (n * 7919) % 1000;
		}
		for (int m = 0; m < 3000; m++) {
			long n = order[m];
			double a = bsim_schedule_at_step(held, n, h);
			double b = bsim_schedule_value(ref, bsim_schedule_index(ref, n, h));
			assert_memory_equal(&a, &b, sizeof a);
		}
		bsim_schedule_free(held);
		bsim_schedule_free(ref);
	}
}

static void assert_same_step(const bsim_state *a, const bsim_state *b)
{
	assert_memory_equal(a->x, b->x, sizeof a->x);
	assert_memory_equal(a->v, b->v, sizeof a->v);
	assert_memory_equal(a->theta, b->theta, (size_t)a->n_beams * sizeof *a->theta);
	assert_memory_equal(a->omega, b->omega, (size_t)a->n_beams * sizeof *a->omega);
	assert_memory_equal(a->contact, b->contact, (size_t)a->n_beams * sizeof *a->contact);
	assert_memory_equal(&a->energy, &b->energy, sizeof a->energy);
	assert_int_equal(a->impacts, b->impacts);
}

/* Steps world A through n_steps of the scene; before each step a world B is
 * created from A's state, and both take the step: B's (nothing kept) must
 * equal A's to the bit. Returns the steps in which the body touched. */
static int step_against_fresh(const bsim_scene *sc, uint64_t seed, int n_steps)
{
	const bsim_backend *be = &bsim_backend_thesis;
	bsim_error err;
	bsim_world *a = NULL;
	assert_int_equal(be->create(sc, NULL, &a, &err), BSIM_OK);
	bsim_effects fx;
	assert_int_equal(bsim_effects_init(&fx, sc, seed), BSIM_OK);
	bsim_state sa, sb;
	assert_int_equal(bsim_state_init(&sa, sc->n_beams), BSIM_OK);
	assert_int_equal(bsim_state_init(&sb, sc->n_beams), BSIM_OK);
	int touching = 0;
	for (int n = 0; n < n_steps; n++) {
		double f[2];
		bsim_effects_force(&fx, n, sc->dt, f);
		be->get_state(a, &sa);
		bsim_world *b = NULL;
		assert_int_equal(be->create(sc, NULL, &b, &err), BSIM_OK);
		assert_int_equal(be->set_state(b, &sa, &err), BSIM_OK);
		assert_int_equal(be->step(a, f, sc->dt, &err), BSIM_OK);
		assert_int_equal(be->step(b, f, sc->dt, &err), BSIM_OK);
		be->get_state(a, &sa);
		be->get_state(b, &sb);
		assert_same_step(&sa, &sb);
		be->destroy(b);
		for (int k = 0; k < sa.n_active; k++)
			if (sa.contact[sa.active[k]]) {
				touching++;
				break;
			}
	}
	bsim_state_free(&sa);
	bsim_state_free(&sb);
	bsim_effects_free(&fx);
	be->destroy(a);
	return touching;
}

/* The essay's gate: the body swings the beams, touches both, and in some
 * trials gets through (F = 9 N) or stays pressed (F = 6 N). */
static void test_gate_as_fresh(void **state)
{
	(void)state;
	const double forces[] = {6.0, 9.0};
	for (int k = 0; k < 2; k++) {
		bsim_scene s;
		bsim_scene_init_gate(&s, forces[k], 30.0);
		int touching = step_against_fresh(&s, 11 + (uint64_t)k, 2000);
		assert_true(touching > 100); /* the caches were used in contact */
		bsim_scene_free(&s);
	}
}

/* A lattice: the grid's broad phase and sleeping beams besides. */
static void test_lattice_as_fresh(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_error err;
	if (bsim_scene_load(bsim_test_src("configs/lattice/uniform_9x9.yaml"), NULL, 0, &s, &err))
		fail_msg("%s", err.msg);
	assert_true(step_against_fresh(&s, 3, 3000) > 100);
	bsim_scene_free(&s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_fminmax_as_libm),
	        cmocka_unit_test(test_schedule_held_value),
	        cmocka_unit_test(test_gate_as_fresh),
	        cmocka_unit_test(test_lattice_as_fresh),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
