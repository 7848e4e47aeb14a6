/* What the MEX functions (beamsim_run, beamsim_sweep, beamsim_landscape)
 * share: their name-value arguments read into the library's types, the
 * structs they return, and their errors. Only the plain mex.h API, so that
 * Octave's `mkoctfile --mex` and MATLAB's `mex` build the same source.
 *
 * Indices: what MATLAB counts is counted from 1. The 'group' and 'trial'
 * arguments and the group and trial fields and columns are those of
 * trials.csv plus 1 (group 1 is trials.csv's group 0), beams are numbered
 * from 1 as in every output (theta1, landscape_beam), and 0 stands for no
 * beam. What the scene file counts keeps its own count: a 'set' key names
 * beams.0 as the YAML file does. */
#ifndef BSIM_MEX_H
#define BSIM_MEX_H

#include <stdint.h>

#include "mex.h"

#include "beamsim/beamsim.h"

/* Strings made from MATLAB values for one call, freed together. */
typedef struct bmx_pool {
	int n, cap;
	char **s;
} bmx_pool;

/* Takes s (malloc'd) into the pool; NULL if s is NULL or out of memory
 * (s freed). */
char *bmx_pool_take(bmx_pool *p, char *s);
void bmx_pool_free(bmx_pool *p);

/* The name-value pairs prhs[first ..] against the names a function takes:
 * values[i] is the value of names[i] (matched ignoring case; a later pair
 * wins), NULL if not given. BSIM_EINPUT naming the function, the argument
 * and the names it takes otherwise. */
int bmx_pairs(int nrhs, const mxArray *prhs[], int first, const char *const *names, int n_names,
              const mxArray **values, bsim_error *err);

/* A character row vector as a string (from the pool). */
int bmx_text(const char *name, const mxArray *a, bmx_pool *p, const char **out, bsim_error *err);
/* A real integer scalar in [lo, hi]. */
int bmx_long(const char *name, const mxArray *a, long lo, long hi, long *out, bsim_error *err);
/* A seed: an integer scalar >= 0 (a double up to 2^53, or an integer class). */
int bmx_seed(const char *name, const mxArray *a, uint64_t *out, bsim_error *err);
/* A logical or numeric scalar: 0 or 1. */
int bmx_flag(const char *name, const mxArray *a, int *out, bsim_error *err);
/* A real finite scalar. */
int bmx_double(const char *name, const mxArray *a, double *out, bsim_error *err);

/* A value as the YAML text of a --set value: a number in the shortest
 * text that reads back to the same double (an integer without a point), a
 * logical as true/false, a vector as [a, b, ...], text as it is. */
int bmx_value_text(const char *name, const mxArray *a, bmx_pool *p, const char **out,
                   bsim_error *err);

/* 'set' (and 'backend_opt'): a cell {KEY, VALUE, KEY, VALUE, ...} as
 * overrides with the origin "--set KEY=VALUE" of the command line's --set,
 * so that a message about one is the program's. */
int bmx_overrides(const char *name, const mxArray *a, bmx_pool *p, bsim_override **ov, int *n,
                  bsim_error *err);

/* 'grid': a cell {KEY, VALUES, ...}: VALUES a numeric or logical vector
 * (one value each) or a cell of values, as --grid KEY=V1,V2,... (the
 * axis's origin "--grid KEY", a value named "--grid KEY=VALUE" as the
 * program names it). The axes and their arrays are malloc'd
 * (bmx_grid_free), the strings the pool's. */
int bmx_grid(const char *name, const mxArray *a, bmx_pool *p, bsim_grid_axis **axes, int *n,
             bsim_error *err);
void bmx_grid_free(bsim_grid_axis *axes, int n);

/* 'backend' and 'backend_opt': the backend by name (NULL: the default
 * backend) with its options, checked against its knobs. */
int bmx_backend(const char *name, const bsim_override *kv, int n_kv, const bsim_backend **b,
                bsim_options *opts, bsim_error *err);

/* ---- what the functions return ---------------------------------------- */

/* s.field = v (the field added if s has none), element i of a struct array. */
void bmx_set(mxArray *s, mwIndex i, const char *field, mxArray *v);
mxArray *bmx_scalar(double x);
mxArray *bmx_string(const char *text);
mxArray *bmx_u64(uint64_t x);
mxArray *bmx_row(const double *x, int n);
/* An n x 1 double column; *data its values. */
mxArray *bmx_column(size_t n, double **data);

/* A member of a struct as it is, at v of size bytes: a number (several
 * doubles a row of them), as run --json and summary.json give it. */
mxArray *bmx_member_int(const void *v, size_t size);
mxArray *bmx_member_long(const void *v, size_t size);
mxArray *bmx_member_ulong(const void *v, size_t size);
mxArray *bmx_member_doubles(const void *v, size_t size);
/* Member m of the struct at p as the field m of element i of s (an
 * X-macro's list names it, beamsim/trial.h, sweep.h); its kind from its
 * type: a type not listed does not compile. */
#define BMX_MEMBER(s, i, p, m)                                                                     \
	bmx_set(s, i, #m,                                                                          \
	        _Generic(&(p)->m,                                                                  \
	                const int *: bmx_member_int,                                               \
	                const long *: bmx_member_long,                                             \
	                const unsigned long *: bmx_member_ulong,                                   \
	                const double *: bmx_member_doubles,                                        \
	                const double(*)[2]: bmx_member_doubles)(&(p)->m, sizeof(p)->m))

/* Distinct texts, each kept once, in order of first appearance: the
 * labels of a text column whose rows are codes from 1 into them, so that a
 * column of a million trials holds a code a row, not a char array. */
typedef struct bmx_labels {
	char **text; /* n (malloc'd) */
	size_t n, cap;
	size_t *slot; /* n_slots (a power of 2): index + 1, 0 free */
	size_t n_slots;
} bmx_labels;
/* The code (from 1) of text in l, added if new; -1 if out of memory. */
long bmx_labels_code(bmx_labels *l, const char *text);
/* l's texts as an n x 1 cell of char rows. */
mxArray *bmx_labels_cell(const bmx_labels *l);
void bmx_labels_free(bmx_labels *l);
/* texts[0 .. n) as an n x 1 cell of char rows. */
mxArray *bmx_cellstr(const char *const *texts, int n);
/* n codes (from 1, of n_labels labels) as an n x 1 column of the narrowest
 * class that holds them: uint8, uint16 or uint32. */
mxArray *bmx_codes(const uint32_t *codes, size_t n, size_t n_labels);
/* A text column: t.name = codes (a column of codes from 1 into labels, an
 * n x 1 cell) and l.name = labels; where `categorical` exists (MATLAB),
 * t.name = categorical(codes, 1:numel(labels), labels) instead, which
 * holds as little (Octave has none). */
void bmx_text_field(mxArray *t, mxArray *l, const char *name, mxArray *codes, mxArray *labels);

/* A field name MATLAB accepts made of key, as MATLAB's and Octave's
 * jsondecode make one (matlab.lang.makeValidName): every character other
 * than a letter, digit or underscore becomes an underscore, and a name that
 * does not start with a letter gets an x in front. */
void bmx_field_name(const char *key, char *buf, size_t size);

/* The names that pick a trial, first of beamsim_run's and beamsim_world
 * 'open''s, in this order. */
enum {
	BMX_TRIAL_SEED,
	BMX_TRIAL_GROUP,
	BMX_TRIAL_TRIAL,
	BMX_TRIAL_BACKEND,
	BMX_TRIAL_BACKEND_OPT,
	BMX_TRIAL_SET,
	BMX_TRIAL_GRID,
	BMX_TRIAL_NAMES
};
#define BMX_TRIAL_NAME_LIST "seed", "group", "trial", "backend", "backend_opt", "set", "grid"

/* A trial as beamsim_run names it, opened (beamsim/replay.h): the replay,
 * its backend (a stored run's own, else 'backend' with 'backend_opt') and
 * options. */
typedef struct bmx_trial {
	bsim_grid_axis *grid;
	int n_grid;
	bsim_replay *rp;
	const bsim_backend *backend;
	bsim_options opts;
} bmx_trial;
/* path and v[0 .. BMX_TRIAL_NAMES) (bmx_pairs's values of those names,
 * NULL where not given) into t; BSIM_OK or err's code. bmx_trial_free
 * releases t either way. */
int bmx_trial_open(const mxArray *path, const mxArray *const *v, bmx_pool *pool, bmx_trial *t,
                   bsim_error *err);
void bmx_trial_free(bmx_trial *t);

/* err's message for a group or trial out of range, counted from 1 as the
 * arguments count: "--group 30: expected 0 to 29 (h1.yaml has 30 groups)"
 * becomes "'group' 31: expected 1 to 30 (h1.yaml has 30 groups)"; its
 * code (BSIM_EINPUT if none). */
int bmx_from_one(bsim_error *err);

/* The error of err as a MATLAB error: identifier beamsim:input (bad
 * arguments or files, the program's exit status 2), beamsim:failed (1),
 * beamsim:disagree (3) or beamsim:stopped; the message is the line the
 * program prints after "beamsim: ". Does not return. */
void bmx_fail(const bsim_error *err);

#endif
