// Bézier curves of any degree: evaluation, derivatives, elevation, splitting,
// arc length and arc-length sampling.
//
// Arc length integrates the speed |B'(t)| with an 8-point Gauss–Legendre rule,
// refined adaptively. Sampling by arc length first tabulates the cumulative
// length over a fixed partition, then solves each target length by Newton's
// method inside its interval (safeguarded by bisection), so a table of n
// samples costs O(n) quadratures instead of O(n) full-length integrals.
#include <math.h>
#include <string.h>

#include "asserts.h"
#include "plume/core.h"
#include "vec_inline.h"

plume_vec3 plume_bezier_eval(const plume_vec3 *points, int count, double t)
{
	PLUME_ASSERT(count >= 1 && count <= PLUME_BEZIER_MAX_POINTS);
	if (count == 4) // the cubic is every barb's curve: Bernstein form without the triangle
		return core_bezier_cubic(points, t);
	if (count == 3) // the hodograph of a cubic, in every arc-length quadrature
		return core_bezier_quadratic(points, t);
	plume_vec3 work[PLUME_BEZIER_MAX_POINTS];
	memcpy(work, points, (size_t)count * sizeof *points);
	for (int level = count - 1; level > 0; --level)
		for (int i = 0; i < level; ++i)
			work[i] = plume_v3_lerp(work[i], work[i + 1], t);
	return work[0];
}

void plume_bezier_hodograph(const plume_vec3 *points, int count, plume_vec3 *out)
{
	PLUME_ASSERT(count >= 2);
	double degree = (double)(count - 1);
	for (int i = 0; i + 1 < count; ++i)
		out[i] = plume_v3_scale(plume_v3_sub(points[i + 1], points[i]), degree);
}

plume_vec3 plume_bezier_derivative(const plume_vec3 *points, int count, int order, double t)
{
	PLUME_ASSERT(count >= 1 && count <= PLUME_BEZIER_MAX_POINTS && order >= 0);
	if (order >= count)
		return plume_v3(0.0, 0.0, 0.0);
	plume_vec3 work[PLUME_BEZIER_MAX_POINTS];
	memcpy(work, points, (size_t)count * sizeof *points);
	for (int k = 0; k < order; ++k) {
		plume_bezier_hodograph(work, count, work); // in place: reads i + 1 before writing i
		--count;
	}
	return plume_bezier_eval(work, count, t);
}

// core_elevation_weight[c][i] = i / c, each a constant expression that the compiler rounds as the
// division would at run time (row 0 and the entries i >= c are never read).
#define ELEVATION_WEIGHT(c, i) ((double)(i) / (double)((c) > 0 ? (c) : 1))
#define ELEVATION_8(c, i)                                                                                              \
	ELEVATION_WEIGHT(c, i), ELEVATION_WEIGHT(c, i + 1), ELEVATION_WEIGHT(c, i + 2), ELEVATION_WEIGHT(c, i + 3),        \
	    ELEVATION_WEIGHT(c, i + 4), ELEVATION_WEIGHT(c, i + 5), ELEVATION_WEIGHT(c, i + 6), ELEVATION_WEIGHT(c, i + 7)
#define ELEVATION_ROW(c)                                                                                               \
	{                                                                                                                  \
		ELEVATION_8(c, 0), ELEVATION_8(c, 8), ELEVATION_8(c, 16), ELEVATION_8(c, 24), ELEVATION_8(c, 32),              \
		    ELEVATION_8(c, 40), ELEVATION_8(c, 48), ELEVATION_8(c, 56)                                                 \
	}
#define ELEVATION_ROWS_8(c)                                                                                            \
	ELEVATION_ROW(c), ELEVATION_ROW(c + 1), ELEVATION_ROW(c + 2), ELEVATION_ROW(c + 3), ELEVATION_ROW(c + 4),          \
	    ELEVATION_ROW(c + 5), ELEVATION_ROW(c + 6), ELEVATION_ROW(c + 7)

const double core_elevation_weight[PLUME_BEZIER_MAX_POINTS][PLUME_BEZIER_MAX_POINTS] = {
    ELEVATION_ROWS_8(0),  ELEVATION_ROWS_8(8),  ELEVATION_ROWS_8(16), ELEVATION_ROWS_8(24),
    ELEVATION_ROWS_8(32), ELEVATION_ROWS_8(40), ELEVATION_ROWS_8(48), ELEVATION_ROWS_8(56)};

void plume_bezier_elevate(const plume_vec3 *points, int count, plume_vec3 *out)
{
	core_bezier_elevate(points, count, out);
}

void plume_bezier_split(const plume_vec3 *points, int count, double t, plume_vec3 *left, plume_vec3 *right)
{
	PLUME_ASSERT(count >= 1 && count <= PLUME_BEZIER_MAX_POINTS);
	plume_vec3 work[PLUME_BEZIER_MAX_POINTS];
	memcpy(work, points, (size_t)count * sizeof *points);
	for (int level = count - 1; level >= 0; --level) {
		left[count - 1 - level] = work[0];
		right[level] = work[level];
		for (int i = 0; i < level; ++i)
			work[i] = plume_v3_lerp(work[i], work[i + 1], t);
	}
}

// ---------------------------------------------------------------------------
// Arc length

static const double gl8_nodes[4] = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267, 0.9602898564975363};
static const double gl8_weights[4] = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};

// The speed |B'(t)| is the length of the hodograph, evaluated by de Casteljau.
static double speed_at(const plume_vec3 *hodograph, int count, double t)
{
	return core_v3_length(plume_bezier_eval(hodograph, count, t));
}

static double gauss8(const plume_vec3 *hodograph, int count, double a, double b)
{
	double mid = 0.5 * (a + b), half = 0.5 * (b - a), sum = 0.0;
	for (int i = 0; i < 4; ++i)
		sum += gl8_weights[i] * (speed_at(hodograph, count, mid - half * gl8_nodes[i]) +
		                         speed_at(hodograph, count, mid + half * gl8_nodes[i]));
	return sum * half;
}

// Subdivisions one length may spend. A smooth curve converges in a few dozen;
// the budget bounds the work independently of the values, so control points
// near DBL_MAX (whose speed overflows to inf and never meets a tolerance) cost
// a few milliseconds instead of 2^30 quadratures.
enum { ADAPTIVE_BUDGET = 4096 };

static double adaptive_length(const plume_vec3 *hodograph, int count, double a, double b, double whole,
                              double tolerance, int depth, int *budget)
{
	double mid = 0.5 * (a + b);
	double left = gauss8(hodograph, count, a, mid), right = gauss8(hodograph, count, mid, b);
	if (depth >= 30 || *budget <= 0 || !isfinite(left + right) || fabs(left + right - whole) <= tolerance)
		return left + right;
	--*budget;
	return adaptive_length(hodograph, count, a, mid, left, 0.5 * tolerance, depth + 1, budget) +
	       adaptive_length(hodograph, count, mid, b, right, 0.5 * tolerance, depth + 1, budget);
}

/// Writes the hodograph (a single zero point for a point curve); returns its count.
static int hodograph_of(const plume_vec3 *points, int count, plume_vec3 *hodograph)
{
	PLUME_ASSERT(count >= 1 && count <= PLUME_BEZIER_MAX_POINTS);
	if (count == 1) {
		hodograph[0] = plume_v3(0.0, 0.0, 0.0);
		return 1;
	}
	plume_bezier_hodograph(points, count, hodograph);
	return count - 1;
}

static double control_polygon_length(const plume_vec3 *points, int count)
{
	double length = 0.0;
	for (int i = 0; i + 1 < count; ++i)
		length += core_v3_distance(points[i], points[i + 1]);
	return length;
}

static double curve_length(const plume_vec3 *hodograph, int count, double scale, double t0, double t1)
{
	// The control polygon bounds the length from above: it sets the absolute tolerance.
	double tolerance = 1e-13 * (scale > 0.0 ? scale : 1.0);
	int budget = ADAPTIVE_BUDGET;
	return adaptive_length(hodograph, count, t0, t1, gauss8(hodograph, count, t0, t1), tolerance, 0, &budget);
}

double plume_bezier_length(const plume_vec3 *points, int count, double t0, double t1)
{
	plume_vec3 hodograph[PLUME_BEZIER_MAX_POINTS];
	int hodograph_count = hodograph_of(points, count, hodograph);
	return curve_length(hodograph, hodograph_count, control_polygon_length(points, count), t0, t1);
}

void plume_bezier_arc_init(plume_bezier_arc *arc, const plume_vec3 *points, int count)
{
	PLUME_ASSERT(arc != NULL && points != NULL);
	PLUME_ASSERT(count >= 1 && count <= PLUME_BEZIER_MAX_POINTS);
	arc->hodograph_count = hodograph_of(points, count, arc->hodograph);
	double scale = control_polygon_length(points, count);
	const int intervals = PLUME_BEZIER_ARC_INTERVALS;
	arc->cumulative[0] = 0.0;
	for (int j = 0; j <= intervals; ++j) {
		double a = (double)j / intervals;
		arc->speed[j] = speed_at(arc->hodograph, arc->hodograph_count, a);
		if (j < intervals)
			arc->cumulative[j + 1] = arc->cumulative[j] + curve_length(arc->hodograph, arc->hodograph_count, scale, a,
			                                                           (double)(j + 1) / intervals);
	}
	arc->length = arc->cumulative[intervals];
}

/// First guess inside interval j: invert the cubic Hermite interpolant of the
/// length (values and speeds at both ends), whose error is O(h^4).
static double hermite_guess(const plume_bezier_arc *arc, int j, double target)
{
	const double h = 1.0 / PLUME_BEZIER_ARC_INTERVALS;
	double span = arc->cumulative[j + 1] - arc->cumulative[j];
	double goal = target - arc->cumulative[j];
	double d0 = arc->speed[j] * h, d1 = arc->speed[j + 1] * h;
	double u = goal / span;
	for (int iteration = 0; iteration < 4; ++iteration) {
		// H(u) = span (3u^2 - 2u^3) + d0 (u - 2u^2 + u^3) + d1 (u^3 - u^2)
		double u2 = u * u, u3 = u2 * u;
		double value = span * (3 * u2 - 2 * u3) + d0 * (u - 2 * u2 + u3) + d1 * (u3 - u2);
		double slope = span * (6 * u - 6 * u2) + d0 * (1 - 4 * u + 3 * u2) + d1 * (3 * u2 - 2 * u);
		if (!(slope > 0.0))
			break;
		double next = u - (value - goal) / slope;
		u = next < 0.0 ? 0.0 : (next > 1.0 ? 1.0 : next);
	}
	return ((double)j + u) * h;
}

double plume_bezier_arc_param(const plume_bezier_arc *arc, double fraction)
{
	const int intervals = PLUME_BEZIER_ARC_INTERVALS;
	double total = arc->length;
	if (total <= 0.0) // a point: any parameter is as good; keep them spread
		return fraction <= 0.0 ? 0.0 : (fraction >= 1.0 ? 1.0 : fraction);
	double target = fraction * total;
	if (target <= 0.0)
		return 0.0;
	if (target >= total)
		return 1.0;
	int lo = 0, hi = intervals;
	while (hi - lo > 1) {
		int mid = (lo + hi) / 2;
		if (arc->cumulative[mid] <= target)
			lo = mid;
		else
			hi = mid;
	}
	double a = (double)lo / intervals, b = (double)(lo + 1) / intervals;
	double base = arc->cumulative[lo];
	double t = arc->cumulative[lo + 1] > base ? hermite_guess(arc, lo, target) : a;
	// Newton on f(t) = length(a, t) - (target - base), kept inside a shrinking
	// bracket. The Hermite guess is within about 1e-10 of the root, so one step
	// usually lands to rounding: a step below 1e-9 leaves an error of order
	// step^2 and is accepted without another quadrature.
	double lower = a, upper = b;
	for (int iteration = 0; iteration < 60; ++iteration) {
		double f = gauss8(arc->hodograph, arc->hodograph_count, a, t) - (target - base);
		if (f > 0.0)
			upper = t;
		else
			lower = t;
		double speed = speed_at(arc->hodograph, arc->hodograph_count, t);
		double step = speed > 0.0 ? f / speed : INFINITY;
		if (fabs(step) <= 1e-9)
			return t - step;
		double next = t - step;
		if (!(next > lower && next < upper))
			next = 0.5 * (lower + upper);
		t = next;
	}
	return t;
}

double plume_bezier_param_at_length(const plume_vec3 *points, int count, double fraction)
{
	plume_bezier_arc arc;
	plume_bezier_arc_init(&arc, points, count);
	return plume_bezier_arc_param(&arc, fraction);
}

void plume_bezier_sample_by_length(const plume_vec3 *points, int count, int sample_count, double *params_out)
{
	PLUME_ASSERT(sample_count >= 2);
	plume_bezier_arc arc;
	plume_bezier_arc_init(&arc, points, count);
	params_out[0] = 0.0;
	for (int k = 1; k + 1 < sample_count; ++k)
		params_out[k] = plume_bezier_arc_param(&arc, (double)k / (sample_count - 1));
	params_out[sample_count - 1] = 1.0;
}

double plume_bezier_closest_param(const plume_vec3 *points, int count, plume_vec3 p)
{
	enum { SEARCH = 64 };
	double best_t = 0.0, best = INFINITY;
	for (int i = 0; i <= SEARCH; ++i) {
		double t = (double)i / SEARCH;
		double distance = plume_v3_distance(plume_bezier_eval(points, count, t), p);
		if (distance < best) {
			best = distance;
			best_t = t;
		}
	}
	double t = best_t;
	for (int iteration = 0; iteration < 30; ++iteration) {
		plume_vec3 offset = plume_v3_sub(plume_bezier_eval(points, count, t), p);
		plume_vec3 d1 = plume_bezier_derivative(points, count, 1, t);
		plume_vec3 d2 = plume_bezier_derivative(points, count, 2, t);
		double f = plume_v3_dot(offset, d1), df = plume_v3_dot(d1, d1) + plume_v3_dot(offset, d2);
		if (!(df > 0.0))
			break;
		double next = t - f / df;
		next = next < 0.0 ? 0.0 : (next > 1.0 ? 1.0 : next);
		if (fabs(next - t) < 1e-16)
			break;
		t = next;
	}
	// Newton may wander to a worse local minimum; keep the better of the two.
	if (plume_v3_distance(plume_bezier_eval(points, count, t), p) > best)
		t = best_t;
	return t;
}
