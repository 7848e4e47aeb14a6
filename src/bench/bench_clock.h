/* The clock reads of Box2D's profiling timers, counted (bench_clock.c). */
#ifndef BSIM_BENCH_BENCH_CLOCK_H
#define BSIM_BENCH_BENCH_CLOCK_H

/* gettimeofday calls made in this process so far. */
unsigned long bench_clock_reads(void);

/* The wall time of one gettimeofday call, s (the median of several
 * timings of many calls), made the way Box2D makes them. */
double bench_clock_read_seconds(void);

#endif
