/* Internal: what the video's files share (beamsim/video.h is the API). */
#ifndef BSIM_VIDEO_VIDEO_INTERNAL_H
#define BSIM_VIDEO_VIDEO_INTERNAL_H

#include "beamsim/video.h"

/* A panel's view of the world: the pixel rectangle it draws into and the
 * world point at its centre. World (x, y) goes to pixel
 *   px = x0 + w/2 + s (x - c_x),   py = y0 + h/2 - s (y - c_y)
 * (y up in the world, down on the screen). */
typedef struct video_view {
	double x0, y0, w, h; /* pixels */
	double scale;        /* s, pixels per metre */
	double c[2];         /* m */
} video_view;

struct bsim_video {
	bsim_video_def def;
	int width, height;
	int n_panels;
	const bsim_scene *scene;
	const bsim_video_track *tracks[BSIM_VIDEO_PANELS_MAX];
	const char *labels[BSIM_VIDEO_PANELS_MAX];
	double t_part[BSIM_VIDEO_PANELS_MAX]; /* s, when panel p parts from the other (or
	                                       * panel 0); -1 never, or one panel */
	const char *part_from[BSIM_VIDEO_PANELS_MAX];
	long frames;            /* hold included */
	long frames_sim;        /* the longest track's frames */
	double field[4];        /* x0, y0, x1, y1, m: what the camera keeps in view */
	double k_min, k_max;    /* N m/rad, the colour scale */
	unsigned char *entered; /* a lattice: columns x rows, the gates entered so far */
	void *surface, *cr;     /* cairo_surface_t, cairo_t: made on first render */
};

/* One entry of the runner's gate path: gate (ix, iy) entered at the end
 * of step `step` (bsim_gate_entry). */
typedef struct video_gate_visit {
	int ix, iy;
	int step;
} video_gate_visit;

/* The gate path of a track, in order (n = 0: none). */
const video_gate_visit *video_track_visits(const bsim_video_track *t, int *n);

/* The body centre after every step of a track: 2 n doubles. */
const double *video_track_trail(const bsim_video_track *t, long *n);
/* The body axis the random force acts along (0 = x). */
int video_track_random_axis(const bsim_video_track *t);

/* The field's bounding box: every beam's reach (pivot +- length), the
 * body at its start, the side boundaries and the success and
 * classification lines, with half a body radius around. */
void video_field_bounds(const bsim_scene *s, double field[4]);

/* The view of panel rectangle (x0, y0, w, h) on the field: the whole
 * field if it fits with the shorter side spanning at most view_span
 * metres, else that scale with the camera on the body (radius r), kept
 * inside the field along each axis where the field is larger than the
 * view, and always keeping the whole body in view. */
void video_view_make(const double field[4], double view_span, double x0, double y0, double w,
                     double h, const double body[2], double r, video_view *out);

/* The overview of a panel whose camera follows the body (the field is
 * larger than the view): the whole field at a small scale in the view's
 * bottom-right corner. 0 if the view shows the whole field (no overview). */
int video_overview_make(const double field[4], const video_view *main, video_view *out);

/* The view of panel p at frame k: its camera on the body of that frame. */
void video_panel_view(const bsim_video *v, int p, long k, video_view *out);

static inline void video_view_pixel(const video_view *v, const double p[2], double px[2])
{
	px[0] = v->x0 + 0.5 * v->w + v->scale * (p[0] - v->c[0]);
	px[1] = v->y0 + 0.5 * v->h - v->scale * (p[1] - v->c[1]);
}

/* Draws frame k into v's cairo surface (made on first use). */
int video_render_frame(bsim_video *v, long k, bsim_error *err);

/* The stiffness colour scale, 0x00RRGGBB: u in [0, 1], 0 the softest. */
uint32_t video_colormap(double u);

#endif
