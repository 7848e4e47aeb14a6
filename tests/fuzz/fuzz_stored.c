/* Fuzz target: the readers of beamsim's stored output directories. The
 * first input byte chooses a file of one of five small valid directories
 * (tests/fuzz/stored: a sweep with kept trajectories, a comparison, a run
 * --out, a 3 x 3 lattice sweep and an accuracy study, as beamsim wrote
 * them); the rest of the input replaces it, with the manifest's entry for
 * it updated to match (the manifest itself is one of the files). The
 * directory is then read by everything that reads one: the manifest check,
 * run.json of a sweep or comparison (bsim_run_record_read), the stored sweep or each side of the
 * comparison (bsim_sweep_dir_read: run.json, inputs/, trials.csv),
 * beamsim plot's readers (bsim_figures_draw, gnuplot kept off the PATH so
 * only the data and scripts are written: summary.json, trials.csv,
 * trajectories.csv, report.json, pairs.csv, trajectory.csv, ledger.csv,
 * accuracy.csv, the lattice's CSVs) and, for every other value of the
 * byte's bit above the choice, beamsim regress (which reruns the few
 * stored trials and compares). */
#define _POSIX_C_SOURCE 200809L

#include "fuzz_common.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/figures.h"
#include "beamsim/regress.h"
#include "beamsim/run_record.h"
#include "beamsim/sweep_dir.h"
#include "store/outdir.h"

enum { SWEEP, COMPARE, RUN, LATTICE, ACCURACY, N_DIRS };
static const char *const names[N_DIRS] = {"sweep", "compare", "run", "lattice", "accuracy"};
static fuzz_fixture dirs[N_DIRS];
static int n_files;
static char figs[300], rerun[300];

static void setup(void)
{
	/* Figures without gnuplot: bsim_figure_available looks on the PATH. */
	setenv("PATH", "/nonexistent-beamsim-fuzz", 1);
	for (int k = 0; k < N_DIRS; k++) {
		fuzz_fixture_open(&dirs[k], names[k]);
		n_files += dirs[k].n;
	}
	snprintf(figs, sizeof figs, "%s/figures", fuzz_dir());
	snprintf(rerun, sizeof rerun, "%s/regress", fuzz_dir());
}

static void check(int rc, const bsim_error *err)
{
	if (rc != BSIM_OK)
		fuzz_check_error(rc, err);
	else
		fuzz_accepted();
}

static void read_dir(int k, int regress)
{
	const char *dir = dirs[k].root;
	bsim_error err;
	bsim_error_clear(&err);
	int has_manifest;
	check(bsim_outdir_verify(dir, &has_manifest, &err), &err);

	if (k != RUN && k != ACCURACY) {
		bsim_run_record rec;
		bsim_error_clear(&err);
		check(bsim_run_record_read(dir, &rec, &err), &err);
	}

	static const char *const sides[] = {"thesis", "box2d"};
	for (int s = 0; (k == SWEEP || k == LATTICE || k == COMPARE) && s < (k == COMPARE ? 2 : 1);
	     s++) {
		bsim_sweep_dir_result res;
		bsim_error_clear(&err);
		int rc = bsim_sweep_dir_read(dir, k == COMPARE ? sides[s] : NULL, &res, &err);
		check(rc, &err);
		if (rc == BSIM_OK)
			bsim_sweep_dir_result_free(&res);
	}

	bsim_figures_def def = bsim_figures_def_default();
	def.out = figs;
	def.threads = 1;
	bsim_figures_result fig;
	bsim_error_clear(&err);
	check(bsim_figures_draw(dir, &def, &fig, &err), &err);
	bsim_figures_result_free(&fig);

	if (regress && k != RUN && k != ACCURACY) {
		bsim_regress_def rd = bsim_regress_def_default();
		rd.baseline = dir;
		rd.out = rerun;
		rd.threads = 1;
		bsim_regress_result rr;
		bsim_error_clear(&err);
		int rc = bsim_regress_run(&rd, &rr, &err);
		check(rc, &err);
		if (rc == BSIM_OK)
			bsim_regress_result_free(&rr);
	}
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	if (!n_files)
		setup();
	if (size == 0)
		return 0;
	int i = data[0] % n_files, k = 0;
	int regress = (data[0] / n_files) % 2;
	while (i >= dirs[k].n)
		i -= dirs[k++].n;
	for (int j = 0; j < N_DIRS; j++)
		fuzz_fixture_replace(&dirs[j], j == k ? i : -1, data + 1, size - 1);
	read_dir(k, regress);
	return 0;
}
