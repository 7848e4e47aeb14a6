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
} fsum_group;

typedef struct fsum_axis {
	char *key;
	int n_values;
	char **values; /* text as in summary.json, in order of first appearance */
	int numeric;   /* every value a number */
	double *x;     /* the numbers, when numeric */
} fsum_axis;

typedef struct fsum {
	char backend[64];
	int trials_per_group;
	int n_axes;
	fsum_axis *axes; /* in the order of the groups' params: the first slowest */
	int n_groups;
	fsum_group *g;
} fsum;

/* Reads path (a summary.json). BSIM_EINPUT naming file and field. */
int fsum_read(const char *path, fsum *s, bsim_error *err);
void fsum_free(fsum *s);
/* Marks the groups matching the selection of f->def; BSIM_EINPUT if a key
 * is no axis or a value matches no group. */
int fsum_select(const figs *f, fsum *s, bsim_error *err);
/* "key = value, key = value" of group g over the axes, into buf, two to
 * a line. */
void fsum_label(const fsum *s, int g, char *buf, size_t size);
/* 1 if two value texts name the same value (numerically where both are
 * numbers). */
int fsum_same_value(const char *a, const char *b);

#endif
