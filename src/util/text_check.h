/* Internal: the bytes of a scene, experiment or --set value checked before
 * libfyaml sees them. libfyaml 0.7.12 (Debian bookworm) hangs on a
 * directive followed by bytes that are not UTF-8 ("%\xcb", two bytes) and
 * crashes on a tab after an explicit key ("? a:\t-", six bytes), leaks
 * memory on escaped quotes in a row inside a single-quoted string, and cuts
 * a document silently at a NUL byte. Scene files need none of these, so
 * they are refused with their position: only UTF-8 text, lines ending in LF
 * or CRLF, spaces rather than tabs, no control characters, no directives
 * and no four apostrophes in a row. */
#ifndef BSIM_UTIL_TEXT_CHECK_H
#define BSIM_UTIL_TEXT_CHECK_H

#include <stddef.h>
#include <stdio.h>

typedef struct text_fault {
	int line, col;  /* 1-based; col counts characters, not bytes */
	char what[128]; /* "a NUL byte", "byte 0xE9, which is not UTF-8", ... */
} text_fault;

/* 1 if buf[0..len) is clean text, else 0 with *fault filled. */
int bsim_text_check(const char *buf, size_t len, text_fault *fault);

/* Drops the CR of every CRLF in place (after bsim_text_check, which allows CR
 * only there); returns the new length. Line numbers do not change. */
size_t bsim_text_strip_cr(char *buf, size_t len);

/* Rewrites the NUL-terminated buf (of capacity size) in place so that it
 * is one line of printable UTF-8: control characters and bytes that are not
 * UTF-8 become \xNN, cut to fit. Error messages quote what the user wrote,
 * and a terminal must not interpret it. */
void bsim_text_escape(char *buf, size_t size);

/* s written to f as one word for a POSIX shell: as it is if it is made of
 * safe characters, else in single quotes with each ' written as '\''
 * (replay and resume lines a user pastes back). */
void bsim_text_shell_word(FILE *f, const char *s);

#endif
