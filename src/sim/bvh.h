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
