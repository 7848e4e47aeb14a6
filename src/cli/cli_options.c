/* The shared options and the parser of every command; see cli_options.h. */
#define _POSIX_C_SOURCE 200809L

#include "cli/cli_options.h"

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct shared_def {
	const char *name;
	int has_arg;
	const char *arg;
	const char *help;
} shared_def;

static const shared_def shared[CLI_N_OPTS] = {
        [CLI_OPT_BACKEND] = {"backend", 1, "B",
                             "physics backend (default {default}; see beamsim backends)"},
        [CLI_OPT_BACKEND_OPT] = {"backend-opt", 1, "K=V",
                                 "a backend option, repeatable; B:K=V sets it on\n"
                                 "backend B (see beamsim backends --help)"},
        [CLI_OPT_THREADS] = {"threads", 1, "N", "worker threads (default: all cores)"},
        [CLI_OPT_TRIALS] = {"trials", 1, "N", "trials per group (default: the experiment's)"},
        [CLI_OPT_SEED] = {"seed", 1, "N", "experiment seed (default: the experiment's)"},
        [CLI_OPT_SET] = {"set", 1, "KEY=VALUE",
                         "override a scene field by dotted path, repeatable\n"
                         "(e.g. --set beams.0.stiffness=250: beams.0 is beam 1)"},
        [CLI_OPT_GRID] = {"grid", 1, "KEY=VALUES",
                          "vary a scene field over VALUES, repeatable: V1,V2,...\n"
                          "(numbers, or the field's words) or A:B:STEP (B\n"
                          "included); replaces the experiment's grid axis of\n"
                          "KEY, or adds one after its axes (e.g. --grid\n"
                          "beams.0.stiffness=100:500:100, --grid\n"
                          "effects.random_force.model=held,ou)"},
        [CLI_OPT_OUT] = {"out", 1, "DIR", "output directory, created if missing (required)"},
        [CLI_OPT_QUIET] = {"quiet", 0, NULL, "no progress line, nothing on stdout"},
        [CLI_OPT_LIMIT] = {"limit", 1, "NAME=N",
                           "raise a limit on what inputs may ask for: input_bytes,\n"
                           "groups, trials, schedule, beam_steps, mat_rows\n"
                           "(docs/robustness.md)"},
        [CLI_OPT_RESUME] = {"resume", 0, NULL, "continue the stopped run in DIR (same inputs)"},
        [CLI_OPT_OVERWRITE] = {"overwrite", 0, NULL,
                               "replace the finished result (or a stopped run's\n"
                               "journal) in DIR; without it such a DIR is refused"},
        [CLI_OPT_TRAJECTORIES] = {"trajectories", 1, "N",
                                  "keep the trajectories of the first N trials of each\n"
                                  "group in DIR/trajectories.csv (and .mat), for\n"
                                  "`beamsim plot DIR`"},
        [CLI_OPT_TRAJECTORY_STRIDE] = {"trajectory-stride", 1, "N",
                                       "a trajectory row every N steps (default 5)"},
        [CLI_OPT_ALPHA] = {"alpha", 1, "A", "family-wise error rate (default 0.05)"},
        [CLI_OPT_MARGIN] = {"margin", 1, "M", "smallest difference that counts (default 0.05)"},
};

cli_common cli_common_default(void)
{
	cli_common c;
	memset(&c, 0, sizeof c);
	return c;
}

void cli_common_free(cli_common *c)
{
	cli_sets_free(&c->sets);
}

/* The default backend's first choice knob set to a choice other than its
 * default, "integrator=euler": an example of an option; KEY=VALUE if it
 * has none. */
static void knob_example(char *buf, size_t size)
{
	const bsim_backend *b = bsim_backend_default();
	for (int i = 0; i < b->n_knobs; i++) {
		const bsim_knob *k = &b->knobs[i];
		if (k->type != BSIM_KNOB_CHOICE || !k->choices)
			continue;
		for (const char *c = k->choices; *c;) {
			size_t n = strcspn(c, "|");
			if (!k->default_value || strlen(k->default_value) != n ||
			    strncmp(c, k->default_value, n) != 0) {
				snprintf(buf, size, "%s=%.*s", k->name, (int)n, c);
				return;
			}
			c += n + (c[n] == '|');
		}
	}
	snprintf(buf, size, "KEY=VALUE");
}

/* Help text with the registry's names in place of its placeholders, so
 * that the help names the backends compiled in: {default} the default
 * backend, {pair} the first two of the default comparison ("A,B"),
 * {backends} every registered backend, {second} the second ("none" if
 * there is one backend), {knob} an option of the default backend. */
static void help_expand(const char *text, char *out, size_t size)
{
	static const char *const names[] = {"{default}", "{pair}", "{backends}", "{second}",
	                                    "{knob}"};
	size_t k = 0;
	out[0] = '\0';
	while (*text && k + 1 < size) {
		int which = -1;
		for (int i = 0; *text == '{' && i < 5 && which < 0; i++)
			if (strncmp(text, names[i], strlen(names[i])) == 0)
				which = i;
		if (which < 0) {
			out[k++] = *text++;
			out[k] = '\0';
			continue;
		}
		char value[256];
		const bsim_backend *b[2];
		switch (which) {
		case 0:
			snprintf(value, sizeof value, "%s", bsim_backend_default()->name);
			break;
		case 1:
			cli_backend_names(value, sizeof value, 2);
			break;
		case 2:
			cli_backend_names(value, sizeof value, 16);
			break;
		case 3:
			snprintf(value, sizeof value, "%s",
			         bsim_backend_compared(b, 2) == 2 ? b[1]->name : "none");
			break;
		default:
			knob_example(value, sizeof value);
		}
		snprintf(out + k, size - k, "%s", value);
		k += strlen(out + k);
		text += strlen(names[which]);
	}
}

/* "  --name ARG" padded to the help column, then the help, continuation
 * lines indented to it. */
static void help_line(FILE *f, const char *name, const char *arg, const char *text)
{
	char head[64], help[2048];
	snprintf(head, sizeof head, "--%s%s%s", name, arg ? " " : "", arg ? arg : "");
	help_expand(text, help, sizeof help);
	fprintf(f, "  %-22s ", head);
	for (const char *p = help; *p; p++) {
		fputc(*p, f);
		if (*p == '\n')
			fprintf(f, "%25s", "");
	}
	fputc('\n', f);
}

static void help_print(const cli_spec *spec)
{
	FILE *f = stdout;
	char text[8192];
	help_expand(spec->about, text, sizeof text);
	fprintf(f, "Usage: beamsim %s %s\n\n%s\nOptions:\n", spec->name, spec->usage, text);
	for (int o = 0; o < CLI_N_OPTS; o++) {
		if (!(spec->common & CLI_USES(o)))
			continue;
		const char *help = spec->help && spec->help[o] ? spec->help[o] : shared[o].help;
		const char *arg = o == CLI_OPT_OUT && spec->out_arg ? spec->out_arg : shared[o].arg;
		help_line(f, shared[o].name, arg, help);
	}
	for (int i = 0; i < spec->n_own; i++)
		help_line(f, spec->own[i].name, spec->own[i].arg, spec->own[i].help);
	fputs("  -h, --help             show this help\n", f);
	if (spec->after) {
		help_expand(spec->after, text, sizeof text);
		fprintf(f, "\n%s", text);
	}
}

/* One shared option's value into c. */
static int shared_take(const cli_spec *spec, cli_common *c, int o, const char *v)
{
	const char *cmd = spec->name;
	switch ((cli_opt)o) {
	case CLI_OPT_BACKEND:
		c->backend = v;
		return CLI_OK;
	case CLI_OPT_BACKEND_OPT:
		if (c->n_backend_opts == CLI_BACKEND_OPTS_MAX)
			return cli_usage(cmd, "--backend-opt %s: more than %d options", v,
			                 CLI_BACKEND_OPTS_MAX);
		c->backend_opt[c->n_backend_opts++] = v;
		return CLI_OK;
	case CLI_OPT_THREADS:
		if (cli_parse_long(v, 1, 4096, &c->threads) != 0)
			return cli_usage(cmd, "--threads %s: expected an integer >= 1", v);
		return CLI_OK;
	case CLI_OPT_TRIALS:
		if (cli_parse_long(v, 1, INT32_MAX, &c->trials) != 0)
			return cli_usage(cmd, "--trials %s: expected an integer >= 1", v);
		return CLI_OK;
	case CLI_OPT_SEED:
		c->has_seed = 1;
		if (cli_parse_u64(v, &c->seed) != 0)
			return cli_usage(cmd, "--seed %s: expected an integer >= 0", v);
		return CLI_OK;
	case CLI_OPT_SET:
		return cli_sets_add(&c->sets, cmd, v);
	case CLI_OPT_GRID:
		if (c->n_grid == CLI_GRID_MAX)
			return cli_usage(cmd, "--grid %s: more than %d axes", v, CLI_GRID_MAX);
		c->grid[c->n_grid++] = v;
		return CLI_OK;
	case CLI_OPT_OUT:
		c->out = v;
		return CLI_OK;
	case CLI_OPT_QUIET:
		c->quiet = 1;
		return CLI_OK;
	case CLI_OPT_LIMIT:
		return cli_limit(cmd, v);
	case CLI_OPT_RESUME:
		c->resume = 1;
		return CLI_OK;
	case CLI_OPT_OVERWRITE:
		c->overwrite = 1;
		return CLI_OK;
	case CLI_OPT_TRAJECTORIES:
		if (cli_parse_long(v, 0, INT32_MAX, &c->keep) != 0)
			return cli_usage(cmd, "--trajectories %s: expected an integer >= 0", v);
		return CLI_OK;
	case CLI_OPT_TRAJECTORY_STRIDE:
		if (cli_parse_long(v, 1, INT32_MAX, &c->keep_stride) != 0)
			return cli_usage(cmd, "--trajectory-stride %s: expected an integer >= 1",
			                 v);
		return CLI_OK;
	case CLI_OPT_ALPHA:
		c->has_alpha = 1;
		return cli_parse_fraction(cmd, "--alpha", v, 1, &c->alpha);
	case CLI_OPT_MARGIN:
		c->has_margin = 1;
		return cli_parse_fraction(cmd, "--margin", v, 0, &c->margin);
	case CLI_N_OPTS:
		break;
	}
	return CLI_USAGE;
}

#define CLI_OWN_MAX 32

int cli_parse(const cli_spec *spec, int argc, char **argv, cli_common *c, void *args,
              const char **pos)
{
	/* getopt_long's table: the shared options the command takes (val = the
	 * option, < CLI_N_OPTS), its own (val = 256 + index) and --help. */
	struct option table[CLI_N_OPTS + CLI_OWN_MAX + 2];
	const char *names[CLI_N_OPTS + CLI_OWN_MAX + 1];
	int n = 0;
	for (int o = 0; o < CLI_N_OPTS; o++)
		if (spec->common & CLI_USES(o)) {
			table[n] = (struct option){
			        shared[o].name, shared[o].has_arg ? required_argument : no_argument,
			        NULL, o};
			names[n++] = shared[o].name;
		}
	for (int i = 0; i < spec->n_own && i < CLI_OWN_MAX; i++) {
		table[n] = (struct option){spec->own[i].name,
		                           spec->own[i].has_arg ? required_argument : no_argument,
		                           NULL, 256 + i};
		names[n++] = spec->own[i].name;
	}
	table[n] = (struct option){"help", no_argument, NULL, 'h'};
	names[n] = "help";
	table[n + 1] = (struct option){NULL, 0, NULL, 0};
	int k;
	opterr = 0;
	optind = 1;
	while ((k = getopt_long(argc, argv, ":h", table, NULL)) != -1) {
		int rc;
		if (k == 'h') {
			help_print(spec);
			return CLI_OK;
		}
		if (k == '?' || k == ':')
			return cli_bad_option_near(spec->name, argv, k, names, n + 1);
		if (k >= 256)
			rc = spec->option(args, k - 256, optarg);
		else
			rc = shared_take(spec, c, k, optarg);
		if (rc != CLI_OK)
			return rc;
	}
	if (spec->positional) {
		if (optind + 1 != argc)
			return cli_usage(spec->name,
			                 optind == argc ? "missing %s" : "expected one %s, got %d",
			                 spec->positional, argc - optind);
		*pos = argv[optind];
	} else if (optind != argc) {
		return cli_usage(spec->name, "unexpected argument %s", argv[optind]);
	}
	for (int i = 0; i < c->n_grid; i++) {
		int rc = cli_grid_add(&c->sets, spec->name, c->grid[i]);
		if (rc != CLI_OK)
			return rc;
	}
	if (c->resume && c->overwrite)
		return cli_usage(spec->name,
		                 "--resume and --overwrite: expected one of them (--resume "
		                 "continues the stopped run in DIR, --overwrite replaces it)");
	if (spec->out_required && !c->out)
		return cli_usage(spec->name, "--out %s is required",
		                 spec->out_arg ? spec->out_arg : "DIR");
	/* DIR/.beamsim/staging/NAME/... must fit the path buffers. */
	if (c->out && strlen(c->out) > 900)
		return cli_usage(spec->name, "--out %s is longer than 900 characters",
		                 spec->out_arg ? spec->out_arg : "DIR");
	return -1;
}

int cli_backend_opts(const cli_common *c, const char *cmd, int n, const char *const *names,
                     bsim_options *const *opts)
{
	char list[256] = "";
	int distinct = 0;
	for (int i = 0; i < n; i++) {
		int seen = 0;
		for (int k = 0; k < i; k++)
			seen |= strcmp(names[k], names[i]) == 0;
		if (!seen)
			snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s",
			         distinct++ ? ", " : "", names[i]);
	}
	for (int o = 0; o < c->n_backend_opts; o++) {
		const char *t = c->backend_opt[o];
		/* A colon counts only before the first '=': B:K=V, not K=V:W. */
		size_t len = strcspn(t, ":=");
		int prefixed = t[len] == ':', used = 0;
		if (!prefixed && distinct > 1)
			return cli_usage(cmd,
			                 "--backend-opt %s: expected B:KEY=VALUE with several "
			                 "backends (B one of %s)",
			                 t, list);
		for (int i = 0; i < n; i++) {
			if (prefixed && (strlen(names[i]) != len || strncmp(t, names[i], len) != 0))
				continue;
			int rc = cli_options_add(opts[i], cmd, prefixed ? t + len + 1 : t);
			if (rc != CLI_OK)
				return rc;
			used = 1;
		}
		if (!used)
			return cli_usage(
			        cmd,
			        "--backend-opt %s: expected B:KEY=VALUE with B %s%s (%.*s is "
			        "not a backend this command runs)",
			        t, distinct > 1 ? "one of " : "", list, (int)len, t);
	}
	return CLI_OK;
}

const bsim_backend *cli_backend_with_opts(const cli_common *c, const char *cmd, const char *spec,
                                          bsim_options *opts)
{
	memset(opts, 0, sizeof *opts);
	size_t n = bsim_backend_spec_name(spec);
	char name[1024];
	if (n >= sizeof name) {
		cli_usage(cmd, "--backend %s: a name longer than %zu characters", spec,
		          sizeof name - 1);
		return NULL;
	}
	snprintf(name, sizeof name, "%.*s", (int)n, spec);
	bsim_error err;
	const bsim_backend *b = bsim_backend_find(name, &err);
	if (!b) {
		cli_error("%s", err.msg);
		return NULL;
	}
	/* --backend-opt B:K=V names the backend by its own name (a plug-in's,
	 * not its path) */
	const char *own = b->name;
	if (cli_backend_opts(c, cmd, 1, &own, &opts) != CLI_OK)
		return NULL;
	if (bsim_backend_spec_options(spec, opts, &err) != BSIM_OK) {
		cli_usage(cmd, "%s", err.msg);
		return NULL;
	}
	if (bsim_options_check(opts, b->knobs, b->n_knobs, b->name, &err) != BSIM_OK) {
		if (spec[n]) /* the spec's own options */
			cli_error("--backend %s: %s", spec, err.msg);
		else
			cli_error("%s", err.msg);
		return NULL;
	}
	return b;
}
