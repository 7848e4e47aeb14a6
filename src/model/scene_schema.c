/* The scene file's keys (docs/files.md "Scene file (YAML)"): one table per
 * mapping. Blocks are namespaces over the same struct, so every offset in
 * the top table's tree is into bsim_scene; the beam table's are into
 * bsim_beam_def. */
#include "model/scene_internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define S(member) offsetof(bsim_scene, member)
#define B(member) offsetof(bsim_beam_def, member)
#define TABLE(fields)                                                                              \
	{                                                                                          \
		fields, (int)(sizeof fields / sizeof fields[0])                                    \
	}

static const scene_field body_fields[] = {
        {"mass", SK_NUMBER, SR_POSITIVE, 1, S(body.mass), NULL}, /* kg */
        /* > 0 for a disk and a capsule, absent for an ellipse (scene_load.c) */
        {"radius", SK_NUMBER, SR_NONNEG, 0, S(body.radius), NULL}, /* m */
        {"start", SK_VEC2, SR_ANY, 0, S(body.start), NULL},        /* m */
        {"velocity", SK_VEC2, SR_ANY, 0, S(body.velocity), NULL},  /* m/s */
        {"shape", SK_LATER, SR_ANY, 0, 0, NULL}, /* disk | capsule | ellipse (scene_load.c) */
        {"length", SK_NUMBER, SR_NONNEG, 0, S(body.length), NULL},                  /* m, capsule */
        {"semi_axes", SK_VEC2, SR_NONNEG, 0, S(body.semi_axes), NULL},              /* m, ellipse */
        {"heading_deg", SK_NUMBER, SR_ANY, 0, S(body.heading_deg), NULL},           /* deg */
        {"angular_velocity", SK_NUMBER, SR_ANY, 0, S(body.angular_velocity), NULL}, /* rad/s */
        {"inertia", SK_NUMBER, SR_NONNEG, 0, S(body.inertia), NULL}, /* kg m^2, 0: from shape */
        {"rotates", SK_LATER, SR_ANY, 0, 0, NULL},                   /* true | false */
};
static const scene_table body_table = TABLE(body_fields);

static const scene_field beam_fields[] = {
        {"pivot", SK_VEC2, SR_ANY, 1, B(pivot), NULL},                     /* m */
        {"rest_angle_deg", SK_NUMBER, SR_ANY, 0, B(rest_angle_deg), NULL}, /* deg */
        {"length", SK_NUMBER, SR_POSITIVE, 1, B(length), NULL},            /* m */
        {"mass", SK_NUMBER, SR_POSITIVE, 1, B(mass), NULL},                /* kg */
        {"inertia", SK_NUMBER, SR_POSITIVE, 0, B(inertia), NULL},          /* kg m^2 */
        {"stiffness", SK_NUMBER, SR_NONNEG, 1, B(stiffness), NULL},        /* N m/rad */
        {"damping", SK_NUMBER, SR_NONNEG, 0, B(damping), NULL},            /* N m s/rad */
        {"initial_theta", SK_NUMBER, SR_ANY, 0, B(initial_theta), NULL},   /* rad */
        {"initial_omega", SK_NUMBER, SR_ANY, 0, B(initial_omega), NULL},   /* rad/s */
};
const scene_table bsim_scene_beam_table = TABLE(beam_fields);

static const scene_field contact_fields[] = {
        {"restitution", SK_NUMBER, SR_UNIT, 0, S(contact.restitution), NULL},
        {"tip_restitution", SK_NUMBER, SR_UNIT, 0, S(contact.tip_restitution), NULL},
        {"rest_threshold", SK_NUMBER, SR_NONNEG, 0, S(contact.rest_threshold), NULL}, /* m/s */
        {"friction", SK_NUMBER, SR_NONNEG, 0, S(contact.friction), NULL},             /* 1 */
};
static const scene_table contact_table = TABLE(contact_fields);

static const scene_field propulsion_fields[] = {
        {"force", SK_NUMBER, SR_ANY, 1, S(effects.propulsion_force), NULL}, /* N */
        {"along", SK_LATER, SR_ANY, 0, 0, NULL}, /* y | heading (scene_load.c) */
};
static const scene_table propulsion_table = TABLE(propulsion_fields);

static const scene_field random_fields[] = {
        {"magnitude", SK_NUMBER, SR_NONNEG, 1, S(effects.random_magnitude), NULL},   /* N */
        {"frequency", SK_NUMBER, SR_POSITIVE, 0, S(effects.random_frequency), NULL}, /* Hz */
        {"model", SK_LATER, SR_ANY, 0, 0, NULL}, /* held | ou | white (scene_load.c) */
        {"correlation_time", SK_NUMBER, SR_POSITIVE, 0, S(effects.random_correlation_time),
         NULL}, /* s */
};
static const scene_table random_table = TABLE(random_fields);

static const scene_field drag_fields[] = {
        {"linear", SK_NUMBER, SR_NONNEG, 1, S(effects.drag_linear), NULL},   /* N s/m */
        {"angular", SK_NUMBER, SR_NONNEG, 0, S(effects.drag_angular), NULL}, /* N m s/rad */
};
static const scene_table drag_table = TABLE(drag_fields);

static const scene_field oscillation_fields[] = {
        {"amplitude", SK_NUMBER, SR_ANY, 1, S(effects.osc_amplitude), NULL},      /* N */
        {"frequency", SK_NUMBER, SR_POSITIVE, 1, S(effects.osc_frequency), NULL}, /* Hz */
        {"phase", SK_NUMBER, SR_ANY, 0, S(effects.osc_phase), NULL},              /* rad */
};
static const scene_table oscillation_table = TABLE(oscillation_fields);

static const scene_field ground_fields[] = {
        {"mu", SK_NUMBER, SR_NONNEG, 1, S(effects.ground_mu), NULL}, /* 1 */
        {"g", SK_NUMBER, SR_POSITIVE, 0, S(effects.ground_g), NULL}, /* m/s^2 */
        {"model", SK_LATER, SR_ANY, 0, 0, NULL}, /* coupled | decoupled (scene_load.c) */
};
static const scene_table ground_table = TABLE(ground_fields);

static const scene_field effects_fields[] = {
        {"propulsion", SK_BLOCK, SR_ANY, 0, S(effects.has_propulsion), &propulsion_table},
        {"random_force", SK_BLOCK, SR_ANY, 0, S(effects.has_random_force), &random_table},
        {"drag", SK_BLOCK, SR_ANY, 0, S(effects.has_drag), &drag_table},
        {"oscillation", SK_BLOCK, SR_ANY, 0, S(effects.has_oscillation), &oscillation_table},
        {"ground_friction", SK_BLOCK, SR_ANY, 0, S(effects.has_ground_friction), &ground_table},
};
static const scene_table effects_table = TABLE(effects_fields);

static const scene_field integration_fields[] = {
        {"dt", SK_NUMBER, SR_POSITIVE, 0, S(dt), NULL}, /* s */
        {"max_steps", SK_INT, SR_POSITIVE, 0, S(max_steps), NULL},
        {"duration", SK_LATER, SR_POSITIVE, 0, 0, NULL}, /* s: max_steps (scene_horizon.c) */
};
static const scene_table integration_table = TABLE(integration_fields);

static const scene_field termination_fields[] = {
        {"success_y", SK_NUMBER, SR_ANY, 0, S(success_y), NULL},   /* m */
        {"side_x", SK_NUMBER, SR_POSITIVE, 0, S(side_x), NULL},    /* m */
        {"classify_y", SK_NUMBER, SR_ANY, 0, S(classify_y), NULL}, /* m, >= success_y */
        {"classify_deadband", SK_NUMBER, SR_NONNEG, 0, S(classify_deadband), NULL}, /* m/s */
        {"gate_steps", SK_INT, SR_NONNEG, 0, S(gate_steps), NULL}, /* 0: max_steps */
        {"gate_time", SK_LATER, SR_NONNEG, 0, 0, NULL}, /* s: gate_steps (scene_horizon.c) */
};
static const scene_table termination_table = TABLE(termination_fields);

static const scene_field landscape_fields[] = {
        {"y0", SK_NUMBER, SR_ANY, 0, S(landscape_y0), NULL}, /* m */
};
static const scene_table landscape_table = TABLE(landscape_fields);

static const scene_field top_fields[] = {
        {"name", SK_NAME, SR_ANY, 0, S(name), NULL},
        {"body", SK_BLOCK, SR_ANY, 1, SCENE_NO_FLAG, &body_table},
        {"beams", SK_BEAMS, SR_ANY, 0, S(beams), &bsim_scene_beam_table},
        {"lattice", SK_LATTICE, SR_ANY, 0, S(has_lattice), &bsim_scene_lattice_table},
        {"contact", SK_BLOCK, SR_ANY, 0, SCENE_NO_FLAG, &contact_table},
        {"effects", SK_BLOCK, SR_ANY, 0, SCENE_NO_FLAG, &effects_table},
        {"integration", SK_BLOCK, SR_ANY, 0, SCENE_NO_FLAG, &integration_table},
        {"termination", SK_BLOCK, SR_ANY, 0, SCENE_NO_FLAG, &termination_table},
        {"landscape", SK_BLOCK, SR_ANY, 0, SCENE_NO_FLAG, &landscape_table},
};
const scene_table bsim_scene_top_table = TABLE(top_fields);

/* The lattice block (scene_lattice.c reads the SK_LATER keys itself). */
static const scene_field lattice_gate_fields[] = {
        {"width", SK_NUMBER, SR_POSITIVE, 0, S(lattice.width), NULL}, /* m */
        {"depth", SK_NUMBER, SR_POSITIVE, 0, S(lattice.depth), NULL}, /* m */
        {"pivot_y", SK_NUMBER, SR_ANY, 0, S(lattice.pivot_y), NULL},  /* m */
};
static const scene_table lattice_gate_table = TABLE(lattice_gate_fields);

static const scene_field lattice_beam_fields[] = {
        {"length", SK_NUMBER, SR_POSITIVE, 1, S(lattice.beam.length), NULL},     /* m */
        {"mass", SK_NUMBER, SR_POSITIVE, 1, S(lattice.beam.mass), NULL},         /* kg */
        {"inertia", SK_NUMBER, SR_POSITIVE, 0, S(lattice.beam.inertia), NULL},   /* kg m^2 */
        {"stiffness", SK_NUMBER, SR_NONNEG, 1, S(lattice.beam.stiffness), NULL}, /* N m/rad */
        {"damping", SK_NUMBER, SR_NONNEG, 0, S(lattice.beam.damping), NULL},     /* N m s/rad */
};
static const scene_table lattice_beam_table = TABLE(lattice_beam_fields);

static const scene_field lattice_fields[] = {
        {"columns", SK_INT, SR_POSITIVE, 0, S(lattice.columns), NULL},
        {"rows", SK_INT, SR_POSITIVE, 1, S(lattice.rows), NULL},
        {"ix_min", SK_INDEX, SR_ANY, 0, S(lattice.ix_min), NULL},
        {"ix_max", SK_INDEX, SR_ANY, 0, S(lattice.ix_max), NULL},
        {"gate", SK_BLOCK, SR_ANY, 0, SCENE_NO_FLAG, &lattice_gate_table},
        {"beam", SK_BLOCK, SR_ANY, 1, SCENE_NO_FLAG, &lattice_beam_table},
        {"stiffness", SK_LATER, SR_NONNEG, 0, 0, NULL},
        {"stiffness_left", SK_LATER, SR_NONNEG, 0, 0, NULL},
        {"stiffness_right", SK_LATER, SR_NONNEG, 0, 0, NULL},
        {"stiffness_file", SK_LATER, SR_ANY, 0, 0, NULL},
        {"protocol", SK_LATER, SR_ANY, 0, 0, NULL},
};
const scene_table bsim_scene_lattice_table = TABLE(lattice_fields);

const char *bsim_scene_phrase(const scene_field *f)
{
	switch (f->kind) {
	case SK_NUMBER:
		switch (f->range) {
		case SR_POSITIVE:
			return "a positive number";
		case SR_NONNEG:
			return "a number >= 0";
		case SR_UNIT:
			return "a number in [0, 1]";
		default:
			return "a number";
		}
	case SK_INT:
		return f->range == SR_NONNEG ? "an integer >= 0" : "a positive integer";
	case SK_VEC2:
		return "a list of 2 numbers [x, y]";
	case SK_NAME:
		return "a non-empty string";
	case SK_BLOCK:
		return "a mapping";
	case SK_BEAMS:
		return "a non-empty list of beams";
	case SK_INDEX:
		return "an integer";
	case SK_LATTICE:
		return "a mapping (a gate lattice)";
	case SK_LATER:
		return "a value";
	}
	return "a value";
}

int bsim_scene_in_range(scene_range r, double v)
{
	if (!isfinite(v))
		return 0;
	switch (r) {
	case SR_POSITIVE:
		return v > 0;
	case SR_NONNEG:
		return v >= 0;
	case SR_UNIT:
		return v >= 0 && v <= 1;
	default:
		return 1;
	}
}

void bsim_scene_path_format(const scene_path *p, char *buf, size_t size)
{
	if (size == 0)
		return;
	buf[0] = '\0';
	if (!p)
		return;
	bsim_scene_path_format(p->up, buf, size);
	size_t len = strlen(buf);
	const char *dot = len ? "." : "";
	if (p->key)
		snprintf(buf + len, size - len, "%s%s", dot, p->key);
	else
		snprintf(buf + len, size - len, "%s%d", dot, p->index);
}

void bsim_scene_keys(const scene_table *t, char *buf, size_t size)
{
	size_t used = 0;
	buf[0] = '\0';
	for (int i = 0; i < t->n_fields && used < size; i++) {
		int k = snprintf(buf + used, size - used, "%s%s", i ? ", " : "", t->fields[i].key);
		if (k < 0)
			break;
		used += (size_t)k;
	}
}
