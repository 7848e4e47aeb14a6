/* The encoder pipe: ffmpeg (Debian ffmpeg) reads raw frames from a pipe on
 * its standard input and writes an MP4 file.
 *
 *   ffmpeg -hide_banner -loglevel error -f rawvideo -pix_fmt bgr0 -video_size WxH
 *          -framerate FPS -i pipe:0 -an -c:v libx264 -preset medium -crf CRF
 *          -pix_fmt yuv420p -movflags +faststart -f mp4 -y file:PATH.tmp.PID
 *
 * A frame is width x height 32-bit values 0x00RRGGBB (cairo's RGB24) in
 * native byte order: B, G, R, 0 in memory on a little-endian machine
 * (ffmpeg's bgr0), 0, R, G, B on a big-endian one (0rgb). yuv420p is the
 * chroma layout every H.264 player decodes.
 *
 * ffmpeg is started with posix_spawnp (no shell, so no quoting of the
 * path), its standard error goes to an unnamed temporary file whose first
 * line is quoted if it fails. The output is the temporary file of a
 * bsim_atomic_file: ffmpeg truncates and fills that same file, and commit
 * syncs it and renames it into place only if ffmpeg exited with status 0,
 * wrote no error (at -loglevel error it writes nothing else) and the file
 * is a whole MP4 (video_mp4.c); else the temporary file is removed.
 * SIGPIPE (ffmpeg gone while frames are written) is blocked in the writing
 * thread only for the write, and a pending one it raised is taken back, so
 * the library leaves the process's signal handling as it found it. */
#define _POSIX_C_SOURCE 200809L

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "util/atomic_file.h"
#include "util/program_log.h"
#include "beamsim/video.h"
#include "video/video_internal.h"
#include "beamsim/limits.h"

extern char **environ;

struct bsim_video_encoder {
	bsim_atomic_file out; /* ffmpeg writes out.tmp; renamed on success */
	char path[BSIM_PATH_MAX];
	char program[256];
	pid_t pid; /* 0 once reaped */
	int status;
	int fd;    /* the pipe's write end, -1 once closed */
	FILE *log; /* ffmpeg's standard error */
	size_t frame_bytes;
};

static const char *raw_pixel_format(void)
{
	const uint32_t probe = 0x00010203;
	unsigned char first;
	memcpy(&first, &probe, 1);
	return first == 0x03 ? "bgr0" : "0rgb";
}

/* Removes the temporary files PATH.tmp.PID that processes no longer alive
 * left beside path (a run killed while ffmpeg wrote): a PID that is alive
 * may be another run writing the same file, and is left alone. */
static void remove_stale(const char *path)
{
	char dir[BSIM_PATH_MAX];
	const char *slash = strrchr(path, '/');
	const char *base = slash ? slash + 1 : path;
	if (slash)
		snprintf(dir, sizeof dir, "%.*s", (int)(slash - path + (slash == path)), path);
	else
		snprintf(dir, sizeof dir, ".");
	size_t blen = strlen(base);
	DIR *d = opendir(dir);
	struct dirent *de;
	while (d && (de = readdir(d))) {
		const char *n = de->d_name;
		if (strncmp(n, base, blen) != 0 || strncmp(n + blen, ".tmp.", 5) != 0)
			continue;
		const char *digits = n + blen + 5;
		char *end;
		errno = 0;
		long pid = strtol(digits, &end, 10);
		if (*digits < '1' || *digits > '9' || *end || errno || pid > INT_MAX ||
		    pid == (long)getpid())
			continue;
		if (kill((pid_t)pid, 0) == 0 || errno != ESRCH)
			continue;
		char stale[BSIM_PATH_MAX];
		struct stat st;
		if (snprintf(stale, sizeof stale, "%s/%s", dir, n) < (int)sizeof stale &&
		    lstat(stale, &st) == 0 && S_ISREG(st.st_mode))
			unlink(stale);
	}
	if (d)
		closedir(d);
}

/* "exited with status 1: <its first line>" or "was killed by signal 9". */
static void describe_status(bsim_video_encoder *e, char *buf, size_t n)
{
	char last[320];
	bsim_program_log_line(e->log, 0, last, sizeof last);
	int k;
	if (WIFEXITED(e->status))
		k = snprintf(buf, n, "%s exited with status %d", e->program,
		             WEXITSTATUS(e->status));
	else if (WIFSIGNALED(e->status))
		k = snprintf(buf, n, "%s was killed by signal %d", e->program, WTERMSIG(e->status));
	else
		k = snprintf(buf, n, "%s ended abnormally", e->program);
	if (last[0] && k > 0 && (size_t)k < n)
		snprintf(buf + k, n - (size_t)k, ": %s", last);
}

static void reap(bsim_video_encoder *e)
{
	if (e->fd >= 0) {
		close(e->fd);
		e->fd = -1;
	}
	if (e->pid <= 0)
		return;
	while (waitpid(e->pid, &e->status, 0) < 0)
		if (errno != EINTR) {
			e->status = -1;
			break;
		}
	e->pid = 0;
}

static void encoder_free(bsim_video_encoder *e)
{
	if (e->log)
		fclose(e->log);
	free(e);
}

static int set_cloexec(int fd)
{
	int flags = fcntl(fd, F_GETFD);
	return flags < 0 ? -1 : fcntl(fd, F_SETFD, flags | FD_CLOEXEC);
}

/* Starts the program with the pipe's read end as its standard input. */
static int spawn(bsim_video_encoder *e, int width, int height, double fps, int crf, int read_fd,
                 bsim_error *err)
{
	char size[48], rate[48], quality[16], output[BSIM_PATH_MAX + 8];
	snprintf(size, sizeof size, "%dx%d", width, height);
	snprintf(rate, sizeof rate, "%.10g", fps);
	snprintf(quality, sizeof quality, "%d", crf);
	/* file: keeps a path with a colon from being read as a protocol. What
	 * is not a regular file (util/atomic_file.h) is written in place:
	 * standard output as ffmpeg's own, a pipe or device by its path; those
	 * cannot seek back to put the index first, so the MP4 is fragmented. */
	struct stat st;
	int seekable = e->out.mode == BSIM_ATOMIC_RENAME ||
	               (e->out.mode == BSIM_ATOMIC_THROUGH && stat(e->path, &st) == 0 &&
	                S_ISREG(st.st_mode));
	if (e->out.mode == BSIM_ATOMIC_STDOUT)
		snprintf(output, sizeof output, "pipe:1");
	else
		snprintf(output, sizeof output, "file:%s",
		         e->out.mode == BSIM_ATOMIC_RENAME ? e->out.tmp : e->path);
	char *argv[] = {
	        e->program,
	        "-hide_banner",
	        "-nostats",
	        "-loglevel",
	        "error",
	        "-f",
	        "rawvideo",
	        "-pix_fmt",
	        (char *)raw_pixel_format(),
	        "-video_size",
	        size,
	        "-framerate",
	        rate,
	        "-i",
	        "pipe:0",
	        "-an",
	        "-c:v",
	        "libx264",
	        "-preset",
	        "medium",
	        "-crf",
	        quality,
	        "-pix_fmt",
	        "yuv420p",
	        "-movflags",
	        seekable ? "+faststart" : "frag_keyframe+empty_moov",
	        "-f",
	        "mp4",
	        "-y",
	        output,
	        NULL,
	};
	posix_spawn_file_actions_t fa;
	if (posix_spawn_file_actions_init(&fa) != 0)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory starting %s", e->program);
	int rc = posix_spawn_file_actions_adddup2(&fa, read_fd, STDIN_FILENO);
	if (rc == 0 && e->out.mode != BSIM_ATOMIC_STDOUT)
		rc = posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
	if (rc == 0)
		rc = posix_spawn_file_actions_adddup2(&fa, fileno(e->log), STDERR_FILENO);
	if (rc == 0)
		rc = posix_spawnp(&e->pid, e->program, &fa, NULL, argv, environ);
	posix_spawn_file_actions_destroy(&fa);
	if (rc == ENOENT && strcmp(e->program, "ffmpeg") == 0)
		return bsim_error_set(err, BSIM_EFAIL,
		                      "ffmpeg not found on PATH: videos are encoded by ffmpeg; "
		                      "install the Debian package ffmpeg (scripts/deps.sh does)");
	if (rc == ENOENT)
		return bsim_error_set(err, BSIM_EFAIL, "%s not found on PATH", e->program);
	if (rc != 0)
		return bsim_error_set(err, BSIM_EFAIL, "cannot start %s: %s", e->program,
		                      strerror(rc));
	return BSIM_OK;
}

int bsim_video_encoder_open(const char *path, const char *program, int width, int height,
                            double fps, int crf, bsim_video_encoder **out, bsim_error *err)
{
	*out = NULL;
	if (!program || !*program)
		program = "ffmpeg";
	bsim_video_encoder *e = calloc(1, sizeof *e);
	if (!e)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory for a video encoder");
	e->fd = -1;
	e->frame_bytes = (size_t)width * (size_t)height * 4;
	if (strlen(path) >= sizeof e->path || strlen(program) >= sizeof e->program) {
		free(e);
		return bsim_error_set(err, BSIM_EFAIL, "%.200s: path too long", path);
	}
	snprintf(e->path, sizeof e->path, "%s", path);
	snprintf(e->program, sizeof e->program, "%s", program);
	remove_stale(e->path);
	int rc = bsim_atomic_file_open(&e->out, e->path, err);
	if (rc != BSIM_OK) {
		free(e);
		return rc;
	}
	e->log = bsim_program_log_open();
	int fds[2] = {-1, -1};
	if (!e->log || pipe(fds) != 0 || set_cloexec(fds[0]) || set_cloexec(fds[1])) {
		rc = bsim_error_set(err, BSIM_EFAIL, "cannot make a pipe to %s: %s", e->program,
		                    strerror(errno));
	} else {
		rc = spawn(e, width, height, fps, crf, fds[0], err);
	}
	if (fds[0] >= 0)
		close(fds[0]);
	if (rc != BSIM_OK) {
		if (fds[1] >= 0)
			close(fds[1]);
		bsim_atomic_file_abort(&e->out);
		encoder_free(e);
		return rc;
	}
	e->fd = fds[1];
	*out = e;
	return BSIM_OK;
}

/* write(2) of all n bytes with SIGPIPE blocked: 0, or the errno. */
static int write_all(int fd, const unsigned char *p, size_t n)
{
	sigset_t pipe_set, old, pending;
	sigemptyset(&pipe_set);
	sigaddset(&pipe_set, SIGPIPE);
	pthread_sigmask(SIG_BLOCK, &pipe_set, &old);
	sigpending(&pending);
	int was_pending = sigismember(&pending, SIGPIPE);
	int saved = 0;
	while (n > 0) {
		ssize_t k = write(fd, p, n);
		if (k < 0 && errno == EINTR)
			continue;
		if (k < 0) {
			saved = errno;
			break;
		}
		p += k;
		n -= (size_t)k;
	}
	if (saved == EPIPE && !was_pending) {
		const struct timespec zero = {0, 0};
		while (sigtimedwait(&pipe_set, NULL, &zero) < 0 && errno == EINTR)
			;
	}
	pthread_sigmask(SIG_SETMASK, &old, NULL);
	return saved;
}

int bsim_video_encoder_write(bsim_video_encoder *e, const uint32_t *pixels, bsim_error *err)
{
	if (e->fd < 0)
		return bsim_error_set(err, BSIM_EFAIL, "%s: the encoder is closed", e->path);
	int saved = write_all(e->fd, (const unsigned char *)pixels, e->frame_bytes);
	if (saved == 0)
		return BSIM_OK;
	char why[512];
	reap(e);
	if (saved == EPIPE) {
		describe_status(e, why, sizeof why);
		return bsim_error_set(err, BSIM_EFAIL, "%s: %s before reading every frame", e->path,
		                      why);
	}
	return bsim_error_set(err, BSIM_EFAIL, "%s: writing a frame to %s: %s", e->path, e->program,
	                      strerror(saved));
}

/* Why the video ffmpeg ended is not whole (of size n, empty if it is):
 * its exit status; a message at -loglevel error, which is an error
 * although the status is 0 (ffmpeg 5.1 exits with 0 after "Error writing
 * trailer": the index of the MP4 is missing); and, for a regular file, the
 * file itself (bsim_video_mp4_whole). */
static void encoder_verdict(bsim_video_encoder *e, char *why, size_t n)
{
	char first[320];
	struct stat st;
	why[0] = '\0';
	/* At -loglevel error ffmpeg writes errors alone, the first the cause
	 * ("Error writing trailer of ...: No space left on device"), those
	 * after it what followed ("Error closing file ..."). */
	bsim_program_log_line(e->log, 0, first, sizeof first);
	if (e->status != 0) {
		describe_status(e, why, n);
		return;
	}
	if (first[0]) {
		snprintf(why, n, "%s exited with status 0 after an error: %s", e->program, first);
		return;
	}
	const char *file = e->out.mode == BSIM_ATOMIC_RENAME ? e->out.tmp : e->path;
	char cut[400];
	if (e->out.mode != BSIM_ATOMIC_STDOUT && stat(file, &st) == 0 && S_ISREG(st.st_mode) &&
	    bsim_video_mp4_whole(file, cut, sizeof cut) != 0)
		snprintf(why, n, "%s exited with status 0 but the MP4 is not whole: %s", e->program,
		         cut);
}

int bsim_video_encoder_close(bsim_video_encoder *e, bsim_error *err)
{
	reap(e);
	int rc;
	char why[768];
	encoder_verdict(e, why, sizeof why);
	if (!why[0]) {
		rc = bsim_atomic_file_commit(&e->out, err);
	} else {
		/* Its temporary file is removed: nothing that looks like a
		 * finished video is left at the path. */
		int removed = e->out.mode == BSIM_ATOMIC_RENAME;
		bsim_atomic_file_abort(&e->out);
		rc = bsim_error_set(err, BSIM_EFAIL, "%s: encoding the video: %s%s", e->path, why,
		                    removed ? "; no video written" : "");
	}
	encoder_free(e);
	return rc;
}

void bsim_video_encoder_abort(bsim_video_encoder *e)
{
	if (!e)
		return;
	if (e->fd >= 0) {
		close(e->fd);
		e->fd = -1;
	}
	if (e->pid > 0)
		kill(e->pid, SIGTERM);
	reap(e);
	bsim_atomic_file_abort(&e->out);
	encoder_free(e);
}
