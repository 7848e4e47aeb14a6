/* Box2D 2.4.1 times every phase of b2World::Step with its b2Timer (into
 * b2Profile), and on Linux a b2Timer reads the clock with gettimeofday
 * (src/common/b2_timer.cpp): two reads for the step, two each for collide,
 * solve, the broad phase and continuous collision (b2_world.cpp), seven per
 * island (b2_island.cpp). No setting turns them off, and a clock read costs
 * tens of nanoseconds in a virtual machine, so part of what bench measures
 * for Box2D is its own timing. To state that part, the program (not the
 * library) defines gettimeofday: the dynamic linker binds the Box2D
 * library's calls to this definition, which counts each call and passes it
 * on to the C library's. Only beamsim itself reads the count; nothing in beamsim calls
 * gettimeofday. */
#define _GNU_SOURCE

#include "bench/bench_clock.h"

#include <dlfcn.h>
#include <stdlib.h>
#include <sys/time.h>

#include "util/clock.h"

typedef int (*gettimeofday_fn)(struct timeval *, void *);

static unsigned long reads;
static gettimeofday_fn next_gettimeofday;

int gettimeofday(struct timeval *restrict tv, void *restrict tz)
{
	if (!next_gettimeofday)
		next_gettimeofday = (gettimeofday_fn)dlsym(RTLD_NEXT, "gettimeofday");
	__atomic_fetch_add(&reads, 1UL, __ATOMIC_RELAXED);
	return next_gettimeofday(tv, tz);
}

unsigned long bench_clock_reads(void)
{
	return __atomic_load_n(&reads, __ATOMIC_RELAXED);
}

static int cmp_double(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

double bench_clock_read_seconds(void)
{
	enum { REPEATS = 7, CALLS = 200000 };
	double t[REPEATS];
	struct timeval tv;
	for (int r = 0; r < REPEATS; r++) {
		double t0 = bsim_clock_seconds();
		for (int i = 0; i < CALLS; i++)
			gettimeofday(&tv, NULL);
		t[r] = (bsim_clock_seconds() - t0) / CALLS;
	}
	qsort(t, REPEATS, sizeof *t, cmp_double);
	return t[REPEATS / 2];
}
