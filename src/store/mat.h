/* MATLAB files (.mat, level 5, zlib-compressed) written with libmatio, so
 * that MATLAB's `load` and Python's scipy.io.loadmat read beamsim's tables
 * directly.
 *
 * A table becomes a struct of column vectors: one field per CSV column,
 * numbers as double columns (n x 1), text as cell arrays of char (n x 1).
 * Group parameters and other named values become nested 1 x 1 structs.
 * MATLAB field names must be valid identifiers (letters, digits, '_', a
 * letter first, at most 63 characters): bsim_mat_name turns a dotted key
 * such as "effects.propulsion.force" into effects_propulsion_force.
 *
 * The file is written under a temporary name, flushed to disk and renamed,
 * so it appears whole or not at all, like every output of beamsim. */
#ifndef BSIM_STORE_MAT_H
#define BSIM_STORE_MAT_H

#include <stddef.h>

#include "beamsim/error.h"

typedef enum {
	BSIM_MAT_DOUBLE,  /* rows x cols doubles, column-major (a column: cols = 1) */
	BSIM_MAT_STRINGS, /* rows strings: a rows x 1 cell array of char */
	BSIM_MAT_STRING,  /* one string: a char row vector */
	BSIM_MAT_STRUCT,  /* a 1 x 1 struct of the n_fields fields */
} bsim_mat_kind;

typedef struct bsim_mat_field {
	const char *name; /* a MATLAB identifier (bsim_mat_name makes one) */
	bsim_mat_kind kind;
	size_t rows, cols;                   /* DOUBLE: shape; STRINGS: rows */
	const double *data;                  /* DOUBLE */
	const char *const *strings;          /* STRINGS: rows entries; STRING: strings[0] */
	const struct bsim_mat_field *fields; /* STRUCT */
	int n_fields;
} bsim_mat_field;

/* Field constructors, for tables built in code. */
bsim_mat_field bsim_mat_column(const char *name, const double *data, size_t rows);
bsim_mat_field bsim_mat_matrix(const char *name, const double *data, size_t rows, size_t cols);
bsim_mat_field bsim_mat_strings(const char *name, const char *const *strings, size_t rows);
bsim_mat_field bsim_mat_string(const char *name, const char *const *string);
bsim_mat_field bsim_mat_struct(const char *name, const bsim_mat_field *fields, int n_fields);

/* Writes the file at path with one top-level variable per entry of vars
 * (usually one struct). BSIM_EFAIL naming path on any error, leaving no
 * file and any earlier file at path as it was. */
int bsim_mat_write(const char *path, const bsim_mat_field *vars, int n_vars, bsim_error *err);

/* A MATLAB identifier from any key into out (size >= 64): characters
 * other than letters, digits and '_' become '_', a leading digit or '_'
 * gets an "x" in front, and the result is cut to 63 characters. */
void bsim_mat_name(const char *key, char *out, size_t size);

#endif
