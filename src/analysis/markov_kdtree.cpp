/* The k nearest visits of an entry state (markov_nearest.c): nanoflann's
 * exact k-d tree behind the C face of markov_internal.h. With
 * NANOFLANN_FIRST_MATCH points at equal distances are taken in the order
 * of their indices, so a tie gives the same neighbours however the tree
 * was split. */
#define NANOFLANN_FIRST_MATCH
#include <nanoflann.hpp>

#include <new>

#include "analysis/markov_kdtree.h"

namespace
{

struct cloud {
	const double (*pts)[3];
	size_t n;
	size_t kdtree_get_point_count() const
	{
		return n;
	}
	double kdtree_get_pt(size_t i, size_t d) const
	{
		return pts[i][d];
	}
	template <class box> bool kdtree_get_bbox(box &) const
	{
		return false;
	}
};

using tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, cloud>, cloud,
                                                 3, size_t>;

} // namespace

struct markov_kdtree {
	cloud c;
	tree t;
	markov_kdtree(const double (*pts)[3], size_t n)
	    : c{pts, n}, t(3, c, nanoflann::KDTreeSingleIndexAdaptorParams(32))
	{
	}
};

extern "C" markov_kdtree *bsim_markov_kdtree_alloc(const double (*pts)[3], long n)
{
	try {
		return new markov_kdtree(pts, (size_t)n);
	} catch (const std::bad_alloc &) {
		return nullptr;
	}
}

extern "C" int bsim_markov_kdtree_nearest(const markov_kdtree *t, const double q[3], int k,
                                          long *idx)
{
	size_t found[BSIM_MARKOV_KDTREE_K_MAX];
	double d2[BSIM_MARKOV_KDTREE_K_MAX];
	const size_t want = k < BSIM_MARKOV_KDTREE_K_MAX ? (size_t)k : BSIM_MARKOV_KDTREE_K_MAX;
	const size_t n = t->t.knnSearch(q, want, found, d2);
	for (size_t i = 0; i < n; i++)
		idx[i] = (long)found[i];
	return (int)n;
}

extern "C" void bsim_markov_kdtree_free(markov_kdtree *t)
{
	delete t;
}
