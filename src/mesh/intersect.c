// The intersection check of issue 14, item 5: which triangles of a soup intersect, decided exactly.
//
// It is the independent proof that contact kept surfaces apart, so it shares nothing with the
// contact solver in src/sim/ (no distances, no tolerances): only signs of determinants.
//
// Broad phase: Embree's rtcCollide of a user-geometry scene with itself gives pairs of
// triangles whose single-precision boxes overlap; the boxes are rounded outwards from the
// double coordinates, so no pair whose double boxes touch is missed, and the double boxes then
// drop the extra pairs. The callback may run on several of Embree's threads at once, so it
// appends under a mutex; the pairs are sorted before anything else, which makes the result
// independent of the threads.
//
// Narrow phase: two closed triangles intersect iff an edge of one meets the other (an extreme
// point of their convex intersection lies on an edge of one of them, since a point in the
// relative interior of both is not extreme). A segment meets a triangle iff it reaches the
// triangle's plane (orient3d of its ends) and the line crosses the triangle there (the three
// orient3d of the line with the triangle's edges agree in sign: they are proportional to the
// barycentric coordinates of the crossing point); a segment in the plane is tested in 2D on a
// coordinate plane where the triangle's projection is not degenerate (orient2d). Triangles
// sharing vertices by index are tested for meeting elsewhere: see shared_vertex_intersect and
// shared_edge_intersect.
//
// Predicates: Shewchuk's orient3d and orient2d ("Adaptive Precision Floating-Point Arithmetic
// and Fast Robust Geometric Predicates", 1997): the determinant in doubles with his first error
// bound (errboundA), plus an absolute term for underflow; when the bound cannot certify the sign,
// the same determinant in GMP integers: every double is m 2^e with an integer m, so the twelve
// coordinates scaled by the smallest 2^e are integers and the determinant's sign is exact.
#include "plume/intersect.h"

#include <embree3/rtcore.h>
#include <float.h>
#include <gmp.h>
#include <limits.h>
#include <math.h>
#include <pthread.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "../core/alloc.h"
#include "../core/asserts.h"

// ---------------------------------------------------------------------------
// Exact predicates

/// Shewchuk's epsilon: half an ulp of 1, the relative error of one rounded operation.
#define ROUND_EPSILON (DBL_EPSILON * 0.5)
/// Shewchuk's first-stage bounds (predicates.c, exactinit): |computed - exact| <= bound * permanent.
#define ORIENT3D_BOUND ((7.0 + 56.0 * ROUND_EPSILON) * ROUND_EPSILON)
#define ORIENT2D_BOUND ((3.0 + 16.0 * ROUND_EPSILON) * ROUND_EPSILON)
/// His bounds assume no underflow. A product that underflows errs by at most 2^-1075 in absolute
/// terms and a determinant has under 20 operations, so this absolute term covers them.
#define UNDERFLOW_BOUND 1e-300

/// Per-thread GMP registers, initialised once so an exact evaluation allocates nothing.
typedef struct exact_scratch {
	mpz_t c[12]; ///< coordinates as integers
	mpz_t t[6];  ///< temporaries
} exact_scratch;

static void scratch_init(exact_scratch *s)
{
	for (int i = 0; i < 12; ++i)
		mpz_init2(s->c[i], 256);
	for (int i = 0; i < 6; ++i)
		mpz_init2(s->t[i], 512);
}

static void scratch_clear(exact_scratch *s)
{
	for (int i = 0; i < 12; ++i)
		mpz_clear(s->c[i]);
	for (int i = 0; i < 6; ++i)
		mpz_clear(s->t[i]);
}

/// Exponent e of the least significant bit of x's 53-bit significand (x = m 2^e, m an integer).
static int lsb_exponent(double x)
{
	int e;
	frexp(x, &e);
	return e - DBL_MANT_DIG;
}

/// Sets the integers c[k] = values[k] 2^-emin, with emin the smallest exponent among them: exact.
static void to_integers(exact_scratch *s, const double *values, int count)
{
	int emin = INT_MAX;
	for (int k = 0; k < count; ++k)
		if (values[k] != 0.0 && lsb_exponent(values[k]) < emin)
			emin = lsb_exponent(values[k]);
	for (int k = 0; k < count; ++k) {
		if (values[k] == 0.0) {
			mpz_set_ui(s->c[k], 0);
			continue;
		}
		int e;
		double significand = ldexp(frexp(values[k], &e), DBL_MANT_DIG); // an integer below 2^53
		mpz_set_d(s->c[k], significand);
		mpz_mul_2exp(s->c[k], s->c[k], (mp_bitcnt_t)(e - DBL_MANT_DIG - emin));
	}
}

static int sign_of(double x) { return (x > 0.0) - (x < 0.0); }

static bool same_point(const plume_vec3 *a, const plume_vec3 *b)
{
	return a->x == b->x && a->y == b->y && a->z == b->z;
}

/// The sign of orient3d(a, b, c, d) in GMP integers (Shewchuk's expansion of the determinant of
/// the rows a - d, b - d, c - d).
static int orient3d_exact(exact_scratch *s, const plume_vec3 *a, const plume_vec3 *b, const plume_vec3 *c,
                          const plume_vec3 *d)
{
	const double values[12] = {a->x, a->y, a->z, b->x, b->y, b->z, c->x, c->y, c->z, d->x, d->y, d->z};
	to_integers(s, values, 12);
	for (int k = 0; k < 9; ++k) // rows minus d: c[0..8] = (a - d, b - d, c - d)
		mpz_sub(s->c[k], s->c[k], s->c[9 + k % 3]);
	mpz_t *adx = &s->c[0], *ady = &s->c[1], *adz = &s->c[2];
	mpz_t *bdx = &s->c[3], *bdy = &s->c[4], *bdz = &s->c[5];
	mpz_t *cdx = &s->c[6], *cdy = &s->c[7], *cdz = &s->c[8];
	// det = adz (bdx cdy - cdx bdy) + bdz (cdx ady - adx cdy) + cdz (adx bdy - bdx ady)
	mpz_mul(s->t[0], *bdx, *cdy);
	mpz_submul(s->t[0], *cdx, *bdy);
	mpz_mul(s->t[1], *adz, s->t[0]);
	mpz_mul(s->t[0], *cdx, *ady);
	mpz_submul(s->t[0], *adx, *cdy);
	mpz_addmul(s->t[1], *bdz, s->t[0]);
	mpz_mul(s->t[0], *adx, *bdy);
	mpz_submul(s->t[0], *bdx, *ady);
	mpz_addmul(s->t[1], *cdz, s->t[0]);
	return mpz_sgn(s->t[1]);
}

/// Sign of the determinant [a - d; b - d; c - d]: positive when d lies below the plane of a, b, c
/// seen counter-clockwise from above (Shewchuk's convention); 0 exactly when the four are coplanar.
static int orient3d(exact_scratch *s, const plume_vec3 *a, const plume_vec3 *b, const plume_vec3 *c,
                    const plume_vec3 *d)
{
	double adx = a->x - d->x, bdx = b->x - d->x, cdx = c->x - d->x;
	double ady = a->y - d->y, bdy = b->y - d->y, cdy = c->y - d->y;
	double adz = a->z - d->z, bdz = b->z - d->z, cdz = c->z - d->z;
	double bdxcdy = bdx * cdy, cdxbdy = cdx * bdy;
	double cdxady = cdx * ady, adxcdy = adx * cdy;
	double adxbdy = adx * bdy, bdxady = bdx * ady;
	double det = adz * (bdxcdy - cdxbdy) + bdz * (cdxady - adxcdy) + cdz * (adxbdy - bdxady);
	double permanent = (fabs(bdxcdy) + fabs(cdxbdy)) * fabs(adz) + (fabs(cdxady) + fabs(adxcdy)) * fabs(bdz) +
	                   (fabs(adxbdy) + fabs(bdxady)) * fabs(cdz);
	double bound = ORIENT3D_BOUND * permanent + UNDERFLOW_BOUND;
	if (det > bound || -det > bound)
		return sign_of(det);
	// Zeros that need no arithmetic: a difference of doubles is 0 exactly when they are equal, so
	// a zero column (the four points on one coordinate plane, a flat sheet) or a repeated point
	// makes the determinant 0 exactly.
	if ((adx == 0.0 && bdx == 0.0 && cdx == 0.0) || (ady == 0.0 && bdy == 0.0 && cdy == 0.0) ||
	    (adz == 0.0 && bdz == 0.0 && cdz == 0.0))
		return 0;
	if (same_point(a, d) || same_point(b, d) || same_point(c, d) || same_point(a, b) || same_point(a, c) ||
	    same_point(b, c))
		return 0;
	return orient3d_exact(s, a, b, c, d);
}

/// A point projected on a coordinate plane.
typedef struct point2 {
	double u, v;
} point2;

/// Drops coordinate `axis` (0 x, 1 y, 2 z), keeping the other two in cyclic order.
static point2 project(const plume_vec3 *p, int axis)
{
	switch (axis) {
	case 0: return (point2){p->y, p->z};
	case 1: return (point2){p->z, p->x};
	default: return (point2){p->x, p->y};
	}
}

static int orient2d_exact(exact_scratch *s, point2 a, point2 b, point2 c)
{
	const double values[6] = {a.u, a.v, b.u, b.v, c.u, c.v};
	to_integers(s, values, 6);
	mpz_sub(s->c[0], s->c[0], s->c[4]); // a - c
	mpz_sub(s->c[1], s->c[1], s->c[5]);
	mpz_sub(s->c[2], s->c[2], s->c[4]); // b - c
	mpz_sub(s->c[3], s->c[3], s->c[5]);
	mpz_mul(s->t[0], s->c[0], s->c[3]);
	mpz_submul(s->t[0], s->c[1], s->c[2]);
	return mpz_sgn(s->t[0]);
}

/// Sign of (a - c) x (b - c): positive when a, b, c turn counter-clockwise.
static int orient2d(exact_scratch *s, point2 a, point2 b, point2 c)
{
	double detleft = (a.u - c.u) * (b.v - c.v);
	double detright = (a.v - c.v) * (b.u - c.u);
	double det = detleft - detright;
	double bound = ORIENT2D_BOUND * (fabs(detleft) + fabs(detright)) + UNDERFLOW_BOUND;
	if (det > bound || -det > bound)
		return sign_of(det);
	// Exact zeros without arithmetic, as in orient3d: points on one coordinate line (a row of a
	// grid) or a repeated point.
	if ((a.u == c.u && b.u == c.u) || (a.v == c.v && b.v == c.v) || (a.u == c.u && a.v == c.v) ||
	    (b.u == c.u && b.v == c.v) || (a.u == b.u && a.v == b.v))
		return 0;
	return orient2d_exact(s, a, b, c);
}

// ---------------------------------------------------------------------------
// Narrow phase

/// One triangle of the soup, with a coordinate plane its projection is not degenerate on.
typedef struct check_triangle {
	plume_vec3 p[3];
	int v[3];
	int axis;        ///< coordinate dropped by project(): the projection keeps the triangle's area
	int orientation; ///< sign of orient2d of the projected corners, +1 or -1
	double lo[3], hi[3];
} check_triangle;

/// Whether p, known to be collinear with a and b, lies on the closed segment ab.
static bool point_on_segment(point2 a, point2 b, point2 p)
{
	return fmin(a.u, b.u) <= p.u && p.u <= fmax(a.u, b.u) && fmin(a.v, b.v) <= p.v && p.v <= fmax(a.v, b.v);
}

/// Closed segments ab and cd on a plane (collinear overlaps included).
static bool segments_meet_2d(exact_scratch *s, point2 a, point2 b, point2 c, point2 d)
{
	int d1 = orient2d(s, c, d, a), d2 = orient2d(s, c, d, b);
	if (d1 * d2 > 0)
		return false;
	int d3 = orient2d(s, a, b, c), d4 = orient2d(s, a, b, d);
	if (d3 * d4 > 0)
		return false;
	if (d1 != 0 || d2 != 0 || d3 != 0 || d4 != 0) {
		// Not all collinear: a proper crossing, or an end on the other segment.
		if (d1 * d2 < 0 && d3 * d4 < 0)
			return true;
		return (d1 == 0 && point_on_segment(c, d, a)) || (d2 == 0 && point_on_segment(c, d, b)) ||
		       (d3 == 0 && point_on_segment(a, b, c)) || (d4 == 0 && point_on_segment(a, b, d));
	}
	// Collinear: they meet iff one contains an end of the other.
	return point_on_segment(c, d, a) || point_on_segment(c, d, b) || point_on_segment(a, b, c) ||
	       point_on_segment(a, b, d);
}

/// Closed 2D point in the closed projected triangle t.
static bool point_in_triangle_2d(exact_scratch *s, const check_triangle *t, point2 p)
{
	point2 q0 = project(&t->p[0], t->axis), q1 = project(&t->p[1], t->axis), q2 = project(&t->p[2], t->axis);
	return orient2d(s, q0, q1, p) * t->orientation >= 0 && orient2d(s, q1, q2, p) * t->orientation >= 0 &&
	       orient2d(s, q2, q0, p) * t->orientation >= 0;
}

/// Closed segment ab, lying in t's plane, against the closed triangle t: in 2D on t's projection,
/// which maps t's plane one to one onto the coordinate plane.
static bool coplanar_segment_meets_triangle(exact_scratch *s, const plume_vec3 *a, const plume_vec3 *b,
                                            const check_triangle *t)
{
	point2 pa = project(a, t->axis), pb = project(b, t->axis);
	if (point_in_triangle_2d(s, t, pa) || point_in_triangle_2d(s, t, pb))
		return true;
	for (int k = 0; k < 3; ++k)
		if (segments_meet_2d(s, pa, pb, project(&t->p[k], t->axis), project(&t->p[(k + 1) % 3], t->axis)))
			return true;
	return false;
}

/// Closed segment ab against the closed triangle t, given oa and ob = orient3d(t, a) and (t, b).
static bool segment_meets_triangle(exact_scratch *s, const plume_vec3 *a, const plume_vec3 *b, int oa, int ob,
                                   const check_triangle *t)
{
	if (oa * ob > 0)
		return false; // both ends strictly on one side of the plane
	if (oa == 0 && ob == 0)
		return coplanar_segment_meets_triangle(s, a, b, t);
	// The segment crosses the plane at one point X, and the line ab is not parallel to it: the
	// three volumes below are proportional (one common nonzero factor) to the signed areas of
	// X p0 p1, X p1 p2, X p2 p0, so X lies in the closed triangle iff no two have opposite signs.
	int s0 = orient3d(s, a, b, &t->p[0], &t->p[1]);
	int s1 = orient3d(s, a, b, &t->p[1], &t->p[2]);
	int s2 = orient3d(s, a, b, &t->p[2], &t->p[0]);
	bool positive = s0 > 0 || s1 > 0 || s2 > 0, negative = s0 < 0 || s1 < 0 || s2 < 0;
	return !(positive && negative);
}

/// Whether three orientations are all strictly positive or all strictly negative.
static bool strictly_one_side(const int o[3])
{
	return (o[0] > 0 && o[1] > 0 && o[2] > 0) || (o[0] < 0 && o[1] < 0 && o[2] < 0);
}

/// Whether every corner of q lies strictly outside the line of an edge of p, in p's projection.
static bool edge_separates(exact_scratch *s, const check_triangle *p, const check_triangle *q)
{
	point2 pp[3], qq[3];
	for (int k = 0; k < 3; ++k) {
		pp[k] = project(&p->p[k], p->axis);
		qq[k] = project(&q->p[k], p->axis);
	}
	for (int k = 0; k < 3; ++k) {
		bool outside = true;
		for (int m = 0; m < 3 && outside; ++m)
			outside = orient2d(s, pp[k], pp[(k + 1) % 3], qq[m]) * p->orientation < 0;
		if (outside)
			return true;
	}
	return false;
}

/// Coplanar triangles, in 2D on p's projection (which maps their plane one to one onto it): two
/// disjoint convex polygons have a separating line through an edge of one of them, with the
/// other strictly on its outer side (the separating axis theorem, with edge normals as axes).
static bool coplanar_triangles_intersect(exact_scratch *s, const check_triangle *p, const check_triangle *q)
{
	check_triangle q_on_p = *q; // q projected like p, with its orientation there
	q_on_p.axis = p->axis;
	q_on_p.orientation =
	    orient2d(s, project(&q->p[0], p->axis), project(&q->p[1], p->axis), project(&q->p[2], p->axis));
	return !edge_separates(s, p, q) && !edge_separates(s, &q_on_p, p);
}

/// Triangles with no vertex index in common.
static bool triangles_intersect(exact_scratch *s, const check_triangle *p, const check_triangle *q)
{
	int op[3], oq[3];
	for (int k = 0; k < 3; ++k)
		op[k] = orient3d(s, &q->p[0], &q->p[1], &q->p[2], &p->p[k]);
	if (strictly_one_side(op))
		return false;
	if (op[0] == 0 && op[1] == 0 && op[2] == 0)
		return coplanar_triangles_intersect(s, p, q);
	for (int k = 0; k < 3; ++k)
		oq[k] = orient3d(s, &p->p[0], &p->p[1], &p->p[2], &q->p[k]);
	if (strictly_one_side(oq))
		return false;
	for (int k = 0; k < 3; ++k)
		if (segment_meets_triangle(s, &p->p[k], &p->p[(k + 1) % 3], op[k], op[(k + 1) % 3], q))
			return true;
	for (int k = 0; k < 3; ++k)
		if (segment_meets_triangle(s, &q->p[k], &q->p[(k + 1) % 3], oq[k], oq[(k + 1) % 3], p))
			return true;
	return false;
}

/// Triangles sharing exactly the vertex index at p's corner i and q's corner j: do they meet
/// anywhere other than that vertex s? If they share a point x != s, follow the ray from s through
/// x: it leaves p through p's edge opposite s at e_p, and q through q's opposite edge at e_q;
/// the nearer of the two lies in both triangles. So they meet elsewhere iff the edge opposite s
/// in one meets the other triangle (such an edge cannot reach s itself).
static bool shared_vertex_intersect(exact_scratch *s, const check_triangle *p, int i, const check_triangle *q, int j)
{
	int p1 = (i + 1) % 3, p2 = (i + 2) % 3, q1 = (j + 1) % 3, q2 = (j + 2) % 3;
	int op1 = orient3d(s, &q->p[0], &q->p[1], &q->p[2], &p->p[p1]);
	int op2 = orient3d(s, &q->p[0], &q->p[1], &q->p[2], &p->p[p2]);
	if (op1 * op2 > 0)
		return false; // p touches q's plane at s only
	int oq1 = orient3d(s, &p->p[0], &p->p[1], &p->p[2], &q->p[q1]);
	int oq2 = orient3d(s, &p->p[0], &p->p[1], &p->p[2], &q->p[q2]);
	if (oq1 * oq2 > 0)
		return false;
	return segment_meets_triangle(s, &p->p[p1], &p->p[p2], op1, op2, q) ||
	       segment_meets_triangle(s, &q->p[q1], &q->p[q2], oq1, oq2, p);
}

/// Triangles sharing the edge (by index) whose far corners are p's corner i and q's corner j.
/// In different planes they meet on the line of the edge only, which holds just the edge of
/// each; in one plane they overlap beyond the edge iff the far corners lie on the same side of it.
static bool shared_edge_intersect(exact_scratch *s, const check_triangle *p, int i, const check_triangle *q, int j)
{
	const plume_vec3 *a = &p->p[(i + 1) % 3], *b = &p->p[(i + 2) % 3];
	if (orient3d(s, a, b, &p->p[i], &q->p[j]) != 0)
		return false;
	point2 pa = project(a, p->axis), pb = project(b, p->axis);
	return orient2d(s, pa, pb, project(&p->p[i], p->axis)) * orient2d(s, pa, pb, project(&q->p[j], p->axis)) > 0;
}

/// The pair's verdict, by the number of vertex indices the triangles share.
static bool pair_intersects(exact_scratch *s, const check_triangle *p, const check_triangle *q)
{
	int shared = 0, pi = -1, qj = -1;
	bool p_shares[3] = {false, false, false}, q_shares[3] = {false, false, false};
	for (int a = 0; a < 3; ++a)
		for (int b = 0; b < 3; ++b)
			if (p->v[a] == q->v[b]) {
				++shared;
				p_shares[a] = q_shares[b] = true;
				pi = a;
				qj = b;
			}
	if (shared == 0)
		return triangles_intersect(s, p, q);
	if (shared == 1)
		return shared_vertex_intersect(s, p, pi, q, qj);
	if (shared == 2) {
		for (int a = 0; a < 3; ++a) {
			if (!p_shares[a])
				pi = a;
			if (!q_shares[a])
				qj = a;
		}
		return shared_edge_intersect(s, p, pi, q, qj);
	}
	return true; // the same three vertices: the triangles coincide
}

// ---------------------------------------------------------------------------
// Input checks

static plume_status check_triangles(const plume_vec3 *positions, int vertex_count, const int *triangles,
                                    int triangle_count, check_triangle *out, plume_error *err)
{
	exact_scratch s;
	scratch_init(&s);
	plume_status status = PLUME_OK;
	for (int t = 0; t < triangle_count && status == PLUME_OK; ++t) {
		check_triangle *c = &out[t];
		for (int k = 0; k < 3; ++k) {
			int v = triangles[3 * t + k];
			PLUME_ASSERT_INDEX(v, vertex_count);
			c->v[k] = v;
			c->p[k] = positions[v];
		}
		for (int k = 0; k < 3 && status == PLUME_OK; ++k) {
			plume_vec3 p = c->p[k];
			if (!isfinite(p.x) || !isfinite(p.y) || !isfinite(p.z))
				status = plume_error_set(err, PLUME_ERROR_NUMERIC,
				                         "intersection check: triangle %d (vertices %d, %d, %d): vertex %d has a "
				                         "non-finite coordinate (%g, %g, %g)",
				                         t, c->v[0], c->v[1], c->v[2], c->v[k], p.x, p.y, p.z);
			else if (fmax(fabs(p.x), fmax(fabs(p.y), fabs(p.z))) > PLUME_INTERSECT_MAX_COORDINATE)
				status = plume_error_set(err, PLUME_ERROR_NUMERIC,
				                         "intersection check: triangle %d (vertices %d, %d, %d): vertex %d at "
				                         "(%g, %g, %g) m is beyond the %g m the check accepts",
				                         t, c->v[0], c->v[1], c->v[2], c->v[k], p.x, p.y, p.z,
				                         PLUME_INTERSECT_MAX_COORDINATE);
		}
		if (status != PLUME_OK)
			break;
		// A coordinate plane on which the triangle keeps an area: the largest normal component's
		// first (a floating-point guess), confirmed exactly; none means the corners are collinear.
		plume_vec3 n = plume_v3_cross(plume_v3_sub(c->p[1], c->p[0]), plume_v3_sub(c->p[2], c->p[0]));
		int first = fabs(n.x) >= fabs(n.y) && fabs(n.x) >= fabs(n.z) ? 0 : fabs(n.y) >= fabs(n.z) ? 1 : 2;
		c->orientation = 0;
		for (int k = 0; k < 3 && c->orientation == 0; ++k) {
			c->axis = (first + k) % 3;
			c->orientation =
			    orient2d(&s, project(&c->p[0], c->axis), project(&c->p[1], c->axis), project(&c->p[2], c->axis));
		}
		if (c->orientation == 0)
			status = plume_error_set(err, PLUME_ERROR_NUMERIC,
			                         "intersection check: triangle %d (vertices %d, %d, %d) has zero area: its "
			                         "corners are repeated or collinear; remove it or move a vertex",
			                         t, c->v[0], c->v[1], c->v[2]);
		for (int axis = 0; axis < 3; ++axis) {
			double a = (&c->p[0].x)[axis], b = (&c->p[1].x)[axis], d = (&c->p[2].x)[axis];
			c->lo[axis] = fmin(a, fmin(b, d));
			c->hi[axis] = fmax(a, fmax(b, d));
		}
	}
	scratch_clear(&s);
	return status;
}

// ---------------------------------------------------------------------------
// Broad phase

typedef struct candidate {
	int i, j;
} candidate;

typedef struct broad_phase {
	const check_triangle *triangles;
	pthread_mutex_t lock;
	candidate *pairs;
	int count, capacity;
	bool out_of_memory;
} broad_phase;

/// The largest float at most x, and the smallest at least x: boxes rounded outwards.
static float float_below(double x)
{
	float f = (float)x;
	return (double)f > x ? nextafterf(f, -INFINITY) : f;
}

static float float_above(double x)
{
	float f = (float)x;
	return (double)f < x ? nextafterf(f, INFINITY) : f;
}

static void triangle_bounds(const struct RTCBoundsFunctionArguments *args)
{
	const broad_phase *b = args->geometryUserPtr;
	const check_triangle *t = &b->triangles[args->primID];
	args->bounds_o->lower_x = float_below(t->lo[0]);
	args->bounds_o->lower_y = float_below(t->lo[1]);
	args->bounds_o->lower_z = float_below(t->lo[2]);
	args->bounds_o->upper_x = float_above(t->hi[0]);
	args->bounds_o->upper_y = float_above(t->hi[1]);
	args->bounds_o->upper_z = float_above(t->hi[2]);
}

static bool boxes_touch(const check_triangle *p, const check_triangle *q)
{
	for (int axis = 0; axis < 3; ++axis)
		if (p->lo[axis] > q->hi[axis] || q->lo[axis] > p->hi[axis])
			return false;
	return true;
}

/// Appends kept pairs under the lock (rtcCollide calls back from several threads).
static void append_pairs(broad_phase *b, const candidate *kept, int count)
{
	pthread_mutex_lock(&b->lock);
	if (PLUME_GROW(b->pairs, b->capacity, b->count + count) == 0) {
		memcpy(b->pairs + b->count, kept, (size_t)count * sizeof *kept);
		b->count += count;
	} else {
		b->out_of_memory = true;
	}
	pthread_mutex_unlock(&b->lock);
}

/// rtcCollide's callback: keeps each pair once, as i < j, when the double boxes touch. Embree
/// reports every pair of primitives of two overlapping leaves, in both orders.
static void collect_pairs(void *user, struct RTCCollision *collisions, unsigned int count)
{
	broad_phase *b = user;
	candidate kept[16];
	int kept_count = 0;
	for (unsigned int k = 0; k < count; ++k) {
		int i = (int)collisions[k].primID0, j = (int)collisions[k].primID1;
		if (i >= j || !boxes_touch(&b->triangles[i], &b->triangles[j]))
			continue;
		kept[kept_count++] = (candidate){i, j};
		if (kept_count == 16) {
			append_pairs(b, kept, kept_count);
			kept_count = 0;
		}
	}
	if (kept_count > 0)
		append_pairs(b, kept, kept_count);
}

static int compare_candidates(const void *a, const void *b)
{
	const candidate *p = a, *q = b;
	if (p->i != q->i)
		return p->i < q->i ? -1 : 1;
	return (p->j > q->j) - (p->j < q->j);
}

static void ignore_embree_error(void *user, enum RTCError code, const char *message)
{
	(void)user;
	(void)code;
	(void)message; // read back through rtcGetDeviceError: the library never prints
}

static plume_status embree_failure(RTCDevice device, const char *what, plume_error *err)
{
	enum RTCError code = rtcGetDeviceError(device); // NULL: the error of a failed rtcNewDevice
	return plume_error_set(err, code == RTC_ERROR_OUT_OF_MEMORY ? PLUME_ERROR_MEMORY : PLUME_ERROR_UNSUPPORTED,
	                       "intersection check: Embree could not %s (error %d)", what, (int)code);
}

/// Candidate pairs (i < j, sorted, unique) whose closed double boxes touch.
static plume_status broad_phase_pairs(const check_triangle *triangles, int triangle_count, candidate **pairs,
                                      int *count, plume_error *err)
{
	*pairs = NULL;
	*count = 0;
	if (triangle_count < 2)
		return PLUME_OK;
	broad_phase b = {.triangles = triangles};
	pthread_mutex_init(&b.lock, NULL);
	plume_status status = PLUME_OK;
	RTCDevice device = rtcNewDevice(NULL);
	RTCScene scene = NULL;
	if (device == NULL) {
		status = embree_failure(NULL, "start", err);
		goto done;
	}
	rtcSetDeviceErrorFunction(device, ignore_embree_error, NULL);
	scene = rtcNewScene(device);
	RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
	if (scene == NULL || geometry == NULL) {
		status = embree_failure(device, "create the scene", err);
		goto done;
	}
	rtcSetGeometryUserPrimitiveCount(geometry, (unsigned int)triangle_count);
	rtcSetGeometryUserData(geometry, &b);
	rtcSetGeometryBoundsFunction(geometry, triangle_bounds, NULL);
	rtcCommitGeometry(geometry);
	rtcAttachGeometry(scene, geometry);
	rtcReleaseGeometry(geometry);
	rtcCommitScene(scene);
	if (rtcGetDeviceError(device) != RTC_ERROR_NONE) {
		status = embree_failure(device, "build the triangles' BVH", err);
		goto done;
	}
	rtcCollide(scene, scene, collect_pairs, &b);
	if (rtcGetDeviceError(device) != RTC_ERROR_NONE) {
		status = embree_failure(device, "collide the BVH with itself", err);
		goto done;
	}
	if (b.out_of_memory) {
		status = plume_error_set(err, PLUME_ERROR_MEMORY, "intersection check: out of memory for candidate pairs");
		goto done;
	}
	qsort(b.pairs, (size_t)b.count, sizeof *b.pairs, compare_candidates);
	int unique = 0;
	for (int k = 0; k < b.count; ++k)
		if (unique == 0 || compare_candidates(&b.pairs[unique - 1], &b.pairs[k]) != 0)
			b.pairs[unique++] = b.pairs[k];
	*pairs = b.pairs;
	*count = unique;
	b.pairs = NULL;
done:
	plume_free(b.pairs);
	if (scene != NULL)
		rtcReleaseScene(scene);
	if (device != NULL)
		rtcReleaseDevice(device);
	pthread_mutex_destroy(&b.lock);
	return status;
}

// ---------------------------------------------------------------------------

plume_status plume_find_intersections(const plume_vec3 *positions, int vertex_count, const int *triangles,
                                      int triangle_count, int max_pairs, int *pairs, int *pair_count, plume_error *err)
{
	PLUME_ASSERT(pair_count != NULL);
	*pair_count = 0;
	PLUME_ASSERT(vertex_count >= 0 && triangle_count >= 0 && max_pairs >= 0);
	PLUME_ASSERT(max_pairs == 0 || pairs != NULL);
	PLUME_ASSERT(triangle_count == 0 || (positions != NULL && triangles != NULL));
	if (triangle_count == 0)
		return PLUME_OK;
	check_triangle *checked = plume_alloc((size_t)triangle_count * sizeof *checked);
	if (checked == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "intersection check: out of memory for %d triangles",
		                       triangle_count);
	plume_status status = check_triangles(positions, vertex_count, triangles, triangle_count, checked, err);
	candidate *candidates = NULL;
	int candidate_count = 0;
	if (status == PLUME_OK)
		status = broad_phase_pairs(checked, triangle_count, &candidates, &candidate_count, err);
	unsigned char *hit = NULL;
	if (status == PLUME_OK && candidate_count > 0) {
		hit = plume_alloc((size_t)candidate_count);
		if (hit == NULL)
			status = plume_error_set(err, PLUME_ERROR_MEMORY, "intersection check: out of memory for %d pairs",
			                         candidate_count);
	}
	if (status == PLUME_OK && candidate_count > 0) {
		// Each verdict depends on its pair only, and they are gathered in the sorted order below.
#pragma omp parallel if (candidate_count >= 1024)
		{
			exact_scratch s;
			scratch_init(&s);
#pragma omp for schedule(dynamic, 256)
			for (int k = 0; k < candidate_count; ++k)
				hit[k] = pair_intersects(&s, &checked[candidates[k].i], &checked[candidates[k].j]);
			scratch_clear(&s);
		}
		int count = 0;
		for (int k = 0; k < candidate_count; ++k) {
			if (!hit[k])
				continue;
			if (count < max_pairs) {
				pairs[2 * count] = candidates[k].i;
				pairs[2 * count + 1] = candidates[k].j;
			}
			++count;
		}
		*pair_count = count;
	}
	plume_free(hit);
	plume_free(candidates);
	plume_free(checked);
	return status;
}
