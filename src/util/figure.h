/* Figures drawn by gnuplot (Debian gnuplot-nox) from scripts beamsim writes.
 *
 * A figure NAME in directory DIR is four kinds of file side by side:
 *   NAME.gp            the gnuplot script, rerunnable by hand (`gnuplot NAME.gp` in DIR)
 *   NAME*.dat / .csv   the data it reads, written by the caller beforehand
 *   NAME.png, NAME.svg what gnuplot draws (pngcairo and svg terminals)
 * The script is the caller's gnuplot commands (the body) wrapped in a loop
 * over the two terminals, so a user restyles the body once and gets both.
 * Data files are named in the body relative to DIR.
 *
 * gnuplot writes the images under temporary names, renamed into place when
 * it exits with status 0 and both images are whole, so a figure appears
 * whole or not at all. A figure gnuplot failed on keeps its script and data
 * (drawn = BSIM_FIGURE_FAILED): what made them is sound, and the caller
 * keeps it (store/session.h, bsim_session_defer). Without gnuplot on the
 * PATH the script and data are still written and the caller is told
 * (drawn = BSIM_FIGURE_UNDRAWN), with a message naming the package to
 * install. */
#ifndef BSIM_UTIL_FIGURE_H
#define BSIM_UTIL_FIGURE_H

#include "beamsim/error.h"

/* The colour convention of every potential-energy landscape (beamsim
 * landscape, the paths of beamsim plot, Fig. 2.7): a grey to dark
 * blue-green map, light where the energy is low (where the paths run), and
 * a colour bar with this label. Nothing drawn over it is grey or
 * blue-green: the paths of the left and right types are blue and
 * vermilion, those of neither type magenta, saturated colours the map never
 * reaches, each drawn over a white outline. */
#define BSIM_FIGURE_LANDSCAPE_PALETTE                                                              \
	"set palette defined (0 '#E4EBE9', 0.35 '#BFCFCB', 0.7 '#7E9E99', 1 '#2E4A47')\n"
#define BSIM_FIGURE_LANDSCAPE_CBLABEL "potential energy E_{total} (J)"
#define BSIM_FIGURE_PATH_LEFT         "#0072B2"
#define BSIM_FIGURE_PATH_RIGHT        "#D55E00"
#define BSIM_FIGURE_PATH_NONE         "#B8008A"
#define BSIM_FIGURE_PATH_OUTLINE      "#FFFFFF"

typedef struct bsim_figure_def {
	const char *dir;  /* output directory, existing */
	const char *name; /* base name of NAME.gp, NAME.png, NAME.svg */
	int width;        /* pixels of the PNG (and the SVG's size), default 900 */
	int height;       /* default 600 */
	const char *font; /* gnuplot font spec, default "sans,11" */
} bsim_figure_def;

/* dir and name NULL, 900 x 600, "sans,11". */
bsim_figure_def bsim_figure_def_default(void);

/* What *drawn of the calls below says. */
enum {
	BSIM_FIGURE_FAILED = -1, /* gnuplot failed (BSIM_EFAIL): scripts and data written */
	BSIM_FIGURE_UNDRAWN = 0, /* gnuplot is missing: scripts and data written */
	BSIM_FIGURE_DRAWN = 1,   /* the images too */
};

/* Writes DIR/NAME.gp around body (gnuplot commands, newline-separated) and,
 * if gnuplot is on the PATH, runs it to draw NAME.png and NAME.svg. drawn
 * (may be NULL) as above. BSIM_EFAIL if the script cannot be written
 * (drawn BSIM_FIGURE_UNDRAWN), or if gnuplot exits with another status than
 * 0 or leaves an image cut short (BSIM_FIGURE_FAILED): the message names
 * the figure, quotes gnuplot's last line, and names the script and the data
 * it reads, which stay in DIR. */
int bsim_figure_render(const bsim_figure_def *def, const char *body, int *drawn, bsim_error *err);

/* Renders n figures as bsim_figure_render does, their gnuplot processes
 * running at the same time (a figure's wall time is mostly gnuplot's). All
 * scripts are written first; drawn (may be NULL) is BSIM_FIGURE_DRAWN if
 * every figure was drawn. A figure that fails does not stop the others; the
 * message names every one that failed, in order. */
int bsim_figure_render_all(const bsim_figure_def *defs, const char *const *bodies, int n,
                           int *drawn, bsim_error *err);

/* Text in a figure, for sizing the canvas to it. The pixels the widest
 * line of text (lines split at '\n', a UTF-8 character counted once) takes
 * in gnuplot's pngcairo at a font of pt points: 0.68 pt a character, the
 * width of the widest lines of the figures' sans measured on their titles
 * (7.5 pixels at 11 pt), so that a title sized by it is not cut off. */
int bsim_figure_text_px(const char *text, double pt);

/* text into out (size bytes) with its lines broken where one would be
 * wider than width pixels at pt points: after the last "; " that leaves a
 * line at least a third as wide, else after the last ", ", else at the
 * last space; a line without a space stays whole. */
void bsim_figure_wrap(const char *text, double pt, int width, char *out, size_t size);

/* 1 if gnuplot can be run (looked up once per process). */
int bsim_figure_available(void);

/* The message for a missing gnuplot, naming the package and DIR: for the
 * CLI to print once after writing a directory's figures. */
const char *bsim_figure_missing_hint(void);

#endif
