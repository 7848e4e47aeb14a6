/* Figures drawn by gnuplot from the scripts beamsim writes (figure.h).
 *
 * The script written for figure NAME:
 *
 *   if (!exists("outbase")) outbase = "NAME"
 *   do for [fmt in "png svg"] {
 *     if (fmt eq "png") { set terminal pngcairo ... } else { set terminal svg ... }
 *     set output outbase.".".fmt
 *     reset            # each pass draws from the same clean settings
 *     <body>
 *     unset output
 *   }
 *
 * By hand it draws NAME.png and NAME.svg. beamsim passes
 * outbase = "NAME.tmp.PID" and renames the two images once gnuplot has
 * exited cleanly, so a reader never sees a half-drawn image. */
#define _POSIX_C_SOURCE 200809L
#include "util/figure.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "util/atomic_file.h"
#include "beamsim/version.h"
#include "beamsim/limits.h"

bsim_figure_def bsim_figure_def_default(void)
{
	bsim_figure_def d = {
	        .dir = NULL, .name = NULL, .width = 900, .height = 600, .font = "sans,11"};
	return d;
}

const char *bsim_figure_missing_hint(void)
{
	return "gnuplot not found: the figures' data and .gp scripts are written, the images "
	       "are not; install the Debian package gnuplot-nox and run `gnuplot NAME.gp` in "
	       "the output directory";
}

int bsim_figure_available(void)
{
	const char *path = getenv("PATH");
	if (!path || !*path)
		path = "/usr/bin:/bin";
	char buf[4096];
	while (*path) {
		size_t n = strcspn(path, ":");
		if (n > 0 && n + sizeof "/gnuplot" < sizeof buf) {
			memcpy(buf, path, n);
			memcpy(buf + n, "/gnuplot", sizeof "/gnuplot");
			if (access(buf, X_OK) == 0)
				return 1;
		}
		path += n + (path[n] == ':');
	}
	return 0;
}

/* Names are made by beamsim, never by a user; they go into a gnuplot
 * string and a file name, so only a safe alphabet is allowed. */
static int name_ok(const char *s)
{
	if (!s || !*s)
		return 0;
	for (; *s; s++)
		if (!(*s >= 'a' && *s <= 'z') && !(*s >= 'A' && *s <= 'Z') &&
		    !(*s >= '0' && *s <= '9') && *s != '_' && *s != '-' && *s != '.')
			return 0;
	return 1;
}

static int script_write(const bsim_figure_def *d, const char *body, bsim_error *err)
{
	char path[1024];
	if (snprintf(path, sizeof path, "%s/%s.gp", d->dir, d->name) >= (int)sizeof path)
		return bsim_error_set(err, BSIM_EFAIL, "%s/%s.gp: path too long", d->dir, d->name);
	bsim_atomic_file o;
	int rc = bsim_atomic_file_open(&o, path, err);
	if (rc)
		return rc;
	fprintf(o.f,
	        "# %s.gp: drawn by beamsim %s. Rerun with `gnuplot %s.gp` in this directory;\n"
	        "# it writes %s.png and %s.svg. The drawing is the block inside the loop.\n"
	        "# `gnuplot -e 'scale=0.75' %s.gp` draws the PNG at 0.75 of its size.\n"
	        "if (!exists(\"outbase\")) outbase = \"%s\"\n"
	        "if (!exists(\"scale\")) scale = 1\n"
	        "do for [fmt in \"png svg\"] {\n"
	        "if (fmt eq \"png\") {\n"
	        "  set terminal pngcairo size %d*scale,%d*scale enhanced font \"%s\" "
	        "fontscale scale linewidth scale\n"
	        "} else {\n"
	        "  set terminal svg size %d,%d dynamic enhanced font \"%s\"\n"
	        "}\n"
	        "set output outbase.\".\".fmt\n"
	        "reset\n",
	        d->name, BSIM_VERSION, d->name, d->name, d->name, d->name, d->name, d->width,
	        d->height, d->font, d->width, d->height, d->font);
	fputs(body, o.f);
	if (*body && body[strlen(body) - 1] != '\n')
		fputc('\n', o.f);
	fputs("unset output\n}\n", o.f);
	return bsim_atomic_file_commit(&o, err);
}

/* Starts `gnuplot -e 'outbase="TMP"' NAME.gp` in DIR, its standard output
 * to /dev/null and its messages to ours. The process id, or -1. */
static pid_t gnuplot_start(const char *dir, const char *name, const char *tmpbase)
{
	char script[BSIM_PATH_MAX], expr[BSIM_PATH_MAX];
	snprintf(script, sizeof script, "%s.gp", name);
	snprintf(expr, sizeof expr, "outbase=\"%s\"", tmpbase);
	fflush(NULL);
	pid_t pid = fork();
	if (pid != 0)
		return pid;
	int null = open("/dev/null", O_WRONLY);
	if (null >= 0)
		dup2(null, STDOUT_FILENO);
	if (chdir(dir) != 0)
		_exit(126);
	execlp("gnuplot", "gnuplot", "-e", expr, script, (char *)NULL);
	_exit(127);
}

/* The exit status of process pid, or -1. */
static int gnuplot_wait(pid_t pid)
{
	if (pid < 0)
		return -1;
	int status;
	while (waitpid(pid, &status, 0) < 0)
		if (errno != EINTR)
			return -1;
	return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/* Moves the images of a finished gnuplot into place, or removes them if
 * it failed. */
static int images_commit(const bsim_figure_def *d, const char *tmpbase, int status, bsim_error *err)
{
	static const char *const ext[] = {"png", "svg"};
	char from[BSIM_PATH_MAX], to[BSIM_PATH_MAX];
	if (status != 0) {
		for (int i = 0; i < 2; i++) {
			snprintf(from, sizeof from, "%s/%s.%s", d->dir, tmpbase, ext[i]);
			unlink(from);
		}
		return bsim_error_set(err, BSIM_EFAIL,
		                      "gnuplot failed on %s/%s.gp (exit status %d); its data and "
		                      "script are left for a look",
		                      d->dir, d->name, status);
	}
	for (int i = 0; i < 2; i++) {
		snprintf(from, sizeof from, "%s/%s.%s", d->dir, tmpbase, ext[i]);
		snprintf(to, sizeof to, "%s/%s.%s", d->dir, d->name, ext[i]);
		if (rename(from, to) != 0)
			return bsim_error_set(err, BSIM_EFAIL, "%s: %s", to, strerror(errno));
	}
	return BSIM_OK;
}

/* def with the defaults filled in. */
static bsim_figure_def def_resolve(const bsim_figure_def *def)
{
	bsim_figure_def d = bsim_figure_def_default();
	d.dir = def->dir;
	d.name = def->name;
	if (def->width > 0)
		d.width = def->width;
	if (def->height > 0)
		d.height = def->height;
	if (def->font)
		d.font = def->font;
	return d;
}

int bsim_figure_render_all(const bsim_figure_def *defs, const char *const *bodies, int n,
                           int *drawn, bsim_error *err)
{
	if (drawn)
		*drawn = 0;
	for (int i = 0; i < n; i++) {
		bsim_figure_def d = def_resolve(&defs[i]);
		if (!d.dir || !name_ok(d.name))
			return bsim_error_set(err, BSIM_EFAIL, "figure: bad name '%s'",
			                      d.name ? d.name : "(null)");
		int rc = script_write(&d, bodies[i], err);
		if (rc)
			return rc;
	}
	if (!bsim_figure_available())
		return BSIM_OK;
	pid_t *pids = malloc((n > 0 ? (size_t)n : 1) * sizeof *pids);
	if (!pids)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	for (int i = 0; i < n; i++) {
		char tmpbase[256];
		snprintf(tmpbase, sizeof tmpbase, "%s.tmp.%ld", defs[i].name, (long)getpid());
		pids[i] = gnuplot_start(defs[i].dir, defs[i].name, tmpbase);
	}
	int rc = BSIM_OK;
	for (int i = 0; i < n; i++) {
		bsim_figure_def d = def_resolve(&defs[i]);
		char tmpbase[256];
		snprintf(tmpbase, sizeof tmpbase, "%s.tmp.%ld", d.name, (long)getpid());
		bsim_error e1;
		int r = images_commit(&d, tmpbase, gnuplot_wait(pids[i]), &e1);
		if (r && rc == BSIM_OK) {
			rc = r;
			if (err)
				*err = e1;
		}
	}
	free(pids);
	if (drawn)
		*drawn = rc == BSIM_OK;
	return rc;
}

int bsim_figure_render(const bsim_figure_def *def, const char *body, int *drawn, bsim_error *err)
{
	return bsim_figure_render_all(def, &body, 1, drawn, err);
}
