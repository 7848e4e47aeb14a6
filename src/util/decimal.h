/* Internal: whether a number as a user wrote it is decimal. strtod reads
 * hexadecimal too ("0x190" is 400, "0x1p3" is 8), and a leading zero is
 * octal to C's strtol and to YAML 1.1 ("0755" is 493 there, 755 here), so
 * where a decimal number is meant such spellings are refused rather than
 * read as something the writer may not have meant. */
#ifndef BSIM_UTIL_DECIMAL_H
#define BSIM_UTIL_DECIMAL_H

#include <stddef.h>

/* 1 if t, after spaces and a sign, starts as a number of another base
 * would: 0x, 0X, 0o, 0O, 0b, 0B, or a 0 followed by a digit. "0", "0.5",
 * "-0e3", ".5", "1e3" are decimal. */
int bsim_decimal_other_base(const char *t);

/* The number a + i * step, for a and step decimal numbers as written
 * ("0.1", "-2.5e-3", "100"), written as a user would write it: in the
 * fewest decimals that hold it exactly, "0.3" for 0.1 + 2 * 0.1, not
 * 0.30000000000000004. The sum is taken on the decimal digits, not in
 * binary floating point, so the text reads back as the number a file
 * holding it gives. 0, or -1 if a or step is not such a number or the
 * result needs more than 18 digits (buf is then untouched). */
int bsim_decimal_step(const char *a, const char *step, long i, char *buf, size_t size);

#endif
