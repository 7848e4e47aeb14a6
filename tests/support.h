/* Helpers shared by the tests: running the real program (and others) and
 * waiting on what it does, temporary directories, reading files. */
#ifndef BSIM_TESTS_SUPPORT_H
#define BSIM_TESTS_SUPPORT_H

#include <stddef.h>
#include <stdint.h>

#include "beamsim/backend_registry.h"
#include "beamsim/lattice_outcome.h"
#include "beamsim/scene.h"

struct CMUnitTest;

/* Runs BSIM_EXE with argv (NULL-terminated, without the program name),
 * capturing stdout and stderr into malloc'd strings (caller frees; may pass
 * NULL to discard). Returns the exit status, 128 + the signal's number if a
 * signal ended it (as the shell reports it). */
int bsim_test_cli(const char *const argv[], char **out, char **err);

/* How bsim_test_cli_with and bsim_test_spawn_with run the program; a zero
 * field is the default. */
typedef struct bsim_test_opts {
	double timeout;  /* s: ended by SIGALRM after this long, 0: never */
	long fsize;      /* bytes: the child's RLIMIT_FSIZE (writes beyond fail), 0: none */
	long as;         /* bytes: the child's RLIMIT_AS (its address space; an allocation
	                  * beyond fails), 0: none */
	const char *out; /* a file to be the child's stdout instead of a capture */
	const char *err; /* a file to be the child's stderr (created) instead of a capture */
	int tty;         /* 1: stderr a pseudo-terminal, which bsim_test_cli_with captures */
} bsim_test_opts;

/* bsim_test_cli with options (o may be NULL). */
int bsim_test_cli_with(const char *const argv[], const bsim_test_opts *o, char **out, char **err);

/* Asserts that argv exits with status 2 and one line on stderr holding
 * every needle (NULL-terminated): the form of every input error. */
void bsim_test_expect_input_error(const char *const argv[], const char *const needles[]);

/* The same checks on a run already made: status rc, stderr err (one_line:
 * and nothing but that line). */
void bsim_test_check_input_error(int rc, const char *err, const char *const needles[],
                                 int one_line);

/* Runs another program, argv[0] looked up on PATH, with stdout into *out
 * (may be NULL) and stderr discarded; returns its status as above. */
int bsim_test_run(const char *const argv[], char **out);

/* dir/small.yaml, a small experiment on configs/thesis/gate.yaml: 4 trials
 * a group, seed 1, F_prop 9 N, groups R_m = 0 and 30 N. Its path (a
 * static buffer). */
const char *bsim_test_gate_experiment(const char *dir);

/* chromium's DOM of the page at url (file://...) as it stands once the page
 * has loaded and gone idle (headless, --virtual-time-budget: chromium
 * dumps it on that event), malloc'd; *console (may be NULL) gets the lines
 * the page wrote to its console (chromium's "CONSOLE" log lines), ""
 * if none. Fails the test, saying what to do, if chromium is not
 * installed (scripts/deps.sh installs it). */
char *bsim_test_browser_dom(const char *url, char **console);

/* Starts BSIM_EXE with argv in the background, stdout and stderr to
 * /dev/null (or o->out, o->err; o may be NULL); returns its pid. */
int bsim_test_spawn(const char *const argv[]);
int bsim_test_spawn_with(const char *const argv[], const bsim_test_opts *o);

/* Waits for a spawned program: its status as bsim_test_cli gives it. */
int bsim_test_wait(int pid);

/* The whole records in a journal (beamsim's util/journal.h format: its
 * header says how long they are), or -1 if there is no journal at path. */
long bsim_test_journal_records(const char *path);

/* The waits below poll every millisecond for an event of the program's
 * (never a fixed time); a program that neither gets there nor ends within
 * a generous guard (300 s) is killed and the test fails.
 *
 * Waits until ready(ctx) holds while the spawned pid runs: 1 if it does,
 * or 0 with *status (as bsim_test_wait gives it) if the program ended
 * first; what names the event in the guard's failure. The waits after it
 * are this one on a journal, a directory or a glob. */
int bsim_test_await(int pid, int (*ready)(void *ctx), void *ctx, const char *what, int *status);

/* Waits until the journal at path holds at least n records while the
 * spawned pid runs: 1 if it does (the program still running), or 0 with
 * *status (as bsim_test_wait gives it) if the program ended first. The
 * journal is created whole (header and all) after the program installs its
 * SIGINT and SIGTERM handlers, so n = 0 waits for that. */
int bsim_test_await_records(int pid, const char *path, long n, int *status);

/* Waits until the directory dir has an entry while the spawned pid runs:
 * 1, or 0 with *status if the program ended first. */
int bsim_test_await_entry(int pid, const char *dir, int *status);

/* Waits until at least n paths match the glob pattern while the spawned
 * pid runs: 1, or 0 with *status if the program ended first. */
int bsim_test_await_glob(int pid, const char *pattern, long n, int *status);

/* A fresh empty directory under BSIM_TEST_TMP named name; returns its path
 * in a static buffer (valid until the next call). */
const char *bsim_test_dir(const char *name);

/* The same in one of four static buffers used in turn, so that a few
 * may be held at once. */
const char *bsim_test_dir_held(const char *name);

/* Removes path and all below it (rm -rf): 0, or -1 on failure. */
int bsim_test_remove(const char *path);

/* Writes text to dir/name and returns the path (static buffer). */
const char *bsim_test_write(const char *dir, const char *name, const char *text);

/* A stand-in for a program the command starts (gnuplot, ffmpeg): writes
 * the shell script text to dir/name (dir made if missing; keep it apart
 * from the outputs), executable, and puts dir first on this
 * process's PATH, so the programs it starts find the stand-in first.
 * Returns the PATH before (malloc'd), for bsim_test_path_restore. A script
 * reaches the real program with PATH="${PATH#*:}" (the PATH without dir). */
char *bsim_test_fake_program(const char *dir, const char *name, const char *script);
void bsim_test_path_restore(char *old);

/* Asserts that dir holds a committed set of files (its manifest.json
 * lists only files there with their size and CRC-32: bsim_outdir_verify),
 * that the manifest lists each of files (NULL-terminated) and none of
 * absent (NULL-terminated, may be NULL), and that no staging area is
 * left (dir/.beamsim). */
void bsim_test_check_committed(const char *dir, const char *const files[],
                               const char *const absent[]);

/* N independent direct trials of the lattice s on the default backend,
 * trial t seeded bsim_schedule_seed_mix(seed, 0, t): share[i] += the share
 * that ended in loc[i] (n locations). Fails the test if a trial fails. */
void bsim_test_simulate_locations(const bsim_scene *s, const bsim_location *loc, int n, int N,
                                  uint64_t seed, double *share);

/* Reads a whole file into a malloc'd, NUL-terminated string (NULL on error). */
char *bsim_test_read(const char *path);

/* The files matching a glob(3) pattern, in name order: all of them
 * concatenated (bsim_test_read_glob, NULL if none), or the first one's path
 * (bsim_test_glob_first, a static buffer; NULL if none). */
char *bsim_test_read_glob(const char *pattern);
const char *bsim_test_glob_first(const char *pattern);

/* "dir/name" in one of four static buffers used in turn (so a few may be
 * held at once); aborts the test if it does not fit. */
const char *bsim_test_join(const char *dir, const char *name);

/* 1 if there is a file or directory at path (access(2), F_OK). */
int bsim_test_exists(const char *path);

/* A file's size in bytes, -1 if it does not exist. */
long bsim_test_size(const char *path);

/* The number of '\n' in text. */
int bsim_test_count_lines(const char *text);

/* Path of a file in the source tree (static buffer). */
const char *bsim_test_src(const char *rel);

/* Every NAME.gp in dir has NAME.png and NAME.svg (when gnuplot is there),
 * each over 1 kB and at most 1 MB, and the PNG nothing drawn in its
 * outermost BSIM_TEST_EDGE_PX pixels (bsim_test_png_edge); the number of
 * figures, or -1 (said on stderr, naming the file) if one is missing, out
 * of that range or drawn to its edge. */
int bsim_test_check_figures(const char *dir);

/* The outermost pixel columns and rows a figure leaves blank: text cut off
 * by the canvas (a title or label wider than the image) or a key placed
 * beyond it reaches the edge. */
#define BSIM_TEST_EDGE_PX 3

/* NULL if the PNG at path has only background (white or transparent)
 * within BSIM_TEST_EDGE_PX pixels of its edges; else the sides that have
 * more ("left, right"), or why it could not be read (a static buffer). */
const char *bsim_test_png_edge(const char *path);

/* The number after "key": in JSON text (the first such key from text on);
 * aborts the test if there is none. */
double bsim_test_json_number(const char *text, const char *key);

/* A JSON (or YAML) document's node at a dotted path ("groups.3.verdict",
 * util/yaml_doc.h's bsim_ydoc_lookup) as a number, or its scalar's text into
 * buf; fails the test, naming the path, if there is none. */
struct fy_node;
double bsim_test_json_at(struct fy_node *root, const char *path);
const char *bsim_test_json_text_at(struct fy_node *root, const char *path, char *buf, size_t size);

/* Asserts that out (a command's stdout) has the line "wrote DIR/ ..."
 * followed by a line "  PATH ..." for every file DIR/manifest.json lists;
 * returns their number. */
int bsim_test_check_wrote(const char *out, const char *dir);

/* The tests that every backend passes (docs/tests.md, "Every backend"):
 * each of the n tests once per backend of the registry
 * (bsim_backend_list), the example plug-in (examples/plugin_gate_euler.c)
 * loaded into it first, named "TEST (BACKEND)" with the backend as its
 * state, so that a backend added to the registry runs them with no edit
 * here; cmocka's status of the whole group. */
int bsim_test_run_per_backend(const char *group, const struct CMUnitTest *tests, size_t n);

/* The bound b states for check (bsim_backend_bound); if it states none,
 * the test (of that backend) is skipped, saying so. */
double bsim_test_bound(const bsim_backend *b, const char *check);

/* Skips the test of backend b, printing why it cannot apply (printf-style). */
void bsim_test_skip(const bsim_backend *b, const char *fmt, ...)
        __attribute__((format(printf, 2, 3)));

/* Skips the test of backend b if b's check refuses scene s (a backend that
 * simulates only some scenes, the example plug-in's disk), saying why;
 * frees s first then. */
void bsim_test_skip_refused(const bsim_backend *b, bsim_scene *s);

/* The options under which the checks of other things (a body's turn, drag,
 * friction, mirror images) take body on b: none, or "ellipse=polygon" where
 * b holds an ellipse only as a polygon and refuses it unless told (a knob
 * "ellipse": off its axes the polygon's restitution is not the scene's,
 * test_impact's "impact.shape.restitution"). */
bsim_options bsim_test_body_options(const bsim_backend *b, const bsim_body_def *body);

/* b's world for s with opts (may be NULL); fails the test with b's message
 * if b refuses. */
bsim_world *bsim_test_world(const bsim_backend *b, const bsim_scene *s, const bsim_options *opts);

/* A backend by name, for a test of that backend's own behaviour (its
 * knobs, its internals); fails the test if none is compiled in. */
const bsim_backend *bsim_test_backend(const char *name);

/* The thesis backend's advance, for the tests that hold its runs to its
 * single step (test_steps, test_flight): one step asked is made by the step
 * itself (advance without a state, then get_state), the truth; more are
 * made by advance, their count added to bsim_test_run_steps and the count
 * of those whose state lists no beam (free flight's) to bsim_test_run_free.
 * A bsim_backend.advance, for a copy of the thesis backend's table. */
extern long bsim_test_run_steps, bsim_test_run_free;
int bsim_test_counted_advance(bsim_world *w, const bsim_wrench *schedule, double h, int n,
                              bsim_state *out, int *made, bsim_error *err);

/* A test's own random numbers, reproducible: xorshift64* from the state
 * *s (seed it nonzero), uniform on [0, 1). */
double bsim_test_uniform(uint64_t *s);

/* Wilson's 95% score interval of k successes in n, in closed form. */
void bsim_test_wilson(int k, int n, double *lo, double *hi);

/* The numbers of the rows of block `block` of a gnuplot data file (blocks
 * separated by two blank lines), up to 16 a row, at most max rows; aborts
 * the test if the file cannot be read. */
int bsim_test_data_rows(const char *path, int block, double (*rows)[16], int max);

#endif
