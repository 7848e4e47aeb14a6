/* The messages of a program beamsim starts (program_log.h). */
#define _POSIX_C_SOURCE 200809L
#include "util/program_log.h"

#include <fcntl.h>
#include <string.h>

#include "beamsim/error.h"

FILE *bsim_program_log_open(void)
{
	FILE *f = tmpfile();
	if (!f)
		return NULL;
	int flags = fcntl(fileno(f), F_GETFD);
	if (flags < 0 || fcntl(fileno(f), F_SETFD, flags | FD_CLOEXEC) != 0) {
		fclose(f);
		return NULL;
	}
	return f;
}

/* Calls each(user, line) for every line of log that is not empty, from
 * its start; a line longer than 511 bytes comes in pieces. */
static void each_line(FILE *log, int (*each)(void *user, const char *line), void *user)
{
	if (!log)
		return;
	char line[512];
	rewind(log);
	while (fgets(line, sizeof line, log)) {
		line[strcspn(line, "\r\n")] = '\0';
		if (line[0] && each(user, line) != 0)
			return;
	}
}

typedef struct line_pick {
	int last;
	char *buf;
	size_t n;
} line_pick;

static int pick(void *user, const char *line)
{
	line_pick *p = user;
	size_t len = strlen(line), m = len < p->n - 1 ? len : p->n - 1; /* cut to fit */
	memcpy(p->buf, line, m);
	p->buf[m] = '\0';
	return !p->last; /* the first: done */
}

void bsim_program_log_line(FILE *log, int last, char *buf, size_t n)
{
	if (n == 0)
		return;
	buf[0] = '\0';
	line_pick p = {last, buf, n};
	each_line(log, pick, &p);
}

static int note(void *user, const char *line)
{
	bsim_note("%s: %s", (const char *)user, line);
	return 0;
}

void bsim_program_log_notes(FILE *log, const char *prefix)
{
	each_line(log, note, (void *)prefix);
}
