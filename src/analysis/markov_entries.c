/* Gate entries observed in simulation (beamsim/markov.h): read from the
 * gate_entries.csv of lattice sweeps, identified by a hash of their values
 * (part of a map's key, so maps built from other entries are never
 * reused), and indexed by entry bin for the single gates to start from. */
#define _POSIX_C_SOURCE 200809L

#include "analysis/markov_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "store/outdir.h"
#include "util/csv_table.h"
#include "util/hash.h"
#include "beamsim/limits.h"

void bsim_markov_entries_free(bsim_markov_entries *e)
{
	if (!e)
		return;
	free(e->edge);
	free(e->pos);
	free(e->x);
	free(e->v);
	memset(e, 0, sizeof *e);
}

int bsim_markov_entries_push(bsim_markov_entries *e, int *cap, int edge, double pos,
                             const double x[2], const double v[2])
{
	if (e->n == *cap) {
		int nc = *cap ? 2 * *cap : 1024;
		int *ne = realloc(e->edge, (size_t)nc * sizeof *ne);
		if (ne)
			e->edge = ne;
		double *np = realloc(e->pos, (size_t)nc * sizeof *np);
		if (np)
			e->pos = np;
		double(*nx)[2] = realloc(e->x, (size_t)nc * sizeof *nx);
		if (nx)
			e->x = nx;
		double(*nv)[2] = realloc(e->v, (size_t)nc * sizeof *nv);
		if (nv)
			e->v = nv;
		if (!ne || !np || !nx || !nv)
			return -1;
		*cap = nc;
	}
	e->edge[e->n] = edge;
	e->pos[e->n] = pos;
	memcpy(e->x[e->n], x, sizeof e->x[0]);
	memcpy(e->v[e->n], v, sizeof e->v[0]);
	e->n++;
	return 0;
}

int bsim_markov_entries_load(const char *const *paths, int n, bsim_markov_entries *out,
                             bsim_error *err)
{
	memset(out, 0, sizeof *out);
	uint64_t h = HASH_FNV1A64_SEED;
	int cap = 0, rc = BSIM_OK;
	static const char *const want[] = {"edge", "pos", "x", "y", "vx", "vy"};
	for (int f = 0; f < n && rc == BSIM_OK; f++) {
		char path[BSIM_PATH_MAX];
		struct stat st;
		int is_dir = stat(paths[f], &st) == 0 && S_ISDIR(st.st_mode);
		if (is_dir)
			snprintf(path, sizeof path, "%s/gate_entries.csv", paths[f]);
		else
			snprintf(path, sizeof path, "%s", paths[f]);
		/* A sweep's directory is read as its run committed it: with a
		 * manifest, each file has the listed size and CRC-32. */
		int has_manifest = 0;
		if (is_dir && (rc = bsim_outdir_verify(paths[f], &has_manifest, err)) != BSIM_OK)
			break;
		csv_table t;
		int col[6];
		if ((rc = bsim_csv_table_read(path, &t, err)) != BSIM_OK)
			break;
		rc = bsim_csv_table_require(&t, path, want, 6, col, err);
		for (long r = 0; rc == BSIM_OK && r < t.n_rows; r++) {
			const char *edge = bsim_csv_table_cell(&t, r, col[0]);
			const int e = bsim_markov_edge_of(edge);
			double val[6];
			int bad = e < 0;
			for (int k = 1; k < 6 && !bad; k++)
				bad = bsim_csv_table_number(&t, r, col[k], &val[k]) != 0 ||
				      !isfinite(val[k]);
			if (bad) {
				rc = bsim_error_set(
				        err, BSIM_EINPUT,
				        "%s:%ld: expected an entry with edge (start, bottom, "
				        "left, right, top) and numbers pos, x, y, vx, vy",
				        path, r + 2);
				break;
			}
			if (e == BSIM_EDGE_START)
				continue;
			h = bsim_hash_fnv1a64(&e, sizeof e, h);
			h = bsim_hash_fnv1a64(val + 1, 5 * sizeof val[0], h);
			const double x[2] = {val[2], val[3]}, v[2] = {val[4], val[5]};
			if (bsim_markov_entries_push(out, &cap, e, val[1], x, v))
				rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
		}
		bsim_csv_table_free(&t);
	}
	if (rc != BSIM_OK) {
		bsim_markov_entries_free(out);
		return rc;
	}
	snprintf(out->id, sizeof out->id, "%016llx %d", (unsigned long long)h, out->n);
	return BSIM_OK;
}

int bsim_markov_entry_index_init(markov_entry_index *x, const bsim_markov_entries *e,
                                 const bsim_markov_bins *b, const bsim_lattice_def *l)
{
	const int nb = bsim_markov_bins_count(b);
	x->first = calloc((size_t)nb + 1, sizeof *x->first);
	x->idx = malloc((size_t)(e && e->n ? e->n : 1) * sizeof *x->idx);
	int *bin = malloc((size_t)(e && e->n ? e->n : 1) * sizeof *bin);
	if (!x->first || !x->idx || !bin) {
		free(bin);
		return -1;
	}
	for (int i = 0; e && i < e->n; i++) {
		bin[i] = bsim_markov_bin_of(b, l, e->edge[i], e->pos[i], e->v[i]);
		x->first[bin[i] + 1]++;
	}
	for (int k = 0; k < nb; k++)
		x->first[k + 1] += x->first[k];
	int *fill = calloc((size_t)nb, sizeof *fill);
	if (!fill) {
		free(bin);
		return -1;
	}
	for (int i = 0; e && i < e->n; i++)
		x->idx[x->first[bin[i]] + fill[bin[i]]++] = i;
	free(fill);
	free(bin);
	return 0;
}

void bsim_markov_entry_index_free(markov_entry_index *x)
{
	free(x->first);
	free(x->idx);
}
