/* Figures of one trial, the directory of `beamsim run --out` (figures.h):
 * the random force over time and its histogram against the normal density
 * N(0, Rm^2) it is drawn from (essay Fig. 2.2), the energy ledger over
 * time, and the trajectory over the landscape (Fig. 2.7).
 *
 * The force is piecewise constant, a fresh draw every 1/f s (docs/model.md
 * section 2): the histogram counts each draw once, the first recorded row
 * of each interval [j/f, (j+1)/f) (rows further apart than 1/f miss
 * some draws, which are then missing from it). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/key_names.h"
#include "figures/figures_kinds.h"
#include "figures/figures_paths.h"
#include "figures/figures_toolkit.h"
#include "store/stored_run.h"
#include "util/csv_table.h"
#include "util/yaml_doc.h"
#include "beamsim/limits.h"

/* Most beams of a scene Fig. 2.7(c) is drawn for (a gate has two). */
#define BSIM_MAX_BEAMS_FIG 16

/* The scene of the run (store/stored_run.h): inputs/scene.yaml with
 * run.json's "set" overrides; outcome and type of the trial into the
 * buffers (32 bytes each), the backend and the overrides for a title into
 * params (bsim_fpath_params). *found is 0 if there is no record to load it
 * from. */
static int run_scene(const char *dir, bsim_scene *scene, char *outcome, char *type, char *params,
                     size_t params_size, int *found, bsim_error *err)
{
	bsim_run_scene rs;
	int rc = bsim_run_scene_load(dir, &rs, found, err);
	if (rc || !*found)
		return rc;
	snprintf(outcome, 32, "%s", rs.outcome);
	snprintf(type, 32, "%s", rs.type);
	bsim_fpath_params(params, params_size, rs.backend, (const char *const *)rs.keys,
	                  (const char *const *)rs.values, rs.n_sets);
	/* the scene is the caller's now */
	*scene = rs.scene;
	rs.scene = (bsim_scene){0};
	bsim_run_scene_free(&rs);
	return BSIM_OK;
}

/* "thesis backend; R_m = 20 N": the run's backend and its --set values from
 * run.json, in plain text (gp 0) or gnuplot's enhanced text (gp 1); no
 * single quote, so it goes inside a quoted gnuplot string as it is. */
static void run_header(const char *dir, int gp, char *buf, size_t size)
{
	char path[BSIM_PATH_MAX];
	snprintf(path, sizeof path, "%s/run.json", dir);
	buf[0] = '\0';
	ydoc d;
	bsim_error ignore;
	if (bsim_ydoc_load_own(&d, path, &ignore) != BSIM_OK)
		return;
	struct fy_node *root = fy_document_root(d.fyd);
	struct fy_node *b = bsim_ydoc_lookup(root, "backend"), *set = bsim_ydoc_lookup(root, "set");
	size_t len = 0;
	const char *bt = b && fy_node_is_scalar(b) ? fy_node_get_scalar(b, &len) : NULL;
	int n = snprintf(buf, size, "%.*s backend", bt ? (int)len : 0, bt ? bt : "?");
	size_t k = n > 0 ? (size_t)n : 0;
	void *it = NULL;
	struct fy_node_pair *p;
	int i = 0;
	while (set && fy_node_is_mapping(set) && (p = fy_node_mapping_iterate(set, &it)) &&
	       k < size) {
		struct fy_node *kn = fy_node_pair_key(p);
		size_t kl = 0;
		const char *kt = kn && fy_node_is_scalar(kn) ? fy_node_get_scalar(kn, &kl) : NULL;
		char *key = kt ? strndup(kt, kl) : NULL;
		char *val = bsim_ydoc_flow_text(fy_node_pair_value(p));
		if (key && val) {
			char v[64], kv[300];
			size_t j = 0;
			/* the value's characters that enhanced text would read */
			for (const char *c = val; *c && j + 2 < sizeof v; c++) {
				if (*c == '\'' || *c == '"')
					continue;
				if (gp && strchr("_^{}@&~\\", *c))
					v[j++] = '\\';
				v[j++] = *c;
			}
			v[j] = '\0';
			if (gp)
				bsim_key_value(key, v, 1, kv, sizeof kv);
			else
				bsim_figs_key_value(key, v, kv, sizeof kv);
			n = snprintf(buf + k, size - k, "%s%s", i++ ? ", " : "; ", kv);
			k += n > 0 ? (size_t)n : 0;
		}
		free(key);
		free(val);
	}
	bsim_ydoc_free(&d);
}

/* ---- Fig. 2.2 -------------------------------------------------------------------- */

static int random_force(figs *f, const char *hdr, const csv_table *t, const char *path,
                        const bsim_scene *s, bsim_error *err)
{
	const double rm = s->effects.random_magnitude, freq = s->effects.random_frequency;
	if (!s->effects.has_random_force || rm <= 0.0) {
		bsim_figs_note(f, "the scene has no random force: no random-force figure");
		return BSIM_OK;
	}
	static const char *const need[] = {"t", "f_rand"};
	int col[2];
	int rc = bsim_csv_table_require(t, path, need, 2, col, err);
	const size_t n = (size_t)t->n_rows;
	double *tt = malloc((2 * n + 1) * sizeof *tt), *ff = tt ? tt + n : NULL;
	if (!rc && !tt)
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	if (!rc)
		rc = bsim_csv_table_numbers(t, path, col[0], 0, 0.0, tt, err);
	if (!rc)
		rc = bsim_csv_table_numbers(t, path, col[1], 0, 0.0, ff, err);
	/* One sample per draw; the last row is the state after the last step,
	 * where no force acts any more. */
	long draws = 0, last = -1;
	double sum = 0.0, sum2 = 0.0;
	enum { BINS = 32 };
	const double lo = -4.0 * rm, width = 8.0 * rm / BINS;
	long hist[BINS] = {0};
	for (size_t r = 0; !rc && r + 1 < n; r++) {
		long j = (long)floor(tt[r] * freq + 1e-9);
		if (j == last)
			continue;
		last = j;
		draws++;
		sum += ff[r];
		sum2 += ff[r] * ff[r];
		int b = (int)floor((ff[r] - lo) / width);
		hist[b < 0 ? 0 : b >= BINS ? BINS - 1 : b]++;
	}
	char file[BSIM_PATH_MAX];
	bsim_atomic_file o;
	if (!rc)
		rc = bsim_figs_data_open(f, "random_force.dat", &o, file, err);
	if (rc) {
		free(tt);
		return rc;
	}
	fprintf(o.f, "# block 0: bin centre (N), density of the draws (1/N), draws in the bin; "
	             "the outer bins also hold what lies beyond +-4 Rm\n");
	for (int b = 0; b < BINS; b++)
		fprintf(o.f, "%.6g %.6g %ld\n", lo + (b + 0.5) * width,
		        draws ? (double)hist[b] / ((double)draws * width) : 0.0, hist[b]);
	fputs("\n\n# block 1: t (s), F_rand (N) at every recorded row\n", o.f);
	for (size_t r = 0; r < n; r++)
		fprintf(o.f, "%.6g %.10g\n", tt[r], ff[r]);
	free(tt);
	if ((rc = bsim_figs_data_commit(&o, err)))
		return rc;
	double mean = draws ? sum / draws : 0.0;
	double sd = draws > 1 ? sqrt((sum2 - draws * mean * mean) / (draws - 1)) : 0.0;
	gp_text g;
	if ((rc = bsim_gp_text_open(&g, err)))
		return rc;
	fprintf(g.f,
	        "set multiplot layout 2,1 title 'random force, R_m = %g N, a draw every %g s: "
	        "%ld draws, mean %.3g N, standard deviation %.3g N'.\"\\n\".'%s'\n"
	        "Rm = %.17g\n"
	        "normal(x) = exp(-0.5 * (x / Rm)**2) / (Rm * sqrt(2 * pi))\n"
	        "set title '(a) distribution of the draws against N(0, R_m^2)'\n"
	        "set xlabel 'F_{rand} (N)'\nset ylabel 'probability density (1/N)'\n"
	        "set xrange [%g:%g]\nset samples 400\nset style fill solid 0.5 border lc rgb '%s'\n"
	        "set key top right\n"
	        "plot 'random_force.dat' index 0 using 1:2:(%.17g) with boxes lc rgb '%s' "
	        "title 'draws', \\\n"
	        "     normal(x) with lines lw 2 lc rgb '%s' title 'N(0, R_m^2)'\n"
	        "set title '(b) the force over the first 2 s (the whole run is in the data)'\n"
	        "set xlabel 't (s)'\nset ylabel 'F_{rand} (N)'\nset xrange [0:2]\n"
	        "set yrange [%g:%g]\nunset key\nset grid\n"
	        "plot 'random_force.dat' index 1 using 1:2 with steps lw 1.2 lc rgb '%s'\n"
	        "unset multiplot\n",
	        rm, 1.0 / freq, draws, mean, sd, hdr, rm, lo, -lo, FIG_SKY, width, FIG_SKY, FIG_RED,
	        -3.5 * rm, 3.5 * rm, FIG_BLUE);
	char *body = bsim_gp_text_take(&g);
	rc = body ? bsim_figs_render(f, "random_force", 900, 800, body, err)
	          : bsim_error_set(err, BSIM_EFAIL, "out of memory");
	free(body);
	return rc;
}

/* ---- the energy ledger ----------------------------------------------------------------- */

static int ledger(figs *f, const char *dir, bsim_error *err)
{
	char hdr[600];
	run_header(dir, 1, hdr, sizeof hdr);
	char path[BSIM_PATH_MAX], file[BSIM_PATH_MAX];
	snprintf(path, sizeof path, "%s/ledger.csv", dir);
	csv_table t;
	int rc = bsim_csv_table_read(path, &t, err);
	if (rc)
		return rc;
	static const char *const need[] = {"t",       "e_kin",      "e_beam",  "e_mech",
	                                   "w_prop",  "w_rand",     "damper",  "impact",
	                                   "contact", "correction", "residual"};
	enum { NC = sizeof need / sizeof need[0] };
	int col[NC];
	rc = bsim_csv_table_require(&t, path, need, NC, col, err);
	const size_t n = (size_t)t.n_rows;
	double *v = malloc((NC * n + 1) * sizeof *v);
	if (!rc && !v)
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	for (int c = 0; !rc && c < NC; c++)
		rc = bsim_csv_table_numbers(&t, path, col[c], 0, 0.0, v + (size_t)c * n, err);
	bsim_csv_table_free(&t);
	bsim_atomic_file o;
	if (!rc && n == 0)
		rc = bsim_error_set(err, BSIM_EINPUT, "%s: expected at least one row", path);
	if (!rc)
		rc = bsim_figs_data_open(f, "ledger.dat", &o, file, err);
	if (rc) {
		free(v);
		return rc;
	}
	fputs("# t (s), then J: e_kin e_beam e_mech, dE = e_mech - e_mech(0), w_prop w_rand "
	      "-damper -impact -contact -correction, the sum of the flows, residual\n",
	      o.f);
	const double e0 = v[3 * n];
	double worst = 0.0;
	for (size_t r = 0; r < n; r++) {
		const double *c = v + r;
#define V(k) c[(size_t)(k)*n]
		double flows = V(4) + V(5) - V(6) - V(7) - V(8) - V(9);
		fprintf(o.f,
		        "%.6g %.10g %.10g %.10g %.10g %.10g %.10g %.10g %.10g %.10g %.10g %.10g "
		        "%.6g\n",
		        V(0), V(1), V(2), V(3), V(3) - e0, V(4), V(5), -V(6), -V(7), -V(8), -V(9),
		        flows, V(10));
		worst = fmax(worst, fabs(V(10)));
#undef V
	}
	const double t_end = v[n - 1];
	free(v);
	if ((rc = bsim_figs_data_commit(&o, err)))
		return rc;
	gp_text g;
	if ((rc = bsim_gp_text_open(&g, err)))
		return rc;
	fprintf(g.f,
	        "set multiplot layout 3,1 title 'energy ledger: dE = W_{prop} + W_{rand} - "
	        "damper - impact - contact - correction + residual'.\"\\n\".'%s'\n"
	        "set xrange [0:%g]\nset grid\nset key outside right top font ',9'\n"
	        "set lmargin 12\nset rmargin 28\n"
	        "set title '(a) the energy of body and beams'\nset ylabel 'J'\nunset xlabel\n"
	        "plot 'ledger.dat' using 1:2 with lines lw 1.5 lc rgb '%s' title 'kinetic', \\\n"
	        "     '' using 1:3 with lines lw 1.5 lc rgb '%s' title 'springs', \\\n"
	        "     '' using 1:4 with lines lw 2 lc rgb '%s' title 'mechanical E'\n"
	        "set title '(b) what went in and out since t = 0'\n"
	        "plot 'ledger.dat' using 1:6 with lines lw 1.5 lc rgb '%s' title 'W_{prop}', \\\n"
	        "     '' using 1:7 with lines lw 1.5 lc rgb '%s' title 'W_{rand}', \\\n"
	        "     '' using 1:8 with lines lw 1.5 lc rgb '%s' title '- damper', \\\n"
	        "     '' using 1:9 with lines lw 1.5 lc rgb '%s' title '- impact', \\\n"
	        "     '' using 1:10 with lines lw 1 lc rgb '%s' title '- contact', \\\n"
	        "     '' using 1:11 with lines lw 1 lc rgb '%s' title '- correction', \\\n"
	        "     '' using 1:5 with lines lw 3 lc rgb '%s' title 'E(t) - E(0)', \\\n"
	        "     '' using 1:12 with lines lw 1.5 dt 2 lc rgb '%s' title 'sum of the flows'\n"
	        "set title '(c) residual: E(t) - E(0) minus the sum of the flows; largest |r| "
	        "%.3g J'\n"
	        "set xlabel 't (s)'\nset format y '%%.1e'\n"
	        "plot 'ledger.dat' using 1:13 with lines lw 1.5 lc rgb '%s' title 'residual'\n"
	        "unset multiplot\n",
	        hdr, t_end > 0 ? t_end : 1.0, FIG_ORANGE, FIG_GREEN, FIG_BLACK, FIG_BLUE, FIG_SKY,
	        FIG_RED, FIG_PURPLE, FIG_YELLOW, FIG_DKGREY, FIG_BLACK, FIG_ORANGE, worst, FIG_RED);
	char *body = bsim_gp_text_take(&g);
	rc = body ? bsim_figs_render(f, "ledger", 1000, 900, body, err)
	          : bsim_error_set(err, BSIM_EFAIL, "out of memory");
	free(body);
	return rc;
}

/* Fig. 2.7(c): a trajectory that went below the surface (a beam left the
 * body while it was still within the beam's reach) drawn over the
 * landscape of the beam that carried it alone, the one of the largest peak
 * angle: the scene's other beams get stiffness 0 for the drawing, so that
 * their terms drop out of both the surface and the path's energy. Drawn
 * only for a path with a state below the surface of a scene of two or
 * more beams. */
static int single_beam(figs *f, bsim_scene *scene, const fpath *p, const char *title,
                       bsim_error *err)
{
	const int nb = scene->n_beams;
	long below = 0;
	int active = 0;
	double peak[BSIM_MAX_BEAMS_FIG] = {0};
	if (nb < 2 || nb > BSIM_MAX_BEAMS_FIG)
		return BSIM_OK;
	for (long k = 0; k < p->n; k++) {
		const double *th = p->theta + (size_t)k * (size_t)nb;
		below += bsim_fpath_below(scene, p->x[k], p->y[k], th);
		for (int b = 0; b < nb; b++)
			peak[b] = fmax(peak[b], fabs(th[b]));
	}
	if (below == 0) {
		bsim_figs_note(
		        f, "landscape_path_single (Fig. 2.7c) not drawn: it shows a run in which "
		           "a beam left the body while the body was still within its reach, and "
		           "this run has none");
		return BSIM_OK;
	}
	for (int b = 1; b < nb; b++)
		if (peak[b] > peak[active])
			active = b;
	double k_saved[BSIM_MAX_BEAMS_FIG];
	for (int b = 0; b < nb; b++) {
		k_saved[b] = scene->beams[b].stiffness;
		if (b != active)
			scene->beams[b].stiffness = 0.0;
	}
	char t[1400];
	snprintf(t, sizeof t,
	         "%s\nover beam %d's landscape alone: F_prop (y0 - y) + 1/2 k_%d th_%d^2, the "
	         "other beam%s left out",
	         title, active + 1, active + 1, active + 1, nb > 2 ? "s" : "");
	int rc = bsim_figs_over_landscape(f, "landscape_path_single", t, scene, p, 1, ~0u, err);
	for (int b = 0; b < nb; b++)
		scene->beams[b].stiffness = k_saved[b];
	return rc;
}

int bsim_figs_run(figs *f, const char *dir, bsim_error *err)
{
	if (f->def->n_select > 0)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: --select chooses groups of a sweep; a run has none",
		                      dir);
	char path[BSIM_PATH_MAX];
	snprintf(path, sizeof path, "%s/trajectory.csv", dir);
	bsim_scene scene;
	char outcome[32] = "", type[32] = "", params[400] = "";
	int found;
	int rc = run_scene(dir, &scene, outcome, type, params, sizeof params, &found, err);
	if (!rc && !found) {
		bsim_figs_note(
		        f,
		        "%s: no run.json and inputs/scene.yaml, so no scene: only the ledger "
		        "is drawn",
		        dir);
		return ledger(f, dir, err);
	}
	if (rc)
		return rc;
	csv_table t;
	rc = bsim_csv_table_read(path, &t, err);
	if (!rc) {
		char hdr[600];
		run_header(dir, 1, hdr, sizeof hdr);
		rc = random_force(f, hdr, &t, path, &scene, err);
		if (!rc)
			rc = ledger(f, dir, err);
		fpaths ps = {0};
		if (!rc)
			rc = bsim_fpaths_read(&t, path, &ps, err);
		if (!rc && ps.n_beams != scene.n_beams)
			rc = bsim_error_set(err, BSIM_EINPUT,
			                    "%s: %d theta columns for a scene of %d beams", path,
			                    ps.n_beams, scene.n_beams);
		if (!rc && ps.n > 0) {
			ps.p[0].cls = bsim_fpath_class(outcome, type);
			char title[1100];
			snprintf(title, sizeof title,
			         "%s: one trial, %s%s%s, over its landscape\n%s", scene.name,
			         outcome, *type && strcmp(type, "none") ? ", type " : "",
			         strcmp(type, "none") ? type : "", params);
			rc = bsim_figs_over_landscape(f, "landscape_path", title, &scene, ps.p, 1,
			                              ~0u, err);
			if (!rc)
				rc = single_beam(f, &scene, &ps.p[0], title, err);
		}
		bsim_fpaths_free(&ps);
		bsim_csv_table_free(&t);
	}
	bsim_scene_free(&scene);
	return rc;
}
