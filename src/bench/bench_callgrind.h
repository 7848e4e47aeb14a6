/* beamsim bench --callgrind and --measure (bench_callgrind.c). */
#ifndef BSIM_BENCH_BENCH_CALLGRIND_H
#define BSIM_BENCH_BENCH_CALLGRIND_H

#include <stdio.h>

#include "beamsim/backend.h"

typedef struct bench_callgrind_args {
	const char *experiment; /* H1 unless --experiment */
	const char *backend;    /* its name, for the children */
	long trials;            /* per group for h1, free, minimal; <= 0: 4, 2, 2 */
	long lattice_trials;    /* T of the lattice measures */
	FILE *report;
} bench_callgrind_args;

/* The table of instructions per step; 0, or the exit status of an error
 * it printed. */
int bench_callgrind(const bench_callgrind_args *a);

typedef struct bench_measure_args {
	const char *what; /* h1, free, minimal, lattice:N */
	const char *experiment;
	long trials;
	const bsim_backend *backend;
	const bsim_options *opts;
} bench_measure_args;

/* One measure, its steps printed ("steps N") for bench_callgrind. */
int bench_measure(const bench_measure_args *a);

#endif
