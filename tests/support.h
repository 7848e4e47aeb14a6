/* Helpers shared by the tests: running the real program, temporary
 * directories, reading files. */
#ifndef BSIM_TEST_SUPPORT_H
#define BSIM_TEST_SUPPORT_H

#include <stddef.h>

/* Runs BSIM_EXE with argv (NULL-terminated, without the program name),
 * capturing stdout and stderr into malloc'd strings (caller frees; may pass
 * NULL to discard). Returns the exit status, or -1 if it did not exit. */
int bsim_test_cli(const char *const argv[], char **out, char **err);

/* A fresh empty directory under BSIM_TEST_TMP named name; returns its path
 * in a static buffer (valid until the next call). */
const char *bsim_test_dir(const char *name);

/* Writes text to dir/name and returns the path (static buffer). */
const char *bsim_test_write(const char *dir, const char *name, const char *text);

/* Reads a whole file into a malloc'd, NUL-terminated string (NULL on error). */
char *bsim_test_read(const char *path);

/* Path of a file in the source tree (static buffer). */
const char *bsim_test_src(const char *rel);

#endif
