/* Internal: what scene.c, scene_schema.c and scene_load.c share. The scene
 * schema is a table per YAML mapping (key, type, range, offset), so the file
 * loader and bsim_scene_validate check the same things from one list. */
#ifndef BSIM_MODEL_SCENE_INTERNAL_H
#define BSIM_MODEL_SCENE_INTERNAL_H

#include <stddef.h>

#include "beamsim/scene.h"
#include "util/yaml_doc.h"

typedef enum scene_kind {
	SK_NUMBER,  /* double, finite, in range */
	SK_INT,     /* int > 0 */
	SK_VEC2,    /* double[2], finite: [x, y] */
	SK_NAME,    /* char[128], non-empty */
	SK_BLOCK,   /* a nested mapping (sub) */
	SK_BEAMS,   /* the list of beams (sub describes one beam) */
	SK_INDEX,   /* int, any sign */
	SK_LATTICE, /* the lattice block (scene_lattice.c) */
	SK_LATER,   /* read by the block's own code after the table's walk */
} scene_kind;

typedef enum scene_range {
	SR_ANY,      /* any finite number */
	SR_POSITIVE, /* > 0 */
	SR_NONNEG,   /* >= 0 */
	SR_UNIT,     /* in [0, 1] */
} scene_range;

/* For an SK_BLOCK without a presence flag. */
#define SCENE_NO_FLAG ((size_t)-1)

typedef struct scene_table scene_table;

typedef struct scene_field {
	const char *key;
	scene_kind kind;
	scene_range range;
	int required;
	/* Byte offset of the value in the struct the table describes; for an
	 * SK_BLOCK, of the int set to 1 when the block is present (effects
	 * simulate only what is listed), or SCENE_NO_FLAG. */
	size_t offset;
	const scene_table *sub;
} scene_field;

struct scene_table {
	const scene_field *fields;
	int n_fields;
};

extern const scene_table bsim_scene_top_table;  /* offsets into bsim_scene */
extern const scene_table bsim_scene_beam_table; /* offsets into bsim_beam_def */

/* What a field expects, for messages: "a positive number", "a mapping". */
const char *bsim_scene_phrase(const scene_field *f);

int bsim_scene_in_range(scene_range r, double v);

/* "pivot, rest_angle_deg, ..." for unknown-key messages. */
void bsim_scene_keys(const scene_table *t, char *buf, size_t size);

/* Everything that has a default gets it; the rest is zero. */
void bsim_scene_defaults(bsim_scene *s);

/* Index of the first beam the body overlaps at the start, or -1; *dist in
 * m. A disk: the distance from its centre to the beam's segment < radius,
 * *dist that distance. Another shape: its outline against the segment
 * (beamsim/body_shape.h) has a gap < 0, *dist the gap (0 where the segment
 * crosses the body's centre line). */
int bsim_scene_overlap(const bsim_scene *s, double *dist);

/* A field's dotted path ("beams.3.stiffness", "body.start.0"), kept as its
 * parts while a scene is walked or checked and spelled out only for a
 * message: a field of a lattice's thousands of beams costs no formatting. */
typedef struct scene_path {
	const struct scene_path *up; /* the enclosing block's or list's, NULL at the top */
	const char *key;             /* the field's key; NULL: item `index` of a list */
	int index;
} scene_path;

/* The path p spelled out into buf ("" for none). */
void bsim_scene_path_format(const scene_path *p, char *buf, size_t size);

/* A walk of a scene document into a scene (scene_load.c). */
typedef struct scene_walk {
	const ydoc *d;
	bsim_scene *s;
	bsim_error *err;
} scene_walk;

/* Walks one mapping (NULL: an empty one) at path `at` (NULL: the top)
 * against table t into base: unknown keys are errors, known ones are
 * stored, missing required ones reported. */
int bsim_scene_walk_table(scene_walk *w, const scene_table *t, struct fy_node *map,
                          struct fy_node *alt, char *base, const scene_path *at);

/* The lattice: block (scene_lattice.c). The loader walks its keys
 * (bsim_scene_lattice_table) between the two calls: begin sets the gate's
 * defaults, finish checks the ranges, reads the stiffness maps and CSV file
 * and builds the beams. */
void bsim_scene_lattice_begin(bsim_scene *s);
int bsim_scene_lattice_finish(scene_walk *w, struct fy_node *n, struct fy_node *key);
extern const scene_table bsim_scene_lattice_table;

/* The termination defaults of a lattice (lattice.c): success_y = depth
 * rows, side_x = width columns / 2, classify_y = success_y, landscape y0 =
 * success_y, gate_steps = 3000, max_steps = gate_steps (rows + columns). */
void bsim_scene_lattice_defaults(bsim_scene *s);

/* The steps of dt that make up t seconds: round(t / dt) when t / dt is
 * within 1e-9 relative of an integer, else ceil(t / dt) (scene_horizon.c). */
double bsim_scene_steps_for(double t, double dt);

/* After the walk of a scene document (w->d, overrides applied; file the
 * document before them): integration.duration and termination.gate_time
 * into max_steps and gate_steps at the scene's dt, or refused where the
 * file (or one override) gives a time and steps that disagree. */
int bsim_scene_horizon(scene_walk *w, const ydoc *file);

/* A limit of beamsim/limits.h that a scene exceeds: the field to blame,
 * what it asks for and the limit's name and value. */
typedef struct scene_excess {
	const char *field; /* "effects.random_force.frequency", ... */
	const char *limit; /* "schedule", "beam_steps" */
	double got, max;
	const char *what; /* "random-force values per trial (frequency x dt x max_steps)" */
	int beams;        /* beam_steps: the scene's beams, a lattice's every one */
} scene_excess;

/* What x's count is made of, for its message: " = 3000 steps x 199800
 * beams" for beam_steps, "" for the others. */
void bsim_scene_excess_detail(const bsim_scene *s, const scene_excess *x, char *buf, size_t size);

/* 1 and *x if the scene asks for more than a limit allows, else 0. */
int bsim_scene_excess_find(const bsim_scene *s, scene_excess *x);

/* A bound on integration.dt from one of the scene's time scales
 * (scene_timestep.c, docs/model.md "The time step"). */
#define SCENE_DT_BOUNDS 5 /* random force, oscillation, spring, damper, crossing */
#define SCENE_DT_PATHS  12
typedef struct scene_dt_bound {
	double max;     /* s, the longest step it allows */
	int strict;     /* 1: dt must stay below max */
	char what[384]; /* "the random force's hold 1/f, f = 50 Hz" */
	/* The fields it involves besides integration.dt, for the loader to
	 * blame the one an override changed last. */
	char paths[SCENE_DT_PATHS][48];
	int n_paths;
} scene_dt_bound;

/* The body's speed scale for the crossing bound, m/s: its start speed, plus
 * what its forces (propulsion, random force magnitude, oscillation
 * amplitude) give it from rest over the distance to the farthest point a
 * beam reaches (a lattice's gate depth or width), capped at the drag's
 * terminal speed F/c, plus its spin times its reach, plus the fastest beam
 * tip a beam's initial angle and speed give. */
typedef struct scene_speed {
	double start, accel, distance, forces, spin, tips, total;
	int drag_capped;
} scene_speed;
void bsim_scene_speed_scale(const bsim_scene *s, scene_speed *v);

/* Every bound the scene has (those of absent effects and of beams without
 * spring or damper are none), the beams' the tightest beam's; returns
 * their number. */
int bsim_scene_dt_bounds(const bsim_scene *s, scene_dt_bound out[SCENE_DT_BOUNDS]);

/* 1 and *broken the tightest bound the scene's dt breaks, else 0. */
int bsim_scene_dt_find(const bsim_scene *s, scene_dt_bound *broken);

/* "expected at most 0.02 s (the random force's hold ...), got 0.5": the
 * bound stated rounded down to 4 digits, so that it is a step accepted. */
void bsim_scene_dt_message(const bsim_scene *s, const scene_dt_bound *b, char *buf, size_t size);

/* bsim_scene_load on a document already read (the experiment loader reads
 * the scene file once and builds every group from a clone of it). */
int bsim_scene_load_parsed(const ydoc *file, const bsim_override *ov, int n, bsim_scene *out,
                           bsim_error *err);

#endif
