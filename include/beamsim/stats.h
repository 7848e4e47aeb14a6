/* Statistics of traversal counts. */
#ifndef BEAMSIM_STATS_H
#define BEAMSIM_STATS_H

#ifdef __cplusplus
extern "C" {
#endif

/* Wilson score interval for k successes in n trials at confidence z
 * (1.959964 for 95%). n = 0 gives [0, 1]. */
void bsim_wilson(int k, int n, double z, double *lo, double *hi);

#define BSIM_Z95 1.959963984540054

#ifdef __cplusplus
}
#endif
#endif
