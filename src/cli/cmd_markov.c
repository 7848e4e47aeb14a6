/* beamsim markov: the Markov chain that predicts a gate lattice from
 * single-gate maps (beamsim/markov.h). build, predict and validate parse
 * and print; the library simulates, composes, solves and writes. */
#define _GNU_SOURCE /* asprintf, mkdtemp */

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <ftw.h>
#include <sys/stat.h>

#include "beamsim/markov.h"
#include "beamsim/lattice_outcome.h"
#include "cli/cli_wrote.h"
#include "cli/cli_common.h"
#include "cli/cli_options.h"
#include "cli/cli_progress.h"
#include "cli/cli_mpi.h"
#include "store/outdir.h"
#include "beamsim/sweep_dir.h"

enum {
	OWN_BINS,
	OWN_VMAX,
	OWN_ENTRIES,
	OWN_MAP,
	OWN_BOOTSTRAP,
	OWN_LOCATIONS,
	OWN_JSON,
	OWN_TOL,
	OWN_NO_GATES,
	OWN_WALKS,
	OWN_GATES, /* predict's options follow each other from OWN_LOCATIONS */
	OWN_SHARD,
	OWN_PASSES,
	OWN_START_TRIALS,
	OWN_AFTER_START,
	OWN_TRAIN,
	OWN_CROSSINGS,
	OWN_PER_CROSSING,
	OWN_AFTER_TRIALS
};

#define MAX_ENTRIES 16

typedef struct markov_args {
	bsim_markov_def def;
	const char *map;
	long bootstrap;
	int locations, json; /* predict: --locations, --json */
	int no_gates;        /* predict: --no-gates */
	int gates;           /* predict: --gates */
	double tol;          /* predict: --tol */
	long walks;          /* predict: --walks */
	const char *visits;  /* predict, validate: --visits */
	int k;               /* predict, validate: --k */
	int train;           /* predict, validate: --train with --visits */
	int shard, shards;   /* build: --shard, 1-based; 0: every map */
	const char *passes;  /* build: --passes */
	int n_entries;
	const char *entries[MAX_ENTRIES];
	int start_trials;      /* build: --start-trials given */
	const char *method;    /* build: --method, NULL not given */
	int train_given;       /* build: --train given (def.train_trials) */
	const char *maps_only; /* build: the first option of the maps' only given */
} markov_args;

/* An integer option of markov build, lo to hi, into *out; else the usage
 * error naming it. */
static int build_count(const char *opt, const char *value, long lo, long hi, int *out)
{
	long n;
	if (cli_parse_long(value, lo, hi, &n) != 0)
		return cli_usage("markov build", "--%s %s: expected an integer %ld to %ld", opt,
		                 value, lo, hi);
	*out = (int)n;
	return CLI_OK;
}

static int markov_option(void *args, int i, const char *value)
{
	markov_args *a = args;
	char *end;
	switch (i) {
	case OWN_BINS: {
		/* Three integers, each read in full: sscanf's %d would take
		 * 4294967298 for 2. */
		long n[3];
		const char *p = value;
		int ok = 1;
		for (int k = 0; k < 3 && ok; k++) {
			char field[8];
			size_t len = strspn(p, "0123456789");
			ok = len > 0 && len < sizeof field && p[len] == (k < 2 ? ',' : '\0');
			if (ok) {
				snprintf(field, sizeof field, "%.*s", (int)len, p);
				ok = cli_parse_long(field, 1, 64, &n[k]) == 0;
				p += len + 1;
			}
		}
		if (!ok)
			return cli_usage("markov",
			                 "--bins %s: expected P,S,D: 1 to 64 bins of "
			                 "position, speed and direction, e.g. --bins 4,4,3",
			                 value);
		a->def.bins.n_pos = (int)n[0];
		a->def.bins.n_speed = (int)n[1];
		a->def.bins.n_dir = (int)n[2];
		bsim_error err;
		if (bsim_markov_bins_check(&a->def.bins, &err) != BSIM_OK)
			return cli_usage("markov", "--bins %s: %s", value, err.msg);
		return CLI_OK;
	}
	case OWN_VMAX:
		a->def.bins.v_max = strtod(value, &end);
		if (end == value || *end || !(a->def.bins.v_max > 0) ||
		    !isfinite(a->def.bins.v_max))
			return cli_usage("markov", "--vmax %s: expected a speed > 0 in m/s", value);
		return CLI_OK;
	case OWN_ENTRIES:
		/* self or self:N: the exits of the map's own single gates, N passes
		 * (default 1); a file named self is ./self */
		{
			bsim_markov_def kind = a->def;
			int is_kind;
			bsim_error err;
			int rc = bsim_markov_entries_kind(value, &kind, &is_kind, &err);
			if (is_kind && (rc != BSIM_OK || a->def.self_entries))
				return cli_usage(
				        "markov",
				        "--entries %s: expected self, self:N, flow or flow:N, N "
				        "passes 0 to "
				        "%d, once",
				        value, BSIM_MARKOV_SELF_PASSES_MAX);
			if (is_kind) {
				if (a->start_trials) /* given: kept, and checked by the build */
					kind.start_trials = a->def.start_trials;
				a->def = kind;
				return CLI_OK;
			}
		}
		if (a->n_entries == MAX_ENTRIES)
			return cli_usage("markov", "--entries %s: at most %d", value, MAX_ENTRIES);
		a->entries[a->n_entries++] = value;
		return CLI_OK;
	case OWN_AFTER_START: {
		long n;
		if (cli_parse_long(value, 0, 1, &n) != 0)
			return cli_usage("markov build", "--after-start %s: expected 0 or 1",
			                 value);
		a->def.after_start = (int)n;
		return CLI_OK;
	}
	case OWN_AFTER_TRIALS:
		return build_count("after-trials", value, 0, 1000000, &a->def.after_trials);
	case OWN_START_TRIALS: {
		const int rc = build_count("start-trials", value, 1, 1000000, &a->def.start_trials);
		if (rc == CLI_OK)
			a->start_trials = 1;
		return rc;
	}
	case OWN_TRAIN:
		return build_count("train", value, 0, 1000000, &a->def.train_trials);
	case OWN_CROSSINGS: {
		long n;
		if (cli_parse_long(value, 0, 1, &n) != 0)
			return cli_usage("markov build", "--crossings %s: expected 0 or 1", value);
		a->def.train_crossings = (int)n;
		return CLI_OK;
	}
	case OWN_PER_CROSSING:
		return build_count("per-crossing", value, 0, 1000000, &a->def.trials_per_crossing);
	case OWN_MAP:
		a->map = value;
		return CLI_OK;
	case OWN_BOOTSTRAP:
		if (cli_parse_long(value, 0, 1000000, &a->bootstrap) != 0)
			return cli_usage("markov",
			                 "--bootstrap %s: expected an integer 0 to 1000000", value);
		return CLI_OK;
	case OWN_LOCATIONS:
		a->locations = 1;
		return CLI_OK;
	case OWN_JSON:
		a->json = 1;
		return CLI_OK;
	case OWN_TOL:
		if (strcmp(value, "sampling") == 0) {
			a->tol = -1.0; /* from the maps, once read */
			return CLI_OK;
		}
		a->tol = strtod(value, &end);
		if (end == value || *end || !(a->tol > 0.0 && a->tol < 1.0))
			return cli_usage("markov predict",
			                 "--tol %s: expected the probability left in the field at "
			                 "which the solution stops, in (0, 1), e.g. 1e-12, or "
			                 "sampling",
			                 value);
		return CLI_OK;
	case OWN_NO_GATES:
		a->no_gates = 1;
		return CLI_OK;
	case OWN_SHARD:
		return cli_shard_parse("markov build", value, &a->shard, &a->shards);
	case OWN_PASSES:
		a->passes = value;
		return CLI_OK;
	case OWN_GATES:
		a->gates = 1;
		return CLI_OK;
	case OWN_WALKS:
		if (cli_parse_long(value, 0, 100000000L, &a->walks) != 0)
			return cli_usage("markov predict",
			                 "--walks %s: expected an integer 0 to 100000000", value);
		return CLI_OK;
	}
	return CLI_USAGE;
}

static const cli_own build_own[] = {
        [OWN_BINS] = {"bins", 1, "P,S,D",
                      "entry bins of position along the edge, speed and\n"
                      "direction (default 14,6,13)"},
        [OWN_VMAX] = {"vmax", 1, "V",
                      "m/s, the top of the speed bins (default 40, or\n"
                      "F_prop/M x 40/7 s where that is more)"},
        [OWN_ENTRIES] = {"entries", 1, "PATH",
                         "gate_entries.csv of a lattice sweep (or its directory),\n"
                         "repeatable: a bin's states are drawn from the entries\n"
                         "that fall in it (default: a training field's, --train); self or\n"
                         "self:N: from the exits of the map's own single gates, N\n"
                         "passes (default 1); flow or flow:N: from every map's exits\n"
                         "weighted by the chain's flow on each lattice (maps for\n"
                         "that lattice only; docs/markov.md)"},
        {"shard", 1, "I/N",
         "build part I of N of the maps (I from 1 to N, as\n"
         "SLURM_ARRAY_TASK_ID of --array=1-N): the build's map j\n"
         "(every group's pairs in turn) is part j mod N + 1's; DIR gets those\n"
         "maps and part.json, beamsim merge joins the N parts'\n"
         "directories into the map directory (docs/cluster.md); with\n"
         "--entries flow or flow:N one pass of the maps (a round)"},
        {"passes", 1, "DIR",
         "with --entries flow[:N] and --shard: the map directory\n"
         "beamsim merge wrote of the round before, whose passes the\n"
         "next round's states come from (none: the first round)"},
        {"start-trials", 1, "N",
         "single-gate trials of the start bin (default 16000, or\n"
         "--trials with self or flow entries, which take no other)"},
        {"after-start", 1, "0|1",
         "1 (default): each start trial that leaves into a gate goes\n"
         "on there from its exact state, for every pair of stiffnesses,\n"
         "and the chain takes the first two gates from those (0 with\n"
         "self or flow entries); 0: entry bins from the start on"},
        {"train", 1, "N",
         "trials of each training field, a 21 x 21 field of the\n"
         "lattice's gate kinds at random (the walks' default 10000);\n"
         "maps: the field whose gate entries the bins' states are\n"
         "drawn from (default 4000; run only when a map is built),\n"
         "0: states uniform in each bin"},
        {"crossings", 1, "0|1",
         "1 (default, with a training field): each bin counts the\n"
         "training field's own crossings of the map's gate kind\n"
         "entered in it, topped up with single gates as\n"
         "--per-crossing says; 0: --trials single gates a bin, from\n"
         "the field's entries"},
        {"per-crossing", 1, "N",
         "single gates a bin is topped up to for each crossing that\n"
         "entered it (as for one where none did), at most --trials\n"
         "(default 5); 0: every bin topped up to --trials"},
        {"after-trials", 1, "N",
         "the first N start trials go on into the gate after the\n"
         "start (default 8000); the others take the continuations of\n"
         "those that entered the same gate; 0: every start trial"},
        {"method", 1, "nearest|maps",
         "nearest (the default): the training fields of the\n"
         "nearest-neighbour walks; maps: single-gate maps of entry\n"
         "bins (implied by any option above but --train)"},
        {"k", 1, "K",
         "the walks: each step drawn from the K nearest visits\n(1 to 64, default 20)"},
};

/* What a map's entry bin holds, for the summaries: trials single gates,
 * or crossings topped up (per single gates a crossing; 0: to trials). */
static void bins_hold(int crossings, int per, int trials, char *buf, size_t size)
{
	if (crossings && per > 0)
		snprintf(buf, size,
		         "their crossings or %d single gates a crossing (at most %d trials)", per,
		         trials);
	else
		snprintf(buf, size, "%s%d trials", crossings ? "their crossings or " : "", trials);
}

static int nearest_option(markov_args *a, const char *cmd, int i, const char *value);

static int build_option(void *args, int i, const char *value)
{
	markov_args *a = args;
	if (i == 11) {
		a->method = value;
		return CLI_OK;
	}
	if (i == 12)
		return nearest_option(a, "markov build", 1, value);
	if (i == 7) /* --train: the walks' training fields or the maps' */
		a->train_given = 1;
	else if (!a->maps_only)
		a->maps_only = build_own[i].name;
	return markov_option(args,
	                     i == 3    ? OWN_SHARD
	                     : i == 4  ? OWN_PASSES
	                     : i == 5  ? OWN_START_TRIALS
	                     : i == 6  ? OWN_AFTER_START
	                     : i == 7  ? OWN_TRAIN
	                     : i == 8  ? OWN_CROSSINGS
	                     : i == 9  ? OWN_PER_CROSSING
	                     : i == 10 ? OWN_AFTER_TRIALS
	                               : i,
	                     value);
}

static const char *const build_help[CLI_N_OPTS] = {
        [CLI_OPT_OUT] = "the directory: training fields or maps already there with the\n"
                        "same key are reused, the others are built there (required)",
        [CLI_OPT_TRIALS] = "maps: single-gate trials per entry bin (default 50)",
        [CLI_OPT_SEED] = "seed of the training fields, entry states and schedules\n(default 1)",
};

static const cli_spec build_spec = {
        .name = "markov build",
        .usage = "EXPERIMENT --out DIR [OPTIONS]",
        .about = "Builds what the Markov chain predicts the lattices of EXPERIMENT from. By\n"
                 "default (--method nearest) the nearest-neighbour walks' training fields:\n"
                 "for each gate kind of a lattice's physics, --train trials (default 10000)\n"
                 "of a 21 x 21 field of the lattice's kinds at random, each trial its own\n"
                 "layout, every gate visit kept with its exact entry and exit states\n"
                 "(visits_HASH.csv, .key, .cost) and markov.json; markov predict and\n"
                 "validate --map DIR walk over them, each step from the --k nearest visits,\n"
                 "for every layout of the same kinds and physics (docs/markov.md).\n"
                 "With --method maps (or any option of theirs: --bins, --vmax, --trials,\n"
                 "--entries, --start-trials, --after-start, --after-trials, --crossings,\n"
                 "--per-crossing, --shard, --passes), the single-gate maps, one per pair of\n"
                 "beam stiffnesses: for every entry bin (edge, position along it, speed,\n"
                 "direction; and the start) single gates with their beams at rest, as the\n"
                 "essay's protocol resets them, run from states drawn in the bin with fresh\n"
                 "random-force schedules until the body leaves the gate or is stuck; the\n"
                 "counts of where it left are the map. A bin's states are the gate entries\n"
                 "in it of a training field (--train trials of a 21 x 21 field of the\n"
                 "lattice's gate kinds at random), so the maps serve every layout of those\n"
                 "kinds. Each start trial that leaves into a gate goes on there, in a gate\n"
                 "of every pair, from its exact state (the gate after the start). DIR\n"
                 "caches them: map_HASH.csv (entry, exit, count),\n"
                 "map_HASH.key (everything the map depends on), map_START.after_GATE.csv,\n"
                 "markov.json.\n",
        .positional = "EXPERIMENT",
        .common = CLI_USES(CLI_OPT_OUT) | CLI_USES(CLI_OPT_TRIALS) | CLI_USES(CLI_OPT_SEED) |
                  CLI_USES(CLI_OPT_THREADS) | CLI_USES(CLI_OPT_BACKEND) |
                  CLI_USES(CLI_OPT_BACKEND_OPT) | CLI_USES(CLI_OPT_SET) | CLI_USES(CLI_OPT_GRID) |
                  CLI_USES(CLI_OPT_QUIET),
        .help = build_help,
        .out_required = 1,
        .own = build_own,
        .n_own = sizeof build_own / sizeof build_own[0],
        .option = build_option,
};

static const cli_own predict_own[] = {
        {"map", 1, "DIR",
         "the directory of beamsim markov build: its walks'\ntraining fields, or maps (or "
         "--visits)"},
        {"locations", 0, NULL, "also print every final location with its probability"},
        {"json", 0, NULL,
         "print one JSON object (totals, every location, predict_seconds)\ninstead of text"},
        {"tol", 1, "T",
         "stop when less than T is left in the field (each\nlocation's p is short by "
         "at most what is left);\ndefault sampling: 1 / (32 sqrt(trials per bin)),\n"
         "1/16 of a map probability's standard error\n(1.1e-3 at 800 trials)"},
        {"no-gates", 0, NULL,
         "no distribution of gates visited, even with --out\n(the sweeps; the mean "
         "from the expected visits)"},
        {"walks", 1, "N",
         "the nearest-neighbour walks (default 200000); maps: walks\nof the semi-Markov "
         "chain for the distribution of the time\nto the outcome (default 100000; 0: none)"},
        {"gates", 0, NULL,
         "also the distribution of gates visited (the series,\nslower; --out implies "
         "it): p_gates,\nprediction_gates.csv"},
        {"visits", 1, "DIR",
         "instead of --map: nearest-neighbour walks over the visits\nof training fields "
         "of the lattice's gate kinds in DIR,\nthose missing run there first "
         "(docs/markov.md);\n--walks N of them (default 200000)"},
        {"k", 1, "K",
         "with --visits: each step drawn from the K nearest visits\n(1 to 64, default "
         "20)"},
        {"train", 1, "N", "with --visits: trials of each training field (default\n10000)"},
};

/* The options of the nearest-neighbour walks: --visits, --k, --train and
 * (validate's) --walks. */
static int nearest_option(markov_args *a, const char *cmd, int i, const char *value)
{
	static const char *const name[] = {"visits", "k", "train", "walks"};
	static const long most[] = {0, 64, INT_MAX, 100000000L};
	long n = 0;
	if (i > 0 && cli_parse_long(value, 1, most[i], &n) != 0)
		return cli_usage(cmd, "--%s %s: expected an integer 1 to %ld", name[i], value,
		                 most[i]);
	if (i == 0)
		a->visits = value;
	else if (i == 1)
		a->k = (int)n;
	else if (i == 2)
		a->train = (int)n;
	else
		a->walks = n;
	return CLI_OK;
}

/* The walks' def of --visits' options (0: not given, the default kept). */
static void nearest_apply(const markov_args *a, const cli_common *c, const bsim_backend *be,
                          const bsim_options *opts, bsim_markov_nearest_def *def)
{
	def->backend = be;
	def->opts = opts;
	def->threads = (int)c->threads;
	if (a->train > 0)
		def->trials = a->train;
	if (a->k > 0)
		def->k = a->k;
	if (a->walks > 0)
		def->walks = a->walks;
}

/* Whether the prediction walks, into *walks: --visits, or --map a build
 * of the walks (markov build's default; else of maps). rc as parsing left
 * it, or the refusal of a --map that is no build. */
static int map_walks(const markov_args *a, int rc, int *walks)
{
	bsim_markov_method method = BSIM_MARKOV_METHOD_NEAREST;
	bsim_error err;
	if (rc < 0 && a->map && bsim_markov_dir_method(a->map, &method, &err) != BSIM_OK)
		rc = cli_report(err.code, &err);
	*walks = a->visits || method == BSIM_MARKOV_METHOD_NEAREST;
	return rc;
}

/* The walks over a build in --map: its own settings (read by the
 * library), these walks and threads. */
static void build_walks_apply(const markov_args *a, const cli_common *c,
                              bsim_markov_nearest_def *def)
{
	def->threads = (int)c->threads;
	if (a->walks > 0)
		def->walks = a->walks;
}

/* predict's own options: --map, then --locations, --json and the others
 * (validate's: validate_option). */
static int predict_option(void *args, int i, const char *value)
{
	if (i >= 7) /* --visits, --k, --train */
		return nearest_option(args, "markov predict", i - 7, value);
	return markov_option(args, i == 0 ? OWN_MAP : OWN_LOCATIONS + i - 1, value);
}

static const char *const predict_help[CLI_N_OPTS] = {
        [CLI_OPT_OUT] = "also write prediction.csv, prediction_gates.csv, time.csv,\n"
                        "their .mat twins and the figures prediction.png (the field)\n"
                        "and time.png into DIR",
        [CLI_OPT_SEED] = "with --visits: seed of the training fields and the walks\n(default 1)",
        [CLI_OPT_THREADS] = "the walks' threads (default all cores; the same answer)",
        [CLI_OPT_BACKEND] = "with --visits: the training fields' backend",
};

static const cli_spec predict_spec = {
        .name = "markov predict",
        .usage = "LATTICE_SCENE (--map DIR | --visits DIR) [OPTIONS]",
        .about = "Predicts the lattice of LATTICE_SCENE from the build in DIR and prints the\n"
                 "probabilities of ending through the end, out a side and stuck in a gate,\n"
                 "and the mean number of gates visited: by nearest-neighbour walks over its\n"
                 "training fields' visits (markov build's default), or, of maps, by the\n"
                 "absorbing Markov chain they compose over the lattice. The\n"
                 "distribution over every final location (the end through column ix, a side\n"
                 "at row iy, stuck in gate (ix, iy)) is --out DIR's prediction.csv, or\n"
                 "printed with --locations or --json. With the maps' holding times it\n"
                 "prints the expected time to the outcome (first-step analysis) and, by\n"
                 "walks of the semi-Markov chain, the outcome at the trial's duration and\n"
                 "the time of each kind (--out DIR's time.csv and time.png).\n"
                 "With --visits DIR instead: the walks over a cache of training fields,\n"
                 "those missing run there first (--train trials each, default 10000), kept\n"
                 "for every layout of the same kinds and physics.\n",
        .positional = "LATTICE_SCENE",
        .common = CLI_USES(CLI_OPT_SET) | CLI_USES(CLI_OPT_OUT) | CLI_USES(CLI_OPT_OVERWRITE) |
                  CLI_USES(CLI_OPT_QUIET) | CLI_USES(CLI_OPT_SEED) | CLI_USES(CLI_OPT_THREADS) |
                  CLI_USES(CLI_OPT_BACKEND) | CLI_USES(CLI_OPT_BACKEND_OPT),
        .help = predict_help,
        .own = predict_own,
        .n_own = 10,
        .option = predict_option,
};

static const cli_own validate_own[] = {
        {"map", 1, "DIR",
         "the directory of beamsim markov build: its walks'\ntraining fields, or maps (or "
         "--visits)"},
        {"bootstrap", 1, "B", "resamples of the simulation (default 2000)"},
        {"shard", 1, "I/N",
         "simulate part I of N (I from 1 to N, as SLURM_ARRAY_TASK_ID\n"
         "of --array=1-N): trial j of the two sweeps (the essay\n"
         "protocol's g*trials+t, then the world's) is part j mod N + 1's;\n"
         "DIR gets part.json and part.journal, beamsim merge joins the\n"
         "N parts' directories into the validation's (docs/cluster.md)"},
        {"visits", 1, "DIR",
         "instead of --map: predict by nearest-neighbour walks over\nthe visits in DIR, "
         "as markov predict --visits (the training\nfields missing there run first)"},
        {"k", 1, "K", "with --visits: as markov predict's (default 20)"},
        {"train", 1, "N", "with --visits: as markov predict's (default 10000)"},
        {"walks", 1, "N", "the nearest-neighbour walks (default 200000)"},
};

static int validate_option(void *args, int i, const char *value)
{
	markov_args *a = args;
	if (i == 2)
		return cli_shard_parse("markov validate", value, &a->shard, &a->shards);
	if (i >= 3)
		return nearest_option(a, "markov validate", i - 3, value);
	return markov_option(args, OWN_MAP + i, value); /* --map, --bootstrap */
}

static const char *const validate_help[CLI_N_OPTS] = {
        [CLI_OPT_OUT] = "output directory (required)",
        [CLI_OPT_BACKEND] = "with --visits: the backend of the training fields and the\n"
                            "simulation (with --map: the maps')",
};

static const cli_spec validate_spec = {
        .name = "markov validate",
        .usage = "LATTICE_EXPERIMENT --map DIR --out DIR [OPTIONS]",
        .about = "Simulates every group of LATTICE_EXPERIMENT directly, under the essay's\n"
                 "protocol and as a whole world, predicts it from the build in --map (the\n"
                 "walks, or the chain of its maps), and writes into --out: validate.json\n"
                 "(total variation distance of the final-location distributions with the\n"
                 "simulation's and the walks' or maps' sampling errors, mean gates visited, CPU "
                 "time of simulation and\n"
                 "prediction, the lattices after which building the maps pays off; with\n"
                 "the maps' holding times the exit times against the chain's walks),\n"
                 "validate.csv, gates.csv, time_validate.csv, their .mat twins and\n"
                 "validate_gNNN (.png .svg). The simulated trials are journaled as they\n"
                 "end, so a stopped or killed run continues with --resume; under\n"
                 "`mpirun -np N` they are spread over the ranks, with --shard I/N over\n"
                 "N processes joined by beamsim merge, the files those of one process\n"
                 "but for the CPU times (docs/cluster.md).\n",
        .positional = "LATTICE_EXPERIMENT",
        .common = CLI_USES(CLI_OPT_OUT) | CLI_USES(CLI_OPT_TRIALS) | CLI_USES(CLI_OPT_SEED) |
                  CLI_USES(CLI_OPT_THREADS) | CLI_USES(CLI_OPT_SET) | CLI_USES(CLI_OPT_GRID) |
                  CLI_USES(CLI_OPT_QUIET) | CLI_USES(CLI_OPT_RESUME) | CLI_USES(CLI_OPT_OVERWRITE) |
                  CLI_USES(CLI_OPT_BACKEND) | CLI_USES(CLI_OPT_BACKEND_OPT),
        .help = validate_help,
        .out_required = 1,
        .own = validate_own,
        .n_own = 7,
        .option = validate_option,
};

/* A part of an MPI job's build: its rank's maps into a directory of
 * its own (markov_build_ranks). */
typedef struct markov_part {
	const char *out;
	int shard, shards; /* 1-based */
} markov_part;

/* The training field's line, ended when its last trial is done: the
 * single gates' line follows on its own. */
static void train_progress_update(void *user, long done, long total)
{
	cli_progress_update(user, done, total);
	if (done == total)
		cli_progress_finish(user);
}

static int markov_build_main(int argc, char **argv, const cli_merge *m, const markov_part *p);

/* A run stopped by SIGINT or SIGTERM, its finished work kept (err says
 * what): said, with what the same command does next; 128 + the signal. */
static int stopped(const bsim_error *err, const char *next)
{
	const int sig = cli_stop ? (int)cli_stop : SIGINT;
	cli_error("%s: %s; the same command %s", sig == SIGTERM ? "SIGTERM" : "SIGINT", err->msg,
	          next);
	return 128 + sig;
}

static int remove_one(const char *path, const struct stat *st, int type, struct FTW *ftw)
{
	(void)st;
	(void)type;
	(void)ftw;
	remove(path);
	return 0;
}

/* A directory and all in it, gone. */
static void remove_tree(const char *dir)
{
	nftw(dir, remove_one, 16, FTW_DEPTH | FTW_PHYS);
}

/* mkdir that accepts a directory already there. */
static int mkdir_have(const char *dir)
{
	if (mkdir(dir, 0777) != 0 && errno != EEXIST) {
		cli_error("%s: cannot create: %s", dir, strerror(errno));
		return CLI_FAIL;
	}
	return CLI_OK;
}

/* The build spread over an MPI job's ranks: rank r builds part r + 1 of
 * the maps into out/.beamsim/parts/R-of-N, rank 0 gathers the parts'
 * files and merges them into out, as merge does. A part's directory is
 * its cache: a job killed before the merge leaves each rank's finished
 * maps there, and the same command with as many ranks reuses them; a
 * merged build removes the parts. */
static int markov_build_ranks(int argc, char **argv, const cli_common *c)
{
	int rank = cli_mpi_rank(), size = cli_mpi_size(), rc = CLI_OK;
	char *work = NULL, *parts = NULL, *part = NULL;
	if (asprintf(&work, "%s/.beamsim", c->out) < 0 || asprintf(&parts, "%s/parts", work) < 0 ||
	    asprintf(&part, "%s/%d-of-%d", parts, rank + 1, size) < 0)
		rc = CLI_FAIL;
	/* out is opened by rank 0's merge; until then the ranks make their
	 * parts in it only if it could be opened (no other run holds it) */
	bsim_error err;
	if (rc == CLI_OK && bsim_outdir_probe(c->out, BSIM_OUTDIR_ADD, NULL, &err) != BSIM_OK)
		rc = cli_report(err.code, &err);
	if (rc == CLI_OK)
		rc = mkdir_have(c->out);
	if (rc == CLI_OK)
		rc = mkdir_have(work);
	if (rc == CLI_OK)
		rc = mkdir_have(parts);
	if (rc != CLI_OK) {
		cli_mpi_abort(rc);
		return rc;
	}
	markov_part p = {part, rank + 1, size};
	rc = markov_build_main(argc, argv, NULL, &p);
	if (rc != CLI_OK)
		cli_mpi_abort(rc); /* printed; the others would wait for ever */
	char **dirs = calloc((size_t)size, sizeof *dirs);
	if (!dirs || (rc = cli_mpi_gather_dir(part, dirs)) != CLI_OK)
		cli_mpi_abort(CLI_FAIL);
	if (rank == 0) {
		cli_merge merge = {c->out, c->threads, c->quiet, (const char *const *)dirs,
		                   size,   0};
		rc = markov_build_main(argc, argv, &merge, NULL);
	}
	/* the other ranks' files as rank 0 received them: copies, not kept */
	for (int r = 1; r < size && dirs && rank == 0; r++)
		if (dirs[r])
			remove_tree(dirs[r]);
	if (rc == CLI_OK && rank == 0) {
		/* merged into out: every part has served, those of a killed
		 * job's with another count of ranks too */
		remove_tree(parts);
		rmdir(work);
	}
	for (int r = 0; r < size && dirs; r++)
		free(dirs[r]);
	free(dirs);
	free(part);
	free(parts);
	free(work);
	if (rc != CLI_OK)
		cli_mpi_abort(rc);
	return rc;
}

/* A group's maps as they come: one line each. */
static void build_group_print(void *user, int group, const bsim_markov_built *maps, int n)
{
	const bsim_markov_build_def *def = user;
	const int nearest = def->method == BSIM_MARKOV_METHOD_NEAREST;
	for (int i = 0; i < n; i++) {
		char of_pass[32] = ""; /* a round before the last: one pass of the maps */
		if (!nearest && maps[i].pass < def->map.self_passes)
			snprintf(of_pass, sizeof of_pass, "pass %d ", maps[i].pass);
		printf("group %d  k = %g, %g N m/rad  %s_%016llx  %s%s\n", group, maps[i].k[0],
		       maps[i].k[1], nearest ? "visits" : "map", (unsigned long long)maps[i].key,
		       of_pass,
		       maps[i].elsewhere ? "another part's"
		       : maps[i].copied  ? "from a part"
		       : maps[i].cached  ? "reused"
		                         : "built");
	}
}

static void build_print(const bsim_markov_build_def *def, const bsim_markov_build_result *res,
                        const char *out)
{
	const int pass = res->pass, last = def->map.self_passes;
	if (def->parts > 0)
		printf("part %d of %d of the maps in %s; beamsim merge joins the %d parts' "
		       "directories\n",
		       def->part, def->parts, cli_path(out), def->parts);
	if (res->round && pass < last && def->n_merge <= 0)
		printf("pass %d of passes 0 to %d (flow entries): once merged into DIR, the next "
		       "round is the same command with --passes DIR\n",
		       pass, last);
	else if (res->round && pass < last)
		printf("passes 0 to %d of the %d (flow entries) in %s: the next round is the "
		       "parts' command with --passes %s\n",
		       pass, last + 1, cli_path(out), cli_path(out));
	const int trained = def->n_entries <= 0 && def->map.train_trials > 0 &&
	                    !def->map.self_entries,
	          crossings = trained && def->map.train_crossings != 0;
	char holds[96];
	bins_hold(crossings, def->map.trials_per_crossing, def->map.trials, holds, sizeof holds);
	printf("%d maps built (%.1f s of CPU), %d reused%s; %d entry bins x %s each, the start's "
	       "%d, in %s\n",
	       res->built, res->seconds, res->reused,
	       res->copied ? ", the others from the parts" : "", res->n_bins, holds,
	       def->map.start_trials > 0 ? def->map.start_trials : def->map.trials, cli_path(out));
	if (res->built > 0 && trained)
		printf("the bins' %s a training field, %d trials of %d x %d gates of the lattice's "
		       "kinds at random (CPU above)\n",
		       crossings ? "counts from the crossings (topped up from the entries) of"
		                 : "states from the gate entries of",
		       def->map.train_trials, BSIM_MARKOV_TRAIN_SIZE, BSIM_MARKOV_TRAIN_SIZE);
	if (res->after_trials > 0)
		printf("the gate after the start (%d of the start trials continued): %d pairs of "
		       "maps built, %d reused (CPU above)\n",
		       res->after_trials, res->next_built, res->next_reused);
	cli_wrote(stdout, out);
}

/* A build's inputs from the command line, whatever its method: the
 * experiment, the directory, --set, --grid and --seed. */
static void build_inputs(bsim_markov_build_def *def, const cli_common *c, const char *path)
{
	def->experiment = path;
	def->out = c->out;
	def->sets = c->sets.ov;
	def->n_sets = c->sets.n;
	def->grid = c->sets.grid;
	def->n_grid = c->sets.n_grid;
	def->has_seed = c->has_seed;
	def->seed = c->seed;
}

/* markov build's default: the walks' training fields, their progress and
 * lines. */
static int markov_build_nearest(cli_common *c, const markov_args *a, const char *path)
{
	bsim_options opts = {0};
	const bsim_backend *be = cli_backend_with_opts(
	        c, "markov build", c->backend ? c->backend : bsim_backend_default()->name, &opts);
	if (!be)
		return CLI_USAGE;
	bsim_markov_build_def def = bsim_markov_build_def_default();
	markov_args given = *a;
	if (a->train_given)
		given.train = a->def.train_trials;
	nearest_apply(&given, c, be, &opts, &def.nearest);
	build_inputs(&def, c, path);
	cli_progress training;
	cli_progress_init(&training, !c->quiet, "training trials");
	def.nearest.progress = train_progress_update;
	def.nearest.progress_user = &training;
	def.nearest.stop = &cli_stop;
	if (!c->quiet) {
		def.group_done = build_group_print;
		def.group_done_user = &def;
	}
	bsim_markov_build_result res;
	bsim_error err;
	cli_signals_install();
	int rc = bsim_markov_build_run(&def, &res, &err);
	cli_signals_restore();
	cli_progress_finish(&training);
	/* Each finished training field is in the directory already. */
	if (rc == BSIM_ESTOPPED)
		return stopped(&err, "runs the rest");
	if (rc == BSIM_OK && !c->quiet) {
		printf("%d training fields run (%.1f s of CPU), %d reused: %ld visits, each "
		       "field %d trials of %d x %d gates of the lattice's kinds at random, in "
		       "%s\n"
		       "markov predict and validate --map %s walk over them, each step from "
		       "the %d nearest visits\n",
		       res.built, res.seconds, res.reused, res.visits, def.nearest.trials,
		       BSIM_MARKOV_TRAIN_SIZE, BSIM_MARKOV_TRAIN_SIZE, cli_path(c->out),
		       cli_path(c->out), def.nearest.k);
		cli_wrote(stdout, c->out);
	}
	if (rc == BSIM_OK)
		bsim_markov_build_result_free(&res);
	return cli_report(rc, &err);
}

static int markov_build_main(int argc, char **argv, const cli_merge *m, const markov_part *p)
{
	cli_common c = cli_common_default();
	markov_args a = {.def = bsim_markov_def_default()};
	const char *path = NULL;
	int rc = cli_parse(&build_spec, argc, argv, &c, &a, &path);
	/* the method: --method's, else maps if an option of theirs alone is
	 * given, else the walks */
	char maps_only[32] = "", k_given[16] = "";
	if (a.maps_only || c.trials > 0)
		snprintf(maps_only, sizeof maps_only, "--%s", a.maps_only ? a.maps_only : "trials");
	if (a.k)
		snprintf(k_given, sizeof k_given, "--k");
	bsim_markov_method method = BSIM_MARKOV_METHOD_NEAREST;
	bsim_error err;
	if (rc < 0 &&
	    bsim_markov_build_method(a.method, maps_only[0] ? maps_only : NULL,
	                             k_given[0] ? k_given : NULL, &method, &err) != BSIM_OK)
		rc = cli_usage("markov build", "%s", err.msg);
	const int nearest = method == BSIM_MARKOV_METHOD_NEAREST && !m && !p;
	if (rc < 0 && nearest && cli_mpi_size() > 1)
		rc = cli_usage("markov build",
		               "the walks' training fields run in one process, on its threads: "
		               "not under mpirun (%d ranks); --method maps spreads its maps over "
		               "the ranks",
		               cli_mpi_size());
	if (rc < 0 && nearest) {
		rc = markov_build_nearest(&c, &a, path);
		cli_common_free(&c);
		return rc;
	}
	if (rc < 0 && a.shards > 0 && cli_mpi_size() > 1)
		rc = cli_usage("markov build",
		               "--shard builds one part in one process: not under mpirun (%d "
		               "ranks)",
		               cli_mpi_size());
	/* flow entries in a job array: a round, one pass of the maps (a merge's
	 * command line is its parts') */
	const int round = a.def.self_entries == 2 && a.shards > 0;
	if (rc < 0 && a.passes && !round)
		rc = cli_usage("markov build",
		               "--passes %s: the merged directory of the round before, for "
		               "--entries flow or flow:N with --shard I/N",
		               a.passes);
	if (rc >= 0) {
		cli_common_free(&c);
		return rc;
	}
	if (!m && !p && cli_mpi_size() > 1) {
		rc = markov_build_ranks(argc, argv, &c);
		cli_common_free(&c);
		return rc;
	}
	/* an MPI job's progress: rank 0's part's */
	const int show_progress = !c.quiet && (!p || cli_mpi_rank() == 0);
	if (p) {
		c.out = p->out;
		c.quiet = 1;
		a.shard = p->shard;
		a.shards = p->shards;
	}
	bsim_markov_build_def def = bsim_markov_build_def_default();
	def.method = BSIM_MARKOV_METHOD_MAPS;
	if (m) {
		cli_merge_apply(m, &c);
		a.shard = a.shards = 0;
		def.merge = m->parts;
		def.n_merge = m->n_parts;
	}
	if (p && cli_mpi_size() > 1) /* flow entries: the ranks meet after each pass */
		a.def.pass_exchange = cli_mpi_pass_exchange;
	bsim_options opts = {0};
	const bsim_backend *be = cli_backend_with_opts(
	        &c, "markov build", c.backend ? c.backend : bsim_backend_default()->name, &opts);
	if (!be) {
		cli_common_free(&c);
		return CLI_USAGE;
	}
	def.map = a.def;
	def.map.backend = be;
	def.map.opts = &opts;
	def.map.threads = (int)c.threads;
	if (c.trials > 0)
		def.map.trials = (int)c.trials;
	build_inputs(&def, &c, path);
	def.entries = a.entries;
	def.n_entries = a.n_entries;
	def.part = a.shard;
	def.parts = a.shards;
	def.round = round;
	def.passes = a.passes;
	/* part.json's command line, its paths as they resolve from anywhere */
	const char *paths[2] = {path, a.passes};
	char **stored = a.shards > 0 ? cli_stored_argv_paths(argc, argv, paths, 2) : NULL;
	def.argc = stored ? argc : 0;
	def.argv = stored;
	if (!c.quiet) {
		def.group_done = build_group_print;
		def.group_done_user = &def;
	}
	cli_progress progress, training;
	cli_progress_init(&progress, show_progress, "single gates");
	cli_progress_init(&training, show_progress, "training trials");
	def.map.progress = cli_progress_update;
	def.map.progress_user = &progress;
	def.map.train_progress = train_progress_update;
	def.map.train_progress_user = &training;
	def.map.stop = &cli_stop;
	bsim_markov_build_result res;
	cli_signals_install();
	rc = a.shards > 0 && !stored ? bsim_error_set(&err, BSIM_EFAIL, "out of memory")
	                             : bsim_markov_build_run(&def, &res, &err);
	cli_progress_finish(&progress);
	cli_signals_restore();
	cli_stored_argv_free(stored, argc, argv);
	/* Each finished map is in the directory already: the same command
	 * reuses them and builds the rest. */
	if (rc == BSIM_ESTOPPED)
		rc = stopped(&err, "builds the rest");
	if (rc == BSIM_OK && !c.quiet)
		build_print(&def, &res, c.out);
	if (rc == BSIM_OK && res.scope[0]) /* quiet too: it is about the maps, not progress */
		cli_error("note: %s", res.scope);
	if (rc == BSIM_OK)
		bsim_markov_build_result_free(&res);
	cli_common_free(&c);
	return rc > BSIM_ESTOPPED ? rc : cli_report(rc, &err);
}

static int markov_build(int argc, char **argv)
{
	return markov_build_main(argc, argv, NULL, NULL);
}

int cmd_markov_merge(int argc, char **argv, const cli_merge *m)
{
	return markov_build_main(argc, argv, m, NULL);
}

/* What the chain's solution says beyond the locations. */
static void chain_print(const bsim_markov_prediction *p)
{
	if (p->n_gates > 0)
		printf("\ngates visited: mean %.2f (%d terms of the series)", p->mean_gates,
		       p->n_gates);
	else
		printf("\ngates visited: mean %.2f (expected visits)", p->mean_gates);
	if (!p->exact || p->left_in_field > 1e-12)
		printf(" (the %s stopped with %.2g still in the field)",
		       p->sweeps ? "sweeps" : "series", p->left_in_field);
	if (p->has_time)
		printf("\nexpected time to the outcome: %.2f s (first-step analysis, without the "
		       "trial's duration)\n",
		       p->mean_time);
	else
		printf("\nexpected time: none (maps built before holding times were kept: "
		       "beamsim markov build simulates them again)\n");
}

static void predict_print(const char *path, const bsim_markov_predict_result *r, const char *out,
                          int locations)
{
	static const char *const kinds[] = {"end", "side", "stuck"};
	const bsim_markov_prediction *p = &r->p;
	const double *total = r->total;
	if (p->nearest_walks > 0)
		printf("lattice     %s (%s): %d x %d gates, %d training fields (%d run now, "
		       "%.1f s of CPU when run), %d visits\n"
		       "walks       %ld, each step from the %d nearest visits (%.2f s of CPU)\n",
		       cli_path(path), r->scene.name, r->scene.lattice.columns,
		       r->scene.lattice.rows, r->n_maps, r->fields_built, r->fields_cost,
		       p->n_states, p->nearest_walks, p->nearest_k, r->cpu_seconds);
	else
		printf("lattice     %s (%s): %d x %d gates, %d maps, %d states (%s)\n",
		       cli_path(path), r->scene.name, r->scene.lattice.columns,
		       r->scene.lattice.rows, r->n_maps, p->n_states,
		       p->exact    ? "LU"
		       : p->sweeps ? "sweeps"
		                   : "series");
	printf("\nfinal location      p\n");
	for (int k = 0; k < 3; k++)
		printf("%-12s %7.4f\n", kinds[k], total[k]);
	printf("%-12s %7.4f\n", "(sum)", total[0] + total[1] + total[2]);
	if (p->nearest_walks > 0)
		printf("\ngates visited: mean %.2f; the walks' own sampling error: TV %.4f\n",
		       p->mean_gates, r->tv_walks);
	else
		chain_print(p);
	if (p->walks > 0) {
		printf("\nat the trial's duration, %g s (%ld walks of the semi-Markov chain; "
		       "their error on a p: at most %.4f):\n"
		       "outcome      p        mean time s   sd s\n",
		       p->duration, p->walks, 0.5 / sqrt((double)p->walks));
		for (int k = 0; k < 3; k++)
			printf("%-12s %7.4f  %10.2f  %8.2f\n", kinds[k], p->p_by[k], p->t_mean[k],
			       p->t_sd[k]);
	}
	if (locations) {
		printf("\nlocation       p\n");
		for (int i = 0; i < p->n_locations; i++) {
			if (p->p[i] < 5e-5)
				continue;
			char label[48];
			bsim_lattice_location_label(p->loc[i], label, sizeof label);
			printf("%-12s %7.4f\n", label, p->p[i]);
		}
	}
	if (!out)
		printf("per location: --locations prints them, --out DIR writes prediction.csv\n");
	else
		cli_wrote(stdout, out);
}

static int markov_predict(int argc, char **argv)
{
	cli_common c = cli_common_default();
	/* The default tolerance is the maps' sampling one (-1: from the maps,
	 * once read): the lean sweeps to it take under 5 ms of CPU on a 9 x 9
	 * field at 4,4,3 bins, where the series to 1e-6 took 24 ms. */
	markov_args a = {.def = bsim_markov_def_default(), .tol = -1.0, .walks = -1};
	const char *path = NULL;
	int rc = cli_parse(&predict_spec, argc, argv, &c, &a, &path);
	if (rc < 0 && !a.map == !a.visits)
		rc = cli_usage("markov predict", "expected one of --map DIR and --visits DIR");
	if (rc < 0 && a.map) {
		const char *alone = c.has_seed                      ? "--seed"
		                    : c.backend || c.n_backend_opts ? "--backend"
		                    : a.k                           ? "--k"
		                    : a.train                       ? "--train"
		                                                    : NULL;
		if (alone)
			rc = cli_usage("markov predict",
			               "%s is for --visits (the build in --map holds its own)",
			               alone);
	}
	int walks = 0;
	rc = map_walks(&a, rc, &walks);
	if (rc < 0 && !walks && c.threads)
		rc = cli_usage("markov predict",
		               "--threads is for the walks (the maps' solve is one "
		               "thread's)");
	if (rc < 0 && walks && (a.tol > 0 || a.no_gates || a.gates))
		rc = cli_usage("markov predict", "--tol, --gates and --no-gates are for maps");
	if (rc < 0 && walks && a.walks == 0)
		rc = cli_usage("markov predict",
		               "--walks 0: expected 1 or more nearest-neighbour walks");
	if (rc >= 0) {
		cli_common_free(&c);
		return rc;
	}
	bsim_markov_predict_def def = bsim_markov_predict_def_default();
	bsim_options opts = {0};
	cli_progress training;
	cli_progress_init(&training, !c.quiet && a.visits, "training trials");
	if (a.visits) {
		const bsim_backend *be = cli_backend_with_opts(
		        &c, "markov predict", c.backend ? c.backend : bsim_backend_default()->name,
		        &opts);
		if (!be) {
			cli_common_free(&c);
			return CLI_USAGE;
		}
		def.visits_dir = a.visits;
		nearest_apply(&a, &c, be, &opts, &def.nearest);
		if (c.has_seed)
			def.nearest.seed = c.seed;
		def.nearest.progress = train_progress_update;
		def.nearest.progress_user = &training;
		def.nearest.stop = &cli_stop;
	} else if (walks)
		build_walks_apply(&a, &c, &def.nearest);
	if (a.walks < 0)
		a.walks = BSIM_MARKOV_WALKS;
	def.scene = path;
	def.sets = c.sets.ov;
	def.n_sets = c.sets.n;
	def.map_dir = a.map;
	def.out = c.out;
	def.overwrite = c.overwrite;
	def.tol = a.tol;
	def.gates = a.no_gates ? 0 : a.gates ? 1 : -1;
	def.walks = a.walks;
	bsim_markov_predict_result r;
	bsim_error err;
	cli_signals_install();
	rc = bsim_markov_predict_run(&def, &r, &err);
	cli_signals_restore();
	cli_progress_finish(&training);
	if (rc == BSIM_ESTOPPED) {
		/* Each finished training field is in the directory already. */
		cli_common_free(&c);
		return stopped(&err, "runs the rest");
	}
	/* --quiet wins over --json: nothing on stdout. */
	if (rc == BSIM_OK && !c.quiet && a.json)
		bsim_markov_predict_json(stdout, path, &r);
	else if (rc == BSIM_OK && !c.quiet)
		predict_print(path, &r, c.out, a.locations);
	if (rc == BSIM_OK)
		bsim_markov_predict_result_free(&r);
	cli_common_free(&c);
	return cli_report(rc, &err);
}

static int markov_validate_main(int argc, char **argv, const cli_merge *m)
{
	cli_common c = cli_common_default();
	markov_args a = {.def = bsim_markov_def_default(), .bootstrap = -1};
	const char *path = NULL;
	char **stored = NULL;
	int rc = cli_parse(&validate_spec, argc, argv, &c, &a, &path);
	if (rc < 0 && !a.map == !a.visits)
		rc = cli_usage("markov validate", "expected one of --map DIR and --visits DIR");
	if (rc < 0 && a.map && (a.k || a.train || c.backend))
		rc = cli_usage("markov validate",
		               "--%s is for --visits (the build in --map holds its own)",
		               a.k       ? "k"
		               : a.train ? "train"
		                         : "backend");
	int walks = 0;
	rc = map_walks(&a, rc, &walks);
	if (rc < 0 && a.walks && !walks)
		rc = cli_usage("markov validate",
		               "--walks is for the walks (the maps in --map hold their own)");
	if (rc < 0 && a.shards > 0 && cli_mpi_size() > 1)
		rc = cli_usage("markov validate",
		               "--shard runs one part in one process: not under mpirun, "
		               "which spreads the whole validation over its %d ranks",
		               cli_mpi_size());
	if (rc >= 0) {
		cli_common_free(&c);
		return rc;
	}
	bsim_markov_validate_def def = bsim_markov_validate_def_default();
	if (m) {
		cli_merge_apply(m, &c);
		a.shard = a.shards = 0;
		def.spread.merge = m->parts;
		def.spread.n_merge = m->n_parts;
	}
	if (a.shards > 0) {
		const char *paths[2] = {path, a.map ? a.map : a.visits};
		def.spread.spread = BSIM_SPREAD_SHARD;
		def.spread.part.index = a.shard - 1;
		def.spread.part.count = a.shards;
		stored = cli_stored_argv_paths(argc, argv, paths, 2);
		def.spread.argc = stored ? argc : 0;
		def.spread.argv = stored;
	}
	int rank = cli_mpi_rank();
	def.resume = c.resume;
	def.overwrite = c.overwrite;
	def.stop = &cli_stop;
	cli_mpi_spread(&def.spread.spread, &def.spread.part, &def.spread.agree,
	               bsim_sweep_record_size(0), def.stop);
	def.experiment = path;
	def.map_dir = a.map;
	bsim_options nearest_opts = {0};
	if (a.visits) {
		const bsim_backend *be = cli_backend_with_opts(
		        &c, "markov validate", c.backend ? c.backend : bsim_backend_default()->name,
		        &nearest_opts);
		if (!be) {
			cli_stored_argv_free(stored, argc, argv);
			cli_common_free(&c);
			return CLI_USAGE;
		}
		def.visits_dir = a.visits;
		nearest_apply(&a, &c, be, &nearest_opts, &def.nearest);
		def.nearest.stop = &cli_stop;
	} else if (walks)
		build_walks_apply(&a, &c, &def.nearest);
	def.out = c.out;
	def.sets = c.sets.ov;
	def.n_sets = c.sets.n;
	def.grid = c.sets.grid;
	def.n_grid = c.sets.n_grid;
	def.trials = c.trials;
	def.has_seed = c.has_seed;
	def.seed = c.seed;
	def.threads = (int)c.threads;
	if (a.bootstrap >= 0)
		def.bootstrap = (int)a.bootstrap;
	cli_progress progress;
	cli_progress_init(&progress, !c.quiet && rank == 0, "trials");
	def.progress = rank == 0 ? cli_progress_update : NULL;
	def.progress_user = &progress;
	cli_progress training; /* the walks' training fields, before the trials */
	cli_progress_init(&training, !c.quiet && rank == 0 && a.visits, "training trials");
	def.nearest.progress = rank == 0 ? train_progress_update : NULL;
	def.nearest.progress_user = &training;
	bsim_markov_validation v;
	bsim_error err;
	cli_signals_install();
	rc = bsim_markov_validate(&def, &v, &err);
	cli_signals_restore();
	cli_progress_finish(&training);
	cli_progress_finish(&progress);
	cli_stored_argv_free(stored, argc, argv);
	if (rc != BSIM_OK || def.spread.spread == BSIM_SPREAD_SEND || a.shards > 0) {
		/* the resume line: "markov validate ...", argv[-1] "markov" (a
		 * merge's stored command line has no argv[-1]) */
		rc = cli_spread_end("markov validate", rc, &err, v.journal, m ? argc : argc + 1,
		                    m ? argv : argv - 1, a.shard, a.shards, c.out, c.quiet);
		bsim_markov_validation_free(&v);
		cli_common_free(&c);
		return rc;
	}
	if (rc == BSIM_OK && v.scope[0])
		cli_error("note: %s", v.scope);
	if (rc == BSIM_OK && !c.quiet) {
		char holds[96];
		bins_hold(v.of_crossings, v.per_crossing, v.trials_per_bin, holds, sizeof holds);
		if (walks)
			printf("visits      %s: nearest-neighbour walks, %ld of them, each step "
			       "from "
			       "the %d nearest visits;\n            training fields of %d trials, "
			       "%.1f s of CPU to run (%lld time steps)\n\n",
			       a.visits ? a.visits : a.map, v.nearest_walks, v.nearest_k,
			       v.nearest_trials, v.map_cost, v.map_steps);
		else
			printf("maps        %s: %d entry bins x %s, %.1f s of CPU to build "
			       "(%lld single-gate steps)\n\n",
			       a.map, v.bins, holds, v.map_cost, v.map_steps);
		/* the maps' sampling error, or with --visits the walks' own */
		printf("group protocol trials    TV  sampling (95%%) %5s   gates sim/chain  "
		       "sim CPU s  predict CPU s   speedup  pays off after\n",
		       walks ? "walks" : "map");
		for (int i = 0; i < v.n; i++) {
			const bsim_markov_check *k = &v.checks[i];
			/* the fields (predictions) after which the maps cost less
			 * than simulating each field directly at these trials */
			const double saved = k->sim_cpu - k->predict;
			char pays[32] = "never";
			if (saved > 0)
				snprintf(pays, sizeof pays, "%.0f fields",
				         ceil(v.map_cost / saved));
			printf("%5d %-8s %6d %5.3f  %5.3f (%5.3f)  %5.3f   %5.2f / %5.2f  %9.3f  "
			       "%13.2e  "
			       "%8.3g  %s\n",
			       k->group, k->protocol == BSIM_PROTOCOL_ESSAY ? "essay" : "world",
			       k->trials, k->tv, k->tv_sampling, k->tv_sampling95, k->tv_map,
			       k->gates_sim, k->gates_chain, k->sim_cpu, k->predict,
			       k->sim_cpu / k->predict, pays);
		}
		if (v.n > 0 && v.checks[0].has_time) {
			printf("\ntime to the outcome, trials out (end or side) by the trial's "
			       "duration (95%% intervals; the difference's without the maps' "
			       "sampling error):\n"
			       "group protocol  out sim [interval]      chain   mean t out sim s   "
			       " "
			       "chain s          difference s    sup|dP(out by t)| (sim's 95%%)\n");
			for (int i = 0; i < v.n; i++) {
				const bsim_markov_check *k = &v.checks[i];
				printf("%5d %-8s %6.4f [%6.4f, %6.4f] %6.4f  %7.2f +- %5.2f  %7.2f "
				       "+- "
				       "%5.2f  %+7.2f +- %5.2f  %6.4f (%6.4f)\n",
				       k->group,
				       k->protocol == BSIM_PROTOCOL_ESSAY ? "essay" : "world",
				       k->out_sim, k->out_sim_lo, k->out_sim_hi, k->out_chain,
				       k->t_out_sim, k->t_out_sim_ci, k->t_out_chain,
				       k->t_out_chain_ci, k->t_out_chain - k->t_out_sim,
				       k->t_out_diff_ci, k->t_ks, k->t_ks95);
			}
		}
		printf("\n");
		cli_wrote(stdout, c.out);
	}
	bsim_markov_validation_free(&v);
	cli_common_free(&c);
	return cli_report(rc, &err);
}

static int markov_validate(int argc, char **argv)
{
	return markov_validate_main(argc, argv, NULL);
}

int cmd_markov_validate_merge(int argc, char **argv, const cli_merge *m)
{
	return markov_validate_main(argc, argv, m);
}

int cmd_markov(int argc, char **argv)
{
	static const char *const subs[] = {"build", "predict", "validate"};
	if (argc < 2 || strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0) {
		FILE *f = argc < 2 ? stderr : stdout;
		fputs("Usage: beamsim markov build EXPERIMENT --out DIR [OPTIONS]\n"
		      "       beamsim markov predict LATTICE_SCENE --map DIR [OPTIONS]\n"
		      "       beamsim markov validate LATTICE_EXPERIMENT --map DIR --out DIR "
		      "[OPTIONS]\n"
		      "       beamsim markov SUBCOMMAND --help\n"
		      "\n"
		      "Predicts where a body ends in a gate lattice from single-gate maps: the\n"
		      "absorbing Markov chain of the essay's Sec. 3.3 (docs/markov.md).\n",
		      f);
		return argc < 2 ? CLI_USAGE : CLI_OK;
	}
	if (strcmp(argv[1], "build") == 0)
		return markov_build(argc - 1, argv + 1);
	if (strcmp(argv[1], "predict") == 0)
		return markov_predict(argc - 1, argv + 1);
	if (strcmp(argv[1], "validate") == 0)
		return markov_validate(argc - 1, argv + 1);
	const char *near = cli_nearest(argv[1], subs, 3);
	if (near)
		return cli_usage("markov", "unknown subcommand '%s'; did you mean '%s'?", argv[1],
		                 near);
	return cli_usage("markov", "unknown subcommand '%s' (expected build, predict or validate)",
	                 argv[1]);
}
