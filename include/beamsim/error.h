/* Error codes and messages: every fallible call returns a code and fills a
 * bsim_error with one readable line (file, line, field, what was expected). */
#ifndef BSIM_ERROR_H
#define BSIM_ERROR_H

#include <stddef.h>

#include "beamsim/base.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The codes double as the program's exit status (docs/files.md "Command
 * line"). */
enum {
	BSIM_OK = 0,
	BSIM_EFAIL = 1,     /* a run failed (I/O, a non-finite state, ...) */
	BSIM_EINPUT = 2,    /* bad usage, a bad scene or experiment file */
	BSIM_EDISAGREE = 3, /* compare/regress found a disagreement */
	BSIM_ESTOPPED = 4,  /* stopped on request (a signal); the program exits
	                       with 128 + the signal's number instead */
};

#define BSIM_ERROR_MSG_MAX 1024

/* msg is one line of printable UTF-8: what a message quotes from the
 * user's input is escaped (\xNN), so it cannot drive a terminal. */
typedef struct bsim_error {
	int code;
	char msg[BSIM_ERROR_MSG_MAX];
} bsim_error;

/* Sets err (if not NULL) and returns code. printf-style message. */
BSIM_API int bsim_error_set(bsim_error *err, int code, const char *fmt, ...)
        __attribute__((format(printf, 3, 4)));

/* Clears err to BSIM_OK with an empty message. */
BSIM_API void bsim_error_clear(bsim_error *err);

/* The library takes text as C strings, which end at their first NUL byte:
 * text that holds one (a Python str, an Octave char array, both of which
 * may) would be cut there without a word. For callers that get text with
 * its length: BSIM_OK if s[0..len) holds no NUL, else BSIM_EINPUT
 * "WHAT "TEXT": expected text without NUL bytes (...)", TEXT escaped (the
 * NUL as \x00) and cut to a few hundred bytes. */
BSIM_API int bsim_error_nul_check(const char *what, const char *s, size_t len, bsim_error *err);

/* A note: what a call that succeeded did not do as asked and the caller
 * should hear of (a table too large for its .mat twin), one line. Notes
 * go to the handler set here, GSL-style, process-wide; the default (fn
 * NULL) writes "beamsim: TEXT" and a line feed to standard error. A
 * program that reports otherwise (a GUI, Python) sets its own; set it once,
 * before running, not while other threads run. */
typedef void (*bsim_note_fn)(void *user, const char *text);
BSIM_API void bsim_note_set_handler(bsim_note_fn fn, void *user);
BSIM_API void bsim_note(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

#ifdef __cplusplus
}
#endif
#endif
