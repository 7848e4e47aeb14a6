/* fmax and fmin, inlined and with signed zeros ordered: the maximumNumber
 * and minimumNumber of IEEE 754-2019 (-0 < +0; a NaN operand gives the
 * other). C leaves the sign of fmax(+0.0, -0.0) to the implementation, and
 * the compiler, taking fmax to be commutative, may swap its operands, so
 * the library's result for a pair of zeros can change with the build; here
 * it cannot (a beam's peak angle that saw -0.0 and +0.0 is +0.0, whatever
 * the order). Inline also because without -ffinite-math-only the compiler
 * calls the library through the PLT, which in a step's inner loops costs
 * more than the comparison. tests/test_step_caches.c checks them. */
#ifndef BSIM_UTIL_FMINMAX_H
#define BSIM_UTIL_FMINMAX_H

#include <math.h>

static inline double bsim_fmax(double a, double b)
{
	if (a > b || b != b)
		return a;
	if (a == b && signbit(b)) /* -0 and +0: +0; equal otherwise: either */
		return a;
	return b;
}

static inline double bsim_fmin(double a, double b)
{
	if (a < b || b != b)
		return a;
	if (a == b && signbit(a))
		return a;
	return b;
}

#endif
