/* An ellipse against a segment (model/body_shape.h). */
#include "model/body_shape.h"

int body_shape_ellipse_segment(double a, double c, const double x[2], double psi,
                               const double p0[2], const double p1[2], body_segment_contact *out)
{
	(void)a, (void)c, (void)x, (void)psi, (void)p0, (void)p1, (void)out;
	return BSIM_EFAIL; /* not written yet */
}
