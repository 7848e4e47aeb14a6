/* A trial's length in seconds: integration.duration beside max_steps, and
 * termination.gate_time beside gate_steps (docs/files.md "A trial's length").
 * The runner counts steps, so a time becomes steps of dt here, after the
 * walk of the scene's keys and before a lattice's defaults; a scene that
 * gives its lengths in seconds keeps them when dt changes.
 *
 * Which key counts, when a scene and its overrides give both of a pair:
 * the one given last (the file before its overrides, a later override
 * before an earlier one), since an override of either replaces the trial's
 * length; both given in one place (the file, or one override's mapping)
 * must agree, max_steps being exactly the steps the time gives at the dt
 * given with them, and the time then counts. */
#include <limits.h>
#include <math.h>
#include <string.h>

#include "model/scene_internal.h"

/* n = t / dt steps, rounded to the nearest integer when t / dt is within
 * 1e-9 relative of it (16.1 / 0.004 is 4025.0000000000005 in doubles, and
 * means 4025), else rounded up, so that the steps cover at least t. */
double bsim_scene_steps_for(double t, double dt)
{
	double r = t / dt;
	double n = round(r);
	return fabs(r - n) <= 1e-9 * r ? n : ceil(r);
}

typedef struct horizon_pair {
	const char *block;      /* "integration" */
	const char *steps_key;  /* "max_steps" */
	const char *time_key;   /* "duration" */
	scene_range time_range; /* SR_POSITIVE: at least one step; SR_NONNEG: 0 allowed */
	int *steps;             /* the scene's field the pair sets */
} horizon_pair;

/* The value at block.key and its key node (for positions of empty values). */
static struct fy_node *lookup(struct fy_node *root, const char *block, const char *key,
                              struct fy_node **key_node)
{
	struct fy_node *map = bsim_ydoc_lookup(root, block);
	struct fy_node_pair *p =
	        map && fy_node_is_mapping(map) ? bsim_ydoc_pair(map, key, strlen(key)) : NULL;
	if (key_node)
		*key_node = p ? fy_node_pair_key(p) : NULL;
	return p ? fy_node_pair_value(p) : NULL;
}

/* 1 if override a was applied after b (NULL: the file, before any). All
 * overrides of one load are one array, so a later one has the higher
 * address. */
static int later(const bsim_override *a, const bsim_override *b)
{
	return a && (!b || a > b);
}

/* The file's own dt, before any override: what the file's steps and time
 * must agree at. The default if the file leaves it out; the scene's dt if
 * the file's is not a valid number (then an override replaced it, or the
 * walk has refused it already). */
static double file_dt(const ydoc *file, const bsim_scene *s)
{
	struct fy_node *n = lookup(fy_document_root(file->fyd), "integration", "dt", NULL);
	double dt = 0;
	if (!n) {
		bsim_scene d = bsim_scene_default();
		return d.dt;
	}
	if (bsim_ydoc_number(n, &dt) != YDOC_NUM_OK || !bsim_scene_in_range(SR_POSITIVE, dt))
		return s->dt;
	return dt;
}

static int resolve(scene_walk *w, const ydoc *file, const horizon_pair *p)
{
	struct fy_node *root = fy_document_root(w->d->fyd), *kt, *ks;
	struct fy_node *nt = lookup(root, p->block, p->time_key, &kt);
	struct fy_node *ns = lookup(root, p->block, p->steps_key, &ks);
	if (!nt)
		return BSIM_OK;
	char tfield[64], sfield[64], got[96];
	snprintf(tfield, sizeof tfield, "%s.%s", p->block, p->time_key);
	snprintf(sfield, sizeof sfield, "%s.%s", p->block, p->steps_key);
	double t = 0;
	int rc = bsim_ydoc_number(nt, &t);
	if (rc == YDOC_NUM_NONFINITE)
		return bsim_ydoc_expected(w->d, nt, kt, tfield, "a finite number (s)", w->err);
	if (rc != YDOC_NUM_OK || !bsim_scene_in_range(p->time_range, t))
		return bsim_ydoc_expected(w->d, nt, kt, tfield,
		                          p->time_range == SR_POSITIVE ? "a positive number (s)"
		                                                       : "a number >= 0 (s)",
		                          w->err);
	if (ns) {
		const bsim_override *os = bsim_ydoc_origin(ns), *ot = bsim_ydoc_origin(nt);
		if (later(os, ot))
			return BSIM_OK; /* the steps, as walked */
		if (os == ot) {
			double dt = os ? w->s->dt : file_dt(file, w->s);
			double want = bsim_scene_steps_for(t, dt);
			if ((double)*p->steps != want) {
				bsim_ydoc_describe(nt, got, sizeof got);
				return bsim_ydoc_fail(
				        w->d, ns, ks, sfield, w->err,
				        "expected %.15g (%s %s s at integration.dt %.15g s; "
				        "give one of the two), got %d",
				        want, tfield, got, dt, *p->steps);
			}
		}
	}
	double n = bsim_scene_steps_for(t, w->s->dt);
	if (!(n <= INT_MAX)) {
		bsim_ydoc_describe(nt, got, sizeof got);
		return bsim_ydoc_fail(
		        w->d, nt, kt, tfield, w->err,
		        "expected at most %d steps of integration.dt %.15g s, got %s s "
		        "(%.3g steps)",
		        INT_MAX, w->s->dt, got, n);
	}
	*p->steps = (int)n;
	return BSIM_OK;
}

int bsim_scene_horizon(scene_walk *w, const ydoc *file)
{
	const horizon_pair pairs[2] = {
	        {"integration", "max_steps", "duration", SR_POSITIVE, &w->s->max_steps},
	        {"termination", "gate_steps", "gate_time", SR_NONNEG, &w->s->gate_steps},
	};
	for (int i = 0; i < 2; i++) {
		int rc = resolve(w, file, &pairs[i]);
		if (rc)
			return rc;
	}
	return BSIM_OK;
}
