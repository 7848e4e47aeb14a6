/* beamsim bench --memory (bench_memory.c). */
#ifndef BSIM_BENCH_BENCH_MEMORY_H
#define BSIM_BENCH_BENCH_MEMORY_H

#include <stdio.h>

typedef struct bench_memory_args {
	long trials;      /* of the large sweep; <= 0: 2,000,000 */
	long steps;       /* of the long trajectory; <= 0: 1,000,000 */
	const char *json; /* NULL: none */
	FILE *report;
} bench_memory_args;

int bench_memory(const bench_memory_args *a);

#endif
