/* Videos of trials: one trial of a scene drawn frame by frame with cairo and
 * encoded as H.264 MP4 by ffmpeg, one panel per backend, side by side.
 *
 * Two ways to make one. A stream runs the trials and draws each frame as
 * they reach it: what it holds does not grow with the steps (beamsim video
 * uses it):
 *
 *   bsim_video_def def = bsim_video_def_default();
 *   bsim_video_stream *s;
 *   bsim_video_stream_alloc(&def, scene, &backend, NULL, &label, 1, seed, &s, err);
 *   bsim_video_stream_write(s, "trial.mp4", &report, err);          // whole or nothing
 *   bsim_video_stream_free(s);
 *
 * Or record the trials first, for any frame in any order (stills, tests),
 * holding every step's centre and every frame's beams:
 *
 *   bsim_video_track *t;
 *   bsim_video_track_record(scene, backend, opts, seed, fps, &t, err);  // runs the trial
 *   bsim_video_def def = bsim_video_def_default();
 *   bsim_video *v = NULL;
 *   bsim_video_alloc(&def, scene, &t, &label, 1, &v, err);
 *   bsim_video_write(v, "trial.mp4", err);                            // whole or nothing
 *
 * Time. Frame k shows the simulated time k / fps: the state after step
 * n_k = min(floor(k / (fps h)), N), the last step at or before that time,
 * where N is the trial's last step (the runner's steps_run, including the
 * run on to classify_y after a traversal). A trial has ceil(N h fps) + 1
 * frames, the last one its end state; side by side, the video lasts
 * as long as the longest trial, a panel whose trial has ended shows its
 * last state, and the last frame is held for `hold` seconds at the end.
 *
 * A frame (one panel per track, left to right) shows the beams coloured by
 * stiffness with the colour scale as a legend, the pivots, the success line
 * and side boundaries, the body and its trail, the random force as an arrow
 * from the body centre (length R |F| / Rm: one body radius per Rm), and
 * overlaid: the backend, the time, the kinetic energy of body and beams,
 * the springs' energy, the propulsive potential F_prop (y0 - y) (docs/model.md
 * section 7), the random force, and the outcome from the moment it is
 * decided. Side by side, each panel also shows the other panels' trails in
 * grey and marks where the body trajectories part (first more than 1% of
 * the body radius apart, as beamsim compare measures it).
 *
 * Camera. A panel shows the whole field (beams, start, success line, side
 * boundaries) when that fits with its shorter side spanning at most
 * view_span metres; a larger field (a lattice of gates) is shown at that
 * scale with the camera on the body, kept inside the field where the field
 * is larger than the view (the essay's MAT2AVI over the lattice), with an
 * overview of the whole field in the bottom-right corner: the trail, the
 * body, the part of the field in view, and for a lattice its gates by
 * stiffness with the gates the body has entered so far (the runner's gate
 * path) filled in the path colour. A lattice's view also shows the gate
 * boundaries, tints the gates entered, names the gate the body is in, and
 * states the outcome as the final location (end, side, stuck gate). */
#ifndef BSIM_VIDEO_H
#define BSIM_VIDEO_H

#include <signal.h>
#include <stdint.h>

#include "beamsim/base.h"
#include "beamsim/backend.h"
#include "beamsim/error.h"
#include "beamsim/scene.h"
#include "beamsim/trial.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The look and encoding of a video (plain definition; start from
 * bsim_video_def_default). */
typedef struct bsim_video_def {
	int width, height;  /* pixels of a frame, all panels; even, >= 64; 0 = 540 x 540 a panel */
	double fps;         /* frames per second of simulated time, 0.01 to 1000; default 30 */
	double hold;        /* s: the last frame is held this long at the end, >= 0; default 1 */
	double view_span;   /* m: the most of the world a panel's shorter side shows; default 200 */
	int crf;            /* x264 constant rate factor, 0-51 (lower is better); default 23 */
	const char *ffmpeg; /* the encoder program, looked up on PATH; default "ffmpeg" */
	/* May be NULL. When *stop becomes nonzero (a signal handler sets it),
	 * bsim_video_write draws no further frame, removes its temporary file
	 * and returns BSIM_ESTOPPED. */
	const volatile sig_atomic_t *stop;
} bsim_video_def;

BSIM_API bsim_video_def bsim_video_def_default(void);

/* Checks a definition's ranges; BSIM_EINPUT naming the field otherwise. */
BSIM_API int bsim_video_def_check(const bsim_video_def *def, bsim_error *err);

/* What a frame of a track shows: the state after step `step`. */
typedef struct bsim_video_sample {
	long step;
	double t;           /* s, step * dt */
	double x[2];        /* body centre, m */
	double f_rand;      /* N, the random force the runner applies over the next step */
	double e_kin;       /* J, body and beams */
	double e_spring;    /* J, 1/2 k theta^2 summed over beams */
	double e_prop;      /* J, F_prop (y0 - y) */
	const float *theta; /* n_beams, rad */
	const unsigned char *contact; /* n_beams, BSIM_CONTACT_* */
} bsim_video_sample;

/* One trial recorded for a video: the body centre after every step (the
 * trail) and the state at every frame time. */
typedef struct bsim_video_track bsim_video_track;

/* Runs trial `seed` (bsim_schedule_seed_mix) of scene on backend exactly as
 * bsim_trial_run does for `beamsim run`, recording at fps frames per second
 * of simulated time. The scene must outlive the track. BSIM_EFAIL if the
 * run fails (the message says why, e.g. a non-finite state) or memory runs
 * out; BSIM_EINPUT for bad backend options or fps. */
BSIM_API int bsim_video_track_record(const bsim_scene *scene, const bsim_backend *backend,
                                     const bsim_options *opts, uint64_t seed, double fps,
                                     bsim_video_track **out, bsim_error *err);
BSIM_API void bsim_video_track_free(bsim_video_track *t);

/* The trial's result, as bsim_trial_run gives it. */
BSIM_API const bsim_trial_result *bsim_video_track_result(const bsim_video_track *t);
/* Frames recorded: ceil(steps_run dt fps) + 1. */
BSIM_API long bsim_video_track_frames(const bsim_video_track *t);
/* Frame k (0 <= k < frames); later k give the last frame. */
BSIM_API bsim_video_sample bsim_video_track_sample(const bsim_video_track *t, long k);
/* The body centre after step n (0 <= n <= steps_run), m. */
BSIM_API void bsim_video_track_position(const bsim_video_track *t, long n, double x[2]);

/* The time, s, at which the body centres of two tracks of the same scene
 * are first more than sep_distance (m) apart, comparing steps both reached;
 * -1 if they never are. */
BSIM_API double bsim_video_track_separation(const bsim_video_track *a, const bsim_video_track *b,
                                            double sep_distance);

/* A video of one to BSIM_VIDEO_PANELS_MAX tracks of the same scene. */
#define BSIM_VIDEO_PANELS_MAX 4
typedef struct bsim_video bsim_video;

/* tracks and labels (one a panel, e.g. the backend names) are borrowed
 * and must outlive v, as must scene. */
BSIM_API int bsim_video_alloc(const bsim_video_def *def, const bsim_scene *scene,
                              const bsim_video_track *const *tracks, const char *const *labels,
                              int n_panels, bsim_video **out, bsim_error *err);
BSIM_API void bsim_video_free(bsim_video *v);

/* Frames of the video, hold included. */
BSIM_API long bsim_video_frames(const bsim_video *v);
/* Pixels of a frame (the def's, or the default for the panel count). */
BSIM_API void bsim_video_size(const bsim_video *v, int *width, int *height);

/* Draws frame k into pixels: width x height values 0x00RRGGBB, row-major
 * from the top-left (cairo's RGB24). BSIM_EFAIL if cairo fails. */
BSIM_API int bsim_video_render(bsim_video *v, long k, uint32_t *pixels, bsim_error *err);

/* The stiffness colour of the legend: 0x00RRGGBB for stiffness k, N m/rad,
 * on this video's scale (the scene's smallest to largest stiffness). */
BSIM_API uint32_t bsim_video_stiffness_color(const bsim_video *v, double k);

/* The colour the body is filled with, 0x00RRGGBB (nothing else is drawn
 * in it, so a frame's body can be found by its colour). */
BSIM_API uint32_t bsim_video_body_color(void);

/* The colour of the gates the body has entered in a lattice's overview,
 * 0x00RRGGBB (nothing else is drawn in it). */
BSIM_API uint32_t bsim_video_path_color(void);

/* Where world point p (m) lies in the overview of panel `panel` at frame k,
 * pixels from the frame's top-left: 1 and px if that frame shows an
 * overview (its camera follows the body over a field larger than the
 * view), else 0. */
BSIM_API int bsim_video_overview_pixel(const bsim_video *v, int panel, long k, const double p[2],
                                       double px[2]);

/* Renders every frame and encodes them with ffmpeg into path: H.264,
 * yuv420p, fps frames per second. The file appears whole or not at all
 * (written under a temporary name, renamed when ffmpeg succeeded, removed
 * when it failed). BSIM_EFAIL naming ffmpeg's package if it is missing;
 * "PATH: encoding the video: " and ffmpeg's exit status and first message
 * if it fails, which it also does by writing a message at status 0 or
 * leaving a file that is not a whole MP4; or the path if it cannot be
 * written. */
BSIM_API int bsim_video_write(bsim_video *v, const char *path, bsim_error *err);

/* What bsim_video_stream_write made. */
typedef struct bsim_video_report {
	bsim_trial_result results[BSIM_VIDEO_PANELS_MAX]; /* each panel's trial, as
	                                                   * bsim_trial_run gives it */
	double t_part; /* s, when the first two panels' body centres are first more than
	                * 1% of the body radius apart; -1 never, or one panel */
	long frames;   /* frames written, the hold included */
	int width, height;
	/* What it held, which does not grow with the steps (docs/video.md,
	 * "Memory"): */
	long trail_points; /* the trails' points at the end, every panel and view scale:
	                    * at most one per 0.75 px travelled in each */
	long steps_held;   /* the most steps' centres a panel handed over with one frame:
	                    * at most 1 / (fps h) + 1 */
} bsim_video_report;

/* A video made as its trials run: nothing it holds grows with the steps. */
typedef struct bsim_video_stream bsim_video_stream;

/* The video of trial `seed` (bsim_schedule_seed_mix) of scene on each of
 * n_panels backends (opts[p] their options, or opts NULL; labels one a
 * panel or NULL; all borrowed, as is scene, until the stream is freed):
 * the frames bsim_video_write writes for the tracks bsim_video_track_record
 * would record. Runs each trial once, for its end, outcome and gate path
 * (what a frame must know before the trial gets there). Fails as
 * bsim_video_def_check and bsim_video_track_record do. */
BSIM_API int bsim_video_stream_alloc(const bsim_video_def *def, const bsim_scene *scene,
                                     const bsim_backend *const *backends,
                                     const bsim_options *const *opts, const char *const *labels,
                                     int n_panels, uint64_t seed, bsim_video_stream **out,
                                     bsim_error *err);
BSIM_API void bsim_video_stream_free(bsim_video_stream *s);

/* Panel p's trial as bsim_trial_run gives it; NULL for no such panel. */
BSIM_API const bsim_trial_result *bsim_video_stream_result(const bsim_video_stream *s, int panel);

/* Runs the trials again, a thread a panel, drawing and encoding each frame
 * as they reach it, and writes the video to path, whole or not at all, as
 * bsim_video_write does (def.stop included: the trials then run on to
 * their end without drawing before it returns). Once a stream; the report
 * (may be NULL) is filled when it returns BSIM_OK. Fails as
 * bsim_video_write does, and with BSIM_EFAIL if a trial's second run does
 * not end as its first. */
BSIM_API int bsim_video_stream_write(bsim_video_stream *s, const char *path,
                                     bsim_video_report *report, bsim_error *err);

/* The ffmpeg pipe: raw frames in, an MP4 file out. */
typedef struct bsim_video_encoder bsim_video_encoder;

/* Starts `program` (ffmpeg; looked up on PATH, no shell) reading width x
 * height RGB24 frames (0x00RRGGBB values) at fps from a pipe and writing
 * H.264 (libx264, yuv420p, crf) in MP4 to a temporary file beside path.
 * BSIM_EFAIL if the program is missing (naming the Debian package ffmpeg)
 * or cannot be started. */
BSIM_API int bsim_video_encoder_open(const char *path, const char *program, int width, int height,
                                     double fps, int crf, bsim_video_encoder **out,
                                     bsim_error *err);
/* Writes one frame. BSIM_EFAIL if ffmpeg has stopped reading (the
 * message then gives its exit status and first message). */
BSIM_API int bsim_video_encoder_write(bsim_video_encoder *e, const uint32_t *pixels,
                                      bsim_error *err);
/* Ends the stream, waits for ffmpeg, and if it exited with status 0
 * without a message and the file is a whole MP4 (its boxes tile it, ftyp,
 * moov and mdat among them; not checked for what is not a regular file),
 * renames the file into place; else removes it and fails as
 * bsim_video_write does. Frees e either way. */
BSIM_API int bsim_video_encoder_close(bsim_video_encoder *e, bsim_error *err);
/* Stops ffmpeg and removes the temporary file; frees e. NULL is a no-op. */
BSIM_API void bsim_video_encoder_abort(bsim_video_encoder *e);

#ifdef __cplusplus
}
#endif
#endif
