/* The pairs of a sweep's sides (beamsim/sweep.h), in the order (0, 1),
 * (0, 2), ..., (1, 2), ...: what the journal's records, the comparison and
 * its files all count pairs by. */
#include "beamsim/sweep.h"

int bsim_sweep_pairs(int n_sides)
{
	return n_sides > 1 ? n_sides * (n_sides - 1) / 2 : 0;
}

void bsim_sweep_pair(int n_sides, int k, int side[2])
{
	side[0] = side[1] = 0;
	for (int i = 0; i < n_sides; i++)
		for (int j = i + 1; j < n_sides; j++)
			if (k-- == 0) {
				side[0] = i;
				side[1] = j;
				return;
			}
}
