/* Internal: the messages of a program beamsim starts (gnuplot, ffmpeg),
 * caught in an unnamed temporary file that is its standard error and read
 * back once it has ended, so that a failure quotes the program's own words
 * ("Error writing trailer of ...: No space left on device", "\"NAME.gp\"
 * line 32: Can't plot with an empty z range!"). */
#ifndef BSIM_UTIL_PROGRAM_LOG_H
#define BSIM_UTIL_PROGRAM_LOG_H

#include <stddef.h>
#include <stdio.h>

/* A temporary file for the messages, closed on exec (other programs
 * started meanwhile do not hold it); dup2 its descriptor to the program's
 * standard error. NULL if none can be made (the messages are then lost,
 * not the run). */
FILE *bsim_program_log_open(void);

/* The first (last = 0) or last (last = 1) line of log that is not empty,
 * line ends removed, cut to fit buf (of size n); "" if there is none. */
void bsim_program_log_line(FILE *log, int last, char *buf, size_t n);

/* Every line of log that is not empty, passed on as a note (bsim_note):
 * "PREFIX: LINE". */
void bsim_program_log_notes(FILE *log, const char *prefix);

#endif
