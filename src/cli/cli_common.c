/* Shared parts of the beamsim subcommands; see cli_common.h. */
#define _POSIX_C_SOURCE 200809L

#include "cli/cli_common.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <getopt.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/limits.h"
#include "cli/cli_progress.h"
#include "util/decimal.h"
#include "util/text_check.h"

void cli_error(const char *fmt, ...)
{
	va_list ap;
	bsim_error e;
	char msg[BSIM_ERROR_MSG_MAX];
	va_start(ap, fmt);
	vsnprintf(msg, sizeof msg, fmt, ap);
	va_end(ap);
	/* The library's escaping of what the message quotes. */
	bsim_error_set(&e, BSIM_EFAIL, "%s", msg);
	fprintf(stderr, "beamsim: %s\n", e.msg);
}

int cli_usage(const char *cmd, const char *fmt, ...)
{
	va_list ap;
	bsim_error e;
	char msg[BSIM_ERROR_MSG_MAX];
	va_start(ap, fmt);
	vsnprintf(msg, sizeof msg, fmt, ap);
	va_end(ap);
	bsim_error_set(&e, BSIM_EINPUT, "%s", msg); /* escapes what it quotes */
	fprintf(stderr, "beamsim: %s: %s\nTry 'beamsim %s --help'.\n", cmd, e.msg, cmd);
	return CLI_USAGE;
}

/* Levenshtein distance of a and b, at most 64 characters of b counted. */
static int edit_distance(const char *a, const char *b)
{
	int row[65], lb = (int)strlen(b);
	lb = lb > 64 ? 64 : lb;
	for (int j = 0; j <= lb; j++)
		row[j] = j;
	for (int i = 1; a[i - 1]; i++) {
		int diag = row[0];
		row[0] = i;
		for (int j = 1; j <= lb; j++) {
			int up = row[j];
			int sub = diag + (a[i - 1] != b[j - 1]);
			int del = row[j] + 1, ins = row[j - 1] + 1;
			row[j] = sub < del ? (sub < ins ? sub : ins) : (del < ins ? del : ins);
			diag = up;
		}
	}
	return row[lb];
}

const char *cli_nearest(const char *word, const char *const *names, int n)
{
	const char *best = NULL;
	int best_d = 0, ties = 0, len = (int)strlen(word);
	if (len == 0 || len > 64)
		return NULL;
	for (int i = 0; i < n; i++) {
		int d = edit_distance(word, names[i]);
		if (!best || d < best_d) {
			best = names[i];
			best_d = d;
			ties = 0;
		} else if (d == best_d) {
			ties++;
		}
	}
	int limit = len / 3 > 1 ? len / 3 : 1;
	return best && best_d <= limit && !ties ? best : NULL;
}

int cli_bad_option_near(const char *cmd, char **argv, int c, const char *const *names, int n)
{
	/* With opterr = 0 the offending option is the argument just consumed;
	 * optopt is 0 for an unknown long option, else the option's value. */
	const char *arg = optind > 0 ? argv[optind - 1] : "?";
	int name_len = (int)strcspn(arg, "=");
	if (c == ':')
		return cli_usage(cmd, "option %s needs a value", arg);
	if (strncmp(arg, "--", 2) != 0)
		return cli_usage(cmd, "unknown option -%c", optopt);
	if (optopt != 0)
		return cli_usage(cmd, "option %.*s takes no value", name_len, arg);
	char word[80];
	snprintf(word, sizeof word, "%.*s", name_len - 2 > 0 ? name_len - 2 : 0, arg + 2);
	const char *near = names ? cli_nearest(word, names, n) : NULL;
	if (near)
		return cli_usage(cmd, "unknown option %.*s (did you mean --%s?)", name_len, arg,
		                 near);
	return cli_usage(cmd, "unknown option %.*s", name_len, arg);
}

int cli_bad_option(const char *cmd, char **argv, int c)
{
	return cli_bad_option_near(cmd, argv, c, NULL, 0);
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

int cli_parse_fraction(const char *cmd, const char *opt, const char *text, int open, double *out)
{
	char *end;
	double x = strtod(text, &end);
	int inside = open ? x > 0.0 && x < 1.0 : x >= 0.0 && x <= 1.0;
	if (end == text || *end || !inside)
		return cli_usage(cmd, "%s %s: expected a number in %s", opt, text,
		                 open ? "(0, 1)" : "[0, 1]");
	*out = x;
	return CLI_OK;
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
	for (int a = 0; a < s->n_grid; a++)
		bsim_experiment_axis_free(&s->grid[a]);
	free(s->grid);
	memset(s, 0, sizeof *s);
}

/* t without the spaces around it, into buf (size > strlen(t)). */
static const char *trimmed(const char *t, size_t len, char *buf)
{
	while (len && *t == ' ')
		t++, len--;
	while (len && t[len - 1] == ' ')
		len--;
	memcpy(buf, t, len);
	buf[len] = '\0';
	return buf;
}

/* 1 if t is a finite decimal number, all of it. */
static int grid_number(const char *t, double *x)
{
	char *end;
	if (!*t || bsim_decimal_other_base(t) || isspace((unsigned char)*t))
		return 0;
	*x = strtod(t, &end);
	return *end == '\0' && isfinite(*x);
}

#define GRID_EXPECTED "KEY=V1,V2,... or KEY=A:B:STEP"

/* The values of "V1,V2,..." into a (values only), as written: numbers, or
 * words for a key whose values are words (effects.random_force.model=
 * held,ou). Each is judged where an experiment file's grid values are, by
 * the scene loader for its key (bsim_experiment_load_grid), which names
 * the value "--grid KEY=VALUE" and what the key takes. */
static int grid_list(bsim_grid_axis *a, const char *cmd, const char *text, const char *list,
                     char *buf)
{
	int n = 1;
	for (const char *p = list; *p; p++)
		n += *p == ',';
	double limit = bsim_limits_get()->groups;
	if (n > limit) {
		char hint[160];
		bsim_limits_hint(hint, sizeof hint, "groups", limit);
		return cli_usage(cmd, "--grid %s: expected at most %.15g values (%s), got %d", text,
		                 limit, hint, n);
	}
	a->values = calloc((size_t)n, sizeof *a->values);
	if (!a->values)
		return CLI_FAIL;
	for (const char *p = list;; p++) {
		size_t len = strcspn(p, ",");
		trimmed(p, len, buf);
		if (!buf[0])
			return cli_usage(cmd,
			                 "--grid %s: expected a non-empty list of values "
			                 "(" GRID_EXPECTED "), got an empty value",
			                 text);
		if (!(a->values[a->n_values++] = strdup(buf)))
			return CLI_FAIL;
		p += len;
		if (!*p)
			return CLI_OK;
	}
}

/* The values of "A:B:STEP" into a (values only). */
static int grid_range(bsim_grid_axis *a, const char *cmd, const char *text, const char *range,
                      char *buf)
{
	char part[3][128];
	double x[3];
	const char *p = range;
	for (int k = 0; k < 3; k++) {
		size_t len = strcspn(p, ":");
		if ((k < 2) != (p[len] == ':') || len >= sizeof part[k])
			return cli_usage(cmd, "--grid %s: expected A:B:STEP, three numbers", text);
		trimmed(p, len, part[k]);
		if (!grid_number(part[k], &x[k]))
			return cli_usage(cmd,
			                 "--grid %s: expected A:B:STEP, three decimal numbers, got "
			                 "\"%s\"",
			                 text, part[k]);
		p += len + 1;
	}
	if (x[2] == 0)
		return cli_usage(cmd, "--grid %s: expected a STEP other than 0 in A:B:STEP", text);
	double steps = (x[1] - x[0]) / x[2];
	if (steps < 0)
		return cli_usage(cmd,
		                 "--grid %s: expected a STEP of the sign of B - A in A:B:STEP (%s "
		                 "to %s is %s)",
		                 text, part[0], part[1], x[1] >= x[0] ? "upwards" : "downwards");
	/* B counts when it is reached within 1e-9 of a STEP. */
	double n = floor(steps + 1e-9) + 1, limit = bsim_limits_get()->groups;
	if (!(n <= limit)) {
		char hint[160];
		bsim_limits_hint(hint, sizeof hint, "groups", limit);
		return cli_usage(cmd, "--grid %s: expected at most %.15g values (%s), got %.15g",
		                 text, limit, hint, n);
	}
	a->values = calloc((size_t)n, sizeof *a->values);
	if (!a->values)
		return CLI_FAIL;
	for (long i = 0; i < (long)n; i++) {
		if (bsim_decimal_step(part[0], part[2], i, buf, 128) != 0)
			snprintf(buf, 128, "%.17g", x[0] + (double)i * x[2]);
		if (!(a->values[a->n_values++] = strdup(buf)))
			return CLI_FAIL;
	}
	return CLI_OK;
}

int cli_grid_add(cli_sets *s, const char *cmd, const char *text)
{
	const char *eq = strchr(text, '=');
	size_t n = strlen(text);
	char *buf = malloc(n + 128);
	if (!buf) {
		cli_error("out of memory");
		return CLI_FAIL;
	}
	if (!eq || !trimmed(text, (size_t)(eq - text), buf)[0]) {
		free(buf);
		return cli_usage(cmd,
		                 "--grid %s: expected " GRID_EXPECTED
		                 ", e.g. --grid beams.0.stiffness=100,200 or "
		                 "--grid effects.propulsion.force=7:9:0.5",
		                 text);
	}
	bsim_grid_axis a = {.key = strdup(buf)};
	int rc = a.key ? CLI_OK : CLI_FAIL;
	if (rc == CLI_OK)
		rc = strchr(eq + 1, ':') ? grid_range(&a, cmd, text, eq + 1, buf)
		                         : grid_list(&a, cmd, text, eq + 1, buf);
	/* One origin for the axis, "--grid KEY": a value's is made from it
	 * when a message names it ("--grid KEY=VALUE"). */
	if (rc == CLI_OK) {
		snprintf(buf, n + 128, "--grid %s", a.key);
		if (!(a.origin = strdup(buf)))
			rc = CLI_FAIL;
	}
	free(buf);
	int at = 0;
	while (rc == CLI_OK && at < s->n_grid && strcmp(s->grid[at].key, a.key) != 0)
		at++;
	if (rc == CLI_OK && at == s->n_grid) {
		bsim_grid_axis *g = realloc(s->grid, (size_t)(at + 1) * sizeof *g);
		if (!g) {
			rc = CLI_FAIL;
		} else {
			s->grid = g;
			memset(&s->grid[s->n_grid++], 0, sizeof *g);
		}
	}
	if (rc != CLI_OK) {
		if (rc == CLI_FAIL)
			cli_error("out of memory");
		bsim_experiment_axis_free(&a);
		return rc;
	}
	bsim_experiment_axis_free(&s->grid[at]);
	s->grid[at] = a;
	return CLI_OK;
}

int cli_limit(const char *cmd, const char *text)
{
	bsim_limits l = *bsim_limits_get();
	bsim_error err;
	if (bsim_limits_parse(&l, text, &err) != BSIM_OK)
		return cli_usage(cmd, "%s", err.msg);
	bsim_limits_set(&l);
	return CLI_OK;
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

int cli_report(int rc, const bsim_error *err)
{
	if (rc != BSIM_OK)
		cli_error("%s", err->msg);
	return rc;
}

int cli_experiment_load(const char *path, const cli_sets *sets, const uint64_t *seed, long trials,
                        bsim_experiment *e)
{
	bsim_error err;
	const bsim_override *ov = sets ? sets->ov : NULL;
	if (bsim_experiment_load_seeded(path, ov, sets ? sets->n : 0, sets ? sets->grid : NULL,
	                                sets ? sets->n_grid : 0, seed, e, &err) != BSIM_OK) {
		cli_error("%s", err.msg);
		return err.code ? err.code : CLI_USAGE;
	}
	if (trials > 0 && bsim_experiment_check_trials(e, trials, &err) != BSIM_OK) {
		cli_error("--trials %ld: %s", trials, err.msg);
		bsim_experiment_free(e);
		return CLI_USAGE;
	}
	if (trials > 0)
		e->trials = (int)trials;
	return CLI_OK;
}

/* The progress state lives here, for exactly the length of the run, so
 * callers cannot leave cfg pointing at it. */
int cli_sweep_run(const bsim_experiment *e, const bsim_sweep_config *cfg, int show_progress,
                  bsim_sweep_result *r)
{
	cli_progress progress;
	bsim_sweep_config c = *cfg;
	bsim_error err;
	cli_progress_init(&progress, show_progress, "trials");
	c.progress = cli_progress_update;
	c.progress_user = &progress;
	int rc = bsim_sweep_run(e, &c, r, &err);
	cli_progress_finish(&progress);
	return cli_report(rc, &err);
}

/* ---- signals and the line that resumes a run ---------------------------- */

volatile sig_atomic_t cli_stop;
const char *cli_program = "beamsim";

static void on_signal(int sig)
{
	if (cli_stop) {
		signal(sig, SIG_DFL);
		raise(sig);
		return;
	}
	cli_stop = sig;
}

void cli_signals_install(void)
{
	struct sigaction sa;
	memset(&sa, 0, sizeof sa);
	sa.sa_handler = on_signal;
	sigemptyset(&sa.sa_mask);
	sa.sa_flags = SA_RESTART;
	cli_stop = 0;
	sigaction(SIGINT, &sa, NULL);
	sigaction(SIGTERM, &sa, NULL);
}

void cli_signals_restore(void)
{
	signal(SIGINT, SIG_DFL);
	signal(SIGTERM, SIG_DFL);
}

/* "build/beamsim sweep ... --resume": the command line that continues the
 * run, starting with the program as it was invoked. */
static void resume_line(FILE *f, int argc, char **argv)
{
	int has = 0;
	bsim_text_shell_word(f, cli_program);
	for (int i = 0; i < argc; i++) {
		fputc(' ', f);
		bsim_text_shell_word(f, argv[i]);
		has |= strcmp(argv[i], "--resume") == 0;
	}
	if (!has)
		fputs(" --resume", f);
}

int cli_run_end(int rc, const char *journal, int argc, char **argv)
{
	if (rc == BSIM_ESTOPPED) {
		int sig = cli_stop ? (int)cli_stop : SIGINT;
		fprintf(stderr, "beamsim: %s: the finished trials are kept in %s; to continue: ",
		        sig == SIGTERM ? "SIGTERM" : "SIGINT", cli_path(journal));
		resume_line(stderr, argc, argv);
		fputc('\n', stderr);
		return 128 + sig;
	}
	if (rc != BSIM_OK && journal[0]) {
		fprintf(stderr,
		        "beamsim: the finished trials are kept in %s; to continue once the "
		        "cause is fixed: ",
		        cli_path(journal));
		resume_line(stderr, argc, argv);
		fputc('\n', stderr);
	}
	return rc;
}

void cli_solver_warning(const char *backend, const bsim_solver_counts *c, const char *where)
{
	char what[160] = "";
	if (c->iteration_limit > 0)
		snprintf(what, sizeof what, "stopped at an iteration limit %ld time%s",
		         c->iteration_limit, c->iteration_limit == 1 ? "" : "s");
	if (c->clamped > 0)
		snprintf(what + strlen(what), sizeof what - strlen(what),
		         "%sclamped the motion to its per-step limits in %ld (sub)step%s",
		         what[0] ? " and " : "", c->clamped, c->clamped == 1 ? "" : "s");
	if (what[0])
		cli_error("warning: the %s backend's solver %s (%s: solver%s); there the motion is "
		          "the solver's limit, not the model's",
		          backend, what, where,
		          strstr(where, "summary.json")
		                  ? "; per trial, trials.csv: iteration_limits, clamps"
		                  : "");
}

void cli_estimate_line(const bsim_backend *b, double beam_steps)
{
	double ns = b->cost_ns_per_beam_step;
	double hours = beam_steps * ns * 1e-9 / 3600.0;
	if (hours > 1.0)
		cli_error(
		        "note: this run may take up to about %.3g hours of one core: at most %.3g "
		        "beam-steps (trials x max_steps x beams) at a stated constant of ~%g ns a "
		        "beam-step on %s (%s)",
		        hours, beam_steps, ns, b->name, b->cost_basis ? b->cost_basis : "");
}

void cli_estimate_sides(void *user, double beam_steps)
{
	const cli_estimate *e = user;
	cli_estimate_line(e->costlier, e->n_run * beam_steps);
}

void cli_backend_names(char *buf, size_t size, int max)
{
	const bsim_backend *b[16];
	int n = bsim_backend_compared(b, max < 16 ? max : 16);
	size_t k = 0;
	if (size > 0)
		buf[0] = '\0';
	for (int i = 0; i < n && k < size; i++)
		k += (size_t)snprintf(buf + k, size - k, "%s%s", i ? "," : "", b[i]->name);
}

const char *cli_path(const char *path)
{
	/* Room for every byte of the longest path as \xNN. */
	static char ring[4][4 * BSIM_PATH_MAX + 1];
	static int next;
	char *b = ring[next++ % 4];
	snprintf(b, sizeof ring[0], "%s", path);
	bsim_text_escape(b, sizeof ring[0]);
	return b;
}

char *cli_text_append(char *text, const char *more)
{
	size_t n = strlen(text), m = strlen(more);
	char *t = realloc(text, n + m + 1);
	if (!t) {
		free(text);
		return NULL;
	}
	memcpy(t + n, more, m + 1);
	return t;
}

double cli_per_second(double count, double wall)
{
	return count / (wall > 0 ? wall : 1e-9);
}
