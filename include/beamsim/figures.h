/* Figures of beamsim's output directories (beamsim plot DIR), drawn by
 * gnuplot from scripts beamsim writes: every figure is NAME.png and
 * NAME.svg with its data (NAME.dat, or NAME.*.dat) and its script NAME.gp
 * side by side, so that a user can restyle it and rerun `gnuplot NAME.gp`.
 *
 * What a directory holds decides what is drawn (docs/figures.md):
 *
 * - a sweep (summary.json, trials.csv): p_traverse over the grid's first
 *   two axes as a heat map with each cell's value and 95% interval;
 *   total, left-type and right-type traversal against each axis with 95%
 *   bands, one panel per combination of the other axes; and, when it kept
 *   trajectories (trajectories.csv), each group's bundle coloured by
 *   outcome and type, and the traversed ones over the potential energy
 *   landscape, stretches below the surface marked;
 * - a sweep of a gate lattice (lattice_map.csv beside them): per group the
 *   final-location distribution laid out as the field (stuck gates as a
 *   map, ends by column, side exits by row and side, 95% intervals) and
 *   the essay's Fig. 3.5 (the stiffness map, the kept trajectories over it,
 *   those that reached the end in blue), instead of the bundle and
 *   landscape; traversal against each axis as reached the end, side exit
 *   and stuck;
 * - a comparison (report.json, pairs.csv): both backends' p_traverse side
 *   by side with their paired differences, and each backend's sweep
 *   figures in DIR/<backend>/; of lattices also both sides' final-location
 *   distributions side by side;
 * - a run (trajectory.csv, ledger.csv): the random force over time and its
 *   histogram against N(0, Rm^2), the energy ledger over time, and the
 *   trajectory over the landscape;
 * - the accuracy study (accuracy.csv): consistency error against speed,
 *   one series per backend and setting, the Pareto front marked;
 * - the essay comparison (essay.csv): each level the essay reports beside
 *   beamsim's probability and interval in each mode.
 *
 * Without gnuplot the data and scripts are still written; the result says
 * how many figures were drawn. */
#ifndef BSIM_FIGURES_H
#define BSIM_FIGURES_H

#include "beamsim/base.h"
#include "beamsim/error.h"
#include "beamsim/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
	BSIM_FIGURES_AUTO = 0, /* by the files in the directory */
	BSIM_FIGURES_SWEEP,
	BSIM_FIGURES_COMPARE,
	BSIM_FIGURES_RUN,
	BSIM_FIGURES_ACCURACY,
	BSIM_FIGURES_ESSAY, /* essay.csv of beamsim essay */
} bsim_figures_kind;

BSIM_API const char *bsim_figures_kind_name(bsim_figures_kind k);

typedef struct bsim_figures_def {
	bsim_figures_kind kind;
	const char *out; /* directory for the figures; NULL: the directory read */
	int overwrite;   /* with out: 1 replaces the result out holds; 0 refuses it */
	/* Only groups whose grid value of KEY equals VALUE (numerically if
	 * both are numbers), for every KEY=VALUE given; the key must be a
	 * grid axis. */
	const bsim_override *select;
	int n_select;
	int threads; /* figures drawn at once; <= 0: all cores */
} bsim_figures_def;

BSIM_API bsim_figures_def bsim_figures_def_default(void);

typedef struct bsim_figures_result {
	bsim_figures_kind kind;
	int n;        /* figures written (script and data) */
	int drawn;    /* of which gnuplot drew the images */
	int failed;   /* figures gnuplot failed on: their scripts and data are written */
	char **paths; /* n "OUT/NAME", without extension, in the order written */
	int n_notes;
	char **notes; /* what was not drawn and why, one line each */
	/* With a selection (def.select), every grid axis of the run, one line
	 * each in the grid's order: "KEY = V (selected of N values)" for an
	 * axis the selection names, "KEY: V1, V2, ... (all N values)" for one
	 * that remains; after a first line "G of N groups selected". NULL
	 * without a selection. */
	char *selection;
} bsim_figures_result;

BSIM_API void bsim_figures_result_free(bsim_figures_result *r);

/* Draws every figure of the directory. BSIM_EINPUT naming the directory
 * and the files looked for when it holds nothing known, or naming file,
 * line and field when a file is malformed; BSIM_EFAIL if a file cannot be
 * written, or if gnuplot fails on a script (out->failed figures): the other
 * figures are still drawn, and the message names the failed figure first
 * by name, gnuplot's message, and its script and data, which stay in the
 * directory. */
BSIM_API int bsim_figures_draw(const char *dir, const bsim_figures_def *def,
                               bsim_figures_result *out, bsim_error *err);

/* beamsim plot DIR: checks DIR's files against its manifest (a mix of two
 * runs is refused, BSIM_EINPUT), draws its figures and commits them as
 * one set: into def->out, or, with def->out NULL, into DIR itself, where
 * they join the files already there (DIR/manifest.json lists both). A
 * figure gnuplot fails on is a failure (BSIM_EFAIL) that keeps the rest:
 * the set is committed, the failed figure's script and data with it.
 * out->paths name the figures where they are once this returns. */
BSIM_API int bsim_figures_plot(const char *dir, const bsim_figures_def *def,
                               bsim_figures_result *out, bsim_error *err);

#ifdef __cplusplus
}
#endif
#endif
