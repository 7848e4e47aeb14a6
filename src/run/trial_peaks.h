/* Internal: what a trial remembers of the beams beyond their state (trial.c
 * keeps one per runner): every beam's peak angle (trials.csv's max_theta,
 * the log's peaks) and the beams touching the body at the last step before
 * success_y at which any did (for the landscape label of a traversal); and
 * of a body that rotates, its largest turn (trials.csv's turn_max).
 * The runner updates them every step: those updates are inline.
 *
 * Beams are the scene's: under the essay's protocol the world's beam i is
 * the scene's map[i] (map NULL: the same). */
#ifndef BSIM_RUN_TRIAL_PEAKS_H
#define BSIM_RUN_TRIAL_PEAKS_H

#include "beamsim/scene.h"
#include "beamsim/state.h"
#include "beamsim/trial.h"
#include "util/fminmax.h"

typedef struct trial_peaks {
	double *peak;  /* per beam of the scene, rad */
	int *negative; /* beams whose peak is still below 0 */
	int n_negative;
	int cap; /* beams the arrays hold */
	/* The beams whose peak may not be 0: the others' is 0 exactly, so a
	 * trial's start clears these, not every beam of the scene. */
	unsigned char *listed;
	int *list;
	int n_list;
	/* The last touching step before success_y: where the body was, and per
	 * beam of the scene its contacts then (all zero between trials:
	 * bsim_trial_peaks_start clears what the last trial set). */
	int touched; /* the body touched a beam at all */
	double last_touch[2];
	int *touching;
	int *touch_list; /* the beams touching[] holds non-zero */
	int n_touch;
	/* Beams 0 and 1's peaks are at +0 or above: a peak never falls, so
	 * they stay there, and a beam at rest cannot raise them. */
	int settled01;
	/* The body's heading at the start, rad, and the largest |heading -
	 * heading0| since, over every step of the run (trial_peaks_turn);
	 * turns: the body rotates (else turn_max stays 0). */
	int turns;
	double heading0, turn_max;
} trial_peaks;

/* Room for a scene of n_beams beams. */
int bsim_trial_peaks_reserve(trial_peaks *p, int n_beams);
void bsim_trial_peaks_free(trial_peaks *p);

/* Peaks at the initial angles s0 (map: every beam of the scene starts at
 * rest), no contact yet, no turn. A beam s0 does not list active is at rest
 * (its angle 0): its peak is 0, and the cost is that of the beams the last
 * trial moved, not of the scene. */
void bsim_trial_peaks_start(trial_peaks *p, const bsim_scene *scene, const int *map,
                            const bsim_state *s0);

/* The landscape label of a traversal: the beam whose barrier the body
 * crossed (bsim_landscape_label at the last touching step), -1 if it
 * touched none. */
int bsim_trial_peaks_label(const trial_peaks *p, const bsim_scene *scene);

/* The body's turn into out (heading_end, angular_velocity_end, turn_end,
 * turn_max), s the run's last state. Not inline: the runner's step loop is
 * compiled as it was without it. */
void bsim_trial_peaks_turn_end(const trial_peaks *p, const bsim_state *s, bsim_trial_result *out);

static inline int scene_beam(const int *map, int i)
{
	return map ? map[i] : i;
}

/* Beam g's peak may leave 0. */
static inline void trial_peaks_list(trial_peaks *p, int g)
{
	if (p->listed[g])
		return;
	p->listed[g] = 1;
	p->list[p->n_list++] = g;
}

/* Every beam's peak theta over the steps so far, s the state after the
 * latest: the active beams, beams 0 and 1 (trials.csv's two columns), and
 * any beam whose peak is still below 0 (a beam at rest has theta 0). */
static inline void trial_peaks_update(trial_peaks *p, const bsim_scene *scene, const int *map,
                                      const bsim_state *s)
{
	double *peak = p->peak;
	for (int k = 0; k < s->n_active; k++) {
		int i = s->active[k], g = scene_beam(map, i);
		trial_peaks_list(p, g);
		peak[g] = bsim_fmax(peak[g], s->theta[i]);
	}
	/* A peak at +0 or above stays: the beam is active (the loop above
	 * took its angle) or at rest (angle +-0, below it or, as bsim_fmax
	 * orders zeros, not above +0). */
	if (!map && !p->settled01) {
		int settled = 1;
		for (int i = 0; i < 2 && i < scene->n_beams; i++) {
			if (!(peak[i] >= 0.0) || signbit(peak[i]))
				peak[i] = bsim_fmax(peak[i], s->theta[i]);
			settled &= peak[i] >= 0.0 && !signbit(peak[i]);
		}
		p->settled01 = settled;
	}
	int m = 0; /* only without a map: the essay's beams all start at rest */
	for (int k = 0; k < p->n_negative; k++) {
		int i = p->negative[k];
		peak[i] = bsim_fmax(peak[i], s->theta[i]);
		if (peak[i] < 0.0)
			p->negative[m++] = i;
	}
	p->n_negative = m;
}

static inline int any_contact(const bsim_state *s)
{
	for (int k = 0; k < s->n_active; k++)
		if (s->contact[s->active[k]])
			return 1;
	return 0;
}

static inline void touching_clear(trial_peaks *p)
{
	for (int k = 0; k < p->n_touch; k++)
		p->touching[p->touch_list[k]] = 0;
	p->n_touch = 0;
}

/* The body touches a beam in s: where it is and the contacts of s in
 * touching[], as a copy of the whole contact array would leave it, at the
 * cost of the beams listed. */
static inline void trial_peaks_contacts(trial_peaks *p, const int *map, const bsim_state *s)
{
	p->touched = 1;
	p->last_touch[0] = s->x[0];
	p->last_touch[1] = s->x[1];
	touching_clear(p);
	for (int k = 0; k < s->n_active; k++) {
		int i = s->active[k];
		if (!s->contact[i])
			continue;
		int g = scene_beam(map, i);
		p->touching[g] = s->contact[i];
		p->touch_list[p->n_touch++] = g;
	}
}

/* The peaks after a step, s the state after it (trial_peaks_update):
 * nothing to do, at the cost of a test, where no beam is active, no peak is
 * below 0 and beams 0 and 1's have settled (or the essay's map, which has
 * no such). */
static inline void trial_peaks_note(trial_peaks *p, const bsim_scene *scene, const int *map,
                                    const bsim_state *s)
{
	if (s->n_active == 0 && p->n_negative == 0 && (map || p->settled01))
		return;
	trial_peaks_update(p, scene, map, s);
}

/* Both of the above after a step, s the state after it, its contact flags
 * computed. */
static inline void trial_peaks_step(trial_peaks *p, const bsim_scene *scene, const int *map,
                                    const bsim_state *s)
{
	trial_peaks_note(p, scene, map, s);
	if (any_contact(s))
		trial_peaks_contacts(p, map, s);
}

/* The largest turn with s, the state after a step (any step of the run,
 * after the outcome too: the run's end state is turn_end's). Only a body
 * that rotates turns: the runner calls this for it alone, so that a step
 * of the essay's disk costs nothing more. A heading that is not a number
 * is not taken (the state's test of finiteness judges the trial). */
static inline void trial_peaks_turn(trial_peaks *p, const bsim_state *s)
{
	if (p->turns)
		p->turn_max = bsim_fmax(p->turn_max, fabs(s->heading - p->heading0));
}

#endif
