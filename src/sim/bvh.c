// The contact broad phase (sim/bvh.h): a binary tree of axis-aligned boxes.
//
// Built top-down: each node splits its boxes at the median of their centres along the
// longest axis of the centres' bounds, ties broken by box index, so the tree depends on
// the boxes alone (never on memory addresses or a sort's stability) and is balanced
// (depth ceil(log2 n)). One box a leaf. Nodes are stored in pre-order (a parent before
// its children), so a reverse sweep refits children before their parents.
//
// Two trees are compared by a simultaneous descent with an explicit stack of node pairs
// (the larger box of a pair is opened first); a tree against itself visits the pairs of
// two different children of a node once each, so it reports each i < j once. Boxes are
// closed: boxes that only touch overlap. The new pairs are sorted by (i, j) at the end
// (two counting-sort passes, or qsort for a few pairs).
#include "sim/bvh.h"

#include "core/alloc.h"
#include "core/asserts.h"
#include "core/sort.h"

typedef struct bvh_node {
	plume_aabb box;
	int left;  ///< first child, or -1 for a leaf
	int right; ///< second child, or -1 for a leaf
	int item;  ///< the leaf's box index, or -1 inside the tree
} bvh_node;

struct plume_bvh {
	uint32_t magic; ///< PLUME_HANDLE_MAGIC while alive (core/asserts.h)
	int count;      ///< boxes (leaves)
	int node_count; ///< 2 count - 1, or 0
	bvh_node *nodes;
};

void plume_pair_list_free(plume_pair_list *list)
{
	if (list == NULL)
		return;
	plume_free(list->pairs);
	*list = (plume_pair_list){0, 0, NULL};
}

static double component(plume_vec3 v, int axis) { return axis == 0 ? v.x : axis == 1 ? v.y : v.z; }

static int overlap(const plume_aabb *a, const plume_aabb *b)
{
	return a->lower.x <= b->upper.x && b->lower.x <= a->upper.x && a->lower.y <= b->upper.y &&
	       b->lower.y <= a->upper.y && a->lower.z <= b->upper.z && b->lower.z <= a->upper.z;
}

static int valid_box(plume_aabb b)
{
	// Also false for NaN.
	return b.lower.x <= b.upper.x && b.lower.y <= b.upper.y && b.lower.z <= b.upper.z;
}

/// A box during the build: its centre beside its index, so that the selection below
/// reads contiguous memory.
typedef struct bvh_item {
	plume_vec3 centre;
	int index;
} bvh_item;

/// The build's scratch: the boxes, their items being split, the nodes being written.
typedef struct bvh_build {
	const plume_aabb *boxes;
	bvh_item *items;
	bvh_node *nodes;
	int node_count;
} bvh_build;

/// (centre along axis, index) of a before that of b: a total order.
static int before(const bvh_item *a, const bvh_item *b, int axis)
{
	double ka = component(a->centre, axis), kb = component(b->centre, axis);
	return ka < kb || (ka == kb && a->index < b->index);
}

static void swap_int(int *a, int *b)
{
	int t = *a;
	*a = *b;
	*b = t;
}

static void swap_items(bvh_item *a, bvh_item *b)
{
	bvh_item t = *a;
	*a = *b;
	*b = t;
}

/// A position in [lo, hi) drawn from (lo, hi, draw) by a fixed hash (SplitMix64's
/// finaliser): pivots that look random, so no input order (sorted, organ pipe, a mesh's
/// grid order) makes the selection quadratic, yet the same on every run.
static int hashed_position(int lo, int hi, uint64_t draw)
{
	uint64_t z = ((uint64_t)(uint32_t)lo << 32 | (uint32_t)hi) + draw * 0x9e3779b97f4a7c15u;
	z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
	z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
	z ^= z >> 31;
	return lo + (int)(z % (uint64_t)(hi - lo));
}

/// Rearranges items[lo, hi) so that items[k] is the one that sorts k-th by (centre along
/// axis, index), with the ones before it in [lo, k) (quickselect; the pivot is the median
/// of three hashed positions; expected linear time).
static void select_kth(bvh_item *items, int axis, int lo, int hi, int k)
{
	for (uint64_t round = 0; hi - lo > 2; ++round) {
		// The median of three, moved to hi - 1, the pivot's place during the partition.
		int a = hashed_position(lo, hi, 3 * round), b = hashed_position(lo, hi, 3 * round + 1),
		    c = hashed_position(lo, hi, 3 * round + 2);
		if (before(&items[b], &items[a], axis))
			swap_int(&a, &b);
		if (before(&items[c], &items[b], axis)) {
			swap_int(&b, &c);
			if (before(&items[b], &items[a], axis))
				swap_int(&a, &b);
		}
		swap_items(&items[b], &items[hi - 1]);
		const bvh_item pivot = items[hi - 1];
		int store = lo;
		for (int i = lo; i < hi - 1; ++i)
			if (before(&items[i], &pivot, axis))
				swap_items(&items[i], &items[store++]);
		swap_items(&items[store], &items[hi - 1]);
		if (k == store)
			return;
		if (k < store)
			hi = store;
		else
			lo = store + 1;
	}
	if (hi - lo == 2 && before(&items[lo + 1], &items[lo], axis))
		swap_items(&items[lo], &items[lo + 1]);
}

/// Builds the subtree over items[begin, end) and returns its node.
static int build_node(bvh_build *build, int begin, int end)
{
	int index = build->node_count++;
	bvh_node *node = &build->nodes[index];
	if (end - begin == 1) {
		int item = build->items[begin].index;
		*node = (bvh_node){build->boxes[item], -1, -1, item};
		return index;
	}
	plume_aabb bounds = {build->items[begin].centre, build->items[begin].centre};
	for (int i = begin + 1; i < end; ++i)
		bounds = plume_aabb_merge(bounds, (plume_aabb){build->items[i].centre, build->items[i].centre});
	plume_vec3 extent = plume_v3_sub(bounds.upper, bounds.lower);
	int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
	int middle = begin + (end - begin) / 2;
	select_kth(build->items, axis, begin, end, middle);
	int left = build_node(build, begin, middle);
	int right = build_node(build, middle, end);
	// node still points at build->nodes[index]: the array does not move.
	node->left = left;
	node->right = right;
	node->item = -1;
	node->box = plume_aabb_merge(build->nodes[left].box, build->nodes[right].box);
	return index;
}

plume_status plume_bvh_create(const plume_aabb *boxes, int count, plume_bvh **out, plume_error *err)
{
	PLUME_ASSERT(out != NULL && count >= 0 && (count == 0 || boxes != NULL));
	PLUME_ASSERT(count <= INT32_MAX / 2);
	*out = NULL;
	plume_bvh *bvh = plume_calloc(1, sizeof *bvh);
	bvh_item *items = plume_calloc((size_t)count + 1, sizeof *items);
	bvh_node *nodes = count > 0 ? plume_calloc(2 * (size_t)count - 1, sizeof *nodes) : NULL;
	if (bvh == NULL || items == NULL || (count > 0 && nodes == NULL)) {
		plume_free(bvh);
		plume_free(items);
		plume_free(nodes);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "bounding-volume hierarchy of %d boxes: out of memory", count);
	}
	for (int i = 0; i < count; ++i) {
		PLUME_ASSERT(valid_box(boxes[i]));
		items[i] = (bvh_item){plume_v3_scale(plume_v3_add(boxes[i].lower, boxes[i].upper), 0.5), i};
	}
	if (count > 0) {
		bvh_build build = {boxes, items, nodes, 0};
		build_node(&build, 0, count);
		PLUME_ASSERT(build.node_count == 2 * count - 1);
	}
	plume_free(items);
	bvh->magic = PLUME_HANDLE_MAGIC;
	bvh->count = count;
	bvh->node_count = count > 0 ? 2 * count - 1 : 0;
	bvh->nodes = nodes;
	*out = bvh;
	return PLUME_OK;
}

void plume_bvh_destroy(plume_bvh *bvh)
{
	if (bvh == NULL)
		return;
	PLUME_ASSERT_HANDLE(bvh);
	bvh->magic = 0;
	plume_free(bvh->nodes);
	plume_free(bvh);
}

void plume_bvh_refit(plume_bvh *bvh, const plume_aabb *boxes)
{
	PLUME_ASSERT_HANDLE(bvh);
	PLUME_ASSERT(bvh->count == 0 || boxes != NULL);
	for (int i = bvh->node_count - 1; i >= 0; --i) {
		bvh_node *node = &bvh->nodes[i];
		if (node->item >= 0) {
			PLUME_ASSERT(valid_box(boxes[node->item]));
			node->box = boxes[node->item];
		} else {
			node->box = plume_aabb_merge(bvh->nodes[node->left].box, bvh->nodes[node->right].box);
		}
	}
}

static double extent_sum(const plume_aabb *b)
{
	return (b->upper.x - b->lower.x) + (b->upper.y - b->lower.y) + (b->upper.z - b->lower.z);
}

/// Pushes the node pair (m, n) on the stack; -1 when memory runs out.
static int push(int **stack, int *capacity, int *size, int m, int n)
{
	if (plume_grow((void **)stack, capacity, *size + 1, 2 * sizeof **stack) != 0)
		return -1;
	(*stack)[2 * *size] = m;
	(*stack)[2 * *size + 1] = n;
	++*size;
	return 0;
}

plume_status plume_bvh_overlaps(const plume_bvh *a, const plume_bvh *b, plume_pair_list *out, plume_error *err)
{
	PLUME_ASSERT_HANDLE(a);
	PLUME_ASSERT_HANDLE(b);
	PLUME_ASSERT(out != NULL && out->count >= 0 && out->count <= out->capacity);
	const int self = a == b;
	const int first = out->count;
	if (a->count == 0 || b->count == 0)
		return PLUME_OK;
	int *stack = NULL, capacity = 0, size = 0, failed = 0;
	failed = push(&stack, &capacity, &size, 0, 0);
	while (!failed && size > 0) {
		--size;
		int m = stack[2 * size], n = stack[2 * size + 1];
		const bvh_node *p = &a->nodes[m], *q = &b->nodes[n];
		if (!overlap(&p->box, &q->box))
			continue;
		int p_leaf = p->item >= 0, q_leaf = q->item >= 0;
		if (self && m == n) {
			// A node against itself: its children against themselves and each other once.
			if (!p_leaf)
				failed = push(&stack, &capacity, &size, p->left, p->left) ||
				         push(&stack, &capacity, &size, p->right, p->right) ||
				         push(&stack, &capacity, &size, p->left, p->right);
		} else if (p_leaf && q_leaf) {
			if (plume_grow((void **)&out->pairs, &out->capacity, out->count + 1, 2 * sizeof *out->pairs) != 0) {
				failed = 1;
				break;
			}
			// Distinct subtrees of one tree hold distinct boxes, so i != j here.
			int i = p->item, j = q->item;
			if (self && i > j)
				swap_int(&i, &j);
			out->pairs[2 * out->count] = i;
			out->pairs[2 * out->count + 1] = j;
			++out->count;
		} else if (q_leaf || (!p_leaf && extent_sum(&p->box) >= extent_sum(&q->box))) {
			failed = push(&stack, &capacity, &size, p->left, n) || push(&stack, &capacity, &size, p->right, n);
		} else {
			failed = push(&stack, &capacity, &size, m, q->left) || push(&stack, &capacity, &size, m, q->right);
		}
	}
	plume_free(stack);
	if (!failed && plume_sort_pairs(out->pairs + 2 * first, out->count - first, a->count, b->count) != 0)
		failed = 1;
	if (failed) {
		int found = out->count - first;
		out->count = first;
		return plume_error_set(err, PLUME_ERROR_MEMORY, "broad phase: out of memory after %d overlapping pairs", found);
	}
	return PLUME_OK;
}
