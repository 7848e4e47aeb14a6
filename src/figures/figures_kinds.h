/* The figures of each kind of directory, as the dispatcher (figures.c)
 * calls them: figures_sweep.c, figures_compare.c, figures_run.c,
 * figures_accuracy.c, figures_essay.c. */
#ifndef BSIM_FIGURES_FIGURES_KINDS_H
#define BSIM_FIGURES_FIGURES_KINDS_H

#include "figures/figures_toolkit.h"

/* inputs: the directory holding experiment.yaml and scene.yaml of the run
 * (DIR/inputs, or the comparison's for one of its backends). */
int bsim_figs_sweep(figs *f, const char *dir, const char *inputs, bsim_error *err);
int bsim_figs_compare(figs *f, const char *dir, bsim_error *err);
int bsim_figs_run(figs *f, const char *dir, bsim_error *err);
int bsim_figs_accuracy(figs *f, const char *dir, bsim_error *err);
int bsim_figs_essay(figs *f, const char *dir, bsim_error *err);

#endif
