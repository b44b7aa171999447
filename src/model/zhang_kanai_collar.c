// The collar C(s) of Zhang & Kanai IV-A, s the arc-length fraction: the
// circle of eq. 1 (scaled by R) or a closed composite cubic Bézier through
// control points, with Catmull–Rom tangents so that it is C1 everywhere.
#include <math.h>

#include "../core/alloc.h"
#include "zhang_kanai_internal.h"

static const double two_pi = 6.283185307179586476925286766559;

plume_status zk_collar_init(zk_collar *collar, const plume_zk_def *def)
{
	*collar = (zk_collar){.kind = def->collar_kind, .radius = def->collar_radius};
	if (def->collar_kind == PLUME_ZK_COLLAR_CIRCLE) {
		collar->length = two_pi * def->collar_radius;
		return PLUME_OK;
	}
	int n = def->collar_point_count;
	collar->segment_count = n;
	collar->segments = plume_alloc((size_t)n * sizeof *collar->segments);
	collar->arcs = plume_alloc((size_t)n * sizeof *collar->arcs);
	collar->start = plume_alloc((size_t)(n + 1) * sizeof *collar->start);
	if (collar->segments == NULL || collar->arcs == NULL || collar->start == NULL) {
		zk_collar_free(collar);
		return PLUME_ERROR_MEMORY;
	}
	const plume_vec2 *q = def->collar_points;
	collar->start[0] = 0.0;
	for (int k = 0; k < n; ++k) {
		plume_vec2 prev = q[(k + n - 1) % n], p0 = q[k], p1 = q[(k + 1) % n], next = q[(k + 2) % n];
		plume_vec3 *b = collar->segments[k];
		b[0] = plume_v3(p0.x, 0.0, p0.y);
		b[1] = plume_v3(p0.x + (p1.x - prev.x) / 6.0, 0.0, p0.y + (p1.y - prev.y) / 6.0);
		b[2] = plume_v3(p1.x - (next.x - p0.x) / 6.0, 0.0, p1.y - (next.y - p0.y) / 6.0);
		b[3] = plume_v3(p1.x, 0.0, p1.y);
		plume_bezier_arc_init(collar->arcs + k, b, 4);
		collar->start[k + 1] = collar->start[k] + collar->arcs[k].length;
	}
	collar->length = collar->start[n];
	return PLUME_OK;
}

void zk_collar_free(zk_collar *collar)
{
	plume_free(collar->segments);
	plume_free(collar->arcs);
	plume_free(collar->start);
	collar->segments = NULL;
	collar->arcs = NULL;
	collar->start = NULL;
}

static double wrap(double s) { return s - floor(s); }

/// The Bézier segment and its parameter at locus s.
static int locate(const zk_collar *collar, double s, double *u)
{
	double target = wrap(s) * collar->length;
	int lo = 0, hi = collar->segment_count;
	while (hi - lo > 1) {
		int mid = (lo + hi) / 2;
		if (collar->start[mid] <= target)
			lo = mid;
		else
			hi = mid;
	}
	double span = collar->start[lo + 1] - collar->start[lo];
	double fraction = span > 0.0 ? (target - collar->start[lo]) / span : 0.0;
	*u = plume_bezier_arc_param(collar->arcs + lo, fraction < 0.0 ? 0.0 : (fraction > 1.0 ? 1.0 : fraction));
	return lo;
}

void zk_collar_frame(const zk_collar *collar, double s, plume_vec3 *point, plume_vec3 *tangent)
{
	if (collar->kind == PLUME_ZK_COLLAR_CIRCLE) {
		double a = two_pi * s, c = cos(a), sn = sin(a);
		*point = plume_v3(collar->radius * sn, 0.0, -collar->radius * c);
		*tangent = plume_v3(c, 0.0, sn);
		return;
	}
	double u;
	int k = locate(collar, s, &u);
	*point = plume_bezier_eval(collar->segments[k], 4, u);
	*tangent = plume_v3_normalize(plume_bezier_derivative(collar->segments[k], 4, 1, u));
}

plume_vec3 zk_collar_point(const zk_collar *collar, double s)
{
	plume_vec3 point, tangent;
	zk_collar_frame(collar, s, &point, &tangent);
	return point;
}
