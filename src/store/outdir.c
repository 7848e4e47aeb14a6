/* Output directories committed as a whole; see store/outdir.h.
 *
 * Layout while a run is under way:
 *   DIR/                  the previous run's files and manifest, untouched
 *   DIR/.beamsim/staging/ this run's files under their final names
 *   DIR/.beamsim/journal  finished trials, for --resume (util/journal.h)
 * The lock is an flock on DIR itself: it needs no file of its own and the
 * kernel drops it when the process dies, however it dies. */
#define _DEFAULT_SOURCE

#include "store/outdir.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <zlib.h>

#include "util/atomic_file.h"
#include "util/json.h"
#include "beamsim/version.h"
#include "util/yaml_doc.h"
#include "beamsim/limits.h"
#include "util/file_read.h"
#include "beamsim/output.h"

struct bsim_outdir {
	char dir[1024];
	char work[1040];
	char stage[1060];
	int lock_fd;
	int created;
	int committed;
};

typedef struct ofile {
	char *rel; /* path below DIR */
	long long bytes;
	unsigned long crc;
} ofile;

typedef struct olist {
	ofile *v;
	size_t n, cap;
} olist;

static void olist_free(olist *l)
{
	for (size_t i = 0; i < l->n; i++)
		free(l->v[i].rel);
	free(l->v);
	memset(l, 0, sizeof *l);
}

static int olist_add(olist *l, const char *rel, long long bytes, unsigned long crc)
{
	if (l->n == l->cap) {
		size_t cap = l->cap ? 2 * l->cap : 16;
		ofile *v = realloc(l->v, cap * sizeof *v);
		if (!v)
			return -1;
		l->v = v;
		l->cap = cap;
	}
	char *copy = malloc(strlen(rel) + 1);
	if (!copy)
		return -1;
	strcpy(copy, rel);
	l->v[l->n++] = (ofile){copy, bytes, crc};
	return 0;
}

static int olist_has(const olist *l, const char *rel)
{
	for (size_t i = 0; i < l->n; i++)
		if (strcmp(l->v[i].rel, rel) == 0)
			return 1;
	return 0;
}

static int by_rel(const void *a, const void *b)
{
	return strcmp(((const ofile *)a)->rel, ((const ofile *)b)->rel);
}

/* buf = a "/" b (b empty: a): 0, or ENAMETOOLONG if it does not fit. */
static int join(char *buf, size_t size, const char *a, const char *b)
{
	int n = snprintf(buf, size, "%s%s%s", a, b[0] ? "/" : "", b);
	return n < 0 || (size_t)n >= size ? ENAMETOOLONG : 0;
}

/* mkdir -p: 0 or the errno of the failure. */
static int mkdir_p(const char *dir)
{
	char path[BSIM_PATH_MAX];
	struct stat st;
	if (snprintf(path, sizeof path, "%s", dir) >= (int)sizeof path)
		return ENAMETOOLONG;
	for (char *p = path + 1; *p; p++) {
		if (*p != '/')
			continue;
		*p = '\0';
		if (mkdir(path, 0777) != 0 && errno != EEXIST)
			return errno;
		*p = '/';
	}
	if (mkdir(path, 0777) != 0 && errno != EEXIST)
		return errno;
	if (stat(path, &st) != 0)
		return errno;
	return S_ISDIR(st.st_mode) ? 0 : ENOTDIR;
}

/* rm -r of what beamsim made: files, links and directories, never
 * following a link. */
static void rm_tree(const char *path)
{
	struct stat st;
	if (lstat(path, &st) != 0)
		return;
	if (S_ISDIR(st.st_mode)) {
		DIR *d = opendir(path);
		struct dirent *e;
		while (d && (e = readdir(d))) {
			if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
				continue;
			char sub[BSIM_PATH_MAX];
			if (join(sub, sizeof sub, path, e->d_name) == 0)
				rm_tree(sub);
		}
		if (d)
			closedir(d);
		rmdir(path);
	} else {
		unlink(path);
	}
}

/* Size and CRC-32 of a file's content (following links, as a reader
 * does); with sync, also flushed to disk (the writer may not have). 0 or
 * an errno. */
static int crc_file(const char *path, int sync, long long *bytes, unsigned long *crc)
{
	int fd = open(path, O_RDONLY);
	if (fd < 0)
		return errno;
	unsigned char buf[65536];
	uLong c = crc32(0L, Z_NULL, 0);
	long long n = 0;
	ssize_t k;
	while ((k = read(fd, buf, sizeof buf)) > 0) {
		c = crc32(c, buf, (uInt)k);
		n += k;
	}
	int saved = k < 0 ? errno : 0;
	if (!saved && sync && fsync(fd) != 0 && errno != EINVAL)
		saved = errno;
	close(fd);
	*bytes = n;
	*crc = c;
	return saved;
}

/* Every file below root/rel, as paths relative to root. */
static int collect(const char *root, const char *rel, olist *l, char *bad, size_t bad_size)
{
	char path[BSIM_PATH_MAX];
	if (join(path, sizeof path, root, rel))
		return ENAMETOOLONG;
	DIR *d = opendir(path);
	if (!d) {
		snprintf(bad, bad_size, "%s", rel);
		return errno;
	}
	struct dirent *e;
	int rc = 0;
	while (!rc && (e = readdir(d))) {
		if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
			continue;
		char sub[BSIM_PATH_MAX], full[BSIM_PATH_MAX];
		struct stat st;
		if (rel[0] ? join(sub, sizeof sub, rel, e->d_name)
		           : join(sub, sizeof sub, e->d_name, "")) {
			rc = ENAMETOOLONG;
		} else if (join(full, sizeof full, root, sub)) {
			rc = ENAMETOOLONG;
		} else if (lstat(full, &st) != 0) {
			rc = errno;
		} else if (S_ISDIR(st.st_mode)) {
			rc = collect(root, sub, l, bad, bad_size);
			continue;
		} else {
			long long bytes = 0;
			unsigned long crc = 0;
			rc = crc_file(full, 1, &bytes, &crc);
			if (!rc && olist_add(l, sub, bytes, crc) != 0)
				rc = ENOMEM;
		}
		if (rc)
			snprintf(bad, bad_size, "%.*s", (int)bad_size - 1,
			         rc == ENAMETOOLONG ? e->d_name : sub);
	}
	closedir(d);
	return rc;
}

static int manifest_read(const char *dir, olist *l, int *has, char *command, size_t command_size,
                         bsim_error *err);

static int input_error(bsim_error *err, const char *dir, int e)
{
	return bsim_error_set(err, BSIM_EINPUT, "%s: cannot write to the output directory: %s", dir,
	                      strerror(e));
}

/* The owner file: "pid N\ncommand C\n", written by the run that holds the
 * lock, read (never written) by a run refused, to say who is there. */
#define OWNER_FILE "owner"

static void owner_write(const bsim_outdir *od, const char *command)
{
	char path[BSIM_PATH_MAX];
	if (join(path, sizeof path, od->work, OWNER_FILE))
		return;
	FILE *f = fopen(path, "w");
	if (!f)
		return;
	fprintf(f, "pid %ld\ncommand %s\n", (long)getpid(), command ? command : "");
	fclose(f); /* a hint for messages: its failure fails nothing */
}

/* " (beamsim sweep, process 1234)" from DIR/.beamsim/owner, or "". */
static void owner_read(const char *work, char *buf, size_t size)
{
	char path[BSIM_PATH_MAX], text[256];
	buf[0] = '\0';
	struct stat st;
	int fd = join(path, sizeof path, work, OWNER_FILE) ? -1 : bsim_file_open_checked(path, &st);
	if (fd < 0)
		return;
	ssize_t n = S_ISREG(st.st_mode) ? read(fd, text, sizeof text - 1) : -1;
	close(fd);
	if (n <= 0)
		return;
	text[n] = '\0';
	long pid = 0;
	char command[64] = "";
	if (sscanf(text, "pid %ld command %63[a-z ]", &pid, command) < 1 || pid <= 0)
		return;
	size_t len = strlen(command);
	while (len > 0 && command[len - 1] == ' ')
		command[--len] = '\0';
	snprintf(buf, size, " (beamsim%s%s, process %ld)", len ? " " : "", command, pid);
}

/* The refusal of a DIR another run holds; who from owner_read. */
static int refuse_running(const char *dir, const char *who, bsim_error *err)
{
	return bsim_error_set(err, BSIM_EINPUT,
	                      "%s: another beamsim run%s is writing this directory: wait for it "
	                      "to end, or choose another output directory",
	                      dir, who);
}

/* The result DIR holds, for the refusal of a run that would replace it
 * (mode NEW): a finished one (a manifest) or a stopped one (a journal). */
static int refuse_held(const bsim_outdir *od, const char *dir, const bsim_outdir_spelling *sp,
                       bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	struct stat st;
	if (join(path, sizeof path, od->work, "journal") == 0 && lstat(path, &st) == 0)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s holds the journal of a stopped run (%s): that run's "
		                      "command with %s continues it, %s discards it and starts "
		                      "over",
		                      dir, path, bsim_outdir_resume_option(sp),
		                      bsim_outdir_overwrite_option(sp));
	olist l = {0};
	int has = 0;
	bsim_error ignored;
	char command[64] = "";
	if (join(path, sizeof path, od->dir, BSIM_OUTDIR_MANIFEST) || lstat(path, &st) != 0)
		return BSIM_OK;
	char what[128];
	if (manifest_read(od->dir, &l, &has, command, sizeof command, &ignored) == BSIM_OK &&
	    command[0])
		snprintf(what, sizeof what, "the finished result of beamsim %s (%zu files in %s)",
		         command, l.n, BSIM_OUTDIR_MANIFEST);
	else
		snprintf(what, sizeof what, "a finished result (%s)", BSIM_OUTDIR_MANIFEST);
	olist_free(&l);
	return bsim_error_set(err, BSIM_EINPUT,
	                      "%s holds %s: add %s to replace it, or choose another output "
	                      "directory",
	                      dir, what, bsim_outdir_overwrite_option(sp));
}

/* lock_take's answer for a DIR that is there and not a directory. */
#define NOT_A_DIRECTORY (-1)

/* Takes DIR's lock: 0, NOT_A_DIRECTORY, or an errno (EWOULDBLOCK: another
 * run holds it).
 * The descriptor must be DIR's as named now: a run that ends removes the
 * directory it created if it left it empty, and the lock on a directory
 * removed is no lock, so the name is looked up again once the lock is
 * held. */
static int lock_take(bsim_outdir *od)
{
	for (int attempt = 0; attempt < 8; attempt++) {
		struct stat held, named;
		int rc = 0;
		if (stat(od->dir, &named) != 0) {
			od->created = 1;
			rc = mkdir_p(od->dir);
		} else if (!S_ISDIR(named.st_mode)) {
			return NOT_A_DIRECTORY;
		}
		if (rc)
			return rc;
		od->lock_fd = open(od->dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
		if (od->lock_fd < 0)
			return errno;
		if (flock(od->lock_fd, LOCK_EX | LOCK_NB) != 0) {
			rc = errno;
			close(od->lock_fd);
			od->lock_fd = -1;
			return rc;
		}
		if (fstat(od->lock_fd, &held) == 0 && stat(od->dir, &named) == 0 &&
		    held.st_dev == named.st_dev && held.st_ino == named.st_ino)
			return 0;
		close(od->lock_fd); /* removed or replaced while we waited: again */
		od->lock_fd = -1;
	}
	return EAGAIN;
}

int bsim_outdir_open(bsim_outdir **out, const char *dir, bsim_outdir_mode mode, const char *command,
                     const bsim_outdir_spelling *spelling, bsim_error *err)
{
	*out = NULL;
	bsim_outdir *od = calloc(1, sizeof *od);
	if (!od)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	od->lock_fd = -1;
	size_t len = strlen(dir);
	while (len > 1 && dir[len - 1] == '/')
		len--;
	if (len == 0 || len >= sizeof od->dir - 40) {
		free(od);
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%.200s: expected a directory name of 1 to %zu "
		                      "characters",
		                      dir, sizeof od->dir - 41);
	}
	memcpy(od->dir, dir, len);
	join(od->work, sizeof od->work, od->dir, ".beamsim");
	join(od->stage, sizeof od->stage, od->work, "staging");

	/* Until the lock is held nothing in DIR is ours: a run refused here
	 * leaves it exactly as it found it, the other run's staging area,
	 * journal and the directory itself included. */
	int rc = lock_take(od);
	if (rc) {
		char who[128];
		owner_read(od->work, who, sizeof who);
		free(od);
		if (rc == NOT_A_DIRECTORY)
			return bsim_error_set(err, BSIM_EINPUT,
			                      "%s: expected an output directory, got a file", dir);
		if (rc == EWOULDBLOCK)
			return refuse_running(dir, who, err);
		return input_error(err, dir, rc);
	}
	if (mode == BSIM_OUTDIR_NEW && (rc = refuse_held(od, dir, spelling, err)) != BSIM_OK) {
		close(od->lock_fd);
		free(od);
		return rc;
	}
	/* Creating the work area and the staging area is the test that DIR
	 * can be written (access() says yes to root on a read-only disk). A
	 * staging area left by a run that was killed is stale: the lock says
	 * no run owns it. */
	if (mkdir(od->work, 0777) != 0 && errno != EEXIST)
		rc = errno;
	if (!rc) {
		rm_tree(od->stage);
		if (mkdir(od->stage, 0777) != 0)
			rc = errno;
	}
	if (rc) {
		bsim_outdir_close(od);
		return input_error(err, dir, rc);
	}
	owner_write(od, command);
	*out = od;
	return BSIM_OK;
}

int bsim_outdir_probe(const char *dir, bsim_outdir_mode mode, const bsim_outdir_spelling *spelling,
                      bsim_error *err)
{
	bsim_outdir probe = {.lock_fd = -1};
	struct stat st;
	if (stat(dir, &st) != 0)
		return BSIM_OK; /* created by the open */
	if (!S_ISDIR(st.st_mode))
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: expected an output directory, got a file", dir);
	if (join(probe.dir, sizeof probe.dir, dir, "") ||
	    join(probe.work, sizeof probe.work, dir, ".beamsim"))
		return bsim_error_set(err, BSIM_EINPUT, "%.200s: path too long", dir);
	int fd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
	if (fd < 0)
		return input_error(err, dir, errno);
	/* shared: probes of one job's processes do not refuse each other */
	int rc = BSIM_OK;
	if (flock(fd, LOCK_SH | LOCK_NB) != 0) {
		char who[128];
		owner_read(probe.work, who, sizeof who);
		rc = errno == EWOULDBLOCK ? refuse_running(dir, who, err)
		                          : input_error(err, dir, errno);
	} else if (mode == BSIM_OUTDIR_NEW) {
		rc = refuse_held(&probe, dir, spelling, err);
	}
	close(fd);
	return rc;
}

int bsim_output_dir_check(const char *dir, int overwrite, const char *overwrite_option,
                          bsim_error *err)
{
	const bsim_outdir_spelling sp = {NULL, overwrite_option};
	return bsim_outdir_probe(dir, overwrite ? BSIM_OUTDIR_OVERWRITE : BSIM_OUTDIR_NEW, &sp,
	                         err);
}

const char *bsim_outdir_dir(const bsim_outdir *od)
{
	return od->dir;
}

const char *bsim_outdir_stage(const bsim_outdir *od)
{
	return od->stage;
}

const char *bsim_outdir_work(const bsim_outdir *od)
{
	return od->work;
}

void bsim_outdir_explain(const bsim_outdir *od, char *text, size_t size)
{
	if (!od)
		return;
	size_t ls = strlen(od->stage), ld = strlen(od->dir);
	char *at;
	while ((at = strstr(text, od->stage)) != NULL) {
		memmove(at + ld, at + ls, strlen(at + ls) + 1);
		memcpy(at, od->dir, ld);
	}
	(void)size; /* the directory's name is shorter than the staging area's */
}

/* Puts the staged file at its place: a rename, or written through when the
 * place holds a symlink, FIFO or device (util/atomic_file.h). */
static int put(const char *staged, const char *final)
{
	if (!bsim_atomic_file_is_through(final))
		return rename(staged, final) == 0 ? 0 : errno;
	FILE *in = fopen(staged, "rb"), *out = in ? fopen(final, "w") : NULL;
	int saved = in && out ? 0 : errno;
	char buf[65536];
	size_t k;
	while (!saved && (k = fread(buf, 1, sizeof buf, in)) > 0)
		if (fwrite(buf, 1, k, out) != k)
			saved = errno ? errno : EIO;
	if (!saved && in && ferror(in))
		saved = EIO;
	if (out && fflush(out) != 0 && !saved)
		saved = errno;
	if (out && fsync(fileno(out)) != 0 && errno != EINVAL && errno != EROFS && !saved)
		saved = errno;
	if (out && fclose(out) != 0 && !saved)
		saved = errno;
	if (in)
		fclose(in);
	if (!saved)
		unlink(staged);
	return saved;
}

static void fsync_dir(const char *dir)
{
	int fd = open(dir, O_RDONLY | O_DIRECTORY);
	if (fd >= 0) {
		fsync(fd);
		close(fd);
	}
}

/* The files a manifest lists (none if there is no manifest) and, if
 * command is not NULL, the command that wrote it ("" if unknown). */
static int manifest_read(const char *dir, olist *l, int *has, char *command, size_t command_size,
                         bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	struct stat st;
	*has = 0;
	if (join(path, sizeof path, dir, BSIM_OUTDIR_MANIFEST) || stat(path, &st) != 0)
		return BSIM_OK;
	ydoc d;
	if (bsim_ydoc_load_own(&d, path, err) != BSIM_OK)
		return BSIM_EINPUT;
	*has = 1;
	struct fy_node *files = bsim_ydoc_lookup(fy_document_root(d.fyd), "files");
	struct fy_node *format = bsim_ydoc_lookup(fy_document_root(d.fyd), "format");
	const char *ft = format && fy_node_is_scalar(format) ? fy_node_get_scalar0(format) : NULL;
	struct fy_node *cmd = bsim_ydoc_lookup(fy_document_root(d.fyd), "command");
	if (command)
		snprintf(command, command_size, "%s",
		         cmd && fy_node_is_scalar(cmd) ? fy_node_get_scalar0(cmd) : "");
	int rc = BSIM_OK;
	/* The one format there has been; a manifest of a later one is not
	 * read as if it were this. */
	if (format && (!ft || strcmp(ft, "beamsim-manifest-1") != 0))
		rc = bsim_ydoc_expected(&d, format, NULL, "format",
		                        "\"beamsim-manifest-1\" (a manifest this beamsim reads)",
		                        err);
	if (!rc && (!files || !fy_node_is_sequence(files)))
		rc = bsim_ydoc_expected(&d, files, NULL, "files", "a list of files", err);
	int n = rc ? 0 : fy_node_sequence_item_count(files);
	for (int i = 0; !rc && i < n; i++) {
		struct fy_node *f = fy_node_sequence_get_by_index(files, i);
		struct fy_node *pn = bsim_ydoc_lookup(f, "path"),
		               *cn = bsim_ydoc_lookup(f, "crc32");
		const char *rel = pn && fy_node_is_scalar(pn) ? fy_node_get_scalar0(pn) : NULL;
		const char *crc = cn && fy_node_is_scalar(cn) ? fy_node_get_scalar0(cn) : NULL;
		long long bytes = -1;
		char *end = NULL;
		unsigned long c = crc ? strtoul(crc, &end, 16) : 0;
		if (!rel || !*rel || strstr(rel, "..") || rel[0] == '/' ||
		    !bsim_ydoc_int64(bsim_ydoc_lookup(f, "bytes"), &bytes) || bytes < 0 || !crc ||
		    *end || strlen(crc) != 8)
			rc = bsim_ydoc_expected(&d, f, files, "files",
			                        "{path, bytes, crc32} of a file", err);
		else if (olist_add(l, rel, bytes, c) != 0)
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	bsim_ydoc_free(&d);
	return rc;
}

int bsim_outdir_files(const char *dir, char ***paths, size_t *n, bsim_error *err)
{
	olist l = {0};
	int has;
	*paths = NULL;
	*n = 0;
	int rc = manifest_read(dir, &l, &has, NULL, 0, err);
	if (rc == BSIM_OK && l.n > 0) {
		*paths = malloc(l.n * sizeof **paths);
		if (!*paths) {
			olist_free(&l);
			return bsim_error_set(err, BSIM_EFAIL, "out of memory");
		}
		for (size_t i = 0; i < l.n; i++)
			(*paths)[i] = l.v[i].rel; /* handed over */
		*n = l.n;
		free(l.v);
		return BSIM_OK;
	}
	olist_free(&l);
	return rc;
}

void bsim_outdir_files_free(char **paths, size_t n)
{
	for (size_t i = 0; paths && i < n; i++)
		free(paths[i]);
	free(paths);
}

static int manifest_write(const char *dir, const char *command, const olist *l, bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	if (join(path, sizeof path, dir, BSIM_OUTDIR_MANIFEST))
		return bsim_error_set(err, BSIM_EFAIL, "%s: path too long", dir);
	bsim_atomic_file o;
	if (bsim_atomic_file_open(&o, path, err) != BSIM_OK)
		return BSIM_EFAIL;
	fputs("{\n  \"format\": \"beamsim-manifest-1\",\n  \"command\": ", o.f);
	bsim_json_string(o.f, command);
	fputs(",\n  \"beamsim_version\": ", o.f);
	bsim_json_string(o.f, BSIM_VERSION);
	fputs(",\n  \"files\": [", o.f);
	for (size_t i = 0; i < l->n; i++) {
		fputs(i ? ",\n    {\"path\": " : "\n    {\"path\": ", o.f);
		bsim_json_string(o.f, l->v[i].rel);
		fprintf(o.f, ", \"bytes\": %lld, \"crc32\": \"%08lx\"}", l->v[i].bytes,
		        l->v[i].crc);
	}
	fputs("\n  ]\n}\n", o.f);
	return bsim_atomic_file_commit(&o, err);
}

static int commit_fail(bsim_error *err, const char *dir, const char *rel, int e)
{
	return bsim_error_set(err, BSIM_EFAIL, "%s/%s: write failed: %s", dir, rel, strerror(e));
}

static int commit_set(bsim_outdir *od, const char *command, int add, bsim_error *err)
{
	olist now = {0}, before = {0};
	char bad[BSIM_PATH_MAX] = "";
	int has = 0, rc = BSIM_OK;
	int e = collect(od->stage, "", &now, bad, sizeof bad);
	if (e) {
		olist_free(&now);
		return commit_fail(err, od->dir, bad, e);
	}
	qsort(now.v, now.n, sizeof *now.v, by_rel);
	/* A damaged old manifest lists nothing to remove: only what a
	 * manifest names is ever deleted. */
	bsim_error ignored;
	char was[64] = "";
	if (manifest_read(od->dir, &before, &has, was, sizeof was, &ignored) != BSIM_OK)
		olist_free(&before);
	/* Files added to a result (plot's figures) leave it the result of the
	 * command that made it. */
	if (add && was[0])
		command = was;
	char path[BSIM_PATH_MAX], staged[BSIM_PATH_MAX];
	if (join(path, sizeof path, od->dir, BSIM_OUTDIR_MANIFEST) == 0 && unlink(path) == 0)
		fsync_dir(od->dir);
	for (size_t i = 0; !rc && i < now.n; i++) {
		const char *rel = now.v[i].rel;
		e = join(path, sizeof path, od->dir, rel);
		if (!e)
			e = join(staged, sizeof staged, od->stage, rel);
		char *slash = strrchr(path, '/');
		if (!e) {
			*slash = '\0';
			e = mkdir_p(path);
			*slash = '/';
		}
		if (!e)
			e = put(staged, path);
		if (e)
			rc = commit_fail(err, od->dir, rel, e);
		else if (strchr(rel, '/')) {
			*slash = '\0';
			fsync_dir(path);
		}
	}
	/* Added files join the set: the previous ones stay, and stay listed. */
	for (size_t i = 0; add && !rc && i < before.n; i++)
		if (!olist_has(&now, before.v[i].rel) &&
		    olist_add(&now, before.v[i].rel, before.v[i].bytes, before.v[i].crc) != 0)
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	if (add)
		qsort(now.v, now.n, sizeof *now.v, by_rel);
	for (size_t i = 0; !add && !rc && i < before.n; i++) {
		struct stat st;
		if (!olist_has(&now, before.v[i].rel) &&
		    !join(path, sizeof path, od->dir, before.v[i].rel) && lstat(path, &st) == 0 &&
		    S_ISREG(st.st_mode))
			unlink(path);
	}
	if (!rc) {
		fsync_dir(od->dir);
		rc = manifest_write(od->dir, command, &now, err);
	}
	if (!rc) {
		rm_tree(od->stage);
		od->committed = 1;
	}
	olist_free(&now);
	olist_free(&before);
	return rc;
}

int bsim_outdir_commit(bsim_outdir *od, const char *command, bsim_error *err)
{
	return commit_set(od, command, 0, err);
}

int bsim_outdir_add(bsim_outdir *od, const char *command, bsim_error *err)
{
	return commit_set(od, command, 1, err);
}

void bsim_outdir_close(bsim_outdir *od)
{
	if (!od)
		return;
	char owner[BSIM_PATH_MAX];
	rm_tree(od->stage);
	if (join(owner, sizeof owner, od->work, OWNER_FILE) == 0)
		unlink(owner);
	rmdir(od->work); /* kept while a journal is in it */
	if (od->created && !od->committed)
		rmdir(od->dir);
	if (od->lock_fd >= 0)
		close(od->lock_fd);
	free(od);
}

/* One listed file checked against its entry: opened without blocking (a
 * FIFO put in its place must not stop the reader), refused unless it is a
 * regular file of the listed size, then read to at most one byte past
 * that size (a file that grows is not followed) for its CRC-32. */
static int verify_one(const char *dir, const char *path, const ofile *want, bsim_error *err)
{
	struct stat st;
	int fd = bsim_file_open_checked(path, &st);
	if (fd < 0)
		return bsim_error_set(err, BSIM_EINPUT, "%s: listed in %s/%s but unreadable: %s",
		                      path, dir, BSIM_OUTDIR_MANIFEST, strerror(errno));
	if (!S_ISREG(st.st_mode)) {
		close(fd);
		return bsim_error_set(
		        err, BSIM_EINPUT, "%s: expected the file %s/%s lists (%lld bytes), got %s",
		        path, dir, BSIM_OUTDIR_MANIFEST, want->bytes, bsim_file_kind(&st));
	}
	unsigned char buf[65536];
	uLong c = crc32(0L, Z_NULL, 0);
	long long n = 0;
	ssize_t k = 0;
	while (n <= want->bytes && (k = read(fd, buf, sizeof buf)) != 0) {
		if (k < 0 && errno == EINTR)
			continue;
		if (k < 0)
			break;
		c = crc32(c, buf, (uInt)k);
		n += k;
	}
	int e = k < 0 ? errno : 0;
	close(fd);
	if (e)
		return bsim_error_set(err, BSIM_EINPUT, "%s: listed in %s/%s but unreadable: %s",
		                      path, dir, BSIM_OUTDIR_MANIFEST, strerror(e));
	/* A file longer than listed is read only one block past its size:
	 * its size is fstat's, its CRC-32 not computed. */
	if (n > want->bytes)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: expected the file %s/%s lists (%lld bytes, CRC-32 "
		                      "%08lx), got %lld bytes: the directory mixes files of two "
		                      "runs, or the file was changed",
		                      path, dir, BSIM_OUTDIR_MANIFEST, want->bytes, want->crc,
		                      (long long)st.st_size);
	if (n != want->bytes || c != want->crc)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: expected the file %s/%s lists (%lld bytes, CRC-32 "
		                      "%08lx), got %lld bytes, CRC-32 %08lx: the directory "
		                      "mixes files of two runs, or the file was changed",
		                      path, dir, BSIM_OUTDIR_MANIFEST, want->bytes, want->crc, n,
		                      c);
	return BSIM_OK;
}

int bsim_outdir_verify(const char *dir, int *has_manifest, bsim_error *err)
{
	olist l = {0};
	int rc = manifest_read(dir, &l, has_manifest, NULL, 0, err);
	for (size_t i = 0; !rc && i < l.n; i++) {
		char path[BSIM_PATH_MAX];
		if (join(path, sizeof path, dir, l.v[i].rel))
			rc = bsim_error_set(err, BSIM_EINPUT, "%s/%s: path too long", dir,
			                    l.v[i].rel);
		else
			rc = verify_one(dir, path, &l.v[i], err);
	}
	olist_free(&l);
	return rc;
}
