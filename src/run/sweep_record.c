/* A lattice sweep's journal record; see sweep_record.h. */
#include "run/sweep_record.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

size_t bsim_sweep_record_bytes(void)
{
	return sizeof(bsim_trial_result) + 3 * sizeof(int32_t) +
	       SWEEP_RECORD_ENTRIES * sizeof(bsim_gate_entry) +
	       SWEEP_RECORD_PEAKS * sizeof(bsim_beam_peak);
}

void bsim_sweep_record_pack(void *rec, const bsim_trial_result *r, const bsim_trial_log *log)
{
	unsigned char *p = rec;
	memset(p, 0, bsim_sweep_record_bytes());
	memcpy(p, r, sizeof *r);
	p += sizeof *r;
	int32_t n[3] = {log->n_entries, log->n_beams, log->n_peaks};
	if (n[0] > SWEEP_RECORD_ENTRIES || n[2] > SWEEP_RECORD_PEAKS)
		n[0] = -1; /* does not fit: the trial runs again */
	memcpy(p, n, sizeof n);
	p += sizeof n;
	if (n[0] < 0)
		return;
	if (n[0] > 0)
		memcpy(p, log->entries, (size_t)n[0] * sizeof *log->entries);
	p += SWEEP_RECORD_ENTRIES * sizeof(bsim_gate_entry);
	if (n[2] > 0)
		memcpy(p, log->peaks, (size_t)n[2] * sizeof *log->peaks);
}

int bsim_sweep_record_unpack(const void *rec, bsim_trial_result *r, bsim_trial_log *log)
{
	const unsigned char *p = rec;
	int32_t n[3];
	memcpy(n, p + sizeof *r, sizeof n);
	if (n[0] < 0 || n[0] > SWEEP_RECORD_ENTRIES || n[1] < 0 || n[2] < 0 ||
	    n[2] > SWEEP_RECORD_PEAKS)
		return 0;
	/* the log's own memory, grown as bsim_trial_log_copy grows it */
	bsim_gate_entry entries[SWEEP_RECORD_ENTRIES];
	bsim_beam_peak peaks[SWEEP_RECORD_PEAKS];
	const unsigned char *q = p + sizeof *r + sizeof n;
	memcpy(entries, q, (size_t)n[0] * sizeof *entries);
	memcpy(peaks, q + SWEEP_RECORD_ENTRIES * sizeof(bsim_gate_entry),
	       (size_t)n[2] * sizeof *peaks);
	bsim_trial_log view = {.n_entries = n[0],
	                       .entries = entries,
	                       .n_beams = n[1],
	                       .n_peaks = n[2],
	                       .peaks = peaks};
	if (bsim_trial_log_copy(log, &view) != BSIM_OK)
		return -1;
	memcpy(r, p, sizeof *r);
	return 1;
}
