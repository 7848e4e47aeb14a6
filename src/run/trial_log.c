/* The trial log (trial.h bsim_trial_log): what a trial can leave beyond
 * its result, the gate path and every beam's peak angle, in memory that
 * grows as needed and is reused from trial to trial. */
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
	free(l->peak);
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
	if (dst->cap_beams < src->n_beams) {
		double *p = realloc(dst->peak, (size_t)src->n_beams * sizeof *p);
		if (!p)
			return BSIM_EFAIL;
		dst->peak = p;
		dst->cap_beams = src->n_beams;
	}
	if (src->n_entries > 0)
		memcpy(dst->entries, src->entries, (size_t)src->n_entries * sizeof *src->entries);
	if (src->n_beams > 0)
		memcpy(dst->peak, src->peak, (size_t)src->n_beams * sizeof *src->peak);
	dst->n_entries = src->n_entries;
	dst->n_beams = src->n_beams;
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

int bsim_trial_log_peaks(bsim_trial_log *l, const double *peak, int n)
{
	if (l->cap_beams < n) {
		double *p = realloc(l->peak, (size_t)n * sizeof *p);
		if (!p)
			return BSIM_EFAIL;
		l->peak = p;
		l->cap_beams = n;
	}
	memcpy(l->peak, peak, (size_t)n * sizeof *peak);
	l->n_beams = n;
	return BSIM_OK;
}
