/* Where a step's straight path crosses a gate boundary (lattice.h: gates
 * are width x depth cells; a boundary is a line x = const or y = const). */
#ifndef BSIM_MODEL_LATTICE_CROSSING_H
#define BSIM_MODEL_LATTICE_CROSSING_H

/* The fraction of the step p0 -> p1 at which the path reaches x = at
 * (axis 0) or y = at (axis 1): in [0, 1] when the step crosses the line,
 * outside it when it does not. A path parallel to the line never reaches
 * it: LATTICE_NO_CROSSING, beyond any step's end, so that of two
 * boundaries the one crossed first is the smaller fraction. */
#define LATTICE_NO_CROSSING 2.0

static inline double lattice_crossing(const double p0[2], const double p1[2], int axis, double at)
{
	double d = p1[axis] - p0[axis];
	return d != 0.0 ? (at - p0[axis]) / d : LATTICE_NO_CROSSING;
}

#endif
