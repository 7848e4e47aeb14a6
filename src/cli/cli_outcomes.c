/* The splits of a sweep's groups on the terminal; see cli_outcomes.h. */
#define _POSIX_C_SOURCE 200809L

#include "cli/cli_outcomes.h"

#include <stdlib.h>
#include <string.h>

#include "beamsim/stats.h"

int cli_outcomes_asymmetric(const bsim_experiment *e, const cli_sets *sets)
{
	const bsim_override *ov = sets ? sets->ov : NULL;
	int n_ov = sets ? sets->n : 0, asym = 0;
	for (int g = 0; g < e->n_groups && !asym; g++) {
		bsim_scene s;
		bsim_error err;
		if (bsim_experiment_group_scene(e, g, ov, n_ov, &s, &err) != BSIM_OK)
			return 0;
		if (!s.has_lattice && s.n_beams == 2) {
			const bsim_beam_def *a = &s.beams[0], *b = &s.beams[1];
			asym = a->length != b->length || a->mass != b->mass ||
			       a->inertia != b->inertia || a->stiffness != b->stiffness ||
			       a->damping != b->damping;
		}
		bsim_scene_free(&s);
	}
	return asym;
}

/* k of n with its 95% interval: Wilson's, or the point k/n for a
 * deterministic group (every trial a copy of one, as summary.json's ci95). */
static void fraction(FILE *f, int k, int n, int deterministic, int digits)
{
	double lo, hi, p = n > 0 ? (double)k / n : 0.0;
	if (deterministic) {
		lo = hi = p;
	} else {
		bsim_stats_wilson(k, n, BSIM_STATS_Z95, &lo, &hi);
	}
	fprintf(f, "%.*f [%.*f, %.*f]", digits, p, digits, lo, digits, hi);
}

/* The widths of the axis values' columns; the total width of the
 * "params" column, at least min. */
static int params_width(const bsim_experiment *e, int *w, int min)
{
	int total = -1;
	for (int a = 0; a < e->n_axes; a++) {
		w[a] = 1;
		for (int i = 0; i < e->axes[a].n_values; i++) {
			int len = (int)strlen(e->axes[a].values[i]);
			w[a] = len > w[a] ? len : w[a];
		}
		total += w[a] + 1;
	}
	return total > min ? total : min;
}

/* Group g's axis values, each right-aligned in its column, padded to width. */
static void params_cell(FILE *f, const bsim_experiment *e, const int *idx, const int *w, int g,
                        int width)
{
	int used = 0;
	bsim_experiment_group_index(e, g, (int *)idx);
	for (int a = 0; a < e->n_axes; a++)
		used += fprintf(f, "%s%*s", a ? " " : "", w[a], e->axes[a].values[idx[a]]);
	fprintf(f, "%*s", width - used, "");
}

/* "group columns: KEY, KEY, ..." naming the axes of the params column,
 * wrapped to 80 columns. */
static void params_legend(FILE *f, const bsim_experiment *e)
{
	int col = fprintf(f, "group columns:");
	for (int a = 0; a < e->n_axes; a++) {
		int len = (int)strlen(e->axes[a].key) + 2;
		if (a > 0 && col + len > 79) {
			fputs(",\n ", f);
			col = 1;
		} else if (a > 0) {
			col += fprintf(f, ",");
		}
		col += fprintf(f, " %s", e->axes[a].key);
	}
	fputc('\n', f);
}

/* One line a group: params, p_traverse, left and right counts, the left
 * fraction of the typed traversals (type none, |v_x| in the dead-band,
 * counts in neither). */
static void print_gate(FILE *f, const bsim_experiment *e, const bsim_sweep_result *r, int *idx,
                       int *w)
{
	int pw = e->n_axes > 0 ? params_width(e, w, 5) : 0;
	fputs("\nTraversals by type (left: v_x > 0 at classify_y, docs/model.md section 6),\n"
	      "fractions with 95% Wilson intervals\n",
	      f);
	if (e->n_axes > 0) {
		params_legend(f, e);
		fprintf(f, "%-*s  ", pw, "group");
	}
	fprintf(f, "%-17s %5s %5s  %s\n", "p_traverse", "left", "right", "left/(left+right)");
	for (int g = 0; g < r->n_groups; g++) {
		const bsim_group_result *G = &r->groups[g];
		if (e->n_axes > 0) {
			params_cell(f, e, idx, w, g, pw);
			fputs("  ", f);
		}
		/* p_traverse and its interval as summary.json holds them */
		fprintf(f, "%.2f [%.2f, %.2f]", G->p_traverse, G->ci95[0], G->ci95[1]);
		fprintf(f, " %5d %5d  ", G->left, G->right);
		if (G->left + G->right > 0)
			fraction(f, G->left, G->left + G->right, G->deterministic, 2);
		else
			fputc('-', f);
		fputc('\n', f);
	}
}

/* A block a group: its axis values, then end, side, stuck (and unstable
 * if any) as counts of its trials and fractions. */
static void print_lattice(FILE *f, const bsim_experiment *e, const bsim_sweep_result *r, int *idx)
{
	fputs("\nFinal locations (docs/lattice.md): through the end, out a side, stuck in a\n"
	      "gate; fractions of the trials with 95% Wilson intervals\n",
	      f);
	for (int g = 0; g < r->n_groups; g++) {
		const bsim_group_result *G = &r->groups[g];
		if (e->n_axes > 0 && r->n_groups > 1) {
			bsim_experiment_group_index(e, g, idx);
			for (int a = 0; a < e->n_axes; a++)
				fprintf(f, "%s%s = %s", a ? ", " : "", e->axes[a].key,
				        e->axes[a].values[idx[a]]);
			fputc('\n', f);
		}
		const char *names[] = {"end", "side", "stuck", "unstable"};
		int counts[] = {G->traversed, G->side_exit, G->stuck, G->unstable};
		for (int k = 0; k < 4; k++) {
			if (k == 3 && counts[k] == 0)
				break;
			fprintf(f, "  %-8s %7d of %d  ", names[k], counts[k], G->trials);
			fraction(f, counts[k], G->trials, G->deterministic, 3);
			fputc('\n', f);
		}
	}
}

void cli_outcomes_print(FILE *f, const bsim_experiment *e, const bsim_sweep_result *r,
                        int asymmetric)
{
	int both = 0;
	for (int g = 0; g < r->n_groups; g++)
		both |= r->groups[g].left > 0 && r->groups[g].right > 0;
	if (!r->lattice && !both && !asymmetric)
		return;
	int *idx = calloc((size_t)e->n_axes + 1, sizeof *idx);
	int *w = calloc((size_t)e->n_axes + 1, sizeof *w);
	if (idx && w) {
		if (r->lattice)
			print_lattice(f, e, r, idx);
		else
			print_gate(f, e, r, idx, w);
	}
	free(idx);
	free(w);
}
