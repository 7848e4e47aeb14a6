/* Writing a video as its trials run (bsim_video_stream_*, beamsim/video.h).
 *
 * A recorded track (video_track.c) keeps every step's centre and every
 * frame's beam angles before the first frame is drawn, so its memory grows
 * with the trial: a long lattice trial took gigabytes. A stream keeps only
 * what the frame being drawn needs, in two passes over the same trial
 * (same seed, same trial: the runner is deterministic):
 *
 * Pass 1 (bsim_video_stream_alloc) runs each panel's trial without
 * recording anything per step, for what a frame must know before the trial
 * reaches it: the last step N (the frame count, and which frame is the end
 * state), the outcome and the step it is decided at (the title shows it
 * from there, but a traversal's type is known only at classify_y, later),
 * and the runner's gate path (an entry a gate, which a lattice's frames
 * tint).
 *
 * Pass 2 (bsim_video_stream_write) runs them again, one thread a panel, all
 * in step: a panel's trace callback (the runner's, called after every step)
 * collects the centres of the steps since the last frame and, at a frame's
 * step, the frame's state (bsim_video_frame_take), hands both to the drawing
 * thread and goes on to the next frame while that one is drawn; it waits
 * only if the frame before is still not taken. The drawing thread waits for frame k from every
 * panel whose trial has not ended, compares the centres step by step where two panels part
 * (bsim_video_track_separation's rule), adds them to the trails thinned for each view
 * (video_trail.c), draws and encodes the frame. The second run must end as the first did (steps
 * run, outcome), else the stream fails: a backend that does not repeat a trial cannot be streamed.
 *
 * Held at any time: three frames' state a panel (n_beams angles as float
 * and contacts; the one drawn, the one handed over, the one being made),
 * the centres of at most one frame interval of steps, 16 bytes each, the
 * trails (24 bytes a point, a point per 0.75 px the body travels), the gate
 * path and the frame's pixels. Nothing grows with the steps but the trails
 * with the distance travelled and, inside the runner, the random-force
 * schedule's drawn values (8 bytes each, one per 1/f seconds). */
#define _POSIX_C_SOURCE 200809L

#include "beamsim/video.h"

#include <math.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "video/video_internal.h"

/* A frame as a panel hands it over: its state and the centres of steps
 * first .. first + n - 1 (those since the panel's previous frame). */
typedef struct stream_buf {
	video_frame f;
	float *theta;
	unsigned char *contact;
	double *xy;
	long first, n, cap;
} stream_buf;

struct stream;

typedef struct stream_panel {
	struct stream *s;
	const bsim_backend *backend;
	const bsim_options *opts;
	bsim_video_track *summary; /* pass 1 */
	long frames, n_last;
	/* the worker's */
	long k_next;
	stream_buf build;
	int oom, stopped;
	bsim_trial_result result; /* pass 2 */
	int rc;
	bsim_error err;
	/* under the lock */
	stream_buf slot;
	int full, done;
	/* the drawing thread's */
	stream_buf cur;
	pthread_t thread;
	int started;
} stream_panel;

typedef struct stream {
	pthread_mutex_t lock;
	pthread_cond_t cond;
	atomic_int cancel;
	const bsim_scene *scene;
	uint64_t seed;
	double fps;
	int n;
	stream_panel panels[BSIM_VIDEO_PANELS_MAX];
} stream;

struct bsim_video_stream {
	stream s;
	bsim_video *v;
	int sync;    /* the lock and condition are made */
	int written; /* a stream writes one video */
};

static int buf_init(stream_buf *b, int n_beams)
{
	size_t nb = (size_t)(n_beams > 0 ? n_beams : 1);
	b->theta = malloc(nb * sizeof *b->theta);
	b->contact = malloc(nb);
	return b->theta && b->contact ? 0 : -1;
}

static void buf_free(stream_buf *b)
{
	free(b->theta);
	free(b->contact);
	free(b->xy);
}

static void buf_swap(stream_buf *a, stream_buf *b)
{
	stream_buf t = *a;
	*a = *b;
	*b = t;
}

/* The step frame k of a trial ending at n_last shows. */
static long stream_frame_step(const stream *s, long k, long n_last)
{
	long n = bsim_video_frame_step(s->fps, s->scene->dt, k);
	return n < n_last ? n : n_last;
}

/* Hands the frame made over to the drawing thread once it has taken the
 * one before; the next frame is made in the buffer it gave back. */
static void stream_deliver(stream_panel *sp, long step)
{
	stream *s = sp->s;
	pthread_mutex_lock(&s->lock);
	while (sp->full && !atomic_load(&s->cancel))
		pthread_cond_wait(&s->cond, &s->lock);
	if (atomic_load(&s->cancel)) {
		sp->stopped = 1;
	} else {
		buf_swap(&sp->build, &sp->slot);
		sp->full = 1;
		pthread_cond_broadcast(&s->cond);
	}
	pthread_mutex_unlock(&s->lock);
	sp->build.first = step + 1;
	sp->build.n = 0;
}

static void stream_trace(void *user, long step, const bsim_state *st)
{
	stream_panel *sp = user;
	stream *s = sp->s;
	stream_buf *b = &sp->build;
	if (sp->oom || sp->stopped || atomic_load(&s->cancel))
		return;
	if (b->n == b->cap) {
		long cap = b->cap ? 2 * b->cap : 256;
		double *xy = realloc(b->xy, (size_t)cap * 2 * sizeof *xy);
		if (!xy) {
			sp->oom = 1;
			return;
		}
		b->xy = xy;
		b->cap = cap;
	}
	b->xy[2 * b->n] = st->x[0];
	b->xy[2 * b->n + 1] = st->x[1];
	b->n++;
	/* Several frames fall on one step when fps h > 1. */
	while (!sp->stopped && sp->k_next < sp->frames &&
	       stream_frame_step(s, sp->k_next, sp->n_last) == step) {
		bsim_video_frame_take(s->scene, bsim_video_track_effects(sp->summary), step, st,
		                      &sp->build.f, sp->build.theta, sp->build.contact);
		stream_deliver(sp, step);
		sp->k_next++;
	}
}

static void *stream_worker(void *arg)
{
	stream_panel *sp = arg;
	stream *s = sp->s;
	bsim_trial_runner *runner = bsim_trial_runner_alloc();
	bsim_trial_log *log = bsim_trial_log_alloc();
	/* The recorder of bsim_video_track_record: trace and gate log. */
	bsim_recorder rec = {.csv = NULL,
	                     .stride = 1,
	                     .trace = stream_trace,
	                     .trace_user = sp,
	                     .trace_whole = 1,
	                     .log = log};
	if (!runner || !log)
		sp->rc = bsim_error_set(&sp->err, BSIM_EFAIL, "out of memory for a video");
	else
		sp->rc = bsim_trial_run(runner, s->scene, sp->backend, sp->opts, s->seed, &rec,
		                        &sp->result, &sp->err);
	bsim_trial_runner_free(runner);
	bsim_trial_log_free(log);
	if (sp->rc == BSIM_OK && sp->oom)
		sp->rc = bsim_error_set(&sp->err, BSIM_EFAIL,
		                        "out of memory for the steps of a video frame");
	pthread_mutex_lock(&s->lock);
	sp->done = 1;
	pthread_cond_broadcast(&s->cond);
	pthread_mutex_unlock(&s->lock);
	return NULL;
}

/* Takes frame k of panel p from its worker; BSIM_EFAIL if the worker ended
 * without it. */
static int stream_take(stream *s, int p, bsim_error *err)
{
	stream_panel *sp = &s->panels[p];
	pthread_mutex_lock(&s->lock);
	while (!sp->full && !sp->done)
		pthread_cond_wait(&s->cond, &s->lock);
	const int got = sp->full;
	if (got) {
		buf_swap(&sp->slot, &sp->cur);
		sp->full = 0;
		pthread_cond_broadcast(&s->cond);
	}
	pthread_mutex_unlock(&s->lock);
	if (got)
		return BSIM_OK;
	if (sp->rc != BSIM_OK)
		return bsim_error_set(err, sp->rc, "%s", sp->err.msg);
	return bsim_error_set(err, BSIM_EFAIL,
	                      "panel %d: the trial's second run ended at step %d, its first at "
	                      "step %ld: a video streams a trial that repeats",
	                      p + 1, sp->result.steps_run, sp->n_last);
}

/* The frame taken from panel p: its centres into the trails and the marks,
 * its state into the panel. */
static int stream_use(stream *s, bsim_video *v, int p, long *steps_held)
{
	stream_panel *sp = &s->panels[p];
	video_panel *pn = &v->panels[p];
	const stream_buf *b = &sp->cur;
	if (b->n > *steps_held)
		*steps_held = b->n;
	for (long i = 0; i < b->n; i++) {
		const long step = b->first + i;
		const double *x = b->xy + 2 * i;
		if (bsim_video_panel_trail_add(v, p, step, x))
			return -1;
		/* The centre at a step another panel ends at: its last frames
		 * draw this trail up to there. */
		for (int q = 0; q < s->n; q++)
			if (q != p && s->panels[q].n_last == step &&
			    pn->n_marks < BSIM_VIDEO_PANELS_MAX)
				pn->marks[pn->n_marks++] = (video_mark){step, {x[0], x[1]}};
	}
	pn->now = (bsim_video_sample){
	        .step = b->f.step,
	        .t = (double)b->f.step * s->scene->dt,
	        .x = {b->f.x[0], b->f.x[1]},
	        .f_rand = b->f.f_rand,
	        .e_kin = b->f.e_kin,
	        .e_spring = b->f.e_spring,
	        .e_prop = b->f.e_prop,
	        .theta = b->theta,
	        .contact = b->contact,
	};
	return 0;
}

/* Where panels p and q, both at frame k, first part over the steps of this
 * frame's interval: panel p's t_part and centre then. */
static void stream_part(stream *s, bsim_video *v, int p, int q)
{
	const stream_buf *a = &s->panels[p].cur, *b = &s->panels[q].cur;
	const double sep = 0.01 * s->scene->body.radius;
	long lo = a->first > b->first ? a->first : b->first;
	long hi = a->first + a->n < b->first + b->n ? a->first + a->n : b->first + b->n;
	for (long n = lo; n < hi; n++) {
		const double *xa = a->xy + 2 * (n - a->first), *xb = b->xy + 2 * (n - b->first);
		if (hypot(xa[0] - xb[0], xa[1] - xb[1]) > sep) {
			v->t_part[p] = (double)n * s->scene->dt;
			v->panels[p].part_x[0] = xa[0];
			v->panels[p].part_x[1] = xa[1];
			return;
		}
	}
}

/* Pass 2: starts the workers, draws and encodes every frame, holds the
 * last; stops the workers and waits for them. */
static int stream_write(stream *s, bsim_video *v, const char *path, bsim_video_report *rep,
                        bsim_error *err)
{
	const size_t n_px = (size_t)v->width * (size_t)v->height;
	uint32_t *pixels = malloc(n_px * sizeof *pixels);
	if (!pixels)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory for a %d x %d frame",
		                      v->width, v->height);
	int rc = BSIM_OK;
	for (int p = 0; p < s->n && rc == BSIM_OK; p++) {
		stream_panel *sp = &s->panels[p];
		const int nb = s->scene->n_beams;
		if (buf_init(&sp->build, nb) || buf_init(&sp->slot, nb) || buf_init(&sp->cur, nb))
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory for a video");
	}
	bsim_video_encoder *enc = NULL;
	if (rc == BSIM_OK)
		rc = bsim_video_encoder_open(path, v->def.ffmpeg, v->width, v->height, v->def.fps,
		                             v->def.crf, &enc, err);
	/* The workers take no asynchronous signal: a stop or a closed pipe is
	 * the drawing thread's to see (a fault stays with the thread at fault). */
	static const int async[] = {SIGINT,  SIGTERM, SIGHUP,  SIGQUIT, SIGPIPE,
	                            SIGCHLD, SIGALRM, SIGUSR1, SIGUSR2};
	sigset_t mask, old;
	sigemptyset(&mask);
	for (size_t i = 0; i < sizeof async / sizeof async[0]; i++)
		sigaddset(&mask, async[i]);
	pthread_sigmask(SIG_BLOCK, &mask, &old);
	for (int p = 0; p < s->n && rc == BSIM_OK; p++) {
		stream_panel *sp = &s->panels[p];
		if (pthread_create(&sp->thread, NULL, stream_worker, sp) != 0)
			rc = bsim_error_set(err, BSIM_EFAIL, "cannot start a thread for panel %d",
			                    p + 1);
		else
			sp->started = 1;
	}
	pthread_sigmask(SIG_SETMASK, &old, NULL);
	for (long k = 0; rc == BSIM_OK && k < v->frames; k++) {
		if (v->def.stop && *v->def.stop)
			break;
		if (k < v->frames_sim) {
			for (int p = 0; p < s->n && rc == BSIM_OK; p++)
				if (k < s->panels[p].frames) {
					rc = stream_take(s, p, err);
					if (rc == BSIM_OK && stream_use(s, v, p, &rep->steps_held))
						rc = bsim_error_set(err, BSIM_EFAIL,
						                    "out of memory for a trail");
				}
			for (int p = 0; p < s->n && s->n > 1 && rc == BSIM_OK; p++) {
				int q = p == 0 ? 1 : 0;
				if (v->t_part[p] < 0.0 && k < s->panels[p].frames &&
				    k < s->panels[q].frames)
					stream_part(s, v, p, q);
			}
			if (rc == BSIM_OK)
				rc = bsim_video_render(v, k, pixels, err);
		}
		if (rc == BSIM_OK)
			rc = bsim_video_encoder_write(enc, pixels, err);
	}
	/* A signal also reaches ffmpeg when it comes from the terminal, so a
	 * frame that could not be written then is the stop, not a failure. */
	if (enc && v->def.stop && *v->def.stop)
		rc = bsim_error_set(err, BSIM_ESTOPPED, "%s: stopped; no video written", path);
	/* A stop or a failure removes the temporary file at once. It ends the
	 * workers' drawing, not their trials: those run on to their end (the
	 * runner cannot be interrupted), without frames. */
	if (rc != BSIM_OK) {
		bsim_video_encoder_abort(enc);
		enc = NULL;
	}
	pthread_mutex_lock(&s->lock);
	atomic_store(&s->cancel, 1);
	pthread_cond_broadcast(&s->cond);
	pthread_mutex_unlock(&s->lock);
	for (int p = 0; p < s->n; p++)
		if (s->panels[p].started)
			pthread_join(s->panels[p].thread, NULL);
	for (int p = 0; p < s->n && rc == BSIM_OK; p++) {
		const stream_panel *sp = &s->panels[p];
		const bsim_trial_result *r1 = bsim_video_track_result(sp->summary);
		if (sp->rc != BSIM_OK)
			rc = bsim_error_set(err, sp->rc, "%s", sp->err.msg);
		else if (sp->result.steps_run != r1->steps_run || sp->result.steps != r1->steps ||
		         sp->result.outcome != r1->outcome)
			rc = bsim_error_set(
			        err, BSIM_EFAIL,
			        "panel %d: the trial's second run ended at step %d (%s), "
			        "its first at step %d (%s): a video streams a trial that "
			        "repeats",
			        p + 1, sp->result.steps_run,
			        bsim_trial_outcome_name(sp->result.outcome), r1->steps_run,
			        bsim_trial_outcome_name(r1->outcome));
	}
	if (rc == BSIM_OK)
		rc = bsim_video_encoder_close(enc, err);
	else
		bsim_video_encoder_abort(enc);
	for (int p = 0; p < s->n; p++) {
		buf_free(&s->panels[p].build);
		buf_free(&s->panels[p].slot);
		buf_free(&s->panels[p].cur);
	}
	free(pixels);
	return rc;
}

void bsim_video_stream_free(bsim_video_stream *vs)
{
	if (!vs)
		return;
	if (vs->sync) {
		pthread_cond_destroy(&vs->s.cond);
		pthread_mutex_destroy(&vs->s.lock);
	}
	for (int p = 0; p < vs->s.n; p++)
		bsim_video_track_free(vs->s.panels[p].summary);
	bsim_video_teardown(vs->v);
	free(vs);
}

int bsim_video_stream_alloc(const bsim_video_def *def, const bsim_scene *scene,
                            const bsim_backend *const *backends, const bsim_options *const *opts,
                            const char *const *labels, int n_panels, uint64_t seed,
                            bsim_video_stream **out, bsim_error *err)
{
	*out = NULL;
	int rc = bsim_video_def_check(def, err);
	if (rc == BSIM_OK)
		rc = bsim_video_scene_check(scene, err);
	if (rc != BSIM_OK)
		return rc;
	if (n_panels < 1 || n_panels > BSIM_VIDEO_PANELS_MAX)
		return bsim_error_set(err, BSIM_EINPUT, "a video has 1 to %d panels, not %d",
		                      BSIM_VIDEO_PANELS_MAX, n_panels);
	bsim_video_stream *vs = calloc(1, sizeof *vs);
	bsim_video *v = calloc(1, sizeof *v);
	if (!vs || !v) {
		free(vs);
		free(v);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory for a video");
	}
	vs->v = v;
	stream *s = &vs->s;
	s->scene = scene;
	s->seed = seed;
	s->fps = def->fps;
	/* Pass 1: each trial's end, outcome and gate path. */
	for (int p = 0; p < n_panels && rc == BSIM_OK; p++) {
		stream_panel *sp = &s->panels[p];
		sp->s = s;
		sp->backend = backends[p];
		sp->opts = opts ? opts[p] : NULL;
		rc = bsim_video_track_summary(scene, backends[p], sp->opts, seed, def->fps,
		                              &sp->summary, err);
		if (rc != BSIM_OK)
			break;
		s->n = p + 1;
		const bsim_trial_result *r = bsim_video_track_result(sp->summary);
		sp->n_last = r->steps_run;
		sp->frames = bsim_video_track_frames(sp->summary);
		video_panel *pn = &v->panels[p];
		pn->result = r;
		pn->frames = sp->frames;
		pn->last_step = sp->n_last;
		pn->visits = bsim_video_track_visits(sp->summary, &pn->n_visits);
		pn->random_axis = bsim_video_track_random_axis(sp->summary);
	}
	if (rc == BSIM_OK)
		rc = bsim_video_setup(v, def, scene, labels, n_panels, err);
	if (rc == BSIM_OK) {
		if (pthread_mutex_init(&s->lock, NULL) == 0) {
			if (pthread_cond_init(&s->cond, NULL) == 0)
				vs->sync = 1;
			else
				pthread_mutex_destroy(&s->lock);
		}
		if (!vs->sync)
			rc = bsim_error_set(err, BSIM_EFAIL, "cannot make a lock for a video");
	}
	if (rc != BSIM_OK) {
		bsim_video_stream_free(vs);
		return rc;
	}
	*out = vs;
	return BSIM_OK;
}

const bsim_trial_result *bsim_video_stream_result(const bsim_video_stream *vs, int panel)
{
	if (panel < 0 || panel >= vs->s.n)
		return NULL;
	return bsim_video_track_result(vs->s.panels[panel].summary);
}

int bsim_video_stream_write(bsim_video_stream *vs, const char *path, bsim_video_report *report,
                            bsim_error *err)
{
	bsim_video_report rep_local;
	bsim_video_report *rep = report ? report : &rep_local;
	memset(rep, 0, sizeof *rep);
	rep->t_part = -1.0;
	if (vs->written)
		return bsim_error_set(err, BSIM_EINPUT, "%s: a video stream writes one video",
		                      path);
	vs->written = 1;
	bsim_video *v = vs->v;
	stream *s = &vs->s;
	/* Pass 2. */
	int rc = stream_write(s, v, path, rep, err);
	if (rc != BSIM_OK)
		return rc;
	rep->t_part = s->n > 1 ? v->t_part[0] : -1.0;
	rep->frames = v->frames;
	rep->width = v->width;
	rep->height = v->height;
	for (int p = 0; p < s->n; p++) {
		rep->results[p] = *bsim_video_track_result(s->panels[p].summary);
		for (int i = 0; i < v->panels[p].n_own; i++)
			rep->trail_points += v->panels[p].own[i].n;
	}
	return BSIM_OK;
}
