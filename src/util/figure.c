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
 * exited with status 0 and both are whole (a PNG ends with its IEND chunk,
 * an SVG with </svg>), so a reader never sees a half-drawn image. gnuplot's
 * messages go to a temporary file: the last line of a failing gnuplot is
 * its error, quoted in ours; those of one that succeeded are warnings,
 * passed on as notes (bsim_note). */
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
#include "util/program_log.h"
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

/* Characters of the n bytes at s (UTF-8 continuation bytes not counted). */
static int text_chars(const char *s, size_t n)
{
	int c = 0;
	for (size_t i = 0; i < n; i++)
		c += ((unsigned char)s[i] & 0xC0) != 0x80;
	return c;
}

/* Pixels a character takes at pt points (see bsim_figure_text_px). */
static double char_px(double pt)
{
	return pt * 15.0 / 22.0;
}

int bsim_figure_text_px(const char *text, double pt)
{
	int widest = 0;
	while (*text) {
		const size_t n = strcspn(text, "\n");
		const int c = text_chars(text, n);
		widest = c > widest ? c : widest;
		text += n + (text[n] == '\n');
	}
	return (int)(widest * char_px(pt) + 0.999);
}

void bsim_figure_wrap(const char *text, double pt, int width, char *out, size_t size)
{
	if (!size)
		return;
	const int most = (int)(width / char_px(pt)) > 8 ? (int)(width / char_px(pt)) : 8;
	size_t k = 0;
	while (*text && k + 1 < size) {
		size_t n = strcspn(text, "\n");
		/* this line's head up to its break, then the rest as a line */
		size_t cut = n;
		if (text_chars(text, n) > most) {
			size_t room = 0; /* the bytes of the first `most` characters */
			for (int c = 0; room < n && c < most; c++)
				do
					room++;
				while (room < n && ((unsigned char)text[room] & 0xC0) == 0x80);
			static const char *const seps[] = {"; ", ", ", " "};
			for (int s = 0; s < 3 && cut == n; s++) {
				const size_t len = strlen(seps[s]);
				for (size_t i = room; i-- > 1;)
					if (i + len <= n && !strncmp(text + i, seps[s], len) &&
					    (s == 2 || text_chars(text, i) >= most / 3)) {
						cut = i + len - 1; /* the space becomes the break */
						break;
					}
			}
		}
		for (size_t i = 0; i < cut && k + 1 < size; i++)
			out[k++] = text[i];
		if (cut < n) {
			if (k + 1 < size)
				out[k++] = '\n';
			text += cut + 1;
			continue;
		}
		text += n;
		if (*text == '\n') {
			if (k + 1 < size)
				out[k++] = '\n';
			text++;
		}
	}
	out[k] = '\0';
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
 * to /dev/null and its messages to log. The process id, or -1. */
static pid_t gnuplot_start(const char *dir, const char *name, const char *tmpbase, FILE *log)
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
	if (log)
		dup2(fileno(log), STDERR_FILENO);
	if (chdir(dir) != 0)
		_exit(126);
	execlp("gnuplot", "gnuplot", "-e", expr, script, (char *)NULL);
	_exit(127);
}

/* The status of process pid as a shell gives it (128 + a signal's
 * number), or -1. */
static int gnuplot_wait(pid_t pid)
{
	if (pid < 0)
		return -1;
	int status;
	while (waitpid(pid, &status, 0) < 0)
		if (errno != EINTR)
			return -1;
	if (WIFSIGNALED(status))
		return 128 + WTERMSIG(status);
	return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/* Whether an image gnuplot wrote is whole: a PNG ends with its IEND chunk,
 * an SVG with its closing tag. gnuplot exits with status 0 when a full disk
 * cut an image short, so its status alone does not tell. 0, or -1 with why
 * (of size n) saying what is wrong of the image NAME.EXT. */
static int image_whole(const char *path, const char *name, const char *ext, char *why, size_t n)
{
	static const unsigned char png_sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
	static const unsigned char png_end[12] = {0,   0,   0,    0,    'I',  'E',
	                                          'N', 'D', 0xae, 0x42, 0x60, 0x82};
	FILE *f = fopen(path, "rb");
	if (!f) {
		snprintf(why, n, "%s.%s was not written: %s", name, ext, strerror(errno));
		return -1;
	}
	unsigned char head[8] = {0}, tail[64] = {0};
	long size = -1;
	size_t got_head = fread(head, 1, sizeof head, f), got_tail = 0;
	if (fseek(f, 0, SEEK_END) == 0 && (size = ftell(f)) >= 0) {
		long from = size > (long)sizeof tail ? size - (long)sizeof tail : 0;
		if (fseek(f, from, SEEK_SET) == 0)
			got_tail = fread(tail, 1, sizeof tail, f);
	}
	fclose(f);
	int whole;
	if (strcmp(ext, "png") == 0) {
		whole = got_head == 8 && memcmp(head, png_sig, 8) == 0 && got_tail >= 12 &&
		        memcmp(tail + got_tail - 12, png_end, 12) == 0;
	} else {
		while (got_tail > 0 && (tail[got_tail - 1] == '\n' || tail[got_tail - 1] == '\r' ||
		                        tail[got_tail - 1] == ' '))
			got_tail--;
		whole = got_tail >= 6 && memcmp(tail + got_tail - 6, "</svg>", 6) == 0;
	}
	if (whole)
		return 0;
	snprintf(why, n, "%s.%s is cut short (%ld bytes, no %s at its end)", name, ext, size,
	         strcmp(ext, "png") == 0 ? "IEND chunk" : "</svg>");
	return -1;
}

/* 1 if name is one of the list ", A, B" in out. */
static int listed(const char *out, const char *name)
{
	size_t len = strlen(name);
	for (const char *q = out; (q = strstr(q, name)) != NULL; q++)
		if (q - out >= 2 && q[-2] == ',' && q[-1] == ' ' && (q[len] == ',' || !q[len]))
			return 1;
	return 0;
}

/* Appends ", A.dat, B.csv" to out (of size n) for the files the script's
 * body reads, named in it in quotes and present in dir (its titles and
 * labels name no file there), each once. */
static void data_names(const char *dir, const char *body, char *out, size_t n)
{
	size_t used = strlen(out);
	for (const char *p = body; *p; p++) {
		if (*p != '\'' && *p != '"')
			continue;
		const char *end = strchr(p + 1, *p);
		if (!end)
			break;
		size_t len = (size_t)(end - p - 1);
		char name[256], path[BSIM_PATH_MAX];
		struct stat st;
		if (len > 0 && len < sizeof name) {
			memcpy(name, p + 1, len);
			name[len] = '\0';
			if (!strchr(name, '/') && !listed(out, name) && used + len + 3 < n &&
			    snprintf(path, sizeof path, "%s/%s", dir, name) < (int)sizeof path &&
			    stat(path, &st) == 0 && S_ISREG(st.st_mode))
				used += (size_t)snprintf(out + used, n - used, ", %s", name);
		}
		p = end;
	}
}

/* Moves the images of a finished gnuplot into place if it exited with
 * status 0 and both are whole: 0. Else removes them and says why (of size
 * n, gnuplot's own message quoted): -1. */
static int images_commit(const bsim_figure_def *d, const char *tmpbase, int status, FILE *log,
                         char *why, size_t n)
{
	static const char *const ext[] = {"png", "svg"};
	char from[BSIM_PATH_MAX], to[BSIM_PATH_MAX], last[400];
	/* gnuplot ends a failure with `"NAME.gp" line N: what went wrong`,
	 * after the command and a caret under the place; what one that
	 * succeeded says are warnings, passed on. */
	bsim_program_log_line(log, 1, last, sizeof last);
	if (status == 0) {
		char prefix[200];
		snprintf(prefix, sizeof prefix, "gnuplot on %s.gp", d->name);
		bsim_program_log_notes(log, prefix);
	}
	why[0] = '\0';
	if (status != 0) {
		snprintf(why, n, "gnuplot %s %d%s%s",
		         status > 128 ? "was killed by signal" : "exited with status",
		         status > 128 ? status - 128 : status, last[0] ? ": " : "", last);
	} else {
		for (int i = 0; i < 2 && !why[0]; i++) {
			char cut[360];
			snprintf(from, sizeof from, "%s/%s.%s", d->dir, tmpbase, ext[i]);
			if (image_whole(from, d->name, ext[i], cut, sizeof cut) != 0)
				snprintf(why, n, "gnuplot exited with status 0 but %s", cut);
		}
	}
	for (int i = 0; i < 2 && !why[0]; i++) {
		snprintf(from, sizeof from, "%s/%s.%s", d->dir, tmpbase, ext[i]);
		snprintf(to, sizeof to, "%s/%s.%s", d->dir, d->name, ext[i]);
		if (rename(from, to) != 0)
			snprintf(why, n, "%s.%s: %s", d->name, ext[i], strerror(errno));
	}
	if (!why[0])
		return 0;
	for (int i = 0; i < 2; i++) {
		snprintf(from, sizeof from, "%s/%s.%s", d->dir, tmpbase, ext[i]);
		unlink(from);
	}
	return -1;
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
		*drawn = BSIM_FIGURE_UNDRAWN;
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
	FILE **logs = calloc(n > 0 ? (size_t)n : 1, sizeof *logs);
	if (!pids || !logs) {
		free(pids);
		free(logs);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	for (int i = 0; i < n; i++) {
		char tmpbase[256];
		snprintf(tmpbase, sizeof tmpbase, "%s.tmp.%ld", defs[i].name, (long)getpid());
		logs[i] = bsim_program_log_open();
		pids[i] = gnuplot_start(defs[i].dir, defs[i].name, tmpbase, logs[i]);
	}
	/* Every figure that failed is named with gnuplot's message, then the
	 * files that remain to look at and rerun it by hand. */
	char fails[BSIM_ERROR_MSG_MAX] = "", files[BSIM_ERROR_MSG_MAX] = "";
	const char *where = NULL;
	int n_failed = 0;
	for (int i = 0; i < n; i++) {
		bsim_figure_def d = def_resolve(&defs[i]);
		char tmpbase[256], why[480];
		snprintf(tmpbase, sizeof tmpbase, "%s.tmp.%ld", d.name, (long)getpid());
		int r = images_commit(&d, tmpbase, gnuplot_wait(pids[i]), logs[i], why, sizeof why);
		if (logs[i])
			fclose(logs[i]);
		if (r == 0)
			continue;
		size_t used = strlen(fails), f_used = strlen(files);
		snprintf(fails + used, sizeof fails - used, "%sfigure %s: %s", n_failed ? "; " : "",
		         d.name, why);
		snprintf(files + f_used, sizeof files - f_used, ", %s.gp", d.name);
		data_names(d.dir, bodies[i], files, sizeof files);
		where = where ? where : d.dir;
		n_failed++;
	}
	int rc = BSIM_OK;
	if (n_failed)
		rc = bsim_error_set(err, BSIM_EFAIL, "%s; %s and data are in %s: %s", fails,
		                    n_failed == 1 ? "its script" : "their scripts", where,
		                    files + 2);
	free(pids);
	free(logs);
	if (drawn)
		*drawn = rc == BSIM_OK ? BSIM_FIGURE_DRAWN : BSIM_FIGURE_FAILED;
	return rc;
}

int bsim_figure_render(const bsim_figure_def *def, const char *body, int *drawn, bsim_error *err)
{
	return bsim_figure_render_all(def, &body, 1, drawn, err);
}
