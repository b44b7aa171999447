// Continuous collision detection (sim/ccd.h): additive CCD (Li, Kaufman and Jiang 2021,
// "Codimensional Incremental Potential Contact", section 5, Algorithm 1).
//
// The four points move linearly, x_i(t) = x_i + t p_i. A common translation changes no
// distance, so the mean displacement is subtracted first (Algorithm 1, line 2). Two
// points of the primitives then move apart or together at most at
//   l_p = |p_0| + max(|p_1|, |p_2|, |p_3|)           (point-triangle)
//   l_p = max(|p_0|, |p_1|) + max(|p_2|, |p_3|)      (edge-edge)
// per unit of t, because a point of a triangle or an edge moves by a convex combination
// of its vertices' displacements (line 3). The distance d is therefore l_p-Lipschitz in
// t: from a time t where d(t) > g, no time in [t, t + (d(t) - g) / l_p] brings it below
// g. Advancing by such steps is conservative advancement; it never passes the time at
// which the distance reaches g, so never the time of impact either.
//
// Algorithm 1 steps by 0.9 d(t) / l_p after the first step, which keeps d > 0 over
// [0, t] and d(t) >= g only at the returned time. Here every step is bounded by the gap
// to g itself, (1 - STEP_MARGIN) (d(t) - g) / l_p, so d stays >= g = separation d(0) at
// every time in [0, t], as sim/ccd.h promises. The two cost alike: both shrink the
// remaining distance geometrically, at the rate at which the primitives actually
// approach against l_p. The loop stops when the gap d(t) - g is a small fraction
// (GAP_TOLERANCE) of d(0) - g (for a steady approach, the time lost is then that
// fraction of the time to close the gap), or when a step reaches t = 1.
#include <math.h>

#include "sim/ccd.h"

#include "core/asserts.h"
#include "sim/contact_distance.h"

/// Iterations before giving up with the last conservative time. Tangential sliding at a
/// small distance takes about l_p / ((1 - separation) d) steps; this bounds a
/// pathological pair to a few milliseconds, and its answer stays conservative.
enum { CCD_MAX_ITERATIONS = 100000 };

/// Each step goes this fraction short of the Lipschitz bound, so that a distance computed
/// with rounding errors at the end of the step still lies above g (a straight approach
/// reaches g in one step, where it would land exactly on g).
static const double STEP_MARGIN = 0.01;

/// The search stops when d(t) - g <= GAP_TOLERANCE (d(0) - g).
static const double GAP_TOLERANCE = 0.05;

typedef double distance2_fn(const plume_vec3 x[4]);

static double point_triangle_fn(const plume_vec3 x[4])
{
	return plume_point_triangle_distance2(x[0], x[1], x[2], x[3], NULL);
}

static double edge_edge_fn(const plume_vec3 x[4]) { return plume_edge_edge_distance2(x[0], x[1], x[2], x[3], NULL); }

static int finite3(plume_vec3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }

/// Algorithm 1 for the primitives x[0 .. split) and x[split .. 4).
static double additive_ccd(const plume_vec3 start[4], const plume_vec3 end[4], double separation, int split,
                           distance2_fn *distance2)
{
	PLUME_ASSERT(separation >= 0 && separation < 1);
	plume_vec3 p[4], mean = {0, 0, 0};
	for (int i = 0; i < 4; ++i) {
		PLUME_ASSERT(finite3(start[i]) && finite3(end[i]));
		p[i] = plume_v3_sub(end[i], start[i]);
		mean = plume_v3_add(mean, p[i]);
	}
	mean = plume_v3_scale(mean, 0.25);
	double first = 0, second = 0;
	for (int i = 0; i < 4; ++i) {
		p[i] = plume_v3_sub(p[i], mean);
		double length = sqrt(plume_v3_dot(p[i], p[i]));
		if (i < split)
			first = length > first ? length : first;
		else
			second = length > second ? length : second;
	}
	double bound = first + second; // l_p

	double d0 = sqrt(distance2(start));
	if (!(d0 > 0))
		return 0; // touching or intersecting already: no time keeps a positive gap
	if (bound == 0)
		return 1; // a rigid translation (or no motion): the distance never changes
	double g = separation * d0;
	double stop = GAP_TOLERANCE * (d0 - g);

	double t = 0, d = d0;
	for (int k = 0; k < CCD_MAX_ITERATIONS; ++k) {
		double gap = d - g; // >= 0: every accepted time keeps d >= g
		if (k > 0 && gap <= stop)
			return t;
		double step = (1 - STEP_MARGIN) * gap / bound;
		if (step >= 1 - t)
			return 1;
		double next = t + step;
		if (!(next > t))
			return t; // the step is below the resolution of t (a start at a tiny distance)
		plume_vec3 x[4];
		for (int i = 0; i < 4; ++i)
			x[i] = plume_v3_mad(start[i], next, p[i]);
		double d_next = sqrt(distance2(x));
		if (!(d_next >= g))
			return t; // only by rounding: the bound keeps d >= g + STEP_MARGIN * gap
		t = next;
		d = d_next;
	}
	return t;
}

double plume_ccd_point_triangle(const plume_vec3 start[4], const plume_vec3 end[4], double separation)
{
	return additive_ccd(start, end, separation, 1, point_triangle_fn);
}

double plume_ccd_edge_edge(const plume_vec3 start[4], const plume_vec3 end[4], double separation)
{
	return additive_ccd(start, end, separation, 2, edge_edge_fn);
}
