/* beamsim video: an MP4 of one trial, the trial `beamsim run` runs with the
 * same arguments, on one backend or on several side by side with the same
 * schedule. Parsing and printing only; the library draws and encodes
 * (beamsim/video.h). */
#define _POSIX_C_SOURCE 200809L

#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/lattice.h"
#include "beamsim/run_output.h"
#include "beamsim/schedule.h"
#include "beamsim/video.h"
#include "beamsim/lattice_outcome.h"
#include "cli/cli_common.h"
#include "cli/cli_options.h"
#include "cli/cli_replay.h"

enum { OWN_BACKENDS, OWN_GROUP, OWN_TRIAL, OWN_FPS, OWN_SIZE, OWN_HOLD, OWN_VIEW, OWN_CRF };

static const cli_own video_own[] = {
        [OWN_BACKENDS] = {"backends", 1, "A,B",
                          "backends side by side, a panel each, each named once\n"
                          "(1 to 4 names of `beamsim backends`: {backends})"},
        [OWN_GROUP] = {"group", 1, "G",
                       "group, from 0: an experiment's grid values and the\n"
                       "seed (default 0)"},
        [OWN_TRIAL] = {"trial", 1, "I", "trial of the group, from 0 (default 0)"},
        [OWN_FPS] = {"fps", 1, "F",
                     "frames per second of simulated time, 0.01 to 1000 (default 30)"},
        [OWN_SIZE] = {"size", 1, "WxH", "frame size in pixels, even (default 540x540 a panel)"},
        [OWN_HOLD] = {"hold", 1, "S", "seconds the last frame is held (default 1)"},
        [OWN_VIEW] = {"view", 1, "M",
                      "metres the shorter side of a panel shows at most; a\n"
                      "larger field is followed by the camera (default 200)"},
        [OWN_CRF] = {"crf", 1, "N", "x264 quality, 0 (lossless) to 51 (smallest); default 23"},
};

static const char *const video_help[CLI_N_OPTS] = {
        [CLI_OPT_OUT] = "the video to write (required)",
        [CLI_OPT_SEED] = "experiment seed (default: the experiment's, a scene's 1;\n"
                         "not with DIR, whose seed is stored)",
};

#define MAX_PANELS BSIM_VIDEO_PANELS_MAX

typedef struct video_args {
	const char *scene, *out;
	int n_backends, has_backends;
	char names[MAX_PANELS][32];
	bsim_options opts[MAX_PANELS];
	uint64_t seed;
	long group, trial;
	int has_group;
	bsim_video_def def;
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

static int video_option(void *args, int i, const char *value)
{
	video_args *a = args;
	switch (i) {
	case OWN_BACKENDS:
		a->has_backends = 1;
		return parse_backends(a, value);
	case OWN_GROUP:
		if (cli_parse_long(value, 0, INT32_MAX, &a->group) != 0)
			return cli_usage("video", "--group %s: expected an integer >= 0", value);
		a->has_group = 1;
		return CLI_OK;
	case OWN_TRIAL:
		if (cli_parse_long(value, 0, INT32_MAX, &a->trial) != 0)
			return cli_usage("video", "--trial %s: expected an integer >= 0", value);
		return CLI_OK;
	case OWN_FPS:
		/* Below 0.01 a frame lasts over 100 s; ffmpeg's MP4 muxer refuses
		 * frames of 1e6 s ("Application provided duration ... is invalid"). */
		return parse_number("--fps", value, 0.01, 1000.0, 0, &a->def.fps);
	case OWN_SIZE:
		return parse_size(a, value);
	case OWN_HOLD:
		return parse_number("--hold", value, 0.0, 60.0, 0, &a->def.hold);
	case OWN_VIEW:
		return parse_number("--view", value, 0.0, 1e6, 1, &a->def.view_span);
	case OWN_CRF: {
		long crf;
		if (cli_parse_long(value, 0, 51, &crf) != 0)
			return cli_usage("video", "--crf %s: expected an integer 0 to 51", value);
		a->def.crf = (int)crf;
		return CLI_OK;
	}
	}
	return CLI_USAGE;
}

static const cli_spec video_spec = {
        .name = "video",
        .usage = "SCENE|EXPERIMENT|DIR --out FILE.mp4 [OPTIONS]",
        .about = "Writes an MP4 (H.264, yuv420p) of one trial: the trial beamsim run runs\n"
                 "with the same SCENE, EXPERIMENT or DIR (trial I of group G of an\n"
                 "experiment as its sweep runs it, or of the sweep or comparison stored\n"
                 "in DIR; see beamsim run --help), --seed, --group, --trial and --set. A\n"
                 "frame shows the beams coloured by stiffness (with the scale), the body and\n"
                 "its trail, the random force as an arrow (one body radius per Rm), the time,\n"
                 "the kinetic, spring and propulsive potential energies, and the outcome once\n"
                 "it is decided. A field larger than the view is followed by the camera.\n"
                 "With --backends A,B the backends run the same schedule side by side, each\n"
                 "panel showing the other's trail in grey and where the two paths part.\n"
                 "Frames are drawn with cairo and encoded by ffmpeg (Debian package ffmpeg).\n"
                 "The file appears whole or not at all.\n",
        .positional = "SCENE|EXPERIMENT|DIR",
        .common = CLI_USES(CLI_OPT_OUT) | CLI_USES(CLI_OPT_BACKEND) |
                  CLI_USES(CLI_OPT_BACKEND_OPT) | CLI_USES(CLI_OPT_SEED) | CLI_USES(CLI_OPT_SET) |
                  CLI_USES(CLI_OPT_GRID),
        .help = video_help,
        .out_arg = "FILE.mp4",
        .out_required = 1,
        .own = video_own,
        .n_own = 8,
        .option = video_option,
};

/* After parsing: the backends (--backend or --backends) and their options. */
static int video_resolve(const cli_common *c, video_args *a, int stored)
{
	a->out = c->out;
	a->seed = c->has_seed ? c->seed : a->seed;
	/* A stored run's side is its backend, with its options. */
	if (stored && a->has_backends)
		return cli_usage("video",
		                 "--backends: %s holds a stored run with its own backend "
		                 "(a comparison's side: --backend LABEL)",
		                 a->scene);
	if (stored)
		return CLI_OK;
	if (c->backend && a->has_backends)
		return cli_usage("video", "--backend and --backends: give one of them");
	if (c->backend) {
		if (strlen(c->backend) >= sizeof a->names[0])
			return cli_usage("video", "--backend %s: unknown backend", c->backend);
		snprintf(a->names[0], sizeof a->names[0], "%s", c->backend);
	}
	if (a->def.width && a->def.width / a->n_backends < 64)
		return cli_usage("video", "--size %dx%d: less than 64 pixels a panel for %d panels",
		                 a->def.width, a->def.height, a->n_backends);
	const char *names[MAX_PANELS];
	bsim_options *opts[MAX_PANELS];
	for (int i = 0; i < a->n_backends; i++) {
		names[i] = a->names[i];
		opts[i] = &a->opts[i];
	}
	return cli_backend_opts(c, "video", a->n_backends, names, opts);
}

static void print_outcome(FILE *out, const char *name, const bsim_scene *s,
                          const bsim_trial_result *r)
{
	fprintf(out, "%-11s %s at t = %.6g s", name, bsim_trial_outcome_name(r->outcome), r->t_end);
	if (s->has_lattice) {
		char loc[48];
		bsim_lattice_location_label(bsim_lattice_location_of(r), loc, sizeof loc);
		fprintf(out, ", ended %s, %d gates entered, %d steps run\n", loc, r->gates_entered,
		        r->steps_run);
		return;
	}
	if (r->outcome == BSIM_TRAVERSED)
		fprintf(out, ", %s type", bsim_trial_type_name(r->type));
	else if (r->outcome == BSIM_STUCK)
		fprintf(out, ", %s", r->in_contact_end ? "in contact" : "not in contact");
	fprintf(out, ", %d steps run\n", r->steps_run);
}

/* Streams the video of the trial on every backend (bsim_video_stream_*:
 * its memory does not grow with the trial's steps) and reports it. */
static int video_main(video_args *a, const bsim_backend *const *backends, const bsim_replay *rp)
{
	const bsim_scene *scene = &rp->scene;
	const char *labels[MAX_PANELS];
	const bsim_options *opts[MAX_PANELS];
	for (int i = 0; i < a->n_backends; i++) {
		labels[i] = a->names[i];
		opts[i] = &a->opts[i];
	}
	uint64_t mixed = bsim_schedule_seed_mix(a->seed, (uint64_t)a->group, (uint64_t)a->trial);
	bsim_error err;
	bsim_video_report rep;
	bsim_video_stream *vs = NULL;
	a->def.stop = &cli_stop;
	int rc = bsim_video_stream_alloc(&a->def, scene, backends, opts, labels, a->n_backends,
	                                 mixed, &vs, &err);
	/* While ffmpeg writes its temporary file, SIGINT and SIGTERM stop the
	 * video and remove it; before, they end the program, which has
	 * written nothing yet. */
	if (rc == BSIM_OK) {
		cli_signals_install();
		rc = bsim_video_stream_write(vs, a->out, &rep, &err);
		cli_signals_restore();
	}
	bsim_video_stream_free(vs);
	if (rc == BSIM_ESTOPPED) {
		int sig = cli_stop ? (int)cli_stop : SIGINT;
		cli_error("%s: %s", sig == SIGTERM ? "SIGTERM" : "SIGINT", err.msg);
		rc = 128 + sig;
	}
	/* A video on standard output keeps it to itself: the report goes to
	 * standard error. */
	FILE *out = strcmp(a->out, "-") == 0 ? stderr : stdout;
	if (rc == BSIM_OK) {
		fprintf(out, "scene       %s (%s), seed %" PRIu64 ", group %ld, trial %ld\n",
		        cli_path(rp->scene_path), scene->name, a->seed, a->group, a->trial);
		if (rp->kind != BSIM_REPLAY_SCENE)
			fprintf(out, "grid        %s of %s\n", rp->grid, cli_path(rp->path));
		for (int i = 0; i < a->n_backends; i++)
			print_outcome(out, a->names[i], scene, &rep.results[i]);
		if (a->n_backends > 1) {
			double t = rep.t_part;
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
		fprintf(out, "wrote       %s: %dx%d, H.264 yuv420p, %g fps, %ld frames, %.6g s\n",
		        cli_path(a->out), rep.width, rep.height, a->def.fps, rep.frames,
		        (double)rep.frames / a->def.fps);
		return cli_replay_check(rp, &rep.results[0], out);
	}
	return rc > BSIM_ESTOPPED ? rc : cli_report(rc, &err);
}

int cmd_video(int argc, char **argv)
{
	video_args *a = calloc(1, sizeof *a);
	if (!a) {
		cli_error("out of memory");
		return CLI_FAIL;
	}
	a->seed = bsim_run_info_default().seed; /* the trial beamsim run runs */
	a->n_backends = 1;
	snprintf(a->names[0], sizeof a->names[0], "%s", bsim_backend_default()->name);
	a->def = bsim_video_def_default();
	cli_common c = cli_common_default();
	int rc = cli_parse(&video_spec, argc, argv, &c, a, &a->scene);
	int stored = rc < 0 && bsim_replay_is_dir(a->scene);
	if (rc < 0 && (rc = video_resolve(&c, a, stored)) == CLI_OK)
		rc = -1;
	if (rc < 0) {
		const bsim_backend *backends[MAX_PANELS];
		rc = CLI_OK;
		for (int i = 0; !stored && i < a->n_backends && rc == CLI_OK; i++)
			if (!(backends[i] = cli_backend(a->names[i], &a->opts[i])))
				rc = CLI_USAGE;
		bsim_replay *rp;
		if (rc == CLI_OK)
			rc = cli_replay_open("video", a->scene, &c, a->group, a->trial,
			                     a->has_group, a->seed, &rp);
		if (rc == CLI_OK) {
			if (stored) {
				backends[0] = rp->backend;
				a->opts[0] = rp->opts;
				snprintf(a->names[0], sizeof a->names[0], "%.31s", rp->label);
			}
			a->seed = rp->seed;
			rc = video_main(a, backends, rp);
			bsim_replay_free(rp);
		}
	}
	cli_common_free(&c);
	free(a);
	return rc;
}
