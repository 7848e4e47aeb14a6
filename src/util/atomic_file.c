/* Whole-or-nothing files; see util/atomic_file.h. */
#define _POSIX_C_SOURCE 200809L

#include "util/atomic_file.h"

#include <errno.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

int bsim_atomic_file_is_through(const char *path)
{
	struct stat st;
	if (strcmp(path, "-") == 0)
		return 1;
	if (lstat(path, &st) != 0)
		return 0;
	return S_ISLNK(st.st_mode) || S_ISFIFO(st.st_mode) || S_ISCHR(st.st_mode) ||
	       S_ISBLK(st.st_mode) || S_ISSOCK(st.st_mode);
}

int bsim_atomic_file_open(bsim_atomic_file *o, const char *path, bsim_error *err)
{
	struct stat st;
	o->f = NULL;
	o->path = path;
	o->tmp[0] = '\0';
	o->mode = BSIM_ATOMIC_RENAME;
	if (strcmp(path, "-") == 0) {
		o->mode = BSIM_ATOMIC_STDOUT;
		o->f = stdout;
		return BSIM_OK;
	}
	if (stat(path, &st) == 0 && S_ISDIR(st.st_mode))
		return bsim_error_set(err, BSIM_EFAIL, "%s: cannot write: it is a directory", path);
	if (bsim_atomic_file_is_through(path)) {
		o->mode = BSIM_ATOMIC_THROUGH;
		o->f = fopen(path, "w");
		if (!o->f)
			return bsim_error_set(err, BSIM_EFAIL, "%s: cannot write: %s", path,
			                      strerror(errno));
		return BSIM_OK;
	}
	/* The process id keeps two runs writing the same PATH apart. */
	int n = snprintf(o->tmp, sizeof o->tmp, "%s.tmp.%ld", path, (long)getpid());
	if (n < 0 || (size_t)n >= sizeof o->tmp)
		/* Abbreviated, so the message keeps its end within the error. */
		return bsim_error_set(err, BSIM_EFAIL, "%.200s%s: path too long", path,
		                      strlen(path) > 200 ? "..." : "");
	o->f = fopen(o->tmp, "w");
	if (!o->f)
		return bsim_error_set(err, BSIM_EFAIL, "%s: cannot write: %s", path,
		                      strerror(errno));
	return BSIM_OK;
}

/* Flushes f to disk and closes it (never standard output): 0, or the
 * errno of the first failure. fsync comes before the rename, else a crash
 * soon after could leave PATH renamed but empty on some file systems; a
 * pipe or a terminal cannot be synced, which is no error. A write that
 * failed earlier shows only as ferror; errno most likely still holds its
 * cause. */
static int flush_close(FILE *f, int close)
{
	int saved = 0;
	if (ferror(f)) {
		/* The failed write's errno is long gone: flushing again most
		 * likely fails the same way and says why. */
		clearerr(f);
		errno = 0;
		saved = fflush(f) != 0 && errno ? errno : EIO;
	} else if (fflush(f) != 0)
		saved = errno ? errno : EIO;
	else if (fsync(fileno(f)) != 0 && errno != EINVAL && errno != EROFS && errno != ENOTSUP)
		saved = errno;
	if (close && fclose(f) != 0 && saved == 0)
		saved = errno ? errno : EIO;
	return saved;
}

int bsim_atomic_file_commit(bsim_atomic_file *o, bsim_error *err)
{
	if (o->mode == BSIM_ATOMIC_STDOUT || o->mode == BSIM_ATOMIC_THROUGH) {
		int saved = flush_close(o->f, o->mode == BSIM_ATOMIC_THROUGH);
		o->f = NULL;
		if (saved == 0)
			return BSIM_OK;
		return bsim_error_set(err, BSIM_EFAIL, "%s: write failed: %s",
		                      o->mode == BSIM_ATOMIC_STDOUT ? "standard output" : o->path,
		                      strerror(saved));
	}
	int saved = flush_close(o->f, 1);
	o->f = NULL;
	if (saved == 0 && rename(o->tmp, o->path) == 0)
		return BSIM_OK;
	if (saved == 0)
		saved = errno;
	unlink(o->tmp);
	return bsim_error_set(err, BSIM_EFAIL, "%s: write failed: %s", o->path, strerror(saved));
}

void bsim_atomic_file_abort(bsim_atomic_file *o)
{
	if (!o->f)
		return;
	if (o->mode == BSIM_ATOMIC_STDOUT) {
		fflush(stdout);
	} else {
		fclose(o->f);
		if (o->mode == BSIM_ATOMIC_RENAME)
			unlink(o->tmp);
	}
	o->f = NULL;
}

int bsim_atomic_file_copy(const char *from, const char *to, bsim_error *err)
{
	FILE *in = fopen(from, "rb");
	if (!in)
		return bsim_error_set(err, BSIM_EFAIL, "%s: cannot read the file: %s", from,
		                      strerror(errno));
	bsim_atomic_file o;
	if (bsim_atomic_file_open(&o, to, err) != BSIM_OK) {
		fclose(in);
		return BSIM_EFAIL;
	}
	char buf[8192];
	size_t n;
	while ((n = fread(buf, 1, sizeof buf, in)) > 0)
		fwrite(buf, 1, n, o.f);
	int bad = ferror(in);
	fclose(in);
	if (bad) {
		bsim_atomic_file_abort(&o);
		return bsim_error_set(err, BSIM_EFAIL, "%s: read error", from);
	}
	return bsim_atomic_file_commit(&o, err);
}
