/* Where the trials of a lattice ended (beamsim/lattice_outcome.h). */
#include "beamsim/lattice_outcome.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/stats.h"

bsim_location bsim_lattice_location_of(const bsim_trial_result *r)
{
	bsim_location loc = {BSIM_LOCATION_STUCK, r->final_ix, r->final_iy};
	if (r->outcome == BSIM_TRAVERSED) {
		loc.kind = BSIM_LOCATION_END;
		loc.iy = 0;
	} else if (r->outcome == BSIM_SIDE_EXIT) {
		loc.kind = BSIM_LOCATION_SIDE;
		loc.ix = 0;
	}
	return loc;
}

int bsim_lattice_location_equal(bsim_location a, bsim_location b)
{
	return a.kind == b.kind && a.ix == b.ix && a.iy == b.iy;
}

void bsim_lattice_location_label(bsim_location loc, char *buf, size_t size)
{
	switch (loc.kind) {
	case BSIM_LOCATION_END:
		snprintf(buf, size, "end:%d", loc.ix);
		return;
	case BSIM_LOCATION_SIDE:
		snprintf(buf, size, "side:%d", loc.iy);
		return;
	case BSIM_LOCATION_STUCK:
		snprintf(buf, size, "stuck:%d:%d", loc.ix, loc.iy);
		return;
	}
	snprintf(buf, size, "?");
}

/* ---- a group of lattice trials ------------------------------------------ */

/* Ends by ix, then sides by iy, then stuck gates by (iy, ix). */
static int location_cmp(bsim_location a, bsim_location b)
{
	if (a.kind != b.kind)
		return a.kind < b.kind ? -1 : 1;
	if (a.iy != b.iy)
		return a.iy < b.iy ? -1 : 1;
	if (a.ix != b.ix)
		return a.ix < b.ix ? -1 : 1;
	return 0;
}

static int location_count_cmp(const void *x, const void *y)
{
	return location_cmp(((const bsim_location_count *)x)->loc,
	                    ((const bsim_location_count *)y)->loc);
}

static int gate_cmp(const int a[2], const int b[2])
{
	if (a[1] != b[1])
		return a[1] < b[1] ? -1 : 1;
	if (a[0] != b[0])
		return a[0] < b[0] ? -1 : 1;
	return 0;
}

static int transition_cmp(const void *x, const void *y)
{
	const bsim_transition *a = x, *b = y;
	int c = gate_cmp(a->from, b->from);
	return c ? c : gate_cmp(a->to, b->to);
}

void bsim_lattice_summary_free(bsim_lattice_summary *s)
{
	if (!s)
		return;
	free(s->locations);
	free(s->transitions);
	free(s->row_trials);
	free(s->row_time);
	memset(s, 0, sizeof *s);
}

void bsim_lattice_row_times(const bsim_trial_result *r, const bsim_trial_log *log, int rows,
                            double *row_time)
{
	for (int iy = 0; iy < rows; iy++)
		row_time[iy] = 0.0;
	for (int k = 0; log && k < log->n_entries; k++) {
		const bsim_gate_entry *e = &log->entries[k];
		double t1 = k + 1 < log->n_entries ? log->entries[k + 1].t : r->t_end;
		if (e->iy >= 0 && e->iy < rows)
			row_time[e->iy] += t1 - e->t;
	}
}

/* Distinct locations and transitions are counted by sorting and merging
 * runs of equal items: a block's items are sorted together with the
 * distinct ones so far (each with its count) and runs merged by adding
 * counts, so the result does not depend on how the trials were split into
 * blocks. Time per row is summed in trial order and divided at the end. */
int bsim_lattice_summary_begin(bsim_lattice_summary *s, int rows)
{
	memset(s, 0, sizeof *s);
	s->rows = rows;
	s->row_trials = calloc(rows > 0 ? (size_t)rows : 1, sizeof *s->row_trials);
	s->row_time = calloc(rows > 0 ? (size_t)rows : 1, sizeof *s->row_time);
	if (!s->row_trials || !s->row_time) {
		bsim_lattice_summary_free(s);
		return BSIM_EFAIL;
	}
	return BSIM_OK;
}

/* Sorts the n items of a (the first n_old distinct already, with their
 * counts) and merges runs of equal ones: the count of distinct items. */
static int merge_runs(void *a, int n, size_t size, int (*cmp)(const void *, const void *),
                      int *(*count)(void *))
{
	qsort(a, (size_t)n, size, cmp);
	char *p = a;
	int m = 0;
	for (int i = 0; i < n; i++) {
		if (m > 0 && cmp(p + (size_t)(m - 1) * size, p + (size_t)i * size) == 0)
			*count(p + (size_t)(m - 1) * size) += *count(p + (size_t)i * size);
		else
			memmove(p + (size_t)(m++) * size, p + (size_t)i * size, size);
	}
	return m;
}

static int *location_count_of(void *x)
{
	return &((bsim_location_count *)x)->count;
}

static int *transition_count_of(void *x)
{
	return &((bsim_transition *)x)->count;
}

int bsim_lattice_summary_add(bsim_lattice_summary *s, const bsim_trial_result *trials,
                             const bsim_trial_log *logs, int n)
{
	int n_steps = 0;
	for (int i = 0; logs && i < n; i++)
		n_steps += logs[i].n_entries > 0 ? logs[i].n_entries - 1 : 0;
	size_t n_loc = (size_t)s->n_locations + (size_t)n;
	size_t n_tr = (size_t)s->n_transitions + (size_t)n_steps;
	bsim_location_count *loc = realloc(s->locations, (n_loc ? n_loc : 1) * sizeof *loc);
	if (!loc)
		return BSIM_EFAIL;
	s->locations = loc;
	bsim_transition *tr = realloc(s->transitions, (n_tr ? n_tr : 1) * sizeof *tr);
	if (!tr)
		return BSIM_EFAIL;
	s->transitions = tr;
	double *t = calloc(s->rows > 0 ? (size_t)s->rows : 1, sizeof *t);
	if (!t)
		return BSIM_EFAIL;
	/* final locations */
	for (int i = 0; i < n; i++) {
		bsim_location_count *c = &loc[s->n_locations + i];
		memset(c, 0, sizeof *c);
		c->loc = bsim_lattice_location_of(&trials[i]);
		c->count = 1;
	}
	s->n_locations =
	        merge_runs(loc, (int)n_loc, sizeof *loc, location_count_cmp, location_count_of);
	/* transitions and time per row */
	int k0 = s->n_transitions;
	for (int i = 0; logs && i < n; i++) {
		const bsim_trial_log *l = &logs[i];
		for (int k = 0; k + 1 < l->n_entries; k++) {
			bsim_transition *x = &tr[k0++];
			x->from[0] = l->entries[k].ix;
			x->from[1] = l->entries[k].iy;
			x->to[0] = l->entries[k + 1].ix;
			x->to[1] = l->entries[k + 1].iy;
			x->count = 1;
		}
		bsim_lattice_row_times(&trials[i], l, s->rows, t);
		for (int iy = 0; iy < s->rows; iy++)
			if (t[iy] > 0.0) {
				s->row_trials[iy]++;
				s->row_time[iy] += t[iy];
			}
	}
	free(t);
	s->n_transitions =
	        merge_runs(tr, (int)n_tr, sizeof *tr, transition_cmp, transition_count_of);
	s->trials += n;
	return BSIM_OK;
}

void bsim_lattice_summary_end(bsim_lattice_summary *s)
{
	for (int k = 0; k < s->n_locations; k++) {
		bsim_location_count *c = &s->locations[k];
		c->p = s->trials > 0 ? (double)c->count / s->trials : 0.0;
		bsim_stats_wilson(c->count, s->trials, BSIM_STATS_Z95, &c->ci95[0], &c->ci95[1]);
	}
	for (int iy = 0; iy < s->rows; iy++)
		if (s->row_trials[iy] > 0)
			s->row_time[iy] /= s->row_trials[iy];
}

int bsim_lattice_summarise(const bsim_trial_result *trials, const bsim_trial_log *logs, int n,
                           int rows, bsim_lattice_summary *out)
{
	if (bsim_lattice_summary_begin(out, rows) != BSIM_OK)
		return BSIM_EFAIL;
	if (bsim_lattice_summary_add(out, trials, logs, n) != BSIM_OK) {
		bsim_lattice_summary_free(out);
		return BSIM_EFAIL;
	}
	bsim_lattice_summary_end(out);
	return BSIM_OK;
}
