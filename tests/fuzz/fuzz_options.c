/* Fuzz target: the command line's option values. The first input byte
 * chooses an option, the rest (up to a NUL, as argv would end it) is its
 * value:
 *   - each option the commands share (cli_options.c: --backend,
 *     --backend-opt, --threads, --trials, --seed, --set, --out, --limit,
 *     --trajectories, --trajectory-stride, --alpha, --margin), parsed by
 *     cli_parse as every command parses it; --backend-opt values are then
 *     resolved for one backend (checked against its knobs) and for two
 *     (B:K=V), as the commands resolve them;
 *   - the commands' own options with a value of their own syntax: video
 *     --size and --backends, markov build --bins, landscape --region,
 *     plot --select, through the command itself with an unknown option
 *     after the value, so that the command stops with a usage error
 *     (status 2) once the value is parsed and never runs;
 *   - compare's --backends sides (bsim_compare_side_parse, each side of
 *     A,B: a backend with inline options, NAME:K=V:...).
 * Every outcome must be "go on" or a usage error (status 2); a --limit the
 * parser accepts is undone after each input. */
#include "fuzz_common.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/compare_dir.h"
#include "beamsim/limits.h"
#include "cli/cli_options.h"

/* The shared options that take a value, by their command-line names. */
static const char *const shared[] = {
        "backend", "backend-opt",  "threads",           "trials", "seed",   "set", "out",
        "limit",   "trajectories", "trajectory-stride", "alpha",  "margin",
};
#define N_SHARED (int)(sizeof shared / sizeof shared[0])

/* A command's own option: the command, its subcommand if any, the option. */
static const struct {
	cli_command_fn fn;
	const char *cmd, *sub, *opt;
} own[] = {
        {cmd_video, "video", NULL, "--size"},      {cmd_video, "video", NULL, "--backends"},
        {cmd_markov, "markov", "build", "--bins"}, {cmd_landscape, "landscape", NULL, "--region"},
        {cmd_plot, "plot", NULL, "--select"},
};
#define N_OWN (int)(sizeof own / sizeof own[0])

static int no_option(void *args, int i, const char *value)
{
	(void)args;
	(void)i;
	(void)value;
	return CLI_USAGE;
}

static void expect(int ok, const char *what, const char *value, int rc)
{
	if (ok)
		return;
	fprintf(stderr, "fuzz: %s \"%s\": unexpected status %d\n", what, value, rc);
	abort();
}

static void shared_option(int o, char *value)
{
	static const cli_spec spec = {
	        .name = "fuzz", .usage = "", .about = "", .common = ~0u, .option = no_option};
	char name[32];
	snprintf(name, sizeof name, "--%s", shared[o]);
	char *argv[] = {"fuzz", name, value, NULL};
	cli_common c = cli_common_default();
	int rc = cli_parse(&spec, 3, argv, &c, NULL, NULL);
	expect(rc == -1 || rc == CLI_USAGE, name, value, rc);
	if (rc == -1)
		fuzz_accepted();
	if (rc == -1 && c.n_backend_opts > 0) {
		bsim_options opts[2];
		cli_backend_with_opts(&c, "fuzz", "thesis", &opts[0]);
		static const char *const names[2] = {"thesis", "box2d"};
		bsim_options *po[2] = {&opts[0], &opts[1]};
		memset(opts, 0, sizeof opts);
		rc = cli_backend_opts(&c, "fuzz", 2, names, po);
		expect(rc == CLI_OK || rc == CLI_USAGE, "--backend-opt for two", value, rc);
	}
	cli_common_free(&c);
}

static void own_option(int i, char *value)
{
	char cmd[32], sub[32], opt[32], end[] = "--fuzz-end-of-options";
	snprintf(cmd, sizeof cmd, "%s", own[i].cmd);
	snprintf(opt, sizeof opt, "%s", own[i].opt);
	char *argv[6];
	int argc = 0;
	argv[argc++] = cmd;
	if (own[i].sub) {
		snprintf(sub, sizeof sub, "%s", own[i].sub);
		argv[argc++] = sub;
	}
	argv[argc++] = opt;
	argv[argc++] = value;
	argv[argc++] = end;
	argv[argc] = NULL;
	int rc = own[i].fn(argc, argv);
	expect(rc == CLI_USAGE, opt, value, rc);
}

static void compare_sides(const char *value)
{
	char side[2][256];
	const char *comma = strchr(value, ',');
	size_t n0 = comma ? (size_t)(comma - value) : strlen(value);
	snprintf(side[0], sizeof side[0], "%.*s", (int)(n0 < 255 ? n0 : 255), value);
	snprintf(side[1], sizeof side[1], "%s", comma ? comma + 1 : "");
	for (int s = 0; s < (comma ? 2 : 1); s++) {
		bsim_compare_side cs;
		bsim_error err;
		memset(&cs, 0, sizeof cs);
		bsim_error_clear(&err);
		int rc = bsim_compare_side_parse(side[s], &cs, &err);
		if (rc != BSIM_OK)
			fuzz_check_error(rc, &err);
		else
			fuzz_accepted();
	}
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	if (size == 0)
		return 0;
	int choice = data[0] % (N_SHARED + N_OWN + 1);
	char *value = malloc(size);
	if (!value)
		return 0;
	memcpy(value, data + 1, size - 1);
	value[size - 1] = '\0';
	if (choice < N_SHARED)
		shared_option(choice, value);
	else if (choice < N_SHARED + N_OWN)
		own_option(choice - N_SHARED, value);
	else
		compare_sides(value);
	bsim_limits l = bsim_limits_default();
	bsim_limits_set(&l);
	free(value);
	return 0;
}
