// Continuous collision detection (sim/ccd.h, issue 14): additive CCD against times of
// impact known in closed form (a point falling onto a face, onto an edge, onto a vertex;
// edges crossing; parallel and degenerate primitives; motion that never touches), the
// separation kept as the header says, and a seeded randomized sweep against an exact
// reference written here: with linear motion, contact needs the four points to be
// coplanar, so the times of impact are roots of a cubic, found by bracketing its sign
// changes (between a fine grid and the cubic's critical points) and bisection, then
// checked for the point inside the triangle or the two segments crossing. The CCD must
// never return a time after the earliest root that is a contact.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "support.h"

#include "sim/ccd.h"
#include "sim/contact_distance.h"

enum { POINT_TRIANGLE = 0, EDGE_EDGE = 1 };

static const double SEPARATIONS[] = {0.1, 0.2};

static double ccd(int kind, const plume_vec3 start[4], const plume_vec3 end[4], double separation)
{
	return kind == POINT_TRIANGLE ? plume_ccd_point_triangle(start, end, separation)
	                              : plume_ccd_edge_edge(start, end, separation);
}

static double distance_at(int kind, const plume_vec3 start[4], const plume_vec3 end[4], double t)
{
	plume_vec3 x[4];
	for (int i = 0; i < 4; ++i)
		x[i] = plume_v3_lerp(start[i], end[i], t);
	double d2 = kind == POINT_TRIANGLE ? plume_point_triangle_distance2(x[0], x[1], x[2], x[3], NULL)
	                                   : plume_edge_edge_distance2(x[0], x[1], x[2], x[3], NULL);
	return sqrt(d2);
}

/// The header's promise: the distance stays >= separation d(0) on [0, t] (sampled densely,
/// with a rounding allowance of 1e-12 of the scene's size).
static void assert_gap_kept(int kind, const plume_vec3 start[4], const plume_vec3 end[4], double separation, double t,
                            double size)
{
	double gap = separation * distance_at(kind, start, end, 0);
	enum { SAMPLES = 64 };
	for (int k = 0; k <= SAMPLES; ++k) {
		double tau = t * k / SAMPLES;
		double d = distance_at(kind, start, end, tau);
		if (!(d >= gap - 1e-12 * size))
			fail_msg("distance %.17g at t = %.17g (returned %.17g) below the gap %.17g", d, tau, t, gap);
	}
}

/// A time of impact known exactly: the CCD returns at most it, and at least a fraction of
/// it that the separation leaves (1 - separation for a head-on approach) less 0.1 for the
/// conservative bound. no_impact: 1 exactly.
static void check_known(int kind, const plume_vec3 start[4], const plume_vec3 end[4], double toi)
{
	for (int k = 0; k < 2; ++k) {
		double s = SEPARATIONS[k];
		double t = ccd(kind, start, end, s);
		if (toi >= 1) {
			if (t != 1)
				fail_msg("separation %g: no impact, CCD returned %.17g", s, t);
		} else if (!(t <= toi && t >= (1 - s - 0.1) * toi)) {
			fail_msg("separation %g: time of impact %.17g, CCD returned %.17g", s, toi, t);
		}
		assert_gap_kept(kind, start, end, s, t, 1);
	}
}

// ---------------------------------------------------------------------------
// Known times of impact

static const plume_vec3 TRIANGLE[3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};

/// Point-triangle with the unit triangle static and the point moving from p0 to p1.
static void check_point(plume_vec3 p0, plume_vec3 p1, double toi)
{
	plume_vec3 start[4] = {p0, TRIANGLE[0], TRIANGLE[1], TRIANGLE[2]};
	plume_vec3 end[4] = {p1, TRIANGLE[0], TRIANGLE[1], TRIANGLE[2]};
	check_known(POINT_TRIANGLE, start, end, toi);
}

static void test_point_onto_face(void **state)
{
	(void)state;
	// Straight down through the interior point (0.2, 0.3, 0): at t = 1/2.
	check_point(plume_v3(0.2, 0.3, 1), plume_v3(0.2, 0.3, -1), 0.5);
	// Obliquely, through (0.3, 0.2, 0) at t = 1/2.
	check_point(plume_v3(0.1, 0.1, 1), plume_v3(0.5, 0.3, -1), 0.5);
	// Through (0.25, 0.25, 0) at t = 0.3: p(t) = q + (t - 0.3) v.
	plume_vec3 q = plume_v3(0.25, 0.25, 0), v = plume_v3(0.1, -0.2, -3);
	check_point(plume_v3_mad(q, -0.3, v), plume_v3_mad(q, 0.7, v), 0.3);
	// Both move: the triangle rises by 0.5 while the point falls by 1.5 from height 1;
	// they meet when 1 - 1.5 t = 0.5 t.
	plume_vec3 start[4] = {{0.2, 0.2, 1}, TRIANGLE[0], TRIANGLE[1], TRIANGLE[2]};
	plume_vec3 end[4] = {{0.2, 0.2, -0.5}, {0, 0, 0.5}, {1, 0, 0.5}, {0, 1, 0.5}};
	check_known(POINT_TRIANGLE, start, end, 0.5);
	// The triangle tilts about edge ab (vertex c rises from z = -1 to z = 1) under a static
	// point at (0.25, 0.5, 0.25), inside its shadow: the plane z = (2 t - 1) y reaches
	// the point when t = 3/4.
	plume_vec3 tilt_start[4] = {{0.25, 0.5, 0.25}, {0, 0, 0}, {1, 0, 0}, {0, 1, -1}};
	plume_vec3 tilt_end[4] = {{0.25, 0.5, 0.25}, {0, 0, 0}, {1, 0, 0}, {0, 1, 1}};
	check_known(POINT_TRIANGLE, tilt_start, tilt_end, 0.75);
}

static void test_point_onto_edge_and_vertex(void **state)
{
	(void)state;
	// Onto the midpoint of edge ab from outside, at t = 0.4 (closest region: the edge).
	plume_vec3 m = plume_v3(0.5, 0, 0), v = plume_v3(0, 1, -2);
	check_point(plume_v3_mad(m, -0.4, v), plume_v3_mad(m, 0.6, v), 0.4);
	// Onto the vertex a from outside the triangle's prism, at t = 1/2.
	check_point(plume_v3(-0.5, -0.5, 0.5), plume_v3(0.5, 0.5, -0.5), 0.5);
	// In the triangle's plane, along the x axis onto vertex a: at t = 1/4.
	check_point(plume_v3(-1, 0, 0), plume_v3(3, 0, 0), 0.25);
	// Edge-edge endpoint to endpoint: a0 falls onto b0 from above, at t = 1/2.
	plume_vec3 start[4] = {{0, 0, 1}, {0, 0, 2}, {0, 0, 0}, {1, 0, 0}};
	plume_vec3 end[4] = {{0, 0, -1}, {0, 0, 0}, {0, 0, 0}, {1, 0, 0}};
	check_known(EDGE_EDGE, start, end, 0.5);
	// An endpoint of one edge onto the middle of the other, sideways, at t = 0.6.
	plume_vec3 side_start[4] = {{0.3, 1, 0}, {0.3, 2, 0}, {0, 0, 0}, {1, 0, 0}};
	plume_vec3 side_end[4] = {{0.3, -2.0 / 3.0, 0}, {0.3, 1.0 / 3.0, 0}, {0, 0, 0}, {1, 0, 0}};
	check_known(EDGE_EDGE, side_start, side_end, 0.6);
}

static void test_edges_crossing(void **state)
{
	(void)state;
	// a along x at height 1 falls to -1 across b along y: at t = 1/2.
	plume_vec3 start[4] = {{-1, 0, 1}, {1, 0, 1}, {0, -1, 0}, {0, 1, 0}};
	plume_vec3 end[4] = {{-1, 0, -1}, {1, 0, -1}, {0, -1, 0}, {0, 1, 0}};
	check_known(EDGE_EDGE, start, end, 0.5);
	// Both move, at 60 degrees, crossing off their midpoints: a point of a at parameter
	// 0.3 meets a point of b at 0.8 when t = 0.2. a moves by (0, 0, -2), b by (0, 0, 0.5);
	// the gap 0.5 closes at 2.5 per unit time.
	plume_vec3 q = plume_v3(0.2, 0.1, 0.3);
	plume_vec3 da = plume_v3(1, 0, 0), db = plume_v3(0.5, sqrt(3) / 2, 0);
	plume_vec3 a0 = plume_v3_add(plume_v3_mad(q, -0.3, da), plume_v3(0, 0, 0.4));
	plume_vec3 b0 = plume_v3_add(plume_v3_mad(q, -0.8, db), plume_v3(0, 0, -0.1));
	plume_vec3 s2[4] = {a0, plume_v3_add(a0, da), b0, plume_v3_add(b0, db)};
	plume_vec3 move_a = plume_v3(0, 0, -2), move_b = plume_v3(0, 0, 0.5);
	plume_vec3 e2[4] = {plume_v3_add(s2[0], move_a), plume_v3_add(s2[1], move_a), plume_v3_add(s2[2], move_b),
	                    plume_v3_add(s2[3], move_b)};
	check_known(EDGE_EDGE, s2, e2, 0.2);
}

static void test_parallel_motion(void **state)
{
	(void)state;
	// Parallel edges 0.1 apart sliding along each other: never touch.
	plume_vec3 start[4] = {{0, 0, 0.1}, {1, 0, 0.1}, {0, 0, 0}, {1, 0, 0}};
	plume_vec3 end[4] = {{2, 0, 0.1}, {3, 0, 0.1}, {0, 0, 0}, {1, 0, 0}};
	check_known(EDGE_EDGE, start, end, 1);
	// Side by side in one plane, sliding the other way.
	plume_vec3 flat_start[4] = {{0, 0.1, 0}, {1, 0.1, 0}, {0, 0, 0}, {1, 0, 0}};
	plume_vec3 flat_end[4] = {{-0.5, 0.1, 0}, {0.5, 0.1, 0}, {0, 0, 0}, {1, 0, 0}};
	check_known(EDGE_EDGE, flat_start, flat_end, 1);
	// Parallel edges approaching each other: the coplanarity cubic is identically zero
	// here, the distance 1 - 2 t reaches 0 at t = 1/2.
	plume_vec3 approach_start[4] = {{0.5, 0, 1}, {1.5, 0, 1}, {0, 0, 0}, {1, 0, 0}};
	plume_vec3 approach_end[4] = {{0.5, 0, -1}, {1.5, 0, -1}, {0, 0, 0}, {1, 0, 0}};
	check_known(EDGE_EDGE, approach_start, approach_end, 0.5);
	// A point moving parallel to the triangle's plane 0.1 above it: its distance never
	// falls under 0.1, above 0.2 of its start (0.224).
	check_point(plume_v3(-0.2, 0.2, 0.1), plume_v3(0.6, 0.2, 0.1), 1);
	// ... and a point moving in the plane, past the triangle, 0.5 away from edge bc.
	check_point(plume_v3(1.5, 1, 0), plume_v3(1, 1.5, 0), 1);
}

static void test_degenerate_primitives(void **state)
{
	(void)state;
	// A triangle with collinear vertices: the point falls onto its middle at t = 1/2 ...
	plume_vec3 start[4] = {{0.5, 0, 1}, {0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
	plume_vec3 end[4] = {{0.5, 0, -1}, {0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
	check_known(POINT_TRIANGLE, start, end, 0.5);
	// ... or falls 0.3 beside it and never touches.
	start[0].y = end[0].y = 0.3;
	check_known(POINT_TRIANGLE, start, end, 1);
	// A triangle collapsed to a point, hit at t = 1/4.
	plume_vec3 dot_start[4] = {{-1, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
	plume_vec3 dot_end[4] = {{3, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
	check_known(POINT_TRIANGLE, dot_start, dot_end, 0.25);
	// An edge of zero length falling onto an edge at t = 0.8.
	plume_vec3 edge_start[4] = {{0.5, 0, 0.8}, {0.5, 0, 0.8}, {0, 0, 0}, {1, 0, 0}};
	plume_vec3 edge_end[4] = {{0.5, 0, -0.2}, {0.5, 0, -0.2}, {0, 0, 0}, {1, 0, 0}};
	check_known(EDGE_EDGE, edge_start, edge_end, 0.8);
}

static void test_no_motion_and_close_starts(void **state)
{
	(void)state;
	plume_vec3 start[4] = {{0.2, 0.2, 0.5}, TRIANGLE[0], TRIANGLE[1], TRIANGLE[2]};
	// No motion, and a rigid translation: the distance never changes.
	assert_true(plume_ccd_point_triangle(start, start, 0.1) == 1);
	plume_vec3 moved[4];
	for (int i = 0; i < 4; ++i)
		moved[i] = plume_v3_add(start[i], plume_v3(3, -7, 11));
	assert_true(plume_ccd_point_triangle(start, moved, 0.1) == 1);
	assert_true(plume_ccd_edge_edge(start, moved, 0.1) == 1);
	// Touching at the start: 0, moving or not.
	plume_vec3 touching[4] = {{0.2, 0.2, 0}, TRIANGLE[0], TRIANGLE[1], TRIANGLE[2]};
	assert_true(plume_ccd_point_triangle(touching, touching, 0.1) == 0);
	assert_true(plume_ccd_point_triangle(touching, start, 0.1) == 0);
	// Edges crossing at the start.
	plume_vec3 crossing[4] = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}};
	plume_vec3 apart[4] = {{-1, 0, 1}, {1, 0, 1}, {0, -1, 0}, {0, 1, 0}};
	assert_true(plume_ccd_edge_edge(crossing, apart, 0.2) == 0);
	// 1e-9 above the face, approaching at unit speed: impact at 1e-9.
	check_point(plume_v3(0.2, 0.2, 1e-9), plume_v3(0.2, 0.2, 1e-9 - 1), 1e-9);
	// ... and leaving: no impact.
	check_point(plume_v3(0.2, 0.2, 1e-9), plume_v3(0.2, 0.2, 1), 1);
	// 1e-170 above: the squared distance underflows to 0, which counts as touching.
	plume_vec3 grazing[4] = {{0.2, 0.2, 1e-170}, TRIANGLE[0], TRIANGLE[1], TRIANGLE[2]};
	assert_true(plume_ccd_point_triangle(grazing, start, 0.1) == 0);
	// Separation 0 still stops before the impact, with a positive distance.
	plume_vec3 fall_end[4] = {{0.2, 0.2, -0.5}, TRIANGLE[0], TRIANGLE[1], TRIANGLE[2]};
	double t = plume_ccd_point_triangle(start, fall_end, 0);
	assert_true(t > 0.9 * 0.5 && t < 0.5);
	assert_true(distance_at(POINT_TRIANGLE, start, fall_end, t) > 0);
}

/// The returned time is where the distance has come down to about separation times its
/// start (a head-on approach, where the bound l_p is the approach speed): at most there,
/// and within 5 % of the way.
static void test_separation_as_specified(void **state)
{
	(void)state;
	plume_vec3 start[4] = {{0.2, 0.2, 1}, TRIANGLE[0], TRIANGLE[1], TRIANGLE[2]};
	plume_vec3 end[4] = {{0.2, 0.2, -1}, TRIANGLE[0], TRIANGLE[1], TRIANGLE[2]};
	const double separations[] = {0, 0.1, 0.2, 0.5, 0.9};
	for (int k = 0; k < 5; ++k) {
		double s = separations[k], t = plume_ccd_point_triangle(start, end, s);
		double exact = 0.5 * (1 - s); // the distance 1 - 2 t reaches s
		if (!(t <= exact && t >= 0.95 * exact))
			fail_msg("separation %g: %.17g, expected in [0.95, 1] x %.17g", s, t, exact);
		assert_true(distance_at(POINT_TRIANGLE, start, end, t) >= s);
	}
}

/// A point sliding 10 across a triangle 1e-7 above it needs about 10^8 steps of the bound:
/// the iteration limit stops the search with a time that is still conservative.
static void test_iteration_limit(void **state)
{
	(void)state;
	plume_vec3 start[4] = {{-5, 0.3, 1e-7}, {-10, 0, 0}, {10, 0, 0}, {0, 10, 0}};
	plume_vec3 end[4] = {{5, 0.3, 1e-7}, {-10, 0, 0}, {10, 0, 0}, {0, 10, 0}};
	double t = plume_ccd_point_triangle(start, end, 0.1);
	assert_true(t > 0 && t < 1);
	assert_gap_kept(POINT_TRIANGLE, start, end, 0.1, t, 10);
}

// ---------------------------------------------------------------------------
// The exact reference

// The reference computes in long double (x87 extended, 64-bit mantissa): for nearly
// parallel edges the crossing point sweeps along the edges a million times faster than t,
// and the coplanarity determinant in double leaves its root too uncertain to tell.
typedef struct lvec3 {
	long double x, y, z;
} lvec3;

static lvec3 l_at(plume_vec3 a, plume_vec3 b, double t)
{
	long double s = t;
	return (lvec3){a.x + s * ((long double)b.x - a.x), a.y + s * ((long double)b.y - a.y),
	               a.z + s * ((long double)b.z - a.z)};
}
static lvec3 l_sub(lvec3 a, lvec3 b) { return (lvec3){a.x - b.x, a.y - b.y, a.z - b.z}; }
static long double l_dot(lvec3 a, lvec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static lvec3 l_cross(lvec3 a, lvec3 b)
{
	return (lvec3){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
static long double l_det(lvec3 u, lvec3 v, lvec3 w) { return l_dot(u, l_cross(v, w)); }

/// The four points at t, in long double.
static void l_points(const plume_vec3 start[4], const plume_vec3 end[4], double t, lvec3 x[4])
{
	for (int i = 0; i < 4; ++i)
		x[i] = l_at(start[i], end[i], t);
}

/// The coplanarity determinant's three vectors: det[b - p, c - p, a - p] for a point and a
/// triangle, det[a1 - a0, b0 - a0, b1 - a0] for two edges.
static void coplanarity_vectors(int kind, const lvec3 x[4], lvec3 out[3])
{
	if (kind == POINT_TRIANGLE) {
		out[0] = l_sub(x[2], x[0]);
		out[1] = l_sub(x[3], x[0]);
		out[2] = l_sub(x[1], x[0]);
	} else {
		out[0] = l_sub(x[1], x[0]);
		out[1] = l_sub(x[2], x[0]);
		out[2] = l_sub(x[3], x[0]);
	}
}

static long double coplanarity(int kind, const plume_vec3 start[4], const plume_vec3 end[4], double t)
{
	lvec3 x[4], u[3];
	l_points(start, end, t, x);
	coplanarity_vectors(kind, x, u);
	return l_det(u[0], u[1], u[2]);
}

/// Critical points in (0, 1) of the cubic f(t) = det[u + t du, v + t dv, w + t dw], from the
/// coefficients of f' (f is multilinear in its columns). Returns how many.
static int critical_points(int kind, const plume_vec3 start[4], const plume_vec3 end[4], double out[2])
{
	lvec3 x0[4], x1[4], u[3], e[3], d[3];
	l_points(start, end, 0, x0);
	l_points(start, end, 1, x1);
	coplanarity_vectors(kind, x0, u);
	coplanarity_vectors(kind, x1, e);
	for (int i = 0; i < 3; ++i)
		d[i] = l_sub(e[i], u[i]);
	double c1 = (double)(l_det(d[0], u[1], u[2]) + l_det(u[0], d[1], u[2]) + l_det(u[0], u[1], d[2]));
	double c2 = (double)(l_det(d[0], d[1], u[2]) + l_det(d[0], u[1], d[2]) + l_det(u[0], d[1], d[2]));
	double c3 = (double)l_det(d[0], d[1], d[2]);
	// f' = 3 c3 t^2 + 2 c2 t + c1.
	double qa = 3 * c3, qb = 2 * c2, qc = c1, roots[2];
	int n = 0;
	if (fabs(qa) > 1e-300) {
		double disc = qb * qb - 4 * qa * qc;
		if (disc >= 0) {
			double q = -0.5 * (qb + copysign(sqrt(disc), qb));
			roots[n++] = q / qa;
			if (q != 0)
				roots[n++] = qc / q;
		}
	} else if (qb != 0) {
		roots[n++] = -qc / qb;
	}
	int count = 0;
	for (int i = 0; i < n; ++i)
		if (roots[i] > 0 && roots[i] < 1)
			out[count++] = roots[i];
	return count;
}

/// At a time when the four points are coplanar: does the point lie in the triangle, or
/// do the segments cross? Tolerance 1e-9 (relative), so grazing contacts count.
static int touching(int kind, const plume_vec3 start[4], const plume_vec3 end[4], double t, double size)
{
	lvec3 x[4];
	l_points(start, end, t, x);
	const long double tol = 1e-9;
	if (kind == POINT_TRIANGLE) {
		lvec3 p = x[0], a = x[1], b = x[2], c = x[3];
		lvec3 n = l_cross(l_sub(b, a), l_sub(c, a));
		long double n2 = l_dot(n, n);
		if (!(n2 > 1e-20L * size * size * size * size))
			return 0; // the sweep draws no degenerate triangle
		long double la = l_dot(l_cross(l_sub(c, b), l_sub(p, b)), n) / n2;
		long double lb = l_dot(l_cross(l_sub(a, c), l_sub(p, c)), n) / n2;
		long double lc = l_dot(l_cross(l_sub(b, a), l_sub(p, a)), n) / n2;
		long double height = fabsl(l_dot(l_sub(p, a), n)) / sqrtl(n2);
		return la >= -tol && lb >= -tol && lc >= -tol && height <= tol * size;
	}
	// The lines meet (they are coplanar here) at a0 + s da = b0 + u db; crossing both sides
	// with db, then da, gives s and u over |da x db|^2, which stays accurate for nearly
	// parallel edges (no A C - B^2 cancellation).
	lvec3 da = l_sub(x[1], x[0]), db = l_sub(x[3], x[2]), r = l_sub(x[2], x[0]);
	lvec3 n = l_cross(da, db);
	long double n2 = l_dot(n, n);
	if (!(n2 > 1e-30L * l_dot(da, da) * l_dot(db, db)))
		return 0; // parallel: the sweep's nearly parallel edges are 1e-7 apart in direction
	long double s = l_dot(l_cross(r, db), n) / n2, u = l_dot(l_cross(r, da), n) / n2;
	return s >= -tol && s <= 1 + tol && u >= -tol && u <= 1 + tol;
}

static int compare_doubles(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

/// The earliest time of impact in [0, 1], or 2 when none: the roots of the coplanarity
/// cubic in order, each checked for contact. Sign changes are bracketed on a grid of 512
/// intervals plus the cubic's critical points (so each interval is monotone and holds at
/// most one root) and bisected to the last bit; a critical point where |f| is within
/// rounding of 0 (a double root: a grazing touch) is checked as a root too.
static double exact_toi(int kind, const plume_vec3 start[4], const plume_vec3 end[4], double size)
{
	enum { GRID = 512 };
	double t[GRID + 3];
	int n = 0;
	for (int k = 0; k <= GRID; ++k)
		t[n++] = (double)k / GRID;
	n += critical_points(kind, start, end, t + n);
	qsort(t, (size_t)n, sizeof *t, compare_doubles);
	const long double flat = 1e-16L * size * size * size; // |f| below this is a root by rounding
	long double f_lo = coplanarity(kind, start, end, t[0]);
	if (fabsl(f_lo) <= flat && touching(kind, start, end, t[0], size))
		return t[0];
	for (int k = 0; k + 1 < n; ++k) {
		double lo = t[k], hi = t[k + 1];
		long double f_hi = coplanarity(kind, start, end, hi);
		if ((f_lo < 0 && f_hi > 0) || (f_lo > 0 && f_hi < 0)) {
			double a = lo, b = hi;
			long double fa = f_lo;
			for (int i = 0; i < 200 && b - a > 0; ++i) {
				double m = 0.5 * (a + b);
				if (m <= a || m >= b)
					break;
				long double fm = coplanarity(kind, start, end, m);
				if ((fm < 0) == (fa < 0) && fm != 0) {
					a = m;
					fa = fm;
				} else {
					b = m;
				}
			}
			if (touching(kind, start, end, a, size) || touching(kind, start, end, b, size))
				return a;
		}
		if (fabsl(f_hi) <= flat && touching(kind, start, end, hi, size))
			return hi;
		f_lo = f_hi;
	}
	return 2;
}

// ---------------------------------------------------------------------------
// The randomized sweep

static plume_vec3 random_point(plume_rng *rng, double half)
{
	return plume_v3(plume_rng_range(rng, -half, half), plume_rng_range(rng, -half, half),
	                plume_rng_range(rng, -half, half));
}

/// Moves the first primitive (the point, or the edge a) by an extra displacement so that
/// its point at weights w[0 .. split) meets the second's at weights w[split .. 4) at t_hit.
static void force_meeting(int kind, plume_vec3 start[4], plume_vec3 end[4], const double w[4], double t_hit)
{
	plume_vec3 x[4];
	for (int i = 0; i < 4; ++i)
		x[i] = plume_v3_lerp(start[i], end[i], t_hit);
	plume_vec3 qa = {0, 0, 0}, qb = {0, 0, 0};
	int split = kind == POINT_TRIANGLE ? 1 : 2;
	for (int i = 0; i < 4; ++i) {
		if (i < split)
			qa = plume_v3_mad(qa, w[i], x[i]);
		else
			qb = plume_v3_mad(qb, w[i], x[i]);
	}
	// The first primitive gets the extra displacement delta t by t_hit.
	plume_vec3 delta = plume_v3_scale(plume_v3_sub(qb, qa), 1 / t_hit);
	for (int i = 0; i < split; ++i)
		end[i] = plume_v3_add(end[i], delta);
}

/// One random case: 0 generic, 1 a forced interior hit, 2 a forced grazing hit on an
/// edge or a vertex (exactly on it, or 1e-10 inside or outside), 3 a near-degenerate
/// motion (point-triangle: sliding parallel to the plane 1e-10 off it; edge-edge: nearly
/// parallel edges forced to meet). Returns the forced time or 2.
static double random_case(plume_rng *rng, int kind, int type, plume_vec3 start[4], plume_vec3 end[4])
{
	double reach = (double[]){0, 0.3, 1.5}[plume_rng_next(rng) % 3];
	for (int i = 0; i < 4; ++i) {
		start[i] = random_point(rng, 1);
		end[i] = plume_v3_add(start[i], random_point(rng, reach));
	}
	int split = kind == POINT_TRIANGLE ? 1 : 2;
	for (int i = 0; i < split; ++i)
		end[i] = random_point(rng, 1);
	if (type == 0)
		return 2;
	double w[4] = {1, 0, 0, 0};
	if (kind == POINT_TRIANGLE) {
		double a = plume_rng_range(rng, 0.05, 0.9), b = plume_rng_range(rng, 0.05, 0.95 - a);
		w[1] = a;
		w[2] = b;
		w[3] = 1 - a - b;
	} else {
		double s = plume_rng_range(rng, 0.05, 0.95), u = plume_rng_range(rng, 0.05, 0.95);
		w[0] = 1 - s;
		w[1] = s;
		w[2] = 1 - u;
		w[3] = u;
	}
	if (type == 2) {
		// Onto a boundary: one weight of a side moved to the other weight(s) of that side.
		double offset = (double[]){0, 1e-10, -1e-10}[plume_rng_next(rng) % 3];
		int i = split + (int)(plume_rng_next(rng) % (uint64_t)(4 - split));
		int j = i == 3 ? split : i + 1;
		w[j] += w[i] - offset;
		w[i] = offset;
		if (kind == EDGE_EDGE && plume_rng_next(rng) % 2) {
			w[0] += w[1];
			w[1] = 0; // vertex against edge end or vertex
		}
	}
	if (type == 3 && kind == POINT_TRIANGLE) {
		// The triangle static, the point moving along its plane 1e-10 (or 0) off it.
		double h = (double[]){0, 1e-10, -1e-10}[plume_rng_next(rng) % 3];
		for (int i = 1; i < 4; ++i)
			end[i] = start[i];
		plume_vec3 n =
		    plume_v3_normalize(plume_v3_cross(plume_v3_sub(start[2], start[1]), plume_v3_sub(start[3], start[1])));
		plume_vec3 q0 = plume_v3_mad(start[1], 0.5, plume_v3_sub(start[2], start[1]));
		// In the plane, across edge ab's midpoint from outside to inside (so the start is
		// 0.3 or more from the triangle: a start touching it to rounding is another test).
		plume_vec3 dir = random_point(rng, 1);
		dir = plume_v3_mad(dir, -plume_v3_dot(dir, n), n);
		plume_vec3 inward = plume_v3_normalize(plume_v3_cross(n, plume_v3_sub(start[2], start[1])));
		if (plume_v3_dot(inward, plume_v3_sub(start[3], q0)) < 0)
			inward = plume_v3_scale(inward, -1);
		double along = plume_v3_dot(dir, inward);
		dir = plume_v3_mad(dir, 0.3 + fabs(along) - along, inward);
		start[0] = plume_v3_mad(plume_v3_mad(q0, -1, dir), h, n);
		end[0] = plume_v3_mad(plume_v3_mad(q0, 1, dir), h, n);
		// In the plane (h = 0) the cubic vanishes to rounding and the reference checks the
		// grid's times for the point inside: it then finds the entry at most 1/512 late.
		return 2;
	}
	if (type == 3) {
		// b nearly parallel to a at the start and the end.
		plume_vec3 eps = random_point(rng, 1e-7);
		start[3] = plume_v3_add(start[2], plume_v3_add(plume_v3_sub(start[1], start[0]), eps));
		end[3] = plume_v3_add(end[2], plume_v3_sub(end[1], end[0]));
	}
	double t_hit = plume_rng_range(rng, 0.05, 0.95);
	force_meeting(kind, start, end, w, t_hit);
	return t_hit;
}

typedef struct sweep_stats {
	int cases, impacts, forced, free_returned_one;
	double worst_ratio; ///< the smallest CCD time / time of impact over impacts
	int ratio_count;
	double ratio_sum;
} sweep_stats;

static void sweep(int kind, int cases, uint64_t seed, double separation, sweep_stats *stats)
{
	plume_rng rng = plume_rng_seed(seed);
	*stats = (sweep_stats){0};
	stats->worst_ratio = 1;
	for (int c = 0; c < cases; ++c) {
		plume_vec3 start[4], end[4];
		int type = c % 4;
		double forced = random_case(&rng, kind, type, start, end);
		// Scale and translate: the guarantee does not depend on units or the origin.
		double scale = (double[]){1, 1e-3, 1e3}[plume_rng_next(&rng) % 3];
		plume_vec3 offset = plume_v3_scale(random_point(&rng, 10), scale);
		for (int i = 0; i < 4; ++i) {
			start[i] = plume_v3_mad(offset, scale, start[i]);
			end[i] = plume_v3_mad(offset, scale, end[i]);
		}
		double toi = exact_toi(kind, start, end, scale);
		if (forced <= 1) {
			++stats->forced;
			// The reference finds the impact the case was built with, or an earlier one
			// (grazing cases built 1e-10 outside may miss: not counted).
			if ((type == 1 || type == 3) && !(toi <= forced + 1e-9))
				fail_msg("case %d: the reference missed the forced impact at %.17g (found %.17g)", c, forced, toi);
		}
		double t = ccd(kind, start, end, separation);
		if (!(t >= 0 && t <= 1))
			fail_msg("case %d: CCD returned %.17g", c, t);
		if (toi <= 1) {
			++stats->impacts;
			if (!(t <= toi))
				fail_msg("case %d (type %d, scale %g): impact at %.17g, CCD returned %.17g (separation %g)", c, type,
				         scale, toi, t, separation);
			if (toi > 0) {
				double ratio = t / toi;
				stats->worst_ratio = ratio < stats->worst_ratio ? ratio : stats->worst_ratio;
				stats->ratio_sum += ratio;
				++stats->ratio_count;
			}
		} else if (t == 1) {
			++stats->free_returned_one;
		}
		assert_gap_kept(kind, start, end, separation, t, 12 * scale);
		++stats->cases;
	}
}

static void check_sweep(int kind, uint64_t seed)
{
	enum { CASES = 10000 };
	const double separations[] = {0, 0.1, 0.2};
	for (int k = 0; k < 3; ++k) {
		sweep_stats stats;
		sweep(kind, CASES, seed + (uint64_t)k, separations[k], &stats);
		double mean = stats.ratio_sum / stats.ratio_count;
		printf("%s, separation %.1f: %d cases, %d impacts (%d forced), CCD / exact time: mean %.3f, worst %.3g; "
		       "%d of %d without impact return 1\n",
		       kind == POINT_TRIANGLE ? "point-triangle" : "edge-edge", separations[k], stats.cases, stats.impacts,
		       stats.forced, mean, stats.worst_ratio, stats.free_returned_one, stats.cases - stats.impacts);
		// The sweep exercises impacts, and a CCD that always answered 0 (never wrong about
		// missing) would fail here: on average it gets most of the way.
		assert_true(stats.impacts > CASES / 3);
		assert_true(mean > 0.5);
		assert_true(stats.free_returned_one > (stats.cases - stats.impacts) / 4);
	}
}

static void test_sweep_point_triangle(void **state)
{
	(void)state;
	check_sweep(POINT_TRIANGLE, 20210);
}

static void test_sweep_edge_edge(void **state)
{
	(void)state;
	check_sweep(EDGE_EDGE, 20212);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_point_onto_face),         cmocka_unit_test(test_point_onto_edge_and_vertex),
	    cmocka_unit_test(test_edges_crossing),          cmocka_unit_test(test_parallel_motion),
	    cmocka_unit_test(test_degenerate_primitives),   cmocka_unit_test(test_no_motion_and_close_starts),
	    cmocka_unit_test(test_separation_as_specified), cmocka_unit_test(test_iteration_limit),
	    cmocka_unit_test(test_sweep_point_triangle),    cmocka_unit_test(test_sweep_edge_edge),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
