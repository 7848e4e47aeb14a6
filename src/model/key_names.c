/* Display names and units of scene keys (beamsim/key_names.h). */
#include "beamsim/key_names.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* One row per key; for a beam key the path after "beams.N." and symbols
 * with a "%d" for the beam's 1-based number. */
typedef struct key_row {
	const char *key;
	const char *name;
	const char *symbol;
	const char *symbol_gp;
	const char *unit;
} key_row;

static const key_row scene_rows[] = {
        {"body.mass", "body mass", "m", "m", "kg"},
        {"body.radius", "body radius", "r", "r", "m"},
        {"body.start", "start position", "(x_0, y_0)", "(x_{0}, y_{0})", "m"},
        {"body.velocity", "initial velocity", "(v_x0, v_y0)", "(v_{x0}, v_{y0})", "m/s"},
        {"body.shape", "body shape", "shape", "shape", ""},
        {"body.rotates", "body rotates", "rotates", "rotates", ""},
        {"body.length", "capsule length", "l", "l", "m"},
        {"body.semi_axes", "semi-axes", "(a, b)", "(a, b)", "m"},
        {"body.heading_deg", "heading", "psi_0", "{/Symbol y}_{0}", "deg"},
        {"body.angular_velocity", "initial angular velocity", "w_0", "{/Symbol w}_{0}", "rad/s"},
        {"body.inertia", "body moment of inertia", "J", "J", "kg m^2"},
        {"contact.restitution", "restitution", "e", "e", ""},
        {"contact.tip_restitution", "tip restitution", "e_tip", "e_{tip}", ""},
        {"contact.rest_threshold", "rest threshold", "v_rest", "v_{rest}", "m/s"},
        {"contact.friction", "contact friction coefficient", "mu_c", "{/Symbol m}_{c}", ""},
        {"effects.propulsion.force", "propulsive force", "F_prop", "F_{prop}", "N"},
        {"effects.random_force.magnitude", "random force magnitude", "R_m", "R_{m}", "N"},
        {"effects.random_force.frequency", "random force frequency", "f_R", "f_{R}", "Hz"},
        {"effects.random_force.correlation_time", "random force correlation time", "tau_R",
         "{/Symbol t}_{R}", "s"},
        {"effects.propulsion.along", "propulsion direction", "along", "along", ""},
        {"effects.drag.linear", "linear drag coefficient", "c", "c", "N s/m"},
        {"effects.drag.angular", "angular drag coefficient", "c_rot", "c_{rot}", "N m s/rad"},
        {"effects.oscillation.amplitude", "oscillation amplitude", "A", "A", "N"},
        {"effects.oscillation.frequency", "oscillation frequency", "f_osc", "f_{osc}", "Hz"},
        {"effects.oscillation.phase", "oscillation phase", "phi", "{/Symbol f}", "rad"},
        {"effects.ground_friction.mu", "ground friction coefficient", "mu", "{/Symbol m}", ""},
        {"effects.ground_friction.g", "gravity", "g", "g", "m/s^2"},
        {"effects.ground_friction.model", "ground friction model", "model", "model", ""},
        {"integration.dt", "time step", "dt", "{/Symbol D}t", "s"},
        {"integration.max_steps", "step limit", "N_steps", "N_{steps}", ""},
        {"integration.duration", "trial duration", "T", "T", "s"},
        {"termination.success_y", "success line", "y_success", "y_{success}", "m"},
        {"termination.side_x", "side-exit line", "x_side", "x_{side}", "m"},
        {"termination.classify_y", "classification line", "y_class", "y_{class}", "m"},
        {"termination.classify_deadband", "classification dead band", "v_dead", "v_{dead}", "m/s"},
        {"termination.gate_steps", "per-gate step limit", "N_gate", "N_{gate}", ""},
        {"termination.gate_time", "per-gate time limit", "T_gate", "T_{gate}", "s"},
        {"landscape.y0", "landscape start line", "y_0", "y_{0}", "m"},
        {"lattice.ix_min", "first column", "ix_min", "ix_{min}", ""},
        {"lattice.ix_max", "last column", "ix_max", "ix_{max}", ""},
        {"lattice.columns", "lattice columns", "n_x", "n_{x}", ""},
        {"lattice.rows", "lattice rows", "n_y", "n_{y}", ""},
        {"lattice.gate.width", "gate width", "w", "w", "m"},
        {"lattice.gate.depth", "gate depth", "d", "d", "m"},
        {"lattice.gate.pivot_y", "pivot line", "y_p", "y_{p}", "m"},
        {"lattice.beam.length", "beam length", "L", "L", "m"},
        {"lattice.beam.mass", "beam mass", "m_b", "m_{b}", "kg"},
        {"lattice.beam.inertia", "beam moment of inertia", "I_b", "I_{b}", "kg m^2"},
        {"lattice.beam.stiffness", "beam stiffness", "k", "k", "N m/rad"},
        {"lattice.beam.damping", "beam damping", "c", "c", "N m s/rad"},
        {"lattice.stiffness", "beam stiffness", "k", "k", "N m/rad"},
        {"lattice.stiffness_left", "left beam stiffness", "k_1", "k_{1}", "N m/rad"},
        {"lattice.stiffness_right", "right beam stiffness", "k_2", "k_{2}", "N m/rad"},
};

/* beams.N.<field>: "%s" takes "left beam", "right beam" or "beam N". */
static const key_row beam_rows[] = {
        {"pivot", "%s pivot", "p_%d", "p_{%d}", "m"},
        {"rest_angle_deg", "%s rest angle", "phi_%d", "{/Symbol f}_{%d}", "deg"},
        {"length", "%s length", "L_%d", "L_{%d}", "m"},
        {"mass", "%s mass", "m_%d", "m_{%d}", "kg"},
        {"inertia", "%s moment of inertia", "I_%d", "I_{%d}", "kg m^2"},
        {"stiffness", "%s stiffness", "k_%d", "k_{%d}", "N m/rad"},
        {"damping", "%s damping", "c_%d", "c_{%d}", "N m s/rad"},
        {"initial_theta", "%s initial angle", "theta_%d(0)", "{/Symbol q}_{%d}(0)", "rad"},
        {"initial_omega", "%s initial angular velocity", "omega_%d(0)", "{/Symbol w}_{%d}(0)",
         "rad/s"},
};

static void fill(bsim_key_name *out, const char *name, const char *symbol, const char *gp,
                 const char *unit)
{
	snprintf(out->name, sizeof out->name, "%s", name);
	snprintf(out->symbol, sizeof out->symbol, "%s", symbol);
	snprintf(out->symbol_gp, sizeof out->symbol_gp, "%s", gp);
	out->unit = unit;
}

/* beams.N.field with N a plain decimal index: the row and N, or NULL. */
static const key_row *beam_row(const char *key, int *n)
{
	if (strncmp(key, "beams.", 6) != 0)
		return NULL;
	const char *p = key + 6;
	char *end;
	if (*p < '0' || *p > '9')
		return NULL;
	long v = strtol(p, &end, 10);
	if (*end != '.' || v > 999)
		return NULL;
	for (size_t i = 0; i < sizeof beam_rows / sizeof beam_rows[0]; i++)
		if (strcmp(end + 1, beam_rows[i].key) == 0) {
			*n = (int)v;
			return &beam_rows[i];
		}
	return NULL;
}

int bsim_key_name_find(const char *key, bsim_key_name *out)
{
	for (size_t i = 0; i < sizeof scene_rows / sizeof scene_rows[0]; i++)
		if (strcmp(key, scene_rows[i].key) == 0) {
			const key_row *r = &scene_rows[i];
			fill(out, r->name, r->symbol, r->symbol_gp, r->unit);
			return 1;
		}
	int n;
	const key_row *r = beam_row(key, &n);
	if (r) {
		char who[24], name[96], symbol[32], gp[48];
		if (n < 2)
			snprintf(who, sizeof who, "%s", n == 0 ? "left beam" : "right beam");
		else
			snprintf(who, sizeof who, "beam %d", n + 1);
		snprintf(name, sizeof name, r->name, who);
		snprintf(symbol, sizeof symbol, r->symbol, n + 1);
		snprintf(gp, sizeof gp, r->symbol_gp, n + 1);
		fill(out, name, symbol, gp, r->unit);
		return 1;
	}
	/* Not a key of the table: the key as it is, and for gnuplot's enhanced
	 * text with its special characters escaped (one backslash each, the
	 * strings are single-quoted). */
	char gp[sizeof out->symbol_gp];
	size_t j = 0;
	for (const char *c = key; *c && j + 2 < sizeof gp; c++) {
		if (strchr("_^{}@&~\\", *c))
			gp[j++] = '\\';
		gp[j++] = *c;
	}
	gp[j] = '\0';
	fill(out, key, key, gp, "");
	return 0;
}

int bsim_key_label(const char *key, int gp, char *buf, size_t size)
{
	bsim_key_name k;
	if (!bsim_key_name_find(key, &k))
		return snprintf(buf, size, "%s", gp ? k.symbol_gp : key);
	const char *symbol = gp ? k.symbol_gp : k.symbol;
	if (k.unit[0])
		return snprintf(buf, size, "%s %s (%s)", k.name, symbol, k.unit);
	return snprintf(buf, size, "%s %s", k.name, symbol);
}

int bsim_key_value(const char *key, const char *value, int gp, char *buf, size_t size)
{
	bsim_key_name k;
	bsim_key_name_find(key, &k);
	const char *symbol = gp ? k.symbol_gp : k.symbol;
	if (k.unit[0])
		return snprintf(buf, size, "%s = %s %s", symbol, value, k.unit);
	return snprintf(buf, size, "%s = %s", symbol, value);
}
