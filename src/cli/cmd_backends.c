/* beamsim backends: each backend with its description and knobs. */
#include <getopt.h>
#include <stdio.h>
#include <string.h>

#include "beamsim/backend.h"
#include "cli_common.h"

static const char backends_help[] =
        "Usage: beamsim backends\n"
        "\n"
        "Lists the physics backends compiled in, with their options: name, type,\n"
        "default, choices and what each does. Set one with --backend-opt NAME=VALUE\n"
        "on run, sweep and bench.\n"
        "\n"
        "Options:\n"
        "  -h, --help             show this help\n";

static const struct option backends_options[] = {
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
};

static const char *knob_type_name(bsim_knob_type t)
{
	switch (t) {
	case BSIM_KNOB_INT:
		return "int";
	case BSIM_KNOB_DOUBLE:
		return "double";
	case BSIM_KNOB_CHOICE:
		return "choice";
	}
	return "?";
}

static int width_of(const bsim_backend *b, int col)
{
	static const char *const headings[] = {"option", "type", "default", "choices"};
	int w = (int)strlen(headings[col]);
	for (int i = 0; i < b->n_knobs; i++) {
		const bsim_knob *k = &b->knobs[i];
		const char *s = col == 0   ? k->name
		                : col == 1 ? knob_type_name(k->type)
		                : col == 2 ? k->default_value
		                           : k->choices;
		int len = s ? (int)strlen(s) : 1;
		w = len > w ? len : w;
	}
	return w;
}

static void backend_print(const bsim_backend *b)
{
	printf("%s\n  %s\n", b->name, b->description ? b->description : "");
	if (b->n_knobs == 0) {
		puts("  (no options)");
		return;
	}
	int w[4];
	for (int c = 0; c < 4; c++)
		w[c] = width_of(b, c);
	printf("\n  %-*s  %-*s  %-*s  %-*s  %s\n", w[0], "option", w[1], "type", w[2], "default",
	       w[3], "choices", "help");
	for (int i = 0; i < b->n_knobs; i++) {
		const bsim_knob *k = &b->knobs[i];
		printf("  %-*s  %-*s  %-*s  %-*s  %s\n", w[0], k->name, w[1],
		       knob_type_name(k->type), w[2], k->default_value ? k->default_value : "-",
		       w[3], k->choices ? k->choices : "-", k->help ? k->help : "");
	}
}

int cmd_backends(int argc, char **argv)
{
	int c;
	opterr = 0;
	while ((c = getopt_long(argc, argv, ":h", backends_options, NULL)) != -1) {
		if (c != 'h')
			return cli_bad_option("backends", argv, c);
		fputs(backends_help, stdout);
		return CLI_OK;
	}
	if (optind != argc)
		return cli_usage("backends", "unexpected argument %s", argv[optind]);
	const bsim_backend *const *all = bsim_backend_list();
	for (int i = 0; all[i]; i++) {
		if (i)
			putchar('\n');
		backend_print(all[i]);
	}
	return CLI_OK;
}
