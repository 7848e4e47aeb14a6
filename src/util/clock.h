/* Wall-clock time for timings and ETAs, and a thread's CPU time for costs
 * measured on a machine other programs share. */
#ifndef BSIM_UTIL_CLOCK_H
#define BSIM_UTIL_CLOCK_H

#ifdef __cplusplus
extern "C" {
#endif

/* Seconds on a monotonic clock from an arbitrary origin. */
double bsim_clock_seconds(void);
/* CPU seconds the calling thread has used, from an arbitrary origin: what a
 * computation costs whatever else the machine runs at the same time. */
double bsim_clock_thread_cpu_seconds(void);
/* CPU seconds of the whole process, all its threads. */
double bsim_clock_process_cpu_seconds(void);

#ifdef __cplusplus
}
#endif
#endif
