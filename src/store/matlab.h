/* MATLAB twins of beamsim's files: every table (CSV) and record (JSON) it
 * writes also as a .mat file (level 5, zlib-compressed, libmatio) that
 * MATLAB's `load` and scipy.io.loadmat read directly.
 *
 * A twin is made from the file it twins, after that file is complete, so
 * that both hold the same values and a column added to a CSV appears in its
 * twin without further code; but trials.mat, a sweep's largest, is made
 * from the trials themselves through their field table as trials.csv is
 * written (bsim_matlab_trials below), to the same bytes, without reading
 * the file back:
 *
 * - a CSV table becomes one struct of column vectors, one field per column
 *   (names made MATLAB identifiers: "max_theta1", "effects_propulsion_force"),
 *   numbers as n x 1 doubles (an empty cell is NaN), text as n x 1 cell
 *   arrays of char;
 * - a JSON object becomes a struct; a list of numbers a 1 x n row; a list
 *   of objects a table, that is a struct of n x 1 columns (a list of k
 *   numbers in each object an n x k matrix, an object a nested table); a
 *   string a char row; true / false 1 / 0; null NaN.
 *
 * Each file is written to a temporary name and renamed, like every output
 * of beamsim: it appears whole or not at all. */
#ifndef BSIM_STORE_MATLAB_H
#define BSIM_STORE_MATLAB_H

#include <stddef.h>

#include "beamsim/error.h"
#include "beamsim/experiment.h"
#include "beamsim/trial.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The twin's path: path with a final ".csv" or ".json" replaced by ".mat"
 * (".mat" appended otherwise). BSIM_EFAIL if it does not fit size. */
int bsim_matlab_path(const char *path, char *out, size_t size, bsim_error *err);

/* The CSV table at csv_path as the struct variable var in mat_path.
 * BSIM_EINPUT naming file and line if the table is malformed (the messages
 * of util/csv_table.h).
 *
 * The table is read as a stream and held as it is written: 8 bytes a cell
 * of a numeric column, a pointer a cell (8 bytes, and 8 more for matio's
 * cell array) of a text column plus about 260 bytes per distinct string.
 * A table of more rows than the limit mat_rows (beamsim/limits.h) gets no
 * twin: it is still checked (a malformed one is BSIM_EINPUT as above), any
 * earlier file at mat_path is removed (a twin never belongs to another
 * table), a note says so (bsim_note, beamsim/error.h: by default on
 * standard error, "beamsim: trials.csv: 2000000 rows, over the limit
 * mat_rows = N: no trials.mat; ..."), and the result is BSIM_OK with the
 * note in err->msg (err->code
 * BSIM_OK): a caller goes on, and the run succeeds without the twin. On
 * any other BSIM_OK err->msg is empty. */
int bsim_matlab_from_csv(const char *csv_path, const char *mat_path, const char *var,
                         bsim_error *err);

/* The JSON file at json_path as the variable var in mat_path. */
int bsim_matlab_from_json(const char *json_path, const char *mat_path, const char *var,
                          bsim_error *err);

/* trials.csv's twin made from the trials themselves as trials.csv's
 * writer is given them (store/trials_csv.h), not by reading the file back:
 * a column per field of beamsim/trial_fields.h, in its order, then one per
 * grid axis; a number as the file holds it (bsim_trial_field_number: to
 * the digits it is written with), so the twin is the one
 * bsim_matlab_from_csv would make of the file, byte for byte. Its columns
 * are held as they grow, as bsim_matlab_from_csv holds them; over the
 * limit mat_rows nothing is held and write gives the same note. */
typedef struct bsim_matlab_trials bsim_matlab_trials;

/* The twin of e's trials.csv (its first axes columns of grid axes, the
 * others added as a sweep's twin adds them); NULL if out of memory. */
bsim_matlab_trials *bsim_matlab_trials_open(const bsim_experiment *e, int axes);

/* Trials first .. first + n - 1 of a sweep of `trials` per group (logs may
 * be NULL), as bsim_trials_csv_rows takes them. */
void bsim_matlab_trials_rows(bsim_matlab_trials *t, long first, long n, int trials,
                             const bsim_trial_result *results, const bsim_trial_log *logs);

/* The twin written beside csv_path (bsim_matlab_path), variable `trials`;
 * BSIM_EFAIL if out of memory on the way or on a write error. */
int bsim_matlab_trials_write(bsim_matlab_trials *t, const char *csv_path, bsim_error *err);

/* Frees t; NULL is fine. */
void bsim_matlab_trials_free(bsim_matlab_trials *t);

/* The twins of a sweep's directory: summary.mat (variable `summary`),
 * trials.mat (`trials`; made from trials.csv only if with_trials, else
 * its writer made it, bsim_matlab_trials) and, when the directory holds it,
 * trajectories.mat (`trajectories`). A table with a `group` column holds
 * the grid values of each row's group by name, as the columns of
 * trials.csv do (trajectories.effects_propulsion_force(i) of row i),
 * numbers as doubles: those the CSV lacks are added. A table over the
 * limit mat_rows gets no twin, as bsim_matlab_from_csv says. */
int bsim_matlab_sweep(const char *dir, const bsim_experiment *e, int with_trials, bsim_error *err);

#ifdef __cplusplus
}
#endif
#endif
