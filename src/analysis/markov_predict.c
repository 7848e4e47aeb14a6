/* A prediction from a map directory (beamsim/markov.h,
 * bsim_markov_predict_run): the scene loaded, its maps read, the chain
 * solved and timed, the walks to the trial's duration, the files; and the
 * prediction as JSON (markov predict --json). */
#include <stdio.h>
#include <string.h>

#include "analysis/markov_internal.h"
#include "beamsim/lattice_outcome.h"
#include "beamsim/markov.h"
#include "store/outdir.h"
#include "util/clock.h"
#include "util/json.h"

bsim_markov_predict_def bsim_markov_predict_def_default(void)
{
	return (bsim_markov_predict_def){.gates = -1,
	                                 .walks = BSIM_MARKOV_WALKS,
	                                 .nearest = bsim_markov_nearest_def_default()};
}

void bsim_markov_predict_result_free(bsim_markov_predict_result *res)
{
	if (!res)
		return;
	bsim_markov_prediction_free(&res->p);
	bsim_scene_free(&res->scene);
	memset(res, 0, sizeof *res);
}

/* The chain of the maps in def->map_dir solved for res->scene, timed, and
 * walked to the trial's duration. */
static int predict_chain(const bsim_markov_predict_def *def, const bsim_markov_set *set,
                         bsim_markov_predict_result *res, bsim_error *err)
{
	const double tol = def->tol > 0 ? def->tol : bsim_markov_tol_sampling(set);
	const int gates = def->gates < 0 ? def->out != NULL : def->gates != 0;
	/* The wall time of the prediction alone (the chain composed and
	 * solved; the maps already read). */
	double t0 = bsim_clock_seconds(), c0 = bsim_clock_thread_cpu_seconds();
	int rc = bsim_markov_predict_with(&res->scene, set, tol, gates ? BSIM_MARKOV_GATES : 0,
	                                  &res->p, err);
	res->seconds = bsim_clock_seconds() - t0;
	res->cpu_seconds = bsim_clock_thread_cpu_seconds() - c0;
	if (rc == BSIM_OK && res->p.has_time && def->walks > 0)
		rc = bsim_markov_predict_time(&res->scene, set, def->walks, set->def.seed, &res->p,
		                              err);
	for (int i = 0; rc == BSIM_OK && i < res->p.n_locations; i++)
		res->total[res->p.loc[i].kind] += res->p.p[i];
	return rc;
}

/* The walks nd over the visits in dir for res->scene, the training fields
 * run there first where missing (not in a build's: nd->read_only). */
static int predict_nearest(const bsim_markov_nearest_def *nd, const char *dir,
                           bsim_markov_predict_result *res, bsim_error *err)
{
	bsim_markov_visits v;
	int rc = bsim_markov_visits_build(&res->scene, nd, dir, &v, err);
	if (rc != BSIM_OK)
		return rc;
	res->n_maps = v.fields;
	res->fields_built = v.built;
	res->fields_cost = v.cost;
	/* the walks run on every thread: the process's CPU time */
	const double t0 = bsim_clock_seconds(), c0 = bsim_clock_process_cpu_seconds();
	rc = bsim_markov_nearest_predict(&res->scene, &v, nd, &res->p, err);
	res->seconds = bsim_clock_seconds() - t0;
	res->cpu_seconds = bsim_clock_process_cpu_seconds() - c0;
	bsim_markov_visits_free(&v);
	for (int i = 0; rc == BSIM_OK && i < res->p.n_locations; i++)
		res->total[res->p.loc[i].kind] += res->p.p[i];
	if (rc == BSIM_OK)
		res->tv_walks = bsim_markov_nearest_tv_walks(res->p.p, res->p.n_locations,
		                                             res->p.nearest_walks);
	return rc;
}

int bsim_markov_predict_run(const bsim_markov_predict_def *def, bsim_markov_predict_result *res,
                            bsim_error *err)
{
	memset(res, 0, sizeof *res);
	/* walks: over visits_dir, or map_dir if a walks' build */
	bsim_markov_nearest_def nd;
	bsim_options nd_opts = {0};
	const char *vdir = NULL;
	if (def->scene) {
		const int rc = bsim_markov_nearest_of_dir(def->map_dir, def->visits_dir,
		                                          &def->nearest, &nd, &nd_opts, &vdir, err);
		if (rc != BSIM_OK)
			return rc;
	}
	if (vdir) {
		int rc = bsim_scene_load(def->scene, def->sets, def->n_sets, &res->scene, err);
		const bsim_outdir_spelling spelling = {NULL, def->overwrite_option};
		if (rc == BSIM_OK && def->out)
			rc = bsim_outdir_probe(
			        def->out, def->overwrite ? BSIM_OUTDIR_OVERWRITE : BSIM_OUTDIR_NEW,
			        &spelling, err);
		if (rc == BSIM_OK)
			rc = predict_nearest(&nd, vdir, res, err);
		if (rc == BSIM_OK && def->out)
			rc = bsim_markov_prediction_store(def->out, def->overwrite, &res->scene,
			                                  NULL, &res->p, err);
		if (rc != BSIM_OK)
			bsim_markov_predict_result_free(res);
		return rc;
	}
	if (!def->scene || !def->map_dir)
		return bsim_error_set(
		        err, BSIM_EINPUT,
		        "markov predict: expected a lattice scene and a map directory");
	if (def->walks < 0 || def->walks > 100000000L)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "walks %ld: expected an integer 0 to 100000000", def->walks);
	int rc = bsim_scene_load(def->scene, def->sets, def->n_sets, &res->scene, err);
	if (rc != BSIM_OK)
		return rc;
	/* out refused before the chain is solved, not after */
	const bsim_outdir_spelling spelling = {NULL, def->overwrite_option};
	if (def->out)
		rc = bsim_outdir_probe(def->out,
		                       def->overwrite ? BSIM_OUTDIR_OVERWRITE : BSIM_OUTDIR_NEW,
		                       &spelling, err);
	bsim_options opts; /* the maps' backend options: the set's, while it lives */
	bsim_markov_set set;
	const int loaded = rc == BSIM_OK && (rc = bsim_markov_load(&res->scene, def->map_dir, &opts,
	                                                           &set, err)) == BSIM_OK;
	if (loaded) {
		res->n_maps = set.n;
		rc = predict_chain(def, &set, res, err);
	}
	if (rc == BSIM_OK && def->out)
		rc = bsim_markov_prediction_store(def->out, def->overwrite, &res->scene, &set,
		                                  &res->p, err);
	if (loaded)
		bsim_markov_set_free(&set);
	if (rc != BSIM_OK)
		bsim_markov_predict_result_free(res);
	return rc;
}

void bsim_markov_predict_json(FILE *f, const char *scene_path,
                              const bsim_markov_predict_result *res)
{
	static const char *const kinds[] = {"end", "side", "stuck"};
	const bsim_markov_prediction *p = &res->p;
	fputs("{\"scene\": ", f);
	bsim_json_string(f, scene_path);
	fputs(", \"name\": ", f);
	bsim_json_string(f, res->scene.name);
	fprintf(f,
	        ", \"columns\": %d, \"rows\": %d, \"maps\": %d, \"states\": %d, \"solve\": "
	        "\"%s\", ",
	        res->scene.lattice.columns, res->scene.lattice.rows, res->n_maps, p->n_states,
	        p->nearest_walks > 0 ? "nearest"
	        : p->exact           ? "LU"
	        : p->sweeps          ? "sweeps"
	                             : "series");
	if (p->nearest_walks > 0) {
		/* maps: the training fields; states: their visits */
		fprintf(f, "\"nearest_walks\": %ld, \"nearest_k\": %d, \"fields_built\": %d, ",
		        p->nearest_walks, p->nearest_k, res->fields_built);
		fputs("\"fields_cpu_seconds\": ", f);
		bsim_json_number(f, res->fields_cost);
		fputs(", \"tv_walks\": ", f);
		bsim_json_number(f, res->tv_walks);
		fputs(", ", f);
	}
	fputs("\"totals\": {", f);
	for (int k = 0; k < 3; k++) {
		fprintf(f, "%s\"%s\": ", k ? ", " : "", kinds[k]);
		bsim_json_number(f, res->total[k]);
	}
	fputs("}, \"mean_gates\": ", f);
	bsim_json_number(f, p->mean_gates);
	fputs(", \"left_in_field\": ", f);
	bsim_json_number(f, p->left_in_field);
	fputs(", \"tol\": ", f);
	bsim_json_number(f, p->tol);
	fprintf(f, ", \"sweeps\": %d", p->sweeps);
	fputs(", \"mean_time\": ", f);
	bsim_json_number(f, p->mean_time);
	if (p->walks > 0) {
		fprintf(f, ", \"walks\": %ld, \"duration\": ", p->walks);
		bsim_json_number(f, p->duration);
		fputs(", \"at_duration\": {", f);
		for (int k = 0; k < 3; k++) {
			fprintf(f, "%s\"%s\": {\"p\": ", k ? ", " : "", kinds[k]);
			bsim_json_number(f, p->p_by[k]);
			fputs(", \"mean_time\": ", f);
			bsim_json_number(f, p->t_mean[k]);
			fputs(", \"sd_time\": ", f);
			bsim_json_number(f, p->t_sd[k]);
			fputc('}', f);
		}
		fputc('}', f);
	}
	fputs(", \"predict_seconds\": ", f);
	bsim_json_number(f, res->seconds);
	/* the CPU time of the same: what it costs on a machine others share */
	fputs(", \"predict_cpu_seconds\": ", f);
	bsim_json_number(f, res->cpu_seconds);
	fputs(", \"locations\": [", f);
	for (int i = 0; i < p->n_locations; i++) {
		char label[48];
		bsim_lattice_location_label(p->loc[i], label, sizeof label);
		fprintf(f, "%s{\"location\": \"%s\", \"kind\": \"%s\", \"p\": ", i ? ", " : "",
		        label, kinds[p->loc[i].kind]);
		bsim_json_number(f, p->p[i]);
		fputc('}', f);
	}
	fputs("], \"p_gates\": [", f);
	for (int k = 0; k <= p->n_gates; k++) {
		fputs(k ? ", " : "", f);
		bsim_json_number(f, p->p_gates[k]);
	}
	fputs("]}\n", f);
}
