/* beamsim backends: each backend with its description and knobs. */
#include <stdio.h>
#include <string.h>

#include "beamsim/backend.h"
#include "cli/cli_common.h"
#include "cli/cli_options.h"

static const cli_spec backends_spec = {
        .name = "backends",
        .usage = "[OPTIONS]",
        .about = "Lists the physics backends compiled in, with their options: name, type,\n"
                 "default, choices and what each does.\n"
                 "\n"
                 "An option is set the same way on every command that runs backends (run,\n"
                 "sweep, compare, video, bench):\n"
                 "  --backend-opt B:KEY=VALUE   sets KEY on backend B; a B the command does\n"
                 "                              not run is an error\n"
                 "  --backend-opt KEY=VALUE     the same, when the command runs one backend\n"
                 "and compare's sides also take options inline, NAME:KEY=VALUE[:KEY=VALUE]...\n"
                 "(--backends thesis,thesis:integrator=euler), which win over --backend-opt.\n"
                 "(bench's --vs backend takes --vs-opt KEY=VALUE.)\n"
                 "Values are checked against the backend's knob: its type, range or choices.\n",
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
	if (b->n_accuracy > 0)
		printf("\n  beamsim accuracy compares %d settings (the first is the reference):\n",
		       b->n_accuracy);
	for (int i = 0; i < b->n_accuracy; i++)
		printf("    %-24s %s\n", b->accuracy[i].name, b->accuracy[i].options);
}

int cmd_backends(int argc, char **argv)
{
	cli_common c = cli_common_default();
	int rc = cli_parse(&backends_spec, argc, argv, &c, NULL, NULL);
	if (rc >= 0)
		return rc;
	const bsim_backend *const *all = bsim_backend_list();
	for (int i = 0; all[i]; i++) {
		if (i)
			putchar('\n');
		backend_print(all[i]);
	}
	return CLI_OK;
}
