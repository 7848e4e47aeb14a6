/* Backend options: `--backend-opt key=value` pairs, checked against the
 * backend's knob table and read with the knob's default. */
#include "beamsim/options.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int bsim_options_add(bsim_options *opts, const char *kv, bsim_error *err)
{
	const char *eq = strchr(kv, '=');
	size_t klen = eq ? (size_t)(eq - kv) : 0;
	if (!eq || klen == 0 || klen >= sizeof opts->key[0] ||
	    strlen(eq + 1) >= sizeof opts->value[0] || eq[1] == '\0')
		return bsim_error_set(err, BSIM_EINPUT,
		                      "--backend-opt %s: expected KEY=VALUE (key < 32, value < 64 "
		                      "characters)",
		                      kv);
	int slot = opts->n;
	for (int i = 0; i < opts->n; i++)
		if (strlen(opts->key[i]) == klen && strncmp(opts->key[i], kv, klen) == 0)
			slot = i;
	if (slot == BSIM_OPTIONS_MAX)
		return bsim_error_set(err, BSIM_EINPUT, "--backend-opt %s: more than %d options",
		                      kv, BSIM_OPTIONS_MAX);
	memcpy(opts->key[slot], kv, klen);
	opts->key[slot][klen] = '\0';
	strcpy(opts->value[slot], eq + 1);
	if (slot == opts->n)
		opts->n++;
	return BSIM_OK;
}

const char *bsim_options_get(const bsim_options *opts, const char *key)
{
	for (int i = 0; opts && i < opts->n; i++)
		if (strcmp(opts->key[i], key) == 0)
			return opts->value[i];
	return NULL;
}

static int parse_double(const char *s, double *out)
{
	char *end;
	errno = 0;
	*out = strtod(s, &end);
	return errno == 0 && end != s && *end == '\0' && isfinite(*out);
}

static int parse_long(const char *s, long *out)
{
	char *end;
	errno = 0;
	*out = strtol(s, &end, 10);
	return errno == 0 && end != s && *end == '\0';
}

/* Index of value in "a|b|c", or -1. */
static int choice_index(const char *choices, const char *value)
{
	size_t n = strlen(value);
	int i = 0;
	for (const char *p = choices; p; i++) {
		const char *bar = strchr(p, '|');
		size_t len = bar ? (size_t)(bar - p) : strlen(p);
		if (len == n && strncmp(p, value, n) == 0)
			return i;
		p = bar ? bar + 1 : NULL;
	}
	return -1;
}

static const bsim_knob *knob_find(const bsim_knob *knobs, int n, const char *name)
{
	for (int i = 0; i < n; i++)
		if (strcmp(knobs[i].name, name) == 0)
			return &knobs[i];
	return NULL;
}

int bsim_options_check(const bsim_options *opts, const bsim_knob *knobs, int n_knobs,
                       const char *backend, bsim_error *err)
{
	for (int i = 0; opts && i < opts->n; i++) {
		const bsim_knob *k = knob_find(knobs, n_knobs, opts->key[i]);
		double d;
		long l;
		if (!k) {
			char names[512] = "";
			for (int j = 0; j < n_knobs; j++) {
				if (j)
					strncat(names, ", ", sizeof names - strlen(names) - 1);
				strncat(names, knobs[j].name, sizeof names - strlen(names) - 1);
			}
			return bsim_error_set(err, BSIM_EINPUT,
			                      "--backend-opt %s: unknown option of backend %s "
			                      "(expected one of %s)",
			                      opts->key[i], backend, names);
		}
		const char *v = opts->value[i];
		int ok = k->type == BSIM_KNOB_DOUBLE ? parse_double(v, &d)
		         : k->type == BSIM_KNOB_INT  ? parse_long(v, &l)
		                                     : choice_index(k->choices, v) >= 0;
		if (!ok)
			return bsim_error_set(err, BSIM_EINPUT,
			                      "--backend-opt %s=%s: expected %s%s", k->name, v,
			                      k->type == BSIM_KNOB_DOUBLE ? "a finite number"
			                      : k->type == BSIM_KNOB_INT  ? "an integer"
			                                                  : "one of ",
			                      k->type == BSIM_KNOB_CHOICE ? k->choices : "");
	}
	return BSIM_OK;
}

double bsim_options_double(const bsim_options *opts, const bsim_knob *knob)
{
	const char *v = bsim_options_get(opts, knob->name);
	double d;
	if (v && parse_double(v, &d))
		return d;
	return strtod(knob->default_value, NULL);
}

long bsim_options_int(const bsim_options *opts, const bsim_knob *knob)
{
	const char *v = bsim_options_get(opts, knob->name);
	long l;
	if (v && parse_long(v, &l))
		return l;
	return strtol(knob->default_value, NULL, 10);
}

int bsim_options_choice(const bsim_options *opts, const bsim_knob *knob)
{
	const char *v = bsim_options_get(opts, knob->name);
	int i = v ? choice_index(knob->choices, v) : -1;
	return i >= 0 ? i : choice_index(knob->choices, knob->default_value);
}

void bsim_options_effective(const bsim_knob *knobs, int n_knobs, const bsim_options *given,
                            bsim_options *out)
{
	*out = given ? *given : (bsim_options){0};
	for (int i = 0; i < n_knobs && out->n < BSIM_OPTIONS_MAX; i++) {
		if (bsim_options_get(out, knobs[i].name) || !knobs[i].default_value)
			continue;
		snprintf(out->key[out->n], sizeof out->key[0], "%s", knobs[i].name);
		snprintf(out->value[out->n], sizeof out->value[0], "%s", knobs[i].default_value);
		out->n++;
	}
}

int bsim_options_add_setting(bsim_options *opts, const bsim_knob_setting *setting, bsim_error *err)
{
	for (const char *p = setting->options; *p;) {
		size_t len = strcspn(p, ":");
		char kv[128];
		if (len >= sizeof kv)
			return bsim_error_set(err, BSIM_EINPUT, "setting %s: option too long",
			                      setting->name);
		snprintf(kv, sizeof kv, "%.*s", (int)len, p);
		if (bsim_options_add(opts, kv, err) != BSIM_OK)
			return BSIM_EINPUT;
		p += len + (p[len] == ':');
	}
	return BSIM_OK;
}
