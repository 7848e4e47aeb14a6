/* JSON values for the files and records beamsim writes (summary.json,
 * run --json, bench --json). Only the two leaf values that need care live
 * here; callers write the braces, commas and keys themselves, so each
 * output keeps the exact layout its contract (docs/files.md) gives. */
#ifndef BSIM_UTIL_JSON_H
#define BSIM_UTIL_JSON_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

/* s as a JSON string: quotes, backslashes and control characters escaped
 * (\n, \r, \t by name, the rest as \u00XX); other bytes, UTF-8 included,
 * are written as they are. */
void bsim_json_string(FILE *f, const char *s);

/* x as the shortest of %.15g, %.16g, %.17g that reads back as the same
 * double; null if x is not finite (JSON has no NaN or infinity). */
void bsim_json_number(FILE *f, double x);

/* [a, b] of two numbers, each as bsim_json_number writes it. */
void bsim_json_pair(FILE *f, const double v[2]);

/* An unsigned 64-bit integer (a seed): a number up to 2^53, which every
 * reader holds exactly in a double; above, a string of its decimal digits,
 * which a double-based reader (MATLAB's jsondecode, JavaScript) would
 * otherwise round. */
void bsim_json_u64(FILE *f, uint64_t x);

/* A member of a struct as it is, after sep: sep, "name": and its value at
 * v of size bytes, an integer, or a number (several doubles a list of
 * them, as bsim_json_number writes each). */
void bsim_json_member_int(FILE *f, const char *sep, const char *name, const void *v, size_t size);
void bsim_json_member_long(FILE *f, const char *sep, const char *name, const void *v, size_t size);
void bsim_json_member_ulong(FILE *f, const char *sep, const char *name, const void *v, size_t size);
void bsim_json_member_doubles(FILE *f, const char *sep, const char *name, const void *v,
                              size_t size);

/* Member m of the struct at s (an X-macro's list names it) to f after sep,
 * which then becomes ", "; its kind from its type: a type not listed does
 * not compile. */
#define BSIM_JSON_MEMBER(f, sep, s, m)                                                               \
	do {                                                                                         \
		_Generic(&(s)->m,                                                                  \
		        const int *: bsim_json_member_int,                                         \
		        const long *: bsim_json_member_long,                                       \
		        const unsigned long *: bsim_json_member_ulong,                             \
		        const double *: bsim_json_member_doubles,                                  \
		        const double(*)[2]: bsim_json_member_doubles)(f, sep, #m, &(s)->m,         \
		                                                      sizeof(s)->m); \
		sep = ", ";                                                                          \
	} while (0)

#ifdef __cplusplus
}
#endif
#endif
