/* beamsim video: an MP4 of one trial, the trial `beamsim run` runs with the
 * same arguments, on one backend or on several side by side with the same
 * schedule. Parsing and printing only; the library draws and encodes
 * (beamsim/video.h). */
#define _POSIX_C_SOURCE 200809L

#include <getopt.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/schedule.h"
#include "beamsim/video.h"
#include "cli_common.h"

static const char video_help[] =
        "Usage: beamsim video SCENE --out FILE.mp4 [OPTIONS]\n"
        "\n"
        "Writes an MP4 (H.264, yuv420p) of one trial of the scene file SCENE: the\n"
        "trial beamsim run runs with the same --seed, --group, --trial and --set. A\n"
        "frame shows the beams coloured by stiffness (with the scale), the body and\n"
        "its trail, the random force as an arrow (one body radius per Rm), the time,\n"
        "the kinetic, spring and propulsive potential energies, and the outcome once\n"
        "it is decided. A field larger than the view is followed by the camera.\n"
        "With --backends A,B the backends run the same schedule side by side, each\n"
        "panel showing the other's trail in grey and where the two paths part.\n"
        "Frames are drawn with cairo and encoded by ffmpeg (Debian package ffmpeg).\n"
        "The file appears whole or not at all.\n"
        "\n"
        "Options:\n"
        "  --out FILE.mp4         the video to write (required)\n"
        "  --backend B            physics backend (default thesis; see beamsim backends)\n"
        "  --backends A,B         several backends side by side (up to 4)\n"
        "  --backend-opt K=V      a backend option; B:K=V for backend B of --backends\n"
        "  --seed N               experiment seed (default 1)\n"
        "  --group G              group index for the seed (default 0)\n"
        "  --trial I              trial index for the seed (default 0)\n"
        "  --set KEY=VALUE        override a scene field by dotted path, repeatable\n"
        "  --fps F                frames per second of simulated time (default 30)\n"
        "  --size WxH             frame size in pixels, even (default 540x540 a panel)\n"
        "  --hold S               seconds the last frame is held (default 1)\n"
        "  --view M               metres the shorter side of a panel shows at most; a\n"
        "                         larger field is followed by the camera (default 200)\n"
        "  -h, --help             show this help\n";

enum {
	OPT_OUT = 256,
	OPT_BACKEND,
	OPT_BACKENDS,
	OPT_BACKEND_OPT,
	OPT_SEED,
	OPT_GROUP,
	OPT_TRIAL,
	OPT_SET,
	OPT_FPS,
	OPT_SIZE,
	OPT_HOLD,
	OPT_VIEW
};

static const struct option video_options[] = {
        {"out", required_argument, NULL, OPT_OUT},
        {"backend", required_argument, NULL, OPT_BACKEND},
        {"backends", required_argument, NULL, OPT_BACKENDS},
        {"backend-opt", required_argument, NULL, OPT_BACKEND_OPT},
        {"seed", required_argument, NULL, OPT_SEED},
        {"group", required_argument, NULL, OPT_GROUP},
        {"trial", required_argument, NULL, OPT_TRIAL},
        {"set", required_argument, NULL, OPT_SET},
        {"fps", required_argument, NULL, OPT_FPS},
        {"size", required_argument, NULL, OPT_SIZE},
        {"hold", required_argument, NULL, OPT_HOLD},
        {"view", required_argument, NULL, OPT_VIEW},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
};

#define MAX_PANELS BSIM_VIDEO_PANELS_MAX

typedef struct video_args {
	const char *scene, *out;
	int n_backends, has_backend, has_backends;
	char names[MAX_PANELS][32];
	bsim_options opts[MAX_PANELS];
	uint64_t seed;
	long group, trial;
	cli_sets sets;
	bsim_video_def def;
	/* --backend-opt is resolved once the backends are known */
	int n_pending;
	char pending[MAX_PANELS * BSIM_OPTIONS_MAX][128];
} video_args;

static int parse_backends(video_args *a, const char *text)
{
	const char *p = text;
	a->n_backends = 0;
	while (1) {
		size_t n = strcspn(p, ",");
		if (n == 0 || n >= sizeof a->names[0] || a->n_backends == MAX_PANELS)
			return cli_usage("video", "--backends %s: expected 1 to %d names A,B,...",
			                 text, MAX_PANELS);
		snprintf(a->names[a->n_backends], sizeof a->names[0], "%.*s", (int)n, p);
		for (int i = 0; i < a->n_backends; i++)
			if (strcmp(a->names[i], a->names[a->n_backends]) == 0)
				return cli_usage("video", "--backends %s: %s is named twice", text,
				                 a->names[i]);
		a->n_backends++;
		if (p[n] == '\0')
			return CLI_OK;
		p += n + 1;
	}
}

/* "K=V" for the only backend, or "B:K=V" for backend B. */
static int backend_opt(video_args *a, const char *text)
{
	const char *colon = strchr(text, ':'), *eq = strchr(text, '=');
	if (colon && (!eq || colon < eq)) {
		for (int i = 0; i < a->n_backends; i++)
			if (strlen(a->names[i]) == (size_t)(colon - text) &&
			    strncmp(text, a->names[i], (size_t)(colon - text)) == 0)
				return cli_options_add(&a->opts[i], "video", colon + 1);
		return cli_usage("video", "--backend-opt %s: %.*s is not one of the backends", text,
		                 (int)(colon - text), text);
	}
	if (a->n_backends > 1)
		return cli_usage("video",
		                 "--backend-opt %s: expected B:KEY=VALUE with several backends",
		                 text);
	return cli_options_add(&a->opts[0], "video", text);
}

static int parse_number(const char *opt, const char *text, double lo, double hi, int open_lo,
                        double *out)
{
	char *end;
	double x = strtod(text, &end);
	int ok = end != text && *end == '\0' && x <= hi && (open_lo ? x > lo : x >= lo);
	if (!ok)
		return cli_usage("video", "%s %s: expected a number in %s%g, %g]", opt, text,
		                 open_lo ? "(" : "[", lo, hi);
	*out = x;
	return CLI_OK;
}

static int parse_size(video_args *a, const char *text)
{
	long w, h;
	char wbuf[16];
	size_t n = strcspn(text, "x");
	if (text[n] != 'x' || n == 0 || n >= sizeof wbuf)
		return cli_usage("video", "--size %s: expected WIDTHxHEIGHT, e.g. 1280x480", text);
	snprintf(wbuf, sizeof wbuf, "%.*s", (int)n, text);
	if (cli_parse_long(wbuf, 64, 7680, &w) != 0 ||
	    cli_parse_long(text + n + 1, 64, 4320, &h) != 0 || w % 2 || h % 2)
		return cli_usage("video",
		                 "--size %s: expected even WIDTHxHEIGHT from 64x64 to 7680x4320",
		                 text);
	a->def.width = (int)w;
	a->def.height = (int)h;
	return CLI_OK;
}

static int video_option(video_args *a, int c)
{
	switch (c) {
	case OPT_OUT:
		a->out = optarg;
		return CLI_OK;
	case OPT_BACKEND:
		a->has_backend = 1;
		a->n_backends = 1;
		if (strlen(optarg) >= sizeof a->names[0])
			return cli_usage("video", "--backend %s: unknown backend", optarg);
		snprintf(a->names[0], sizeof a->names[0], "%s", optarg);
		return CLI_OK;
	case OPT_BACKENDS:
		a->has_backends = 1;
		return parse_backends(a, optarg);
	case OPT_BACKEND_OPT:
		if (a->n_pending == (int)(sizeof a->pending / sizeof a->pending[0]) ||
		    strlen(optarg) >= sizeof a->pending[0])
			return cli_usage("video", "--backend-opt %s: too many or too long", optarg);
		snprintf(a->pending[a->n_pending++], sizeof a->pending[0], "%s", optarg);
		return CLI_OK;
	case OPT_SEED:
		if (cli_parse_u64(optarg, &a->seed) != 0)
			return cli_usage("video", "--seed %s: expected an integer >= 0", optarg);
		return CLI_OK;
	case OPT_GROUP:
		if (cli_parse_long(optarg, 0, INT32_MAX, &a->group) != 0)
			return cli_usage("video", "--group %s: expected an integer >= 0", optarg);
		return CLI_OK;
	case OPT_TRIAL:
		if (cli_parse_long(optarg, 0, INT32_MAX, &a->trial) != 0)
			return cli_usage("video", "--trial %s: expected an integer >= 0", optarg);
		return CLI_OK;
	case OPT_SET:
		return cli_sets_add(&a->sets, "video", optarg);
	case OPT_FPS:
		return parse_number("--fps", optarg, 0.0, 1000.0, 1, &a->def.fps);
	case OPT_SIZE:
		return parse_size(a, optarg);
	case OPT_HOLD:
		return parse_number("--hold", optarg, 0.0, 60.0, 0, &a->def.hold);
	case OPT_VIEW:
		return parse_number("--view", optarg, 0.0, 1e6, 1, &a->def.view_span);
	}
	return CLI_USAGE;
}

/* Fills a; returns -1 to go on, else the exit status. */
static int video_parse(int argc, char **argv, video_args *a)
{
	int c;
	opterr = 0;
	while ((c = getopt_long(argc, argv, ":h", video_options, NULL)) != -1) {
		if (c == 'h') {
			fputs(video_help, stdout);
			return CLI_OK;
		}
		if (c == '?' || c == ':')
			return cli_bad_option("video", argv, c);
		int rc = video_option(a, c);
		if (rc != CLI_OK)
			return rc;
	}
	if (optind + 1 != argc)
		return cli_usage("video",
		                 optind == argc ? "missing SCENE" : "expected one SCENE, got %d",
		                 argc - optind);
	a->scene = argv[optind];
	if (!a->out)
		return cli_usage("video", "--out FILE.mp4 is required");
	if (a->has_backend && a->has_backends)
		return cli_usage("video", "--backend and --backends: give one of them");
	if (a->def.width && a->def.width / a->n_backends < 64)
		return cli_usage("video", "--size %dx%d: less than 64 pixels a panel for %d panels",
		                 a->def.width, a->def.height, a->n_backends);
	for (int i = 0; i < a->n_pending; i++) {
		int rc = backend_opt(a, a->pending[i]);
		if (rc != CLI_OK)
			return rc;
	}
	return -1;
}

static void print_outcome(FILE *out, const char *name, const bsim_trial_result *r)
{
	fprintf(out, "%-11s %s at t = %.6g s", name, bsim_trial_outcome_name(r->outcome), r->t_end);
	if (r->outcome == BSIM_TRAVERSED)
		fprintf(out, ", %s type", bsim_trial_type_name(r->type));
	else if (r->outcome == BSIM_STUCK)
		fprintf(out, ", %s", r->in_contact_end ? "in contact" : "not in contact");
	fprintf(out, ", %d steps run\n", r->steps_run);
}

/* Records every backend's trial and writes the video. */
static int video_main(video_args *a, const bsim_backend *const *backends, const bsim_scene *scene)
{
	bsim_video_track *tracks[MAX_PANELS] = {0};
	const char *labels[MAX_PANELS];
	uint64_t mixed = bsim_schedule_seed_mix(a->seed, (uint64_t)a->group, (uint64_t)a->trial);
	bsim_error err;
	int rc = BSIM_OK;
	for (int i = 0; i < a->n_backends && rc == BSIM_OK; i++) {
		labels[i] = a->names[i];
		rc = bsim_video_track_record(scene, backends[i], &a->opts[i], mixed, a->def.fps,
		                             &tracks[i], &err);
	}
	bsim_video *v = NULL;
	if (rc == BSIM_OK)
		rc = bsim_video_alloc(&a->def, scene, (const bsim_video_track *const *)tracks,
		                      labels, a->n_backends, &v, &err);
	if (rc == BSIM_OK)
		rc = bsim_video_write(v, a->out, &err);
	/* A video on standard output keeps it to itself: the report goes to
	 * standard error. */
	FILE *out = strcmp(a->out, "-") == 0 ? stderr : stdout;
	if (rc == BSIM_OK) {
		fprintf(out, "scene       %s (%s), seed %" PRIu64 ", group %ld, trial %ld\n",
		        a->scene, scene->name, a->seed, a->group, a->trial);
		for (int i = 0; i < a->n_backends; i++)
			print_outcome(out, a->names[i], bsim_video_track_result(tracks[i]));
		if (a->n_backends > 1) {
			double t = bsim_video_track_separation(tracks[0], tracks[1],
			                                       0.01 * scene->body.radius);
			if (t >= 0.0)
				fprintf(out,
				        "paths part  at t = %.6g s (%s and %s more than 1%% of the "
				        "body radius apart)\n",
				        t, a->names[0], a->names[1]);
			else
				fprintf(out,
				        "paths part  never (%s and %s stay within 1%% of the body "
				        "radius)\n",
				        a->names[0], a->names[1]);
		}
		int w, h;
		bsim_video_size(v, &w, &h);
		long frames = bsim_video_frames(v);
		fprintf(out, "wrote       %s: %dx%d, H.264 yuv420p, %g fps, %ld frames, %.6g s\n",
		        a->out, w, h, a->def.fps, frames, (double)frames / a->def.fps);
	}
	bsim_video_free(v);
	for (int i = 0; i < a->n_backends; i++)
		bsim_video_track_free(tracks[i]);
	return cli_report(rc, &err);
}

int cmd_video(int argc, char **argv)
{
	video_args *a = calloc(1, sizeof *a);
	if (!a) {
		cli_error("out of memory");
		return CLI_FAIL;
	}
	a->seed = 1;
	a->n_backends = 1;
	snprintf(a->names[0], sizeof a->names[0], "thesis");
	a->def = bsim_video_def_default();
	int rc = video_parse(argc, argv, a);
	if (rc < 0) {
		const bsim_backend *backends[MAX_PANELS];
		rc = CLI_OK;
		for (int i = 0; i < a->n_backends && rc == CLI_OK; i++)
			if (!(backends[i] = cli_backend(a->names[i], &a->opts[i])))
				rc = CLI_USAGE;
		bsim_scene scene;
		bsim_error err;
		if (rc == CLI_OK &&
		    bsim_scene_load(a->scene, a->sets.ov, a->sets.n, &scene, &err) != BSIM_OK) {
			cli_error("%s", err.msg);
			rc = err.code ? err.code : CLI_USAGE;
		} else if (rc == CLI_OK) {
			rc = video_main(a, backends, &scene);
			bsim_scene_free(&scene);
		}
	}
	cli_sets_free(&a->sets);
	free(a);
	return rc;
}
