/* What the fuzz targets share: a scratch directory for the input file
 * (the loaders under test read files, as the program does), and the checks
 * every outcome must pass. */
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

/* A loader's failure must be one readable line with a code: aborts (a
 * finding) if rc is not BSIM_EINPUT or BSIM_EFAIL or the message is empty
 * or not one line. */
void fuzz_check_error(int rc, const bsim_error *err);

/* Runs a few hundred steps of the scene on both backends: a scene the
 * loader accepts must not crash a backend or be undefined behaviour. */
void fuzz_run_scene(const bsim_scene *s);

/* Set by replay_main -v: each input's outcome on stdout, "accepted" or the
 * loader's message. */
extern int fuzz_verbose;

/* Notes an accepted input (if fuzz_verbose). */
void fuzz_accepted(void);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#endif
