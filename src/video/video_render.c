/* Drawing one frame of a video with cairo (Debian libcairo2-dev).
 *
 * The frame is split into equal panels, one a track, left to right. A
 * panel is a title bar (label, time) over a view of the world (camera in
 * video_camera.c). Beam i at angle theta points along its rest direction
 * u0 turned by sigma theta, sigma = +1 for a beam pointing right at rest
 * and -1 for one pointing left (forward positive: the tip swings to +y):
 *   tip = pivot + L (cos(a0 + sigma theta), sin(a0 + sigma theta)),
 *   a0 = atan2(u0_y, u0_x).
 * Colours are given as 8-bit sRGB values so that a fully covered pixel
 * gets exactly that value (cairo stores d * 65535 and reads back the high
 * byte): the body's colour is found in a frame by tests, and the beams'
 * colours are the legend's.
 *
 * A lattice's frames also show its gates: dashed boundaries (the essay's
 * Fig. 2.8) and, tinted, the gates the body has entered so far (the
 * runner's gate path up to the frame's step). When the camera follows the
 * body, an overview in the bottom-right corner shows the whole field: each
 * gate's left and right half in the paled colour of the beam that sweeps
 * it, the gates entered filled in the path colour, the trail, the body as
 * a dot and the rectangle the camera shows. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <cairo.h>

#include "beamsim/lattice.h"
#include "beamsim/lattice_outcome.h"
#include "video/video_internal.h"

#define VIDEO_TAU 6.28318530717958647692 /* a full circle, rad */

/* Colours, 0x00RRGGBB. The body's appears nowhere else. */
enum {
	COLOR_BODY = 0xE8590C,
	COLOR_BODY_EDGE = 0x7A2E06,
	COLOR_TRAIL = 0xA8400A,
	COLOR_GHOST = 0x9A9A9A,
	COLOR_PIVOT = 0x333333,
	COLOR_SIDE = 0xB4B4B4,
	COLOR_SUCCESS = 0x2E9E44,
	COLOR_ARROW = 0x111111,
	COLOR_TITLE = 0xE9E9E9,
	COLOR_TEXT = 0x111111,
	COLOR_BACKGROUND = 0xFFFFFF,
	COLOR_GATE_LINE = 0x7FC08F, /* gate boundaries, a light green */
	COLOR_PATH_TINT = 0xFFF0E0, /* the gates entered, in the view */
	COLOR_PATH = 0xF6B26B,      /* the gates entered, in the overview */
	COLOR_OVERVIEW_EDGE = 0x555555,
};

/* Viridis at u = 0, 1/8, ..., 1 (dark purple to yellow). */
static const unsigned char viridis[9][3] = {
        {68, 1, 84},    {71, 44, 122}, {59, 81, 139},  {44, 113, 142}, {33, 144, 141},
        {39, 173, 129}, {92, 200, 99}, {170, 220, 50}, {253, 231, 37},
};

/* The softest beam is light (viridis 0.9, yellow-green, still visible on
 * white) and the stiffest dark (viridis 0). */
uint32_t bsim_video_colormap(double u)
{
	if (!(u >= 0.0))
		u = 0.0;
	if (u > 1.0)
		u = 1.0;
	double x = 0.9 * (1.0 - u) * 8.0;
	int i = (int)floor(x);
	if (i >= 8)
		i = 7;
	double f = x - i;
	uint32_t c = 0;
	for (int ch = 0; ch < 3; ch++) {
		double v = viridis[i][ch] + f * (viridis[i + 1][ch] - viridis[i][ch]);
		c = (c << 8) | (uint32_t)lround(v);
	}
	return c;
}

uint32_t bsim_video_body_color(void)
{
	return COLOR_BODY;
}

uint32_t bsim_video_path_color(void)
{
	return COLOR_PATH;
}

/* c blended toward white by f (0: c, 1: white). */
static uint32_t paled(uint32_t c, double f)
{
	uint32_t out = 0;
	for (int sh = 16; sh >= 0; sh -= 8) {
		double ch = (c >> sh) & 255;
		out |= (uint32_t)lround(ch + f * (255.0 - ch)) << sh;
	}
	return out;
}

uint32_t bsim_video_stiffness_color(const bsim_video *v, double k)
{
	double span = v->k_max - v->k_min;
	return bsim_video_colormap(span > 0.0 ? (k - v->k_min) / span : 0.5);
}

static void set_color(cairo_t *cr, uint32_t c)
{
	cairo_set_source_rgb(cr, ((c >> 16) & 255) / 255.0, ((c >> 8) & 255) / 255.0,
	                     (c & 255) / 255.0);
}

static void beam_tip(const bsim_beam_def *b, double theta, double tip[2])
{
	double u0[2];
	bsim_scene_beam_rest_direction(b, u0);
	double a = atan2(u0[1], u0[0]) + bsim_scene_beam_forward_sign(b) * theta;
	tip[0] = b->pivot[0] + b->length * cos(a);
	tip[1] = b->pivot[1] + b->length * sin(a);
}

static void line_world(cairo_t *cr, const video_view *vw, const double a[2], const double b[2])
{
	double pa[2], pb[2];
	video_view_pixel(vw, a, pa);
	video_view_pixel(vw, b, pb);
	cairo_move_to(cr, pa[0], pa[1]);
	cairo_line_to(cr, pb[0], pb[1]);
}

/* Panel q's path from step 0 to step `last` in a view, from its trail
 * thinned at that view's scale (video_trail.c): the kept points before
 * `last` and the centre at `last`, or up to the first centre that is not
 * finite. */
static void draw_trail(cairo_t *cr, const video_view *vw, const bsim_video *v, int q,
                       const video_trail *tr, long last, uint32_t color, double width)
{
	const video_panel *pn = &v->panels[q];
	const long hi = pn->track ? pn->last_step : pn->now.step;
	if (last > hi)
		last = hi;
	if (last < 1 || !tr || tr->n == 0)
		return;
	double p[2];
	video_view_pixel(vw, tr->p[0].x, p);
	cairo_move_to(cr, p[0], p[1]);
	const int broken = tr->broken >= 0 && tr->broken <= last;
	long i = 1;
	for (; i < tr->n && tr->p[i].step < last; i++) {
		video_view_pixel(vw, tr->p[i].x, p);
		cairo_line_to(cr, p[0], p[1]);
	}
	if (!broken) {
		double x[2];
		if (pn->track) {
			bsim_video_track_position(pn->track, last, x);
		} else if (last == pn->now.step) {
			x[0] = pn->now.x[0];
			x[1] = pn->now.x[1];
		} else {
			/* a step another panel ended at, marked as it passed */
			x[0] = tr->p[i - 1].x[0];
			x[1] = tr->p[i - 1].x[1];
			for (int m = 0; m < pn->n_marks; m++)
				if (pn->marks[m].step == last) {
					x[0] = pn->marks[m].x[0];
					x[1] = pn->marks[m].x[1];
				}
		}
		video_view_pixel(vw, x, p);
		cairo_line_to(cr, p[0], p[1]);
	}
	set_color(cr, color);
	cairo_set_line_width(cr, width);
	cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
	cairo_stroke(cr);
}

/* The side boundaries and the success line, dashed. */
static void draw_bounds(cairo_t *cr, const bsim_video *v, const video_view *vw)
{
	const bsim_scene *s = v->scene;
	const double *f = v->field;
	double dash[] = {6.0, 4.0};
	cairo_set_dash(cr, dash, 2, 0.0);
	cairo_set_line_width(cr, 1.5);
	for (int side = -1; side <= 1; side += 2) {
		double a[2] = {side * s->side_x, f[1]}, b[2] = {side * s->side_x, f[3]};
		line_world(cr, vw, a, b);
	}
	set_color(cr, COLOR_SIDE);
	cairo_stroke(cr);
	double a[2] = {-s->side_x, s->success_y}, b[2] = {s->side_x, s->success_y};
	line_world(cr, vw, a, b);
	set_color(cr, COLOR_SUCCESS);
	cairo_stroke(cr);
	cairo_set_dash(cr, NULL, 0, 0.0);
}

/* Which gates of a lattice the body has entered by step `step` (the
 * runner's path): entered[iy columns + ix - ix_min] = 1; the gate of the
 * last entry so far in *cur. Returns the number of entries so far. */
static int gates_entered(const bsim_video *v, int p, long step, unsigned char *entered, int cur[2])
{
	const bsim_lattice_def *l = &v->scene->lattice;
	int n = v->panels[p].n_visits, count = 0;
	const video_gate_visit *e = v->panels[p].visits;
	memset(entered, 0, (size_t)(l->columns * l->rows));
	cur[0] = cur[1] = 0;
	for (int i = 0; i < n && e[i].step <= step; i++) {
		if (e[i].ix >= l->ix_min && e[i].ix <= l->ix_max && e[i].iy >= 0 &&
		    e[i].iy < l->rows)
			entered[e[i].iy * l->columns + e[i].ix - l->ix_min] = 1;
		cur[0] = e[i].ix;
		cur[1] = e[i].iy;
		count++;
	}
	return count;
}

static void rect_world(cairo_t *cr, const video_view *vw, double x0, double y0, double x1,
                       double y1)
{
	double a[2], b[2];
	const double p0[2] = {x0, y0}, p1[2] = {x1, y1};
	video_view_pixel(vw, p0, a);
	video_view_pixel(vw, p1, b);
	cairo_rectangle(cr, fmin(a[0], b[0]), fmin(a[1], b[1]), fabs(b[0] - a[0]),
	                fabs(b[1] - a[1]));
}

/* The main view's gates: the entered ones tinted, the boundaries dashed. */
static void draw_gates(cairo_t *cr, const bsim_video *v, const video_view *vw,
                       const unsigned char *entered)
{
	const bsim_lattice_def *l = &v->scene->lattice;
	const double w = l->width, d = l->depth;
	for (int iy = 0; iy < l->rows; iy++)
		for (int ix = l->ix_min; ix <= l->ix_max; ix++)
			if (entered[iy * l->columns + ix - l->ix_min])
				rect_world(cr, vw, w * ix - 0.5 * w, d * iy, w * ix + 0.5 * w,
				           d * (iy + 1));
	set_color(cr, COLOR_PATH_TINT);
	cairo_fill(cr);
	const double x0 = w * l->ix_min - 0.5 * w, x1 = w * l->ix_max + 0.5 * w;
	const double y0 = 0.0, y1 = d * l->rows;
	for (int c = 0; c <= l->columns; c++) {
		const double a[2] = {x0 + w * c, y0}, b[2] = {x0 + w * c, y1};
		line_world(cr, vw, a, b);
	}
	for (int r = 0; r <= l->rows; r++) {
		const double a[2] = {x0, y0 + d * r}, b[2] = {x1, y0 + d * r};
		line_world(cr, vw, a, b);
	}
	double dash[] = {4.0, 4.0};
	cairo_set_dash(cr, dash, 2, 0.0);
	cairo_set_line_width(cr, 1.0);
	set_color(cr, COLOR_GATE_LINE);
	cairo_stroke(cr);
	cairo_set_dash(cr, NULL, 0, 0.0);
}

/* The overview ov of the whole field (bsim_video_overview_make): a lattice's
 * gates by stiffness, the entered ones in the path colour, or the beams at
 * rest of any other scene; the bounds, the trail, the body as a dot and
 * the main view's rectangle. */
static void draw_overview(cairo_t *cr, const bsim_video *v, const video_view *ov,
                          const video_view *main, int panel, long step, const double body[2],
                          const unsigned char *entered)
{
	const bsim_scene *s = v->scene;
	cairo_save(cr);
	cairo_rectangle(cr, ov->x0 - 1.0, ov->y0 - 1.0, ov->w + 2.0, ov->h + 2.0);
	set_color(cr, COLOR_BACKGROUND);
	cairo_fill_preserve(cr);
	set_color(cr, COLOR_OVERVIEW_EDGE);
	cairo_set_line_width(cr, 1.0);
	cairo_stroke(cr);
	cairo_rectangle(cr, ov->x0, ov->y0, ov->w, ov->h);
	cairo_clip(cr);
	if (s->has_lattice) {
		const bsim_lattice_def *l = &s->lattice;
		const double w = l->width, d = l->depth;
		for (int iy = 0; iy < l->rows; iy++)
			for (int ix = l->ix_min; ix <= l->ix_max; ix++) {
				const int in = entered[iy * l->columns + ix - l->ix_min];
				for (int side = 0; side < 2; side++) {
					const bsim_beam_def *b =
					        &s->beams[bsim_lattice_beam(l, ix, iy, side)];
					const double xa = w * ix + (side ? 0.0 : -0.5 * w);
					rect_world(cr, ov, xa, d * iy, xa + 0.5 * w, d * (iy + 1));
					set_color(cr, in ? COLOR_PATH
					                 : paled(bsim_video_stiffness_color(
					                                 v, b->stiffness),
					                         0.55));
					cairo_fill(cr);
				}
			}
		const double x0 = w * l->ix_min - 0.5 * w, y1 = d * l->rows;
		for (int c = 0; c <= l->columns; c++) {
			const double a[2] = {x0 + w * c, 0.0}, b[2] = {x0 + w * c, y1};
			line_world(cr, ov, a, b);
		}
		for (int r = 0; r <= l->rows; r++) {
			const double a[2] = {x0, d * r}, b[2] = {x0 + w * l->columns, d * r};
			line_world(cr, ov, a, b);
		}
		set_color(cr, COLOR_BACKGROUND);
		cairo_set_line_width(cr, 0.8);
		cairo_stroke(cr);
	} else {
		cairo_set_line_width(cr, 1.5);
		for (int i = 0; i < s->n_beams; i++) {
			const bsim_beam_def *b = &s->beams[i];
			double tip[2];
			beam_tip(b, 0.0, tip);
			line_world(cr, ov, b->pivot, tip);
			set_color(cr, paled(bsim_video_stiffness_color(v, b->stiffness), 0.3));
			cairo_stroke(cr);
		}
	}
	draw_trail(cr, ov, v, panel, v->panels[panel].trail[v->n_panels], step, COLOR_TRAIL, 1.0);
	double p[2];
	if (isfinite(body[0]) && isfinite(body[1])) {
		video_view_pixel(ov, body, p);
		cairo_new_sub_path(cr);
		cairo_arc(cr, p[0], p[1], fmax(2.5, s->body.radius * ov->scale), 0.0, VIDEO_TAU);
		set_color(cr, COLOR_TEXT);
		cairo_fill(cr);
	}
	/* the main view's rectangle */
	const double half_w = 0.5 * main->w / main->scale, half_h = 0.5 * main->h / main->scale;
	rect_world(cr, ov, main->c[0] - half_w, main->c[1] - half_h, main->c[0] + half_w,
	           main->c[1] + half_h);
	set_color(cr, COLOR_OVERVIEW_EDGE);
	cairo_set_line_width(cr, 1.0);
	cairo_stroke(cr);
	cairo_restore(cr);
}

static void draw_beams(cairo_t *cr, const bsim_video *v, const video_view *vw,
                       const bsim_video_sample *sm)
{
	const bsim_scene *s = v->scene;
	cairo_set_line_width(cr, 4.0);
	cairo_set_line_cap(cr, CAIRO_LINE_CAP_BUTT);
	for (int i = 0; i < s->n_beams; i++) {
		const bsim_beam_def *b = &s->beams[i];
		double tip[2];
		if (!isfinite(sm->theta[i]))
			continue;
		beam_tip(b, sm->theta[i], tip);
		line_world(cr, vw, b->pivot, tip);
		set_color(cr, bsim_video_stiffness_color(v, b->stiffness));
		cairo_stroke(cr);
	}
	set_color(cr, COLOR_PIVOT);
	for (int i = 0; i < s->n_beams; i++) {
		double p[2];
		video_view_pixel(vw, s->beams[i].pivot, p);
		cairo_new_sub_path(cr);
		cairo_arc(cr, p[0], p[1], 3.0, 0.0, VIDEO_TAU);
	}
	cairo_fill(cr);
}

static void draw_body(cairo_t *cr, const bsim_video *v, const video_view *vw, const double x[2])
{
	if (!isfinite(x[0]) || !isfinite(x[1]))
		return;
	double p[2];
	video_view_pixel(vw, x, p);
	double r = v->scene->body.radius * vw->scale;
	cairo_new_sub_path(cr);
	cairo_arc(cr, p[0], p[1], r, 0.0, VIDEO_TAU);
	set_color(cr, COLOR_BODY);
	cairo_fill_preserve(cr);
	set_color(cr, COLOR_BODY_EDGE);
	cairo_set_line_width(cr, 1.5);
	cairo_stroke(cr);
}

/* The random force from the body centre, one body radius per Rm. */
static void draw_force(cairo_t *cr, const bsim_video *v, const video_view *vw,
                       const bsim_video_sample *sm, int axis)
{
	const bsim_scene *s = v->scene;
	if (!s->effects.has_random_force || s->effects.random_magnitude <= 0.0 ||
	    sm->f_rand == 0.0 || !isfinite(sm->x[0]) || !isfinite(sm->x[1]))
		return;
	double len = s->body.radius * sm->f_rand / s->effects.random_magnitude;
	double a[2], b[2] = {sm->x[0], sm->x[1]};
	video_view_pixel(vw, sm->x, a);
	b[axis] += len;
	video_view_pixel(vw, b, b);
	double dx = b[0] - a[0], dy = b[1] - a[1], d = hypot(dx, dy);
	if (d < 1.0)
		return;
	double ux = dx / d, uy = dy / d, head = fmin(10.0, 0.5 * d);
	set_color(cr, COLOR_ARROW);
	cairo_set_line_width(cr, 2.5);
	cairo_move_to(cr, a[0], a[1]);
	cairo_line_to(cr, b[0] - ux * head * 0.8, b[1] - uy * head * 0.8);
	cairo_stroke(cr);
	cairo_move_to(cr, b[0], b[1]);
	cairo_line_to(cr, b[0] - ux * head - uy * head * 0.45, b[1] - uy * head + ux * head * 0.45);
	cairo_line_to(cr, b[0] - ux * head + uy * head * 0.45, b[1] - uy * head - ux * head * 0.45);
	cairo_close_path(cr);
	cairo_fill(cr);
}

/* Lines of text in a light box with its corner at (x, y): anchor_right
 * puts the box's right edge at x, anchor_bottom its bottom at y. */
static void text_box(cairo_t *cr, double x, double y, const char *const *lines, int n,
                     int anchor_right, int anchor_bottom, double fs)
{
	double w = 0.0, pad = 0.4 * fs, lh = 1.3 * fs;
	for (int i = 0; i < n; i++) {
		cairo_text_extents_t e;
		cairo_text_extents(cr, lines[i], &e);
		w = fmax(w, e.x_advance);
	}
	double bw = w + 2.0 * pad, bh = n * lh + 2.0 * pad - 0.3 * fs;
	double bx = anchor_right ? x - bw : x, by = anchor_bottom ? y - bh : y;
	cairo_rectangle(cr, bx, by, bw, bh);
	cairo_set_source_rgba(cr, 1.0, 1.0, 1.0, 0.85);
	cairo_fill(cr);
	set_color(cr, COLOR_TEXT);
	for (int i = 0; i < n; i++) {
		cairo_move_to(cr, bx + pad, by + pad + i * lh + fs * 0.95);
		cairo_show_text(cr, lines[i]);
	}
}

/* The stiffness scale: a vertical bar at the view's right, stiffest on
 * top, with its ends labelled; one swatch if every beam is alike. */
static void draw_legend(cairo_t *cr, const bsim_video *v, const video_view *vw, double fs)
{
	if (v->scene->n_beams == 0)
		return;
	char top[64], bottom[64];
	const double bar_w = 14.0, bar_h = fmax(40.0, 0.3 * vw->h);
	const double x1 = vw->x0 + vw->w - 8.0, y0 = vw->y0 + 8.0;
	const int uniform = !(v->k_max > v->k_min);
	snprintf(top, sizeof top, "%.4g", v->k_max);
	snprintf(bottom, sizeof bottom, "%.4g", v->k_min);
	cairo_text_extents_t e;
	cairo_text_extents(cr, uniform ? top : (strlen(top) > strlen(bottom) ? top : bottom), &e);
	const char *title = "k, N m/rad";
	cairo_text_extents_t et;
	cairo_text_extents(cr, title, &et);
	double box_w = fmax(bar_w + 6.0 + e.x_advance, et.x_advance) + 12.0;
	double box_h = (uniform ? bar_w : bar_h) + 2.2 * fs + 10.0;
	cairo_rectangle(cr, x1 - box_w, y0, box_w, box_h);
	cairo_set_source_rgba(cr, 1.0, 1.0, 1.0, 0.85);
	cairo_fill(cr);
	set_color(cr, COLOR_TEXT);
	cairo_move_to(cr, x1 - box_w + 6.0, y0 + 1.1 * fs);
	cairo_show_text(cr, title);
	double bx = x1 - box_w + 6.0, by = y0 + 1.6 * fs;
	if (uniform) {
		cairo_rectangle(cr, bx, by, bar_w, bar_w);
		set_color(cr, bsim_video_stiffness_color(v, v->k_min));
		cairo_fill(cr);
		set_color(cr, COLOR_TEXT);
		cairo_move_to(cr, bx + bar_w + 6.0, by + 0.5 * bar_w + 0.4 * fs);
		cairo_show_text(cr, top);
		return;
	}
	for (int j = 0; j < (int)bar_h; j++) {
		double u = 1.0 - (j + 0.5) / bar_h;
		cairo_rectangle(cr, bx, by + j, bar_w, 1.0);
		set_color(cr, bsim_video_colormap(u));
		cairo_fill(cr);
	}
	set_color(cr, COLOR_TEXT);
	cairo_move_to(cr, bx + bar_w + 6.0, by + 0.8 * fs);
	cairo_show_text(cr, top);
	cairo_move_to(cr, bx + bar_w + 6.0, by + bar_h);
	cairo_show_text(cr, bottom);
}

static void outcome_text(const bsim_scene *s, const bsim_trial_result *r, char *buf, size_t n)
{
	if (s->has_lattice && r->outcome != BSIM_UNSTABLE) {
		const bsim_location loc = bsim_lattice_location_of(r);
		if (loc.kind == BSIM_LOCATION_END)
			snprintf(buf, n, "reached the end in column %d at t = %.2f s", loc.ix,
			         r->t_end);
		else if (loc.kind == BSIM_LOCATION_SIDE)
			snprintf(buf, n, "left through the %s side in row %d at t = %.2f s",
			         r->x_end < bsim_lattice_centre_x(s) ? "left" : "right", loc.iy,
			         r->t_end);
		else
			snprintf(buf, n, "stuck in gate (%d, %d) at t = %.2f s", loc.ix, loc.iy,
			         r->t_end);
		return;
	}
	switch (r->outcome) {
	case BSIM_TRAVERSED:
		snprintf(buf, n, "traversed at t = %.2f s (%s type)", r->t_end,
		         bsim_trial_type_name(r->type));
		break;
	case BSIM_SIDE_EXIT:
		snprintf(buf, n, "side exit at t = %.2f s", r->t_end);
		break;
	case BSIM_STUCK:
		snprintf(buf, n, "stuck at t = %.2f s (%s)", r->t_end,
		         r->in_contact_end ? "in contact" : "not in contact");
		break;
	default:
		snprintf(buf, n, "%s at t = %.2f s", bsim_trial_outcome_name(r->outcome), r->t_end);
		break;
	}
}

/* The font size of a frame, px: the title bar is two of it high. */
static double font_size(const bsim_video *v)
{
	return fmax(11.0, floor(v->height / 40.0));
}

void bsim_video_panel_view(const bsim_video *v, int p, long k, video_view *out)
{
	const double px0 = (double)(p * v->width / v->n_panels);
	const double pw = (double)((p + 1) * v->width / v->n_panels) - px0;
	const double title_h = ceil(2.0 * font_size(v));
	const bsim_video_sample sm = video_panel_sample(v, p, k);
	bsim_video_view_make(v->field, v->def.view_span, px0, title_h, pw, v->height - title_h,
	                     sm.x, v->scene->body.radius, out);
}

int bsim_video_panel_scales(const bsim_video *v, int p, double *s_main, double *s_over)
{
	const double px0 = (double)(p * v->width / v->n_panels);
	const double pw = (double)((p + 1) * v->width / v->n_panels) - px0;
	const double title_h = ceil(2.0 * font_size(v));
	video_view vw, ov;
	bsim_video_view_make(v->field, v->def.view_span, px0, title_h, pw, v->height - title_h,
	                     v->scene->body.start, v->scene->body.radius, &vw);
	*s_main = vw.scale;
	*s_over = 0.0;
	if (!bsim_video_overview_make(v->field, &vw, &ov))
		return 0;
	*s_over = ov.scale;
	return 1;
}

int bsim_video_overview_pixel(const bsim_video *v, int panel, long k, const double p[2],
                              double px[2])
{
	if (panel < 0 || panel >= v->n_panels)
		return 0;
	if (k >= v->frames_sim)
		k = v->frames_sim - 1;
	video_view vw, ov;
	bsim_video_panel_view(v, panel, k, &vw);
	if (!bsim_video_overview_make(v->field, &vw, &ov))
		return 0;
	video_view_pixel(&ov, p, px);
	return 1;
}

static void draw_panel(cairo_t *cr, const bsim_video *v, int p, long k, double fs)
{
	const bsim_scene *s = v->scene;
	const video_panel *pn = &v->panels[p];
	const double px0 = (double)(p * v->width / v->n_panels);
	const double pw = (double)((p + 1) * v->width / v->n_panels) - px0;
	const double title_h = ceil(2.0 * fs);
	const bsim_video_sample sm = video_panel_sample(v, p, k);
	const bsim_trial_result *res = pn->result;
	char buf[160];

	cairo_save(cr);
	cairo_rectangle(cr, px0, 0.0, pw, v->height);
	cairo_clip(cr);
	set_color(cr, COLOR_BACKGROUND);
	cairo_paint(cr);

	video_view vw, ov;
	bsim_video_panel_view(v, p, k, &vw);
	const int overview = bsim_video_overview_make(v->field, &vw, &ov);
	unsigned char *entered = NULL;
	int cur[2] = {0, 0}, n_entered = 0;
	if (s->has_lattice) {
		entered = v->entered;
		n_entered = gates_entered(v, p, sm.step, entered, cur);
	}
	cairo_save(cr);
	cairo_rectangle(cr, vw.x0, vw.y0, vw.w, vw.h);
	cairo_clip(cr);
	if (entered)
		draw_gates(cr, v, &vw, entered);
	draw_bounds(cr, v, &vw);
	for (int q = 0; q < v->n_panels; q++)
		if (q != p)
			draw_trail(cr, &vw, v, q, v->panels[q].trail[p], sm.step, COLOR_GHOST, 1.2);
	draw_trail(cr, &vw, v, p, pn->trail[p], sm.step, COLOR_TRAIL, 1.5);
	draw_beams(cr, v, &vw, &sm);
	draw_body(cr, v, &vw, sm.x);
	draw_force(cr, v, &vw, &sm, pn->random_axis);
	const double t_part = v->t_part[p];
	if (t_part >= 0.0 && sm.t >= t_part) {
		double pp[2];
		video_view_pixel(&vw, pn->part_x, pp);
		cairo_new_sub_path(cr);
		cairo_arc(cr, pp[0], pp[1], 5.0, 0.0, VIDEO_TAU);
		set_color(cr, COLOR_TEXT);
		cairo_set_line_width(cr, 1.5);
		cairo_stroke(cr);
	}

	/* Overlays inside the view. */
	if (overview)
		draw_overview(cr, v, &ov, &vw, p, sm.step, sm.x, entered);
	char l_kin[48], l_spring[48], l_prop[48], l_force[48], l_part[96], l_gate[64];
	const char *lines[6] = {l_kin, l_spring, l_prop};
	int n_lines = 3;
	snprintf(l_kin, sizeof l_kin, "E_kin    %7.1f J", sm.e_kin);
	snprintf(l_spring, sizeof l_spring, "E_spring %7.1f J", sm.e_spring);
	snprintf(l_prop, sizeof l_prop, "E_prop   %7.1f J", sm.e_prop);
	if (s->effects.has_random_force) {
		snprintf(l_force, sizeof l_force, "F_rand   %7.1f N", sm.f_rand);
		lines[n_lines++] = l_force;
	}
	if (entered) {
		snprintf(l_gate, sizeof l_gate, "gate (%d, %d), %d entered", cur[0], cur[1],
		         n_entered);
		lines[n_lines++] = l_gate;
	}
	if (t_part >= 0.0 && sm.t >= t_part) {
		snprintf(l_part, sizeof l_part, "parts from %s at t = %.2f s", v->part_from[p],
		         t_part);
		lines[n_lines++] = l_part;
	}
	cairo_select_font_face(cr, "monospace", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
	text_box(cr, vw.x0 + 6.0, vw.y0 + vw.h - 6.0, lines, n_lines, 0, 1, fs);
	cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
	draw_legend(cr, v, &vw, fs);
	/* The title bar: label on the left, time on the right, and between
	 * them the outcome once it is decided (in the view's top left corner
	 * if the bar is too narrow for it). */
	char outcome[128] = "";
	if (sm.step >= res->steps)
		outcome_text(s, res, outcome, sizeof outcome);
	snprintf(buf, sizeof buf, "t = %.3f s%s", sm.t, k >= pn->frames ? " (ended)" : "");
	const char *label = v->labels[p] ? v->labels[p] : "";
	cairo_text_extents_t e_label, e_time, e_out;
	cairo_text_extents(cr, buf, &e_time);
	cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_BOLD);
	cairo_text_extents(cr, label, &e_label);
	cairo_text_extents(cr, outcome, &e_out);
	const double gap = 1.5 * fs;
	const int in_bar =
	        e_label.x_advance + e_out.x_advance + e_time.x_advance + 2.0 * gap + fs <= pw;
	if (outcome[0] && !in_bar) {
		const char *one[1] = {outcome};
		text_box(cr, vw.x0 + 6.0, vw.y0 + 6.0, one, 1, 0, 0, fs);
	}
	cairo_restore(cr);

	cairo_rectangle(cr, px0, 0.0, pw, title_h);
	set_color(cr, COLOR_TITLE);
	cairo_fill(cr);
	set_color(cr, COLOR_TEXT);
	cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_BOLD);
	cairo_move_to(cr, px0 + 0.5 * fs, 1.4 * fs);
	cairo_show_text(cr, label);
	if (outcome[0] && in_bar) {
		double x = px0 + 0.5 * fs + e_label.x_advance + gap;
		double room = pw - fs - e_label.x_advance - e_time.x_advance - 2.0 * gap;
		cairo_move_to(cr, x + 0.5 * (room - e_out.x_advance), 1.4 * fs);
		cairo_show_text(cr, outcome);
	}
	cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
	cairo_move_to(cr, px0 + pw - e_time.x_advance - 0.5 * fs, 1.4 * fs);
	cairo_show_text(cr, buf);
	/* A rule between panels. */
	if (p > 0) {
		cairo_rectangle(cr, px0, 0.0, 1.0, v->height);
		set_color(cr, COLOR_PIVOT);
		cairo_fill(cr);
	}
	cairo_restore(cr);
}

int bsim_video_render_frame(bsim_video *v, long k, bsim_error *err)
{
	if (!v->surface) {
		cairo_surface_t *sf =
		        cairo_image_surface_create(CAIRO_FORMAT_RGB24, v->width, v->height);
		if (cairo_surface_status(sf) != CAIRO_STATUS_SUCCESS) {
			cairo_status_t st = cairo_surface_status(sf);
			cairo_surface_destroy(sf);
			return bsim_error_set(err, BSIM_EFAIL, "cairo: %d x %d frame: %s", v->width,
			                      v->height, cairo_status_to_string(st));
		}
		v->surface = sf;
		v->cr = cairo_create(sf);
	}
	cairo_t *cr = v->cr;
	const double fs = font_size(v);
	cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
	cairo_set_font_size(cr, fs);
	for (int p = 0; p < v->n_panels; p++)
		draw_panel(cr, v, p, k, fs);
	cairo_surface_flush(v->surface);
	cairo_status_t st = cairo_status(cr);
	if (st != CAIRO_STATUS_SUCCESS)
		return bsim_error_set(err, BSIM_EFAIL, "cairo: frame %ld: %s", k,
		                      cairo_status_to_string(st));
	return BSIM_OK;
}
