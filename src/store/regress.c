/* A stored run repeated and compared; see beamsim/regress.h. */
#define _POSIX_C_SOURCE 200809L

#include "beamsim/regress.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "beamsim/backend_registry.h"
#include "beamsim/compare_dir.h"
#include "beamsim/effects.h"
#include "beamsim/output.h"
#include "beamsim/report.h"
#include "beamsim/sweep_dir.h"
#include "beamsim/version.h"
#include "util/json.h"
#include "store/session.h"
#include "store/rerun.h"
#include "store/store.h"
#include "beamsim/limits.h"

bsim_regress_def bsim_regress_def_default(void)
{
	bsim_regress_def d;
	memset(&d, 0, sizeof d);
	d.alpha = -1.0;
	d.margin = -1.0;
	return d;
}

/* The stored record, its backends and its experiment. */
static int regress_load(const bsim_regress_def *def, bsim_regress_result *res,
                        const bsim_backend **backend, bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	int has_manifest = 0;
	if (bsim_outdir_verify(def->baseline, &has_manifest, err) != BSIM_OK ||
	    bsim_run_record_read(def->baseline, &res->rec, err) != BSIM_OK)
		return BSIM_EINPUT;
	for (int i = 0; i < res->rec.n_backends; i++) {
		backend[i] = bsim_run_record_backend(&res->rec, i, err);
		if (!backend[i] ||
		    bsim_options_check(&res->rec.opts[i], backend[i]->knobs, backend[i]->n_knobs,
		                       backend[i]->name, err) != BSIM_OK)
			return BSIM_EINPUT;
	}
	if (bsim_session_path(path, sizeof path, def->baseline, "inputs/experiment.yaml", err))
		return BSIM_EINPUT;
	int rc = bsim_store_experiment(path, NULL, 0, NULL, 0, res->rec.trials, NULL, &res->e, err);
	if (rc != BSIM_OK)
		return rc;
	res->e.seed = res->rec.seed;
	return BSIM_OK;
}

/* The rerun into stage, written as the original command writes it. */
/* A stored comparison's record (else a sweep's). */
static int is_comparison(const bsim_run_record *rec)
{
	return strcmp(rec->command, "compare") == 0;
}

static int regress_rerun(const bsim_regress_def *def, bsim_regress_result *res,
                         const bsim_backend *const *backend, const char *stage, bsim_error *err)
{
	const bsim_run_record *rec = &res->rec;
	if (is_comparison(rec)) {
		bsim_compare_dir_def d = bsim_compare_dir_def_default();
		d.n_sides = rec->n_backends;
		for (int i = 0; i < rec->n_backends; i++) {
			d.side[i].backend = backend[i];
			d.side[i].opts = rec->opts[i];
			snprintf(d.side[i].label, sizeof d.side[i].label, "%s", rec->label[i]);
			/* a side read from a file: the same file, its hash checked */
			snprintf(d.side[i].trials, sizeof d.side[i].trials, "%s",
			         rec->read_from[i]);
			snprintf(d.side[i].trials_hash, sizeof d.side[i].trials_hash, "%s",
			         rec->read_hash[i]);
			if (i < 2) /* --protocols: two sides */
				d.protocol[i] = rec->protocol[0][0] ? rec->protocol[i] : NULL;
		}
		d.threads = def->threads;
		d.rule = rec->rule;
		d.progress = def->progress;
		d.progress_user = def->progress_user;
		bsim_compare_dir_result r;
		int rc = bsim_store_compare_rerun(&d, &res->e, stage, &r, err);
		if (rc == BSIM_OK)
			bsim_compare_sides_free(&r.cmp);
		return rc;
	}
	bsim_sweep_dir_def d = bsim_sweep_dir_def_default();
	d.backend = backend[0];
	d.opts = rec->opts[0];
	d.threads = def->threads;
	d.progress = def->progress;
	d.progress_user = def->progress_user;
	bsim_sweep_result r;
	int rc = bsim_store_sweep_rerun(&d, &res->e, stage, &r, err);
	if (rc == BSIM_OK)
		bsim_sweep_result_free(&r);
	return rc;
}

/* Side i's trials in dir (a sweep's directory, or the side's in a
 * comparison's), with the groups without random draws marked: each is one
 * trial, compared as one pair (beamsim/compare.h). */
static int side_read(const bsim_regress_result *res, const char *dir, int i, bsim_sweep_result *r,
                     bsim_error *err)
{
	char path[BSIM_PATH_MAX], sub[BSIM_PATH_MAX];
	if (is_comparison(&res->rec)) {
		char name[128];
		bsim_compare_dir_label(res->rec.label[i], name, sizeof name);
		if (bsim_session_path(sub, sizeof sub, dir, name, err))
			return BSIM_EFAIL;
		dir = sub;
	}
	if (bsim_session_path(path, sizeof path, dir, "trials.csv", err))
		return BSIM_EFAIL;
	int rc = bsim_output_trials_read(path, res->e.n_groups, res->e.trials, r, err);
	if (rc != BSIM_OK)
		return rc;
	for (int g = 0; g < res->e.n_groups; g++) {
		bsim_scene s;
		if ((rc = bsim_experiment_group_scene(&res->e, g, NULL, 0, &s, err)) != BSIM_OK) {
			bsim_sweep_result_free(r);
			return rc;
		}
		r->groups[g].deterministic = !bsim_effects_random(&s);
		bsim_scene_free(&s);
	}
	return BSIM_OK;
}

static int trials_changed(const bsim_sweep_result r[2])
{
	int changed = 0, known = bsim_compare_known(&r[0], &r[1]);
	for (long i = 0; i < (long)r[0].n_groups * r[0].trials; i++)
		changed += !bsim_compare_identical(&r[0].trials_out[i], &r[1].trials_out[i], known);
	return changed;
}

typedef struct regress_files {
	const bsim_regress_def *def;
	const bsim_regress_result *res;
	bsim_report rep[BSIM_COMPARE_SIDES_MAX];
} regress_files;

static void regress_md(FILE *f, const void *arg)
{
	const regress_files *w = arg;
	const bsim_regress_result *res = w->res;
	fprintf(f,
	        "# beamsim regress\n\nBaseline `%s` (%s by beamsim %s), rerun `%s` by beamsim "
	        "%s: experiment `%s`, seed %llu, %d groups x %d trials.\n\n",
	        w->def->baseline, res->rec.command, res->rec.version, w->def->out, bsim_version(),
	        res->e.path, (unsigned long long)res->e.seed, res->e.n_groups, res->e.trials);
	for (int i = 0; i < res->n_sides; i++) {
		fprintf(f, "## %s\n\n", res->side[i].label);
		if (res->rec.read_from[i][0])
			fprintf(f,
			        "Read, not run: `%s` again, the bytes the comparison read (FNV-1a "
			        "64 "
			        "%s).\n\n",
			        res->rec.read_from[i], res->rec.read_hash[i]);
		fprintf(f, "%d of %d trials changed in some trials.csv field.\n\n",
		        res->side[i].changed, res->side[i].trials);
		bsim_report_md(f, &w->rep[i]);
	}
}

static void regress_json(FILE *f, const void *arg)
{
	const regress_files *w = arg;
	fputs("{\"baseline_version\": ", f);
	bsim_json_string(f, w->res->rec.version);
	fputs(", \"version\": ", f);
	bsim_json_string(f, bsim_version());
	fputs(", \"backends\": [\n", f);
	for (int i = 0; i < w->res->n_sides; i++) {
		fputs(i ? ",\n" : "", f);
		bsim_report_json(f, &w->rep[i]);
	}
	fputs("]}\n", f);
}

/* Each side's stored and rerun trials compared, and the two files. */
static int regress_compare(const bsim_regress_def *def, bsim_regress_result *res,
                           const bsim_backend *const *backend, const char *stage, bsim_error *err)
{
	bsim_sweep_result r[BSIM_COMPARE_SIDES_MAX][2];
	regress_files w = {.def = def, .res = res};
	bsim_override protocol_b = {"lattice.protocol", res->rec.protocol[1],
	                            "--protocols (side b)"};
	bsim_compare_rule rule = res->rec.rule;
	if (def->alpha >= 0.0)
		rule.alpha = def->alpha;
	if (def->margin >= 0.0)
		rule.margin = def->margin;
	rule.exact |= def->exact;
	memset(r, 0, sizeof r);
	int rc = BSIM_OK;
	for (int n = 0; n < res->rec.n_backends && rc == BSIM_OK; n++) {
		bsim_regress_side *p = &res->side[n];
		snprintf(p->label, sizeof p->label, "%s", res->rec.label[n]);
		p->trials = res->e.n_groups * res->e.trials;
		rc = side_read(res, def->baseline, n, &r[n][0], err);
		if (rc == BSIM_OK && (rc = side_read(res, stage, n, &r[n][1], err)) != BSIM_OK)
			bsim_sweep_result_free(&r[n][0]);
		if (rc != BSIM_OK)
			break;
		res->n_sides = n + 1;
		p->changed = trials_changed(r[n]);
		rc = bsim_compare_analyse(&r[n][0], &r[n][1], NULL, &rule, &p->cmp, err);
		if (rc != BSIM_OK)
			rc = BSIM_EFAIL;
		int side_b = n == 1 && res->rec.protocol[1][0];
		w.rep[n] = (bsim_report){
		        .e = &res->e,
		        .extra = side_b ? &protocol_b : NULL,
		        .n_extra = side_b,
		        .side = {{"baseline", backend[n], &res->rec.opts[n], &r[n][0], NULL},
		                 {"rerun", backend[n], &res->rec.opts[n], &r[n][1], NULL}},
		        .cmp = &p->cmp,
		        .examples = 3,
		};
		res->beyond += p->cmp.n_disagree;
	}
	if (rc == BSIM_OK)
		rc = bsim_store_text(stage, "regress.json", NULL, regress_json, &w, err);
	if (rc == BSIM_OK)
		rc = bsim_store_text(stage, "regress.md", NULL, regress_md, &w, err);
	for (int n = 0; n < res->n_sides; n++) {
		bsim_sweep_result_free(&r[n][0]);
		bsim_sweep_result_free(&r[n][1]);
	}
	return rc;
}

void bsim_regress_result_free(bsim_regress_result *res)
{
	for (int i = 0; i < BSIM_COMPARE_SIDES_MAX; i++)
		bsim_compare_free(&res->side[i].cmp);
	bsim_experiment_free(&res->e);
	memset(res, 0, sizeof *res);
}

int bsim_regress_run(const bsim_regress_def *def, bsim_regress_result *res, bsim_error *err)
{
	memset(res, 0, sizeof *res);
	struct stat sb, so;
	if (stat(def->baseline, &sb) == 0 && stat(def->out, &so) == 0 && sb.st_ino == so.st_ino &&
	    sb.st_dev == so.st_dev)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "--out %s: expected a directory other than the baseline",
		                      def->out);
	const bsim_backend *backend[BSIM_COMPARE_SIDES_MAX] = {NULL};
	int rc = regress_load(def, res, backend, err);
	bsim_session ss;
	if (rc == BSIM_OK)
		rc = bsim_session_open(&ss, def->out, bsim_session_mode(0, def->overwrite),
		                       "regress", NULL, NULL, 0, err);
	if (rc != BSIM_OK) {
		bsim_regress_result_free(res);
		return rc;
	}
	rc = regress_rerun(def, res, backend, ss.stage, err);
	if (rc == BSIM_OK)
		rc = regress_compare(def, res, backend, ss.stage, err);
	rc = bsim_session_close(&ss, rc, "regress", NULL, err);
	if (rc != BSIM_OK)
		bsim_regress_result_free(res);
	return rc;
}
