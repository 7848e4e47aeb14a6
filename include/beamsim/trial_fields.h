/* The columns of a trial's record, trials.csv's row: each described once,
 * here, with its name, kind, unit and meaning and how its value is had
 * from a trial. The CSV writer, the MATLAB results and the test of the
 * documentation's table (docs/files.md) are made from this list; its
 * order is the file's. After these columns a sweep writes one per grid
 * axis. */
#ifndef BSIM_TRIAL_FIELDS_H
#define BSIM_TRIAL_FIELDS_H

#include <stddef.h>
#include <stdio.h>

#include "beamsim/base.h"
#include "beamsim/trial.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
	BSIM_FIELD_INT,      /* an integer */
	BSIM_FIELD_REAL,     /* a number, written "%.10g" */
	BSIM_FIELD_MEASURED, /* a number, or nothing (NaN): not measured */
	BSIM_FIELD_WORD,     /* a word of a fixed list (words, n_words) */
	BSIM_FIELD_TEXT,     /* a text made from the trial */
} bsim_field_kind;

/* A row of trials.csv: trial `trial` (0-based) of group `group`, its result,
 * and its log (NULL: none; a lattice's path is then its final gate). */
typedef struct bsim_trial_row {
	int group, trial;
	const bsim_trial_result *r;
	const bsim_trial_log *log;
} bsim_trial_row;

typedef struct bsim_trial_field {
	const char *name; /* the column's */
	bsim_field_kind kind;
	const char *unit; /* SI ("m", "m/s", "s", "rad", "rad/s", "J"), "" none */
	const char *help; /* what it is, in a line */
	int index;        /* 1: a 0-based index (a result in MATLAB counts it from 1) */
	/* INT, REAL and MEASURED: its value; WORD: its index into words */
	double (*value)(const bsim_trial_row *row);
	/* WORD: the list, index 0 first */
	const char *const *words;
	int n_words;
	/* TEXT: its text written to out */
	void (*text)(FILE *out, const bsim_trial_row *row);
} bsim_trial_field;

/* The columns, in trials.csv's order; *n gets how many. */
BSIM_API const bsim_trial_field *bsim_trial_fields(int *n);

/* Field f of row written as trials.csv writes it (no separator). */
BSIM_API void bsim_trial_field_write(FILE *out, const bsim_trial_field *f,
                                     const bsim_trial_row *row);

#ifdef __cplusplus
}
#endif
#endif
