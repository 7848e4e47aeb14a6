/* Hostile inputs through the real program: bytes that crash or hang
 * libfyaml 0.7.12, text cut at a NUL, exponential aliases, valid values that
 * ask for more memory or time than a machine has, extreme numbers. Each is
 * refused before the work it asks for, with exit status 2 and one line
 * naming where, the field or cause and the limit, or (extreme but valid
 * numbers) runs without undefined behaviour: the sanitized build halts on
 * any. The truth is the contract (docs/files.md "Command line"), and, for the
 * libfyaml cases, the crash and the hang that the same bytes cause without
 * the checks. "Before the work" is shown by what the work would have left
 * or said, never by a clock: the timeout only ends a hang. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "support.h"

/* Any hang shows as a kill after this long, not as a stuck test. */
#define TIMEOUT 60.0

static const char *gate(void)
{
	static char path[1200];
	snprintf(path, sizeof path, "%s", bsim_test_src("configs/thesis/gate.yaml"));
	return path;
}

/* Writes n bytes to dir/name (the text may hold NULs); returns the path. */
static const char *write_bytes(const char *name, const char *bytes, size_t n)
{
	static char path[1200];
	snprintf(path, sizeof path, "%s/%s", bsim_test_dir(name), name);
	FILE *f = fopen(path, "wb");
	assert_non_null(f);
	assert_int_equal(fwrite(bytes, 1, n, f), n);
	assert_int_equal(fclose(f), 0);
	return path;
}

/* argv exits 2 with one stderr line holding every needle. */
static void expect_refusal(const char *const argv[], const char *const needles[])
{
	bsim_test_opts o = {.timeout = TIMEOUT};
	char *err = NULL;
	int rc = bsim_test_cli_with(argv, &o, NULL, &err);
	if (rc == 128 + SIGALRM)
		fail_msg("ended by the timeout of %g s, stderr: %s", TIMEOUT, err);
	bsim_test_check_input_error(rc, err, needles, 1);
	free(err);
}

static void run_refused(const char *path, const char *const needles[])
{
	const char *argv[] = {"run", path, NULL};
	expect_refusal(argv, needles);
}

/* The six bytes that make libfyaml 0.7.12 dereference a bad pointer in
 * fy_indent_vacuum_internal (a tab after an explicit key). */
static void test_libfyaml_indent_crash(void **state)
{
	(void)state;
	const char *needles[] = {"indent_crash.yaml:1:5: ", "tab character", NULL};
	run_refused(write_bytes("indent_crash.yaml", "? -:\t-", 6), needles);
}

/* Two bytes on which libfyaml 0.7.12 loops for ever in fy_scan_directive:
 * a directive followed by a byte that is not UTF-8; and the same with a
 * sequence glibc's iconv accepts although it is above U+10FFFF. */
static void test_libfyaml_directive_hang(void **state)
{
	(void)state;
	const char *needles[] = {"hang.yaml:1:1: ", "directive", NULL};
	run_refused(write_bytes("hang.yaml", "%\xcb", 2), needles);
	const char *needles2[] = {"hang2.yaml:1:1: ", "directive", NULL};
	run_refused(write_bytes("hang2.yaml", "%\xf4\x90\x80\x80", 5), needles2);
	/* Not UTF-8 elsewhere: the byte, its line and column. */
	const char *needles3[] = {"high.yaml:2:7: ", "byte 0xF4, which is not UTF-8", NULL};
	run_refused(write_bytes("high.yaml", "# x\nname: \xf4\x90\x80\x80\n", 15), needles3);
}

/* A NUL byte used to end the document there, silently dropping the rest. */
static void test_nul_byte(void **state)
{
	(void)state;
	static const char text[] =
	        "body: { mass: 1, radius: 10 }\n"
	        "beams:\n"
	        "  - { pivot: [-25, 30], length: 25, mass: 0.1, stiffness: 400 }\n"
	        "\0effects: { propulsion: { force: 7 } }\n";
	const char *needles[] = {"nul.yaml:4:1: ", "NUL byte", NULL};
	run_refused(write_bytes("nul.yaml", text, sizeof text - 1), needles);
}

/* A Latin-1 comment (e9 is "é" in Latin-1, not UTF-8). */
static void test_latin1_comment(void **state)
{
	(void)state;
	char *g = bsim_test_read(gate());
	assert_non_null(g);
	size_t n = strlen(g);
	char *text = malloc(n + 32);
	int k = sprintf(text, "# r\xe9glage\n");
	memcpy(text + k, g, n);
	const char *needles[] = {"latin1.yaml:1:4: ", "byte 0xE9", NULL};
	run_refused(write_bytes("latin1.yaml", text, (size_t)k + n), needles);
	free(text);
	free(g);
}

/* A lone carriage return, control characters, a second document. */
static void test_other_bytes(void **state)
{
	(void)state;
	const char *cr[] = {"cr.yaml:1:2: ", "carriage return", NULL};
	run_refused(write_bytes("cr.yaml", ":\r:", 3), cr);
	const char *esc[] = {"esc.yaml:1:7: ", "control character U+001B", NULL};
	run_refused(write_bytes("esc.yaml", "name: \x1b[31m\n", 12), esc);
	/* escaped quotes in a row: libfyaml 0.7.12 leaks a buffer on them (the
	 * sanitized build's leak check fails without the refusal) */
	const char *quotes[] = {"quotes.yaml:1:9: ", "four apostrophes in a row", NULL};
	static const char q[] = "name: 'a''''''''''''b'\n";
	run_refused(write_bytes("quotes.yaml", q, sizeof q - 1), quotes);
	const char *doc[] = {"two.yaml: ", "one YAML document", NULL};
	run_refused(write_bytes("two.yaml", "name: a\n---\nname: b\n", 20), doc);
	/* CRLF line ends are text: the gate with them loads and runs. */
	char *g = bsim_test_read(gate());
	char *crlf = malloc(2 * strlen(g) + 1), *w = crlf;
	for (const char *p = g; *p; p++)
		w += *p == '\n' ? sprintf(w, "\r\n") : sprintf(w, "%c", *p);
	const char *argv[] = {"run", write_bytes("crlf.yaml", crlf, (size_t)(w - crlf)), NULL};
	assert_int_equal(bsim_test_cli(argv, NULL, NULL), 0);
	free(crlf);
	free(g);
}

/* Twenty-six levels of nine aliases: 9^26 (6e24) nodes if expanded, 1.2 kB.
 * The refusal names the first alias, b.0 = *a, as an alias: expanding
 * (libfyaml's resolve puts a copy of the anchored node in its place) leaves
 * none to name, and a build that expanded, or walked the expansion to
 * count it, before the check would never get there (the timeout ends it as
 * the hang it is). */
static void test_billion_laughs(void **state)
{
	(void)state;
	char text[2048];
	int n = sprintf(text, "a: &a [lol, lol, lol, lol, lol, lol, lol, lol, lol]\n");
	for (char c = 'b'; c <= 'z'; c++)
		n += sprintf(text + n, "%c: &%c [*%c, *%c, *%c, *%c, *%c, *%c, *%c, *%c, *%c]\n", c,
		             c, c - 1, c - 1, c - 1, c - 1, c - 1, c - 1, c - 1, c - 1, c - 1);
	const char *needles[] = {"laughs.yaml:2:9: b.0: ", "got the alias *a", NULL};
	const char *argv[] = {"run", write_bytes("laughs.yaml", text, (size_t)n), NULL};
	expect_refusal(argv, needles);
}

/* The size limit, and raising it. */
static void test_size_limit(void **state)
{
	(void)state;
	char *g = bsim_test_read(gate());
	size_t n = strlen(g), big = 1100000;
	char *text = malloc(big + n);
	memset(text, '#', big);
	for (size_t i = 80; i < big; i += 81)
		text[i] = '\n';
	text[big - 1] = '\n';
	memcpy(text + big, g, n);
	const char *path = write_bytes("big.yaml", text, big + n);
	const char *needles[] = {"big.yaml: ", "at most 1048576 bytes", "--limit input_bytes=N",
	                         NULL};
	run_refused(path, needles);
	const char *raised[] = {"run", path, "--limit", "input_bytes=2e6", NULL};
	assert_int_equal(bsim_test_cli(raised, NULL, NULL), 0);
	free(text);
	free(g);
}

/* What is not a regular file is refused at once: a FIFO with no writer
 * (reading it used to wait for one for ever), a directory, a device, as a
 * scene and as a CSV input (gate entries of markov build). */
static void test_not_regular(void **state)
{
	(void)state;
	char dir[1200], fifo[1300];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("not_regular"));
	snprintf(fifo, sizeof fifo, "%s/pipe.yaml", dir);
	assert_int_equal(mkfifo(fifo, 0600), 0);
	const char *fifo_says[] = {"pipe.yaml: ", "expected a YAML file, got a FIFO", NULL};
	run_refused(fifo, fifo_says);
	const char *folder[] = {"not_regular: ", "expected a YAML file, got a directory", NULL};
	run_refused(dir, folder);
	const char *device[] = {"/dev/zero: ", "expected a YAML file, got a character device",
	                        NULL};
	run_refused("/dev/zero", device);
	char out[1300];
	snprintf(out, sizeof out, "%s/maps", dir);
	const char *track = bsim_test_src("configs/markov/c_track.yaml");
	const char *argv[] = {"markov", "build", track, "--entries", fifo, "--out", out, NULL};
	const char *csv[] = {"pipe.yaml: ", "expected a CSV file, got a FIFO", NULL};
	expect_refusal(argv, csv);
}

/* The same hazards through --set, and the --set with spaces that used to
 * report "out of memory" (and leak: the sanitized build checks leaks). */
static void test_set_values(void **state)
{
	(void)state;
	static const struct {
		const char *set;
		const char *needle;
	} cases[] = {
	        {"body.mass=\t2", "tab character"},
	        {"body.mass=%\xcb", "directive"},
	        {"body=? -:\t-", "tab character"},
	        {"name=caf\xe9", "byte 0xE9"},
	        {"body.mass=*x", "alias *x"},
	        {"body.mass=[1,", "expected a YAML value"},
	        {"body.ma ss=2", "expected a dotted key"},
	        {"effects.random_force.frequency=1e9", "integration.dt: expected at most 1e-09 s"},
	};
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		const char *argv[] = {"run", gate(), "--set", cases[i].set, NULL};
		const char *needles[] = {"--set ", cases[i].needle, NULL};
		expect_refusal(argv, needles);
	}
	char *spaced = NULL, *plain = NULL;
	const char *a[] = {"run", gate(), "--json", "--set", "body.mass = 2", NULL};
	const char *b[] = {"run", gate(), "--json", "--set", "body.mass=2", NULL};
	const char *c[] = {"run", gate(), "--json", NULL};
	char *heavy = NULL;
	assert_int_equal(bsim_test_cli(a, &spaced, NULL), 0);
	assert_int_equal(bsim_test_cli(b, &plain, NULL), 0);
	assert_int_equal(bsim_test_cli(c, &heavy, NULL), 0);
	assert_string_equal(spaced, plain);
	assert_string_not_equal(plain, heavy); /* the override took effect */
	free(spaced);
	free(plain);
	free(heavy);
}

/* Valid values that ask for too much: each names its field and limit, and
 * is refused at once, not after validating 10^9 groups or allocating
 * gigabytes. */
static void test_limits(void **state)
{
	(void)state;
	char *g = bsim_test_read(gate());
	char *fast = malloc(strlen(g) + 64);
	/* frequency 1e9 Hz in the file, and the step of 1 ns its hold needs:
	 * 2e6 random-force values in 2e6 steps */
	char *f = strstr(g, "frequency: 50.0");
	char *t = strstr(g, "{ dt: 0.004, duration: 12 }");
	assert_true(f && t && f < t);
	sprintf(fast, "%.*sfrequency: 1e9%.*s{ dt: 1e-9, max_steps: 2000000 }%s", (int)(f - g), g,
	        (int)(t - f - strlen("frequency: 50.0")), f + strlen("frequency: 50.0"),
	        t + strlen("{ dt: 0.004, duration: 12 }"));
	const char *sched[] = {"frequency.yaml:", "effects.random_force.frequency",
	                       "random-force values", "--limit schedule=N", NULL};
	run_refused(write_bytes("frequency.yaml", fast, strlen(fast)), sched);
	const char *steps[] = {"run",   gate(),
	                       "--set", "effects.random_force.magnitude=0",
	                       "--set", "integration.max_steps=2000000000",
	                       NULL};
	const char *steps_needles[] = {"integration.max_steps", "beam-steps",
	                               "--limit beam_steps=N", NULL};
	expect_refusal(steps, steps_needles);

	/* 10^9 groups from nine lists of ten, in 700 bytes. The last two lists
	 * are each fine with the other at its first value, but their second
	 * values together put the body 20 m from the beams with a radius of
	 * 25 m: group 11 of the product, met at once by a build that builds
	 * the groups before counting them. The product alone refuses it. */
	static const char pair[] = "  body.radius: [10, 25, 11, 12, 13, 14, 15, 16, 17, 18]\n"
	                           "  body.start.1: [0, 10, 1, 2, 3, 4, 5, 6, 7, 8]\n";
	char two[1400], out[1200];
	int n = sprintf(two, "scene: %s\ntrials: 10\nseed: 1\ngrid:\n%s", gate(), pair);
	snprintf(out, sizeof out, "%s", bsim_test_dir("pair_out"));
	const char *by_two[] = {"sweep", write_bytes("pair.yaml", two, (size_t)n), "--out", out,
	                        NULL};
	const char *overlap[] = {"pair.yaml:5: ", "the body (radius 25) overlaps beam 1",
	                         "distance 20 m", NULL};
	expect_refusal(by_two, overlap);
	/* The same two lists last of nine: the count is refused, not group 11,
	 * so no group was built past each value with the others at their first;
	 * and the output directory was never opened. */
	char exp[2048];
	n = sprintf(exp, "scene: %s\ntrials: 10\nseed: 1\ngrid:\n", gate());
	const char *keys[] = {"body.mass",       "beams.0.stiffness", "beams.1.stiffness",
	                      "beams.0.damping", "beams.1.damping",   "beams.0.mass",
	                      "beams.1.mass"};
	for (int k = 0; k < 7; k++)
		n += sprintf(exp + n, "  %s: [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0]\n",
		             keys[k]);
	n += sprintf(exp + n, "%s", pair);
	const char *path = write_bytes("groups.yaml", exp, (size_t)n);
	snprintf(out, sizeof out, "%s", bsim_test_dir("groups_out"));
	const char *sweep[] = {"sweep", path, "--out", out, NULL};
	const char *groups_needles[] = {"groups.yaml:5:3: grid: ", "got 1000000000",
	                                "--limit groups=N", NULL};
	expect_refusal(sweep, groups_needles);
	assert_false(bsim_test_exists(bsim_test_join(out, ".beamsim")));

	/* H1 has 30 groups: a limit of 29 refuses it, 30 admits it. */
	const char *h1 = bsim_test_src("configs/thesis/h1_symmetric.yaml");
	char h1_path[1200];
	snprintf(h1_path, sizeof h1_path, "%s", h1);
	const char *low[] = {"sweep",   h1_path,     "--quiet", "--trials",           "1",
	                     "--limit", "groups=29", "--out",   bsim_test_dir("low"), NULL};
	const char *low_needles[] = {"grid: ", "at most 29 groups", "got 30", NULL};
	expect_refusal(low, low_needles);
	const char *ok[] = {"sweep",   h1_path,     "--quiet", "--trials",          "1",
	                    "--limit", "groups=30", "--out",   bsim_test_dir("ok"), NULL};
	assert_int_equal(bsim_test_cli(ok, NULL, NULL), 0);
	/* --trials beyond the limit of trials in all */
	const char *many[] = {
	        "sweep", h1_path, "--trials", "400000", "--out", bsim_test_dir("many"), NULL};
	const char *many_needles[] = {"--trials 400000", "30 groups x 400000 trials",
	                              "--limit trials=N", NULL};
	expect_refusal(many, many_needles);
	free(fast);
	free(g);
}

/* Extreme but valid numbers, on every backend of the registry: every
 * double-to-integer conversion they reach is defined (the sanitized build
 * halts on one that is not: UBSan's float-cast-overflow). Each run ends with a result or a stated
 * failure. */
static void test_extreme_numbers(void **state)
{
	(void)state;
	static const char *const sets[][2] = {
	        {"beams.0.rest_angle_deg=1e300", "beams.1.rest_angle_deg=-1e300"},
	        {"beams.0.rest_angle_deg=9.3e18", "beams.1.rest_angle_deg=180"},
	        {"integration.dt=1e-300", "effects.random_force.frequency=1e-300"},
	        {"integration.dt=1e300", "integration.max_steps=2"},
	        {"effects.random_force.frequency=3e-9", "integration.dt=1e-300"},
	        {"effects.random_force.frequency=1e5", "integration.dt=1e-8"},
	        {"body.mass=1e-300", "body.velocity=[1e300, -1e300]"},
	};
	const bsim_backend *const *backends = bsim_backend_list();
	for (size_t i = 0; i < sizeof sets / sizeof sets[0]; i++) {
		for (int b = 0; backends[b]; b++) {
			const char *argv[] = {"run",   gate(),     "--backend", backends[b]->name,
			                      "--set", sets[i][0], "--set",     sets[i][1],
			                      NULL};
			char *err = NULL;
			bsim_test_opts o = {.timeout = TIMEOUT};
			int rc = bsim_test_cli_with(argv, &o, NULL, &err);
			if ((rc != 0 && rc != 1 && rc != 2) || strstr(err, "runtime error"))
				fail_msg("%s --set %s --set %s: exit %d, stderr %s",
				         backends[b]->name, sets[i][0], sets[i][1], rc, err);
			free(err);
		}
	}
}

#define LATTICE_3X3                                                                                \
	"body: { mass: 1, radius: 10 }\n"                                                          \
	"lattice:\n  columns: 3\n  rows: 3\n"                                                      \
	"  beam: { length: 25, mass: 0.1, stiffness: 400, damping: 50 }\n"                         \
	"  stiffness_file: map.csv\n"

/* Numbers are decimal: strtod read "0x190" as 400, and a leading zero is
 * octal to YAML 1.1; both are refused in scenes, --set values, a lattice's
 * CSV and the CSV tables beamsim reads back, while "1e3", "-0.5", ".5" stay
 * numbers. */
static void test_decimal_numbers(void **state)
{
	(void)state;
	const char *g = gate();
	const char *hex[] = {"run", g, "--set", "body.mass=0x190", NULL};
	const char *hex_says[] = {"body.mass: expected a positive number, got 0x190", NULL};
	expect_refusal(hex, hex_says);
	const char *oct[] = {"run", g, "--set", "integration.max_steps=010", NULL};
	const char *oct_says[] = {"integration.max_steps: expected a positive integer, got 010",
	                          NULL};
	expect_refusal(oct, oct_says);
	const char *fine[] = {"run",   g,
	                      "--set", "body.mass=1e3",
	                      "--set", "body.velocity.0=-0.5",
	                      "--set", "contact.restitution=.5",
	                      "--set", "integration.max_steps=5",
	                      NULL};
	assert_int_equal(bsim_test_cli(fine, NULL, NULL), 0);

	char dir[1200], scene[1300];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("decimal"));
	snprintf(scene, sizeof scene, "%s", bsim_test_write(dir, "scene.yaml", LATTICE_3X3));
	bsim_test_write(dir, "map.csv", "1, 0x190, 3\n4, 5, 6\n7, 8, 9\n");
	const char *lat[] = {"run", scene, NULL};
	const char *lat_says[] = {"map.csv:1:", "lattice.stiffness_file", "got 0x190", NULL};
	expect_refusal(lat, lat_says);
	bsim_test_write(dir, "map.csv", "1e3, .5, 0.5\n4, 5, 6\n7, 8, 9\n");
	const char *lat_ok[] = {"run", scene, "--set", "integration.max_steps=5", NULL};
	assert_int_equal(bsim_test_cli(lat_ok, NULL, NULL), 0);

	const char *entries =
	        bsim_test_write(dir, "gate_entries.csv",
	                        "group,trial,seq,ix,iy,edge,step,t,pos,x,y,vx,vy\n"
	                        "0,0,0,0,0,start,0,0,0,0,0,0,0\n"
	                        "0,0,1,1,0,left,1280,5.12,0x10,-24.99,19.98,2.67,0.075\n");
	char path[1300], out[1300];
	snprintf(path, sizeof path, "%s", entries);
	snprintf(out, sizeof out, "%s/maps", dir);
	const char *track = bsim_test_src("configs/markov/c_track.yaml");
	const char *mk[] = {"markov", "build", track, "--entries", path, "--out", out, NULL};
	const char *mk_says[] = {"gate_entries.csv:3: expected an entry", NULL};
	expect_refusal(mk, mk_says);
}

/* dir/name holding n bytes (NULs too). */
static void put_bytes(const char *dir, const char *name, const char *bytes, size_t n)
{
	char path[1300];
	snprintf(path, sizeof path, "%s/%s", dir, name);
	FILE *f = fopen(path, "wb");
	assert_non_null(f);
	assert_int_equal(fwrite(bytes, 1, n, f), n);
	assert_int_equal(fclose(f), 0);
}

/* A NUL byte in a CSV is named with its line and column (it used to read
 * as a line too long, or to end the line unseen). */
static void test_nul_in_csv(void **state)
{
	(void)state;
	char dir[1200], scene[1300];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("nul_csv"));
	snprintf(scene, sizeof scene, "%s", bsim_test_write(dir, "scene.yaml", LATTICE_3X3));
	static const char map[] = "1, 2, 3\n4,\0 5, 6\n7, 8, 9\n";
	put_bytes(dir, "map.csv", map, sizeof map - 1);
	const char *lat[] = {"run", scene, NULL};
	const char *lat_says[] = {
	        "map.csv:2:3: lattice.stiffness_file: expected text, got a NUL byte", NULL};
	expect_refusal(lat, lat_says);

	static const char entries[] = "group,trial,seq,ix,iy,edge,step,t,pos,x,y,vx,vy\n"
	                              "0,0,0,0,0,start,0,0,0,0,0,0,0\n"
	                              "0,0,1,\0001,0,left,1280,5.12,1,-24.99,19.98,2.67,0.075\n";
	put_bytes(dir, "gate_entries.csv", entries, sizeof entries - 1);
	char path[1300], out[1300];
	snprintf(path, sizeof path, "%s/gate_entries.csv", dir);
	snprintf(out, sizeof out, "%s/maps", dir);
	const char *track = bsim_test_src("configs/markov/c_track.yaml");
	const char *mk[] = {"markov", "build", track, "--entries", path, "--out", out, NULL};
	const char *mk_says[] = {"gate_entries.csv:3:7: expected text, got a NUL byte", NULL};
	expect_refusal(mk, mk_says);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_libfyaml_indent_crash),
	        cmocka_unit_test(test_libfyaml_directive_hang),
	        cmocka_unit_test(test_nul_byte),
	        cmocka_unit_test(test_latin1_comment),
	        cmocka_unit_test(test_other_bytes),
	        cmocka_unit_test(test_billion_laughs),
	        cmocka_unit_test(test_size_limit),
	        cmocka_unit_test(test_not_regular),
	        cmocka_unit_test(test_set_values),
	        cmocka_unit_test(test_limits),
	        cmocka_unit_test(test_extreme_numbers),
	        cmocka_unit_test(test_decimal_numbers),
	        cmocka_unit_test(test_nul_in_csv),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
