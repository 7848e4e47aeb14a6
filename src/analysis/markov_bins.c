/* The entry bins of the single-gate maps (beamsim/markov.h): the bin of
 * an entry state, and states drawn uniformly in a bin for the single
 * gates that have no observed entry to start from. */
#include "analysis/markov_internal.h"

#include <math.h>
#include <string.h>

static const double PI = 3.14159265358979323846;

bsim_markov_bins bsim_markov_bins_default(void)
{
	return (bsim_markov_bins){.n_pos = 14, .n_speed = 6, .n_dir = 13, .v_max = 0.0};
}

double bsim_markov_bins_v_max(const bsim_markov_bins *b, const bsim_scene *lattice)
{
	if (b->v_max > 0)
		return b->v_max;
	const bsim_effects_def *e = &lattice->effects;
	const double a = e->has_propulsion ? fabs(e->propulsion_force) / lattice->body.mass : 0.0;
	return fmax(BSIM_MARKOV_V_MAX, a * BSIM_MARKOV_V_MAX_TIME);
}

int bsim_markov_bins_count(const bsim_markov_bins *b)
{
	return 1 + 4 * b->n_pos * b->n_speed * b->n_dir;
}

int bsim_markov_bins_check(const bsim_markov_bins *b, bsim_error *err)
{
	if (b->n_pos < 1 || b->n_speed < 1 || b->n_dir < 1 || b->n_pos > 64 || b->n_speed > 64 ||
	    b->n_dir > 64)
		return bsim_error_set(
		        err, BSIM_EINPUT,
		        "expected 1 to 64 bins of position, speed and direction each, "
		        "got %d,%d,%d",
		        b->n_pos, b->n_speed, b->n_dir);
	return BSIM_OK;
}

/* Bin 0 is the start; bin 1 + ((e n_pos + ip) n_speed + is) n_dir + id is
 * edge e (0 bottom, 1 left, 2 right, 3 top), position ip, speed is and
 * direction id. An edge's inward normal n and tangent t (gate frame), and
 * the range of the position along it:
 *   bottom  n = (0, 1),  t = (1, 0), pos = x in [-w/2, w/2]
 *   left    n = (1, 0),  t = (0, 1), pos = y in [0, d]
 *   right   n = (-1, 0), t = (0, 1), pos = y in [0, d]
 *   top     n = (0, -1), t = (1, 0), pos = x in [-w/2, w/2]
 * The direction is atan2(v.t, v.n), in [-pi/2, pi/2] for a body moving in. */

static void edge_frame(int edge, double n[2], double t[2])
{
	static const double N[4][2] = {{0, 1}, {1, 0}, {-1, 0}, {0, -1}};
	int e = edge - BSIM_EDGE_BOTTOM;
	n[0] = N[e][0];
	n[1] = N[e][1];
	t[0] = fabs(N[e][1]);
	t[1] = fabs(N[e][0]);
}

static void edge_range(int edge, const bsim_lattice_def *l, double *lo, double *hi)
{
	if (edge == BSIM_EDGE_BOTTOM || edge == BSIM_EDGE_TOP) {
		*lo = -0.5 * l->width;
		*hi = 0.5 * l->width;
	} else {
		*lo = 0.0;
		*hi = l->depth;
	}
}

static int clamp_bin(double u, int n)
{
	int i = (int)floor(u * n);
	return i < 0 ? 0 : i >= n ? n - 1 : i;
}

/* The entry state's position, speed and direction, each as a share of
 * its range: u[0] along the edge, u[1] of v_max, u[2] of [-pi/2, pi/2]. */
static void entry_shares(const bsim_markov_bins *b, const bsim_lattice_def *l, int edge, double pos,
                         const double v[2], double u[3])
{
	double lo, hi, n[2], t[2];
	edge_range(edge, l, &lo, &hi);
	edge_frame(edge, n, t);
	u[0] = (pos - lo) / (hi - lo);
	u[1] = hypot(v[0], v[1]) / b->v_max;
	double a = atan2(v[0] * t[0] + v[1] * t[1], v[0] * n[0] + v[1] * n[1]);
	u[2] = (a + 0.5 * PI) / PI;
}

int bsim_markov_bin_of(const bsim_markov_bins *b, const bsim_lattice_def *l, int edge, double pos,
                       const double v[2])
{
	if (edge < BSIM_EDGE_BOTTOM || edge > BSIM_EDGE_TOP)
		return 0;
	double u[3];
	entry_shares(b, l, edge, pos, v, u);
	int ip = clamp_bin(u[0], b->n_pos);
	int is = clamp_bin(u[1], b->n_speed);
	int id = clamp_bin(u[2], b->n_dir);
	return 1 + (((edge - BSIM_EDGE_BOTTOM) * b->n_pos + ip) * b->n_speed + is) * b->n_dir + id;
}

void bsim_markov_entry_feature(const bsim_markov_bins *b, const bsim_lattice_def *l, int edge,
                               double pos, const double v[2], double f[3])
{
	entry_shares(b, l, edge, pos, v, f);
	f[0] *= b->n_pos;
	f[1] *= b->n_speed;
	f[2] *= b->n_dir;
}

/* A state drawn uniformly in entry bin (> 0): position on the edge, moved
 * inside by half a step's normal travel (the lattice sees an entry at the
 * end of the step that crossed). */
void bsim_markov_bin_sample(const bsim_markov_bins *b, const bsim_lattice_def *l, double h, int bin,
                            gsl_rng *rng, double x[2], double v[2])
{
	int k = bin - 1;
	int id = k % b->n_dir;
	k /= b->n_dir;
	int is = k % b->n_speed;
	k /= b->n_speed;
	int ip = k % b->n_pos;
	int edge = BSIM_EDGE_BOTTOM + k / b->n_pos;
	double lo, hi, n[2], t[2];
	edge_range(edge, l, &lo, &hi);
	edge_frame(edge, n, t);
	double pos = lo + (hi - lo) * (ip + gsl_rng_uniform(rng)) / b->n_pos;
	double speed = b->v_max * (is + gsl_rng_uniform(rng)) / b->n_speed;
	double a = -0.5 * PI + PI * (id + gsl_rng_uniform(rng)) / b->n_dir;
	v[0] = speed * (cos(a) * n[0] + sin(a) * t[0]);
	v[1] = speed * (cos(a) * n[1] + sin(a) * t[1]);
	double inset = 0.5 * fabs(v[0] * n[0] + v[1] * n[1]) * h + 1e-9;
	const double w2 = 0.5 * l->width, d = l->depth;
	switch (edge) {
	case BSIM_EDGE_BOTTOM:
		x[0] = pos;
		x[1] = inset;
		break;
	case BSIM_EDGE_TOP:
		x[0] = pos;
		x[1] = d - inset;
		break;
	case BSIM_EDGE_LEFT:
		x[0] = -w2 + inset;
		x[1] = pos;
		break;
	default:
		x[0] = w2 - inset;
		x[1] = pos;
		break;
	}
}

static const char *const edge_names[] = {"start", "bottom", "left", "right", "top"};

const char *bsim_markov_edge_name(int edge)
{
	return edge_names[edge];
}

int bsim_markov_edge_of(const char *name)
{
	for (int e = BSIM_EDGE_START; e <= BSIM_EDGE_TOP; e++)
		if (strcmp(name, bsim_markov_edge_name(e)) == 0)
			return e;
	return -1;
}

const char *bsim_markov_bin_edge(const bsim_markov_bins *b, int bin)
{
	if (bin == 0)
		return edge_names[BSIM_EDGE_START];
	int per = b->n_pos * b->n_speed * b->n_dir;
	return edge_names[1 + (bin - 1) / per];
}
