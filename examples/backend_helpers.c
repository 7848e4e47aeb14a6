/* What a backend reports as a beam's contact flag, computed with the
 * helpers every backend uses (beamsim/contact_flag.h for a disk,
 * beamsim/body_shape.h for a capsule or an ellipse), on cases whose answer
 * is known in closed form. Prints each case; exits 1 if one differs.
 *
 *   backend_helpers */
#include <math.h>
#include <stdio.h>

#include <beamsim/body_shape.h>
#include <beamsim/contact_flag.h>

static int failures;

static void expect_flag(const char *what, int got, int want)
{
	printf("%-44s flag %d (want %d)\n", what, got, want);
	failures += got != want;
}

static void expect_near(const char *what, double got, double want)
{
	printf("%-44s %.15g (want %.15g)\n", what, got, want);
	failures += !(fabs(got - want) <= 1e-12);
}

/* A disk of radius R beside a beam of length L pivoted at the origin,
 * rest direction +x, turned a quarter turn to +y: the segment is x = 0,
 * 0 <= y <= L, and a centre at (R + g, y) with 0 < y < L has the gap g. */
static void disk_beside_beam(void)
{
	const double R = 0.5, L = 1.0, p[2] = {0.0, 0.0}, u0[2] = {1.0, 0.0};
	const double theta = acos(0.0); /* rad */
	double u[2];
	bsim_beam_direction(u0, 1.0, theta, u);
	expect_near("direction after a quarter turn, u_y", u[1], 1.0);

	const double g_in = 0.5 * BSIM_CONTACT_TOL, g_out = 1.5 * BSIM_CONTACT_TOL;
	const double near[2] = {R + g_in, 0.5}, far[2] = {R + g_out, 0.5};
	int type;
	double d2 = bsim_beam_distance2(p, u, L, near, &type);
	expect_near("|C - Q|^2 at a gap of tol/2, m^2", d2, (R + g_in) * (R + g_in));
	expect_flag("gap tol/2: in contact, along the segment", bsim_contact_flag(d2, R, type, 0),
	            BSIM_CONTACT_TANGENT);
	d2 = bsim_beam_distance2(p, u, L, far, &type);
	expect_flag("gap 1.5 tol: no contact", bsim_contact_flag(d2, R, type, 0),
	            BSIM_CONTACT_NONE);
	expect_flag("gap 1.5 tol, pushed in the step", bsim_contact_flag(d2, R, type, 1),
	            BSIM_CONTACT_TANGENT);

	/* beyond the tip (0, L) on the beam's line */
	const double past[2] = {0.0, L + R + g_in};
	d2 = bsim_beam_distance2(p, u, L, past, &type);
	expect_flag("gap tol/2 beyond the tip", bsim_contact_flag(d2, R, type, 0),
	            BSIM_CONTACT_TIP);
}

/* An ellipse with semi-axes a (along its heading psi) and b at the origin
 * against a long segment on the line n . y = h: its support in direction n
 * is sqrt(a^2 cos^2(phi - psi) + b^2 sin^2(phi - psi)), phi the angle of n,
 * and the gap is h less that. */
static void ellipse_beside_segment(void)
{
	bsim_body_def body = bsim_body_def_default();
	body.shape = BSIM_SHAPE_ELLIPSE;
	body.semi_axes[0] = 2.0;
	body.semi_axes[1] = 1.0;
	const double psi = 0.2, phi = 0.7, h = 2.5, x[2] = {0.0, 0.0};
	const double n[2] = {cos(phi), sin(phi)}, t[2] = {-n[1], n[0]};
	const double p0[2] = {h * n[0] - 10.0 * t[0], h * n[1] - 10.0 * t[1]};
	const double p1[2] = {h * n[0] + 10.0 * t[0], h * n[1] + 10.0 * t[1]};
	const double ca = cos(phi - psi), sa = sin(phi - psi);
	const double support = sqrt(4.0 * ca * ca + 1.0 * sa * sa);

	bsim_body_segment_contact c;
	if (bsim_body_shape_segment(&body, x, psi, p0, p1, &c) != BSIM_OK) {
		printf("bsim_body_shape_segment failed on an ellipse apart from the segment\n");
		failures++;
		return;
	}
	expect_near("ellipse's gap, m", c.dist, h - support);
	expect_near("normal toward the body, . n", c.n[0] * n[0] + c.n[1] * n[1], -1.0);
	expect_flag("its segment's nearest point is an end", c.at_end, 0);
	expect_near("reach: the major semi-axis, m", bsim_body_shape_reach(&body), 2.0);
}

int main(void)
{
	disk_beside_beam();
	ellipse_beside_segment();
	if (failures)
		fprintf(stderr, "backend_helpers: %d case(s) differ from their closed form\n",
		        failures);
	return failures ? 1 : 0;
}
