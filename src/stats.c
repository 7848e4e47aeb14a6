/* Statistics of traversal counts.
 *
 * Wilson score interval: with p = k/n and c = z^2/n,
 *   centre = (p + c/2) / (1 + c)
 *   half   = z / (1 + c) * sqrt(p (1 - p) / n + c / (4 n))
 * It stays inside [0, 1] and is sensible at p = 0 and p = 1, where the
 * normal-approximation interval collapses to a point. */
#include "beamsim/stats.h"

#include <math.h>

void bsim_wilson(int k, int n, double z, double *lo, double *hi)
{
	if (n <= 0) {
		*lo = 0.0;
		*hi = 1.0;
		return;
	}
	double p = (double)k / n;
	double c = z * z / n;
	double centre = (p + 0.5 * c) / (1.0 + c);
	double half = z / (1.0 + c) * sqrt(p * (1.0 - p) / n + 0.25 * c / n);
	/* At k = 0 and k = n the bound is exactly 0 or 1; computing it would
	 * leave a round-off residue like 1e-18 in the output. */
	*lo = k <= 0 ? 0.0 : fmax(0.0, centre - half);
	*hi = k >= n ? 1.0 : fmin(1.0, centre + half);
}
