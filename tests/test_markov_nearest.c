/* Nearest-neighbour walks (beamsim/markov_nearest.h) against independent
 * truths:
 *   - on hand-made visits whose kernel is exact (k every visit of a pool),
 *     the walks' final locations and gates visited are the hand-solved
 *     products of the visits' shares, within the walks' sampling error:
 *     the walk follows an exit into the gate above, to the end and out a
 *     side as the chain's geometry says;
 *   - with k = 1 a walk takes the visit nearest its entry state;
 *   - a walk that never leaves the field is a failure said, not a result;
 *   - on a field of two gate kinds under the essay's protocol the walks
 *     over training fields' visits agree with direct simulation of the
 *     field within the sampling errors of both;
 *   - the visits are the same with 1 and 2 threads, read back from their
 *     directory as they were run, and run again when the physics changes;
 *     the walks are the same on any number of threads and change with the
 *     seed; a build stopped keeps the training fields it finished;
 *   - a malformed visits file, visits of other kinds and bad options are
 *     input errors naming what is wrong (exit 2 from the program). */
#define _POSIX_C_SOURCE 200809L

#include <glob.h>
#include <math.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "beamsim/lattice.h"
#include "beamsim/lattice_outcome.h"
#include "beamsim/markov.h"
#include "beamsim/markov_nearest.h"
#include "beamsim/schedule.h"
#include "beamsim/trial.h"
#include "support.h"

static double p_of(const bsim_markov_prediction *p, bsim_location_kind kind, int ix, int iy)
{
	for (int i = 0; i < p->n_locations; i++)
		if (p->loc[i].kind == kind && p->loc[i].ix == ix && p->loc[i].iy == iy)
			return p->p[i];
	fail_msg("no location %d %d %d", kind, ix, iy);
	return NAN;
}

/* Whether the walks' p is q within 5 of their standard errors. */
static void walks_near(double p, double q, long walks, int line)
{
	const double se = sqrt(q * (1.0 - q) / (double)walks) + 1e-12;
	if (!(fabs(p - q) <= 5.0 * se))
		fail_msg("line %d: %.6f is not %.6f within 5 standard errors (%.6f)", line, p, q,
		         se);
}
#define assert_walks_near(p, q, w) walks_near((p), (q), (w), __LINE__)

/* A column of `rows` gates of one kind (the scene's own stiffness). */
static void column(bsim_scene *s, int rows)
{
	assert_int_equal(bsim_lattice_scene_init(s, 1, rows, 6, 30), BSIM_OK);
	s->lattice.protocol = BSIM_PROTOCOL_ESSAY;
}

static bsim_markov_visit visit(const bsim_scene *s, int edge, double pos, int exit_edge,
                               double exit_pos)
{
	bsim_markov_visit v = {.edge = edge,
	                       .pos = pos,
	                       .exit_edge = exit_edge,
	                       .exit_pos = exit_pos,
	                       .steps = 10};
	v.k[0] = s->beams[0].stiffness;
	v.k[1] = s->beams[1].stiffness;
	v.v[1] = edge == BSIM_EDGE_START ? 0.0 : 20.0; /* in through the bottom, straight up */
	v.exit_v[1] = 20.0;
	if (exit_edge == BSIM_EDGE_LEFT) { /* into the gate on the right */
		v.exit_v[0] = 20.0;
		v.exit_v[1] = 0.0;
	}
	return v;
}

/* A column of three gates, one kind. Start visits: a quarter stuck, a
 * half up, a quarter out to the right (a side: one column); the bottom's:
 * half stuck, half up. With k = 2 (every bottom visit) each step is a fair
 * draw, so stuck (0, 0) 1/4, side 0 1/4, stuck (0, 1) 1/4, stuck (0, 2)
 * 1/8 and the end 1/8; gates visited 1: 1/2, 2: 1/4, 3: 1/4. */
static void test_walks_by_hand(void **state)
{
	(void)state;
	bsim_scene s;
	column(&s, 3);
	bsim_markov_visit v[6] = {
	        visit(&s, BSIM_EDGE_START, 0, 0, 0),
	        visit(&s, BSIM_EDGE_START, 0, BSIM_EDGE_BOTTOM, -1.0),
	        visit(&s, BSIM_EDGE_START, 0, BSIM_EDGE_BOTTOM, 1.0),
	        visit(&s, BSIM_EDGE_START, 0, BSIM_EDGE_LEFT, 5.0),
	        visit(&s, BSIM_EDGE_BOTTOM, -2.0, 0, 0),
	        visit(&s, BSIM_EDGE_BOTTOM, 2.0, BSIM_EDGE_BOTTOM, 0.0),
	};
	const bsim_markov_visits vs = {.n = 6, .v = v, .fields = 1};
	bsim_markov_nearest_def def = bsim_markov_nearest_def_default();
	def.k = 2;
	def.walks = 400000;
	bsim_markov_prediction p;
	bsim_error err;
	assert_int_equal(bsim_markov_nearest_predict(&s, &vs, &def, &p, &err), BSIM_OK);
	const long W = def.walks;
	assert_walks_near(p_of(&p, BSIM_LOCATION_STUCK, 0, 0), 0.25, W);
	assert_walks_near(p_of(&p, BSIM_LOCATION_SIDE, 0, 0), 0.25, W);
	assert_walks_near(p_of(&p, BSIM_LOCATION_STUCK, 0, 1), 0.25, W);
	assert_walks_near(p_of(&p, BSIM_LOCATION_STUCK, 0, 2), 0.125, W);
	assert_walks_near(p_of(&p, BSIM_LOCATION_END, 0, 0), 0.125, W);
	assert_int_equal(p.n_gates, 3);
	assert_walks_near(p.p_gates[1], 0.5, W);
	assert_walks_near(p.p_gates[2], 0.25, W);
	assert_walks_near(p.p_gates[3], 0.25, W);
	double sum = 0.0;
	for (int i = 0; i < p.n_locations; i++)
		sum += p.p[i];
	assert_true(fabs(sum - 1.0) < 1e-12);
	assert_int_equal(p.nearest_walks, W);
	assert_int_equal(p.n_states, 6);
	bsim_markov_prediction_free(&p);
	bsim_scene_free(&s);
}

/* k = 1: the visit nearest the entry state. The start leaves into the
 * gate above at the bottom edge's left end or its right end (two scenes);
 * of the bottom's two visits, the one entered at the left end is stuck,
 * the other goes on up. Entered at the left: all stuck in (0, 1); at the
 * right: all reach the end. */
static void test_nearest_visit(void **state)
{
	(void)state;
	bsim_scene s;
	column(&s, 2);
	const double w2 = 0.5 * s.lattice.width;
	for (int right = 0; right < 2; right++) {
		bsim_markov_visit v[3] = {
		        visit(&s, BSIM_EDGE_START, 0, BSIM_EDGE_BOTTOM,
		              right ? 0.9 * w2 : -0.9 * w2),
		        visit(&s, BSIM_EDGE_BOTTOM, -0.8 * w2, 0, 0),
		        visit(&s, BSIM_EDGE_BOTTOM, 0.8 * w2, BSIM_EDGE_BOTTOM, 0.0),
		};
		const bsim_markov_visits vs = {.n = 3, .v = v, .fields = 1};
		bsim_markov_nearest_def def = bsim_markov_nearest_def_default();
		def.k = 1;
		def.walks = 1000;
		bsim_markov_prediction p;
		bsim_error err;
		assert_int_equal(bsim_markov_nearest_predict(&s, &vs, &def, &p, &err), BSIM_OK);
		assert_true(p_of(&p, BSIM_LOCATION_STUCK, 0, 1) == (right ? 0.0 : 1.0));
		assert_true(p_of(&p, BSIM_LOCATION_END, 0, 0) == (right ? 1.0 : 0.0));
		bsim_markov_prediction_free(&p);
	}
	bsim_scene_free(&s);
}

/* Visits that pass the body up and down between two gates for ever (row
 * 0 left downwards is row 0 entered again through its bottom): the walks
 * never end, and the prediction fails saying so. A pool a walk enters
 * without visits is an input error naming the kind and the edge. */
static void test_walks_that_never_end_said(void **state)
{
	(void)state;
	bsim_scene s;
	column(&s, 2);
	bsim_markov_visit v[2] = {
	        visit(&s, BSIM_EDGE_START, 0, BSIM_EDGE_BOTTOM, 0.0),
	        visit(&s, BSIM_EDGE_BOTTOM, 0.0, BSIM_EDGE_TOP, 0.0),
	};
	v[1].exit_v[1] = -20.0;
	bsim_markov_visits vs = {.n = 2, .v = v, .fields = 1};
	bsim_markov_nearest_def def = bsim_markov_nearest_def_default();
	def.walks = 10;
	bsim_markov_prediction p;
	bsim_error err;
	/* the top of (0, 0) entered from (0, 1) has no visit */
	assert_int_equal(bsim_markov_nearest_predict(&s, &vs, &def, &p, &err), BSIM_EINPUT);
	assert_non_null(strstr(err.msg, "entered through its top edge"));
	bsim_markov_visit both[3] = {v[0], v[1], v[1]};
	both[2].edge = BSIM_EDGE_TOP;
	vs = (bsim_markov_visits){.n = 3, .v = both, .fields = 1};
	assert_int_equal(bsim_markov_nearest_predict(&s, &vs, &def, &p, &err), BSIM_EFAIL);
	assert_non_null(strstr(err.msg, "10 of 10 walks still in the field after 10000 gates"));
	assert_null(p.p);
	bsim_scene_free(&s);
}

static void ring(bsim_scene *s)
{
	bsim_error err;
	assert_int_equal(bsim_scene_load(bsim_test_src("configs/markov/kinds/field_ring5.yaml"),
	                                 NULL, 0, s, &err),
	                 BSIM_OK);
	s->lattice.protocol = BSIM_PROTOCOL_ESSAY;
}

/* A ring of one kind around 3 x 3 of another (5 x 5) under the essay's
 * protocol: the walks over the visits of two training fields of 600
 * trials each against 1,500 direct trials, every location within 4.5
 * standard errors of both samples. */
static void test_walks_against_simulation(void **state)
{
	(void)state;
	bsim_scene s;
	ring(&s);
	bsim_markov_nearest_def def = bsim_markov_nearest_def_default();
	def.trials = 600;
	def.walks = 20000;
	bsim_markov_visits vs;
	bsim_error err;
	assert_int_equal(bsim_markov_visits_build(&s, &def, bsim_test_dir("against"), &vs, &err),
	                 BSIM_OK);
	assert_int_equal(vs.fields, 2);
	assert_int_equal(vs.built, 2);
	assert_true(vs.cost > 0 && vs.steps > 0 && vs.left_out > 0);
	bsim_markov_prediction p;
	assert_int_equal(bsim_markov_nearest_predict(&s, &vs, &def, &p, &err), BSIM_OK);
	const int N = 1500;
	double *sim = calloc((size_t)p.n_locations, sizeof *sim);
	bsim_test_simulate_locations(&s, p.loc, p.n_locations, N, 77, sim);
	int seen = 0;
	double worst = 0.0;
	for (int i = 0; i < p.n_locations; i++) {
		const double q = fmax(fmax(sim[i], p.p[i]), 1.0 / N);
		const double se = sqrt(q * (1.0 - q) * (1.0 / N + 1.0 / def.walks));
		worst = fmax(worst, fabs(sim[i] - p.p[i]) / se);
		if (!(fabs(sim[i] - p.p[i]) <= 4.5 * se))
			fail_msg("location %d (%d, %d, %d): walks %.4f, simulation %.4f (se %.4f)",
			         i, p.loc[i].kind, p.loc[i].ix, p.loc[i].iy, p.p[i], sim[i], se);
		seen += sim[i] > 0;
	}
	print_message("largest difference: %.2f standard errors\n", worst);
	assert_true(seen > 5);
	free(sim);
	bsim_markov_prediction_free(&p);
	bsim_markov_visits_free(&vs);
	bsim_scene_free(&s);
}

static int files_matching(const char *dir, const char *pattern)
{
	glob_t g;
	const int rc = glob(bsim_test_join(dir, pattern), 0, NULL, &g);
	const int n = rc == 0 ? (int)g.gl_pathc : 0;
	globfree(&g);
	return n;
}

static int visits_same(const bsim_markov_visits *a, const bsim_markov_visits *b)
{
	if (a->n != b->n)
		return 0;
	for (long i = 0; i < a->n; i++) {
		const bsim_markov_visit *x = &a->v[i], *y = &b->v[i];
		if (memcmp(x->k, y->k, sizeof x->k) || x->edge != y->edge || x->pos != y->pos ||
		    memcmp(x->v, y->v, sizeof x->v) || x->exit_edge != y->exit_edge ||
		    x->exit_pos != y->exit_pos || memcmp(x->exit_v, y->exit_v, sizeof x->v) ||
		    x->steps != y->steps)
			return 0;
	}
	return 1;
}

/* The visits on 1 and 2 threads, and read back: the same; another physics
 * runs its own fields beside them. The walks on 1 and 2 threads: the same;
 * another seed: not. */
static void test_threads_cache_and_seed(void **state)
{
	(void)state;
	bsim_scene s;
	ring(&s);
	char one[1100], two[1100];
	snprintf(one, sizeof one, "%s", bsim_test_dir_held("threads1"));
	snprintf(two, sizeof two, "%s", bsim_test_dir_held("threads2"));
	bsim_markov_nearest_def def = bsim_markov_nearest_def_default();
	def.trials = 80;
	def.walks = 3000;
	bsim_markov_visits a, b, c;
	bsim_error err;
	def.threads = 1;
	assert_int_equal(bsim_markov_visits_build(&s, &def, one, &a, &err), BSIM_OK);
	def.threads = 2;
	assert_int_equal(bsim_markov_visits_build(&s, &def, two, &b, &err), BSIM_OK);
	assert_true(visits_same(&a, &b));
	assert_int_equal(b.built, 2);
	assert_int_equal(files_matching(two, "visits_*.key"), 2);
	/* read back: nothing run */
	assert_int_equal(bsim_markov_visits_build(&s, &def, two, &c, &err), BSIM_OK);
	assert_int_equal(c.built, 0);
	assert_int_equal(c.reused, 2);
	assert_true(visits_same(&a, &c));
	assert_true(c.cost == b.cost || fabs(c.cost - b.cost) < 1e-5 * b.cost);
	assert_int_equal(c.left_out, b.left_out);
	bsim_markov_visits_free(&c);
	/* the walks */
	bsim_markov_prediction p1, p2, p3;
	def.threads = 1;
	assert_int_equal(bsim_markov_nearest_predict(&s, &a, &def, &p1, &err), BSIM_OK);
	def.threads = 2;
	assert_int_equal(bsim_markov_nearest_predict(&s, &a, &def, &p2, &err), BSIM_OK);
	assert_memory_equal(p1.p, p2.p, (size_t)p1.n_locations * sizeof *p1.p);
	def.seed = 2;
	assert_int_equal(bsim_markov_nearest_predict(&s, &a, &def, &p3, &err), BSIM_OK);
	assert_memory_not_equal(p1.p, p3.p, (size_t)p1.n_locations * sizeof *p1.p);
	bsim_markov_prediction_free(&p1);
	bsim_markov_prediction_free(&p2);
	bsim_markov_prediction_free(&p3);
	/* another physics: its own fields, the first ones kept */
	s.effects.random_magnitude += 1.0;
	def.seed = 1;
	assert_int_equal(bsim_markov_visits_build(&s, &def, two, &c, &err), BSIM_OK);
	assert_int_equal(c.built, 2);
	assert_int_equal(files_matching(two, "visits_*.key"), 4);
	bsim_markov_visits_free(&c);
	bsim_markov_visits_free(&a);
	bsim_markov_visits_free(&b);
	bsim_scene_free(&s);
}

/* A progress callback that stops the build as the second training field
 * starts: its first count after the first field's last (one thread: the
 * counts in order). */
typedef struct stopper {
	volatile sig_atomic_t stop;
	int first_done;
} stopper;

static void stop_at_second_field(void *user, long done, long total)
{
	stopper *st = user;
	if (st->first_done)
		st->stop = 1;
	if (done == total)
		st->first_done = 1;
}

/* A build stopped in its second training field keeps the first, whole,
 * and writes nothing of the second; run again it runs the second alone,
 * and the visits are those of a build never stopped. */
static void test_stopped_keeps_fields(void **state)
{
	(void)state;
	bsim_scene s;
	ring(&s);
	char dir[1100], whole[1100];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir_held("stopped"));
	snprintf(whole, sizeof whole, "%s", bsim_test_dir_held("unstopped"));
	bsim_markov_nearest_def def = bsim_markov_nearest_def_default();
	def.trials = 100;
	def.threads = 1;
	stopper st = {0};
	def.progress = stop_at_second_field;
	def.progress_user = &st;
	def.stop = &st.stop;
	bsim_markov_visits a, b;
	bsim_error err;
	assert_int_equal(bsim_markov_visits_build(&s, &def, dir, &a, &err), BSIM_ESTOPPED);
	assert_int_equal(files_matching(dir, "visits_*.key"), 1);
	assert_int_equal(files_matching(dir, "visits_*.csv"), 1);
	def.progress = NULL;
	def.stop = NULL;
	assert_int_equal(bsim_markov_visits_build(&s, &def, dir, &a, &err), BSIM_OK);
	assert_int_equal(a.built, 1);
	assert_int_equal(a.reused, 1);
	assert_int_equal(bsim_markov_visits_build(&s, &def, whole, &b, &err), BSIM_OK);
	assert_true(visits_same(&a, &b));
	bsim_markov_visits_free(&a);
	bsim_markov_visits_free(&b);
	bsim_scene_free(&s);
}

/* Replaces the first `from` in path's text after its header with `to`. */
static void spoil(const char *path, const char *from, const char *to)
{
	char *text = bsim_test_read(path);
	assert_non_null(text);
	char *at = strstr(strchr(text, '\n'), from);
	assert_non_null(at);
	FILE *f = fopen(path, "w");
	assert_non_null(f);
	fprintf(f, "%.*s%s%s", (int)(at - text), text, to, at + strlen(from));
	fclose(f);
	free(text);
}

static void test_bad_inputs(void **state)
{
	(void)state;
	bsim_scene s;
	ring(&s);
	const char *dir = bsim_test_dir("bad");
	char keep[1100];
	snprintf(keep, sizeof keep, "%s", dir);
	bsim_markov_nearest_def def = bsim_markov_nearest_def_default();
	def.trials = 50;
	def.walks = 100;
	bsim_markov_visits vs;
	bsim_error err;
	assert_int_equal(bsim_markov_visits_build(&s, &def, keep, &vs, &err), BSIM_OK);
	bsim_markov_prediction p;
	def.k = 0;
	assert_int_equal(bsim_markov_nearest_predict(&s, &vs, &def, &p, &err), BSIM_EINPUT);
	assert_non_null(strstr(err.msg, "k 0: expected 1 to 64"));
	def.k = 20;
	def.walks = 0;
	assert_int_equal(bsim_markov_nearest_predict(&s, &vs, &def, &p, &err), BSIM_EINPUT);
	def.walks = 100;
	/* visits of other kinds: none of the start gate's */
	bsim_scene other;
	column(&other, 2);
	assert_int_equal(bsim_markov_nearest_predict(&other, &vs, &def, &p, &err), BSIM_EINPUT);
	assert_non_null(strstr(err.msg, "no start visit of the start gate's kind"));
	bsim_markov_visits_free(&vs);
	/* a malformed visits file, by file, line and field */
	char csv[1200];
	snprintf(csv, sizeof csv, "%s", bsim_test_glob_first(bsim_test_join(keep, "visits_*.csv")));
	spoil(csv, ",start,", ",middle,"); /* the first visit, line 2 */
	assert_int_equal(bsim_markov_visits_build(&s, &def, keep, &vs, &err), BSIM_EINPUT);
	assert_non_null(strstr(err.msg, csv));
	assert_non_null(strstr(err.msg, ".csv:2: edge: expected start, bottom, left, right or "
	                                "top, got 'middle'"));
	bsim_scene_free(&other);
	bsim_scene_free(&s);
}

/* The program: --visits predicts and validates, writing the usual files;
 * options that belong to the other method, or none of --map and
 * --visits, are refused with exit 2. */
/* The program refuses argv: exit 2, and says says (a usage error: its
 * line, then the pointer to --help). */
static void refused(const char *const *argv, const char *says)
{
	char *err = NULL;
	const int rc = bsim_test_cli(argv, NULL, &err);
	bsim_test_check_input_error(rc, err, (const char *const[]){says, NULL}, 0);
	free(err);
}

static void test_cli(void **state)
{
	(void)state;
	char ring5[1100], exp[1100], dir[1100], out[1200], val[1200];
	snprintf(ring5, sizeof ring5, "%s", bsim_test_src("configs/markov/kinds/field_ring5.yaml"));
	snprintf(exp, sizeof exp, "%s", bsim_test_src("configs/markov/kinds/exp_ring5.yaml"));
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("cli"));
	snprintf(out, sizeof out, "%s/pred", dir);
	snprintf(val, sizeof val, "%s/val", dir);
	char *o = NULL, *e = NULL;
	const char *predict[] = {"markov",  "predict", ring5,     "--visits", dir,
	                         "--train", "60",      "--walks", "500",      "--out",
	                         out,       "--json",  NULL};
	assert_int_equal(bsim_test_cli(predict, &o, &e), 0);
	assert_non_null(strstr(o, "\"solve\": \"nearest\""));
	assert_non_null(strstr(o, "\"fields_built\": 2"));
	const char *files[] = {"prediction.csv", "prediction_gates.csv", "prediction.png", NULL};
	bsim_test_check_committed(out, files, NULL);
	free(o);
	free(e);
	const char *validate[] = {"markov",  "validate", exp,       "--visits", dir,
	                          "--train", "60",       "--walks", "500",      "--trials",
	                          "40",      "--out",    val,       "--quiet",  NULL};
	assert_int_equal(bsim_test_cli(validate, NULL, NULL), 0);
	char *json = bsim_test_read(bsim_test_join(val, "validate.json"));
	assert_non_null(json);
	assert_non_null(strstr(json, "\"visits_dir\""));
	assert_non_null(strstr(json, "\"nearest_walks\": 500"));
	free(json);
	struct {
		const char *argv[10];
		const char *says;
	} bad[] = {
	        {{"markov", "predict", ring5, NULL}, "expected one of --map DIR and --visits DIR"},
	        {{"markov", "predict", ring5, "--map", dir, "--visits", dir, NULL},
	         "expected one of --map DIR and --visits DIR"},
	        {{"markov", "predict", ring5, "--map", dir, "--train", "5", NULL},
	         "--train is for --visits"},
	        {{"markov", "predict", ring5, "--visits", dir, "--k", "65", NULL},
	         "--k 65: expected an integer 1 to 64"},
	        {{"markov", "predict", ring5, "--visits", dir, "--tol", "0.01", NULL},
	         "--tol, --gates and --no-gates are for maps"},
	        {{"markov", "validate", exp, "--map", dir, "--k", "3", "--out", val, NULL},
	         "--k is for --visits"},
	        {{"markov", "validate", exp, "--out", val, NULL},
	         "expected one of --map DIR and --visits DIR"},
	};
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
		refused(bad[i].argv, bad[i].says);
}

/* markov build's default is the walks: its directory is a build (a
 * manifest, markov.json) that markov predict and validate --map walk
 * over, to the same numbers as the walks over a cache of the same
 * settings; another layout of the same kinds needs no new field, another
 * physics is refused naming what differs; the maps are --method maps, or
 * implied by an option only they have. */
static void test_default_build(void **state)
{
	(void)state;
	char ring5[1100], cols9[1100], exp[1100], dir[1100], built[1200], cache[1200];
	snprintf(ring5, sizeof ring5, "%s", bsim_test_src("configs/markov/kinds/field_ring5.yaml"));
	snprintf(cols9, sizeof cols9, "%s",
	         bsim_test_src("configs/markov/kinds/field_late_cols9.yaml"));
	snprintf(exp, sizeof exp, "%s", bsim_test_src("configs/markov/kinds/exp_ring5.yaml"));
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("default_build"));
	snprintf(built, sizeof built, "%s/built", dir);
	snprintf(cache, sizeof cache, "%s/cache", dir);
	const char *build[] = {"markov", "build", exp,       "--train", "60",
	                       "--out",  built,   "--quiet", NULL};
	assert_int_equal(bsim_test_cli(build, NULL, NULL), 0);
	char *json = bsim_test_read(bsim_test_join(built, "markov.json"));
	assert_non_null(json);
	assert_non_null(strstr(json, "\"method\": \"nearest\""));
	assert_non_null(strstr(json, "\"train\": 60"));
	free(json);
	char *manifest = bsim_test_read(bsim_test_join(built, "manifest.json"));
	assert_non_null(manifest);
	assert_non_null(strstr(manifest, "visits_"));
	free(manifest);
	/* the same walks over the build and over a cache of its settings */
	for (int f = 0; f < 2; f++) {
		const char *scene = f ? cols9 : ring5;
		char *a = NULL, *b = NULL;
		const char *over_build[] = {"markov",  "predict", scene,    "--map", built,
		                            "--walks", "2000",    "--json", NULL};
		const char *over_cache[] = {"markov", "predict", scene, "--visits",
		                            cache,    "--train", "60",  "--walks",
		                            "2000",   "--json",  NULL};
		assert_int_equal(bsim_test_cli(over_build, &a, NULL), 0);
		assert_int_equal(bsim_test_cli(over_cache, &b, NULL), 0);
		/* no field run for the build's prediction, another layout too */
		assert_non_null(strstr(a, "\"fields_built\": 0"));
		const char *la = strstr(a, "\"locations\""), *lb = strstr(b, "\"locations\"");
		assert_non_null(la);
		assert_non_null(lb);
		assert_string_equal(la, lb);
		free(a);
		free(b);
	}
	char val[1300];
	snprintf(val, sizeof val, "%s/val", dir);
	const char *validate[] = {"markov",  "validate", exp,        "--map", built,
	                          "--walks", "500",      "--trials", "40",    "--out",
	                          val,       "--quiet",  NULL};
	assert_int_equal(bsim_test_cli(validate, NULL, NULL), 0);
	json = bsim_test_read(bsim_test_join(val, "validate.json"));
	assert_non_null(json);
	assert_non_null(strstr(json, "\"map_dir\""));
	assert_non_null(strstr(json, "\"method\": \"nearest\""));
	assert_non_null(strstr(json, "\"train_trials\": 60"));
	free(json);
	/* the maps: --method maps, or implied by --bins */
	char maps[1300];
	snprintf(maps, sizeof maps, "%s/maps", dir);
	const char *build_maps[] = {
	        "markov", "build",   exp, "--bins", "1,1,1", "--trials", "2", "--start-trials",
	        "20",     "--train", "0", "--out",  maps,    "--quiet",  NULL};
	assert_int_equal(bsim_test_cli(build_maps, NULL, NULL), 0);
	json = bsim_test_read(bsim_test_join(maps, "markov.json"));
	assert_non_null(json);
	assert_null(strstr(json, "nearest"));
	assert_non_null(strstr(json, "\"bins\""));
	free(json);
	char *o = NULL;
	const char *predict_maps[] = {"markov", "predict", ring5, "--map", maps, "--json", NULL};
	assert_int_equal(bsim_test_cli(predict_maps, &o, NULL), 0);
	assert_null(strstr(o, "\"solve\": \"nearest\""));
	free(o);
	struct {
		const char *argv[12];
		const char *says;
	} bad[] = {
	        {{"markov", "predict", ring5, "--map", built, "--set", "effects.propulsion.force=8",
	          NULL},
	         "where this one needs 'effects propulsion 1 8"},
	        {{"markov", "build", exp, "--method", "nearest", "--bins", "2,2,2", "--out", dir,
	          NULL},
	         "--bins is for method maps"},
	        {{"markov", "build", exp, "--method", "maps", "--k", "3", "--out", dir, NULL},
	         "--k is for the nearest-neighbour walks"},
	        {{"markov", "build", exp, "--method", "bins", "--out", dir, NULL},
	         "method bins: expected nearest or maps"},
	        {{"markov", "predict", ring5, "--map", built, "--tol", "0.01", NULL},
	         "--tol, --gates and --no-gates are for maps"},
	        {{"markov", "predict", ring5, "--map", maps, "--threads", "2", NULL},
	         "--threads is for the walks"},
	        {{"markov", "validate", exp, "--map", maps, "--walks", "9", "--out", val, NULL},
	         "--walks is for the walks"},
	};
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
		refused(bad[i].argv, bad[i].says);
}

int main(int argc, char **argv)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_walks_by_hand),
	        cmocka_unit_test(test_nearest_visit),
	        cmocka_unit_test(test_walks_that_never_end_said),
	        cmocka_unit_test(test_walks_against_simulation),
	        cmocka_unit_test(test_threads_cache_and_seed),
	        cmocka_unit_test(test_stopped_keeps_fields),
	        cmocka_unit_test(test_bad_inputs),
	        cmocka_unit_test(test_cli),
	        cmocka_unit_test(test_default_build),
	};
	if (argc > 1) /* one test by name, e.g. test_cli */
		cmocka_set_test_filter(argv[1]);
	return cmocka_run_group_tests(tests, NULL, NULL);
}
