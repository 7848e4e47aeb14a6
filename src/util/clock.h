/* Wall-clock time for timings and ETAs. */
#ifndef BSIM_UTIL_CLOCK_H
#define BSIM_UTIL_CLOCK_H

#ifdef __cplusplus
extern "C" {
#endif

/* Seconds on a monotonic clock from an arbitrary origin. */
double bsim_clock_seconds(void);

#ifdef __cplusplus
}
#endif
#endif
