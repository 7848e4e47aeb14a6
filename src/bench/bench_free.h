/* beamsim bench's free-flight figure (bench_free.c). */
#ifndef BSIM_BENCH_BENCH_FREE_H
#define BSIM_BENCH_BENCH_FREE_H

#include "beamsim/backend.h"
#include "beamsim/options.h"

typedef struct bench_free_args {
	const char *experiment; /* its scene, made free flight */
	long trials;            /* per group, 0: the experiment's */
	const bsim_backend *backend;
	const bsim_options *opts;
	int only; /* 0: both; 1: beamsim's sweep only; 2: the minimal loop only */
} bench_free_args;

typedef struct bench_free_result {
	long trials, steps;     /* beamsim's, equal to the minimal loop's */
	double beamsim_seconds; /* wall, one thread */
	double minimal_seconds; /* wall */
	double checksum;        /* of the minimal loop's final states */
} bench_free_result;

/* Runs the free-flight sweep and the minimal loop; 0, or the exit status
 * of an error it printed. */
int bench_free(const bench_free_args *a, bench_free_result *out);

#endif
