/* The journal of finished work (util/journal.h), on its own: records
 * appended from several threads all come back, byte for byte; a torn or
 * damaged tail is cut off and only it; a journal of other inputs, other
 * fields, another record size or another format version (format 1, as
 * the build before it wrote) is refused, naming what differs. The fields
 * a sweep's journal names (beamsim/trial_fields.h) cover the result, the
 * gate entry and the beam peak member by member, as the compiler lays
 * them out. */
#define _POSIX_C_SOURCE 200809L

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <zlib.h>

#include "beamsim/trial_fields.h"
#include "beamsim/trial.h"
#include "util/journal.h"
#include "support.h"

#define N    400
#define SIZE 40 /* bytes of payload */

static const char inputs[] = "beamsim test\nseed 1\ntrials 400\n";
static const char fields[] = "test_record 40\na double 0 8\nb double 8 32\n";

/* Record i's payload: a pattern of i, so any mix-up shows. */
static void payload(uint64_t i, unsigned char *p)
{
	for (int k = 0; k < SIZE; k++)
		p[k] = (unsigned char)(i * 31 + (uint64_t)k * 7);
}

typedef struct seen {
	int count[N];
	int bad;
} seen;

static int take(void *user, uint64_t index, const void *data)
{
	seen *s = user;
	unsigned char want[SIZE];
	if (index >= N)
		return 1;
	payload(index, want);
	s->bad += memcmp(want, data, SIZE) != 0;
	s->count[index]++;
	return 0;
}

typedef struct writer {
	bsim_journal *j;
	int first, step;
} writer;

static void *write_some(void *arg)
{
	writer *w = arg;
	unsigned char p[SIZE];
	bsim_error err;
	for (int i = w->first; i < N; i += w->step) {
		payload((uint64_t)i, p);
		if (bsim_journal_append(w->j, (uint64_t)i, p, &err) != BSIM_OK)
			return (void *)1;
	}
	return NULL;
}

static const char *path_of(const char *name)
{
	static char path[1200];
	snprintf(path, sizeof path, "%s/journal", bsim_test_dir(name));
	return path;
}

/* Writes all N records from four threads. */
static void fill(const char *path)
{
	bsim_journal *j;
	bsim_error err;
	assert_int_equal(bsim_journal_create(&j, path, fields, inputs, SIZE, &err), BSIM_OK);
	long kept, cut;
	assert_int_equal(bsim_journal_replay(j, NULL, NULL, &kept, &cut, &err), BSIM_OK);
	assert_int_equal(kept, 0);
	pthread_t t[4];
	writer w[4];
	for (int k = 0; k < 4; k++) {
		w[k] = (writer){j, k, 4};
		pthread_create(&t[k], NULL, write_some, &w[k]);
	}
	for (int k = 0; k < 4; k++) {
		void *bad;
		pthread_join(t[k], &bad);
		assert_null(bad);
	}
	assert_int_equal(bsim_journal_close(j, &err), BSIM_OK);
}

/* Resumes path and counts what comes back. */
static long replay(const char *path, seen *s, long *cut)
{
	bsim_journal *j;
	bsim_error err;
	long kept = 0;
	memset(s, 0, sizeof *s);
	assert_int_equal(bsim_journal_resume(&j, path, fields, inputs, SIZE, &err), BSIM_OK);
	assert_int_equal(bsim_journal_replay(j, take, s, &kept, cut, &err), BSIM_OK);
	assert_int_equal(bsim_journal_close(j, &err), BSIM_OK);
	assert_int_equal(s->bad, 0);
	return kept;
}

static void test_all_records_back(void **state)
{
	(void)state;
	const char *path = path_of("all");
	fill(path);
	seen s;
	long cut;
	assert_int_equal(replay(path, &s, &cut), N);
	assert_int_equal(cut, 0);
	for (int i = 0; i < N; i++)
		assert_int_equal(s.count[i], 1);
}

static long file_size(const char *path)
{
	struct stat st;
	assert_int_equal(stat(path, &st), 0);
	return (long)st.st_size;
}

/* A kill in the middle of a write leaves part of a record: it is cut off,
 * the rest kept, and appending carries on from there. */
static void test_torn_tail(void **state)
{
	(void)state;
	const char *path = path_of("torn");
	fill(path);
	long size = file_size(path);
	assert_int_equal(truncate(path, size - 5), 0);
	seen s;
	long cut;
	assert_int_equal(replay(path, &s, &cut), N - 1);
	assert_int_equal(cut, SIZE + 16 - 5);
	assert_int_equal(file_size(path), size - (SIZE + 16));
	/* append the lost one again and all are there */
	bsim_journal *j;
	bsim_error err;
	long kept;
	int lost = -1;
	assert_int_equal(bsim_journal_resume(&j, path, fields, inputs, SIZE, &err), BSIM_OK);
	assert_int_equal(bsim_journal_replay(j, take, &s, &kept, &cut, &err), BSIM_OK);
	for (int i = 0; i < N; i++)
		if (s.count[i] == 0)
			lost = i;
	assert_true(lost >= 0);
	unsigned char p[SIZE];
	payload((uint64_t)lost, p);
	assert_int_equal(bsim_journal_append(j, (uint64_t)lost, p, &err), BSIM_OK);
	assert_int_equal(bsim_journal_close(j, &err), BSIM_OK);
	assert_int_equal(replay(path, &s, &cut), N);
}

/* One flipped bit in record 100: it and everything after it are dropped
 * (they run again), nothing before it. */
static void test_damaged_record(void **state)
{
	(void)state;
	const char *path = path_of("damaged");
	fill(path);
	long header = file_size(path) - (long)N * (SIZE + 16);
	FILE *f = fopen(path, "r+b");
	assert_non_null(f);
	long at = header + 100L * (SIZE + 16) + 20;
	fseek(f, at, SEEK_SET);
	int c = fgetc(f);
	fseek(f, at, SEEK_SET);
	fputc(c ^ 4, f);
	fclose(f);
	seen s;
	long cut;
	assert_int_equal(replay(path, &s, &cut), 100);
	assert_int_equal(cut, (long)(N - 100) * (SIZE + 16));
}

/* Other inputs, another record size, or no journal at all. */
static void test_refusals(void **state)
{
	(void)state;
	const char *path = path_of("refuse");
	fill(path);
	bsim_journal *j = NULL;
	bsim_error err;
	assert_int_equal(bsim_journal_resume(&j, path, fields, "beamsim test\nseed 2\ntrials 400\n",
	                                     SIZE, &err),
	                 BSIM_EINPUT);
	assert_null(j);
	assert_non_null(strstr(err.msg, "\"seed 1\" then, \"seed 2\" now (line 2"));
	assert_int_equal(bsim_journal_resume(&j, path, fields, inputs, SIZE + 8, &err),
	                 BSIM_EINPUT);
	assert_non_null(strstr(err.msg, "records of 40 bytes"));
	const char *other = bsim_test_write(bsim_test_dir("refuse2"), "x", "not a journal\n");
	assert_int_equal(bsim_journal_resume(&j, other, fields, inputs, SIZE, &err), BSIM_EINPUT);
	assert_non_null(strstr(err.msg, "expected a beamsim journal"));
}

/* Records of other fields (a member moved), and a journal of format 1
 * (its header without the fields, as the build before this format wrote
 * it), are refused by a one-line message naming the file and what
 * differs; the file is left as it was. */
static void test_other_format(void **state)
{
	(void)state;
	char path[1200], v1[1200];
	snprintf(path, sizeof path, "%s", path_of("format"));
	snprintf(v1, sizeof v1, "%s", path_of("format1"));
	fill(path);
	long size = file_size(path);
	bsim_journal *j = NULL;
	bsim_error err;
	const char *moved = "test_record 40\na double 0 8\nb double 16 24\n";
	assert_int_equal(bsim_journal_resume(&j, path, moved, inputs, SIZE, &err), BSIM_EINPUT);
	assert_null(j);
	assert_non_null(strstr(err.msg, path));
	assert_non_null(strstr(err.msg, "records of other fields: \"b double 8 32\" then, "
	                                "\"b double 16 24\" now (line 3 of the fields)"));
	assert_null(strchr(err.msg, '\n'));
	long n, cut;
	assert_int_equal(bsim_journal_read(path, moved, inputs, SIZE, NULL, NULL, &n, &cut, &err),
	                 BSIM_EINPUT);
	assert_non_null(strstr(err.msg, "records of other fields"));

	/* format 1: "BSIMJNL1", u32 record size, u32 inputs length, inputs,
	 * u32 CRC-32 of them; then the same records */
	uint32_t rs = SIZE, il = (uint32_t)strlen(inputs);
	unsigned char h[16 + sizeof inputs + 4];
	memcpy(h, "BSIMJNL1", 8);
	memcpy(h + 8, &rs, 4);
	memcpy(h + 12, &il, 4);
	memcpy(h + 16, inputs, il);
	uint32_t crc = (uint32_t)crc32(0L, h, 16 + il);
	memcpy(h + 16 + il, &crc, 4);
	FILE *f = fopen(v1, "wb");
	assert_non_null(f);
	assert_int_equal(fwrite(h, 1, 20 + il, f), 20 + il);
	assert_int_equal(fclose(f), 0);
	assert_int_equal(bsim_journal_resume(&j, v1, fields, inputs, SIZE, &err), BSIM_EINPUT);
	assert_null(j);
	assert_non_null(strstr(err.msg, v1));
	assert_non_null(strstr(err.msg, "a journal of format 1, this build reads format 2"));
	assert_int_equal(file_size(v1), 20 + il);
	assert_int_equal(file_size(path), size);
	/* the right fields still read it, every record */
	seen s;
	assert_int_equal(replay(path, &s, &cut), N);
}

static int by_offset(const void *a, const void *b)
{
	const bsim_trial_member *x = a, *y = b;
	return (x->offset > y->offset) - (x->offset < y->offset);
}

/* The members named for a journal's records tile each struct: in the
 * order of their offsets, every one at the first offset its alignment
 * allows after the one before, the last ending where the struct's
 * alignment pads it to its size. A member of the struct left out of the
 * table leaves a gap that fails here; the kind's size divides the
 * member's (an array is of its element's kind). */
static void test_members_cover_the_result(void **state)
{
	(void)state;
	int n;
	const bsim_trial_member *all = bsim_trial_members(&n);
	bsim_trial_member *m = malloc((size_t)n * sizeof *m);
	assert_non_null(m);
	memcpy(m, all, (size_t)n * sizeof *m);
	const struct {
		const char *prefix;
		size_t size;
	} structs[] = {{"", sizeof(bsim_trial_result)},
	               {"gate_entry.", sizeof(bsim_gate_entry)},
	               {"beam_peak.", sizeof(bsim_beam_peak)}};
	int k = 0;
	for (int s = 0; s < 3; s++) {
		int first = k;
		size_t pl = strlen(structs[s].prefix);
		while (k < n && (pl ? strncmp(m[k].name, structs[s].prefix, pl) == 0
		                    : strncmp(m[k].name, "gate_entry.", 11) != 0))
			k++;
		assert_true(k > first);
		qsort(m + first, (size_t)(k - first), sizeof *m, by_offset);
		size_t end = 0, align_max = 1;
		for (int i = first; i < k; i++) {
			size_t kind =
			        strcmp(m[i].kind, "double") == 0 ||
			                        strcmp(m[i].kind, "long") == 0 ||
			                        strcmp(m[i].kind, "ulong") == 0
			                ? 8
			        : strcmp(m[i].kind, "int") == 0 || strcmp(m[i].kind, "uint") == 0
			                ? 4
			                : 0;
			if (kind == 0 || m[i].size % kind != 0)
				fail_msg("%s: kind %s, %zu bytes", m[i].name, m[i].kind, m[i].size);
			size_t at = (end + kind - 1) / kind * kind;
			if (m[i].offset != at)
				fail_msg("%s at %zu, expected %zu: a member before it is not in "
				         "the table",
				         m[i].name, m[i].offset, at);
			end = m[i].offset + m[i].size;
			align_max = kind > align_max ? kind : align_max;
		}
		size_t padded = (end + align_max - 1) / align_max * align_max;
		if (padded != structs[s].size)
			fail_msg("struct %d: its members end at %zu, the struct at %zu: a member "
			         "after the last is not in the table",
			         s, end, structs[s].size);
	}
	assert_int_equal(k, n);
	free(m);
	/* the journal's text names each struct and member, one a line */
	const char *text = bsim_trial_record_fields();
	int nl = 0;
	for (const char *c = text; *c; c++)
		nl += *c == '\n';
	assert_int_equal(nl, n + 3);
	char want[64];
	snprintf(want, sizeof want, "bsim_trial_result %zu\n", sizeof(bsim_trial_result));
	assert_int_equal(strncmp(text, want, strlen(want)), 0);
	assert_non_null(strstr(text, "\noutcome uint 0 4\n"));
	assert_non_null(strstr(text, "\nbsim_beam_peak 16\nbeam int 0 4\npeak double 8 8\n"));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_all_records_back),
	        cmocka_unit_test(test_torn_tail),
	        cmocka_unit_test(test_damaged_record),
	        cmocka_unit_test(test_refusals),
	        cmocka_unit_test(test_other_format),
	        cmocka_unit_test(test_members_cover_the_result),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
