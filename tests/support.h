/* Helpers shared by the tests: running the real program, temporary
 * directories, reading files. */
#ifndef BSIM_TESTS_SUPPORT_H
#define BSIM_TESTS_SUPPORT_H

#include <stddef.h>

/* Runs BSIM_EXE with argv (NULL-terminated, without the program name),
 * capturing stdout and stderr into malloc'd strings (caller frees; may pass
 * NULL to discard). Returns the exit status, or -1 if it did not exit. */
int bsim_test_cli(const char *const argv[], char **out, char **err);

/* How bsim_test_cli_with runs the program. */
typedef struct bsim_test_opts {
	double timeout;  /* s: killed (SIGKILL) after this long, 0: never */
	long fsize;      /* bytes: the child's RLIMIT_FSIZE (writes beyond fail), 0: none */
	const char *out; /* a file to be the child's stdout instead of a capture */
} bsim_test_opts;

/* bsim_test_cli with options; returns the exit status, 128 + the signal's
 * number if a signal ended it (as the shell reports it). */
int bsim_test_cli_with(const char *const argv[], const bsim_test_opts *o, char **out, char **err);

/* Starts BSIM_EXE with argv in the background, stdout and stderr to
 * /dev/null; returns its pid. */
int bsim_test_spawn(const char *const argv[]);

/* Waits for a spawned program: its status as bsim_test_cli_with gives it. */
int bsim_test_wait(int pid);

/* A fresh empty directory under BSIM_TEST_TMP named name; returns its path
 * in a static buffer (valid until the next call). */
const char *bsim_test_dir(const char *name);

/* Writes text to dir/name and returns the path (static buffer). */
const char *bsim_test_write(const char *dir, const char *name, const char *text);

/* Reads a whole file into a malloc'd, NUL-terminated string (NULL on error). */
char *bsim_test_read(const char *path);

/* Path of a file in the source tree (static buffer). */
const char *bsim_test_src(const char *rel);

/* Every NAME.gp in dir has NAME.png and NAME.svg (when gnuplot is there),
 * each over 1 kB and at most 1 MB; the number of figures, or -1 (said on
 * stderr) if one is missing or out of that range. */
int bsim_test_check_figures(const char *dir);

/* The number after "key": in JSON text (the first such key from text on);
 * aborts the test if there is none. */
double bsim_test_json_number(const char *text, const char *key);

/* Wilson's 95% score interval of k successes in n, in closed form. */
void bsim_test_wilson(int k, int n, double *lo, double *hi);

/* The numbers of the rows of block `block` of a gnuplot data file (blocks
 * separated by two blank lines), up to 16 a row, at most max rows; aborts
 * the test if the file cannot be read. */
int bsim_test_data_rows(const char *path, int block, double (*rows)[16], int max);

#endif
