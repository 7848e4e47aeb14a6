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
 * runs of equal items. */
int bsim_lattice_summarise(const bsim_trial_result *trials, const bsim_trial_log *logs, int n,
                           int rows, bsim_lattice_summary *out)
{
	memset(out, 0, sizeof *out);
	out->trials = n;
	out->rows = rows;
	int n_steps = 0;
	for (int i = 0; logs && i < n; i++)
		n_steps += logs[i].n_entries > 0 ? logs[i].n_entries - 1 : 0;
	out->locations = calloc(n > 0 ? (size_t)n : 1, sizeof *out->locations);
	out->transitions = calloc(n_steps > 0 ? (size_t)n_steps : 1, sizeof *out->transitions);
	out->row_trials = calloc(rows > 0 ? (size_t)rows : 1, sizeof *out->row_trials);
	out->row_time = calloc(rows > 0 ? (size_t)rows : 1, sizeof *out->row_time);
	double *t = calloc(rows > 0 ? (size_t)rows : 1, sizeof *t);
	if (!out->locations || !out->transitions || !out->row_trials || !out->row_time || !t) {
		free(t);
		bsim_lattice_summary_free(out);
		return BSIM_EFAIL;
	}
	/* final locations */
	for (int i = 0; i < n; i++) {
		out->locations[i].loc = bsim_lattice_location_of(&trials[i]);
		out->locations[i].count = 1;
	}
	qsort(out->locations, (size_t)n, sizeof *out->locations, location_count_cmp);
	int m = 0;
	for (int i = 0; i < n; i++) {
		if (m > 0 &&
		    bsim_lattice_location_equal(out->locations[m - 1].loc, out->locations[i].loc))
			out->locations[m - 1].count++;
		else
			out->locations[m++] = out->locations[i];
	}
	out->n_locations = m;
	for (int k = 0; k < m; k++) {
		bsim_location_count *c = &out->locations[k];
		c->p = n > 0 ? (double)c->count / n : 0.0;
		bsim_stats_wilson(c->count, n, BSIM_STATS_Z95, &c->ci95[0], &c->ci95[1]);
	}
	/* transitions and time per row */
	int s = 0;
	for (int i = 0; logs && i < n; i++) {
		const bsim_trial_log *l = &logs[i];
		for (int k = 0; k + 1 < l->n_entries; k++) {
			bsim_transition *x = &out->transitions[s++];
			x->from[0] = l->entries[k].ix;
			x->from[1] = l->entries[k].iy;
			x->to[0] = l->entries[k + 1].ix;
			x->to[1] = l->entries[k + 1].iy;
			x->count = 1;
		}
		bsim_lattice_row_times(&trials[i], l, rows, t);
		for (int iy = 0; iy < rows; iy++)
			if (t[iy] > 0.0) {
				out->row_trials[iy]++;
				out->row_time[iy] += t[iy];
			}
	}
	free(t);
	qsort(out->transitions, (size_t)s, sizeof *out->transitions, transition_cmp);
	m = 0;
	for (int i = 0; i < s; i++) {
		if (m > 0 && transition_cmp(&out->transitions[m - 1], &out->transitions[i]) == 0)
			out->transitions[m - 1].count++;
		else
			out->transitions[m++] = out->transitions[i];
	}
	out->n_transitions = m;
	for (int iy = 0; iy < rows; iy++)
		if (out->row_trials[iy] > 0)
			out->row_time[iy] /= out->row_trials[iy];
	return BSIM_OK;
}
