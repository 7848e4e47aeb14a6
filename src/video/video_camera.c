/* The camera of a video panel (the essay's MAT2AVI over a lattice).
 *
 * Scale. With the field W x H metres and the panel's view w x h pixels,
 *   s_fit  = min(w / W, h / H)          the whole field in view
 *   s_min  = min(w, h) / view_span      the shorter side spans view_span m
 *   s      = max(s_fit, s_min)
 * so a gate is shown whole and a field of many gates is shown at a scale
 * where the body stays large enough to see.
 *
 * Centre, per axis, with half = (w or h) / (2 s) metres:
 *   field narrower than the view:  c = the field's centre (nothing moves)
 *   else                           c = clamp(body, lo + half, hi - half)
 * (the camera follows the body and stops at the field's edges), and then
 * c is moved the least needed to keep the whole body, radius r, in view,
 * so a body that leaves the field is still followed.
 *
 * Overview. A panel whose camera follows (s > s_fit) also shows the whole
 * field in its bottom-right corner, at the scale that fits it into at most
 * 36% of the view's height and 40% of its width. */
#include <math.h>

#include "video/video_internal.h"

void bsim_video_field_bounds(const bsim_scene *s, double field[4])
{
	const double r = s->body.radius;
	double x0 = s->body.start[0] - r, x1 = s->body.start[0] + r;
	double y0 = s->body.start[1] - r, y1 = s->body.start[1] + r;
	for (int i = 0; i < s->n_beams; i++) {
		const bsim_beam_def *b = &s->beams[i];
		x0 = fmin(x0, b->pivot[0] - b->length);
		x1 = fmax(x1, b->pivot[0] + b->length);
		y0 = fmin(y0, b->pivot[1] - b->length);
		y1 = fmax(y1, b->pivot[1] + b->length);
	}
	x0 = fmin(x0, -s->side_x);
	x1 = fmax(x1, s->side_x);
	y1 = fmax(y1, fmax(s->success_y, s->classify_y) + r);
	field[0] = x0 - 0.5 * r;
	field[1] = y0 - 0.5 * r;
	field[2] = x1 + 0.5 * r;
	field[3] = y1 + 0.5 * r;
}

/* One axis of the centre: lo..hi the field, half the view's half span. */
static double axis_centre(double lo, double hi, double half, double body, double r)
{
	if (!isfinite(body)) /* a state that blew up: show the field */
		return 0.5 * (lo + hi);
	double c;
	if (hi - lo <= 2.0 * half)
		c = 0.5 * (lo + hi);
	else
		c = fmin(fmax(body, lo + half), hi - half);
	if (r <= half) {
		c = fmax(c, body + r - half);
		c = fmin(c, body - r + half);
	} else {
		c = body;
	}
	return c;
}

void bsim_video_view_make(const double field[4], double view_span, double x0, double y0, double w,
                          double h, const double body[2], double r, video_view *out)
{
	const double fw = field[2] - field[0], fh = field[3] - field[1];
	const double s_fit = fmin(w / fw, h / fh);
	const double s_min = fmin(w, h) / view_span;
	out->x0 = x0;
	out->y0 = y0;
	out->w = w;
	out->h = h;
	out->scale = fmax(s_fit, s_min);
	out->c[0] = axis_centre(field[0], field[2], 0.5 * w / out->scale, body[0], r);
	out->c[1] = axis_centre(field[1], field[3], 0.5 * h / out->scale, body[1], r);
}

int bsim_video_overview_make(const double field[4], const video_view *main, video_view *out)
{
	const double fw = field[2] - field[0], fh = field[3] - field[1];
	const double s_fit = fmin(main->w / fw, main->h / fh);
	if (!(main->scale > s_fit * (1.0 + 1e-9)))
		return 0;
	const double margin = 8.0;
	const double s = fmin(0.36 * main->h / fh, 0.40 * main->w / fw);
	out->w = fw * s;
	out->h = fh * s;
	out->x0 = main->x0 + main->w - out->w - margin;
	out->y0 = main->y0 + main->h - out->h - margin;
	out->scale = s;
	out->c[0] = 0.5 * (field[0] + field[2]);
	out->c[1] = 0.5 * (field[1] + field[3]);
	return 1;
}
