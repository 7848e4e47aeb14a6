#define _POSIX_C_SOURCE 200809L

#include "support.h"

#include "util/figure.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <time.h>
#include <sys/wait.h>
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

int bsim_test_cli(const char *const argv[], char **out, char **err)
{
	int n = 0;
	while (argv[n])
		n++;
	char **args = calloc((size_t)n + 2, sizeof *args);
	args[0] = (char *)BSIM_EXE;
	for (int i = 0; i < n; i++)
		args[i + 1] = (char *)argv[i];

	FILE *fo = tmpfile(), *fe = tmpfile();
	fflush(NULL);
	pid_t pid = fork();
	if (pid == 0) {
		dup2(fileno(fo), 1);
		dup2(fileno(fe), 2);
		int devnull = open("/dev/null", O_RDONLY);
		dup2(devnull, 0);
		execv(BSIM_EXE, args);
		_exit(127);
	}
	int status = 0;
	waitpid(pid, &status, 0);
	free(args);
	if (out)
		*out = slurp_fd(fileno(fo));
	if (err)
		*err = slurp_fd(fileno(fe));
	fclose(fo);
	fclose(fe);
	return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
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

const char *bsim_test_dir(const char *name)
{
	static char path[1024];
	char cmd[1200];
	snprintf(path, sizeof path, "%s/%s", BSIM_TEST_TMP, name);
	snprintf(cmd, sizeof cmd, "rm -rf '%s'", path);
	if (system(cmd) != 0)
		return path;
	mkdirs(path);
	return path;
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

static char **argv_build(const char *const argv[])
{
	int n = 0;
	while (argv[n])
		n++;
	char **args = calloc((size_t)n + 2, sizeof *args);
	args[0] = (char *)BSIM_EXE;
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

int bsim_test_cli_with(const char *const argv[], const bsim_test_opts *o, char **out, char **err)
{
	char **args = argv_build(argv);
	FILE *fo = tmpfile(), *fe = tmpfile();
	fflush(NULL);
	pid_t pid = fork();
	if (pid == 0) {
		int to = o->out ? open(o->out, O_WRONLY) : fileno(fo);
		dup2(to, 1);
		dup2(fileno(fe), 2);
		int devnull = open("/dev/null", O_RDONLY);
		dup2(devnull, 0);
		if (o->fsize > 0) {
			struct rlimit rl = {(rlim_t)o->fsize, (rlim_t)o->fsize};
			setrlimit(RLIMIT_FSIZE, &rl);
			signal(SIGXFSZ, SIG_IGN); /* a write beyond fails with EFBIG */
		}
		execv(BSIM_EXE, args);
		_exit(127);
	}
	int status = 0;
	if (o->timeout > 0) {
		struct timespec step = {0, 10000000};
		double waited = 0;
		while (waitpid(pid, &status, WNOHANG) == 0) {
			if (waited >= o->timeout) {
				kill(pid, SIGKILL);
				waitpid(pid, &status, 0);
				break;
			}
			nanosleep(&step, NULL);
			waited += 0.01;
		}
	} else {
		waitpid(pid, &status, 0);
	}
	free(args);
	if (out)
		*out = slurp_fd(fileno(fo));
	if (err)
		*err = slurp_fd(fileno(fe));
	fclose(fo);
	fclose(fe);
	return status_code(status);
}

int bsim_test_spawn(const char *const argv[])
{
	char **args = argv_build(argv);
	fflush(NULL);
	pid_t pid = fork();
	if (pid == 0) {
		int devnull = open("/dev/null", O_RDWR);
		dup2(devnull, 0);
		dup2(devnull, 1);
		dup2(devnull, 2);
		execv(BSIM_EXE, args);
		_exit(127);
	}
	free(args);
	return (int)pid;
}

int bsim_test_wait(int pid)
{
	int status = 0;
	waitpid((pid_t)pid, &status, 0);
	return status_code(status);
}

/* Every NAME.gp in dir has NAME.png and NAME.svg (when gnuplot is there),
 * each over 1 kB and at most 1 MB; the number of figures, or -1 (said on
 * stderr) if one is missing or out of that range. */
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
