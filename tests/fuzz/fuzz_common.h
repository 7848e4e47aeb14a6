/* What the fuzz targets share: a scratch directory for the input file
 * (the loaders under test read files, as the program does), small stored
 * output directories to start from, and the checks every outcome must
 * pass. */
#ifndef BSIM_FUZZ_FUZZ_COMMON_H
#define BSIM_FUZZ_FUZZ_COMMON_H

#include <stddef.h>
#include <stdint.h>

#include "beamsim/error.h"
#include "beamsim/scene.h"

/* The scratch directory (created once per process, removed at exit),
 * holding a copy of the essay's gate as gate.yaml for experiments to name. */
const char *fuzz_dir(void);

/* Writes data to fuzz_dir()/name and returns the path (static buffer). */
const char *fuzz_write(const char *name, const uint8_t *data, size_t size);

/* A small valid output directory of beamsim (tests/fuzz/stored/NAME, the
 * files beamsim wrote, without their .mat twins), copied into the scratch
 * directory once; each input then replaces one of its files. */
#define FUZZ_FIXTURE_FILES 32

typedef struct fuzz_file {
	char rel[300];  /* the path in the directory, "inputs/scene.yaml" */
	char path[700]; /* the copy's path */
	uint8_t *data;  /* the original bytes */
	size_t size;
} fuzz_file;

typedef struct fuzz_fixture {
	char root[300]; /* the copy */
	int n;
	fuzz_file file[FUZZ_FIXTURE_FILES]; /* sorted by rel */
	int manifest;                       /* the index of manifest.json, -1: none */
	int dirty[FUZZ_FIXTURE_FILES];      /* differs from the original */
} fuzz_fixture;

/* Copies tests/fuzz/stored/name into fuzz_dir()/name (aborts on error). */
void fuzz_fixture_open(fuzz_fixture *fx, const char *name);

/* Puts back the files the last input changed, then replaces file i (i <
 * 0: none) with data and makes manifest.json's entry for it (its size
 * and CRC-32) match, so that the readers get past their manifest check
 * to the file. */
void fuzz_fixture_replace(fuzz_fixture *fx, int i, const uint8_t *data, size_t size);

/* A loader's failure must be one readable line with a code: aborts (a
 * finding) if rc is not BSIM_EINPUT or BSIM_EFAIL or the message is empty
 * or not one line. */
void fuzz_check_error(int rc, const bsim_error *err);

/* Runs a few hundred steps of the scene on both backends: a scene the
 * loader accepts must not crash a backend or be undefined behaviour. */
void fuzz_run_scene(const bsim_scene *s);

/* Loads the scene file at path with the overrides, as `beamsim run` does:
 * a refusal goes through fuzz_check_error, an accepted scene is noted and
 * run (fuzz_run_scene). */
void fuzz_load_and_run(const char *path, const bsim_override *ov, int n_ov);

/* Set by replay_main -v: each input's outcome on stdout, "accepted" or the
 * loader's message. */
extern int fuzz_verbose;

/* Notes an accepted input (if fuzz_verbose). */
void fuzz_accepted(void);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#endif
