/* Internal: what the video's files share (beamsim/video.h is the API). */
#ifndef BSIM_VIDEO_VIDEO_INTERNAL_H
#define BSIM_VIDEO_VIDEO_INTERNAL_H

#include "beamsim/effects.h"
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

/* One entry of the runner's gate path: gate (ix, iy) entered at the end
 * of step `step` (bsim_gate_entry). */
typedef struct video_gate_visit {
	int ix, iy;
	int step;
} video_gate_visit;

/* The body's path as one view draws it: its centre at step 0 and then at
 * every step more than 0.75 px from the last point kept along x or y, at
 * that view's scale,
 *   keep x_n  iff  s |x_n - x_kept| >= 0.75 or s |y_n - y_kept| >= 0.75,
 * up to the first step whose centre is not finite. The view then draws the
 * kept points before the frame's step and the centre at that step, which is
 * the polyline of every step's centre thinned at the same rule when drawn
 * (0.75 px: a long trial has many steps a pixel). The points are at most
 * one a step and one per 0.75 px the body travels, so a trail grows with
 * the distance travelled in pixels, not with the steps. */
typedef struct video_trail_point {
	double x[2]; /* m */
	long step;
} video_trail_point;

typedef struct video_trail {
	double scale; /* px/m of the view it is drawn in */
	video_trail_point *p;
	long n, cap;
	long broken; /* the first step whose centre is not finite; -1 none */
} video_trail;

/* Adds the centre after step `step` (steps in order, from 0). 0, or -1 if
 * memory runs out. */
int bsim_video_trail_add(video_trail *t, long step, const double x[2]);
void bsim_video_trail_free(video_trail *t);

/* The body centre after step n and its step, kept by a streamed panel for
 * a step a later frame draws up to (another panel's last step). */
typedef struct video_mark {
	long step;
	double x[2];
} video_mark;

/* A panel: what its frames show of its trial. A recorded track answers
 * for any frame (track set); a streamed panel (video_stream.c) holds only
 * the frame being drawn (now) and the centres it marked. */
typedef struct video_panel {
	const bsim_video_track *track;   /* NULL: streamed */
	const bsim_trial_result *result; /* the trial's outcome */
	long frames;                     /* the trial's frames, ceil(N h fps) + 1 */
	long last_step;                  /* N, the trial's last step */
	const video_gate_visit *visits;
	int n_visits;
	int random_axis;
	bsim_video_sample now; /* streamed: the frame being drawn */
	video_mark marks[BSIM_VIDEO_PANELS_MAX];
	int n_marks;
	/* The trail in each panel's view (trail[j] for panel j, ghost or own)
	 * and in the own overview (trail[n_panels]); the same scale shares a
	 * list: trail[j] points into own[]. */
	video_trail *trail[BSIM_VIDEO_PANELS_MAX + 1];
	video_trail own[BSIM_VIDEO_PANELS_MAX + 1];
	int n_own;
	double part_x[2]; /* m, the centre where the path parts from the other's */
} video_panel;

struct bsim_video {
	bsim_video_def def;
	int width, height;
	int n_panels;
	const bsim_scene *scene;
	video_panel panels[BSIM_VIDEO_PANELS_MAX];
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

/* A video of n_panels panels of scene (labels borrowed), every panel's
 * result, frames, last step, visits and random axis already set; makes the
 * rest: frame count, field, colour scale, the trails' lists at the views'
 * scales (empty). t_part and part_x are the caller's. */
int bsim_video_setup(bsim_video *v, const bsim_video_def *def, const bsim_scene *scene,
                     const char *const *labels, int n_panels, bsim_error *err);
/* Frees what bsim_video_setup made and v itself. */
void bsim_video_teardown(bsim_video *v);

/* Adds the centre after step `step` of panel p to each of its trails;
 * -1 if memory runs out. */
int bsim_video_panel_trail_add(bsim_video *v, int p, long step, const double x[2]);

/* The gate path of a track, in order (n = 0: none). */
const video_gate_visit *bsim_video_track_visits(const bsim_video_track *t, int *n);

/* The body centre after every step of a track: 2 n doubles. */
const double *bsim_video_track_trail(const bsim_video_track *t, long *n);
/* The body axis the random force acts along (0 = x). */
int bsim_video_track_random_axis(const bsim_video_track *t);

/* The state a frame keeps besides the beams' angles and contacts. */
typedef struct video_frame {
	long step;
	double x[2];
	double f_rand, e_kin, e_spring, e_prop;
} video_frame;

/* The step frame k shows, before the trial's end: floor(k / (fps h)). */
long bsim_video_frame_step(double fps, double dt, long k);
/* The frames of a trial whose last step is n_last: ceil(n_last h fps) + 1. */
long bsim_video_frame_count(double fps, double dt, long n_last);
/* The frame of the state s after step `step`: its energies (as
 * video_track.c says), its beams' angles (float) and contacts, and the
 * random force fx applies over the next step. */
void bsim_video_frame_take(const bsim_scene *sc, bsim_effects *fx, long step, const bsim_state *s,
                           video_frame *f, float *theta, unsigned char *contact);

/* Pass 1 of a stream (video_stream.c): runs the trial as
 * bsim_video_track_record does but keeps only its result, its frame count
 * and its gate path; its effect pipeline (bsim_video_track_effects) is the
 * one a second run of the trial takes its frames' forces from. */
int bsim_video_track_summary(const bsim_scene *scene, const bsim_backend *backend,
                             const bsim_options *opts, uint64_t seed, double fps,
                             bsim_video_track **out, bsim_error *err);
bsim_effects *bsim_video_track_effects(bsim_video_track *t);

/* The field's bounding box: every beam's reach (pivot +- length), the
 * body at its start, the side boundaries and the success and
 * classification lines, with half a body radius around. */
void bsim_video_field_bounds(const bsim_scene *s, double field[4]);

/* The view of panel rectangle (x0, y0, w, h) on the field: the whole
 * field if it fits with the shorter side spanning at most view_span
 * metres, else that scale with the camera on the body (radius r), kept
 * inside the field along each axis where the field is larger than the
 * view, and always keeping the whole body in view. */
void bsim_video_view_make(const double field[4], double view_span, double x0, double y0, double w,
                          double h, const double body[2], double r, video_view *out);

/* The overview of a panel whose camera follows the body (the field is
 * larger than the view): the whole field at a small scale in the view's
 * bottom-right corner. 0 if the view shows the whole field (no overview). */
int bsim_video_overview_make(const double field[4], const video_view *main, video_view *out);

/* The view of panel p at frame k: its camera on the body of that frame. */
void bsim_video_panel_view(const bsim_video *v, int p, long k, video_view *out);
/* The scale of panel p's view and, if it has one (returns 1), of its
 * overview, px/m: the same in every frame (only the camera moves). */
int bsim_video_panel_scales(const bsim_video *v, int p, double *s_main, double *s_over);

static inline void video_view_pixel(const video_view *v, const double p[2], double px[2])
{
	px[0] = v->x0 + 0.5 * v->w + v->scale * (p[0] - v->c[0]);
	px[1] = v->y0 + 0.5 * v->h - v->scale * (p[1] - v->c[1]);
}

/* What panel p shows at frame k: its track's frame k, or a streamed
 * panel's frame being drawn. */
static inline bsim_video_sample video_panel_sample(const bsim_video *v, int p, long k)
{
	const video_panel *pn = &v->panels[p];
	return pn->track ? bsim_video_track_sample(pn->track, k) : pn->now;
}

/* Draws frame k into v's cairo surface (made on first use). */
int bsim_video_render_frame(bsim_video *v, long k, bsim_error *err);

/* The stiffness colour scale, 0x00RRGGBB: u in [0, 1], 0 the softest. */
uint32_t bsim_video_colormap(double u);

/* 0 if the file at path is a whole MP4 (video_mp4.c): its boxes tile it
 * exactly and ftyp (first), moov and mdat are among them; else -1 with why
 * (of size n) saying what is wrong ("its box 'mdat' at byte 48 claims ...",
 * "... has no moov box"). */
int bsim_video_mp4_whole(const char *path, char *why, size_t n);

/* BSIM_OK for a scene the video can draw (a disk), else BSIM_EINPUT with
 * err naming body.shape (video.c). */
int bsim_video_scene_check(const bsim_scene *scene, bsim_error *err);

#endif
