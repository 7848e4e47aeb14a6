/* Spellings of numbers that look like another base; see util/decimal.h. */
#include "util/decimal.h"

#include <ctype.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int bsim_decimal_other_base(const char *t)
{
	while (isspace((unsigned char)*t))
		t++;
	if (*t == '+' || *t == '-')
		t++;
	return t[0] == '0' &&
	       ((strchr("xXoObB", t[1]) && t[1] != '\0') || isdigit((unsigned char)t[1]));
}

/* t as m * 10^e with |m| < 10^18: digits, an optional point and an
 * optional exponent; 0, or -1 if t is not that. */
static int decimal_parse(const char *t, int64_t *m, int *e)
{
	int neg = 0, digits = 0, frac = 0, point = 0;
	int64_t v = 0;
	long ex = 0;
	if (*t == '+' || *t == '-')
		neg = *t++ == '-';
	for (; *t; t++) {
		if (*t == '.' && !point) {
			point = 1;
		} else if (isdigit((unsigned char)*t)) {
			if (v == 0 && *t == '0') {
				/* leading zeros add no digits */
			} else if (++digits > 18) {
				return -1;
			}
			v = v * 10 + (*t - '0');
			frac += point;
		} else {
			break;
		}
	}
	if (*t == 'e' || *t == 'E') {
		char *end;
		ex = strtol(t + 1, &end, 10);
		if (end == t + 1 || ex > 300 || ex < -300)
			return -1;
		t = end;
	}
	if (*t != '\0')
		return -1;
	*m = neg ? -v : v;
	*e = (int)(ex - frac);
	return 0;
}

/* m * 10^k for k >= 0, 0 or -1 on overflow. */
static int scale10(int64_t *m, int k)
{
	for (; k > 0; k--)
		if (__builtin_mul_overflow(*m, 10, m))
			return -1;
	return 0;
}

int bsim_decimal_step(const char *a, const char *step, long i, char *buf, size_t size)
{
	int64_t ma, ms, v;
	int ea, es;
	if (bsim_decimal_other_base(a) || bsim_decimal_other_base(step) ||
	    decimal_parse(a, &ma, &ea) || decimal_parse(step, &ms, &es))
		return -1;
	int e = ea < es ? ea : es;
	if (scale10(&ma, ea - e) || scale10(&ms, es - e) || __builtin_mul_overflow(ms, i, &v) ||
	    __builtin_add_overflow(v, ma, &v) || v > 999999999999999999 || v < -999999999999999999)
		return -1;
	/* The digits of |v|, then the point -e digits from the right (zeros
	 * padded in front), the fraction's trailing zeros dropped. */
	char d[48];
	int n = snprintf(d, sizeof d, "%lld", (long long)(v < 0 ? -v : v));
	if (e >= 0) {
		if (n + e > 40)
			return -1;
		for (int k = 0; k < e && v != 0; k++)
			d[n++] = '0';
		d[n] = '\0';
		if ((size_t)n + 2 > size)
			return -1;
		snprintf(buf, size, "%s%s", v < 0 ? "-" : "", d);
		return 0;
	}
	int f = -e;
	char out[96];
	int k = 0;
	if (v < 0)
		out[k++] = '-';
	if (f > 60)
		return -1;
	if (n <= f) {
		out[k++] = '0';
		out[k++] = '.';
		for (int z = 0; z < f - n; z++)
			out[k++] = '0';
		memcpy(out + k, d, (size_t)n);
		k += n;
	} else {
		memcpy(out + k, d, (size_t)(n - f));
		k += n - f;
		out[k++] = '.';
		memcpy(out + k, d + n - f, (size_t)f);
		k += f;
	}
	while (out[k - 1] == '0')
		k--;
	if (out[k - 1] == '.')
		k--;
	out[k] = '\0';
	if ((size_t)k + 1 > size)
		return -1;
	memcpy(buf, out, (size_t)k + 1);
	return 0;
}
