/* beamsim bench --lattice (bench_lattice.c). */
#ifndef BSIM_BENCH_BENCH_LATTICE_H
#define BSIM_BENCH_BENCH_LATTICE_H

#include <stdio.h>

#include "beamsim/backend.h"

typedef struct bench_lattice_args {
	const bsim_backend *backend, *vs; /* vs may be NULL */
	const bsim_options *opts, *vs_opts;
	long trials, vs_trials; /* per size; <= 0: 200 and 20 */
	const char *json;       /* NULL: none */
	FILE *report;           /* the tables (stderr when the JSON goes to stdout) */
} bench_lattice_args;

int bench_lattice(const bench_lattice_args *a);

/* trials trials (seed 1, group 0) of 1000 steps on the n x n lattice, the
 * world kept from trial to trial, setup included: their steps and wall
 * time, s. 0, or the exit status of an error it printed. */
int bench_lattice_long(const bsim_backend *b, const bsim_options *opts, int n, long trials,
                       long *steps, double *wall);

#endif
