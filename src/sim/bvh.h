// Private: a bounding-volume hierarchy of axis-aligned boxes, the contact broad phase
// (helper-owned; contract). Built once per surface, refit when the boxes move;
// queries return every overlapping pair in a deterministic order.
#ifndef PLUME_SIM_BVH_H
#define PLUME_SIM_BVH_H

#include "plume/core.h"

typedef struct plume_aabb {
	plume_vec3 lower;
	plume_vec3 upper;
} plume_aabb;

/// The smallest box holding a and b, by comparisons (one minsd / maxsd per bound: libm's
/// fmin and fmax are calls, with their NaN rules, which GCC does not inline).
static inline plume_aabb plume_aabb_merge(plume_aabb a, plume_aabb b)
{
	plume_aabb m;
	m.lower = plume_v3(a.lower.x < b.lower.x ? a.lower.x : b.lower.x, a.lower.y < b.lower.y ? a.lower.y : b.lower.y,
	                   a.lower.z < b.lower.z ? a.lower.z : b.lower.z);
	m.upper = plume_v3(a.upper.x > b.upper.x ? a.upper.x : b.upper.x, a.upper.y > b.upper.y ? a.upper.y : b.upper.y,
	                   a.upper.z > b.upper.z ? a.upper.z : b.upper.z);
	return m;
}

/// A growable list of index pairs, owned by the caller (plume_pair_list_free).
typedef struct plume_pair_list {
	int count;
	int capacity;
	int *pairs; ///< 2 per pair
} plume_pair_list;
void plume_pair_list_free(plume_pair_list *list);

typedef struct plume_bvh plume_bvh;

/// Builds a tree over count boxes (count >= 0). PLUME_ERROR_MEMORY on failure.
plume_status plume_bvh_create(const plume_aabb *boxes, int count, plume_bvh **out, plume_error *err);
void plume_bvh_destroy(plume_bvh *bvh);
/// Same count, new boxes: updates the node boxes bottom-up without changing the topology.
void plume_bvh_refit(plume_bvh *bvh, const plume_aabb *boxes);

/// Appends to out every pair (i of a, j of b) whose boxes overlap; with a == b only
/// i < j. Pairs come sorted by (i, j), so the result is the same on every run and
/// thread count. PLUME_ERROR_MEMORY on failure.
plume_status plume_bvh_overlaps(const plume_bvh *a, const plume_bvh *b, plume_pair_list *out, plume_error *err);

#endif // PLUME_SIM_BVH_H
