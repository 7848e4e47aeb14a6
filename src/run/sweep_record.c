/* A lattice sweep's journal record; see sweep_record.h. */
#include "run/sweep_record.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

size_t bsim_sweep_record_bytes(int beams_max)
{
	return sizeof(bsim_trial_result) + 2 * sizeof(int32_t) +
	       SWEEP_RECORD_ENTRIES * sizeof(bsim_gate_entry) + (size_t)beams_max * sizeof(double);
}

int bsim_sweep_record_beams(const bsim_scene *scenes, int n)
{
	int most = 0;
	for (int g = 0; g < n; g++)
		most = scenes[g].n_beams > most ? scenes[g].n_beams : most;
	return most;
}

void bsim_sweep_record_pack(void *rec, int beams_max, const bsim_trial_result *r,
                            const bsim_trial_log *log)
{
	unsigned char *p = rec;
	memset(p, 0, bsim_sweep_record_bytes(beams_max));
	memcpy(p, r, sizeof *r);
	p += sizeof *r;
	int32_t n_entries = log->n_entries, n_beams = log->n_beams;
	if (n_entries > SWEEP_RECORD_ENTRIES || n_beams > beams_max)
		n_entries = -1; /* does not fit: the trial runs again */
	memcpy(p, &n_entries, sizeof n_entries);
	memcpy(p + sizeof n_entries, &n_beams, sizeof n_beams);
	p += 2 * sizeof(int32_t);
	if (n_entries < 0)
		return;
	if (n_entries > 0)
		memcpy(p, log->entries, (size_t)n_entries * sizeof *log->entries);
	p += SWEEP_RECORD_ENTRIES * sizeof(bsim_gate_entry);
	if (n_beams > 0)
		memcpy(p, log->peak, (size_t)n_beams * sizeof *log->peak);
}

int bsim_sweep_record_unpack(const void *rec, int beams_max, bsim_trial_result *r,
                             bsim_trial_log *log)
{
	const unsigned char *p = rec;
	int32_t n_entries, n_beams;
	memcpy(&n_entries, p + sizeof *r, sizeof n_entries);
	memcpy(&n_beams, p + sizeof *r + sizeof n_entries, sizeof n_beams);
	if (n_entries < 0 || n_entries > SWEEP_RECORD_ENTRIES || n_beams < 0 || n_beams > beams_max)
		return 0;
	/* the log's own memory, grown as bsim_trial_log_copy grows it */
	bsim_trial_log view = {0};
	bsim_gate_entry entries[SWEEP_RECORD_ENTRIES];
	const unsigned char *q = p + sizeof *r + 2 * sizeof(int32_t);
	memcpy(entries, q, (size_t)n_entries * sizeof *entries);
	view.n_entries = n_entries;
	view.entries = entries;
	double *peak = n_beams > 0 ? (double *)malloc((size_t)n_beams * sizeof *peak) : NULL;
	if (n_beams > 0 && !peak)
		return -1;
	if (n_beams > 0)
		memcpy(peak, q + SWEEP_RECORD_ENTRIES * sizeof(bsim_gate_entry),
		       (size_t)n_beams * sizeof *peak);
	view.n_beams = n_beams;
	view.peak = peak;
	int rc = bsim_trial_log_copy(log, &view);
	free(peak);
	if (rc != BSIM_OK)
		return -1;
	memcpy(r, p, sizeof *r);
	return 1;
}
