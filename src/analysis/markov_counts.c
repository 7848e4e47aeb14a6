/* The counts of a single-gate map (beamsim/markov.h), kept by row: an
 * entry bin's single gates end in at most as many exit bins as they are,
 * so a row holds its nonzero exits only (compressed sparse rows), and a
 * map's memory grows as its bins times its trials, not as the bins'
 * square. Made from the single gates' exits, from the rows of a map file,
 * or from a dense matrix. */
#include "analysis/markov_internal.h"

#include <stdlib.h>
#include <string.h>

void bsim_markov_counts_free(bsim_markov_map *m)
{
	free(m->count_first);
	free(m->count_exit);
	free(m->count_n);
	m->count_first = m->count_exit = m->count_n = NULL;
}

/* Room for nnz exits of m's rows (the old counts freed): 0, or -1 out of
 * memory (then none). */
static int counts_alloc(bsim_markov_map *m, long nnz)
{
	bsim_markov_counts_free(m);
	m->count_first = malloc((size_t)(m->n_bins + 1) * sizeof *m->count_first);
	m->count_exit = malloc((size_t)(nnz > 0 ? nnz : 1) * sizeof *m->count_exit);
	m->count_n = malloc((size_t)(nnz > 0 ? nnz : 1) * sizeof *m->count_n);
	if (m->count_first && m->count_exit && m->count_n)
		return 0;
	bsim_markov_counts_free(m);
	return -1;
}

static int int_cmp(const void *a, const void *b)
{
	const int x = *(const int *)a, y = *(const int *)b;
	return (x > y) - (x < y);
}

int bsim_markov_counts_of_exits(bsim_markov_map *m, const int *exit)
{
	const long units = bsim_markov_map_units(m);
	int *sorted = malloc((size_t)(units > 0 ? units : 1) * sizeof *sorted);
	if (!sorted || counts_alloc(m, units) != 0) {
		free(sorted);
		return -1;
	}
	memcpy(sorted, exit, (size_t)units * sizeof *sorted);
	int k = 0;
	for (int a = 0; a < m->n_bins; a++) {
		int *row = sorted + bsim_markov_bin_first(m, a);
		const int T = bsim_markov_bin_trials(m, a);
		qsort(row, (size_t)T, sizeof *row, int_cmp);
		m->count_first[a] = k;
		for (int t = 0; t < T; t++) {
			if (t == 0 || row[t] != row[t - 1]) {
				m->count_exit[k] = row[t];
				m->count_n[k++] = 0;
			}
			m->count_n[k - 1]++;
		}
	}
	m->count_first[m->n_bins] = k;
	free(sorted);
	return 0;
}

/* A cell of a map file: its row, exit, count and the order it came in. */
typedef struct cell {
	int entry, exit, count;
	long order;
} cell;

static int cell_cmp(const void *a, const void *b)
{
	const cell *x = a, *y = b;
	if (x->entry != y->entry)
		return (x->entry > y->entry) - (x->entry < y->entry);
	if (x->exit != y->exit)
		return (x->exit > y->exit) - (x->exit < y->exit);
	return (x->order > y->order) - (x->order < y->order);
}

int bsim_markov_counts_of_cells(bsim_markov_map *m, long n, const int *cells, long *again)
{
	cell *c = malloc((size_t)(n > 0 ? n : 1) * sizeof *c);
	if (!c)
		return -1;
	for (long i = 0; i < n; i++)
		c[i] = (cell){cells[3 * i], cells[3 * i + 1], cells[3 * i + 2], i};
	qsort(c, (size_t)n, sizeof *c, cell_cmp);
	/* a pair given twice: the later of the two */
	long dup = -1;
	for (long i = 1; i < n; i++)
		if (c[i].entry == c[i - 1].entry && c[i].exit == c[i - 1].exit &&
		    (dup < 0 || c[i].order < dup))
			dup = c[i].order;
	if (dup >= 0 || counts_alloc(m, n) != 0) {
		free(c);
		*again = dup;
		return dup >= 0 ? 1 : -1;
	}
	long i = 0;
	for (int a = 0; a < m->n_bins; a++) {
		m->count_first[a] = (int)i;
		for (; i < n && c[i].entry == a; i++) {
			m->count_exit[i] = c[i].exit;
			m->count_n[i] = c[i].count;
		}
	}
	m->count_first[m->n_bins] = (int)n;
	free(c);
	return 0;
}

int bsim_markov_counts_copy(bsim_markov_map *to, const bsim_markov_map *from)
{
	const long nnz = from->count_first[from->n_bins];
	if (counts_alloc(to, nnz) != 0)
		return -1;
	memcpy(to->count_first, from->count_first,
	       (size_t)(from->n_bins + 1) * sizeof *to->count_first);
	memcpy(to->count_exit, from->count_exit, (size_t)nnz * sizeof *to->count_exit);
	memcpy(to->count_n, from->count_n, (size_t)nnz * sizeof *to->count_n);
	return 0;
}

int bsim_markov_counts_equal(const bsim_markov_map *a, const bsim_markov_map *b)
{
	if (a->n_bins != b->n_bins)
		return 0;
	const long nnz = a->count_first[a->n_bins];
	return memcmp(a->count_first, b->count_first,
	              (size_t)(a->n_bins + 1) * sizeof *a->count_first) == 0 &&
	       memcmp(a->count_exit, b->count_exit, (size_t)nnz * sizeof *a->count_exit) == 0 &&
	       memcmp(a->count_n, b->count_n, (size_t)nnz * sizeof *a->count_n) == 0;
}

int bsim_markov_map_count(const bsim_markov_map *m, int entry, int exit)
{
	if (!m->count_first || entry < 0 || entry >= m->n_bins)
		return 0; /* not counted, or no such row */
	int lo = m->count_first[entry], hi = m->count_first[entry + 1];
	while (lo < hi) { /* the first exit >= exit */
		const int mid = lo + (hi - lo) / 2;
		if (m->count_exit[mid] < exit)
			lo = mid + 1;
		else
			hi = mid;
	}
	return lo < m->count_first[entry + 1] && m->count_exit[lo] == exit ? m->count_n[lo] : 0;
}

int bsim_markov_map_set_counts(bsim_markov_map *m, const int *dense, bsim_error *err)
{
	const int nb = m->n_bins;
	long nnz = 0;
	for (long i = 0; i < (long)nb * nb; i++)
		nnz += dense[i] != 0;
	if (counts_alloc(m, nnz) != 0)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	int k = 0;
	for (int a = 0; a < nb; a++) {
		m->count_first[a] = k;
		for (int x = 0; x < nb; x++)
			if (dense[(long)a * nb + x]) {
				m->count_exit[k] = x;
				m->count_n[k++] = dense[(long)a * nb + x];
			}
	}
	m->count_first[nb] = k;
	return BSIM_OK;
}
