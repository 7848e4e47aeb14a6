/* beamsim backends: each backend of the registry with its description, what
 * it is built on, its knobs and the bounds it holds itself to. */
#include <stdio.h>
#include <string.h>

#include "beamsim/backend.h"
#include "beamsim/backend_plugin.h"
#include "cli/cli_common.h"
#include "cli/cli_options.h"

static const cli_spec backends_spec = {
        .name = "backends",
        .usage = "[OPTIONS]",
        .about = "Lists the physics backends compiled in, the default first, then the\n"
                 "plug-ins loaded from BEAMSIM_PLUGINS: what each is built on (and a\n"
                 "plug-in's library), its options (name, type, default, choices and what\n"
                 "each does) and the bounds it holds itself to in the checks every backend\n"
                 "runs (docs/tests.md, \"Every backend\").\n"
                 "\n"
                 "A backend of one's own (docs/backends.md, \"Your own solver\"): a shared\n"
                 "library exporting a backend table (beamsim/backend_plugin.h), run by any\n"
                 "command as --backend plugin:PATH[:KEY=VALUE]... (a compare side\n"
                 "likewise), or by its name when BEAMSIM_PLUGINS lists PATH (several\n"
                 "separated by ':').\n"
                 "\n"
                 "An option is set the same way on every command that runs backends (run,\n"
                 "sweep, compare, video, bench):\n"
                 "  --backend-opt B:KEY=VALUE   sets KEY on backend B; a B the command does\n"
                 "                              not run is an error\n"
                 "  --backend-opt KEY=VALUE     the same, when the command runs one backend\n"
                 "and compare's sides also take options inline, NAME:KEY=VALUE[:KEY=VALUE]...\n"
                 "(--backends {default},{default}:{knob}), which win over --backend-opt.\n"
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

/* The bounds b states (bsim_backend.bounds), a line each. */
static void bounds_print(const bsim_backend *b)
{
	if (b->n_bounds == 0) {
		puts("\n  states no bounds: the checks that need one skip it");
		return;
	}
	int w = 0;
	for (int i = 0; i < b->n_bounds; i++)
		w = (int)strlen(b->bounds[i].check) > w ? (int)strlen(b->bounds[i].check) : w;
	printf("\n  bounds in the checks every backend runs (%d):\n", b->n_bounds);
	for (int i = 0; i < b->n_bounds; i++)
		printf("    %-*s  %-7g  %s\n", w, b->bounds[i].check, b->bounds[i].bound,
		       b->bounds[i].basis ? b->bounds[i].basis : "");
}

static void backend_print(const bsim_backend *b)
{
	printf("%s\n  %s\n", b->name, b->description ? b->description : "");
	if (b->engine)
		printf("  built on %s %s\n", b->engine, b->version ? b->version : "");
	const char *lib = bsim_backend_plugin_path(b);
	if (lib)
		printf("  plug-in %s\n", lib);
	if (b->n_knobs == 0) {
		puts("  (no options)");
		bounds_print(b);
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
	bounds_print(b);
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
