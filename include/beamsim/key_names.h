/* Display names and units of scene keys: what figures, legends, panel titles
 * and tables show instead of a YAML path ("propulsive force F_prop (N)" for
 * effects.propulsion.force). One table for the whole project, so that a key
 * reads the same in every figure. */
#ifndef BSIM_KEY_NAMES_H
#define BSIM_KEY_NAMES_H

#include "beamsim/base.h"

#include <stddef.h>

/* How a scene key reads. name: words ("propulsive force"); symbol: the
 * model's symbol in plain ASCII ("F_prop", "k_1"), for terminals and CSV;
 * symbol_gp: the same in gnuplot's enhanced text ("F_{prop}", "k_{1}");
 * unit: SI unit ("N", "N m/rad"), "" for a number without one. Beam keys
 * (beams.N.*) follow the essay's numbering: beam 1 (beams.0) is the left
 * beam of a gate and beam 2 (beams.1) the right one, as in every shipped
 * gate scene. */
typedef struct bsim_key_name {
	char name[96];
	char symbol[96];
	char symbol_gp[192];
	const char *unit;
} bsim_key_name;

/* Fills *out for key ("effects.random_force.magnitude", "beams.0.stiffness",
 * "lattice.stiffness_left", ...). Returns 1 for a key of the table; 0 for
 * any other, with name and symbols the key itself and unit "". */
BSIM_API int bsim_key_name_find(const char *key, bsim_key_name *out);

/* "propulsive force F_prop (N)": an axis label in plain text (gp 0) or in
 * gnuplot's enhanced text (gp 1; the caller's text must then be drawn
 * enhanced). Returns what snprintf returns. */
BSIM_API int bsim_key_label(const char *key, int gp, char *buf, size_t size);

/* "F_prop = 8 N": a key's value for a title or legend, value as written
 * (the grid's text, "8"). gp as for bsim_key_label. */
BSIM_API int bsim_key_value(const char *key, const char *value, int gp, char *buf, size_t size);

#endif
