// Private: inline bodies of the vector, matrix and Bézier basics that the
// generators call in their innermost loops. The public functions in vec.c and
// bezier.c are these same bodies, so a caller that inlines them computes the
// same bits (the build contracts no floating-point expression: -ffp-contract=off).
#ifndef PLUME_CORE_VEC_INLINE_H
#define PLUME_CORE_VEC_INLINE_H

#include <math.h>

#include "plume/core.h"

static inline double core_v3_length(plume_vec3 a) { return sqrt(plume_v3_dot(a, a)); }

static inline double core_v3_distance(plume_vec3 a, plume_vec3 b) { return core_v3_length(plume_v3_sub(a, b)); }

static inline plume_vec3 core_v3_normalize(plume_vec3 a)
{
	double length = core_v3_length(a);
	return length > 0.0 ? plume_v3_scale(a, 1.0 / length) : a;
}

static inline plume_vec3 core_m3_apply(const plume_mat3 *a, plume_vec3 v)
{
	return (plume_vec3){a->m[0][0] * v.x + a->m[0][1] * v.y + a->m[0][2] * v.z,
	                    a->m[1][0] * v.x + a->m[1][1] * v.y + a->m[1][2] * v.z,
	                    a->m[2][0] * v.x + a->m[2][1] * v.y + a->m[2][2] * v.z};
}

/// Rotation about a unit axis by the angle whose cosine is c and sine s (Rodrigues):
/// R = c I + s [k]x + (1 - c) k k^T. A caller that turns many axes by one angle
/// takes its sine and cosine once.
static inline plume_mat3 core_m3_rotation_cs(plume_vec3 axis, double c, double s)
{
	double v = 1.0 - c;
	double x = axis.x, y = axis.y, z = axis.z;
	return (plume_mat3){{{c + v * x * x, v * x * y - s * z, v * x * z + s * y},
	                     {v * x * y + s * z, c + v * y * y, v * y * z - s * x},
	                     {v * x * z - s * y, v * y * z + s * x, c + v * z * z}}};
}

/// The cubic Bézier curve of points[0..3] at t (Bernstein form).
static inline plume_vec3 core_bezier_cubic(const plume_vec3 *points, double t)
{
	double s = 1.0 - t;
	double b0 = s * s * s, b1 = 3.0 * s * s * t, b2 = 3.0 * s * t * t, b3 = t * t * t;
	return (plume_vec3){b0 * points[0].x + b1 * points[1].x + b2 * points[2].x + b3 * points[3].x,
	                    b0 * points[0].y + b1 * points[1].y + b2 * points[2].y + b3 * points[3].y,
	                    b0 * points[0].z + b1 * points[1].z + b2 * points[2].z + b3 * points[3].z};
}

/// The quadratic Bézier curve of points[0..2] at t: a cubic's hodograph.
static inline plume_vec3 core_bezier_quadratic(const plume_vec3 *points, double t)
{
	double s = 1.0 - t;
	double b0 = s * s, b1 = 2.0 * s * t, b2 = t * t;
	return (plume_vec3){b0 * points[0].x + b1 * points[1].x + b2 * points[2].x,
	                    b0 * points[0].y + b1 * points[1].y + b2 * points[2].y,
	                    b0 * points[0].z + b1 * points[1].z + b2 * points[2].z};
}

/// i / c for c < PLUME_BEZIER_MAX_POINTS, folded by the compiler (bezier.c): a
/// division saved in every point of every degree elevation.
extern const double core_elevation_weight[PLUME_BEZIER_MAX_POINTS][PLUME_BEZIER_MAX_POINTS];

/// Degree elevation by one, count points to count + 1 (out may be points):
/// q_0 = p_0, q_{n+1} = p_n, q_i = (i / (n+1)) p_{i-1} + (1 - i / (n+1)) p_i.
static inline void core_bezier_elevate(const plume_vec3 *points, int count, plume_vec3 *out)
{
	int n = count - 1;
	plume_vec3 last = points[n];
	plume_vec3 previous = points[0];
	out[0] = points[0];
	const double *weight = count < PLUME_BEZIER_MAX_POINTS ? core_elevation_weight[count] : NULL;
	for (int i = 1; i <= n; ++i) {
		plume_vec3 current = points[i];
		double a = weight != NULL ? weight[i] : (double)i / (double)(n + 1);
		out[i] = plume_v3_add(plume_v3_scale(previous, a), plume_v3_scale(current, 1.0 - a));
		previous = current;
	}
	out[n + 1] = last;
}

#endif
