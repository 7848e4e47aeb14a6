/* CSV tables read row by row (csv_stream.h). */
#define _POSIX_C_SOURCE 200809L
#include "util/csv_stream.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "util/csv_table.h"
#include "util/file_read.h"

/* The first read's buffer; it grows to hold the longest line. */
#define CSV_STREAM_CHUNK 262144

static int cannot_read(const char *path, int e, bsim_error *err)
{
	return bsim_error_set(err, BSIM_EINPUT, "%s: cannot read the file: %s", path,
	                      e ? strerror(e) : "read error");
}

static int too_big(const char *path, bsim_error *err)
{
	return bsim_error_set(err, BSIM_EINPUT,
	                      "%s: expected a file of at most %.15g bytes, got more", path,
	                      CSV_TABLE_MAX_BYTES);
}

/* More bytes after s->end, the buffer compacted and grown as needed. */
static int fill(csv_stream *s, bsim_error *err)
{
	if (s->start > 0) {
		memmove(s->buf, s->buf + s->start, s->end - s->start);
		s->end -= s->start;
		s->start = 0;
	}
	if (s->end == s->cap) {
		size_t cap = 2 * s->cap;
		char *b = realloc(s->buf, cap);
		if (!b)
			return bsim_error_set(err, BSIM_EFAIL, "out of memory reading %s", s->path);
		s->buf = b;
		s->cap = cap;
	}
	for (;;) {
		ssize_t k = read(s->fd, s->buf + s->end, s->cap - s->end);
		if (k < 0 && errno == EINTR)
			continue;
		if (k < 0)
			return cannot_read(s->path, errno, err);
		s->eof = k == 0;
		s->end += (size_t)k;
		s->bytes += (double)k;
		return s->bytes > CSV_TABLE_MAX_BYTES ? too_big(s->path, err) : BSIM_OK;
	}
}

/* The line feed that ends the row at p (avail bytes, the first scanned
 * of them already seen, with *quoted the quoting after them): one outside
 * double quotes, as a quoted field may hold a line break
 * (bsim_csv_field_write). NULL if the bytes hold none yet; *breaks counts the
 * line feeds inside quotes. */
static char *row_end(char *p, size_t avail, size_t *scanned, int *quoted, long *breaks)
{
	while (*scanned < avail) {
		char *from = p + *scanned;
		char *nl = memchr(from, '\n', avail - *scanned);
		char *to = nl ? nl : p + avail;
		for (char *q = memchr(from, '"', (size_t)(to - from)); q;
		     q = q + 1 < to ? memchr(q + 1, '"', (size_t)(to - q - 1)) : NULL)
			*quoted = !*quoted; /* a doubled quote turns it twice */
		*scanned = nl ? (size_t)(nl - p) + 1 : avail;
		if (nl && !*quoted)
			return nl;
		*breaks += nl != NULL;
	}
	return NULL;
}

/* The next row, its line feed (and a CR before it) cut off: 1 and *line,
 * 0 at the end of the file, -1 on a NUL byte or a last line cut short
 * (bsim_csv_text_check's messages) or a read error. */
static int next_line(csv_stream *s, char **line, bsim_error *err)
{
	size_t scanned = 0; /* bytes after start already seen */
	int quoted = 0;
	long breaks = 0;
	for (;;) {
		char *p = s->buf + s->start;
		size_t avail = s->end - s->start;
		char *nl = row_end(p, avail, &scanned, &quoted, &breaks);
		if (nl || (s->eof && avail > 0)) {
			size_t len = nl ? (size_t)(nl - p) : avail;
			s->line += 1 + s->breaks;
			s->breaks = breaks;
			char *z = memchr(p, '\0', len);
			if (z) {
				bsim_error_set(err, BSIM_EINPUT,
				               "%s:%ld:%ld: expected text, got a NUL byte", s->path,
				               s->line, (long)(z - p) + 1);
				return -1;
			}
			if (!nl) {
				bsim_error_set(
				        err, BSIM_EINPUT,
				        "%s:%ld: expected a whole line ending in a line feed, "
				        "got the file cut short in this line",
				        s->path, s->line);
				return -1;
			}
			*nl = '\0';
			if (len > 0 && p[len - 1] == '\r')
				p[len - 1] = '\0';
			s->start += len + 1;
			*line = p;
			return 1;
		}
		if (s->eof)
			return 0;
		if (fill(s, err) != BSIM_OK)
			return -1;
	}
}

void bsim_csv_stream_close(csv_stream *s)
{
	if (s->fd >= 0)
		close(s->fd);
	if (s->names) {
		free(s->names[0]);
		free(s->names);
	}
	free(s->cells);
	free(s->buf);
	memset(s, 0, sizeof *s);
	s->fd = -1;
}

int bsim_csv_stream_open(const char *path, csv_stream *s, bsim_error *err)
{
	memset(s, 0, sizeof *s);
	s->path = path;
	struct stat st;
	s->fd = bsim_file_open_checked(path, &st);
	if (s->fd < 0)
		return cannot_read(path, errno, err);
	int rc = BSIM_OK;
	if (!S_ISREG(st.st_mode))
		rc = bsim_error_set(err, BSIM_EINPUT, "%s: expected a CSV file, got %s", path,
		                    bsim_file_kind(&st));
	else if ((double)st.st_size > CSV_TABLE_MAX_BYTES)
		rc = too_big(path, err);
	else if (!(s->buf = malloc(CSV_STREAM_CHUNK)))
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory reading %s", path);
	s->cap = CSV_STREAM_CHUNK;
	char *header = NULL;
	int got = rc ? -1 : next_line(s, &header, err);
	if (!rc && got == 0)
		rc = bsim_error_set(err, BSIM_EINPUT, "%s:1: expected a header line", path);
	else if (!rc && got < 0)
		rc = err ? err->code : BSIM_EINPUT;
	if (!rc) {
		s->n_cols = bsim_csv_count_fields(header);
		s->names = calloc((size_t)s->n_cols, sizeof *s->names);
		s->cells = calloc((size_t)s->n_cols, sizeof *s->cells);
		char *copy = strdup(header);
		if (!s->names || !s->cells || !copy) {
			free(copy);
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory reading %s", path);
		} else {
			bsim_csv_split(copy, s->names, s->n_cols);
		}
	}
	if (rc)
		bsim_csv_stream_close(s);
	return rc;
}

int bsim_csv_stream_next(csv_stream *s, bsim_error *err)
{
	char *line;
	int got;
	while ((got = next_line(s, &line, err)) == 1) {
		int n = bsim_csv_count_fields(line);
		if (n == s->n_cols && s->bad_line == 0 && bsim_csv_split(line, s->cells, n) == n)
			return 1;
		if (s->bad_line == 0) {
			s->bad_line = s->line;
			s->bad_got = n == s->n_cols ? -1 : n; /* -1: a malformed quote */
		}
	}
	if (got == 0 && s->bad_line > 0 && s->bad_got < 0) {
		bsim_error_set(err, BSIM_EINPUT,
		               "%s:%ld: expected %d fields, got a quoted field not closed where "
		               "its field ends",
		               s->path, s->bad_line, s->n_cols);
		return -1;
	}
	if (got == 0 && s->bad_line > 0) {
		bsim_error_set(err, BSIM_EINPUT, "%s:%ld: expected %d fields, got %d", s->path,
		               s->bad_line, s->n_cols, s->bad_got);
		return -1;
	}
	return got;
}

double bsim_csv_count_lines(const char *path)
{
	struct stat st;
	int fd = bsim_file_open_checked(path, &st);
	if (fd < 0)
		return -1;
	char *buf = S_ISREG(st.st_mode) ? malloc(CSV_STREAM_CHUNK) : NULL;
	double n = buf ? 0 : -1;
	for (ssize_t k; buf;) {
		k = read(fd, buf, CSV_STREAM_CHUNK);
		if (k < 0 && errno == EINTR)
			continue;
		if (k <= 0) {
			n = k < 0 ? -1 : n;
			break;
		}
		for (char *p = buf, *end = buf + k; (p = memchr(p, '\n', (size_t)(end - p))); p++)
			n++;
	}
	free(buf);
	close(fd);
	return n;
}
