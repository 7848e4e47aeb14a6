/* The beamsim program as a user meets it (docs/files.md "Command line",
 * "Outputs of `sweep --out DIR`"): help, version, exit statuses, run,
 * sweep, backends. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <dirent.h>

#include <cmocka.h>

#include "beamsim/version.h"
#include "support.h"

/* trials.csv: the contract's first eleven columns, then the appended ones
 * (the ledger, the overlap, the lattice's final gate, location and path,
 * the solver's counts, the exit time, the body's turn, the group's grid
 * values by key). */
#define TRIALS_HEADER                                                                              \
	"group,trial,outcome,type,steps,t_end,x_end,y_end,vx_end,max_theta1,max_theta2,"           \
	"e_start,e_end,work_in,losses,residual,overlap_max,final_ix,final_iy,location,path,"       \
	"iteration_limits,clamps,t_exit,heading_end,angular_velocity_end,turn_end,turn_max,"       \
	"effects.propulsion.force,effects.random_force.magnitude\n"
#define TRAJ_HEADER                                                                                \
	"t,x,y,vx,vy,theta1,omega1,theta2,omega2,f_rand,contact1,contact2,e_kin,e_beam,e_prop\n"

/* Runs the program; keeps stdout and stderr for the checks. */
typedef struct cli_run {
	int status;
	char *out, *err;
} cli_run;

static cli_run run_cli(const char *const argv[])
{
	cli_run r;
	r.status = bsim_test_cli(argv, &r.out, &r.err);
	assert_non_null(r.out);
	assert_non_null(r.err);
	return r;
}

static void cli_run_free(cli_run *r)
{
	free(r->out);
	free(r->err);
}

static void assert_contains(const char *text, const char *part)
{
	if (!strstr(text, part))
		fail_msg("expected \"%s\" in:\n%s", part, text);
}

static char gate[1024];

static int setup(void **state)
{
	(void)state;
	snprintf(gate, sizeof gate, "%s", bsim_test_src("configs/thesis/gate.yaml"));
	return 0;
}

/* A small experiment on the essay's gate: 2 x 1 groups of 3 short trials. */
static const char *small_experiment(const char *dir)
{
	char text[2048];
	snprintf(text, sizeof text,
	         "scene: %s\n"
	         "trials: 3\n"
	         "seed: 5\n"
	         "set:\n"
	         "  integration.max_steps: 800\n"
	         "grid:\n"
	         "  effects.propulsion.force: [6, 8]\n"
	         "  effects.random_force.magnitude: [20]\n",
	         gate);
	return bsim_test_write(dir, "small.yaml", text);
}

static void check_help(const char *cmd, const char *const *mentions)
{
	const char *argv[] = {cmd, "--help", NULL};
	cli_run r = run_cli(argv);
	assert_int_equal(r.status, 0);
	for (int i = 0; mentions[i]; i++)
		assert_contains(r.out, mentions[i]);
	cli_run_free(&r);
}

static void test_help(void **state)
{
	(void)state;
	static const char *const top[] = {"run",   "sweep",     "backends", "bench",
	                                  "essay", "--version", NULL};
	static const char *const run[] = {
	        "SCENE", "--backend",    "--backend-opt", "--seed", "--group", "--trial",
	        "--set", "--trajectory", "--stride",      "--json", NULL};
	static const char *const sweep[] = {"EXPERIMENT", "--out",    "--backend", "--backend-opt",
	                                    "--threads",  "--trials", "--seed",    "--set",
	                                    "--quiet",    NULL};
	static const char *const backends[] = {"backends", "--help", NULL};
	static const char *const essay[] = {"--out",  "--trials",  "--mode", "--sensitivity",
	                                    "--seed", "--threads", NULL};
	static const char *const bench[] = {"--backend", "--backend-opt", "--experiment",
	                                    "--trials",  "--no-h2",       "--json",
	                                    NULL};
	const char *argv[] = {"--help", NULL};
	cli_run r = run_cli(argv);
	assert_int_equal(r.status, 0);
	for (int i = 0; top[i]; i++)
		assert_contains(r.out, top[i]);
	cli_run_free(&r);
	check_help("run", run);
	check_help("sweep", sweep);
	check_help("backends", backends);
	check_help("bench", bench);
	check_help("essay", essay);
}

/* beamsim help COMMAND [SUBCOMMAND] prints exactly what COMMAND
 * [SUBCOMMAND] --help prints; an unknown command is a usage error naming
 * the nearest one; the general help points to the guide and the configs. */
static void test_help_command(void **state)
{
	(void)state;
	static const char *const pairs[][5] = {
	        {"help", "sweep", NULL, "sweep", "--help"},
	        {"help", "markov", "build", "markov", "build"},
	};
	for (size_t i = 0; i < sizeof pairs / sizeof pairs[0]; i++) {
		const char *via_help[] = {pairs[i][0], pairs[i][1], pairs[i][2], NULL};
		const char *direct[] = {pairs[i][3], pairs[i][4], pairs[i][2] ? "--help" : NULL,
		                        NULL};
		cli_run a = run_cli(via_help), b = run_cli(direct);
		assert_int_equal(a.status, 0);
		assert_int_equal(b.status, 0);
		assert_string_equal(a.out, b.out);
		assert_contains(a.out, "Usage: beamsim ");
		cli_run_free(&a);
		cli_run_free(&b);
	}
	const char *typo[] = {"help", "swep", NULL};
	cli_run r = run_cli(typo);
	assert_int_equal(r.status, 2);
	assert_contains(r.err, "did you mean 'sweep'");
	cli_run_free(&r);
	const char *top[] = {"help", NULL};
	r = run_cli(top);
	assert_int_equal(r.status, 0);
	assert_contains(r.out, "beamsim help COMMAND");
	assert_contains(r.out, "docs/");
	assert_contains(r.out, "share/beamsim/configs");
	cli_run_free(&r);
}

static void test_version(void **state)
{
	(void)state;
	const char *argv[] = {"--version", NULL};
	cli_run r = run_cli(argv);
	assert_int_equal(r.status, 0);
	/* The first line is the project's version; then what built it: what
	 * each registered backend is built on (the Box2D backend's, the CMake
	 * package the build found), and this compiler. */
	assert_true(strncmp(r.out, "beamsim " BSIM_VERSION "\n",
	                    strlen("beamsim " BSIM_VERSION "\n")) == 0);
	assert_contains(r.out, "\ncommit ");
	for (const bsim_backend *const *b = bsim_backend_list(); *b; b++) {
		char line[256];
		snprintf(line, sizeof line, "\nbackend %s: %s %s\n", (*b)->name, (*b)->engine,
		         (*b)->version);
		assert_contains(r.out, line);
	}
	assert_contains(r.out, ": Box2D " BSIM_TEST_BOX2D_VERSION "\n");
#if defined(__GNUC__) && !defined(__clang__)
	char compiler[64];
	snprintf(compiler, sizeof compiler, "\ncompiler gcc %d.%d.%d\n", __GNUC__, __GNUC_MINOR__,
	         __GNUC_PATCHLEVEL__);
	assert_contains(r.out, compiler);
#endif
	cli_run_free(&r);
}

/* `run --json` prints the one JSON object and nothing else, on every
 * backend of the registry: an engine that writes to stdout itself
 * (Debian's Chipmunk prints a banner at its first space; the chipmunk
 * backend sends it to /dev/null) would put its lines first. */
static void test_run_json_alone(void **state)
{
	(void)state;
	for (const bsim_backend *const *b = bsim_backend_list(); *b; b++) {
		const char *argv[] = {"run", gate, "--backend", (*b)->name, "--json", NULL};
		cli_run r = run_cli(argv);
		assert_int_equal(r.status, 0);
		assert_true(r.out[0] == '{');
		char backend[128];
		snprintf(backend, sizeof backend, "\"backend\": \"%s\"", (*b)->name);
		assert_non_null(strstr(r.out, backend));
		const char *end = strrchr(r.out, '}');
		assert_non_null(end);
		assert_string_equal(end, "}\n");
		assert_null(strstr(r.out, "Chipmunk v"));
		assert_null(strstr(r.err, "Chipmunk v"));
		cli_run_free(&r);
	}
}

static void test_bad_usage(void **state)
{
	(void)state;
	const char *none[] = {NULL};
	const char *unknown[] = {"fly", NULL};
	const char *bad_opt[] = {"run", gate, "--warp", NULL};
	const char *no_value[] = {"run", gate, "--seed", NULL};
	const char *bad_seed[] = {"run", gate, "--seed", "-3", NULL};
	const char *bad_set[] = {"run", gate, "--set", "nokey", NULL};
	const char *no_scene[] = {"run", NULL};
	const char *const *cases[] = {none,     unknown, bad_opt, no_value,
	                              bad_seed, bad_set, no_scene};
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		cli_run r = run_cli(cases[i]);
		assert_int_equal(r.status, 2);
		assert_contains(r.err, "beamsim");
		assert_string_equal(r.out, "");
		cli_run_free(&r);
	}
}

static void test_sweep_needs_out(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("needs_out");
	char exp[1024];
	snprintf(exp, sizeof exp, "%s", small_experiment(dir));
	const char *argv[] = {"sweep", exp, NULL};
	cli_run r = run_cli(argv);
	assert_int_equal(r.status, 2);
	assert_contains(r.err, "--out");
	cli_run_free(&r);
}

static void test_unknown_backend(void **state)
{
	(void)state;
	const char *argv[] = {"run", gate, "--backend", "nosuch", NULL};
	cli_run r = run_cli(argv);
	assert_int_equal(r.status, 2);
	assert_contains(r.err, "nosuch");
	assert_contains(r.err, "thesis");
	cli_run_free(&r);
	const char *opt[] = {"run", gate, "--backend-opt", "nosuch=1", NULL};
	r = run_cli(opt);
	assert_int_equal(r.status, 2);
	assert_contains(r.err, "nosuch");
	cli_run_free(&r);
	/* a knob's value out of its range */
	const char *mass[] = {"run", gate, "--backend-opt", "impact_mass=0", NULL};
	bsim_test_expect_input_error(mass, (const char *const[]){"impact_mass", "> 0", NULL});
}

static void test_bad_scene(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("bad_scene");
	char path[1024];
	snprintf(path, sizeof path, "%s",
	         bsim_test_write(dir, "bad.yaml", "name: bad\nbody: {mass: -1, radius: 10}\n"));
	const char *argv[] = {"run", path, NULL};
	cli_run r = run_cli(argv);
	assert_int_equal(r.status, 2);
	assert_contains(r.err, "bad.yaml");
	assert_contains(r.err, "body.mass");
	cli_run_free(&r);
	const char *missing[] = {"run", "/nonexistent/scene.yaml", NULL};
	r = run_cli(missing);
	assert_int_equal(r.status, 2);
	cli_run_free(&r);
	const char *bad_set[] = {"run", gate, "--set", "body.mass=-1", NULL};
	r = run_cli(bad_set);
	assert_int_equal(r.status, 2);
	assert_contains(r.err, "--set");
	cli_run_free(&r);
}

static long json_long(const char *json, const char *key)
{
	char pat[64];
	snprintf(pat, sizeof pat, "\"%s\": ", key);
	const char *p = strstr(json, pat);
	assert_non_null(p);
	return strtol(p + strlen(pat), NULL, 10);
}

static void test_run(void **state)
{
	(void)state;
	const char *text[] = {"run", gate, NULL};
	cli_run r = run_cli(text);
	assert_int_equal(r.status, 0);
	assert_contains(r.out, "outcome");
	assert_contains(r.out, "residual");
	cli_run_free(&r);

	const char *json[] = {"run", gate, "--json", "--seed", "3", "--trial", "2", NULL};
	r = run_cli(json);
	assert_int_equal(r.status, 0);
	assert_true(r.out[0] == '{');
	assert_contains(r.out, "\"outcome\": \"");
	assert_contains(r.out, "\"ledger\": {");
	assert_true(json_long(r.out, "draws") > 0);
	cli_run_free(&r);

	/* --set reaches the scene: without random force there are no draws. */
	const char *no_rand[] = {"run", gate, "--json", "--set", "effects.random_force.magnitude=0",
	                         NULL};
	r = run_cli(no_rand);
	assert_int_equal(r.status, 0);
	assert_int_equal(json_long(r.out, "draws"), 0);
	cli_run_free(&r);
}

/* No PATH.tmp.PID is left behind in dir. */
static void assert_no_tmp(const char *dir)
{
	DIR *d = opendir(dir);
	assert_non_null(d);
	for (struct dirent *e; (e = readdir(d));)
		if (strstr(e->d_name, ".tmp."))
			fail_msg("left over: %s/%s", dir, e->d_name);
	closedir(d);
}

static void test_trajectory(void **state)
{
	(void)state;
	char dir[1024], path[1100];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("trajectory"));
	snprintf(path, sizeof path, "%s/traj.csv", dir);
	const char *argv[] = {"run", gate, "--json", "--trajectory", path, NULL};
	cli_run r = run_cli(argv);
	assert_int_equal(r.status, 0);
	long steps_run = json_long(r.out, "steps_run");
	cli_run_free(&r);
	char *csv = bsim_test_read(path);
	assert_non_null(csv);
	assert_memory_equal(csv, TRAJ_HEADER, strlen(TRAJ_HEADER));
	/* One row per state: t = 0 and after every step. */
	assert_int_equal(bsim_test_count_lines(csv) - 1, steps_run + 1);
	free(csv);
	assert_no_tmp(dir);

	/* With a stride, every N-th step and the last one. */
	const char *strided[] = {"run", gate, "--trajectory", path, "--stride", "10", NULL};
	r = run_cli(strided);
	assert_int_equal(r.status, 0);
	cli_run_free(&r);
	csv = bsim_test_read(path);
	assert_non_null(csv);
	int rows = bsim_test_count_lines(csv) - 1;
	assert_true(rows >= steps_run / 10 && rows <= steps_run / 10 + 2);
	free(csv);

	/* A trajectory in folders that do not exist yet: created, as --out's. */
	char nested[1200];
	snprintf(nested, sizeof nested, "%s/new/deeper/t.csv", dir);
	const char *in_new[] = {"run", gate, "--trajectory", nested, NULL};
	r = run_cli(in_new);
	assert_int_equal(r.status, 0);
	cli_run_free(&r);
	csv = bsim_test_read(nested);
	assert_non_null(csv);
	assert_int_equal(bsim_test_count_lines(csv) - 1, steps_run + 1);
	free(csv);

	/* run --out DIR lists what it wrote. */
	char out_dir[1100];
	snprintf(out_dir, sizeof out_dir, "%s/run_out", dir);
	const char *run_out[] = {"run", gate, "--out", out_dir, NULL};
	r = run_cli(run_out);
	assert_int_equal(r.status, 0);
	assert_true(bsim_test_check_wrote(r.out, out_dir) >= 4);
	cli_run_free(&r);

	/* A path with no room for FILE.tmp.PID is a usage error, before the run. */
	char long_path[1300];
	memset(long_path, 'a', sizeof long_path - 1);
	long_path[0] = '/';
	long_path[sizeof long_path - 1] = '\0';
	const char *too_long[] = {"run", gate, "--trajectory", long_path, NULL};
	const char *says[] = {"--trajectory /aaa", "path too long (1299 bytes, at most 1199)",
	                      NULL};
	char *err = NULL;
	int rc = bsim_test_cli(too_long, NULL, &err);
	bsim_test_check_input_error(rc, err, says, 0);
	free(err);
}

/* Keys appear in this order in text. */
static void assert_in_order(const char *text, const char *const *keys)
{
	const char *at = text;
	for (int i = 0; keys[i]; i++) {
		const char *p = strstr(at, keys[i]);
		if (!p)
			fail_msg("expected %s after offset %ld in:\n%s", keys[i], (long)(at - text),
			         text);
		at = p + strlen(keys[i]);
	}
}

static void test_sweep(void **state)
{
	(void)state;
	char dir[1024], exp[1100], out[1100], file[1200];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("sweep"));
	snprintf(exp, sizeof exp, "%s", small_experiment(dir));
	snprintf(out, sizeof out, "%s/out/nested", dir);
	const char *argv[] = {"sweep", exp, "--out", out, "--threads", "2", NULL};
	cli_run r = run_cli(argv);
	assert_int_equal(r.status, 0);
	assert_contains(r.out, "effects.propulsion.force");
	assert_contains(r.out, "trials/s");
	/* every file of the manifest on a line of its own */
	assert_true(bsim_test_check_wrote(r.out, out) >= 6);
	cli_run_free(&r);

	snprintf(file, sizeof file, "%s/trials.csv", out);
	char *csv = bsim_test_read(file);
	assert_non_null(csv);
	assert_memory_equal(csv, TRIALS_HEADER, strlen(TRIALS_HEADER));
	assert_int_equal(bsim_test_count_lines(csv), 1 + 2 * 3);
	assert_contains(csv, "\n1,2,");
	assert_contains(csv, ",8,20\n"); /* group 1's values */
	free(csv);

	snprintf(file, sizeof file, "%s/summary.json", out);
	char *json = bsim_test_read(file);
	assert_non_null(json);
	static const char *const top[] = {"\"backend\": \"thesis\"",
	                                  "\"backend_options\": {",
	                                  "\"experiment\": ",
	                                  "\"seed\": 5",
	                                  "\"trials_per_group\": 3",
	                                  "\"wall_seconds\": ",
	                                  "\"groups\": [",
	                                  "\"version\": \"0.1.0\"",
	                                  "\"scene\": ",
	                                  NULL};
	static const char *const group[] = {"{\"params\": {\"effects.propulsion.force\": 6, "
	                                    "\"effects.random_force.magnitude\": 20}",
	                                    "\"trials\": 3",
	                                    "\"traversed\": ",
	                                    "\"side_exit\": ",
	                                    "\"stuck\": ",
	                                    "\"left\": ",
	                                    "\"right\": ",
	                                    "\"p_traverse\": ",
	                                    "\"ci95\": [",
	                                    "\"effects.propulsion.force\": 8",
	                                    NULL};
	assert_in_order(json, top);
	assert_in_order(json, group);
	free(json);
	assert_no_tmp(out);

	/* --quiet prints nothing on success. */
	const char *quiet[] = {"sweep", exp, "--out", out, "--quiet", "--overwrite", NULL};
	r = run_cli(quiet);
	assert_int_equal(r.status, 0);
	assert_string_equal(r.out, "");
	cli_run_free(&r);
}

/* A bad experiment writes nothing, not even the directory. */
/* Per group of trials.csv (read independently of the program's counts):
 * trials, traversed, left, right, side exits, stuck, unstable. */
typedef struct csv_counts {
	int trials, traversed, left, right, side, stuck, unstable;
} csv_counts;

static void count_trials_csv(const char *path, csv_counts *c, int n_groups)
{
	char *csv = bsim_test_read(path);
	assert_non_null(csv);
	memset(c, 0, (size_t)n_groups * sizeof *c);
	char *save = NULL;
	strtok_r(csv, "\n", &save); /* the header */
	for (char *line = strtok_r(NULL, "\n", &save); line; line = strtok_r(NULL, "\n", &save)) {
		int g;
		char outcome[32], type[16];
		assert_int_equal(sscanf(line, "%d,%*d,%31[^,],%15[^,]", &g, outcome, type), 3);
		assert_true(g >= 0 && g < n_groups);
		csv_counts *k = &c[g];
		k->trials++;
		if (strcmp(outcome, "traversed") == 0) {
			k->traversed++;
			k->left += strcmp(type, "left") == 0;
			k->right += strcmp(type, "right") == 0;
		}
		k->side += strcmp(outcome, "side_exit") == 0;
		k->stuck += strcmp(outcome, "stuck") == 0;
		k->unstable += strcmp(outcome, "unstable") == 0;
	}
	free(csv);
}

/* A printed "p [lo, hi]" against k of n and Wilson's interval, to the
 * printed digits. */
static void check_fraction(double p, double lo, double hi, int k, int n, double tol)
{
	double wlo, whi;
	bsim_test_wilson(k, n, &wlo, &whi);
	assert_true(fabs(p - (double)k / n) <= tol);
	assert_true(fabs(lo - wlo) <= tol);
	assert_true(fabs(hi - whi) <= tol);
}

/* An asymmetric gate (beam 1 stiffer): the sweep prints each group's
 * p_traverse and its left/right split, which match the counts of
 * trials.csv and Wilson's interval; a sweep with no traversal on the
 * symmetric gate prints no split. */
static void test_sweep_split(void **state)
{
	(void)state;
	char dir[1024], exp[1100], out[1100], text[2048];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("sweep_split"));
	snprintf(text, sizeof text,
	         "scene: %s\ntrials: 12\nseed: 3\nset:\n  integration.max_steps: 3000\n"
	         "  beams.1.stiffness: 500\n"
	         "grid:\n  effects.propulsion.force: [7, 9]\n"
	         "  effects.random_force.magnitude: [20]\n  beams.0.stiffness: [100, 150]\n",
	         gate);
	snprintf(exp, sizeof exp, "%s", bsim_test_write(dir, "h2.yaml", text));
	snprintf(out, sizeof out, "%s/out", dir);
	const char *argv[] = {"sweep", exp, "--out", out, NULL};
	cli_run r = run_cli(argv);
	assert_int_equal(r.status, 0);
	csv_counts c[4];
	count_trials_csv(bsim_test_join(out, "trials.csv"), c, 4);
	const char *p = strstr(r.out, "left/(left+right)\n");
	assert_non_null(p);
	p = strchr(p, '\n') + 1;
	int typed = 0;
	for (int g = 0; g < 4; g++) {
		double f, rf, k0, pt, lo, hi, pl, llo, lhi;
		int left, right, n;
		n = sscanf(p, "%lf %lf %lf %lf [%lf, %lf] %d %d %lf [%lf, %lf]", &f, &rf, &k0, &pt,
		           &lo, &hi, &left, &right, &pl, &llo, &lhi);
		assert_true(n >= 8);
		/* group g's values: force slowest, stiffness fastest */
		assert_true(f == (g < 2 ? 7 : 9) && rf == 20 && k0 == (g % 2 ? 150 : 100));
		assert_int_equal(c[g].trials, 12);
		check_fraction(pt, lo, hi, c[g].traversed, c[g].trials, 0.0051);
		assert_int_equal(left, c[g].left);
		assert_int_equal(right, c[g].right);
		if (left + right > 0) {
			assert_int_equal(n, 11);
			check_fraction(pl, llo, lhi, left, left + right, 0.0051);
			typed++;
		}
		p = strchr(p, '\n') + 1;
	}
	assert_true(typed > 0);
	cli_run_free(&r);

	/* The symmetric gate with no traversal: nothing to split. */
	const char *none[] = {"sweep", small_experiment(dir),     "--out",       out,
	                      "--set", "integration.max_steps=5", "--overwrite", NULL};
	r = run_cli(none);
	assert_int_equal(r.status, 0);
	assert_null(strstr(r.out, "left/(left+right)"));
	cli_run_free(&r);
}

static void test_sweep_bad_experiment(void **state)
{
	(void)state;
	char dir[1024], exp[1100], out[1100];
	struct stat st;
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("sweep_bad"));
	snprintf(exp, sizeof exp, "%s",
	         bsim_test_write(dir, "bad.yaml", "scene: nosuch.yaml\ntrials: 3\n"));
	snprintf(out, sizeof out, "%s/out", dir);
	const char *argv[] = {"sweep", exp, "--out", out, NULL};
	cli_run r = run_cli(argv);
	assert_int_equal(r.status, 2);
	assert_contains(r.err, "beamsim: ");
	cli_run_free(&r);
	assert_true(stat(out, &st) != 0);
}

/* The stiff-beam scene on Box2D's explicit spring torque blows up: run
 * says why and exits 1; a sweep writes the trials as unstable, counts
 * them in summary.json and exits 1. The implicit thesis spring is fine. */
static void test_unstable(void **state)
{
	(void)state;
	char scene[1024], exp[1024], out[1100], file[1200];
	snprintf(scene, sizeof scene, "%s", bsim_test_src("configs/hard/stiff_beam.yaml"));
	snprintf(exp, sizeof exp, "%s", bsim_test_src("configs/hard/stiff_beam_sweep.yaml"));
	const char *torque[] = {"run",           scene,           "--backend", "box2d",
	                        "--backend-opt", "spring=torque", NULL};
	cli_run r = run_cli(torque);
	assert_int_equal(r.status, 1);
	assert_contains(r.out, "outcome     unstable");
	assert_contains(r.out, "unstable    energy created: ledger residual");
	assert_contains(r.err, "box2d backend: unstable trial: energy created");
	cli_run_free(&r);
	const char *thesis[] = {"run", scene, "--json", NULL};
	r = run_cli(thesis);
	assert_int_equal(r.status, 0);
	assert_contains(r.out, "\"instability\": null");
	cli_run_free(&r);

	snprintf(out, sizeof out, "%s", bsim_test_dir("unstable"));
	const char *sweep[] = {"sweep",         exp,     "--backend", "box2d", "--backend-opt",
	                       "spring=torque", "--out", out,         NULL};
	r = run_cli(sweep);
	assert_int_equal(r.status, 1);
	assert_contains(r.err, "trials unstable on the box2d backend");
	cli_run_free(&r);
	snprintf(file, sizeof file, "%s/trials.csv", out);
	char *csv = bsim_test_read(file);
	assert_non_null(csv);
	assert_contains(csv, "\n0,0,unstable,none,");
	free(csv);
	snprintf(file, sizeof file, "%s/summary.json", out);
	char *json = bsim_test_read(file);
	assert_contains(json, "\"unstable\": 10, \"deterministic\": true, \"solver\": ");
	free(json);
}

/* A group without random force runs once: every row is the same trial and
 * its interval is the point p_traverse; with random force the rows differ
 * and the interval is Wilson's. */
static void test_sweep_deterministic(void **state)
{
	(void)state;
	char dir[1024], exp[1100], out[1100], file[1200];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("det"));
	char text[2048];
	snprintf(text, sizeof text,
	         "scene: %s\ntrials: 4\nseed: 5\ngrid:\n"
	         "  effects.propulsion.force: [9]\n"
	         "  effects.random_force.magnitude: [0, 20]\n",
	         gate);
	snprintf(exp, sizeof exp, "%s", bsim_test_write(dir, "det.yaml", text));
	snprintf(out, sizeof out, "%s/out", dir);
	const char *argv[] = {"sweep", exp, "--quiet", "--out", out, NULL};
	cli_run r = run_cli(argv);
	assert_int_equal(r.status, 0);
	cli_run_free(&r);
	snprintf(file, sizeof file, "%s/trials.csv", out);
	char *csv = bsim_test_read(file);
	char *rows[8];
	int n = 0;
	for (char *line = strtok(strchr(csv, '\n') + 1, "\n"); line && n < 8;
	     line = strtok(NULL, "\n"))
		rows[n++] = strchr(strchr(line, ',') + 1, ','); /* after group,trial */
	assert_int_equal(n, 8);
	for (int t = 1; t < 4; t++)
		assert_string_equal(rows[0], rows[t]);
	assert_string_not_equal(rows[4], rows[5]);
	free(csv);
	snprintf(file, sizeof file, "%s/summary.json", out);
	char *json = bsim_test_read(file);
	assert_contains(json, "\"p_traverse\": 1, \"ci95\": [1, 1]");
	assert_contains(json, "\"deterministic\": true, \"solver\": ");
	assert_contains(json, "\"deterministic\": false, \"solver\": ");
	free(json);
}

static void test_backends(void **state)
{
	(void)state;
	const char *argv[] = {"backends", NULL};
	cli_run r = run_cli(argv);
	assert_int_equal(r.status, 0);
	assert_contains(r.out, "thesis");
	cli_run_free(&r);
}

/* A misspelt command or option is answered with the nearest one (edit
 * distance), exit 2; a word near nothing gets the list, not a guess. */
static void test_did_you_mean(void **state)
{
	(void)state;
	const char *runn[] = {"runn", gate, NULL};
	cli_run r = run_cli(runn);
	assert_int_equal(r.status, 2);
	assert_contains(r.err, "unknown command 'runn'; did you mean 'run'?");
	cli_run_free(&r);
	const char *trails[] = {"sweep", "x.yaml", "--trails", "3", NULL};
	r = run_cli(trails);
	assert_int_equal(r.status, 2);
	assert_contains(r.err, "unknown option --trails (did you mean --trials?)");
	cli_run_free(&r);
	const char *far[] = {"xyzzy", NULL};
	r = run_cli(far);
	assert_int_equal(r.status, 2);
	assert_true(strstr(r.err, "did you mean") == NULL);
	assert_contains(r.err, "Commands:");
	cli_run_free(&r);
}

/* --backend-opt B:K=V sets K on backend B, on run as on compare: for the
 * backend run runs it is K=V (the JSON's options show it); for another it
 * is refused, naming the backends the command runs. */
static void test_backend_opt_story(void **state)
{
	(void)state;
	const char *mine[] = {"run",    gate, "--backend-opt", "thesis:integrator=euler",
	                      "--json", NULL};
	cli_run r = run_cli(mine);
	assert_int_equal(r.status, 0);
	assert_contains(r.out, "\"integrator\": \"euler\"");
	cli_run_free(&r);
	const char *other[] = {"run", gate, "--backend-opt", "box2d:substeps=2", NULL};
	r = run_cli(other);
	assert_int_equal(r.status, 2);
	assert_contains(r.err,
	                "--backend-opt box2d:substeps=2: expected B:KEY=VALUE with B thesis");
	cli_run_free(&r);
	const char *help[] = {"backends", "--help", NULL};
	r = run_cli(help);
	assert_int_equal(r.status, 0);
	assert_contains(r.out, "--backend-opt B:KEY=VALUE");
	assert_contains(r.out, "--backend-opt KEY=VALUE");
	cli_run_free(&r);
}

/* File names are printed escaped: a newline in one does not start a line of
 * the report (nor could an escape sequence reach the terminal). */
static void test_names_escaped(void **state)
{
	(void)state;
	char dir[1024], scene[1100], out_dir[1100];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("names"));
	char *text = bsim_test_read(gate);
	assert_non_null(text);
	snprintf(scene, sizeof scene, "%s", bsim_test_write(dir, "ga\nte.yaml", text));
	free(text);
	const char *run[] = {"run", scene, "--set", "integration.max_steps=5", NULL};
	char *out = NULL;
	assert_int_equal(bsim_test_cli(run, &out, NULL), 0);
	assert_non_null(strstr(out, "ga\\x0Ate.yaml (thesis-gate)"));
	assert_null(strstr(out, "ga\nte"));
	free(out);
	snprintf(out_dir, sizeof out_dir, "%s/o\x1b[2Jut", dir);
	const char *sweep[] = {"sweep",    bsim_test_src("configs/thesis/h2_asymmetric.yaml"),
	                       "--trials", "1",
	                       "--set",    "integration.max_steps=5",
	                       "--out",    out_dir,
	                       NULL};
	out = NULL;
	assert_int_equal(bsim_test_cli(sweep, &out, NULL), 0);
	assert_non_null(strstr(out, "o\\x1B[2Jut/ (manifest.json lists these)"));
	assert_null(strchr(out, '\x1b'));
	free(out);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_help),
	        cmocka_unit_test(test_version),
	        cmocka_unit_test(test_run_json_alone),
	        cmocka_unit_test(test_help_command),
	        cmocka_unit_test(test_bad_usage),
	        cmocka_unit_test(test_sweep_needs_out),
	        cmocka_unit_test(test_unknown_backend),
	        cmocka_unit_test(test_bad_scene),
	        cmocka_unit_test(test_run),
	        cmocka_unit_test(test_trajectory),
	        cmocka_unit_test(test_names_escaped),
	        cmocka_unit_test(test_sweep),
	        cmocka_unit_test(test_sweep_split),
	        cmocka_unit_test(test_sweep_bad_experiment),
	        cmocka_unit_test(test_unstable),
	        cmocka_unit_test(test_sweep_deterministic),
	        cmocka_unit_test(test_backends),
	        cmocka_unit_test(test_did_you_mean),
	        cmocka_unit_test(test_backend_opt_story),
	};
	return cmocka_run_group_tests(tests, setup, NULL);
}
