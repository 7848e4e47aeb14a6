/* The figures of a gate lattice (figures_lattice.c). */
#ifndef BSIM_FIGURES_FIGURES_LATTICE_H
#define BSIM_FIGURES_FIGURES_LATTICE_H

#include "figures/figures_summary.h"
#include "figures/figures_toolkit.h"

/* 1 if dir holds a lattice run (lattice_map.csv beside trials.csv). */
int bsim_figs_is_lattice(const char *dir);

/* A lattice sweep's own figures per selected group: final_locations_gNNN
 * (where the trials ended, laid out as the field) and lattice_gNNN (the
 * essay's Fig. 3.5: the stiffness map and the kept trajectories over it),
 * drawn instead of the single gate's trajectory and landscape figures.
 * bsim_figs_lattice_load reads and checks every input (lattice_map.csv,
 * trials.csv, the stored experiment, trajectories.csv) before any figure
 * is drawn; s must outlive the job. */
typedef struct lat_job lat_job;
int bsim_figs_lattice_load(figs *f, const char *dir, const char *inputs, const fsum *s,
                           lat_job **out, bsim_error *err);
int bsim_figs_lattice_draw(figs *f, lat_job *j, bsim_error *err);
void bsim_figs_lattice_free(lat_job *j);

/* final_locations_gNNN of a comparison: every side's final locations side
 * by side on the same scales; dirs are the n sides' sweep directories, s
 * the groups (with the selection), tests[g] a line (or lines) on the
 * group's tests. */
int bsim_figs_lattice_compare(figs *f, int n, const char *const *dirs, const char *const *labels,
                              const fsum *s, const char *const *tests, bsim_error *err);

#endif
