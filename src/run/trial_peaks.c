/* A trial's memory of the beams (trial_peaks.h): room for it, its start,
 * and the landscape label it leaves at the end. */
#include "run/trial_peaks.h"

#include <stdlib.h>

#include "beamsim/error.h"
#include "beamsim/landscape.h"

int trial_peaks_reserve(trial_peaks *p, int n_beams)
{
	if (p->cap >= n_beams && p->peak)
		return BSIM_OK;
	trial_peaks_free(p);
	size_t n = n_beams > 0 ? (size_t)n_beams : 1;
	p->peak = malloc(n * sizeof *p->peak);
	p->negative = malloc(n * sizeof *p->negative);
	p->touching = calloc(n, sizeof *p->touching);
	p->touch_list = malloc(n * sizeof *p->touch_list);
	p->cap = p->peak && p->negative && p->touching && p->touch_list ? n_beams : 0;
	return p->cap ? BSIM_OK : BSIM_EFAIL;
}

void trial_peaks_free(trial_peaks *p)
{
	free(p->peak);
	free(p->negative);
	free(p->touching);
	free(p->touch_list);
	p->peak = NULL;
	p->negative = p->touching = p->touch_list = NULL;
	p->cap = p->n_touch = p->n_negative = 0;
}

void trial_peaks_start(trial_peaks *p, const bsim_scene *scene, const int *map,
                       const bsim_state *s0)
{
	p->n_negative = 0;
	for (int i = 0; i < scene->n_beams; i++)
		p->peak[i] = map ? 0.0 : s0->theta[i];
	for (int i = 0; !map && i < scene->n_beams; i++)
		if (p->peak[i] < 0.0)
			p->negative[p->n_negative++] = i;
	p->touched = 0;
	p->last_touch[0] = p->last_touch[1] = 0.0;
	touching_clear(p);
}

int trial_peaks_label(const trial_peaks *p, const bsim_scene *scene)
{
	return p->touched ? bsim_landscape_label(scene, p->last_touch, p->touching) : -1;
}
