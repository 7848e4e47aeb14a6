/* The CPython extension beamsim._beamsim over libbeamsim: what its files
 * share. The functions are called by the package beamsim (__init__.py),
 * which turns the user's arguments (dicts, numbers) into the strings the
 * command line would give, so that every check and every message is the
 * library's. */
#ifndef BSIM_PYB_H
#define BSIM_PYB_H

#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <stdint.h>

#include "beamsim/beamsim.h"

/* Raises the exception of a failed call: ValueError for bad input
 * (BSIM_EINPUT), RuntimeError otherwise, with err's one line. NULL. */
PyObject *pyb_raise(int rc, const bsim_error *err);

/* The UTF-8 text of the str o, which the library reads as a C string: NULL
 * with TypeError if o is no str, or ValueError naming what ("set: the
 * key") if it holds a NUL, which would end the text there
 * (bsim_error_nul_check). Valid while o lives. */
const char *pyb_text(PyObject *o, const char *what);

/* --set overrides from a sequence of (key, value, origin) str tuples. The
 * strings are the tuples' own (valid while seq lives). -1 with an
 * exception set. */
typedef struct pyb_sets {
	int n;
	bsim_override *ov;
} pyb_sets;
int pyb_sets_from(PyObject *seq, pyb_sets *s);
void pyb_sets_free(pyb_sets *s);

/* --grid axes from a sequence of (key, [values], origin) tuples. */
typedef struct pyb_grid {
	int n;
	bsim_grid_axis *axes;
} pyb_grid;
int pyb_grid_from(PyObject *seq, pyb_grid *g);
void pyb_grid_free(pyb_grid *g);

/* A call's set= and grid=, both read or neither (-1 with an exception set,
 * nothing to free). */
int pyb_sets_grid_from(PyObject *sets, PyObject *grid, pyb_sets *s, pyb_grid *g);

/* A call's seed=: None leaves *has_seed 0; else *has_seed 1 and *seed. -1
 * with an exception set. */
int pyb_seed_from(PyObject *o, int *has_seed, uint64_t *seed);

/* A backend "NAME[:KEY=VALUE]..." (NULL or None: the default backend) with
 * the "KEY=VALUE" options of seq (applied first; the spec's win), checked.
 * NULL with an exception set. */
const bsim_backend *pyb_backend(const char *spec, PyObject *seq, bsim_options *opts);

/* A NumPy array of n doubles (or int32 when ints), copied from data with
 * the given stride (values between consecutive elements). New reference. */
PyObject *pyb_column(const double *data, long n, long stride, int ints);
/* A 1-, 2- or 3-D float64 array copied from data (C order). */
PyObject *pyb_array(int nd, const long *dims, const double *data);
/* A NumPy int32 array of the n ints v. */
PyObject *pyb_int_array(const int *v, long n);

/* A NumPy array of n int64 (ints) or float64 values that takes over data
 * (malloc'd, at least n values; freed with the array). New reference, or
 * NULL with data still the caller's. */
PyObject *pyb_adopt(void *data, long n, int ints);
/* A NumPy str array of n rows, row k the string labels[codes[k]] (labels a
 * list of str; NULL if n is 0), as wide as the longest. New reference. */
PyObject *pyb_text_column(const uint32_t *codes, long n, PyObject *labels);

/* Sets d[key] = value and drops the reference to value. -1 on failure
 * (value NULL included). */
int pyb_set(PyObject *d, const char *key, PyObject *value);

/* The module's functions. */
/* A trial named as beamsim.run names it (run.c): a scene, an experiment's
 * (group, trial) or a stored run's, with the seed, the backend (for a
 * stored run: a side's label) and its options, the overrides and the grid
 * axes; the replay's definition (def) borrows them. 0, or -1 with a Python
 * exception; pyb_trial_free releases it either way. */
typedef struct pyb_trial {
	bsim_replay_def def;
	int stored;                  /* a stored run's directory */
	const bsim_backend *backend; /* NULL for a stored run: its own */
	bsim_options opts;
	pyb_sets sets;
	pyb_grid grid;
} pyb_trial;
int pyb_trial_from(const char *path, PyObject *seed_o, long group, long trial,
                   const char *backend_spec, PyObject *sets_o, PyObject *opts_o, PyObject *grid_o,
                   pyb_trial *t);
void pyb_trial_free(pyb_trial *t);

PyObject *pyb_run(PyObject *self, PyObject *args, PyObject *kw);
/* register_backend(cls, name, description) (pybackend.c). */
PyObject *pyb_register_backend(PyObject *self, PyObject *args);
PyObject *pyb_sweep(PyObject *self, PyObject *args, PyObject *kw);
PyObject *pyb_compare(PyObject *self, PyObject *args, PyObject *kw);
PyObject *pyb_landscape(PyObject *self, PyObject *args, PyObject *kw);
/* markov_build, markov_predict and markov_validate (markov.c). */
PyObject *pyb_markov_build(PyObject *self, PyObject *args, PyObject *kw);
PyObject *pyb_markov_predict(PyObject *self, PyObject *args, PyObject *kw);
PyObject *pyb_markov_method(PyObject *self, PyObject *args);
PyObject *pyb_markov_validate(PyObject *self, PyObject *args, PyObject *kw);
PyObject *pyb_read_table(PyObject *self, PyObject *args);

/* Adds the type World (world.c) to the module: 0, or -1 with an
 * exception. */
int pyb_world_add(PyObject *module);

/* A progress callback for long runs (bsim_progress_fn), called from the
 * thread that started the run while the GIL is released: every so often
 * it takes the GIL, calls the user's callable(done, total) if any and
 * checks for signals (Ctrl-C); a Python exception sets stop, which ends
 * the run (BSIM_ESTOPPED), and is kept to be raised once it has. */
typedef struct pyb_progress {
	PyObject *fn;                   /* None or NULL: no callable */
	volatile sig_atomic_t stop;     /* the run's stop flag */
	double last;                    /* s, monotonic clock of the last check */
	PyObject *type, *value, *trace; /* the exception that stopped the run */
} pyb_progress;
void pyb_progress_init(pyb_progress *p, PyObject *fn);
void pyb_progress_update(void *user, long done, long total);
/* After the run, with the GIL: the kept exception raised (NULL) if there
 * is one, else the error of rc (pyb_raise) if rc is not BSIM_OK, else
 * Py_None (borrowed, a non-NULL marker). */
PyObject *pyb_progress_end(pyb_progress *p, int rc, const bsim_error *err);

/* What the runs of an experiment (sweep, compare, markov_build and
 * markov_validate) take alike: the seed, set=, grid= and the progress
 * callable. */
typedef struct pyb_run_inputs {
	int has_seed;
	uint64_t seed;
	pyb_sets sets;
	pyb_grid grid;
	pyb_progress progress;
} pyb_run_inputs;
/* progress_o checked to be None or a callable, then the seed, sets and
 * grid read: 0, or -1 with a Python exception and nothing held. */
int pyb_run_inputs_from(PyObject *seed_o, PyObject *sets_o, PyObject *grid_o, PyObject *progress_o,
                        pyb_run_inputs *in);
/* Frees the sets and grid (after the run). */
void pyb_run_inputs_free(pyb_run_inputs *in);
/* Sets a run's def's seed (where one was given), sets and grid from in:
 * fields the defs of sweep, compare, markov build and validate name
 * alike (in outlives the run). */
#define PYB_RUN_INPUTS_SET_SCENES(def, in)                                                         \
	do {                                                                                       \
		if ((in).has_seed) {                                                               \
			(def).has_seed = 1;                                                        \
			(def).seed = (in).seed;                                                    \
		}                                                                                  \
		(def).sets = (in).sets.ov;                                                         \
		(def).n_sets = (in).sets.n;                                                        \
		(def).grid = (in).grid.axes;                                                       \
		(def).n_grid = (in).grid.n;                                                        \
	} while (0)
/* The same and the progress and the names of resume and overwrite, as
 * sweep's, compare's and markov validate's defs have them. */
#define PYB_RUN_INPUTS_SET(def, in)                                                                \
	do {                                                                                       \
		PYB_RUN_INPUTS_SET_SCENES(def, in);                                                \
		(def).resume_option = "resume=True";                                               \
		(def).overwrite_option = "overwrite=True";                                         \
		(def).progress = pyb_progress_update;                                              \
		(def).progress_user = &(in).progress;                                              \
		(def).stop = &(in).progress.stop;                                                  \
	} while (0)

#endif
