/* A trial's memory of the beams (trial_peaks.h): room for it, its start,
 * and the landscape label it leaves at the end. */
#include "run/trial_peaks.h"

#include <stdlib.h>

#include "beamsim/error.h"
#include "beamsim/landscape.h"

int bsim_trial_peaks_reserve(trial_peaks *p, int n_beams)
{
	if (p->cap >= n_beams && p->peak)
		return BSIM_OK;
	bsim_trial_peaks_free(p);
	size_t n = n_beams > 0 ? (size_t)n_beams : 1;
	p->peak = malloc(n * sizeof *p->peak);
	p->negative = malloc(n * sizeof *p->negative);
	p->touching = calloc(n, sizeof *p->touching);
	p->touch_list = malloc(n * sizeof *p->touch_list);
	p->listed = calloc(n, sizeof *p->listed);
	p->list = malloc(n * sizeof *p->list);
	p->cap = p->peak && p->negative && p->touching && p->touch_list && p->listed && p->list
	                 ? n_beams
	                 : 0;
	if (!p->cap)
		return BSIM_EFAIL;
	for (size_t i = 0; i < n; i++)
		p->peak[i] = 0.0;
	return BSIM_OK;
}

void bsim_trial_peaks_free(trial_peaks *p)
{
	free(p->peak);
	free(p->negative);
	free(p->touching);
	free(p->touch_list);
	free(p->listed);
	free(p->list);
	p->peak = NULL;
	p->negative = p->touching = p->touch_list = p->list = NULL;
	p->listed = NULL;
	p->cap = p->n_touch = p->n_negative = p->n_list = 0;
}

void bsim_trial_peaks_start(trial_peaks *p, const bsim_scene *scene, const int *map,
                            const bsim_state *s0)
{
	for (int k = 0; k < p->n_list; k++) {
		p->peak[p->list[k]] = 0.0;
		p->listed[p->list[k]] = 0;
	}
	p->n_list = 0;
	p->n_negative = 0;
	/* Beams 0 and 1 (trials.csv's columns) are read every step. */
	for (int i = 0; i < 2 && i < scene->n_beams; i++)
		trial_peaks_list(p, i);
	if (!map)
		for (int k = 0; k < s0->n_active; k++) {
			int i = s0->active[k];
			trial_peaks_list(p, i);
			p->peak[i] = s0->theta[i];
		}
	for (int k = 0; !map && k < p->n_list; k++) {
		int i = p->list[k];
		if (p->peak[i] < 0.0)
			p->negative[p->n_negative++] = i;
	}
	p->touched = 0;
	p->last_touch[0] = p->last_touch[1] = 0.0;
	p->settled01 = 0;
	touching_clear(p);
	p->turns = scene->body.rotates;
	p->heading0 = s0->heading;
	p->turn_max = 0.0;
}

int bsim_trial_peaks_label(const trial_peaks *p, const bsim_scene *scene)
{
	/* the landscape's label is the disk's (bsim_landscape_label): none for
	 * another shape */
	if (scene->body.shape != BSIM_SHAPE_DISK)
		return -1;
	return p->touched ? bsim_landscape_label(scene, p->last_touch, p->touching) : -1;
}

void bsim_trial_peaks_turn_end(const trial_peaks *p, const bsim_state *s, bsim_trial_result *out)
{
	out->heading_end = s->heading;
	out->angular_velocity_end = s->angular_velocity;
	out->turn_end = s->heading - p->heading0;
	out->turn_max = p->turn_max;
}
