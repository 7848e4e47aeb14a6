/* The end of a run that wrote an output directory: every file its
 * manifest.json lists, one line each with a few words of what it is. */
#ifndef BSIM_CLI_CLI_WROTE_H
#define BSIM_CLI_CLI_WROTE_H

#include <stddef.h>
#include <stdio.h>

/* "wrote DIR/ (manifest.json lists these):" then each file listed in
 * DIR/manifest.json, indented, with what it is. Prints only the first line
 * if the manifest cannot be read. */
void cli_wrote(FILE *f, const char *dir);

/* What the file at path (below an output directory) is, in a few words:
 * a figure, or the caption index.html gives it (store/index_html.h), in
 * buf; "" if it is not one beamsim names (a .mat: cli_wrote names its
 * twin). */
const char *cli_wrote_what(const char *path, char *buf, size_t size);

#endif
