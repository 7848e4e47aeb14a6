/* beamsim plot (figures.h): what a directory holds, and the kind's
 * figures drawn (figures_kinds.h). */
#define _POSIX_C_SOURCE 200809L
#include "beamsim/figures.h"

#include <omp.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "beamsim/output.h"
#include "util/figure.h"
#include "figures/figures_kinds.h"
#include "figures/figures_toolkit.h"
#include "beamsim/limits.h"

const char *bsim_figures_kind_name(bsim_figures_kind k)
{
	static const char *names[] = {"auto", "sweep", "compare", "run", "accuracy", "essay"};
	return (unsigned)k < 6 ? names[k] : "?";
}

bsim_figures_def bsim_figures_def_default(void)
{
	bsim_figures_def d = {.kind = BSIM_FIGURES_AUTO};
	return d;
}

void bsim_figures_result_free(bsim_figures_result *r)
{
	for (int i = 0; i < r->n; i++)
		free(r->paths[i]);
	for (int i = 0; i < r->n_notes; i++)
		free(r->notes[i]);
	free(r->paths);
	free(r->notes);
	free(r->selection);
	memset(r, 0, sizeof *r);
}

static int has(const char *dir, const char *file)
{
	char path[BSIM_PATH_MAX];
	struct stat st;
	snprintf(path, sizeof path, "%s/%s", dir, file);
	return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

static bsim_figures_kind recognise(const char *dir)
{
	if (has(dir, "report.json") && has(dir, "pairs.csv"))
		return BSIM_FIGURES_COMPARE;
	if (has(dir, "summary.json") && has(dir, "trials.csv"))
		return BSIM_FIGURES_SWEEP;
	if (has(dir, "trajectory.csv") && has(dir, "ledger.csv"))
		return BSIM_FIGURES_RUN;
	if (has(dir, "accuracy.csv"))
		return BSIM_FIGURES_ACCURACY;
	if (has(dir, "essay.csv"))
		return BSIM_FIGURES_ESSAY;
	return BSIM_FIGURES_AUTO;
}

int bsim_figures_draw(const char *dir, const bsim_figures_def *def, bsim_figures_result *out,
                      bsim_error *err)
{
	memset(out, 0, sizeof *out);
	bsim_figures_def d = def ? *def : bsim_figures_def_default();
	if (strlen(dir) > BSIM_DIR_MAX || (d.out && strlen(d.out) > BSIM_DIR_MAX))
		return bsim_error_set(err, BSIM_EINPUT, "%s: path too long", dir);
	struct stat st;
	if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode))
		return bsim_error_set(err, BSIM_EINPUT, "%s: no such directory", dir);
	bsim_figures_kind kind = d.kind ? d.kind : recognise(dir);
	if (kind == BSIM_FIGURES_AUTO)
		return bsim_error_set(
		        err, BSIM_EINPUT,
		        "%s: no output of beamsim found (expected summary.json and "
		        "trials.csv of a sweep, report.json and pairs.csv of compare, "
		        "trajectory.csv and ledger.csv of run --out, accuracy.csv or essay.csv)",
		        dir);
	figs_failure failure = {.name = ""};
	figs f = {
	        .out = d.out ? d.out : dir,
	        .def = &d,
	        .res = out,
	        .threads = d.threads > 0 ? d.threads : omp_get_max_threads(),
	        .failure = &failure,
	};
	out->kind = kind;
	int rc = bsim_output_mkdir(f.out, err);
	if (rc)
		return rc;
	char inputs[BSIM_PATH_MAX];
	snprintf(inputs, sizeof inputs, "%s/inputs", dir);
	switch (kind) {
	case BSIM_FIGURES_SWEEP:
		rc = bsim_figs_sweep(&f, dir, inputs, err);
		break;
	case BSIM_FIGURES_COMPARE:
		rc = bsim_figs_compare(&f, dir, err);
		break;
	case BSIM_FIGURES_RUN:
		rc = bsim_figs_run(&f, dir, err);
		break;
	case BSIM_FIGURES_ACCURACY:
		rc = bsim_figs_accuracy(&f, dir, err);
		break;
	case BSIM_FIGURES_ESSAY:
		rc = bsim_figs_essay(&f, dir, err);
		break;
	default:
		break;
	}
	if (rc == BSIM_OK && out->failed > 0)
		return bsim_error_set(err, BSIM_EFAIL, "%s%s", failure.err.msg,
		                      out->failed > 1 ? " (and more figures gnuplot failed on)"
		                                      : "");
	if (rc == BSIM_OK && out->n > 0 && out->drawn < out->n)
		bsim_figs_note(&f, "%s", bsim_figure_missing_hint());
	return rc;
}
