// Contact distances and the IPC barrier energy of one pair (sim/contact_distance.h,
// sim/contact_barrier.h): the closest-region distances against an independent nested
// golden-section minimisation and dense sampling, the region formulas' gradients and
// Hessians against finite differences for all 16 regions, the barrier's closed form,
// the edge-edge mollifier near parallel edges, the PSD projection characterised
// without eigen-solvers of the library, and continuity across region boundaries.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"

#include "sim/contact_barrier.h"
#include "sim/contact_distance.h"
#include "sim/dense.h"

static const double PI = 3.14159265358979323846;

/// The regions of plume_distance_kind: 7 point-triangle, 9 edge-edge.
enum { REGION_COUNT = PLUME_EE_LINES + 1 };

// ---------------------------------------------------------------------------
// Helpers

static plume_vec3 random_vec3(plume_rng *rng, double size)
{
	return plume_v3(plume_rng_range(rng, -size, size), plume_rng_range(rng, -size, size),
	                plume_rng_range(rng, -size, size));
}

static plume_vec3 random_unit(plume_rng *rng)
{
	for (;;) {
		plume_vec3 v = random_vec3(rng, 1);
		double length = plume_v3_length(v);
		if (length > 0.1 && length < 1)
			return plume_v3_scale(v, 1 / length);
	}
}

static double log_uniform(plume_rng *rng, double lo_exponent, double hi_exponent)
{
	return pow(10.0, plume_rng_range(rng, lo_exponent, hi_exponent));
}

static plume_mat3 random_rotation(plume_rng *rng)
{
	return plume_m3_rotation(random_unit(rng), plume_rng_range(rng, -PI, PI));
}

/// A rigid motion of the four points (a rotation and a translation), so that the
/// constructions below are not aligned with the axes.
static void move_rigidly(plume_rng *rng, plume_vec3 x[4])
{
	plume_mat3 rotation = random_rotation(rng);
	plume_vec3 shift = random_vec3(rng, 1);
	for (int i = 0; i < 4; ++i)
		x[i] = plume_v3_add(plume_m3_apply(rotation, x[i]), shift);
}

static double pair_distance2(plume_contact_pair_type type, const plume_vec3 x[4], plume_distance_kind *kind)
{
	return type == PLUME_CONTACT_POINT_TRIANGLE ? plume_point_triangle_distance2(x[0], x[1], x[2], x[3], kind)
	                                            : plume_edge_edge_distance2(x[0], x[1], x[2], x[3], kind);
}

// ---------------------------------------------------------------------------
// The independent reference: nested golden-section minimisation

/// Minimum of a convex function of one variable on [lo, hi] by golden-section search,
/// to the resolution of doubles; the ends are candidates too.
static double golden_minimum(double (*f)(const void *, double), const void *context, double lo, double hi)
{
	const double ratio = 0.6180339887498949;
	double best = fmin(f(context, lo), f(context, hi));
	double x1 = hi - ratio * (hi - lo), x2 = lo + ratio * (hi - lo);
	double f1 = f(context, x1), f2 = f(context, x2);
	for (int iteration = 0; iteration < 90 && hi - lo > 0; ++iteration) {
		if (f1 < f2) {
			hi = x2;
			x2 = x1;
			f2 = f1;
			x1 = hi - ratio * (hi - lo);
			f1 = f(context, x1);
		} else {
			lo = x1;
			x1 = x2;
			f1 = f2;
			x2 = lo + ratio * (hi - lo);
			f2 = f(context, x2);
		}
	}
	return fmin(best, fmin(f1, f2));
}

/// The squared distance between q and the point from + t (to - from).
typedef struct segment_context {
	plume_vec3 q, from, to;
} segment_context;

static double segment_point(const void *context, double t)
{
	const segment_context *c = context;
	plume_vec3 d = plume_v3_sub(c->q, plume_v3_lerp(c->from, c->to, t));
	return plume_v3_dot(d, d);
}

/// Point-triangle: for each u, the triangle's points a + u (b - a) + v (c - a),
/// v in [0, 1 - u], form the segment from a + u (b - a) to c + u (b - c); the
/// squared distance to it, minimised over v, is convex in u.
typedef struct triangle_context {
	plume_vec3 p, a, b, c;
} triangle_context;

static double triangle_slice(const void *context, double u)
{
	const triangle_context *t = context;
	segment_context s = {t->p, plume_v3_lerp(t->a, t->b, u), plume_v3_lerp(t->c, t->b, u)};
	return golden_minimum(segment_point, &s, 0, 1);
}

static double reference_point_triangle(const plume_vec3 x[4])
{
	triangle_context t = {x[0], x[1], x[2], x[3]};
	return golden_minimum(triangle_slice, &t, 0, 1);
}

/// Edge-edge: the squared distance from a0 + s (a1 - a0) to the segment b, convex in s.
typedef struct edges_context {
	plume_vec3 a0, a1, b0, b1;
} edges_context;

static double edges_slice(const void *context, double s)
{
	const edges_context *e = context;
	segment_context c = {plume_v3_lerp(e->a0, e->a1, s), e->b0, e->b1};
	return golden_minimum(segment_point, &c, 0, 1);
}

static double reference_edge_edge(const plume_vec3 x[4])
{
	edges_context e = {x[0], x[1], x[2], x[3]};
	return golden_minimum(edges_slice, &e, 0, 1);
}

/// The smallest squared distance over a 40 x 40 grid of sample pairs: an upper bound.
static double sampled_distance2(plume_contact_pair_type type, const plume_vec3 x[4])
{
	enum { SAMPLES = 40 };
	double best = INFINITY;
	for (int i = 0; i <= SAMPLES; ++i)
		for (int j = 0; j <= SAMPLES; ++j) {
			double s = (double)i / SAMPLES, t = (double)j / SAMPLES;
			plume_vec3 d;
			if (type == PLUME_CONTACT_POINT_TRIANGLE) {
				if (i + j > SAMPLES)
					continue;
				plume_vec3 on = plume_v3_add(plume_v3_mad(x[1], s, plume_v3_sub(x[2], x[1])),
				                             plume_v3_scale(plume_v3_sub(x[3], x[1]), t));
				d = plume_v3_sub(x[0], on);
			} else {
				d = plume_v3_sub(plume_v3_lerp(x[0], x[1], s), plume_v3_lerp(x[2], x[3], t));
			}
			best = fmin(best, plume_v3_dot(d, d));
		}
	return best;
}

// ---------------------------------------------------------------------------
// Random configurations, near-degenerate ones included

static void random_point_triangle(plume_rng *rng, int variant, plume_vec3 x[4])
{
	for (int i = 0; i < 4; ++i)
		x[i] = random_vec3(rng, 1);
	plume_vec3 ab = plume_v3_sub(x[2], x[1]), ac = plume_v3_sub(x[3], x[1]);
	plume_vec3 normal = plume_v3_normalize(plume_v3_cross(ab, ac));
	double u = plume_rng_range(rng, -0.5, 1.5), v = plume_rng_range(rng, -0.5, 1.5);
	plume_vec3 in_plane = plume_v3_add(plume_v3_mad(x[1], u, ab), plume_v3_scale(ac, v));
	double sign = plume_rng_uniform(rng) < 0.5 ? -1 : 1;
	switch (variant) {
	case 0: break; // generic
	case 1:        // the point close to the triangle's plane, over it or beside it
		x[0] = plume_v3_mad(in_plane, sign * log_uniform(rng, -8, -1), normal);
		break;
	case 2: // a degenerate triangle: c on the line ab
		x[3] = plume_v3_mad(x[1], plume_rng_range(rng, -0.5, 1.5), ab);
		break;
	case 3: // two coincident vertices
		x[3] = x[2];
		break;
	case 4: // a sliver: c off the line ab by a tiny amount
		x[3] = plume_v3_add(plume_v3_mad(x[1], plume_rng_range(rng, -0.5, 1.5), ab),
		                    plume_v3_scale(random_unit(rng), log_uniform(rng, -9, -4)));
		break;
	case 5: { // the point close to an edge or a vertex
		int edge = (int)(plume_rng_uniform(rng) * 3);
		plume_vec3 from = x[1 + edge], to = x[1 + (edge + 1) % 3];
		plume_vec3 on = plume_v3_lerp(from, to, plume_rng_range(rng, -0.1, 1.1));
		x[0] = plume_v3_mad(on, log_uniform(rng, -8, -2), random_unit(rng));
		break;
	}
	default: // the point exactly in the plane
		x[0] = in_plane;
		break;
	}
}

static void random_edge_edge(plume_rng *rng, int variant, plume_vec3 x[4])
{
	for (int i = 0; i < 4; ++i)
		x[i] = random_vec3(rng, 1);
	plume_vec3 da = plume_v3_sub(x[1], x[0]);
	switch (variant) {
	case 0: break; // generic
	case 1: {      // nearly parallel
		plume_vec3 tilt = plume_v3_scale(random_unit(rng), log_uniform(rng, -9, -2));
		plume_vec3 db = plume_v3_scale(plume_v3_add(da, tilt), plume_rng_range(rng, 0.3, 1.5));
		x[2] = plume_v3_add(x[0], plume_v3_add(plume_v3_scale(da, plume_rng_range(rng, -1, 1)),
		                                       plume_v3_scale(random_unit(rng), log_uniform(rng, -6, -1))));
		x[3] = plume_v3_add(x[2], db);
		break;
	}
	case 2: { // exactly parallel (one a multiple of the other, overlapping or not)
		x[2] = plume_v3_add(x[0], plume_v3_add(plume_v3_scale(da, plume_rng_range(rng, -1.5, 1.5)),
		                                       plume_v3_scale(random_unit(rng), log_uniform(rng, -6, -1))));
		x[3] = plume_v3_mad(x[2], plume_rng_range(rng, -1.5, 1.5), da);
		break;
	}
	case 3: // on one line
		x[2] = plume_v3_mad(x[0], plume_rng_range(rng, -1.5, 2.5), da);
		x[3] = plume_v3_mad(x[0], plume_rng_range(rng, -1.5, 2.5), da);
		break;
	case 4: { // crossing at a small distance
		plume_vec3 on = plume_v3_mad(x[0], plume_rng_range(rng, -0.2, 1.2), da);
		plume_vec3 db = random_vec3(rng, 1);
		plume_vec3 gap = plume_v3_scale(plume_v3_normalize(plume_v3_cross(da, db)), log_uniform(rng, -8, -2));
		double t = plume_rng_range(rng, -0.2, 1.2);
		x[2] = plume_v3_add(plume_v3_mad(on, -t, db), gap);
		x[3] = plume_v3_add(x[2], db);
		break;
	}
	case 5: // a degenerate edge
		x[1] = x[0];
		break;
	default: { // an endpoint of b close to the inside of a
		plume_vec3 on = plume_v3_mad(x[0], plume_rng_range(rng, 0, 1), da);
		x[2] = plume_v3_mad(on, log_uniform(rng, -8, -2), random_unit(rng));
		break;
	}
	}
}

// ---------------------------------------------------------------------------
// (a) Distances against the independent minimisation

/// Checks one configuration; returns the region reported.
static plume_distance_kind check_distance(plume_contact_pair_type type, const plume_vec3 x[4], double *worst)
{
	plume_distance_kind kind;
	double d2 = pair_distance2(type, x, &kind);
	double reference = type == PLUME_CONTACT_POINT_TRIANGLE ? reference_point_triangle(x) : reference_edge_edge(x);
	double scale2 = 0; // the configuration's size, squared
	for (int i = 0; i < 4; ++i)
		scale2 = fmax(scale2, plume_v3_dot(x[i], x[i]));
	// Rounding: relative to the distance, plus the coordinates' rounding times the
	// distance (a difference of two points of size sqrt(scale2)).
	double tolerance = 1e-9 * reference + 1e-13 * sqrt(scale2 * reference) + 1e-15 * scale2;
	double region_tolerance = 1e-7 * reference + 1e-12 * sqrt(scale2 * reference) + 1e-15 * scale2;
	if (type == PLUME_CONTACT_EDGE_EDGE) {
		plume_vec3 da = plume_v3_sub(x[1], x[0]), db = plume_v3_sub(x[3], x[2]);
		plume_vec3 normal = plume_v3_cross(da, db);
		double aa = plume_v3_dot(da, da), bb = plume_v3_dot(db, db);
		double sin2 = aa * bb > 0 ? plume_v3_dot(normal, normal) / (aa * bb) : 0;
		// Below sin² = 1e-14 the contract measures edges as parallel (endpoint against
		// edge), which overstates d² by up to sin² times the squared edge length.
		if (sin2 < 2e-14) {
			tolerance += 2e-14 * fmax(aa, bb);
			region_tolerance += 2e-14 * fmax(aa, bb);
		}
		// The lines' closed form loses eps L / (d sin) relatively: its normal's
		// direction is that uncertain (the mollifier silences this range).
		else
			region_tolerance += 1e-14 * sqrt(scale2 * reference) / sqrt(sin2);
	}
	if (!(fabs(d2 - reference) <= tolerance))
		fail_msg("type %d kind %d: d2 = %.17g, reference %.17g", (int)type, (int)kind, d2, reference);
	*worst = fmax(*worst, fabs(d2 - reference) / tolerance);
	// Never more than the best of dense samples.
	assert_true(d2 <= sampled_distance2(type, x) + tolerance);
	// The region's closed form, evaluated here, is the distance: the region is right
	// (a wrong region's form would measure to a line or a plane closer than the
	// primitive, or to the wrong vertex).
	double in_region = plume_pair_distance2(type, kind, x, NULL, NULL);
	if (!(fabs(in_region - reference) <= region_tolerance))
		fail_msg("type %d kind %d: region form %.17g, reference %.17g", (int)type, (int)kind, in_region, reference);
	return kind;
}

static void test_distances_against_minimisation(void **state)
{
	(void)state;
	plume_rng rng = plume_rng_seed(14);
	int seen[PLUME_EE_LINES + 1] = {0};
	double worst = 0;
	for (int trial = 0; trial < 2100; ++trial) {
		plume_vec3 x[4];
		random_point_triangle(&rng, trial % 7, x);
		seen[check_distance(PLUME_CONTACT_POINT_TRIANGLE, x, &worst)]++;
	}
	for (int trial = 0; trial < 2100; ++trial) {
		plume_vec3 x[4];
		random_edge_edge(&rng, trial % 7, x);
		plume_distance_kind kind = check_distance(PLUME_CONTACT_EDGE_EDGE, x, &worst);
		seen[kind]++;
		// Parallel edges are measured between endpoints and edges, never as lines.
		if (trial % 7 == 2 || trial % 7 == 3 || trial % 7 == 5)
			assert_int_not_equal(kind, PLUME_EE_LINES);
	}
	// Nearly parallel edges close together, the closest points inside both (where the
	// lines' normal equations are ill-conditioned: sin² from 1e-13 to 1e-8).
	for (int trial = 0; trial < 400; ++trial) {
		plume_vec3 x[4];
		x[0] = random_vec3(&rng, 1);
		x[1] = random_vec3(&rng, 1);
		plume_vec3 da = plume_v3_sub(x[1], x[0]);
		plume_vec3 side = plume_v3_normalize(plume_v3_cross(da, random_unit(&rng)));
		plume_vec3 mid = plume_v3_mad(x[0], plume_rng_range(&rng, 0.3, 0.7), da);
		plume_vec3 gap = plume_v3_scale(plume_v3_normalize(plume_v3_cross(da, side)), log_uniform(&rng, -7, -5));
		plume_vec3 db = plume_v3_scale(plume_v3_mad(da, log_uniform(&rng, -6.5, -4) * plume_v3_length(da), side),
		                               plume_rng_range(&rng, 0.5, 1.5));
		double t = plume_rng_range(&rng, 0.3, 0.7);
		x[2] = plume_v3_add(plume_v3_mad(mid, -t, db), gap);
		x[3] = plume_v3_add(x[2], db);
		seen[check_distance(PLUME_CONTACT_EDGE_EDGE, x, &worst)]++;
	}
	// Every region was met.
	for (int kind = 0; kind <= PLUME_EE_LINES; ++kind)
		if (seen[kind] == 0)
			fail_msg("region %d never met", kind);
	printf("distances: 4600 configurations, worst difference from the reference %.2g of its tolerance\n", worst);
}

// ---------------------------------------------------------------------------
// (b) Region formulas: finite differences

typedef double pair_fn(const void *context, const plume_vec3 x[4], double *gradient, double *hessian);

typedef struct region_context {
	plume_contact_pair_type type;
	plume_distance_kind kind;
} region_context;

static double region_fn(const void *context, const plume_vec3 x[4], double *gradient, double *hessian)
{
	const region_context *c = context;
	return plume_pair_distance2(c->type, c->kind, x, gradient, hessian);
}

typedef struct energy_context {
	plume_contact_pair_type type;
	const plume_vec3 *rest;
	double dhat, stiffness;
	bool project;
} energy_context;

static double energy_fn(const void *context, const plume_vec3 x[4], double *gradient, double *hessian)
{
	const energy_context *c = context;
	return plume_contact_pair_energy(c->type, x, c->rest, c->dhat, c->stiffness, c->project, gradient, hessian);
}

/// Central differences of the value (for the gradient) and of the gradient (for the
/// Hessian) with step h; returns the larger relative error (Euclidean / Frobenius).
static double finite_difference_error(pair_fn *fn, const void *context, const plume_vec3 x0[4], double h)
{
	plume_vec3 x[4];
	memcpy(x, x0, sizeof x);
	double gradient[12], hessian[144];
	double value = fn(context, x, gradient, hessian);
	// The optional outputs do not change one another.
	double only_gradient[12], only_hessian[144];
	assert_true(fn(context, x, only_gradient, NULL) == value);
	assert_true(fn(context, x, NULL, only_hessian) == value);
	assert_true(fn(context, x, NULL, NULL) == value);
	assert_memory_equal(only_gradient, gradient, sizeof gradient);
	assert_memory_equal(only_hessian, hessian, sizeof hessian);
	for (int r = 0; r < 12; ++r)
		for (int c = 0; c < 12; ++c)
			assert_true(hessian[r * 12 + c] == hessian[c * 12 + r]);
	double fd_gradient[12], fd_hessian[144];
	for (int k = 0; k < 12; ++k) {
		double at = test_coordinate(x0, k), gp[12], gm[12];
		test_set_coordinate(x, k, at + h);
		double ep = fn(context, x, gp, NULL);
		test_set_coordinate(x, k, at - h);
		double em = fn(context, x, gm, NULL);
		test_set_coordinate(x, k, at);
		fd_gradient[k] = (ep - em) / (2 * h);
		for (int r = 0; r < 12; ++r)
			fd_hessian[r * 12 + k] = (gp[r] - gm[r]) / (2 * h);
	}
	double diff_g[12], diff_h[144];
	for (int k = 0; k < 12; ++k)
		diff_g[k] = fd_gradient[k] - gradient[k];
	for (int k = 0; k < 144; ++k)
		diff_h[k] = fd_hessian[k] - hessian[k];
	assert_true(test_norm(gradient, 12) > 0);
	return fmax(test_norm(diff_g, 12) / test_norm(gradient, 12), test_norm(diff_h, 144) / test_norm(hessian, 144));
}

/// A configuration well inside region `kind`, moved rigidly at random. Point-triangle:
/// the point is put over the interior, beside an edge or beyond a vertex of a random
/// well-shaped triangle; edge-edge: two crossing edges, an endpoint over the inside of
/// the other edge, or two endpoints facing each other, with the roles swapped to reach
/// every region. distance is the distance between the primitives.
static void region_configuration(plume_rng *rng, plume_distance_kind kind, double distance, plume_vec3 x[4])
{
	if (kind <= PLUME_PT_PLANE) {
		plume_vec3 a = plume_v3(0, 0, 0), b = plume_v3(1 + plume_rng_range(rng, 0, 0.3), 0, 0),
		           c = plume_v3(plume_rng_range(rng, 0.2, 0.6), plume_rng_range(rng, 0.7, 1.1), 0);
		plume_vec3 corner[3] = {a, b, c};
		plume_vec3 up = plume_v3(0, 0, 1);
		plume_vec3 foot;
		double along = plume_rng_range(rng, 0.3, 0.7);
		if (kind == PLUME_PT_PLANE) {
			foot = plume_v3_scale(plume_v3_add(a, plume_v3_add(b, c)), 1.0 / 3.0);
			x[0] = plume_v3_mad(foot, distance, up);
		} else if (kind >= PLUME_PT_AB) {
			// Beside the edge, at 45 degrees between the plane and its normal.
			int e = kind - PLUME_PT_AB;
			plume_vec3 from = corner[e], to = corner[(e + 1) % 3];
			foot = plume_v3_lerp(from, to, along);
			plume_vec3 outward = plume_v3_normalize(plume_v3_cross(plume_v3_sub(to, from), up));
			plume_vec3 direction = plume_v3_normalize(plume_v3_add(outward, up));
			x[0] = plume_v3_mad(foot, distance, direction);
		} else {
			// Beyond the vertex, along the bisector of its outer angle, raised.
			int v = kind - PLUME_PT_A;
			plume_vec3 at = corner[v];
			plume_vec3 e1 = plume_v3_normalize(plume_v3_sub(corner[(v + 1) % 3], at));
			plume_vec3 e2 = plume_v3_normalize(plume_v3_sub(corner[(v + 2) % 3], at));
			plume_vec3 away = plume_v3_normalize(plume_v3_scale(plume_v3_add(e1, e2), -1));
			x[0] = plume_v3_mad(at, distance, plume_v3_normalize(plume_v3_add(away, plume_v3_scale(up, 0.7))));
		}
		x[1] = a;
		x[2] = b;
		x[3] = c;
	} else {
		// The closest points are the origin on a and (0, 0, distance) on b. An edge
		// whose inside is closest lies across the gap (a along x, b along y); an edge
		// whose endpoint is closest runs away from the other edge from there.
		double length = plume_rng_range(rng, 0.8, 1.2);
		bool endpoint_a = kind != PLUME_EE_LINES && kind != PLUME_EE_A_B0 && kind != PLUME_EE_A_B1;
		bool endpoint_b = kind != PLUME_EE_LINES && kind != PLUME_EE_A0_B && kind != PLUME_EE_A1_B;
		plume_vec3 a0 = endpoint_a ? plume_v3(0, 0, 0) : plume_v3(-0.4 * length, 0, 0);
		plume_vec3 a1 = endpoint_a ? plume_v3(0.6 * length, 0.2, -0.5) : plume_v3(0.6 * length, 0, 0);
		plume_vec3 b0 = endpoint_b ? plume_v3(0, 0, distance) : plume_v3(0, -0.5 * length, distance);
		plume_vec3 b1 = endpoint_b ? plume_v3(-0.3, 0.5 * length, distance + 0.6) : plume_v3(0, 0.5 * length, distance);
		// Swap the ends so that the closest features are those of kind.
		bool swap_a = kind == PLUME_EE_A1_B0 || kind == PLUME_EE_A1_B1 || kind == PLUME_EE_A1_B;
		bool swap_b = kind == PLUME_EE_A0_B1 || kind == PLUME_EE_A1_B1 || kind == PLUME_EE_A_B1;
		x[0] = swap_a ? a1 : a0;
		x[1] = swap_a ? a0 : a1;
		x[2] = swap_b ? b1 : b0;
		x[3] = swap_b ? b0 : b1;
	}
	move_rigidly(rng, x);
}

static plume_contact_pair_type type_of(plume_distance_kind kind)
{
	return kind <= PLUME_PT_PLANE ? PLUME_CONTACT_POINT_TRIANGLE : PLUME_CONTACT_EDGE_EDGE;
}

static void test_region_finite_differences(void **state)
{
	(void)state;
	plume_rng rng = plume_rng_seed(15);
	double worst = 0;
	for (int kind = 0; kind <= PLUME_EE_LINES; ++kind)
		for (int trial = 0; trial < 6; ++trial) {
			plume_vec3 x[4];
			double distance = trial < 3 ? plume_rng_range(&rng, 0.1, 0.5) : log_uniform(&rng, -4, -2);
			region_configuration(&rng, (plume_distance_kind)kind, distance, x);
			plume_contact_pair_type type = type_of((plume_distance_kind)kind);
			plume_distance_kind found;
			double d2 = pair_distance2(type, x, &found);
			if (found != (plume_distance_kind)kind)
				fail_msg("constructed region %d, found %d", kind, (int)found);
			region_context context = {type, (plume_distance_kind)kind};
			assert_close(plume_pair_distance2(type, (plume_distance_kind)kind, x, NULL, NULL), distance * distance,
			             1e-10 * distance * distance);
			assert_close(d2, distance * distance, 1e-10 * distance * distance);
			double error = finite_difference_error(region_fn, &context, x, 1e-6);
			if (!(error < 1e-6))
				fail_msg("region %d, distance %g: relative error %.3g", kind, distance, error);
			worst = fmax(worst, error);
		}
	printf("region forms: %d regions x 6 configurations, worst relative FD error %.2e\n", REGION_COUNT, worst);
}

// ---------------------------------------------------------------------------
// (c) The barrier

static void test_barrier_closed_form(void **state)
{
	(void)state;
	const double dhats[] = {1.0, 1e-3, 2e-5};
	double worst = 0;
	for (int i = 0; i < 3; ++i) {
		double h = dhats[i] * dhats[i];
		double db, d2b;
		// Zero with zero derivatives at and beyond d̂ (C² there)...
		assert_true(plume_barrier(h, h, &db, &d2b) == 0 && db == 0 && d2b == 0);
		assert_true(plume_barrier(2 * h, h, &db, &d2b) == 0 && db == 0 && d2b == 0);
		// ... and just below it: b = O(δ³), b' = O(δ²), b'' = O(δ) with t = h (1 - δ).
		double delta = 1e-4, b = plume_barrier(h * (1 - delta), h, &db, &d2b);
		assert_true(b > 0 && b < 2 * h * h * delta * delta * delta);
		assert_true(db < 0 && -db < 4 * h * delta * delta);
		assert_true(d2b > 0 && d2b < 8 * delta);
		// Against the formula at d² = d̂²/e, where ln(d²/d̂²) = -1: b = d̂⁴ (1 - 1/e)².
		double e = exp(1.0);
		assert_close(plume_barrier(h / e, h, NULL, NULL), h * h * (1 - 1 / e) * (1 - 1 / e), 1e-14 * h * h);
		// b -> infinity as d -> 0, like d̂⁴ ln(d̂²/d²).
		double previous = 0;
		for (int k = 2; k <= 30; k += 4) {
			double t = h * pow(10.0, -k);
			double value = plume_barrier(t, h, NULL, NULL);
			assert_true(value > previous);
			assert_close(value / (h * h * log(h / t)), 1.0, 0.03);
			previous = value;
		}
		assert_true(previous > 60 * h * h);
		// Derivatives against central differences in d².
		for (int k = 1; k < 20; ++k) {
			double t = h * k / 20.0 * (k < 3 ? 0.1 : 1);
			double step = 1e-5 * t;
			double b1, b2, bp, bm, dp, dm;
			plume_barrier(t, h, &b1, &b2);
			bp = plume_barrier(t + step, h, &dp, NULL);
			bm = plume_barrier(t - step, h, &dm, NULL);
			double error1 = fabs((bp - bm) / (2 * step) - b1) / fabs(b1);
			double error2 = fabs((dp - dm) / (2 * step) - b2) / fabs(b2);
			if (!(error1 < 1e-6 && error2 < 1e-6))
				fail_msg("d2/dhat2 = %g: relative errors %.3g %.3g", t / h, error1, error2);
			worst = fmax(worst, fmax(error1, error2));
			// Decreasing and convex below d̂ (so the Newton step pushes pairs apart).
			assert_true(b1 < 0 && b2 > 0);
		}
	}
	printf("barrier: worst relative FD error %.2e\n", worst);
}

/// The energy of every region within d̂, against finite differences.
static void test_energy_finite_differences(void **state)
{
	(void)state;
	plume_rng rng = plume_rng_seed(16);
	double worst = 0;
	for (int kind = 0; kind <= PLUME_EE_LINES; ++kind)
		for (int trial = 0; trial < 4; ++trial) {
			plume_vec3 x[4];
			double dhat = trial < 2 ? 0.4 : 1e-3;
			double distance = dhat * plume_rng_range(&rng, 0.05, 0.9);
			region_configuration(&rng, (plume_distance_kind)kind, distance, x);
			// The rest shape is the current one: the edges are far from parallel, the
			// mollifier is 1.
			energy_context context = {type_of((plume_distance_kind)kind), x, dhat, 1e4, false};
			double energy = energy_fn(&context, x, NULL, NULL);
			double b = plume_barrier(distance * distance, dhat * dhat, NULL, NULL);
			assert_close(energy, 1e4 * b, 1e-8 * 1e4 * b);
			plume_vec3 rest[4];
			memcpy(rest, x, sizeof rest);
			context.rest = rest;
			double error = finite_difference_error(energy_fn, &context, x, 1e-4 * distance);
			// Point-triangle pairs do not read the rest shape.
			if (context.type == PLUME_CONTACT_POINT_TRIANGLE)
				assert_true(plume_contact_pair_energy(context.type, x, NULL, dhat, 1e4, false, NULL, NULL) == energy);
			if (!(error < 1e-6))
				fail_msg("region %d, d/dhat %g: relative error %.3g", kind, distance / dhat, error);
			worst = fmax(worst, error);
			// Beyond d̂: nothing.
			double gradient[12], hessian[144];
			context.dhat = 0.99 * distance;
			assert_true(energy_fn(&context, x, gradient, hessian) == 0);
			for (int i = 0; i < 12; ++i)
				assert_true(gradient[i] == 0);
			for (int i = 0; i < 144; ++i)
				assert_true(hessian[i] == 0);
		}
	printf("pair energies: %d regions x 4, worst relative FD error %.2e\n", REGION_COUNT, worst);
}

// ---------------------------------------------------------------------------
// Eigenvalues, for the checks of the projection

/// Eigenvalues of a symmetric 12 x 12 matrix by cyclic Jacobi rotations (written here,
/// independent of the library's Householder-QL).
static void jacobi_eigenvalues(const double *matrix, double values[12])
{
	double a[12][12];
	memcpy(a, matrix, sizeof a);
	for (int sweep = 0; sweep < 100; ++sweep) {
		double off = 0, total = 0;
		for (int i = 0; i < 12; ++i)
			for (int j = 0; j < 12; ++j) {
				total += a[i][j] * a[i][j];
				if (i != j)
					off += a[i][j] * a[i][j];
			}
		if (off <= 1e-30 * total)
			break;
		for (int p = 0; p < 12; ++p)
			for (int q = p + 1; q < 12; ++q) {
				if (a[p][q] == 0)
					continue;
				double theta = (a[q][q] - a[p][p]) / (2 * a[p][q]);
				double t = (theta >= 0 ? 1 : -1) / (fabs(theta) + sqrt(theta * theta + 1));
				double c = 1 / sqrt(t * t + 1), s = t * c;
				for (int k = 0; k < 12; ++k) { // columns p, q
					double akp = a[k][p], akq = a[k][q];
					a[k][p] = c * akp - s * akq;
					a[k][q] = s * akp + c * akq;
				}
				for (int k = 0; k < 12; ++k) { // rows p, q
					double apk = a[p][k], aqk = a[q][k];
					a[p][k] = c * apk - s * aqk;
					a[q][k] = s * apk + c * aqk;
				}
			}
	}
	for (int i = 0; i < 12; ++i)
		values[i] = a[i][i];
}

static double smallest(const double values[12])
{
	double m = values[0];
	for (int i = 1; i < 12; ++i)
		m = fmin(m, values[i]);
	return m;
}

static double largest_magnitude(const double values[12])
{
	double m = 0;
	for (int i = 0; i < 12; ++i)
		m = fmax(m, fabs(values[i]));
	return m;
}

// ---------------------------------------------------------------------------
// (d) The mollifier of nearly parallel edges

/// Two edges of length 1 at an angle close to parallel, distance apart. Crossing: a
/// along x, b turned by angle in a plane parallel to it, the closest points inside both.
/// Otherwise a starts over the inside of b and rises away from it (a0 closest), each
/// edge turned by half the angle.
static void nearly_parallel(double angle, double distance, bool crossing, plume_vec3 x[4])
{
	double turn = crossing ? angle : 0.5 * angle;
	double c = cos(turn), s = sin(turn);
	x[0] = plume_v3(crossing ? -0.5 : 0.2, 0, 0);
	x[1] = crossing ? plume_v3(0.5, 0, 0) : plume_v3_add(x[0], plume_v3(c, 0, s));
	x[2] = plume_v3(-0.5 * c, -0.5 * s, -distance);
	x[3] = plume_v3(0.5 * c, 0.5 * s, -distance);
}

static void test_mollifier(void **state)
{
	(void)state;
	plume_rng rng = plume_rng_seed(17);
	const double dhat = 1e-2, stiffness = 1e3;
	plume_vec3 rest[4];
	nearly_parallel(0.5, dhat, true, rest); // rest lengths 1: ε = 1e-3
	const double epsilon = 1e-3;
	double worst = 0;
	for (int trial = 0; trial < 24; ++trial) {
		bool crossing = trial % 2 == 0;
		// sin² of the angle between 1e-7 and 0.9 ε: the mollifier is active.
		double angle = asin(sqrt(epsilon * log_uniform(&rng, -4, -0.05)));
		double distance = dhat * plume_rng_range(&rng, 0.1, 0.8);
		plume_vec3 x[4];
		nearly_parallel(angle, distance, crossing, x);
		move_rigidly(&rng, x);
		plume_distance_kind kind;
		double d2 = plume_edge_edge_distance2(x[0], x[1], x[2], x[3], &kind);
		assert_int_equal(kind, crossing ? PLUME_EE_LINES : PLUME_EE_A0_B);
		// E = k m(x) b(d²), m(x) = 2 x/ε - x²/ε² (IPC eq. 14), x = |e0 x e1|².
		plume_vec3 cross = plume_v3_cross(plume_v3_sub(x[1], x[0]), plume_v3_sub(x[3], x[2]));
		double s = plume_v3_dot(cross, cross) / epsilon;
		assert_true(s < 1);
		double expected = stiffness * (2 * s - s * s) * plume_barrier(d2, dhat * dhat, NULL, NULL);
		energy_context context = {PLUME_CONTACT_EDGE_EDGE, rest, dhat, stiffness, false};
		double energy = energy_fn(&context, x, NULL, NULL);
		assert_close(energy, expected, 1e-8 * expected);
		// The step is small against the angle, whose derivatives are of order 1/angle.
		double error = finite_difference_error(energy_fn, &context, x, 1e-4 * fmin(distance, angle));
		if (!(error < 1e-6))
			fail_msg("angle %.3g, d/dhat %.3g: relative error %.3g", angle, distance / dhat, error);
		worst = fmax(worst, error);
		// The projection of a mollified pair's Hessian (all four points involved).
		double exact[144], projected[144], values[12];
		plume_contact_pair_energy(PLUME_CONTACT_EDGE_EDGE, x, rest, dhat, stiffness, false, NULL, exact);
		plume_contact_pair_energy(PLUME_CONTACT_EDGE_EDGE, x, rest, dhat, stiffness, true, NULL, projected);
		jacobi_eigenvalues(exact, values);
		double scale = largest_magnitude(values);
		plume_project_psd(exact, 12);
		for (int i = 0; i < 144; ++i)
			assert_close(projected[i], exact[i], 1e-12 * scale);
	}
	// Exactly parallel edges have no edge-edge energy (their points meet the other edge).
	plume_vec3 x[4];
	nearly_parallel(0, 0.5 * dhat, true, x);
	double gradient[12];
	assert_true(plume_contact_pair_energy(PLUME_CONTACT_EDGE_EDGE, x, rest, dhat, stiffness, false, gradient, NULL) ==
	            0);
	// C¹ where the mollifier turns off (x = ε): the energy and its slope in the angle
	// agree on both sides.
	double threshold = asin(sqrt(epsilon));
	double energy_at[4];
	const double offsets[4] = {-2e-7, -1e-7, 1e-7, 2e-7};
	for (int k = 0; k < 4; ++k) {
		nearly_parallel(threshold + offsets[k], 0.5 * dhat, true, x);
		energy_at[k] = plume_contact_pair_energy(PLUME_CONTACT_EDGE_EDGE, x, rest, dhat, stiffness, false, NULL, NULL);
	}
	double slope_below = (energy_at[1] - energy_at[0]) / 1e-7, slope_above = (energy_at[3] - energy_at[2]) / 1e-7;
	assert_close(energy_at[2], energy_at[1], 1e-6 * energy_at[1]);
	// (A mollifier only continuous, such as x/ε, would change slope by about 60 E here;
	// this one's slopes differ by the second derivative times the offsets, ~1e-3 E.)
	assert_close(slope_below, slope_above, 1e-2 * energy_at[1]);
	printf("mollifier: 24 near-parallel pairs, worst relative FD error %.2e\n", worst);
}

// ---------------------------------------------------------------------------
// (e) The PSD projection

static void test_projected_hessian(void **state)
{
	(void)state;
	plume_rng rng = plume_rng_seed(18);
	int indefinite = 0;
	for (int kind = 0; kind <= PLUME_EE_LINES; ++kind)
		for (int trial = 0; trial < 4; ++trial) {
			plume_vec3 x[4], rest[4];
			double dhat = trial < 2 ? 0.4 : 1e-3;
			double distance = dhat * plume_rng_range(&rng, 0.05, 0.9);
			region_configuration(&rng, (plume_distance_kind)kind, distance, x);
			memcpy(rest, x, sizeof rest);
			plume_contact_pair_type type = type_of((plume_distance_kind)kind);
			double exact[144], projected[144], g_exact[12], g_projected[12];
			double e = plume_contact_pair_energy(type, x, rest, dhat, 1e4, false, g_exact, exact);
			assert_true(plume_contact_pair_energy(type, x, rest, dhat, 1e4, true, g_projected, projected) == e);
			assert_memory_equal(g_exact, g_projected, sizeof g_exact);
			// Moving all four points together changes nothing (what lets the projection
			// drop the translations): the gradient's and the Hessian's rows' sums over
			// the points vanish.
			for (int c = 0; c < 3; ++c) {
				assert_close(g_exact[c] + g_exact[3 + c] + g_exact[6 + c] + g_exact[9 + c], 0.0,
				             1e-12 * test_norm(g_exact, 12));
				for (int row = 0; row < 12; ++row)
					assert_close(exact[row * 12 + c] + exact[row * 12 + 3 + c] + exact[row * 12 + 6 + c] +
					                 exact[row * 12 + 9 + c],
					             0.0, 1e-12 * test_norm(exact, 144));
			}
			// P is the Frobenius-nearest PSD matrix to H iff P >= 0, P - H >= 0 and
			// P (P - H) = 0 (the two parts of H's spectral split are orthogonal).
			double values[12], difference[144], product_norm = 0;
			jacobi_eigenvalues(exact, values);
			double scale = largest_magnitude(values);
			if (smallest(values) < -1e-9 * scale)
				indefinite++;
			jacobi_eigenvalues(projected, values);
			assert_true(smallest(values) >= -1e-12 * scale);
			for (int i = 0; i < 144; ++i)
				difference[i] = projected[i] - exact[i];
			jacobi_eigenvalues(difference, values);
			assert_true(smallest(values) >= -1e-12 * scale);
			for (int i = 0; i < 12; ++i)
				for (int j = 0; j < 12; ++j) {
					double sum = 0;
					for (int k = 0; k < 12; ++k)
						sum += projected[i * 12 + k] * difference[k * 12 + j];
					product_norm += sum * sum;
				}
			assert_true(sqrt(product_norm) <= 1e-12 * scale * scale);
			// The same as projecting the whole 12 x 12 matrix (the energy projects only
			// the rows of the points involved, without their translations).
			double whole[144];
			memcpy(whole, exact, sizeof whole);
			plume_project_psd(whole, 12);
			for (int i = 0; i < 144; ++i)
				assert_close(projected[i], whole[i], 1e-12 * scale);
		}
	// The barrier's Hessian is indefinite (b' < 0 bends it down sideways), so the
	// projection is exercised, not skipped.
	assert_true(indefinite > 0);
	printf("projection: %d of %d exact Hessians indefinite\n", indefinite, 4 * REGION_COUNT);
}

// ---------------------------------------------------------------------------
// (f) Continuity across region boundaries

/// Walks configurations along a straight path in the 12 coordinates; where the region
/// changes, bisects to the boundary and compares the two regions' forms (value and
/// gradient) on either side. Returns the number of boundaries checked.
static int check_boundaries(plume_contact_pair_type type, const plume_vec3 start[4], const plume_vec3 end[4])
{
	enum { STEPS = 200 };
	int checked = 0;
	plume_vec3 x[4];
	plume_distance_kind previous = PLUME_PT_A;
	for (int step = 0; step <= STEPS; ++step) {
		double t = (double)step / STEPS;
		for (int i = 0; i < 4; ++i)
			x[i] = plume_v3_lerp(start[i], end[i], t);
		plume_distance_kind kind;
		pair_distance2(type, x, &kind);
		if (step > 0 && kind != previous) {
			double lo = (double)(step - 1) / STEPS, hi = t;
			plume_distance_kind kind_lo = previous, kind_hi = kind;
			for (int iteration = 0; iteration < 60; ++iteration) {
				double mid = 0.5 * (lo + hi);
				for (int i = 0; i < 4; ++i)
					x[i] = plume_v3_lerp(start[i], end[i], mid);
				plume_distance_kind k;
				pair_distance2(type, x, &k);
				if (k == kind_lo)
					lo = mid;
				else {
					hi = mid;
					kind_hi = k;
				}
			}
			plume_vec3 x_lo[4], x_hi[4];
			for (int i = 0; i < 4; ++i) {
				x_lo[i] = plume_v3_lerp(start[i], end[i], lo);
				x_hi[i] = plume_v3_lerp(start[i], end[i], hi);
			}
			double g_lo[12], g_hi[12], diff[12];
			double v_lo = plume_pair_distance2(type, kind_lo, x_lo, g_lo, NULL);
			double v_hi = plume_pair_distance2(type, kind_hi, x_hi, g_hi, NULL);
			if (!(fabs(v_lo - v_hi) <= 1e-10 * v_lo + 1e-15))
				fail_msg("regions %d | %d: %.17g | %.17g", (int)kind_lo, (int)kind_hi, v_lo, v_hi);
			for (int i = 0; i < 12; ++i)
				diff[i] = g_lo[i] - g_hi[i];
			if (!(test_norm(diff, 12) <= 1e-7 * test_norm(g_lo, 12)))
				fail_msg("regions %d | %d: gradients differ by %.3g of %.3g", (int)kind_lo, (int)kind_hi,
				         test_norm(diff, 12), test_norm(g_lo, 12));
			checked++;
		}
		previous = kind;
	}
	return checked;
}

static void test_continuity_across_regions(void **state)
{
	(void)state;
	plume_rng rng = plume_rng_seed(19);
	int checked[2] = {0, 0};
	for (int trial = 0; trial < 60; ++trial) {
		plume_contact_pair_type type = trial % 2 == 0 ? PLUME_CONTACT_POINT_TRIANGLE : PLUME_CONTACT_EDGE_EDGE;
		plume_vec3 start[4], end[4];
		for (int i = 0; i < 4; ++i)
			start[i] = random_vec3(&rng, 1);
		// Mostly the point (or edge a) sweeping past the other primitive, a little of
		// everything else moving too.
		for (int i = 0; i < 4; ++i)
			end[i] = plume_v3_add(start[i],
			                      random_vec3(&rng, i == 0 || (type == PLUME_CONTACT_EDGE_EDGE && i == 1) ? 2.0 : 0.3));
		checked[type] += check_boundaries(type, start, end);
	}
	assert_true(checked[0] > 20 && checked[1] > 20);
	printf("continuity: %d point-triangle and %d edge-edge region boundaries\n", checked[0], checked[1]);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_distances_against_minimisation),
	    cmocka_unit_test(test_region_finite_differences),
	    cmocka_unit_test(test_barrier_closed_form),
	    cmocka_unit_test(test_energy_finite_differences),
	    cmocka_unit_test(test_mollifier),
	    cmocka_unit_test(test_projected_hessian),
	    cmocka_unit_test(test_continuity_across_regions),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
