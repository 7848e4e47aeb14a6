/* A regular file read whole, without blocking on anything else
 * (util/file_read.h). */
#define _POSIX_C_SOURCE 200809L
#include "util/file_read.h"

#include <errno.h>
#include <fcntl.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "beamsim/limits.h"

void bsim_file_text_free(file_text *t)
{
	free(t->text);
	t->text = NULL;
	t->len = 0;
}

static int cannot_read(const char *path, int e, bsim_error *err)
{
	return bsim_error_set(err, BSIM_EINPUT, "%s: cannot read the file: %s", path,
	                      e ? strerror(e) : "read error");
}

const char *bsim_file_kind(const struct stat *st)
{
	mode_t m = st->st_mode;
	return S_ISDIR(m)    ? "a directory"
	       : S_ISFIFO(m) ? "a FIFO"
	       : S_ISCHR(m)  ? "a character device"
	       : S_ISBLK(m)  ? "a block device"
	       : S_ISSOCK(m) ? "a socket"
	                     : "a special file";
}

static int too_big(const char *path, double max_bytes, const char *limit_name, bsim_error *err)
{
	if (!limit_name)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: expected a file of at most %.15g bytes, got more", path,
		                      max_bytes);
	char hint[160];
	bsim_limits_hint(hint, sizeof hint, limit_name, max_bytes);
	return bsim_error_set(err, BSIM_EINPUT,
	                      "%s: expected a file of at most %.15g bytes, got more (%s)", path,
	                      max_bytes, hint);
}

/* Reads fd to its end into a buffer of cap bytes to start with (grown as
 * the file turns out longer than fstat said), stopping at limit + 1 bytes:
 * *n past limit means too large. NULL with errno on failure. */
static char *read_fd(int fd, size_t cap, size_t limit, size_t *n)
{
	char *buf = malloc(cap + 1); /* + 1: the NUL */
	*n = 0;
	while (buf) {
		if (*n == cap) {
			if (cap > limit)
				break;
			size_t grown = cap < limit / 2 ? 2 * cap : limit + 1;
			char *b = realloc(buf, grown + 1);
			if (!b) {
				free(buf);
				errno = ENOMEM;
				return NULL;
			}
			buf = b;
			cap = grown;
		}
		ssize_t k = read(fd, buf + *n, cap - *n);
		if (k < 0 && errno == EINTR)
			continue;
		if (k < 0) {
			int e = errno;
			free(buf);
			errno = e;
			return NULL;
		}
		if (k == 0)
			break;
		*n += (size_t)k;
	}
	if (!buf)
		errno = ENOMEM;
	return buf;
}

int bsim_file_open_checked(const char *path, struct stat *st)
{
	int fd = open(path, O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
	if (fd >= 0 && fstat(fd, st) != 0) {
		int e = errno;
		close(fd);
		errno = e;
		fd = -1;
	}
	return fd;
}

int bsim_file_read(const char *path, const char *what, double max_bytes, const char *limit_name,
                   file_text *out, bsim_error *err)
{
	out->text = NULL;
	out->len = 0;
	struct stat st;
	int fd = bsim_file_open_checked(path, &st);
	if (fd < 0)
		return cannot_read(path, errno, err);
	if (!S_ISREG(st.st_mode)) {
		close(fd);
		return bsim_error_set(err, BSIM_EINPUT, "%s: expected %s, got %s", path, what,
		                      bsim_file_kind(&st));
	}
	if ((double)st.st_size > max_bytes) {
		close(fd);
		return too_big(path, max_bytes, limit_name, err);
	}
	/* Past SIZE_MAX / 4 no buffer could be had anyway. */
	size_t limit = max_bytes < (double)(SIZE_MAX / 4) ? (size_t)max_bytes : SIZE_MAX / 4;
	/* fstat's size is a hint (a file in /proc says 0, a file may grow):
	 * one byte more, to see its end without another allocation. */
	size_t cap = (size_t)st.st_size < limit ? (size_t)st.st_size + 1 : limit + 1;
	if (cap < 4096 && limit >= 4096)
		cap = 4096;
	size_t n;
	errno = 0;
	char *buf = read_fd(fd, cap, limit, &n);
	int e = errno;
	close(fd);
	if (!buf)
		return e == ENOMEM ? bsim_error_set(err, BSIM_EFAIL, "%s: out of memory", path)
		                   : cannot_read(path, e, err);
	if (n > limit) {
		free(buf);
		return too_big(path, max_bytes, limit_name, err);
	}
	buf[n] = '\0';
	out->text = buf;
	out->len = n;
	return BSIM_OK;
}
