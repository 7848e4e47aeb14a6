/* The files of a lattice sweep (docs/lattice.md "Files"), beside
 * summary.json and trials.csv, each written atomically:
 *
 *   lattice_map.csv     group,ix,iy,x_min,x_max,y_min,y_max,pivot_y,k_left,k_right
 *                       one row per gate: the stiffness map (Fig. 3.5a)
 *   final_locations.csv group,location,kind,ix,iy,count,p,ci95_lo,ci95_hi
 *   transitions.csv     group,from_ix,from_iy,to_ix,to_iy,count
 *   gate_entries.csv    group,trial,seq,ix,iy,edge,step,t,pos,x,y,vx,vy,
 *                       theta_left,omega_left,theta_right,omega_right
 *                       every gate entry with its state, gate frame (Eq. 2.17)
 *   beam_peaks.csv      group,trial,beam,ix,iy,side,max_theta  (beams that moved)
 *
 * Units: m, s, m/s, rad, rad/s, N m/rad; x, y in lattice_map are the
 * field's X, Y. Each file has its MATLAB twin (.mat, a struct of columns
 * named for the file: lattice_map, final_locations, ...). */
#define _POSIX_C_SOURCE 200809L

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "util/atomic_file.h"
#include "beamsim/lattice.h"
#include "store/matlab.h"
#include "beamsim/output.h"
#include "beamsim/lattice_outcome.h"
#include "beamsim/limits.h"
#include "store/lattice_files.h"
#include "beamsim/trial_fields.h"

typedef int (*lattice_writer)(FILE *f, const bsim_experiment *e, const bsim_override *extra,
                              int n_extra, const bsim_sweep_result *r, bsim_error *err);

static int write_map(FILE *f, const bsim_experiment *e, const bsim_override *extra, int n_extra,
                     const bsim_sweep_result *r, bsim_error *err)
{
	fputs("group,ix,iy,x_min,x_max,y_min,y_max,pivot_y,k_left,k_right\n", f);
	for (int g = 0; g < r->n_groups; g++) {
		bsim_scene s;
		int rc = bsim_experiment_group_scene(e, g, extra, n_extra, &s, err);
		if (rc)
			return rc;
		const bsim_lattice_def *l = &s.lattice;
		for (int iy = 0; s.has_lattice && iy < l->rows; iy++)
			for (int ix = l->ix_min; ix <= l->ix_max; ix++) {
				const bsim_beam_def *bl = &s.beams[bsim_lattice_beam(l, ix, iy, 0)];
				const bsim_beam_def *br = &s.beams[bsim_lattice_beam(l, ix, iy, 1)];
				fprintf(f, "%d,%d,%d,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g\n",
				        g, ix, iy, l->width * ix - 0.5 * l->width,
				        l->width * ix + 0.5 * l->width, l->depth * iy,
				        l->depth * (iy + 1), l->depth * iy + l->pivot_y,
				        bl->stiffness, br->stiffness);
			}
		bsim_scene_free(&s);
	}
	return BSIM_OK;
}

static int write_summaries(FILE *f, const bsim_sweep_result *r, int transitions, bsim_error *err)
{
	fputs(transitions ? "group,from_ix,from_iy,to_ix,to_iy,count\n"
	                  : "group,location,kind,ix,iy,count,p,ci95_lo,ci95_hi\n",
	      f);
	static const char *const kinds[] = {"end", "side", "stuck"};
	for (int g = 0; g < r->n_groups; g++) {
		bsim_lattice_summary own, *ls = &own;
		if (bsim_lattice_group_summary(r, g, &ls) != BSIM_OK)
			return bsim_error_set(err, BSIM_EFAIL, "out of memory");
		for (int k = 0; transitions && k < ls->n_transitions; k++) {
			const bsim_transition *x = &ls->transitions[k];
			fprintf(f, "%d,%d,%d,%d,%d,%d\n", g, x->from[0], x->from[1], x->to[0],
			        x->to[1], x->count);
		}
		for (int k = 0; !transitions && k < ls->n_locations; k++) {
			const bsim_location_count *c = &ls->locations[k];
			char label[48];
			bsim_lattice_location_label(c->loc, label, sizeof label);
			fprintf(f, "%d,%s,%s,", g, label, kinds[c->loc.kind]);
			if (c->loc.kind != BSIM_LOCATION_SIDE)
				fprintf(f, "%d", c->loc.ix);
			fputc(',', f);
			if (c->loc.kind != BSIM_LOCATION_END)
				fprintf(f, "%d", c->loc.iy);
			fprintf(f, ",%d,%.10g,%.10g,%.10g\n", c->count, c->p, c->ci95[0],
			        c->ci95[1]);
		}
		if (ls == &own)
			bsim_lattice_summary_free(&own);
	}
	return BSIM_OK;
}

static int write_locations(FILE *f, const bsim_experiment *e, const bsim_override *extra,
                           int n_extra, const bsim_sweep_result *r, bsim_error *err)
{
	(void)e;
	(void)extra;
	(void)n_extra;
	return write_summaries(f, r, 0, err);
}

static int write_transitions(FILE *f, const bsim_experiment *e, const bsim_override *extra,
                             int n_extra, const bsim_sweep_result *r, bsim_error *err)
{
	(void)e;
	(void)extra;
	(void)n_extra;
	return write_summaries(f, r, 1, err);
}

int bsim_lattice_group_summary(const bsim_sweep_result *r, int g, bsim_lattice_summary **ls)
{
	if (r->lattice_summaries) {
		*ls = &r->lattice_summaries[g];
		return BSIM_OK;
	}
	size_t i0 = (size_t)g * r->trials;
	return bsim_lattice_summarise(&r->trials_out[i0], r->logs ? &r->logs[i0] : NULL, r->trials,
	                              r->lattice_def.rows, *ls);
}

/* The rows of the logs' gate entries, or (def given) their beams' peaks:
 * a row each, the columns of the file's field table. */
static void log_rows(FILE *f, const bsim_lattice_def *def, long first, long n, int trials,
                     const bsim_trial_log *logs)
{
	int n_fields;
	const bsim_trial_field *c =
	        def ? bsim_beam_peak_fields(&n_fields) : bsim_gate_entry_fields(&n_fields);
	for (long i = 0; i < n; i++) {
		bsim_trial_row row = {(int)((first + i) / trials),
		                      (int)((first + i) % trials),
		                      NULL,
		                      &logs[i],
		                      0,
		                      def};
		int count = def ? logs[i].n_peaks : logs[i].n_entries;
		for (row.seq = 0; row.seq < count; row.seq++)
			bsim_trial_fields_line(f, c, n_fields, &row);
	}
}

void bsim_lattice_entries_header(FILE *f)
{
	int n;
	const bsim_trial_field *c = bsim_gate_entry_fields(&n);
	bsim_trial_fields_header(f, c, n);
}

void bsim_lattice_entries_rows(FILE *f, long first, long n, int trials, const bsim_trial_log *logs)
{
	log_rows(f, NULL, first, n, trials, logs);
}

void bsim_lattice_peaks_header(FILE *f)
{
	int n;
	const bsim_trial_field *c = bsim_beam_peak_fields(&n);
	bsim_trial_fields_header(f, c, n);
}

void bsim_lattice_peaks_rows(FILE *f, const bsim_lattice_def *def, long first, long n, int trials,
                             const bsim_trial_log *logs)
{
	log_rows(f, def, first, n, trials, logs);
}

static int write_entries(FILE *f, const bsim_experiment *e, const bsim_override *extra, int n_extra,
                         const bsim_sweep_result *r, bsim_error *err)
{
	(void)e;
	(void)extra;
	(void)n_extra;
	(void)err;
	bsim_lattice_entries_header(f);
	bsim_lattice_entries_rows(f, 0, (long)r->n_groups * r->trials, r->trials, r->logs);
	return BSIM_OK;
}

static int write_peaks(FILE *f, const bsim_experiment *e, const bsim_override *extra, int n_extra,
                       const bsim_sweep_result *r, bsim_error *err)
{
	(void)e;
	(void)extra;
	(void)n_extra;
	(void)err;
	bsim_lattice_peaks_header(f);
	bsim_lattice_peaks_rows(f, &r->lattice_def, 0, (long)r->n_groups * r->trials, r->trials,
	                        r->logs);
	return BSIM_OK;
}

int bsim_output_lattice(const char *dir, const bsim_experiment *e, const bsim_override *extra,
                        int n_extra, const bsim_sweep_result *r, bsim_error *err)
{
	static const struct {
		const char *name;
		lattice_writer fn;
	} files[] = {
	        {"lattice_map.csv", write_map},         {"final_locations.csv", write_locations},
	        {"transitions.csv", write_transitions}, {"gate_entries.csv", write_entries},
	        {"beam_peaks.csv", write_peaks},
	};
	if (!r->lattice || (!r->logs && !r->lattice_summaries))
		return BSIM_OK;
	/* A streamed sweep wrote its trials' entries and peaks as they came
	 * (the last two files): only the map and the summaries are left. */
	size_t n_files = r->logs ? sizeof files / sizeof files[0] : 3;
	for (size_t k = 0; k < n_files; k++) {
		char path[BSIM_PATH_MAX];
		int n = snprintf(path, sizeof path, "%s/%s", dir, files[k].name);
		if (n < 0 || (size_t)n >= sizeof path)
			return bsim_error_set(err, BSIM_EFAIL, "%s/%s: path too long", dir,
			                      files[k].name);
		bsim_atomic_file o;
		if (bsim_atomic_file_open(&o, path, err) != BSIM_OK)
			return BSIM_EFAIL;
		int rc = files[k].fn(o.f, e, extra, n_extra, r, err);
		if (rc != BSIM_OK) {
			bsim_atomic_file_abort(&o);
			return rc;
		}
		if (bsim_atomic_file_commit(&o, err) != BSIM_OK)
			return BSIM_EFAIL;
		/* its MATLAB twin (store/matlab.h), a struct named for the file */
		char mat[BSIM_PATH_MAX], var[32];
		snprintf(var, sizeof var, "%.*s", (int)strcspn(files[k].name, "."), files[k].name);
		if (bsim_matlab_path(path, mat, sizeof mat, err) != BSIM_OK ||
		    bsim_matlab_from_csv(path, mat, var, err) != BSIM_OK)
			return BSIM_EFAIL;
	}
	return BSIM_OK;
}
