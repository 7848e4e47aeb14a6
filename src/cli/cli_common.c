/* Shared parts of the beamsim subcommands; see cli_common.h. */
#define _POSIX_C_SOURCE 200809L

#include "cli_common.h"

#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

void cli_error(const char *fmt, ...)
{
	va_list ap;
	fputs("beamsim: ", stderr);
	va_start(ap, fmt);
	vfprintf(stderr, fmt, ap);
	va_end(ap);
	fputc('\n', stderr);
}

int cli_usage(const char *cmd, const char *fmt, ...)
{
	va_list ap;
	fprintf(stderr, "beamsim: %s: ", cmd);
	va_start(ap, fmt);
	vfprintf(stderr, fmt, ap);
	va_end(ap);
	fprintf(stderr, "\nTry 'beamsim %s --help'.\n", cmd);
	return CLI_USAGE;
}

int cli_bad_option(const char *cmd, char **argv, int c)
{
	/* With opterr = 0 the offending option is the argument just consumed;
	 * optopt is 0 for an unknown long option, else the option's value. */
	const char *arg = optind > 0 ? argv[optind - 1] : "?";
	int name_len = (int)strcspn(arg, "=");
	if (c == ':')
		return cli_usage(cmd, "option %s needs a value", arg);
	if (strncmp(arg, "--", 2) != 0)
		return cli_usage(cmd, "unknown option -%c", optopt);
	if (optopt == 0)
		return cli_usage(cmd, "unknown option %.*s", name_len, arg);
	return cli_usage(cmd, "option %.*s takes no value", name_len, arg);
}

int cli_parse_long(const char *text, long min, long max, long *out)
{
	char *end;
	errno = 0;
	long v = strtol(text, &end, 10);
	if (errno || end == text || *end != '\0' || v < min || v > max)
		return -1;
	*out = v;
	return 0;
}

int cli_parse_u64(const char *text, uint64_t *out)
{
	char *end;
	/* strtoull accepts "-1" as 2^64 - 1; a seed is never negative. */
	if (strchr(text, '-'))
		return -1;
	errno = 0;
	unsigned long long v = strtoull(text, &end, 10);
	if (errno || end == text || *end != '\0')
		return -1;
	*out = (uint64_t)v;
	return 0;
}

static char *dup_range(const char *s, size_t n)
{
	char *d = malloc(n + 1);
	if (d) {
		memcpy(d, s, n);
		d[n] = '\0';
	}
	return d;
}

int cli_sets_add(cli_sets *s, const char *cmd, const char *kv)
{
	const char *eq = strchr(kv, '=');
	if (!eq || eq == kv)
		return cli_usage(cmd,
		                 "--set %s: expected KEY=VALUE, e.g. "
		                 "--set effects.propulsion.force=7",
		                 kv);
	if (s->n == s->cap) {
		int cap = s->cap ? 2 * s->cap : 8;
		bsim_override *ov = realloc(s->ov, (size_t)cap * sizeof *ov);
		if (!ov) {
			cli_error("out of memory");
			return CLI_FAIL;
		}
		s->ov = ov;
		s->cap = cap;
	}
	size_t n = strlen(kv);
	char *origin = malloc(n + sizeof "--set ");
	char *key = dup_range(kv, (size_t)(eq - kv));
	char *value = dup_range(eq + 1, strlen(eq + 1));
	if (!origin || !key || !value) {
		free(origin);
		free(key);
		free(value);
		cli_error("out of memory");
		return CLI_FAIL;
	}
	snprintf(origin, n + sizeof "--set ", "--set %s", kv);
	s->ov[s->n++] = (bsim_override){.key = key, .value = value, .origin = origin};
	return CLI_OK;
}

void cli_sets_free(cli_sets *s)
{
	for (int i = 0; i < s->n; i++) {
		free((char *)s->ov[i].key);
		free((char *)s->ov[i].value);
		free((char *)s->ov[i].origin);
	}
	free(s->ov);
	memset(s, 0, sizeof *s);
}

int cli_options_add(bsim_options *opts, const char *cmd, const char *kv)
{
	bsim_error err;
	if (bsim_options_add(opts, kv, &err) != BSIM_OK)
		return cli_usage(cmd, "%s", err.msg);
	return CLI_OK;
}

const bsim_backend *cli_backend(const char *name, const bsim_options *opts)
{
	bsim_error err;
	const bsim_backend *b = bsim_backend_find(name, &err);
	if (b && bsim_options_check(opts, b->knobs, b->n_knobs, b->name, &err) == BSIM_OK)
		return b;
	cli_error("%s", err.msg);
	return NULL;
}

void cli_json_string(FILE *f, const char *s)
{
	fputc('"', f);
	for (const unsigned char *p = (const unsigned char *)s; *p; p++) {
		if (*p == '"' || *p == '\\')
			fprintf(f, "\\%c", *p);
		else if (*p == '\n')
			fputs("\\n", f);
		else if (*p == '\t')
			fputs("\\t", f);
		else if (*p < 0x20)
			fprintf(f, "\\u%04x", *p);
		else
			fputc(*p, f);
	}
	fputc('"', f);
}

void cli_json_double(FILE *f, double x)
{
	char buf[32];
	if (!isfinite(x)) {
		fputs("null", f);
		return;
	}
	/* The shortest %.Ng that reads back as x. */
	for (int prec = 15; prec <= 17; prec++) {
		snprintf(buf, sizeof buf, "%.*g", prec, x);
		if (strtod(buf, NULL) == x)
			break;
	}
	fputs(buf, f);
}

void cli_json_options(FILE *f, const bsim_backend *b, const bsim_options *opts)
{
	fputc('{', f);
	for (int i = 0; i < b->n_knobs; i++) {
		const char *v = bsim_options_get(opts, b->knobs[i].name);
		if (!v)
			v = b->knobs[i].default_value ? b->knobs[i].default_value : "";
		fputs(i ? ", " : "", f);
		cli_json_string(f, b->knobs[i].name);
		fputs(": ", f);
		cli_json_string(f, v);
	}
	fputc('}', f);
}

int cli_file_open(cli_file *o, const char *path)
{
	o->path = path;
	o->f = NULL;
	int n = snprintf(o->tmp, sizeof o->tmp, "%s.tmp.%ld", path, (long)getpid());
	if (n < 0 || (size_t)n >= sizeof o->tmp) {
		cli_error("%s: path too long", path);
		return CLI_FAIL;
	}
	o->f = fopen(o->tmp, "w");
	if (!o->f) {
		cli_error("%s: cannot write: %s", o->tmp, strerror(errno));
		return CLI_FAIL;
	}
	return CLI_OK;
}

int cli_file_commit(cli_file *o)
{
	int bad = ferror(o->f) || fflush(o->f) != 0 || fsync(fileno(o->f)) != 0;
	int saved = errno;
	bad |= fclose(o->f) != 0;
	o->f = NULL;
	if (!bad && rename(o->tmp, o->path) == 0)
		return CLI_OK;
	if (!bad)
		saved = errno;
	unlink(o->tmp);
	cli_error("%s: write failed: %s", o->path, strerror(saved));
	return CLI_FAIL;
}

void cli_file_abort(cli_file *o)
{
	if (o->f) {
		fclose(o->f);
		o->f = NULL;
		unlink(o->tmp);
	}
}

double cli_now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
