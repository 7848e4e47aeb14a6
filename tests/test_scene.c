/* Scene and experiment loading through the public API: the essay's files
 * load to the essay's numbers, overrides land where their dotted path says,
 * defaults fill what a file leaves out, and grids expand in the documented
 * order. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/experiment.h"
#include "beamsim/scene.h"
#include "support.h"

/* cmocka 1.1.5 has no assert_double_equal. */
#define assert_near(a, b, tol) assert_true(fabs((a) - (b)) <= (tol))

/* A gate with nothing optional: every default applies. */
static const char minimal_scene[] =
        "body: { mass: 2, radius: 5 }\n"
        "beams:\n"
        "  - { pivot: [-20, 40], length: 10, mass: 0.3, stiffness: 100 }\n";

static const char *write_minimal(const char *dir_name)
{
	const char *dir = bsim_test_dir(dir_name);
	return bsim_test_write(dir, "minimal.yaml", minimal_scene);
}

static void load_ok(const char *path, const bsim_override *ov, int n, bsim_scene *s)
{
	bsim_error err = {0};
	int rc = bsim_scene_load(path, ov, n, s, &err);
	if (rc != BSIM_OK)
		fail_msg("%s: %s", path, err.msg);
}

static void assert_beam_equal(const bsim_beam_def *a, const bsim_beam_def *b)
{
	assert_true(a->pivot[0] == b->pivot[0] && a->pivot[1] == b->pivot[1]);
	assert_true(a->rest_angle_deg == b->rest_angle_deg);
	assert_true(a->length == b->length);
	assert_true(a->mass == b->mass);
	assert_near(a->inertia, b->inertia, 1e-12);
	assert_true(a->stiffness == b->stiffness);
	assert_true(a->damping == b->damping);
	assert_true(a->initial_theta == b->initial_theta);
	assert_true(a->initial_omega == b->initial_omega);
}

static void assert_scene_equal(const bsim_scene *a, const bsim_scene *b)
{
	assert_string_equal(a->name, b->name);
	assert_memory_equal(&a->body, &b->body, sizeof a->body);
	assert_int_equal(a->n_beams, b->n_beams);
	for (int i = 0; i < a->n_beams; i++)
		assert_beam_equal(&a->beams[i], &b->beams[i]);
	assert_memory_equal(&a->contact, &b->contact, sizeof a->contact);
	assert_int_equal(a->effects.has_propulsion, b->effects.has_propulsion);
	assert_true(a->effects.propulsion_force == b->effects.propulsion_force);
	assert_int_equal(a->effects.has_random_force, b->effects.has_random_force);
	assert_true(a->effects.random_magnitude == b->effects.random_magnitude);
	assert_true(a->effects.random_frequency == b->effects.random_frequency);
	assert_true(a->dt == b->dt);
	assert_int_equal(a->max_steps, b->max_steps);
	assert_true(a->success_y == b->success_y);
	assert_true(a->side_x == b->side_x);
	assert_true(a->classify_y == b->classify_y);
	assert_true(a->landscape_y0 == b->landscape_y0);
}

static void gate_file_is_table_2_1(void **state)
{
	(void)state;
	bsim_scene s;
	load_ok(bsim_test_src("configs/thesis/gate.yaml"), NULL, 0, &s);
	assert_string_equal(s.name, "thesis-gate");
	assert_non_null(strstr(s.path, "configs/thesis/gate.yaml"));
	assert_true(s.body.mass == 1.0 && s.body.radius == 10.0);
	assert_true(s.body.start[0] == 0 && s.body.start[1] == 0);
	assert_int_equal(s.n_beams, 2);
	assert_true(s.beams[0].pivot[0] == -25 && s.beams[0].pivot[1] == 30);
	assert_true(s.beams[1].pivot[0] == 25 && s.beams[1].rest_angle_deg == 180);
	for (int i = 0; i < 2; i++) {
		assert_true(s.beams[i].length == 25 && s.beams[i].mass == 0.1);
		assert_near(s.beams[i].inertia, 20.833333333333, 1e-9); /* m L^2 / 3 */
		assert_true(s.beams[i].stiffness == 400 && s.beams[i].damping == 50);
	}
	assert_true(s.contact.restitution == 0.8 && s.contact.tip_restitution == 1.0);
	assert_true(s.contact.rest_threshold == 0.05);
	assert_true(s.effects.has_propulsion && s.effects.propulsion_force == 7.0);
	assert_true(s.effects.has_random_force && s.effects.random_magnitude == 20.0);
	assert_true(s.effects.random_frequency == 50.0);
	assert_true(s.dt == 0.004 && s.max_steps == 3000);
	assert_true(s.success_y == 65 && s.side_x == 25 && s.classify_y == 80);
	assert_true(s.landscape_y0 == 60);

	bsim_scene g;
	bsim_scene_init_gate(&g, 7, 20);
	assert_string_equal(g.path, "");
	assert_scene_equal(&s, &g);
	bsim_scene_free(&g);
	bsim_scene_free(&s);
}

static void init_gate_is_valid_and_rm_zero_has_no_random_force(void **state)
{
	(void)state;
	bsim_scene g;
	bsim_error err = {0};
	bsim_scene_init_gate(&g, 4, 0);
	assert_int_equal(bsim_scene_validate(&g, &err), BSIM_OK);
	assert_int_equal(g.effects.has_random_force, 0);
	assert_int_equal(g.effects.has_propulsion, 1);
	assert_true(g.effects.propulsion_force == 4);
	bsim_scene_free(&g);
}

static void override_sets_beam_stiffness(void **state)
{
	(void)state;
	bsim_override ov[] = {{"beams.0.stiffness", "250", "--set beams.0.stiffness=250"}};
	bsim_scene s;
	load_ok(bsim_test_src("configs/thesis/gate.yaml"), ov, 1, &s);
	assert_true(s.beams[0].stiffness == 250);
	assert_true(s.beams[1].stiffness == 400);
	bsim_scene_free(&s);
}

static void override_sets_body_start_list(void **state)
{
	(void)state;
	bsim_override ov[] = {{"body.start", "[1, 2]", NULL}};
	bsim_scene s;
	load_ok(bsim_test_src("configs/thesis/gate.yaml"), ov, 1, &s);
	assert_true(s.body.start[0] == 1 && s.body.start[1] == 2);
	bsim_scene_free(&s);
}

static void later_override_wins(void **state)
{
	(void)state;
	bsim_override ov[] = {{"effects.propulsion", "{force: 3}", "a"},
	                      {"effects.propulsion.force", "5", "b"}};
	bsim_scene s;
	load_ok(bsim_test_src("configs/thesis/gate.yaml"), ov, 2, &s);
	assert_true(s.effects.propulsion_force == 5);
	bsim_scene_free(&s);
}

static void override_inserts_missing_block(void **state)
{
	(void)state;
	const char *path = write_minimal("insert_block");
	bsim_scene s;
	load_ok(path, NULL, 0, &s);
	assert_int_equal(s.effects.has_random_force, 0);
	assert_int_equal(s.effects.has_propulsion, 0);
	bsim_scene_free(&s);

	bsim_override ov[] = {{"effects.random_force.magnitude", "30", "--set x"}};
	load_ok(path, ov, 1, &s);
	assert_int_equal(s.effects.has_random_force, 1);
	assert_true(s.effects.random_magnitude == 30);
	assert_true(s.effects.random_frequency == 50); /* the block's default */
	assert_int_equal(s.effects.has_propulsion, 0);
	bsim_scene_free(&s);
}

static void defaults_fill_what_a_file_leaves_out(void **state)
{
	(void)state;
	bsim_scene s;
	load_ok(write_minimal("defaults"), NULL, 0, &s);
	assert_string_equal(s.name, "minimal"); /* base name without extension */
	assert_true(s.body.mass == 2 && s.body.radius == 5);
	assert_true(s.body.start[0] == 0 && s.body.velocity[1] == 0);
	assert_int_equal(s.n_beams, 1);
	const bsim_beam_def *b = &s.beams[0];
	assert_true(b->rest_angle_deg == 0 && b->damping == 0);
	assert_true(b->initial_theta == 0 && b->initial_omega == 0);
	assert_near(b->inertia, 0.3 * 10 * 10 / 3.0, 1e-12);
	assert_true(s.contact.restitution == 0.8 && s.contact.tip_restitution == 1.0);
	assert_true(s.contact.rest_threshold == 0.05);
	assert_true(s.effects.random_frequency == 50);
	assert_true(s.dt == 0.004 && s.max_steps == 3000);
	assert_true(s.success_y == 65 && s.side_x == 25 && s.classify_y == 80);
	assert_true(s.landscape_y0 == 60);
	/* bsim_scene_default is the same defaults, for scenes built in code:
	 * every field the file left out equal to the file's. */
	bsim_scene d = bsim_scene_default();
	assert_true(d.n_beams == 0 && d.beams == NULL && !d.effects.has_propulsion);
	assert_memory_equal(&d.contact, &s.contact, sizeof d.contact);
	assert_memory_equal(&d.effects, &s.effects, sizeof d.effects);
	assert_true(d.dt == s.dt && d.max_steps == s.max_steps && d.success_y == s.success_y);
	assert_true(d.side_x == s.side_x && d.classify_y == s.classify_y);
	assert_true(d.classify_deadband == s.classify_deadband && d.landscape_y0 == s.landscape_y0);
	assert_true(d.gate_steps == s.gate_steps && d.has_lattice == s.has_lattice);
	bsim_scene_free(&s);
}

/* The parts' default functions against the essay's gate and lattice as the
 * shipped files give them (Table 2.1, Sec. 2.6), and against what a file
 * that leaves the keys out gets. */
static void part_defaults_are_the_essays(void **state)
{
	(void)state;
	bsim_scene g, l, m;
	load_ok(bsim_test_src("configs/thesis/gate.yaml"), NULL, 0, &g);
	load_ok(bsim_test_src("configs/lattice/uniform_9x9.yaml"), NULL, 0, &l);
	load_ok(write_minimal("part_defaults"), NULL, 0, &m);
	bsim_beam_def b = bsim_beam_def_default(), want = g.beams[0];
	want.pivot[0] = want.pivot[1] = 0;
	want.rest_angle_deg = 0;
	assert_memory_equal(&b, &want, sizeof b);
	bsim_body_def body = bsim_body_def_default();
	assert_memory_equal(&body, &g.body, sizeof body);
	bsim_contact_def c = bsim_contact_def_default();
	assert_memory_equal(&c, &g.contact, sizeof c);
	assert_memory_equal(&c, &m.contact, sizeof c);
	bsim_effects_def e = bsim_effects_def_default();
	assert_false(e.has_propulsion || e.has_random_force);
	assert_memory_equal(&e, &m.effects, sizeof e);
	bsim_lattice_def ld = bsim_lattice_def_default();
	assert_true(ld.columns == l.lattice.columns && ld.rows == l.lattice.rows);
	assert_true(ld.ix_min == l.lattice.ix_min && ld.ix_max == l.lattice.ix_max);
	assert_true(ld.width == l.lattice.width && ld.depth == l.lattice.depth);
	assert_true(ld.pivot_y == l.lattice.pivot_y && ld.protocol == l.lattice.protocol);
	assert_memory_equal(&ld.beam, &l.lattice.beam, sizeof ld.beam);
	bsim_scene_free(&g);
	bsim_scene_free(&l);
	bsim_scene_free(&m);
}

static void zero_magnitude_means_no_random_force(void **state)
{
	(void)state;
	bsim_override ov[] = {{"effects.random_force.magnitude", "0", NULL}};
	bsim_scene s;
	load_ok(bsim_test_src("configs/thesis/gate.yaml"), ov, 1, &s);
	assert_int_equal(s.effects.has_random_force, 0);
	assert_int_equal(s.effects.has_propulsion, 1);
	bsim_scene_free(&s);
}

/* The message names where, which field, what was expected, what was there. */
static void expect_error(const char *path, const bsim_override *ov, int n, const char *msg)
{
	bsim_scene s;
	bsim_error err = {0};
	assert_int_equal(bsim_scene_load(path, ov, n, &s, &err), BSIM_EINPUT);
	assert_int_equal(err.code, BSIM_EINPUT);
	if (!strstr(err.msg, msg))
		fail_msg("got \"%s\", wanted \"%s\"", err.msg, msg);
	assert_null(s.beams);
}

static void errors_name_file_line_field(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("errors");
	const char *p = bsim_test_write(dir, "bad.yaml",
	                                "body: { mass: 1, radius: 10 }\n"
	                                "beams:\n"
	                                "  - pivot: [-25, 30]\n"
	                                "    length: 25\n"
	                                "    mass: 0.1\n"
	                                "    stifness: 400\n");
	expect_error(p, NULL, 0,
	             "bad.yaml:6:5: beams.0.stifness: unknown key (expected one of pivot, "
	             "rest_angle_deg, length, mass, inertia, stiffness, damping, initial_theta, "
	             "initial_omega)");
	p = bsim_test_write(dir, "missing.yaml",
	                    "body: { mass: 1, radius: 10 }\n"
	                    "beams:\n"
	                    "  - { pivot: [-25, 30], length: 25, mass: 0.1, stiffness: 1 }\n"
	                    "  - { pivot: [25, 30], mass: 0.1, stiffness: 1 }\n");
	expect_error(p, NULL, 0,
	             "missing.yaml:4:7: beams.1.length: missing (expected a positive number)");
	p = bsim_test_write(dir, "mass.yaml", "body: { mass: -1, radius: 10 }\n");
	expect_error(p, NULL, 0, "mass.yaml:1:15: body.mass: expected a positive number, got -1");
}

/* The second moment and the area of a uniform body, by counting the
 * centres of an n x n grid of cells over its bounding box that lie inside
 * it: an independent truth of bsim_body_inertia's and bsim_body_area's
 * closed forms (the grid's error is O(1/n) of the boundary). */
static void grid_moments(const bsim_body_def *b, int n, double *area, double *second)
{
	double hx, hy;
	if (b->shape == BSIM_SHAPE_ELLIPSE) {
		hx = b->semi_axes[0];
		hy = b->semi_axes[1];
	} else {
		hx = b->length / 2 + b->radius;
		hy = b->radius;
	}
	double dx = 2 * hx / n, dy = 2 * hy / n, a = 0, j = 0;
	for (int i = 0; i < n; i++)
		for (int k = 0; k < n; k++) {
			double x = -hx + (i + 0.5) * dx, y = -hy + (k + 0.5) * dy, inside;
			if (b->shape == BSIM_SHAPE_ELLIPSE) {
				double u = x / hx, v = y / hy;
				inside = u * u + v * v <= 1;
			} else {
				double ax = fmin(fmax(x, -b->length / 2), b->length / 2);
				inside = hypot(x - ax, y) <= b->radius;
			}
			if (inside) {
				a += dx * dy;
				j += dx * dy * (x * x + y * y);
			}
		}
	*area = a;
	*second = j;
}

static void body_shapes_load_and_have_their_inertia(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("shapes");
	const char *beams =
	        "beams:\n  - { pivot: [-25, 30], length: 25, mass: 0.1, stiffness: 1 }\n";
	char text[512];
	snprintf(text, sizeof text,
	         "body: { mass: 2, radius: 4, shape: capsule, length: 12, heading_deg: 30 }\n%s",
	         beams);
	bsim_scene s;
	load_ok(bsim_test_write(dir, "capsule.yaml", text), NULL, 0, &s);
	assert_int_equal(s.body.shape, BSIM_SHAPE_CAPSULE);
	assert_int_equal(s.body.rotates, 1); /* the default for a shape that is not a disk */
	assert_near(bsim_body_heading(&s.body), 3.14159265358979323846 / 6, 1e-15);
	double area, second;
	grid_moments(&s.body, 2000, &area, &second);
	assert_near(bsim_body_area(&s.body), area, 2e-3 * area);
	assert_near(bsim_body_inertia(&s.body), 2 * second / area, 2e-3 * 2 * second / area);
	bsim_scene_free(&s);

	snprintf(text, sizeof text,
	         "body: { mass: 3, shape: ellipse, semi_axes: [9, 4], rotates: false }\n%s", beams);
	load_ok(bsim_test_write(dir, "ellipse.yaml", text), NULL, 0, &s);
	assert_int_equal(s.body.shape, BSIM_SHAPE_ELLIPSE);
	assert_int_equal(s.body.rotates, 0);
	assert_near(bsim_body_heading(&s.body), 3.14159265358979323846 / 2, 1e-15);
	grid_moments(&s.body, 2000, &area, &second);
	assert_near(bsim_body_area(&s.body), area, 2e-3 * area);
	assert_near(bsim_body_inertia(&s.body), 3 * second / area, 2e-3 * 3 * second / area);
	bsim_scene_free(&s);

	/* The essay's disk: M R^2 / 2, not turning; a given inertia wins. */
	snprintf(text, sizeof text,
	         "body: { mass: 2, radius: 5, inertia: 7 }\ncontact: { friction: 0.3 }\n"
	         "effects: { propulsion: { force: 4, along: heading } }\n%s",
	         beams);
	load_ok(bsim_test_write(dir, "disk.yaml", text), NULL, 0, &s);
	assert_int_equal(s.body.rotates, 0);
	assert_near(bsim_body_inertia(&s.body), 7, 0);
	s.body.inertia = 0;
	assert_near(bsim_body_inertia(&s.body), 2 * 25 / 2.0, 1e-12);
	assert_near(s.contact.friction, 0.3, 0);
	assert_int_equal(s.effects.propulsion_along, BSIM_ALONG_HEADING);
	bsim_scene_free(&s);

	struct {
		const char *body, *msg;
	} bad[] = {
	        {"{ mass: 1, shape: ellipse }", "b0.yaml:1:9: body.semi_axes: missing"},
	        {"{ mass: 1, shape: capsule, radius: 3 }", "b1.yaml:1:9: body.length: missing"},
	        {"{ mass: 1, shape: square, radius: 3 }",
	         "b2.yaml:1:25: body.shape: expected disk, capsule"},
	        {"{ mass: 1, radius: 3, rotates: maybe }",
	         "b3.yaml:1:38: body.rotates: expected true or false, got maybe"},
	        {"{ mass: 1, radius: 3, length: 4 }",
	         "b4.yaml:1:37: body.length: expected none for a disk"},
	        {"{ mass: 1, shape: ellipse, semi_axes: [3, 2], radius: 3 }",
	         "b5.yaml:1:61: body.radius: expected none for an ellipse"},
	        {"{ mass: 1, radius: 3, angular_velocity: 2 }",
	         "body.angular_velocity: expected 0 for a body that does not turn"},
	        {"{ mass: 1 }", "b7.yaml:1:9: body.radius: missing (expected a positive number"},
	};
	for (int i = 0; i < (int)(sizeof bad / sizeof bad[0]); i++) {
		char name[16];
		snprintf(name, sizeof name, "b%d.yaml", i);
		snprintf(text, sizeof text, "body: %s\n%s", bad[i].body, beams);
		expect_error(bsim_test_write(dir, name, text), NULL, 0, bad[i].msg);
	}
}

static void override_errors_name_the_override(void **state)
{
	(void)state;
	const char *gate = bsim_test_src("configs/thesis/gate.yaml");
	bsim_override mass[] = {{"body.mass", "-1", "--set body.mass=-1"}};
	expect_error(gate, mass, 1,
	             "--set body.mass=-1: body.mass: expected a positive number, got -1");
	bsim_override idx[] = {{"beams.2.stiffness", "1", "h2.yaml:7"}};
	expect_error(gate, idx, 1, "h2.yaml:7: beams.2: expected an index from 0 to 1, got 2");
	bsim_override through[] = {{"body.mass.x", "1", "o"}};
	expect_error(gate, through, 1, "o: body.mass.x: expected a mapping or list at body.mass");
	bsim_override start[] = {{"body.start", "[0, 25]", "s"}};
	expect_error(gate, start, 1,
	             "s: body.start: the body (radius 10) overlaps beam 1 (beams.0) at the start "
	             "(distance 5 m)");
	/* An unknown key inside an override's own mapping still names it. */
	bsim_override inner[] = {{"effects.propulsion", "{forc: 3}", "p"}};
	expect_error(gate, inner, 1,
	             "p: effects.propulsion.forc: unknown key (expected one of force, along)");
}

/* A trial's length in seconds (docs/files.md "A trial's length"). The
 * independent truth of the derived count: the steps cover the duration
 * (n dt >= duration, to the 1e-9 relative the rule forgives) and one step
 * fewer would not ((n - 1) dt < duration). */
static void assert_covers(int n, double dt, double duration)
{
	if (!(n * dt >= duration * (1 - 1e-9) && (n - 1) * dt < duration))
		fail_msg("%d steps of %g s for %g s", n, dt, duration);
}

static const char *write_length(const char *dir_name, const char *name, const char *tail)
{
	char text[1024];
	snprintf(text, sizeof text, "%s%s", minimal_scene, tail);
	return bsim_test_write(bsim_test_dir(dir_name), name, text);
}

static void duration_gives_the_steps(void **state)
{
	(void)state;
	static const struct {
		const char *dt, *duration;
		int steps;
	} cases[] = {
	        {"0.004", "12", 3000},
	        {"0.004", "16.1", 4025}, /* 16.1 / 0.004 = 4025.0000000000005 in doubles */
	        {"0.004", "0.8", 200},
	        {"0.004", "216", 54000},
	        {"0.1", "0.3", 3},   /* 0.3 / 0.1 = 2.9999999999999996 */
	        {"0.003", "1", 334}, /* not a whole number of steps: rounded up */
	        {"0.004", "1e-6", 1},
	};
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		char tail[128];
		snprintf(tail, sizeof tail, "integration: { dt: %s, duration: %s }\n", cases[i].dt,
		         cases[i].duration);
		bsim_scene s;
		load_ok(write_length("duration", "d.yaml", tail), NULL, 0, &s);
		assert_covers(s.max_steps, s.dt, atof(cases[i].duration));
		assert_int_equal(s.max_steps, cases[i].steps);
		bsim_scene_free(&s);
	}
	/* The shipped gate says 12 s: the essay's 3000 steps of 0.004 s. */
	bsim_scene g;
	load_ok(bsim_test_src("configs/thesis/gate.yaml"), NULL, 0, &g);
	assert_true(g.dt == 0.004 && g.max_steps == 3000);
	bsim_scene_free(&g);
}

/* Changing dt keeps the duration: 12 s at 0.001 s is 12,000 steps, also
 * when the file gives both keys (they agree at the file's own dt). A scene
 * that gives steps keeps its steps. */
static void dt_override_keeps_the_duration(void **state)
{
	(void)state;
	bsim_override dt[] = {{"integration.dt", "0.001", "--set integration.dt=0.001"}};
	bsim_scene s;
	load_ok(bsim_test_src("configs/thesis/gate.yaml"), dt, 1, &s);
	assert_true(s.dt == 0.001);
	assert_int_equal(s.max_steps, 12000);
	assert_covers(s.max_steps, s.dt, 12);
	bsim_scene_free(&s);
	const char *both =
	        write_length("dt_keeps", "both.yaml",
	                     "integration: { dt: 0.004, max_steps: 3000, duration: 12 }\n");
	load_ok(both, NULL, 0, &s);
	assert_int_equal(s.max_steps, 3000);
	bsim_scene_free(&s);
	load_ok(both, dt, 1, &s);
	assert_int_equal(s.max_steps, 12000);
	bsim_scene_free(&s);
	const char *steps = write_length("dt_keeps", "steps.yaml",
	                                 "integration: { dt: 0.004, max_steps: 3000 }\n");
	load_ok(steps, dt, 1, &s);
	assert_int_equal(s.max_steps, 3000);
	bsim_scene_free(&s);
}

/* An override of either key replaces the trial's length the file gives;
 * of two overrides, the later counts. */
static void override_of_steps_or_duration_replaces_the_length(void **state)
{
	(void)state;
	const char *gate = bsim_test_src("configs/thesis/gate.yaml");
	bsim_override steps[] = {{"integration.max_steps", "500", "a"}};
	bsim_scene s;
	load_ok(gate, steps, 1, &s);
	assert_int_equal(s.max_steps, 500);
	bsim_scene_free(&s);
	/* steps given stay steps when dt changes after them */
	bsim_override steps_dt[] = {{"integration.max_steps", "500", "a"},
	                            {"integration.dt", "0.001", "b"}};
	load_ok(gate, steps_dt, 2, &s);
	assert_int_equal(s.max_steps, 500);
	bsim_scene_free(&s);
	const char *file_steps = write_length("override_length", "steps.yaml",
	                                      "integration: { dt: 0.004, max_steps: 3000 }\n");
	bsim_override time[] = {{"integration.duration", "4", "a"}};
	load_ok(file_steps, time, 1, &s);
	assert_int_equal(s.max_steps, 1000);
	bsim_scene_free(&s);
	bsim_override both[] = {{"integration.duration", "4", "a"},
	                        {"integration.max_steps", "700", "b"}};
	load_ok(file_steps, both, 2, &s);
	assert_int_equal(s.max_steps, 700);
	bsim_scene_free(&s);
	bsim_override both_rev[] = {{"integration.max_steps", "700", "a"},
	                            {"integration.duration", "4", "b"}};
	load_ok(file_steps, both_rev, 2, &s);
	assert_int_equal(s.max_steps, 1000);
	bsim_scene_free(&s);
}

/* Both keys of a pair given in one place must agree; the message names the
 * file, line, field and both values. */
static void inconsistent_steps_and_time_are_refused(void **state)
{
	(void)state;
	const char *p = write_length("inconsistent", "bad.yaml",
	                             "integration: { dt: 0.004, max_steps: 2500, duration: 12 }\n");
	expect_error(p, NULL, 0,
	             "bad.yaml:4:38: integration.max_steps: expected 3000 (integration.duration "
	             "12 s at integration.dt 0.004 s; give one of the two), got 2500");
	/* One override's mapping is one place too. */
	const char *gate = bsim_test_src("configs/thesis/gate.yaml");
	bsim_override block[] = {{"integration", "{max_steps: 10, duration: 1}", "o"}};
	expect_error(gate, block, 1,
	             "o: integration.max_steps: expected 250 (integration.duration 1 s at "
	             "integration.dt 0.004 s; give one of the two), got 10");
	p = write_length("inconsistent", "gate.yaml",
	                 "termination: { gate_steps: 400, gate_time: 2 }\n");
	expect_error(p, NULL, 0,
	             "gate.yaml:4:28: termination.gate_steps: expected 500 (termination.gate_time "
	             "2 s at integration.dt 0.004 s; give one of the two), got 400");
	p = write_length("inconsistent", "neg.yaml", "integration: { duration: -1 }\n");
	expect_error(p, NULL, 0,
	             "neg.yaml:4:26: integration.duration: expected a positive number (s), got -1");
	bsim_override huge[] = {{"integration.duration", "1e300", "h"}};
	expect_error(gate, huge, 1,
	             "h: integration.duration: expected at most 2147483647 steps of "
	             "integration.dt 0.004 s, got 1e300 s");
}

/* A lattice's per-gate limit in seconds: its steps at the scene's dt, and
 * the total default gate_steps (rows + columns) from them. */
static void lattice_gate_time_gives_gate_steps(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("gate_time");
	const char *p = bsim_test_write(dir, "lattice.yaml",
	                                "body: { mass: 1, radius: 10 }\n"
	                                "lattice:\n  columns: 3\n  rows: 2\n"
	                                "  beam: { length: 25, mass: 0.1, stiffness: 400 }\n"
	                                "termination: { gate_time: 2 }\n");
	bsim_scene s;
	load_ok(p, NULL, 0, &s);
	assert_int_equal(s.gate_steps, 500);
	assert_covers(s.gate_steps, s.dt, 2);
	assert_int_equal(s.max_steps, 500 * (2 + 3));
	bsim_scene_free(&s);
	bsim_override dt[] = {{"integration.dt", "0.002", "d"}};
	load_ok(p, dt, 1, &s);
	assert_int_equal(s.gate_steps, 1000);
	assert_int_equal(s.max_steps, 1000 * (2 + 3));
	bsim_scene_free(&s);
	/* The shipped lattices: 12 s a gate, 216 s in all, at 0.004 s. */
	const char *files[] = {"configs/lattice/c_track.yaml", "configs/lattice/uniform_9x9.yaml",
	                       "configs/lattice/mixed_9x9.yaml"};
	for (int i = 0; i < 3; i++) {
		load_ok(bsim_test_src(files[i]), NULL, 0, &s);
		assert_int_equal(s.gate_steps, 3000);
		assert_int_equal(s.max_steps, 54000);
		bsim_scene_free(&s);
		load_ok(bsim_test_src(files[i]), dt, 1, &s);
		assert_int_equal(s.gate_steps, 6000);
		assert_int_equal(s.max_steps, 108000);
		bsim_scene_free(&s);
	}
}

static void validate_checks_code_built_scenes(void **state)
{
	(void)state;
	bsim_scene g, c;
	bsim_error err = {0};
	bsim_scene_init_gate(&g, 7, 20);
	assert_int_equal(bsim_scene_copy(&c, &g), BSIM_OK);
	assert_ptr_not_equal(c.beams, g.beams);
	c.beams[1].length = 0;
	assert_int_equal(bsim_scene_validate(&c, &err), BSIM_EINPUT);
	assert_non_null(strstr(err.msg, "beams.1.length: expected a positive number, got 0"));
	assert_true(g.beams[1].length == 25); /* the copy is deep */
	c.beams[1].length = 25;
	c.body.start[1] = 25; /* 5 m below the left beam */
	assert_int_equal(bsim_scene_validate(&c, &err), BSIM_EINPUT);
	assert_non_null(strstr(err.msg, "overlaps beam 1 (beams.0)"));
	c.body.start[1] = 0;
	assert_int_equal(bsim_scene_set_beams(&c, 3), BSIM_OK);
	assert_true(c.beams[2].length == 0 && c.beams[1].length == 25);
	assert_int_equal(bsim_scene_validate(&c, &err), BSIM_EINPUT);
	assert_int_equal(bsim_scene_set_beams(&c, 2), BSIM_OK);
	assert_int_equal(bsim_scene_validate(&c, &err), BSIM_OK);
	bsim_scene_free(&c);
	bsim_scene_free(&g);
}

/* ---- the time step (docs/model.md "The time step") ---------------------- */

#define PI 3.14159265358979323846

/* The scene at path with overrides ov[0..n) and then integration.dt = dt:
 * its load's return code, err its message. */
static int load_at_dt(const char *path, const bsim_override *ov, int n, double dt, bsim_error *err)
{
	bsim_override all[8];
	char value[32];
	snprintf(value, sizeof value, "%.17g", dt);
	assert_true(n < 8);
	for (int i = 0; i < n; i++)
		all[i] = ov[i];
	all[n] = (bsim_override){"integration.dt", value, NULL};
	bsim_scene s;
	int rc = bsim_scene_load(path, all, n + 1, &s, err);
	bsim_scene_free(&s);
	return rc;
}

/* The bound (s) computed by the test from the scene's numbers: a step a
 * millionth longer is refused, the message naming integration.dt, what
 * (the bound's name and where it comes from) and a bound of its own within
 * 1e-3 below the test's; a step a millionth shorter loads. A bound that is
 * not strict also loads at the number the message states; a strict one
 * (the oscillation's Nyquist) is refused at the bound itself. */
static void expect_dt_bound(const char *path, const bsim_override *ov, int n, double bound,
                            int strict, const char *what)
{
	bsim_error err = {0};
	assert_int_equal(load_at_dt(path, ov, n, bound * (1 + 1e-6), &err), BSIM_EINPUT);
	const char *prefix = strict ? "integration.dt: expected less than "
	                            : "integration.dt: expected at most ";
	const char *at = strstr(err.msg, prefix);
	if (!at || !strstr(err.msg, what))
		fail_msg("\"%s\" lacks \"%s\" or \"%s\"", err.msg, prefix, what);
	double stated = strtod(at + strlen(prefix), NULL);
	if (!(stated <= bound && stated >= bound * (1 - 1e-3)))
		fail_msg("%s: states %.17g, the bound is %.17g", err.msg, stated, bound);
	assert_int_equal(load_at_dt(path, ov, n, bound * (1 - 1e-6), &err), BSIM_OK);
	if (strict)
		assert_int_equal(load_at_dt(path, ov, n, bound, &err), BSIM_EINPUT);
	else
		assert_int_equal(load_at_dt(path, ov, n, stated, &err), BSIM_OK);
}

/* Each bound on the essay's gate (configs/thesis/gate.yaml: a 1 kg disk of
 * radius 10 m at rest at the origin, F_prop 7 N, the random force 20 N at
 * 50 Hz, beams of 0.1 kg and 25 m, k 400 N m/rad, d 50 N m s/rad, pivots
 * (-/+25, 30)), made the tightest by the overrides, at the value the
 * model's formula gives. */
static void time_step_bounds_refuse_and_accept(void **state)
{
	(void)state;
	const char *gate = bsim_test_src("configs/thesis/gate.yaml");
	const double inertia = 0.1 * 25.0 * 25.0 / 3.0; /* m L^2 / 3 */
	/* the farthest point a beam reaches from the start: pivot + L */
	const double reach = hypot(25.0, 30.0) + 25.0;
	const double forces = sqrt(2.0 * 7.0 / 1.0 * reach); /* F_prop alone, from rest */
	/* held: a value must hold for a step */
	expect_dt_bound(gate, NULL, 0, 1.0 / 50.0, 0, "the random force's hold 1/f, f = 50 Hz");
	bsim_override ou[] = {{"effects.random_force.model", "ou", NULL},
	                      {"effects.random_force.correlation_time", "0.005", NULL}};
	expect_dt_bound(gate, ou, 2, 0.005, 0, "correlation time tau = 0.005 s");
	/* without the random force, each of the others in turn */
	bsim_override osc[] = {{"effects.random_force.magnitude", "0", NULL},
	                       {"effects.oscillation", "{amplitude: 1, frequency: 4}", NULL}};
	expect_dt_bound(gate, osc, 2, 1.0 / (2.0 * 4.0), 1, "half the oscillation's period");
	bsim_override spring[] = {{"effects.random_force.magnitude", "0", NULL},
	                          {"beams.0.stiffness", "1e5", NULL}};
	expect_dt_bound(gate, spring, 2, PI * sqrt(inertia / 1e5), 0,
	                "half the natural period pi sqrt(I/k) of beam 1 (beams.0)");
	bsim_override damper[] = {{"effects.random_force.magnitude", "0", NULL},
	                          {"beams.1.damping", "5000", NULL}};
	expect_dt_bound(gate, damper, 2, 2.0 * inertia / 5000.0, 0,
	                "twice the damping time 2 I/d of beam 2 (beams.1)");
	bsim_override calm[] = {{"effects.random_force.magnitude", "0", NULL}};
	expect_dt_bound(gate, calm, 1, 10.0 / forces, 0,
	                "the body's crossing: its half-width 10 m");
	/* a start speed adds to the speed scale */
	bsim_override fast[] = {{"effects.random_force.magnitude", "0", NULL},
	                        {"body.velocity", "[0, 50]", NULL}};
	expect_dt_bound(gate, fast, 2, 10.0 / (50.0 + forces), 0, "start 50 m/s");
	/* an ellipse: its smaller semi-axis */
	expect_dt_bound(bsim_test_src("configs/shape/gate_ellipse.yaml"), calm, 1, 7.071 / forces,
	                0, "its half-width 7.071 m");
	/* a capsule that spins: its half-width 6 m, its ends 6 + 16.755 / 2 m
	 * from its centre turning at 3 rad/s */
	const char *capsule = bsim_test_src("configs/shape/gate_capsule.yaml");
	bsim_override spin[] = {{"effects.random_force.magnitude", "0", NULL},
	                        {"body.angular_velocity", "3", NULL}};
	expect_dt_bound(capsule, spin, 2, 6.0 / (forces + 3.0 * (6.0 + 16.755 / 2.0)), 0,
	                "its half-width 6 m");
}

/* The same check on a scene built in code, as the bindings' programs may
 * build one: the gate at dt 0.5 s is refused, at 1/f = 0.02 s it is not. */
static void validate_checks_the_time_step(void **state)
{
	(void)state;
	bsim_scene g;
	bsim_error err = {0};
	bsim_scene_init_gate(&g, 7, 20);
	g.dt = 0.5;
	assert_int_equal(bsim_scene_validate(&g, &err), BSIM_EINPUT);
	assert_non_null(strstr(err.msg, "thesis-gate: integration.dt: expected at most 0.02 s "
	                                "(the random force's hold 1/f, f = 50 Hz), got 0.5"));
	g.dt = 1.0 / 50.0;
	assert_int_equal(bsim_scene_validate(&g, &err), BSIM_OK);
	bsim_scene_free(&g);
}

static void load_experiment(const char *rel, bsim_experiment *e)
{
	bsim_error err = {0};
	if (bsim_experiment_load(bsim_test_src(rel), NULL, 0, e, &err) != BSIM_OK)
		fail_msg("%s: %s", rel, err.msg);
}

static void group_scene(const bsim_experiment *e, int g, bsim_scene *s)
{
	bsim_error err = {0};
	if (bsim_experiment_group_scene(e, g, NULL, 0, s, &err) != BSIM_OK)
		fail_msg("group %d: %s", g, err.msg);
}

static void h1_has_30_groups_first_axis_slowest(void **state)
{
	(void)state;
	bsim_experiment e;
	load_experiment("configs/thesis/h1_symmetric.yaml", &e);
	assert_int_equal(e.n_groups, 30);
	assert_int_equal(e.trials, 100);
	assert_true(e.seed == 1);
	assert_int_equal(e.n_set, 0);
	assert_int_equal(e.n_axes, 2);
	assert_string_equal(e.axes[0].key, "effects.propulsion.force");
	assert_string_equal(e.axes[1].key, "effects.random_force.magnitude");
	assert_non_null(strstr(e.scene_path, "configs/thesis/gate.yaml"));
	char where[1400];
	bsim_experiment_value_origin(&e.axes[1], 2, where, sizeof where);
	assert_non_null(strstr(where, "h1_symmetric.yaml:7"));

	int idx[2];
	static const int want[][3] = {{0, 0, 0}, {1, 0, 1}, {5, 1, 0}, {29, 5, 4}};
	for (int i = 0; i < 4; i++) {
		bsim_experiment_group_index(&e, want[i][0], idx);
		assert_int_equal(idx[0], want[i][1]);
		assert_int_equal(idx[1], want[i][2]);
	}
	static const double f_rm[][3] = {{0, 4, 0}, {1, 4, 10}, {5, 5, 0}, {29, 9, 40}};
	for (int i = 0; i < 4; i++) {
		bsim_scene s;
		group_scene(&e, (int)f_rm[i][0], &s);
		assert_true(s.effects.propulsion_force == f_rm[i][1]);
		assert_true(s.effects.random_magnitude == f_rm[i][2]);
		assert_int_equal(s.effects.has_random_force, f_rm[i][2] > 0);
		assert_true(s.beams[0].stiffness == 400);
		bsim_scene_free(&s);
	}
	bsim_experiment_free(&e);
}

static void h2_has_162_groups_and_set_block(void **state)
{
	(void)state;
	bsim_experiment e;
	load_experiment("configs/thesis/h2_asymmetric.yaml", &e);
	assert_int_equal(e.n_groups, 162);
	assert_true(e.seed == 2);
	assert_int_equal(e.n_set, 1);
	assert_string_equal(e.set[0].key, "beams.1.stiffness");
	assert_string_equal(e.set[0].value, "500");
	bsim_scene s;
	group_scene(&e, 0, &s);
	assert_true(s.beams[1].stiffness == 500);
	assert_true(s.beams[0].stiffness == 100);
	assert_true(s.effects.propulsion_force == 7 && s.effects.random_magnitude == 10);
	bsim_scene_free(&s);
	group_scene(&e, 161, &s);
	assert_true(s.beams[1].stiffness == 500 && s.beams[0].stiffness == 500);
	assert_true(s.effects.propulsion_force == 9 && s.effects.random_magnitude == 60);
	bsim_scene_free(&s);
	group_scene(&e, 10, &s); /* F7, Rm20 (10 / 9 = 1), k1 150 (10 % 9 = 1) */
	assert_true(s.effects.random_magnitude == 20 && s.beams[0].stiffness == 150);
	bsim_scene_free(&s);
	bsim_experiment_free(&e);
}

static void experiment_grid_value_is_validated_at_load(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("exp_bad");
	bsim_test_write(dir, "gate.yaml", minimal_scene);
	const char *p = bsim_test_write(dir, "exp.yaml",
	                                "scene: gate.yaml\n"
	                                "trials: 3\n"
	                                "seed: 0\n"
	                                "grid:\n"
	                                "  body.mass: [1, 2,\n"
	                                "    -4]\n");
	bsim_experiment e;
	bsim_error err = {0};
	assert_int_equal(bsim_experiment_load(p, NULL, 0, &e, &err), BSIM_EINPUT);
	assert_non_null(
	        strstr(err.msg, "exp.yaml:6: body.mass: expected a positive number, got -4"));
	assert_int_equal(e.n_groups, 0);

	bsim_override extra[] = {{"body.radius", "0", "--set body.radius=0"}};
	p = bsim_test_write(dir, "good.yaml",
	                    "name: h0\nscene: gate.yaml\ntrials: 3\nseed: 0\n"
	                    "grid: {body.mass: [1, 2]}\n");
	assert_int_equal(bsim_experiment_load(p, extra, 1, &e, &err), BSIM_EINPUT);
	assert_non_null(
	        strstr(err.msg, "--set body.radius=0: body.radius: expected a positive number"));
	assert_int_equal(bsim_experiment_load(p, NULL, 0, &e, &err), BSIM_OK);
	assert_int_equal(e.n_groups, 2);
	bsim_experiment_free(&e);
}

static void experiment_set_takes_any_yaml_value(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("exp_set");
	bsim_test_write(dir, "gate.yaml", minimal_scene);
	const char *p = bsim_test_write(dir, "exp.yaml",
	                                "scene: gate.yaml\n"
	                                "trials: 1\n"
	                                "seed: 18446744073709551615\n"
	                                "set:\n"
	                                "  body.start: [3, -4]\n"
	                                "  effects.propulsion: { force: 6 }\n"
	                                "  name: 'h 1'\n"
	                                "grid:\n"
	                                "  body.start.1: [-5]\n");
	bsim_experiment e;
	bsim_error err = {0};
	if (bsim_experiment_load(p, NULL, 0, &e, &err) != BSIM_OK)
		fail_msg("%s", err.msg);
	assert_true(e.seed == UINT64_MAX);
	assert_int_equal(e.n_set, 3);
	assert_string_equal(e.set[0].value, "[3, -4]");
	assert_non_null(strstr(e.set[1].origin, "exp.yaml:6"));
	bsim_scene s;
	bsim_override extra[] = {{"body.mass", "4", "--set body.mass=4"}};
	if (bsim_experiment_group_scene(&e, 0, extra, 1, &s, &err) != BSIM_OK)
		fail_msg("%s", err.msg);
	assert_true(s.body.start[0] == 3 && s.body.start[1] == -5); /* grid after set */
	assert_true(s.effects.has_propulsion && s.effects.propulsion_force == 6);
	assert_string_equal(s.name, "h 1");
	assert_true(s.body.mass == 4);
	bsim_scene_free(&s);
	bsim_experiment_free(&e);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(gate_file_is_table_2_1),
	        cmocka_unit_test(init_gate_is_valid_and_rm_zero_has_no_random_force),
	        cmocka_unit_test(override_sets_beam_stiffness),
	        cmocka_unit_test(override_sets_body_start_list),
	        cmocka_unit_test(later_override_wins),
	        cmocka_unit_test(override_inserts_missing_block),
	        cmocka_unit_test(defaults_fill_what_a_file_leaves_out),
	        cmocka_unit_test(part_defaults_are_the_essays),
	        cmocka_unit_test(zero_magnitude_means_no_random_force),
	        cmocka_unit_test(errors_name_file_line_field),
	        cmocka_unit_test(body_shapes_load_and_have_their_inertia),
	        cmocka_unit_test(override_errors_name_the_override),
	        cmocka_unit_test(duration_gives_the_steps),
	        cmocka_unit_test(dt_override_keeps_the_duration),
	        cmocka_unit_test(override_of_steps_or_duration_replaces_the_length),
	        cmocka_unit_test(inconsistent_steps_and_time_are_refused),
	        cmocka_unit_test(lattice_gate_time_gives_gate_steps),
	        cmocka_unit_test(validate_checks_code_built_scenes),
	        cmocka_unit_test(time_step_bounds_refuse_and_accept),
	        cmocka_unit_test(validate_checks_the_time_step),
	        cmocka_unit_test(h1_has_30_groups_first_axis_slowest),
	        cmocka_unit_test(h2_has_162_groups_and_set_block),
	        cmocka_unit_test(experiment_grid_value_is_validated_at_load),
	        cmocka_unit_test(experiment_set_takes_any_yaml_value),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
