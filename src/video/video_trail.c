/* A trail thinned for one view (video_internal.h): the points of the body's
 * path that view draws. A frame draws the path up to its step as a
 * polyline at pixel resolution, so of every step's centre it needs only
 * those 0.75 px apart at its scale; keeping only those, as the steps come,
 * bounds a trail by the pixels the body travels rather than by the steps
 * (a body at rest for a million steps keeps one point). The distance is
 * s (x_n - x_kept), the same for every camera position, so a list made as
 * the trial runs is the list any later frame would have thinned. */
#include <math.h>
#include <stdlib.h>

#include "video/video_internal.h"

int bsim_video_trail_add(video_trail *t, long step, const double x[2])
{
	if (t->broken >= 0)
		return 0;
	if (!isfinite(x[0]) || !isfinite(x[1])) {
		t->broken = step;
		return 0;
	}
	if (t->n > 0) {
		const double *k = t->p[t->n - 1].x;
		if (fabs(t->scale * (x[0] - k[0])) < 0.75 && fabs(t->scale * (x[1] - k[1])) < 0.75)
			return 0;
	}
	if (t->n == t->cap) {
		long cap = t->cap ? 2 * t->cap : 256;
		video_trail_point *p = realloc(t->p, (size_t)cap * sizeof *p);
		if (!p)
			return -1;
		t->p = p;
		t->cap = cap;
	}
	t->p[t->n++] = (video_trail_point){{x[0], x[1]}, step};
	return 0;
}

void bsim_video_trail_free(video_trail *t)
{
	free(t->p);
	t->p = NULL;
	t->n = t->cap = 0;
}
