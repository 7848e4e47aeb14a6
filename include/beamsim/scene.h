/* A scene: one body, any number of beams, the contact law, the effects to
 * simulate, and the integration and termination settings (docs/files.md
 * "Scene file (YAML)", docs/model.md sections 1-6). All quantities SI. */
#ifndef BSIM_SCENE_H
#define BSIM_SCENE_H

#include "beamsim/base.h"
#include "beamsim/override.h"
#include "beamsim/error.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct bsim_beam_def {
	double pivot[2];       /* m */
	double rest_angle_deg; /* direction of the beam at rest, 0 = +x, degrees */
	double length;         /* m, > 0 */
	double mass;           /* kg, > 0 */
	double inertia;        /* kg m^2 about the pivot; default mass*length^2/3 */
	double stiffness;      /* N m/rad, >= 0 */
	double damping;        /* N m s/rad, >= 0 */
	double initial_theta;  /* rad, forward positive; default 0 */
	double initial_omega;  /* rad/s; default 0 */
} bsim_beam_def;

/* The body's outline. A disk of radius R; a capsule: the points within R
 * of a segment of length `length` along the heading (length + 2R long, 2R
 * wide); an ellipse with semi-axes a along the heading and b across. */
typedef enum bsim_body_shape {
	BSIM_SHAPE_DISK = 0,
	BSIM_SHAPE_CAPSULE = 1,
	BSIM_SHAPE_ELLIPSE = 2,
} bsim_body_shape;

typedef struct bsim_body_def {
	double mass;        /* kg, > 0 */
	double radius;      /* m, > 0: the disk's, the capsule's half-width; unused by an ellipse */
	double start[2];    /* m; default (0, 0) */
	double velocity[2]; /* m/s; default (0, 0) */
	bsim_body_shape shape; /* default BSIM_SHAPE_DISK */
	double length;         /* m, > 0: the capsule's segment */
	double semi_axes[2];   /* m, > 0: the ellipse's a (along the heading) and b */
	/* The heading: the direction of the body's long axis and of a thrust
	 * along it, degrees from +x, counter-clockwise; default 90 (+y, the
	 * direction of travel). The body's angle in the state is this in rad. */
	double heading_deg;
	double angular_velocity; /* rad/s, counter-clockwise; default 0 */
	double inertia;          /* kg m^2 about the centre; 0: from shape and mass
	                          * (bsim_body_inertia) */
	/* 1: the body turns under torque; 0: its heading is fixed (the essay's
	 * disk). A scene file's default is 0 for a disk, 1 otherwise. */
	int rotates;
} bsim_body_def;

typedef struct bsim_contact_def {
	double restitution;     /* tangent impacts, in [0, 1]; default 0.8 */
	double tip_restitution; /* tip (point) impacts, in [0, 1]; default 1 */
	double rest_threshold;  /* m/s: slower approaches become persistent; default 0.05 */
	double friction;        /* body-beam Coulomb coefficient, >= 0; default 0 (the essay's
	                         * frictionless contact) */
} bsim_contact_def;

/* What the propulsive force follows: +y (the essay's) or the heading. */
typedef enum bsim_propulsion_along {
	BSIM_ALONG_Y = 0,
	BSIM_ALONG_HEADING = 1,
} bsim_propulsion_along;

/* How the random force's values follow each other (docs/files.md "Forcing
 * spectra" gives each one's power spectral density). */
typedef enum bsim_random_model {
	BSIM_RANDOM_HELD = 0,  /* the essay's: Rm z_j held for 1/frequency s */
	BSIM_RANDOM_OU = 1,    /* Ornstein-Uhlenbeck: stationary std Rm, correlation time tau */
	BSIM_RANDOM_WHITE = 2, /* a new value each step, std Rm / sqrt(frequency dt) */
} bsim_random_model;

/* How ground friction acts on a body that turns (docs/files.md "A body
 * that turns"); a body that does not turn only slides, where both agree. */
typedef enum bsim_friction_model {
	BSIM_FRICTION_COUPLED = 0,   /* Coulomb over the footprint: each patch against its own
	                              * velocity v + omega x r */
	BSIM_FRICTION_DECOUPLED = 1, /* the sliding and the spinning each within its own limit
	                              * (the earlier model; Box2D's friction joint's) */
} bsim_friction_model;

/* Effects: only those present are simulated (has_* = 1). */
typedef struct bsim_effects_def {
	int has_propulsion;
	double propulsion_force;                /* N, along +y or the heading */
	bsim_propulsion_along propulsion_along; /* default BSIM_ALONG_Y */
	int has_random_force;
	double random_magnitude;        /* N, Rm: F_rand = Rm * N(0,1), >= 0 */
	double random_frequency;        /* Hz, refresh rate of the draw, > 0; default 50 */
	bsim_random_model random_model; /* default BSIM_RANDOM_HELD */
	double random_correlation_time; /* s, tau of the OU model, > 0; default 0.01 */
	int has_drag;
	double drag_linear;  /* N s/m, c: F = -c v, >= 0 */
	double drag_angular; /* N m s/rad, torque -c_w w on a body that rotates */
	int has_oscillation;
	double osc_amplitude; /* N, A: F_x = A sin(2 pi f t + phase) */
	double osc_frequency; /* Hz, f, > 0 */
	double osc_phase;     /* rad; default 0 */
	int has_ground_friction;
	double ground_mu;                 /* Coulomb friction coefficient with the plane, >= 0 */
	double ground_g;                  /* m/s^2, > 0; default 9.81 */
	bsim_friction_model ground_model; /* default BSIM_FRICTION_COUPLED */
} bsim_effects_def;

/* A gate lattice (docs/model.md section 8, docs/lattice.md "Scenes"): gates
 * (ix, iy), ix_min <= ix <= ix_max, 0 <= iy < rows. Gate (ix, iy) spans
 * X in [width ix - width/2, width ix + width/2), Y in [depth iy, depth (iy + 1))
 * (essay Eq. 2.17); its left beam hangs at (width ix - width/2, depth iy +
 * pivot_y) pointing +x, its right beam at (width ix + width/2, ...) pointing
 * -x, so neighbouring gates share pivot points. The scene's beams are the
 * lattice's, gate by gate: beam 2 ((iy) columns + ix - ix_min) + side, side 0
 * the left beam and 1 the right (bsim_lattice_beam). */
typedef enum bsim_protocol {
	BSIM_PROTOCOL_WORLD = 0, /* one world: every beam keeps its state */
	BSIM_PROTOCOL_ESSAY = 1, /* the essay's: only the active gate, reset on entry */
} bsim_protocol;

typedef struct bsim_lattice_def {
	int columns, rows;        /* gates across (ix) and along (iy), >= 1 */
	int ix_min, ix_max;       /* ix_max - ix_min + 1 = columns */
	double width;             /* m, gate width along x; default 50 */
	double depth;             /* m, gate depth along y; default 60 */
	double pivot_y;           /* m, pivot row above the gate's bottom edge; default 30 */
	bsim_beam_def beam;       /* every beam's length, mass, inertia, stiffness, damping */
	bsim_protocol protocol;   /* default BSIM_PROTOCOL_WORLD */
	char stiffness_file[256]; /* the map's CSV as the scene names it, "" if none */
} bsim_lattice_def;

typedef struct bsim_scene {
	char name[128];
	char path[1024]; /* the file it came from, "" if built in code */
	bsim_body_def body;
	int n_beams;
	bsim_beam_def *beams; /* n_beams entries, owned by the scene */
	bsim_contact_def contact;
	bsim_effects_def effects;
	double dt;                /* s, > 0; default 0.004 */
	int max_steps;            /* > 0; default 3000; a file may give integration.duration
	                           * (s) instead, which the loader makes steps of dt */
	double success_y;         /* m; default 65 */
	double side_x;            /* m, > 0; default 25 */
	double classify_y;        /* m, >= success_y; default 80 */
	double classify_deadband; /* m/s: |v_x| at classify_y below it is type none;
	                           * default 0.01 */
	double landscape_y0;      /* m, zero of the propulsive potential; default 60 */
	/* Stuck: the body stayed gate_steps steps in one gate (a lattice;
	 * default 3000, the essay's single-gate limit), or max_steps in all.
	 * 0: the same as max_steps. A file may give termination.gate_time (s)
	 * instead. */
	int gate_steps;
	int has_lattice; /* 1: beams were built from lattice */
	bsim_lattice_def lattice;
} bsim_scene;

/* Loads and validates a scene file, applying the overrides in order (later
 * ones win). On failure returns BSIM_EINPUT with one message naming the file
 * (or the override's origin), line, field and what was expected. */
BSIM_API int bsim_scene_load(const char *path, const bsim_override *overrides, int n_overrides,
                             bsim_scene *out, bsim_error *err);

/* A scene with no body and no beams, every other field at the default a
 * scene file gets where it leaves the key out (docs/files.md): contact
 * 0.8 / 1 / 0.05 m/s, random force at 50 Hz when present, dt 0.004 s, 3000
 * steps, success_y 65 m, side_x 25 m, classify_y 80 m, classify_deadband
 * 0.01 m/s, landscape_y0 60 m, no effects. Set body and beams (and effects)
 * before bsim_scene_validate; free with bsim_scene_free. */
BSIM_API bsim_scene bsim_scene_default(void);

/* The parts of a scene at their defaults. Where a scene file may leave a
 * key out, the default is what it gets (bsim_scene_default uses these);
 * where a file must give a key (a beam's and the body's sizes, a lattice's
 * columns and rows), the default is the essay's value (Table 2.1, Sec.
 * 2.6), for a scene built in code:
 *   beam: pivot (0, 0), rest 0 deg, 25 m, 0.1 kg, inertia m L^2 / 3,
 *         400 N m/rad, 50 N m s/rad, at rest;
 *   body: a 1 kg disk of radius 10 m at (0, 0), at rest, heading 90 deg,
 *         not rotating (length, semi_axes, inertia 0);
 *   contact: restitution 0.8, tip restitution 1, rest threshold 0.05 m/s,
 *            no friction;
 *   effects: none (the random force at 50 Hz once it is switched on);
 *   lattice: 9 x 9 gates (ix -4..4) of 50 m x 60 m, pivots 30 m up, the
 *            beam above, the whole-world protocol, no stiffness map. */
BSIM_API bsim_beam_def bsim_beam_def_default(void);
BSIM_API bsim_body_def bsim_body_def_default(void);
BSIM_API bsim_contact_def bsim_contact_def_default(void);
BSIM_API bsim_effects_def bsim_effects_def_default(void);
BSIM_API bsim_lattice_def bsim_lattice_def_default(void);

/* The body's moment of inertia about its centre, kg m^2: body->inertia if
 * it is given (> 0), else the uniform body's of its shape and mass: disk
 * M R^2 / 2; ellipse M (a^2 + b^2) / 4; capsule the rectangle's
 * M_r (L^2 + 4 R^2) / 12 plus the two half-disks' M_d (R^2 / 2 + L^2 / 4 +
 * 4 R L / (3 pi)), M_r and M_d the mass shared by area. */
BSIM_API double bsim_body_inertia(const bsim_body_def *body);

/* The body's heading at the start, rad (body.heading_deg converted). */
BSIM_API double bsim_body_heading(const bsim_body_def *body);

/* The body's area, m^2: pi R^2, 2 R L + pi R^2, pi a b. */
BSIM_API double bsim_body_area(const bsim_body_def *body);

/* Fills the essay's single-gate scene (docs/model.md section 1, Table 2.1)
 * with the given propulsion and random force magnitude (0 = effect
 * absent). */
BSIM_API void bsim_scene_init_gate(bsim_scene *s, double f_prop, double rm);

/* Range and geometry checks (positive masses, no initial overlap, ...) on a
 * scene built in code; bsim_scene_load runs the same checks. */
BSIM_API int bsim_scene_validate(const bsim_scene *s, bsim_error *err);

BSIM_API int bsim_scene_copy(bsim_scene *dst, const bsim_scene *src);
BSIM_API void bsim_scene_free(bsim_scene *s);

/* Sets the number of beams, (re)allocating the array; new beams are zeroed. */
BSIM_API int bsim_scene_set_beams(bsim_scene *s, int n_beams);

/* The unit direction u0 of beam b at rest (rest_angle_deg, 0 = +x), exact
 * at multiples of 90 degrees, so that the beams of a mirrored gate (0 and
 * 180 degrees) are mirrored bit for bit. */
BSIM_API void bsim_scene_beam_rest_direction(const bsim_beam_def *b, double u0[2]);

/* +1 if a forward swing (theta > 0, the tip toward +y) turns beam b
 * counter-clockwise (a beam pointing right at rest), -1 otherwise. */
BSIM_API double bsim_scene_beam_forward_sign(const bsim_beam_def *b);

#ifdef __cplusplus
}
#endif
#endif
