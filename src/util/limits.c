/* Process-wide input limits; see beamsim/limits.h. */
#include "beamsim/limits.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* The defaults of beamsim/limits.h. */
#define LIMITS_DEFAULT                                                                             \
	{                                                                                          \
		.input_bytes = 1048576, .groups = 1e5, .trials = 1e7, .schedule = 1e6,             \
		.beam_steps = 1e8, .mat_rows = 1.5e6,                                              \
	}

static bsim_limits current = LIMITS_DEFAULT;

bsim_limits bsim_limits_default(void)
{
	return (bsim_limits)LIMITS_DEFAULT;
}

const bsim_limits *bsim_limits_get(void)
{
	return &current;
}

void bsim_limits_set(const bsim_limits *l)
{
	current = l ? *l : bsim_limits_default();
}

static const struct {
	const char *name;
	size_t offset;
} names[] = {
        {"input_bytes", offsetof(bsim_limits, input_bytes)},
        {"groups", offsetof(bsim_limits, groups)},
        {"trials", offsetof(bsim_limits, trials)},
        {"schedule", offsetof(bsim_limits, schedule)},
        {"beam_steps", offsetof(bsim_limits, beam_steps)},
        {"mat_rows", offsetof(bsim_limits, mat_rows)},
};

int bsim_limits_parse(bsim_limits *l, const char *text, bsim_error *err)
{
	const char *eq = strchr(text, '=');
	size_t len = eq ? (size_t)(eq - text) : strlen(text);
	for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
		if (strlen(names[i].name) != len || strncmp(text, names[i].name, len) != 0)
			continue;
		char *end = NULL;
		double v = eq ? strtod(eq + 1, &end) : NAN;
		/* Whole numbers up to 2^53, where a double still counts exactly. */
		if (!eq || end == eq + 1 || *end || !(v >= 1 && v <= 9007199254740992.0))
			return bsim_error_set(err, BSIM_EINPUT,
			                      "--limit %s: expected NAME=N with N a number >= 1",
			                      text);
		*(double *)((char *)l + names[i].offset) = floor(v);
		return BSIM_OK;
	}
	return bsim_error_set(err, BSIM_EINPUT,
	                      "--limit %s: expected one of input_bytes, groups, trials, "
	                      "schedule, beam_steps, mat_rows as NAME=N",
	                      text);
}

void bsim_limits_hint(char *buf, unsigned size, const char *name, double value)
{
	snprintf(buf, size, "limit %s = %.15g; raise it with --limit %s=N", name, value, name);
}

double bsim_memory_available(void)
{
	FILE *f = fopen("/proc/meminfo", "r");
	char line[256];
	double kib = -1;
	while (f && kib < 0 && fgets(line, sizeof line, f))
		if (sscanf(line, "MemAvailable: %lf kB", &kib) != 1)
			kib = -1;
	if (f)
		fclose(f);
	if (kib >= 0)
		return kib * 1024.0;
#if defined(_SC_AVPHYS_PAGES) && defined(_SC_PAGESIZE)
	long pages = sysconf(_SC_AVPHYS_PAGES), page = sysconf(_SC_PAGESIZE);
	if (pages > 0 && page > 0)
		return (double)pages * (double)page;
#endif
	return INFINITY;
}
