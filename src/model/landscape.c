/* The potential energy landscape (beamsim/landscape.h, docs/model.md
 * section 7).
 *
 * phi is computed from the centre's components along the rest direction u0
 * and along the forward normal sgn * perp(u0), so that a mirrored beam (u0
 * and sgn both negated in x) gives the same two components bit for bit and
 * the landscape of a symmetric gate is exactly mirror symmetric. */
#include "beamsim/landscape.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

double bsim_landscape_theta(const bsim_beam_def *b, double radius, const double c[2])
{
	double u0[2];
	bsim_scene_beam_rest_direction(b, u0);
	const double sgn = bsim_scene_beam_forward_sign(b);
	const double dx = c[0] - b->pivot[0], dy = c[1] - b->pivot[1];
	const double along = u0[0] * dx + u0[1] * dy;       /* rho cos(phi) */
	const double fwd = sgn * (u0[0] * dy - u0[1] * dx); /* rho sin(phi) */
	const double rho2 = along * along + fwd * fwd;
	const double L = b->length, R = radius;
	if (rho2 >= (L + R) * (L + R)) /* the same test as bsim_landscape_beam_reach */
		return 0.0;
	const double rho = sqrt(rho2);
	const double phi = atan2(fwd, along);
	double th;
	if (rho * rho <= L * L + R * R)
		th = phi + (R >= rho ? 1.5707963267948966 : asin(R / rho));
	else
		th = phi + acos(fmin(1.0, (rho * rho + L * L - R * R) / (2.0 * rho * L)));
	return th > 0.0 ? th : 0.0;
}

double bsim_landscape_e_prop(const bsim_scene *s, double y)
{
	if (!s->effects.has_propulsion)
		return 0.0;
	return s->effects.propulsion_force * (s->landscape_y0 - y);
}

double bsim_landscape_energy(const bsim_scene *s, const double c[2], double *theta, double *e_beam,
                             double *e_prop)
{
	double eb = 0.0;
	for (int i = 0; i < s->n_beams; i++) {
		double th = bsim_landscape_theta(&s->beams[i], s->body.radius, c);
		if (theta)
			theta[i] = th;
		eb += 0.5 * s->beams[i].stiffness * th * th;
	}
	double ep = bsim_landscape_e_prop(s, c[1]);
	if (e_beam)
		*e_beam = eb;
	if (e_prop)
		*e_prop = ep;
	return ep + eb;
}

int bsim_landscape_beam_reach(const bsim_beam_def *b, double radius, const double c[2])
{
	const double dx = c[0] - b->pivot[0], dy = c[1] - b->pivot[1];
	const double reach = b->length + radius;
	return dx * dx + dy * dy < reach * reach;
}

int bsim_landscape_in_reach(const bsim_scene *s, const double c[2])
{
	for (int i = 0; i < s->n_beams; i++)
		if (bsim_landscape_beam_reach(&s->beams[i], s->body.radius, c))
			return 1;
	return 0;
}

int bsim_landscape_label(const bsim_scene *s, const double c[2], const int *touching)
{
	int best = -1;
	double e_best = 0.0;
	for (int i = 0; i < s->n_beams; i++) {
		if ((touching && !touching[i]) ||
		    !bsim_landscape_beam_reach(&s->beams[i], s->body.radius, c))
			continue;
		const double th = bsim_landscape_theta(&s->beams[i], s->body.radius, c);
		const double e = 0.5 * s->beams[i].stiffness * th * th;
		if (e > e_best) {
			e_best = e;
			best = i;
		} else if (e == e_best && e > 0.0) {
			best = -2; /* a tie so far; a larger energy later still wins */
		}
	}
	return best >= 0 ? best : -1;
}

bsim_landscape_grid_def bsim_landscape_grid_def_default(void)
{
	bsim_landscape_grid_def d = {.has_region = 0, .region = {0, 0, 0, 0}, .spacing = 0.0};
	return d;
}

/* Intervals along the region's longer side at the default spacing. */
enum { GRID_DEFAULT_INTERVALS = 260 };

static int grid_region(const bsim_scene *s, const bsim_landscape_grid_def *def, double r[4],
                       bsim_error *err)
{
	if (def->has_region) {
		for (int i = 0; i < 4; i++)
			r[i] = def->region[i];
		if (!(isfinite(r[0]) && isfinite(r[1]) && isfinite(r[2]) && isfinite(r[3])) ||
		    !(r[0] < r[1]) || !(r[2] < r[3]))
			return bsim_error_set(
			        err, BSIM_EINPUT,
			        "region %g,%g,%g,%g: expected x0,x1,y0,y1 with x0 < x1 "
			        "and y0 < y1",
			        r[0], r[1], r[2], r[3]);
		return BSIM_OK;
	}
	r[0] = -s->side_x;
	r[1] = s->side_x;
	r[2] = s->body.start[1];
	r[3] = s->success_y;
	if (!(r[2] < r[3]))
		return bsim_error_set(
		        err, BSIM_EINPUT,
		        "%s: the body starts at y = %g m, not before success_y = %g m: "
		        "give the landscape a region",
		        s->path[0] ? s->path : s->name, r[2], r[3]);
	return BSIM_OK;
}

/* The points x0 + i h up to x0 + len (a hair of slack so that a region
 * that is a whole number of spacings ends on its edge). */
static double grid_points(double len, double h)
{
	return floor(len / h + 1e-9) + 1.0;
}

/* The finest spacing, to three digits as text (rounded up), whose grid
 * over a w x hgt region has at most BSIM_LANDSCAPE_MAX_POINTS points: from
 * (w / h + 1) (hgt / h + 1) = N, a quadratic in 1 / h, then checked on the
 * value the text reads back as. */
static void finest_spacing(double w, double hgt, char *text, size_t size)
{
	const double n = BSIM_LANDSCAPE_MAX_POINTS, b = w + hgt;
	double h = 2.0 * w * hgt / (-b + sqrt(b * b + 4.0 * w * hgt * (n - 1.0)));
	const double step = pow(10.0, floor(log10(h)) - 2.0);
	h = ceil(h / step) * step;
	for (;;) {
		snprintf(text, size, "%.3g", h);
		const double read = strtod(text, NULL);
		if (grid_points(w, read) * grid_points(hgt, read) <= n)
			return;
		h += step;
	}
}

int bsim_landscape_grid_alloc(const bsim_scene *s, const bsim_landscape_grid_def *def,
                              bsim_landscape_grid **out, bsim_error *err)
{
	*out = NULL;
	/* The landscape is the disk's: each beam turned just clear of a disk
	 * at c, a function of the centre alone. Another shape's clearance
	 * depends on its heading too. */
	if (s->body.shape != BSIM_SHAPE_DISK)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s: body.shape: expected disk for the energy landscape (a "
		                      "function of the disk's centre alone), got %s",
		                      s->path[0] ? s->path : s->name,
		                      s->body.shape == BSIM_SHAPE_CAPSULE ? "capsule" : "ellipse");
	double r[4];
	int rc = grid_region(s, def, r, err);
	if (rc)
		return rc;
	const double w = r[1] - r[0], hgt = r[3] - r[2];
	double h = def->spacing;
	if (h == 0.0)
		h = fmax(w, hgt) / GRID_DEFAULT_INTERVALS;
	if (!(h > 0.0) || !isfinite(h))
		return bsim_error_set(err, BSIM_EINPUT, "--resolution %g: expected a spacing > 0 m",
		                      def->spacing);
	const double nxd = grid_points(w, h), nyd = grid_points(hgt, h);
	if (nxd < 3 || nyd < 3)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "--resolution %g: under 3 points across the %g x %g m region",
		                      h, w, hgt);
	if (nxd * nyd > BSIM_LANDSCAPE_MAX_POINTS) {
		/* The counts in full up to 10^15, so that a tiny spacing gives
		 * "5e+301", not 300 digits. */
		char finest[32];
		finest_spacing(w, hgt, finest, sizeof finest);
		if (strtod(finest, NULL) > fmin(w, hgt) / 2.0)
			return bsim_error_set(err, BSIM_EINPUT,
			                      "--resolution %g: %.15g x %.15g points over the %g x "
			                      "%g m region, more than the %d a landscape may have, "
			                      "and no spacing gives fewer with 3 points a side; "
			                      "expected a smaller --region",
			                      h, nxd, nyd, w, hgt, BSIM_LANDSCAPE_MAX_POINTS);
		return bsim_error_set(err, BSIM_EINPUT,
		                      "--resolution %g: %.15g x %.15g points over the %g x %g m "
		                      "region, more than the %d a landscape may have; expected a "
		                      "spacing of at least %s m (or a smaller --region)",
		                      h, nxd, nyd, w, hgt, BSIM_LANDSCAPE_MAX_POINTS, finest);
	}
	bsim_landscape_grid *g = calloc(1, sizeof *g);
	if (!g)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	g->nx = (int)nxd;
	g->ny = (int)nyd;
	g->x0 = r[0];
	g->y0 = r[2];
	g->spacing = h;
	for (int i = 0; i < 4; i++)
		g->region[i] = r[i];
	g->n_beams = s->n_beams;
	const size_t n = (size_t)g->nx * (size_t)g->ny;
	g->e_total = malloc(n * sizeof(double));
	g->e_beam = malloc(n * sizeof(double));
	g->e_prop = malloc(n * sizeof(double));
	g->theta = malloc((s->n_beams > 0 ? (size_t)s->n_beams : 1) * n * sizeof(double));
	if (!g->e_total || !g->e_beam || !g->e_prop || !g->theta) {
		bsim_landscape_grid_free(g);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory for %zu landscape points", n);
	}
	double *th = s->n_beams > 0 ? malloc((size_t)s->n_beams * sizeof(double)) : NULL;
	if (s->n_beams > 0 && !th) {
		bsim_landscape_grid_free(g);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	for (int j = 0; j < g->ny; j++)
		for (int i = 0; i < g->nx; i++) {
			const size_t k = (size_t)j * (size_t)g->nx + (size_t)i;
			const double c[2] = {g->x0 + i * h, g->y0 + j * h};
			g->e_total[k] =
			        bsim_landscape_energy(s, c, th, &g->e_beam[k], &g->e_prop[k]);
			for (int b = 0; b < s->n_beams; b++)
				g->theta[(size_t)b * n + k] = th[b];
		}
	free(th);
	*out = g;
	return BSIM_OK;
}

void bsim_landscape_grid_free(bsim_landscape_grid *g)
{
	if (!g)
		return;
	free(g->e_total);
	free(g->e_beam);
	free(g->e_prop);
	free(g->theta);
	free(g);
}
