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
#include "beamsim/lattice.h"
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
	BSIM_FIELD_FIXED,    /* a number, written "%.6f" */
} bsim_field_kind;

/* A row of trials.csv: trial `trial` (0-based) of group `group`, its result,
 * and its log (NULL: none; a lattice's path is then its final gate). A row
 * of a lattice's gate_entries.csv or beam_peaks.csv is one of the log's
 * entries or peaks, number seq, on the lattice def (its beams' gates). */
typedef struct bsim_trial_row {
	int group, trial;
	const bsim_trial_result *r;
	const bsim_trial_log *log;
	int seq;
	const bsim_lattice_def *def;
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
	/* INT and REAL read back (trials.csv read by regress and compare's
	 * file sides): the member of bsim_trial_result the number goes to, at
	 * back bytes from its start, of back_size bytes (an int, a long or a
	 * double; a sum, work_in or losses, into its first term, which then
	 * holds the whole). back_size 0: not read back (an index, a word, a
	 * text, overlap_max, t_exit). */
	size_t back, back_size;
} bsim_trial_field;

/* A member of a trial's result, bsim_trial_result, as it lies in memory
 * (a nested struct's members by their path, "ledger.e_start"); also the
 * gate entries and beam peaks a lattice's journal record holds. A journal
 * stores results byte for byte: its header names every member with its
 * kind, offset and size (bsim_trial_record_fields), so that a journal of
 * another layout is refused, naming the member that differs. */
typedef struct bsim_trial_member {
	const char *name; /* "t_end", "ledger.e_start", "gate_entry.x" */
	const char *kind; /* "i32", "u32" (an enum), "i64", "u64", "f64" */
	size_t offset;    /* bytes from the start of its struct */
	size_t size;      /* bytes; an array's whole (max_theta: 16) */
} bsim_trial_member;

/* The members of bsim_trial_result (in the order of beamsim/trial.h's
 * lists, BSIM_TRIAL_RESULT_PLAIN ...), then bsim_gate_entry's and
 * bsim_beam_peak's; *n gets how many. */
BSIM_API const bsim_trial_member *bsim_trial_members(int *n);

/* The text a journal's header holds for its records: a line a struct
 * ("bsim_trial_result 296") followed by a line a member ("t_end f64 16
 * 8": name, kind, offset, size), made from bsim_trial_members. */
BSIM_API const char *bsim_trial_record_fields(void);

/* The columns, in trials.csv's order; *n gets how many. */
BSIM_API const bsim_trial_field *bsim_trial_fields(int *n);

/* trials.csv's column of that name, or NULL: other records that show a
 * trial's outcome, type or location (a comparison's pairs.csv, a side's
 * columns) take the column's description from here. */
BSIM_API const bsim_trial_field *bsim_trial_field_find(const char *name);

/* The columns of a lattice's gate_entries.csv (a row a gate entry, its
 * state in the gate's frame) and of its beam_peaks.csv (a row a beam that
 * moved), in their files' order, as bsim_trial_fields; *n gets how many. */
BSIM_API const bsim_trial_field *bsim_gate_entry_fields(int *n);
BSIM_API const bsim_trial_field *bsim_beam_peak_fields(int *n);

/* The n fields' names as a CSV header line, or row's values as a CSV line,
 * to out (each ended by a line feed). */
BSIM_API void bsim_trial_fields_header(FILE *out, const bsim_trial_field *f, int n);
BSIM_API void bsim_trial_fields_line(FILE *out, const bsim_trial_field *f, int n,
                                     const bsim_trial_row *row);

/* Field f of row as a number as trials.csv holds it (an INT, REAL or
 * MEASURED field; a REAL to the ten digits it is written with, what
 * reading the file gives), NaN for a MEASURED field not measured. */
BSIM_API double bsim_trial_field_number(const bsim_trial_field *f, const bsim_trial_row *row);

/* Field f of row written as trials.csv writes it (no separator). */
BSIM_API void bsim_trial_field_write(FILE *out, const bsim_trial_field *f,
                                     const bsim_trial_row *row);

#ifdef __cplusplus
}
#endif
#endif
