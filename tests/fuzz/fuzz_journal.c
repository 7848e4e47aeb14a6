/* Fuzz target: a journal found in an output directory (beamsim sweep
 * --resume, compare --resume), opened with bsim_journal_resume and read
 * with bsim_journal_replay as a resumed run reads it. The first input
 * byte chooses how the rest makes the file:
 *   0  the whole file, header included;
 *   1  a valid header for this target's inputs, then the rest as it is
 *      (torn and damaged records);
 *   2  a valid header, then records made of the rest with their magic
 *      number and CRC-32 right (each 8 bytes of index and a payload), so
 *      that the replay's callback sees them: it refuses an index out of
 *      range, as the sweep's does.
 * A journal that is accepted must then take one more record and read back
 * with exactly the records kept before and that one, nothing cut. */
#include "fuzz_common.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

#include "util/journal.h"

#define RECORD      24 /* payload bytes */
#define INDICES     64
#define MAX_RECORDS 64

static const char fields[] = "payload 24\nbytes uchar 0 24\n";
static const char inputs[] = "beamsim fuzz\nbackend thesis\nseed 1\n";
static uint8_t header[256];
static size_t header_size;

/* The header a new journal starts with. */
static void make_header(void)
{
	char path[400];
	snprintf(path, sizeof path, "%s/header.jnl", fuzz_dir());
	bsim_journal *j;
	bsim_error err;
	if (bsim_journal_create(&j, path, fields, inputs, RECORD, &err) != BSIM_OK ||
	    bsim_journal_close(j, &err) != BSIM_OK) {
		fprintf(stderr, "fuzz: %s\n", err.msg);
		abort();
	}
	FILE *f = fopen(path, "rb");
	header_size = f ? fread(header, 1, sizeof header, f) : 0;
	if (!f || header_size == 0 || header_size == sizeof header)
		abort();
	fclose(f);
}

static int take(void *user, uint64_t index, const void *payload)
{
	(void)payload;
	++*(long *)user;
	return index >= INDICES;
}

static void fail(const char *what, const bsim_error *err)
{
	fprintf(stderr, "fuzz: %s: %s\n", what, err->msg);
	abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	if (!header_size)
		make_header();
	if (size == 0)
		return 0;
	int mode = data[0] % 3;
	data++, size--;
	size_t cap = header_size + size + (size / 8 + 1) * (RECORD + 16);
	uint8_t *file = malloc(cap), *p = file;
	if (!file)
		return 0;
	if (mode > 0) {
		memcpy(p, header, header_size);
		p += header_size;
	}
	if (mode < 2) {
		memcpy(p, data, size);
		p += size;
	} else {
		for (size_t at = 0; at + 8 <= size && (p - file) + RECORD + 16 <= (long)cap;) {
			uint32_t magic = 0x5243524Au;
			memcpy(p, &magic, 4);
			memcpy(p + 4, data + at, 8);
			at += 8;
			size_t n = size - at < RECORD ? size - at : RECORD;
			memset(p + 12, 0, RECORD);
			memcpy(p + 12, data + at, n);
			at += n;
			uint32_t crc = (uint32_t)crc32(0L, p + 4, 8 + RECORD);
			memcpy(p + 12 + RECORD, &crc, 4);
			p += 16 + RECORD;
		}
	}
	const char *path = fuzz_write("journal.jnl", file, (size_t)(p - file));
	free(file);

	bsim_journal *j;
	bsim_error err;
	bsim_error_clear(&err);
	int rc = bsim_journal_resume(&j, path, fields, inputs, RECORD, &err);
	if (rc != BSIM_OK) {
		fuzz_check_error(rc, &err);
		return 0;
	}
	long seen = 0, kept = 0, cut = 0;
	rc = bsim_journal_replay(j, take, &seen, &kept, &cut, &err);
	if (rc != BSIM_OK) {
		fuzz_check_error(rc, &err);
		bsim_journal_close(j, &err);
		return 0;
	}
	fuzz_accepted();
	uint8_t payload[RECORD] = {1, 2, 3};
	if (bsim_journal_append(j, 7, payload, &err) != BSIM_OK)
		fail("append", &err);
	if (bsim_journal_close(j, &err) != BSIM_OK)
		fail("close", &err);
	/* Read back: what was kept, the appended record, nothing cut. */
	long seen2 = 0, kept2 = 0, cut2 = 0;
	if (bsim_journal_resume(&j, path, fields, inputs, RECORD, &err) != BSIM_OK)
		fail("resume after append", &err);
	if (bsim_journal_replay(j, take, &seen2, &kept2, &cut2, &err) != BSIM_OK)
		fail("replay after append", &err);
	bsim_journal_close(j, &err);
	if (kept2 != kept + 1 || cut2 != 0) {
		fprintf(stderr,
		        "fuzz: journal kept %ld records, cut %ld bytes; after one append "
		        "it reads back %ld records, cut %ld\n",
		        kept, cut, kept2, cut2);
		abort();
	}
	return 0;
}
