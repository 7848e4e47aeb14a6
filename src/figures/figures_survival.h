/* The survival figure of a sweep (figures_survival.c): the Kaplan-Meier
 * time to leave the gate and the outcome shares against the horizon, from
 * survival.csv and horizon.csv (docs/first_passage.md). */
#ifndef BSIM_FIGURES_FIGURES_SURVIVAL_H
#define BSIM_FIGURES_FIGURES_SURVIVAL_H

#include "figures/figures_summary.h"

/* Most groups one survival figure shows; with more selected, those with the
 * most exits, the others named in a note (--select chooses). */
#define FIGS_SURVIVAL_GROUPS 8

/* Draws survival.png from dir's survival.csv and horizon.csv, if dir has
 * them (an older sweep has not: nothing drawn, BSIM_OK); BSIM_EINPUT if
 * either is malformed. */
int bsim_figs_survival(figs *f, const char *dir, const fsum *s, bsim_error *err);

#endif
