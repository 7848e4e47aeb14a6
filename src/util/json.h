/* JSON values for the files and records beamsim writes (summary.json,
 * run --json, bench --json). Only the two leaf values that need care live
 * here; callers write the braces, commas and keys themselves, so each
 * output keeps the exact layout its contract (docs/files.md) gives. */
#ifndef BSIM_UTIL_JSON_H
#define BSIM_UTIL_JSON_H

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

#ifdef __cplusplus
}
#endif
#endif
