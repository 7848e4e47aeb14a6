/* beamsim video: the file is a valid H.264 MP4 (ffprobe) with the frame
 * size, frame count and duration that the trial's length (from beamsim
 * run) and the frame rate give, on one backend and side by side; the video
 * shows the trial beamsim run runs (positions, energies and random force
 * equal the runner's trajectory at every frame time); on a field larger
 * than the view the body is in every frame although it travels further
 * than a view spans (the camera follows it), in the rendered frames and in
 * the decoded MP4; beams take their stiffness's colour; on a lattice the
 * overview fills exactly the gates of the runner's own gate path entered by
 * the frame's step, and a field that fits the view has no overview; a
 * failing or missing ffmpeg and bad arguments write nothing. A streamed
 * video (what beamsim video writes) has the very pixels of the recorded
 * one, frame for frame, and what it holds does not grow with the steps. */
#define _POSIX_C_SOURCE 200809L

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <dirent.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "beamsim/backend.h"
#include "beamsim/schedule.h"
#include "beamsim/trial.h"
#include "beamsim/video.h"
#include "support.h"

/* The gate scene's time step, s (configs/thesis/gate.yaml). */
#define GATE_DT 0.004

typedef struct probe {
	char codec[32], pix_fmt[32], format[128];
	int width, height;
	long frames;
	double duration;
} probe;

static void probe_value(const char *text, const char *key, char *buf, size_t n)
{
	char needle[64];
	snprintf(needle, sizeof needle, "\n%s=", key);
	const char *p = strstr(text, needle);
	if (!p)
		fail_msg("ffprobe gave no %s in:\n%s", key, text);
	p += strlen(needle);
	size_t len = strcspn(p, "\r\n");
	snprintf(buf, n, "%.*s", (int)len, p);
}

/* What ffprobe finds in the file's first video stream (decoding every
 * frame to count them). */
static void ffprobe(const char *path, probe *p)
{
	const char *argv[] = {"ffprobe",
	                      "-v",
	                      "error",
	                      "-count_frames",
	                      "-select_streams",
	                      "v:0",
	                      "-show_entries",
	                      "stream=codec_name,pix_fmt,width,height,nb_read_frames,duration:"
	                      "format=format_name",
	                      "-of",
	                      "default=nw=1",
	                      path,
	                      NULL};
	char *out = NULL;
	assert_int_equal(bsim_test_run(argv, &out), 0);
	char text[4096], v[128];
	snprintf(text, sizeof text, "\n%s", out);
	free(out);
	probe_value(text, "codec_name", p->codec, sizeof p->codec);
	probe_value(text, "pix_fmt", p->pix_fmt, sizeof p->pix_fmt);
	probe_value(text, "format_name", p->format, sizeof p->format);
	probe_value(text, "width", v, sizeof v);
	p->width = atoi(v);
	probe_value(text, "height", v, sizeof v);
	p->height = atoi(v);
	probe_value(text, "nb_read_frames", v, sizeof v);
	p->frames = atol(v);
	probe_value(text, "duration", v, sizeof v);
	p->duration = atof(v);
}

/* steps_run of `beamsim run SCENE ARGS... --json`. */
static long run_steps(const char *scene, const char *const *args)
{
	const char *argv[32] = {"run", scene, "--json"};
	int n = 3;
	for (int i = 0; args[i]; i++)
		argv[n++] = args[i];
	argv[n] = NULL;
	char *out = NULL;
	assert_int_equal(bsim_test_cli(argv, &out, NULL), 0);
	const char *p = strstr(out, "\"steps_run\": ");
	assert_non_null(p);
	long steps = atol(p + strlen("\"steps_run\": "));
	free(out);
	return steps;
}

/* Frames of a trial of `steps` steps of dt at fps, plus the hold:
 * ceil(steps dt fps) + 1 + round(hold fps), computed here in integers
 * (dt fps = num / den exactly). */
static long expected_frames(long steps, long num, long den, long hold_frames)
{
	return (steps * num + den - 1) / den + 1 + hold_frames;
}

/* 1 if dir holds no entry but . and .. */
static int dir_empty(const char *dir)
{
	DIR *d = opendir(dir);
	assert_non_null(d);
	struct dirent *e;
	int n = 0;
	while ((e = readdir(d)))
		if (strcmp(e->d_name, ".") && strcmp(e->d_name, ".."))
			n++;
	closedir(d);
	return n == 0;
}

static void cli_single_backend(void **state)
{
	(void)state;
	char gate[1200], out[1400];
	snprintf(gate, sizeof gate, "%s", bsim_test_src("configs/thesis/gate.yaml"));
	const char *dir = bsim_test_dir("single");
	snprintf(out, sizeof out, "%s/trial.mp4", dir);
	const char *same[] = {"--seed", "4", "--trial", "2", "--set", "integration.max_steps=500",
	                      NULL};
	long steps = run_steps(gate, same);
	const char *argv[] = {"video",   gate, "--seed", "4",
	                      "--trial", "2",  "--set",  "integration.max_steps=500",
	                      "--fps",   "25", "--hold", "0.4",
	                      "--out",   out,  NULL};
	char *so = NULL, *se = NULL;
	int rc = bsim_test_cli(argv, &so, &se);
	if (rc != 0)
		fail_msg("exit %d: %s", rc, se);
	probe p;
	ffprobe(out, &p);
	/* 25 fps at 4 ms: one frame every 10 steps; 0.4 s hold: 10 frames. */
	long frames = expected_frames(steps, 1, 10, 10);
	printf("# one backend: %ld steps, %ld frames (%s %s %dx%d, %.4f s)\n", steps, p.frames,
	       p.codec, p.pix_fmt, p.width, p.height, p.duration);
	assert_string_equal(p.codec, "h264");
	assert_string_equal(p.pix_fmt, "yuv420p");
	assert_non_null(strstr(p.format, "mp4"));
	assert_int_equal(p.width, 540); /* the default, a panel */
	assert_int_equal(p.height, 540);
	assert_int_equal(p.frames, frames);
	assert_true(fabs(p.duration - frames / 25.0) < 1e-3);
	/* Only the video is left in the directory: no temporary file. */
	DIR *d = opendir(dir);
	struct dirent *e;
	while ((e = readdir(d)))
		assert_true(e->d_name[0] == '.' || strcmp(e->d_name, "trial.mp4") == 0);
	closedir(d);
	free(so);
	free(se);
}

static void cli_side_by_side(void **state)
{
	(void)state;
	char gate[1200], out[1400];
	snprintf(gate, sizeof gate, "%s", bsim_test_src("configs/thesis/gate.yaml"));
	snprintf(out, sizeof out, "%s/pair.mp4", bsim_test_dir("pair"));
	/* A violent random force: both bodies leave through a side within
	 * 2 s, at different steps, so the video lasts as the longer trial. */
	const char *common[] = {"--trial", "1", "--set", "effects.random_force.magnitude=150",
	                        NULL};
	const char *thesis[] = {"--backend", "thesis",  common[0], common[1],
	                        common[2],   common[3], NULL};
	const char *box2d[] = {"--backend", "box2d",   common[0], common[1],
	                       common[2],   common[3], NULL};
	long s_thesis = run_steps(gate, thesis), s_box2d = run_steps(gate, box2d);
	long steps = s_thesis > s_box2d ? s_thesis : s_box2d;
	const char *argv[] = {"video",   gate,      "--backends", "thesis,box2d", common[0],
	                      common[1], common[2], common[3],    "--size",       "640x320",
	                      "--out",   out,       NULL};
	char *se = NULL;
	int rc = bsim_test_cli(argv, NULL, &se);
	if (rc != 0)
		fail_msg("exit %d: %s", rc, se);
	probe p;
	ffprobe(out, &p);
	/* 30 fps at 4 ms: 3 frames every 25 steps; 1 s hold: 30 frames. */
	long frames = expected_frames(steps, 3, 25, 30);
	printf("# side by side: %ld / %ld steps, %ld frames (%s %dx%d, %.4f s)\n", s_thesis,
	       s_box2d, p.frames, p.codec, p.width, p.height, p.duration);
	assert_string_equal(p.codec, "h264");
	assert_string_equal(p.pix_fmt, "yuv420p");
	assert_int_equal(p.width, 640);
	assert_int_equal(p.height, 320);
	assert_int_equal(p.frames, frames);
	assert_true(fabs(p.duration - frames / 30.0) < 1e-3);
	free(se);
}

/* The body's pixels in an RGB frame: those within tol of its colour in
 * every channel; their count and bounding box. */
typedef struct blob {
	long n;
	int x0, y0, x1, y1;
} blob;

static blob find_color(const unsigned char *rgb, int w, int h, int x_from, int x_to, uint32_t color,
                       int tol)
{
	blob b = {0, w, h, -1, -1};
	const int c[3] = {(int)(color >> 16) & 255, (int)(color >> 8) & 255, (int)color & 255};
	for (int y = 0; y < h; y++)
		for (int x = x_from; x < x_to; x++) {
			const unsigned char *p = rgb + 3 * ((size_t)y * w + x);
			if (abs(p[0] - c[0]) > tol || abs(p[1] - c[1]) > tol ||
			    abs(p[2] - c[2]) > tol)
				continue;
			b.n++;
			b.x0 = x < b.x0 ? x : b.x0;
			b.x1 = x > b.x1 ? x : b.x1;
			b.y0 = y < b.y0 ? y : b.y0;
			b.y1 = y > b.y1 ? y : b.y1;
		}
	return b;
}

static void to_rgb(const uint32_t *px, int n, unsigned char *rgb)
{
	for (int i = 0; i < n; i++) {
		rgb[3 * i] = (unsigned char)(px[i] >> 16);
		rgb[3 * i + 1] = (unsigned char)(px[i] >> 8);
		rgb[3 * i + 2] = (unsigned char)px[i];
	}
}

static void load(const char *rel, bsim_scene *s)
{
	bsim_error err;
	if (bsim_scene_load(bsim_test_src(rel), NULL, 0, s, &err) != BSIM_OK)
		fail_msg("%s", err.msg);
}

/* A 3 x 3 field of gates (200 x 240 m with its margins) in a 320 x 240
 * frame showing at most 40 m: the body must be whole in every frame while
 * it travels further than the view is high. */
static void lib_camera_follows_the_body(void **state)
{
	(void)state;
	bsim_scene scene;
	load("tests/data/field_3x3.yaml", &scene);
	bsim_error err;
	bsim_options opts = {0};
	bsim_video_track *t = NULL;
	assert_int_equal(bsim_video_track_record(&scene, bsim_test_backend("thesis"), &opts,
	                                         bsim_schedule_seed_mix(1, 0, 0), 30.0, &t, &err),
	                 BSIM_OK);
	bsim_video_def def = bsim_video_def_default();
	def.width = 320;
	def.height = 240;
	def.view_span = 40.0;
	def.hold = 0.0;
	bsim_video *v = NULL;
	const char *label = "thesis";
	assert_int_equal(bsim_video_alloc(&def, &scene, (const bsim_video_track *const *)&t, &label,
	                                  1, &v, &err),
	                 BSIM_OK);
	const int w = 320, h = 240;
	uint32_t *px = malloc(sizeof *px * w * h);
	unsigned char *rgb = malloc(3 * w * h);
	double y_min = 1e300, y_max = -1e300, d_min = 1e300, d_max = 0.0;
	long frames = bsim_video_frames(v);
	for (long k = 0; k < frames; k++) {
		assert_int_equal(bsim_video_render(v, k, px, &err), BSIM_OK);
		to_rgb(px, w * h, rgb);
		blob b = find_color(rgb, w, h, 0, w, bsim_video_body_color(), 0);
		bsim_video_sample s = bsim_video_track_sample(t, k);
		if (b.n == 0)
			fail_msg("frame %ld: no body (at %.1f, %.1f m)", k, s.x[0], s.x[1]);
		/* The whole disc, clear of the frame's edges. */
		double d = b.x1 - b.x0 + 1;
		if (b.x0 <= 0 || b.y0 <= 0 || b.x1 >= w - 1 || b.y1 >= h - 1 ||
		    b.n < 0.7 * 3.14159265358979 * d * d / 4)
			fail_msg("frame %ld: body cut at the frame's edge (%ld px, box %d..%d x "
			         "%d..%d)",
			         k, b.n, b.x0, b.x1, b.y0, b.y1);
		d_min = fmin(d_min, d);
		d_max = fmax(d_max, d);
		y_min = fmin(y_min, s.x[1]);
		y_max = fmax(y_max, s.x[1]);
	}
	/* Pixels a metre, from the body's diameter (radius 10 m). */
	double scale = d_min / 20.0;
	printf("# field: %ld frames, body %g-%g px across (%.2f px/m), travelled %.1f m "
	       "= %.0f px, frame %d px high, field %.0f px wide\n",
	       frames, d_min, d_max, scale, y_max - y_min, (y_max - y_min) * scale, h,
	       200.0 * scale);
	assert_true(d_max - d_min <= 2.0);        /* one scale throughout */
	assert_true(200.0 * scale > w);           /* the field is larger than the view */
	assert_true((y_max - y_min) * scale > h); /* no fixed camera could keep the body */
	free(px);
	free(rgb);
	bsim_video_free(v);
	bsim_video_track_free(t);
	bsim_scene_free(&scene);
}

/* The field's MP4, decoded: the body (its colour within the encoder's
 * error) is in every frame. */
static void cli_field_mp4_follows_the_body(void **state)
{
	(void)state;
	char scene[1200], out[1400], raw[1400];
	snprintf(scene, sizeof scene, "%s", bsim_test_src("tests/data/field_3x3.yaml"));
	const char *dir = bsim_test_dir("field");
	snprintf(out, sizeof out, "%s/field.mp4", dir);
	snprintf(raw, sizeof raw, "%s/field.rgb", dir);
	const char *same[] = {NULL};
	long steps = run_steps(scene, same);
	const char *argv[] = {"video",  scene, "--view", "40", "--size", "320x240",
	                      "--hold", "0",   "--out",  out,  NULL};
	char *se = NULL;
	int rc = bsim_test_cli(argv, NULL, &se);
	if (rc != 0)
		fail_msg("exit %d: %s", rc, se);
	free(se);
	probe p;
	ffprobe(out, &p);
	long frames = expected_frames(steps, 3, 25, 0);
	assert_string_equal(p.codec, "h264");
	assert_int_equal(p.frames, frames);
	const char *dec[] = {"ffmpeg",   "-v",       "error", "-i", out, "-f",
	                     "rawvideo", "-pix_fmt", "rgb24", "-y", raw, NULL};
	assert_int_equal(bsim_test_run(dec, NULL), 0);
	const int w = 320, h = 240;
	FILE *f = fopen(raw, "rb");
	assert_non_null(f);
	unsigned char *rgb = malloc(3 * w * h);
	long k = 0, n_min = w * h;
	while (fread(rgb, 3, (size_t)w * h, f) == (size_t)w * h) {
		blob b = find_color(rgb, w, h, 0, w, bsim_video_body_color(), 40);
		if (b.n < 1000 || b.x0 <= 0 || b.y0 <= 0 || b.x1 >= w - 1 || b.y1 >= h - 1)
			fail_msg("decoded frame %ld: body missing or cut (%ld px)", k, b.n);
		n_min = b.n < n_min ? b.n : n_min;
		k++;
	}
	printf("# field MP4: %ld decoded frames, body >= %ld px in each\n", k, n_min);
	assert_int_equal(k, frames);
	fclose(f);
	free(rgb);
}

/* The gate with a soft left beam and a stiff right one: each is drawn in
 * its own colour of the scale, the soft one left of the body, the stiff
 * one right. */
static void lib_beams_take_their_stiffness_color(void **state)
{
	(void)state;
	bsim_scene scene;
	bsim_scene_init_gate(&scene, 7.0, 0.0);
	scene.beams[0].stiffness = 200.0;
	scene.beams[1].stiffness = 600.0;
	scene.max_steps = 10;
	bsim_error err;
	bsim_options opts = {0};
	bsim_video_track *t = NULL;
	assert_int_equal(bsim_video_track_record(&scene, bsim_test_backend("thesis"), &opts, 1,
	                                         30.0, &t, &err),
	                 BSIM_OK);
	bsim_video_def def = bsim_video_def_default();
	bsim_video *v = NULL;
	assert_int_equal(bsim_video_alloc(&def, &scene, (const bsim_video_track *const *)&t, NULL,
	                                  1, &v, &err),
	                 BSIM_OK);
	int w, h;
	bsim_video_size(v, &w, &h);
	uint32_t soft = bsim_video_stiffness_color(v, 200.0);
	uint32_t stiff = bsim_video_stiffness_color(v, 600.0);
	uint32_t mid = bsim_video_stiffness_color(v, 400.0);
	assert_true(soft != stiff && mid != soft && mid != stiff);
	uint32_t *px = malloc(sizeof *px * w * h);
	unsigned char *rgb = malloc(3 * (size_t)w * h);
	assert_int_equal(bsim_video_render(v, 0, px, &err), BSIM_OK);
	to_rgb(px, w * h, rgb);
	blob body = find_color(rgb, w, h, 0, w, bsim_video_body_color(), 0);
	int cx = (body.x0 + body.x1) / 2;
	blob soft_l = find_color(rgb, w, h, 0, cx, soft, 0);
	blob stiff_l = find_color(rgb, w, h, 0, cx, stiff, 0);
	blob stiff_r = find_color(rgb, w, h, cx, w, stiff, 0);
	printf("# beam colours: soft %06x %ld px left, stiff %06x %ld px right, %ld left\n", soft,
	       soft_l.n, stiff, stiff_r.n, stiff_l.n);
	/* A 25 m beam at the body's scale (body 20 m across) and 4 px wide. */
	double beam_px = 25.0 * (body.x1 - body.x0 + 1) / 20.0;
	assert_true(soft_l.n > 2.0 * beam_px);
	assert_true(stiff_r.n > 2.0 * beam_px);
	assert_int_equal(stiff_l.n, 0);
	free(px);
	free(rgb);
	bsim_video_free(v);
	bsim_video_track_free(t);
	bsim_scene_free(&scene);
}

/* The C-track (9 x 9 gates) and a trial that follows its spine to the end
 * (seed 1, trial 592, 30 s): in the overview of a frame, a gate's cell
 * holds the path colour if and only if the runner's gate path, recorded
 * here by a run of its own, entered that gate by the frame's step. */
static void lib_lattice_overview_shows_the_gate_path(void **state)
{
	(void)state;
	bsim_scene scene;
	load("configs/lattice/c_track.yaml", &scene);
	const uint64_t seed = bsim_schedule_seed_mix(1, 0, 592);
	bsim_error err;
	bsim_options opts = {0};
	/* the truth: the runner's path */
	bsim_trial_runner *runner = bsim_trial_runner_alloc();
	bsim_trial_log *log = bsim_trial_log_alloc();
	bsim_recorder rec = {.stride = 1, .log = log};
	bsim_trial_result res;
	assert_int_equal(bsim_trial_run(runner, &scene, bsim_test_backend("thesis"), &opts, seed,
	                                &rec, &res, &err),
	                 BSIM_OK);
	assert_true(log->n_entries >= 10); /* it travels far */
	bsim_video_track *t = NULL;
	assert_int_equal(bsim_video_track_record(&scene, bsim_test_backend("thesis"), &opts, seed,
	                                         30.0, &t, &err),
	                 BSIM_OK);
	bsim_video_def def = bsim_video_def_default();
	def.width = def.height = 480;
	bsim_video *v = NULL;
	const char *label = "thesis";
	assert_int_equal(bsim_video_alloc(&def, &scene, (const bsim_video_track *const *)&t, &label,
	                                  1, &v, &err),
	                 BSIM_OK);
	const int w = 480, h = 480;
	uint32_t *px = malloc(sizeof *px * w * h);
	const long frames = bsim_video_track_frames(t);
	const long ks[2] = {frames / 2, frames - 1};
	for (int f = 0; f < 2; f++) {
		const long k = ks[f], step = bsim_video_track_sample(t, k).step;
		assert_int_equal(bsim_video_render(v, k, px, &err), BSIM_OK);
		int entered = 0, cells = 0;
		for (int iy = 0; iy < 9; iy++)
			for (int ix = -4; ix <= 4; ix++) {
				int in = 0;
				for (int e = 0; e < log->n_entries; e++)
					in |= log->entries[e].ix == ix &&
					      log->entries[e].iy == iy &&
					      log->entries[e].step <= step;
				const double lo[2] = {50.0 * ix - 25, 60.0 * iy},
				             hi[2] = {50.0 * ix + 25, 60.0 * iy + 60};
				double a[2], b[2];
				assert_int_equal(bsim_video_overview_pixel(v, 0, k, lo, a), 1);
				assert_int_equal(bsim_video_overview_pixel(v, 0, k, hi, b), 1);
				/* the cell's inside, a pixel clear of its edges */
				long n = 0, path = 0;
				for (int y = (int)ceil(b[1]) + 1; y < (int)floor(a[1]) - 1; y++)
					for (int x = (int)ceil(a[0]) + 1; x < (int)floor(b[0]) - 1;
					     x++) {
						n++;
						path += px[y * w + x] == bsim_video_path_color();
					}
				assert_true(n >= 40);
				if (in ? path < 0.3 * n : path != 0)
					fail_msg("frame %ld (step %ld): gate (%d, %d) %s the path, "
					         "%ld of %ld pixels in the path colour",
					         k, step, ix, iy, in ? "in" : "not in", path, n);
				entered += in;
				cells++;
			}
		printf("# lattice overview, frame %ld: %d of %d gates entered, as the runner's "
		       "path\n",
		       k, entered, cells);
		assert_true(entered >= (f ? 10 : 2));
	}
	free(px);
	bsim_video_free(v);
	bsim_video_track_free(t);
	bsim_trial_log_free(log);
	bsim_trial_runner_free(runner);
	/* a gate that fits the view: no overview */
	bsim_scene gate;
	bsim_scene_init_gate(&gate, 7.0, 0.0);
	gate.max_steps = 10;
	assert_int_equal(bsim_video_track_record(&gate, bsim_test_backend("thesis"), &opts, 1, 30.0,
	                                         &t, &err),
	                 BSIM_OK);
	assert_int_equal(bsim_video_alloc(&def, &gate, (const bsim_video_track *const *)&t, NULL, 1,
	                                  &v, &err),
	                 BSIM_OK);
	double q[2];
	assert_int_equal(bsim_video_overview_pixel(v, 0, 0, gate.body.start, q), 0);
	bsim_video_free(v);
	bsim_video_track_free(t);
	bsim_scene_free(&gate);
	bsim_scene_free(&scene);
}

/* Column index of name in a CSV header line. */
static int column(const char *header, const char *name)
{
	int i = 0;
	size_t n = strlen(name);
	for (const char *p = header;; i++) {
		size_t len = strcspn(p, ",\n");
		if (len == n && strncmp(p, name, n) == 0)
			return i;
		if (p[len] != ',')
			break;
		p += len + 1;
	}
	fail_msg("no column %s", name);
	return -1;
}

/* Every frame of the gate's video shows the state of step min(floor(k/(fps
 * h)), N) of the trajectory beamsim run records for the same trial:
 * position, energies and the random force the runner applies over that
 * step; 601 steps end between two frame times, and the last frame is the
 * trial's end state. */
/* The frames of a video of trial 5 of seed 3 of the scene rel (with
 * steps steps and --set extra, if not NULL) against the rows of `run
 * --trajectory` of the same trial. */
static void frames_match_run(const char *rel, const char *steps, const char *extra)
{
	char gate[1200], csv[1400], max_steps[64];
	snprintf(gate, sizeof gate, "%s", bsim_test_src(rel));
	snprintf(csv, sizeof csv, "%s/t.csv", bsim_test_dir("same"));
	snprintf(max_steps, sizeof max_steps, "integration.max_steps=%s", steps);
	const char *argv[] = {"run",
	                      gate,
	                      "--seed",
	                      "3",
	                      "--trial",
	                      "5",
	                      "--set",
	                      max_steps,
	                      "--trajectory",
	                      csv,
	                      extra ? "--set" : NULL,
	                      extra,
	                      NULL};
	assert_int_equal(bsim_test_cli(argv, NULL, NULL), 0);
	char *text = bsim_test_read(csv);
	assert_non_null(text);
	const char *names[] = {"x", "y", "f_rand", "e_kin", "e_beam", "e_prop"};
	int col[6];
	for (int i = 0; i < 6; i++)
		col[i] = column(text, names[i]);
	/* Rows: one per step from step 0. */
	long n_rows = 0, cap = 1024;
	double(*rows)[6] = malloc(sizeof *rows * cap);
	for (char *line = strchr(text, '\n') + 1; *line; n_rows++) {
		if (n_rows == cap)
			rows = realloc(rows, sizeof *rows * (cap *= 2));
		char *p = line;
		for (int c = 0; *p && *p != '\n'; c++) {
			double x = strtod(p, &p);
			for (int i = 0; i < 6; i++)
				if (col[i] == c)
					rows[n_rows][i] = x;
			if (*p == ',')
				p++;
		}
		line = *p ? p + 1 : p;
	}

	bsim_scene scene;
	bsim_override ov[2] = {{"integration.max_steps", steps, "test"}, {NULL, NULL, "test"}};
	char key[64] = "";
	if (extra) {
		snprintf(key, sizeof key, "%.*s", (int)(strchr(extra, '=') - extra), extra);
		ov[1].key = key;
		ov[1].value = strchr(extra, '=') + 1;
	}
	bsim_error err;
	assert_int_equal(bsim_scene_load(gate, ov, extra ? 2 : 1, &scene, &err), BSIM_OK);
	bsim_options opts = {0};
	bsim_video_track *t = NULL;
	assert_int_equal(bsim_video_track_record(&scene, bsim_test_backend("thesis"), &opts,
	                                         bsim_schedule_seed_mix(3, 0, 5), 30.0, &t, &err),
	                 BSIM_OK);
	long frames = bsim_video_track_frames(t);
	assert_int_equal(n_rows, bsim_video_track_result(t)->steps_run + 1);
	const long n_last = n_rows - 1;
	assert_int_equal(frames, expected_frames(n_last, 3, 25, 0));
	double worst = 0.0;
	int forces_seen = 0;
	for (long k = 0; k < frames; k++) {
		bsim_video_sample s = bsim_video_track_sample(t, k);
		long step = k * 25 / 3; /* floor(k / (30 fps x 4 ms)), to the end */
		if (step > n_last)
			step = n_last;
		assert_int_equal(s.step, step);
		const double got[6] = {s.x[0], s.x[1], s.f_rand, s.e_kin, s.e_spring, s.e_prop};
		for (int i = 0; i < 6; i++) {
			/* The last row's f_rand is the last force applied, not the
			 * next one: compare forces only over steps that were run. */
			if (i == 2 && step == n_last)
				continue;
			double want = rows[step][i];
			double e = fabs(got[i] - want) / fmax(1.0, fabs(want));
			worst = fmax(worst, e);
			if (e > 1e-8)
				fail_msg("frame %ld (step %ld): %s %.10g, run's trajectory %.10g",
				         k, step, names[i], got[i], want);
		}
		forces_seen += s.f_rand != 0.0;
	}
	assert_int_equal(bsim_video_track_sample(t, frames - 1).step, n_last);
	printf("# %ld frames equal the run's trajectory to %.1e (relative)\n", frames, worst);
	assert_true(forces_seen > frames / 2);
	free(rows);
	free(text);
	bsim_video_track_free(t);
	bsim_scene_free(&scene);
}

static void lib_frames_are_the_runs_states(void **state)
{
	(void)state;
	frames_match_run("configs/thesis/gate.yaml", "601", NULL);
}

/* Under the essay's lattice protocol the world holds only the active
 * gate's two beams; the video draws the whole field from the lattice's
 * state, as the trajectory records it. */
static void lib_essay_protocol_frames_are_the_runs_states(void **state)
{
	(void)state;
	frames_match_run("configs/lattice/c_track.yaml", "3001", "lattice.protocol=essay");
}

/* An encoder that exits with status 1 without reading: the error says so
 * and neither the video nor a temporary file is left. */
static void lib_failing_encoder_writes_nothing(void **state)
{
	(void)state;
	bsim_scene scene;
	bsim_scene_init_gate(&scene, 7.0, 20.0);
	scene.max_steps = 50;
	bsim_error err;
	bsim_options opts = {0};
	bsim_video_track *t = NULL;
	assert_int_equal(bsim_video_track_record(&scene, bsim_test_backend("thesis"), &opts, 1,
	                                         30.0, &t, &err),
	                 BSIM_OK);
	bsim_video_def def = bsim_video_def_default();
	def.ffmpeg = "false";
	bsim_video *v = NULL;
	assert_int_equal(bsim_video_alloc(&def, &scene, (const bsim_video_track *const *)&t, NULL,
	                                  1, &v, &err),
	                 BSIM_OK);
	const char *dir = bsim_test_dir("failing");
	char out[1400];
	snprintf(out, sizeof out, "%s/x.mp4", dir);
	assert_int_equal(bsim_video_write(v, out, &err), BSIM_EFAIL);
	printf("# %s\n", err.msg);
	assert_non_null(strstr(err.msg, "false exited with status 1"));
	assert_true(dir_empty(dir));
	/* The process is unharmed by the broken pipe: a second try fails alike. */
	assert_int_equal(bsim_video_write(v, out, &err), BSIM_EFAIL);
	assert_true(dir_empty(dir));
	bsim_video_free(v);
	bsim_video_track_free(t);
	bsim_scene_free(&scene);
}

static void cli_missing_ffmpeg(void **state)
{
	(void)state;
	char gate[1200], out[1400];
	snprintf(gate, sizeof gate, "%s", bsim_test_src("configs/thesis/gate.yaml"));
	const char *dir = bsim_test_dir("missing");
	snprintf(out, sizeof out, "%s/x.mp4", dir);
	const char *path = getenv("PATH");
	char *saved = path ? strdup(path) : NULL;
	setenv("PATH", dir, 1); /* an empty directory: no ffmpeg */
	const char *argv[] = {"video", gate, "--set", "integration.max_steps=20",
	                      "--out", out,  NULL};
	char *se = NULL;
	int rc = bsim_test_cli(argv, NULL, &se);
	if (saved)
		setenv("PATH", saved, 1);
	free(saved);
	printf("# %s", se);
	assert_int_equal(rc, 1);
	assert_non_null(strstr(se, "ffmpeg not found"));
	assert_non_null(strstr(se, "Debian package ffmpeg"));
	assert_true(dir_empty(dir));
	free(se);
}

/* ---- ffmpeg failing after it started ----------------------------------------------------- */

/* beamsim video of a short gate trial into dir/x.mp4 with the ffmpeg
 * stand-in script (in its own directory, first on the PATH): exit 1, one
 * line on stderr naming the step and holding need, and dir empty (no video,
 * no temporary file). */
static void expect_encoder_failure(const char *name, const char *script, const char *need)
{
	const char *base = bsim_test_dir(name);
	char bin[1100], dir[1100], out[1200], gate[1200];
	snprintf(bin, sizeof bin, "%s/bin", base);
	snprintf(dir, sizeof dir, "%s/out", base);
	snprintf(out, sizeof out, "%s/x.mp4", dir);
	snprintf(gate, sizeof gate, "%s", bsim_test_src("configs/thesis/gate.yaml"));
	assert_int_equal(mkdir(dir, 0755), 0);
	char *old = bsim_test_fake_program(bin, "ffmpeg", script);
	const char *argv[] = {"video", gate, "--set", "integration.max_steps=20", "--size", "64x64",
	                      "--out", out,  NULL};
	char *se = NULL;
	int rc = bsim_test_cli(argv, NULL, &se);
	bsim_test_path_restore(old);
	printf("# exit %d: %s", rc, se);
	assert_int_equal(rc, 1);
	assert_int_equal(bsim_test_count_lines(se), 1);
	char step[1400];
	snprintf(step, sizeof step, "beamsim: %s: encoding the video: ", out);
	assert_non_null(strstr(se, step));
	assert_non_null(strstr(se, need));
	assert_non_null(strstr(se, "; no video written\n"));
	assert_true(dir_empty(dir));
	free(se);
}

/* ffmpeg 5.1 on a full disk exits with status 0 after "Error writing
 * trailer": an ffmpeg that writes half a file, says so and exits 0 is a
 * failure quoting its message, and the half file is removed. */
static void cli_ffmpeg_error_with_status_0(void **state)
{
	(void)state;
	expect_encoder_failure(
	        "error_status_0",
	        "#!/bin/sh\nfor a; do out=${a#file:}; done\n"
	        "head -c 1000 > \"$out\"; cat > /dev/null\n"
	        "echo \"Error writing trailer of file:$out: No space left on device\" >&2\n"
	        "echo \"Error closing file file:$out: No space left on device\" >&2\n"
	        "exit 0\n",
	        "ffmpeg exited with status 0 after an error: Error writing trailer of file:");
}

/* An ffmpeg that says nothing and exits 0 but leaves an MP4 cut short
 * (its frames' box claims 1 MiB, 8 bytes follow): the file is checked. */
static void cli_mp4_cut_short_with_status_0(void **state)
{
	(void)state;
	expect_encoder_failure(
	        "cut_status_0",
	        "#!/bin/sh\nfor a; do out=${a#file:}; done\ncat > /dev/null\n"
	        "printf '\\0\\0\\0\\10ftyp\\0\\20\\0\\0mdatframes..' > \"$out\"\n",
	        "ffmpeg exited with status 0 but the MP4 is not whole: its box 'mdat' at byte 8 "
	        "claims 1048576 bytes, of 16 left");
}

/* The real ffmpeg on a full disk, made without privilege by a file-size
 * limit on beamsim, which ffmpeg inherits (SIGXFSZ ignored: a write beyond
 * fails with EFBIG as one to a full disk with ENOSPC): the video of the
 * same trial, unlimited, is S bytes; under a limit of S / 2 the command
 * exits 1 quoting ffmpeg and leaves nothing at the path. */
static void cli_full_disk_real_ffmpeg(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("full_disk");
	char gate[1200], whole[1400], cut[1400];
	snprintf(gate, sizeof gate, "%s", bsim_test_src("configs/thesis/gate.yaml"));
	snprintf(whole, sizeof whole, "%s/whole.mp4", dir);
	snprintf(cut, sizeof cut, "%s/cut.mp4", dir);
	const char *a1[] = {"video", gate, "--size", "128x128", "--out", whole, NULL};
	assert_int_equal(bsim_test_cli(a1, NULL, NULL), 0);
	const long size = bsim_test_size(whole);
	const bsim_test_opts half = {.fsize = size / 2};
	const char *a2[] = {"video", gate, "--size", "128x128", "--out", cut, NULL};
	char *se = NULL;
	int rc = bsim_test_cli_with(a2, &half, NULL, &se);
	printf("# %ld bytes whole; limited to %ld: exit %d: %s", size, size / 2, rc, se);
	assert_int_equal(rc, 1);
	assert_non_null(strstr(se, ": encoding the video: ffmpeg "));
	assert_non_null(strstr(se, "File too large"));
	assert_false(bsim_test_exists(cut));
	char pattern[1500];
	snprintf(pattern, sizeof pattern, "%s.tmp.*", cut);
	assert_null(bsim_test_glob_first(pattern));
	free(se);
}

static void cli_bad_arguments(void **state)
{
	(void)state;
	char gate[1200], out[1400];
	snprintf(gate, sizeof gate, "%s", bsim_test_src("configs/thesis/gate.yaml"));
	const char *dir = bsim_test_dir("bad");
	snprintf(out, sizeof out, "%s/x.mp4", dir);
	const char *bad_scene =
	        bsim_test_write(dir, "bad.yaml", "body: { mass: -1, radius: 10 }\n");
	char scene[1400];
	snprintf(scene, sizeof scene, "%s", bad_scene);
	const struct {
		const char *args[6];
		const char *needle;
	} cases[] = {
	        {{"--fps", "0"}, "--fps 0: expected a number in [0.01, 1000]"},
	        {{"--fps", "1e-9"}, "--fps 1e-9: expected a number in [0.01, 1000]"},
	        {{"--fps", "1001"}, "--fps 1001: expected a number in [0.01, 1000]"},
	        {{"--fps", "30x"}, "--fps 30x"},
	        {{"--size", "641x480"}, "expected even WIDTHxHEIGHT"},
	        {{"--size", "640"}, "--size 640: expected WIDTHxHEIGHT"},
	        {{"--size", "32x32"}, "from 64x64"},
	        {{"--hold", "-1"}, "--hold -1"},
	        {{"--view", "0"}, "--view 0"},
	        {{"--crf", "52"}, "--crf 52: expected an integer 0 to 51"},
	        {{"--backend", "nope"}, "nope"},
	        {{"--backends", "thesis,nope"}, "nope"},
	        {{"--backends", "thesis,thesis"}, "named twice"},
	        {{"--backends", "a,b,c,d,e"}, "expected 1 to 4 names"},
	        {{"--backends", "thesis,box2d", "--backend", "thesis"}, "give one of them"},
	        {{"--backends", "thesis,box2d", "--backend-opt", "substeps=2"}, "B:KEY=VALUE"},
	        {{"--backend-opt", "nonsense=1"}, "nonsense"},
	        {{"--set", "body.mass=-1"}, "body.mass"},
	        {{"--trial", "-3"}, "--trial -3"},
	        {{"--frames", "3"}, "unknown option --frames"},
	};
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		const char *argv[16] = {"video", gate, "--out", out};
		int n = 4;
		for (int j = 0; cases[i].args[j]; j++)
			argv[n++] = cases[i].args[j];
		argv[n] = NULL;
		char *se = NULL;
		int rc = bsim_test_cli(argv, NULL, &se);
		if (rc != 2 || !strstr(se, cases[i].needle))
			fail_msg("case %zu: exit %d, stderr \"%s\" (expected 2 and \"%s\")", i, rc,
			         se, cases[i].needle);
		free(se);
		assert_true(dir_empty(dir) || access(out, F_OK) != 0);
	}
	/* The help says what the parser takes: 1 to BSIM_VIDEO_PANELS_MAX names. */
	const char *help[] = {"video", "--help", NULL};
	char *so = NULL, want[32];
	assert_int_equal(bsim_test_cli(help, &so, NULL), 0);
	snprintf(want, sizeof want, "1 to %d names", BSIM_VIDEO_PANELS_MAX);
	assert_non_null(strstr(so, want));
	assert_null(strstr(so, "up to 4"));
	free(so);
	/* No --out, no scene, a bad scene file. */
	const char *no_out[] = {"video", gate, NULL};
	const char *no_scene[] = {"video", "--out", out, NULL};
	const char *bad[] = {"video", scene, "--out", out, NULL};
	const char *const *more[] = {no_out, no_scene, bad};
	const char *needles[] = {"--out FILE.mp4 is required", "missing SCENE",
	                         "bad.yaml:1:15: body.mass"};
	for (int i = 0; i < 3; i++) {
		char *se = NULL;
		int rc = bsim_test_cli(more[i], NULL, &se);
		if (rc != 2 || !strstr(se, needles[i]))
			fail_msg("exit %d, stderr \"%s\" (expected 2 and \"%s\")", rc, se,
			         needles[i]);
		free(se);
	}
	assert_int_equal(access(out, F_OK), -1);
	/* Nothing but the bad scene in the directory. */
	DIR *d = opendir(dir);
	struct dirent *e;
	while ((e = readdir(d)))
		assert_true(e->d_name[0] == '.' || strcmp(e->d_name, "bad.yaml") == 0);
	closedir(d);
}

/* SIGINT or SIGTERM while ffmpeg writes (its temporary file out.mp4.tmp.PID
 * is there) stops the video with 128 + the signal and removes the file;
 * temporary files of processes no longer alive (a video killed with
 * SIGKILL) are removed by the next video to the same path, those of a
 * live process are left alone. */
static void cli_stopped_video_leaves_no_temporary(void **state)
{
	(void)state;
	char gate[1200], out[1400], dir[1100], errfile[1400], pattern[1500];
	snprintf(gate, sizeof gate, "%s", bsim_test_src("configs/thesis/gate.yaml"));
	snprintf(dir, sizeof dir, "%s", bsim_test_dir("stopped"));
	snprintf(out, sizeof out, "%s/x.mp4", dir);
	snprintf(errfile, sizeof errfile, "%s.err", dir);
	snprintf(pattern, sizeof pattern, "%s.tmp.*", out);
	static const int sigs[] = {SIGINT, SIGTERM};
	for (int i = 0; i < 2; i++) {
		/* 60 s held at 1000 frames a second: far longer than the wait */
		const char *argv[] = {"video",  gate,    "--set",  "integration.max_steps=20",
		                      "--fps",  "1000",  "--hold", "60",
		                      "--size", "64x64", "--out",  out,
		                      NULL};
		const bsim_test_opts o = {.err = errfile};
		int pid = bsim_test_spawn_with(argv, &o);
		int status = -1;
		assert_int_equal(bsim_test_await_glob(pid, pattern, 1, &status), 1);
		kill(pid, sigs[i]);
		assert_int_equal(bsim_test_wait(pid), 128 + sigs[i]);
		char *se = bsim_test_read(errfile);
		assert_non_null(se);
		printf("# %s", se);
		assert_non_null(strstr(se, sigs[i] == SIGINT ? "SIGINT" : "SIGTERM"));
		assert_non_null(strstr(se, "stopped; no video written"));
		free(se);
		assert_true(dir_empty(dir));
	}
	unlink(errfile);

	/* A stale file: a process that has ended (spawned and reaped). */
	const char *quick[] = {"backends", NULL};
	int dead = bsim_test_spawn(quick);
	assert_int_equal(bsim_test_wait(dead), 0);
	char name[64], live[64];
	snprintf(name, sizeof name, "x.mp4.tmp.%d", dead);
	snprintf(live, sizeof live, "x.mp4.tmp.%d", (int)getpid());
	char stale[1500];
	snprintf(stale, sizeof stale, "%s", bsim_test_write(dir, name, "half a video"));
	char alive[1500];
	snprintf(alive, sizeof alive, "%s", bsim_test_write(dir, live, "being written"));
	const char *argv[] = {"video", gate, "--set", "integration.max_steps=20", "--size", "64x64",
	                      "--out", out,  NULL};
	assert_int_equal(bsim_test_cli(argv, NULL, NULL), 0);
	assert_true(bsim_test_exists(out));
	assert_false(bsim_test_exists(stale));
	assert_true(bsim_test_exists(alive));
}

/* An "ffmpeg" that writes the raw frames it reads beside the output file
 * (its last argument, file:OUT.tmp.PID) as OUT.frames, so a test reads back
 * what was sent, and into the output the smallest MP4 whose boxes are
 * whole (ftyp, moov, mdat, 8 bytes each), which the encoder's check of the
 * file takes. */
static const char *raw_encoder(const char *dir)
{
	static char path[1500];
	snprintf(path, sizeof path, "%s",
	         bsim_test_write(dir, "raw-ffmpeg",
	                         "#!/bin/sh\nfor a; do out=${a#file:}; done\n"
	                         "cat > \"${out%.tmp.*}.frames\" || exit 1\n"
	                         "printf '\\0\\0\\0\\10ftyp\\0\\0\\0\\10moov\\0\\0\\0\\10mdat' "
	                         "> \"$out\"\n"));
	assert_int_equal(chmod(path, 0755), 0);
	return path;
}

/* Peak resident memory of this process, bytes. */
static long peak_rss(void)
{
	struct rusage u;
	assert_int_equal(getrusage(RUSAGE_SELF, &u), 0);
	return u.ru_maxrss * 1024L;
}

/* A million steps of a body at rest, streamed at one frame per 5000 steps
 * (201 frames): the stream hands over one frame interval of centres at a
 * time, keeps one trail point, and the process's peak memory grows by far
 * less than the 16 MB that one centre a step would take (a recorded
 * track's trail alone). First in the program, so that the peak before is
 * the program's start, not an earlier test's. */
static void lib_stream_memory_does_not_grow_with_steps(void **state)
{
	(void)state;
	bsim_scene scene;
	bsim_scene_init_gate(&scene, 0.0, 0.0);
	scene.max_steps = 1000000;
	const char *dir = bsim_test_dir("stream-memory");
	char out[1400];
	snprintf(out, sizeof out, "%s/long.raw", dir);
	bsim_video_def def = bsim_video_def_default();
	def.fps = 0.05;
	def.width = def.height = 64;
	def.hold = 0.0;
	def.ffmpeg = raw_encoder(dir);
	const bsim_backend *backend = bsim_test_backend("thesis");
	bsim_video_report rep;
	bsim_error err;
	const long before = peak_rss();
	bsim_video_stream *vs = NULL;
	assert_int_equal(
	        bsim_video_stream_alloc(&def, &scene, &backend, NULL, NULL, 1, 1, &vs, &err),
	        BSIM_OK);
	assert_int_equal(bsim_video_stream_write(vs, out, &rep, &err), BSIM_OK);
	/* once a stream */
	assert_int_equal(bsim_video_stream_write(vs, out, NULL, &err), BSIM_EINPUT);
	bsim_video_stream_free(vs);
	const long grown = peak_rss() - before;
	const long steps = rep.results[0].steps_run;
	const long per_frame = (long)ceil(1.0 / (def.fps * scene.dt));
	printf("# %ld steps, %ld frames: %ld trail points, at most %ld steps held (a frame is "
	       "%ld steps), peak memory grew %ld KB\n",
	       steps, rep.frames, rep.trail_points, rep.steps_held, per_frame, grown / 1024);
	assert_int_equal(steps, 1000000);
	assert_int_equal(rep.frames, 201);
	assert_int_equal(bsim_test_size(bsim_test_join(dir, "long.raw.frames")),
	                 201L * 64 * 64 * 4);
	assert_true(rep.steps_held <= per_frame + 1);
	assert_true(rep.trail_points <= 2); /* at rest: the start, a list a view scale */
#if !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
	/* Not under a sanitizer: AddressSanitizer's quarantine keeps freed
	 * memory (up to 256 MB), so the peak grows with what the runner and
	 * cairo allocate and free, not with what is held, and ThreadSanitizer
	 * shadows every byte touched; the counts above are the check there. */
	assert_true(grown < 8L * 1024 * 1024);
#endif
	bsim_scene_free(&scene);
}

/* Records the tracks of trial `seed` on the backends and renders every
 * frame of their video, hold included, into one buffer. */
static uint32_t *recorded_frames(const bsim_scene *scene, const bsim_backend *const *backends,
                                 const char *const *labels, int n, uint64_t seed,
                                 const bsim_video_def *def, long *frames, double *t_part,
                                 long *steps)
{
	bsim_error err;
	bsim_options opts = {0};
	bsim_video_track *t[4] = {0};
	for (int p = 0; p < n; p++)
		assert_int_equal(bsim_video_track_record(scene, backends[p], &opts, seed, def->fps,
		                                         &t[p], &err),
		                 BSIM_OK);
	bsim_video *v = NULL;
	assert_int_equal(bsim_video_alloc(def, scene, (const bsim_video_track *const *)t, labels, n,
	                                  &v, &err),
	                 BSIM_OK);
	int w, h;
	bsim_video_size(v, &w, &h);
	*frames = bsim_video_frames(v);
	uint32_t *px = malloc(sizeof *px * (size_t)w * h * *frames);
	assert_non_null(px);
	for (long k = 0; k < *frames; k++)
		assert_int_equal(bsim_video_render(v, k, px + (size_t)k * w * h, &err), BSIM_OK);
	*t_part = n > 1 ? bsim_video_track_separation(t[0], t[1], 0.01 * scene->body.radius) : -1;
	for (int p = 0; p < n; p++) {
		steps[p] = bsim_video_track_result(t[p])->steps_run;
		bsim_video_track_free(t[p]);
	}
	bsim_video_free(v);
	return px;
}

/* The streamed video's frames, as sent to the encoder, equal the recorded
 * video's rendered frames byte for byte: a gate trial side by side whose
 * paths part and whose panels end at different steps (the ring, the ended
 * panel, the ghost trail up to its end), and a field the camera follows
 * with its overview. */
static void lib_stream_draws_the_recorded_frames(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("stream-same");
	const char *encoder = raw_encoder(dir);
	bsim_scene gate, field;
	bsim_override ov[] = {{"effects.propulsion.force", "6", "test"},
	                      {"effects.random_force.magnitude", "30", "test"}};
	bsim_error err;
	assert_int_equal(
	        bsim_scene_load(bsim_test_src("configs/thesis/gate.yaml"), ov, 2, &gate, &err),
	        BSIM_OK);
	load("tests/data/field_3x3.yaml", &field);
	const struct {
		const bsim_scene *scene;
		const bsim_backend *backends[2];
		int n;
		uint64_t seed;
		int w, h;
		double view;
	} cases[] = {
	        {&gate,
	         {bsim_test_backend("thesis"), bsim_test_backend("box2d")},
	         2,
	         bsim_schedule_seed_mix(1, 13, 15),
	         320,
	         160,
	         200.0},
	        {&field,
	         {bsim_test_backend("thesis")},
	         1,
	         bsim_schedule_seed_mix(1, 0, 0),
	         320,
	         240,
	         40.0},
	};
	const char *labels[] = {"thesis", "box2d"};
	for (int c = 0; c < 2; c++) {
		bsim_video_def def = bsim_video_def_default();
		def.width = cases[c].w;
		def.height = cases[c].h;
		def.view_span = cases[c].view;
		def.hold = 0.1;
		def.ffmpeg = encoder;
		long frames, steps[2];
		double t_part;
		uint32_t *want =
		        recorded_frames(cases[c].scene, cases[c].backends, labels, cases[c].n,
		                        cases[c].seed, &def, &frames, &t_part, steps);
		char out[1400];
		snprintf(out, sizeof out, "%s/case%d.raw", dir, c);
		bsim_video_report rep;
		bsim_video_stream *vs = NULL;
		assert_int_equal(bsim_video_stream_alloc(&def, cases[c].scene, cases[c].backends,
		                                         NULL, labels, cases[c].n, cases[c].seed,
		                                         &vs, &err),
		                 BSIM_OK);
		for (int p = 0; p < cases[c].n; p++)
			assert_int_equal(bsim_video_stream_result(vs, p)->steps_run, steps[p]);
		assert_null(bsim_video_stream_result(vs, cases[c].n));
		assert_int_equal(bsim_video_stream_write(vs, out, &rep, &err), BSIM_OK);
		bsim_video_stream_free(vs);
		const size_t frame_px = (size_t)cases[c].w * cases[c].h;
		assert_int_equal(rep.frames, frames);
		assert_true(rep.t_part == t_part);
		for (int p = 0; p < cases[c].n; p++)
			assert_int_equal(rep.results[p].steps_run, steps[p]);
		char frames_path[1500];
		snprintf(frames_path, sizeof frames_path, "%s.frames", out);
		char *got = bsim_test_read(frames_path);
		assert_non_null(got);
		assert_int_equal(bsim_test_size(frames_path), (long)(frames * frame_px * 4));
		long differ = 0;
		for (long k = 0; k < frames; k++) {
			const uint32_t *g =
			        (const uint32_t *)(const void *)(got + k * frame_px * 4);
			for (size_t i = 0; i < frame_px; i++)
				differ += (g[i] & 0xFFFFFFu) != want[k * frame_px + i];
		}
		printf("# case %d: %ld frames, %d panel(s), parts at %g s, %ld trail points "
		       "kept of %ld steps: %ld pixels differ\n",
		       c, frames, cases[c].n, t_part, rep.trail_points,
		       steps[0] + (cases[c].n > 1 ? steps[1] : 0), differ);
		assert_int_equal(differ, 0);
		if (c == 0)
			assert_true(t_part > 0.0 && steps[0] != steps[1]);
		free(got);
		free(want);
	}
	bsim_scene_free(&gate);
	bsim_scene_free(&field);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(lib_stream_memory_does_not_grow_with_steps),
	        cmocka_unit_test(lib_stream_draws_the_recorded_frames),
	        cmocka_unit_test(cli_single_backend),
	        cmocka_unit_test(cli_side_by_side),
	        cmocka_unit_test(lib_camera_follows_the_body),
	        cmocka_unit_test(cli_field_mp4_follows_the_body),
	        cmocka_unit_test(lib_beams_take_their_stiffness_color),
	        cmocka_unit_test(lib_lattice_overview_shows_the_gate_path),
	        cmocka_unit_test(lib_frames_are_the_runs_states),
	        cmocka_unit_test(lib_essay_protocol_frames_are_the_runs_states),
	        cmocka_unit_test(lib_failing_encoder_writes_nothing),
	        cmocka_unit_test(cli_missing_ffmpeg),
	        cmocka_unit_test(cli_ffmpeg_error_with_status_0),
	        cmocka_unit_test(cli_mp4_cut_short_with_status_0),
	        cmocka_unit_test(cli_full_disk_real_ffmpeg),
	        cmocka_unit_test(cli_stopped_video_leaves_no_temporary),
	        cmocka_unit_test(cli_bad_arguments),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
