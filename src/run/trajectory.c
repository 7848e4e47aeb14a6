/* Trajectories kept in memory (beamsim/trajectory.h). Positions and angles
 * go to trajectories.csv with 7 significant digits: 1e-5 m at 80 m, far
 * below what a figure shows and about a seventh of the bytes of a full
 * trajectory row. */
#include "beamsim/trajectory.h"

#include <stdlib.h>
#include <string.h>

int bsim_trajectory_width(int n_beams)
{
	return 3 + 2 * n_beams;
}

void bsim_trajectory_record(void *user, const bsim_record_row *row)
{
	bsim_trajectory *tr = user;
	const bsim_state *s = row->state;
	if (tr->oom)
		return;
	if (tr->n == 0)
		tr->n_beams = s->n_beams;
	const int w = bsim_trajectory_width(tr->n_beams);
	if (tr->n == tr->cap) {
		long cap = tr->cap ? 2 * tr->cap : 256;
		double *rows = realloc(tr->rows, (size_t)cap * (size_t)w * sizeof *rows);
		if (!rows) {
			tr->oom = 1;
			return;
		}
		tr->rows = rows;
		tr->cap = cap;
	}
	double *r = tr->rows + (size_t)tr->n * (size_t)w;
	r[0] = row->t;
	r[1] = s->x[0];
	r[2] = s->x[1];
	for (int i = 0; i < tr->n_beams; i++) {
		r[3 + i] = s->theta[i];
		r[3 + tr->n_beams + i] = s->contact[i];
	}
	tr->n++;
}

int bsim_trajectory_copy(bsim_trajectory *dst, const bsim_trajectory *src)
{
	const size_t n = (size_t)src->n * (size_t)bsim_trajectory_width(src->n_beams);
	double *rows = malloc((n ? n : 1) * sizeof *rows);
	if (!rows)
		return BSIM_EFAIL;
	if (n)
		memcpy(rows, src->rows, n * sizeof *rows);
	free(dst->rows);
	*dst = *src;
	dst->rows = rows;
	dst->cap = src->n;
	return BSIM_OK;
}

void bsim_trajectory_clear(bsim_trajectory *tr)
{
	tr->n = 0;
	tr->oom = 0;
}

void bsim_trajectory_free(bsim_trajectory *tr)
{
	if (!tr)
		return;
	free(tr->rows);
	tr->rows = NULL;
	tr->n = tr->cap = 0;
	tr->oom = 0;
}

void bsim_trajectory_csv_header(FILE *f, int n_beams)
{
	fputs("group,trial,t,x,y", f);
	for (int i = 1; i <= n_beams; i++)
		fprintf(f, ",theta%d", i);
	for (int i = 1; i <= n_beams; i++)
		fprintf(f, ",contact%d", i);
	fputc('\n', f);
}

void bsim_trajectory_csv_rows(FILE *f, int group, int trial, const bsim_trajectory *tr)
{
	const int w = bsim_trajectory_width(tr->n_beams);
	for (long k = 0; k < tr->n; k++) {
		const double *r = tr->rows + (size_t)k * (size_t)w;
		fprintf(f, "%d,%d,%.6g,%.7g,%.7g", group, trial, r[0], r[1], r[2]);
		for (int i = 0; i < tr->n_beams; i++)
			fprintf(f, ",%.7g", r[3 + i]);
		for (int i = 0; i < tr->n_beams; i++)
			fprintf(f, ",%d", (int)r[3 + tr->n_beams + i]);
		fputc('\n', f);
	}
}
