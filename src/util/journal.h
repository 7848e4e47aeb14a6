/* A journal of finished work, so that a stopped or killed run loses only
 * what was in flight. Append-only; each record is one fixed-size payload
 * (for a sweep, a whole bsim_trial_result) with its index and a CRC-32,
 * written to the file with one write(2) as soon as it is appended, so a
 * killed process loses nothing appended; the file is synced to disk in
 * chunks (at most a second apart), so a crash of the machine loses at most
 * the last second.
 *
 * The header names the format's version and the records' fields: a text
 * naming every member of the structs a record holds with its kind, offset
 * and size (beamsim/trial_fields.h: bsim_trial_record_fields), since the
 * records are those structs' bytes. A journal of another version or other
 * fields is refused, naming the version or the first field that differs:
 * it was written by another build, which can finish it.
 *
 * The header holds the inputs too: a text naming everything the records
 * depend on (version, command, backends and options, seed, trials,
 * experiment, scene). A run resumes from a journal only with identical
 * inputs; a refusal names the first line that differs.
 *
 * Format 2 (host byte order: a journal is read back by the machine and
 * build that wrote it):
 *   header  "BSIMJNL2", u32 record size, u32 fields length, fields,
 *           u32 inputs length, inputs, u32 CRC-32 of all before it
 *   record  u32 0x5243524A ("JRCR"), u64 index, payload, u32 CRC-32 of
 *           index and payload
 * Format 1 ("BSIMJNL1", the same without the fields) is refused by name.
 * Reading stops at the first record that is torn or fails its CRC, and the
 * file is cut there before anything more is appended. */
#ifndef BSIM_UTIL_JOURNAL_H
#define BSIM_UTIL_JOURNAL_H

#include <stddef.h>
#include <stdint.h>

#include "beamsim/error.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct bsim_journal bsim_journal;

/* Called for each intact record in file order; nonzero rejects it (an
 * index out of range): reading stops there as at a damaged record. */
typedef int (*bsim_journal_fn)(void *user, uint64_t index, const void *payload);

/* The version of the format this build writes and reads. */
#define BSIM_JOURNAL_VERSION 2

/* Creates path anew (replacing any file there), for records of
 * record_size bytes whose fields the text fields names. BSIM_EFAIL naming
 * path. */
int bsim_journal_create(bsim_journal **out, const char *path, const char *fields,
                        const char *inputs, size_t record_size, bsim_error *err);

/* Opens path to continue it: BSIM_EINPUT if it is not a journal, is of
 * another format version, holds records of other fields (the message
 * names the first field that differs) or size, or was written for other
 * inputs (the first line that differs). Call bsim_journal_replay next. */
int bsim_journal_resume(bsim_journal **out, const char *path, const char *fields,
                        const char *inputs, size_t record_size, bsim_error *err);

/* Passes every intact record to fn, in file order, cuts off a damaged tail
 * and readies the journal for appending: call it once, before the first
 * append (on a created journal it finds nothing). *n_records gets the
 * records kept, *n_cut the bytes cut off. */
int bsim_journal_replay(bsim_journal *j, bsim_journal_fn fn, void *user, long *n_records,
                        long *n_cut, bsim_error *err);

/* Reads the journal at path without changing it: checks its header as
 * bsim_journal_resume does, then passes every intact record to fn in file
 * order; *n_cut gets the bytes after the last intact record (0 for a
 * whole journal). */
int bsim_journal_read(const char *path, const char *fields, const char *inputs, size_t record_size,
                      bsim_journal_fn fn, void *user, long *n_records, long *n_cut,
                      bsim_error *err);

/* Appends one record; safe from several threads at once. BSIM_EFAIL naming
 * the file on a write error (a full disk): the run should stop, since what
 * it finishes from then on would not be kept. */
int bsim_journal_append(bsim_journal *j, uint64_t index, const void *payload, bsim_error *err);

/* Syncs to disk and closes; NULL is fine. */
int bsim_journal_close(bsim_journal *j, bsim_error *err);

/* The errno with which an append (or the replay) failed, 0 if none did:
 * what was appended before it is in the file and worth keeping. */
int bsim_journal_failed(const bsim_journal *j);

/* The file's path. */
const char *bsim_journal_path(const bsim_journal *j);

#ifdef __cplusplus
}
#endif
#endif
