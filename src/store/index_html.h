/* DIR/index.html: a page playing the trajectories of an output directory
 * (store/viewer_data.h) and showing every figure of it with a one-line
 * caption and links to its SVG, its gnuplot script and its data, then the
 * directory's other files (index_html.c). Written into the staging area
 * with the run's other files, so it appears with them and manifest.json
 * lists it. */
#ifndef BSIM_STORE_INDEX_HTML_H
#define BSIM_STORE_INDEX_HTML_H

#include <stddef.h>

#include "beamsim/error.h"

/* The caption of a file (by its base name, "landscape_g003.png"), from a
 * table of name patterns: "" for a name the table does not know. A
 * pattern's '*' stands for any text; a caption's "%s" is that text, "%k"
 * the scene key it names ("beams_0_stiffness") by its display label. */
void bsim_index_caption(const char *base, char *buf, size_t size);

/* Writes stage/index.html if stage (or, with add, also dir: the set the
 * run's files join) holds a .png, under any subdirectory, or a trajectory
 * to play (then also stage/viewer_data.js and stage/viewer.js); dir is the
 * directory as the user named it (the page's title), command names the
 * run ("sweep", "plot"). Nothing is written if there is neither. */
int bsim_index_html_write(const char *stage, const char *dir, int add, const char *command,
                          bsim_error *err);

#endif
