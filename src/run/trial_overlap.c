/* The overlap of body and beams (trial_overlap.h). A solver that keeps
 * contacts apart holds it near 0; measuring it costs about a fifth of a
 * step of the essay's solver, which is why the recorder asks for it only
 * when told. */
#include "run/trial_overlap.h"

#include <math.h>

#include "beamsim/contact_flag.h"

void bsim_trial_overlap_shapes(beam_shape *shape, const bsim_scene *sc)
{
	for (int i = 0; i < sc->n_beams; i++) {
		const bsim_beam_def *b = &sc->beams[i];
		beam_shape *q = &shape[i];
		q->p[0] = b->pivot[0];
		q->p[1] = b->pivot[1];
		bsim_scene_beam_rest_direction(b, q->u0);
		q->sgn = bsim_scene_beam_forward_sign(b);
		q->length = b->length;
		q->reach2 = (b->length + sc->body.radius) * (b->length + sc->body.radius);
	}
}

/* R - min_i |C - Q_i|, Q_i the point of beam i's segment nearest the
 * centre C (docs/model.md section 3), measured as the contact flag measures
 * it (beamsim/contact_flag.h). A beam whose reach L + R does not hold the
 * centre costs one distance test. */
double bsim_trial_overlap_depth(const beam_shape *shape, int n, double radius, const bsim_state *s)
{
	double depth = 0.0;
	for (int i = 0; i < n; i++) {
		const beam_shape *q = &shape[i];
		double dx = s->x[0] - q->p[0], dy = s->x[1] - q->p[1];
		if (dx * dx + dy * dy >= q->reach2)
			continue;
		double u[2];
		int type;
		bsim_beam_direction(q->u0, q->sgn, s->theta[i], u);
		depth = fmax(depth, radius - bsim_beam_distance(q->p, u, q->length, s->x, &type));
	}
	return depth;
}
