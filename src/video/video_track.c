/* A trial recorded for a video (beamsim/video.h).
 *
 * The runner's trace callback sees the state after every step n. Every
 * step's body centre goes into the trail; frame k takes the state of step
 *   n_k = min(floor(k / (fps h)), N)
 * (the last step at or before the frame's time k / fps; N the trial's last
 * step), so a trial has ceil(N h fps) + 1 frames and the last one shows its
 * end state. Each frame keeps the energies of its state,
 *   E_kin = 1/2 M |v|^2 + sum 1/2 I_i omega_i^2,  E_spring = sum 1/2 k_i theta_i^2,
 *   E_prop = F_prop (y0 - y),
 * and the random force of step n_k. The force comes from a second effect
 * pipeline built from the same scene and seed: the schedule is a function of
 * (seed, index) alone (beamsim/schedule.h), so it gives the very values the
 * runner applies. Angles are kept as float, enough for a pixel. The
 * runner's own gate path (its log) is kept too: the gates entered and the
 * step of each entry, which a lattice's frames mark.
 *
 * A recorded track answers for any frame and any step, so it grows with the
 * trial: 16 bytes a step for the trail and 56 + 5 n_beams bytes a frame.
 * It is for stills, tests and short trials; beamsim video streams instead
 * (video_stream.c), running the trial twice: first as a summary (result,
 * frame count and gate path only, bsim_video_track_summary), then drawing each
 * frame as the trial reaches it. */
#include "beamsim/video.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/effects.h"
#include "beamsim/landscape.h"
#include "video/video_internal.h"

/* Frame scalars (video_frame); the angles and contacts live in the
 * track's arrays. */
typedef video_frame track_frame;

struct bsim_video_track {
	const bsim_scene *scene;
	double fps;
	bsim_trial_result result;
	int n_beams;
	double *trail; /* 2 (n_trail), body centre after steps 0, 1, ... */
	long n_trail, cap_trail;
	track_frame *frames;
	float *theta;           /* n_beams per frame */
	unsigned char *contact; /* n_beams per frame */
	long n_frames, cap_frames;
	bsim_effects fx; /* the same schedule as the runner's, for the force */
	long last_step;  /* a step after the last frame's, kept in the next slot; -1 none */
	int oom;
	video_gate_visit *visits; /* the gate path: the runner's entries in order */
	int n_visits;
	int summary; /* 1: a stream's first pass, no trail and no frames */
};

/* The step a frame shows. The 1e-9 keeps a frame time that is a whole
 * number of steps (k = 3 at 30 fps and 4 ms: 25 steps) on that step
 * whatever the rounding of k / (fps h). */
long bsim_video_frame_step(double fps, double dt, long k)
{
	return (long)floor((double)k / (fps * dt) + 1e-9);
}

static long frame_step(const bsim_video_track *t, long k)
{
	return bsim_video_frame_step(t->fps, t->scene->dt, k);
}

/* As bsim_video_track_record counts them: the frames whose step is at or
 * before n_last, and one more for the end state if no frame falls on
 * n_last, at most ceil(n_last h fps) + 1. */
long bsim_video_frame_count(double fps, double dt, long n_last)
{
	long k = (long)floor((double)n_last * fps * dt) - 2;
	if (k < 0 || bsim_video_frame_step(fps, dt, k) > n_last)
		k = 0;
	while (bsim_video_frame_step(fps, dt, k) <= n_last)
		k++;
	/* k frames at or before n_last; frame k - 1 is n_last's if any is */
	const long frames = (long)ceil((double)n_last * fps * dt - 1e-9) + 1;
	if (k >= frames)
		return frames;
	return bsim_video_frame_step(fps, dt, k - 1) == n_last ? k : k + 1;
}

static int grow(void **p, long *cap, long need, size_t size)
{
	if (need <= *cap)
		return 0;
	long c = *cap ? *cap : 256;
	while (c < need)
		c *= 2;
	void *q = realloc(*p, (size_t)c * size);
	if (!q)
		return -1;
	*p = q;
	*cap = c;
	return 0;
}

static int frames_reserve(bsim_video_track *t, long need)
{
	long cap = t->cap_frames;
	if (grow((void **)&t->frames, &cap, need, sizeof *t->frames))
		return -1;
	size_t nb = (size_t)(t->n_beams > 0 ? t->n_beams : 1);
	if (cap > t->cap_frames) {
		float *th = realloc(t->theta, (size_t)cap * nb * sizeof *th);
		if (!th)
			return -1;
		t->theta = th;
		unsigned char *c = realloc(t->contact, (size_t)cap * nb);
		if (!c)
			return -1;
		t->contact = c;
		t->cap_frames = cap;
	}
	return 0;
}

void bsim_video_frame_take(const bsim_scene *sc, bsim_effects *fx, long step, const bsim_state *s,
                           video_frame *f, float *th, unsigned char *ct)
{
	f->step = step;
	f->x[0] = s->x[0];
	f->x[1] = s->x[1];
	f->e_kin = 0.5 * sc->body.mass * (s->v[0] * s->v[0] + s->v[1] * s->v[1]);
	if (sc->body.rotates)
		f->e_kin += 0.5 * bsim_body_inertia(&sc->body) * s->angular_velocity *
		            s->angular_velocity;
	f->e_spring = 0.0;
	for (int i = 0; i < sc->n_beams; i++) {
		const bsim_beam_def *b = &sc->beams[i];
		f->e_kin += 0.5 * b->inertia * s->omega[i] * s->omega[i];
		f->e_spring += 0.5 * b->stiffness * s->theta[i] * s->theta[i];
		th[i] = (float)s->theta[i];
		ct[i] = (unsigned char)s->contact[i];
	}
	f->e_prop = bsim_landscape_e_prop(sc, s->x[1]);
	double force[BSIM_WRENCH];
	bsim_effects_force_at(fx, step, sc->dt, s, force);
	f->f_rand = fx->random ? fx->random->last : 0.0;
}

/* Writes the state of step `step` into frame slot k. */
static void frame_take(bsim_video_track *t, long k, long step, const bsim_state *s)
{
	bsim_video_frame_take(t->scene, &t->fx, step, s, &t->frames[k],
	                      t->theta + (size_t)k * (size_t)t->n_beams,
	                      t->contact + (size_t)k * (size_t)t->n_beams);
}

static void track_trace(void *user, long step, const bsim_state *s)
{
	bsim_video_track *t = user;
	if (t->oom)
		return;
	if (grow((void **)&t->trail, &t->cap_trail, t->n_trail + 1, 2 * sizeof(double))) {
		t->oom = 1;
		return;
	}
	t->trail[2 * t->n_trail] = s->x[0];
	t->trail[2 * t->n_trail + 1] = s->x[1];
	t->n_trail++;
	if (frames_reserve(t, t->n_frames + 1)) {
		t->oom = 1;
		return;
	}
	if (frame_step(t, t->n_frames) > step) {
		/* Not a frame's step: kept in the next slot in case it is the
		 * last step of the trial. */
		frame_take(t, t->n_frames, step, s);
		t->last_step = step;
		return;
	}
	while (frame_step(t, t->n_frames) <= step) {
		if (frames_reserve(t, t->n_frames + 1)) {
			t->oom = 1;
			return;
		}
		frame_take(t, t->n_frames, step, s);
		t->n_frames++;
	}
	t->last_step = -1;
}

static int track_run(const bsim_scene *scene, const bsim_backend *backend, const bsim_options *opts,
                     uint64_t seed, double fps, int summary, bsim_video_track **out,
                     bsim_error *err)
{
	*out = NULL;
	if (!(fps > 0.0) || !isfinite(fps))
		return bsim_error_set(err, BSIM_EINPUT, "fps: expected a positive number, got %g",
		                      fps);
	bsim_video_track *t = calloc(1, sizeof *t);
	bsim_trial_runner *runner = bsim_trial_runner_alloc();
	if (!t || !runner) {
		free(t);
		bsim_trial_runner_free(runner);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory for a video track");
	}
	t->scene = scene;
	t->fps = fps;
	t->n_beams = scene->n_beams;
	t->last_step = -1;
	t->summary = summary;
	if (bsim_effects_init(&t->fx, scene, seed)) {
		free(t);
		bsim_trial_runner_free(runner);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory for a video track");
	}
	bsim_trial_log *log = bsim_trial_log_alloc();
	bsim_recorder rec = {.csv = NULL,
	                     .stride = 1,
	                     .trace = summary ? NULL : track_trace,
	                     .trace_user = t,
	                     .trace_whole = 1,
	                     .log = log};
	int rc = log ? bsim_trial_run(runner, scene, backend, opts, seed, &rec, &t->result, err)
	             : bsim_error_set(err, BSIM_EFAIL, "out of memory for a video track");
	bsim_trial_runner_free(runner);
	if (rc == BSIM_OK && log->n_entries > 0) {
		t->visits = malloc((size_t)log->n_entries * sizeof *t->visits);
		if (!t->visits)
			t->oom = 1;
		for (int i = 0; t->visits && i < log->n_entries; i++) {
			const bsim_gate_entry *e = &log->entries[i];
			t->visits[i] = (video_gate_visit){e->ix, e->iy, e->step};
		}
		t->n_visits = t->visits ? log->n_entries : 0;
	}
	bsim_trial_log_free(log);
	if (rc == BSIM_OK && t->oom)
		rc = bsim_error_set(err, BSIM_EFAIL,
		                    "out of memory recording %ld steps for a video", t->n_trail);
	if (rc != BSIM_OK) {
		bsim_video_track_free(t);
		return rc;
	}
	if (summary) {
		t->n_frames = bsim_video_frame_count(fps, scene->dt, t->result.steps_run);
		*out = t;
		return BSIM_OK;
	}
	/* Frames 0 .. ceil(N h fps): all those at or before the end, and one
	 * for the end state; frames past it that floor() also maps to step N
	 * (when fps h > 1 or the end falls just before a frame time) go. */
	long n_last = t->n_trail - 1;
	long frames = (long)ceil((double)n_last * fps * scene->dt - 1e-9) + 1;
	if (t->n_frames >= frames)
		t->n_frames = frames;
	else if (t->last_step == n_last)
		t->n_frames++; /* the end state, kept in the next slot */
	*out = t;
	return BSIM_OK;
}

int bsim_video_track_record(const bsim_scene *scene, const bsim_backend *backend,
                            const bsim_options *opts, uint64_t seed, double fps,
                            bsim_video_track **out, bsim_error *err)
{
	return track_run(scene, backend, opts, seed, fps, 0, out, err);
}

int bsim_video_track_summary(const bsim_scene *scene, const bsim_backend *backend,
                             const bsim_options *opts, uint64_t seed, double fps,
                             bsim_video_track **out, bsim_error *err)
{
	return track_run(scene, backend, opts, seed, fps, 1, out, err);
}

bsim_effects *bsim_video_track_effects(bsim_video_track *t)
{
	return &t->fx;
}

void bsim_video_track_free(bsim_video_track *t)
{
	if (!t)
		return;
	bsim_effects_free(&t->fx);
	free(t->visits);
	free(t->trail);
	free(t->frames);
	free(t->theta);
	free(t->contact);
	free(t);
}

const bsim_trial_result *bsim_video_track_result(const bsim_video_track *t)
{
	return &t->result;
}

long bsim_video_track_frames(const bsim_video_track *t)
{
	return t->n_frames;
}

bsim_video_sample bsim_video_track_sample(const bsim_video_track *t, long k)
{
	if (k >= t->n_frames)
		k = t->n_frames - 1;
	if (k < 0)
		k = 0;
	const track_frame *f = &t->frames[k];
	bsim_video_sample s = {
	        .step = f->step,
	        .t = (double)f->step * t->scene->dt,
	        .x = {f->x[0], f->x[1]},
	        .f_rand = f->f_rand,
	        .e_kin = f->e_kin,
	        .e_spring = f->e_spring,
	        .e_prop = f->e_prop,
	        .theta = t->theta + (size_t)k * (size_t)t->n_beams,
	        .contact = t->contact + (size_t)k * (size_t)t->n_beams,
	};
	return s;
}

void bsim_video_track_position(const bsim_video_track *t, long n, double x[2])
{
	if (n >= t->n_trail)
		n = t->n_trail - 1;
	if (n < 0)
		n = 0;
	x[0] = t->trail[2 * n];
	x[1] = t->trail[2 * n + 1];
}

const double *bsim_video_track_trail(const bsim_video_track *t, long *n)
{
	*n = t->n_trail;
	return t->trail;
}

const video_gate_visit *bsim_video_track_visits(const bsim_video_track *t, int *n)
{
	*n = t->n_visits;
	return t->visits;
}

int bsim_video_track_random_axis(const bsim_video_track *t)
{
	return t->fx.random ? t->fx.random->axis : 0;
}

double bsim_video_track_separation(const bsim_video_track *a, const bsim_video_track *b,
                                   double sep_distance)
{
	long n = a->n_trail < b->n_trail ? a->n_trail : b->n_trail;
	for (long k = 0; k < n; k++)
		if (hypot(a->trail[2 * k] - b->trail[2 * k],
		          a->trail[2 * k + 1] - b->trail[2 * k + 1]) > sep_distance)
			return (double)k * a->scene->dt;
	return -1.0;
}
