// The intersection check (plume_find_intersections): hand-made pairs with known answers
// (piercing, touching at a vertex, an edge on a face, coplanar overlaps, shared vertices and
// edges), near-degenerate cases where double arithmetic gets the sign wrong, closed meshes
// separated and overlapping by 1e-9 m, a randomized comparison with an independent reference
// (a linear program over barycentric coordinates, solved in GMP rationals), determinism across
// thread counts and the error messages.
#include <gmp.h>
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"

// ---------------------------------------------------------------------------
// Helpers

/// Number of intersecting pairs; fails the test on an error.
static int count_pairs(const plume_vec3 *positions, int vertex_count, const int *triangles, int triangle_count)
{
	int count = -1;
	plume_error err;
	if (plume_find_intersections(positions, vertex_count, triangles, triangle_count, 0, NULL, &count, &err) != PLUME_OK)
		fail_msg("%s", err.message);
	return count;
}

/// Two triangles: vertices 0-2 and 3-5.
static int two(plume_vec3 a0, plume_vec3 a1, plume_vec3 a2, plume_vec3 b0, plume_vec3 b1, plume_vec3 b2)
{
	const plume_vec3 positions[6] = {a0, a1, a2, b0, b1, b2};
	const int triangles[6] = {0, 1, 2, 3, 4, 5};
	int forward = count_pairs(positions, 6, triangles, 2);
	// The verdict must not depend on the order of the triangles or of their corners.
	const int swapped[6] = {4, 5, 3, 2, 0, 1};
	assert_int_equal(count_pairs(positions, 6, swapped, 2), forward);
	return forward;
}

static const plume_vec3 o = {0, 0, 0}, ex = {1, 0, 0}, ey = {0, 1, 0};

// ---------------------------------------------------------------------------
// Independent reference: two closed triangles P, Q intersect iff some barycentric weights
// x = (l0, l1, l2, m0, m1, m2) >= 0 with sum l = sum m = 1 give the same point,
// sum l_i P_i = sum m_j Q_j: a linear program's feasibility. A nonempty polytope
// {x >= 0, A x = b} is the hull of its vertices, the basic feasible solutions, which are found by
// trying every basis of the row-reduced system in exact rationals. With shared vertices the
// question becomes whether a vertex of that polytope is another point than the shared ones.

typedef struct reference {
	mpq_t a[5][7]; ///< the system: 3 coordinate rows, 2 weight rows; column 6 is the right side
	mpq_t b[5][6]; ///< a basis' square system
	mpq_t t;
} reference;

static void reference_init(reference *r)
{
	for (int i = 0; i < 5; ++i) {
		for (int j = 0; j < 7; ++j)
			mpq_init(r->a[i][j]);
		for (int j = 0; j < 6; ++j)
			mpq_init(r->b[i][j]);
	}
	mpq_init(r->t);
}

static void reference_clear(reference *r)
{
	for (int i = 0; i < 5; ++i) {
		for (int j = 0; j < 7; ++j)
			mpq_clear(r->a[i][j]);
		for (int j = 0; j < 6; ++j)
			mpq_clear(r->b[i][j]);
	}
	mpq_clear(r->t);
}

/// Gauss-Jordan elimination of rows x (columns + 1) (the last is the right side), in place,
/// rows of stride `stride`. Returns the rank, or -1 when the system has no solution.
static int reduce(mpq_t *m, int rows, int columns, int stride, mpq_t t)
{
	int rank = 0;
	for (int c = 0; c < columns && rank < rows; ++c) {
		int pivot = -1;
		for (int i = rank; i < rows; ++i)
			if (mpq_sgn(m[i * stride + c]) != 0) {
				pivot = i;
				break;
			}
		if (pivot < 0)
			continue;
		for (int j = 0; j <= columns; ++j)
			mpq_swap(m[pivot * stride + j], m[rank * stride + j]);
		for (int j = columns; j >= c; --j)
			mpq_div(m[rank * stride + j], m[rank * stride + j], m[rank * stride + c]);
		for (int i = 0; i < rows; ++i) {
			if (i == rank || mpq_sgn(m[i * stride + c]) == 0)
				continue;
			for (int j = columns; j >= c; --j) {
				mpq_mul(t, m[i * stride + c], m[rank * stride + j]);
				mpq_sub(m[i * stride + j], m[i * stride + j], t);
			}
		}
		++rank;
	}
	for (int i = rank; i < rows; ++i)
		if (mpq_sgn(m[i * stride + columns]) != 0)
			return -1;
	return rank;
}

/// Whether triangles p and q (positions; vertex indices pv, qv) meet outside their shared vertices.
static bool reference_intersect(reference *r, const plume_vec3 p[3], const int pv[3], const plume_vec3 q[3],
                                const int qv[3])
{
	for (int c = 0; c < 3; ++c) {
		for (int k = 0; k < 3; ++k) {
			mpq_set_d(r->a[c][k], (&p[k].x)[c]);
			mpq_set_d(r->a[c][3 + k], -(&q[k].x)[c]);
		}
		mpq_set_ui(r->a[c][6], 0, 1);
	}
	for (int k = 0; k < 6; ++k) {
		mpq_set_ui(r->a[3][k], k < 3, 1);
		mpq_set_ui(r->a[4][k], k >= 3, 1);
	}
	mpq_set_ui(r->a[3][6], 1, 1);
	mpq_set_ui(r->a[4][6], 1, 1);
	int rank = reduce(&r->a[0][0], 5, 6, 7, r->t);
	if (rank < 0)
		return false;
	bool shared[3] = {false, false, false};
	int shared_count = 0;
	for (int i = 0; i < 3; ++i)
		for (int j = 0; j < 3; ++j)
			if (pv[i] == qv[j]) {
				shared[i] = true;
				++shared_count;
			}
	if (shared_count == 3)
		return true;
	for (int mask = 0; mask < 64; ++mask) {
		if (__builtin_popcount((unsigned)mask) != rank)
			continue;
		for (int i = 0; i < rank; ++i) {
			int column = 0;
			for (int k = 0; k < 6; ++k)
				if (mask & (1 << k))
					mpq_set(r->b[i][column++], r->a[i][k]);
			mpq_set(r->b[i][column], r->a[i][6]);
		}
		if (reduce(&r->b[0][0], rank, rank, 6, r->t) != rank)
			continue; // singular basis
		bool feasible = true;
		double weight_elsewhere = 0.0; // p's weight on its unshared corners: > 0 off the shared ones
		for (int i = 0, k = 0; k < 6; ++k) {
			if (!(mask & (1 << k)))
				continue;
			if (mpq_sgn(r->b[i][rank]) < 0)
				feasible = false;
			if (k < 3 && !shared[k] && mpq_sgn(r->b[i][rank]) > 0)
				weight_elsewhere = 1.0;
			++i;
		}
		if (feasible && (shared_count == 0 || weight_elsewhere > 0.0))
			return true;
	}
	return false;
}

/// All intersecting pairs (i < j, sorted) by the reference, over every pair of the soup.
static int reference_pairs(reference *r, const plume_vec3 *positions, const int *triangles, int triangle_count,
                           int *pairs)
{
	int count = 0;
	for (int i = 0; i < triangle_count; ++i)
		for (int j = i + 1; j < triangle_count; ++j) {
			plume_vec3 p[3], q[3];
			for (int k = 0; k < 3; ++k) {
				p[k] = positions[triangles[3 * i + k]];
				q[k] = positions[triangles[3 * j + k]];
			}
			bool apart = false; // boxes apart on an axis: no common point (saves the rationals)
			for (int c = 0; c < 3; ++c) {
				double plo = fmin((&p[0].x)[c], fmin((&p[1].x)[c], (&p[2].x)[c]));
				double phi = fmax((&p[0].x)[c], fmax((&p[1].x)[c], (&p[2].x)[c]));
				double qlo = fmin((&q[0].x)[c], fmin((&q[1].x)[c], (&q[2].x)[c]));
				double qhi = fmax((&q[0].x)[c], fmax((&q[1].x)[c], (&q[2].x)[c]));
				apart = apart || plo > qhi || qlo > phi;
			}
			if (apart)
				continue;
			if (reference_intersect(r, p, &triangles[3 * i], q, &triangles[3 * j])) {
				pairs[2 * count] = i;
				pairs[2 * count + 1] = j;
				++count;
			}
		}
	return count;
}

/// The exact sign of orient3d(a, b, c, d) in rationals (the reference's, not the library's).
static int exact_orient3d(const plume_vec3 *a, const plume_vec3 *b, const plume_vec3 *c, const plume_vec3 *d)
{
	mpq_t m[3][3], t, u, det;
	const plume_vec3 *rows[3] = {a, b, c};
	for (int i = 0; i < 3; ++i)
		for (int j = 0; j < 3; ++j) {
			mpq_init(m[i][j]);
			mpq_t x;
			mpq_init(x);
			mpq_set_d(m[i][j], (&rows[i]->x)[j]);
			mpq_set_d(x, (&d->x)[j]);
			mpq_sub(m[i][j], m[i][j], x);
			mpq_clear(x);
		}
	mpq_inits(t, u, det, NULL);
	for (int j = 0; j < 3; ++j) { // cofactor expansion along the first row, with Shewchuk's sign
		int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
		mpq_mul(t, m[1][j1], m[2][j2]);
		mpq_mul(u, m[1][j2], m[2][j1]);
		mpq_sub(t, t, u);
		mpq_mul(t, t, m[0][j]);
		mpq_add(det, det, t);
	}
	int sign = mpq_sgn(det);
	for (int i = 0; i < 3; ++i)
		for (int j = 0; j < 3; ++j)
			mpq_clear(m[i][j]);
	mpq_clears(t, u, det, NULL);
	return sign;
}

/// Whether three points are collinear, exactly (the reference's rationals).
static bool exact_collinear(plume_vec3 a, plume_vec3 b, plume_vec3 c)
{
	// Collinear iff all three coordinate-plane projections have zero signed area.
	mpq_t x[6], t, u;
	for (int k = 0; k < 6; ++k)
		mpq_init(x[k]);
	mpq_inits(t, u, NULL);
	bool collinear = true;
	for (int axis = 0; axis < 3 && collinear; ++axis) {
		int i = (axis + 1) % 3, j = (axis + 2) % 3;
		mpq_set_d(x[0], (&b.x)[i]);
		mpq_set_d(t, (&a.x)[i]);
		mpq_sub(x[0], x[0], t);
		mpq_set_d(x[1], (&b.x)[j]);
		mpq_set_d(t, (&a.x)[j]);
		mpq_sub(x[1], x[1], t);
		mpq_set_d(x[2], (&c.x)[i]);
		mpq_set_d(t, (&a.x)[i]);
		mpq_sub(x[2], x[2], t);
		mpq_set_d(x[3], (&c.x)[j]);
		mpq_set_d(t, (&a.x)[j]);
		mpq_sub(x[3], x[3], t);
		mpq_mul(t, x[0], x[3]);
		mpq_mul(u, x[1], x[2]);
		collinear = mpq_equal(t, u) != 0;
	}
	for (int k = 0; k < 6; ++k)
		mpq_clear(x[k]);
	mpq_clears(t, u, NULL);
	return collinear;
}

static uint64_t rng_state;
static uint64_t next_random(void)
{
	rng_state ^= rng_state << 13;
	rng_state ^= rng_state >> 7;
	rng_state ^= rng_state << 17;
	return rng_state;
}
static double uniform(void) { return (double)(next_random() >> 11) * 0x1p-53; }
static int below(int n) { return (int)(next_random() % (uint64_t)n); }

// ---------------------------------------------------------------------------
// Hand-made pairs

static void test_piercing_and_apart(void **state)
{
	(void)state;
	// A thin triangle through the unit triangle's interior.
	assert_int_equal(two(o, ex, ey, plume_v3(0.2, 0.2, -1), plume_v3(0.3, 0.2, 1), plume_v3(0.2, 0.3, 1)), 1);
	// The same lifted above, and moved beside it.
	assert_int_equal(two(o, ex, ey, plume_v3(0.2, 0.2, 0.5), plume_v3(0.3, 0.2, 1), plume_v3(0.2, 0.3, 1)), 0);
	assert_int_equal(two(o, ex, ey, plume_v3(0.8, 0.8, -1), plume_v3(0.9, 0.8, 1), plume_v3(0.8, 0.9, 1)), 0);
	// Two triangles crossing like the links of a chain: each pierces the other's interior.
	assert_int_equal(
	    two(o, plume_v3(2, 0, 0), plume_v3(1, 2, 0), plume_v3(1, 1, -1), plume_v3(1, 1, 1), plume_v3(1, -2, 0)), 1);
}

static void test_touching(void **state)
{
	(void)state;
	// A vertex on the face (closed triangles: touching counts).
	assert_int_equal(two(o, ex, ey, plume_v3(0.25, 0.25, 0), plume_v3(0.3, 0.2, 1), plume_v3(0.2, 0.3, 1)), 1);
	// A vertex on an edge, and on a vertex, from above.
	assert_int_equal(two(o, ex, ey, plume_v3(0.5, 0, 0), plume_v3(0.6, 0, 1), plume_v3(0.5, 0.1, 1)), 1);
	assert_int_equal(two(o, ex, ey, plume_v3(1, 0, 0), plume_v3(1.1, 0, 1), plume_v3(1, 0.1, 1)), 1);
	// An edge lying on the face, the third corner above.
	assert_int_equal(two(o, ex, ey, plume_v3(0.2, 0.2, 0), plume_v3(0.4, 0.2, 0), plume_v3(0.3, 0.3, 1)), 1);
	// Two edges crossing at one point, the triangles on opposite sides of each other's plane.
	assert_int_equal(two(o, ex, ey, plume_v3(0.25, -0.5, 0.5), plume_v3(0.25, 0.5, -0.5), plume_v3(0.25, -1, -1)), 1);
	// That edge lowered by 1e-12: it crosses z = 0 at y = -1e-12, outside.
	assert_int_equal(
	    two(o, ex, ey, plume_v3(0.25, -0.5, 0.5 - 1e-12), plume_v3(0.25, 0.5, -0.5 - 1e-12), plume_v3(0.25, -1, -1)),
	    0);
}

static void test_coplanar(void **state)
{
	(void)state;
	// Overlapping corners, one inside the other, and apart across the hypotenuse.
	assert_int_equal(two(o, ex, ey, plume_v3(0.2, 0.2, 0), plume_v3(1, 0.2, 0), plume_v3(0.2, 1, 0)), 1);
	assert_int_equal(two(o, ex, ey, plume_v3(0.1, 0.1, 0), plume_v3(0.2, 0.1, 0), plume_v3(0.1, 0.2, 0)), 1);
	assert_int_equal(two(o, ex, ey, plume_v3(1, 1, 0), plume_v3(2, 1, 0), plume_v3(1, 2, 0)), 0);
	// Touching at a point of the hypotenuse, and along a piece of an edge.
	assert_int_equal(two(o, ex, ey, plume_v3(0.5, 0.5, 0), plume_v3(1, 1, 0), plume_v3(0.5, 1, 0)), 1);
	assert_int_equal(two(o, ex, ey, plume_v3(0.5, 0, 0), plume_v3(2, 0, 0), plume_v3(1, -1, 0)), 1);
	// A star of David: no vertex inside the other triangle, edges crossing.
	assert_int_equal(two(plume_v3(0, 0, 0), plume_v3(2, 0, 0), plume_v3(1, 1.8, 0), plume_v3(0, 1.2, 0),
	                     plume_v3(2, 1.2, 0), plume_v3(1, -0.6, 0)),
	                 1);
	// Coplanar in a tilted plane, a + s (1, 0, 0) + t (0, 1, 1), with exact (dyadic) coordinates, so
	// the filter cannot decide the zeros and the exact fallback does: a corner of the second on
	// the first's hypotenuse (s = t = 1/2) touches, the same moved 2^-40 further in t does not.
	plume_vec3 a = {0.125, 0.25, 0.375}, b = {1.125, 0.25, 0.375}, c = {0.125, 1.25, 1.375};
	assert_int_equal(
	    two(a, b, c, plume_v3(0.625, 0.75, 0.875), plume_v3(1.625, 0.75, 0.875), plume_v3(0.625, 1.75, 1.875)), 1);
	const double h = 0x1p-40;
	assert_int_equal(two(a, b, c, plume_v3(0.625, 0.75 + h, 0.875 + h), plume_v3(1.625, 0.75 + h, 0.875 + h),
	                     plume_v3(0.625, 1.75 + h, 1.875 + h)),
	                 0);
}

/// Two triangles sharing vertices by index: vertices 0-2 are the first, `second` the other.
static int shared(const plume_vec3 *positions, int vertex_count, const int second[3])
{
	int triangles[6] = {0, 1, 2, second[0], second[1], second[2]};
	int forward = count_pairs(positions, vertex_count, triangles, 2);
	int backward[6] = {second[1], second[2], second[0], 2, 0, 1};
	assert_int_equal(count_pairs(positions, vertex_count, backward, 2), forward);
	return forward;
}

static void test_shared_edge(void **state)
{
	(void)state;
	// Triangle 0 1 2 and 1 0 3: the shared edge is the x axis from 0 to 1.
	plume_vec3 p[4] = {o, ex, ey, {0.5, -1, 0}};
	assert_int_equal(shared(p, 4, (int[]){1, 0, 3}), 0); // flat hinge
	p[3] = plume_v3(0.5, -1, 0.3);
	assert_int_equal(shared(p, 4, (int[]){1, 0, 3}), 0); // bent hinge
	p[3] = plume_v3(0.3, 0.3, 1e-17);
	assert_int_equal(shared(p, 4, (int[]){1, 0, 3}), 0); // closed to a hair, not through
	p[3] = plume_v3(0.3, 0.3, 0);
	assert_int_equal(shared(p, 4, (int[]){1, 0, 3}), 1); // folded through, flat onto the first
	p[3] = plume_v3(3, 0.1, 0);
	assert_int_equal(shared(p, 4, (int[]){0, 1, 3}), 1); // folded through, overhanging
	// The same position under another index is not shared: the flat hinge then touches.
	plume_vec3 q[6] = {o, ex, ey, {0.5, -1, 0}, o, ex};
	assert_int_equal(shared(q, 6, (int[]){5, 4, 3}), 1);
}

static void test_shared_vertex(void **state)
{
	(void)state;
	// Triangle 0 1 2 and 0 3 4: the shared vertex is the origin.
	plume_vec3 p[5] = {o, ex, ey, {-1, 0, 0.5}, {0, -1, 0.5}};
	assert_int_equal(shared(p, 5, (int[]){0, 3, 4}), 0); // away, not in the plane
	p[3] = plume_v3(-1, 0, 0);
	p[4] = plume_v3(0, -1, 0);
	assert_int_equal(shared(p, 5, (int[]){0, 3, 4}), 0); // opposite corner, coplanar
	p[3] = plume_v3(0.4, 0.4, 1);
	p[4] = plume_v3(0.4, 0.4, -1);
	assert_int_equal(shared(p, 5, (int[]){0, 3, 4}), 1); // cuts through along the diagonal
	p[3] = plume_v3(-0.4, -0.4, 1);
	p[4] = plume_v3(-0.4, -0.4, -1);
	assert_int_equal(shared(p, 5, (int[]){0, 3, 4}), 0); // the same plane, outside the corner
	p[3] = plume_v3(0.5, 0.1, 0);
	p[4] = plume_v3(0.1, 0.5, 0);
	assert_int_equal(shared(p, 5, (int[]){0, 3, 4}), 1); // coplanar, inside the corner
	p[3] = plume_v3(2, 0, 0);
	p[4] = plume_v3(0, -1, 0);
	assert_int_equal(shared(p, 5, (int[]){0, 3, 4}), 1); // coplanar, along the x edge
	p[3] = plume_v3(0.3, 0.3, 0);
	p[4] = plume_v3(0, 0, 1);
	assert_int_equal(shared(p, 5, (int[]){0, 3, 4}), 1); // an edge from the vertex on the face
	p[3] = plume_v3(-0.3, -0.3, 0);
	assert_int_equal(shared(p, 5, (int[]){0, 3, 4}), 0); // that edge pointing away
	p[3] = plume_v3(0.5, 0.1, 1);
	p[4] = plume_v3(0.1, 0.5, -1);
	assert_int_equal(shared(p, 5, (int[]){0, 3, 4}), 1); // the far edge pierces the face at (0.3, 0.3, 0)
	// The same triangle twice coincides.
	assert_int_equal(shared(p, 5, (int[]){2, 0, 1}), 1);
}

static void test_near_degenerate(void **state)
{
	(void)state;
	// A vertex 1e-17 m off the plane z = 0, above, below and on it.
	plume_vec3 b = {0.3, 0.2, 1}, c = {0.2, 0.3, 1};
	assert_int_equal(two(o, ex, ey, plume_v3(0.25, 0.25, 1e-17), b, c), 0);
	assert_int_equal(two(o, ex, ey, plume_v3(0.25, 0.25, -1e-17), b, c), 1);
	assert_int_equal(two(o, ex, ey, plume_v3(0.25, 0.25, 0), b, c), 1);
	// A tilted plane whose points are not doubles: points computed on it land within 1e-16 of it,
	// on either side, and the sign of orient3d in doubles is often wrong there. A triangle with
	// one corner there and two far above touches the first iff that corner is on or below.
	const plume_vec3 a0 = {0.1, 0.2, 0.3}, a1 = {1.7, 0.4, 0.9}, a2 = {0.3, 1.9, 1.3};
	plume_vec3 up = plume_v3_cross(plume_v3_sub(a1, a0), plume_v3_sub(a2, a0));
	int naive_wrong = 0, touching = 0;
	rng_state = 0x9e3779b97f4a7c15ull;
	for (int n = 0; n < 400; ++n) {
		double s = 0.2 + 0.3 * uniform(), t = 0.2 + 0.3 * uniform();
		plume_vec3 d = plume_v3_add(
		    a0, plume_v3_add(plume_v3_scale(plume_v3_sub(a1, a0), s), plume_v3_scale(plume_v3_sub(a2, a0), t)));
		plume_vec3 far1 = plume_v3_add(d, plume_v3_add(plume_v3_scale(up, 0.5), plume_v3(0.01, 0, 0)));
		plume_vec3 far2 = plume_v3_add(d, plume_v3_add(plume_v3_scale(up, 0.5), plume_v3(0, 0.01, 0)));
		int side = exact_orient3d(&a0, &a1, &a2, &far1); // the far corners' side
		int exact = exact_orient3d(&a0, &a1, &a2, &d);
		assert_int_not_equal(side, 0);
		int expected = exact == 0 || exact == -side;
		// The plain double determinant with the library's formula, for the record.
		double adx = a0.x - d.x, bdx = a1.x - d.x, cdx = a2.x - d.x, ady = a0.y - d.y, bdy = a1.y - d.y,
		       cdy = a2.y - d.y, adz = a0.z - d.z, bdz = a1.z - d.z, cdz = a2.z - d.z;
		double naive = adz * (bdx * cdy - cdx * bdy) + bdz * (cdx * ady - adx * cdy) + cdz * (adx * bdy - bdx * ady);
		naive_wrong += ((naive > 0) - (naive < 0)) != exact;
		touching += expected;
		assert_int_equal(two(a0, a1, a2, d, far1, far2), expected);
	}
	print_message("near-degenerate: %d of 400 corners touch; the double determinant's sign is wrong for %d\n", touching,
	              naive_wrong);
	assert_true(naive_wrong > 0); // the case is one that needs the exact fallback
	assert_true(touching > 0 && touching < 400);
}

/// The exact sign of the 2D orientation of a, b, c in the xy plane (the reference's rationals).
static int exact_orient2d(plume_vec3 a, plume_vec3 b, plume_vec3 c)
{
	plume_vec3 lifted = plume_v3(c.x, c.y, c.z + 1);
	return exact_orient3d(&a, &b, &lifted, &c); // the prism over a b c has the triangle's sign
}

static void test_near_degenerate_coplanar(void **state)
{
	(void)state;
	// In the plane z = 0.5: a corner computed on the slanted edge a1 a2 lands within rounding of
	// it, on either side; a triangle from there away from the first (in the plane) touches it iff
	// that corner is on the edge or inside. The 2D orientation in doubles is often wrong there.
	const plume_vec3 a0 = {0.1, 0.2, 0.5}, a1 = {1.7, 0.4, 0.5}, a2 = {0.3, 1.9, 0.5};
	int naive_wrong = 0, touching = 0;
	rng_state = 0x1234567887654321ull;
	for (int n = 0; n < 400; ++n) {
		double t = 0.1 + 0.8 * uniform();
		plume_vec3 d = plume_v3_add(a1, plume_v3_scale(plume_v3_sub(a2, a1), t));
		plume_vec3 far1 = plume_v3(d.x + 1, d.y + 1, 0.5), far2 = plume_v3(d.x + 1.2, d.y + 0.9, 0.5);
		int inside = exact_orient2d(a1, a2, a0), side = exact_orient2d(a1, a2, d);
		assert_int_equal(exact_orient2d(a1, a2, far1), -inside); // the far corners are outside
		int expected = side == 0 || side == inside;
		double naive = (a1.x - d.x) * (a2.y - d.y) - (a1.y - d.y) * (a2.x - d.x);
		naive_wrong += ((naive > 0) - (naive < 0)) != side;
		touching += expected;
		assert_int_equal(two(a0, a1, a2, d, far1, far2), expected);
	}
	print_message("near-degenerate in a plane: %d of 400 corners touch; the double orient2d is wrong for %d\n",
	              touching, naive_wrong);
	assert_true(naive_wrong > 0);
	assert_true(touching > 0 && touching < 400);
}

// ---------------------------------------------------------------------------
// Meshes

/// A UV sphere: `rings` latitude bands of `segments` triangles around, poles on the z axis.
static int sphere(plume_vec3 center, double radius, int segments, int rings, plume_vec3 *positions, int *triangles,
                  int vertex_offset)
{
	const double pi = 3.14159265358979323846;
	int v = 0;
	positions[v++] = plume_v3(center.x, center.y, center.z - radius);
	for (int r = 1; r < rings; ++r)
		for (int s = 0; s < segments; ++s) {
			double theta = pi * r / rings, phi = 2 * pi * s / segments;
			positions[v++] = plume_v3(center.x + radius * sin(theta) * cos(phi),
			                          center.y + radius * sin(theta) * sin(phi), center.z - radius * cos(theta));
		}
	positions[v++] = plume_v3(center.x, center.y, center.z + radius);
	int t = 0;
#define RING(r, s) (1 + ((r)-1) * segments + ((s) % segments) + vertex_offset)
	for (int s = 0; s < segments; ++s) {
		int *f = &triangles[3 * t++];
		f[0] = vertex_offset;
		f[1] = RING(1, s + 1);
		f[2] = RING(1, s);
	}
	for (int r = 1; r + 1 < rings; ++r)
		for (int s = 0; s < segments; ++s) {
			int *f = &triangles[3 * t++];
			f[0] = RING(r, s);
			f[1] = RING(r, s + 1);
			f[2] = RING(r + 1, s + 1);
			f = &triangles[3 * t++];
			f[0] = RING(r, s);
			f[1] = RING(r + 1, s + 1);
			f[2] = RING(r + 1, s);
		}
	for (int s = 0; s < segments; ++s) {
		int *f = &triangles[3 * t++];
		f[0] = vertex_offset + v - 1;
		f[1] = RING(rings - 1, s);
		f[2] = RING(rings - 1, s + 1);
	}
#undef RING
	return t;
}

/// A square sheet of n x n quads, 2 triangles each, side 1 cm, at height z (tilted by `slope`).
static int sheet(int n, double z, double slope, plume_vec3 *positions, int *triangles, int vertex_offset)
{
	for (int i = 0; i <= n; ++i)
		for (int j = 0; j <= n; ++j) {
			double x = 0.01 * i / n, y = 0.01 * j / n;
			positions[i * (n + 1) + j] = plume_v3(x, y, z + slope * (x - 0.005));
		}
	int t = 0;
	for (int i = 0; i < n; ++i)
		for (int j = 0; j < n; ++j) {
			int a = vertex_offset + i * (n + 1) + j, b = a + n + 1;
			int *f = &triangles[3 * t];
			f[0] = a, f[1] = b, f[2] = b + 1, f[3] = a, f[4] = b + 1, f[5] = a + 1;
			t += 2;
		}
	return t;
}

/// The pairs of a soup whose first `split` triangles form one mesh: every pair must join the two.
static int cross_pairs(const plume_vec3 *positions, int vertex_count, const int *triangles, int triangle_count,
                       int split)
{
	int count = 0, capacity = 4 * triangle_count;
	int *pairs = malloc((size_t)capacity * 2 * sizeof *pairs);
	plume_error err;
	if (plume_find_intersections(positions, vertex_count, triangles, triangle_count, capacity, pairs, &count, &err) !=
	    PLUME_OK)
		fail_msg("%s", err.message);
	assert_true(count <= capacity);
	for (int k = 0; k < count; ++k) {
		assert_true(pairs[2 * k] < split && pairs[2 * k + 1] >= split);
		if (k > 0)
			assert_true(pairs[2 * k - 2] < pairs[2 * k] ||
			            (pairs[2 * k - 2] == pairs[2 * k] && pairs[2 * k - 1] < pairs[2 * k + 1]));
	}
	free(pairs);
	return count;
}

static void test_spheres(void **state)
{
	(void)state;
	enum { segments = 16, rings = 8, vertices = 2 + (rings - 1) * segments, faces = 2 * segments * (rings - 1) };
	static plume_vec3 positions[2 * vertices];
	static int triangles[6 * faces];
	const double radius = 0.01;
	int first = sphere(o, radius, segments, rings, positions, triangles, 0);
	assert_int_equal(first, faces);
	// Alone, a closed mesh has no intersecting pair: neighbours share edges and vertices only.
	assert_int_equal(count_pairs(positions, vertices, triangles, faces), 0);
	// A second sphere above, its south pole 1e-9 m over the first's north pole, then 1e-9 m into it.
	for (int gap = -1; gap <= 1; gap += 2) {
		sphere(plume_v3(0, 0, 2 * radius + gap * 1e-9), radius, segments, rings, positions + vertices,
		       triangles + 3 * faces, vertices);
		int count = cross_pairs(positions, 2 * vertices, triangles, 2 * faces, faces);
		print_message("spheres %s by 1e-9 m: %d intersecting pairs\n", gap > 0 ? "apart" : "overlapping", count);
		if (gap > 0)
			assert_int_equal(count, 0);
		else // the two pole fans cross each other; the reference finds the same
			assert_true(count >= segments);
	}
}

static void test_sheets(void **state)
{
	(void)state;
	enum { n = 20, vertices = (n + 1) * (n + 1), faces = 2 * n * n };
	static plume_vec3 positions[2 * vertices];
	static int triangles[6 * faces];
	sheet(n, 0, 0, positions, triangles, 0);
	assert_int_equal(count_pairs(positions, vertices, triangles, faces), 0); // flat: coplanar neighbours
	sheet(n, 1e-9, 0, positions + vertices, triangles + 3 * faces, vertices);
	assert_int_equal(cross_pairs(positions, 2 * vertices, triangles, 2 * faces, faces), 0);
	sheet(n, -1e-9, 0, positions + vertices, triangles + 3 * faces, vertices);
	assert_int_equal(cross_pairs(positions, 2 * vertices, triangles, 2 * faces, faces), 0);
	// The second sheet tilted through the first along the line x = 5 mm: the triangles of the
	// two columns of quads around that line, each of the first sheet's 2n triangles on that line
	// crossed by some of the other's.
	sheet(n, 0, 1e-3, positions + vertices, triangles + 3 * faces, vertices);
	int crossing = cross_pairs(positions, 2 * vertices, triangles, 2 * faces, faces);
	print_message("sheets crossing along a line: %d pairs\n", crossing);
	assert_true(crossing >= 2 * n);
	// The same sheet twice (coplanar, offset by half a cell in x): every triangle overlaps some.
	sheet(n, 0, 0, positions + vertices, triangles + 3 * faces, vertices);
	for (int v = 0; v < vertices; ++v)
		positions[vertices + v].x += 0.005 / n;
	assert_true(cross_pairs(positions, 2 * vertices, triangles, 2 * faces, faces) >= faces);
}

// ---------------------------------------------------------------------------
// Randomized comparison with the reference

/// A random soup of `triangle_count` non-degenerate triangles over a pool of vertices: family 0
/// on an integer grid (many coplanar, touching and coincident configurations), 1 on a 0.1 grid
/// (coordinates that are not exact decimals), 2 uniform with corners placed in floating point on
/// other triangles' planes and edges (within rounding of touching).
static int random_soup(int family, plume_vec3 *pool, int pool_count, int *triangles, int triangle_count)
{
	for (int v = 0; v < pool_count; ++v) {
		if (family == 0)
			pool[v] = plume_v3(below(3), below(3), below(3));
		else if (family == 1)
			pool[v] = plume_v3(0.1 * below(5), 0.1 * below(5), 0.1 * below(5));
		else if (v < 4 || below(2) == 0)
			pool[v] = plume_v3(uniform(), uniform(), uniform());
		else { // on the plane (or an edge) of three earlier vertices, rounded
			plume_vec3 a = pool[below(v)], b = pool[below(v)], c = pool[below(v)];
			double s = below(3) == 0 ? 0.0 : uniform() * 1.5 - 0.25, t = uniform() * 1.5 - 0.25;
			pool[v] = plume_v3_add(
			    a, plume_v3_add(plume_v3_scale(plume_v3_sub(b, a), s), plume_v3_scale(plume_v3_sub(c, a), t)));
		}
	}
	for (int t = 0; t < triangle_count; ++t) {
		int a, b, c;
		do {
			a = below(pool_count), b = below(pool_count), c = below(pool_count);
		} while (a == b || b == c || a == c || exact_collinear(pool[a], pool[b], pool[c]));
		triangles[3 * t] = a, triangles[3 * t + 1] = b, triangles[3 * t + 2] = c;
	}
	return triangle_count;
}

static void test_random_against_reference(void **state)
{
	(void)state;
	enum { soups = 300, pool_count = 10, triangle_count = 8, pair_max = triangle_count * (triangle_count - 1) / 2 };
	reference r;
	reference_init(&r);
	rng_state = 0x2545f4914f6cdd1dull;
	int total = 0, per_family[3] = {0, 0, 0};
	for (int n = 0; n < soups; ++n) {
		int family = n % 3;
		plume_vec3 pool[pool_count];
		int triangles[3 * triangle_count];
		random_soup(family, pool, pool_count, triangles, triangle_count);
		int expected[2 * pair_max], found[2 * pair_max];
		int expected_count = reference_pairs(&r, pool, triangles, triangle_count, expected);
		int found_count = -1;
		plume_error err;
		if (plume_find_intersections(pool, pool_count, triangles, triangle_count, pair_max, found, &found_count,
		                             &err) != PLUME_OK)
			fail_msg("soup %d: %s", n, err.message);
		if (found_count != expected_count || memcmp(found, expected, (size_t)found_count * 2 * sizeof(int)) != 0) {
			for (int k = 0; k < found_count; ++k)
				print_message("found %d %d\n", found[2 * k], found[2 * k + 1]);
			for (int k = 0; k < expected_count; ++k)
				print_message("expected %d %d\n", expected[2 * k], expected[2 * k + 1]);
			fail_msg("soup %d (family %d): %d pairs, the reference %d", n, family, found_count, expected_count);
		}
		total += found_count;
		per_family[family] += found_count;
	}
	print_message("random soups: %d soups of %d triangles, %d intersecting pairs (%d, %d, %d by family)\n", soups,
	              triangle_count, total, per_family[0], per_family[1], per_family[2]);
	// Each family must exercise both answers (out of 28 pairs a soup).
	for (int f = 0; f < 3; ++f)
		assert_true(per_family[f] > 0 && per_family[f] < soups / 3 * pair_max);
	reference_clear(&r);
}

static void test_spheres_against_reference(void **state)
{
	(void)state;
	// Two coarse spheres overlapping by about 1 mm off their axis: the pairs, one by one, against
	// the reference over every pair of the two meshes (their own neighbours included).
	enum { segments = 8, rings = 6, vertices = 2 + (rings - 1) * segments, faces = 2 * segments * (rings - 1) };
	plume_vec3 positions[2 * vertices];
	int triangles[6 * faces];
	sphere(o, 0.01, segments, rings, positions, triangles, 0);
	sphere(plume_v3(0.001, 0.0005, 0.02 - 1e-3), 0.01, segments, rings, positions + vertices, triangles + 3 * faces,
	       vertices);
	int found[2 * faces * 4], found_count = 0;
	plume_error err;
	assert_int_equal(
	    plume_find_intersections(positions, 2 * vertices, triangles, 2 * faces, 4 * faces, found, &found_count, &err),
	    PLUME_OK);
	reference r;
	reference_init(&r);
	static int expected[2 * 2 * faces * 2 * faces];
	int expected_count = reference_pairs(&r, positions, triangles, 2 * faces, expected);
	reference_clear(&r);
	print_message("coarse spheres overlapping: %d pairs, the reference %d\n", found_count, expected_count);
	assert_int_equal(found_count, expected_count);
	assert_memory_equal(found, expected, (size_t)found_count * 2 * sizeof(int));
	assert_true(found_count > 0);
}

// ---------------------------------------------------------------------------
// Determinism, capacity, errors, memory

static void test_deterministic(void **state)
{
	(void)state;
	enum { n = 30, vertices = (n + 1) * (n + 1), faces = 2 * n * n };
	static plume_vec3 positions[2 * vertices];
	static int triangles[6 * faces];
	sheet(n, 0, 0, positions, triangles, 0);
	sheet(n, 0, 2e-3, positions + vertices, triangles + 3 * faces, vertices);
	for (int v = 0; v < vertices; ++v)
		positions[vertices + v].y += 0.003 / n;
	static int runs[3][2 * 4 * faces];
	int counts[3];
	int threads[3] = {1, 2, 2};
	int saved = omp_get_max_threads();
	for (int k = 0; k < 3; ++k) {
		omp_set_num_threads(threads[k]);
		plume_error err;
		assert_int_equal(plume_find_intersections(positions, 2 * vertices, triangles, 2 * faces, 4 * faces, runs[k],
		                                          &counts[k], &err),
		                 PLUME_OK);
	}
	omp_set_num_threads(saved);
	assert_true(counts[0] > 0 && counts[0] <= 4 * faces);
	for (int k = 1; k < 3; ++k) {
		assert_int_equal(counts[k], counts[0]);
		assert_memory_equal(runs[k], runs[0], (size_t)counts[0] * 2 * sizeof(int));
	}
	// A smaller capacity gets the first pairs and the whole count.
	int few[6], count = 0;
	plume_error err;
	assert_int_equal(plume_find_intersections(positions, 2 * vertices, triangles, 2 * faces, 3, few, &count, &err),
	                 PLUME_OK);
	assert_int_equal(count, counts[0]);
	assert_memory_equal(few, runs[0], sizeof few);
}

static void test_errors(void **state)
{
	(void)state;
	plume_vec3 p[5] = {o, ex, ey, {2, 0, 0}, {0.5, 0.5, 1}};
	int count = 7;
	plume_error err;
	// A vertex with NaN: the triangle, its vertices and the value are named.
	p[4].y = NAN;
	const int triangles[6] = {0, 1, 2, 0, 3, 4};
	assert_int_equal(plume_find_intersections(p, 5, triangles, 2, 0, NULL, &count, &err), PLUME_ERROR_NUMERIC);
	assert_int_equal(count, 0);
	assert_string_equal(err.message,
	                    "intersection check: triangle 1 (vertices 0, 3, 4): vertex 4 has a non-finite coordinate "
	                    "(0.5, nan, 1)");
	p[4].y = INFINITY;
	assert_int_equal(plume_find_intersections(p, 5, triangles, 2, 0, NULL, &count, &err), PLUME_ERROR_NUMERIC);
	assert_non_null(strstr(err.message, "vertex 4 has a non-finite coordinate (0.5, inf, 1)"));
	p[4].y = 2e15;
	assert_int_equal(plume_find_intersections(p, 5, triangles, 2, 0, NULL, &count, &err), PLUME_ERROR_NUMERIC);
	assert_non_null(strstr(err.message, "triangle 1 (vertices 0, 3, 4): vertex 4 at (0.5, 2e+15, 1) m is beyond"));
	// Collinear corners (on the x axis), and a repeated index: zero area.
	p[4] = plume_v3(0.5, 0.5, 1);
	const int flat[6] = {0, 1, 2, 1, 0, 3};
	assert_int_equal(plume_find_intersections(p, 5, flat, 2, 0, NULL, &count, &err), PLUME_ERROR_NUMERIC);
	assert_string_equal(err.message, "intersection check: triangle 1 (vertices 1, 0, 3) has zero area: its corners "
	                                 "are repeated or collinear; remove it or move a vertex");
	const int repeated[6] = {0, 1, 2, 4, 4, 2};
	assert_int_equal(plume_find_intersections(p, 5, repeated, 2, 0, NULL, &count, &err), PLUME_ERROR_NUMERIC);
	assert_non_null(strstr(err.message, "triangle 1 (vertices 4, 4, 2) has zero area"));
	// Zero area is decided exactly: corners on the decimal line y = x + 0.6 are not collinear as
	// doubles (a sliver of area ~1e-18 m^2) and are accepted; a, a + d, a + 2 d with dyadic
	// a and d are collinear exactly, on a line along no axis, and are refused.
	plume_vec3 q[3] = {{0.1, 0.7, 0}, {0.2, 0.8, 0}, {0.3, 0.9, 0}};
	assert_false(exact_collinear(q[0], q[1], q[2]));
	assert_int_equal(plume_find_intersections(q, 3, (int[]){0, 1, 2}, 1, 0, NULL, &count, &err), PLUME_OK);
	q[0] = plume_v3(0.5, 0.25, 0.125), q[1] = plume_v3(0.75, 0.75, 0.875), q[2] = plume_v3(1, 1.25, 1.625);
	assert_true(exact_collinear(q[0], q[1], q[2]));
	assert_int_equal(plume_find_intersections(q, 3, (int[]){0, 1, 2}, 1, 0, NULL, &count, &err), PLUME_ERROR_NUMERIC);
	// Nothing, one triangle: no pairs.
	assert_int_equal(plume_find_intersections(NULL, 0, NULL, 0, 0, NULL, &count, &err), PLUME_OK);
	assert_int_equal(count, 0);
	assert_int_equal(plume_find_intersections(p, 5, triangles, 1, 0, NULL, &count, &err), PLUME_OK);
	assert_int_equal(count, 0);
}

static void test_no_leak(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	enum { n = 10, vertices = (n + 1) * (n + 1), faces = 2 * n * n };
	static plume_vec3 positions[2 * vertices];
	static int triangles[6 * faces];
	sheet(n, 0, 0, positions, triangles, 0);
	sheet(n, 0, 1e-3, positions + vertices, triangles + 3 * faces, vertices);
	int count;
	plume_error err;
	assert_int_equal(plume_find_intersections(positions, 2 * vertices, triangles, 2 * faces, 0, NULL, &count, &err),
	                 PLUME_OK);
	assert_true(count > 0);
	assert_true(plume_bytes_in_use() == before);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_piercing_and_apart),
	    cmocka_unit_test(test_touching),
	    cmocka_unit_test(test_coplanar),
	    cmocka_unit_test(test_shared_edge),
	    cmocka_unit_test(test_shared_vertex),
	    cmocka_unit_test(test_near_degenerate),
	    cmocka_unit_test(test_near_degenerate_coplanar),
	    cmocka_unit_test(test_spheres),
	    cmocka_unit_test(test_sheets),
	    cmocka_unit_test(test_random_against_reference),
	    cmocka_unit_test(test_spheres_against_reference),
	    cmocka_unit_test(test_deterministic),
	    cmocka_unit_test(test_errors),
	    cmocka_unit_test(test_no_leak),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
