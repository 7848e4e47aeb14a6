/* A sweep's summary.json as the figures read it (figures_summary.c). */
#ifndef BSIM_FIGURES_FIGURES_SUMMARY_H
#define BSIM_FIGURES_FIGURES_SUMMARY_H

#include <stddef.h>

#include "figures/figures_toolkit.h"

typedef struct fsum_group {
	int *idx; /* value index per axis */
	int trials, traversed, side_exit, stuck, left, right;
	int land_left, land_right; /* traversed, by the larger peak angle */
	double p, lo, hi;          /* p_traverse and its Wilson 95% interval */
	int selected;              /* matches every KEY=VALUE of the selection */
	int deterministic;         /* no random force: one trial, its rows copies */
} fsum_group;

typedef struct fsum_axis {
	char *key;
	int n_values;
	char **values;  /* text as in summary.json, in order of first appearance */
	int numeric;    /* every value a number */
	double *x;      /* the numbers, when numeric */
	int n_selected; /* values among the selected groups (bsim_fsum_select) */
} fsum_axis;

typedef struct fsum {
	char backend[64];
	int trials_per_group;
	int n_axes;
	fsum_axis *axes; /* in the order of the groups' params: the first slowest */
	int n_groups;
	fsum_group *g;
	/* "thesis backend; k_2 = 500 N m/rad, F_prop = 8 N": what every
	 * figure's title says of the run (bsim_fsum_header) */
	char header[700];
	/* the scene values the header names, as keys and value texts */
	int n_fixed;
	char fixed_key[16][96];
	char fixed_value[16][64];
} fsum;

/* Reads path (a summary.json). BSIM_EINPUT naming file and field. */
int bsim_fsum_read(const char *path, fsum *s, bsim_error *err);
void bsim_fsum_free(fsum *s);
/* Marks the groups matching the selection of f->def; BSIM_EINPUT if a key
 * is no axis or a value matches no group. */
int bsim_fsum_select(const figs *f, fsum *s, bsim_error *err);
/* Fills s->header: who (the backend, "thesis backend") and what differs
 * from the scene file: the experiment's set: values (inputs/experiment.yaml
 * of the run, --set included) and the grid axes with one selected value.
 * A missing or unreadable experiment leaves its part out. */
void bsim_fsum_header(fsum *s, const char *inputs, const char *who);
/* The value of a key the header names as a number; 1 if there is one. */
int bsim_fsum_fixed_number(const fsum *s, const char *key, double *x);
/* "F_prop = 8 N, R_m = 30 N" of group g over the axes with more than one
 * selected value (the others are in the header), into buf, two to a
 * line. */
void bsim_fsum_label(const fsum *s, int g, char *buf, size_t size);
/* 1 if two value texts name the same value (numerically where both are
 * numbers). */
int bsim_fsum_same_value(const char *a, const char *b);

#endif
