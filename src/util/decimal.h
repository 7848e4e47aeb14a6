/* Internal: whether a number as a user wrote it is decimal. strtod reads
 * hexadecimal too ("0x190" is 400, "0x1p3" is 8), and a leading zero is
 * octal to C's strtol and to YAML 1.1 ("0755" is 493 there, 755 here), so
 * where a decimal number is meant such spellings are refused rather than
 * read as something the writer may not have meant. */
#ifndef BSIM_UTIL_DECIMAL_H
#define BSIM_UTIL_DECIMAL_H

/* 1 if t, after spaces and a sign, starts as a number of another base
 * would: 0x, 0X, 0o, 0O, 0b, 0B, or a 0 followed by a digit. "0", "0.5",
 * "-0e3", ".5", "1e3" are decimal. */
int decimal_other_base(const char *t);

#endif
