/* Trajectories kept in memory: the rows a sweep keeps of its first trials
 * (beamsim sweep --trajectories N) for figures and files.
 *
 * A row is the compact state of one recorded time:
 *   t, x, y, theta_1 .. theta_N, contact_1 .. contact_N
 * (s, m, m, rad forward positive, BSIM_CONTACT_*), enough to draw the path,
 * the beams' energy E_beam = sum 1/2 k_i theta_i^2 and the propulsive
 * potential along it. The rows are those of bsim_recorder: t = 0, every
 * stride-th step and the last step. */
#ifndef BSIM_TRAJECTORY_H
#define BSIM_TRAJECTORY_H

#include "beamsim/base.h"
#include "beamsim/error.h"
#include "beamsim/trial.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct bsim_trajectory {
	int n_beams;
	long n, cap;  /* rows held, rows allocated */
	double *rows; /* n rows of bsim_trajectory_width(n_beams) values */
	int oom;      /* a row could not be stored: the trajectory is incomplete */
} bsim_trajectory;

/* Values per row: 3 + 2 n_beams. */
BSIM_API int bsim_trajectory_width(int n_beams);

/* A bsim_record_fn: appends the row to the bsim_trajectory user (whose
 * n_beams it sets on the first row). Sets oom instead of failing. */
BSIM_API void bsim_trajectory_record(void *user, const bsim_record_row *row);

/* dst becomes a copy of src (dst's rows are freed). BSIM_EFAIL if out
 * of memory, dst unchanged. */
BSIM_API int bsim_trajectory_copy(bsim_trajectory *dst, const bsim_trajectory *src);

/* Forgets the rows, keeps the memory. */
BSIM_API void bsim_trajectory_clear(bsim_trajectory *tr);
BSIM_API void bsim_trajectory_free(bsim_trajectory *tr);

/* The header of trajectories.csv for n_beams beams:
 *   group,trial,t,x,y,theta1,...,thetaN,contact1,...,contactN */
BSIM_API void bsim_trajectory_csv_header(FILE *f, int n_beams);

/* The rows of one trajectory as trajectories.csv lines of (group, trial). */
BSIM_API void bsim_trajectory_csv_rows(FILE *f, int group, int trial, const bsim_trajectory *tr);

#ifdef __cplusplus
}
#endif
#endif
