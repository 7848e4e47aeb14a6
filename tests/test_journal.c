/* The journal of finished work (util/journal.h), on its own: records
 * appended from several threads all come back, byte for byte; a torn or
 * damaged tail is cut off and only it; a journal of other inputs or
 * another record size is refused, naming what differs. */
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

#include "util/journal.h"
#include "support.h"

#define N    400
#define SIZE 40 /* bytes of payload */

static const char inputs[] = "beamsim test\nseed 1\ntrials 400\n";

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
	assert_int_equal(bsim_journal_create(&j, path, inputs, SIZE, &err), BSIM_OK);
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
	assert_int_equal(bsim_journal_resume(&j, path, inputs, SIZE, &err), BSIM_OK);
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
	assert_int_equal(bsim_journal_resume(&j, path, inputs, SIZE, &err), BSIM_OK);
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
	assert_int_equal(
	        bsim_journal_resume(&j, path, "beamsim test\nseed 2\ntrials 400\n", SIZE, &err),
	        BSIM_EINPUT);
	assert_null(j);
	assert_non_null(strstr(err.msg, "\"seed 1\" then, \"seed 2\" now (line 2"));
	assert_int_equal(bsim_journal_resume(&j, path, inputs, SIZE + 8, &err), BSIM_EINPUT);
	assert_non_null(strstr(err.msg, "records of 40 bytes"));
	const char *other = bsim_test_write(bsim_test_dir("refuse2"), "x", "not a journal\n");
	assert_int_equal(bsim_journal_resume(&j, other, inputs, SIZE, &err), BSIM_EINPUT);
	assert_non_null(strstr(err.msg, "expected a beamsim journal"));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_all_records_back),
	        cmocka_unit_test(test_torn_tail),
	        cmocka_unit_test(test_damaged_record),
	        cmocka_unit_test(test_refusals),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
