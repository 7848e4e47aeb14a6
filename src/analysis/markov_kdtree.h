/* Internal: the k nearest neighbours of a point among n in three
 * dimensions (markov_kdtree.cpp, nanoflann's exact k-d tree, Euclidean),
 * for the nearest-neighbour walks (markov_nearest.c). */
#ifndef BSIM_ANALYSIS_MARKOV_KDTREE_H
#define BSIM_ANALYSIS_MARKOV_KDTREE_H

#ifdef __cplusplus
extern "C" {
#endif

typedef struct markov_kdtree markov_kdtree;

/* The most neighbours a query returns. */
#define BSIM_MARKOV_KDTREE_K_MAX 64

/* NULL out of memory; pts must outlive the tree. */
markov_kdtree *bsim_markov_kdtree_alloc(const double (*pts)[3], long n);
/* The k (at most n and BSIM_MARKOV_KDTREE_K_MAX) points nearest q,
 * nearest first, those at equal distances in the order of their indices:
 * their indices into idx; their number. */
int bsim_markov_kdtree_nearest(const markov_kdtree *t, const double q[3], int k, long *idx);
void bsim_markov_kdtree_free(markov_kdtree *t);

#ifdef __cplusplus
}
#endif
#endif
