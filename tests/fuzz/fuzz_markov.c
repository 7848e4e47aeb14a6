/* Fuzz target: the files `beamsim markov predict` and `markov validate`
 * read. The first input byte chooses a file of a small valid map
 * directory (tests/fuzz/stored/markov, made by `beamsim markov build` for
 * the 3 x 3 lattice of tests/fuzz/stored/lattice: markov.json and each
 * map's .csv, .key, .cost and .hold.csv) or a gate_entries.csv (what --entries
 * reads); the rest of the input replaces it. The maps are then loaded for
 * the lattice and, if accepted, the chain is solved; an entries file is
 * read as --entries reads it. */
#include "fuzz_common.h"

#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>

#include "beamsim/markov.h"
#include "beamsim/options.h"

static fuzz_fixture maps;
static bsim_scene lattice;
static char entries_dir[300];

static void setup(void)
{
	fuzz_fixture_open(&maps, "markov");
	bsim_error err;
	char path[300];
	snprintf(path, sizeof path, "%s/lattice/inputs/scene.yaml", BSIM_FUZZ_STORED);
	if (bsim_scene_load(path, NULL, 0, &lattice, &err) != BSIM_OK) {
		fprintf(stderr, "fuzz: %s\n", err.msg);
		abort();
	}
	snprintf(entries_dir, sizeof entries_dir, "%s/entries", fuzz_dir());
	mkdir(entries_dir, 0700);
}

static void predict(void)
{
	bsim_options opts;
	bsim_markov_set set;
	bsim_error err;
	bsim_error_clear(&err);
	int rc = bsim_markov_load(&lattice, maps.root, &opts, &set, &err);
	if (rc != BSIM_OK) {
		fuzz_check_error(rc, &err);
		return;
	}
	bsim_markov_prediction p;
	rc = bsim_markov_predict(&lattice, &set, &p, &err);
	if (rc == BSIM_OK && p.has_time) /* the holding times, walked */
		rc = bsim_markov_predict_time(&lattice, &set, 200, 1, &p, &err);
	if (rc != BSIM_OK)
		fuzz_check_error(rc, &err);
	else
		fuzz_accepted();
	bsim_markov_prediction_free(&p);
	bsim_markov_set_free(&set);
}

static void entries(const uint8_t *data, size_t size)
{
	char name[320];
	snprintf(name, sizeof name, "entries/gate_entries.csv");
	fuzz_write(name, data, size);
	const char *paths[1] = {entries_dir};
	bsim_markov_entries e;
	bsim_error err;
	bsim_error_clear(&err);
	int rc = bsim_markov_entries_load(paths, 1, &e, &err);
	if (rc != BSIM_OK) {
		fuzz_check_error(rc, &err);
		return;
	}
	fuzz_accepted();
	bsim_markov_entries_free(&e);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	if (!maps.root[0])
		setup();
	if (size == 0)
		return 0;
	int i = data[0] % (maps.n + 1);
	if (i == maps.n) {
		fuzz_fixture_replace(&maps, -1, NULL, 0);
		entries(data + 1, size - 1);
	} else {
		fuzz_fixture_replace(&maps, i, data + 1, size - 1);
		predict();
	}
	return 0;
}
