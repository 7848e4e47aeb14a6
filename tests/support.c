/* Helpers shared by the tests (support.h): one way to run the program and
 * wait on what it does, temporary directories and files. */
#define _XOPEN_SOURCE 700 /* posix_openpt */

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "support.h"

#include "beamsim/backend_plugin.h"
#include "beamsim/backend_registry.h"
#include "beamsim/schedule.h"
#include "beamsim/trial.h"

#include "util/figure.h"
#include "store/outdir.h"
#include "util/yaml_doc.h"

#include <cairo.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <glob.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

static char *slurp_fd(int fd)
{
	size_t cap = 4096, len = 0;
	char *buf = malloc(cap);
	if (!buf)
		return NULL;
	lseek(fd, 0, SEEK_SET);
	for (;;) {
		if (len + 1 >= cap) {
			cap *= 2;
			char *nb = realloc(buf, cap);
			if (!nb) {
				free(buf);
				return NULL;
			}
			buf = nb;
		}
		ssize_t k = read(fd, buf + len, cap - len - 1);
		if (k <= 0)
			break;
		len += (size_t)k;
	}
	buf[len] = '\0';
	return buf;
}

static void mkdirs(const char *path)
{
	char tmp[1024];
	snprintf(tmp, sizeof tmp, "%s", path);
	for (char *p = tmp + 1; *p; p++) {
		if (*p == '/') {
			*p = '\0';
			mkdir(tmp, 0755);
			*p = '/';
		}
	}
	mkdir(tmp, 0755);
}

int bsim_test_remove(const char *path)
{
	char cmd[1500];
	snprintf(cmd, sizeof cmd, "rm -rf '%s'", path);
	return system(cmd) == 0 ? 0 : -1;
}

const char *bsim_test_dir(const char *name)
{
	static char path[1024];
	snprintf(path, sizeof path, "%s/%s", BSIM_TEST_TMP, name);
	if (bsim_test_remove(path) != 0)
		return path;
	mkdirs(path);
	return path;
}

const char *bsim_test_dir_held(const char *name)
{
	static char buf[4][1200];
	static int k;
	k = (k + 1) % 4;
	snprintf(buf[k], sizeof buf[k], "%s", bsim_test_dir(name));
	return buf[k];
}

const char *bsim_test_write(const char *dir, const char *name, const char *text)
{
	static char path[1024];
	snprintf(path, sizeof path, "%s/%s", dir, name);
	FILE *f = fopen(path, "w");
	if (f) {
		fputs(text, f);
		fclose(f);
	}
	return path;
}

char *bsim_test_fake_program(const char *dir, const char *name, const char *script)
{
	if (mkdir(dir, 0755) != 0 && errno != EEXIST)
		fail_msg("%s: %s", dir, strerror(errno));
	const char *path = bsim_test_write(dir, name, script);
	if (chmod(path, 0755) != 0)
		fail_msg("%s: %s", path, strerror(errno));
	const char *now = getenv("PATH");
	char *old = strdup(now ? now : "/usr/bin:/bin");
	size_t n = strlen(dir) + strlen(old) + 2;
	char *with = malloc(n);
	if (!old || !with)
		abort();
	snprintf(with, n, "%s:%s", dir, old);
	setenv("PATH", with, 1);
	free(with);
	return old;
}

void bsim_test_path_restore(char *old)
{
	setenv("PATH", old, 1);
	free(old);
}

void bsim_test_check_committed(const char *dir, const char *const files[],
                               const char *const absent[])
{
	int has = 0;
	bsim_error err;
	if (bsim_outdir_verify(dir, &has, &err) != BSIM_OK)
		fail_msg("%s: %s", dir, err.msg);
	if (!has)
		fail_msg("%s: no manifest.json", dir);
	char **paths = NULL;
	size_t n = 0;
	if (bsim_outdir_files(dir, &paths, &n, &err) != BSIM_OK)
		fail_msg("%s: %s", dir, err.msg);
	for (int k = 0; k < 2; k++) {
		const char *const *names = k == 0 ? files : absent;
		for (int i = 0; names && names[i]; i++) {
			int found = 0;
			for (size_t j = 0; j < n; j++)
				found |= strcmp(paths[j], names[i]) == 0;
			if (found != (k == 0))
				fail_msg("%s/manifest.json %s %s", dir, k == 0 ? "lacks" : "lists",
				         names[i]);
		}
	}
	bsim_outdir_files_free(paths, n);
	if (bsim_test_exists(bsim_test_join(dir, ".beamsim")))
		fail_msg("%s/.beamsim is left", dir);
}

char *bsim_test_read(const char *path)
{
	int fd = open(path, O_RDONLY);
	if (fd < 0)
		return NULL;
	char *s = slurp_fd(fd);
	close(fd);
	return s;
}

const char *bsim_test_src(const char *rel)
{
	static char path[1024];
	snprintf(path, sizeof path, "%s/%s", BSIM_SOURCE_DIR, rel);
	return path;
}

char *bsim_test_read_glob(const char *pattern)
{
	glob_t g;
	if (glob(pattern, 0, NULL, &g) != 0)
		return NULL;
	size_t len = 0;
	char *all = calloc(1, 1);
	for (size_t i = 0; all && i < g.gl_pathc; i++) {
		char *t = bsim_test_read(g.gl_pathv[i]);
		size_t n = t ? strlen(t) : 0;
		char *more = realloc(all, len + n + 1);
		if (more) {
			memcpy(more + len, t ? t : "", n + 1);
			len += n;
		} else {
			free(all);
		}
		all = more;
		free(t);
	}
	globfree(&g);
	return all;
}

const char *bsim_test_glob_first(const char *pattern)
{
	static char path[1200];
	glob_t g;
	if (glob(pattern, 0, NULL, &g) != 0)
		return NULL;
	snprintf(path, sizeof path, "%s", g.gl_pathv[0]);
	globfree(&g);
	return path;
}

const char *bsim_test_join(const char *dir, const char *name)
{
	static char buf[4][1400];
	static int k;
	k = (k + 1) % 4;
	if (snprintf(buf[k], sizeof buf[k], "%s/%s", dir, name) >= (int)sizeof buf[k])
		fail_msg("path too long: %s/%s", dir, name);
	return buf[k];
}

int bsim_test_exists(const char *path)
{
	return access(path, F_OK) == 0;
}

long bsim_test_size(const char *path)
{
	struct stat st;
	return stat(path, &st) == 0 ? (long)st.st_size : -1;
}

int bsim_test_count_lines(const char *text)
{
	int n = 0;
	for (; *text; text++)
		n += *text == '\n';
	return n;
}

/* The argument vector of prog: prog, then argv. */
static char **argv_build(const char *prog, const char *const argv[])
{
	int n = 0;
	while (argv[n])
		n++;
	char **args = calloc((size_t)n + 2, sizeof *args);
	if (!args)
		abort();
	args[0] = (char *)prog;
	for (int i = 0; i < n; i++)
		args[i + 1] = (char *)argv[i];
	return args;
}

static int status_code(int status)
{
	if (WIFEXITED(status))
		return WEXITSTATUS(status);
	return WIFSIGNALED(status) ? 128 + WTERMSIG(status) : -1;
}

/* Starts file with args (looked up on PATH if search): stdin /dev/null,
 * stdout out_fd and stderr err_fd (-1: /dev/null) unless o names files for
 * them, and o's limits. The child exits 127 if it cannot start. */
static pid_t launch(const char *file, char *const args[], int search, const bsim_test_opts *o,
                    int out_fd, int err_fd)
{
	fflush(NULL);
	pid_t pid = fork();
	if (pid != 0)
		return pid;
	int null = open("/dev/null", O_RDWR);
	int to = out_fd < 0 ? null : out_fd, te = err_fd < 0 ? null : err_fd;
	if (o && o->out)
		to = open(o->out, O_WRONLY);
	if (o && o->err)
		te = open(o->err, O_WRONLY | O_CREAT | O_TRUNC, 0600);
	if (null < 0 || to < 0 || te < 0)
		_exit(127);
	dup2(null, 0);
	dup2(to, 1);
	dup2(te, 2);
	if (o && o->fsize > 0) {
		struct rlimit rl = {(rlim_t)o->fsize, (rlim_t)o->fsize};
		setrlimit(RLIMIT_FSIZE, &rl);
		signal(SIGXFSZ, SIG_IGN); /* a write beyond fails with EFBIG */
	}
	if (o && o->as > 0) {
		struct rlimit rl = {(rlim_t)o->as, (rlim_t)o->as};
		setrlimit(RLIMIT_AS, &rl);
	}
	if (o && o->timeout > 0)
		alarm((unsigned)ceil(o->timeout)); /* kept across exec */
	if (search)
		execvp(file, args);
	else
		execv(file, args);
	_exit(127);
}

/* A pseudo-terminal: its terminal side's descriptor, the other side's in
 * *master, both closed on exec. What is written to the terminal reads back
 * as written ("\n" not made "\r\n"). Fails the test if there is none. */
static int pty_open(int *master)
{
	int m = posix_openpt(O_RDWR | O_NOCTTY);
	if (m < 0 || grantpt(m) != 0 || unlockpt(m) != 0)
		fail_msg("no pseudo-terminal: %s", strerror(errno));
	const char *name = ptsname(m);
	int t = name ? open(name, O_RDWR | O_NOCTTY) : -1;
	struct termios tio;
	if (t < 0 || tcgetattr(t, &tio) != 0)
		fail_msg("no pseudo-terminal: %s", strerror(errno));
	tio.c_oflag &= ~(tcflag_t)OPOST;
	tcsetattr(t, TCSANOW, &tio);
	fcntl(m, F_SETFD, FD_CLOEXEC);
	fcntl(t, F_SETFD, FD_CLOEXEC);
	*master = m;
	return t;
}

/* Copies what fd gives into file until its writers are gone: a terminal's
 * other side reads EIO once no process holds the terminal open. */
static void drain(int fd, FILE *file)
{
	char buf[4096];
	ssize_t k;
	while ((k = read(fd, buf, sizeof buf)) > 0 || (k < 0 && errno == EINTR))
		if (k > 0)
			fwrite(buf, 1, (size_t)k, file);
	fflush(file);
}

/* Runs to the end with stdout and stderr captured (unless o redirects
 * them) into *out and *err (either may be NULL). */
static int run_captured(const char *file, char *const args[], int search, const bsim_test_opts *o,
                        char **out, char **err)
{
	FILE *fo = tmpfile(), *fe = tmpfile();
	if (!fo || !fe)
		abort();
	int master = -1, term = o && o->tty ? pty_open(&master) : -1;
	pid_t pid = launch(file, args, search, o, fileno(fo), term >= 0 ? term : fileno(fe));
	if (term >= 0) {
		close(term);
		drain(master, fe);
		close(master);
	}
	int status = 0;
	waitpid(pid, &status, 0);
	if (out)
		*out = slurp_fd(fileno(fo));
	if (err)
		*err = slurp_fd(fileno(fe));
	fclose(fo);
	fclose(fe);
	return status_code(status);
}

int bsim_test_cli_with(const char *const argv[], const bsim_test_opts *o, char **out, char **err)
{
	char **args = argv_build(BSIM_EXE, argv);
	int rc = run_captured(BSIM_EXE, args, 0, o, out, err);
	free(args);
	return rc;
}

int bsim_test_cli(const char *const argv[], char **out, char **err)
{
	return bsim_test_cli_with(argv, NULL, out, err);
}

void bsim_test_check_input_error(int rc, const char *err, const char *const needles[], int one_line)
{
	assert_non_null(err);
	if (rc != 2)
		fail_msg("exit status %d, stderr: %s", rc, err);
	for (int i = 0; needles[i]; i++)
		if (!strstr(err, needles[i]))
			fail_msg("stderr \"%s\" lacks \"%s\"", err, needles[i]);
	/* One message: libfyaml must not print diagnostics of its own. */
	const char *nl = strchr(err, '\n');
	if (one_line && (!nl || nl[1] != '\0'))
		fail_msg("expected one line on stderr, got \"%s\"", err);
}

void bsim_test_expect_input_error(const char *const argv[], const char *const needles[])
{
	char *out = NULL, *err = NULL;
	int rc = bsim_test_cli(argv, &out, &err);
	bsim_test_check_input_error(rc, err, needles, 1);
	free(out);
	free(err);
}

int bsim_test_run(const char *const argv[], char **out)
{
	return run_captured(argv[0], (char *const *)argv, 1, NULL, out, NULL);
}

const char *bsim_test_gate_experiment(const char *dir)
{
	char yaml[2048];
	snprintf(yaml, sizeof yaml,
	         "scene: %s\ntrials: 4\nseed: 1\ngrid:\n"
	         "  effects.propulsion.force: [9]\n"
	         "  effects.random_force.magnitude: [0, 30]\n",
	         bsim_test_src("configs/thesis/gate.yaml"));
	return bsim_test_write(dir, "small.yaml", yaml);
}

char *bsim_test_browser_dom(const char *url, char **console)
{
	const char *probe[] = {"chromium", "--version", NULL};
	if (bsim_test_run(probe, NULL) != 0)
		fail_msg("chromium is not installed: run scripts/deps.sh (it installs the Debian "
		         "package chromium), then run this test again");
	char profile[1200];
	snprintf(profile, sizeof profile, "--user-data-dir=%s", bsim_test_dir("chromium_profile"));
	/* --no-sandbox: the sandbox refuses to run as root (CI, containers);
	 * --virtual-time-budget: the DOM is dumped once the page has loaded;
	 * --enable-logging=stderr: the page's console lines on stderr */
	const char *argv[] = {"chromium",
	                      "--headless",
	                      "--no-sandbox",
	                      "--disable-gpu",
	                      "--no-first-run",
	                      profile,
	                      "--enable-logging=stderr",
	                      "--v=0",
	                      "--virtual-time-budget=5000",
	                      "--dump-dom",
	                      url,
	                      NULL};
	char *out = NULL, *err = NULL;
	int rc = run_captured(argv[0], (char *const *)argv, 1, NULL, &out, &err);
	if (rc != 0 || !out)
		fail_msg("chromium %s: exit status %d: %s", url, rc, err ? err : "");
	if (console) {
		/* "[pid:tid:date:INFO:CONSOLE:line] "message", source: URL (line)" */
		size_t n = 0;
		char *lines = calloc(1, 1);
		const char *l = err ? err : "";
		while (lines && *l) {
			const char *nl = strchr(l, '\n');
			size_t len = nl ? (size_t)(nl - l) : strlen(l);
			const char *hit = strstr(l, ":CONSOLE");
			if (hit && hit < l + len) {
				char *grown = realloc(lines, n + len + 2);
				if (!grown)
					abort();
				lines = grown;
				memcpy(lines + n, l, len);
				n += len;
				lines[n++] = '\n';
				lines[n] = '\0';
			}
			l += len + (nl != NULL);
		}
		if (!lines)
			abort();
		*console = lines;
	}
	free(err);
	return out;
}

int bsim_test_spawn_with(const char *const argv[], const bsim_test_opts *o)
{
	char **args = argv_build(BSIM_EXE, argv);
	pid_t pid = launch(BSIM_EXE, args, 0, o, -1, -1);
	free(args);
	return (int)pid;
}

int bsim_test_spawn(const char *const argv[])
{
	return bsim_test_spawn_with(argv, NULL);
}

int bsim_test_wait(int pid)
{
	int status = 0;
	waitpid((pid_t)pid, &status, 0);
	return status_code(status);
}

long bsim_test_journal_records(const char *path)
{
	int fd = open(path, O_RDONLY);
	if (fd < 0)
		return -1;
	/* "BSIMJNL2", u32 record size, u32 fields length, fields, u32 inputs
	 * length, inputs, u32 CRC; then records of u32 magic, u64 index,
	 * payload, u32 CRC. */
	unsigned char h[16];
	struct stat st;
	long n = 0;
	uint32_t size = 0, flen = 0, ilen = 0;
	int ok = read(fd, h, sizeof h) == (ssize_t)sizeof h && fstat(fd, &st) == 0;
	if (ok) {
		memcpy(&size, h + 8, 4);
		memcpy(&flen, h + 12, 4);
		ok = pread(fd, &ilen, 4, 16 + (off_t)flen) == 4;
	}
	if (ok) {
		long header = 16 + (long)flen + 4 + (long)ilen + 4, record = 16 + (long)size;
		if ((long)st.st_size > header)
			n = ((long)st.st_size - header) / record;
	}
	close(fd);
	return n;
}

static int has_records(const char *path, long n)
{
	return bsim_test_journal_records(path) >= n;
}

static int has_entry(const char *dir, long n)
{
	(void)n;
	DIR *d = opendir(dir);
	if (!d)
		return 0;
	struct dirent *e;
	int found = 0;
	while (!found && (e = readdir(d)))
		found = strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0;
	closedir(d);
	return found;
}

/* A guard against a program that hangs, never what a test waits for: far
 * beyond any run the tests start, even on a loaded machine. */
#define AWAIT_DEADLINE_S 300.0

int bsim_test_await(int pid, int (*ready)(void *ctx), void *ctx, const char *what, int *status)
{
	const struct timespec tick = {0, 1000000};
	struct timespec t0, t;
	clock_gettime(CLOCK_MONOTONIC, &t0);
	for (;;) {
		if (ready(ctx))
			return 1;
		int st = 0;
		pid_t w = waitpid((pid_t)pid, &st, WNOHANG);
		if (w != 0) {
			*status = w == (pid_t)pid ? status_code(st) : -1;
			return 0;
		}
		clock_gettime(CLOCK_MONOTONIC, &t);
		if ((double)(t.tv_sec - t0.tv_sec) > AWAIT_DEADLINE_S) {
			kill((pid_t)pid, SIGKILL);
			waitpid((pid_t)pid, &st, 0);
			fail_msg("waited %g s for %s while the program neither got there nor "
			         "ended: killed it",
			         AWAIT_DEADLINE_S, what);
		}
		nanosleep(&tick, NULL);
	}
}

/* What a wait on a file or a directory looks at: ready(path, n). */
typedef struct path_wait {
	int (*ready)(const char *path, long n);
	const char *path;
	long n;
} path_wait;

static int path_ready(void *ctx)
{
	const path_wait *pw = ctx;
	return pw->ready(pw->path, pw->n);
}

static int await(int pid, int (*ready)(const char *, long), const char *path, long n, int *status)
{
	path_wait pw = {ready, path, n};
	char what[1200];
	snprintf(what, sizeof what, "%s (%ld)", path, n);
	return bsim_test_await(pid, path_ready, &pw, what, status);
}

int bsim_test_await_records(int pid, const char *path, long n, int *status)
{
	return await(pid, has_records, path, n, status);
}

int bsim_test_await_entry(int pid, const char *dir, int *status)
{
	return await(pid, has_entry, dir, 0, status);
}

static int has_matches(const char *pattern, long n)
{
	glob_t g;
	long found = glob(pattern, 0, NULL, &g) == 0 ? (long)g.gl_pathc : 0;
	if (found)
		globfree(&g);
	return found >= n;
}

int bsim_test_await_glob(int pid, const char *pattern, long n, int *status)
{
	return await(pid, has_matches, pattern, n, status);
}

/* Every NAME.gp in dir has NAME.png and NAME.svg (when gnuplot is there),
 * each over 1 kB and at most 1 MB; the number of figures, or -1 (said on
 * stderr) if one is missing or out of that range. */
const char *bsim_test_png_edge(const char *path)
{
	static char why[128];
	cairo_surface_t *img = cairo_image_surface_create_from_png(path);
	if (cairo_surface_status(img) != CAIRO_STATUS_SUCCESS) {
		snprintf(why, sizeof why, "unreadable (%s)",
		         cairo_status_to_string(cairo_surface_status(img)));
		cairo_surface_destroy(img);
		return why;
	}
	cairo_surface_flush(img);
	const int w = cairo_image_surface_get_width(img), h = cairo_image_surface_get_height(img);
	const int stride = cairo_image_surface_get_stride(img);
	const cairo_format_t fmt = cairo_image_surface_get_format(img);
	const unsigned char *px = cairo_image_surface_get_data(img);
	const int e = BSIM_TEST_EDGE_PX;
	int side[4] = {0, 0, 0, 0}; /* left, right, top, bottom */
	for (int y = 0; px && y < h; y++)
		for (int x = 0; x < w; x++) {
			if (x >= e && x < w - e && y >= e && y < h - e) {
				x = w - e - 1; /* the row's inside: on to its right edge */
				continue;
			}
			uint32_t p;
			memcpy(&p, px + (size_t)y * (size_t)stride + 4 * (size_t)x, sizeof p);
			/* ARGB32 (or RGB24, opaque): ink is a pixel not nearly
			 * transparent and darker than the white background in any
			 * channel (anti-aliased text edges included) */
			const unsigned a = fmt == CAIRO_FORMAT_ARGB32 ? p >> 24 : 255;
			const unsigned r = p >> 16 & 255, g = p >> 8 & 255, b = p & 255;
			if (a <= 8 || (r >= 235 && g >= 235 && b >= 235))
				continue;
			side[0] |= x < e;
			side[1] |= x >= w - e;
			side[2] |= y < e;
			side[3] |= y >= h - e;
		}
	cairo_surface_destroy(img);
	static const char *const name[4] = {"left", "right", "top", "bottom"};
	size_t k = 0;
	why[0] = '\0';
	for (int i = 0; i < 4; i++)
		if (side[i])
			k += (size_t)snprintf(why + k, sizeof why - k, "%s%s", k ? ", " : "",
			                      name[i]);
	return k ? why : NULL;
}

int bsim_test_check_figures(const char *dir)
{
	DIR *d = opendir(dir);
	if (!d) {
		fprintf(stderr, "cannot open %s\n", dir);
		return -1;
	}
	struct dirent *e;
	int n = 0, bad = 0;
	while ((e = readdir(d))) {
		size_t len = strlen(e->d_name);
		if (len < 4 || strcmp(e->d_name + len - 3, ".gp") != 0)
			continue;
		n++;
		static const char *const ext[] = {"png", "svg"};
		for (int i = 0; i < 2 && bsim_figure_available(); i++) {
			char path[1200];
			struct stat st;
			snprintf(path, sizeof path, "%s/%.*s.%s", dir, (int)len - 3, e->d_name,
			         ext[i]);
			if (stat(path, &st) != 0) {
				fprintf(stderr, "missing %s\n", path);
				bad = 1;
			} else if (st.st_size <= 1000 || st.st_size > 1000000) {
				fprintf(stderr, "%s: %ld bytes\n", path, (long)st.st_size);
				bad = 1;
			} else if (i == 0) {
				const char *edge = bsim_test_png_edge(path);
				if (edge) {
					fprintf(stderr,
					        "%s: drawn within %d pixels of its edge (%s): a "
					        "title, label or key cut off by the canvas\n",
					        path, BSIM_TEST_EDGE_PX, edge);
					bad = 1;
				}
			}
		}
	}
	closedir(d);
	return bad ? -1 : n;
}

/* Wilson's score interval at 95% in closed form (Wilson 1927), written here
 * apart from the library's. */
void bsim_test_wilson(int k, int n, double *lo, double *hi)
{
	const double z = 1.959963984540054, p = (double)k / n;
	double c = (p + z * z / (2 * n)) / (1 + z * z / n);
	double h = z / (1 + z * z / n) * sqrt(p * (1 - p) / n + z * z / (4.0 * n * n));
	*lo = fmax(0.0, c - h);
	*hi = fmin(1.0, c + h);
}

int bsim_test_data_rows(const char *path, int block, double (*rows)[16], int max)
{
	char *text = bsim_test_read(path);
	if (!text) { /* a test's failure, as its assertion was */
		fprintf(stderr, "cannot read %s\n", path);
		abort();
	}
	int b = 0, n = 0;
	for (char *p = text; *p;) {
		char *nl = strchr(p, '\n');
		if (!nl)
			nl = p + strlen(p);
		if (nl == p) { /* an empty line: two in a row end a block */
			if (nl[1] == '\n')
				b++, p = nl + 2;
			else
				p = nl + 1;
			continue;
		}
		if (*p != '#' && b == block && n < max) {
			char *q = p, *end;
			int k = 0;
			while (k < 16 && q < nl) {
				rows[n][k] = strtod(q, &end);
				if (end == q)
					break;
				k++;
				q = end;
			}
			if (k)
				n++;
		}
		p = *nl ? nl + 1 : nl;
	}
	free(text);
	return n;
}

double bsim_test_json_number(const char *text, const char *key)
{
	char pat[128];
	snprintf(pat, sizeof pat, "\"%s\": ", key);
	const char *p = text ? strstr(text, pat) : NULL;
	if (!p) {
		fprintf(stderr, "no \"%s\" in the JSON\n", key);
		abort();
	}
	return strtod(p + strlen(pat), NULL);
}

double bsim_test_json_at(struct fy_node *root, const char *path)
{
	double v = NAN;
	struct fy_node *n = bsim_ydoc_lookup(root, path);
	if (!n || bsim_ydoc_number(n, &v) != YDOC_NUM_OK)
		fail_msg("JSON: no number at %s", path);
	return v;
}

const char *bsim_test_json_text_at(struct fy_node *root, const char *path, char *buf, size_t size)
{
	struct fy_node *n = bsim_ydoc_lookup(root, path);
	size_t len = 0;
	const char *t = n && fy_node_is_scalar(n) ? fy_node_get_scalar(n, &len) : NULL;
	if (!t)
		fail_msg("JSON: no text at %s", path);
	snprintf(buf, size, "%.*s", (int)len, t);
	return buf;
}

int bsim_test_check_wrote(const char *out, const char *dir)
{
	char path[2048];
	snprintf(path, sizeof path, "%s/manifest.json", dir);
	char *m = bsim_test_read(path);
	if (!m)
		fail_msg("%s missing", path);
	snprintf(path, sizeof path, "wrote %s/ (manifest.json lists these):\n", dir);
	if (!strstr(out, path))
		fail_msg("no '%s' in:\n%s", path, out);
	const char *after = strstr(out, path) + strlen(path);
	int n = 0;
	static const char key[] = "{\"path\": \"";
	for (const char *p = strstr(m, key); p; p = strstr(p + 1, key)) {
		const char *name = p + strlen(key);
		size_t len = strcspn(name, "\"");
		char line[1100];
		snprintf(line, sizeof line, "  %.*s", (int)len, name);
		/* the name, then two spaces and its words or the line's end */
		const char *at = strstr(after, line);
		if (!at || (at[2 + len] != ' ' && at[2 + len] != '\n'))
			fail_msg("%.*s (in %s/manifest.json) is not in the wrote lines:\n%s",
			         (int)len, name, dir, out);
		n++;
	}
	free(m);
	return n;
}

int bsim_test_run_per_backend(const char *group, const struct CMUnitTest *tests, size_t n)
{
	/* The example plug-in, registered as a user's is, by BEAMSIM_PLUGINS
	 * (which the commands a test runs inherit): its tests are the built-in
	 * backends' */
	bsim_error err;
	setenv(BSIM_PLUGINS_ENV, BSIM_TEST_PLUGIN, 1);
	if (!bsim_backend_load(BSIM_TEST_PLUGIN, &err)) {
		fprintf(stderr, "%s: %s\n", group, err.msg);
		return 1;
	}
	const bsim_backend *const *all = bsim_backend_list();
	size_t nb = 0;
	while (all[nb])
		nb++;
	struct CMUnitTest *t = calloc(n * nb, sizeof *t);
	char(*names)[128] = calloc(n * nb, sizeof *names);
	if (!t || !names) {
		fprintf(stderr, "%s: out of memory\n", group);
		return 1;
	}
	for (size_t i = 0, k = 0; i < n; i++)
		for (size_t j = 0; j < nb; j++, k++) {
			t[k] = tests[i];
			snprintf(names[k], sizeof names[k], "%s (%s)", tests[i].name, all[j]->name);
			t[k].name = names[k];
			t[k].initial_state = (void *)all[j];
		}
	int rc = _cmocka_run_group_tests(group, t, n * nb, NULL, NULL);
	free(t);
	free(names);
	return rc;
}

double bsim_test_bound(const bsim_backend *b, const char *check)
{
	double v;
	if (!bsim_backend_bound_of(b, check, &v))
		bsim_test_skip(b,
		               "it states no bound for the check %s (bsim_backend.bounds, "
		               "docs/tests.md)",
		               check);
	return v;
}

void bsim_test_skip(const bsim_backend *b, const char *fmt, ...)
{
	char why[512];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(why, sizeof why, fmt, ap);
	va_end(ap);
	print_message("SKIP %s: %s\n", b->name, why);
	skip();
}

const bsim_backend *bsim_test_backend(const char *name)
{
	bsim_error err;
	const bsim_backend *b = bsim_backend_find(name, &err);
	if (!b)
		fail_msg("%s", err.msg);
	return b;
}

long bsim_test_run_steps, bsim_test_run_free;

int bsim_test_counted_advance(bsim_world *w, const bsim_wrench *schedule, double h, int n,
                              bsim_state *out, int *made, bsim_error *err)
{
	const bsim_backend *be = bsim_test_backend("thesis");
	if (n == 1 && out) {
		int rc = be->advance(w, schedule, h, 1, NULL, made, err);
		be->get_state(w, out);
		return rc;
	}
	int rc = be->advance(w, schedule, h, n, out, made, err);
	bsim_test_run_steps += *made;
	for (int k = 0; out && k < *made; k++)
		bsim_test_run_free += out[k].n_active == 0;
	return rc;
}

double bsim_test_uniform(uint64_t *s)
{
	*s ^= *s >> 12;
	*s ^= *s << 25;
	*s ^= *s >> 27;
	return (double)((*s * 2685821657736338717ull) >> 11) * 0x1.0p-53;
}

void bsim_test_skip_refused(const bsim_backend *b, bsim_scene *s)
{
	char field[64];
	bsim_error err;
	if (b->check && b->check(s, NULL, field, sizeof field, &err) != BSIM_OK) {
		bsim_scene_free(s);
		bsim_test_skip(b, "it refuses the scene: %s", err.msg);
	}
}

bsim_options bsim_test_body_options(const bsim_backend *b, const bsim_body_def *body)
{
	bsim_options o;
	memset(&o, 0, sizeof o);
	if (body->shape != BSIM_SHAPE_ELLIPSE)
		return o;
	for (int k = 0; k < b->n_knobs; k++) {
		if (strcmp(b->knobs[k].name, "ellipse") == 0) {
			bsim_error err;
			if (bsim_options_add(&o, "ellipse=polygon", &err) != BSIM_OK)
				fail_msg("%s", err.msg);
		}
	}
	return o;
}

bsim_world *bsim_test_world(const bsim_backend *b, const bsim_scene *s, const bsim_options *opts)
{
	bsim_world *w = NULL;
	bsim_error err;
	if (b->create(s, opts, &w, &err) != BSIM_OK)
		fail_msg("%s: %s", b->name, err.msg);
	return w;
}

void bsim_test_simulate_locations(const bsim_scene *s, const bsim_location *loc, int n, int N,
                                  uint64_t seed, double *share)
{
	bsim_trial_runner *r = bsim_trial_runner_alloc();
	const bsim_options none = {0};
	bsim_error err;
	assert_non_null(r);
	for (int t = 0; t < N; t++) {
		bsim_trial_result res;
		assert_int_equal(bsim_trial_run(r, s, bsim_backend_default(), &none,
		                                bsim_schedule_seed_mix(seed, 0, (uint64_t)t), NULL,
		                                &res, &err),
		                 BSIM_OK);
		const bsim_location at = bsim_lattice_location_of(&res);
		for (int i = 0; i < n; i++)
			if (bsim_lattice_location_equal(loc[i], at))
				share[i] += 1.0 / N;
	}
	bsim_trial_runner_free(r);
}
