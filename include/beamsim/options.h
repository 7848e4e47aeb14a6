/* Backend options: typed key/value knobs (`--backend-opt key=value`),
 * checked against a backend's knob table (beamsim/backend.h) and read with
 * each knob's default. */
#ifndef BSIM_OPTIONS_H
#define BSIM_OPTIONS_H

#include "beamsim/base.h"
#include "beamsim/error.h"

#ifdef __cplusplus
extern "C" {
#endif

#define BSIM_OPTIONS_MAX 16
typedef struct bsim_options {
	int n;
	char key[BSIM_OPTIONS_MAX][32];
	char value[BSIM_OPTIONS_MAX][64];
} bsim_options;

/* Parses "key=value" into opts (later wins). BSIM_EINPUT on bad syntax. */
BSIM_API int bsim_options_add(bsim_options *opts, const char *kv, bsim_error *err);
/* The value of key, or NULL. */
BSIM_API const char *bsim_options_get(const bsim_options *opts, const char *key);

typedef enum { BSIM_KNOB_INT, BSIM_KNOB_DOUBLE, BSIM_KNOB_CHOICE } bsim_knob_type;

typedef struct bsim_knob {
	const char *name;
	bsim_knob_type type;
	const char *default_value;
	const char *choices; /* "a|b|c" for BSIM_KNOB_CHOICE, else NULL */
	const char *help;
} bsim_knob;

/* A setting of several knobs under a short name: options is
 * "KEY=VALUE:KEY=VALUE..." (the syntax of compare's inline options). */
typedef struct bsim_knob_setting {
	const char *name;    /* "midpoint simultaneous" */
	const char *options; /* "integrator=midpoint:impact_order=simultaneous" */
} bsim_knob_setting;

/* Adds a setting's options to opts (later ones win). BSIM_EINPUT naming
 * the setting on bad syntax. */
BSIM_API int bsim_options_add_setting(bsim_options *opts, const bsim_knob_setting *setting,
                                      bsim_error *err);

/* Checks every option names a knob and parses as its type (BSIM_EINPUT
 * naming the option and what was expected otherwise). */
BSIM_API int bsim_options_check(const bsim_options *opts, const bsim_knob *knobs, int n_knobs,
                                const char *backend, bsim_error *err);
/* Typed look-ups with the knob's default. */
BSIM_API double bsim_options_double(const bsim_options *opts, const bsim_knob *knob);
BSIM_API long bsim_options_int(const bsim_options *opts, const bsim_knob *knob);
/* Index of the chosen value in knob->choices. */
BSIM_API int bsim_options_choice(const bsim_options *opts, const bsim_knob *knob);

/* out = given with every knob of the table not given set to its default:
 * the options a run really used. */
BSIM_API void bsim_options_effective(const bsim_knob *knobs, int n_knobs, const bsim_options *given,
                                     bsim_options *out);

#ifdef __cplusplus
}
#endif
#endif
