// plume intersection check: which triangles of a surface soup intersect, decided exactly.
//
// The proof that a simulation never lets surfaces pass through each other (issue 14, item 5):
// every output frame's feathers and bodies go through this check, which shares no code with the
// contact solver (src/sim/). Candidate pairs come from Embree's BVH-against-BVH query
// (rtcCollide) over boxes rounded outwards; each candidate is decided by orientation predicates
// (orient3d, orient2d) evaluated exactly: a floating-point filter with Shewchuk's error bound,
// and GMP integer arithmetic where the filter cannot decide. docs/contact.md, "Intersection check".
#ifndef PLUME_INTERSECT_H
#define PLUME_INTERSECT_H

#include "plume/core.h"

#ifdef __cplusplus
extern "C" {
#endif
PLUME_API_BEGIN

/// Largest coordinate magnitude the check accepts, m: the broad phase's boxes are single
/// precision (Embree drops boxes beyond about 1.8e18), and the filter's error bound assumes
/// that no product of coordinate differences overflows.
#define PLUME_INTERSECT_MAX_COORDINATE 1e15

/// Pairs of triangles of a triangle soup that intersect, by exact arithmetic.
/// positions[vertex_count]; triangles: 3 indices each, in [0, vertex_count). Triangles are closed
/// sets: touching at a point counts as intersecting. Triangles sharing one vertex or one edge
/// (by index) count only when they meet somewhere other than their shared vertex/edge (a fold
/// through); distinct vertices at the same position are not shared, so they touch. Two triangles
/// with the same three vertices coincide and count.
/// Writes up to max_pairs pairs (i < j, sorted by (i, j)) into pairs[2*max_pairs] (may be NULL
/// when max_pairs is 0) and the total count into *pair_count (0 on failure).
/// Errors (nothing written to pairs): PLUME_ERROR_NUMERIC for a triangle with a non-finite
/// coordinate, one beyond PLUME_INTERSECT_MAX_COORDINATE, or zero area (collinear vertices,
/// decided exactly), naming the triangle and its vertices; PLUME_ERROR_MEMORY;
/// PLUME_ERROR_UNSUPPORTED when Embree fails. Indices out of range are programmer errors (assert).
/// Deterministic: the same input gives the same pairs with any number of threads.
plume_status plume_find_intersections(const plume_vec3 *positions, int vertex_count, const int *triangles,
                                      int triangle_count, int max_pairs, int *pairs, int *pair_count, plume_error *err);

PLUME_API_END
#ifdef __cplusplus
}
#endif

#endif // PLUME_INTERSECT_H
