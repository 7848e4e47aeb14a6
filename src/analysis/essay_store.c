/* The essay comparison stored in an output directory (beamsim essay --out
 * DIR; beamsim/essay_compare.h): essay.csv, sensitivity.csv, their .mat
 * twins, essay.md and the figure, written as one set after every sweep. */
#include "beamsim/essay_compare.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "beamsim/limits.h"
#include "store/matlab.h"
#include "store/session.h"
#include "analysis/essay_internal.h"
#include "util/atomic_file.h"

/* A number, or an empty field for NaN (a trend has no essay value). */
static void num(FILE *f, const char *fmt, double v)
{
	if (isfinite(v))
		fprintf(f, fmt, v);
}

static int write_csv(const char *path, const bsim_essay_result *r, bsim_error *err)
{
	bsim_atomic_file o;
	int rc = bsim_atomic_file_open(&o, path, err);
	if (rc)
		return rc;
	fputs("figure,quantity,condition,mode,kind,expect,essay_value,essay_n,essay_count,"
	      "beamsim_value,beamsim_n,beamsim_count,ci_low,ci_high,diff_low,diff_high,test,"
	      "p_value,verdict\n",
	      o.f);
	for (int i = 0; i < r->n; i++) {
		const bsim_essay_row *w = &r->rows[i];
		int lv = w->kind == BSIM_ESSAY_LEVEL;
		fprintf(o.f, "%s,%s,%s,%s,%s,%s,", w->figure, w->quantity, w->condition, w->mode,
		        lv ? "level" : "trend", w->expect);
		num(o.f, "%.4f", w->essay_value);
		fprintf(o.f, ",%d,", w->essay_n);
		if (lv)
			fprintf(o.f, "%d", w->essay_count);
		fprintf(o.f, ",%.6g,%d,", w->value, w->n);
		if (lv)
			fprintf(o.f, "%d", w->count);
		fprintf(o.f, ",%.6g,%.6g,", w->ci_lo, w->ci_hi);
		num(o.f, "%.6g", w->diff_lo);
		fputc(',', o.f);
		num(o.f, "%.6g", w->diff_hi);
		fprintf(o.f, ",%s,%.4g,%s\n", w->test, w->p,
		        w->consistent ? "consistent" : "differs");
	}
	return bsim_atomic_file_commit(&o, err);
}

static int write_sens_csv(const char *path, const bsim_essay_result *r, bsim_error *err)
{
	bsim_atomic_file o;
	int rc = bsim_atomic_file_open(&o, path, err);
	if (rc)
		return rc;
	fputs("parameter,value,shipped,condition,mode,n,traversed,left,right,side_exit,stuck,"
	      "p_traverse,ci_low,ci_high,essay_value,reaches_essay\n",
	      o.f);
	for (int i = 0; i < r->n_sens; i++) {
		const bsim_essay_sens_row *w = &r->sens[i];
		fprintf(o.f, "%s,%s,%d,%s,%s,%d,%d,%d,%d,%d,%d,%.4f,%.4f,%.4f,%.2f,%d\n",
		        w->parameter, w->value, w->is_default, w->condition, w->mode, w->n,
		        w->traversed, w->left, w->right, w->side_exit, w->stuck, w->p, w->lo, w->hi,
		        w->essay_value, w->reaches);
	}
	return bsim_atomic_file_commit(&o, err);
}

static void md_num(FILE *f, const bsim_essay_row *w, double v)
{
	if (w->kind == BSIM_ESSAY_LEVEL)
		fprintf(f, "%.3f", v);
	else
		fprintf(f, "%+.3f", v);
}

static int write_md(const char *path, const bsim_essay_result *r, const bsim_essay_config *cfg,
                    bsim_error *err)
{
	bsim_atomic_file o;
	int rc = bsim_atomic_file_open(&o, path, err);
	if (rc)
		return rc;
	FILE *f = o.f;
	fprintf(f,
	        "# The essay's numbers and trends against beamsim\n\n"
	        "Backend %s, seed %llu, %d trials a single-gate group, %d of the C-track "
	        "(the essay: 100 and 20). %ld trials in %.1f s.\n\n"
	        "A level is `consistent` when Fisher's exact test of beamsim's count against the "
	        "essay's (value x n) gives p >= 0.05; a trend when beamsim's estimate has the "
	        "stated sign and its test gives p < 0.05 (Cochran-Armitage for a slope, a Wald z "
	        "test for a change of a difference). Intervals are 95%%: Wilson for a level, "
	        "Wald for a trend; `beamsim - essay` is Newcombe's hybrid score interval.\n\n",
	        cfg->backend, (unsigned long long)cfg->seed, cfg->trials, cfg->lattice_trials,
	        r->trials_run, r->wall_seconds);
	fputs("| figure | quantity | condition | mode | essay | beamsim [95%] | beamsim - essay "
	      "[95%] | p | verdict |\n|---|---|---|---|---|---|---|---|---|\n",
	      f);
	for (int i = 0; i < r->n; i++) {
		const bsim_essay_row *w = &r->rows[i];
		fprintf(f, "| %s | %s | %s | %s | ", w->figure, w->quantity, w->condition, w->mode);
		if (w->kind == BSIM_ESSAY_LEVEL)
			fprintf(f, "%.2f (%d/%d)", w->essay_value, w->essay_count, w->essay_n);
		else
			fprintf(f, "%s", w->expect);
		fputs(" | ", f);
		md_num(f, w, w->value);
		fputs(" [", f);
		md_num(f, w, w->ci_lo);
		fputs(", ", f);
		md_num(f, w, w->ci_hi);
		fputs("] | ", f);
		if (w->kind == BSIM_ESSAY_LEVEL)
			fprintf(f, "%+.3f [%+.3f, %+.3f]", w->value - w->essay_value, w->diff_lo,
			        w->diff_hi);
		fprintf(f, " | %.2g | %s |\n", w->p, w->consistent ? "consistent" : "**differs**");
	}
	if (r->n_sens > 0) {
		fprintf(f,
		        "\n## Sensitivity of the symmetric levels (%d trials a group)\n\n"
		        "p_traverse at k1 = k2 = 500 against the essay's total; `reaches` when "
		        "beamsim's 95%% interval reaches the essay's value. `*` marks the shipped "
		        "value.\n\n"
		        "| parameter | value | condition | mode | p_traverse [95%%] | left / right "
		        "/ "
		        "side exit / stuck | essay | reaches "
		        "|\n|---|---|---|---|---|---|---|---|\n",
		        cfg->sens_trials);
		for (int i = 0; i < r->n_sens; i++) {
			const bsim_essay_sens_row *w = &r->sens[i];
			fprintf(f,
			        "| %s | %s%s | %s | %s | %.3f [%.3f, %.3f] | %d / %d / %d / %d | "
			        "%.2f | %s |\n",
			        w->parameter, w->value, w->is_default ? "*" : "", w->condition,
			        w->mode, w->p, w->lo, w->hi, w->left, w->right, w->side_exit,
			        w->stuck, w->essay_value, w->reaches ? "yes" : "no");
		}
	}
	return bsim_atomic_file_commit(&o, err);
}

static int write_table(const char *stage, const char *name,
                       int (*write)(const char *, const bsim_essay_result *, bsim_error *),
                       const bsim_essay_result *r, bsim_error *err)
{
	char path[BSIM_PATH_MAX], mat[BSIM_PATH_MAX];
	snprintf(path, sizeof path, "%s/%s.csv", stage, name);
	snprintf(mat, sizeof mat, "%s/%s.mat", stage, name);
	int rc = write(path, r, err);
	if (rc == BSIM_OK)
		rc = bsim_matlab_from_csv(path, mat, name, err);
	return rc;
}

int bsim_essay_compare_store(const char *out, const bsim_essay_config *cfg, bsim_essay_result *res,
                             bsim_figures_result *fig, bsim_error *err)
{
	memset(res, 0, sizeof *res);
	memset(fig, 0, sizeof *fig);
	const bsim_sweep_spread *sp = &cfg->spread;
	sweep_batch sb = {.command = "essay",
	                  .out = out,
	                  .resume = cfg->resume,
	                  .overwrite = cfg->overwrite,
	                  .spread = sp->spread != BSIM_SPREAD_NONE || sp->n_merge > 0 ? sp : NULL,
	                  .progress = cfg->progress,
	                  .progress_user = cfg->progress_user,
	                  .stop = cfg->stop};
	int rc = bsim_essay_compare_batch(cfg, &sb, res, err);
	const char *stage = sb.ss.stage;
	if (rc == BSIM_OK && sb.writes)
		rc = write_table(stage, "essay", write_csv, res, err);
	if (rc == BSIM_OK && sb.writes && res->n_sens > 0)
		rc = write_table(stage, "sensitivity", write_sens_csv, res, err);
	if (rc == BSIM_OK && sb.writes) {
		char path[BSIM_PATH_MAX];
		snprintf(path, sizeof path, "%s/essay.md", stage);
		rc = write_md(path, res, cfg, err);
	}
	if (rc == BSIM_OK && sb.writes) {
		bsim_figures_def def = bsim_figures_def_default();
		def.kind = BSIM_FIGURES_ESSAY;
		rc = bsim_figures_draw(stage, &def, fig, err);
		/* the tables are kept beside a figure gnuplot failed on */
		rc = bsim_session_defer(&sb.ss, rc, fig->failed > 0, err);
	}
	rc = bsim_sweep_batch_end(&sb, rc, err);
	if (rc != BSIM_OK) {
		bsim_figures_result_free(fig);
		bsim_essay_result_free(res);
	}
	snprintf(res->journal, sizeof res->journal, "%s", sb.journal);
	return rc;
}
