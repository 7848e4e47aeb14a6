/* Limits on what an input may ask for. A scene or experiment that is valid
 * YAML with valid values can still ask for more than a machine has: a grid
 * of 10^9 groups, a random force refreshed 10^9 times a second, a trial of
 * 10^12 beam-steps. Loading checks these limits and stops with one message
 * naming the field, the value and the limit, and how to raise it
 * (`--limit NAME=N` on the command line, bsim_limits_set in a program).
 *
 * The limits are process-wide, like GSL's error handler: set them once
 * before loading, not while other threads load. */
#ifndef BSIM_LIMITS_H
#define BSIM_LIMITS_H

#include "beamsim/base.h"
#include "beamsim/error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The sizes of paths, in one place. A directory a caller names (an output
 * directory, a stored run) may be up to BSIM_DIR_MAX bytes. beamsim appends
 * names of at most BSIM_NAME_MAX bytes to it (a staging area, a side's
 * folder, inputs/scene.yaml, NAME.tmp.PID); a buffer holding a directory it
 * derived has BSIM_PATH_MAX - BSIM_NAME_MAX bytes, one holding any path
 * BSIM_PATH_MAX, so that a file name appended to a derived directory always
 * fits. A path that would not fit is refused with "path too long", never
 * cut. */
#define BSIM_DIR_MAX  900
#define BSIM_NAME_MAX 200
#define BSIM_PATH_MAX 1400

typedef struct bsim_limits {
	double input_bytes; /* size of a scene or experiment file, or a --set value */
	double groups;      /* groups of an experiment's grid */
	double trials;      /* groups x trials of one sweep or comparison */
	double schedule;    /* random-force values of one trial: max_steps dt frequency */
	double beam_steps;  /* max_steps x beams of one trial */
	double mat_rows;    /* rows of a CSV table given a .mat twin */
} bsim_limits;

/* The defaults: 1 MiB, 100,000 groups, 10^7 trials (a sweep streams its
 * trials to disk; a comparison holds them in memory: docs/robustness.md
 * "Memory"), 10^6 random-force values (8 MB per thread), 10^8 beam-steps
 * (about 15 s of one core for the thesis backend on a gate) and 1,500,000
 * rows of a table with a .mat twin (about 230 bytes a row of trials.csv
 * while the twin is written, 130 of a trajectory; a larger table gets no
 * twin, and the run goes on). */
BSIM_API bsim_limits bsim_limits_default(void);

/* The limits in force (the defaults until bsim_limits_set). */
BSIM_API const bsim_limits *bsim_limits_get(void);

/* Replaces the limits in force; NULL restores the defaults. */
BSIM_API void bsim_limits_set(const bsim_limits *l);

/* Applies "NAME=N" (e.g. "groups=1e6") to l. BSIM_EINPUT naming the known
 * names if NAME is unknown, or if N is not a number >= 1. */
BSIM_API int bsim_limits_parse(bsim_limits *l, const char *text, bsim_error *err);

/* The memory the machine can still give a process, bytes: Linux's
 * MemAvailable (/proc/meminfo: free memory and the caches it may drop),
 * else the free physical pages; INFINITY if neither is known. For a
 * caller about to hold something that grows with the work (the bindings'
 * columns of a sweep's trials) to refuse it at once rather than be killed
 * half-way. */
BSIM_API double bsim_memory_available(void);

/* "(limit NAME = N; raise it with --limit NAME=M)" for messages. */
BSIM_API void bsim_limits_hint(char *buf, unsigned size, const char *name, double value);

#ifdef __cplusplus
}
#endif
#endif
