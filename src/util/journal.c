/* The journal of finished work; see util/journal.h. */
#define _POSIX_C_SOURCE 200809L

#include "util/journal.h"
#include "beamsim/limits.h"

#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <zlib.h>

/* "BSIMJNL" and the format's version */
static const char magic[8] = {'B', 'S', 'I', 'M', 'J', 'N', 'L', '0' + BSIM_JOURNAL_VERSION};
#define RECORD_MAGIC  0x5243524Au
#define SYNC_INTERVAL 1.0 /* s between syncs to disk */

struct bsim_journal {
	int fd;
	size_t record_size;
	unsigned char *buf; /* one encoded record */
	pthread_mutex_t lock;
	double last_sync; /* s, monotonic */
	int failed;       /* the errno of the append that failed: the rest are refused with it */
	char path[BSIM_PATH_MAX];
};

static double now_seconds(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* write(2) of all n bytes: 0 or an errno. */
static int write_all(int fd, const void *p, size_t n)
{
	const char *c = p;
	while (n > 0) {
		ssize_t k = write(fd, c, n);
		if (k < 0 && errno == EINTR)
			continue;
		if (k <= 0)
			return k < 0 ? errno : EIO;
		c += k;
		n -= (size_t)k;
	}
	return 0;
}

/* read(2) of up to n bytes, until EOF: the count, or -1. */
static ssize_t read_all(int fd, void *p, size_t n)
{
	size_t got = 0;
	while (got < n) {
		ssize_t k = read(fd, (char *)p + got, n - got);
		if (k < 0 && errno == EINTR)
			continue;
		if (k < 0)
			return -1;
		if (k == 0)
			break;
		got += (size_t)k;
	}
	return (ssize_t)got;
}

static bsim_journal *journal_alloc(const char *path, size_t record_size)
{
	bsim_journal *j = calloc(1, sizeof *j);
	if (!j)
		return NULL;
	j->fd = -1;
	j->record_size = record_size;
	j->buf = malloc(record_size + 16);
	snprintf(j->path, sizeof j->path, "%s", path);
	if (!j->buf || pthread_mutex_init(&j->lock, NULL) != 0) {
		free(j->buf);
		free(j);
		return NULL;
	}
	j->last_sync = now_seconds();
	return j;
}

static void journal_free(bsim_journal *j)
{
	if (j->fd >= 0)
		close(j->fd);
	pthread_mutex_destroy(&j->lock);
	free(j->buf);
	free(j);
}

/* u32 n then n bytes of text at p; p past them. */
static unsigned char *put_text(unsigned char *p, const char *text, uint32_t n)
{
	memcpy(p, &n, 4);
	memcpy(p + 4, text, n);
	return p + 4 + n;
}

/* The header for these fields and inputs, malloc'd, its size in *n. */
static unsigned char *header_encode(const char *fields, const char *inputs, size_t record_size,
                                    size_t *n)
{
	uint32_t rs = (uint32_t)record_size, fl = (uint32_t)strlen(fields),
	         il = (uint32_t)strlen(inputs);
	*n = sizeof magic + 4 + 4 + fl + 4 + il + 4;
	unsigned char *h = malloc(*n);
	if (!h)
		return NULL;
	memcpy(h, magic, sizeof magic);
	memcpy(h + 8, &rs, 4);
	unsigned char *p = put_text(put_text(h + 12, fields, fl), inputs, il);
	uint32_t crc = (uint32_t)crc32(0L, h, (uInt)(p - h));
	memcpy(p, &crc, 4);
	return h;
}

int bsim_journal_create(bsim_journal **out, const char *path, const char *fields,
                        const char *inputs, size_t record_size, bsim_error *err)
{
	*out = NULL;
	bsim_journal *j = journal_alloc(path, record_size);
	size_t n = 0;
	unsigned char *h = j ? header_encode(fields, inputs, record_size, &n) : NULL;
	char tmp[BSIM_PATH_MAX];
	if (!h || snprintf(tmp, sizeof tmp, "%s.new", path) >= (int)sizeof tmp) {
		if (j)
			journal_free(j);
		free(h);
		return bsim_error_set(err, BSIM_EFAIL, "%s: out of memory or path too long", path);
	}
	/* The header is written under another name and renamed into place: a
	 * journal that exists has its whole header, whenever the process is
	 * killed. */
	j->fd = open(tmp, O_RDWR | O_CREAT | O_TRUNC | O_APPEND | O_CLOEXEC, 0666);
	int e = j->fd < 0 ? errno : write_all(j->fd, h, n);
	if (!e && fsync(j->fd) != 0)
		e = errno;
	if (!e && rename(tmp, path) != 0)
		e = errno;
	free(h);
	if (e) {
		unlink(tmp);
		journal_free(j);
		return bsim_error_set(err, BSIM_EFAIL, "%s: cannot write the journal: %s", path,
		                      strerror(e));
	}
	*out = j;
	return BSIM_OK;
}

/* The first line where a and b (the text named what) differ, for the
 * refusal message. */
static void first_difference(const char *a, const char *b, const char *what, char *msg, size_t size)
{
	int line = 1;
	const char *la = a, *lb = b;
	while (*a && *a == *b) {
		if (*a == '\n') {
			line++;
			la = a + 1;
			lb = b + 1;
		}
		a++;
		b++;
	}
	int na = (int)strcspn(la, "\n"), nb = (int)strcspn(lb, "\n");
	snprintf(msg, size, "\"%.*s\" then, \"%.*s\" now (line %d of the %s)", na > 120 ? 120 : na,
	         la, nb > 120 ? 120 : nb, lb, line, what);
}

/* The next u32 length and text of the header being read into *h (grown),
 * its bytes counted in *used; the text's offset in *at. 0, or -1 if the
 * file ends or the length is past any header's. */
static int read_text(int fd, unsigned char **h, size_t *used, size_t *at, uint32_t *len)
{
	unsigned char *g = realloc(*h, *used + 4);
	if (!g || read_all(fd, g + *used, 4) != 4) {
		*h = g ? g : *h;
		return -1;
	}
	*h = g;
	memcpy(len, g + *used, 4);
	*used += 4;
	if (*len > 64u << 20)
		return -1;
	if (!(g = realloc(*h, *used + *len + 1)))
		return -1;
	*h = g;
	*at = *used;
	if (read_all(fd, g + *used, *len) != (ssize_t)*len)
		return -1;
	*used += *len;
	return 0;
}

/* Checks the header at the start of fd against fields, inputs and
 * record_size. */
static int header_check(int fd, const char *path, const char *fields, const char *inputs,
                        size_t record_size, bsim_error *err)
{
	unsigned char head[12];
	uint32_t rs = 0, fl = 0, il = 0;
	if (read_all(fd, head, sizeof head) != (ssize_t)sizeof head ||
	    memcmp(head, magic, sizeof magic - 1) != 0)
		return bsim_error_set(err, BSIM_EINPUT, "%s: expected a beamsim journal", path);
	if (head[7] < '0' || head[7] > '9')
		return bsim_error_set(err, BSIM_EINPUT, "%s: expected a beamsim journal", path);
	if (head[7] != magic[7])
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: a journal of format %c, this build reads format %c "
		                      "(another beamsim build wrote it)",
		                      path, head[7], magic[7]);
	memcpy(&rs, head + 8, 4);
	size_t used = sizeof head, f_at = 0, i_at = 0;
	unsigned char *h = malloc(used);
	if (!h)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	memcpy(h, head, used);
	uint32_t crc = 0;
	int ok = read_text(fd, &h, &used, &f_at, &fl) == 0 &&
	         read_text(fd, &h, &used, &i_at, &il) == 0 && read_all(fd, &crc, 4) == 4 &&
	         crc == (uint32_t)crc32(0L, h, (uInt)used);
	if (!ok) {
		free(h);
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: expected a beamsim journal, got a damaged header", path);
	}
	char *then_fields = (char *)h + f_at, *then = (char *)h + i_at;
	int rc = BSIM_OK;
	char diff[400];
	if (strlen(fields) != fl || memcmp(then_fields, fields, fl) != 0) {
		char *z = strndup(then_fields, fl);
		if (!z) {
			free(h);
			return bsim_error_set(err, BSIM_EFAIL, "out of memory");
		}
		first_difference(z, fields, "fields", diff, sizeof diff);
		free(z);
		rc = bsim_error_set(
		        err, BSIM_EINPUT,
		        "%s: records of other fields: %s (another beamsim build wrote it)", path,
		        diff);
	} else if (rs != record_size) {
		rc = bsim_error_set(
		        err, BSIM_EINPUT,
		        "%s: records of %u bytes, this build writes %zu (another beamsim "
		        "build)",
		        path, rs, record_size);
	} else if (strlen(inputs) != il || memcmp(then, inputs, il) != 0) {
		then[il] = '\0'; /* the last text: room was made for it */
		first_difference(then, inputs, "inputs", diff, sizeof diff);
		rc = bsim_error_set(err, BSIM_EINPUT, "the run was started with other inputs: %s",
		                    diff);
	}
	free(h);
	return rc;
}

int bsim_journal_resume(bsim_journal **out, const char *path, const char *fields,
                        const char *inputs, size_t record_size, bsim_error *err)
{
	*out = NULL;
	bsim_journal *j = journal_alloc(path, record_size);
	if (!j)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	j->fd = open(path, O_RDWR | O_CLOEXEC);
	if (j->fd < 0) {
		int e = errno;
		journal_free(j);
		return bsim_error_set(err, e == ENOENT ? BSIM_EINPUT : BSIM_EFAIL,
		                      "%s: cannot read the journal: %s", path, strerror(e));
	}
	int rc = header_check(j->fd, path, fields, inputs, record_size, err);
	if (rc) {
		journal_free(j);
		return rc;
	}
	*out = j;
	return BSIM_OK;
}

int bsim_journal_replay(bsim_journal *j, bsim_journal_fn fn, void *user, long *n_records,
                        long *n_cut, bsim_error *err)
{
	*n_records = 0;
	*n_cut = 0;
	/* Records start after the header; a created journal is at its end. */
	off_t good = lseek(j->fd, 0, SEEK_CUR);
	size_t n = 4 + 8 + j->record_size + 4;
	for (int e = good < 0; !e;) {
		if (read_all(j->fd, j->buf, n) != (ssize_t)n)
			break;
		uint32_t m, crc;
		uint64_t index;
		memcpy(&m, j->buf, 4);
		memcpy(&index, j->buf + 4, 8);
		memcpy(&crc, j->buf + 12 + j->record_size, 4);
		if (m != RECORD_MAGIC ||
		    crc != (uint32_t)crc32(0L, j->buf + 4, (uInt)(8 + j->record_size)))
			break;
		if (fn && fn(user, index, j->buf + 12) != 0)
			break;
		++*n_records;
		good += (off_t)n;
	}
	struct stat st;
	int e = good < 0 || fstat(j->fd, &st) != 0 ? errno : 0;
	if (!e && st.st_size > good) {
		*n_cut = (long)(st.st_size - good);
		if (ftruncate(j->fd, good) != 0 || fsync(j->fd) != 0)
			e = errno;
	}
	/* Appends go to the end from here on. */
	int flags = e ? -1 : fcntl(j->fd, F_GETFL);
	if (!e && (flags < 0 || fcntl(j->fd, F_SETFL, flags | O_APPEND) != 0))
		e = errno;
	if (e) {
		j->failed = e;
		return bsim_error_set(err, BSIM_EFAIL, "%s: cannot continue the journal: %s",
		                      j->path, strerror(e));
	}
	return BSIM_OK;
}

int bsim_journal_read(const char *path, const char *fields, const char *inputs, size_t record_size,
                      bsim_journal_fn fn, void *user, long *n_records, long *n_cut, bsim_error *err)
{
	*n_records = 0;
	*n_cut = 0;
	int fd = open(path, O_RDONLY | O_CLOEXEC);
	if (fd < 0) {
		int e = errno;
		return bsim_error_set(err, e == ENOENT ? BSIM_EINPUT : BSIM_EFAIL,
		                      "%s: cannot read the journal: %s", path, strerror(e));
	}
	int rc = header_check(fd, path, fields, inputs, record_size, err);
	size_t n = 4 + 8 + record_size + 4;
	unsigned char *buf = rc ? NULL : malloc(n);
	if (!rc && !buf)
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	off_t good = rc ? 0 : lseek(fd, 0, SEEK_CUR);
	while (!rc && buf && read_all(fd, buf, n) == (ssize_t)n) {
		uint32_t m, crc;
		uint64_t index;
		memcpy(&m, buf, 4);
		memcpy(&index, buf + 4, 8);
		memcpy(&crc, buf + 12 + record_size, 4);
		if (m != RECORD_MAGIC ||
		    crc != (uint32_t)crc32(0L, buf + 4, (uInt)(8 + record_size)))
			break;
		if (fn && fn(user, index, buf + 12) != 0)
			break;
		++*n_records;
		good += (off_t)n;
	}
	struct stat st;
	if (!rc && fstat(fd, &st) == 0 && st.st_size > good)
		*n_cut = (long)(st.st_size - good);
	free(buf);
	close(fd);
	return rc;
}

int bsim_journal_append(bsim_journal *j, uint64_t index, const void *payload, bsim_error *err)
{
	uint32_t m = RECORD_MAGIC;
	int e = 0;
	pthread_mutex_lock(&j->lock);
	if (j->failed) {
		/* The cause, not a generic I/O error: which thread's append is
		 * reported is up to the caller (a sweep names the lowest trial). */
		e = j->failed;
	} else {
		memcpy(j->buf, &m, 4);
		memcpy(j->buf + 4, &index, 8);
		memcpy(j->buf + 12, payload, j->record_size);
		uint32_t crc = (uint32_t)crc32(0L, j->buf + 4, (uInt)(8 + j->record_size));
		memcpy(j->buf + 12 + j->record_size, &crc, 4);
		e = write_all(j->fd, j->buf, 16 + j->record_size);
		double t = now_seconds();
		if (!e && t - j->last_sync >= SYNC_INTERVAL) {
			if (fdatasync(j->fd) != 0)
				e = errno;
			j->last_sync = t;
		}
		j->failed = e;
	}
	pthread_mutex_unlock(&j->lock);
	if (e)
		return bsim_error_set(err, BSIM_EFAIL, "%s: cannot append to the journal: %s",
		                      j->path, strerror(e));
	return BSIM_OK;
}

int bsim_journal_close(bsim_journal *j, bsim_error *err)
{
	if (!j)
		return BSIM_OK;
	int e = fsync(j->fd) != 0 ? errno : 0;
	if (close(j->fd) != 0 && !e)
		e = errno;
	j->fd = -1;
	char path[sizeof j->path];
	snprintf(path, sizeof path, "%s", j->path);
	journal_free(j);
	if (e)
		return bsim_error_set(err, BSIM_EFAIL, "%s: cannot write the journal: %s", path,
		                      strerror(e));
	return BSIM_OK;
}

int bsim_journal_failed(const bsim_journal *j)
{
	return j->failed;
}

const char *bsim_journal_path(const bsim_journal *j)
{
	return j->path;
}
