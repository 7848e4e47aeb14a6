/* A video of one trial: panels, frame count, the stiffness scale, and the
 * loop that renders every frame and feeds it to the encoder pipe
 * (beamsim/video.h). Frame k of a track is its state at time k / fps
 * (video_track.c); after a track's last frame its panel shows that frame,
 * and after the longest track's last frame the video holds it for `hold`
 * seconds. */
#include "beamsim/video.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <cairo.h>

#include "video/video_internal.h"

bsim_video_def bsim_video_def_default(void)
{
	bsim_video_def d = {
	        .width = 0,
	        .height = 0,
	        .fps = 30.0,
	        .hold = 1.0,
	        .view_span = 200.0,
	        .crf = 23,
	        .ffmpeg = "ffmpeg",
	};
	return d;
}

int bsim_video_def_check(const bsim_video_def *d, bsim_error *err)
{
	if (!(d->fps >= 0.01) || d->fps > 1000.0)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "fps: expected 0.01 to 1000 frames per second, got %g",
		                      d->fps);
	if (!(d->hold >= 0.0) || d->hold > 60.0)
		return bsim_error_set(err, BSIM_EINPUT, "hold: expected 0 to 60 s, got %g",
		                      d->hold);
	if (!(d->view_span > 0.0) || !isfinite(d->view_span))
		return bsim_error_set(err, BSIM_EINPUT,
		                      "view_span: expected a positive number of metres, got %g",
		                      d->view_span);
	if (d->crf < 0 || d->crf > 51)
		return bsim_error_set(err, BSIM_EINPUT, "crf: expected 0 to 51, got %d", d->crf);
	if (d->width == 0 && d->height == 0)
		return BSIM_OK;
	if (d->width < 64 || d->height < 64 || d->width > 7680 || d->height > 4320 ||
	    d->width % 2 || d->height % 2)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "size %dx%d: expected even width and height, 64x64 to "
		                      "7680x4320 (H.264 in yuv420p halves the colour planes)",
		                      d->width, d->height);
	return BSIM_OK;
}

/* The list of panel p's trails at scale s, shared by the views of that
 * scale; NULL if memory runs out. */
static video_trail *trail_at(video_panel *pn, double s)
{
	for (int i = 0; i < pn->n_own; i++)
		if (pn->own[i].scale == s)
			return &pn->own[i];
	video_trail *t = &pn->own[pn->n_own++];
	*t = (video_trail){.scale = s, .broken = -1};
	return t;
}

int bsim_video_setup(bsim_video *v, const bsim_video_def *def, const bsim_scene *scene,
                     const char *const *labels, int n_panels, bsim_error *err)
{
	int rc = bsim_video_def_check(def, err);
	if (rc != BSIM_OK)
		return rc;
	if (n_panels < 1 || n_panels > BSIM_VIDEO_PANELS_MAX)
		return bsim_error_set(err, BSIM_EINPUT, "a video has 1 to %d panels, not %d",
		                      BSIM_VIDEO_PANELS_MAX, n_panels);
	const int width = def->width ? def->width : 540 * n_panels;
	const int height = def->height ? def->height : 540;
	if (width / n_panels < 32)
		return bsim_error_set(err, BSIM_EINPUT, "size %dx%d: too narrow for %d panels",
		                      width, height, n_panels);
	v->def = *def;
	if (!v->def.ffmpeg)
		v->def.ffmpeg = "ffmpeg";
	v->width = width;
	v->height = height;
	v->n_panels = n_panels;
	v->scene = scene;
	for (int p = 0; p < n_panels; p++) {
		v->labels[p] = labels ? labels[p] : NULL;
		if (v->panels[p].frames > v->frames_sim)
			v->frames_sim = v->panels[p].frames;
		v->t_part[p] = -1.0;
		if (n_panels > 1) {
			int q = p == 0 ? 1 : 0;
			v->part_from[p] = labels && labels[q] ? labels[q] : "the other";
		}
	}
	v->frames = v->frames_sim + lround(v->def.hold * v->def.fps);
	if (scene->has_lattice) {
		v->entered = calloc((size_t)(scene->lattice.columns * scene->lattice.rows), 1);
		if (!v->entered)
			return bsim_error_set(err, BSIM_EFAIL, "out of memory for a video");
	}
	bsim_video_field_bounds(scene, v->field);
	v->k_min = scene->n_beams ? scene->beams[0].stiffness : 0.0;
	v->k_max = v->k_min;
	for (int i = 1; i < scene->n_beams; i++) {
		v->k_min = fmin(v->k_min, scene->beams[i].stiffness);
		v->k_max = fmax(v->k_max, scene->beams[i].stiffness);
	}
	/* Each panel's trail is drawn in every panel's view (its own or as a
	 * ghost) and in its own overview: one list a scale. */
	double s_main[BSIM_VIDEO_PANELS_MAX], s_over[BSIM_VIDEO_PANELS_MAX];
	int over[BSIM_VIDEO_PANELS_MAX];
	for (int p = 0; p < n_panels; p++)
		over[p] = bsim_video_panel_scales(v, p, &s_main[p], &s_over[p]);
	for (int q = 0; q < n_panels; q++) {
		video_panel *pn = &v->panels[q];
		for (int j = 0; j < n_panels; j++)
			pn->trail[j] = trail_at(pn, s_main[j]);
		pn->trail[n_panels] = over[q] ? trail_at(pn, s_over[q]) : NULL;
	}
	return BSIM_OK;
}

int bsim_video_panel_trail_add(bsim_video *v, int p, long step, const double x[2])
{
	video_panel *pn = &v->panels[p];
	for (int i = 0; i < pn->n_own; i++)
		if (bsim_video_trail_add(&pn->own[i], step, x))
			return -1;
	return 0;
}

void bsim_video_teardown(bsim_video *v)
{
	if (!v)
		return;
	if (v->cr)
		cairo_destroy(v->cr);
	if (v->surface)
		cairo_surface_destroy(v->surface);
	for (int p = 0; p < v->n_panels; p++)
		for (int i = 0; i < v->panels[p].n_own; i++)
			bsim_video_trail_free(&v->panels[p].own[i]);
	free(v->entered);
	free(v);
}

int bsim_video_scene_check(const bsim_scene *scene, bsim_error *err)
{
	if (scene->body.shape == BSIM_SHAPE_DISK)
		return BSIM_OK;
	return bsim_error_set(err, BSIM_EINPUT,
	                      "%s: body.shape: expected disk (the video draws the body as a disk), "
	                      "got %s",
	                      scene->path[0] ? scene->path : scene->name,
	                      scene->body.shape == BSIM_SHAPE_CAPSULE ? "capsule" : "ellipse");
}

int bsim_video_alloc(const bsim_video_def *def, const bsim_scene *scene,
                     const bsim_video_track *const *tracks, const char *const *labels, int n_panels,
                     bsim_video **out, bsim_error *err)
{
	*out = NULL;
	if (bsim_video_scene_check(scene, err) != BSIM_OK)
		return BSIM_EINPUT;
	bsim_video *v = calloc(1, sizeof *v);
	if (!v)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory for a video");
	for (int p = 0; p < n_panels && p < BSIM_VIDEO_PANELS_MAX; p++) {
		video_panel *pn = &v->panels[p];
		const bsim_video_track *t = tracks[p];
		long n;
		pn->track = t;
		pn->result = bsim_video_track_result(t);
		pn->frames = bsim_video_track_frames(t);
		bsim_video_track_trail(t, &n);
		pn->last_step = n - 1;
		pn->visits = bsim_video_track_visits(t, &pn->n_visits);
		pn->random_axis = bsim_video_track_random_axis(t);
	}
	int rc = bsim_video_setup(v, def, scene, labels, n_panels, err);
	if (rc != BSIM_OK) {
		bsim_video_teardown(v);
		return rc;
	}
	/* Side by side, each panel parts from the first; the first from the
	 * second. 1% of the body radius, as beamsim compare measures it. */
	const double sep = 0.01 * scene->body.radius;
	for (int p = 0; p < n_panels && n_panels > 1; p++) {
		int q = p == 0 ? 1 : 0;
		v->t_part[p] = bsim_video_track_separation(tracks[p], tracks[q], sep);
		if (v->t_part[p] >= 0.0)
			bsim_video_track_position(tracks[p], lround(v->t_part[p] / scene->dt),
			                          v->panels[p].part_x);
	}
	/* The trails, thinned as a stream thins them. */
	for (int p = 0; p < n_panels; p++) {
		long n;
		const double *xy = bsim_video_track_trail(tracks[p], &n);
		for (long i = 0; i < n; i++)
			if (bsim_video_panel_trail_add(v, p, i, xy + 2 * i)) {
				bsim_video_teardown(v);
				return bsim_error_set(err, BSIM_EFAIL, "out of memory for a video");
			}
	}
	*out = v;
	return BSIM_OK;
}

void bsim_video_free(bsim_video *v)
{
	bsim_video_teardown(v);
}

long bsim_video_frames(const bsim_video *v)
{
	return v->frames;
}

void bsim_video_size(const bsim_video *v, int *width, int *height)
{
	*width = v->width;
	*height = v->height;
}

int bsim_video_render(bsim_video *v, long k, uint32_t *pixels, bsim_error *err)
{
	if (k < 0 || k >= v->frames)
		return bsim_error_set(err, BSIM_EINPUT, "frame %ld: the video has frames 0 to %ld",
		                      k, v->frames - 1);
	/* The hold repeats the last simulated frame. */
	int rc = bsim_video_render_frame(v, k < v->frames_sim ? k : v->frames_sim - 1, err);
	if (rc != BSIM_OK)
		return rc;
	cairo_surface_t *sf = v->surface;
	const unsigned char *data = cairo_image_surface_get_data(sf);
	const int stride = cairo_image_surface_get_stride(sf);
	for (int y = 0; y < v->height; y++) {
		const uint32_t *row = (const uint32_t *)(const void *)(data + (size_t)y * stride);
		uint32_t *dst = pixels + (size_t)y * (size_t)v->width;
		for (int x = 0; x < v->width; x++)
			dst[x] = row[x] & 0xFFFFFFu;
	}
	return BSIM_OK;
}

int bsim_video_write(bsim_video *v, const char *path, bsim_error *err)
{
	uint32_t *pixels = malloc((size_t)v->width * (size_t)v->height * sizeof *pixels);
	if (!pixels)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory for a %d x %d frame",
		                      v->width, v->height);
	bsim_video_encoder *enc = NULL;
	int rc = bsim_video_encoder_open(path, v->def.ffmpeg, v->width, v->height, v->def.fps,
	                                 v->def.crf, &enc, err);
	for (long k = 0; rc == BSIM_OK && k < v->frames; k++) {
		if (v->def.stop && *v->def.stop)
			break;
		/* Held frames are the same picture: draw it once. */
		if (k <= v->frames_sim)
			rc = bsim_video_render(v, k, pixels, err);
		if (rc == BSIM_OK)
			rc = bsim_video_encoder_write(enc, pixels, err);
	}
	/* A signal also reaches ffmpeg when it comes from the terminal, so a
	 * frame that could not be written then is the stop, not a failure. */
	if (enc && v->def.stop && *v->def.stop)
		rc = bsim_error_set(err, BSIM_ESTOPPED, "%s: stopped; no video written", path);
	if (rc == BSIM_OK) {
		rc = bsim_video_encoder_close(enc, err);
	} else {
		bsim_video_encoder_abort(enc);
	}
	free(pixels);
	return rc;
}
