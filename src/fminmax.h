/* fmax and fmin inlined, with the C library's results bit for bit (glibc on
 * x86-64: the other operand when one is NaN, the second when they compare
 * equal, so fmax(-0.0, +0.0) is +0.0). Without -ffinite-math-only the
 * compiler calls the library through the PLT, which in a step's inner loops
 * costs more than the comparison. tests/test_fminmax.c checks them against
 * the library on zeros of both signs, infinities and NaNs. */
#ifndef BSIM_FMINMAX_H
#define BSIM_FMINMAX_H

static inline double bsim_fmax(double a, double b)
{
	return a > b || b != b ? a : b;
}

static inline double bsim_fmin(double a, double b)
{
	return a < b || b != b ? a : b;
}

#endif
