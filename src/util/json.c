/* JSON leaf values; see util/json.h. */
#include "util/json.h"

#include <inttypes.h>
#include <math.h>
#include <stdlib.h>

/* The escape for byte c, or NULL if it is written as it is. Control
 * characters without a short name get \u00XX from the caller. */
static const char *json_escape(unsigned char c)
{
	switch (c) {
	case '"':
		return "\\\"";
	case '\\':
		return "\\\\";
	case '\n':
		return "\\n";
	case '\r':
		return "\\r";
	case '\t':
		return "\\t";
	}
	return NULL;
}

void bsim_json_string(FILE *f, const char *s)
{
	fputc('"', f);
	for (const unsigned char *p = (const unsigned char *)s; *p; p++) {
		const char *esc = json_escape(*p);
		if (esc)
			fputs(esc, f);
		else if (*p < 0x20)
			fprintf(f, "\\u%04x", *p);
		else
			fputc(*p, f);
	}
	fputc('"', f);
}

/* %.17g always round-trips a double, but prints 0.42 as
 * "0.41999999999999998"; trying 15 and 16 digits first keeps such values
 * short and still exact. */
void bsim_json_number(FILE *f, double x)
{
	char buf[32];
	if (!isfinite(x)) {
		fputs("null", f);
		return;
	}
	for (int prec = 15; prec <= 17; prec++) {
		snprintf(buf, sizeof buf, "%.*g", prec, x);
		if (strtod(buf, NULL) == x)
			break;
	}
	fputs(buf, f);
}

void bsim_json_u64(FILE *f, uint64_t x)
{
	if (x <= (UINT64_C(1) << 53))
		fprintf(f, "%" PRIu64, x);
	else
		fprintf(f, "\"%" PRIu64 "\"", x);
}

void bsim_json_pair(FILE *f, const double v[2])
{
	fputc('[', f);
	bsim_json_number(f, v[0]);
	fputs(", ", f);
	bsim_json_number(f, v[1]);
	fputc(']', f);
}

void bsim_json_member_int(FILE *f, const char *sep, const char *name, const void *v, size_t size)
{
	(void)size;
	fprintf(f, "%s\"%s\": %d", sep, name, *(const int *)v);
}

void bsim_json_member_long(FILE *f, const char *sep, const char *name, const void *v, size_t size)
{
	(void)size;
	fprintf(f, "%s\"%s\": %ld", sep, name, *(const long *)v);
}

void bsim_json_member_ulong(FILE *f, const char *sep, const char *name, const void *v, size_t size)
{
	(void)size;
	fprintf(f, "%s\"%s\": %lu", sep, name, *(const unsigned long *)v);
}

void bsim_json_member_doubles(FILE *f, const char *sep, const char *name, const void *v,
                              size_t size)
{
	const double *d = v;
	size_t n = size / sizeof *d;
	fprintf(f, "%s\"%s\": %s", sep, name, n > 1 ? "[" : "");
	for (size_t i = 0; i < n; i++) {
		fputs(i ? ", " : "", f);
		bsim_json_number(f, d[i]);
	}
	fputs(n > 1 ? "]" : "", f);
}
