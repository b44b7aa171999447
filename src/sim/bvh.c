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
#include <stdlib.h>
#include <string.h>

#include "sim/bvh.h"

#include "core/alloc.h"
#include "core/asserts.h"

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

static plume_aabb merge(plume_aabb a, plume_aabb b)
{
	plume_aabb m;
	m.lower = plume_v3(a.lower.x < b.lower.x ? a.lower.x : b.lower.x, a.lower.y < b.lower.y ? a.lower.y : b.lower.y,
	                   a.lower.z < b.lower.z ? a.lower.z : b.lower.z);
	m.upper = plume_v3(a.upper.x > b.upper.x ? a.upper.x : b.upper.x, a.upper.y > b.upper.y ? a.upper.y : b.upper.y,
	                   a.upper.z > b.upper.z ? a.upper.z : b.upper.z);
	return m;
}

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

/// The build's scratch: box centres and the permutation being split.
typedef struct bvh_build {
	const plume_aabb *boxes;
	const plume_vec3 *centre;
	int *order;
	bvh_node *nodes;
	int node_count;
} bvh_build;

/// (centre along axis, index) of box a before that of box b: a total order.
static int before(const plume_vec3 *centre, int axis, int a, int b)
{
	double ka = component(centre[a], axis), kb = component(centre[b], axis);
	return ka < kb || (ka == kb && a < b);
}

static void swap_int(int *a, int *b)
{
	int t = *a;
	*a = *b;
	*b = t;
}

/// Rearranges order[lo, hi) so that order[k] is the box that sorts k-th by (centre, index)
/// with the ones before it in [lo, k) (quickselect, median-of-three pivot, deterministic).
static void select_kth(const plume_vec3 *centre, int axis, int *order, int lo, int hi, int k)
{
	while (hi - lo > 2) {
		int mid = lo + (hi - lo) / 2;
		// Median of three at hi - 1, the pivot's place during the partition.
		if (before(centre, axis, order[mid], order[lo]))
			swap_int(&order[mid], &order[lo]);
		if (before(centre, axis, order[hi - 1], order[lo]))
			swap_int(&order[hi - 1], &order[lo]);
		if (before(centre, axis, order[mid], order[hi - 1]))
			swap_int(&order[mid], &order[hi - 1]);
		int pivot = order[hi - 1], store = lo;
		for (int i = lo; i < hi - 1; ++i)
			if (before(centre, axis, order[i], pivot))
				swap_int(&order[i], &order[store++]);
		swap_int(&order[store], &order[hi - 1]);
		if (k == store)
			return;
		if (k < store)
			hi = store;
		else
			lo = store + 1;
	}
	if (hi - lo == 2 && before(centre, axis, order[lo + 1], order[lo]))
		swap_int(&order[lo], &order[lo + 1]);
}

/// Builds the subtree over order[begin, end) and returns its node.
static int build_node(bvh_build *build, int begin, int end)
{
	int index = build->node_count++;
	bvh_node *node = &build->nodes[index];
	if (end - begin == 1) {
		int item = build->order[begin];
		*node = (bvh_node){build->boxes[item], -1, -1, item};
		return index;
	}
	plume_vec3 lo = build->centre[build->order[begin]], hi = lo;
	for (int i = begin + 1; i < end; ++i) {
		plume_aabb c =
		    merge((plume_aabb){lo, hi}, (plume_aabb){build->centre[build->order[i]], build->centre[build->order[i]]});
		lo = c.lower;
		hi = c.upper;
	}
	plume_vec3 extent = plume_v3_sub(hi, lo);
	int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
	int middle = begin + (end - begin) / 2;
	select_kth(build->centre, axis, build->order, begin, end, middle);
	int left = build_node(build, begin, middle);
	int right = build_node(build, middle, end);
	// build->nodes[index] again: node points into the same array, which does not move.
	node->left = left;
	node->right = right;
	node->item = -1;
	node->box = merge(build->nodes[left].box, build->nodes[right].box);
	return index;
}

plume_status plume_bvh_create(const plume_aabb *boxes, int count, plume_bvh **out, plume_error *err)
{
	PLUME_ASSERT(out != NULL && count >= 0 && (count == 0 || boxes != NULL));
	PLUME_ASSERT(count <= INT32_MAX / 2);
	*out = NULL;
	plume_bvh *bvh = plume_calloc(1, sizeof *bvh);
	plume_vec3 *centre = plume_calloc((size_t)count + 1, sizeof *centre);
	int *order = plume_calloc((size_t)count + 1, sizeof *order);
	bvh_node *nodes = count > 0 ? plume_calloc(2 * (size_t)count - 1, sizeof *nodes) : NULL;
	if (bvh == NULL || centre == NULL || order == NULL || (count > 0 && nodes == NULL)) {
		plume_free(bvh);
		plume_free(centre);
		plume_free(order);
		plume_free(nodes);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "bounding-volume hierarchy of %d boxes: out of memory", count);
	}
	for (int i = 0; i < count; ++i) {
		PLUME_ASSERT(valid_box(boxes[i]));
		centre[i] = plume_v3_scale(plume_v3_add(boxes[i].lower, boxes[i].upper), 0.5);
		order[i] = i;
	}
	if (count > 0) {
		bvh_build build = {boxes, centre, order, nodes, 0};
		build_node(&build, 0, count);
		PLUME_ASSERT(build.node_count == 2 * count - 1);
	}
	plume_free(centre);
	plume_free(order);
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
			node->box = merge(bvh->nodes[node->left].box, bvh->nodes[node->right].box);
		}
	}
}

static double extent_sum(const plume_aabb *b)
{
	return (b->upper.x - b->lower.x) + (b->upper.y - b->lower.y) + (b->upper.z - b->lower.z);
}

static int compare_pairs(const void *a, const void *b)
{
	const int *p = a, *q = b;
	if (p[0] != q[0])
		return (p[0] > q[0]) - (p[0] < q[0]);
	return (p[1] > q[1]) - (p[1] < q[1]);
}

/// One stable counting-sort pass: from's pairs into to, ordered by their component
/// (0: i, 1: j), each < range. start holds range + 1 ints of scratch.
static void counting_pass(const int *from, int *to, int count, int component, int range, int *start)
{
	memset(start, 0, ((size_t)range + 1) * sizeof *start);
	for (int k = 0; k < count; ++k)
		++start[from[2 * k + component] + 1];
	for (int r = 0; r < range; ++r)
		start[r + 1] += start[r];
	for (int k = 0; k < count; ++k) {
		int d = start[from[2 * k + component]]++;
		to[2 * d] = from[2 * k];
		to[2 * d + 1] = from[2 * k + 1];
	}
}

/// Sorts count pairs (i < ni, j < nj) by (i, j): by j then stably by i, two counting
/// passes in O(count + ni + nj), which beats qsort by about 5x at half a million pairs;
/// qsort where the pairs are few against the ranges. -1 when memory runs out (the pairs
/// are then unchanged).
static int sort_pairs(int *pairs, int count, int ni, int nj)
{
	if (count < 2)
		return 0;
	if (count < 256 || (size_t)count < ((size_t)ni + (size_t)nj) / 8) {
		qsort(pairs, (size_t)count, 2 * sizeof *pairs, compare_pairs);
		return 0;
	}
	int range = ni > nj ? ni : nj;
	int *scratch = plume_alloc((size_t)count * 2 * sizeof *scratch);
	int *start = plume_alloc(((size_t)range + 1) * sizeof *start);
	if (scratch == NULL || start == NULL) {
		plume_free(scratch);
		plume_free(start);
		return -1;
	}
	counting_pass(pairs, scratch, count, 1, nj, start);
	counting_pass(scratch, pairs, count, 0, ni, start);
	plume_free(scratch);
	plume_free(start);
	return 0;
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
	if (!failed && sort_pairs(out->pairs + 2 * first, out->count - first, a->count, b->count) != 0)
		failed = 1;
	if (failed) {
		int found = out->count - first;
		out->count = first;
		return plume_error_set(err, PLUME_ERROR_MEMORY, "broad phase: out of memory after %d overlapping pairs", found);
	}
	return PLUME_OK;
}
