/* The trial log (trial.h bsim_trial_log): what a trial can leave beyond
 * its result, the gate path and the moved beams' peak angles, in memory
 * that grows as needed and is reused from trial to trial. */
#include "run/trial_log.h"

#include <stdlib.h>
#include <string.h>

bsim_trial_log *bsim_trial_log_alloc(void)
{
	return calloc(1, sizeof(bsim_trial_log));
}

void bsim_trial_log_clear(bsim_trial_log *l)
{
	if (!l)
		return;
	free(l->entries);
	free(l->peaks);
	memset(l, 0, sizeof *l);
}

void bsim_trial_log_free(bsim_trial_log *l)
{
	bsim_trial_log_clear(l);
	free(l);
}

int bsim_trial_log_copy(bsim_trial_log *dst, const bsim_trial_log *src)
{
	/* A log's slot is reused trial after trial (a streamed sweep's
	 * blocks): its memory is kept and grown, never dropped. */
	if (dst->cap_entries < src->n_entries) {
		bsim_gate_entry *p = realloc(dst->entries, (size_t)src->n_entries * sizeof *p);
		if (!p)
			return BSIM_EFAIL;
		dst->entries = p;
		dst->cap_entries = src->n_entries;
	}
	if (dst->cap_peaks < src->n_peaks) {
		bsim_beam_peak *p = realloc(dst->peaks, (size_t)src->n_peaks * sizeof *p);
		if (!p)
			return BSIM_EFAIL;
		dst->peaks = p;
		dst->cap_peaks = src->n_peaks;
	}
	if (src->n_entries > 0)
		memcpy(dst->entries, src->entries, (size_t)src->n_entries * sizeof *src->entries);
	if (src->n_peaks > 0)
		memcpy(dst->peaks, src->peaks, (size_t)src->n_peaks * sizeof *src->peaks);
	dst->n_entries = src->n_entries;
	dst->n_beams = src->n_beams;
	dst->n_peaks = src->n_peaks;
	return BSIM_OK;
}

int bsim_trial_log_push(bsim_trial_log *l, const bsim_gate_entry *e)
{
	if (l->n_entries == l->cap_entries) {
		int cap = l->cap_entries ? 2 * l->cap_entries : 16;
		bsim_gate_entry *p = realloc(l->entries, (size_t)cap * sizeof *p);
		if (!p)
			return BSIM_EFAIL;
		l->entries = p;
		l->cap_entries = cap;
	}
	l->entries[l->n_entries++] = *e;
	return BSIM_OK;
}

static int peak_order(const void *a, const void *b)
{
	int i = ((const bsim_beam_peak *)a)->beam, j = ((const bsim_beam_peak *)b)->beam;
	return (i > j) - (i < j);
}

int bsim_trial_log_peaks(bsim_trial_log *l, const double *peak, const int *list, int n_list,
                         int n_beams)
{
	if (l->cap_peaks < n_list) {
		bsim_beam_peak *p = realloc(l->peaks, (size_t)n_list * sizeof *p);
		if (!p)
			return BSIM_EFAIL;
		l->peaks = p;
		l->cap_peaks = n_list;
	}
	int n = 0;
	for (int k = 0; k < n_list; k++)
		if (peak[list[k]] != 0.0)
			l->peaks[n++] = (bsim_beam_peak){list[k], peak[list[k]]};
	qsort(l->peaks, (size_t)n, sizeof *l->peaks, peak_order);
	l->n_peaks = n;
	l->n_beams = n_beams;
	return BSIM_OK;
}
